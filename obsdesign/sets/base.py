"""Common interface of the convex sets, and the float views of their exact data."""

from __future__ import annotations

from abc import ABC, abstractmethod
from functools import cached_property
from typing import Any

import numpy as np

from obsdesign.certify.exact import to_float

#: rounds of :meth:`ConvexSet.sample`'s rejection sampler before it gives up
MAX_SAMPLE_ROUNDS = 20_000


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

    def contains_rel(self, x: np.ndarray, rel: float = 1e-9) -> np.ndarray | bool:
        """Float membership up to ``rel`` of the set's size. This default takes ``rel`` × the
        widest side of the bounding box (plus four float spacings of its largest coordinate)
        in state units; every set of this package overrides it to read each direction at its
        own scale (a box per side, a polytope per face, an ellipsoid on its form, decided
        exactly near the threshold), as the widest side let a point 8× outside a thin
        direction count as inside (re-check trial, session 34). A new set type should too.
        An absolute tolerance of 1e-9 let a point 16 % outside a set 3·10⁻¹² wide count as
        inside (soundness trial, session 34)."""
        return self.contains(x, tol=self._slack(rel))

    def contains_exact(self, x: np.ndarray) -> np.ndarray | bool:
        """Membership of the float point x as it is in the exact set, no tolerance (the test
        of :meth:`sample`). This default is ``contains_rel`` at ``rel = 0`` (four float
        spacings); every set of this package overrides it with an exact decision."""
        return self.contains_rel(x, rel=0.0)

    def _slack(self, rel: float) -> float:
        """``rel`` × the widest side of the bounding box + 4 float spacings of its magnitude."""
        lo, hi = (np.asarray(b, dtype=float) for b in self.bounding_box())
        if not lo.size:
            return 0.0
        mag = float(np.max(np.maximum(np.abs(lo), np.abs(hi))))
        return rel * float(np.max(hi - lo)) + 4 * float(np.spacing(mag))

    def sample(self, rng: np.random.Generator, k: int, budget: Any = None) -> np.ndarray:
        """k points of the set (rejection sampling from the bounding box), in at most
        :data:`MAX_SAMPLE_ROUNDS` rounds: a set of (almost) no volume, a segment in the plane,
        accepted nothing and the loop ran forever (independent simulate review). Raises
        :class:`~obsdesign.errors.InputError` then. A drawn point is kept when it is in the
        set exactly (:meth:`contains_exact`): the float ``contains`` (absolute 10⁻¹²) kept
        points 5.9 strip widths outside a thin sheared strip at |x| ≈ 3·10¹³ (re-check trial,
        session 36), and four float spacings of a face's offset still 140 widths (re-check
        trial, session 37). ``budget`` (a simulation's time budget, or None) is looked at every
        16 rounds: a set far thinner than the float spacing at its position has every drawn
        point decided in rational arithmetic, up to a minute before the "no volume" error."""
        from obsdesign.errors import InputError

        lo, hi = self.bounding_box()
        with np.errstate(over="ignore"):
            wide = ~np.isfinite(np.subtract(hi, lo, dtype=float))
        if np.any(wide):  # numpy's uniform overflowed: exit 4 "beyond the float range"
            i = int(np.argmax(wide))
            raise InputError(
                f"the bounding box of the {self.kind or 'set'} is wider than the float range "
                f"(coordinate {i + 1} from {float(lo[i]):.4g} to {float(hi[i]):.4g}): it "
                "cannot be sampled"
            )
        out: list[np.ndarray] = []
        got = 0
        for i in range(MAX_SAMPLE_ROUNDS):
            if got >= k:
                break
            if budget is not None and i % 16 == 0:
                budget.check(f"sampling the {self.kind or 'set'} ({got:,} of {k:,} points kept)")
            pts = rng.uniform(lo, hi, size=(max(4 * k, 64), self.dim))
            out.append(pts[np.asarray(self.contains_exact(pts), dtype=bool)])
            got += len(out[-1])
        if got < k:
            draws = MAX_SAMPLE_ROUNDS * max(4 * k, 64)
            raise InputError(
                f"rejection sampling kept {got:,} of {draws:,} points drawn in the bounding box "
                f"of the {self.kind or 'set'} (wanted {k:,}): it has (almost) no volume"
            )
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
