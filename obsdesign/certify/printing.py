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
    m = fmpz(m)
    if m == 0:
        return "0"
    sign = "-" if m < 0 else ""
    digits = str(abs(m))  # flint's decimal string: no Python int-string limit (4300 digits)
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


#: log₂ 5, for the exponent of a power of 5 from its bit length (:func:`fmt_exact`)
_LOG2_5 = math.log2(5)
#: beyond this |a − b| a value p/(2^a 5^b) has more than 33 significant decimal digits (its
#: mantissa p·2^(b−a) or p·5^(a−b) has no trailing zero), too many for :func:`fmt_exact`
_MAX_SKEW = 110


def fmt_exact(x: Any) -> str:
    """``x`` exactly: a decimal m·10^e (shown in at most 32 characters, scientific beyond
    10¹² or below 10⁻⁶) when it has one, else p/q. Any exponent: a spec's ``1e-300`` was
    shown as 1/1000…0 (301 digits), since only 10^e with e < 40 was tried (session 30)."""
    q = Q(x)
    den = int(q.q)
    twos = (den & -den).bit_length() - 1
    rest = den >> twos
    fives: int | None = 0
    if rest != 1:  # a power of 5? (no loop of divisions: 5^b from the bit length)
        b = round((rest.bit_length() - 1) / _LOG2_5)
        fives = next((k for k in (b - 1, b, b + 1) if k > 0 and 5**k == rest), None)
    if fives is not None and abs(twos - fives) <= _MAX_SKEW:
        e = max(twos, fives)
        s = _show(q.p * fmpz(2) ** (e - twos) * fmpz(5) ** (e - fives), -e)
        if len(s) <= 32:
            return s
    return str(q)
