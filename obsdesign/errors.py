"""Error types and the exit codes they map to (DESIGN.md, "Exit codes and output").

0 ok; 1 infeasible design or a failed claim; 2 bad input; 3 solver or internal failure;
4 numerically inconclusive (a candidate the exact check could not certify).
"""

from __future__ import annotations

EXIT_OK = 0
EXIT_INFEASIBLE = 1
EXIT_BAD_INPUT = 2
EXIT_SOLVER = 3
EXIT_INCONCLUSIVE = 4


class ObsdesignError(Exception):
    """Base class: carries the exit code and a one-line message for the user."""

    exit_code: int = EXIT_SOLVER

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


class SpecError(ObsdesignError):
    """Bad input: a spec or report file that is malformed. Message names file and key."""

    exit_code = EXIT_BAD_INPUT

    def __init__(self, file: str, key: str, expected: str) -> None:
        where = f"{file}: [{key}]" if key else f"{file}:"
        super().__init__(f"{where} {expected}")
        self.file = file
        self.key = key
        self.expected = expected


class InputError(ObsdesignError):
    """Bad input that is not tied to a spec key (missing file, bad report JSON, ...)."""

    exit_code = EXIT_BAD_INPUT


class InfeasibleError(ObsdesignError):
    """The design problem has no solution; the message says which condition fails."""

    exit_code = EXIT_INFEASIBLE


class SolverError(ObsdesignError):
    """A numerical solver failed in a way that says nothing about feasibility."""

    exit_code = EXIT_SOLVER


class InconclusiveError(ObsdesignError):
    """A candidate was found but the exact check could not certify it."""

    exit_code = EXIT_INCONCLUSIVE
