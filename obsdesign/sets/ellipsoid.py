"""Ellipsoids {x : (x - c)ᵀ E (x - c) <= 1} with E symmetric positive definite."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from obsdesign.sets.base import ConvexSet, float_view


@dataclass(frozen=True, eq=False)
class Ellipsoid(ConvexSet):
    """Ellipsoid with exact shape ``E_q`` (symmetric positive definite) and centre
    ``center_q``, object arrays of fmpq; ``E`` and ``center`` are their float views."""

    E_q: np.ndarray
    center_q: np.ndarray
    kind = "ellipsoid"
    E = float_view("E_q")
    center = float_view("center_q")

    @property
    def dim(self) -> int:
        return self.E_q.shape[0]

    def contains(self, x: np.ndarray, tol: float = 1e-12) -> np.ndarray | bool:
        d = np.asarray(x, dtype=float) - self.center
        return np.einsum("...i,ij,...j->...", d, self.E, d) <= 1 + tol

    def contains_rel(self, x: np.ndarray, rel: float = 1e-9) -> np.ndarray | bool:
        """(x − c)ᵀE(x − c) ≤ 1 + ``rel``: the quadratic form is already relative to the
        set's size (:meth:`ConvexSet.contains_rel`)."""
        return self.contains(x, tol=rel)

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        half = np.sqrt(np.diag(np.linalg.inv(self.E)))
        return self.center - half, self.center + half
