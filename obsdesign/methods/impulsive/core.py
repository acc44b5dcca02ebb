"""The design pipeline of the impulsive observer, independent of the spec format.

Order of the paper (001): coordinates (9)-(10) → κ_n (Lemma 1) and ϖ_o (Lemma 2, (16)) →
γ, β (18), (21c) → λ*_on, λ*_no → κ from (22) → T_max (26b), T_min (26c) → radius of B
(Theorem 2). :func:`design_window` computes everything (floats first, then rounded to exact
rationals); :func:`certify_window` rebuilds every claim from the exact parameters only.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from flint import fmpq
from scipy.optimize import minimize

from obsdesign.certify.claim import Claim, exact_claim
from obsdesign.certify.exact import Q, dyadic, to_float
from obsdesign.certify.linalg import norm_bound_holds, norm_upper
from obsdesign.certify.psd import check_pd, check_psd

from .coordinates import (
    Coordinates,
    default_coordinates,
    orthonormal_complement,
    rational_M,
    transform,
)
from .dissipativity import QSR, best_rate, qsr_lipschitz, ssd_matrix
from .window import (
    T_max_lower,
    T_min_upper,
    coupling,
    gamma_of,
    kappa_max,
    kappa_widest,
    radius_upper,
    safe_window,
)

REF = "impulsive-dissipativity paper (001)"


class Infeasible(Exception):
    """A condition of the paper fails; the message names it and by how much."""


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
    A: np.ndarray  # exact n×n
    C: np.ndarray  # exact m×n
    L: np.ndarray  # exact diagonal of L (m)
    alpha: fmpq
    w_bar: fmpq  # bound on ‖w_k‖ (Euclidean), ‖w‖∞ of the paper
    M: Any  # exact (n−m)×n, or "orthonormal" / "optimize"
    data: BlockData | LipschitzX
    kappa: Any = "max"  # "max" | "widest" | fmpq
    optimize_scaling: bool = True
    digits: int = 4

    @property
    def m(self) -> int:
        return self.C.shape[0]


# -- derived block data --------------------------------------------------------------------
def derived_blocks(ell: Any, co: Coordinates) -> tuple[BlockData, dict[str, fmpq]]:
    """Split-reading data from ‖ψ(x̂) − ψ(x)‖ ≤ ℓ‖x̂ − x‖ (x = T⁻¹ z = P_o z_o + P_n z_n):

    ‖φ_o‖ ≤ ‖C‖ℓ‖P_o‖‖ε_o‖,  ‖c_o‖ ≤ ‖C‖ℓ‖P_n‖‖ε_n‖,  ‖φ_n‖ ≤ ‖M‖ℓ‖P_n‖‖ε_n‖,  ‖c_n‖ ≤ ‖M‖ℓ‖P_o‖‖ε_o‖,

    own parts as Lipschitz QSR (−I, 0, ℓ_ii² I). Every norm is an exact upper bound.
    """
    e = Q(ell)
    nC, nM = norm_upper(co.T[: co.m]), norm_upper(co.M)
    nPo, nPn = norm_upper(co.Pinv_o), norm_upper(co.Pinv_n)
    b = {"norm_C": nC, "norm_M": nM, "norm_Po": nPo, "norm_Pn": nPn}
    l_oo, l_on, l_nn, l_no = nC * e * nPo, nC * e * nPn, nM * e * nPn, nM * e * nPo
    k = co.m
    q_o = qsr_lipschitz(l_oo, k)
    q_n = qsr_lipschitz(l_nn, co.T.shape[0] - k)
    q_o.how = f"derived from lipschitz_x: ℓ_oo = ‖C‖ℓ‖P_o‖ ≤ {float(l_oo):.6g}"
    q_n.how = f"derived from lipschitz_x: ℓ_nn = ‖M‖ℓ‖P_n‖ ≤ {float(l_nn):.6g}"
    return BlockData(q_o, q_n, l_on, l_no), b


def blocks_for(p: Problem, co: Coordinates) -> tuple[BlockData, dict[str, fmpq]]:
    if isinstance(p.data, LipschitzX):
        return derived_blocks(p.data.ell, co)
    return p.data, {}


# -- float evaluation (used by the M search) -------------------------------------------------
def float_window(p: Problem, Mf: np.ndarray) -> float:
    """Window width T_max − T_min in floats for a float M (lipschitz_x data); a negative
    score measures how far (22) is from holding. Used only to choose M."""
    A, C = (np.asarray(to_float(x), dtype=float) for x in (p.A, p.C))
    ell = float(p.data.ell)  # type: ignore[union-attr]
    T = np.vstack([C, Mf])
    if abs(np.linalg.det(T)) < 1e-9:
        return -1e6
    Ti = np.linalg.inv(T)
    Ab = T @ A @ Ti
    m = p.m
    n2 = lambda X: float(np.linalg.norm(X, 2)) if X.size else 0.0  # noqa: E731
    nC, nM, nPo, nPn = n2(C), n2(Mf), n2(Ti[:, :m]), n2(Ti[:, m:])
    Ao, Aon, Ano, An = Ab[:m, :m], Ab[:m, m:], Ab[m:, :m], Ab[m:, m:]
    varpi = float(np.linalg.eigvalsh(Ao + Ao.T).max()) + 2 * nC * ell * nPo
    kap_n = -float(np.linalg.eigvalsh(An + An.T).max()) - 2 * nM * ell * nPn
    g, beta = (float(v) for v in gamma_of(p.L))
    coup = n2(Ano) + nM * ell * nPo + beta * (n2(Aon) + nC * ell * nPn)
    kmax = kap_n - coup
    if kmax <= 0:
        return kmax - 10.0
    kap = _kappa_float(p, max(varpi, 0.0), coup, g, kmax)
    tmax = -np.log((1 - g) ** 2) / (max(varpi, 0.0) + kap + coup)
    tmin = -np.log((float(p.alpha) - g) / float(p.alpha)) / kap
    return tmax - tmin


def _kappa_float(p: Problem, varpi: float, coup: float, g: float, kmax: float) -> float:
    if p.kappa == "max":
        return kmax * (1 - 1e-6)
    if p.kappa == "widest":
        return min(kappa_widest(varpi, coup, g, float(p.alpha)), kmax * (1 - 1e-6))
    return float(p.kappa)


def optimize_M(p: Problem, seed: int = 0, starts: int = 6) -> np.ndarray:
    """Search M (float) maximizing the window width T_max − T_min (Nelder-Mead from the
    orthonormal complement and random starts). Only meaningful when the nonlinearity data
    transform with T (``lipschitz_x``)."""
    C = np.asarray(to_float(p.C), dtype=float)
    n, m = C.shape[1], C.shape[0]
    M0 = orthonormal_complement(C)
    rng = np.random.default_rng(seed)
    best, best_val = M0, float_window(p, M0)
    for s in range(starts):
        x0 = (M0 if s == 0 else M0 + rng.normal(scale=0.5, size=M0.shape)).ravel()
        res = minimize(
            lambda v: -float_window(p, v.reshape(n - m, n)),
            x0,
            method="Nelder-Mead",
            options={"maxiter": 400 * n, "xatol": 1e-6, "fatol": 1e-9},
        )
        val = -float(res.fun)
        if val > best_val:
            best, best_val = res.x.reshape(n - m, n), val
    return best


# -- exact rounding of the two rates --------------------------------------------------------
def certified_rate(Ablk: np.ndarray, qsr: QSR, theta: fmpq, rate_f: float, lower: bool) -> fmpq:
    """Round the float rate to a dyadic rational on the safe side and bump it until the exact
    check N(rate) ⪯ 0 passes: κ_n rounded down (``lower``), −ϖ_o likewise (ϖ_o up)."""
    q = qsr.scaled(theta)
    step = 2.0**-30 * max(1.0, abs(rate_f))
    r = Q(dyadic(rate_f - step, 40))
    for _ in range(60):
        if check_psd(-ssd_matrix(Ablk, q, r)):
            return r
        r = r - Q(dyadic(step, 40))
        step *= 4
    raise Infeasible(
        "the ssd LMI could not be certified near its float optimum (ill-conditioned data)"
    )


def coordinates_for(p: Problem) -> Coordinates:
    if isinstance(p.M, str):
        if p.M == "orthonormal":
            return default_coordinates(p.A, p.C)
        return transform(p.A, p.C, rational_M(optimize_M(p)), "optimized")
    return transform(p.A, p.C, p.M, "given")


def design_window(p: Problem) -> tuple[dict[str, Any], list[str]]:
    """All parameters of the design, exact; raises :class:`Infeasible` with the failing
    inequality and its numbers."""
    notes: list[str] = []
    co = coordinates_for(p)
    data, derived = blocks_for(p, co)
    Af = {k: np.asarray(to_float(getattr(co, k)), dtype=float) for k in ("Ao", "An")}
    if not check_pd(-data.qsr_o.Q):
        raise Infeasible("Lemma 2 needs Q_o ≺ 0; the declared Q_o is not negative definite")
    if data.qsr_n.k and not check_psd(-data.qsr_n.Q):
        raise Infeasible(
            "Assumption 1 needs Q_n ⪯ 0; the declared Q_n is not negative semidefinite"
        )
    # Lemma 2 / (16): ϖ_o = max eig of M_o (rounded up, certified)
    ko, th_o, _ = best_rate(Af["Ao"], data.qsr_o, p.optimize_scaling)
    lam_Mo = -ko
    varpi = -certified_rate(co.Ao, data.qsr_o, th_o, ko, True)
    # Lemma 1: κ_n = largest ssd rate of Σ(Ā_n, I, I)
    kn_f, th_n, resid = best_rate(Af["An"], data.qsr_n, p.optimize_scaling)
    if not np.isfinite(kn_f) or resid > 1e-7:
        raise Infeasible(
            "Lemma 1: no κ_n makes Σ(Ā_n, I, I) (−R_n, −S_nᵀ, −Q_n)-ssd (I + S_n ∉ range Q_n)"
        )
    kappa_n = certified_rate(co.An, data.qsr_n, th_n, kn_f, True)
    n_no, n_on = norm_upper(co.Ano), norm_upper(co.Aon)
    lam_no, lam_on = n_no + data.ell_no, n_on + data.ell_on
    gamma, beta = gamma_of(p.L)
    if not kappa_n > lam_no:
        raise Infeasible(
            f"Lemma 1 fails: κ_n = {float(kappa_n):.6g} ≤ λ*_no = ‖Ā_no‖ + ℓ_no = {float(lam_no):.6g} "
            f"(short by {float(lam_no - kappa_n):.4g}); try another M"
        )
    kmax = kappa_max(kappa_n, lam_no, lam_on, beta)
    if kmax <= 0:
        raise Infeasible(
            f"condition (22) fails for every κ > 0: κ_n = {float(kappa_n):.6g} ≤ λ*_no + β λ*_on = "
            f"{float(lam_no):.6g} + {float(beta):.6g}·{float(lam_on):.6g} = {float(coupling(lam_no, lam_on, beta)):.6g}"
            f" (short by {float(-kmax):.4g})"
        )
    vp = max(float(varpi), 0.0)
    if p.kappa in ("max", "widest"):
        kf = _kappa_float(p, vp, float(coupling(lam_no, lam_on, beta)), float(gamma), float(kmax))
        kappa = Q(dyadic(kf, 30))
        while kappa >= kmax:
            kappa = kappa * fmpq(1023, 1024)
    else:
        kappa = Q(p.kappa)
        if not (0 < kappa < kmax):
            raise Infeasible(
                f"condition (22) fails for the given κ = {float(kappa):.6g}: it must lie in (0, {float(kmax):.6g})"
            )
    if varpi <= 0:
        # N(−ϖ) ⪯ N(−ϖ_o) for ϖ ≥ ϖ_o, so ϖ_o = 0 is still certified and keeps (26b) finite
        notes.append(
            f"Assumption 2 (ϖ_o > 0) does not hold: λ_max(M_o) = {lam_Mo:.6g}; ϖ_o = 0 is used in (26b) "
            "(sound: the ssd LMI of Lemma 2 holds for every ϖ_o ≥ λ_max(M_o))"
        )
        varpi = fmpq(0)
    T_max = T_max_lower(gamma, varpi, kappa, lam_no, lam_on, beta)
    T_min = T_min_upper(p.alpha, gamma, kappa)
    T_max_r, T_min_r = safe_window(T_max, T_min, p.digits)
    if not T_min_r < T_max_r:
        raise Infeasible(
            f"empty window: T_min = {float(T_min):.6g} ≥ T_max = {float(T_max):.6g} (κ = {float(kappa):.6g}); "
            "a larger α, a smaller γ (L closer to I... ) or another κ/M may help"
        )
    params: dict[str, Any] = {
        "T": co.T,
        "M_source": co.source,
        "Abar": co.Abar,
        "theta_o": th_o,
        "theta_n": th_n,
        "varpi_o": varpi,
        "lambda_max_Mo": lam_Mo,
        "assumption2": bool(lam_Mo > 0),
        "kappa_n": kappa_n,
        "norm_Ano": n_no,
        "norm_Aon": n_on,
        "ell_no": Q(data.ell_no),
        "ell_on": Q(data.ell_on),
        "lambda_no": lam_no,
        "lambda_on": lam_on,
        "gamma": gamma,
        "beta": beta,
        "kappa_max": kmax,
        "kappa": kappa,
        "T_min": T_min_r,
        "T_max": T_max_r,
        "alpha": Q(p.alpha),
        "w_bar": Q(p.w_bar),
        "ball_radius": radius_upper(p.alpha, p.w_bar),
    }
    params.update(derived)
    notes.append(f"M from {co.source}; QSR o: {data.qsr_o.how}; n: {data.qsr_n.how}")
    return params, notes


# -- certificate ------------------------------------------------------------------------------
@dataclass
class _Claims:
    items: list[Claim] = field(default_factory=list)

    def add(
        self, id: str, stmt: str, ref: str, check: str, ok: bool, detail: str, margin: Any = 0
    ) -> None:
        self.items.append(exact_claim(id, stmt, f"{ref}, {REF}", check, margin, ok, detail))


def certify_window(p: Problem, P: dict[str, Any]) -> list[Claim]:
    """Every claim of the design, rebuilt from the problem and the exact parameters."""
    c = _Claims()
    T = np.asarray(P["T"], dtype=object)
    n, m = p.A.shape[0], p.m
    ok_shape = T.shape == (n, n) and all(T[i, j] == p.C[i, j] for i in range(m) for j in range(n))
    if not isinstance(p.M, str) and ok_shape:
        ok_shape = all(T[m + i, j] == p.M[i, j] for i in range(n - m) for j in range(n))
    try:
        co = transform(p.A, p.C, T[m:], str(P.get("M_source", "given")))
        nonsing = True
    except ValueError:
        nonsing = False
    c.add(
        "T",
        "T = [C; M] with C from the spec (and M from the spec when given), det T ≠ 0",
        "eq. (9)",
        "exact rank",
        ok_shape and nonsing,
        "" if ok_shape and nonsing else "T is not [C; M] or is singular",
    )
    if not (ok_shape and nonsing):
        return c.items
    same = np.asarray(P["Abar"], dtype=object).shape == co.Abar.shape and all(
        a == b for a, b in zip(np.asarray(P["Abar"], dtype=object).flat, co.Abar.flat, strict=True)
    )
    c.add(
        "Abar",
        "Ā = T A T⁻¹ (blocks Ā_o, Ā_on, Ā_no, Ā_n)",
        "eq. (10c)",
        "exact rational inverse and product",
        same,
        "" if same else "reported Ā differs from T A T⁻¹",
    )
    data, derived = blocks_for(p, co)
    for k, v in derived.items():
        if k in P and Q(P[k]) != v:
            c.add(k, f"{k} recomputed", "split reading", "exact", False, f"report {P[k]} ≠ {v}")
    if derived:
        X = {"norm_C": co.T[:m], "norm_M": co.M, "norm_Po": co.Pinv_o, "norm_Pn": co.Pinv_n}
        ok = all(norm_bound_holds(X[k], derived[k]) for k in X)
        c.add(
            "lipschitz-x-blocks",
            "own/cross Lipschitz constants ℓ‖·‖‖·‖ of ψ̄ from the bound in x are upper bounds",
            "split reading of Assumption 1",
            "exact u²I − XᵀX ⪰ 0 for each norm",
            ok,
            "",
        )
    r = check_pd(-data.qsr_o.Q)
    c.add("Q_o-negative-definite", "Q_o ≺ 0", "Lemma 2", "exact LDLᵀ", r.ok, r.detail)
    r = check_psd(-data.qsr_n.Q) if data.qsr_n.k else None
    c.add(
        "Q_n-negative-semidefinite",
        "Q_n ⪯ 0",
        "Assumption 1",
        "exact LDLᵀ",
        r is None or r.ok,
        "" if r is None else r.detail,
    )
    th_o, th_n = Q(P["theta_o"]), Q(P["theta_n"])
    ok_th = th_o > 0 and th_n > 0
    varpi, kappa_n = Q(P["varpi_o"]), Q(P["kappa_n"])
    r = check_psd(-ssd_matrix(co.Ao, data.qsr_o.scaled(th_o), -varpi)) if ok_th else None
    c.add(
        "varpi_o",
        f"Σ(Ā_o, I, I) is (−R_o, −S_oᵀ, −Q_o)-ssd(−ϖ_o), ϖ_o = {float(varpi):.6g} ≥ λ_max(M_o)",
        "Lemma 2, eq. (16)",
        "exact LDLᵀ of −N(−ϖ_o) (scaled QSR θ_o > 0)",
        bool(r),
        "" if r is None else r.detail,
    )
    r = check_psd(-ssd_matrix(co.An, data.qsr_n.scaled(th_n), kappa_n)) if ok_th else None
    c.add(
        "kappa_n",
        f"Σ(Ā_n, I, I) is (−R_n, −S_nᵀ, −Q_n)-ssd(κ_n), κ_n = {float(kappa_n):.6g}",
        "Lemma 1, eq. (7)",
        "exact LDLᵀ of −N(κ_n) (scaled QSR θ_n > 0)",
        bool(r),
        "" if r is None else r.detail,
    )
    lam_no, lam_on = Q(P["lambda_no"]), Q(P["lambda_on"])
    ok = norm_bound_holds(co.Ano, lam_no - data.ell_no)
    c.add(
        "lambda_no",
        f"λ*_no = ‖Ā_no‖ + ℓ_no ≤ {float(lam_no):.6g}",
        "Lemma 1",
        "exact u²I − XᵀX ⪰ 0",
        ok,
        "",
    )
    ok = norm_bound_holds(co.Aon, lam_on - data.ell_on)
    c.add(
        "lambda_on",
        f"λ*_on = ‖Ā_on‖ + ℓ_on ≤ {float(lam_on):.6g}",
        "Theorem 1",
        "exact u²I − XᵀX ⪰ 0",
        ok,
        "",
    )
    gamma, beta = gamma_of(p.L)
    ok = Q(P["gamma"]) == gamma and Q(P["beta"]) == beta and 0 < 1 - gamma < 1
    c.add(
        "gamma-beta",
        f"1 − γ = λ_max(I − L) = {float(1 - gamma):.6g} ∈ (0, 1), β = 1/(1 − γ)² = {float(beta):.6g}",
        "eqs. (18), (21c)",
        "exact",
        ok,
        "",
    )
    c.add(
        "lemma1-iss",
        f"κ_n > λ*_no ({float(kappa_n):.6g} > {float(lam_no):.6g}): (14b) is ISS w.r.t. ε_o",
        "Lemma 1",
        "exact",
        kappa_n > lam_no,
        "",
    )
    kappa = Q(P["kappa"])
    rhs = coupling(lam_no, lam_on, beta) + kappa
    c.add(
        "condition-22",
        f"κ_n > λ*_no + β λ*_on + κ with κ = {float(kappa):.6g} > 0",
        "Theorem 1, eq. (22)",
        "exact",
        bool(kappa > 0 and kappa_n > rhs),
        f"slack {float(kappa_n - rhs):.6g}",
    )
    T_max, T_min = Q(P["T_max"]), Q(P["T_min"])
    try:
        lo = T_max_lower(gamma, varpi, kappa, lam_no, lam_on, beta)
        ok, det = bool(0 < T_max <= lo), f"T_max = {T_max} ≤ {float(lo):.10g} (outward-rounded)"
    except ValueError as e:
        ok, det = False, str(e)
    c.add(
        "T_max",
        f"T_max = {float(T_max):.6g} ≤ −ln((1−γ)²)/(ϖ_o + κ + λ*_no + βλ*_on)",
        "Theorem 2, eq. (26b); (22) for i = o",
        "interval arithmetic, rounded down",
        ok,
        det,
    )
    try:
        hi = T_min_upper(p.alpha, gamma, kappa)
        ok, det = bool(T_min >= hi), f"T_min = {T_min} ≥ {float(hi):.10g} (outward-rounded)"
    except ValueError as e:
        ok, det = False, str(e)
    c.add(
        "T_min",
        f"T_min = {float(T_min):.6g} ≥ −ln((α − γ)/α)/κ, α = {float(p.alpha):g} > γ",
        "Theorem 2, eq. (26c)",
        "interval arithmetic, rounded up",
        ok,
        det,
    )
    c.add(
        "window",
        f"T_min < T_max ({float(T_min):.6g} < {float(T_max):.6g})",
        "Theorem 2, eq. (26a)",
        "exact",
        T_min < T_max,
        "",
    )
    rad = Q(P["ball_radius"])
    c.add(
        "ball_radius",
        f"radius of B ≥ √(α‖w‖∞) = √({float(p.alpha):g}·{float(p.w_bar):g})",
        "Theorem 2",
        "exact r² ≥ α w̄",
        bool(rad >= 0 and rad * rad >= Q(p.alpha) * Q(p.w_bar)) and Q(P["w_bar"]) == Q(p.w_bar),
        "",
    )
    return c.items
