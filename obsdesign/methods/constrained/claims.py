"""The certificate of the constrained redesign (paper 000): every claim is rebuilt from the
spec and the reported parameters, in exact arithmetic (or outward-rounded intervals)."""

from __future__ import annotations

from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.claim import Claim, exact_claim
from obsdesign.certify.exact import Q, dyadic, to_float
from obsdesign.certify.interval import sqrt_upper
from obsdesign.certify.psd import check_pd, check_psd
from obsdesign.methods import lyapunov
from obsdesign.methods.constrained import bounds as B
from obsdesign.methods.constrained.cmap import ConstraintMap
from obsdesign.methods.constrained.design import v_max_breve, xhat_set
from obsdesign.methods.constrained.lyap import error_input, iss_matrix, w_sq_max
from obsdesign.methods.constrained.options import Options
from obsdesign.params import Parameters
from obsdesign.sets import Box, Ellipsoid, Polytope, vertices_exact
from obsdesign.sets.base import ConvexSet
from obsdesign.spec.models import Spec

REF = "constrained-redesign paper (000)"


def _q(params: Parameters, k: str) -> Any:
    v = params[k]
    if isinstance(v, fmpq) or (isinstance(v, np.ndarray) and v.dtype == object):
        return v
    arr = np.asarray(v, dtype=float)
    return Q(float(arr)) if arr.ndim == 0 else dyadic(arr, 60)


def _c(
    id: str, stmt: str, ref: str, check: str, ok: bool, detail: str, float_ok: bool | None = None
) -> Claim:
    return exact_claim(id, stmt, f"{ref}, {REF}", check, 0, ok, detail, float_ok)


REQUIRED = (
    "P",
    "rho",
    "mu",
    "gamma",
    "delta_sq",
    "eps_min",
    "eps_max",
    "v_max",
    "v_min",
    "theta",
)


def certify(spec: Spec, params: Parameters) -> list[Claim]:
    """All claims of item 7 of the issue (decay LMI, P ≻ 0, (5), inclusions, δ, (24), v_max,
    v_min, θ), each recomputed from spec + parameters."""
    o: Options = spec.options
    missing = [k for k in REQUIRED if k not in params]
    if missing:
        return [
            _c(
                "parameters-present",
                "the report gives every parameter",
                "report",
                "presence",
                False,
                f"missing: {', '.join(missing)}",
            )
        ]
    if o.L is not None and "L" not in params:
        return [
            _c(
                "parameters-present",
                "the report gives L",
                "report",
                "presence",
                False,
                "missing: L",
            )
        ]
    L = _q(params, "L") if o.L is not None else None
    P, rho, mu = _q(params, "P"), Q(_q(params, "rho")), Q(_q(params, "mu"))
    gamma, dsq = Q(_q(params, "gamma")), Q(_q(params, "delta_sq"))
    eps_min, eps_max = Q(_q(params, "eps_min")), Q(_q(params, "eps_max"))
    v_max, v_min, theta = Q(_q(params, "v_max")), Q(_q(params, "v_min")), Q(_q(params, "theta"))
    out: list[Claim] = []
    same = np.array_equal(np.asarray(L), np.asarray(o.L))
    out.append(
        _c(
            "L-matches-spec",
            "the gain L is the spec's",
            "spec [method].L",
            "exact equality",
            same,
            "" if same else "the report's L differs from the spec's",
        )
    )
    if o.P is not None:
        same = np.array_equal(np.asarray(P), np.asarray(o.P)) and rho == o.rho and mu == o.mu
        out.append(
            _c(
                "lyapunov-data-matches-spec",
                "P, ρ, μ are the spec's",
                "spec [method]",
                "exact equality",
                same,
                "" if same else "P, rho or mu differ from the spec",
            )
        )
    if (
        eps_min != o.eps_min
        or (o.eps_max is not None and eps_max != o.eps_max)
        or (o.gamma is not None and gamma != o.gamma)
    ):
        out.append(
            _c(
                "values-match-spec",
                "ε_min, ε_max, γ are the spec's where given",
                "spec [method]",
                "exact equality",
                False,
                "a reported value differs from the spec",
            )
        )
    r = check_pd(P, o.margin)
    out.append(_c("P-positive-definite", "P ≻ 0", "eq. (4)", "exact LDLᵀ over Q", r.ok, r.detail))
    if o.model is not None and o.model.nonlinear:
        out.append(_iss_sampled(spec, params, P, rho, mu, v_max))
    else:
        out += _linear_claims(spec, params, L, P, rho, mu)
    out += _convexity(o.cmap)
    out.append(
        _c(
            "eps-order",
            f"ε_max = {float(eps_max):.6g} > ε_min = {float(eps_min):.6g} > 0",
            "Assumption 3",
            "exact comparison",
            eps_max > eps_min > 0,
            "",
        )
    )
    Xhat = xhat_set(o)
    out += _inclusions(o, Xhat, eps_min, eps_max)
    Pinv = B.qinv(P)
    W = w_sq_max(o.D_lower, o.D_upper)
    vb = B.v_max_bound(P, rho, mu, o.X, Xhat, W)
    out.append(
        _c(
            "v_max-bound",
            f"v_max = {float(v_max):.8g} ≥ max β(V(x̂ − x), d) over X × X̂ × D",
            "eq. (13)",
            f"recomputed: {float(vb.value):.8g} ({vb.how})",
            v_max >= vb.value,
            "",
        )
    )
    sup = B.sup_norm_c_over_Xhat_max(o.cmap, P, Pinv, o.X, v_max)
    out.append(
        _c(
            "Xhat_max-in-Cmax",
            "X̂_max ⊆ C_max",
            "Assumption 3(2), eq. (15)",
            "sup |c| over X̂_max bounded by per-face support functions (outward rounding)",
            sup <= eps_max,
            f"sup |c| ≤ {float(sup):.6g} vs ε_max = {float(eps_max):.6g}",
        )
    )
    ok, det = B.delta_sq_valid(o.cmap, eps_max, dsq)
    if "delta" in params:
        ok = ok and Q(_q(params, "delta")) ** 2 >= dsq
    out.append(
        _c(
            "delta-bound",
            f"sup over C_max of |dc/dx| ≤ δ, δ² = {float(dsq):.6g}",
            "Assumption 3(4)",
            "exact",
            ok,
            det,
        )
    )
    ok, det = B.gamma_ok(P, gamma, dsq)
    out.append(
        _c(
            "gamma-bound",
            f"γ = {float(gamma):.6g} ≤ λ_min(P)/δ²",
            "Theorem 1, eq. (24)",
            "exact LDLᵀ of P − γδ²I",
            ok,
            det + ("" if ok else f"; largest certified γ ≈ {float(B.gamma_bound(P, dsq)):.6g}"),
            float_ok=False,
        )
    )
    ok = B.v_min_condition(o.cmap, P, Pinv, o.X, eps_min, v_min) and v_min >= 0
    out.append(
        _c(
            "v_min-bound",
            f"V(x̂ − x) ≤ v_min = {float(v_min):.8g}, x ∈ X ⟹ x̂ ∈ C_min",
            "eq. (21)",
            "per-face support functions, exact/outward rounding",
            ok,
            "",
        )
    )
    need = max(v_max - v_min, fmpq(0)) / (gamma * eps_min**2)
    out.append(
        _c(
            "theta-covers",
            f"θ = {int(theta)} ≥ (v_max − v_min)/(γ ε_min²) = {float(need):.6g}",
            "eq. (22)",
            "exact rational comparison",
            theta >= need and theta == int(theta),
            "",
        )
    )
    if "v_max_breve" in params and o.X0 is not None and o.Xhat0 is not None:
        vbr = Q(_q(params, "v_max_breve"))
        ref = v_max_breve(P, rho, mu, o.X0, o.Xhat0, W)
        tb = Q(_q(params, "theta_breve"))
        need_b = max(min(vbr, v_max) - v_min, fmpq(0)) / (gamma * eps_min**2)
        out.append(
            _c(
                "v_max_breve",
                f"v̆_max = {float(vbr):.6g} bounds V along solutions from X0 × X̂0; θ̆ = {int(tb)}",
                "Section 4",
                "exact rational comparison",
                vbr >= ref and tb >= need_b and rho < 1,
                "",
            )
        )
    return out


def _linear_claims(
    spec: Spec, params: Parameters, L: Any, P: Any, rho: Any, mu: Any
) -> list[Claim]:
    """Decay LMI and inequality (5) for the linear error dynamics, exactly."""
    o: Options = spec.options
    s = spec.system
    out: list[Claim] = []
    Acl = s.A.q - L @ s.C.q
    if "lambda" in params:
        lam = Q(_q(params, "lambda"))
        M = lyapunov.decay_matrix(s.A.q, s.C.q, L, P, lam, True)
        r = check_pd(M, o.margin)
        out.append(
            _c(
                "decay-lmi",
                f"(A−LC)ᵀP(A−LC) ⪯ λ²P with λ = {float(lam):.6g}",
                "Section 5",
                "exact LDLᵀ over Q of the rebuilt matrix",
                r.ok,
                r.detail,
            )
        )
        if o.rho is None and rho != lam * lam:
            out.append(
                _c(
                    "rho-is-lambda-squared",
                    "ρ = λ²",
                    "Remark 1",
                    "exact equality",
                    False,
                    f"ρ = {rho}",
                )
            )
    Bw = error_input(s.A.q, s.Bd.q, s.Dn.q, L)
    r = check_psd(iss_matrix(Acl, Bw, P, rho, mu))
    ok = r.ok and rho < 1
    out.append(
        _c(
            "iss-bound",
            f"V(e⁺) ≤ ρV(e) + μ|w|² with ρ = {float(rho):.6g}, μ = {float(mu):.6g}",
            "Assumption 2, eq. (5)-(6)",
            "exact LDLᵀ over Q (linear error dynamics)",
            ok,
            r.detail + ("" if rho < 1 else "; ρ must be < 1"),
        )
    )
    return out


def _iss_sampled(spec: Spec, params: Parameters, P: Any, rho: Any, mu: Any, v_max: Any) -> Claim:
    """Inequality (5) for expression-defined f, h, F: sampled (numerical claim)."""
    from obsdesign.certify.claim import numerical_claim
    from obsdesign.methods.constrained.nonlinear import check_iss_samples
    from obsdesign.methods.constrained.observer import LinearF

    o: Options = spec.options
    s = spec.system
    F = o.model.F
    if F is None:
        F = LinearF(s.A.f, s.B.f, s.C.f, s.D.f, np.asarray(to_float(o.L), dtype=float))
    Pf = np.asarray(to_float(P), dtype=float)
    ok, _, det = check_iss_samples(spec, o.model, F, Pf, float(rho), float(mu), float(v_max))
    ok = ok and rho < 1
    return numerical_claim(
        "iss-bound",
        f"V(Δ(x, e, u, w)) ≤ ρV(e) + μ|w|² with ρ = {float(rho):.6g}, μ = {float(mu):.6g}",
        f"Assumption 2, eq. (5)-(6), {REF}",
        "sampled in float64 (expression-defined f, h, F): not a proof",
        0,
        ok,
        det,
    )


def _convexity(cm: ConstraintMap) -> list[Claim]:
    if cm.affine:
        return [
            _c(
                "c-convex",
                "each c_i = max(g_iᵀx − h_i, 0)² is convex",
                "Assumption 3(3), Lemma 2",
                "by construction (affine φ_i)",
                True,
                f"{cm.n_c} components",
            )
        ]
    r = check_pd(cm.Q_q)
    return [
        _c(
            "c-convex",
            "c = max(xᵀQx/r − 1, 0)² is convex (Q ≻ 0)",
            "Assumption 3(3), Lemma 1",
            "exact LDLᵀ of Q",
            r.ok,
            r.detail,
        )
    ]


def _inclusions(o: Options, Xhat: ConvexSet, eps_min: fmpq, eps_max: fmpq) -> list[Claim]:
    """Assumption 3(1): X ⊂ C_0 ⊂ C_min ⊂ X̂ ⊂ C_max."""
    cm = o.cmap
    out = []
    b = B.max_phi_over(cm, o.X)
    worst = max(b)
    out.append(
        _c(
            "X-in-C0",
            "X ⊂ C_0 = {c = 0}",
            "Assumption 3(1)",
            "exact: φ_i at the vertices of X",
            worst <= 0,
            f"max φ over X = {float(worst):.6g}",
        )
    )
    ok, det = _cmin_in_xhat(cm, eps_min, Xhat)
    out.append(
        _c(
            "Cmin-in-Xhat",
            "C_min ⊂ X̂",
            "Assumption 3(1)",
            "exact: the outer set {φ_i ≤ t}, t ≥ √ε_min, lies in X̂",
            ok,
            det,
        )
    )
    sup = B.sup_norm_c_over_set(cm, Xhat)
    out.append(
        _c(
            "Xhat-in-Cmax",
            "X̂ ⊂ C_max",
            "Assumption 3(1)",
            "sup |c| over X̂ (vertices / support function)",
            sup <= eps_max,
            f"sup |c| over X̂ ≤ {float(sup):.6g}",
        )
    )
    return out


def _cmin_in_xhat(cm: ConstraintMap, eps_min: fmpq, Xhat: ConvexSet) -> tuple[bool, str]:
    from mpmath import iv

    from obsdesign.certify.interval import upper

    t = sqrt_upper(eps_min)
    if cm.kind == "box" and isinstance(Xhat, (Box, Polytope)):
        # the outer set of C_min is the box [r̲ − t, r̄ + t]: compare face by face (closed form)
        n = cm.dim
        lo = np.array([-cm.h_q[2 * i] - t for i in range(n)], dtype=object)
        hi = np.array([cm.h_q[2 * i + 1] + t for i in range(n)], dtype=object)
        G, g = Xhat.h_form_q()
        worst = max(
            sum((max(G[j, i] * lo[i], G[j, i] * hi[i]) for i in range(n)), fmpq(0)) - g[j]
            for j in range(G.shape[0])
        )
        return worst <= 0, f"max over the outer box of C_min of (H x − k) = {float(worst):.6g}"
    if cm.affine:
        V, bounded = vertices_exact(cm.G_q, np.array([h + t for h in cm.h_q], dtype=object))
        if not bounded or len(V) == 0:
            return False, "the outer set of C_min is unbounded"
        bad = [v for v in V if not _contains_q(Xhat, v)]
        return not bad, f"{len(V)} vertices checked" + (f"; {len(bad)} outside X̂" if bad else "")
    # ellipsoid c: outer set {xᵀQx ≤ r(1 + t)}
    R = Q(cm.r_q) * (1 + t)
    if isinstance(Xhat, Ellipsoid):
        if any(c != 0 for c in Xhat.center_q):
            return False, "X̂ ellipsoid must be centred at 0 for this check"
        r = check_psd(cm.Q_q * (1 / R) - Xhat.E_q)
        return r.ok, f"E_X̂ ⪯ Q/(r(1+√ε_min)): {r.detail}"
    G, g = Xhat.h_form_q()  # type: ignore[attr-defined]
    Qinv = B.qinv(cm.Q_q)
    for j in range(G.shape[0]):
        s = upper(lambda R, w: iv.sqrt(R * w), R, B.quad(Qinv, G[j]))
        if s > g[j]:
            return False, f"face {j}: support {float(s):.6g} > {float(g[j]):.6g}"
    return True, "support function of the outer ellipsoid below every face of X̂"


def _contains_q(S: ConvexSet, v: np.ndarray) -> bool:
    if isinstance(S, Box):
        return all(lo <= x <= hi for lo, x, hi in zip(S.lower_q, v, S.upper_q, strict=True))
    if isinstance(S, Polytope):
        G, g = S.h_form_q()
        return all(B.quad_lin(G[j], v) <= g[j] for j in range(G.shape[0]))
    assert isinstance(S, Ellipsoid)
    return B.quad(S.E_q, v - S.center_q) <= 1
