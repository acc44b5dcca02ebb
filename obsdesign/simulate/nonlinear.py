"""The linear observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) (or its continuous analogue)
against a plant given by expressions (``[system] f``, ``psi``, ``h``), for one run or a batch
of Monte Carlo runs at once.

Plant: x⁺ (or ẋ) = f(x, u, d, t), or A x + B u + Bd d + ψ(x, u, d, t); y = h(x, u, v, t), or
C x + D u + Dn v; ``t`` is the grid value (the sample index in discrete time, the time in
continuous time). Every expression is compiled once (``Expr.on``) and evaluated on the
(runs, ·) array of all runs together, so a step costs a few numpy calls whatever the number
of runs. Continuous time: the classical Runge–Kutta scheme (RK4) with :data:`SUBSTEPS` equal
steps per ``dt``, the signals held over each ``dt`` (as the linear path holds them). The
runs step the plant x and the error e = x̂ − x (:class:`Plant`), as the linear path does, so
an unstable plant keeps its error's digits; x̂ = x + e.

Monte Carlo runs draw their initial errors and signals exactly as the linear path does
(:func:`obsdesign.simulate.montecarlo.study`: same child seeds, same order of draws, same
per-run metrics), and every operation acts on each run's row alone, so a run's numbers do
not depend on the batching.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from obsdesign.simulate import montecarlo as mc
from obsdesign.simulate.budget import TimeBudget
from obsdesign.simulate.linear import sim_grid
from obsdesign.simulate.result import SimResult, norms
from obsdesign.spec.models import Spec

#: RK4 steps per sample interval ``dt`` (continuous time)
SUBSTEPS = 8


class Plant:
    """The plant's right-hand side and output map over a batch (arrays (R, ·)), and the
    observer's matrices for gain ``L``: x̂⁺ = (A − L C) x̂ + (B − L D) u + L y.

    The runs step [x; e] (e = x̂ − x), never x̂ alone: the error's recursion,
    e⁺ = (A − L C) e + L (y − C x − D u) − (x⁺ − A x − B u) (:meth:`error_step`; ė the
    same in continuous time), takes the defects y − C x − D u and x⁺ − A x − B u as the
    model gives them (D_n v and B_d d + ψ when the plant is A x + … + ψ; h − C x − D u and
    f − A x − B u when ``f`` or ``h`` give the whole map), so an unstable plant whose x
    passes 10¹⁶·|e| keeps its error (x̂ − x from x and x̂ would lose every digit)."""

    def __init__(self, spec: Spec, L: np.ndarray):
        s = self.s = spec.system
        self.n = s.n
        x_u_d_t = [*s.states, *s.inputs, *s.disturbances, "t"]
        x_u_v_t = [*s.states, *s.inputs, *s.noises, "t"]
        self.f = [e.on(x_u_d_t) for e in (s.f or s.psi or [])]
        self.additive = s.f is None
        self.h = [e.on(x_u_v_t) for e in s.h] if s.h is not None else None
        A, C, D = s.A.f, s.C.f, s.D.f
        L = np.asarray(L, dtype=float).reshape(s.n, s.p)
        #: [e, y − C x − D u] @ errT is (A − L C) e + L (y − C x − D u)
        self.errT = np.concatenate([A - L @ C, L], axis=1).T.copy()
        self.linT = np.concatenate([A, s.B.f], axis=1).T.copy()  # [x, u] @ linT = A x + B u
        self.outT = np.concatenate([C, D], axis=1).T.copy()  # [x, u] @ outT = C x + D u

    def rhs(
        self, X: np.ndarray, U: np.ndarray, Dd: np.ndarray, t: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """(x⁺ or ẋ, its defect x⁺ − A x − B u) of every run: (R, n) each."""
        s = self.s
        Z = _args(X, U, Dd, t)
        parts = np.stack([g(Z) for g in self.f], axis=-1) if self.f else 0.0
        lin = mc._mm(np.concatenate([X, U], axis=1), self.linT)
        if not self.additive:
            return parts, parts - lin
        defect = Dd @ s.Bd.f.T + parts
        return lin + defect, defect

    def out(
        self, X: np.ndarray, U: np.ndarray, V: np.ndarray, t: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """(y, its defect y − C x − D u) of every run: (R, p) each."""
        s = self.s
        lin = mc._mm(np.concatenate([X, U], axis=1), self.outT)
        if self.h is None:
            defect = V @ s.Dn.f.T
            return lin + defect, defect
        Z = _args(X, U, V, t)
        y = np.stack([g(Z) for g in self.h], axis=-1)
        return y, y - lin

    def error_step(self, E: np.ndarray, y_defect: np.ndarray, x_defect: np.ndarray) -> np.ndarray:
        """The error's e⁺ (discrete) or ė (continuous) of every run,
        (A − L C) e + L (y − C x − D u) − (x⁺ − A x − B u): one product with the runs as rows
        (see :func:`obsdesign.simulate.montecarlo._mm`)."""
        return mc._mm(np.concatenate([E, y_defect], axis=1), self.errT) - x_defect


def _args(X: np.ndarray, a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    """The expressions' argument array [x, a, b, t] of every run: (R, n + · + · + 1)."""
    return np.concatenate([X, a, b, np.full((len(X), 1), t)], axis=1)


#: the signals u, d, v of every run at step k: (R, m), (R, nd), (R, nv)
Signals = Callable[[int], tuple[np.ndarray, np.ndarray, np.ndarray]]


def step_runs(
    plant: Plant,
    spec: Spec,
    grid: np.ndarray,
    X0: np.ndarray,
    XH0: np.ndarray,
    at: Signals,
    keep: bool,
    budget: TimeBudget | None = None,
) -> tuple[dict[str, np.ndarray], tuple[np.ndarray, ...] | None]:
    """Step R ≥ 2 runs (rows of ``X0``, ``XH0``) over ``grid``; per-run metrics (as
    :func:`obsdesign.simulate.montecarlo.study` names them) and, when ``keep``, run 0's
    (x, x̂, y) trajectories. ``budget`` (the time budget) is looked at every 1024 steps."""
    K = len(grid) - 1
    X, E = X0.copy(), XH0 - X0
    XH = X + E
    sup_e, sup_h = np.abs(E), np.abs(XH)
    # the sum of squares kept over the running max |e| (montecarlo._scaled_add): e of 10²⁰⁰
    # made the RMSE inf and e of 10⁻²⁰⁰ made it 0 (Dask trial, session 29)
    sq, sc = np.zeros_like(E), np.zeros_like(E)
    mc._scaled_add(sq, sc, E)
    traj = [np.empty((K + 1, plant.n)) for _ in range(3)] + [np.empty((K + 1, plant.s.p))]
    dt = float(grid[1] - grid[0]) if K else 0.0
    for k in range(K + 1):
        if budget is not None and k % 1024 == 0:
            budget.check(f"the expression plant at step {k:,} of {K:,}")
        U, Dd, V = at(k)
        if keep:
            traj[0][k], traj[1][k], traj[2][k] = X[0], XH[0], E[0]
            traj[3][k] = plant.out(X[:1], U[:1], V[:1], grid[k])[0][0]
        if k == K:
            break
        if plant.s.discrete:
            _, ydef = plant.out(X, U, V, grid[k])
            Xn, xdef = plant.rhs(X, U, Dd, grid[k])
            X, E = Xn, plant.error_step(E, ydef, xdef)
        else:
            X, E = _rk4(plant, X, E, U, Dd, V, grid[k], dt)
        XH = X + E
        np.maximum(sup_e, np.abs(E), out=sup_e)
        mc._scaled_add(sq, sc, E)
        np.maximum(sup_h, np.abs(XH), out=sup_h)
    m = {
        "sup_abs_error": sup_e,
        "rmse": mc._scaled_rmse(sq[:, None, :], sc[:, None, :], np.zeros_like(E), K + 1),
        "sup_abs_estimate": sup_h,
        "final_error_norm": norms(E),
    }
    # run 0's (x, x̂, y, e), in the order montecarlo.study reads them
    return m, ((traj[0], traj[1], traj[3], traj[2]) if keep else None)


def _rk4(
    plant: Plant,
    X: np.ndarray,
    E: np.ndarray,
    U: np.ndarray,
    Dd: np.ndarray,
    V: np.ndarray,
    t0: float,
    dt: float,
) -> tuple[np.ndarray, np.ndarray]:
    """One sample interval of the joint ODE (plant x, error e = x̂ − x; see
    :class:`Plant`) by :data:`SUBSTEPS` RK4 steps with u, d, v held (RK4 commutes with the
    linear change of coordinates from (x, x̂), so these are its numbers to rounding)."""
    h = dt / SUBSTEPS

    def F(t: float, X: np.ndarray, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        xdot, xdef = plant.rhs(X, U, Dd, t)
        return xdot, plant.error_step(E, plant.out(X, U, V, t)[1], xdef)

    for i in range(SUBSTEPS):
        t = t0 + i * h
        k1 = F(t, X, E)
        k2 = F(t + h / 2, X + h / 2 * k1[0], E + h / 2 * k1[1])
        k3 = F(t + h / 2, X + h / 2 * k2[0], E + h / 2 * k2[1])
        k4 = F(t + h, X + h * k3[0], E + h * k3[1])
        X = X + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        E = E + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return X, E


def simulate_one(spec: Spec, L: np.ndarray, budget: TimeBudget | None = None) -> SimResult:
    """The spec's scenario once (x0, xhat0, signals from ``seed``), stepped as two equal rows
    (so that it is run 0 of a batch to the bit)."""
    from obsdesign.simulate.runner import signals

    sim = mc._need(spec)
    grid = sim_grid(spec)
    sig = signals(spec, grid)
    pair = [np.stack([a, a], axis=1) for a in sig]  # (K + 1, 2, ·)
    X0, XH0 = np.tile(sim.x0.f, (2, 1)), np.tile(sim.xhat0.f, (2, 1))
    _, traj = step_runs(
        Plant(spec, L),
        spec,
        grid,
        X0,
        XH0,
        lambda k: (pair[0][k], pair[1][k], pair[2][k]),
        True,
        budget,
    )
    assert traj is not None
    return SimResult(grid, traj[0], traj[1], traj[2], spec.system.states, error=traj[3])


def batch_stepper(
    spec: Spec, L: np.ndarray, budget: TimeBudget | None = None
) -> tuple[np.ndarray, int, Any]:
    """What :func:`obsdesign.simulate.montecarlo.study` needs to run Monte Carlo runs of the
    observer with gain ``L`` against the expression plant, stepped together: the grid, the
    memory of a run's random draws, and the batch step (draws as the linear path makes them,
    then :func:`step_runs`)."""
    sim = mc._need(spec)
    grid = sim_grid(spec)
    plant = Plant(spec, L)
    sigs = (sim.u, sim.disturbance, sim.noise)
    rand = [i for i, g in enumerate(sigs) if mc._random(g)]
    fast = all(sigs[i].kind == "uniform" for i in rand)
    shared = [g.evaluate(grid, np.random.default_rng(sim.seed)) for g in sigs]
    w = sum(sigs[i].dim for i in rand)

    def step(
        rngs: list[np.random.Generator], e0: np.ndarray, keep: bool, scaled: bool = False
    ) -> Any:
        # scaled: the RMSE here is always kept scaled (step_runs), so nothing changes
        R = len(rngs)
        rows = max(R, 2)  # one run is stepped as two equal rows
        draws = mc._Draws(rand, fast, sigs, rngs, grid) if rand else None
        now: dict[str, Any] = {"c1": -1}

        def at(k: int) -> tuple[np.ndarray, ...]:
            if draws is not None and k >= now["c1"]:
                now["c0"], now["c1"] = k, min(len(grid), k + mc.CHUNK)
                now["vals"] = [
                    _values(sigs[i], raw, rows, fast)
                    for i, raw in zip(rand, draws.chunk(k, now["c1"]), strict=True)
                ]
            out = []
            for i, g in enumerate(sigs):
                if i in rand:
                    out.append(now["vals"][rand.index(i)][:, k - now["c0"]])
                else:
                    out.append(np.broadcast_to(shared[i][k], (rows, g.dim)))
            return tuple(out)

        X0 = np.tile(sim.x0.f, (rows, 1))
        XH0 = X0 + np.concatenate([e0, e0[:1]]) if R == 1 else X0 + e0
        m, traj = step_runs(plant, spec, grid, X0, XH0, at, keep, budget)
        return {k: a[:R] for k, a in m.items()}, traj

    return grid, (mc.CHUNK if fast else len(grid)) * w * 8, step


def _values(sig: Any, raw: np.ndarray, rows: int, fast: bool) -> np.ndarray:
    """A chunk of a random signal's values (rows, steps, dim): ``-b + 2b·U`` from raw draws
    (the formula of ``Generator.uniform``), else the values themselves."""
    V = raw.reshape(len(raw), -1, sig.dim)
    if fast:
        lo = -np.asarray(sig.bound, dtype=float)
        V = lo + np.subtract(sig.bound, lo) * V
    if len(V) < rows:
        V = np.concatenate([V, V[:1]])
    return V
