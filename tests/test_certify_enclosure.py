"""The float enclosure of the decay matrix (obsdesign.certify.enclosure) and its use in
lyap.decay_pd: the error bound e must hold exactly, and the proof must never go through at or
beyond the exact smallest eigenvalue.

Test data with an exactly known λ_min: A = Q·D with Q rational orthogonal (Cayley transform
of a rational skew-symmetric S: Q = (I − S)(I + S)⁻¹), so AᵀA = D² exactly while the float
copy of Q is rounded and every float product rounds."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq, fmpq_mat
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign import lyap
from obsdesign.certify import enclosure, vchol
from obsdesign.certify.enclosure import decay_enclosure

U = fmpq(1, 2**53)


@pytest.fixture(autouse=True)
def _float_proofs_first(monkeypatch: pytest.MonkeyPatch) -> None:
    """These tests are about the enclosure: lyap.decay_pd must not answer small matrices by
    the fraction-free LDLᵀ first (its speed path, tested in test_lyap.py)."""
    monkeypatch.setattr(lyap, "FFLU_MAX_N", 0)


def _eye(n: int) -> fmpq_mat:
    return fmpq_mat(n, n, [fmpq(int(i == j)) for i in range(n) for j in range(n)])


def _cayley(n: int, seed: int) -> fmpq_mat:
    """A rational orthogonal matrix (Cayley transform of a random skew-symmetric S)."""
    rng = np.random.default_rng(seed)
    S = fmpq_mat(n, n)
    for i in range(n):
        for j in range(i + 1, n):
            v = fmpq(int(rng.integers(-9, 10)), int(rng.integers(1, 8)))
            S[i, j], S[j, i] = v, -v
    return (_eye(n) - S) * (_eye(n) + S).inv()


def _diag(d: list[fmpq]) -> fmpq_mat:
    n = len(d)
    return fmpq_mat(n, n, [d[i] if i == j else fmpq(0) for i in range(n) for j in range(n)])


def _exact_decay(A: fmpq_mat, P: fmpq_mat, r: fmpq, discrete: bool) -> fmpq_mat:
    if discrete:
        M = P * (r * r) - A.transpose() * P * A
    else:
        M = -(A.transpose() * P + P * A + P * (2 * r))
    return (M + M.transpose()) * fmpq(1, 2)


def _frob2(M: fmpq_mat) -> fmpq:
    return sum((x * x for x in M.entries()), fmpq(0))


def _check_bound(A: fmpq_mat, P: fmpq_mat, r: fmpq, discrete: bool) -> None:
    """‖M_s − H‖_F ≤ e + u‖H‖_F + nη, exactly: e bounds ‖M − V‖ and H is V_s rounded."""
    Af, Pf = vchol.to_float(A), vchol.to_float(P)
    out = decay_enclosure(Af, Pf, r, discrete)
    assert out is not None
    H, e = out
    n = A.nrows()
    Hq = fmpq_mat(n, n, [fmpq(*float(x).as_integer_ratio()) for x in H.ravel()])
    slack = e + U * enclosure.frob_up(H) + n * vchol.ETA
    assert _frob2(_exact_decay(A, P, r, discrete) - Hq) <= slack * slack


@pytest.mark.parametrize("discrete", [True, False])
@pytest.mark.parametrize("n", [3, 20, 60])
def test_error_bound_holds_with_rounded_data(n: int, discrete: bool) -> None:
    """Non-dyadic data (every float copy rounded), entries spread over 2^±20."""
    rng = np.random.default_rng(n)
    scale = [fmpq(2) ** int(k) for k in rng.integers(-20, 21, n)]
    A = _cayley(n, n) * _diag(scale) * fmpq(1, 3)
    B = _cayley(n, n + 1) * _diag([fmpq(int(v), 7) for v in rng.integers(1, 50, n)])
    P = B * B.transpose()
    _check_bound(A, P, fmpq(95, 100) if discrete else fmpq(1, 10), discrete)


@given(
    n=st.integers(1, 12),
    seed=st.integers(0, 10**6),
    discrete=st.booleans(),
    cancel=st.booleans(),
)
@settings(max_examples=60, deadline=None)
def test_error_bound_holds_random(n: int, seed: int, discrete: bool, cancel: bool) -> None:
    """Random rational data; with ``cancel`` the rate makes ρP nearly equal AᵀPA (discrete)
    or 2αP nearly cancel AᵀP + PA (continuous): large products, a small result."""
    rng = np.random.default_rng(seed)
    A = fmpq_mat(
        n,
        n,
        [
            fmpq(int(v), int(w))
            for v, w in zip(rng.integers(-99, 100, n * n), rng.integers(1, 30, n * n), strict=True)
        ],
    )
    B = fmpq_mat(n, n, [fmpq(int(v), 3) for v in rng.integers(-9, 10, n * n)])
    P = B * B.transpose() + _eye(n)
    Af = vchol.to_float(A)
    bound = max(float(np.max(np.abs(np.linalg.eigvals(Af)))), 1e-3)
    if discrete:
        r = fmpq(*float(bound * (1.0001 if cancel else 1.5)).as_integer_ratio())
    else:
        r = fmpq(
            *float(
                -np.max(np.linalg.eigvals(Af).real) * (0.9999 if cancel else 0.5)
            ).as_integer_ratio()
        )
    _check_bound(A, P, r, discrete)


@pytest.mark.parametrize("discrete", [True, False])
@pytest.mark.parametrize("n", [4, 30])
def test_never_proves_at_or_beyond_the_exact_minimum(n: int, discrete: bool) -> None:
    """A = Q·D (discrete: AᵀPA = D² with P = I, λ_min(ρI − D²) = ρ − max d² exactly;
    continuous: A = −D, M = 2D − 2α·I, λ_min = 2(min d − α)): margin at λ_min and 10⁻²⁰ above
    are refused (the exact path then decides), 10⁻⁶ below is proved by the enclosure."""
    rng = np.random.default_rng(n)
    d = [fmpq(int(v), 13) for v in rng.integers(1, 12, n)]
    P = _eye(n)
    if discrete:
        A = _cayley(n, n + 7) * _diag(d)
        r = fmpq(1)
        lam = r * r - max(x * x for x in d)
    else:
        A = -_diag(d) * fmpq(1)
        A = _cayley(n, n + 7).transpose() * A * _cayley(n, n + 7)  # QᵀDQ: same spectrum
        r = fmpq(1, 100)
        lam = 2 * (min(d) - r)
    assert lam > fmpq(1, 10**5)
    for m, want in ((lam, False), (lam + fmpq(1, 10**20), False)):
        res, _ = lyap.decay_pd(A, P, r, discrete, m)
        assert res.ok is want and res.path != "float-enclosure"
    res, H = lyap.decay_pd(A, P, r, discrete, lam - fmpq(1, 10**6))
    assert res.ok and res.path == "float-enclosure" and H.shape == (n, n)
    assert 0 < res.min_pivot <= float(fmpq(1, 10**6)) * 1.0001


def test_refuses_non_finite_and_huge_data() -> None:
    Af = np.array([[0.5, np.inf], [0.0, 0.5]])
    assert decay_enclosure(Af, np.eye(2), fmpq(9, 10), True) is None
    big = np.full((2, 2), 1e300)
    assert decay_enclosure(big, big, fmpq(9, 10), True) is None
    assert decay_enclosure(np.zeros((0, 0)), np.zeros((0, 0)), fmpq(1, 2), True) is None


def test_flush_to_zero_mode_leaves_it_to_the_exact_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """Were subnormals flushed (a fast-math library in the process), the float proofs say
    unknown and the exact path decides the same verdict."""
    A = _cayley(5, 1) * _diag([fmpq(1, 2)] * 5)
    res, _ = lyap.decay_pd(A, _eye(5), fmpq(9, 10), True, fmpq(1, 10**9))
    assert res.ok and res.path == "float-enclosure"
    monkeypatch.setattr(vchol, "subnormals_kept", lambda: False)
    res, _ = lyap.decay_pd(A, _eye(5), fmpq(9, 10), True, fmpq(1, 10**9))
    assert res.ok and res.path != "float-enclosure"
    assert vchol.verified_pd_float(np.eye(3), fmpq(0)) is None
