"""Typed access to a TOML table, with errors that name the file and the key.

Numbers arrive as ``decimal.Decimal`` (TOML floats, parsed with ``parse_float=Decimal``) or
``int``; :class:`Value` keeps both the exact rational form (``.q``, for certification) and
float64 (``.f``, for solvers). So ``0.1`` in a spec is exactly 1/10.
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, to_float
from obsdesign.errors import SpecError
from obsdesign.limits import INT_MAX, decimal_problem, int_problem

_MISSING: Any = object()


@dataclass(frozen=True)
class Value:
    """A number, vector or matrix from a spec: exact (``q``: fmpq or object array) and float."""

    q: Any
    f: Any

    def __post_init__(self) -> None:
        # read-only: designs keep results for the spec's data (the lyapunov memo, caches),
        # and a report embeds the spec's text; an array edited in place after loading made
        # api.certify certify claims about A that were false for the edited A (API review,
        # session 42). Edit the text and load it again instead.
        for a in (self.q, self.f):
            while isinstance(a, np.ndarray):  # the array and every array it views: a
                a.flags.writeable = False  # write through ``.base`` edited A as well
                a = a.base

    def __reduce__(self) -> tuple[Any, tuple[Any, Any]]:
        # copies (copy.deepcopy, pickle) are made through __init__, so read-only as well
        return (Value, (self.q, self.f))

    @classmethod
    def of(cls, q: Any) -> Value:
        if isinstance(q, fmpq):
            return cls(q, float(to_float(q)))
        # a copy: the Value is read-only, and the caller's own array was frozen in place
        # with it (re-check review, session 43)
        arr = np.array(q, dtype=object)
        if not all(isinstance(v, fmpq) for v in arr.flat):
            # floats and ints as their exact values: Python floats kept as the "exact" part
            # were a bare TypeError in three methods (API review, session 43)
            arr = np.array([Q(v) for v in arr.flat], dtype=object).reshape(arr.shape)
        return cls(arr, np.asarray(to_float(arr), dtype=float).reshape(arr.shape))

    @property
    def shape(self) -> tuple[int, ...]:
        return np.shape(self.f)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, Decimal)) and not isinstance(v, bool)


class Table:
    """A TOML table with its file name and key path; getters validate and convert."""

    def __init__(
        self,
        data: dict[str, Any],
        file: str,
        path: str = "",
        checked: bool = False,
        parent: Table | None = None,
    ) -> None:
        """:param data: the table's parsed TOML; :param file: for messages; :param path: the
        key path; :param checked: every number in ``data`` has passed
        :func:`obsdesign.limits.data_problem` (the loader's walk): the getters then skip the
        per-number size check before the exact conversion (it would repeat the walk's);
        :param parent: the table this one was read from (for the hint of a missing key)."""
        self.data = data
        self.file = file
        self.path = path
        self.checked = checked
        self.parent = parent
        self._used: set[str] = set()

    # -- plumbing ---------------------------------------------------------------------------
    def key(self, k: str) -> str:
        return f"{self.path}.{k}" if self.path else k

    def error(self, k: str, expected: str) -> SpecError:
        return SpecError(self.file, self.key(k) if k else self.path, expected)

    def has(self, k: str) -> bool:
        return k in self.data

    def mark(self, *keys: str) -> None:
        self._used.update(keys)

    def _get(self, k: str, default: Any) -> Any:
        self._used.add(k)
        if k in self.data:
            return self.data[k]
        if default is _MISSING:
            import difflib

            close = difflib.get_close_matches(k, sorted(set(self.data) - self._used), n=1)
            hint = f" (is '{close[0]}' a misspelling of it?)" if close else ""
            if not close:
                hint = self._in_misspelt_sibling(k)
            raise self.error(k, f"is missing{hint}")
        return default

    def _in_misspelt_sibling(self, k: str) -> str:
        """The hint for a key missing here that a sibling table with a close name holds:
        ``[simulte]`` beside a ``[simulate.noise]`` subtable was reported as
        "[simulate.horizon] is missing" without naming the typo (docs trial, session 31)."""
        import difflib

        if self.parent is None or not self.path:
            return ""
        name = self.path.rsplit(".", 1)[-1]
        holders = [
            s for s, v in self.parent.data.items() if s != name and isinstance(v, dict) and k in v
        ]
        close = difflib.get_close_matches(name, sorted(holders), n=1)
        if not close:
            return ""
        return (
            f" (it is in [{self.parent.key(close[0])}]: is '{close[0]}' a misspelling of '{name}'?)"
        )

    def done(self, allowed_extra: tuple[str, ...] = ()) -> None:
        """Reject keys nobody read: a typo must not be silently ignored."""
        unknown = sorted(set(self.data) - self._used - set(allowed_extra))
        if unknown:
            import difflib

            # a key the table also holds is a hint too: sweep's --set method.lambdaa=… beside
            # the spec's lambda had no "did you mean" (docs trial, session 31)
            known = sorted(self._used | set(allowed_extra))
            # a key that differs only in case first ([method.d] for [method.D] had no hint:
            # re-check trial, session 32)
            close = [k for k in known if k.lower() == unknown[0].lower()] or (
                difflib.get_close_matches(unknown[0], known, n=1, cutoff=0.6)
            )
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            odd = _non_ascii(unknown[0])
            if odd:
                # "lambdа" with a Cyrillic а printed like "lambda" (hostile-input trial, 38)
                hint += f"; it holds non-ASCII characters: {odd}"
            raise self.error(unknown[0], f"is not a known key here{hint}")

    # -- tables -----------------------------------------------------------------------------
    def table(self, k: str, required: bool = False) -> Table | None:
        v = self._get(k, _MISSING if required else None)
        if v is None:
            return None
        if not isinstance(v, dict):
            raise self.error(k, "expected a table")
        return Table(v, self.file, self.key(k), self.checked, self)

    def tables(self, k: str) -> dict[str, Table]:
        t = self.table(k)
        if t is None:
            return {}
        out = {}
        for name, v in t.data.items():
            if not isinstance(v, dict):
                raise t.error(name, "expected a table")
            t.mark(name)
            out[name] = Table(v, self.file, t.key(name), self.checked, t)
        return out

    # -- scalars ----------------------------------------------------------------------------
    def str(self, k: str, default: Any = _MISSING, choices: tuple[str, ...] | None = None) -> Any:
        v = self._get(k, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, str):
            raise self.error(k, f"expected a string, got {_tname(v)}")
        if choices is not None and v not in choices:
            raise self.error(k, f"expected one of {', '.join(choices)}; got {v!r}")
        return v

    def bool(self, k: str, default: Any = _MISSING) -> Any:
        v = self._get(k, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, bool):
            raise self.error(k, f"expected true or false, got {_tname(v)}")
        return v

    def int(self, k: str, default: Any = _MISSING, min: int | None = None) -> Any:
        v = self._get(k, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, int) or isinstance(v, bool):
            raise self.error(k, f"expected an integer, got {_tname(v)}")
        if min is not None and v < min:
            raise self.error(k, f"expected an integer >= {min}, got {v}")
        if k != "seed" and abs(v) > INT_MAX:  # numpy takes a seed of any size
            # runs = 10**400 reached a float conversion (exit 3), a discrete horizon of 400
            # digits exit 4 naming no key (CLI review, session 44)
            raise self.error(k, f"expected an integer of at most 2^63 − 1, got {v}")
        return v

    def scalar(
        self,
        k: str,
        default: Any = _MISSING,
        min: Any = None,
        max: Any = None,
        strict_min: bool = False,
        strict_max: bool = False,
    ) -> Any:
        """A finite number as :class:`Value`; bounds are checked exactly."""
        v = self._get(k, default)
        if v is default and default is not _MISSING:
            return v if (v is None or isinstance(v, Value)) else Value.of(Q(v))
        q = self._number(k, v)
        if min is not None and (q <= Q(min) if strict_min else q < Q(min)):
            raise self.error(
                k, f"expected a number {'>' if strict_min else '>='} {min}, got {_show(v)}"
            )
        if max is not None and (q >= Q(max) if strict_max else q > Q(max)):
            raise self.error(
                k, f"expected a number {'<' if strict_max else '<='} {max}, got {_show(v)}"
            )
        return self._value(k, q)

    def _number(self, k: str, v: Any) -> fmpq:
        if type(v) is Decimal and self.checked and v.is_finite():
            return fmpq(*v.as_integer_ratio())  # the common case, as below without the tests
        if not _is_number(v):
            raise self.error(k, f"expected a number, got {_tname(v)}")
        if isinstance(v, Decimal) and not v.is_finite():
            raise self.error(k, f"expected a finite number, got {v}")
        if self.checked:  # the loader's walk checked every number of the spec already
            why = None
        else:
            why = decimal_problem(v) if isinstance(v, Decimal) else int_problem(v)
        if why:  # checked before the conversion to a rational (which could take forever)
            raise self.error(k, why)
        return Q(v)

    # -- arrays -----------------------------------------------------------------------------
    def vector(self, k: str, n: int | None = None, default: Any = _MISSING) -> Any:
        """A list of numbers (a scalar is accepted when n == 1)."""
        v = self._get(k, default)
        if v is default and default is not _MISSING:
            return v
        if _is_number(v) and (n is None or n == 1):
            v = [v]
        if not isinstance(v, list) or not v or any(isinstance(x, list) for x in v):
            raise self.error(k, f"expected a non-empty list of numbers{_len(n)}")
        if n is not None and len(v) != n:
            raise self.error(k, f"expected {n} number{'' if n == 1 else 's'}, got {len(v)}")
        return self._value(k, np.array([self._number(k, x) for x in v], dtype=object))

    def matrix(
        self,
        k: str,
        rows: int | None = None,
        cols: int | None = None,
        default: Any = _MISSING,
        vector_as: str = "row",
    ) -> Any:
        """A list of rows. A flat list is one row (``vector_as='row'``) or one column."""
        v = self._get(k, default)
        if v is default and default is not _MISSING:
            return v
        if _is_number(v):
            v = [[v]]
        flat = isinstance(v, list) and bool(v) and all(_is_number(x) for x in v)
        if flat:
            v = [v] if vector_as == "row" else [[x] for x in v]
        if not isinstance(v, list) or not v or not all(isinstance(r, list) and r for r in v):
            empty = isinstance(v, list) and all(isinstance(r, list) and not r for r in v)
            # B = [] or [[], []] for a plant without inputs said only "of shape 2×?" (edge-
            # shape trial, session 26): an empty matrix is no matrix, omit the key
            hint = (
                "; [] and [[], ...] are not matrices (a plant without inputs or disturbances "
                "leaves B, D or Bd out)"
                if empty
                else ""
            )
            if empty and k == "Dn":
                # leaving Dn out is the identity, one noise per output, not "no noise"
                # (lyapunov trial, session 39)
                hint = (
                    "; [] and [[], ...] are not matrices (left out, Dn is the identity: one "
                    "noise per output; an output without noise writes its row of Dn as zeros)"
                )
            raise self.error(
                k, f"expected a matrix (a list of rows of numbers){_shape(rows, cols)}{hint}"
            )
        widths = {len(r) for r in v}
        if len(widths) != 1:
            raise self.error(k, "expected rows of equal length")
        fast = _checked_rows(v) if self.checked else None
        if fast is not None:
            arr = np.empty(len(v) * len(v[0]), dtype=object)
            arr[:] = fast[0]
            arr = arr.reshape(len(v), len(v[0]))
            self._shape(k, arr.shape, rows, cols, flat, vector_as)
            val = Value(arr, np.array(fast[1], dtype=float).reshape(arr.shape))
            self._no_underflow(k, val)
            return val
        arr = np.empty((len(v), len(v[0])), dtype=object)
        for i, r in enumerate(v):
            for j, x in enumerate(r):
                if isinstance(x, list):
                    raise self.error(k, "expected a matrix of numbers (nested too deep)")
                arr[i, j] = self._number(k, x)
        self._shape(k, arr.shape, rows, cols, flat, vector_as)
        return self._value(k, arr)

    def _shape(
        self,
        k: str,
        shape: tuple[int, ...],
        rows: int | None,
        cols: int | None,
        flat: bool,
        vector_as: str,
    ) -> None:
        """Refuse a matrix of another shape than rows×cols (None: any), naming ``k``. A flat
        list read as a column where a row fits (or the reverse) says how to write it: L = [1,
        0.5] for n = 1, p = 2 said only "expected shape 1×2, got 2×1" (lyapunov review,
        session 41)."""
        if (rows is None or shape[0] == rows) and (cols is None or shape[1] == cols):
            return
        hint = ""
        if flat and (rows is None or shape[1] == rows) and (cols is None or shape[0] == cols):
            hint = f" (a flat list is read as one {vector_as}: write " + (
                "[[a], [b], ...] for a column)"
                if vector_as == "row"
                else "[[a, b, ...]] for a row)"
            )
        raise self.error(
            k, f"expected shape {_dim(rows)}×{_dim(cols)}, got {shape[0]}×{shape[1]}{hint}"
        )

    def _value(self, k: str, q: Any) -> Value:
        """:meth:`Value.of`, with a number beyond the float range (|x| ≥ 2^1024 after
        rounding) as bad input naming the key: the design computes in floats too."""
        try:
            val = Value.of(q)
        except OverflowError:
            raise self.error(
                k, "has a number beyond the float range (magnitude above 1.8e308)"
            ) from None
        self._no_underflow(k, val)
        return val

    def _no_underflow(self, k: str, val: Value) -> None:
        """A nonzero number below the normal float range (|x| < 2.2e-308) is bad input naming
        the key, as one above it is: the design computes in floats too, where it becomes 0 or
        loses its digits (rate_tol = 1e-400 ended in exit 4 'the spec's numbers are too
        large', C = 1e-400 in a singular-matrix error, exit 3: CLI fuzzer)."""
        f = np.abs(np.asarray(val.f, dtype=float))
        if not np.any(f < _TINY):
            return
        q = np.asarray(val.q, dtype=object).reshape(f.shape)
        if any(q.flat[i] != 0 for i in np.flatnonzero(f < _TINY)):
            raise self.error(
                k,
                "has a nonzero number below the float range (magnitude under 2.2e-308, which "
                "floats round to 0 or to few digits)",
            )


#: the smallest normal float64
_TINY = float(np.finfo(float).tiny)


def _checked_rows(rows: list[list[Any]]) -> tuple[list[fmpq], list[float]] | None:
    """The exact values and their correctly rounded floats of rows of numbers the loader's
    walk already checked, in one pass over Python ints (``Decimal.as_integer_ratio``; int /
    int true division is correctly rounded, as :func:`to_float` is): about half the cost of
    :meth:`Table._number` then :meth:`Value.of` at the 10⁴ entries of a 100-state A. None
    when anything is not a finite Decimal or a plain int (the general path then decides and
    names the problem)."""
    qs: list[fmpq] = []
    fs: list[float] = []
    qa, fa = qs.append, fs.append
    try:
        for r in rows:
            for x in r:
                t = type(x)
                if t is Decimal:
                    p, q = x.as_integer_ratio()  # ValueError / OverflowError: not finite
                elif t is int:
                    p, q = x, 1
                else:
                    return None
                qa(fmpq(p, q))
                fa(p / q)  # OverflowError beyond the float range: the general path
    except (ValueError, OverflowError, TypeError):
        return None
    return qs, fs


def _tname(v: Any) -> str:
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, (int, Decimal)):
        return f"the number {_show(v)}"
    if isinstance(v, str):
        return f"the string {v!r}"
    if isinstance(v, list):
        return "a list"
    if isinstance(v, dict):
        return "a table"
    return type(v).__name__


def _show(v: Any) -> str:
    return str(v)


def _len(n: int | None) -> str:
    return f" of length {n}" if n is not None else ""


def _dim(d: int | None) -> str:
    return "?" if d is None else str(d)


def _shape(r: int | None, c: int | None) -> str:
    return "" if r is None and c is None else f" of shape {_dim(r)}×{_dim(c)}"


def _non_ascii(key: str) -> str:
    """The non-ASCII characters of ``key`` by code point and name (a Cyrillic 'а' in a key
    looks like the Latin 'a' in a message), or ''."""
    import unicodedata

    seen = dict.fromkeys(ch for ch in key if ord(ch) > 127)
    return ", ".join(f"U+{ord(ch):04X} {unicodedata.name(ch, 'unnamed')}" for ch in list(seen)[:5])
