"""The ``[method]`` and ``[simulate]`` keys of the ``stubborn`` method (paper 002: Astolfi,
Alessandri, Zaccarian, "Stubborn observers for linear and nonlinear systems", WUDS 2017)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.errors import SpecError
from obsdesign.methods.base import table_schema
from obsdesign.simulate.budget import DEFAULT_LIMIT, TIME_LIMIT_SCHEMA, parse_time_limit
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

#: design criteria of the slides' "optimized parameter selection" (steps 2-4)
CRITERIA = ("R", "K", "l2")
MODES = ("full", "redesign", "high-gain")

#: stated defaults (docs/methods/stubborn.md, "Choices where the paper is ambiguous")
DEFAULT_FRACTION = fmpq(1, 2)
DEFAULT_GAIN_BOUND = fmpq(100)
DEFAULT_MARGIN = fmpq(1, 10**6)
DEFAULT_LAMBDA_TOL = fmpq(1, 1000)
#: high-gain: ε of σ' = −ℓλσ + ℓ(λ + ε)e_y² (the slides prove some ε* exists, give no formula)
DEFAULT_EPSILON = fmpq(1)
#: high-gain: ℓ = this factor times the bound ℓ* ≥ 2L|P| when the spec gives no ℓ
ELL_FACTOR = fmpq(11, 10)


@dataclass
class Options:
    """Typed ``[method]`` of ``stubborn``.

    mode: ``full`` (design K, λ, R, W: LMIs (1)-(3) or (7)-(9) with X free), ``redesign``
    (K given: X = P K, LMIs in P) or ``high-gain`` (second part of the slides).
    K: the given gain (redesign; for high-gain the Hurwitz coefficients k_1..k_n).
    lam: a fixed λ (no search) or None; fraction: λ = fraction·λ_max (continuous time) or
    1 − λ = fraction·(1 − λ_best) (discrete time). gain_bound: ‖X‖₂ ≤ gain_bound with P ⪰ I
    (hence ‖K‖₂ ≤ gain_bound) in full mode (default 100, none when only r_bound is given).
    r_bound: R ⪯ r_bound·I (optional). criterion: R (min λ_max(R)), K (min ‖X‖₂),
    l2 (min the L2 gain from d to e, bounded real lemma on A − KC with Bd).
    margin: strictness margin of the solver (LMIs are certified strict, exactly).
    """

    mode: str
    K: np.ndarray | None
    lam: fmpq | None
    fraction: fmpq
    gain_bound: fmpq | None
    criterion: str
    margin: fmpq
    lambda_tol: fmpq
    # high-gain redesign
    lipschitz: fmpq | None = None
    ell: fmpq | None = None
    epsilon: fmpq | None = None
    #: high-gain: φ̂ = φ(clip(x̂, −state_bound, state_bound)) (bounded outside X); None: no clip
    state_bound: np.ndarray | None = None
    #: R ⪯ r_bound·I in every solve (the other way to make the best λ finite); with it the gain
    #: bound is off unless given too
    r_bound: fmpq | None = None
    #: not a spec key: the gain bound as ‖X‖₂ ≤ gain_bound·s with P ⪰ s·I (scale-free, still
    #: ‖K‖₂ ≤ gain_bound), the design's retry when ‖X‖₂ ≤ gain_bound with P ⪰ I, W ⪰ I is
    #: infeasible (:func:`obsdesign.methods.stubborn.design.design`); the report says so in
    #: its parameter ``gain_normalization``
    scale_free_gain: bool = False


@dataclass
class SimOptions:
    """Method keys of ``[simulate]``: outlier study settings and the saturation initial state.

    noise_std: standard deviation of the Gaussian measurement noise; outlier_rate:
    probability that a sample carries an outlier; amplitudes: maximal absolute values of the
    outliers (uniform in [−a, a]); runs: Monte Carlo runs per amplitude; sigma0: σ̄(0)
    (None: max_i w_i (C e(0))_i², so that the injection starts unsaturated); time_limit:
    seconds the simulation may run (exit 3 past it)."""

    noise_std: float = 0.05
    outlier_rate: float = 0.01
    amplitudes: tuple[float, ...] = (0.1, 1.0, 10.0, 100.0, 1000.0)
    runs: int = 100
    sigma0: float | None = None
    #: high-gain scenario: an impulsive outlier (held over one step dt) and a window of
    #: high-frequency noise (uniform in [−hf_amplitude, hf_amplitude], new every step)
    impulse_time: float | None = None
    impulse_value: float = 0.0
    hf_start: float = 0.0
    hf_stop: float = 0.0
    hf_amplitude: float = 0.0
    #: high-gain scenario: Heun substeps per dt (ν held over the step)
    substeps: int = 1
    #: seconds the simulation may run (exit 3 past it)
    time_limit: float = DEFAULT_LIMIT


def _check_triangular(spec: Spec) -> None:
    """The high-gain certificate is about ẋ = A₀x + φ(x) with A₀ the chain of integrators (ones
    on the superdiagonal) and φ in the triangular form of the slides (φ_i of x_1..x_i for
    i < n): [system.A] above its diagonal must be A₀'s, and ψ_i (or f_i − x_{i+1}) must not
    depend on x_{i+1}..x_n (sympy, after expansion: a dependence sympy cannot cancel is
    refused). A spec's A was never read by the certificate: A = [[0, 1], [5, 0]] was
    certified "A − KC is Hurwitz" for A₀ − KC while the spec's A − KC is not, and the
    simulated error grew to 10⁶ (independent soundness trial, session 23). The terms of A on
    and below the diagonal belong to φ: [method].lipschitz must cover them."""
    import sympy

    s = spec.system
    n = s.n
    if s.A is not None:
        A = np.asarray(s.A.q, dtype=object)
        for i in range(n):
            for j in range(i + 1, n):
                if A[i, j] != (1 if j == i + 1 else 0):
                    raise SpecError(
                        spec.file,
                        "system.A",
                        f"has {A[i, j]} at ({i + 1}, {j + 1}): mode = 'high-gain' needs the "
                        "triangular form ẋ_i = x_{i+1} + φ_i(x_1..x_i), so A must be 1 on the "
                        "superdiagonal and 0 above it (its entries on and below the diagonal "
                        "are part of φ, and [method].lipschitz must cover them)",
                    )
    exprs, key = (s.f, "system.f") if s.f is not None else (s.psi, "system.psi")
    for i, e in enumerate((exprs or [])[: n - 1]):
        later_states = set(s.states[i + 1 :])
        try:
            phi = e.sympy() - (sympy.Symbol(s.states[i + 1]) if s.f is not None else 0)
            later = {str(v) for v in phi.free_symbols} & later_states
            # expanded only where a later state is left, and only when small: expanding
            # (x1 + 1)^300000 took 6 GB at load (non-finite expressions trial, session 35)
            small = _expandable(phi)
            if later and small:
                later = {str(v) for v in sympy.expand(phi).free_symbols} & later_states
        except (ArithmeticError, TypeError, ValueError, RecursionError) as err:
            # max(x1, 1/0), sat(x1, 0/0): sympy's "not comparable" was exit 3 (same trial)
            raise SpecError(
                spec.file,
                f"{key}[{i}]",
                f"cannot be read for the high-gain triangular-form check: {err}",
            ) from None
        if later:
            what = f"{key}[{i}]" + (f" − {s.states[i + 1]}" if s.f is not None else "")
            raise SpecError(
                spec.file,
                key,
                f"{what} depends on {', '.join(sorted(later))}"
                + ("" if small else " (too large to expand and cancel)")
                + ": mode = 'high-gain' needs the "
                f"triangular form ẋ_i = x_{{i+1}} + φ_i(x_1..x_i) (φ_{i + 1} of "
                f"{', '.join(s.states[: i + 1])} only)",
            )


#: the triangular-form check expands φ_i only with at most this many operations and integer
#: powers of at most this degree (:func:`_expandable`)
EXPAND_MAX_OPS = 2000
EXPAND_MAX_POWER = 64


def _expandable(phi: Any) -> bool:
    """Whether sympy may expand φ_i to cancel a dependence: at most :data:`EXPAND_MAX_OPS`
    operations and no integer power above :data:`EXPAND_MAX_POWER` (expansion grows with
    the power's binomial coefficients)."""
    import sympy

    if sympy.count_ops(phi) > EXPAND_MAX_OPS:
        return False
    return all(
        not (p.exp.is_Integer and abs(int(p.exp)) > EXPAND_MAX_POWER) for p in phi.atoms(sympy.Pow)
    )


def parse_options(table: Table, spec: Spec) -> Options:
    """Read and validate ``[method]`` (every error names file and key)."""
    s = spec.system
    mode_default = "redesign" if table.has("K") else "full"
    mode = table.str("mode", default=mode_default, choices=MODES)
    n = s.n
    lip = ell = eps = None
    if mode == "high-gain":
        if s.p != 1:
            raise table.error("mode", "the high-gain redesign needs one output y = x1")
        # the slides' high-gain part is continuous time, with y = x1: a discrete spec was
        # certified with the continuous ℓ-bound and crashed in simulate, and another C was
        # ignored (the observer measured x1 whatever C said) — stubborn review
        if s.discrete:
            raise SpecError(
                spec.file,
                "system.time",
                "is 'discrete', but mode = 'high-gain' is the continuous-time high-gain "
                "redesign of the slides: use time = 'continuous'",
            )
        if s.C is not None and not all(
            v == (1 if j == 0 else 0) for j, v in enumerate(np.asarray(s.C.q).reshape(-1))
        ):
            raise SpecError(
                spec.file,
                "system.C",
                "must be [[1, 0, …, 0]] in mode = 'high-gain' (the high-gain observer measures "
                "y = x1 of the triangular form): reorder the states so that y is the first",
            )
        _check_triangular(spec)
        K = table.vector("K", n=n).q
        lip = table.scalar("lipschitz", min=0).q
        e = table.scalar("ell", default=None, min=1)
        ell = None if e is None else e.q
        eps = table.scalar("epsilon", default=DEFAULT_EPSILON, min=0, strict_min=True).q
        lam_v = table.scalar("lambda", default=fmpq(1), min=0, strict_min=True)
        sb = table.vector("state_bound", n=n).f if table.has("state_bound") else None
        if sb is not None and np.any(sb <= 0):
            raise table.error("state_bound", "expected positive bounds")
        table.done()
        return Options(
            mode,
            np.asarray(K, dtype=object).reshape(n, 1),
            lam_v.q,
            DEFAULT_FRACTION,
            DEFAULT_GAIN_BOUND,
            "R",
            DEFAULT_MARGIN,
            DEFAULT_LAMBDA_TOL,
            lip,
            ell,
            eps,
            sb,
        )
    if s.A is None or s.C is None:
        raise table.error("mode", "full and redesign modes need the linear model A, C in [system]")
    for key, v in (("f", s.f), ("psi", s.psi)):
        if v is not None:
            raise SpecError(
                spec.file,
                f"system.{key}",
                f"is not read in {mode} mode (LMIs (1)-(3)/(7)-(9) certify the linear plant "
                "A, C): remove it, or use mode = 'high-gain'",
            )
    K = None
    if mode == "redesign":
        if not table.has("K"):
            raise table.error("K", "is missing: the stubborn redesign keeps a given gain K")
        K = table.matrix("K", rows=n, cols=s.p, vector_as="column").q
    elif table.has("K"):
        raise table.error("K", "full-stubborn mode designs K; use mode = 'redesign' to give it")
    if s.discrete:
        lv = table.scalar("lambda", default=None, min=0, max=1, strict_min=True, strict_max=True)
    else:
        lv = table.scalar("lambda", default=None, min=0, strict_min=True)
    frac = table.scalar(
        "lambda_fraction", default=DEFAULT_FRACTION, min=0, max=1, strict_min=True
    ).q
    if lv is not None and table.has("lambda_fraction"):
        raise table.error("lambda_fraction", "give lambda (fixed) or lambda_fraction, not both")
    rb = table.scalar("r_bound", default=None, min=0, strict_min=True)
    gb_default = None if rb is not None else DEFAULT_GAIN_BOUND
    gbv = table.scalar("gain_bound", default=gb_default, min=0, strict_min=True)
    gb = None if gbv is None else gbv.q
    if mode == "redesign" and table.has("gain_bound"):
        raise table.error("gain_bound", "the redesign keeps the given K: no gain bound to set")
    crit = table.str("criterion", default="R", choices=CRITERIA)
    if crit == "K" and mode == "redesign":
        raise table.error("criterion", "criterion 'K' sizes the designed gain: full mode only")
    if crit == "l2" and s.nd == 0:
        raise table.error("criterion", "criterion 'l2' needs a disturbance input: give [system] Bd")
    margin = table.scalar("margin", default=DEFAULT_MARGIN, min=0, strict_min=True).q
    tol = table.scalar("lambda_tol", default=DEFAULT_LAMBDA_TOL, min=0, strict_min=True).q
    table.done()
    o = Options(mode, K, None if lv is None else lv.q, frac, gb, crit, margin, tol)
    o.r_bound = None if rb is None else rb.q
    return o


def parse_simulate(table: Table, spec: Spec) -> SimOptions:
    """The method's own ``[simulate]`` keys (the outlier model of the study)."""
    o = SimOptions()
    if table.has("noise_std"):
        o.noise_std = float(table.scalar("noise_std", min=0).f)
    if table.has("outlier_rate"):
        o.outlier_rate = float(table.scalar("outlier_rate", min=0, max=1).f)
    if table.has("amplitudes"):
        o.amplitudes = tuple(float(a) for a in table.vector("amplitudes").f)
        if any(a < 0 for a in o.amplitudes):
            raise table.error("amplitudes", "expected non-negative outlier amplitudes")
    if table.has("runs"):
        o.runs = table.int("runs", min=1)
    if table.has("sigma0"):
        o.sigma0 = float(table.scalar("sigma0", min=0).f)
    if table.has("impulse_time"):
        o.impulse_time = float(table.scalar("impulse_time", min=0).f)
        o.impulse_value = float(table.scalar("impulse_value").f)
    if table.has("hf_start") or table.has("hf_stop"):
        o.hf_start = float(table.scalar("hf_start", min=0).f)
        o.hf_stop = float(table.scalar("hf_stop", min=0).f)
        o.hf_amplitude = float(table.scalar("hf_amplitude", min=0).f)
        if o.hf_stop < o.hf_start:  # an empty window added no noise, silently (review 19)
            raise table.error(
                "hf_stop", f"expected hf_stop >= hf_start = {o.hf_start:g} (the noise window)"
            )
    if table.has("substeps"):
        o.substeps = table.int("substeps", min=1)
        if o.substeps > MAX_SUBSTEPS:
            raise table.error(
                "substeps", f"expected an integer <= {MAX_SUBSTEPS:,}, got {o.substeps}"
            )
    o.time_limit = parse_time_limit(table)
    return o


#: the largest ``[simulate] substeps`` of the high-gain scenario
MAX_SUBSTEPS = 10_000


def options_schema(key: str) -> dict[str, Any]:
    """JSON schema of the method's ``[method]`` table."""
    num = {"type": "number"}
    vec = {"type": "array", "items": num}
    mat = {"type": "array", "items": {"anyOf": [num, vec]}}
    return table_schema(
        key,
        {
            "mode": {"enum": list(MODES)},
            "K": mat,
            "lambda": {**num, "exclusiveMinimum": 0},
            "lambda_fraction": {**num, "exclusiveMinimum": 0, "maximum": 1},
            "gain_bound": {**num, "exclusiveMinimum": 0},
            "r_bound": {**num, "exclusiveMinimum": 0},
            "criterion": {"enum": list(CRITERIA)},
            "margin": {**num, "exclusiveMinimum": 0},
            "lambda_tol": {**num, "exclusiveMinimum": 0},
            "lipschitz": {**num, "minimum": 0},
            "ell": {**num, "minimum": 1},
            "epsilon": {**num, "exclusiveMinimum": 0},
            "state_bound": {
                **vec,
                "description": "high-gain mode: the estimate is clipped to |x̂_i| ≤ state_bound_i inside φ",
            },
        },
    )


def simulate_schema() -> dict[str, Any]:
    """JSON-schema properties of the method's own ``[simulate]`` keys."""
    num = {"type": "number"}
    return {
        "noise_std": {**num, "minimum": 0},
        "outlier_rate": {**num, "minimum": 0, "maximum": 1},
        "amplitudes": {  # one number is a list of one (the reader's vector)
            "anyOf": [
                {**num, "minimum": 0},
                {"type": "array", "items": {**num, "minimum": 0}, "minItems": 1},
            ]
        },
        "runs": {"type": "integer", "minimum": 1},
        "sigma0": {**num, "minimum": 0},
        "impulse_time": {**num, "minimum": 0},
        "impulse_value": num,
        "hf_start": {**num, "minimum": 0},
        "hf_stop": {**num, "minimum": 0},
        "hf_amplitude": {**num, "minimum": 0},
        "substeps": {"type": "integer", "minimum": 1, "maximum": MAX_SUBSTEPS},
        "time_limit": TIME_LIMIT_SCHEMA,
    }
