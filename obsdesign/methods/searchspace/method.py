"""The ``search-space`` method: the concatenated ε-γ observer of Hernández & García, "An
alternative approach to the state observation problem for Lipschitz continuous systems with
controls" (paper 004) — certified ΔT, K, γ/ε schedule, and a vectorized observer over a grid
of hypercube centres."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from obsdesign.certify.claim import Claim
from obsdesign.methods.base import (
    Design,
    Method,
    Progress,
    SimOption,
    SolverResult,
    SolverStatus,
    SummaryField,
)
from obsdesign.methods.searchspace import claims as _claims
from obsdesign.methods.searchspace import options as _opts
from obsdesign.methods.searchspace.design import design_params
from obsdesign.params import Parameters
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
        SummaryField("L_f", "L_f"),
        SummaryField("L_h", "L_h"),
        SummaryField("‖f_u‖", "f_sup"),
        SummaryField("κ", "kappa"),
        SummaryField("ΔT", "dT", ".4g"),
        SummaryField("K", "K", ".0f"),
        SummaryField("ε⋆", "eps_star", ".4g"),
    )
    sim_options = (
        SimOption("max_centres", "int", None, "memory cap: live centres (fails, never drops)", 1),
        SimOption("refine", "str", None, "refinement at switches", choices=_opts.REFINE),
        SimOption("substeps", "int", None, "RK4 steps per sample (0: automatic)", 0),
        SimOption("store_every", "int", None, "store the centres every k samples", 1),
        SimOption("progress", "bool", False, "show a progress bar"),
    )

    def parse_options(self, table: Table, spec: Spec) -> _opts.Options:
        return _opts.parse_options(table, spec)

    def parse_simulate(self, table: Table, spec: Spec) -> _opts.SimOptions:
        return _opts.parse_sim(table, spec)

    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        if progress:
            progress("constants on E by interval arithmetic, then Theorem 1's rules")
        t0 = time.perf_counter()
        vals, notes = design_params(spec)
        solver = SolverResult(
            "interval branch and bound + exact rules",
            SolverStatus.CLOSED_FORM,
            seconds=time.perf_counter() - t0,
        )
        return Design(Parameters(vals), solver, notes)

    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        return _claims.certify(spec, params)

    def simulate(self, spec: Spec, params: Parameters, **options: Any) -> Any:
        from obsdesign.methods.searchspace import sim

        return sim.simulate(spec, params, **options)

    def plot_simulation(self, spec: Spec, result: Any, path: str | Path) -> Any:
        from obsdesign.methods.searchspace import plots

        return plots.plot_simulation(spec, result, path)

    def options_schema(self) -> dict[str, Any]:
        return _opts.options_schema(self.key)

    def simulate_schema(self) -> dict[str, Any]:
        return _opts.simulate_schema()


METHOD = SearchSpace()
