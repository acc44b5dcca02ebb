"""``obsdesign check --junit FILE`` (obsdesign/junit.py) and the pre-commit hook
(.pre-commit-hooks.yaml), issue 14 item 5.

The JUnit XML is validated against tests/data/junit.xsd (the subset of Jenkins' junit-10.xsd
that obsdesign writes) with ``xmlschema`` when it is installed, and structurally (counts,
one testcase per spec and per claim) with xml.etree always."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from typer.testing import CliRunner

from obsdesign.api import CheckRow
from obsdesign.cli import app
from obsdesign.junit import _clean, junit_xml

ROOT = Path(__file__).resolve().parents[1]
XSD = ROOT / "tests" / "data" / "junit.xsd"
GOOD = """[system]
time = "discrete"
A = [[0.5, 0.1], [0, 0.8]]
C = [[1, 0]]
[method]
key = "lyapunov"
L = [0.2, 0]
lambda = 0.9
"""
runner = CliRunner()


def _folder(tmp_path: Path) -> Path:
    d = tmp_path / "designs"
    (d / "sub").mkdir(parents=True)
    (d / "good.toml").write_text(GOOD)
    # lambda below the spectral radius of A − LC (0.8): infeasible (exit 1)
    (d / "sub" / "fails.toml").write_text(GOOD.replace("lambda = 0.9", "lambda = 0.7"))
    (d / "bad.toml").write_text(GOOD.replace("lambda = 0.9", "lamda = 0.9"))
    return d


def _validate_xsd(path: Path) -> None:
    xmlschema = pytest.importorskip("xmlschema")
    xmlschema.XMLSchema(str(XSD)).validate(str(path))


def test_check_junit_one_testcase_per_spec_and_claim(tmp_path: Path):
    d = _folder(tmp_path)
    out = tmp_path / "junit.xml"
    r = runner.invoke(app, ["check", str(d), "--junit", str(out), "--format", "json"])
    assert r.exit_code == 2  # the worst row: bad input
    import json

    rows = json.loads(r.stdout)
    root = ET.parse(out).getroot()
    assert root.tag == "testsuites"
    suites = root.findall("testsuite")
    assert [s.get("name") for s in suites] == [row["spec"] for row in rows]
    total = fails = errs = 0
    for s, row in zip(suites, rows, strict=True):
        cases = s.findall("testcase")
        # one for the spec, one per claim, in order
        assert [c.get("name") for c in cases] == ["design and verify"] + [
            c["id"] for c in row["claims"]
        ]
        f = sum(len(c.findall("failure")) for c in cases)
        e = sum(len(c.findall("error")) for c in cases)
        assert (s.get("tests"), s.get("failures"), s.get("errors")) == (
            str(len(cases)),
            str(f),
            str(e),
        )
        total, fails, errs = total + len(cases), fails + f, errs + e
    assert (root.get("tests"), root.get("failures"), root.get("errors")) == (
        str(total),
        str(fails),
        str(errs),
    )
    by_name = {s.get("name"): s for s in suites}
    good = by_name[str(d / "good.toml")]
    assert good.get("failures") == "0" and good.get("errors") == "0"
    assert len(good.findall("testcase")) >= 3
    failing = by_name[str(d / "sub" / "fails.toml")]
    (case,) = failing.findall("testcase")  # the design stopped: no claim
    fail = case.find("failure")
    assert fail is not None and fail.get("type") == "exit-1" and "λ = 0.7" in (fail.text or "")
    bad = by_name[str(d / "bad.toml")]
    (case,) = bad.findall("testcase")
    err = case.find("error")
    assert err is not None and err.get("type") == "exit-2" and "lamda" in (err.text or "")
    _validate_xsd(out)


def test_junit_failed_claims_are_failures(tmp_path: Path):
    claims = [
        {"id": "decay-lmi", "status": "failed", "statement": "M ⪯ 0", "detail": "pivot -1"},
        {"id": "P-pd", "status": "certified", "statement": "P ≻ 0", "detail": ""},
        {"id": "sim", "status": "numerical", "statement": "float check", "detail": ""},
    ]
    row = CheckRow("s.toml", "lyapunov", 1, 1, 1, 1, "", 0.25, "decay-lmi: pivot -1", claims)
    p = tmp_path / "j.xml"
    p.write_text(junit_xml([row]), encoding="utf-8")
    suite = ET.parse(p).getroot().find("testsuite")
    assert suite is not None
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("4", "2", "0")
    cases = {c.get("name"): c for c in suite.findall("testcase")}
    assert cases["design and verify"].find("failure") is not None
    f = cases["decay-lmi"].find("failure")
    assert f is not None and f.get("message") == "M ⪯ 0" and "pivot -1" in (f.text or "")
    assert cases["P-pd"].find("failure") is None
    assert "numerical" in (cases["sim"].findtext("system-out") or "")
    _validate_xsd(p)


def test_junit_cleans_characters_xml_forbids(tmp_path: Path):
    row = CheckRow("a\x01b.toml", "lyapunov", 1, 0, 0, 1, "", 0.5, "bad \x1b[31m", [])
    row.claims = [{"id": "x", "status": "failed", "statement": "s\x00", "detail": "d\x07"}]
    p = tmp_path / "j.xml"
    p.write_text(junit_xml([row]), encoding="utf-8")
    root = ET.parse(p).getroot()  # parses: no forbidden character left
    # escaped as the text table shows it, not dropped: "ab.toml" is another file (session 29)
    suite = root.find("testsuite")
    assert suite.get("name") == "a\\x01b.toml"
    assert suite.find("testcase").get("classname") == "obsdesign.lyapunov.a\\x01b.toml"
    failure = suite.find("testcase").find("failure")
    assert failure.get("message") == "exit 1: bad \\x1b[31m"
    claim = suite.findall("testcase")[1].find("failure")
    assert claim.get("message") == "s\\x00" and claim.text == "s\\x00\nd\\x07"
    _validate_xsd(p)


def test_junit_names_escape_newlines_and_bidi_controls(tmp_path: Path):
    """A name is one line, as in the text table: a newline or U+202E in a file name is
    written as an escape; a message keeps its newlines."""
    row = CheckRow("a\nb\u202e.toml", "lyapunov", 0, 1, 0, 0, "ok", 0.1, "", [])
    root = ET.fromstring(junit_xml([row]))
    assert root.find("testsuite").get("name") == "a\\nb\\u202e.toml"


def test_junit_refuses_a_symbolic_link(tmp_path: Path):
    d = _folder(tmp_path)
    target = tmp_path / "t.xml"
    target.write_text("keep")
    link = tmp_path / "l.xml"
    link.symlink_to(target)
    r = runner.invoke(app, ["check", str(d / "good.toml"), "--junit", str(link)])
    assert r.exit_code == 2 and "symbolic link" in r.stderr
    assert target.read_text() == "keep"


def _pre_commit() -> str:
    exe = shutil.which("pre-commit") or str(Path(sys.executable).parent / "pre-commit")
    if not Path(exe).exists():
        # a dev dependency that `make install` installs: missing is a set-up failure, not a skip
        pytest.fail("pre-commit is not installed (it is in the dev extras; see docs/ci.md)")
    return exe


def _scratch_repo(tmp_path: Path) -> Path:
    repo = tmp_path / "scratch"
    (repo / "designs").mkdir(parents=True)
    (repo / "designs" / "ok.toml").write_text(GOOD)
    (repo / "designs" / "fails.toml").write_text(GOOD.replace("lambda = 0.9", "lambda = 0.7"))
    (repo / "pyproject.toml").write_text("[project]\nname = 'x'\n")  # not a design: not passed
    env = {
        **os.environ,
        "GIT_AUTHOR_NAME": "t",
        "GIT_AUTHOR_EMAIL": "t@t",
        "GIT_COMMITTER_NAME": "t",
    }
    env["GIT_COMMITTER_EMAIL"] = "t@t"
    for cmd in (["git", "init", "-q", "."], ["git", "add", "."], ["git", "commit", "-qm", "x"]):
        subprocess.run(cmd, cwd=repo, check=True, env=env, capture_output=True)
    return repo


def _try_repo(repo: Path, hook: str, files: list[str], home: Path) -> subprocess.CompletedProcess:
    bin_dir = str(Path(sys.executable).parent)
    env = {
        **os.environ,
        "PRE_COMMIT_HOME": str(home),
        "PATH": bin_dir + os.pathsep + os.environ["PATH"],
    }
    return subprocess.run(
        [_pre_commit(), "try-repo", str(ROOT), hook, "--files", *files],
        cwd=repo,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_pre_commit_hook_system(tmp_path: Path):
    """``pre-commit try-repo`` of this repository's hook on a scratch repository: passes on a
    certified design, fails (showing the failed claim) on a failing one."""
    if subprocess.run(["git", "-C", str(ROOT), "rev-parse"], capture_output=True).returncode:
        pytest.skip("not a git checkout")
    repo = _scratch_repo(tmp_path)
    ok = _try_repo(repo, "obsdesign-check-system", ["designs/ok.toml"], tmp_path / "home")
    assert ok.returncode == 0, ok.stdout + ok.stderr
    assert "Passed" in ok.stdout
    bad = _try_repo(
        repo, "obsdesign-check-system", ["designs/ok.toml", "designs/fails.toml"], tmp_path / "home"
    )
    assert bad.returncode == 1
    assert "Failed" in bad.stdout and "NOT all checked: 2 specs, 1 ok, 1 failed" in bad.stdout


@pytest.mark.slow
def test_pre_commit_hook_python(tmp_path: Path):
    """The ``language: python`` hook builds its own environment (pip installs obsdesign and
    its dependencies: needs the package index, minutes)."""
    repo = _scratch_repo(tmp_path)
    ok = _try_repo(repo, "obsdesign-check", ["designs/ok.toml"], tmp_path / "home")
    assert ok.returncode == 0, ok.stdout + ok.stderr


# --- Mutation review 29: _clean and _name ---------------------------------------------------


def test_clean_keeps_every_character_xml_allows_and_escapes_the_rest() -> None:
    """XML 1.0's Char production: tab, newline, CR, U+0020-U+D7FF, U+E000-U+FFFD and the
    astral planes stay as they are; the C0 controls, the surrogates, U+FFFE and U+FFFF are
    written as escapes (mutation review 29: dropping tab from the allowed set, moving a range
    end by one, or escaping every astral character passed every test)."""
    kept = "a\tb\nc\rd \ud7ff\ue000\ufffd\U00010000\U0001f600\U0010ffff"
    assert _clean(kept) == kept
    assert _clean("\x00\x08\x1f") == "\\x00\\x08\\x1f"
    assert _clean("\ud800\udfff\ufffe\uffff") == "\\ud800\\udfff\\ufffe\\uffff"
    ET.fromstring(f"<a b='{_clean(kept)}'/>".encode())  # a parser takes it


def test_junit_classname_escapes_newlines_and_bidi_controls() -> None:
    """The classname names the spec too: one line, as the text table shows it (mutation
    review 29: the classname through _clean only, with a raw newline and U+202E, passed)."""
    row = CheckRow("a\nb\u202e.toml", "lyapunov", 0, 1, 0, 0, "ok", 0.1, "", [])
    row.claims = [{"id": "c\nd", "status": "certified", "statement": "s", "detail": ""}]
    root = ET.fromstring(junit_xml([row]))
    cases = root.find("testsuite").findall("testcase")
    assert {c.get("classname") for c in cases} == {"obsdesign.lyapunov.a\\nb\\u202e.toml"}
    assert cases[1].get("name") == "c\\nd"


def test_junit_names_escape_what_xml_forbids_beyond_the_controls() -> None:
    """A lone surrogate (a file name's undecodable byte) and U+FFFE in a spec's name are
    escaped in every attribute that names it, so the XML parses (mutation review 29)."""
    row = CheckRow("a\udc80b\ufffe.toml", "lyapunov", 0, 1, 0, 0, "ok", 0.1, "", [])
    text = junit_xml([row])
    root = ET.fromstring(text.encode("utf-8", "surrogatepass"))
    suite = root.find("testsuite")
    # the undecodable byte as \\x80, as reports and check's JSON write it (CLI review 46)
    assert suite.get("name") == "a\\x80b\\ufffe.toml"
    assert suite.find("testcase").get("classname") == "obsdesign.lyapunov.a\\x80b\\ufffe.toml"
