"""Sampling window of Theorems 1-2: γ, β, condition (22), T_max (26b), T_min (26c), ball B.

All functions here take exact rationals and return exact rationals; transcendental values
(ln, √) go through outward-rounded interval arithmetic, and the reported bounds are rounded
in the safe direction: T_max down, T_min up, the radius of B up.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q
from obsdesign.certify.interval import bounds, rlog, round_down, round_up, sqrt_upper


def gamma_of(L_diag: Any) -> tuple[fmpq, fmpq]:
    """(γ, β): 1 − γ = the largest eigenvalue of the diagonal I − L (text after (18)),
    β = 1/(1 − γ)² (21c). Requires every eigenvalue of I − L in (0, 1)."""
    one_minus = max(fmpq(1) - Q(v) for v in np.asarray(L_diag, dtype=object).flat)
    return fmpq(1) - one_minus, fmpq(1) / (one_minus * one_minus)


def coupling(lam_no: Any, lam_on: Any, beta: Any) -> fmpq:
    """λ*_no + β λ*_on: the coupling term of (22) and (26b)."""
    return Q(lam_no) + Q(beta) * Q(lam_on)


def kappa_max(kappa_n: Any, lam_no: Any, lam_on: Any, beta: Any) -> fmpq:
    """Supremum of κ allowed by (22) for i = n: κ < κ_n − λ*_no − β λ*_on."""
    return Q(kappa_n) - coupling(lam_no, lam_on, beta)


def kappa_widest(varpi_o: float, coup: float, gamma: Any, alpha: float) -> float:
    """κ maximizing T_max(κ) − T_min(κ) = c₁/(D₀ + κ) − c₂/κ (26b)-(26c), D₀ = ϖ_o + coupling,
    c₁ = −ln((1−γ)²), c₂ = −ln((α − γ)/α).

    Stationary point: κ/(D₀ + κ) = √(c₂/c₁), i.e. κ = D₀ r/(1 − r), r = √(c₂/c₁). The
    logarithms go through log1p: with α ≫ γ, (α − γ)/α rounds to 1 in floats and c₂ was 0,
    so κ = 0 and the exact T_min bound (26c) refused it (exit 3 on valid input, found by the
    soundness audit at α = 10¹⁶). r is formed in log space (c₂ ≈ γ/α may be subnormal) and a
    κ that still underflows is returned as the smallest positive double: the caller caps it
    by the largest admissible κ, and the exact checks decide the window either way.
    ``gamma`` may be exact (an ``fmpq``): c₁ near γ = 1 then comes from the exact 1 − γ; from
    the float γ, L = 1 − 10⁻¹⁷ rounded to 1, c₁ = ∞ and κ = 5·10⁻³²⁴, T_min = ∞: "empty
    window", exit 1, where κ = 0.07 certifies (impulsive review, session 42).
    """
    g = float(gamma)
    om = 1 - Q(gamma)  # exact: 1 − γ of a γ within an ulp of 1
    if g <= 0.5:
        c1 = -2.0 * np.log1p(-g)
    elif om > 0:  # the logarithm of the exact ratio: 1 − γ = 10⁻³³⁰ is 0.0 as a float, and
        # c₁ = ∞ gave κ = 5·10⁻³²⁴, "empty window" (re-check review, session 43)
        c1 = -2.0 * (math.log(int(om.p)) - math.log(int(om.q)))
    else:
        c1 = np.inf
    c2 = -np.log1p(-g / alpha)
    gamma = g
    d0 = varpi_o + coup
    if d0 <= 0 or not c1 > 0:
        return np.inf
    if c2 > 0:
        r = float(np.exp(0.5 * (np.log(c2) - np.log(c1))))
    else:  # γ/α below the float range: c₂ ≈ γ/α, its logarithm from the factors
        r = float(np.exp(0.5 * (np.log(gamma) - np.log(alpha) - np.log(c1))))
    if r >= 1:
        return np.inf
    kappa = d0 * r / (1 - r)
    return kappa if kappa > 0 else float(np.nextafter(0.0, 1.0))


def T_max_lower(gamma: Any, varpi_o: Any, kappa: Any, lam_no: Any, lam_on: Any, beta: Any) -> fmpq:
    """Rational lower bound of T_max = −ln((1−γ)²)/(ϖ_o + κ + λ*_no + β λ*_on) (26b).

    The denominator is exact; requires it > 0. The bound is the larger of the interval
    enclosure's lower end and the exact 2γ/den (−ln(1−γ) = γ + γ²/2 + … ≥ γ for γ ∈ [0, 1)):
    for a tiny γ (L = 1e-300) the interval's working precision cannot resolve 1 − γ and its
    lower end was negative, so an empty-window message printed T_max = −2.4·10⁻³⁴ where
    T_max ≈ 7.6·10⁻³⁰¹ (review)."""
    den = Q(varpi_o) + Q(kappa) + coupling(lam_no, lam_on, beta)
    if den <= 0:
        raise ValueError("the denominator of (26b) is not positive")
    g = Q(gamma)
    lo, _ = bounds(lambda om, d: -rlog(om * om) / d, fmpq(1) - g, den)
    return max(lo, 2 * g / den) if 0 <= g < 1 else lo


def T_min_upper(alpha: Any, gamma: Any, kappa: Any) -> fmpq:
    """Rational upper bound of T_min = −ln((α − γ)/α)/κ (26c); requires α > γ, κ > 0.

    The bound is the smaller of the interval enclosure's upper end and the exact
    x/((1 − x)κ), x = γ/α (−ln(1−x) ≤ x/(1−x) for x ∈ [0, 1)): tight where the interval's
    working precision cannot resolve 1 − x (a tiny γ/α)."""
    a, g, k = Q(alpha), Q(gamma), Q(kappa)
    if not (a > g and k > 0):
        raise ValueError("(26c) needs α > γ and κ > 0")
    _, hi = bounds(lambda r, kk: -rlog(r) / kk, (a - g) / a, k)
    x = g / a
    return min(hi, x / ((1 - x) * k)) if x >= 0 else hi


def radius_upper(alpha: Any, w_bar: Any) -> fmpq:
    """Rational upper bound of the radius √(α ‖w‖∞) of B (Theorem 2)."""
    return sqrt_upper(Q(alpha) * Q(w_bar))


def safe_window(T_max_lo: fmpq, T_min_hi: fmpq, digits: int) -> tuple[fmpq, fmpq]:
    """Decimal rounding in the safe direction: T_max down, T_min up."""
    return round_down(T_max_lo, digits), round_up(T_min_hi, digits)
