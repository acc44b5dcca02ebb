"""Property tests of the search-space observer (paper 004) on random observable linear 2-state
systems ẋ = A x, y = x1 (Observation 2: observable linear systems are γ-observable), from random
initial states inside D: the design certifies; the true state's cell is never dropped (at every
sample a live centre is within ε_i e^{L_f (t − τ_i)} of it); Theorem 1's final error: at the
last switch the true state is within ε⋆ of a live centre.

The centroid of the live centres is *not* always within ε⋆: over 14 random systems its final
error exceeded ε⋆ in 3 (at most 1.24 ε⋆; e.g. A = [[0.7, −1], [1, −0.8]], x0 = (−0.08, 0.14):
0.0342 > 1/30), because a cell is discarded only when its output leaves the γ-band within one
window. The test bounds it by 2 ε⋆ (an observation, not a theorem)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.linalg import expm

from obsdesign import api

TEMPLATE = """
[system]
time = "continuous"
states = ["x1", "x2"]
f = ["{a11}*x1 + {a12}*x2", "{a21}*x1 + {a22}*x2"]
h = ["x1"]

[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 0.4
[method.E]
lower = [-4, -4]
upper = [4, 4]
[method.D]
lower = [-1, -1]
upper = [1, 1]

[simulate]
horizon = {horizon}
x0 = [{x1}, {x2}]
xhat0 = [0, 0]
max_centres = 200000
"""

tenth = st.integers(-10, 10).map(lambda k: k / 10)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    a11=tenth,
    a12=st.sampled_from([-1.0, -0.8, -0.6, -0.4, 0.4, 0.6, 0.8, 1.0]),
    a21=tenth,
    a22=tenth,
    x1=st.integers(-95, 95).map(lambda k: k / 100),
    x2=st.integers(-95, 95).map(lambda k: k / 100),
)
def test_random_linear_observable(tmp_path_factory, a11, a12, a21, a22, x1, x2):
    A = np.array([[a11, a12], [a21, a22]])
    assume(np.max(np.linalg.eigvals(A).real) <= 0.05)  # trajectories stay in E
    horizon = 4
    ts = np.linspace(0, horizon, 81)
    traj = np.array([expm(A * t) @ [x1, x2] for t in ts])
    assume(np.max(np.abs(traj)) < 3.5)
    text = TEMPLATE.format(a11=a11, a12=a12, a21=a21, a22=a22, x1=x1, x2=x2, horizon=horizon)
    p = tmp_path_factory.mktemp("ss") / "s.toml"
    p.write_text(text, encoding="utf-8")
    sp = api.load_spec(p)
    rep = api.design(sp)
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    p = rep.parameters
    eps = [float(e) for e in p.float("eps_schedule")]
    eps_star, L_f, dtau = p.float("eps_star"), p.float("L_f"), p.float("dtau")
    assume(dtau * len(eps) <= horizon)  # γ⋆ is reached before the end
    res = api.simulate(sp, rep)
    i = np.floor(res.t / dtau + 1e-9).astype(int)
    level = np.array([eps[min(j, len(eps) - 1)] for j in i]) * np.exp(L_f * (res.t - i * dtau))
    near = res.extra["true_cell"]
    assert np.all(near <= level * (1 + 1e-9))
    last = int(np.argmin(np.abs(res.t - res.extra["switches"][-1])))
    assert res.extra["switches"][-1] >= dtau * (len(eps) - 1) - 1e-9  # γ⋆ reached
    assert near[last] <= eps_star
    assert res.info["final_error"] <= 2 * eps_star, res.info


@pytest.mark.slow
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    a11=tenth,
    a12=st.sampled_from([-1.0, -0.7, -0.4, 0.4, 0.7, 1.0]),
    a21=tenth,
    a22=tenth,
    x1=st.integers(-95, 95).map(lambda k: k / 100),
    x2=st.integers(-95, 95).map(lambda k: k / 100),
)
def test_random_linear_observable_long(tmp_path_factory, a11, a12, a21, a22, x1, x2):
    test_random_linear_observable.hypothesis.inner_test(
        tmp_path_factory, a11, a12, a21, a22, x1, x2
    )
