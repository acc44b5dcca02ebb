"""The bodies of the ``obsdesign`` commands, and their printing.

Imported when a command runs (:func:`obsdesign.cli._run`), so that ``obsdesign --help``
reads (and, without cached bytecode, compiles) only the declarations in
:mod:`obsdesign.cli`. Each body returns the command's exit code; errors are raised as
:class:`obsdesign.errors.ObsdesignError` and mapped to exit codes by the caller.
"""

from __future__ import annotations

import os
import stat
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from obsdesign.cli import STDIN, STDIN_NAME, Fmt

#: -q/--quiet of the running command (kept here, not in :mod:`obsdesign.cli`: run as
#: ``python obsdesign/cli.py`` that module is ``__main__`` and this one imports a copy)
_state = {"quiet": False}


def setup(quiet: bool = False, width: int | None = None) -> None:
    """Apply -q/--quiet and --width for this command (no --width: none, not the last
    command's; an in-process caller's earlier ``--width 40`` wrapped every later table)."""
    _state["quiet"] = quiet
    if width is not None or "obsdesign.report.render" in sys.modules:  # else it is fresh
        from obsdesign.report.render import set_width

        set_width(width)


def _is_stdin(path: Path | None) -> bool:
    return path is not None and str(path) == STDIN


def _inputs(*paths: Path | None) -> tuple[Path, ...]:
    """The input files among ``paths`` (None left out), for the output checks; stdin (``-``)
    as ``/dev/stdin`` when it is a regular file (``design - -o spec.toml < spec.toml``
    overwrote the spec: CLI fuzzer)."""
    out = []
    for p in paths:
        if p is None:
            continue
        if not _is_stdin(p):
            out.append(p)
            continue
        try:
            if stat.S_ISREG(os.fstat(0).st_mode) and os.path.exists("/dev/stdin"):
                out.append(Path("/dev/stdin"))
        except OSError:
            pass
    return tuple(out)


def _sim_input_files(sp: Any, option: list[str] | None) -> list[Path]:
    """The files a simulation reads besides spec and report: path-valued ``[simulate]``
    options of the method (the impulsive ``sampling_file``, relative to the spec) and
    path-valued ``--option KEY=PATH``. ``simulate --csv samp.csv`` overwrote the sampling
    file it read, exit 0 (CLI review, session 44)."""
    from obsdesign import api

    out: list[Path] = []
    so = getattr(sp.simulate, "options", None) if sp.simulate is not None else None
    for v in getattr(so, "__dict__", {}).values():
        if isinstance(v, Path):
            out.append(v)
    kinds = {o.name: o.kind for o in api.method(sp.method).sim_options}
    for item in option or []:
        k, eq, v = item.partition("=")
        if eq and kinds.get(k.strip()) == "path" and v.strip():
            out.append(Path(v.strip()))
    return out


def _sweep_sim_files(tasks: list[Any], option: list[str] | None) -> list[Path]:
    """:func:`_sim_input_files` of every point of a sweep whose spec loads (a point that does
    not is its own row's bad input); none when the method reads no file."""
    from obsdesign import api
    from obsdesign.errors import ObsdesignError
    from obsdesign.sweep import point_text

    out: list[Path] = []
    for t in tasks:
        try:
            sp = api.load_spec_text(point_text(t.text, t.values, t.file), t.file)
        except ObsdesignError:
            continue
        if not any(o.kind == "path" for o in api.method(sp.method).sim_options):
            return []
        out += [f for f in _sim_input_files(sp, option) if f not in out]
    return out


def _read_stdin(what: str) -> str:
    """Standard input as text, within ``max_file_bytes`` (``-`` in place of a path)."""
    from obsdesign.errors import InputError
    from obsdesign.limits import limits

    lim = limits().max_file_bytes
    if sys.stdin is None:  # started with stdin closed (obsdesign design - <&-)
        raise InputError(f"{STDIN_NAME}: standard input is closed; give a file instead of -")
    data = sys.stdin.buffer.read(lim + 1)
    if len(data) > lim:
        raise InputError(
            f"{STDIN_NAME}: {what} is above the limit of {lim} bytes (--limit max_file_bytes=N)"
        )
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{STDIN_NAME}: {what} is not UTF-8 text") from None


def _precheck(spec: Path) -> None:
    """The cheap checks of a spec file before the heavy imports (none for stdin)."""
    if not _is_stdin(spec):
        from obsdesign.limits import precheck_spec

        precheck_spec(spec)


def _load_spec(spec: Path) -> Any:
    """The bound spec at ``spec``, or read from stdin for ``-`` (file name ``<stdin>``)."""
    from obsdesign import api

    if not _is_stdin(spec):
        return api.load_spec(spec)
    from obsdesign.errors import InputError
    from obsdesign.limits import values_problem

    text = _read_stdin("spec")
    said = values_problem(text.count(","))
    if said:
        raise InputError(f"{STDIN_NAME}: {said}")
    return api.load_spec_text(text, STDIN_NAME)


def _say(text: str) -> None:
    """An informational line on stdout (text format), unless --quiet; made one line as
    errors are (a file name with ESC and a newline reached the terminal raw in "report
    written to …"; hostile-input trial, session 24)."""
    if not _state["quiet"]:
        from obsdesign.errors import one_line

        print(one_line(text))


def _distinct_outputs(a: Path | None, b: Path | None) -> None:
    """Refuse one file named for two outputs (``-o X --plot X`` kept the plot and said
    "report written": CLI fuzzer), whether or not it exists, --force or not."""
    if a is None or b is None:
        return
    from obsdesign.errors import InputError

    same = os.path.realpath(a) == os.path.realpath(b)
    if not same:
        try:
            same = os.path.samefile(a, b)
        except OSError:
            same = False
    if same:
        raise InputError(f"{b}: is given for two outputs; name two different files")


def _check_plot(path: Path | None, force: bool, inputs: tuple[Path, ...] = ()) -> None:
    """Refuse a plot path before any work: an unknown format or a path that
    :func:`obsdesign.report.model.check_output` refuses (exit 2)."""
    if path is None:
        return
    from obsdesign.api import check_plot_path

    check_plot_path(path, force, inputs)


def _write_plot(path: Path, draw: Callable[[Path], Any], force: bool) -> None:
    from obsdesign.report.model import write_via

    write_via(path, draw, force)


def _check_distributed(
    paths: list[Path],
    workers: int | None,
    scheduler: str | None,
    quiet: bool,
    timeout: float | None = None,
) -> list[Any]:
    """``check`` on Dask, with a progress bar on stderr (unless --quiet); ``timeout``: seconds
    per spec, applied in the worker."""
    from obsdesign import api
    from obsdesign.distributed import check_workers, progress_bar

    check_workers(workers, scheduler)
    n = len(api.spec_files(list(paths)))
    with progress_bar(n, "check", quiet) as advance:
        return api.check(
            list(paths),
            workers=workers,
            scheduler=scheduler,
            on_row=lambda r: advance(r.code != 0),
            timeout=timeout,
        )


def _print_sweep(rows: list[dict[str, Any]], fmt: Fmt) -> None:
    from obsdesign.sweep import TIMING_COLUMNS, columns

    cols = [c for c in columns(rows) if c not in ("method", *TIMING_COLUMNS)]
    if fmt == Fmt.md:
        print("| " + " | ".join(cols) + " |")
        print("|" + " --- |" * len(cols))
        for r in rows:
            print("| " + " | ".join(_md_cell(_md_value(r.get(c, ""))) for c in cols) + " |")
        return
    from rich.table import Table

    from obsdesign.errors import escape_controls
    from obsdesign.report.render import console, esc

    # control characters as escapes in both layouts: the paragraphs printed an ESC colour
    # sequence of a swept value raw, and a newline broke them (CLI review 45)
    cells = [[escape_controls(_sweep_cell(r.get(c))) for c in cols] for r in rows]
    # every column whole at its widest (header and values), the message at least
    # CHECK_RESULT_MIN, and the borders: below that rich folded headers and values mid-word
    # ("metho / d.lam / bda", "faile / d" at --width 40; CLI review 44) or cropped the
    # table, so each point is then a paragraph of key=value items, wrapped at spaces
    # in terminal cells, not characters: a CJK value is two cells a character (re-check 45)
    from rich.cells import cell_len

    widths = [
        CHECK_RESULT_MIN if c == "message" else max(cell_len(c), *(cell_len(x[i]) for x in cells))
        for i, c in enumerate(cols)
    ]
    con = console()
    if cells and con.width < 3 * len(cols) + 1 + sum(widths):
        from rich.text import Text

        def para(text: str) -> None:  # wrapped at spaces, indented by 2, no trailing blanks
            for line in Text(text).wrap(con, max(con.width - 2, 8), overflow="fold"):
                line.rstrip()
                con.print(Text("  ") + line, soft_wrap=True)

        con.print("[bold]obsdesign sweep[/]")
        for x in cells:
            named = dict(zip(cols, x, strict=True))
            con.print(Text(f"point {named.get('point', '')}"), overflow="fold")
            para(
                "  ".join(
                    f"{c}={v}" for c, v in named.items() if v and c not in ("point", "message")
                )
            )
            if named.get("message"):
                para(named["message"])
        return
    t = Table(title="obsdesign sweep")
    for c in cols:
        t.add_column(esc(c), overflow="fold")
    for x in cells:
        t.add_row(*(esc(v) for v in x))
    con.print(t)


def _sweep_cell(v: Any) -> str:
    """A sweep table's cell: a float in 6 significant digits, marked "≈" when that text is
    not the value (its decimal is not the float, or the float is not the exact parameter:
    :class:`obsdesign.sweep.ExactFloat`); an ISS bound 24842821.6875 showed as a bare
    "2.48428e+07", below the bound (session 28)."""
    from obsdesign.report.shown import APPROX
    from obsdesign.sweep import ExactFloat

    if v is None:
        return ""
    if isinstance(v, float):
        text = format(v, ".6g")
        same = v.shows(text) if isinstance(v, ExactFloat) else (float(text) == v or v != v)
        return text if same else APPROX + text
    return str(v)


def _md_value(v: Any) -> Any:
    """A Markdown sweep cell's value: the float's repr, marked "≈" when that decimal is not
    the exact parameter (:class:`obsdesign.sweep.ExactFloat`)."""
    from obsdesign.report.shown import APPROX
    from obsdesign.sweep import ExactFloat

    if isinstance(v, ExactFloat):
        text = repr(float(v))
        return text if v.shows(text) else APPROX + text
    return v


def _kv(items: list[str]) -> dict[str, str]:
    from obsdesign.errors import InputError

    out = {}
    for it in items:
        if "=" not in it:
            raise InputError(f"--option expects KEY=VALUE, got {it!r}")
        k, v = it.split("=", 1)
        k = k.strip()
        if k in out and out[k] != v.strip():
            # the last one was used without a word, while --runs 2 --option runs=3 and a
            # repeated sweep --set key are refused (CLI hostile-input trial, session 34)
            raise InputError(f"--option {k} is given twice ({out[k]}, {v.strip()}): give it once")
        out[k] = v.strip()
    return out


def _dumps(obj: Any, **kw: Any) -> str:
    """``json.dumps`` of :func:`obsdesign.errors.json_safe` ``obj``, so the text is valid JSON: a non-finite
    metric printed as ``NaN`` / ``Infinity``, which JSON has not (independent simulate
    review). json loads only on the paths that print JSON."""
    import json

    from obsdesign.errors import json_safe

    return json.dumps(json_safe(obj, kw.pop("default", None)), allow_nan=False, **kw)


def _jsonable(o: Any) -> Any:
    try:
        import numpy as np

        if isinstance(o, np.ndarray):
            return o.tolist()
        if isinstance(o, (np.floating, np.integer)):
            return o.item()
    except ImportError:  # pragma: no cover
        pass
    return str(o)


def _progress() -> Callable[[str], None]:
    def show(msg: str) -> None:
        if sys.stderr.isatty():
            sys.stderr.write(f"\r\033[K{msg}")
            sys.stderr.flush()

    return show


def _print_report(rep: Any, fmt: Fmt) -> str | None:
    """Print a report in ``fmt``: the JSON text printed for ``--format json``, else None."""
    from obsdesign.report.render import render_markdown, render_text

    if sys.stderr.isatty() and fmt == Fmt.text:
        sys.stderr.write("\r\033[K")
    if fmt == Fmt.json:
        text = rep.to_json()
        print(text)
        return text
    elif fmt == Fmt.md:
        sys.stdout.write(render_markdown(rep))
    else:
        render_text(rep)


def _result_text(r: Any) -> str:
    """A check row's result cell: the summary of a row that passed, else why it did not (the
    Markdown table showed the summary of rows that exited 1 or 4 with claims, the text table
    the reason: rendering trial, session 27)."""
    return str(r.summary if r.code == 0 else (r.message or r.summary))


#: the least widths of check's spec and result columns in its table (below: blocks of lines);
#: a typical row is then a table at 80 columns
CHECK_SPEC_MIN, CHECK_RESULT_MIN = 12, 16


def _print_rows(rows: list[Any], fmt: Fmt) -> None:
    if fmt == Fmt.md:
        print("| spec | method | exit | certified | numerical | failed | result | seconds |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        for r in rows:
            cells = [r.spec, r.method, r.code, r.certified, r.numerical, r.failed]
            cells += [_result_text(r), f"{r.seconds:.2f}"]
            print("| " + " | ".join(_md_cell(c) for c in cells) + " |")
        return
    from rich.table import Table

    from obsdesign.report.render import console, esc

    c = console()
    if not rows:  # (check refuses an empty list of specs before; the widths need a row)
        return
    cells = [
        (
            esc(r.spec),
            esc(r.method),
            "ok" if r.code == 0 else f"exit {r.code}",
            f"{r.certified}/{r.numerical}/{r.failed}",
            esc(_result_text(r)),
            f"{r.seconds:.2f}",
        )
        for r in rows
    ]
    # the columns that never wrap, at their widest, plus room for the spec and the result
    # and the borders: below that rich ellipsized them ("5/0…" for 5/0/1, the failed claim
    # hidden) and squeezed spec and result to nothing (--width 40; rendering trial, session
    # 29), so each row is then a block of lines
    fixed = sum(
        max(len(h), *(len(x[i]) for x in cells))
        for i, h in ((1, "method"), (2, "verdict"), (3, "claims"), (5, "s"))
    )
    if cells and c.width < fixed + CHECK_SPEC_MIN + CHECK_RESULT_MIN + 19:
        c.print("[bold]obsdesign check[/] (claims: certified/numerical/failed)")
        for (spec, method, verdict, claims, result, secs), r in zip(cells, rows, strict=True):
            style = "green" if r.code == 0 else "bold red"
            c.print(spec, overflow="fold")
            c.print(
                f"  {method} · [{style}]{verdict}[/] · claims {claims} · {secs} s",
                overflow="fold",
            )
            c.print(f"  {result}", overflow="fold")
        return
    t = Table(title="obsdesign check", caption="claims: certified/numerical/failed")
    # method, verdict and the claim counts never wrap; the spec path folds (no spaces in
    # it) and the result wraps at spaces with twice the spec's share of the rest
    t.add_column("spec", overflow="fold", ratio=1)
    t.add_column("method", no_wrap=True)
    t.add_column("verdict", no_wrap=True)
    t.add_column("claims", no_wrap=True)
    t.add_column("result", overflow="fold", ratio=2)
    t.add_column("s", no_wrap=True)
    for (spec, method, verdict, claims, result, secs), r in zip(cells, rows, strict=True):
        style = "green" if r.code == 0 else "bold red"
        t.add_row(spec, method, f"[{style}]{verdict}[/]", claims, result, secs)
    c.print(t)


def _check_verdict(rows: list[Any]) -> str:
    """The one-line verdict of ``check``."""
    ok = sum(r.code == 0 for r in rows)
    cert = sum(r.certified for r in rows)
    num = sum(r.numerical for r in rows)
    fail = sum(r.failed for r in rows)
    claims = f"{cert} claim{'s' if cert != 1 else ''} certified"
    if num:
        claims += f", {num} numerical"
    head = "checked" if ok == len(rows) else "NOT all checked"
    return (
        f"{head}: {len(rows)} spec{'s' if len(rows) != 1 else ''}, {ok} ok, "
        f"{len(rows) - ok} failed; {claims}, {fail} failed"
    )


def _read_report(report: Path) -> Any:
    """The report path, or for ``-`` the report read from stdin (a Report)."""
    if not _is_stdin(report):
        return report
    from obsdesign.report.model import Report

    return Report.from_text(_read_stdin("report"), STDIN_NAME)[0]


def _json_only(v: Any) -> bool:
    """A metric that is nested data (a mapping of mappings, e.g. the outlier study's medians
    by observer, amplitude and state): JSON shows it; text and Markdown show its table."""
    return isinstance(v, dict) and bool(v) and all(isinstance(x, dict) for x in v.values())


def _metric_text(v: Any) -> str:
    """A metric's value in the text and Markdown output: yes / no for a truth value, none
    for a missing one, a flat mapping as ``key = value, …``, a list item by item — Python's
    reprs (None, True, {'standard': 1.28…}) were printed as they were (CLI review 46; JSON
    keeps null, true and the objects)."""
    if type(v).__name__ in ("bool", "bool_"):  # numpy's too
        return "yes" if v else "no"
    if v is None:
        return "none"
    if isinstance(v, dict):
        return ", ".join(f"{k} = {_metric_text(x)}" for k, x in v.items())
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_metric_text(x) for x in v) + "]"
    return str(v)


def _metrics_markdown(m: dict[str, Any]) -> str:
    lines = ["| state | sup \\|e_i\\| | RMSE | sup \\|x̂_i\\| |", "| --- | --- | --- | --- |"]
    for st, v in m["sup_abs_error"].items():
        lines.append(
            f"| {_md_cell(st)} | {v:.6g} | {m['rmse'][st]:.6g} | {m['sup_abs_estimate'][st]:.6g} |"
        )
    lines += ["", f"final \\|e\\| = {m['final_error_norm']:.6g}"]
    for k, v in m.items():
        if k == "warnings" and isinstance(v, list):
            lines += [f"- warning: {_md_cell(str(w).removeprefix('warning: '))}" for w in v]
        elif _json_only(v):
            continue
        elif isinstance(v, str) and "\n" in v.strip():
            # a preformatted table (the stubborn outlier study) collapsed onto one line
            # (outsider trial, session 22): a fenced block keeps its rows
            lines += [f"- {_md_cell(k)}:", "", "```", v.strip("\n"), "```", ""]
        elif k not in (*_MAIN_METRICS, "quantiles"):
            lines.append(f"- {_md_cell(k)}: {_md_cell(_metric_text(v))}")
    head, rows = _quantile_rows(m.get("quantiles"))
    if rows:
        lines += ["", "| quantiles | " + " | ".join(head) + " |", "| --- " * (len(head) + 1) + "|"]
        lines += ["| " + " | ".join(_md_cell(c) for c in r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


#: the metrics printed in the table; the rest, one line each
_MAIN_METRICS = ("sup_abs_error", "rmse", "final_error_norm", "sup_abs_estimate", "exit_code")
_METRIC_NAMES = {
    "sup_abs_error": "sup |e_{}|",
    "rmse": "RMSE e_{}",
    "sup_abs_estimate": "sup |x̂_{}|",
    "final_error_norm": "final |e|",
}


def _num(v: Any) -> str:
    """A number as ``.6g``; anything else as its text."""
    return f"{v:.6g}" if isinstance(v, (int, float)) and not isinstance(v, bool) else str(v)


def _quantile_rows(q: Any) -> tuple[list[str], list[list[str]]]:
    """The Monte Carlo quantiles (``{metric: {state: {q05: …}}}`` or ``{metric: {q05: …}}``)
    as a table: the quantile names, then one row per metric and state (the raw dict was
    printed before; independent simulate review). Empty when ``q`` is not of that shape."""
    if not isinstance(q, dict):
        return [], []
    head: list[str] = []
    rows: list[list[str]] = []

    def add(label: str, qs: dict[str, Any]) -> None:
        for k in qs:
            if k not in head:
                head.append(k)
        rows.append([label, *(_num(qs[k]) if k in qs else "" for k in head)])

    for metric, v in q.items():
        if not isinstance(v, dict) or not v:
            continue
        name = _METRIC_NAMES.get(metric, metric + " {}")
        if all(isinstance(x, dict) for x in v.values()):
            for state, qs in v.items():
                add(name.format(state), qs)
        else:
            add(name.replace("_{}", "").replace(" {}", ""), v)
    return head, [r + [""] * (len(head) + 1 - len(r)) for r in rows]


def _md_cell(v: Any) -> str:
    """A Markdown table cell: pipes escaped, one line (:func:`obsdesign.report.render.md_cell`)."""
    from obsdesign.report.render import md_cell

    return md_cell(v)


def _print_metrics(m: dict[str, Any]) -> None:
    from rich.table import Table

    from obsdesign.report.render import console, esc

    who = m.get("observer")
    # which observer the numbers are of, where a method simulates several (constrained,
    # stubborn): the title said "simulation metrics" only (soundness trial, session 34)
    t = Table(title="simulation metrics" + (f" ({esc(str(who))})" if who else ""))
    t.add_column("state")
    t.add_column("sup |e_i|")
    t.add_column("RMSE")
    t.add_column("sup |x̂_i|")
    for s, v in m["sup_abs_error"].items():
        t.add_row(esc(s), f"{v:.6g}", f"{m['rmse'][s]:.6g}", f"{m['sup_abs_estimate'][s]:.6g}")
    c = console()
    c.print(t)
    c.print(f"final |e| = {m['final_error_norm']:.6g}")
    for k, v in m.items():
        if k == "warnings" and isinstance(v, list):  # one per line, not a Python list repr
            for w in v:
                c.print(esc(f"warning: {str(w).removeprefix('warning: ')}"))
        elif _json_only(v):
            continue
        elif isinstance(v, str) and "\n" in v.strip():  # a preformatted table: no wrapping,
            # each line escaped (escaped whole, its newlines printed as "\n": simulate trial)
            c.print("\n".join(esc(line) for line in f"{k}: {v}".split("\n")), soft_wrap=True)
        elif k not in (*_MAIN_METRICS, "quantiles"):
            c.print(esc(f"{k}: {_metric_text(v)}"))
    head, rows = _quantile_rows(m.get("quantiles"))
    if rows:
        q = Table(title=f"quantiles over {m.get('runs', 'the')} runs")
        for h in ("metric", *head):
            q.add_column(h)
        for r in rows:
            q.add_row(*(esc(c) for c in r))
        c.print(q)


def design(
    spec: Path,
    output: Path | None,
    fmt: Fmt,
    plot: Path | None,
    force: bool,
    quiet: bool,
    timeout: float = 0.0,
) -> int:
    """The body of ``obsdesign design`` (see :func:`obsdesign.cli.design`)."""
    _precheck(spec)  # before the heavy imports: an oversized spec is refused at once
    from obsdesign import api
    from obsdesign.errors import InputError, SolverError
    from obsdesign.report.model import check_output

    _distinct_outputs(output, plot)
    if output is not None:
        check_output(output, force, _inputs(spec))
    _check_plot(plot, force, _inputs(spec, output))
    progress = _progress() if fmt == Fmt.text and not quiet else None
    # --timeout covers reading the spec: a polytope set's exact vertices are found there
    # (8-60 s past --timeout 2; responsiveness review 47)
    import time

    budget = api.budget_seconds(timeout)
    deadline = None if budget is None else time.monotonic() + budget
    try:
        with api._design_budget(budget, deadline):
            sp = _load_spec(spec)
    except SolverError as e:  # the budget ran out while the spec was read: name it
        from obsdesign.errors import valid_text

        raise SolverError(
            f"{STDIN_NAME if _is_stdin(spec) else valid_text(str(spec))}: {e.message} "
            "(reading the spec)"
        ) from None
    if plot is not None and api.method(sp.method).plot_design is None:
        raise InputError(f"--plot: method '{sp.method}' has no design plot")
    with _naming_the_spec(sp.file):
        try:
            rep = api.design_within(sp, output, progress, force, budget, deadline)
        except Exception as e:
            _design_error_outputs(sp, e, output, fmt)
            raise
    printed = _print_report(rep, fmt) if not quiet or fmt == Fmt.json else None
    if printed is not None and output is None:
        _warn_printed_report(rep, printed)
    if plot is not None:
        _write_plot(plot, lambda tmp: api.plot_design(sp, rep.parameters, tmp, atomic=False), force)
        if fmt == Fmt.text:
            _say(f"plot written to {plot}")
    if output is not None and fmt == Fmt.text:
        _say(f"report written to {output}")
    if output is not None:
        _warn_above_read_limit(output)
        _warn_above_digit_limit(rep, output)
    return rep.exit_code()


def _warn_above_digit_limit(rep: Any, output: Path) -> None:
    """A warning on stderr (also with -q) when the report holds an exact value longer than
    ``max_digits``: a set-invariant design with a Q entry of 1e-300 exited 0 with a report
    (4471-digit vertices) that its own ``verify`` refused as bad input, exit 2 (CLI review,
    session 44). The report is right; reading it takes a raised limit, which the warning
    names."""
    try:  # a scan of the written text first: the walk below only when a run is that long
        if not stat.S_ISREG(os.stat(output).st_mode):  # a FIFO or device (--force)
            return
        text = Path(output).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return
    _warn_digits(rep, text, output)


def _warn_digits(rep: Any, text: str, where: Path | str) -> None:
    """The max_digits warning for a report's JSON ``text`` written to ``where``: a scan of the
    text first, the walk of the report's exact values only when a digit run is that long."""
    import re

    from obsdesign.limits import exact_digits, limits

    # each digit run tried from its start only (a lookbehind): tried from every position the
    # search was quadratic in a run's length, 1 s for one 20,000-digit value (re-check, 44)
    if re.search(rf"(?<![0-9])[0-9]{{{limits().max_digits + 1}}}", text) is None:
        return
    need = exact_digits(rep.to_dict().get("parameters", {}).get("exact", {}))
    _warn_limit(where, f"holds exact values of {need:,} digits", "max_digits", need)


def _warn_printed_report(rep: Any, text: str) -> None:
    """``design --format json`` without ``-o``: the warnings ``-o`` gives for a report that
    ``verify`` reads only under a raised limit, for the report printed (a saved copy of it
    was refused by verify, exit 2, with no word at design time; CLI review 44)."""
    where = "the report printed"
    size = len(text.encode()) + 1  # print's newline
    _warn_limit(where, f"is {size:,} bytes", "max_file_bytes", size)
    _warn_digits(rep, text, where)


def _warn_above_read_limit(output: Path) -> None:
    """A warning on stderr (also with -q) when the written report is larger than
    ``max_file_bytes``: a search-space design with a 70,000-entry schedule exited 0 with an
    18.9 MB report that its own ``verify`` then refused as bad input, exit 2 (re-check trial,
    session 31). The report is right; reading it takes a raised limit, which the warning
    names."""

    try:
        size = os.path.getsize(output)
    except OSError:  # written through a link to a device, or gone since: nothing to say
        return
    _warn_limit(output, f"is {size:,} bytes", "max_file_bytes", size)


def _warn_limit(output: Path | str, what: str, key: str, need: int) -> None:
    """The warning of a written report that ``verify`` reads only with ``--limit key=need``
    (when ``need`` is above the limit in force); ``what`` says how the report exceeds it;
    ``output`` is its file, or "the report printed" (verified as a saved FILE)."""
    from obsdesign.errors import one_line
    from obsdesign.limits import limits

    lim = getattr(limits(), key)
    if need > lim:
        sys.stderr.write(
            one_line(
                f"obsdesign: warning: {output} {what}, above {key} = {lim:,}, the most verify "
                f"reads: verify it with 'obsdesign --limit {key}={need} verify "
                f"{output if isinstance(output, Path) else 'FILE'}'"
            )
            + "\n"
        )


def _design_error_outputs(sp: Any, e: Exception, output: Path | None, fmt: Fmt) -> None:
    """What a design that stopped with an error (exit 1, 3 or 4) prints besides its error
    line: ``--format json`` the error report that ``-o`` writes (stdout was empty, so a CI
    job parsing it got a JSON error instead of ``"verdict": "error"``), text a line saying
    ``-o`` now holds that report (it was replaced silently; rendering trial, session 29).
    Bad input (exit 2) writes and prints no report."""
    from obsdesign import api
    from obsdesign.errors import EXIT_BAD_INPUT

    code, message = api.design_error(e)
    if code == EXIT_BAD_INPUT:
        return
    if fmt == Fmt.json:
        print(api.error_report(sp, code, message, getattr(e, "candidate", None)).to_json())
    elif output is not None and fmt == Fmt.text:
        tried = getattr(e, "candidate", None)
        holds = f" (its parameters: {', '.join(tried)} tried, not certified)" if tried else ""
        _say(f"error report written to {output}{holds}")


@contextmanager
def _naming_the_spec(file: str) -> Iterator[None]:
    """Prefix an error's message with the spec's file when it does not name it: a method's
    "Lemma 1 fails …" (exit 1, 3 or 4) did not say which spec, so a loop over many specs in
    CI could not tell which one failed (outsider trial, session 22)."""
    from obsdesign.errors import ObsdesignError

    try:
        yield
    except ObsdesignError as e:
        if file and not e.message.startswith(file):
            e.message = f"{file}: {e.message}"
            e.args = (e.message,)
        raise


def verify(report: Path, spec: Path | None, fmt: Fmt, quiet: bool) -> int:
    """The body of ``obsdesign verify`` (see :func:`obsdesign.cli.verify`)."""
    from obsdesign.limits import precheck_spec, read_input

    if spec is not None and _is_stdin(spec):
        from obsdesign.errors import InputError

        # "-: no such spec file" (hostile-input trial, session 24)
        raise InputError(
            "--spec -: verify reads the spec from a file (the report may come from stdin, "
            "the spec cannot)"
        )
    if not _is_stdin(report):
        read_input(report, "report")  # before the heavy imports (regular file, size)
    if spec is not None:
        precheck_spec(spec)
    from obsdesign import api
    from obsdesign.report.render import verdict_line

    rep = api.verify(_read_report(report), spec)
    if not quiet or fmt == Fmt.json:
        _print_report(rep, fmt)
    if fmt == Fmt.md and not quiet:
        print(f"\n**{verdict_line(rep)}**")
    elif fmt != Fmt.json:
        print(verdict_line(rep))
    return rep.exit_code()


def check(
    paths: list[Path],
    fmt: Fmt,
    junit: Path | None,
    quiet: bool,
    workers: int | None,
    scheduler: str | None,
    timeout: float | None = None,
) -> int:
    """The body of ``obsdesign check`` (see :func:`obsdesign.cli.check`)."""
    from obsdesign import api, interrupt

    if any(str(p) == "-" for p in paths):
        from obsdesign.errors import InputError

        # it gave a row "-: no such spec file" (outsider trial, session 22)
        raise InputError(
            "-: check takes spec files and folders, not stdin (design -, verify -, simulate - "
            "and sweep - read a spec from stdin)"
        )
    if junit is not None:
        from obsdesign.report.model import check_output

        # every spec the folders hold, not only the paths named (check DIR --junit DIR/x.toml
        # replaced a spec with the JUnit XML: CLI fuzzer)
        check_output(junit, False, _inputs(*paths, *api.spec_files(list(paths))), forceable=False)

    def each(f: Path) -> None:
        interrupt.check()  # a Ctrl-C whose exception was lost in the last spec stops here
        if fmt == Fmt.text and not quiet:
            from obsdesign.errors import escape_controls

            sys.stderr.write(f"checking {escape_controls(str(f))} ...\n")

    if workers is None and scheduler is None:
        rows = api.check(list(paths), on_start=each, timeout=timeout or None)
    else:
        rows = _check_distributed(list(paths), workers, scheduler, quiet, timeout or None)
    if junit is not None:
        from obsdesign.junit import write_junit

        write_junit(junit, rows)
    if fmt == Fmt.json:
        print(_dumps([r.__dict__ for r in rows], indent=2, default=_jsonable))
    else:
        if not quiet:
            _print_rows(rows, fmt)
        line = _check_verdict(rows)
        print(f"\n**{line}**" if fmt == Fmt.md and not quiet else line)
    return api.check_exit_code(rows)


def sweep(
    spec: Path,
    sets: list[str],
    simulate: bool,
    option: list[str] | None,
    output: Path | None,
    plot: Path | None,
    y: str | None,
    x: str | None,
    fmt: Fmt,
    workers: int | None,
    scheduler: str | None,
    force: bool,
    quiet: bool,
    timeout: float | None = None,
) -> int:
    """The body of ``obsdesign sweep`` (see :func:`obsdesign.cli.sweep`)."""
    _precheck(spec)
    import types

    from obsdesign import sweep as sw
    from obsdesign.distributed import check_workers, progress_bar
    from obsdesign.errors import InputError

    check_workers(workers, scheduler)
    _distinct_outputs(output, plot)
    if output is not None:
        sw.check_output_path(output, force, _inputs(spec))
    if plot is not None and y is None:
        raise InputError("--plot needs --y COLUMN (the plotted column)")
    if plot is None and (y is not None or x is not None):
        raise InputError("--y/--x choose what --plot draws: give --plot FILE")
    _check_plot(plot, force, _inputs(spec, output))
    src: Any = spec
    if _is_stdin(spec):
        src = types.SimpleNamespace(text=_read_stdin("spec"), file=STDIN_NAME)
    axes = sw.parse_grid(sets)
    _, tasks = sw.plan(src, sets, simulate, _kv(option or []))
    if simulate and (output is not None or plot is not None):
        # the points' scenario files (impulsive sampling_file, also one --set per point):
        # sweep --simulate -o samp.csv wrote the table over it, exit 0 (re-check review, 44)
        files = _sweep_sim_files(tasks, option)
        if files:
            if output is not None:
                sw.check_output_path(output, force, _inputs(spec, *files))
            _check_plot(plot, force, _inputs(spec, output, *files))
    cols = None
    if plot is not None:
        cols = sw.expected_columns(tasks[0].text, axes, simulate)
        if y in sw.TEXT_COLUMNS:
            raise InputError(f"--y {y}: a column of text; --y takes a column of numbers")
        if x is not None and x not in [a.key for a in axes]:
            raise InputError(f"--x {x}: not a swept key")
        if cols is not None and y not in cols:
            raise InputError(f"--y {y}: not a column of this sweep ({', '.join(sorted(cols))})")
    with progress_bar(len(tasks), "sweep", quiet) as advance:
        rows = sw.sweep_rows(
            src,
            sets,
            simulate=simulate,
            options=_kv(option or []),
            workers=workers,
            scheduler=scheduler,
            on_row=lambda r: advance(r["exit_code"] != 0),
            timeout=timeout,
        )
    if plot is not None:
        # before -o: a --y that no row has was refused after the table was written (output
        # trial, session 30)
        sw.check_plot_column(rows, axes, y or "", x, cols)
    if output is not None:
        sw.write_table(output, rows, force)
    if plot is not None:
        _write_plot(plot, lambda tmp: sw.plot_sweep(rows, axes, y or "", tmp, x), force)
        gaps = sw.missing_y(rows, y or "")
        if gaps:  # ok rows without a value: gaps that are not failures (sweep review)
            from obsdesign.errors import one_line

            sys.stderr.write(
                one_line(
                    f"obsdesign: warning: {gaps} ok row(s) have no value of --y {y} (the "
                    "method gives none there, e.g. alpha in discrete time, mu without "
                    "iss_gain): gaps in the plot, not failures"
                )
                + "\n"
            )
    if fmt == Fmt.json:
        print(_dumps(rows, indent=2, ensure_ascii=False, default=_jsonable))
        return sw.exit_code(rows)
    if output is None and not quiet:
        _print_sweep(rows, fmt)
    ok = sum(r["exit_code"] == 0 for r in rows)
    pts = f"{len(rows)} point{'' if len(rows) == 1 else 's'}"
    line = f"swept: {pts}, {ok} ok, {len(rows) - ok} not ok"
    if rows and ok < len(rows):
        line += f" (worst exit {sw.exit_code(rows)})"
    if fmt == Fmt.text:  # wrapped at the table width as the table is (session 45's note)
        line = _wrapped(line)
    print(f"\n**{line}**" if fmt == Fmt.md and not quiet else line)
    if output is not None and fmt == Fmt.text:
        _say(f"table written to {output}")
    if plot is not None and fmt == Fmt.text:
        _say(f"plot written to {plot}")
    return sw.exit_code(rows)


def _wrapped(line: str) -> str:
    """``line`` folded at spaces to the text tables' width (:func:`render.width`; the
    terminal's when that leaves it to rich)."""
    import shutil
    import textwrap

    from obsdesign.report.render import MIN_WIDTH, width

    w = width() or max(MIN_WIDTH, shutil.get_terminal_size().columns)
    return textwrap.fill(line, w, break_long_words=False, break_on_hyphens=False)


#: grid points of a run that ``simulate --plot`` draws at most
MAX_PLOT_POINTS = 1_000_000


def simulate(
    spec: Path,
    report: Path | None,
    plot: Path | None,
    fmt: Fmt,
    option: list[str] | None,
    force: bool,
    runs: int | None,
    study: str | None,
    workers: int | None,
    scheduler: str | None,
    quiet: bool,
    csv: Path | None = None,
) -> int:
    """The body of ``obsdesign simulate`` (see :func:`obsdesign.cli.simulate`)."""
    _precheck(spec)  # before the heavy imports
    from obsdesign import api
    from obsdesign.report.model import check_output

    if report is not None and _is_stdin(report):
        from obsdesign.errors import InputError

        # it said "-: no such report file" (CLI review 45); the spec may come from stdin
        raise InputError(
            "--report -: a report is read from a file, not from stdin (use ./- for a file named -)"
        )
    if workers is not None or scheduler is not None:
        from obsdesign.distributed import check_workers

        check_workers(workers, scheduler)
    _distinct_outputs(plot, csv)
    _check_plot(plot, force, _inputs(spec, report))
    if csv is not None:
        check_output(csv, force, _inputs(spec, report))
    sp = _load_spec(spec)
    files = _sim_input_files(sp, option)
    if files:  # the scenario's own input files (impulsive sampling_file) are inputs too
        _check_plot(plot, force, _inputs(spec, report, *files))
        if csv is not None:
            check_output(csv, force, _inputs(spec, report, *files))
    steps = (
        api.sim_grid_steps(sp)
        if plot is not None and sp.simulate is not None and api.method(sp.method).sim_grid_from_dt
        else None
    )
    if steps is not None and steps + 1 > MAX_PLOT_POINTS:  # N steps are N + 1 grid points
        from obsdesign.errors import InputError

        # refused after the whole run (10⁷ steps, 40 s) until session 33; the check after
        # the run stays for grids the horizon does not count (a run's exact length); exact
        # (the float quotient 299.9997 / 0.0003 = 999999.0000000001 refused a run that fits)
        raise InputError(
            f"{spec}: [simulate] horizon{'' if sp.system.discrete else ' / dt'} gives a run of "
            f"{steps:,} steps ({steps + 1:,} grid points), above the {MAX_PLOT_POINTS:,} "
            f"--plot {plot} takes (a shorter horizon or a larger dt; --csv writes any length)"
        )
    opts = _kv(option or [])
    if runs is not None or study is not None:
        from obsdesign.methods import get_method

        _flags_known(get_method(sp.method), runs, study)
    if runs is not None:
        if "runs" in opts and opts["runs"].strip().lstrip("+").lstrip("0") != str(runs):
            from obsdesign.errors import InputError

            # --runs silently won over --option runs=..., unchecked (review)
            raise InputError(
                f"--runs {runs} and --option runs={opts['runs']}: give the run count once"
            )
        opts["runs"] = str(runs)
    if study is not None:
        if "study" in opts and opts["study"] != study:
            from obsdesign.errors import InputError

            raise InputError(f"--study {study} and --option study={opts['study']}: give it once")
        opts["study"] = study
    if quiet and "progress" in opts:  # -q: no progress, whatever --option asked
        from obsdesign.methods import get_method

        # the user's value checked first: -q hid a bad one (exit 0; docs trial, session 31)
        with _naming_the_spec(sp.file):
            get_method(sp.method).parse_sim_options({"progress": opts["progress"]})
        opts["progress"] = "false"
    with _naming_the_spec(sp.file):
        res = api.simulate(sp, report, options=opts, workers=workers, scheduler=scheduler)
    if plot is not None and len(res.t) > MAX_PLOT_POINTS:
        from obsdesign.errors import InputError

        # matplotlib took 5.6 GB for a 2·10⁷-step run the memory estimate had let through
        # (independent simulate review); refused before anything is printed or written
        raise InputError(
            f"--plot {plot}: the run has {len(res.t):,} grid points, above the "
            f"{MAX_PLOT_POINTS:,} a plot takes (a shorter horizon or a larger dt; --csv writes "
            "any length)"
        )
    m = res.metrics()
    if fmt == Fmt.json:
        print(_dumps(m, indent=2, default=_jsonable))
    elif fmt == Fmt.md and not quiet:
        sys.stdout.write(_metrics_markdown(m))
    elif not quiet:
        _print_metrics(m)
    if plot is not None:
        _write_plot(plot, lambda tmp: api.plot_simulation(sp, res, tmp, atomic=False), force)
        if fmt == Fmt.text:
            _say(f"plot written to {plot}")
    if csv is not None:
        from obsdesign.report.model import write_via

        def rows(tmp: Path) -> None:  # streamed: never the whole text in memory
            with open(tmp, "w", encoding="utf-8") as f:
                f.writelines(res.csv_chunks())

        write_via(csv, rows, force)
        if fmt == Fmt.text:
            _say(f"trajectories written to {csv}")
    return int(res.info.get("exit_code", 0))


def _flags_known(method: Any, runs: int | None, study: str | None) -> None:
    """``--runs`` / ``--study`` on a method without that simulation option: an error naming
    the flag the user typed (it said "--option runs: not an option", a flag they had not
    typed; outsider trial, session 22) and the methods that have it."""
    from obsdesign.errors import InputError
    from obsdesign.methods import get_method, method_keys

    known = {o.name for o in method.sim_options}
    for flag, name, val in (("--runs", "runs", runs), ("--study", "study", study)):
        if val is not None and name not in known:
            have = [k for k in method_keys() if name in {o.name for o in get_method(k).sim_options}]
            # "simulate makes one run" was false for impulsive, which has runs but no study
            # (simulate review, session 36)
            what = "one run" if "runs" not in known else "its runs, without a study"
            raise InputError(
                f"{flag} {val}: method '{method.key}' has no {name} option (simulate makes "
                f"{what}; {flag} is for {', '.join(have)})"
            )


def schema() -> int:
    """The body of ``obsdesign schema`` (see :func:`obsdesign.cli.schema`)."""
    from obsdesign import api

    print(_dumps(api.schema(), indent=2, ensure_ascii=False))
    return 0


def init(method: str) -> int:
    """The body of ``obsdesign init`` (see :func:`obsdesign.cli.init`)."""
    from obsdesign import api

    sys.stdout.write(api.template(method))
    return 0


def import_mat(
    mat: Path,
    a: str,
    c: str,
    b: str | None,
    d: str | None,
    bd: str | None,
    dt: str | None,
    dt_var: str | None,
    method: str,
) -> int:
    """The body of ``obsdesign import`` (see :func:`obsdesign.cli.import_mat`)."""
    from obsdesign import api
    from obsdesign.interop import spec_text_from_mat

    api.method(method)  # an unknown key: "did you mean"
    names = {"A": a, "C": c, "B": b, "D": d, "Bd": bd}
    seconds = None if dt is None else _dt_seconds(dt)
    sys.stdout.write(spec_text_from_mat(mat, names, method, dt=seconds, dt_name=dt_var))
    return 0


def _dt_seconds(text: str) -> Any:
    """``import --dt``: the text read exactly (a Decimal), so that a positive sample time below
    the float range is refused rather than read as 0, continuous time (``--dt 1e-400`` wrote
    ``time = "continuous"``; hostile-input trial, session 38), and the spec holds the value
    typed (``--dt 0.1000000000000000000001`` was written as 0.1; re-check review 44)."""
    import math
    from decimal import Decimal, InvalidOperation

    from obsdesign.errors import InputError

    try:
        if not text.isascii():  # Decimal reads Arabic-Indic digits; --limit does not (45)
            raise InvalidOperation
        q = Decimal(text.strip().replace("_", ""))
        f = float(q)
    except (InvalidOperation, ValueError):
        import re

        m = re.fullmatch(r"\s*[+-]?[\d_]*\.?[\d_]*[eE]([+-]?)[\d_]+\s*", text)
        if m is not None:  # an exponent past Decimal's range: "expected a number" (45)
            where = "below" if m.group(1) == "-" else "beyond"
            raise InputError(f"--dt {text!r}: {where} the float range") from None
        raise InputError(
            f"--dt {text!r}: expected a number of seconds (0: continuous time)"
        ) from None
    if q.is_finite() and q > 0 and f == 0:
        raise InputError(
            f"--dt {text!r}: a nonzero number below the float range (it would read as 0, "
            "continuous time)"
        )
    # only -1 itself is MATLAB's "no sample time"; the text as typed in the message (1e999
    # said "--dt inf"; CLI review, session 42)
    # the sign of the exact value: −1e-400 rounds to −0.0, which passed "f >= 0" and wrote
    # continuous time (re-check review, session 43)
    if q.is_finite() and not math.isfinite(f):
        raise InputError(f"--dt {text!r}: beyond the float range")  # it said "not finite" (45)
    if not (q.is_finite() and math.isfinite(f) and (q >= 0 or q == -1)):
        raise InputError(
            f"--dt {text!r}: expected a finite number >= 0 (0: continuous time), or exactly -1 "
            "(discrete time with no sample time, as MATLAB's Ts = -1)"
        )
    return -1.0 if q == -1 else q


def methods(fmt: Fmt) -> int:
    """The body of ``obsdesign methods`` (see :func:`obsdesign.cli.methods`)."""
    from obsdesign import __version__, api

    ms = api.methods()
    if fmt == Fmt.json:
        rows = [
            {
                "key": m.key,
                "title": m.title,
                "paper": m.paper,
                "needs_linear": m.needs_linear,
                "extra_tables": list(m.extra_tables),
            }
            for m in ms
        ]
        print(_dumps({"version": __version__, "methods": rows}, indent=2))
    elif fmt == Fmt.md:
        print("| key | title | paper |")
        print("| --- | --- | --- |")
        for m in ms:
            print(f"| {_md_cell(m.key)} | {_md_cell(m.title)} | {_md_cell(m.paper)} |")
    else:
        for m in ms:
            print(f"{m.key:15s} {m.title}  ({m.paper})")
    return 0
