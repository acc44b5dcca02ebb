"""A rigorous float enclosure of the decay matrix of a quadratic Lyapunov function: the float
matrix V computed with BLAS from correctly rounded copies of the exact data, and an exact
rational e ≥ ‖M − V‖₂ — so that a verified Cholesky of V with the margin raised by e proves
the exact matrix M positive definite without forming it (issue 12: at n = 100 the exact
integer products and their conversion cost ~30 ms a check, this ~3 ms).

Notation as in :mod:`obsdesign.certify.vchol`: u = 2⁻⁵³, γ_k = k·u/(1 − k·u), ‖·‖ the
Frobenius norm (an upper bound of the spectral norm, submultiplicative, and
‖|X||Y|‖ ≤ ‖X‖‖Y‖); η₁ = 2⁻¹⁰²¹, twice the smallest normal number, as the absolute error of
one product or sum in the underflow range (generous: it holds even if a BLAS kernel flushed
subnormals to zero).

**Data.** Exact A (n×n; the error dynamics A − LC) and P (n×n), exact rate ρ = λ² (discrete)
or c = 2α (continuous). A_f, P_f are their entrywise correctly rounded float copies
(:func:`obsdesign.certify.vchol.to_float`), so ‖A − A_f‖ ≤ u‖A_f‖ + nη₁ =: a and likewise p
for P; ρ_f = fl(ρ), whose error |ρ − ρ_f| is computed exactly.

**Lemma (floating-point products).** For float matrices X (m×n), Y (n×k) and any order of
summation, with or without fused multiply-add, |fl(XY) − XY| ≤ γ_n|X||Y| + nη₁ entrywise
(Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., §3.1 and §3.5, plus one
absolute underflow error per product). Hence ‖fl(XY) − XY‖ ≤ γ_n‖X‖‖Y‖ + n²η₁ for square
n×n factors. An elementwise operation z = fl(x ∘ y) has |z − x ∘ y| ≤ u|z| + η₁, so a whole
matrix is off by at most u‖Z‖ + nη₁.

**Discrete,** M = ρP − AᵀPA: T = fl(P_f A_f), S = fl(A_fᵀ T), U = fl(ρ_f P_f), V = fl(U − S).
M − V = (ρP − ρ_fP_f) − (AᵀPA − A_fᵀP_fA_f) + (ρ_fP_f − U) − (A_fᵀP_fA_f − S) + (U − S − V), so
with N_A = ‖A_f‖ + a ≥ ‖A‖ and N_P = ‖P_f‖ + p ≥ ‖P‖,

    e = |ρ − ρ_f| N_P + |ρ_f| p                                   (rate and P rounded)
      + a N_P N_A + ‖A_f‖ p N_A + ‖A_f‖ ‖P_f‖ a                   (A, P rounded, in AᵀPA)
      + u‖U‖ + nη₁                                                (U)
      + ‖A_f‖(γ_n‖P_f‖‖A_f‖ + n²η₁) + γ_n‖A_f‖‖T‖ + n²η₁          (T and S)
      + u‖V‖ + nη₁                                                (V)

**Continuous,** M = −(AᵀP + PA + cP): X = fl(A_fᵀP_f), Y = fl(P_fA_f), W = fl(X + Y),
U = fl(c_f P_f), V = −fl(W + U) (negation is exact), and

    e = |c − c_f| N_P + |c_f| p + 2(a N_P + ‖A_f‖ p)
      + 2(γ_n‖A_f‖‖P_f‖ + n²η₁) + u‖W‖ + u‖U‖ + u‖V‖ + 3nη₁

**Use.** H = fl((V + Vᵀ)/2) is the correctly rounded symmetric part of V, so it meets step 1
of :mod:`obsdesign.certify.vchol` for the matrix V_s = (V + Vᵀ)/2. The checked matrix is
M_s = (M + Mᵀ)/2, and ‖M_s − V_s‖₂ ≤ ‖M − V‖₂ ≤ e. If the verified Cholesky proves
λ_min(V_s − (δ + e)I) > 0, then by Weyl λ_min(M_s − δI) ≥ λ_min(V_s − δI) − e > 0. Every norm
above is a rigorous upper bound (:func:`frob_up`) and e is summed exactly over Q. The test
can only prove; when it does not, the caller decides exactly.
"""

from __future__ import annotations

import numpy as np
from flint import fmpq

from obsdesign.certify.vchol import U, _sqrt_up, _sum_sq_up

#: η₁ = 2⁻¹⁰²¹: the absolute error allowed to one operation in the underflow range
ETA1 = fmpq(1, 2**1021)


def frob_up(X: np.ndarray) -> fmpq:
    """A rigorous upper bound of the Frobenius norm of a finite float matrix (exact).

    :param X: the matrix. Raises OverflowError when the float sum of squares overflows."""
    return _sqrt_up(_sum_sq_up(X))


def _gamma(n: int) -> fmpq:
    return n * U / (1 - n * U)


def _q(x: float) -> fmpq:
    return fmpq(*float(x).as_integer_ratio())


def decay_enclosure(
    Af: np.ndarray, Pf: np.ndarray, rate: fmpq, discrete: bool
) -> tuple[np.ndarray, fmpq] | None:
    """(H, e): H = fl((V + Vᵀ)/2) for the float decay matrix V of the module docstring and an
    exact e ≥ ‖M − V‖₂, M = λ²P − AᵀPA (discrete, eq. (5)-(6) with w = 0 of the
    constrained-redesign paper, Astolfi et al., NOLCOS 2019) or −(AᵀP + PA + 2αP)
    (continuous); None when a value is not finite or n·u is not small.

    :param Af: the correctly rounded float copy of the exact A (A − LC); :param Pf: that of
    the exact P; :param rate: λ (discrete) or α (continuous), exact."""
    n = Af.shape[0]
    if n == 0 or n * U >= fmpq(1, 100):
        return None
    if not (np.all(np.isfinite(Af)) and np.all(np.isfinite(Pf))):
        return None
    eta_n = n * ETA1
    with np.errstate(all="ignore"):
        try:
            nA, nP = frob_up(Af), frob_up(Pf)
            a, p = U * nA + eta_n, U * nP + eta_n
            NA, NP = nA + a, nP + p
            g = _gamma(n)
            prod = g * nA * nP + n * eta_n  # one n×n product of A_f and P_f (Lemma)
            if discrete:
                rho = rate * rate
                rf = float(rho)
                T = Pf @ Af
                S = Af.T @ T
                Um = rf * Pf
                V = Um - S
                if not np.all(np.isfinite(V)):
                    return None
                e = (
                    abs(rho - _q(rf)) * NP
                    + abs(_q(rf)) * p
                    + a * NP * NA
                    + nA * p * NA
                    + nA * nP * a
                    + U * frob_up(Um)
                    + eta_n
                    + nA * prod
                    + g * nA * frob_up(T)
                    + n * eta_n
                    + U * frob_up(V)
                    + eta_n
                )
            else:
                c = 2 * rate
                cf = float(c)
                X = Af.T @ Pf
                Y = Pf @ Af
                W = X + Y
                Um = cf * Pf
                V = -(W + Um)
                if not np.all(np.isfinite(V)):
                    return None
                e = (
                    abs(c - _q(cf)) * NP
                    + abs(_q(cf)) * p
                    + 2 * (a * NP + nA * p)
                    + 2 * prod
                    + U * (frob_up(W) + frob_up(Um) + frob_up(V))
                    + 3 * eta_n
                )
            H = (V + V.T) * 0.5
        except OverflowError:
            return None
    if not np.all(np.isfinite(H)):
        return None
    return H, e
