"""Outward-rounded bounds for quantities that are not rational (sqrt, log, exp, ...).

mpmath's interval type ``iv.mpf`` rounds the arithmetic operations and √ outward (exact
directed rounding), so the true value of an expression built from them lies in the returned
interval. Its transcendental functions do NOT: ``iv.exp`` at 60 bits gave [1 + 2⁻⁴⁰] for
e^(2⁻⁴⁰), whose true value is 1 + 2⁻⁴⁰ + 2⁻⁸¹ + …, and ``iv.log`` misses likewise at many
precisions (search-space soundness trial, session 38: four false certificates). ``rexp`` and
``rlog`` below take exp and log from python-flint's ``arb`` balls (rigorous) and return
mpmath intervals; every enclosure here uses them. We convert interval ends to exact rationals,
so a bound reported as "T_max ≥ 1.0899" is a proof. Directions are explicit in every name:
``*_upper`` returns a rational ≥ the true value, ``*_lower`` one ≤ it.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

from flint import fmpq
from mpmath import iv
from mpmath.libmp import finf, fnan, fninf, from_man_exp, mpf_pos

from obsdesign.certify.exact import Q
from obsdesign.errors import InconclusiveError

PREC = 113  # bits of the interval endpoints (quad precision); widths far below 1e-30


class _prec:
    """Context manager: run mpmath's interval context at ``bits`` (default PREC), then
    restore."""

    def __init__(self, bits: int = PREC) -> None:
        self.bits = bits

    def __enter__(self) -> None:
        self.saved = iv.prec
        iv.prec = self.bits

    def __exit__(self, *exc: object) -> None:
        iv.prec = self.saved


def q_to_iv(x: Any, bits: int = PREC) -> Any:
    """Exact rational → the tightest interval (of ``bits``-bit end points) that contains
    it."""
    q = Q(x)
    with _prec(bits):
        return iv.mpf(int(q.p)) / iv.mpf(int(q.q))


#: largest |binary exponent| of an interval end turned into an exact rational (2^(2^26) is an
#: 8 MB integer, formed in milliseconds); beyond it python-flint refused the power
#: ("exponent too large") or died with SIGFPE (e^(L_f Δτ) for K = 10¹⁵, review 19)
MAX_EXPONENT = 2**26


class MagnitudeError(InconclusiveError, ArithmeticError):
    """An interval end beyond :data:`MAX_EXPONENT`: exit 4 (numerically inconclusive) where
    it surfaces; an ArithmeticError for the enclosures that treat a failed evaluation as
    "bounds nothing"."""


def raw_to_q(x: tuple) -> fmpq:
    """Exact rational value of a finite raw mpmath float (sign, man, exp, bc).
    :class:`MagnitudeError` when its binary exponent exceeds :data:`MAX_EXPONENT`."""
    if x in (finf, fninf, fnan):
        raise ArithmeticError("interval evaluation did not give a finite enclosure")
    sign, man, exp, bc = x
    if abs(int(exp)) > MAX_EXPONENT or abs(int(exp) + int(bc)) > MAX_EXPONENT:
        raise MagnitudeError(
            f"an interval bound of magnitude 2^{int(exp) + int(bc)} is beyond exact arithmetic "
            "(the spec's numbers are too large or too small)"
        )
    v = fmpq(int(man)) * fmpq(2) ** int(exp)
    return -v if sign else v


def _raw_arb(x: tuple) -> Any:
    """The finite raw mpmath float x as an exact python-flint ``arb`` (radius 0)."""
    from flint import arb, arf, fmpz

    if x in (finf, fninf, fnan):
        raise ArithmeticError("interval evaluation did not give a finite enclosure")
    sign, man, exp, _ = x
    a = arb(arf((fmpz(-man if sign else man), fmpz(exp))))
    return a


def _arb_raw(a: Any, rnd: str) -> tuple:
    """The exact ``arb`` point a (a ball's end) as a raw mpmath float rounded to ``iv.prec``
    bits in direction ``rnd`` ('f' down, 'c' up)."""
    if not a.is_finite():
        raise ArithmeticError("interval evaluation did not give a finite enclosure")
    man, exp = a.man_exp()
    return mpf_pos(from_man_exp(int(man), int(exp)), iv.prec, rnd)


def _monotone_arb(name: str, x: Any) -> Any:
    """The mpmath interval enclosing f(x) for an increasing function f (``arb`` method
    ``name``), x an mpmath interval or number: [f(lo)↓, f(hi)↑] from rigorous balls at
    ``iv.prec`` + 32 bits, ends rounded outward to ``iv.prec``."""
    from flint import ctx

    lo, hi = iv.mpf(x)._mpi_
    with ctx.workprec(iv.prec + 32):
        a = getattr(_raw_arb(lo), name)()
        b = getattr(_raw_arb(hi), name)()
        return iv.make_mpf((_arb_raw(a.lower(), "f"), _arb_raw(b.upper(), "c")))


def rexp(x: Any) -> Any:
    """e^x of an mpmath interval, rigorously (``arb``; ``iv.exp`` is not: module docstring)."""
    return _monotone_arb("exp", x)


def rlog(x: Any) -> Any:
    """ln x of an mpmath interval x > 0, rigorously (``arb``; ``iv.log`` is not: module
    docstring). ArithmeticError when x reaches 0 or below."""
    lo, _ = iv.mpf(x)._mpi_
    if lo in (finf, fninf, fnan) or lo[0] or lo[1] == 0:
        raise ArithmeticError("log of an interval reaching 0 or below")
    return _monotone_arb("log", x)


def bounds(f: Callable[..., Any], *args: Any, bits: int = PREC) -> tuple[fmpq, fmpq]:
    """Rational (lower, upper) enclosing f(*args), f built from mpmath ``iv`` operations at
    ``bits`` bits (default :data:`PREC`).

    ``args`` are exact rationals (or anything :func:`Q` takes); ``f`` receives intervals.
    """
    with _prec(bits):
        # a constant result becomes an interval
        r = iv.mpf(f(*[q_to_iv(a, bits) for a in args]))
        lo, hi = r._mpi_
    return raw_to_q(lo), raw_to_q(hi)


def upper(f: Callable[..., Any], *args: Any) -> fmpq:
    """A rational ≥ f(*args) (outward rounding)."""
    return bounds(f, *args)[1]


def lower(f: Callable[..., Any], *args: Any) -> fmpq:
    """A rational ≤ f(*args) (outward rounding)."""
    return bounds(f, *args)[0]


# One-sided bounds of √x, ln x (x > 0) and eˣ: ``f_upper(x)`` ≥ f(x) ≥ ``f_lower(x)``.
def exact_sqrt(x: Any) -> fmpq | None:
    """√x when it is rational (x ≥ 0 a square of a rational), else None."""
    from math import isqrt

    q = Q(x)
    if q < 0:
        return None
    n, d = int(q.p), int(q.q)
    rn, rd = isqrt(n), isqrt(d)
    return fmpq(rn, rd) if rn * rn == n and rd * rd == d else None


def sqrt_upper(x: Any) -> fmpq:
    """An upper bound of √x: √x itself when rational (an outward interval end lies strictly
    above it, so X̂ = C_min exactly failed the inclusion: random-spec fuzzer), else the
    outward-rounded interval end."""
    r = exact_sqrt(x)
    return r if r is not None else upper(iv.sqrt, x)


def sqrt_lower(x: Any) -> fmpq:
    """A lower bound of √x: √x itself when rational, else the outward interval end."""
    r = exact_sqrt(x)
    return r if r is not None else lower(iv.sqrt, x)


log_upper: Callable[[Any], fmpq] = partial(upper, rlog)
log_lower: Callable[[Any], fmpq] = partial(lower, rlog)


def log_bounds(x: Any, bits: int = PREC) -> tuple[fmpq, fmpq]:
    """Rational (lower, upper) enclosing ln x (x > 0 exact) at ``bits`` ≥ PREC bits of
    working precision: more where a decision needs it (the K of Theorem 1, search-space
    paper, compares K·ΔT·L_f with ln(κ/L_h) when K ≈ 10³⁰⁰)."""
    q = Q(x)
    with _prec(max(PREC, bits)):
        r = rlog(iv.mpf(int(q.p)) / iv.mpf(int(q.q)))
        lo, hi = r._mpi_
    return raw_to_q(lo), raw_to_q(hi)


def log_compare(
    x: Any, r: Any, bits: int = PREC, max_bits: int = 65536
) -> tuple[int | None, fmpq, fmpq]:
    """x against ln r (x exact, r > 0 exact), decided by enclosures of ln r at ``bits``,
    doubled up to ``max_bits``: (−1 when x < ln r, +1 when x > ln r, 0 when x = ln r, None
    when still undecided at ``max_bits``) and the enclosure (lower, upper) that decided (the
    last one tried when undecided). For rational r ≠ 1, ln r is irrational
    (Lindemann–Weierstrass), so equality happens only at r = 1, x = 0, decided exactly; any
    other tie is decided once the enclosure is narrower than |x − ln r|. The K of Theorem 1
    and Lemma 2 (search-space paper) at a near tie: a fixed 121 bits called a Lemma 2 that
    holds failed by "at least −4.4e-35" (search-space trial, session 29).

    :param x: the exact number compared; :param r: the argument of ln; :param bits: the
    first working precision; :param max_bits: the most tried."""
    q, xq = Q(r), Q(x)
    if q == 1:
        return (0 if xq == 0 else (1 if xq > 0 else -1)), fmpq(0), fmpq(0)
    b = max(PREC, bits)
    while True:
        lo, hi = log_bounds(q, b)
        if xq < lo:
            return -1, lo, hi
        if xq > hi:
            return 1, lo, hi
        if b >= max_bits:
            return None, lo, hi
        b = min(2 * b, max_bits)


exp_upper: Callable[[Any], fmpq] = partial(upper, rexp)
exp_lower: Callable[[Any], fmpq] = partial(lower, rexp)


def round_up(x: Any, digits: int) -> fmpq:
    """Smallest multiple of 10^-digits that is ≥ x (exact)."""
    q = Q(x) * fmpq(10) ** digits
    return fmpq(int(q.ceil())) / fmpq(10) ** digits


def round_down(x: Any, digits: int) -> fmpq:
    """Largest multiple of 10^-digits that is ≤ x (exact)."""
    q = Q(x) * fmpq(10) ** digits
    return fmpq(int(q.floor())) / fmpq(10) ** digits


def ceil_int(x: Any) -> int:
    """⌈x⌉ of an exact rational."""
    return int(Q(x).ceil())
