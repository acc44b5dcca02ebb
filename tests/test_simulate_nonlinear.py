"""The linear observer against a plant given by expressions (obsdesign.simulate.nonlinear):
the batched Monte Carlo runs equal N separate runs of the observer equations written out,
do not depend on the batching, and a linear plant written as expressions gives the linear
path's numbers."""

from __future__ import annotations

import numpy as np
import pytest
from test_simulate_montecarlo import INPUT_PLANT, PLANT, UNIFORM, scenario

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.simulate import montecarlo as mc
from obsdesign.simulate.linear import simulate_linear_observer, simulate_linear_observer_batch

L = np.array([[0.6], [0.1]])
PSI = PLANT.replace("Bd = [[1], [0]]", 'Bd = [[1], [0]]\npsi = ["0.1*sin(x1)", "0.05*x1*x2"]')
#: the whole maps: f with the input and the disturbance, h with the noise (y = x1 + x1³/20 + v)
WHOLE = INPUT_PLANT.replace(
    "Bd = [[1], [0]]",
    'Bd = [[1], [0]]\nf = ["0.5*x1 + x2 + d1", "0.8*x2 + u1 - 0.1*sin(x2)"]\n'
    'h = ["x1 + x1**3/20 + 0.5*u1 + v1"]',
)
CASES = {
    "psi, uniform noise": scenario(PSI, horizon=200, noise=UNIFORM),
    "f and h, random u and d": scenario(
        WHOLE,
        horizon=200,
        u={"kind": "uniform", "bound": 0.5},
        disturbance={"kind": "uniform", "bound": 0.05},
        noise=UNIFORM,
    ),
    "psi, outliers": scenario(
        PSI, horizon=200, noise={"kind": "outliers", "amplitude": 1, "rate": 0.05}
    ),
}


def separate(sp, runs, ie="E0"):
    """Every run on its own: its generator (child r of the seed), its initial error and
    signals drawn in the documented order, then the plant and the observer equations written
    out one step and one run at a time (the expressions evaluated on scalars)."""
    s, sim = sp.system, sp.simulate
    A, B, C, D, Bd, Dn = s.A.f, s.B.f, s.C.f, s.D.f, s.Bd.f, s.Dn.f
    grid = np.arange(int(sim.horizon.f) + 1, dtype=float)
    xud = [*s.states, *s.inputs, *s.disturbances, "t"]
    xuv = [*s.states, *s.inputs, *s.noises, "t"]

    def call(exprs, names, *vals):
        env = dict(zip(names, np.concatenate([np.atleast_1d(v) for v in vals]), strict=True))
        return np.array([float(e(**env)) for e in exprs])

    out = []
    for child in mc.run_seeds(sim.seed, runs):
        g = np.random.default_rng(child)
        e0 = sp.sets[ie].sample(g, 1)[0] if ie else sim.xhat0.f - sim.x0.f
        u, d, v = (sig.evaluate(grid, g) for sig in (sim.u, sim.disturbance, sim.noise))
        x, xh = sim.x0.f.copy(), sim.x0.f + e0
        X, XH = [x], [xh]
        for k in range(len(grid) - 1):
            t = grid[k]
            y = call(s.h, xuv, x, u[k], v[k], t) if s.h else C @ x + D @ u[k] + Dn @ v[k]
            xh = A @ xh + B @ u[k] + L @ (y - C @ xh - D @ u[k])
            if s.f:
                x = call(s.f, xud, x, u[k], d[k], t)
            else:
                x = A @ x + B @ u[k] + Bd @ d[k] + call(s.psi, xud, x, u[k], d[k], t)
            X.append(x)
            XH.append(xh)
        E, XH = np.array(XH) - np.array(X), np.array(XH)
        out.append(
            {
                "sup_abs_error": np.abs(E).max(axis=0),
                "rmse": np.sqrt((E**2).mean(axis=0)),
                "sup_abs_estimate": np.abs(XH).max(axis=0),
                "final_error_norm": np.linalg.norm(E[-1]),
            }
        )
    return out


@pytest.mark.parametrize("case", CASES)
def test_batched_runs_are_the_separate_runs(case):
    sp = load_spec_text(CASES[case])
    r = simulate_linear_observer_batch(sp, L, 5, "E0")
    for i, m in enumerate(separate(sp, 5)):
        for k, want in m.items():
            np.testing.assert_allclose(r.extra["per_run"][k][i], want, rtol=1e-12, atol=1e-13)
    assert r.info["runs"] == 5 and r.y.shape == (201, 1)


@pytest.mark.parametrize("case", CASES)
def test_results_do_not_depend_on_batching_or_span(case):
    sp = load_spec_text(CASES[case])
    a = simulate_linear_observer_batch(sp, L, 6, "E0")
    b = simulate_linear_observer_batch(sp, L, 6, "E0", batch=1)
    c = simulate_linear_observer_batch(sp, L, 6, "E0", batch=4)
    d = mc.merge(
        [simulate_linear_observer_batch(sp, L, 6, "E0", span=s) for s in ((0, 2), (2, 6))],
        ["x1", "x2"],
    )
    for k, arr in a.extra["per_run"].items():
        for other in (b, c, d):
            np.testing.assert_array_equal(arr, other.extra["per_run"][k])
    np.testing.assert_array_equal(a.xhat, b.xhat)


def test_one_run_is_run_0_of_a_batch():
    sp = load_spec_text(scenario(PSI, horizon=100, noise={"kind": "constant", "value": [0.02]}))
    one = simulate_linear_observer(sp, L)  # x0 = [1, -1], x̂0 = 0: x0 + (x̂0 − x0) is x̂0
    batch = simulate_linear_observer_batch(sp, L, 3)
    np.testing.assert_array_equal(one.xhat, batch.xhat)
    np.testing.assert_array_equal(one.y, batch.y)
    np.testing.assert_array_equal(one.e, batch.e)
    m = one.metrics()  # np.mean's pairwise sum against the batch's running sum: to rounding
    got = batch.extra["per_run"]["rmse"][0]
    np.testing.assert_allclose(got, [m["rmse"]["x1"], m["rmse"]["x2"]], rtol=1e-14)


def test_a_linear_plant_as_expressions_gives_the_linear_numbers():
    text = scenario(horizon=300, noise=UNIFORM)
    zero = text.replace("Bd = [[1], [0]]", 'Bd = [[1], [0]]\npsi = ["0", "0"]')
    lin, nl = load_spec_text(text), load_spec_text(zero)
    assert lin.system.linear and not nl.system.linear
    a = simulate_linear_observer_batch(lin, L, 4, "E0").extra["per_run"]
    b = simulate_linear_observer_batch(nl, L, 4, "E0").extra["per_run"]
    for k in a:
        np.testing.assert_allclose(b[k], a[k], rtol=1e-12)


def test_continuous_rk4_against_the_exact_zero_order_hold():
    text = (
        scenario(horizon=2, noise=UNIFORM)
        .replace('"discrete"', '"continuous"')
        .replace("horizon = 2", "horizon = 2\ndt = 0.02")
        .replace("[[0.5, 1], [0, 0.8]]", "[[0, 1], [-2, -0.3]]")
    )
    zero = text.replace("Bd = [[1], [0]]", 'Bd = [[1], [0]]\npsi = ["0", "0"]')
    a = simulate_linear_observer_batch(load_spec_text(text), L, 3, "E0").extra["per_run"]
    b = simulate_linear_observer_batch(load_spec_text(zero), L, 3, "E0").extra["per_run"]
    for k in a:  # RK4 with dt/8 steps: error ~ (2.5e-3)^4 per unit time
        np.testing.assert_allclose(b[k], a[k], rtol=1e-9)


def test_simulate_runs_through_the_api_uses_the_expressions(write_spec):
    text = scenario(PSI, horizon=100, noise=UNIFORM)
    path = write_spec(text.replace("seed = 11", 'seed = 11\ninitial_error = "E0"'))
    res = api.simulate(path, options={"runs": "4"})
    sp = load_spec_text(text)
    want = separate(sp, 4)
    got = res.extra["per_run"]["final_error_norm"]
    np.testing.assert_allclose(got, [m["final_error_norm"] for m in want], rtol=1e-9)
    one = api.simulate(path)  # one run: run 0 of the four, through the expression plant
    assert one.extra["per_run"]["final_error_norm"][0] == got[0]


def _scalar_plant(time: str, a: float, gain: float, horizon: str):
    """x⁺ (or ẋ) = a x + 0.1 sin(x), y = x, the observer gain ``gain``, x0 = 1, x̂0 = 2."""
    return load_spec_text(
        f'[system]\ntime = "{time}"\nA = [[{a}]]\nC = [[1]]\npsi = ["0.1*sin(x1)"]\n'
        f'[method]\nkey = "lyapunov"\nL = [{gain}]\n[simulate]\nhorizon = {horizon}\n'
        "x0 = [1]\nxhat0 = [2]\n",
        f"{time}.toml",
    )


def test_an_unstable_expression_plant_keeps_its_error() -> None:
    """x⁺ = 3x + 0.1 sin(x), L = 2.5: e⁺ = 0.5e − 0.1 sin(x), so |e| ≤ 0.2 after the start,
    while x passes 10²⁸. The runs step [x; e]; from x and x̂ the error would be rounding of
    size 10¹² (found by a random-spec fuzzer on the linear path). Same in continuous time
    (ẋ = x + 0.1 sin(x), L = 3: ė = −2e − 0.1 sin(x), so |e| → ≤ 0.05), and in the batch."""
    disc = _scalar_plant("discrete", a=3, gain=2.5, horizon="60")
    r = simulate_linear_observer(disc, np.array([[2.5]]))
    x, e = [1.0], [1.0]
    for _ in range(60):  # the plant and the error's recursion written out
        x, e = [*x, 3 * x[-1] + 0.1 * np.sin(x[-1])], [*e, 0.5 * e[-1] - 0.1 * np.sin(x[-1])]
    assert abs(r.x[-1, 0]) > 1e28
    np.testing.assert_allclose(r.x[:, 0], x, rtol=1e-15)
    np.testing.assert_allclose(r.e[:, 0], e, rtol=1e-12, atol=1e-15)
    assert r.metrics()["final_error_norm"] <= 0.2
    b = simulate_linear_observer_batch(disc, np.array([[2.5]]), 3)
    assert np.all(b.extra["per_run"]["final_error_norm"] <= 0.2)
    cont = _scalar_plant("continuous", a=1, gain=3, horizon="40\ndt = 0.05")
    r = simulate_linear_observer(cont, np.array([[3.0]]))
    assert abs(r.x[-1, 0]) > 1e16
    late = np.abs(r.e[r.t >= 10, 0])  # e^{-20} of the start is left by t = 10
    assert late.max() <= 0.05 + 1e-8
    np.testing.assert_allclose(r.xhat, r.x + r.e, rtol=1e-15)


def test_a_signal_the_expressions_do_not_name_is_warned() -> None:
    """``[system] h`` is the whole output map: noise that h does not name reaches nothing and
    gave the same numbers as without it, with no word (review). Named (v1 in h), no warning;
    the same for a disturbance and ``f``."""
    base = PLANT.replace("Bd = [[1], [0]]", "Bd = [[1], [0]]\nDn = [[1]]")
    cases = {
        'h = ["x1"]': ("noise", True),
        'h = ["x1 + v1"]': ("noise", False),
        'f = ["0.5*x1 + x2", "0.8*x2"]': ("disturbance", True),
        'f = ["0.5*x1 + x2 + d1", "0.8*x2"]': ("disturbance", False),
    }
    for line, (sig, warned) in cases.items():
        text = scenario(base.replace("[method]", line + "\n[method]"), horizon=5, **{sig: UNIFORM})
        notes = api.simulate(load_spec_text(text)).info.get("warnings", [])
        said = any(f"[simulate.{sig}] reaches nothing" in w for w in notes)
        assert said is warned, (line, notes)


@pytest.mark.parametrize("scale", [1e200, 1e-200])
def test_rmse_of_errors_beyond_the_squares_range(scale: float) -> None:
    """Errors of 10^±200 on an expression plant: the plain sum of e² gave RMSE inf (or 0);
    it is kept scaled by the running max |e| (Dask trial, session 29), and each run's RMSE is
    the separate run's, computed here with its own scale."""
    box = f"lower = [{-2 * scale!r}, {-scale!r}]\nupper = [{2 * scale!r}, {scale!r}]"
    text = scenario(PSI, horizon=200, noise={"kind": "constant", "value": [0.0]}).replace(
        "lower = [-2, -1]\nupper = [2, 1]", box
    )
    assert box in text
    sp = load_spec_text(text)
    r = simulate_linear_observer_batch(sp, L, 4, "E0")
    rmse = r.extra["per_run"]["rmse"]
    assert np.all(np.isfinite(rmse)) and np.all(rmse > 0)
    E = r.error  # run 0's error trajectory: its RMSE with its own scale
    top = np.abs(E).max(axis=0)
    np.testing.assert_allclose(rmse[0], top * np.sqrt(((E / top) ** 2).mean(axis=0)), rtol=1e-12)
    for i in range(4):  # max |e| / √(K + 1) ≤ RMSE ≤ max |e|, each run
        top = r.extra["per_run"]["sup_abs_error"][i]
        assert np.all(top / np.sqrt(201) <= rmse[i] * (1 + 1e-12))
        assert np.all(rmse[i] <= top * (1 + 1e-12))


def test_a_diverging_nonlinear_run_has_a_nan_rmse_not_0() -> None:
    """x1⁺ = x1² + d from 1 leaves the float range: its RMSE is nan (as run 0's table says),
    not 0 — the scaled sum of squares read a nan scale as "no error" and the quantiles
    printed RMSE 0 (re-check trial, session 41). The scaled RMSE keeps nan and inf scales."""
    import warnings

    import numpy as np

    from obsdesign import api
    from obsdesign.simulate import montecarlo as mc

    text = (
        '[system]\ntime = "discrete"\nA = [[0]]\nBd = [[1]]\nC = [[1]]\npsi = ["x1^2"]\n'
        '[method]\nkey = "lyapunov"\nL = [0]\n'
        "[simulate]\nhorizon = 60\nx0 = [1]\nxhat0 = [1]\nseed = 0\n"
        '[simulate.disturbance]\nkind = "uniform"\nbound = 0.01\n'
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = api.simulate(api.load_spec_text(text, "sq.toml"), runs=2)
    q = res.info["quantiles"]["rmse"]["x1"]
    assert all(np.isnan(v) for v in q.values()), q
    sc = np.array([[[np.nan]], [[np.inf]], [[2.0]]])
    got = mc._scaled_rmse(np.array([[[0.0]], [[0.0]], [[1.0]]]), sc, np.zeros((3, 1)), 4)
    assert np.isnan(got[0, 0]) and got[1, 0] == np.inf and got[2, 0] == 1.0
