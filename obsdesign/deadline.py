"""The wall-clock deadline of the time budget in force (``design --timeout``, ``check
--timeout``; :func:`obsdesign.api._time_budget`), for native solvers that take a time limit
of their own: a budget's alarm reaches Python only between bytecodes, so one long solver call
(Clarabel on a 24-state stubborn LMI, about 25 s) ran past ``--timeout 5`` (responsiveness
review 47). Context-local: a Dask task's budget is its own."""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

_DEADLINE: ContextVar[float | None] = ContextVar("obsdesign_deadline", default=None)


@contextmanager
def until(seconds: float) -> Iterator[None]:
    """The budget ending ``seconds`` from now in force within the block (an outer budget that
    ends earlier stays in force)."""
    end = time.monotonic() + seconds
    outer = _DEADLINE.get()
    token = _DEADLINE.set(end if outer is None else min(outer, end))
    try:
        yield
    finally:
        _DEADLINE.reset(token)


def seconds_left() -> float | None:
    """Seconds left of the budget in force (never below 0), or None when there is none."""
    end = _DEADLINE.get()
    return None if end is None else max(0.0, end - time.monotonic())
