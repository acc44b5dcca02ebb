"""Quadratic Lyapunov functions of a linear observer's error dynamics, shared by the methods.

Linear observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) (or its continuous analogue) on the plant
x⁺ = A x + B u + Bd d, y = C x + D u + Dn v: the error e = x̂ − x obeys

    e⁺ = Acl e + B_w w,   Acl = A − L C,   w = (d, v),   B_w = [−Bd, L Dn]

(ė = … in continuous time). This is the linear case of the quadratic Lyapunov function
V(e) = eᵀ P e of eq. (4) and the dissipation inequality V(Δ(x, e, w)) ≤ β(V(e), w) of eq. (5)
with β(v, w) = ρ v + μ |w|² (eq. (6)-(7)), ρ = λ², as in Section 5 of Astolfi, Bernard,
Postoyan, Marconi, "Redesign of discrete-time nonlinear observers with state estimate
constraints guaranteed in prescribed convex set", NOLCOS 2019 (the "constrained-redesign
paper"). Continuous time uses the analogue V̇ ≤ −2α V + μ |w|².

Every function takes explicit numbers (matrices, rates, margins, tolerances), never a method's
options object. Exact functions take and return ``fmpq`` object arrays (see
:mod:`obsdesign.certify.exact`); the float helpers say so.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq, fmpq_mat, fmpq_poly

from obsdesign.certify.detect import hurwitz_stable, schur_stable
from obsdesign.certify.exact import Q, dyadic, qeye, symmetrize
from obsdesign.certify.psd import check_pd, check_psd
from obsdesign.errors import InconclusiveError, InfeasibleError

#: reference printed in claims that check these formulas
REF = (
    "decay LMI, eq. (4)-(7) and Section 5 of Astolfi, Bernard, Postoyan, Marconi, "
    "NOLCOS 2019 (constrained-redesign paper)"
)
#: dyadic rounding of P (significant bits relative to its largest entry)
BITS = 40

INFEASIBLE = "infeasible"
NOT_CERTIFIABLE = "not-certifiable"


# -- exact matrices ------------------------------------------------------------------------
def closed_loop(A: np.ndarray, C: np.ndarray, L: np.ndarray) -> np.ndarray:
    """Acl = A − L C, the error dynamics matrix of eq. (3) for a linear observer (exact).

    :param A: n×n state matrix; :param C: p×n output matrix; :param L: n×p gain."""
    return A - L @ C


def decay_matrix(
    A: np.ndarray, C: np.ndarray, L: np.ndarray, P: np.ndarray, rate: Any, discrete: bool
) -> np.ndarray:
    """The matrix that is ⪰ 0 exactly when V = eᵀPe decays at ``rate`` (exact).

    Discrete: λ² P − Aclᵀ P Acl, i.e. eq. (5) with w = 0 and β(v, 0) = ρ v, ρ = λ² (eq. (6));
    continuous: −(Aclᵀ P + P Acl + 2α P), i.e. V̇ ≤ −2α V. Section 5 of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019) certifies its P this way.

    :param A, C, L: plant and gain (exact); :param P: symmetric n×n (exact);
    :param rate: λ (discrete) or α (continuous); :param discrete: time domain."""
    Acl = closed_loop(A, C, L)
    r = Q(rate)
    if discrete:
        return symmetrize(P * (r * r) - Acl.T @ P @ Acl)
    return symmetrize(-(Acl.T @ P + P @ Acl + P * (2 * r)))


def error_input(Bd: np.ndarray, Dn: np.ndarray, L: np.ndarray) -> np.ndarray:
    """B_w = [−Bd, L Dn] (exact): how w = (d, v) enters the error dynamics, eq. (3) of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019) for a linear observer.

    :param Bd: n×k process-disturbance input (k may be 0); :param Dn: p×q output-noise input
    (q may be 0); :param L: n×p gain. Returns n×(k+q), zero columns when both are empty."""
    n = L.shape[0]
    parts = []
    if Bd.shape[1]:
        parts.append(-Bd)
    if Dn.shape[1]:
        parts.append(L @ Dn)
    if not parts:
        return np.full((n, 0), fmpq(0), dtype=object)
    return np.hstack(parts)


def iss_matrix(
    Acl: np.ndarray, Bw: np.ndarray, P: np.ndarray, rho: Any, mu: Any, discrete: bool = True
) -> np.ndarray:
    """Block matrix that is ⪰ 0 exactly when the ISS inequality holds (exact).

    Discrete, eq. (5) with β(v, w) = ρ v + μ|w|² (eq. (6)) of the constrained-redesign paper
    (Astolfi et al., NOLCOS 2019): [[ρP − AclᵀPAcl, −AclᵀPB_w], [−B_wᵀPAcl, μI − B_wᵀPB_w]].
    Continuous, V̇ ≤ −ρ V + μ|w|² (ρ = 2α): [[−(AclᵀP + PAcl + ρP), −PB_w], [−B_wᵀP, μI]].

    :param Acl: A − LC; :param Bw: error input (:func:`error_input`); :param P: the Lyapunov
    matrix; :param rho: decay factor of V (λ² discrete, 2α continuous); :param mu: ISS gain."""
    k = Bw.shape[1]
    r = Q(rho)
    if discrete:
        S = symmetrize(P * r - Acl.T @ P @ Acl)
    else:
        S = symmetrize(-(Acl.T @ P + P @ Acl + P * r))
    if k == 0:
        return S
    if discrete:
        off = -(Acl.T @ P @ Bw)
        low = qeye(k) * Q(mu) - Bw.T @ P @ Bw
    else:
        off = -(P @ Bw)
        low = qeye(k) * Q(mu)
    return symmetrize(np.block([[S, off], [off.T, low]]))


def decay_factor(rate: Any, discrete: bool) -> fmpq:
    """ρ of β(v, w) = ρ v + μ|w|² (eq. (6), constrained-redesign paper) for a decay rate:
    λ² (discrete) or 2α (continuous, V̇ ≤ −2αV + μ|w|²).

    :param rate: λ or α; :param discrete: time domain."""
    r = Q(rate)
    return r * r if discrete else 2 * r


def iss_mu(
    Acl: np.ndarray,
    Bw: np.ndarray,
    P: np.ndarray,
    rho: Any,
    discrete: bool = True,
    strict: bool = False,
) -> fmpq:
    """Smallest ISS gain μ (rounded up, then certified exactly) for the given ρ.

    Schur complement of :func:`iss_matrix` (eq. (5)-(6) of the constrained-redesign paper,
    Astolfi et al., NOLCOS 2019): μ ≥ λ_max(B_wᵀPB_w + B_wᵀPAcl S⁻¹ AclᵀPB_w) with
    S = ρP − AclᵀPAcl ≻ 0 (discrete), μ ≥ λ_max(B_wᵀP S⁻¹ P B_w) with
    S = −(AclᵀP + PAcl + ρP) (continuous). The float value is rounded up to 30 bits and raised
    by 10 % steps until the exact check passes.

    :param Acl, Bw, P, rho, discrete: as in :func:`iss_matrix`;
    :param strict: certify the block matrix ≻ 0 (``check_pd``) instead of ⪰ 0 (``check_psd``).
    Returns μ (0 when B_w has no column). Raises :class:`InconclusiveError` when no μ certifies.
    """
    if Bw.shape[1] == 0:
        return fmpq(0)
    Af, Bf, Pf = (np.asarray(M, dtype=float) for M in (Acl, Bw, P))
    r = Q(rho)
    if discrete:
        S = np.asarray(symmetrize(P * r - Acl.T @ P @ Acl), dtype=float)
        G = Bf.T @ Pf @ Bf + Bf.T @ Pf @ Af @ np.linalg.solve(S, Af.T @ Pf @ Bf)
    else:
        S = np.asarray(symmetrize(-(Acl.T @ P + P @ Acl + P * r)), dtype=float)
        G = Bf.T @ Pf @ np.linalg.solve(S, Pf @ Bf)
    mu_f = float(np.linalg.eigvalsh((G + G.T) / 2).max())
    mu = dyadic(mu_f * (1 + 1e-9) + 1e-12, 30)
    check = check_pd if strict else check_psd
    for _ in range(80):
        if check(iss_matrix(Acl, Bw, P, r, mu, discrete)):
            return mu
        mu = mu * fmpq(11, 10) + fmpq(1, 10**9)
    raise InconclusiveError(
        "could not certify the ISS gain μ of eq. (5) (rate too close to its limit?)"
    )


# -- exact stability tests (the infeasible end of a rate bracket) ---------------------------
def _charpoly(M: np.ndarray) -> fmpq_poly:
    n = M.shape[0]
    return fmpq_mat(n, n, [Q(x) for x in M.flat]).charpoly()


def rate_feasible(Acl: np.ndarray, rate: Any, discrete: bool) -> bool:
    """Whether some P ≻ 0 makes :func:`decay_matrix` ≻ 0 at ``rate``, decided exactly.

    Discrete: iff every eigenvalue z of Acl has |z| < λ, i.e. det(zI − Acl/λ) is Schur stable
    (exact Schur–Cohn test); continuous: iff Acl + αI is Hurwitz (exact Routh test) — both from
    :mod:`obsdesign.certify.detect`. Necessity: for Acl v = z v,
    v* (λ²P − AclᵀPAcl) v = (λ² − |z|²) v*Pv (and −2(Re z + α) v*Pv in continuous time);
    sufficiency: the Lyapunov equation. This decides the decay LMI of eq. (4)-(6), Section 5 of
    the constrained-redesign paper (Astolfi et al., NOLCOS 2019), for a fixed gain.

    :param Acl: A − LC (exact); :param rate: λ or α (exact); :param discrete: time domain."""
    r = Q(rate)
    n = Acl.shape[0]
    if n == 0:
        return True
    if discrete:
        if r <= 0:
            return False
        return schur_stable(_charpoly(Acl * (1 / r)))[0]
    return hurwitz_stable(_charpoly(Acl + qeye(n) * r))[0]


def stability_test(discrete: bool) -> str:
    """The name of the exact test behind :func:`rate_feasible` (for messages and claims).

    :param discrete: time domain (Schur–Cohn, Section 5 setting of the constrained-redesign
    paper) or continuous (Routh)."""
    return "exact Schur–Cohn test" if discrete else "exact Routh test"


def as_qarray(M: fmpq_mat) -> np.ndarray:
    """An ``fmpq_mat`` as an exact object array (the form the functions here take), e.g. the
    unobservable restriction A_u whose modes bound every rate of eq. (4)-(6).

    :param M: a flint rational matrix."""
    return np.array(
        [[M[i, j] for j in range(M.ncols())] for i in range(M.nrows())], dtype=object
    ).reshape(M.nrows(), M.ncols())


# -- P from the Lyapunov equation, certified -----------------------------------------------
def lyapunov_P(
    A: np.ndarray, C: np.ndarray, L: np.ndarray, rate: float, discrete: bool
) -> np.ndarray:
    """P solving (A−LC)ᵀP(A−LC) − λ²P = −I (discrete; the paper's P of Section 5,
    constrained-redesign paper, Astolfi et al., NOLCOS 2019) or
    (A−LC+αI)ᵀP + P(A−LC+αI) = −I (continuous), in floats.

    :param A, C, L: float matrices; :param rate: λ or α; :param discrete: time domain."""
    from scipy.linalg import solve_continuous_lyapunov, solve_discrete_lyapunov

    Acl = A - L @ C
    n = A.shape[0]
    if discrete:
        P = solve_discrete_lyapunov((Acl / rate).T, np.eye(n) / rate**2)
    else:
        P = solve_continuous_lyapunov((Acl + rate * np.eye(n)).T, -np.eye(n))
    return (P + P.T) / 2


def certified_P(
    A: np.ndarray,
    C: np.ndarray,
    L: np.ndarray,
    discrete: bool,
    rate: Any,
    margin: Any,
    bits: int = BITS,
) -> np.ndarray | None:
    """A rational P (the Lyapunov-equation P rounded to ``bits`` dyadic bits) with
    P − margin·I ≻ 0 and :func:`decay_matrix` − margin·I ≻ 0 exactly, or None.

    Eq. (4)-(6) and Section 5 of the constrained-redesign paper (Astolfi et al., NOLCOS 2019).

    :param A, C, L: exact plant and gain; :param discrete: time domain; :param rate: λ or α
    (exact); :param margin: δ of the strict checks; :param bits: rounding of P."""
    r = Q(rate)
    if (discrete and r <= 0) or A.shape[0] == 0:
        return None
    Af, Cf, Lf = (np.asarray(x, dtype=float) for x in (A, C, L))
    try:
        Pf = lyapunov_P(Af, Cf, Lf, float(r), discrete)
    except (np.linalg.LinAlgError, ValueError):
        return None
    if not np.all(np.isfinite(Pf)):
        return None
    P = symmetrize(dyadic(Pf, bits))
    if not check_pd(P, margin):
        return None
    if not check_pd(decay_matrix(A, C, L, P, r, discrete), margin):
        return None
    return P


# -- the best rate, bracketed --------------------------------------------------------------
@dataclass
class RateBracket:
    """The best certified decay rate for a fixed gain and the other end of its bracket.

    ``best`` (λ or α) is certified with ``P``; ``other`` is the closest rate on the other side
    that was ``kind`` = ``"infeasible"`` (proved by :func:`rate_feasible`: no P ≻ 0 exists)
    or ``"not-certifiable"`` (feasible, but the rounded Lyapunov-equation P failed the exact
    check with the margin); |best − other| ≤ tol unless the search stopped on the grid."""

    best: fmpq
    P: np.ndarray
    other: fmpq
    kind: str
    tol: fmpq


def _grid(tol: fmpq) -> fmpq:
    digits = max(0, -int(np.floor(np.log10(float(tol))))) + 1
    return fmpq(1, 10**digits)


def _snap(x: fmpq, grid: fmpq, up: bool) -> fmpq:
    q = x / grid
    return (fmpq(int(q.ceil())) if up else fmpq(int(q.floor()))) * grid


def best_rate(
    A: np.ndarray,
    C: np.ndarray,
    L: np.ndarray,
    discrete: bool,
    *,
    tol: Any,
    margin: Any,
    known: tuple[Any, np.ndarray] | None = None,
    progress: Callable[[str], None] | None = None,
) -> RateBracket:
    """Bisection for the best certified rate of V = eᵀPe: the smallest λ (discrete) or the
    largest α (continuous) at which :func:`certified_P` succeeds, bracketed.

    The certified/feasible side of eq. (4)-(6) (constrained-redesign paper, Astolfi et al.,
    NOLCOS 2019, Section 5) is searched on a decimal grid of step tol/10. The bracket starts
    from the spectral bound: the grid point just beyond ρ(Acl) (resp. −max Re eig(Acl)) proved
    infeasible by :func:`rate_feasible`, and the certified end 1 − grid (resp. grid), or finer
    candidates when those fail. Each midpoint is decided exactly; a midpoint that fails is the
    new infeasible / not-certifiable end. ``known`` = (rate, P), a rate already certified
    (the user's), keeps the result at least as good: the search never reports a worse rate.

    :param A, C, L: exact plant and gain; :param discrete: time domain; :param tol: bracket
    width; :param margin: δ of the checks; :param known: a certified (rate, P);
    :param progress: callback for messages. Raises :class:`InfeasibleError` when Acl is not
    Schur / Hurwitz (exact) and :class:`InconclusiveError` when it is but nothing certifies."""
    Acl = closed_loop(A, C, L)
    tol_q = Q(tol)
    grid = _grid(tol_q)
    eig = np.linalg.eigvals(np.asarray(Acl, dtype=float))
    # r-space: r = λ (discrete) or r = −α (continuous); smaller r is better in both
    sign = 1 if discrete else -1

    def rate(r: fmpq) -> fmpq:
        return r * sign

    def cert(r: fmpq) -> np.ndarray | None:
        return certified_P(A, C, L, discrete, rate(r), margin)

    def feasible(r: fmpq) -> bool:
        return rate_feasible(Acl, rate(r), discrete)

    bound = float(np.max(np.abs(eig))) if discrete else float(np.max(eig.real))
    lo = _snap(Q(max(bound, 0.0)) if discrete else Q(bound), grid, False)
    while feasible(lo):  # float error put the spectral bound above a feasible grid point
        lo -= grid
    lo_kind = INFEASIBLE
    edge = fmpq(1) if discrete else fmpq(0)  # r must stay below it
    if lo >= edge:
        what = "Schur" if discrete else "Hurwitz"
        lim = f"spectral radius ≈ {bound:.6g}" if discrete else f"largest real part ≈ {bound:.6g}"
        raise InfeasibleError(f"A − LC is not {what}: {lim} ({stability_test(discrete)})")
    known_r = None if known is None else Q(known[0]) * sign
    hi, P = edge - grid, None
    if hi > lo:
        P = cert(hi)
    k = 1
    while P is None and k <= 12:
        if known_r is not None:
            hi, P = known_r, known[1]  # type: ignore[index]
            break
        cand = edge - grid / 10**k
        k += 1
        if cand > lo:
            P = cert(cand)
            hi = cand
    if P is None:
        what = "λ < 1" if discrete else "α > 0"
        raise InconclusiveError(
            f"A − LC is {'Schur' if discrete else 'Hurwitz'} (exact test) but no decay rate "
            f"{what} could be certified"
        )
    while hi - lo > tol_q:
        # the midpoint through float64 (as the search always did: same candidates, same result)
        mid = _snap(Q(float((lo + hi) / 2)), grid, True)
        if mid >= hi:
            break
        if progress:
            progress(f"bisection {'λ' if discrete else 'α'} = {float(rate(mid)):.6g}")
        Pm = cert(mid)
        if Pm is not None:
            hi, P = mid, Pm
        elif known_r is not None and known_r < mid:
            hi, P = known_r, known[1]  # type: ignore[index]
        else:
            lo, lo_kind = mid, (NOT_CERTIFIABLE if feasible(mid) else INFEASIBLE)
    if known_r is not None and known_r < hi:
        hi, P = known_r, known[1]  # type: ignore[index]
    return RateBracket(rate(hi), P, rate(lo), lo_kind, tol_q)
