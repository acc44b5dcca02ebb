"""The verified floating-point Cholesky (obsdesign.certify.vchol, issue 12 item 1): it may
say "unknown", never "positive definite" when the exact LDLᵀ says not.

Matrices with an exactly known smallest eigenvalue are built over Q: B Bᵀ with B of rank
n − 1 has λ_min = 0 exactly, so B Bᵀ + t·I has λ_min = t exactly (t of either sign)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from flint import fmpq, fmpq_mat, fmpz_mat
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from obsdesign.certify import vchol
from obsdesign.certify.psd import (
    _fraction_free,
    check_pd,
    check_pd_fast,
    check_pd_int,
    check_text,
)
from obsdesign.certify.vchol import float_cholesky, int_to_float, to_float, verified_pd


def _eye(n: int) -> fmpq_mat:
    return fmpq_mat(n, n, [fmpq(int(i == j)) for i in range(n) for j in range(n)])


def _with_lambda_min(n: int, t: fmpq, seed: int = 0) -> fmpq_mat:
    """B Bᵀ + t·I with B an integer n×(n−1) matrix: λ_min = t exactly."""
    rng = np.random.default_rng(seed)
    B = fmpq_mat(n, n - 1, [fmpq(int(v)) for v in rng.integers(-5, 6, size=n * (n - 1))])
    return B * B.transpose() / 7 + _eye(n) * t


@pytest.mark.parametrize("n", [50, 100])
@pytest.mark.parametrize("t", [fmpq(-1, 10**12), fmpq(0)])
def test_not_pd_is_never_proved(n: int, t: fmpq) -> None:
    """λ_min = −10⁻¹² or exactly 0 at n = 50 / 100: no proof, and the fast test says no."""
    M = _with_lambda_min(n, t, seed=n)
    assert verified_pd(M) is None
    r = check_pd_fast(M)
    assert not r.ok and r.path in ("eigenvector", "fraction-free")


@pytest.mark.parametrize("n", [50, 100])
def test_margin_just_above_the_true_one(n: int) -> None:
    """λ_min(M) = 1 exactly: δ = 1 − 10⁻⁹ is proved, δ = 1 and δ = 1 + 10⁻¹⁵ are not."""
    M = _with_lambda_min(n, fmpq(1), seed=n + 1)
    v = verified_pd(M, fmpq(1) - fmpq(1, 10**9))
    assert v is not None and 0 < v.bound <= fmpq(1, 10**9)
    assert verified_pd(M, 1) is None
    assert verified_pd(M, fmpq(1) + fmpq(1, 10**15)) is None
    assert not check_pd_fast(M, 1).ok


def test_tampered_matrix() -> None:
    """A proved matrix with one symmetric pair of entries changed to make it indefinite."""
    n = 50
    M = _with_lambda_min(n, fmpq(1, 2), seed=3)
    assert verified_pd(M) is not None
    bad = fmpq_mat(M)
    big = fmpq(10**6)
    bad[0, 1] = big
    bad[1, 0] = big
    assert verified_pd(bad) is None and not check_pd_fast(bad).ok


def test_scaled_and_extreme_inputs() -> None:
    """Exact power-of-two scaling keeps far-out magnitudes away from over/underflow; the
    zero matrix and the empty matrix are never "proved"."""
    n = 6
    for s in (fmpq(1, 10**300), fmpq(10**300)):
        v = verified_pd(_eye(n) * s)
        assert v is not None and v.bound > 0
        assert verified_pd(_eye(n) * s, s) is None
    assert verified_pd(_eye(n) * 0) is None
    assert verified_pd(fmpq_mat(0, 0)) is None
    assert to_float(_eye(2) * fmpq(10**400)) is None  # beyond the float range: unknown


def test_conversion_is_correctly_rounded() -> None:
    """Step 1 of the theorem: every entry of fl(M) is the nearest double."""
    from fractions import Fraction

    rng = np.random.default_rng(5)
    vals = [fmpq(int(a), int(b)) for a, b in rng.integers(1, 2**62, size=(50, 2))]
    vals += [fmpq(1, 3) * fmpq(2) ** -1070, fmpq(10**30 + 1, 7)]
    H = to_float(fmpq_mat(1, len(vals), vals))
    assert H is not None
    for x, h in zip(vals, H[0], strict=True):
        assert h == float(Fraction(int(x.p), int(x.q)))


def test_backward_error_bound_holds() -> None:
    """Step 3 checked exactly on random matrices: |R̃ᵀR̃ − G| ≤ γ_{n+1}|R̃ᵀ||R̃| entrywise."""
    rng = np.random.default_rng(11)
    for n in (5, 30):
        X = rng.standard_normal((n, n))
        G = X @ X.T + 1e-3 * np.eye(n)
        R = float_cholesky(G)
        assert R is not None
        q = [fmpq(*v.as_integer_ratio()) for v in R.flat]
        Rq = fmpq_mat(n, n, q)
        Aq = fmpq_mat(n, n, [abs(v) for v in q])
        Gq = fmpq_mat(n, n, [fmpq(*v.as_integer_ratio()) for v in G.flat])
        D = Rq.transpose() * Rq - Gq
        B = Aq.transpose() * Aq * vchol._gamma(n + 1)
        assert all(abs(D[i, j]) <= B[i, j] for i in range(n) for j in range(n))
    assert float_cholesky(np.array([[1.0, 2.0], [2.0, 1.0]])) is None
    assert float_cholesky(np.array([[np.inf]])) is None


@st.composite
def _symmetric(draw: st.DrawFn) -> tuple[fmpq_mat, fmpq]:
    n = draw(st.integers(1, 10))
    k = draw(st.integers(1, n))
    ent = st.integers(-20, 20)
    V = [[fmpq(draw(ent), draw(st.integers(1, 9))) for _ in range(k)] for _ in range(n)]
    Vm = fmpq_mat(V)
    shift = draw(st.sampled_from([0, 1, -1, 10**-9, -(10**-9), 10**-15]))
    sh = fmpq(*float(shift).as_integer_ratio()) if shift else fmpq(0)
    margin = draw(st.sampled_from([fmpq(0), fmpq(1, 10**6), fmpq(1, 2), fmpq(1)]))
    return Vm * Vm.transpose() + _eye(n) * sh, margin


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_symmetric())
def test_never_pd_when_exact_says_not(case: tuple[fmpq_mat, fmpq]) -> None:
    """Random symmetric rational matrices near the PD edge: a verified-float proof implies the
    exact LDLᵀ verdict PD (the converse need not hold: "unknown" is allowed)."""
    M, margin = case
    exact = _fraction_free(M - _eye(M.nrows()) * margin).ok
    assert exact == check_pd(np.array(M.tolist(), dtype=object), margin).ok
    if verified_pd(M, margin) is not None:
        assert exact
    r = check_pd_fast(M, margin)
    assert r.ok == exact
    assert check_text(r)


@pytest.mark.parametrize(
    ("n", "seed", "margin"), [(5, 1, fmpq(0)), (30, 2, fmpq(1, 10)), (60, 3, fmpq(0))]
)
def test_the_proved_bound_leaves_room_for_every_error_term(n: int, seed: int, margin: fmpq) -> None:
    """The bound verified_pd reports is at most c − δ minus every term of the theorem,
    recomputed here exactly from the same factor R̃ (γ_{n+1}·Σ r̃², n·τ, u·‖H‖_F + nη,
    u·max|G_ii|): an under-estimated error term (even by half) fails this test."""
    F = _with_lambda_min(n, fmpq(1, 3), seed)
    res = verified_pd(F, margin)
    assert res is not None
    H = to_float(F)
    G = H.copy()
    G[np.arange(n), np.arange(n)] = np.subtract(np.diag(H), res.shift)
    R = float_cholesky(G)
    assert R is not None

    def q(x: float) -> fmpq:
        return fmpq(*float(x).as_integer_ratio())

    u, eta = fmpq(1, 2**53), fmpq(1, 2**1074)
    gamma = (n + 1) * u / (1 - (n + 1) * u)
    sum_r2 = sum((q(x) * q(x) for x in R.ravel()), fmpq(0))
    tau = fmpq(1, 2**1000) * (n + 2) * (1 + q(np.max(np.diag(R))))
    gmax = q(np.max(np.abs(np.diag(G))))
    room = q(res.shift) - margin - gamma * sum_r2 - n * tau - u * gmax - n * eta - res.bound
    sum_h2 = sum((q(x) * q(x) for x in H.ravel()), fmpq(0))
    assert room >= 0 and room * room >= u * u * sum_h2  # room ≥ u·‖H‖_F
    assert res.bound > 0


# -- integer matrices (check_pd_int: the decay matrix times its positive denominator) ------
def _int_part(M: fmpq_mat) -> tuple[fmpz_mat, fmpq]:
    """(Z, c) with M = c·Z, Z an integer matrix, c > 0."""
    Z, d = M.numer_denom()
    return Z, fmpq(1) / fmpq(d)


@pytest.mark.parametrize("n", [30, 100])
def test_int_path_margin_at_the_exact_minimum(n: int) -> None:
    """λ_min(M) = 1 exactly, M = c·Z: M − δI ≻ 0 is proved for δ = 1 − 10⁻⁹ and refused for
    δ = 1 (singular) and δ = 1 + 10⁻¹⁵, through the integer matrix b·Z − a·D·I."""
    M = _with_lambda_min(n, fmpq(1), seed=n + 5)
    for delta, want in (
        (fmpq(1) - fmpq(1, 10**9), True),
        (fmpq(1), False),
        (fmpq(1) + fmpq(1, 10**15), False),
    ):
        N = M - _eye(n) * delta
        Z, c = _int_part(N)
        r, H = check_pd_int(Z, c)
        assert r.ok is want, (delta, r)
        assert H is not None and H.shape == (n, n)
        if want:
            assert r.path == "verified-float" and 0 < r.min_pivot <= 1e-9 * 1.0001


def test_int_path_reports_the_bound_of_the_scaled_matrix() -> None:
    """The bound reported is a lower bound on λ_min(c·Z) (here 3), in c·Z's units: it scales
    with c, while the float matrix Z·2⁻ˢ it was proved on does not."""
    M = _with_lambda_min(20, fmpq(3), seed=2)
    Z, c = _int_part(M)
    r, H = check_pd_int(Z, c)
    r2, H2 = check_pd_int(Z, c * 1024)
    assert r.ok and r2.ok and 0 < r.min_pivot <= 3 and 0 < r2.min_pivot <= 3 * 1024
    assert r2.min_pivot == 1024 * r.min_pivot and (H == H2).all()


def test_int_path_refuses_asymmetry_and_bad_scale() -> None:
    Z = fmpz_mat(2, 2, [2, 1, 0, 2])
    r, H = check_pd_int(Z, 1)
    assert not r.ok and r.path == "symmetry" and "(0, 1)" in r.detail and H is None
    with pytest.raises(ValueError):
        check_pd_int(fmpz_mat(2, 2, [2, 0, 0, 2]), 0)
    assert check_pd_int(fmpz_mat(0, 0, []), 1)[0].ok


def test_int_to_float_is_correctly_rounded_beyond_the_float_range() -> None:
    """Entries of 2⁻ˢZ rounded to nearest (ties to even) even when Z's entries are far beyond
    the float range, and the largest lands in [1, 2]."""
    big = 2**3000
    vals = [big + 1, -(big // 3), 7, 0, 2**3000 - 2**2947, -(2**2946) - 1]
    Z = fmpz_mat(2, 3, vals)
    H, s = int_to_float(Z)
    for z, h in zip(vals, H.ravel().tolist(), strict=True):
        assert h == float(Fraction(z, 2**s))  # Fraction → float: correctly rounded
    assert 1 <= np.max(np.abs(H)) <= 2
    # a tie at 2⁻⁵³ relative: rounds to even
    Z = fmpz_mat(1, 2, [2**60, 2**60 + 2**7])
    H, s = int_to_float(Z)
    assert s == 60 and H[0, 1] == 1.0


@given(
    n=st.integers(1, 7),
    seed=st.integers(0, 10**6),
    scale_bits=st.integers(0, 1200),
    t=st.sampled_from([fmpq(-1, 10**9), fmpq(0), fmpq(1, 10**9), fmpq(1)]),
)
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_int_path_agrees_with_exact_ldl(n: int, seed: int, scale_bits: int, t: fmpq) -> None:
    """Random symmetric integer matrices with λ_min of either sign or exactly 0, scaled by
    2^scale_bits (far beyond the float range): the verdict is the exact LDLᵀ's."""
    M = _with_lambda_min(n + 1, t, seed) * 7 * fmpq(10**9)  # integer entries
    Z, c = _int_part(M)
    Z = Z * (2**scale_bits)
    assert check_pd_int(Z, c)[0].ok == _fraction_free(fmpq_mat(Z)).ok


def test_exact_paths_with_pivots_beyond_the_float_range() -> None:
    """Entries and pivots beyond the float range (no float conversion possible): the exact
    verdict, its pivot shown as ±inf, no OverflowError (found with the integer path's
    property test: the fraction-free path showed a pivot with float())."""
    big = fmpq(2) ** 1100
    assert check_pd_fast(fmpq_mat(2, 2, [big, 0, 0, big])).min_pivot == float("inf")
    r = check_pd_fast(fmpq_mat(2, 2, [big, 0, 0, -big]))
    assert not r.ok and r.min_pivot == float("-inf")
    r, _ = check_pd_int(fmpz_mat(2, 2, [2**1100, 0, 0, -(2**1100)]), 1)
    assert not r.ok


def test_int_to_float_of_zero_and_empty_matrices() -> None:
    """The zero matrix has shift 0 (no largest entry to scale), the empty one too."""
    H, s = vchol.int_to_float(fmpz_mat(2, 2, [0, 0, 0, 0]))
    assert s == 0 and H.dtype == float and not H.any() and H.shape == (2, 2)
    H, s = vchol.int_to_float(fmpz_mat(0, 0, []))
    assert s == 0 and H.shape == (0, 0)
    H, s = vchol.int_to_float(fmpz_mat(1, 2, [3, -5]))
    assert s == 2 and H.tolist() == [[0.75, -1.25]]


@pytest.mark.parametrize("fflu_max_n", [None, 0])
def test_to_float_entry_by_entry_is_correctly_rounded_with_distinct_denominators(
    monkeypatch, fflu_max_n
) -> None:
    """to_float went through one common denominator (264,000 digits for 10⁴ distinct
    30-digit ones: 15 s, 3 GB; responsiveness review 47); entry by entry it is the same
    correctly rounded copy. And the smallest false margin still fails: P with distinct long
    denominators whose smallest eigenvalue is −2⁻²⁰⁰ is not proved positive definite."""
    import random
    from fractions import Fraction

    from obsdesign import lyap

    if fflu_max_n is not None:  # the verified float Cholesky and the integer check decide
        monkeypatch.setattr(lyap, "FFLU_MAX_N", fflu_max_n)
    rnd = random.Random(47)
    n = 6
    F = fmpq_mat(n, n)
    for i in range(n):
        for j in range(i, n):
            q = rnd.getrandbits(100) | 1
            F[i, j] = F[j, i] = fmpq(rnd.getrandbits(90) * (2 if i == j else 1), q)
    H = to_float(F)
    for i in range(n):
        for j in range(n):
            x = F[i, j]
            assert H[i, j] == float(Fraction(int(x.p), int(x.q)))
    # v = e₁ − e₂: vᵀPv = P₁₁ − 2P₁₂ + P₂₂ set to −2⁻²⁰⁰, the smallest false margin here
    P = fmpq_mat(n, n, [fmpq(int(i == j) * 2) for i in range(n) for j in range(n)])
    q = fmpq(1, rnd.getrandbits(100) | 1)
    P[0, 1] = P[1, 0] = fmpq(2) + q
    P[0, 0] = fmpq(1) + q
    P[1, 1] = 2 * P[0, 1] - P[0, 0] - fmpq(1, 2**200)  # vᵀPv = −2⁻²⁰⁰ exactly
    r = lyap.pd_verdict(P, 0, None, P, to_float(P))
    assert not r.ok
    P[1, 1] = 2 * P[0, 1] - P[0, 0] + 1  # then vᵀPv = 1: decided the other way
    assert lyap.pd_verdict(P, 0, None, P, to_float(P)).ok
