"""Renderers: rich terminal tables and Markdown."""

from __future__ import annotations

from typing import Any

import numpy as np

from obsdesign.certify.claim import ClaimStatus
from obsdesign.errors import ascii_name
from obsdesign.report.model import Report
from obsdesign.report.shown import cell

STYLE = {
    ClaimStatus.CERTIFIED: "green",
    ClaimStatus.NUMERICAL: "yellow",
    ClaimStatus.FAILED: "bold red",
}


def fmt_value(v: Any, digits: int = 6) -> str:
    """Compact float rendering of a parameter (matrices row by row)."""
    if isinstance(v, (int, float, np.floating, np.integer)) and not isinstance(v, bool):
        return f"{float(v):.{digits}g}"
    try:
        arr = np.asarray(v)
    except (ValueError, TypeError):  # a ragged list from a report: exit 3 in verify's table
        arr = np.asarray(None)  # (re-check trial, session 27): shown as text below
    if arr.dtype.kind in "fiu" and arr.ndim in (1, 2):
        if arr.ndim == 1:
            return "[" + ", ".join(f"{x:.{digits}g}" for x in arr) + "]"
        return "[" + "; ".join(", ".join(f"{x:.{digits}g}" for x in row) for row in arr) + "]"
    s = str(v)
    return s if len(s) < 200 else s[:197] + "..."


def _sides(method: str) -> dict[str, str]:
    """Parameter → the side its rounding keeps statements true on ("up" / "down"), from the
    method's summary fields (:class:`obsdesign.methods.base.SummaryField`); none for an
    unknown method."""
    try:
        from obsdesign.methods import get_method

        fields = get_method(method).summary_fields
    except Exception:  # noqa: BLE001 - an unknown or hostile method name: no sides
        return {}
    return {f.param: f.side for f in fields if f.side}


def _param_rows(report: Report, most: int | None = None) -> list[tuple[str, str, str]]:
    """(name, value, form) of the report's parameters, at most ``most`` of them (all when
    None): 100,000 parameters took 54 s, each row built and looked up in a list (CLI review
    45). Cut to ``most``, the verified parameters come first, in report order: 600 unread
    parameters before L and P filled the table and hid every verified one (re-check review
    46)."""
    rows = []
    sides = _sides(report.method)
    unverified = set(report.unverified)
    keys = list(report.parameters)
    if most is not None and len(keys) > most:
        keys = [k for k in keys if k not in unverified] + [k for k in keys if k in unverified]
        keys = keys[:most]
    for k in keys:
        raw = report.parameters[k]
        # a rounded number is marked "≈" (a certified α = 2.16666655 showed as "2.16667",
        # a proven-infeasible rate: rendering trial, session 27); a one-sided bound is
        # rounded to its safe side, "≥ 0.608686" for T_max = 0.6086869942…, not "≈ 0.608687"
        # above the limit of (26b) (soundness trial, session 34)
        text = (
            cell(raw, report.parameters.float(k), side=sides.get(k, ""))
            if _numeric(raw)
            else fmt_value(raw)
        )
        # a text or true/false parameter is neither exact nor float (a bracket's kind showed
        # "float": docs trial, session 31)
        form = "exact" if report.parameters.is_exact(k) else "float" if _numeric(raw) else "text"
        name = k
        if k in unverified:
            form = "not verified"
            name = ascii_name(k)  # a Cyrillic "Р" showed as the method's "P" (session 35)
        rows.append((name, text, form))
    return rows


def esc(text: Any) -> str:
    """Text with rich markup escaped: ``[system.A]`` prints as it is; control characters
    as escapes (a spec file named with ESC drove the terminal from ``check``'s table and
    ``design``'s title; outsider trial, session 26)."""
    from rich.markup import escape

    from obsdesign.errors import escape_controls

    return escape(escape_controls(str(text)))


def _numeric(v: Any) -> bool:
    """A number or an array of numbers (not a bool, not text that reads as one)."""
    if v is None or isinstance(v, (bool, np.bool_, str, bytes)):  # None read as nan: "≈ nan"
        return False
    try:
        np.asarray(
            v if not isinstance(v, np.ndarray) or v.dtype != object else v.astype(float),
            dtype=float,
        )
        return True
    except (TypeError, ValueError):
        return False


#: ``--width N`` of the command line (None: see :func:`width`)
_WIDTH: dict[str, int | None] = {"width": None}
#: the narrowest table width (``--width`` refuses less; COLUMNS or a terminal below it get it)
MIN_WIDTH = 40
#: width of tables when stdout is not a terminal and COLUMNS is not set (CI logs, pipes)
DEFAULT_WIDTH = 100
#: below this width the claims table puts check and detail under the statement
NARROW = 120
#: below this width the parameters table puts each parameter's form under its name
NARROW_PARAMS = 72


def set_width(n: int | None) -> None:
    """Fix the width of rendered tables (``--width N``); None restores the default."""
    _WIDTH["width"] = n


def stderr_console() -> Any:
    """A rich console on stderr for progress bars, ``--width`` columns wide when given (else
    rich's own: the terminal's, or COLUMNS) — the bars ignored --width (session 45's note)."""
    import sys

    from rich.console import Console

    return Console(file=sys.stderr, width=_WIDTH["width"])


def width() -> int | None:
    """The table width: ``--width`` if given, else ``COLUMNS`` if set to a positive number,
    else the terminal's width (None: rich asks the terminal) when stdout is a terminal, else
    :data:`DEFAULT_WIDTH` columns; never below :data:`MIN_WIDTH`."""
    import os
    import sys

    if _WIDTH["width"] is not None:
        return _WIDTH["width"]
    env = os.environ.get("COLUMNS", "").strip()
    if env.isdigit() and int(env) > 0:
        # at least MIN_WIDTH, as --width: COLUMNS=20 wrapped every cell to 6 characters
        # (outsider trial, session 29)
        return max(MIN_WIDTH, int(env))
    if not sys.stdout.isatty():
        return DEFAULT_WIDTH
    import shutil

    cols = shutil.get_terminal_size((DEFAULT_WIDTH, 24)).columns
    return None if cols >= MIN_WIDTH else MIN_WIDTH


def console() -> Any:
    """A rich console of :func:`width` columns. It highlights (numbers, strings, ...) only
    where it prints styles at all: without a colour system (not a terminal: a pipe, a file,
    CI) highlighting would not change a byte, and compiling its patterns costs ~10 ms of a
    cold ``obsdesign design``."""
    from rich.console import Console

    class _Console(Console):
        def on_broken_pipe(self) -> None:
            """The reader of stdout went away: raise it to the CLI, which exits 141. rich's own
            handler exits 1, the code of a failed claim (``verify r.json | head -1`` of a
            good report exited 1; soundness trial, session 34)."""
            self.quiet = True
            raise BrokenPipeError

    out = _Console(width=width())
    return out if out.color_system is not None else _Console(width=width(), highlight=False)


def verdict_line(report: Report, verb: str = "verified") -> str:
    """The one-line verdict printed last by ``verify``: ``verified: 8 claims certified,
    0 failed`` (numerical claims named when there are any; ``NOT verified`` when a claim
    failed or the design stopped with an error)."""
    n = report.status_counts()
    ok = report.exit_code() == 0
    parts = [f"{n['certified']} claim{'s' if n['certified'] != 1 else ''} certified"]
    if n["numerical"]:
        parts.append(f"{n['numerical']} numerical")
    parts.append(f"{n['failed']} failed")
    head = verb if ok else f"NOT {verb}"
    if report.error is not None:
        head += f" (design stopped with exit {report.error.get('exit_code', '?')})"
    return f"{head}: {', '.join(parts)}"


#: the most rows of a text report's parameter and claim tables: rich lays a row out in ~2 ms,
#: and a 9 MB report padded with 100,000 claims took 3.7 minutes to print its verify (tamper
#: review 45); past it, every failed claim is kept (in order) and a line counts the rest
TEXT_MAX_ROWS = 500


def _shown_claims(claims: list[Any]) -> list[Any]:
    """At most :data:`TEXT_MAX_ROWS` of ``claims`` in their order: every failed one first
    (up to the cap), then the others."""
    if len(claims) <= TEXT_MAX_ROWS:
        return list(claims)
    failed = [i for i, cl in enumerate(claims) if cl.status is ClaimStatus.FAILED]
    rest = [i for i, cl in enumerate(claims) if cl.status is not ClaimStatus.FAILED]
    keep = sorted((failed + rest)[:TEXT_MAX_ROWS])
    return [claims[i] for i in keep]


def render_text(report: Report, title: str = "") -> None:
    """Print a report on the terminal with rich (at most :data:`TEXT_MAX_ROWS` rows a
    table; ``--format json`` or ``md`` list everything)."""
    from rich.table import Table

    out = console()
    t = Table(title=esc(title or f"{report.method} — {report.spec_file}"), show_lines=False)
    rows = _param_rows(report, TEXT_MAX_ROWS)
    hidden_params = len(report.parameters) - len(rows)
    if out.width < NARROW_PARAMS:
        # two columns, the form under the name: three equal columns at --width 40 cut names
        # ("lambda_br…" for both lambda_bracket and lambda_bracket_kind) and split numbers
        # ("2.56225e+0" / "8"; rendering trial, session 29); a name folds, never ellipsized
        name_w = max(4, min(max((len(esc(k)) for k, _, _ in rows), default=4), out.width // 3))
        t.add_column("parameter / form", overflow="fold", min_width=name_w, max_width=name_w)
        t.add_column("value", overflow="fold")
        for k, v, form in rows:
            t.add_row(f"{esc(k)}\n[dim]{form}[/]", esc(v))
    else:
        t.add_column("parameter", overflow="fold")
        t.add_column("value", overflow="fold")
        t.add_column("form", no_wrap=True)
        for k, v, form in rows:
            t.add_row(esc(k), esc(v), form)
    out.print(t)
    if hidden_params > 0:
        out.print(
            f"… {hidden_params:,} more parameters not shown (--format json or md lists every one)"
        )
    claims = _shown_claims(report.claims)
    c = Table(title="claims")
    # claim ids never break mid-word: their column is as wide as the longest id (up to 32
    # characters); the prose columns wrap at spaces. Below NARROW columns the check and
    # the detail go under the statement (two columns), so nothing is cropped at 80.
    id_w = min(max((len(cl.id) for cl in claims), default=2), 32)
    if out.width < NARROW:
        # and never so wide that the prose column is squeezed below 24 columns: a 25-column id
        # at --width 40 made rich crop the statements with no mark ("T_max = 1." for
        # "T_max = 1.3452 ≤ …"; rendering trial, session 27); an id then folds
        # nor below its longest word (a 28-character quoted id in a verify detail at --width
        # 60 cropped the whole table: rich measures a column's minimum by its longest word,
        # and a forced minimum on the id column then left no room; re-check, session 27)
        words = (
            w for cl in claims for t in (cl.statement, cl.check, cl.detail) for w in esc(t).split()
        )
        prose = max(24, max((len(w) for w in words), default=0) + 8)  # + "detail: "
        id_w = max(4, min(id_w, out.width - 7 - prose))
        c.add_column("id / status", overflow="fold", min_width=id_w, max_width=id_w)
        c.add_column("statement / check / detail", overflow="fold")
        for cl in claims:
            c.add_row(
                f"{esc(cl.id)}\n[{STYLE[cl.status]}]{cl.status.value}[/]",
                f"{esc(cl.statement)}\n[dim]check:[/] {esc(cl.check)}"
                f"\n[dim]detail:[/] {esc(cl.detail)}",
            )
    else:
        c.add_column("id", overflow="fold", min_width=id_w)
        c.add_column("status", no_wrap=True, min_width=9)
        for col in ("statement", "check", "detail"):
            c.add_column(col, overflow="fold")
        for cl in claims:
            c.add_row(
                esc(cl.id),
                f"[{STYLE[cl.status]}]{cl.status.value}[/]",
                esc(cl.statement),
                esc(cl.check),
                esc(cl.detail),
            )
    out.print(c)
    if len(report.claims) > len(claims):
        seen = {id(cl) for cl in claims}
        hidden = [cl for cl in report.claims if id(cl) not in seen]
        bad = sum(cl.status is ClaimStatus.FAILED for cl in hidden)
        out.print(
            f"… {len(hidden):,} more claims not shown ({bad:,} of them failed; --format json "
            "or md lists every one)"
        )
    if report.error is not None:
        out.print(f"design stopped: {esc(report.error.get('message', ''))}", markup=True)
    for n in report.notes:
        out.print(f"note: {esc(n)}")
    counts = report.status_counts()
    out.print(
        f"claims: {counts['certified']} certified, {counts['numerical']} numerical, "
        f"{counts['failed']} failed"
    )


def md_cell(v: Any) -> str:
    """A Markdown table cell (or list item): pipes escaped, one line, other control
    characters as escapes (:func:`obsdesign.errors.escape_controls`)."""
    from obsdesign.errors import escape_controls

    one = str(v).replace("|", "\\|").replace("\r", " ").replace("\n", " ")
    return escape_controls(one)


def md_code(v: Any) -> str:
    """An inline code span of :func:`md_cell`'s text that a backtick inside cannot end: the
    fence is one backtick longer than the longest run inside (a backtick in a spec's file name
    ended the span of "- spec: `…`": rendering trial, session 27)."""
    import re

    text = md_cell(v)
    if "`" not in text:
        return f"`{text}`"
    fence = "`" * (max(len(m) for m in re.findall("`+", text)) + 1)
    return f"{fence} {text} {fence}"


def render_markdown(report: Report) -> str:
    """The report as Markdown. Every cell goes through :func:`md_cell`: the statement
    V(e⁺) ≤ λ²V(e) + μ|w|² split its row at the pipes (outsider trial, session 22)."""
    c_ = md_cell
    lines = [
        f"# obsdesign report: {c_(report.method)}",
        "",
        f"- spec: {md_code(report.spec_file)}",
        f"- spec sha256: {md_code(report.spec_sha256)}",
        f"- tool: {c_(report.tool.get('version', ''))}",
        "",
    ]
    lines += ["## Parameters", "", "| symbol | value | form |", "| --- | --- | --- |"]
    lines += [f"| {c_(k)} | {md_code(v)} | {c_(f)} |" for k, v, f in _param_rows(report)]
    lines += [
        "",
        "## Claims",
        "",
        "| id | status | statement | reference | check | detail |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for c in report.claims:
        cells = [c.id, f"**{c.status.value}**", c.statement, c.reference, c.check, c.detail]
        lines.append("| " + " | ".join(c_(x) for x in cells) + " |")
    if report.notes:
        lines += ["", "## Notes", ""] + [f"- {c_(n)}" for n in report.notes]
    return "\n".join(lines) + "\n"
