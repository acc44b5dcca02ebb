"""Float-only mode of the set-invariant method: no ``cdd.gmp`` (e.g. pycddlib-standalone).

Issue 4 item 1: where only the float ``cdd`` is installed, the design still runs and its
claims are marked ``numerical``, never certified. The iterations already run in float64
(:mod:`.algorithms`); here the final polytope is taken as a float hull (qhull, outward-fixed:
Ω's vertices are in the cloud, so it contains Ω up to rounding), Theorem 3.1 is evaluated at
the float Z_d with the float LP (9); the claims (one table, :mod:`.claims`) are then checked by
its float backend, built on the functions here, with the relative tolerance :data:`TOL`. The
switch is :data:`obsdesign.sets.polytope_ops.HAVE_GMP`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linprog

from obsdesign.sets import polytope_ops as po

from . import lps
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
    tol = 1e-9 * np.abs(Vo).max(axis=0)  # relative to Ω's extent, as in design.final_stage
    near = np.array([(np.abs(Vo - p) <= tol).all(axis=1).any() for p in P], dtype=bool)
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


def gain_constraints(
    fl: Problem, lam: float, G: np.ndarray, V: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Rows a·vec(L) <= b of the admissible set of linear gains (proof of Proposition 7.1),
    in float64: G_i (A + L C) e + G_i L η + δ_i <= λ at every vertex e and noise vertex η."""
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
    return np.vstack(rows), np.concatenate(rhs)


def float_gains(fl: Problem, lam: float, G: np.ndarray, V: np.ndarray) -> GainSet:
    """A linear gain in the admissible set (max-margin HiGHS LP), checked in float64 only;
    the admissible set's vertices are not enumerated (that needs cdd.gmp)."""
    n, p = fl.n, fl.p
    Af, bf = gain_constraints(fl, lam, G, V)
    with np.errstate(over="ignore", invalid="ignore"):
        norms = np.linalg.norm(Af, axis=1)
    A_lp = np.hstack([Af, norms[:, None]])
    if not lps.lp_in_range(A_lp, bf):
        return GainSet(None, None, "the linear-gain LP's data are beyond a float LP's range")
    c = np.zeros(n * p + 1)
    c[-1] = -1.0
    res = linprog(
        c,
        A_ub=A_lp,
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
