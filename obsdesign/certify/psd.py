"""Exact positive (semi)definiteness by symmetric Gaussian elimination (LDLᵀ) over Q.

A symmetric rational matrix M is positive definite iff its LDLᵀ factorization without
pivoting exists with every pivot > 0 (Sylvester's criterion in factored form). For positive
*semi*definiteness we use diagonal pivoting: at each step take the largest remaining diagonal
entry; if it is negative, M is not PSD; if it is zero, every remaining entry must be zero.
All arithmetic is exact (python-flint ``fmpq``), so the answer is a proof, not an estimate.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, qeye, qmat


@dataclass(frozen=True)
class PSDResult:
    """Outcome of an exact definiteness test.

    ``ok`` is the verdict; ``min_pivot`` the smallest pivot met (a float, for the report);
    ``detail`` says why it failed (index of the first bad pivot, asymmetry, ...).
    """

    ok: bool
    min_pivot: float
    detail: str

    def __bool__(self) -> bool:
        return self.ok


def _as_q(M: Any) -> np.ndarray:
    """Square exact matrix: every entry converted to ``fmpq`` exactly (floats by their binary
    value), so that no decision is ever taken in floating point, whatever the input mixes."""
    arr = np.asarray(M, dtype=object)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
        raise ValueError("expected a square matrix")
    return qmat(arr)


def _symmetric(arr: np.ndarray) -> str:
    n = arr.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            if arr[i, j] != arr[j, i]:
                return f"not symmetric at ({i}, {j})"
    return ""


def ldl_pivots(M: Any) -> list[fmpq]:
    """Pivots of the LDLᵀ factorization of a symmetric rational matrix, no pivoting.

    Works on the lower triangle only; stops at the first non-positive pivot (returned as
    the last element). O(n³/6) exact ``fmpq`` operations.
    """
    arr = _as_q(M)
    n = arr.shape[0]
    a = [[arr[i, j] for j in range(i + 1)] for i in range(n)]
    pivots: list[fmpq] = []
    for k in range(n):
        p = a[k][k]
        pivots.append(p)
        if p <= 0:
            break
        inv = 1 / p
        col = [a[i][k] if i >= k else None for i in range(n)]  # column k, rows i >= k
        for i in range(k + 1, n):
            f = col[i] * inv
            if f == 0:
                continue
            ai = a[i]
            for j in range(k + 1, i + 1):
                if col[j] != 0:
                    ai[j] -= f * col[j]
    return pivots


def check_pd(M: Any, margin: Any = 0) -> PSDResult:
    """Exact test of M − margin·I ≻ 0 for symmetric rational M (strict LMI check)."""
    arr = _as_q(M)
    asym = _symmetric(arr)
    if asym:
        return PSDResult(False, float("nan"), asym)
    n = arr.shape[0]
    if n == 0:
        return PSDResult(True, float("inf"), "empty matrix")
    m = Q(margin)
    if m != 0:
        arr = arr - qeye(n) * m
    pivots = ldl_pivots(arr)
    mn = min(pivots)
    if mn > 0:
        return PSDResult(True, float(mn), f"all {n} LDLᵀ pivots > 0 (min {float(mn):.3g})")
    k = next(i for i, p in enumerate(pivots) if p <= 0)
    return PSDResult(False, float(mn), f"LDLᵀ pivot {k} = {float(pivots[k]):.6g} <= 0")


def check_psd(M: Any, margin: Any = 0) -> PSDResult:
    """Exact test of M − margin·I ⪰ 0 (semidefinite) with diagonal pivoting."""
    arr = _as_q(M)
    asym = _symmetric(arr)
    if asym:
        return PSDResult(False, float("nan"), asym)
    n = arr.shape[0]
    m = Q(margin)
    if m != 0:
        arr = arr - qeye(n) * m
    a = [[arr[i, j] for j in range(n)] for i in range(n)]
    idx = list(range(n))
    min_piv = None
    while idx:
        k = max(idx, key=lambda t: a[t][t])
        p = a[k][k]
        min_piv = p if min_piv is None or p < min_piv else min_piv
        if p < 0:
            return PSDResult(False, float(p), f"negative diagonal {float(p):.6g} after elimination")
        if p == 0:
            for i in idx:
                for j in idx:
                    if a[i][j] != 0:
                        return PSDResult(False, 0.0, "zero pivot with a nonzero off-diagonal entry")
            return PSDResult(True, 0.0, f"PSD, rank {n - len(idx)}")
        idx.remove(k)
        inv = 1 / p
        for i in idx:
            f = a[i][k] * inv
            if f == 0:
                continue
            for j in idx:
                a[i][j] -= f * a[k][j]
    return PSDResult(True, float(min_piv if min_piv is not None else 0), "PSD (full rank)")
