"""`make bench`: the speed figures the issues ask for, each printed with its target.

Foundation figures first, then every ``benchmarks/bench_*.py`` that defines ``main()``.
"""

from __future__ import annotations

import importlib.util
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"


FLOAT_DESIGN = """
import json, sys, tomllib
import numpy as np
import scipy.linalg as sl

spec = tomllib.load(open(sys.argv[1], "rb"))
A = np.array(spec["system"]["A"], float)
C = np.array(spec["system"]["C"], float)
L = np.array(spec["method"]["L"], float).reshape(-1, 1)
lam = float(spec["method"]["lambda"])
Acl = A - L @ C
rho = float(max(abs(np.linalg.eigvals(Acl))))
P = sl.solve_discrete_lyapunov((Acl / lam).T, np.eye(len(A)) / lam**2)
np.linalg.cholesky(P)
np.linalg.cholesky(lam**2 * P - Acl.T @ P @ Acl)
json.dump({"rho": rho, "P": P.tolist()}, open(sys.argv[2], "w"))
"""


def line(name: str, value: str, target: str, ok: bool) -> None:
    print(f"{name:55s} {value:>14s}   target {target:18s} {'ok' if ok else 'MISSED'}")


def wall(cmd: list[str], repeat: int = 7) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=True, cwd=ROOT)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def foundation() -> None:
    print("== foundation (issue: Foundation)")
    exe = str(Path(sys.executable).parent / "obsdesign")
    base = wall([sys.executable, "-c", "import typer, rich"])
    cli = wall([exe, "--help"])
    line(
        "obsdesign --help cold start / import typer,rich",
        f"{cli / base:.2f}x",
        "<= 1.2x",
        cli / base <= 1.2,
    )
    print(f"    ({cli * 1e3:.0f} ms vs {base * 1e3:.0f} ms)")
    # issue 12 item 3: cold `design` of the shipped Lyapunov spec vs a float-only scipy script
    # doing the same work (read the TOML, Lyapunov equation, PD checks, write JSON)
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        script = Path(d) / "float_design.py"
        script.write_text(FLOAT_DESIGN)
        fl = wall([sys.executable, str(script), str(SPEC), str(Path(d) / "f.json")])
        cold = wall([exe, "design", str(SPEC), "-o", str(Path(d) / "r.json"), "--force"])
    line(
        "cold `obsdesign design` Lyapunov spec / float scipy script",
        f"{cold / fl:.2f}x",
        "<= 1.5x",
        cold / fl <= 1.5,
    )
    print(f"    ({cold * 1e3:.0f} ms vs {fl * 1e3:.0f} ms)")

    from obsdesign import api

    api.design(SPEC)  # warm the imports once
    t = []
    for _ in range(5):
        t0 = time.perf_counter()
        rep = api.design(SPEC)
        api.verify(rep)
        t.append(time.perf_counter() - t0)
    d = statistics.median(t)
    line("design + exact verify, shipped spec (in process)", f"{d:.3f} s", "< 1 s", d < 1)
    w = wall([exe, "check", str(SPEC)], repeat=3)
    line("design + exact verify, shipped spec (CLI wall, cold)", f"{w:.3f} s", "< 1 s", w < 1)

    from obsdesign.certify.exact import qmat
    from obsdesign.certify.psd import check_pd

    rng = np.random.default_rng(0)
    B = rng.integers(-1000, 1000, size=(30, 30))
    M = qmat(B @ B.T + np.eye(30, dtype=np.int64))
    M = M / 997  # rationals with a non-trivial denominator
    t = []
    for _ in range(5):
        t0 = time.perf_counter()
        assert check_pd(M).ok
        t.append(time.perf_counter() - t0)
    d = statistics.median(t)
    line("exact PD test, 30×30 rational matrix", f"{d * 1e3:.1f} ms", "< 200 ms", d < 0.2)


def method_benchmarks() -> None:
    for f in sorted((ROOT / "benchmarks").glob("bench_*.py")):
        spec = importlib.util.spec_from_file_location(f.stem, f)
        assert spec and spec.loader
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        if hasattr(mod, "main"):
            print(f"\n== {f.name}")
            mod.main()


if __name__ == "__main__":
    foundation()
    method_benchmarks()
