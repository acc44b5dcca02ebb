"""Interval enclosures with exact rational end points of a spec expression's value (no
derivatives), for the input-range claim u(t) ∈ U (Remark 2.5, Hernández & García).

The float enclosures of :mod:`obsdesign.methods.searchspace.intervals` round every operation
outward, so a bound the input attains exactly is never proved: u = 0.3·sin(t) against
U = [−0.3, 0.3] gives 0.3 (the nearest double, below 0.3) times [−1, 1], rounded out to
±0.30000000000000004 (exit 4, "not proved either way"). A :class:`QI` keeps its end points as
``Fraction`` and is exact wherever the arithmetic is rational:

- decimal literals at their exact value, ``+ − × ÷`` and integer powers exactly (÷ refuses a
  divisor interval that contains 0), ``abs max min sat step heaviside sign floor mod``, the
  switch readings of :mod:`~obsdesign.methods.searchspace.switches` (``X*step(X)`` =
  max(X, 0), ``X*step(-X)`` = min(X, 0), ``X*sign(X)`` = |X|, …) and ``X - floor(X)``,
  ``floor(X) - X`` exactly;
- the smooth functions (``sin cos tan exp log sqrt atan tanh sinh cosh``) through the float
  enclosure of their argument (:func:`~obsdesign.methods.searchspace.intervals.d_fn`,
  rigorous) intersected with the exact range of the function: [−1, 1] for sin, cos and tanh,
  [0, ∞) for exp and sqrt, [1, ∞) for cosh; so sin(t) on any interval lies in [−1, 1] exactly,
  and 0.5 + 0.6·sin(2t) in [−0.1, 1.1]; the increasing ones also by their exact values at a
  rational point (``_ANCHORS``: atan, tanh, sinh at 0; exp(0) = 1; log(1) = 0; sqrt at 0 and
  1), so atan(t) ≥ 0 exactly for t ≥ 0;
- anything else (a non-integer power, ``pi`` and ``e``) through the float enclosure of that
  sub-expression, converted exactly.

Every result contains the exact value of the expression at every point of the box (each rule
is an interval extension of the operation, and an intersection of two enclosures is one).
"""

from __future__ import annotations

import ast
import math
import operator
from dataclasses import dataclass
from fractions import Fraction

from obsdesign.methods.searchspace import switches
from obsdesign.methods.searchspace.intervals import (
    _CONSTS,
    Dual,
    I,
    _is_call,
    _lit,
    _same,
    d_fn,
    evaluate,
    int_literal,
)
from obsdesign.spec.expr import source_segment

_SMOOTH = ("exp", "log", "sqrt", "sin", "cos", "tan", "atan", "tanh", "sinh", "cosh")
#: the exact range of a smooth function, where it has a rational one
_RANGE: dict[str, tuple[Fraction | None, Fraction | None]] = {
    "sin": (Fraction(-1), Fraction(1)),
    "cos": (Fraction(-1), Fraction(1)),
    "tanh": (Fraction(-1), Fraction(1)),
    "exp": (Fraction(0), None),
    "sqrt": (Fraction(0), None),
    "cosh": (Fraction(1), None),
}

#: exact values of increasing smooth functions at a rational point: f(c) = v, so f(x) ≥ v
#: for x ≥ c and f(x) ≤ v for x ≤ c (u = atan(t) on [0, 10⁶] against U = [0, 1.5707963]
#: was inconclusive: the float enclosure of atan near t = 0 reaches −5e-324)
_ANCHORS: dict[str, tuple[tuple[Fraction, Fraction], ...]] = {
    "atan": ((Fraction(0), Fraction(0)),),
    "tanh": ((Fraction(0), Fraction(0)),),
    "sinh": ((Fraction(0), Fraction(0)),),
    "exp": ((Fraction(0), Fraction(1)),),
    "log": ((Fraction(1), Fraction(0)),),
    "sqrt": ((Fraction(0), Fraction(0)), (Fraction(1), Fraction(1))),
}


@dataclass(frozen=True, slots=True)
class QI:
    """A closed interval [lo, hi] with exact rational (finite) end points."""

    lo: Fraction
    hi: Fraction

    @staticmethod
    def point(x: Fraction) -> QI:
        return QI(x, x)

    @staticmethod
    def of_float(x: I) -> QI:
        """The float interval x, exactly (ArithmeticError when an end point is infinite)."""
        if not x.finite:
            raise ArithmeticError("unbounded enclosure")
        return QI(Fraction(x.lo), Fraction(x.hi))

    def to_float(self) -> I:
        """The tightest float interval containing this one."""
        return I(I.of_q(self.lo).lo, I.of_q(self.hi).hi)

    def __add__(self, o: QI) -> QI:
        return QI(self.lo + o.lo, self.hi + o.hi)

    def __neg__(self) -> QI:
        return QI(-self.hi, -self.lo)

    def __sub__(self, o: QI) -> QI:
        return QI(self.lo - o.hi, self.hi - o.lo)

    def __mul__(self, o: QI) -> QI:
        ps = [a * b for a in (self.lo, self.hi) for b in (o.lo, o.hi)]
        return QI(min(ps), max(ps))

    def __truediv__(self, o: QI) -> QI:
        if o.lo <= 0 <= o.hi:
            raise ArithmeticError("division by an interval that contains 0")
        return self * QI(1 / o.hi, 1 / o.lo)

    def meet(self, lo: Fraction | None, hi: Fraction | None) -> QI:
        """The intersection with [lo, hi] (None: unbounded), where the exact range of the
        enclosed values is known to lie (so the intersection is never empty)."""
        a = self.lo if lo is None else max(self.lo, lo)
        b = self.hi if hi is None else min(self.hi, hi)
        return QI(a, b) if a <= b else self

    def abs(self) -> QI:
        if self.lo >= 0:
            return self
        if self.hi <= 0:
            return -self
        return QI(Fraction(0), max(-self.lo, self.hi))


ZERO_Q = QI(Fraction(0), Fraction(0))
ONE_Q = QI(Fraction(1), Fraction(1))


def qmax(a: QI, b: QI) -> QI:
    return QI(max(a.lo, b.lo), max(a.hi, b.hi))


def qmin(a: QI, b: QI) -> QI:
    return QI(min(a.lo, b.lo), min(a.hi, b.hi))


def qstep(a: QI, sign: bool = False) -> QI:
    """step(a) = [a > 0], or sign(a) (as :func:`~.intervals.d_step`, values only)."""
    if a.lo > 0:
        return ONE_Q
    if a.hi < 0 or (a.hi <= 0 and not sign):
        return QI(Fraction(-1), Fraction(-1)) if sign else ZERO_Q
    if sign and a.lo == a.hi == 0:
        return ZERO_Q
    return QI(Fraction(-1 if (sign and a.lo < 0) else 0), Fraction(1 if a.hi > 0 else 0))


def qfloor(a: QI) -> QI:
    return QI(Fraction(math.floor(a.lo)), Fraction(math.floor(a.hi)))


def qfrac(a: QI) -> QI:
    """a − floor(a) ∈ [0, 1): exact where floor(a) is constant."""
    k = math.floor(a.lo)
    if k == math.floor(a.hi):
        return a - QI.point(Fraction(k))
    return QI(Fraction(0), Fraction(1))


def qpow_int(a: QI, k: int) -> QI:
    """a^k for an integer k, exactly (k < 0: 1/a^|k|, refused when a contains 0). The
    exponent's size is the caller's to bound (the spec's expression limits)."""
    if k == 0:
        return ONE_Q
    if k < 0:
        return ONE_Q / qpow_int(a, -k)
    lo, hi = a.lo**k, a.hi**k
    if k % 2 == 1:
        return QI(lo, hi)
    if a.lo <= 0 <= a.hi:
        return QI(Fraction(0), max(lo, hi))
    return QI(min(lo, hi), max(lo, hi))


def _qmod(a: QI, b: QI) -> QI:
    """mod(a, b) = b·frac(a/b) for b > 0."""
    if b.lo <= 0:
        raise ArithmeticError("mod(a, b) is enclosed only for b > 0")
    return qfrac(a / b) * b


#: integer powers beyond this exponent go through the float enclosure (the exact end points
#: of x^k grow like k digits; those of more than MAX_BITS bits do too, whatever k): 64 made
#: 2^1100 and 10^400 float overflows, and h = (x1 + 2^1100) − 2^1100 (exactly x1) could not
#: refute a given L_h = 0.5 (soundness trial, session 33)
MAX_EXACT_POWER = 4096
#: an end point whose numerator or denominator passes this many bits is widened to the
#: enclosing float interval (rigorous), so nested powers such as ((t^64)^64)^64 cannot
#: build numbers of millions of digits
MAX_BITS = 4096


def _bits(q: QI) -> int:
    """The largest bit length of a numerator or denominator of q's end points."""
    return max(
        q.lo.numerator.bit_length(),
        q.lo.denominator.bit_length(),
        q.hi.numerator.bit_length(),
        q.hi.denominator.bit_length(),
    )


def _cap(q: QI) -> QI:
    """q, or the float interval enclosing it when an end point has grown past MAX_BITS
    (ArithmeticError when that is beyond the float range)."""
    if _bits(q) > MAX_BITS:
        try:
            return QI.of_float(q.to_float())
        except OverflowError:
            raise ArithmeticError("enclosure beyond the float range") from None
    return q


def evaluate_q(node: ast.AST, env: dict[str, QI], params: dict[str, QI], src: str | None) -> QI:
    """Enclosure of the value of ``node`` over the box ``env`` (variable → :class:`QI`),
    ``params`` the spec parameters' intervals, ``src`` the text the tree was parsed from
    (decimal literals at their exact value). Raises ArithmeticError or ValueError when no
    finite enclosure is found (the caller then says "not proved")."""
    if isinstance(node, ast.Expression):
        node = node.body
    if isinstance(node, ast.Constant):
        seg = source_segment(src, node)
        try:
            return QI.point(Fraction(seg)) if seg is not None else _float_q(node, env, params, src)
        except (ValueError, ZeroDivisionError):
            return QI.of_float(_lit(float(node.value), 0).v)
    if isinstance(node, ast.Name):
        if node.id in env:
            return env[node.id]
        if node.id in params:
            return params[node.id]
        return QI.of_float(_CONSTS[node.id])
    if isinstance(node, ast.UnaryOp):
        a = evaluate_q(node.operand, env, params, src)
        return -a if isinstance(node.op, ast.USub) else a
    if isinstance(node, ast.BinOp):
        return _cap(_binop(node, env, params, src))
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        name = node.func.id
        if name in _SMOOTH:
            a = evaluate_q(node.args[0], env, params, src)
            v = d_fn(Dual(a.to_float(), ()), name).v
            out = QI.of_float(v).meet(*_RANGE.get(name, (None, None)))
            for c, fc in _ANCHORS.get(name, ()):  # monotone: the side of f(c) is exact
                if a.lo >= c:
                    out = out.meet(fc, None)
                if a.hi <= c:
                    out = out.meet(None, fc)
            return out
        args = [evaluate_q(x, env, params, src) for x in node.args]
        if name == "abs":
            return args[0].abs()
        if name == "max":
            return qmax(args[0], args[1])
        if name == "min":
            return qmin(args[0], args[1])
        if name == "sat":
            r = args[1] if len(args) == 2 else ONE_Q
            return qmax(-r, qmin(r, args[0]))
        if name in ("step", "heaviside"):
            return qstep(args[0])
        if name == "sign":
            return qstep(args[0], sign=True)
        if name == "floor":
            return qfloor(args[0])
        if name == "mod":
            return _qmod(args[0], args[1])
    return _float_q(node, env, params, src)


def _binop(node: ast.BinOp, env: dict[str, QI], params: dict[str, QI], src: str | None) -> QI:
    op = type(node.op)
    left, right = node.left, node.right
    if op is ast.Mult and (sp := switches.split(node, src)) is not None:
        return _split_q(sp, env, params, src)  # X*step(X) = max(X, 0), …
    if op is ast.Sub and _is_call(right, "floor") and _same(right.args[0], left, src):
        return qfrac(evaluate_q(left, env, params, src))
    if op is ast.Sub and _is_call(left, "floor") and _same(left.args[0], right, src):
        return -qfrac(evaluate_q(right, env, params, src))  # floor(X) - X = -frac(X)
    if op in (ast.Pow, ast.BitXor):
        k = int_literal(right, src)
        if k is not None and abs(k) <= MAX_EXACT_POWER:
            a = evaluate_q(left, env, params, src)
            if _bits(a) * abs(k) <= MAX_BITS:
                return qpow_int(a, k)
        return _float_q(node, env, params, src)
    fn = _ARITH.get(op)
    if fn is None:
        raise ValueError(f"operator {op.__name__}")
    return fn(evaluate_q(left, env, params, src), evaluate_q(right, env, params, src))


def _split_q(sp: switches.Split, env: dict[str, QI], params: dict[str, QI], src: str | None) -> QI:
    """Exact enclosure of a product with its switches taken out (:func:`switches.split`):
    the remaining factors times max(B, 0), min(B, 0) or |B| of each switch's core B."""

    def prod(nodes: tuple[ast.AST, ...]) -> QI | None:
        acc: QI | None = None
        for f in nodes:
            v = evaluate_q(f, env, params, src)
            acc = v if acc is None else _cap(acc * v)
        return acc

    acc = prod(sp.rest)
    for sw in sp.switches:
        core = prod(sw.core)
        assert core is not None  # split never takes a switch with an empty core
        v = core.abs() if sw.kind == "abs" else (qmax if sw.kind == "max" else qmin)(core, ZERO_Q)
        acc = v if acc is None else _cap(acc * v)
    assert acc is not None
    return -acc if sp.sign < 0 else acc


#: the exact binary operations on :class:`QI`
_ARITH = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Mod: _qmod,
}


def _float_q(node: ast.AST, env: dict[str, QI], params: dict[str, QI], src: str | None) -> QI:
    """The float enclosure of the sub-expression ``node`` (rigorous), converted exactly."""
    fenv = {k: Dual(v.to_float(), ()) for k, v in env.items()}
    fpar = {k: v.to_float() for k, v in params.items()}
    return QI.of_float(evaluate(node, fenv, fpar, 0, src).v)
