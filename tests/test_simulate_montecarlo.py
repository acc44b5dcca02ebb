"""Batched Monte Carlo runs (obsdesign.simulate.montecarlo): results independent of the
batching and of the run count, every run equal (to rounding) to the same run simulated on its
own, initial errors from a declared set, known quantiles."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from obsdesign.api import load_spec_text
from obsdesign.errors import SpecError
from obsdesign.simulate import montecarlo as mc
from obsdesign.simulate.linear import (
    exogenous,
    joint_system,
    step_all,
)
from obsdesign.simulate.result import SimResult
from obsdesign.spec.reader import Table

PLANT = (Path(__file__).parent / "specs" / "simulate-plant.toml").read_text()
L = np.array([[0.6], [0.1]])


def _value(v: object) -> str:
    """A TOML value: tables inline, lists and scalars as JSON (which TOML reads)."""
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return json.dumps(v)


def toml(name: str, **keys: object) -> str:
    """One TOML table ``[name]`` with ``keys``."""
    return f"\n[{name}]\n" + "".join(f"{k} = {_value(v)}\n" for k, v in keys.items())


SETS = toml("sets.E0", type="box", lower=[-2, -1], upper=[2, 1]) + toml(
    "sets.line", type="box", dim=1, lower=[-1], upper=[1]
)


def scenario(plant: str = PLANT, horizon: int = 600, **signals: dict) -> str:
    """``plant`` with the sets above and a ``[simulate]`` table (x0 = [1, -1], x̂0 = 0, seed 11)
    whose signals are given as ``noise={"kind": ...}``, ``u=...``, ``disturbance=...``."""
    sim = toml("simulate", horizon=horizon, x0=[1, -1], xhat0=[0, 0], seed=11)
    return plant + SETS + sim + "".join(toml(f"simulate.{k}", **v) for k, v in signals.items())


UNIFORM = {"kind": "uniform", "bound": 0.05}
RANDOM = scenario(noise=UNIFORM)
FIXED = scenario(noise={"kind": "constant", "value": [0.02]})
#: a plant with an input: random u and d reach the plant (every run has its own x)
INPUT_PLANT = PLANT.replace("Bd = [[1], [0]]", "B = [[0], [1]]\nD = [[0.5]]\nBd = [[1], [0]]")


def _run(text, runs, batch=None, ie="E0"):
    sp = load_spec_text(text)
    return mc.run_batch(sp, joint_system(sp, L), runs, ie, batch=batch), sp


def separate(sp, runs, ie="E0"):
    """Every run simulated on its own: its generator (child r of the seed), its initial error
    and signals drawn in the documented order, stepped by the single-run engine
    (``linear.step_all``); a SimResult per run."""
    js, sim, s = joint_system(sp, L), sp.simulate, sp.system
    out = []
    for child in mc.run_seeds(sim.seed, runs):
        g = np.random.default_rng(child)
        e0 = sp.sets[ie].sample(g, 1)[0] if ie else sim.xhat0.f - sim.x0.f
        u, d, v = (sig.evaluate(js.grid, g) for sig in (sim.u, sim.disturbance, sim.noise))
        Z = step_all(js, np.concatenate([sim.x0.f, sim.x0.f + e0]), exogenous(u, d, v)[:-1])
        y = Z[:, :2] @ s.C.f.T + u @ s.D.f.T + v @ s.Dn.f.T
        out.append(SimResult(js.grid, Z[:, :2], Z[:, 2:], y, s.states))
    return out


def assert_runs_match(per_run, ref, rtol=1e-12):
    for i, m in enumerate(r.metrics() for r in ref):
        for k in ("sup_abs_error", "rmse", "sup_abs_estimate"):
            want = [m[k]["x1"], m[k]["x2"]]
            np.testing.assert_allclose(per_run[k][i], want, rtol=rtol, atol=1e-13)
        np.testing.assert_allclose(
            per_run["final_error_norm"][i], m["final_error_norm"], rtol=1e-9, atol=1e-13
        )


CASES = {
    "uniform noise": RANDOM,
    "constant noise": FIXED,
    "outliers": scenario(noise={"kind": "outliers", "amplitude": 2, "rate": 0.05, "bound": 0.01}),
    "random u, d, noise": scenario(
        INPUT_PLANT,
        u={"kind": "uniform", "bound": 1},
        disturbance={"kind": "uniform", "bound": 0.1},
        noise=UNIFORM,
    ),
    "windows and a seeded noise": scenario(
        disturbance={"kind": "windows", "windows": [{"start": 3, "stop": 9, "value": [0.3]}]},
        noise={**UNIFORM, "seed": 4},
    ),
    "continuous": scenario(horizon=3, noise=UNIFORM)
    .replace('"discrete"', '"continuous"')
    .replace("horizon = 3", "horizon = 3\ndt = 0.01")
    .replace("[[0.5, 1], [0, 0.8]]", "[[0, 1], [-2, -0.3]]"),
}


@pytest.mark.parametrize("case", CASES)
def test_each_run_is_the_same_run_simulated_on_its_own(case):
    r, sp = _run(CASES[case], 6)
    assert_runs_match(r.extra["per_run"], separate(sp, 6))


@pytest.mark.parametrize("case", CASES)
def test_results_do_not_depend_on_batching_or_run_count(case, monkeypatch):
    a, _ = _run(CASES[case], 7)
    b, _ = _run(CASES[case], 7, batch=1)
    c, _ = _run(CASES[case], 7, batch=3)
    d, _ = _run(CASES[case], 4, batch=2)
    monkeypatch.setattr(mc, "CHUNK", 48)  # the draws made in other pieces: the same numbers
    e, _ = _run(CASES[case], 7)
    for k, arr in a.extra["per_run"].items():
        for other in (b, c, e):
            np.testing.assert_array_equal(arr, other.extra["per_run"][k])
        np.testing.assert_array_equal(arr[:4], d.extra["per_run"][k])
    np.testing.assert_array_equal(a.extra["initial_errors"], c.extra["initial_errors"])
    np.testing.assert_array_equal(a.xhat, b.xhat)  # run 0's trajectory


@pytest.mark.parametrize("case", ["uniform noise", "random u, d, noise"])
def test_run_0_trajectory_is_its_separate_run(case):
    r, sp = _run(CASES[case], 3)
    one = separate(sp, 1)[0]
    np.testing.assert_allclose(r.xhat, one.xhat, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(r.y, one.y, rtol=1e-12, atol=1e-13)
    m = one.metrics()
    got = r.metrics()
    for k in ("sup_abs_error", "rmse", "sup_abs_estimate"):
        for st in ("x1", "x2"):
            assert got[k][st] == pytest.approx(m[k][st], rel=1e-12)


def test_initial_errors_come_from_the_set_and_differ():
    r, _ = _run(FIXED, 50)
    e0 = r.extra["initial_errors"]
    assert np.all(np.abs(e0[:, 0]) <= 2) and np.all(np.abs(e0[:, 1]) <= 1)
    assert len({tuple(e) for e in e0}) == 50
    assert r.info["initial_error"] == "E0" and r.info["runs"] == 50
    fixed, _ = _run(FIXED, 3, ie=None)
    np.testing.assert_array_equal(fixed.extra["initial_errors"], [[-1, 1]] * 3)


@pytest.mark.parametrize(
    "table",
    [
        {"type": "box", "lower": [-2, -1], "upper": [2, 1]},
        {"type": "ellipsoid", "E": [[2, 0.5], [0.5, 1]], "center": [0.5, 0]},
        # a thin strip (2 % of its bounding box): many runs find no point in the first block
        {"type": "polytope", "G": [[1, -1], [-1, 1], [1, 1], [-1, -1]], "g": [0.02] * 2 + [2] * 2},
        # one draw in 10⁴ inside: runs need more than 16 rounds, whose size then doubles (the
        # continuation after the first block counts it: start_round = 1; session 38)
        {"type": "polytope", "G": [[1, -1], [-1, 1], [1, 1], [-1, -1]], "g": [1e-4] * 2 + [2] * 2},
    ],
)
def test_initial_errors_at_once_are_the_sets_own_samples(table):
    sp = load_spec_text(scenario(noise=UNIFORM) + toml("sets.S", **table))
    S = sp.sets["S"]
    kids = mc.run_seeds(5, 40)
    want = np.stack([S.sample(np.random.default_rng(c), 1)[0] for c in kids])
    gens = [np.random.default_rng(c) for c in kids]
    np.testing.assert_array_equal(mc.initial_errors(S, gens, np.zeros(2)), want)
    after = [np.random.default_rng(c) for c in kids]
    for g in after:
        S.sample(g, 1)
    # each generator is left where the set's sample leaves it (the signals come next)
    assert [g.random() for g in gens] == [g.random() for g in after]


def test_noise_seeds_are_spawned_per_run():
    r, _ = _run(RANDOM, 4, ie=None)  # same initial error, different noise
    sup = r.extra["per_run"]["rmse"][:, 0]
    assert len(set(sup.tolist())) == 4
    kids = mc.run_seeds(11, 4)
    assert [k.spawn_key for k in kids] == [(0,), (1,), (2,), (3,)]
    again = np.random.SeedSequence(11, spawn_key=(2,)).generate_state(4)
    assert kids[2].generate_state(4).tolist() == again.tolist()


def test_quantiles_known_answer():
    q = mc.quantiles({"final_error_norm": np.arange(101.0), "rmse": np.ones((3, 1))}, ["x1"])
    assert q["final_error_norm"] == {"q05": 5.0, "q50": 50.0, "q95": 95.0, "max": 100.0}
    assert q["rmse"]["x1"]["max"] == 1.0


def test_parse_initial_error():
    sp = load_spec_text(FIXED)
    assert mc.parse_initial_error(Table({"initial_error": "E0"}, "f.toml", "simulate"), sp) == "E0"
    assert mc.parse_initial_error(Table({}, "f.toml", "simulate"), sp) is None
    with pytest.raises(SpecError, match=r"simulate.initial_error.*known: E0, line"):
        mc.parse_initial_error(Table({"initial_error": "nope"}, "f.toml", "simulate"), sp)
    with pytest.raises(SpecError, match="dimension 2"):
        mc.parse_initial_error(Table({"initial_error": "line"}, "f.toml", "simulate"), sp)


def test_products_in_pieces_keep_every_row():
    g = np.random.default_rng(0)
    a, b = g.standard_normal((1001, 19)), g.standard_normal((19, 64))
    whole = mc._mm(a, b)  # cut into pieces of at most 2^18 / (19·64) rows
    np.testing.assert_allclose(whole, a @ b, rtol=1e-13)
    for rows in (slice(0, 2), slice(5, 8), slice(300, 1001)):
        np.testing.assert_array_equal(mc._mm(a[rows], b), whole[rows])


def test_runs_of_an_unstable_plant_keep_their_errors() -> None:
    """x⁺ = 3x, L = 2.5 (e⁺ = 0.5e), 60 steps, initial errors from [−1, 1]: x reaches
    4·10²⁸, and the runs used to report x̂ − x of that size (every run ≈ 10¹², quantiles
    all equal; random-spec fuzzer). Stepped in [x; e], every run's final error is
    0.5⁶⁰·|e0| and run 0's trajectory carries the same error, also with an [x; x̂] joint
    system passed in (run_batch converts it)."""
    from obsdesign.simulate.linear import simulate_linear_observer_batch

    text = (
        '[system]\ntime = "discrete"\nA = [[3]]\nC = [[1]]\n[sets.E0]\ntype = "box"\n'
        'lower = [-1]\nupper = [1]\n[method]\nkey = "lyapunov"\nL = [2.5]\n[simulate]\n'
        "horizon = 60\nx0 = [1]\nxhat0 = [2]\n"
    )
    sp = load_spec_text(text)
    for res in (
        simulate_linear_observer_batch(sp, np.array([[2.5]]), 7, "E0"),
        mc.run_batch(sp, joint_system(sp, np.array([[2.5]])), 7, "E0"),
    ):
        e0 = np.abs(res.extra["initial_errors"][:, 0])
        fin = res.extra["per_run"]["final_error_norm"]
        np.testing.assert_allclose(fin, e0 * 0.5**60, rtol=1e-12)
        np.testing.assert_allclose(
            res.e[:, 0], res.extra["initial_errors"][0, 0] * 0.5 ** np.arange(61), rtol=1e-12
        )
        assert res.x[-1, 0] == 3.0**60


@pytest.mark.parametrize("disturbance", [None, {"kind": "uniform", "bound": 0.1}])
def test_runs_keep_a_finite_error_after_the_plant_overflows(disturbance) -> None:
    """x⁺ = 3x (+ d), L = 2.5 (e⁺ = 0.5e − d), 700 steps: x leaves the float range at step
    647 while the error stays finite. The error read x's columns with coefficient 0, and
    0·inf = nan made every run's sup |e|, RMSE and final |e| nan, and the 16-step block
    product spread it back to the block's start (simulate trial, session 39; the single run
    was right). Shared x (no random signal in the plant) and per-run x alike: each run's
    error metrics are those of its own run stepped with x and e apart."""
    text = (
        '[system]\ntime = "discrete"\nA = [[3]]\nC = [[1]]\nBd = [[1]]\n[sets.E0]\n'
        'type = "box"\nlower = [-1]\nupper = [1]\n[method]\nkey = "lyapunov"\nL = [2.5]\n'
        "[simulate]\nhorizon = 700\nx0 = [1]\nxhat0 = [2]\nseed = 5\n"
    )
    if disturbance is not None:
        text += toml("simulate.disturbance", **disturbance)
    sp = load_spec_text(text)
    Lg = np.array([[2.5]])
    js = joint_system(sp, Lg)
    # sup |x̂| = inf in every run, and only it (the warning said "their errors or estimates
    # leave the float range … smaller initial errors": re-check trial, session 39)
    with pytest.warns(UserWarning) as said:
        res = mc.run_batch(sp, js, 5, "E0")
    text = " ".join(str(w.message) for w in said)
    assert not [w for w in said if issubclass(w.category, RuntimeWarning)]  # numpy's, raw
    assert "sup |x̂| of 5 of 5 runs is not finite" in text and "initial errors" not in text
    per = res.extra["per_run"]
    sim = sp.simulate
    for r, child in enumerate(mc.run_seeds(sim.seed, 5)):
        g = np.random.default_rng(child)
        e0 = sp.sets["E0"].sample(g, 1)[0]
        u, d, v = (sig.evaluate(js.grid, g) for sig in (sim.u, sim.disturbance, sim.noise))
        e = np.empty(701)
        e[0] = e0[0]
        for k in range(700):  # e = x̂ − x: e⁺ = 0.5e − d (+ L·v, v = 0)
            e[k + 1] = 0.5 * e[k] - d[k, 0]
        assert per["sup_abs_error"][r, 0] == pytest.approx(np.max(np.abs(e)), rel=1e-12)
        assert per["rmse"][r, 0] == pytest.approx(np.sqrt(np.mean(e * e)), rel=1e-12)
        assert per["final_error_norm"][r] == pytest.approx(abs(e[-1]), rel=1e-9, abs=1e-300)
        assert per["sup_abs_estimate"][r, 0] == np.inf
    assert np.all(np.isfinite(res.e))  # run 0's error trajectory


def test_runs_1_is_run_0_of_any_run_count(tmp_path) -> None:
    """``--runs 1`` took the single scenario (default_rng(seed)), so its numbers differed from
    run 0 of ``--runs 2`` (child 0 of SeedSequence(seed)), against the documented "run r's
    numbers do not depend on N" (independent simulate review). Any given run count is the
    Monte Carlo study now; no run count is the single scenario, as before."""
    from obsdesign import api

    p = tmp_path / "s.toml"
    p.write_text(RANDOM)
    single = api.simulate(p).metrics()
    one = api.simulate(p, options={"runs": "1"})
    two = api.simulate(p, options={"runs": "2"})
    for k, v in one.extra["per_run"].items():
        np.testing.assert_array_equal(v[0], two.extra["per_run"][k][0])
    assert one.info["runs"] == 1 and "quantiles" in one.info
    assert single["final_error_norm"] != one.metrics()["final_error_norm"]
    p.write_text(RANDOM.replace("seed = 11", "seed = 11\nruns = 1"))
    spec_one = api.simulate(p)
    np.testing.assert_array_equal(spec_one.extra["per_run"]["rmse"], one.extra["per_run"]["rmse"])


EXPR = PLANT.replace("[method]", 'f = ["0.5*x1 + x2 + 0.01*sin(x1)", "0.8*x2"]\n[method]')


@pytest.mark.parametrize(
    "text, options, where",
    [
        (RANDOM, {}, "the run at step 0 of 600"),
        (RANDOM, {"runs": "3"}, "0 of 3 Monte Carlo runs done"),
        (scenario(EXPR, noise=UNIFORM), {}, "the expression plant at step 0 of 600"),
        (scenario(EXPR, noise=UNIFORM), {"runs": "3"}, "0 of 3 Monte Carlo runs done"),
    ],
)
def test_lyapunov_simulate_has_a_time_budget(text, options, where, slow_clock, tmp_path):
    """``[simulate] time_limit`` / ``--option time_limit`` (default 300 s) bound the lyapunov
    simulation: 10⁶ steps of an expression plant took ~70 s and the memory limit allowed 20
    times more, with no way to stop it. A clock past the budget stops the single run and the
    Monte Carlo study, linear or not, with exit 3 naming the key and where it got to."""
    from obsdesign import api
    from obsdesign.errors import SolverError

    p = tmp_path / "s.toml"
    p.write_text(text)
    api.simulate(p, options={**options, "time_limit": "999"})  # the real clock: finished
    slow_clock()  # every look at the clock is 1000 s later
    with pytest.raises(SolverError, match=rf"within 999 s \(\[simulate\] time_limit\): {where}"):
        api.simulate(p, options={**options, "time_limit": "999"})
    slow_clock()
    p.write_text(text.replace("seed = 11", "seed = 11\ntime_limit = 999"))
    with pytest.raises(SolverError, match="within 999 s"):
        api.simulate(p, options=options)


def test_a_batch_checks_its_budget_between_chunks(monkeypatch) -> None:
    """The Monte Carlo stepping looks at the budget before every chunk of CHUNK steps, not only
    between batches (one batch of 512 runs × 10⁶ steps is the long part)."""
    from obsdesign.errors import SolverError
    from obsdesign.simulate.budget import TimeBudget

    monkeypatch.setattr(mc, "CHUNK", 160)  # a multiple of BLOCK
    sp = load_spec_text(RANDOM)
    looks = []
    budget = TimeBudget(60, "advice")
    real = budget.check

    def check(where: str) -> None:
        looks.append(where)
        if len(looks) == 5:
            budget.deadline = -1.0
        real(where)

    budget.check = check
    with pytest.raises(SolverError, match=r"a batch of 2 runs at step 320 of 600"):
        mc.run_batch(sp, joint_system(sp, L), 2, "E0", budget=budget)
    assert looks[:3] == [
        "0 of 2 Monte Carlo runs done",
        "drawing initial errors (0 of 128 points tested)",  # session 37: the draw looks too
        "a batch of 2 runs at step 0 of 600",
    ]


def test_an_initial_error_set_without_volume_is_bad_input() -> None:
    """A polytope of (almost) no volume (|x1 − x2| ≤ 1e-12) as ``initial_error``: rejection
    sampling accepted nothing and ``--runs`` hung, ignoring time_limit (review). It is exit 2
    naming the key now; the sampler itself gives up after MAX_SAMPLE_ROUNDS rounds."""
    from obsdesign.errors import InputError
    from obsdesign.sets import base

    thin = toml(
        "sets.T", type="polytope", G=[[1, -1], [-1, 1], [1, 0], [-1, 0]], g=[1e-12, 1e-12, 1, 1]
    )
    text = (
        PLANT
        + SETS
        + thin
        + toml("simulate", horizon=10, x0=[1, -1], xhat0=[0, 0], initial_error="T", runs=3)
    )
    with pytest.raises(
        SpecError, match=r"\[simulate\.initial_error\] set 'T': rejection sampling kept 0 of"
    ):
        load_spec_text(text)
    sp = load_spec_text(text.replace('initial_error = "T"', 'initial_error = "E0"'))
    with pytest.raises(InputError, match="it has \\(almost\\) no volume"):
        sp.sets["T"].sample(np.random.default_rng(1), 1)
    assert base.MAX_SAMPLE_ROUNDS == 20_000
    pts = sp.sets["E0"].sample(np.random.default_rng(1), 5)
    assert pts.shape == (5, 2) and np.all(sp.sets["E0"].contains(pts))


def test_metrics_and_quantiles_of_huge_or_infinite_errors() -> None:
    """Errors near 1e300 printed RMSE and final |e| as inf (e² overflowed), and quantiles of
    metrics that are all inf printed nan beside a max of inf (review): the RMSE and norm are
    scaled where they overflow, and a quantile between two equal infinities is that infinity."""
    from obsdesign.simulate.result import metrics

    e = np.array([[1e300, -1e300], [2e300, 0.0]])
    m = metrics(e, ["a", "b"])
    assert m["rmse"]["a"] == pytest.approx(np.sqrt(2.5) * 1e300)
    assert m["final_error_norm"] == 2e300
    small = np.array([[0.1, 3.0], [2.0, -1.0]])
    m = metrics(small)  # the unscaled numbers, to the bit
    assert m["rmse"]["x1"] == float(np.sqrt(np.mean(small[:, 0] ** 2)))
    assert m["final_error_norm"] == float(np.linalg.norm(small[-1]))
    q = mc._q(np.array([np.inf, np.inf, np.inf]))
    assert all(v == np.inf for v in q.values())
    q = mc._q(np.array([1.0, 2.0, 3.0]))
    assert q["q50"] == 2.0 and q["max"] == 3.0


def test_runs_whose_metrics_overflow_are_said_in_words(tmp_path) -> None:
    """x0 = ±1.7e308: the runs leave the float range; the only word was numpy's "overflow
    encountered in multiply" (review). One worded warning counts the runs. At x0 = ±1e300
    every value is finite and so is every metric now: the RMSE's running sum of e² overflowed
    (inf, with that warning) and is measured again from the run's trajectory (session 27)."""
    from obsdesign import api

    p = tmp_path / "s.toml"
    p.write_text(RANDOM.replace("x0 = [1, -1]", "x0 = [1.7e308, -1.7e308]"))
    notes = api.simulate(p, options={"runs": "3"}).info["warnings"]
    assert any(
        w.startswith("warning: UserWarning: the metrics of 3 of 3 runs are not finite")
        for w in notes
    )
    # in spans (as on Dask): the same words, counted over every run (re-check trial,
    # session 29: no "warning: UserWarning: " prefix)
    spans = api.simulate(p, options={"runs": "3"}, batches=2).info["warnings"]
    assert [w for w in spans if "not finite" in w] == [w for w in notes if "not finite" in w]
    p.write_text(RANDOM.replace("x0 = [1, -1]", "x0 = [1e300, -1e300]"))
    info = api.simulate(p, options={"runs": "3"}).info
    assert "warnings" not in info
    assert 1e298 < info["quantiles"]["rmse"]["x1"]["max"] < 1e300
    p.write_text(RANDOM)
    assert "warnings" not in api.simulate(p, options={"runs": "3"}).info


def test_a_thin_set_that_a_run_cannot_draw_from_is_named(monkeypatch) -> None:
    """A thin but sampleable initial-error set passed the load-time draw, then a run's draw
    gave up with a message naming neither file nor key (re-check review): the study names
    both. Shown with the sampler's rounds cut to 1 after loading (a band |x1 − x2| ≤ 10⁻³:
    about one draw in 2,000 of its bounding box is inside)."""
    from obsdesign import api
    from obsdesign.errors import InputError
    from obsdesign.sets import base

    band = [[1, -1], [-1, 1], [1, 0], [-1, 0]]
    thin = toml("sets.T", type="polytope", G=band, g=[1e-3, 1e-3, 1, 1])
    text = (
        PLANT
        + SETS
        + thin
        + toml("simulate", horizon=10, x0=[1, -1], xhat0=[0, 0], initial_error="T", runs=50)
    )
    sp = load_spec_text(text, "thin.toml")
    monkeypatch.setattr(base, "MAX_SAMPLE_ROUNDS", 1)
    with pytest.raises(InputError, match=r"^thin\.toml: \[simulate\.initial_error\] set 'T': "):
        api.simulate(sp)


@pytest.mark.parametrize("runs", [0, -3, 2.5, True])
def test_the_api_refuses_a_run_count_below_one_or_not_whole(runs: object) -> None:
    """``simulate(spec, runs=0)`` ran once (``runs or 1``) while the CLI refuses ``--runs 0``
    (outsider trial, session 22): a run count is a whole number ≥ 1 (numpy integers too;
    since session 45 also a whole float such as 2.0, as the integer options take theirs)."""
    from obsdesign import api
    from obsdesign.errors import InputError

    spec = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    with pytest.raises(InputError, match="at least 1"):
        api.simulate(spec, runs=runs)
    assert api.simulate(spec, runs=np.int64(2)).metrics()["runs"] == 2


def test_the_api_refuses_a_run_count_past_64_bits() -> None:
    """``simulate(spec, runs=10**400)`` was a bare OverflowError (exit 3 from the CLI; API
    review, session 44): refused by name, exit 2."""
    from obsdesign import api
    from obsdesign.errors import InputError

    spec = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    for runs in (2**63, 10**400):
        with pytest.raises(InputError, match="runs: expected at most 2"):
            api.simulate(spec, runs=runs)


_SCALE_SPEC = """[system]
time = "discrete"
A = [[0, 1], [1, 0]]
C = [[1, 0]]
[method]
key = "lyapunov"
L = [-1.87, 1.874]
lambda = 0.955
[simulate]
horizon = 300
x0 = [0, 0]
xhat0 = [S, S]
"""


def _exact_metrics(s: str) -> tuple[list[float], float]:
    """RMSE of e_1, e_2 and the final |e| of e⁺ = (A − LC)e from e(0) = (s, s), exactly."""
    from fractions import Fraction as F

    L = [F(-187, 100), F(1874, 1000)]
    e = [F(s), F(s)]
    traj = [e]
    for _ in range(300):
        e = [e[1] - L[0] * e[0], e[0] - L[1] * e[0]]
        traj.append(e)
    scale = 1 / F(s)
    rms = [
        float(sum((v[i] * scale) ** 2 for v in traj) / len(traj)) ** 0.5 / float(scale)
        for i in range(2)
    ]
    fin = float(sum((v * scale) ** 2 for v in traj[-1])) ** 0.5 / float(scale)
    return rms, fin


@pytest.mark.parametrize("s", ["1e-200", "1e200"])
def test_metrics_of_errors_near_the_ends_of_the_float_range(s: str) -> None:
    """RMSE and final |e| of errors near 10⁻²⁰⁰ and 10²⁰⁰, single run and Monte Carlo, match
    the exact values (Fractions) to 10⁻¹⁰: the single run printed RMSE 0.0 for 10⁻²⁰⁰, the
    Monte Carlo quantiles 0.0 and inf, beside run 0's finite table (simulate trial, session
    27)."""
    from obsdesign import api

    spec = load_spec_text(_SCALE_SPEC.replace("S", s), "scale.toml")
    rms, fin = _exact_metrics(s)
    one = api.simulate(spec).metrics()
    mc_q = api.simulate(spec, runs=2).info["quantiles"]
    for got in (
        [one["rmse"]["x1"], one["rmse"]["x2"], one["final_error_norm"]],
        [mc_q["rmse"]["x1"]["max"], mc_q["rmse"]["x2"]["max"], mc_q["final_error_norm"]["max"]],
    ):
        np.testing.assert_allclose(got, [*rms, fin], rtol=1e-10)


@pytest.mark.parametrize("scale", ["1e200", "1e-200"])
@pytest.mark.parametrize("case", ["uniform noise", "random u, d, noise"])
def test_rmse_beyond_the_squares_range_is_every_runs_own_for_any_span(case, scale) -> None:
    """Initial errors of size 10^±200: the running sum of e² overflows (underflows) for every
    run. At most 64 runs were measured again, per span, so two spans printed other quantiles
    than one, and the 36 runs left at inf moved the serial quantiles by 30–46 % (Dask trial,
    session 29). Every such run is now measured again (scaled): each run's RMSE is the one of
    the same run simulated on its own, and spans give the serial run's numbers bit for bit."""
    s = float(scale)
    box = f"lower = [{-2 * s!r}, {-s!r}]\nupper = [{2 * s!r}, {s!r}]"
    text = CASES[case].replace("lower = [-2, -1]\nupper = [2, 1]", box)
    assert box in text
    runs = 70  # > 64: the old cap
    whole, sp = _run(text, runs)
    rmse = whole.extra["per_run"]["rmse"]
    assert np.all(np.isfinite(rmse)) and np.all(rmse > 0)
    for i, m in enumerate(r.metrics() for r in separate(sp, runs)):
        np.testing.assert_allclose(rmse[i], [m["rmse"]["x1"], m["rmse"]["x2"]], rtol=1e-12)
    js = joint_system(sp, L)
    parts = [mc.run_batch(sp, js, runs, "E0", span=sp_) for sp_ in ((0, 30), (30, 70))]
    merged = mc.merge(parts, sp.system.states)
    for k, arr in whole.extra["per_run"].items():
        np.testing.assert_array_equal(arr, merged.extra["per_run"][k])
    assert merged.info["quantiles"] == whole.info["quantiles"]


def test_run_seed_is_the_spawned_child() -> None:
    """A batch makes only its own seeds (10⁷ runs spawned all of theirs, 4 GB, before the
    first time-limit check; Dask trial, session 29): child r alone is spawn's child r."""
    kids = mc.run_seeds(11, 5)
    for r in range(5):
        a, b = np.random.default_rng(kids[r]), np.random.default_rng(mc.run_seed(11, r))
        assert np.array_equal(a.random(4), b.random(4))


def test_nonfinite_runs_are_counted_over_every_span() -> None:
    """Two spans of 100 runs each said "36 of 100 runs" for 72 of 200 (each span counted its
    own and the texts merged; Dask trial, session 29): a span leaves the count to merge."""
    per_run = {
        "sup_abs_error": np.ones((4, 2)),
        "rmse": np.array([[1.0, 1.0], [np.inf, 1.0], [1.0, 1.0], [1.0, np.nan]]),
        "sup_abs_estimate": np.ones((4, 2)),
        "final_error_norm": np.ones(4),
    }
    assert mc.nonfinite_warning(per_run).startswith("the metrics of 2 of 4 runs are not finite")
    per_run["rmse"][1:] = 1.0
    assert mc.nonfinite_warning(per_run) == ""


def test_initial_errors_from_a_far_thin_strip_are_inside_it() -> None:
    """Re-check trial 36: all 20 Monte Carlo initial errors drawn from a thin sheared strip
    at e1 ≈ 3·10¹³ were outside it (the float ``contains`` with an absolute 10⁻¹²); the
    batch draw now tests membership as ``ConvexSet.sample`` does (``contains_rel`` at
    SAMPLE_REL), and gives the same points as the set's own sampler."""
    from fractions import Fraction

    from flint import fmpq

    from obsdesign.certify.exact import frac, qmat, qvec
    from obsdesign.sets import Polytope

    E0 = Polytope(
        qmat([[fmpq(1, 10), fmpq(3, 10)], [fmpq(-1, 10), fmpq(-3, 10)], [1, 0], [-1, 0]]),
        qvec([fmpq(1, 10**4), fmpq(1, 10**4), 30000000000001, -29999999999999]),
    )
    gens = [np.random.default_rng(s) for s in range(20)]
    got = mc.initial_errors(E0, gens, np.zeros(2))
    for x in got:
        for row, b in zip(E0.G_q, E0.g_q, strict=True):
            assert sum(frac(a) * Fraction(float(v)) for a, v in zip(row, x, strict=True)) <= frac(b)
    want = np.stack([E0.sample(np.random.default_rng(s), 1)[0] for s in range(20)])
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize(
    ("runs", "where"),
    [
        (3, "sampling the ellipsoid"),
        (512, r"drawing initial errors \([\d,]+ of 32,768 points tested"),
    ],
)
def test_drawing_initial_errors_respects_the_time_limit(runs: int, where: str) -> None:
    """Re-check trial 37: an ellipsoid 10⁻⁵ wide at 3·10¹³ (thinner than the float spacing
    there, 0.004) has every drawn point decided in rational arithmetic: the spec loader's
    check and the runs' draws took ~55 s each before the "no volume" error, past any
    time_limit. The loader now gives up after LOAD_SAMPLE_SECONDS (leaving the set to the
    runs) and the draws look at the time budget: exit 3 naming the sampling — with 512 runs
    between chunks of the first block's 32,768 points (16 s untested in n = 10; re-check 37b)."""
    from obsdesign import api
    from obsdesign.simulate.budget import TimeExceeded

    text = """[system]
time = "discrete"
A = [[0.5, 1], [0, 0.8]]
C = [[1, 0]]
[method]
key = "lyapunov"
L = [0.6, 0.1]
[sets.E0]
type = "ellipsoid"
E = [[10000000000, 0], [0, 1]]
center = [30000000000000.001953125, 0]
[simulate]
horizon = 5
x0 = [0, 0]
xhat0 = [0, 0]
seed = 1
runs = RUNS
time_limit = 0.5
initial_error = "E0"
"""
    sp = load_spec_text(text.replace("RUNS", str(runs)), "far.toml")
    with pytest.raises(TimeExceeded, match=where):
        api.simulate(sp, api.design(sp))


def test_span_and_client_keywords_are_checked() -> None:
    """simulate(spec, span="ab") and span=(0.5, 2.5) were bare TypeErrors, client=object() a
    bare AttributeError (API review 45): InputErrors naming the keyword; a span of numpy
    integers still runs."""
    import numpy as np

    from obsdesign import api
    from obsdesign.errors import InputError

    spec = api.load_spec(
        Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    )
    for span in ("ab", (0.5, 2.5), (True, 2), (0, 1, 2)):
        with pytest.raises(InputError, match="span: expected a pair of whole numbers"):
            api.simulate(spec, runs=5, span=span)
    with pytest.raises(InputError, match="client: expected a dask.distributed.Client"):
        api.simulate(spec, runs=3, client=object())
    res = api.simulate(spec, runs=5, span=(np.int64(1), np.int64(3)))
    assert res.info["span"] == [1, 3]


def test_runs_take_whole_values_as_the_integer_options_do_and_huge_ints_are_named() -> None:
    """runs = Decimal(3), Fraction(3), 3.0 and a 0-d array were refused while seed took them,
    and an int past Python's 4,300-digit text limit (seed, runs, span, batches) was a bare
    ValueError from the message itself (re-check review 45). runs take whole values of any
    real type, never a bool; a huge int is named by its digit count; a huge seed runs."""
    from decimal import Decimal
    from fractions import Fraction

    from obsdesign import api
    from obsdesign.errors import InputError

    spec = api.load_spec(
        Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    )
    # every numpy float too (np.float32(3) was refused beside np.float64(3); re-check review 46)
    wholes = (np.float32(3), np.float16(3), np.longdouble(3), np.array(np.float32(3)))
    for runs in (Decimal(3), Fraction(3), 3.0, np.array(3), np.int64(3), *wholes):
        assert api.simulate(spec, runs=runs).info["runs"] == 3
    for runs in (True, 2.5, Decimal("3.5"), 0, "3x", np.float32(2.5), np.longdouble("inf")):
        with pytest.raises(InputError, match="runs: expected a whole number of runs"):
            api.simulate(spec, runs=runs)
    with pytest.raises(
        InputError, match="runs: expected at most 2.63 − 1 runs, got a number of about 4301 digits"
    ):
        api.simulate(spec, runs=10**4301)
    with pytest.raises(InputError, match=r"span: expected 0 <= a < b <= 4, got \(0, a number of"):
        api.simulate(spec, runs=4, span=(0, 10**5000))
    imp = api.load_spec(
        spec.file.replace("constrained-redesign-sec5-lyapunov", "schaum-impulsive-example")
    )
    assert api.simulate(imp, runs=2, seed=10**4301).info["runs"] == 2
