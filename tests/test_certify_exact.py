"""Rational conversions (obsdesign.certify.exact)."""

from __future__ import annotations

from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest
from flint import fmpq
from hypothesis import given
from hypothesis import strategies as st

from obsdesign.certify.exact import Q, dyadic, qmat, qparse, qstr, to_float


def test_decimal_is_exact():
    assert Q(Decimal("0.1")) + Q(Decimal("0.2")) == fmpq(3, 10)
    assert Q(0.1) != fmpq(1, 10)  # a float is its binary value


def test_conversions():
    assert Q(Fraction(-187, 100)) == fmpq(-187, 100)
    assert Q("-187/100") == fmpq(-187, 100)
    assert Q(3) == fmpq(3)
    with pytest.raises(ValueError):
        Q(float("nan"))
    with pytest.raises(ValueError):
        Q(Decimal("inf"))
    with pytest.raises(TypeError):
        Q(True)


def test_qstr_qparse_roundtrip_3d():
    a = qmat([[1, 2], [3, 4]])
    assert (qparse(qstr(a)) == a).all()
    cube = np.empty((2, 2, 2), dtype=object)
    for idx in np.ndindex(2, 2, 2):
        cube[idx] = fmpq(sum(idx) - 1, 3)
    back = qparse(qstr(cube))
    assert back.shape == (2, 2, 2) and (back == cube).all()


@given(st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=6))
def test_dyadic_close_and_exact_grid(xs):
    arr = np.array(xs)
    q = dyadic(arr, 30)
    back = np.asarray(to_float(q), dtype=float)
    assert np.all(np.abs(back - arr) <= np.abs(arr) * 2.0**-30)
    for v in q:
        assert int(v.q) & (int(v.q) - 1) == 0  # denominator is a power of two
