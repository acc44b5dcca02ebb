"""Exact PD/PSD tests (obsdesign.certify.psd): a known-answer table and negative cases.

Every case has an answer known exactly (by hand: determinants, eigenvalues of small rational
matrices); the table includes the broken-certificate cases of issue 15 (zero pivot with a
nonzero off-diagonal, the skipped elimination, float input, asymmetry) and margins exactly at
the boundary of definiteness.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from flint import fmpq, fmpq_mat
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.certify.exact import qeye, qmat
from obsdesign.certify.psd import (
    FAST_CHECK,
    PSDResult,
    _fraction_free,
    _gershgorin_certificate,
    check_pd,
    check_pd_fast,
    check_psd,
    check_text,
    ldl_pivots,
    to_fmpq_mat,
)

F = fmpq
THIRD_FLOAT = 1 / 3  # 0.333…3148 < 1/3 exactly

# (name, matrix, psd, pd): exact answers.
TABLE = [
    ("zero-diag-swap [[0,1],[1,0]] (eigenvalues ±1)", [[0, 1], [1, 0]], False, False),
    ("zero first pivot, coupling [[0,1],[1,5]] (det -1)", [[0, 1], [1, 5]], False, False),
    ("needs elimination [[2,2],[2,1]] (det -2)", [[2, 2], [2, 1]], False, False),
    ("needs elimination [[1,2],[2,1]] (det -3)", [[1, 2], [2, 1]], False, False),
    (
        "float input [[3.0,1.0],[1.0,fl(1/3)]] (det = 3 fl(1/3) - 1 < 0)",
        [[3.0, 1.0], [1.0, THIRD_FLOAT]],
        False,
        False,
    ),
    ("exact [[3,1],[1,1/3]] (singular PSD)", [[3, 1], [1, F(1, 3)]], True, False),
    ("singular 3x3 [[1,1,0],[1,1,0],[0,0,2]]", [[1, 1, 0], [1, 1, 0], [0, 0, 2]], True, False),
    ("zero after one step, coupled rest (det -1)", [[1, 1, 1], [1, 1, 0], [1, 0, 1]], False, False),
    ("rank one [[1,2],[2,4]]", [[1, 2], [2, 4]], True, False),
    ("rank one [[4,2],[2,1]]", [[4, 2], [2, 1]], True, False),
    ("zero 2x2", [[0, 0], [0, 0]], True, False),
    ("[[0]]", [[0]], True, False),
    ("[[-1]]", [[-1]], False, False),
    ("[[1]]", [[1]], True, True),
    ("[[0,0],[0,1]] (PSD, zero leading pivot)", [[0, 0], [0, 1]], True, False),
    ("[[1,0],[0,0]]", [[1, 0], [0, 0]], True, False),
    ("[[1,0],[0,-1/10^30]]", [[1, 0], [0, F(-1, 10**30)]], False, False),
    # the largest diagonal 0 and a negative one after it (the zero-pivot branch must look at
    # the diagonal too: Q_n = diag(0, 1) was certified ⪯ 0 under a mutant; review 40)
    ("diag(0, -1) (largest pivot 0)", [[0, 0], [0, -1]], False, False),
    ("diag(-1, 0, 0)", [[-1, 0, 0], [0, 0, 0], [0, 0, 0]], False, False),
    ("[[2,1],[1,2]] (eigenvalues 1, 3)", [[2, 1], [1, 2]], True, True),
    ("[[4,2,2],[2,5,1],[2,1,6]]", [[4, 2, 2], [2, 5, 1], [2, 1, 6]], True, True),
    ("[[1,1],[1,1+2^-60]] (PD, float-singular)", [[1, 1], [1, 1 + F(1, 2**60)]], True, True),
    ("[[1,1],[1,1-2^-60]] (indefinite)", [[1, 1], [1, 1 - F(1, 2**60)]], False, False),
    ("diag(2, 0, 3) singular", [[2, 0, 0], [0, 0, 0], [0, 0, 3]], True, False),
    ("diag(3, -1/7, 2)", [[3, 0, 0], [0, F(-1, 7), 0], [0, 0, 2]], False, False),
    # det = 5x - 7 with leading minors 3, 5: x = 7/5 is singular PSD of rank 2
    (
        "rank 2 [[3,1,1],[1,2,-1],[1,-1,7/5]]",
        [[3, 1, 1], [1, 2, -1], [1, -1, F(7, 5)]],
        True,
        False,
    ),
    (
        "negative only after elimination [[1,1,0],[1,2,1],[0,1,1/2]] (det -1/2)",
        [[1, 1, 0], [1, 2, 1], [0, 1, F(1, 2)]],
        False,
        False,
    ),
]


def _det(M: np.ndarray) -> fmpq:
    from flint import fmpq_mat

    n = M.shape[0]
    return fmpq_mat(n, n, list(M.flat)).det()


@pytest.mark.parametrize(("name", "M", "psd", "pd"), TABLE, ids=[t[0] for t in TABLE])
def test_known_answers(name: str, M: list, psd: bool, pd: bool):
    r_psd, r_pd = check_psd(M), check_pd(M)
    assert r_psd.ok is psd, (name, r_psd)
    assert r_pd.ok is pd, (name, r_pd)
    assert bool(r_psd) is psd and bool(r_pd) is pd
    # the same answers for the exact transpose-symmetric input given as fmpq
    Mq = qmat(M)
    assert check_psd(Mq).ok is psd and check_pd(Mq).ok is pd
    # the fast test, and each of its two proofs on its own, give the same exact verdict
    assert check_pd_fast(M).ok is pd and check_pd_fast(Mq).ok is pd
    Fm = to_fmpq_mat(Mq)
    assert _fraction_free(Fm).ok is pd
    g = _gershgorin_certificate(Fm, np.array(Mq.tolist(), dtype=float))
    assert g is None or g.ok is pd
    # and an independent exact oracle: the leading minors / all principal minors
    assert _pd_by_minors(Mq) is pd
    assert _psd_by_principal_minors(Mq) is psd


def _pd_by_minors(M: np.ndarray) -> bool:
    n = M.shape[0]
    return all(_det(M[:k, :k]) > 0 for k in range(1, n + 1))


def _psd_by_principal_minors(M: np.ndarray) -> bool:
    from itertools import combinations

    n = M.shape[0]
    for k in range(1, n + 1):
        for S in combinations(range(n), k):
            if _det(M[np.ix_(S, S)]) < 0:
                return False
    return True


def test_details_and_pivots():
    r = check_psd([[0, 1], [1, 0]])
    assert r == PSDResult(False, 0.0, "zero pivot with a nonzero off-diagonal entry")
    r = check_psd([[2, 2], [2, 1]])
    assert r.min_pivot == -1.0
    assert r.detail == "negative diagonal -1 after elimination"
    r = check_psd([[1, 1, 0], [1, 1, 0], [0, 0, 2]])
    assert r == PSDResult(True, 0.0, "PSD, rank 2")
    assert check_psd([[0, 0], [0, 0]]).detail == "PSD, rank 0"
    r = check_psd([[2, 0], [0, 3]])
    assert r == PSDResult(True, 2.0, "PSD (full rank)")
    r = check_psd([[5, 0, 0], [0, 3, 0], [0, 0, 4]])
    assert r.min_pivot == 3.0 and r.ok
    r = check_psd(np.empty((0, 0), dtype=object))
    assert r == PSDResult(True, 0.0, "PSD (full rank)")
    r = check_pd(np.empty((0, 0), dtype=object))
    assert r == PSDResult(True, float("inf"), "empty matrix")
    r = check_pd([[2, 1], [1, 2]])
    assert r == PSDResult(True, 1.5, "all 2 LDLᵀ pivots > 0 (min ≥ 1.5)")
    r = check_pd([[1, 0, 0], [0, 1, 0], [0, 0, 0]])
    assert r == PSDResult(False, 0.0, "LDLᵀ pivot 2 = 0 <= 0")
    r = check_pd([[1, 2], [2, 1]])
    assert r == PSDResult(False, -3.0, "LDLᵀ pivot 1 = -3 <= 0")
    r = check_pd([[-2]])
    assert r == PSDResult(False, -2.0, "LDLᵀ pivot 0 = -2 <= 0")


def test_ldl_pivots_exact():
    assert ldl_pivots([[2, 1], [1, 2]]) == [F(2), F(3, 2)]
    assert ldl_pivots([[4, 2, 2], [2, 5, 1], [2, 1, 6]]) == [F(4), F(4), F(5)]
    # stops at the first non-positive pivot (no division by zero)
    assert ldl_pivots([[0, 1], [1, 0]]) == [F(0)]
    assert ldl_pivots([[1, 1, 5], [1, 1, 2], [5, 2, 9]]) == [F(1), F(0)]
    assert ldl_pivots([[1, 2], [2, 1]]) == [F(1), F(-3)]
    # [[2,2],[2,1]]: the elimination step cannot be skipped
    assert ldl_pivots([[2, 2], [2, 1]]) == [F(2), F(-1)]
    # a zero in column k must not stop the update of later columns
    assert ldl_pivots([[1, 0, 1], [0, 1, 1], [1, 1, 3]]) == [F(1), F(1), F(1)]
    assert ldl_pivots([[2, 0, 2], [0, 1, 0], [2, 0, 3]]) == [F(2), F(1), F(1)]
    assert ldl_pivots(np.empty((0, 0), dtype=object)) == []


@pytest.mark.parametrize("check", [check_psd, check_pd])
def test_asymmetric_rejected(check):
    for M in ([[2, 1], [0, 2]], [[2, 0], [1, 2]], [[1, 0, 0], [0, 1, 0], [0, F(1, 10**40), 1]]):
        r = check(M)
        assert not r.ok and "not symmetric" in r.detail, r
        assert np.isnan(r.min_pivot)
    r = check([[1, 0, 0], [0, 1, 2], [0, 3, 1]])
    assert r.detail == "not symmetric at (1, 2)"
    r = check([[1, 5, 0], [6, 1, 2], [0, 2, 1]])
    assert r.detail == "not symmetric at (0, 1)"
    # float asymmetry below float resolution of the entries is still asymmetry
    r = check([[1.0, 0.1], [0.1 + 2**-56, 1.0]])
    assert not r.ok


@pytest.mark.parametrize("check", [check_psd, check_pd])
def test_not_square(check):
    with pytest.raises(ValueError, match=r"^expected a square matrix$"):
        check([[1, 2, 3], [4, 5, 6]])
    with pytest.raises(ValueError, match=r"^expected a square matrix$"):
        check([1, 2])
    with pytest.raises(ValueError, match=r"^expected a square matrix$"):
        ldl_pivots([[1, 2]])


def test_float_input_is_decided_exactly():
    M = [[3.0, 1.0], [1.0, THIRD_FLOAT]]
    assert not check_psd(M).ok
    assert not check_psd(np.array(M)).ok
    assert not check_pd(np.array(M)).ok
    assert ldl_pivots(np.array(M))[-1] < 0
    # mixed: first entry exact, the rest float
    Mix = [[F(3), 1.0], [1.0, THIRD_FLOAT]]
    assert not check_psd(Mix).ok and not check_pd(Mix).ok
    # Fractions, strings and numpy integers are converted exactly as well
    assert check_psd([[Fraction(3), 1], [1, Fraction(1, 3)]]).ok
    assert check_psd([["3", "1"], ["1", "1/3"]]).ok
    assert not check_pd([["3", "1"], ["1", "1/3"]]).ok
    assert check_pd(np.array([[2, 1], [1, 2]], dtype=np.int64)).ok
    assert ldl_pivots([["3", "1"], ["1", "1/3"]]) == [F(3), F(0)]


def test_margins_at_the_boundary():
    M = qmat([[2, 1], [1, 2]])  # eigenvalues 1 and 3
    assert check_psd(M, 1).ok  # M - I = [[1,1],[1,1]] singular PSD
    assert not check_pd(M, 1).ok
    tiny = F(1, 2**80)
    assert not check_psd(M, 1 + tiny).ok  # the smallest false δ region starts right above 1
    assert check_pd(M, 1 - tiny).ok
    assert check_psd(M, 1 - tiny).ok
    assert not check_pd(M, 1 + tiny).ok
    assert check_psd(M, F(-5)).ok and check_pd(M, -5).ok
    assert check_psd(M, "1").ok and not check_psd(M, "1.0000000001").ok
    assert check_pd(M, 0.5).ok and check_pd(M, "0.999").ok
    # margin 1 on I: 0 is PSD, not PD; on I/2: indefinite
    assert check_psd(qeye(3), 1).ok and not check_pd(qeye(3), 1).ok
    assert not check_psd(qeye(3) * F(1, 2), 1).ok
    assert not check_pd(qeye(3) * F(1, 2), 1).ok
    assert check_pd(qeye(4)).ok and check_pd(qeye(4), F(1, 2)).ok
    # rational eigenvalue 1/3 of [[2/3, 1/3],[1/3, 2/3]] (eigenvalues 1/3, 1)
    N = qmat([[F(2, 3), F(1, 3)], [F(1, 3), F(2, 3)]])
    assert check_psd(N, F(1, 3)).ok and not check_pd(N, F(1, 3)).ok
    assert not check_psd(N, F(1, 3) + F(1, 10**50)).ok
    # 1x1 with margin 1: the margin must be subtracted
    assert not check_psd([[F(1, 2)]], 1).ok and not check_pd([[F(1, 2)]], 1).ok
    assert check_psd([[1]], 1).ok and not check_pd([[1]], 1).ok


def test_singular_psd_is_psd_not_pd():
    M = qmat([[1, 1, 0], [1, 1, 0], [0, 0, 2]])
    assert check_psd(M).ok
    assert not check_pd(M).ok


def test_badly_scaled_20x20():
    rng = np.random.default_rng(1)
    B = rng.standard_normal((20, 20))
    S = np.diag(10.0 ** np.linspace(-6, 6, 20))
    M = S @ (B @ B.T + 1e-3 * np.eye(20)) @ S
    Mq = qmat(M)  # every float exactly
    Mq = (Mq + Mq.T) * fmpq(1, 2)
    assert check_pd(Mq).ok and check_psd(Mq).ok
    piv = ldl_pivots(Mq)
    assert all(p > 0 for p in piv)
    bad = Mq.copy()
    bad[19, 19] -= piv[-1] * 2
    assert not check_pd(bad).ok and not check_psd(bad).ok
    edge = Mq.copy()
    edge[19, 19] -= piv[-1]  # exactly singular now
    assert check_psd(edge).ok and not check_pd(edge).ok


def test_exactness_beats_floats():
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
        ev = np.linalg.eigvalsh(np.asarray(N, dtype=float))
        assert check_psd(N).ok == bool(ev.min() >= -1e-9)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 5), st.integers(1, 5), st.integers(0, 2**31 - 1))
def test_random_low_rank_against_minors(n: int, r: int, seed: int):
    """Low-rank Gram matrices minus a tiny shift: compare with the exact principal-minor test."""
    rng = np.random.default_rng(seed)
    B = qmat(rng.integers(-3, 4, size=(n, r)))
    M = B @ B.T
    assert check_psd(M).ok and _psd_by_principal_minors(M)
    shift = F(int(rng.integers(-2, 3)), 7)
    N = M - qeye(n) * shift
    assert check_psd(N).ok is _psd_by_principal_minors(N)
    assert check_pd(N).ok is _pd_by_minors(N)


# ------------------------------------------------------------ check_pd_fast (issue 12)


def test_pd_fast_paths_and_details():
    r = check_pd_fast([[2, 1], [1, 2]])
    assert r.ok and r.path == "verified-float" and 0 < r.min_pivot < 1e-12
    assert r.detail.startswith("verified float Cholesky: λ_min(M − δI) ≥ ")
    assert check_text(r).startswith("verified floating-point Cholesky")
    # the float-guided certificate behind it (when the verified float test cannot decide)
    Fm = fmpq_mat([[2, 1], [1, 2]])
    g = _gershgorin_certificate(Fm, np.array([[2.0, 1.0], [1.0, 2.0]]))
    assert g is not None and g.ok and g.min_pivot == 1.0 and g.path == "gershgorin"
    assert g.detail == (
        "M = RᵀR + S with S strictly diagonally dominant (exact), n = 2; float λ_min ≈ 1"
    )
    assert "diagonally dominant" in check_text(g)
    r = check_pd_fast([[1, 2], [2, 1]])
    assert r == PSDResult(
        False, -1.0, "vᵀMv = -1 <= 0 for a rational v (float eigenvector, checked exactly)"
    )
    # entries beyond the float range: the exact fraction-free path decides
    big = F(10) ** 400
    r = check_pd_fast([[big, 0], [0, 1]])
    assert r == PSDResult(
        True, 1.0, "fraction-free LDLᵀ: all 2 leading principal minors > 0 (min pivot ≥ 1)"
    )
    r = check_pd_fast([[big, 0], [0, -1]])
    assert r == PSDResult(False, -1.0, "fraction-free LDLᵀ: pivot 1 = -1 <= 0 (leading minor ≤ 0)")
    r = check_pd_fast([[0, 1], [1, big]])
    assert r == PSDResult(False, 0.0, "leading principal minor 1 is 0 (fraction-free LDLᵀ)")
    r = check_pd_fast([[big, 1, 0], [1, 1, 0], [0, 0, -3]])
    assert not r.ok and r.detail.startswith("fraction-free LDLᵀ: pivot 2 = -3 <= 0")
    # PD by a margin of 2^-60 only: no float certificate, the exact path decides
    r = check_pd_fast([[1, 1], [1, 1 + F(1, 2**60)]])
    assert r.ok and r.detail.startswith("fraction-free LDLᵀ: all 2 leading principal minors > 0")
    assert r.min_pivot == float(F(1, 2**60))
    assert "fraction-free" in FAST_CHECK and "diagonally dominant" in FAST_CHECK
    assert "verified floating-point Cholesky" in FAST_CHECK and r.path == "fraction-free"


def test_pd_fast_inputs_margins_and_errors():
    from flint import fmpq_mat, fmpz_mat

    M = [[2, 1], [1, 2]]
    assert check_pd_fast(fmpz_mat(M)).ok and check_pd_fast(fmpq_mat(M)).ok
    assert to_fmpq_mat(fmpq_mat(M)) == fmpq_mat(M)
    assert to_fmpq_mat(fmpz_mat(M)) == fmpq_mat(M)
    assert to_fmpq_mat([[0.1]])[0, 0] == Fraction(0.1).numerator / F(Fraction(0.1).denominator)
    with pytest.raises(ValueError, match=r"^expected a matrix$"):
        to_fmpq_mat([1, 2])
    with pytest.raises(ValueError, match=r"^expected a square matrix$"):
        check_pd_fast([[1, 2, 3], [4, 5, 6]])
    r = check_pd_fast([[1, 0, 0], [0, 1, 2], [0, 3, 1]])
    assert r.detail == "not symmetric at (1, 2)" and not r.ok and np.isnan(r.min_pivot)
    assert not check_pd_fast([[2, 1], [0, 2]]).ok
    assert check_pd_fast(np.empty((0, 0), dtype=object)) == PSDResult(
        True, float("inf"), "empty matrix"
    )
    # margins exactly at the boundary (eigenvalues 1 and 3)
    assert not check_pd_fast(M, 1).ok
    assert check_pd_fast(M, 1 - F(1, 2**80)).ok
    assert not check_pd_fast(M, 1 + F(1, 2**80)).ok
    assert check_pd_fast(M, "1/2").ok and not check_pd_fast(M, 3).ok
    assert not check_pd_fast([[F(1, 2)]], 1).ok and check_pd_fast([[2]], 1).ok
    # float input decided exactly
    assert not check_pd_fast([[3.0, 1.0], [1.0, THIRD_FLOAT]]).ok
    with pytest.raises(ValueError, match=r"^not a finite number: inf$"):
        check_pd_fast([[np.inf, 0.0], [0.0, 1.0]])


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 12), st.integers(0, 2**31 - 1), st.integers(-3, 3))
def test_pd_fast_agrees_with_ldl(n: int, seed: int, shift: int):
    rng = np.random.default_rng(seed)
    r = int(rng.integers(1, n + 1))
    B = qmat(rng.integers(-3, 4, size=(n, r)))
    M = B @ B.T - qeye(n) * F(shift, 5)  # often singular or nearly so
    assert check_pd_fast(M).ok is check_pd(M).ok


def test_pd_fast_large():
    rng = np.random.default_rng(7)
    n = 60
    B = rng.standard_normal((n, n))
    M = qmat(B @ B.T + np.eye(n))
    M = (M + M.T) * F(1, 2)
    r = check_pd_fast(M)
    assert r.ok and r.path == "verified-float"
    g = _gershgorin_certificate(to_fmpq_mat(M), np.asarray(M, dtype=float))
    assert g is not None and g.ok and g.detail.startswith("M = RᵀR + S")
    bad = M.copy()
    bad[0, 0] = -F(1)
    assert not check_pd_fast(bad).ok


def test_negative_direction_never_proves_a_positive_definite_matrix_not_pd() -> None:
    """negative_direction is a proof of F ⊁ 0 guided by a float matrix: a lying guide (a
    negative eigenvalue where F is PD), or F PD by the smallest margin, gives None; a
    singular PSD F (vᵀFv = 0 exactly) is shown not PD."""
    from flint import fmpq, fmpq_mat

    from obsdesign.certify.psd import negative_direction

    F = fmpq_mat(2, 2, [2, 1, 1, 2])
    assert negative_direction(F, np.array([[1.0, 0.0], [0.0, -1.0]])) is None
    assert negative_direction(F, np.array([[2.0, 1.0], [1.0, 2.0]])) is None
    tiny = fmpq(1, 2**60)  # det = tiny > 0: PD by the smallest margin in reach of floats
    G = fmpq_mat(2, 2, [1, 1, 1, 1 + tiny])
    assert negative_direction(G, np.array([[1.0, 1.0], [1.0, 1.0]])) is None
    S = fmpq_mat(2, 2, [1, 1, 1, 1])
    r = negative_direction(S, np.array([[1.0, 1.0], [1.0, 1.0]]))
    assert r is not None and not r.ok


@given(st.lists(st.integers(-50, 50), min_size=9, max_size=9), st.integers(1, 10**6))
def test_negative_direction_with_random_guides_on_pd_matrices(entries: list[int], k: int) -> None:
    """F = BᵀB + I/k is PD; whatever float guide is given (here −F and a random symmetric
    matrix), negative_direction must not claim F ⊁ 0."""
    from flint import fmpq, fmpq_mat

    from obsdesign.certify.psd import negative_direction

    B = fmpq_mat(3, 3, entries)
    F = B.transpose() * B + fmpq_mat(3, 3, [fmpq(1, k) if i % 4 == 0 else 0 for i in range(9)])
    Ff = np.array([[float(F[i, j]) for j in range(3)] for i in range(3)])
    R = np.array(entries, dtype=float).reshape(3, 3)
    for guide in (-Ff, R + R.T):
        assert negative_direction(F, guide) is None


def test_asymmetric_names_the_matrix_and_the_entry() -> None:
    """psd.asymmetric: None for an exactly symmetric square matrix; a failed result naming the
    matrix and the first asymmetric entry for 2⁻¹⁰⁰ off (the smallest false margin at this
    size); a non-square matrix fails too."""
    from obsdesign.certify.psd import asymmetric

    S = qmat([[2, 1], [1, 3]])
    assert asymmetric(S, "P") is None
    T = S.copy()
    T[1, 0] = T[1, 0] + fmpq(1, 2**100)
    r = asymmetric(T, "P")
    assert r is not None and not r.ok and r.detail == "P is not symmetric at (0, 1)"
    r = asymmetric(qmat([[1, 2, 3], [2, 1, 0]]), "Q")
    assert r is not None and not r.ok and "Q is not a square matrix" in r.detail


def test_asymmetric_takes_a_flint_matrix() -> None:
    """The fmpq_mat path (flint's own comparison) decides as the array path: symmetric is
    None, one entry 2⁻¹⁰⁰ off fails at that entry."""
    from obsdesign.certify.psd import asymmetric

    S = fmpq_mat([[2, 1], [1, 3]])
    assert asymmetric(S, "P") is None
    T = fmpq_mat([[2, 1], [fmpq(1) + fmpq(1, 2**100), 3]])
    r = asymmetric(T, "P")
    assert r is not None and not r.ok and r.detail == "P is not symmetric at (0, 1)"


def test_a_negative_diagonal_behind_a_zero_pivot_is_named_as_such() -> None:
    """diag(0, −1): the message said "zero pivot with a nonzero off-diagonal entry" though
    the offending entry is the diagonal −1 (mutation review, session 40)."""
    r = check_psd([[0, 0], [0, -1]])
    assert not r.ok and "negative diagonal -1" in r.detail and "off-diagonal" not in r.detail
    r = check_psd([[0, 1], [1, 0]])
    assert not r.ok and "off-diagonal" in r.detail
