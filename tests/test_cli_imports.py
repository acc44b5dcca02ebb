"""Import discipline of the command line (issue 12 item 3, cold start): ``obsdesign --help``
and a cold ``obsdesign design`` of the shipped Lyapunov spec load only what their path
needs. Run in fresh interpreters (subprocess), since this test process has imported
everything already. Not timed: it checks which modules load, which is what the timings
follow from."""

from __future__ import annotations

import subprocess
import sys
from enum import Enum
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"

#: never needed by ``design`` of a linear Lyapunov spec (nor by ``--help``)
HEAVY = (
    "cvxpy",
    "clarabel",
    "scipy.spatial",
    "scipy.optimize",
    "matplotlib",
    "cdd",
    "dask",
    "distributed",
    "pydantic",
    "sympy",
    "pandas",
    "pyarrow",
    "obsdesign.sweep",
    "obsdesign.distributed",
    "obsdesign.interop",
)
#: besides, ``--help`` needs no numerics, no rich and no obsdesign module but the CLI
HELP_ONLY = (
    "numpy",
    "scipy",
    "flint",
    "rich",
    "json",
    "importlib.metadata",
    "obsdesign.api",
    "obsdesign.spec",
    "obsdesign.methods",
    "obsdesign.report",
    "obsdesign.cli_commands",
    "obsdesign.cli_coerce",
    "typer._adapters",
)

RUN = """
import sys
sys.argv = ["obsdesign", *sys.argv[1:]]
from obsdesign.cli import main
code = None
try:
    main()
except SystemExit as e:
    code = e.code
sys.stdout.flush()
sys.stderr.write("\\nMODULES " + repr([code, sorted(sys.modules)]) + "\\n")
"""


def _loaded(args: list[str], tmp_path: Path) -> tuple[int, set[str]]:
    """Exit code and ``sys.modules`` after ``obsdesign ARGS`` in a fresh interpreter."""
    import ast

    r = subprocess.run(
        [sys.executable, "-c", RUN, *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=300,
    )
    tail = r.stderr.rsplit("MODULES ", 1)
    assert len(tail) == 2, r.stderr
    code, mods = ast.literal_eval(tail[1].strip())
    return code, set(mods)


def _present(mods: set[str], names: tuple[str, ...]) -> list[str]:
    return [n for n in names if n in mods or any(m.startswith(n + ".") for m in mods)]


def test_help_loads_only_the_command_line(tmp_path: Path) -> None:
    code, mods = _loaded(["--help"], tmp_path)
    assert code == 0
    assert _present(mods, HEAVY + HELP_ONLY) == []


def test_cold_lyapunov_design_loads_no_heavy_module(tmp_path: Path) -> None:
    out = tmp_path / "r.json"
    code, mods = _loaded(["design", str(SPEC), "-o", str(out)], tmp_path)
    assert code == 0 and out.exists()
    assert _present(mods, HEAVY) == []
    # the dependency versions of the report are read without importlib.metadata's own
    # machinery; a 2-state Lyapunov equation is solved by numpy (lyap.solve_lyapunov), so
    # scipy.linalg (~0.3 s) is not imported at all
    assert {"numpy", "flint", "obsdesign.methods.lyapunov"} <= mods
    assert _present(mods, ("scipy",)) == []
    for other in ("constrained", "impulsive", "setinvariant", "searchspace", "stubborn"):
        assert f"obsdesign.methods.{other}" not in mods


@pytest.mark.parametrize("args", [["methods"], ["schema"]])
def test_listing_commands_load_no_solver(args: list[str], tmp_path: Path) -> None:
    """``methods`` and ``schema`` import every method's facade and options, never its
    solvers (impulsive's scipy.optimize and set-invariant's LPs load with its design)."""
    code, mods = _loaded(args, tmp_path)
    assert code in (0, None)
    assert _present(mods, HEAVY + ("scipy.sparse", "scipy.integrate")) == []


# -- the pydantic-free coercion of command-line values must give typer's own results ----
def _typer_params() -> list[tuple[Any, Any]]:
    import typer.main

    from obsdesign.cli import app

    group = typer.main.get_command(app)
    cmds = [group, *group.commands.values()]  # type: ignore[attr-defined]
    return [(p, c) for c in cmds for p in c.params if hasattr(p, "type_descriptor")]


VALUES = [
    "x.toml",
    "",
    "-",
    " a b ",
    "dir/",
    "0",
    "7",
    "40",
    "39",
    "-3",
    "007",
    "+5",
    " 5",
    "1_000",
    "5.0",
    "99999999999999999999",
    "text",
    "json",
    "md",
    "JSON",
    "yaml",
    "lyapunov",
    ("a=1", "b=2"),
    ("x.toml", "specs"),
    (),
]


@pytest.mark.parametrize("value", VALUES, ids=repr)
def test_fast_coercion_matches_typer(value: Any, tmp_path: Path) -> None:
    """Where the direct path coerces a value, typer's pydantic adapter gives the same
    (equal value, same type); where typer refuses a value, the direct path hands it to
    typer (returns the sentinel) instead of accepting it."""
    try:
        from typer._click import Context
        from typer._coercion import build_runtime_param
    except ImportError:  # pragma: no cover - typer without pydantic coercion
        pytest.skip("typer coerces through click types here")
    from obsdesign import cli_coerce

    checked = 0
    for p, cmd in _typer_params():
        desc = p.type_descriptor
        is_list = p.multiple or p.nargs == -1
        if isinstance(value, tuple) != is_list or desc.annotation is bool:
            continue
        ctx = Context(cmd)
        fast = cli_coerce.fast_value(desc, value, p, ctx)
        try:
            slow = build_runtime_param(desc)._coerce_value(value, param=p, ctx=ctx)
        except Exception:  # noqa: BLE001 - typer refuses the value
            assert fast is cli_coerce.SLOW, (p.name, value, fast)
            continue
        if fast is not cli_coerce.SLOW:
            assert fast == slow and type(fast) is type(slow), (p.name, value, fast, slow)
            if isinstance(slow, Enum):
                assert fast is slow
            checked += 1
    assert checked > 0  # every value is a plain one for some parameter


def test_typer_internals_changed_falls_back_to_typer(monkeypatch: pytest.MonkeyPatch) -> None:
    """If typer's RuntimeParam no longer takes what FastParam gives it, commands still run,
    through typer's own coercion (with its messages)."""
    from typer.testing import CliRunner

    from obsdesign import cli_coerce
    from obsdesign.cli import app

    def broken(descriptor: Any) -> Any:
        raise TypeError("typer internals changed")

    monkeypatch.setattr(cli_coerce, "FastParam", broken)
    r = CliRunner().invoke(app, ["init", "lyapunov"])
    assert r.exit_code == 0 and "[method]" in r.output
    r = CliRunner().invoke(app, ["design", str(SPEC), "--width", "10"])
    assert r.exit_code == 2 and "--width" in r.output


def test_the_start_up_ctrl_c_exits_130_with_stderr_closed(monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C during start-up with stderr closed or full exited 1: the early handler's error
    line raised before its exit (re-check trial, session 34). The line is dropped."""
    import io
    import sys

    import obsdesign

    def fake_exit(code: int) -> None:
        raise SystemExit(code)

    monkeypatch.setattr(obsdesign._os, "_exit", fake_exit)
    closed = io.StringIO()
    closed.close()
    for stream in (closed, None):
        monkeypatch.setattr(sys, "stderr", stream)
        with pytest.raises(SystemExit) as e:
            obsdesign._early_interrupt(2, None)
        assert e.value.code == 130


def test_the_early_interrupt_line_is_the_one_of_every_other_interrupt(monkeypatch) -> None:
    """Ctrl-C in the first ~0.05 s printed "obsdesign: interrupted", later the documented
    "obsdesign: error: interrupted" (CLI review, session 42): one wording."""
    import io
    import sys

    import obsdesign

    def fake_exit(code: int) -> None:
        raise SystemExit(code)

    monkeypatch.setattr(obsdesign._os, "_exit", fake_exit)
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    with pytest.raises(SystemExit) as e:
        obsdesign._early_interrupt(2, None)
    assert e.value.code == 130 and err.getvalue() == "obsdesign: error: interrupted\n"


def test_no_float_option_is_left_for_typer_to_coerce() -> None:
    """``--timeout`` is a str read exactly by its callback (``1e-400`` was 0.0, no limit;
    session 44): no option is a float, so no command-line float reaches pydantic."""
    assert not [p.name for p, _ in _typer_params() if p.type_descriptor.annotation is float]
