"""Batched Monte Carlo runs (obsdesign.simulate.montecarlo): results independent of the
batching and of the run count, initial errors from a declared set, known quantiles."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from obsdesign.api import load_spec_text
from obsdesign.errors import SpecError
from obsdesign.simulate import montecarlo as mc
from obsdesign.simulate.linear import joint_system, simulate_linear_observer
from obsdesign.spec.reader import Table

PLANT = Path(__file__).parent / "specs" / "simulate-plant.toml"
BASE = (
    PLANT.read_text()
    + """
[sets.E0]
type = "box"
lower = [-2, -1]
upper = [2, 1]
[sets.line]
type = "box"
dim = 1
lower = [-1]
upper = [1]
[simulate]
horizon = 600
x0 = [1, -1]
xhat0 = [0, 0]
seed = 11
[simulate.noise]
kind = "NOISE"
"""
)
L = np.array([[0.6], [0.1]])
RANDOM = BASE.replace('kind = "NOISE"', 'kind = "uniform"\nbound = 0.05')
FIXED = BASE.replace('kind = "NOISE"', 'kind = "constant"\nvalue = [0.02]')


def _run(text, runs, batch=None, ie="E0"):
    sp = load_spec_text(text)
    return mc.run_batch(sp, joint_system(sp, L), runs, ie, batch), sp


@pytest.mark.parametrize("text", [RANDOM, FIXED])
def test_results_do_not_depend_on_batching_or_run_count(text):
    a, _ = _run(text, 7)
    b, _ = _run(text, 7, batch=1)
    c, _ = _run(text, 7, batch=3)
    d, _ = _run(text, 4, batch=2)
    for k, arr in a.extra["per_run"].items():
        np.testing.assert_array_equal(arr, b.extra["per_run"][k])
        np.testing.assert_array_equal(arr, c.extra["per_run"][k])
        np.testing.assert_array_equal(arr[:4], d.extra["per_run"][k])
    np.testing.assert_array_equal(a.extra["initial_errors"], c.extra["initial_errors"])
    np.testing.assert_array_equal(a.xhat, b.xhat)  # run 0's trajectory


def test_initial_errors_come_from_the_set_and_differ():
    r, _ = _run(FIXED, 50)
    e0 = r.extra["initial_errors"]
    assert np.all(np.abs(e0[:, 0]) <= 2) and np.all(np.abs(e0[:, 1]) <= 1)
    assert len({tuple(e) for e in e0}) == 50
    assert r.info["initial_error"] == "E0" and r.info["runs"] == 50
    fixed, _ = _run(FIXED, 3, ie=None)
    np.testing.assert_array_equal(fixed.extra["initial_errors"], [[-1, 1]] * 3)


def test_each_run_is_the_single_simulation_from_its_initial_error():
    r, _ = _run(FIXED, 5)
    for i in (0, 3):
        e0 = r.extra["initial_errors"][i]
        sp = load_spec_text(
            FIXED.replace(
                "xhat0 = [0, 0]", f"xhat0 = [{float(1 + e0[0])!r}, {float(-1 + e0[1])!r}]"
            )
        )
        m = simulate_linear_observer(sp, L).metrics()
        for k in ("sup_abs_error", "rmse", "sup_abs_estimate"):
            np.testing.assert_allclose(
                r.extra["per_run"][k][i], [m[k]["x1"], m[k]["x2"]], rtol=1e-12, atol=1e-12
            )
        assert r.extra["per_run"]["final_error_norm"][i] == pytest.approx(
            m["final_error_norm"], rel=1e-9, abs=1e-12
        )


def test_noise_seeds_are_spawned_per_run():
    r, _ = _run(RANDOM, 4, ie=None)  # same initial error, different noise
    sup = r.extra["per_run"]["rmse"][:, 0]
    assert len(set(sup.tolist())) == 4
    kids = mc.run_seeds(11, 4)
    assert [k.spawn_key for k in kids] == [(0,), (1,), (2,), (3,)]


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
