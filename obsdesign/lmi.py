"""cvxpy building blocks for LMIs: symmetric-by-construction blocks, strictness margins,
and a solver call that says why it failed.

Recipe (DESIGN.md): a strict LMI F ≻ 0 is solved as F ⪰ δ_solve·I with a normalization
(P ⪰ I); only status ``optimal`` is accepted; the solution is then rounded and checked exactly
by :mod:`obsdesign.certify`. ``optimal_inaccurate`` is "not certified", never "infeasible".
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from obsdesign.errors import InconclusiveError, SolverError

SOLVERS = ("CLARABEL", "SCS")


@dataclass
class SolveResult:
    """Outcome of :func:`solve`: ``status`` is cvxpy's status string."""

    status: str
    solver: str
    seconds: float

    @property
    def optimal(self) -> bool:
        return self.status == "optimal"

    @property
    def infeasible(self) -> bool:
        return self.status in ("infeasible", "infeasible_inaccurate")


def sym(M: Any) -> Any:
    """(M + Mᵀ)/2 for a cvxpy expression: use on blocks assembled from products, so that the
    constraint cvxpy sees is exactly the symmetric matrix the certificate rebuilds."""
    return (M + M.T) / 2


def solve(problem: Any, solvers: tuple[str, ...] = SOLVERS) -> SolveResult:
    """Solve with the first solver that returns a definite status; fall back on errors."""
    import cvxpy as cp

    last = ""
    t0 = time.perf_counter()
    for name in solvers:
        if name not in cp.installed_solvers():
            continue
        try:
            with warnings.catch_warnings():  # "solution may be inaccurate": we read the status
                warnings.simplefilter("ignore", UserWarning)
                if name == "SCS":
                    _solve_scs(problem, time_limit(name))
                else:
                    problem.solve(solver=name, **time_limit(name))
        except cp.error.SolverError as e:
            last = f"{name}: {e}"
            continue
        except ValueError as e:
            overflow(e)
            raise
        status = str(problem.status)
        if status in ("optimal", "infeasible", "unbounded"):
            return SolveResult(status, name, time.perf_counter() - t0)
        last = f"{name}: {status}"
    if last.endswith("inaccurate"):
        return SolveResult(last.split(": ")[1], last.split(":")[0], time.perf_counter() - t0)
    raise SolverError(f"no SDP solver succeeded ({last or 'none installed'})")


def overflow(e: ValueError) -> None:
    """Raise InconclusiveError (exit 4) for cvxpy's "Problem data contains NaN or Inf": a
    product of the spec's numbers overflowed float64 (C = [[1e300, ...]] makes CᵀC
    infinite), which no float solver can take; other ValueErrors are left to the caller.

    :param e: the ValueError cvxpy raised."""
    if "NaN or Inf" in str(e):
        raise InconclusiveError(
            "the LMIs' float data are not finite (a product of the spec's numbers overflows "
            "float64): the numbers are too large for a float SDP solver"
        ) from e


#: each solver's own time-limit setting (seconds), given what is left of the time budget in
#: force (:mod:`obsdesign.deadline`): one Clarabel solve of a 24-state stubborn LMI ran 25 s
#: past ``design --timeout 5``, the budget's alarm waiting for it (responsiveness review 47)
TIME_LIMIT_OPTION = {"CLARABEL": "time_limit", "SCS": "time_limit_secs"}


def time_limit(name: str) -> dict[str, float]:
    """``{option: seconds}`` for solver ``name`` under a time budget (at least 10 ms: a
    solver stopped by its limit returns, and the budget's own stop follows), else {}."""
    from obsdesign.deadline import seconds_left

    left = seconds_left()
    option = TIME_LIMIT_OPTION.get(name)
    if left is None or option is None:
        return {}
    return {option: max(left, 0.01)}


def _solve_scs(problem: Any, opts: dict[str, float] | None = None) -> None:
    """``problem.solve(solver="SCS")`` through cvxpy's documented steps (get_problem_data,
    solve_via_data, unpack_results), so that SCS's raw status can be read: SCS replaces the
    SIGINT handler while it iterates and, on Ctrl-C, stops with status "interrupted", which
    cvxpy reports as a solver error, so the interrupt would be lost (and the next solver
    tried). That status raises KeyboardInterrupt here."""
    data, chain, inverse = problem.get_problem_data(solver="SCS")
    raw = chain.solve_via_data(problem, data, solver_opts=dict(opts or {}))
    info = raw.get("info", {}) if isinstance(raw, dict) else {}
    if info.get("status_val") == -5 or info.get("status") == "interrupted":  # SCS_SIGINT
        raise KeyboardInterrupt
    problem.unpack_results(raw, chain, inverse)


def value(x: Any) -> np.ndarray:
    """Float value of a cvxpy variable/expression as a numpy array."""
    return np.asarray(x.value, dtype=float)
