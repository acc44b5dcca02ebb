"""Batched Monte Carlo runs of a joint linear plant + observer system
(:class:`obsdesign.simulate.linear.JointSystem`): N initial errors and N signal draws, stepped
together over a batch axis, with per-run metrics and their quantiles.

Randomness: run r uses ``numpy.random.default_rng(SeedSequence(seed).spawn(runs)[r])`` (seed
= ``[simulate] seed``): first its initial error (when ``[simulate] initial_error`` names a
set of ``[sets]``: one point drawn by the set's ``sample``; else xhat0 − x0 for every run),
then its input, disturbance and noise signals in that order (only when one of them is random;
a signal with its own ``seed``, or a deterministic one, is the same in every run). So run r's
draws do not depend on how many runs there are or how they are batched. The batch step is
one row-layout product Z @ Mᵀ (a 2-D product even for one run); with the OpenBLAS build
numpy ships its rows are bitwise the same for any batch size (tested in
tests/test_simulate_montecarlo.py), with another BLAS they agree to rounding.

``[simulate] initial_error = "NAME"`` is read by :func:`parse_initial_error`, which a method
calls from its ``parse_simulate``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from obsdesign.errors import InputError
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

#: memory of one batch (trajectory chunk + per-run signals), bytes
BATCH_BYTES = 128 * 2**20
#: steps stepped between two metric updates (a fixed number, so that batching cannot change
#: how the RMSE sums are rounded)
STEPS = 256
#: quantiles reported for every per-run metric
QUANTILES = {"q05": 0.05, "q50": 0.5, "q95": 0.95}
METRICS = ("sup_abs_error", "rmse", "sup_abs_estimate", "final_error_norm")


def parse_initial_error(table: Table, spec: Spec) -> str | None:
    """``[simulate] initial_error``: the name of a set in ``[sets]`` of dimension n from
    which each Monte Carlo run draws its initial error x̂0 − x0 (None: xhat0 − x0)."""
    name = table.str("initial_error", default=None)
    if name is None:
        return None
    if name not in spec.sets:
        known = ", ".join(sorted(spec.sets)) or "none"
        raise table.error("initial_error", f"expected the name of a set in [sets] (known: {known})")
    dim = spec.sets[name].dim
    if dim != spec.system.n:
        raise table.error(
            "initial_error", f"expected a set of dimension {spec.system.n} (states), got {dim}"
        )
    return name


def _random(sig: Any) -> bool:
    return sig.kind in ("uniform", "outliers") and sig.seed is None


def run_seeds(seed: int, runs: int) -> list[np.random.SeedSequence]:
    """The N independent child seeds of ``seed`` (numpy ``SeedSequence.spawn``)."""
    return np.random.SeedSequence(seed).spawn(runs)


def run_batch(
    spec: Spec,
    js: Any,
    runs: int,
    initial_error: str | None = None,
    batch: int | None = None,
    span: tuple[int, int] | None = None,
) -> SimResult:
    """``runs`` runs of ``js`` (a :class:`~obsdesign.simulate.linear.JointSystem` of the
    bound ``spec``); ``initial_error``: a set name of ``[sets]`` (None: xhat0 − x0);
    ``batch``: runs stepped together (None: as many as fit :data:`BATCH_BYTES`);
    ``span = (a, b)``: only runs a..b-1 of the ``runs`` (same child seeds as in the full
    range, so run r is the same whatever the span: :func:`merge` joins spans; None: all).

    Returns run 0's trajectory with ``info`` = runs, where the initial errors come from and
    the quantiles of every per-run metric, and ``extra["per_run"]`` = the per-run metrics
    (sup |e_i|, RMSE of e_i, sup |x̂_i|: arrays (runs, n); final |e|: (runs,)) and
    ``extra["initial_errors"]`` (runs, n)."""
    sim, s = spec.simulate, spec.system
    if sim is None:
        raise InputError(f"{spec.file}: [simulate] is missing: nothing to simulate")
    if runs < 1:
        raise InputError(f"runs: expected at least 1, got {runs}")
    first, last = span if span is not None else (0, runs)
    if not 0 <= first < last <= runs:
        raise InputError(f"span: expected 0 <= a < b <= {runs}, got ({first}, {last})")
    n, grid = js.n, js.grid
    K = len(grid) - 1
    x0, xhat0 = sim.x0.f, sim.xhat0.f
    if initial_error is not None and initial_error not in spec.sets:
        raise InputError(f"{spec.file}: initial_error = {initial_error!r} is not in [sets]")
    eset = spec.sets[initial_error] if initial_error is not None else None
    sigs = (sim.u, sim.disturbance, sim.noise)
    random = any(_random(g) for g in sigs)
    children = run_seeds(sim.seed, runs)[first:last]
    total, runs = runs, last - first  # below: runs of the span, indexed from 0
    shared = None
    ET = js.E.T
    width = js.E.shape[1]
    if not random:
        from obsdesign.simulate.runner import signals

        shared = signals(spec, grid)
        S_shared = np.concatenate(shared, axis=1)[:-1]  # (K, width)
    per_run = (K + 1) * width * 8 if random else 0
    B = batch or int(max(1, min(runs, BATCH_BYTES // max(per_run, 1))))
    chunk = STEPS  # fixed (not from B): the per-chunk sums then round the same for any B
    MT = np.ascontiguousarray(js.M.T)  # rows: z_next[b] = z[b] @ M^T
    out = {
        "sup_abs_error": np.zeros((runs, n)),
        "rmse": np.zeros((runs, n)),
        "sup_abs_estimate": np.zeros((runs, n)),
        "final_error_norm": np.zeros(runs),
    }
    e0_all = np.zeros((runs, n))
    traj0: list[np.ndarray] = []
    sig0 = shared
    for b0 in range(0, runs, B):
        idx = range(b0, min(runs, b0 + B))
        b = len(idx)
        rngs = [np.random.default_rng(children[r]) for r in idx]
        e0 = np.stack(
            [eset.sample(g, 1)[0] if eset is not None else xhat0 - x0 for g in rngs]
        ).reshape(b, n)
        e0_all[b0 : b0 + b] = e0
        if random:
            Sb = np.empty((K, b, width))  # time-major: one step's signals are contiguous
            for j, rng in enumerate(rngs):
                one = [g.evaluate(grid, rng) for g in sigs]
                if b0 == 0 and j == 0:
                    sig0 = tuple(one)
                Sb[:, j, :] = np.concatenate(one, axis=1)[:-1]
        Z = np.concatenate([np.broadcast_to(x0, (b, n)), x0 + e0], axis=1)
        sup_e = np.abs(Z[:, n:] - Z[:, :n]).T.copy()  # (n, b) accumulators
        sq = sup_e**2
        sup_h = np.abs(Z[:, n:]).T.copy()
        if b0 == 0:
            traj0.append(Z[:1].copy())
        k0 = 0
        while k0 < K:
            k1 = min(K, k0 + chunk)
            if random:
                Wc = (Sb[k0:k1].reshape(-1, width) @ ET).reshape(k1 - k0, b, 2 * n)
            else:
                Wc = S_shared[k0:k1] @ ET  # (chunk, 2n), broadcast over the runs
            buf = np.empty((k1 - k0, b, 2 * n))
            for k in range(k1 - k0):
                dst = buf[k]
                np.matmul(Z, MT, out=dst)
                dst += Wc[k]
                Z = dst
            # metrics on the runs-last copy (k, 2n, b): every operation then runs along
            # contiguous rows of b values (column slices of (k, b, 2n) cost several times more)
            bt = np.ascontiguousarray(buf.transpose(0, 2, 1))
            e = bt[:, n:] - bt[:, :n]  # (k, n, b)
            np.maximum(sup_e, e.max(axis=0), out=sup_e)
            np.maximum(sup_e, -e.min(axis=0), out=sup_e)
            sq += np.einsum("kib,kib->ib", e, e)
            np.maximum(sup_h, bt[:, n:].max(axis=0), out=sup_h)
            np.maximum(sup_h, -bt[:, n:].min(axis=0), out=sup_h)
            if b0 == 0:
                traj0.append(buf[:, 0, :].copy())
            k0 = k1
        sl = slice(b0, b0 + len(idx))
        out["sup_abs_error"][sl] = sup_e.T
        out["rmse"][sl] = np.sqrt(sq / (K + 1)).T
        out["sup_abs_estimate"][sl] = sup_h.T
        out["final_error_norm"][sl] = np.linalg.norm(Z[:, n:] - Z[:, :n], axis=1)
    Z0 = np.concatenate(traj0)
    x, xh = Z0[:, :n], Z0[:, n:]
    assert sig0 is not None
    u, _, v = sig0
    y = x @ s.C.f.T + u @ s.D.f.T + v @ s.Dn.f.T
    res = SimResult(grid, x, xh, y, s.states)
    res.extra["per_run"] = out
    res.extra["initial_errors"] = e0_all
    res.info["runs"] = total
    res.info["initial_error"] = initial_error or "xhat0 - x0 (every run)"
    res.info["trajectory"] = f"run {first}"
    if span is not None:
        res.info["span"] = [first, last]
    res.info["quantiles"] = quantiles(out, s.states)
    return res


def merge(parts: list[SimResult], states: list[str]) -> SimResult:
    """Join the results of :func:`run_batch` over contiguous spans (a0 = 0, b_i = a_{i+1},
    last b = runs, in that order) into the full range's: per-run metrics and initial errors
    concatenated in run order, quantiles computed once from all runs, run 0's trajectory."""
    if not parts:
        raise InputError("merge: no spans to join")
    spans = [p.info.get("span", [0, p.info["runs"]]) for p in parts]
    total = parts[0].info["runs"]
    if (
        spans[0][0] != 0
        or spans[-1][1] != total
        or any(s[1] != t[0] for s, t in zip(spans, spans[1:], strict=False))
    ):
        raise InputError(f"merge: spans {spans} do not cover runs 0..{total} in order")
    res = parts[0]
    out = {k: np.concatenate([p.extra["per_run"][k] for p in parts]) for k in res.extra["per_run"]}
    res.extra["per_run"] = out
    res.extra["initial_errors"] = np.concatenate([p.extra["initial_errors"] for p in parts])
    res.info.pop("span", None)
    res.info["quantiles"] = quantiles(out, states)
    return res


def quantiles(per_run: dict[str, np.ndarray], states: list[str]) -> dict[str, Any]:
    """Quantiles (:data:`QUANTILES`) and max of every per-run metric, per state."""
    q = {}
    for k, a in per_run.items():
        if a.ndim == 1:
            q[k] = _q(a)
        else:
            q[k] = {st: _q(a[:, i]) for i, st in enumerate(states)}
    return q


def _q(a: np.ndarray) -> dict[str, float]:
    d = {name: float(np.quantile(a, p)) for name, p in QUANTILES.items()}
    d["max"] = float(a.max())
    return d
