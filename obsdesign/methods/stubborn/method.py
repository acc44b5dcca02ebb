"""The ``stubborn`` method facade: declarations and delegation (paper 002: Astolfi, Alessandri,
Zaccarian, "Stubborn observers for linear and nonlinear systems", WUDS 2017)."""

from __future__ import annotations

from typing import Any

from obsdesign.methods.base import Method, SimOption, SummaryField
from obsdesign.methods.stubborn import options as _opts
from obsdesign.spec.models import Spec


class Stubborn(Method):
    key = "stubborn"
    title = "Stubborn observer: K = P⁻¹X, λ, R, W = diag(w_i) by LMIs; high-gain redesign"
    paper = (
        "Astolfi, Alessandri, Zaccarian, Stubborn observers for linear and nonlinear systems, "
        "slides, WUDS 2017"
    )
    Options = _opts.Options
    SimOptions = _opts.SimOptions
    needs_linear = False  # the high-gain mode reads f / psi; linear modes check A, C themselves
    plant_expressions = frozenset({"f", "psi", "u"})  # f / psi: high-gain mode only
    required_params = ("K", "lambda")
    summary_fields = (
        SummaryField("λ", "lambda"),
        SummaryField("λ_max", "lambda_max"),
        SummaryField("K", fmt=".4g"),
        SummaryField("R", fmt=".4g"),
        SummaryField("W", fmt=".4g"),
        SummaryField("ℓ", "ell"),
        SummaryField("ε", "epsilon"),
    )
    sim_options = (
        SimOption(
            "study",
            "str",
            "none",
            "run the outlier study (Monte Carlo)",
            choices=("none", "outliers"),
        ),
        SimOption(
            "runs", "int", 0, "Monte Carlo runs per amplitude (0: the spec's, default 100)", min=0
        ),
        SimOption(
            "observer",
            "str",
            "stubborn",
            "observer of the single run",
            choices=("stubborn", "luenberger", "standard"),
        ),
        SimOption("time_limit", "float", None, "seconds the simulation may run", min=1e-3),
    )

    def sim_bytes(self, spec: Spec, runs: int, steps: float, options: dict[str, Any]) -> float:
        """One run's trajectories without ``study`` (the spec's ``runs`` are the outlier
        study's: a single run of 10⁶ steps was refused by the memory estimate of 100 runs;
        independent simulate review), else the study's runs (the default estimate).

        :param spec: the bound spec; :param runs: the study's runs; :param steps: steps per
        run; :param options: the typed ``simulate`` options (``study``)."""
        if options.get("study", "none") == "none":
            runs = 1
        return super().sim_bytes(spec, runs, steps, options)

    def plot_simulation(self, spec: Spec, result: Any, path: Any) -> Any:
        from obsdesign.methods.stubborn import plots

        return plots.plot_simulation(spec, result, path)


METHOD = Stubborn()
