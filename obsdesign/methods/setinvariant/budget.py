"""The time budget of a set-invariant design (``[method] time_limit``, issue 12 item 2): one
deadline (a ``time.perf_counter()`` value) checked between slices, LP blocks, iterations and
breakpoints, so that a design stops with a reason instead of running for minutes."""

from __future__ import annotations

import time


class Timeout(Exception):
    """The time budget ran out (between two slices, LP blocks or breakpoints)."""


def check_deadline(deadline: float | None) -> None:
    """Raise :class:`Timeout` past ``deadline`` (None: no budget)."""
    if deadline is not None and time.perf_counter() > deadline:
        raise Timeout
