"""obsdesign.riccati: the doubling (SDA) solution of the discrete algebraic Riccati equation
agrees with scipy's on random stabilizable/detectable problems, is the stabilizing one, and
hands over to scipy whenever its own checks fail (Q = 0 with an unstable A: SDA cannot leave
H = 0; a non-stabilizable pair: scipy's error passes through)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign import riccati


def _problem(seed: int, n: int, m: int, scale: float) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n)) * scale
    B = rng.standard_normal((n, m))
    Qh = rng.standard_normal((n, n))
    Rh = rng.standard_normal((m, m))
    return A, B, Qh @ Qh.T + 0.01 * np.eye(n), Rh @ Rh.T + 0.1 * np.eye(m)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 9),
    m=st.integers(1, 4),
    scale=st.sampled_from([0.3, 1.0, 1.5]),
)
def test_sda_matches_scipy_and_stabilizes(seed: int, n: int, m: int, scale: float) -> None:
    """Where SDA answers, its X is scipy's to 10⁻⁷ relative (scipy's own error on these
    problems), meets the residual bound, and its gain makes A − BK Schur."""
    A, B, Q, R = _problem(seed, n, min(m, n), scale)
    with np.errstate(all="ignore"):
        X = riccati.dare_sda(A, B, Q, R)
    Xs = sl.solve_discrete_are(A, B, Q, R)
    if X is None:  # allowed (scipy is then used); must be rare on these well-posed problems
        return
    assert riccati.dare_residual(A, B, Q, R, X) <= riccati.RESIDUAL_TOL
    assert np.abs(X - Xs).max() <= 1e-7 * max(1.0, np.abs(Xs).max())
    K = np.linalg.solve(R + B.T @ X @ B, B.T @ X @ A)
    assert np.abs(np.linalg.eigvals(A - B @ K)).max() < 1.0


def test_sda_answers_the_benchmark_kind_of_problem() -> None:
    """The observer problem of the benchmarks (dual pair of a stable-ish 30-state plant):
    SDA answers (no fallback) and agrees with scipy to 10⁻¹²."""
    rng = np.random.default_rng(7)
    A = rng.standard_normal((30, 30))
    A *= 0.95 / np.abs(np.linalg.eigvals(A)).max()
    C = rng.standard_normal((3, 30))
    X, name = riccati.solve_dare(A.T, C.T, np.eye(30), np.eye(3))
    assert name == riccati.SDA_NAME
    Xs = sl.solve_discrete_are(A.T, C.T, np.eye(30), np.eye(3))
    assert np.abs(X - Xs).max() <= 1e-12 * np.abs(Xs).max()


def test_q_zero_with_unstable_a_falls_back_to_scipy() -> None:
    """Q = 0: H stays 0 in SDA, which is the stabilizing solution only for a Schur A. For an
    unstable A the check Aₖ → 0 fails and scipy answers (X ≠ 0)."""
    A = np.array([[1.5, 1.0], [0.0, 0.5]])
    B = np.array([[0.0], [1.0]])
    Q = np.zeros((2, 2))
    R = np.eye(1)
    with np.errstate(all="ignore"):
        assert riccati.dare_sda(A, B, Q, R) is None
    X, name = riccati.solve_dare(A, B, Q, R)
    assert name == riccati.SCIPY_NAME
    assert np.abs(X).max() > 0.1
    assert riccati.dare_residual(A, B, Q, R, X) < 1e-8


def test_q_zero_with_schur_a_is_zero_or_scipy() -> None:
    """Q = 0 and A Schur: X = 0 is the stabilizing solution; whichever solver answers gives it."""
    A = np.array([[0.5, 0.2], [0.0, 0.3]])
    X, _ = riccati.solve_dare(A, np.eye(2), np.zeros((2, 2)), np.eye(2))
    assert np.abs(X).max() <= 1e-12


def test_not_stabilizable_raises_through_scipy() -> None:
    """An unstable mode B cannot reach: SDA fails its checks, scipy's error passes through."""
    A = np.diag([2.0, 0.5])
    B = np.array([[0.0], [1.0]])
    with pytest.raises((np.linalg.LinAlgError, ValueError)):
        riccati.solve_dare(A, B, np.eye(2), np.eye(1))


def test_residual_is_relative_to_the_terms() -> None:
    """The exact solution of a scalar DARE has residual ~ rounding; a perturbed one does not;
    all-zero terms give 0."""
    a, b, q, r = 2.0, 1.0, 1.0, 1.0
    # x = a²x − a²b²x²/(r + b²x) + q  ⇔  x² − 4x − 1 = 0 for these values: x = 2 + √5
    x = 2.0 + np.sqrt(5.0)
    A, B, Q, R = (np.array([[v]]) for v in (a, b, q, r))
    assert riccati.dare_residual(A, B, Q, R, np.array([[x]])) < 1e-15
    assert riccati.dare_residual(A, B, Q, R, np.array([[x * (1 + 1e-6)]])) > 1e-8
    Z = np.zeros((1, 1))
    assert riccati.dare_residual(Z, B, Z, R, Z) == 0.0


def test_a_wrong_solution_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    """The residual check must refuse a converged-looking but wrong answer: with the residual
    tolerance tightened below rounding, SDA's answer is refused and scipy answers."""
    A, B, Q, R = _problem(3, 4, 2, 0.5)
    monkeypatch.setattr(riccati, "RESIDUAL_TOL", 0.0)
    with np.errstate(all="ignore"):
        assert riccati.dare_sda(A, B, Q, R) is None
    assert riccati.solve_dare(A, B, Q, R)[1] == riccati.SCIPY_NAME


def test_high_precision_doubling_scalar_and_refusal() -> None:
    """dare_sda_hp at 128 bits: the scalar DARE x² − 4x − 1 = 0 gives 2 + √5 to 10⁻³⁰;
    Q = 0 with an unstable A (Aₖ does not vanish) gives None."""
    from flint import arb, ctx, fmpq_mat

    old = ctx.prec
    ctx.prec = 128
    try:
        one = fmpq_mat([[1]])
        X = riccati.dare_sda_hp(fmpq_mat([[2]]), one, one, one, 128)
        assert X is not None
        assert abs(X[0, 0] - (2 + arb(5).sqrt())) < arb(10) ** -30
        A = fmpq_mat([[3, 1], [0, 1]])
        B = fmpq_mat([[0], [1]])
        assert riccati.dare_sda_hp(A, B, fmpq_mat(2, 2), one, 128) is None
    finally:
        ctx.prec = old


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 9),
    m=st.integers(1, 4),
    scale=st.sampled_from([0.3, 1.0, 3.0]),
)
def test_care_by_doubling_matches_scipy(seed: int, n: int, m: int, scale: float) -> None:
    """The Cayley-transformed doubling solves the CARE: where it answers, X is scipy's to
    10⁻⁷ relative, meets the residual bound, and A − GX is Hurwitz."""
    A, B, Q, R = _problem(seed, n, min(m, n), scale)
    with np.errstate(all="ignore"):
        X = riccati.care_sda(A, B, Q, R)
    Xs = sl.solve_continuous_are(A, B, Q, R)
    if X is None:
        return
    assert riccati.care_residual(A, B, Q, R, X) <= riccati.RESIDUAL_TOL
    assert np.abs(X - Xs).max() <= 1e-7 * max(1.0, np.abs(Xs).max())
    G = B @ np.linalg.solve(R, B.T)
    assert np.linalg.eigvals(A - G @ X).real.max() < 0


def test_care_answers_the_observer_problem_and_falls_back() -> None:
    """A 30-state observer problem: the doubling answers, to 10⁻¹² of scipy. Q = 0 with an
    unstable A: the doubling cannot leave X = 0 and scipy answers."""
    rng = np.random.default_rng(8)
    A = rng.standard_normal((30, 30))
    A -= (np.linalg.eigvals(A).real.max() + 0.1) * np.eye(30)
    C = rng.standard_normal((3, 30))
    X, name = riccati.solve_care(A.T, C.T, np.eye(30), np.eye(3))
    assert name == riccati.SDA_CARE_NAME
    Xs = sl.solve_continuous_are(A.T, C.T, np.eye(30), np.eye(3))
    assert np.abs(X - Xs).max() <= 1e-12 * np.abs(Xs).max()
    A2 = np.array([[1.0, 1.0], [0.0, -2.0]])
    B2 = np.array([[1.0], [0.0]])
    X2, name2 = riccati.solve_care(A2, B2, np.zeros((2, 2)), np.eye(1))
    assert name2 == riccati.SCIPY_CARE_NAME
    assert riccati.care_residual(A2, B2, np.zeros((2, 2)), np.eye(1), X2) < 1e-10


def test_care_residual_is_relative_to_the_terms() -> None:
    """Scalar CARE 2ax − x²b²/r + q = 0 with a = 1, b = r = q = 1: x = 1 + √2 has residual
    ~ rounding, a perturbed x does not."""
    x = 1.0 + np.sqrt(2.0)
    one = np.array([[1.0]])
    assert riccati.care_residual(one, one, one, one, np.array([[x]])) < 1e-15
    assert riccati.care_residual(one, one, one, one, np.array([[x * (1 + 1e-6)]])) > 1e-8


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 6), m=st.integers(1, 3))
def test_care_by_high_precision_doubling_matches_scipy(seed: int, n: int, m: int) -> None:
    """care_sda_hp at 128 bits (the Cayley transform and the doubling in arb_mat midpoints)
    on the exact rationals of a random well-posed CARE: X is scipy's to 10⁻⁷ relative."""
    from flint import ctx, fmpq_mat

    from obsdesign.certify.exact import Q as q

    A, B, Qw, R = _problem(seed, n, min(m, n), 1.0)

    def exact(M: np.ndarray) -> fmpq_mat:
        return fmpq_mat(M.shape[0], M.shape[1], [q(float(v)) for v in M.ravel()])

    old = ctx.prec
    ctx.prec = 128
    try:
        X = riccati.care_sda_hp(exact(A), exact(B), exact(Qw), exact(R), 128)
    finally:
        ctx.prec = old
    Xs = sl.solve_continuous_are(A, B, Qw, R)
    assert X is not None
    Xf = np.array([[float(X[i, j].mid()) for j in range(n)] for i in range(n)])
    assert np.abs(Xf - Xs).max() <= 1e-7 * max(1.0, np.abs(Xs).max())


def test_care_high_precision_refuses_q_zero_with_an_unstable_a() -> None:
    """Q = 0 with an unstable A: the doubling cannot leave X = 0 (Eₖ does not vanish): None."""
    from flint import ctx, fmpq_mat

    old = ctx.prec
    ctx.prec = 128
    try:
        A = fmpq_mat([[1, 1], [0, 2]])
        B = fmpq_mat([[0], [1]])
        assert riccati.care_sda_hp(A, B, fmpq_mat(2, 2), fmpq_mat([[1]]), 128) is None
    finally:
        ctx.prec = old
