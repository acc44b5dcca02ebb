"""Lyapunov data of Assumption 2, constrained-redesign paper (Astolfi, Bernard, Postoyan,
Marconi, NOLCOS 2019): V(e) = eᵀPe (eq. (4)) and β(v, w) = ρ v + μ |w|² (eq. (6)) with
V(Δ(x, e, w)) ≤ β(V(e), w) (eq. (5)).

Linear observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) on x⁺ = A x + B u + Bd d,
y = C x + D u + Dn v: the error e = x̂ − x obeys e⁺ = (A − LC) e + B_w w with
w = (d, v) and B_w = [−Bd, L Dn]. P is the certified solution of
(A−LC)ᵀP(A−LC) − λ²P = −I; ρ = λ² by default (any ρ ≥ λ² is allowed: a larger ρ buys a much
smaller μ), and μ is the smallest certified value for that ρ. The maths is shared with the
``lyapunov`` method in :mod:`obsdesign.lyap`; this module keeps the names ``constrained``
imports (discrete time, ⪰ 0 checks).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from flint import fmpq

from obsdesign import lyap
from obsdesign.certify.exact import Q
from obsdesign.lyap import best_rate, certified_P, decay_matrix, rate_feasible

__all__ = [
    "best_rate",
    "certified_P",
    "decay_matrix",
    "error_input",
    "iss_matrix",
    "iss_mu",
    "rate_feasible",
    "w_sq_max",
]


def error_input(A: np.ndarray, Bd: np.ndarray, Dn: np.ndarray, L: np.ndarray) -> np.ndarray:
    """B_w = [−Bd, L Dn], exact: how w = (d, v) enters the error dynamics (3)
    (:func:`obsdesign.lyap.error_input`; ``A`` is not used, kept for the callers)."""
    return lyap.error_input(Bd, Dn, L)


def iss_matrix(Acl: np.ndarray, Bw: np.ndarray, P: np.ndarray, rho: Any, mu: Any) -> np.ndarray:
    """[[ρP − AclᵀPAcl, −AclᵀPB_w], [−B_wᵀPAcl, μI − B_wᵀPB_w]] ⪰ 0 ⟺ eq. (5) with
    β(v, w) = ρv + μ|w|² for the linear error dynamics (exact; discrete time)."""
    return lyap.iss_matrix(Acl, Bw, P, rho, mu, discrete=True)


def iss_mu(Acl: np.ndarray, Bw: np.ndarray, P: np.ndarray, rho: Any) -> fmpq:
    """Smallest μ (rounded up, then certified ⪰ 0 exactly) with eq. (5) for the given ρ:
    μ ≥ λ_max(B_wᵀPB_w + B_wᵀPAcl S⁻¹ AclᵀPB_w), S = ρP − AclᵀPAcl ≻ 0 (Schur complement)."""
    return lyap.iss_mu(Acl, Bw, P, rho, discrete=True, strict=False)


def w_sq_max(lower: np.ndarray, upper: np.ndarray) -> fmpq:
    """max over the box D of |w|², exact."""
    return sum((max(Q(a) ** 2, Q(b) ** 2) for a, b in zip(lower, upper, strict=True)), fmpq(0))
