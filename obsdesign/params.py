"""Design parameters: exact values where certified, floats otherwise, and their JSON form.

In a report, ``parameters`` maps each of the paper's symbols to a float (a matrix is a list of
rows of floats); the exact form sits beside it under ``parameters["exact"]`` as strings like
``"-187/100"``. Reading a report back, the exact strings are what the checks use, and
:meth:`Parameters.from_json` says whether each float still matches its exact value (an
edited float is caught there).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import qparse_floats, qstr, qstr_floats, to_float
from obsdesign.errors import InputError


def _is_exact(v: Any) -> bool:
    if isinstance(v, fmpq):
        return True
    return (
        isinstance(v, np.ndarray)
        and v.dtype == object
        and v.size > 0
        and isinstance(v.flat[0], fmpq)
    )


def _floats(v: Any) -> Any:
    if isinstance(v, fmpq):
        return float(to_float(v))
    if isinstance(v, np.ndarray):
        arr = np.asarray(to_float(v), dtype=float) if v.dtype == object else v.astype(float)
        return arr.tolist()
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    if isinstance(v, (list, tuple)):
        return [_floats(x) for x in v]
    return v


class Parameters(Mapping[str, Any]):
    """Ordered mapping symbol → value (fmpq / exact object array / float / ndarray / misc):
    a read-only ``collections.abc.Mapping`` (``len``, ``keys``, ``values``, ``dict(p)``; it
    said "mapping" but had none of these: outsider trial, session 22) with item assignment."""

    def __init__(self, values: dict[str, Any] | None = None) -> None:
        self._v: dict[str, Any] = dict(values or {})
        #: float forms (:meth:`float_json`) already made, by key (``from_json`` makes them
        #: for its consistency check); dropped when the key is set again
        self._fj: dict[str, Any] = {}

    def __getitem__(self, k: str) -> Any:
        return self._v[k]

    def __setitem__(self, k: str, v: Any) -> None:
        self._v[k] = v
        self._fj.pop(k, None)

    def __contains__(self, k: object) -> bool:
        return k in self._v

    def __iter__(self) -> Iterator[str]:
        return iter(self._v)

    def __len__(self) -> int:
        return len(self._v)

    # identity, as before it was a Mapping: Mapping's value equality would compare numpy
    # arrays (ambiguous truth value) and make the object unhashable
    __eq__ = object.__eq__
    __hash__ = object.__hash__

    def get(self, k: str, default: Any = None) -> Any:
        return self._v.get(k, default)

    def items(self) -> Any:
        return self._v.items()

    def float(self, k: str) -> Any:
        """Float view of a parameter (numpy array for arrays)."""
        v = self._v[k]
        f = _floats(v)
        return np.asarray(f, dtype=float) if isinstance(f, list) else f

    def shaped(self, k: str, shape: tuple[int, ...]) -> np.ndarray:
        """The float view of parameter ``k`` as an array of ``shape`` (one entry may be −1:
        any number of rows), refused (:class:`InputError`, "report: …", exit 2) when its
        shape is another: a vector (or a scalar) stands for a shape with one dimension above
        1. A 2×3 L in a report for a 3×2 gain was reshaped row-major into another matrix and
        simulated with exit 0 (re-check trial, session 28)."""
        a = np.asarray(self.float(k), dtype=float)
        want = tuple(int(d) for d in shape)
        if -1 in want:
            cols = want[1]
            ok = cols > 0 and (
                (a.ndim == 2 and a.shape[1] == cols) or (a.ndim == 1 and a.size == cols)
            )
            target = (-1, cols)
        else:
            size = int(np.prod(want, dtype=np.int64)) if want else 1
            vector = sum(d != 1 for d in want) <= 1
            ok = a.shape == want or (a.ndim <= 1 and a.size == size and vector)
            if not ok and vector and a.size == size:  # a column for a row and so on
                ok = sum(d != 1 for d in a.shape) <= 1
            target = want
        if not ok:
            got = "×".join(map(str, a.shape)) or "a number"
            exp = "×".join("N" if d == -1 else str(d) for d in want) or "a number"
            raise InputError(f"report: parameters.{k} has shape {got}, expected {exp}")
        return a.reshape(target)

    def float_json(self, k: str) -> Any:
        """The float form ``to_json`` writes for parameter ``k`` (lists for arrays; a fresh
        copy, the caller may change it)."""
        if k in self._fj:
            return _copy_rows(self._fj[k])
        return _floats(self._v[k])

    def is_exact(self, k: str) -> bool:
        return _is_exact(self._v.get(k))

    def exact(self, k: str, claims: list[Any], accept_float: bool = False) -> Any:
        """The exact value of parameter ``k`` for a certificate, or None after appending a
        failed claim saying why (missing; or float-only, ``<k>-exact``, unless
        ``accept_float``: a report carries every certified parameter exactly, and the exact
        value is authoritative, so a report whose exact value was removed is not certified
        on its float by any method; before, constrained, lyapunov and stubborn took the
        float's binary value while impulsive refused it). A float-only value, when accepted
        (a simulation), is taken at its exact binary value."""
        return exact_param(self, k, claims, accept_float)

    def require(self, keys: tuple[str, ...] | list[str], claims: list[Any]) -> bool:
        """True when every key is present; else one failed claim per missing key."""
        from obsdesign.certify.claim import missing_claim

        missing = [k for k in keys if k not in self._v]
        claims.extend(missing_claim(k) for k in missing)
        return not missing

    def to_json(self) -> dict[str, Any]:
        """The report's ``parameters`` object: floats, and ``exact`` strings beside them.

        A value held under two keys (the lyapunov method's P and P_best when the asked rate
        is the best one) is converted once; each key still gets its own lists."""
        out: dict[str, Any] = {}
        exact: dict[str, Any] = {}
        done: dict[int, tuple[Any, Any]] = {}  # id of an array value → (floats, exact strings)
        for k, v in self._v.items():
            hit = done.get(id(v)) if isinstance(v, np.ndarray) else None
            if hit is None:
                try:
                    both = qstr_floats(v) if _is_exact(v) and isinstance(v, np.ndarray) else None
                    if both is not None:
                        hit = (both[1], both[0])
                    else:
                        hit = (_floats(v), qstr(v) if _is_exact(v) else None)
                except OverflowError as e:
                    raise OverflowError(f"parameter '{k}': {e}") from e
                if isinstance(v, np.ndarray):
                    done[id(v)] = hit
                    out[k], ex = hit
                else:
                    out[k], ex = hit
            else:
                out[k], ex = _copy_rows(hit[0]), _copy_rows(hit[1])
            if ex is not None:
                exact[k] = ex
        out["exact"] = exact
        return out

    def shape_of(self, k: str) -> str:
        """What parameter ``k`` holds, in words for an error message: "a number", "3×1
        array", "text", "missing"."""
        if k not in self._v:
            return "missing"
        v = self._v[k]
        if isinstance(v, str):
            return "text"
        if isinstance(v, bool):
            return "a boolean"
        if isinstance(v, dict):
            return "an object"
        if v is None:
            return "null"
        try:
            shape = np.shape(v)
        except ValueError:  # ragged lists
            return "a ragged list"
        return "a number" if shape == () else "×".join(map(str, shape)) + " array"

    def traced(self, finite: bool = False) -> ReadTrace:
        """A copy that records the keys read, in order (:class:`ReadTrace`)."""
        t = ReadTrace(self._v, finite)
        t._fj = dict(self._fj)
        return t

    @classmethod
    def from_json(cls, d: dict[str, Any], file: str = "report") -> tuple[Parameters, list[str]]:
        """Parameters from a report's ``parameters`` object, and a list of inconsistencies
        (a float that no longer matches its exact value); ``file`` names the report in
        error messages."""
        if not isinstance(d, dict):
            raise InputError(f"{file}: 'parameters' must be an object")
        exact = d.get("exact", {})
        if not isinstance(exact, dict):
            raise InputError(f"{file}: 'parameters.exact' must be an object")
        vals: dict[str, Any] = {}
        problems: list[str] = []
        # exact lists already parsed, with their float lists and verdict: a value written
        # under two keys (P and P_best) is parsed once, each key getting its own copy
        parsed: list[tuple[list[Any], Any, Any, bool, Any]] = []
        fj: dict[str, Any] = {}
        for k, v in d.items():
            if k == "exact":
                continue
            if k in exact:
                ek = exact[k]
                hit = None
                if isinstance(ek, list):
                    hit = next((h for h in parsed if h[0] == ek and h[1] == v), None)
                if hit is not None:
                    q, same, fl = hit[2].copy(), hit[3], hit[4]
                else:
                    try:
                        q, fl = qparse_floats(ek)
                    except (ValueError, TypeError, ZeroDivisionError) as e:
                        why = str(e).removeprefix("not an exact value: ")
                        raise InputError(
                            f"{file}: parameters.exact.{k}: not an exact value ({why})"
                        ) from e
                    except OverflowError:
                        # no report carries one (its float view would be infinite: the design
                        # stops with exit 4); a hand-edited 10⁴⁰⁰ was an internal failure
                        raise InputError(
                            f"{file}: parameters.exact.{k}: an exact value beyond the float "
                            "range (magnitude above 1.8e308), which a report cannot carry"
                        ) from None
                    same = _same(fl, v)
                    if isinstance(ek, list):
                        parsed.append((ek, v, q, same, fl))
                vals[k] = q
                fj[k] = fl
                if not same:
                    problems.append(f"parameter '{k}': float value differs from its exact value")
            else:
                vals[k] = np.asarray(v, dtype=float) if _numeric_list(v) else v
        for k in exact:
            if k not in d:
                problems.append(f"parameter '{k}': exact value without a float value")
        out = cls(vals)
        out._fj = fj
        return out, problems


def _copy_rows(x: Any) -> Any:
    """A copy of nested lists (the leaves shared: numbers and strings are immutable)."""
    if not isinstance(x, list):
        return x
    if any(issubclass(t, list) for t in set(map(type, x))):  # the kinds, not the entries
        return [_copy_rows(v) for v in x]
    return x[:]  # a row of leaves: one C-level copy


def _numeric_list(v: Any) -> bool:
    if not isinstance(v, list):
        return False
    try:
        np.asarray(v, dtype=float)
        return True
    except (TypeError, ValueError):
        return False


def same_bits(a: Any, b: Any) -> bool:
    """Whether two float forms (numbers, nested lists) are the same doubles entry by entry,
    bit for bit: equal values with the same sign (−0.0 is not the nearest double to an exact
    0, which is +0.0; ``verify`` took it: rendering trial, session 29); booleans, strings and
    ragged lists are never equal to numbers; vectorized for rectangular arrays of plain
    numbers."""
    if isinstance(a, list) and isinstance(b, list):
        fa, fb = _plain_array(a), _plain_array(b)
        if fa is not None and fb is not None:
            return (
                fa.shape == fb.shape
                and bool(np.array_equal(fa, fb))
                and bool(np.array_equal(np.signbit(fa), np.signbit(fb)))
            )
        return len(a) == len(b) and all(same_bits(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, list) or isinstance(b, list):
        return False
    if not isinstance(a, (int, float)) or not isinstance(b, (int, float)):
        return False
    try:
        x, y = float(a), float(b)
    except OverflowError:  # a JSON integer beyond the float range is no double (report fuzz)
        return False
    return x == y and math.copysign(1.0, x) == math.copysign(1.0, y)


def _same(a: Any, b: Any) -> bool:
    """Whether the float form ``b`` read from a report still matches ``a``, the floats of its
    exact value: numbers within a relative 10⁻¹², nested lists entry by entry (vectorized for
    a rectangular array of plain numbers, the same test)."""
    if isinstance(a, list) and isinstance(b, list):
        fa, fb = _plain_array(a), _plain_array(b)
        if fa is not None and fb is not None:
            if fa.shape != fb.shape:
                return False
            tol = np.maximum(1e-12 * np.maximum(np.abs(fa), np.abs(fb)), 1e-300)
            with np.errstate(invalid="ignore", over="ignore"):
                return bool(np.all(np.abs(fa - fb) <= tol))
    if isinstance(a, list) or isinstance(b, list):
        if not (isinstance(a, list) and isinstance(b, list)) or len(a) != len(b):
            return False
        return all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, bool) or isinstance(b, bool):
        return a == b
    if not isinstance(b, (int, float)):
        return False
    try:
        return math.isclose(float(a), float(b), rel_tol=1e-12, abs_tol=1e-300)
    except OverflowError:  # a JSON integer beyond the float range (report fuzz: exit 3)
        return False


def _plain_array(x: list[Any]) -> np.ndarray | None:
    """A list (of lists) of plain ints and floats as a finite float array, None for anything
    else (booleans, strings, ragged lists, non-finite values, ints beyond the float range):
    :func:`_same` then compares entry by entry."""
    shape: list[int] = []
    level: Any = x
    while isinstance(level, list):
        shape.append(len(level))
        level = level[0] if level else None
    try:
        arr = np.array(x, dtype=object)
    except ValueError:
        return None
    if arr.shape != tuple(shape):
        return None
    for v in arr.flat:
        t = type(v)
        if t is not float and t is not int:
            return None
    try:
        out = arr.astype(float)
    except OverflowError:
        return None
    return out if np.all(np.isfinite(out)) else None


def shaped(v: Any, shape: tuple[int | None, ...], key: str) -> np.ndarray:
    """A report parameter ``v`` as an object array of exactly ``shape`` (None: any length on
    that axis), else ValueError naming ``key`` (a failed ``parameters-wellformed`` claim,
    :func:`obsdesign.api.certify`). A reshape is no check: a stubborn K of 4×2 written as 2×4
    (its entries row-major) and a set-invariant G of 6×2 written as 2×6 were reshaped back
    and verified with exit 0, although the matrices as written state other claims (shape
    review, session 41).

    :param v: the value (nested lists, an array); :param shape: the expected shape;
    :param key: the parameter's name, for the message."""
    arr = np.asarray(v, dtype=object)
    if arr.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(arr.shape, shape, strict=True)
    ):
        want_s = "×".join("?" if d is None else str(d) for d in shape) or "a scalar"
        got_s = "×".join(str(d) for d in arr.shape) or "a scalar"
        raise ValueError(f"parameters.{key}: expected shape {want_s}, got {got_s}")
    return arr


def exact_param(params: Parameters, k: str, claims: list[Any], accept_float: bool = True) -> Any:
    """The exact value of parameter ``k`` for a certificate, or None after appending a failed
    claim saying why (missing; or float-only when ``accept_float`` is False). A float-only
    value, when accepted, is taken at its exact binary value."""
    from obsdesign.certify.claim import exact_claim, missing_claim
    from obsdesign.certify.exact import Q, dyadic

    if k not in params:
        claims.append(missing_claim(k))
        return None
    v = params[k]
    if _is_exact(v):
        return v
    if not accept_float:
        claims.append(
            exact_claim(
                f"{k}-exact",
                f"{k} is given exactly",
                "report",
                "presence of the exact value",
                0,
                False,
                f"{k} has no exact value in the report",
            )
        )
        return None
    arr = np.asarray(v, dtype=float)
    return Q(float(arr)) if arr.ndim == 0 else dyadic(arr, 60)


class ReadTrace(Parameters):
    """Parameters that record which keys were read, in order (``read``; iterating or
    ``items()`` reads every key). ``verify`` names the parameters no check read ("not
    verified"); ``simulate --report`` names the parameters read before a wrong-shape failure,
    where numpy's "cannot reshape array of size 6 into shape (2,1)" named none (session 27's
    note), and with ``finite`` refuses a float view holding inf or nan: a report's
    L = [[inf], [1]] with its exact value removed was simulated with exit 0 and nan metrics;
    no design writes a non-finite value that a simulation reads (session 28)."""

    def __init__(self, values: dict[str, Any] | None = None, finite: bool = False) -> None:
        super().__init__(values)
        #: keys read, in order
        self.read: list[str] = []
        self.finite = finite

    def __getitem__(self, k: str) -> Any:
        self.read.append(k)
        return super().__getitem__(k)

    def get(self, k: str, default: Any = None) -> Any:
        self.read.append(k)
        return super().get(k, default)

    def float(self, k: str) -> Any:
        """The float view; with ``finite``, refused (exit 2, naming the key) when a number in
        it is not finite."""
        self.read.append(k)
        f = super().float(k)
        a = np.asarray(f) if self.finite and isinstance(f, (np.ndarray, float)) else None
        if a is not None and a.dtype.kind == "f" and not np.isfinite(a).all():
            bad = a.ravel()[~np.isfinite(a.ravel())][0]
            raise InputError(f"report: parameters.{k}: a value is not a finite number ({bad})")
        return f

    def is_exact(self, k: str) -> bool:
        self.read.append(k)
        return super().is_exact(k)

    def exact(self, k: str, claims: list[Any], accept_float: bool = False) -> Any:
        self.read.append(k)
        return super().exact(k, claims, accept_float)

    def items(self) -> Any:
        self.read.extend(self._v)
        return super().items()

    def __iter__(self) -> Iterator[str]:
        self.read.extend(self._v)
        return super().__iter__()
