"""The iterated convex-hull algorithms of Sections V and VI (Dórea & Pimenta, paper 003).

Both run in float64 on a point cloud ``P`` whose hull is the current polyhedron ``C^i``
(``Ω``'s vertices are always kept in ``P``, so ``Ω ⊆ C^i`` whatever the hull merges). New
points are floats, so nothing grows like exact iterated hulls do; the final polyhedron is
proved exactly by :mod:`.certificate`.

* :func:`general` — Section V, steps 1-9: at the worst breakpoint z^l (max of ε(z^l), LP (9))
  the image ``Q^i = A·S(z^l) + B1·D + v^l`` of the slice is added, scaled by 1/λ:
  ``C^{i+1} = Conv(C^i ∪ (1/λ) Q^i)``. Option ``mirror`` also adds ``−(1/λ) Q^i`` (keeps a
  symmetric start symmetric; converges in fewer iterations on Example 7.2).
* :func:`symmetric` — Section VI: steps 2-5 become "compute φ_q(0) and ε = max_i(φ_q,i(0) +
  ξ_i)" (condition (14)), and ``Q^i = A·S(0) + B1·D`` with S(0) = {|Q^i e| <= 1, |C e| <= η̄};
  converges to C_K^∞(Ω, D, λ).

Stopping: ε^i <= ``lam_stop`` (the paper's rule is λ(1 + Δδ)), or the iteration cap.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from obsdesign.errors import SolverError
from obsdesign.sets import polytope_ops as po

from . import lps
from .budget import Timeout, check_deadline

Progress = Callable[[str], None]


@dataclass
class Problem:
    """Float data of one design: x⁺ = A x + B1 d, z = C e + η, Ω = {G0 e <= 1}, D = conv(Dv)."""

    A: np.ndarray
    B1: np.ndarray
    C: np.ndarray
    G0: np.ndarray
    Dv: np.ndarray
    eta: float

    @property
    def n(self) -> int:
        return self.A.shape[0]

    @property
    def p(self) -> int:
        return self.C.shape[0]


@dataclass
class IterResult:
    """Outcome of an algorithm run: the last polyhedron and how it got there."""

    G: np.ndarray
    P: np.ndarray
    eps: float
    iterations: int
    converged: bool
    history: list[dict[str, float]] = field(default_factory=list)
    #: stopped at the time budget (``deadline``), not at the iteration cap
    timed_out: bool = False
    #: stopped because the polyhedron grew past :data:`GROWTH_MAX` times Ω's size, or past
    #: :data:`LP_GROWTH` times it with LP (9) failing there
    diverged: bool = False
    #: why it was stopped as diverging (for the report's note)
    why: str = ""


#: the general algorithm stops, not converged, when a new vertex lies more than this many
#: times Ω's largest vertex norm from the origin: the iteration is diverging (the soundness
#: audit's A = [[0.14, 0], [726.54, 0.12]] grew to 10²⁰ and ended with exit 4 "out of a float
#: LP's range"); a polyhedron that size is beyond what the float LPs and hulls resolve anyway
GROWTH_MAX = 1e10
#: a failure of HiGHS on LP (9) while the polyhedron lies more than this many times Ω's size
#: from the origin is the iteration diverging, not a solver failure (a 3-state system at
#: 3·10⁹ Ω-units ended with exit 3 "HiGHS failed on LP (9)"; scaling trial, session 26)
LP_GROWTH = 1e6


def _drop_inside(
    img: np.ndarray, G: np.ndarray, tol: float, deadline: float | None = None
) -> np.ndarray:
    """Keep only the new points that stick out of {G e <= 1} by more than ``tol``, in blocks
    of points with the budget checked between them (:class:`Timeout` past ``deadline``)."""
    if len(img) == 0:
        return img
    step = max(1, po.BLOCK_ENTRIES // max(1, len(G)))
    keep = np.empty(len(img), dtype=bool)
    for a in range(0, len(img), step):
        check_deadline(deadline)
        keep[a : a + step] = (img[a : a + step] @ G.T).max(axis=1) > 1 + tol
    return img[keep]


def _hull(P: np.ndarray, deadline: float | None) -> po.HullState:
    """The iteration's hull, the budget checked inside it (while qhull runs, too). The first
    iteration's hull was exempt, so that a run always had a polyhedron; but a run stopped by
    the budget reports none anyway (exit 3), and the exemption let the first hull of a
    9-state design with ``time_limit = 10`` run 66 s (re-check review 46): a first hull
    stopped by the budget is :func:`_unfinished`."""
    if deadline is None:
        return po.hull(P)
    return po.hull(P, check=lambda: check_deadline(deadline))


def _unfinished(P: np.ndarray, it: int, hist: list, spent: bool = False) -> IterResult:
    """The run stopped by the budget in its first hull (of the points ``P``): no polyhedron
    (``G`` has no rows), ``it`` iterations done, ε unknown (inf); ``spent``: the budget was
    used up before the run began (a continuation after a long exact check: "the first hull
    … did not finish" named a hull that never started; re-check review 47)."""
    why = "the budget was used up before this run began" if spent else ""
    return IterResult(
        np.zeros((0, P.shape[1])), P, np.inf, it, False, hist, timed_out=True, why=why
    )


def _eps_screened(
    G: np.ndarray,
    phi: np.ndarray,
    dl: np.ndarray,
    zs: np.ndarray,
    prev: tuple[np.ndarray, np.ndarray] | None,
    lam_stop: float,
    deadline: float | None = None,
) -> lps.EpsResult:
    """ε(z^l) of LP (9), solving the LP only where needed.

    For any v, max_i(φ_i + δ_i + G_i v) >= ε(z) (LP (9) is a minimum over v), so the
    previous iteration's injections, interpolated at the new z^l, give upper bounds. Where the
    bound is <= the stopping level the LP is skipped (that z cannot be the worst violator,
    and the bound is reported as its ε); the LP is solved at the other z^l. The worst z and
    the stopping decision are therefore the same as with all LPs solved."""
    if prev is None or len(prev[0]) < 2:
        return lps.eps_batch(G, phi, dl, deadline=deadline)
    zp, vp = prev
    vi = np.stack([np.interp(zs, zp, vp[:, k]) for k in range(vp.shape[1])], axis=1)
    ub = (phi + dl[None, :] + vi @ G.T).max(axis=1)
    need = np.nonzero(ub > lam_stop)[0]
    eps, v = ub.copy(), vi
    if len(need):
        er = lps.eps_batch(G, phi[need], dl, deadline=deadline)
        better = er.eps < ub[need]
        eps[need] = np.where(better, er.eps, ub[need])
        v[need] = np.where(better[:, None], er.v, vi[need])
    return lps.EpsResult(eps, v)


def centred(Dv: np.ndarray) -> np.ndarray:
    """D's vertices less their mean c, for the general algorithm's iterations.

    The paper assumes 0 ∈ D (Section III, "Ω and D are compact, convex polyhedra containing
    the origin"); the spec may not. With D = c + D₀ the injection absorbs the offset:
    max_i(φ_i + δ_i + G_i v) is the same with v' = v + B1·c over D₀, so ε(z) of LP (9) and the
    stopping rule do not change, but the image Q^i = A·S(z^l) + B1·D + v^l of step 7 depends on
    which of LP (9)'s many optimal v^l HiGHS returns, and with D off the origin that choice made
    a rotation with D = [0.01, 0.03] diverge (ε ≈ 2.94 after 21 iterations) where D = [−0.01,
    0.01] converges in 2 (set-invariant trial, session 39). Centring makes the iterations the
    same for D and any translate of it. Only the float iterations use it: the final polyhedron
    is proved exactly against the spec's own D, with v^l from LP (9) over it."""
    return Dv - Dv.mean(axis=0) if len(Dv) else Dv


def general(
    pb: Problem,
    lam_run: float,
    lam_stop: float,
    max_iter: int,
    mirror: bool = False,
    start: np.ndarray | None = None,
    progress: Progress | None = None,
    drop_tol: float = 1e-10,
    it0: int = 0,
    history: list | None = None,
    deadline: float | None = None,
) -> IterResult:
    """General algorithm, Section V steps 1-9 (single output). ``start`` is an optional
    point cloud to start from (it is merged with Ω's vertices); ``deadline``: a
    ``time.perf_counter()`` value after which the run stops, not converged, with
    ``timed_out`` set."""
    c = pb.C.reshape(-1)
    Vo = po.h_to_v(pb.G0).V
    P = Vo if start is None else np.vstack([start, Vo])
    too_far = GROWTH_MAX * float(np.max(np.linalg.norm(Vo, axis=1)))
    hist = [] if history is None else history
    Dv = centred(pb.Dv)
    Bd = Dv @ pb.B1.T if pb.B1.shape[1] else np.zeros((1, pb.n))
    eps_l = np.inf
    st = None
    prev: tuple[np.ndarray, np.ndarray] | None = None
    spent = deadline is not None and time.perf_counter() > deadline
    for it in range(it0 + 1, it0 + max_iter + 1):
        try:
            nxt = _hull(P, deadline)
        except Timeout:  # the budget ran out in the hull of the grown cloud
            if st is None:
                return _unfinished(P, it - 1, hist, spent)
            return IterResult(st.G, st.V, eps_l, it - 1, False, hist, timed_out=True)
        st = nxt
        P, G = st.V, st.G
        dl = lps.delta(G, pb.B1, Dv)
        zs = lps.z_d(P, c, pb.eta)  # step 3
        try:
            phi, slices = lps.phi_at(G, pb.A, P, st.edges, c, pb.eta, zs, deadline)  # step 4a
            er = _eps_screened(G, phi, dl, zs, prev, lam_stop, deadline)  # step 4b
        except Timeout:  # the budget ran out inside the iteration
            return IterResult(G, P, eps_l, it - 1, False, hist, timed_out=True)
        except SolverError as e:
            size = float(np.max(np.linalg.norm(P, axis=1)))
            if not size > LP_GROWTH * float(np.max(np.linalg.norm(Vo, axis=1))):
                raise
            why = f"LP (9) failed ({e.message}) on a polyhedron {size:.3g} from the origin"
            return IterResult(G, P, eps_l, it - 1, False, hist, diverged=True, why=why)
        prev = (zs, er.v)
        l = int(np.argmax(er.eps))  # step 5
        eps_l = float(er.eps[l])
        hist.append({"iteration": it, "facets": len(G), "vertices": len(P), "eps": eps_l})
        if progress:
            progress(f"general: iteration {it}, {len(G)} facets, eps = {eps_l:.6f}")
        if eps_l <= lam_stop:  # step 6
            return IterResult(G, P, eps_l, it, True, hist)
        if deadline is not None and time.perf_counter() > deadline:
            return IterResult(G, P, eps_l, it, False, hist, timed_out=True)
        img = slices[l] @ pb.A.T + er.v[l]  # step 7
        img = po.minkowski_points(img, Bd) / lam_run  # step 8
        if mirror:
            img = np.vstack([img, -img])
        if len(img) and not float(np.max(np.linalg.norm(img, axis=1))) <= too_far:
            return IterResult(G, P, eps_l, it, False, hist, diverged=True)
        try:
            P = np.vstack([P, _drop_inside(img, G, drop_tol, deadline)])
        except Timeout:
            return IterResult(G, P, eps_l, it, False, hist, timed_out=True)
    assert st is not None
    return IterResult(st.G, st.V, eps_l, it0 + max_iter, False, hist)


def symmetric(
    pb: Problem,
    lam_run: float,
    lam_stop: float,
    max_iter: int,
    progress: Progress | None = None,
    drop_tol: float = 1e-10,
    it0: int = 0,
    start: np.ndarray | None = None,
    history: list | None = None,
    deadline: float | None = None,
) -> IterResult:
    """Symmetric algorithm of Section VI: condition (14) at z = 0 with v = 0 (``deadline``
    as in :func:`general`).

    D is symmetrized (D ∪ −D), which only enlarges it: the paper assumes |E d| <= 1."""
    c = pb.C.reshape(-1) if pb.p == 1 else None
    Vo = po.h_to_v(pb.G0).V
    P = np.vstack([Vo, -Vo]) if start is None else np.vstack([start, -start, Vo, -Vo])
    Dv = np.vstack([pb.Dv, -pb.Dv]) if len(pb.Dv) else pb.Dv
    Bd = Dv @ pb.B1.T if pb.B1.shape[1] else np.zeros((1, pb.n))
    hist = [] if history is None else history
    eps = np.inf
    st = None
    spent = deadline is not None and time.perf_counter() > deadline
    for it in range(it0 + 1, it0 + max_iter + 1):
        try:
            nxt = _hull(P, deadline)
        except Timeout:  # the budget ran out in the hull of the grown cloud
            if st is None:
                return _unfinished(P, it - 1, hist, spent)
            return IterResult(st.G, st.V, eps, it - 1, False, hist, timed_out=True)
        st = nxt
        P, G = st.V, st.G
        xi = lps.delta(G, pb.B1, Dv)  # (13)
        if c is not None:
            S = po.slice_points(P, st.edges, c, -pb.eta, pb.eta)
            if len(S) == 0:
                # λ = 1e-17 left a polytope whose slice has no point in floats: numpy's
                # "zero-size array to reduction" was an internal failure, exit 3 (set-invariant
                # trial, session 39); the design reports a float computation that failed
                raise po.PolytopeError(
                    "the slice |c·x| ≤ η of the polytope has no point in float arithmetic"
                )
            phi0 = (G @ pb.A @ S.T).max(axis=1)
        else:
            phi0, S = lps.phi_slice_general(G, pb.A, pb.C, pb.eta)
        eps = float((phi0 + xi).max())  # condition (14)
        hist.append({"iteration": it, "facets": len(G), "vertices": len(P), "eps": eps})
        if progress:
            progress(f"symmetric: iteration {it}, {len(G)} facets, eps(14) = {eps:.6f}")
        if eps <= lam_stop:
            return IterResult(G, P, eps, it, True, hist)
        if deadline is not None and time.perf_counter() > deadline:
            return IterResult(G, P, eps, it, False, hist, timed_out=True)
        img = po.minkowski_points(S @ pb.A.T, Bd) / lam_run
        img = np.vstack([img, -img])
        try:
            P = np.vstack([P, _drop_inside(img, G, drop_tol, deadline)])
        except Timeout:
            return IterResult(G, P, eps, it, False, hist, timed_out=True)
    assert st is not None
    return IterResult(st.G, st.V, eps, it0 + max_iter, False, hist)
