"""The ``constrained`` method: redesign of a discrete-time observer so that its estimate stays
in a prescribed convex set (Astolfi, Bernard, Postoyan, Marconi, "Redesign of discrete-time
nonlinear observers with state estimate constraints guaranteed in prescribed convex set",
NOLCOS 2019). A thin facade over :mod:`.options`, :mod:`.design`, :mod:`.claims`, :mod:`.sim`."""

from __future__ import annotations

from typing import Any

from obsdesign.methods.base import Method, SimOption, SummaryField
from obsdesign.methods.constrained import claims as _claims
from obsdesign.methods.constrained.options import Options, SimOptions
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec


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
    plant_expressions = frozenset({"f", "h", "psi"})  # psi: refused with its own message
    required_params = _claims.REQUIRED
    # γ, γ_max and θ are the design's choices, used together ((22)-(24)): rounded each to
    # a side of its own, "γ ≥ 2.396e-05 … θ ≤ 1.11e+15" broke θ-covers (re-check trial,
    # session 32); the bounds δ, v_max, v_min are shown on their safe sides
    summary_fields = (
        SummaryField("γ", "gamma"),
        SummaryField("γ_max", "gamma_max"),
        SummaryField("δ", "delta", side="up"),
        SummaryField("v_max", side="up"),
        SummaryField("v_min", side="down"),
        SummaryField("θ", "theta"),
    )
    summary_format = ".4g"
    sim_options = (
        SimOption(
            "theta_m",
            "str",
            None,
            "refining steps per sample, comma separated (one modified observer each)",
        ),
        SimOption("gamma", "float", None, "simulation-only γ (UNCERTIFIED above (24))", min=0),
        SimOption("saturation_r", "float", None, "also run the saturated observer (29)", min=0),
        SimOption("time_limit", "float", None, "seconds the simulation may run", min=1e-3),
    )

    def plot_simulation(self, spec: Spec, result: SimResult, path: Any) -> Any:  # type: ignore[override]
        from obsdesign.methods.constrained.sim import plot

        return plot(spec, result, path)


METHOD = Constrained()
