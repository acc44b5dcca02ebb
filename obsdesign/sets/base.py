"""Common interface of the convex sets, and the float views of their exact data."""

from __future__ import annotations

from abc import ABC, abstractmethod
from functools import cached_property

import numpy as np

from obsdesign.certify.exact import to_float


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


def float_view(exact: str, flat: bool = False) -> cached_property:
    """The float64 view of a set's exact array attribute ``exact`` (each entry correctly
    rounded): computed on first use and kept, as the sets are frozen; read-only, so that no
    caller changes it in place. ``flat``: a 1-D view whatever the shape of the exact array."""

    def view(self: ConvexSet) -> np.ndarray:
        arr = np.asarray(to_float(getattr(self, exact)), dtype=float)
        arr = arr.reshape(-1) if flat else arr
        arr.setflags(write=False)
        return arr

    view.__doc__ = f"float64 view of ``{exact}`` (read-only)"
    return cached_property(view)
