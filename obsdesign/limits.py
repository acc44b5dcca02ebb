"""Input limits: every size a spec or report may have, checked before the expensive step.

One number, one file or one expression must never hang the tool, exhaust memory or hit
Python's recursion limit. Each limit has a default (``docs/reliability.md`` lists them) and
can be changed for one run with ``obsdesign --limit KEY=VALUE`` (or :func:`set_limits`).

Checked where the input enters:

- files (spec, report): a regular file (``stat`` before ``open``, so a FIFO or /dev/zero is
  refused at once) of at most ``max_file_bytes``;
- values: a spec holds at most ``max_values`` comma-separated values, and as many lines
  (counted on the text before the TOML parser runs: a 2000×2000 matrix is refused in
  milliseconds);
- numbers: at most ``max_digits`` significant digits and a decimal exponent within
  ``±max_exponent``, checked on the text / ``Decimal`` before any conversion to a rational;
- TOML and JSON nesting: at most ``max_depth`` levels (walked iteratively);
- expressions: at most ``max_expr_chars`` characters and ``max_expr_depth`` levels of the
  syntax tree (walked iteratively, before anything recursive runs);
- state dimension: at most ``max_states`` (the method's own ``max_states`` when it declares
  one, else the default); inputs, outputs and disturbances at most ``max_states`` each;
- simulation memory: ``runs × steps × states`` doubles estimated before allocating, at most
  ``max_sim_bytes``.
"""

from __future__ import annotations

import os
import re
import stat
import sys
import weakref
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, fields, replace
from decimal import Decimal
from pathlib import Path
from typing import Any

from obsdesign.errors import InputError

#: the largest integer a spec key, a simulate option or a run count takes (a 64-bit count;
#: a seed takes any size); larger ones reached float conversions (session 44)
INT_MAX = 2**63 - 1


@dataclass(frozen=True)
class Limits:
    """The limits in force (see the module docstring)."""

    max_file_bytes: int = 16 * 1024 * 1024
    max_values: int = 50_000
    max_digits: int = 1000
    max_exponent: int = 1000
    max_depth: int = 32
    max_expr_chars: int = 10_000
    max_expr_depth: int = 200
    max_states: int = 100
    max_sim_bytes: int = 2 * 1024**3


_current = Limits()
_overridden: set[str] = set()

#: the largest value ``--limit`` / :func:`set_limits` accepts for a limit whose raised value
#: would let one number or one nesting hang the tool or exhaust Python's recursion (measured
#: from the CLI, session 25): converting a number's text is quadratic in its digits (10⁶ digits
#: took 45 s, 10⁵ take ~1 s); ``1e-30000000`` took 45 s to reach its "below the float range"
#: refusal (10⁶ take 0.7 s); TOML nested ~500 deep and an expression ~1000 deep ran into
#: RecursionError (the expression as exit 3 inside sympy), reported as "nested more than
#: <the raised limit> levels". The other limits bound sizes the user may raise at will
#: (memory and time grow with them, not without bound for one value).
CEILINGS: dict[str, int] = {
    "max_digits": 100_000,
    "max_exponent": 2**20,  # "1M" on the command line
    "max_depth": 256,
    "max_expr_depth": 400,
}

#: per-method practical state-dimension limits (a method may declare ``max_states`` itself).
#: stubborn: its LMIs (1)-(3) / (7)-(9) go to an interior-point SDP solver many times (the λ
#: search): ~1 min at n = 24 on 2 cores, and n = 100 ran past 300 s with 9.7 GB (stubborn
#: review)
METHOD_MAX_STATES: dict[str, int] = {"set-invariant": 12, "stubborn": 24}


#: Python's recursion limit while obsdesign works: an expression at the depth limit (200,
#: or 400 raised) is walked recursively by the evaluators, several frames a level — a
#: 190-deep ``x1*sin(sin(…))`` in a search-space f was exit 3 "RecursionError" under the
#: default 1000 (CLI hostile-input trial, session 34); 198 levels need ~2,500
RECURSION_LIMIT = 6000


def ensure_recursion_limit() -> None:
    """Raise Python's recursion limit to :data:`RECURSION_LIMIT` (never lower it: a caller's
    higher limit is kept, and threads need no restore)."""
    if sys.getrecursionlimit() < RECURSION_LIMIT:
        sys.setrecursionlimit(RECURSION_LIMIT)


#: a context's own raised limits (:func:`raised`): the API raised the process-wide limits
#: for one object and restored them, and two threads doing so left them raised for the whole
#: process — a 1500-digit number then passed max_digits = 1000 (API review 46)
_RAISED: ContextVar[tuple[Limits, frozenset[str]] | None] = ContextVar(
    "obsdesign_raised_limits", default=None
)


def limits() -> Limits:
    """The limits in force (in this thread or task: :func:`raised` / :func:`applied` ones
    first)."""
    own = _RAISED.get()
    return own[0] if own is not None else _current


def _overridden_now() -> frozenset[str] | set[str]:
    """The limit names given explicitly, in this thread or task (:func:`applied`) first."""
    own = _RAISED.get()
    return own[1] if own is not None else _overridden


@contextmanager
def raised(**values: int) -> Iterator[None]:
    """The limits with ``values`` in force for this thread or task only, within the block
    (each no lower than the limit in force)."""
    now = limits()
    new = replace(now, **{k: max(v, getattr(now, k)) for k, v in values.items()})
    token = _RAISED.set((new, frozenset(_overridden_now())))
    try:
        yield
    finally:
        _RAISED.reset(token)


@contextmanager
def applied(values: Limits, overridden: frozenset[str] | set[str]) -> Iterator[None]:
    """``values`` (with ``overridden``, the names given explicitly) in force for this thread
    or task only, within the block: a Dask task runs with its caller's limits — reset and set
    process-wide, two tasks in the threads of one worker undid each other's, and a row under
    --limit max_digits=2000 was refused at 1000 (re-check review 46)."""
    token = _RAISED.set((values, frozenset(overridden)))
    try:
        yield
    finally:
        _RAISED.reset(token)


def _checked_value(k: str, v: Any) -> int:
    """A limit's value: a whole number ≥ 1 (a float, a string or None was a bare TypeError or
    broke every later design; API review 46)."""
    import numbers

    # any integer type (numpy's too, as the rest of the API takes them), never a bool
    if type(v).__name__ in ("bool", "bool_") or not isinstance(v, numbers.Integral) or v < 1:
        raise InputError(f"limit {k}: expected a whole number ≥ 1, got {v!r}"[:200])
    return int(v)


def set_limits(**values: int) -> Limits:
    """Change limits (``set_limits(max_digits=5000)``); returns the previous ones."""
    global _current
    old = _current
    known = {f.name for f in fields(Limits)}
    for k, v in values.items():
        if k not in known:
            # "limit", not the CLI's "--limit": parse_limit checks --limit first (re-check 46)
            raise InputError(f"limit {k}: unknown limit (known: {', '.join(sorted(known))})")
        values[k] = _checked_value(k, v)
        _check_ceiling(k, values[k], prefix="limit")
    # for reset_limits(old), while old lives (no count cap: a 64-entry table forgot a saved
    # Limits after 64 calls; re-check review 46)
    if id(old) not in _GIVEN:
        weakref.finalize(old, _GIVEN.pop, id(old), None)
    _GIVEN[id(old)] = (weakref.ref(old), frozenset(_overridden))
    _current = replace(_current, **values)
    _overridden.update(values)
    return old


#: the names given explicitly when each Limits that set_limits returned was in force, by
#: the object's id while it lives
_GIVEN: dict[int, tuple[weakref.ref[Limits], frozenset[str]]] = {}


def saved() -> tuple[Limits, frozenset[str]]:
    """The limits in force and the names overridden, for :func:`restore`."""
    return _current, frozenset(_overridden)


def restore(state: tuple[Limits, frozenset[str]]) -> None:
    """Back to a :func:`saved` state: the CLI's ``--limit`` holds for one command (in one
    process, ``CliRunner`` invocations kept the previous command's limits)."""
    global _current
    _current = state[0]
    _overridden.clear()
    _overridden.update(state[1])


def _check_ceiling(k: str, v: int, shown: str | None = None, prefix: str = "--limit") -> None:
    """An :class:`InputError` when ``v`` is above the limit's :data:`CEILINGS` entry
    (``shown``: the value as the user wrote it, else ``v``)."""
    cap = CEILINGS.get(k)
    if cap is not None and v > cap:
        raise InputError(
            f"{prefix} {k}: at most {cap} (above it one value can take minutes or exhaust "
            f"Python's recursion), got {shown if shown is not None else v}"
        )


def reset_limits(old: Limits | None = None) -> None:
    """Back to ``old`` (or to the defaults)."""
    global _current
    _current = old if old is not None else Limits()
    # overridden: as when ``old`` was in force (set_limits returned it), else what differs
    # from the defaults — reset_limits(set_limits(max_states=200)) kept max_states marked
    # overridden, and the per-method caps gave way to 100 for the rest of the process (API
    # review 46); an explicit max_states = 100 stays given (re-check review 46)
    known = _GIVEN.get(id(old)) if old is not None else None
    _overridden.clear()
    if known is not None and known[0]() is old:
        _overridden.update(known[1])
    else:
        defaults = Limits()
        _overridden.update(
            f.name for f in fields(Limits) if getattr(_current, f.name) != getattr(defaults, f.name)
        )


def max_states_for(key: str, declared: int | None = None) -> int:
    """The state-dimension limit of method ``key``: ``--limit max_states`` when given, else
    the method's declared ``max_states``, else :data:`METHOD_MAX_STATES`, else the default."""
    if "max_states" in _overridden_now():
        return limits().max_states
    return int(declared or METHOD_MAX_STATES.get(key, limits().max_states))


def parse_limit(text: str) -> tuple[str, int]:
    """``KEY=VALUE`` of ``--limit`` (VALUE a positive integer, ``16M``/``2G`` allowed)."""
    if "=" not in text:
        raise InputError(f"--limit expects KEY=VALUE, got {text!r}")
    k, v = (s.strip() for s in text.split("=", 1))
    mult = {"k": 1024, "m": 1024**2, "g": 1024**3}.get(v[-1:].lower(), 1)
    num = v[:-1] if mult != 1 else v
    if not num.isascii() or not num.isdigit() or not num.strip("0"):
        raise InputError(f"--limit {k}: expected a positive integer, got {v!r}")
    if k not in {f.name for f in fields(Limits)}:
        known = ", ".join(sorted(f.name for f in fields(Limits)))
        raise InputError(f"--limit {k}: unknown limit (known: {known})")
    if len(num.lstrip("0")) > 18:
        # a positive integer, too large: it said "expected a positive integer" (CLI
        # hostile-input trial, session 34); a limit with a ceiling names it
        _check_ceiling(k, 10**18, v if len(v) <= 40 else f"a {len(num)}-digit number")
        raise InputError(f"--limit {k}: at most 18 digits, got {len(num.lstrip('0'))}")
    _check_ceiling(k, int(num) * mult)
    return k, int(num) * mult


def parse_limits(texts: list[str]) -> dict[str, int]:
    """Every ``--limit KEY=VALUE`` of a command (:func:`parse_limit` each); a key given twice
    is an InputError, as for ``--option`` and ``--set`` (the last one was used without a
    word: re-check review 47)."""
    out: dict[str, int] = {}
    for text in texts:
        k, v = parse_limit(text)
        if k in out:
            raise InputError(f"--limit {k} is given twice ({out[k]}, {v}): give it once")
        out[k] = v
    return out


# -- files ----------------------------------------------------------------------------------
def read_input(path: str | Path, what: str) -> bytes:
    """The bytes of an input file: a regular file (symlinks followed) of at most
    ``max_file_bytes``. Anything else is an :class:`InputError` naming the path; checked
    with ``stat`` before ``open`` so a FIFO, a device or /dev/zero is refused at once."""
    p = Path(path)
    lim = limits().max_file_bytes
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise InputError(f"{p}: no such {what} file") from None
    except OSError as e:
        raise InputError(f"{p}: cannot read {what} ({e.strerror})") from None
    kernel = kernel_dir(p)
    if kernel:
        # /proc/kmsg is a "regular file" of 0 bytes whose read waits for kernel messages
        # (and, as root, consumes them): verify of a report naming it as spec_file, or
        # design /proc/kmsg, hung (CLI review, session 42); `check /proc` walked the
        # process table, a row per unreadable folder (re-check review, session 42)
        raise InputError(f"{p}: is under {kernel} (the kernel's interface), not a {what} file")
    if stat.S_ISDIR(st.st_mode):
        try:
            os.scandir(p).close()
        except OSError as e:  # a subfolder of check's that cannot be listed (api._toml_files)
            raise InputError(
                f"{p}: a folder that cannot be read ({e.strerror}): its specs are not checked"
            ) from None
        raise InputError(f"{p}: is a directory, not a {what} file")
    if not stat.S_ISREG(st.st_mode):
        raise InputError(f"{p}: is not a regular file (refusing to read a {what} file from it)")
    if st.st_size > lim:
        raise InputError(
            f"{p}: {what} file is {st.st_size} bytes, above the limit of {lim} bytes "
            f"(--limit max_file_bytes=N)"
        )
    data = _read_nonblocking(p, what, lim)
    if len(data) > lim:
        raise InputError(f"{p}: {what} file is above the limit of {lim} bytes")
    return data


#: file systems of the kernel's interfaces: their files look regular but may block or change
KERNEL_DIRS = ("/proc", "/sys")


def kernel_dir(p: Path) -> str:
    """The kernel directory (:data:`KERNEL_DIRS`) that ``p`` resolves into, or ""."""
    try:
        real = os.path.realpath(p)
    except OSError:  # a relative path in a removed working folder (re-check review, 44)
        real = os.path.abspath(p) if os.path.isabs(p) else str(p)
    return kernel_dir_of_real(real)


def kernel_dir_of_real(real: str) -> str:
    """The kernel directory (:data:`KERNEL_DIRS`) that the resolved path ``real`` lies in,
    or "" (:func:`kernel_dir` without the resolving: a folder walk extends its parent's real
    path by each real subfolder's name instead of resolving every path again)."""
    return next((d for d in KERNEL_DIRS if real == d or real.startswith(d + "/")), "")


def _read_nonblocking(p: Path, what: str, lim: int) -> bytes:
    """At most ``lim`` + 1 bytes of ``p``, opened with O_NONBLOCK and checked again on the
    open descriptor (a regular file still: the path may have been replaced since ``stat``):
    a file whose read would wait is refused, never waited on."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(p, flags)
    except OSError as e:
        raise InputError(f"{p}: cannot read {what} ({e.strerror})") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise InputError(f"{p}: is not a regular file (refusing to read a {what} file from it)")
        chunks: list[bytes] = []
        got = 0
        while got <= lim:
            try:
                b = os.read(fd, min(lim + 1 - got, 1 << 20))
            except BlockingIOError:
                raise InputError(
                    f"{p}: cannot read {what} (its read would wait: not a plain file)"
                ) from None
            if not b:
                break
            chunks.append(b)
            got += len(b)
        return b"".join(chunks)
    except OSError as e:
        raise InputError(f"{p}: cannot read {what} ({e.strerror})") from None
    finally:
        os.close(fd)


def precheck_spec(path: str | Path) -> None:
    """The cheap checks of a spec file (regular file, size, value count), with nothing but
    the standard library loaded: the CLI runs them before importing numpy and the solvers,
    so that an oversized spec is refused in milliseconds."""
    data = read_input(path, "spec")
    said = values_problem(data.count(b","))
    if said:
        raise InputError(f"{path}: {said}")


def values_problem(commas: int) -> str | None:
    """The refusal of a spec text with ``commas`` commas, None within ``max_values``. The
    count is on the text, before any parse (comments and strings included): a spec of 12
    values with a 60,000-comma comment was refused as "holds about 60019 values" (docs
    review, session 41); the message says what was counted. One wording for the three
    places that count (the file pre-check, the loader, stdin)."""
    lim = limits().max_values
    if commas < lim:
        return None
    return (
        f"has {commas} commas, above the limit of {lim} values (counted on the text, "
        f"comments and strings included; --limit max_values=N)"
    )


# -- numbers --------------------------------------------------------------------------------
def decimal_problem(d: Decimal) -> str | None:
    """Why a Decimal is too big to convert to a rational (None when it is fine)."""
    if not d.is_finite():
        return None
    lim = limits()
    text = str(d)
    if "E" not in text and len(text) <= min(lim.max_digits, lim.max_exponent):
        # plain notation: the digits and |exponent| are at most the length (exactly the
        # verdict below, ~5× faster: a 100-state spec has 10⁴ numbers)
        return None
    t = d.as_tuple()
    digits = len(t.digits)
    exp = int(t.exponent)  # type: ignore[arg-type]
    if digits > lim.max_digits:
        return f"has {digits} digits, above the limit of {lim.max_digits} (--limit max_digits=N)"
    adjusted = exp + digits - 1
    if abs(exp) > lim.max_exponent + lim.max_digits or abs(adjusted) > lim.max_exponent:
        return (
            f"has decimal exponent {adjusted}, outside ±{lim.max_exponent} (--limit max_exponent=N)"
        )
    return None


def exact_digits(obj: Any) -> int:
    """The most decimal digits of an integer in the exact strings (``"p/q"``) under ``obj``
    (a report's ``parameters.exact``: nested dicts and lists). A design's exact values can
    be longer than ``max_digits`` allows a report read back (a set-invariant Q entry 1e-300
    gave 4471-digit vertices; CLI review, session 44)."""
    best = 0
    stack = [obj]
    while stack:
        x = stack.pop()
        if isinstance(x, str):
            if len(x) > best:  # a part is never longer than the string
                for part in x.split("/"):
                    best = max(best, len(part.strip().lstrip("+-")))
        elif isinstance(x, dict):
            stack.extend(x.values())
        elif isinstance(x, (list, tuple)):
            stack.extend(x)
    return best


def int_problem(v: int) -> str | None:
    """Why an int has too many digits (None when it is fine); no decimal conversion made."""
    lim = limits().max_digits
    bits = abs(v).bit_length()
    # up to lim digits for sure below that many bits; else compared exactly with 10^lim (the
    # estimate's slack of one digit let a 1001-digit integer pass the limit of 1000, and
    # max_digits = 1 called 153 "about 2 digits"; CLI trial, session 40)
    if (bits - 1) * 0.30103 < lim - 1 or abs(v) < 10**lim:
        return None
    # v ≥ 2^(bits − 1); 0.3010299956 < log10 2 keeps it a lower bound (0.30103 is above it:
    # 2^13301 has 4004 digits and was "at least 4005"; re-check trial, session 40)
    least = max(lim + 1, int((bits - 1) * 0.3010299956) + 1)
    return f"has at least {least} digits, above the limit of {lim} (--limit max_digits=N)"


_NUM = re.compile(
    r"^\s*[+-]?(?:(\d+)(?:\.(\d*))?|\.(\d+))(?:[eE]([+-]?\d+))?\s*$"  # decimal
)
_NUMBERISH = re.compile(r"^[\s0-9+\-./eE_]*$")
_FRAC = re.compile(r"^\s*[+-]?(\d+)\s*/\s*[+-]?(\d+)\s*$")


def number_text_problem(s: str) -> str | None:
    """Why the text of an exact number ("p/q" or a decimal) is too big to convert (None when
    fine or when it is not a number at all: the converter then says so)."""
    lim = limits()
    if len(s) <= min(lim.max_digits, lim.max_exponent) and "e" not in s and "E" not in s:
        # no exponent: digits ≤ length (the verdict below, without the regexes; a 100-state
        # report has 2×10⁴ exact strings)
        return None
    if not _NUMBERISH.match(s):
        return None
    if len(s) > 4 * (lim.max_digits + 20):
        return f"is {len(s)} characters long, above the limit for a number (--limit max_digits=N)"
    m = _FRAC.match(s)
    if m:
        for g in m.groups():
            if len(g.lstrip("0")) > lim.max_digits:
                return f"has more than {lim.max_digits} digits (--limit max_digits=N)"
        return None
    m = _NUM.match(s.replace("_", ""))
    if not m:
        return None
    ip, fp, fp2, ex = m.groups()
    digits = len((ip or "") + (fp or "") + (fp2 or "")) if (ip or fp or fp2) else 0
    if digits > lim.max_digits:
        return f"has {digits} digits, above the limit of {lim.max_digits} (--limit max_digits=N)"
    if ex is not None:
        if len(ex.lstrip("+-").lstrip("0")) > 9 or abs(int(ex)) > lim.max_exponent + digits:
            return (
                f"has decimal exponent {ex}, outside ±{lim.max_exponent} (--limit max_exponent=N)"
            )
    return None


@contextmanager
def int_digits() -> Iterator[None]:
    """Let the parsers read integers up to ``max_digits`` digits when that is above Python's
    int-string limit (4300 by default); the digit count is then checked by the walker."""
    get = getattr(sys, "get_int_max_str_digits", None)
    old = get() if get is not None else 0
    need = limits().max_digits + 1
    if get is None or old == 0 or old >= need:
        yield
        return
    sys.set_int_max_str_digits(need)
    try:
        yield
    finally:
        sys.set_int_max_str_digits(old)


@contextmanager
def own_int_digits() -> Iterator[None]:
    """No int-string limit while the tool writes numbers it made itself (a report's exact
    values): a design of a spec with 5040-digit numbers, allowed by --limit max_digits=6000,
    ended in exit 3 "Exceeds the limit (4300 digits) for integer string conversion" while
    writing its report (re-check trial, session 29). Input is never read under it."""
    get = getattr(sys, "get_int_max_str_digits", None)
    old = get() if get is not None else 0
    if get is None or old == 0:
        yield
        return
    sys.set_int_max_str_digits(0)
    try:
        yield
    finally:
        sys.set_int_max_str_digits(old)


# -- nesting --------------------------------------------------------------------------------
# A node of the walk is (parent node, key, is_dict_key) or None for the top: the key path is
# only spelled out for the node that breaks a limit (building ~10⁵ path strings for a
# 100-state report cost more than the checks).
_Node = tuple[Any, Any, bool] | None


def _path(node: _Node) -> str:
    parts: list[tuple[Any, bool]] = []
    while node is not None:
        node, key, is_key = node
        parts.append((key, is_key))
    out = ""
    for key, is_key in reversed(parts):
        out = (f"{out}.{key}" if out else str(key)) if is_key else f"{out}[{key}]"
    return out


def walk(data: Any) -> Iterator[tuple[str, Any, int]]:
    """Every (key path, value, depth) of nested dicts/lists, iteratively (no recursion)."""
    for node, v, depth in _walk(data):
        yield _path(node), v, depth


def _walk(
    data: Any, skip_at: int | None = None, skip: tuple[type, ...] = ()
) -> Iterator[tuple[_Node, Any, int]]:
    """(node, value, depth) of nested dicts/lists, depth first, iteratively; list entries
    of exactly the types ``skip`` are not visited at depths up to ``skip_at`` (the caller
    says they can break no limit there)."""
    stack: list[tuple[_Node, Any, int]] = [(None, data, 0)]
    while stack:
        node, v, depth = stack.pop()
        yield node, v, depth
        if isinstance(v, dict):
            for k, x in v.items():
                stack.append(((node, k, True), x, depth + 1))
        elif isinstance(v, list):
            leaves = skip_at is not None and depth + 1 <= skip_at
            for i, x in enumerate(v):
                if not (leaves and type(x) in skip):
                    stack.append(((node, i, False), x, depth + 1))


def data_problem(data: Any, exact_strings: bool = False) -> tuple[str, str] | None:
    """The first (key path, reason) where parsed TOML/JSON data breaks a limit: nesting
    depth, digits or exponent of a number (Decimal or int), and, with ``exact_strings``,
    the text of a string that reads as a number.

    The entries of a list are checked in the list's own loop (a 100-state report has 2×10⁴
    exact strings: one stack frame each cost more than the checks); dicts and nested lists
    are walked iteratively, depth first."""
    lim = limits()
    max_depth = lim.max_depth
    short = min(lim.max_digits, lim.max_exponent)
    stack: list[tuple[_Node, Any, int]] = [(None, data, 0)]
    while stack:
        node, v, depth = stack.pop()
        if depth > max_depth:
            return _too_deep(node, max_depth)
        if isinstance(v, dict):
            if v and depth + 1 > max_depth:
                return _too_deep((node, next(reversed(v)), True), max_depth)
            for k, x in v.items():
                t = type(x)
                if t is float or t is bool:
                    continue  # never a problem: not pushed (a report's claims hold ~10² such)
                if t is str and (
                    not exact_strings or (len(x) <= short and "e" not in x and "E" not in x)
                ):
                    continue  # number_text_problem's own first test, inline
                stack.append(((node, k, True), x, depth + 1))
            continue
        if isinstance(v, list):
            if v and depth + 1 > max_depth:
                return _too_deep((node, 0, False), max_depth)
            # whole lists the loop below would pass entry by entry, decided at C speed: all
            # floats / booleans, or all strings that pass the inline test of the loop (a
            # report's 10⁴-entry rows of floats and of exact "p/q" strings)
            kinds = set(map(type, v))
            if kinds <= _NEVER_A_PROBLEM:
                continue
            if kinds == _STRINGS and (
                not exact_strings or (max(map(len, v)) <= short and _no_exponent("".join(v)))
            ):
                continue
            for i, x in enumerate(v):
                t = type(x)
                if t is float or t is bool:
                    continue
                if t is str and (
                    not exact_strings or (len(x) <= short and "e" not in x and "E" not in x)
                ):
                    continue  # number_text_problem's own first test, inline
                if t is Decimal:
                    text = str(x)  # decimal_problem's own first test, inline
                    if "E" not in text and len(text) <= short:
                        continue
                if t is list or t is dict or isinstance(x, (list, dict)):
                    stack.append(((node, i, False), x, depth + 1))
                    continue
                why = _leaf_problem(x, exact_strings)
                if why:
                    return _path((node, i, False)) or "(top)", why
            continue
        why = _leaf_problem(v, exact_strings)
        if why:
            return _path(node) or "(top)", why
    return None


_NEVER_A_PROBLEM = {float, bool}
_STRINGS = {str}


def _no_exponent(text: str) -> bool:
    return "e" not in text and "E" not in text


def _too_deep(node: _Node, max_depth: int) -> tuple[str, str]:
    return _path(node).split("[")[0] or "(top)", (
        f"is nested more than {max_depth} levels deep (--limit max_depth=N)"
    )


def _leaf_problem(v: Any, exact_strings: bool) -> str | None:
    """Why one number (or, with ``exact_strings``, one number's text) breaks a limit."""
    if isinstance(v, bool):
        return None
    if isinstance(v, Decimal):
        return decimal_problem(v)
    if isinstance(v, int):
        return int_problem(v)
    if exact_strings and isinstance(v, str):
        return number_text_problem(v)
    return None
