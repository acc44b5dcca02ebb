"""Design of a set-invariant estimator (Dórea & Pimenta, "Design of set-invariant estimators
for linear discrete-time systems"): iterations → final polytope → exact parameters.

The iterations run in float64 (:mod:`.algorithms`, Sections V and VI); the final point cloud
is proved once (:func:`final_stage`: exact hull, Theorem 3.1 at every z of Z_d) and
:func:`polytope_params` derives every reported quantity from that polytope (injection table
of Proposition 4.1, admissible linear gains of Proposition 7.1). Without ``cdd.gmp`` the same
stages run in float64 (:mod:`.numerical`) and every claim is numerical.
"""

from __future__ import annotations

import dataclasses
import re
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q
from obsdesign.certify.printing import fmt_exact
from obsdesign.errors import InconclusiveError, InfeasibleError, SolverError
from obsdesign.methods.base import Design, Progress, SolverResult, SolverStatus
from obsdesign.params import Parameters
from obsdesign.sets import polytope_ops as po
from obsdesign.spec.models import Spec

from . import algorithms as al
from . import certificate as ce
from . import laws, lps, memo, numerical, scaling
from .budget import Timeout, check_deadline
from .linear import admissible_gains
from .options import Options
from .problem import Data, build, check_detectable


@dataclass
class Stage:
    """A proved polytope: facets ``G`` (rhs 1), its vertex representation, and the Theorem 3.1
    result (None for p > 1)."""

    G: np.ndarray
    vrep: Any
    res: Any


def final_stage(
    data: Data,
    P: np.ndarray,
    single: bool,
    lam: float,
    deadline: float | None = None,
    o: Options | None = None,
) -> Stage:
    """The polytope conv(Ω's vertices ∪ P), proved: Ω's vertices exactly, the other points
    snapped (po.snap), one exact hull (po.exact_hull) for G and the edges, then Theorem 3.1 at every
    z^l of Z_d with v^l from LP (9) (Section III, eq. (6), (9)). Without cdd.gmp: the float
    hull and Theorem 3.1 in float64 (numerical.float_stage).

    ``data``: float and exact problem; ``P``: float points (rows); ``single``: one output;
    ``lam``: λ (float, for the float-only stage); ``deadline``: ``time.perf_counter()`` value
    past which the exact stage does not start, or its Theorem 3.1 loop stops, with a
    SolverError naming ``o.time_limit`` (checked before the hull and between breakpoints; a
    cdd.gmp hull, needed only when the incidence proof of the float hull fails, runs in a
    child process killed at the deadline)."""
    fl, ex = data.fl, data.ex
    if ex is None:
        Gf, resf, vrf = numerical.float_stage(fl, P, lam)
        return Stage(Gf, vrf, resf)
    Vo_f = po.qfloat(ex.Vo)
    P = np.asarray(P, dtype=float).reshape(-1, fl.n)
    # float copies of Ω's vertices: within 1e-9 of Ω's extent per coordinate (an absolute
    # 1e-9 dropped every new point of an Ω of size 1e-9, and no copy of one of size 1e9)
    tol = 1e-9 * np.abs(Vo_f).max(axis=0)
    near = np.array([(np.abs(Vo_f - p) <= tol).all(axis=1).any() for p in P], dtype=bool)
    Pq = np.vstack([ex.Vo, po.rationalize(P[~near])]) if (~near).any() else ex.Vo
    limit = f"{o.time_limit:g} s ([method] time_limit)" if o is not None else "the budget"
    if deadline is not None and time.perf_counter() > deadline:
        raise SolverError(
            f"exact certificate not started within {limit}: the iterations used the budget "
            f"({len(P)} points to prove; raise time_limit, or a larger λ or Δδ)"
        )
    try:
        Gq, vrep = po.exact_hull(Pq, deadline=deadline)
    except po.HullTimeout:
        raise SolverError(
            f"exact certificate not finished within {limit}: the exact hull of {len(Pq)} "
            "points (the repair of qhull's facets or the cdd.gmp run) was stopped (raise "
            "time_limit, or a larger λ or Δδ for a smaller polyhedron)"
        ) from None
    if not single:
        return Stage(Gq, vrep, None)
    try:
        v_rows = _merged(Pq, deadline)
    except Timeout:
        raise SolverError(
            f"exact certificate not finished within {limit}: the float hull of the "
            f"{len(Pq)} exact points (for LP (9)) was stopped (raise time_limit, or a larger λ "
            "or Δδ for a smaller polyhedron)"
        ) from None
    try:
        res = ce.theorem31(
            ex, Gq, v_solver=lps.eps_batch, vrep=vrep, deadline=deadline, v_rows=v_rows
        )
    except ce.BudgetExceeded as e:
        raise SolverError(
            f"exact certificate not finished within {limit}: Theorem 3.1 checked at {e} of "
            f"{2 * len(vrep.V)} or fewer breakpoints of a {len(Gq)}-facet polyhedron (raise "
            "time_limit, or a larger λ or Δδ for a smaller polyhedron)"
        ) from None
    return Stage(Gq, vrep, res)


def eps_vs_lam(what: str, eps: float, lam: fmpq) -> str:
    """``"{what} ≈ ε > λ = …"`` for a float ε (a contractivity of eq. (22), set-invariant
    paper) against the spec's exact λ: λ as given (``{lam:g}`` printed λ = 0.9999999 as
    "λ = 1": re-check trial, session 31); ε with the fewest digits (from 6, and more than
    λ's own) whose decimal lies on ε's side of λ, and "≤" when it is not above; within 4
    ulps of λ, ``"{what} = λ = … in floats"`` (10⁻⁶² above printed "0.9 > λ = 0.9": review
    19)."""
    lam_text = fmt_exact(lam)
    if not np.isfinite(eps):
        return f"{what} = {eps:g}, λ = {lam_text}"
    if abs(eps - float(lam)) <= 4 * np.spacing(float(lam)):
        return f"{what} = λ = {lam_text} in floats"
    above = Q(eps) > lam
    # more than λ's own digits: "ε ≈ 1 > λ = 0.9999999" is true but shows nothing
    first = max(6, len(re.sub(r"\D", "", lam_text).lstrip("0")) + 1)
    text = next((t for d in range(first, 18) if (Q(t := f"{eps:.{d}g}") > lam) == above), repr(eps))
    return f"{what} ≈ {text} {'>' if above else '≤'} λ = {lam_text}"


def _final_of(
    r: al.IterResult, data: Data, single: bool, lam: float, dl: float, o: Options
) -> Stage:
    """:func:`final_stage` of an iteration's last cloud. For a run that did not converge, a
    final stage that cannot finish (the budget, an LP beyond HiGHS) ends the design as not
    converged, exit 1, not as a solver failure (a diverging run whose last 381-facet
    polyhedron plainly failed Theorem 3.1 used the budget on it and ended with exit 3;
    scaling trial, session 26)."""
    try:
        return final_stage(data, r.P, single, lam, dl, o)
    except SolverError as e:
        if r.converged:
            raise
        how = "diverges" if r.diverged else "did not converge"
        raise InfeasibleError(
            f"not converged: the iteration {how} after {r.iterations} iterations "
            f"({eps_vs_lam('last ε', r.eps, o.lam)}), and the exact check of its last "
            f"polyhedron did not finish ({e.message}), so it is not reported"
        ) from None


def _merged(Pq: np.ndarray, deadline: float | None = None) -> np.ndarray | None:
    """The float hull's rows of the exact points (near-coplanar facets merged: 492 rows
    where the exact hull has 548 on a random 3-state system), for LP (9); None if qhull
    fails. The budget is looked at inside the hull (:class:`~.budget.Timeout` past
    ``deadline``: the 9-cube's ran 49-56 s with none; re-check review 47)."""
    check = None if deadline is None else (lambda: check_deadline(deadline))
    try:
        return po.hull(po.qfloat(Pq), with_edges=False, check=check).G
    except po.PolytopeError:
        return None


@dataclass
class _Run:
    """What the iterations produced: the proved stage, iteration count, notes, history."""

    stage: Stage
    iterations: int
    converged: bool
    notes: list[str] = field(default_factory=list)
    history: list[dict[str, float]] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)


def _budget(r: al.IterResult, o: Options, run: _Run) -> None:
    """Stop the design when the iterations ran out of time (``[method] time_limit``): a
    SolverError (exit 3) saying how far they got, instead of running for minutes. A run that
    diverged (:data:`algorithms.GROWTH_MAX`) gets a note saying so (it is reported not
    converged, exit 1, with its last polyhedron)."""
    if r.diverged:
        where = (
            r.why or f"a new vertex lies more than {al.GROWTH_MAX:g} times Ω's size from the origin"
        )
        run.notes.append(
            f"the general algorithm diverges: after {r.iterations} iterations {where} "
            f"({eps_vs_lam('last ε', r.eps, o.lam)}); stopped there, not converged"
        )
    if r.timed_out:
        if not len(r.G):  # stopped in its first hull (algorithms._unfinished)
            last = r.why or f"the first hull of {len(r.P)} points did not finish"
        elif np.isfinite(r.eps):
            last = eps_vs_lam("last ε", r.eps, o.lam) + f" with {len(r.G)} facets"
        else:
            last = f"no iteration finished, {len(r.G)} facets"
        raise SolverError(
            f"not converged within {o.time_limit:g} s ([method] time_limit) / {r.iterations} "
            f"iterations: {last} (raise time_limit, or a larger λ or Δδ)"
        )


def _strict_retries(
    run: _Run,
    data: Data,
    single: bool,
    lam: float,
    dd: float,
    dl: float,
    o: Options,
    progress: Progress | None,
) -> None:
    """The strict continuation: up to three runs of the general algorithm scaled by
    λ/(1 + margin) from the last polyhedron, the margin at least twice the last
    float-vs-exact gap (one try judged by the float LP (9) alone ended "converged" with the
    exact factor 2·10⁻⁸ above λ = 1 at delta_tol = 1e-9, below what the LP resolves: census
    46). The first retry that converges with its factor certified ≤ λ is reported. Otherwise
    the finished polyhedron with the lowest certified factor stands, with its iteration count
    and history: a retry that ran out of the time budget, failed in a solver or a hull,
    reached ``max_iterations`` or diverged is dropped with a note saying which (a retry's
    timeout replaced an exit-1 report by exit 3 with no polyhedron, and a retry's unfinished
    exact check did so still, with its history and a "diverges" note left in the report:
    re-check reviews 46, 47)."""
    fl, hist = data.fl, run.history
    best = (run.stage, run.iterations, run.converged, len(hist))
    margin = dd
    for tries_left in (2, 1, 0):
        V0 = po.qfloat(run.stage.vrep.V) if data.ex is not None else run.stage.vrep.V
        try:
            r = al.general(
                fl, lam / (1 + margin), lam * (1 - 1e-12), o.max_iterations, o.mirror,
                start=V0, progress=progress, it0=run.iterations, history=hist, deadline=dl,
            )  # fmt: skip
            _budget(r, o, _Run(run.stage, run.iterations, run.converged))  # raises past dl
            if not r.converged:
                how = (
                    "diverges" + (f" ({r.why})" if r.why else "")
                    if r.diverged
                    else f"reached its max_iterations = {o.max_iterations}"
                )
                run.notes.append(
                    f"the strict retry {how} after {r.iterations} iterations in all, not "
                    "converged: the best polyhedron before it is reported"
                )
                break
            stage = final_stage(data, r.P, single, lam, dl, o)
        except (SolverError, InfeasibleError, InconclusiveError) as e:
            # InconclusiveError: an LP beyond HiGHS's range in a retry ended the design with
            # exit 4 and no polyhedron (re-check review 47)
            run.notes.append(
                f"the strict retry stopped ({e.message}): the best polyhedron before it is reported"
            )
            break
        except po.PolytopeError as e:
            run.notes.append(
                f"the strict retry stopped (a float polytope computation failed: {e}): the "
                "best polyhedron before it is reported"
            )
            break
        run.iterations, run.converged, run.stage = r.iterations, r.converged, stage
        res = stage.res
        if res is not None and res.ok:
            return
        if res is None:  # no exact result (cannot happen with the exact data that started it)
            break
        if res.factor < best[0].res.factor:
            best = (run.stage, run.iterations, run.converged, len(hist))
        if not tries_left:
            break
        gap = float(res.factor) / float(lam) - 1
        margin = max(2 * margin, 2 * gap)
        run.notes.append(
            f"the exact factor {float(res.factor):.12g} is still above λ (by {gap:.3g} "
            f"relative, more than delta_tol = {dd:g}: the float LP's accuracy): iterating "
            f"again with the margin {margin:.3g}"
        )
    if best[0] is not run.stage:
        run.notes.append(
            "the strict retries did not certify λ: the polyhedron with the lowest certified "
            "factor is reported"
        )
    run.stage, run.iterations, run.converged, kept = best
    del hist[kept:]  # the dropped retries' iterations


def _iterate(
    spec: Spec, data: Data, progress: Progress | None, deadline: float | None = None
) -> _Run:
    """The algorithm of the spec: symmetric C_K^∞ (Section VI; condition (14)), general
    (Section V; stopping rule ε^i ≤ λ(1 + Δδ)) or none (Ω itself); the symmetric-to-general
    fallback (Example 7.2) and the strict continuation until the certified factor is ≤ λ."""
    o: Options = spec.options
    fl = data.fl
    single = spec.system.p == 1
    lam, dd = float(o.lam), float(o.delta_tol)
    # the budget of the whole design (from its start: ``deadline``)
    dl = deadline if deadline is not None else time.perf_counter() + o.time_limit
    run = _Run(Stage(np.zeros((0, fl.n)), None, None), 0, True)
    hist = run.history
    sym_failed = False
    if o.algorithm == "none":
        run.iterations = 1
        run.stage = final_stage(data, np.zeros((0, fl.n)), single, lam, dl, o)
    elif o.algorithm == "symmetric":
        r = al.symmetric(
            fl, lam, lam * (1 + dd), o.max_iterations, progress, history=hist, deadline=dl
        )
        _budget(r, o, run)
        run.iterations, run.converged = r.iterations, r.converged
        run.stage = _final_of(r, data, single, lam, dl, o)
        res = run.stage.res
        if r.converged and single and res is not None and not res.ok:
            sym_failed = True
            try:
                _, epsz = lps.epsilon_profile(r.G, fl.A, fl.B1, fl.C[0], fl.Dv, fl.eta, deadline=dl)
            except Timeout:
                raise SolverError(
                    f"not converged within {o.time_limit:g} s ([method] time_limit) / "
                    f"{r.iterations} iterations: the symmetric C_K^∞ meets condition (14) but "
                    "not Theorem 3.1, and its ε profile was not finished (raise time_limit, or "
                    "a larger λ or Δδ)"
                ) from None
            sym_eps = float(np.max(epsz))
            run.extra.update(
                symmetric_G=run.stage.G,
                symmetric_iterations=r.iterations,
                symmetric_contractivity=sym_eps,
            )
            # floats may not resolve the excess (A₁₁ = 0.7 + 1e-61 printed "0.9 > λ = 0.9")
            excess = eps_vs_lam("max ε(z)", sym_eps, o.lam)
            if " > λ" not in excess:
                excess += (", " if excess.endswith("floats") else " in floats, ") + (
                    "exceeded in exact arithmetic"
                )
            msg = (
                f"the symmetric C_K^∞ meets condition (14) after {r.iterations} iterations but "
                f"not Theorem 3.1: {excess}"
            )
            run.notes.append(msg)
            if progress:
                progress(msg)
            if o.fallback == "general":
                r = al.general(
                    fl, lam / (1 + dd), lam, o.max_iterations, o.mirror,
                    start=r.P, progress=progress, it0=r.iterations, history=hist,
                    deadline=dl,
                )  # fmt: skip
                _budget(r, o, run)
                run.iterations, run.converged = r.iterations, r.converged
                run.stage = _final_of(r, data, single, lam, dl, o)
                run.notes.append(
                    f"general algorithm (Section V) continued from C_K^∞: {r.iterations} "
                    "iterations in all"
                )
    else:
        lam_run = lam / (1 + dd) if o.strict else lam
        lam_stop = lam if o.strict else lam * (1 + dd)
        r = al.general(
            fl, lam_run, lam_stop, o.max_iterations, o.mirror, progress=progress, history=hist,
            deadline=dl,
        )  # fmt: skip
        _budget(r, o, run)
        run.iterations, run.converged = r.iterations, r.converged
        run.stage = _final_of(r, data, single, lam, dl, o)
    res = run.stage.res
    if single and o.strict and run.converged and res is not None and not res.ok:
        # within 2Δδ of λ, or within the float LP's accuracy (~1e-8) for a tiny Δδ: the
        # retry never started at delta_tol ≤ 5e-9 with the factor 2e-8 above λ (re-check
        # review 46)
        if o.algorithm != "none" and float(res.factor) <= lam * (1 + max(2 * dd, 1e-7)):
            if not sym_failed or o.fallback == "general":
                run.notes.append(
                    f"certified factor {float(res.factor):.9g} > λ: iterating with the hull "
                    "scaled by λ/(1 + Δδ) until the certified factor is <= λ"
                )
                # up to three tries, the margin at least twice the last float-vs-exact gap:
                # one try judged by the float LP (9) alone ended "converged" with the exact
                # factor 2·10⁻⁸ above λ = 1 at delta_tol = 1e-9, below what the LP resolves
                # (census 46)
                # the best finished polyhedron stands when a retry runs out of the time budget
                # or ends worse: a retry's timeout replaced an exit-1 report by exit 3 with no
                # polyhedron (re-check review 46)
                _strict_retries(run, data, single, lam, dd, dl, o, progress)
    return run


def _unscale(run: _Run, s: list[fmpq]) -> None:
    """Map what the iterations proved in ẽ = S⁻¹e (:mod:`.scaling`) back to the spec's
    coordinates, exactly: G̃S⁻¹, SṼ (same order, so the edges stand), v^l = S ṽ^l."""
    st = run.stage
    vrep = None
    if st.vrep is not None:
        vrep = dataclasses.replace(st.vrep, V=scaling.unscale_points(st.vrep.V, s))
    run.stage = Stage(scaling.unscale_rows(st.G, s), vrep, scaling.unscale_result(st.res, s))
    if "symmetric_G" in run.extra:
        run.extra["symmetric_G"] = scaling.unscale_rows(run.extra["symmetric_G"], s)


def _vec_text(M: np.ndarray) -> str:
    """An exact matrix as a flat list of 4 significant digits for a note (a fixed number of
    decimals showed a gain of 10⁻³⁰¹ as 0.0), marked "≈" when an entry is not its exact
    value (four vertices of a polygon 10⁻²⁴ wide printed as two equal pairs, unmarked;
    set-invariant trial, session 31)."""
    exact = np.asarray(M, dtype=object).reshape(-1)
    shown = [f"{x:.4g}" for x in np.asarray(po.qfloat(M), dtype=float).reshape(-1)]
    rounded = any("inf" in t or Q(t) != Q(q) for t, q in zip(shown, exact, strict=True))
    return ("≈" if rounded else "") + "[" + ", ".join(shown) + "]"


def polytope_params(
    spec: Spec,
    data: Data,
    stage: Stage,
    notes: list[str],
    scaled: tuple[Data, Stage, list[fmpq]] | None = None,
) -> Parameters:
    """Every reported quantity derived from a proved polytope: G, V, the certified factor and
    the injection table of Proposition 4.1 (breakpoints = Z_d, v^l, and the interpolation (12)
    L^j, w^j) for one output, and the admissible linear gains of Proposition 7.1 (p = n − 1).

    ``spec``: the bound spec; ``data``: its float/exact problem; ``stage``: the polytope;
    ``notes``: report notes (appended to); ``scaled``: the design's coordinates (data, the
    same polytope there, s of :mod:`.scaling`), where the linear gains are chosen and mapped
    back (L = S L̃)."""
    o: Options = spec.options
    s = spec.system
    exact = data.ex is not None
    G, V, res = stage.G, stage.vrep.V, stage.res
    params = Parameters()
    params["G"] = G
    params["V"] = V
    params["lambda"] = o.lam
    params["facets"] = len(G)
    params["vertices"] = len(V)
    if res is not None:
        dt = object if exact else float
        params["contractivity"] = res.factor
        params["breakpoints"] = np.array(res.zs, dtype=dt)
        params["v_breakpoints"] = np.array(res.vs, dtype=dt).reshape(len(res.zs), s.n)
        if len(res.zs) > 1:
            Ls, ws = laws.pieces(list(res.zs), [list(v) for v in res.vs])
            params["L_pieces"] = np.array(Ls, dtype=dt)
            params["w_pieces"] = np.array(ws, dtype=dt)
        if res.exact_lp:
            notes.append(
                f"{res.exact_lp} breakpoint injections came from the exact (cdd.gmp) LP (9)"
            )
    if o.linear_law and s.p == s.n - 1:
        if data.ex is None:
            gs = numerical.float_gains(data.fl, float(o.lam), G, V)
        elif scaled is not None:
            work, found, sc = scaled
            gs = scaling.unscale_gains(admissible_gains(work.ex, found.G, found.vrep.V), sc)
        else:
            gs = admissible_gains(data.ex, G, V)
        if gs.L is not None:
            params["L"] = gs.L
            params["L_factor"] = gs.factor
            if gs.vertices:
                params["L_admissible_vertices"] = np.array(
                    [v.reshape(-1) for v in gs.vertices], dtype=object
                )
            notes.append(f"linear law v = L z: {gs.how}")
            if len(gs.vertices) > 1:
                vs_txt = "; ".join(_vec_text(v) for v in gs.vertices)
                notes.append(
                    f"admissible linear gains: the convex hull of {len(gs.vertices)} vertices "
                    f"({vs_txt}); dimension {gs.dimension}"
                )
            for i, Lp in gs.prop71:
                notes.append(
                    f"Proposition 7.1 with Q_I = row {i + 1} of G (counted from 1) gives L = "
                    f"{_vec_text(Lp)}"
                )
        else:
            notes.append(f"no linear law: {gs.how}")
    if o.L is not None:
        params["L_user"] = o.L
    return params


def design(spec: Spec, progress: Progress | None = None) -> Design:
    """Design for a bound spec: the algorithm of Section V or VI, the exact final stage, the
    injection table (Proposition 4.1) and linear gains (Proposition 7.1).

    Every stage runs in Ω-unit coordinates (:mod:`.scaling`: ẽ = S⁻¹e, S = diag of Ω's
    exact extents) and the proved polytope is mapped back exactly (:func:`_unscale`).

    ``spec``: the bound spec; ``progress``: optional callback for progress lines. Raises
    InfeasibleError when (C, A) has a mode faster than λ that the output cannot see
    (Section II)."""
    o: Options = spec.options
    t0 = time.perf_counter()
    try:
        # one budget from here: Ω's exact vertices (a child process from 8 states) count
        deadline = time.perf_counter() + o.time_limit
        try:
            data = build(spec, deadline)
        except Timeout:
            raise SolverError(
                f"not converged within {o.time_limit:g} s ([method] time_limit) / 0 "
                "iterations: Ω's exact vertices were not found (raise time_limit)"
            ) from None
        check_detectable(spec.system.A.q, spec.system.C.q, o.lam)
        work, s = scaling.scaled(data)
        run = _iterate(spec, work, progress, deadline)
        found = run.stage  # in the design's coordinates
        if s is not None:
            _unscale(run, s)
    except po.PolytopeError as e:
        # a float hull or vertex enumeration that qhull cannot do (a set thinner or larger
        # than float arithmetic resolves, e.g. Q = [[1e50, 0], [0, 1]]): numerically
        # inconclusive (exit 4), not an internal failure
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        sets = f"[sets.{o.omega}]" + (f", [sets.{o.disturbance}]" if o.disturbance else "")
        raise InconclusiveError(
            f"{spec.file}: a float polytope computation failed: {first} (a set of the spec, "
            f"{sets}, the noise bound eta_bar, the plant's A or [method] lambda = "
            f"{float(o.lam):.3g} may be too thin, too small or too large for float arithmetic)"
        ) from e
    notes = list(run.notes)
    # the linear gains are chosen where the polytope was found (the max-margin LP is not
    # scale-free: a diagonally rescaled spec got another L; scaling trial, session 26)
    params = polytope_params(spec, data, run.stage, notes, None if s is None else (work, found, s))
    params["iterations"] = run.iterations
    params["converged"] = bool(run.converged)
    for k, v in run.extra.items():
        params[k] = v
    if spec.system.p != 1 and "L" not in params and run.history:
        params["contractivity_14"] = run.history[-1]["eps"]
    params["history_facets"] = [h["facets"] for h in run.history]
    params["history_eps"] = [h["eps"] for h in run.history]
    if not run.converged:
        notes.append(
            f"NOT CONVERGED after {run.iterations} iterations in all (max_iterations = "
            f"{o.max_iterations} for each algorithm that ran); the last polyhedron is reported"
        )
    name = "HiGHS (scipy) LPs + qhull hulls; " + (
        "cdd.gmp exact" if data.ex is not None else "float64 only (no cdd.gmp)"
    )
    solver = SolverResult(
        name,
        SolverStatus.OPTIMAL if run.converged else SolverStatus.FAILED,
        f"{'converged' if run.converged else 'not converged'} after {run.iterations} iterations",
        time.perf_counter() - t0,
    )
    if data.ex is None:
        notes.append(numerical.NOTE)
    else:
        _record(data, run.stage, params)
    return Design(params, solver, notes)


def _record(data: Data, stage: Stage, params: Parameters) -> None:
    """Hand the exact facts the final stage proved to ``certify`` of this very ``params``
    object (:mod:`.memo`): conv(V) = {G e <= 1} with every point of V a vertex (the last
    exact hull ran on exactly V), and Theorem 3.1's exact maximum for the reported v^l at
    Z_d. Keyed by the exact inputs, so a changed parameter or spec recomputes."""
    if stage.vrep is None:
        return
    rec = memo.Recorder()
    G, V = stage.G, stage.vrep.V
    rec.put("forms", memo.fingerprint(G, V), (True, po.forms_detail(len(V), len(G)), stage.vrep))
    res = stage.res
    if res is not None:
        key = memo.fingerprint(G, V, list(res.zs), [list(v) for v in res.vs])
        rec.put(
            "theorem31",
            (memo.problem_key(data.ex), key),
            dataclasses.replace(res, exact_lp=0, notes=[]),
        )
    memo.attach(params, rec)
