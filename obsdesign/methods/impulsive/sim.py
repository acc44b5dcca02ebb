"""Simulation of the impulsive observer (11) for a spec, and its plots (Figs. 3-6 of paper 001).

Scenarios, all with the same seeded sampling sequences (intervals uniform in the certified
window [T_min, T_max], or read from a file), the first sample after one interval:

- ``noise``: measurement noise from ``[simulate.noise]`` at the sample instants (Fig. 5);
- ``clean``: the same sequences without noise — the error must decay (Fig. 6);
- ``open``: one run without injection, L = 0 (Fig. 4).

The report says, per run, whether ‖ε‖ (z-coordinates, ε = ẑ − z of (12)) ends inside
B = {‖ε‖ ≤ √(α‖w‖∞)} and the last time it was outside.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from obsdesign.certify.printing import fmt_exact
from obsdesign.errors import InputError
from obsdesign.methods.impulsive.hybrid import (
    HybridBatch,
    ball_report,
    draw_intervals,
    intervals_drawn,
    pad_to_horizon,
    simulate_hybrid,
)
from obsdesign.methods.impulsive.options import SimOptions
from obsdesign.methods.impulsive.plant import plant_field, psi_callable
from obsdesign.params import Parameters
from obsdesign.simulate.budget import TimeBudget
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec


def read_intervals(path: Path) -> np.ndarray:
    """Sampling intervals from a text file: numbers separated by whitespace/commas/newlines.
    Read through :func:`obsdesign.limits.read_input` (a regular file within
    ``max_file_bytes``): /dev/zero ran out of memory and a FIFO blocked forever (CLI fuzzer)."""
    from obsdesign.limits import read_input

    try:
        txt = read_input(path, "sampling-interval").decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{path}: sampling file is not UTF-8 text") from None
    try:
        vals = np.array([float(t) for t in txt.replace(",", " ").split()], dtype=float)
    except ValueError:
        raise InputError(f"{path}: expected numbers (sampling intervals)") from None
    if vals.size == 0 or np.any(~np.isfinite(vals)) or np.any(vals <= 0):
        raise InputError(f"{path}: expected positive sampling intervals")
    return vals


def check_memory(
    runs: int, samples: float, n: int, dense: int = 8, file: str = "", why: str = ""
) -> None:
    """Refuse (:class:`InputError`) a simulation whose arrays would exceed the
    ``max_sim_bytes`` limit: two batches of ``runs`` trajectories with ``samples`` intervals
    of ``dense`` points, each point holding t, x, ẑ (n each) and flags, as float64. Counted
    in floats, so that horizon = 1e300 is a clear refusal (it printed a 295-digit number of
    GiB, with no file named; independent simulate review).

    :param runs: runs; :param samples: sampling intervals per run; :param n: states;
    :param dense: points per interval; :param file: the spec file, for the message;
    :param why: where the sample count comes from, for the message."""
    from obsdesign.limits import limits

    r, k = float(runs), float(samples)
    need = 2.0 * r * (k * dense + 1.0) * (2 * n + 3) * 8.0 + r * k * 8.0 * 3
    cap = limits().max_sim_bytes
    if not need <= cap:  # NaN or inf included
        where = f"{file}: " if file else ""
        raise InputError(
            f"{where}the simulation would need about {need / 2**30:.3g} GiB "
            f"({runs:,} runs × {k:.3g} samples × {n} states{why}); the limit is "
            f"{cap / 2**30:.3g} GiB (fewer runs, a shorter horizon, or "
            "obsdesign --limit max_sim_bytes=...)"
        )


def simulate(
    spec: Spec,
    params: Parameters,
    runs: int | None = None,
    seed: int | None = None,
    sampling_file: Path | None = None,
    rtol: float | None = None,
    time_limit: float | None = None,
) -> SimResult:
    """Run the three scenarios. ``runs``, ``seed``, ``sampling_file``, ``rtol``,
    ``time_limit`` (typed values of ``simulate --option``, validated by the API) override the
    spec's ``[simulate]``. Past ``time_limit`` seconds (all three scenarios together) the
    simulation stops with :class:`~obsdesign.simulate.budget.TimeExceeded` (exit 3) saying how far it got."""
    o = spec.options
    sim = spec.simulate
    if sim is None:
        raise InputError(f"{spec.file}: no [simulate] table")
    so: SimOptions = sim.options if isinstance(sim.options, SimOptions) else SimOptions()
    runs = so.runs if runs is None else int(runs)
    seed = sim.seed if seed is None else int(seed)
    # where the path came from, for its errors (they named the file only: review 20)
    given_by = (
        f"[simulate.sampling_file] of {spec.file}"
        if sampling_file is None
        else "--option sampling_file"
    )
    sampling_file = so.sampling_file if sampling_file is None else Path(sampling_file)
    rtol = so.rtol if rtol is None else float(rtol)
    budget = TimeBudget(
        so.time_limit if time_limit is None else float(time_limit),
        "raise time_limit, or fewer runs, a shorter horizon, a looser rtol, or intervals "
        "within the window [T_min, T_max]",
    )
    horizon = float(sim.horizon.f)
    T = np.asarray(params.float("T"), dtype=float)
    Ld = np.array([float(v) for v in o.problem.L])
    m = len(Ld)
    t_lo, t_hi = params.float("T_min"), params.float("T_max")
    radius = params.float("ball_radius")
    n = spec.system.n
    if sampling_file is not None:
        try:
            h = read_intervals(sampling_file)
        except InputError as e:
            raise InputError(f"{e} (the sampling file of {given_by})") from None
        runs = 1
        check_memory(1, h.size, n, file=spec.file)
        H = pad_to_horizon(h[None, :], horizon)
        if H.shape[1] == 0 or np.sum(H) < horizon * 0.999:
            raise InputError(
                f"{sampling_file}: the intervals do not cover the horizon {horizon:g} (the "
                f"sampling file of {given_by})"
            )
    else:
        if not 0 < t_lo <= t_hi:
            raise InputError(f"report: expected 0 < T_min ≤ T_max, got {t_lo:g}, {t_hi:g}")
        # the count comes from T_min: a valid design with α = 1e30 (T_min ≈ 3·10⁻¹⁶) was
        # refused for 2.6·10¹¹ GiB without a word of why (soundness trial, session 34)
        why = (
            f"; ⌈horizon / T_min⌉ + 1 intervals of each run are drawn first, T_min = "
            f"{t_lo:.3g} (26c): a smaller [method.alpha] or a sampling file avoids it"
        )
        check_memory(runs, np.ceil(horizon / t_lo) + 1, n, file=spec.file, why=why)
    # run r draws from its own generator, child r of SeedSequence(seed): first its sampling
    # intervals, then its noise, each of a length that does not depend on the other runs, so
    # run r's numbers do not depend on the number of runs (docs/spec.md). One generator for
    # all runs made run 0's noise, and the printed metrics, change with --runs (final ε of
    # run 0: 0.059 / 0.051 / 0.0087 for 1 / 3 / 5 runs; simulate-correctness trial, session 25)
    rngs = [np.random.default_rng(c) for c in np.random.SeedSequence(seed).spawn(runs)]
    if sampling_file is None:
        H = draw_intervals(rngs, t_lo, t_hi, horizon)
    K = H.shape[1]
    Dn = spec.system.Dn.f
    k_all = K if sampling_file is not None else intervals_drawn(t_lo, horizon)
    W = np.stack([sim.noise.evaluate(np.arange(k_all, dtype=float), g)[:K] @ Dn.T for g in rngs])
    # noise_bound bounds the Euclidean norm of w_k (docs/methods/impulsive.md, "Noise"): the
    # largest component alone let w = (0.09, −0.09), ‖w‖ = 0.127, pass a bound of 0.1
    # (independent simulate review)
    # (over the samples that end an interval of their run, H > 0: a shorter run's padded
    # positions draw noise that no jump uses; simulate-correctness trial, session 25)
    used = np.linalg.norm(W, axis=-1)[H > 0] if W.size else np.zeros(0)
    w_max = float(np.max(used)) if used.size else 0.0
    w_bar = params.float("w_bar")
    if w_max > w_bar:
        warnings.warn(
            f"[simulate] the noise reaches ‖w_k‖ = {w_max:.4g} > noise_bound = {w_bar:g} of "
            "the design: the runs are outside the premise of Theorem 2 and the radius of B",
            stacklevel=2,
        )
    f = plant_field(spec)
    split = (spec.system.A.f, psi_callable(spec))  # f = Ax + ψ(x): the error's linear part
    x0 = np.tile(sim.x0.f, (runs, 1))
    xh0 = np.tile(sim.xhat0.f, (runs, 1))

    def stage(name: str) -> Callable[[int, int], None]:
        def check(k: int, K: int) -> None:
            if budget.expired():
                longest = float(np.max(H[:, k])) if k < H.shape[1] else 0.0
                budget.check(
                    f"the {name} runs at sampling interval {k:,} of {K:,}, of length up to "
                    f"{longest:.4g}"
                )

        return check

    # a plant that leaves the float range stops its run (``escaped``), counted in the metrics
    # and said once below in words, not as numpy's overflow warnings (review: x0 = 1e300)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        noisy = simulate_hybrid(
            f, T, Ld, x0, xh0, H, W, rtol=rtol, check=stage("noisy"), split=split
        )
        clean = simulate_hybrid(
            f,
            T,
            Ld,
            x0,
            xh0,
            H,
            np.zeros_like(W),
            rtol=rtol,
            check=stage("noise-free"),
            split=split,
        )
        open_ = simulate_hybrid(
            f,
            T,
            np.zeros(m),
            x0[:1],
            xh0[:1],
            H[:1],
            W[:1],
            rtol=rtol,
            check=stage("open-loop"),
            split=split,
        )
    if noisy.escaped.any() or clean.escaped.any() or open_.escaped.any():
        warnings.warn(
            "the plant leaves the float range (or its field is not finite) in "
            f"{int(noisy.escaped.sum())} of {runs} noisy "
            f"runs and {int(clean.escaped.sum())} noise-free runs (from x0 = "
            f"{np.array2string(sim.x0.f, precision=4)}): those runs stop there, the error is "
            "not defined beyond (plant_escaped_runs); a smaller x0 or horizon keeps it finite",
            stacklevel=2,
        )
    after = horizon / 2
    br = ball_report(noisy, radius, after)
    used = H[H > 0]
    inside = _in_window(used, t_lo, t_hi, params["T_min"], params["T_max"])
    in_window = bool(np.all(inside))
    if not in_window:
        # the noise beyond noise_bound was warned of, these not: "intervals_in_window: False"
        # beside "noise_free_decay: True" read as confirming the certificate (soundness
        # trial, session 30)
        out = used[~inside]
        warnings.warn(
            # the doubles themselves (shortest repr): at 6 digits 0.417599999999, just below
            # T_min = 0.4176, printed as 0.4176 (impulsive review, session 42)
            f"[simulate] {out.size:,} of {used.size:,} sampling intervals (from "
            f"{float(out.min())!r} to {float(out.max())!r}) lie outside the certified window "
            f"T_min = {fmt_exact(params['T_min'])} < t_(k+1) − t_k < T_max = "
            f"{fmt_exact(params['T_max'])}: the runs are outside the premise of Theorems 1-2, "
            "and their decay says nothing of the certificate",
            stacklevel=2,
        )
    valid0 = noisy.valid[0]
    cl_end = np.array([clean.eps[j, np.nonzero(clean.valid[j])[0][-1]] for j in range(runs)])
    cl_start = clean.eps[:, 0]
    info = {
        "time": "continuous",
        "runs": runs,
        "window": [t_lo, t_hi],
        "intervals_in_window": in_window,
        "interval_min_max": [float(used.min()), float(used.max())],
        "ball_radius": radius,
        "noise_max_norm": w_max,
        "runs_ending_in_ball": int(br.entered.sum()),
        "max_settle_time": float(np.nanmax(br.settle_time)) if br.entered.any() else None,
        # None when no run reaches t > after (every run diverged or escaped before): was
        # numpy's "All-NaN slice encountered" warning and a NaN
        f"worst_eps_after_t{after:g}": (
            None if np.all(np.isnan(br.worst_after)) else float(np.nanmax(br.worst_after))
        ),
        "diverged_runs": int(noisy.diverged.sum()),
        "plant_escaped_runs": int(noisy.escaped.sum()),
        "noise_free_final_eps_max": float(cl_end.max()),
        # a run that starts at ε = 0 decays when it stays there: the strict < alone printed
        # "noise_free_decay: False" beside "noise_free_final_eps_max: 0.0" for x̂_0 = x_0
        # (simulate review, session 36)
        "noise_free_decay": bool(
            np.all((cl_end < cl_start) | ((cl_start == 0) & (cl_end == 0)))
            and not clean.diverged.any()
        ),
        "open_loop_final_eps": float(open_.eps[0, np.nonzero(open_.valid[0])[0][-1]]),
        # where the open-loop run stopped before the horizon (its error blew up, or the plant
        # left the float range), its "final" ε is the one at that stop: the same 3.5·10⁸ was
        # printed for horizons 3 and 11.5 without a word (re-check review, session 42)
        "open_loop_stopped_at": (
            float(open_.t[0, np.nonzero(open_.valid[0])[0][-1]])
            if bool(open_.diverged[0] or open_.escaped[0])
            else None
        ),
    }
    info["quantiles"] = run_quantiles(noisy, list(spec.system.states))
    res = SimResult(
        noisy.t[0, valid0],
        noisy.x[0, valid0],
        noisy.xhat[0, valid0],
        None,
        list(spec.system.states),
        {},
        info,
        error=noisy.err[0, valid0],
    )
    res.extra = {
        "noisy": noisy,
        "clean": clean,
        "open": open_,
        "radius": radius,
        "after": after,
        "intervals": H,  # (runs, K) sampling intervals, 0 past a run's end
        "noise": W,  # (runs, K, m) w_k at the sample ending interval k
    }
    return res


def _in_window(h: np.ndarray, lo: float, hi: float, T_min: Any, T_max: Any) -> np.ndarray:
    """Whether each interval h lies in the open window T_min < h < T_max (Theorems 1-2),
    exactly: ``lo``, ``hi`` are the doubles nearest to T_min, T_max, so h > lo (h < hi) already
    implies h > T_min (h < T_max); only an h equal to one of them is compared as a rational
    (it was h ≥ lo and h ≤ hi: a closed window, and in floats)."""
    from flint import fmpq

    ok = (h > lo) & (h < hi)
    for i in np.nonzero((h == lo) | (h == hi))[0]:
        q = fmpq(*float(h[i]).as_integer_ratio())
        ok[i] = bool(T_min < q < T_max)
    return ok


def run_quantiles(b: HybridBatch, states: list[str]) -> dict[str, Any]:
    """Quantiles over the runs (:func:`obsdesign.simulate.montecarlo.quantiles`: q05, q50,
    q95, max) of each run's metrics, computed as run 0's printed ones are (sup |e_i|, RMSE of
    e_i and sup |x̂_i| over its dense points before it stopped, final |e|), e = x̂ − x as
    stepped by its own dynamics (:attr:`HybridBatch.err`).

    :param b: the noisy runs; :param states: the state names."""
    from obsdesign.simulate.montecarlo import METRICS, quantiles

    per: dict[str, list[Any]] = {k: [] for k in METRICS}
    for j in range(b.x.shape[0]):
        v = b.valid[j]
        m = SimResult(b.t[j, v], b.x[j, v], b.xhat[j, v], None, states, error=b.err[j, v])
        m = m.metrics()
        for k in ("sup_abs_error", "rmse", "sup_abs_estimate"):
            per[k].append([m[k][st] for st in states])
        per["final_error_norm"].append(m["final_error_norm"])
    return quantiles({k: np.asarray(v, dtype=float) for k, v in per.items()}, states)


#: states drawn in the time panels of :func:`plot_simulation` (the title says when more
#: exist: x4 of a 4-state plant was dropped without a word until session 30)
PLOT_STATES = 6


def plot_simulation(spec: Spec, res: SimResult, path: str | Path) -> Path:
    """Phase portrait (Fig. 3), no injection (Fig. 4), with noise (Fig. 5), without noise
    (Fig. 6), and ‖ε‖ of every run against the radius of B."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from obsdesign.simulate.plot import plain, save_figure

    ex = res.extra
    fig, axes = plt.subplots(2, 3, figsize=(15, 8))
    f = plant_field(spec)
    ax = axes[0, 0]
    lo = np.minimum(res.x.min(0), res.xhat.min(0))[:2]
    hi = np.maximum(res.x.max(0), res.xhat.max(0))[:2]
    pad = 0.2 * (hi - lo) + 0.5
    gx, gy = np.meshgrid(
        np.linspace(lo[0] - pad[0], hi[0] + pad[0], 40),
        np.linspace(lo[1] - pad[1], hi[1] + pad[1], 40),
    )
    names = spec.system.states
    n = spec.system.n
    if n == 2:
        V = f(np.stack([gx, gy], -1).reshape(-1, 2)).reshape(40, 40, 2)
        ax.streamplot(gx, gy, V[..., 0], V[..., 1], density=1.0, color="0.6", linewidth=0.7)
    # n > 2: the trajectories' projection on the first two states (no field: it depends on
    # the others); the panel was left empty for n ≠ 2 (soundness trial, session 30)
    ax.plot(res.x[:, 0], res.x[:, 1], "k-", lw=1.2, label="plant")
    ax.plot(res.xhat[:, 0], res.xhat[:, 1], "r--", lw=1.2, label="observer")
    ax.legend(fontsize=8)
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1])
    ax.set_title(
        "phase portrait (Fig. 3)"
        if n == 2
        else f"phase portrait (Fig. 3), projection of {n} states"
    )
    shown = min(n, PLOT_STATES)
    more = f" — first {shown} of {n} states" if shown < n else ""
    for ax, key, title in (
        (axes[0, 1], "open", "no injection (Fig. 4)"),
        (axes[0, 2], "noisy", "with noise (Fig. 5)"),
        (axes[1, 0], "clean", "without noise (Fig. 6)"),
    ):
        b = ex[key]
        v = b.valid[0]
        for i in range(shown):
            line = ax.plot(b.t[0, v], b.x[0, v, i], "-", lw=1.1, label=names[i])[0]
            ax.plot(b.t[0, v], b.xhat[0, v, i], "--", color=line.get_color(), lw=1.1)
        ax.set_title(title + more)
        ax.set_xlabel("t")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    ax = axes[1, 1]
    b = ex["noisy"]
    for j in range(b.t.shape[0]):
        v = b.valid[j]
        ax.semilogy(b.t[j, v], np.maximum(b.eps[j, v], 1e-12), lw=0.6, alpha=0.6)
    ax.axhline(ex["radius"], color="k", ls="--", label=f"radius of B = {ex['radius']:.4g}")
    ax.set_title("‖ε(t)‖, all runs, with noise")
    ax.set_xlabel("t")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[1, 2]
    st = b.sample_times
    h = np.diff(np.concatenate([np.zeros((st.shape[0], 1)), st], axis=1), axis=1)
    ax.hist(h[np.isfinite(h)], bins=30, color="0.5")
    w = res.info["window"]
    ax.axvline(w[0], color="r")
    ax.axvline(w[1], color="r")
    ax.set_title("sampling intervals vs [T_min, T_max]")
    fig.suptitle(plain(spec.title or "impulsive observer"))
    fig.tight_layout()
    return save_figure(fig, path)
