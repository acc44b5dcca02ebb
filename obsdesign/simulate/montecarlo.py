"""Batched Monte Carlo runs of a joint linear plant + observer system
(:class:`obsdesign.simulate.linear.JointSystem`): N initial errors and N signal draws, stepped
together over a batch axis, with per-run metrics and their quantiles.

Randomness: run r uses ``numpy.random.default_rng(SeedSequence(seed).spawn(runs)[r])`` (seed
= ``[simulate] seed``): first its initial error (when ``[simulate] initial_error`` names a
set of ``[sets]``: one point drawn by the set's ``sample``; else xhat0 − x0 for every run),
then its input, disturbance and noise signals in that order (only when one of them is random;
a signal with its own ``seed``, or a deterministic one, is the same in every run). So run r's
draws do not depend on how many runs there are or how they are batched.

Speed (issue 12 item 4): the plant trajectory x is computed once when no random signal
reaches it (then only the estimate is stepped per run, x entering as a shared input), the
deterministic signals enter as one shared term per block; the time recursion goes
:data:`BLOCK` steps per matrix product over the batch axis; uniform draws are made
:data:`CHUNK` steps at a time as raw U[0, 1) numbers (the range and offset folded into the
matrices); only running per-run metrics are kept (elementwise over the blocks, on whole
contiguous arrays). The products keep the runs as rows, which OpenBLAS computes the same way
whatever the number of rows (two or more), so a run's numbers are bitwise the same for any
batch size or span (tested in tests/test_simulate_montecarlo.py); they agree with a separate
run (:func:`obsdesign.simulate.linear.simulate_linear_observer`) to rounding.

Coordinates: the joint system is in [x; e], e = x̂ − x (:func:`obsdesign.simulate.linear.
joint_system` with ``error=True``): the runs step the error (and x when it varies) and form
the estimate as x + e, never the error as x̂ − x, which on an unstable plant over a long
horizon loses every digit once |x| passes 10¹⁶·|e| (x⁺ = 3x with e⁺ = 0.5e: every run's
"error" was 10¹² at step 60; random-spec fuzzer). Run 0's trajectory carries its error too.

``[simulate] initial_error = "NAME"`` is read by :func:`parse_initial_error`, which a method
calls from its ``parse_simulate``.
"""

from __future__ import annotations

import numbers
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from obsdesign.errors import InputError
from obsdesign.sets.base import MEMBERSHIP_CHUNK, ConvexSet
from obsdesign.simulate.budget import TimeBudget, TimeExceeded
from obsdesign.simulate.result import SimResult, norms
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

#: memory of one batch's random draws, bytes
BATCH_BYTES = 128 * 2**20
#: runs stepped together at most: the block arrays of a batch stay in cache and, at n = 2,
#: every block product runs on one OpenBLAS thread (256-512 measured ~10 % faster than 1000)
BATCH_RUNS = 512
#: steps per block of the time recursion (one matrix product per block over the batch axis)
BLOCK = 16
#: steps whose random draws are made at once, per run (a multiple of :data:`BLOCK`: blocks
#: then start at multiples of BLOCK, so the chunking changes no number)
CHUNK = 1024
#: rows × columns × inner size of a product that OpenBLAS runs on one thread
MNK_ONE_THREAD = 1 << 18
#: seconds the spec loader spends trying to draw one point of ``initial_error``'s set
LOAD_SAMPLE_SECONDS = 2.0
#: points of the first rejection-sampling block of ``ConvexSet.sample(rng, 1)``
SAMPLE_BLOCK = 64
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
    # a set the runs cannot draw from (no volume) is bad input here, not a hang later; a set
    # whose points all need rational arithmetic can take a minute to say so, and is left to
    # the runs after LOAD_SAMPLE_SECONDS (they draw under the simulation's time_limit)
    try:
        spec.sets[name].sample(
            np.random.default_rng(0), 1, TimeBudget(LOAD_SAMPLE_SECONDS, "not reported")
        )
    except InputError as e:
        raise table.error("initial_error", f"set {name!r}: {e}") from None
    except TimeExceeded:
        pass
    return name


def _random(sig: Any) -> bool:
    return sig.kind in ("uniform", "outliers") and sig.seed is None


def run_seeds(seed: int, runs: int) -> list[np.random.SeedSequence]:
    """The N independent child seeds of ``seed`` (numpy ``SeedSequence.spawn``; child r is
    ``SeedSequence(seed, spawn_key=(r,))``)."""
    return np.random.SeedSequence(seed).spawn(runs)


def run_seed(seed: int, r: int) -> np.random.SeedSequence:
    """Child r of :func:`run_seeds` alone (the same seed: ``spawn`` gives child r the spawn key
    (r,)), so a batch or a span makes only its own: 10⁷ runs spawned all their seeds (4 GB)
    before the first time-limit check, and every Dask worker spawned all N (Dask trial,
    session 29)."""
    return np.random.SeedSequence(seed, spawn_key=(r,))


def initial_errors(
    eset: ConvexSet | None,
    rngs: list[np.random.Generator],
    default: np.ndarray,
    budget: TimeBudget | None = None,
) -> np.ndarray:
    """One initial error per run, ``eset.sample(rngs[r], 1)[0]`` (``default`` for every run when
    ``eset`` is None), drawn for all runs at once when the set keeps the rejection sampler of
    :meth:`ConvexSet.sample <obsdesign.sets.base.ConvexSet.sample>`: each run's first block of
    :data:`SAMPLE_BLOCK` uniform points of the bounding box (``lo + (hi − lo)·U``, the formula
    of ``Generator.uniform``, so the same numbers), one membership test for all runs, and the
    set's own ``sample`` only for a run none of whose points is inside (the generator then
    continues exactly where ``sample`` would). Membership is ``contains_exact``, the test of
    ``sample``; ``budget`` (the time budget) is passed on to it. Returns (runs, n)."""
    R = len(rngs)
    if eset is None:
        return np.tile(default, (R, 1))
    if type(eset).sample is not ConvexSet.sample:
        return np.stack([eset.sample(g, 1, budget)[0] for g in rngs]).reshape(R, -1)
    n = eset.dim
    lo, hi = eset.bounding_box()
    lo, rg = np.asarray(lo, dtype=float), np.subtract(hi, lo, dtype=float)
    raw = np.empty((R, SAMPLE_BLOCK * n))
    for r, g in enumerate(rngs):
        g.random(out=raw[r])
    pts = lo + rg * raw.reshape(R, SAMPLE_BLOCK, n)
    flat = pts.reshape(-1, n)
    inside = np.empty(len(flat), dtype=bool)
    for a in range(0, len(flat), MEMBERSHIP_CHUNK):  # the budget between chunks: a thin far
        if budget is not None:  # set's 512 × 64 points took 16 s in rational arithmetic
            budget.check(f"drawing initial errors ({a:,} of {len(flat):,} points tested)")
        b = min(a + MEMBERSHIP_CHUNK, len(flat))
        inside[a:b] = np.asarray(eset.contains_exact(flat[a:b]), dtype=bool).reshape(b - a)
    inside = inside.reshape(R, SAMPLE_BLOCK)
    first = inside.argmax(axis=1)
    out = pts[np.arange(R), first]
    for r in np.flatnonzero(~inside.any(axis=1)):
        out[r] = eset.sample(rngs[r], 1, budget, start_round=1)[0]
    return out


@dataclass
class _Blocks:
    """The time recursion s_{k+1} = F s_k + G w_k grouped in blocks of b steps: the states
    s_{k0+1} .. s_{k0+b} (stacked, b·N rows) are ``P`` s_{k0} + ``T`` [w_{k0}; …; w_{k0+b-1}]
    with P = [F; F²; …; F^b] and T the block lower-triangular Toeplitz matrix of F^{i-j} G
    (one matrix product per block over the whole batch axis)."""

    P: np.ndarray  # (b·N, N)
    T: np.ndarray  # (b·N, b·w)

    @classmethod
    def of(cls, F: np.ndarray, G: np.ndarray, b: int) -> _Blocks:
        N, w = G.shape
        pows = [np.eye(N)]
        for _ in range(b):
            pows.append(F @ pows[-1])
        P = np.concatenate(pows[1:], axis=0)
        T = np.zeros((b * N, b * w))
        for i in range(b):
            for j in range(i + 1):
                T[i * N : (i + 1) * N, j * w : (j + 1) * w] = pows[i - j] @ G
        return cls(P, T)


def _mm(a: np.ndarray, b: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``a @ b`` in row pieces of at least two rows, each small enough for OpenBLAS to run
    it on one thread (:data:`MNK_ONE_THREAD`): a threaded product of this size gains little
    and, on a loaded machine, can stall for milliseconds. A row of a product does not depend
    on the other rows (two or more), so the pieces change no number."""
    R = a.shape[0]
    if out is None:
        out = np.empty((R, b.shape[1]))
    step = max(2, MNK_ONE_THREAD // max(1, b.shape[0] * b.shape[1]))
    if R <= step:
        return np.matmul(a, b, out=out)
    pieces = max(1, min(-(-R // step), R // 2))  # pieces of at most `step`, at least 2 rows
    cuts = [R * i // pieces for i in range(pieces + 1)]
    for i, j in zip(cuts, cuts[1:], strict=False):
        np.matmul(a[i:j], b, out=out[i:j])
    return out


def _block_inputs(bl: _Blocks, W: np.ndarray, K: int) -> np.ndarray:
    """Per block, the contribution T [w_{k0}; …; w_{k0+b-1}] of the inputs ``W`` (K, w):
    (blocks, b·N); the last block is padded with zero inputs."""
    nb, w = -(-K // BLOCK), W.shape[1]
    Wp = np.zeros((nb * BLOCK, w))
    Wp[:K] = W
    return _mm(Wp.reshape(nb, BLOCK * w), np.ascontiguousarray(bl.T.T))


def _step_blocks(F: np.ndarray, G: np.ndarray, s0: np.ndarray, W: np.ndarray) -> np.ndarray:
    """The single trajectory s_0 .. s_K of s⁺ = F s + G w_k for the inputs ``W`` (K, w), by
    :class:`_Blocks` of :data:`BLOCK` steps: all block input terms in one product, the block
    starts one small step each, then all states in one product."""
    K, N = len(W), len(s0)
    bl = _Blocks.of(F, G, BLOCK)
    U = _block_inputs(bl, W, K)
    Fb = bl.P[-N:]
    starts = np.empty((len(U), N))
    s = np.asarray(s0, dtype=float)
    for i in range(len(U)):
        starts[i] = s
        s = Fb @ s + U[i, -N:]
    out = np.empty((K + 1, N))
    out[0] = s0
    out[1:] = (_mm(starts, np.ascontiguousarray(bl.P.T)) + U).reshape(-1, N)[:K]
    return out


@dataclass
class _Plan:
    """How a batch is stepped (see :func:`run_batch`): the per-run state coordinates ``idx``
    of z = [x; x̂] (the estimate only, when the plant trajectory x is the same in every run),
    the shared input w_sh(k) (deterministic signals, the offsets of uniform draws and, when x
    is shared, x(k)) with its matrix, and per random signal its columns and scale."""

    idx: np.ndarray
    F: np.ndarray
    G_sh: np.ndarray
    W_sh: np.ndarray  # (K, ·)
    x_sh: np.ndarray | None  # (K + 1, n) when x is the same in every run
    rand: list[int]  # indices into (u, d, v) of the random signals
    G_rand: list[np.ndarray]  # (N, dim_i), scaled by the uniform range
    fast: bool  # all random signals uniform: draws made chunk by chunk from raw U[0, 1)


def _plan(js: Any, sigs: tuple[Any, ...], grid: np.ndarray, x0: np.ndarray, seed: int) -> _Plan:
    n, M, E = js.n, js.M, js.E
    K = len(grid) - 1
    dims = [g.dim for g in sigs]
    cols = np.cumsum([0, *dims])
    rand = [i for i, g in enumerate(sigs) if _random(g)]
    fast = all(sigs[i].kind == "uniform" for i in rand)
    S = np.zeros((K + 1, E.shape[1]))
    lo: dict[int, np.ndarray] = {}
    rg: dict[int, np.ndarray] = {}
    rng = np.random.default_rng(seed)  # deterministic kinds do not use it
    for i, g in enumerate(sigs):
        c = slice(cols[i], cols[i + 1])
        if i not in rand:
            S[:, c] = g.evaluate(grid, rng)
        elif fast:  # Generator.uniform(-b, b) = -b + (b - (-b))·U
            lo[i] = -np.asarray(g.bound, dtype=float)
            rg[i] = np.subtract(g.bound, lo[i])
            S[:, c] = lo[i]
    rcols = np.concatenate([np.arange(cols[i], cols[i + 1]) for i in rand] or [[]]).astype(int)
    x_varies = bool(np.any(E[:n, rcols] != 0)) or bool(np.any(M[:n, n:] != 0))
    x_sh = None
    if x_varies:
        idx = np.arange(2 * n)
        G_sh, W_sh = E, S[:-1]
    else:
        idx = np.arange(n, 2 * n)
        x_sh = _step_blocks(M[:n, :n], E[:n], x0, S[:-1])
        G_sh = np.concatenate([M[n:, :n], E[n:]], axis=1)
        W_sh = np.concatenate([x_sh[:-1], S[:-1]], axis=1)
        # only the inputs the error reads: in error coordinates e⁺ does not read x (a zero
        # block), and a plant state that overflowed (an unstable plant over a long horizon)
        # made every run's error nan through 0·inf — sup |e| = nan for a converging error
        # that the single run gives finite (simulate trial, session 39)
        reads = np.any(G_sh != 0, axis=0)
        G_sh, W_sh = G_sh[:, reads], W_sh[:, reads]
    G_rand = []
    for i in rand:
        Gi = E[idx][:, cols[i] : cols[i + 1]]
        G_rand.append(Gi * rg[i] if fast else Gi)
    return _Plan(idx, M[np.ix_(idx, idx)], G_sh, W_sh, x_sh, rand, G_rand, fast)


class _Draws:
    """The random signals of a batch of runs, chunk by chunk: ``chunk(k0, k1)`` gives, per
    random signal, a (runs, (k1 − k0)·dim) array whose row r holds run r's values (raw U[0, 1)
    draws in the fast path; scale and offset are in the plan) for steps k0..k1-1, time-major
    as ``Signal.evaluate`` draws them. Fast path: signal j of run r draws from run r's
    generator advanced past the earlier random signals' (K + 1)·dim draws, so the numbers are
    those of ``evaluate`` called in order; otherwise every signal is evaluated whole, run by
    run, in order (``outliers``)."""

    def __init__(
        self,
        rand: list[int],
        fast: bool,
        sigs: tuple[Any, ...],
        rngs: list[np.random.Generator],
        grid: Any,
    ):
        self.fast, self.dims = fast, [sigs[i].dim for i in rand]
        R, K1 = len(rngs), len(grid)
        if fast:
            self.gens: list[list[np.random.Generator]] = []
            skip = 0
            for d in self.dims:
                if skip == 0:
                    self.gens.append(rngs)
                else:
                    self.gens.append([_advanced(g, skip) for g in rngs])
                skip += K1 * d
            self.buf = [np.empty((R, CHUNK * d)) for d in self.dims]
        else:
            self.full = [np.empty((R, K1 * d)) for d in self.dims]
            for r, g in enumerate(rngs):
                vals = [s.evaluate(grid, g) for s in sigs]
                for j, i in enumerate(rand):
                    self.full[j][r] = vals[i].ravel()

    def chunk(self, k0: int, k1: int) -> list[np.ndarray]:
        if not self.fast:
            return [f[:, k0 * d : k1 * d] for f, d in zip(self.full, self.dims, strict=True)]
        out = []
        for gens, buf, d in zip(self.gens, self.buf, self.dims, strict=True):
            m = (k1 - k0) * d
            for r, g in enumerate(gens):
                g.random(out=buf[r, :m])
            out.append(buf[:, :m])
        return out


def _advanced(g: np.random.Generator, steps: int) -> np.random.Generator:
    """A copy of ``g`` advanced by ``steps`` 64-bit draws (one per float64 of ``random``)."""
    bg = type(g.bit_generator)()
    bg.state = g.bit_generator.state
    return np.random.Generator(bg.advance(steps))


def run_batch(
    spec: Spec, js: Any, runs: int, initial_error: str | None = None, **study_options: Any
) -> SimResult:
    """``runs`` runs of ``js`` (a :class:`~obsdesign.simulate.linear.JointSystem` of the
    bound ``spec``); ``initial_error``: a set name of ``[sets]`` (None: xhat0 − x0);
    ``study_options``: ``batch`` (runs stepped together), ``span`` (only runs a..b-1) and
    ``budget`` (the time budget), see :func:`study`.

    Linearity does the work: the deterministic signals (and the plant trajectory x when no
    random signal reaches it: only the estimate is then stepped per run) enter as one
    shared term per block; the steps are grouped :data:`BLOCK` at a time (one product per
    block over the batch axis, :class:`_Blocks`), the metrics are updated per block and
    nothing of a run but its metrics is kept (run 0's trajectory excepted).

    Returns what :func:`study` returns."""
    sim = _need(spec)
    js = js.in_error_coordinates()
    n, grid = js.n, js.grid
    K = len(grid) - 1
    sigs = (sim.u, sim.disturbance, sim.noise)
    with np.errstate(over="ignore", invalid="ignore"):  # a shared x that overflows: in words
        plan = _plan(js, sigs, grid, sim.x0.f, sim.seed)
    w = sum(sigs[i].dim for i in plan.rand)

    budget = study_options.get("budget")

    def step(
        rngs: list[np.random.Generator], e0: np.ndarray, keep: bool, scaled: bool = False
    ) -> Any:
        draws = _Draws(plan.rand, plan.fast, sigs, rngs, grid) if plan.rand else None
        traj0 = np.empty((K + 1, len(plan.idx))) if keep else None
        m = _run(plan, draws, sim.x0.f, e0, K, n, traj0, budget, scaled)
        if traj0 is None:
            return m, None
        x, e = _trajectory(plan, traj0, n)
        return m, (x, x + e, None, e)

    per_run = (CHUNK if plan.fast else K + 1) * w * 8
    batch, span = study_options.get("batch"), study_options.get("span")
    res = study(spec, grid, runs, initial_error, batch, span, per_run, step, budget)
    s = spec.system
    eset = spec.sets[initial_error] if initial_error is not None else None
    child = np.random.SeedSequence(sim.seed, spawn_key=(span[0] if span else 0,))
    u, _, v = _signals0(spec, grid, eset, child)
    res.y = res.x @ s.C.f.T + u @ s.D.f.T + v @ s.Dn.f.T
    return res


def _need(spec: Spec) -> Any:
    if spec.simulate is None:
        raise InputError(f"{spec.file}: [simulate] is missing: nothing to simulate")
    return spec.simulate


def study(
    spec: Spec,
    grid: np.ndarray,
    runs: int,
    initial_error: str | None,
    batch: int | None,
    span: tuple[int, int] | None,
    per_run_bytes: int,
    step: Any,
    budget: TimeBudget | None = None,
) -> SimResult:
    """The Monte Carlo study of the bound ``spec`` on ``grid``: the child seeds, the batches
    (``batch`` runs, default :data:`BATCH_RUNS` or fewer when ``per_run_bytes`` each do not
    fit :data:`BATCH_BYTES`; ``span = (a, b)``: only runs a..b-1 of the ``runs``, with the
    same child seeds as in the full range, so run r is the same whatever the span:
    :func:`merge` joins spans; None: all), each run's generator and initial error, then
    ``step(rngs, e0, keep)`` → (per-run metrics of the batch, run 0's (x, x̂), (x, x̂, y) or
    (x, x̂, y or None, e) when ``keep``) (the generators stand just after the initial errors'
    draws). ``budget`` (the time budget) is looked at before every batch.

    Returns run 0's trajectory with ``info`` = runs, where the
    initial errors come from and the quantiles of every per-run metric, and
    ``extra["per_run"]`` = the per-run metrics (sup |e_i|, RMSE of e_i, sup |x̂_i|: arrays
    (runs, n); final |e|: (runs,)) and ``extra["initial_errors"]`` (runs, n)."""
    sim, s = _need(spec), spec.system
    if runs < 1:
        raise InputError(f"runs: expected at least 1, got {runs}")
    if span is not None and not (
        isinstance(span, (tuple, list))
        and len(span) == 2
        and all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in span)
    ):
        # span="ab" or (0.5, 2.5) were bare TypeErrors (API review 45)
        raise InputError(f"span: expected a pair of whole numbers (a, b), got {span!r}")
    first, last = (int(span[0]), int(span[1])) if span is not None else (0, runs)
    if not 0 <= first < last <= runs:
        from obsdesign.errors import value_text

        raise InputError(
            f"span: expected 0 <= a < b <= {runs}, got ({value_text(first)}, {value_text(last)})"
        )
    if initial_error is not None and initial_error not in spec.sets:
        raise InputError(f"{spec.file}: initial_error = {initial_error!r} is not in [sets]")
    eset = spec.sets[initial_error] if initial_error is not None else None
    n = s.n
    total, runs = runs, last - first  # below: runs of the span, indexed from 0

    def children(a: int, b: int) -> list[np.random.SeedSequence]:
        return [run_seed(sim.seed, first + r) for r in range(a, b)]

    cap = int(max(1, min(runs, BATCH_RUNS, BATCH_BYTES // max(per_run_bytes, 1))))
    B = batch or -(-runs // -(-runs // cap))  # equal batches of at most `cap` runs
    out = {k: np.zeros((runs, n)) for k in METRICS[:3]}
    out["final_error_norm"] = np.zeros(runs)
    e0_all = np.zeros((runs, n))
    traj: Any = None
    for b0 in range(0, runs, B):
        if budget is not None:
            budget.check(f"{b0:,} of {runs:,} Monte Carlo runs done")
        rngs = [np.random.default_rng(c) for c in children(b0, min(b0 + B, runs))]
        try:
            e0 = initial_errors(eset, rngs, sim.xhat0.f - sim.x0.f, budget)
        except InputError as e:  # a thin set a run could not draw from: name file and key
            raise InputError(
                f"{spec.file}: [simulate.initial_error] set {initial_error!r}: {e}"
            ) from None
        e0_all[b0 : b0 + len(rngs)] = e0
        with np.errstate(over="ignore", invalid="ignore"):  # said in words below
            m, t0 = step(rngs, e0, b0 == 0)
        traj = t0 if b0 == 0 else traj
        for k, a in m.items():
            out[k][b0 : b0 + len(rngs)] = a
    _remeasure(out, children, eset, sim.xhat0.f - sim.x0.f, step, B, budget)
    y0 = traj[2] if len(traj) > 2 else None
    err = traj[3] if len(traj) > 3 else None
    res = SimResult(grid, traj[0], traj[1], y0, s.states, error=err)
    res.extra["per_run"] = out
    res.extra["initial_errors"] = e0_all
    res.info["runs"] = total
    res.info["initial_error"] = initial_error or "xhat0 - x0 (every run)"
    res.info["trajectory"] = f"run {first}"
    if span is not None:
        res.info["span"] = [first, last]
    res.info["quantiles"] = quantiles(out, s.states)
    text = nonfinite_warning(out)
    if text and span is None:  # a span's count is of its runs: merge says it for all
        warnings.warn(text, stacklevel=2)
    return res


def nonfinite_warning(per_run: dict[str, np.ndarray]) -> str:
    """The warning for runs whose metrics are not finite ("" when there are none), counted
    over every run given: numpy's "overflow encountered in multiply" was the only word
    (review), and a study in two spans said "36 of 100 runs" for 136 of 200, each span
    counting its own and the two texts merged (Dask trial, session 29)."""
    runs = len(per_run["final_error_norm"])
    flat = np.hstack([a.reshape(runs, -1) for a in per_run.values()])
    bad = int((~np.all(np.isfinite(flat), axis=1)).sum())
    if not bad:
        return ""
    err = np.hstack([per_run[k].reshape(runs, -1) for k in per_run if k != "sup_abs_estimate"])
    if np.all(np.isfinite(err)):
        # an unstable plant with converging errors: "their errors or estimates leave the
        # float range … smaller initial errors" beside the single run's "only sup |x̂| is
        # not finite" (re-check trial, session 39)
        return (
            f"sup |x̂| of {bad:,} of {runs:,} runs is not finite: the plant leaves the float "
            "range while every error metric stays finite, so those quantiles of sup |x̂| are "
            "inf or nan; a shorter horizon"
        )
    return (
        f"the metrics of {bad:,} of {runs:,} runs are not finite: their errors or estimates "
        "leave the float range, so their quantiles are inf or nan; smaller initial errors or "
        "a shorter horizon"
    )


def _remeasure(
    out: dict[str, np.ndarray],
    children: Any,
    eset: Any,
    e_default: np.ndarray,
    step: Any,
    batch: int,
    budget: TimeBudget | None = None,
) -> None:
    """The RMSE of the runs whose running sum of e² left the float range — overflowed (inf
    beside a finite sup |e|) or may have underflowed (sup |e| < 10⁻¹⁵⁰) — stepped again
    together, ``batch`` at a time, with the sum of squares scaled by each position's running
    max |e| (``step(..., scaled=True)``): the quantiles printed RMSE inf for errors of 10²⁰⁰
    and 0.0 for 10⁻²⁰⁰ while run 0's table said 3.6·10²⁰⁰ (simulate trial, session 27). Every
    such run is measured again: at most 64 were, one by one, counted per span, so a study on
    two Dask workers printed other quantiles than the serial run, whose 36 runs left at inf
    moved its finite quantiles by 30–46 % (Dask trial, session 29). A run's numbers do not
    depend on the runs beside it (see :func:`_run`), so the result is the same for any span.

    :param out: the per-run metrics (``rmse`` is updated); :param children: ``(a, b)`` →
    the child seeds of the span's runs a..b-1; :param eset, e_default: where the initial
    errors come from; :param step: the batch stepper of :func:`study`; :param batch: runs
    stepped together; :param budget: the time budget, looked at per batch."""
    sup, rmse = out["sup_abs_error"], out["rmse"]
    with np.errstate(all="ignore"):
        bad = np.flatnonzero(
            np.any(np.isfinite(sup) & ((~np.isfinite(rmse)) | (sup < 1e-150) & (sup > 0)), axis=1)
        )
    for b0 in range(0, len(bad), batch):
        if budget is not None:
            budget.check(f"{b0:,} of {len(bad):,} runs measured again (errors near 1e±154)")
        rows = bad[b0 : b0 + batch]
        rngs = [np.random.default_rng(children(int(r), int(r) + 1)[0]) for r in rows]
        e0 = initial_errors(eset, rngs, e_default, budget)
        with np.errstate(over="ignore", invalid="ignore"):
            m, _ = step(rngs, e0, False, scaled=True)
        rmse[rows] = m["rmse"]


def _run(
    plan: _Plan,
    draws: _Draws | None,
    x0: np.ndarray,
    e0: np.ndarray,
    K: int,
    n: int,
    traj0: np.ndarray | None,
    budget: TimeBudget | None = None,
    scaled: bool = False,
) -> dict[str, np.ndarray]:
    """Step one batch (initial errors ``e0`` (R, n)) over K steps; per-run metrics.

    The joint state is [x; e] (e = x̂ − x; the error alone when x is shared). Every block of
    m steps gives, per run, the estimates H = (x̂_{k0+1}, …, x̂_{k0+m}) and the errors E as
    rows of (R, m·n) arrays, each from products with the runs as rows ([state, 1] times the
    block matrices, plus the raw draws times the Toeplitz part; the shared terms ride on the
    column of ones): OpenBLAS computes every row the same way whatever the number of rows
    (two or more; one run is stepped as two equal rows), so a run's numbers do not depend on
    the batching. E is stepped; H = E + x (shared x: its block term; else the stepped X).
    The metrics are running elementwise max / min / sum of squares over the blocks (whole
    contiguous arrays), reduced over the m positions once at the end. ``traj0`` (K + 1, N)
    receives run 0's stepped states ([x; e], or e) when given; ``budget`` (the time budget)
    is looked at before every chunk of :data:`CHUNK` steps. ``scaled``: the sum of squares
    of each position is kept over its running max |e| (:func:`_scaled_add`), so the RMSE
    neither overflows near 10¹⁵⁴ nor underflows near 10⁻¹⁵⁴ (slower: :func:`_remeasure`
    asks for it for the runs where the plain sum left the float range)."""
    R, N = len(e0), len(plan.idx)
    Rr = max(R, 2)
    shared_x = plan.x_sh is not None
    st = np.ones((Rr, N + 1))  # the states and a column of ones
    xh0 = x0 + e0  # (R, n)
    if shared_x:
        st[:R, :N] = e0
    else:
        st[:R, :n] = x0
        st[:R, n:N] = e0
    st[R:] = st[:1]
    if traj0 is not None:
        traj0[0] = st[0, :N]
    bm = _BlockMatrices(plan, K, n)
    hi = np.full((2, Rr, BLOCK * n), -np.inf)  # running max of [H; E] per position
    lo = np.full((2, Rr, BLOCK * n), np.inf)
    sq = np.zeros((Rr, BLOCK * n))  # running sum of E² per position (scaled: of (E/sc)²)
    sc = np.zeros((Rr, BLOCK * n)) if scaled else None  # running max |E| per position
    # per block length: [H; E] stacked (each half contiguous, and the whole: one max and one
    # min call per block for both), X and a scratch T
    bufs = {
        m: (np.empty((2, Rr, m * n)), np.empty((Rr, m * n)), np.empty((Rr, m * n)))
        for m in {BLOCK, K % BLOCK}
        if m
    }
    dims = draws.dims if draws is not None else []
    E = np.empty((Rr, 0))
    mm = _matmul_for(Rr, max(N + 1, BLOCK * max(dims, default=1)), BLOCK * n)
    PH, PE, PX = bm.PH, bm.PE, bm.PX
    # the error from [e; 1] alone when it does not read x (as for a shared x, see _plan): the
    # plant's columns of st may overflow while the error stays finite (0·inf = nan)
    st_e, PE_e = st, PE
    if not shared_x and not np.any(PE[:n]):
        st_e, PE_e = st[:, n:], PE[n:]
    for c0 in range(0, K, CHUNK):
        if budget is not None:
            budget.check(f"a batch of {R:,} runs at step {c0:,} of {K:,}")
        c1 = min(K, c0 + CHUNK)
        raw = draws.chunk(c0, c1) if draws is not None else []
        for k0 in range(c0, c1, BLOCK):
            m = min(BLOCK, c1 - k0)
            cm = m * n
            HE, X, T = bufs[m]
            H, E = HE[0], HE[1]
            bm.at(k0 // BLOCK)
            full = m == BLOCK
            mm(st_e, PE_e if full else PE_e[:, :cm], out=E)  # the stepped error
            if shared_x:
                mm(st, PH if full else PH[:, :cm], out=H)  # e + x(k) (x in the block term)
            else:
                mm(st, PX if full else PX[:, :cm], out=X)
            for j, (a, d) in enumerate(zip(raw, dims, strict=True)):
                blk = a[:, (k0 - c0) * d : (k0 - c0 + m) * d]
                if R == 1:
                    blk = np.concatenate([blk, blk])
                mm(blk, bm.TH[j] if full else bm.TH[j][: m * d, :cm], out=T)
                np.add(E, T, out=E)
                if shared_x:
                    np.add(H, T, out=H)
                else:
                    mm(blk, bm.TX[j] if full else bm.TX[j][: m * d, :cm], out=T)
                    np.add(X, T, out=X)
            if not shared_x:
                np.add(E, X, out=H)
                st[:, :n] = X[:, cm - n :]
            st[:, N - n : N] = E[:, cm - n :]
            if sc is not None:
                _scaled_add(sq[:, :cm], sc[:, :cm], E)
            else:
                np.multiply(E, E, out=T)
            if full:
                np.maximum(hi, HE, out=hi)
                np.minimum(lo, HE, out=lo)
                if sc is None:
                    np.add(sq, T, out=sq)
            else:  # a last, shorter block: its cm first positions
                hi[:, :, :cm] = np.maximum(hi[:, :, :cm], HE)
                lo[:, :, :cm] = np.minimum(lo[:, :, :cm], HE)
                if sc is None:
                    sq[:, :cm] += T
            if traj0 is not None:
                traj0[k0 + 1 : k0 + m + 1, N - n :] = E[0].reshape(m, n)
                if not shared_x:
                    traj0[k0 + 1 : k0 + m + 1, :n] = X[0].reshape(m, n)
    e = e0
    e_end = E[:R, -n:] if K else e
    top = np.maximum(hi[:, :R], -lo[:, :R]).reshape(2, R, BLOCK, n).max(axis=2)
    sup_h, sup_e = top[0], top[1]
    if sc is None:
        rmse = np.sqrt((e * e + sq[:R].reshape(R, BLOCK, n).sum(axis=1)) / (K + 1))
    else:
        rmse = _scaled_rmse(sq[:R].reshape(R, BLOCK, n), sc[:R].reshape(R, BLOCK, n), e, K + 1)
    return {
        "sup_abs_error": np.maximum(sup_e, np.abs(e)),
        "rmse": rmse,
        "sup_abs_estimate": np.maximum(sup_h, np.abs(xh0)),
        "final_error_norm": norms(e_end),
    }


def _scaled_add(sq: np.ndarray, sc: np.ndarray, E: np.ndarray) -> None:
    """sq ← Σ (e/sc)² with sc ← max(sc, |e|), in place, entry by entry: the running sum of
    squares kept relative to the running max |e|, rescaled when the max grows, so that it
    neither overflows nor underflows (:func:`_scaled_rmse` puts the scale back).

    :param sq, sc: the running scaled sums and scales (views, updated); :param E: the new
    errors, the same shape."""
    new = np.maximum(sc, np.abs(E))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(new > 0, sc / new, 0.0)
        q = np.where(new > 0, E / new, 0.0)
    sq *= r * r
    sq += q * q
    sc[...] = new


def _scaled_rmse(sq: np.ndarray, sc: np.ndarray, e0: np.ndarray, count: int) -> np.ndarray:
    """The RMSE per run and state from :func:`_scaled_add`'s sums over the positions (R, m, n)
    and the initial error e0 (R, n): S·√((Σ_pos sq·(sc/S)² + (e0/S)²)/count) with S the
    largest scale, computed without forming any square of a number near 10^±154.

    :param sq, sc: the scaled sums and their scales; :param e0: the initial errors;
    :param count: the number of errors summed (K + 1)."""
    S = np.maximum(sc.max(axis=1), np.abs(e0))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        Sd = np.where(S > 0, S, 1.0)
        rel = sc / Sd[:, None, :]
        tot = (sq * rel * rel).sum(axis=1) + (e0 / Sd) ** 2
        out = np.where(S > 0, S * np.sqrt(tot / count), 0.0)
    # a run whose error left the float range: its scale is nan (or inf) and so is its RMSE;
    # it was 0 (nan > 0 is false), a diverging run's RMSE 0 in the quantiles beside a table
    # saying nan (re-check trial, session 41)
    return np.where(np.isfinite(S), out, S)


def _matmul_for(rows: int, inner: int, cols: int) -> Any:
    """``np.matmul`` when products of ``rows`` × ``inner`` × ``cols`` run on one thread,
    else :func:`_mm` (pieces)."""
    return np.matmul if rows * inner * cols <= MNK_ONE_THREAD else _mm


class _BlockMatrices:
    """The block matrices of :func:`_run`, columns step-major (position i·n + j: state j of
    step i + 1, so that a shorter block uses a prefix): ``at(block)`` gives the (N + 1)-row
    maps [state; 1] → errors, estimates (when the plant trajectory is shared: the errors
    plus x(k)) and plant states ``PE``, ``PH``, ``PX``, whose last row is that block's shared
    term after ``at(block)``; ``TH[j]``,
    ``TX[j]``: the Toeplitz maps of random signal j's raw draws to errors, plant states."""

    def __init__(self, plan: _Plan, K: int, n: int):
        N = len(plan.idx)
        sh = _Blocks.of(plan.F, plan.G_sh, BLOCK)
        steps = np.arange(BLOCK)[:, None] * N
        rows_h = (steps + np.arange(N - n, N)).ravel()  # the estimate's coordinates
        rows_x = (steps + np.arange(n)).ravel()
        Csh = _block_inputs(sh, plan.W_sh, K)  # (blocks, b·N)
        self.CE = Csh[:, rows_h]  # the error's coordinates (the last n of the state)
        self.CX = Csh[:, rows_x]
        if plan.x_sh is not None:
            xs = np.zeros((len(Csh) * BLOCK, n))
            xs[:K] = plan.x_sh[1:]
            self.CH = self.CE + xs.reshape(len(Csh), BLOCK * n)
        self.PE = np.vstack([sh.P[rows_h].T, np.zeros((1, BLOCK * n))])
        self.PH = self.PE.copy()
        self.PX = np.vstack([sh.P[rows_x].T, np.zeros((1, BLOCK * n))])
        self.shared_x = plan.x_sh is not None
        self.TH, self.TX = [], []
        for G in plan.G_rand:
            T = _Blocks.of(plan.F, G, BLOCK).T
            self.TH.append(np.ascontiguousarray(T[rows_h].T))
            self.TX.append(np.ascontiguousarray(T[rows_x].T))

    def at(self, block: int) -> None:
        """Put that block's shared terms in the last rows of PE and PH (or PX)."""
        self.PE[-1] = self.CE[block]
        if self.shared_x:
            self.PH[-1] = self.CH[block]
        else:
            self.PX[-1] = self.CX[block]


def _trajectory(plan: _Plan, traj0: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Run 0's (x, e) from its stepped coordinates ([x; e], or e with x shared)."""
    if plan.x_sh is not None:
        return plan.x_sh, traj0
    return traj0[:, :n], traj0[:, n:]


def _signals0(
    spec: Spec, grid: np.ndarray, eset: ConvexSet | None, child: np.random.SeedSequence
) -> tuple[np.ndarray, ...]:
    """Run 0's signals u, d, v (drawn again from its generator, after its initial error)."""
    sim = spec.simulate
    assert sim is not None
    g = np.random.default_rng(child)
    if eset is not None:
        eset.sample(g, 1)
    return tuple(sig.evaluate(grid, g) for sig in (sim.u, sim.disturbance, sim.noise))


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
    text = nonfinite_warning(out)
    if text:  # counted over every run (each span leaves it to merge); worded as the serial
        # run's warnings.warn is captured (it lacked "warning: UserWarning: ", re-check trial)
        res.info["warnings"] = [*res.info.get("warnings", []), f"warning: UserWarning: {text}"]
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
    """numpy's (linear) quantiles and the max of ``a``; a quantile between two infinite
    values of the same sign is that infinity (the interpolation gave inf − inf = nan beside a
    max of inf when every run's metric overflowed; independent simulate review)."""
    with np.errstate(invalid="ignore"):
        d = {name: float(np.quantile(a, p)) for name, p in QUANTILES.items()}
    for name, p in QUANTILES.items():
        if np.isnan(d[name]) and not np.isnan(a).any():
            d[name] = float(np.quantile(a, p, method="lower"))
    d["max"] = float(a.max())
    return d
