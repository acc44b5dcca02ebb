"""Design-space sweeps: a grid over dotted spec keys, one designed and verified spec per point.

A grid is a list of axes, each written ``KEY=VALUES`` (the ``--set`` of ``obsdesign
sweep``), KEY a dotted spec key (``method.lambda``, ``simulate.noise.bound``) and VALUES

- ``a:b:n``: ``n`` values from ``a`` to ``b`` evenly spaced (both ends included);
- ``a:b:n:log``: ``n`` values from ``a`` to ``b`` evenly spaced in log scale (``a, b > 0``);
- ``[v1, v2, ...]``: these TOML values (a bare word is a string: ``[clarabel, scs]``); to
  sweep arrays, give a list of arrays (``method.L=[[-1.87, 1.874], [-1.8, 1.9]]``);
- ``v``: one value (a fixed change applied to every point).

The grid is the product of the axes (the last axis varies fastest); point ``i`` is row
``i``. Each point's spec is the spec's TOML text with the values written in place as
decimals (``0.93``, ``0.0031622776601684``: linear values exactly when they have at most 15
significant digits, log values rounded to 15), so the spec of every point is exact and
self-contained: the design certifies that text. The key's value is replaced in place (found
by the lexer of :mod:`obsdesign.spec.tomltext`; a trailing comment kept), or the key is
added to its table when absent; the edit is checked by parsing the new text and comparing
it with the old one with only that key changed.

Every point is designed, serialized, reloaded and verified (as ``obsdesign check`` does),
and simulated with ``simulate=True``. A point that fails (bad input, infeasible, solver
failure, an internal error) is a row with its exit code and message, never a lost row.
"""

from __future__ import annotations

import json
import math
import numbers
import re
import sys
import time
import tomllib
import types
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from decimal import Decimal, localcontext
from fractions import Fraction
from itertools import product
from pathlib import Path
from typing import Any

from obsdesign.errors import EXIT_BAD_INPUT, EXIT_OK, EXIT_SOLVER, InputError, ObsdesignError
from obsdesign.limits import limits
from obsdesign.spec import tomltext

#: at most this many points in one sweep (a typo such as 1:2:1000000000 is refused at once)
MAX_POINTS = 100_000
#: significant digits of the values written into the spec (linear values that need more are
#: rounded; log values always are)
DIGITS = 15
#: output formats by suffix
OUTPUT_SUFFIXES = (".csv", ".jsonl", ".parquet")
#: columns that differ between two runs of the same sweep (wall-clock times)
TIMING_COLUMNS = ("design_s", "verify_s", "simulate_s", "seconds")

_KEY_RE = re.compile(r"^[A-Za-z0-9_-]+(\.[A-Za-z0-9_-]+)*$")
_NUM = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_RANGE_RE = re.compile(rf"^({_NUM}):({_NUM}):([-+]?\d+)(?::(lin|log))?$")


# -- axes and grid --------------------------------------------------------------------------
@dataclass(frozen=True)
class Axis:
    """One swept key and its values (TOML literals, as written into the spec)."""

    key: str
    values: tuple[str, ...]


def parse_axis(text: str) -> Axis:
    """``KEY=VALUES`` (see the module docstring) as an :class:`Axis`; :class:`InputError`
    naming the ``--set`` on any mistake."""
    if "=" not in text:
        raise InputError(f"--set expects KEY=VALUES (e.g. method.lambda=0.9:0.99:10), got {text!r}")
    key, spec = (s.strip() for s in text.split("=", 1))
    if key.count(".") >= limits().max_depth:
        # 3000 parts ran past 60 s before any other check (hostile-input trial, session 24)
        raise InputError(
            f"--set: the key has {key.count('.') + 1} parts, deeper than a spec may nest "
            f"({limits().max_depth})"
        )
    if not _KEY_RE.match(key):
        raise InputError(f"--set {text!r}: {key!r} is not a dotted spec key (e.g. method.lambda)")
    if not spec:
        raise InputError(f"--set {key}: no value")
    m = _RANGE_RE.match(spec)
    if m and len(m.group(3).lstrip("+-").lstrip("0")) > 12:
        # int() of a 5000-digit count raised past Python's int-string limit: exit 3
        # (hostile-input trial, session 24)
        raise InputError(
            f"--set {key}: {len(m.group(3))}-digit number of values, above the "
            f"limit of {MAX_POINTS} points"
        )
    if m:
        return Axis(
            key,
            tuple(_range_values(key, m.group(1), m.group(2), int(m.group(3)), m.group(4) == "log")),
        )
    if ":" in spec and not spec.startswith(("[", "{", '"', "'")):
        # 0.5:0.7:2.0 and 1_0:2_0:2 were "is not a TOML value" (batch trial, session 39)
        raise InputError(
            f"--set {key}: {spec!r} is not a range START:STOP:N[:lin|log] (START and STOP "
            "decimal numbers such as 0.9 or 1e-3, N a whole number of values)"
        )
    if spec.startswith("["):
        items = _split_list(key, spec)
        if not items:
            raise InputError(f"--set {key}: the list of values is empty")
        return Axis(key, tuple(_literal(key, it) for it in items))
    return Axis(key, (_literal(key, spec),))


def _range_values(key: str, a_text: str, b_text: str, n: int, log: bool) -> list[str]:
    if n < 1:
        raise InputError(f"--set {key}: the number of values must be at least 1, got {n}")
    if n > MAX_POINTS:
        raise InputError(f"--set {key}: {n} values, above the limit of {MAX_POINTS} points")
    for t in (a_text, b_text):
        digits = len(t.lstrip("+-").split("e")[0].split("E")[0].replace(".", "").lstrip("0"))
        if digits > 50:
            raise InputError(f"--set {key}: {t!r} has more than 50 significant digits")
        exp = re.search(r"[eE]([+-]?\d+)$", t)
        if exp and abs(int(exp.group(1))) > 300:
            raise InputError(f"--set {key}: the exponent of {t!r} is out of range (±300)")
    a, b = Decimal(a_text), Decimal(b_text)
    if n == 1 and a != b:
        # the one value was a, and b was dropped without a word (CLI hostile-input trial,
        # session 34): the docs say both ends are included
        raise InputError(
            f"--set {key}: {a_text}:{b_text}:1 has one value but two different ends: give "
            f"at least 2 values, or the one value ({a_text})"
        )
    as_int = all("." not in t and "e" not in t.lower() for t in (a_text, b_text))
    prec = max(DIGITS, len(a.as_tuple().digits), len(b.as_tuple().digits))
    out: list[Decimal] = []
    if log:
        if a <= 0 or b <= 0:
            raise InputError(f"--set {key}: a log range needs positive ends, got {a_text}:{b_text}")
        for i in range(n):
            if i == 0 or n == 1:
                out.append(a)
            elif i == n - 1:
                out.append(b)
            else:
                with localcontext() as ctx:
                    ctx.prec = prec + 25
                    v = (a.ln() + (b.ln() - a.ln()) * i / (n - 1)).exp()
                with localcontext() as ctx:
                    ctx.prec = prec
                    out.append(+v)
    else:
        fa, fb = Fraction(a), Fraction(b)
        for i in range(n):
            q = fa if n == 1 else fa + (fb - fa) * Fraction(i, n - 1)
            with localcontext() as ctx:
                ctx.prec = prec
                out.append(Decimal(q.numerator) / Decimal(q.denominator))
    return [_decimal_text(v, as_int) for v in out]


def _decimal_text(v: Decimal, as_int: bool) -> str:
    """A TOML number for ``v``: plain decimal digits (no exponent), an integer only when the
    range's ends were integers."""
    s = format(v.normalize(), "f")
    if s in ("-0", "-0.0"):
        s = "0"
    if "." not in s and not as_int:
        s += ".0"
    return s


def _split_list(key: str, spec: str) -> list[str]:
    """The top-level items of ``[a, b, c]`` (brackets, braces and quotes respected; in a
    "basic" string a backslash escapes the next character, as in TOML: ``["a\\"b", c]`` was
    refused as unbalanced; outsider trial, session 22)."""
    if not spec.endswith("]"):
        raise InputError(f"--set {key}: a list of values must end with ']': {spec!r}")
    body = spec[1:-1]
    items, depth, quote, cur = [], 0, "", []
    escaped = False
    for ch in body:
        if quote:
            cur.append(ch)
            if escaped:
                escaped = False
            elif ch == "\\" and quote == '"':
                escaped = True
            elif ch == quote:
                quote = ""
            continue
        if ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
            if depth < 0:
                raise InputError(f"--set {key}: unbalanced brackets in {spec!r}")
        elif ch == "," and depth == 0:
            items.append("".join(cur).strip())
            cur = []
            continue
        cur.append(ch)
    if quote or depth:
        raise InputError(f"--set {key}: unbalanced brackets or quotes in {spec!r}")
    last = "".join(cur).strip()
    if last:  # a trailing comma ends the list, as TOML allows ([0.96,] was "empty item")
        items.append(last)
    elif not items:
        pass
    elif not items[-1]:
        items.append(last)  # ",," at the end: an empty item, refused below
    if any(not it for it in items):
        raise InputError(f"--set {key}: empty item in {spec!r}")
    return items


def _literal(key: str, text: str) -> str:
    """``text`` as a TOML value literal: as written when it is one, else a quoted string
    (a bare word). A number is written as given (its decimal text is the exact value); one
    too long for Python's int-to-text limit is kept as written, and its point becomes a
    bad-input row like any number past ``max_digits`` (a 5000-digit value was an internal
    failure; outsider trial, session 22)."""
    try:
        tomllib.loads(f"x = {text}")
        return text
    except tomllib.TOMLDecodeError:
        pass
    except ValueError:  # an integer past Python's int-string limit: TOML, but too long
        return text
    except RecursionError:  # [[[…]]] 3000 deep: exit 3 (hostile-input trial, session 24)
        raise InputError(f"--set {key}: the value is nested too deeply") from None
    if re.match(r"^[A-Za-z_][A-Za-z0-9_.+-]*$", text):
        return json.dumps(text)
    raise InputError(f"--set {key}: {text!r} is not a TOML value")


def grid_points(axes: Sequence[Axis]) -> list[dict[str, str]]:
    """The product of the axes, the last varying fastest: one ``{key: literal}`` per point."""
    keys = [a.key for a in axes]
    if len(set(keys)) != len(keys):
        dup = sorted({k for k in keys if keys.count(k) > 1})
        raise InputError(f"--set: key {dup[0]} is given twice")
    total = math.prod(len(a.values) for a in axes)
    if total > MAX_POINTS:
        raise InputError(f"--set: the grid has {total} points, above the limit of {MAX_POINTS}")
    return [dict(zip(keys, vals, strict=True)) for vals in product(*(a.values for a in axes))]


def parse_grid(grid: Sequence[str] | dict[str, Any]) -> list[Axis]:
    """Axes from ``--set`` texts, or from a dict ``{key: "a:b:n" | [values] | value}``
    (values may be Python numbers: written with ``repr``, i.e. the shortest decimal; a
    numpy array is the list of its values along its first axis, as a list would be)."""
    if isinstance(grid, dict):
        texts = []
        for k, v in grid.items():
            if _is_ndarray(v) and getattr(v, "ndim", 0) > 0:
                v = list(v)  # the points; as one string it was one bad point (API trial 33)
            if isinstance(v, (list, tuple)):
                v = "[" + ", ".join(_py_literal(x, k) for x in v) + "]"
            elif not isinstance(v, str):
                v = _py_literal(v, k)
            texts.append(f"{k}={v}")
        grid = texts
    elif isinstance(grid, str):
        grid = [grid]  # one KEY=VALUES text, not its characters
    else:
        # a generator is true even when empty: an empty one swept one unswept point, ok
        # (API review 45); None or 5 were bare TypeErrors (CLI review 46)
        try:
            grid = list(grid)
        except TypeError:
            raise InputError(
                f"sweep: expected KEY=VALUES texts (or a dict) as the grid, got "
                f"{type(grid).__name__}"
            ) from None
    if not grid:
        raise InputError("sweep: no --set KEY=VALUES given (nothing to sweep)")
    bad = next((t for t in grid if not isinstance(t, str)), None)
    if bad is not None:
        raise InputError(f"sweep: expected KEY=VALUES texts (or a dict), got {bad!r}")
    return [parse_axis(t) for t in grid]


def _is_ndarray(v: Any) -> bool:
    """Whether ``v`` is a numpy array, without importing numpy for a grid that has none."""
    return type(v).__module__ == "numpy" and type(v).__name__ == "ndarray"


def _py_literal(x: Any, key: str = "") -> str:
    """One value of a dict grid as TOML, written as :func:`obsdesign.interop` writes a spec
    value: numpy scalars and arrays as numbers (they became strings, ``'0.96'`` for a
    float32: API trial, session 33), exact rationals exactly or refused (a Fraction(29, 30)
    was rounded to 28 digits silently)."""
    if isinstance(x, int) and not isinstance(x, bool):
        from obsdesign.limits import int_problem

        why = int_problem(x)  # str() of a 5000-digit int is a ValueError (outsider trial)
        if why is not None:
            raise InputError(f"sweep: {key}: an integer value {why}")
    from obsdesign.interop import _value

    try:
        return _value(x)
    except InputError as e:
        raise InputError(f"sweep: {key}: {e}") from None


# -- editing the spec text --------------------------------------------------------------------
def _tables(stmts: list[tomltext.Statement]) -> list[tuple[tuple[str, ...] | None, int]]:
    """For each statement, the table it belongs to (``()`` for the root; None inside an
    array of tables or under a header that does not parse: never edited) and its index."""
    out: list[tuple[tuple[str, ...] | None, int]] = []
    table: tuple[str, ...] | None = ()
    for k, s in enumerate(stmts):
        if s.kind == "table":
            table = s.key
        elif s.kind == "aot":
            table = None
        out.append((table, k))
    return out


def set_key(text: str, key: str, literal: str, file: str = "<spec>") -> str:
    """The TOML ``text`` with dotted ``key`` set to the TOML ``literal``: the key's value is
    replaced in place (whatever follows it on its line kept), or the key is added after the
    last statement of its deepest existing table. The statements and the value's span come
    from a lexer (:mod:`obsdesign.spec.tomltext`); the result is parsed and compared with
    the original: exactly that key changed, or :class:`InputError`."""
    parts = tuple(key.split("."))
    original = text
    stmts = tomltext.statements(text)
    aot = next((s.key for s in stmts if s.kind == "aot" and s.key == parts[: len(s.key)]), None)
    if aot is not None:  # [[simulate.noise.windows]] (re-check review 47)
        if len(aot) < len(parts):
            whole = ".".join(aot)
            raise InputError(
                f"{file}: cannot set {key}: [[{whole}]] is an array of tables: --set replaces "
                f"it whole, e.g. --set '{whole}=[[{{ ... }}, ...]]' (one point: the outer brackets "
                "list the swept values)"
            )
        text = _without_aot(text, stmts, aot)
        stmts = tomltext.statements(text)
    owner = _tables(stmts)
    new_text = None
    for j in range(len(parts) - 1, -1, -1):  # the value: [a.b] c = ..., [a] b.c = ..., a.b.c
        for table, k in owner:
            s = stmts[k]
            if s.kind == "keyval" and table == parts[:j] and s.key == parts[j:]:
                new_text = text[: s.value_start] + literal + text[s.value_end :]
                break
        if new_text is not None:
            break
    if new_text is None:  # a new key, after the last statement of its deepest table
        for j in range(len(parts) - 1, -1, -1):
            mine = [k for table, k in owner if table == parts[:j]]
            if j and not any(stmts[k].kind == "table" for k in mine):
                continue
            line = f"{'.'.join(parts[j:])} = {literal}"
            if not mine:  # the root holds no statement: the key goes first
                new_text = f"{line}\n{text}"
            else:
                at = stmts[mine[-1]].end
                new_text = f"{text[:at]}\n{line}{text[at:]}"
            break
    if new_text is None:
        new_text = f"{'.'.join(parts)} = {literal}\n" + text
    _check_edit(original, new_text, list(parts), literal, file)
    return new_text


def _without_aot(text: str, stmts: list[tomltext.Statement], key: tuple[str, ...]) -> str:
    """``text`` without the array of tables ``[[key]]``: each ``[[key]]`` header through the
    statements and sub-tables (``[key.sub]``) that follow it, up to the next header outside
    ``key``. ``--set key=[...]`` then adds the key as an inline array (``windows`` written as
    ``[[simulate.noise.windows]]`` was refused with the advice to write an inline table as a
    [table]; re-check review 47)."""
    cut: list[tuple[int, int]] = []
    at: int | None = None
    for s in stmts:
        if s.kind in ("table", "aot"):
            inside = s.key is not None and s.key[: len(key)] == key
            if at is not None and not inside:
                cut.append((at, s.start))
                at = None
            if at is None and s.kind == "aot" and s.key == key:
                at = s.start
    if at is not None:
        cut.append((at, len(text)))
    for a, b in reversed(cut):
        text = text[:a] + text[b:]
    return text


def _check_edit(old: str, new: str, parts: list[str], literal: str, file: str) -> None:
    """The edited text sets exactly ``parts`` to ``literal`` and nothing else. A spec nested
    too deeply for the TOML parser is bad input (a RecursionError was exit 3: CLI fuzzer;
    the spec loader refuses it by its own depth limit)."""
    try:
        _check_edit_parsed(old, new, parts, literal, file)
    except RecursionError:
        raise InputError(
            f"{file}: nested too deeply to edit (tables, arrays or dotted keys)"
        ) from None


def _immutable_hint(before: dict, parts: list[str]) -> str:
    """Why TOML cannot add ``parts`` to the spec ``before``: a part that is an array (an
    array's entry is no key: ``system.A.0`` said "an inline table holds it"; batch trial,
    session 39), else an inline table."""
    d: object = before
    for i, p in enumerate(parts[:-1]):
        d = d.get(p) if isinstance(d, dict) else None
        if isinstance(d, list):
            whole = ".".join(parts[: i + 1])
            return f"; {whole} is an array: --set replaces it whole, e.g. --set {whole}=[...]"
    return "; an inline table holds it: write it as a [table]"


def _check_edit_parsed(old: str, new: str, parts: list[str], literal: str, file: str) -> None:
    key = ".".join(parts)
    try:
        before = tomllib.loads(old)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"{file}: is not valid TOML ({e})") from None
    try:
        after = tomllib.loads(new)
        want = tomllib.loads(f"x = {literal}")["x"]
    except ValueError as e:
        if not isinstance(e, tomllib.TOMLDecodeError):  # Python's int-string limit
            raise InputError(
                f"{file}: [{key}] has a number with more than {limits().max_digits} digits "
                "(--limit max_digits=N)"
            ) from None
        node: Any = before
        for i, p in enumerate(parts):
            node = node.get(p) if isinstance(node, dict) else None
            if i < len(parts) - 1 and node is not None and not isinstance(node, (dict, list)):
                # a key under a number (method.lambda.x=1): "Cannot overwrite a value" alone
                # (re-check review 46)
                above = ".".join(parts[: i + 1])
                raise InputError(
                    f"{file}: cannot set {key} = {literal}: [{above}] is a value, not a table"
                ) from None
        if isinstance(node, dict):
            # tomllib's "Cannot overwrite a value (at line 15, column 8)" named a line of
            # the text as edited, not the user's (CLI review 46)
            raise InputError(
                f"{file}: cannot set {key} = {literal}: [{key}] is a table; --set sets a "
                f"value in it ({key}.NAME=VALUES)"
            ) from None
        # the position is in the text as edited, which the user never saw (CLI review 46)
        why = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(e))
        raise InputError(
            f"{file}: cannot set {key} = {literal} ({why}"
            + (_immutable_hint(before, parts) if "immutable" in str(e) else "")
            + ")"
        ) from None
    d = before
    for p in parts[:-1]:
        nxt = d.get(p) if isinstance(d, dict) else None
        if nxt is None:
            nxt = {}
            d[p] = nxt
        if not isinstance(nxt, dict):
            raise InputError(f"{file}: cannot set {key}: {p} is not a table")
        d = nxt
    d[parts[-1]] = want
    if not _same_toml(before, after):
        raise InputError(
            f"{file}: cannot set {key} in the spec text (an inline table or an array of "
            f"tables holds it: write it as a [table] key)"
        )


def _same_toml(a: Any, b: Any) -> bool:
    """Equality of parsed TOML with nan equal to nan (``--set method.lambda=nan`` was refused
    as "an inline table holds it", since nan != nan; outsider trial, session 22: the spec
    loader now refuses the nan, as any non-finite number, in that point's row)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same_toml(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same_toml(x, y) for x, y in zip(a, b, strict=True))
    return type(a) is type(b) and a == b


def point_text(text: str, values: dict[str, str], file: str = "<spec>") -> str:
    """The spec text of one grid point (every key of ``values`` set)."""
    for k, lit in values.items():
        text = set_key(text, k, lit, file)
    return text


# -- one point --------------------------------------------------------------------------------
@dataclass(frozen=True)
class PointTask:
    """Everything a worker needs for one point (the spec travels as text: no shared files)."""

    index: int
    values: dict[str, str]
    text: str
    file: str
    simulate: bool = False
    sim_options: dict[str, str] = field(default_factory=dict)
    #: seconds this point may run (None: no limit), as ``check --timeout``; on Dask too
    timeout: float | None = None


_VERDICTS = {0: "ok", 1: "failed", 2: "bad input", 3: "error", 4: "inconclusive"}


def _value(lit: str) -> Any:
    """A row's cell for a swept literal: its value when a scalar, else (or when Python
    cannot hold it as text: an integer past the int-string limit; or a float literal with
    more digits than the double shows) the literal itself."""
    try:
        v = tomllib.loads(f"x = {lit}")["x"]
    except ValueError:
        return lit
    if isinstance(v, float) and math.isfinite(v) and not _float_says(v, lit):
        # more digits than a double holds: 0.9999999999999999999999 showed as 1.0, a λ the
        # spec loader refuses, beside the certified row (outsider trial, session 26)
        return lit.strip()
    if isinstance(v, float) and math.isinf(v) and "inf" not in lit.lower():
        # 1e400, past the float range, was the cell inf, a real inf point's look (CLI
        # review 45): the literal as written
        return lit.strip()
    return v if isinstance(v, (int, float, str, bool)) else lit


def _float_says(v: float, lit: str) -> bool:
    """Is the shortest repr of ``v`` the same number as the TOML float literal ``lit``?"""
    try:
        return Decimal(repr(v)) == Decimal(lit.strip().replace("_", ""))
    except ArithmeticError:
        # decimal.InvalidOperation: an exponent past Decimal's range (0.9e-10^20 read as
        # 0.0, a real zero's look; re-check review 45): the literal is kept
        return False


def _row_head(task: PointTask) -> dict[str, Any]:
    return {"point": task.index, **{k: _value(v) for k, v in task.values.items()}}


def failure_row(task: PointTask, code: int, message: str, method: str = "") -> dict[str, Any]:
    """The row of a point that stopped with exit ``code``."""
    return {
        **_row_head(task),
        "verdict": _VERDICTS.get(code, "error"),
        "exit_code": code,
        "message": message,
        "method": method,
    }


def task_method(task: PointTask) -> str:
    """The method of a point whose run left no row (a worker lost with it): its spec's
    ``[method] key`` when that is a known method, else "" (the row of a lost point had an
    empty method where check's names it; Dask trial, session 29)."""
    import tomllib

    from obsdesign.methods import method_keys

    try:
        doc = tomllib.loads(point_text(task.text, task.values, task.file))
    except Exception:  # noqa: BLE001 - a point that does not read has no method to name
        return ""
    key = doc.get("method", {}).get("key") if isinstance(doc.get("method"), dict) else None
    return key if isinstance(key, str) and key in method_keys() else ""


def run_point(task: PointTask) -> dict[str, Any]:
    """Design, serialize, reload and verify one point (and simulate it when asked): its
    row. Never raises (but KeyboardInterrupt): an error is the row's exit code and message;
    a point past ``task.timeout`` is exit 3 "not finished" (one hanging point cost every
    row of the sweep; hostile-input trial, session 24)."""
    from obsdesign import api

    t0 = time.perf_counter()
    seen = [""]  # the method, once the point's spec is loaded
    try:
        with api._time_budget(task.timeout):
            return _run_point(task, t0, seen)
    except api.SpecTimeout:
        # the method named, as check's row does (it was empty: Dask trial, session 29)
        row = failure_row(
            task,
            EXIT_SOLVER,
            f"not finished within {task.timeout:g} s (sweep --timeout SECONDS; 0: no limit)",
            seen[0],
        )
        row["seconds"] = round(time.perf_counter() - t0, 4)
        return row


def _run_point(task: PointTask, t0: float, seen: list[str]) -> dict[str, Any]:
    """:func:`run_point` without the time budget; ``seen[0]`` becomes the point's method once
    its spec is loaded."""
    from obsdesign import api

    method = ""
    name = f"{task.file}[point {task.index}]"
    try:
        text = point_text(task.text, task.values, name)
        sp = api.load_spec_text(text, name)
        method = seen[0] = sp.method
        rep = api.design(sp)
        t1 = time.perf_counter()
        ver = api.verify_own(rep)  # as check: its own exact values, of any length
        t2 = time.perf_counter()
        code = ver.exit_code()
        counts = ver.status_counts()
        row = {
            **_row_head(task),
            "verdict": _VERDICTS.get(code, "error"),
            "exit_code": code,
            "message": "; ".join(f"{c.id}: {c.detail}" for c in ver.failed),
            "method": method,
            "certified": counts["certified"],
            "numerical": counts["numerical"],
            "failed": counts["failed"],
        }
        m = api.method(method)
        for f in m.summary_fields:
            if f.param in ver.parameters:
                row[f.param] = _scalar(ver.parameters, f.param)
        row["design_s"] = round(t1 - t0, 4)
        row["verify_s"] = round(t2 - t1, 4)
        if task.simulate:
            try:
                res = api.simulate(sp, rep, options=dict(task.sim_options))
                row.update(_flat_metrics(res.metrics()))
                sim_code = int(res.info.get("exit_code", 0) or 0)
            except ObsdesignError as e:
                sim_code = e.exit_code
                row["message"] = "; ".join(
                    x for x in (row["message"], f"simulate: {e.message}") if x
                )
            row["simulate_s"] = round(time.perf_counter() - t2, 4)
            if sim_code > row["exit_code"]:
                row["exit_code"] = sim_code
                row["verdict"] = _VERDICTS.get(sim_code, "error")
        row["seconds"] = round(time.perf_counter() - t0, 4)
        return row
    except ObsdesignError as e:
        # the spec's key when the error left none (a value past the reader's range: the
        # row's method was "" beside the others' "lyapunov"; CLI review 46)
        row = failure_row(
            task, e.exit_code, e.message, method or api.error_method(e) or task_method(task)
        )
    except Exception as e:  # noqa: BLE001 - one row per point, whatever happened in it
        row = failure_row(task, EXIT_SOLVER, f"internal failure: {type(e).__name__}: {e}", method)
    row["seconds"] = round(time.perf_counter() - t0, 4)
    return row


class ExactFloat(float):
    """A summary parameter's float beside the exact value it stands for (``exact``, "p/q"):
    tables compare the decimal they show with the exact value and mark it "≈" when it is not
    that value (:func:`obsdesign.cli_commands._sweep_cell`); CSV, JSON and Parquet cells are
    the float. A certified λ = 0.9999999999999999999999 was shown as a bare "1" (sweep,
    import and check trial, session 28), and an exact μ = 58250127/262144 as its double's
    shortest text 222.20660018920898 in Markdown, below the bound (re-check trial): every
    exact parameter carries its value, not only those whose double differs from it."""

    __slots__ = ("exact",)
    exact: str

    def __new__(cls, value: float, exact: str) -> ExactFloat:
        self = super().__new__(cls, value)
        self.exact = exact
        return self

    def __reduce__(self) -> tuple[Any, ...]:  # pickles (Dask) as itself
        return (ExactFloat, (float(self), self.exact))

    def shows(self, text: str) -> bool:
        """Whether the decimal ``text`` is the exact value."""
        from obsdesign.certify.exact import Q

        return Q(text) == Q(self.exact)


def _scalar(params: Any, key: str) -> Any:
    """A summary parameter's cell: an integer stays one (``facets`` 6, not 6.0: outsider
    trial, session 22), a number is its float (an :class:`ExactFloat` for an exact
    parameter), a matrix the JSON list of its floats (K, R, W of stubborn were
    numpy's text of an object array, with literal "\\n": session 28), anything else its
    JSON text."""
    from flint import fmpq

    v0 = params[key]
    if isinstance(v0, numbers.Integral) and not isinstance(v0, bool):
        return int(v0)
    try:
        f = float(params.float(key))
    except (TypeError, ValueError):
        v = params[key]
        if isinstance(v, (int, str, bool)):
            return v
        try:
            return json.dumps(params.float_json(key), allow_nan=False)
        except (TypeError, ValueError):
            return json.dumps(v, default=str)
    if isinstance(v0, fmpq) and math.isfinite(f):
        return ExactFloat(f, str(v0))
    return f


def _flat_metrics(m: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in m.items():
        if k == "exit_code":
            continue
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(_flat_metrics(v, name + "."))
        elif isinstance(v, (bool, int, float, str)) or v is None:
            out[name] = v
        else:
            try:
                out[name] = float(v)
            except (TypeError, ValueError):
                out[name] = json.dumps(v, default=str)
    return out


# -- the sweep --------------------------------------------------------------------------------
def _spec_source(spec: Any) -> tuple[str, str]:
    """(text, file name) of a spec path or :class:`obsdesign.spec.Spec`."""
    if isinstance(spec, (str, Path)):
        from obsdesign.limits import read_input

        p = Path(spec)
        raw = read_input(p, "spec")
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            raise InputError(f"{p}: is not UTF-8 text") from None
        if text.startswith("\ufeff"):
            # the loader's message (design, check, simulate): sweep said "is not valid TOML
            # (Invalid statement …)" of the edited point (CLI trial, session 40)
            from obsdesign.spec.loader import read_spec_text

            read_spec_text(text, str(p))
        return text, str(p)
    text, file = getattr(spec, "text", None), getattr(spec, "file", None)
    if not isinstance(text, str) or not isinstance(file, str):
        # sweep(123, ...) was a bare AttributeError (API review 45)
        raise InputError(
            f"sweep: spec must be a path or a Spec (api.load_spec), got {type(spec).__name__}"
        )
    if hasattr(spec, "changed_since_read"):
        # the points are the text's: an object edited after loading (its system replaced)
        # swept its text, every row ok, where design refuses it (API review 46)
        from obsdesign.api import _text_describes

        _text_describes(spec)
    return text, file


def plan(
    spec: Any,
    grid: Sequence[str] | dict[str, Any],
    simulate: bool = False,
    options: dict[str, str] | None = None,
    timeout: float | None = None,
) -> tuple[list[Axis], list[PointTask]]:
    """The axes and one task per grid point; bad input that concerns every point (a bad
    ``--set``, a key that cannot be written, a spec without ``[simulate]`` for
    ``simulate=True``) is an :class:`InputError` here, before any work."""
    from obsdesign.api import budget_seconds

    timeout = budget_seconds(timeout)
    if options is not None and not (
        isinstance(options, Mapping)
        and all(isinstance(k, str) and isinstance(v, str) for k, v in options.items())
    ):
        # options=[1]: a bare TypeError from dict() (hostile-input trial, session 38)
        raise InputError(
            f"options: expected a mapping of option names to value texts "
            f"({{'time_limit': '10'}}), got {options!r}"
        )
    axes = parse_grid(grid)
    text, file = _spec_source(spec)
    points = grid_points(axes)
    point_text(text, points[0], file)  # every point edits the same lines: check once
    if simulate:
        try:
            doc = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise InputError(f"{file}: is not valid TOML ({e})") from None
        if "simulate" not in doc and not any(k.startswith("simulate.") for k in points[0]):
            raise InputError(f"{file}: [simulate] is missing: nothing to simulate (--simulate)")
    tasks = [
        PointTask(i, p, text, file, simulate, dict(options or {}), timeout)
        for i, p in enumerate(points)
    ]
    if options:
        check_options(tasks, simulate, options)
    return axes, tasks


def check_options(tasks: Sequence[PointTask], simulate: bool, options: dict[str, str]) -> None:
    """The ``--option`` pairs, checked once before any work: without ``simulate`` they were
    ignored unread, and with it a bad one was found point by point after each design and
    verify (docs trial, session 31). They are the same for every point, so they are checked
    against the method of each point (of the first alone when ``method.key`` is not swept);
    a point whose method does not read gets its own row later."""
    if not simulate:
        keys = ", ".join(sorted(options))
        raise InputError(f"--option {keys}: simulation options need --simulate")
    from obsdesign.methods import get_method

    swept = any(k in ("method", "method.key") for k in tasks[0].values)
    methods = {task_method(t) for t in (tasks if swept else tasks[:1])} - {""}
    for key in sorted(methods):
        get_method(key).parse_sim_options(options)


def sweep_rows(
    spec: Any,
    grid: Sequence[str] | dict[str, Any],
    *,
    simulate: bool = False,
    options: dict[str, str] | None = None,
    client: Any = None,
    workers: int | None = None,
    scheduler: str | None = None,
    on_row: Callable[[dict[str, Any]], None] | None = None,
    timeout: float | None = None,
) -> list[dict[str, Any]]:
    """One row per grid point, in grid order (see the module docstring); ``on_row(row)`` is
    called as each row arrives (completion order); ``timeout``: seconds per point (on Dask
    too: applied in the worker), past which the point's row is exit 3."""
    if type(simulate).__name__ not in ("bool", "bool_"):  # 'no' simulated (CLI review 46)
        raise InputError(f"simulate: expected True or False, got {simulate!r}"[:300])
    _, tasks = plan(spec, grid, bool(simulate), options, timeout)

    def lost(task: PointTask, message: str) -> dict[str, Any]:
        return failure_row(task, EXIT_SOLVER, message, task_method(task))

    return run_rows(run_point, tasks, lost, workers, scheduler, client, on_row)


def run_rows(
    fn: Callable[[Any], Any],
    items: Sequence[Any],
    lost: Callable[[Any, str], Any],
    workers: int | None,
    scheduler: str | None,
    client: Any,
    on_row: Callable[[Any], None] | None,
) -> list[Any]:
    """``[fn(item) for item in items]``, in this process or on Dask
    (:func:`obsdesign.distributed.run_tasks`: ``workers``, ``scheduler`` or ``client``), in
    item order; ``on_row(row)`` as each row arrives; ``lost(item, message)`` is the row of an
    item whose worker died. Shared by ``sweep`` and ``check``."""
    from obsdesign.distributed import run_tasks

    return run_tasks(
        fn,
        items,
        workers=workers,
        scheduler=scheduler,
        client=client,
        on_result=(lambda i, r: on_row(r)) if on_row is not None else None,
        lost=lost,
    )


def columns(rows: Sequence[dict[str, Any]]) -> list[str]:
    """Every column of ``rows``, in order of first appearance (timings last)."""
    cols: dict[str, None] = {}
    for r in rows:
        for k in r:
            cols.setdefault(k, None)
    head = [c for c in cols if c not in TIMING_COLUMNS]
    return head + [c for c in TIMING_COLUMNS if c in cols]


def to_frame(rows: list[dict[str, Any]]) -> Any:
    """A pandas DataFrame of ``rows`` (columns as :func:`columns`), or ``rows`` themselves
    when pandas is not installed."""
    try:
        import pandas as pd
    except ImportError:
        return rows
    return pd.DataFrame(rows, columns=columns(rows))


def sweep(
    spec: Any,
    grid: Sequence[str] | dict[str, Any],
    client: Any = None,
    *,
    simulate: bool = False,
    options: dict[str, str] | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    timeout: float | None = None,
) -> Any:
    """Sweep ``spec`` (a path or a Spec) over ``grid`` (``["method.lambda=0.9:0.99:10"]`` or
    ``{"method.lambda": [0.9, 0.95]}``): a pandas DataFrame with one row per point (a list of
    dicts without pandas). ``client`` (a ``dask.distributed.Client``), ``workers`` (a
    LocalCluster) or ``scheduler`` run the points on Dask; the rows are the same.
    ``timeout``: seconds per point (None or 0: no limit), past which the point's row is exit
    3, as ``sweep --timeout`` (the API had no budget: a TypeError; batch trial, session 35)."""
    rows = sweep_rows(
        spec,
        grid,
        simulate=simulate,
        options=options,
        client=client,
        workers=workers,
        scheduler=scheduler,
        timeout=timeout,
    )
    return to_frame(rows)


def exit_code(rows: Sequence[dict[str, Any]]) -> int:
    """The worst row's exit code (0 when every point passed)."""
    return max((int(r.get("exit_code", EXIT_OK)) for r in rows), default=EXIT_OK)


# -- output ---------------------------------------------------------------------------------
def check_output_path(path: Path, force: bool, inputs: tuple[Path, ...]) -> None:
    """Refuse an output path before any work: unknown suffix, Parquet without pyarrow, or a
    path :func:`obsdesign.report.model.check_output` refuses."""
    from obsdesign.report.model import check_output

    if str(path) == "-":  # design's words for it, not "unknown table format" (CLI review 46)
        check_output(path, force, inputs)
    suf = path.suffix.lower()
    if suf not in OUTPUT_SUFFIXES:
        raise InputError(
            f"{path}: unknown table format {path.suffix or '(no suffix)'!r} "
            f"(expected one of {', '.join(OUTPUT_SUFFIXES)})"
        )
    if suf == ".parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise InputError(f"{path}: Parquet needs pyarrow (pip install pyarrow)") from None
    check_output(path, force, inputs)


def _cell(v: Any) -> Any:
    if isinstance(v, float) and not math.isfinite(v):
        return str(v)
    return v


def write_table(path: Path, rows: list[dict[str, Any]], force: bool = False) -> None:
    """Write ``rows`` to ``path`` atomically (CSV, JSON Lines or Parquet by suffix)."""
    from obsdesign.errors import valid_strings
    from obsdesign.report.model import write_via

    # a non-UTF-8 spec file name in the messages: written with escapes, not a
    # UnicodeEncodeError after the sweep (session 40)
    rows = [valid_strings(r) for r in rows]
    cols = columns(rows)
    suf = path.suffix.lower()

    def w(tmp: Path) -> None:
        if suf == ".csv":
            import csv

            with open(tmp, "w", encoding="utf-8", newline="") as f:
                wr = csv.DictWriter(f, fieldnames=cols, restval="")
                wr.writeheader()
                for r in rows:
                    wr.writerow({k: ("" if v is None else v) for k, v in r.items()})
        elif suf == ".jsonl":
            with open(tmp, "w", encoding="utf-8") as f:
                for r in rows:
                    f.write(json.dumps({k: _cell(v) for k, v in r.items()}, ensure_ascii=False))
                    f.write("\n")
        else:
            import pyarrow as pa
            import pyarrow.parquet as pq

            data = {c: _parquet_column([r.get(c) for r in rows]) for c in cols}
            pq.write_table(pa.table(data), str(tmp))

    write_via(path, w, force)


def _kind(v: Any) -> str:
    if isinstance(v, bool):
        return "bool"
    if isinstance(v, numbers.Real):
        return "number"
    return type(v).__name__


def _parquet_column(values: list[Any]) -> list[Any]:
    """A column Arrow can type: as it is when its values (None aside) are of one kind
    (numbers of both int and float become doubles), else every value as its text (a swept
    value a double cannot show is text beside numbers, and pyarrow raised ArrowTypeError:
    exit 3; re-run trial, session 26)."""
    kinds = {_kind(v) for v in values if v is not None}
    if len(kinds) <= 1:
        return values
    return [
        None if v is None else (v if isinstance(v, str) else json.dumps(_cell(v))) for v in values
    ]


def plot_groups(
    rows: list[dict[str, Any]], others: list[str], x: str, y: str
) -> dict[tuple[Any, ...], list[tuple[float, float]]]:
    """The points of :func:`plot_sweep`: per value of the ``others`` keys, (x, y) pairs, y
    nan (a gap) where the row is not ok (exit code 0). An inconclusive row (exit 4) was
    drawn as a value although nothing in it is certified, against docs/sweeps.md's "points
    that are not ok are gaps" (sweep, import and check trial, session 28)."""
    groups: dict[tuple[Any, ...], list[tuple[float, float]]] = {}
    for r in rows:
        g = tuple(r.get(k) for k in others)
        try:
            xv = float(r[x])
            yv = float(r[y]) if r.get(y) is not None and r.get("exit_code") == 0 else math.nan
        except (TypeError, ValueError, KeyError):
            continue
        if not math.isfinite(xv):
            # a swept 1e400 or inf has no place on the axis: matplotlib's limits were an
            # internal failure, exit 3, no table (re-check review 45)
            continue
        groups.setdefault(g, []).append((xv, yv))
    return groups


def _x_codes(rows: list[dict[str, Any]], x: str) -> list[tuple[float, Any]]:
    """(x as a number, exit code) of the rows whose x is a number."""
    out = []
    for r in rows:
        try:
            xv = float(r[x])
        except (TypeError, ValueError, KeyError):
            continue
        if math.isfinite(xv):  # as in _groups: no place on the axis
            out.append((xv, r.get("exit_code")))
    return out


def missing_y(rows: list[dict[str, Any]], y: str) -> int:
    """How many ok rows (exit 0) have no number in column ``y`` (gaps of the plot that are
    not failures: alpha of a discrete-time spec, mu where iss_gain is false)."""
    n = 0
    for r in rows:
        if r.get("exit_code") != 0:
            continue
        try:
            float(r[y])
        except (TypeError, ValueError, KeyError):
            n += 1
    return n


def plot_sweep(
    rows: list[dict[str, Any]], axes: list[Axis], y: str, path: Path, x: str | None = None
) -> None:
    """Plot column ``y`` against the swept key ``x`` (the first axis by default), one line
    per value of the other axes; failed points are left out (gaps) and marked × on the x
    axis, whose range covers every swept value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from obsdesign.simulate.plot import plain

    keys = [a.key for a in axes]
    x = x or keys[0]
    others = [k for k in keys if k != x]
    groups = plot_groups(rows, others, x, y)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    try:
        for g, pts in groups.items():
            pts.sort()
            label = plain(", ".join(f"{k} = {v}" for k, v in zip(others, g, strict=True))) or None
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=label)
        # the points that are not ok, marked × on the x axis over the whole swept range: a
        # gap at an end of the range was simply off the axis (the README's sweep showed
        # 0.96 … 0.99 of 0.90 … 0.99, nothing said six points failed; outsider trial,
        # session 29)
        # the rows with exit ≠ 0 only: an ok row without a value of y (alpha of a discrete
        # spec, mu with iss_gain = false) is a gap, not a failure — all four ok rows of a
        # sweep were marked "not ok" (sweep review, session 42)
        bad = sorted({xv for xv, code in _x_codes(rows, x) if code != 0})
        xs = [p[0] for pts in groups.values() for p in pts]
        if bad:
            ax.plot(
                bad,
                [0.0] * len(bad),
                "x",
                color="tab:red",
                clip_on=False,
                transform=ax.get_xaxis_transform(),
                label="not ok (a row with exit ≠ 0)",
            )
        if len(xs) > 1 and min(xs) < max(xs):
            pad = (max(xs) - min(xs)) * 0.04
            ax.set_xlim(min(xs) - pad, max(xs) + pad)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        if len(groups) > 1 or bad:
            ax.legend(fontsize="small")
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
    except BaseException:
        plt.close(fig)
        raise
    from obsdesign.simulate.plot import save_figure

    save_figure(fig, path, dpi=100)


def expected_columns(text: str, axes: list[Axis], simulate: bool) -> set[str] | None:
    """The columns a sweep of the spec ``text`` will have (swept keys, verdict, counts, the
    method's summary parameters, timings), or None when unknown beforehand (``simulate``:
    the metrics depend on the method)."""
    if simulate:
        return None
    try:
        key = tomllib.loads(text).get("method", {}).get("key")
        from obsdesign import api

        m = api.method(str(key))
    except (tomllib.TOMLDecodeError, AttributeError, ObsdesignError):
        return None
    fixed = {"point", "verdict", "exit_code", "message", "method", "certified", "numerical"}
    fixed |= {"failed", *TIMING_COLUMNS}
    return fixed | {a.key for a in axes} | {f.param for f in m.summary_fields}


#: columns of text, which ``--y`` cannot plot (an empty plot and exit 0: outsider trial)
TEXT_COLUMNS = frozenset({"verdict", "message", "method"})


def check_plot_column(
    rows: list[dict[str, Any]],
    axes: list[Axis],
    y: str,
    x: str | None,
    expected: set[str] | None = None,
) -> None:
    """--y must be a column of the table and --x a swept key (after the run: columns
    depend on the method). A column in ``expected`` (known before the run) is one even when
    no point was ok: the plot is then all gaps (it was exit 2 "not a column" after the whole
    sweep had run: outsider trial, session 22)."""
    keys = [a.key for a in axes]
    if x is not None and x not in keys:
        raise InputError(f"--x {x}: not a swept key (swept: {', '.join(keys)})")
    cols = columns(rows)
    if y not in cols and not (expected is not None and y in expected):
        raise InputError(f"--y {y}: not a column of the table (columns: {', '.join(cols)})")


# `obsdesign.sweep(spec, grid, client=None)` is this module's `sweep`: importing the module
# makes it the package attribute `obsdesign.sweep`, so the module itself is callable.
class _CallableModule(types.ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule

__all__ = [
    "Axis",
    "EXIT_BAD_INPUT",
    "PointTask",
    "columns",
    "exit_code",
    "grid_points",
    "parse_axis",
    "parse_grid",
    "plan",
    "point_text",
    "run_point",
    "set_key",
    "sweep",
    "sweep_rows",
    "to_frame",
    "write_table",
]
