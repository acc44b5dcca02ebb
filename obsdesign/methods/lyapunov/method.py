"""The ``lyapunov`` method: a linear observer with a certified quadratic Lyapunov function.

Observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) (or its continuous analogue); P ≻ 0 with
(A − LC)ᵀP(A − LC) ⪯ λ²P (continuous: (A − LC)ᵀP + P(A − LC) ⪯ −2αP), for a given or an
LMI-designed L, the best rate with its bracket, and optionally the ISS gain μ: the linear case
of eq. (4)-(7), Section 5 of Astolfi, Bernard, Postoyan, Marconi, "Redesign of discrete-time
nonlinear observers with state estimate constraints guaranteed in prescribed convex set",
NOLCOS 2019. Options in :mod:`.options`, design in :mod:`.design`, claims in :mod:`.claims`.
"""

from __future__ import annotations

from typing import Any

from obsdesign.certify.claim import Claim
from obsdesign.methods.base import Design, Method, Progress, SummaryField
from obsdesign.methods.lyapunov import claims as _claims
from obsdesign.methods.lyapunov import design as _design
from obsdesign.methods.lyapunov.options import Options, parse_options, schema
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


class Lyapunov(Method):
    key = "lyapunov"
    title = "Lyapunov-decay linear observer"
    paper = (
        "Astolfi, Bernard, Postoyan, Marconi, 'Redesign of discrete-time nonlinear observers "
        "with state estimate constraints guaranteed in prescribed convex set', NOLCOS 2019, "
        "Section 5 (quadratic Lyapunov function)"
    )
    Options = Options
    required_params = ("L", "P")
    summary_fields = (
        SummaryField("lambda", "lambda"),
        SummaryField("alpha", "alpha"),
        SummaryField("best", "lambda_best"),
        SummaryField("best", "alpha_best"),
        SummaryField("mu", "mu", ".4g"),
    )

    def parse_options(self, table: Table, spec: Spec) -> Options:
        return parse_options(table, spec)

    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        return _design.design(spec, progress)

    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        return _claims.certify(spec, params)

    def simulate(self, spec: Spec, params: Parameters, **options: Any) -> Any:
        from obsdesign.simulate.linear import simulate_linear_observer

        return simulate_linear_observer(spec, params.float("L"))

    def options_schema(self) -> dict[str, Any]:
        return schema(self.key)


METHOD = Lyapunov()
