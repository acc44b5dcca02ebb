"""Expression-defined plant and observer (paper 000, eq. (1)-(2)) with user-given (P, ρ, μ):
inequality (5) is checked on samples (claim ``numerical``), the rest exactly."""

from __future__ import annotations

import numpy as np
import pytest

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.certify.claim import ClaimStatus
from obsdesign.errors import SpecError

NL = """
[system]
time = "discrete"
A = [[0, 1], [0, 0]]
C = [[1, 0]]
f = ["x2", "0.5*sin(x1)"]
h = ["x1 + v1"]
[sets.X]
type = "box"
lower = [-1, -1]
upper = [1, 1]
[method]
key = "constrained"
F = ["x2_hat + 0.2*(y1 - x1_hat)", "0.5*sin(x1_hat)"]
P = [[1, 0], [0, 2.4]]
rho = {rho}
mu = 0.2
X = "X"
eps_min = 0.01
[method.c]
type = "box"
lower = [-1.2, -1.2]
upper = [1.2, 1.2]
[method.D]
lower = [-0.5]
upper = [0.5]
[simulate]
horizon = 60
x0 = [0.9, -0.5]
xhat0 = [1.3, 1.3]
theta_m = [50]
gamma = {gamma}
[simulate.noise]
kind = "windows"
windows = [{{ start = 30, stop = 31, value = [0.5] }}]
"""


def test_nonlinear_design_sampled_iss():
    sp = load_spec_text(NL.format(rho=0.81, gamma=0.001), "nl.toml")
    rep = api.design(sp)
    st = {c.id: c.status for c in rep.claims}
    assert st["iss-bound"] == ClaimStatus.NUMERICAL
    assert all(s != ClaimStatus.FAILED for s in st.values()), [(c.id, c.detail) for c in rep.failed]
    assert "L" not in rep.parameters
    res = api.simulate(sp, rep)
    tr = res.extra["traces"]["modified θ_m=50"]
    assert np.all(np.isfinite(tr.xhat))
    assert float(res.info["modified θ_m=50: max V increase over a refining step"]) <= 1e-9


def test_nonlinear_wrong_rho_fails_sampling():
    """ρ too small for this observer: the sampled check of (5) finds a violation."""
    rep = api.design(load_spec_text(NL.format(rho=0.3, gamma=0.001), "nl.toml"))
    st = {c.id: c for c in rep.claims}
    assert st["iss-bound"].status == ClaimStatus.FAILED
    assert rep.exit_code() == 1


def test_nonlinear_needs_P():
    text = NL.format(rho=0.81, gamma=0.001).replace(
        "P = [[1, 0], [0, 2.4]]\nrho = 0.81\nmu = 0.2\n", "lambda = 0.9\n"
    )
    with pytest.raises(SpecError) as e:
        load_spec_text(text, "nl.toml")
    assert "method.P" in str(e.value)


def test_bad_expression_rejected():
    text = NL.format(rho=0.81, gamma=0.001).replace('"0.5*sin(x1)"]', '"__import__(1)"]')
    with pytest.raises(SpecError) as e:
        load_spec_text(text, "nl.toml")
    assert "system.f" in str(e.value)
