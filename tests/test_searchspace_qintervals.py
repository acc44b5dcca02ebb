"""Exact-end-point value enclosures (obsdesign.methods.searchspace.qintervals): every
enclosure contains the exact value at every point of its box, and it is exact where the
arithmetic is rational."""

from __future__ import annotations

from fractions import Fraction

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

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
        v = _exact(text, t)
        if v.is_Rational:
            assert q.lo <= Fraction(int(v.p), int(v.q)) <= q.hi, (text, t)
        else:
            x = sympy.Float(v.evalf(60), 60)
            assert sympy.Rational(q.lo.numerator, q.lo.denominator) <= x, (text, t)
            assert x <= sympy.Rational(q.hi.numerator, q.hi.denominator), (text, t)


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
