"""Numbers printed inside claim statements: exact, or rounded in the direction that keeps the
statement true.

A statement "x ≤ U" may print U rounded *up*, "x ≥ L" may print L rounded *down*; a value
that the statement asserts equality of is printed exactly (as a fraction) — see the soundness
rule of the method contract. Every function returns a decimal string whose exact value is
on the safe side of ``q`` (tested by parsing the string back and comparing exactly).
"""

from __future__ import annotations

import math
from typing import Any

from flint import fmpq, fmpz

from obsdesign.certify.exact import Q


def _scaled(q: fmpq, digits: int) -> tuple[int, fmpq]:
    """Exponent e with 10^(digits-1) ≤ |q|/10^e < 10^digits (q ≠ 0) and the scaled value."""
    a = abs(q)
    # log10 a from the bit lengths (within 1), then at most a few corrections: stepping e one
    # by one from 0 took ~400 big-rational steps per number near 1e-400 (a search-space
    # schedule of 1,300 such entries ran for minutes: CLI fuzzer)
    bits = int(a.p).bit_length() - int(a.q).bit_length()
    e = math.floor(bits * 0.30102999566398120) - digits

    def scaled(e: int) -> fmpq:
        return a / fmpq(10) ** e if e >= 0 else a * fmpq(10) ** (-e)

    while scaled(e) >= 10**digits:
        e += 1
    while scaled(e) < 10 ** (digits - 1):
        e -= 1
    s = q / fmpq(10) ** e if e >= 0 else q * fmpq(10) ** (-e)
    return e, s


def _show(m: fmpz | int, e: int) -> str:
    m = int(m)
    if m == 0:
        return "0"
    sign = "-" if m < 0 else ""
    digits = str(abs(m))
    exp10 = e + len(digits) - 1
    if exp10 > 12 or exp10 < -6:
        body = digits.rstrip("0")
        mant = body[0] + ("." + body[1:] if len(body) > 1 else "")
        return f"{sign}{mant}e{exp10}"
    if e >= 0:
        return sign + digits + "0" * e
    k = -e
    if len(digits) <= k:
        digits = "0" * (k - len(digits) + 1) + digits
    whole, frac = digits[:-k], digits[-k:].rstrip("0")
    return sign + whole + ("." + frac if frac else "")


def _fmt(x: Any, digits: int, up: bool) -> str:
    q = Q(x)
    if q == 0:
        return "0"
    e, s = _scaled(q, digits)
    return _show(s.ceil() if up else s.floor(), e)


def fmt_up(x: Any, digits: int = 6) -> str:
    """``x`` rounded up (towards +∞) to ``digits`` significant digits, as a decimal string."""
    return _fmt(x, digits, True)


def fmt_down(x: Any, digits: int = 6) -> str:
    """``x`` rounded down (towards −∞) to ``digits`` significant digits, as a decimal string."""
    return _fmt(x, digits, False)


def fmt_value_up(x: Any, digits: int = 6, longest: int = 16) -> str:
    """What follows "= " for an upper-bound quantity such as an ISS gain μ: ``x`` exactly when
    that takes at most ``longest`` characters, else "p/q ≤ d" with d rounded up to ``digits``
    significant digits — never a rounded number behind "=" (constrained's "μ = 24485.1886"
    for μ = 200582665/8192, rendering soundness trial, session 29).

    :param x: the exact value; :param digits: significant digits of the bound;
    :param longest: the longest exact text shown alone."""
    m = fmt_exact(x)
    return m if len(m) <= longest else f"{Q(x)} ≤ {fmt_up(x, digits)}"


def fmt_value_down(x: Any, digits: int = 6, longest: int = 16) -> str:
    """:func:`fmt_value_up` for a quantity whose statement stays true when it is smaller
    (constrained's γ in γδ² ≤ λ_min(P)): the exact value when short, else "p/q ≥ d" with d
    rounded down ("γ = 0.000012345678" for γ = 24691357802469/2·10¹⁸ put a rounded number
    behind "=": re-check trial, session 29).

    :param x: the exact value; :param digits: significant digits of the bound;
    :param longest: the longest exact text shown alone."""
    m = fmt_exact(x)
    return m if len(m) <= longest else f"{Q(x)} ≥ {fmt_down(x, digits)}"


def fmt_exact(x: Any) -> str:
    """``x`` exactly: a finite decimal when it has one with at most 30 digits, else p/q."""
    q = Q(x)
    den = int(q.q)
    k = 0
    while den % 10 == 0 or den % 2 == 0 or den % 5 == 0:
        if den % 10 == 0:
            den //= 10
        elif den % 2 == 0:
            den //= 2
        else:
            den //= 5
        k += 1
    if den == 1:
        for e in range(0, 40):
            m = q * fmpq(10) ** e
            if m.q == 1:
                s = _show(m.p, -e)
                if len(s) <= 32:
                    return s
                break
    return str(q)
