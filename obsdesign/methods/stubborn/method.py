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
            "observer of the single run (the outlier study compares all four)",
            choices=("stubborn", "luenberger", "standard"),
        ),
        SimOption("time_limit", "float", None, "seconds the simulation may run", min=1e-3),
    )

    def sim_run_count(self, runs: int, options: dict[str, Any]) -> int:
        """One run without ``study`` (the spec's ``runs`` are the study's; the refusal of a
        single run said "100 run(s)": review)."""
        return runs if options.get("study", "none") != "none" else 1

    def sim_bytes(self, spec: Spec, runs: int, steps: float, options: dict[str, Any]) -> float:
        """One run's trajectories without ``study`` (the spec's ``runs`` are the outlier
        study's: a single run of 10⁶ steps was refused by the memory estimate of 100 runs;
        independent simulate review); with it, also the study's batch of 4 observers ×
        amplitudes × runs and its chunks of noise.

        :param spec: the bound spec; :param runs: the study's runs; :param steps: steps per
        run; :param options: the typed ``simulate`` options (``study``)."""
        one = super().sim_bytes(spec, 1, steps, options)
        if options.get("study", "none") == "none":
            return one
        # the study steps 4 observers × amplitudes × runs at once, its noise drawn 2,000 steps
        # at a time: 10,000 amplitudes reached 4.3 GB, the estimate counting neither the
        # amplitudes nor the observers (independent simulate review)
        so = spec.simulate.options if spec.simulate is not None else None
        na = len(getattr(so, "amplitudes", ())) or 1
        s = spec.system
        batch = 4.0 * na * runs
        chunk = min(2000.0, steps)  # the study draws its noise 2,000 steps at a time
        return one + 8.0 * (3 * chunk * na * runs * s.p + 12 * batch * max(s.n, s.p))

    def plot_simulation(self, spec: Spec, result: Any, path: Any) -> Any:
        from obsdesign.methods.stubborn import plots

        return plots.plot_simulation(spec, result, path)


METHOD = Stubborn()
