"""The ``impulsive`` method: the facade over options, design, claims and simulation.

Schaum, Feketa, Meurer, Moreno, "Robust nonlinear observer design based on impulsive
dissipativity" (MTNS 2020). Spec: ``[system]`` (A, C, ``psi``), ``[nonlinearity]`` (data of
Assumption 1, optional ``[nonlinearity.falsify]``), ``[method]`` (L, alpha, noise_bound, M,
kappa, qsr_scaling, digits); see docs/methods/impulsive.md.
"""

from __future__ import annotations

from pathlib import Path

from obsdesign.methods.base import Method, SimOption, SummaryField
from obsdesign.methods.impulsive import claims as _claims
from obsdesign.methods.impulsive.options import Options, SimOptions
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec


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
    sim_grid_from_dt = False  # the grid follows the sampling instants
    plant_expressions = frozenset({"psi", "f", "h", "u"})  # f, h, u refused with its own message
    required_params = _claims.PARAM_KEYS
    summary_fields = (
        SummaryField("T_min", side="up"),
        SummaryField("T_max", side="down"),
        SummaryField("κ", "kappa"),
        SummaryField("κ_n", "kappa_n", side="down"),
        SummaryField("ϖ_o", "varpi_o", side="up"),
        SummaryField("r_B", "ball_radius", side="up"),
    )
    summary_format = ".4g"
    sim_options = (
        SimOption("runs", "int", 20, "number of sampling sequences (runs)", min=1, max=100_000),
        SimOption("seed", "int", 0, "seed of the sampling intervals and the noise", min=0),
        SimOption("sampling_file", "path", None, "sampling intervals from a file (one run)"),
        SimOption("rtol", "float", 1e-7, "relative tolerance of RK45", min=1e-14, max=1e-2),
        SimOption("time_limit", "float", None, "seconds the simulation may run", min=1e-3),
    )

    def plot_simulation(self, spec: Spec, result: SimResult, path: str | Path) -> Path:
        from obsdesign.methods.impulsive.sim import plot_simulation

        return plot_simulation(spec, result, path)


METHOD = Impulsive()
