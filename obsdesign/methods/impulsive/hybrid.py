"""The hybrid observer (11) run on many sampling sequences at once.

Flow (11a): ż̂ = Ā ẑ + ψ̄(ẑ) = T f(T⁻¹ ẑ) between samples, with the plant ẋ = f(x) = A x + ψ(x);
jump (11b): ẑ_o⁺ = ẑ_o − L (ẑ_o − y_k), y_k = C x(t_k) + w_k (impulsive-dissipativity paper 001).

Batching: each trajectory j has its own sampling intervals h_{j,k}. On interval k we integrate
every trajectory over the *normalized* time s ∈ [0, 1] (t = t_{j,k-1} + s·h_{j,k}), i.e.
dx/ds = h_{j,k} f(x): all trajectories then share one time axis and one scipy RK45 (dopri5)
call integrates them together; zero-length (padding) intervals stay still. This gives the
same solution as integrating each trajectory with solve_ivp (to the tolerance), many times
faster because the Python overhead is paid once per interval instead of once per
trajectory and interval.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

VectorField = Callable[[np.ndarray], np.ndarray]  # (N, n) -> (N, n)


@dataclass
class HybridBatch:
    """Trajectories of N runs on per-run time grids.

    ``t``: (N, G) times; ``x``, ``xhat``: (N, G, n); ``eps``: (N, G) ‖ẑ − z‖ (z-coordinates,
    the ε of (12)); ``err``: (N, G, n) the error x̂ − x = T⁻¹ε, stepped by its own dynamics
    (not the difference of x̂ and x: on an escaping plant that difference of two numbers near
    10¹⁵⁰ printed final |e| = 0.0 and sup |e| ~ 10¹³² for a certified design; re-check review,
    session 41); ``valid``: (N, G) mask (False on padding after the horizon or after a
    run stopped); ``sample_times``: (N, K) instants t_k (NaN for padding); ``diverged``:
    (N,) runs stopped because the *error* blew up (ε above ``blowup``·max(1, ε(0)) and above
    10⁻³‖z‖, or not finite); ``escaped``: (N,) runs stopped because the *plant* left the float range
    (‖x‖ above :data:`ESCAPE`, an unstable plant over a long horizon: not an observer
    failure).
    """

    t: np.ndarray
    x: np.ndarray
    xhat: np.ndarray
    eps: np.ndarray
    err: np.ndarray
    valid: np.ndarray
    sample_times: np.ndarray
    diverged: np.ndarray
    escaped: np.ndarray


#: a run stops when its plant state exceeds this (products of such states would overflow)
ESCAPE = 1e150


def intervals_drawn(t_lo: float, horizon: float) -> int:
    """How many intervals each run draws: ⌈horizon / t_lo⌉ + 1, enough to pass the horizon
    whatever the draws (the same for every run, so a run's draws do not depend on the others).

    :param t_lo: the shortest interval (> 0); :param horizon: the simulated time."""
    return int(np.ceil(horizon / t_lo)) + 1


def draw_intervals(
    rngs: Sequence[np.random.Generator], t_lo: float, t_hi: float, horizon: float
) -> np.ndarray:
    """Sampling intervals uniform in [t_lo, t_hi) until each run passes ``horizon``, run r
    drawing :func:`intervals_drawn` of them from ``rngs[r]``; (runs, K), padded with zeros
    (K = the longest run).

    :param rngs: one generator per run (the same one repeated draws the runs in turn)."""
    k = intervals_drawn(t_lo, horizon)
    H = np.array([g.uniform(t_lo, t_hi, size=k) for g in rngs]).reshape(len(rngs), k)
    return pad_to_horizon(H, horizon)


def pad_to_horizon(H: np.ndarray, horizon: float) -> np.ndarray:
    """Zero every interval that starts at or after ``horizon``; trim all-zero columns."""
    H = np.array(H, dtype=float)
    start = np.cumsum(H, axis=1) - H
    H[start >= horizon] = 0.0
    keep = np.any(H > 0, axis=0)
    last = int(np.max(np.nonzero(keep)[0])) + 1 if keep.any() else 0
    return H[:, :last]


def simulate_hybrid(
    f: VectorField,
    T: np.ndarray,
    L_diag: np.ndarray,
    x0: np.ndarray,
    xhat0: np.ndarray,
    H: np.ndarray,
    W: np.ndarray,
    dense: int = 8,
    rtol: float = 1e-7,
    atol: float = 1e-9,
    blowup: float = 1e8,
    check: Callable[[int, int], None] | None = None,
    split: tuple[np.ndarray, VectorField] | None = None,
) -> HybridBatch:
    """Run plant + observer (11) for N runs: x0, xhat0 (N, n); H (N, K) intervals (0 = padding);
    W (N, K, m) noise w_k at the sample ending interval k. ``dense`` points per interval.
    The output at a sample is y_k = C x(t_k) + w_k with C the first m rows of T = [C; M].
    ``check(k, K)`` runs before each interval k of K (a time budget may raise there).

    Integrated are the plant x and the error ε = ẑ − Tx of (12) (z-coordinates), not ẑ:
    flow ε̇ = T(f(x + T⁻¹ε) − f(x)), which with ``split`` = (A, ψ), f(x) = Ax + ψ(x) of (1a),
    is Āε + T(ψ(x + T⁻¹ε) − ψ(x)), Ā = TAT⁻¹, its linear part free of x; jump (11b)
    ε_o⁺ = ε_o − L(ε_o − w_k). The estimate is ẑ = Tx + ε. Stepping ẑ and differencing lost
    every digit of ε once ‖x‖ passed 10¹⁶‖ε‖ (an unstable plant; re-check review, session
    41). The nonlinear part ψ(x + T⁻¹ε) − ψ(x) is still a difference of doubles at x, so it
    loses its digits there too (docs/methods/impulsive.md, "Simulation").
    """
    x0 = np.atleast_2d(np.asarray(x0, dtype=float))
    xhat0 = np.atleast_2d(np.asarray(xhat0, dtype=float))
    N, n = x0.shape
    K = H.shape[1]
    m = W.shape[2] if W.ndim == 3 else 1
    T = np.asarray(T, dtype=float)
    Ti = np.linalg.inv(T)
    Ld = np.asarray(L_diag, dtype=float).reshape(1, m)

    if split is not None:
        Abar = T @ np.asarray(split[0], dtype=float) @ Ti
        psi = split[1]

        def fe(X: np.ndarray, E: np.ndarray, dX: np.ndarray) -> np.ndarray:
            return E @ Abar.T + (psi(X + E @ Ti.T) - psi(X)) @ T.T

    else:

        def fe(X: np.ndarray, E: np.ndarray, dX: np.ndarray) -> np.ndarray:
            return (f(X + E @ Ti.T) - dX) @ T.T

    G = K * dense + 1
    t = np.zeros((N, G))
    xs = np.zeros((N, G, n))
    es = np.zeros((N, G, n))
    valid = np.zeros((N, G), dtype=bool)
    X = x0.copy()
    with np.errstate(all="ignore"):
        Z = (xhat0 - x0) @ T.T  # the error ε (12), not ẑ
        xs[:, 0], es[:, 0], valid[:, 0] = X, Z, True
        e0 = np.nan_to_num(np.linalg.norm(Z, axis=1), posinf=np.inf)
    diverged = np.zeros(N, dtype=bool)
    with np.errstate(all="ignore"):  # a start already beyond ESCAPE (or not finite)
        escaped = ~np.all(np.isfinite(X), axis=1) | (np.abs(X).max(axis=1) > ESCAPE)
        diverged = ~escaped & ~np.all(np.isfinite(Z), axis=1)
    s_eval = np.linspace(0.0, 1.0, dense + 1)[1:]
    tk = np.zeros(N)
    sample_times = np.full((N, K), np.nan)
    for k in range(K):
        if check is not None:
            check(k, K)
        h = np.where(diverged | escaped, 0.0, H[:, k])
        active = h > 0
        if not active.any():
            break

        calls = [0]
        # runs whose field is not finite in this interval: frozen (derivative 0), then
        # stopped as escaped (the plant's field) or diverged (the observer's). RK45 shrank its
        # step on a NaN field until time_limit (ψ of the shipped example at x0 = 1e160, or a
        # sampling interval of 1e300; independent simulate review)
        bad_x = np.zeros(N, dtype=bool)
        bad_z = np.zeros(N, dtype=bool)

        def rhs(
            _s: float,
            u: np.ndarray,
            h: np.ndarray = h,
            k: int = k,
            calls: list[int] = calls,
            bad_x: np.ndarray = bad_x,
            bad_z: np.ndarray = bad_z,
        ) -> np.ndarray:
            # the time budget inside the interval too: with NaN or huge dynamics RK45
            # shrinks its step without end (time_limit = 5 ran past 60 s: CLI fuzzer)
            calls[0] += 1
            if check is not None and calls[0] % 256 == 0:
                check(k, K)
            U = u.reshape(N, 2, n)
            with np.errstate(all="ignore"):
                dX = f(U[:, 0])
                d = np.stack([dX, fe(U[:, 0], U[:, 1], dX)], axis=1)
                d *= h[:, None, None]
            bad_x |= ~np.all(np.isfinite(d[:, 0]), axis=1)
            bad_z |= ~np.all(np.isfinite(d[:, 1]), axis=1)
            d[bad_x | bad_z] = 0.0
            return d.ravel()

        sol = solve_ivp(
            rhs,
            (0.0, 1.0),
            np.stack([X, Z], 1).ravel(),
            method="RK45",
            t_eval=s_eval,
            rtol=rtol,
            atol=atol,
        )
        if sol.status != 0 or sol.y.shape[1] != dense:
            raise ArithmeticError(f"integration failed on interval {k}: {sol.message}")
        U = sol.y.reshape(N, 2, n, dense)
        frozen = bad_x | bad_z
        active = active & ~frozen
        escaped |= bad_x
        diverged |= bad_z & ~bad_x
        X[frozen], Z[frozen] = 0.0, 0.0
        cols = slice(1 + k * dense, 1 + (k + 1) * dense)
        t[:, cols] = tk[:, None] + h[:, None] * s_eval[None, :]
        xs[:, cols] = np.moveaxis(U[:, 0], 2, 1)
        es[:, cols] = np.moveaxis(U[:, 1], 2, 1)
        valid[:, cols] = active[:, None]
        X = np.where(active[:, None], U[:, 0, :, -1], X)
        Z = np.where(active[:, None], U[:, 1, :, -1], Z)
        tk = tk + h
        # jump (11b) at t_k = end of interval k, only for runs that really sampled:
        # y_k = C x(t_k) + w_k = (T x)_o + w_k, T = [C; M] (eq. (9)), so in the error
        # ε_o⁺ = ẑ_o⁺ − (Tx)_o = ε_o − L(ε_o − w_k)
        Zo = Z[:, :m] - Ld * (Z[:, :m] - W[:, k, :])
        Z[:, :m] = np.where(active[:, None], Zo, Z[:, :m])
        sample_times[:, k] = np.where(active, tk, np.nan)
        with np.errstate(all="ignore"):
            xmax = np.abs(X).max(axis=1)
            out = ~np.all(np.isfinite(X), axis=1) | (xmax > ESCAPE)
            e = np.linalg.norm(Z, axis=1)
            zn = np.linalg.norm(X @ T.T, axis=1)
        big = (e > blowup * np.maximum(1.0, e0)) & (e > 1e-3 * zn)
        bad = ~out & (~np.all(np.isfinite(Z), axis=1) | big)
        stop = bad | out
        if stop.any():
            diverged |= bad
            escaped |= out
            X[stop], Z[stop] = 0.0, 0.0
        # the post-jump value is what the next interval starts from; the stored point at t_k
        # is the pre-jump (left-continuous) value, as in the paper.
    with np.errstate(all="ignore"):  # runs that escaped: their values are not finite
        err = es @ Ti.T
        xhat = xs + err
        eps = np.linalg.norm(es, axis=2)
    return HybridBatch(t, xs, xhat, eps, err, valid, sample_times, diverged, escaped)


def simulate_one_by_one(
    f: VectorField,
    T: np.ndarray,
    L_diag: np.ndarray,
    x0: np.ndarray,
    xhat0: np.ndarray,
    h: np.ndarray,
    w: np.ndarray,
    rtol: float = 1e-7,
    atol: float = 1e-9,
    final_jump: bool = True,
) -> np.ndarray:
    """Reference: one trajectory, one solve_ivp call per interval; returns [x; ẑ] at the end
    (after the last jump unless ``final_jump`` is False).

    Used by the benchmark and the tests to check :func:`simulate_hybrid` against it."""
    T = np.asarray(T, dtype=float)
    Ti = np.linalg.inv(T)
    n = len(x0)
    m = np.size(L_diag)
    X = np.asarray(x0, dtype=float).copy()
    Z = T @ np.asarray(xhat0, dtype=float)
    for k, hk in enumerate(h):
        if hk <= 0:
            continue

        def rhs(_t: float, u: np.ndarray) -> np.ndarray:
            return np.concatenate([f(u[None, :n])[0], T @ f((Ti @ u[n:])[None, :])[0]])

        sol = solve_ivp(rhs, (0.0, hk), np.concatenate([X, Z]), method="RK45", rtol=rtol, atol=atol)
        X, Z = sol.y[:n, -1].copy(), sol.y[n:, -1].copy()
        if not final_jump and k == len(h) - 1:
            break
        Z[:m] = Z[:m] - np.asarray(L_diag, dtype=float) * (Z[:m] - ((T @ X)[:m] + w[k]))
    return np.concatenate([X, Z])


@dataclass
class BallReport:
    """Whether ‖ε‖ enters B = {‖ε‖ ≤ r} and stays (Theorem 2), per run."""

    radius: float
    entered: np.ndarray  # (N,) bool: inside B at the end of the horizon
    settle_time: (
        np.ndarray
    )  # (N,) last time ‖ε‖ > r (0 if never outside), NaN if not inside at the end
    worst_after: np.ndarray  # (N,) max ‖ε‖ after ``after`` (NaN if no point after)
    after: float


def ball_report(b: HybridBatch, radius: float, after: float) -> BallReport:
    """Settling into B: the last instant each run is outside B, and the worst ‖ε‖ after
    ``after`` (a transient allowance)."""
    out = (b.eps > radius) & b.valid
    N = b.t.shape[0]
    last_out = np.where(out.any(axis=1), np.max(np.where(out, b.t, -np.inf), axis=1), 0.0)
    last_idx = np.array([np.max(np.nonzero(b.valid[j])[0]) for j in range(N)])
    inside_end = b.eps[np.arange(N), last_idx] <= radius
    inside_end &= ~(b.diverged | b.escaped)
    settle = np.where(inside_end, last_out, np.nan)
    mask = b.valid & (b.t > after)
    worst = np.where(mask.any(axis=1), np.max(np.where(mask, b.eps, -np.inf), axis=1), np.nan)
    return BallReport(radius, inside_end, settle, worst, after)
