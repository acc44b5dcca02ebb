"""Plots: user text (titles, file names, swept values) is drawn as written."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from obsdesign.cli import app
from obsdesign.simulate.plot import plain

ROOT = Path(__file__).resolve().parents[1]


def test_plain_escapes_every_dollar() -> None:
    assert plain("costs $5 to $10") == r"costs \$5 to \$10"
    assert plain("no math") == "no math"


@pytest.mark.parametrize(
    "spec", ["constrained-redesign-sec5-lyapunov.toml", "astolfi-stubborn-example1.toml"]
)
def test_a_title_with_dollars_plots_as_written(tmp_path: Path, spec: str) -> None:
    """A title "bad $\\frac{ mathtext $" ended simulate --plot with exit 3 after the run
    (matplotlib parsed it as math text), and "costs $5 to $10" was drawn "costs 5to10" (CLI
    hostile-input trial, session 34): titles go through :func:`plain`."""
    text = (ROOT / "specs" / spec).read_text()
    s = tmp_path / "s.toml"
    s.write_text(
        'title = "bad $\\\\frac{ mathtext $ \\\\x"\n'
        + "\n".join(line for line in text.splitlines() if not line.startswith("title"))
    )
    png = tmp_path / "p.png"
    r = CliRunner().invoke(app, ["simulate", str(s), "-q", "--plot", str(png)])
    assert r.exit_code == 0, r.output
    assert png.stat().st_size > 1000
