"""The vectorized ε-γ observer of the search-space method (paper 004): consistency (the true
state's cell is never dropped), the final error, shrinking at the switches, the memory cap, the
literal Definition 7 and the "consistency lost" diagnosis."""

from __future__ import annotations

import itertools
import math
import warnings
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.cli import app
from obsdesign.errors import InconclusiveError, InputError
from obsdesign.methods.searchspace import sim as S
from obsdesign.methods.searchspace.sim import ConsistencyLost, MemoryCap, cover_box, recover
from obsdesign.simulate.budget import TimeBudget, TimeExceeded

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "hernandez-garcia-example.toml"
PEND = ROOT / "specs" / "hernandez-garcia-pendulum.toml"
TEXT = SPEC.read_text(encoding="utf-8")


def _load(text: str, tmp_path: Path):
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    sp = api.load_spec(p)
    return sp, api.design(sp)


@pytest.fixture(scope="module")
def example():
    sp = api.load_spec(SPEC)
    rep = api.design(sp)
    return sp, rep, api.simulate(sp, rep)


def _level_bounds(res, rep):
    """ε_i e^{L_f (t − τ_i)} at every sample (the radius Lemma 2 guarantees)."""
    p = rep.parameters
    eps = [float(e) for e in p.float("eps_schedule")]
    L_f, dtau = p.float("L_f"), p.float("dtau")
    t0 = res.t[0]
    i = np.floor((res.t - t0) / dtau + 1e-9).astype(int)
    since = res.t - t0 - i * dtau
    return np.array([eps[min(j, len(eps) - 1)] for j in i]) * np.exp(L_f * since)


def test_true_cell_is_never_dropped(example):
    """Consistency (Lemma 2 / Theorem 1): at every sample a live centre lies within
    ε_i e^{L_f (t − τ_i)} of the true state."""
    sp, rep, res = example
    near = res.extra["true_cell"]
    assert np.all(near <= _level_bounds(res, rep) * (1 + 1e-9))


def test_final_error_at_most_eps_star(example):
    """After the schedule reached γ⋆, right after each switch the true state is inside a
    live cell of radius ε⋆; at the end the true cell's error is ≤ ε⋆ e^{L_f (t − τ)}."""
    sp, rep, res = example
    eps_star = rep.parameters.float("eps_star")
    t, near = res.t, res.extra["true_cell"]
    reached = rep.parameters.float("dtau") * (len(rep.parameters["gamma_schedule"]) - 1)
    for s in res.extra["switches"]:
        if s >= reached - 1e-9:
            k = int(np.argmin(np.abs(t - s)))
            assert near[k] <= eps_star
    assert res.info["final_true_cell"] <= _level_bounds(res, rep)[-1]
    assert res.info["max_live"] <= 1300  # the figure for a sound re-covering


def test_centroid_error_after_informative_phase(tmp_path):
    """y = x1·[x1 > 0] is informative while x1 > 0 (t < 6.7 here): at t = 5 the centroid's
    error is below ε⋆ = 1/30 (over [6.7, 12] the output is 0 and it stays ≈ 0.05)."""
    sp, rep = _load(TEXT.replace("horizon = 12", "horizon = 5"), tmp_path)
    res = api.simulate(sp, rep)
    assert res.info["final_error"] <= rep.parameters.float("eps_star")


def test_search_space_shrinks_at_switches(example):
    """Figs. 3-5: in the informative phase the search space's extent (footnote 9's error)
    falls at most switches and by a factor > 10 overall."""
    sp, rep, res = example
    t, ext = res.t, res.extra["err_fn9"].max(axis=1)
    sw = [s for s in res.extra["switches"] if 1.5 < s < 6.1]
    at = [ext[int(np.argmin(np.abs(t - s)))] for s in sw]
    falls = sum(b < a for a, b in zip(at, at[1:], strict=False))
    assert falls >= 0.7 * (len(at) - 1)
    assert at[-1] < at[0] / 10  # 3.55 → 0.19 on the shipped example


def test_pendulum_final_error(tmp_path):
    sp = api.load_spec(PEND)
    rep = api.design(sp)
    assert rep.exit_code() == 0
    res = api.simulate(sp, rep)
    assert res.info["final_error"] <= rep.parameters.float("eps_star")
    assert np.all(res.extra["true_cell"] <= _level_bounds(res, rep) * (1 + 1e-9))


def test_memory_cap_fails_with_explanation(example):
    sp, rep, _ = example
    with pytest.raises(MemoryCap, match="dropping any of them could drop the cell"):
        api.simulate(sp, rep, max_centres=12)


def test_definition_7_literally_grows(example):
    sp, rep, _ = example
    with pytest.raises(MemoryCap, match="grows without bound"):
        api.simulate(sp, rep, refine="paper", max_centres=3000)


def test_consistency_lost_is_diagnosed(tmp_path):
    """x0 outside D with an informative output: every centre is dropped at t₀; the message
    says which assumption failed. (With the example's output a state outside D can be
    recovered: the search space dilates while y = 0.)"""
    text = TEXT.replace("x0 = [0, 1]", "x0 = [1.5, 0]").replace('["x1*step(x1)"]', '["x1"]')
    sp, rep = _load(text, tmp_path)
    with pytest.raises(ConsistencyLost, match=r"consistency lost.*x0 = \[1\.5, 0\.0\] is not in D"):
        api.simulate(sp, rep)
    # near the float limit: np.round(x0, 6) multiplied by 10⁶ and printed inf (session 44)
    sp, rep = _load(text.replace("x0 = [1.5, 0]", "x0 = [1e308, 0]"), tmp_path)
    with pytest.raises(ConsistencyLost, match=r"x0 = \[1e\+308, 0\.0\] is not in D"):
        api.simulate(sp, rep)


def test_cli_simulate_option_and_cap(tmp_path):
    r = CliRunner().invoke(app, ["simulate", str(SPEC), "--option", "max_centres=12"])
    assert r.exit_code == 1
    assert "memory cap" in r.output
    r = CliRunner().invoke(app, ["simulate", str(SPEC), "--option", "refine=literal"])
    assert r.exit_code == 2


def test_time_limit_stops_the_simulation_with_a_clear_message(example, tmp_path, monkeypatch):
    """A budget below the run's time (``time_limit``, as an option and as a ``[simulate]``
    key) stops it with exit 3 and a message naming the key and the progress; the default
    (300 s) lets the example finish. A clock that jumps past the budget inside the
    refinement stops there (checked per chunk of rows)."""
    import time as _time

    from obsdesign.methods.searchspace import sim as S

    sp, rep, res = example
    assert res.x.shape[0] > 2  # the default budget: finished
    with pytest.raises(
        TimeExceeded, match=r"not finished within 0\.001 s \(\[simulate\] time_limit\)"
    ):
        api.simulate(sp, rep, time_limit=1e-3)
    text = TEXT.replace("[simulate]", "[simulate]\ntime_limit = 0.001", 1)
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    r = CliRunner().invoke(app, ["simulate", str(p)])
    assert r.exit_code == 3 and "time_limit" in r.output and "samples done" in r.output
    r = CliRunner().invoke(app, ["simulate", str(SPEC), "--option", "time_limit=0"])
    assert r.exit_code == 2
    C = np.random.default_rng(0).uniform(-1, 1, size=(40, 2))
    past = TimeBudget(5.0, "advice")
    past.deadline = _time.perf_counter() - 1
    with pytest.raises(TimeExceeded, match=r"within 5 s .*: refinement \(0 of 40 centres"):
        S.recover(C, 0.3, 0.1, 10**6, past)
    assert len(S.recover(C, 0.3, 0.1, 10**6, TimeBudget(60.0, "advice")))


def test_time_limit_is_checked_inside_one_sample_flow(example):
    """``substeps = 10⁶`` ran past 8× its time_limit: the budget was looked at only between
    samples (independent simulate review). It is now looked at every BUDGET_EVERY RK4
    substeps: 10⁵ substeps of the first sample (seconds) stop at the budget, inside it."""
    import time as _time

    sp, rep, _ = example
    t0 = _time.perf_counter()
    with pytest.raises(
        TimeExceeded, match=r"in the RK4 flow \(100,000 substeps a sample\) of sample 1 of"
    ):
        api.simulate(sp, rep, time_limit=0.3, substeps=100_000)
    assert _time.perf_counter() - t0 < 30


def test_unused_simulate_keys_are_warned(tmp_path):
    """noise, seed and dt gave the same numbers as without them, with no word (review): the
    observer samples y = h(x) exactly. Each given key is named in one warning."""
    p = tmp_path / "s.toml"
    text = TEXT.replace("[simulate]", "[simulate]\nseed = 3\ndt = 0.5", 1)
    p.write_text(text + '\n[simulate.noise]\nkind = "uniform"\nbound = 0.01\n', encoding="utf-8")
    from obsdesign.methods.searchspace import sim as S

    with pytest.warns(UserWarning, match=r"\[simulate\] noise, seed, dt not used by the search"):
        S._warn_unused(api.load_spec(p))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        S._warn_unused(api.load_spec(SPEC))


def test_consistency_lost_after_leaving_E_blames_E_not_L_h(tmp_path):
    """The true state leaves E (f pushes it out), then every centre is discarded: the
    message names that cause and stops there — it also blamed L_h before (random-spec
    fuzzer), though outside E no constant of the design applies."""
    text = """[system]
time = "continuous"
states = ["x1"]
f = ["0.18*x1 + 0.63*sqrt(1 + x1^2)"]
h = ["sin(20*x1)"]
u = ["-0.34", "0.25"]
[method]
key = "search-space"
alpha = 0.43
eps_star = 0.04
gamma0 = 1.6
[method.E]
lower = [-0.0718]
upper = [1.28]
[method.D]
lower = [0.437]
upper = [0.771]
[method.U]
lower = [-0.34, 0.25]
upper = [-0.34, 0.25]
[simulate]
horizon = 2.3
x0 = [0.617]
xhat0 = [0]
"""
    sp, rep = _load(text, tmp_path)
    with pytest.raises(ConsistencyLost, match="The true state left E at t = 0.648") as ei:
        api.simulate(sp, rep)
    assert "L_h" not in ei.value.message and "Lemma 2" not in ei.value.message


def test_input_leaving_U_and_a_run_past_the_horizon_are_said(tmp_path):
    """u = t with U = [0, 1/8] and [method] horizon = 1/8, simulated to t = 2: the design
    certifies (u stays in U over its horizon); the run leaves U at the first midpoint past
    1/8 and runs past the horizon, and simulate says both (random-spec fuzzer: a true-cell
    distance 2.9× the bound ε e^(L_f t) with exit 0 and no word). Within the horizon: no
    warning."""
    text = """[system]
time = "continuous"
states = ["x1"]
f = ["u1*x1"]
h = ["x1^3"]
u = ["t"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.1
gamma0 = 0.2
horizon = 0.125
[method.E]
lower = [-3]
upper = [3]
[method.D]
lower = [-0.5]
upper = [0.5]
[method.U]
lower = [0]
upper = [0.125]
[simulate]
horizon = 2
x0 = [0.2]
xhat0 = [0]
"""
    sp, rep = _load(text, tmp_path)
    assert rep.exit_code() == 0
    res = api.simulate(sp, rep)
    said = " ".join(res.info.get("warnings", []))
    assert "leaves the input range U" in said and "beyond [method] horizon = 0.125" in said
    assert 0.125 < res.info["left_U_at"] < 0.13 and res.info["past_horizon"] == 0.125
    sp2, rep2 = _load(text.replace("horizon = 2\n", "horizon = 0.125\n"), tmp_path)
    res = api.simulate(sp2, rep2)
    assert not res.info.get("warnings")
    assert "left_U_at" not in res.info and "past_horizon" not in res.info


def test_a_horizon_beyond_the_record_budget_is_refused_before_the_run(tmp_path):
    """[simulate] horizon = 1e30 (CLI fuzzer): the pass that looked for u leaving U went over
    all 3·10³¹ half-periods before the loop and its time budget, and the loop itself ran
    until time_limit. The number of sampling periods is now checked against max_sim_bytes
    first (exit 2 naming the key), and u is checked period by period inside the loop."""
    sp, rep = _load(TEXT.replace("\nhorizon = 12\n", "\nhorizon = 1e30\n"), tmp_path)
    with pytest.raises(
        InputError, match=r"\[simulate\] horizon = 1e\+30 is .* sampling periods"
    ) as e:
        api.simulate(sp, rep)
    assert e.value.exit_code == 2 and "max_sim_bytes" in e.value.message


def test_the_plant_follows_its_exact_flow_across_the_jumps_of_u(example):
    """The example's x' = u(x2, −x1), u = t/3 − ⌊t/3⌋ from x0 = (0, 1) is (sin Θ, cos Θ) with
    Θ(t) = 3/2·⌊t/3⌋ + r²/6, r = t − 3⌊t/3⌋. One fixed RK4 step across each jump of u (t = 3,
    6, 9) put the simulated plant 1.7·10⁻³ off it while the flow-error estimate said 10⁻¹³
    (independent simulate review); the substep holding a jump is now halved until the
    step-doubling estimate is small, and the estimate covers every sample."""
    sp, rep, res = example
    t = np.asarray(res.t, dtype=float)
    k = np.floor(t / 3 + 1e-12)
    r = t - 3 * k
    theta = 1.5 * k + r**2 / 6
    exact = np.stack([np.sin(theta), np.cos(theta)], axis=1)
    err = float(np.max(np.abs(np.asarray(res.x, dtype=float) - exact)))
    assert err < 1e-6
    assert res.info["flow_error_estimate"] >= err / 10  # the estimate is of the right size


def test_recover_covers_every_ball_point():
    """Sound re-covering: every point within η of a centre lies in a returned cell."""
    rng = np.random.default_rng(1)
    C = rng.uniform(-1, 1, size=(40, 2))
    eta, s = 0.3, 0.1
    cells = recover(C, eta, s, cap=10**6)
    for c in C:
        for _ in range(50):
            d = rng.normal(size=2)
            p = c + eta * rng.uniform() ** 0.5 * d / np.linalg.norm(d)
            assert np.any(np.all(np.abs(cells - p) <= s + 1e-12, axis=1))
    # merged: each cell once
    assert len(np.unique(np.round(cells / s).astype(int), axis=0)) == len(cells)


def test_cover_box_degenerate_side():
    C = cover_box(np.array([0.0, -2.0]), np.array([0.0, 2.0]), 1 / math.sqrt(2) * 2 / 3)
    assert np.all(C[:, 0] == 0) and C[:, 1].min() <= -2 + 0.48 and C[:, 1].max() >= 2 - 0.48


def test_plot_writes_figs_3_to_5(tmp_path):
    sp, rep = _load(TEXT.replace("horizon = 12", "horizon = 1"), tmp_path)
    res = api.simulate(sp, rep, store_every=5)
    out = api.plot_simulation(sp, res, tmp_path / "figs.png")
    assert Path(out).stat().st_size > 10_000


def test_consistency_lost_names_L_h(tmp_path):
    """A given L_h below h's Lipschitz constant (its claim fails; simulate runs anyway): the
    refinement's output filter drops the true cell and the diagnosis names L_h."""
    sp, rep = _load(TEXT.replace("gamma0 = 1 ", "gamma0 = 1\nL_h = 0.3 "), tmp_path)
    assert {c.id for c in rep.failed} == {"L_h-bound"}
    with pytest.raises(ConsistencyLost, match="L_h is not a Lipschitz constant of h"):
        api.simulate(sp, rep)


_TRIVIAL = """[system]
time = "continuous"
states = ["x1"]
f = ["F"]
h = ["H"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.1
gamma0 = 0.2
[method.E]
lower = [-2]
upper = [2]
[method.D]
lower = [-0.5]
upper = [0.5]
[simulate]
horizon = 2
x0 = [0.2]
xhat0 = [0]
"""


@pytest.mark.parametrize("h", ["1", "0*x1"])
def test_a_constant_output_is_refused_as_unobservable(h, tmp_path):
    """h constant on E (L_h^E = 0): the output says nothing about x. It used to be floored at
    10⁻⁶ silently, giving ΔT = 18000 and failed claims advising "decrease α or γ⋆"
    (random-spec fuzzer); now exit 1 saying why."""
    from obsdesign.errors import InfeasibleError

    p = tmp_path / "s.toml"
    p.write_text(_TRIVIAL.replace("F", "-x1").replace("H", h), encoding="utf-8")
    with pytest.raises(InfeasibleError, match="h is constant on E") as ei:
        api.design(api.load_spec(p))
    assert ei.value.exit_code == 1


def test_zero_dynamics_floor_is_said_and_a_run_without_samples_warns(tmp_path):
    """f ≡ 0: L_f = ‖f_u‖ = 0 on E, floored at 10⁻⁶ (a true upper bound; Theorem 1's rules
    divide by them), which the notes now say; ΔT then exceeds the 2 s horizon, and simulate
    warns that the observer takes no sample (it ran 0 samples silently)."""
    sp, rep = _load(_TRIVIAL.replace("F", "0").replace("H", "x1"), tmp_path)
    assert rep.exit_code() == 0
    said = " ".join(rep.notes)
    assert "L_f: interval bound 0" in said and "the bound is 0, so 0.000001" in said
    res = api.simulate(sp, rep)
    assert any("takes no sample" in w for w in res.info.get("warnings", []))


def test_substeps_are_bounded_and_a_hopeless_flow_error_is_not_halved_forever(example):
    """``substeps = 10⁹`` built one tuple per substep and took the machine's memory: it is at
    most MAX_SUBSTEPS (exit 2 naming the key). x0 = (0, 1e300) made partition() halve every
    substep 48 levels deep (2⁴⁸ pieces a sample) until time_limit: a non-finite flow-error
    estimate is not halved and one sample makes at most MAX_EXTRA_PIECES halvings."""
    from obsdesign.errors import SpecError
    from obsdesign.methods.searchspace import options as O
    from obsdesign.methods.searchspace import sim as S

    r = CliRunner().invoke(app, ["simulate", str(SPEC), "--option", "substeps=100001"])
    assert r.exit_code == 2 and "expected a value <= 100000" in r.output
    with pytest.raises(SpecError, match=r"\[simulate\.substeps\] expected at most 100,000"):
        api.load_spec_text(TEXT.replace("[simulate]", "[simulate]\nsubsteps = 100001", 1))
    assert O.MAX_SUBSTEPS == 100_000
    sp, _, _ = example
    plant = S.Plant(sp)
    P = np.array([[0.0, np.inf]])
    with np.errstate(all="ignore"):
        steps, err = S.partition(plant, P, 0.0, 0.1, 4, 1e-12)
    assert len(steps) == 4 and not np.isfinite(err)  # not halved: the estimate is not finite
    # x = 1e300: the estimate is finite since its norm is scaled (it overflowed to inf before
    # session 29), so the sample is halved — at most MAX_EXTRA_PIECES times
    with np.errstate(all="ignore"):
        steps, err = S.partition(plant, np.array([[0.0, 1e300]]), 0.0, 0.1, 4, 1e-12)
    assert np.isfinite(err) and len(steps) == 4 + S.MAX_EXTRA_PIECES
    P = np.array([[0.0, 1.5]])
    steps, _ = S.partition(plant, P, 0.0, 0.1, 4, 0.0)  # a tolerance no halving meets
    assert len(steps) == 4 + S.MAX_EXTRA_PIECES


def test_max_centres_beyond_the_memory_limit_is_refused() -> None:
    """``max_centres = 10⁹`` was accepted and the run grew past 1 GB until time_limit
    (review): a cap whose centres would not fit in max_sim_bytes is exit 2 naming the key;
    the default (2·10⁶) fits."""
    r = CliRunner().invoke(app, ["simulate", str(SPEC), "--option", "max_centres=1000000000"])
    assert r.exit_code == 2
    assert (
        "[simulate] max_centres = 1,000,000,000 centres of 2 states may need about 156" in r.output
    )
    from obsdesign.methods.searchspace import sim as S

    S._check_centres(api.load_spec(SPEC), 2_000_000)


def test_svg_plot_rasterizes_the_search_space(example, tmp_path):
    """The centres are drawn as one embedded raster in a vector format: each was its own path
    before, and the template's ``simulate --plot x.svg`` wrote 87 MB. The lines stay vectors."""
    sp, _, res = example
    n_centres = sum(len(c) for _, c in res.extra["stored"])
    out = api.plot_simulation(sp, res, tmp_path / "figs.svg")
    text = Path(out).read_text(encoding="utf-8")
    assert n_centres > 20_000 and "<image" in text
    assert len(text) < 2_000_000, (len(text), n_centres)


_CUBE = """[system]
time = "continuous"
states = ["x1"]
f = ["0.01*(0.95 - x1)"]
h = ["x1^3"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 4.05
[method.E]
lower = [-1]
upper = [1]
[method.D]
lower = [0.95]
upper = [0.95]
[simulate]
horizon = 5
x0 = [0.95]
xhat0 = [0]
"""


def test_a_cell_centred_outside_E_is_named_as_the_cause(tmp_path):
    """y = x1³, E = [−1, 1], x0 = 0.95 inside E: the grid 1.8ℤ puts the true state's cell at
    centre 1.8, outside E, where x³ is steeper than the certified L_h = 3, and the filter drops
    it at t₀. The message said only "consistency lost"; it names the centre outside E now
    (search-space trial, session 27). A D well inside E (centre 0) does not lose it."""
    sp, rep = _load(_CUBE, tmp_path)
    assert rep.exit_code() == 0
    with pytest.raises(ConsistencyLost, match=r"nearest the true state, \[1\.8\], lies outside E"):
        api.simulate(sp, rep)
    inner = _CUBE.replace("0.95", "0.1")
    sp, rep = _load(inner, tmp_path)
    assert api.simulate(sp, rep).info["final_error"] >= 0


def test_progress_goes_to_stderr_and_quiet_silences_it(tmp_path):
    """--option progress=true drew its bar on stdout, before --format json's JSON, and -q did
    not silence it (simulate trial, session 27)."""
    import json

    runner = CliRunner()
    args = ["simulate", str(SPEC), "--option", "progress=true", "--format", "json"]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    json.loads(r.stdout)  # stdout holds the JSON alone
    r = runner.invoke(app, [*args[:4], "-q"])
    assert r.exit_code == 0 and r.stdout == "" and "centres" not in r.stderr


def _scaled_plant(e: int) -> str:
    """A 2-state search-space plant ẋ = −x, y = x on E = [−10^e, 10^e]², D half of it,
    γ⋆ = 10^(e−1), γ₀ = 10^e, x0 = 0.3·10^e (the distances' squares leave the float range
    for |e| ≳ 154)."""
    return f"""[system]
time = "continuous"
states = ["x1", "x2"]
f = ["-x1", "-x2"]
h = ["x1", "x2"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 1e{e - 1}
gamma0 = 1e{e}
[method.E]
lower = [-1e{e}, -1e{e}]
upper = [1e{e}, 1e{e}]
[method.D]
lower = [-5e{e - 1}, -5e{e - 1}]
upper = [5e{e - 1}, 5e{e - 1}]
[simulate]
horizon = 2
x0 = [3e{e - 1}, 3e{e - 1}]
xhat0 = [0, 0]
"""


def _scaled_run(e: int) -> tuple[Any, float, np.ndarray, np.ndarray]:
    """(the simulation of :func:`_scaled_plant`, its final |e| by math.hypot, the true cell's
    distance series, the bound series)."""
    sim = api.simulate(api.load_spec_text(_scaled_plant(e), "scaled.toml"))
    err = sim.xhat[-1] - sim.x[-1]
    want = math.hypot(*(float(v) for v in err))
    return sim, want, np.asarray(sim.extra["true_cell"]), np.asarray(sim.extra["bound"])


def test_distances_do_not_underflow_at_tiny_scales() -> None:
    """A plant on E = [−1e-198, 1e-198]²: the squares of the distances underflow, so
    final_error, final_true_cell and the true_cell series read 0 beside a final |e| of
    2.9e-201 (search-space trial, session 29). They now agree with the scaled norm, and the
    true cell is within the bound at every sample."""
    sim, want, near, bound = _scaled_run(-198)
    info = sim.info
    assert want > 0 and info["final_error"] == pytest.approx(want, rel=1e-12)
    assert np.all(near > 0) and info["final_true_cell"] > 0
    assert np.all(near <= bound)


@pytest.mark.parametrize(
    ("h", "want"),
    [
        ('["x1"]', {0: [0]}),
        ('["x1 + x2", "x1 - x2"]', {}),  # y1 was drawn on the x1 panel as "output y"
        ('["x2", "x1"]', {1: [0], 0: [1]}),
        ('["2*x1"]', {}),
    ],
)
def test_outputs_are_drawn_only_on_the_panel_of_the_state_they_are(h: str, want: dict) -> None:
    """An output goes on a state's panel only when it is that state (search-space trial,
    session 29: with h = [x1 + x2, x1 − x2] y1 was drawn on x1's panel, y2 nowhere)."""
    from obsdesign.methods.searchspace.plots import output_panels

    old = 'h = ["x1*step(x1)"]'
    assert old in TEXT
    text = TEXT.replace(old, f"h = {h}")
    sp = api.load_spec_text(text, "p.toml")
    assert output_panels(sp, ["x1", "x2"]) == want


# --- Mutation review 29: _row_norm at huge scales


def test_distances_do_not_overflow_at_huge_scales() -> None:
    """The mirror of the tiny plant: on E = [−1e198, 1e198]² the squares of the distances
    overflow (1e396), so the summed squares read inf; the true cell's distance, the bound and
    the final error must stay finite and agree with the scaled norm (mutation review 29: a
    ``_row_norm`` that took the summed squares whenever they were not too small passed every
    test)."""
    sim, want, near, bound = _scaled_run(198)
    info = sim.info
    assert math.isfinite(want) and info["final_error"] == pytest.approx(want, rel=1e-12)
    assert np.all(np.isfinite(near)) and np.all(np.isfinite(bound))
    assert math.isfinite(info["final_true_cell"])
    assert np.all(near <= bound)


@pytest.mark.parametrize("scale", [1e-200, 1.0, 1e200])
def test_row_norm_picks_the_norm_at_every_scale(scale: float) -> None:
    """``_row_norm(D, pick)`` is pick of the Euclidean row norms, the picked one (min or
    max) whatever the scale: the squares underflow at 1e-200 and overflow at 1e200, where
    the scaled fallback must still pick with ``pick`` (mutation review 29: the fallback
    taking np.max for np.min, and the fast path taken above SAFE_HI², passed every test)."""
    from obsdesign.methods.searchspace.sim import _row_norm

    D = np.array([[3.0, 4.0], [0.3, 0.4], [-6.0, 8.0]]) * scale
    assert _row_norm(D, np.min) == pytest.approx(0.5 * scale, rel=1e-14)
    assert _row_norm(D, np.max) == pytest.approx(10.0 * scale, rel=1e-14)


def test_centroid_error_is_within_the_bound_at_every_sample(example) -> None:
    """The "bound" series is the spread of the live centres about their centroid plus the
    cell radius ε e^{L_f(t − τ)}, so the centroid's error never exceeds it, and at a
    stored sample with every centre kept it is at least the largest distance of a centre
    from the centroid (mutation review 29: the spread taken as the SMALLEST distance passed
    every test)."""
    from obsdesign.simulate.result import norms

    _, _, res = example
    bound = np.asarray(res.extra["bound"])
    err = norms(np.asarray(res.xhat) - np.asarray(res.x))
    assert np.all(err <= bound * (1 + 1e-12))
    tt = list(np.asarray(res.t))
    live = np.asarray(res.extra["live"])
    checked = 0
    for t, C in res.extra["stored"]:
        i = tt.index(t)
        if len(C) == live[i]:  # every centre stored
            spread = float(np.max(norms(C - C.mean(axis=0))))
            assert spread <= bound[i] * (1 + 1e-12)
            checked += 1
    assert checked > 0


@pytest.mark.parametrize("scale", [1e-250, 1e250])
def test_flow_error_scales_with_the_state(example, scale: float) -> None:
    """The example's f is linear in x for a fixed u (f = [u x2, −u x1]), so RK4 and its
    step-doubling estimate scale exactly with x: at 1e-250 the differences' squares
    underflow (the estimate read 0: no substep refinement) and at 1e250 they overflow (inf:
    never refined). flow_error must be ``scale`` times its value at scale 1 (mutation review
    29: ``np.linalg.norm`` back in flow_error passed every test)."""
    from obsdesign.methods.searchspace import sim as S

    sp, _, _ = example
    plant = S.Plant(sp)
    X = np.array([[0.3, 1.5], [-1.0, 0.7]])
    one = S.flow_error(plant, X, 1.0, 0.5, 1)  # u = t/3 ≠ 0 on [1, 1.5]
    assert one > 0
    with np.errstate(all="ignore"):
        got = S.flow_error(plant, X * scale, 1.0, 0.5, 1)
    assert got == pytest.approx(one * scale, rel=1e-6)


def test_plot_draws_each_output_on_the_panel_of_its_state(tmp_path, monkeypatch) -> None:
    """h = [x2, x1]: y1 is drawn on x2's panel and y2 on x1's, each with its OWN samples
    (mutation review 29: drawing y[:, 0] on every panel, or one output on the wrong panel,
    passed every test: only output_panels was tested, not the figure)."""
    import matplotlib.axes

    old = 'h = ["x1*step(x1)"]'
    text = TEXT.replace("horizon = 12", "horizon = 1").replace(old, 'h = ["x2", "x1"]')
    sp, rep = _load(text, tmp_path)
    res = api.simulate(sp, rep, store_every=5)
    drawn: dict[str, np.ndarray] = {}
    real = matplotlib.axes.Axes.plot

    def spy(self, *args, **kw):
        if str(kw.get("label", "")).startswith("output"):
            drawn[kw["label"]] = np.asarray(args[1], dtype=float)
        return real(self, *args, **kw)

    monkeypatch.setattr(matplotlib.axes.Axes, "plot", spy)
    api.plot_simulation(sp, res, tmp_path / "figs.png")
    assert set(drawn) == {"output y1 = x2", "output y2 = x1"}
    assert np.array_equal(drawn["output y1 = x2"], res.y[:, 0])
    assert np.array_equal(drawn["output y2 = x1"], res.y[:, 1])
    assert not np.array_equal(res.y[:, 0], res.y[:, 1])


def test_output_panels_skip_an_output_that_is_a_constant() -> None:
    """h = [x1, pi] loads (a constant output); pi is a bare name but no state, so it is on
    no panel, and the plot does not fail on it (mutation review 29: dropping ``in names``
    passed every test; names.index('pi') then raised ValueError in plot_simulation)."""
    from obsdesign.methods.searchspace.plots import output_panels

    old = 'h = ["x1*step(x1)"]'
    sp = api.load_spec_text(TEXT.replace(old, 'h = ["x1", "pi"]'), "p.toml")
    assert output_panels(sp, ["x1", "x2"]) == {0: [0]}


def test_error_panel_floor_follows_eps_star(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a plant of size 1e-198 every error curve sat on a fixed 1e-12 floor and ε⋆ was off
    the axis (re-check trial, session 29): the floor is ε⋆·1e-6, ε⋆ is in view and the
    curves keep their values."""
    from obsdesign.simulate import plot as simplot

    figs = []
    monkeypatch.setattr(simplot, "save_figure", lambda fig, path, dpi: figs.append(fig))
    sp = api.load_spec_text(_scaled_plant(-198), "tiny.toml")
    res = api.simulate(sp)
    api.plot_simulation(sp, res, tmp_path / "p.png")
    ax = figs[0].axes[-1]
    eps = res.info["eps_star"]
    lo, hi = ax.get_ylim()
    assert lo <= eps / 100 and hi > eps
    curve = next(ln for ln in ax.lines if ln.get_label() == "|centroid − x|")
    assert np.min(curve.get_ydata()) < 1e-199


_X0_SPEC = """
[system]
time = "continuous"
states = ["x1", "x2"]
f = ["x2", "-x1 + u1"]
h = ["x1"]
u = ["sin(t)"]
[method]
key = "search-space"
alpha = 0.5
gamma_star = 0.2
gamma0 = 1
E = {{lower = [-2, -2], upper = [2, 2]}}
D = {{lower = [-1, -1], upper = [1, 1]}}
U = {{lower = [-1], upper = [1]}}
[simulate]
horizon = 0.5
x0 = [{x0}, 0.2]
xhat0 = [0, 0]
"""


@pytest.mark.parametrize(("x0", "warned"), [("1.5", True), ("1.0000001", True), ("1", False)])
def test_x0_outside_D_is_warned(x0: str, warned: bool) -> None:
    """x0 = (1.5, 0.2) with D = [−1, 1]² ran silently with its metrics (search-space trial,
    session 31): the guarantee assumes x0 ∈ D. A warning names x0 and D, decided exactly (x0
    on D's edge is in D)."""
    res = api.simulate(api.load_spec_text(_X0_SPEC.format(x0=x0), "x0.toml"))
    said = [w for w in res.info.get("warnings", []) if "is not in D" in w]
    assert bool(said) == warned
    if warned:
        assert f"[simulate] x0 = ({x0}, 0.2) is not in D = [-1, 1] × [-1, 1]" in said[0]


FAR = """
[system]
time = "continuous"
states = ["x1", "x2"]
f = ["x2", "-(x1 - 1000000000)"]
h = ["x1"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = GSTAR
gamma0 = 0.001
E = {lower = [999999999.99, -0.01], upper = [1000000000.01, 0.01]}
D = {lower = [999999999.995, -0.005], upper = [1000000000.005, 0.005]}
[simulate]
horizon = 4
x0 = [1000000000.001, 0.0005]
xhat0 = [0, 0]
max_centres = 300000
"""


def test_cells_finer_than_the_float_spacing_of_E_are_refused_as_inconclusive() -> None:
    """Around x1 = 10⁹ the float spacing is 1.19·10⁻⁷: cells of half-side 4.7·10⁻⁹ cannot be
    represented, the run lost consistency (exit 1) and the message blamed the certified L_h
    (soundness trial, session 33). The run is refused before it starts, exit 4, naming the
    spacing (cells of about 40 spacings, γ⋆ = 10⁻⁵ with a wider E, run and keep the true
    state: 9 s for half the horizon, so checked by hand, not here)."""
    from obsdesign.errors import InconclusiveError
    from obsdesign.methods.searchspace import sim as S

    narrow = (
        FAR.replace("GSTAR", "0.00000001")
        .replace("gamma0 = 0.001", "gamma0 = 0.0000001")
        .replace("999999999.99, -0.01", "999999999.9999975, -0.0000025")
        .replace("1000000000.01, 0.01", "1000000000.0000025, 0.0000025")
        .replace("999999999.995, -0.005", "999999999.999998, -0.000002")
        .replace("1000000000.005, 0.005", "1000000000.000002, 0.000002")
        .replace("1000000000.001, 0.0005", "1000000000.000001, 0.0000005")
    )
    assert narrow.count("999999999.99999") == 2 and "0.0000005]" in narrow
    sp = api.load_spec_text(narrow, "far.toml")
    with pytest.raises(InconclusiveError, match=r"below 16 float spacings \(1\.19e-07\) of E"):
        api.simulate(sp)
    o = sp.options
    ulp = float(np.spacing(1000000000.0000025))
    S._check_float_spacing(o, S.MIN_CELL_ULPS * ulp)  # at the threshold: runs
    with pytest.raises(InconclusiveError):
        S._check_float_spacing(o, S.MIN_CELL_ULPS * ulp * (1 - 1e-9))


# -- mutation review 34 (session 33's checks) ----------------------------------------
def _E(lower: list[float], upper: list[float]) -> SimpleNamespace:
    return SimpleNamespace(E=SimpleNamespace(lower=lower, upper=upper))


def test_the_float_spacing_is_that_of_the_larger_end_of_E() -> None:
    """Kills S06 (|lower| only) and S07 (|upper| only): E = [0, 10⁹] and [−10⁹, 0] both
    have spacing 1.19·10⁻⁷ at their far end: a half-side of 10⁻⁹ is refused for both."""
    for o in (_E([0.0], [1e9]), _E([-1e9], [0.0])):
        with pytest.raises(InconclusiveError, match="below 16 float spacings"):
            S._check_float_spacing(o, 1e-9)  # type: ignore[arg-type]
    S._check_float_spacing(_E([0.0], [1.0]), 1e-9)  # type: ignore[arg-type]


class _Seen(Exception):
    pass


@pytest.mark.parametrize("horizon", ["12", "1.3"])
def test_the_spacing_check_takes_the_finest_level_the_horizon_reaches(
    monkeypatch: pytest.MonkeyPatch, horizon: str
) -> None:
    """Kills S09 (ε₀, the coarsest level), S10 (the last level whatever the horizon) and S11
    (ε_i without /√n): the half-side checked is ε_i/√n for i = min(len − 1, N // K), N the
    samples of the horizon (the shipped example: i = 11 for horizon 12, i = 3 for 1.3)."""
    text = SPEC.read_text(encoding="utf-8").replace("horizon = 12", f"horizon = {horizon}")
    sp = api.load_spec_text(text, "h.toml")
    rep = api.design(sp)
    p = rep.parameters
    eps = [float(e) for e in p["eps_schedule"]]
    K = int(round(float(p["K"])))
    N = S._samples(sp, float(p["dT"]))
    i = min(len(eps) - 1, N // K)
    assert (horizon == "12") == (i == len(eps) - 1) and i > 0
    seen: list[float] = []

    def spy(o, s):  # noqa: ANN001, ANN202
        seen.append(s)
        raise _Seen

    monkeypatch.setattr(S, "_check_float_spacing", spy)
    with pytest.raises(_Seen):
        api.simulate(sp)
    assert seen == [pytest.approx(eps[i] / math.sqrt(sp.system.n), rel=1e-12)]


def test_a_state_that_floats_cannot_evaluate_is_inconclusive_not_left_e(tmp_path: Path) -> None:
    """f = x2 + 0·2^1100·x1 is exactly a rotation (certified correctly), but floats evaluate
    0·inf = nan: the run ended exit 1 "the true state left E", blaming the constants
    (expression soundness trial, session 34). It is exit 4 naming the non-finite state."""
    from obsdesign.errors import InconclusiveError

    text = (
        '[system]\ntime = "continuous"\nstates = ["x1", "x2"]\n'
        'f = ["x2 + 0*2^1100*x1", "-x1"]\nh = ["x1 + 0"]\n[method]\nkey = "search-space"\n'
        "alpha = 0.9\ngamma_star = 0.05\ngamma0 = 1\n"
        "[method.E]\nlower = [-2, -2]\nupper = [2, 2]\n[method.D]\nlower = [-1, -1]\n"
        "upper = [1, 1]\n[simulate]\nhorizon = 1\nx0 = [0.5, 0.5]\nxhat0 = [0, 0]\n"
    )
    p = tmp_path / "nan.toml"
    p.write_text(text)
    assert api.design(p).exit_code() == 0  # the certificate is right
    with pytest.raises(InconclusiveError, match="not finite in floats at t = ") as e:
        api.simulate(p)
    assert "left E" not in e.value.message


@pytest.mark.parametrize(
    ("f2", "h", "at_t0"),
    [
        ("-x1", "x1 + 0*2^1100*x2", True),  # the output alone is nan, from t₀ on
        ("-x2 + 0*2^1100*x2", "x1", False),  # the state alone turns nan after a step
    ],
    ids=["output-at-t0", "state-later"],
)
def test_an_output_or_state_floats_cannot_evaluate_is_inconclusive(
    tmp_path: Path, f2: str, h: str, at_t0: bool
) -> None:
    """Each half of the finiteness check, at t₀ and in the loop: without the check at t₀, or
    with the state alone checked, a nan output gave exit 1 "every centre was discarded by the
    output filter at t₀", blaming the certificate; with the output alone checked, a nan state
    crashed with "cannot convert float NaN to integer" (mutation review 35, S1, S3, S4)."""
    from obsdesign.errors import InconclusiveError

    f1 = "x2" if at_t0 else "-x1"
    text = (
        '[system]\ntime = "continuous"\nstates = ["x1", "x2"]\n'
        f'f = ["{f1}", "{f2}"]\nh = ["{h}"]\n[method]\nkey = "search-space"\n'
        "alpha = 0.9\ngamma_star = 0.05\ngamma0 = 1\n"
        "[method.E]\nlower = [-2, -2]\nupper = [2, 2]\n[method.D]\nlower = [-1, -1]\n"
        "upper = [1, 1]\n[simulate]\nhorizon = 1\nx0 = [0.5, 0.5]\nxhat0 = [0, 0]\n"
    )
    p = tmp_path / "nan.toml"
    p.write_text(text)
    with pytest.raises(InconclusiveError, match="not finite in floats at t = ") as e:
        api.simulate(p)
    assert ("at t = 0 " in e.value.message) is at_t0, e.value.message


@pytest.mark.parametrize("t0", ["1e16", "-1e308", "1e13"])
def test_times_too_coarse_for_the_step_are_refused_as_inconclusive(t0: str) -> None:
    """t0 = 10¹⁶ (float spacing 2 against ΔT = 0.0064): the run held u(t) over windows of
    hundreds of periods and simulated another plant (final state (−0.75, −0.66) where the
    spec's is (sin 6, cos 6)); t0 = −10³⁰⁸ a plant that never moved; both exit 0 with no word
    (search-space trial, session 40). Refused before the run, exit 4, naming the spacing."""
    from obsdesign.errors import InconclusiveError

    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "hernandez-garcia-example.toml").read_text()
    sp = api.load_spec_text(text.replace("[method]\n", f"[method]\nt0 = {t0}\n", 1), "t.toml")
    with pytest.raises(InconclusiveError, match=r"below 1024 float spacings .* of its times"):
        api.simulate(sp)


def test_the_time_spacing_is_that_of_the_later_end_and_of_the_substep() -> None:
    """The check's threshold: MIN_STEP_ULPS spacings of the larger of |t0| and |t_end| (a
    run from −10⁹ to 0 has the spacing of 10⁹), for the substep ΔT / n."""
    ulp = float(np.spacing(1e9))
    S._check_time_spacing(-1e9, 0.0, S.MIN_STEP_ULPS * ulp, 1)  # at the threshold: runs
    for t0, t1 in ((-1e9, 0.0), (0.0, 1e9)):
        with pytest.raises(InconclusiveError, match="below 1024 float spacings"):
            S._check_time_spacing(t0, t1, S.MIN_STEP_ULPS * ulp * (1 - 1e-9), 1)
    with pytest.raises(InconclusiveError, match="substeps"):
        S._check_time_spacing(1e9, 1e9, 1e-6 / 8, 8)
    S._check_time_spacing(0.0, 12.0, 1e-6, 1)


def test_a_true_state_leaving_E_is_warned(tmp_path: Path) -> None:
    """f = 1.26·sat(x1) − 0.146·x1 drives x from −0.36 past E = [−3, 3] at t ≈ 3.05: the run
    ended with a final error 15 times ε⋆ and said so only in an info line (search-space
    review, session 43). It warns, naming E and the time."""
    text = """[system]
time = "continuous"
states = ["x1"]
f = ["1.26*sat(x1) - 0.146307*x1"]
h = ["tanh(x1)"]
u = ["0.5 + 0.5*cos(3*t)"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.2
gamma0 = 0.8
[method.E]
lower = [-3.0]
upper = [3.0]
[method.D]
lower = [-0.5]
upper = [0.5]
[method.U]
lower = [-1]
upper = [1]
[simulate]
horizon = 5
x0 = [-0.3603]
xhat0 = [0]
max_centres = 200000
"""
    sp, rep = _load(text, tmp_path)
    assert rep.exit_code() == 0
    res = api.simulate(sp, rep)
    said = " ".join(res.info.get("warnings", []))
    assert "the true state leaves E = [-3, 3] at t = 3.0" in said
    assert 3.0 < res.info["left_E_at"] < 3.1


def test_recover_refuses_a_ball_beyond_the_cap_before_enumerating_it() -> None:
    """An initial state of −1e16 made η/ε ≈ 7·10³, and ``recover`` listed the (2R + 1)ⁿ grid
    offsets first: 2.4 GB, MemoryError (exit 3); past 10⁹⁹ "int too large" (exit 4); neither
    time_limit nor max_sim_bytes stopped it (CLI review, session 44). MemoryCap now, at once,
    with the ball's least cell count; a ball that fits still recovers."""
    C = np.zeros((1, 2))
    for eta in (1e4, 1e100, 1e300, float("inf")):
        with pytest.raises(MemoryCap, match="the refinement needs"):
            recover(C, eta, 0.5, 200_000)
    # the smallest refusal: ⌊η/(s√2)⌋² just above the cap (η/(s√2) = 448, 448² > 200,000)
    with pytest.raises(MemoryCap, match="at least 200,704 live centres"):
        recover(C, 448 * 0.5 * math.sqrt(2) * (1 + 1e-9), 0.5, 200_000)
    assert len(recover(C, 10.0, 0.5, 200_000)) > 0


def test_ball_offsets_list_only_what_can_meet_the_ball() -> None:
    """At n = 5 a ball meeting about 1.5 million cells (η/ε ≈ 11.4) was refused under
    max_centres = 2,000,000: its offset cube has 27⁵ = 14.3 million rows, above 4·cap
    (re-check review, session 44). The offsets are pruned axis by axis; every offset the
    exact test keeps for some centre is among them."""
    from obsdesign.methods.searchspace.sim import ball_offsets

    offs = ball_offsets(11.4, 0.5, 5, 8_000_000)
    assert 1_000_000 < len(offs) < 27**5 // 4
    rng = np.random.default_rng(7)
    for n, eta, s in ((1, 2.3, 0.25), (2, 1.7, 0.3), (3, 0.9, 0.2)):
        got = {tuple(k) for k in ball_offsets(eta, s, n, 10**7)}
        R = math.ceil((eta + s) / (2 * s) + 0.5)
        cube = np.array(list(itertools.product(range(-R, R + 1), repeat=n)))
        for c in rng.uniform(-3, 3, size=(20, n)):
            base = np.rint(c / (2 * s))
            g = (base + cube) * (2 * s)
            d = np.maximum(np.abs(c - g) - s, 0.0)
            hit = cube[(d * d).sum(axis=1) <= eta * eta]
            assert {tuple(k) for k in hit} <= got


def test_recover_far_from_the_origin_keeps_every_cell_the_full_cube_keeps(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """At |c|/s ≈ 10¹⁰ the double quotient rint(c/2s) put a centre near a cell boundary
    1.03·s from its grid point, past the s the pruning assumed, and recover dropped cells
    that meet the ball exactly (re-check review 45: 4 of 76 in one case). The offsets are
    widened by the centres' measured excess: recover's cells equal the full cube's on such
    cases, near and far from the origin."""
    rng = np.random.default_rng(11)
    real = S.ball_offsets

    def cube(eta: float, s: float, n: int, most: int, excess: float = 0.0) -> np.ndarray:
        R = math.ceil((eta + s + excess) / (2 * s) + 1.5)
        return np.array(list(itertools.product(range(-R, R + 1), repeat=n)), dtype=np.int64)

    for lo in (1e3, 1e7, 1e9, 1e10):
        for _ in range(60):
            n = int(rng.integers(1, 4))
            s = float(rng.uniform(0.1, 3))
            b = rng.integers(int(lo), int(lo * 100), n).astype(float) * 2
            C = ((b + 1) * s + rng.uniform(-3e-4, 3e-4, n) * s)[None, :]
            eta = 2 * s * int(rng.integers(1, 3)) * (1 - float(10 ** rng.uniform(-9, -4)))
            monkeypatch.setattr(S, "ball_offsets", real)
            pruned = {tuple(r) for r in recover(C, eta, s, 10**6)}
            monkeypatch.setattr(S, "ball_offsets", cube)
            full = {tuple(r) for r in recover(C, eta, s, 10**6)}
            assert pruned == full, (lo, n, s, eta, C.tolist())
