"""Benchmarks of sweeps and checks on Dask (issue 13): a 200-point sweep of a fast shipped spec
serial vs a LocalCluster of 2 worker processes (target ≥ 1.6× on a 2-core machine), the Dask
overhead per task (no-op tasks on the warm cluster, target ≤ 20 ms) and ``check`` of specs/
serial vs 2 workers. The rows of the two runs are compared (they must be equal but the
timing columns). The load average is printed: other processes on the machine take from the
2 workers what they take from the serial run.

``OBSDESIGN_BENCH_QUICK=1``: a 50-point sweep and no check of specs/."""

from __future__ import annotations

import os
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
QUICK = bool(os.environ.get("OBSDESIGN_BENCH_QUICK"))


def line(name: str, value: str, target: str, ok: bool | None) -> None:
    mark = "" if ok is None else ("ok" if ok else "MISSED")
    print(f"{name:55s} {value:>14s}   target {target:18s} {mark}")


def _strip(rows: list[dict]) -> list[dict]:
    from obsdesign.sweep import TIMING_COLUMNS

    return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in rows]


def _burn(n: int) -> int:
    s = 0
    for i in range(n):
        s += i * i
    return s


def main() -> None:
    from obsdesign import api
    from obsdesign import sweep as sw
    from obsdesign.distributed import dask_client, run_tasks

    n = 50 if QUICK else 200
    grid = [f"method.lambda=0.951:0.999:{n}"]
    print(f"load average (1 min) before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    sw.sweep_rows(SPEC, ["method.lambda=0.97"])  # imports, first solve
    t0 = time.perf_counter()
    serial = sw.sweep_rows(SPEC, grid)
    t_serial = time.perf_counter() - t0
    line(f"sweep, {n} points, serial", f"{t_serial:.2f} s", "(report)", None)

    t0 = time.perf_counter()
    ctx = dask_client(workers=2)  # the LocalCluster of `--workers 2`
    client = ctx.__enter__()
    t_start = time.perf_counter() - t0
    try:
        line("LocalCluster(2 processes) start", f"{t_start:.2f} s", "(report)", None)
        t0 = time.perf_counter()
        sw.sweep_rows(SPEC, ["method.lambda=[0.97, 0.98]"], client=client)  # worker imports
        t_warm = time.perf_counter() - t0
        line("first 2 points on the cluster (worker imports)", f"{t_warm:.2f} s", "(report)", None)
        t0 = time.perf_counter()
        dist = sw.sweep_rows(SPEC, grid, client=client)
        t_dist = time.perf_counter() - t0
        same = _strip(dist) == _strip(serial)
        line(f"sweep, {n} points, 2 workers (warm cluster)", f"{t_dist:.2f} s", "(report)", None)
        sp = t_serial / t_dist
        line("  speed-up, warm cluster (rows identical)" if same else "  speed-up (ROWS DIFFER)",
             f"{sp:.2f}x", ">= 1.6x", sp >= 1.6 and same)  # fmt: skip
        cold = t_serial / (t_dist + t_start + t_warm)
        line("  speed-up incl. cluster start and worker imports", f"{cold:.2f}x", "(report)", None)

        # what the machine gives 2 processes now: the same pure-Python CPU work, serial vs
        # the 2 workers (with other processes running, this bounds the speed-up above)
        work = [2_000_000] * 8
        t0 = time.perf_counter()
        run_tasks(_burn, work)
        t_b1 = time.perf_counter() - t0
        t0 = time.perf_counter()
        run_tasks(_burn, work, client=client)
        t_b2 = time.perf_counter() - t0
        line("  machine's 2-process capacity now (pure CPU work)", f"{t_b1 / t_b2:.2f}x",
             "(report; ~2x idle)", None)  # fmt: skip

        m = 400
        run_tasks(abs, list(range(20)), client=client, chunk=1)
        t0 = time.perf_counter()
        run_tasks(abs, list(range(m)), client=client, chunk=1)
        per = (time.perf_counter() - t0) / m
        line(f"Dask overhead per task ({m} no-op tasks, 1 item each)", f"{per * 1e3:.2f} ms",
             "<= 20 ms", per <= 0.020)  # fmt: skip
        t0 = time.perf_counter()
        run_tasks(abs, list(range(m)), client=client)
        per = (time.perf_counter() - t0) / m
        line("  per item, chunked as sweeps are", f"{per * 1e3:.2f} ms", "(report)", None)
        # per point, the work itself: the serial time divided by the points
        line("  (work per sweep point, serial)", f"{t_serial / n * 1e3:.1f} ms", "(report)", None)

        if not QUICK:
            specs = api.spec_files([ROOT / "specs"])
            t0 = time.perf_counter()
            a = api.check(specs)
            t_cs = time.perf_counter() - t0
            t0 = time.perf_counter()
            b = api.check(specs, client=client)
            t_cd = time.perf_counter() - t0
            same = [{**r.__dict__, "seconds": 0} for r in a] == [
                {**r.__dict__, "seconds": 0} for r in b
            ]
            line(f"check specs/ ({len(specs)} specs), serial", f"{t_cs:.2f} s", "(report)", None)
            line("check specs/, 2 workers (warm cluster)", f"{t_cd:.2f} s", "(report)", None)
            line("  speed-up (rows identical)" if same else "  speed-up (ROWS DIFFER)",
                 f"{t_cs / t_cd:.2f}x", "(report)", same if not same else None)  # fmt: skip
    finally:
        ctx.__exit__(None, None, None)
    print(f"load average (1 min) after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
