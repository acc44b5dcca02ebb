"""Design of the ``lyapunov`` method: the gain (given or by an LMI), the certified P at the
asked rate, the best rate with its bracket, the ISS gain μ.

The Lyapunov function is the linear case of eq. (4)-(7), Section 5 of Astolfi, Bernard,
Postoyan, Marconi, "Redesign of discrete-time nonlinear observers with state estimate
constraints guaranteed in prescribed convex set", NOLCOS 2019; the maths is in
:mod:`obsdesign.lyap`.
"""

from __future__ import annotations

import numpy as np

from obsdesign import lyap
from obsdesign.certify.detect import detectability, unobservable_restriction
from obsdesign.certify.exact import dyadic
from obsdesign.certify.printing import fmt_exact
from obsdesign.errors import InconclusiveError, InfeasibleError, SolverError
from obsdesign.methods.base import Design, Progress, SolverResult, SolverStatus
from obsdesign.methods.lyapunov.options import Options
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec


def rate_name(discrete: bool) -> str:
    """``lambda`` (discrete, eq. (6): ρ = λ²) or ``alpha`` (continuous), the parameter name of
    the decay rate of V (Section 5, constrained-redesign paper).

    :param discrete: time domain."""
    return "lambda" if discrete else "alpha"


def design(spec: Spec, progress: Progress | None = None) -> Design:
    """Parameters of the ``lyapunov`` method: L, P at the asked (or best) rate, the best rate
    with its bracket (``<rate>_best``, ``<rate>_bracket``, ``<rate>_bracket_kind``) and μ.

    Decay LMI eq. (4)-(6), ISS inequality eq. (5)-(7), Section 5 of the constrained-redesign
    paper (Astolfi et al., NOLCOS 2019). A rate given in the spec is checked directly, before
    any search; the best-rate search then never reports a worse rate.

    :param spec: the bound spec (``spec.options`` is :class:`Options`);
    :param progress: callback for progress messages."""
    o: Options = spec.options
    s = spec.system
    A, C = s.A.q, s.C.q
    notes: list[str] = []
    solver = SolverResult("scipy Lyapunov equation", SolverStatus.CLOSED_FORM)
    if o.L is None:
        Lf, solver = design_gain(spec, o, progress)
        L = dyadic(Lf, lyap.BITS)
        notes.append("L designed by the LMI in (P, X = P L); certified with the rounded L")
    else:
        L = o.L
    Acl = lyap.closed_loop(A, C, L)
    eig = np.linalg.eigvals(np.asarray(Acl, dtype=float))
    params = Parameters({"L": L})
    name = rate_name(s.discrete)
    sym = "λ" if s.discrete else "α"
    if s.discrete:
        bound = float(np.max(np.abs(eig)))
        params["rho"] = bound
        lim = f"spectral radius ≈ {bound:.6g}"
    else:
        bound = float(np.max(eig.real))
        params["max_real_eig"] = bound
        lim = f"largest real part ≈ {bound:.6g}"
    known = None
    if o.rate is not None:
        # the asked rate first, directly: no search can make it fail
        P = lyap.certified_P(A, C, L, s.discrete, o.rate, o.margin)
        if P is None:
            if not lyap.rate_feasible(Acl, o.rate, s.discrete):
                raise InfeasibleError(
                    f"no P ≻ 0 gives decay rate {sym} = {fmt_exact(o.rate)}: A − LC has an "
                    f"eigenvalue {'of modulus ≥ λ' if s.discrete else 'with real part ≥ −α'} "
                    f"({lyap.stability_test(s.discrete)}; {lim})"
                )
            raise InconclusiveError(
                f"decay rate {sym} = {fmt_exact(o.rate)} is feasible "
                f"({lyap.stability_test(s.discrete)}) but the "
                f"rounded Lyapunov-equation P fails the exact check with margin "
                f"{fmt_exact(o.margin)} (too close to the limit: {lim})"
            )
        known = (o.rate, P)
    elif not lyap.rate_feasible(Acl, 1 if s.discrete else 0, s.discrete):
        raise InfeasibleError(
            f"A − LC is not {'Schur' if s.discrete else 'Hurwitz'}: {lim} "
            f"({lyap.stability_test(s.discrete)})"
            + ("" if o.L is None else " (the given L does not stabilize the error)")
        )
    br = lyap.best_rate(
        A, C, L, s.discrete, tol=o.rate_tol, margin=o.margin, known=known, progress=progress
    )
    rate, P = (br.best, br.P) if known is None else known
    params["P"] = P
    params[name] = rate
    params["P_best"] = br.P
    params[f"{name}_best"] = br.best
    params[f"{name}_bracket"] = br.other
    params[f"{name}_bracket_kind"] = br.kind
    if o.iss_gain:
        Bw = lyap.error_input(s.Bd.q, s.Dn.q, L)
        rho = lyap.decay_factor(rate, s.discrete)
        params["mu"] = lyap.iss_mu(Acl, Bw, P, rho, s.discrete, strict=True)
    why = (
        f"no P ≻ 0 exists there ({lyap.stability_test(s.discrete)})"
        if br.kind == lyap.INFEASIBLE
        else "feasible, but the rounded Lyapunov-equation P fails the exact check there"
    )
    notes.append(
        f"best rate {name} = {fmt_exact(br.best)} for this L (bracket tolerance "
        f"{fmt_exact(o.rate_tol)}); {name} = {fmt_exact(br.other)} is {br.kind}: {why}; "
        + (f"infimum {bound:.6g}" if s.discrete else f"supremum {-bound:.6g}")
    )
    return Design(params, solver, notes)


def design_gain(
    spec: Spec, o: Options, progress: Progress | None
) -> tuple[np.ndarray, SolverResult]:
    """Design L through the LMI in (P, X = P L), bisecting on the rate (float gain).

    Discrete: [[λ²P, (PA − XC)ᵀ], [PA − XC, P]] ⪰ δ I, the Schur complement of the decay LMI
    eq. (4)-(6) (Section 5, constrained-redesign paper, Astolfi et al., NOLCOS 2019);
    continuous: −(AᵀP + PA − CᵀXᵀ − XC + 2αP) ⪰ δ I. Normalization I ⪯ P ⪯ t·I, minimal t.
    (C, A) is tested for detectability exactly first (exit 1 with the reason when it is not;
    an asked rate that an unobservable mode forbids is also exit 1); a solver that then finds
    no gain makes the run inconclusive (exit 4), never "infeasible".

    :param spec: the bound spec; :param o: its options; :param progress: callback."""
    import cvxpy as cp

    from obsdesign.lmi import solve, sym

    s = spec.system
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

    time = "discrete" if s.discrete else "continuous"
    det = detectability(s.A.q, s.C.q, time)
    what = "Schur" if s.discrete else "Hurwitz"
    if not det.detectable:
        raise InfeasibleError(f"no gain L makes A − LC {what}: (C, A) is {det.reason}")
    if o.rate is not None:
        # the unobservable modes are eigenvalues of A − LC for every L (exact)
        _, Au = unobservable_restriction(s.A.q, s.C.q)
        if Au.nrows() and not lyap.rate_feasible(lyap.as_qarray(Au), o.rate, s.discrete):
            raise InfeasibleError(
                f"no gain L gives decay rate {fmt_exact(o.rate)}: an unobservable mode of "
                f"(C, A) (a root of {Au.charpoly()}) is an eigenvalue of A − LC for every L "
                f"and fails the rate ({lyap.stability_test(s.discrete)})"
            )
        # design with some slack (2 %) so the rounded gain certifies robustly at the asked rate
        slack = float(o.rate) * (0.98 if s.discrete else 1.02)
        if not feasible(slack) and not feasible(float(o.rate)):
            raise InconclusiveError(
                f"the LMI solver found no gain at rate {fmt_exact(o.rate)}, although (C, A) "
                f"allows it ({det.reason})"
            )
    elif s.discrete:
        lo, hi = 0.0, 1.0 - tol
        if not feasible(hi):
            raise InconclusiveError(
                f"the LMI solver found no gain with λ ≤ {1.0 - tol:g} ({det.reason})"
            )
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
            raise InconclusiveError(f"the LMI solver found no gain with α ≥ {tol:g} ({det.reason})")
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
    return Lf, SolverResult(name, SolverStatus.OPTIMAL, seconds=total)
