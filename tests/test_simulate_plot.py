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


def test_the_api_plots_check_their_path_and_arguments(tmp_path: Path) -> None:
    """api.plot_design / plot_simulation checked nothing (API review 45): a folder or a name
    without suffix said "Format 'tmp' is not supported", an int path was a bare TypeError,
    a plain dict of parameters an AttributeError, Parameters() a KeyError, and a symbolic
    link was replaced by a regular file. Each is an InputError now, the link kept; a plot to
    a new .png is written."""
    from obsdesign import api
    from obsdesign.errors import InputError
    from obsdesign.params import Parameters

    spec = api.load_spec(Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml")
    rep = api.design(spec)
    (tmp_path / "target.png").write_bytes(b"target")
    (tmp_path / "link.png").symlink_to(tmp_path / "target.png")
    for path, match in (
        (tmp_path, "is a directory"),  # it said "unknown plot format" (CLI review 45)
        (tmp_path / "noext", "unknown plot format"),
        (3, "plot path: expected a path"),
        (tmp_path / "link.png", "symbolic link"),
        # a name too long was a bare OSError from is_dir (re-check review 45)
        (tmp_path / ("a" * 300 + ".png"), "cannot write"),
    ):
        with pytest.raises(InputError, match=match):
            api.plot_design(spec, rep.parameters, path)
    assert (tmp_path / "target.png").read_bytes() == b"target"
    assert (tmp_path / "link.png").is_symlink()
    with pytest.raises(InputError, match="params must be Parameters"):
        api.plot_design(spec, dict(rep.parameters.items()), tmp_path / "a.png")
    with pytest.raises(InputError, match="not a design of this spec"):
        api.plot_design(spec, Parameters(), tmp_path / "a.png")
    with pytest.raises(InputError, match="result must be a SimResult"):
        api.plot_simulation(spec, {"t": []}, tmp_path / "s.png")
    api.plot_design(spec, rep.parameters, tmp_path / "ok.png")
    assert (tmp_path / "ok.png").stat().st_size > 0
    # a write-protected file: refused, and replaced with force=True (the API had no force
    # while the check said "(--force)"; re-check review 45)
    ro = tmp_path / "ro.png"
    ro.write_bytes(b"old")
    ro.chmod(0o444)
    with pytest.raises(InputError, match="write-protected"):
        api.plot_design(spec, rep.parameters, ro)
    api.plot_design(spec, rep.parameters, ro, force=True)
    assert ro.read_bytes() != b"old"
