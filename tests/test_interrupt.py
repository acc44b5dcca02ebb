"""The recorded Ctrl-C (obsdesign.interrupt) and how the CLI acts on it."""

from __future__ import annotations

import sys
from types import SimpleNamespace

import pytest
import typer

from obsdesign import cli, interrupt


@pytest.fixture(autouse=True)
def _clean():
    interrupt.reset()
    yield
    interrupt.reset()


def test_the_handler_records_and_raises():
    assert not interrupt.requested()
    interrupt.check()  # nothing recorded: no exception
    with pytest.raises(KeyboardInterrupt):
        interrupt.handler(2, None)
    assert interrupt.requested()
    with pytest.raises(KeyboardInterrupt):
        interrupt.check()
    interrupt.reset()
    assert not interrupt.requested()


def _swallowing_body(cmd: object) -> int:
    """A command body in which the KeyboardInterrupt is lost on its way up (as C code that
    clears a callback's error does) and which then finishes normally."""
    try:
        interrupt.handler(2, None)
    except BaseException:  # noqa: BLE001 - the point of the test
        pass
    return 0


def test_a_lost_keyboard_interrupt_still_ends_in_exit_130(capsys: pytest.CaptureFixture[str]):
    with pytest.raises(typer.Exit) as e:
        cli._run(_swallowing_body)
    assert e.value.exit_code == 130
    assert capsys.readouterr().err == "obsdesign: error: interrupted\n"  # one line, once


def test_a_lost_interrupt_wins_over_an_error_raised_after_it(
    capsys: pytest.CaptureFixture[str],
):
    from obsdesign.errors import InputError

    def body(cmd: object) -> int:
        _swallowing_body(cmd)
        raise InputError("x.toml: bad")

    with pytest.raises(typer.Exit) as e:
        cli._run(body)
    assert e.value.exit_code == 130
    assert capsys.readouterr().err == "obsdesign: error: interrupted\n"


def test_each_command_starts_with_no_recorded_interrupt():
    with pytest.raises(KeyboardInterrupt):
        interrupt.handler(2, None)
    with pytest.raises(typer.Exit) as e:
        cli._run(lambda cmd: 0)
    assert e.value.exit_code == 0


def test_check_stops_before_the_next_spec_once_an_interrupt_is_recorded(tmp_path, monkeypatch):
    from obsdesign import api
    from obsdesign.cli_commands import Fmt, check

    for name in ("a.toml", "b.toml"):
        (tmp_path / name).write_text("")
    seen: list[str] = []

    def one(path, timeout=None):
        seen.append(path.name)
        try:
            interrupt.handler(2, None)
        except KeyboardInterrupt:
            pass
        return api.CheckRow(str(path), "x", 0, 0, 0, 0, "", 0.0)

    monkeypatch.setattr(api, "check_one", one)
    with pytest.raises(KeyboardInterrupt):
        check([tmp_path], Fmt.text, None, True, None, None)
    assert seen == ["a.toml"]


def test_a_recorded_interrupt_keeps_the_output_file_untouched(tmp_path) -> None:
    """A Ctrl-C whose KeyboardInterrupt a library swallowed (mpmath's from_float has a bare
    except) let ``design -o`` finish and write the report before exit 130 (hostile-input
    trial, session 24). write_via checks the record before it puts the file in place: the
    old file stays, and no temp file is left."""
    from obsdesign.report.model import write_atomic

    out = tmp_path / "out.json"
    out.write_text("SENTINEL\n")
    interrupt.reset()
    with pytest.raises(KeyboardInterrupt):
        interrupt.handler(2, None)  # recorded, and its exception "lost"
    try:
        with pytest.raises(KeyboardInterrupt):
            write_atomic(out, "{}")
    finally:
        interrupt.reset()
    assert out.read_text() == "SENTINEL\n" and [p.name for p in tmp_path.iterdir()] == ["out.json"]
    write_atomic(out, "{}")  # with no interrupt recorded it writes
    assert out.read_text() == "{}\n"


def test_an_unraisable_keyboard_interrupt_of_a_recorded_ctrl_c_is_not_printed(capsys) -> None:
    """Ctrl-C landing in an import lock's weakref callback printed "Exception ignored in …"
    and a traceback after `check`'s one-line "interrupted" (full suite under load, session
    31). The console script's unraisable hook drops a KeyboardInterrupt once the interrupt is
    recorded (exit 130 follows from the record); anything else, and a KeyboardInterrupt
    before any record, still reaches the previous hook."""
    import gc
    import sys
    import weakref

    seen: list[type] = []
    quiet = interrupt.quiet_unraisable(lambda a: seen.append(type(a.exc_value)))
    old = sys.unraisablehook
    sys.unraisablehook = quiet

    class Obj:
        pass

    def fire(exc: BaseException) -> None:
        def cb(_ref: object) -> None:
            raise exc

        o = Obj()
        r = weakref.ref(o, cb)  # noqa: F841 - the callback runs when o dies
        del o
        gc.collect()

    try:
        fire(KeyboardInterrupt())  # no interrupt recorded: passed on
        interrupt._requested = True
        fire(KeyboardInterrupt())  # recorded: dropped
        fire(ValueError("x"))  # never dropped
    finally:
        sys.unraisablehook = old
    assert seen == [KeyboardInterrupt, ValueError]
    assert capsys.readouterr().err == ""


# -- mutation review 32 (session 31's checks) ----------------------------------------
def test_install_quiet_unraisable_installs_once_and_passes_others(monkeypatch) -> None:  # noqa: ANN001
    seen: list = []
    monkeypatch.setattr(sys, "unraisablehook", lambda a: seen.append(a))
    monkeypatch.setattr(interrupt, "_requested", False)
    interrupt.install_quiet_unraisable()
    h = sys.unraisablehook
    assert getattr(h, "_obsdesign_quiet", False) is True
    interrupt.install_quiet_unraisable()
    assert sys.unraisablehook is h  # not wrapped twice
    h(SimpleNamespace(exc_value=ValueError("x")))
    assert len(seen) == 1
    monkeypatch.setattr(interrupt, "_requested", True)
    h(SimpleNamespace(exc_value=KeyboardInterrupt()))
    assert len(seen) == 1


@pytest.mark.parametrize("code", [130, 143, 129, 131])
def test_an_interrupted_command_ends_by_os_exit(monkeypatch: pytest.MonkeyPatch, code: int) -> None:
    """CPython 3.11 kills the process with SIGINT at exit when the interrupt's
    KeyboardInterrupt passed through exec'd code (``import cvxpy``): a SIGTERM ended 130
    about 1 run in 4 (re-check trial, session 34). main() ends an interrupted command by
    os._exit with its code; any other code by sys.exit."""
    from obsdesign import cli

    def fake_exit(c: int) -> None:
        raise SystemExit(("os._exit", c))

    monkeypatch.setattr(cli.os, "_exit", fake_exit)
    monkeypatch.setattr(cli, "app", lambda **kw: code)
    monkeypatch.setattr(cli.sys, "argv", ["obsdesign", "methods"])
    monkeypatch.setattr(cli.sys, "stderr", cli.sys.stderr)  # main() wraps it: restored after
    with pytest.raises(SystemExit) as e:
        cli.main()
    assert e.value.code == ("os._exit", code)
    monkeypatch.setattr(cli, "app", lambda **kw: 2)
    with pytest.raises(SystemExit) as e:
        cli.main()
    assert e.value.code == 2


def test_cvxpy_logs_nothing_once_an_interrupt_is_recorded(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Re-check 34 §3: a signal inside cvxpy's solver import made cvxpy log "Encountered
    unexpected exception importing solver HIGHS" over several lines before the one-line
    "interrupted"; before any interrupt its warnings still pass."""
    import logging

    log = logging.getLogger("__cvxpy__")
    monkeypatch.setattr(log, "filters", [])
    monkeypatch.setattr(log, "handlers", [logging.StreamHandler(sys.stderr)])
    monkeypatch.setattr(log, "propagate", False)
    monkeypatch.setattr(sys, "unraisablehook", sys.unraisablehook)
    monkeypatch.setattr(interrupt, "_requested", False)
    interrupt.install_quiet_unraisable()
    interrupt.install_quiet_unraisable()
    assert log.filters == [interrupt.quiet_after_interrupt]  # once
    log.warning("before")
    monkeypatch.setattr(interrupt, "_requested", True)
    log.warning("Encountered unexpected exception importing solver HIGHS:\nSystemError()")
    assert capsys.readouterr().err == "before\n"


def test_deferred_records_a_stop_and_raises_it_as_the_block_ends() -> None:
    """interrupt.deferred(): the handler records a stop inside the block without raising;
    the outermost block raises KeyboardInterrupt as it ends; a stop recorded before the
    block is not raised again by it (session 40)."""
    import signal

    from obsdesign import interrupt

    interrupt.reset()
    ran = []
    with pytest.raises(KeyboardInterrupt):
        with interrupt.deferred():
            with interrupt.deferred():
                interrupt.handler(signal.SIGTERM, None)  # no raise here
                ran.append("inner")
            ran.append("outer")  # the inner block does not raise either
    assert ran == ["inner", "outer"] and interrupt.signal_number() == signal.SIGTERM
    with interrupt.deferred():  # recorded before: not raised again
        pass
    interrupt.reset()
    with pytest.raises(KeyboardInterrupt):  # outside a block the handler raises at once
        interrupt.handler(signal.SIGINT, None)
    interrupt.reset()


def test_a_second_stop_right_after_the_first_is_recorded_not_raised(monkeypatch) -> None:
    """A second SIGTERM landing as the first one's cleanup began (write_via's finally)
    raised KeyboardInterrupt there and skipped the temp file's removal (re-check trial,
    session 40). Within REPEAT_GRACE_S of a stop another is recorded only; after it, one is
    raised again (the first may have been swallowed by a library)."""
    import signal

    from obsdesign import interrupt

    interrupt.reset()
    with pytest.raises(KeyboardInterrupt):
        interrupt.handler(signal.SIGTERM, None)
    try:
        interrupt.handler(signal.SIGTERM, None)  # no raise: the first one is on its way
    except KeyboardInterrupt:
        pytest.fail("a second stop within the grace raised again")
    assert interrupt.requested() and interrupt.signal_number() == signal.SIGTERM
    monkeypatch.setattr(interrupt, "_first_at", interrupt._first_at - 2 * interrupt.REPEAT_GRACE_S)
    with pytest.raises(KeyboardInterrupt):
        interrupt.handler(signal.SIGINT, None)
    interrupt.reset()
