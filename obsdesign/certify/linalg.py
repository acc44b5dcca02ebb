"""Exact linear algebra over Q: inverse, rank, and certified spectral-norm bounds."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from flint import fmpq, fmpq_mat

from obsdesign.certify.exact import Q, dyadic, qeye, qmat, to_float
from obsdesign.certify.psd import check_pd, check_psd


def qinv(M: Any) -> np.ndarray:
    """Exact inverse of a square rational matrix (ZeroDivisionError if singular, ValueError if
    not square)."""
    return qmat(fmpq_mat(qmat(M).tolist()).inv().tolist())


def qrank(M: Any) -> int:
    """Exact rank of a rational matrix (0 for an empty one)."""
    return int(fmpq_mat(qmat(M).tolist()).rank())


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
    return bool(check_psd(qeye(len(G)) * (u * u) - G))


#: how far above ‖X‖₂ a bound may lie and still be "‖X‖₂ rounded up" (:func:`not_above`):
#: relative 10⁻⁶ and absolute 10⁻⁹ (:func:`norm_upper` gives f(1 + 2⁻³⁰) + 2⁻⁴⁰)
ROUNDED_UP_REL = fmpq(1, 10**6)
ROUNDED_UP_ABS = fmpq(1, 10**9)


def not_above(X: Any, u: Any) -> bool:
    """Exact check of u ≤ (1 + 10⁻⁶)‖X‖₂ + 10⁻⁹: the bound u is ‖X‖₂ rounded up, not any
    larger number. With w = (u − 10⁻⁹)/(1 + 10⁻⁶): true when w ≤ 0, else when w²I − XᵀX is
    not positive definite (‖X‖₂ ≥ w)."""
    X = qmat(X)
    w = (Q(u) - ROUNDED_UP_ABS) / (1 + ROUNDED_UP_REL)
    if w <= 0:
        return True
    if X.size == 0:
        return False
    return not check_pd(qeye(X.shape[1]) * (w * w) - X.T @ X).ok


def norm_upper(X: Any) -> fmpq:
    """A rational u ≥ ‖X‖₂ (spectral norm), proved by u ≥ 0 and u² I − XᵀX ⪰ 0 exactly.

    The float norm is raised by a relative 2⁻³⁰ (and by 1/1024 a step while the proof fails);
    an absolute 2⁻⁴⁰ beside it was 90 % of the bound for a block of norm 10⁻¹², so a plant
    scaled by 10⁻¹² (a time rescaling) failed condition (22) of the impulsive paper (re-check
    trial, session 28). A norm the floats cannot see (underflow, or a float norm the proof
    keeps refusing) falls back on the exact Frobenius norm, which bounds it."""
    X = qmat(X)
    if X.size == 0:
        return fmpq(0)
    if all(v == 0 for v in X.flat):
        return fmpq(0)
    try:
        f = float(np.linalg.norm(to_float(X), 2))
    except OverflowError:  # an entry beyond the float range (10⁴⁰⁰): the exact bound below
        # (it raised, exit 4 for an impulsive spec the Frobenius bound certifies; primitives
        # review, session 43)
        f = math.inf
    if f > 0.0 and math.isfinite(f):
        # 40 bits: at 30 the raise of 2⁻³⁰ itself rounded away when f is a power of two (‖X‖ =
        # 1 + 10⁻³⁴ for X = (1, 5·10⁻¹⁸)ᵀ: u = 1 failed, the next step gave 1.00098 and the
        # impulsive design failed its own lambda_no claim, exit 1; impulsive review, session 42)
        u = Q(dyadic(f * (1 + 2.0**-30), 40))
        for _ in range(40):
            if norm_bound_holds(X, u):
                return u
            u = u * fmpq(1025, 1024)
    return _frobenius_upper(X)


def _frobenius_upper(X: Any) -> fmpq:
    """A rational u ≥ ‖X‖_F ≥ ‖X‖₂, proved by u² ≥ Σ x² exactly."""
    f2 = sum((v * v for v in X.flat), fmpq(0))
    num, den = int(f2.p), int(f2.q)
    # the least root/2^shift whose square is ≥ num/den, at a binary scale fine for the entries
    shift = max(0, (den.bit_length() - num.bit_length()) // 2 + 40)
    target = -(-(num << (2 * shift)) // den)  # ⌈num·4^shift/den⌉
    root = math.isqrt(target)
    if root * root < target:
        root += 1
    return fmpq(root, 2**shift)
