"""The printed numbers of the constrained redesign (Section 5 of Astolfi, Bernard, Postoyan,
Marconi, NOLCOS 2019) stay what docs/methods/constrained.md says: the shipped spec exactly,
the variants of the documented tables at their printed precision."""

from __future__ import annotations

from pathlib import Path

import pytest
from flint import fmpq
from test_constrained_method import variant

from obsdesign import api
from obsdesign.certify.claim import ClaimStatus

SPEC = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5.toml"


def test_shipped_spec_exact_numbers() -> None:
    rep = api.design(SPEC)
    assert rep.exit_code() == 0
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    assert [c.id for c in rep.claims] == [
        "P-positive-definite",
        "decay-lmi",
        "iss-bound",
        "c-convex",
        "eps-order",
        "X-in-C0",
        "Cmin-in-Xhat",
        "Xhat-in-Cmax",
        "v_max-bound",
        "Xhat_max-in-Cmax",
        "delta-bound",
        "lambda_min-bound",
        "gamma-bound",
        "gamma_max-bound",
        "v_min-bound",
        "theta-covers",
    ]
    p = rep.parameters
    assert p["lambda"] == fmpq(191, 200) and p["rho"] == fmpq(191, 200)
    assert p["mu"] == fmpq(200582665, 8192)  # 24485.19
    assert p["eps_max"] == 140098
    assert p["delta_sq"] == 560392  # δ = 2√ε_max = 748.59
    assert round(p.float("delta"), 2) == 748.59
    assert p["gamma"] == p["gamma_max"] == fmpq(4793, 200000000)  # 2.3965e-5
    assert p["lambda_min_P"] == fmpq(901260129, 67108864)  # 13.43
    assert p["v_min"] == fmpq(90753137, 100000000)
    assert round(p.float("v_max"), 1) == 2659567.3
    assert p["theta"] == 1109771083258944  # 1.11e15
    summary = api.method("constrained").summary(p)
    # the bounds rounded on their safe sides (soundness trial, session 32): v_min down, δ and
    # v_max up; the design's choices γ, γ_max, θ marked "≈" (re-check trial, session 32)
    assert summary == (
        "γ ≈ 2.396e-05, γ_max ≈ 2.396e-05, δ ≤ 748.6, v_max ≤ 2.66e+06, v_min ≥ 0.9075, "
        "θ ≈ 1.11e+15"
    )


X0 = (
    '[sets.X0]\ntype = "box"\nlower = [-1, -1]\nupper = [-0.9, -0.9]\n\n'
    '[sets.Xhat0]\ntype = "box"\nlower = [0.9, 0.9]\nupper = [1, 1]\n\n[method]'
)
D03 = ("lower = [-3]\nupper = [3]", "lower = [-0.3]\nupper = [0.3]")
MAXNORM = 'type = "box"\nnorm = "max"\nlower = [-1.1, -1.1]\nupper = [1.1, 1.1]'

# (variant, {parameter: value at the printed precision (significant digits)})
TABLE = [
    (
        dict(replace=[("rho = 0.955\n", "")]),  # ρ = λ²
        {"mu": 2.562e8, "v_max": 2.308e9, "eps_max": 1.217e8, "delta": 2.206e4},
    ),
    (dict(replace=[("rho = 0.955\n", "")]), {"gamma": 2.759e-8, "v_min": 0.9075, "theta": 8.37e20}),
    (
        dict(replace=[("rho = 0.955", "rho = 0.97")]),
        {"mu": 1.856e4, "v_max": 2.645e6, "eps_max": 1.393e5, "delta": 746.5, "gamma": 2.410e-5},
    ),
    (dict(replace=[("rho = 0.955", "rho = 0.97")]), {"theta": 1.10e15}),
    (
        dict(c=MAXNORM),
        {"eps_max": 103515, "delta": 643.47, "gamma": 3.2434e-5, "v_min": 1.0270701},
    ),
    (dict(c=MAXNORM), {"theta": 8.2e14}),
    (dict(replace=[D03]), {"v_max": 2.441e6, "delta": 717.2, "gamma": 2.611e-5, "theta": 9.35e14}),
    (
        dict(add='X0 = "X0"\nXhat0 = "Xhat0"', replace=[("[method]", X0)]),
        {"v_max_breve": 7.008e6, "theta_breve": 1.11e15},
    ),
    (
        dict(add='X0 = "X0"\nXhat0 = "Xhat0"', replace=[("[method]", X0), D03]),
        {"v_max_breve": 2.160e6, "theta_breve": 8.27e14},
    ),
]


def _sig(x: float) -> int:
    from decimal import Decimal

    return len(Decimal(repr(x)).normalize().as_tuple().digits)


@pytest.mark.parametrize("kw, expected", TABLE)
def test_documented_variants(kw: dict, expected: dict[str, float]) -> None:
    rep = api.design(api.load_spec_text(variant(**kw), "variant.toml"))
    assert rep.exit_code() == 0
    for k, v in expected.items():
        got = rep.parameters.float(k)
        assert float(f"{got:.{_sig(v)}g}") == v, (k, got, v)


def test_iss_bound_statement_shows_mu_exactly() -> None:
    """μ = 200582665/8192 is printed with its rounded-up value beside it, not as
    "μ = 24485.1886" (rendering soundness trial, session 29)."""
    rep = api.design(SPEC)
    st = {c.id: c.statement for c in rep.claims}
    assert "μ = 200582665/8192 ≤ 24485.1886, ρ < 1" in st["iss-bound"]


def test_gamma_bound_statement_shows_a_long_gamma_exactly() -> None:
    """A given γ = 0.0000123456789012345 was printed "γ = 0.000012345678" (rounded, behind
    "="; re-check trial, session 29): now exactly, its rounded-down value beside it."""
    text = SPEC.read_text().replace("[method]\n", "[method]\ngamma = 0.0000123456789012345\n", 1)
    rep = api.design(api.load_spec_text(text, "g.toml"))
    st = {c.id: c.statement for c in rep.claims}
    assert "γ = 24691357802469/2000000000000000000 ≥ 0.000012345678" in st["gamma-bound"]
