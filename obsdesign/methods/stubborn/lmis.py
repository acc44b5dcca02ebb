"""The LMIs of the stubborn observer, as formulas over exact (or float) matrices.

Continuous time, eqs. (1)-(3) of the stubborn-observer slides (Astolfi, Alessandri, Zaccarian,
WUDS 2017); discrete time, eqs. (7)-(9) (the slides' (4)-(6) carry a proof marked wrong).
He(Z) = Z + Zᵀ. The same formulas build the certificate's matrices from the reported
(rounded, rational) P, X, U, W, Y, R, λ; :mod:`design` writes them again in cvxpy.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def _he(Z: np.ndarray) -> np.ndarray:
    return Z + Z.T


def _diag(v: np.ndarray, zero: Any) -> np.ndarray:
    p = len(v)
    D = np.full((p, p), zero, dtype=object)
    for i in range(p):
        D[i, i] = v[i]
    return D


def global_sector(
    A: np.ndarray,
    C: np.ndarray,
    P: np.ndarray,
    X: np.ndarray,
    u: np.ndarray,
    R: np.ndarray,
    lam: Any,
    discrete: bool,
) -> np.ndarray:
    """The matrix of LMI (1) (continuous) or (7) (discrete); the LMI says it is ≺ 0. It
    carries U, the multiplier of the slides' *global* sector condition (claim ``lmi-global``).

    (1): He[[PA − XC + ½(λP − CᵀRC), X], [UC, −U]];
    (7): He[[−½(λP + CᵀRC), 0, 0], [UC, −U, 0], [PA − XC, X, −½P]].
    ``u`` holds the diagonal of U (p entries)."""
    zero = P.flat[0] * 0
    U = _diag(u, zero)
    G = P @ A - X @ C
    n, p = X.shape
    if not discrete:
        return np.block([[_he(G) + lam * P - C.T @ R @ C, X + C.T @ U], [X.T + U @ C, -2 * U]])
    Z = np.full((n, n), zero, dtype=object)
    return np.block(
        [
            [-(lam * P) - C.T @ R @ C, C.T @ U, G.T],
            [U @ C, -2 * U, X.T],
            [G, X, -P + Z],
        ]
    )


def regional_sector(
    A: np.ndarray,
    C: np.ndarray,
    P: np.ndarray,
    X: np.ndarray,
    w: np.ndarray,
    Y: np.ndarray,
    discrete: bool,
) -> np.ndarray:
    """The matrix of LMI (2) (continuous) or (8) (discrete); the LMI says it is ≺ 0. It
    carries W and Y of the slides' *regional* sector condition (claim ``lmi-regional``).

    (2): He[[PA − XC, X], [WC + Y, −W]];
    (8): He[[−½P, 0, 0], [WC + Y, −W, 0], [PA − XC, X, −½P]]. ``w``: the diagonal of W."""
    zero = P.flat[0] * 0
    W = _diag(w, zero)
    G = P @ A - X @ C
    S = W @ C + Y
    if not discrete:
        return np.block([[_he(G), X + S.T], [X.T + S, -2 * W]])
    return np.block([[-P, S.T, G.T], [S, -2 * W, X.T], [G, X, -P]])


def sector(P: np.ndarray, Y: np.ndarray, w: np.ndarray, i: int) -> np.ndarray:
    """The matrix of LMI (3) / (9) for output i: [[P, Y_iᵀ], [Y_i, w_i]] ⪰ 0."""
    Yi = Y[i : i + 1, :]
    return np.block([[P, Yi.T], [Yi, np.array([[w[i]]], dtype=object)]])


def l2_gain(
    A: np.ndarray,
    C: np.ndarray,
    Bd: np.ndarray,
    P: np.ndarray,
    X: np.ndarray,
    g: Any,
    discrete: bool,
) -> np.ndarray:
    """Bounded real lemma for ė = (A − KC)e + Bd d (or e⁺ = ...), PK = X: the L2 gain from d
    to e is below √g when this matrix is ≺ 0 (slides, criterion 4).

    Continuous: [[He(PA − XC) + I, P Bd], [Bdᵀ P, −g I]];
    discrete: [[−P + I, 0, Gᵀ], [0, −g I, Bdᵀ P], [G, P Bd, −P]] with G = PA − XC."""
    zero = P.flat[0] * 0
    one = zero + 1
    n = P.shape[0]
    k = Bd.shape[1]
    In = _diag(np.array([one] * n, dtype=object), zero)
    Ik = _diag(np.array([one] * k, dtype=object), zero)
    G = P @ A - X @ C
    PB = P @ Bd
    if not discrete:
        return np.block([[_he(G) + In, PB], [PB.T, -g * Ik]])
    Z = np.full((n, k), zero, dtype=object)
    return np.block([[-P + In, Z, G.T], [Z.T, -g * Ik, PB.T], [G, PB, -P]])
