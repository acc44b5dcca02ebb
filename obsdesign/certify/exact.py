"""Rational numbers and matrices for exact checks.

The exact scalar type is ``flint.fmpq``; an exact matrix is a 2-D numpy array of dtype
``object`` holding ``fmpq`` entries, so that formulas such as ``A - L @ C`` can be rebuilt
in exact arithmetic with ordinary numpy syntax. Never mix ``fmpq`` with ``fractions.Fraction``
(they do not compare equal); convert with :func:`Q`.
"""

from __future__ import annotations

import math
import re
import sys
from decimal import Decimal
from fractions import Fraction
from typing import Any

import numpy as np
from flint import fmpq

Rational = fmpq
_RATIO = re.compile(r"(-?[0-9]+)(?:/([0-9]+))?")
QMatrix = np.ndarray  # dtype=object, entries fmpq


def Q(x: Any) -> fmpq:  # noqa: N802 - Q for the rationals
    """Convert an int, Fraction, Decimal, finite float, fmpq or "p/q" string to ``fmpq`` exactly."""
    if isinstance(x, fmpq):
        return x
    if isinstance(x, bool):
        raise TypeError("a boolean is not a number")
    if isinstance(x, (int, np.integer)):
        return fmpq(int(x))
    if isinstance(x, (float, np.floating)):
        if not math.isfinite(float(x)):
            raise ValueError(f"not a finite number: {x!r}")
        return fmpq(*float(x).as_integer_ratio())
    if isinstance(x, Decimal):
        if not x.is_finite():
            raise ValueError(f"not a finite number: {x!r}")
        return fmpq(*x.as_integer_ratio())
    if isinstance(x, Fraction):
        return fmpq(x.numerator, x.denominator)
    if isinstance(x, str):
        m = _RATIO.fullmatch(x)
        if m:  # the canonical "p/q" or "p" of qstr: integer parsing, no Fraction round trip
            return fmpq(int(m[1]), int(m[2])) if m[2] else fmpq(int(m[1]))
        if not x.isascii():  # Fraction reads "١" (Arabic-Indic one) as 1: a report's or
            # spec's number is ASCII (report-edit trial, session 26)
            raise ValueError(f"not a number: {x!r} (non-ASCII characters)")
        fr = Fraction(x.strip())
        return fmpq(fr.numerator, fr.denominator)
    raise TypeError(f"cannot convert {type(x).__name__} to a rational")


def qmat(a: Any) -> QMatrix:
    """Exact 2-D object array of ``fmpq`` from nested lists / arrays of numbers."""
    arr = np.array(a, dtype=object)
    if arr.ndim == 1:
        arr = arr.reshape(1, -1)
    if arr.ndim != 2:
        raise ValueError("expected a matrix")
    out = np.empty(arr.shape, dtype=object)
    for idx, v in np.ndenumerate(arr):
        out[idx] = Q(v)
    return out


def qvec(a: Any) -> QMatrix:
    """Exact 1-D object array of ``fmpq``."""
    arr = np.array(a, dtype=object).reshape(-1)
    return np.array([Q(v) for v in arr], dtype=object)


def qeye(n: int) -> QMatrix:
    """Exact identity matrix."""
    out = np.full((n, n), fmpq(0), dtype=object)
    for i in range(n):
        out[i, i] = fmpq(1)
    return out


def qzeros(shape: tuple[int, ...]) -> QMatrix:
    """Exact zero array."""
    return np.full(shape, fmpq(0), dtype=object)


def to_float(a: Any) -> np.ndarray | float:
    """Nearest float64 of an exact scalar or array."""
    if isinstance(a, fmpq):
        return _qfloat(a)
    arr = np.asarray(a, dtype=object)
    if not arr.size:
        return arr.astype(float)
    return np.fromiter((_qfloat(v) for v in arr.flat), dtype=float, count=arr.size).reshape(
        arr.shape
    )


def float_or_inf(x: Any) -> float:
    """The nearest float of an exact number for display (a pivot, a bound), ±inf beyond the
    float range instead of an OverflowError (the exact value decided; this only shows it)."""
    try:
        return _qfloat(Q(x))
    except OverflowError:
        return math.inf if Q(x) > 0 else -math.inf


def float_floor(x: Any) -> float:
    """The largest float ≤ the exact number x (−inf below the float range): a float y
    satisfies y ≤ x exactly iff y ≤ float_floor(x)."""
    q = Q(x)
    f = float_or_inf(q)
    if math.isinf(f):
        return f if f < 0 else sys.float_info.max
    return f if frac(f) <= frac(q) else math.nextafter(f, -math.inf)


def float_ceil(x: Any) -> float:
    """The smallest float ≥ the exact number x (+inf above the float range): a float y
    satisfies y ≥ x exactly iff y ≥ float_ceil(x)."""
    return -float_floor(-Q(x))


def _qfloat(x: Any) -> float:
    if isinstance(x, fmpq):
        # int / int is correctly rounded in CPython (it is what Fraction.__float__ does)
        return int(x.p) / int(x.q)
    return float(x)


def frac(x: Any) -> Fraction:
    """An exact number (fmpq, Fraction, int, a float or numpy scalar as it is) as a Fraction."""
    if isinstance(x, fmpq):
        return Fraction(int(x.p), int(x.q))
    if isinstance(x, (float, np.floating)):
        return Fraction(float(x))
    if isinstance(x, np.integer):  # Fraction(np.int64) keeps a numpy numerator, which fmpq
        return Fraction(int(x))  # refuses (canonical with an integer array; mutation review)
    return Fraction(x)


def dyadic(a: Any, bits: int = 24) -> QMatrix | fmpq:
    """Round each float to ``bits`` significant bits (a dyadic rational) and return it exactly.

    Rounding keeps the rationals short (fast exact checks) while every entry keeps its own
    relative accuracy 2^-bits, so badly scaled matrices survive. DESIGN.md: "round the
    solution to a dyadic grid before converting to rationals".
    """
    arr = np.asarray(a, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError("cannot round a non-finite number")

    def one(v: float) -> fmpq:
        if v == 0.0:
            return fmpq(0)
        m, e = math.frexp(v)  # v = m·2^e, 0.5 <= |m| < 1
        k = bits - e
        num = round(m * 2.0**bits)
        return fmpq(num, 2**k) if k >= 0 else fmpq(num * 2 ** (-k))

    if arr.ndim == 0:
        return one(float(arr))
    out = np.empty(arr.shape, dtype=object)
    for idx, v in np.ndenumerate(arr):
        out[idx] = one(float(v))
    return out


def symmetrize(M: QMatrix) -> QMatrix:
    """Exact (M + Mᵀ)/2."""
    return (M + M.T) * fmpq(1, 2)


def qstr(a: Any) -> Any:
    """Exact value(s) as strings like "-187/100" (nested lists for arrays)."""
    if isinstance(a, fmpq):
        return str(a)
    arr = np.asarray(a, dtype=object)
    if arr.ndim == 0:
        return str(Q(arr.item()))
    flat = np.empty(arr.size, dtype=object)
    flat[:] = [_qs(x) if isinstance(x, fmpq) else str(Q(x)) for x in arr.flat]
    return flat.reshape(arr.shape).tolist()


def _qs(x: fmpq) -> str:
    """``str(x)`` ("p/q", or "p" when q = 1), through Python ints: about 2× faster than
    flint's own str at the 10⁴ entries of a 100-state P."""
    q = int(x.q)
    return f"{int(x.p)}/{q}" if q != 1 else str(int(x.p))


def qstr_floats(a: np.ndarray) -> tuple[list[Any], list[Any]] | None:
    """(:func:`qstr` of ``a``, :func:`to_float` of ``a`` as nested lists) in one pass over
    Python ints, for an object array of ``fmpq`` (None for anything else): a report's exact
    strings and the floats beside them, each entry's numerator and denominator converted
    once. OverflowError beyond the float range, as :func:`to_float`."""
    flat = a.ravel().tolist()
    if not flat or set(map(type, flat)) != {fmpq}:
        return None
    strs: list[str] = []
    fls: list[float] = []
    for x in flat:
        p, q = int(x.p), int(x.q)
        strs.append(f"{p}/{q}" if q != 1 else str(p))
        fls.append(p / q)  # int / int: correctly rounded, as _qfloat
    out = np.empty(len(strs), dtype=object)
    out[:] = strs
    return out.reshape(a.shape).tolist(), np.array(fls, dtype=float).reshape(a.shape).tolist()


#: why a float is not a report's exact value (:func:`qparse_floats`)
_FLOAT_ENTRY = (
    'the float {!r} is not an exact value: write it as a string such as "1/10" or '
    '"0.1" (a JSON number does not say whether the decimal or the nearest double is meant)'
)


def qparse(s: Any) -> Any:
    """Inverse of :func:`qstr`: a string (or nested lists of them, any depth) back to ``fmpq``
    (an object array for lists)."""
    return _qparse(s, None)


def qparse_floats(s: Any) -> tuple[Any, Any]:
    """(:func:`qparse` of ``s``, its :func:`to_float` as a float or nested lists) with each
    canonical "p/q" string's integers converted once (a report's exact parameters and the
    floats its consistency check compares). OverflowError beyond the float range.

    A report's exact value is a string (or an integer): a float (a JSON number such as 0.1)
    is refused with ValueError, since it does not say whether 1/10 or the double nearest to
    it is meant (verify took the double's binary value)."""
    if isinstance(s, list):
        fls: list[float] = []
        q = _qparse(s, fls, strict=True)
        return q, np.array(fls, dtype=float).reshape(q.shape).tolist()
    q = _qparse(s, None, strict=True)
    return q, _qfloat(q)


def _qparse(s: Any, floats: list[float] | None, strict: bool = False) -> Any:
    """:func:`qparse`; with ``floats``, each entry's nearest float appended to it; ``strict``:
    a float entry is refused (:func:`qparse_floats`)."""
    if strict and isinstance(s, float):
        raise ValueError(_FLOAT_ENTRY.format(s))
    if isinstance(s, (str, int, float)) and not isinstance(s, bool):
        return Q(s)
    if isinstance(s, list):
        arr = np.array(s, dtype=object)
        if arr.size == 0:
            raise ValueError("ragged or empty exact array")
        flat = arr.reshape(-1)
        vals: list[fmpq] = []
        match = _RATIO.fullmatch
        for v in flat:
            if type(v) is str and (m := match(v)) is not None:
                # the canonical "p/q" or "p" of qstr, inline (Q's first case; ~2× faster at
                # the 2×10⁴ strings of a 100-state lyapunov report)
                p, q = int(m[1]), (int(m[2]) if m[2] else 1)
                vals.append(fmpq(p, q))  # ZeroDivisionError for q = 0, before p / q
                if floats is not None:
                    floats.append(p / q)  # int / int: correctly rounded, as _qfloat
                continue
            if isinstance(v, list):  # a ragged nesting: numpy keeps the shorter rows as lists
                raise ValueError("ragged or empty exact array")
            if isinstance(v, bool) or not isinstance(v, (str, int, float)):
                raise ValueError(f"not an exact value: {v!r}")
            if strict and isinstance(v, float):
                raise ValueError(_FLOAT_ENTRY.format(v))
            x = Q(v)
            vals.append(x)
            if floats is not None:
                floats.append(_qfloat(x))
        out = np.empty(flat.shape, dtype=object)
        out[:] = vals
        return out.reshape(arr.shape)
    raise ValueError(f"not an exact value: {s!r}")


def qmax_abs(M: QMatrix) -> fmpq:
    """Exact max |entry|."""
    return max((abs(v) for v in np.asarray(M, dtype=object).flat), default=fmpq(0))
