"""The algebraic Riccati equations in floats: the structure-preserving doubling algorithm
(SDA) first — directly for the discrete equation, after a Cayley transform for the continuous
one — and scipy's ``solve_discrete_are`` / ``solve_continuous_are`` when SDA does not pass its
own checks; both also in python-flint ``arb_mat`` high precision (:func:`dare_sda_hp`, :func:`care_sda_hp`).

Why not scipy alone (issue 12, item 1): scipy's solver (an ordered QZ of a 2n×2n pencil) is
~90 % of the float baseline and of the lyapunov design's float work at n = 100 (90 ms); SDA
reaches the same solution to rounding (relative difference ≤ 10⁻¹⁴ on the benchmark systems)
in 7–8 doubling steps of n×n products and one LU each — 0.2 ms at n = 8, 10 ms at n = 100 —
and no library ships it (python-control and slycot call the same QZ method). The gain only
*proposes* L: every claim about it is certified exactly afterwards, so a poor solution costs a
weaker design, never a wrong certificate; even so, SDA's answer is taken only when it passes
the checks of :func:`dare_sda` and scipy is the fallback.

Equation (control form; the observer design calls it on the dual pair (Āᵀ, Cᵀ)):

    X = AᵀXA − AᵀXB (R + BᵀXB)⁻¹ BᵀXA + Q,   Q = Qᵀ ⪰ 0,  R = Rᵀ ≻ 0,

equivalently X = Aᵀ X (I + G X)⁻¹ A + Q with G = B R⁻¹ Bᵀ. SDA (Chu, Fan, Lin & Wang,
"Structure-preserving algorithms for periodic discrete-time algebraic Riccati equations",
Int. J. Control 77 (2004); Huang, Li & Lin, *Structure-Preserving Doubling Algorithms for
Nonlinear Matrix Equations*, SIAM 2018, Alg. 3.1): A₀ = A, G₀ = G, H₀ = Q and, with
Sₖ = (I + GₖHₖ)⁻¹,

    Aₖ₊₁ = Aₖ Sₖ Aₖ,   Gₖ₊₁ = Gₖ + Aₖ Sₖ Gₖ Aₖᵀ,   Hₖ₊₁ = Hₖ + Aₖᵀ Hₖ Sₖ Aₖ.

When (A, B) is stabilizable and (A, Q^½) detectable, Hₖ converges quadratically to the
stabilizing solution X: ‖Hₖ − X‖ = O(ρ(A_cl)^(2^(k+1))), A_cl = A − B(R + BᵀXB)⁻¹BᵀXA.
:func:`doubling` runs this iteration from any (E₀, G₀, H₀) (Eₖ for Aₖ); the continuous
equation enters it through the Cayley transform of :func:`care_sda`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from flint import arb_mat, fmpq_mat

#: doubling steps before giving up: 2⁶⁰ squarings cover any ρ(A_cl) < 1 − 10⁻¹⁶
MAX_STEPS = 60
#: relative size of the last update below which the iteration has converged (quadratic
#: convergence: the next update would be below rounding)
STEP_TOL = 1e-13
#: relative residual of the equation an SDA solution must meet to be taken
RESIDUAL_TOL = 1e-10


def dare_residual(
    A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray, X: np.ndarray
) -> float:
    """The relative residual of the discrete algebraic Riccati equation (module docstring):
    ‖AᵀXA − AᵀXB(R + BᵀXB)⁻¹BᵀXA + Q − X‖_max over the largest max-norm of its four terms
    (a solution of a problem with ρ(A) ≫ 1 cancels terms far larger than X, and rounding is
    relative to them); 0 when every term is 0.

    :param A, B, Q, R: as :func:`dare_sda`; :param X: the candidate solution."""
    XA = X @ A
    XB = X @ B
    K = np.linalg.solve(R + B.T @ XB, XB.T @ A)
    terms = (A.T @ XA, (A.T @ XB) @ K, Q, X)
    res = float(np.abs(terms[0] - terms[1] + terms[2] - terms[3]).max())
    scale = max(float(np.abs(t).max()) for t in terms)
    if scale == 0.0:
        return 0.0
    return res / scale


def doubling(E: np.ndarray, G: np.ndarray, H: np.ndarray) -> np.ndarray | None:
    """The doubling iteration of the module docstring from (E₀, G₀, H₀) = (E, G, H): the limit
    of Hₖ, or None when it does not converge within :data:`MAX_STEPS` steps with every value
    finite, or Eₖ does not vanish (Eₖ ≈ S^(2^k) up to factors, S the closed loop of the
    equation's discrete form: it vanishes only for the stabilizing solution).

    :param E: n×n; :param G, H: n×n symmetric."""
    n = E.shape[0]
    eye = np.eye(n)
    Ek, Gk, Hk = E.copy(), (G + G.T) / 2, (H + H.T) / 2
    for _ in range(MAX_STEPS):
        S = np.linalg.solve(eye + Gk @ Hk, np.hstack([Ek, Gk]))
        SE, SG = S[:, :n], S[:, n:]
        Hn = Hk + Ek.T @ (Hk @ SE)
        Gk = Gk + Ek @ SG @ Ek.T
        Ek = Ek @ SE
        Hn = (Hn + Hn.T) / 2
        Gk = (Gk + Gk.T) / 2
        if not (np.all(np.isfinite(Hn)) and np.all(np.isfinite(Ek))):
            return None
        step = float(np.abs(Hn - Hk).max())
        Hk = Hn
        if step <= STEP_TOL * float(np.abs(Hk).max()):
            return Hk if float(np.abs(Ek).max()) <= 1e-3 else None
    return None


def _psd(X: np.ndarray) -> bool:
    """X ⪰ 0 to rounding (its smallest eigenvalue ≥ −10⁻⁹ of its largest entry)."""
    return float(np.linalg.eigvalsh(X)[0]) >= -1e-9 * float(np.abs(X).max())


def dare_sda(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray) -> np.ndarray | None:
    """The stabilizing solution X of the DARE by the structure-preserving doubling algorithm
    (module docstring; E₀ = A, G₀ = B R⁻¹ Bᵀ, H₀ = Q), or None when it does not pass its
    checks: those of :func:`doubling`, relative residual ≤ :data:`RESIDUAL_TOL`, X symmetric
    positive semidefinite to rounding.

    :param A: n×n; :param B: n×m; :param Q: n×n symmetric ⪰ 0; :param R: m×m symmetric ≻ 0."""
    try:
        X = doubling(A, B @ np.linalg.solve(R, B.T), Q)
        if X is None or dare_residual(A, B, Q, R, X) > RESIDUAL_TOL or not _psd(X):
            return None
    except np.linalg.LinAlgError:
        return None
    return X


def care_residual(
    A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray, X: np.ndarray
) -> float:
    """The relative residual of the continuous algebraic Riccati equation
    AᵀX + XA − XB R⁻¹BᵀX + Q = 0: its max-norm over the largest max-norm of its terms (0
    when every term is 0).

    :param A, B, Q, R: as :func:`care_sda`; :param X: the candidate solution."""
    XB = X @ B
    terms = (A.T @ X, X @ A, XB @ np.linalg.solve(R, XB.T), Q)
    res = float(np.abs(terms[0] + terms[1] - terms[2] + terms[3]).max())
    scale = max(float(np.abs(t).max()) for t in terms)
    return 0.0 if scale == 0.0 else res / scale


def care_sda(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray) -> np.ndarray | None:
    """The stabilizing solution X of the CARE AᵀX + XA − XGX + Q = 0 (G = B R⁻¹ Bᵀ) by the
    doubling algorithm after a Cayley transform (SDA-1 of Chu, Fan & Lin, "A
    structure-preserving doubling algorithm for continuous-time algebraic Riccati
    equations", Linear Algebra Appl. 396 (2005)): with γ > 0, A_γ = A − γI and
    W = A_γᵀ + Q A_γ⁻¹ G,

        E₀ = I + 2γ W⁻ᵀ,   G₀ = 2γ A_γ⁻¹ G W⁻¹,   H₀ = 2γ W⁻¹ Q A_γ⁻¹,

    then :func:`doubling` (the closed loop's eigenvalues λ map to (λ + γ)/(λ − γ), inside the
    unit circle for Re λ < 0). These formulas were checked numerically against scipy's
    ``solve_continuous_are`` (tests/test_riccati.py). γ = max(1.05‖A‖_F, √(‖G‖_F‖Q‖_F)):
    above the spectral radius of A (so A_γ is invertible) and of the size of the Hamiltonian's
    spectrum. None when the checks of :func:`doubling` fail, the relative residual exceeds
    :data:`RESIDUAL_TOL` or X is not ⪰ 0 to rounding.

    :param A: n×n; :param B: n×m; :param Q: n×n symmetric ⪰ 0; :param R: m×m symmetric ≻ 0."""
    n = A.shape[0]
    eye = np.eye(n)
    try:
        G = B @ np.linalg.solve(R, B.T)
        G = (G + G.T) / 2
        gam = max(
            1.05 * float(np.linalg.norm(A)), float(np.sqrt(np.linalg.norm(G) * np.linalg.norm(Q)))
        )
        if not (math.isfinite(gam) and gam > 0):
            return None
        Ag = A - gam * eye
        AgiG = np.linalg.solve(Ag, G)
        Wi = np.linalg.inv(Ag.T + Q @ AgiG)
        E0 = eye + 2 * gam * Wi.T
        G0 = 2 * gam * AgiG @ Wi
        H0 = 2 * gam * Wi @ np.linalg.solve(Ag.T, Q.T).T  # W⁻¹ Q A_γ⁻¹
        X = doubling(E0, G0, H0)
        if X is None or care_residual(A, B, Q, R, X) > RESIDUAL_TOL or not _psd(X):
            return None
    except np.linalg.LinAlgError:
        return None
    return X


def solve_dare(
    A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, str]:
    """(X, the solver that ran): :func:`dare_sda`, or scipy's ``solve_discrete_are`` when SDA
    does not pass its checks (scipy's errors — LinAlgError, ValueError — pass through).

    :param A, B, Q, R: as :func:`dare_sda`."""
    return _doubling_or_scipy(dare_sda, "solve_discrete_are", SDA_NAME, A, B, Q, R)


def solve_care(
    A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, str]:
    """(X, the solver that ran): :func:`care_sda`, or scipy's ``solve_continuous_are`` when
    it does not pass its checks (scipy's errors pass through).

    :param A, B, Q, R: as :func:`care_sda`."""
    return _doubling_or_scipy(care_sda, "solve_continuous_are", SDA_CARE_NAME, A, B, Q, R)


def _doubling_or_scipy(
    sda: Callable[..., np.ndarray | None], scipy_name: str, sda_name: str, *args: np.ndarray
) -> tuple[np.ndarray, str]:
    """``sda(*args)`` named ``sda_name``, else ``scipy.linalg.<scipy_name>(*args)``."""
    with np.errstate(all="ignore"):
        X = sda(*args)
    if X is not None:
        return X, sda_name
    import scipy.linalg

    return getattr(scipy.linalg, scipy_name)(*args), f"scipy {scipy_name}"


#: the solver names :func:`solve_dare` and :func:`solve_care` report
SDA_NAME = "structure-preserving doubling (numpy)"
SCIPY_NAME = "scipy solve_discrete_are"
SDA_CARE_NAME = "structure-preserving doubling after a Cayley transform (numpy)"
SCIPY_CARE_NAME = "scipy solve_continuous_are"


#: the largest state dimension the high-precision doubling is tried at (24 until session 41:
#: Jordan blocks of 25-64 states certify from it in 1-60 s; at 80-100 states such a block
#: took 40-100 s to find no gain)
HP_MAX_N = 64
#: the working precisions (bits) of the high-precision doubling, tried in turn
HP_PRECISIONS = (128, 320, 1024)


def dare_sda_hp(A: fmpq_mat, B: fmpq_mat, Q: fmpq_mat, R: fmpq_mat, prec: int) -> arb_mat | None:
    """:func:`dare_sda` in python-flint ``arb_mat`` arithmetic at ``prec`` bits (midpoints
    only: no error bounds are needed, whatever the solution proposes is checked exactly
    afterwards), for the badly conditioned problems where every float solver is wrong — e.g.
    a 3-state plant with ρ(A) ≈ 2000 and one output, where scipy's X gives an observer gain
    with ρ(A − LC) ≈ 34 and the float doubling refuses its own. The DARE and the iteration
    are those of the module docstring. Returns X as an ``arb_mat`` of midpoints at ``prec``
    bits (the caller computes in the same context), or None when it does not converge in
    :data:`MAX_STEPS` steps or Aₖ does not vanish.

    :param A: n×n; :param B: n×m; :param Q: n×n; :param R: m×m (``fmpq_mat``, exact);
    :param prec: working precision in bits (the caller sets ``flint.ctx.prec`` to it)."""
    from flint import arb_mat  # noqa: F811 (the runtime import of the type-checking name)

    Bh = arb_mat(B)
    G = (Bh * arb_mat(R).solve(Bh.transpose())).mid()
    return _doubling_hp(arb_mat(A), G, arb_mat(Q), prec)


def care_sda_hp(A: fmpq_mat, B: fmpq_mat, Q: fmpq_mat, R: fmpq_mat, prec: int) -> arb_mat | None:
    """:func:`care_sda` in python-flint ``arb_mat`` arithmetic at ``prec`` bits (midpoints
    only; the caller checks what it proposes exactly): the Cayley transform of SDA-1 (Chu,
    Fan & Lin 2005, see :func:`care_sda`) formed at that precision, then the doubling of
    :func:`dare_sda_hp`. For continuous plants where scipy and the float doubling give no
    solution at all (an integer companion matrix of order 10 with one output: "Failed to find
    a finite solution", review 19). γ is chosen in floats as in :func:`care_sda` (any γ above
    the spectral radius of A works). None when the transform is singular or the doubling does
    not converge.

    :param A: n×n; :param B: n×m; :param Q: n×n; :param R: m×m (``fmpq_mat``, exact);
    :param prec: working precision in bits (the caller sets ``flint.ctx.prec`` to it)."""
    from flint import arb_mat  # noqa: F811

    n = A.nrows()
    eye = arb_mat([[1 if i == j else 0 for j in range(n)] for i in range(n)])
    Ah, Bh, Qh = arb_mat(A), arb_mat(B), arb_mat(Q)
    G = (Bh * arb_mat(R).solve(Bh.transpose())).mid()

    def fro(M: arb_mat) -> float:
        return math.sqrt(
            sum(float(M[i, j].mid()) ** 2 for i in range(M.nrows()) for j in range(M.ncols()))
        )

    gam = max(1.05 * fro(Ah), math.sqrt(fro(G) * fro(Qh)))
    if not (math.isfinite(gam) and gam > 0):
        return None
    g = arb_mat([[gam]])[0, 0]
    Ag = Ah - eye * g
    AgiG = Ag.solve(G)
    Wi = (Ag.transpose() + Qh * AgiG).inv()
    E0 = (eye + Wi.transpose() * (2 * g)).mid()
    G0 = (AgiG * Wi * (2 * g)).mid()
    H0 = (Wi * Ag.transpose().solve(Qh.transpose()).transpose() * (2 * g)).mid()
    return _doubling_hp(E0, G0, H0, prec)


def _doubling_hp(E: arb_mat, G: arb_mat, H: arb_mat, prec: int) -> arb_mat | None:
    """:func:`doubling` in ``arb_mat`` midpoint arithmetic at ``prec`` bits (module docstring;
    Huang, Li & Lin 2018, Alg. 3.1): the limit of Hₖ, or None when it does not converge
    within :data:`MAX_STEPS` steps, a value leaves the float range, a solve is singular, or
    Eₖ does not vanish.

    :param E, G, H: n×n ``arb_mat``; :param prec: the working precision (bits)."""
    from flint import arb_mat  # noqa: F811

    n = E.nrows()
    eye = arb_mat([[1 if i == j else 0 for j in range(n)] for i in range(n)])
    Ak, Gk, Hk = E, G, H
    tol = 2.0 ** (-(prec // 2))
    try:
        for _ in range(MAX_STEPS):
            W = eye + Gk * Hk
            SA = W.solve(Ak)
            SG = W.solve(Gk)
            Hn = (Hk + Ak.transpose() * (Hk * SA)).mid()
            Gk = (Gk + Ak * SG * Ak.transpose()).mid()
            Ak = (Ak * SA).mid()
            step = _max_abs(Hn - Hk)
            Hk = Hn
            top = _max_abs(Hk)
            if not (math.isfinite(step) and math.isfinite(top)):
                return None
            if step <= tol * top:
                return Hk if _max_abs(Ak) <= 1e-3 else None
    except (ZeroDivisionError, ValueError):
        return None
    return None


def _max_abs(M: arb_mat) -> float:
    """max |midpoint| of an ``arb_mat``'s entries, as a float (inf beyond the float range)."""
    return max(
        (abs(float(M[i, j].mid())) for i in range(M.nrows()) for j in range(M.ncols())), default=0.0
    )
