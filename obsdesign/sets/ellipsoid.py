"""Ellipsoids {x : (x - c)ᵀ E (x - c) <= 1} with E symmetric positive definite."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from obsdesign.certify.exact import to_float
from obsdesign.sets.base import ConvexSet


@dataclass(frozen=True, eq=False)
class Ellipsoid(ConvexSet):
    """Ellipsoid with exact shape ``E_q`` and centre ``center_q``."""

    E_q: np.ndarray
    center_q: np.ndarray
    kind = "ellipsoid"

    @property
    def dim(self) -> int:
        return self.E_q.shape[0]

    @property
    def E(self) -> np.ndarray:
        return np.asarray(to_float(self.E_q), dtype=float)

    @property
    def center(self) -> np.ndarray:
        return np.asarray(to_float(self.center_q), dtype=float)

    def contains(self, x: np.ndarray, tol: float = 1e-12) -> np.ndarray | bool:
        d = np.asarray(x, dtype=float) - self.center
        return np.einsum("...i,ij,...j->...", d, self.E, d) <= 1 + tol

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        half = np.sqrt(np.diag(np.linalg.inv(self.E)))
        return self.center - half, self.center + half
