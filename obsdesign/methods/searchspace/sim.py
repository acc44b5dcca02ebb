"""The concatenated ε-γ observer of Hernández & García ("An alternative approach to the state
observation problem for Lipschitz continuous systems with controls", Definitions 5-7), run on a
grid of hypercube centres with every live centre flowed at once.

- **Cells.** A hypercube of radius ε (footnote 2: radius = diam/2) has half-side ε/√n, so
  every point of the cell is within Euclidean distance ε of its centre. Level i uses the fixed
  grid of centres 2 s_i ℤⁿ with s_i = ε_i/√n.
- **Flow.** Between samples all live centres are advanced together by a fixed-step RK4
  (chunks of centres, so the only per-centre memory is the state itself); the step count is
  chosen and checked by step doubling (error control) at every switch.
- **Discarding** (Definition 6): at t_k a centre is dropped when |y_k − h(x̄)| > γ_i.
- **Refinement at the switches** (Definition 7 and the consistency part of Theorem 1's proof).
  ``refine = "recover"`` (default, sound): by Lemma 2's estimate (2) the true state at τ_{i+1}
  lies in the Euclidean ball of radius η = ε_i e^{L_f Δτ} (+ the flow error estimate) around
  some surviving centre; the new level's grid cells that meet one of these balls are taken
  (duplicates merge: the grid is fixed) and a cell is kept only when |h(c) − y(τ_{i+1})| ≤
  L_h ε_{i+1}, which every cell that contains a point of h⁻¹(y(τ_{i+1})) satisfies — this is
  the paper's ∩ (h⁻¹(y))_ε without computing h⁻¹. Guarantee: the cell that contains the
  true state is never dropped, as long as L_f, L_h are Lipschitz constants on a set that
  contains the trajectories and the cells around them and the flow error stays below its
  estimate. ``refine = "paper"`` is Definition 7 literally, D_{i+1} = [(X + G_ε) ∪ X] ∩
  (h⁻¹(y))_ε with G_ε = {±ε/√n}ⁿ: the 2ⁿ children cover the *cube* of radius 2ε, not the
  *ball* of radius η that (2) gives, so for n ≥ 2 it can lose the true state, and it grows
  without bound (only exact duplicates merge).
- **Estimate**: the centroid of the live centres; the error of footnote 9 (the largest
  coordinate-wise distance between a live centre and the true state) is reported beside the
  centroid's error and an observable bound (spread of the centres + the current cell radius).
"""

from __future__ import annotations

import itertools
import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from obsdesign.certify.printing import fmt_exact
from obsdesign.errors import InconclusiveError, InfeasibleError, InputError, count_text
from obsdesign.limits import limits
from obsdesign.methods.searchspace.options import Options, SimOptions
from obsdesign.params import Parameters
from obsdesign.simulate.budget import TimeBudget
from obsdesign.simulate.result import SAFE_HI, SAFE_LO, SimResult, norms
from obsdesign.spec.models import Spec

CHUNK = 1 << 15
#: relative/absolute inflation of every radius used in a covering test (float rounding)
INFLATE = 1e-9


class ConsistencyLost(InfeasibleError):
    """Every centre was discarded: the message says which bound was violated."""


class MemoryCap(InfeasibleError):
    """The search space needs more live centres than the cap allows."""


#: what to change when the simulation runs past ``[simulate] time_limit``
ADVICE = (
    "raise time_limit, or lower max_centres, start from a smaller D or a larger γ₀, or shorten "
    "the horizon"
)


@dataclass
class Plant:
    """Vectorized f, h, u of a spec: ``rhs(X, t)`` on (N, n) arrays, ``out(X)`` → (N, p)."""

    spec: Spec
    states: list[str] = field(init=False)
    inputs: list[str] = field(init=False)
    #: the time budget, called by :func:`rk4` every :data:`BUDGET_EVERY` substeps (a sample's
    #: flow with ``substeps = 10⁶`` ran past 8× its time_limit: the budget was looked at
    #: only between samples; independent simulate review)
    budget: Callable[[], None] | None = field(default=None, init=False)
    ticks: int = field(default=0, init=False)

    def __post_init__(self) -> None:
        s = self.spec.system
        self.states = list(s.states)
        self.inputs = list(s.inputs)
        self._cache: dict[float, dict[str, float]] = {}
        names = {*s.variables, *(v for ex in (*s.f, *s.h) for v in ex.variables)}
        self._zeros = {v: 0.0 for v in names}

    def u(self, t: float) -> dict[str, float]:
        """u(t) by name (the last few times are cached: RK4 asks each time twice)."""
        s = self.spec.system
        if not self.inputs:
            return {}
        hit = self._cache.get(t)
        if hit is None:
            if len(self._cache) > 8:
                self._cache.clear()
            hit = {n: float(ex(t=t)) for n, ex in zip(self.inputs, s.u_signal, strict=True)}
            self._cache[t] = hit
        return hit

    def rhs(self, X: np.ndarray, t: float, out: np.ndarray | None = None) -> np.ndarray:
        """f(X, u(t)) for every row of X (eq. (1))."""
        env: dict[str, Any] = dict(self._zeros)  # every variable given: Expr skips its name search
        env.update({n: X[:, i] for i, n in enumerate(self.states)})
        env.update(self.u(t))
        env["t"] = t
        out = np.empty_like(X) if out is None else out
        for i, ex in enumerate(self.spec.system.f):
            out[:, i] = ex(**env)
        return out

    def out(self, X: np.ndarray) -> np.ndarray:
        """h(X) for every row of X."""
        env: dict[str, Any] = dict(self._zeros)
        env.update({n: X[..., i] for i, n in enumerate(self.states)})
        return np.stack(
            [np.broadcast_to(ex(**env), X.shape[:-1]) for ex in self.spec.system.h], axis=-1
        )


#: :func:`rk4` looks at the plant's time budget every this many substeps
BUDGET_EVERY = 64


def rk4(
    plant: Plant, X: np.ndarray, t: float, dt: float, nsub: int, inplace: bool = False
) -> np.ndarray:
    """Advance every row of X from t to t + dt by ``nsub`` classical RK4 steps, in chunks of
    CHUNK rows (temporaries are per chunk: no per-centre memory beyond the state; with
    ``inplace`` the result overwrites X); the plant's ``budget`` is called every
    :data:`BUDGET_EVERY` substeps."""
    h = dt / nsub
    out = X if inplace else np.empty_like(X)
    budget = plant.budget
    for a in range(0, X.shape[0], CHUNK):
        x = X[a : a + CHUNK].copy()
        acc = np.empty_like(x)
        xt = np.empty_like(x)
        k = np.empty_like(x)
        tt = t
        for _ in range(nsub):
            if budget is not None:
                plant.ticks += 1
                if plant.ticks % BUDGET_EVERY == 0:
                    budget()
            plant.rhs(x, tt, k)
            np.multiply(k, h / 6, out=acc)
            acc += x
            np.multiply(k, h / 2, out=xt)
            xt += x
            plant.rhs(xt, tt + h / 2, k)
            acc += (h / 3) * k
            np.multiply(k, h / 2, out=xt)
            xt += x
            plant.rhs(xt, tt + h / 2, k)
            acc += (h / 3) * k
            np.multiply(k, h, out=xt)
            xt += x
            plant.rhs(xt, tt + h, k)
            acc += (h / 6) * k
            x, acc = acc, x
            tt += h
        out[a : a + CHUNK] = x
    return out


#: the flow error accepted per RK4 substep, relative to the current ε (:func:`partition`)
FLOW_TOL = 1e-6

#: how many times one RK4 substep of a sample may be halved by :func:`partition`
MAX_SPLITS = 48

#: halvings of :func:`partition` in one sample at most (beyond the ``nsub`` substeps): a state
#: whose flow error never meets the tolerance (x0 = 1e300) made up to 2⁴⁸ pieces a sample
MAX_EXTRA_PIECES = 64 * MAX_SPLITS


def partition(
    plant: Plant, P: np.ndarray, t: float, dT: float, nsub: int, tol: float
) -> tuple[list[tuple[float, float]], float]:
    """The RK4 substeps (start, width) of the sample [t, t + ΔT]: ``nsub`` equal ones, each
    halved (at most :data:`MAX_SPLITS` times) while its step-doubling error estimate on the
    probe rows ``P`` (the plant state and a few centres) is above ``tol``; returns them and
    the sum of the accepted substeps' estimates (the sample's flow-error estimate).

    A fixed step across a jump of u(t) (the shipped example's sawtooth u = t/3 − ⌊t/3⌋ at
    t = 3, 6, 9) is only first-order accurate: the independent simulate review found the
    simulated plant 1.7·10⁻³ off the exact flow, against a flow-error estimate of 10⁻¹³
    (step doubling was done only at the switches, on smooth stretches). Halving the substep
    that contains the jump shrinks its error in proportion, so a few dozen halvings reach
    ``tol``, on the probe rows only; all centres then follow the same substeps. A jump that
    depends on the state (a ``step`` or ``sign`` of x in f) is seen only where a probe row
    crosses it. A non-finite estimate is not halved (halving cannot make it finite), and at
    most :data:`MAX_EXTRA_PIECES` halvings are made in one sample (independent simulate
    review: x0 = 1e300 ran until time_limit, up to 2⁴⁸ pieces a sample)."""
    h = dT / nsub
    splits = 0
    todo = [(t + (nsub - 1 - j) * h, h, 0) for j in range(nsub)]  # a stack: earliest last
    out: list[tuple[float, float]] = []
    total = 0.0
    while todo:
        a, w, depth = todo.pop()
        one = rk4(plant, P, a, w, 1)
        two = rk4(plant, P, a, w, 2)
        err = float(np.max(norms(one - two))) * 16 / 15 if len(P) else 0.0
        if err > tol and depth < MAX_SPLITS and splits < MAX_EXTRA_PIECES and math.isfinite(err):
            splits += 1
            todo += [(a + w / 2, w / 2, depth + 1), (a, w / 2, depth + 1)]
            continue
        out.append((a, w))
        total += err
        P = one
    return out, total


def observer_step(
    plant: Plant,
    C: np.ndarray,
    x: np.ndarray,
    t: float,
    dT: float,
    nsub: int,
    gamma: float,
    tol: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """One sample of the ε-γ observer (Definition 6): flow the live centres C (in place) and the
    plant state x (1 × n, same RK4 steps) from t to t + ΔT, measure y = h(x), and mark the
    centres to keep, |y − h(c)| ≤ γ. With ``tol``, the substeps come from :func:`partition`
    (probes: x and up to 16 centres). Returns (flowed C, keep mask, x, y, the sample's
    flow-error estimate, 0 without ``tol``)."""
    err = 0.0
    steps = None
    if tol is not None:
        probes = np.vstack([x, C[:: max(1, len(C) // 16)]])
        steps, err = partition(plant, probes, t, dT, nsub, tol)
    if steps is None or len(steps) == nsub:  # equal substeps: one call each
        C = rk4(plant, C, t, dT, nsub, inplace=True)
        x = rk4(plant, x, t, dT, nsub)
    else:
        for a, w in steps:
            C = rk4(plant, C, a, w, 1, inplace=True)
            x = rk4(plant, x, a, w, 1, inplace=True)
    y = plant.out(x)[0]
    keep = np.all(np.abs(plant.out(C) - y) <= gamma, axis=1)
    return C, keep, x, y, err


def flow_error(plant: Plant, X: np.ndarray, t: float, dt: float, nsub: int) -> float:
    """Step-doubling estimate of the RK4 error over one sample interval (max over the rows)."""
    if X.shape[0] == 0:
        return 0.0
    a = rk4(plant, X, t, dt, nsub)
    b = rk4(plant, X, t, dt, 2 * nsub)
    return float(np.max(norms(a - b))) * 16 / 15


def cover_box(lo: np.ndarray, hi: np.ndarray, s: float) -> np.ndarray:
    """Centres of the grid 2sℤⁿ whose cells [c − s, c + s] meet the box [lo, hi] (the ε-cover
    F_ε(D) of Definition 5 on a fixed grid, not necessarily minimal)."""
    axes = [
        np.arange(
            math.ceil((a - s) / (2 * s) - INFLATE), math.floor((b + s) / (2 * s) + INFLATE) + 1
        )
        for a, b in zip(lo, hi, strict=True)
    ]
    grid = np.array(list(itertools.product(*axes)), dtype=np.int64).reshape(-1, len(lo))
    return grid * (2 * s)


def _ball_fits(eta: float, s: float, n: int, cap: int) -> None:
    """:class:`MemoryCap` before :func:`recover` lists the grid offsets of a ball B(c, η) in
    cells of half-side s, when the ball alone meets more than ``cap`` cells (a cube of
    half-side η/√n inside it meets at least ⌊η/(s√n)⌋ⁿ). An initial state of −1e16 gave a
    ball whose (2R + 1)ⁿ offsets filled 2.4 GB (MemoryError, exit 3; past 10⁹⁹ "int too
    large", exit 4), and neither time_limit nor max_sim_bytes stopped it (CLI review,
    session 44); :func:`ball_offsets` lists only the offsets that can meet the ball."""
    why = None
    if not (math.isfinite(eta) and math.isfinite(s) and s > 0):
        why = f"a search radius η = {eta:.3g} for cells of half-side {s:.3g}"
    else:
        least = math.floor(eta / (s * math.sqrt(n))) ** n
        if least > cap:
            why = f"at least {count_text(least)} live centres (η/ε ≈ {eta / (2 * s):.3g} per state)"
    if why is not None:
        raise MemoryCap(
            f"the refinement needs {why}, above the memory cap max_centres = {cap:,}: the "
            "error bound grew past what the grid can cover (a state far outside D?); raise "
            "max_centres, or start from a smaller D or a larger γ₀"
        )


def ball_offsets(eta: float, s: float, n: int, most: int, excess: float = 0.0) -> np.ndarray:
    """The integer offsets k (rows) of the cells of half-side s around the grid point nearest
    a centre c that can meet B(c, η): with |c − 2s·base| ≤ s per coordinate, the cell
    2s(base + k) is at least max(0, (|k_i| − 1)·2s) away from c along axis i, and a k whose
    squares of those sum past η² cannot meet the ball (the exact test in :func:`recover`
    decides the rest). Built axis by axis, so that only the offsets that pass are listed:
    the whole cube (2R + 1)ⁿ refused balls of 0.8–1.9 million cells at n = 5 below
    max_centres (re-check review, session 44). :class:`MemoryCap` past ``most`` offsets.

    ``excess``: how far past s a centre may lie from its nearest grid point in doubles (its
    ``rint(c/2s)`` rounds the quotient: at |c|/s ≈ 10¹⁰ a centre near a cell boundary was
    1.03·s from it, and cells that meet its ball were pruned; re-check review 45): every gap
    is that much smaller.

    :param eta: the ball's radius; :param s: the cells' half-side; :param n: the dimension;
    :param most: the most offsets listed; :param excess: the centres' distance past s."""
    R = math.ceil((eta + s + excess) / (2 * s) + 0.5)
    r = np.arange(-R, R + 1, dtype=np.int64)
    gap = np.maximum(np.maximum(np.abs(r) - 1, 0).astype(float) * (2 * s) - excess, 0.0)
    per = gap * gap
    reach = eta * eta * (1 + 1e-9) + 1e-300
    offs = np.zeros((1, 0), dtype=np.int64)
    acc = np.zeros(1)
    for _ in range(n):
        new = acc[:, None] + per[None, :]
        keep = new <= reach
        count = int(np.count_nonzero(keep))
        if count > most:
            raise MemoryCap(
                f"the refinement needs more than {count_text(most)} grid offsets per centre "
                f"(η/ε ≈ {eta / (2 * s):.3g} per state), above 4·max_centres: the error bound "
                "grew past what the grid can cover; raise max_centres, or start from a "
                "smaller D or a larger γ₀"
            )
        i, j = np.nonzero(keep)
        offs = np.concatenate([offs[i], r[j][:, None]], axis=1)
        acc = new[keep]
    return offs


def recover(
    C: np.ndarray,
    eta: float,
    s: float,
    cap: int,
    budget: TimeBudget | None = None,
) -> np.ndarray:
    """Centres of the grid 2sℤⁿ whose cells meet some ball B(c, η), c a row of C (merged:
    each cell once). Raises :class:`MemoryCap` when more than ``cap`` cells are needed, and
    :class:`~obsdesign.simulate.budget.TimeExceeded` past ``budget`` (checked per chunk of rows)."""
    n = C.shape[1]
    eta = eta * (1 + INFLATE) + INFLATE * s
    _ball_fits(eta, s, n, cap)
    base = np.rint(C / (2 * s)).astype(np.int64)
    # how far past s the centres are from their grid points as the hit test below computes
    # them (in doubles), with the rounding of the grid points themselves
    far = float(np.max(np.abs(C - base * (2 * s)), initial=0.0)) - s
    excess = max(far, 0.0) + 4 * np.finfo(float).eps * float(np.max(np.abs(C), initial=0.0))
    offs = ball_offsets(eta, s, n, 4 * cap, excess)
    step = max(1, (1 << 20) // len(offs))
    keys: list[np.ndarray] = []
    total = 0
    for a in range(0, C.shape[0], step):
        if budget is not None:
            budget.check(f"refinement ({a:,} of {C.shape[0]:,} centres done)")
        idx = base[a : a + step, None, :] + offs[None, :, :]
        g = idx * (2 * s)
        d = np.maximum(np.abs(C[a : a + step, None, :] - g) - s, 0.0)
        hit = np.einsum("ijk,ijk->ij", d, d) <= eta * eta
        kept = np.unique(idx[hit], axis=0)
        keys.append(kept)
        total += len(kept)
        if total > 4 * cap:  # merge early to keep memory bounded
            keys = [np.unique(np.concatenate(keys), axis=0)]
            total = len(keys[0])
            if total > cap:
                break
    allk = np.unique(np.concatenate(keys), axis=0) if keys else np.zeros((0, n), np.int64)
    if len(allk) > cap:
        raise MemoryCap(
            f"the refinement needs at least {len(allk):,} live centres, above the memory cap "
            f"max_centres = {cap:,}; dropping any of them could drop the cell of the true state, "
            "so the observer stops: raise max_centres, or start from a smaller D or a larger γ₀"
        )
    return allk * (2 * s)


def paper_children(C: np.ndarray, s: float) -> np.ndarray:
    """Definition 7 literally: X ∪ (X + G_ε), G_ε = {±ε/√n}ⁿ = {±s}ⁿ (exact duplicates merged)."""
    n = C.shape[1]
    G = np.array(list(itertools.product((-s, s), repeat=n)))
    kids = np.concatenate([C, (C[:, None, :] + G[None, :, :]).reshape(-1, n)])
    key = np.round(kids / (s * 1e-6)).astype(np.int64)
    _, first = np.unique(key, axis=0, return_index=True)
    return kids[np.sort(first)]


@dataclass
class Run:
    """What the observer recorded at every sample."""

    t: list[float] = field(default_factory=list)
    x: list[np.ndarray] = field(default_factory=list)
    y: list[np.ndarray] = field(default_factory=list)
    xhat: list[np.ndarray] = field(default_factory=list)
    live: list[int] = field(default_factory=list)
    err9: list[np.ndarray] = field(default_factory=list)
    near: list[float] = field(default_factory=list)
    bound: list[float] = field(default_factory=list)
    gamma: list[float] = field(default_factory=list)
    stored: list[tuple[float, np.ndarray]] = field(default_factory=list)
    switches: list[float] = field(default_factory=list)


#: bytes a live centre may take per state at the peak of a refinement (the centres, their
#: children, the flowed copy, the RK4 temporaries; measured: 6.6·10⁶ centres of 2 states took
#: 1.11 GB, 168 bytes each; re-check review)
CENTRE_BYTES = 72


def _check_centres(spec: Spec, max_centres: int) -> None:
    """Refuse (InputError, exit 2, naming the key) a ``max_centres`` whose centres would not
    fit in ``max_sim_bytes``: 10⁹ were accepted and the run grew past 1 GB until time_limit
    (independent simulate review).

    :param spec: the bound spec; :param max_centres: the cap in force."""
    need = float(max_centres) * (CENTRE_BYTES * spec.system.n + 24)
    cap = limits().max_sim_bytes
    if need > cap:
        raise InputError(
            f"{spec.file}: [simulate] max_centres = {max_centres:,} centres of "
            f"{spec.system.n} states may need about {need / 2**30:.3g} GiB, above the limit of "
            f"{cap / 2**30:.3g} GiB (a smaller max_centres, or --limit max_sim_bytes=N)"
        )


def _options(spec: Spec, kw: dict[str, Any]) -> SimOptions:
    base = spec.simulate.options if spec.simulate and spec.simulate.options else SimOptions()
    vals = {k: v for k, v in kw.items() if v is not None and hasattr(base, k)}
    return SimOptions(**{**base.__dict__, **vals})


def simulate(spec: Spec, params: Parameters, progress: bool = False, **kw: Any) -> SimResult:
    """Run the plant from [simulate] x0 and the concatenated ε-γ observer over the horizon."""
    so = _options(spec, kw)
    o: Options = spec.options
    assert spec.simulate is not None
    plant = Plant(spec)
    n = spec.system.n
    if so.max_centres != SimOptions().max_centres:  # a cap the user gave (the default is not
        _check_centres(spec, so.max_centres)  # a promise to fill it: MemoryCap stops there)
    dT = params.float("dT")
    K = int(round(params.float("K")))
    gam = [float(g) for g in params.float("gamma_schedule")]
    eps = [float(e) for e in params.float("eps_schedule")]
    L_f, L_h = params.float("L_f"), params.float("L_h")
    t0 = float(o.t0)
    N = _samples(spec, dT)
    _warn_unused(spec)
    if N == 0:
        warnings.warn(
            f"[simulate] horizon = {float(spec.simulate.horizon.f):g} is shorter than one "
            f"sampling period ΔT = {dT:.6g}: the observer takes no sample",
            stacklevel=2,
        )
    _check_float_spacing(o, eps[min(len(eps) - 1, N // max(K, 1))] / math.sqrt(n))
    t_end = t0 + N * dT
    _check_time_spacing(t0, t_end, dT / (so.substeps or 1), so.substeps or 1)
    x0 = np.asarray(spec.simulate.x0.f, dtype=float).reshape(1, n)
    _warn_x0_outside_D(spec, o)
    E_lo, E_hi = o.E.lower, o.E.upper
    nsub = so.substeps or 1
    bar = _progress(progress, N)

    t = t0
    x = x0.copy()
    y = plant.out(x)[0]
    _check_finite(x[0], y, t0)
    i = 0
    s = eps[0] / math.sqrt(n)
    cover = cover_box(o.D.lower, o.D.upper, s)
    C = cover[_consistent(plant, cover, y, L_h * eps[0]) & _meets(cover, s, E_lo, E_hi)]
    if len(C) > so.max_centres:
        raise MemoryCap(
            f"the ε₀-cover of D needs {len(C):,} centres, above max_centres = {so.max_centres:,}"
        )
    run = Run()
    tau = t0
    steps = 0
    flow_err = 0.0
    left_E: float | None = None
    left_U = _left_U(plant, o, t0, dT, 0)
    t_start = time.perf_counter()
    budget = TimeBudget(so.time_limit, ADVICE)
    k = 0

    def flow_budget() -> None:
        budget.check(f"in the RK4 flow ({nsub:,} substeps a sample) of sample {k:,} of {N:,}")

    plant.budget = flow_budget
    if not len(C):
        raise ConsistencyLost(_diagnose(run, x0[0], o, "the output filter at t₀", None, cover))
    _record(run, t, x[0], y, C, eps[0], 0.0, L_f, gam[0], so, 0)
    if so.substeps == 0:
        nsub, flow_err = _auto_substeps(plant, C, t, dT, nsub, eps[0])
        _check_time_spacing(t0, t_end, dT / nsub, nsub)
    for k in range(1, N + 1):
        if left_U is None:
            left_U = _left_U(plant, o, t0, dT, k)
        t_next = t0 + k * dT
        steps += len(C) * nsub
        C, keep, x, y, fe = observer_step(
            plant,
            C,
            x,
            t,
            dT,
            nsub,
            gam[min(i, len(gam) - 1)],
            FLOW_TOL * eps[min(i, len(eps) - 1)],
        )
        flow_err = max(flow_err, fe)
        t = t_next
        _check_finite(x[0], y, t)
        if left_E is None and not (np.all(x[0] >= E_lo) and np.all(x[0] <= E_hi)):
            left_E = t
        if not keep.any():
            raise ConsistencyLost(
                _diagnose(
                    run,
                    x[0],
                    o,
                    f"discarding at t = {t:.6g} (γ = {gam[min(i, len(gam) - 1)]:.6g})",
                    (C, eps[min(i, len(eps) - 1)], L_f, t - tau, left_E, flow_err, left_U),
                )
            )
        C = C[keep]
        if k % K == 0:  # switch τ_{i+1}: refine (Definition 7)
            survivors, since = C, t - tau
            e_old = eps[min(i, len(eps) - 1)]
            i += 1
            e_new = eps[min(i, len(eps) - 1)]
            s = e_new / math.sqrt(n)
            if so.refine == "paper":
                C = paper_children(C, s)
                if len(C) > so.max_centres:
                    raise MemoryCap(
                        f"Definition 7 taken literally needs {len(C):,} centres at t = {t:.4g}, "
                        f"above max_centres = {so.max_centres:,} (it grows without bound: "
                        'use refine = "recover")'
                    )
            else:
                eta = e_old * math.exp(L_f * K * dT) + K * flow_err
                C = recover(C, eta, s, so.max_centres, budget)
            C = C[_consistent(plant, C, y, L_h * e_new) & _meets(C, s, E_lo, E_hi)]
            run.switches.append(t)
            tau = t
            if not len(C):
                raise ConsistencyLost(
                    _diagnose(
                        run,
                        x[0],
                        o,
                        f"the refinement at τ = {t:.6g}",
                        (survivors, e_old, L_f, since, left_E, flow_err, left_U),
                    )
                )
            if so.substeps == 0:
                nsub, fe = _auto_substeps(plant, C, t, dT, nsub, e_new)
                _check_time_spacing(t0, t_end, dT / nsub, nsub)
                flow_err = max(flow_err, fe)
        e_cur = eps[min(i, len(eps) - 1)]
        _record(run, t, x[0], y, C, e_cur, t - tau, L_f, gam[min(i, len(gam) - 1)], so, k)
        if bar is not None:
            bar(k, len(C))
        if k < N:
            budget.check(f"{k:,} of {N:,} samples done, {len(C):,} live centres")
    secs = time.perf_counter() - t_start
    if bar is not None:
        bar(None, 0)
    res = _result(spec, run, params, steps, secs, nsub, flow_err, left_E, so)
    _outside_the_design(res, o, t0, N * dT, left_U, left_E)
    return res


#: generic ``[simulate]`` keys this method does not use: the observer of Definition 6 reads
#: the plant's output at the sampling instants ΔT (no noise, no disturbance, no other step)
UNUSED_KEYS = ("noise", "disturbance", "seed", "dt")


def _warn_x0_outside_D(spec: Spec, o: Options) -> None:
    """Warn when [simulate] x0 is not in D (compared exactly): D is the initial search space,
    and the guarantee that the true state's cell is never discarded (Theorem 1, Hernández &
    García) assumes x0 ∈ D; a run from outside it ran silently, with its metrics, until the
    centres were all discarded (search-space trial, session 31)."""
    assert spec.simulate is not None
    x0 = np.asarray(spec.simulate.x0.q, dtype=object).reshape(-1)
    if all(a <= v <= b for v, a, b in zip(x0, o.D.lower_q, o.D.upper_q, strict=True)):
        return
    shown = ", ".join(fmt_exact(v) for v in x0)
    warnings.warn(
        f"[simulate] x0 = ({shown}) is not in D = {o.D.describe()}, the initial search space: "
        "the observer's guarantee (the cell of the true state is never discarded) assumes "
        "x0 ∈ D, so this run shows nothing about it",
        stacklevel=3,
    )


def _warn_unused(spec: Spec) -> None:
    """Warn once for the generic ``[simulate]`` keys the search-space observer ignores
    (:data:`UNUSED_KEYS`): noise, seed and dt gave the same numbers as without them, with no
    word (independent simulate review). The ε-γ observer of Definition 6 (search-space
    paper) discards centres by exact samples y(kΔT) of eq. (1)."""
    sm = spec.simulate
    given = [k for k in UNUSED_KEYS if sm is not None and sm.table.has(k)]
    if given:
        warnings.warn(
            f"[simulate] {', '.join(given)} not used by the search-space observer: it samples "
            "the plant's output y = h(x) exactly every ΔT (Definition 6), without noise or "
            "disturbance",
            stacklevel=3,
        )


#: bytes one sample's record takes (:func:`_record`: four small arrays, five floats and the
#: list entries), beside 8 bytes per state and output entry
RECORD_BYTES = 700


def _samples(spec: Spec, dT: float) -> int:
    """The number of sampling periods ΔT in ``[simulate] horizon``, refused (InputError, exit
    2, naming the key) when their records would not fit in ``max_sim_bytes``: the samples
    follow ΔT of the design, not ``[simulate] dt``, so the API's check before the run cannot
    count them, and ``horizon = 1e30`` ran until ``time_limit``.

    :param spec: the bound spec; :param dT: the design's sampling period."""
    assert spec.simulate is not None
    h = float(spec.simulate.horizon.f)
    ratio = h / dT
    s = spec.system
    per = RECORD_BYTES + 8.0 * (3 * s.n + s.p)
    cap = limits().max_sim_bytes
    if not math.isfinite(ratio) or (ratio + 1.0) * per > cap:
        raise InputError(
            f"{spec.file}: [simulate] horizon = {h:g} is {ratio:.3g} sampling periods ΔT = "
            f"{dT:.6g} of the design, whose records need about {(ratio + 1.0) * per / 2**30:.3g} "
            f"GiB, above the limit of {cap / 2**30:.3g} GiB (a shorter horizon, or --limit "
            "max_sim_bytes=N)"
        )
    return int(math.floor(ratio + 1e-9))


def _left_U(plant: Plant, o: Options, t0: float, dT: float, k: int) -> float | None:
    """The first of the times t0 + (2k − 1)·dT/2 and t0 + k·dT (k = 0: t0 alone), the
    midpoint and the end of sampling period k, where u(t) leaves the input range U of the
    design (None: it does not, or no U). Outside U, L_f and the bound of f are not constants
    of the plant along the run (random-spec fuzzer: u = t run past U gave a true-cell distance
    2.9× the bound ε e^(L_f t) with no word of why). Called once per period inside the
    simulation loop, so it runs under ``time_limit`` (a pass over the whole horizon before the
    loop did not: ``horizon = 1e30`` ran past every limit)."""
    if o.U is None or not plant.inputs:
        return None
    lo, hi = np.asarray(o.U.lower, dtype=float), np.asarray(o.U.upper, dtype=float)
    for j in (0,) if k == 0 else (2 * k - 1, 2 * k):
        t = t0 + j * dT / 2
        u = np.array([plant.u(t)[name] for name in plant.inputs])
        if np.any(u < lo) or np.any(u > hi):
            return t
    return None


def _outside_the_design(
    res: SimResult,
    o: Options,
    t0: float,
    span: float,
    left_U: float | None,
    left_E: float | None = None,
) -> None:
    """Warn (and record in ``info``) when the run leaves what the design certified: u left U
    (``left_U_at``), the true state left E (``left_E_at``: the cell holding it may then be
    discarded; it was an info line only, beside a final error 15 times ε⋆ — search-space
    review, session 43), or the run goes past ``[method] horizon`` (``past_horizon``), where
    the input range was checked (search-space paper, Hernández & García, Lemmas 1-2 hold for
    the constants on E × U)."""
    if left_E is not None:
        warnings.warn(
            f"[simulate] the true state leaves E = {o.E.describe()} at t = {left_E:.6g}: the "
            "constants on E (and the paper's assumption that x stays in E) do not hold after "
            "it, so neither do the observer's bounds",
            stacklevel=3,
        )
    if left_U is not None:
        res.info["left_U_at"] = left_U
        warnings.warn(
            f"[simulate] u(t) leaves the input range U = {o.U.describe() if o.U else ''} at "
            f"t = {left_U:.6g}: L_f and the bound of f are not certified there, so neither "
            "are the observer's bounds",
            stacklevel=3,
        )
    if o.horizon is not None and span > float(o.horizon) * (1 + 1e-12):
        res.info["past_horizon"] = float(o.horizon)
        warnings.warn(
            f"[simulate] the run covers {span:.6g} s past t0, beyond [method] horizon = "
            f"{fmt_exact(o.horizon)}, over which the design checked the input range",
            stacklevel=3,
        )


def _consistent(plant: Plant, C: np.ndarray, y: np.ndarray, r: float) -> np.ndarray:
    """Cells that may contain a point of h⁻¹(y): |h(c) − y| ≤ L_h ε (componentwise, inflated
    for float rounding) — the ∩ (h⁻¹(y))_ε of Definition 7 without h⁻¹."""
    if len(C) == 0:
        return np.zeros(0, dtype=bool)
    return np.all(np.abs(plant.out(C) - y) <= r * (1 + INFLATE) + 1e-12, axis=1)


def _meets(C: np.ndarray, s: float, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Cells [c − s, c + s] that meet the box E: the true state stays in E (the paper's
    ambient-space assumption), so a cell outside E cannot hold it."""
    pad = s * (1 + INFLATE) + INFLATE
    return np.all((C + pad >= lo) & (C - pad <= hi), axis=1)


def _auto_substeps(
    plant: Plant, C: np.ndarray, t: float, dT: float, nsub: int, eps: float
) -> tuple[int, float]:
    """Smallest RK4 step count (doubling from ``nsub``) whose step-doubling error estimate over
    one sample is below 1e-4·ε on a subset of the centres; returns it and the estimate."""
    sub = C[:: max(1, len(C) // 256)]
    err = flow_error(plant, sub, t, dT, nsub)
    while err > 1e-4 * eps and nsub < 256:
        nsub *= 2
        err = flow_error(plant, sub, t, dT, nsub)
    return nsub, err


def _record(
    run: Run,
    t: float,
    x: np.ndarray,
    y: np.ndarray,
    C: np.ndarray,
    eps: float,
    since: float,
    L_f: float,
    gamma: float,
    so: SimOptions,
    k: int,
) -> None:
    c = C.mean(axis=0)
    run.t.append(t)
    run.x.append(x.copy())
    run.y.append(np.asarray(y, dtype=float).copy())
    run.xhat.append(c)
    run.live.append(len(C))
    run.err9.append(np.max(np.abs(C - x), axis=0))
    run.near.append(_row_norm(C - x, np.min))
    spread = _row_norm(C - c, np.max)
    run.bound.append(spread + eps * math.exp(L_f * since))
    run.gamma.append(gamma)
    if k % so.store_every == 0:
        sub = C if len(C) <= 4000 else C[:: len(C) // 4000 + 1]
        run.stored.append((t, sub.copy()))


def _row_norm(D: np.ndarray, pick: Any) -> float:
    """``pick`` (np.min or np.max) of the Euclidean norms of the rows of D, the squares
    summed directly (fast, at millions of centres) unless the picked square lies outside
    [SAFE_LO², SAFE_HI²], where they underflow or overflow: then row by row scaled
    (:func:`obsdesign.simulate.result.norms`). On a plant of size 10⁻²⁰⁰ the true cell's
    distance read 0 at every sample next to a final |e| of 2.9·10⁻²⁰¹ (search-space trial,
    session 29)."""
    sq = float(pick(np.einsum("ij,ij->i", D, D)))
    if SAFE_LO * SAFE_LO <= sq <= SAFE_HI * SAFE_HI:
        return math.sqrt(sq)
    return float(pick(norms(D)))


def _diagnose(
    run: Run, x: np.ndarray, o: Options, where: str, ctx: Any, cells: np.ndarray | None = None
) -> str:
    """'consistency lost': which assumption or bound failed, from the true trajectory.
    ``cells``: the centres before the filter when ``ctx`` (the discarding or refinement
    context) is None."""
    msg = [f"consistency lost: every centre was discarded by {where}."]
    x0 = run.x[0] if run.x else x
    if not np.all(o.D.contains(x0)):
        # %.6g, not np.round: round(1e308, 6) multiplies by 10⁶ and printed inf (session 44)
        shown = ", ".join(repr(float(f"{float(v):.6g}")) for v in np.ravel(x0))
        msg.append(f"x0 = [{shown}] is not in D = {o.D.describe()}.")
    outside = _centre_outside_E(cells if ctx is None else ctx[0], x, o)
    if outside is not None and ctx is None:
        msg.append(outside)
    if ctx is not None:
        C, eps, L_f, since, left_E, flow_err, left_U = ctx
        if left_U is not None and (not run.t or left_U <= run.t[-1] + 1e-12):
            msg.append(
                f"The input left U at t = {left_U:.6g}: the constants on E × U do not apply."
            )
            return " ".join(msg)
        if left_E is not None:
            msg.append(
                f"The true state left E at t = {left_E:.6g}: the constants on E do not apply."
            )
            # outside E the constants are not Lipschitz constants there: that is the cause,
            # the bound checks below would only blame L_h or L_f for it
            return " ".join(msg)
        if outside is not None:
            msg.append(outside)
            return " ".join(msg)
        bound = eps * math.exp(L_f * since) + flow_err
        d = _row_norm(C - x, np.min) if len(C) else math.inf
        if "refinement" in where and d <= bound:
            msg.append(
                f"The nearest survivor was within (2)'s bound ({d:.4g} ≤ {bound:.4g}), so a "
                "re-covered cell held the true state and failed |h(c) − y(τ)| ≤ L_h ε: L_h is "
                "not a Lipschitz constant of h there (a given L_h too small?)."
            )
        elif d > bound:
            msg.append(
                f"Lemma 2's estimate (2) is violated: the nearest centre is {d:.4g} from the true "
                f"state, above ε e^(L_f (t − τ)) = {bound:.4g} (L_f is not a Lipschitz constant "
                "along the trajectory, or the flow error exceeded its estimate)."
            )
        else:
            msg.append(
                f"The nearest centre is within (2)'s bound ({d:.4g} ≤ {bound:.4g}) but its output "
                "differs by more than γ: L_h is not a Lipschitz constant of h there, or Lemma 2's "
                "horizon Δτ < log(κ/L_h)/L_f does not hold."
            )
    return " ".join(msg)


#: the smallest cell half-side, in float spacings of E's coordinates, that a run takes
MIN_CELL_ULPS = 16
#: the smallest RK4 time step, in float spacings of the times a run reaches: each time then
#: lies within 1/2048 of a step of its value (t0 = 1.7·10⁹, a Unix time, allows steps from
#: 2.4·10⁻⁴ s)
MIN_STEP_ULPS = 1024


def _check_finite(x: np.ndarray, y: Any, t: float) -> None:
    """Refuse (exit 4) a run whose true state or output is not finite in floats: f = x2 +
    0·2^1100·x1 (exactly a rotation) evaluated 0·inf = nan, and the run ended exit 1 "the true
    state left E", blaming the certified constants (expression soundness trial, session 34)."""
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(np.asarray(y, dtype=float)))):
        raise InconclusiveError(
            f"the true state or output is not finite in floats at t = {t:.6g} (x = "
            f"{np.asarray(x).tolist()}): f, h or u overflows or is undefined there in float "
            "arithmetic (e.g. 0·2^1100 = 0·inf), so floats cannot simulate this plant"
        )


def _check_float_spacing(o: Options, s: float) -> None:
    """Refuse (exit 4) a run whose smallest cell half-side ``s`` = ε_i/√n (the finest level
    the horizon reaches) is below MIN_CELL_ULPS float spacings of a coordinate of E: the grid
    2sℤⁿ of Definition 7 cannot be represented there, centres round by more than a cell, and
    the run lost consistency with a message blaming the certified L_h (E = 10⁹ ± 2.5·10⁻⁶,
    ε⋆ = 6.7·10⁻⁹ against a spacing of 1.2·10⁻⁷; soundness trial, session 33)."""
    big = np.maximum(np.abs(np.asarray(o.E.lower, float)), np.abs(np.asarray(o.E.upper, float)))
    ulp = np.spacing(big)
    j = int(np.argmax(ulp))
    if s < MIN_CELL_ULPS * ulp[j]:
        raise InconclusiveError(
            f"the cells of the finest level the horizon reaches have half-side ε/√n = {s:.3g}, "
            f"below {MIN_CELL_ULPS} float spacings ({ulp[j]:.3g}) of E's coordinate {j + 1} "
            f"(up to {big[j]:.6g} in magnitude): float64 centres cannot represent the grid "
            "(translate the state so that E lies near the origin, or a larger γ⋆ / shorter "
            "horizon)"
        )


def _check_time_spacing(t0: float, t_end: float, step: float, nsub: int) -> None:
    """Refuse (exit 4) a run whose RK4 step ΔT / substeps is below MIN_STEP_ULPS float
    spacings of the times it reaches: t0 + k·ΔT then rounds by more than a step, the input
    u(t) is held over windows of many sampling periods and the time column repeats — with
    t0 = 10¹⁶ (spacing 2, ΔT = 0.0064) the run simulated another plant (final state
    (−0.75, −0.66) where the spec's is (sin 6, cos 6)) and with t0 = −10³⁰⁸ a plant that never
    moved, both exit 0 with no word (search-space trial, session 40). The space analogue is
    :func:`_check_float_spacing`."""
    ulp = float(np.spacing(max(abs(t0), abs(t_end))))
    if not step >= MIN_STEP_ULPS * ulp:
        per = f"ΔT / {nsub:,} substeps = {step:.3g}" if nsub > 1 else f"ΔT = {step:.3g}"
        raise InconclusiveError(
            f"the simulation's time step {per} is below {MIN_STEP_ULPS} float spacings "
            f"({ulp:.3g}) of its times (t0 = {t0:.6g} to {t_end:.6g}): float64 times cannot "
            "resolve it, so u(t) and the flow would be evaluated at the wrong times (set "
            "[method] t0 nearer 0, e.g. shift the time in f, h and u)"
        )


def _centre_outside_E(C: np.ndarray | None, x: np.ndarray, o: Options) -> str | None:
    """The cause when the centre nearest the true state lies outside E: h and f were evaluated
    there, where the constants on E need not hold (y = x1³ with E = [−1, 1]: the true state's
    cell had its centre at 1.8 and was dropped at t₀, with a message that named no cause;
    search-space trial, session 27)."""
    if C is None or not len(C):
        return None
    c = C[int(np.argmin(np.max(np.abs(C - x), axis=1)))]
    if np.all(c >= o.E.lower) and np.all(c <= o.E.upper):
        return None
    return (
        f"The centre of the cell nearest the true state, {np.round(c, 6).tolist()}, lies "
        f"outside E = {o.E.describe()}: h and f are evaluated there, where the constants on E "
        "need not hold (the guarantee needs E to contain the cells around the trajectories: "
        "enlarge E by the cell radius ε₀, or move x0 or D away from E's edge)."
    )


def _progress(on: bool, N: int) -> Any:
    if not on:
        return None
    from rich.progress import BarColumn, Progress, TextColumn

    from obsdesign.report.render import stderr_console

    # on stderr: on stdout it came before --format json's JSON (simulate trial, session 27)
    p = Progress(
        TextColumn("observer"),
        BarColumn(),
        TextColumn("{task.fields[live]} centres"),
        console=stderr_console(),
    )
    task = p.add_task("run", total=N, live=0)
    p.start()

    def update(k: int | None, live: int) -> None:
        if k is None:
            p.stop()
            return
        p.update(task, completed=k, live=live)

    return update


def _result(
    spec: Spec,
    run: Run,
    params: Parameters,
    steps: int,
    secs: float,
    nsub: int,
    flow_err: float,
    left_E: float | None,
    so: SimOptions,
) -> SimResult:
    x = np.array(run.x)
    xhat = np.array(run.xhat)
    err9 = np.array(run.err9)
    final = float(norms(xhat[-1] - x[-1]))
    info = {
        "eps_star": params.float("eps_star"),
        "final_error": final,
        "final_error_fn9": err9[-1].tolist(),
        "final_bound": run.bound[-1],
        "final_true_cell": run.near[-1],
        "final_live": run.live[-1],
        "max_live": int(max(run.live)),
        "switches": len(run.switches),
        "centre_steps": int(steps),
        "centre_steps_per_s": steps / secs if secs > 0 else math.inf,
        "rk4_substeps": nsub,
        "flow_error_estimate": flow_err,
        "refine": so.refine,
    }
    if left_E is not None:
        info["left_E_at"] = left_E
    return SimResult(
        t=np.array(run.t),
        x=x,
        xhat=xhat,
        y=np.array(run.y),
        states=list(spec.system.states),
        extra={
            "live": np.array(run.live),
            "err_fn9": err9,
            "true_cell": np.array(run.near),
            "bound": np.array(run.bound),
            "gamma": np.array(run.gamma),
            "switches": np.array(run.switches),
            "stored": run.stored,
        },
        info=info,
    )
