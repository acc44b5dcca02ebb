"""Units of the float stages: the design runs in coordinates where Ω has unit extent.

The set-invariant design (Dórea & Pimenta, "Design of set-invariant estimators for linear
discrete-time systems", Sections III, V-VI) is invariant under a change of state
coordinates e = S ẽ with S = diag(s) > 0: the error dynamics (3) become
ẽ⁺ = S⁻¹AS ẽ + S⁻¹B1 d + S⁻¹v(z), z = CS ẽ + η, Ω becomes {G0 S ẽ <= 1}, and a polyhedron
{G̃ ẽ <= 1} = conv(Ṽ) with injections ṽ^l at the breakpoints of Z_d is, in the spec's
coordinates, {G̃S⁻¹ e <= 1} = conv(SṼ) with v^l = S ṽ^l. The outputs z, the breakpoints
Z_d, δ_i = max_d G_i B1 d, φ_i(z) and the certified factor are unchanged.

The float stages (LPs, qhull, the snap of float vertices to short rationals) are not
scale-free: a random 2-state system certified with 10 facets and, rescaled exactly by
10⁶, did not converge. So the design scales each coordinate by Ω's exact extent
s_i = max over Ω's vertices of |e_i| (an exact rational: a diagonally rescaled spec then
gives exactly the same scaled problem, hence the same design), runs every stage there and
maps the proved polytope back exactly. ``certify`` and ``verify`` work in the spec's
coordinates only.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from flint import fmpq

from obsdesign.sets import polytope_ops as po

from .algorithms import Problem
from .certificate import ExactProblem, Theorem31Result
from .linear import GainSet
from .problem import Data


def omega_extents(Vo: np.ndarray) -> list[fmpq]:
    """s_i = max over Ω's exact vertices of |e_i| (> 0: the origin is interior to Ω)."""
    V = np.asarray(Vo, dtype=object)
    return [max(abs(x) for x in V[:, i]) for i in range(V.shape[1])]


def _floats(M: np.ndarray) -> np.ndarray | None:
    """Floats of an exact array, or None when one is beyond the float range."""
    try:
        out = po.qfloat(M)
    except OverflowError:
        return None
    return out if np.isfinite(out).all() else None


def scaled(data: Data) -> tuple[Data, list[fmpq] | None]:
    """The problem in the coordinates ẽ = S⁻¹e, S = diag(:func:`omega_extents`), and s; the
    data unchanged (and None) when S = I, without the exact problem (float-only mode), or
    when a scaled entry leaves the float range."""
    ex = data.ex
    if ex is None:
        return data, None
    s = omega_extents(ex.Vo)
    if all(x == 1 for x in s):
        return data, None
    n = ex.n
    A = np.array([[ex.A[i, j] * s[j] / s[i] for j in range(n)] for i in range(n)], dtype=object)
    A = A.reshape(n, n)
    B1 = np.array([[x / s[i] for x in ex.B1[i]] for i in range(n)], dtype=object)
    B1 = B1.reshape(ex.B1.shape)
    C = np.array([[r[j] * s[j] for j in range(n)] for r in ex.C], dtype=object)
    C = C.reshape(ex.C.shape)
    G0 = po.canonical(scale_columns(ex.G0, s))
    Vo = np.array([[v[i] / s[i] for i in range(n)] for v in ex.Vo], dtype=object)
    Vo = Vo.reshape(ex.Vo.shape)
    fl = [_floats(M) for M in (A, B1, C, G0)]
    if any(f is None for f in fl):
        return data, None
    Af, B1f, Cf, G0f = fl
    ex_s = ExactProblem(A, B1, C, G0, Vo, ex.Dv, ex.eta, ex.lam)
    fl_s = Problem(Af, B1f, Cf, G0f, data.fl.Dv, data.fl.eta)
    return Data(fl_s, ex_s), s


def scale_columns(G: np.ndarray, s: list[fmpq]) -> np.ndarray:
    """G·diag(s) exactly (the rows of a polyhedron {G e <= 1} in ẽ = S⁻¹e are G S)."""
    G = np.asarray(G, dtype=object)
    out = np.array([[r[j] * s[j] for j in range(len(s))] for r in G], dtype=object)
    return out.reshape(G.shape)


def unscale_rows(G: np.ndarray, s: list[fmpq]) -> np.ndarray:
    """The rows G̃S⁻¹ of {G̃ ẽ <= 1} in the spec's coordinates e = Sẽ, in the same order (so
    a row index, e.g. Proposition 7.1's Q_I, names the same facet in both)."""
    return scale_columns(G, [1 / x for x in s])


def unscale_gain(L: np.ndarray, s: list[fmpq]) -> np.ndarray:
    """A gain of v = L z in the spec's coordinates: v = S ṽ, so L = S L̃ (row i times s_i)."""
    L = np.asarray(L, dtype=object)
    out = np.array([[x * s[i] for x in row] for i, row in enumerate(L)], dtype=object)
    return out.reshape(L.shape)


def unscale_gains(gs: GainSet, s: list[fmpq]) -> GainSet:
    """The admissible linear gains (Proposition 7.1) found in ẽ, in the spec's coordinates:
    every gain L = S L̃; the factor, the dimension and the row indices are unchanged."""
    return dataclasses.replace(
        gs,
        L=None if gs.L is None else unscale_gain(gs.L, s),
        vertices=[unscale_gain(v, s) for v in gs.vertices],
        prop71=[(i, unscale_gain(Lp, s)) for i, Lp in gs.prop71],
    )


def unscale_points(V: np.ndarray, s: list[fmpq]) -> np.ndarray:
    """The points S ṽ (rows) of exact points ṽ (rows), in the same order."""
    V = np.asarray(V, dtype=object)
    return scale_columns(V, s)


def unscale_result(res: Theorem31Result | None, s: list[fmpq]) -> Theorem31Result | None:
    """Theorem 3.1's result in the spec's coordinates: v^l = S ṽ^l; Z_d, the levels and the
    factor are unchanged (φ_i, G_i v and δ_i are invariant)."""
    if res is None:
        return None
    vs = [[x * s[i] for i, x in enumerate(v)] for v in res.vs]
    return dataclasses.replace(res, vs=vs, notes=list(res.notes))
