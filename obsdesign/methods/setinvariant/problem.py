"""From a spec to the float and exact data of a set-invariant design (paper 003, Section II-III).

Error dynamics (3): e(k+1) = A e(k) + B1 d(k) + v(z(k)), z(k) = C e(k) + η(k), d ∈ D,
|η| <= η̄; Ω = {e : G0 e <= 1} is the initial-error polytope (canonical form, right-hand
side 1, which needs the origin in its interior).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.printing import fmt_exact
from obsdesign.errors import InfeasibleError
from obsdesign.sets import Box, Polytope
from obsdesign.sets import polytope_ops as po
from obsdesign.spec.models import Spec

from .algorithms import Problem
from .certificate import ExactProblem


@dataclass
class Data:
    """Float problem and exact problem (``ex`` is None without cdd.gmp: float-only mode)."""

    fl: Problem
    ex: ExactProblem | None


def omega_rows(s: Any) -> np.ndarray:
    """Exact canonical rows (right-hand side 1) of a Box / Polytope set; raises ValueError
    when the origin is not in the interior."""
    if isinstance(s, Box):
        G, g = s.h_form_q()
    elif isinstance(s, Polytope):
        G, g = s.G_q, s.g_q
    else:  # pragma: no cover - filtered by parse_options
        raise ValueError("expected a box or a polytope")
    if any(x <= 0 for x in np.asarray(g).reshape(-1)):
        raise ValueError("the origin must be in the interior (every right-hand side > 0)")
    return po.canonical(np.asarray(G, dtype=object), np.asarray(g, dtype=object))


def disturbance_vertices(s: Any, nd: int) -> np.ndarray:
    """Exact vertices of D (rows); an empty (0, nd) array when there is no disturbance."""
    if s is None:
        return np.zeros((0, nd), dtype=object)
    if isinstance(s, Box):
        return np.asarray(s.vertices_q(), dtype=object)
    return np.asarray(s.vertices_q(), dtype=object).reshape(-1, nd)


def disturbance_vertices_float(s: Any, nd: int) -> np.ndarray:
    """Float vertices of D (float cdd for a polytope); (0, nd) when there is none."""
    if s is None:
        return np.zeros((0, nd))
    if isinstance(s, Box):
        return po.qfloat(np.asarray(s.vertices_q(), dtype=object)).reshape(-1, nd)
    from obsdesign.sets.polytope import vertices_float

    return vertices_float(s.G, s.g)[0].reshape(-1, nd)


@lru_cache(maxsize=16)
def _omega_vertices(rows: tuple[tuple[fmpq, ...], ...]) -> np.ndarray:
    return po.exact_h_to_v(np.array(rows, dtype=object)).V


def omega_vertices(G0: np.ndarray, deadline: float | None = None) -> np.ndarray:
    """Exact vertices of Ω = {G0 e <= 1} (cdd.gmp), computed once per Ω and process (the
    design and its certify both build the problem); a copy, keyed by the exact rows.
    ``deadline`` (``time.perf_counter()``): an enumeration in a child process (8+ states) is
    stopped past it (:class:`~.budget.Timeout`): Ω's vertices of an 8-state spec took 150 s
    against ``time_limit = 5`` (responsiveness review 47)."""
    key = tuple(tuple(r) for r in np.asarray(G0, dtype=object))
    if deadline is None:
        return _omega_vertices(key).copy()
    with _deadline(deadline):  # looked at only while a child enumerates (a cache miss)
        return _omega_vertices(key).copy()


def _deadline(deadline: float) -> Any:
    """The budget's check for the child processes of :mod:`obsdesign.sets.polytope_ops`
    started inside the block (:data:`obsdesign.sets.polytope_ops.CHILD_CHECK`)."""
    from .budget import check_deadline

    return po.child_check(lambda: check_deadline(deadline))


def build(spec: Spec, deadline: float | None = None) -> Data:
    """Float and exact data of the spec (the options were validated by parse_options);
    ``deadline``: as for :func:`omega_vertices`."""
    o = spec.options
    s = spec.system
    G0 = omega_rows(spec.sets[o.omega])
    if not po.HAVE_GMP:  # float-only mode: no exact problem (claims are numerical)
        return Data(
            Problem(
                s.A.f.astype(float),
                np.asarray(s.Bd.f, dtype=float).reshape(s.n, s.nd),
                s.C.f.astype(float),
                po.qfloat(G0),
                disturbance_vertices_float(o.D, s.nd),
                float(o.eta_bar),
            ),
            None,
        )
    Vo = omega_vertices(G0, deadline)
    D = o.D
    Dv = disturbance_vertices(D, s.nd)
    B1 = np.asarray(s.Bd.q, dtype=object).reshape(s.n, s.nd)
    ex = ExactProblem(
        np.asarray(s.A.q, dtype=object),
        B1,
        np.asarray(s.C.q, dtype=object),
        G0,
        Vo,
        Dv,
        o.eta_bar,
        o.lam,
    )
    fl = Problem(
        s.A.f.astype(float),
        np.asarray(s.Bd.f, dtype=float).reshape(s.n, s.nd),
        s.C.f.astype(float),
        po.qfloat(G0),
        po.qfloat(Dv).reshape(len(Dv), s.nd),
        float(o.eta_bar),
    )
    return Data(fl, ex)


def check_detectable(A: Any, C: Any, lam: Any) -> None:
    """Refuse (InfeasibleError) only a mode the output cannot see that is provably faster
    than λ (Section II: the injection cannot act on an unobservable mode, so a λ-contractive
    set needs |μ| <= λ for each), or a defective one at μ = ±λ.

    Exact first: the unobservable modes are the roots of the characteristic polynomial of A
    restricted to the unobservable subspace (:func:`obsdesign.certify.detect.unobservable_restriction`);
    none (observable) or all with |μ| < λ (exact Schur–Cohn test of χ(λz)) pass. Otherwise
    the distinct roots of the restriction's minimal polynomial are enclosed in rigorous balls
    (python-flint ``complex_roots``, 64 to 1024 bits): a root whose modulus is certainly above
    λ is refused. np.roots of the float polynomial was used before, and split a repeated root
    by 10⁻⁸ (double) to 10⁻⁵ (triple): A = diag(0.3, 0.9, 0.9), C = (1, 0, 0), λ = 0.9 was
    refused as "|μ| = 0.9 > λ = 0.9" although its box Ω certifies (set-invariant soundness
    trial, session 25). A root ±λ of multiplicity ≥ 2 in the minimal polynomial (a Jordan
    block at |μ| = λ: its powers grow like k·λᵏ) is refused, decided exactly; any other mode
    with |μ| = λ (e.g. μ = 1 with λ = 1, not excited by the disturbance: the soundness
    audit's example, whose box Ω is invariant) goes on to the algorithm, which decides. The
    message says "(C, A) is not detectable" when |μ| > 1.

    :param A, C: exact plant matrices (object arrays); :param lam: λ (exact)."""
    from flint import arb, ctx, fmpq_poly

    from obsdesign.certify.detect import schur_stable, unobservable_restriction
    from obsdesign.certify.exact import Q

    _, Au = unobservable_restriction(A, C)
    k = Au.nrows()
    if k == 0:
        return
    lq = Q(lam)
    chi = Au.charpoly()
    # χ(λz) = Σ a_i λ^i z^i: its roots are μ/λ
    scaled = fmpq_poly([c * lq**i for i, c in enumerate(chi.coeffs())])
    if lq > 0 and schur_stable(scaled)[0]:
        return
    minp = Au.minpoly()
    for prec in (64, 256, 1024):
        with ctx.workprec(prec):
            lam_b = arb(lq)
            over = [(r, abs(r)) for r, _ in minp.complex_roots() if abs(r) > lam_b]
            if over:
                r, a = max(over, key=lambda t: float(t[1].mid()))
                _refuse(r, a, lq)
    for sign in (1, -1):
        mu = sign * lq
        if minp(mu) == 0 and minp.derivative()(mu) == 0:
            raise InfeasibleError(
                f"the unobservable mode μ = {fmt_exact(mu)} (|μ| = λ) is defective (a Jordan "
                "block: its powers grow like k·λᵏ): no polyhedron is λ-contractive (choose "
                "λ > |μ|)"
            )


def _refuse(mu: Any, modulus: Any, lam: Any) -> None:
    """The InfeasibleError of an unobservable mode ``mu`` (an acb ball) with |μ| certainly
    above λ (``modulus``, an arb ball of |μ|), printed from the balls' midpoints with the
    fewest significant digits (3 to 40) that show |μ| above the bound: "|μ| = 0.9 > λ = 0.9"
    was said of |μ| = 0.9000001, 17 digits of a double showed μ = 19/20 as
    0.94999999999999996 (soundness trial, session 30), and a double could not show
    1 + 10⁻¹⁷ above 1 at all ("|μ| ≈ 1 > 1"; re-check trial, session 30)."""
    from fractions import Fraction

    bound = Fraction(1) if modulus > 1 else Fraction(int(lam.p), int(lam.q))
    d = next((d for d in range(3, 41) if Fraction(_digits(modulus, d)) > bound), 40)
    re, im = _digits(mu.real, d), _digits(mu.imag, d)
    shown = re if float(mu.imag.mid()) == 0 else f"{re}{'' if im.startswith('-') else '+'}{im}j"
    m = _digits(modulus, d)
    if modulus > 1:
        raise InfeasibleError(
            f"(C, A) is not detectable: the mode μ ≈ {shown} (|μ| ≈ {m} > 1) "
            "is unobservable, so no bounded set is D-(C,A)-invariant"
        )
    raise InfeasibleError(
        f"the unobservable mode μ ≈ {shown} has |μ| ≈ {m} > λ = {fmt_exact(lam)}: "
        "no polyhedron is λ-contractive (choose λ >= |μ|)"
    )


def _digits(x: Any, d: int) -> str:
    """The midpoint of the arb ball ``x`` in ``d`` significant decimal digits, without
    trailing zeros."""
    s = x.mid().str(d, radius=False)
    mant, e, exp = s.partition("e")
    if "." in mant:
        mant = mant.rstrip("0").rstrip(".")
    return mant + e + exp


def necessary_condition(
    G: np.ndarray, B1: np.ndarray, Dv: np.ndarray, lam: fmpq
) -> tuple[bool, fmpq]:
    """Section II: λΩ ⊇ B1·D, i.e. max over D's vertices of G_i B1 d <= λ, exactly."""
    from .certificate import delta_exact

    if B1.shape[1] == 0 or len(Dv) == 0:
        return True, fmpq(0)
    m = max(delta_exact(G, B1, Dv))
    return m <= lam, m
