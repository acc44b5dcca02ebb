"""The ``constrained`` method: redesign of a discrete-time observer so that its estimate stays
in a prescribed convex set (Astolfi, Bernard, Postoyan, Marconi, NOLCOS 2019; paper 000)."""

from __future__ import annotations

from typing import Any

from obsdesign.certify.claim import Claim
from obsdesign.methods.base import Design, Method, Progress
from obsdesign.methods.constrained import claims as _claims
from obsdesign.methods.constrained import sim as _sim
from obsdesign.methods.constrained.design import design_params
from obsdesign.methods.constrained.options import Options, parse_options, parse_sim
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


class Constrained(Method):
    key = "constrained"
    title = "Constrained-estimate redesign: refining map M/G, v_max, v_min, δ, γ, θ"
    paper = "000 (Astolfi, Bernard, Postoyan, Marconi, NOLCOS 2019)"

    def parse_options(self, table: Table, spec: Spec) -> Options:
        return parse_options(table, spec)

    def parse_simulate(self, table: Table, spec: Spec) -> None:
        o: Options = spec.options
        o.sim = parse_sim(table, spec)

    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        if progress:
            progress("Lyapunov data, v_max, ε_max, δ, γ, v_min, θ")
        vals, notes = design_params(spec)
        solver = {"name": "scipy Lyapunov equation + exact rational bounds", "status": "optimal"}
        return Design(Parameters(vals), solver, notes)

    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        return _claims.certify(spec, params)

    def simulate(self, spec: Spec, params: Parameters, **kwargs: Any) -> Any:
        return _sim.simulate(spec, params, **kwargs)

    def plot_simulation(self, spec: Spec, res: Any, path: Any) -> Any:
        return _sim.plot(spec, res, path)

    def summary(self, params: Parameters) -> str:
        f = params.float
        return (
            f"γ = {f('gamma'):.4g} (≤ {f('gamma_max'):.4g}), δ = {f('delta'):.4g}, v_max = {f('v_max'):.4g}, "
            f"v_min = {f('v_min'):.4g}, θ = {f('theta'):.4g}"
        )

    def template(self) -> str:
        return TEMPLATE

    def options_schema(self) -> dict[str, Any]:
        num = {"type": "number"}
        vec = {"type": "array", "items": num}
        mat = {"type": "array", "items": {"anyOf": [num, vec]}}
        return {
            "type": "object",
            "required": ["key", "X", "c", "eps_min"],
            "additionalProperties": False,
            "properties": {
                "key": {"const": self.key},
                "L": mat,
                "lambda": {**num, "exclusiveMinimum": 0, "exclusiveMaximum": 1},
                "rho": {**num, "minimum": 0, "exclusiveMaximum": 1},
                "P": mat,
                "mu": {**num, "minimum": 0},
                "X": {"type": "string"},
                "Xhat": {"type": "string"},
                "X0": {"type": "string"},
                "Xhat0": {"type": "string"},
                "eps_min": {**num, "exclusiveMinimum": 0},
                "eps_max": {**num, "exclusiveMinimum": 0},
                "gamma": {**num, "exclusiveMinimum": 0},
                "gamma_uncertified": {"type": "boolean"},
                "margin": {**num, "minimum": 0},
                "rate_tol": {**num, "exclusiveMinimum": 0},
                "c": {
                    "type": "object",
                    "properties": {
                        "type": {"enum": ["box", "polytope", "ellipsoid"]},
                        "norm": {"enum": ["euclidean", "max"]},
                        "lower": vec,
                        "upper": vec,
                        "G": mat,
                        "h": vec,
                        "Q": mat,
                        "r": {**num, "exclusiveMinimum": 0},
                    },
                    "required": ["type"],
                },
                "D": {"type": "object", "properties": {"lower": vec, "upper": vec}},
                "U": {"type": "object", "properties": {"lower": vec, "upper": vec}},
                "f": {"type": "array", "items": {"type": "string"}},
                "h": {"type": "array", "items": {"type": "string"}},
                "F": {"type": "array", "items": {"type": "string"}},
            },
        }


METHOD = Constrained()

TEMPLATE = """\
# obsdesign spec: constrained-estimate redesign (method "constrained", paper 000).
# Observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u), refined between samples by
# G(x̂) = x̂ − γ P⁻¹ (dc/dx)ᵀ c(x̂) while x̂ ∈ C_max \\ C_min (eq. (20), (23)).
title = "my constrained observer"

[system]
time = "discrete"
A = [[0, 1], [1, 0]]
C = [[1, 0]]

[sets.X]                     # where the plant state lives (Assumption 1): box or polytope
type = "box"
lower = [-1, -1]
upper = [1, 1]

[method]
key = "constrained"
L = [-1.87, 1.874]           # observer gain (a column)
lambda = 0.955               # P solves (A−LC)ᵀP(A−LC) − λ²P = −I (omit: best certified λ)
# rho = 0.96                 # β(v, w) = ρ v + μ|w|², default ρ = λ²; μ is computed
# P = [[...]]  rho = ...  mu = ...   # or give the Lyapunov data yourself (instead of lambda)
X = "X"
# Xhat = "Xhat"              # the set where x̂ must stay (default: outer set of C_min)
eps_min = 0.01               # C_min = {|c| ≤ ε_min}
# eps_max = 1e5              # default: the smallest with X̂_max ⊆ C_max (Assumption 3(2))
# gamma = 1e-5               # default: the largest γ allowed by (24), γ ≤ λ_min(P)/δ²
# gamma_uncertified = false  # true: accept a γ above (24) (claims fail, simulation allowed)
# X0 = "X0"  Xhat0 = "Xhat0"  # optional: v̆_max of Section 4 from initial-condition sets
# Nonlinear plant/observer (then give P, rho, mu; (5) is checked on samples, "numerical"):
# the plant's f and h go in [system] (f = ["x2", "0.5*sin(x1)"], h = ["x1 + v1"]);
# F = ["x2_hat + 0.2*(y1 - x1_hat)", "0.5*sin(x1_hat)"]   # x̂⁺ = F(x̂, u, y)
# [method.U]  lower = [...]  upper = [...]   # input bounds (needed with expressions and inputs)

[method.c]                   # the constraint map c of Assumption 3
type = "box"                 # box (eq. 19) | polytope (G x ≤ h) | ellipsoid (eq. 18: Q, r)
# norm = "euclidean"         # |c| in C_ε = {|c| ≤ ε}: "euclidean" (paper) or "max" (box-shaped C_ε)
lower = [-1.1, -1.1]
upper = [1.1, 1.1]

[method.D]                   # bounds of w = (d, v): process disturbance, then output noise
lower = [-3]
upper = [3]

[simulate]
horizon = 300
x0 = [-1, -1]
xhat0 = [1, 1]
theta_m = [10, 3]            # refining steps per sample (default: θ of (22), capped)
# gamma = 17                 # simulation-only γ (reported as uncertified if above (24))
saturation_r = 2             # also run the naive saturated observer (29)
[simulate.noise]
kind = "windows"
windows = [{ start = 151, stop = 153, value = [3] }]
"""
