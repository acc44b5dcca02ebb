"""``simulate --runs N --workers K`` (issue 13): the Monte Carlo runs split into contiguous
spans of the same spawned seed list, one per worker, give the serial run's per-run metrics,
initial errors, trajectory and quantiles whatever K; methods without Monte Carlo runs refuse.

One LocalCluster (2 worker processes: the ``dask_client`` fixture) is shared by the module."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("dask.distributed")

from typer.testing import CliRunner  # noqa: E402

from obsdesign import api, distributed  # noqa: E402
from obsdesign.cli import app  # noqa: E402
from obsdesign.errors import InputError  # noqa: E402
from obsdesign.simulate import montecarlo as mc  # noqa: E402
from obsdesign.simulate.linear import joint_system  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
RUNS = 7


def _mc_text() -> str:
    """The shipped lyapunov spec on a short horizon, with random initial errors (a box of
    [sets]) and uniform output noise: every run differs."""
    text = SPEC.read_text()
    old_noise = 'kind = "windows"\nwindows = [{ start = 151, stop = 153, value = [3] }]'
    assert "horizon = 300\n" in text and old_noise in text
    text = text.replace("horizon = 300\n", 'horizon = 40\ninitial_error = "E0"\nseed = 5\n')
    text = text.replace(old_noise, 'kind = "uniform"\nbound = 0.05')
    return text + '\n[sets.E0]\ntype = "box"\nlower = [-2, -1]\nupper = [2, 1]\n'


@pytest.fixture(scope="module")
def spec_and_report(tmp_path_factory):
    path = tmp_path_factory.mktemp("mc") / "mc.toml"
    path.write_text(_mc_text())
    sp = api.load_spec(path)
    return path, sp, api.design(sp)


def _same(a, b) -> None:
    for k, arr in a.extra["per_run"].items():
        assert arr.shape[0] == RUNS
        np.testing.assert_array_equal(arr, b.extra["per_run"][k])
    np.testing.assert_array_equal(a.extra["initial_errors"], b.extra["initial_errors"])
    np.testing.assert_array_equal(a.xhat, b.xhat)  # run 0's trajectory
    assert a.info["quantiles"] == b.info["quantiles"]
    assert a.info["runs"] == b.info["runs"] == RUNS
    assert a.metrics() == b.metrics()


def test_spans_are_the_full_range_cut_in_pieces(spec_and_report):
    _, sp, rep = spec_and_report
    js = joint_system(sp, rep.parameters.float("L"))
    full = mc.run_batch(sp, js, RUNS, "E0")
    parts = [mc.run_batch(sp, js, RUNS, "E0", span=s) for s in [(0, 2), (2, 3), (3, RUNS)]]
    assert parts[1].info["trajectory"] == "run 2"
    np.testing.assert_array_equal(
        parts[2].extra["per_run"]["rmse"], full.extra["per_run"]["rmse"][3:]
    )
    _same(full, mc.merge(parts, sp.system.states))
    assert len({tuple(e) for e in full.extra["initial_errors"]}) == RUNS  # runs differ
    with pytest.raises(InputError, match="span"):
        mc.run_batch(sp, js, RUNS, "E0", span=(3, 8))
    with pytest.raises(InputError, match="do not cover"):
        mc.merge([mc.run_batch(sp, js, RUNS, "E0", span=(0, 2))], sp.system.states)


def test_workers_do_not_change_the_numbers(spec_and_report, dask_client):
    _, sp, rep = spec_and_report
    serial = api.simulate(sp, rep, options={"runs": str(RUNS)})
    one = api.simulate(sp, rep, options={"runs": str(RUNS)}, batches=1)  # in process
    three = api.simulate(sp, rep, options={"runs": str(RUNS)}, batches=3)  # in process
    two = api.simulate(sp, rep, options={"runs": str(RUNS)}, client=dask_client)  # 2 workers
    five = api.simulate(sp, rep, options={"runs": str(RUNS)}, client=dask_client, batches=5)
    for r in (one, three, two, five):
        _same(serial, r)


def test_cli_scheduler_output_is_the_serial_output(spec_and_report, dask_client):
    path, _, _ = spec_and_report
    runner = CliRunner()
    args = ["simulate", str(path), "--runs", str(RUNS), "--format", "json"]
    serial = runner.invoke(app, args)
    assert serial.exit_code == 0, serial.output
    dist = runner.invoke(app, [*args, "--scheduler", dask_client.scheduler.address])
    assert dist.exit_code == 0, dist.output
    assert json.loads(dist.stdout) == json.loads(serial.stdout)
    assert json.loads(serial.stdout)["runs"] == RUNS


def test_method_without_monte_carlo_refuses_workers():
    spec = ROOT / "specs" / "astolfi-stubborn-example1.toml"
    r = CliRunner().invoke(app, ["simulate", str(spec), "--workers", "2"])
    assert r.exit_code == 2, r.output
    assert "does not distribute its simulation runs" in r.output


def test_the_single_scenario_is_not_distributed() -> None:
    """A spec without a run count (nor initial_error) asks for one scenario: --workers made it
    a one-run Monte Carlo study with other noise than the serial run's (simulate trial,
    session 27); now exit 2 before any cluster starts, and the API says the same."""
    r = CliRunner().invoke(app, ["simulate", str(SPEC), "--workers", "2"])
    assert r.exit_code == 2, r.output
    assert "give --runs N" in r.output
    with pytest.raises(InputError, match="give --runs N"):
        api.simulate(SPEC, batches=2)
    assert api.simulate(SPEC, batches=2, runs=1).info["runs"] == 1


@pytest.mark.parametrize("batches", [0, 2.5, True, 2**63])
def test_a_batch_count_is_a_whole_number_from_one(batches: object) -> None:
    """``batches=2.5`` was a bare TypeError and ``batches=True`` one batch (API review,
    session 44): refused by name, exit 2, before any run."""
    with pytest.raises(InputError, match="batches: expected a whole number from 1"):
        api.simulate(SPEC, batches=batches, runs=2)


def test_workers_without_dask_say_how_to_install(monkeypatch, spec_and_report):
    path, _, _ = spec_and_report
    monkeypatch.setattr(distributed, "dask_available", lambda: False)
    r = CliRunner().invoke(app, ["simulate", str(path), "--runs", "3", "--workers", "2"])
    assert r.exit_code == 2, r.output
    assert "pip install 'obsdesign[distributed]'" in r.output
