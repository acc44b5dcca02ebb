"""Reliability benchmark (issue 11): the time to reject each oversized or hostile input,
target under 1 s each whatever the size. Measured in process (the API call that reads the
input, the median of 3), and for two inputs also through the CLI (cold start included).

Run alone with ``python benchmarks/bench_reliability.py`` or with ``make bench``."""

from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
TEXT = SPEC.read_text()


def _line(name: str, seconds: float, target: float = 1.0, cpu: float | None = None) -> None:
    ok = "ok" if seconds < target else "MISSED"
    extra = f"  (cpu {cpu * 1e3:.0f} ms; the rest is waiting on a loaded machine)" if cpu else ""
    print(f"{name:55s} {seconds * 1e3:11.1f} ms   target < {target:.0f} s   {ok}{extra}")


def _sub(old: str, new: str) -> str:
    assert old in TEXT
    return TEXT.replace(old, new, 1)


def _matrix(n: int) -> str:
    return "[" + ",".join("[" + ",".join(["0.5"] * n) + "]" for _ in range(n)) + "]"


def _rejects(fn: Callable[[], object]) -> float:
    """Median seconds for ``fn`` to raise an ObsdesignError with exit code 2."""
    from obsdesign.errors import ObsdesignError

    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        try:
            fn()
        except ObsdesignError as e:
            assert e.exit_code == 2, e.message
        else:
            raise AssertionError("input was accepted")
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    from obsdesign import api
    from obsdesign.limits import reset_limits

    reset_limits()
    api.design(SPEC)  # warm the imports
    with tempfile.TemporaryDirectory() as tmp_s:
        tmp = Path(tmp_s)

        def spec(name: str, text: str) -> Path:
            p = tmp / name
            p.write_text(text)
            return p

        cases: list[tuple[str, Path]] = [
            (
                "margin = 1e-999999999",
                spec("m.toml", _sub("lambda = 0.955", "lambda = 1e-999999999")),
            ),
            (
                "A entry 1e-999999999",
                spec("a.toml", _sub("A = [[0, 1], [1, 0]]", "A = [[0, 1e-999999999], [1, 0]]")),
            ),
            (
                "5000-digit integer in A",
                spec(
                    "i.toml", _sub("A = [[0, 1], [1, 0]]", "A = [[0, " + "9" * 5000 + "], [1, 0]]")
                ),
            ),
            (
                "TOML nested 1000 levels",
                spec("n.toml", TEXT + "\n[x]\ny = " + "[" * 1000 + "]" * 1000 + "\n"),
            ),
            (
                "3999-long unary minus chain",
                spec(
                    "u.toml",
                    _sub("C = [[1, 0]]", 'C = [[1, 0]]\npsi = ["' + "-" * 3999 + 'x1", "0"]'),
                ),
            ),
            (
                "2**2**… chain (3000 long)",
                spec(
                    "p.toml",
                    _sub(
                        "C = [[1, 0]]",
                        'C = [[1, 0]]\npsi = ["' + "**".join(["2"] * 3000) + '", "0"]',
                    ),
                ),
            ),
            (
                "150×150 system (state limit)",
                spec("b150.toml", _sub("A = [[0, 1], [1, 0]]", "A = " + _matrix(150))),
            ),
            (
                "300×300 system",
                spec("b300.toml", _sub("A = [[0, 1], [1, 0]]", "A = " + _matrix(300))),
            ),
            (
                "2000×2000 system (16 MB)",
                spec("b2000.toml", _sub("A = [[0, 1], [1, 0]]", "A = " + _matrix(2000))),
            ),
            ("17 MB spec (size limit)", spec("big.toml", TEXT + "\n#" + "x" * (17 * 2**20) + "\n")),
        ]
        zero = tmp / "zero.toml"
        zero.symlink_to("/dev/zero")
        cases.append(("a symlink to /dev/zero", zero))
        for name, path in cases:
            _line(f"spec: {name}", _rejects(lambda p=path: api.load_spec(p)))

        sim = spec("sim.toml", _sub("horizon = 300", "horizon = 100000000000"))
        _line("simulate: 1e11 steps (memory estimate)", _rejects(lambda: api.simulate(sim)))

        rep = api.design(SPEC)
        d = json.loads(rep.to_json())

        def report(name: str, edit: Callable[[dict], None] | None, raw: str | None = None) -> Path:
            p = tmp / name
            if raw is not None:
                p.write_text(raw)
            else:
                e = json.loads(json.dumps(d))
                assert edit is not None
                edit(e)
                p.write_text(json.dumps(e))
            return p

        rcases = [
            (
                'exact "1e999999999"',
                report(
                    "r1.json",
                    lambda e: e["parameters"]["exact"].__setitem__("lambda", "1e999999999"),
                ),
            ),
            (
                "exact 5000-digit fraction",
                report(
                    "r2.json",
                    lambda e: e["parameters"]["exact"].__setitem__("lambda", "9" * 5000 + "/7"),
                ),
            ),
            (
                "JSON nested 100000 levels",
                report(
                    "r3.json",
                    None,
                    json.dumps(d)[:-1] + ', "x": ' + "[" * 100000 + "]" * 100000 + "}",
                ),
            ),
            (
                "17 MB report (size limit)",
                report("r4.json", None, json.dumps({**d, "pad": "x" * (17 * 2**20)})),
            ),
        ]
        for name, path in rcases:
            _line(f"report: {name}", _rejects(lambda p=path: api.verify(p)))

        exe = str(Path(sys.executable).parent / "obsdesign")
        for name, args in (
            ("CLI: 2000×2000 system (cold start included)", ["design", str(tmp / "b2000.toml")]),
            ("CLI: spec symlink to /dev/zero (cold start incl.)", ["design", str(zero)]),
        ):
            t, c = [], []
            for _ in range(3):
                c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
                t0 = time.perf_counter()
                r = subprocess.run([exe, *args], capture_output=True, env={**os.environ})
                t.append(time.perf_counter() - t0)
                c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
                c.append(c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime)
                assert r.returncode == 2, r.stderr
            _line(name, statistics.median(t), cpu=statistics.median(c))


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    main()
