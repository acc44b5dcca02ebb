"""Tests of the impulsive simulation hook, the template and the M choices."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.certify.exact import Q, qmat, qvec
from obsdesign.errors import InputError
from obsdesign.methods import get_method
from obsdesign.methods.impulsive.claims import certify_window
from obsdesign.methods.impulsive.core import LipschitzX, Problem
from obsdesign.methods.impulsive.design import design_window

ROOT = Path(__file__).resolve().parents[1]
SPEC3 = ROOT / "specs" / "impulsive-sector-3state.toml"


def _spec3(extra: str = "", horizon: str = "8") -> str:
    txt = SPEC3.read_text(encoding="utf-8").replace("horizon = 40", f"horizon = {horizon}")
    return txt.replace("runs = 20", "runs = 3" + extra)


def test_simulate_enters_ball(tmp_path: Path) -> None:
    spec = load_spec_text(_spec3(), str(tmp_path / "s.toml"))
    rep = api.design(spec)
    res = get_method("impulsive").simulate(spec, rep.parameters)
    info = res.info
    assert info["runs_ending_in_ball"] == 3 and info["intervals_in_window"]
    assert info["noise_free_decay"]
    assert res.x.shape == res.xhat.shape and res.x.shape[1] == 3
    png = get_method("impulsive").plot_simulation(spec, res, tmp_path / "p.png")
    assert png.exists() and png.stat().st_size > 10_000


def test_sampling_file(tmp_path: Path) -> None:
    (tmp_path / "h.txt").write_text("\n".join(["0.5", "0.9", "1.2"] * 5), encoding="utf-8")
    spec = load_spec_text(_spec3('\nsampling_file = "h.txt"'), str(tmp_path / "s.toml"))
    rep = api.design(spec)
    res = get_method("impulsive").simulate(spec, rep.parameters)
    assert res.info["runs"] == 1
    assert res.info["interval_min_max"] == [0.5, 1.2]
    (tmp_path / "h.txt").write_text("0.5 -1", encoding="utf-8")
    with pytest.raises(InputError, match="positive"):
        get_method("impulsive").simulate(spec, rep.parameters)


def test_template_designs() -> None:
    """`obsdesign init impulsive` writes a spec that loads and designs."""
    spec = load_spec_text(get_method("impulsive").template(), "template.toml")
    assert api.design(spec).exit_code() == 0


def test_M_choices_with_lipschitz_x() -> None:
    """orthonormal / given / optimized M: all certify; the optimized window is not narrower."""
    A = qmat([[Q("0.2"), Q("0.005")], [Q("0.5"), -3]])
    C = qmat([[1, 0]])
    widths = {}
    for M in ("orthonormal", "optimize", qmat([[0, 1]])):
        p = Problem(A, C, qvec([Q("0.8")]), Q(3), Q("0.1"), M, LipschitzX(Q("0.005")), "widest")
        P, _ = design_window(p)
        assert all(c.ok for c in certify_window(p, P))
        widths[P["M_source"]] = float(P["T_max"] - P["T_min"])
    assert widths["optimized"] >= widths["orthonormal"] - 1e-4
    assert np.isclose(widths["given"], widths["orthonormal"])
