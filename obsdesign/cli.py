"""The ``obsdesign`` command line: arguments, rendering and exit codes only.

Exit codes: 0 ok; 1 infeasible design or a failed claim; 2 bad input; 3 solver or internal
failure; 4 numerically inconclusive. Errors are one line on stderr; ``--debug`` shows the
traceback.
"""

from __future__ import annotations

import os
import signal
import sys


def _early_interrupt(signum: int, frame: object) -> None:  # pragma: no cover - timing
    """Ctrl-C while the heavy modules load: one line, exit 130, no traceback."""
    sys.stderr.write("obsdesign: interrupted\n")
    os._exit(130)


# installed before the heavy imports below (typer, rich); _run() restores Python's handler
# when the command body starts, so that cleanup code (temp files) runs on Ctrl-C
if signal.getsignal(signal.SIGINT) is signal.default_int_handler and os.path.basename(
    sys.argv[0]
) in ("obsdesign", "cli.py"):
    signal.signal(signal.SIGINT, _early_interrupt)

import json  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Callable  # noqa: E402
from enum import StrEnum  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Annotated, Any  # noqa: E402

import typer  # noqa: E402

app = typer.Typer(
    name="obsdesign",
    help="Observer design with exact certificates: design, verify, simulate, check.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    rich_markup_mode=None,  # plain click help: rendering help through rich costs ~150 ms
)
_state = {"debug": False}
#: plot formats (matplotlib's savefig, by the file suffix)
PLOT_SUFFIXES = (
    ".png",
    ".svg",
    ".svgz",
    ".pdf",
    ".eps",
    ".ps",
    ".jpg",
    ".jpeg",
    ".tif",
    ".tiff",
    ".webp",
)


class Fmt(StrEnum):
    text = "text"
    json = "json"
    md = "md"


def _err(msg: str) -> None:
    sys.stderr.write(f"obsdesign: error: {msg}\n")


def _run(fn: Callable[[], int]) -> None:
    """Run a command body, mapping errors to exit codes without a traceback."""
    from obsdesign.errors import EXIT_SOLVER, ObsdesignError

    try:
        # from here on Ctrl-C raises KeyboardInterrupt (handled below, cleanup runs)
        if signal.getsignal(signal.SIGINT) is _early_interrupt:
            signal.signal(signal.SIGINT, signal.default_int_handler)
        # the API turns warnings into report notes; any other stray warning (numpy, scipy)
        # is not printed unless --debug
        with warnings.catch_warnings(record=True) as stray:
            warnings.simplefilter("always")
            code = fn()
        if _state["debug"]:
            for w in stray:
                _err(f"warning: {w.category.__name__}: {w.message}")
    except ObsdesignError as e:
        if _state["debug"]:
            raise
        _err(e.message)
        raise typer.Exit(e.exit_code) from None
    except typer.Exit:
        raise
    except BrokenPipeError:
        _quiet_broken_pipe()
    except KeyboardInterrupt:
        _err("interrupted")
        raise typer.Exit(130) from None
    except Exception as e:  # noqa: BLE001 - last line of defence: no traceback for users
        if _state["debug"]:
            raise
        _err(f"internal failure: {type(e).__name__}: {e} (run with --debug for the traceback)")
        raise typer.Exit(EXIT_SOLVER) from None
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_broken_pipe()
    raise typer.Exit(code)


def _quiet_broken_pipe() -> None:
    """The reader of stdout went away (``obsdesign schema | head -1``): stop quietly with
    exit 141, as a process killed by SIGPIPE would (stdout is pointed at /dev/null so that
    Python's own flush at exit does not complain)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    raise typer.Exit(141) from None


def _check_plot(path: Path | None, force: bool, inputs: tuple[Path, ...] = ()) -> None:
    """Refuse a plot path before any work: an unknown format or a path that
    :func:`obsdesign.report.model.check_output` refuses (exit 2)."""
    if path is None:
        return
    from obsdesign.errors import InputError
    from obsdesign.report.model import check_output

    if path.suffix.lower() not in PLOT_SUFFIXES:
        raise InputError(
            f"{path}: unknown plot format {path.suffix or '(no suffix)'!r} "
            f"(expected one of {', '.join(PLOT_SUFFIXES)})"
        )
    check_output(path, force, inputs)


def _write_plot(path: Path, draw: Callable[[Path], Any], force: bool) -> None:
    from obsdesign.report.model import write_via

    write_via(path, draw, force)


@app.callback()
def _main(
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks on errors.")] = False,
    limit: Annotated[
        list[str] | None,
        typer.Option(
            "--limit",
            help="Change an input limit for this run, KEY=VALUE (repeatable), e.g. "
            "max_digits=5000, max_file_bytes=64M; see docs/reliability.md.",
        ),
    ] = None,
) -> None:
    _state["debug"] = debug
    if limit:
        from obsdesign.errors import ObsdesignError
        from obsdesign.limits import parse_limit, set_limits

        try:
            set_limits(**dict(parse_limit(x) for x in limit))
        except ObsdesignError as e:
            _err(e.message)
            raise typer.Exit(e.exit_code) from None


@app.command()
def design(
    spec: Annotated[Path, typer.Argument(help="Spec file (TOML).")],
    output: Annotated[
        Path | None, typer.Option("-o", "--output", help="Write the JSON report here.")
    ] = None,
    fmt: Annotated[Fmt, typer.Option("--format", help="Output format on stdout.")] = Fmt.text,
    plot: Annotated[
        Path | None,
        typer.Option(
            "--plot", "--plot-epsilon", help="Write the method's design plot (PNG/SVG), e.g. ε(z)."
        ),
    ] = None,
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Write -o/--plot even over the spec itself, through a symbolic link, into a "
            "non-regular file or over a write-protected file.",
        ),
    ] = False,
) -> None:
    """Design the observer of SPEC, certify every claim, and print (or write) the report.

    The report at -o is written whatever the verdict (its "verdict" says ok, failed,
    inconclusive, or error when the design stopped with an error), so it is never stale;
    bad input (exit 2) writes nothing."""

    def body() -> int:
        from obsdesign.limits import precheck_spec

        precheck_spec(spec)  # before the heavy imports: an oversized spec is refused at once
        from obsdesign import api
        from obsdesign.errors import InputError
        from obsdesign.report.model import check_output

        if output is not None:
            check_output(output, force, (spec,))
        _check_plot(plot, force, (spec,) + ((output,) if output is not None else ()))
        progress = _progress() if fmt == Fmt.text else None
        sp = api.load_spec(spec)
        if plot is not None and api.method(sp.method).plot_design is None:
            raise InputError(f"--plot: method '{sp.method}' has no design plot")
        rep = api.design(sp, output, progress=progress, force=force)
        _print_report(rep, fmt)
        if plot is not None:
            _write_plot(plot, lambda tmp: api.plot_design(sp, rep.parameters, tmp), force)
            if fmt == Fmt.text:
                print(f"plot written to {plot}")
        if output is not None and fmt == Fmt.text:
            print(f"report written to {output}")
        return rep.exit_code()

    _run(body)


@app.command()
def verify(
    report: Annotated[Path, typer.Argument(help="JSON report written by 'design'.")],
    spec: Annotated[
        Path | None, typer.Option("--spec", help="Check against this spec (hash must match).")
    ] = None,
    fmt: Annotated[Fmt, typer.Option("--format")] = Fmt.text,
) -> None:
    """Re-check every claim of REPORT independently; exit 0 only if all hold."""

    def body() -> int:
        from obsdesign.limits import precheck_spec, read_input

        read_input(report, "report")  # before the heavy imports (regular file, size)
        if spec is not None:
            precheck_spec(spec)
        from obsdesign import api

        rep = api.verify(report, spec)
        _print_report(rep, fmt)
        return rep.exit_code()

    _run(body)


@app.command()
def check(
    paths: Annotated[list[Path], typer.Argument(help="Spec files or folders of *.toml.")],
    fmt: Annotated[Fmt, typer.Option("--format")] = Fmt.text,
) -> None:
    """Design and verify every spec; one row per spec; non-zero exit if any fails.

    Folders are searched recursively for *.toml (hidden folders skipped). Every spec gets a
    row whatever happens in it: its exit code and message (an internal error is exit 3)."""

    def body() -> int:
        from obsdesign import api

        def each(f: Path) -> None:
            if fmt == Fmt.text:
                sys.stderr.write(f"checking {f} ...\n")

        rows = api.check(list(paths), on_start=each)
        if fmt == Fmt.json:
            print(json.dumps([r.__dict__ for r in rows], indent=2))
        else:
            _print_rows(rows, fmt)
        return api.check_exit_code(rows)

    _run(body)


@app.command()
def simulate(
    spec: Annotated[Path, typer.Argument(help="Spec file with a [simulate] table.")],
    report: Annotated[
        Path | None, typer.Option("--report", help="Use this report's parameters.")
    ] = None,
    plot: Annotated[Path | None, typer.Option("--plot", help="Write a plot (PNG/SVG).")] = None,
    fmt: Annotated[Fmt, typer.Option("--format")] = Fmt.text,
    option: Annotated[
        list[str] | None,
        typer.Option("--option", help="Method simulation option KEY=VALUE (repeatable)."),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Write --plot even where it is refused by default.")
    ] = False,
) -> None:
    """Run the plant and the designed observer over the spec's scenario; print metrics."""

    def body() -> int:
        from obsdesign.limits import precheck_spec

        precheck_spec(spec)  # before the heavy imports
        from obsdesign import api

        _check_plot(plot, force, (spec,) + ((report,) if report is not None else ()))
        sp = api.load_spec(spec)
        res = api.simulate(sp, report, options=_kv(option or []))
        m = res.metrics()
        if fmt == Fmt.json:
            print(json.dumps(m, indent=2, default=_jsonable))
        else:
            _print_metrics(m)
        if plot is not None:
            _write_plot(plot, lambda tmp: api.plot_simulation(sp, res, tmp), force)
            if fmt == Fmt.text:
                print(f"plot written to {plot}")
        return int(res.info.get("exit_code", 0))

    _run(body)


@app.command()
def schema() -> None:
    """Print the JSON schema of the spec format."""

    def body() -> int:
        from obsdesign import api

        print(json.dumps(api.schema(), indent=2, ensure_ascii=False))
        return 0

    _run(body)


@app.command()
def init(method: Annotated[str, typer.Argument(help="Method key.")]) -> None:
    """Print a commented template spec for METHOD."""

    def body() -> int:
        from obsdesign import api

        sys.stdout.write(api.template(method))
        return 0

    _run(body)


@app.command()
def methods() -> None:
    """List the design methods."""

    def body() -> int:
        from obsdesign import api

        for m in api.methods():
            print(f"{m.key:15s} {m.title}  ({m.paper})")
        return 0

    _run(body)


# -- helpers -------------------------------------------------------------------------------
def _kv(items: list[str]) -> dict[str, str]:
    from obsdesign.errors import InputError

    out = {}
    for it in items:
        if "=" not in it:
            raise InputError(f"--option expects KEY=VALUE, got {it!r}")
        k, v = it.split("=", 1)
        out[k.strip()] = v.strip()
    return out


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


def _print_report(rep: Any, fmt: Fmt) -> None:
    from obsdesign.report.render import render_markdown, render_text

    if sys.stderr.isatty() and fmt == Fmt.text:
        sys.stderr.write("\r\033[K")
    if fmt == Fmt.json:
        print(rep.to_json())
    elif fmt == Fmt.md:
        sys.stdout.write(render_markdown(rep))
    else:
        render_text(rep)


def _print_rows(rows: list[Any], fmt: Fmt) -> None:
    if fmt == Fmt.md:
        print("| spec | method | exit | certified | numerical | failed | result | seconds |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        for r in rows:
            cells = [r.spec, r.method, r.code, r.certified, r.numerical, r.failed]
            cells += [r.summary or r.message, f"{r.seconds:.2f}"]
            print("| " + " | ".join(_md_cell(c) for c in cells) + " |")
        return
    from rich.table import Table

    from obsdesign.report.render import console, esc

    t = Table(title="obsdesign check")
    for c in ("spec", "method", "verdict", "cert.", "num.", "failed", "result", "s"):
        t.add_column(c, overflow="fold")
    for r in rows:
        verdict = "[green]ok[/]" if r.code == 0 else f"[bold red]exit {r.code}[/]"
        t.add_row(
            esc(r.spec),
            esc(r.method),
            verdict,
            str(r.certified),
            str(r.numerical),
            str(r.failed),
            esc(r.summary if r.code == 0 else r.message),
            f"{r.seconds:.2f}",
        )
    console().print(t)


def _md_cell(v: Any) -> str:
    """A Markdown table cell: pipes escaped, one line."""
    return str(v).replace("|", "\\|").replace("\n", " ")


def _print_metrics(m: dict[str, Any]) -> None:
    from rich.table import Table

    from obsdesign.report.render import console, esc

    t = Table(title="simulation metrics")
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
        if k not in ("sup_abs_error", "rmse", "final_error_norm", "sup_abs_estimate", "exit_code"):
            c.print(esc(f"{k}: {v}"))


def main() -> None:
    """Console-script entry point."""
    try:
        app()
    except KeyboardInterrupt:  # pragma: no cover - Ctrl-C outside a command body
        _err("interrupted")
        sys.exit(130)


if __name__ == "__main__":
    main()
