"""Exact-end-point value enclosures (obsdesign.methods.searchspace.qintervals): every
enclosure contains the exact value at every point of its box, and it is exact where the
arithmetic is rational."""

from __future__ import annotations

import ast
import math
from fractions import Fraction
from itertools import product

import mpmath
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.methods.searchspace import qintervals as QM
from obsdesign.methods.searchspace.intervals import I
from obsdesign.methods.searchspace.qintervals import QI, evaluate_q, qpow_int
from obsdesign.spec.expr import parse_expr

TEMPLATES = [
    "{a}*sin({k}*t) + {c}",
    "{a}*cos(t)^2 - {c}",
    "({a}*t - {c})^3",
    "abs({a}*t - {c}) + floor(t)",
    "sat({a}*t, {k}) * {c}",
    "t - floor(t) + {c}*step(t - {k})",
    "floor(t) - t + {a}",
    "mod({a}*t, {k})",
    "max({a}*t, {c}) - min(t, {k})",
    "exp(-{k}*t) * {a}",
    "tanh({a}*t) + sqrt(t + {k})",
    "{a}/(t + {k})",
    "(t - {c})*step(t - {c})",
    "-(t - {c})*step(t - {c})",
    "{a}*(t - {c})*step({k}*(t - {c}))",
    "(t - {c})*step(-(t - {c}))*{a}",
    "(t - {c})*sign(t - {c})*{k}",
    "t*(t - {c})*step(t - {c})",
    "sign(t - {c}) * {a}",
    "atan(t - {c}/3) * {a}",
    "sinh((t - {k})/4) + tanh(t - {c}/3)",
    "log(t/{k} + 1/2) + exp(({c}/10 - t)/4)",
    "sqrt(t/{k}) - {a}",
]


def _enclose(text: str, lo: Fraction, hi: Fraction) -> QI:
    ex = parse_expr(text, ["t"])
    return evaluate_q(ex.tree, {"t": QI(lo, hi)}, {}, ex.source.strip().replace("^", "**"))


def _exact(text: str, t: Fraction) -> sympy.Expr:
    ex = parse_expr(text, ["t"])
    return ex.sympy().subs(sympy.Symbol("t"), sympy.Rational(t.numerator, t.denominator))


def _assert_contains(q: QI, v: sympy.Expr, where: object) -> None:
    """The exact value v (rational, else to 60 digits) lies in the enclosure q."""
    if v.is_Rational:
        assert q.lo <= Fraction(int(v.p), int(v.q)) <= q.hi, where
    else:
        x = sympy.Float(v.evalf(60), 60)
        assert sympy.Rational(q.lo.numerator, q.lo.denominator) <= x, where
        assert x <= sympy.Rational(q.hi.numerator, q.hi.denominator), where


@settings(max_examples=120, deadline=None)
@given(
    st.sampled_from(TEMPLATES),
    st.integers(-30, 30),
    st.integers(1, 9),
    st.integers(-30, 30),
    st.integers(0, 800),
    st.integers(0, 300),
    st.lists(st.integers(0, 1000), min_size=3, max_size=3),
)
def test_enclosure_contains_the_exact_value(
    tpl: str, a: int, k: int, c: int, t0: int, w: int, fracs: list[int]
) -> None:
    """At rational points of a random sub-interval of [0, 11], the exact value (sympy: exact
    for rational arithmetic, 60 digits for the transcendental functions) lies in the
    enclosure of the sub-interval."""
    text = tpl.format(a=a / 10, k=k, c=c / 10)
    lo, hi = Fraction(t0, 100), Fraction(t0 + w, 100)
    q = _enclose(text, lo, hi)
    assert q.lo <= q.hi
    for f in [0, 1000, *fracs]:
        t = lo + (hi - lo) * Fraction(f, 1000)
        _assert_contains(q, _exact(text, t), (text, t))


@pytest.mark.parametrize(
    "text,lo,hi,want",
    [
        ("0.3*sin(t)", 0, 8, (Fraction(-3, 10), Fraction(3, 10))),
        ("0.5 + 0.6*sin(2*t)", 0, 8, (Fraction(-1, 10), Fraction(11, 10))),
        ("0.1*t^2 - t", -1, 2, (Fraction(-2), Fraction(7, 5))),  # no dependency tracking
        ("floor(t) - t + 1", Fraction(1, 2), 3, (Fraction(0), Fraction(1))),
        ("(t - 1)*step(t - 1)", 0, 2, (Fraction(0), Fraction(1))),
        # the switch readings (switches.split): exact, where the product as written gave
        # [-2, 2], [-1, 1] and [-1, 2]
        ("2*(t - 1)*step(t - 1)", 0, 2, (Fraction(0), Fraction(2))),
        ("(t - 1)*step(1 - t)", 0, 2, (Fraction(-1), Fraction(0))),
        ("(t - 1)*sign(t - 1)", 0, 3, (Fraction(0), Fraction(2))),
        ("t/(t + 1)", 1, 3, (Fraction(1, 4), Fraction(3, 2))),
    ],
)
def test_exact_where_rational(text: str, lo: int, hi: int, want: tuple) -> None:
    q = _enclose(text, Fraction(lo), Fraction(hi))
    assert (q.lo, q.hi) == want


def test_refusals_and_powers() -> None:
    """A divisor interval containing 0 raises (the caller says "not proved"); integer powers
    are exact with the sign rules of even and odd exponents."""
    with pytest.raises(ArithmeticError):
        _enclose("1/t", Fraction(-1), Fraction(1))
    x = QI(Fraction(-2), Fraction(1))
    assert qpow_int(x, 2) == QI(Fraction(0), Fraction(4))
    assert qpow_int(x, 3) == QI(Fraction(-8), Fraction(1))
    assert qpow_int(QI(Fraction(1, 2), Fraction(2)), -2) == QI(Fraction(1, 4), Fraction(4))
    # a non-integer power goes through the float enclosure: contains 2^0.5
    q = _enclose("t^0.5", Fraction(2), Fraction(2))
    assert q.lo < Fraction(14142135623730951, 10**16) and q.hi > Fraction(14142135623730950, 10**16)


def test_nested_powers_stay_small() -> None:
    """((t^64)^64)^64 on [1/2, 3/4]: the exact end points would have ~10⁶ bits; they are
    widened to the enclosing float interval past MAX_BITS (3/4 to the 262144th underflows to
    the smallest subnormal or 0 in floats: the enclosure still contains the value)."""
    from obsdesign.methods.searchspace import qintervals as qi

    q = _enclose("((t^64)^64)^64", Fraction(1, 2), Fraction(3, 4))
    assert q.lo >= 0 and q.hi > 0
    assert max(q.hi.numerator.bit_length(), q.hi.denominator.bit_length()) <= 1100
    assert q.lo <= Fraction(1, 2) ** 262144 and q.hi >= Fraction(3, 4) ** 262144
    big = qi._cap(QI(Fraction(3, 4) ** 4000, Fraction(1)))
    assert big.lo <= Fraction(3, 4) ** 4000 and big.hi == 1


@pytest.mark.parametrize(
    "text,lo,hi,want_lo,want_hi",
    [
        ("atan(t)", "0", "1/2", Fraction(0), None),  # atan(0) = 0: t ≥ 0 gives ≥ 0 exactly
        ("atan(t)", "-1/2", "0", None, Fraction(0)),
        ("atan(t)", "0", "0", Fraction(0), Fraction(0)),
        ("tanh(t)", "-3", "0", None, Fraction(0)),
        ("sinh(t)", "0", "2", Fraction(0), None),
        ("exp(t)", "0", "1", Fraction(1), None),
        ("exp(t)", "-1", "0", None, Fraction(1)),
        ("log(t)", "1", "2", Fraction(0), None),
        ("log(t)", "1/2", "1", None, Fraction(0)),
        ("sqrt(t)", "1", "4", Fraction(1), None),
        ("sqrt(t)", "0", "1", Fraction(0), Fraction(1)),
    ],
)
def test_increasing_functions_are_exact_at_their_anchor(
    text: str, lo: str, hi: str, want_lo: Fraction | None, want_hi: Fraction | None
) -> None:
    """f(c) = v exactly for an increasing f (atan, tanh, sinh at 0; exp(0) = 1; log(1) = 0;
    sqrt(0) = 0, sqrt(1) = 1): on an interval at or beyond c the enclosure's end is v, not
    a float rounded outwards past it."""
    q = _enclose(text, Fraction(lo), Fraction(hi))
    if want_lo is not None:
        assert q.lo == want_lo, q
    if want_hi is not None:
        assert q.hi == want_hi, q


# -- mutation review 23: exact oracles for every rule of the exact-end-point kernel --------
_fr = st.builds(Fraction, st.integers(-40, 40), st.integers(1, 12))
_qis = st.builds(lambda a, b: QI(min(a, b), max(a, b)), _fr, _fr)


def _hull(vals: list[Fraction]) -> QI:
    return QI(min(vals), max(vals))


def _points(q: QI) -> list[Fraction]:
    """End points, the midpoint and the integers and 0 inside (where the rules turn)."""
    pts = [q.lo, q.hi, (q.lo + q.hi) / 2]
    pts += [Fraction(k) for k in range(math.floor(q.lo), math.ceil(q.hi) + 1) if q.lo <= k <= q.hi]
    return pts


@settings(max_examples=100, deadline=None)
@given(_qis, _qis, st.integers(-5, 7))
def test_exact_interval_rules_are_the_exact_hulls(x: QI, y: QI, k: int) -> None:
    """mutation review 23: + − × ÷ neg abs max min x^k of rational intervals are exactly the
    hulls of the exact results (÷ and negative powers refused across 0); floor, step, sign
    and frac are the exact ranges over the interval's turning points."""
    ends = list(product((x.lo, x.hi), (y.lo, y.hi)))
    assert x + y == _hull([a + b for a, b in ends])
    assert x - y == _hull([a - b for a, b in ends])
    assert x * y == _hull([a * b for a, b in ends])
    assert -x == QI(-x.hi, -x.lo)
    if y.lo <= 0 <= y.hi:
        with pytest.raises(ArithmeticError):
            x / y
    else:
        assert x / y == _hull([a / b for a, b in ends])
    pts = _points(x)
    assert x.abs() == _hull([abs(t) for t in pts])
    assert QM.qmax(x, y) == QI(max(x.lo, y.lo), max(x.hi, y.hi))
    assert QM.qmin(x, y) == QI(min(x.lo, y.lo), min(x.hi, y.hi))
    assert QM.qfloor(x) == _hull([Fraction(math.floor(t)) for t in pts])
    step = _hull([Fraction(int(t > 0)) for t in pts])
    assert QM.qstep(x) == step
    assert QM.qstep(x, sign=True) == _hull([Fraction((t > 0) - (t < 0)) for t in pts])
    if math.floor(x.lo) == math.floor(x.hi):
        assert QM.qfrac(x) == QI(x.lo - math.floor(x.lo), x.hi - math.floor(x.lo))
    else:
        assert QM.qfrac(x) == QI(Fraction(0), Fraction(1))
    if k < 0 and x.lo <= 0 <= x.hi:
        with pytest.raises(ArithmeticError):
            QM.qpow_int(x, k)
    else:
        assert QM.qpow_int(x, k) == _hull([t**k for t in pts if t != 0 or k >= 0])
    b = QI(abs(y.hi) + 1, abs(y.hi) + 1)
    assert QM._qmod(x, b) == QM.qfrac(x / b) * b


def test_exact_interval_helpers() -> None:
    """mutation review 23: meet intersects (or keeps the interval when the intersection is
    empty), of_float / to_float convert exactly and outward, _bits and _cap bound the size of
    the end points exactly at MAX_BITS, _qmod refuses b ≤ 0."""
    q = QI(Fraction(-2), Fraction(3))
    assert q.meet(Fraction(-1), Fraction(1)) == QI(Fraction(-1), Fraction(1))
    assert q.meet(None, Fraction(1)) == QI(Fraction(-2), Fraction(1))
    assert q.meet(Fraction(-1), None) == QI(Fraction(-1), Fraction(3))
    assert q.meet(None, None) == q and q.meet(Fraction(-5), Fraction(5)) == q
    assert q.meet(Fraction(3), None) == QI(Fraction(3), Fraction(3))
    assert q.meet(None, Fraction(-2)) == QI(Fraction(-2), Fraction(-2))
    assert q.meet(Fraction(4), None) == q and q.meet(None, Fraction(-3)) == q
    assert QI.of_float(I(0.1, 0.5)) == QI(Fraction(0.1), Fraction(1, 2))
    for bad in (I(0.0, math.inf), I(-math.inf, 0.0)):
        with pytest.raises(ArithmeticError):
            QI.of_float(bad)
    tenth = QI(Fraction(1, 10), Fraction(1, 10)).to_float()
    assert Fraction(tenth.lo) < Fraction(1, 10) < Fraction(tenth.hi)
    assert math.nextafter(tenth.lo, 1.0) == tenth.hi
    assert QI(Fraction(1, 4), Fraction(3)).to_float() == I(0.25, 3.0)
    assert QI.point(Fraction(3, 7)) == QI(Fraction(3, 7), Fraction(3, 7))
    assert QM._bits(QI(Fraction(-7, 3), Fraction(1, 1024))) == 11
    assert QM._bits(QI(Fraction(1, 3), Fraction(2**20, 3))) == 21
    assert QM._bits(QI(Fraction(-(2**30), 3), Fraction(1))) == 31
    assert QM._bits(QI(Fraction(0), Fraction(1, 2**40 + 1))) == 41
    kept = QI(Fraction(1, 2**4095 + 1), Fraction(1))  # 4096 bits: exact
    assert QM._cap(kept) == kept
    wide = QM._cap(QI(Fraction(1, 2**4096 + 1), Fraction(1)))  # 4097 bits: the float hull
    assert wide == QI(Fraction(0), Fraction(1))
    huge = QI(Fraction(1), Fraction(2**4100))
    with pytest.raises(ArithmeticError, match="float range"):
        QM._cap(huge)
    with pytest.raises(ArithmeticError):
        QM._qmod(q, QI(Fraction(0), Fraction(1)))
    assert QM.qpow_int(q, 0) == QM.ONE_Q == QI(Fraction(1), Fraction(1))
    assert QM.ZERO_Q == QI(Fraction(0), Fraction(0))


@pytest.mark.parametrize(
    ("text", "lo", "hi", "want"),
    [
        ("abs(t)", "-3", "1", ("0", "3")),
        ("abs(t)", "-3", "-1", ("1", "3")),
        ("abs(t)", "0", "2", ("0", "2")),
        ("abs(t)", "-2", "0", ("0", "2")),
        ("abs(t - 1)", "2", "3", ("1", "2")),
        ("max(t, 0.5)", "0", "1", ("1/2", "1")),
        ("min(t, 0.5)", "0", "1", ("0", "1/2")),
        ("sat(t)", "-2", "1/2", ("-1", "1/2")),
        ("sat(t, 0.5)", "-2", "2", ("-1/2", "1/2")),
        ("sat(3*t)", "0", "1/6", ("0", "1/2")),
        ("step(t)", "0", "1", ("0", "1")),
        ("step(t)", "-1", "0", ("0", "0")),
        ("step(t)", "1/2", "1", ("1", "1")),
        ("heaviside(t - 1)", "0", "1", ("0", "0")),
        ("sign(t)", "-1", "0", ("-1", "0")),
        ("sign(t)", "0", "0", ("0", "0")),
        ("sign(t)", "-1", "-1/2", ("-1", "-1")),
        ("sign(t)", "0", "1", ("0", "1")),
        ("sign(t)", "-1", "1", ("-1", "1")),
        ("floor(t)", "1/2", "5/2", ("0", "2")),
        ("floor(t)", "-3/2", "-1/2", ("-2", "-1")),
        ("t - floor(t)", "1/4", "3/4", ("1/4", "3/4")),
        ("t - floor(t)", "1/2", "3/2", ("0", "1")),
        ("floor(t) - t", "5/4", "7/4", ("-3/4", "-1/4")),
        ("floor(t) - t", "1/2", "3/2", ("-1", "0")),
        ("mod(t, 2)", "5/2", "7/2", ("1/2", "3/2")),
        ("t % 0.75", "0", "1/2", ("0", "1/2")),
        ("t % 0.75", "1/2", "1", ("0", "3/4")),
        ("t*step(t)", "-1", "2", ("0", "2")),
        ("step(t)*t", "-2", "-1", ("0", "0")),
        ("-t*step(t)", "-1", "2", ("-2", "0")),
        ("step(t)*(-t)", "1", "2", ("-2", "-1")),
        ("t*step(t - 1)", "-1", "2", ("-1", "2")),
        ("(-t)*step(t - 1)", "-1", "2", ("-2", "1")),
        ("t**2", "-2", "1", ("0", "4")),
        ("t**3", "-2", "1", ("-8", "1")),
        ("t**2", "-3", "-1", ("1", "9")),
        ("(t/3)**2", "1", "2", ("1/9", "4/9")),
        ("t**0", "-1", "1", ("1", "1")),
        (
            "t**64",
            "1/3",
            "1/3",
            ("1/3433683820292512484657849089281", "1/3433683820292512484657849089281"),
        ),
        ("t - 2*t", "1", "2", ("-3", "0")),
        ("+t - 1", "1", "2", ("0", "1")),
        ("0x10*t", "1", "2", ("16", "32")),
        ("t/(t + 1)", "1", "3", ("1/4", "3/2")),
        ("sin(t)", "0", "8", ("-1", "1")),
        ("cos(t)", "0", "8", ("-1", "1")),
        ("tanh(t)", "-30", "30", ("-1", "1")),
        ("exp(t)", "-800", "0", ("0", "1")),
        ("sqrt(t)", "0", "1/4", ("0", None)),
        ("cosh(t)", "-1", "1", ("1", None)),
        ("sinh(t)", "-1", "0", (None, "0")),
        ("log(t)", "1", "1", ("0", "0")),
    ],
)
def test_exact_enclosures_known_answers(text: str, lo: str, hi: str, want: tuple) -> None:
    """mutation review 23: exact end points for every exact rule of evaluate_q (abs max min
    sat step heaviside sign floor mod, the patterns, integer powers up to MAX_EXACT_POWER,
    hexadecimal literals) and the exact ranges / anchors of the smooth functions."""
    q = _enclose(text, Fraction(lo), Fraction(hi))
    if want[0] is not None:
        assert q.lo == Fraction(want[0]), q
    if want[1] is not None:
        assert q.hi == Fraction(want[1]), q
    if None in want:
        assert q.lo < q.hi


def test_exact_enclosures_limits_and_refusals() -> None:
    """mutation review 23: powers beyond MAX_EXACT_POWER, or whose end points would pass
    MAX_BITS, go through the float enclosure (still containing the value); parameters are
    taken exactly; no source text means literals known as their doubles; an unknown
    operator, a divisor or modulus across 0 are refused."""
    third = Fraction(1, 3)
    # exact up to MAX_BITS bits whatever the exponent (65 went through floats until session
    # 33, and 2^1100 overflowed them), signed exponents too; 3^4097 is beyond MAX_BITS
    assert _enclose("t**65", third, third) == QI(third**65, third**65)
    assert _enclose("(t + 2**1100) - 2**1100", third, third) == QI(third, third)
    assert _enclose("t*2**(-1100)", third, third) == QI(third / 2**1100, third / 2**1100)
    assert _enclose("t**(-3)", third, third) == QI(Fraction(27), Fraction(27))
    q = _enclose("t**4097", third, third)
    assert q.lo < third**4097 < q.hi
    big = Fraction(1, 2**63 + 1)  # 64 bits: 64·64 = MAX_BITS, kept exact
    assert _enclose("t**64", big, big) == QI(big**64, big**64)
    big = Fraction(1, 2**64 + 1)  # 65 bits: the float enclosure
    q = _enclose("t**64", big, big)
    assert q.lo <= big**64 <= q.hi and q.lo != q.hi
    ex = parse_expr("a*t", ["t"], {"a": Fraction(3, 10)})
    a = QI(Fraction(3, 10), Fraction(3, 10))
    got = evaluate_q(ex.tree, {"t": QI(Fraction(1), Fraction(2))}, {"a": a}, ex.source)
    assert got == QI(Fraction(3, 10), Fraction(3, 5))
    t = {"t": QI(Fraction(1), Fraction(2))}
    assert evaluate_q(ast.parse("3*t", mode="eval"), t, {}, None) == QI(Fraction(3), Fraction(6))
    q = evaluate_q(ast.parse("0.1*t", mode="eval"), t, {}, None)
    assert q.lo < Fraction(1, 10) and Fraction(1, 5) < q.hi
    q = evaluate_q(ast.parse("pi + t - e", mode="eval"), t, {}, None)
    with mpmath.workdps(40):
        assert float(q.lo) <= 1 + mpmath.pi - mpmath.e and 2 + mpmath.pi - mpmath.e <= float(q.hi)
    assert q.hi - q.lo < 1 + Fraction(1, 10**14)
    with pytest.raises(ValueError, match="operator"):
        evaluate_q(ast.parse("t << 1", mode="eval"), t, {}, None)
    with pytest.raises(ValueError, match="cannot enclose"):
        evaluate_q(ast.parse("t.real", mode="eval"), t, {}, None)
    for text in ("mod(t, t - 1)", "t % 0", "1/(t - 1)"):
        with pytest.raises(ArithmeticError):
            _enclose(text, Fraction(1), Fraction(2))


@pytest.mark.parametrize(
    "text",
    [
        "sign(t - 1)*t", "heaviside(t - 1)*2", "min(t, 1)*max(t, 2)", "cosh(t) - sinh(t)",
        "tan(t/8)", "pi*t - e", "(t + 1)**0.5", "(t + 1)**t", "atan(t - 1)", "exp(-t)*sin(3*t)",
        "log(t + 1/2)", "sqrt(t) - t", "sat(t - 1, 0.25)", "mod(3*t, 0.7)", "floor(2*t)/2",
    ],
)  # fmt: skip
def test_exact_enclosures_contain_the_value(text: str) -> None:
    """mutation review 23: the enclosure on sub-intervals of [0, 4] (ends on multiples of
    1/4, so on the turning points) contains the exact value at their ends, midpoints and
    quarter points (sympy, 60 digits for transcendental values)."""
    for a, b in [(0, 1), (1, 1), (0, 4), (1, 2), (3, 4), (2, 2), (1, 3)]:
        lo, hi = Fraction(a, 1), Fraction(b, 1)
        q = _enclose(text, lo, hi)
        assert q.lo <= q.hi
        for f in (0, 1, 2, 3, 4):
            t = lo + (hi - lo) * Fraction(f, 4)
            _assert_contains(q, _exact(text, t), (text, t))


@pytest.mark.parametrize(
    ("text", "lo", "hi", "want"),
    [
        ("t*heaviside(t)", "-1", "2", ("0", "2")),
        ("heaviside(t)*t", "-1", "2", ("0", "2")),
        ("-t*heaviside(t)", "-1", "2", ("-2", "0")),
        ("heaviside(t)*(-t)", "1", "2", ("-2", "-1")),
        ("(t - a)*step(t - a)", "0", "1", ("0", "9/10")),
        ("(t - 0.1)*step(t - 0.1)", "0", "1", ("0", "9/10")),
        ("-(t - a)*step(t - a)", "0", "1", ("-9/10", "0")),
        ("-(t - 0.1)*step(t - 0.1)", "0", "1", ("-9/10", "0")),
        ("(t + a) - floor(t + a)", "0", "1/2", ("1/10", "3/5")),
        ("(t + 0.1) - floor(t + 0.1)", "0", "1/2", ("1/10", "3/5")),
        ("floor(t + a) - (t + a)", "0", "1/2", ("-3/5", "-1/10")),
        ("floor(t + 0.1) - (t + 0.1)", "0", "1/2", ("-3/5", "-1/10")),
        ("(t + a)**2", "0", "1", ("1/100", "121/100")),
        ("(t + 0.1)**2", "0", "1", ("1/100", "121/100")),
        ("-(t - a)", "0", "1", ("-9/10", "1/10")),
        ("-(t - 0.1)", "0", "1", ("-9/10", "1/10")),
        ("abs(t - a)", "0", "1", ("0", "9/10")),
        ("abs(t - 0.1)", "0", "1", ("0", "9/10")),
        ("max(t, 0.1)", "0", "1", ("1/10", "1")),
        ("min(t, a)", "0", "1", ("0", "1/10")),
        ("sat(t, 0.3)", "-1", "1", ("-3/10", "3/10")),
        ("sat(t - a)", "0", "1/2", ("-1/10", "2/5")),
        ("step(t - 0.1)", "0", "1/10", ("0", "0")),
        ("heaviside(t - a)", "0", "1/10", ("0", "0")),
        ("sign(t - 0.1)", "1/10", "1/10", ("0", "0")),
        ("floor(t - a)", "1/10", "11/10", ("0", "1")),
        ("mod(t, 0.3)", "0", "1/10", ("0", "1/10")),
        ("t % a", "0", "1/20", ("0", "1/20")),
    ],
)
def test_patterns_keep_parameters_and_exact_literals(
    text: str, lo: str, hi: str, want: tuple[str, str]
) -> None:
    """mutation review 23: the step patterns with heaviside, the ramp and sawtooth patterns
    and integer powers take a parameter (a = 1/10) and a decimal literal at their exact
    values (the range claim compares with U exactly); a sub-expression enclosed in floats
    gets the parameters too."""
    ex = parse_expr(text, ["t"], {"a": Fraction(1, 10)})
    a = QI(Fraction(1, 10), Fraction(1, 10))
    src = ex.source.strip().replace("^", "**")
    q = evaluate_q(ex.tree, {"t": QI(Fraction(lo), Fraction(hi))}, {"a": a}, src)
    assert q == QI(Fraction(want[0]), Fraction(want[1])), q


@pytest.mark.parametrize("text", ["atan(t - a)", "atan(t - 0.1)", "sinh(t - a)", "tanh(t - 0.1)"])
def test_anchors_see_the_exact_argument(text: str) -> None:
    """mutation review 23: the argument of a smooth function is enclosed exactly (parameter
    and literal at their exact values), so t − 1/10 ≥ 0 on [1/10, 1] gives f ≥ f(0) = 0."""
    ex = parse_expr(text, ["t"], {"a": Fraction(1, 10)})
    a = QI(Fraction(1, 10), Fraction(1, 10))
    src = ex.source.strip().replace("^", "**")
    q = evaluate_q(ex.tree, {"t": QI(Fraction(1, 10), Fraction(1))}, {"a": a}, src)
    assert q.lo == 0 and q.hi > Fraction(7, 10)


def test_float_sub_expressions_take_decimal_literals_exactly() -> None:
    """mutation review 23: a sub-expression that goes through the float enclosure (a
    non-integer power) reads its decimal literals from the source text (the tightest float
    interval around 0.1), as the float kernel does."""
    from obsdesign.methods.searchspace.intervals import Dual, evaluate

    text = "(0.1*t)**0.5"
    ex = parse_expr(text, ["t"])
    q = _enclose(text, Fraction(2), Fraction(3))
    want = evaluate(ex.tree, {"t": Dual(I(2.0, 3.0), ())}, {}, 0, ex.source).v
    assert q == QI.of_float(want)
    ex = parse_expr("(a*t)**0.5", ["t"], {"a": Fraction(1, 10)})
    a = QI(Fraction(1, 10), Fraction(1, 10))
    q = evaluate_q(ex.tree, {"t": QI(Fraction(10), Fraction(10))}, {"a": a}, ex.source)
    assert q.lo <= 1 <= q.hi and q.hi - q.lo < Fraction(1, 10**15)


_WITH_K = [
    "-(k*t)", "+(k*t)", "(t - k)*step(t - k)", "step(t - k)*(t - k)", "-(t - k)*step(t - k)",
    "step(t - k)*(-(t - k))", "(t + k) - floor(t + k)", "floor(t + k) - (t + k)", "(t + k)**2",
    "(t + 2)**k", "sin(k*t)", "atan(t - k)", "max(t, k)", "min(k, t)", "mod(t, k)", "t % k",
    "sat(t, k)", "abs(t - k)", "step(t - k)", "heaviside(k - t)", "sign(t - k)", "floor(t - k)",
    "t/k", "k - t", "exp(t*k)", "t*heaviside(t - k)", "(t - k)*heaviside(t - k)",
    "-(t - k)*heaviside(t - k)", "(t - k)**65",
]  # fmt: skip


@pytest.mark.parametrize("text", _WITH_K)
def test_parameters_and_literals_reach_every_exact_rule(text: str) -> None:
    """mutation review 23: a parameter k = 1/10 and the literal 0.1 (exact, from the source
    text) give the same enclosure through every rule and pattern of evaluate_q, on a box
    with the rational end points 1/10 and 3/2: each recursive call passes on the parameters
    and the text."""
    box = {"t": QI(Fraction(1, 10), Fraction(3, 2))}
    ex = parse_expr(text, ["t"], {"k": Fraction(1, 10)})
    with_k = evaluate_q(ex.tree, box, {"k": QI(Fraction(1, 10), Fraction(1, 10))}, ex.source)
    lit = parse_expr(text.replace("k", "0.1"), ["t"])
    assert with_k == evaluate_q(lit.tree, box, {}, lit.source)
