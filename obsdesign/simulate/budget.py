"""The time budget of a simulation (``[simulate] time_limit`` / ``--option time_limit``): a
deadline looked at inside the long loops, so that no number a spec gives (a horizon, a step,
a refining budget) makes ``simulate`` run without end. Past it the run stops with
:class:`~obsdesign.errors.SolverError` (exit 3), saying how far it got and what to change.

A ``theta_m`` of 10⁵ (constrained) ran past 120 s and a stubborn single run of 10⁶ steps took
114 s, neither with a way to stop it (independent simulate review, session 19).
"""

from __future__ import annotations

import time
from typing import Any

from obsdesign.errors import SolverError

#: the default budget in seconds, as impulsive's and search-space's ``time_limit``
DEFAULT_LIMIT = 300.0


class TimeExceeded(SolverError):
    """A simulation ran past its ``[simulate] time_limit`` (exit 3, as a design past its
    own ``time_limit``)."""


class TimeBudget:
    """A deadline ``limit`` seconds from now; :meth:`check` raises past it.

    :param limit: seconds; :param advice: what to change, for the message ("raise
    time_limit, or …")."""

    def __init__(self, limit: float, advice: str) -> None:
        self.limit = float(limit)
        self.deadline = time.perf_counter() + self.limit
        self.advice = advice

    def expired(self) -> bool:
        """Whether the deadline has passed."""
        return time.perf_counter() > self.deadline

    def check(self, where: str) -> None:
        """Raise :class:`TimeExceeded` naming ``[simulate] time_limit`` and ``where`` (what
        runs and how far it got) once the deadline has passed."""
        if self.expired():
            raise TimeExceeded(
                f"simulation not finished within {self.limit:g} s ([simulate] time_limit): "
                f"{where} ({self.advice})"
            )


#: the smallest budget a spec or ``--option time_limit`` may give, in seconds
MIN_LIMIT = 0.001


def parse_time_limit(table: Any) -> float:
    """``[simulate] time_limit`` of any method: seconds, at least :data:`MIN_LIMIT` (the bound
    of ``--option time_limit``), default :data:`DEFAULT_LIMIT`; an error names the key.

    :param table: the ``[simulate]`` table (:class:`obsdesign.spec.reader.Table`)."""
    from flint import fmpq

    v = table.scalar("time_limit", default=None, min=fmpq(1, 1000))
    return DEFAULT_LIMIT if v is None else float(v.f)


#: the JSON schema of ``[simulate] time_limit`` (every method's)
TIME_LIMIT_SCHEMA: dict[str, Any] = {
    "type": "number",
    "minimum": MIN_LIMIT,
    "description": "seconds the simulation may run (exit 3 past it)",
}
