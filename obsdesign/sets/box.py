"""Axis-aligned boxes {x : lower <= x <= upper}."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from obsdesign.certify.exact import float_ceil, float_floor, qzeros
from obsdesign.sets.base import ConvexSet, float_view


@dataclass(frozen=True, eq=False)
class Box(ConvexSet):
    """Box with exact bounds ``lower_q`` <= ``upper_q`` (object arrays of fmpq; a side may be
    degenerate, e.g. the search-space method's initial set D); ``lower``, ``upper`` are their
    float views."""

    lower_q: np.ndarray
    upper_q: np.ndarray
    kind = "box"

    @property
    def dim(self) -> int:
        return len(self.lower_q)

    lower = float_view("lower_q")
    upper = float_view("upper_q")

    def describe(self) -> str:
        """The exact bounds, e.g. ``[-1, 1] × [0, 1/2]``."""
        return " × ".join(f"[{a}, {b}]" for a, b in zip(self.lower_q, self.upper_q, strict=True))

    def contains(self, x: np.ndarray, tol: float = 1e-12) -> np.ndarray | bool:
        x = np.asarray(x, dtype=float)
        ok = (x >= self.lower - tol) & (x <= self.upper + tol)
        return ok.all(axis=-1)

    def contains_rel(self, x: np.ndarray, rel: float = 1e-9) -> np.ndarray | bool:
        """Membership up to ``rel`` of each side's own width (plus four float spacings of its
        bounds): the widest side's let a box 10¹² times thinner in one coordinate count a
        point 8× outside as inside (re-check trial, session 34). ``rel·hi − rel·lo`` and
        spacings capped at the largest float's (2⁹⁷¹): ``rel·(hi − lo)`` overflowed for a side
        ±1.7·10³⁰⁸, and its inf slack let x₁ = 1.79·10³⁰⁸ in (session 37). A non-finite
        coordinate is outside, as in the other sets."""
        x = np.asarray(x, dtype=float)
        lo, hi = np.asarray(self.lower, float), np.asarray(self.upper, float)
        with np.errstate(over="ignore"):  # spacing of the largest float is inf; hi + slack
            ulp = np.minimum(np.spacing(np.maximum(np.abs(lo), np.abs(hi))), 2.0**971)
            slack = (rel * hi - rel * lo) + 4 * ulp
            inside = (x >= lo - slack) & (x <= hi + slack)
        return (inside & np.isfinite(x)).all(axis=-1)

    def contains_exact(self, x: np.ndarray) -> np.ndarray | bool:
        """lower ≤ x ≤ upper exactly for the float point x: x ≥ the smallest float ≥ each
        exact lower bound and ≤ the largest float ≤ each upper bound. A side that holds no
        float at all — a degenerate side 1/10, or [3·10¹³ + 0.001, 3·10¹³ + 0.002] — is read
        as the floats nearest its ends (the float 0.1; 3·10¹³ and 3·10¹³ + 0.0039), the
        point a spec's decimal stands for: else a fixed coordinate 0.1 could not be sampled."""
        lo, hi = self._float_inner()
        x = np.asarray(x, dtype=float)
        return ((x >= lo) & (x <= hi)).all(axis=-1)

    def contains_rounded(self, x: np.ndarray) -> np.ndarray | bool:
        """Whether the float point x is the nearest float of a point of the box: between the
        floats nearest its bounds (the float views), with no tolerance (as
        :meth:`Polytope.contains_rounded`)."""
        x = np.asarray(x, dtype=float)
        return ((x >= self.lower) & (x <= self.upper)).all(axis=-1)

    def _float_inner(self) -> tuple[np.ndarray, np.ndarray]:
        """(smallest float ≥ lower_q, largest float ≤ upper_q) per side, or the nearest
        floats of both ends where the side holds no float; once per box."""
        inner = self.__dict__.get("_inner")
        if inner is None:
            lo = np.array([float_ceil(v) for v in self.lower_q], dtype=float)
            hi = np.array([float_floor(v) for v in self.upper_q], dtype=float)
            empty = lo > hi
            lo[empty] = np.asarray(self.lower, dtype=float)[empty]
            hi[empty] = np.asarray(self.upper, dtype=float)[empty]
            inner = (lo, hi)
            self.__dict__["_inner"] = inner
        return inner

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        return self.lower, self.upper

    def vertices_q(self) -> np.ndarray:
        """All 2^n vertices, exact (rows)."""
        pts = list(itertools.product(*zip(self.lower_q, self.upper_q, strict=True)))
        return np.array(pts, dtype=object).reshape(len(pts), self.dim)

    def h_form_q(self) -> tuple[np.ndarray, np.ndarray]:
        """Exact (G, g) with G x <= g: rows e_i (upper) then -e_i (lower)."""
        n = self.dim
        G = qzeros((2 * n, n))
        g = np.empty(2 * n, dtype=object)
        for i in range(n):
            G[i, i] = 1
            G[n + i, i] = -1
            g[i] = self.upper_q[i]
            g[n + i] = -self.lower_q[i]
        return G, g
