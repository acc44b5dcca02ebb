"""Output files (issue 11 item 1): never destroy a user's file, never leave a stale report,
every OS error on output is exit 2 with the path and the reason; broken pipes are quiet."""

from __future__ import annotations

import errno
import json
import math
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from obsdesign.cli import app

SPEC = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
runner = CliRunner()


@pytest.fixture
def spec(tmp_path: Path) -> Path:
    p = tmp_path / "s.toml"
    shutil.copy(SPEC, p)
    return p


def _refused(res, *words: str) -> None:
    assert res.exit_code == 2, res.output
    err = res.output.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("obsdesign: error:"), res.output
    for w in words:
        assert w in err[0]


def test_output_is_the_spec_itself(spec: Path):
    before = spec.read_bytes()
    _refused(runner.invoke(app, ["design", str(spec), "-o", str(spec)]), "input file itself")
    assert spec.read_bytes() == before


def test_output_through_symlink_to_spec(spec: Path, tmp_path: Path):
    link = tmp_path / "r.json"
    link.symlink_to(spec)
    before = spec.read_bytes()
    _refused(runner.invoke(app, ["design", str(spec), "-o", str(link)]))
    assert spec.read_bytes() == before and link.is_symlink()


def test_output_symlink_elsewhere(spec: Path, tmp_path: Path):
    target = tmp_path / "t.json"
    target.write_text("keep")
    link = tmp_path / "r.json"
    link.symlink_to(target)
    _refused(runner.invoke(app, ["design", str(spec), "-o", str(link)]), "symbolic link")
    assert target.read_text() == "keep" and link.is_symlink()
    # with --force the link is written through: the link stays, its target gets the report
    assert runner.invoke(app, ["design", str(spec), "-o", str(link), "--force"]).exit_code == 0
    assert link.is_symlink() and json.loads(target.read_text())["verdict"] == "ok"


def test_output_fifo_and_directory(spec: Path, tmp_path: Path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    _refused(runner.invoke(app, ["design", str(spec), "-o", str(fifo)]), "not a regular file")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    d = tmp_path / "dir"
    d.mkdir()
    _refused(runner.invoke(app, ["design", str(spec), "-o", str(d)]), "is a directory")
    _refused(runner.invoke(app, ["design", str(spec), "-o", str(d), "--force"]), "directory")


@pytest.mark.parametrize("through_link", [False, True])
def test_plot_force_writes_into_a_fifo_and_keeps_it(
    spec: Path, tmp_path: Path, through_link: bool
) -> None:
    """``simulate --plot FIFO --force`` writes the PNG into the FIFO (a reader gets it) and
    leaves a FIFO: the plot writer made its own temp file and renamed it over the FIFO, or
    through a link over a device node (simulate trial, session 27). The link case is a FIFO
    too: a device node here would be the machine's own."""

    fifo = tmp_path / "f.png"
    os.mkfifo(fifo)
    target = fifo
    if through_link:
        target = tmp_path / "link.png"
        target.symlink_to(fifo)
    res, got = _invoke_reading(
        fifo, ["simulate", str(spec), "-q", "--plot", str(target), "--force"]
    )
    assert res.exit_code == 0, res.output
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert got.startswith(b"\x89PNG")


def test_output_dev_null_is_not_replaced(spec: Path):
    _refused(runner.invoke(app, ["design", str(spec), "-o", os.devnull]), "not a regular file")
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)
    res = runner.invoke(app, ["design", str(spec), "-o", os.devnull, "--force"])
    assert res.exit_code == 0 and stat.S_ISCHR(os.stat(os.devnull).st_mode)


def test_output_write_protected(spec: Path, tmp_path: Path):
    ro = tmp_path / "ro.json"
    ro.write_text("keep")
    ro.chmod(0o444)
    _refused(runner.invoke(app, ["design", str(spec), "-o", str(ro)]), "write-protected")
    assert ro.read_text() == "keep"


def test_plot_unknown_format_and_spec(spec: Path, tmp_path: Path):
    out = tmp_path / "r.json"
    _refused(
        runner.invoke(app, ["design", str(spec), "-o", str(out), "--plot", "x.txt"]),
        "plot format",
    )
    assert not out.exists()  # refused before anything is written
    _refused(runner.invoke(app, ["simulate", str(spec), "--plot", str(spec)]), "plot format")


def test_report_mode_follows_umask(spec: Path, tmp_path: Path):
    old = os.umask(0o022)
    try:
        out = tmp_path / "r.json"
        assert runner.invoke(app, ["design", str(spec), "-o", str(out)]).exit_code == 0
        assert stat.S_IMODE(out.stat().st_mode) == 0o644
    finally:
        os.umask(old)


def test_failed_design_replaces_stale_report(spec: Path, tmp_path: Path):
    out = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(spec), "-o", str(out)]).exit_code == 0
    # a gain that makes A − LC unstable: the design stops with exit 1
    bad = tmp_path / "bad.toml"
    bad.write_text(spec.read_text().replace("L = [-1.87, 1.874]", "L = [5, 5]"))
    res = runner.invoke(app, ["design", str(bad), "-o", str(out)])
    assert res.exit_code == 1
    d = json.loads(out.read_text())
    assert d["verdict"] == "error" and d["error"]["exit_code"] == 1
    ver = runner.invoke(app, ["verify", str(out), "--format", "json"])
    assert ver.exit_code == 1
    assert [c["id"] for c in json.loads(ver.output)["claims"]] == ["design-completed"]
    # failed claims (not an error): the verdict says failed
    slow = tmp_path / "slow.toml"
    slow.write_text(spec.read_text().replace("lambda = 0.955", "lambda = 0.9"))
    res = runner.invoke(app, ["design", str(slow), "-o", str(out)])
    assert res.exit_code in (1, 4)
    assert json.loads(out.read_text())["verdict"] in ("error", "failed", "inconclusive")


@pytest.mark.parametrize(
    ("exc", "code"),
    [("inconclusive", 4), ("overflow", 4), ("internal", 3)],
)
def test_error_while_certifying_replaces_stale_report(
    spec: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, exc: str, code: int
):
    """An error raised by the certify step (after the design returned) writes the error
    report too, never leaving an earlier run's report at -o (found by the spec fuzzer:
    search-space alpha = 1e-320 overflowed in certify, exit 4, and the old report stayed)."""
    from obsdesign import api
    from obsdesign.errors import InconclusiveError

    out = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(spec), "-o", str(out)]).exit_code == 0

    def boom(*a, **k):
        if exc == "inconclusive":
            raise InconclusiveError("certify could not decide")
        if exc == "overflow":
            raise OverflowError("integer division result too large for a float")
        raise RuntimeError("bug")

    monkeypatch.setattr(api, "certify", boom)
    res = runner.invoke(app, ["design", str(spec), "-o", str(out)])
    assert res.exit_code == code, res.output
    d = json.loads(out.read_text())
    assert d["verdict"] == "error" and d["error"]["exit_code"] == code
    monkeypatch.undo()
    assert runner.invoke(app, ["verify", str(out)]).exit_code == code


def test_overflow_in_certify_of_a_fuzzed_spec_writes_the_error_report(tmp_path: Path):
    """The fuzzer's case: search-space with a tiny alpha. 1e-320 (below the normal float
    range) is now refused as input, exit 2 naming the key; 1e-307 still overflows inside the
    computation, and the report says so."""
    text = (
        Path(__file__).resolve().parents[1] / "specs" / "hernandez-garcia-example.toml"
    ).read_text()
    assert "alpha = " in text
    import re

    bad = tmp_path / "s.toml"
    bad.write_text(re.sub(r"(?m)^alpha = .*$", "alpha = 1e-320", text))
    out = tmp_path / "r.json"
    _refused(runner.invoke(app, ["design", str(bad), "-o", str(out)]), "[method.alpha]", "below")
    assert not out.exists()
    bad.write_text(re.sub(r"(?m)^alpha = .*$", "alpha = 1e-307", text))
    res = runner.invoke(app, ["design", str(bad), "-o", str(out)])
    assert res.exit_code == 4, res.output
    assert json.loads(out.read_text())["verdict"] == "error"
    assert runner.invoke(app, ["verify", str(out)]).exit_code == 4


def test_bad_input_leaves_output_untouched(spec: Path, tmp_path: Path):
    out = tmp_path / "r.json"
    out.write_text("old")
    bad = tmp_path / "bad.toml"
    bad.write_text(spec.read_text().replace('key = "lyapunov"', 'key = "lyapunovv"'))
    res = runner.invoke(app, ["design", str(bad), "-o", str(out)])
    assert res.exit_code == 2 and out.read_text() == "old"


@pytest.mark.parametrize("err", [errno.EROFS, errno.EPERM, errno.ENOSPC])
def test_os_errors_on_output_are_exit_2(spec: Path, tmp_path: Path, monkeypatch, err: int):
    out = tmp_path / "r.json"

    def boom(src, dst):
        raise OSError(err, os.strerror(err))

    monkeypatch.setattr(os, "replace", boom)
    res = runner.invoke(app, ["design", str(spec), "-o", str(out)])
    _refused(res, str(out), os.strerror(err))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]  # no temp file left
    res = runner.invoke(app, ["simulate", str(spec), "--plot", str(tmp_path / "p.png")])
    assert res.exit_code == 2 and os.strerror(err) in res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_output_in_missing_folder_under_a_file(spec: Path, tmp_path: Path):
    _refused(
        runner.invoke(app, ["design", str(spec), "-o", str(spec / "r.json")]),
        "Not a directory",
    )


def test_broken_pipe_is_quiet(tmp_path: Path):
    exe = Path(sys.executable).parent / "obsdesign"
    r = subprocess.run(
        f"'{exe}' schema | head -c 10; exit ${{PIPESTATUS[0]}}",
        shell=True,
        executable="/bin/bash",
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.stdout == '{\n  "$sche'[:10] or len(r.stdout) == 10
    assert r.stderr == "" and r.returncode in (0, 141)


@pytest.mark.parametrize("delay", [0.5, 1.5])
def test_ctrl_c_is_one_line_no_traceback(delay: float):
    import signal
    import time

    exe = Path(sys.executable).parent / "obsdesign"
    specs = Path(__file__).resolve().parents[1] / "specs"

    def as_from_a_terminal() -> None:
        # the child starts as from an interactive shell, whatever the test runner inherited
        # (a runner started in the background without job control ignores SIGINT)
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})

    p = subprocess.Popen(
        [str(exe), "check", str(specs)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=as_from_a_terminal,  # noqa: PLW1509 - no threads here
    )
    time.sleep(delay)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert err.strip().splitlines()[-1].endswith("interrupted")


@pytest.mark.parametrize(
    ("delay", "background", "sig"),
    [
        (0.5, False, "SIGTERM"),
        (1.5, False, "SIGTERM"),
        (3.0, False, "SIGTERM"),
        (1.5, True, "SIGTERM"),
        (1.5, False, "SIGHUP"),
        (1.5, False, "SIGQUIT"),
        (1.5, False, "SIGUSR1"),
        (1.5, True, "SIGALRM"),
    ],
)
def test_sigterm_cleans_up_like_ctrl_c(
    spec: Path, tmp_path: Path, delay: float, background: bool, sig: str
) -> None:
    """SIGTERM (what ``timeout`` sends) during ``simulate --csv`` killed the process at once
    and left a hidden half-written ``.out.csv.XXXX.csv`` beside the output (simulate trial,
    session 27). It is handled as Ctrl-C is now: cleanup runs, one line "terminated", exit
    143 (128 + 15); the file is there whole or not at all. ``background``: started with
    SIGINT ignored, as a script's background job is (the handler was installed only with
    SIGINT's: re-check trial, session 27). SIGHUP (a closed terminal) and SIGQUIT (Ctrl-\\)
    left the temp file (CLI hostile-input trial, session 34): "hung up" 129, "quit" 131; so did
    SIGUSR1 / SIGALRM (session 38): "user signal 1" 138, "alarm clock" 142."""
    import signal
    import time

    exe = Path(sys.executable).parent / "obsdesign"
    spec.write_text(spec.read_text().replace("horizon = 300", "horizon = 400000"))
    out = tmp_path / "out.csv"

    def as_a_background_job() -> None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    p = subprocess.Popen(
        [str(exe), "simulate", str(spec), "-q", "--csv", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=as_a_background_job if background else None,  # noqa: PLW1509
    )
    time.sleep(delay)
    num = int(getattr(signal, sig))
    p.send_signal(num)
    _, err = p.communicate(timeout=120)
    assert "Traceback" not in err
    assert p.returncode in (0, 128 + num), err
    if p.returncode == 128 + num:
        word = {
            "SIGTERM": "terminated",
            "SIGHUP": "hung up",
            "SIGQUIT": "quit",
            "SIGUSR1": "user signal 1",
            "SIGALRM": "alarm clock",
        }[sig]
        assert err.strip().splitlines()[-1].endswith(word)
        assert not out.exists()
    else:
        assert out.read_text().count("\n") == 400001 + 1  # the header and every step
    assert not [f.name for f in tmp_path.iterdir() if f.name.startswith(".")]


def test_simulate_refuses_an_error_report(spec: Path, tmp_path: Path):
    bad = tmp_path / "bad.toml"
    bad.write_text(spec.read_text().replace("L = [-1.87, 1.874]", "L = [5, 5]"))
    out = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(bad), "-o", str(out)]).exit_code == 1
    res = runner.invoke(app, ["simulate", str(bad), "--report", str(out)])
    _refused(res, "stopped with an error")
    assert f"{out}: records a design that stopped" in res.output  # names the report file


#: a shipped spec per method and a parameter its simulation reads
SIM_PARAMS = [
    ("constrained-redesign-sec5-lyapunov", "L"),
    ("astolfi-stubborn-example1", "K"),
    ("dorea-pimenta-7-1", "G"),
    ("hernandez-garcia-example", "L_h"),
    ("schaum-impulsive-example", "T_max"),
]


def _simulate_edited(tmp_path: Path, name: str, key: str, edit: Any) -> Any:
    """Design the shipped spec ``name``, apply ``edit(parameters)`` to its report with the
    exact value of ``key`` removed, and simulate the spec with that report."""
    src = SPEC.parent / f"{name}.toml"
    rep = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(src), "-q", "-o", str(rep)]).exit_code == 0
    d = json.loads(rep.read_text())
    d["parameters"]["exact"].pop(key, None)
    edit(d["parameters"])
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    return runner.invoke(app, ["simulate", str(src), "-q", "--report", str(bad)])


@pytest.mark.parametrize(("name", "key"), SIM_PARAMS)
def test_simulate_a_report_missing_a_parameter_is_bad_input(
    tmp_path: Path, name: str, key: str
) -> None:
    """A report without a parameter the simulation reads, or with one of the wrong shape:
    exit 2 naming the report and the key, not exit 3 "internal failure: KeyError" (simulate
    trial, session 27)."""
    res = _simulate_edited(tmp_path, name, key, lambda p: p.pop(key))
    _refused(res, "bad.json", f"has no parameter '{key}'")


def test_simulate_a_report_with_a_parameter_of_the_wrong_shape_is_bad_input(
    spec: Path, tmp_path: Path
) -> None:
    rep = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(spec), "-q", "-o", str(rep)]).exit_code == 0
    d = json.loads(rep.read_text())
    d["parameters"]["L"] = [[-1.87], [1.874], [3.0]]
    d["parameters"]["exact"]["L"] = [["-187/100"], ["937/500"], ["3"]]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    res = runner.invoke(app, ["simulate", str(spec), "-q", "--report", str(bad)])
    _refused(res, "bad.json", "parameters.L has shape 3×1, expected 2×1")


@pytest.mark.parametrize(("name", "key"), SIM_PARAMS)
def test_simulate_names_the_report_parameter_of_the_wrong_shape(
    tmp_path: Path, name: str, key: str
) -> None:
    """Every method: a parameter of the wrong shape (a 5 × 3 array, float only) is listed with
    its shape among those read before the failure; numpy's "cannot reshape array of size 15"
    named none (session 27's note, fixed in session 28)."""
    res = _simulate_edited(tmp_path, name, key, lambda p: p.__setitem__(key, [[1.0, 2.0, 3.0]] * 5))
    err = res.output
    if "has shape" in err:  # a gain the simulation reads with its shape (Parameters.shaped)
        _refused(res, "bad.json", f"parameters.{key} has shape 5×3, expected")
    else:
        # "for the impulsive simulation", not "for a impulsive simulation" (session 35)
        _refused(res, "bad.json", "wrong shape or kind", f"{key} (5×3 array)", "for the ")


def test_simulate_says_when_a_report_does_not_hold(spec: Path, tmp_path: Path) -> None:
    """A report whose own claims fail is simulated with a note saying so (it ran with exit 0
    and no word: simulate trial, session 27)."""
    rep = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(spec), "-q", "-o", str(rep)]).exit_code == 0
    d = json.loads(rep.read_text())
    d["claims"][0]["status"] = "failed"
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    from obsdesign import api

    res = api.simulate(spec, bad)
    assert any("verdict 'failed'" in w for w in res.info["warnings"])
    assert "warnings" not in api.simulate(spec, rep).info


def test_simulate_without_a_report_says_when_its_design_does_not_certify(tmp_path: Path) -> None:
    """simulate SPEC of a design whose claim fails (design exit 1: linear-plant, the plant is
    given by f) warns as simulate --report does (exit 0 and no word: rendering trial, session
    29); a design that certifies gives no such warning."""
    from obsdesign import api

    text = """[system]
time = "discrete"
states = ["x1", "x2"]
A = [[0, 1], [1, 0]]
C = [[1, 0]]
f = ["x2", "x1 + 0.01*sin(x1)"]
[method]
key = "lyapunov"
L = [-1.87, 1.874]
lambda = 0.955
[simulate]
horizon = 5
x0 = [-1, -1]
xhat0 = [1, 1]
"""
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    res = api.simulate(bad)
    assert any(
        "verdict 'failed' (linear-plant)" in w and "not certified" in w
        for w in res.info["warnings"]
    )
    good = tmp_path / "good.toml"
    good.write_text(text.replace('f = ["x2", "x1 + 0.01*sin(x1)"]\n', ""))
    assert "warnings" not in api.simulate(good).info


def test_a_plot_of_values_near_the_float_limit_is_exit_4_and_writes_nothing(
    spec: Path, tmp_path: Path
) -> None:
    """x0 = xhat0 = ±1.7e308 (every value finite): matplotlib's tick locator fails, which was
    exit 3 "internal failure: arange" (simulate trial, session 27). Now exit 4 saying so, and
    no file (nor temp file) is left; 1e300 still plots."""
    text = spec.read_text().replace("x0 = [-1, -1]", "x0 = [1.7e308, -1.7e308]")
    text = text.replace("xhat0 = [1, 1]", "xhat0 = [1.7e308, -1.7e308]")
    assert "1.7e308" in text
    src = tmp_path / "huge.toml"
    src.write_text(text)
    out = tmp_path / "p.png"
    res = runner.invoke(app, ["simulate", str(src), "-q", "--plot", str(out)])
    assert res.exit_code == 4, res.output
    assert "cannot draw values as large as 1.7e+308" in res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["huge.toml", "s.toml"]
    src.write_text(text.replace("1.7e308", "1e300"))
    assert runner.invoke(app, ["simulate", str(src), "-q", "--plot", str(out)]).exit_code == 0


def test_a_spec_on_stdin_is_not_overwritten(spec: Path):
    """``design - -o s.toml < s.toml`` replaced the spec with the report (CLI fuzzer): stdin
    that is a regular file counts as the input file."""
    exe = Path(sys.executable).parent / "obsdesign"
    before = spec.read_bytes()
    with open(spec, "rb") as f:
        r = subprocess.run(
            [str(exe), "design", "-", "-o", str(spec)], stdin=f, capture_output=True, text=True
        )
    assert r.returncode == 2 and "input file itself" in r.stderr, r.stderr
    assert spec.read_bytes() == before


def test_one_file_named_for_two_outputs(spec: Path, tmp_path: Path):
    """``design -o X --plot X`` kept the plot and said "report written" (CLI fuzzer): refused,
    whether X exists or not, with or without --force; likewise sweep -o / --plot."""
    out = tmp_path / "x.svg"
    for extra in ([], ["--force"]):
        _refused(
            runner.invoke(app, ["design", str(spec), "-o", str(out), "--plot", str(out), *extra]),
            "two outputs",
        )
        out.write_text("keep")
    assert out.read_text() == "keep"
    res = runner.invoke(
        app,
        ["sweep", str(spec), "--set", "method.margin=1e-9", "-o", str(tmp_path / "t.csv"),
         "--plot", str(tmp_path / "." / "t.csv"), "--y", "exit_code"],
    )  # fmt: skip
    _refused(res, "two outputs")


def test_junit_over_a_spec_inside_a_checked_folder(spec: Path):
    """``check DIR --junit DIR/s.toml`` replaced the spec with the JUnit XML (the guard knew
    only the paths named): every spec the folders hold is an input."""
    before = spec.read_bytes()
    _refused(runner.invoke(app, ["check", str(spec.parent), "--junit", str(spec)]), "itself")
    assert spec.read_bytes() == before


def test_an_existing_toml_file_is_never_an_output(spec: Path, tmp_path: Path):
    """No output is TOML, so an existing .toml is somebody's spec: refused for -o, --csv and
    check --junit (a .toml in a hidden folder, which check skips, was replaced by the JUnit XML:
    session 26), byte-for-byte intact; design -o --force still replaces it. A new .toml name
    is refused too, without --force: the report written there made the next run refuse it and
    every later check read it as a bad spec (docs trial, session 31)."""
    hidden = tmp_path / ".old"
    hidden.mkdir()
    other = hidden / "other.toml"
    shutil.copy(SPEC, other)
    before = other.read_bytes()
    for args in (
        ["check", str(tmp_path), "--junit", str(other)],
        ["design", str(spec), "-o", str(other)],
        ["simulate", str(spec), "--csv", str(other)],
    ):
        _refused(runner.invoke(app, args), str(other), "is a spec file (.toml)")
        assert other.read_bytes() == before
    res = runner.invoke(app, ["design", str(spec), "-q", "-o", str(other), "--force"])
    assert res.exit_code == 0 and json.loads(other.read_text())["verdict"] == "ok"
    new = tmp_path / "new.toml"
    for args in (
        ["check", str(spec), "--junit", str(new)],
        ["design", str(spec), "-o", str(new)],
        ["simulate", str(spec), "--csv", str(new)],
    ):
        _refused(runner.invoke(app, args), str(new), "a .toml name is read as a spec")
        assert not new.exists()
    assert runner.invoke(app, ["design", str(spec), "-q", "-o", str(new), "--force"]).exit_code == 0


def test_an_output_folder_that_takes_no_file_is_refused_before_the_work(
    spec: Path, tmp_path: Path, monkeypatch
):
    """``sweep -o /sys/s.csv`` and ``check --junit /sys/j.xml`` ran every point, then lost all
    rows on the write (CLI fuzzer): the folder is tried first (an empty probe file, removed)."""
    from obsdesign.report import model

    ran = []
    monkeypatch.setattr("obsdesign.api.check", lambda *a, **k: ran.append(1) or [])

    def no(*a, **k):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    monkeypatch.setattr(model.tempfile, "mkstemp", no)
    res = runner.invoke(app, ["check", str(spec), "--junit", str(tmp_path / "j.xml")])
    _refused(res, "cannot write in", os.strerror(errno.EROFS))
    assert not ran
    monkeypatch.undo()
    res = runner.invoke(app, ["check", str(spec), "--junit", str(tmp_path / "j.xml")])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["j.xml", "s.toml"]  # probe removed


def test_lone_surrogate_escapes_and_a_closed_stdin_are_bad_input(spec: Path, tmp_path: Path):
    """A report whose JSON holds "\\ud800" (valid JSON, but no UTF-8 output can print it)
    ended in UnicodeEncodeError, exit 3, and ``design - <&-`` in AttributeError (CLI
    fuzzer): both are one-line exit 2. A valid surrogate pair (an emoji) verifies."""
    out = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(spec), "-o", str(out)]).exit_code == 0
    d = json.loads(out.read_text())
    for note, code in (("\\ud800", 2), ("\\ud83d\\ude00", 0)):
        text = json.dumps({**d, "notes": [*d["notes"], "NOTE"]}).replace("NOTE", note)
        bad = tmp_path / "b.json"
        bad.write_text(text)
        res = runner.invoke(app, ["verify", str(bad)])
        if code == 2:
            _refused(res, "not valid Unicode")
        else:
            assert res.exit_code == 0, res.output
    exe = Path(sys.executable).parent / "obsdesign"
    r = subprocess.run(
        f"'{exe}' design - <&-", shell=True, executable="/bin/bash", capture_output=True,
        text=True, timeout=60,
    )  # fmt: skip
    assert r.returncode == 2 and "standard input is closed" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_the_api_never_writes_a_report_over_a_loaded_specs_file(tmp_path: Path) -> None:
    """``design(load_spec("s.toml"), out="s.toml")`` replaced the spec with the report
    (outsider trial, session 22): only a spec given as a path was protected. A loaded spec's
    own file is now an input too (exit 2, the spec untouched); a spec from text whose name is
    no file still writes to that name."""
    from obsdesign import api
    from obsdesign.errors import InputError

    src = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    spec = tmp_path / "s.toml"
    spec.write_bytes(src.read_bytes())
    with pytest.raises(InputError, match="is the input file itself") as e:
        api.design(api.load_spec(spec), out=spec)
    assert e.value.exit_code == 2 and spec.read_bytes() == src.read_bytes()
    out = tmp_path / "virtual.json"  # (a new .toml name is refused: session 31)
    api.design(api.load_spec_text(src.read_text(encoding="utf-8"), str(out)), out=out)
    assert out.read_text(encoding="utf-8").lstrip().startswith("{")


@pytest.mark.parametrize(("name", "key"), SIM_PARAMS)
@pytest.mark.parametrize("bad_value", [math.inf, math.nan])
def test_simulate_refuses_a_report_parameter_that_is_not_finite(
    tmp_path: Path, name: str, key: str, bad_value: float
) -> None:
    """A report parameter with a non-finite number (exact value removed) was simulated with
    exit 0 and nan metrics (session 27's note); now exit 2 naming the key."""

    def edit(p: dict) -> None:
        v = p[key]
        if isinstance(v, list):
            row = v[0] if isinstance(v[0], list) else v
            row[0] = bad_value
        else:
            p[key] = bad_value

    res = _simulate_edited(tmp_path, name, key, edit)
    _refused(res, "bad.json", f"parameters.{key}", "not a finite number")


def _edit_consistently(d: dict, key: str, value: Any) -> None:
    """Set parameter ``key`` of report dict ``d`` to ``value`` in floats and exactly alike
    (the nearest doubles of the exact values), claims left as they were."""
    from fractions import Fraction

    def exact(v: Any) -> Any:
        return [exact(x) for x in v] if isinstance(v, list) else str(Fraction(v))

    d["parameters"][key] = value
    d["parameters"]["exact"][key] = exact(value)


@pytest.mark.parametrize(
    ("name", "key", "value", "failed"),
    [
        ("constrained-redesign-sec5-lyapunov", "L", [[1.0], [5.0]], "L-matches-spec"),
        ("schaum-impulsive-example", "T_min", 4.0, "T_max"),
        ("astolfi-stubborn-example1", "K", None, "lmi-global"),
    ],
)
def test_simulate_a_report_edited_consistently_warns(
    tmp_path: Path, name: str, key: str, value: Any, failed: str
) -> None:
    """A report whose parameters were edited consistently (float and exact), its claims left
    "certified": simulate recomputes the claims from the spec and warns that the parameters
    are not certified, naming the failed claims. It ran L = [1, 5] against a spec that fixes
    L (final |e| = 4·10⁹⁰), an impulsive window [4, 5] with "intervals_in_window: True" and a
    destabilizing K, each with exit 0 and no word (verify tamper trial, session 39)."""
    src = SPEC.parent / f"{name}.toml"
    rep = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(src), "-q", "-o", str(rep)]).exit_code == 0
    ok = runner.invoke(app, ["simulate", str(src), "--report", str(rep)])
    assert ok.exit_code == 0 and "not certified" not in ok.output
    d = json.loads(rep.read_text())
    if key == "T_min":
        _edit_consistently(d, "T_max", 5.0)
    elif key == "K":
        value = [[-100.0 for _ in row] for row in d["parameters"]["K"]]  # its shape
    _edit_consistently(d, key, value)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    res = runner.invoke(app, ["simulate", str(src), "--report", str(bad)])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert f"{bad}: its parameters' claims, recomputed from the spec, give the verdict" in text
    assert failed in text and "not certified (obsdesign verify" in text


# --- Mutation review 29: api._uncertified_design


def _claim(cid: str, status: str, float_ok: bool):
    from obsdesign.certify.claim import Claim, ClaimStatus

    return Claim(cid, "s", "r", "c", "0", ClaimStatus(status), "d", float_ok)


@pytest.mark.parametrize(
    ("claims", "want"),
    [
        ([("a", "certified", True)], None),
        ([("a", "failed", True)], "the design's claims give the verdict 'inconclusive' (a)"),
        ([("a", "failed", True), ("b", "failed", False)], "verdict 'failed' (a, b)"),
        ([("a", "certified", True), ("b", "failed", False)], "verdict 'failed' (b)"),
        ([(f"c{i}", "failed", False) for i in range(5)], "(c0, c1, c2, c3, c4)"),
        ([(f"c{i}", "failed", False) for i in range(6)], "(c0, c1, c2, c3, c4, …)"),
    ],
)
def test_uncertified_design_names_its_verdict_and_claims(monkeypatch, claims, want) -> None:
    """The warning simulate SPEC gives: nothing when every claim holds; 'inconclusive' only
    when EVERY failed claim holds in floats, else 'failed'; at most five ids, "…" after
    (mutation review 29: any() for all(), a verdict always 'failed', one id, "…" at five:
    each passed every test, which had one failed claim only)."""
    from obsdesign import api

    sp = api.load_spec_text(api.template("lyapunov"), "s.toml")
    monkeypatch.setattr(api, "certify", lambda sp, p: [_claim(*c) for c in claims])
    notes = api._uncertified_design(sp, api.Parameters())
    if want is None:
        assert notes == []
    else:
        (note,) = notes
        assert want in note and note.startswith("s.toml: ") and "not certified" in note
        if "…" not in want:
            assert "…" not in note


@pytest.mark.parametrize("exc", [OverflowError("x"), None])
def test_uncertified_design_says_when_certify_stops(monkeypatch, exc) -> None:
    """A certification that stops with an error (here an InconclusiveError, and an
    OverflowError that captured_warnings makes one) is said so, and the simulation still
    runs (mutation review 29: returning [] there, or certify outside captured_warnings,
    passed every test)."""
    from obsdesign import api
    from obsdesign.errors import InconclusiveError

    def boom(sp, p):
        raise exc if exc is not None else InconclusiveError("no proof here")

    sp = api.load_spec_text(api.template("lyapunov"), "s.toml")
    monkeypatch.setattr(api, "certify", boom)
    (note,) = api._uncertified_design(sp, api.Parameters())
    assert note.startswith("s.toml: the designed parameters could not be certified (")
    assert "not certified" in note


def test_bad_input_inside_a_design_leaves_the_output_untouched(
    spec: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Bad input (exit 2) raised inside the design writes no error report: -o keeps what it
    held, as api.design documents (mutation review 29: writing the report for every error
    code passed every test; only exit 1, 3 and 4 were tried)."""
    from obsdesign import api
    from obsdesign.errors import InputError

    out = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(spec), "-o", str(out)]).exit_code == 0
    before = out.read_bytes()

    def boom(*a, **k):
        raise InputError("[method.L] not the shape of C (test)")

    monkeypatch.setattr(api, "certify", boom)
    res = runner.invoke(app, ["design", str(spec), "-o", str(out), "--format", "json"])
    assert res.exit_code == 2 and res.stdout == ""
    assert out.read_bytes() == before


def test_parquet_into_a_fifo_keeps_the_fifo_and_arrives_whole(spec: Path, tmp_path: Path):
    """``sweep -o X.parquet --force`` into a FIFO: pyarrow's writer removes its target path on
    any error (a FIFO cannot seek), and deleted the FIFO — through a link, a device node
    such as /dev/full (output trial, session 30). The writer now works on a temp file whose
    bytes are copied in: the reader gets the whole Parquet file, and the FIFO stays."""

    pytest.importorskip("pyarrow")
    fifo = tmp_path / "o.parquet"
    os.mkfifo(fifo)
    args = ["sweep", str(spec), "--set", "method.lambda=[0.96, 0.97]", "-q", "-o", str(fifo)]
    res, got = _invoke_reading(fifo, [*args, "--force"])
    assert res.exit_code == 0, res.output
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert got.startswith(b"PAR1") and got.endswith(b"PAR1")


@pytest.mark.parametrize("suffix", [".csv", ".json"])
def test_a_name_of_nearly_255_bytes_is_written_or_refused_before_the_work(
    spec: Path, tmp_path: Path, suffix: str
) -> None:
    """A 241–255-byte output name passed the check before the work (a short probe name) and
    failed after it: the temp file ".NAME.XXXXXXXX.csv" passed 255 bytes (output trial,
    session 30). The temp name is cut to fit: the file is written under its full name."""
    name = "b" * (255 - len(suffix)) + suffix
    out = tmp_path / name
    if suffix == ".csv":
        args = ["sweep", str(spec), "--set", "method.lambda=[0.96, 0.97]", "-q", "-o", str(out)]
    else:
        args = ["design", str(spec), "-q", "-o", str(out)]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    assert out.is_file() and out.stat().st_size > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["s.toml", name])


def test_force_through_a_dangling_link_creates_no_folders(spec: Path, tmp_path: Path) -> None:
    """``-o link --force``, the link pointing into a missing folder tree, created every
    missing folder (the plain path is refused: output trial, session 30); it is refused
    before the work, and nothing is created."""
    link = tmp_path / "link.json"
    link.symlink_to(tmp_path / "no" / "such" / "x.json")
    res = runner.invoke(app, ["design", str(spec), "-q", "-o", str(link), "--force"])
    _refused(res, "does not exist")
    assert not (tmp_path / "no").exists()


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize(
    "args",
    [
        ["schema"],
        ["init", "lyapunov"],
        ["methods"],
        # a command's text output: the line was printed twice when buffered (re-check 46)
        ["design", str(Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml")],
    ],
)
def test_a_full_disk_on_stdout_is_exit_2(args: list[str]) -> None:
    """``obsdesign schema > /dev/full`` (no space left) was exit 3 "internal failure:
    OSError" (output trial, session 30): an OS error writing stdout is bad output, exit 2
    with one line, as for any output file; a closed pipe stays exit 141."""
    _assert_full_stdout_is_exit_2(args)


def test_an_eps_plot_prints_nothing_on_stderr(spec: Path, tmp_path: Path) -> None:
    """``simulate --plot o.eps -q`` printed matplotlib's "The PostScript backend does not
    support transparency" on stderr (its logger, not a warning; output trial, session 30)."""
    p = subprocess.run(
        [
            sys.executable,
            "-m",
            "obsdesign",
            "simulate",
            str(spec),
            "-q",
            "--plot",
            str(tmp_path / "o.eps"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 0 and p.stderr == "", p.stderr
    assert (tmp_path / "o.eps").read_bytes().startswith(b"%!PS")


def test_temp_names_keep_whole_characters_and_the_given_suffix(tmp_path: Path) -> None:
    """The temp name was cut in bytes through a UTF-8 character (a 255-byte 'é…x.parquet'
    ended exit 3 from pyarrow after the sweep), kept a suffix over 244 bytes (a legal name
    refused "File name too long"), and, through a link to a suffix-less FIFO, took the
    target's suffix (a plot "Format 'tmp' is not supported", exit 3; re-check trial, session
    30). The temp name is whole UTF-8 within 255 bytes with the suffix of the name given."""
    from obsdesign.report.model import NAME_MAX, _temp_file

    for name in ("é" * 123 + "x.parquet", "é" * 119 + "xy.parquet", "r." + "x" * 253):
        p = tmp_path / name
        assert len(os.fsencode(p.name)) <= NAME_MAX
        fd, tmp = _temp_file(p)
        os.close(fd)
        t = os.fsencode(Path(tmp).name)
        assert len(t) <= NAME_MAX and t.decode("utf-8")  # whole characters
        assert Path(tmp).suffix == (p.suffix if len(p.suffix) <= 32 else ".tmp")
        os.unlink(tmp)
    fd, tmp = _temp_file(tmp_path / "fifo", ".svg")
    os.close(fd)
    assert tmp.endswith(".svg")
    os.unlink(tmp)


def test_plot_through_a_link_to_a_suffixless_fifo(spec: Path, tmp_path: Path) -> None:
    """``--plot p.svg --force`` where p.svg links to a FIFO named without a suffix: the
    format is the name given's (svg), as before session 30's temp copy."""

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    link = tmp_path / "p.svg"
    link.symlink_to(fifo)
    res, got = _invoke_reading(fifo, ["simulate", str(spec), "-q", "--plot", str(link), "--force"])
    assert res.exit_code == 0, res.output
    assert b"<svg" in got[:500]


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize("args", [["--help"], ["--version"], ["design", "--help"]])
def test_help_and_version_to_a_full_stdout_are_exit_2(args: list[str]) -> None:
    """click's own output to a full stdout was a traceback and exit 1 (re-check trial,
    session 30)."""
    _assert_full_stdout_is_exit_2(args)


def test_a_closed_stdout_drops_the_output_and_keeps_the_exit_code(spec: Path, tmp_path: Path):
    """With stdout closed (``>&-``) every print raised AttributeError: exit 3, or a traceback
    and exit 1 after the report was written (re-check trial, session 30). What goes to stdout
    is dropped; files are written and the exit code is the command's."""
    out = tmp_path / "r.json"
    for args, code in ((["schema"], 0), (["design", str(spec), "-q", "-o", str(out)], 0)):
        p = subprocess.run(
            [sys.executable, "-m", "obsdesign", *args],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
            preexec_fn=lambda: os.close(1),
        )
        assert p.returncode == code and p.stderr == "", (args, p.stderr)
    assert json.loads(out.read_text())["verdict"] == "ok"


def _assert_full_stdout_is_exit_2(args: list[str]) -> None:
    """``obsdesign ARGS > /dev/full`` ends with exit 2 and the one line "stdout: cannot
    write (No space left on device)" — with stdout buffered as on a fresh machine, and
    unbuffered (PYTHONUNBUFFERED, set where this suite was first run: the buffered case was
    exit 120 with "Exception ignored … OSError" at Python's own flush; fresh-Debian review
    46)."""
    base = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    for env in (base, {**base, "PYTHONUNBUFFERED": "1"}):
        with open("/dev/full", "w") as full:
            p = subprocess.run(
                [sys.executable, "-m", "obsdesign", *args],
                stdout=full,
                stderr=subprocess.PIPE,
                text=True,
                timeout=120,
                env=env,
            )
        said = "obsdesign: error: stdout: cannot write (No space left on device)"
        assert p.returncode == 2 and p.stderr.strip() == said, (env.get("PYTHONUNBUFFERED"), p)


def _invoke_reading(fifo: Path, args: list[str]) -> tuple[Any, bytes]:
    """Run ``obsdesign ARGS`` (CliRunner) while a thread reads the FIFO to its end: the
    result and the bytes read (b"" when nothing arrived within 30 s)."""
    import threading

    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    res = runner.invoke(app, args)
    reader.join(timeout=30)
    return res, (got[0] if got else b"")


@pytest.mark.parametrize("command", ["design", "verify"])
def test_a_closed_pipe_under_the_text_tables_is_exit_141(
    spec: Path, tmp_path: Path, command: str
) -> None:
    """``verify r.json | head -1`` of a good report exited 1 (the code of a failed claim)
    with nothing on stderr: rich's console handles a broken pipe itself with SystemExit(1)
    (soundness trial, session 34). The reader here has gone before anything is written."""
    rep = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(spec), "-q", "-o", str(rep)]).exit_code == 0
    arg = str(spec) if command == "design" else str(rep)
    p = subprocess.Popen(
        [sys.executable, "-m", "obsdesign", command, arg],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert p.stdout is not None and p.stderr is not None
    p.stdout.close()
    err = p.stderr.read()
    assert p.wait(timeout=120) == 141 and err == b"", err


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize("redirect", ["2>/dev/full", "2>&-"])
def test_a_stderr_that_cannot_take_the_error_line_keeps_the_exit_code(
    spec: Path, tmp_path: Path, redirect: str
) -> None:
    """With stderr closed or full every command exited 1 (the error line's write raised
    inside the error handler): bad input 2 → 1, an ok design 0 → 1 (CLI hostile-input
    trial, session 34). The line is dropped; the code is the command's."""
    exe = Path(sys.executable).parent / "obsdesign"
    bad = tmp_path / "bad.toml"
    bad.write_text(spec.read_text().replace("[system]", "[system]\nbogus_key = 1", 1))
    out = tmp_path / "r.json"
    for args, code in (([str(bad)], 2), ([str(spec), "-q", "-o", str(out)], 0)):
        r = subprocess.run(
            f"'{exe}' design {' '.join(args)} {redirect}",
            shell=True,
            executable="/bin/bash",
            capture_output=True,
            timeout=120,
        )
        assert r.returncode == code, (args, r.returncode)
    assert json.loads(out.read_text())["verdict"] == "ok"


def test_a_spec_file_name_that_is_not_utf8_is_written_with_escapes(tmp_path: Path) -> None:
    """A spec named with the byte 0xff reaches Python as a lone surrogate: ``design -o``
    ended with exit 3 "UnicodeEncodeError … surrogates not allowed" and no report, and the
    JSON of check and sweep held text no UTF-8 reader takes (session 40). The name is
    written with escapes (``a\\xff.toml``) in the report, the rows and the tables."""
    from typer.testing import CliRunner

    from obsdesign.cli import app

    src = SPEC.read_bytes()
    raw = os.fsencode(tmp_path) + b"/a\xff.toml"
    with open(raw, "wb") as f:
        f.write(src)
    spec = os.fsdecode(raw)
    run = CliRunner().invoke
    out = tmp_path / "r.json"
    res = run(app, ["design", spec, "-o", str(out), "-q"])
    assert res.exit_code == 0, res.output
    d = json.loads(out.read_bytes().decode("utf-8"))  # strict UTF-8
    assert d["spec_file"].endswith("a\\xff.toml")
    assert run(app, ["verify", str(out), "-q"]).exit_code == 0
    res = run(app, ["check", spec, "--format", "json"])
    assert res.exit_code == 0
    assert json.loads(res.stdout_bytes.decode("utf-8"))[0]["spec"].endswith("a\\xff.toml")
    for name in ("s.csv", "s.jsonl"):  # a row that fails names the file in its message
        res = run(app, ["sweep", spec, "--set", "method.nokey=1", "-o", str(tmp_path / name)])
        assert res.exit_code == 2, res.output
        assert "xff.toml[point 0]" in (tmp_path / name).read_bytes().decode("utf-8")


def test_force_never_overwrites_the_spec(spec: Path) -> None:
    """``design s.toml -o s.toml --force`` replaced the spec with its report; an input of the
    run is refused even with --force (the brief: never overwrite the spec; session 44)."""
    before = spec.read_bytes()
    res = runner.invoke(app, ["design", str(spec), "-o", str(spec), "--force"])
    _refused(res, "input file itself", "even with --force")
    assert spec.read_bytes() == before


def test_simulate_never_overwrites_the_sampling_file_it_reads(tmp_path: Path) -> None:
    """``simulate s.toml --csv samp.csv`` with ``[simulate] sampling_file = "samp.csv"`` (or
    ``--option sampling_file=samp.csv``) replaced the sampling intervals it had read with the
    trajectory, exit 0 (CLI review, session 44): refused, exit 2, the file kept."""
    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "schaum-impulsive-example.toml").read_text(encoding="utf-8")
    assert "\nseed = 1\n" in text
    spec = tmp_path / "s.toml"
    spec.write_text(text.replace("\nseed = 1\n", '\nseed = 1\nsampling_file = "samp.csv"\n'))
    samp = tmp_path / "samp.csv"
    samp.write_text("0.8\n" * 100)
    before = samp.read_bytes()
    for extra in ([], ["--force"], ["--option", f"sampling_file={samp}"]):
        res = runner.invoke(app, ["simulate", str(spec), "-q", "--csv", str(samp), *extra])
        _refused(res, "input file itself")
        assert samp.read_bytes() == before
    # sweep --simulate reads it at every point: -o onto it wrote the table over it (re-check
    # review, session 44), also when a --set names it
    plain = tmp_path / "plain.toml"
    plain.write_text(text)  # no sampling_file: a --set names it for every point
    for spec_, extra in ((spec, []), (plain, ["--set", 'simulate.sampling_file="samp.csv"'])):
        sweep = ["sweep", str(spec_), "--set", "method.alpha=3:3.1:2", "--simulate", "-q"]
        res = runner.invoke(app, [*sweep, "-o", str(samp), *extra])
        _refused(res, "input file itself")
        assert samp.read_bytes() == before
