"""The lyapunov method: the paper's P (constrained-redesign paper, Section 5) and properties."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.certify.claim import ClaimStatus
from obsdesign.errors import InfeasibleError


def test_paper_P_and_Pinv(specs_dir):
    """Paper 000 prints P = 1e5·[[1.259, 1.319], [1.319, 1.381]] and
    P⁻¹ = [[0.039, -0.037], [-0.037, 0.036]] for λ = 0.955."""
    rep = api.design(specs_dir / "constrained-redesign-sec5-lyapunov.toml")
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    P = rep.parameters.float("P")
    np.testing.assert_array_equal(np.round(P / 1e5, 3), [[1.259, 1.319], [1.319, 1.381]])
    Pinv = np.linalg.inv(P)
    np.testing.assert_array_equal(np.round(Pinv, 3), [[0.039, -0.037], [-0.037, 0.036]])
    assert rep.parameters["lambda"] == fmpq(955, 1000)
    # best rate: the infimum is max|eig(A − LC)| = 0.95, found to the tolerance 1e-4
    best = float(rep.parameters.float("lambda_best"))
    assert 0.95 < best <= 0.95 + 1e-4 + 1e-9
    assert "mu" in rep.parameters


def _spec(A, C, L, extra=""):
    def fmt(M):
        return (
            "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in M) + "]"
        )  # noqa: E731

    return load_spec_text(
        f"""
[system]
time = "discrete"
A = {fmt(A)}
C = {fmt(C)}
[method]
key = "lyapunov"
L = {fmt(L)}
{extra}
""",
        "prop.toml",
    )


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(2, 4), st.integers(0, 2**31 - 1), st.floats(0.05, 0.9))
def test_random_schur_error_dynamics_certify(n: int, seed: int, radius: float):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    C = rng.standard_normal((1, n))
    # choose L = 0 and scale A so that A − LC = A has the given spectral radius
    A *= radius / max(np.abs(np.linalg.eigvals(A)).max(), 1e-9)
    L = np.zeros((n, 1))
    rep = api.design(_spec(A, C, L))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    rho = np.abs(np.linalg.eigvals(_spec(A, C, L).system.A.f)).max()
    assert float(rep.parameters.float("lambda_best")) >= rho - 1e-12


@settings(max_examples=15, deadline=None)
@given(st.integers(2, 4), st.integers(0, 2**31 - 1), st.floats(1.001, 3.0))
def test_unstable_error_dynamics_exit_1(n: int, seed: int, radius: float):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A *= radius / np.abs(np.linalg.eigvals(A)).max()
    with pytest.raises(InfeasibleError) as ei:
        api.design(_spec(A, np.ones((1, n)), np.zeros((n, 1))))
    assert ei.value.exit_code == 1 and "not Schur" in ei.value.message


def test_requested_rate_below_spectral_radius_is_infeasible():
    A = np.array([[0.0, 1.0], [1.0, 0.0]])
    with pytest.raises(InfeasibleError, match="spectral radius"):
        api.design(_spec(A, np.array([[1.0, 0.0]]), np.array([[-1.87], [1.874]]), "lambda = 0.94"))


def test_designed_gain_discrete_and_undetectable():
    text = """
[system]
time = "discrete"
A = [[1.1, 1], [0, 0.9]]
C = [[1, 0]]
[method]
key = "lyapunov"
lambda = 0.5
"""
    rep = api.design(load_spec_text(text))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    L = rep.parameters.float("L")
    assert (
        np.abs(np.linalg.eigvals(np.array([[1.1, 1], [0, 0.9]]) - L @ np.array([[1.0, 0]]))).max()
        < 0.5
    )
    # (C, A) not detectable: the unobservable mode 1.2 is unstable
    bad = text.replace("A = [[1.1, 1], [0, 0.9]]", "A = [[0.5, 0], [0, 1.2]]").replace(
        "lambda = 0.5\n", ""
    )
    with pytest.raises(InfeasibleError, match="detectable"):
        api.design(load_spec_text(bad))


def test_continuous_given_gain_and_iss():
    text = """
[system]
time = "continuous"
A = [[0, 1], [-2, -0.1]]
C = [[1, 0]]
[method]
key = "lyapunov"
L = [3, 2]
alpha = 0.5
iss_gain = true
"""
    rep = api.design(load_spec_text(text))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    eig = np.linalg.eigvals(
        np.array([[0, 1], [-2, -0.1]]) - np.array([[3.0], [2.0]]) @ np.array([[1.0, 0]])
    )
    assert float(rep.parameters.float("alpha_best")) <= -eig.real.max() + 1e-12
    assert float(rep.parameters.float("alpha_best")) >= -eig.real.max() - 2e-4


def test_verify_catches_tampered_P():
    A = np.array([[0.0, 1.0], [1.0, 0.0]])
    rep = api.design(
        _spec(A, np.array([[1.0, 0.0]]), np.array([[-1.87], [1.874]]), "lambda = 0.955")
    )
    P = rep.parameters["P"].copy()
    P[0, 0] = P[0, 0] / 2  # no longer a certificate
    rep.parameters["P"] = P
    ver = api.verify(rep)
    assert ver.exit_code() == 1
    assert any(c.id == "decay-lmi" and c.status == ClaimStatus.FAILED for c in ver.claims)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(2, 4), st.integers(0, 2**31 - 1), st.sampled_from(["discrete", "continuous"]))
def test_designed_gain_random_observable_systems(n: int, seed: int, time: str):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n)) * 1.2 / np.sqrt(n)
    C = rng.standard_normal((1, n))

    def fmt(M):
        return (
            "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in M) + "]"
        )  # noqa: E731

    text = f'[system]\ntime = "{time}"\nA = {fmt(A)}\nC = {fmt(C)}\n[method]\nkey = "lyapunov"\nrate_cap = 2\n'
    rep = api.design(load_spec_text(text))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    L = rep.parameters.float("L")
    eig = np.linalg.eigvals(A - L @ C)
    if time == "discrete":
        assert np.abs(eig).max() <= float(rep.parameters.float("lambda")) + 1e-9
    else:
        assert -eig.real.max() >= float(rep.parameters.float("alpha")) - 1e-9
