"""Polytopes in H-form {x : G x <= g}, and symmetric polytopes {x : |Q x| <= 1}.

Vertex enumeration goes through pycddlib: exact with ``cdd.gmp`` (rationals in, rationals
out) for certificates, float ``cdd`` for speed elsewhere. Whether exact cdd is available is
decided by one switch, :data:`obsdesign.sets.polytope_ops.HAVE_GMP` (read at call time, so a
test can turn it off); without it :func:`vertices_exact` raises and :func:`check_polytope_q`
decides boundedness and emptiness with HiGHS LPs instead.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, float_or_inf, frac, to_float
from obsdesign.sets import polytope_ops as po
from obsdesign.sets.base import ConvexSet, float_view

#: exact vertex enumerations in this many dimensions or more run in a child process
#: (:func:`vertices_exact`): the count of vertices can grow as 2ⁿ (a 17-cube written as a
#: polytope has 131,072; cdd.gmp took 7.5 s at n = 16 and minutes at 17), and the one C call
#: holds the interpreter, so neither ``design --timeout`` nor SIGTERM / Ctrl-C could stop it
#: (72-89 s against --timeout 5, 28 s to answer SIGTERM; responsiveness review 47). Starting
#: the child costs 0.2-0.9 s, about what an enumeration at this size costs anyway
CHILD_MIN_DIM = 8


def vertices_exact(G_q: np.ndarray, g_q: np.ndarray) -> tuple[np.ndarray, bool]:
    """Exact vertices of {G x <= g} by cdd.gmp; returns (vertices (k, n) of fmpq, bounded).
    From :data:`CHILD_MIN_DIM` dimensions on, in a child process that this one waits for in
    Python (a time budget's alarm, SIGTERM or Ctrl-C stop the wait, and the child is killed).

    Raises :class:`~obsdesign.sets.polytope_ops.PolytopeError` when cdd.gmp is not available
    (:data:`~obsdesign.sets.polytope_ops.HAVE_GMP` is False)."""
    if not po.HAVE_GMP:
        raise po.PolytopeError("cdd.gmp is not available: exact vertex enumeration is disabled")
    if np.asarray(G_q).ndim == 2 and np.asarray(G_q).shape[1] >= CHILD_MIN_DIM:
        rows = [[(int(Q(x).p), int(Q(x).q)) for x in r] for r in np.asarray(G_q, dtype=object)]
        rhs = [(int(Q(x).p), int(Q(x).q)) for x in np.asarray(g_q, dtype=object).reshape(-1)]
        verts, bounded = po.in_child("vertices", (rows, rhs))
        n = np.asarray(G_q).shape[1]
        V = np.array([[fmpq(a, b) for a, b in r] for r in verts], dtype=object)
        return V.reshape(len(verts), n), bounded
    return _vertices_exact(G_q, g_q)


def _vertices_child(payload: tuple[list, list]) -> tuple[list, bool]:
    """:func:`_vertices_exact` of the integer pairs ``payload`` (rows of G, entries of g),
    as integer pairs: the child process's side of :func:`vertices_exact`."""
    rows, rhs = payload
    G = np.array([[fmpq(a, b) for a, b in r] for r in rows], dtype=object)
    g = np.array([fmpq(a, b) for a, b in rhs], dtype=object)
    V, bounded = _vertices_exact(G.reshape(len(rows), -1), g)
    return [[(int(x.p), int(x.q)) for x in r] for r in V], bounded


def _vertices_exact(G_q: np.ndarray, g_q: np.ndarray) -> tuple[np.ndarray, bool]:
    """:func:`vertices_exact` in this process."""
    import cdd
    import cdd.gmp

    rows = [[frac(g_q[i])] + [-frac(v) for v in G_q[i]] for i in range(G_q.shape[0])]
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


def _float_vertices_ok(G: np.ndarray, g: np.ndarray, V: np.ndarray) -> bool:
    """Whether float cdd's vertices V of {G x <= g} pass three float checks: at least one
    vertex, every vertex inside (to 10⁻⁹ of the row's scale), and every row's support over V
    equal to its LP maximum over the polytope (HiGHS), so no vertex is missing."""
    from scipy.optimize import linprog

    if not len(V) or not np.all(np.isfinite(V)):
        return False
    scale = np.abs(G) @ np.abs(V).max(axis=0) + np.abs(g)
    tol = 1e-9 * np.maximum(scale, np.finfo(float).tiny)
    if np.any(V @ G.T > g + tol):
        return False
    free = [(None, None)] * G.shape[1]
    for i in range(G.shape[0]):
        r = linprog(-G[i], A_ub=G, b_ub=g, bounds=free, method="highs")
        if r.status != 0 or float(np.max(V @ G[i])) < -r.fun - tol[i]:
            return False
    return True


def _checked_float_vertices(G: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Float cdd's vertices of {G x <= g} (rows scaled to unit length first), if
    :func:`_float_vertices_ok`; else :class:`~obsdesign.sets.polytope_ops.PolytopeError`
    (float-only mode: no exact enumeration to fall back on)."""
    norms = np.linalg.norm(G, axis=1)
    norms[norms == 0] = 1.0
    try:
        V = vertices_float(G / norms[:, None], g / norms)[0]
    except RuntimeError as e:
        raise po.PolytopeError(
            f"float vertex enumeration failed ({e}); exact cdd.gmp is needed"
        ) from e
    if not _float_vertices_ok(G, g, V):
        raise po.PolytopeError(
            "float vertex enumeration is unreliable for this polytope (a vertex missing or "
            "outside); exact cdd.gmp is needed"
        )
    return V


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
        across one face pass points 8× outside; re-check trial, session 34).

        Decided for the float point x as it is: in floats where the rounding of G_i x − g_i
        (G and g rounded, the sum; bounded by 4(n + 8)·ε·(Σ_j |G_ij x_j| + |g_i|)) cannot
        reach the threshold, else exactly with the spec's G and g, as
        :meth:`Ellipsoid.contains_rel` does. The float test alone read points 1.45 strip
        widths outside a sheared strip at |x| ≈ 3·10¹³ as inside (re-check trial, session 35).
        """
        lo, hi = self._row_extent()
        mag = np.maximum(np.maximum(np.abs(lo), np.abs(hi)), np.abs(self.g))
        with np.errstate(all="ignore"):
            # rel·hi − rel·lo: hi − lo overflowed for |x1| ≤ 1e308, and an inf slack let
            # (1.7e308, 0) pass (re-check trial, session 36)
            slack = (rel * hi - rel * lo) + 4 * np.spacing(mag)
        return self._decide(x, slack, lambda k, i: self._slack_q(i, rel))

    def contains_exact(self, x: np.ndarray) -> np.ndarray | bool:
        """G x ≤ g exactly for the float point x as it is (no tolerance; the test of
        :meth:`~obsdesign.sets.base.ConvexSet.sample`): in floats where the rounding of
        G_i x − g_i cannot reach 0, else exactly."""
        return self._decide(x, np.zeros(len(self.g)), lambda k, i: Fraction(0))

    def contains_rounded(self, x: np.ndarray) -> np.ndarray | bool:
        """Whether the float point x is within its own rounding of the polytope, face by face:
        G_i x − g_i ≤ Σ_j |G_ij|·spacing(x_j)/2 exactly, i.e. x could be the nearest float of a
        point on the inner side of each face — a decimal written at a bound (d = 0.1 for
        d ≤ 1/10, the float above) is in, a point 5.9 times a face's offset out is not, however
        far the polytope's other faces are (four spacings of the face's magnitude let
        e₁ = 5.9·10⁻⁸ into e₁ ≤ 10⁻⁸ of a set reaching −10⁸; re-check trial 37b). The test of a
        simulated scenario's admissibility (set-invariant)."""
        X = np.asarray(x, dtype=float)
        X2 = X.reshape(-1, self.dim)
        with np.errstate(all="ignore"):
            half = np.minimum(np.spacing(np.abs(X2)), 2.0**971) / 2
            slack = half @ np.abs(self.G).T  # (points, rows)

        def exact(k: int, i: int) -> Fraction:
            return (
                sum(
                    (
                        abs(frac(self.G_q[i][j]))
                        * Fraction(float(min(np.spacing(abs(v)), 2.0**971)))
                        for j, v in enumerate(X2[k])
                    ),
                    start=Fraction(0),
                )
                / 2
            )

        return self._decide(x, slack, exact)

    def _decide(
        self, x: np.ndarray, slack: np.ndarray, exact_slack: Callable[[int, int], Fraction]
    ) -> np.ndarray | bool:
        """G_i x − g_i ≤ slack_i for every row, for the float point x as it is: in floats
        where the rounding of G_i x − g_i (bounded by 4(n + 8)·(ε·(Σ_j |G_ij x_j| + |g_i|) +
        the smallest subnormal) + twice the smallest subnormal per unit of Σ_j |x_j − c_j|, for
        subnormal entries of G) cannot reach the threshold, else exactly with the spec's G and g; a row whose slack is
        not finite against ``exact_slack(k, i)`` (``slack`` per row, or per point and row)."""
        X = np.asarray(x, dtype=float)
        one = X.ndim == 1
        X2 = X.reshape(-1, self.dim)
        G = self.G
        c, b = self._reference()
        with np.errstate(all="ignore"):
            # G x − g = G(x − c) + (G c − g) about a float point c of the polytope (the middle
            # of its bounding box), G c − g exact then rounded: the rounding then scales with
            # |x − c|, not |x|. With G x − g directly a strip of width 10⁻⁴ at |x| ≈ 3·10¹³
            # had every point within the rounding bound of a face, decided exactly: 58 s to
            # sample 200 points (re-check trial, session 37)
            d = X2 - c
            r = d @ G.T + b
            s = np.abs(d) @ np.abs(G).T + np.abs(b)
            # + the smallest subnormal per term (a product that underflows is off absolutely)
            # and per unit of |x − c| (a subnormal G_ij is rounded absolutely: a = 10⁻³¹⁸ at
            # x1 = 5·10²⁹⁹ was 10⁻²⁴ off; re-check trial, session 37)
            err = 4 * (self.dim + 8) * (np.finfo(float).eps * s + 5e-324)
            err = err + 2 * 5e-324 * np.sum(np.abs(d), axis=-1)[:, None]
        ok = r <= slack
        finite = np.isfinite(X2).all(axis=-1)
        # a row whose slack is beyond the float range (its width, or g, overflowed) is decided
        # exactly for every finite point, against its exact slack: an inf slack let any point
        # pass, and a NaN one refused (1.5e308, 1.5e308) in a strip |2x1 − 2x2| ≤ 1 of the box
        # ±1.7e308 (mutation review 36)
        S = np.broadcast_to(slack, r.shape)  # per row, or per point and row
        wide = ~np.isfinite(S)
        unsure = finite[:, None] & (~(np.abs(r - S) > err) | wide)
        for k, i in zip(*np.nonzero(unsure), strict=True):
            thr = exact_slack(int(k), int(i)) if wide[k, i] else Fraction(float(S[k, i]))
            ok[k, i] = self._row_q(int(i), X2[k]) <= thr
        out = np.all(ok, axis=-1) & finite
        return bool(out[0]) if one else out.reshape(X.shape[:-1])

    def _reference(self) -> tuple[np.ndarray, np.ndarray]:
        """(c, b): c the middle of the float bounding box (the origin where a vertex is beyond
        the float range), b = G c − g exactly, then rounded (once per polytope)."""
        ref = self.__dict__.get("_ref")
        if ref is None:
            lo, hi = self.bounding_box()
            with np.errstate(all="ignore"):
                c = lo / 2 + hi / 2
            if not np.all(np.isfinite(c)):
                c = np.zeros(self.dim)
            cq = [frac(float(v)) for v in c]
            b = np.array(
                [
                    float_or_inf(sum((frac(a) * v for a, v in zip(row, cq, strict=True)), -frac(g)))
                    for row, g in zip(self.G_q, self.g_q, strict=True)
                ]
            )
            ref = (c, b)
            self.__dict__["_ref"] = ref
        return ref

    def _slack_q(self, i: int, rel: float) -> Fraction:
        """Row i's slack of :meth:`contains_rel` exactly, for a row whose float slack is not
        finite: ``rel`` × its exact width + four spacings of the largest finite float (2⁹⁷¹
        each; ``np.spacing`` of it is inf)."""
        lo, hi = self._row_extent_q()
        return Fraction(rel) * (frac(hi[i]) - frac(lo[i])) + 4 * 2**971

    def _row_extent_q(self) -> tuple[list[fmpq], list[fmpq]]:
        """Exact min and max of G_i v over the exact vertices, per row (once per polytope)."""
        ext = self.__dict__.get("_row_extent_q_")
        if ext is None:
            P = [
                [sum((a * b for a, b in zip(row, v, strict=True)), fmpq(0)) for row in self.G_q]
                for v in self.vertices_q()
            ]
            cols = list(zip(*P, strict=True))
            ext = ([min(c) for c in cols], [max(c) for c in cols])
            self.__dict__["_row_extent_q_"] = ext
        return ext

    def _row_extent(self) -> tuple[np.ndarray, np.ndarray]:
        """min and max of G_i v over the vertices, per row, in floats (once per polytope):
        from the float vertices, or exactly (then rounded) where a vertex is beyond the float
        range (nearly parallel rows), whose inf − inf made a row's width NaN, or where a
        product G_i v overflowed (a row [2, −2] over vertices near 1.7e308; mutation review
        36)."""
        ext = self.__dict__.get("_row_extent_f")
        if ext is None:
            V = self.vertices()
            proj = None
            if np.all(np.isfinite(V)):
                with np.errstate(all="ignore"):
                    proj = V @ self.G.T
            if proj is not None and np.all(np.isfinite(proj)):
                ext = (proj.min(axis=0), proj.max(axis=0))
            else:
                lo, hi = self._row_extent_q()
                ext = (
                    np.array([float_or_inf(v) for v in lo]),
                    np.array([float_or_inf(v) for v in hi]),
                )
            self.__dict__["_row_extent_f"] = ext
        return ext

    def _row_q(self, i: int, x: np.ndarray) -> Fraction:
        """G_i x − g_i exactly, for the float point x as it is."""
        row = self.G_q[i]
        total = sum((frac(row[j]) * Fraction(float(v)) for j, v in enumerate(x)), start=Fraction(0))
        return total - frac(self.g_q[i])

    def vertices_q(self) -> np.ndarray:
        """Exact vertices (cdd.gmp), enumerated once per polytope."""
        V = self.__dict__.get("_vertices_q")
        if V is None:
            G, g = self.h_form_q()
            V = vertices_exact(G, g)[0]
            self.__dict__["_vertices_q"] = V
        return V

    def vertices(self) -> np.ndarray:
        """Float vertices: the exact ones (cdd.gmp) rounded to floats, enumerated once per
        polytope. Float cdd answered a thin sheared polytope with a "numerical
        inconsistency", with no vertex at all (a strip at x₁ ≈ 3·10¹⁵) and with 2 of a box's
        4 vertices (rows scaled 10⁻⁸), so Monte Carlo drew every initial error from a segment
        (re-check trials, session 35). Without cdd.gmp, float cdd's vertices are used when
        :func:`_float_vertices_ok` accepts them, else
        :class:`~obsdesign.sets.polytope_ops.PolytopeError`."""
        V = self.__dict__.get("_vertices_f")
        if V is None:
            if po.HAVE_GMP:
                # a vertex beyond the float range (nearly parallel rows) is ±inf, not an
                # OverflowError
                Vq = self.vertices_q()
                V = np.array([float_or_inf(v) for v in Vq.flat], dtype=float).reshape(-1, self.dim)
            else:
                V = _checked_float_vertices(self.G, self.g)
            V.setflags(write=False)
            self.__dict__["_vertices_f"] = V
        return V

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
