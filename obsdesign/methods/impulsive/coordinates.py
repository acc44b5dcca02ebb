"""Coordinates z = T x with T = [C; M] and the blocks of Ā = T A T⁻¹.

Eqs. (9)-(10c), impulsive-dissipativity paper (001): z_o = C x is measured, z_n = M x is not,
Ā = T A T⁻¹ = [[Ā_o, Ā_on], [Ā_no, Ā_n]], C̄ = C T⁻¹ = [I 0], ψ̄(z) = T ψ(T⁻¹ z).

Everything here is exact (``fmpq``): T is the user's M (exact from the spec) or a float choice
rounded to a dyadic grid, and T⁻¹ is the exact rational inverse, so Ā and its blocks are the
exact matrices the certificate talks about.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from obsdesign.certify.exact import dyadic, to_float
from obsdesign.certify.linalg import qinv, qrank

#: bits of the dyadic grid used to round a float M before it enters exact arithmetic
M_BITS = 20


@dataclass
class Coordinates:
    """T = [C; M], its exact inverse and Ā = T A T⁻¹ with its blocks (eqs. (9)-(10c)).

    ``source`` says where M came from: ``given`` (spec), ``orthonormal`` (complement of the
    row space of C, rounded) or ``optimized`` (search that widens the window's ratio T_max / T_min).
    """

    T: np.ndarray
    Tinv: np.ndarray
    Abar: np.ndarray
    m: int
    source: str

    @property
    def M(self) -> np.ndarray:
        return self.T[self.m :, :]

    @property
    def Ao(self) -> np.ndarray:
        return self.Abar[: self.m, : self.m]

    @property
    def Aon(self) -> np.ndarray:
        return self.Abar[: self.m, self.m :]

    @property
    def Ano(self) -> np.ndarray:
        return self.Abar[self.m :, : self.m]

    @property
    def An(self) -> np.ndarray:
        return self.Abar[self.m :, self.m :]

    @property
    def Pinv_o(self) -> np.ndarray:
        """Columns of T⁻¹ acting on z_o (x = T⁻¹z = P_o z_o + P_n z_n)."""
        return self.Tinv[:, : self.m]

    @property
    def Pinv_n(self) -> np.ndarray:
        return self.Tinv[:, self.m :]

    def floats(self) -> dict[str, np.ndarray]:
        return {
            k: np.asarray(to_float(getattr(self, k)), dtype=float) for k in ("T", "Tinv", "Abar")
        }


def transform(A: Any, C: Any, M: Any, source: str = "given") -> Coordinates:
    """Exact T = [C; M], T⁻¹ and Ā = T A T⁻¹ (eqs. (9), (10c)).

    Raises ValueError when det T = 0 (M does not complement the rows of C).
    """
    A = np.asarray(A, dtype=object)
    C = np.asarray(C, dtype=object)
    M = (
        np.asarray(M, dtype=object).reshape(-1, A.shape[0])
        if np.size(M)
        else np.zeros((0, A.shape[0]), dtype=object)
    )
    T = np.vstack([C, M])
    if T.shape[0] != T.shape[1] or qrank(T) < T.shape[0]:
        raise ValueError("T = [C; M] is singular (M must complement the rows of C)")
    Tinv = qinv(T)
    Abar = T @ A @ Tinv
    return Coordinates(T, Tinv, Abar, C.shape[0], source)


def orthonormal_complement(C: np.ndarray) -> np.ndarray:
    """Rows spanning the orthogonal complement of the row space of C (SVD null space), float.

    The default M: with it T⁻¹ = [C⁺, Mᵀ] up to rounding, so ‖Ā_on‖ and ‖Ā_no‖ are not
    inflated by a badly conditioned T.
    """
    C = np.asarray(C, dtype=float)
    _, _, vt = np.linalg.svd(C)
    # C has full row rank m (checked exactly on load): the complement has n − m rows. A float
    # rank with a relative cut-off gave M a row too many for ‖C‖ < 1e-12 or an ill-conditioned
    # C, and "T = [C; M] is singular", exit 3 (re-check review, session 43)
    return vt[C.shape[0] :, :]


def rational_M(Mf: np.ndarray) -> np.ndarray:
    """Round a float M to the dyadic grid (exact rationals) before it enters T."""
    return np.asarray(dyadic(np.asarray(Mf, dtype=float), M_BITS), dtype=object)


def default_coordinates(A: Any, C: Any) -> Coordinates:
    """T = [C; M] with M the (rounded) orthonormal complement of the rows of C."""
    Mf = orthonormal_complement(np.asarray(to_float(np.asarray(C, dtype=object)), dtype=float))
    return transform(A, C, rational_M(Mf), "orthonormal")
