"""Benchmarks of the constrained method (Astolfi, Bernard, Postoyan, Marconi, NOLCOS 2019): design + exact verify of the
shipped Section 5 spec; the modified observer step with up to θ_m = 10 refinements for
n = 2, 10, 50; and a batch of 10,000 trajectories × 300 samples, vectorized vs a plain Python
loop (same arithmetic, one trajectory at a time)."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5.toml"


def _system(n: int, seed: int = 0):
    """x⁺ = A x with ‖A‖_∞ = 1, y = x (C = I), A − LC = K of spectral radius 0.9; box map
    r = ±1.1, ε_min = 0.01, and a small γ so that refining runs its full θ_m budget."""
    from obsdesign.certify.exact import Q
    from obsdesign.methods.constrained.cmap import box_map
    from obsdesign.methods.constrained.observer import LinearF, Refiner

    rng = np.random.default_rng(seed)
    A = rng.uniform(-1, 1, (n, n))
    A /= np.abs(A).sum(axis=1).max()
    K = rng.uniform(-1, 1, (n, n))
    K *= 0.9 / np.max(np.abs(np.linalg.eigvals(K)))
    L = A - K
    F = LinearF(A, np.zeros((n, 0)), np.eye(n), np.zeros((n, 0)), L)
    M = rng.standard_normal((n, n))
    Pinv = np.linalg.inv(M @ M.T + np.eye(n))
    cm = box_map([Q(-1.1)] * n, [Q(1.1)] * n)
    return A, F, Refiner(cm, Pinv, 1e-4, 0.01, 1e12)


def main() -> None:
    from obsdesign import api
    from obsdesign.methods.constrained.observer import Observer

    api.design(SPEC)  # warm imports
    t0 = time.perf_counter()
    report = api.design(SPEC)  # the report in memory: verify re-reads it from its JSON form
    t1 = time.perf_counter()
    assert api.verify(report).exit_code() == 0
    t2 = time.perf_counter()
    ok = t2 - t0 < 1.0
    print(
        f"constrained design + exact verify (Section 5 spec): {t2 - t0:.3f} s "
        f"(design {t1 - t0:.3f} s) (target < 1 s) {'ok' if ok else 'MISSED'}"
    )

    for n in (2, 10, 50):
        A, F, ref = _system(n)
        rng = np.random.default_rng(1)
        xs = rng.uniform(3, 6, (2000, n))  # far outside C_min: all 10 refinements run
        y = rng.uniform(-1, 1, (2000, n))
        u = np.zeros(0)
        t0 = time.perf_counter()
        total = 0
        for j in range(len(xs)):
            x1 = F(xs[j], u, y[j])
            _, s = ref.refine(x1, 10)
            total += s
        dt = time.perf_counter() - t0
        print(
            f"constrained modified observer step, n = {n:2d}, θ_m = 10: "
            f"{dt / len(xs) * 1e6:.1f} µs per sample ({total / len(xs):.1f} refinements per sample)"
        )

    B, N, n = 10_000, 300, 2
    A, F, ref = _system(n, seed=3)
    rng = np.random.default_rng(2)
    x0 = rng.uniform(-1, 1, (B, n))
    X = np.empty((B, N + 1, n))
    X[:, 0] = x0
    for k in range(N):
        X[:, k + 1] = X[:, k] @ A.T
    Y = X + rng.uniform(-0.05, 0.05, X.shape)
    U = np.zeros((B, N + 1, 0))
    Xh0 = rng.uniform(-1.2, 1.2, (B, n)) * 8  # start far off: peaking and refining
    t0 = time.perf_counter()
    est, steps = Observer(F, ref, 10).run_batch(U, Y, Xh0)
    tv = time.perf_counter() - t0
    rate_v = B * N / tv
    sub = 100  # the plain loop on a subset, same arithmetic (rate per sample)
    t0 = time.perf_counter()
    for b in range(sub):
        xh = Xh0[b].copy()
        for k in range(N):
            xh = F(xh, U[b, k], Y[b, k])
            xh, _ = ref.refine(xh, 10)
    tl = time.perf_counter() - t0
    rate_l = sub * N / tl
    assert np.allclose(xh, est[sub - 1, -1], rtol=1e-9, atol=1e-9)
    ratio = rate_v / rate_l
    print(
        f"constrained batch 10,000 × 300 (θ_m = 10, {steps.mean():.2f} refinements per sample): "
        f"{rate_v:,.0f} samples/s vectorized vs {rate_l:,.0f} samples/s plain loop: "
        f"{ratio:.0f}× (target ≥ 50×) {'ok' if ratio >= 50 else 'MISSED'}"
    )


if __name__ == "__main__":
    main()
