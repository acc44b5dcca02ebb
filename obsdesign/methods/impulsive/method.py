"""The ``impulsive`` method: the facade over options, design, claims and simulation.

Schaum, Feketa, Meurer, Moreno, "Robust nonlinear observer design based on impulsive
dissipativity" (MTNS 2020). Spec: ``[system]`` (A, C, ``psi``), ``[nonlinearity]`` (data of
Assumption 1, optional ``[nonlinearity.falsify]``), ``[method]`` (L, alpha, noise_bound, M,
kappa, qsr_scaling, digits); see docs/methods/impulsive.md.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from obsdesign.certify.claim import Claim
from obsdesign.methods.base import Design, Method, Progress, SimOption, SummaryField
from obsdesign.methods.impulsive import claims as _claims
from obsdesign.methods.impulsive import design as _design
from obsdesign.methods.impulsive import options as _options
from obsdesign.methods.impulsive.options import Options, SimOptions
from obsdesign.params import Parameters
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


class Impulsive(Method):
    """Impulsive dissipative observer (11) with the sampling window [T_min, T_max] of
    Theorem 2."""

    key = "impulsive"
    title = "Impulsive dissipative observer: sampling window [T_min, T_max]"
    paper = (
        "Schaum, Feketa, Meurer, Moreno, Robust nonlinear observer design based on impulsive "
        "dissipativity, MTNS 2020"
    )
    Options = Options
    SimOptions = SimOptions
    extra_tables = ("nonlinearity",)
    required_params = _claims.PARAM_KEYS
    summary_fields = (
        SummaryField("T_min", "T_min", ".4g"),
        SummaryField("T_max", "T_max", ".4g"),
        SummaryField("κ", "kappa", ".4g"),
        SummaryField("κ_n", "kappa_n", ".4g"),
        SummaryField("ϖ_o", "varpi_o", ".4g"),
        SummaryField("r_B", "ball_radius", ".4g"),
    )
    sim_options = (
        SimOption("runs", "int", 20, "number of sampling sequences (runs)", min=1, max=100_000),
        SimOption("seed", "int", 0, "seed of the sampling intervals and the noise", min=0),
        SimOption("sampling_file", "path", None, "sampling intervals from a file (one run)"),
        SimOption("rtol", "float", 1e-7, "relative tolerance of RK45", min=1e-14, max=1e-2),
    )

    def parse_options(self, table: Table, spec: Spec) -> Options:
        return _options.parse_options(table, spec)

    def parse_simulate(self, table: Table, spec: Spec) -> SimOptions:
        return _options.parse_simulate(table, spec)

    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        return _design.design(spec, progress)

    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        return _claims.certify(spec, params)

    def simulate(self, spec: Spec, params: Parameters, **options: Any) -> SimResult:
        from obsdesign.methods.impulsive.sim import simulate_spec

        return simulate_spec(spec, params, **options)

    def plot_simulation(self, spec: Spec, result: SimResult, path: str | Path) -> Path:
        from obsdesign.methods.impulsive.sim import plot_simulation

        return plot_simulation(spec, result, path)

    def options_schema(self) -> dict[str, Any]:
        return _options.options_schema(self.key)

    def simulate_schema(self) -> dict[str, Any]:
        return _options.simulate_schema()


METHOD = Impulsive()
