"""The time budget of a simulation (``[simulate] time_limit`` / ``--option time_limit``): a
deadline looked at inside the long loops, so that no number a spec gives (a horizon, a step,
a refining budget) makes ``simulate`` run without end. Past it the run stops with
:class:`~obsdesign.errors.SolverError` (exit 3), saying how far it got and what to change.

A ``theta_m`` of 10⁵ (constrained) ran past 120 s and a stubborn single run of 10⁶ steps took
114 s, neither with a way to stop it (independent simulate review, session 19).
"""

from __future__ import annotations

import time

from obsdesign.errors import SolverError

#: the default budget in seconds, as impulsive's and search-space's ``time_limit``
DEFAULT_LIMIT = 300.0


class TimeBudget:
    """A deadline ``limit`` seconds from now; :meth:`check` raises past it.

    :param limit: seconds; :param advice: what to change, for the message ("raise
    time_limit, or …")."""

    def __init__(self, limit: float, advice: str) -> None:
        self.limit = float(limit)
        self.deadline = time.perf_counter() + self.limit
        self.advice = advice

    def check(self, where: str) -> None:
        """Raise :class:`SolverError` naming ``[simulate] time_limit`` and ``where`` (what
        runs and how far it got) once the deadline has passed."""
        if time.perf_counter() > self.deadline:
            raise SolverError(
                f"simulation not finished within {self.limit:g} s ([simulate] time_limit): "
                f"{where} ({self.advice})"
            )
