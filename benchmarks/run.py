"""`make bench`: the speed figures the issues ask for, each printed with its target.

Foundation figures first, then every ``benchmarks/bench_*.py`` that defines ``main()``.
"""

from __future__ import annotations

import importlib.util
import os
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

# the same float work without scipy: the Lyapunov equation as its n²×n² linear system, as
# obsdesign.lyap.solve_lyapunov solves it up to 8 states (information: what obsdesign's own
# layers cost once neither side pays the scipy.linalg import)
FLOAT_DESIGN_NUMPY = FLOAT_DESIGN.replace("import scipy.linalg as sl\n", "").replace(
    "P = sl.solve_discrete_lyapunov((Acl / lam).T, np.eye(len(A)) / lam**2)",
    "n = len(A)\nP = np.linalg.solve(lam**2 * np.eye(n * n) - np.kron(Acl.T, Acl.T), "
    "np.eye(n).ravel()).reshape(n, n)",
)


def line(name: str, value: str, target: str, ok: bool) -> None:
    print(f"{name:55s} {value:>14s}   target {target:18s} {'ok' if ok else 'MISSED'}")


def wall(cmd: list[str], repeat: int = 7) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=True, cwd=ROOT)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def paired(
    cmds: list[list[str]], repeat: int = 11, env: dict[str, str] | None = None
) -> list[tuple[float, float]]:
    """Median wall and CPU (user + system of the child) seconds of each command, the commands
    run interleaved ``repeat`` times (on a loaded machine both drift together, so their
    ratios hold; CPU time drifts less than wall time)."""
    w: list[list[float]] = [[] for _ in cmds]
    c: list[list[float]] = [[] for _ in cmds]
    for _ in range(repeat):
        for i, cmd in enumerate(cmds):
            t0 = time.perf_counter()
            p = subprocess.Popen(
                cmd, cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
            )
            err = p.stderr.read() if p.stderr else b""
            _, status, ru = os.wait4(p.pid, 0)
            if os.waitstatus_to_exitcode(status) != 0:
                raise RuntimeError(f"{' '.join(cmd)} failed: {err.decode(errors='replace')}")
            w[i].append(time.perf_counter() - t0)
            c[i].append(ru.ru_utime + ru.ru_stime)
    return [(statistics.median(a), statistics.median(b)) for a, b in zip(w, c, strict=True)]


def ratio_line(name: str, ours: tuple[float, float], base: tuple[float, float], limit: float):
    """One figure: wall ratio against its target, CPU ratio and the times beside it."""
    r = ours[0] / base[0]
    line(name, f"{r:.2f}x", f"<= {limit}x", r <= limit)
    print(
        f"    ({ours[0] * 1e3:.0f} ms vs {base[0] * 1e3:.0f} ms wall; CPU "
        f"{ours[1] * 1e3:.0f} vs {base[1] * 1e3:.0f} ms = {ours[1] / base[1]:.2f}x; "
        "paired medians of 11)"
    )


def _bytecode_fresh() -> bool:
    """Whether every obsdesign module has bytecode at least as new as its source."""
    import importlib.util

    pkg = ROOT / "obsdesign"
    for src in pkg.rglob("*.py"):
        pyc = Path(importlib.util.cache_from_source(str(src)))
        if not pyc.exists() or pyc.stat().st_mtime < src.stat().st_mtime:
            return False
    return True


def foundation() -> None:
    print("== foundation (issue: Foundation; issue 12 item 3, cold start)")
    exe = str(Path(sys.executable).parent / "obsdesign")
    base, cli = paired([[sys.executable, "-c", "import typer, rich"], [exe, "--help"]])
    ratio_line("obsdesign --help cold start / import typer,rich", cli, base, 1.2)
    # issue 12 item 3: cold `design` of the shipped Lyapunov spec vs a float-only scipy script
    # doing the same work (read the TOML, Lyapunov equation, PD checks, write JSON)
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        script = Path(d) / "float_design.py"
        script.write_text(FLOAT_DESIGN)
        script_np = Path(d) / "float_design_numpy.py"
        script_np.write_text(FLOAT_DESIGN_NUMPY)
        fl_cmd = [sys.executable, str(script), str(SPEC), str(Path(d) / "f.json")]
        np_cmd = [sys.executable, str(script_np), str(SPEC), str(Path(d) / "g.json")]
        cold_cmd = [exe, "design", str(SPEC), "-o", str(Path(d) / "r.json"), "--force"]
        fl, fl_np, cold = paired([fl_cmd, np_cmd, cold_cmd])
        ratio_line("cold `obsdesign design` Lyapunov spec / float scipy script", cold, fl, 1.5)
        print(
            f"    (information: / the same float script without scipy, {cold[0] / fl_np[0]:.2f}x "
            f"wall, {cold[1] / fl_np[1]:.2f}x CPU: obsdesign's own layers (typer, rich, flint, "
            "the exact checks, the report); obsdesign solves a Lyapunov equation of up to 8 "
            "states by numpy and no longer imports scipy.linalg)"
        )
        if os.environ.get("PYTHONDONTWRITEBYTECODE") and not _bytecode_fresh():
            # an editable install never gets bytecode written in such an environment, so every
            # cold run compiles ~10,000 lines; an installed package ships it (`make bench`
            # runs compileall first)
            print("    (obsdesign has no fresh bytecode here: these times include compiling it;")
            print("     run `make bench`, which compiles it first as an installed package would)")

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
