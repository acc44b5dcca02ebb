"""Tests of obsdesign.api's argument checks (the CLI's own checks are in test_cli*.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from obsdesign import api
from obsdesign.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"


def test_true_false_arguments_take_bools_only(tmp_path: Path) -> None:
    """force='no' was true: design wrote its report over a .toml file, which it refuses to
    replace without force (CLI review 46). A bool (numpy's too) is taken, anything else is an
    InputError and nothing is written."""
    victim = tmp_path / "victim.toml"
    victim.write_text("x = 1\n", encoding="utf-8")
    for bad in ("no", "", 0, 1, None):
        with pytest.raises(InputError, match="force: expected True or False"):
            api.design(SPEC, out=victim, force=bad)
    assert victim.read_text(encoding="utf-8") == "x = 1\n"
    rep = api.design(SPEC, out=tmp_path / "r.json", force=np.bool_(False))
    assert rep.exit_code() == 0 and (tmp_path / "r.json").exists()
    with pytest.raises(InputError, match="force: expected True or False"):
        api.check_plot_path(tmp_path / "p.png", force="yes")
    res = api.simulate(SPEC)
    with pytest.raises(InputError, match="atomic: expected True or False"):
        api.plot_simulation(SPEC, res, tmp_path / "p.png", atomic="no")
    assert not (tmp_path / "p.png").exists()


def test_a_method_key_that_is_not_a_text_is_bad_input() -> None:
    """api.method(5) and api.method(None) were bare TypeErrors from the suggestion lookup
    (CLI review 46)."""
    for bad in (5, None, b"lyapunov"):
        with pytest.raises(InputError, match="expected a method key"):
            api.method(bad)
    assert api.method("lyapunov").key == "lyapunov"
