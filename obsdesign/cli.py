"""The ``obsdesign`` command line: arguments, rendering and exit codes only.

Exit codes: 0 ok; 1 infeasible design or a failed claim; 2 bad input; 3 solver or internal
failure; 4 numerically inconclusive. Errors are one line on stderr; ``--debug`` shows the
traceback.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any

import typer

app = typer.Typer(
    name="obsdesign",
    help="Observer design with exact certificates: design, verify, simulate, check.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    rich_markup_mode=None,  # plain click help: rendering help through rich costs ~150 ms
)
_state = {"debug": False}


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
        code = fn()
    except ObsdesignError as e:
        if _state["debug"]:
            raise
        _err(e.message)
        raise typer.Exit(e.exit_code) from None
    except typer.Exit:
        raise
    except KeyboardInterrupt:
        _err("interrupted")
        raise typer.Exit(130) from None
    except Exception as e:  # noqa: BLE001 - last line of defence: no traceback for users
        if _state["debug"]:
            raise
        _err(f"internal failure: {type(e).__name__}: {e} (run with --debug for the traceback)")
        raise typer.Exit(EXIT_SOLVER) from None
    raise typer.Exit(code)


@app.callback()
def _main(
    debug: Annotated[bool, typer.Option("--debug", help="Show tracebacks on errors.")] = False,
) -> None:
    _state["debug"] = debug


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
) -> None:
    """Design the observer of SPEC, certify every claim, and print (or write) the report."""

    def body() -> int:
        from obsdesign import api

        progress = _progress() if fmt == Fmt.text else None
        rep = api.design(spec, output, progress=progress)
        _print_report(rep, fmt)
        if plot is not None:
            api.plot_design(spec, rep.parameters, plot)
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
    """Design and verify every spec; one row per spec; non-zero exit if any fails."""

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
) -> None:
    """Run the plant and the designed observer over the spec's scenario; print metrics."""

    def body() -> int:
        from obsdesign import api

        sp = api.load_spec(spec)
        res = api.simulate(sp, report, options=_kv(option or []))
        m = res.metrics()
        if fmt == Fmt.json:
            print(json.dumps(m, indent=2, default=_jsonable))
        else:
            _print_metrics(m)
        if plot is not None:
            api.plot_simulation(sp, res, plot)
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
            print(
                f"| {r.spec} | {r.method} | {r.code} | {r.certified} | {r.numerical} | {r.failed} | "
                f"{r.summary or r.message} | {r.seconds:.2f} |"
            )
        return
    from rich.table import Table

    from obsdesign.report.render import console

    t = Table(title="obsdesign check")
    for c in ("spec", "method", "verdict", "cert.", "num.", "failed", "result", "s"):
        t.add_column(c, overflow="fold")
    for r in rows:
        verdict = "[green]ok[/]" if r.code == 0 else f"[bold red]exit {r.code}[/]"
        t.add_row(
            r.spec,
            r.method,
            verdict,
            str(r.certified),
            str(r.numerical),
            str(r.failed),
            r.summary if r.code == 0 else r.message,
            f"{r.seconds:.2f}",
        )
    console().print(t)


def _print_metrics(m: dict[str, Any]) -> None:
    from rich.table import Table

    from obsdesign.report.render import console

    t = Table(title="simulation metrics")
    t.add_column("state")
    t.add_column("sup |e_i|")
    t.add_column("RMSE")
    t.add_column("sup |x̂_i|")
    for s, v in m["sup_abs_error"].items():
        t.add_row(s, f"{v:.6g}", f"{m['rmse'][s]:.6g}", f"{m['sup_abs_estimate'][s]:.6g}")
    c = console()
    c.print(t)
    c.print(f"final |e| = {m['final_error_norm']:.6g}")
    for k, v in m.items():
        if k not in ("sup_abs_error", "rmse", "final_error_norm", "sup_abs_estimate", "exit_code"):
            c.print(f"{k}: {v}")


def main() -> None:
    """Console-script entry point."""
    app()


if __name__ == "__main__":
    main()
