"""The joint linear plant + observer system (obsdesign.simulate.linear): one matrix product
per step, exact zero-order hold in continuous time, against step-by-step references."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from obsdesign.api import load_spec_text
from obsdesign.simulate.linear import (
    joint_system,
    simulate_linear_observer,
    simulate_linear_observer_batch,
)
from obsdesign.simulate.runner import signals

FULL = """
[system]
time = "discrete"
A = [[0.5, 1], [0, 0.8]]
B = [[0], [1]]
C = [[1, 0]]
D = [[0.5]]
Bd = [[1], [0]]
[method]
key = "lyapunov"
L = [0.6, 0.1]
[simulate]
horizon = 40
x0 = [1, -1]
xhat0 = [0, 0.5]
seed = 3
[simulate.u]
kind = "sequence"
values = [1, -1, 0.5, 2]
[simulate.disturbance]
kind = "windows"
windows = [{ start = 3, stop = 9, value = [0.3] }]
[simulate.noise]
kind = "uniform"
bound = 0.1
"""
L = np.array([[0.6], [0.1]])


def _reference_discrete(sp):
    """The observer equations written out, one step at a time."""
    s, sim = sp.system, sp.simulate
    A, B, C, D, Bd, Dn = s.A.f, s.B.f, s.C.f, s.D.f, s.Bd.f, s.Dn.f
    N = int(sim.horizon.f)
    u, d, v = signals(sp, np.arange(N + 1))
    x, xh = sim.x0.f.copy(), sim.xhat0.f.copy()
    X, XH = [x], [xh]
    for k in range(N):
        y = C @ x + D @ u[k] + Dn @ v[k]
        xh = A @ xh + B @ u[k] + L @ (y - C @ xh - D @ u[k])
        x = A @ x + B @ u[k] + Bd @ d[k]
        X.append(x)
        XH.append(xh)
    return np.array(X), np.array(XH)


def test_discrete_joint_system_matches_the_observer_equations():
    sp = load_spec_text(FULL)
    res = simulate_linear_observer(sp, L)
    X, XH = _reference_discrete(sp)
    np.testing.assert_allclose(res.x, X, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.xhat, XH, rtol=0, atol=1e-12)
    u, _, v = signals(sp, res.t)
    np.testing.assert_allclose(res.y[:, 0], X[:, 0] + 0.5 * u[:, 0] + v[:, 0], atol=1e-12)


def test_continuous_zero_order_hold_matches_an_aligned_integration():
    text = FULL.replace('"discrete"', '"continuous"').replace(
        "horizon = 40", "horizon = 1\ndt = 0.05"
    )
    text = text.replace("A = [[0.5, 1], [0, 0.8]]", "A = [[0, 1], [-2, -0.3]]")
    sp = load_spec_text(text)
    res = simulate_linear_observer(sp, L)
    s = sp.system
    A, B, C, D, Bd, Dn = s.A.f, s.B.f, s.C.f, s.D.f, s.Bd.f, s.Dn.f
    u, d, v = signals(sp, res.t)
    z = np.concatenate([sp.simulate.x0.f, sp.simulate.xhat0.f])
    for k in range(len(res.t) - 1):  # integrate each hold interval on its own, tightly

        def f(t, z, k=k):
            x, xh = z[:2], z[2:]
            y = C @ x + D @ u[k] + Dn @ v[k]
            return np.concatenate(
                [A @ x + B @ u[k] + Bd @ d[k], A @ xh + B @ u[k] + L @ (y - C @ xh - D @ u[k])]
            )

        z = solve_ivp(f, (0, 0.05), z, rtol=1e-12, atol=1e-14, method="DOP853").y[:, -1]
        np.testing.assert_allclose(z[:2], res.x[k + 1], atol=1e-10)
        np.testing.assert_allclose(z[2:], res.xhat[k + 1], atol=1e-10)


def test_joint_matrices():
    sp = load_spec_text(FULL)
    js = joint_system(sp, L)
    A, C = sp.system.A.f, sp.system.C.f
    np.testing.assert_array_equal(js.M[:2, :2], A)
    np.testing.assert_array_equal(js.M[:2, 2:], 0)
    np.testing.assert_array_equal(js.M[2:, :2], L @ C)
    np.testing.assert_array_equal(js.M[2:, 2:], A - L @ C)
    # E = [[B, Bd, 0], [B, 0, L Dn]]: the D u terms cancel in the observer
    np.testing.assert_array_equal(js.E, [[0, 1, 0], [1, 0, 0], [0, 0, 0.6], [1, 0, 0.1]])


def test_one_batched_run_equals_the_single_run_without_randomness():
    sp = load_spec_text(
        FULL.replace('kind = "uniform"\nbound = 0.1', 'kind = "constant"\nvalue = [0.1]')
    )
    a = simulate_linear_observer(sp, L)
    b = simulate_linear_observer_batch(sp, L, 1)
    np.testing.assert_allclose(b.x, a.x, atol=1e-12)
    np.testing.assert_allclose(b.xhat, a.xhat, atol=1e-12)
    ma = a.metrics()
    for k in ("sup_abs_error", "rmse", "sup_abs_estimate"):
        for st, val in ma[k].items():
            assert abs(b.extra["per_run"][k][0, a.states.index(st)] - val) <= 1e-12
    assert abs(b.extra["per_run"]["final_error_norm"][0] - ma["final_error_norm"]) <= 1e-12


def test_the_single_run_keeps_the_error_of_an_unstable_plant() -> None:
    """x⁺ = 3x, L = 2.5 (A − LC = 0.5): after 60 steps x ≈ 4·10²⁸ and x̂ − x computed from
    the two would be pure rounding (|error| ~ 10¹²); the run steps [x; e], so the error is
    0.5^k exactly as the observer's recursion gives it (random-spec fuzzer), in discrete and
    continuous time (ẋ = x, L = 3: ė = −2e)."""

    disc = load_spec_text(
        '[system]\ntime = "discrete"\nA = [[3]]\nC = [[1]]\n[method]\nkey = "lyapunov"\n'
        "L = [2.5]\n[simulate]\nhorizon = 60\nx0 = [1]\nxhat0 = [2]\n",
        "u.toml",
    )
    r = simulate_linear_observer(disc, np.array([[2.5]]))
    np.testing.assert_allclose(r.e[:, 0], 0.5 ** np.arange(61), rtol=1e-13)
    assert r.x[-1, 0] == 3.0**60 and r.metrics()["final_error_norm"] < 1e-18
    np.testing.assert_allclose(r.xhat, r.x + r.e, rtol=1e-15)
    cont = load_spec_text(
        '[system]\ntime = "continuous"\nA = [[1]]\nC = [[1]]\n[method]\nkey = "lyapunov"\n'
        "L = [3]\n[simulate]\nhorizon = 40\ndt = 0.01\nx0 = [1]\nxhat0 = [2]\n",
        "c.toml",
    )
    r = simulate_linear_observer(cont, np.array([[3.0]]))
    np.testing.assert_allclose(r.e[:, 0], np.exp(-2 * r.t), rtol=1e-9)


CONT = """[system]
time = "continuous"
A = [[0, 1], [-2, -0.3]]
C = [[1, 0]]
[method]
key = "lyapunov"
L = [1, 1]
[simulate]
x0 = [1, 0]
xhat0 = [0, 0]
"""


def test_the_continuous_grid_ends_at_the_horizon() -> None:
    """dt = 0.3 over horizon 1 stopped at t = 0.9, dt = 5 > horizon simulated t = 0 alone
    (independent simulate review): dt is lowered to horizon / ⌈horizon / dt⌉ and the API says
    so; a dt that divides the horizon (to 10⁻⁹, 10 / 0.1 included) is kept as given."""
    from obsdesign import api
    from obsdesign.simulate.linear import sim_grid

    for dt, want in (("0.3", [0, 0.25, 0.5, 0.75, 1]), ("5", [0, 1]), ("0.25", None)):
        sp = load_spec_text(CONT + f"horizon = 1\ndt = {dt}\n")
        grid = sim_grid(sp)
        if want is None:
            np.testing.assert_array_equal(grid, [0, 0.25, 0.5, 0.75, 1])
            assert sp.simulate.dt_given is None
            continue
        np.testing.assert_allclose(grid, want, rtol=0, atol=1e-15)
        res = api.simulate(sp)
        assert res.t[-1] == 1.0
        note = res.info["warnings"][0]
        assert note.startswith(f"[simulate] dt = {float(dt)!r} does not divide horizon = 1.0: the")
    sp = load_spec_text(CONT + "horizon = 10\ndt = 0.1\n")
    assert sp.simulate.dt_given is None and len(sim_grid(sp)) == 101
    assert float(sp.simulate.dt.f) == 0.1
    # an astronomic step count is said in a few digits (it overflowed float() once)
    from obsdesign.api import _step_note

    note = _step_note(load_spec_text(CONT + "horizon = 1e300\ndt = 3e-300\n"))
    assert "(about 1e599 steps)" in note
    # 1.43e9 steps and a fraction: not a whole number (the relative 1e-9 alone said it was)
    assert load_spec_text(CONT + "horizon = 1e300\ndt = 7e290\n").simulate.dt_given is not None


def test_a_dt_beyond_the_exact_discretization_is_bad_input() -> None:
    """horizon = 1e50 (dt = horizon / 1000) printed NaN metrics and "the plant or the observer
    diverges" for a stable plant and observer (review): expm overflows; it is exit 2 naming
    [simulate] dt now. 1e20 still simulates."""
    import pytest

    from obsdesign import api
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match=r"\[simulate\] dt = 1e\+47 is too large"):
        api.simulate(load_spec_text(CONT + "horizon = 1e50\n"))
    m = api.simulate(load_spec_text(CONT + "horizon = 1e20\n")).metrics()
    assert np.isfinite(m["final_error_norm"])


def test_a_start_beyond_the_float_range_is_said_so() -> None:
    """x0 = 1e308, xhat0 = −1e308: the error overflows at once; the warning said "the plant or
    the observer diverges", which is false, beside numpy's overflow warnings (review)."""
    from obsdesign import api

    text = CONT.replace("x0 = [1, 0]", "x0 = [1e308, 0]").replace(
        "xhat0 = [0, 0]", "xhat0 = [-1e308, 0]"
    )
    res = api.simulate(load_spec_text(text + "horizon = 1\n"))
    assert res.info["warnings"] == [
        "the trajectory is not finite at its start: x0, xhat0 or the error xhat0 − x0 the "
        "simulation steps is beyond the float range (about 1.8e308), so the metrics are not "
        "finite; take smaller initial states"
    ]


def test_an_overflowing_plant_leaves_a_decoupled_error_finite() -> None:
    """A = [[1.1, 1], [0, 1.2]] (unstable) with L making A − LC = eigenvalues 0.5, 0.6: x
    overflows near k = 3881, but e⁺ = (A − LC)e does not read x. The joint step M·[x; e]
    multiplied the zero block by inf and the error became nan (simulate trial, session 27);
    it is stepped apart now, and matches its own recursion (which reaches exactly 0)."""
    from obsdesign import api

    spec = load_spec_text(
        '[system]\ntime = "discrete"\nA = [[1.1, 1], [0, 1.2]]\nC = [[1, 0]]\n[method]\n'
        'key = "lyapunov"\nL = [1.2, 0.42]\nlambda = 0.9\n[simulate]\nhorizon = 5000\n'
        "x0 = [1, 1]\nxhat0 = [0, 0]\n",
        "unstable.toml",
    )
    res = api.simulate(spec)
    assert not np.all(np.isfinite(res.x))  # the plant does leave the float range
    Acl = np.array([[1.1 - 1.2, 1.0], [-0.42, 1.2]])
    e = np.empty((5001, 2))
    e[0] = [-1.0, -1.0]
    for k in range(5000):
        e[k + 1] = Acl @ e[k]
    np.testing.assert_allclose(res.e, e, rtol=1e-12, atol=1e-300)
    m = res.metrics()
    assert m["sup_abs_error"] == {"x1": 1.0, "x2": 1.0} and m["final_error_norm"] == 0.0


def test_an_observer_unstable_in_doubles_is_said_so_not_blamed_on_dt() -> None:
    """A certified 12-state design (‖L‖ ≈ 2.5·10¹¹): exp of the joint system over the default
    dt is not finite because A − LC in doubles is not Hurwitz; simulate was exit 2 blaming
    "[simulate] dt = 0.01", and a smaller dt gave NaN (census 46). Exit 4 naming A − LC in
    doubles; the design and its verify stand."""
    from pathlib import Path

    import pytest

    from obsdesign import api
    from obsdesign.errors import InconclusiveError

    spec = api.load_spec(Path(__file__).parent / "specs" / "lyapunov-float-unstable-12state.toml")
    rep = api.design(spec)
    assert rep.exit_code() == 0 and api.verify(rep).exit_code() == 0
    with pytest.raises(InconclusiveError, match="A − LC formed in doubles is not Hurwitz") as e:
        api.simulate(spec, rep)
    assert "dt" not in str(e.value).split("not Hurwitz")[0] and e.value.exit_code == 4
