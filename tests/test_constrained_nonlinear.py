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
    assert float(res.info["modified θ_m=50: max V increase over a refining step"]) <= 1e-9


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
