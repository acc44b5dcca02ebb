"""obsdesign.lmi: the solver call (status, fallback, Ctrl-C through SCS)."""

from __future__ import annotations

import os
import signal
import threading

import cvxpy as cp
import numpy as np
import pytest

from obsdesign import lmi
from obsdesign.errors import SolverError


def _lyapunov_lmi(n: int, rho: float = 0.9) -> cp.Problem:
    rng = np.random.default_rng(0)
    A = rng.normal(size=(n, n))
    A *= rho / max(abs(np.linalg.eigvals(A)))
    P = cp.Variable((n, n), symmetric=True)
    return cp.Problem(
        cp.Minimize(cp.trace(P)), [P >> np.eye(n), lmi.sym(A.T @ P @ A - P) << -np.eye(n)]
    )


@pytest.mark.parametrize("solvers", [("CLARABEL",), ("SCS",)])
def test_solve_reports_status_and_values(solvers: tuple[str, ...]):
    prob = _lyapunov_lmi(4)
    r = lmi.solve(prob, solvers)
    assert r.optimal and r.solver == solvers[0]
    P = lmi.value(prob.variables()[0])
    assert np.linalg.eigvalsh(P).min() > 0.99


def test_an_infeasible_lmi_is_reported_infeasible():
    P = cp.Variable((2, 2), symmetric=True)
    prob = cp.Problem(cp.Minimize(0), [P >> np.eye(2), P << -np.eye(2)])
    assert lmi.solve(prob).infeasible


def test_no_installed_solver_is_a_solver_error():
    with pytest.raises(SolverError, match="none installed"):
        lmi.solve(_lyapunov_lmi(2), ("NO-SUCH-SOLVER",))


@pytest.mark.skipif(not hasattr(signal, "pthread_kill"), reason="POSIX signals")
def test_ctrl_c_during_an_scs_solve_is_a_keyboard_interrupt():
    """SCS installs its own SIGINT handler while it iterates and stops with status
    "interrupted", which cvxpy turns into a solver error (and lmi.solve would then report
    "no SDP solver succeeded"): the interrupt must come out as KeyboardInterrupt. Python's
    handler is replaced by one that only counts, so a signal that lands outside SCS cannot
    raise: only lmi.solve's reading of SCS's status can."""
    prob = _lyapunov_lmi(24)
    counted: list[int] = []
    old = signal.signal(signal.SIGINT, lambda s, f: counted.append(s))
    done = threading.Event()

    def pester() -> None:
        while not done.wait(0.005):
            os.kill(os.getpid(), signal.SIGINT)

    t = threading.Thread(target=pester, daemon=True)
    t.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            lmi.solve(prob, ("SCS",))
    finally:
        done.set()
        t.join()
        signal.signal(signal.SIGINT, old)


def test_non_finite_problem_data_is_inconclusive_not_an_internal_failure():
    """A product of huge spec numbers overflows float64 (1e300² = inf): cvxpy refuses the
    problem with "Problem data contains NaN or Inf"; that is exit 4, not exit 3."""
    from obsdesign.errors import InconclusiveError

    P = cp.Variable((2, 2), symmetric=True)
    big = np.array([[1e300, 0.0], [0.0, 1.0]])
    a = cp.Parameter(nonneg=True, value=1.0)  # as stubborn's λ: cvxpy checks the data then
    prob = cp.Problem(cp.Minimize(cp.trace(P)), [P >> np.eye(2), a * (big @ P @ big) << np.eye(2)])
    with pytest.raises(InconclusiveError, match="not finite") as e:
        lmi.solve(prob)
    assert e.value.exit_code == 4
    lmi.overflow(ValueError("other"))  # any other ValueError is left to the caller


def test_a_stubborn_spec_whose_products_overflow_is_inconclusive():
    """C = [[1e300, 0, 0, 0], ...] (found by the spec fuzzer): exit 4 naming the overflow."""
    from pathlib import Path

    from obsdesign import api
    from obsdesign.errors import InconclusiveError

    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "astolfi-stubborn-example4.toml").read_text()
    old = "\nC = [[1, 0, 0, 0], [0, 0, 1, 0]]\n"
    assert old in text
    spec = api.load_spec_text(text.replace(old, old.replace("[[1,", "[[1e300,")), "t.toml")
    with pytest.raises(InconclusiveError, match="not finite"):
        api.design(spec)
