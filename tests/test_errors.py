"""obsdesign.errors: exit codes of the error types and one-line messages."""

from __future__ import annotations

import json
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.cli import app
from obsdesign.errors import InputError, SpecError, one_line

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()


def test_one_line_escapes_control_characters_and_shortens_digit_runs() -> None:
    assert one_line("a\nb\r\tc\x1b[2K\x85d\u2028e") == "a\\nb\\r\\tc\\x1b[2K\\x85d\\u2028e"
    assert one_line("x " + "9" * 99 + " y") == "x " + "9" * 99 + " y"
    assert one_line("9" * 100) == "9" * 20 + "…(100 digits)"
    assert one_line("plain message: [method.lambda] 0.5 ∈ (0, 1)") == (
        "plain message: [method.lambda] 0.5 ∈ (0, 1)"
    )


@given(st.text())
def test_one_line_is_one_printable_line_and_idempotent(s: str) -> None:
    out = one_line(s)
    assert len(out.splitlines()) <= 1 and "\x1b" not in out
    assert one_line(out) == out


def test_errors_carry_one_line_messages() -> None:
    e = SpecError("f\n.toml", "method.evil\x1b[2K", "is not a known key here")
    assert e.message == "f\\n.toml: [method.evil\\x1b[2K] is not a known key here"
    assert str(InputError("a\nb")) == "a\\nb"


def test_a_key_with_a_newline_and_escape_gives_one_line(tmp_path: Path) -> None:
    """Found by the CLI fuzzer: a quoted TOML key with a newline and an ESC sequence was
    printed raw, a two-line error that also erased part of the terminal line."""
    text = (ROOT / "tests" / "specs" / "lyapunov-minimal.toml").read_text()
    spec = tmp_path / "s.toml"
    spec.write_text(text.replace("[method]\n", '[method]\n"evil\\nok\\u001b[2K" = 1\n', 1))
    r = runner.invoke(app, ["design", str(spec), "-o", str(tmp_path / "r.json")])
    assert r.exit_code == 2
    assert r.stderr.count("\n") == 1 and "\x1b" not in r.stderr
    assert "[method.evil\\nok\\x1b[2K] is not a known key here" in r.stderr


def test_a_5000_digit_schema_version_is_one_short_line(tmp_path: Path) -> None:
    """Found by the CLI fuzzer: with --limit max_digits=10000 a report whose schema_version
    has 5000 digits was an internal failure (exit 3, Python's int-string limit); it is now
    exit 2 with the number shortened. A numeric schema_version is refused as such, the
    number not printed; a 5000-digit string is shortened."""
    rep = api.design(api.load_spec(ROOT / "tests" / "specs" / "lyapunov-minimal.toml"))
    d = rep.to_dict()
    d["schema_version"] = "SV"
    bad = tmp_path / "r.json"
    bad.write_text(json.dumps(d).replace('"SV"', "9" * 5000))
    r = runner.invoke(app, ["--limit", "max_digits=10000", "verify", str(bad)])
    assert r.exit_code == 2, r.stderr
    assert r.stderr.count("\n") == 1 and len(r.stderr) < 300
    assert 'schema_version must be a string like "1.1", got a number' in r.stderr
    bad.write_text(json.dumps(d).replace('"SV"', '"' + "9" * 5000 + '.1"'))
    r = runner.invoke(app, ["--limit", "max_digits=10000", "verify", str(bad)])
    assert r.exit_code == 2, r.stderr
    assert r.stderr.count("\n") == 1 and len(r.stderr) < 300
    assert "schema_version 99999999999999999999…(5000 digits)" in r.stderr
    assert "is not supported (this tool reads 1.x reports and writes 1.1)" in r.stderr
    bad.write_text(json.dumps(d).replace('"SV"', '"' + "9" * 5000 + '"'))  # no MINOR
    r = runner.invoke(app, ["--limit", "max_digits=10000", "verify", str(bad)])
    assert r.exit_code == 2 and r.stderr.count("\n") == 1 and len(r.stderr) < 300
    assert "must be MAJOR.MINOR" in r.stderr


def test_one_line_shortens_a_huge_message_and_success_lines_are_one_line(tmp_path) -> None:
    """An unknown TOML key of 5·10⁶ characters was echoed whole (a 5 MB error "line"), and
    "report written to …" printed a file name's ESC and newline raw (hostile-input trial,
    session 24)."""
    from typer.testing import CliRunner

    from obsdesign.cli import app
    from obsdesign.errors import MAX_LINE

    long = one_line("k" * 5_000_000)
    assert len(long) < MAX_LINE + 40 and long.startswith("k" * 100) and "characters)…" in long
    assert one_line("x" * MAX_LINE) == "x" * MAX_LINE  # up to the limit: whole
    spec = tmp_path / "s.toml"
    spec.write_text(
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[method]\nkey = "lyapunov"\n'
    )
    out = tmp_path / "o\x1b[31m\nx.json"
    res = CliRunner().invoke(app, ["design", str(spec), "-o", str(out)])
    assert res.exit_code == 0 and "\x1b" not in res.stdout and "o\\x1b[31m\\nx.json" in res.stdout


def test_bidirectional_controls_are_escaped() -> None:
    """U+202E (RIGHT-TO-LEFT OVERRIDE) and the other bidi controls in a file name reordered
    the rest of a printed line in bidi-aware viewers (rendering trial, session 27): escaped
    like the other controls; a soft hyphen or a joiner (also Cf) stays as it is."""
    from obsdesign.errors import escape_controls

    for ch in "\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069":
        assert escape_controls(f"a{ch}b") == f"a\\u{ord(ch):04x}b"
    assert escape_controls("soft\u00adhy\u200dphen") == "soft\u00adhy\u200dphen"


def test_invisible_format_characters_and_look_alike_names_are_shown_escaped(
    tmp_path: Path,
) -> None:
    """A parameter "mu\\u200b" a report adds showed as a second "mu" row and a Cyrillic "Р" as
    the method's "P" (verify trial, session 35): zero-width and other invisible format
    characters are escaped wherever user text is, and a name no check reads is shown in
    ASCII escapes."""
    from obsdesign.errors import ascii_name, escape_controls

    for ch in ("\u200b", "\u2060", "\ufeff", "\u2062", "\u180e"):
        assert escape_controls(f"mu{ch}") == f"mu\\u{ord(ch):04x}", ch
    # the soft hyphen and the joiners stay in text (session 27), but not in a name no check
    # reads
    assert ascii_name("mu\u200d") == "mu\\u200d"
    assert escape_controls("θ, ß, 中") == "θ, ß, 中"  # visible text as it is
    assert ascii_name("\u0420") == "\\u0420" and ascii_name("theta_1") == "theta_1"
    d = api.design(api.load_spec(ROOT / "tests" / "specs" / "lyapunov-minimal.toml")).to_dict()
    d["parameters"]["\u0420"] = 1.5
    d["parameters"]["exact"]["\u0420"] = "3/2"
    d["parameters"]["mu\u200b"] = 1
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d))
    r = runner.invoke(app, ["verify", str(p), "--width", "200"])
    assert r.exit_code == 0, r.output
    assert "\\u0420" in r.stdout and "mu\\u200b" in r.stdout
    assert "\u0420" not in r.stdout + r.stderr and "\u200b" not in r.stdout + r.stderr


def test_count_text_shortens_a_long_count_and_one_line_keeps_lists() -> None:
    """``{n:,}`` printed a 400-digit theta_m whole (CLI review, session 44): counts go through
    ``count_text``; one_line's pattern for grouped digits also caught a list of 3-digit
    numbers ("100,101,…" became "10010110210310410510…(120 digits)": re-check review), so
    a list is kept as given."""
    from obsdesign.errors import count_text, one_line

    assert count_text(10**400 - 1) == "99999999999999999999…(400 digits)"
    assert count_text(1234567) == "1,234,567" and count_text(-(10**120)).startswith("-1000")
    listed = ",".join(str(k) for k in range(100, 140))
    assert one_line(f"--set method.lambda={listed}") == f"--set method.lambda={listed}"


def test_a_byte_that_is_not_utf8_is_written_as_in_reports() -> None:
    """A file name's byte that is not UTF-8 reaches Python as a lone surrogate: error lines
    and JUnit names showed it as \\udcff, reports and check's JSON as \\xff (CLI review
    46). One spelling, \\xff, everywhere."""
    from obsdesign.errors import escape_controls, one_line, valid_text

    name = "b\udcffd.toml"
    assert valid_text(name) == "b\\xffd.toml"
    assert one_line(f"{name}: no such spec file") == "b\\xffd.toml: no such spec file"
    assert escape_controls(name) == "b\\xffd.toml"
    assert escape_controls("plain\nname") == "plain\\nname"
