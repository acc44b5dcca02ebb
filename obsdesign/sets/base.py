"""Common interface of the convex sets, and the float views of their exact data."""

from __future__ import annotations

from abc import ABC, abstractmethod
from functools import cached_property
from typing import Any

import numpy as np

from obsdesign.certify.exact import to_float

#: rounds of max(4k, 64) points that :meth:`ConvexSet.sample`'s rejection sampler draws (as
#: fewer, larger rounds after the first ones) before it gives up
MAX_SAMPLE_ROUNDS = 20_000
#: rounds of :meth:`ConvexSet.sample` at each round size before the size doubles
SAMPLE_ESCALATE = 16
#: the largest round of :meth:`ConvexSet.sample`, in multiples of the first
SAMPLE_MAX_FACTOR = 1024
#: points of one round tested at once, with a look at the time budget between
MEMBERSHIP_CHUNK = 2048


#: the most points one round of :meth:`ConvexSet.sample` draws once it escalates (a round of
#: max(4k, 64) points is never cut): 1024 × 4k points for k = 20,000 were 82 million points,
#: about 1.3 GB at n = 2 (re-check trial, session 38)
SAMPLE_MAX_ROUND = 1 << 16


def _round_size(i: int, base: int) -> int:
    """Points drawn in round i of :meth:`ConvexSet.sample` (``base`` = max(4k, 64))."""
    return min(
        base * min(1 << (i // SAMPLE_ESCALATE), SAMPLE_MAX_FACTOR), max(base, SAMPLE_MAX_ROUND)
    )


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

    def sample(
        self, rng: np.random.Generator, k: int, budget: Any = None, start_round: int = 0
    ) -> np.ndarray:
        """k points of the set (rejection sampling from the bounding box), from at most
        :data:`MAX_SAMPLE_ROUNDS` × max(4k, 64) drawn points: a set of (almost) no volume, a
        segment in the plane, accepted nothing and the loop ran forever (independent simulate
        review). Raises :class:`~obsdesign.errors.InputError` then. A drawn point is kept when
        it is in the set exactly (:meth:`contains_exact`): the float ``contains`` (absolute
        10⁻¹²) kept points 5.9 strip widths outside a thin sheared strip at |x| ≈ 3·10¹³
        (re-check trial, session 36), and four float spacings of a face's offset still 140
        widths (re-check trial, session 37).

        Rounds draw max(4k, 64) points each for the first :data:`SAMPLE_ESCALATE` rounds, then
        twice as many every :data:`SAMPLE_ESCALATE` rounds (at most :data:`SAMPLE_MAX_FACTOR`
        times): deciding "no volume" took 20,000 calls of ``contains_exact`` on 64 points,
        2.4 s, beyond the spec loader's 2 s for that check, so a thin set passed the loader on
        a busy machine and failed it on an idle one. A set that keeps a point within the first
        rounds draws the same numbers as before. ``budget`` (a simulation's time budget, or
        None) is looked at every 16 rounds and between chunks of :data:`MEMBERSHIP_CHUNK`
        points of a larger round: a set far thinner than the float spacing at its position has
        every drawn point decided in rational arithmetic. ``start_round``: rounds already drawn
        from ``rng`` by the caller (the Monte Carlo draw's first block), so that the
        continuation draws what an uninterrupted call would."""
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
        base = max(4 * k, 64)
        total = MAX_SAMPLE_ROUNDS * base
        drawn = sum(_round_size(r, base) for r in range(start_round))
        out: list[np.ndarray] = []
        got, i = 0, start_round
        while got < k and drawn < total:
            size = min(_round_size(i, base), total - drawn)
            if budget is not None and i % 16 == 0:
                budget.check(f"sampling the {self.kind or 'set'} ({got:,} of {k:,} points kept)")
            pts = rng.uniform(lo, hi, size=(size, self.dim))
            keep = np.empty(size, dtype=bool)
            for a in range(0, size, MEMBERSHIP_CHUNK):
                if budget is not None and a:
                    budget.check(
                        f"sampling the {self.kind or 'set'} ({got:,} of {k:,} points kept)"
                    )
                b = min(a + MEMBERSHIP_CHUNK, size)
                keep[a:b] = np.asarray(self.contains_exact(pts[a:b]), dtype=bool).reshape(b - a)
            out.append(pts[keep])
            got += len(out[-1])
            drawn += size
            i += 1
        if got < k:
            raise InputError(
                f"rejection sampling kept {got:,} of {total:,} points drawn in the bounding box "
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
