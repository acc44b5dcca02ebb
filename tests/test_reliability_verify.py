"""`verify` compares what the report claims (issue 11 item 6): the recomputed claim list,
the verdict, the parameters (float = nearest double of the exact value) and the notes."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.certify.claim import ClaimStatus
from obsdesign.cli import app
from obsdesign.report.model import Report

SPEC = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
runner = CliRunner()


@pytest.fixture(scope="module")
def good() -> dict[str, Any]:
    return json.loads(api.design(SPEC).to_json())


def _verify(d: dict[str, Any]) -> Report:
    return api.verify(Report.from_dict(copy.deepcopy(d))[0])


def _failed(rep: Report) -> set[str]:
    return {c.id for c in rep.failed}


def test_untouched_report_verifies(good):
    rep = _verify(good)
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    assert rep.unverified == ["spectral_radius"]  # design information no check reads
    assert good["verdict"] == "ok"


def test_added_claim_fails(good):
    d = copy.deepcopy(good)
    d["claims"].append({**d["claims"][0], "id": "one-is-two", "statement": "1 = 2"})
    rep = _verify(d)
    assert _failed(rep) == {"report-adds:one-is-two"}
    assert rep.exit_code() == 1


@pytest.mark.parametrize("mark", ["\U000e0020", "\u034f", "\ufe0f", "\u3164", "\U0001d173"])
def test_an_added_claim_id_is_shown_in_ascii(good, mark: str) -> None:
    """A tag character, U+034F, U+FE0F or U+3164 appended to a claim id printed
    "report-adds:<id>" beside "report-omits:<id>", the two looking identical (re-check
    trial, session 35): the added id is shown in ASCII escapes."""
    d = copy.deepcopy(good)
    cid = d["claims"][0]["id"]
    d["claims"][0]["id"] = cid + mark
    failed = _failed(_verify(d))
    esc = mark.encode("ascii", "backslashreplace").decode("ascii")
    assert failed == {f"report-adds:{cid}{esc}", f"report-omits:{cid}"}
    assert all(x.isascii() for x in failed)


def test_duplicated_claim_fails(good):
    d = copy.deepcopy(good)
    d["claims"].append(copy.deepcopy(d["claims"][0]))
    assert _failed(_verify(d)) == {f"report-adds:{d['claims'][0]['id']}"}


def test_removed_claim_fails(good):
    d = copy.deepcopy(good)
    gone = d["claims"].pop(1)
    assert _failed(_verify(d)) == {f"report-omits:{gone['id']}"}


def test_all_claims_removed_fails(good):
    d = copy.deepcopy(good)
    ids = {c["id"] for c in d["claims"]}
    d["claims"] = []
    rep = _verify(d)
    assert _failed(rep) == {f"report-omits:{i}" for i in ids}
    assert rep.exit_code() == 1


def test_altered_statement_fails(good):
    d = copy.deepcopy(good)
    c = d["claims"][0]
    c["statement"] = c["statement"] + " (and more)"
    assert _failed(_verify(d)) == {f"report-alters:{c['id']}"}


def test_altered_status_fails(good):
    d = copy.deepcopy(good)
    c = d["claims"][0]
    c["status"] = "numerical"
    assert _failed(_verify(d)) == {f"report-alters:{c['id']}"}


def test_verify_only_claim_in_report_fails(good):
    d = copy.deepcopy(good)
    d["claims"].append({**d["claims"][0], "id": "parameters-consistent"})
    assert _failed(_verify(d)) == {"report-adds:parameters-consistent"}


def test_altered_verdict_fails(good):
    d = copy.deepcopy(good)
    d["verdict"] = "failed"
    assert _failed(_verify(d)) == {"report-verdict"}


def test_extra_parameter_is_not_verified(good):
    d = copy.deepcopy(good)
    d["parameters"]["certified_by"] = "NASA"
    d["parameters"]["gain"] = 1.5
    d["parameters"]["exact"]["gain"] = "3/2"
    rep = _verify(d)
    assert rep.exit_code() == 0
    assert {"certified_by", "gain"} <= set(rep.unverified)
    res = runner.invoke(app, ["verify", "-", "--format", "json"], input="")
    assert res.exit_code == 2  # '-' is not a file


def test_extra_parameter_flagged_in_text_output(good, tmp_path: Path):
    d = copy.deepcopy(good)
    d["parameters"]["gain"] = 1.5
    d["parameters"]["exact"]["gain"] = "3/2"
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d))
    res = runner.invoke(app, ["verify", str(p)])
    assert res.exit_code == 0
    row = next(line for line in res.output.splitlines() if " gain " in line)
    assert "not verified" in row and "exact" not in row
    j = json.loads(runner.invoke(app, ["verify", str(p), "--format", "json"]).output)
    assert "gain" in j["unverified_parameters"]


def test_injected_note_is_flagged(good):
    d = copy.deepcopy(good)
    d["notes"] = ["all claims independently audited by a third party"]
    rep = _verify(d)
    assert rep.exit_code() == 0
    assert rep.notes[0].startswith("not verified (from the report): all claims")
    assert not any(n.startswith("all claims") for n in rep.notes)


def test_float_one_ulp_off_fails(good):
    d = copy.deepcopy(good)
    x = d["parameters"]["P"][0][0]
    d["parameters"]["P"][0][0] = math.nextafter(x, math.inf)
    rep = _verify(d)
    assert _failed(rep) == {"parameters-consistent"}
    assert "nearest double" in rep.failed[0].detail and "'P'" in rep.failed[0].detail


def test_unknown_top_level_key_is_noted(good):
    d = copy.deepcopy(good)
    d["signature"] = "trust me"
    rep = _verify(d)
    assert rep.exit_code() == 0
    assert any("signature" in n for n in rep.notes)


def test_error_report_verifies_as_failed(good):
    d = copy.deepcopy(good)
    d.update(verdict="error", error={"exit_code": 1, "message": "not detectable"}, claims=[])
    d["parameters"] = {"exact": {}}
    rep = _verify(d)
    assert _failed(rep) == {"design-completed"} and rep.exit_code() == 1
    assert "not detectable" in rep.failed[0].detail


@pytest.mark.parametrize("verdict", ["great", "", None, 0])
def test_bad_verdict_value_is_refused(good, tmp_path: Path, verdict):
    d = copy.deepcopy(good)
    d["verdict"] = verdict
    if verdict is None:
        del d["verdict"]
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d))
    res = runner.invoke(app, ["verify", str(p)])
    assert res.exit_code == 2 and "verdict" in res.output


@pytest.mark.parametrize(
    ("spec", "key"),
    [
        ("constrained-redesign-sec5.toml", "v_min"),
        ("constrained-redesign-sec5-lyapunov.toml", "P"),
        ("astolfi-stubborn-example4.toml", "K"),
        # set-invariant's copy of the spec's λ: 1.0 is exactly 1, and a float-only λ was
        # compared by its double and verified (tamper review 46)
        ("dorea-pimenta-7-2.toml", "lambda"),
        ("dorea-pimenta-7-1.toml", "L_user"),
    ],
)
def test_verify_refuses_a_parameter_whose_exact_value_was_removed(
    spec: str, key: str, tmp_path: Path
) -> None:
    """Every method reads certified parameters exactly: a report whose exact value of
    ``key`` was deleted (its float kept) fails ``<key>-exact`` (exit 1) instead of being
    certified on the float's binary value (constrained, lyapunov and stubborn accepted it;
    fuzz report, session 17)."""
    rep = api.design(api.load_spec(Path(__file__).resolve().parents[1] / "specs" / spec))
    assert rep.exit_code() == 0
    d = rep.to_dict()
    del d["parameters"]["exact"][key]
    out = tmp_path / "r.json"
    out.write_text(json.dumps(d), encoding="utf-8")
    ver = api.verify(out)
    assert ver.exit_code() == 1
    assert any(c.id == f"{key}-exact" and not c.ok for c in ver.claims)


def test_a_spec_file_that_differs_from_the_embedded_spec_is_named(tmp_path: Path) -> None:
    """verify checks the embedded spec; a report whose embedded spec was edited (its hash
    updated) verified while the header named an unchanged file, for which the claims were
    false (review 21). A note now says the file differs and how to check against it; none
    when the file is the embedded text, is missing, or is not a regular file (a FIFO is
    not opened: no hang)."""
    import os

    spec = tmp_path / "s.toml"
    spec.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    rep = api.design(api.load_spec(spec))
    out = tmp_path / "r.json"
    out.write_text(rep.to_json(), encoding="utf-8")

    def moved(path: Path) -> list[str]:
        return [n for n in api.verify(path).notes if "differs from it" in n]

    assert moved(out) == []
    spec.write_text(SPEC.read_text(encoding="utf-8") + "# edited\n", encoding="utf-8")
    (note,) = moved(out)
    assert f"not the file {spec}" in note and f'--spec {spec}" checks' in note
    assert api.verify(out).exit_code() == 0  # a note, not a verdict
    r = CliRunner().invoke(app, ["verify", str(out)])
    assert r.exit_code == 0 and "differs from it" in r.output
    spec.unlink()
    assert moved(out) == []
    os.mkfifo(spec)
    assert moved(out) == []


def test_a_huge_integer_in_a_report_names_the_digit_limit(tmp_path: Path) -> None:
    """A 5000-digit integer in a report said "more than 4300 digits" (Python's int-string
    limit) beside the 1000 every other digit message names (outsider trial, session 22)."""
    from obsdesign import api
    from obsdesign.errors import InputError
    from obsdesign.report.model import Report

    spec = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    text = api.design(spec).to_json()
    p = tmp_path / "r.json"
    p.write_text(text.replace('"lambda": 0.955', '"lambda": ' + "7" * 5000, 1), encoding="utf-8")
    assert "7" * 5000 in p.read_text(encoding="utf-8")
    with pytest.raises(InputError, match="more than 1000 digits"):
        Report.load(p)


def test_an_error_in_the_embedded_spec_names_the_report(tmp_path: Path) -> None:
    """A broken embedded spec (sha256 updated) was reported against the report's spec_file
    ("s.toml: is not valid TOML") while s.toml on disk was fine (hostile-input trial,
    session 24): the message names the report and says the embedded spec is at fault."""
    import hashlib

    from obsdesign import api
    from obsdesign.errors import SpecError

    src = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    rep = api.design(src)
    d = rep.to_dict()
    d["spec"] = d["spec"].replace("[system]", "[system\n", 1)
    d["spec_sha256"] = hashlib.sha256(d["spec"].encode()).hexdigest()
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d))
    with pytest.raises(SpecError) as e:
        api.verify(p)
    msg = str(e.value)
    assert msg.startswith(f"{p}: the embedded spec (from ") and "is not valid TOML" in msg


def test_verify_says_what_is_wrong_with_claims_and_a_stdin_spec(tmp_path: Path) -> None:
    """A "claims" object gave "malformed claims (string indices must be integers, not
    'str')", and ``verify - --spec -`` said "-: no such spec file" (hostile-input trial,
    session 24): both now say what is expected."""
    from obsdesign import api
    from obsdesign.cli import app

    src = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    d = api.design(src).to_dict()
    d["claims"] = {"a": 1}
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d))
    res = CliRunner().invoke(app, ["verify", str(p)])
    assert res.exit_code == 2 and "key 'claims': expected a list of claim objects" in res.output
    res = CliRunner().invoke(app, ["verify", "-", "--spec", "-"], input="")
    assert res.exit_code == 2 and "--spec -: verify reads the spec from a file" in res.output


def test_a_huge_edited_statement_or_id_is_quoted_clipped() -> None:
    """A report's 4 MB statement (or 3 MB claim id) was echoed whole in the report-alters /
    report-adds detail, and rendering took 85 s (rendering trial, session 27): quoted to at
    most 2,000 characters, its length said; the verdict is unchanged (failed)."""
    d = api.design(SPEC).to_dict()
    d["claims"][0]["statement"] = "A " * 2_000_000
    ver = api.verify(Report.from_dict(d)[0])
    bad = [c for c in ver.claims if c.id.startswith("report-alters:")]
    assert ver.exit_code() == 1 and bad and len(bad[0].detail) < 5000
    assert "characters)" in bad[0].detail
    d["claims"][0]["statement"] = "P ≻ 0"
    d["claims"][0]["id"] = "x" * 3_000_000
    ver = api.verify(Report.from_dict(d)[0])
    adds = [c for c in ver.claims if c.id.startswith("report-adds:")]
    assert ver.exit_code() == 1 and adds
    assert len(adds[0].id) < 2100 and len(adds[0].detail) < 5000


def test_a_report_read_from_json_and_edited_in_memory_is_verified_as_edited(good):
    """verify(Report) took the parameters as read (for the bit-for-bit float check) even when
    the object was edited after reading: μ = 1 or λ_best = 0.9 set on a loaded report made
    certified claims false and verify said ok (API trial, session 33). An edited report is
    verified as edited; an unedited one still as read (a float one ulp off still fails)."""
    from flint import fmpq

    rep, _ = Report.from_dict(copy.deepcopy(good))
    assert api.verify(rep).exit_code() == 0
    rep.parameters["mu"] = fmpq(1)
    got = api.verify(rep)
    assert got.exit_code() == 1 and "iss-gain" in _failed(got), _failed(got)
    rep, _ = Report.from_dict(copy.deepcopy(good))
    rep.parameters["lambda_best"] = fmpq(9, 10)
    assert "decay-lmi_best" in _failed(api.verify(rep))
    d = copy.deepcopy(good)
    d["parameters"]["P"][0][0] = math.nextafter(d["parameters"]["P"][0][0], math.inf)
    rep, _ = Report.from_dict(d)
    assert _failed(api.verify(rep)) == {"parameters-consistent"}


def test_load_spec_text_takes_a_path_as_the_file_name(tmp_path: Path) -> None:
    """``load_spec_text(text, Path(...))`` kept the Path as the spec's file: ``design(out=)``
    was a bare TypeError (json cannot write a Path) and the error report could not be
    written either, so ``out`` kept an earlier run's report of another spec (API review,
    session 44). The path is taken as its str; a file name of another type is refused."""
    from obsdesign.errors import InputError

    text = SPEC.read_text("utf-8")
    out = tmp_path / "r.json"
    sp = api.load_spec_text(text, tmp_path / "named.toml")
    assert sp.file == str(tmp_path / "named.toml")
    assert api.design(sp, out=out).exit_code() == 0
    assert api.verify(out).exit_code() == 0
    with pytest.raises(InputError, match="file must be a str"):
        api.load_spec_text(text, 7)  # type: ignore[arg-type]
    from obsdesign.spec import read_spec_text  # the spec layer takes a Path too (session 44)

    assert read_spec_text(text, tmp_path / "raw.toml").file == str(tmp_path / "raw.toml")


def test_api_arguments_of_the_wrong_type_are_input_errors(tmp_path: Path) -> None:
    """``load_spec_text(bytes | None)``, ``design(123)``, ``verify({})`` and
    ``simulate(spec, bogus=3)`` raised bare TypeError / AttributeError from deep in the
    reader or the method (API trial, session 33): each is an :class:`InputError` naming
    the argument, and a misspelt simulate keyword gets a hint and the known ones."""
    from obsdesign.errors import InputError

    text = SPEC.read_text("utf-8")
    with pytest.raises(
        InputError,
        match=r"<spec>: expected the spec's text as a str, got a va"
        r"lue of type bytes \(decode it",
    ):
        api.load_spec_text(text.encode())
    with pytest.raises(InputError, match="of type NoneType"):
        api.load_spec_text(None)  # type: ignore[arg-type]
    assert api.load_spec_text(text).method == "lyapunov"
    with pytest.raises(InputError, match="spec: expected a path or a Spec, got .* int"):
        api.design(123)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="out: expected a path, got .* float"):
        api.design(SPEC, out=1.5)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="report: expected a path or a Report, got .* dict"):
        api.verify({})  # type: ignore[arg-type]
    out = tmp_path / "r.json"
    api.design(SPEC, out=out)
    with pytest.raises(InputError, match="spec: expected a path, got .* int"):
        api.verify(out, spec=7)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="report: expected a path or a Report, got .* int"):
        api.simulate(SPEC, report=5)  # type: ignore[arg-type]
    # certify took a path, a dict or a Report to a bare AttributeError (API review, 43)
    rep = api.design(SPEC)
    with pytest.raises(InputError, match="certify: spec must be a Spec .* got PosixPath"):
        api.certify(SPEC, rep.parameters)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="certify: params must be Parameters .* got Report"):
        api.certify(api.load_spec(SPEC), rep)  # type: ignore[arg-type]
    with pytest.raises(
        InputError,
        match=r"simulate: run: not an option of method 'lyapunov' \(did you mean 'runs'\?\) "
        r"\(known: batch, runs, span, time_limit\)",
    ):
        api.simulate(SPEC, run=3)
    assert api.simulate(SPEC, runs=2).metrics  # the known keywords still pass


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: api.design(str(SPEC) + "\0"), "spec: a path with a NUL character"),
        (
            lambda: api.simulate(SPEC, time_limit="x"),
            "simulate: time_limit: expected a finite number, got 'x'",
        ),
        (
            lambda: api.simulate(SPEC, time_limit=-1),
            "simulate: time_limit: expected a value >= 0.001, got -1",
        ),
        (
            lambda: api.simulate(SPEC, time_limit=float("nan")),
            "time_limit: expected a finite number, got nan",
        ),
        (lambda: api.check(None), "check: expected a path or a list of paths, got .* NoneType"),
        (lambda: api.check(123), "check: expected a path or a list of paths, got .* int"),
        (lambda: api.check([SPEC, 5]), "check: expected a path, got .* int"),
        (
            lambda: api.sweep(SPEC, {"method.lambda": [0.96]}, workers="2"),
            "--workers: expected a whole number of processes, got '2'",
        ),
        (
            lambda: api.sweep(SPEC, {"method.lambda": [0.96]}, simulate=True, options=[1]),
            "options: expected a mapping",
        ),
    ],
)
def test_the_api_refuses_bad_arguments_with_input_errors(call: Any, match: str) -> None:
    """Hostile-input trial, session 38: each was a bare ValueError / TypeError, a TimeExceeded
    (the exit-3 class) for time_limit=-1 where the CLI says exit 2, or ran without a limit
    (time_limit=nan). docs/reliability.md promises InputError."""
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match=match):
        call()


def test_the_api_still_takes_numpy_numbers_for_simulate_options() -> None:
    """The typed check of simulate keywords takes what worked before it (re-check trial,
    session 38): numpy numbers and booleans, Decimal, a text parsed as --option parses it,
    any value of a str option (theta_m=10), and check() of a numpy array or a set of paths;
    simulate(options=[1]) is an InputError (it was an AttributeError)."""
    from decimal import Decimal

    import numpy as np

    from obsdesign.errors import InputError

    r = api.simulate(SPEC, time_limit=np.float64(60), runs=np.int64(2))
    assert r.metrics
    assert api.simulate(SPEC, time_limit="60").metrics
    sec5 = SPEC.parent / "constrained-redesign-sec5.toml"
    assert api.simulate(sec5, theta_m=10, gamma=Decimal("17"), time_limit=Decimal(60)).metrics
    hg = SPEC.parent / "hernandez-garcia-example.toml"
    assert api.simulate(hg, progress=np.bool_(False)).metrics
    assert len(api.check(np.array([str(SPEC)]))) == 1 == len(api.check({str(SPEC)}))
    with pytest.raises(InputError, match="options: expected a mapping"):
        api.simulate(sec5, options=[1])
    with pytest.raises(InputError, match="simulate: time_limit: expected a finite number"):
        api.simulate(SPEC, time_limit="soon")
    # second re-check: beyond the float range or a signalling NaN were bare errors; whole
    # numbers written as floats, 0 / 1 for true / false, a 0-d array and dict keys are taken
    from fractions import Fraction

    for bad in (10**400, -(10**400), Fraction(10**400), Decimal("sNaN")):
        with pytest.raises(InputError, match="simulate: gamma: expected a finite number"):
            api.simulate(sec5, gamma=bad)
    assert api.simulate(hg, max_centres=100000.0, progress=0).metrics
    assert api.simulate(sec5, gamma=np.array(17.0), theta_m="10").metrics
    assert len(api.check({str(SPEC): 1}.keys())) == 1 == len(api.check(np.array(str(SPEC))))
    with pytest.raises(InputError, match="check: no paths given"):
        api.check(set())


# -- mutation review 34 (session 33's checks) ----------------------------------------
LYAP = (
    '[system]\ntime = "continuous"\nA = [[-1, 1], [0, -2]]\nC = [[1, 0]]\n'
    '[method]\nkey = "lyapunov"\nL = [1, 0]\n'
    "[simulate]\nhorizon = H\ndt = DT\nx0 = [1, 0]\nxhat0 = [0, 0]\n"
)


def test_sim_grid_steps_rounds_the_exact_quotient() -> None:
    """Kills A03 (int of the float quotient): 0.3 / 0.1 is 2.9999999999999996 in floats, but
    the grid time_grid builds has 3 steps (the exact quotient rounded to the nearest)."""
    sp = api.load_spec_text(LYAP.replace("H", "0.3").replace("DT", "0.1"), "s.toml")
    assert 0.3 / 0.1 < 3
    assert api.sim_grid_steps(sp) == 3
    sp = api.load_spec_text(LYAP.replace("H", "1").replace("DT", "0.4"), "s.toml")
    assert api.sim_grid_steps(sp) == 3  # 2.5 rounds half up (steps_of)


def test_a_report_whose_parameters_lost_a_key_is_verified_as_edited() -> None:
    """Kills A11 (no key-set comparison in _unchanged_since_read: the loop over the keys as
    read looked up the missing one in the edited parameters, a KeyError out of verify). A
    report read from JSON whose parameters are replaced without μ is verified as edited:
    exit 1 with "mu missing"."""
    import copy
    import json

    from obsdesign.params import Parameters
    from obsdesign.report.model import Report

    spec = SPEC
    good = json.loads(api.design(spec).to_json())
    rep, _ = Report.from_dict(copy.deepcopy(good))
    rep.parameters = Parameters({k: v for k, v in rep.parameters.items() if k != "mu"})
    got = api.verify(rep)
    assert got.exit_code() == 1
    assert "mu-present" in {c.id for c in got.failed}


def _lyap_report() -> dict:
    from obsdesign import api

    src = Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5-lyapunov.toml"
    return api.design(src).to_dict()


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (
            lambda c: c.__setitem__("extra", "x"),
            "claims[1] (ID): key 'extra': expected an object, got a string",
        ),
        (lambda c: c.pop("status"), "claims[1] (ID): key 'status' is missing"),
        (lambda c: c.__setitem__("status", "proved"), "key 'status': expected one of certified"),
        (lambda c: c.__setitem__("status", 1), "key 'status': expected one of"),
        (
            lambda c: c.__setitem__("float_ok", "yes"),
            "key 'float_ok': expected true, false or null",
        ),
        (lambda c: c.pop("id"), "claims[1]: key 'id' is missing"),
    ],
    ids=["extra-string", "no-status", "unknown-status", "numeric-status", "float-ok", "no-id"],
)
def test_a_malformed_claim_is_named_with_its_key(tmp_path: Path, edit: Any, words: str) -> None:
    """ "malformed claims ('status')" and "malformed claims (dictionary update sequence element
    #0 has length 1; 2 is required)" named neither the claim nor the key (verify trial,
    session 35)."""
    from obsdesign.cli import app

    d = _lyap_report()
    cid = d["claims"][1]["id"]
    edit(d["claims"][1])
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d))
    res = CliRunner().invoke(app, ["verify", str(p)])
    assert res.exit_code == 2, res.output
    assert words.replace("ID", cid) in res.output, res.output


@pytest.mark.parametrize(
    "version", ["1.x", "1", "1.-1", "1.1.1", "1.1\n", " 1.1", "01.1", "1.01", "١.١"]
)
def test_schema_version_is_major_dot_minor(tmp_path: Path, version: str) -> None:
    """Only the part before the first dot was compared: "1.x", "1", "1.1.1" and "1.1\\n"
    verified while "01.1" was refused (verify trial, session 35). MAJOR.MINOR in ASCII digits,
    no leading zeros, or exit 2; 1.0 and 1.1 still read."""
    from obsdesign.cli import app

    d = _lyap_report()
    d["schema_version"] = version
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d))
    res = CliRunner().invoke(app, ["verify", str(p)])
    assert res.exit_code == 2 and "schema_version must be MAJOR.MINOR" in res.output, res.output
    for minor in ("1.1", "1.2"):  # any 1.x is read (docs/spec.md)
        d["schema_version"] = minor
        p.write_text(json.dumps(d))
        assert CliRunner().invoke(app, ["verify", str(p)]).exit_code == 0
    d["schema_version"] = "2.1"  # the message said "(expected 1.1)" while 1.2 read
    p.write_text(json.dumps(d))
    res = CliRunner().invoke(app, ["verify", str(p)])
    assert res.exit_code == 2 and "(this tool reads 1.x reports and writes 1.1)" in res.output


def test_an_upper_case_spec_hash_says_so_and_a_bool_exact_value_reads_once(tmp_path: Path) -> None:
    """An upper-case spec_sha256 failed spec-hash with two identical-looking 12-digit
    prefixes; a boolean exact value said "not an exact value (not an exact value: True)"
    (verify trial, session 35)."""
    from obsdesign import api
    from obsdesign.cli import app

    d = _lyap_report()
    d["spec_sha256"] = d["spec_sha256"].upper()
    ver = api.verify(Report.from_dict(d)[0])
    (c,) = [c for c in ver.claims if c.id == "spec-hash"]
    assert c.status == ClaimStatus.FAILED and "upper case" in c.detail
    d = _lyap_report()
    d["spec_sha256"] = (
        d["spec_sha256"][:12]
        + ("0" if d["spec_sha256"][12] != "0" else "1")
        + d["spec_sha256"][13:]
    )
    ver = api.verify(Report.from_dict(d)[0])
    (c,) = [c for c in ver.claims if c.id == "spec-hash"]
    assert c.status == ClaimStatus.FAILED and d["spec_sha256"] in c.detail  # whole, not a prefix
    d = _lyap_report()
    key = next(iter(d["parameters"]["exact"]))
    d["parameters"]["exact"][key] = True
    p = tmp_path / "r.json"
    p.write_text(json.dumps(d))
    res = CliRunner().invoke(app, ["verify", str(p)])
    assert res.exit_code == 2 and f"parameters.exact.{key}: not an exact value (True)" in res.output


def test_simulate_refuses_a_report_verify_refuses_first(tmp_path: Path) -> None:
    """``simulate SPEC --report R`` compared only the spec's sha256 with the report's: a report
    whose method was edited (verify: exit 2), or whose embedded spec text was replaced
    (verify: exit 1, spec-hash), ran with exit 0 (tamper review 45). Both are bad input for
    simulate now, naming the report; the honest report runs."""
    rep = api.design(SPEC)
    good = tmp_path / "good.json"
    good.write_text(rep.to_json(), encoding="utf-8")
    r = CliRunner().invoke(app, ["simulate", str(SPEC), "--report", str(good), "-q"])
    assert r.exit_code == 0, r.output
    other = (SPEC.parent / "constrained-redesign-sec5.toml").read_text(encoding="utf-8")
    for edit, want in (
        (lambda d: d.update(method="stubborn"), "method 'stubborn' but the spec says 'lyapunov'"),
        (lambda d: d.update(spec=other), "its embedded spec is not the one its spec_sha256 names"),
    ):
        d = json.loads(rep.to_json())
        edit(d)
        bad = tmp_path / "bad.json"
        bad.write_text(json.dumps(d), encoding="utf-8")
        assert CliRunner().invoke(app, ["verify", str(bad), "-q"]).exit_code in (1, 2)
        r = CliRunner().invoke(app, ["simulate", str(SPEC), "--report", str(bad), "-q"])
        assert r.exit_code == 2 and want in r.stderr and str(bad) in r.stderr, r.output


def test_verify_json_output_is_strict_json_whatever_the_report_holds(tmp_path: Path) -> None:
    """A report with 1e400 (valid JSON, read as inf) or NaN in an unread parameter, its tool
    or its timings: verify --format json printed Infinity / NaN, which strict JSON readers
    refuse (tamper review 45). Non-finite values are written as their text; a report of the
    tool's own is written unchanged."""
    rep = api.design(SPEC)
    plain = json.loads(rep.to_json())
    assert json.loads(rep.to_json(), parse_constant=_refuse) == plain
    text = rep.to_json().replace('"parameters": {', '"parameters": {\n"odd_extra": 1e400,', 1)
    text = text.replace('"timings": {', '"timings": {"odd": NaN, ', 1)
    assert "1e400" in text and "NaN" in text
    bad = tmp_path / "bad.json"
    bad.write_text(text, encoding="utf-8")
    r = CliRunner().invoke(app, ["verify", str(bad), "--format", "json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout, parse_constant=_refuse)
    assert out["parameters"]["odd_extra"] == "inf"


def _refuse(c: str) -> Any:
    """json's parse_constant for a strict reader: NaN and ±Infinity are not JSON."""
    raise ValueError(f"not JSON: {c}")


def test_verify_with_spec_checks_the_embedded_spec_too(tmp_path: Path) -> None:
    """A report whose embedded spec had its A edited (spec_sha256 left as designed):
    ``verify R`` failed spec-hash, but ``verify R --spec SPEC`` hashed only the file and
    said ok, its JSON output embedding the edited plant (re-check review 45). Both fail
    spec-hash now; the honest report verifies either way."""
    rep = api.design(SPEC)
    good = tmp_path / "good.json"
    good.write_text(rep.to_json(), encoding="utf-8")
    assert api.verify(good, spec=SPEC).exit_code() == 0
    d = json.loads(rep.to_json())
    assert "A = [[0, 1], [1, 0]]" in d["spec"]
    d["spec"] = d["spec"].replace("A = [[0, 1], [1, 0]]", "A = [[0, 1], [1, 0.5]]")
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d), encoding="utf-8")
    for kw in ({}, {"spec": SPEC}):
        ver = api.verify(bad, **kw)
        assert ver.exit_code() == 1 and [c.id for c in ver.failed] == ["spec-hash"], kw
    detail = api.verify(bad, spec=SPEC).failed[0].detail
    assert detail.startswith("the embedded spec has sha256"), detail


def test_a_parameter_past_the_float_range_is_a_failed_claim_not_an_exception() -> None:
    """A set-invariant G with an entry of 10**400: api.certify, documented as never raising
    for malformed parameters, raised a bare OverflowError converting it to a float (API
    review 45). It is the failed parameters-wellformed claim."""
    from obsdesign.params import Parameters

    sp = api.load_spec(SPEC.parent / "dorea-pimenta-7-1.toml")
    rep = api.design(sp)
    p = Parameters(dict(rep.parameters.items()))
    G = p["G"].copy()
    G.flat[-1] = 10**400
    p["G"] = G
    claims = api.certify(sp, p)
    bad = [c for c in claims if c.status is ClaimStatus.FAILED]
    assert [c.id for c in bad] == ["parameters-wellformed"] and "OverflowError" in bad[0].detail


def test_a_malformed_report_object_is_bad_input_for_verify_and_simulate() -> None:
    """Report objects built or edited by hand — parameters a plain dict, claims as dicts, an
    exact array holding None, an int parameter key, extra_keys that are not strings — made
    api.verify and api.simulate raise bare TypeErrors and AttributeErrors (API review 45):
    an InputError (exit 2) naming the report."""
    import dataclasses

    import numpy as np

    from obsdesign.errors import InputError
    from obsdesign.params import Parameters

    sp = api.load_spec(SPEC)
    rep = api.design(sp)
    L = np.array(rep.parameters["L"], dtype=object)
    L.flat[-1] = None
    odd = {
        "parameters=dict": dataclasses.replace(rep, parameters=dict(rep.parameters.items())),
        "claims=dicts": dataclasses.replace(rep, claims=[c.to_dict() for c in rep.claims]),
        "None in L": dataclasses.replace(
            rep, parameters=Parameters({**dict(rep.parameters.items()), "L": L})
        ),
        "int key": dataclasses.replace(
            rep, parameters=Parameters({**dict(rep.parameters.items()), 1: 0.5})
        ),
        "extra_keys": dataclasses.replace(rep, extra_keys=[1, None]),
        # a lone surrogate in the spec text: a bare UnicodeEncodeError at its hash (45)
        "surrogate": dataclasses.replace(rep, spec=rep.spec + "# \ud800\n"),
    }
    for name, r in odd.items():
        for call in (lambda r=r: api.verify(r), lambda r=r: api.simulate(sp, r)):
            with pytest.raises(
                InputError, match="report: (not a well-formed|its spec holds a string)"
            ):
                call()
        assert name
    assert api.verify(rep).exit_code() == 0


def test_verify_says_which_tool_verified_a_report_of_another_tool() -> None:
    """verify's output kept the input report's tool field — any name or version, or {} —
    beside the claims this tool recomputed, with no word of which tool verified (tamper
    review 45): a note says so when the field is not this obsdesign's; the tool's own
    reports get no such note."""
    from obsdesign import __version__

    rep = api.design(SPEC)
    assert not any(n.startswith("verified by obsdesign") for n in api.verify(rep).notes)
    for tool in (
        {},
        {"name": "obsdesign", "version": "9.9"},
        {"name": "other", "version": __version__},
    ):
        d = json.loads(rep.to_json())
        d["tool"] = tool
        r, _ = Report.from_dict(d)
        ver = api.verify(r)
        assert ver.exit_code() == 0
        assert f"verified by obsdesign {__version__}; the report's tool field" in " ".join(
            ver.notes
        )


def test_the_not_verified_note_names_at_most_fifty_parameters() -> None:
    """A report with 100,000 unread parameters made verify's "not verified" note ~14,000
    lines (CLI review 45): it names the first NOTE_NAMES and counts the rest."""
    rep = api.design(SPEC)
    d = json.loads(rep.to_json())
    d["parameters"].update({f"extra_{i}": i for i in range(60)})
    r, _ = Report.from_dict(d)
    ver = api.verify(r)
    note = next(n for n in ver.notes if n.startswith("not verified (no check reads them"))
    unread = len(ver.unverified)
    assert unread > api.NOTE_NAMES == 50
    assert note.endswith(f" and {unread - 50:,} more") and "extra_59" not in note, note


def test_verify_with_a_crlf_copy_of_the_spec_says_why_the_hash_differs(tmp_path: Path) -> None:
    """``verify R --spec COPY`` with COPY the spec converted to CRLF (or given a BOM) said only
    that the sha256 differs (CLI review 45): the detail says the two differ only in line
    endings or a byte-order mark; an edited copy gets no such words."""
    rep = api.design(SPEC)
    text = SPEC.read_text(encoding="utf-8")
    for name, copied in (
        ("crlf.toml", text.replace("\n", "\r\n")),
        ("bom.toml", "\ufeff" + text),
        ("edited.toml", text.replace("lambda = 0.955", "lambda = 0.96")),
    ):
        p = tmp_path / name
        p.write_bytes(copied.encode("utf-8"))
        ver = api.verify(rep, spec=p)
        assert ver.exit_code() == 1 and [c.id for c in ver.failed] == ["spec-hash"]
        said = "differ only in line endings or a byte-order mark" in ver.failed[0].detail
        assert said == (name != "edited.toml"), (name, ver.failed[0].detail)


def test_simulate_with_a_crlf_copy_of_the_spec_says_why_the_hash_differs(tmp_path: Path) -> None:
    """``simulate COPY --report R`` with COPY the spec converted to CRLF said only that the
    sha256 differs, while verify --spec says why (tamper review 46); an edited copy gets no
    such words. Both are exit 2."""
    from obsdesign.errors import InputError

    rep = api.design(SPEC)
    text = SPEC.read_text(encoding="utf-8")
    for name, copied in (
        ("crlf.toml", text.replace("\n", "\r\n")),
        ("edited.toml", text.replace("lambda = 0.955", "lambda = 0.96")),
    ):
        p = tmp_path / name
        p.write_bytes(copied.encode("utf-8"))
        with pytest.raises(InputError, match="made from another spec") as ei:
            api.simulate(p, rep)
        said = "differ only in line endings or a byte-order mark" in str(ei.value)
        assert said == (name == "crlf.toml") and ei.value.exit_code == 2, str(ei.value)


def test_the_differs_note_finds_a_spec_whose_name_is_not_utf8(tmp_path: Path) -> None:
    """A report names a spec file whose name is not UTF-8 with each such byte as \\xNN; the
    note "that file differs" looked up that text, found no file, and said nothing after the
    file was edited (re-check review 46). The name is read back to its bytes."""
    import os

    name = tmp_path / os.fsdecode(b"b\xffd.toml")
    name.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    out = tmp_path / "r.json"
    api.design(api.load_spec(name), out=out)
    assert "\\xff" in json.loads(out.read_text(encoding="utf-8"))["spec_file"]
    assert not [n for n in api.verify(out).notes if "differs from it" in n]
    with open(name, "a", encoding="utf-8") as f:
        f.write("# edited\n")
    notes = [n for n in api.verify(out).notes if "differs from it" in n]
    assert notes and "holds bytes that are not UTF-8" in notes[0]


@pytest.mark.parametrize(
    "name",
    [
        b"my spec.toml",
        b"it's.toml",
        b"$(echo hi).toml",
        b"d\xff/s.toml",
        b"e\xfe/'x y.toml",
        b"a\\tb/s\xff.toml",  # a backslash in the folder's name: read back as a TAB (47)
    ],
)
def test_the_differs_note_gives_a_command_a_shell_reads_back(tmp_path: Path, name: bytes) -> None:
    """The note's "obsdesign verify REPORT --spec FILE" named the file unquoted: a space
    split it, an apostrophe left a quote open, "$(…)" ran when pasted (the name comes from
    the report); a folder whose name is not UTF-8 got no hint (re-check review 47). The
    argument, as bash reads it, is the file's path, byte for byte."""
    import os
    import re
    import shutil
    import subprocess

    path = tmp_path / os.fsdecode(name)
    path.parent.mkdir(exist_ok=True)
    path.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    out = tmp_path / "r.json"
    api.design(api.load_spec(path), out=out)
    with open(path, "a", encoding="utf-8") as f:
        f.write("# edited\n")
    (note,) = [n for n in api.verify(out).notes if "differs from it" in n]
    arg = re.search(r'"obsdesign verify REPORT --spec (.*)" checks', note).group(1)
    assert ("not UTF-8" in note) == (b"\xff" in name or b"\xfe" in name), note
    bash = shutil.which("bash")
    if bash is None:  # pragma: no cover - Debian has bash
        pytest.skip("no bash to read the command back")
    got = subprocess.run([bash, "-c", f"printf %s {arg}"], capture_output=True, check=True)
    assert got.stdout == os.fsencode(path)
