"""Safe-direction printing of numbers in claim statements (obsdesign.certify.printing).

Every printed string is parsed back exactly and compared with the value: ``fmt_up`` is ≥ it,
``fmt_down`` ≤ it, ``fmt_exact`` equal, with the stated number of significant digits.
"""

from __future__ import annotations

from fractions import Fraction

import pytest
from flint import fmpq
from hypothesis import given
from hypothesis import strategies as st

from obsdesign.certify.printing import fmt_down, fmt_exact, fmt_up, fmt_value_up

F = fmpq


def parse(s: str) -> fmpq:
    fr = Fraction(s)
    return F(fr.numerator, fr.denominator)


KNOWN = [
    # (value, digits, fmt_up, fmt_down)
    (F(1, 3), 6, "0.333334", "0.333333"),
    (F(-1, 3), 6, "-0.333333", "-0.333334"),
    (F(2, 3), 2, "0.67", "0.66"),
    (F(123456789), 6, "123457000", "123456000"),
    (F(10**13 + 1), 3, "1.01e13", "1e13"),
    (F(-(10**13) - 1), 3, "-1e13", "-1.01e13"),
    (F(1, 10**7) + F(1, 10**12), 2, "1.1e-7", "1e-7"),
    (F(1, 10**7), 2, "1e-7", "1e-7"),
    (F(1), 6, "1", "1"),
    (F(100), 6, "100", "100"),
    (F(1, 10**6), 6, "0.000001", "0.000001"),
    (F(1, 10**500), 3, "1e-500", "1e-500"),  # no floor: exact at any exponent
    (F(385360653, 536870912), 5, "0.7178", "0.71779"),  # issue 15: μ printed as 0.71779
    (F(999999), 3, "1000000", "999000"),
    (F(1999, 2), 3, "1000", "999"),
    (F(-5, 10**8), 2, "-5e-8", "-5e-8"),
    (F(12345678901234), 20, "1.2345678901234e13", "1.2345678901234e13"),
    (F(1, 7), 1, "0.2", "0.1"),
    (F(10**12), 3, "1000000000000", "1000000000000"),
    (F(123, 10**6), 2, "0.00013", "0.00012"),
    (F(0), 3, "0", "0"),
    (F(1000001, 1000), 4, "1001", "1000"),
    (F(-999, 1000), 2, "-0.99", "-1"),
]


@pytest.mark.parametrize(("q", "digits", "up", "down"), KNOWN)
def test_known_strings(q: fmpq, digits: int, up: str, down: str):
    assert fmt_up(q, digits) == up
    assert fmt_down(q, digits) == down
    assert parse(up) >= q >= parse(down)


def test_default_digits_and_inputs():
    assert fmt_up(F(1, 3)) == "0.333334" and fmt_down(F(1, 3)) == "0.333333"
    assert fmt_up("1/3", 2) == "0.34" and fmt_down(0.1, 3) == "0.1"
    assert fmt_up(0.1, 20) == "0.10000000000000000556"  # the float's exact binary value


EXACT = [
    (F(1, 4), "0.25"),
    (F(1, 3), "1/3"),
    (F(5), "5"),
    (F(-187, 100), "-1.87"),
    (F(1, 2**40), "1/1099511627776"),
    # any exponent (only 10^e with e < 40 was tried: a spec's 1e-300 showed as 1/10³⁰⁰
    # written out, session 30)
    (F(3, 10**45), "3e-45"),
    (F(1, 10**300), "1e-300"),
    (F(-25, 10**308), "-2.5e-307"),
    (F(3, 2**45 * 10**45), "3/" + str(2**45 * 10**45)),
    (F(10**20), "1e20"),
    (F(0), "0"),
    (F(1, 2**20), "9.5367431640625e-7"),
    (F(7, 5**10), "7.168e-7"),
    (F(10**31 + 1), "10000000000000000000000000000001"),
    (F(-3, 8), "-0.375"),
    (F(1, 6), "1/6"),
    (F(1, 10), "0.1"),
    (F(3, 50), "0.06"),
    (F(7, 20), "0.35"),
    (F(123456789, 1000), "123456.789"),
    (F(1, 5**13), "8.192e-10"),
]


@pytest.mark.parametrize(("q", "s"), EXACT)
def test_fmt_exact_known(q: fmpq, s: str):
    assert fmt_exact(q) == s
    assert parse(s) == q


finite = st.builds(
    lambda p, q, e: F(p, q) * F(10) ** e,
    st.integers(-(10**9), 10**9),
    st.integers(1, 10**6),
    st.integers(-30, 30),
)


@given(finite, st.integers(1, 12))
def test_safe_direction_and_tight(q: fmpq, digits: int):
    up, down = parse(fmt_up(q, digits)), parse(fmt_down(q, digits))
    assert down <= q <= up
    if q != 0:
        # one unit in the last of `digits` significant digits
        assert up - down <= abs(q) * F(10) ** (1 - digits) * 10
        assert up - q <= abs(q) * F(10) ** (1 - digits)
        assert q - down <= abs(q) * F(10) ** (1 - digits)
    for s in (fmt_up(q, digits), fmt_down(q, digits)):
        mant = s.lstrip("-").split("e")[0].replace(".", "").strip("0")
        assert len(mant) <= digits


@given(
    st.builds(
        lambda p, q, e: F(p, q) * F(10) ** e,
        st.integers(-(10**9), 10**9).filter(bool),
        st.integers(1, 10**6),
        st.integers(-700, 700),
    ),
    st.integers(1, 12),
)
def test_safe_and_tight_at_any_exponent(q: fmpq, digits: int):
    """The exponent now comes from the bit lengths (one big-rational power per number instead
    of ~400 steps): safe and one unit tight from 1e-700 to 1e700, where the old −400 floor
    printed 1e-500 as "1e-400" (safe but not tight: this test fails on it)."""
    up, down = parse(fmt_up(q, digits)), parse(fmt_down(q, digits))
    assert down <= q <= up
    assert up - down <= abs(q) * F(10) ** (1 - digits) * 10


@given(finite)
def test_exact_roundtrip(q: fmpq):
    assert parse(fmt_exact(q)) == q


def test_fmt_exact_huge_denominators():
    # no float conversion of the denominator anywhere (2^1100 overflows a float)
    for q in (F(1, 2**1100), F(7, 5**500), F(1, 3 * 10**400)):
        s = fmt_exact(q)
        assert parse(s) == q and "/" in s
    assert fmt_exact(F(3, 10**400)) == "3e-400"  # a decimal at any exponent
    assert fmt_exact(F(1, 10**300000)) == "1e-300000"
    assert fmt_exact(F(1, 11)) == "1/11" and fmt_exact(F(1, 22)) == "1/22"


def test_fmt_exact_length_limits():
    """A decimal is used when it fits 32 characters, whatever its exponent, else p/q."""
    assert fmt_exact(F(1, 10**39)) == "1e-39"
    assert fmt_exact(F(1, 10**40)) == "1e-40"  # p/q until session 30
    assert fmt_exact(F(1, 2**30)) == "9.31322574615478515625e-10"  # 26 characters
    assert fmt_exact(F(1, 2**45)) == "1/" + str(2**45)  # 2.84…e-14 has 38
    s32 = fmt_exact(F(1234567890123456789012345678901, 10**20))
    assert s32 == "12345678901.23456789012345678901" and len(s32) == 32
    q33 = F(12345678901234567890123456789012, 10**21)
    s33 = fmt_exact(q33)
    assert s33 == str(q33) and "/" in s33 and parse(s33) == q33


def test_fmt_value_up_never_puts_a_rounded_number_behind_equals() -> None:
    """Short exact values alone; long ones as "p/q ≤ bound" with the bound ≥ the value
    (constrained printed "μ = 24485.1886" for 200582665/8192, session 29)."""
    assert fmt_value_up(fmpq(512451229, 2)) == "256225614.5"
    mu = fmpq(200582665, 8192)
    text = fmt_value_up(mu, 10)
    assert text == "200582665/8192 ≤ 24485.1886"
    assert Fraction(text.split(" ≤ ")[1]) >= Fraction(200582665, 8192)


@given(st.fractions(min_value=-(10**6), max_value=10**6))
def test_fmt_value_up_is_exact_or_a_safe_bound(x: Fraction) -> None:
    """Either the exact value, or its p/q followed by an upper bound."""
    text = fmt_value_up(fmpq(x.numerator, x.denominator))
    if " ≤ " in text:
        exact, bound = text.split(" ≤ ")
        assert Fraction(exact) == x and Fraction(bound) >= x
    else:
        assert Fraction(text) == x


# --- Mutation review 29: fmt_value_up


def test_fmt_value_up_boundaries_and_default_digits() -> None:
    """An exact text of exactly ``longest`` (16) characters is shown alone, 17 get the bound;
    the bound has 6 significant digits by default (mutation review 29: ``<`` for ``<=`` and
    ``digits = 5`` passed every test)."""
    assert fmt_value_up(fmpq(123456789012345, 10**8)) == "1234567.89012345"  # 16 characters
    seventeen = fmpq(1234567890123451, 10**9)  # 1234567.890123451: 17 characters
    assert fmt_value_up(seventeen) == "1234567890123451/1000000000 ≤ 1234570"
    assert fmt_value_up(fmpq(200582665, 8192)) == "200582665/8192 ≤ 24485.2"


@given(st.fractions(min_value=-(10**6), max_value=10**6))
def test_fmt_value_down_is_exact_or_a_safe_bound(x: Fraction) -> None:
    """Either the exact value, or its p/q followed by a lower bound (constrained's
    "γ = 0.000012345678" for γ = 24691357802469/2·10¹⁸: re-check trial, session 29)."""
    from obsdesign.certify.printing import fmt_value_down

    text = fmt_value_down(fmpq(x.numerator, x.denominator))
    if " ≥ " in text:
        exact, bound = text.split(" ≥ ")
        assert Fraction(exact) == x and Fraction(bound) <= x
    else:
        assert Fraction(text) == x


def test_fmt_value_down_of_a_long_gamma() -> None:
    from obsdesign.certify.printing import fmt_value_down

    g = fmpq(24691357802469, 2 * 10**18)
    assert fmt_value_down(g, 8) == "24691357802469/2000000000000000000 ≥ 0.000012345678"
    assert fmt_value_down(fmpq(23965, 10**9), 8) == "0.000023965"


# -- mutation review 30 (docs/mutation.md)


# --- Mutation review 30: printing.fmt_exact / _show (ready to append to
# tests/test_certify_printing.py)


def test_fmt_exact_decimal_up_to_the_longest_skew_that_fits() -> None:
    """Mutation review 30 (printing._MAX_SKEW = 110 → 80): 1/5⁸⁹ = 2⁸⁹·10⁻⁸⁹ has a 27-digit
    mantissa and fits 32 characters exactly; 1/5⁹⁰ does not. The skew cap must not cut the
    decimals that fit."""
    s = fmt_exact(F(1, 5**89))
    assert s == "6.18970019642690137449562112e-63" and len(s) == 32 and parse(s) == F(1, 5**89)
    assert fmt_exact(F(1, 5**90)) == "1/" + str(5**90)
    assert fmt_exact(F(1, 2**38)) == "3.63797880709171295166015625e-12"  # 32 characters


def test_fmt_exact_of_an_integer_beyond_pythons_int_string_limit() -> None:
    """Mutation review 30 (printing._show: ``m = fmpz(m)`` → ``int(m)``): Python refuses to
    write an int of more than 4300 digits (ValueError); fmt_exact of a 4772-digit integer is
    its exact digits (p/q with q = 1), not a crash."""
    from flint import fmpz

    big = fmpz(3) ** 10000
    s = fmt_exact(F(big))
    assert s == str(big) and len(s) == 4772
    assert fmt_exact(F(big, 2**40)) == str(big) + "/" + str(2**40)
