"""The discrete algebraic Riccati equation in floats: the structure-preserving doubling
algorithm (SDA) first, scipy's ``solve_discrete_are`` when SDA does not pass its own checks.

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
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

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


def dare_sda(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray) -> np.ndarray | None:
    """The stabilizing solution X of the DARE by the structure-preserving doubling algorithm
    (module docstring), or None when it does not pass its checks: converged within
    :data:`MAX_STEPS` steps with every value finite, Aₖ → 0 (the solution is the stabilizing
    one), relative residual ≤ :data:`RESIDUAL_TOL`, X symmetric positive semidefinite to
    rounding.

    :param A: n×n; :param B: n×m; :param Q: n×n symmetric ⪰ 0; :param R: m×m symmetric ≻ 0."""
    n = A.shape[0]
    eye = np.eye(n)
    try:
        G = B @ np.linalg.solve(R, B.T)
        G = (G + G.T) / 2
        Ak, Gk, Hk = A.copy(), G, (Q + Q.T) / 2
        for _ in range(MAX_STEPS):
            S = np.linalg.solve(eye + Gk @ Hk, np.hstack([Ak, Gk]))
            SA, SG = S[:, :n], S[:, n:]
            Hn = Hk + Ak.T @ (Hk @ SA)
            Gk = Gk + Ak @ SG @ Ak.T
            Ak = Ak @ SA
            Hn = (Hn + Hn.T) / 2
            Gk = (Gk + Gk.T) / 2
            if not (np.all(np.isfinite(Hn)) and np.all(np.isfinite(Ak))):
                return None
            step = float(np.abs(Hn - Hk).max())
            Hk = Hn
            if step <= STEP_TOL * float(np.abs(Hk).max()):
                break
        else:
            return None
        top = float(np.abs(Hk).max())
        # Aₖ ≈ A_cl^(2^k) up to factors: it vanishes only for the stabilizing solution
        if float(np.abs(Ak).max()) > 1e-3:
            return None
        if dare_residual(A, B, Q, R, Hk) > RESIDUAL_TOL:
            return None
        if float(np.linalg.eigvalsh(Hk)[0]) < -1e-9 * top:
            return None
    except np.linalg.LinAlgError:
        return None
    return Hk


def solve_dare(
    A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray
) -> tuple[np.ndarray, str]:
    """(X, the solver that ran): :func:`dare_sda`, or scipy's ``solve_discrete_are`` when SDA
    does not pass its checks (scipy's errors — LinAlgError, ValueError — pass through).

    :param A, B, Q, R: as :func:`dare_sda`."""
    with np.errstate(all="ignore"):
        X = dare_sda(A, B, Q, R)
    if X is not None:
        return X, SDA_NAME
    from scipy.linalg import solve_discrete_are

    return solve_discrete_are(A, B, Q, R), SCIPY_NAME


#: the solver names :func:`solve_dare` reports
SDA_NAME = "structure-preserving doubling (numpy)"
SCIPY_NAME = "scipy solve_discrete_are"


#: the largest state dimension the high-precision doubling is tried at
HP_MAX_N = 24
#: the working precisions (bits) of the high-precision doubling, tried in turn
HP_PRECISIONS = (128, 320, 1024)


def dare_sda_hp(A: Any, B: Any, Q: Any, R: Any, prec: int) -> Any:
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
    from flint import arb_mat

    n = A.nrows()
    eye = arb_mat([[1 if i == j else 0 for j in range(n)] for i in range(n)])
    Ak, Bh = arb_mat(A), arb_mat(B)
    Gk = (Bh * arb_mat(R).solve(Bh.transpose())).mid()
    Hk = arb_mat(Q)
    tol = 2.0 ** (-(prec // 2))
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
    return None


def _max_abs(M: Any) -> float:
    """max |midpoint| of an ``arb_mat``'s entries, as a float (inf beyond the float range)."""
    return max(
        (abs(float(M[i, j].mid())) for i in range(M.nrows()) for j in range(M.ncols())), default=0.0
    )
