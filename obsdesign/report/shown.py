"""Parameter values as tables and one-line summaries show them: short decimals, marked "≈"
whenever the decimal shown is not the value itself.

A parameter table or a ``check`` summary prints a few significant digits of a value the report
holds exactly. Rounded to nearest, a bound can land on its unsafe side: a certified decay rate
α = 2.16666655 was shown as "2.16667 exact", a rate its own bracket claim proves infeasible,
and "κ = 2, κ_n = 2" read as condition (22) of the impulsive paper failing (rendering trial,
session 27). Statements keep their directed rounding (:mod:`obsdesign.certify.printing`); here
the number's role is not known, so the mark says that the shown decimal is rounded.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from obsdesign.certify.exact import Q

#: the mark of a rounded value
APPROX = "≈"


def _entry(exact: Any, value: float, fmt: str) -> tuple[str, bool]:
    """One number: its text in ``fmt`` and whether that text's decimal is the exact value
    (``exact``: an ``fmpq`` or int, compared exactly, or a float, which the text must read
    back as; ``value``: its float, made by the caller)."""
    text = format(value, fmt)
    if isinstance(exact, float):  # a float parameter: the text reads back as that float
        return text, float(text) == exact or (exact != exact and value != value)
    if not math.isfinite(value):  # an exact value beyond the float range
        return text, False
    return text, Q(text) == Q(exact)


def shown(raw: Any, floats: Any, fmt: str = ".6g") -> tuple[str, bool]:
    """The text of a numeric parameter (a scalar, or a vector / matrix as ``[a, b; c, d]``,
    rows separated by ';') with each entry in ``fmt``, and whether every entry shown is
    the value held (exactly, for an exact parameter; for a float one, a decimal that reads
    back as that float). ``raw`` is the held value, ``floats`` its float view (same shape)."""
    f = np.asarray(floats, dtype=float)
    r = np.asarray(raw, dtype=object).reshape(f.shape) if f.ndim else raw
    if f.ndim == 0:
        return _entry(r, float(f), fmt)
    rows_f = f if f.ndim == 2 else f.reshape(1, -1)
    rows_r = r if f.ndim == 2 else r.reshape(1, -1)
    same = True
    texts = []
    for rf, rr in zip(rows_f, rows_r, strict=True):
        row = []
        for x, q in zip(rf, rr, strict=True):
            if same:
                t, same = _entry(q, float(x), fmt)
            else:  # one rounded entry marks the whole value: the rest need no exact compare
                t = format(float(x), fmt)
            row.append(t)
        texts.append(", ".join(row))
    return "[" + "; ".join(texts) + "]", same


def cell(raw: Any, floats: Any, fmt: str = ".6g", side: str = "") -> str:
    """A table cell: :func:`shown`'s text, prefixed "≈ " when rounded; with ``side`` "up"
    ("down") an exact scalar is rounded up (down) and prefixed "≤ " ("≥ "), as
    :func:`item` does."""
    text, same = shown(raw, floats, fmt)
    bound = None if same else _one_sided(raw, floats, fmt, side)
    if bound is not None:
        return bound
    return text if same else f"{APPROX} {text}"


def _one_sided(raw: Any, floats: Any, fmt: str, side: str) -> str | None:
    """ "≤ text" (side "up") or "≥ text" (side "down") for an exact scalar rounded that way
    to ``fmt``'s digits; None for another side, a vector, or a value that is not exact."""
    if side not in ("up", "down") or np.ndim(floats) != 0:
        return None
    directed = _directed(raw, fmt, side == "up")
    return None if directed is None else f"{'≤' if side == 'up' else '≥'} {directed}"


def item(label: str, raw: Any, floats: Any, fmt: str, side: str = "") -> str:
    """A summary item: ``label = text`` when the text is the value, else ``label ≈ text``;
    with ``side`` "up" ("down") an exact scalar rounded for the text is rounded up (down)
    to ``fmt``'s digits and shown ``label ≤ text`` (``label ≥ text``)."""
    text, same = shown(raw, floats, fmt)
    bound = None if same else _one_sided(raw, floats, fmt, side)
    if bound is not None:
        return f"{label} {bound}"
    return f"{label} {'=' if same else APPROX} {text}"


def _directed(raw: Any, fmt: str, up: bool) -> str | None:
    """``raw`` (exact) rounded up or down to the significant digits of ``fmt`` (".4g": 4;
    other formats: 6), printed in ``fmt``; None for a value that is not exact and finite."""
    from obsdesign.certify.printing import fmt_down, fmt_up

    if isinstance(raw, (float, bool)) or raw is None:
        return None
    try:
        q = Q(raw)
    except (TypeError, ValueError):
        return None
    m = re.fullmatch(r"\.(\d+)g", fmt)
    digits = int(m[1]) if m else 6
    d = Q(fmt_up(q, digits) if up else fmt_down(q, digits))
    text = format(float(d), fmt)
    return text if Q(text) == d else str(d)
