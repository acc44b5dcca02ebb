"""Item 10 of the issue: property tests of Theorem 1 / Lemma 3 (paper 000) on random 2- and
3-state systems with box X and X̂, θ_m = θ and the certified γ."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.methods.constrained.design import xhat_set
from obsdesign.spec.models import Spec


def _fmt(M) -> str:
    M = np.atleast_2d(M)
    return "[" + ", ".join("[" + ", ".join(f"{v:.6f}" for v in row) + "]" for row in M) + "]"


def _vec(v) -> str:
    return "[" + ", ".join(f"{x:.6f}" for x in v) + "]"


@dataclass(frozen=True)
class Case:
    """One random system and design of :func:`random_spec`: ``n`` states, drawn from ``seed``;
    the box c-map reaches ``r_pad`` beyond X, C_min has ε = ``eps_min``, the noise bound is
    ``wbound``, the error dynamics have spectral radius ``rad``, and ``norm`` is the c-map's."""

    n: int
    seed: int
    r_pad: float
    eps_min: float
    wbound: float
    rad: float = 0.8
    norm: str = "euclidean"


CASES = st.builds(
    Case,
    n=st.integers(2, 3),
    seed=st.integers(0, 2**31 - 1),
    r_pad=st.floats(0.1, 1.0),
    eps_min=st.floats(0.05, 0.5),
    wbound=st.sampled_from([0.0, 0.05, 0.3]),
    rad=st.sampled_from([0.5, 0.8]),
    norm=st.sampled_from(["euclidean", "max"]),
)


def random_spec(case: Case) -> tuple[Spec, np.ndarray]:
    """x⁺ = A x with ‖A‖_∞ ≤ 1 (so X = [−1, 1]ⁿ is invariant, Assumption 1), y = x + v
    (C = I), L = A − K with K of spectral radius ``rad``, λ = rad + 0.1; returns (spec, A)."""
    n, seed, r_pad, eps_min = case.n, case.seed, case.r_pad, case.eps_min
    wbound, rad, norm = case.wbound, case.rad, case.norm
    rng = np.random.default_rng(seed)
    A = rng.uniform(-1, 1, (n, n))
    A /= np.abs(A).sum(axis=1).max()
    K = rng.uniform(-1, 1, (n, n))
    K *= rad / max(np.max(np.abs(np.linalg.eigvals(K))), 1e-3)
    L = A - K
    lam = round(min(rad + 0.1, 0.95), 2)
    x0 = rng.uniform(-1, 1, n)
    r = 1 + r_pad
    t = np.sqrt(eps_min) * 0.999
    xhat0 = rng.choice([-1, 1], n) * (r + t)  # x̂0 at a vertex of X̂ (the outer box of C_min)
    text = f"""
[system]
time = "discrete"
A = {_fmt(A)}
C = {_fmt(np.eye(n))}
[sets.X]
type = "box"
lower = {_vec(-np.ones(n))}
upper = {_vec(np.ones(n))}
[method]
key = "constrained"
L = {_fmt(L)}
lambda = {lam}
X = "X"
eps_min = {eps_min:.6f}
[method.c]
type = "box"
norm = "{norm}"
lower = {_vec(-r * np.ones(n))}
upper = {_vec(r * np.ones(n))}
[method.D]
lower = {_vec(-wbound * np.ones(n))}
upper = {_vec(wbound * np.ones(n))}
[simulate]
horizon = 25
x0 = {_vec(x0)}
xhat0 = {_vec(xhat0)}
seed = {seed % 1000}
[simulate.noise]
kind = "uniform"
bound = {_vec(wbound * np.ones(n))}
"""
    return load_spec_text(text, "prop.toml"), A


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(CASES)
def test_theorem1_invariance_and_lemma3(case: Case):
    check_run(case)


def test_refining_is_exercised():
    """A case where the refining map runs thousands of steps (seed found by search)."""
    steps = check_run(Case(n=2, seed=4, r_pad=0.2, eps_min=0.05, wbound=0.3, rad=0.8))
    assert steps.sum() > 1000


def check_run(case: Case) -> np.ndarray:
    """Design, simulate with θ_m = θ, and check (25a), (25b) and Lemma 3 (A.1a); returns the
    refining steps per sample."""
    sp, _ = random_spec(case)
    rep = api.design(sp)
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    p = rep.parameters
    theta = int(p["theta"])
    res = api.simulate(sp, rep, theta_m=str(theta))
    tr = res.extra["traces"][f"modified θ_m={theta}"]
    Xhat = xhat_set(sp.options)
    # (25b): x̂_k ∈ X̂ at every sample
    assert np.all(Xhat.contains(tr.xhat, tol=1e-9))
    P = p.float("P")
    rho, mu = p.float("rho"), p.float("mu")
    x = res.x
    w = res.y - x  # C = I, D = 0: y = x + v
    unmod = res.extra["traces"]["unmodified"]
    for k, path in enumerate(tr.iterates):
        E = np.asarray(path) - x[k + 1]
        V = np.einsum("ij,jk,ik->i", E, P, E)
        # Lemma 3 (A.1a): V never increases across a refining step
        assert np.all(np.diff(V) <= 1e-9 * np.maximum(V[:-1], 1.0))
        # (25a): V(e_{k+1}) ≤ ρ V(e_k) + μ|w_k|²
        e0 = tr.xhat[k] - x[k]
        e1 = tr.xhat[k + 1] - x[k + 1]
        assert e1 @ P @ e1 <= rho * (e0 @ P @ e0) + mu * (w[k] @ w[k]) + 1e-9 * (1 + e0 @ P @ e0)
    # the refined error never exceeds the unmodified observer's bound sequence from the same start
    Vm = np.einsum("ij,jk,ik->i", tr.xhat - x, P, tr.xhat - x)
    bound = np.zeros_like(Vm)
    bound[0] = Vm[0]
    for k in range(len(Vm) - 1):
        bound[k + 1] = rho * bound[k] + mu * (w[k] @ w[k])
    assert np.all(Vm <= bound * (1 + 1e-9) + 1e-9)
    assert unmod.xhat.shape == tr.xhat.shape
    return tr.steps
