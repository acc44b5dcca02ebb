"""Common interface of the convex sets."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np


class ConvexSet(ABC):
    """A compact convex set in R^n with exact data."""

    kind: str = ""

    @property
    @abstractmethod
    def dim(self) -> int: ...

    @abstractmethod
    def contains(self, x: np.ndarray, tol: float = 1e-12) -> np.ndarray | bool:
        """Float membership test; ``x`` is (n,) or a batch (k, n)."""

    @abstractmethod
    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        """Float (lower, upper) of the smallest enclosing box."""

    def sample(self, rng: np.random.Generator, k: int) -> np.ndarray:
        """k points of the set (rejection sampling from the bounding box)."""
        lo, hi = self.bounding_box()
        out: list[np.ndarray] = []
        while sum(len(o) for o in out) < k:
            pts = rng.uniform(lo, hi, size=(max(4 * k, 64), self.dim))
            out.append(pts[np.asarray(self.contains(pts))])
        return np.concatenate(out)[:k]
