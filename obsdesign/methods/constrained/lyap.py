"""Lyapunov data of Assumption 2, constrained-redesign paper (000): V(e) = eᵀPe (eq. (4)) and
β(v, w) = ρ v + μ |w|² (eq. (6)) with V(Δ(x, e, w)) ≤ β(V(e), w) (eq. (5)).

Linear observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) on x⁺ = A x + B u + Bd d,
y = C x + D u + Dn v: the error e = x̂ − x obeys e⁺ = (A − LC) e + B_w w with
w = (d, v) and B_w = [−Bd, L Dn]. P comes from the ``lyapunov`` method (the solution of
(A−LC)ᵀP(A−LC) − λ²P = −I, certified exactly); ρ = λ² by default (any ρ ≥ λ² is allowed: a
larger ρ buys a much smaller μ), and μ is the smallest certified value for that ρ.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, dyadic, qeye, symmetrize
from obsdesign.certify.psd import check_psd
from obsdesign.errors import InconclusiveError


def error_input(A: np.ndarray, Bd: np.ndarray, Dn: np.ndarray, L: np.ndarray) -> np.ndarray:
    """B_w = [−Bd, L Dn], exact: how w = (d, v) enters the error dynamics (3)."""
    n = A.shape[0]
    parts = []
    if Bd.shape[1]:
        parts.append(-Bd)
    if Dn.shape[1]:
        parts.append(L @ Dn)
    if not parts:
        return np.full((n, 0), fmpq(0), dtype=object)
    return np.hstack(parts)


def iss_matrix(Acl: np.ndarray, Bw: np.ndarray, P: np.ndarray, rho: Any, mu: Any) -> np.ndarray:
    """[[ρP − AclᵀPAcl, −AclᵀPB_w], [−B_wᵀPAcl, μI − B_wᵀPB_w]] ⪰ 0 ⟺ eq. (5) with
    β(v, w) = ρv + μ|w|² for the linear error dynamics (exact)."""
    k = Bw.shape[1]
    S = symmetrize(P * Q(rho) - Acl.T @ P @ Acl)
    if k == 0:
        return S
    off = -(Acl.T @ P @ Bw)
    low = qeye(k) * Q(mu) - Bw.T @ P @ Bw
    return symmetrize(np.block([[S, off], [off.T, low]]))


def iss_mu(Acl: np.ndarray, Bw: np.ndarray, P: np.ndarray, rho: Any) -> fmpq:
    """Smallest μ (rounded up, then certified exactly) with eq. (5) for the given ρ:
    μ ≥ λ_max(B_wᵀPB_w + B_wᵀPAcl S⁻¹ AclᵀPB_w), S = ρP − AclᵀPAcl ≻ 0 (Schur complement)."""
    if Bw.shape[1] == 0:
        return fmpq(0)
    Af, Bf, Pf = (np.asarray(M, dtype=float) for M in (Acl, Bw, P))
    S = np.asarray(symmetrize(P * Q(rho) - Acl.T @ P @ Acl), dtype=float)
    G = Bf.T @ Pf @ Bf + Bf.T @ Pf @ Af @ np.linalg.solve(S, Af.T @ Pf @ Bf)
    mu_f = float(np.linalg.eigvalsh((G + G.T) / 2).max())
    mu = dyadic(mu_f * (1 + 1e-9) + 1e-12, 30)
    for _ in range(80):
        if check_psd(iss_matrix(Acl, Bw, P, rho, mu)):
            return mu
        mu = mu * fmpq(11, 10) + fmpq(1, 10**9)
    raise InconclusiveError("could not certify the ISS gain μ of eq. (5) (ρ too close to λ²?)")


def w_sq_max(lower: np.ndarray, upper: np.ndarray) -> fmpq:
    """max over the box D of |w|², exact."""
    return sum((max(Q(a) ** 2, Q(b) ** 2) for a, b in zip(lower, upper, strict=True)), fmpq(0))
