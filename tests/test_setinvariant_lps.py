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
    # the hint names A and the growth of the iterates too: a spec without B1 whose scale came
    # from A (entries 5e11) was pointed at "B1, the sets" (independent fuzz, session 38)
    assert "(A, C, B1, the sets) or the growth of the iterates under A" in e.value.message


@pytest.mark.parametrize("entry", ["9007199254740993", "1e15"])
def test_a_highs_failure_on_wide_data_is_inconclusive(entry: str) -> None:
    """A = [[0.7, 2^53 + 1], [−0.7, 0.7]] in Dórea–Pimenta 7.1: HiGHS answered "status not
    recognized" after every retry and the design was exit 3, an internal failure (CLI review,
    session 44). With right-hand sides past 10¹² the failure is the data's: exit 4."""
    text = (ROOT / "specs" / "dorea-pimenta-7-1.toml").read_text()
    old = "A = [[0.7, 0.7], [-0.7, 0.7]]"
    assert old in text
    spec = api.load_spec_text(text.replace(old, f"A = [[0.7, {entry}], [-0.7, 0.7]]"), "t.toml")
    with pytest.raises(InconclusiveError, match=r"HiGHS failed on LP \(9\).*too large") as e:
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


@pytest.mark.parametrize("s", [1e-9, 1e9])
def test_epsilon_profile_does_not_depend_on_the_units_of_the_state(s: float) -> None:
    """ε(z) (LP (9)) of Example 7.1's unit box, with the state in other units: Ω = {|e|∞ <=
    s}, B1 = s·B1 (G = rows / s; φ, δ, ε are gauge values and do not change, z = s·z).
    Unscaled, HiGHS dropped G's entries ~1e-9 as zeros (``small_matrix_value``) and gave
    ε = 2.4 at both ends of Z_d, where it is 1."""
    A = np.array([[0.7, 0.7], [-0.7, 0.7]])
    G1 = np.vstack([np.eye(2), -np.eye(2)])
    c, Dv = np.array([1.0, 1.0]), np.array([[-1.0], [1.0]])
    z1, e1 = lps.epsilon_profile(G1, A, np.ones((2, 1)), c, Dv, 0.0)
    zs, es = lps.epsilon_profile(G1 / s, A, s * np.ones((2, 1)), c, Dv, 0.0)
    assert np.allclose(z1, [-2, 0, 2]) and np.allclose(e1, [1, 2.4, 1], rtol=1e-12)
    assert np.allclose(zs, s * z1, rtol=1e-12) and np.allclose(es, e1, rtol=1e-12)


@pytest.mark.parametrize("s", [1e-9, 1e9, 2.0**-40, 3e12, 1e-30, 1e30])
def test_lp9_does_not_depend_on_the_units_of_the_state(s: float) -> None:
    """LP (9) with G / s (the same polyhedron, the state in units 1/s of the original):
    the same ε and v scaled by s, whatever s (its columns are scaled to 1 for HiGHS)."""
    G1 = np.vstack([np.eye(2), -np.eye(2), [[0.5, 0.5], [-0.5, -0.5]]])
    phi = np.array([[1.4, 0.0, 0.0, -1.4, 0.7, -0.7], [0.7, 0.7, -0.7, -0.7, 0.7, -0.7]])
    dl = np.full(6, 0.5)
    r1 = lps.eps_batch(G1, phi, dl)
    rs = lps.eps_batch(G1 / s, phi, dl)
    assert np.allclose(r1.eps, [1.2, 0.5], rtol=1e-12)
    assert np.allclose(rs.eps, r1.eps, rtol=1e-12)
    # v^l may differ where LP (9) has several optima; its level on every row may not
    assert np.allclose((phi + dl + rs.v @ (G1 / s).T).max(axis=1), r1.eps, rtol=1e-12)


@pytest.mark.parametrize("c", [1e-15, 1e-200])
def test_zd_merges_near_duplicates_relative_to_the_scale_of_z(c: float) -> None:
    """Z_d of the float iterations merges points within 1e-12 of the largest |z| (relative):
    with z = c·e on the unit box, c = 1e-15 had all of Z_d merged into one point (an
    absolute floor of 1e-12), so the general algorithm saw only the worst slice's neighbour
    and stopped on a polyhedron failing Theorem 3.1 (2.23 where c = 1 gives 9/10)."""
    V = np.array([[1.0, 1], [-1, 1], [-1, -1], [1, -1], [1, 0.5]])
    cvec = np.array([1.0, 0.0])
    assert np.array_equal(lps.z_d(V, c * cvec, 0.0), c * lps.z_d(V, cvec, 0.0))
    assert len(lps.z_d(V, c * cvec, 0.0)) == 2
    assert len(lps.z_d(V, c * np.array([1.0, 1.0]), 0.0)) == 4


def test_slice_of_ker_C_does_not_depend_on_the_scale_of_C() -> None:
    """φ_q(0) of Lemma 6.1 (η̄ = 0) slices Ω along ker C; C's rank is counted relative to its
    largest singular value, so C = 1e-13·[1, 1] has the kernel of [1, 1] (an absolute floor
    1e-12 counted rank 0 and sliced nothing off)."""
    A = np.array([[0.7, 0.7], [-0.7, 0.7]])
    G = np.vstack([np.eye(2), -np.eye(2)])
    C = np.array([[1.0, 1.0]])
    phi1, S1 = lps.phi_slice_general(G, A, C, 0.0)
    phis, Ss = lps.phi_slice_general(G, A, 1e-13 * C, 0.0)
    assert np.allclose(phis, phi1) and np.allclose(np.abs(Ss @ C.T), 0.0, atol=1e-12)


def test_a_phi_table_too_large_is_refused_by_name(monkeypatch) -> None:
    """A 7-state design reached 949,004 facets and 4,834 breakpoints: LP (6)'s table was an
    internal failure, MemoryError for 34.2 GiB (session 47). It is a SolverError naming the
    size."""
    from obsdesign.errors import SolverError
    from obsdesign.methods.setinvariant import lps

    monkeypatch.setattr(lps, "PHI_MAX_BYTES", 8 * 3 * 5)
    G, A, V = np.eye(3), np.eye(3), np.eye(3)
    c = np.array([1.0, 0.0, 0.0])
    with pytest.raises(SolverError, match=r"3 facets with 6 breakpoints: LP \(6\)'s table"):
        lps.phi_at(G, A, V, np.zeros((0, 2), dtype=int), c, 0.0, np.arange(6.0))
    out, _ = lps.phi_at(G, A, V, np.zeros((0, 2), dtype=int), c, 0.0, np.arange(5.0) / 10)
    assert out.shape == (5, 3)
