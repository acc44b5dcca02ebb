"""Exact inverse, rank and spectral-norm bounds (obsdesign.certify.linalg)."""

from __future__ import annotations

import numpy as np
from flint import fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.certify.exact import qeye, qmat
from obsdesign.certify.linalg import norm_bound_holds, norm_upper, qinv, qrank


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 6), st.integers(0, 2**31 - 1))
def test_inverse_and_rank(n: int, seed: int):
    rng = np.random.default_rng(seed)
    B = rng.integers(-4, 5, size=(n, n))
    M = qmat(B) / 3
    r = qrank(M)
    assert r == np.linalg.matrix_rank(B)
    if r == n:
        assert (M @ qinv(M) == qeye(n)).all()


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 5), st.integers(1, 5), st.integers(0, 2**31 - 1))
def test_norm_upper_is_a_tight_proved_bound(r: int, c: int, seed: int):
    X = np.random.default_rng(seed).standard_normal((r, c))
    Xq = qmat(X)
    u = norm_upper(Xq)
    assert norm_bound_holds(Xq, u)
    f = np.linalg.norm(X, 2)
    assert f <= float(u) <= f * (1 + 1e-6) + 1e-9
    assert not norm_bound_holds(Xq, u * fmpq(999, 1000)) or f < 1e-9


def test_norm_of_zero_and_empty():
    assert norm_upper(qmat([[0, 0]])) == 0
    assert norm_upper(np.empty((0, 2), dtype=object)) == 0
