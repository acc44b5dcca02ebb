"""Claims of the stubborn observer, each recomputed from the spec and the reported parameters.

Exact: P ≻ 0, U, W diagonal ≻ 0, R ≻ 0, λ in range, X = P K, and LMIs (1)-(3) (continuous) or
(7)-(9) (discrete) of the slides (Astolfi, Alessandri, Zaccarian, "Stubborn observers for
linear and nonlinear systems", WUDS 2017) by exact LDLᵀ (:func:`check_pd`) of the rebuilt
block matrices. What the spec fixes (K in redesign mode, λ or its fraction, the criterion,
the gain bound) is read from the spec and compared exactly with the report's copy.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.claim import Claim, Claims
from obsdesign.certify.exact import Q, qmat
from obsdesign.certify.printing import fmt_exact, fmt_up
from obsdesign.certify.psd import check_pd
from obsdesign.methods.stubborn import lmis
from obsdesign.methods.stubborn.options import Options
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec

PAPER = "stubborn-observer slides (Astolfi, Alessandri, Zaccarian, WUDS 2017)"


def _mat(v: Any, shape: tuple[int, int]) -> np.ndarray:
    M = qmat(np.asarray(v, dtype=object).reshape(shape))
    return M


def _vec(v: Any, n: int) -> np.ndarray:
    arr = np.asarray(v, dtype=object).reshape(-1)
    if arr.size != n:
        raise ValueError(f"expected {n} entries, got {arr.size}")
    return np.array([Q(x) for x in arr], dtype=object)


def lmi_claims(spec: Spec, params: dict[str, Any] | Parameters) -> list[Claim]:
    """Every claim of a linear-mode design (full-stubborn or redesign)."""
    pr = params if isinstance(params, Parameters) else Parameters(params)
    o: Options = spec.options
    s = spec.system
    n, p = s.n, s.p
    A, C = s.A.q, s.C.q
    disc = s.discrete
    c = Claims()
    keys = ["K", "P", "X", "U", "W", "Y", "R", "lambda"]
    vals = {k: pr.exact(k, c) for k in keys}
    if any(v is None for v in vals.values()):
        return c
    P = _mat(vals["P"], (n, n))
    Xr = _mat(vals["X"], (n, p))
    u = _vec(vals["U"], p)
    w = _vec(vals["W"], p)
    Y = _mat(vals["Y"], (p, n))
    R = _mat(vals["R"], (p, p))
    lam = (
        Q(np.asarray(vals["lambda"], dtype=object).reshape(-1)[0])
        if not isinstance(vals["lambda"], fmpq)
        else vals["lambda"]
    )
    if o.K is not None:
        K = np.asarray(o.K, dtype=object)
        c.matches("K", _mat(vals["K"], (n, p)), K, "[method].K")
    else:
        K = _mat(vals["K"], (n, p))
    crit = pr.get("criterion")
    if crit is not None and crit != o.criterion:
        c.failed(
            id="criterion-matches-spec",
            statement="the reported criterion is the one the spec fixes ([method].criterion)",
            reference="spec [method].criterion",
            detail=f"report says {crit!r}, the spec {o.criterion!r}",
        )
    X = P @ K
    eq = all(X[i, j] == Xr[i, j] for i in range(n) for j in range(p))
    c.exact(
        id="gain-relation",
        statement="K = P⁻¹X: the reported X equals P K exactly",
        reference=f"{PAPER}, Theorem (K = P⁻¹X)",
        check="exact matrix product",
        passed=eq,
        detail="X = P K" if eq else "the reported X differs from P K",
        float_ok=eq,
    )
    r = check_pd(P)
    c.exact(
        id="P-positive",
        statement="P ≻ 0",
        reference=f"{PAPER}, Theorem",
        check="exact LDLᵀ",
        passed=r.ok,
        detail=r.detail,
    )
    ok_u = all(x > 0 for x in u)
    c.exact(
        id="U-positive",
        statement="U = diag(u) ≻ 0 (sector multiplier)",
        reference=f"{PAPER}, global sector condition",
        check="exact sign of each entry",
        passed=ok_u,
        detail=f"min u_i = {float(min(u)):.6g}",
    )
    ok_w = all(x > 0 for x in w)
    c.exact(
        id="W-positive",
        statement="W = diag(w) ≻ 0 (σ_i = √(σ̄/w_i))",
        reference=f"{PAPER}, regional sector condition",
        check="exact sign of each entry",
        passed=ok_w,
        detail=f"min w_i = {float(min(w)):.6g}",
    )
    r = check_pd(R)
    c.exact(
        id="R-positive",
        statement="R = Rᵀ ≻ 0",
        reference=f"{PAPER}, adaptive saturation law",
        check="exact LDLᵀ",
        passed=r.ok,
        detail=r.detail,
    )
    in_range = lam > 0 and (lam < 1 or not disc)
    c.exact(
        id="lambda-range",
        statement=f"λ = {fmt_exact(lam)} " + ("∈ (0, 1)" if disc else "> 0"),
        reference=f"{PAPER}, adaptive saturation law",
        check="exact comparison",
        passed=in_range,
        detail="",
    )
    _lambda_choice(c, o, pr, lam, disc)
    eqs = ("(7)", "(8)", "(9)") if disc else ("(1)", "(2)", "(3)")
    M1 = lmis.regional(A, C, P, X, u, R, lam, disc)
    r = check_pd(-M1)
    c.exact(
        id="lmi-regional",
        statement=f"LMI {eqs[0]} holds strictly at λ = {fmt_exact(lam)} with K = P⁻¹X",
        reference=f"{PAPER}, eq. {eqs[0]}",
        check="exact LDLᵀ of −M (all pivots > 0)",
        passed=r.ok,
        detail=r.detail,
    )
    M2 = lmis.global_(A, C, P, X, w, Y, disc)
    r = check_pd(-M2)
    c.exact(
        id="lmi-global",
        statement=f"LMI {eqs[1]} holds strictly",
        reference=f"{PAPER}, eq. {eqs[1]}",
        check="exact LDLᵀ of −M (all pivots > 0)",
        passed=r.ok,
        detail=r.detail,
    )
    bad = []
    for i in range(p):
        ri = check_pd(lmis.sector(P, Y, w, i))
        if not ri.ok:
            bad.append(f"i = {i + 1}: {ri.detail}")
    c.exact(
        id="lmi-sector",
        statement=f"LMI {eqs[2]} holds (strictly) for every output i = 1..{p}",
        reference=f"{PAPER}, eq. {eqs[2]}",
        check="exact LDLᵀ of each [[P, Y_iᵀ], [Y_i, w_i]]",
        passed=not bad,
        detail="; ".join(bad) or f"{p} block(s), all pivots > 0",
    )
    if o.criterion == "l2":
        g = pr.exact("gamma2", c)
        if g is not None:
            M3 = lmis.l2_gain(A, C, s.Bd.q, P, X, Q(g), disc)
            r = check_pd(-M3)
            c.exact(
                id="l2-gain",
                statement=f"the L2 gain from d to e of the Luenberger part (gain K) is ≤ √γ², "
                f"γ² ≤ {fmt_up(g, 8)}",
                reference=f"{PAPER}, criterion 4 (bounded real lemma)",
                check="exact LDLᵀ of the bounded-real-lemma matrix",
                passed=r.ok,
                detail=r.detail,
            )
    return c


def _lambda_choice(c: Claims, o: Options, pr: Parameters, lam: fmpq, disc: bool) -> None:
    """λ is the spec's λ, or fraction·λ_max (continuous) / 1 − fraction·(1 − λ_best) (discrete)."""
    if o.lam is not None:
        c.matches("lambda", lam, o.lam, "[method].lambda")
        return
    lm = pr.exact("lambda_max", c)
    if lm is None:
        return
    lm = Q(lm)
    want = o.fraction * lm if not disc else 1 - o.fraction * (1 - lm)
    ok = want == lam
    rule = "λ = fraction·λ_max" if not disc else "1 − λ = fraction·(1 − λ_best)"
    c.exact(
        id="lambda-choice",
        statement=f"{rule} with fraction = {fmt_exact(o.fraction)} ([method].lambda_fraction)",
        reference=f"{PAPER}, optimized parameter selection",
        check="exact equality",
        passed=ok,
        detail="" if ok else f"expected λ = {fmt_exact(want)}",
    )
