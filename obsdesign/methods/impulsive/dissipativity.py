"""QSR data of the nonlinearity (Assumption 1) and the two dissipation rates κ_n, ϖ_o.

Reading of Assumption 1 (eq. (15), impulsive-dissipativity paper 001). Taken literally, (15)
with Q_i ⪯ 0 "uniformly with respect to ε_j" forces ψ̃_i = 0 whenever ε_i = 0 (put ε_i = 0:
ψ̃_iᵀ Q_i ψ̃_i ≥ 0), so ψ̃_i may not depend on ε_j at all. obsdesign reads it in *split form*:

    ψ̃_i(ε) = φ_i(ε_i) + c_i(ε),   φ_i(ε_i) = ψ̄_i(z_i + ε_i, z_j) − ψ̄_i(z),
                                   c_i(ε)   = ψ̄_i(z + ε) − ψ̄_i(z_i + ε_i, z_j),

with the *own part* φ_i (Q_i, S_i, R_i)-dissipative in the sense of (15) for every trajectory
point z (in the stated region) and the *cross part* bounded linearly, ‖c_i‖ ≤ ℓ_ij ‖ε_j‖.
The proofs of Lemmas 1-2 go through unchanged with the coupling norms enlarged:
2ε_nᵀ(Ā_no ε_o + c_n) ≤ 2(‖Ā_no‖ + ℓ_no)‖ε_n‖‖ε_o‖, i.e. λ*_no = ‖Ā_no‖ + ℓ_no and
λ*_on = ‖Ā_on‖ + ℓ_on. With ℓ_on = ℓ_no = 0 this is the literal reading.

A QSR triple may be multiplied by any θ > 0 and stays valid, but (16) and the ssd LMI are not
scale invariant; the tool picks θ (rounded to a dyadic rational) to minimize ϖ_o / maximize
κ_n, unless ``qsr_scaling = "as-given"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, dyadic, qeye, qzeros, symmetrize, to_float


@dataclass
class QSR:
    """A supply-rate triple (Q, S, R) of eq. (4)/(15), exact, k×k blocks; ``how`` documents
    where it came from (given / Lipschitz / sector / derived from a bound in x)."""

    Q: np.ndarray
    S: np.ndarray
    R: np.ndarray
    how: str

    def __post_init__(self) -> None:
        k = np.shape(self.Q)[0] if np.ndim(self.Q) else 0
        if any(np.shape(x) != (k, k) for x in (self.Q, self.S, self.R)):
            raise ValueError(f"QSR ({self.how}): Q, S and R must be k×k blocks of one size")

    @property
    def k(self) -> int:
        """The block size k (the dimension of ε and φ in eq. (15))."""
        return self.Q.shape[0]

    def scaled(self, theta: Any) -> QSR:
        """θ·(Q, S, R): the same supply rate scaled by θ > 0 (valid for any θ > 0, see above)."""
        t = Q(theta)
        return QSR(self.Q * t, self.S * t, self.R * t, self.how)

    def floats(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Q, S, R in float64 (k×k each), for the solver."""
        return tuple(
            np.asarray(to_float(x), dtype=float).reshape(self.k, self.k)
            for x in (self.Q, self.S, self.R)
        )  # type: ignore[return-value]


def qsr_lipschitz(ell: Any, k: int) -> QSR:
    """‖φ(ε)‖ ≤ ℓ‖ε‖  ⇔  ℓ²‖ε‖² − ‖φ‖² ≥ 0  ⇔  (Q, S, R) = (−I, 0, ℓ² I) in (15)."""
    e = Q(ell)
    return QSR(-qeye(k), qzeros((k, k)), qeye(k) * (e * e), f"Lipschitz bound ℓ = {e}")


def qsr_sector(k1: Any, k2: Any, k: int) -> QSR:
    """Sector [k1, k2]: (φ − k1 ε)ᵀ(k2 ε − φ) ≥ 0  ⇔  (Q, S, R) = (−I, (k1+k2)/2 I, −k1 k2 I)."""
    a, b = Q(k1), Q(k2)
    return QSR(-qeye(k), qeye(k) * ((a + b) / 2), qeye(k) * (-a * b), f"sector [{a}, {b}]")


def ssd_matrix(Ablk: Any, qsr: QSR, rate: Any) -> np.ndarray:
    """N(κ) = [[Ā + Āᵀ + κ I + R, I + Sᵀ], [I + S, Q]], exact.

    Σ(Ā, I, I) is (−R, −Sᵀ, −Q)-ssd(κ) iff N(κ) ⪯ 0: eq. (7) with storage xᵀx, y = x and the
    supply (−R, −Sᵀ, −Q) (Lemma 1; Lemma 2's proof with κ = −ϖ_o).
    """
    A = np.asarray(Ablk, dtype=object)
    k = A.shape[0]
    top = np.hstack([A + A.T + qeye(k) * Q(rate) + qsr.R, qeye(k) + qsr.S.T])
    bot = np.hstack([qeye(k) + qsr.S, qsr.Q])
    return symmetrize(np.vstack([top, bot]))


def best_rate_float(
    Ablk: np.ndarray, Qm: np.ndarray, S: np.ndarray, R: np.ndarray
) -> tuple[float, float]:
    """Largest κ with N(κ) ⪯ 0 in floats, and the range residual.

    By the generalized Schur complement (Q ⪯ 0): N(κ) ⪯ 0 iff (I − QQ⁺)(I + S) = 0 and
    Ā + Āᵀ + R − (I + S)ᵀ Q⁺ (I + S) + κ I ⪯ 0, so κ* = −λ_max(Ā + Āᵀ + R − (I+S)ᵀQ⁺(I+S)).
    For Q ≺ 0 this is −λ_max(M_o) of eq. (16).
    """
    r, resid, _ = _rate_resid_scale(Ablk, Qm, S, R)
    return r, resid


def _rate_resid_scale(
    Ablk: np.ndarray, Qm: np.ndarray, S: np.ndarray, R: np.ndarray
) -> tuple[float, float, float]:
    """:func:`best_rate_float`'s (κ*, residual) and the size of the terms summed for κ*
    (max |entry| of Ā + Āᵀ, R and (I + S)ᵀQ⁺(I + S)): κ* is their sum's λ_max, so its float
    error is about one ulp of that size."""
    k = Ablk.shape[0]
    B = np.eye(k) + S
    Qp = np.linalg.pinv(Qm, rcond=1e-12)
    resid = float(np.linalg.norm((np.eye(k) - Qm @ Qp) @ B)) if k else 0.0
    BQB = B.T @ Qp @ B
    Mx = Ablk + Ablk.T + R - BQB
    lam = float(np.linalg.eigvalsh((Mx + Mx.T) / 2).max()) if k else -np.inf
    size = max((float(np.abs(t).max(initial=0.0)) for t in (Ablk + Ablk.T, R, BQB)), default=0.0)
    return -lam, resid, size


def range_theta(qsr: QSR) -> fmpq | None:
    """The one θ > 0 with (I − QQ⁺)(I + θS) = 0 when Q is singular (exact), else None.

    With Q ⪯ 0 singular, N(κ) ⪯ 0 needs I + θS ∈ range Q (the generalized Schur complement
    of :func:`best_rate_float`): Nᵀ(I + θS) = 0 for a basis N of ker Q. Unless NᵀS = 0 (then
    no θ works) that fixes θ = −⟨Nᵀ, NᵀS⟩ / ⟨NᵀS, NᵀS⟩, checked exactly. The float search
    lands near it, and its dyadic rounding missed it: Q_n = 0 with S_n = −0.999999 needs
    θ = 1000000/999999, and the design ended "could not be certified" although a report with
    that θ verifies (lyapunov/impulsive soundness trial, session 28)."""
    from flint import fmpq_mat

    k = qsr.k
    if k == 0:
        return None
    Qm = fmpq_mat(k, k, [Q(x) for x in np.asarray(qsr.Q, dtype=object).ravel()])
    X, nullity = Qm.numer_denom()[0].nullspace()  # ker of the integer multiple of Q
    if nullity == 0:
        return None
    N = [[fmpq(X[i, j]) for i in range(k)] for j in range(nullity)]  # rows: a basis of ker Q
    S = [[Q(x) for x in row] for row in np.asarray(qsr.S, dtype=object)]
    NS = [[sum((v[i] * S[i][c] for i in range(k)), fmpq(0)) for c in range(k)] for v in N]
    den = sum((x * x for row in NS for x in row), fmpq(0))
    if den == 0:
        return None
    num = sum(
        (a * b for va, vb in zip(N, NS, strict=True) for a, b in zip(va, vb, strict=True)), fmpq(0)
    )
    theta = -num / den
    if theta <= 0:
        return None
    ok = all(va[c] + theta * vb[c] == 0 for va, vb in zip(N, NS, strict=True) for c in range(k))
    return theta if ok else None


#: the weight of κ*(θ)'s float error (relative to the size of its terms) in the θ search of
#: :func:`best_rate`: a few ulps, so that among near-equal rates the search prefers the θ
#: whose float rate the exact rounding (:func:`~obsdesign.methods.impulsive.design.
#: certified_rate`, first step 2⁻⁵⁰ of that size) can confirm
ERROR_WEIGHT = 2.0**-48

#: the log θ grid of :func:`best_rate`'s first look, and how far it may be moved (θ within
#: e^±LOG_THETA_MAX: far inside the float range, θ·Q stays finite for any spec's Q)
LOG_THETA_GRID = np.linspace(-12, 12, 49)
LOG_THETA_MAX = 600.0


def _bracket_log_theta(neg: Any) -> tuple[float, float]:
    """A bracket [lo, hi] of log θ around the minimum of ``neg`` (−κ*(θ) plus a penalty),
    for the bounded search of :func:`best_rate`.

    The grid e^−12 … e^12 holds the optimum for plants of unit scale; the optimum moves
    like 1/(the plant's scale), so a plant scaled by 10⁻⁶ or 10⁹ (a time rescaling, whose
    window scales by 10⁶ / 10⁻⁹) had its optimum at a grid end: "Lemma 1 fails" (exit 1) on a
    feasible plant, or a window 2× too narrow (lyapunov/impulsive soundness trial, session
    28). While the minimum sits at an end, the grid moves that way by half its width
    (−κ*(θ) is convex in θ, so unimodal in log θ), in one direction only and up to
    |log θ| = :data:`LOG_THETA_MAX`. Moving by the whole width made consecutive grids share
    an end, and a minimum near log θ = ±12 sent the grid back and forth forever (re-check
    trial, session 28)."""
    grid = LOG_THETA_GRID
    half = (grid[-1] - grid[0]) / 2
    vals = [neg(g) for g in grid]
    direction = 0
    while True:
        i = int(np.argmin(vals))
        step = 0.0
        if i == 0 and direction <= 0 and grid[0] - half >= -LOG_THETA_MAX:
            step = -half
        elif i == len(grid) - 1 and direction >= 0 and grid[-1] + half <= LOG_THETA_MAX:
            step = half
        if step == 0.0:
            return grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
        direction = 1 if step > 0 else -1
        grid = grid + step
        vals = [neg(g) for g in grid]


def best_rate(Ablk: np.ndarray, qsr: QSR, optimize: bool) -> tuple[float, fmpq, float]:
    """(κ*, θ, range residual): the largest ssd rate over the scalings θ·(Q, S, R), θ > 0.

    κ*(θ) is concave in θ (λ_max of an affine-plus-convex matrix function), so a bounded
    scalar search over log θ finds the optimum. θ is returned as a short dyadic rational.
    """
    Qm, S, R = qsr.floats()
    if not optimize or qsr.k == 0:
        r, res = best_rate_float(Ablk, Qm, S, R)
        return r, fmpq(1), res

    def neg(lt: float) -> float:
        t = float(np.exp(lt))
        with np.errstate(all="ignore"):
            r, res, size = _rate_resid_scale(Ablk, t * Qm, t * S, t * R)
        # plus the float error of κ*(θ) (about an ulp of the terms it sums, which grow like
        # θ): a sector 7·10⁻¹⁸ wide has κ*(θ) rising to its supremum as θ → ∞, flat in floats
        # from θ ≈ e¹⁰ on, and the search followed rounding noise to θ ≈ 4·10²⁰, where the
        # float rate was −128 and the certified κ_n −1042: "Lemma 1 fails", exit 1, on a
        # design that certifies with κ_n ≈ 9.1 (impulsive review, session 42)
        v = -r + (1e6 * res if res > 1e-9 else 0.0) + ERROR_WEIGHT * size
        # an overflowed θ (NaN or inf) is the worst value, not the first argmin: a sector
        # [0, 10¹⁶⁰] overflowed (θS)² on the whole first grid, and its NaN was taken as the
        # minimum ("I + S_n ∉ range Q_n", a false reason; non-finite expressions trial,
        # session 35)
        return v if math.isfinite(v) else math.inf

    lo, hi = _bracket_log_theta(neg)
    from scipy.optimize import minimize_scalar  # loaded by the designs that need it

    res = minimize_scalar(neg, bounds=(lo, hi), method="bounded", options={"xatol": 1e-9})
    theta = range_theta(qsr) or dyadic(float(np.exp(res.x)), 24)
    tf = float(to_float(theta))
    r, resid = best_rate_float(Ablk, tf * Qm, tf * S, tf * R)
    return r, theta, resid
