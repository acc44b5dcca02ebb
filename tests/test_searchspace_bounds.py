"""Norm bounds of the search-space constants (:mod:`obsdesign.methods.searchspace.bounds`):
squares taken after scaling, so constants near the ends of the float range are bounded
(search-space trial, session 27: L_h = 10¹⁶⁰ was refused as "not Lipschitz (a jump?)")."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from obsdesign import api
from obsdesign.methods.searchspace import bounds as B

_mag = st.floats(min_value=0.0, max_value=1e307, allow_nan=False, allow_infinity=False)


def _bounds_tightly(r: float, xs: list[float]) -> bool:
    """r² ≥ Σ x² exactly (never below the root), and r² ≤ (1 + 10⁻¹³)·Σ x² unless the root
    is near the subnormal range (where one least subnormal is the rounding)."""
    s = sum(Fraction(x) ** 2 for x in xs)
    if Fraction(r) ** 2 < s:
        return False
    return r <= 1e-290 or Fraction(r) ** 2 <= s * (1 + Fraction(1, 10**13))


@given(st.lists(_mag, min_size=1, max_size=6))
def test_hypot_hi_is_a_tight_upper_bound_anywhere_in_the_float_range(xs: list[float]) -> None:
    r = B.hypot_hi(xs)
    assert r == math.inf or _bounds_tightly(r, xs)
    assert r < math.inf or sum(Fraction(x) ** 2 for x in xs) > Fraction(1.7e308) ** 2


def test_hypot_hi_at_the_ends_of_the_float_range() -> None:
    """1e160 squared overflows and 1e-300 squared underflows; scaled, both are bounded
    tightly. A root just below each (the smallest false margin, 2⁻⁵⁰ relative) is not."""
    for xs in ([1e160], [3e200, 4e200], [1e-300], [5e-324, 5e-324], [1e300, 1e-300]):
        r = B.hypot_hi(xs)
        assert _bounds_tightly(r, xs), (xs, r)
        assert not _bounds_tightly(r * (1 - 2**-50), xs) or r <= 1e-290
    assert B.hypot_hi([]) == 0.0 and B.hypot_hi([0.0, 0.0]) == 0.0
    assert B.hypot_hi([0.0, math.inf]) == math.inf
    assert B.hypot_hi([1.7e308, 1.7e308]) == math.inf  # √2·1.7·10³⁰⁸ is beyond the range


def test_norm_upper_of_huge_entries_is_finite() -> None:
    r = B.norm_upper([[1e160, 0.0], [0.0, 1e160]])
    assert 1e160 <= r <= 1e160 * (1 + 1e-14)
    r = B.norm_upper([[1e200, 1e200], [1e200, 1e200]])
    assert 2e200 <= r <= 2e200 * (1 + 1e-14)


def test_sampled_norms_do_not_overflow() -> None:
    V = np.array([[3e200, 4e200], [0.0, 0.0], [math.inf, 1.0]])
    n = B._norms(V)
    assert math.isclose(n[0], 5e200, rel_tol=1e-15) and n[1] == 0.0 and n[2] == math.inf


_HUGE = """[system]
time = "continuous"
states = ["x1"]
f = ["-x1"]
h = ["1e160*x1"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 1
[method.E]
lower = [-1]
upper = [1]
[method.D]
lower = [-0.5]
upper = [0.5]
"""


def test_a_constant_above_1e154_is_certified() -> None:
    rep = api.design(api.load_spec_text(_HUGE, "huge.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    L_h = Fraction(str(rep.parameters["L_h"]))
    assert 10**160 <= L_h <= Fraction(100001, 100000) * 10**160


# -- mutation review 27: hypot_hi stays exact where it can, _norms scales small rows ----------
def test_hypot_hi_is_exact_when_the_root_is_a_float() -> None:
    """mutation review 27 (kills bounds.x_hypot_hi__mutmut_26: a quotient stepped up when it
    is exact instead of when it underflowed; x_hypot_hi__mutmut_42: the result always
    stepped up; x_hypot_hi__mutmut_49: `ldexp(out, −e) >= r` → `>`). The power-of-two
    scaling is exact, so a root that is a float is returned as it is (3-4-5, a single entry,
    a subnormal pair); each mutant returned a larger float. An entry whose quotient
    underflows still moves the bound above the root."""
    assert B.hypot_hi([3.0, 4.0]) == 5.0
    assert B.hypot_hi([1.0]) == 1.0 and B.hypot_hi([2.0**600]) == 2.0**600
    assert B.hypot_hi([3e200, 4e200]) == B.hypot_hi([4e200, 3e200])
    assert B.hypot_hi([3.0 * 2**-1074, 4.0 * 2**-1074]) == 5.0 * 2**-1074
    r = B.hypot_hi([1.0, 2.0**-1074])  # 2⁻¹⁰⁷⁵ underflows: rounded up, not to 0
    assert r > 1.0 and Fraction(r) ** 2 >= 1 + Fraction(2) ** -2148


def test_sampled_norms_of_tiny_rows_do_not_underflow() -> None:
    """mutation review 27 (kills bounds.x__norms__mutmut_24: rows scaled only when their
    largest entry is above 1, `m > 0` → `m > 1`). The squares of 3·10⁻²⁰⁰ and 4·10⁻²⁰⁰
    underflow to 0: unscaled, the sampled estimate of ‖(3, 4)·10⁻²⁰⁰‖ was 0, not 5·10⁻²⁰⁰
    (a given constant below the true value could not be refuted)."""
    n = B._norms(np.array([[3e-200, 4e-200], [0.0, 3e-170], [0.5, 0.0]]))
    assert math.isclose(n[0], 5e-200, rel_tol=1e-15)
    assert n[1] == 3e-170 and n[2] == 0.5
