"""Verified floating-point Cholesky: a proof that M − δI ≻ 0 for a symmetric rational M from
one float factorization and a few exact scalar comparisons (issue 12: exact LDLᵀ at n = 100).

Notation: u = 2⁻⁵³ (unit roundoff of IEEE double), η = 2⁻¹⁰⁷⁴ (smallest subnormal),
γ_k = k·u / (1 − k·u), |X| the entrywise absolute value, ‖·‖_F the Frobenius norm.

**Theorem** (what :func:`verified_pd` proves). Let M be a symmetric rational n×n matrix and
δ ≥ 0 rational.

1. *Conversion.* H = fl(M) entry by entry, each entry the correctly rounded quotient of its
   integer numerator and the common denominator (CPython's int/int true division is correctly
   rounded). Then |M − H| ≤ E with E_ij = u·|H_ij| + η, so ‖M − H‖₂ ≤ ‖E‖_F ≤ u‖H‖_F + nη.
   H is exactly symmetric (the same rounding of the same number).
   *Integer form* (:func:`int_to_float`): for M = c·Z with Z an integer matrix and c > 0
   rational, M − 0·I ≻ 0 iff Z·2⁻ˢ ≻ 0; H = fl(Z·2⁻ˢ), each entry an int/int quotient,
   correctly rounded, satisfies step 1 for the matrix Z·2⁻ˢ, and the proved bound times c·2ˢ
   bounds λ_min(M). The decay matrix of a Lyapunov check is proved this way, without its
   rational entries (:func:`obsdesign.lyap.decay_pd`).
2. *Shift.* For a float c ≥ 0, G equals H off the diagonal and G_ii = fl(H_ii − c); an IEEE
   subtraction is correctly rounded (and exact in the subnormal range), so
   |G_ii − (H_ii − c)| ≤ u·|G_ii|.
3. *Factorization.* The outer-product (right-looking) Cholesky of G is run in IEEE double with
   numpy elementwise operations only — every product, quotient, difference and square root
   correctly rounded, no fused multiply-add, no BLAS/LAPACK reordering. If it runs to
   completion with positive finite pivots, the computed factor R̃ satisfies
   R̃ᵀR̃ = G + ΔG with |ΔG| ≤ γ_{n+1}|R̃ᵀ||R̃| + τ·𝟙𝟙ᵀ (Higham, *Accuracy and Stability of
   Numerical Algorithms*, 2nd ed., Thm 10.3, whose proof uses only that the recurrences
   complete, not that G is definite; Rump, "Verification of positive definiteness", BIT 46
   (2006), builds on exactly this). τ covers underflow: each entry of R̃ᵀR̃ is formed by at
   most 2n + 2 multiplications, divisions and square roots, each with an absolute error
   ≤ η, amplified by at most 1 + max_k r̃_kk when multiplied back; we take the deliberately
   generous τ = 2⁻¹⁰⁰⁰·(n + 2)·(1 + max_k r̃_kk) (more than 2⁷⁰ times that count).
   Since R̃ᵀR̃ ⪰ 0 and ‖|R̃ᵀ||R̃|‖₂ = ‖|R̃|‖₂² ≤ ‖R̃‖_F²,
   λ_min(G) ≥ −‖ΔG‖₂ ≥ −(γ_{n+1}‖R̃‖_F² + n·τ).
4. *Conclusion* (Weyl): M − δI = G + (H − cI − G) + (M − H) + (c − δ)I, so
   λ_min(M − δI) ≥ c − δ − γ_{n+1}‖R̃‖_F² − nτ − u‖H‖_F − nη − u·max_i|G_ii|.

The right-hand side is evaluated exactly over Q (``fmpq``), with every float sum replaced by
a rigorous upper bound: a float sum s̃ of N correctly rounded squares (any summation order)
satisfies s ≤ (s̃ + Nη)/(1 − N·u), and square roots are rounded up and checked by squaring
exactly. If it is > 0, M − δI ≻ 0 is proved. Otherwise — the factorization breaks down, or the
margin is too small to show in double precision — the test says *unknown* (``None``) and the
caller falls back to an exact test: this test never proves "not positive definite".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq, fmpq_mat

from obsdesign.certify.printing import fmt_down

#: unit roundoff u = 2⁻⁵³ and the smallest subnormal η = 2⁻¹⁰⁷⁴, exactly
U = fmpq(1, 2**53)
ETA = fmpq(1, 2**1074)
#: the deliberately generous underflow unit of τ (see the module docstring)
TAU_UNIT = fmpq(1, 2**1000)

#: the ``check`` wording of a claim proved by :func:`verified_pd`
VCHOL_CHECK = (
    "verified floating-point Cholesky of fl(M) − cI (numpy elementwise IEEE operations; "
    "Higham Thm 10.3 backward error γ_{n+1}|R̃ᵀ||R̃| plus conversion, shift and underflow "
    "bounds, the final inequality checked exactly over Q)"
)


@dataclass(frozen=True)
class VCholResult:
    """A proof of M − δI ≻ 0: ``bound`` is the exact lower bound on λ_min(M − δI) the theorem
    gives (> 0), ``shift`` the float c, ``n`` the size."""

    bound: fmpq
    shift: float
    n: int

    @property
    def detail(self) -> str:
        """One line for the claim's detail."""
        return (
            f"verified float Cholesky: λ_min(M − δI) ≥ {fmt_down(self.bound, 3)} > 0 "
            f"(shift c ≈ {self.shift:.3g}, n = {self.n})"
        )


def to_float(F: fmpq_mat) -> np.ndarray | None:
    """H = fl(F) entry by entry, each entry correctly rounded (step 1 of the theorem), or None
    when an entry lies beyond the float range.

    :param F: a rational matrix."""
    n, m = F.nrows(), F.ncols()
    # entry by entry: one common denominator (F.numer_denom()) of a hostile report's 10⁴
    # distinct 30-digit denominators had 264,000 digits, took 15 s and 3.3 GB in one C call,
    # and 600-digit ones ran out of memory (responsiveness review 47)
    try:
        vals = [int(x.p) / int(x.q) for x in F.entries()]  # int/int: correctly rounded
    except OverflowError:
        return None
    H = np.array(vals, dtype=float).reshape(n, m)
    if not np.all(np.isfinite(H)):
        return None
    return H


def float_cholesky(G: np.ndarray) -> np.ndarray | None:
    """The upper Cholesky factor R̃ of G (G ≈ R̃ᵀR̃) by the outer-product algorithm in numpy
    elementwise IEEE operations (step 3 of the theorem), or None when a pivot is not positive
    or a value is not finite.

    :param G: a symmetric float matrix (not modified)."""
    n = G.shape[0]
    W = np.array(G, dtype=float, copy=True)
    R = np.zeros_like(W)
    for k in range(n):
        p = float(W[k, k])
        if not (p > 0.0 and math.isfinite(p)):
            return None
        r = math.sqrt(p)  # correctly rounded (IEEE)
        row = np.divide(W[k, k + 1 :], r)
        R[k, k] = r
        R[k, k + 1 :] = row
        if k + 1 < n:
            sub = W[k + 1 :, k + 1 :]
            np.subtract(sub, np.multiply.outer(row, row), out=sub)
    if not np.all(np.isfinite(R)):
        return None
    return R


def _sum_sq_up(X: np.ndarray) -> fmpq:
    """A rigorous upper bound of Σ X_ij² (exact): (s̃ + Nη)/(1 − Nu) for the float sum s̃."""
    N = X.size
    s = float(np.sum(np.multiply(X, X)))
    if not math.isfinite(s):
        raise OverflowError
    return (fmpq(*s.as_integer_ratio()) + N * ETA) / (1 - N * U)


def _sqrt_up(q: fmpq) -> fmpq:
    """An upper bound of √q (q ≥ 0), checked by squaring exactly."""
    if q <= 0:
        return fmpq(0)
    r = math.sqrt(float(q))
    while True:
        r = math.nextafter(r * (1 + 2**-40), math.inf)
        rq = fmpq(*r.as_integer_ratio())
        if rq * rq >= q:
            return rq


def _gamma(k: int) -> fmpq:
    return k * U / (1 - k * U)


def int_to_float(Z: Any) -> tuple[np.ndarray, int]:
    """H = fl(Z·2⁻ˢ) entry by entry for an integer matrix Z, each entry correctly rounded
    (step 1 of the theorem, for the matrix Z·2⁻ˢ), with the exponent s chosen so that the
    largest entry of Z·2⁻ˢ lies in [1, 2): no overflow, and the scaling is exact. Positive
    definiteness is invariant under the positive factor 2⁻ˢ, so an integer matrix (e.g. the
    decay matrix of eq. (4)-(6), constrained-redesign paper, times its positive common
    denominator) is tested without forming its rational entries.

    :param Z: a flint ``fmpz_mat``. Returns (H, s); s = 0 for the zero matrix."""
    n, m = Z.nrows(), Z.ncols()
    ents = [int(z) for z in Z.entries()]
    top = max(map(abs, ents), default=0)
    s = top.bit_length() - 1 if top else 0
    d = 1 << s
    vals = [z / d for z in ents]  # int/int true division: correctly rounded, |value| ≤ 2
    return np.array(vals, dtype=float).reshape(n, m), s


def verified_pd(F: fmpq_mat, margin: Any = 0, H: np.ndarray | None = None) -> VCholResult | None:
    """A proof that F − margin·I ≻ 0 by the theorem of this module, or None (unknown: never a
    proof of the contrary).

    :param F: symmetric n×n rational matrix (symmetry is the caller's to check);
    :param margin: δ ≥ 0 (exact); :param H: fl(F) from :func:`to_float`, when already made.
    """
    n = F.nrows()
    if n == 0:
        return None
    delta = margin if isinstance(margin, fmpq) else fmpq(margin)
    if H is None:
        H = to_float(F)
        if H is None:
            return None
    top = float(np.max(np.abs(H)))
    if top == 0.0:
        return None
    e = math.frexp(top)[1]
    if not -500 <= e <= 500:
        # M − δI ≻ 0 iff 2⁻ᵉ(M − δI) ≻ 0: scale exactly, away from overflow and underflow
        s = fmpq(2) ** (-e)
        F, delta = F * s, delta * s
        H = to_float(F)
        if H is None:
            return None
    return verified_pd_float(H, delta)


def subnormals_kept() -> bool:
    """Whether numpy's arithmetic keeps subnormal numbers in this process (no flush-to-zero
    or denormals-are-zero mode, which a library built with fast-math can switch on for the
    whole process): the underflow terms η of the theorem assume gradual underflow. When it
    does not, the float proofs say "unknown" and the exact tests decide."""
    tiny = np.array([2.0**-1074, 2.0**-1060])
    return bool(np.all((tiny * 1.0) == tiny) and (tiny[1] * 0.5) > 0.0)


def verified_pd_float(H: np.ndarray, delta: fmpq) -> VCholResult | None:
    """Steps 2-4 of the theorem: a proof that M − δI ≻ 0 from H, or None (unknown).

    H must be the entrywise correctly rounded float matrix of the (symmetric, exact) matrix M
    meant — :func:`to_float` of M, or :func:`int_to_float` of an integer matrix Z with
    M = Z·2⁻ˢ — so that |M − H| ≤ u|H| + η (step 1); every entry finite and the largest
    within 2^±500 of 1 (:func:`verified_pd` rescales when it is not).

    :param H: the float matrix; :param delta: δ ≥ 0 (exact)."""
    n = H.shape[0]
    if n == 0 or not np.all(np.isfinite(H)) or not subnormals_kept():
        return None
    top = float(np.max(np.abs(H)))
    if top == 0.0 or not -500 <= math.frexp(top)[1] <= 500:
        return None
    try:
        hf = _sqrt_up(_sum_sq_up(H))
        conv = U * hf + n * ETA  # ≥ ‖M − H‖₂
        dmax = float(np.max(np.abs(np.diag(H))))
        est = float(_gamma(n + 1)) * float(np.sum(np.abs(np.diag(H)))) + float(conv) + dmax * 2**-52
        c = float(delta) + 2.0 * est + 2.0 * float(n * TAU_UNIT)
        for _ in range(2):
            c = float(np.nextafter(c, np.inf))
            G = H.copy()
            idx = np.arange(n)
            G[idx, idx] = np.subtract(np.diag(H), c)
            R = float_cholesky(G)
            if R is None:
                return None
            rmax = fmpq(*float(np.max(np.diag(R))).as_integer_ratio())
            tau = TAU_UNIT * (n + 2) * (1 + rmax)
            gmax = fmpq(*float(np.max(np.abs(np.diag(G)))).as_integer_ratio())
            err = _gamma(n + 1) * _sum_sq_up(R) + n * tau + conv + U * gmax
            bound = fmpq(*c.as_integer_ratio()) - delta - err
            if bound > 0:
                return VCholResult(bound, c, n)
            c = float(delta) + 2.0 * float(err)  # the estimate was short: one retry
    except OverflowError:
        return None
    return None
