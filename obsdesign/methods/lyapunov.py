"""Lyapunov-decay design of a linear observer (method key ``lyapunov``).

Observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) (discrete) or its continuous analogue; the error
e = x̂ − x obeys e⁺ = (A − LC) e + L Dn v. The method finds P ≻ 0 with

- discrete:   (A − LC)ᵀ P (A − LC) ⪯ λ² P          (decay V(e⁺) ≤ λ² V(e), V = eᵀPe)
- continuous: (A − LC)ᵀ P + P (A − LC) ⪯ −2α P     (V̇ ≤ −2α V)

either for a given gain L (P from a Lyapunov equation: no SDP needed) or designing L through
the LMI in (P, X = P L). The best rate (smallest λ / largest α) is found by bisection, each
candidate decided by the exact check. Optionally the ISS gain μ of output noise:
V(e⁺) ≤ λ² V(e) + μ |v|² (discrete), V̇ ≤ −2α V + μ |v|² (continuous).

This is the quadratic Lyapunov function (4)-(7) with β(v, d) = ρ v + μ|d|², ρ = λ², of the
constrained-redesign paper (000, Section 5), where P solves (A−LC)ᵀP(A−LC) − λ²P = −I.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.claim import Claim, exact_claim
from obsdesign.certify.exact import Q, dyadic, qeye, symmetrize
from obsdesign.certify.psd import check_pd
from obsdesign.errors import InconclusiveError, InfeasibleError, SolverError
from obsdesign.methods.base import Design, Method, Progress
from obsdesign.params import Parameters, exact_param
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

REF = "Lyapunov decay LMI; eq. (4)-(7) and Section 5, constrained-redesign paper (000)"
BITS = 40  # dyadic rounding of P and L (relative to their largest entry)


@dataclass
class Options:
    """``[method]`` of ``lyapunov``."""

    L: Any | None  # exact n×p gain, or None to design it
    rate: Any | None  # exact λ (discrete) or α (continuous) to certify; None: the best found
    rate_tol: Any  # bisection tolerance on the rate
    rate_cap: Any  # continuous, designed L: the largest α tried
    iss_gain: bool
    margin: Any  # δ_check: certify the LMI with M ⪰ margin·I


class Lyapunov(Method):
    key = "lyapunov"
    title = "Lyapunov-decay linear observer"
    paper = "000 (Section 5) / standard quadratic Lyapunov LMI"

    # -- spec -------------------------------------------------------------------------------
    def parse_options(self, table: Table, spec: Spec) -> Options:
        s = spec.system
        L = None
        if table.has("L"):
            L = table.matrix("L", rows=s.n, cols=s.p, vector_as="column").q
        if s.discrete:
            rate = table.scalar(
                "lambda", default=None, min=0, max=1, strict_min=True, strict_max=True
            )
            if table.has("alpha"):
                raise table.error("alpha", "is for continuous time; use lambda in discrete time")
        else:
            rate = table.scalar("alpha", default=None, min=0, strict_min=True)
            if table.has("lambda"):
                raise table.error("lambda", "is for discrete time; use alpha in continuous time")
        tol = table.scalar("rate_tol", default=fmpq(1, 10000), min=0, strict_min=True)
        cap = table.scalar("rate_cap", default=fmpq(10), min=0, strict_min=True)
        iss = table.bool("iss_gain", default=False)
        margin = table.scalar("margin", default=fmpq(1, 10**9), min=0)
        table.done()
        return Options(
            L,
            None if rate is None else rate.q,
            tol.q,
            cap.q,
            iss,
            margin.q,
        )

    # -- design -----------------------------------------------------------------------------
    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        o: Options = spec.options
        s = spec.system
        notes: list[str] = []
        solver: dict[str, Any] = {"name": "scipy Lyapunov equation", "status": "optimal"}
        if o.L is None:
            Lf, solver = design_gain(spec, progress)
            L = dyadic(Lf, BITS)
            notes.append("L designed by the LMI in (P, X = P L); certified with the rounded L")
        else:
            L = o.L
        Acl = s.A.f - np.asarray(L, dtype=float) @ s.C.f
        eig = np.linalg.eigvals(Acl)
        params = Parameters({"L": L})
        if s.discrete:
            rho = float(np.max(np.abs(eig)))
            params["rho"] = rho
            if rho >= 1 and o.rate is None:
                raise InfeasibleError(
                    f"A − LC is not Schur: spectral radius {rho:.6g} >= 1"
                    + ("" if o.L is None else " (the given L does not stabilize the error)")
                )
        else:
            rho = float(np.max(eig.real))
            params["max_real_eig"] = rho
            if rho >= 0 and o.rate is None:
                raise InfeasibleError(f"A − LC is not Hurwitz: largest real part {rho:.6g} >= 0")
        best, P_best = best_rate(s.A.q, s.C.q, L, s.discrete, o, rho)
        if o.rate is None:
            rate, P = best, P_best
        else:
            rate = o.rate
            P = certified_P(s.A.q, s.C.q, L, s.discrete, rate, o.margin)
            if P is None:
                what = "λ" if s.discrete else "α"
                lim = f"spectral radius {rho:.6g}" if s.discrete else f"−max Re eig = {-rho:.6g}"
                if (s.discrete and float(rate) <= rho) or (not s.discrete and float(rate) >= -rho):
                    raise InfeasibleError(
                        f"no P ≻ 0 gives decay rate {what} = {float(rate):g}: A − LC has {lim}"
                    )
                raise InconclusiveError(
                    f"decay rate {what} = {float(rate):g} is feasible in floats but the exact "
                    "check failed (too close to the limit)"
                )
        name = "lambda" if s.discrete else "alpha"
        params["P"] = P
        params[name] = rate
        params["P_best"] = P_best
        params[f"{name}_best"] = best
        if o.iss_gain:
            params["mu"] = iss_gain(s, L, P, rate)
        notes.append(
            f"best rate {name} = {float(best):.6g} (bisection tolerance {float(o.rate_tol):g}); "
            + (f"infimum {rho:.6g}" if s.discrete else f"supremum {-rho:.6g}")
        )
        return Design(params, solver, notes)

    # -- certificate ------------------------------------------------------------------------
    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        s = spec.system
        o: Options = spec.options
        name = "lambda" if s.discrete else "alpha"
        claims: list[Claim] = []
        L = exact_param(params, "L", claims)
        P = exact_param(params, "P", claims)
        rate = exact_param(params, name, claims)
        if L is None or P is None or rate is None:
            return claims
        if o.L is not None and not np.array_equal(np.asarray(L), np.asarray(o.L)):
            claims.append(
                exact_claim(
                    "L-matches-spec",
                    "the reported gain L is the L given in the spec",
                    "spec [method].L",
                    "exact equality",
                    0,
                    False,
                    "the report's L differs from the spec's L",
                )
            )
        if o.rate is not None and Q(rate) != o.rate:
            claims.append(
                exact_claim(
                    f"{name}-matches-spec",
                    f"the certified rate is the {name} asked for in the spec",
                    f"spec [method].{name}",
                    "exact equality",
                    0,
                    False,
                    f"report has {name} = {rate}, spec asks {o.rate}",
                )
            )
        claims.append(_pd_claim("P-positive-definite", "P ≻ 0", P, o.margin))
        claims.append(_decay_claim(s, L, P, rate, o.margin, ""))
        if "P_best" in params and f"{name}_best" in params:
            Pb = exact_param(params, "P_best", claims)
            rb = exact_param(params, f"{name}_best", claims)
            if Pb is not None and rb is not None:
                claims.append(_pd_claim("P_best-positive-definite", "P_best ≻ 0", Pb, o.margin))
                claims.append(_decay_claim(s, L, Pb, rb, o.margin, "_best"))
        if o.iss_gain:
            mu = exact_param(params, "mu", claims)
            if mu is not None:
                claims.append(_iss_claim(s, L, P, rate, mu))
        return claims

    # -- simulation -------------------------------------------------------------------------
    def simulate(self, spec: Spec, params: Parameters, **kwargs: Any) -> Any:
        from obsdesign.simulate.linear import simulate_linear_observer

        return simulate_linear_observer(spec, params.float("L"))

    def summary(self, params: Parameters) -> str:
        name = "lambda" if "lambda" in params else "alpha"
        out = f"{name} = {params.float(name):.6g}, best {params.float(name + '_best'):.6g}"
        if "mu" in params:
            out += f", mu = {params.float('mu'):.4g}"
        return out

    def template(self) -> str:
        return TEMPLATE

    def options_schema(self) -> dict[str, Any]:
        from obsdesign.spec.schema import MAT as mat
        from obsdesign.spec.schema import NUM as num

        return {
            "type": "object",
            "required": ["key"],
            "additionalProperties": False,
            "properties": {
                "key": {"const": self.key},
                "L": mat,
                "lambda": {**num, "exclusiveMinimum": 0, "exclusiveMaximum": 1},
                "alpha": {**num, "exclusiveMinimum": 0},
                "rate_tol": {**num, "exclusiveMinimum": 0},
                "rate_cap": {**num, "exclusiveMinimum": 0},
                "iss_gain": {"type": "boolean"},
                "margin": {**num, "minimum": 0},
            },
        }


# -- exact formulas (rebuilt by the certificate; never taken from a solver) ----------------
def decay_matrix(A: Any, C: Any, L: Any, P: Any, rate: Any, discrete: bool) -> np.ndarray:
    """The matrix that must be ⪰ 0 for decay, exactly.

    Discrete: λ² P − (A−LC)ᵀ P (A−LC). Continuous: −((A−LC)ᵀ P + P (A−LC) + 2α P).
    """
    Acl = A - L @ C
    r = Q(rate)
    if discrete:
        return symmetrize(P * (r * r) - Acl.T @ P @ Acl)
    return symmetrize(-(Acl.T @ P + P @ Acl + P * (2 * r)))


def iss_matrix(A: Any, C: Any, L: Any, Dn: Any, P: Any, rate: Any, mu: Any, discrete: bool) -> Any:
    """Block matrix ⪰ 0 ⟺ the ISS inequality with gain μ (noise v enters as L Dn v).

    Discrete: [[λ²P − AclᵀPAcl, −AclᵀPLd], [−LdᵀPAcl, μI − LdᵀPLd]].
    Continuous: [[−(AclᵀP + PAcl + 2αP), −PLd], [−LdᵀP, μI]].
    """
    Acl = A - L @ C
    Ld = L @ Dn
    k = Ld.shape[1]
    S = decay_matrix(A, C, L, P, rate, discrete)
    if discrete:
        off = -(Acl.T @ P @ Ld)
        low = qeye(k) * Q(mu) - Ld.T @ P @ Ld
    else:
        off = -(P @ Ld)
        low = qeye(k) * Q(mu)
    return symmetrize(np.block([[S, off], [off.T, low]]))


def _pd_claim(id: str, what: str, P: Any, margin: Any) -> Claim:
    r = check_pd(P, margin)
    return exact_claim(id, what, REF, "exact LDLᵀ over Q", margin, r.ok, r.detail, None)


def _decay_claim(s: Any, L: Any, P: Any, rate: Any, margin: Any, suffix: str) -> Claim:
    M = decay_matrix(s.A.q, s.C.q, L, P, rate, s.discrete)
    r = check_pd(M, margin)
    fl = bool(np.linalg.eigvalsh(np.asarray(M, dtype=float)).min() > float(margin))
    if s.discrete:
        stmt = f"(A−LC)ᵀP{suffix}(A−LC) ⪯ λ{suffix}²·P{suffix} with λ{suffix} = {rate}"
    else:
        stmt = f"(A−LC)ᵀP{suffix} + P{suffix}(A−LC) ⪯ −2α{suffix}·P{suffix} with α{suffix} = {rate}"
    return exact_claim(
        f"decay-lmi{suffix}",
        stmt,
        REF,
        "exact LDLᵀ over Q of the rebuilt matrix",
        margin,
        r.ok,
        r.detail,
        fl,
    )


def _iss_claim(s: Any, L: Any, P: Any, rate: Any, mu: Any) -> Claim:
    M = iss_matrix(s.A.q, s.C.q, L, s.Dn.q, P, rate, mu, s.discrete)
    r = check_pd(M, 0)
    what = "V(e⁺) ≤ λ²V(e) + μ|v|²" if s.discrete else "V̇ ≤ −2αV + μ|v|²"
    return exact_claim(
        "iss-gain",
        f"{what} with μ = {float(Q(mu)):.6g}",
        REF,
        "exact LDLᵀ over Q",
        0,
        r.ok,
        r.detail,
    )


# -- numerical parts -----------------------------------------------------------------------
def lyapunov_P(
    A: np.ndarray, C: np.ndarray, L: np.ndarray, rate: float, discrete: bool
) -> np.ndarray:
    """P solving (A−LC)ᵀP(A−LC) − λ²P = −I (discrete) or
    (A−LC+αI)ᵀP + P(A−LC+αI) = −I (continuous), in floats."""
    from scipy.linalg import solve_continuous_lyapunov, solve_discrete_lyapunov

    Acl = A - L @ C
    n = A.shape[0]
    if discrete:
        P = solve_discrete_lyapunov((Acl / rate).T, np.eye(n) / rate**2)
    else:
        P = solve_continuous_lyapunov((Acl + rate * np.eye(n)).T, -np.eye(n))
    return (P + P.T) / 2


def certified_P(A: Any, C: Any, L: Any, discrete: bool, rate: Any, margin: Any) -> Any:
    """A rational P ≻ 0 that passes the exact decay check at ``rate``, or None."""
    Af, Cf, Lf = (np.asarray(x, dtype=float) for x in (A, C, L))
    try:
        Pf = lyapunov_P(Af, Cf, Lf, float(Q(rate)), discrete)
    except (np.linalg.LinAlgError, ValueError):
        return None
    if not np.all(np.isfinite(Pf)):
        return None
    P = symmetrize(dyadic(Pf, BITS))
    if not check_pd(P, margin):
        return None
    if not check_pd(decay_matrix(A, C, L, P, rate, discrete), margin):
        return None
    return P


def best_rate(A: Any, C: Any, L: Any, discrete: bool, o: Options, limit: float) -> tuple[Any, Any]:
    """Bisection for the best certified rate: smallest λ (discrete) / largest α (continuous).

    The limit (spectral radius / −max Re eig of A−LC) is the infimum / supremum; every
    candidate is a decimal on the tolerance grid and is decided by the exact check.
    """
    tol = Q(o.rate_tol)
    digits = max(0, -int(np.floor(np.log10(float(tol))))) + 1
    grid = fmpq(1, 10**digits)

    def snap(x: float, up: bool) -> fmpq:
        q = Q(x) / grid
        return (fmpq(int(q.ceil())) if up else fmpq(int(q.floor()))) * grid

    if discrete:
        lo, hi = snap(max(limit, 0.0), False), fmpq(1) - grid
        P = certified_P(A, C, L, True, hi, o.margin)
        if P is None:
            raise InfeasibleError(f"no decay rate below 1 certifies (spectral radius {limit:.6g})")
        while hi - lo > tol:
            mid = snap(float((lo + hi) / 2), True)
            if mid >= hi:
                break
            Pm = certified_P(A, C, L, True, mid, o.margin)
            if Pm is None:
                lo = mid
            else:
                hi, P = mid, Pm
        return hi, P
    sup = -limit
    lo, hi = grid, snap(sup, False)
    P = certified_P(A, C, L, False, lo, o.margin)
    if P is None:
        raise InfeasibleError(f"no decay rate α > 0 certifies (−max Re eig = {sup:.6g})")
    while hi - lo > tol:
        mid = snap(float((lo + hi) / 2), False)
        if mid <= lo:
            break
        Pm = certified_P(A, C, L, False, mid, o.margin)
        if Pm is None:
            hi = mid
        else:
            lo, P = mid, Pm
    return lo, P


def iss_gain(s: Any, L: Any, P: Any, rate: Any) -> fmpq:
    """Smallest μ (rounded up, then certified) with the ISS inequality; Schur complement
    μ ≥ λ_max(LdᵀPLd + LdᵀPAcl S⁻¹ AclᵀPLd) (discrete) or λ_max(LdᵀP S⁻¹ P Ld) (continuous)."""
    A, C, Dn = s.A.f, s.C.f, s.Dn.f
    Lf, Pf, _r = np.asarray(L, float), np.asarray(P, float), float(Q(rate))
    Acl = A - Lf @ C
    Ld = Lf @ Dn
    S = np.asarray(decay_matrix(s.A.q, s.C.q, L, P, rate, s.discrete), dtype=float)
    if s.discrete:
        G = Ld.T @ Pf @ Ld + Ld.T @ Pf @ Acl @ np.linalg.solve(S, Acl.T @ Pf @ Ld)
    else:
        G = Ld.T @ Pf @ np.linalg.solve(S, Pf @ Ld)
    mu_f = float(np.linalg.eigvalsh((G + G.T) / 2).max()) if G.size else 0.0
    mu = dyadic(mu_f * (1 + 1e-9) + 1e-12, 30)
    for _ in range(60):
        if check_pd(iss_matrix(s.A.q, s.C.q, L, s.Dn.q, P, rate, mu, s.discrete)):
            return mu
        mu = mu * fmpq(11, 10) + fmpq(1, 10**9)
    raise InconclusiveError("could not certify an ISS gain μ for the noise input")


def design_gain(spec: Spec, progress: Progress | None) -> tuple[np.ndarray, dict[str, Any]]:
    """Design L through the LMI in (P, X = P L), bisecting on the rate.

    Discrete: [[λ²P, (PA − XC)ᵀ], [PA − XC, P]] ⪰ δ I (Schur complement of the decay LMI).
    Continuous: −(AᵀP + PA − CᵀXᵀ − XC + 2αP) ⪰ δ I. Normalization P ⪰ I.
    """
    import cvxpy as cp

    from obsdesign.lmi import solve, sym

    s = spec.system
    o: Options = spec.options
    A, C = s.A.f, s.C.f
    n, p = s.n, s.p
    P = cp.Variable((n, n), symmetric=True)
    X = cp.Variable((n, p))
    r = cp.Parameter(nonneg=True)
    delta = 1e-6
    if s.discrete:
        PAc = P @ A - X @ C
        M = cp.bmat([[r * P, PAc.T], [PAc, P]])
    else:
        M = -(A.T @ P + P @ A - C.T @ X.T - X @ C + 2 * r * P)
    t = cp.Variable()
    # I ⪯ P ⪯ t·I, minimal t: a well-conditioned P keeps the gain moderate and the problem
    # bounded (minimizing ‖X‖ alone leaves solvers "optimal_inaccurate")
    cons = [P >> np.eye(n), P << t * np.eye(n), sym(M) >> delta * np.eye(M.shape[0])]
    prob = cp.Problem(cp.Minimize(t), cons)
    tol = float(o.rate_tol)
    best: tuple[np.ndarray, str, float] | None = None
    total = 0.0

    def feasible(rate: float) -> bool:
        nonlocal best, total
        r.value = rate**2 if s.discrete else rate
        try:
            res = solve(prob, ("CLARABEL",))  # SCS is slow and loose at the boundary
        except SolverError:
            return False
        total += res.seconds
        if not res.optimal:
            return False
        Lc = np.linalg.solve(P.value, X.value)
        eig = np.linalg.eigvals(A - Lc @ C)
        # the decay LMI at `rate` implies this; a solver answer that breaks it is not trusted
        if s.discrete:
            broken = np.abs(eig).max() > rate * (1 + 1e-6)
        else:
            broken = -eig.real.max() < rate * (1 - 1e-6)
        if broken:
            return False
        best = (Lc, res.solver, rate)
        return True

    if o.rate is not None:
        # design with some slack (2 %) so the rounded gain certifies robustly at the asked rate
        slack = float(o.rate) * (0.98 if s.discrete else 1.02)
        if not feasible(slack) and not feasible(float(o.rate)):
            raise InfeasibleError(
                f"the LMI for L is infeasible at rate {float(o.rate):g}"
                + (" ((C, A) not detectable?)" if s.discrete else "")
            )
    elif s.discrete:
        lo, hi = 0.0, 1.0 - tol
        if not feasible(hi):
            raise InfeasibleError("no gain L makes A − LC Schur: (C, A) is not detectable")
        while hi - lo > tol:
            mid = (lo + hi) / 2
            if progress:
                progress(f"bisection λ = {mid:.6f}")
            if feasible(mid):
                hi = mid
            else:
                lo = mid
        feasible(hi)
    else:
        lo, hi = 0.0, float(o.rate_cap)
        if not feasible(tol):
            raise InfeasibleError("no gain L makes A − LC Hurwitz: (C, A) is not detectable")
        lo = tol
        if feasible(hi):
            lo = hi
        while hi - lo > tol:
            mid = (lo + hi) / 2
            if progress:
                progress(f"bisection α = {mid:.6f}")
            if feasible(mid):
                lo = mid
            else:
                hi = mid
        feasible(lo)
    assert best is not None
    Lf, name, _ = best
    return Lf, {"name": name, "status": "optimal", "seconds": round(total, 4)}


METHOD = Lyapunov()

TEMPLATE = """\
# obsdesign spec: Lyapunov-decay linear observer (method "lyapunov").
# Observer: x̂⁺ = A x̂ + B u + L (y − C x̂ − D u); certify (A−LC)ᵀP(A−LC) ⪯ λ²P exactly.
title = "my observer"

[system]
time = "discrete"            # or "continuous" (then use alpha instead of lambda)
A = [[0, 1], [1, 0]]
C = [[1, 0]]
# B = [[0], [1]]             # input matrix (optional)
# Dn = [[1]]                 # noise input on the output (default identity)

[method]
key = "lyapunov"
L = [-1.87, 1.874]           # the gain (a column); omit it to design L by the LMI
lambda = 0.955               # decay rate to certify; omit to report the best one found
rate_tol = 0.0001            # bisection tolerance for the best rate
iss_gain = true              # also certify V(e⁺) ≤ λ²V(e) + μ|v|²
# margin = 1e-9              # certify the LMI with this margin: M ⪰ margin·I

[simulate]
horizon = 100                # samples (seconds in continuous time)
x0 = [-1, -1]
xhat0 = [1, 1]
seed = 0
[simulate.noise]
kind = "uniform"             # zero | constant | windows | uniform | outliers | sequence
bound = 0.01
"""
