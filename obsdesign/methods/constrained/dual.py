"""C_min ⊂ {a·x ≤ b} for an affine constraint map by a dual certificate (Assumption 3(1),
constrained-redesign paper, Astolfi et al., NOLCOS 2019).

For φ = G x − h the components are c_i = (φ_i⁺)² (eqs. (18)-(19)), so
C_min = {x : ‖φ(x)⁺‖_q ≤ √ε_min} with q = 4 for the Euclidean |c| of eq. (16) and q = ∞ for
the max norm. For every y ≥ 0 with Gᵀy = a (Hölder, q* = 4/3 or 1):

    a·x = yᵀh + yᵀφ(x) ≤ yᵀh + yᵀφ(x)⁺ ≤ yᵀh + ‖y‖_{q*} √ε_min   on C_min,

so ``b − yᵀh ≥ √ε_min ‖y‖_{q*}`` proves the face. By conic duality the best y gives
max_{C_min} a·x (C_min has an interior for ε_min > 0), so an inclusion with any margin above
the float solver's tolerance has such a y. It is found in floats (cvxpy, Clarabel) and made
exact: Gᵀy = a by an exact least-norm correction on y's support, y ≥ 0 and the inequality
checked in rationals (q* = 1) or rigorous arb balls (q* = 4/3). The outer set {φ_i ≤ t} of
C_min has corners that a Euclidean C_min does not (and t ≥ √ε_min is rounded up), so its
vertex test refused true inclusions, exit 4 (independent fuzz, session 37).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from flint import fmpq, fmpq_mat, fmpz

from obsdesign.certify.exact import Q, to_float
from obsdesign.lmi import time_limit

#: y_i below this fraction of max y are dropped before the exact correction (the solver's
#: zeros are ~1e-10, not 0)
SUPPORT_REL = 1e-9


def holder_below(eps: fmpq, w: list[fmpq], a: fmpq) -> bool | None:
    """Whether √ε·‖w‖_{4/3} ≤ a, i.e. ε²·(Σ w_i^{4/3})³ ≤ a⁴ with a ≥ 0 and w ≥ 0 (the
    Hölder bound of the Euclidean C_min's support, eq. (16)): exact when the nonzero w_i are
    a rational cube apart, w_i = w_1·k_i³ ((Σ w_i^{4/3})³ = w_1⁴(Σ k_i⁴)³; equal weights:
    m³w⁴), else in rigorous balls (python-flint arb, 64 to 1024 bits).
    None when a tie stays undecided at 1024 bits.

    :param eps: ε_min; :param w: the weights; :param a: the margin (≥ 0)."""
    from flint import arb, ctx

    nz = [Q(x) for x in w if x != 0]
    if not nz:
        return True
    ks = _cube_roots([x / nz[0] for x in nz])
    if ks is not None:
        # w_i = w_1·k_i³ with rational k_i: Σ w_i^{4/3} = w_1^{4/3}·Σ k_i⁴, so the cube is
        # w_1⁴·(Σ k_i⁴)³, rational (equal weights: k_i = 1). Weights 1.2³, 1.5³, 2³ touching
        # C_min were "undecided at 1024 bits", exit 4 (mutation review, session 39)
        s4 = sum((k**4 for k in ks), fmpq(0))
        return eps * eps * nz[0] ** 4 * s4**3 <= a**4
    for prec in (64, 256, 1024):
        with ctx.workprec(prec):
            s43 = sum((arb(x) ** arb(fmpq(4, 3)) for x in nz), arb(0))
            lhs, rhs = arb(eps * eps) * s43**3, arb(a**4)
            if lhs < rhs:
                return True
            if lhs > rhs:
                return False
    return None


def _cube_roots(r: list[fmpq]) -> list[fmpq] | None:
    """The rational cube roots of the positive rationals ``r``, or None when one has none."""
    out = []
    for x in r:
        if x <= 0:
            return None
        p, q = fmpz(x.p), fmpz(x.q)
        cp, cq = p.root(3), q.root(3)
        if cp**3 != p or cq**3 != q:
            return None
        out.append(fmpq(cp, cq))
    return out


def face_holds(
    G: np.ndarray, h: np.ndarray, norm: str, eps: fmpq, a: np.ndarray, b: fmpq, y: np.ndarray
) -> bool | None:
    """Whether the exact y proves max_{C_min} a·x ≤ b (module docstring): y ≥ 0, Gᵀy = a and
    b − yᵀh ≥ √ε‖y‖_{q*}. False when y is no certificate or the bound misses b; None on an
    undecided tie.

    :param G, h: the map's φ = G x − h (exact); :param norm: "euclidean" or "max";
    :param eps: ε_min; :param a, b: the face (exact); :param y: the multipliers (exact)."""
    m, n = G.shape
    if len(a) != n or len(y) != m or any(v < 0 for v in y):
        return False
    for j in range(n):
        if sum((G[i, j] * y[i] for i in range(m) if y[i] != 0), fmpq(0)) != a[j]:
            return False
    margin = b - sum((y[i] * h[i] for i in range(m) if y[i] != 0), fmpq(0))
    if margin < 0:
        return False
    if norm == "max":
        s = sum(y, fmpq(0))
        return eps * s * s <= margin * margin
    return holder_below(eps, list(y), margin)


def exact_multipliers(G: np.ndarray, a: np.ndarray, yf: np.ndarray) -> np.ndarray | None:
    """Rational y ≥ 0 near the float ``yf`` with Gᵀy = a exactly, supported where yf is not
    negligible (:data:`SUPPORT_REL`): y = y₀ + G_S z with (G_SᵀG_S) z = a − G_Sᵀy₀ (the
    least-norm correction) when G_S has full column rank, else a basic solution of
    G_Sᵀδ = a − G_Sᵀy₀ by exact row reduction. A multiplier the correction makes negative
    (a solver's 4·10⁻⁹ for a zero) leaves the support and the correction is redone. None
    when no such y is found. (:func:`face_holds` checks the result again.)

    :param G: the map's rows (exact, m × n); :param a: the face (exact); :param yf: floats."""
    m = G.shape[0]
    top = float(np.max(yf)) if len(yf) else 0.0
    if not top > 0 or not math.isfinite(top):
        return None
    S = [i for i in range(m) if yf[i] > SUPPORT_REL * top]
    while S:
        y = _corrected(G, a, yf, S)
        if y is None:
            return None
        neg = [i for i in S if y[i] < 0]
        if not neg:
            return y
        S = [i for i in S if i not in neg]
    return None


def _corrected(G: np.ndarray, a: np.ndarray, yf: np.ndarray, S: list[int]) -> np.ndarray | None:
    """y supported on S with Gᵀy = a exactly, near yf (:func:`exact_multipliers`), or None."""
    m, n = G.shape
    y = np.array([fmpq(0)] * m, dtype=object)
    for i in S:
        y[i] = Q(float(yf[i]))
    r = [a[j] - sum((G[i, j] * y[i] for i in S), fmpq(0)) for j in range(n)]
    if all(x == 0 for x in r):
        return y
    GS = fmpq_mat([[G[i, j] for j in range(n)] for i in S])  # |S| × n
    GtG = GS.transpose() * GS
    if len(S) >= n and GtG.rank() == n:
        d = GS * GtG.solve(fmpq_mat([[x] for x in r]))
        for k, i in enumerate(S):
            y[i] += d[k, 0]
        return y
    aug = fmpq_mat([[G[i, j] for i in S] + [r[j]] for j in range(n)])  # [G_Sᵀ | r]
    R, rank = aug.rref()
    k = len(S)
    for row in range(rank):
        col = next(c for c in range(k + 1) if R[row, c] != 0)
        if col == k:
            return None  # inconsistent: a − G_Sᵀy₀ is not in the range of G_Sᵀ
        y[S[col]] += R[row, k]
    return y


def float_multipliers(
    Gf: np.ndarray, hf: np.ndarray, norm: str, eps: float, af: np.ndarray
) -> np.ndarray | None:
    """The float y minimizing yᵀh + √ε‖y‖_{q*} subject to Gᵀy = a, y ≥ 0 (the dual of
    max_{C_min} a·x; cvxpy, Clarabel), or None when the solver gives none. Solved for
    z = ‖a‖⁻¹ D y (D the rows' norms): Ĝᵀz = â with unit rows Ĝ = D⁻¹G and â = a/‖a‖, and
    ‖D⁻¹z‖_{q*} in the objective. Unscaled, a face written as 10⁻¹⁰x₁ + 10⁻¹⁰x₂ ≤ 2.38·10⁻¹⁰ or
    one row scaled by 10⁸ gave no y (Clarabel said "infeasible"), and true inclusions with
    margins of 0.5 % to 1000 % stayed exit 4 (re-check trial, session 38). A zero row of G
    gets the multiplier 0.

    :param Gf, hf: the map (floats); :param norm: "euclidean" or "max"; :param eps: ε_min;
    :param af: the face's normal (floats)."""
    import warnings

    import cvxpy as cp

    d_all = np.linalg.norm(Gf, axis=1)
    na = float(np.linalg.norm(af))
    keep = d_all > 0
    if not (na > 0 and keep.any() and np.all(np.isfinite(d_all)) and math.isfinite(na)):
        return None
    if not keep.all():
        # a zero row of G (φ_i = −h_i, a constant) adds nothing to Gᵀy: its multiplier is 0
        # (the exact check decides with it); it made the unit-row scaling divide by 0 and
        # every face undecided, exit 4 for a true inclusion (constrained fuzz, session 39)
        y = float_multipliers(Gf[keep], hf[keep], norm, eps, af)
        if y is None:
            return None
        out = np.zeros(Gf.shape[0])
        out[keep] = y
        return out
    d = d_all
    z = cp.Variable(Gf.shape[0], nonneg=True)
    # the weights √ε/d inside the norm, one O(1) vector: √ε·‖z/d‖ with rows of size 1e-6
    # (1/d ~ 1e6, √ε ~ 3e-7) made Clarabel fail (re-check trial, session 38)
    w = cp.multiply(math.sqrt(eps) / d, z)
    size = cp.norm1(w) if norm == "max" else cp.pnorm(w, 4 / 3)
    obj = (hf / d) @ z + size
    prob = cp.Problem(cp.Minimize(obj), [(Gf / d[:, None]).T @ z == af / na])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "Solution may be inaccurate": checked exactly
            prob.solve(solver=cp.CLARABEL, **time_limit("CLARABEL"))
    except (cp.error.SolverError, ValueError, ArithmeticError):
        return None
    if z.value is None or not np.all(np.isfinite(z.value)):
        return None
    return np.maximum(np.asarray(z.value, dtype=float), 0.0) * na / d


def faces_by_duality(
    G: np.ndarray, h: np.ndarray, norm: str, eps: Any, H: np.ndarray, k: np.ndarray
) -> tuple[bool, list[int]]:
    """C_min ⊂ {H x ≤ k} for φ = G x − h, one dual certificate per face (module docstring).
    Returns (every face proved, the faces not proved).

    :param G, h: the map (exact); :param norm: "euclidean" or "max"; :param eps: ε_min;
    :param H, k: X̂'s faces (exact)."""
    e = Q(eps)
    if not e <= fmpq(10) ** 300:  # beyond the float solver (a spec's ε_min is a float)
        return False, list(range(H.shape[0]))
    Gf = np.asarray(to_float(G), dtype=float)
    hf = np.asarray(to_float(h), dtype=float).reshape(-1)
    Hf = np.asarray(to_float(H), dtype=float)
    open_faces = []
    for j in range(H.shape[0]):
        yf = float_multipliers(Gf, hf, norm, float(e), Hf[j])
        y = None if yf is None else exact_multipliers(G, H[j], yf)
        if y is None or face_holds(G, h, norm, e, H[j], k[j], y) is not True:
            open_faces.append(j)
    return not open_faces, open_faces
