"""Property tests of the ``stubborn`` method (paper 002, Proposition: LMIs (1)-(3) feasible iff
(C, A) detectable): random detectable pairs give a certified design whose noise-free error
converges to 0 from random initial errors (GAS); random undetectable pairs exit 1 naming
detectability."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.certify.claim import ClaimStatus
from obsdesign.certify.detect import detectability
from obsdesign.certify.exact import qmat
from obsdesign.cli import app
from obsdesign.errors import InfeasibleError
from obsdesign.methods.stubborn import sim

ints = st.integers(min_value=-3, max_value=3)


def _spec(A: np.ndarray, C: np.ndarray, extra: str = "") -> str:
    """The Proposition (feasible iff detectable) has no gain bound; the design needs one to
    bound λ. Integer plants up to ±3 can need ‖K‖₂ > 100 (the default) under P ⪰ I, e.g.
    A = [[3, 2], [-3, 2]], C = [1, 0] (infeasible at 100, certified at 1000), so the property
    is checked with gain_bound = 1000."""
    rows = ", ".join("[" + ", ".join(str(int(v)) for v in r) + "]" for r in A)
    crow = ", ".join(str(int(v)) for v in C[0])
    return (
        f'[system]\ntime = "continuous"\nA = [{rows}]\nC = [[{crow}]]\n'
        f'[method]\nkey = "stubborn"\nlambda_tol = 0.1\ngain_bound = 1000\n{extra}'
    )


def _not_certified(rep: api.Report) -> list[str]:
    """Ids of the claims that failed or are numerical only (bar the float λ_max bracket)."""
    return [
        c.id
        for c in rep.claims
        if c.status == ClaimStatus.FAILED
        or (c.status == ClaimStatus.NUMERICAL and c.id != "lambda-max-bracket")
    ]


def _noise_free_errors(g: sim.Gains, e0: np.ndarray, steps: int, dt: float) -> np.ndarray:
    """The stubborn observer's error from e0 with no noise and no saturation bound."""
    _, e, _ = sim.run_errors(
        g,
        e0,
        lambda k0, k1: np.zeros((k1 - k0, 1)),
        steps,
        dt,
        np.full(1, np.inf),
        np.array(True),
        sim.root0_of(g, e0, None),
    )
    return e


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    a=st.lists(ints, min_size=4, max_size=4),
    c=st.lists(ints, min_size=2, max_size=2),
    e0=st.lists(st.floats(-2, 2), min_size=2, max_size=2),
)
def test_detectable_pair_certified_and_gas(a: list[int], c: list[int], e0: list[float]) -> None:
    A = np.array(a, dtype=float).reshape(2, 2)
    C = np.array([c], dtype=float)
    assume(detectability(qmat(A), qmat(C), "continuous").detectable)
    assume(np.linalg.norm(e0) > 0.1)
    sp = api.load_spec_text(_spec(A, C), "p.toml")
    rep = api.design(sp)
    assert not _not_certified(rep)
    g = sim.Gains.of(sp, rep.parameters)
    e0a = np.asarray(e0)
    T = 10.0 + 20.0 / g.lam  # a few time constants of σ̄
    dt = 1e-3
    steps = int(T / dt)
    e = _noise_free_errors(g, e0a, steps, dt)
    assert np.linalg.norm(e) <= 1e-3 * np.linalg.norm(e0a)


@settings(max_examples=4, deadline=None)
@given(a=st.integers(0, 3), c=ints, b=ints, k=ints)
def test_undetectable_pair_exit_1(a: int, c: int, b: int, k: int) -> None:
    # x1' = a x1 (a ≥ 0: not asymptotically stable) never reaches y = x2; hidden by T = [[1, k], [0, 1]]
    A0 = np.array([[a, b], [0, c]], dtype=float)
    T = np.array([[1, k], [0, 1]], dtype=float)
    Ti = np.array([[1, -k], [0, 1]], dtype=float)
    A = T @ A0 @ Ti
    C = np.array([[0, 1]], dtype=float) @ Ti
    assert not detectability(qmat(A), qmat(C), "continuous").detectable
    with np.testing.assert_raises_regex(InfeasibleError, "not detectable"):
        api.design(api.load_spec_text(_spec(A, C, "lambda = 1\n"), "u.toml"))


def test_undetectable_cli_exit_1(tmp_path) -> None:
    f = tmp_path / "u.toml"
    f.write_text(_spec(np.array([[1, 0], [0, -1]]), np.array([[0, 1]])))
    r = CliRunner().invoke(app, ["design", str(f), "-o", str(tmp_path / "r.json")])
    assert r.exit_code == 1
    assert "not detectable" in r.output


def test_discrete_redesign_certified_and_gas() -> None:
    """Discrete time, K given (deadbeat-like gain of a double integrator): LMIs (7)-(9) in P;
    the noise-free error of the stubborn observer converges."""
    text = (
        '[system]\ntime = "discrete"\nA = [[1, 1], [0, 1]]\nC = [[1, 0]]\n'
        '[method]\nkey = "stubborn"\nK = [1.5, 0.5]\nlambda_tol = 0.05\n'
    )
    sp = api.load_spec_text(text, "d.toml")
    rep = api.design(sp)
    assert not _not_certified(rep)
    assert "gain-bound" not in {c.id for c in rep.claims}  # redesign: K is the spec's
    g = sim.Gains.of(sp, rep.parameters)
    e0 = np.array([3.0, -2.0])
    e = _noise_free_errors(g, e0, 400, 1.0)
    assert np.linalg.norm(e) <= 1e-6 * np.linalg.norm(e0)
