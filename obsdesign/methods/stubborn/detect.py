"""Detectability of (C, A) for the "not detectable" diagnosis (Proposition of the slides:
LMIs (1)-(3) are feasible iff (C, A) is detectable).

Uses the exact test of :mod:`obsdesign.certify.detect` (exact over Q: unobservable restriction,
Routh / Schur–Cohn) when that module is present; without it, a float PBH test: (C, A) is detectable iff rank [A − μI; C] = n for every eigenvalue μ of A with
Re μ ≥ 0 (continuous) or |μ| ≥ 1 (discrete). The test is *inconclusive* (verdict None, exit 4
upstream) when an eigenvalue is within ``tol`` of the stability boundary or the smallest
singular value of [A − μI; C] is between ``tol`` and ``1e3·tol`` (relative to the data).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Detectability:
    """verdict True / False / None (numerically inconclusive), and why."""

    verdict: bool | None
    detail: str


def detectability(A: np.ndarray, C: np.ndarray, discrete: bool, tol: float = 1e-9) -> Detectability:
    """PBH test of (C, A) (float; see the module docstring for the inconclusive zone)."""
    exact = _exact(A, C, discrete)
    if exact is not None:
        return exact
    A = np.asarray(A, dtype=float) if np.asarray(A).dtype != object else _f(A)
    C = np.asarray(C, dtype=float) if np.asarray(C).dtype != object else _f(C)
    n = A.shape[0]
    scale = max(1.0, float(np.linalg.norm(A)), float(np.linalg.norm(C)))
    inconclusive = []
    for mu in np.linalg.eigvals(A):
        d = (abs(mu) - 1) if discrete else mu.real
        if d < -1e3 * tol * scale:
            continue
        M = np.vstack([A - mu * np.eye(n), C.astype(complex)])
        s = np.linalg.svd(M, compute_uv=False)[-1] / scale
        if abs(d) <= 1e3 * tol * scale:
            inconclusive.append(f"eigenvalue {mu:.6g} on the stability boundary (float)")
        elif s < tol:
            where = "|μ| ≥ 1" if discrete else "Re μ ≥ 0"
            return Detectability(False, f"PBH: the mode μ = {mu:.6g} ({where}) is unobservable")
        elif s < 1e3 * tol:
            inconclusive.append(f"PBH rank at μ = {mu:.6g}: smallest singular value {s:.3g}")
    if inconclusive:
        return Detectability(None, "; ".join(inconclusive))
    return Detectability(
        True, "PBH: every mode with " + ("|μ| ≥ 1" if discrete else "Re μ ≥ 0") + " is observable"
    )


def _exact(A: np.ndarray, C: np.ndarray, discrete: bool) -> Detectability | None:
    """The exact test of :mod:`obsdesign.certify.detect` (Kalman/Hautus over Q), when present."""
    try:
        from obsdesign.certify.detect import detectability as exact_detectability
    except ImportError:
        return None
    r = exact_detectability(A, C, "discrete" if discrete else "continuous")
    return Detectability(bool(r.detectable), f"exact: {r.reason}")


def _f(M: np.ndarray) -> np.ndarray:
    from obsdesign.certify.exact import to_float

    return np.asarray(to_float(M), dtype=float)
