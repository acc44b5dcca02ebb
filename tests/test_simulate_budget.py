"""Tests of obsdesign/simulate/budget.py: one time budget for every method's ``simulate``."""

from __future__ import annotations

from pathlib import Path

import pytest

from obsdesign import api
from obsdesign.errors import EXIT_SOLVER, SolverError
from obsdesign.simulate.budget import TimeBudget, TimeExceeded

SPECS = Path(__file__).resolve().parent.parent / "specs"


def test_a_budget_raises_only_past_its_deadline(slow_clock) -> None:
    """Before the deadline nothing happens; past it the error is exit 3 and names the key,
    the budget, where the run got to and the advice."""
    slow_clock(still=2)
    b = TimeBudget(999, "raise time_limit")
    assert not b.expired()
    b.check("step 1")  # the clock still stands at 0
    assert b.expired()
    with pytest.raises(TimeExceeded) as e:
        b.check("step 7 of 9")
    assert isinstance(e.value, SolverError) and e.value.exit_code == EXIT_SOLVER
    assert str(e.value) == (
        "simulation not finished within 999 s ([simulate] time_limit): step 7 of 9 "
        "(raise time_limit)"
    )


@pytest.mark.parametrize(
    "spec",
    [
        "constrained-redesign-sec5.toml",
        "constrained-redesign-sec5-lyapunov.toml",
        "astolfi-stubborn-example1.toml",
        "schaum-impulsive-example.toml",
        "dorea-pimenta-7-1.toml",
        "hernandez-garcia-example.toml",
    ],
)
def test_every_method_stops_at_the_shared_budget(spec: str, slow_clock) -> None:
    """Each method's simulation looks at the one budget of this module (impulsive and
    search-space had their own clocks before): a clock past ``time_limit`` stops it with
    :class:`TimeExceeded`, whichever method runs."""
    sp = api.load_spec(SPECS / spec)
    rep = api.design(sp)
    slow_clock()  # every look after the budget's start is 1000 s later: past 300 s
    with pytest.raises(TimeExceeded, match=r"within 300 s \(\[simulate\] time_limit\): "):
        api.simulate(sp, rep)
