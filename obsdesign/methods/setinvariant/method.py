"""The ``set-invariant`` method (Dórea & Pimenta, "Design of set-invariant estimators for
linear discrete-time systems"): a thin facade over :mod:`.options`, :mod:`.design`,
:mod:`.claims`, :mod:`.sim` and :mod:`.plots`.

Design: a D-(C,A)-λ-contractive polyhedron {e : G e <= 1} containing Ω, by the symmetric
algorithm (Section VI) or the general algorithm (Section V), the piecewise-affine injection
table of Proposition 4.1 (one output) and, when it exists, a linear gain L (Proposition 7.1);
all proved exactly (Theorem 3.1 at every z of Z_d, in rationals). The choices where the paper
is ambiguous are listed in docs/methods/set-invariant.md.
"""

from __future__ import annotations

from pathlib import Path

from obsdesign.methods.base import Method, SimOption, SummaryField
from obsdesign.params import Parameters
from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec

from .options import LAWS, Options, SimOptions


class SetInvariant(Method):
    """Set-invariant estimator: polyhedron, injection table, linear gain, exact claims."""

    key = "set-invariant"
    title = "Set-invariant estimator (D-(C,A)-λ-contractive polyhedron)"
    paper = (
        "C. E. T. Dórea, A. C. C. Pimenta, Design of set-invariant estimators for linear "
        "discrete-time systems, IEEE CDC-ECC 2005"
    )
    Options = Options
    SimOptions = SimOptions
    needs_linear = True
    required_params = ("G", "V", "lambda", "converged")
    summary_fields = (
        SummaryField("facets", "facets", "d"),
        SummaryField("iterations", "iterations", "d"),
        SummaryField("certified factor", "contractivity", ".9g", side="up"),
        SummaryField("L factor", "L_factor", ".9g", side="up"),
    )
    sim_options = (
        SimOption(
            "law",
            "str",
            None,
            "injection law: interpolated (eq. (12), default with one output), time-varying "
            "(eq. (10)), online-lp (LP (9) at each step) or linear (v = L z: the spec's [method].L when given, else the designed L)",
            choices=LAWS,
        ),
        SimOption("time_limit", "float", None, "seconds the simulation may run", min=1e-3),
    )

    # parse_options, design, certify, simulate, options_schema: the base class's defaults
    # (options / design / claims / sim modules of this package, imported on first use)

    def plot_simulation(self, spec: Spec, res: SimResult, path: str | Path) -> Path:
        """The polyhedra with the error trajectory (Fig. 1)."""
        from .plots import plot_simulation

        return plot_simulation(spec, res, path)

    def plot_design(self, spec: Spec, params: Parameters, path: str | Path) -> Path:
        """ε(z) of LP (9) against z (Fig. 2) next to the polyhedra."""
        from .plots import plot_design

        return plot_design(spec, params, path)


METHOD = SetInvariant()
