"""Simulation runners and scenario signals (obsdesign.simulate, obsdesign.spec.signals)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import expm

from obsdesign.api import load_spec_text
from obsdesign.simulate.linear import simulate_linear_observer
from obsdesign.simulate.result import metrics

PLANT = Path(__file__).parent / "specs" / "simulate-plant.toml"
BASE = (
    PLANT.read_text()
    + """
[simulate]
horizon = 50
x0 = [1, -1]
xhat0 = [0, 0]
seed = 3
"""
)


def test_windows_are_inclusive_and_add():
    spec = load_spec_text(
        BASE + "[simulate.disturbance]\nkind='windows'\n"
        "windows=[{start=2, stop=4, value=[1]}, {start=4, stop=5, value=[2]}]\n"
    )
    d = spec.simulate.disturbance.evaluate(np.arange(8), np.random.default_rng(0))[:, 0]
    np.testing.assert_array_equal(d, [0, 0, 1, 1, 3, 2, 0, 0])


@settings(max_examples=20, deadline=None)
@given(st.floats(0.01, 10), st.integers(0, 1000))
def test_uniform_noise_is_bounded_and_seeded(bound: float, seed: int):
    spec = load_spec_text(
        BASE + f"[simulate.noise]\nkind='uniform'\nbound={bound!r}\nseed={seed}\n"
    )
    a = spec.simulate.noise.evaluate(np.arange(200), np.random.default_rng(0))
    b = spec.simulate.noise.evaluate(np.arange(200), np.random.default_rng(99))
    assert np.all(np.abs(a) <= bound)
    np.testing.assert_array_equal(a, b)  # its own seed wins over the run's generator


def test_outliers_rate_and_amplitude():
    spec = load_spec_text(
        BASE + "[simulate.noise]\nkind='outliers'\namplitude=5\nrate=0.1\nbound=0.01\nseed=1\n"
    )
    v = spec.simulate.noise.evaluate(np.arange(5000), np.random.default_rng(0))[:, 0]
    big = np.abs(v) > 0.01
    assert 0.07 < big.mean() < 0.13 and np.all(np.abs(v) <= 5)


def test_sequence_then_zero():
    spec = load_spec_text(BASE + "[simulate.disturbance]\nkind='sequence'\nvalues=[1, -1, 1]\n")
    d = spec.simulate.disturbance.evaluate(np.arange(5), np.random.default_rng(0))[:, 0]
    np.testing.assert_array_equal(d, [1, -1, 1, 0, 0])


def test_discrete_runner_matches_closed_form():
    spec = load_spec_text(BASE)
    res = simulate_linear_observer(spec, np.array([[0.6], [0.1]]))
    A = np.array([[0.5, 1], [0, 0.8]])
    Acl = A - np.array([[0.6], [0.1]]) @ np.array([[1.0, 0]])
    e0 = np.array([-1.0, 1.0])
    for k in (0, 1, 7, 50):
        np.testing.assert_allclose(res.e[k], np.linalg.matrix_power(Acl, k) @ e0, atol=1e-12)
        np.testing.assert_allclose(res.x[k], np.linalg.matrix_power(A, k) @ [1, -1], atol=1e-12)


def test_continuous_runner_matches_expm():
    text = BASE.replace('"discrete"', '"continuous"').replace(
        "horizon = 50", "horizon = 2\ndt = 0.01"
    )
    text = text.replace("A = [[0.5, 1], [0, 0.8]]", "A = [[0, 1], [-2, -0.3]]")
    spec = load_spec_text(text)
    L = np.array([[0.6], [0.1]])
    res = simulate_linear_observer(spec, L)
    A = np.array([[0, 1], [-2, -0.3]])
    Acl = A - L @ np.array([[1.0, 0]])
    np.testing.assert_allclose(res.x[-1], expm(A * 2.0) @ [1, -1], atol=1e-6)
    np.testing.assert_allclose(res.e[-1], expm(Acl * 2.0) @ [-1, 1], atol=1e-6)


def test_metrics():
    e = np.array([[1.0, -2.0], [0.0, 1.0], [3.0, 0.0]])
    m = metrics(e, ["a", "b"])
    assert m["sup_abs_error"] == {"a": 3.0, "b": 2.0}
    assert m["rmse"]["a"] == pytest.approx(np.sqrt(10 / 3))
    assert m["final_error_norm"] == 3.0


@pytest.mark.filterwarnings("error::RuntimeWarning")
def test_a_diverging_trajectory_gets_a_plain_warning():
    """An unstable plant over a long horizon: the first warning says where the trajectory
    leaves the float range (not only numpy's overflow warnings); a stable one has none. The
    error of a run past the float range (inf − inf) raised numpy's "invalid value" warning
    (session 45: the one warning of the suite's log)."""
    from obsdesign import api

    text = (
        '[system]\ntime = "discrete"\nA = [[400.0]]\nC = [[1.0]]\n'
        '[method]\nkey = "lyapunov"\nL = [[400.0]]\n'
        "[simulate]\nhorizon = 200\nx0 = [1]\nxhat0 = [0]\n"
    )
    res = api.simulate(load_spec_text(text, "diverge.toml"))
    first = res.info["warnings"][0]
    assert "leaves the float range at t = 119 (sample 119 of 201)" in first  # 400^119 > 1e308
    # e⁺ = (400 − 400)e stays finite: only sup |x̂| is not (it said "the metrics are not
    # finite" beside a finite sup |e|, RMSE, final |e|: simulate trial, session 39)
    assert "while the error stays finite, so only sup |x̂| is not finite" in first
    assert np.isfinite(res.metrics()["sup_abs_error"]["x1"])
    both = res.__class__(res.t, res.x, res.x * 2, res.y, res.states)  # e = x: not finite
    said = api._left_float_range(both)
    assert said is not None and "the plant or the observer diverges over this horizon, so " in said
    stable = text.replace("A = [[400.0]]", "A = [[0.5]]").replace("L = [[400.0]]", "L = [[0.5]]")
    res = api.simulate(load_spec_text(stable, "stable.toml"))
    assert not any("float range" in w for w in res.info.get("warnings", []))


def test_a_divergence_gets_one_plain_warning_not_numpy_s_too() -> None:
    """x1⁺ = x1² from 10 overflows at t = 9: the plain warning, and none of numpy's four
    "overflow / invalid value encountered" lines beside it (docs review, session 41)."""
    from obsdesign import api

    text = (
        '[system]\ntime = "discrete"\nA = [[0.5, 0], [0, 0.5]]\nC = [[0, 1]]\n'
        'f = ["x1^2", "0.5*x2"]\n[method]\nkey = "lyapunov"\nL = [0, 0]\nlambda = 0.6\n'
        "[simulate]\nhorizon = 20\nx0 = [10, 1]\nxhat0 = [0, 0]\n"
    )
    said = api.simulate(load_spec_text(text, "square.toml")).info["warnings"]
    assert "leaves the float range at t = 9" in said[0]
    assert not [w for w in said if "RuntimeWarning" in w], said
    # a divide by zero that stays finite (min(1/t, 1) at t = 0) is another matter: kept
    other = (
        '[system]\ntime = "discrete"\nA = [[1.5]]\nC = [[1]]\npsi = ["0.001*min(1/t, 1)"]\n'
        '[method]\nkey = "lyapunov"\nL = [1.2]\n[simulate]\nhorizon = 2000\nx0 = [1]\nxhat0 = [0]\n'
    )
    said = api.simulate(load_spec_text(other, "div.toml")).info["warnings"]
    assert "leaves the float range" in said[0]
    assert any("divide by zero" in w for w in said), said


def test_an_input_that_is_not_finite_is_not_called_a_divergence() -> None:
    """u = 1e308·10·t is inf from the first step: the warning blamed a divergence of the plant
    or the observer (non-finite expressions trial, session 35). One step after values far
    inside the float range, it names a non-finite input or field instead."""
    from obsdesign import api

    text = (
        '[system]\ntime = "continuous"\nA = [[0, 1], [-1, 0]]\nB = [[0], [1]]\n'
        'C = [[1, 1]]\nu = ["1e308*10*t"]\n[method]\nkey = "stubborn"\n'
        "[simulate]\nhorizon = 0.05\ndt = 0.001\nx0 = [1, 0]\nxhat0 = [0.9, 0]\n"
    )
    res = api.simulate(load_spec_text(text, "u.toml"))
    first = next(w for w in res.info["warnings"] if "finite" in w)
    assert "an input u(t) or the field" in first and "diverges" not in first
    assert "one step after values of at most 1:" in first


def test_obsdesign_simulate_stays_callable_after_the_subpackage_loads() -> None:
    """README's ``obsdesign.simulate(spec)``: the first call imports ``obsdesign.simulate.*``,
    which rebinds the package attribute to the subpackage; the subpackage is callable, so a
    second call works too (it raised "'module' object is not callable")."""
    from pathlib import Path

    import obsdesign
    import obsdesign.simulate.runner  # noqa: F401 - what the first call does

    spec = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    a = obsdesign.simulate(obsdesign.load_spec(spec))
    b = obsdesign.simulate(obsdesign.load_spec(spec))
    assert type(a).__name__ == "SimResult" and (a.xhat == b.xhat).all()


def test_csv_text_quotes_names_and_round_trips_floats() -> None:
    import csv
    import io

    import numpy as np

    from obsdesign.simulate.result import SimResult

    x = np.array([[0.1, 1e-300], [2.0 / 3.0, -5.0]])
    res = SimResult(np.array([0.0, 0.5]), x, x + 0.25, None, ["a,b", 'q"'])
    rows = list(csv.reader(io.StringIO(res.csv_text())))
    assert rows[0] == ["t", "x_a,b", 'x_q"', "xhat_a,b", 'xhat_q"', "e_a,b", 'e_q"']
    tab = np.array(rows[1:], dtype=float)
    assert np.array_equal(tab[:, 1:3], x) and np.array_equal(tab[:, 5:7], res.e)


def test_csv_is_written_in_chunks_with_the_same_text() -> None:
    """``--csv`` streams :meth:`SimResult.csv_chunks` to the file (the whole text of a
    2·10⁷-step run passed 3.4 GB; review): the chunks join to :meth:`csv_text`, a header and
    then pieces of ``rows`` rows, y columns included."""
    import numpy as np

    from obsdesign.simulate.result import SimResult

    rng = np.random.default_rng(2)
    x = rng.standard_normal((11, 2))
    res = SimResult(np.arange(11.0), x, x * 0.5, rng.standard_normal((11, 1)), ["p", "q"])
    parts = list(res.csv_chunks(rows=4))
    assert len(parts) == 1 + 3 and parts[0] == "t,x_p,x_q,xhat_p,xhat_q,e_p,e_q,y1\n"
    assert [p.count("\n") for p in parts[1:]] == [4, 4, 3]
    assert "".join(parts) == res.csv_text()
    assert parts[1].split("\n")[0].split(",")[1] == repr(float(x[0, 0]))
