"""Commented spec template of the set-invariant method (``obsdesign init set-invariant``)."""

TEMPLATE = """\
# obsdesign spec: set-invariant estimator (method "set-invariant", Dórea & Pimenta).
# Error e = x − x̂ obeys e⁺ = A e + B1 d + v(z), z = C e + η, d ∈ D, |η| <= eta_bar.
# The design finds a D-(C,A)-λ-contractive polyhedron {G e <= 1} containing Ω and the
# output injection v(z); observer x̂⁺ = A x̂ − v(z), z = y − C x̂.
title = "my set-invariant estimator"

[system]
time = "discrete"
A = [[0.7, 0.7], [-0.7, 0.7]]
B1 = [1, 1]                   # disturbance input (a column); omit when there is none
C = [[1, 1]]                  # one output (or p = n − 1 outputs: linear law, eta_bar = 0)

[sets.omega]                  # initial-error polytope Ω (must contain the origin inside)
type = "symmetric-polytope"   # |Q e| <= 1 ; or type = "polytope" with G, g ; or "box"
Q = [[1, 0], [0, 1]]

[method]
key = "set-invariant"
omega = "omega"
disturbance = { type = "box", lower = [-1], upper = [1] }   # D (dimension = columns of B1)
eta_bar = 0                   # measurement-noise bound |η| <= eta_bar
lambda = 0.9                  # contraction rate, 0 < λ <= 1 (1: invariance)
algorithm = "symmetric"       # symmetric (Section VI) | general (Section V) | none (check Ω)
delta_tol = 1e-6              # Δδ of the stopping rule ε <= λ(1 + Δδ)
max_iterations = 100
# mirror = true               # general algorithm: also add the mirrored image (keeps symmetry)
# strict = true               # certified factor must be <= λ (default)
# fallback = "general"        # symmetric C_K^∞ fails Theorem 3.1 -> continue with general
# L = [-0.7, -0.2212]         # a linear gain to certify exactly (p = n − 1)

[simulate]
horizon = 17
x0 = [0, 0]
xhat0 = [0, 0]
[simulate.disturbance]
kind = "sequence"
values = [1, -1, -1, 1, 1, -1, 1, -1, -1, -1, 1, -1, 1, -1, -1, -1, 1]
"""
