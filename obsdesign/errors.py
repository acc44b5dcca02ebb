"""Error types and the exit codes they map to (DESIGN.md, "Exit codes and output").

0 ok; 1 infeasible design or a failed claim; 2 bad input; 3 solver or internal failure;
4 numerically inconclusive (a candidate the exact check could not certify).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

EXIT_OK = 0
EXIT_INFEASIBLE = 1
EXIT_BAD_INPUT = 2
EXIT_SOLVER = 3
EXIT_INCONCLUSIVE = 4


#: runs of digits at least this long are shortened in messages
#: a run of 100 or more digits (a number grouped by thousands separators is not one: its
#: printers keep it short, :func:`count_text`; a pattern for groups also caught lists of
#: 3-digit numbers, "100,101,…": re-check review, session 44)
_LONG_DIGITS = re.compile(r"\d{100,}")


def _escape_char(c: str) -> str:
    if c in "\n\r\t":
        return {"\n": "\\n", "\r": "\\r", "\t": "\\t"}[c]
    o = ord(c)
    return f"\\x{o:02x}" if o < 0x100 else f"\\u{o:04x}"


def escape_controls(text: str) -> str:
    """``text`` with control characters (newline, ESC, …) and Unicode line/paragraph
    separators written as escapes (``\\n``, ``\\x1b``), everything else as it is: for
    user-given names in tables and progress lines (:func:`one_line` for messages). A byte of
    a file name that is not UTF-8 (a lone surrogate) is written ``\\xNN`` as in reports
    (:func:`valid_text`): error lines showed ``\\udcff`` where the JSON showed ``\\xff`` (CLI
    review 46)."""
    return _CONTROLS.sub(lambda m: _escape_char(m[0]), valid_text(text))


#: the characters of Unicode categories Cc, Zl and Zp, and the bidirectional controls of Cf
#: (LRM, RLM, the embeddings, overrides and isolates: U+202E in a file name reordered the rest
#: of check's row and of the Markdown report in bidi-aware viewers, "Trojan Source" style;
#: rendering trial, session 27), and the invisible format characters of Cf that no text needs
#: (zero-width space, word joiner, invisible operators, BOM: a parameter "mu\u200b" showed as a
#: second "mu" row; verify trial, session 35): what :func:`escape_controls` escapes. The soft
#: hyphen and the zero-width (non-)joiner, which Persian, Indic and emoji text use, stay.
_CONTROLS = re.compile(
    "[\x00-\x1f\x7f-\x9f\u061c\u180e\u200b\u200e\u200f\u2028\u2029\u202a-\u202e"
    "\u2060-\u2064\u2066-\u206f\ufeff\ufff9-\ufffb]"
)


def ascii_name(text: str) -> str:
    """``text`` with every character outside ASCII written as an escape (``\\u0420``): for
    names a report adds that no check reads, where a Cyrillic "Р" showed as the method's "P"
    (verify trial, session 35). The method's own names are ASCII."""
    return escape_controls(text).encode("ascii", "backslashreplace").decode("ascii")


def valid_text(text: str) -> str:
    """``text`` as valid Unicode: a file name that is not UTF-8 reaches Python as lone
    surrogates (``a\udcff.toml``), which no UTF-8 output can hold (``design -o`` of such a
    spec ended with exit 3 "UnicodeEncodeError … surrogates not allowed" and no report:
    session 40); each such byte is written as ``\xff``. Ordinary text is returned as is."""
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        try:
            return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
        except UnicodeEncodeError:  # a surrogate that is not a byte's escape (\ud800)
            return text.encode("utf-8", "backslashreplace").decode("utf-8")


def valid_strings(obj: Any) -> Any:
    """``obj`` (JSON data: dicts, lists, strings, numbers) with every string and key passed
    through :func:`valid_text`."""
    if isinstance(obj, str):
        return valid_text(obj)
    if isinstance(obj, dict):
        return {
            valid_text(k) if isinstance(k, str) else k: valid_strings(v) for k, v in obj.items()
        }
    if isinstance(obj, (list, tuple)):
        return [valid_strings(v) for v in obj]
    return obj


def _shorten_digits(m: re.Match[str]) -> str:
    """A long digit run as its first 20 digits and its length."""
    return f"{m[0][:20]}…({len(m[0])} digits)"


def count_text(n: int) -> str:
    """An integer count for a message: with thousands separators, or, from 100 digits on, its
    first 20 digits and its length as :func:`one_line` shortens a digit run (``{n:,}`` of a
    400-digit theta_m printed 533 characters; CLI review, session 44)."""
    if abs(n) < 10**99:
        return f"{n:,}"
    import sys

    get = getattr(sys, "get_int_max_str_digits", None)
    if get is not None and get() and n.bit_length() > 3.3 * get():
        return f"{'-' if n < 0 else ''}a number of about {int(n.bit_length() * 0.30103)} digits"
    digits = str(abs(n))
    return f"{'-' if n < 0 else ''}{digits[:20]}…({len(digits)} digits)"


def one_line(message: str) -> str:
    """``message`` safe to print as one line: control characters (newline, ESC, …) and
    Unicode line/paragraph separators from user-given names (TOML keys, file names) are
    written as escapes, so a key cannot break the line or drive the terminal; a run of 100 or
    more digits (a 5000-digit number from a file) is shortened to its first 20 digits and
    its length; a line longer than :data:`MAX_LINE` characters keeps its start and end
    around "…(N characters)…" (a 5-million-character TOML key was echoed whole;
    hostile-input trial, session 24). Idempotent on ordinary text."""
    out = escape_controls(message)
    out = _LONG_DIGITS.sub(_shorten_digits, out)
    if len(out) > MAX_LINE:
        cut = len(out) - MAX_LINE // 2 - MAX_LINE // 4
        out = f"{out[: MAX_LINE // 2]}…({cut} characters)…{out[-(MAX_LINE // 4) :]}"
    return out


#: the longest message line printed whole (:func:`one_line`)
MAX_LINE = 2000


class ObsdesignError(Exception):
    """Base class: carries the exit code and a one-line message for the user (made one line
    by :func:`one_line`)."""

    exit_code: int = EXIT_SOLVER
    #: the ``[method].key`` of the spec the error arose in, when the spec was parsed far
    #: enough to say it (set by the loader and the method binding): ``check`` and ``sweep``
    #: rows of bad input name the method instead of "?"
    method_key: str | None = None
    #: what the design tried before it stopped (a :class:`obsdesign.params.Parameters`, not
    #: certified), written to the error report's ``parameters`` so that a user can retry
    #: with it (the lyapunov method's designed L); None: nothing worth keeping
    candidate: Any = None

    def __init__(self, message: str) -> None:
        message = one_line(message)
        super().__init__(message)
        self.message = message


class SpecError(ObsdesignError):
    """Bad input: a spec or report file that is malformed. Message names file and key."""

    exit_code = EXIT_BAD_INPUT

    def __init__(self, file: str, key: str, expected: str) -> None:
        where = f"{file}: [{key}]" if key else f"{file}:"
        super().__init__(f"{where} {expected}")
        self.file = file
        self.key = key
        self.expected = expected


class InputError(ObsdesignError):
    """Bad input that is not tied to a spec key (missing file, bad report JSON, ...)."""

    exit_code = EXIT_BAD_INPUT


class InfeasibleError(ObsdesignError):
    """The design problem has no solution; the message says which condition fails."""

    exit_code = EXIT_INFEASIBLE


class SolverError(ObsdesignError):
    """A numerical solver failed in a way that says nothing about feasibility."""

    exit_code = EXIT_SOLVER


class InconclusiveError(ObsdesignError):
    """A candidate was found but the exact check could not certify it."""

    exit_code = EXIT_INCONCLUSIVE


def json_safe(o: Any, default: Callable[[Any], Any] | None = None) -> Any:
    """``o`` with every non-finite float written as the string ``"nan"``, ``"inf"`` or
    ``"-inf"`` (Python's own spelling, which ``float()`` reads back), containers walked, and
    what JSON cannot hold passed through ``default`` first; strings made valid Unicode (a
    non-UTF-8 spec file name in a row's message: :func:`valid_text`). JSON has no NaN or
    Infinity: a non-finite metric (independent simulate review) or a report's unread 1e400
    (tamper review 45) was printed as such, which strict readers refuse."""
    import math

    if isinstance(o, bool) or o is None or isinstance(o, int):
        return o
    if isinstance(o, str):
        return valid_text(o)
    if isinstance(o, float):
        return o if math.isfinite(o) else repr(o)
    if isinstance(o, dict):
        return {valid_text(str(k)): json_safe(v, default) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [json_safe(v, default) for v in o]
    if default is None:
        return o
    return json_safe(default(o), None)


def value_text(v: Any) -> str:
    """``repr(v)`` for a message, an integer of 100 digits or more as :func:`count_text`
    shortens it: repr of an int past Python's 4,300-digit limit is itself a ValueError
    (``seed=10**4301`` was a bare ValueError from the message; re-check review 45)."""
    if isinstance(v, int) and not isinstance(v, bool) and abs(v) >= 10**99:
        return count_text(v)
    return repr(v)
