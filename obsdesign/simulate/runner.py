"""Plant + observer runners over a spec's ``[simulate]`` scenario (linear plants).

Discrete: x⁺ = A x + B u + Bd d, y = C x + D u + Dn v; the observer is a step function
``step(k, xhat, y, u) -> xhat⁺``. Continuous: the same plant as ẋ, integrated with scipy's
``solve_ivp`` (RK45) jointly with the observer ``rhs(t, xhat, y, u) -> dxhat``; signals are held
constant over each ``dt``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from obsdesign.errors import InputError
from obsdesign.simulate.grid import time_grid
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec


def _need(spec: Spec) -> None:
    if spec.simulate is None:
        raise InputError(f"{spec.file}: [simulate] is missing: nothing to simulate")


def signals(spec: Spec, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Input u, disturbance d and noise v on ``grid``, from one seeded generator."""
    sim = spec.simulate
    assert sim is not None
    rng = np.random.default_rng(sim.seed)
    return (
        sim.u.evaluate(grid, rng),
        sim.disturbance.evaluate(grid, rng),
        sim.noise.evaluate(grid, rng),
    )


def run_discrete(
    spec: Spec, step: Callable[[int, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
) -> SimResult:
    """Run a discrete-time observer against the linear plant for ``horizon`` samples."""
    _need(spec)
    s, sim = spec.system, spec.simulate
    assert sim is not None
    N = int(sim.horizon.f)
    k = np.arange(N + 1)
    u, d, v = signals(spec, k)
    A, B, C, D, Bd, Dn = s.A.f, s.B.f, s.C.f, s.D.f, s.Bd.f, s.Dn.f
    x = np.zeros((N + 1, s.n))
    xh = np.zeros((N + 1, s.n))
    y = np.zeros((N + 1, s.p))
    x[0], xh[0] = sim.x0.f, sim.xhat0.f
    for i in range(N + 1):
        y[i] = C @ x[i] + D @ u[i] + Dn @ v[i]
        if i == N:
            break
        xh[i + 1] = step(i, xh[i], y[i], u[i])
        x[i + 1] = A @ x[i] + B @ u[i] + Bd @ d[i]
    return SimResult(k.astype(float), x, xh, y, s.states)


def run_continuous(
    spec: Spec, rhs: Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
) -> SimResult:
    """Integrate the linear plant and a continuous-time observer with solve_ivp (RK45)."""
    from scipy.integrate import solve_ivp

    _need(spec)
    s, sim = spec.system, spec.simulate
    assert sim is not None and sim.dt is not None
    dt = float(sim.dt.f)
    grid = time_grid(sim.horizon.q, sim.dt.q)
    u, d, v = signals(spec, grid)
    A, B, C, D, Bd, Dn = s.A.f, s.B.f, s.C.f, s.D.f, s.Bd.f, s.Dn.f
    n = s.n

    def idx(t: float) -> int:
        return min(int(t / dt), len(grid) - 1)

    def f(t: float, z: np.ndarray) -> np.ndarray:
        i = idx(t)
        x, xh = z[:n], z[n:]
        y = C @ x + D @ u[i] + Dn @ v[i]
        return np.concatenate([A @ x + B @ u[i] + Bd @ d[i], rhs(t, xh, y, u[i])])

    z0 = np.concatenate([sim.x0.f, sim.xhat0.f])
    sol = solve_ivp(f, (0.0, grid[-1]), z0, t_eval=grid, max_step=dt, rtol=1e-8, atol=1e-10)
    if not sol.success:
        raise InputError(f"{spec.file}: simulation failed ({sol.message})")
    z = sol.y.T
    y = (C @ z[:, :n].T).T + (D @ u.T).T + (Dn @ v.T).T
    return SimResult(sol.t, z[:, :n], z[:, n:], y, s.states)
