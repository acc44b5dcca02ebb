"""Design of the refining map's parameters (Sections 3-4 of Astolfi, Bernard, Postoyan,
Marconi, NOLCOS 2019, the constrained-redesign paper).

Order: Lyapunov data (P, ρ, μ; Assumption 2) → X̂ → v_max (13) → ε_max (Assumption 3(2)) →
δ (Assumption 3(4)) → γ (24) → v_min (21) → θ (22), and optionally v̆_max of Section 4.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign import lyap
from obsdesign.certify.exact import Q, float_or_inf
from obsdesign.certify.interval import sqrt_upper
from obsdesign.certify.printing import fmt_exact
from obsdesign.errors import InconclusiveError, InfeasibleError, SpecError
from obsdesign.methods.base import Design, Progress, SolverResult, SolverStatus
from obsdesign.methods.constrained import bounds as B
from obsdesign.methods.constrained.lyap import w_sq_max
from obsdesign.methods.constrained.options import Options, default_Xhat
from obsdesign.params import Parameters
from obsdesign.sets.base import ConvexSet
from obsdesign.spec.models import Spec

REF = "Astolfi, Bernard, Postoyan, Marconi, NOLCOS 2019 (constrained-redesign paper)"


@dataclass
class LyapData:
    """P, ρ, μ of Assumption 2 (exact) and, when computed, the decay rate λ."""

    P: np.ndarray
    rho: fmpq
    mu: fmpq
    lam: fmpq | None
    #: best-rate search: the other end of the bracket and whether it is proved infeasible
    lam_other: fmpq | None = None
    other_kind: str = ""


def _radius_figure(A: Any, C: Any, L: Any) -> str:
    """ "spectral radius ≈ …" of A − LC for a message, from the spectral guide (naming its
    source when it is not accurate float eigenvalues; :func:`obsdesign.spectrum.spectrum`)."""
    from obsdesign.spectrum import spectrum

    Am = lyap.fmat(lyap.closed_loop(A, C, L))
    return spectrum(Am, lyap.mat_float(Am)).figure(True)


def lyapunov_data(spec: Spec) -> LyapData:
    """Assumption 2 and Section 5 of the constrained-redesign paper (Astolfi et al., NOLCOS
    2019): V(e) = eᵀPe (eq. (4)) with P solving (A−LC)ᵀP(A−LC) − λ²P = −I, certified exactly
    ((A−LC)ᵀP(A−LC) ⪯ λ²P); β(v, w) = ρv + μ|w|² (eq. (6)) with ρ = λ² or the spec's ρ ≥ λ²,
    and the smallest certified μ of eq. (5). The user's (P, ρ, μ) when the spec gives them.

    :param spec: the bound spec (``[method]`` L, lambda, rho, P, mu, margin, rate_tol).
    Raises :class:`InfeasibleError` when A − LC is not Schur or λ is below its spectral
    radius, :class:`InconclusiveError` when λ holds in floats but not exactly."""
    o: Options = spec.options
    s = spec.system
    if o.P is not None:
        return LyapData(o.P, Q(o.rho), Q(o.mu), None)
    A, C = s.A.q, s.C.q
    with np.errstate(over="ignore", invalid="ignore"):
        Acl_f = s.A.f - np.asarray(o.L, dtype=float) @ s.C.f
    # A − LC past the float range (C = 1e308): no float radius, the exact test decides (eigvals
    # raised LinAlgError, exit 3; CLI review, session 44)
    finite = bool(np.all(np.isfinite(Acl_f)))
    rad = float(np.max(np.abs(np.linalg.eigvals(Acl_f)))) if finite else math.inf
    if rad >= 1:
        # the float radius only raises the question; the exact test decides (a Jordan block
        # at 0.99999 has float radius 1.00017 and was refused, while lyapunov certified
        # λ = 0.999999 for the same A − LC: edge-shape trial, session 26)
        schur, how = lyap.rate_feasibility(lyap.closed_loop(A, C, o.L), 1, True)
        if not schur:
            raise InfeasibleError(
                f"A − LC is not Schur (an eigenvalue of modulus ≥ 1, {how}; "
                f"{_radius_figure(A, C, o.L)}): no Lyapunov function (Assumption 2)"
            )
    bracket: tuple[fmpq | None, str] = (None, "")
    if o.lam is None:
        try:
            br = lyap.best_rate(A, C, o.L, True, tol=o.rate_tol, margin=o.margin)
        except lyap.RateResolutionError as e:
            raise SpecError(spec.file, "method.rate_tol", e.hint()) from None
        lam, P = br.best, br.P
        bracket = (br.other, br.kind)

        if o.rho is not None and Q(o.rho) < lam * lam:
            # ρ ≥ λ² is needed (eq. (6)); with λ given this is a spec check, with λ omitted
            # it is known only now: it ran on to μ of eq. (5) and ended "inconclusive"
            # (exit 4) for a request no P can meet when ρ ≤ ρ(A − LC)² (outsider trial)
            raise SpecError(
                spec.file,
                "method.rho",
                f"expected rho >= λ_best² = {float(lam * lam):.6g} (λ omitted: the best "
                f"certified rate λ_best = {float(lam):.6g}, A − LC has "
                f"{_radius_figure(A, C, o.L)}; the design builds P for that rate and "
                "certifies β(v, d) = ρv + μ|d|² for ρ ≥ λ²): give a larger rho, or lambda "
                "with rho >= lambda²",
            )
    else:
        lam = o.lam
        P = lyap.certified_P(A, C, o.L, True, lam, o.margin)
        if P is None:
            # decided exactly (a float comparison of λ with the float radius decided before)
            ok, how = lyap.rate_feasibility(lyap.closed_loop(A, C, o.L), lam, True)
            if not ok:
                raise InfeasibleError(
                    f"{lyap.infeasible_head(o.margin)} decay rate λ = {fmt_exact(lam)}: A − LC "
                    "has an eigenvalue "
                    f"of modulus ≥ λ ({how}; {_radius_figure(A, C, o.L)})"
                    + lyap.nonstrict_note(o.margin, True)
                )
            raise InconclusiveError(
                f"decay rate λ = {float(lam):g} holds in floats but the exact check failed"
            )
    if lyap.beyond_float(P):
        # A − LC = 0 with rate_tol = 1e-300: the report's generic "integer division result
        # too large for a float" named no key (degenerate-sizes review, session 42)
        which = (
            f"a larger [method].rate_tol (now {fmt_exact(o.rate_tol)}) or [method].lambda"
            if o.lam is None
            else "a larger [method].lambda"
        )
        raise InconclusiveError(
            f"the certificate P at λ = {fmt_exact(lam)} has entries beyond the float range "
            f"(the decay LMI with margin δ = {fmt_exact(o.margin)} needs a P that large at "
            f"that rate), so the report cannot show it: {which}"
        )
    rho = Q(o.rho) if o.rho is not None else lam * lam
    Acl = lyap.closed_loop(A, C, o.L)
    mu = lyap.iss_mu(Acl, lyap.error_input(s.Bd.q, s.Dn.q, o.L), P, rho)
    return LyapData(P, rho, mu, lam, *bracket)


def design(spec: Spec, progress: Progress | None = None) -> Design:
    """The whole design of Sections 3-4 of the constrained-redesign paper (Astolfi et al.,
    NOLCOS 2019): see :func:`design_params`; the solver is the Lyapunov equation (closed form)
    certified exactly, then exact rational bounds.

    :param spec: the bound spec; :param progress: optional message callback."""
    import time

    if progress:
        progress("Lyapunov data, v_max, ε_max, δ, γ, v_min, θ")
    t0 = time.perf_counter()
    vals, notes = design_params(spec)
    o: Options = spec.options
    name = (
        "user-given Lyapunov data (P, ρ, μ) + exact rational bounds"
        if o.P is not None
        else f"{lyap.lyapunov_solver_name(spec.system.n, spec.system.discrete)}, certified "
        "exactly + exact rational bounds"
    )
    solver = SolverResult(name, SolverStatus.CLOSED_FORM, seconds=time.perf_counter() - t0)
    return Design(Parameters(vals), solver, notes)


def xhat_set(o: Options) -> ConvexSet:
    """X̂ of Assumption 3(1) (constrained-redesign paper, Astolfi et al., NOLCOS 2019): the
    spec's set, or the outer set of C_min (see :func:`default_Xhat`).

    :param o: the method's options."""
    return o.Xhat if o.Xhat is not None else default_Xhat(o.cmap, o.eps_min)


def design_params(spec: Spec) -> tuple[dict[str, Any], list[str]]:
    """Every parameter of the report (exact rationals) and notes on what is exact or a bound.

    Constrained-redesign paper (Astolfi et al., NOLCOS 2019): Lyapunov data (Assumption 2,
    eq. (4)-(6)) → X̂ → v_max (eq. (13)) → ε_max (Assumption 3(2), eq. (15)) → δ (Assumption
    3(4)) → γ (eq. (24)) → v_min (eq. (21)) → θ (eq. (22)), and v̆_max, θ̆ of Section 4.

    :param spec: the bound spec. Raises :class:`InfeasibleError` when γ violates (24)."""
    o: Options = spec.options
    notes: list[str] = []
    ld = lyapunov_data(spec)
    P = ld.P
    Pinv = B.qinv(P)
    Xhat = xhat_set(o)
    W = w_sq_max(o.D_lower, o.D_upper)
    vmax = B.v_max_bound(P, ld.rho, ld.mu, o.X, Xhat, W)
    notes.append(f"v_max (13): {vmax.how}")
    if o.eps_max is None:
        need = max(
            B.sup_norm_c_over_Xhat_max(o.cmap, P, Pinv, o.X, vmax.value),
            B.sup_norm_c_over_set(o.cmap, Xhat),
        )
        eps_max = B.round_sig(need, 6, up=True)
        if eps_max <= o.eps_min:
            eps_max = B.round_sig(o.eps_min * fmpq(1000001, 1000000), 8, up=True)
        notes.append(
            "ε_max: the smallest (6 digits, rounded up) for which the safe upper bounds of sup |c| "
            "prove X̂ ⊆ C_max and X̂_max ⊆ C_max (Assumption 3(1)-(2); the true smallest can be lower)"
        )
    else:
        eps_max = o.eps_max
    dsq = B.delta_sq_upper(o.cmap, eps_max)
    notes.append(f"δ: {dsq.how}")
    g_max = B.gamma_bound(P, dsq.value)
    if o.gamma is None:
        gamma = g_max
        if gamma <= 0:
            raise InfeasibleError(
                "no γ > 0 satisfies (24): P is not positive definite (λ_min(P) ≤ 0; for a "
                "P ≻ 0 the bound 1/‖P⁻¹‖_∞ ≤ λ_min(P) is always proved)"
            )
    else:
        gamma = o.gamma
        ok, _ = B.gamma_ok(P, gamma, dsq.value)
        if not ok:
            msg = (
                f"γ = {float(gamma):g} exceeds the bound (24) γ ≤ λ_min(P)/δ²: the largest certified γ is "
                f"{float(g_max):.6g} (λ_min(P) ≥ {float(B.lambda_min_lower(P)):.6g}, δ² ≤ {float(dsq.value):.6g}); "
                # "above it" read as the excess over (24) itself, which may be far smaller
                # (a γ 1e-15 past (24) said "2.1e-06 above it"; random-plant review, 43)
                f"γ is {_over(gamma, g_max, 'that certified γ')}"
            )
            if not o.gamma_uncertified:
                raise InfeasibleError(
                    msg + " (set gamma_uncertified = true to design and simulate with it anyway)"
                )
            notes.append("UNCERTIFIED: " + msg)
    vmin = B.v_min_lower(o.cmap, P, Pinv, o.X, o.eps_min)
    notes.append(f"v_min (21): {vmin.how}")
    theta = B.theta_of(vmax.value, vmin.value, gamma, o.eps_min)
    if not _has_float(theta):  # no float view in the report (a tiny eps_min: review, 1e-300)
        size = f"θ ≈ 10^{int(theta.bit_length() * 0.30103)}"
        if _has_float(int(theta * o.eps_min * o.eps_min)):  # ε_min alone makes it so
            raise SpecError(
                spec.file,
                "method.eps_min",
                f"eps_min = {fmt_exact(o.eps_min)} gives {size} refining steps (eq. (22): "
                "θ ≥ (v_max − v_min)/(γ ε_min²)), beyond the float range of a report; "
                "expected a larger eps_min",
            )
        raise InconclusiveError(
            f"{size} refining steps (eq. (22): θ ≥ (v_max − v_min)/(γ ε_min²) with v_max ≈ "
            f"{float_or_inf(vmax.value):.3g}, γ ≈ {float_or_inf(gamma):.3g}) is beyond the "
            "float range of a report: the spec's numbers are too large"
        )
    if theta == 0:
        notes.append(
            "Remark 2: v_max ≤ v_min, the estimate never leaves X̂ after a jump: θ = 0, no refining needed"
        )
    params: dict[str, Any] = {} if o.L is None else {"L": o.L}
    if ld.lam is not None:
        params["lambda"] = ld.lam
    if ld.lam_other is not None and ld.other_kind == lyap.INFEASIBLE:
        params["lambda_infeasible"] = ld.lam_other
        notes.append(
            "λ: the best certified rate; no P ≻ 0 exists at λ_infeasible "
            f"({lyap.stability_test(spec.system.discrete)}), bracket width ≤ rate_tol = "
            f"{o.rate_tol}"
        )
    elif ld.lam_other is not None:
        notes.append(
            f"λ: the best certified rate to within rate_tol; λ = {float(ld.lam_other):.6g} is "
            "feasible but could not be certified"
        )
    params.update(
        {
            "P": P,
            "rho": ld.rho,
            "mu": ld.mu,
            "gamma": gamma,
            "gamma_max": g_max,
            "lambda_min_P": B.lambda_min_lower(P),
            "delta": sqrt_upper(dsq.value),
            "delta_sq": dsq.value,
            "eps_min": o.eps_min,
            "eps_max": eps_max,
            "v_max": vmax.value,
            "v_min": vmin.value,
            "theta": fmpq(theta),
        }
    )
    if o.X0 is not None and o.Xhat0 is not None:
        vb = v_max_breve(P, ld.rho, ld.mu, o.X0, o.Xhat0, W)
        params["v_max_breve"] = vb
        params["theta_breve"] = fmpq(B.theta_of(min(vb, vmax.value), vmin.value, gamma, o.eps_min))
        notes.append(
            "v̆_max (Section 4) = max V(x̂0 − x0) + μ max|w|²/(1 − ρ) over X0 × X̂0; θ̆ uses min(v_max, v̆_max)"
        )
    return params, notes


def v_max_breve(
    P: np.ndarray, rho: Any, mu: Any, X0: ConvexSet, Xhat0: ConvexSet, w_sq: Any
) -> fmpq:
    """v̆_max = V(e_0,max) + α(d_max)/(1 − ρ), Section 4 of the constrained-redesign paper
    (Astolfi et al., NOLCOS 2019): an upper bound of V along solutions from X0 × X̂0 when
    β = ρv + μ|d|², by induction (ρ v̆ + μ|d|² ≤ v̆).

    :param P, rho, mu: Lyapunov data; :param X0, Xhat0: initial-state / estimate sets;
    :param w_sq: max |w|² over D."""
    v0 = B.max_V_diff(P, X0, Xhat0).value
    return v0 + Q(mu) * Q(w_sq) / (1 - Q(rho))


def _over(value: Any, bound: Any, what: str = "it") -> str:
    """How far ``value`` exceeds ``bound`` (> 0), readable at any size: "3.2× too large", or
    "1e-06 (relative) above <what>" when the ratio would print as 1× (a γ just past (24))."""
    r = float(Q(value) / Q(bound))
    return f"{r:.3g}× too large" if r >= 1.01 else f"{r - 1:.2g} (relative) above {what}"


def _has_float(k: int) -> bool:
    """Whether the integer θ of eq. (22) (constrained-redesign paper) has a float view (the
    report writes one beside every exact value).

    :param k: the integer."""
    try:
        float(k)
    except OverflowError:
        return False
    return True
