"""Float-only mode of the set-invariant method: no ``cdd.gmp`` (e.g. pycddlib-standalone).

Issue 4 item 1: where only the float ``cdd`` is installed, the design still runs and its
claims are marked ``numerical``, never certified. The iterations already run in float64
(:mod:`.algorithms`); here the final polytope is taken as a float hull (qhull, outward-fixed:
Ω's vertices are in the cloud, so it contains Ω up to rounding), Theorem 3.1 is evaluated at
the float Z_d with the float LP (9), and :func:`certify` re-checks the same claim ids as the
exact certificate, in float64, with the relative tolerance :data:`TOL`. The switch is
:data:`obsdesign.sets.polytope_ops.HAVE_GMP`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linprog

from obsdesign.certify.claim import Claim, numerical_claim
from obsdesign.params import Parameters
from obsdesign.sets import polytope_ops as po
from obsdesign.spec.models import Spec

from . import laws, lps
from .algorithms import Problem
from .linear import GainSet

TOL = 1e-9  # relative tolerance of every float64 check (float error is ~1e-15 relative)
CHECK = f"float64, relative tolerance {TOL:g} (cdd.gmp not installed: not certified)"
NOTE = (
    "cdd.gmp is not installed (only the float cdd, e.g. pycddlib-standalone): the design ran "
    f"in float64 and every claim was checked in float64 with relative tolerance {TOL:g}, so "
    "the claims are 'numerical', not certified; install pycddlib with cdd.gmp to certify"
)


@dataclass
class FloatVRep:
    """Float vertices and a superset of the edges (triangulation edges of qhull)."""

    V: np.ndarray
    edges: np.ndarray


@dataclass
class FloatT31:
    """Float outcome of the Theorem 3.1 check (same fields as the exact result)."""

    ok: bool
    factor: float
    zs: np.ndarray
    vs: np.ndarray
    eps: np.ndarray
    worst: int
    n_vertices: int
    exact_lp: int = 0
    notes: list[str] = field(default_factory=list)


def omega_vertices(fl: Problem) -> np.ndarray:
    """Float vertices of Ω = {G0 e <= 1}."""
    return po.h_to_v(fl.G0).V


def theorem31_float(
    fl: Problem,
    G: np.ndarray,
    vrep: FloatVRep,
    lam: float,
    vs_given: np.ndarray | None = None,
    zs_given: np.ndarray | None = None,
) -> FloatT31:
    """Theorem 3.1 in float64: ``φ(z^l) + G v^l + δ <= λ(1 + TOL)`` at every z^l of Z_d.

    Without ``vs_given`` (design) v^l is the float LP (9) optimum; with it (verify) every
    point of Z_d must be in ``zs_given`` (within TOL) and its v^l is used."""
    c = fl.C[0]
    V, edges = vrep.V, vrep.edges
    zs = lps.z_d(V, c, fl.eta)
    dl = lps.delta(G, fl.B1, fl.Dv)
    phi, _ = lps.phi_at(G, fl.A, V, edges, c, fl.eta, zs)
    if vs_given is None:
        vs = lps.eps_batch(G, phi, dl).v
    else:
        zg = np.asarray(zs_given, dtype=float).reshape(-1)
        scale = max(1.0, float(np.abs(zg).max()) if len(zg) else 1.0)
        vs = np.empty((len(zs), G.shape[1]))
        for l, z in enumerate(zs):
            k = int(np.argmin(np.abs(zg - z))) if len(zg) else -1
            if k < 0 or abs(zg[k] - z) > TOL * scale:
                return FloatT31(
                    False,
                    float("inf"),
                    zs,
                    np.zeros((0, G.shape[1])),
                    np.zeros(0),
                    0,
                    len(V),
                    0,
                    [f"breakpoint {z:.9g} of Z_d is missing from the injection table"],
                )
            vs[l] = vs_given[k]
    eps = (phi + dl[None, :] + vs @ G.T).max(axis=1) if len(zs) else np.zeros(0)
    worst = int(np.argmax(eps)) if len(zs) else 0
    factor = float(eps[worst]) if len(zs) else 0.0
    return FloatT31(factor <= lam * (1 + TOL), factor, zs, vs, eps, worst, len(V))


def float_stage(
    fl: Problem, P: np.ndarray, lam: float
) -> tuple[np.ndarray, FloatT31 | None, FloatVRep]:
    """Float counterpart of the exact stage: the hull of Ω's vertices and the cloud ``P``
    (outward-fixed, so it contains both) and, for one output, Theorem 3.1 in float64."""
    Vo = omega_vertices(fl)
    P = np.asarray(P, dtype=float).reshape(-1, fl.n)
    near = np.array([np.abs(Vo - p).max(axis=1).min() <= 1e-9 for p in P], dtype=bool)
    st = po.hull(np.vstack([Vo, P[~near]]))
    vrep = FloatVRep(st.V, st.edges)
    if fl.p != 1:
        return st.G, None, vrep
    return st.G, theorem31_float(fl, st.G, vrep, lam), vrep


def linear_factor(fl: Problem, G: np.ndarray, V: np.ndarray, L: np.ndarray) -> float:
    """max over rows i and vertices e of G_i (A + L C) e + |G_i L| η̄ + δ_i (float64)."""
    GM = G @ (fl.A + L @ fl.C)
    noise = np.abs(G @ L).sum(axis=1) * fl.eta
    return float(((GM @ V.T).max(axis=1) + noise + lps.delta(G, fl.B1, fl.Dv)).max())


def float_gains(fl: Problem, lam: float, G: np.ndarray, V: np.ndarray) -> GainSet:
    """A linear gain in the admissible set (max-margin HiGHS LP), checked in float64 only;
    the admissible set's vertices are not enumerated (that needs cdd.gmp)."""
    n, p = fl.n, fl.p
    etas = (
        np.array(np.meshgrid(*[[-fl.eta, fl.eta]] * p)).reshape(p, -1).T
        if fl.eta > 0
        else np.zeros((1, p))
    )
    dl = lps.delta(G, fl.B1, fl.Dv)
    GAV = G @ fl.A @ V.T  # (rows, vertices)
    CV = V @ fl.C.T  # (vertices, p)
    rows, rhs = [], []
    for eta in etas:
        W = CV + eta  # (vertices, p)
        # a[r*p + k] = G[i, r] * W[j, k]
        a = np.einsum("ir,jk->ijrk", G, W).reshape(len(G) * len(V), n * p)
        rows.append(a)
        rhs.append((lam - dl[:, None] - GAV).reshape(-1))
    Af, bf = np.vstack(rows), np.concatenate(rhs)
    norms = np.linalg.norm(Af, axis=1)
    c = np.zeros(n * p + 1)
    c[-1] = -1.0
    res = linprog(
        c,
        A_ub=np.hstack([Af, norms[:, None]]),
        b_ub=bf,
        bounds=[(None, None)] * (n * p) + [(None, 1.0)],
        method="highs",
    )
    if res.status != 0 or res.x[-1] < -TOL:
        return GainSet(None, None, "the admissible set of linear gains is empty (float LP)")
    L = res.x[: n * p].reshape(n, p)
    f = linear_factor(fl, G, V, L)
    if f > lam * (1 + TOL):
        return GainSet(None, None, f"the float LP gain does not pass the float check ({f:.9g})")
    return GainSet(
        L,
        f,
        "max-margin point of the admissible set (float LP; its vertices are not enumerated "
        "without cdd.gmp)",
        margin=float(res.x[-1]),
    )


# =============================================================================== certify


def _rows_match(A: np.ndarray, B: np.ndarray, tol: float) -> tuple[int, int]:
    """(rows of A with no row of B within tol, rows of B with no row of A within tol)."""
    if len(A) == 0 or len(B) == 0:
        return len(A), len(B)
    D = np.abs(A[:, None, :] - B[None, :, :]).max(axis=2)
    return int((D.min(axis=1) > tol).sum()), int((D.min(axis=0) > tol).sum())


def certify(spec: Spec, params: Parameters, fl: Problem, ref: str) -> list[Claim]:
    """The claims of the exact certificate, evaluated in float64 (status ``numerical``)."""
    o = spec.options
    s = spec.system
    lam = float(o.lam)
    claims: list[Claim] = []

    def add(cid: str, statement: str, reference: str, ok: bool, detail: str) -> None:
        claims.append(numerical_claim(cid, statement, reference, CHECK, TOL, bool(ok), detail))

    for k in ("G", "V"):
        if k not in params:
            add(f"{k}-present", f"the report gives {k}", "report", False, f"{k} missing")
            return claims
    try:
        G = np.asarray(params.float("G"), dtype=float).reshape(-1, s.n)
        V = np.asarray(params.float("V"), dtype=float).reshape(-1, s.n)
    except (TypeError, ValueError) as e:
        add("G-present", "the report gives G and V as matrices", "report", False, str(e))
        return claims
    lam_r = params.get("lambda")
    try:
        lam_ok = lam_r is not None and float(lam_r) == lam
    except (TypeError, ValueError):
        lam_ok = False
    if not lam_ok:
        add(
            "lambda-matches-spec",
            "the report's λ is the spec's λ",
            "spec [method].lambda",
            False,
            f"report λ = {lam_r}, spec λ = {o.lam}",
        )
    gs = TOL * max(1.0, float(np.abs(G).max()) if G.size else 1.0)
    try:
        st = po.hull(V)
        a, b = _rows_match(st.G, G, gs)
        ok = len(st.V) == len(V) and a == 0 and b == 0 and len(st.G) == len(G)
        detail = (
            f"{len(V)} vertices, {len(G)} facets (V- and H-forms agree within {TOL:g})"
            if ok
            else f"float hull of V: {len(st.V)} of {len(V)} points are vertices; {a} facet(s) "
            f"not in G, {b} row(s) of G not facets of conv(V) (tolerance {TOL:g})"
        )
    except po.PolytopeError as e:
        st, ok, detail = None, False, str(e)
    add(
        "polyhedron-forms",
        "{e : G e <= 1} = conv(V): a bounded polytope with the origin inside, given by its facets G and vertices V",
        f"{ref}, Section III",
        ok,
        detail,
    )
    if not ok or st is None:
        return claims
    vrep = FloatVRep(V, st.edges)
    m = float((G @ omega_vertices(fl).T).max())
    add(
        "omega-contained",
        "Ω ⊆ {e : G e <= 1}",
        f"{ref}, Section V (C^0 = Ω ⊆ C^i)",
        m <= 1 + TOL,
        f"max G_i e over Ω's vertices = {m:.12g}",
    )
    dl = lps.delta(G, fl.B1, fl.Dv)
    m = float(dl.max()) if len(dl) else 0.0
    add(
        "necessary-condition",
        "λ·{G e <= 1} ⊇ B1·D (necessary condition of Section II)",
        f"{ref}, Section II",
        m <= lam * (1 + TOL),
        f"max = {m:.12g}, λ = {lam:g}",
    )
    if s.p == 1 and "breakpoints" in params and "v_breakpoints" in params:
        zs = np.asarray(params.float("breakpoints"), dtype=float).reshape(-1)
        vs = np.asarray(params.float("v_breakpoints"), dtype=float).reshape(len(zs), s.n)
        res = theorem31_float(fl, G, vrep, lam, vs_given=vs, zs_given=zs)
        add(
            "theorem-3.1",
            f"{{G e <= 1}} is D-(C,A)-λ-contractive with λ = {o.lam}: φ(z^l) + G v^l + δ <= λ·1 at every z^l ∈ Z_d",
            f"{ref}, Theorem 3.1 and LPs (6), (9)",
            res.ok,
            (
                f"max over {len(res.zs)} breakpoints of max_i(φ_i(z) + G_i v + δ_i) = {res.factor:.12g} "
                f"(λ = {lam:g}, tolerance λ·{TOL:g}); worst z = {float(res.zs[res.worst]):.6g}"
                if not res.notes
                else "; ".join(res.notes)
            ),
        )
        if "contractivity" in params and not res.notes:
            c = params.get("contractivity")
            try:
                cf = float(c)
            except (TypeError, ValueError):
                cf = float("nan")
            add(
                "contractivity-value",
                "the reported contractivity equals the factor max_l max_i(φ_i + G_i v^l + δ_i)",
                f"{ref}, Theorem 3.1",
                abs(cf - res.factor) <= TOL * max(1.0, abs(res.factor)),
                f"reported {cf:.12g}, recomputed {res.factor:.12g}",
            )
        if "L_pieces" in params and "w_pieces" in params:
            Ls, ws = laws.pieces(list(zs), [list(r) for r in vs])
            Lr = np.asarray(params.float("L_pieces"), dtype=float).reshape(-1)
            wr = np.asarray(params.float("w_pieces"), dtype=float).reshape(-1)
            La, wa = np.array(Ls, dtype=float).reshape(-1), np.array(ws, dtype=float).reshape(-1)
            okp = (
                Lr.shape == La.shape
                and wr.shape == wa.shape
                and bool(np.all(np.abs(Lr - La) <= TOL * np.maximum(1.0, np.abs(La))))
                and bool(np.all(np.abs(wr - wa) <= TOL * np.maximum(1.0, np.abs(wa))))
            )
            add(
                "injection-table",
                "L^j, w^j are the interpolation (12) of v^j: L^j = (v^{j+1} − v^j)/(z^{j+1} − z^j), w^j = v^j − z^j L^j",
                f"{ref}, Proposition 4.1",
                okp,
                f"{len(Ls)} segments",
            )
    elif s.p == 1:
        add("theorem-3.1", "Theorem 3.1", ref, False, "the report has no breakpoint table")
    for key, label in (("L", "designed"), ("L_user", "given in the spec")):
        if key in params:
            L = np.asarray(params.float(key), dtype=float).reshape(s.n, s.p)
            f = linear_factor(fl, G, V, L)
            add(
                f"linear-law{'-user' if key == 'L_user' else ''}",
                f"the linear injection v = L z ({label}) keeps {{G e <= 1}} λ-contractive: |G(A + L C) e + G L η| + δ <= λ",
                f"{ref}, Proposition 7.1",
                f <= lam * (1 + TOL),
                f"factor {f:.12g} (λ = {lam:g}, tolerance λ·{TOL:g})",
            )
    if o.L is not None and "L_user" not in params:
        add("linear-law-user", "the spec's L is checked", ref, False, "the report lacks L_user")
    if s.p != 1 and "L" not in params:
        add(
            "linear-law",
            "a linear injection keeps the polyhedron λ-contractive (Proposition 7.1)",
            f"{ref}, Proposition 7.1",
            False,
            "no admissible linear gain was found",
        )
    if params.get("converged") is False:
        add(
            "converged",
            "the algorithm converged within max_iterations",
            f"{ref}, Sections V-VI",
            False,
            f"not converged after {params.get('iterations')} iterations",
        )
    return claims
