"""Benchmarks of the simulation (issue 12 item 4), printed beside their targets.

1. 10⁶ steps of the shipped Lyapunov spec (specs/constrained-redesign-sec5-lyapunov.toml with
   horizon = 10⁶): ``simulate_linear_observer`` (the joint [x; x̂] system, one matrix-vector
   product per step, exogenous terms precomputed) against a plain numpy loop doing the same
   work (observer equations step by step, trajectories x, x̂, y stored). Targets: time and
   peak memory (tracemalloc, numpy buffers included) each <= 1.5× the plain loop.
2. 1,000 runs × 10⁴ steps of the same plant with uniform output noise (a fresh noise draw per
   run) and initial errors drawn from a box: the batched Monte Carlo
   (``simulate_linear_observer_batch``) against 1,000 separate runs of
   ``simulate_linear_observer`` + metrics (timed on a sample interleaved with the batched
   runs, scaled to 1,000). Target >= 100×.
   The old Python-loop runner (``runner.run_discrete``, the path before issue 12) is timed on
   a few runs for reference.
3. The same study with the plant given by an expression (``[system] psi``): the batched runs
   (:mod:`obsdesign.simulate.nonlinear`) against separate runs. Target >= 100×.

``OBSDESIGN_BENCH_QUICK=1``: fewer repetitions, and 2,000 steps in the nonlinear study.
"""

from __future__ import annotations

import os
import re
import statistics
import time
import tracemalloc
from pathlib import Path

import numpy as np

QUICK = bool(os.environ.get("OBSDESIGN_BENCH_QUICK"))
ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"


def _spec(horizon: int, noise: str | None = None, psi: str | None = None):
    from obsdesign.api import load_spec_text

    text = SPEC.read_text()
    if psi is not None:
        text = text.replace("C = [[1, 0]]\n", f"C = [[1, 0]]\n{psi}\n")
    text = re.sub(r"horizon = \d+", f"horizon = {horizon}", text)
    if noise is not None:
        text = text[: text.index("[simulate.noise]")] + noise
    text = text.replace(
        "[simulate]", '[sets.E0]\ntype = "box"\nlower = [-2, -2]\nupper = [2, 2]\n\n[simulate]'
    )
    return load_spec_text(text, "bench.toml")


def _gain(sp) -> np.ndarray:
    return np.asarray(sp.options.L, dtype=float).reshape(sp.system.n, sp.system.p)


def plain_loop(sp, L: np.ndarray):
    """The baseline: the observer equations written out in numpy, one step at a time."""
    from obsdesign.simulate.runner import signals

    s, sim = sp.system, sp.simulate
    A, C, Dn = s.A.f, s.C.f, s.Dn.f
    N = int(sim.horizon.f)
    grid = np.arange(N + 1, dtype=float)
    _, _, v = signals(sp, grid)
    X = np.empty((N + 1, s.n))
    XH = np.empty((N + 1, s.n))
    Y = np.empty((N + 1, s.p))
    x, xh = sim.x0.f.copy(), sim.xhat0.f.copy()
    X[0], XH[0] = x, xh
    for k in range(N + 1):
        y = C @ x + Dn @ v[k]
        Y[k] = y
        if k == N:
            break
        xh = A @ xh + L @ (y - C @ xh)
        x = A @ x
        X[k + 1], XH[k + 1] = x, xh
    return X, XH, Y


def _timed(f, *a, **k):
    t = time.perf_counter()
    r = f(*a, **k)
    return r, time.perf_counter() - t


def _peak(f, *a) -> float:
    tracemalloc.start()
    try:
        f(*a)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def line(name: str, value: str, target: str, ok: bool) -> None:
    print(f"{name:58s} {value:>12s}   target {target:10s} {'ok' if ok else 'MISSED'}")


def million_steps(N: int = 10**6) -> None:
    from obsdesign.simulate.linear import simulate_linear_observer

    sp = _spec(N)
    L = _gain(sp)
    res, t_ours = _timed(simulate_linear_observer, sp, L)
    (X, XH, _), t_plain = _timed(plain_loop, sp, L)
    err = max(float(np.abs(res.x - X).max()), float(np.abs(res.xhat - XH).max()))
    m_ours = _peak(simulate_linear_observer, sp, L)
    m_plain = _peak(plain_loop, sp, L)
    print(f"10^6 steps of {SPEC.name}: ours {t_ours:.2f} s, {m_ours / 2**20:.0f} MB peak; plain "
          f"numpy loop {t_plain:.2f} s, {m_plain / 2**20:.0f} MB peak; max |difference| {err:.1e}")  # fmt: skip
    line(
        "time: simulate / plain numpy loop",
        f"{t_ours / t_plain:.2f}x",
        "<= 1.5x",
        t_ours <= 1.5 * t_plain,
    )
    line("peak memory: simulate / plain numpy loop", f"{m_ours / m_plain:.2f}x", "<= 1.5x", m_ours <= 1.5 * m_plain)  # fmt: skip


def _separate(sp, L: np.ndarray):
    """One separate run as a user would make it: simulate, then its metrics."""
    from obsdesign.simulate.linear import simulate_linear_observer

    return simulate_linear_observer(sp, L).metrics()


def monte_carlo(runs: int = 1000, N: int = 10**4, rounds: int = 5, sample: int = 6) -> None:
    """Batched runs against separate runs, paired: each round times one batched study and
    ``sample`` separate runs; the ratio (the target's) is of the medians (the machine may be
    loaded). The ratio of the fastest timings is printed beside it as a reference: on a
    shared machine another process slows a 0.2 s batched study more often than a 20 ms
    separate run, so the medians' ratio moves with the load (76× and 133× back to back in
    one session) while the minima, each side's least disturbed run, move less."""
    from obsdesign.simulate.linear import simulate_linear_observer_batch
    from obsdesign.simulate.runner import run_discrete

    noise = '[simulate.noise]\nkind = "uniform"\nbound = 0.05\n'
    sp = _spec(N, noise)
    L = _gain(sp)
    tb, ts = [], []
    for _ in range(rounds):
        res, t = _timed(simulate_linear_observer_batch, sp, L, runs, "E0")
        tb.append(t)
        ts += [_timed(_separate, sp, L)[1] for _ in range(sample)]
    t_batch, t_sep = statistics.median(tb), statistics.median(ts) * runs
    s = sp.system
    A, B, C, D = s.A.f, s.B.f, s.C.f, s.D.f

    def old_step(k, xh, y, u):
        return A @ xh + B @ u + L @ (y - C @ xh - D @ u)

    t_old = statistics.median(_timed(run_discrete, sp, old_step)[1] for _ in range(3)) * runs
    q = res.info["quantiles"]["final_error_norm"]
    print(f"{runs} runs × {N} steps: batched {t_batch:.3f} s (median of {rounds}); separate runs "
          f"{t_sep:.1f} s (simulate + metrics, median of {rounds * sample} × {runs}, interleaved); "
          f"the old Python-loop runner {t_old:.0f} s (3 × {runs}); final |e| quantiles "
          f"q50 {q['q50']:.3g}, q95 {q['q95']:.3g}, max {q['max']:.3g}")  # fmt: skip
    line("1000 separate runs / 1000 batched runs", f"{t_sep / t_batch:.0f}x", ">= 100x", t_sep >= 100 * t_batch)  # fmt: skip
    m_ratio = min(ts) * runs / min(tb)
    line("  the same, ratio of the fastest timings", f"{m_ratio:.0f}x", "(reference)", True)
    line("old runner, 1000 runs / 1000 batched runs", f"{t_old / t_batch:.0f}x", "(reference)", True)  # fmt: skip


def monte_carlo_nonlinear(runs: int = 1000, N: int = 10**4, rounds: int = 3) -> None:
    """The same study with the plant given by expressions (x⁺ = A x + ψ(x), ψ = 0.1 sin(x1)
    in the first state): the batched runs evaluate each compiled expression once per step
    over all runs; a separate run evaluates it once per step for itself. Paired as above."""
    from obsdesign.simulate.linear import (
        simulate_linear_observer,
        simulate_linear_observer_batch,
    )

    noise = '[simulate.noise]\nkind = "uniform"\nbound = 0.05\n'
    sp = _spec(N, noise, psi='psi = ["0.1*sin(x1)", "0"]')
    L = _gain(sp)
    tb, ts = [], []
    for _ in range(rounds):
        tb.append(_timed(simulate_linear_observer_batch, sp, L, runs, "E0")[1])
        ts.append(_timed(lambda: simulate_linear_observer(sp, L).metrics())[1])
    t_batch, t_sep = statistics.median(tb), statistics.median(ts) * runs
    print(f"{runs} runs × {N} steps, plant with psi = 0.1 sin(x1): batched {t_batch:.2f} s; "
          f"separate runs {t_sep:.0f} s (median of {rounds} × {runs}, interleaved)")  # fmt: skip
    line("nonlinear: 1000 separate runs / 1000 batched runs", f"{t_sep / t_batch:.0f}x", ">= 100x", t_sep >= 100 * t_batch)  # fmt: skip


def main() -> None:
    million_steps()
    if QUICK:
        monte_carlo(rounds=3, sample=4)
        monte_carlo_nonlinear(N=2000, rounds=1)
    else:
        monte_carlo()
        monte_carlo_nonlinear()


if __name__ == "__main__":
    main()
