"""Constraint maps c of Assumption 3, constrained-redesign paper (000).

Every component is ``c_i(x) = max(φ_i(x), 0)²`` with φ_i convex:

- ``box``: φ = (r̲_i − x_i, x_i − r̄_i) per coordinate, in the order of eq. (19)
  (Lemma 2): c = (c̲_1, c̄_1, …, c̲_n, c̄_n);
- ``polytope``: φ_i = g_iᵀx − h_i, one component per face of {G x ≤ h};
- ``ellipsoid``: φ = xᵀQx / r − 1 with Q ≻ 0, n_c = 1 (eq. (18), Lemma 1).

The sublevel sets are C_ε = {x : |c(x)| ≤ ε} (eq. (16), |·| the Euclidean norm), so
C_0 = {φ_i ≤ 0 ∀i}. For affine φ, C_ε lies between the inner polytope {φ_i ≤ t_in(ε)} and the
outer polytope {φ_i ≤ √ε}; at most one face of each *antipodal class* (a face alone, or a pair
of faces whose normals are negative multiples of each other, e.g. the two faces of a box
coordinate) can be violated at a point, which the bounds below use.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, qzeros, to_float

KINDS = ("box", "polytope", "ellipsoid")


@dataclass(frozen=True, eq=False)
class ConstraintMap:
    """The map c of Assumption 3 (exact data; float views for the runtime).

    Affine kinds (box, polytope) keep ``G_q`` (n_c × n) and ``h_q`` (n_c) with φ = G x − h;
    the ellipsoid keeps ``Q_q`` (n × n, ≻ 0) and ``r_q`` > 0 with φ = xᵀQx/r − 1.
    """

    kind: str
    G_q: np.ndarray | None = None
    h_q: np.ndarray | None = None
    Q_q: np.ndarray | None = None
    r_q: Any = None
    classes: list[list[int]] = field(default_factory=list)
    #: the norm |c| of eq. (16): "euclidean" (the paper's |·|) or "max" (then C_ε is the
    #: polytope {φ_i ≤ √ε} for affine maps); Lemma 3 holds for both, since |c|₂ ≥ |c|_∞
    norm: str = "euclidean"
    _f: dict[str, Any] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        # float views, computed once (the runtime evaluates c millions of times)
        if self.affine:
            self._f["G"] = np.asarray(to_float(self.G_q), dtype=float)
            self._f["h"] = np.asarray(to_float(self.h_q), dtype=float).reshape(-1)
        else:
            self._f["Q"] = np.asarray(to_float(self.Q_q), dtype=float)
            self._f["r"] = float(Q(self.r_q))

    # -- float views ------------------------------------------------------------------------
    @property
    def affine(self) -> bool:
        return self.kind != "ellipsoid"

    @property
    def n_c(self) -> int:
        return 1 if not self.affine else int(self.G_q.shape[0])  # type: ignore[union-attr]

    @property
    def dim(self) -> int:
        return int(self.G_q.shape[1] if self.affine else self.Q_q.shape[0])  # type: ignore[union-attr]

    @property
    def G(self) -> np.ndarray:
        return self._f["G"]

    @property
    def h(self) -> np.ndarray:
        return self._f["h"]

    @property
    def Qf(self) -> np.ndarray:
        return self._f["Q"]

    @property
    def r(self) -> float:
        return self._f["r"]

    # -- float evaluation (vectorized over leading axes) ------------------------------------
    def phi(self, x: np.ndarray) -> np.ndarray:
        """φ(x), shape (..., n_c)."""
        x = np.asarray(x, dtype=float)
        if self.affine:
            return x @ self.G.T - self.h
        return (np.einsum("...i,ij,...j->...", x, self.Qf, x) / self.r - 1.0)[..., None]

    def c(self, x: np.ndarray) -> np.ndarray:
        """c(x) = max(φ(x), 0)², eq. (18)/(19), shape (..., n_c)."""
        return np.maximum(self.phi(x), 0.0) ** 2

    def norm_c(self, x: np.ndarray) -> np.ndarray:
        """|c(x)|, the norm used in the sets C_ε of eq. (16) (Euclidean or max)."""
        if self.norm == "max":
            return np.max(self.c(x), axis=-1)
        return np.linalg.norm(self.c(x), axis=-1)

    def jtc(self, x: np.ndarray) -> np.ndarray:
        """(dc/dx)(x)ᵀ c(x), the direction in M of eq. (20), shape (..., n).

        Affine: dc_i/dx = 2 φ_i⁺ g_iᵀ, so (dc/dx)ᵀc = Gᵀ(2 φ⁺³).
        Ellipsoid: dc/dx = 2 φ⁺ (2 Q x / r)ᵀ, so (dc/dx)ᵀc = 4 φ⁺³ Q x / r.
        """
        x = np.asarray(x, dtype=float)
        p = np.maximum(self.phi(x), 0.0)
        if self.affine:
            return (2.0 * p**3) @ self.G
        return 4.0 * p**3 * (x @ self.Qf.T) / self.r

    # -- exact evaluation -------------------------------------------------------------------
    def phi_q(self, x: np.ndarray) -> list[fmpq]:
        """φ(x) exactly at a rational point."""
        if self.affine:
            G, h = self.G_q, self.h_q
            return [
                sum((G[i, j] * x[j] for j in range(G.shape[1])), fmpq(0)) - h[i]
                for i in range(G.shape[0])
            ]
        Qm = self.Q_q
        n = Qm.shape[0]
        val = sum((x[i] * Qm[i, j] * x[j] for i in range(n) for j in range(n)), fmpq(0))
        return [val / Q(self.r_q) - 1]

    def norm_c_sq_q(self, x: np.ndarray) -> fmpq:
        """|c(x)|² exactly at a rational point."""
        out = fmpq(0)
        for p in self.phi_q(x):
            if p > 0:
                out = max(out, p**4) if self.norm == "max" else out + p**4
        return out


def antipodal_classes(G: np.ndarray) -> list[list[int]]:
    """Group the faces of {G x ≤ h} in *antipodal classes*: a face alone, or a pair of faces
    whose normals are negative multiples of each other (exact rational test on the rows).

    The two faces of a pair can never be violated at the same point of a non-empty polytope
    (g x > h₁ and −s g x > h₂ need h₁ < g x < −h₂/s ≤ h₁), so at most one φ_i per class is
    positive at any x: the bounds of :mod:`obsdesign.methods.constrained.bounds` (Σ over
    classes of the worst face) rely on it. Faces with the *same* outward direction (a
    redundant face such as −x ≤ 1 beside −½x ≤ ½) can be violated together, so they never
    share a class: each face pairs with at most one antipodal face, the first unpaired one.
    (Grouping every negative multiple of a face together put two same-direction faces in one
    class and under-estimated |c| and |dc/dx|: a certified v_min that was false; found by
    the random-spec fuzzer.)
    """
    m = G.shape[0]
    cls: list[list[int]] = []
    used = [False] * m
    for i in range(m):
        if used[i]:
            continue
        used[i] = True
        j = next(
            (j for j in range(i + 1, m) if not used[j] and _negative_multiple(G[i], G[j])), None
        )
        if j is None:
            cls.append([i])
        else:
            used[j] = True
            cls.append([i, j])
    return cls


def _negative_multiple(a: np.ndarray, b: np.ndarray) -> bool:
    k = next((t for t in range(len(a)) if a[t] != 0), None)
    if k is None or b[k] == 0:
        return False
    s = b[k] / a[k]
    return bool(s < 0 and all(b[t] == s * a[t] for t in range(len(a))))


def box_map(lower: np.ndarray, upper: np.ndarray, norm: str = "euclidean") -> ConstraintMap:
    """The box map of eq. (19): rows −e_i (φ = r̲_i − x_i) then +e_i (φ = x_i − r̄_i)."""
    n = len(lower)
    G = qzeros((2 * n, n))
    h = np.empty(2 * n, dtype=object)
    for i in range(n):
        G[2 * i, i] = fmpq(-1)
        h[2 * i] = -Q(lower[i])
        G[2 * i + 1, i] = fmpq(1)
        h[2 * i + 1] = Q(upper[i])
    return ConstraintMap(
        "box", G_q=G, h_q=h, classes=[[2 * i, 2 * i + 1] for i in range(n)], norm=norm
    )


def polytope_map(G: np.ndarray, h: np.ndarray, norm: str = "euclidean") -> ConstraintMap:
    """One component c_i = max(g_iᵀx − h_i, 0)² per face of {G x ≤ h}."""
    return ConstraintMap("polytope", G_q=G, h_q=h, classes=antipodal_classes(G), norm=norm)


def ellipsoid_map(Qm: np.ndarray, r: Any) -> ConstraintMap:
    """The ellipsoid map of eq. (18): c = max(xᵀQx/r − 1, 0)², Q ≻ 0, r > 0."""
    return ConstraintMap("ellipsoid", Q_q=Qm, r_q=Q(r), classes=[[0]])
