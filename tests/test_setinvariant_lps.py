"""obsdesign.methods.setinvariant.lps: the float LPs' range check (LP (9))."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from obsdesign import api
from obsdesign.errors import InconclusiveError
from obsdesign.methods.setinvariant import lps

ROOT = Path(__file__).resolve().parents[1]


def test_lp_range_edges() -> None:
    """Matrix entries up to 1e15 and right-hand sides below 1e20 pass; one float beyond
    either, or a non-finite value, is out of HiGHS's range."""
    ok_A, ok_b = np.array([[lps.HIGHS_MATRIX_MAX, 1.0]]), np.array([1.0])
    lps.check_lp_range(ok_A, ok_b, "LP")
    lps.check_lp_range(np.ones((1, 2)), np.array([np.nextafter(lps.HIGHS_INFINITY, 0)]), "LP")
    bad = [
        (np.array([[np.nextafter(lps.HIGHS_MATRIX_MAX, np.inf), 1.0]]), ok_b),
        (np.array([[-np.nextafter(lps.HIGHS_MATRIX_MAX, np.inf), 1.0]]), ok_b),
        (np.ones((1, 2)), np.array([-lps.HIGHS_INFINITY])),
        (np.ones((1, 2)), np.array([np.nan])),
        (np.array([[np.inf, 1.0]]), ok_b),
    ]
    for A, b in bad:
        with pytest.raises(InconclusiveError, match="out of a float LP's range"):
            lps.check_lp_range(A, b, "LP")


def test_a_huge_disturbance_gain_is_inconclusive_not_a_solver_failure() -> None:
    """B1 = [1e50, 1] (found by the spec fuzzer): LP (9)'s right-hand side reaches 5e49,
    which HiGHS reads as infinite ("Model error", exit 3 before); now exit 4 naming LP (9)."""
    text = (ROOT / "specs" / "dorea-pimenta-7-1.toml").read_text()
    assert "\nB1 = [1, 1]\n" in text
    spec = api.load_spec_text(text.replace("\nB1 = [1, 1]\n", "\nB1 = [1e50, 1]\n"), "t.toml")
    with pytest.raises(InconclusiveError, match=r"LP \(9\) is out of a float LP's range") as e:
        api.design(spec)
    assert e.value.exit_code == 4


def test_failing_highs_stops_at_the_deadline(monkeypatch: pytest.MonkeyPatch) -> None:
    """A HiGHS that keeps failing (status 4 after 100 ms each call) on a 64-block LP (9):
    the split-and-retry stops at the budget (Timeout) instead of about 2·64·3 calls; every
    call gets the remaining seconds as its time limit. The soundness audit's 3-state spec
    with time_limit = 30 ran past 300 s inside these retries."""
    import time
    from types import SimpleNamespace

    from obsdesign.methods.setinvariant.budget import Timeout

    limits: list[float] = []

    def failing(*a, options=None, **k):  # type: ignore[no-untyped-def]
        limits.append(options["time_limit"])
        time.sleep(0.1)
        return SimpleNamespace(status=4, message="Solve error", x=None)

    monkeypatch.setattr(lps, "linprog", failing)
    G = np.vstack([np.eye(2), -np.eye(2)])
    t0 = time.perf_counter()
    with pytest.raises(Timeout):
        lps.eps_batch(G, np.zeros((64, 4)), np.zeros(4), deadline=t0 + 0.3)
    assert time.perf_counter() - t0 < 1.0
    assert 0 < len(limits) < 10 and all(0 < t <= 0.3 for t in limits)
    # without a budget the failure is HiGHS's, reported as such
    monkeypatch.setattr(
        lps, "linprog", lambda *a, **k: SimpleNamespace(status=4, message="Solve error", x=None)
    )
    from obsdesign.errors import SolverError

    with pytest.raises(SolverError, match="HiGHS failed on LP \\(9\\)"):
        lps.eps_batch(G, np.zeros((4, 4)), np.zeros(4))


def test_lp_in_range_is_the_check_without_raising() -> None:
    """``lp_in_range`` answers what ``check_lp_range`` raises on."""
    assert lps.lp_in_range(np.ones((1, 2)), np.array([1.0]))
    assert not lps.lp_in_range(np.array([[np.inf, 1.0]]), np.array([1.0]))
    assert not lps.lp_in_range(np.ones((1, 2)), np.array([lps.HIGHS_INFINITY]))


#: the CLI fuzzer's spec: its linear-gain LP is beyond a float LP's range (C = 1e300)
HUGE_C = ROOT / "tests" / "specs" / "setinvariant-huge-C.toml"


def test_linear_gain_lp_beyond_float_range_is_not_an_internal_failure() -> None:
    """Found by the CLI fuzzer: η̄ = 1e300 or C = [[1e300, 1]] made the linear-gain LP (proof
    of Proposition 7.1) raise scipy's "A_ub must not contain values inf" (exit 3). The LP is
    now skipped when its data are beyond a float LP's range; the exact candidates (vertices
    of the admissible set, Proposition 7.1) are still tried."""
    spec = api.load_spec(HUGE_C)
    rep = api.design(spec)
    assert rep.exit_code() == 0 and "L" in rep.parameters
    assert any(c.id == "linear-gains-vertices" and c.status == "certified" for c in rep.claims)
    # η̄ = 1e300: the design's breakpoints lie beyond the float range of the report: exit 4
    # from the report's float view (built by design itself since session 24, with or
    # without an output file), not an internal failure during the design
    text = HUGE_C.read_text().replace("C = [[1e300, 1]]", "C = [[1, 1]]")
    with pytest.raises(InconclusiveError, match="beyond the float range") as e:
        api.design(api.load_spec_text(text.replace("eta_bar = 0", "eta_bar = 1e300"), "t.toml"))
    assert e.value.exit_code == 4
