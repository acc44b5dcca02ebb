"""Read-only spec data: every numpy array a bound spec's sets and method options hold.

A ``Spec`` is a value of its text (docs/architecture.md): its arrays are read-only, so that a
result kept within one process (the lyapunov memo, the search-space caches, set-invariant's
exact hull) and the embedded text always describe the data a design used. ``Value`` freezes
the system's arrays; the sets' and the options' own arrays (a polytope's ``G_q``, the
search-space boxes E, D, U, the constrained map's ``G_q`` / ``h_q``) stayed writable, and an
in-place edit made a report whose embedded text no longer matched (API review, session 43).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np


def freeze_arrays(obj: Any) -> None:
    """Make every numpy array reachable from ``obj`` read-only, with every array it views.

    Walks dataclass fields, lists, tuples, sets and dict values (each object once); other
    objects (callables, expressions, exact scalars) are left alone.

    :param obj: the object to walk (a set, the method's options, a tuple of them)."""
    seen: set[int] = set()
    stack = [obj]
    while stack:
        x = stack.pop()
        if id(x) in seen:
            continue
        seen.add(id(x))
        if isinstance(x, np.ndarray):
            a: Any = x
            while isinstance(a, np.ndarray):  # exact entries (fmpq) are immutable
                a.flags.writeable = False
                a = a.base
        elif dataclasses.is_dataclass(x) and not isinstance(x, type):
            stack.extend(getattr(x, f.name, None) for f in dataclasses.fields(x))
        elif isinstance(x, list | tuple | set | frozenset):
            stack.extend(x)
        elif isinstance(x, dict):
            stack.extend(x.values())


class ReadOnlyDict(dict):  # type: ignore[type-arg]
    """A dict that refuses every in-place change (``TypeError``), and copies and pickles as
    itself: an expression's ``parameters`` edited in place (``f[0].parameters["k"] = 1``)
    designed a report certified for k = 1 whose embedded text said k = 10 (re-check review,
    session 44)."""

    def _refuse(self, *args: Any, **kwargs: Any) -> None:
        raise TypeError("a spec's parameters are read-only (edit the spec text and load it again)")

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = _refuse  # type: ignore[assignment]
    __ior__ = _refuse  # type: ignore[assignment]

    def __reduce__(self) -> tuple[Any, ...]:
        return (ReadOnlyDict, (dict(self),))
