"""Polytopes in H-form {x : G x <= g}, and symmetric polytopes {x : |Q x| <= 1}.

Vertex enumeration goes through pycddlib: exact with ``cdd.gmp`` (rationals in, rationals
out) for certificates, float ``cdd`` for speed elsewhere. Whether exact cdd is available is
decided by one switch, :data:`obsdesign.sets.polytope_ops.HAVE_GMP` (read at call time, so a
test can turn it off); without it :func:`vertices_exact` raises and :func:`check_polytope_q`
decides boundedness and emptiness with HiGHS LPs instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, to_float
from obsdesign.sets import polytope_ops as po
from obsdesign.sets.base import ConvexSet, float_view


def _frac(q: fmpq) -> Fraction:
    return Fraction(int(q.p), int(q.q))


def vertices_exact(G_q: np.ndarray, g_q: np.ndarray) -> tuple[np.ndarray, bool]:
    """Exact vertices of {G x <= g} by cdd.gmp; returns (vertices (k, n) of fmpq, bounded).

    Raises :class:`~obsdesign.sets.polytope_ops.PolytopeError` when cdd.gmp is not available
    (:data:`~obsdesign.sets.polytope_ops.HAVE_GMP` is False)."""
    if not po.HAVE_GMP:
        raise po.PolytopeError("cdd.gmp is not available: exact vertex enumeration is disabled")
    import cdd
    import cdd.gmp

    rows = [[_frac(g_q[i])] + [-_frac(v) for v in G_q[i]] for i in range(G_q.shape[0])]
    mat = cdd.gmp.matrix_from_array(rows, rep_type=cdd.RepType.INEQUALITY)
    gen = cdd.gmp.copy_generators(cdd.gmp.polyhedron_from_matrix(mat))
    verts, bounded = [], not gen.lin_set
    for r in gen.array:
        if r[0] == 0:
            bounded = False
        else:
            verts.append([Q(v) / Q(r[0]) for v in r[1:]])
    n = G_q.shape[1]
    return np.array(verts, dtype=object).reshape(len(verts), n), bounded


def vertices_float(G: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, bool]:
    """Float vertices of {G x <= g} by float cdd; returns (vertices, bounded)."""
    import cdd

    rows = np.hstack([np.asarray(g, float).reshape(-1, 1), -np.asarray(G, float)])
    mat = cdd.matrix_from_array(rows.tolist(), rep_type=cdd.RepType.INEQUALITY)
    gen = cdd.copy_generators(cdd.polyhedron_from_matrix(mat))
    arr = np.array(gen.array, dtype=float).reshape(-1, G.shape[1] + 1)
    bounded = not gen.lin_set and bool(np.all(arr[:, 0] != 0)) if len(arr) else True
    verts = arr[arr[:, 0] != 0]
    return verts[:, 1:] / verts[:, :1], bounded


def check_polytope_q(G_q: np.ndarray, g_q: np.ndarray) -> tuple[bool, bool, bool]:
    """(non-empty, bounded, exact) for {G x <= g}.

    With cdd.gmp (:data:`~obsdesign.sets.polytope_ops.HAVE_GMP`) this is decided exactly by
    vertex enumeration (``exact`` True). Without it, by HiGHS LPs in float64 (``exact`` False):
    non-empty when ``G x <= g`` is feasible, bounded when ``±x_k`` is bounded above on it for
    every coordinate k. A set empty or unbounded only within float rounding may be misjudged.
    """
    if po.HAVE_GMP:
        verts, bounded = vertices_exact(G_q, g_q)
        # a line or ray means non-empty (cdd gives no vertex for a polyhedron with a line)
        return len(verts) > 0 or not bounded, bounded and len(verts) > 0, True
    from scipy.optimize import linprog

    G = np.asarray(to_float(G_q), dtype=float).reshape(len(g_q), -1)
    g = np.asarray(to_float(np.asarray(g_q, dtype=object)), dtype=float).reshape(-1)
    n = G.shape[1]
    free = [(None, None)] * n
    feas = linprog(np.zeros(n), A_ub=G, b_ub=g, bounds=free, method="highs")
    if feas.status == 2:
        return False, True, False
    if feas.status != 0:
        return True, False, False
    for k in range(n):
        for sgn in (1.0, -1.0):
            c = np.zeros(n)
            c[k] = -sgn  # maximize sgn * x_k
            r = linprog(c, A_ub=G, b_ub=g, bounds=free, method="highs")
            if r.status != 0:  # 3: unbounded (anything else: treat as not proven bounded)
                return True, False, False
    return True, True, False


@dataclass(frozen=True, eq=False)
class Polytope(ConvexSet):
    """{x : G x <= g} with exact data ``G_q`` (m × n) and ``g_q`` (m), object arrays of fmpq;
    ``G`` and ``g`` (always 1-D) are their float views."""

    G_q: np.ndarray
    g_q: np.ndarray
    kind = "polytope"
    G = float_view("G_q")
    g = float_view("g_q", flat=True)

    @property
    def dim(self) -> int:
        return self.G_q.shape[1]

    def h_form_q(self) -> tuple[np.ndarray, np.ndarray]:
        return self.G_q, self.g_q

    def contains(self, x: np.ndarray, tol: float = 1e-12) -> np.ndarray | bool:
        x = np.asarray(x, dtype=float)
        return np.all(x @ self.G.T <= self.g + tol, axis=-1)

    def contains_rel(self, x: np.ndarray, rel: float = 1e-9) -> np.ndarray | bool:
        """G_i x ≤ g_i + rel·(the polytope's width along row i, max − min of G_i v over its
        vertices) + four float spacings, row by row: independent of how the rows are scaled
        and of a thin direction (the widest side's slack let a polytope 10¹² times thinner
        across one face pass points 8× outside; re-check trial, session 34)."""
        x = np.asarray(x, dtype=float)
        proj = self.vertices() @ self.G.T
        mag = np.maximum(np.abs(proj).max(axis=0), np.abs(self.g))
        slack = rel * (proj.max(axis=0) - proj.min(axis=0)) + 4 * np.spacing(mag)
        return np.all(x @ self.G.T <= self.g + slack, axis=-1)

    def vertices_q(self) -> np.ndarray:
        """Exact vertices (cdd.gmp)."""
        G, g = self.h_form_q()
        return vertices_exact(G, g)[0]

    def vertices(self) -> np.ndarray:
        """Float vertices (float cdd); the exact ones in floats where float cdd finds a
        "numerical inconsistency" (a thin, sheared polytope: simulate's membership flag was
        exit 3 for a valid X̂ before session 35)."""
        try:
            return vertices_float(self.G, self.g)[0]
        except RuntimeError:
            if not po.HAVE_GMP:
                raise
            return np.asarray(to_float(self.vertices_q()), dtype=float).reshape(-1, self.dim)

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        v = self.vertices()
        return v.min(axis=0), v.max(axis=0)


@dataclass(frozen=True, eq=False)
class SymmetricPolytope(Polytope):
    """{x : |Q x| <= 1} (componentwise), i.e. G = [Q; -Q], g = 1."""

    kind = "symmetric-polytope"

    @classmethod
    def from_Q(cls, Q_q: np.ndarray) -> SymmetricPolytope:
        G = np.vstack([Q_q, -Q_q])
        g = np.array([fmpq(1)] * G.shape[0], dtype=object)
        return cls(G, g)

    @property
    def Q_q(self) -> np.ndarray:
        return self.G_q[: self.G_q.shape[0] // 2]
