"""The ``stubborn`` method facade: declarations and delegation (paper 002: Astolfi, Alessandri,
Zaccarian, "Stubborn observers for linear and nonlinear systems", WUDS 2017)."""

from __future__ import annotations

from typing import Any

from obsdesign.certify.claim import Claim
from obsdesign.methods.base import Design, Method, Progress, SimOption, SummaryField
from obsdesign.methods.stubborn import options as _opts
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


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
    required_params = ("K", "lambda")
    summary_fields = (
        SummaryField("λ", "lambda"),
        SummaryField("λ_max", "lambda_max"),
        SummaryField("K", "K"),
        SummaryField("R", "R"),
        SummaryField("W", "W"),
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
    )

    def summary(self, params: Parameters) -> str:
        """The summary fields, matrices printed compactly (rows separated by ';', 4 digits)."""
        import numpy as np

        out = []
        for f in self.summary_fields:
            if f.param not in params:
                continue
            v = np.asarray(params.float(f.param), dtype=float)
            if v.ndim == 0:
                out.append(f"{f.label} = {float(v):.6g}")
            else:
                rows = np.atleast_2d(v) if v.ndim == 2 else v.reshape(1, -1)
                txt = "; ".join(", ".join(f"{x:.4g}" for x in r) for r in rows)
                out.append(f"{f.label} = [{txt}]")
        return ", ".join(out)

    def parse_options(self, table: Table, spec: Spec) -> _opts.Options:
        return _opts.parse_options(table, spec)

    def parse_simulate(self, table: Table, spec: Spec) -> _opts.SimOptions:
        return _opts.parse_sim(table, spec)

    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        if spec.options.mode == "high-gain":
            from obsdesign.methods.stubborn.highgain import design_params as hg

            vals, solver, notes = hg(spec, progress)
        else:
            from obsdesign.methods.stubborn.design import design_params

            vals, solver, notes = design_params(spec, progress)
        return Design(Parameters(vals), solver, notes)

    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        if spec.options.mode == "high-gain":
            from obsdesign.methods.stubborn.highgain import certify as hg

            return hg(spec, params)
        from obsdesign.methods.stubborn.claims import lmi_claims

        return lmi_claims(spec, params)

    def simulate(self, spec: Spec, params: Parameters, **options: Any) -> Any:
        from obsdesign.methods.stubborn import sim

        return sim.simulate(spec, params, **options)

    def plot_simulation(self, spec: Spec, result: Any, path: Any) -> Any:
        from obsdesign.methods.stubborn import plots

        return plots.plot_simulation(spec, result, path)

    def options_schema(self) -> dict[str, Any]:
        num = {"type": "number"}
        vec = {"type": "array", "items": num}
        mat = {"type": "array", "items": {"anyOf": [num, vec]}}
        return {
            "type": "object",
            "required": ["key"],
            "additionalProperties": False,
            "properties": {
                "key": {"const": self.key},
                "mode": {"enum": list(_opts.MODES)},
                "K": mat,
                "lambda": {**num, "exclusiveMinimum": 0},
                "lambda_fraction": {**num, "exclusiveMinimum": 0, "maximum": 1},
                "gain_bound": {**num, "exclusiveMinimum": 0},
                "r_bound": {**num, "exclusiveMinimum": 0},
                "criterion": {"enum": list(_opts.CRITERIA)},
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
        }

    def simulate_schema(self) -> dict[str, Any]:
        num = {"type": "number"}
        return {
            "noise_std": {**num, "minimum": 0},
            "outlier_rate": {**num, "minimum": 0, "maximum": 1},
            "amplitudes": {"type": "array", "items": {**num, "minimum": 0}},
            "runs": {"type": "integer", "minimum": 1},
            "sigma0": {**num, "minimum": 0},
            "impulse_time": {**num, "minimum": 0},
            "impulse_value": num,
            "hf_start": {**num, "minimum": 0},
            "hf_stop": {**num, "minimum": 0},
            "hf_amplitude": {**num, "minimum": 0},
        }


METHOD = Stubborn()
