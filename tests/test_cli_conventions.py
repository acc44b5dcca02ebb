"""Command-line conventions (issue 14 item 2): --version, -q, ``-`` for stdin, --format on
every printing command with nothing but JSON on stdout, "did you mean", the one-line verdict
of verify and check, readable --help, table width."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from obsdesign import __version__
from obsdesign.cli import app
from obsdesign.methods import method_keys

SPEC = """title = "one state"
[system]
time = "discrete"
A = [[0.5, 0.1], [0, 0.8]]
C = [[1, 0]]
[method]
key = "lyapunov"
lambda = 0.9
[simulate]
horizon = 20
x0 = [1, -1]
xhat0 = [0, 0]
"""
runner = CliRunner()


def _run(*args: str, input: str | None = None) -> tuple[int, str, str]:
    r = runner.invoke(app, list(args), input=input)
    return r.exit_code, r.stdout, r.stderr


@pytest.fixture()
def spec(tmp_path: Path) -> Path:
    p = tmp_path / "s.toml"
    p.write_text(SPEC)
    return p


@pytest.fixture(autouse=True)
def _no_columns(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("COLUMNS", raising=False)
    from obsdesign.report import render

    render.set_width(None)


def test_version_and_methods_json():
    code, out, _ = _run("--version")
    assert code == 0 and out.strip() == f"obsdesign {__version__}"
    code, out, _ = _run("methods", "--format", "json")
    d = json.loads(out)
    assert d["version"] == __version__
    assert [m["key"] for m in d["methods"]] == method_keys()
    code, out, _ = _run("methods", "--format", "md")
    assert out.splitlines()[0] == "| key | title | paper |" and len(out.splitlines()) == 2 + len(
        method_keys()
    )


def test_stdin_spec_quiet_and_verdict(tmp_path: Path):
    out_json = tmp_path / "r.json"
    code, out, _ = _run("design", "-", "-q", "-o", str(out_json), input=SPEC)
    assert code == 0 and out == ""  # quiet: nothing on stdout
    d = json.loads(out_json.read_text())
    assert d["spec_file"] == "<stdin>" and d["verdict"] == "ok"
    n = len(d["claims"])
    code, out, _ = _run("verify", str(out_json))
    assert code == 0
    assert out.rstrip().splitlines()[-1] == f"verified: {n} claims certified, 0 failed"
    code, out, _ = _run("verify", str(out_json), "-q")
    assert out == f"verified: {n} claims certified, 0 failed\n"
    # a report from stdin
    code, out, _ = _run("verify", "-", "-q", input=out_json.read_text())
    assert code == 0 and out == f"verified: {n} claims certified, 0 failed\n"
    # tampered: the verdict says so and the exit code is 1
    d["parameters"]["exact"]["L"][0][0] = "7"
    d["parameters"]["L"][0][0] = 7.0
    code, out, _ = _run("verify", "-", "-q", input=json.dumps(d))
    assert code == 1 and out.startswith("NOT verified: ")


def test_stdin_report_is_parsed_like_a_file(tmp_path: Path):
    """``verify -`` refuses a key repeated in one JSON object, as ``verify FILE`` does, with
    exit 2 naming <stdin> and the key: stdin skipped the duplicate-key check and verified the
    last of two "parameters" copies (session 27), while other readers take the first."""
    out_json = tmp_path / "r.json"
    assert _run("design", "-", "-q", "-o", str(out_json), input=SPEC)[0] == 0
    text = out_json.read_text()
    bad = text.replace('"parameters":', '"parameters": {}, "parameters":', 1)
    for args in (("verify", "-"), ("verify", str(_write(tmp_path / "bad.json", bad)))):
        code, out, err = _run(*args, "-q", input=bad)
        assert code == 2 and out == "", err
        assert "key 'parameters' appears twice in one JSON object" in err
        assert ("<stdin>" in err) == (args[1] == "-")


def _write(p: Path, text: str) -> Path:
    p.write_text(text)
    return p


def test_verify_json_verdict_is_the_verification(tmp_path: Path):
    """``verify --format json`` carries the verdict its recomputed claims give, not the
    report's stored one: a tampered statement printed "verdict": "ok" beside a failed
    report-alters claim and exit 1 (rendering trial, session 27); a CI job reading the field
    would have passed it. The stored verdict edited to "inconclusive" is likewise replaced."""
    out_json = tmp_path / "r.json"
    assert _run("design", "-", "-q", "-o", str(out_json), input=SPEC)[0] == 0
    d = json.loads(out_json.read_text())
    code, out, _ = _run("verify", "-", "--format", "json", input=json.dumps(d))
    assert code == 0 and json.loads(out)["verdict"] == "ok"
    d["claims"][0]["statement"] += " (edited)"
    for stored in ("ok", "inconclusive"):
        d["verdict"] = stored
        code, out, _ = _run("verify", "-", "--format", "json", input=json.dumps(d))
        v = json.loads(out)
        assert code == 1 and v["verdict"] == "failed", stored
        assert any(c["id"].startswith("report-alters:") for c in v["claims"])


def test_stdin_output_checks_still_refuse(tmp_path: Path):
    target = tmp_path / "t.json"
    target.write_text("{}")
    link = tmp_path / "link.json"
    link.symlink_to(target)
    code, _, err = _run("design", "-", "-o", str(link), input=SPEC)
    assert code == 2 and "symbolic link" in err
    assert target.read_text() == "{}"
    target.chmod(0o444)  # write-protected (mode bits count even for root)
    code, _, err = _run("design", "-", "-o", str(target), input=SPEC)
    assert code == 2 and "write-protected" in err


@pytest.mark.parametrize(
    "args",
    [
        ("design", "{spec}", "--format", "json"),
        ("verify", "{report}", "--format", "json"),
        ("check", "{spec}", "--format", "json"),
        ("simulate", "{spec}", "--format", "json"),
        ("methods", "--format", "json"),
        ("schema", "--format", "json"),
    ],
)
def test_json_only_on_stdout(args: tuple[str, ...], spec: Path, tmp_path: Path):
    report = tmp_path / "r.json"
    assert _run("design", str(spec), "-q", "-o", str(report))[0] == 0
    argv = [a.format(spec=spec, report=report) for a in args]
    code, out, _ = _run(*argv)
    assert code == 0
    json.loads(out)  # the whole of stdout is one JSON document


def test_check_verdict_line_and_md(spec: Path, tmp_path: Path):
    bad = tmp_path / "bad.toml"
    bad.write_text(SPEC.replace("lambda = 0.9", "lamda = 0.9"))
    code, out, _ = _run("check", str(spec), "-q")
    assert code == 0
    assert re.fullmatch(r"checked: 1 spec, 1 ok, 0 failed; \d+ claims certified, 0 failed\n", out)
    code, out, _ = _run("check", str(spec), str(bad), "--format", "md")
    assert code == 2
    assert out.rstrip().splitlines()[-1].startswith("**NOT all checked: 2 specs, 1 ok, 1 failed;")


def test_check_md_says_why_a_row_failed(tmp_path: Path):
    """A row that exits 1 with claims shows its failure in Markdown as in text: the md table
    showed the summary (rendering trial, session 27). A nonlinear psi fails linear-plant."""
    nonlin = tmp_path / "nonlin.toml"
    nonlin.write_text(SPEC.replace("C = [[1, 0]]", 'C = [[1, 0]]\npsi = ["0", "0.01*sin(x1)"]'))
    for fmt in ("md", "text"):
        code, out, _ = _run("check", str(nonlin), "--format", fmt, "--width", "300")
        assert code == 1, out
        assert "linear-plant: [system] psi make(s) the plant nonlinear" in out, fmt


def test_did_you_mean(tmp_path: Path):
    # an unknown key next to an optional one
    code, _, err = _run("design", "-", input=SPEC.replace("[simulate]", "[simulat]"))
    assert code == 2 and "(did you mean 'simulate'?)" in err
    code, _, err = _run(
        "design", "-", input=SPEC.replace("lambda = 0.9", "lambda = 0.9\nrate_tl = 1")
    )
    assert code == 2 and "[method.rate_tl]" in err and "(did you mean 'rate_tol'?)" in err
    # a misspelt required key
    si = runner.invoke(app, ["init", "set-invariant"]).stdout
    assert re.search(r"^lambda = ", si, re.M)
    code, _, err = _run("design", "-", input=re.sub(r"^lambda = ", "lamda = ", si, flags=re.M))
    assert code == 2 and "[method.lambda] is missing (is 'lamda' a misspelling of it?)" in err
    code, _, err = _run("init", "lyapunv")
    assert code == 2 and "did you mean 'lyapunov'" in err


def test_help_metavars_readable():
    names = [c.name or c.callback.__name__ for c in app.registered_commands]
    assert {"design", "verify", "check", "simulate", "schema", "init", "import", "methods"} <= set(
        names
    )
    for cmd in [*names, "--help"]:
        out = runner.invoke(app, [cmd, "--help"] if cmd != "--help" else ["--help"]).stdout
        for bad in ("{", "<list[", "<path>", "<str>"):
            assert bad not in out, (cmd, bad)
    assert (
        "Usage: obsdesign check [OPTIONS] PATH..." in runner.invoke(app, ["check", "--help"]).stdout
    )
    assert "--install-completion" in runner.invoke(app, ["--help"]).stdout


@pytest.mark.parametrize("width", [80, 100, 160])
def test_width_and_unbroken_ids(width: int, spec: Path, tmp_path: Path):
    report = tmp_path / "r.json"
    assert _run("design", str(spec), "-q", "-o", str(report))[0] == 0
    ids = [c["id"] for c in json.loads(report.read_text())["claims"]]
    code, out, _ = _run("verify", str(report), "--width", str(width))
    lines = out.splitlines()
    assert max(len(x) for x in lines) <= width
    cells = {c.strip() for line in lines for c in re.split(r"[│┃]", line)}
    for cid in ids:
        assert cid in cells, cid  # each id whole in one cell, never broken


def test_default_width_not_a_terminal(spec: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    report = tmp_path / "r.json"
    assert _run("design", str(spec), "-q", "-o", str(report))[0] == 0
    out = _run("verify", str(report))[1]
    assert max(len(x) for x in out.splitlines()) == 100  # not a terminal: 100 columns
    monkeypatch.setenv("COLUMNS", "90")
    out = _run("verify", str(report))[1]
    assert max(len(x) for x in out.splitlines()) == 90


def test_columns_below_40_get_40(spec: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """COLUMNS=20 wrapped every cell to 6 characters (outsider trial, session 29): the width
    is at least 40, the least --width takes."""
    report = tmp_path / "r.json"
    assert _run("design", str(spec), "-q", "-o", str(report))[0] == 0
    monkeypatch.setenv("COLUMNS", "20")
    lines = _run("verify", str(report))[1].splitlines()[:-1]  # the verdict line is one line
    assert max(len(x) for x in lines) == 40


def test_the_package_installs_the_interrupt_handler_before_any_other_import() -> None:
    """``from typing import …`` ran before the handler was installed: a Ctrl-C in those
    milliseconds printed a traceback ending in obsdesign/__init__.py (re-check review,
    session 42). Only _signal, os and sys (already loaded by the interpreter) come first."""
    import ast

    import obsdesign

    tree = ast.parse(Path(obsdesign.__file__).read_text(encoding="utf-8"))
    install = next(
        i
        for i, node in enumerate(tree.body)
        if isinstance(node, ast.If) and "_early_interrupt" in ast.unparse(node)
    )
    # the installing ``if`` itself tests the handler, not the environment first
    test = ast.unparse(tree.body[install].test)
    assert "getsignal" in test and "environ" not in test, test
    for node in tree.body[:install]:
        if isinstance(node, ast.ImportFrom):
            assert node.module == "__future__", ast.unparse(node)
        elif isinstance(node, ast.Import):
            assert {a.name for a in node.names} <= {"_signal", "os", "sys"}, ast.unparse(node)
        else:  # the docstring, the handler's def, constants: no lookups (the worker's
            # environment test ran first and left a window too)
            ok = (ast.Expr, ast.FunctionDef, ast.Assign)
            assert isinstance(node, ok), ast.unparse(node)
            if isinstance(node, ast.Assign):
                assert isinstance(node.value, ast.Constant), ast.unparse(node)


def test_early_interrupt_handler_installed_by_the_package():
    code = (
        "import sys, signal; sys.argv[0] = '/x/bin/obsdesign'; import obsdesign; "
        "print(signal.getsignal(signal.SIGINT) is obsdesign._early_interrupt)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.stdout.strip() == "True"
    r = subprocess.run(
        [sys.executable, "-c", code.replace("/x/bin/obsdesign", "python")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.stdout.strip() == "False"  # a library import leaves Ctrl-C alone


def test_python_dash_m_runs_the_command_line(tmp_path: Path):
    """``python -m obsdesign`` is the console script (there was no __main__: two trials of
    session 29 reached for it); its early Ctrl-C handler is installed as for the script."""
    r = subprocess.run(
        [sys.executable, "-m", "obsdesign", "--version"], capture_output=True, text=True, timeout=60
    )
    assert r.returncode == 0 and r.stdout.strip().startswith("obsdesign ")
    bad = tmp_path / "bad.toml"
    bad.write_text("[system\n")
    r = subprocess.run(
        [sys.executable, "-m", "obsdesign", "design", str(bad)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "Traceback" not in r.stderr
    code = (
        "import sys; sys.argv[0] = '-m'; import obsdesign, signal; "
        "print(signal.getsignal(signal.SIGINT) is obsdesign._early_interrupt)"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.stdout.strip() == "True"


def test_check_table_at_80_columns(spec: Path, tmp_path: Path):
    si = tmp_path / "si.toml"
    si.write_text(runner.invoke(app, ["init", "set-invariant"]).stdout)
    out = _run("check", str(spec), str(si), "--width", "80")[1]
    lines = out.splitlines()
    assert max(len(x) for x in lines) <= 80
    words = {w.strip() for line in lines for w in re.split(r"[│┃·]", line)}
    assert {"lyapunov", "set-invariant", "ok"} <= words  # never broken
    assert "…" not in out


@pytest.mark.parametrize("width", [40, 50, 60])
def test_check_rows_stay_whole_at_narrow_widths(width: int, spec: Path, tmp_path: Path):
    """At --width 40 rich ellipsized the claim counts ("5/0…" for 5/0/1: the failed claim
    hidden) and squeezed the spec and result columns to nothing (rendering trial, session
    29): each row is then a block of lines with every field whole."""
    bad = tmp_path / "bad.toml"
    bad.write_text(SPEC.replace("lambda = 0.9", "L = [0, 0]\nlambda = 0.5"))
    code, out, _ = _run("check", str(spec), str(bad), "--width", str(width))
    assert code == 1
    lines = out.splitlines()[:-1]  # the verdict line is one line whatever the width
    assert max(len(x) for x in lines) <= width
    assert "…" not in out
    joined = "".join(x.strip() for x in lines)
    assert str(bad).replace(" ", "") in joined.replace(" ", "")
    assert "exit 1" in out and re.search(r"claims \d+/\d+/\d+", out)


@pytest.mark.parametrize("width", [40, 50])
def test_parameter_names_are_never_ellipsized(width: int, spec: Path, tmp_path: Path):
    """Three equal columns at --width 40 showed lambda_bracket and lambda_bracket_kind both
    as "lambda_br…" (rendering trial, session 29): names fold, the form goes under them."""
    report = tmp_path / "r.json"
    assert _run("design", str(spec), "-q", "-o", str(report))[0] == 0
    out = _run("verify", str(report), "--width", str(width))[1]
    assert max(len(x) for x in out.splitlines()) <= width
    table = out.split("claims")[0]
    assert "…" not in table
    names = json.loads(report.read_text())["parameters"].keys() - {"exact"}
    flat = "".join(c.strip() for line in table.splitlines() for c in re.split(r"[│┃]", line)[1:2])
    for k in names:
        assert k in flat, k


def test_simulate_from_stdin_json():
    code, out, _ = _run("simulate", "-", "--format", "json", input=SPEC)
    assert code == 0 and json.loads(out)["final_error_norm"] >= 0
    code, out, _ = _run("simulate", "-", "-q", input=SPEC)
    assert code == 0 and out == ""


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["design", "--bogus", "s.toml"],
            "No such option: --bogus (see 'obsdesign design --help')",
        ),
        (["desgn"], "No such command 'desgn'. Did you mean 'design'? (see 'obsdesign --help')"),
        (["design"], "Missing argument 'SPEC'. (see 'obsdesign design --help')"),
        (["design", "--width", "3", "s.toml"], "Invalid value for '--width'"),
        (["simulate", "s.toml", "--runs", "x"], "Invalid value for '--runs'"),
    ],
)
def test_usage_errors_are_one_line_exit_2(
    argv: list[str], message: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    """Click's own usage errors printed a four-line block ("Usage: …", "Try …", blank,
    "Error: …"); through the console entry point they are now one line like every other
    bad input, exit 2."""
    from obsdesign.cli import main

    monkeypatch.setattr(sys, "argv", ["obsdesign", *argv])
    with pytest.raises(SystemExit) as e:
        main()
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("obsdesign: error: ") and err.count("\n") == 1 and message in err


def test_entry_point_passes_exit_codes_and_help_through(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    """main() runs click outside its standalone mode: a command's exit code, --help and a
    bare ``obsdesign`` (the help, exit 2 as click gives it) are unchanged."""
    from obsdesign.cli import main

    spec = tmp_path / "s.toml"
    spec.write_text(SPEC)
    for argv, code in (
        (["design", str(spec), "-q"], 0),
        (["design", str(spec).replace("s.toml", "t.toml")], 2),
        (["--help"], 0),
        ([], 2),
    ):
        monkeypatch.setattr(sys, "argv", ["obsdesign", *argv])
        with pytest.raises(SystemExit) as e:
            main()
        assert e.value.code == code, argv
    c = capsys.readouterr()
    assert "Usage: obsdesign" in c.out and "Usage: obsdesign" in c.err


# --- Mutation review 29: narrow check rows and parameter tables


def _check_fixed(spec: Path, bad: Path) -> int:
    """The width of check's never-wrapping columns (method, verdict, claims, s) at their
    widest, headers included, as _print_rows computes it (from the JSON rows)."""
    rows = json.loads(_run("check", str(spec), str(bad), "--format", "json")[1])
    cols = [
        ("method", [r["method"] for r in rows]),
        ("verdict", ["ok" if r["code"] == 0 else f"exit {r['code']}" for r in rows]),
        ("claims", [f"{r['certified']}/{r['numerical']}/{r['failed']}" for r in rows]),
        ("s", [f"{r['seconds']:.2f}" for r in rows]),
    ]
    return sum(max(len(h), *map(len, v)) for h, v in cols)


def test_check_switches_to_blocks_exactly_below_its_threshold(spec: Path, tmp_path: Path):
    """The table while it fits (the fixed columns + CHECK_SPEC_MIN + CHECK_RESULT_MIN + 19
    for the borders), blocks of lines below; a block holds the result text too (mutation
    review 29: moving the threshold by the borders, ``<=`` for ``<``, headers or the claims
    column left out of the sum, or the result line dropped, each passed every test)."""
    bad = tmp_path / "bad.toml"
    bad.write_text(SPEC.replace("lambda = 0.9", "L = [0, 0]\nlambda = 0.5"))
    from obsdesign.cli_commands import CHECK_RESULT_MIN, CHECK_SPEC_MIN

    T = _check_fixed(spec, bad) + CHECK_SPEC_MIN + CHECK_RESULT_MIN + 19
    for width, table in ((T, True), (T - 1, False), (T + 19, True), (T - 19, False)):
        code, out, _ = _run("check", str(spec), str(bad), "--width", str(width))
        assert code == 1
        assert ("┃" in out) is table, (width, T, out)
        # the verdict line is one line whatever the width
        assert "…" not in out and max(len(x) for x in out.splitlines()[:-1]) <= width
        if not table:
            flat = " ".join(out.split())
            assert "no P ≻ 0 gives decay rate λ = 0.5" in flat, out


@pytest.mark.parametrize("width", [40, 50, 71])
def test_parameter_forms_go_under_names_below_72_columns(width: int, spec: Path, tmp_path: Path):
    """Below 72 columns the parameters table has two columns, "parameter / form" and value,
    each name followed by its form (exact, float, text or not verified); a name folds only when
    it is longer than a third of the width (mutation review 29: the wide table below 72,
    the threshold at 41, the form left out, a narrower name column: each passed)."""
    report = tmp_path / "r.json"
    assert _run("design", str(spec), "-q", "-o", str(report))[0] == 0
    out = _run("verify", str(report), "--width", str(width))[1]
    table = out.split("claims")[0]
    assert "parameter /" in table and "form" in table
    cells = [
        re.split(r"[│┃]", line)[1].strip() for line in table.splitlines() if line.startswith("│")
    ]
    d = json.loads(report.read_text())
    names = [k for k in d["parameters"] if k != "exact"]
    flat = "".join(cells)
    for k in names:
        i = flat.index(k)
        assert flat[i + len(k) :].startswith(("exact", "float", "text", "not verified")), (k, flat)
        if len(k) <= width // 3:
            assert k in cells, (k, cells)  # whole on its line
    wide = _run("verify", str(report), "--width", "72")[1].split("claims")[0]
    assert "parameter /" not in wide and "form" in wide


def test_print_rows_of_no_rows_prints_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    """_print_rows([]) raised TypeError (the column widths were taken before any guard;
    mutation review 29; check refuses an empty list of specs before reaching it)."""
    from obsdesign.cli import Fmt
    from obsdesign.cli_commands import _print_rows

    _print_rows([], Fmt.text)
    assert capsys.readouterr().out == ""


def test_width_does_not_outlive_its_command(spec: Path, tmp_path: Path):
    """--width was kept for every later command of the same process (CliRunner, an API
    caller of the CLI): one `verify --width 40` wrapped the tables of all the commands after
    it, and a test of the default table broke depending on the tests before it (session 30)."""
    report = tmp_path / "r.json"
    assert _run("design", str(spec), "-q", "-o", str(report))[0] == 0
    narrow = _run("verify", str(report), "--width", "40")[1]
    assert max(len(x) for x in narrow.splitlines()) <= 40
    out = _run("verify", str(report))[1]
    assert max(len(x) for x in out.splitlines()) == 100


def test_messages_name_the_papers_as_the_docs_do(tmp_path: Path) -> None:
    """ "paper 000" / "paper 004" are the team's folder numbers, defined nowhere a user reads:
    the wrong-time refusals of constrained and search-space, and every search-space claim's
    reference, printed them (docs trial, session 33). They name the authors, as the docs do."""
    for key, time, who in (
        ("constrained", "continuous", "Astolfi et al."),
        ("search-space", "discrete", "Hernández & García"),
    ):
        spec = tmp_path / f"{key}.toml"
        spec.write_text(
            f'[system]\ntime = "{time}"\nA = [[0.5]]\nC = [[1]]\n[method]\nkey = "{key}"\n'
        )
        r = CliRunner().invoke(app, ["design", str(spec)])
        assert r.exit_code == 2 and who in r.output and "paper 0" not in r.output, r.output
    root = Path(__file__).parent.parent
    r = CliRunner().invoke(
        app, ["design", str(root / "specs" / "hernandez-garcia-example.toml"), "--format", "json"]
    )
    refs = {c["reference"] for c in json.loads(r.output)["claims"]}
    assert r.exit_code == 0 and refs and not [x for x in refs if "paper 0" in x], refs


def test_dot_slash_dash_is_the_file_named_dash_not_stdin(tmp_path: Path) -> None:
    """``design ./-`` read stdin, the spec piped in, and never the file ``-`` (typer made it
    ``Path("-")``, the value that means stdin; CLI review, session 44). Only the literal ``-``
    is stdin."""
    root = Path(__file__).resolve().parents[1] / "specs"
    shutil.copy(root / "schaum-impulsive-example.toml", tmp_path / "-")
    piped = (root / "constrained-redesign-sec5-lyapunov.toml").read_text(encoding="utf-8")
    run = [sys.executable, "-m", "obsdesign", "design"]
    for arg, method in (("./-", "impulsive"), (".//-", "impulsive"), ("-", "lyapunov")):
        r = subprocess.run(
            [*run, arg, "--format", "json"],
            input=piped,
            capture_output=True,
            text=True,
            cwd=tmp_path,
            timeout=300,
        )
        assert r.returncode == 0, r.stderr
        assert json.loads(r.stdout)["method"] == method, arg


def test_an_os_error_naming_a_file_outside_a_command_names_that_file(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    """``--install-completion`` into a read-only home said "stdout: cannot write (Read-only
    file system)" (CLI review, session 44): an OS error with a file name names the file; one
    without (stdout full) still says stdout."""
    import errno

    import typer._completion_shared

    from obsdesign import cli

    # the shell is found from the parent processes: under `sh make.sh test` (sh, no bash
    # between) --install-completion was refused for sh before the error under test (fresh-
    # Debian review 46)
    monkeypatch.setattr(typer._completion_shared, "_get_shell_name", lambda: "bash")
    for exc, want in (
        (OSError(errno.EROFS, "Read-only file system", "/home/u/.bashrc"), "/home/u/.bashrc"),
        (OSError(errno.ENOSPC, "No space left on device"), "stdout: cannot write"),
    ):

        def boom(*a: object, _e: OSError = exc, **k: object) -> None:
            raise _e

        monkeypatch.setattr(cli, "app", boom)
        monkeypatch.setattr(sys, "argv", ["obsdesign", "--install-completion"])
        with pytest.raises(SystemExit) as e:
            cli.main()
        assert e.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith(f"obsdesign: error: {want}"), err


@pytest.mark.parametrize(
    "argv",
    [
        ["--install-completion", "tcsh"],
        ["--show-completion", "nushell"],
        ["design", "x.toml", "--show-completion"],
        ["--install-completion", "--show-completion"],  # installed silently (CLI review 45)
        ["--", "--install-completion"],  # no command before --: click reads the flag (45)
    ],
)
def test_a_completion_flag_with_anything_else_is_bad_input(
    argv: list[str], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    """``--install-completion tcsh`` installed bash completion, exit 0, the shell name
    silently dropped (CLI review 44): typer's completion flags take no value and act at once,
    so anything given with them is refused before they run, naming it."""
    from obsdesign import cli

    ran: list[object] = []
    monkeypatch.setattr(cli, "app", lambda *a, **k: ran.append(a))
    monkeypatch.setattr(sys, "argv", ["obsdesign", *argv])
    with pytest.raises(SystemExit) as e:
        cli.main()
    assert e.value.code == 2 and not ran
    err = capsys.readouterr().err
    other = next((a for a in argv if not a.endswith("-completion")), argv[1])
    assert err.startswith("obsdesign: error: --") and repr(other) in err, err
    assert err.count("\n") == 1


def test_completion_is_for_its_shells_and_a_file_after_dash_dash_is_a_file(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    """From sh, typer said "Shell sh not supported." and exited 1, a failed claim's code
    (the install variant on stdout); a spec file named ``--show-completion`` given after
    ``--`` was refused as the flag (CLI review 45). The shell is named, exit 2; after ``--``
    the name is a file's; from bash the flag runs."""
    import typer._completion_shared as shared

    from obsdesign import cli

    ran: list[object] = []
    monkeypatch.setattr(cli, "app", lambda *a, **k: ran.append(a))
    for shell, argv, code in (
        ("sh", ["--show-completion"], 2),
        (None, ["--install-completion"], 2),
        ("bash", ["--show-completion"], None),
        ("sh", ["design", "--", "--show-completion"], None),
    ):
        monkeypatch.setattr(shared, "_get_shell_name", lambda s=shell: s)
        monkeypatch.setattr(sys, "argv", ["obsdesign", *argv])
        ran.clear()
        if code is None:
            with pytest.raises(SystemExit):
                cli.main()
            assert ran, argv
            continue
        with pytest.raises(SystemExit) as e:
            cli.main()
        assert e.value.code == 2 and not ran
        err = capsys.readouterr().err
        assert f"the shell here is {shell or 'unknown'!r}" in err, err


def test_dot_slash_dash_in_a_removed_folder_is_no_traceback(tmp_path: Path) -> None:
    """``./-`` is made absolute from the working folder; with that folder removed,
    os.getcwd() raised FileNotFoundError before the error handling: a traceback, exit 1
    (re-check review, session 44). One line, no traceback."""
    gone = tmp_path / "gone"
    gone.mkdir()
    (tmp_path / "gone2").mkdir()
    code = (
        "import os, sys; os.chdir(sys.argv[1]); os.rmdir(sys.argv[1]); "
        "sys.argv = ['obsdesign', 'design', './-']; from obsdesign.cli import main; main()"
    )
    r = subprocess.run(
        [sys.executable, "-c", code, str(gone)],
        input="",
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert "Traceback" not in r.stderr and r.returncode == 2, r.stderr
    assert "./-: cannot use (the working folder no longer exists" in r.stderr, r.stderr
    # check of a relative file there was an internal failure, exit 3 (realpath; re-check):
    # its row says so; a command with an absolute path still runs (--version, here)
    code = code.replace("'design', './-'", "'check', './x.toml'")
    again = [sys.executable, "-c", code, str(tmp_path / "gone2")]
    r = subprocess.run(again, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "no such spec file" in r.stdout + r.stderr, r.stderr
    code = code.replace("'check', './x.toml'", "'--version'")
    again = [sys.executable, "-c", code, str(tmp_path / "gone3")]
    (tmp_path / "gone3").mkdir()
    r = subprocess.run(again, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
