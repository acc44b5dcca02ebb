"""The ``obsdesign`` command line: arguments, rendering and exit codes only.

Exit codes: 0 ok; 1 infeasible design or a failed claim; 2 bad input; 3 solver or internal
failure; 4 numerically inconclusive. Errors are one line on stderr; ``--debug`` shows the
traceback.
"""

# No ``from __future__ import annotations``: typer evaluates string annotations again for
# every command (all of them, for --help too) on each run.

import os
import signal
import sys

# obsdesign/__init__.py (imported before this module) installs the early Ctrl-C handler
from obsdesign import _early_interrupt

# installed before the heavy imports below (typer, rich) when the package's own check did
# not (``python obsdesign/cli.py``); _run() restores Python's handler when the command body
# starts, so that cleanup code (temp files) runs on Ctrl-C
if signal.getsignal(signal.SIGINT) is signal.default_int_handler and os.path.basename(
    sys.argv[0]
) in ("obsdesign", "cli.py"):
    signal.signal(signal.SIGINT, _early_interrupt)

import warnings  # noqa: E402
from collections.abc import Callable  # noqa: E402
from enum import StrEnum  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Annotated, Any  # noqa: E402

import typer  # noqa: E402


def _usage_name(self: Any) -> str:
    """Usage-line name of an argument as click writes it (SPEC, [SPEC], PATH...): typer ≥ 0.2x
    writes a required argument as {SPEC}, which reads like a placeholder to substitute."""
    name = self.metavar or self.display_name_raw
    if not self.required:
        name = f"[{name}]"
    if self.nargs != 1 and not name.endswith("..."):
        name += "..."
    return name


def _arg_type(self: Any, ctx: Any) -> str | None:
    """No ``<path>`` / ``<list[Path]>`` after an argument that has a metavar (SPEC, PATH...):
    the metavar and the help say what it is."""
    return None if self.metavar else _ARG_TYPE(self, ctx)


if hasattr(typer.core.TyperArgument, "_usage_display_name"):
    typer.core.TyperArgument._usage_display_name = _usage_name  # type: ignore[method-assign]
_ARG_TYPE = typer.core.TyperArgument.display_type_rich
typer.core.TyperArgument.display_type_rich = _arg_type  # type: ignore[method-assign]

#: "take typer's own path" (see :func:`_fast_value`)
_SLOW = object()


def _fast_leaf(ann: Any, info: Any, value: Any, param: Any, ctx: Any) -> Any:
    """``value`` coerced to ``ann`` as typer's pydantic adapter would, for the plain cases
    (a str, a Path, a decimal int within min/max, an enum member or its name); ``_SLOW``
    for anything else, which typer then handles itself, with its own error message."""
    from enum import Enum

    from typer import _param_types as pt

    if ann is str:
        return value if type(value) is str else _SLOW
    if ann is int and not info.clamp:
        if type(value) is str:
            digits = value.removeprefix("-")
            if not (digits.isascii() and digits.isdigit() and len(digits) <= 18):
                return _SLOW
            value = int(value)
        if type(value) is not int:
            return _SLOW
        if (info.min is not None and value < info.min) or (
            info.max is not None and value > info.max
        ):
            return _SLOW
        return value
    if isinstance(ann, type) and issubclass(ann, Enum):
        try:
            return pt.coerce_cli_choice(
                value, choices=tuple(ann), case_sensitive=info.case_sensitive, ctx=ctx
            )
        except ValueError:
            return _SLOW
    if isinstance(ann, type) and issubclass(ann, Path) and info.path_type is None:
        if type(value) is str:
            value = ann(value)  # what pydantic's Path validator returns for a str
        if not isinstance(value, ann):
            return _SLOW
        try:
            return pt.coerce_cli_path(value, info, path_type=ann, param=param, ctx=ctx)
        except Exception:  # noqa: BLE001 - typer's own path raises its own message
            return _SLOW
    return _SLOW


def _fast_value(desc: Any, value: Any, param: Any, ctx: Any) -> Any:
    """A command-line value coerced without pydantic where :func:`_fast_leaf` can (lists
    item by item, as typer's list adapter does), else ``_SLOW``."""
    from typing import get_args, get_origin

    info = desc.parameter_info
    if info.parser is not None or desc.file_annotation is not None:
        return _SLOW
    if get_origin(desc.annotation) is list and isinstance(value, (list, tuple)):
        (item,) = get_args(desc.annotation)
        out = [_fast_leaf(item, info, v, param, ctx) for v in value]
        return _SLOW if any(o is _SLOW for o in out) else out
    return _fast_leaf(desc.annotation, info, value, param, ctx)


def _install_fast_coercion() -> None:
    """typer ≥ 0.2x coerces every command-line value through a pydantic ``TypeAdapter``
    built per parameter when a command runs: importing pydantic and building the adapters
    costs ~150 ms of a ~0.5 s cold ``obsdesign design``. Values of the plain types this CLI
    declares are coerced directly (the results pydantic gives); anything else, and every
    value typer would refuse, goes through typer's own adapter, so results and error
    messages are typer's. Older typer (click types, no pydantic): nothing to do."""
    try:
        from dataclasses import dataclass

        from typer import _coercion
        from typer.core import _TyperParameter

        base, build = _coercion.RuntimeParam, _coercion.build_runtime_param
        _TyperParameter.get_runtime_param  # noqa: B018 - present in the versions patched
    except (ImportError, AttributeError):  # pragma: no cover - typer without pydantic
        return

    @dataclass(frozen=True)
    class FastParam(base):  # type: ignore[misc, valid-type]
        descriptor: Any = None

        def _coerce_value(self, value: Any, param: Any, ctx: Any) -> Any:
            out = _fast_value(self.descriptor, value, param, ctx)
            if out is _SLOW:
                out = build(self.descriptor)._coerce_value(value, param=param, ctx=ctx)
            return out

    def get_runtime_param(self: Any) -> Any:
        if self._runtime_param is None:
            d = self.type_descriptor
            self._runtime_param = FastParam(d.parameter_info, d.annotation, d)
        return self._runtime_param

    _TyperParameter.get_runtime_param = get_runtime_param  # type: ignore[method-assign]


_install_fast_coercion()

app = typer.Typer(
    name="obsdesign",
    help="Observer design with exact certificates: design, verify, simulate, check.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    # `obsdesign --install-completion` / `--show-completion` (bash, zsh, fish, PowerShell)
    add_completion=True,
    rich_markup_mode=None,  # plain click help: rendering help through rich costs ~150 ms
)
_state = {"debug": False, "quiet": False}
#: ``-`` in place of a spec (or report) path: read it from standard input
STDIN = "-"
STDIN_NAME = "<stdin>"
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


# options shared by the commands that print results
QuietOpt = Annotated[
    bool,
    typer.Option(
        "-q",
        "--quiet",
        help="Print only the one-line verdict (verify, check) or nothing (design, simulate); "
        "no progress. Errors still go to stderr; --format json still prints the JSON.",
    ),
]
WidthOpt = Annotated[
    int | None,
    typer.Option(
        "--width",
        metavar="COLUMNS",
        min=40,
        help="Width of text tables (default: the terminal's; else $COLUMNS; else 100).",
    ),
]


def _setup(quiet: bool = False, width: int | None = None) -> None:
    """Apply -q/--quiet and --width for this command."""
    _state["quiet"] = quiet
    if width is not None:
        from obsdesign.report.render import set_width

        set_width(width)


def _is_stdin(path: Path | None) -> bool:
    return path is not None and str(path) == STDIN


def _inputs(*paths: Path | None) -> tuple[Path, ...]:
    """The input files among ``paths`` (stdin and None left out), for the output checks."""
    return tuple(p for p in paths if p is not None and not _is_stdin(p))


def _read_stdin(what: str) -> str:
    """Standard input as text, within ``max_file_bytes`` (``-`` in place of a path)."""
    from obsdesign.errors import InputError
    from obsdesign.limits import limits

    lim = limits().max_file_bytes
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
    from obsdesign.limits import limits

    text = _read_stdin("spec")
    if text.count(",") >= limits().max_values:
        raise InputError(
            f"{STDIN_NAME}: holds about {text.count(',') + 1} values, above the limit of "
            f"{limits().max_values} (--limit max_values=N)"
        )
    return api.load_spec_text(text, STDIN_NAME)


def _say(text: str) -> None:
    """An informational line on stdout (text format), unless --quiet."""
    if not _state["quiet"]:
        print(text)


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


def _version(value: bool) -> None:
    if value:
        from obsdesign import __version__

        print(f"obsdesign {__version__}")
        raise typer.Exit(0)


@app.callback()
def _main(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks on errors.")] = False,
    limit: Annotated[
        list[str] | None,
        typer.Option(
            "--limit",
            metavar="KEY=VALUE",
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
    spec: Annotated[
        Path, typer.Argument(metavar="SPEC", help="Spec file (TOML); - reads it from stdin.")
    ],
    output: Annotated[
        Path | None,
        typer.Option("-o", "--output", metavar="FILE", help="Write the JSON report here."),
    ] = None,
    fmt: Annotated[
        Fmt, typer.Option("--format", help="Output format on stdout (json: the report only).")
    ] = Fmt.text,
    plot: Annotated[
        Path | None,
        typer.Option(
            "--plot",
            "--plot-epsilon",
            metavar="FILE",
            help="Write the method's design plot (PNG/SVG), e.g. ε(z).",
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
    quiet: QuietOpt = False,
    width: WidthOpt = None,
) -> None:
    """Design the observer of SPEC, certify every claim, and print (or write) the report.

    The report at -o is written whatever the verdict (its "verdict" says ok, failed,
    inconclusive, or error when the design stopped with an error), so it is never stale;
    bad input (exit 2) writes nothing."""

    def body() -> int:
        _setup(quiet, width)
        _precheck(spec)  # before the heavy imports: an oversized spec is refused at once
        from obsdesign import api
        from obsdesign.errors import InputError
        from obsdesign.report.model import check_output

        if output is not None:
            check_output(output, force, _inputs(spec))
        _check_plot(plot, force, _inputs(spec, output))
        progress = _progress() if fmt == Fmt.text and not quiet else None
        sp = _load_spec(spec)
        if plot is not None and api.method(sp.method).plot_design is None:
            raise InputError(f"--plot: method '{sp.method}' has no design plot")
        rep = api.design(sp, output, progress=progress, force=force)
        if not quiet or fmt == Fmt.json:
            _print_report(rep, fmt)
        if plot is not None:
            _write_plot(plot, lambda tmp: api.plot_design(sp, rep.parameters, tmp), force)
            if fmt == Fmt.text:
                _say(f"plot written to {plot}")
        if output is not None and fmt == Fmt.text:
            _say(f"report written to {output}")
        return rep.exit_code()

    _run(body)


@app.command()
def verify(
    report: Annotated[
        Path,
        typer.Argument(
            metavar="REPORT", help="JSON report written by 'design'; - reads it from stdin."
        ),
    ],
    spec: Annotated[
        Path | None,
        typer.Option("--spec", metavar="SPEC", help="Check against this spec (hash must match)."),
    ] = None,
    fmt: Annotated[Fmt, typer.Option("--format", help="Output format on stdout.")] = Fmt.text,
    quiet: QuietOpt = False,
    width: WidthOpt = None,
) -> None:
    """Re-check every claim of REPORT independently; exit 0 only if all hold.

    The last line (text and md) is the verdict, e.g. "verified: 8 claims certified,
    0 failed"."""

    def body() -> int:
        _setup(quiet, width)
        from obsdesign.limits import precheck_spec, read_input

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

    _run(body)


# Dask options (issue 13; obsdesign.distributed)
WorkersOpt = Annotated[
    int | None,
    typer.Option(
        "--workers",
        metavar="N",
        help="Run on a Dask LocalCluster of N worker processes (needs obsdesign[distributed]); "
        "the output is the serial run's.",
    ),
]
SchedulerOpt = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="Run on an existing Dask cluster (see docs/sweeps.md: dask scheduler, dask worker).",
    ),
]


@app.command()
def check(
    paths: Annotated[
        list[Path],
        typer.Argument(metavar="PATH...", help="Spec files or folders of *.toml."),
    ],
    fmt: Annotated[Fmt, typer.Option("--format", help="Output format on stdout.")] = Fmt.text,
    junit: Annotated[
        Path | None,
        typer.Option(
            "--junit",
            metavar="FILE",
            help="Also write a JUnit XML report (one testcase per spec and per claim).",
        ),
    ] = None,
    quiet: QuietOpt = False,
    width: WidthOpt = None,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
) -> None:
    """Design and verify every spec; one row per spec; non-zero exit if any fails.

    Folders are searched recursively for *.toml (hidden folders skipped). Every spec gets a
    row whatever happens in it: its exit code and message (an internal error is exit 3).
    The last line (text and md) is the verdict, e.g. "checked: 13 specs, 13 ok, 0 failed;
    151 claims certified, 5 numerical, 0 failed"."""

    def body() -> int:
        _setup(quiet, width)
        from obsdesign import api

        if junit is not None:
            from obsdesign.report.model import check_output

            check_output(junit, False, _inputs(*paths))

        def each(f: Path) -> None:
            if fmt == Fmt.text and not quiet:
                sys.stderr.write(f"checking {f} ...\n")

        if workers is None and scheduler is None:
            rows = api.check(list(paths), on_start=each)
        else:
            rows = _check_distributed(list(paths), workers, scheduler, quiet)
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

    _run(body)


def _check_distributed(
    paths: list[Path], workers: int | None, scheduler: str | None, quiet: bool
) -> list[Any]:
    """``check`` on Dask, with a progress bar on stderr (unless --quiet)."""
    from obsdesign import api
    from obsdesign.distributed import check_workers, progress_bar

    check_workers(workers, scheduler)
    n = len(api.spec_files(list(paths)))
    with progress_bar(n, "check", quiet) as advance:
        return api.check(
            list(paths), workers=workers, scheduler=scheduler, on_row=lambda r: advance(r.code != 0)
        )


@app.command()
def sweep(
    spec: Annotated[
        Path, typer.Argument(metavar="SPEC", help="Spec file (TOML); - reads it from stdin.")
    ],
    sets: Annotated[
        list[str],
        typer.Option(
            "--set",
            metavar="KEY=VALUES",
            help="A swept spec key (repeatable): a:b:n (linear), a:b:n:log, [v1, v2, ...] "
            "or one value; e.g. method.lambda=0.90:0.99:10.",
        ),
    ],
    simulate: Annotated[
        bool, typer.Option("--simulate", help="Also simulate every point (metrics columns).")
    ] = False,
    option: Annotated[
        list[str] | None,
        typer.Option(
            "--option", metavar="KEY=VALUE", help="Simulation option KEY=VALUE (repeatable)."
        ),
    ] = None,
    output: Annotated[
        Path | None,
        typer.Option(
            "-o",
            "--output",
            metavar="FILE",
            help="Write the table (.csv, .jsonl, .parquet), atomically at the end.",
        ),
    ] = None,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", metavar="FILE", help="Plot --y against a swept key (PNG/SVG)."),
    ] = None,
    y: Annotated[
        str | None, typer.Option("--y", metavar="COLUMN", help="The plotted column.")
    ] = None,
    x: Annotated[
        str | None,
        typer.Option("--x", metavar="KEY", help="The swept key on the x axis (the first one)."),
    ] = None,
    fmt: Annotated[Fmt, typer.Option("--format", help="Output format on stdout.")] = Fmt.text,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    force: Annotated[
        bool, typer.Option("--force", help="Write -o/--plot even where refused by default.")
    ] = False,
    quiet: QuietOpt = False,
    width: WidthOpt = None,
) -> None:
    """Design and verify SPEC at every point of a grid of spec keys; one row per point.

    Every point gets a row whatever happens in it (its exit code and message); the exit code
    is the worst row's. See docs/sweeps.md."""

    def body() -> int:
        _setup(quiet, width)
        _precheck(spec)
        import types

        from obsdesign import sweep as sw
        from obsdesign.distributed import check_workers, progress_bar
        from obsdesign.errors import InputError

        check_workers(workers, scheduler)
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
        if plot is not None:
            cols = sw.expected_columns(tasks[0].text, axes, simulate)
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
            )
        if output is not None:
            sw.write_table(output, rows, force)
        if plot is not None:
            sw.check_plot_column(rows, axes, y or "", x)
            _write_plot(plot, lambda tmp: sw.plot_sweep(rows, axes, y or "", tmp, x), force)
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
        print(f"\n**{line}**" if fmt == Fmt.md and not quiet else line)
        if output is not None and fmt == Fmt.text:
            _say(f"table written to {output}")
        if plot is not None and fmt == Fmt.text:
            _say(f"plot written to {plot}")
        return sw.exit_code(rows)

    _run(body)


def _print_sweep(rows: list[dict[str, Any]], fmt: Fmt) -> None:
    from obsdesign.sweep import TIMING_COLUMNS, columns

    cols = [c for c in columns(rows) if c not in ("method", *TIMING_COLUMNS)]
    if fmt == Fmt.md:
        print("| " + " | ".join(cols) + " |")
        print("|" + " --- |" * len(cols))
        for r in rows:
            print("| " + " | ".join(_md_cell(r.get(c, "")) for c in cols) + " |")
        return
    from rich.table import Table

    from obsdesign.report.render import console, esc

    t = Table(title="obsdesign sweep")
    for c in cols:
        t.add_column(esc(c), overflow="fold")
    for r in rows:
        t.add_row(*(esc(_sweep_cell(r.get(c))) for c in cols))
    console().print(t)


def _sweep_cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return format(v, ".6g")
    return str(v)


@app.command()
def simulate(
    spec: Annotated[
        Path,
        typer.Argument(
            metavar="SPEC", help="Spec file with a [simulate] table; - reads it from stdin."
        ),
    ],
    report: Annotated[
        Path | None,
        typer.Option("--report", metavar="REPORT", help="Use this report's parameters."),
    ] = None,
    plot: Annotated[
        Path | None, typer.Option("--plot", metavar="FILE", help="Write a plot (PNG/SVG).")
    ] = None,
    fmt: Annotated[Fmt, typer.Option("--format", help="Output format on stdout.")] = Fmt.text,
    option: Annotated[
        list[str] | None,
        typer.Option(
            "--option",
            metavar="KEY=VALUE",
            help="Method simulation option KEY=VALUE (repeatable).",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Write --plot even where it is refused by default.")
    ] = False,
    runs: Annotated[
        int | None,
        typer.Option(
            "--runs",
            metavar="N",
            min=1,
            help="Monte Carlo runs (same as --option runs=N, for methods with a runs option): "
            "initial errors from [simulate] initial_error, signals from seeds spawned from "
            "[simulate] seed; prints quantiles of the per-run metrics.",
        ),
    ] = None,
    study: Annotated[
        str | None,
        typer.Option(
            "--study",
            metavar="NAME",
            help="A method's study (same as --option study=NAME), e.g. 'outliers' for stubborn.",
        ),
    ] = None,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    quiet: QuietOpt = False,
    width: WidthOpt = None,
) -> None:
    """Run the plant and the designed observer over the spec's scenario; print metrics.

    With --workers/--scheduler the Monte Carlo runs (--runs) are split into one batch per
    Dask worker; the numbers are the serial run's."""

    def body() -> int:
        _setup(quiet, width)
        _precheck(spec)  # before the heavy imports
        from obsdesign import api

        if workers is not None or scheduler is not None:
            from obsdesign.distributed import check_workers

            check_workers(workers, scheduler)
        _check_plot(plot, force, _inputs(spec, report))
        sp = _load_spec(spec)
        opts = _kv(option or [])
        if runs is not None:
            opts["runs"] = str(runs)
        if study is not None:
            opts["study"] = study
        res = api.simulate(sp, report, options=opts, workers=workers, scheduler=scheduler)
        m = res.metrics()
        if fmt == Fmt.json:
            print(_dumps(m, indent=2, default=_jsonable))
        elif fmt == Fmt.md and not quiet:
            sys.stdout.write(_metrics_markdown(m))
        elif not quiet:
            _print_metrics(m)
        if plot is not None:
            _write_plot(plot, lambda tmp: api.plot_simulation(sp, res, tmp), force)
            if fmt == Fmt.text:
                _say(f"plot written to {plot}")
        return int(res.info.get("exit_code", 0))

    _run(body)


class JsonFmt(StrEnum):
    json = "json"


@app.command()
def schema(
    fmt: Annotated[
        JsonFmt, typer.Option("--format", help="Output format (JSON schema only).")
    ] = JsonFmt.json,
) -> None:
    """Print the JSON schema of the spec format (draft 2020-12).

    Expression-valued keys carry "format": "obsdesign-expression"."""

    def body() -> int:
        from obsdesign import api

        print(_dumps(api.schema(), indent=2, ensure_ascii=False))
        return 0

    _run(body)


@app.command()
def init(
    method: Annotated[
        str,
        typer.Argument(
            metavar="METHOD", help="Method key (see 'obsdesign methods').", show_default=False
        ),
    ],
) -> None:
    """Print a commented template spec (TOML) for METHOD, e.g. obsdesign init lyapunov > my.toml.

    Every commented line "# key = value" is a valid alternative once uncommented."""

    def body() -> int:
        from obsdesign import api

        sys.stdout.write(api.template(method))
        return 0

    _run(body)


@app.command("import")
def import_mat(
    mat: Annotated[
        Path, typer.Argument(metavar="FILE.mat", help="MATLAB .mat file (scipy.io.loadmat).")
    ],
    a: Annotated[str, typer.Option("--A", metavar="NAME", help="Variable holding A.")] = "A",
    c: Annotated[str, typer.Option("--C", metavar="NAME", help="Variable holding C.")] = "C",
    b: Annotated[
        str | None, typer.Option("--B", metavar="NAME", help="Variable holding B (optional).")
    ] = None,
    d: Annotated[
        str | None, typer.Option("--D", metavar="NAME", help="Variable holding D (optional).")
    ] = None,
    bd: Annotated[
        str | None,
        typer.Option("--Bd", metavar="NAME", help="Variable holding the disturbance input Bd."),
    ] = None,
    dt: Annotated[
        float | None,
        typer.Option(
            "--dt", metavar="SECONDS", help="Sample time: discrete time (default: continuous)."
        ),
    ] = None,
    dt_var: Annotated[
        str | None,
        typer.Option("--dt-var", metavar="NAME", help="Variable holding the sample time."),
    ] = None,
    method: Annotated[
        str, typer.Option("--method", metavar="KEY", help="[method] key of the spec.")
    ] = "lyapunov",
) -> None:
    """Print a spec (TOML) built from the matrices of a MATLAB .mat file, e.g.
    obsdesign import plant.mat --A A --C C --dt 0.1 > spec.toml.

    Floats are written by their shortest repr (the spec reads back as the same doubles).
    Add the method's options to the printed [method] table (see obsdesign init KEY)."""

    def body() -> int:
        from obsdesign import api
        from obsdesign.interop import spec_text_from_mat

        api.method(method)  # an unknown key: "did you mean"
        names = {"A": a, "C": c, "B": b, "D": d, "Bd": bd}
        sys.stdout.write(spec_text_from_mat(mat, names, method, dt=dt, dt_name=dt_var))
        return 0

    _run(body)


@app.command()
def methods(
    fmt: Annotated[Fmt, typer.Option("--format", help="Output format on stdout.")] = Fmt.text,
) -> None:
    """List the design methods (--format json also gives the obsdesign version)."""

    def body() -> int:
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


def _dumps(obj: Any, **kw: Any) -> str:
    """``json.dumps`` (json loads only on the paths that print JSON)."""
    import json

    return json.dumps(obj, **kw)


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

    t = Table(title="obsdesign check", caption="claims: certified/numerical/failed")
    # method, verdict and the claim counts never wrap; the spec path folds (no spaces in
    # it) and the result wraps at spaces with twice the spec's share of the rest
    t.add_column("spec", overflow="fold", ratio=1)
    t.add_column("method", no_wrap=True)
    t.add_column("verdict", no_wrap=True)
    t.add_column("claims", no_wrap=True)
    t.add_column("result", overflow="fold", ratio=2)
    t.add_column("s", no_wrap=True)
    for r in rows:
        verdict = "[green]ok[/]" if r.code == 0 else f"[bold red]exit {r.code}[/]"
        t.add_row(
            esc(r.spec),
            esc(r.method),
            verdict,
            f"{r.certified}/{r.numerical}/{r.failed}",
            esc(r.summary if r.code == 0 else r.message),
            f"{r.seconds:.2f}",
        )
    console().print(t)


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
    import json

    from obsdesign.errors import InputError
    from obsdesign.limits import int_digits
    from obsdesign.report.model import Report

    text = _read_stdin("report")
    try:
        with int_digits():
            d = json.loads(text)
    except json.JSONDecodeError as e:
        raise InputError(f"{STDIN_NAME}: not a readable JSON report ({e})") from None
    except RecursionError:
        raise InputError(f"{STDIN_NAME}: JSON nested too deeply") from None
    return Report.from_dict(d, STDIN_NAME)[0]


def _metrics_markdown(m: dict[str, Any]) -> str:
    lines = ["| state | sup \\|e_i\\| | RMSE | sup \\|x̂_i\\| |", "| --- | --- | --- | --- |"]
    for st, v in m["sup_abs_error"].items():
        lines.append(
            f"| {_md_cell(st)} | {v:.6g} | {m['rmse'][st]:.6g} | {m['sup_abs_estimate'][st]:.6g} |"
        )
    lines += ["", f"final \\|e\\| = {m['final_error_norm']:.6g}"]
    for k, v in m.items():
        if k not in ("sup_abs_error", "rmse", "final_error_norm", "sup_abs_estimate", "exit_code"):
            lines.append(f"- {_md_cell(k)}: {_md_cell(v)}")
    return "\n".join(lines) + "\n"


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
