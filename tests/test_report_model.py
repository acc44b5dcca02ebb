"""Report model, JSON round trip, verdicts and atomic writes (obsdesign.report)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from flint import fmpq

from obsdesign.certify.claim import Claim, ClaimStatus, exact_claim, numerical_claim
from obsdesign.certify.exact import qmat
from obsdesign.errors import InputError
from obsdesign.params import Parameters
from obsdesign.report.model import Report, write_atomic
from obsdesign.report.render import render_markdown


def _report(claims: list[Claim]) -> Report:
    return Report(
        "lyapunov",
        "spec text",
        "s.toml",
        "0" * 64,
        Parameters({"P": qmat([[2, 1], [1, 2]]), "lambda": fmpq(191, 200), "it": 3}),
        claims,
    )


def _c(ok: bool, float_ok: bool | None = None) -> Claim:
    return exact_claim("c", "s", "ref", "exact", 0, ok, "", float_ok)


def test_exit_codes():
    assert (
        _report([_c(True), numerical_claim("n", "s", "r", "float", 0, True, "")]).exit_code() == 0
    )
    assert _report([_c(True), _c(False)]).exit_code() == 1
    assert _report([_c(False, float_ok=True)]).exit_code() == 4  # inconclusive
    assert _report([_c(False, float_ok=True), _c(False, float_ok=False)]).exit_code() == 1


def test_json_round_trip_keeps_exact_values():
    r = _report([_c(True)])
    d = json.loads(r.to_json())
    assert d["parameters"]["exact"]["P"] == [["2", "1"], ["1", "2"]]
    assert d["parameters"]["exact"]["lambda"] == "191/200"
    assert d["parameters"]["it"] == 3 and "it" not in d["parameters"]["exact"]
    back, problems = Report.from_dict(d)
    assert problems == []
    assert back.parameters["lambda"] == fmpq(191, 200)
    assert (back.parameters["P"] == r.parameters["P"]).all()
    assert back.claims[0].status == ClaimStatus.CERTIFIED


def test_edited_float_is_reported():
    d = json.loads(_report([]).to_json())
    d["parameters"]["lambda"] = 0.9
    _, problems = Report.from_dict(d)
    assert problems and "lambda" in problems[0]


@pytest.mark.parametrize(
    "bad",
    [
        [],
        {"schema_version": "1.0"},
        {  # a numeric schema_version (1.1 was read as "1.1")
            "schema_version": 1.1,
            "method": "x",
            "spec": "",
            "spec_sha256": "",
            "parameters": {},
            "claims": [],
            "verdict": "ok",
        },
        {
            "schema_version": "9",
            "method": "x",
            "spec": "",
            "spec_sha256": "",
            "parameters": {},
            "claims": [],
        },
    ],
)
def test_malformed_reports(bad):
    with pytest.raises(InputError):
        Report.from_dict(bad)


def test_write_atomic_leaves_nothing_on_failure(tmp_path: Path, monkeypatch):
    target = tmp_path / "r.json"
    write_atomic(target, "first")
    assert target.read_text() == "first\n"

    def boom(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(InputError, match="disk full"):
        write_atomic(target, "second")
    assert target.read_text() == "first\n"  # old content intact
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json"]  # no temp file left


def test_markdown_renders_claims():
    md = render_markdown(_report([_c(True), _c(False)]))
    assert "| c | **certified** |" in md and "**failed**" in md
    assert np.isfinite(1.0)


@pytest.mark.parametrize("code", [1, 3, 4, 0, 2, -1, -9, 5, 130, 141, 10**11, 10**100])
def test_an_error_report_carries_only_a_design_stop_code(code: int) -> None:
    """verify exits with an error report's exit_code, so only the codes a stopped design
    writes (1, 3, 4) are accepted; anything else is bad input naming error.exit_code (the
    report fuzz made verify exit 255, 247, 141 or 130 by editing it)."""
    rep = Report("lyapunov", "spec text", "s.toml", "0" * 64, Parameters(), [])
    d = rep.to_dict()
    d["verdict"], d["error"] = "error", {"exit_code": code, "message": "stopped"}
    if code in (1, 3, 4):
        back, _ = Report.from_dict(d)
        assert back.exit_code() == code
    else:
        with pytest.raises(InputError, match=r"key 'error.exit_code': expected one of 1, 3, 4"):
            Report.from_dict(d)


@pytest.mark.parametrize("where", ["top", "nested"])
def test_a_report_with_a_repeated_key_is_refused(tmp_path: Path, where: str) -> None:
    """A key twice in one JSON object (Python keeps the last copy, other readers the first):
    exit 2 naming the key (a duplicated "spec_sha256" or "claims" verified silently: report
    fuzz, review 19). The same report without the repeat loads."""
    text = _report([_c(True)]).to_json()
    Report.load(_write(tmp_path / "ok.json", text))
    if where == "top":
        bad = text.replace('"method":', '"method": "stubborn", "method":', 1)
        key = "method"
    else:
        bad = text.replace('"exact": {', '"exact": {"it": "4",', 1).replace(
            '"it": 3', '"it": 3, "it": 4', 1
        )
        key = "it"
    with pytest.raises(InputError, match=f"key '{key}' appears twice in one JSON object"):
        Report.load(_write(tmp_path / "bad.json", bad))


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    "value",
    [
        fmpq(10**400),
        fmpq(1, 10**400),  # underflows to 0.0: a float view exists
        10**400,
        np.array([fmpq(1), fmpq(10**400, 3)], dtype=object),
        np.array([fmpq(1, 3), fmpq(-(2**1023) * 3, 2)], dtype=object),  # rounds past the range
        np.array([fmpq(2**1023 * 2 - 2**970, 1), fmpq(1)], dtype=object),  # the largest double
        np.array([fmpq(1, 10**400)], dtype=object),
        [fmpq(10**400)],  # anything unusual: the JSON form decides
    ],
)
def test_check_float_view_agrees_with_the_float_view(value) -> None:
    """design checks the float view without building it (numpy's float conversion, ~10×
    faster than the JSON strings at n = 100, session 24): it must raise exactly when
    :meth:`Report.float_view` does, with the same exit-4 message."""
    from obsdesign.errors import InconclusiveError
    from obsdesign.params import Parameters

    rep = Report(
        method="lyapunov",
        spec="",
        spec_file="s.toml",
        spec_sha256="",
        parameters=Parameters({"x": value}),
        claims=[],
    )
    try:
        rep.float_view()
        want = None
    except InconclusiveError as e:
        want = e.message
    try:
        rep.check_float_view()
        got = None
    except InconclusiveError as e:
        got = e.message
    assert (got is None) == (want is None)
    if want is not None:
        assert "parameter 'x'" in got and "float view" in got


@pytest.mark.parametrize("where", ["probe", "write"])
def test_a_stop_as_the_temp_file_appears_leaves_no_file(tmp_path: Path, where: str) -> None:
    """A stop signal (here SIGUSR1 with the CLI's handler, interrupt.handler, which it
    installs for SIGTERM and the other stop signals) that lands right after a temp file is
    created: the probe of the output folder and write_via's temp file were left behind (4 of
    25 ``design -o`` runs under SIGTERM; CLI trial, session 40). Deferred during creation and
    cleanup, the stop is raised inside the block that removes the file."""
    import signal

    from obsdesign import interrupt
    from obsdesign.report import model as m

    real = m._temp_file

    def created_then_stopped(*a: Any, **k: Any) -> tuple[int, str]:
        out = real(*a, **k)
        os.kill(os.getpid(), signal.SIGUSR1)  # delivered now, or held until the block ends
        return out

    old = signal.signal(signal.SIGUSR1, interrupt.handler)
    interrupt.reset()
    try:
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(m, "_temp_file", created_then_stopped)
            with pytest.raises(KeyboardInterrupt):
                if where == "probe":
                    m._probe_dir(tmp_path / "r.json")
                else:
                    m.write_via(tmp_path / "r.json", lambda p: p.write_text("{}"))
    finally:
        signal.signal(signal.SIGUSR1, old)
        assert interrupt.requested()
        interrupt.reset()
    assert sorted(os.listdir(tmp_path)) == []


def test_a_report_with_a_byte_order_mark_gets_a_sentence(tmp_path: Path) -> None:
    """A report file starting with a UTF-8 BOM said Python's hint "Unexpected UTF-8 BOM
    (decode using utf-8-sig)" (tamper review 46); it says what a spec with one is told."""
    from obsdesign import api
    from obsdesign.errors import InputError

    spec = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    p = tmp_path / "bom.json"
    p.write_text("\ufeff" + api.design(api.load_spec(spec)).to_json(), encoding="utf-8")
    with pytest.raises(InputError, match="starts with a byte-order mark") as e:
        api.verify(p)
    assert "utf-8-sig" not in str(e.value)


@pytest.mark.parametrize(("flag", "word"), [("+a", "append-only"), ("+i", "immutable")])
def test_an_append_only_or_immutable_output_is_refused_before_any_work(
    tmp_path: Path, flag: str, word: str
) -> None:
    """os.access allows writing to an append-only file (chattr +a), but a rename cannot
    replace it: sweep, check and design did all their work, then exit 2 "cannot write
    (Operation not permitted)" and the rows were lost (CLI review 46). Refused up front, even
    with --force (the flag is the file's own). Skipped where chattr does not work (tmpfs,
    no CAP_LINUX_IMMUTABLE)."""
    import shutil
    import subprocess

    from obsdesign.errors import InputError
    from obsdesign.report.model import check_output

    out = tmp_path / "out.json"
    out.write_text("{}", encoding="utf-8")
    chattr = shutil.which("chattr")
    if chattr is None or subprocess.run([chattr, flag, str(out)]).returncode != 0:
        pytest.skip("chattr is not available here")
    try:
        for force in (False, True):
            with pytest.raises(InputError, match=f"out.json: is {word}: it cannot be replaced"):
                check_output(out, force, ())
    finally:
        subprocess.run([chattr, "-" + flag[1:], str(out)], check=True)
    check_output(out, False, ())  # a plain file again


def test_an_append_only_folder_is_refused_before_any_work(tmp_path: Path) -> None:
    """A folder with chattr +a takes new files but no rename or removal: the probe file and
    the finished temp file were left in it, and the refusal came after the work (re-check
    review 46). Refused up front, nothing left."""
    import shutil
    import subprocess

    from obsdesign.errors import InputError
    from obsdesign.report.model import check_output

    folder = tmp_path / "ad"
    folder.mkdir()
    chattr = shutil.which("chattr")
    if chattr is None or subprocess.run([chattr, "+a", str(folder)]).returncode != 0:
        pytest.skip("chattr is not available here")
    try:
        with pytest.raises(InputError, match="the folder is append-only"):
            check_output(folder / "r.json", False, ())
        assert list(folder.iterdir()) == []
    finally:
        subprocess.run([chattr, "-a", str(folder)], check=True)
