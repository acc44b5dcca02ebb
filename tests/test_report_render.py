"""The terminal renderer: highlighting is skipped only where it cannot change a byte (no
colour system), and the dependency versions of a report are read as importlib.metadata
reads them (issue 12 item 3: both are cold-start savings that must not change output)."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import pytest

from obsdesign import api
from obsdesign.report import model, render

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"


def _rendered(monkeypatch: pytest.MonkeyPatch, rep: Any, **console_kw: Any) -> str:
    """render_text of ``rep`` into a string through a Console made with ``console_kw``."""
    from rich.console import Console

    buf = io.StringIO()
    monkeypatch.setattr(render, "console", lambda: Console(file=buf, width=100, **console_kw))
    rep.notes = [*rep.notes, "0.5 and 'text' and None and [1, 2] and x=3"]  # highlightable
    render.render_text(rep)
    return buf.getvalue()


@pytest.mark.parametrize("color", [None, "truecolor"])
def test_highlight_changes_nothing_without_a_colour_system(
    monkeypatch: pytest.MonkeyPatch, color: str | None
) -> None:
    rep = api.design(SPEC)
    kw: dict[str, Any] = {"color_system": color, "force_terminal": color is not None}
    on = _rendered(monkeypatch, rep, highlight=True, **kw)
    off = _rendered(monkeypatch, api.design(SPEC), highlight=False, **kw)
    if color is None:
        assert on == off and "\x1b[" not in on
    else:  # with colours the highlighting shows, so it must stay on there
        assert on != off


def test_console_highlights_only_with_colours(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("FORCE_COLOR", raising=False)
    monkeypatch.setenv("TERM", "dumb")
    plain = render.console()  # stdout is captured by pytest: not a terminal
    assert plain.color_system is None and plain._highlight is False
    monkeypatch.setenv("FORCE_COLOR", "1")
    monkeypatch.setenv("TERM", "xterm-256color")
    coloured = render.console()
    assert coloured.color_system is not None and coloured._highlight is True


def test_dependency_versions_match_importlib_metadata() -> None:
    from importlib import metadata

    names = (*model.DEPS, "obsdesign", "typer", "rich", "no-such-distribution-xyz")
    fast = model.dist_versions(names)
    for n in names:
        try:
            want: str | None = metadata.version(n)
        except metadata.PackageNotFoundError:
            want = None
        assert fast[n] == want, n
    info = model.tool_info()
    assert info["version"] == metadata.version("obsdesign")
    assert set(info["dependencies"]) == set(model.DEPS)


def test_markdown_rows_keep_their_columns_whatever_the_text() -> None:
    """The lyapunov/constrained statement V(e⁺) ≤ λ²V(e) + μ|w|² split its claims row at the
    pipes in ``design --format md`` (outsider trial, session 22; the other commands' tables
    escaped them). Every row of both tables has as many unescaped pipes as its header, and a
    note with a newline stays one list item."""
    import re

    from obsdesign import api
    from obsdesign.report.render import render_markdown

    spec = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    rep = api.design(spec)
    assert any("|" in c.statement for c in rep.claims)
    rep.claims[0].detail = "a | b\nc"
    rep.notes.append("first | line\nsecond line")
    text = render_markdown(rep)
    rows = [ln for ln in text.splitlines() if ln.startswith("|")]
    pipes = [len(re.findall(r"(?<!\\)\|", ln)) for ln in rows]
    assert set(pipes) == {4, 7}, pipes  # 3 and 6 columns
    assert "- first \\| line second line" in text.splitlines()


def test_parameter_tables_mark_rounded_values(monkeypatch: pytest.MonkeyPatch) -> None:
    """The text and Markdown parameter tables show "≈" before a value rounded for display
    and nothing before one shown exactly (the certified rate α = 43333331/20000000 showed as
    "2.16667 exact", above the end its bracket proves infeasible: rendering trial, session
    27); the continuous lyapunov spec of that trial."""
    spec = api.load_spec_text(
        '[system]\ntime = "continuous"\nA = [[0, 1], [-2, -3]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nL = [1.3333333, 0.7777777]\nrate_tol = 0.0000001\n',
        "alpha.toml",
    )
    rep = api.design(spec)
    assert rep.exit_code() == 0 and str(rep.parameters["alpha"]) == "43333331/20000000"
    rows = {k: v for k, v, _ in render._param_rows(rep)}
    # α is a lower bound (its summary field's side is "down"): rounded down, marked ≥
    # (session 34; "≈ 2.16667" before, above the certified rate)
    assert rows["alpha"] == "≥ 2.16666" and rows["L"] == "≈ [1.33333; 0.777778]"
    md = render.render_markdown(rep)
    assert "| alpha | `≥ 2.16666` | exact |" in md
    assert "≥ 2.16666" in _rendered(monkeypatch, rep)
    assert rows["alpha_bracket"].startswith("≈ ")
    # a text parameter's form is "text", not "float" (docs trial, session 31)
    forms = {k: f for k, _, f in render._param_rows(rep)}
    assert forms["alpha_bracket_kind"] == "text" and forms["spectral_abscissa"] == "float"
    assert "| alpha_bracket_kind | `infeasible` | text |" in md


@pytest.mark.parametrize("width", [40, 47, 59])
def test_narrow_tables_fold_instead_of_cropping(width: int, tmp_path: Path) -> None:
    """At --width 40–59 the claims table kept the id column as wide as the longest id (25
    characters here), so rich cropped the statements with no mark: "T_max = 1." for
    "T_max = 1.3452 ≤ …" (rendering trial, session 27). Every table row keeps its right
    border now, and the statement's number is printed whole."""
    from typer.testing import CliRunner

    from obsdesign.cli import app

    spec = ROOT / "specs" / "impulsive-sector-3state.toml"
    rep = tmp_path / "r.json"
    r = CliRunner().invoke(app, ["design", str(spec), "-q", "-o", str(rep)])
    assert r.exit_code == 0
    r = CliRunner().invoke(app, ["verify", str(rep), "--width", str(width)])
    assert r.exit_code == 0, r.output
    rows = [ln for ln in r.output.splitlines() if ln.startswith("│")]
    assert rows and all(ln.rstrip().endswith("│") for ln in rows)
    assert "1.3452" in r.output


def test_a_backtick_in_the_spec_file_name_stays_inside_its_code_span() -> None:
    """`- spec: \\`…\\`` ended at a backtick in the file name (rendering trial, session 27): the
    fence is one backtick longer than the longest run in the text."""
    from obsdesign.report.render import md_code

    assert md_code("plain.toml") == "`plain.toml`"
    assert md_code("a`b.toml") == "`` a`b.toml ``"
    assert md_code("a``b|c.toml") == "``` a``b\\|c.toml ```"
    rep = api.design(SPEC)
    rep.spec_file = "we`ird.toml"
    assert "- spec: `` we`ird.toml ``" in render.render_markdown(rep).splitlines()


@pytest.mark.parametrize("width", [58, 64, 69])
def test_a_long_word_in_a_verify_detail_does_not_crop_the_table(width: int, tmp_path) -> None:
    """A verify-only claim quoting a 28-character id ('assumption1-falsification') at --width
    58–69: rich measures a column's minimum by its longest word, the forced minimum of the
    id column left no room, and the whole claims table was cropped (re-check trial, session
    27). The id column now yields to the prose's longest word."""
    import json

    from typer.testing import CliRunner

    from obsdesign.cli import app

    rep = tmp_path / "r.json"
    spec = ROOT / "specs" / "schaum-impulsive-example.toml"
    assert CliRunner().invoke(app, ["design", str(spec), "-q", "-o", str(rep)]).exit_code == 0
    d = json.loads(rep.read_text())
    d["claims"] = [c for c in d["claims"] if c["id"] != "assumption1-falsification"]
    rep.write_text(json.dumps(d))
    r = CliRunner().invoke(app, ["verify", str(rep), "--width", str(width)])
    assert r.exit_code == 1
    rows = [ln for ln in r.output.splitlines() if ln.startswith("│")]
    assert rows and all(ln.rstrip().endswith("│") for ln in rows)


def test_odd_parameter_values_render_as_text() -> None:
    """A report's ragged list parameter made verify's text and md tables end in exit 3
    ("internal failure" from numpy), and a null one showed as "≈ nan" (re-check trial,
    session 27): both are shown as the text they are."""
    from obsdesign.params import Parameters

    rep = api.design(SPEC)
    rep.parameters = Parameters(
        {**dict(rep.parameters.items()), "odd": [[1, 2], [3]], "none": None}
    )
    rows = {k: v for k, v, _ in render._param_rows(rep)}
    assert rows["odd"] == "[[1, 2], [3]]" and rows["none"] == "None"
    assert "| odd | `[[1, 2], [3]]` |" in render.render_markdown(rep)


def test_a_report_with_thousands_of_claims_prints_the_failed_ones_and_counts_the_rest(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A 9 MB report padded with 100,000 claims took 3.7 minutes to print its verify, rich
    laying out ~2 ms a row (tamper review 45): the text tables stop at TEXT_MAX_ROWS rows,
    the failed claims first, and a line counts what is not shown; a report under the cap
    prints every row, and no "not shown" line."""
    from dataclasses import replace

    from obsdesign.certify.claim import ClaimStatus

    monkeypatch.setattr(render, "TEXT_MAX_ROWS", 12)
    rep = api.design(SPEC)
    few = _rendered(monkeypatch, rep)
    assert "not shown" not in few and all(cl.id in few for cl in rep.claims)
    ok = list(rep.claims)
    bad = [
        replace(ok[0], id=f"pad-{i}", status=ClaimStatus.FAILED, detail="padded") for i in range(20)
    ]
    rep.claims = [*ok, *bad]
    out = _rendered(monkeypatch, rep)
    assert all(f"pad-{i} " in out or f"pad-{i}\n" in out for i in range(12)), out
    assert "pad-12" not in out and ok[0].id not in out.split("claims")[1]
    assert f"… {len(ok) + 8} more claims not shown (8 of them failed;" in out
    from obsdesign.params import Parameters

    rep.parameters = Parameters({f"extra{i}": float(i) for i in range(20)})
    out = _rendered(monkeypatch, rep)
    assert "… 8 more parameters not shown (--format json or md lists every one)" in out
    # the rows past the cap are not built (100,000 parameters took 54 s; CLI review 45)
    assert len(render._param_rows(rep, 3)) == 3 and len(render._param_rows(rep)) == 20


def test_the_capped_parameter_table_shows_the_verified_parameters_first(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """600 unread parameters before L and P: the 500-row table showed only them, "not
    verified", and hid every parameter the checks read (re-check review 46). Cut to the cap,
    the verified parameters come first in report order, then the unread ones."""
    from obsdesign.params import Parameters

    monkeypatch.setattr(render, "TEXT_MAX_ROWS", 12)
    rep = api.design(SPEC)
    real = dict(rep.parameters.items())
    pad = {f"a{i:04d}": float(i) for i in range(20)}
    rep.parameters = Parameters({**pad, **real})
    rep.unverified = list(pad)
    rows = render._param_rows(rep, 12)
    want = [*real, *pad][:12]
    assert [r[0] for r in rows] == want
    assert all(r[2] != "not verified" for r in rows[: len(real)])
    out = _rendered(monkeypatch, rep)
    assert all(f"\n{k} " in out or f" {k} " in out for k in list(real)[:3]), out
    # under the cap: report order, unchanged
    assert [r[0] for r in render._param_rows(rep)] == [*pad, *real]
