"""Benchmarks of the impulsive method: design + exact verify of the two shipped specs (the
3-state one runs the falsification pass in verify too), and 1,000 hybrid trajectories of 50
samples, batched vs one-by-one solve_ivp."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "schaum-impulsive-example.toml"
SPEC3 = ROOT / "specs" / "impulsive-sector-3state.toml"


def _field(X: np.ndarray) -> np.ndarray:
    x1, x2 = X[:, 0], X[:, 1]
    return np.stack([x1 * x2 * (x2**2 - 4) / (1 + x2**4), 3 * x1 - x2], 1)


def main() -> None:
    import tempfile

    from obsdesign import api
    from obsdesign.methods.impulsive.hybrid import simulate_hybrid, simulate_one_by_one

    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        api.design(SPEC, Path(d) / "r.json")
        t1 = time.perf_counter()
        rep = api.verify(Path(d) / "r.json")
        t2 = time.perf_counter()
    assert rep.exit_code() == 0
    print(f"impulsive design of the shipped example: {t1 - t0:.3f} s (incl. falsification pass)")
    print(f"impulsive design + exact verify: {t2 - t0:.3f} s (target < 1 s)")
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        r3 = api.design(SPEC3, Path(d) / "r3.json")
        t1 = time.perf_counter()
        rep = api.verify(Path(d) / "r3.json")
        t2 = time.perf_counter()
    assert rep.exit_code() == 0
    p = r3.parameters
    print(
        f"impulsive 3-state spec: window [{p.float('T_min'):.4f}, {p.float('T_max'):.4f}], "
        f"design {t1 - t0:.3f} s, verify {t2 - t1:.3f} s (both with falsification)"
    )

    rng = np.random.default_rng(0)
    N, K = 1000, 50
    T = np.array([[1.0, 0.0], [-3.0, 1.0]])
    H = rng.uniform(0.1551, 0.5396, (N, K))
    W = rng.uniform(-0.1, 0.1, (N, K, 1))
    x0, xh0 = np.tile([1.0, 1.0], (N, 1)), np.tile([0.0, 0.5], (N, 1))
    t0 = time.perf_counter()
    simulate_hybrid(_field, T, np.array([0.8]), x0, xh0, H, W, dense=1)
    tb = time.perf_counter() - t0
    M = 25
    t0 = time.perf_counter()
    for j in range(M):
        simulate_one_by_one(_field, T, np.array([0.8]), x0[j], xh0[j], H[j], W[j, :, 0])
    to = (time.perf_counter() - t0) / M * N
    print(f"impulsive 1,000 hybrid trajectories x 50 samples, batched RK45: {tb:.2f} s")
    print(f"impulsive same, one-by-one solve_ivp (extrapolated from {M}): {to:.1f} s")
    print(f"impulsive batch speed-up: {to / tb:.0f}x (target >= 10x)")


if __name__ == "__main__":
    main()
