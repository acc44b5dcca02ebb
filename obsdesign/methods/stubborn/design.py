"""Design of the stubborn observer: the λ search and the optimized selection of K, R, W.

Slides "Stubborn observers for linear and nonlinear systems" (Astolfi, Alessandri, Zaccarian,
WUDS 2017): LMIs (1)-(3) (continuous time) and (7)-(9) (discrete time), K = P⁻¹X; the
"optimized parameter selection": first the best λ, then λ at a fraction of it with W ⪰ I,
P ⪰ I, then one criterion (size of R, size of K through X, or the L2 gain).

Recipe (DESIGN.md, Exactness): each strict LMI F ≺ 0 is solved as F ⪯ −δ·I (δ the margin),
Clarabel, only status ``optimal`` is accepted; P, U, W, Y, R and the gain K itself are rounded
to dyadic rationals and X is rebuilt exactly as X = P K, so the certificate checks the LMIs
with the reported gain.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, dyadic, symmetrize, to_float
from obsdesign.certify.printing import fmt_down, fmt_exact, fmt_up
from obsdesign.errors import InconclusiveError, InfeasibleError, SolverError
from obsdesign.lmi import overflow, solve, time_limit
from obsdesign.methods.base import Design, Progress, SolverResult, SolverStatus
from obsdesign.methods.stubborn import claims as _claims
from obsdesign.methods.stubborn.detect import detectability
from obsdesign.methods.stubborn.options import Options
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec

#: bits of the dyadic rounding of the solution (relative per entry)
BITS = 40
#: the λ search stops at these caps (continuous: λ ≤ LAMBDA_CAP; discrete: λ ≥ 1/LAMBDA_CAP)
LAMBDA_CAP = 1e6
#: continuous time: below λ = 10⁻⁶ the search goes down by LOW_STEP a step to LAMBDA_FLOOR
LOW_STEP = 1e4
LAMBDA_FLOOR = 1e-26


@dataclass
class Plant:
    """The linear data the LMIs use (floats for the solver)."""

    A: np.ndarray
    C: np.ndarray
    Bd: np.ndarray
    discrete: bool

    @classmethod
    def of(cls, spec: Spec) -> Plant:
        s = spec.system
        return cls(
            np.asarray(s.A.f, float),
            np.asarray(s.C.f, float),
            np.asarray(s.Bd.f, float),
            s.discrete,
        )


#: the solver keeps ‖X‖₂ and R within their bounds times (1 − this): strictly inside, as
#: the claims check ‖K‖₂ ≤ gain_bound, R ⪯ r_bound·I of the rounded values
BOUND_INSIDE = 1e-6


def _problem(
    pl: Plant,
    o: Options,
    lam: Any,
    criterion: str | None,
    margin: Any,
    inside: float = BOUND_INSIDE,
) -> Any:
    """cvxpy problem of LMIs (1)-(3) / (7)-(9) at a fixed λ, normalized P ⪰ I, W ⪰ I.

    ``criterion`` None: feasibility; ``R``: minimize λ_max(R); ``K``: minimize ‖X‖₂;
    ``l2``: minimize g with the bounded real lemma (g = γ², γ the L2 gain d → e).
    Full mode adds ‖X‖₂ ≤ gain_bound·(1 − inside) (then ‖K‖₂ = ‖P⁻¹X‖₂ ≤ gain_bound);
    r_bound adds R ⪯ r_bound·(1 − inside)·I."""
    import cvxpy as cp

    A, C = pl.A, pl.C
    n, p = A.shape[0], C.shape[0]
    P = cp.Variable((n, n), symmetric=True)
    u = cp.Variable(p)
    w = cp.Variable(p)
    Y = cp.Variable((p, n))
    R = cp.Variable((p, p), symmetric=True)
    Kf = None if o.K is None else np.asarray(to_float(o.K), float)
    X = P @ Kf if Kf is not None else cp.Variable((n, p))
    U, W = cp.diag(u), cp.diag(w)
    G = P @ A - X @ C
    S = W @ C + Y

    def sym(M: Any) -> Any:
        return (M + M.T) / 2

    if not pl.discrete:
        M1 = cp.bmat([[G + G.T + lam * P - C.T @ R @ C, X + C.T @ U], [X.T + U @ C, -2 * U]])
        M2 = cp.bmat([[G + G.T, X + S.T], [X.T + S, -2 * W]])
    else:
        M1 = cp.bmat([[-lam * P - C.T @ R @ C, C.T @ U, G.T], [U @ C, -2 * U, X.T], [G, X, -P]])
        M2 = cp.bmat([[-P, S.T, G.T], [S, -2 * W, X.T], [G, X, -P]])
    m = margin
    cons = [
        sym(M1) << -m * np.eye(M1.shape[0]),
        sym(M2) << -m * np.eye(M2.shape[0]),
        P >> np.eye(n),
        w >= 1,
        u >= m,
        R >> m * np.eye(p),
    ]
    for i in range(p):
        Mi = cp.bmat(
            [[P, Y[i : i + 1, :].T], [Y[i : i + 1, :], cp.reshape(w[i], (1, 1), order="C")]]
        )
        cons.append(sym(Mi) >> m * np.eye(n + 1))
    if o.K is None and o.gain_bound is not None:
        gb = float(o.gain_bound) * (1 - inside)  # strictly inside: the claim checks ‖K‖₂ ≤ bound
        if o.scale_free_gain:
            # ‖X‖₂ ≤ gb·s and P ⪰ s·I give ‖K‖₂ = ‖P⁻¹X‖₂ ≤ gb, homogeneous like the LMIs
            sg = cp.Variable()
            cons.append(P >> sg * np.eye(n))
            cons.append(cp.bmat([[gb * sg * np.eye(n), X], [X.T, gb * sg * np.eye(p)]]) >> 0)
        else:
            cons.append(cp.bmat([[gb * np.eye(n), X], [X.T, gb * np.eye(p)]]) >> 0)
    if o.r_bound is not None:
        cons.append(R << float(o.r_bound) * (1 - inside) * np.eye(p))
    obj: Any = cp.Minimize(0)
    extra: dict[str, Any] = {}
    if criterion == "R":
        obj = cp.Minimize(cp.lambda_max(R))
    elif criterion == "K":
        t = cp.Variable()
        cons.append(cp.bmat([[t * np.eye(n), X], [X.T, t * np.eye(p)]]) >> 0)
        obj = cp.Minimize(t)
    elif criterion == "l2":
        g = cp.Variable()
        Bd = pl.Bd
        k = Bd.shape[1]
        PB = P @ Bd
        if not pl.discrete:
            M3 = cp.bmat([[G + G.T + np.eye(n), PB], [PB.T, -g * np.eye(k)]])
        else:
            M3 = cp.bmat(
                [
                    [-P + np.eye(n), np.zeros((n, k)), G.T],
                    [np.zeros((k, n)), -g * np.eye(k), PB.T],
                    [G, PB, -P],
                ]
            )
        cons.append(sym(M3) << -m * np.eye(M3.shape[0]))
        obj = cp.Minimize(g)
        extra["g"] = g
    prob = cp.Problem(obj, cons)
    return prob, dict(P=P, X=X, u=u, w=w, Y=Y, R=R, **extra)


def margin_at(o: Options, pl: Plant, lam: float) -> float:
    """The solver's strictness margin δ at λ (every strict LMI F ≺ 0 is solved as F ⪯ −δI):
    ``[method] margin``, times min(1, λ) in continuous time. LMI (1) holds with at most about
    (λ_max − λ)·‖P‖ to spare, and P ⪰ I fixes the scale, so a fixed δ = 10⁻⁶ made every λ
    infeasible for a plant whose rates are 10⁻⁹ (A, C of size 10⁻⁹; a mode at −10⁻²⁰) and
    the design said "infeasible for every λ tried" where exact certificates exist
    (stubborn soundness trial, session 25). Discrete time: λ ∈ (0, 1) and the LMIs are
    scale-free in P, δ as given.

    :param o: the options; :param pl: the plant; :param lam: the rate λ > 0."""
    m = float(o.margin)
    return m if pl.discrete else m * min(1.0, float(lam))


def solve_cold(prob: Any) -> tuple[bool, str]:
    """Solve one LMI problem of the λ search (LMIs (1)-(3) / (7)-(9)) with Clarabel without warm
    start (cvxpy's default warm start reuses the solver object of the
    previous λ, so the answer near the boundary would depend on the search's history; cold, the
    same λ always gives the same answer, here and in ``verify``). Returns (optimal, status)."""
    import cvxpy as cp

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            prob.solve(solver="CLARABEL", warm_start=False, **time_limit("CLARABEL"))
    except cp.error.SolverError as e:
        return False, f"solver failure ({e})"
    except ValueError as e:
        overflow(e)
        raise
    return prob.status == "optimal", str(prob.status)


class Feasibility:
    """Feasibility of LMIs (1)-(3) / (7)-(9) as a function of λ: one cvxpy problem with λ as a
    parameter (canonicalized once), each λ solved cold (:func:`solve_cold`), so the answer
    at a λ does not depend on the λs solved before (``verify`` re-solves the bracket's far
    end with a new object and gets the search's answer)."""

    def __init__(self, pl: Plant, o: Options, inside: float = BOUND_INSIDE) -> None:
        import cvxpy as cp

        self.pl, self.o = pl, o
        self.calls = 0
        self.lam = cp.Parameter(nonneg=True)
        self.margin = cp.Parameter(nonneg=True)
        self.prob, _ = _problem(pl, o, self.lam, None, self.margin, inside)

    def __call__(self, lam: float) -> tuple[bool, str]:
        """Whether the solver finds the LMIs feasible at λ (margin :func:`margin_at`), and
        its status."""
        self.calls += 1
        self.lam.value = float(lam)
        self.margin.value = margin_at(self.o, self.pl, lam)
        return solve_cold(self.prob)


def feasible(pl: Plant, o: Options, lam: float) -> tuple[bool, str]:
    """Whether the solver finds LMIs (1)-(3) / (7)-(9) feasible at λ (status, for the report)."""
    return Feasibility(pl, o)(lam)


#: the solver status that counts as "the LMIs are infeasible" at the bracket's far end
INFEASIBLE = "infeasible"
#: the far end is moved outward at most this many times (doubling its distance each time:
#: from a gap of one ulp, 2⁸⁰ times it passes the search caps)
FAR_STEPS = 80


def search_lambda(pl: Plant, o: Options) -> tuple[float, float, str]:
    """The best λ to a relative tolerance: (certifiable side, other side, status there).

    Continuous time: the largest λ > 0 (feasibility is monotone: a smaller λ only relaxes
    (1)); doubling from 1 brackets it, bisection refines until hi − lo ≤ tol·lo. Discrete
    time: the smallest λ ∈ (0, 1) (a larger λ relaxes (7)); bisection on (0, 1).

    Only Clarabel's ``optimal`` counts as feasible. The bisection treats every other answer
    as "not found feasible", but the far end of the bracket must be a λ where the solver
    reports ``infeasible``: near the boundary Clarabel also answers ``optimal_inaccurate``,
    ``infeasible_inaccurate`` or fails (Example 1: optimal at 7.5117, inaccurate or failing
    on 7.52 … 7.55, infeasible from 7.57 on; a certificate exists at 7.53 — stubborn review),
    so a far end without a solver infeasibility certificate is moved outward
    (:func:`_far_end`) and the bracket may end wider than ``lambda_tol``: it says where the
    solver's answers are reliable, not more."""
    tol = float(o.lambda_tol) / 2  # half the tolerance: _certified_best may step back tol/8 ×3
    feas = Feasibility(pl, o)

    def feasible(_pl: Plant, _o: Options, lam: float) -> tuple[bool, str]:
        return feas(lam)

    if not pl.discrete:
        lo, hi = 0.0, 1.0
        ok, st = feasible(pl, o, hi)
        while ok:
            lo, hi = hi, 2 * hi
            if hi > LAMBDA_CAP:
                return lo, float("inf"), "feasible up to the cap"
            ok, st = feasible(pl, o, hi)
        if lo == 0.0:
            lo = 1e-6
            ok, st_lo = feasible(pl, o, lo)
            while not ok:
                # a slow plant (time scale beyond 10⁶): down by 10⁴ a step to LAMBDA_FLOOR
                # (a plant at scale 1e-9 needs λ ≈ 1e-11: the search stopped at 1e-6 and
                # said "infeasible for every λ tried"; unusual-spec trial, session 24)
                hi, st = lo, st_lo
                lo /= LOW_STEP
                # 10⁻⁶ / (10⁴)⁵ is 9.99…·10⁻²⁷ in floats: the floor itself is tried (the
                # docs said 10⁻³⁰, a floor a plain < never reached; stubborn trial, session 40)
                if lo < LAMBDA_FLOOR * (1 - 1e-9):
                    return 0.0, hi, st
                ok, st_lo = feasible(pl, o, lo)
        lo, hi, st, known = _bisect(feas, lo, hi, st, tol)
        return (lo, *_far_end(feas, lo, hi, st, known, False))
    top = 1 - 1e-6
    ok, st = feasible(pl, o, top)
    if not ok:
        # the solver's own status (it was "infeasible" whatever the solver said, so an
        # inaccurate answer near 1 − 10⁻⁶ became exit 1; soundness trial, session 30)
        return 1.0, top, st
    bot = 1 / LAMBDA_CAP
    ok, st = feasible(pl, o, bot)
    if ok:
        return bot, 0.0, "feasible down to the cap"
    hi, lo, st, known = _bisect(feas, top, bot, st, tol)
    return (hi, *_far_end(feas, hi, lo, st, known, True))


def _bisect(
    feas: Feasibility, good: float, bad: float, status: str, tol: float
) -> tuple[float, float, str, float | None]:
    """Bisection between a feasible λ (good) and one not found feasible (bad, the solver's
    ``status`` there) until |bad − good| ≤ tol·|good|, or until the two are adjacent floats
    (a ``lambda_tol`` below the float resolution: the midpoint equals an end and the gap
    can shrink no more; such a tolerance hung the design — stubborn review). Returns
    (good, bad, the status at bad, the nearest λ the solver reported infeasible or None)."""
    known = bad if status == INFEASIBLE else None
    while abs(bad - good) > tol * abs(good):
        mid = (good + bad) / 2
        if mid == good or mid == bad:
            break
        ok, st = feas(mid)
        if ok:
            good = mid
        else:
            bad, status = mid, st
            if st == INFEASIBLE:
                known = mid
    return good, bad, status, known


def _far_end(
    feas: Feasibility,
    good: float,
    bad: float,
    status: str,
    known: float | None,
    discrete: bool,
) -> tuple[float, str]:
    """The bracket's far end: ``bad`` when the solver reports it ``infeasible``, else the
    first of good ± 2ᵏ·|bad − good| (k = 1, 2, …; outward: up in continuous time, down in
    discrete) where it does — or ``known``, the nearest λ the search already found
    infeasible, once the steps pass it — within the search caps. Returns (far end, status
    there); when none is found the last point tried and its status (the bracket claim then
    names the status and fails)."""
    gap = abs(bad - good)
    k = 0
    while status != INFEASIBLE and k < FAR_STEPS:
        k += 1
        cand = good + gap * 2**k if not discrete else good - gap * 2**k
        if known is not None and (cand >= known if not discrete else cand <= known):
            return known, INFEASIBLE
        if (not discrete and cand > LAMBDA_CAP) or (discrete and cand < 1 / LAMBDA_CAP):
            break
        bad, status = cand, feas(cand)[1]
    return bad, status


def _chosen(o: Options, best: fmpq, discrete: bool) -> fmpq:
    """λ from the best rate: fraction·λ_max (continuous), 1 − fraction·(1 − λ_best)
    (discrete: the decay margin 1 − λ is the fraction of the best one)."""
    return o.fraction * best if not discrete else 1 - o.fraction * (1 - best)


def design(spec: Spec, progress: Progress | None = None) -> Design:
    """The stubborn design (Astolfi, Alessandri, Zaccarian, WUDS 2017): the slides' Theorem
    (LMIs (1)-(3) / (7)-(9), :func:`design_params`) in the linear modes, the high-gain
    redesign (:func:`obsdesign.methods.stubborn.highgain.design_params`) in mode ``high-gain``.

    :param spec: the bound spec; :param progress: optional callback for status lines."""
    if spec.options.mode == "high-gain":
        from obsdesign.methods.stubborn.highgain import design_params as high_gain

        vals, solver, notes = high_gain(spec, progress)
    else:
        vals, solver, notes = _design_or_scale_free(spec, progress)
    return Design(Parameters(vals), solver, notes)


def _design_or_scale_free(
    spec: Spec, progress: Any = None
) -> tuple[dict[str, Any], SolverResult, list[str]]:
    """:func:`design_params`; when it ends "infeasible" with the gain bound among the bounds
    to raise, or without a verdict at every λ tried (exit 4: inaccurate answers, badly scaled
    data), once more with the gain bound scale-free (``Options.scale_free_gain``).

    With the normalization P ⪰ I, W ⪰ I the bound ‖X‖₂ ≤ gain_bound is not scale-free: a plant
    whose LMIs need P ≫ W (A = 0.5, C = 1000: P ≳ 10⁶ for w ≥ 1) needs ‖X‖₂ = ‖P K‖₂ ≳ 500
    although K = 0.01 certifies, and the design said "LMIs (1)-(3) infeasible for every λ
    tried: raise gain_bound (now 100)", exit 1 (stubborn trial, session 40). The retry bounds
    ‖X‖₂ ≤ gain_bound·s with P ⪰ s·I, which still gives ‖K‖₂ ≤ gain_bound (the certified
    claim) and scales with P; the report's ``gain_normalization = "scale-free"`` says which
    problem its λ bracket is of. The first error stands when the retry fails too."""
    from dataclasses import replace as _replace

    o: Options = spec.options
    try:
        return design_params(spec, progress)
    except (InfeasibleError, InconclusiveError) as e:
        # exit 1 naming the gain bound, or exit 4 where no λ was found feasible without a
        # verdict: with C ~ 10⁵ the solver's answer is "inaccurate", or the data span gate
        # says it is no verdict, where the scale-free problem certifies (re-check trial,
        # session 40); not the exit 4 of a margin or bound at its feasibility limit
        named = getattr(e, "gain_bound_hint", False)
        if o.K is not None or o.gain_bound is None or o.scale_free_gain or not named:
            raise
        first = e
    free = _replace(spec, options=_replace(o, scale_free_gain=True))
    if progress:
        progress(
            "infeasible with ‖X‖₂ ≤ gain_bound and P ⪰ I: again with ‖X‖₂ ≤ gain_bound·s, P ⪰ s·I"
        )
    try:
        vals, solver, notes = design_params(free, progress)
    except (InfeasibleError, InconclusiveError):
        raise first from None
    vals["gain_normalization"] = "scale-free"
    notes.insert(
        0,
        f"with P ⪰ I, W ⪰ I and ‖X‖₂ ≤ gain_bound = {fmt_exact(o.gain_bound)} "
        + (
            "the solver reports the LMIs infeasible"
            if isinstance(first, InfeasibleError)
            else "the design gives no verdict (exit 4)"
        )
        + " (that bound is not scale-free: the LMIs may need P ≫ W); "
        "designed with ‖X‖₂ ≤ gain_bound·s and P ⪰ s·I instead, which still gives "
        "‖K‖₂ ≤ gain_bound (claim gain-bound)",
    )
    return vals, solver, notes


def design_params(
    spec: Spec, progress: Any = None
) -> tuple[dict[str, Any], SolverResult, list[str]]:
    """Full-stubborn or redesign (slides' Theorem, LMIs (1)-(3) / (7)-(9), K = P⁻¹X): the λ
    search ("first maximize λ"), λ at the fraction, the criterion step (min R, min K through X,
    or the L2 gain), rounding and the exact self-check. ``spec``: the bound spec;
    ``progress``: optional callback for status lines. Returns (parameters, solver info, notes)."""
    o: Options = spec.options
    pl = Plant.of(spec)
    t0 = time.perf_counter()
    notes: list[str] = []
    vals: dict[str, Any] = {}
    _require_detectable(spec, pl)
    if o.K is not None and not _stable_gain(spec, o.K, pl.discrete):
        # exact, before any solve: with A − KC on the stability boundary (s(s + 1), the
        # double integrator with K = [1, 0]) the solver answered "optimal" or "inaccurate" at
        # a tiny λ, not "infeasible", and the design ended with exit 4 "could not be
        # certified" (constrained/stubborn soundness trial, session 28)
        _unstable_gain(pl, "at every λ")
    if o.lam is not None:
        lam_q = o.lam  # a rate the user asks for is checked directly, before any search
        ok, st = feasible(pl, o, float(lam_q))
        if not ok and st == INFEASIBLE:
            where = f"at the given λ = {fmt_exact(lam_q)}"
            _unless_feasible_with_less_margin(pl, o, float(lam_q), where)
            _infeasible(spec, pl, o, where)
        # any other answer (inaccurate, a failure) is no verdict: the certification below
        # decides, and says exit 4 when it finds no point (Example 1 at λ = 7.53, where a
        # certificate exists, was exit 1 "infeasible at the given λ"; soundness trial)
    else:
        if progress:
            progress("searching the best λ")
        good, bad, st = search_lambda(pl, o)
        if good == (0.0 if not pl.discrete else 1.0):
            if st != INFEASIBLE:
                err = InconclusiveError(
                    f"stubborn: the solver found LMIs {_refs(pl)} feasible at no λ tried "
                    f"(down to {bad:g}), but did not report them infeasible there either "
                    f"(status {st}): not a verdict; a smaller [method] margin (now "
                    f"{fmt_exact(o.margin)}), "
                    + (f"a larger {_bounds_text(o)}, " if _bounds_text(o) else "")
                    + "or a rescaled plant may help"
                )
                err.gain_bound_hint = o.K is None and o.gain_bound is not None  # type: ignore[attr-defined]
                raise err
            _unless_feasible_with_less_margin(pl, o, bad, "for every λ tried")
            _infeasible(spec, pl, o, "for every λ tried")
        best, cert = _certified_best(spec, pl, o, good)
        vals["lambda_max"] = best
        for k in POINT_KEYS:
            vals[f"{k}_at_max"] = cert[k]
        # a bracket only where the solver reports the LMIs infeasible: a far end it answered
        # otherwise (infeasible_inaccurate up to the cap) made the design fail its own
        # lambda-max-bracket claim, exit 1 on a valid design (soundness trial, session 25)
        other = Q(bad) if np.isfinite(bad) and bad != 0.0 and st == INFEASIBLE else None
        if other is not None:
            vals["lambda_bracket"] = np.array([best, other], dtype=object)
        lam_q = _chosen(o, best, pl.discrete)
        # at a search cap the best λ is only bounded on one side: ≥ in continuous time (the
        # LMIs held up to the cap, and may for every λ, e.g. C invertible), ≤ in discrete
        # time, where the best λ is the smallest (the note said ≥: outsider trial, session 22)
        cap = f"{LAMBDA_CAP:g}" if not pl.discrete else f"{1 / LAMBDA_CAP:g}"
        # the one-sided bound rounded in its own direction: "≤ 1e-06" printed a certified
        # 1.0000003·10⁻⁶, and the cap read "λ = 1/1e+06" (statement audit, session 43)
        shown = (
            f"{float(best):.6g}"
            if other is not None
            else (fmt_up(best, 6) if pl.discrete else fmt_down(best, 6))
        )
        notes.append(
            f"best λ {'≈' if other is not None else ('≤' if pl.discrete else '≥')} "
            f"{shown} (certified there"
            + (
                f"; solver: {st} at {float(bad):.6g})"
                if other is not None
                else (
                    f"; the search stops at its cap λ = {cap}, so there is no bracket)"
                    if not np.isfinite(bad) or bad == 0.0
                    else f"; the solver reports the LMIs infeasible nowhere up to the cap — "
                    f"its last answer: {st} at {float(bad):.6g} — so there is no bracket)"
                )
            )
            + f"; λ = {'fraction·λ_max' if not pl.discrete else '1 − fraction·(1 − λ_best)'}"
        )
        if other is not None and abs(other - best) > o.lambda_tol * abs(best):
            notes.append(
                f"the λ bracket [{float(best):.6g}, {float(bad):.6g}] is wider than lambda_tol "
                f"= {fmt_exact(o.lambda_tol)}: the solver reports the LMIs infeasible nowhere "
                "nearer (near the boundary its answers are inaccurate), so the far end is the "
                "nearest λ found where it does"
            )
    if progress:
        progress(f"criterion '{o.criterion}' at λ = {float(lam_q):.6g}")
    cand, margin, solver = _certify_point(spec, pl, o, lam_q, o.criterion)
    if cand is None:
        # the criterion step did not give a certifiable optimum: fall back on the certified
        # feasibility point at the same λ (the criterion is then not optimized; said in notes);
        # for l2, with a certified L2-gain bound of that point (_l2_bound)
        why = solver
        cand, margin, solver = _certify_point(spec, pl, o, lam_q, None)
        if cand is not None and o.criterion == "l2":
            cand = _l2_bound(spec, cand)
            solver = solver if cand is not None else "no certified L2-gain bound at the point"
        if cand is not None:
            notes.append(
                f"criterion '{o.criterion}' step not certified ({why}): the reported point is "
                "the certified feasibility solution at this λ (criterion not optimized"
                + ("; γ² is a certified bound for it, scaled" if o.criterion == "l2" else "")
                + ")"
            )
    if cand is None:
        raise InconclusiveError(
            f"stubborn: no candidate certified at λ = {fmt_exact(lam_q)} ({solver})"
        )
    cand.update(vals)
    cand["criterion"] = o.criterion
    if o.K is None and o.gain_bound is not None:
        cand["gain_bound"] = o.gain_bound
    if o.r_bound is not None:
        cand["r_bound"] = o.r_bound
    notes.append(f"solver margin {margin:g}")
    notes.append(_linear_decay_note(pl, cand["K"]))
    sr = SolverResult(f"cvxpy/{solver}", SolverStatus.OPTIMAL, "", time.perf_counter() - t0)
    return cand, sr, notes


#: the matrices of one certified point of LMIs (1)-(3) / (7)-(9)
POINT_KEYS = ("K", "P", "U", "W", "Y", "R")


def _certified_best(spec: Spec, pl: Plant, o: Options, good: float) -> tuple[fmpq, dict[str, Any]]:
    """A certified point at (or just inside) the solver's best λ: λ_max rounded to 20 bits
    towards the feasible side, then stepped back by tol/8 (up to 3 times), then by 2ᵏ·tol
    (relative, up to a tenth) until the rounded solution passes the exact checks (the
    bracket [λ_max, λ_other] widens by at most 3/8 of lambda_tol in the first steps — the
    search's own bracket is half of it — and the bracket claim says when it is wider)."""
    step = float(o.lambda_tol) / 8 * abs(good)
    # then back-offs of 2^k·lambda_tol up to about a tenth of the gap to 0 (continuous) or
    # to 1 (discrete): at a plant's time scale 10⁻⁹ the solver's answers near the boundary
    # stay inaccurate over more than 3/8 of lambda_tol (the bracket then says it is wider)
    span = abs(good) if not pl.discrete else abs(1 - good)
    offs = [i * step for i in range(4)]
    k = 0
    while (2**k) * float(o.lambda_tol) * span <= 0.1 * span and k < 60:
        offs.append((2**k) * float(o.lambda_tol) * span)
        k += 1
    for off in offs:
        g = good - off if not pl.discrete else good + off
        best = dyadic(g, 20)
        if (not pl.discrete and best > Q(g)) or (pl.discrete and best < Q(g)):
            best = Q(g)
        cand, _, _ = _certify_point(spec, pl, o, best, None, attempts=2)
        if cand is not None:
            return best, cand
    raise InconclusiveError(
        f"stubborn: the solver's best λ ≈ {good:.6g} could not be certified exactly"
    )


def _certify_point(
    spec: Spec, pl: Plant, o: Options, lam_q: fmpq, criterion: str | None, attempts: int = 4
) -> tuple[dict[str, Any] | None, float, str]:
    """Solve at λ (with the criterion, or feasibility), round, check exactly; raise the solver
    margin ×10 on failure. Returns (candidate or None, margin, solver name or last problem)."""
    margin = margin_at(o, pl, float(lam_q))
    last = ""
    for _attempt in range(attempts):
        prob, v = _problem(pl, o, float(lam_q), criterion, margin)
        try:
            r = solve(prob, ("CLARABEL",))
        except SolverError as e:
            last = e.message
            margin *= 10
            continue
        if not r.optimal:
            # never an "infeasible" verdict here: λ is one the feasibility problem passed
            # (the search's certified λ_max scaled, or the spec's λ), and the criterion
            # step's extra constraints (l2: He(G) + I ≺ 0 with ‖X‖ ≤ gain_bound) can be
            # infeasible where the design is not; the caller falls back on the feasibility
            # point (the l2 criterion with B_d ~ 10³ ended in exit 1 "infeasible at λ with
            # the criterion step" although the fallback certifies; soundness trial, session 25)
            last = f"solver status {r.status}"
            margin *= 10
            continue
        cand = _round(v, o, lam_q)
        bad = _claims.point_failures(spec, cand, criterion == "l2")
        if not bad:
            return cand, margin, r.solver
        if bad == ["gain-bound"]:
            for fit in _within_gain_bound(cand, o):
                if not _claims.point_failures(spec, fit, criterion == "l2"):
                    return fit, margin, r.solver
        last = f"exact check failed: {', '.join(bad)}"
        margin *= 10
    return None, margin, last


def _l2_bound(spec: Spec, cand: dict[str, Any]) -> dict[str, Any] | None:
    """A certified L2-gain bound γ² for a certified point of LMIs (1)-(3) / (7)-(9) (slides,
    criterion 4, bounded real lemma :func:`~obsdesign.methods.stubborn.lmis.l2_gain`), when
    the l2 criterion step itself fails (Clarabel inaccurate at λ near λ_max: exit 4 before;
    random-spec fuzzer). The LMIs are homogeneous in (P, X, U, W, Y, R), so the point scaled
    by a power of two s ≥ 1 still passes them exactly (same K); the bounded real lemma's
    constant I then weighs less: with N₀ = He(G) (continuous) or [[−P, Gᵀ], [G, −P]]
    (discrete), ≺ 0 by LMI (2) / (8), N(s) = s N₀ + diag(I, 0) ≺ 0 once s λ_min(−N₀) > 1,
    and the Schur complement gives γ² > λ_max(bᵀ(−N(s))⁻¹b), b = s[P B_d] (continuous) or
    s[0; P B_d] (discrete). The s with the least float γ² is tried first; the exact check
    (:func:`~obsdesign.methods.stubborn.claims.point_failures`) decides. None when no
    scaling certifies (or R ⪯ r_bound·I would be lost)."""
    o: Options = spec.options
    sy = spec.system
    A, C, Bd = (np.asarray(to_float(M), float) for M in (sy.A.q, sy.C.q, sy.Bd.q))
    P0 = np.asarray(to_float(cand["P"]), float)
    K = np.asarray(to_float(cand["K"]), float)
    n, k = P0.shape[0], Bd.shape[1]
    G0 = P0 @ A - P0 @ K @ C
    if sy.discrete:
        N0 = np.block([[-P0, G0.T], [G0, -P0]])
        E = np.diag([1.0] * n + [0.0] * n)
        b0 = np.vstack([np.zeros((n, k)), P0 @ Bd])
    else:
        N0, E, b0 = G0 + G0.T, np.eye(n), P0 @ Bd
    with np.errstate(all="ignore"):
        try:
            mu = float(np.linalg.eigvalsh(-(N0 + N0.T) / 2)[0])
        except np.linalg.LinAlgError:
            return None
    if not mu > 0 or not np.isfinite(mu):
        return None
    k0 = max(0, int(np.ceil(np.log2(2 / mu))))
    trials = []
    for j in range(k0, k0 + 12):
        sc = 2.0**j
        with np.errstate(all="ignore"):
            try:
                g = float(
                    np.linalg.eigvalsh(sc * sc * b0.T @ np.linalg.solve(-(sc * N0 + E), b0))[-1]
                )
            except np.linalg.LinAlgError:
                continue
        if np.isfinite(g) and g >= 0:
            trials.append((g, j))
    for g, j in sorted(trials)[:4]:
        sc = fmpq(2**j)
        out = dict(cand)
        for key in ("P", "U", "W", "Y", "R"):
            out[key] = np.asarray(cand[key], dtype=object) * sc
        out["X"] = out["P"] @ out["K"]
        if o.r_bound is not None and sc != 1 and _claims.point_failures(spec, out, False):
            return None  # R ⪯ r_bound·I lost by the scaling
        out["gamma2"] = dyadic(g * (1 + 1e-6) + 1e-12, BITS)
        if not _claims.point_failures(spec, out, True):
            return out
    return None


def _snap(M: Any) -> np.ndarray:
    """Entries below 10⁻¹² of the largest set to 0 (solver noise; the exact check decides)."""
    a = np.array(M, dtype=float)
    a[np.abs(a) < 1e-12 * max(float(np.abs(a).max(initial=0.0)), 1e-300)] = 0.0
    return a


def _within_gain_bound(cand: dict[str, Any], o: Options) -> Iterator[dict[str, Any]]:
    """The candidate with K shrunk into ‖K‖₂ ≤ gain_bound, for a point whose only failed
    check is the gain bound: K scaled by gain_bound·(1 − 10⁻⁶)/‖K‖_F (rounded down to 40
    bits; ‖K‖₂ ≤ ‖K‖_F), then K = 0 (X = P K rebuilt). The solver keeps ‖X‖₂ within the
    bound only to its own accuracy (about 10⁻⁸): with gain_bound = 10⁻¹² every point failed
    and a stable plant, for which K = 0 certifies, was exit 4 (independent fuzz, session 38).
    The exact checks decide, as for any candidate."""
    if o.K is not None or o.gain_bound is None:
        return
    K = cand["K"]
    fro2 = sum((k * k for k in K.ravel()), fmpq(0))
    if fro2 > 0:
        s = dyadic(float(o.gain_bound) * (1 - BOUND_INSIDE) / math.sqrt(float(fro2)), BITS)
        while s * s * fro2 > Q(o.gain_bound) ** 2 and s > 0:
            s /= 2
        if s > 0:
            Ks = np.array([[dyadic(float(k * s), BITS) for k in row] for row in K], dtype=object)
            yield {**cand, "K": Ks, "X": cand["P"] @ Ks}
    Z = np.array([[fmpq(0)] * K.shape[1] for _ in range(K.shape[0])], dtype=object)
    yield {**cand, "K": Z, "X": cand["P"] @ Z}


def _round(v: dict[str, Any], o: Options, lam_q: fmpq) -> dict[str, Any]:
    """Dyadic rounding (40 bits); K rounded itself and X rebuilt exactly as P K (DESIGN.md
    recipe: check the LMIs in the original variables with the reported gain)."""
    P = symmetrize(dyadic(_snap((v["P"].value + v["P"].value.T) / 2), BITS))
    Xf = np.asarray(v["X"].value, float)
    if o.K is None:
        K = dyadic(_snap(np.linalg.solve(np.asarray(to_float(P), float), Xf)), BITS)
    else:
        K = np.asarray(o.K, dtype=object)
    X = P @ K
    R = symmetrize(dyadic(_snap((v["R"].value + v["R"].value.T) / 2), BITS))
    U = dyadic(np.asarray(v["u"].value, float).reshape(-1), BITS)
    W = dyadic(np.asarray(v["w"].value, float).reshape(-1), BITS)
    Y = dyadic(_snap(np.asarray(v["Y"].value, float)), BITS)
    out: dict[str, Any] = {"K": K, "P": P, "X": X, "U": U, "W": W, "Y": Y, "R": R, "lambda": lam_q}
    if "g" in v:
        g = Q(float(v["g"].value))
        out["gamma2"] = dyadic(float(g) * (1 + 1e-6) + 1e-9, BITS)
    return out


def _require_detectable(spec: Spec, pl: Plant) -> None:
    """Refuse a plant whose (C, A) is not detectable (exact test), before any LMI solve: the
    (1,1) block of (2) (resp. (8)) makes A − KC Hurwitz (Schur) for the design's K, so such a
    plant makes LMIs (1)-(3) / (7)-(9) infeasible for every λ. A solver can still report
    'feasible' at a tiny λ near an unobservable mode on the stability boundary (two undamped
    oscillators, one seen: λ ≈ 3·10⁻⁵, then exit 4 "could not be certified"; random-spec
    fuzzer), so the exact test runs first. An inconclusive verdict (float fallback) does not
    stop the design."""
    det = detectability(spec.system.A.q, spec.system.C.q, pl.discrete)
    if det.verdict is False:
        raise InfeasibleError(
            f"stubborn: (C, A) is not detectable ({det.detail}); LMIs {_refs(pl)} are infeasible"
        )


#: the solver's `infeasible` is a verdict only if it holds with the margin divided by this too
MARGIN_CONFIRM = 1000


def _unless_feasible_with_less_margin(pl: Plant, o: Options, lam: float, where: str) -> None:
    """Exit 4 when the solver, having answered `infeasible` for the tightened problem, finds
    LMIs (1)-(3) / (7)-(9) feasible at ``lam`` with less tightening: first the strictness
    margin δ / :data:`MARGIN_CONFIRM` (``[method] margin``: it solves F ⪯ −δI, not F ≺ 0;
    A = 2.414213 < 1 + √2, C = 1 in discrete time was exit 1 "infeasible for every λ tried",
    and certified with margin = 1e-9; soundness trial, session 30), then also the bounds
    gain_bound / r_bound kept inside by :data:`BOUND_INSIDE` / :data:`MARGIN_CONFIRM` only
    (A = C = 1 with gain_bound = 1.562501 > 25/16, the exact limit, was exit 1 "raise
    gain_bound"; re-check trial, session 30). ``lam``: the most lenient λ the answer was at."""
    less = replace(o, margin=o.margin / MARGIN_CONFIRM)
    head = f"stubborn: the solver reports LMIs {_refs(pl)} infeasible {where}"
    if Feasibility(pl, less)(lam)[0]:
        raise InconclusiveError(
            f"{head} with the strictness margin {fmt_exact(o.margin)} ([method] margin: it "
            f"solves F ⪯ −margin·I), but feasible at λ = {lam:g} with margin "
            f"{fmt_exact(less.margin)}: not a verdict (the LMIs are near their feasibility "
            f"boundary); set [method] margin = {fmt_exact(less.margin)}"
        )
    bounds = [
        k
        for k, v in (("gain_bound", o.gain_bound if o.K is None else None), ("r_bound", o.r_bound))
        if v is not None
    ]
    if bounds and Feasibility(pl, less, BOUND_INSIDE / MARGIN_CONFIRM)(lam)[0]:
        names = " and ".join(bounds)
        raise InconclusiveError(
            f"{head}, but feasible at λ = {lam:g} with margin {fmt_exact(less.margin)} and "
            f"{names} tightened by {BOUND_INSIDE / MARGIN_CONFIRM:g} instead of "
            f"{BOUND_INSIDE:g} relative: not a verdict ({names} at the feasibility limit); "
            f"raise {names} by a little more than {BOUND_INSIDE:g} relative"
        )


def _bounds_text(o: Options) -> str:
    """The design's bounds in force, "gain_bound (now 100), r_bound (now 12.9)" (empty when
    none): the gain bound applies in full mode only (redesign keeps the given K)."""
    return ", ".join(
        f"{k} (now {fmt_exact(v)})"
        for k, v in (("gain_bound", o.gain_bound if o.K is None else None), ("r_bound", o.r_bound))
        if v is not None
    )


def _infeasible(spec: Spec, pl: Plant, o: Options, where: str) -> None:
    """Say why: (C, A) not detectable (necessary for the LMIs; in continuous time also
    sufficient, the slides' Proposition), or the bounds of the design (gain bound, given K,
    given λ); in discrete time, when the LMIs are infeasible even without the bounds, that a
    detectable (C, A) is not enough there."""
    det = detectability(spec.system.A.q, spec.system.C.q, pl.discrete)
    if det.verdict is False:
        raise InfeasibleError(
            f"stubborn: (C, A) is not detectable ({det.detail}); LMIs {_refs(pl)} are infeasible"
        )
    if det.verdict is None:
        raise InconclusiveError(
            f"stubborn: LMIs {_refs(pl)} infeasible {where}, and detectability of (C, A) is "
            f"numerically inconclusive ({det.detail})"
        )
    if o.K is not None and not _stable_gain(spec, o.K, pl.discrete):
        _unstable_gain(pl, where)
    spread = _data_spread(pl, o.K)
    if spread > SPREAD_MAX:
        # Clarabel answered "infeasible" on feasible LMIs of plants such as A = [[1e-8, 1],
        # [0, 1e-8]], C = [[1e8, 0]] (K = 0 and an exact P certify them) and A = [[0, 1],
        # [0, 0]], C = [[1e6, 0]] (edge-shape trial, session 26), and of the redesign of
        # A = [[0, 1], [0, 0]], C = [[1, 0]] with the slow K = (1e-5, 1e-10), feasible by a
        # rescaled certificate (search-space/stubborn trial, session 31): on data this badly
        # scaled the status is no proof
        what = "A, C and the given K" if o.K is not None else "A and C"
        err = InconclusiveError(
            f"stubborn: the solver reports LMIs {_refs(pl)} infeasible {where}, but (C, A) is "
            f"detectable and the nonzero entries of {what} span a factor {spread:.3g} (above "
            f"{SPREAD_MAX:g}): on data this badly scaled that status is no proof of "
            "infeasibility (rescale the states or the outputs)"
        )
        err.gain_bound_hint = o.K is None and o.gain_bound is not None  # type: ignore[attr-defined]
        raise err
    _bounds_too_tight(pl, o, where, det.verdict)


#: the spread of the plant's nonzero |entries| (A and C) above which a solver's `infeasible`
#: is not taken as a verdict (exit 4 instead of 1); the edge-shape trial's false verdicts
#: had 10⁶ … 10¹⁶, plants that certified 10⁴
SPREAD_MAX = 1e5


def _data_spread(pl: Plant, K: np.ndarray | None = None) -> float:
    """max / min of the nonzero |entries| of A, C and the given gain K (1 when there are
    none)."""
    parts = [np.asarray(pl.A, float).ravel(), np.asarray(pl.C, float).ravel()]
    if K is not None:
        parts.append(np.asarray(K, float).ravel())
    v = np.abs(np.concatenate(parts))
    v = v[(v > 0) & np.isfinite(v)]
    return float(v.max() / v.min()) if v.size else 1.0


def _unstable_gain(pl: Plant, where: str) -> None:
    """Exit 1: the given K does not make A − KC Hurwitz (Schur), decided exactly: the (1,1)
    block of (2) / (8) needs it, so no λ or R can help (the hint used to say "try a smaller λ
    or raise gain_bound", a key the redesign refuses — stubborn review)."""
    kind = "Schur (spectral radius < 1)" if pl.discrete else "Hurwitz"
    raise InfeasibleError(
        f"stubborn: LMIs {_refs(pl)} infeasible {where}: A − KC is not {kind} for the "
        "given K (exact test), which LMI "
        f"{'(8)' if pl.discrete else '(2)'} requires for every λ: give a K that makes A − KC "
        f"{kind}, or omit K to let the design choose it"
    )


def _bounds_too_tight(pl: Plant, o: Options, where: str, verdict: bool | None) -> None:
    """Exit 1 naming the bounds of the design to relax (the solver's `infeasible` on
    well-scaled data of a detectable plant)."""
    bounds = _bounds_text(o)
    # λ: the decay asked of V, λ·V in (1) (larger is harder) but λ·P in (7), where a
    # λ closer to 1 is weaker (random-spec fuzzer: the discrete hint said "smaller")
    lam_hint = ""
    if o.lam is not None:
        lam_hint = "a larger λ (closer to 1)" if pl.discrete else "a smaller λ"
    hints = [h for h in (lam_hint and f"try {lam_hint}", bounds and f"raise {bounds}") if h]
    relax_gain = o.K is None and o.gain_bound is not None
    if o.K is not None:
        # the given K may not be the obstacle: on ker C the (1,1) block of (1) does not depend
        # on K, so a λ beyond A's own decay there fails for every K (hard-case fuzzer: "the
        # given K does not allow it" at λ = 1000 with A ≈ −100·I)
        why = "(C, A) is detectable; with the given K (redesign: X = P K): " + " or ".join(
            [*hints, "omit K to let the design choose it"]
        )
    else:
        why = "(C, A) is detectable: " + (" or ".join(hints) or "no bound or λ to relax")
        if verdict is True and pl.discrete:
            free = replace(o, gain_bound=None, r_bound=None)
            # only the solver's `infeasible` is a verdict: its "solver failure" on a plant
            # feasible at λ = 1/3 by an exact witness (gain ≈ 1.2·10⁴) said "infeasible at any
            # λ … detectability does not suffice" instead of "raise gain_bound", exit 1
            # (stubborn review, session 42)
            if feasible(pl, free, 1 - 1e-6)[1] == INFEASIBLE:
                relax_gain = False  # infeasible without any bound: nothing to retry
                _slow_mode(pl, where)
                at = "at any λ ≤ 1 − 10⁻⁶ (the search's most lenient λ)"
                without = f" even without {bounds} and {at}" if bounds else f" {at}"
                why = (
                    f"(C, A) is detectable, but the LMIs are infeasible{without}: in discrete "
                    "time detectability does not suffice (the sector conditions of the "
                    "saturation, (8)-(9), also limit how unstable A may be; e.g. A = 2.6, "
                    "C = 1 has no solution): a faster sampling (A closer to I) or the "
                    "continuous-time model may help"
                )
    err = InfeasibleError(f"stubborn: LMIs {_refs(pl)} infeasible {where}: {why}")
    # the gain bound is among what to relax: the design tries it scale-free (see design())
    err.gain_bound_hint = relax_gain  # type: ignore[attr-defined]
    raise err


#: a stable mode of A with |μ|² above 1 − NEAR_ONE makes a discrete `infeasible` at the
#: search's λ = 1 − 10⁻⁶ no verdict (:func:`_slow_mode`)
NEAR_ONE = 1e-5


def _slow_mode(pl: Plant, where: str) -> None:
    """Exit 4 when the discrete LMIs (7)-(9), infeasible at the search's most lenient
    λ = 1 − 10⁻⁶, may be feasible closer to 1: a mode of A the output does not see bounds λ
    from below by |μ|² (its block of (7) is negative definite only for λ > |μ|²), so a stable
    mode with |μ|² within :data:`NEAR_ONE` of 1 may need a λ the search never tries (A =
    diag(0.9999999, 1.5), C = (0, 1) was exit 1 "infeasible at any λ < 1", feasible at
    λ = 0.9999999 by an exact witness; search-space/stubborn trial, session 31)."""
    mags = np.abs(np.linalg.eigvals(np.asarray(pl.A, float))) ** 2
    slow = mags[(mags < 1) & (mags > 1 - NEAR_ONE)]
    if slow.size:
        mu2 = float(slow.max())
        raise InconclusiveError(
            f"stubborn: the solver reports LMIs {_refs(pl)} infeasible {where}, the most "
            f"lenient λ of the search being 1 − 10⁻⁶; but A has a stable mode with |μ|² ≈ "
            f"{mu2:.10g} (float), within {NEAR_ONE:g} of 1: a mode the output does not see "
            "needs λ > |μ|², so a λ closer to 1 may be feasible: not a verdict (give "
            "[method] lambda between |μ|² and 1)"
        )


def _linear_decay_note(pl: Plant, K: Any) -> str:
    """A float note on how fast the unsaturated error e' = (A − KC)e decays: the LMIs bound
    no rate for e (λ is σ̄'s), and criterion K can make it very slow (the stubborn review: K ≈
    −2.4·10⁻⁷ for A = 0, certified, and the error did not move in 5 s)."""
    M = pl.A - np.asarray(to_float(K), dtype=float).reshape(pl.A.shape[0], -1) @ pl.C
    ev = np.linalg.eigvals(M)
    if pl.discrete:
        return (
            f"A − KC: spectral radius ≈ {float(np.max(np.abs(ev))):.4g} (float; the "
            "unsaturated error shrinks by about this factor per step)"
        )
    return (
        f"A − KC: spectral abscissa ≈ {float(np.max(ev.real)):.4g} (float; the unsaturated "
        "error decays about as exp of this times t)"
    )


def _stable_gain(spec: Spec, K: Any, discrete: bool) -> bool:
    """Whether A − KC is Hurwitz (continuous) or Schur (discrete), decided exactly (Routh /
    Schur–Cohn test of its characteristic polynomial): the (1,1) block He(P(A − KC)) of
    LMI (2) (resp. −P + (A − KC)ᵀP(A − KC) of (8)) needs it, for any λ."""
    from obsdesign.certify.detect import hurwitz_stable, schur_stable
    from obsdesign.lyap import fmat

    s = spec.system
    M = np.asarray(s.A.q, dtype=object) - np.asarray(K, dtype=object) @ np.asarray(
        s.C.q, dtype=object
    )
    poly = fmat(M).charpoly()
    return bool((schur_stable if discrete else hurwitz_stable)(poly)[0])


def _refs(pl: Plant) -> str:
    return "(7)-(9)" if pl.discrete else "(1)-(3)"
