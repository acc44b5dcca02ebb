"""The time budget's deadline as native solvers see it (obsdesign.deadline, lmi.time_limit)."""

from __future__ import annotations

import time

import pytest

from obsdesign import api, lmi
from obsdesign.deadline import seconds_left, until


def test_solvers_get_what_is_left_of_the_budget() -> None:
    """One Clarabel solve of a 24-state stubborn LMI ran 25 s past design --timeout 5, the
    budget's alarm waiting for it (responsiveness review 47): under a budget each SDP solver
    gets its own time limit, what is left (at least 10 ms); none without a budget; the
    earlier of two nested budgets holds."""
    assert seconds_left() is None and lmi.time_limit("CLARABEL") == {}
    with until(30):
        got = lmi.time_limit("CLARABEL")["time_limit"]
        assert 29 < got <= 30
        assert 29 < lmi.time_limit("SCS")["time_limit_secs"] <= 30
        with until(100):
            assert seconds_left() <= 30
        with until(1):
            assert seconds_left() <= 1
    assert seconds_left() is None
    with until(0):
        time.sleep(0.01)
        assert lmi.time_limit("CLARABEL") == {"time_limit": 0.01}


def test_a_design_budget_reaches_the_solver(monkeypatch) -> None:
    """api._time_budget puts its deadline in force for the block; lmi.solve passes it on."""
    import cvxpy as cp

    seen: list[dict] = []
    real = cp.Problem.solve

    def solve(self, *a, **k):
        seen.append(k)
        return real(self, *a, **k)

    monkeypatch.setattr(cp.Problem, "solve", solve)
    x = cp.Variable()
    prob = cp.Problem(cp.Minimize(x), [x >= 1])
    with api._time_budget(20):
        assert 19 < seconds_left() <= 20
        lmi.solve(prob, ("CLARABEL",))
    assert seen and 19 < seen[0]["time_limit"] <= 20
    seen.clear()
    lmi.solve(prob, ("CLARABEL",))
    assert seen == [{"solver": "CLARABEL"}]


@pytest.mark.parametrize("seconds", [None, 0])
def test_no_budget_no_deadline(seconds) -> None:
    with api._time_budget(seconds):
        assert seconds_left() is None
