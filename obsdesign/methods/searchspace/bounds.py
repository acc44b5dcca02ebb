"""Certified upper bounds of the constants L_f^E, L_h^E and ‖f_u‖_E by interval arithmetic
with subdivision (branch and bound) on the expression tree, with a sampled lower estimate
that says how tight each bound is.

Hernández & García, "An alternative approach to the state observation problem for Lipschitz
continuous systems with controls": L_h^E and ‖f_u‖_E enter Lemma 1 (ΔT < γ/(2 L_h ‖f_u‖)),
L_f^E and L_h^E Lemma 2 (t̄ − t₀ < log(γ/(ε L_h))/L_f) and all three Theorem 1. Any valid
upper bound of a Lipschitz constant is itself a Lipschitz constant, so the rules applied to
certified upper bounds keep every conclusion of the paper.

- ‖f_u‖_E = sup over x ∈ E, u ∈ U of |f(x, u)| (Euclidean): per sub-box, the square root of
  Σ_i max|f_i|² over the interval enclosure.
- L_f^E (in x, uniformly in u ∈ U) and L_h^E: per sub-box, the interval enclosure J of the
  (Clarke) Jacobian; with M = |J| entry-wise, ‖J‖₂ ≤ min(‖M‖_F, √(‖M‖₁‖M‖_∞)). E and U are
  boxes (convex), so by the mean-value theorem the largest bound over the sub-boxes is a
  Lipschitz constant on E.
"""

from __future__ import annotations

import ast
import heapq
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from obsdesign.certify.exact import float_or_inf
from obsdesign.methods.searchspace.intervals import (
    ZERO,
    Dual,
    I,
    _div_lo,
    _down,
    _up,
    add_hi,
    add_lo,
    evaluate,
    mul_hi,
    mul_lo,
    sqrt_hi,
    sqrt_lo,
)
from obsdesign.methods.searchspace.qintervals import QI, evaluate_q
from obsdesign.simulate.result import norms as _norms
from obsdesign.spec.expr import Expr


@dataclass
class Bound:
    """A certified upper bound (float, rigorous) and a sampled lower estimate of a constant;
    ``witness``: the sample point(s) of that estimate (two points of a difference quotient, or
    one point of a sup norm), inside the exact box (:func:`proved_lower_sq` proves a lower
    bound there)."""

    upper: float
    lower_est: float
    boxes: int
    witness: tuple[np.ndarray, ...] | None = None
    #: some float sample was not finite (an expression that overflows floats on part of the
    #: box): the witness may miss where the constant is reached, so a refutation also tries
    #: :func:`corner_witnesses`
    overflow: bool = False

    @property
    def finite(self) -> bool:
        return math.isfinite(self.upper)

    @property
    def tightness(self) -> float:
        """upper / lower estimate (1 is tight; inf when the estimate is 0)."""
        if self.lower_est <= 0:
            return math.inf if self.upper > 0 else 1.0
        return self.upper / self.lower_est


Box = tuple[I, ...]


def _params(ex: Expr) -> dict[str, I]:
    """The expression's own parameters as point intervals (each expression its own: one dict
    merged over all of them, the last value winning, bounded f = (k·u1·x2, −u1·x1) with the
    k of the other component, and certified L_f = 1 for k = 10; API review, session 43)."""
    from obsdesign.certify.exact import Q

    return {k: I.of_q(Q(v)) for k, v in ex.parameters.items()}


def _enclose(
    exprs: Sequence[Expr], names: Sequence[str], box: Box, diff: Sequence[str]
) -> list[Dual]:
    nd = len(diff)
    env: dict[str, Dual] = {}
    for name, iv in zip(names, box, strict=True):
        g = tuple(
            I(1.0, 1.0) if (d == name) else ZERO for d in diff
        )  # unit vector for a differentiation variable
        env[name] = Dual(iv, g)
    # the text the tree was parsed from (spec.expr rewrites ^ as **): exact decimal literals
    return [
        evaluate(ex.tree, env, _params(ex), nd, ex.source.strip().replace("^", "**"))
        for ex in exprs
    ]


def _sum_hi(xs: Sequence[float]) -> float:
    s = 0.0
    for x in xs:
        s = add_hi(s, x)
    return s


def norm_upper_iv(J: Sequence[Sequence[I]]) -> float:
    """A float ≥ ‖A‖₂ for every matrix A in the interval matrix J: the least of the magnitude
    bounds of :func:`norm_upper` and √ of Gershgorin's bound of λ_max on the interval
    enclosure of JᵀJ (it contains every AᵀA, A ∈ J)."""
    M = [[g.mag for g in row] for row in J]
    best = norm_upper(M)
    if not math.isfinite(best):
        return best
    n = len(J[0])
    B = [
        [_dot([J[r][i] for r in range(len(J))], [J[r][j] for r in range(len(J))]) for j in range(n)]
        for i in range(n)
    ]
    gersh = max(
        add_hi(B[i][i].hi, _sum_hi([B[i][j].mag for j in range(n) if j != i])) for i in range(n)
    )
    return min(best, sqrt_hi(max(gersh, 0.0)))


def _dot(a: Sequence[I], b: Sequence[I]) -> I:
    acc = ZERO
    for x, y in zip(a, b, strict=True):
        acc = acc + (x.sqr() if x is y else x * y)
    return acc


def hypot_hi(xs: Sequence[float]) -> float:
    """A float ≥ √(Σ x_i²) for magnitudes x_i ≥ 0, squared after scaling by the power of two
    2^e just above max x_i (exact, each quotient that underflows rounded up), so that the
    squares neither overflow nor vanish: squared as they were, entries above ~1.3·10¹⁵⁴ gave
    +∞ and L_h = 10¹⁶⁰ was refused as "not Lipschitz (a jump?)" (search-space trial,
    session 27), and 10⁻³⁰⁰ was bounded by 2.2·10⁻¹⁶² (the least subnormal's root)."""
    m = max(xs, default=0.0)
    if m == 0.0 or not math.isfinite(m):
        return m
    e = math.frexp(m)[1]  # m < 2^e
    terms = []
    for x in xs:
        t = math.ldexp(x, -e)
        if math.ldexp(t, e) != x:  # the quotient underflowed: rounded, so take the next up
            t = _up(t)
        terms.append(mul_hi(t, t))
    r = sqrt_hi(_sum_hi(terms))
    try:
        out = math.ldexp(r, e)  # exact unless subnormal (then rounded: stepped up)
    except OverflowError:  # beyond the float range
        return math.inf
    return out if math.ldexp(out, -e) >= r else _up(out)


_FLOAT_MAX = 1.7976931348623157e308


def hypot_lo(xs: Sequence[float]) -> float:
    """A float ≤ √(Σ x_i²) for magnitudes x_i ≥ 0, scaled as :func:`hypot_hi` (each quotient
    that underflows rounded down)."""
    m = max(xs, default=0.0)
    if m == 0.0 or not math.isfinite(m):
        return m
    e = math.frexp(m)[1]
    s = 0.0
    for x in xs:
        t = math.ldexp(x, -e)
        if math.ldexp(t, e) != x:
            t = max(0.0, _down(t))
        s = add_lo(s, mul_lo(t, t))
    r = sqrt_lo(s)
    try:
        out = math.ldexp(r, e)
    except OverflowError:
        return _FLOAT_MAX
    return out if math.ldexp(out, -e) <= r else max(0.0, _down(out))


#: coordinates that stand for an exact value (index → its tight float interval): a zero-width
#: side of E or U with no double ({1/10})
Fixed = dict[int, I]


def fixed_sides(lo: Sequence[Any], hi: Sequence[Any]) -> Fixed:
    """The sides of the box [lo, hi] that hold no float (a zero-width side whose exact value
    has no double, or one narrower than an ulp between two doubles): no float lies in them, so a sample's coordinate there is a float next to the value, and the value
    is enclosed by its tight interval instead (:func:`_values_at`)."""
    out: Fixed = {}
    for j, (a, b) in enumerate(zip(lo, hi, strict=True)):
        iv_a, iv_b = I.of_q(a), I.of_q(b)
        if iv_a.hi > iv_b.lo:  # no float inside: a single value with no double, or narrower
            out[j] = I(iv_a.lo, iv_b.hi)  # than one ulp (re-check trial, session 36)
    return out


def _values_at(
    exprs: Sequence[Expr], names: Sequence[str], z: np.ndarray, fixed: Fixed | None = None
) -> list[I] | None:
    """Outward-rounded enclosures of the expressions' values at the float point z, with the
    coordinates of ``fixed`` at their exact values (None where an enclosure cannot be
    computed)."""
    fixed = fixed or {}
    box = tuple(fixed.get(j) or I.point(float(v)) for j, v in enumerate(z))
    try:
        return [d.v for d in _enclose(exprs, names, box, ())]
    except (ArithmeticError, ValueError, OverflowError):
        return None


def proved_norm_at(
    exprs: Sequence[Expr], names: Sequence[str], z: np.ndarray, fixed: Fixed | None = None
) -> float:
    """A float ≤ |F(z)| (Euclidean), from the enclosure of F at the float point z (the
    coordinates of ``fixed`` at their exact values): the sampled sup-norm estimate, free of
    the float evaluation's rounding (0 where F cannot be enclosed)."""
    vs = _values_at(exprs, names, z, fixed)
    if vs is None:
        return 0.0
    return hypot_lo([0.0 if v.contains0() else min(abs(v.lo), abs(v.hi)) for v in vs])


def proved_quotient(
    exprs: Sequence[Expr],
    names: Sequence[str],
    p: np.ndarray,
    q: np.ndarray,
    fixed: Fixed | None = None,
) -> float:
    """A float ≤ |F(p) − F(q)| / |p − q| (Euclidean) at the float points p ≠ q, from the
    enclosures of F at both: the sampled Lipschitz estimate, free of the float evaluation's
    rounding. A float quotient of values near 10⁶ over 4·10⁻⁶ was 1.0000076 for h = x1 + 10⁶
    (exactly 1), and refuted the design's own L_h = 1 (Lipschitz-pair review, session 35)."""
    a, b = _values_at(exprs, names, p, fixed), _values_at(exprs, names, q, fixed)
    if a is None or b is None:
        return 0.0
    gaps = []
    for x, y in zip(a, b, strict=True):
        d = x - y
        gaps.append(0.0 if d.contains0() else min(abs(d.lo), abs(d.hi)))
    num = hypot_lo(gaps)
    den = hypot_hi([(I.point(float(u)) - I.point(float(w))).mag for u, w in zip(p, q, strict=True)])
    if not num or not den or not math.isfinite(den):
        return 0.0
    if not math.isfinite(num):
        return _FLOAT_MAX
    return max(0.0, _div_lo(num / den, num, den))


def norm_upper(M: Sequence[Sequence[float]]) -> float:
    """A float ≥ ‖A‖₂ for every matrix A with |A_ij| ≤ M_ij (min of Frobenius and
    √(‖M‖₁‖M‖_∞)), rounded upward, without squaring an entry or the product unscaled."""
    if any(not math.isfinite(v) for row in M for v in row):
        return math.inf
    fro = hypot_hi([v for row in M for v in row])
    rows = [_sum_hi(list(r)) for r in M]
    cols = [_sum_hi([r[j] for r in M]) for j in range(len(M[0]))]
    prod = mul_hi(sqrt_hi(max(rows)), sqrt_hi(max(cols)))
    return min(fro, prod)


def _split(box: Box, widths0: Sequence[float]) -> tuple[Box, Box] | None:
    best, k = 0.0, -1
    for j, (iv, w0) in enumerate(zip(box, widths0, strict=True)):
        if w0 > 0 and iv.hi > iv.lo:
            r = (iv.hi - iv.lo) / w0
            if r > best:
                best, k = r, j
    if k < 0:
        return None
    iv = box[k]
    m = 0.5 * (iv.lo + iv.hi)
    if not (iv.lo < m < iv.hi):
        return None
    a = (*box[:k], I(iv.lo, m), *box[k + 1 :])
    b = (*box[:k], I(m, iv.hi), *box[k + 1 :])
    return a, b


#: a sampled lower estimate and the point(s) where it was taken (None: no finite sample)
Sample = tuple[float, tuple[np.ndarray, ...] | None]


def branch_and_bound(
    box: Box,
    upper_of: Callable[[Box], float],
    lower_of: Callable[[Box], Sample],
    budget: int,
    rtol: float,
    prove: Callable[[tuple[np.ndarray, ...]], float] | None = None,
) -> Bound:
    """Largest of ``upper_of`` over a subdivision of ``box``: split the sub-box with the
    largest bound (along its relatively widest side) until that bound is within ``rtol`` of
    the best sampled value ``lower_of`` or ``budget`` sub-boxes were evaluated. The bound
    keeps the best sample's point(s) as its witness. ``prove`` (witness → a proved lower
    bound of the constant there) replaces a float sample by its proved value; it runs only
    for a sample whose float value beats the best float value so far (every child was
    proved before: 30 % of a search-space design's time)."""
    widths0 = [iv.hi - iv.lo for iv in box]
    upper_of = _safe(upper_of)
    ub0 = upper_of(box)
    lb, wit = lower_of(box)
    best_float = lb  # the float value of the best sample (proved ones are compared to lb)
    if prove is not None:
        lb = prove(wit) if wit is not None and lb > 0 else 0.0
    heap: list[tuple[float, int, Box]] = [(-ub0, 0, box)]
    count = 1
    while count < budget:
        neg, _, top = heap[0]
        ub = -neg
        if math.isfinite(ub) and ub <= lb * (1 + rtol):
            break
        parts = _split(top, widths0)
        if parts is None:
            break
        heapq.heappop(heap)
        for child in parts:
            count += 1
            heapq.heappush(heap, (-upper_of(child), count, child))
            v, w = lower_of(child)
            if prove is not None:
                if not v > best_float:
                    continue
                best_float = v
                v = prove(w) if w is not None else 0.0
            if v > lb:
                lb, wit = v, w
    return Bound(-heap[0][0], lb, count, wit, getattr(lower_of, "overflow", False))


def _safe(upper_of: Callable[[Box], float]) -> Callable[[Box], float]:
    """An enclosure that cannot be computed on a box (log or sqrt of a box reaching 0, a
    non-integer power of a base that may be negative, …) bounds nothing: +∞."""

    def f(b: Box) -> float:
        try:
            return upper_of(b)
        except (ArithmeticError, ValueError):
            return math.inf

    return f


def _box(E_lo: Sequence[Any], E_hi: Sequence[Any]) -> Box:
    return tuple(I(I.of_q(a).lo, I.of_q(b).hi) for a, b in zip(E_lo, E_hi, strict=True))


def _mid(box: Box) -> np.ndarray:
    return np.array([iv.mid for iv in box])


def _samples(box: Box) -> np.ndarray:
    """The midpoint and (up to 5 dimensions) the corners of a box: where a sampled lower
    estimate is taken."""
    pts = [_mid(box)]
    if len(box) <= 5 and all(iv.finite for iv in box):
        import itertools

        pts += [np.array(c) for c in itertools.product(*[(iv.lo, iv.hi) for iv in box])]
    return np.array(pts)


def _eval(exprs: Sequence[Expr], names: Sequence[str], X: np.ndarray) -> np.ndarray:
    """Float values of the expressions at the rows of X (every variable of an expression is
    given, unused ones as 0, so the expression skips its name search)."""
    out = []
    with np.errstate(all="ignore"):
        for ex in exprs:
            env = {v: 0.0 for v in ex.variables}
            env.update({n: X[..., i] for i, n in enumerate(names)})
            r = ex(**env)
            out.append(np.broadcast_to(np.asarray(r, dtype=float), X.shape[:-1]))
    return np.stack(out, axis=-1)


def sup_norm(
    exprs: Sequence[Expr],
    names: Sequence[str],
    lo: Sequence[Any],
    hi: Sequence[Any],
    budget: int,
    rtol: float,
) -> Bound:
    """Certified ‖F‖ = sup |F(z)| over the box [lo, hi] (z = ``names``)."""

    def upper_of(b: Box) -> float:
        vs = _enclose(exprs, names, b, ())
        return hypot_hi([d.v.mag for d in vs])

    def lower_of(b: Box) -> Sample:
        # the samples are kept in the exact box (its float box is rounded outward), so that
        # the witness is a point of E × U
        Z = np.clip(_samples(b), inner_lo, inner_hi)
        v = _norms(_eval(exprs, names, Z))
        ok = np.flatnonzero(np.isfinite(v))
        if ok.size < len(v):
            lower_of.overflow = True  # type: ignore[attr-defined]
        if not ok.size:  # no float value: the midpoint still serves the exact proof
            return 0.0, (Z[0],)
        i = int(ok[np.argmax(v[ok])])
        return float(v[i]), (Z[i],)

    inner_lo = np.array([I.of_q(x).hi for x in lo])
    inner_hi = np.array([I.of_q(x).lo for x in hi])
    return branch_and_bound(
        _box(lo, hi),
        upper_of,
        lower_of,
        budget,
        rtol,
        prove=lambda w: proved_norm_at(exprs, names, w[0], fixed_sides(lo, hi)),
    )


def lipschitz(
    exprs: Sequence[Expr],
    names: Sequence[str],
    diff: Sequence[str],
    lo: Sequence[Any],
    hi: Sequence[Any],
    budget: int,
    rtol: float,
) -> Bound:
    """Certified Lipschitz constant of z ↦ F(z) in the variables ``diff`` over the box
    [lo, hi] (uniformly in the other variables of the box)."""
    idx = [list(names).index(d) for d in diff]

    def upper_of(b: Box) -> float:
        vs = _enclose(exprs, names, b, diff)
        return norm_upper_iv([list(d.g) for d in vs])

    def lower_of(b: Box) -> Sample:
        """Largest difference quotient |F(m + δv) − F(m − δv)|/(2δ) at the sample points m,
        v the top right singular vector of a finite-difference Jacobian, in floats;
        :func:`branch_and_bound` bounds the best pair's quotient below rigorously
        (:func:`proved_quotient`), so the estimate is a true lower bound of the Lipschitz
        constant, float rounding included."""
        M = _samples(b)
        scale = 1e-6 * (1.0 + float(np.max(np.abs(M))))
        steps = np.zeros((len(idx), M.shape[1]))
        for c, j in enumerate(idx):
            steps[c, j] = scale
        P = np.concatenate([M[None] + steps[:, None], M[None] - steps[:, None]])
        V = _eval(exprs, names, P)  # (2·nd, S, p)
        J = (V[: len(idx)] - V[len(idx) :]).transpose(1, 2, 0) / (2 * scale)  # (S, p, nd)
        if not np.all(np.isfinite(J)):
            lower_of.overflow = True  # type: ignore[attr-defined]
            return 0.0, _across(b)
        _, _, vt = np.linalg.svd(J)
        v = np.zeros_like(M)
        v[:, idx] = vt[:, 0, :]
        # the quotient's two points are kept in E: from a corner, m ± δv left E and crossed
        # a jump just outside it (floor(x2) at x2 = 0 with E's x2 ∈ [0, 1/2] gave 2.5·10⁵
        # and failed a true L_f = 1; search-space trial, session 24). Not in the sub-box:
        # branch and bound narrows a box to a few ulps, and a pair clipped into it divided
        # float rounding by 10⁻¹⁷ — a "sampled quotient" of 1 failed a true L_f = 0.8725
        # (exactly 0.7 at that pair; expression soundness trial, session 34). A pair much
        # closer than δ (clipped at E's edge) is skipped for the same reason.
        Pp, Pm = (
            np.clip(M + scale * v, inner_lo, inner_hi),
            np.clip(M - scale * v, inner_lo, inner_hi),
        )
        d = _eval(exprs, names, Pp) - _eval(exprs, names, Pm)
        dist = np.linalg.norm(Pp - Pm, axis=-1)
        with np.errstate(all="ignore"):
            q = _norms(d) / dist
        ok = np.flatnonzero(np.isfinite(q) & (dist > 1e-3 * scale))
        if not np.all(np.isfinite(q)):
            lower_of.overflow = True  # type: ignore[attr-defined]
        if not ok.size:
            return 0.0, _across(b)
        i = int(ok[np.argmax(q[ok])])
        return float(q[i]), (Pp[i], Pm[i])

    def _across(b: Box) -> tuple[np.ndarray, np.ndarray] | None:
        """Two points of the box (and of E) across it in the variables ``diff``, the others
        at the midpoint: the exact proof's pair where floats give no quotient. An expression
        that overflows floats (h = (x1 + 2^1100) − 2^1100, exactly x1) had every sample
        inf − inf, no witness, and a given L_h = 0.5 stayed numerical, exit 0 (soundness
        trial, session 33); its exact rational value refutes it."""
        p = np.clip(_mid(b), inner_lo, inner_hi)
        q = p.copy()
        for j in idx:
            p[j] = max(b[j].lo, inner_lo[j])
            q[j] = min(b[j].hi, inner_hi[j])
        return (p, q) if np.any(p != q) else None

    # floats inside the exact box [lo, hi] (its own float box is rounded outward)
    inner_lo = np.array([I.of_q(x).hi for x in lo])
    inner_hi = np.array([I.of_q(x).lo for x in hi])

    # a zero-width side with no double ({1/10} of U): the samples' coordinate there is the
    # float next to it, and a quotient proved at that float point is of another u — it
    # failed a true given L_f = 2 (f2 = 2·10¹⁷(0.1 as a double − u1)·x1, L_f^E = 1.11 at
    # u1 = 1/10, 2.78 at the float below it; re-check trial, session 36)
    fixed = fixed_sides(lo, hi)

    def prove(w: tuple[np.ndarray, ...]) -> float:
        return proved_quotient(exprs, names, w[0], w[1], fixed) if len(w) == 2 else 0.0

    return branch_and_bound(_box(lo, hi), upper_of, lower_of, budget, rtol, prove=prove)


#: at most this many held-variable corners (2^4) in :func:`corner_witnesses`
MAX_CORNER_VARS = 4


def corner_witnesses(
    names: Sequence[str], diff: Sequence[str], lo: Sequence[Any], hi: Sequence[Any]
) -> list[tuple[np.ndarray, ...]]:
    """Candidate witnesses for :func:`proved_lower_sq` where float samples overflowed
    (:attr:`Bound.overflow`), at the exact box [lo, hi]'s corners (floats inside it): for a
    sup (``diff`` empty) every corner of the first MAX_CORNER_VARS + 1 variables, the others
    at their midpoints; for a Lipschitz constant the pair across the box in ``diff`` with the
    held variables at every corner of the first MAX_CORNER_VARS of them, and, for each
    variable of ``diff``, the pair across it alone (at the upper and the lower corner of the
    other differenced variables) with the held variables at their midpoints. A given f_sup, or an L_f reached at an input's extreme, or
    a constant reached where floats overflow stayed numerical, exit 0, when only the sampled
    witness was proved (re-check trial, session 33)."""
    import itertools

    a = np.array([I.of_q(x).hi for x in lo])
    b = np.array([I.of_q(x).lo for x in hi])
    mid = np.clip((a + b) / 2, a, b)
    idx = [list(names).index(d) for d in diff]
    held = [i for i in range(len(names)) if i not in idx]
    out: list[tuple[np.ndarray, ...]] = []
    if not idx:
        free = held[: MAX_CORNER_VARS + 1]
        for c in itertools.product((0, 1), repeat=len(free)):
            z = mid.copy()
            for i, k in zip(free, c, strict=True):
                z[i] = b[i] if k else a[i]
            out.append((z,))
        return out
    free = held[:MAX_CORNER_VARS]
    for c in itertools.product((0, 1), repeat=len(free)):
        base = mid.copy()
        for i, k in zip(free, c, strict=True):
            base[i] = b[i] if k else a[i]
        p, q = base.copy(), base.copy()
        p[idx], q[idx] = a[idx], b[idx]
        out.append((p, q))
    if len(idx) > 1:  # each coordinate alone, the held variables at their midpoints (with
        # them at every corner too, 6 states and 6 inputs took 33 s against 4 s: re-check)
        for j in idx:
            for side in (a, b):
                p, q = mid.copy(), mid.copy()
                p[idx], q[idx] = side[idx], side[idx]
                p[j], q[j] = a[j], b[j]
                out.append((p, q))
    return [w for w in out if not all(np.array_equal(w[0], x) for x in w[1:]) or len(w) == 1]


#: relative distance within which a float stands for the exact value of a zero-width side
_ULP_REL = Fraction(1, 2**51)


#: :func:`proved_lower_sq` also tries the witness pair shrunk by 10⁻¹ … 10⁻ᴷ (K below)
#: towards either point and its midpoint: a secant 2·10⁻⁶ long refuted only values about
#: 10⁻⁶ below the constant (x1² on [0, 1.5] with a given L_h = 2.999999997 stayed numerical;
#: re-check trial, session 31)
SHRINK_STEPS = 12


def proved_lower_sq(
    exprs: Sequence[Expr],
    names: Sequence[str],
    diff: Sequence[str],
    lo: Sequence[Any],
    hi: Sequence[Any],
    witness: tuple[np.ndarray, ...] | None,
    target: Fraction | None = None,
) -> tuple[Fraction, tuple[tuple[Fraction, ...], ...]] | None:
    """An exact lower bound of the square of the constant a :class:`Bound` estimates, proved at
    its witness: ‖F(a) − F(b)‖²/‖a − b‖² for two points a ≠ b of the box [lo, hi] that differ
    only in the variables ``diff`` (so it bounds the squared Lipschitz constant in ``diff``
    from below, uniformly in the others: L_f^E, L_h^E of Lemmas 1-2, Hernández & García), the
    largest over the pair and its shrunk copies on the segment [a, b] (:data:`SHRINK_STEPS`:
    a shorter secant comes closer to the derivative), or ‖F(z)‖² for one point z of the box
    (‖f_u‖_E of Lemma 1). Each F_i is enclosed with exact rational end points
    (:func:`~obsdesign.methods.searchspace.qintervals.evaluate_q` at the points' exact
    values) and only the part of the enclosure away from 0 counts, so a given constant below
    this bound is refuted, not just doubted. Returns it with the exact point(s) that prove
    it; None when a point is not in the box exactly, the points differ elsewhere or
    coincide, or no evaluation succeeds.

    :param exprs: F's components; :param names: the variables, in the points' order;
    :param diff: the variables of the difference quotient; :param lo, hi: the exact box;
    :param witness: one or two float points; :param target: stop at the first pair whose
        square exceeds it (all that a refutation of a value whose square is ``target``
        needs)."""
    if witness is None or len(witness) not in (1, 2):
        return None
    LO, HI = [_frac(q) for q in lo], [_frac(q) for q in hi]
    pts = []
    for w in witness:
        if len(w) != len(names) or not np.all(np.isfinite(w)):
            return None
        # a side of zero width whose value has no double ({1/10}) holds one point, its exact
        # value: the floats beside it were outside the box, every witness was refused and a
        # false L_h or f_sup stayed numerical (re-check trial, session 33)
        q = [
            a if a == b and abs(Fraction(float(x)) - a) <= abs(a) * _ULP_REL else Fraction(float(x))
            for a, b, x in zip(LO, HI, w, strict=True)
        ]
        if not all(a <= x <= b for a, x, b in zip(LO, q, HI, strict=True)):
            return None
        pts.append(q)
    params = [_exact_params(ex) for ex in exprs]
    srcs = [ex.source.strip().replace("^", "**") for ex in exprs]

    def values(z: list[Fraction]) -> list[QI]:
        env = {n: QI.point(x) for n, x in zip(names, z, strict=True)}
        return [
            evaluate_q(ex.tree, env, pa, sr) for ex, pa, sr in zip(exprs, params, srcs, strict=True)
        ]

    def mig_sq(d: QI) -> Fraction:
        m = Fraction(0) if d.lo <= 0 <= d.hi else min(abs(d.lo), abs(d.hi))
        return m * m

    if len(pts) == 1:
        try:
            return sum((mig_sq(v) for v in values(pts[0])), Fraction(0)), (tuple(pts[0]),)
        except (ArithmeticError, ValueError, KeyError):
            return None
    a, b = pts
    same = [i for i, n in enumerate(names) if n not in diff]
    if any(a[i] != b[i] for i in same) or a == b:
        return None
    mid = [(x + y) / 2 for x, y in zip(a, b, strict=True)]
    pairs = [(a, b)]
    for k in range(1, SHRINK_STEPS + 1):
        t = Fraction(1, 10**k)
        for c in (a, b, mid):  # the segment's points stay in the (convex) box
            pairs.append(
                (
                    [x + (y - x) * t for x, y in zip(c, a, strict=True)] if c is not a else a,
                    [x + (y - x) * t for x, y in zip(c, b, strict=True)] if c is not b else b,
                )
            )
    best: tuple[Fraction, tuple[tuple[Fraction, ...], ...]] | None = None
    for p, q in pairs:
        dist_sq = sum(((x - y) ** 2 for x, y in zip(p, q, strict=True)), Fraction(0))
        if dist_sq == 0:
            continue
        try:
            vp, vq = values(p), values(q)
        except (ArithmeticError, ValueError, KeyError):
            continue
        r = sum((mig_sq(x - y) for x, y in zip(vp, vq, strict=True)), Fraction(0)) / dist_sq
        if best is None or r > best[0]:
            best = r, (tuple(p), tuple(q))
            if target is not None and r > target:
                break
    return best


def range_inside(
    exprs: Sequence[Expr],
    var: str,
    t_lo: Any,
    t_hi: Any,
    lo: Sequence[Any],
    hi: Sequence[Any],
    budget: int,
) -> tuple[bool, float, int, bool]:
    """Whether every component i of ``exprs`` (functions of the one variable ``var``) stays in
    [lo_i, hi_i] for var ∈ [t_lo, t_hi] (Remark 2.5, Hernández & García), and whether some
    point provably leaves it.

    A component that does not depend on ``var`` is compared exactly (its sympy value: a
    decimal literal is its exact rational, so u = 0.1 in [0.1, 1] is proved; float
    enclosures of 0.1 reach below 0.1). The others go through interval enclosures on a
    bisection of the variable's interval (at most ``budget`` sub-intervals): the float
    enclosure first and, where it does not prove a bound, the enclosure with exact rational
    end points (:mod:`~obsdesign.methods.searchspace.qintervals`: u = 0.3·sin(t) in
    [−0.3, 0.3] is proved; the float enclosure reaches 0.30000000000000004). Returns
    (proved inside, largest excess of an enclosure beyond the bounds (0 when proved),
    sub-intervals used, proved outside: some enclosure, of a sub-interval or of a constant,
    lies wholly beyond a bound)."""
    LO = [_frac(q) for q in lo]
    HI = [_frac(q) for q in hi]
    live = []
    outside = False
    for i, ex in enumerate(exprs):
        if ex.uses(var):
            live.append(i)
            continue
        inside, out = _constant_inside(ex, LO[i], HI[i])
        if out:
            return False, math.inf, 0, True
        if not inside:
            live.append(i)  # not decided exactly: the enclosures below try
    if not live:
        return True, 0.0, 0, False
    exprs = [exprs[i] for i in live]
    LO, HI = [LO[i] for i in live], [HI[i] for i in live]

    qparams = [_exact_params(ex) for ex in exprs]  # once, for every sub-interval

    def excess(b: Box) -> tuple[float, bool]:
        try:
            vs = _enclose(exprs, [var], b, ())
        except (ArithmeticError, ValueError):
            return math.inf, False
        worst = 0.0
        out = False
        for k, (d, a, z) in enumerate(zip(vs, LO, HI, strict=True)):
            if not d.v.finite:
                return math.inf, False
            lo_k, hi_k = Fraction(d.v.lo), Fraction(d.v.hi)
            if lo_k < a or hi_k > z:  # not proved in floats: the exact-end-point enclosure
                q = _enclose_q(exprs[k], var, b, qparams[k], ends)
                if q is not None:
                    lo_k, hi_k = max(lo_k, q.lo), min(hi_k, q.hi)
            below = a - lo_k
            above = hi_k - z
            # ±inf past the float range: U = [−1.7e308, 1.7e308] and u near 1e308 made the
            # difference overflow, exit 4 for a range proved inside (float pre-screen
            # review, session 43)
            worst = max(worst, float_or_inf(below), float_or_inf(above))
            if below > 0 or above > 0:
                worst = max(worst, 1e-300)
            out = out or hi_k < a or lo_k > z
        return worst, out

    stack = [_box([t_lo], [t_hi])]
    # the outermost sub-interval ends are the exact t_lo, t_hi, not their outward float
    # enclosures (u = t, U = [0, 1/10], horizon 1/10: the float end 0.1 + 5.6e-18 left U and
    # the claim was inconclusive, exit 4; random-spec fuzzer)
    ends = (stack[0][0].lo, _frac(t_lo), stack[0][0].hi, _frac(t_hi))
    used = 0
    worst_left = 0.0
    while stack:
        b = stack.pop()
        used += 1
        ex, out = excess(b)
        if out:  # proved outside: the claim fails whatever the other sub-intervals give
            # (it went on bisecting to the budget; re-check review, session 43)
            outside = True
            worst_left = max(worst_left, ex)
            break
        if ex <= 0.0:
            continue
        parts = _split(b, [1.0])
        if parts is None or used + len(stack) + 2 > budget:
            worst_left = max(worst_left, ex)
            continue
        stack.extend(parts)
    if worst_left > 0.0 and not outside:
        # not proved either way: u at the horizon's two ends, exactly. The enclosures of
        # floor(t) on sub-intervals reaching t = 1 always overlap U = [0, 0], so a u that
        # leaves U at an end point only was inconclusive, exit 4 (search-space review,
        # session 42); at the point itself the exact enclosure is [1, 1]
        outside = _points_outside(exprs, var, (_frac(t_lo), _frac(t_hi)), LO, HI, qparams)
    return worst_left == 0.0, worst_left, used, outside


def _points_outside(
    exprs: Sequence[Expr],
    var: str,
    points: Sequence[Fraction],
    LO: Sequence[Fraction],
    HI: Sequence[Fraction],
    qparams: Sequence[dict[str, QI]],
) -> bool:
    """Whether some component of ``exprs`` provably leaves [LO_i, HI_i] at one of the exact
    ``points`` of ``var``: its exact-end-point enclosure at the point
    (:func:`~obsdesign.methods.searchspace.qintervals.evaluate_q`) lies wholly beyond a bound
    (Remark 2.5, Hernández & García: u(t) ∈ U over the horizon)."""
    for t in points:
        for ex, a, z, prm in zip(exprs, LO, HI, qparams, strict=True):
            try:
                v = evaluate_q(
                    ex.tree, {var: QI.point(t)}, prm, ex.source.strip().replace("^", "**")
                )
            except (ArithmeticError, ValueError, KeyError):
                continue
            if v is not None and (v.hi < a or v.lo > z):
                return True
    return False


def _exact_params(ex: Expr) -> dict[str, QI]:
    """The spec parameters of ``ex`` at their exact values, as point intervals."""
    from obsdesign.certify.exact import Q

    return {
        k: QI.point(Fraction(int(q.p), int(q.q)))
        for k, q in ((k, Q(v)) for k, v in ex.parameters.items())
    }


def _frac(q: Any) -> Fraction:
    """An exact rational (fmpq, Fraction or int) as a Fraction."""
    if isinstance(q, (Fraction, int)):
        return Fraction(q)
    return Fraction(int(q.p), int(q.q))


def _enclose_q(
    ex: Expr,
    var: str,
    b: Box,
    params: dict[str, QI],
    ends: tuple[float, Fraction, float, Fraction] | None = None,
) -> QI | None:
    """The exact-end-point enclosure of ``ex`` over the one-variable box b
    (:func:`~obsdesign.methods.searchspace.qintervals.evaluate_q`) with the parameters
    ``params`` (:func:`_exact_params`), or None when it finds no finite one. ``ends`` =
    (float lo, exact lo, float hi, exact hi) of the whole interval: an end of b at a float
    end is replaced by the exact one (the float ends enclose the exact ones outwards)."""
    t = QI.of_float(b[0])
    if ends is not None:
        f_lo, q_lo, f_hi, q_hi = ends
        t = QI(q_lo if b[0].lo == f_lo else t.lo, q_hi if b[0].hi == f_hi else t.hi)
    try:
        return evaluate_q(ex.tree, {var: t}, params, ex.source.strip().replace("^", "**"))
    except (ArithmeticError, ValueError, KeyError):
        return None


def _rational_arithmetic(ex: Expr) -> bool:
    """Whether the expression is built from numeric literals and the spec's parameters (exact
    rationals) by + − × ÷ and powers only: its exact value is a rational that sympy computes
    without evaluating any function (:func:`_constant_inside`)."""
    ok_ops = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.BitXor, ast.USub, ast.UAdd)
    for node in ast.walk(ex.tree):
        if isinstance(node, (ast.Expression, ast.BinOp, ast.UnaryOp, *ok_ops)):
            continue
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            continue
        if isinstance(node, ast.Name) and node.id in ex.parameters:
            continue
        if isinstance(node, ast.Load):
            continue
        return False
    return True


def _constant_inside(ex: Expr, lo: Fraction, hi: Fraction) -> tuple[bool, bool]:
    """(proved lo ≤ value ≤ hi, proved outside) for an expression without the variable,
    compared exactly when it is rational arithmetic on literals and parameters (+ − × ÷ and
    integer powers, each power small enough to take exactly); anything else (a function, π,
    e, a power taken in floats) is undecided here, (False, False), and left to the interval
    enclosures. sympy used to decide every constant: ``floor(e**e**e**e)`` hung in its
    evalf, and ``pi**1000000/10**100000``, whose power was taken in floats (inf), became an
    exact 0 and was certified inside U = [0, 1] (hostile-input trial, session 24)."""
    import sympy

    from obsdesign.spec.expr import InexactPower

    if not _rational_arithmetic(ex):
        return False, False
    try:
        v = ex.exact_sympy()
        if not v.is_Rational:
            return False, False
        a, b = (
            sympy.Rational(lo.numerator, lo.denominator),
            sympy.Rational(hi.numerator, hi.denominator),
        )
        ge, le = (v >= a), (v <= b)
    except (InexactPower, TypeError, ValueError, ArithmeticError, AttributeError):
        return False, False
    if ge is sympy.true and le is sympy.true:
        return True, False
    if ge is sympy.false or le is sympy.false:
        return False, True
    return False, False
