"""check_pd_fast (issue 12 item 1): the same exact verdict as check_pd, by a float-guided
certificate checked over Q (M = RᵀR + S, S diagonally dominant; or vᵀMv ≤ 0) or, when neither
goes through, the fraction-free LDLᵀ over Z. Known answers, must-fail cases on the edge, every
proof path exercised, agreement with check_pd on random matrices."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq, fmpq_mat, fmpz_mat
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from obsdesign.certify import psd
from obsdesign.certify.exact import Q, qmat
from obsdesign.certify.psd import check_pd, check_pd_fast, check_psd


@pytest.mark.parametrize(
    ("M", "margin", "ok"),
    [
        ([[4, 2, 0], [2, 3, 1], [0, 1, 5]], 0, True),
        ([[1, 2], [2, 3]], 0, False),  # det −1
        ([[1, 2], [2, 4]], 0, False),  # singular PSD: not ≻ 0
        ([[0, 2], [2, 3]], 0, False),  # zero leading minor
        ([[1, fmpq(1, 2)], [fmpq(1, 2), 1]], fmpq(1, 2), False),  # eigenvalue 1/2 − 1/2 = 0
        ([[1, fmpq(1, 2)], [fmpq(1, 2), 1]], fmpq(49, 100), True),
        ([[fmpq(1, 3)]], fmpq(1, 3), False),
        ([[fmpq(1, 3)]], fmpq(1, 3) - fmpq(1, 10**30), True),
        ([[-1]], 0, False),
    ],
)
def test_known_answers(M, margin, ok) -> None:  # noqa: ANN001
    assert check_pd_fast(qmat(M), margin).ok is ok
    assert check_pd(qmat(M), margin).ok is ok


def test_asymmetric_and_empty_and_input_types() -> None:
    r = check_pd_fast(qmat([[2, 1], [0, 2]]))
    assert not r.ok and "not symmetric at (0, 1)" in r.detail
    assert check_pd_fast(np.zeros((0, 0), dtype=object)).ok
    assert check_pd_fast(fmpz_mat([[2, 1], [1, 2]])).ok
    assert check_pd_fast(fmpq_mat([[2, 1], [1, 2]]) / 7).ok
    assert check_pd_fast(np.array([[2.0, 1.0], [1.0, 2.0]])).ok
    with pytest.raises(ValueError):
        check_pd_fast(qmat([[1, 2, 3]]))


def _hilbert(n: int) -> np.ndarray:
    return qmat([[fmpq(1, i + j + 1) for j in range(n)] for i in range(n)])


def test_every_proof_path() -> None:
    """Well-conditioned: the verified float Cholesky; indefinite: the rational vector; Hilbert
    13×13 (condition ≈ 10¹⁸, PD): floats cannot, the fraction-free LDLᵀ decides."""
    rng = np.random.default_rng(0)
    B = rng.standard_normal((30, 30))
    good = qmat(B @ B.T + 30 * np.eye(30))
    r = check_pd_fast(good)
    assert r.ok and r.path == "verified-float" and "verified float Cholesky" in r.detail
    bad = qmat(B + B.T)
    r = check_pd_fast(bad)
    assert not r.ok and "vᵀMv" in r.detail
    H = _hilbert(13)
    r = check_pd_fast(H)
    assert r.ok and "fraction-free" in r.detail and r.path == "fraction-free"
    # δ = 10⁻¹⁷ lies above λ_min(H₁₃) (about 10⁻¹⁸): H − δI is not ≻ 0, the same way
    lam = fmpq(1, 10**17)
    assert not check_pd_fast(H, lam).ok and not check_pd(H, lam).ok


def test_edge_by_the_smallest_margin() -> None:
    """M = [[a, b], [b, c]] ≻ 0 iff a > 0 and ac > b²: at c = b²/a exactly it fails, one ulp
    of 10⁻⁴⁰ above it passes (both paths must see it: the float certificate cannot, so the
    exact fallback decides)."""
    a, b = fmpq(3), fmpq(5)
    edge = b * b / a
    assert not check_pd_fast(qmat([[a, b], [b, edge]])).ok
    assert check_pd_fast(qmat([[a, b], [b, edge + fmpq(1, 10**40)]])).ok
    n = 40
    rng = np.random.default_rng(1)
    V = rng.standard_normal((n, n))
    M = qmat(V @ V.T)
    # the margin just past λ_min: vᵀ(M − δI)v < 0 for some v; just below: PD
    lam = float(np.linalg.eigvalsh(np.asarray(M, dtype=float))[0])
    assert check_pd_fast(M, Q(lam * (1 - 1e-6))).ok
    assert not check_pd_fast(M, Q(lam * (1 + 1e-6))).ok


def test_certificate_cannot_pass_a_wrong_matrix(monkeypatch: pytest.MonkeyPatch) -> None:
    """A Cholesky factor of another matrix (here: of M + I, for the indefinite M) must not
    certify M: the exact S = M − RᵀR is not diagonally dominant, so the exact fallback says no."""
    M = qmat([[1, 2], [2, 1]])  # eigenvalues 3, −1
    real_eigvalsh = np.linalg.eigvalsh
    monkeypatch.setattr(np.linalg, "eigvalsh", lambda X: np.abs(real_eigvalsh(X)) + 5)
    real_chol = np.linalg.cholesky
    monkeypatch.setattr(np.linalg, "cholesky", lambda X: real_chol(np.array([[5.0, 2], [2, 5]])))
    r = check_pd_fast(M)
    assert not r.ok and "fraction-free" in r.detail


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.integers(1, 9),
    st.integers(0, 2**31 - 1),
    st.sampled_from([0, 1, -1]),
    st.integers(0, 3),
)
def test_agrees_with_check_pd(n: int, seed: int, shift: int, rank_drop: int) -> None:
    """Random rational symmetric matrices near the PD edge: V Vᵀ of low rank plus a shift of
    ±10⁻⁹ or 0: the two exact tests give the same verdict."""
    rng = np.random.default_rng(seed)
    k = max(1, n - rank_drop)
    V = rng.integers(-9, 10, size=(n, k))
    M = qmat(V @ V.T) / 7 + np.diag([fmpq(shift, 10**9)] * n).astype(object)
    M = qmat(M)
    assert check_pd_fast(M).ok == check_pd(M).ok
    margin = fmpq(1, 10**6)
    assert check_pd_fast(M, margin).ok == check_pd(M, margin).ok


def test_fast_check_wording_is_exported() -> None:
    assert "diagonally dominant" in psd.FAST_CHECK and "fraction-free" in psd.FAST_CHECK


def test_fraction_free_int_known_answers_and_edges() -> None:
    """scale·Z ≻ 0 by Sylvester's criterion: the pivots are those of scale·Z; a zero leading
    minor (a row exchange), a zero or negative pivot are refused, each naming where."""
    r = psd.fraction_free_int(fmpz_mat([[2, 1], [1, 2]]), fmpq(1, 2))
    assert r.ok and r.path == "fraction-free" and r.min_pivot == 0.75  # pivots 1, 3/4
    r = psd.fraction_free_int(fmpz_mat([[4]]), fmpq(1, 8))
    assert r.ok and r.min_pivot == 0.5
    r = psd.fraction_free_int(fmpz_mat([[2, 3], [3, 2]]))
    assert not r.ok and r.min_pivot == -2.5 and "pivot 1" in r.detail
    r = psd.fraction_free_int(fmpz_mat([[1, 1], [1, 1]]))  # singular: last pivot exactly 0
    assert not r.ok and r.min_pivot == 0.0 and "pivot 1" in r.detail
    r = psd.fraction_free_int(fmpz_mat([[0, 1], [1, 2]]))  # Δ_1 = 0: flint exchanges rows
    assert not r.ok and "leading principal minor 1 is 0" in r.detail
    r = psd.fraction_free_int(fmpz_mat([[5, 0, 0], [0, 0, 1], [0, 1, 7]]))
    assert not r.ok and "leading principal minor 2 is 0" in r.detail
    assert not psd.fraction_free_int(fmpz_mat([[-1]])).ok
    assert psd.fraction_free_int(fmpz_mat(0, 0, [])).ok
    # the smallest false margin: diag(3, 5) − 3·I has a zero pivot; 1 below it is ≻ 0
    assert not psd.fraction_free_int(fmpz_mat([[0, 0], [0, 2]])).ok
    assert psd.fraction_free_int(fmpz_mat([[1, 0], [0, 3]])).ok


def test_fflu_cheap_by_size_and_entries() -> None:
    """The speed choice: small n with short entries yes; long diagonal entries or n beyond
    FFLU_FIRST_MAX_N no."""
    assert psd.fflu_cheap(fmpz_mat(2, 2, [2, 1, 1, 2]))
    assert psd.fflu_cheap(fmpz_mat(8, 8, [(2**300 if i % 9 == 0 else 1) for i in range(64)]))
    assert not psd.fflu_cheap(fmpz_mat(8, 8, [(2**1000 if i % 9 == 0 else 1) for i in range(64)]))
    n = psd.FFLU_FIRST_MAX_N + 1
    assert not psd.fflu_cheap(fmpz_mat(n, n, [int(i % (n + 1) == 0) for i in range(n * n)]))
    n = psd.FFLU_FIRST_MAX_N  # the largest size still taken
    assert psd.fflu_cheap(fmpz_mat(n, n, [int(i % (n + 1) == 0) for i in range(n * n)]))
    assert psd.fflu_cheap(fmpz_mat(0, 0, []))
    # n⁴ × bits exactly at the bound (10⁴ × 130 = 1.3·10⁶) is taken, one bit more is not
    assert psd.FFLU_FIRST_COST == 1_300_000
    assert psd.fflu_cheap(fmpz_mat(10, 10, [(2**129 if i % 11 == 0 else 0) for i in range(100)]))
    assert not psd.fflu_cheap(
        fmpz_mat(10, 10, [(2**130 if i % 11 == 0 else 0) for i in range(100)])
    )


def test_check_text_of_an_unknown_path_lists_every_test() -> None:
    assert psd.check_text(psd.PSDResult(True, 1.0, "", "no-such-path")) == psd.FAST_CHECK


def test_every_lower_bound_in_a_detail_is_rounded_down() -> None:
    """A detail's "λ_min ≥ x" / "min ≥ x" never shows x above the exact bound: `.3g` of the
    float below λ_min = 0.9999998 printed "λ_min ≥ 1" on a shipped spec (rendering trial,
    session 27). Each case sits just below a 3-digit decimal, the smallest false margin of
    round-to-nearest."""
    from obsdesign.certify import vchol
    from obsdesign.certify.printing import fmt_down

    just_below = fmpq(9999999, 10**7)  # shown as "1" by `.3g`
    r = psd.diag_dominant_int(fmpz_mat([[3, 1], [1, 3]]), just_below / 2)  # bound = slack·c
    assert r is not None and "λ_min ≥ 0.999 > 0" in r.detail
    r = psd.check_pd([[just_below, 0], [0, 2]])
    assert r.ok and r.detail.endswith("(min ≥ 0.999)")
    r = psd.fraction_free_int(fmpz_mat([[9999999, 0], [0, 10**7]]), fmpq(1, 10**7))
    assert r.ok and r.detail.endswith("(min pivot ≥ 0.999)")
    v = vchol.VCholResult(just_below, 0.5, 2)
    assert "λ_min(M − δI) ≥ 0.999 > 0" in v.detail
    assert fmt_down(just_below, 3) == "0.999"


def test_diag_dominant_int_proves_only_strict_dominance() -> None:
    """Gershgorin over Z: strict dominance with positive diagonal proves scale·Z ≻ 0 with
    λ_min ≥ scale·min slack; a row exactly balanced (the smallest false margin), a
    non-positive diagonal or an empty matrix give no conclusion."""
    r = psd.diag_dominant_int(fmpz_mat([[5, -2], [-2, 4]]), fmpq(1, 2))
    assert r is not None and r.ok and r.path == "diagonal-dominance" and r.min_pivot == 1.0
    assert "by Gershgorin" in r.detail and "λ_min ≥ 1 " in r.detail
    r = psd.diag_dominant_int(fmpz_mat([[4, -2], [-2, 5]]), fmpq(1, 2))  # the smallest slack
    assert r is not None and r.min_pivot == 1.0  # is row 0's, not the last row's
    assert psd.diag_dominant_int(fmpz_mat([[2, -2], [-2, 4]])) is None  # row 0 balanced
    assert psd.diag_dominant_int(fmpz_mat([[3, -2], [-2, 3]])) is not None
    assert psd.diag_dominant_int(fmpz_mat([[-3, 1], [1, 3]])) is None
    assert psd.diag_dominant_int(fmpz_mat([[0]])) is None
    assert psd.diag_dominant_int(fmpz_mat(0, 0, [])) is None
    assert psd.diag_dominant_int(fmpz_mat([[2, 1, 1], [1, 2, 1], [1, 1, 2]])) is None  # ≻ 0


@settings(max_examples=80, deadline=None)
@given(n=st.integers(1, 6), seed=st.integers(0, 10**6))
def test_diag_dominant_int_agrees_with_check_pd(n: int, seed: int) -> None:
    """Whenever diagonal dominance proves a random symmetric integer matrix ≻ 0, the exact
    LDLᵀ agrees, and the bound is below its smallest eigenvalue (M − bound·I ⪰ 0 is not
    contradicted: M − 2·bound·I may fail, M − bound·I/2 must hold)."""
    rng = np.random.default_rng(seed)
    B = rng.integers(-5, 6, (n, n))
    S = B + B.T
    S[np.diag_indices(n)] = np.abs(S).sum(axis=1) - np.abs(np.diag(S)) + rng.integers(-2, 3, n)
    Z = fmpz_mat([[int(v) for v in row] for row in S])
    r = psd.diag_dominant_int(Z)
    M = qmat(S.tolist())
    if r is not None:
        assert check_pd(M).ok
        assert check_psd(M, Q(r.min_pivot)).ok  # the bound shown is ≤ λ_min


def test_integer_tests_refuse_their_premises_broken() -> None:
    """A non-symmetric Z or a scale ≤ 0 is a caller's error (ValueError), never a verdict:
    [[1, 3], [0, 1]] has an indefinite symmetric part, and −1·[[1]] is not ≻ 0, yet the
    unguarded tests said "≻ 0" (session-17 review)."""
    for f in (psd.fraction_free_int, psd.diag_dominant_int):
        with pytest.raises(ValueError, match="symmetric"):
            f(fmpz_mat([[1, 3], [0, 1]]))
        for bad in (-1, 0):
            with pytest.raises(ValueError, match="positive"):
                f(fmpz_mat([[1]]), bad)


def test_diag_dominance_bound_is_shown_at_or_below_the_exact_one() -> None:
    """λ_min = 9/7 exactly, and the bound is tight: the float shown is ≤ 9/7 (the nearest
    float lies above it)."""
    r = psd.diag_dominant_int(fmpz_mat([[3, 0], [0, 3]]), fmpq(3, 7))
    assert r is not None and Q(r.min_pivot) <= fmpq(9, 7)
    assert float(fmpq(9, 7)) > r.min_pivot  # one step below the nearest


@pytest.mark.parametrize("scale_bits", [0, 60, 120, 200])
def test_the_cholesky_certificate_holds_at_any_scale(scale_bits: int) -> None:
    """[[1, 3/2], [3/2, 3]] (PD, not diagonally dominant) times 2^s: the certificate
    F = RᵀR + S needs RᵀR subtracted at its true scale, 2^(−2k); for entries above 2¹⁰⁴ the
    float factor's shift k is negative, a branch no test reached (the mutant 2^(−k) there
    went unnoticed; mutation review, session 40). S = F − RᵀR must come out dominant at every
    scale; the mutant leaves S ≈ F, not dominant, and finds no proof."""
    s = fmpq(2) ** scale_bits
    M = qmat([[1, fmpq(3, 2)], [fmpq(3, 2), 3]]) * s
    F = fmpq_mat(2, 2, list(M.flat))
    Mf = np.array([[float(x) for x in row] for row in M], dtype=float)
    r = psd._gershgorin_certificate(F, Mf)
    assert r is not None and r.ok and r.detail.startswith("M = RᵀR + S")


def test_the_integer_tests_refuse_a_rational_matrix() -> None:
    """check_pd_int and diag_dominant_int truncated an fmpq_mat's entries: [[2, 29/10],
    [29/10, 4]] (determinant −41/100) was "≻ 0" as [[2, 2], [2, 4]], and I + (99/100)·S with
    λ_min = −0.98 was "diagonally dominant" (primitives review, session 43). A TypeError."""
    from flint import fmpq_mat

    bad = fmpq_mat([[2, fmpq(29, 10)], [fmpq(29, 10), 4]])
    for f in (psd.check_pd_int, psd.diag_dominant_int, psd.fraction_free_int):
        with pytest.raises(TypeError, match="fmpz_mat"):
            f(bad)
