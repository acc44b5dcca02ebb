"""Exact PD/PSD tests (obsdesign.certify.psd)."""

from __future__ import annotations

import numpy as np
from flint import fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.certify.exact import qeye, qmat
from obsdesign.certify.psd import check_pd, check_psd, ldl_pivots


def test_pd_identity_and_margin():
    assert check_pd(qeye(4)).ok
    assert check_pd(qeye(4), fmpq(1, 2)).ok
    assert not check_pd(qeye(4), 1).ok  # I - I = 0 is not PD


def test_psd_singular_is_psd_not_pd():
    M = qmat([[1, 1, 0], [1, 1, 0], [0, 0, 2]])
    assert check_psd(M).ok
    assert not check_pd(M).ok


def test_indefinite():
    M = qmat([[1, 2], [2, 1]])
    assert not check_psd(M).ok
    assert not check_pd(M).ok


def test_zero_pivot_with_nonzero_coupling_is_not_psd():
    M = qmat([[0, 1], [1, 5]])
    assert not check_psd(M).ok


def test_asymmetric_rejected():
    r = check_pd(qmat([[2, 1], [0, 2]]))
    assert not r.ok and "symmetric" in r.detail


def test_badly_scaled_20x20():
    rng = np.random.default_rng(1)
    B = rng.standard_normal((20, 20))
    S = np.diag(10.0 ** np.linspace(-6, 6, 20))
    M = S @ (B @ B.T + 1e-3 * np.eye(20)) @ S
    Mq = qmat(M)  # every float exactly
    Mq = (Mq + Mq.T) * fmpq(1, 2)
    assert check_pd(Mq).ok
    # subtract a tiny multiple of e1 e1ᵀ beyond the smallest pivot: becomes indefinite
    piv = ldl_pivots(Mq)
    assert all(p > 0 for p in piv)
    bad = Mq.copy()
    bad[19, 19] -= piv[-1] * 2
    assert not check_pd(bad).ok


def test_exactness_beats_floats():
    # [[1, 1], [1, 1 + 2^-60]] is PD; in float64 it rounds to a singular matrix
    eps = fmpq(1, 2**60)
    M = qmat([[1, 1], [1, 1]])
    M[1, 1] += eps
    assert check_pd(M).ok
    assert np.linalg.eigvalsh(np.array([[1.0, 1.0], [1.0, 1.0 + 2.0**-60]])).min() <= 0


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 8), st.integers(0, 2**31 - 1))
def test_random_gram_matrices(n: int, seed: int):
    rng = np.random.default_rng(seed)
    B = rng.integers(-5, 6, size=(n, n))
    M = qmat(B @ B.T)  # integer Gram matrix: PSD, PD iff B invertible
    assert check_psd(M).ok
    assert check_pd(M).ok == (round(abs(np.linalg.det(B))) != 0)
    v = rng.integers(-3, 4, size=n)
    N = M - qmat(np.outer(v, v)) * (1 + int(np.abs(v).sum() > 0) * 1000)
    if np.any(v):
        # subtracting a large rank-one term makes it indefinite unless v is orthogonal to range
        ev = np.linalg.eigvalsh(np.asarray(N, dtype=float))
        assert check_psd(N).ok == bool(ev.min() >= -1e-9)
