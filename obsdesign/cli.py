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


def _fast_runtime_param(self: Any) -> Any:
    """``_TyperParameter.get_runtime_param`` of typer ≥ 0.2x, which coerces every
    command-line value through a pydantic ``TypeAdapter`` built per parameter when a command
    runs: importing pydantic and building the adapters costs ~150 ms of a ~0.5 s cold
    ``obsdesign design``. See :mod:`obsdesign.cli_coerce` (loaded with the first value a
    command coerces; ``--help`` coerces none)."""
    if self._runtime_param is None:
        try:
            from obsdesign.cli_coerce import FastParam

            self._runtime_param = FastParam(self.type_descriptor)
        except (ImportError, AttributeError, TypeError):  # a typer whose internals differ
            return _TYPER_RUNTIME_PARAM(self)
    return self._runtime_param


# typer without pydantic coercion (click types, < 0.2x) has no such method: nothing to do
_TYPER_RUNTIME_PARAM = getattr(
    getattr(typer.core, "_TyperParameter", None), "get_runtime_param", None
)
if _TYPER_RUNTIME_PARAM is not None:
    typer.core._TyperParameter.get_runtime_param = _fast_runtime_param  # type: ignore[method-assign]

app = typer.Typer(
    name="obsdesign",
    help="Observer design with exact certificates: design, verify, simulate, check.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    # `obsdesign --install-completion` / `--show-completion` (bash, zsh, fish, PowerShell)
    add_completion=True,
    rich_markup_mode=None,  # plain click help: rendering help through rich costs ~150 ms
)
_state = {"debug": False}
#: ``-`` in place of a spec (or report) path: read it from standard input
STDIN = "-"
STDIN_NAME = "<stdin>"


class Fmt(StrEnum):
    text = "text"
    json = "json"
    md = "md"


def _err(msg: str) -> None:
    from obsdesign.errors import one_line

    sys.stderr.write(f"obsdesign: error: {one_line(msg)}\n")


# options shared by the commands that print results
QuietOpt = Annotated[
    bool,
    typer.Option(
        "-q",
        "--quiet",
        help="Print only the one-line verdict (verify, check, sweep) or nothing (design, "
        "simulate); no progress. Errors still go to stderr; --format json still prints the "
        "JSON.",
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


FmtOpt = Annotated[Fmt, typer.Option("--format", help="Output format on stdout.")]
SpecArg = Annotated[
    Path, typer.Argument(metavar="SPEC", help="Spec file (TOML); - reads it from stdin.")
]


def _run(fn: Callable[[Any], int], quiet: bool = False, width: int | None = None) -> None:
    """Run a command body ``fn(obsdesign.cli_commands)`` with -q/--quiet and --width applied,
    mapping errors to exit codes without a traceback."""
    from obsdesign import interrupt
    from obsdesign.errors import EXIT_SOLVER, ObsdesignError

    # the console script (not an in-process caller such as CliRunner) owns SIGINT: from here
    # on Ctrl-C raises KeyboardInterrupt (handled below, cleanup runs) and is recorded, so
    # that it ends in exit 130 even when the exception is lost on its way up
    owned = signal.getsignal(signal.SIGINT) is _early_interrupt
    interrupt.reset()
    try:
        if owned:
            signal.signal(signal.SIGINT, interrupt.handler)
            interrupt.install_quiet_unraisable()  # the console script's own process
        # SIGTERM whoever owns SIGINT: a script's background job starts with SIGINT ignored,
        # and `timeout` there still left a half-written temp file (re-check trial, session 27)
        # SIGHUP (a closed terminal, a dropped ssh) and SIGQUIT (Ctrl-\\) likewise: they left
        # the hidden temp file of an output being written (CLI hostile-input trial, session 34)
        caught = [
            sig
            for sig in _STOP_SIGNALS
            if _main_thread() and signal.getsignal(sig) is signal.SIG_DFL
        ]
        for sig in caught:
            signal.signal(sig, interrupt.handler)
        if caught and os.path.basename(sys.argv[0] if sys.argv else "") in _SCRIPTS:
            interrupt.install_quiet_unraisable()  # a background console script's process
        from obsdesign import cli_commands

        cli_commands.setup(quiet, width)
        sys.stdout = _Stdout(sys.stdout)  # an OS error on stdout is exit 2 (undone below)

        # the API turns warnings into report notes; any other stray warning (numpy, scipy)
        # is not printed unless --debug
        with warnings.catch_warnings(record=True) as stray:
            warnings.simplefilter("always")
            code = fn(cli_commands)
        _settle(owned)
        if _state["debug"]:
            for w in stray:
                _err(f"warning: {w.category.__name__}: {w.message}")
    except ObsdesignError as e:
        _settle(owned)
        if _state["debug"]:
            raise
        _err(e.message)
        if e.message.startswith("stdout: cannot write"):
            # what stdout still buffers would fail main's flush: the line printed twice
            # without PYTHONUNBUFFERED (re-check review 46)
            _drop_stdout()
        raise typer.Exit(e.exit_code) from None
    except typer.Exit:
        _settle(owned)
        raise
    except BrokenPipeError:
        _quiet_broken_pipe()
    except KeyboardInterrupt:
        _settle(owned)
        _interrupted()
    except Exception as e:  # noqa: BLE001 - last line of defence: no traceback for users
        _settle(owned)
        if _state["debug"]:
            raise
        _err(f"internal failure: {type(e).__name__}: {e} (run with --debug for the traceback)")
        raise typer.Exit(EXIT_SOLVER) from None
    finally:
        if isinstance(sys.stdout, _Stdout):
            sys.stdout = sys.stdout.wrapped
    raise typer.Exit(_flushed(code))


def _flushed(code: int) -> int:
    """``code`` once what stdout still buffers is written, else the exit code of the failure,
    said once: 141 for a closed pipe (quietly), 2 for any other OS error."""
    try:
        sys.stdout.flush()
        return code
    except BrokenPipeError:
        _drop_stdout()
        return 141
    except OSError as e:
        _err(_stdout_error(e).message)
        _drop_stdout()
        return int(_stdout_error(e).exit_code)


def _drop_stdout() -> None:
    """Point stdout's descriptor at /dev/null once its error is reported: the bytes left in
    Python's buffer made the flush at exit fail again, "Exception ignored … OSError" and exit
    120 — on any machine without PYTHONUNBUFFERED (fresh-Debian review 46)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):
        pass


#: the program names of the console script's own process (``obsdesign``, ``python -m
#: obsdesign``, ``python obsdesign/cli.py``), where process-wide hooks may be installed
_SCRIPTS = ("obsdesign", "__main__.py", "cli.py")


def _stdout_error(e: OSError) -> Any:
    """The bad-input error of an OS error (no space, I/O error) writing stdout."""
    from obsdesign.errors import InputError

    return InputError(f"stdout: cannot write ({e.strerror or e})")


class _Stdout:
    """sys.stdout during a command: an OS error writing it (``obsdesign schema > /dev/full``:
    no space left) is exit 2 "stdout: cannot write (REASON)", as for any output file; it
    was exit 3 "internal failure" (output trial, session 30). A broken pipe stays
    BrokenPipeError (exit 141). Everything else is the wrapped stream's."""

    def __init__(self, wrapped: Any) -> None:
        self.wrapped = wrapped

    def write(self, text: str) -> int:
        try:
            return int(self.wrapped.write(text))
        except BrokenPipeError:
            raise
        except OSError as e:
            raise _stdout_error(e) from None

    def flush(self) -> None:
        try:
            self.wrapped.flush()
        except BrokenPipeError:
            raise
        except OSError as e:
            raise _stdout_error(e) from None

    def __getattr__(self, name: str) -> Any:
        return getattr(self.wrapped, name)


class _Stderr:
    """sys.stderr for the whole process: a stream that cannot take the error line (closed,
    ``2>/dev/full``, a pipe whose reader has gone) drops it, and the exit code stays the
    command's. Every such write raised inside the error handler, and bad input, an ok design
    and Ctrl-C all ended exit 1 (CLI hostile-input trial, session 34)."""

    def __init__(self, wrapped: Any) -> None:
        self.wrapped = wrapped
        self.dead = False

    def write(self, text: str) -> int:
        if not self.dead:
            try:
                self.wrapped.write(text)
                self.wrapped.flush()  # an error line must not wait in a buffer
            except (OSError, ValueError):
                self.dead = True
        return len(text)

    def flush(self) -> None:
        if not self.dead:
            try:
                self.wrapped.flush()
            except (OSError, ValueError):
                self.dead = True

    def isatty(self) -> bool:
        try:
            return not self.dead and bool(self.wrapped.isatty())
        except (OSError, ValueError):
            return False

    def __getattr__(self, name: str) -> Any:
        return getattr(self.wrapped, name)


def _settle(owned: bool) -> None:
    """The command body has ended: a Ctrl-C from now on is ignored (the work is done and its
    files are written; Python's shutdown would otherwise die of the signal, exit -2), and a
    Ctrl-C recorded during the body ends the command with exit 130 whatever it returned."""
    from obsdesign import interrupt

    if owned:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    for sig in _STOP_SIGNALS:
        if _main_thread() and signal.getsignal(sig) is interrupt.handler:
            # the work is done and written: back to the default (an in-process caller keeps
            # its own SIGTERM behaviour after the command)
            signal.signal(sig, signal.SIG_DFL)
    if interrupt.requested():
        _interrupted()


#: signals that stop a command as Ctrl-C does (cleanup runs, exit 128 + the signal), where
#: their action is still the default, with the one line printed for each. Every catchable
#: signal whose default action ends the process: SIGUSR1 / SIGUSR2 / SIGALRM (a stray `kill
#: -USR1`, an alarm set by a wrapper) left the hidden temp file of an output being written
#: (CLI hostile-input trial, session 38); SIGXCPU is a CPU-time limit (``ulimit -t``) reached.
#: SIGPIPE is ignored by Python (a closed stdout is exit 141, see _quiet_broken_pipe).
_STOP_WORDS = {
    "SIGTERM": "terminated",
    "SIGHUP": "hung up",
    "SIGQUIT": "quit",
    "SIGUSR1": "user signal 1",
    "SIGUSR2": "user signal 2",
    "SIGALRM": "alarm clock",
    "SIGVTALRM": "virtual timer expired",
    "SIGPROF": "profiling timer expired",
    "SIGXCPU": "CPU time limit exceeded",
}
_STOP_SIGNALS = tuple(getattr(signal, n) for n in _STOP_WORDS if hasattr(signal, n))
#: the one line printed for each
_SIGNAL_WORDS = {
    int(signal.SIGINT): "interrupted",
    **{int(getattr(signal, n)): w for n, w in _STOP_WORDS.items() if hasattr(signal, n)},
}


#: the exit codes of a command stopped by a signal (128 + SIGINT and each of _STOP_SIGNALS)
_INTERRUPT_CODES = frozenset(128 + num for num in _SIGNAL_WORDS)


def _main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


def _interrupted() -> None:
    """One line and exit 130, as after Ctrl-C in a shell (the record is cleared: the
    ``except typer.Exit`` branch of :func:`_run` settles again and must not say it twice)."""
    from obsdesign import interrupt

    num = interrupt.signal_number() or int(signal.SIGINT)
    interrupt.reset()
    _err(_SIGNAL_WORDS.get(num, "interrupted"))
    raise typer.Exit(128 + num) from None


def _quiet_broken_pipe() -> None:
    """The reader of stdout went away (``obsdesign schema | head -1``): stop quietly with
    exit 141, as a process killed by SIGPIPE would (stdout is pointed at /dev/null so that
    Python's own flush at exit does not complain)."""
    _drop_stdout()
    raise typer.Exit(141) from None


def _quiet_broken_pipe_exit() -> None:
    """:func:`_quiet_broken_pipe` outside typer (``main``): exit 141 by ``sys.exit``."""
    try:
        _quiet_broken_pipe()
    except typer.Exit as e:
        sys.exit(e.exit_code)


def _version(value: bool) -> None:
    if value:
        from obsdesign import __version__

        print(f"obsdesign {__version__}")
        raise typer.Exit(0)


def _seconds(value: str | float) -> float:
    """``--timeout``'s value: a number of seconds ≥ 0 or inf; nan gets its own message
    (typer's min=0 check said "greater than or equal to 0" of nan). The text is read
    exactly first: ``1e-400`` read as 0.0 (no limit) and ``-1e-400`` as −0.0 passed (CLI
    review, session 44); a positive budget below the float range is the smallest one."""
    import math
    from decimal import Decimal, InvalidOperation

    if isinstance(value, (int, float)):  # the default
        q = Decimal(value)
    else:
        try:
            if not value.isascii():  # Decimal reads Arabic-Indic digits; --limit does not (45)
                raise InvalidOperation
            q = Decimal(value.strip())
        except InvalidOperation:
            raise typer.BadParameter(f"{value!r} is not a number of seconds") from None
    if q.is_nan() or (q < 0 and not q.is_zero()):
        raise typer.BadParameter(f"{value} is not a number of seconds >= 0 (0 or inf: none)")
    f = float(q)
    return math.ulp(0.0) if f == 0 and q > 0 else abs(f)


@app.callback()
def _main(
    ctx: typer.Context,
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
        from obsdesign.limits import parse_limits, restore, saved, set_limits

        # for this command only: in one process (CliRunner, an embedding program) the next
        # command ran under them (a test's max_file_bytes failed 46 later tests; session 32)
        before = saved()
        ctx.call_on_close(lambda: restore(before))
        try:
            set_limits(**parse_limits(limit))
        except ObsdesignError as e:
            _err(e.message)
            raise typer.Exit(e.exit_code) from None


@app.command()
def design(
    spec: SpecArg,
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
            help="Write the method's design plot, e.g. ε(z) (.png .svg .pdf .eps .jpg … by "
            "the suffix).",
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
    timeout: Annotated[
        str,  # read as text (exactly), made seconds by the callback
        typer.Option(
            "--timeout",
            metavar="SECONDS",
            callback=_seconds,
            help="Time budget of the design and its certification (0 or inf: none, the "
            "default); past it the design stops with exit 3 and -o gets its error report.",
        ),
    ] = "0",
) -> None:
    """Design the observer of SPEC, certify every claim, and print (or write) the report.

    The report at -o is written whatever the verdict (its "verdict" says ok, failed,
    inconclusive, or error when the design stopped with an error), so it is never stale;
    bad input (exit 2) writes nothing."""

    _run(
        lambda cmd: cmd.design(spec, output, fmt, plot, force, quiet, float(timeout)), quiet, width
    )


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
    fmt: FmtOpt = Fmt.text,
    quiet: QuietOpt = False,
    width: WidthOpt = None,
) -> None:
    """Re-check every claim of REPORT independently; exit 0 only if all hold.

    The last line (text and md) is the verdict, e.g. "verified: 8 claims certified,
    0 failed"."""

    _run(lambda cmd: cmd.verify(report, spec, fmt, quiet), quiet, width)


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


def _timeout_opt(unit: str) -> Any:
    """``--timeout SECONDS`` of ``check`` (per spec) and ``sweep`` (per point)."""
    return Annotated[
        str,  # read as text (exactly), made seconds by the callback
        typer.Option(
            "--timeout",
            metavar="SECONDS",
            callback=_seconds,
            help=f"Time budget per {unit} (0 or inf: none); a {unit} past it gets exit 3 and "
            "the others still run (on Dask too: applied in the worker). It stops a "
            f"{unit} only between imports: a budget below ~0.1 s can be overrun by the first "
            f"{unit}'s imports.",
        ),
    ]


SpecTimeoutOpt = _timeout_opt("spec")
PointTimeoutOpt = _timeout_opt("point")
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
    fmt: FmtOpt = Fmt.text,
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
    timeout: SpecTimeoutOpt = "600",
) -> None:
    """Design and verify every spec; one row per spec; non-zero exit if any fails.

    Folders are searched recursively for *.toml (hidden folders skipped). Every spec gets a
    row whatever happens in it: its exit code and message (an internal error is exit 3).
    The last line (text and md) is the verdict, e.g. "checked: 13 specs, 13 ok, 0 failed;
    149 claims certified, 8 numerical, 0 failed"."""

    _run(
        lambda cmd: cmd.check(paths, fmt, junit, quiet, workers, scheduler, float(timeout)),
        quiet,
        width,
    )


@app.command()
def sweep(
    spec: SpecArg,
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
        typer.Option(
            "--plot",
            metavar="FILE",
            help="Plot --y against a swept key (.png .svg .pdf … by the suffix).",
        ),
    ] = None,
    y: Annotated[
        str | None, typer.Option("--y", metavar="COLUMN", help="The plotted column.")
    ] = None,
    x: Annotated[
        str | None,
        typer.Option("--x", metavar="KEY", help="The swept key on the x axis (the first one)."),
    ] = None,
    fmt: FmtOpt = Fmt.text,
    workers: WorkersOpt = None,
    scheduler: SchedulerOpt = None,
    force: Annotated[
        bool, typer.Option("--force", help="Write -o/--plot even where refused by default.")
    ] = False,
    quiet: QuietOpt = False,
    width: WidthOpt = None,
    timeout: PointTimeoutOpt = "600",
) -> None:
    """Design and verify SPEC at every point of a grid of spec keys; one row per point.

    Every point gets a row whatever happens in it (its exit code and message); the exit code
    is the worst row's. See docs/sweeps.md."""

    _run(
        lambda cmd: cmd.sweep(
            spec,
            sets,
            simulate,
            option,
            output,
            plot,
            y,
            x,
            fmt,
            workers,
            scheduler,
            force,
            quiet,
            float(timeout),
        ),
        quiet,
        width,
    )


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
        Path | None,
        typer.Option(
            "--plot", metavar="FILE", help="Write a plot (.png .svg .pdf … by the suffix)."
        ),
    ] = None,
    csv: Annotated[
        Path | None,
        typer.Option(
            "--csv",
            metavar="FILE",
            help="Write the trajectories as CSV: t, x_*, xhat_*, e_*, y* (impulsive: no y*, its y_k exists at the samples only; run 0 of --runs).",
        ),
    ] = None,
    fmt: FmtOpt = Fmt.text,
    option: Annotated[
        list[str] | None,
        typer.Option(
            "--option",
            metavar="KEY=VALUE",
            help="Method simulation option KEY=VALUE (repeatable).",
        ),
    ] = None,
    force: Annotated[
        bool,
        typer.Option("--force", help="Write --plot / --csv even where refused by default."),
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

    _run(
        lambda cmd: cmd.simulate(
            spec, report, plot, fmt, option, force, runs, study, workers, scheduler, quiet, csv
        ),
        quiet,
        width,
    )


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

    _run(lambda cmd: cmd.schema())


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

    Every commented line "# key = value" is an optional key; some go together or need values
    that fit your plant (the template's comments say which)."""

    _run(lambda cmd: cmd.init(method))


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
        str | None,
        typer.Option(
            "--dt",
            metavar="SECONDS",
            help=(
                "Sample time: discrete time with this sample time; 0: continuous time (not "
                "with --dt-var). Without --dt and --dt-var the spec is continuous time (refused "
                "when the file holds a scalar named like a sample time, e.g. Ts)."
            ),
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
    Add the method's options to the printed [method] table (see obsdesign init KEY). A method
    whose [method] table has required keys (constrained, set-invariant, ...) is refused,
    saying which: start from obsdesign init KEY instead."""

    _run(lambda cmd: cmd.import_mat(mat, a, c, b, d, bd, dt, dt_var, method))


@app.command()
def methods(
    fmt: FmtOpt = Fmt.text,
) -> None:
    """List the design methods (--format json also gives the obsdesign version)."""

    _run(lambda cmd: cmd.methods(fmt))


# -- helpers -------------------------------------------------------------------------------


def _click_kind(e: BaseException) -> str | None:
    """Which of click's exceptions ``e`` is ("NoArgsIsHelpError", "UsageError",
    "ClickException", "Abort"), by class name: typer 0.2x vendors click as ``typer._click``,
    older ones use ``click`` itself, so the classes differ by version."""
    names = [c.__name__ for c in type(e).__mro__]
    for kind in ("NoArgsIsHelpError", "UsageError", "ClickException", "Abort"):
        if kind in names:
            return kind
    return None


#: the options of ``obsdesign`` itself (before the command)
GLOBAL_OPTIONS = ("--limit", "--debug", "--version")

#: the options that name an output file
OUTPUT_OPTIONS = ("-o", "--output", "--plot", "--plot-epsilon", "--junit", "--csv")


#: the options that take one value, once (a test ties this to the commands' own options):
#: given twice, click kept the last without a word — verify --spec a --spec b checked b
#: only, --timeout 0.001 --timeout 0 ran unbounded (CLI review 46)
SINGLE_OPTIONS = (
    *OUTPUT_OPTIONS,
    *("--spec", "--report", "--format", "--timeout", "--width", "--workers", "--scheduler"),
    *("--runs", "--study", "--x", "--y", "--method"),
    *("--A", "--B", "--Bd", "--C", "--D", "--dt", "--dt-var"),
)

#: the options that take a value and may be repeated
REPEATED_OPTIONS = ("--set", "--option", "--limit")

#: the options that are names of one option (-o / --output, --plot / --plot-epsilon)
_SAME_OUTPUT = {"-o": "--output", "--plot-epsilon": "--plot"}


def _option_uses(args: list[str]) -> list[tuple[str, str, str, bool]]:
    """(option as written, its canonical name, its value, whether the value is a word of its
    own) for each use of an option that
    takes one value (:data:`SINGLE_OPTIONS`) before ``--``: ``--opt VALUE`` (the value of
    every option that takes one is skipped, so a value that reads like an option is not
    one), ``--opt=VALUE``, the glued ``-oVALUE`` and a cluster of short options ending in o
    (``-qo VALUE``, ``-qoVALUE``)."""
    uses = []
    i = 0
    while i < len(args):
        a = args[i]
        if a == "--":
            break
        name, eq, val = a.partition("=")
        if a in REPEATED_OPTIONS:
            i += 2
            continue
        if a in SINGLE_OPTIONS and i + 1 < len(args):
            uses.append((a, _SAME_OUTPUT.get(a, a), args[i + 1], True))
            i += 2
            continue
        if a.startswith("--") and eq and name in SINGLE_OPTIONS:
            uses.append((name, _SAME_OUTPUT.get(name, name), val, False))
        elif a.startswith("-") and not a.startswith("--") and "o" in a[1:]:
            # a cluster of short options, as click reads it: flags (-q) up to the o, whose
            # value is the rest of the word or the next word — -qo a.json -o b.json wrote
            # only b.json, and -qo out.json/ passed the checks (CLI review 46)
            rest = a[a.index("o", 1) + 1 :]
            if rest:
                uses.append(("-o", "--output", rest, False))
            elif i + 1 < len(args):
                uses.append(("-o", "--output", args[i + 1], True))
                i += 1
        i += 1
    return uses


def _output_problem(args: list[str]) -> str | None:
    """The one-line error for an option that takes one value given twice (click kept the
    last; CLI review 46), or for an output option used badly, or None: given twice (click kept
    the last: ``-o a.json -o b.json`` wrote b.json alone), a name that ends in a slash or in
    "/." (pathlib dropped it and wrote out.json), or ``-o=FILE`` (click read a file named
    "=FILE") — hostile-input trial and re-checks, session 38."""
    seen: set[str] = set()
    for written, key, value, separate in _option_uses(args):
        if written not in OUTPUT_OPTIONS:
            if key in seen:
                return f"{key} is given twice; give it once (the last one would be used alone)"
            seen.add(key)
            continue
        if written == "-o" and value.startswith("="):
            return f"-o{value}: write -o FILE or --output=FILE (-o= names a file starting with '=')"
        if key in seen:
            shown = {"--output": "-o/--output", "--plot": "--plot/--plot-epsilon"}.get(key, key)
            return f"{shown} is given twice; give each output once"
        seen.add(key)
        if separate and value.startswith("-") and value != "-":
            # -o -q wrote a file named -q: the file name was forgotten (CLI review 46)
            return (
                f"{written} {value}: the file name reads like an option (was it left out?); "
                f"write ./{value} for a file of that name"
            )
        bare = value.rstrip("/" + os.sep)
        folder = value.endswith(("/", os.sep)) or value.endswith(("/.", os.sep + "."))
        if folder and bare.strip("." + "/" + os.sep):
            end = "'/.'" if value.endswith(("/.", os.sep + ".")) else "'/'"
            return f"{value}: names a folder (trailing {end}); outputs are files"
    return None


def _matplotlib_config_dir() -> None:
    """A private, persistent ``MPLCONFIGDIR`` when matplotlib's own (``$XDG_CONFIG_HOME`` or
    ``~/.config``) cannot be written: matplotlib then printed two warning lines on stderr and
    rebuilt its font cache in a fresh temporary folder at every plot, about 5 s
    (hostile-input trial, session 38, with a read-only HOME). Set before any matplotlib import;
    a user's own MPLCONFIGDIR is kept, and a folder not ours (a symbolic link, another owner,
    open to others) is not used."""
    import stat
    import tempfile

    if os.environ.get("MPLCONFIGDIR"):
        return
    base = os.environ.get("XDG_CONFIG_HOME") or os.path.join(os.path.expanduser("~"), ".config")
    probe = os.path.join(base, "matplotlib")
    while probe and not os.path.exists(probe):
        parent = os.path.dirname(probe)
        if parent == probe:
            break
        probe = parent
    if os.path.isdir(probe) and os.access(probe, os.W_OK | os.X_OK):
        return
    own = os.path.join(tempfile.gettempdir(), f"obsdesign-matplotlib-{os.getuid()}")
    try:
        os.makedirs(own, mode=0o700, exist_ok=True)
        st = os.lstat(own)
    except OSError:
        return
    if stat.S_ISDIR(st.st_mode) and st.st_uid == os.getuid() and not st.st_mode & 0o077:
        os.environ["MPLCONFIGDIR"] = own


def _empty_arg(a: str) -> bool:
    """An empty argument: '' or an option's ``--name=`` form with nothing after '='."""
    return a == "" or (a.startswith("--") and a.endswith("=") and a.count("=") == 1)


def _json_escape(err: UnicodeError) -> tuple[str, int]:
    """Codec error handler: each character the stream cannot encode as a JSON string escape,
    ``\\u`` and four hex digits (a surrogate pair beyond the BMP), so JSON output stays valid JSON and text
    stays readable."""
    if not isinstance(err, UnicodeEncodeError):  # pragma: no cover - encoding only
        raise err
    out = []
    for ch in err.object[err.start : err.end]:
        c = ord(ch)
        if c > 0xFFFF:
            c -= 0x10000
            out.append(f"\\u{0xD800 + (c >> 10):04x}\\u{0xDC00 + (c & 0x3FF):04x}")
        else:
            out.append(f"\\u{c:04x}")
    return "".join(out), err.end


def _encodable(stream: Any) -> None:
    """Let ``stream`` write any text: on a stream whose encoding is not UTF-8
    (``PYTHONIOENCODING=ascii``, a latin-1 console) a character it cannot encode is written as
    a JSON string escape (:func:`_json_escape`, ``\\u2014``) instead of raising
    UnicodeEncodeError — which made a valid ``verify``, ``check``, ``methods`` or ``schema``
    exit 3 "internal failure", and ``design -o`` exit 3 after writing a report whose verdict
    is ok (hostile-input trial, session 38)."""
    import codecs

    enc = (getattr(stream, "encoding", None) or "").lower().replace("-", "").replace("_", "")
    if enc not in ("utf8", "utf8sig") and hasattr(stream, "reconfigure"):
        codecs.register_error("obsdesign-json-escape", _json_escape)
        try:
            stream.reconfigure(errors="obsdesign-json-escape")
        except (ValueError, OSError):  # pragma: no cover - a stream that refuses
            pass


def _dash_file(arg: str) -> str:
    """An argument that names the file '-' (``./-``, ``.//-``) as its absolute path: typer
    makes it ``Path("-")``, the very value that means stdin, and ``design ./-`` read stdin
    (a terminal: it waited) instead of the file (CLI review, session 44). Only the literal
    ``-`` is stdin."""
    if arg != "-" and arg.endswith("-") and os.path.normpath(arg) == "-":
        try:
            return os.path.join(os.getcwd(), "-")
        except OSError:  # the working folder removed: a traceback (re-check review, 44),
            # and returning ./- read stdin (it is Path("-") to typer)
            # an input or an output (-o ./-): "cannot read" was wrong for the latter (45)
            _err(f"{arg}: cannot use (the working folder no longer exists: cd to one)")
            sys.exit(2)
    return arg


def _completion_extra(args: list[str]) -> str | None:
    """The error for ``--install-completion`` / ``--show-completion`` given with anything
    else: typer's flags take no value and act at once, so ``--install-completion tcsh``
    installed bash completion, exit 0, the shell name silently dropped (CLI review 44)."""
    # after `--` an argument is a file name, but only once a command came before it: with
    # none, click reads `-- --install-completion` as the flag (re-check review 45)
    cut = args.index("--") if "--" in args else len(args)
    before = args[:cut] if any(not a.startswith("-") for a in args[:cut]) else args
    flags = [a for a in before if a in ("--install-completion", "--show-completion")]
    if not flags:
        return None
    from obsdesign.errors import one_line

    others = [a for a in args if a not in flags]
    if others or len(flags) > 1:
        # --install-completion --show-completion together installed silently (CLI review 45)
        got = others[0] if others else flags[1]
        return one_line(
            f"{flags[0]} takes no argument (got {got!r}): it acts for the shell it runs in "
            "(bash, zsh, fish or PowerShell); run it alone from that shell"
        )
    # typer says "Shell sh not supported." and exits 1, the code of a failed claim (CLI
    # review 45): the shell is looked at first, exit 2 naming it
    try:
        from typer._completion_shared import _get_shell_name

        shell = _get_shell_name()
    except Exception:  # noqa: BLE001 - typer's private helper moved: typer decides
        return None
    if shell not in ("bash", "zsh", "fish", "powershell", "pwsh"):
        return one_line(
            f"{flags[0]}: the shell here is {shell or 'unknown'!r}; completion is for bash, "
            "zsh, fish and PowerShell: run it from one of them"
        )
    return None


def main() -> None:
    """Console-script entry point. Click's own usage errors (an unknown option, a missing
    argument, a bad option value) become one line, like every other bad input: "obsdesign:
    error: <what> (see 'obsdesign CMD --help')", exit 2, instead of click's four-line
    usage block."""
    if sys.stdout is None:
        # stdout closed (`>&-`): what goes there is dropped, files are written and the exit
        # code is the command's (every print raised AttributeError: exit 3, or a traceback
        # and exit 1; re-check trial, session 30)
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - for the whole process
    _encodable(sys.stdout)
    _encodable(sys.stderr)
    _matplotlib_config_dir()
    # stderr closed (`2>&-`), full or a dead pipe: the error line is dropped, the exit code
    # is the command's (exit 1 for everything before session 34)
    sys.stderr = _Stderr(sys.stderr if sys.stderr is not None else open(os.devnull, "w"))  # noqa: SIM115
    bad_output = _output_problem(sys.argv[1:])
    if bad_output is not None:
        _err(bad_output)
        sys.exit(2)
    empty = next((i for i, a in enumerate(sys.argv[1:], 1) if _empty_arg(a)), None)
    if empty is not None:
        # an empty argument is a path '' that pathlib reads as '.': `check "$SPECS"` with
        # SPECS unset checked every spec under the working folder, `-o ''` said ".: is a
        # directory" (CLI hostile-input trial, session 34). No option takes '' either, nor
        # the `--output=` form (it read '.' too; hostile-input trial, session 38).
        arg = sys.argv[empty]
        if arg:
            after = f" after {arg[:-1]!r}"
        else:
            after = f" after {sys.argv[empty - 1]!r}" if empty > 1 else ""
        _err(f"an empty argument{after} (an unset shell variable?): give a path or a value")
        sys.exit(2)
    completion = _completion_extra(sys.argv[1:])
    if completion is not None:
        _err(completion)
        sys.exit(2)
    sys.argv[1:] = [_dash_file(a) for a in sys.argv[1:]]
    try:
        rv = app(standalone_mode=False, prog_name="obsdesign")
    except KeyboardInterrupt:  # pragma: no cover - Ctrl-C outside a command body
        _err("interrupted")
        sys.exit(130)
    except BrokenPipeError:  # --help | head -1: as a command's output
        _quiet_broken_pipe_exit()
    except OSError as e:
        # click's own output (--help, --version, usage) to a full stdout: a traceback and
        # exit 1 (re-check trial, session 30); a command's OS errors are handled in _run.
        # An error naming a file is that file's (--install-completion into a read-only
        # home said "stdout: cannot write"; CLI review, session 44)
        if e.filename is not None:
            from obsdesign.errors import one_line

            _err(one_line(f"{e.filename}: cannot write ({e.strerror or e})"))
        else:
            _err(_stdout_error(e).message)
            _drop_stdout()
        sys.exit(2)
    except Exception as e:
        kind = _click_kind(e)
        if kind is None:
            # --debug re-raises for the traceback; the exit code stays the error's (every
            # failure was exit 1, "infeasible", under --debug; CLI hostile-input trial,
            # session 34)
            import traceback

            from obsdesign.errors import ObsdesignError

            traceback.print_exc()
            sys.exit(e.exit_code if isinstance(e, ObsdesignError) else 3)
        if kind == "NoArgsIsHelpError":  # bare `obsdesign`: the help, as click shows it
            e.show()  # type: ignore[attr-defined]
        elif kind == "UsageError":
            ctx = getattr(e, "ctx", None)
            where = ctx.command_path if ctx is not None else "obsdesign"
            opt = getattr(e, "option_name", None)
            if opt in GLOBAL_OPTIONS and where != "obsdesign":
                # `design s.toml --limit …` suggested "--plot" (hostile-input trial, 38)
                _err(
                    f"{opt} is an option of obsdesign itself: give it before the command "
                    f"(obsdesign {opt} … {where.split(' ', 1)[-1]} …)"
                )
                sys.exit(2)
            _err(f"{e.format_message()} (see '{where} --help')")  # type: ignore[attr-defined]
        elif kind == "ClickException":  # e.g. a click.File that cannot be opened
            _err(e.format_message())  # type: ignore[attr-defined]
        else:  # Abort: EOF at a prompt (there is none today)
            _err("interrupted")
            sys.exit(130)
        sys.exit(getattr(e, "exit_code", 2))
    code = rv if isinstance(rv, int) else 0
    if code in _INTERRUPT_CODES:
        # an interrupt's KeyboardInterrupt that passed through exec'd code (dataclasses'
        # generated functions during `import cvxpy`) makes CPython 3.11 kill the process with
        # SIGINT at exit, whatever the code: 130 for a SIGTERM about 1 run in 4 (re-check
        # trial, session 34). The command's cleanup has run; end without Python's exit path.
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError, AttributeError):
                pass
        os._exit(code)
    # what is still buffered (--version, click's help): its errors as a command's
    sys.exit(_flushed(code))


if __name__ == "__main__":
    main()
