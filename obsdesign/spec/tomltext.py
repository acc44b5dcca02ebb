"""Where the statements of a TOML text are: headers and key/value pairs with the exact span
of each value, for editing a spec's text in place (``obsdesign sweep``).

A one-pass lexer of TOML 1.0's layout: strings of the four kinds (with escapes in basic
ones), arrays and inline tables nested to any depth, comments. It does not validate (a
malformed text is refused by the TOML parser that reads the edited text back); it only
finds where each statement and value starts and ends, in time linear in the text. Line-based
guesses were wrong three ways (outsider trial, session 26): a multi-line string further down
moved the end of a value, a matrix row on a line of its own (``  [1, 0]``) was taken for a
table header, and ``\"\"\"`` inside a literal string for the start of a multi-line string.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass

# the rest of a string after its opening delimiter, through the closing one (a multi-line
# string may end with one or two quotes next to its delimiter)
_ML_BASIC = re.compile(r'(?:[^"\\]|\\.|"(?!""))*"""(?:"{1,2}(?!"))?', re.S)
_ML_LITERAL = re.compile(r"(?:[^']|'(?!''))*'''(?:'{1,2}(?!'))?", re.S)
_BASIC = re.compile(r'(?:[^"\\\n]|\\.)*"')
_LITERAL = re.compile(r"[^'\n]*'")
_PLAIN = re.compile(r"[^\[\]{}\"'#]+")  # inside an array or inline table
_SCALAR = re.compile(r"[^#\n]*")
_KEY = re.compile(r"[^=\"'\n#\[]+")


@dataclass(frozen=True)
class Statement:
    """One statement: a ``[table]`` or ``[[array of tables]]`` header (``value_*`` = -1), or
    a key/value pair. ``key`` is the dotted key's parts (None when its text does not parse);
    ``start`` the statement's first character; ``value_start``/``value_end`` the value's
    span; ``end`` the end of its last line (before the newline, after any comment)."""

    kind: str  # "table", "aot" or "keyval"
    key: tuple[str, ...] | None
    start: int
    value_start: int
    value_end: int
    end: int


def string_end(t: str, i: int) -> int:
    """Index just past the string whose opening quote is ``t[i]`` (the text's end when it is
    not closed)."""
    if t.startswith('"""', i):
        m = _ML_BASIC.match(t, i + 3)
    elif t.startswith("'''", i):
        m = _ML_LITERAL.match(t, i + 3)
    elif t[i] == '"':
        m = _BASIC.match(t, i + 1)
    else:
        m = _LITERAL.match(t, i + 1)
    return m.end() if m else len(t)


def _line_end(t: str, i: int) -> int:
    k = t.find("\n", i)
    return len(t) if k < 0 else k


def value_end(t: str, i: int) -> int:
    """Index just past the TOML value that starts at ``t[i]`` (after spaces): a string, an
    array or inline table (brackets counted outside strings and comments), or a scalar up to
    a comment or the end of its line (trailing spaces excluded)."""
    n = len(t)
    while i < n and t[i] in " \t":
        i += 1
    if i >= n:
        return n
    c = t[i]
    if c in "\"'":
        return string_end(t, i)
    if c in "[{":
        depth = 0
        while i < n:
            c = t[i]
            if c in "[{":
                depth += 1
                i += 1
            elif c in "]}":
                depth -= 1
                i += 1
                if depth == 0:
                    return i
            elif c in "\"'":
                i = string_end(t, i)
            elif c == "#":
                i = _line_end(t, i)
            else:
                m = _PLAIN.match(t, i)
                i = m.end() if m else i + 1
        return n
    end = _SCALAR.match(t, i).end()  # type: ignore[union-attr]
    while end > i and t[end - 1] in " \t\r":
        end -= 1
    return end


def key_parts(text: str) -> tuple[str, ...] | None:
    """The parts of a dotted key (bare or quoted), or None when it is not a key."""
    text = text.strip()
    if not text:
        return None
    if '"' not in text and "'" not in text:
        parts = tuple(p.strip() for p in text.split("."))
        return parts if all(re.fullmatch(r"[A-Za-z0-9_-]+", p) for p in parts) else None
    try:
        d = tomllib.loads(f"{text} = 0")
    except ValueError:
        return None
    out: list[str] = []
    while isinstance(d, dict) and len(d) == 1:
        ((k, d),) = d.items()
        out.append(k)
    return tuple(out) if d == 0 and out else None


def _key_text_end(t: str, i: int) -> int:
    """Index of the '=' (or of the line's end) after the key that starts at ``t[i]``."""
    n = len(t)
    while i < n:
        c = t[i]
        if c in "\"'":
            i = string_end(t, i)
        elif c in "=\n#":
            return i
        else:
            m = _KEY.match(t, i)
            i = m.end() if m else i + 1
    return n


def statements(t: str) -> list[Statement]:
    """Every header and key/value pair of the TOML text ``t``, in order."""
    out: list[Statement] = []
    n, i = len(t), 0
    while i < n:
        c = t[i]
        if c in " \t\r\n":
            i += 1
            continue
        if c == "#":
            i = _line_end(t, i)
            continue
        if c == "[":
            aot = t.startswith("[[", i)
            j = i + (2 if aot else 1)
            k = j
            while k < n and t[k] not in "]\n":
                k = string_end(t, k) if t[k] in "\"'" else k + 1
            name = key_parts(t[j:k])
            end = _line_end(t, k)
            out.append(Statement("aot" if aot else "table", name, i, -1, -1, end))
            i = end
            continue
        k = _key_text_end(t, i)
        if k >= n or t[k] != "=":  # not a statement TOML accepts: skip the line
            i = _line_end(t, k)
            continue
        v0 = k + 1
        while v0 < n and t[v0] in " \t":
            v0 += 1
        v1 = value_end(t, v0)
        end = _line_end(t, v1)
        out.append(Statement("keyval", key_parts(t[i:k]), i, v0, v1, end))
        i = end
    return out
