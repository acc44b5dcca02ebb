"""Issue 11, every reported case in one table: the command, the exit code it must give and
words its output must contain. (Item 8, exact detectability, is tested with
obsdesign/certify/detect.py; Ctrl-C and warnings in test_reliability_output/check.)"""

from __future__ import annotations

import json
import math
import os
import stat
from collections.abc import Callable
from pathlib import Path

import pytest
from typer.testing import CliRunner

from obsdesign.cli import app
from obsdesign.limits import reset_limits

ROOT = Path(__file__).resolve().parents[1]
LYAP = (ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml").read_text()
IMP = (ROOT / "specs" / "impulsive-sector-3state.toml").read_text()
runner = CliRunner()


def _spec(tmp: Path, text: str = LYAP, name: str = "s.toml") -> Path:
    p = tmp / name
    p.write_text(text)
    return p


def _sub(text: str, old: str, new: str) -> str:
    assert old in text
    return text.replace(old, new, 1)


def _report(tmp: Path, edit: Callable[[dict], None]) -> Path:
    out = tmp / "r.json"
    assert runner.invoke(app, ["design", str(_spec(tmp)), "-o", str(out)]).exit_code == 0
    d = json.loads(out.read_text())
    edit(d)
    out.write_text(json.dumps(d))
    return out


def _matrix(n: int) -> str:
    return "[" + ",".join("[" + ",".join(["0.5"] * n) + "]" for _ in range(n)) + "]"


def _add_claim(d: dict) -> None:
    d["claims"].append({**d["claims"][0], "id": "x", "statement": "1 = 2"})


def _ulp(d: dict) -> None:
    d["parameters"]["lambda"] = math.nextafter(d["parameters"]["lambda"], 1.0)


# (item, case, argv builder (tmp) -> argv, exit code, words in the output)
CASES: list[tuple[str, str, Callable[[Path], list[str]], int, list[str]]] = [
    (
        "1",
        "-o is the spec",
        lambda t: ["design", str(_spec(t)), "-o", str(t / "s.toml")],
        2,
        ["input file itself"],
    ),
    (
        "1",
        "-o /dev/null",
        lambda t: ["design", str(_spec(t)), "-o", os.devnull],
        2,
        ["not a regular file"],
    ),
    (
        "1",
        "-o FIFO",
        lambda t: (os.mkfifo(t / "f"), ["design", str(_spec(t)), "-o", str(t / "f")])[1],
        2,
        ["not a regular file"],
    ),
    (
        "1",
        "-o symlink",
        lambda t: ((t / "l").symlink_to(t / "x"), ["design", str(_spec(t)), "-o", str(t / "l")])[1],
        2,
        ["symbolic link"],
    ),
    (
        "1",
        "-o write-protected",
        lambda t: (
            (t / "ro").write_text("k"),
            (t / "ro").chmod(0o444),
            ["design", str(_spec(t)), "-o", str(t / "ro")],
        )[2],
        2,
        ["write-protected"],
    ),
    (
        "2",
        "NaN ψ with on_violation = fail",
        lambda t: [
            "design",
            str(
                _spec(
                    t,
                    _sub(
                        IMP,
                        'psi = ["0.2*sin(x1)", "0.3*tanh(x2)", "0.3*tanh(x3)"]',
                        'psi = ["0*9**9**9", "0", "0"]',
                    ),
                )
            ),
        ],
        1,
        [],
    ),
    (
        "2",
        "x1**1e308",
        lambda t: ["design", str(_spec(t, _sub(IMP, '"0.2*sin(x1)"', '"x1**1e308"')))],
        1,
        [],
    ),
    (
        "3",
        "margin 1e-999999999",
        lambda t: ["design", str(_spec(t, _sub(LYAP, "lambda = 0.955", "lambda = 1e-999999999")))],
        2,
        ["method.lambda"],
    ),
    (
        "3",
        "A entry 1e-999999999",
        lambda t: [
            "design",
            str(_spec(t, _sub(LYAP, "A = [[0, 1], [1, 0]]", "A = [[0, 1], [1e-999999999, 0]]"))),
        ],
        2,
        ["system.A"],
    ),
    (
        "3",
        '"1e999999999" in a report',
        lambda t: [
            "verify",
            str(
                _report(t, lambda d: d["parameters"]["exact"].__setitem__("lambda", "1e999999999"))
            ),
        ],
        2,
        ["parameters.exact.lambda"],
    ),
    (
        "3",
        "5000-digit integer in A",
        lambda t: [
            "design",
            str(
                _spec(
                    t, _sub(LYAP, "A = [[0, 1], [1, 0]]", "A = [[0, 1], [" + "9" * 5000 + ", 0]]")
                )
            ),
        ],
        2,
        ["key A", "digits"],
    ),
    (
        "4",
        "check: [system.A] in a message",
        lambda t: ["check", str(_spec(t, _sub(LYAP, "A = [[0, 1], [1, 0]]", "A = [[0, 1]]")))],
        2,
        ["[system.A]"],
    ),
    (
        "5",
        "spec is a symlink to /dev/zero",
        lambda t: ((t / "z.toml").symlink_to("/dev/zero"), ["design", str(t / "z.toml")])[1],
        2,
        ["not a regular file"],
    ),
    (
        "5",
        "300×300 system",
        lambda t: [
            "design",
            str(_spec(t, _sub(LYAP, "A = [[0, 1], [1, 0]]", "A = " + _matrix(300)))),
        ],
        2,
        ["max_values"],
    ),
    (
        "5",
        "2000×2000 system",
        lambda t: [
            "design",
            str(_spec(t, _sub(LYAP, "A = [[0, 1], [1, 0]]", "A = " + _matrix(2000)))),
        ],
        2,
        ["max_values"],
    ),
    (
        "5",
        "simulate: huge horizon",
        lambda t: [
            "simulate",
            str(_spec(t, _sub(LYAP, "horizon = 300", "horizon = 100000000000"))),
        ],
        2,
        ["GiB"],
    ),
    (
        "5",
        "simulate --option runs=1e8",
        lambda t: ["simulate", str(_spec(t, IMP)), "--option", "runs=1e8"],
        2,
        ["runs"],
    ),
    (
        "6",
        "added claim 1 = 2",
        lambda t: ["verify", str(_report(t, _add_claim))],
        1,
        ["report-adds:x"],
    ),
    (
        "6",
        "removed claim",
        lambda t: ["verify", str(_report(t, lambda d: d["claims"].pop()))],
        1,
        ["report-omits:"],
    ),
    (
        "6",
        "all claims removed",
        lambda t: ["verify", str(_report(t, lambda d: d["claims"].clear()))],
        1,
        ["report-omits:"],
    ),
    (
        "6",
        "injected note",
        lambda t: ["verify", str(_report(t, lambda d: d["notes"].append("audited")))],
        0,
        ["not verified (from the report): audited"],
    ),
    (
        "6",
        "extra parameter",
        lambda t: ["verify", str(_report(t, lambda d: d["parameters"].__setitem__("gain", 2.0)))],
        0,
        ["not verified"],
    ),
    ("6", "float one ulp off", lambda t: ["verify", str(_report(t, _ulp))], 1, ["nearest double"]),
    (
        "7",
        "TOML nested 1000 levels",
        lambda t: ["design", str(_spec(t, LYAP + "\n[x]\ny = " + "[" * 1000 + "]" * 1000 + "\n"))],
        2,
        ["nested"],
    ),
    (
        "7",
        "3999-long unary minus chain",
        lambda t: [
            "design",
            str(
                _spec(
                    t,
                    _sub(LYAP, "C = [[1, 0]]", 'C = [[1, 0]]\npsi = ["' + "-" * 3999 + 'x1", "0"]'),
                )
            ),
        ],
        2,
        ["levels deep"],
    ),
    (
        "7",
        "2**2**… chain",
        lambda t: [
            "design",
            str(
                _spec(
                    t,
                    _sub(
                        LYAP,
                        "C = [[1, 0]]",
                        'C = [[1, 0]]\npsi = ["' + "**".join(["2"] * 1500) + '", "0"]',
                    ),
                )
            ),
        ],
        2,
        ["levels deep"],
    ),
    (
        "7",
        "directory as -o",
        lambda t: ["design", str(_spec(t)), "-o", str(t)],
        2,
        ["is a directory"],
    ),
    (
        "7",
        "--plot x.txt",
        lambda t: ["design", str(_spec(t)), "--plot", str(t / "x.txt")],
        2,
        ["plot format"],
    ),
]


@pytest.mark.parametrize("item,case,argv,code,words", CASES, ids=[f"{c[0]}: {c[1]}" for c in CASES])
def test_issue11_table(tmp_path: Path, item, case, argv, code, words):
    reset_limits()
    args = argv(tmp_path)
    res = runner.invoke(app, args, env={"COLUMNS": "300"})
    assert res.exit_code == code, f"{case}: {res.output[-1500:]}"
    assert "Traceback" not in res.output and "internal failure" not in res.output
    for w in words:
        assert w in res.output, f"{case}: {w!r} not in {res.output[-1500:]}"
    if code == 2 and args[0] == "design":
        assert res.output.strip().count("\n") == 0  # one line
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)
