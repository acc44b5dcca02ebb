"""Exact linear algebra over Q: inverse, rank, and certified spectral-norm bounds."""

from __future__ import annotations

from typing import Any

import numpy as np
from flint import fmpq, fmpq_mat

from obsdesign.certify.exact import Q, dyadic, qeye, qmat, to_float
from obsdesign.certify.psd import check_psd


def qinv(M: Any) -> np.ndarray:
    """Exact inverse of a square rational matrix (ZeroDivisionError if singular)."""
    A = np.asarray(M, dtype=object)
    n = A.shape[0]
    fm = fmpq_mat(n, n, [Q(v) for v in A.flat])
    inv = fm.inv()
    return qmat([[inv[i, j] for j in range(n)] for i in range(n)])


def qrank(M: Any) -> int:
    """Exact rank of a rational matrix."""
    A = np.asarray(M, dtype=object)
    r, c = A.shape
    if r == 0 or c == 0:
        return 0
    return int(fmpq_mat(r, c, [Q(v) for v in A.flat]).rank())


def norm_bound_holds(X: Any, u: Any) -> bool:
    """Exact check of ‖X‖₂ ≤ u: u ≥ 0 and u² I − XᵀX ⪰ 0.

    ``X`` (any numbers, floats by their exact binary value) and ``u`` are converted to
    rationals first; a negative ``u`` is never a norm bound (callers pass differences such as
    λ − ℓ, which may be negative)."""
    X = qmat(X)
    u = Q(u)
    if u < 0:
        return False
    if X.size == 0:
        return True
    G = X.T @ X
    return bool(check_psd(qeye(G.shape[0]) * (u * u) - G))


def norm_upper(X: Any) -> fmpq:
    """A rational u ≥ ‖X‖₂ (spectral norm), proved by u ≥ 0 and u² I − XᵀX ⪰ 0 exactly."""
    X = qmat(X)
    if X.size == 0:
        return fmpq(0)
    Xf = np.asarray(to_float(X), dtype=float)
    f = float(np.linalg.norm(Xf, 2))
    if f == 0.0 and all(v == 0 for v in X.flat):
        return fmpq(0)
    u = Q(dyadic(f * (1 + 2.0**-30) + 2.0**-40, 30))
    for _ in range(40):
        if norm_bound_holds(X, u):
            return u
        u = u * fmpq(1025, 1024) + fmpq(1, 2**30)
    raise ArithmeticError("could not certify a norm bound")
