"""Problem data of the impulsive observer, independent of the spec format (paper 001).

Schaum, Feketa, Meurer, Moreno, "Robust nonlinear observer design based on impulsive
dissipativity" (MTNS 2020). :class:`Problem` holds what the spec fixes (A, C, the diagonal of
L, α, ‖w‖∞, M when given, κ when given, the data of Assumption 1); :mod:`.design` computes the
window from it and :mod:`.claims` certifies a report against it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q
from obsdesign.certify.linalg import norm_upper

from .coordinates import Coordinates
from .dissipativity import QSR, qsr_lipschitz

REF = "impulsive-dissipativity paper (Schaum et al., MTNS 2020)"

#: the four norm bounds behind the block data derived from ``lipschitz_x``
NORM_KEYS = ("norm_C", "norm_M", "norm_Po", "norm_Pn")


class Infeasible(Exception):
    """A condition of the paper fails; the message names it and by how much."""


#: decimals of T_min / T_max when ``digits`` is not given, and the most ``digits`` allows
DEFAULT_DIGITS = 4
MAX_DIGITS = 30


@dataclass
class BlockData:
    """Declared data of Assumption 1 in z-coordinates (split reading, see dissipativity.py)."""

    qsr_o: QSR
    qsr_n: QSR
    ell_on: fmpq = fmpq(0)
    ell_no: fmpq = fmpq(0)


@dataclass
class LipschitzX:
    """‖ψ(x̂) − ψ(x)‖ ≤ ℓ‖x̂ − x‖ in the original coordinates; block data are derived for any T."""

    ell: fmpq


@dataclass
class Problem:
    """Everything the spec fixes, exact: A (n×n), C (m×n), the diagonal of L (m), α, the noise
    bound w̄ = ‖w‖∞, M ((n−m)×n matrix, or "orthonormal" / "optimize"), the data of Assumption 1,
    κ ("max", "widest" or a number), whether the QSR scaling is optimized, decimals of the
    window."""

    A: np.ndarray
    C: np.ndarray
    L: np.ndarray
    alpha: fmpq
    w_bar: fmpq
    M: Any
    data: BlockData | LipschitzX
    kappa: Any = "max"
    optimize_scaling: bool = True
    #: decimals of T_min / T_max; None (not given): DEFAULT_DIGITS, or more when a narrow
    #: window holds no pair of such bounds (up to MAX_DIGITS)
    digits: int | None = None

    @property
    def m(self) -> int:
        return self.C.shape[0]

    @property
    def given_M(self) -> np.ndarray | None:
        """M when the spec gives it as a matrix."""
        return None if isinstance(self.M, str) else self.M

    @property
    def given_kappa(self) -> fmpq | None:
        """κ when the spec gives it as a number."""
        return None if isinstance(self.kappa, str) else Q(self.kappa)


def norm_matrices(co: Coordinates) -> dict[str, np.ndarray]:
    """The matrices whose spectral norms enter the derived block data: C, M, P_o, P_n."""
    return {
        "norm_C": co.T[: co.m],
        "norm_M": co.M,
        "norm_Po": co.Pinv_o,
        "norm_Pn": co.Pinv_n,
    }


def norm_bounds(co: Coordinates) -> dict[str, fmpq]:
    """Exact upper bounds of ‖C‖, ‖M‖, ‖P_o‖, ‖P_n‖ (each proved by u²I − XᵀX ⪰ 0)."""
    return {k: norm_upper(X) for k, X in norm_matrices(co).items()}


def blocks_from_norms(ell: Any, norms: dict[str, Any], m: int, n: int) -> BlockData:
    """Split-reading data from ‖ψ(x̂) − ψ(x)‖ ≤ ℓ‖x̂ − x‖ (x = T⁻¹ z = P_o z_o + P_n z_n):

    ‖φ_o‖ ≤ ‖C‖ℓ‖P_o‖‖ε_o‖,  ‖c_o‖ ≤ ‖C‖ℓ‖P_n‖‖ε_n‖,  ‖φ_n‖ ≤ ‖M‖ℓ‖P_n‖‖ε_n‖,
    ‖c_n‖ ≤ ‖M‖ℓ‖P_o‖‖ε_o‖, own parts as Lipschitz QSR (−I, 0, ℓ_ii² I) — valid whenever
    ``norms`` are upper bounds of the four norms."""
    e = Q(ell)
    nC, nM, nPo, nPn = (Q(norms[k]) for k in NORM_KEYS)
    l_oo, l_on, l_nn, l_no = nC * e * nPo, nC * e * nPn, nM * e * nPn, nM * e * nPo
    q_o = qsr_lipschitz(l_oo, m)
    q_n = qsr_lipschitz(l_nn, n - m)
    q_o.how = f"derived from lipschitz_x: ℓ_oo = ‖C‖ℓ‖P_o‖ ≤ {float(l_oo):.6g}"
    q_n.how = f"derived from lipschitz_x: ℓ_nn = ‖M‖ℓ‖P_n‖ ≤ {float(l_nn):.6g}"
    return BlockData(q_o, q_n, l_on, l_no)
