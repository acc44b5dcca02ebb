"""The ``search-space`` method: the concatenated ε-γ observer of Hernández & García, "An
alternative approach to the state observation problem for Lipschitz continuous systems with
controls" (paper 004) — certified ΔT, K, γ/ε schedule, and a vectorized observer over a grid
of hypercube centres."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from obsdesign.methods.base import Method, SimOption, SummaryField
from obsdesign.methods.searchspace import options as _opts
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


class SearchSpace(Method):
    key = "search-space"
    title = "Search-space (discarding) observer: ΔT, Δτ = KΔT, γ/ε schedule, hypercube grid"
    paper = (
        "Hernández, García, An alternative approach to the state observation problem for "
        "Lipschitz continuous systems with controls"
    )
    Options = _opts.Options
    SimOptions = _opts.SimOptions
    needs_linear = False
    sim_grid_from_dt = False  # the grid follows the sampling instants
    plant_expressions = frozenset({"f", "h", "u"})
    required_params = (
        "L_f",
        "L_h",
        "f_sup",
        "kappa",
        "gamma_star",
        "eps_star",
        "dT",
        "K",
        "dtau",
        "gamma_schedule",
        "eps_schedule",
    )
    summary_fields = (
        SummaryField("L_f", side="up"),
        SummaryField("L_h", side="up"),
        SummaryField("‖f_u‖", "f_sup", side="up"),
        SummaryField("κ", "kappa"),
        SummaryField("ΔT", "dT", ".4g"),
        SummaryField("K", fmt=".0f"),
        SummaryField("ε⋆", "eps_star", ".4g"),
    )
    sim_options = (
        SimOption("max_centres", "int", None, "memory cap: live centres (fails, never drops)", 1),
        SimOption("refine", "str", None, "refinement at switches", choices=_opts.REFINE),
        SimOption(
            "substeps", "int", None, "RK4 steps per sample (0: automatic)", 0, _opts.MAX_SUBSTEPS
        ),
        SimOption("store_every", "int", None, "store the centres every k samples", 1),
        SimOption("time_limit", "float", None, "seconds the simulation may run", 1e-3),
        SimOption("progress", "bool", False, "show a progress bar"),
    )

    def parse_simulate(self, table: Table, spec: Spec) -> _opts.SimOptions:
        return _opts.parse_sim(table, spec)

    def plot_simulation(self, spec: Spec, result: Any, path: str | Path) -> Any:
        from obsdesign.methods.searchspace import plots

        return plots.plot_simulation(spec, result, path)


METHOD = SearchSpace()
