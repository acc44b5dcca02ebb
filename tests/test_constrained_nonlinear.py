"""Expression-defined plant and observer (paper 000, eq. (1)-(2)) with user-given (P, ρ, μ):
inequality (5) is checked on samples (claim ``numerical``), the rest exactly."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.certify.claim import ClaimStatus
from obsdesign.errors import SpecError

NL = (Path(__file__).resolve().parent / "specs" / "constrained-nonlinear.toml").read_text(
    encoding="utf-8"
)


def nl(rho: float = 0.81) -> str:
    """The shared nonlinear test spec with another ρ."""
    return NL.replace("rho = 0.81", f"rho = {rho}")


def test_nonlinear_design_sampled_iss():
    sp = load_spec_text(nl(), "nl.toml")
    rep = api.design(sp)
    st = {c.id: c.status for c in rep.claims}
    assert st["iss-bound"] == ClaimStatus.NUMERICAL
    assert all(s != ClaimStatus.FAILED for s in st.values()), [(c.id, c.detail) for c in rep.failed]
    assert "L" not in rep.parameters
    res = api.simulate(sp, rep)
    tr = res.extra["traces"]["modified θ_m=50"]
    assert np.all(np.isfinite(tr.xhat))
    assert float(res.info["modified θ_m=50: max relative V increase over a refining step"]) <= 1e-9


def test_nonlinear_wrong_rho_fails_sampling():
    """ρ too small for this observer: the sampled check of (5) finds a violation."""
    rep = api.design(load_spec_text(nl(0.3), "nl.toml"))
    st = {c.id: c for c in rep.claims}
    assert st["iss-bound"].status == ClaimStatus.FAILED
    assert rep.exit_code() == 1


def test_nonlinear_needs_P():
    text = nl().replace("P = [[1, 0], [0, 2.4]]\nrho = 0.81\nmu = 0.2\n", "lambda = 0.9\n")
    with pytest.raises(SpecError) as e:
        load_spec_text(text, "nl.toml")
    assert "method.P" in str(e.value)


def test_bad_expression_rejected():
    text = nl().replace('"0.5*sin(x1)"]', '"__import__(1)"]')
    with pytest.raises(SpecError) as e:
        load_spec_text(text, "nl.toml")
    assert "system.f" in str(e.value)


# -- constrained trial, session 24: v̆_max and the sampled (5) --------------------------------
_SAT_P = """[system]
time = "discrete"
states = ["x1"]
f = ["0.5*x1"]
h = ["x1 + v1"]
[sets.X]
type = "box"
lower = [-1]
upper = [1]
[sets.X0]
type = "box"
lower = [-0.01]
upper = [0.01]
[sets.Xhat0]
type = "box"
lower = [-0.01]
upper = [0.01]
[method]
key = "constrained"
F = ["0.5*x1_hat + 1.4*sat(x1_hat - y1)"]
P = [[1e-8]]
rho = 0.7
mu = 1e-8
X = "X"
X0 = "X0"
Xhat0 = "Xhat0"
eps_min = 0.01
[method.c]
type = "box"
lower = [-1.1]
upper = [1.1]
[method.D]
lower = [-0.01]
upper = [0.01]
"""
_LIN_MU = """[system]
time = "discrete"
A = [[0.5]]
C = [[1]]
[sets.X]
type = "box"
lower = [-1]
upper = [1]
[sets.X0]
type = "box"
lower = [0]
upper = [0.001]
[sets.Xhat0]
type = "box"
lower = [0]
upper = [0.001]
[method]
key = "constrained"
L = [0.1]
P = [[1]]
rho = 0.5
mu = 0.001
X = "X"
X0 = "X0"
Xhat0 = "Xhat0"
eps_min = 0.01
[method.c]
type = "box"
lower = [-1.1]
upper = [1.1]
[method.D]
lower = [-0.5]
upper = [0.5]
"""
_BAND = """[system]
time = "discrete"
states = ["x1"]
f = ["0.5*x1"]
h = ["x1 + v1"]
[sets.X]
type = "box"
lower = [-1]
upper = [1]
[method]
key = "constrained"
F = ["0.5*x1_hat + 0.5*(x1_hat - y1)*step((x1_hat - y1)^2 - 0.0057)*step(0.00577 - (x1_hat - y1)^2)"]
P = [[1]]
rho = 0.5
mu = 0
X = "X"
eps_min = 1
[method.c]
type = "box"
lower = [-1.1]
upper = [1.1]
[method.D]
lower = [0]
upper = [0]
"""
_NL1 = """[system]
time = "discrete"
states = ["x1", "x2"]
f = ["0.5*x1 + 0.1*sin(x2)", "0.4*x2 + d1"]
h = ["x1 + v1"]
disturbances = 1
[sets.X]
type = "box"
lower = [-1, -1]
upper = [1, 1]
[sets.X0]
type = "box"
lower = [-0.5, -0.5]
upper = [0.5, 0.5]
[sets.Xhat0]
type = "box"
lower = [-1, -1]
upper = [1, 1]
[method]
key = "constrained"
F = ["0.5*x1_hat + 0.1*sin(x2_hat)", "0.4*x2_hat"]
P = [[1, 0], [0, 1]]
rho = 0.5
mu = 2
X = "X"
X0 = "X0"
Xhat0 = "Xhat0"
eps_min = 0.01
[method.c]
type = "box"
lower = [-1.1, -1.1]
upper = [1.1, 1.1]
[method.D]
lower = [-0.1, -0.1]
upper = [0.1, 0.1]
"""


def _claim(rep, cid):
    return next(c for c in rep.claims if c.id == cid)


def test_v_max_breve_rests_on_inequality_5() -> None:
    """v̆_max bounds V along solutions only where (5) holds, yet its claim was certified on
    the arithmetic alone: with (5) failing exactly (linear, μ too small) and with (5) false
    but only sampled (F with a saturated high gain, P = 1e-8) it stayed certified and
    false; with (5) sampled and passing it is now numerical (constrained trial, session 24)."""
    for text in (_LIN_MU, _SAT_P):
        rep = api.design(load_spec_text(text, "f.toml"))
        assert _claim(rep, "iss-bound").status is ClaimStatus.FAILED
        assert _claim(rep, "v_max_breve-bound").status is ClaimStatus.FAILED
        assert rep.exit_code() == 1
    rep = api.design(load_spec_text(_NL1, "nl1.toml"))
    assert _claim(rep, "iss-bound").status is ClaimStatus.NUMERICAL
    assert _claim(rep, "v_max_breve-bound").status is ClaimStatus.NUMERICAL
    assert rep.exit_code() == 0
    # the bound is proved for disturbances in D only, and says so (statement audit, session 43)
    assert "w_k ∈ D" in _claim(rep, "v_max_breve-bound").statement


def test_the_sampled_inequality_5_is_scaled_by_the_spec_not_the_report() -> None:
    """(5) was sampled on V-shells up to 10·v_max with the report's v_max and an absolute
    floor of 1e-6: a report with v_max raised to 10⁶ moved the samples off a violation and
    verify accepted a spec whose design failed; with P = 1e-8 the shells lay beyond every
    reachable error (constrained trial, session 24). The scale is now the v_max bound
    recomputed from the spec, with shells twelve decades below it."""
    from flint import fmpq

    rep = api.design(load_spec_text(_BAND, "band.toml"))
    assert _claim(rep, "iss-bound").status is ClaimStatus.FAILED
    rep.parameters["v_max"] = fmpq(10**6)
    again = api.certify(load_spec_text(_BAND, "band.toml"), rep.parameters)
    assert next(c for c in again if c.id == "iss-bound").status is ClaimStatus.FAILED
