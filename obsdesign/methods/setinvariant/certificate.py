"""Exact certificates for the set-invariant method (paper 003), all in rational arithmetic.

* :func:`omega_contained` — Ω ⊆ {G e <= 1}: every exact vertex of Ω satisfies every row.
* :func:`theorem31` — Theorem 3.1: for every z^l in Z_d (computed exactly from the exact
  vertices of {G e <= 1}), ``φ(z^l) + G v^l + δ <= λ 1`` holds exactly for the rational v^l,
  with φ(z^l) (LP (6)) taken exactly as the max of G A over the slice's exact vertices and
  δ exactly from D's vertices. Because φ is concave (an LP value in its right-hand side) and
  the slice's vertices move affinely between consecutive points of Z_d, φ is affine on each
  segment [z^l, z^{l+1}], so the interpolated law (12) of Proposition 4.1 is certified too.
* :func:`linear_law` — Proposition 7.1 / linear injection ``v = L z``: for every vertex e of
  {G e <= 1} and every vertex η of the noise box, ``G (A + L C) e + G L η + δ <= λ 1``.

Float values are used only to pick which entries to evaluate exactly. Each is a rigorous
bracket: a relative slack far above the rounding of the float products, and for an edge
crossing of a slice the whole possible error of its float weight (:func:`_weight_error`),
so a skipped entry is provably below the bound.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from fractions import Fraction
from itertools import product

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import float_or_inf
from obsdesign.errors import InconclusiveError, SolverError
from obsdesign.sets import polytope_ops as po

from .budget import Timeout

_FILTER = 1e-7  # relative slack of the float prefilter (float error is ~1e-15 relative)
#: a candidate whose weight error (:func:`_weight_error`) is at most this shares one radius
#: vector in :meth:`_Slices.row_bounds`; a larger one (an edge nearly level in c) has its own
_PRECISE = 1e-6


@dataclass
class ExactProblem:
    """Exact data: A, B1, C (p×n), Ω rows G0 (rhs 1), vertices of Ω and of D, η̄, λ."""

    A: np.ndarray
    B1: np.ndarray
    C: np.ndarray
    G0: np.ndarray
    Vo: np.ndarray
    Dv: np.ndarray
    eta: fmpq
    lam: fmpq

    @property
    def n(self) -> int:
        return self.A.shape[0]


def qmatmul(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """Exact product of two fmpq object arrays (python-flint's fmpq_mat)."""
    from flint import fmpq_mat

    X = np.asarray(X, dtype=object)
    Y = np.asarray(Y, dtype=object)
    (r, k), c = X.shape, Y.shape[1]
    if r == 0 or c == 0 or k == 0:
        out = np.empty((r, c), dtype=object)
        out[...] = fmpq(0)
        return out
    P = fmpq_mat(r, k, X.reshape(-1).tolist()) * fmpq_mat(k, c, Y.reshape(-1).tolist())
    return np.array(P.entries(), dtype=object).reshape(r, c)


def delta_exact(G: np.ndarray, B1: np.ndarray, Dv: np.ndarray) -> list[fmpq]:
    """δ_i = max_{d ∈ vert D} G_i B1 d exactly (Section III)."""
    if B1.shape[1] == 0 or len(Dv) == 0:
        return [fmpq(0)] * len(G)
    GBD = qmatmul(qmatmul(G, B1), np.asarray(Dv, dtype=object).T)
    return [max(row) for row in GBD.tolist()]


def omega_contained(G: np.ndarray, Vo: np.ndarray) -> tuple[bool, fmpq]:
    """Ω ⊆ {G e <= 1} exactly; returns (ok, max over rows and Ω-vertices of G_i e).

    A float prefilter picks the pairs within :data:`_FILTER` × max |G||V| of the float max
    (far above the float error of any entry), so the exact max over those pairs is the
    exact max."""
    Gf, Vf = po.qfloat(G), po.qfloat(Vo)
    with np.errstate(all="ignore"):
        M = Gf @ Vf.T
        tol = _FILTER * float((np.abs(Gf) @ np.abs(Vf).T).max()) + 1e-300
    if np.all(np.isfinite(M)) and math.isfinite(tol):
        cand = np.argwhere(M >= M.max() - tol)
    else:  # inf − inf = NaN compares False: every pair exactly (statement-vs-check review)
        cand = np.argwhere(np.ones(M.shape, dtype=bool))
    m = max(po.qdot(G[i], Vo[j]) for i, j in cand)
    return m <= 1, m


def exact_zd(V: np.ndarray, c: np.ndarray, eta: fmpq) -> tuple[list[fmpq], list[fmpq]]:
    """(Z_d sorted and distinct, c·V per vertex), exactly (Section III)."""
    cv = [po.qdot(c, v) for v in V]
    zs = sorted([x - eta for x in cv] + [x + eta for x in cv])  # (sort, not a set: fmpq
    return [z for i, z in enumerate(zs) if i == 0 or z != zs[i - 1]], cv  # hashes slowly)


@dataclass
class Theorem31Result:
    """Exact outcome of the Theorem 3.1 check."""

    ok: bool
    factor: fmpq
    zs: list[fmpq]
    vs: list[list[fmpq]]
    #: the exact level max_i(φ_i + G_i v + δ_i) at each z^l where it can reach λ or the
    #: maximum; None where the float bracket proves it below both
    eps: list[fmpq | None]
    worst: int
    n_vertices: int
    exact_lp: int = 0
    notes: list[str] = field(default_factory=list)


def _weight_error(
    t: float | np.ndarray, ca: np.ndarray, cb: np.ndarray, den: np.ndarray
) -> np.ndarray:
    """A rigorous bound on |w − w*| for the float weight w = clip((t − ca)/(cb − ca), 0, 1)
    of an edge crossing, w* = (t* − ca*)/(cb* − ca*) its exact value: t, ca, cb are the
    nearest floats of exact t*, ca*, cb* (relative error ≤ u = 2⁻⁵³ each) and each float
    operation adds one more, so the numerator and the denominator are each within
    e = 4u(|t| + |ca| + |cb|) of their exact values; with |den| > 2e,
    |w − w*| ≤ (e + e·|w*|)/(|den| − e) ≤ 2e/(|den| − e) (|w*| ≤ 1), doubled for margin.
    1 (the whole edge) where the edge is too level in c for that."""
    e = 4.0 * 2.0**-53 * (np.abs(t) + np.abs(ca) + np.abs(cb)) + 2.0**-1070
    gap = np.abs(den) - e
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(np.abs(den) > 2 * e, 4 * e / gap, 1.0)
    return np.minimum(out, 1.0)


#: the spacing of the subnormal doubles: the absolute error of rounding an exact value
#: below 2⁻¹⁰²² to a double (its relative error is then not 2⁻⁵³ but up to 25 %)
_SUBNORMAL_ULP = 2.0**-1074


def _subnormal_slack(aGA: np.ndarray, aP: np.ndarray) -> np.ndarray:
    """The error of G_i A p from rounding subnormal entries of G A and of p to doubles, which
    the relative slack ``_FILTER`` does not cover: (rows, points) ``2·2⁻¹⁰⁷⁴ (|p|₁ + |G_i A|₁)``
    (the entries' rounding errors are at most half an ulp each, a float crossing point's
    coordinates up to two: twice that, so the slack keeps a margin of its own; re-check
    review, session 42). G A ≈ 2.6·2⁻¹⁰⁷⁴ rounded
    to 3·2⁻¹⁰⁷⁴ times a vertex near 10³⁰⁰ reversed the float order of a slice's two ends, the
    true maximizer was skipped and a tampered report certified theorem-3.1 at 0.9 for an
    exact 0.9 + 4.75·10⁻²⁵ (re-check review, session 42).

    :param aGA: |G A| (rows, n); :param aP: |p| per point (points, n)."""
    with np.errstate(over="ignore"):
        return 2 * _SUBNORMAL_ULP * (aP.sum(axis=1)[None, :] + aGA.sum(axis=1)[:, None])


class _Slices:
    """Slices of {G e <= 1} at each z^l: float candidates, exact points on demand.

    For each slab ``|c·e − z| <= η̄`` the candidates are the vertices and edge crossings
    that the float prefilter cannot exclude (threshold 1e-9 relative to the largest compared
    value, far above the float error); a candidate's exact point is computed only when a row
    of φ needs it, and only if it exists exactly (vertex inside the slab, or strict
    crossing). The true maximizer of every needed row is among the candidates within the
    float tolerance of the float max, so the exact φ_i is exact."""

    def __init__(
        self, ex: ExactProblem, G: np.ndarray, vrep: po.ExactVRep, zs: list[fmpq], cv: list[fmpq]
    ):
        self.G = G
        self.GA = qmatmul(G, ex.A)
        self.GAf = po.qfloat(self.GA)
        self.absGA = np.abs(self.GAf)
        self.V = vrep.V
        self.Vf = po.qfloat(vrep.V)
        self.cv = cv
        self.cvf = po.qfloat(np.array(cv, dtype=object))
        self.eta = ex.eta
        self.zs = zs
        e = np.array(vrep.edges, dtype=int).reshape(-1, 2)
        self.ea, self.eb = e[:, 0], e[:, 1]
        ca, cb = self.cvf[self.ea], self.cvf[self.eb]
        emin, emax = np.minimum(ca, cb), np.maximum(ca, cb)
        dV = self.Vf[self.eb] - self.Vf[self.ea]
        #: per z^l: (vertex indices, [edge indices crossing z − η̄, z + η̄]) of the candidates
        self.cands: list[tuple[np.ndarray, list[np.ndarray]]] = []
        self.ptsf: list[np.ndarray] = []
        #: per z^l: each candidate's edge direction (zero for a vertex), a rigorous bound on
        #: the error of its float weight w (1: anywhere on the edge) and whether it certainly
        #: exists exactly (float c-values beyond tol): see :meth:`row_bounds`
        self.ends: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        # every (breakpoint, vertex) and (breakpoint, edge) pair at once (numpy calls per
        # breakpoint cost more than the arithmetic on small polytopes), then split by
        # breakpoint: vertices first, then the crossings of z − η̄, then of z + η̄
        lo = np.array([float(z - ex.eta) for z in zs])
        hi = np.array([float(z + ex.eta) for z in zs])
        # the prefilter's tolerance, relative to the compared floats (c·v, z ± η̄), each the
        # nearest double of its exact value: a comparison errs by at most 2⁻⁵² of the largest
        # of them, far below 1e-9 of it (subnormals: the absolute 2⁻¹⁰⁷⁰). Its old floor of 1
        # put every vertex in every slab when z ~ 1e-9 (C = [[1e-9, 1e-9]]): the float φ and
        # LP (9)'s v^l came from the whole polytope, and Theorem 3.1 failed with 1.18 where
        # C = [[1, 1]] gives 9/10 (unusual-spec trial, session 24)
        scale = max(
            float(np.abs(self.cvf).max(initial=0.0)),
            float(np.abs(lo).max(initial=0.0)),
            float(np.abs(hi).max(initial=0.0)),
        )
        tol = 1e-9 * scale + 2.0**-1070
        nz, n = len(zs), ex.n
        vm = (self.cvf[None, :] >= lo[:, None] - tol) & (self.cvf[None, :] <= hi[:, None] + tol)
        lv, jv = np.nonzero(vm)
        parts = [
            (
                jv,
                np.bincount(lv, minlength=nz),
                self.Vf[jv],
                np.zeros((len(jv), n)),
                np.zeros(len(jv)),
                (self.cvf[jv] >= lo[lv] + tol) & (self.cvf[jv] <= hi[lv] - tol),
            )
        ]
        for T in (lo, hi) if ex.eta != 0 else (lo,):
            lk, k = np.nonzero(
                (emin[None, :] <= T[:, None] + tol) & (emax[None, :] >= T[:, None] - tol)
            )
            t = T[lk]
            den = cb[k] - ca[k]
            with np.errstate(divide="ignore", invalid="ignore"):
                w = np.where(den == 0, 0.5, np.clip((t - ca[k]) / den, 0.0, 1.0))
            parts.append(
                (
                    k,
                    np.bincount(lk, minlength=nz),
                    self.Vf[self.ea[k]] + w[:, None] * dV[k],
                    dV[k],
                    _weight_error(t, ca[k], cb[k], den),
                    (emin[k] < t - tol) & (emax[k] > t + tol),
                )
            )
        cuts = [np.cumsum(c)[:-1] for _, c, *_ in parts]
        split = [
            [np.split(x, cut) for x in part[2:]] + [np.split(part[0], cut)]
            for part, cut in zip(parts, cuts, strict=True)
        ]
        for l in range(nz):
            pts, dirs, errs, sure, idx = zip(*[[a[l] for a in sp] for sp in split], strict=True)
            self.cands.append((idx[0], list(idx[1:])))
            self.ptsf.append(np.concatenate(pts).reshape(-1, n))
            self.ends.append(
                (np.concatenate(dirs).reshape(-1, n), np.concatenate(errs), np.concatenate(sure))
            )
        self._cache: dict[tuple, tuple | None] = {}
        self._phif: dict[int, np.ndarray] = {}
        self._bounds: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def _cand(self, l: int, j: int) -> tuple:
        """The j-th candidate of slice l: ("v", vertex) or ("e", a, b, side)."""
        vj, sides = self.cands[l]
        if j < len(vj):
            return ("v", int(vj[j]))
        j -= len(vj)
        for side, k in enumerate(sides):
            if j < len(k):
                return ("e", int(self.ea[k[j]]), int(self.eb[k[j]]), side)
            j -= len(k)
        raise IndexError(j)  # pragma: no cover

    def _exact_point(self, l: int, cand: tuple) -> tuple | None:
        key = (l, cand)
        if key in self._cache:
            return self._cache[key]
        z = self.zs[l]
        lo, hi = z - self.eta, z + self.eta
        out = None
        if cand[0] == "v":
            j = cand[1]
            if lo <= self.cv[j] <= hi:
                out = tuple(self.V[j])
        else:
            _, a, b, side = cand
            t = hi if side else lo
            da, db = self.cv[a] - t, self.cv[b] - t
            if (da < 0 < db) or (db < 0 < da):
                w = (t - self.cv[a]) / (self.cv[b] - self.cv[a])
                out = tuple(
                    self.V[a][k] + w * (self.V[b][k] - self.V[a][k]) for k in range(self.V.shape[1])
                )
        self._cache[key] = out
        return out

    def phi_float(self, l: int) -> np.ndarray:
        """Float φ(z^l) over the candidates (computed once per breakpoint: ~20 ms for 1000
        facets and points)."""
        if l not in self._phif:
            self._phif[l] = (self.GAf @ self.ptsf[l].T).max(axis=1)
        return self._phif[l]

    def _rad(self, l: int, rows: np.ndarray | slice, cols: np.ndarray | slice) -> np.ndarray:
        """The radius of :meth:`row_bounds` for the given rows and candidates of slice l:
        |G_i A (V_b − V_a)|·err_j (the candidate's weight error) plus the slack ``_FILTER``
        (relative) for the rounding of the float products (~1e-15 relative)."""
        dirs, err, _ = self.ends[l]
        S, D = self.ptsf[l][cols], dirs[cols]
        GA, aGA = self.GAf[rows], self.absGA[rows]
        rad = np.abs(GA @ D.T) * err[cols][None, :]
        rad += _FILTER * (aGA @ (np.abs(S) + np.abs(D)).T) + 1e-300
        rad += _subnormal_slack(aGA, np.abs(S) + np.abs(D))
        return rad

    def cand_up(self, l: int, rows: np.ndarray) -> np.ndarray:
        """Per row i of ``rows`` and candidate j of slice l, a float bound ``up[i, j]`` ≥
        G_i A p_j whatever the float error of the candidate's point: the exact crossing is
        p_j = V_a + w*·(V_b − V_a) with |w* − w| ≤ ``err`` (:func:`_weight_error`; 1 when
        the edge is too level in c to say), so G_i A p_j is within |G_i A (V_b − V_a)|·err
        of its float value (:meth:`_rad`). Only for the given rows: only the rows evaluated
        exactly need it."""
        return self.GAf[rows] @ self.ptsf[l].T + self._rad(l, rows, slice(None))

    def row_bounds(self, l: int) -> tuple[np.ndarray, np.ndarray]:
        """Rigorous row bounds ``phi_up`` ≥ φ_i(z^l) ≥ ``phi_low`` (LP (6); −inf when no
        candidate certainly exists) from one float product over the candidates.

        For the candidates whose weight error is small (≤ ``_PRECISE``: every vertex and
        nearly every crossing) the radius of :meth:`_rad` is bounded row by row by
        |G_i A|·r with r_k = max_j (err_j |d_jk| + _FILTER (|p_jk| + |d_jk|)), which
        dominates every term: max_j (c_ij ± rad_ij) is within max_j c_ij ± |G_i A|·r. The few
        candidates with a large error (an edge nearly level in c) get their own radius. So
        the bounds cost O(rows × candidates) once, not three such products per breakpoint
        (81 of 153 s of a 2372-facet design before)."""
        if l not in self._bounds:
            dirs, err, sure = self.ends[l]
            S = self.ptsf[l]
            m = self.GAf.shape[0]
            up = np.full(m, -np.inf)
            low = np.full(m, -np.inf)
            prec = err <= _PRECISE

            # rows whose float products are not all finite carry no information: an overflow
            # gives an infinity of either sign (−inf for a true +10²⁹⁹), and a max over the
            # others is then a finite number below the truth (float pre-screen review,
            # session 42): such a row gets up = +inf, low = −inf
            blind = np.zeros(m, dtype=bool)

            def cmax(cols: np.ndarray) -> np.ndarray:  # max_j c_ij over the columns (or -inf)
                if not cols.any():
                    return np.full(m, -np.inf)
                M = self.GAf @ S[cols].T
                blind[:] |= ~np.all(np.isfinite(M), axis=1)
                return M.max(axis=1)

            if prec.any():
                Sp, Dp = np.abs(S[prec]), np.abs(dirs[prec])
                r = (err[prec][:, None] * Dp + _FILTER * (Sp + Dp)).max(axis=0)
                radp = self.absGA @ r + 1e-300
                radp += _subnormal_slack(self.absGA, (Sp + Dp).max(axis=0)[None, :])[:, 0]
                sure_max = cmax(prec & sure)
                up = np.maximum(sure_max, cmax(prec & ~sure)) + radp
                low = sure_max - radp
            loose = np.nonzero(~prec)[0]
            if len(loose):
                cen = self.GAf @ S[loose].T
                rad = self._rad(l, slice(None), loose)
                blind |= ~np.all(np.isfinite(cen) & np.isfinite(rad), axis=1)
                up = np.maximum(up, (cen + rad).max(axis=1))
                ls = sure[loose]
                if ls.any():
                    low = np.maximum(low, (cen[:, ls] - rad[:, ls]).max(axis=1))
            blind |= ~np.isfinite(up) | np.isnan(low)
            up = np.where(blind, np.inf, up)
            low = np.where(blind, -np.inf, low)
            self._bounds[l] = (up, low)
        return self._bounds[l]

    def phi_exact(self, l: int, rows=None) -> dict[int, fmpq]:
        """Exact φ_i(z^l) (LP (6)) for the given rows: max of G_i A over the slice vertices
        (only over the candidates whose rigorous upper bound reaches the row's rigorous
        lower bound: :meth:`cand_up`, :meth:`row_bounds`)."""
        _, phi_low = self.row_bounds(l)
        rows = np.arange(len(self.G)) if rows is None else np.asarray(rows, dtype=int)
        up = self.cand_up(l, rows)
        out = {}
        for r, i in enumerate(rows):
            best = None
            # a float bound that is not a number decides nothing: G_i A p of a vertex near
            # 1e299 overflowed to an infinity of the wrong sign (−inf for +T/2), its bound was
            # NaN or −inf, the point was skipped and φ_i taken from the smallest one — verify
            # certified theorem-3.1 for a true level of 5·10²⁹⁸ (float pre-screen review,
            # session 42): such a row keeps every candidate
            row = up[r]
            if np.all(np.isfinite(row)) and math.isfinite(phi_low[i]) or phi_low[i] == -np.inf:
                keep = ~(row < phi_low[i]) | ~np.isfinite(row)
            else:
                keep = np.ones(len(row), dtype=bool)
            for j in np.nonzero(keep)[0]:
                p = self._exact_point(l, self._cand(l, int(j)))
                if p is not None:
                    val = po.qdot(self.GA[i], p)
                    best = val if best is None or val > best else best
            if best is None:
                raise RuntimeError("empty exact slice (internal error)")
            out[int(i)] = best
        return out


def exact_lp9(G: np.ndarray, phi: list[fmpq], dl: list[fmpq]) -> tuple[fmpq, list[fmpq]]:
    """LP (9) solved exactly by cdd.gmp: min ε s.t. φ + G v + δ <= ε 1. Returns (ε, v)."""
    import cdd
    import cdd.gmp as cddg

    fr = po._fr
    n = G.shape[1]
    rows = [
        [-fr(dl[i]) - fr(phi[i])] + [-fr(x) for x in G[i]] + [Fraction(1)] for i in range(len(G))
    ]
    m = cddg.matrix_from_array(
        rows,
        rep_type=cdd.RepType.INEQUALITY,
        obj_type=cdd.LPObjType.MIN,
        obj_func=[Fraction(0)] * (n + 1) + [Fraction(1)],
    )
    lp = cddg.linprog_from_matrix(m)
    cddg.linprog_solve(lp)
    if lp.status != cdd.LPStatusType.OPTIMAL:
        raise RuntimeError(f"exact LP (9) status {lp.status}")
    x = lp.primal_solution
    return po._q(x[n]), [po._q(t) for t in x[:n]]


class BudgetExceeded(Exception):
    """The design's time budget ran out inside :func:`theorem31` (argument: breakpoints
    done)."""


def _solve_v(
    ex: ExactProblem,
    sl: _Slices,
    Gf: np.ndarray,
    phif: np.ndarray,
    dlf: np.ndarray,
    v_solver,
    deadline: float | None,
    v_rows: np.ndarray | None,
):
    """v^l of LP (9) at every breakpoint (see :func:`theorem31`, ``v_rows``); the returned
    ``eps`` is the float level of v^l on all rows of G."""
    if v_rows is None or len(v_rows) >= len(Gf):
        return v_solver(Gf, phif, dlf, deadline=deadline)
    Af, B1f, Dvf = po.qfloat(ex.A), po.qfloat(ex.B1), po.qfloat(ex.Dv)
    GmA = v_rows @ Af
    phim = np.array([(GmA @ sl.ptsf[l].T).max(axis=1) for l in range(len(phif))])
    dlm = (v_rows @ B1f @ Dvf.T).max(axis=1) if B1f.shape[1] and len(Dvf) else np.zeros(len(v_rows))
    try:
        er = v_solver(v_rows, phim.reshape(len(phif), len(v_rows)), dlm, deadline=deadline)
    except (SolverError, InconclusiveError):
        # the float hull's rows do not bound a polytope HiGHS can use (B1 = [1e50, 1]: one
        # row; LP (9) on it is unbounded): all rows of G decide, and raise if they fail too
        return v_solver(Gf, phif, dlf, deadline=deadline)
    er.eps = (phif + dlf[None, :] + er.v @ Gf.T).max(axis=1)
    lamf = float(ex.lam)
    tight = np.nonzero(er.eps > lamf * (1 - 1e-9))[0]
    if len(tight):
        full = v_solver(Gf, phif[tight], dlf, deadline=deadline)
        er.v[tight], er.eps[tight] = full.v, full.eps
    return er


def theorem31(
    ex: ExactProblem,
    G: np.ndarray,
    vs: list[list[fmpq]] | None = None,
    zs_given: list[fmpq] | None = None,
    v_solver=None,
    vrep: po.ExactVRep | None = None,
    deadline: float | None = None,
    v_rows: np.ndarray | None = None,
) -> Theorem31Result:
    """Exact check of Theorem 3.1 for {G e <= 1} (single output).

    With ``vs`` given (verify), every breakpoint of Z_d must be in ``zs_given`` and the check
    uses the given v^l at the Z_d points. Without (design), v^l comes from the float LP (9)
    (``v_solver(G, phi, delta, deadline=...) -> EpsResult``), rounded by :func:`po.snap`, and from an exact
    cdd.gmp LP wherever the rounded v does not pass. ``deadline`` (design only): a
    ``time.perf_counter()`` value checked before each breakpoint (:class:`BudgetExceeded`).
    ``v_rows`` (design only): float rows of the same polytope with near-coplanar facets
    merged (the float hull; fewer rows than the exact G): LP (9) is solved on them, and
    again on all rows of G only at the breakpoints where that v^l does not stay below λ
    with a 10⁻⁹ margin; the exact check below decides either way.
    """
    if vrep is None:
        vrep = po.exact_h_to_v(G)
    c = ex.C[0]
    zs, cv = exact_zd(vrep.V, c, ex.eta)
    dl = delta_exact(G, ex.B1, ex.Dv)
    notes: list[str] = []
    if vs is not None:
        assert zs_given is not None
        pos = {(z.p, z.q): i for i, z in enumerate(zs_given)}
        missing = [z for z in zs if (z.p, z.q) not in pos]
        if missing:
            return Theorem31Result(
                False,
                fmpq(10**9),
                zs,
                [],
                [],
                0,
                len(vrep.V),
                0,
                [f"breakpoint {missing[0]} of Z_d is missing from the injection table"],
            )
        vs_use = [vs[pos[z.p, z.q]] for z in zs]
    sl = _Slices(ex, G, vrep, zs, cv)
    Gf = po.qfloat(G)
    dlf = po.qfloat(np.array(dl, dtype=object))
    if vs is None:
        phif = np.empty((len(zs), len(G)))
        for l in range(len(zs)):
            if deadline is not None and time.perf_counter() > deadline:
                raise BudgetExceeded(0)
            phif[l] = sl.phi_float(l)
        try:
            er = _solve_v(ex, sl, Gf, phif, dlf, v_solver, deadline, v_rows)
        except Timeout:
            raise BudgetExceeded(0) from None
        vs_use = [[po.snap(x) for x in er.v[l]] for l in range(len(zs))]
    absG = np.abs(Gf)
    lamf = float(ex.lam)
    nz = len(zs)
    # float level of every breakpoint, bracketed: hi[l] >= the exact level > lo[l] (the
    # margin _FILTER is far above the float error); exact work only where it can matter
    fl_rows = []
    hi, lo = np.empty(nz), np.empty(nz)
    for l in range(nz):
        vf = po.qfloat(np.array(vs_use[l], dtype=object))
        if deadline is not None and time.perf_counter() > deadline:
            raise BudgetExceeded(0)
        phi_up, phi_low = sl.row_bounds(l)
        rest = Gf @ vf + dlf
        tol = _FILTER * (np.abs(phi_up) + absG @ np.abs(vf) + np.abs(dlf) + 1.0)
        up, low = phi_up + rest + tol, phi_low + rest - tol  # low may be -inf
        fl_rows.append((up, low))
        hi[l], lo[l] = float(up.max()), float(low.max())
    eps_l: list[fmpq | None] = [None] * nz
    out_vs: list[list[fmpq]] = [list(v) for v in vs_use]
    n_exact = 0

    def exact_at(l: int) -> None:
        nonlocal n_exact
        if deadline is not None and time.perf_counter() > deadline:
            raise BudgetExceeded(sum(e is not None for e in eps_l))
        v = vs_use[l]
        up, low = fl_rows[l]
        top = float(low.max())
        thr = min(lamf, top) if math.isfinite(top) else -math.inf
        # every row that can reach the level or λ; a bound that is not a finite number (inf
        # − inf, or an overflow to an infinity of the wrong sign) is a row to evaluate
        rows = np.nonzero(~(up < thr) | ~np.isfinite(up))[0]
        ph = sl.phi_exact(l, rows)
        e = max(ph[i] + po.qdot(G[i], v) + dl[i] for i in ph)
        # the exact LP only helps where the float LP says ε(z) <= λ and rounding broke it;
        # where the float optimum is already above λ (a non-converged polyhedron) it cannot
        # pass and costs ~0.4 s per breakpoint
        if e > ex.lam and vs is None and er.eps[l] <= lamf * (1 + 1e-9):
            phall = sl.phi_exact(l)
            e, v = exact_lp9(G, [phall[i] for i in range(len(G))], dl)
            n_exact += 1
        eps_l[l] = e
        out_vs[l] = list(v)

    # The float brackets decide only where they are numbers: an injection value of 1e308
    # made G v = inf − inf = NaN, every comparison with it False, no breakpoint was evaluated
    # exactly and the factor fell back to 0 — a tampered report with a true factor of
    # 2·10³⁰⁹ verified (statement-vs-check review, session 42). NaN counts as "may exceed".
    # 1. every breakpoint whose level may exceed λ (where the exact LP may replace v^l)
    # (an overflow may also give an infinity of the wrong sign: −inf is no proof either)
    for l in np.nonzero(~(hi <= lamf) | ~np.isfinite(hi))[0]:
        exact_at(int(l))
    # 2. every breakpoint whose level may reach the largest: the certified factor is exact;
    #    the others are provably below it (and below λ)
    floor = max(
        [float_or_inf(e) for e in eps_l if e is not None]
        + [float(lo[l]) for l in range(nz) if eps_l[l] is None and math.isfinite(lo[l])],
        default=-math.inf,
    )
    for l in range(nz):
        if eps_l[l] is None and not (math.isfinite(hi[l]) and hi[l] < floor):
            exact_at(l)
    done = [l for l in range(nz) if eps_l[l] is not None]
    if nz and not done:  # (every level bracketed below another: impossible; never factor 0)
        for l in range(nz):
            exact_at(l)
        done = list(range(nz))
    worst = max(done, key=lambda k: eps_l[k]) if done else 0
    factor = eps_l[worst] if done else fmpq(0)
    return Theorem31Result(
        factor <= ex.lam, factor, zs, out_vs, eps_l, worst, len(vrep.V), n_exact, notes
    )


def linear_law(ex: ExactProblem, G: np.ndarray, V: np.ndarray, L: np.ndarray) -> tuple[bool, fmpq]:
    """Exact check of the linear injection v = L z on {G e <= 1} with vertices V:
    max over vertices e, noise vertices η (|η_k| = η̄) and rows i of
    ``G_i (A + L C) e + G_i L η + δ_i`` must be <= λ (proof of Proposition 7.1).
    Returns (ok, the certified factor)."""
    M = ex.A + qmatmul(L, ex.C)
    GM = qmatmul(G, M)
    GL = qmatmul(G, L)
    dl = delta_exact(G, ex.B1, ex.Dv)
    best = None
    for i in range(len(G)):
        noise = sum((abs(x) for x in GL[i]), fmpq(0)) * ex.eta
        m = max(po.qdot(GM[i], v) for v in V) + noise + dl[i]
        best = m if best is None or m > best else best
    assert best is not None
    return best <= ex.lam, best


def noise_vertices(p: int, eta: fmpq) -> list[tuple[fmpq, ...]]:
    """Vertices of the noise box {|η_k| <= η̄}."""
    return list(product(*[(-eta, eta)] * p))
