"""Outward-rounded bounds (obsdesign.certify.interval)."""

from __future__ import annotations

import math

from flint import fmpq
from hypothesis import given
from hypothesis import strategies as st
from mpmath import iv

from obsdesign.certify.interval import (
    bounds,
    ceil_int,
    log_lower,
    log_upper,
    round_down,
    round_up,
    sqrt_lower,
    sqrt_upper,
)


@given(st.integers(1, 10**9), st.integers(1, 10**6))
def test_sqrt_bounds_bracket(p: int, q: int):
    x = fmpq(p, q)
    lo, hi = sqrt_lower(x), sqrt_upper(x)
    assert lo * lo <= x <= hi * hi  # exact check of the enclosure
    assert hi - lo < fmpq(1, 10**20) * (1 + hi)


def test_log_bounds():
    lo, hi = log_lower(fmpq(3)), log_upper(fmpq(3))
    assert lo <= hi and float(lo) <= math.log(3) <= float(hi)


def test_composite_expression():
    lo, hi = bounds(lambda a, b: iv.log(a) / b + iv.sqrt(b), fmpq(25), fmpq(1, 7))
    val = math.log(25) * 7 + math.sqrt(1 / 7)
    assert float(lo) <= val <= float(hi)


def test_rounding_directions():
    assert round_up(fmpq(1, 3), 2) == fmpq(34, 100)
    assert round_down(fmpq(1, 3), 2) == fmpq(33, 100)
    assert round_up(fmpq(-1, 3), 2) == fmpq(-33, 100)
    assert round_down(fmpq(-1, 3), 2) == fmpq(-34, 100)
    assert round_up(fmpq(1, 2), 1) == fmpq(1, 2)
    assert ceil_int(fmpq(7, 2)) == 4 and ceil_int(fmpq(4)) == 4
