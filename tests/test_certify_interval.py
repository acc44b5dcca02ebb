"""Outward-rounded bounds (obsdesign.certify.interval), checked in EXACT arithmetic.

Every direction test compares with an independent oracle built from exact rationals only
(Taylor series of exp with a rigorous remainder, squared back with outward rounding), never with
floats: a bound that is wrong by 1e-34 (a swapped ``log_upper`` / ``log_lower``) is caught.
"""

from __future__ import annotations

import math

import pytest
from flint import fmpq
from hypothesis import given
from hypothesis import strategies as st
from mpmath import iv

from obsdesign.certify import interval
from obsdesign.certify import interval as I
from obsdesign.certify.interval import (
    PREC,
    bounds,
    ceil_int,
    exp_lower,
    exp_upper,
    log_lower,
    log_upper,
    lower,
    q_to_iv,
    raw_to_q,
    round_down,
    round_up,
    sqrt_lower,
    sqrt_upper,
    upper,
)

F = fmpq
BITS = 600  # the oracle rounds outward to BITS significant bits


def _scale(q: fmpq) -> fmpq:
    e = int(q.p).bit_length() - int(q.q).bit_length()
    return F(2) ** (BITS - e)


def _floor(q: fmpq) -> fmpq:
    s = _scale(q)
    return F(int((q * s).floor())) / s


def _ceil(q: fmpq) -> fmpq:
    s = _scale(q)
    return F(int((q * s).ceil())) / s


def exp_enclosure(r: fmpq) -> tuple[fmpq, fmpq]:
    """Exact rationals lo ≤ e^r ≤ hi (relative width < 2^-500 for |r| ≤ 40), no floats.

    e^s for |s| ≤ 1/2 by its Taylor polynomial of degree 90 with the remainder bound
    |R| ≤ 2 |s|^91 / 91!, then e^r = (e^s)^(2^m) squared with outward rounding.
    """
    m = 0
    while abs(r) / 2**m > F(1, 2):
        m += 1
    s = r / 2**m
    term, total = F(1), F(1)
    for k in range(1, 91):
        term = term * s / k
        total += term
    rem = 2 * abs(s) ** 91 / math.factorial(91)
    lo, hi = _floor(total - rem), _ceil(total + rem)
    assert lo > 0
    for _ in range(m):
        lo, hi = _floor(lo * lo), _ceil(hi * hi)
    return lo, hi


def test_oracle_is_sound_on_known_values():
    lo, hi = exp_enclosure(F(0))
    assert lo <= 1 <= hi
    lo, hi = exp_enclosure(F(1))  # e = 2.718281828459045235360287471352662497757…
    e39 = F(2718281828459045235360287471352662497757, 10**39)  # e truncated to 39 decimals
    assert e39 < lo and hi < e39 + F(1, 10**39)
    assert hi - lo < F(1, 2**500)


rationals = st.builds(F, st.integers(1, 10**9), st.integers(1, 10**6))


@given(rationals)
def test_log_bounds_direction_exact(x: fmpq):
    lo, hi = log_lower(x), log_upper(x)
    # lo ≤ ln x  ⟸  e^lo ≤ x ;  ln x ≤ hi  ⟸  x ≤ e^hi   (exact comparisons)
    assert exp_enclosure(lo)[1] <= x, "log_lower is above ln x"
    assert x <= exp_enclosure(hi)[0], "log_upper is below ln x"
    assert hi - lo <= F(1, 2**100) * (1 + abs(hi))
    if x != 1:  # ln x is irrational: both bounds are strict
        assert lo < hi


@given(st.builds(F, st.integers(-40 * 10**6, 40 * 10**6), st.just(10**6)))
def test_exp_bounds_direction_exact(r: fmpq):
    lo, hi = exp_lower(r), exp_upper(r)
    olo, ohi = exp_enclosure(r)
    assert lo <= olo and ohi <= hi
    assert lo > 0 and hi - lo <= F(1, 2**100) * hi


def test_log_and_exp_known_points():
    assert log_lower(1) <= 0 <= log_upper(1)
    for x in (F(3), F(1, 3), F(10**30), F(1, 10**30), F(2**200 + 1, 2**200)):
        lo, hi = log_lower(x), log_upper(x)
        assert exp_enclosure(lo)[1] < x < exp_enclosure(hi)[0]
    for r in (F(-30), F(1, 7), F(25)):
        assert exp_lower(r) < exp_enclosure(r)[0] and exp_enclosure(r)[1] < exp_upper(r)
    assert exp_lower(0) <= 1 <= exp_upper(0)


@given(st.integers(1, 10**9), st.integers(1, 10**6))
def test_sqrt_bounds_bracket(p: int, q: int):
    x = fmpq(p, q)
    lo, hi = sqrt_lower(x), sqrt_upper(x)
    assert lo * lo <= x <= hi * hi  # exact check of the enclosure
    assert hi - lo < fmpq(1, 10**20) * (1 + hi)


def test_sqrt_strict_on_non_squares():
    for x in (F(2), F(1, 3), F(10**40 + 1), F(7, 10**40)):
        lo, hi = sqrt_lower(x), sqrt_upper(x)
        assert lo * lo < x < hi * hi
    assert sqrt_lower(F(9, 4)) <= F(3, 2) <= sqrt_upper(F(9, 4))


@pytest.mark.parametrize("x", [F(9, 25), F(0), F(10**40), F(1, 10**40), F(144, 169)], ids=str)
def test_sqrt_of_a_rational_square_is_exact(x: fmpq):
    """√(9/25) = 3/5 exactly on both sides (the outward end lay strictly above: C_min equal
    to X̂ failed its inclusion, random-spec fuzzer); a square times (1 + 10⁻³⁰) is not a
    square and gets strict bounds."""
    q = x
    r = interval.exact_sqrt(q)
    assert r is not None and r * r == q
    assert sqrt_lower(q) == r == sqrt_upper(q)
    if q:
        off = q * (1 + F(1, 10**30))
        assert interval.exact_sqrt(off) is None
        assert sqrt_lower(off) ** 2 < off < sqrt_upper(off) ** 2
    assert interval.exact_sqrt(-q - 1) is None


def test_precision_is_113_bits_and_restored():
    assert PREC == 113
    lo, hi = sqrt_lower(2), sqrt_upper(2)
    assert hi - lo == F(1, 2**112)  # one ulp of a 113-bit float in [1, 2)
    for v in (lo, hi):
        assert 2**112 % int(v.q) == 0 and int(v.p).bit_length() <= 113
    saved = iv.prec
    iv.prec = 30
    try:
        log_upper(5)
        assert iv.prec == 30  # restored after the call
        with interval._prec():
            assert iv.prec == PREC
        assert iv.prec == 30
    finally:
        iv.prec = saved


def test_q_to_iv_encloses_the_rational():
    for x in (F(1, 3), F(-(10**50) - 1, 3), F(2**300 + 1, 2**301), F(0), F(7)):
        lo, hi = q_to_iv(x)._mpi_
        assert raw_to_q(lo) <= x <= raw_to_q(hi)
    lo, hi = q_to_iv(F(7))._mpi_
    assert raw_to_q(lo) == raw_to_q(hi) == 7
    assert q_to_iv("1/4")._mpi_[0] == q_to_iv(0.25)._mpi_[1]


def test_raw_to_q_values():
    from mpmath.libmp import finf, fnan, fninf, from_int, from_rational

    assert raw_to_q(from_int(12)) == 12
    assert raw_to_q(from_int(-12)) == -12
    assert raw_to_q(from_int(3 * 2**70)) == 3 * 2**70
    assert raw_to_q(from_rational(3, 8, 53)) == F(3, 8)
    assert raw_to_q(from_rational(-5, 64, 53)) == F(-5, 64)
    for bad in (finf, fninf, fnan):
        with pytest.raises(
            ArithmeticError, match=r"^interval evaluation did not give a finite enclosure$"
        ):
            raw_to_q(bad)


def test_generic_bounds():
    assert bounds(lambda a: 2, 3) == (2, 2)  # a constant becomes an interval
    assert lower(lambda a: -a, 3) == -3 and upper(lambda a: -a, 3) == -3
    lo, hi = bounds(lambda a, b: a / b, 1, 3)
    assert lo < F(1, 3) < hi
    with pytest.raises(ArithmeticError):
        log_upper(0)
    with pytest.raises(ArithmeticError):
        lower(iv.log, 0)
    # a composite expression, checked exactly: e^(1/7) * 25 via the oracle
    lo, hi = bounds(lambda a, b: iv.exp(a) * b, F(1, 7), F(25))
    olo, ohi = exp_enclosure(F(1, 7))
    assert lo <= 25 * olo and 25 * ohi <= hi


def test_rounding_directions():
    assert round_up(fmpq(1, 3), 2) == fmpq(34, 100)
    assert round_down(fmpq(1, 3), 2) == fmpq(33, 100)
    assert round_up(fmpq(-1, 3), 2) == fmpq(-33, 100)
    assert round_down(fmpq(-1, 3), 2) == fmpq(-34, 100)
    assert round_up(fmpq(1, 2), 1) == fmpq(1, 2)
    assert round_down(fmpq(1, 2), 1) == fmpq(1, 2)
    assert round_up(fmpq(12345, 1), -2) == 12400 and round_down(fmpq(12345), -2) == 12300
    assert round_up(0.1, 0) == 1 and round_down(0.1, 0) == 0
    assert ceil_int(fmpq(7, 2)) == 4 and ceil_int(fmpq(4)) == 4 and ceil_int(-0.5) == 0
    assert isinstance(ceil_int(F(1, 2)), int)


@given(st.builds(F, st.integers(-(10**12), 10**12), st.integers(1, 10**6)), st.integers(0, 8))
def test_rounding_property(x: fmpq, d: int):
    up, down = round_up(x, d), round_down(x, d)
    step = F(1, 10**d)
    assert down <= x <= up and up - down <= step and (up * 10**d).q == 1
    assert (down * 10**d).q == 1


def test_raw_to_q_refuses_an_exponent_beyond_exact_arithmetic() -> None:
    """An interval end 2^(2^26 + 1) is a MagnitudeError (exit 4, and an ArithmeticError for
    the enclosures that treat it as "bounds nothing"); python-flint died with SIGFPE on such
    powers (review 19). 2^(2^26) itself converts."""
    import mpmath

    from obsdesign.certify.interval import MAX_EXPONENT, MagnitudeError, raw_to_q
    from obsdesign.errors import EXIT_INCONCLUSIVE

    big = mpmath.ldexp(mpmath.mpf(1), MAX_EXPONENT + 1)
    with pytest.raises(MagnitudeError) as ei:
        raw_to_q(big._mpf_)
    assert isinstance(ei.value, ArithmeticError) and ei.value.exit_code == EXIT_INCONCLUSIVE
    with pytest.raises(MagnitudeError):
        raw_to_q(mpmath.ldexp(mpmath.mpf(1), -MAX_EXPONENT - 2)._mpf_)
    ok = raw_to_q(mpmath.ldexp(mpmath.mpf(1), MAX_EXPONENT - 1)._mpf_)
    assert ok.p.bit_length() == MAX_EXPONENT


# --- Mutation review 29: log_compare


def test_log_compare_below_one() -> None:
    """ln r < 0 for r < 1: x = −1/2 lies above ln(1/2) ≈ −0.693 and −1 below it, decided by
    the enclosures (mutation review 29: ``q <= 1`` answered the sign of x against 0 for every
    r ≤ 1 and no test had an r below 1)."""
    from obsdesign.certify.interval import log_compare

    assert log_compare(fmpq(-1, 2), fmpq(1, 2))[0] == 1
    assert log_compare(fmpq(-1), fmpq(1, 2))[0] == -1
    assert log_compare(fmpq(1, 10), fmpq(1, 2))[0] == 1
    # and r = 1 exactly: x > 0 is above ln 1 = 0
    assert log_compare(fmpq(1, 10**40), fmpq(1))[0] == 1


def test_log_compare_doubles_and_stops_at_max_bits(monkeypatch: pytest.MonkeyPatch) -> None:
    """The working precision doubles from ``bits`` and never exceeds ``max_bits`` (mutation
    review 29: one step past the cap, or +1 bit at a time, passed every test). x is 1e-300
    above ln 1.5 (≈ 2^-997), so 950 bits cannot decide it."""
    import mpmath as mp

    from obsdesign.certify import interval as ivq

    with mp.workdps(400):
        s = mp.nstr(mp.log(mp.mpf(3) / 2) + mp.mpf(10) ** -300, 390)
    from obsdesign.certify.exact import Q

    near = Q(s)
    seen: list[int] = []
    real = ivq.log_bounds

    def spy(x, bits=ivq.PREC):
        seen.append(bits)
        return real(x, bits)

    monkeypatch.setattr(ivq, "log_bounds", spy)
    d, lo, hi = ivq.log_compare(near, fmpq(3, 2), ivq.PREC, 950)
    assert d is None and lo <= near <= hi
    assert seen == [113, 226, 452, 904, 950]
    seen.clear()
    assert ivq.log_compare(near, fmpq(3, 2), 113, 4000)[0] == 1
    assert seen == [113, 226, 452, 904, 1808]


# -- mutation review 32 (session 31's checks) ----------------------------------------
def _width(x) -> fmpq:  # noqa: ANN001
    lo, hi = x._mpi_
    return raw_to_q(hi) - raw_to_q(lo)


def test_q_to_iv_has_end_points_of_the_bits_asked() -> None:
    third = F(1, 3)
    assert 0 < _width(q_to_iv(third)) <= fmpq(1, 2 ** (PREC - 1))  # default PREC bits
    assert _width(q_to_iv(third)) > fmpq(1, 2 ** (PREC + 2))
    assert 0 < _width(q_to_iv(third, 1024)) <= fmpq(1, 2**1020)


def test_bounds_at_more_bits_is_narrower_than_at_prec() -> None:
    """The identity and exp of 1/3 (not a binary fraction) at 1024 bits: ≈ 2^-1024 wide."""
    for f in (lambda x: x, iv.exp):
        lo, hi = I.bounds(f, fmpq(1, 3), bits=1024)
        assert lo <= hi and hi - lo < fmpq(1, 2**1000)
        lo, hi = I.bounds(f, fmpq(1, 3))
        assert hi - lo > fmpq(1, 2**120)


@pytest.mark.parametrize("bits", [60, 113, 247])
def test_rexp_and_rlog_enclose_where_mpmath_intervals_miss(bits: int) -> None:
    """mpmath's iv.exp / iv.log round a slightly low approximation, so their "upper" end can
    lie below the true value: iv.exp at 60 bits gave [1 + 2⁻⁴⁰] for e^(2⁻⁴⁰) (true
    1 + 2⁻⁴⁰ + 2⁻⁸¹ + …), iv.log missed ln(1 + 2⁻¹³²) at 247 bits (search-space soundness
    trial, session 38: four false certificates). rexp / rlog (python-flint arb) enclose every
    x = ±2⁻ᵏ, 1 + 2⁻ᵏ, checked against mpmath at 600 bits (errors ~2⁻⁶⁰⁰, far below the
    ends' distance to the truth)."""
    import mpmath
    from mpmath import iv
    from mpmath.libmp import from_man_exp

    from obsdesign.certify import interval as ivq

    with mpmath.workprec(600):
        for k in range(1, bits + 20, 3):
            for raw, f, ref in (
                (from_man_exp(1, -k), ivq.rexp, mpmath.exp),
                (from_man_exp(-1, -k), ivq.rexp, mpmath.exp),
                (from_man_exp((1 << k) + 1, -k), ivq.rlog, mpmath.log),
            ):
                with ivq._prec(bits):
                    lo, hi = f(iv.make_mpf((raw, raw)))._mpi_
                truth = ref(mpmath.mpf(raw))
                assert mpmath.mpf(lo) <= truth <= mpmath.mpf(hi), (k, f.__name__)
    with ivq._prec(60):
        lo, hi = ivq.rexp(iv.make_mpf((from_man_exp(1, -40),) * 2))._mpi_
    assert hi != from_man_exp((1 << 40) + 1, -40)  # not the end iv.exp gave
    with pytest.raises(ArithmeticError):
        ivq.rlog(iv.mpf([0, 1]))
    # ln 2 = 0.69314718055994530941…
    assert ivq.log_lower(2) < fmpq(6931471805599453095, 10**19)
    assert ivq.log_upper(2) > fmpq(6931471805599453094, 10**19)
    assert ivq.exp_upper(fmpq(1, 2**40)) > 1 + fmpq(1, 2**40) + fmpq(1, 2**81)


def test_rexp_lower_end_is_below_one_for_a_tiny_negative_argument() -> None:
    """e^(−2⁻²⁰⁰) < 1: the lower end of the ball, not its midpoint (which rounds to 1 at
    113 bits); a mutation reading the midpoint survived every test (mutation review,
    session 39). Likewise e^(2⁻²⁰⁰) > 1 at the upper end."""
    assert exp_lower(-fmpq(1, 2**200)) < 1
    assert exp_upper(fmpq(1, 2**200)) > 1
