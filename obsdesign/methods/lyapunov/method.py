"""The ``lyapunov`` method: a linear observer with a certified quadratic Lyapunov function.

Observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) (or its continuous analogue); P ≻ 0 with
(A − LC)ᵀP(A − LC) ⪯ λ²P (continuous: (A − LC)ᵀP + P(A − LC) ⪯ −2αP), for a given or an
LMI-designed L, the best rate with its bracket, and optionally the ISS gain μ: the linear case
of eq. (4)-(7), Section 5 of Astolfi, Bernard, Postoyan, Marconi, "Redesign of discrete-time
nonlinear observers with state estimate constraints guaranteed in prescribed convex set",
NOLCOS 2019. Options in :mod:`.options`, design in :mod:`.design`, claims in :mod:`.claims`.
"""

from __future__ import annotations

from typing import Any

from obsdesign.certify.claim import Claim
from obsdesign.methods.base import Design, Method, Progress, SimOption, SummaryField, sim_width
from obsdesign.methods.lyapunov import claims as _claims
from obsdesign.methods.lyapunov import design as _design
from obsdesign.methods.lyapunov.options import (
    Options,
    SimOptions,
    parse_options,
    parse_simulate,
    schema,
    simulate_schema,
)
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


class Lyapunov(Method):
    key = "lyapunov"
    title = "Lyapunov-decay linear observer"
    paper = (
        "Astolfi, Bernard, Postoyan, Marconi, 'Redesign of discrete-time nonlinear observers "
        "with state estimate constraints guaranteed in prescribed convex set', NOLCOS 2019, "
        "Section 5 (quadratic Lyapunov function)"
    )
    Options = Options
    SimOptions = SimOptions
    required_params = ("L", "P")
    # certified on the linear model; an expression plant gets the failed claim linear-plant
    # (the observer can still be simulated on it)
    plant_expressions = frozenset({"f", "psi", "h"})
    summary_fields = (
        SummaryField("lambda", "lambda", side="up"),
        SummaryField("alpha", "alpha", side="down"),
        SummaryField("best", "lambda_best", side="up"),
        SummaryField("best", "alpha_best", side="down"),
        SummaryField("mu", "mu", ".4g", side="up"),
    )

    sim_options = (
        SimOption("runs", "int", None, "Monte Carlo runs (default [simulate] runs, else 1)", min=1),
        SimOption(
            "batch", "int", None, "runs stepped together (default: as many as fit in memory)", min=1
        ),
        SimOption("time_limit", "float", None, "seconds the simulation may run", min=1e-3),
    )

    def parse_options(self, table: Table, spec: Spec) -> Options:
        return parse_options(table, spec)

    def parse_simulate(self, table: Table, spec: Spec) -> SimOptions:
        return parse_simulate(table, spec)

    def simulate_schema(self) -> dict[str, Any]:
        return simulate_schema()

    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        return _design.design(spec, progress)

    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        return _claims.certify(spec, params)

    def simulate(
        self,
        spec: Spec,
        params: Parameters,
        runs: int | None = None,
        batch: int | None = None,
        span: tuple[int, int] | None = None,
        time_limit: float | None = None,
    ) -> Any:
        """One run of the spec's scenario, or ``runs`` batched Monte Carlo runs (per-run
        metrics and quantiles; :func:`obsdesign.simulate.linear.simulate_linear_observer_batch`);
        ``span = (a, b)``: only runs a..b-1 of them (``simulate --workers``, see
        :func:`obsdesign.simulate.montecarlo.run_batch`). ``runs`` given, even 1, is the Monte
        Carlo study: its run 0 is run 0 of any N (``--runs 1`` was the single scenario, drawn
        from ``default_rng(seed)``, not from child 0 of ``SeedSequence(seed)``; review).
        ``time_limit`` (else ``[simulate] time_limit``, 300 s): past it, exit 3 (10⁶ steps of
        an expression plant took ~70 s, and memory allowed 20 times more)."""
        from obsdesign.simulate.budget import DEFAULT_LIMIT, TimeBudget
        from obsdesign.simulate.linear import (
            simulate_linear_observer,
            simulate_linear_observer_batch,
        )

        _warn_unused_signals(spec)
        so = spec.simulate.options if spec.simulate is not None else None
        given = runs if runs is not None else (so.runs if so is not None else None)
        n = given or 1
        ie = so.initial_error if so is not None else None
        limit = time_limit if time_limit is not None else (so.time_limit if so else DEFAULT_LIMIT)
        budget = TimeBudget(limit, "raise time_limit, or fewer runs or a shorter horizon")
        L = params.shaped("L", (spec.system.n, spec.system.p))
        _warn_float_gain(spec, params, L)
        if given is None and ie is None and batch is None and span is None:
            return simulate_linear_observer(spec, L, budget)
        return simulate_linear_observer_batch(spec, L, n, ie, batch, span, budget)

    def sim_bytes(self, spec: Spec, runs: int, steps: float, options: dict[str, Any]) -> float:
        """One run keeps its trajectories; several runs keep run 0's trajectories, per-run
        metrics and one batch's block buffers (:mod:`obsdesign.simulate.montecarlo`).

        :param spec: the bound spec; :param runs: runs; :param steps: steps per run;
        :param options: the typed ``simulate`` options (``batch``)."""
        from obsdesign.simulate import montecarlo as mc

        s = spec.system
        one = super().sim_bytes(spec, 1, steps, options)
        if runs == 1:
            return one
        width = sim_width(s)
        batch = options.get("batch") or mc.BATCH_RUNS
        blocks = 8.0 * min(batch, runs) * (mc.CHUNK + mc.BLOCK + 1) * width
        return one + 8.0 * runs * (5 * s.n + 1) + blocks

    def options_schema(self) -> dict[str, Any]:
        return schema(self.key)


def _warn_unused_signals(spec: Spec) -> None:
    """Warn when ``[simulate.noise]`` (``[simulate.disturbance]``) is given but the plant's
    ``[system] h`` (``f``), being the whole output (state) map, names no v1… (d1…): the signal
    then reaches nothing (independent simulate review: ``h = ["x1 + 0.01*x2^2"]`` gave the
    same numbers with and without noise, without a word). Section 5 of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019) has y = Cx + v."""
    import warnings

    s, sim = spec.system, spec.simulate
    if sim is None:
        return
    for sig, exprs, names, what, key in (
        (sim.noise, s.h, s.noises, "h", "noise"),
        (sim.disturbance, s.f, s.disturbances, "f", "disturbance"),
    ):
        if exprs is None or sig.kind == "zero":
            continue
        if not any(ex.uses(v) for ex in exprs for v in names):
            warnings.warn(
                f"[simulate.{key}] reaches nothing: [system] {what} is the whole "
                f"{'output' if what == 'h' else 'state'} map and names none of "
                f"{', '.join(names) or 'its variables'}",
                stacklevel=3,
            )


METHOD = Lyapunov()


def _warn_float_gain(spec: Spec, params: Parameters, L: Any) -> None:
    """A warning when the simulation's closed loop, A − LC in doubles, is not within the
    certified rate (or not stable): the certificate is about the exact gain, and an
    ill-conditioned 5-state plant certified at ρ = 0.647 simulated to |e| = 8.7·10⁴⁰ with
    exit 0 and no word (interop trial, session 39). Decided exactly
    (:func:`obsdesign.lyap.float_realization`); nothing for a plant without A and C.

    :param spec: the spec; :param params: the parameters simulated; :param L: their gain
    in floats."""
    import warnings

    from obsdesign.lyap import exact_closed_loop, exact_within, float_closed_loop, float_realization

    s = spec.system
    if s.A is None or s.C is None:
        return
    key = "lambda" if s.discrete else "alpha"
    rate = params.exact(key, [], accept_float=True) if key in params else None
    # the design says so in a note; simulate was an internal failure (re-check, 44)
    Ao = float_closed_loop(s.A.f, L, s.C.f, "a simulation in doubles")
    verdict = float_realization(Ao, s.discrete, rate)
    if verdict == "ok":
        return
    what = (
        "is not stable" if verdict == "unstable" else "is stable but slower than the certified rate"
    )
    Lq = params.exact("L", [], accept_float=True) if "L" in params else None
    Aex = None if Lq is None else exact_closed_loop(s.A.q, Lq, s.C.q)
    if Aex is not None and not exact_within(Aex, s.discrete, rate if verdict == "slower" else None):
        # the gain itself, not its doubles: an L edited to an unstable gain was blamed on the
        # doubles (tamper review 46)
        warnings.warn(
            f"the simulated observer's A − LC {what}, in doubles and for the exact gain "
            "alike: the report's claims cannot hold for it (obsdesign verify says which fail)",
            UserWarning,
            stacklevel=2,
        )
        return
    warnings.warn(
        f"the simulated observer's A − LC in doubles {what}: the certificate is about the "
        "exact gain (report parameters.exact), which doubles do not hold on this "
        "ill-conditioned plant",
        UserWarning,
        stacklevel=2,
    )
