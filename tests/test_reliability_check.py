"""`check` never loses a row (issue 11 item 4): one row per spec whatever happened in it,
subfolders searched, rich markup escaped; warnings become notes (item 9)."""

from __future__ import annotations

import json
import os
import re
import shutil
import warnings
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.cli import app
from obsdesign.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
runner = CliRunner()


def _rows(output: str) -> list[dict]:
    return json.loads(output[output.index("[") :])


def test_internal_error_in_one_spec_keeps_every_row(tmp_path: Path, monkeypatch):
    shutil.copy(SPEC, tmp_path / "a.toml")
    (tmp_path / "b.toml").write_text(SPEC.read_text().replace("0.955", "0.956"))
    (tmp_path / "c.toml").write_text("not = [valid")
    real = api.design

    def flaky(spec, *a, **k):
        if str(getattr(spec, "file", spec)).endswith("b.toml"):
            raise RuntimeError("boom in b")
        return real(spec, *a, **k)

    monkeypatch.setattr(api, "design", flaky)
    res = runner.invoke(app, ["check", str(tmp_path), "--format", "json"])
    rows = _rows(res.output)
    assert [Path(r["spec"]).name for r in rows] == ["a.toml", "b.toml", "c.toml"]
    assert [r["code"] for r in rows] == [0, 3, 2]
    assert "boom in b" in rows[1]["message"] and rows[1]["method"] == "lyapunov"
    assert res.exit_code == 3


def test_a_spec_past_its_time_budget_keeps_every_row(tmp_path: Path, monkeypatch):
    """One spec that hangs (search-space with γ⋆ = 1e-400 ran for minutes, and check printed
    no row at all: CLI fuzzer) is stopped at --timeout with exit 3 and the others still run;
    even a design that catches every Exception cannot swallow the stop."""
    import time

    shutil.copy(SPEC, tmp_path / "a.toml")
    (tmp_path / "b.toml").write_text(SPEC.read_text().replace("0.955", "0.956"))
    shutil.copy(SPEC, tmp_path / "c.toml")
    real = api.design

    def hangs(spec, *a, **k):
        if str(getattr(spec, "file", spec)).endswith("b.toml"):
            while True:
                try:
                    time.sleep(0.05)
                except Exception:  # noqa: BLE001, S110 - a method that swallows everything
                    pass
        return real(spec, *a, **k)

    monkeypatch.setattr(api, "design", hangs)
    t0 = time.perf_counter()
    res = runner.invoke(app, ["check", str(tmp_path), "--format", "json", "--timeout", "1"])
    assert time.perf_counter() - t0 < 30
    rows = _rows(res.output)
    assert [r["code"] for r in rows] == [0, 3, 0]
    assert "not finished within 1 s" in rows[1]["message"]
    assert rows[1]["method"] == "lyapunov"  # it was loaded: the row showed "?"
    assert res.exit_code == 3


def test_check_recurses_into_subfolders(tmp_path: Path):
    sub = tmp_path / "sub" / "deeper"
    sub.mkdir(parents=True)
    shutil.copy(SPEC, sub / "x.toml")
    hidden = tmp_path / ".git"
    hidden.mkdir()
    (hidden / "y.toml").write_text("junk")
    res = runner.invoke(app, ["check", str(tmp_path), "--format", "json"])
    rows = _rows(res.output)
    assert [Path(r["spec"]).name for r in rows] == ["x.toml"] and res.exit_code == 0


def test_check_escapes_markup(tmp_path: Path):
    (tmp_path / "s.toml").write_text(
        SPEC.read_text().replace("A = [[0, 1], [1, 0]]", "A = [[0, 1]]")
    )
    res = runner.invoke(app, ["check", str(tmp_path)], env={"COLUMNS": "250"})
    assert res.exit_code == 2
    assert "[system.A]" in res.output
    md = runner.invoke(app, ["check", str(tmp_path), "--format", "md"])
    assert "[system.A]" in md.output


def test_verify_text_escapes_markup(tmp_path: Path):
    out = tmp_path / "r.json"
    assert runner.invoke(app, ["design", str(SPEC), "-o", str(out)]).exit_code == 0
    d = json.loads(out.read_text())
    d["notes"] = ["see [method].L and [bold]this[/bold]"]
    out.write_text(json.dumps(d))
    res = runner.invoke(app, ["verify", str(out)], env={"COLUMNS": "250"})
    assert "[method].L" in res.output and "[bold]this[/bold]" in res.output


def test_warnings_become_notes(monkeypatch):
    from obsdesign.methods import get_method

    m = get_method("lyapunov")
    real = type(m).design

    def noisy(self, spec, progress=None):
        import numpy as np

        np.log(np.zeros(1))  # RuntimeWarning: divide by zero
        warnings.warn("ill-conditioned matrix", RuntimeWarning, stacklevel=1)
        return real(self, spec, progress)

    monkeypatch.setattr(type(m), "design", noisy)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a leaked warning would raise here
        rep = api.design(SPEC)
    assert any("divide by zero" in n for n in rep.notes)
    assert any("ill-conditioned matrix" in n for n in rep.notes)


def test_check_takes_one_path_as_a_string_or_a_path(tmp_path: Path) -> None:
    """``obsdesign.check("specs/")`` iterated the string's characters, and its "/" searched the
    whole file system (outsider trial, session 22). One str or Path is one path."""
    shutil.copy(SPEC, tmp_path / "x.toml")
    for one in (str(tmp_path), tmp_path, str(tmp_path / "x.toml")):
        rows = api.check(one)
        assert [Path(r.spec).name for r in rows] == ["x.toml"] and rows[0].code == 0
    assert api.spec_files(str(tmp_path)) == [tmp_path / "x.toml"]


def test_a_bad_input_row_names_the_declared_method(tmp_path: Path) -> None:
    """A spec refused as bad input showed method "?" in check's rows (JSON, JUnit) even when
    its TOML declared a known method (session 22's note). The row now names the method the
    spec declares, whether the error came from the generic sections or the method's own keys;
    an unknown or missing key, or a file that is not TOML, stays "?"."""
    text = SPEC.read_text()
    (tmp_path / "a.toml").write_text(text.replace("[system]", "[system]\nbogus = 1", 1))
    (tmp_path / "b.toml").write_text(text.replace("[method]", "[method]\nbogus = 1", 1))
    (tmp_path / "c.toml").write_text(text.replace('key = "lyapunov"', 'key = "lyapunv"'))
    (tmp_path / "d.toml").write_text("not = [valid")
    rows = {Path(r.spec).name: r for r in api.check(tmp_path)}
    assert {k: (r.code, r.method) for k, r in rows.items()} == {
        "a.toml": (2, "lyapunov"),
        "b.toml": (2, "lyapunov"),
        "c.toml": (2, "?"),
        "d.toml": (2, "?"),
    }, {k: r.message for k, r in rows.items()}


def test_check_timeout_beyond_the_timer_range_is_no_limit(tmp_path: Path) -> None:
    """``check --timeout inf`` (or 1e300, 1e10) made setitimer raise OverflowError: exit 3
    "timestamp out of range" for a good spec (hostile-input trial, session 24). A budget
    beyond about 31 years is no budget."""
    spec = tmp_path / "s.toml"
    shutil.copy(ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml", spec)
    for t in ("inf", "1e300", "1e10"):
        res = runner.invoke(app, ["check", str(spec), "--timeout", t, "-q"])
        assert res.exit_code == 0, (t, res.output)
    with api._time_budget(1e300):
        pass


@pytest.mark.parametrize("bad", [-1, -1e-9, float("nan"), "1", True, [1]])
def test_the_api_reads_its_timeout_as_the_cli_does(tmp_path: Path, bad: object) -> None:
    """``api.check`` / ``api.sweep`` / ``check_one`` took ``timeout=`` unread: −1 reached
    setitimer's raw "Invalid argument", NaN and −10⁻⁹ ran without a limit, "1" was a
    TypeError and True one second (re-check trial, session 35). Each is an InputError naming
    the timeout; 0, None, inf and 1e300 are no limit, as ``--timeout``."""
    spec = tmp_path / "s.toml"
    shutil.copy(ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml", spec)
    with pytest.raises(InputError, match=r"^timeout must be"):
        api.check([spec], timeout=bad)
    with pytest.raises(InputError, match=r"^timeout must be"):
        api.check_one(spec, timeout=bad)
    with pytest.raises(InputError, match=r"^timeout must be"):
        api.sweep(spec, ["method.lambda=0.9:0.95:2"], timeout=bad)


def test_budget_seconds_keeps_a_real_budget_and_drops_no_budget() -> None:
    assert [api.budget_seconds(t) for t in (None, 0, 0.0, float("inf"), 1e300)] == [None] * 5
    assert api.budget_seconds(2.5) == 2.5 and api.budget_seconds(1) == 1.0
    assert api.budget_seconds(api.MAX_BUDGET_S) == api.MAX_BUDGET_S
    # re-check trial, session 36: 10**400 raised OverflowError; a positive Fraction that
    # rounds to 0.0 became no limit
    from fractions import Fraction

    assert api.budget_seconds(10**400) is None
    assert api.budget_seconds(Fraction(1, 10**400)) == api.MIN_BUDGET_S
    with pytest.raises(InputError):
        api.budget_seconds(-(10**400))
    # API review, session 44: a Decimal and a 0-d array were refused (simulate's time_limit
    # takes them); a Decimal NaN or a negative one is still refused
    from decimal import Decimal

    import numpy as np

    assert api.budget_seconds(Decimal("2.5")) == 2.5 == api.budget_seconds(np.array(2.5))
    assert api.budget_seconds(Decimal("1e-400")) == api.MIN_BUDGET_S
    for bad in (Decimal("NaN"), Decimal("-1"), np.array(True)):
        with pytest.raises(InputError):
            api.budget_seconds(bad)
    # re-check review, session 44: Decimal('1e10000000') built 10^10⁷ in full (8 s), and
    # Infinity was refused; a negative value below the float range passed as −0.0
    import time

    t0 = time.perf_counter()
    assert api.budget_seconds(Decimal("1e999999999")) is None
    assert time.perf_counter() - t0 < 1.0
    assert api.budget_seconds(Decimal("Infinity")) is None
    assert api.budget_seconds(Decimal("1e-999999999")) == api.MIN_BUDGET_S
    for zero in ("0E+500", "-0E+500", "0E+401"):  # zeros, whatever the exponent (re-check)
        assert api.budget_seconds(Decimal(zero)) is None
    t0 = time.perf_counter()
    with pytest.raises(InputError, match="must be ≥ 0 seconds"):
        api.budget_seconds(Decimal("-1e100000000"))  # built 10^10⁸ before (re-check review)
    assert time.perf_counter() - t0 < 1.0
    for bad in (Decimal("-1e-999999999"), Fraction(-1, 10**400), Decimal("-Infinity")):
        with pytest.raises(InputError, match="must be ≥ 0 seconds"):
            api.budget_seconds(bad)


def test_a_spec_named_twice_gets_one_row(tmp_path: Path) -> None:
    """``check d d/ d/a.toml`` gave each of d's specs two rows and a third for a.toml, so the
    verdict counted them twice (outsider trial, session 26); a symlink to a spec is the spec."""
    d = tmp_path / "d"
    d.mkdir()
    (d / "a.toml").write_text("x = 1\n")
    (d / "b.toml").write_text("x = 1\n")
    (tmp_path / "link.toml").symlink_to(d / "a.toml")
    got = api.spec_files([d, f"{d}/", d / "a.toml", tmp_path / "link.toml"])
    assert got == [d / "a.toml", d / "b.toml"]


def test_a_link_and_its_target_are_one_row_named_after_the_target(tmp_path: Path) -> None:
    """A folder with alias.toml -> real/b.toml had one row, "alias.toml", and real/b.toml
    in none (docs trial, session 31): the file itself names the row, in the link's place."""
    (tmp_path / "real").mkdir()
    (tmp_path / "real" / "b.toml").write_text("x = 1\n")
    (tmp_path / "alias.toml").symlink_to(tmp_path / "real" / "b.toml")
    (tmp_path / "c.toml").write_text("x = 1\n")
    assert api.spec_files(tmp_path) == [tmp_path / "c.toml", tmp_path / "real" / "b.toml"]
    assert api.spec_files([tmp_path / "alias.toml"]) == [tmp_path / "alias.toml"]


def test_a_time_budget_whose_first_alarm_is_swallowed_fires_again() -> None:
    """An exception raised while Python runs a __del__ or a weakref callback is printed and
    dropped: a sweep point past its 1 s budget then ran to its end (exit 1 instead of 3; a CI
    run, session 26). The alarm repeats every api.RETIMEOUT_S until the block is left."""
    swallowed, took = _second_stop_within(0.2)
    assert swallowed == 2 and took < 2


def _second_stop_within(seconds: float) -> tuple[int, float]:
    """Spin in Python inside ``_time_budget(seconds)``, swallowing the first stop (as an
    ignored callback does) and letting the second out; then 0.3 s more of Python outside the
    block, where no stop may arrive. (stops seen, seconds until the block was left)."""
    import time

    swallowed = 0
    t0 = time.perf_counter()
    try:
        with api._time_budget(seconds):
            while time.perf_counter() - t0 < 10:
                try:
                    while time.perf_counter() - t0 < 10:
                        pass
                except api.SpecTimeout:
                    swallowed += 1  # the first one lost, as in an ignored callback
                    if swallowed > 1:
                        raise
    except api.SpecTimeout:
        pass
    took = time.perf_counter() - t0
    for _ in range(30):  # the stop was cleared on leaving the block: nothing fires here
        time.sleep(0.01)
    return swallowed, took


def _deep_folder(top: Path, levels: int) -> None:
    """``top/a/a/…/a`` (``levels`` deep), made without recursion (os.makedirs recurses)."""
    top.mkdir()
    fd = os.open(top, os.O_RDONLY)
    try:
        for _ in range(levels):
            os.mkdir("a", dir_fd=fd)
            nxt = os.open("a", os.O_RDONLY, dir_fd=fd)
            os.close(fd)
            fd = nxt
    finally:
        os.close(fd)


def _remove_deep_folder(top: Path) -> None:
    """Remove what :func:`_deep_folder` made, without recursion: pytest's own clean-up of old
    temporary folders (shutil.rmtree, recursive) stopped the session with a RecursionError."""
    while (top / "a" / "a").is_dir():  # lift the subtree one level: short paths only
        (top / "a" / "a").rename(top / "b")
        (top / "a").rmdir()
        (top / "b").rename(top / "a")
    if (top / "a").is_dir():
        (top / "a").rmdir()
    top.rmdir()


def test_a_very_deep_folder_costs_no_other_row(tmp_path: Path) -> None:
    """``check good deep`` with a folder 1,100 levels deep stopped with exit 3
    (RecursionError in Path.rglob) and printed no row, the good spec's included (sweep,
    import and check trial, session 28)."""
    good = tmp_path / "good"
    good.mkdir()
    shutil.copy(SPEC, good / "s.toml")
    _deep_folder(tmp_path / "deep", 1100)
    try:
        res = runner.invoke(app, ["check", str(good), str(tmp_path / "deep"), "--format", "json"])
        # the good spec keeps its row; the deep folder, holding no spec, is a row of its own
        # saying so since session 45 (an empty folder beside a spec was dropped silently)
        rows = json.loads(res.stdout)
        assert [r["code"] for r in rows] == [0, 2], res.output
        assert rows[1]["message"].endswith("a folder with no spec files (*.toml)")
        assert api.spec_files([good, tmp_path / "deep"]) == [good / "s.toml", tmp_path / "deep"]
    finally:
        _remove_deep_folder(tmp_path / "deep")
    assert not (tmp_path / "deep").exists()


def test_folders_named_toml_are_searched_not_checked(tmp_path: Path) -> None:
    """A folder named ``v1.toml`` (or a link to a folder, named ``l.toml``) was a failed
    "is a directory" row beside the specs inside it (session 28); hidden folders and links to
    folders are not searched, hidden files are checked as before."""
    (tmp_path / "v1.toml").mkdir()
    shutil.copy(SPEC, tmp_path / "v1.toml" / "spec.toml")
    (tmp_path / "l.toml").symlink_to(tmp_path / "v1.toml")
    (tmp_path / ".hid").mkdir()
    (tmp_path / ".hid" / "x.toml").write_text("x = 1\n")
    (tmp_path / ".h.toml").write_text("x = 1\n")
    assert api.spec_files(tmp_path) == [tmp_path / ".h.toml", tmp_path / "v1.toml" / "spec.toml"]


def _unlistable(monkeypatch: pytest.MonkeyPatch, name: str) -> None:
    """Make every folder called ``name`` unlistable (PermissionError from os.scandir): root,
    which runs CI, reads any folder whatever its mode."""
    real = os.scandir

    def scandir(p: object = ".") -> object:
        if Path(str(p)).name == name:
            raise PermissionError(13, "Permission denied")
        return real(p)

    monkeypatch.setattr(os, "scandir", scandir)


def test_a_folder_that_cannot_be_listed_gets_a_row(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Path.rglob skipped a folder it could not read, silently: its specs had no row
    (session 28). The folder is a row saying it cannot be read."""
    (tmp_path / "shut").mkdir()
    shutil.copy(SPEC, tmp_path / "shut" / "s.toml")
    shutil.copy(SPEC, tmp_path / "ok.toml")
    _unlistable(monkeypatch, "shut")
    rows = {Path(r.spec).name: r for r in api.check(tmp_path)}
    assert rows["ok.toml"].code == 0
    assert rows["shut"].code == 2
    assert "a folder that cannot be read (Permission denied)" in rows["shut"].message


def test_check_junit_refusals_do_not_suggest_force(tmp_path: Path) -> None:
    """``check --junit`` refusals ended "(--force)", an option check does not have
    (session 28)."""
    shutil.copy(SPEC, tmp_path / "a.toml")
    for target in (tmp_path / "a.toml", Path("/dev/null")):
        res = runner.invoke(app, ["check", str(tmp_path), "--junit", str(target)])
        assert res.exit_code == 2, res.output
        assert "refusing" in res.output and "--force" not in res.output, res.output
    res = runner.invoke(app, ["design", str(SPEC), "-o", "/dev/null"])
    assert res.exit_code == 2 and "(--force writes into it)" in res.output
    # the checked folder itself as --junit: "is a directory", as any folder (it said "is the
    # input file itself"; sweep and check review, session 42)
    res = runner.invoke(app, ["check", str(tmp_path), "--junit", str(tmp_path)])
    assert res.exit_code == 2 and f"{tmp_path}: is a directory" in res.output, res.output
    # and through a symbolic link to it (re-check review, session 43)
    link = tmp_path.parent / f"{tmp_path.name}-link"
    link.symlink_to(tmp_path)
    res = runner.invoke(app, ["check", str(tmp_path), "--junit", str(link)])
    assert res.exit_code == 2 and f"{link}: is a directory" in res.output, res.output


def test_a_folder_that_cannot_be_listed_does_not_end_the_search(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Mutation review 28: obsdesign.api.x__toml_files__mutmut_9 (``continue`` -> ``break`` after a subfolder
    that cannot be listed: every folder still on the stack was skipped, its specs with no
    row). Two folders each holding a spec and an unlistable subfolder: whichever is walked
    first, the other is still searched."""
    for name in ("a", "b"):
        (tmp_path / name / "shut").mkdir(parents=True)
        shutil.copy(SPEC, tmp_path / name / "s.toml")
    _unlistable(monkeypatch, "shut")
    assert api.spec_files(tmp_path) == [
        tmp_path / "a" / "s.toml",
        tmp_path / "a" / "shut",
        tmp_path / "b" / "s.toml",
        tmp_path / "b" / "shut",
    ]


def test_an_entry_whose_kind_cannot_be_read_is_not_searched(tmp_path: Path) -> None:
    """Mutation review 28: obsdesign.api.x__toml_files__mutmut_16 (an entry whose ``is_dir`` raises taken as a
    folder): a symbolic link to itself (ELOOP) not named *.toml is neither searched nor a
    row; the spec beside it is the only row."""
    shutil.copy(SPEC, tmp_path / "a.toml")
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    assert api.spec_files(tmp_path) == [tmp_path / "a.toml"]


def test_a_named_folder_that_cannot_be_listed_gets_a_row(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``check good locked`` said "1 ok" and ``check locked`` "no spec files" for a folder
    named on the command line that cannot be listed (re-check trial, session 28)."""
    (tmp_path / "good").mkdir()
    shutil.copy(SPEC, tmp_path / "good" / "s.toml")
    (tmp_path / "shut").mkdir()
    _unlistable(monkeypatch, "shut")
    rows = {Path(r.spec).name: r for r in api.check([tmp_path / "good", tmp_path / "shut"])}
    assert rows["s.toml"].code == 0 and rows["shut"].code == 2
    assert "a folder that cannot be read" in rows["shut"].message
    assert api.spec_files(tmp_path / "shut") == [tmp_path / "shut"]


def _in_thread(fn: Any) -> Any:
    """``fn()`` run in a new thread (no signal reaches it, as a Dask worker's task); its
    result, or the exception it raised, re-raised here."""
    import threading

    out: list[Any] = []

    def run() -> None:
        try:
            out.append(("ok", fn()))
        except BaseException as e:  # noqa: BLE001 - handed back to the caller
            out.append(("raised", e))

    t = threading.Thread(target=run)
    t.start()
    t.join(60)
    assert out, "the thread did not finish"
    kind, v = out[0]
    if kind == "raised":
        raise v
    return v


def test_a_time_budget_stops_a_loop_outside_the_main_thread() -> None:
    """``check --workers`` / ``sweep --workers`` ran every spec unbounded: SIGALRM reaches the
    main thread only, and a Dask task runs in a worker thread (session 30). There the stop is
    an exception scheduled in the thread; it repeats if swallowed, and nothing fires once the
    block is left."""
    import pytest

    swallowed, took = _in_thread(lambda: _second_stop_within(0.2))
    assert swallowed == 2 and took < 2
    assert _in_thread(lambda: _spin_within(api._time_budget(5), 0.3)) == "done"
    with pytest.raises(api.SpecTimeout):
        _in_thread(lambda: _spin_within(api._time_budget(0.1), 5))


def _spin_within(budget: Any, seconds: float) -> str:
    """Run Python for ``seconds`` inside ``budget``; "done" when it was not stopped."""
    import time

    t0 = time.perf_counter()
    with budget:
        while time.perf_counter() - t0 < seconds:
            pass
    time.sleep(0.2)  # after the block: a late stop would be raised here
    return "done"


def test_check_remote_applies_the_time_budget_in_its_thread(tmp_path: Path, monkeypatch):
    """The item a Dask worker gets carries ``check --timeout``; the worker's thread is
    stopped at it (exit 3 row naming the method), where it ran to its end (session 30)."""
    import time

    spec = tmp_path / "b.toml"
    shutil.copy(SPEC, spec)
    real = api.design

    def slow(sp, *a, **k):
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < 8:
            time.sleep(0.01)
        return real(sp, *a, **k)

    monkeypatch.setattr(api, "design", slow)
    item = (*api._remote_item(spec), 0.5)
    t0 = time.perf_counter()
    row = _in_thread(lambda: api.check_remote(item))
    assert time.perf_counter() - t0 < 5
    assert row.code == 3 and "not finished within 0.5 s" in row.message
    assert row.method == "lyapunov"


def test_check_workers_passes_the_timeout_on(tmp_path: Path, monkeypatch) -> None:
    """``check --workers 2 --timeout 7`` hands the budget to the Dask run (it was dropped:
    the workers ran every spec unbounded; session 30); ``--timeout 0`` is no budget."""
    import obsdesign.distributed as dist

    spec = tmp_path / "s.toml"
    shutil.copy(SPEC, spec)
    seen: list[Any] = []
    real = api.check

    def record(paths: Any, *a: Any, **k: Any) -> Any:
        seen.append(k.get("timeout"))
        k.pop("workers", None)
        return real(paths, *a, **{**k, "client": None})

    monkeypatch.setattr(dist, "check_workers", lambda *a: None)
    monkeypatch.setattr(api, "check", record)
    for t, want in (("7", 7.0), ("0", None)):
        res = runner.invoke(app, ["check", str(spec), "--workers", "2", "--timeout", t, "-q"])
        assert res.exit_code == 0, res.output
        assert seen[-1] == want


# -- mutation review 30 (docs/mutation.md)


# --- Mutation review 30: api._thread_budget (ready to append to tests/test_reliability_check.py)


class _FakeTimer:
    """threading.Timer that never runs by itself: the test fires it by hand."""

    made: list[_FakeTimer] = []

    def __init__(self, after: float, fn: Any) -> None:
        self.after, self.fn, self.cancelled, self.daemon = after, fn, False, False
        _FakeTimer.made.append(self)

    def start(self) -> None:
        pass

    def cancel(self) -> None:
        self.cancelled = True


def test_thread_budget_schedules_no_stop_once_the_block_is_left(monkeypatch) -> None:
    """Mutation review 30 (api._thread_budget: ``armed = [True]`` kept after the block, the
    ``if armed[0]`` test dropped, ``timers[0].cancel()`` dropped, the final
    ``_async_raise(tid, None)`` dropped, ``timers.append``): a timer that fires after the block
    was left (it lost the race for the lock) schedules nothing and starts no retimer; every
    timer is cancelled, and a stop scheduled before leaving is cancelled on the way out."""
    import threading

    _FakeTimer.made = []
    calls: list[tuple[int, Any]] = []
    monkeypatch.setattr(api.threading, "Timer", _FakeTimer)
    monkeypatch.setattr(api, "_async_raise", lambda tid, exc: calls.append((tid, exc)))
    tid = threading.get_ident()
    with api._thread_budget(5.0):
        assert [t.after for t in _FakeTimer.made] == [5.0]
        _FakeTimer.made[0].fn()  # the deadline passes inside the block: a stop, then a retimer
        assert calls == [(tid, api.SpecTimeout)]
        assert [t.after for t in _FakeTimer.made] == [5.0, api.RETIMEOUT_S]
    assert _FakeTimer.made[-1].cancelled  # the retimer pending at the exit
    assert calls[-1] == (tid, None)  # a stop scheduled but not yet raised is cancelled
    n_calls, n_timers = len(calls), len(_FakeTimer.made)
    for t in list(_FakeTimer.made):
        t.fn()  # a timer that fires late (it was waiting for the lock while the block left)
    assert len(calls) == n_calls and len(_FakeTimer.made) == n_timers
    with api._thread_budget(3.0):
        pass
    assert _FakeTimer.made[-1].after == 3.0 and _FakeTimer.made[-1].cancelled


@pytest.mark.parametrize("thread", [False, True])
def test_a_time_budget_waits_for_an_import_to_finish(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, thread: bool
) -> None:
    """A budget that fired inside ``import cvxpy`` left half of cvxpy in sys.modules, and every
    later spec of that ``check`` failed "module 'cvxpy' has no attribute 'promote'" (CLI
    hostile-input trial, session 34). The stop waits until no module is being imported: the
    slow import completes, the stop comes right after it."""
    import sys
    import threading
    import time

    (tmp_path / "slow_mod_34.py").write_text(
        "import time\nt0 = time.perf_counter()\n"
        "while time.perf_counter() - t0 < 0.6:\n    pass\ndone = True\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "slow_mod_34", raising=False)
    out: dict[str, Any] = {}

    def run() -> None:
        try:
            with api._time_budget(0.1):
                import slow_mod_34  # noqa: F401

                out["imported"] = time.perf_counter()
                while True:
                    time.sleep(0.01)
        except api.SpecTimeout:
            out["stopped"] = time.perf_counter()

    if thread:
        th = threading.Thread(target=run)
        th.start()
        th.join(10)
    else:
        run()
    assert sys.modules["slow_mod_34"].done is True
    assert "imported" in out and out["stopped"] - out["imported"] < 0.5
    sys.modules.pop("slow_mod_34", None)


def test_a_time_budget_started_inside_an_import_still_stops(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The wait for a running import counted the caller's own: a ``check(timeout=2)`` at the
    top level of an imported module never stopped (re-check trial, session 34). Only imports
    begun after the budget started make it wait."""
    import sys

    (tmp_path / "outer_mod_34.py").write_text(
        "import time\nfrom obsdesign import api\nt0 = time.perf_counter()\nstopped = None\n"
        "try:\n    with api._time_budget(0.2):\n"
        "        while time.perf_counter() - t0 < 5:\n            pass\n"
        "except api.SpecTimeout:\n    stopped = time.perf_counter() - t0\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "outer_mod_34", raising=False)
    import outer_mod_34  # type: ignore[import-not-found]

    assert outer_mod_34.stopped is not None and outer_mod_34.stopped < 2
    sys.modules.pop("outer_mod_34", None)


def test_the_api_check_refuses_an_empty_path() -> None:
    """``check([''])`` checked the working folder (pathlib reads '' as '.'), which the CLI
    refuses (re-check trial, session 34)."""
    from obsdesign.errors import InputError

    for paths in ("", [""], ["specs", ""]):
        with pytest.raises(InputError, match="check: an empty path"):
            api.check(paths)


def _real_itimer_and_alarm_restored(before: Any) -> None:
    import signal

    assert signal.getsignal(signal.SIGALRM) is before
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_a_stop_that_lands_as_the_timer_starts_leaves_no_timer(monkeypatch) -> None:
    """``check --timeout 1e-7``: the first alarm landed between starting the timer and the
    ``try``, so the ``finally`` never ran — the timer kept repeating with the budget's handler,
    and the process died "Alarm clock" (exit 142) after check had written its rows (batch
    trial, session 35). Here the alarm's handler runs right after the timer is armed, past
    the deadline of a 10⁻⁷ s budget (an alarm before the deadline is not the budget's)."""
    import signal

    before = signal.getsignal(signal.SIGALRM)
    real = signal.setitimer

    def arm_then_fire(which: int, seconds: float, interval: float = 0.0) -> Any:
        out = real(which, seconds, interval)
        if seconds > 0:
            signal.getsignal(signal.SIGALRM)(signal.SIGALRM, None)
        return out

    monkeypatch.setattr(signal, "setitimer", arm_then_fire)
    with pytest.raises(api.SpecTimeout):
        with api._time_budget(1e-7):
            pass
    monkeypatch.setattr(signal, "setitimer", real)
    _real_itimer_and_alarm_restored(before)


def test_a_stop_that_lands_as_the_block_is_left_is_ignored(monkeypatch) -> None:
    """The other end of the same race: an alarm landing in the ``finally`` before the timer
    was cleared raised there and skipped the cleanup (batch trial, session 35). A stop that
    comes once the block is being left is ignored: the block's work is done."""
    import signal

    before = signal.getsignal(signal.SIGALRM)
    real = signal.setitimer

    def fire_then_disarm(which: int, seconds: float, interval: float = 0.0) -> Any:
        if seconds == 0:
            signal.getsignal(signal.SIGALRM)(signal.SIGALRM, None)
        return real(which, seconds, interval)

    monkeypatch.setattr(signal, "setitimer", fire_then_disarm)
    with api._time_budget(30):
        done = True
    monkeypatch.setattr(signal, "setitimer", real)
    assert done
    _real_itimer_and_alarm_restored(before)


def test_many_tiny_budgets_leave_no_timer_behind() -> None:
    """The race itself, not simulated: budgets of 10⁻⁷ s fire at every point of the way in
    and out; none may leave the timer or its handler behind (batch trial, session 35)."""
    import signal

    before = signal.getsignal(signal.SIGALRM)
    for _ in range(300):
        try:
            with api._time_budget(1e-7):
                sum(range(50))
        except api.SpecTimeout:
            pass
    _real_itimer_and_alarm_restored(before)


def test_the_thread_budget_timer_survives_a_failed_import_probe(monkeypatch) -> None:
    """A Dask worker's budget timer died of "dictionary changed size during iteration" while
    it looked for running imports, and the spec then ran unbounded (batch trial, session 35):
    a failed probe schedules no stop now, and the timer tries again."""
    _FakeTimer.made = []
    calls: list[Any] = []
    monkeypatch.setattr(api.threading, "Timer", _FakeTimer)
    monkeypatch.setattr(api, "_async_raise", lambda tid, exc: calls.append(exc))

    def broken(already: Any) -> bool:
        raise RuntimeError("dictionary changed size during iteration")

    with api._thread_budget(5.0):
        monkeypatch.setattr(api, "_importing", broken)
        _FakeTimer.made[0].fn()  # does not raise
        assert calls == [] and [t.after for t in _FakeTimer.made] == [5.0, api.RETIMEOUT_S]
        monkeypatch.setattr(api, "_importing", lambda already: False)
        _FakeTimer.made[-1].fn()  # the retry stops the work
        assert calls == [api.SpecTimeout]


def test_a_stop_python_cannot_propagate_is_not_printed(monkeypatch) -> None:
    """A SpecTimeout raised inside a ``__del__`` printed "Exception ignored in …" with a
    traceback on a Dask worker's stderr (batch trial, session 35); the budget's repeat stops
    the work again, so the hook drops it and passes anything else on."""
    import sys
    from types import SimpleNamespace

    seen: list[Any] = []
    monkeypatch.setattr(sys, "unraisablehook", lambda a: seen.append(a.exc_value))
    api._install_quiet_timeout()
    api._install_quiet_timeout()
    sys.unraisablehook(SimpleNamespace(exc_value=api.SpecTimeout()))
    err = ValueError("x")
    sys.unraisablehook(SimpleNamespace(exc_value=err))
    assert seen == [err]
    assert sys.unraisablehook._obsdesign_quiet_timeout is True


def test_a_worker_row_names_a_file_with_a_newline_as_the_serial_row_does(
    tmp_path: Path, monkeypatch
) -> None:
    """The worker's message holds the file name escaped ("nl\\\\nname.toml"), so replacing the
    raw absolute path missed it and ``check --workers`` rows kept the worker's absolute path
    where the serial row has the name as given (batch trial, session 35)."""
    monkeypatch.chdir(tmp_path)
    name = Path("nl\nname.toml")
    name.write_text('title = "x"\n')
    serial = api.check_one(name)
    remote = api.check_remote((*api._remote_item(name), None))
    assert remote.code == serial.code == 2
    assert remote.message == serial.message, (remote.message, serial.message)
    assert str(tmp_path) not in remote.message


@pytest.mark.parametrize("bad", [-1, "1", True, float("nan")])
def test_check_refuses_a_bad_timeout_before_any_row(bad) -> None:
    """Mutation review 36: check() reads timeout= by budget_seconds itself, so a bad budget is
    an InputError even when no spec would reach check_one (an empty list of paths)."""
    from obsdesign import api
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match="timeout"):
        api.check([], timeout=bad)


def _hang_forever(*a: Any, **k: Any) -> Any:
    """A stage that never ends and swallows every Exception (as a method might)."""
    import time

    while True:
        try:
            time.sleep(0.05)
        except Exception:  # noqa: BLE001, S110
            pass


@pytest.mark.parametrize("stage", ["design", "certify"])
def test_design_timeout_stops_a_stage_with_exit_3_and_an_error_report(
    tmp_path: Path, monkeypatch, stage: str
):
    """``design --timeout`` bounds the design and its certification together: a search-space
    spec with a long expression in u ran for minutes and only ``check --timeout`` could stop
    it (search-space trial, session 38). Past the budget: exit 3, one line, and -o holds the
    error report (never a stale one)."""
    import time

    from obsdesign.methods import get_method

    out = tmp_path / "r.json"
    out.write_text('{"stale": true}')
    if stage == "design":
        monkeypatch.setattr(type(get_method("lyapunov")), "design", _hang_forever)
    else:
        monkeypatch.setattr(api, "certify", _hang_forever)
    t0 = time.perf_counter()
    res = runner.invoke(app, ["design", str(SPEC), "-o", str(out), "--timeout", "0.5"])
    assert time.perf_counter() - t0 < 30
    assert res.exit_code == 3, res.output
    assert "not finished within 0.5 s (design --timeout" in res.output
    assert "Traceback" not in res.output
    rep = json.loads(out.read_text())
    assert rep["verdict"] == "error" and rep["error"]["exit_code"] == 3
    with pytest.raises(api.SolverError, match="not finished within 0.5 s"):
        api.design(SPEC, timeout=0.5)


def test_design_timeout_is_one_budget_for_both_stages(monkeypatch):
    """The certify stage gets what the design stage left, not a fresh budget."""
    import time

    from obsdesign.methods import get_method

    cls = type(get_method("lyapunov"))
    real = cls.design

    def slow(self: Any, *a: Any, **k: Any) -> Any:
        time.sleep(0.6)
        return real(self, *a, **k)

    def sleepy_certify(*a: Any, **k: Any) -> Any:
        time.sleep(0.6)
        return []

    monkeypatch.setattr(cls, "design", slow)
    monkeypatch.setattr(api, "certify", sleepy_certify)
    with pytest.raises(api.SolverError, match="not finished within 1 s"):
        api.design(SPEC, timeout=1)
    assert api.design(SPEC, timeout=5).claims == []  # both stages fit in 5 s


def test_design_timeout_generous_or_none_changes_nothing(tmp_path: Path):
    ref = api.design(SPEC)
    for t in (None, 0, 600, float("inf")):
        rep = api.design(SPEC, timeout=t)
        assert rep.verdict == ref.verdict == "ok"
        assert [c.status for c in rep.claims] == [c.status for c in ref.claims]
    assert runner.invoke(app, ["design", str(SPEC), "--timeout", "600", "-q"]).exit_code == 0
    res = runner.invoke(app, ["design", str(SPEC), "--timeout", "-1"])
    assert res.exit_code == 2 and "Traceback" not in res.output
    for bad in (-1, float("nan"), "1", True):
        with pytest.raises(InputError, match="timeout"):
            api.design(SPEC, timeout=bad)


def test_a_budget_puts_back_the_callers_own_timer(tmp_path: Path):
    """An API caller's own watchdog (setitimer / alarm) survives check(timeout=) and
    design(timeout=): the budget disarmed it for good, so the caller's hang protection was
    silently lost (batch trial, session 39). It is re-armed with what was left of it."""
    import signal
    import time

    fired = []
    old = signal.signal(signal.SIGALRM, lambda *a: fired.append(1))
    try:
        signal.setitimer(signal.ITIMER_REAL, 30.0)
        api.check([SPEC], timeout=600)
        left, _ = signal.getitimer(signal.ITIMER_REAL)
        assert 0 < left <= 30.0
        api.design(SPEC, timeout=600)
        left2, _ = signal.getitimer(signal.ITIMER_REAL)
        assert 0 < left2 <= left
        signal.setitimer(signal.ITIMER_REAL, 0.2)  # runs out during the budget's block
        real = api.design

        def slow(*a, **k):
            time.sleep(0.4)
            return real(*a, **k)

        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(api, "design", slow)
            api.check([SPEC], timeout=600)
        t0 = time.monotonic()
        while not fired and time.monotonic() - t0 < 5:
            time.sleep(0.01)
        assert fired  # fired right after the block
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _slow_lyapunov_design(monkeypatch: Any, seconds: float) -> None:
    """Make the lyapunov method's design take ``seconds`` more, in 0.05 s sleeps (each a
    point where a signal's handler runs)."""
    import time

    from obsdesign.methods import get_method

    cls = type(get_method("lyapunov"))
    real = cls.design

    def slow(self: Any, *a: Any, **k: Any) -> Any:
        for _ in range(round(seconds / 0.05)):
            time.sleep(0.05)
        return real(self, *a, **k)

    monkeypatch.setattr(cls, "design", slow)


def test_the_callers_timer_fires_on_time_during_a_budget(monkeypatch):
    """A caller's 0.3 s watchdog during design(timeout=100) of a design that takes 2 s fired
    only when the design returned (re-check trial, session 39): the timer is armed for the
    earlier of the two deadlines, and the caller's alarm goes to the caller's handler."""
    import signal
    import time

    class Watchdog(Exception):
        pass

    def bark(*a: Any) -> None:
        raise Watchdog

    _slow_lyapunov_design(monkeypatch, 2.0)
    old = signal.signal(signal.SIGALRM, bark)
    try:
        t0 = time.monotonic()
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        with pytest.raises(Watchdog):
            api.design(SPEC, timeout=100)
        assert time.monotonic() - t0 < 1.5
        assert signal.getitimer(signal.ITIMER_REAL)[0] == 0  # the budget's timer is gone
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_a_sigalrm_from_outside_is_not_the_budgets(monkeypatch):
    """kill -ALRM during check's 600 s budget was read as the budget's own alarm: the spec
    was "not finished within 600 s" after 0.06 s (re-check trial, session 39). An alarm
    before the deadline goes to the handler installed before the budget (the CLI's stops
    the command, "alarm clock", exit 142)."""
    import os
    import signal
    import threading

    got = []
    _slow_lyapunov_design(monkeypatch, 1.0)
    old = signal.signal(signal.SIGALRM, lambda *a: got.append(1))
    try:
        threading.Timer(0.2, lambda: os.kill(os.getpid(), signal.SIGALRM)).start()
        rep = api.design(SPEC, timeout=600)  # no SolverError "not finished within 600 s"
        assert rep.verdict == "ok" and got == [1]
    finally:
        signal.signal(signal.SIGALRM, old)


def test_a_watchdog_that_rearms_itself_keeps_firing_and_does_not_delay_the_budget(monkeypatch):
    """A caller's handler that re-arms its timer (setitimer / alarm in the handler) replaced
    the budget's deadline and was then disarmed for good: no more alarms after
    design(timeout=100), and a 0.5 s budget stopped at 2 s behind a 5 s re-arm (re-check
    trial, session 39). The handler runs with the timer stopped; its new time is the
    caller's."""
    import signal
    import time

    _slow_lyapunov_design(monkeypatch, 2.0)
    fired: list[float] = []
    t0 = time.monotonic()

    def rearm(*a: Any) -> None:
        fired.append(time.monotonic() - t0)
        signal.setitimer(signal.ITIMER_REAL, 0.3)

    old = signal.signal(signal.SIGALRM, rearm)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.3)
        api.design(SPEC, timeout=100)
        assert len(fired) >= 4  # 0.3, 0.6, … through the 2 s design
        assert signal.getitimer(signal.ITIMER_REAL)[0] > 0  # still armed after it
        signal.setitimer(signal.ITIMER_REAL, 0)

        def slow_rearm(*a: Any) -> None:
            signal.setitimer(signal.ITIMER_REAL, 5.0)

        signal.signal(signal.SIGALRM, slow_rearm)
        signal.setitimer(signal.ITIMER_REAL, 0.1)
        t1 = time.monotonic()
        with pytest.raises(api.SolverError, match="not finished within 0.5 s"):
            api.design(SPEC, timeout=0.5)
        assert time.monotonic() - t1 < 1.5
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_an_outer_budgets_stop_is_not_an_inner_designs_timeout(monkeypatch):
    """design(timeout=100) inside a 1 s budget: the outer stop came out as "not finished
    within 100 s" (re-check trial, session 39); it reaches the outer budget."""
    import time

    _slow_lyapunov_design(monkeypatch, 2.0)
    t0 = time.monotonic()
    with pytest.raises(api.SpecTimeout):
        with api._time_budget(1.0):
            api.design(SPEC, timeout=100)
    assert time.monotonic() - t0 < 1.8


@pytest.mark.parametrize("cmd", ["design", "check", "sweep"])
def test_a_nan_or_negative_timeout_is_named_as_such(tmp_path: Path, cmd: str):
    """``--timeout nan`` got typer's "greater than or equal to 0", which nan is not less
    than either (CLI review, session 39): the message now says it is not a number of
    seconds; negative values too; both are exit 2 with nothing written."""
    args = {"design": ["design", str(SPEC)], "check": ["check", str(SPEC)]}.get(
        cmd, ["sweep", str(SPEC), "--set", "method.L=[[1],[1]]"]
    )
    for bad in ("nan", "-1", "-inf", "-1e-400"):
        res = runner.invoke(app, [*args, "--timeout", bad])
        assert res.exit_code == 2, res.output
        assert "is not a number of seconds >= 0" in res.output
        assert "Traceback" not in res.output


def test_a_positive_timeout_below_the_float_range_is_the_smallest_budget() -> None:
    """``--timeout 1e-400`` read as 0.0, no limit, and ran the whole design (CLI review,
    session 44): it is the smallest budget, exit 3 at once; ``-0`` is no limit."""
    res = runner.invoke(app, ["design", str(SPEC), "-q", "--timeout", "1e-400"])
    assert res.exit_code == 3 and "not finished within" in res.output, res.output
    assert runner.invoke(app, ["design", str(SPEC), "-q", "--timeout", "-0"]).exit_code == 0
    # Arabic-Indic digits: Decimal read them, --limit refuses them (CLI review 45)
    res = runner.invoke(app, ["design", str(SPEC), "-q", "--timeout", "٥"])
    assert res.exit_code == 2 and "is not a number of seconds" in res.output, res.output


def test_an_exception_of_the_callers_alarm_handler_reaches_the_caller(monkeypatch):
    """A caller whose watchdog's SIGALRM handler raises (its own TimeoutError) during
    check(timeout=) / design(timeout=) gets that exception: check made it the row's exit 3
    "internal failure: …" and went on to the next spec (session 39)."""
    import signal
    import time

    class Watchdog(Exception):
        pass

    def bark(*a: Any) -> None:
        raise Watchdog("caller's deadline")

    old = signal.signal(signal.SIGALRM, bark)
    try:
        _slow_lyapunov_design(monkeypatch, 2.0)
        for run in (
            lambda: api.check([SPEC, SPEC], timeout=600),
            lambda: api.design(SPEC, timeout=600),
        ):
            signal.setitimer(signal.ITIMER_REAL, 0.2)
            t0 = time.monotonic()
            with pytest.raises(Watchdog, match="caller's deadline"):
                run()
            assert time.monotonic() - t0 < 1.5  # stopped by it, not after the work
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_the_callers_alarm_waits_for_an_import_to_end(monkeypatch):
    """A caller's alarm handler that raises inside ``import cvxpy`` (the first design of a
    process) left cvxpy half-imported: every later design failed with "module 'cvxpy' has no
    attribute 'promote'" (re-check trial, session 40). During a budget the caller's alarm
    now waits for the import to end, as the budget's own stop does (an import simulated
    here for 0.3 s)."""
    import signal
    import time

    from obsdesign import api as api_mod

    class Watchdog(Exception):
        pass

    importing = [True]
    monkeypatch.setattr(api_mod, "_importing", lambda already: importing[0])
    fired: list[float] = []

    def bark(*a: Any) -> None:
        fired.append(time.monotonic())
        raise Watchdog

    old = signal.signal(signal.SIGALRM, bark)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.05)
        t0 = time.monotonic()
        with pytest.raises(Watchdog), api_mod._time_budget(100):
            while time.monotonic() - t0 < 0.3:  # "importing"
                pass
            importing[0] = False
            while time.monotonic() - t0 < 3:
                pass
        assert len(fired) == 1 and 0.3 <= fired[0] - t0 < 1.0
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_a_name_too_long_is_one_row_not_the_whole_check(tmp_path: Path) -> None:
    """``check good.toml <300-character name>.toml`` was exit 3 "internal failure: OSError:
    File name too long" with no row at all (``is_dir`` raised ENAMETOOLONG; CLI review,
    session 44): the long name is a file whose row fails, and the good spec keeps its row."""
    good = tmp_path / "good.toml"
    shutil.copy(SPEC, good)
    long = tmp_path / ("a" * 300 + ".toml")
    assert api.spec_files([good, long]) == [good, long]
    res = runner.invoke(app, ["check", str(good), str(long), "--format", "json"])
    rows = json.loads(res.stdout)
    assert res.exit_code == 2 and [r["code"] for r in rows] == [0, 2], res.output


def test_a_report_with_long_exact_values_is_checked_and_its_design_warns(tmp_path: Path) -> None:
    """A Q entry of 1e-300 in the Dórea–Pimenta 7.2 spec gives exact values of ~2,200 digits:
    ``design -o`` exited 0 silently with a report its own ``verify`` refused as bad input
    (max_digits = 1000), and ``check`` made the valid spec a row "exit 2 bad input" (CLI
    review, session 44). check verifies its own report with the digit limit raised to it;
    design warns with the --limit that verifies the file, and that limit does."""
    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "dorea-pimenta-7-2.toml").read_text(encoding="utf-8")
    assert "[0.2681, 0.7595, -0.0851]" in text
    spec = tmp_path / "q.toml"
    spec.write_text(text.replace("[0.2681, 0.7595, -0.0851]", "[1e-300, 0.7595, -0.0851]"))
    res = runner.invoke(app, ["check", str(spec), "-q"])
    assert res.exit_code == 0, res.output
    out = tmp_path / "q.json"
    res = runner.invoke(app, ["design", str(spec), "-q", "-o", str(out)])
    assert res.exit_code == 0
    m = re.search(r"verify it with 'obsdesign --limit max_digits=(\d+) verify", res.stderr)
    assert m and int(m.group(1)) > 1000, res.stderr
    assert runner.invoke(app, ["verify", str(out), "-q"]).exit_code == 2
    need = m.group(1)
    ok = runner.invoke(app, ["--limit", f"max_digits={need}", "verify", str(out), "-q"])
    assert ok.exit_code == 0, ok.output
    short = runner.invoke(app, ["--limit", f"max_digits={int(need) - 1}", "verify", str(out)])
    assert short.exit_code == 2
    # --format json without -o warned of nothing, and its saved stdout was refused by verify
    # (CLI review 44): the printed report gets the same warning, its file called FILE
    res = runner.invoke(app, ["design", str(spec), "--format", "json"])
    assert res.exit_code == 0
    assert (
        f"the report printed holds exact values of {int(need):,} digits" in res.stderr
        and f"verify it with 'obsdesign --limit max_digits={need} verify FILE'" in res.stderr
    ), res.stderr
    saved = tmp_path / "saved.json"
    saved.write_text(res.stdout, encoding="utf-8")
    assert (
        runner.invoke(app, ["--limit", f"max_digits={need}", "verify", str(saved)]).exit_code == 0
    )
    # a float one ulp off beside the long exact values, the report loaded under the raised
    # limit: verify of the file was exit 1, of the object read from it exit 0 (its as-read
    # comparison re-read it under the normal limits and took it for edited; re-check 45)
    import math

    from obsdesign.limits import restore, set_limits
    from obsdesign.limits import saved as saved_limits
    from obsdesign.report.model import Report

    d = json.loads(out.read_text(encoding="utf-8"))
    d["parameters"]["contractivity"] = math.nextafter(d["parameters"]["contractivity"], 2.0)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d), encoding="utf-8")
    state = saved_limits()
    set_limits(max_digits=int(need))
    try:
        loaded, problems = Report.load(bad)
        assert not problems and api.verify(bad).exit_code() == 1
    finally:
        restore(state)
    ver = api.verify(loaded)
    assert ver.exit_code() == 1 and [c.id for c in ver.failed] == ["parameters-consistent"]
    # in memory, the report's own numbers are read as they are: verify(design(spec)) and
    # simulate(spec, design(spec)) were "exit 2 bad input" (re-check review, session 44)
    sp = api.load_spec(spec)
    rep = api.design(sp)
    assert api.verify(rep).exit_code() == 0
    assert api.simulate(sp, rep).metrics()


def test_an_empty_folder_beside_a_spec_is_a_row_saying_so(tmp_path: Path) -> None:
    """``check EMPTY good.toml`` dropped the empty folder and said ok, exit 0, while ``check
    EMPTY`` alone is exit 2 "no spec files" (CLI review 45): the folder is a row of its
    own, exit 2, saying it holds no spec; alone it is still the one-line refusal."""
    empty = tmp_path / "empty"
    empty.mkdir()
    good = tmp_path / "good.toml"
    shutil.copy(SPEC, good)
    rows = api.check([empty, good])
    assert [r.code for r in rows] == [2, 0]
    assert rows[0].message == f"{empty}: a folder with no spec files (*.toml)"
    res = runner.invoke(app, ["check", str(empty), str(good), "-q"])
    assert res.exit_code == 2
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match="no spec files"):
        api.check([empty])


def test_a_repeat_stop_is_not_raised_while_the_first_is_handled() -> None:
    """The budget's stop repeats every RETIMEOUT_S until its block is left (a first one
    raised in a __del__ is dropped). Unwinding a design's large exact objects took longer
    than that, and the repeat, landing in the budget's __exit__ before its except, raised a
    second SpecTimeout that escaped as a traceback, exit 1, no error report (responsiveness
    review 47). A repeat that lands while this budget's own stop is being handled returns;
    one landing after it was dropped still raises."""
    import signal
    import time

    from obsdesign.errors import SolverError

    def repeat_raises(handled: bool) -> bool:
        """Whether the budget's handler, called again after its first stop (while that stop
        is handled, or after it was dropped), raises a second one."""
        raised = []
        with pytest.raises(SolverError, match="not finished within"):
            with api._design_budget(0.05, time.monotonic() + 0.05):
                handler = signal.getsignal(signal.SIGALRM)
                try:
                    while True:
                        pass
                except api.SpecTimeout:
                    if handled:
                        try:
                            handler(signal.SIGALRM, None)  # the repeat, while handled
                        except api.SpecTimeout:
                            raised.append(True)
                        raise
                try:  # dropped, as in a __del__: the repeat comes later
                    handler(signal.SIGALRM, None)
                except api.SpecTimeout:
                    raised.append(True)
                    raise
        return bool(raised)

    assert not repeat_raises(handled=True)
    assert repeat_raises(handled=False)
