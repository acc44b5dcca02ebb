"""The linear observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) (or its continuous analogue)
against the linear plant, as ONE joint linear system stepped by matrix products.

With z = [x; x̂] and the exogenous signals s = [u; d; v] (input, disturbance, noise):

* discrete time: z⁺ = M z + E s with M = [[A, 0], [L C, A − L C]] and
  E = [[B, Bd, 0], [B, 0, L Dn]] (y = C x + D u + Dn v; the D u terms cancel);
* continuous time: ż = M z + E s with the same M, E, and s held constant over each dt (the
  scenario's signals are sampled on the grid), so the exact zero-order-hold discretization
  z_{k+1} = Φ z_k + Γ s_k, [Φ Γ] = the top rows of expm([[M, E], [0, 0]] dt), gives the
  solution at the grid points up to rounding (no RK45 tolerance).

The exogenous terms E s_k are computed before the loop (one matrix product per chunk of
steps), so each step is one matrix-vector product and one addition. The single run steps
[x; e], e = x̂ − x, instead (:func:`joint_system` with ``error=True``; x̂ = x + e): the
error of an unstable plant's observer keeps its digits when x grows past 10¹⁶·|e|; so do
the Monte Carlo runs (:mod:`obsdesign.simulate.montecarlo`). :func:`simulate_linear_observer`
runs the spec's scenario once; :func:`simulate_linear_observer_batch` runs N Monte Carlo runs
over a batch axis (:mod:`obsdesign.simulate.montecarlo`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from obsdesign.errors import InputError
from obsdesign.simulate.budget import TimeBudget
from obsdesign.simulate.grid import time_grid
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec


@dataclass
class JointSystem:
    """The one-step map of plant + observer on a grid: z_{k+1} = M z_k + E s_k, with
    s = [u; d; v]; ``grid`` holds the sample indices (discrete) or times (continuous)."""

    M: np.ndarray
    E: np.ndarray
    grid: np.ndarray
    n: int
    #: coordinates: [x; e], e = x̂ − x (True) or [x; x̂] (False)
    error: bool = False

    def in_error_coordinates(self) -> JointSystem:
        """The same map in [x; e], e = x̂ − x: with T = [[I, 0], [−I, I]], M ↦ T M T⁻¹,
        E ↦ T E (itself when already there)."""
        if self.error:
            return self
        n = self.n
        T = np.eye(2 * n)
        T[n:, :n] = -np.eye(n)
        Ti = np.eye(2 * n)
        Ti[n:, :n] = np.eye(n)
        return JointSystem(T @ self.M @ Ti, T @ self.E, self.grid, n, True)


def sim_grid(spec: Spec) -> np.ndarray:
    """The simulation grid of the bound spec: sample indices 0..horizon (discrete time) or
    times 0, dt, …, horizon (continuous time)."""
    sim = spec.simulate
    if sim is None:
        raise InputError(f"{spec.file}: [simulate] is missing: nothing to simulate")
    if spec.system.discrete:
        return np.arange(int(sim.horizon.f) + 1, dtype=float)
    assert sim.dt is not None
    return time_grid(sim.horizon.q, sim.dt.q)


def joint_system(spec: Spec, L: np.ndarray, error: bool = False) -> JointSystem:
    """The joint plant + observer map of the bound spec for gain ``L`` (n×p): discrete
    matrices as they are, continuous ones discretized exactly (zero-order hold over dt).

    ``error``: in the coordinates z = [x; e], e = x̂ − x, instead of [x; x̂]:
    e⁺ = (A − LC) e − Bd d + L Dn v (the error dynamics of eq. (3) of the constrained-redesign
    paper's linear observer), M = diag(A, A − LC), E = [[B, Bd, 0], [0, −Bd, L Dn]]."""
    s, sim = spec.system, spec.simulate
    grid = sim_grid(spec)
    A, B, C, Bd, Dn = s.A.f, s.B.f, s.C.f, s.Bd.f, s.Dn.f
    n = s.n
    L = np.asarray(L, dtype=float).reshape(n, s.p)
    LC = L @ C
    m, nd, nv = B.shape[1], Bd.shape[1], Dn.shape[1]
    Z = np.zeros((n, n))
    if error:
        M = np.block([[A, Z], [Z, A - LC]])
        E = np.block([[B, Bd, np.zeros((n, nv))], [np.zeros((n, m)), -Bd, L @ Dn]])
    else:
        M = np.block([[A, Z], [LC, A - LC]])
        E = np.block([[B, Bd, np.zeros((n, nv))], [B, np.zeros((n, nd)), L @ Dn]])
    if s.discrete:
        return JointSystem(M, E, grid, n, error)
    from scipy.linalg import expm

    dt = float(sim.dt.f)
    k = 2 * n + m + nd + nv
    aug = np.zeros((k, k))
    aug[: 2 * n, : 2 * n] = M
    aug[: 2 * n, 2 * n :] = E
    with np.errstate(all="ignore"):
        F = expm(aug * dt)
    if not np.all(np.isfinite(F)):
        from obsdesign.lyap import float_realization

        Acl = A - LC
        if not np.all(np.isfinite(Acl)) or float_realization(Acl, False) == "unstable":
            # the observer in doubles, not dt: a certified 12-state design with ‖L‖ ≈ 2.5e11
            # was exit 2 blaming the default dt, and a smaller dt gave NaN (census 46)
            from obsdesign.errors import InconclusiveError

            raise InconclusiveError(
                f"{spec.file}: A − LC formed in doubles is not Hurwitz (decided exactly on "
                "the doubles), and exp of the observer over dt is not finite: a simulation in "
                "doubles cannot run this observer; the certificate is about the exact gain "
                "(report parameters.exact)"
            )
        # horizon 1e50 (dt = horizon / 1000) printed NaN metrics and "the plant or the
        # observer diverges" for a stable plant and observer (independent simulate review)
        raise InputError(
            f"{spec.file}: [simulate] dt = {dt:g} is too large for the exact zero-order-hold "
            "discretization: exp([[M, E], [0, 0]]·dt) is not finite in floats (a smaller dt or "
            "a shorter horizon)"
        )
    return JointSystem(F[: 2 * n, : 2 * n], F[: 2 * n, 2 * n :], grid, n, error)


def exogenous(u: np.ndarray, d: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The stacked signals s_k = [u_k; d_k; v_k] along the last axis."""
    return np.concatenate([u, d, v], axis=-1)


#: steps whose exogenous terms E s_k are computed at once (bounds the extra memory)
CHUNK = 1 << 16


def step_all(
    js: JointSystem, z0: np.ndarray, S: np.ndarray, budget: TimeBudget | None = None
) -> np.ndarray:
    """The trajectory z_0 .. z_K of z_{k+1} = M z_k + E s_k for the signals ``S`` ((K, ·):
    s_0 .. s_{K-1}); E s_k is computed :data:`CHUNK` steps at a time, one product each;
    ``budget`` is looked at before every chunk."""
    Z = _step_all(js, z0, S, budget, split=False)
    n, M = js.n, js.M
    # in error coordinates e⁺ does not read x (M's lower-left block is 0): when the run left
    # the float range, the blocks are stepped again apart, so a plant state that overflows
    # (an unstable plant over a long horizon) does not make the error nan through 0·inf
    # (simulate trial, session 27: a certified, converging error printed sup |e| = nan);
    # one product a step otherwise (twice as fast)
    if M.shape[0] == 2 * n and not np.any(M[n:, :n]) and not np.all(np.isfinite(Z)):
        Z = _step_all(js, z0, S, budget, split=True)
    return Z


def _step_all(
    js: JointSystem, z0: np.ndarray, S: np.ndarray, budget: TimeBudget | None, split: bool
) -> np.ndarray:
    """:func:`step_all`'s loop; ``split``: x and e stepped by their own blocks of M."""
    K = len(S)
    Z = np.empty((K + 1, len(z0)))
    Z[0] = z0
    M, ET = js.M, js.E.T
    mm = np.matmul
    n = js.n
    Mx, Me = M[:n], M[n:, n:]
    for k0 in range(0, K, CHUNK):
        if budget is not None:
            budget.check(f"the run at step {k0:,} of {K:,}")
        k1 = min(K, k0 + CHUNK)
        W = S[k0:k1] @ ET
        for k in range(k0, k1):
            z = Z[k + 1]
            if split:
                mm(Mx, Z[k], out=z[:n])
                mm(Me, Z[k, n:], out=z[n:])
            else:
                mm(M, Z[k], out=z)
            z += W[k - k0]
    return Z


def simulate_linear_observer(
    spec: Spec, L: np.ndarray, budget: TimeBudget | None = None
) -> SimResult:
    """Simulate the linear Luenberger observer with gain L against the spec's plant over
    the ``[simulate]`` scenario (x0, xhat0, signals from ``seed``); one run. A plant given by
    expressions (``[system] f / psi / h``) runs through
    :func:`obsdesign.simulate.nonlinear.simulate_one`. ``budget``: the time budget."""
    from obsdesign.simulate.runner import signals

    s = spec.system
    if not s.linear:
        from obsdesign.simulate.nonlinear import simulate_one

        return simulate_one(spec, L, budget)
    js = joint_system(spec, L, error=True)
    u, d, v = signals(spec, js.grid)
    sim = spec.simulate
    assert sim is not None
    # a run that leaves the float range is said in words by the API
    # (:func:`obsdesign.api._left_float_range`), not by numpy's overflow warnings
    with np.errstate(over="ignore", invalid="ignore"):
        z0 = np.concatenate([sim.x0.f, sim.xhat0.f - sim.x0.f])
        Z = step_all(js, z0, exogenous(u, d, v)[:-1], budget)
        x, e = Z[:, : js.n], Z[:, js.n :]
        y = x @ s.C.f.T + u @ s.D.f.T + v @ s.Dn.f.T
        xhat = x + e
    return SimResult(js.grid, x, xhat, y, s.states, error=e)


def simulate_linear_observer_batch(
    spec: Spec,
    L: np.ndarray,
    runs: int,
    initial_error: str | None = None,
    batch: int | None = None,
    span: tuple[int, int] | None = None,
    budget: TimeBudget | None = None,
) -> SimResult:
    """N Monte Carlo runs of the linear observer with gain L (see
    :func:`obsdesign.simulate.montecarlo.run_batch`; a plant given by expressions:
    :func:`obsdesign.simulate.nonlinear.batch_stepper`): run r draws its initial error from the
    set ``initial_error`` of ``[sets]`` (default: xhat0 − x0 for every run) and its signals
    from child r of ``SeedSequence(seed).spawn(runs)``; ``batch`` caps the runs stepped
    together (default: ``montecarlo.BATCH_RUNS``, fewer when their draws do not fit
    ``montecarlo.BATCH_BYTES``). Per-run metrics in ``extra["per_run"]``,
    quantiles in ``info["quantiles"]``; the trajectory shown is run 0's. ``span = (a, b)``:
    only runs a..b-1 (``simulate --workers``, see :func:`~obsdesign.simulate.montecarlo.merge`).
    ``budget``: the time budget, looked at per batch and per chunk of steps.
    """
    from obsdesign.simulate import montecarlo as mc

    if spec.system.linear:
        js = joint_system(spec, L, error=True)
        return mc.run_batch(spec, js, runs, initial_error, batch=batch, span=span, budget=budget)
    from obsdesign.simulate.nonlinear import batch_stepper

    grid, per_run, step = batch_stepper(spec, L, budget)
    return mc.study(spec, grid, runs, initial_error, batch, span, per_run, step, budget)
