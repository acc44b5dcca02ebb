"""Benchmarks of the stubborn method (Astolfi, Alessandri, Zaccarian, "Stubborn observers for
linear and nonlinear systems", WUDS 2017): design (with the λ search) + exact verify for
n = 2, 4, 8, 16 states; the outlier study of Example 1 with 1,000 Monte Carlo runs, vectorized
across runs vs the same error integration one run at a time."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EX1 = ROOT / "specs" / "astolfi-stubborn-example1.toml"


def line(name: str, value: str, target: str, ok: bool | None) -> None:
    mark = "" if ok is None else ("ok" if ok else "MISSED")
    print(f"{name:55s} {value:>14s}   target {target:18s} {mark}")


def spec_text(n: int, seed: int = 0) -> str:
    """A random continuous-time plant with n states and one output: A = G/√n − I with G
    standard Gaussian (rounded to 3 decimals; a few unstable modes), C Gaussian (observable
    almost surely)."""
    rng = np.random.default_rng(seed)
    A = np.round(rng.standard_normal((n, n)) / np.sqrt(n) - np.eye(n), 3)
    C = np.round(rng.standard_normal(n), 3)
    rows = ", ".join("[" + ", ".join(repr(float(v)) for v in r) + "]" for r in A)
    crow = ", ".join(repr(float(v)) for v in C)
    return (
        f'[system]\ntime = "continuous"\nA = [{rows}]\nC = [[{crow}]]\n'
        '[method]\nkey = "stubborn"\ngain_bound = 1000\n'
    )


def main() -> None:
    from obsdesign import api
    from obsdesign.methods.stubborn import sim
    from obsdesign.methods.stubborn.options import SimOptions

    api.design(api.load_spec_text(spec_text(2), "warm.toml"))  # imports, first compile
    for n in (2, 4, 8, 16):
        t0 = time.perf_counter()
        rep = api.design(api.load_spec_text(spec_text(n), f"n{n}.toml"))
        t1 = time.perf_counter()
        ver = api.verify(rep)
        t2 = time.perf_counter()
        ok = ver.exit_code() == 0
        target = "< 5 s" if n == 8 else "(report)"
        line(
            f"design (λ search) + exact verify, n = {n}{'' if ok else ' (NOT VERIFIED)'}",
            f"{t2 - t0:.2f} s",
            target,
            (t2 - t0 < 5 and ok) if n == 8 else None,
        )
        print(f"    (design {t1 - t0:.2f} s, verify {t2 - t1:.2f} s)")

    sp = api.load_spec(EX1)
    rep = api.design(sp)
    t0 = time.perf_counter()
    st = sim.study(sp, rep.parameters, runs=1000)
    t_vec = time.perf_counter() - t0
    line("outlier study, Example 1, 1000 runs × 5 amplitudes", f"{t_vec:.2f} s", "(report)", None)
    # one run at a time: the same integration with a batch of one (4 observers × 1 amplitude)
    g = sim.Gains.of(sp, rep.parameters)
    so: SimOptions = sp.simulate.options
    steps, dt = sim._grid(sp)
    e0 = np.asarray(sp.simulate.x0.f, float) - np.asarray(sp.simulate.xhat0.f, float)
    levels = np.full((4, 1, 1, 1), np.inf)
    adaptive = np.zeros((4, 1, 1), bool)
    adaptive[3] = True
    k = 5
    t0 = time.perf_counter()
    for i in range(k):
        rng = np.random.default_rng(i)
        base = sim.noise_fn(rng, (1, 1), 1, so, np.asarray([[10.0]]))
        sim.run_errors(
            g, e0, lambda a, b, base=base: base(a, b)[:, None], steps, dt, levels, adaptive, 0.0
        )
    t_one = (time.perf_counter() - t0) / k * 1000 * len(so.amplitudes)
    ratio = t_one / t_vec
    line("  one run at a time (extrapolated from 5 runs)", f"{t_one:.1f} s", "(report)", None)
    line("  vectorized speed-up", f"{ratio:.0f}x", ">= 10x", ratio >= 10)
    med = st["median_rmse"]
    print(
        "    medians at amplitude 1000 (x1): Luenberger "
        f"{med['luenberger']['1000']['x1']:.3g}, stubborn {med['stubborn']['1000']['x1']:.3g}"
    )


if __name__ == "__main__":
    main()
