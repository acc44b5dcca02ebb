"""Tests of obsdesign.api's argument checks (the CLI's own checks are in test_cli*.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from obsdesign import api
from obsdesign.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"


def test_true_false_arguments_take_bools_only(tmp_path: Path) -> None:
    """force='no' was true: design wrote its report over a .toml file, which it refuses to
    replace without force (CLI review 46). A bool (numpy's too) is taken, anything else is an
    InputError and nothing is written."""
    victim = tmp_path / "victim.toml"
    victim.write_text("x = 1\n", encoding="utf-8")
    for bad in ("no", "", 0, 1, None):
        with pytest.raises(InputError, match="force: expected True or False"):
            api.design(SPEC, out=victim, force=bad)
    assert victim.read_text(encoding="utf-8") == "x = 1\n"
    rep = api.design(SPEC, out=tmp_path / "r.json", force=np.bool_(False))
    assert rep.exit_code() == 0 and (tmp_path / "r.json").exists()
    with pytest.raises(InputError, match="force: expected True or False"):
        api.check_plot_path(tmp_path / "p.png", force="yes")
    res = api.simulate(SPEC)
    with pytest.raises(InputError, match="atomic: expected True or False"):
        api.plot_simulation(SPEC, res, tmp_path / "p.png", atomic="no")
    assert not (tmp_path / "p.png").exists()


def test_a_method_key_that_is_not_a_text_is_bad_input() -> None:
    """api.method(5) and api.method(None) were bare TypeErrors from the suggestion lookup
    (CLI review 46)."""
    for bad in (5, None, b"lyapunov"):
        with pytest.raises(InputError, match="expected a method key"):
            api.method(bad)
    assert api.method("lyapunov").key == "lyapunov"


def test_callbacks_and_paths_of_other_types_are_bad_input(tmp_path: Path) -> None:
    """design(progress=5), check(on_row=5) were bare TypeErrors after the work began (and
    design(out=…) wrote them as the tool's "internal failure"); bind(None), check_one(None),
    spec_files(None), a NUL in observer_statespace's path and plot_simulation(…, None,
    atomic=False) were bare exceptions; check_one took only a Path (API review 46)."""
    from obsdesign.interop import observer_statespace

    out = tmp_path / "r.json"
    for bad in (5, "x", lambda: None):
        with pytest.raises(InputError, match="progress: expected a function of one argument"):
            api.design(SPEC, out=out, progress=bad)
    assert not out.exists()
    with pytest.raises(InputError, match="on_row: expected a function of one argument"):
        api.check(SPEC, on_row=5)
    seen: list[str] = []
    assert api.check(SPEC, on_start=lambda p: seen.append(str(p)))[0].code == 0
    assert seen == [str(SPEC)]
    for call, said in (
        (lambda: api.bind(None), "bind: expected a Spec"),
        (lambda: api.check_one(None), "check_one: expected a path"),
        (lambda: api.spec_files(None), "spec_files: expected a path or a list of paths"),
        (lambda: observer_statespace("a\0b"), "a path with a NUL character"),
    ):
        with pytest.raises(InputError, match=said):
            call()
    assert api.check_one(str(SPEC)).code == 0
    res = api.simulate(SPEC)
    for bad in (None, ""):
        with pytest.raises(InputError, match="plot path"):
            api.plot_simulation(SPEC, res, bad, atomic=False)
    # Path(""), a folder; spec_files of a 0-d array and of "" (re-check review 46)
    for bad in (Path(""), tmp_path):
        with pytest.raises(InputError, match="is a directory|empty path"):
            api.plot_simulation(SPEC, res, bad, atomic=False)
    for bad, said in ((tmp_path / "no" / "x.png", "cannot write"), (tmp_path / "x.zz", "unknown")):
        with pytest.raises(InputError, match=said):  # bare exceptions (re-check review 46)
            api.plot_simulation(SPEC, res, bad, atomic=False)
    assert api.spec_files(np.array(str(SPEC))) == [SPEC]
    with pytest.raises(InputError, match="spec_files: an empty path"):
        api.spec_files([""])


def test_check_rows_give_seconds_to_a_tenth_of_a_millisecond() -> None:
    """check --format json printed seconds as 0.000980008000624366 while sweep rounds to 4
    places (CLI review 46)."""
    row = api.check(SPEC)[0]
    assert row.seconds == round(row.seconds, 4)
    assert api.CheckRow("s", "m", 0, 0, 0, 0, "", 0.000980008000624366).seconds == 0.001


def test_unchecked_plots_write_temp_names_and_devices_and_leave_no_part(tmp_path: Path) -> None:
    """atomic=False is for a path the caller made (a mkstemp name, a device): those have no
    suffix and were refused as "unknown plot format '(no suffix)'"; a name too long was a
    bare OSError; a write that failed part-way left a half-written file (re-check review
    47). No suffix writes PNG; a file the call made is removed on failure."""
    import errno
    import os
    import tempfile

    res = api.simulate(SPEC)
    fd, tmp = tempfile.mkstemp(dir=tmp_path)
    os.close(fd)
    api.plot_simulation(SPEC, res, tmp, atomic=False)
    assert Path(tmp).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    api.plot_simulation(SPEC, res, os.devnull, atomic=False)
    with pytest.raises(InputError, match="cannot write"):
        api.plot_simulation(SPEC, res, tmp_path / ("n" * 300 + ".png"), atomic=False)
    with pytest.raises(InputError, match=r"unknown plot format '\.gif'"):
        api.plot_simulation(SPEC, res, tmp_path / "x.gif", atomic=False)

    def half(p: Path) -> None:  # a disk that fills up part-way
        p.write_bytes(b"\x89PNG" + b"0" * 100)
        raise OSError(errno.ENOSPC, "No space left on device")

    new = tmp_path / "new.png"
    with pytest.raises(InputError, match="No space left on device"):
        api._plot_to(new, half, atomic=False)
    assert not new.exists()
    with pytest.raises(InputError, match="the file may hold part of a plot"):
        api._plot_to(tmp, half, atomic=False)  # the caller's own file stays
    assert Path(tmp).exists()


def test_a_report_object_is_verified_under_the_limits_its_spec_was_read_under() -> None:
    """A spec read under max_digits = 3000 (a 1404-digit λ), designed after the limits were
    reset (or in a spawned process), gave design exit 0 and verify exit 2 for the same
    object: the embedded spec was re-read under the defaults (API review 46). A report
    object carries the limits its spec was read under (never into its file: a file is read
    under the limits in force)."""
    import dataclasses
    import pickle

    from obsdesign.errors import ObsdesignError, SpecError
    from obsdesign.limits import limits, reset_limits, set_limits
    from obsdesign.report.model import Report

    text = SPEC.read_text(encoding="utf-8").replace(
        "lambda = 0.955", "lambda = 0.955" + "0" * 1400 + "1"
    )
    old = set_limits(max_digits=3000)
    try:
        sp = api.load_spec_text(text, "long.toml")
    finally:
        reset_limits(old)
    assert limits().max_digits == 1000
    rep = api.design(sp)
    assert rep.exit_code() == 0 and api.verify(rep).exit_code() == 0
    assert api.verify(pickle.loads(pickle.dumps(rep))).exit_code() == 0  # a process's hand-off
    assert limits().max_digits == 1000  # raised for the call only
    with pytest.raises(ObsdesignError, match="1000"):  # a file: read under today's limits
        api.verify(Report.from_dict(rep.to_dict())[0])
    rep.spec_file = "long.toml"  # an object re-read under today's limits: the spec alone
    bare = dataclasses.replace(rep, read_limits=None)
    with pytest.raises(SpecError, match="above the limit of 1000"):
        api.verify(bare)
    assert "read_limits" not in rep.to_json()


def test_spec_files_in_a_removed_working_folder_is_the_folder_itself(tmp_path, monkeypatch) -> None:
    """``check .`` in a working folder removed since: exit 3 "internal failure:
    FileNotFoundError" for a while (the folder walk's real path; re-check review 47); the
    folder is its own row, as before."""
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    assert api.spec_files(".") == [Path(".")]
