"""The ``constrained`` method: redesign of a discrete-time observer so that its estimate stays
in a prescribed convex set (Astolfi, Bernard, Postoyan, Marconi, "Redesign of discrete-time
nonlinear observers with state estimate constraints guaranteed in prescribed convex set",
NOLCOS 2019). A thin facade over :mod:`.options`, :mod:`.design`, :mod:`.claims`, :mod:`.sim`."""

from __future__ import annotations

from typing import Any

from obsdesign.certify.claim import Claim
from obsdesign.methods.base import Design, Method, Progress, SimOption, SummaryField
from obsdesign.methods.constrained import claims as _claims
from obsdesign.methods.constrained import sim as _sim
from obsdesign.methods.constrained.design import design
from obsdesign.methods.constrained.options import (
    Options,
    SimOptions,
    options_schema,
    parse_options,
    parse_sim,
    simulate_schema,
)
from obsdesign.params import Parameters
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


class Constrained(Method):
    """Refining map M (20) / G (23) with certified γ (24), δ, v_max (13), v_min (21), θ (22)."""

    key = "constrained"
    title = "Constrained-estimate redesign: refining map M/G, v_max, v_min, δ, γ, θ"
    paper = (
        "Astolfi, Bernard, Postoyan, Marconi, Redesign of discrete-time nonlinear observers "
        "with state estimate constraints guaranteed in prescribed convex set, NOLCOS 2019"
    )
    Options = Options
    SimOptions = SimOptions
    needs_linear = False
    required_params = _claims.REQUIRED
    summary_fields = (
        SummaryField("γ", "gamma", ".4g"),
        SummaryField("γ_max", "gamma_max", ".4g"),
        SummaryField("δ", "delta", ".4g"),
        SummaryField("v_max", "v_max", ".4g"),
        SummaryField("v_min", "v_min", ".4g"),
        SummaryField("θ", "theta", ".4g"),
    )
    sim_options = (
        SimOption(
            "theta_m",
            "str",
            None,
            "refining steps per sample, comma separated (one modified observer each)",
        ),
        SimOption("gamma", "float", None, "simulation-only γ (UNCERTIFIED above (24))", min=0),
        SimOption("saturation_r", "float", None, "also run the saturated observer (29)", min=0),
    )

    def parse_options(self, table: Table, spec: Spec) -> Options:
        return parse_options(table, spec)

    def parse_simulate(self, table: Table, spec: Spec) -> SimOptions:
        return parse_sim(table, spec)

    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        return design(spec, progress)

    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        return _claims.certify(spec, params)

    def simulate(self, spec: Spec, params: Parameters, **options: Any) -> SimResult:
        return _sim.simulate(spec, params, **options)

    def plot_simulation(self, spec: Spec, result: SimResult, path: Any) -> Any:  # type: ignore[override]
        return _sim.plot(spec, result, path)

    def options_schema(self) -> dict[str, Any]:
        return options_schema(self.key)

    def simulate_schema(self) -> dict[str, Any]:
        return simulate_schema()


METHOD = Constrained()
