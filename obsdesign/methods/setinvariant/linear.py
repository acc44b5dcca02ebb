"""Linear output injection v = L z (Proposition 7.1, Dórea & Pimenta, paper 003).

Proposition 7.1 (p = n − 1, η = 0): if the symmetric polyhedron {|Q e| <= 1} satisfies
condition (15) (= (14)), then ``L = A [Q_I; C]^{-1} [0; −I]`` keeps it λ-contractive, where
Q_I is "the only non-redundant row of Q in Ω ∩ ker C". That row need not be unique: on
Example 7.1 two rows tie, and the two choices give different gains. So this module computes
the whole *admissible set* of linear gains,

    𝓛 = {L : G_i (A + L C) e + G_i L η + δ_i <= λ  for every row i, vertex e, noise vertex η},

a polyhedron in L (the constraints are linear in L), reports it (its vertices when the
dimension n·p is small), and picks a gain inside it: the max-margin point when 𝓛 has an
interior, else the average of its vertices (a relative-interior point; every Prop. 7.1
choice of Q_I lies in 𝓛 by the proposition, so this is in the convex hull of them when they
span it).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from flint import fmpq
from scipy.optimize import linprog

from obsdesign.sets import polytope_ops as po

from .certificate import ExactProblem, delta_exact, linear_law, noise_vertices, qmatmul
from .lps import lp_in_range, unit_columns


@dataclass
class GainSet:
    """The admissible linear gains and the pick."""

    L: np.ndarray | None  # (n, p) fmpq, None if 𝓛 is empty
    factor: fmpq | None
    how: str
    vertices: list[np.ndarray] = field(default_factory=list)  # exact vertices of 𝓛 (small n·p)
    dimension: int | None = None
    prop71: list[tuple[int, np.ndarray]] = field(default_factory=list)  # (row index, L)
    margin: float = 0.0


def _constraints(
    ex: ExactProblem, G: np.ndarray, V: np.ndarray
) -> tuple[list[list[fmpq]], list[fmpq]]:
    """Rows a·vec(L) <= b of 𝓛 (vec row-major over L's n×p entries), exactly."""
    n, p = ex.n, ex.C.shape[0]
    GA = qmatmul(G, ex.A)
    dl = delta_exact(G, ex.B1, ex.Dv)
    etas = noise_vertices(p, ex.eta) if ex.eta != 0 else [tuple([fmpq(0)] * p)]
    Ce = [[po.qdot(ex.C[k], v) for k in range(p)] for v in V]
    rows, rhs = [], []
    seen = set()
    for i in range(len(G)):
        for j, v in enumerate(V):
            base = ex.lam - dl[i] - po.qdot(GA[i], v)
            for eta in etas:
                w = [Ce[j][k] + eta[k] for k in range(p)]
                a = [G[i][r] * w[k] for r in range(n) for k in range(p)]
                key = (tuple(a), base)
                if key not in seen:
                    seen.add(key)
                    rows.append(a)
                    rhs.append(base)
    return rows, rhs


def prop71_gains(ex: ExactProblem, G: np.ndarray) -> list[tuple[int, np.ndarray]]:
    """L = A [Q_I; C]^{-1} [0; −I] for every tying choice of Q_I (Proposition 7.1, p = n−1).

    ker C is one-dimensional, spanned by k; the non-redundant rows of Ω ∩ ker C are those
    with the largest |G_i k| (rows i and −i give the same L, counted once)."""
    from flint import fmpq_mat

    n, p = ex.n, ex.C.shape[0]
    if p != n - 1:
        return []
    # kernel vector of C: solve with one free coordinate set to 1
    k = None
    for j in range(n):
        cols = [c for c in range(n) if c != j]
        M = fmpq_mat([[ex.C[r][c] for c in cols] for r in range(p)])
        if M.det() != 0:
            rhs = fmpq_mat([[-ex.C[r][j]] for r in range(p)])
            sol = M.solve(rhs)
            k = [fmpq(0)] * n
            k[j] = fmpq(1)
            for t, c in enumerate(cols):
                k[c] = sol[t, 0]
            break
    if k is None:
        return []
    vals = [abs(po.qdot(G[i], k)) for i in range(len(G))]
    best = max(vals)
    Am = fmpq_mat([[x for x in r] for r in ex.A])
    rhs = fmpq_mat(n, p, [fmpq(-1) if r == c + 1 else fmpq(0) for r in range(n) for c in range(p)])
    out: list[tuple[int, np.ndarray]] = []
    for i in range(len(G)):
        if vals[i] != best:
            continue
        M = fmpq_mat([[x for x in G[i]]] + [[x for x in r] for r in ex.C])
        if M.det() == 0:
            continue
        Lm = Am * M.solve(rhs)
        L = np.array([[Lm[r, c] for c in range(p)] for r in range(n)], dtype=object)
        if not any(np.array_equal(L, L2) for _, L2 in out):
            out.append((i, L))
    return out


def gain_vertices(
    ex: ExactProblem,
    G: np.ndarray,
    V: np.ndarray,
    constraints: tuple[list[list[fmpq]], list[fmpq]] | None = None,
) -> tuple[list[np.ndarray], bool]:
    """Exact vertices of the admissible set 𝓛 of linear gains (proof of Proposition 7.1),
    by cdd.gmp vertex enumeration, and whether 𝓛 has directions (lines or rays).

    ``ex``: exact problem; ``G``: facets of the polyhedron (rhs 1); ``V``: its vertices;
    ``constraints``: the rows of 𝓛 when already computed."""
    import cdd
    import cdd.gmp as cddg

    n, p = ex.n, ex.C.shape[0]
    rows, rhs = constraints if constraints is not None else _constraints(ex, G, V)
    mat = [[po._fr(rhs[i])] + [-po._fr(x) for x in rows[i]] for i in range(len(rows))]
    poly = cddg.polyhedron_from_matrix(cddg.matrix_from_array(mat, rep_type=cdd.RepType.INEQUALITY))
    gen = cddg.copy_generators(poly)
    verts: list[np.ndarray] = []
    has_dir = bool(gen.lin_set) or any(r[0] == 0 for r in gen.array)
    if gen.lin_set:
        # a set with lines has no vertices: cdd's point is only a point of a minimal face
        # (C = 0, η̄ = 0: every L is admissible, and (0, 0) was certified "exactly the
        # vertices of the set of linear gains"; degenerate-sizes review, session 42)
        return verts, has_dir
    for r in gen.array:
        if r[0] != 0:
            verts.append(np.array([po._q(x / r[0]) for x in r[1:]], dtype=object).reshape(n, p))
    return verts, has_dir


def admissible_gains(
    ex: ExactProblem, G: np.ndarray, V: np.ndarray, max_dim_enum: int = 4
) -> GainSet:
    """The admissible set 𝓛 of linear gains for {G e <= 1} and a certified pick inside it."""
    n, p = ex.n, ex.C.shape[0]
    rows, rhs = _constraints(ex, G, V)
    Af = po.qfloat(np.array(rows, dtype=object))
    bf = po.qfloat(np.array(rhs, dtype=object))
    nl = n * p
    # max-margin LP: max t s.t. A x + t·‖a‖ <= b, t <= 1, in x = vec(L) / s: the columns of A
    # scaled to 1 (lps.unit_columns), so neither HiGHS nor the margin t depends on the units
    # of e and z (C = 1e-9·C had an "empty" admissible set that C has not: HiGHS infeasible)
    As, s = unit_columns(Af)
    with np.errstate(over="ignore", invalid="ignore"):
        norms = np.linalg.norm(As, axis=1)
    c = np.zeros(nl + 1)
    c[-1] = -1.0
    A_lp = np.hstack([As, norms[:, None]])
    res = None
    if lp_in_range(A_lp, bf):
        res = linprog(
            c, A_ub=A_lp, b_ub=bf, bounds=[(None, None)] * nl + [(None, 1.0)], method="highs"
        )
        if res.status == 0:
            res.x[:nl] *= s
    prop = prop71_gains(ex, G)
    if res is not None and (res.status != 0 or res.x[-1] < -1e-9):
        return GainSet(None, None, "the admissible set of linear gains is empty", prop71=prop)
    # data beyond a float LP's range (huge B1, η̄ or C): no max-margin point; the exact
    # candidates (vertices of 𝓛, Proposition 7.1) are still tried
    margin = float(res.x[-1]) if res is not None else 0.0
    verts: list[np.ndarray] = []
    dim = None
    if nl <= max_dim_enum:
        verts, has_dir = gain_vertices(ex, G, V, (rows, rhs))
        if verts and not has_dir:
            dim = _affine_dim(verts)
    candidates: list[tuple[np.ndarray, str]] = []
    if margin > 1e-9:
        candidates.append(
            (
                po.rationalize(res.x[:nl]).reshape(n, p),
                "max-margin point of the admissible set (it has an interior)",
            )
        )
    if verts:
        avg = sum((v for v in verts), np.full((n, p), fmpq(0), dtype=object)) * fmpq(1, len(verts))
        candidates.append(
            (
                avg,
                f"average of the {len(verts)} vertices of the admissible set (a relative-interior point)",
            )
        )
    if prop:
        avg = sum((L for _, L in prop), np.full((n, p), fmpq(0), dtype=object)) * fmpq(1, len(prop))
        candidates.append((avg, "average of the Proposition 7.1 gains"))
        for i, L in prop:
            candidates.append((L, f"Proposition 7.1 with Q_I = row {i + 1} of G (counted from 1)"))
    if res is not None:
        candidates.append((po.rationalize(res.x[:nl]).reshape(n, p), "max-margin LP point"))
    for L, how in candidates:
        ok, f = linear_law(ex, G, V, L)
        if ok:
            return GainSet(L, f, how, verts, dim, prop, margin)
    why = "no candidate gain passed the exact check"
    if res is None:
        why += " (the max-margin LP was skipped: its data are beyond a float LP's range)"
    return GainSet(None, None, why, verts, dim, prop, margin)


def _affine_dim(verts: list[np.ndarray]) -> int:
    """The exact affine dimension of the hull of the vertices (exact rational arrays): the
    rank of their differences from the first, in flint. A float rank with an absolute
    tolerance of 10⁻¹² said "dimension 1" for four vertices spanning a polygon 10⁻²⁴ wide
    next to a note that the set has an interior (set-invariant trial, session 31)."""
    from flint import fmpq_mat

    if len(verts) < 2:
        return 0
    rows = [np.asarray(v, dtype=object).reshape(-1) for v in verts]
    D = [[x - y for x, y in zip(r, rows[0], strict=True)] for r in rows[1:]]
    return int(fmpq_mat(len(D), len(D[0]), [x for r in D for x in r]).rank())
