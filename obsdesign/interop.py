"""python-control and MATLAB interop (the optional extra ``obsdesign[control]``).

- :func:`spec_from_statespace` / :func:`spec_text_from_statespace`: a ``control.StateSpace``
  (or ``(A, B, C, D, dt)`` matrices) → a spec. ``dt = 0`` is continuous time; ``dt > 0``
  discrete time with ``sample_time = dt``; ``dt = True`` (discrete, unspecified period)
  discrete time without a sample time. Every float is written as its shortest ``repr``
  (the decimal that reads back as the same double; the spec means that decimal exactly).
- :func:`observer_statespace`: the designed observer of a report as a ``control.StateSpace``
  (inputs ``u[i]`` then ``y[j]``, states and outputs ``xhat[i]``) for the linear observers:
  ``lyapunov`` (x̂⁺ = A x̂ + B u + L(y − C x̂ − D u)), ``set-invariant`` with its linear law
  (x̂⁺ = A x̂ + B u − L(y − C x̂ − D u), the sign of eq. (3) of the set-invariant paper) and the
  Luenberger part of ``stubborn`` (x̂⁺ = A x̂ + B u + K(y − C x̂ − D u), without its
  saturation). The piecewise-affine injection of ``set-invariant`` (eq. (10)/(12), one
  output) is a ``control.NonlinearIOSystem``. The other methods' observers (constrained:
  projection onto X̂; impulsive: sampled, hybrid; search-space: set-valued) are not offered.
- :func:`spec_text_from_mat`: matrices from a MATLAB ``.mat`` file (``scipy.io.loadmat``) →
  spec text (``obsdesign import FILE.mat --A A --C C ...``).
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Mapping
from decimal import Decimal, localcontext
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from obsdesign.errors import InputError, SpecError

#: methods whose designed observer is linear (a control.StateSpace)
LINEAR = ("lyapunov", "set-invariant", "stubborn")


def _control() -> Any:
    try:
        import control
    except ImportError:  # pragma: no cover - the extra is not installed
        raise InputError(
            "python-control is not installed: pip install 'obsdesign[control]'"
        ) from None
    return control


# -- TOML writing ---------------------------------------------------------------------------
def _rational(x: Any) -> Fraction | int | None:
    """``x`` as a Fraction (an int when integral) when it is an exact rational of another
    type — ``flint.fmpq``, ``sympy.Rational`` / ``sympy.Integer`` (any ``numbers.Rational``)
    — else None. These were rounded to doubles (re-check trial, session 28)."""
    from flint import fmpq

    if isinstance(x, (bool, np.bool_, int, np.integer, Fraction)):
        return None
    if isinstance(x, fmpq):
        return Fraction(int(x.p), int(x.q))
    if isinstance(x, numbers.Integral):
        return int(x)
    if isinstance(x, numbers.Rational):
        return Fraction(int(x.numerator), int(x.denominator))
    return None


def _exact(x: Any) -> Decimal | None:
    """The exact decimal a spec writes for an exact input (session 28: these were rounded
    to doubles, so the certificate was about another matrix), else None:

    - a ``Decimal``: its own digits;
    - a ``Fraction`` (any non-integer ``numbers.Rational``): its finite decimal expansion;
      one without (1/3) is refused, as a spec's numbers are decimals;
    - a long double (``np.longdouble`` wider than a double): its shortest repr at its own
      precision, which reads back as the same long double (as a double's repr does)."""
    r = _rational(x)
    if r is not None:
        x = Fraction(r)
    if isinstance(x, Decimal):
        if not x.is_finite():
            raise InputError(f"cannot write the non-finite number {x} into a spec")
        return x
    if isinstance(x, Fraction):
        from obsdesign.limits import int_problem

        for part in (x.numerator, x.denominator):
            why = int_problem(part)  # str() of a 5000-digit int is a ValueError (session 34)
            if why is not None:
                raise InputError(f"the exact number's numerator or denominator {why}")
        d, twos, fives = x.denominator, 0, 0
        while d % 2 == 0:
            d, twos = d // 2, twos + 1
        while d % 5 == 0:
            d, fives = d // 5, fives + 1
        if d != 1:
            raise InputError(
                f"the exact number {x} has no finite decimal form, which a spec's numbers "
                "are: round it (e.g. float(x)) or rescale the model"
            )
        with localcontext() as ctx:
            ctx.prec = len(str(abs(x.numerator))) + max(twos, fives) + 2
            return Decimal(x.numerator) / Decimal(x.denominator)
    if isinstance(x, np.floating) and x.dtype.itemsize > 8:
        if not np.isfinite(x):
            raise InputError(f"cannot write the non-finite number {x} into a spec")
        return Decimal(np.format_float_scientific(x, unique=True))
    return None


def _num(x: Any) -> str:
    """A number as TOML: integers as they are, floats by their shortest repr (exact decimal),
    exact inputs (Decimal, Fraction, long double) exactly (:func:`_exact`)."""
    if isinstance(x, (bool, np.bool_)):
        return "true" if x else "false"
    if isinstance(x, (int, np.integer)):
        try:  # any size the spec reader takes (a seed, an exact matrix entry)
            return str(int(x))
        except ValueError:  # past Python's int-string limit: a bare ValueError (CLI review 46)
            from obsdesign.errors import value_text

            raise InputError(
                f"cannot write {value_text(int(x))} into a spec (past Python's 4,300-digit "
                "limit for integer text)"
            ) from None
    q = _exact(x)
    if q is not None:
        if q == q.to_integral_value() and abs(q) < 10**18:
            return str(int(q))
        return str(q).replace("E", "e")
    f = float(x)
    if not math.isfinite(f):
        raise InputError(f"cannot write the non-finite number {f!r} into a spec")
    if f == int(f) and abs(f) < 2**53:
        return str(int(f))
    return repr(f)


def _tstr(v: str) -> str:
    """A TOML basic string of ``v``: backslash, quote and every control character escaped
    (a file name with ESC or CR in it gave a title TOML refuses: outsider trial, session
    22); a lone surrogate, which no UTF-8 text holds, becomes U+FFFD."""
    out = []
    for ch in v:
        o = ord(ch)
        if ch in '"\\':
            out.append("\\" + ch)
        elif o < 0x20 or o == 0x7F:
            out.append({"\n": "\\n", "\t": "\\t", "\r": "\\r"}.get(ch, f"\\u{o:04X}"))
        elif 0xD800 <= o <= 0xDFFF:  # a lone surrogate (a file name's undecodable byte)
            out.append("\\uFFFD")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _key(k: Any) -> str:
    """A TOML key: bare when it can be, else a quoted string."""
    k = str(k)
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _tstr(k)


def _value(v: Any) -> str:
    """A TOML value: a string, a number (:func:`_num`), an array, or an inline table (a
    mapping inside an array, as ``[simulate.noise] windows = [{...}]``). A mapping or None
    inside an array went to ``np.asarray`` as a 0-d object array whose item is itself: a
    RecursionError (sweep, import and check trial, session 28)."""
    if isinstance(v, str):
        return _tstr(v)
    if isinstance(v, (bool, np.bool_, numbers.Real, Decimal)) or _rational(v) is not None:
        return _num(v)
    if v is None:
        raise InputError("a missing value (None) cannot be written into a spec")
    if isinstance(v, Mapping):
        return "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)) or (
        isinstance(v, np.ndarray) and v.dtype == object and v.ndim > 0
    ):
        # item by item: np.asarray made True 1.0 beside a float, and `L=[[True], [0.5]]`
        # was written as L = [[1], [0.5]] and certified; a boolean stays `true`, which the
        # spec refuses where a number belongs (re-check trial, session 35)
        return "[" + ", ".join(_value(x) for x in v) + "]"
    arr = np.asarray(v)
    if arr.ndim == 0:
        item = arr.item()
        # a complex number's item is a new complex, never `v` itself: RecursionError (API
        # trial, session 33); the same type again means nothing was unwrapped
        if item is v or type(item) is type(v) or isinstance(item, complex):
            raise InputError(f"cannot write a value of type {type(v).__name__} into a spec")
        return _value(item)
    if arr.dtype.kind in "fiub":
        if arr.ndim == 1:
            return "[" + ", ".join(_num(x) for x in arr) + "]"
        return "[" + ", ".join(_value(row) for row in arr) + "]"
    return "[" + ", ".join(_value(x) for x in v) + "]"


def _table(name: str, data: Mapping[str, Any]) -> list[str]:
    """``[name]`` with its plain keys first, then its sub-tables; an error names the key."""
    lines = [f"[{name}]"]
    subs = []
    for k, v in data.items():
        if isinstance(v, Mapping):
            subs.append((k, v))
        elif v is not None:
            try:
                lines.append(f"{_key(k)} = {_value(v)}")
            except InputError as e:
                raise InputError(f"[{name}] {k}: {e}") from None
    out = lines + [""]
    for k, v in subs:
        # a sub-table's name quoted as a key is: "my noise" wrote invalid TOML, and a name
        # with a dot or a bracket made other tables, or injected some (API review 45)
        out += _table(f"{name}.{_key(k)}", v)
    return out


# -- StateSpace → spec -----------------------------------------------------------------------
def _matrices(sys: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Any]:
    if isinstance(sys, tuple):
        if len(sys) not in (4, 5):
            raise InputError(f"expected (A, B, C, D) or (A, B, C, D, dt), got {len(sys)} items")
        A, B, C, D, dt = (*sys, 0)[:5] if len(sys) == 4 else sys
    elif all(hasattr(sys, k) for k in ("A", "B", "C", "D")):
        A, B, C, D, dt = sys.A, sys.B, sys.C, sys.D, getattr(sys, "dt", 0)
    else:
        # a transfer function (control.tf) raised AttributeError: 'TransferFunction' has no
        # attribute 'A' (outsider trial, session 22)
        raise InputError(
            f"expected a state-space system (control.StateSpace or (A, B, C, D[, dt])), got "
            f"{type(sys).__name__}: convert it first, e.g. control.ss(sys)"
        )
    A = np.atleast_2d(_real(A, "A"))
    C = np.atleast_2d(_real(C, "C"))
    n = A.shape[0]
    if A.size == 0:  # a 0×0 plant printed "A = []", which no spec accepts (outsider trial)
        raise InputError(f"A has shape {A.shape}: a plant needs at least one state")
    if A.shape != (n, n) or C.ndim != 2 or C.shape[1] != n:
        raise InputError(f"state-space shapes do not fit: A {A.shape}, C {C.shape}")
    B = _columns(B, n, "B", "n, the states")
    p, m = C.shape[0], B.shape[1]
    Dr = _real(D, "D")
    if Dr.size == 0:
        D = np.zeros((p, m))
    elif Dr.shape == (p, m) or (Dr.ndim == 1 and Dr.size == p * m and 1 in (p, m)):
        D = Dr.reshape(p, m)  # a vector is D's one row (p = 1) or one column (m = 1)
    else:
        # a wrongly shaped B or D was reshaped row-major into another matrix, then certified
        # (independent soundness trial, session 23)
        raise InputError(f"D has shape {Dr.shape}: expected p×m = {p}×{m} (C's rows, B's columns)")
    return A, B, C, D, dt


def _big_int(x: Any) -> bool:
    """An integer (not a bool) that a double does not hold exactly: beyond 2⁵³."""
    return isinstance(x, (int, np.integer)) and not isinstance(x, bool) and abs(int(x)) > 2**53


def _is_bool(x: Any) -> bool:
    """A boolean: Python's, numpy's, or a 0-d numpy array of one (``np.array(True)`` in a
    list was read as 1; mutation review 35)."""
    return isinstance(x, (bool, np.bool_)) or (
        isinstance(x, np.ndarray) and x.ndim == 0 and x.dtype.kind == "b"
    )


def _real(M: Any, name: str) -> np.ndarray:
    """A real matrix: integer entries stay integers (exact: an int64 above 2⁵³ was rounded by
    a conversion to float, soundness trial, session 23), anything else as floats; complex
    entries are refused (they were cast to their real part), and so are ragged rows, text,
    None and other non-numbers (a bare ValueError, TypeError or OverflowError, or "nan" for
    None; lyapunov trial, session 34)."""
    try:
        arr = np.asarray(M)
    except (ValueError, TypeError):
        raise InputError(
            f"{name} is not a matrix of numbers: its rows are not all of one length"
        ) from None
    probe = arr
    if arr.dtype.kind in "iuf" and isinstance(M, (list, tuple)):
        probe = np.array(M, dtype=object)
        if probe.shape != arr.shape:
            probe = arr
    # a boolean is not a number, as in a spec ("a boolean"): numpy made True 1 in a plain
    # list, and 1.0 beside a float, but refused it beside a Fraction (re-check 34 §9)
    if arr.dtype.kind == "b" or (probe.dtype == object and any(map(_is_bool, probe.flat))):
        where = next((list(i) for i, x in np.ndenumerate(probe) if _is_bool(x)), [0] * arr.ndim)
        raise InputError(f"{name}{where} is a boolean, not a number")
    if arr.dtype.kind == "f" and probe.dtype == object and any(_big_int(x) for x in probe.flat):
        # a list mixing floats with an integer beyond 2⁵³ became floats: the integer rounded
        arr = probe
    if arr.dtype.kind == "c" or (
        arr.dtype == object and any(isinstance(x, (complex, np.complexfloating)) for x in arr.flat)
    ):
        raise InputError(f"{name} has complex entries: a spec's matrices are real")
    if arr.dtype.kind not in "biuf" and arr.dtype != object:
        first = str(arr.reshape(-1)[0]) if arr.size else ""
        raise InputError(f"{name} has the entry {first!r}, which is not a number")
    if arr.dtype == object:
        for idx, x in np.ndenumerate(arr):
            if not isinstance(x, (numbers.Real, Decimal)) and _rational(x) is None:
                raise InputError(f"{name}{list(idx)} = {x!r}, which is not a number")
    if arr.dtype.kind in "iu":
        return arr
    if arr.dtype == object and all(
        isinstance(x, (int, np.integer)) and not isinstance(x, bool) for x in arr.flat
    ):
        return arr
    if (arr.dtype.kind == "f" and arr.dtype.itemsize > 8) or (
        arr.dtype == object
        and any(
            isinstance(x, (Decimal, Fraction)) or _rational(x) is not None or _big_int(x)
            for x in arr.flat
        )
    ):
        # an integer beyond 2⁵³ beside floats is kept exact too: it was rounded to a double,
        # or overflowed (10⁴⁰⁰: a bare OverflowError; lyapunov trial, session 34)
        # exact inputs kept exact (written by _num through _exact): they were rounded to
        # doubles (sweep, import and check trial, session 28)
        out = np.empty(arr.shape, dtype=object)
        for idx, x in np.ndenumerate(arr):
            if (
                isinstance(x, bool)
                or not isinstance(x, (numbers.Real, Decimal))
                and _rational(x) is None
            ):
                raise InputError(f"{name} has the entry {x!r}, which is not a number")
            try:
                q = _exact(x)
            except InputError as e:
                raise InputError(f"{name}{list(idx)}: {e}") from None
            out[idx] = x if q is None else q
            try:
                f = float(out[idx])
            except OverflowError:
                f = math.inf
            if not math.isfinite(f) or (f == 0) != (out[idx] == 0):
                raise InputError(
                    f"{name}{list(idx)} = {x}: outside the float range, which a spec refuses: "
                    "rescale the model"
                )
        return out
    out = arr.astype(float)
    tiny = (out != 0) & (np.abs(out) < np.finfo(float).tiny)
    if tiny.any():  # written as 5e-324, then refused by the spec loader (outsider trial)
        x = float(out[tiny].reshape(-1)[0])
        raise InputError(
            f"{name} has the entry {x!r}, a nonzero number below the float range (subnormal), "
            "which a spec refuses: rescale the model or write it as 0"
        )
    return out


def _columns(M: Any, rows: int, name: str, what: str) -> np.ndarray:
    """``M`` as a matrix of ``rows`` rows (B, Bd): a matrix with that many rows as it is, a
    vector of that length (1-D, or one row when rows > 1) as one column, nothing as rows×0;
    any other shape is refused (it was reshaped row-major into another matrix: a 2×3 B of a
    3-state plant became [[1, 2], [3, 4], [5, 6]] and was certified)."""
    arr = _real(M, name)
    if arr.size == 0:
        return np.zeros((rows, 0))
    if arr.ndim == 2 and arr.shape[0] == rows:
        return arr
    if (arr.ndim == 1 and arr.shape[0] == rows) or (arr.ndim == 2 and arr.shape == (1, rows)):
        return arr.reshape(rows, 1)
    raise InputError(f"{name} has shape {arr.shape}: expected {rows} rows ({what})")


def _time_of(dt: Any) -> tuple[str, float | Decimal | None]:
    """``time`` and ``sample_time`` of a system's ``dt``: None or 0 continuous, True discrete
    without a sample time, > 0 discrete with it. The sign is the exact value's: a Fraction
    or Decimal below the float range (1/10⁴⁰⁰) read as 0.0, continuous time, and −1/10⁴⁰⁰
    as −0.0 passed (API review, session 44); such a dt is refused."""
    import math

    if dt is None:
        return "continuous", None
    if dt is True:
        return "discrete", None
    try:
        zero, positive = bool(dt == 0), bool(dt > 0)
        try:
            f = float(dt)
        except OverflowError:  # Fraction(10**400): beyond the float range, not "not positive"
            f = math.inf
    except (TypeError, ValueError, ArithmeticError):
        zero = positive = False
        f = math.nan
    if zero:
        return "continuous", None
    if positive and math.isfinite(f) and f > 0:
        # an exact dt (a Decimal, a Fraction with a decimal form) is written as it is: import
        # --dt 0.1000000000000000000001 wrote the nearest double, 0.1 (re-check review, 44)
        try:
            q = _exact(dt) if isinstance(dt, (Decimal, Fraction)) else None
        except InputError:  # Fraction(1, 3): no decimal form, written as its double
            q = None
        # q even when it is a double's value: 0.1's double written "0.1" read back as 1/10
        return "discrete", (f if q is None else q)
    if positive and f == 0:
        raise InputError(f"dt {dt!r} is positive but below the float range (it would read as 0)")
    if positive and not math.isfinite(f):
        raise InputError(f"dt {dt!r} is beyond the float range")
    raise InputError(f"dt must be 0, True or a finite positive number, got {dt!r}")


def spec_text_from_statespace(
    sys: Any,
    method: str = "lyapunov",
    *,
    title: str | None = None,
    states: list[str] | None = None,
    sets: Mapping[str, Mapping[str, Any]] | None = None,
    nonlinearity: Mapping[str, Any] | None = None,
    simulate: Mapping[str, Any] | None = None,
    Bd: Any = None,
    **options: Any,
) -> str:
    """Spec text (TOML) of the plant ``sys`` (a ``control.StateSpace``, or a tuple
    ``(A, B, C, D[, dt])``) with ``[method] key = method`` and the method's ``options``
    (``lambda=0.9``, ``L=[[...]]``; a key that is not a Python name: ``**{"rate-x": 1}``).

    ``dt``: 0 (or None) continuous; True discrete without a sample time; > 0 discrete with
    ``sample_time = dt``. ``B`` and ``D`` are written when they are not all zero. ``sets``,
    ``nonlinearity`` and ``simulate`` are written as tables (nested mappings → sub-tables),
    ``Bd`` as the disturbance input. Floats are written by their shortest repr, so the spec
    reads back as the same doubles; the spec's exact values, and so its certificate, are those
    decimals (0.1 is 1/10, not the double's binary value), which a certificate with a margin
    near 10⁻¹⁶ relative can tell apart (docs/quickstart.md). Integer entries are written
    exactly; B and Bd must have n rows and D p×m (a vector is one column, D's one row or
    column), else InputError. A boolean is written as ``true`` / ``false`` wherever it sits
    (never as 1 / 0 beside a float), so the spec refuses it where a number belongs."""
    args = {"sets": sets, "nonlinearity": nonlinearity, "simulate": simulate, **options}
    for name, v in args.items():
        _nesting_check(name, v)
    try:
        return _spec_text(sys, method, title, states, sets, nonlinearity, simulate, Bd, options)
    except RecursionError:
        raise InputError("a value nested too deeply to be written into a spec") from None


def _nesting_check(name: str, value: Any) -> None:
    """Refuse ``value`` nested deeper than the spec reader's ``max_depth`` (walked
    iteratively): mappings or lists thousands deep were a bare RecursionError, or — under a
    raised recursion limit — written into a spec no reader takes (CLI review 46)."""
    from obsdesign.limits import limits

    most = limits().max_depth
    stack = [(value, 1)]
    while stack:
        v, depth = stack.pop()
        if isinstance(v, Mapping):
            items: Any = v.values()
        elif isinstance(v, (list, tuple)) or (isinstance(v, np.ndarray) and v.dtype == object):
            items = v
        else:
            continue
        if depth > most:
            raise InputError(
                f"{name}: nested more than {most} levels deep, past what a spec may hold "
                "(--limit max_depth)"
            )
        stack.extend((x, depth + 1) for x in items)


def _spec_text(
    sys: Any,
    method: str,
    title: str | None,
    states: Any,
    sets: Any,
    nonlinearity: Any,
    simulate: Any,
    Bd: Any,
    options: dict[str, Any],
) -> str:
    """:func:`spec_text_from_statespace`'s body."""
    for what, v in (("sets", sets), ("nonlinearity", nonlinearity), ("simulate", simulate)):
        if v is not None and not isinstance(v, Mapping):
            raise InputError(f"{what}: expected a mapping of keys to values, got {_tname(v)}")
    if states is not None:
        # any iterable of names (a list, a tuple, a numpy array, a generator); states=5 was
        # a bare TypeError (CLI review 46)
        try:
            items = None if isinstance(states, (str, bytes)) else list(states)
        except TypeError:
            items = None
        if items is None or not all(isinstance(x, str) for x in items):
            raise InputError(
                f"states: expected a list of state names (texts), got {_tname(states)}"
            )
        states = [str(x) for x in items]
    if not isinstance(method, str):
        raise InputError(f"method: expected a method key (a text), got {_tname(method)}")
    A, B, C, D, dt = _matrices(sys)
    time, sample_time = _time_of(dt)
    system: dict[str, Any] = {"time": time, "A": A, "C": C}
    if B.size and np.any(B != 0):
        system["B"] = B
    elif B.shape[1]:
        system["inputs"] = B.shape[1]
    if D.size and np.any(D != 0):
        # also with B = 0: the feedthrough still enters y, so the observer's u-column is −L D
        # (a nonzero D was dropped with a zero B: outsider trial, session 22)
        system["D"] = D
    if Bd is not None:
        system["Bd"] = _columns(Bd, A.shape[0], "Bd", "n, the states")
    if sample_time is not None:
        system["sample_time"] = sample_time
    if states is not None:
        system["states"] = list(states)
    head = [f"title = {_value(title)}", ""] if title else []
    lines = head + _table("system", system)
    for name, s in (sets or {}).items():
        lines += _table(f"sets.{_key(name)}", s)
    if nonlinearity:
        lines += _table("nonlinearity", nonlinearity)
    lines += _table("method", {"key": method, **options})
    if simulate:
        lines += _table("simulate", simulate)
    return "\n".join(lines).rstrip("\n") + "\n"


def _tname(v: Any) -> str:
    return type(v).__name__


def spec_from_statespace(sys: Any, method: str = "lyapunov", **options: Any) -> Any:
    """The bound :class:`obsdesign.spec.Spec` of :func:`spec_text_from_statespace` (file name
    ``<statespace>``); its ``text`` is the TOML."""
    from obsdesign.api import load_spec_text

    return load_spec_text(spec_text_from_statespace(sys, method, **options), "<statespace>")


# -- report → observer ------------------------------------------------------------------------
def _names(prefix: str, k: int) -> list[str]:
    return [f"{prefix}[{i}]" for i in range(k)]


def _named(shaped: Any, key: str, shape: tuple[int, int], where: str) -> np.ndarray:
    """``shaped(key, shape)`` (:meth:`Parameters.shaped`) with its refusal naming the report."""
    try:
        return shaped(key, shape)  # type: ignore[no-any-return]
    except InputError as e:
        raise InputError(f"{where}: {e.message.removeprefix('report: ')}") from None


def observer_statespace(report: Any, law: str | None = None, verify: bool = False) -> Any:
    """The designed observer of ``report`` (a :class:`obsdesign.report.model.Report` or a path
    to one) as a python-control system with inputs ``u[0..m-1]``, ``y[0..p-1]`` and outputs
    (and states) ``xhat[0..n-1]``: a ``control.StateSpace`` for the linear observers
    (:data:`LINEAR`), a ``control.NonlinearIOSystem`` for set-invariant's piecewise-affine
    injection (``law="interpolated"`` or ``"time-varying"``; the default for one output when
    the report has a breakpoint table is still the linear law when it has one: pass ``law``
    to choose; the linear law's gain is the spec's ``[method].L`` when given, else the
    designed L, as ``simulate``'s ``law=linear``). Continuous-time plants give continuous-time observers, discrete ones
    discrete (``dt`` = ``sample_time``, else True).

    The report's claims are not recomputed unless ``verify`` (then a report that
    :func:`obsdesign.api.verify` does not find ok is refused, :class:`InputError`). Always
    refused: a float parameter that differs from its exact value, and an embedded spec whose
    sha256 is not the report's ``spec_sha256``; a report whose stored claims give a verdict
    other than ok gives a ``UserWarning``. A report with L edited to an unstable gain gave
    an observer with no word (sweep, import and check trial, session 28)."""
    import hashlib
    import os
    import warnings

    from obsdesign.api import load_spec_text, object_report
    from obsdesign.report.model import Report

    if not isinstance(report, (Report, str, os.PathLike)):
        # None was a bare TypeError from the path handling (CLI review 46)
        raise InputError(f"report: expected a Report or the path of one, got {_tname(report)}")
    if not isinstance(report, Report) and "\0" in os.fspath(report):
        # open() said "embedded null byte", a bare ValueError (API review 46)
        raise InputError(f"report: a path with a NUL character: {os.fspath(report)!r}")
    if law is not None and not isinstance(law, str):
        raise InputError(f"law: expected a law name (a text), got {_tname(law)}")
    ct = _control()
    where = "report" if isinstance(report, Report) else str(report)
    report, problems = object_report(report) if isinstance(report, Report) else Report.load(report)
    if problems:
        raise InputError(f"{where}: {problems[0]}")
    if report.error is not None:
        raise InputError("the report records a design that stopped with an error: no observer")
    if hashlib.sha256(report.spec.encode()).hexdigest() != report.spec_sha256:
        raise InputError(f"{where}: its embedded spec does not match its spec_sha256")
    if verify:
        from obsdesign.api import verify as recheck

        got = recheck(report).computed_verdict()
        if got != "ok":
            raise InputError(f"{where}: obsdesign verify gives '{got}', not 'ok': no observer")
    elif report.computed_verdict() != "ok":
        warnings.warn(
            f"{where}: its claims give the verdict '{report.computed_verdict()}', not 'ok': "
            "the observer's parameters are not certified",
            UserWarning,
            stacklevel=2,
        )
    if report.method not in LINEAR:
        raise InputError(_NOT_LINEAR.format(method=report.method, linear=", ".join(LINEAR)))
    if law not in (None, "linear") and report.method != "set-invariant":
        # law="online-lp" with a lyapunov report was dropped without a word, while
        # set-invariant refuses a law it does not know (CLI review 46)
        raise InputError(
            f"law {law!r}: the {report.method} observer is linear and has no other law; "
            "law is for set-invariant reports"
        )
    sp = load_spec_text(report.spec, report.spec_file or "<report>")
    s, params = sp.system, report.parameters
    if s.A is None or s.C is None:
        # AttributeError "'NoneType' object has no attribute 'f'" for the shipped stubborn
        # high-gain spec (Duffing, f and h only) and every search-space design (outsider
        # trial, session 29)
        raise InputError(
            f"{where}: the plant of method '{report.method}' is given by expressions "
            "([system] f / h), not by the matrices A and C: its observer is not a linear "
            "state-space system and is not offered as a python-control system"
        )
    n, p = s.n, s.p
    A, C = np.asarray(s.A.f, float), np.asarray(s.C.f, float)
    B = np.asarray(s.B.f, float).reshape(n, -1)
    m = B.shape[1]
    D = np.asarray(s.D.f, float).reshape(p, m) if m else np.zeros((p, 0))
    if s.discrete:
        dt: Any = float(s.sample_time.f) if getattr(s, "sample_time", None) is not None else True
    else:
        dt = 0
    inputs, outputs = _names("u", m) + _names("y", p), _names("xhat", n)
    name = f"obsdesign-{report.method}"

    def linear(
        G: np.ndarray, sign: float, rate: Any = None, key: str | None = None, strict: bool = True
    ) -> Any:
        # x̂' = A x̂ + B u + sign·G (y − C x̂ − D u); key: the report parameter holding G
        # exactly (None: the spec's [method].L); strict: the certificate implies asymptotic
        # stability (set-invariant with λ = 1 proves invariance only: ρ ≤ 1)
        from obsdesign.lyap import float_closed_loop

        G = np.asarray(G, float).reshape(n, p)
        Ao = float_closed_loop(A, sign * G, C, "observer_statespace(), in doubles,")

        def exact_loop() -> Any:
            return _exact_loop(sp, params, key, sign)

        if strict:
            _check_float_realization(Ao, s.discrete, rate, where, exact_loop)
        else:
            _check_invariant_gain(exact_loop(), where)
        with np.errstate(all="ignore"):
            Bo = np.hstack([B - sign * G @ D, sign * G])
        return ct.ss(
            Ao,
            Bo,
            np.eye(n),
            np.zeros((n, m + p)),
            dt,
            inputs=inputs,
            outputs=outputs,
            states=outputs,
            name=name,
        )

    # shaped: a 4×5 L of a 5×4 gain was reshaped row-major into another gain and returned
    # without a word, while simulate --report refuses it (lyapunov trial, session 34)
    if report.method == "lyapunov":
        key = "lambda" if s.discrete else "alpha"
        rate = params.exact(key, [], accept_float=True) if key in params else None
        return linear(_named(params.shaped, "L", (n, p), where), +1.0, rate, "L")
    if report.method == "stubborn":
        if getattr(sp.options, "mode", None) == "high-gain" or not s.linear:
            # A + psi in mode high-gain passed the f / h test above and returned the linear
            # observer with the K of the nominal design: the certified observer injects
            # k_i·ℓ^i and runs ψ(x̂) (interop trial, session 39)
            raise InputError(
                f"{where}: the stubborn observer of this spec (mode high-gain, or a plant "
                "with psi) runs the nonlinearity and the high-gain injection: it is not a "
                "linear state-space system and is not offered as a python-control system"
            )
        return linear(_named(params.shaped, "K", (n, p), where), +1.0, key="K")
    if report.method == "set-invariant":
        use = law or ("linear" if "L" in params or sp.options.L is not None else "interpolated")
        if use == "linear":
            from obsdesign.methods.setinvariant.sim import make_law

            key = None if sp.options.L is not None else "L"  # make_law's choice
            # λ = 1 certifies an invariant polytope, ρ(A + LC) ≤ 1, not a stable observer:
            # such a certified, verified report was refused as unstable (re-check review 46)
            strict = sp.options.lam < 1
            return linear(make_law(sp, params, "linear").L, -1.0, key=key, strict=strict)
        return _setinvariant_nonlinear(ct, sp, params, use, A, B, C, D, dt, inputs, outputs, name)
    raise InputError(_NOT_LINEAR.format(method=report.method, linear=", ".join(LINEAR)))


def _exact_loop(sp: Any, params: Any, key: str | None, sign: float) -> Any:
    """A − sign·G·C in exact arithmetic, G the exact gain (report parameter ``key``, or the
    spec's ``[method].L`` for None), or None when an exact value is not at hand."""
    from obsdesign.lyap import exact_closed_loop

    G = sp.options.L if key is None else params.exact(key, [], accept_float=True)
    if G is None:
        return None
    G = np.asarray(G, dtype=object)
    return exact_closed_loop(sp.system.A.q, G if sign > 0 else -G, sp.system.C.q)


def _check_invariant_gain(Aex: Any, where: str) -> None:
    """For a certificate of invariance only (set-invariant with λ = 1: ρ(A + LC) ≤ 1): refuse
    an exact gain whose A + LC has an eigenvalue clearly outside the unit disk — no P ≻ 0
    decays at the rate 1 + 2⁻⁴⁰, decided exactly — as the report's claims cannot hold for it.
    With λ = 1 no check ran, and an L edited to a gain with eigenvalue 10.65 was exported
    without a word while verify fails it (re-check review 46). ``Aex`` None: not at hand."""
    from obsdesign.certify.exact import Q
    from obsdesign.lyap import exact_within

    if Aex is not None and not exact_within(Aex, True, Q(1) + Q(1) / 2**40):
        raise InputError(
            f"{where}: the observer matrix of the report's exact gain has an eigenvalue outside "
            "the unit disk: the report's invariance claims cannot hold for it (obsdesign "
            "verify says which fail); no observer is offered"
        )


def _check_float_realization(
    Ao: np.ndarray, discrete: bool, rate: Any, where: str, exact_loop: Any = None
) -> None:
    """The exported observer matrix (A − LC formed in doubles, the realization the user
    takes away) checked exactly: every eigenvalue within the certified ``rate`` (lyapunov's
    λ or α; None: stability, |z| < 1 or Re z < 0), by :func:`obsdesign.lyap.float_realization`
    on the doubles' exact values. The certificate is about the exact gain: on an
    ill-conditioned plant (ρ(A − LC) = 0.647 certified) the doubles gave ρ = 3.5, an
    unstable observer handed over with no word (interop trial, session 39). Unstable: an
    :class:`InconclusiveError`; stable but slower than ``rate``: a ``UserWarning`` — unless
    ``exact_loop()`` (A − LC of the exact gain) fails too: the gain itself is unstable
    (:class:`InputError`, its claims cannot hold) or slower (a warning saying so)."""
    import warnings

    from obsdesign.certify.exact import Q
    from obsdesign.errors import InconclusiveError
    from obsdesign.lyap import exact_within, float_realization, stability_test

    verdict = float_realization(Ao, discrete, rate)
    if verdict == "ok":
        return
    Aex = exact_loop() if exact_loop is not None else None
    if Aex is not None and not exact_within(Aex, discrete, rate if verdict == "slower" else None):
        # the exact gain itself: the doubles were blamed for an L edited to an unstable or
        # slower gain, exit 4, while verify says the report's claims fail (tamper review 46)
        what = (
            f"is not {'Schur' if discrete else 'Hurwitz'} ({stability_test(discrete)})"
            if verdict == "unstable"
            else f"does not keep the certified rate {float(Q(rate)):.6g}"
        )
        text = (
            f"{where}: the observer matrix A − LC of the report's exact gain {what}: the "
            "report's claims cannot hold for it (obsdesign verify says which fail)"
        )
        if verdict == "unstable":
            raise InputError(text + "; no observer is offered")
        warnings.warn(text, UserWarning, stacklevel=3)
        return
    if verdict == "slower":
        warnings.warn(
            f"{where}: the observer matrix in doubles (A − LC rounded) is stable but does "
            f"not keep the certified rate {float(Q(rate)):.6g}: the certificate is about "
            "the exact gain (report parameters.exact)",
            UserWarning,
            stacklevel=3,
        )
        return
    # no word on the certificate itself: with verify=False the report's claims are taken as
    # stored, and a tampered unstable gain was said to be certified (tamper review 45)
    raise InconclusiveError(
        f"{where}: the observer matrix in doubles (A − LC rounded) is not "
        f"{'Schur' if discrete else 'Hurwitz'}: no observer is offered (a report's "
        "certificate is about the exact gain, parameters.exact, which an ill-conditioned "
        "observer's doubles can lose; obsdesign verify checks whether the report's claims hold)"
    )


#: why a method's observer is not offered as a python-control system
_NOT_LINEAR = (
    "method '{method}': its observer is not linear (constrained: projection onto X̂; "
    "impulsive: sampled and hybrid; search-space: set-valued) and is not offered as a "
    "python-control system; observers are offered for {linear}"
)


def _setinvariant_nonlinear(
    ct: Any,
    sp: Any,
    params: Any,
    law: str,
    A: Any,
    B: Any,
    C: Any,
    D: Any,
    dt: Any,
    inputs: list[str],
    outputs: list[str],
    name: str,
) -> Any:
    """set-invariant's piecewise-affine injection (eq. (12) interpolated, eq. (10)
    time-varying) as a discrete-time ``control.NonlinearIOSystem``: x̂⁺ = A x̂ + B u − v(z),
    z = y − C x̂ − D u (k = t / dt for the time-varying law)."""
    from obsdesign.methods.setinvariant.sim import make_law

    f = make_law(sp, params, law)
    m = B.shape[1]
    step = float(dt) if dt not in (True, 0) else 1.0

    def update(t: float, x: np.ndarray, w: np.ndarray, prm: Any) -> np.ndarray:
        u, y = w[:m], w[m:]
        z = y - C @ x - D @ u
        return A @ x + B @ u - np.asarray(f(float(z[0]), int(round(t / step))), float)

    return ct.nlsys(
        update,
        lambda t, x, w, prm: x,
        states=outputs,
        inputs=inputs,
        outputs=outputs,
        dt=dt if dt is not None else True,
        name=name,
    )


# -- MATLAB .mat → spec ------------------------------------------------------------------------
#: variable names (lower case, without "_") that :func:`spec_text_from_mat` reads as a
#: sample time the user did not choose
_SAMPLE_TIME_NAMES = frozenset({"ts", "dt", "tsample", "sampletime", "samplingtime"})


#: MATLAB classes whose memory the declared shape bounds (others, a cell or a struct, hold
#: arrays of any size behind a 1×1 shape)
MAT_BOUNDED_CLASSES = frozenset(
    ("double", "single", "logical", "char", "sparse")
    + tuple(f"{s}int{b}" for s in ("", "u") for b in (8, 16, 32, 64))
)


def spec_text_from_mat(
    path: str | Path,
    names: Mapping[str, str | None],
    method: str = "lyapunov",
    dt: float | Decimal | None = None,
    dt_name: str | None = None,
) -> str:
    """Spec text from the matrices of a MATLAB ``.mat`` file: ``names`` maps ``A``, ``B``,
    ``C``, ``D``, ``Bd`` to variable names in the file (``None``: absent). The sample time is
    ``dt`` or the scalar variable ``dt_name`` (0: continuous time; neither: continuous time,
    refused when the file holds a scalar named like a sample time, e.g. ``Ts``)."""
    from scipy.io import loadmat, whosmat

    from obsdesign.limits import limits, read_input

    if dt is not None and dt_name is not None:  # --dt was ignored (outsider trial, session 26)
        raise InputError(f"{path}: give the sample time by --dt or by --dt-var, not both")

    read_input(path, "MATLAB")  # a regular file within the size limit
    wanted = [v for v in (*names.values(), dt_name) if v is not None]
    try:
        # the declared shapes first, and only the named variables loaded: a 7.5 MB file of
        # compressed zeros inflated to 11 GB before any check (hostile-input trial, session 24)
        info = whosmat(str(path))
        shapes = {name: shape for name, shape, _ in info}
        kinds = {name: kind for name, _, kind in info}
        names_seen = [name for name, _, _ in info]
        twice = next((v for v in names_seen if names_seen.count(v) > 1), None)
        if twice is not None:
            # any name: a file that holds Ts twice was read by its last copy (re-check, 38)
            # the dicts keep the last copy (1×1) while loadmat inflates every one: 498 KB to
            # 1.7 GB before "shapes do not fit" (re-check trial, session 38)
            raise InputError(f"{path}: variable '{twice}' appears more than once in the file")
        for key, v in (*names.items(), ("the sample time", dt_name)):
            if v is None or v not in shapes:
                continue
            if kinds[v] not in MAT_BOUNDED_CLASSES:
                # a 1×1 cell or struct passed the shape check and loadmat inflated what it
                # holds: 1.1 MB to 1.4 GB (hostile-input trial, session 38)
                raise InputError(
                    f"{path}: variable '{v}' ({key}) is a MATLAB {kinds[v]}, not a numeric matrix"
                )
            size = int(np.prod(shapes[v], dtype=object))
            if size > limits().max_values or max(shapes[v], default=0) > limits().max_states:
                raise InputError(
                    f"{path}: variable '{v}' ({key}) is {'×'.join(map(str, shapes[v]))}, above "
                    f"{limits().max_states} states or {limits().max_values:,} values "
                    "(--limit max_states / max_values)"
                )
        data = loadmat(str(path), variable_names=[v for v in wanted if v in shapes])
    except InputError:
        raise
    except Exception as e:  # noqa: BLE001 - scipy raises several kinds on a bad file
        raise InputError(f"{path}: not a readable .mat file ({type(e).__name__}: {e})") from None

    def var(key: str) -> np.ndarray | None:
        v = names.get(key)
        if v is None:
            return None
        if v not in data:
            known = ", ".join(sorted(k for k in shapes if not k.startswith("__")))
            raise InputError(f"{path}: no variable '{v}' for {key} (variables: {known})")
        raw = data[v]
        if hasattr(raw, "toarray"):
            # a MATLAB sparse matrix (loadmat gives a scipy.sparse one; np.asarray made a
            # 0-d object array, refused as "not a real numeric matrix" although the docs
            # accept sparse: interop trial, session 39); its size is bounded above
            raw = raw.toarray()
        arr = np.asarray(raw)
        if arr.dtype.kind == "c":
            if np.any(arr.imag != 0):
                raise InputError(
                    f"{path}: variable '{v}' ({key}) is complex, with a nonzero imaginary part"
                )
            arr = arr.real.copy()
        if arr.dtype.kind not in "fiu":
            raise InputError(f"{path}: variable '{v}' ({key}) is not a real numeric matrix")
        if arr.ndim > 2:
            raise InputError(f"{path}: variable '{v}' ({key}) has {arr.ndim} dimensions, not 2")
        if arr.dtype.kind == "f" and not np.all(np.isfinite(arr)):
            raise InputError(f"{path}: variable '{v}' ({key}) has a non-finite entry (inf or nan)")
        return arr

    A, C = var("A"), var("C")
    if A is None or C is None:
        raise InputError("--A and --C are required")
    if C.size == 0 and A.size:  # printed "C = []", which no spec accepts (session 28)
        raise InputError(
            f"{path}: variable '{names['C']}' (C) is {'×'.join(map(str, C.shape))}: a plant "
            "needs at least one output"
        )
    n = A.shape[0]
    B, D, Bd = var("B"), var("D"), var("Bd")
    if Bd is not None and Bd.size == 0:
        Bd = None  # no disturbance input: "Bd = [[], []]" was refused by the loader
    if dt is None and dt_name is None:
        # no time given: continuous. A discrete plant exported with its Ts became a
        # continuous-time spec without a word, every claim certified about another system
        # (outsider trial, session 29): a scalar named like a sample time asks for a choice
        ts = [
            k
            for k, shape in shapes.items()
            if k.lower().replace("_", "") in _SAMPLE_TIME_NAMES and int(np.prod(shape)) == 1
        ]
        if ts:
            raise InputError(
                f"{path}: the file holds '{ts[0]}', which reads as a sample time: give "
                f"--dt-var {ts[0]} for discrete time, or --dt 0 for continuous time (without "
                "--dt the spec is continuous time)"
            )
    given = "--dt"
    unspecified = dt == -1  # MATLAB's Ts = -1: discrete time, the sample time not given
    if dt is not None and not unspecified and not (math.isfinite(dt) and dt >= 0):
        raise InputError(
            f"--dt {dt!r}: expected a finite number >= 0 (0: continuous time), or -1 (discrete "
            "time with no sample time, as MATLAB's Ts = -1)"
        )
    if dt_name is not None:
        given = f"{path}: variable '{dt_name}' (the sample time)"
        t = data.get(dt_name)
        if t is None:
            raise InputError(f"{path}: no variable '{dt_name}' for the sample time")
        if hasattr(t, "toarray"):  # sparse, as the matrices (re-check trial, session 39)
            t = t.toarray()
        t = np.asarray(t)
        if t.dtype.kind == "c" and t.size == 1 and not np.any(t.imag != 0):
            t = t.real.copy()
        if t.dtype.kind not in "fiu" or t.size != 1:
            raise InputError(
                f"{path}: variable '{dt_name}' (the sample time) is not a real numeric scalar"
            )
        dt = float(t.reshape(-1)[0])
        # MATLAB writes Ts = -1 for a discrete-time system whose sample time is not given
        # (it was refused as "expected a finite number >= 0"; interop trial, session 39)
        unspecified = dt == -1
        if not unspecified and not (np.isfinite(dt) and dt >= 0):
            raise InputError(
                f"{path}: variable '{dt_name}' (the sample time) is {dt:g}; expected a finite "
                "number >= 0 (0: continuous time), or -1 (discrete time with no sample time)"
            )
    if dt is not None and 0 < dt < np.finfo(float).tiny:
        # written as sample_time = 5e-324, then refused by the spec loader (session 28)
        raise InputError(
            f"{given} is {_num(dt)}, a nonzero number below the float range (subnormal), which a "
            "spec refuses: rescale time"
        )
    # D without B: the inputs enter y only (the spec had D with no input and was refused)
    Bm = B if B is not None else np.zeros((n, 0 if D is None else np.atleast_2d(D).shape[-1]))
    Dm = D if D is not None else np.zeros((C.shape[0], 0))
    try:
        text = spec_text_from_statespace(
            (A, Bm, C, Dm, True if unspecified else (dt if dt else 0)),
            method,
            Bd=Bd,
            title=f"imported from {Path(path).name}",
        )
    except InputError as e:  # e.g. shapes that do not fit: name the file
        raise InputError(f"{path}: {e}") from None
    from obsdesign.api import load_spec_text

    try:  # what import prints, the spec loader accepts (session 28: C = [] exit 0, then 2)
        load_spec_text(text, f"{Path(path).name} (imported)")
    except SpecError as e:
        if e.key.startswith("method.") and e.expected.startswith("is missing"):
            # import writes [method] key only: for a method whose [method] table has
            # required keys it could never print a spec, while --help said to add the
            # options to the printed table (soundness trial, session 30)
            raise InputError(
                f"{path}: --method {method} needs [{e.key}] (and the method's other required "
                "keys), which import does not write: start from `obsdesign init "
                f"{method}` and put the matrices in its [system] table, or call "
                f'obsdesign.spec_from_statespace(sys, method="{method}", ...) with them'
            ) from None
        raise InputError(f"{path}: the imported spec would be refused: {e}") from None
    except InputError as e:
        raise InputError(f"{path}: the imported spec would be refused: {e}") from None
    return text
