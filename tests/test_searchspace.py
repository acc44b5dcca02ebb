"""search-space method (Hernández & García, paper 004): the example's certified numbers, and
for every claim id a tampered report (or spec) that makes exactly that claim fail."""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import re
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from flint import fmpq
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.certify import interval as I
from obsdesign.certify import interval as ivq
from obsdesign.certify.claim import Claims, ClaimStatus
from obsdesign.certify.exact import Q
from obsdesign.certify.interval import iv
from obsdesign.cli import app
from obsdesign.errors import InfeasibleError, InputError, SpecError
from obsdesign.methods import get_method
from obsdesign.methods.searchspace import claims as C
from obsdesign.methods.searchspace import design as D
from obsdesign.params import Parameters

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "hernandez-garcia-example.toml"
TEXT = SPEC.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def example():
    sp = api.load_spec(SPEC)
    rep = api.design(sp)
    return sp, rep


def test_example_numbers_exact(example):
    sp, rep = example
    p = rep.parameters
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims), [
        (c.id, c.detail) for c in rep.failed
    ]
    assert p["L_f"] == 1 and p["L_h"] == 1
    assert p["f_sup"] == fmpq(353554, 100000)  # 2.5·√2 = 3.5355339… rounded up to 6 digits
    assert p["kappa"] == fmpq(3, 2)
    assert p["dT"] == fmpq(9, 10) * fmpq(1, 20) / (2 * p["f_sup"]) == fmpq(1125, 176777)
    assert p["K"] == 63  # 63·ΔT = 0.40093 < log 1.5 = 0.405465 < 64·ΔT
    assert p["eps_star"] == fmpq(1, 30)
    g = list(p["gamma_schedule"])
    assert len(g) == 12 and g[0] == 1 and g[-1] == fmpq(1, 20)
    assert all(a > b for a, b in zip(g, g[1:], strict=False))
    ids = [c.id for c in rep.claims]
    assert ids == [
        "input-range",
        "D-in-E",
        "L_h-bound",
        "L_f-bound",
        "f_sup-bound",
        "kappa-range",
        "gamma0-above-star",
        "dT-rule",
        "lemma1-discarding",
        "dtau-rule",
        "K-rule",
        "lemma2-consistency",
        "gamma-schedule",
        "eps-schedule",
        "eps-star",
    ]


def test_verify_roundtrip(example, tmp_path):
    _, rep = example
    out = tmp_path / "r.json"
    out.write_text(rep.to_json())
    ver = api.verify(out)
    assert ver.exit_code() == 0
    assert [(c.id, c.statement, c.status) for c in ver.claims] == [
        (c.id, c.statement, c.status) for c in rep.claims
    ]


def test_printed_numbers_are_true(example):
    """Every number printed in a statement is exact or rounded to the safe side."""
    sp, rep = example
    p = rep.parameters
    st = {c.id: c.statement for c in rep.claims}
    m = re.search(r"log\(κ/L_h\^E\)/L_f\^E ≥ ([0-9.]+)", st["lemma2-consistency"])
    assert m and Q(m.group(1)) <= ivq.log_lower(p["kappa"] / p["L_h"]) / p["L_f"]
    m = re.search(r"‖f_u‖_E\) = ([0-9/]+)", st["dT-rule"])
    assert m and Q(m.group(1)) == p["dT"]
    m = re.search(r"\(‖f_u‖_E ≤ ([0-9.]+)\)", st["f_sup-bound"])
    assert m and Q(m.group(1)) == p["f_sup"]
    m = re.search(r"ε⋆ = γ⋆/κ = ([0-9/]+)", st["eps-star"])
    assert m and Q(m.group(1)) == p["eps_star"]


# -- tampering -------------------------------------------------------------------------------
def _consistent(sp, **over):
    """Parameters from the rules with some inputs overridden (consistently downstream)."""
    o = sp.options
    c = D.constants(sp)
    c = dataclasses.replace(c, **{k: v for k, v in over.items() if k in ("L_f", "L_h", "f_sup")})
    if "gamma_star" in over or "gamma0" in over:
        o = dataclasses.replace(
            o,
            gamma_star=over.get("gamma_star", o.gamma_star),
            gamma0=over.get("gamma0", o.gamma0),
        )
    return D.rules(c, o, kappa=over.get("kappa"), K=over.get("K"))


def _report_with(rep, vals: dict, tmp_path: Path) -> Path:
    d = rep.to_dict()
    vals = {k: np.array(v, dtype=object) if isinstance(v, list) else v for k, v in vals.items()}
    d["parameters"] = Parameters(vals).to_json()
    out = tmp_path / "tampered.json"
    out.write_text(json.dumps(d))
    return out


def _failed(path: Path) -> set[str]:
    """The method's own failed claims after verify (verify adds report-alters:<id> /
    report-verdict when the stored claims differ from the recomputed ones); exit code 1."""
    ver = api.verify(path)
    assert ver.exit_code() == 1, [(c.id, c.float_ok) for c in ver.failed]
    return {c.id for c in ver.failed if not c.id.startswith("report-")}


def _reschedule(vals: dict, o) -> dict:
    """Recompute Δτ-dependent entries after a change of dT / K / dtau."""
    gam = D.schedule(o.gamma0, vals["gamma_star"], vals["L_f"], vals["dtau"])
    v = dict(vals)
    v["gamma_schedule"] = gam
    v["eps_schedule"] = [g / v["kappa"] for g in gam]
    return D.params_from(
        v["L_f"],
        v["L_h"],
        v["f_sup"],
        v["kappa"],
        v["gamma_star"],
        v["dT"],
        int(v["K"]),
        v["dtau"],
        gam,
    )


ULP_BELOW_1 = fmpq(1) - fmpq(1, 2**53)


def test_tamper_L_h(example, tmp_path):
    sp, rep = example
    assert _failed(_report_with(rep, _consistent(sp, L_h=ULP_BELOW_1), tmp_path)) == {"L_h-bound"}


def test_tamper_L_f(example, tmp_path):
    sp, rep = example
    assert _failed(_report_with(rep, _consistent(sp, L_f=ULP_BELOW_1), tmp_path)) == {"L_f-bound"}


def test_tamper_f_sup(example, tmp_path):
    sp, rep = example
    below = Q("3.53553390593273")  # < 2.5·√2 = 3.5355339059327376…
    assert _failed(_report_with(rep, _consistent(sp, f_sup=below), tmp_path)) == {"f_sup-bound"}


def test_tamper_kappa(example, tmp_path):
    """κ = 2 = 2L_h, the open interval's end: failed, and the detail names the end point (it
    read "κ leaves (L_h, 2L_h) by 0")."""
    sp, rep = example
    path = _report_with(rep, _consistent(sp, kappa=fmpq(2)), tmp_path)
    assert _failed(path) == {"kappa-range"}
    detail = next(c.detail for c in api.verify(path).failed if c.id == "kappa-range")
    assert "κ = 2L_h = 2, and the interval is open" in detail and "by 0" not in detail


def test_tamper_gamma_star(example, tmp_path):
    sp, rep = example
    v = _consistent(sp, gamma_star=fmpq(1, 20) + fmpq(1, 2**60))
    assert _failed(_report_with(rep, v, tmp_path)) == {"gamma_star-matches-spec"}


def test_tamper_gamma0(example, tmp_path):
    sp, rep = example
    v = _consistent(sp, gamma0=fmpq(1) + fmpq(1, 2**60))
    assert _failed(_report_with(rep, v, tmp_path)) == {"gamma0-matches-spec"}


def test_tamper_dT(example, tmp_path):
    sp, rep = example
    v = _consistent(sp)
    v["dT"] += fmpq(1, 2**80)
    v["dtau"] = v["K"] * v["dT"]
    assert _failed(_report_with(rep, _reschedule(v, sp.options), tmp_path)) == {"dT-rule"}


def test_tamper_dtau(example, tmp_path):
    sp, rep = example
    v = _consistent(sp)
    v["dtau"] -= fmpq(1, 2**80)
    assert _failed(_report_with(rep, _reschedule(v, sp.options), tmp_path)) == {"dtau-rule"}


def test_tamper_K_smaller_is_not_the_rule(example, tmp_path):
    sp, rep = example
    v = _consistent(sp, K=62)
    assert _failed(_report_with(rep, v, tmp_path)) == {"K-rule"}


def test_tamper_K_larger_breaks_lemma2_and_the_K_rule(example, tmp_path):
    """K = 64 for the example's 63: 64·ΔT > log(1.5) (L_f = 1), so K is not an integer with
    KΔT < log(κ/L_h)/L_f at all, let alone the largest; K-rule was certified beside the failed
    Lemma 2, checking only that K + 1 fails (search-space trial, session 27)."""
    sp, rep = example
    v = _consistent(sp, K=64)
    assert _failed(_report_with(rep, v, tmp_path)) == {"lemma2-consistency", "K-rule"}
    from obsdesign.params import Parameters

    rule = next(c for c in api.certify(sp, Parameters(v)) if c.id == "K-rule")
    # the detail names the side that fails (it said "a larger K also keeps Lemma 2's horizon")
    assert "K itself breaks the rule" in rule.detail and rule.margin.startswith("-")
    v = _consistent(sp, K=62)
    rule = next(c for c in api.certify(sp, Parameters(v)) if c.id == "K-rule")
    assert rule.detail == "a larger K also keeps Lemma 2's horizon"


def test_tamper_schedule_entry(example, tmp_path):
    sp, rep = example
    v = _consistent(sp)
    g = list(v["gamma_schedule"])
    x = v["L_f"] * v["dtau"]
    g[3] = g[2] * D.exp_lower(x) / 2 - fmpq(1, 2**80)  # below γ_2 e^{L_f Δτ}/2
    v["gamma_schedule"] = g
    v["eps_schedule"] = [a / v["kappa"] for a in g]
    assert _failed(_report_with(rep, v, tmp_path)) == {"gamma-schedule"}


def test_tamper_schedule_truncated(example, tmp_path):
    sp, rep = example
    v = _consistent(sp)
    v["gamma_schedule"] = list(v["gamma_schedule"])[:-1]
    v["eps_schedule"] = list(v["eps_schedule"])[:-1]
    assert _failed(_report_with(rep, v, tmp_path)) == {"gamma-schedule"}


def test_tamper_eps_entry(example, tmp_path):
    sp, rep = example
    v = _consistent(sp)
    e = list(v["eps_schedule"])
    e[5] += fmpq(1, 2**80)
    v["eps_schedule"] = e
    assert _failed(_report_with(rep, v, tmp_path)) == {"eps-schedule"}


def test_tamper_eps_star(example, tmp_path):
    sp, rep = example
    v = _consistent(sp)
    v["eps_star"] += fmpq(1, 2**80)
    assert _failed(_report_with(rep, v, tmp_path)) == {"eps-star"}


def test_tampered_report_cli_exit_1(example, tmp_path):
    sp, rep = example
    path = _report_with(rep, _consistent(sp, K=64), tmp_path)
    r = CliRunner().invoke(app, ["verify", str(path)])
    assert r.exit_code == 1, r.output


# -- spec-level: conditions that cannot all hold --------------------------------------------
def _design_failed(text: str, tmp_path: Path) -> set[str]:
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    rep = api.design(p)
    out = tmp_path / "r.json"
    out.write_text(rep.to_json())
    assert api.verify(out).exit_code() == 1
    return {c.id for c in rep.failed}


@pytest.mark.parametrize(
    ("old", "new", "failed"),
    [
        ("lower = [0]\nupper = [1]", "lower = [0]\nupper = [0.99]", "input-range"),
        ("lower = [0, -2]\nupper = [0, 2]", "lower = [0, -2]\nupper = [0, 2.6]", "D-in-E"),
        ("alpha = 0.9 ", "alpha = 1 ", "lemma1-discarding"),  # α = 1 breaks Lemma 1
        ("gamma0 = 1 ", "gamma0 = 0.0499 ", "gamma0-above-star"),  # γ₀ below γ⋆
    ],
    ids=["input-outside-U", "D-outside-E", "alpha-one-breaks-lemma1", "gamma0-below-gamma-star"],
)
def test_spec_condition_fails_exactly_its_claim(tmp_path, old, new, failed):
    text = TEXT.replace(old, new)
    assert _design_failed(text, tmp_path) == {failed}


def test_given_constants(tmp_path):
    """User-given constants: proved when the interval bound is below them; a value below a
    sampled difference quotient fails; the report must carry the spec's value."""
    text = TEXT.replace("gamma0 = 1 ", "gamma0 = 1\nL_h = 1\nL_f = 1.5 ")
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    sp = api.load_spec(p)
    rep = api.design(sp)
    assert rep.exit_code() == 0
    assert rep.parameters["L_f"] == fmpq(3, 2)
    assert "given" in next(c.statement for c in rep.claims if c.id == "L_f-bound")
    v = _consistent(sp, L_h=fmpq(1) + fmpq(1, 2**52))
    assert _failed(_report_with(rep, v, tmp_path)) == {"L_h-matches-spec"}
    bad = TEXT.replace("gamma0 = 1 ", "gamma0 = 1\nL_h = 0.9 ")
    failed = _design_failed(bad, tmp_path)
    assert failed == {"L_h-bound"}


def test_kappa_outside_range_and_K_one_too_long(tmp_path):
    """κ ≥ 2 L_h: the paper's conditions cannot all hold; say which and by how much."""
    text = TEXT.replace("# kappa = 1.5 ", "kappa = 2.5 ")
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    rep = api.design(p)
    bad = {c.id: c.detail for c in rep.failed}
    # κ/L_h > 2 also makes e^{L_f Δτ}/2 ≥ 1 possible: here the schedule cannot decrease
    assert set(bad) == {"kappa-range", "gamma-schedule"}
    assert "by 0.5" in bad["kappa-range"]
    # γ⋆ so large that even K = 1 exceeds Lemma 2's horizon
    text = TEXT.replace("# kappa = 1.5 ", "kappa = 1.001 ").replace("alpha = 0.9 ", "alpha = 0.99 ")
    text = text.replace("gamma_star = 0.05 ", "gamma_star = 0.5 ")
    p.write_text(text, encoding="utf-8")
    rep = api.design(p)
    assert {c.id for c in rep.failed} == {"lemma2-consistency"}
    assert rep.parameters["K"] == 1
    assert "K = 1 already too long" in rep.failed[0].detail


def test_bad_inputs(tmp_path):
    from obsdesign.errors import SpecError

    p = tmp_path / "s.toml"
    p.write_text(TEXT.replace('f = ["u1*x2", "-u1*x1"]', 'f = ["u1*x2 + t", "-u1*x1"]'))
    # the key is where the term is (it named [method.key]: outsider trial, session 22)
    with pytest.raises(SpecError, match=r"\[system\.f\] f\[0\] uses t: .*time enters through u"):
        api.load_spec(p)
    p.write_text(TEXT.replace('h = ["x1*step(x1)"]', 'h = ["x1*step(x1) + t"]'))
    with pytest.raises(SpecError, match=r"\[system\.h\] h\[0\] uses t"):
        api.load_spec(p)
    p.write_text(TEXT.replace("gamma_star = 0.05 ", "eps_star = 0.05\ngamma_star = 0.05 "))
    with pytest.raises(SpecError, match="exactly one of gamma_star and eps_star"):
        api.load_spec(p)
    p.write_text(TEXT.replace("lower = [0, -2]\nupper = [0, 2]", "lower = [0, 2]\nupper = [0, -2]"))
    with pytest.raises(SpecError, match="lower <= upper"):
        api.load_spec(p)


def test_eps_star_spelling(tmp_path):
    text = TEXT.replace("gamma_star = 0.05 ", "eps_star = 0.04 ")
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    rep = api.design(p)
    assert rep.exit_code() == 0
    assert rep.parameters["gamma_star"] == fmpq(3, 2) * fmpq(1, 25)
    assert rep.parameters["eps_star"] == fmpq(1, 25)


def test_copy_is_untouched(example):
    """Tampering helpers work on copies: the module fixture stays certified."""
    sp, rep = example
    assert copy.deepcopy(rep).exit_code() == 0


@pytest.mark.parametrize(
    ("old", "new", "failed"),
    [
        ("gamma0 = 1 ", "gamma0 = 0.05 ", set()),  # γ₀ = γ⋆ is allowed (≥)
        ("gamma0 = 1 ", "gamma0 = 0.04999999999 ", {"gamma0-above-star"}),
        ("lower = [0, -2]\nupper = [0, 2]", "lower = [0, -2.5]\nupper = [0, 2.5]", set()),
        (
            "lower = [0, -2]\nupper = [0, 2]",
            "lower = [0, -2.5]\nupper = [0, 2.50000000001]",
            {"D-in-E"},
        ),
        ("alpha = 0.9 ", "alpha = 0.99999999999 ", set()),
    ],
)
def test_spec_boundaries(tmp_path, old, new, failed):
    """The inequalities at their boundaries: allowed equality passes, the smallest step past
    it fails exactly that claim."""
    assert old in TEXT
    p = tmp_path / "s.toml"
    p.write_text(TEXT.replace(old, new), encoding="utf-8")
    rep = api.design(p)
    assert {c.id for c in rep.failed} == failed


def test_spec_fixed_kappa_and_K_are_bound(tmp_path):
    """κ and K given in the spec: a report with another (consistently recomputed) value fails
    exactly the comparison with the spec."""
    text = TEXT.replace("# kappa = 1.5 ", "kappa = 1.5\nK = 50 ")
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    sp = api.load_spec(p)
    rep = api.design(sp)
    assert rep.exit_code() == 0 and rep.parameters["K"] == 50
    assert "K-rule" not in {c.id for c in rep.claims}
    v = _consistent(sp, kappa=fmpq(8, 5))
    assert _failed(_report_with(rep, v, tmp_path)) == {"kappa-matches-spec"}
    v = _consistent(sp, K=49)
    assert _failed(_report_with(rep, v, tmp_path)) == {"K-matches-spec"}


_INPUT_SPEC = """
[system]
time = "continuous"
states = ["x1", "x2"]
f = ["u1*x2", "-u1*x1"]
h = ["x1"]
u = ["{u}"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 1
horizon = 6
[method.E]
lower = [-2, -2]
upper = [2, 2]
[method.D]
lower = [0, -1]
upper = [0, 1]
[method.U]
lower = [{lo}]
upper = [{hi}]
"""


@pytest.mark.parametrize(
    "u,lo,hi,status,code",
    [
        ("0.1", "0.1", "1", "certified", 0),  # the soundness audit's case (was failed, exit 1)
        ("0.3*sin(t)", "-0.3", "0.3", "certified", 0),  # attained: exact end points (was 4)
        ("0.3*sin(t) + 1e-30", "-0.3", "0.3", "failed", 4),  # over by 1e-30: not proved either way
        ("0.31*sin(t)", "-0.3", "0.3", "failed", 1),  # proved violation
    ],
)
def test_input_range_claim_exit_codes(u: str, lo: str, hi: str, status: str, code: int) -> None:
    from obsdesign.api import load_spec_text

    rep = api.design(load_spec_text(_INPUT_SPEC.format(u=u, lo=lo, hi=hi), "u.toml"))
    claim = next(c for c in rep.claims if c.id == "input-range")
    assert claim.status.value == status
    assert rep.exit_code() == code


@pytest.mark.parametrize(("u", "at"), [("sqrt(-1 - t)", "t = 0"), ("log(t - 7)", "t = 0")])
def test_an_input_undefined_on_the_horizon_is_hinted(u: str, at: str) -> None:
    """u undefined at t = 0: input-range stays inconclusive (exit 4; floats prove nothing),
    and the detail names the expression and the first time its float value is not finite
    (it said only "leaves U by up to inf": review 19). A finite input gets no such hint."""
    from obsdesign.api import load_spec_text

    rep = api.design(load_spec_text(_INPUT_SPEC.format(u=u, lo="-1", hi="1"), "u.toml"))
    claim = next(c for c in rep.claims if c.id == "input-range")
    assert rep.exit_code() == 4
    assert f"u1(t) = {u} is not finite at {at} in floats" in claim.detail
    rep = api.design(
        load_spec_text(_INPUT_SPEC.format(u="0.3*sin(t) + 1e-30", lo="-0.3", hi="0.3"))
    )
    assert "not finite" not in next(c for c in rep.claims if c.id == "input-range").detail


@pytest.mark.parametrize(
    ("est", "status"), [(1.0, "certified"), (1.0 + 2e-6, "failed"), (1.0000000000000002, "failed")]
)
def test_a_sampled_value_above_the_bound_fails_the_claim(
    example, monkeypatch: pytest.MonkeyPatch, est: float, status: str
) -> None:
    """The safety net of _constant: an enclosure that "proves" L_h ≤ 1 while a sample of the
    run-time evaluator reaches 1 + 2·10⁻⁶ (beyond float error, 10⁻⁶ relative) fails L_h-bound
    (the two evaluators disagreed on sat(x, r < 0) and a false sup |f| was certified: review
    19); a sample at the bound itself does not."""
    from obsdesign.methods.searchspace import claims as C
    from obsdesign.methods.searchspace.bounds import Bound

    sp, rep = example
    real = C.interval_bound

    def fake(k: str, spec):  # noqa: ANN001, ANN202
        return Bound(1.0, est, 1) if k == "L_h" else real(k, spec)

    monkeypatch.setattr(C, "interval_bound", fake)
    got = {c.id: c.status.value for c in api.certify(sp, rep.parameters)}
    assert got["L_h-bound"] == status


@pytest.mark.parametrize("K", [10**15, 10**20])
def test_tamper_K_huge_fails_the_schedule_without_forming_the_exponential(
    example, tmp_path: Path, K: int
) -> None:
    """K = 10¹⁵ with Δτ = KΔT kept consistent: verify fails Lemma 2 and the schedule
    (L_f Δτ ≥ 1, so e^(L_f Δτ)/2 ≥ 1) and returns; it died with SIGFPE in python-flint while
    forming the 113-bit enclosure of e^(L_f Δτ) (review 19). design.schedule stops at γ₀."""
    sp, rep = example
    v = _consistent(sp, K=K)
    assert v["gamma_schedule"] == [sp.options.gamma0]
    failed = _failed(_report_with(rep, v, tmp_path))
    assert {"lemma2-consistency", "gamma-schedule"} <= failed
    ver = api.verify(tmp_path / "tampered.json")
    detail = next(c.detail for c in ver.claims if c.id == "gamma-schedule")
    assert "≥ 1, so e^(L_f Δτ)/2 ≥ (1 + L_f Δτ)/2 ≥ 1" in detail


def test_digits_beyond_30_is_bad_input(tmp_path: Path) -> None:
    """digits = 31 is exit 2 naming [method.digits] (100000 was an internal failure: Python's
    4300-digit limit of int-to-string conversion, review 19); 30 designs."""
    spec = tmp_path / "s.toml"
    spec.write_text(TEXT.replace('key = "search-space"', 'key = "search-space"\ndigits = 31'))
    res = CliRunner().invoke(app, ["design", str(spec), "-o", str(tmp_path / "r.json")])
    assert res.exit_code == 2 and "[method.digits] expected at most 30" in res.output
    sp = api.load_spec_text(
        TEXT.replace('key = "search-space"', 'key = "search-space"\ndigits = 30')
    )
    assert api.design(sp).exit_code() == 0


def test_a_schedule_cut_by_the_cap_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    """A schedule that needs more entries than the design lists (MAX_SCHEDULE, here 7 for the
    example's 12; at 5 it is refused before listing, the rule needing at least est/2 > 5)
    fails gamma-schedule with the cap and the way out named (it read only "ends at …, not at
    γ⋆", though every listed entry keeps the rule: review 19, κ near 2L_h)."""
    from obsdesign.methods.searchspace import claims as C

    monkeypatch.setattr(D, "MAX_SCHEDULE", 7)
    monkeypatch.setattr(C, "MAX_SCHEDULE", 7)
    rep = api.design(api.load_spec(SPEC))
    bad = {c.id: c.detail for c in rep.failed}
    assert list(bad) == ["gamma-schedule"]
    assert "at most 7 entries" in bad["gamma-schedule"] and "a smaller K" in bad["gamma-schedule"]
    # the note said "γ reaches γ⋆ after 4 switches" beside it (re-check trial, session 31)
    assert any("does not reach γ⋆ within the 7 listed entries" in n for n in rep.notes)
    assert not any("reaches γ⋆ after" in n for n in rep.notes)


#: the example with γ⋆ = 1e-300
TINY_STAR = TEXT.replace("gamma_star = 0.05 ", "gamma_star = 1e-300 ")


def test_K_rule_decides_a_K_of_10_to_the_300(tmp_path: Path) -> None:
    """γ⋆ = 1e-300 gives K ≈ 1.3·10³⁰⁰: the design's own K certifies K-rule and Lemma 2 (at
    113 bits ln(κ/L_h) cannot tell K from K + 1 and K-rule failed for it, exit 1: review 19),
    verify agrees, and K − 1 (not the largest) and K + 1 (breaks Lemma 2) fail."""
    assert "1e-300" in TINY_STAR
    sp = api.load_spec_text(TINY_STAR, "tiny.toml")
    rep = api.design(sp)
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    K = int(rep.parameters.get("K"))
    assert 10**300 < K < 10**301
    assert api.verify(rep).exit_code() == 0
    for k, claims in ((K - 1, {"K-rule"}), (K + 1, {"lemma2-consistency", "K-rule"})):
        v = _consistent(sp, K=k)
        assert _failed(_report_with(rep, v, tmp_path)) == claims, k


def test_K_bits_grow_with_K_and_are_capped() -> None:
    """K_bits: 113 for K ≈ 10, 113 + ~1000 for K ≈ 10³⁰⁰, MAX_K_BITS for a hostile ΔT of
    10⁻¹⁰⁰⁰⁰⁰ (a report cannot make verify compute a logarithm to millions of bits)."""
    assert D.K_bits(fmpq(1, 10)) == 113 + 4
    assert 113 + 990 < D.K_bits(fmpq(1, 10**300)) < 113 + 1010
    assert D.K_bits(fmpq(1, 10**100000)) == D.MAX_K_BITS
    assert D.K_bits(fmpq(0)) == 113


def test_the_safety_net_refutes_exactly_above_the_value(example, monkeypatch) -> None:
    """Mutation review 20, restated in session 36: the sampled estimate is a proved lower bound
    (bounds.proved_quotient), so _constant refutes a value exactly when the estimate is above
    it. An estimate equal to the value does not refute a proved L_h (≥ would); one float
    spacing above it does; a constant h (interval bound 0, sample 0) has the bound 0 proved."""
    import math

    from obsdesign.api import bind
    from obsdesign.certify.claim import Claims
    from obsdesign.methods.searchspace import claims as C
    from obsdesign.methods.searchspace.bounds import Bound

    sp, rep = example
    bsp = bind(sp)
    val = fmpq(1)
    cases = [
        (Bound(0.5, 1.0, 1), val, ClaimStatus.CERTIFIED),
        (Bound(0.5, math.nextafter(1.0, 2.0), 1), val, ClaimStatus.FAILED),
        (Bound(0.0, 0.0, 1), fmpq(0), ClaimStatus.CERTIFIED),
    ]
    for bound, v, want in cases:
        monkeypatch.setattr(C, "interval_bound", lambda k, spec, b=bound: b)
        c = Claims()
        C._constant(c, bsp, "L_h", v)
        (claim,) = c
        assert claim.id == "L_h-bound" and claim.status == want, claim.detail


def test_an_unproved_constant_fails_unless_the_user_gave_it(example, monkeypatch) -> None:
    """Mutation review 20: which branch of _constant decides. A computed constant (not in the
    spec) that the interval bound does not prove fails exactly, even with every sample below
    it; a value the user gave, unproved and not refuted (a sample equal to it is not above
    it), is a numerical pass."""
    from obsdesign.api import bind
    from obsdesign.certify.claim import Claims
    from obsdesign.methods.searchspace import claims as C
    from obsdesign.methods.searchspace.bounds import Bound

    sp, _ = example
    given = bind(api.load_spec_text(TEXT.replace("gamma0 = 1 ", "gamma0 = 1\nL_h = 1 "), "g.toml"))
    assert given.options.L_h == 1 and bind(sp).options.L_h is None
    cases = [
        (bind(sp), Bound(2.0, 0.5, 1), ClaimStatus.FAILED),
        (given, Bound(2.0, 0.5, 1), ClaimStatus.NUMERICAL),
        (given, Bound(2.0, 1.0, 1), ClaimStatus.NUMERICAL),
    ]
    for spec, bound, want in cases:
        monkeypatch.setattr(C, "interval_bound", lambda k, s, b=bound: b)
        c = Claims()
        C._constant(c, spec, "L_h", fmpq(1))
        (claim,) = c
        assert claim.status == want, (bound, claim.detail)


def test_schedule_checks_every_transition_and_the_fixed_point() -> None:
    """Mutation review 20: _schedule on exact inputs (L_f = 1, Δτ = 1/10, γ⋆ = 1/100). The
    rule's own schedule passes; an entry 1.45× the rule's value (allowed: 10⁻¹² relative)
    fails; dropping the second-to-last entry (the last transition then jumps to γ⋆ early)
    fails; a schedule [γ⋆] with e^(L_f Δτ)/2 > 1 (L_f Δτ = 4/5) fails."""
    from obsdesign.certify.claim import Claims
    from obsdesign.methods.searchspace import claims as C

    L_f, dtau, g_star = fmpq(1), fmpq(1, 10), fmpq(1, 100)

    def status(gam, dt=dtau):  # noqa: ANN001, ANN202
        c = Claims()
        C._schedule(c, list(gam), g_star, L_f, dt)
        (claim,) = c
        assert claim.id == "gamma-schedule"
        return claim.status

    good = D.schedule(fmpq(1), g_star, L_f, dtau)
    assert len(good) >= 4 and good[-1] == g_star and good[-2] > g_star
    assert status(good) == ClaimStatus.CERTIFIED
    assert status([fmpq(1), *D.schedule(fmpq(4, 5), g_star, L_f, dtau)]) == ClaimStatus.FAILED
    assert status([*good[:-2], g_star]) == ClaimStatus.FAILED
    assert status([g_star], fmpq(4, 5)) == ClaimStatus.FAILED


# -- mutation review 21: bounds.sup_norm / bounds.lipschitz and claims.certify -----------------
# To be appended to tests/test_searchspace.py (uses its TEXT, example, _consistent,
# _report_with, _failed, D, api, fmpq, ClaimStatus, pytest).


def _constant_status(text: str, k: str, val: fmpq) -> ClaimStatus:
    """Status of the claim <k>-bound that claims._constant gives ``val`` on the spec ``text``,
    with the real interval bound (computed afresh: design's cache cleared)."""
    from obsdesign.api import bind
    from obsdesign.certify.claim import Claims
    from obsdesign.methods.searchspace import claims as C

    D._CACHE.clear()
    c = Claims()
    C._constant(c, bind(api.load_spec_text(text, "c.toml")), k, val)
    (claim,) = c
    assert claim.id == f"{k}-bound"
    return claim.status


def _given(text: str, k: str, value: str) -> str:
    return text.replace("gamma0 = 1 ", f"gamma0 = 1\n{k} = {value} ")


def test_a_given_f_sup_below_a_sampled_value_fails() -> None:
    """Mutation review 21 (bounds.sup_norm): the sampled lower estimate of ‖f_u‖_E is what
    fails a user-given f_sup that the interval bound does not prove. The example's
    ‖f_u‖_E = 2.5·√2 ≈ 3.536 (attained at a corner of E × U): f_sup = 3 given fails, 3.6 is
    proved. (A lower estimate stuck at 0 let the false 3 pass as numerical.)"""
    assert _constant_status(_given(TEXT, "f_sup", "3"), "f_sup", fmpq(3)) == ClaimStatus.FAILED
    good = _given(TEXT, "f_sup", "3.6")
    assert _constant_status(good, "f_sup", fmpq(18, 5)) == ClaimStatus.CERTIFIED


def test_sup_norm_estimate_ignores_boxes_where_f_is_undefined() -> None:
    """Mutation review 21 (bounds.sup_norm): a sub-box where f has no finite sample (sqrt of a
    negative x1) adds nothing to the sampled lower estimate: no exception (a box without a
    finite sample crashed the bound) and no invented value (1.0 refuted a true given bound
    below 1). sup |√x − x/2| over the part of [−2.5, 2.5] where it is defined is 1/2 (x = 1);
    the budget goes to the undefined half, so the estimate is only near it."""
    from obsdesign.methods.searchspace import bounds as B
    from obsdesign.spec.expr import parse_expr

    ex = [parse_expr("sqrt(x1) - x1/2", ["x1"])]
    b = B.sup_norm(ex, ["x1"], [fmpq(-5, 2)], [fmpq(5, 2)], 64, 1e-6)
    assert not b.finite  # the sub-boxes with x1 < 0 bound nothing
    assert 0.4 < b.lower_est <= 0.5 * (1 + 1e-9)


@pytest.mark.parametrize(
    ("h", "E", "value", "want"),
    [
        # L_h = 1 comes from x2 only: the estimate must follow the Jacobian's direction, not
        # a fixed axis (finite differences of zero length left the direction x1, estimate 0)
        ("x2", None, "0.9", ClaimStatus.FAILED),
        # E away from 0 (every |x| > 1): the finite-difference step 10⁻⁶·(1 + max|x|) is
        # positive (with 1 − max|x| it was negative and the estimate negative)
        ("x1", ("[2, 2]", "[4, 4]"), "0.9", ClaimStatus.FAILED),
        # E at 10⁶: the step grows with |x| (10⁻⁶/(1 + max|x|) is below the float spacing
        # there: the quotient was 0, or a rounding jump far above 1)
        ("x1", ("[1000000, 1000000]", "[1000001, 1000001]"), "0.9", ClaimStatus.FAILED),
        ("x1", ("[1000000, 1000000]", "[1000001, 1000001]"), "1", ClaimStatus.CERTIFIED),
        # (x1 + 5/2)^1.5/10 has L_h = 1.5·√5/10 ≈ 0.3354 on E but no finite interval bound
        # (the derivative's enclosure at x1 = −5/2); the corner x1 = −5/2 has no finite
        # difference quotient (x1 − step is outside the domain): that box adds nothing to
        # the estimate (1.0 refuted the true given 0.34)
        ("(x1 + 2.5)^1.5/10", None, "0.34", ClaimStatus.NUMERICAL),
    ],
)
def test_a_given_L_h_is_refuted_only_by_a_true_difference_quotient(
    h: str, E: tuple[str, str] | None, value: str, want: ClaimStatus
) -> None:
    """Mutation review 21 (bounds.lipschitz): the sampled lower estimate of L_h^E is a true
    difference quotient near the constant, whatever the box and the direction; it alone
    decides a user-given L_h that the interval bound does not prove (FAILED when a sample
    exceeds it, NUMERICAL otherwise) and refutes a proved one."""
    text = TEXT.replace('h = ["x1*step(x1)"]', f'h = ["{h}"]')
    if E is not None:
        text = text.replace(
            "lower = [-2.5, -2.5]\nupper = [2.5, 2.5]", f"lower = {E[0]}\nupper = {E[1]}"
        )
        assert E[0] in text
    assert _constant_status(_given(text, "L_h", value), "L_h", Q(value)) == want


def test_a_report_without_the_exact_value_is_not_verified_on_its_float(example, tmp_path) -> None:
    """Mutation review 21 (certify): every parameter is read with accept_float=False. A report
    whose exact strings for L_f and K were removed (their floats 1.0 and 63.0 are exactly the
    certified values) fails L_f-exact and K-exact; accepting the floats verified it."""
    sp, rep = example
    d = rep.to_dict()
    del d["parameters"]["exact"]["L_f"], d["parameters"]["exact"]["K"]
    assert d["parameters"]["L_f"] == 1.0 and d["parameters"]["K"] == 63.0
    out = tmp_path / "floats.json"
    out.write_text(json.dumps(d))
    assert _failed(out) == {"L_f-exact", "K-exact"}


@pytest.mark.parametrize(("K", "K_rule"), [(None, set()), (5, {"K-rule"})])
def test_tamper_kappa_at_the_lower_end(example, tmp_path, K, K_rule) -> None:
    """Mutation review 21 (certify): κ = L_h, the open interval's lower end, fails
    kappa-range (L_h ≤ κ passed it) and names the end point; Lemma 2 fails too (log(κ/L_h)
    = 0). K-rule then asks K = 1 (the paper's max{·, 1}): K = 5 fails it (with κ/L_h ≥ 1
    sent to the logarithm, any K passed)."""
    sp, rep = example
    path = _report_with(rep, _consistent(sp, kappa=fmpq(1), K=K), tmp_path)
    assert _failed(path) == {"kappa-range", "lemma2-consistency"} | K_rule
    detail = next(c.detail for c in api.verify(path).failed if c.id == "kappa-range")
    assert "κ = L_h = 1, and the interval is open" in detail


def test_tamper_K_not_an_integer(example, tmp_path) -> None:
    """Mutation review 21 (certify): K = 127/2 with Δτ = KΔT and the schedule recomputed
    keeps Lemma 2 (63.5·ΔT < log 1.5) but is no integer: dtau-rule and K-rule fail (with
    "K.q == 1 or K ≥ 1" every claim passed)."""
    sp, rep = example
    o = sp.options
    v = _consistent(sp)
    v["K"] = fmpq(127, 2)
    v["dtau"] = v["K"] * v["dT"]
    v["gamma_schedule"] = D.schedule(o.gamma0, v["gamma_star"], v["L_f"], v["dtau"])
    v["eps_schedule"] = [g / v["kappa"] for g in v["gamma_schedule"]]
    assert _failed(_report_with(rep, v, tmp_path)) == {"dtau-rule", "K-rule"}


def test_K_one_is_the_rule_when_one_step_exceeds_lemma2s_horizon(tmp_path) -> None:
    """Mutation review 21 (certify): K-rule's branch for K = 1 compares ΔT·L_f with log(κ/L_h).
    With L_f = 100 given, ΔT·L_f ≈ 7 ≥ log 1.001 > ΔT/L_f: K = 1 keeps K-rule (only Lemma 2
    fails, and the schedule: L_f Δτ ≥ 1; ΔT/L_f failed K-rule too)."""
    text = TEXT.replace("# kappa = 1.5 ", "kappa = 1.001 ").replace("alpha = 0.9 ", "alpha = 0.99 ")
    text = text.replace("gamma_star = 0.05 ", "gamma_star = 0.5\nL_f = 100 ")
    rep = api.design(api.load_spec_text(text, "k1.toml"))
    assert rep.parameters["K"] == 1 and rep.parameters["L_f"] == 100
    assert {c.id for c in rep.failed} == {"lemma2-consistency", "gamma-schedule"}


def _certified(sp, v: dict) -> dict:
    return {k: c.status for k, c in _claims(sp, v).items()}


def _claims(sp, v: dict) -> dict:
    from obsdesign.params import Parameters

    return {c.id: c for c in api.certify(sp, Parameters(v))}


def test_lemma2_and_K_rule_use_the_safe_side_of_the_logarithm(example) -> None:
    """Mutation review 21 (certify): Lemma 2 compares L_f Δτ with a LOWER bound of
    log(κ/L_h), K-rule (K+1)ΔT L_f with an UPPER bound, each reaching it (≥) or not (<)
    exactly. Δτ a hair above log 1.5 (a 400-bit upper bound, below the 113-bit one) fails
    Lemma 2 (it passed against the upper bound); ΔT = hi/64, so that 64 ΔT equals the
    113-bit upper bound hi, keeps K = 63 (">" failed it)."""
    sp, _ = example
    v = _consistent(sp)
    assert v["L_f"] == 1 and v["L_h"] == 1 and v["kappa"] == fmpq(3, 2) and v["K"] == 63
    bits = D.K_bits(v["dT"] * v["L_f"])
    lo, hi = ivq.log_bounds(fmpq(3, 2), bits)
    tight = ivq.log_bounds(fmpq(3, 2), 400)[1]
    assert lo < tight < hi
    w = dict(v, dtau=tight)
    assert _certified(sp, w)["lemma2-consistency"] == ClaimStatus.FAILED
    dT = hi / 64
    assert D.K_bits(dT) == bits
    w = dict(v, dT=dT, dtau=63 * dT)
    assert _certified(sp, w)["K-rule"] == ClaimStatus.CERTIFIED


def test_tamper_K_one_is_not_the_rule(example, tmp_path) -> None:
    """Mutation review 21 (certify): K = 1 is allowed only when one step already reaches
    log(κ/L_h)/L_f; the example's rule gives 63, so K = 1 (consistent otherwise) fails K-rule
    ("K == 1 or …" passed it)."""
    sp, rep = example
    assert _failed(_report_with(rep, _consistent(sp, K=1), tmp_path)) == {"K-rule"}


# -- mutation review 21b: claims.certify, Lemma 2 and ε⋆ (the mutants not run in review 21) ------
# To be appended to tests/test_searchspace.py (uses its example, _consistent, _certified, D,
# ivq, fmpq, ClaimStatus).


def test_lemma2_is_decided_beyond_the_working_precision_of_L_f_dT(example) -> None:
    """Mutation review 21b (certify), restated in session 29: Lemma 2 compares L_f Δτ with
    log(κ/L_h) starting at K_bits(ΔT·L_f) bits (L_f = 2²⁰: 114 bits). At Δτ = lo/L_f, lo the
    114-bit lower bound, L_f Δτ = lo < log 1.5 is true: it failed while 114 bits did not
    decide it, and is certified now that undecided comparisons get more bits. Just above
    log 1.5 (its 114-bit upper bound, or 2⁻³⁰⁰ above it) Lemma 2 fails, proved (exit 1)."""
    import mpmath as mp

    sp, _ = example
    v = _consistent(sp, L_f=fmpq(2**20))
    L_f, ratio = v["L_f"], v["kappa"] / v["L_h"]
    assert ratio == fmpq(3, 2)
    bits = D.K_bits(v["dT"] * L_f)
    assert bits == 114
    lo, hi = ivq.log_bounds(ratio, bits)
    assert _certified(sp, dict(v, dtau=lo / L_f))["lemma2-consistency"] == ClaimStatus.CERTIFIED
    with mp.workdps(200):
        above = Q(mp.nstr(mp.log(mp.mpf(3) / 2) + mp.mpf(2) ** -300, 190))
    for x in (hi, above):
        claims = _claims(sp, dict(v, dtau=x / L_f))
        c = claims["lemma2-consistency"]
        assert c.status == ClaimStatus.FAILED and not c.float_ok, x
        assert "by at least" in c.detail and "−" not in c.detail


def test_lemma2_fails_at_kappa_equal_L_h_whatever_dtau(example) -> None:
    """Mutation review 21b (certify): κ = L_h (log(κ/L_h) = 0) fails Lemma 2 without a
    logarithm, even for a report's Δτ < 0 (with κ/L_h ≥ 1 sent to the logarithm, whose bounds
    at 1 are exactly 0, L_f Δτ < 0 passed it)."""
    sp, _ = example
    v = _consistent(sp, kappa=fmpq(1))
    assert v["L_h"] == 1 and v["dtau"] > 0
    w = dict(v, dtau=-v["dtau"])
    assert _certified(sp, w)["lemma2-consistency"] == ClaimStatus.FAILED


def test_eps_star_off_by_a_hair_holds_in_floats(example) -> None:
    """Mutation review 21b (certify): ε⋆ = γ⋆/κ + 2⁻⁸⁰ fails eps-star exactly (the only failed
    claim) but holds in float64 (float(ε⋆) == 0.05/1.5): float_ok is True, so such a run is
    inconclusive (exit 4), not infeasible (without float_ok it was None: exit 1)."""
    from obsdesign.params import Parameters

    sp, _ = example
    v = _consistent(sp)
    v["eps_star"] += fmpq(1, 2**80)
    bad = [c for c in api.certify(sp, Parameters(v)) if c.status == ClaimStatus.FAILED]
    assert [c.id for c in bad] == ["eps-star"]
    assert bad[0].float_ok is True


@pytest.mark.parametrize(
    ("value", "want"),
    [("0.5", ClaimStatus.NUMERICAL), ("0.4999", ClaimStatus.FAILED)],
)
def test_a_given_constant_equal_to_the_true_one_is_not_refuted(value: str, want) -> None:
    """h = x1^1.5/3 on E = [0, 1]²: L_h = 1/2 exactly (at x1 = 1), not proved by the interval
    bound. The given 1/2 failed on a sampled estimate 1e-11 above it (a strict comparison
    without the float tolerance the refutation uses; review 21): it is numerical now, and a
    value 2·10⁻⁴ below the constant is still refuted."""
    text = TEXT.replace('h = ["x1*step(x1)"]', 'h = ["x1^1.5/3"]').replace(
        "lower = [-2.5, -2.5]\nupper = [2.5, 2.5]", "lower = [0, 0]\nupper = [1, 1]"
    )
    assert "x1^1.5/3" in text and "lower = [0, 0]" in text
    assert _constant_status(_given(text, "L_h", value), "L_h", Q(value)) == want


@pytest.mark.parametrize(
    ("h", "L_h"),
    [("2*x1*step(x1)", 2), ("1.001*x1*step(x1)", Q("1.001")), ("x1*step(-x1)", 1)],
)
def test_switch_products_in_h_design_and_verify(h: str, L_h, tmp_path) -> None:
    """The shipped example with y = 2·x1·[x1 > 0], 1.001·x1·[x1 > 0] or x1·[x1 < 0]: each
    was refused ("L_h^E has no finite interval bound on E … a jump?", exit 1) because only
    X*step(X) and -X*step(X) were read as ramps (session 22's note). Now designed with a
    tight L_h and verified."""
    text = TEXT.replace('h = ["x1*step(x1)"]', f'h = ["{h}"]')
    assert h in text
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    rep = api.design(api.load_spec(p))
    assert rep.exit_code() == 0, [c.detail for c in rep.failed]
    # a valid constant, tight (1.001 has no float: its enclosure is rounded outward and up)
    assert L_h <= rep.parameters["L_h"] <= L_h * Q("1.0001")
    out = tmp_path / "r.json"
    out.write_text(json.dumps(rep.to_dict()), encoding="utf-8")
    assert api.verify(out).exit_code() == 0


@pytest.mark.parametrize(("key", "line"), [("A", "A = [[0, 1], [-1, 0]]"), ("C", "C = [[1, 0]]")])
def test_a_linear_model_beside_f_and_h_is_refused(key: str, line: str) -> None:
    """A search-space spec with f, h and also A (or C) was accepted and A silently ignored
    (independent soundness trial, session 23): it is bad input naming the key."""
    text = TEXT.replace("[system]\n", f"[system]\n{line}\n", 1)
    assert line in text
    with pytest.raises(SpecError) as ei:
        api.load_spec_text(text, "s.toml")
    assert ei.value.key == f"system.{key}"


_ONE_STATE = """[system]
time = "continuous"
states = ["x1"]
{system}
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 1
{method}
[simulate]
horizon = 5
x0 = [{x0}]
xhat0 = [0]
"""


def test_a_constant_input_taken_in_floats_is_not_certified_inside_U() -> None:
    """u = 0.5^20001 = 2⁻²⁰⁰⁰¹ > 0 is too large to take exactly (expr._sympy_pow) and became
    the float 0.0, which "u ∈ U = [−1, 0]" compared as exact and certified (search-space
    trial, session 24). A float value is now undecided: the claim is not certified."""
    text = _ONE_STATE.format(
        system='f = ["u1 - x1"]\nh = ["x1"]\nu = ["0.5^20001"]',
        method="[method.E]\nlower = [-2]\nupper = [2]\n[method.D]\nlower = [-1]\nupper = [1]\n"
        "[method.U]\nlower = [-1]\nupper = [0]",
        x0="0.5",
    )
    rep = api.design(api.load_spec_text(text, "powu.toml"))
    claim = next(c for c in rep.claims if c.id == "input-range")
    assert claim.status != ClaimStatus.CERTIFIED and rep.exit_code() != 0


def test_exp_below_the_underflow_range_gets_a_true_bound() -> None:
    """f = exp(x)·10⁴⁰⁰ on E = [−1000, −800]: exp's enclosure was [0, 0] there, and L_f and
    ‖f‖ were certified at 10⁻⁶ although both are f(−800) ≈ 3.67·10⁵² (search-space trial,
    session 24). Whatever the design does now, a certified constant is ≥ the true one."""
    import mpmath

    text = _ONE_STATE.format(
        system='f = ["exp(x1)*1e200*1e200"]\nh = ["x1"]',
        method="[method.E]\nlower = [-1000]\nupper = [-800]\n"
        "[method.D]\nlower = [-900]\nupper = [-850]",
        x0="-870",
    )
    rep = api.design(api.load_spec_text(text, "underflow.toml"))
    true = mpmath.exp(-800) * mpmath.mpf(10) ** 400
    for k in ("L_f", "f_sup"):
        claim = next(c for c in rep.claims if c.id == f"{k}-bound")
        if claim.status == ClaimStatus.CERTIFIED:
            v = Q(rep.parameters[k])
            assert mpmath.mpf(int(v.p)) / int(v.q) >= true, k


def test_the_sampled_estimate_stays_inside_E() -> None:
    """f₁ = x2 − floor(x2) on E with x2 ∈ [0, 1/2] is x2 there (L_f = 1), but the sampled
    difference quotient stepped from E's corner x2 = 0 across the jump just outside E
    (2.5·10⁵) and failed the true L_f-bound claim (search-space trial, session 24). The
    quotient's points are now kept in E, and the design certifies."""
    text = (
        _ONE_STATE.replace('states = ["x1"]', 'states = ["x1", "x2"]')
        .format(
            system='f = ["x2 - floor(x2)", "-x1"]\nh = ["x1"]',
            method="[method.E]\nlower = [-1, 0]\nupper = [1, 0.5]\n"
            "[method.D]\nlower = [-0.5, 0.1]\nupper = [0.5, 0.4]",
            x0="0, 0.2",
        )
        .replace("xhat0 = [0]", "xhat0 = [0, 0]")
    )
    rep = api.design(api.load_spec_text(text, "inside.toml"))
    assert rep.exit_code() == 0, [c.detail for c in rep.failed]
    assert Q(rep.parameters["L_f"]) >= 1


@pytest.mark.parametrize(
    "u", ["pi**1000000/10**100000", "e**e**e**e*10**-100000", "floor(e**e**e**e)"]
)
def test_a_constant_input_beyond_exact_arithmetic_is_never_certified(u: str) -> None:
    """A constant power taken in floats is inf or 0.0, which sympy absorbs (X/oo = 0): u =
    π^(10⁶)/10^(10⁵) ≈ 10^397150 was certified inside U = [0, 1]; and sympy's evalf of
    floor(e^e^e^e) never returned (hostile-input trial, session 24). Only rational
    arithmetic taken exactly is decided by sympy now; these are left to the enclosures."""
    text = _ONE_STATE.format(
        system=f'f = ["u1 - x1"]\nh = ["x1"]\nu = ["{u}"]',
        method="[method.E]\nlower = [-2]\nupper = [2]\n[method.D]\nlower = [-1]\nupper = [1]\n"
        "[method.U]\nlower = [0]\nupper = [1]",
        x0="0.5",
    )
    rep = api.design(api.load_spec_text(text, "u.toml"))
    claim = next(c for c in rep.claims if c.id == "input-range")
    assert claim.status != ClaimStatus.CERTIFIED


_SQRT_U = """[system]
time = "continuous"
states = ["x1"]
f = ["-x1+u1"]
h = ["x1"]
u = ["sqrt(1 - t)"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 1
[method.E]
lower = [-1]
upper = [1]
[method.D]
lower = [0.2]
upper = [0.5]
[method.U]
lower = [0]
upper = [1]
[simulate]
horizon = 5
x0 = [0.2]
xhat0 = [0]
"""


def test_a_function_undefined_on_part_of_its_interval_proves_nothing() -> None:
    """sqrt and log of an enclosure reaching below 0 are refused, not enclosed on their
    defined part: u = sqrt(1 − t), undefined for t > 1, was certified in U = [0, 1] over
    t ∈ [0, 5], and f = −x1 + sqrt(u1) with U = [−1/2, 1/2] had certified L_f and ‖f_u‖ bounds
    (search-space trial, session 27). A u defined on the whole horizon still certifies."""
    rep = api.design(api.load_spec_text(_SQRT_U, "sqrt-u.toml"))
    c = next(c for c in rep.claims if c.id == "input-range")
    assert not c.ok and rep.exit_code() == 4
    ok = api.design(api.load_spec_text(_SQRT_U.replace("sqrt(1 - t)", "sqrt(5 - t)/3"), "ok"))
    assert ok.exit_code() == 0, [(c.id, c.detail) for c in ok.failed]
    text = (
        _SQRT_U.replace('f = ["-x1+u1"]', 'f = ["-x1+sqrt(u1)"]')
        .replace('u = ["sqrt(1 - t)"]', 'u = ["0.5*sin(t)"]')
        .replace("lower = [0]\nupper = [1]", "lower = [-0.5]\nupper = [0.5]")
    )
    assert "sqrt(u1)" in text and "lower = [-0.5]" in text
    with pytest.raises(InfeasibleError, match="no finite interval bound on E"):
        api.design(api.load_spec_text(text, "sqrt-f.toml"))


# -- mutation review 27: the K-rule's new condition (K itself satisfies the rule) -------------
def test_K_rule_decides_K_at_the_lower_bound(example) -> None:
    """mutation review 27, restated in session 29. ΔT = lo/63, lo the 113-bit lower bound of
    log 1.5 at the K-rule's precision: 63·ΔT·L_f = lo < log 1.5 is true and 64·ΔT ≥ hi, so
    K = 63 is the largest — it failed while 113 bits did not decide it, and is certified now
    that an undecided side gets more bits. ΔT = hi/63 puts 63·ΔT above log 1.5: K = 63 breaks
    the rule, proved (exit 1)."""
    sp, _ = example
    v = _consistent(sp)
    assert v["L_f"] == 1 and v["kappa"] == fmpq(3, 2) and v["K"] == 63
    bits = D.K_bits(v["dT"] * v["L_f"])
    lo, hi = ivq.log_bounds(fmpq(3, 2), bits)
    dT = lo / 63
    assert D.K_bits(dT) == bits and 64 * dT >= hi
    assert _certified(sp, dict(v, dT=dT, dtau=63 * dT))["K-rule"] == ClaimStatus.CERTIFIED
    dT = hi / 63
    c = _claims(sp, dict(v, dT=dT, dtau=63 * dT))["K-rule"]
    assert c.status == ClaimStatus.FAILED and not c.float_ok and "K itself breaks" in c.detail


def test_K_rule_K_one_with_a_small_L_f_is_not_the_rule(example) -> None:
    """mutation review 27 (kills claims.x_certify__mutmut_408: `K == 1 and ΔT·L_f ≥ hi` →
    `ΔT/L_f ≥ hi`). With L_f = 2⁻¹⁰, ΔT·L_f ≈ 6·10⁻⁶ is far below log 1.5, so the rule's K
    is about 6.5·10⁴ and K = 1 fails K-rule; ΔT/L_f ≈ 6.5 ≥ log 1.5 certified it."""
    sp, _ = example
    L_f = fmpq(1, 1024)
    v = _consistent(sp, L_f=L_f, K=1)
    assert v["K"] == 1 and 2 * v["dT"] * L_f < fmpq(2, 5) < v["dT"] / L_f
    assert _certified(sp, v)["K-rule"] == ClaimStatus.FAILED


def test_K_rule_works_at_the_precision_of_dT_times_L_f(example) -> None:
    """mutation review 27 (kills claims.x_certify__mutmut_394: `K_bits(ΔT·L_f)` →
    `K_bits(ΔT/L_f)`). With L_f = 2⁻¹⁰ the rule's K is ≈ 6.5·10⁴ and K_bits(ΔT·L_f) = 131;
    ΔT is set so that (K+1)·ΔT·L_f equals the 131-bit upper bound hi of log 1.5 exactly, so
    K-rule holds (≥) and is certified. At the precision of ΔT/L_f (114 bits) the upper
    bound is above hi, and the same true claim failed."""
    sp, _ = example
    L_f = fmpq(1, 1024)
    v = _consistent(sp, L_f=L_f)
    K = int(v["K"])
    assert K > 60000
    bits = D.K_bits(v["dT"] * L_f)
    lo, hi = ivq.log_bounds(fmpq(3, 2), bits)
    dT = hi / ((K + 1) * L_f)
    assert D.K_bits(dT * L_f) == bits and K * dT * L_f < lo
    assert ivq.log_bounds(fmpq(3, 2), D.K_bits(dT / L_f))[1] > hi  # the mutant's bound
    w = dict(v, dT=dT, dtau=K * dT)
    assert _certified(sp, w)["K-rule"] == ClaimStatus.CERTIFIED


#: γ⋆ (60 digits) for which 63·ΔT lies 1.7e-59 below ln 1.5 ("dn": the largest K is 63) or
#: 4.6e-59 above it ("up": 62); ΔT = γ⋆/4 with α = 1/2 and L_f = L_h = f_sup = 1
_TIE_GAMMA = {
    "dn": (
        "0.025743816387819960760508769235831691210920026886507568102476",
        "0.077231449163459882281526307707495073632760080659522704307428",
    ),
    "up": (
        "0.025743816387819960760508769235831691210920026886507568102480",
        "0.077231449163459882281526307707495073632760080659522704307440",
    ),
}


def _tie_spec(side: str, extra: str = "") -> str:
    return _scalar_spec(*_TIE_GAMMA[side], "1.5", extra)


def _scalar_spec(g_star: str, g0: str, kappa: str, extra: str = "") -> str:
    """ẋ = −x, y = x on E = [−1, 1] with the exact constants L_f = L_h = f_sup = 1 given,
    α = 1/2: the spec of the near-tie tests (γ⋆, γ₀, κ as TOML literals)."""
    return f"""[system]
time = "continuous"
states = ["x1"]
f = ["-x1"]
h = ["x1"]
[method]
key = "search-space"
alpha = 0.5
gamma_star = {g_star}
gamma0 = {g0}
L_f = 1
L_h = 1
f_sup = 1
kappa = {kappa}
{extra}[method.E]
lower = [-1]
upper = [1]
[method.D]
lower = [-0.5]
upper = [0.5]
"""


def _largest_K(side: str) -> int:
    """The largest K with K·ΔT < ln 1.5, by mpmath at 300 digits (independent)."""
    from fractions import Fraction

    import mpmath as mp

    with mp.workdps(300):
        dT = Fraction(_TIE_GAMMA[side][0]) / 4
        return int(mp.floor(mp.log(mp.mpf(3) / 2) / (mp.mpf(dT.numerator) / dT.denominator)))


@pytest.mark.parametrize("side", ["dn", "up"])
def test_K_rule_decides_a_near_tie(side: str) -> None:
    """63·ΔT within 1e-58 of ln 1.5: the design picks the largest K (62 where 63 was largest,
    and "a larger K also keeps Lemma 2's horizon" beside the right K: search-space trial,
    session 29) and every claim certifies; K = 63 given on the 'dn' side certifies Lemma 2
    (it failed "by at least −4.36e-35")."""
    want = _largest_K(side)
    assert want == (63 if side == "dn" else 62)
    rep = api.design(api.load_spec_text(_tie_spec(side), "tie.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    assert rep.parameters["K"] == want
    if side == "dn":
        given = api.design(api.load_spec_text(_tie_spec(side, "K = 63\n"), "tie.toml"))
        assert given.exit_code() == 0, [(c.id, c.detail) for c in given.failed]


@pytest.mark.parametrize(
    ("side", "K", "why"), [("dn", 62, "a larger K also keeps"), ("up", 63, "K itself breaks")]
)
def test_K_rule_near_a_tie_refuses_the_wrong_K(side: str, K: int, why: str) -> None:
    """A report whose K is one off at the near tie fails K-rule with the side proved (exit
    1); the lemma 2 claim of a K one too large fails with a positive excess."""
    rep = api.design(api.load_spec_text(_tie_spec(side), "tie.toml"))
    p = rep.parameters
    p["K"] = fmpq(K)
    p["dtau"] = K * p["dT"]
    claims = {c.id: c for c in api.certify(api.load_spec_text(_tie_spec(side), "tie.toml"), p)}
    assert claims["K-rule"].status == ClaimStatus.FAILED and why in claims["K-rule"].detail
    assert not claims["K-rule"].float_ok
    lemma2 = claims["lemma2-consistency"]
    if K > _largest_K(side):
        assert lemma2.status == ClaimStatus.FAILED and not lemma2.float_ok
        assert "by at least" in lemma2.detail and "−" not in lemma2.detail.split("by at least")[1]
    else:
        assert lemma2.status == ClaimStatus.CERTIFIED


def test_K_rule_undecided_at_the_cap_is_inconclusive(monkeypatch: pytest.MonkeyPatch) -> None:
    """With the cap at 150 bits the near tie cannot be decided: the design keeps the K it
    proved (62 on the 'dn' side) and K-rule is inconclusive (exit 4: no proof either way),
    not failed; Lemma 2 holds for 62."""
    from obsdesign.methods.searchspace import claims as SC

    monkeypatch.setattr(D, "MAX_K_BITS", 150)
    monkeypatch.setattr(SC, "MAX_K_BITS", 150)
    rep = api.design(api.load_spec_text(_tie_spec("dn"), "tie.toml"))
    assert rep.parameters["K"] == 62 and rep.exit_code() == 4
    (bad,) = rep.failed
    assert bad.id == "K-rule" and bad.float_ok and "not decided at 150 bits" in bad.detail


def test_log_compare_decides_by_doubling_and_says_when_it_cannot() -> None:
    """x against ln r: decided at the precision that separates them, None at the cap; r = 1
    exactly (ln 1 = 0)."""
    import mpmath as mp

    with mp.workdps(400):
        ln15 = mp.log(mp.mpf(3) / 2)
        near = Q(mp.nstr(ln15 + mp.mpf(10) ** -300, 390))  # 1e-300 above ln 1.5
    assert ivq.log_compare(near, fmpq(3, 2))[0] == 1
    d, lo, hi = ivq.log_compare(near, fmpq(3, 2), max_bits=500)
    assert d is None and lo <= near <= hi
    assert ivq.log_compare(fmpq(0), fmpq(1))[0] == 0
    assert ivq.log_compare(fmpq(-1), fmpq(1))[0] == -1
    assert ivq.log_compare(fmpq(2, 5), fmpq(3, 2))[0] == -1  # ln 1.5 ≈ 0.405


@pytest.mark.parametrize(("boxes", "ok"), [(20_000, True), (20_001, False), (10**8, False)])
def test_bound_boxes_is_capped(boxes: int, ok: bool) -> None:
    """bound_boxes = 10⁸ ran for hours in design, and in verify of a 3-KB report whose
    embedded spec asked for it (search-space trial, session 29): at most 20,000, exit 2
    naming the key above (the spec is only loaded here, not designed)."""
    from obsdesign.methods.searchspace import options as O

    text = SPEC.read_text().replace("[method]\n", f"[method]\nbound_boxes = {boxes}\n", 1)
    assert O.MAX_BOUND_BOXES == 20_000
    if ok:
        assert api.load_spec_text(text, "b.toml").options.bound_boxes == boxes
    else:
        with pytest.raises(SpecError, match=r"\[method\.bound_boxes\] expected at most 20,000"):
            api.load_spec_text(text, "b.toml")


# --- Mutation review 29: K-rule / Lemma 2 near a tie
# uses _tie_spec, _largest_K, D, api, fmpq, ClaimStatus, TEXT from this module


def _capped(monkeypatch: pytest.MonkeyPatch, bits: int = 150) -> None:
    from obsdesign.methods.searchspace import claims as SC

    monkeypatch.setattr(D, "MAX_K_BITS", bits)
    monkeypatch.setattr(SC, "MAX_K_BITS", bits)


def _tie_claims(side: str, K: int) -> dict:
    """The claims of the tie spec's design with K replaced (and Δτ = K ΔT)."""
    sp = api.load_spec_text(_tie_spec(side), "tie.toml")
    p = api.design(sp).parameters
    p["K"] = fmpq(K)
    p["dtau"] = K * p["dT"]
    return {c.id: c for c in api.certify(sp, p)}


def test_lemma2_undecided_at_the_cap_is_inconclusive(monkeypatch: pytest.MonkeyPatch) -> None:
    """K = 63 given on the 'dn' side: 63·ΔT lies 1e-58 below ln 1.5, so 150 bits cannot
    decide Lemma 2: it fails as inconclusive (exit 4, float_ok, "not decided"), never
    certified (mutation review 29: ``d != 1`` certified it, ``open2 = False`` made it exit 1,
    and no test had Lemma 2 undecided)."""
    _capped(monkeypatch)
    rep = api.design(api.load_spec_text(_tie_spec("dn", "K = 63\n"), "tie.toml"))
    assert rep.parameters["K"] == 63 and rep.exit_code() == 4
    (bad,) = rep.failed
    assert bad.id == "lemma2-consistency" and bad.float_ok is True
    assert "not decided at 150 bits" in bad.detail and "by at least" not in bad.detail


def test_K_rule_with_K_itself_undecided_is_not_certified(monkeypatch: pytest.MonkeyPatch) -> None:
    """K = 63 on the 'up' side is one too large (63·ΔT is 1e-58 ABOVE ln 1.5; _largest_K
    says 62). At 150 bits "K itself keeps the rule" is undecided while K + 1 = 64 surely
    breaks it: the K-rule claim must stay unproved (inconclusive), never certified
    (mutation review 29: ``itself is not False`` certified this false K-rule)."""
    assert _largest_K("up") == 62
    _capped(monkeypatch)
    c = _tie_claims("up", 63)["K-rule"]
    assert c.status == ClaimStatus.FAILED and c.float_ok is True
    assert "not decided at 150 bits" in c.detail and c.margin == "0"


def test_K_rule_of_a_non_integer_K_is_false_not_inconclusive(example) -> None:
    """K = 127/2 for the example (63.5·ΔT < ln 1.5 < 64.5·ΔT, so both sides of the rule
    'hold'): the K-rule claim fails as false (float_ok False, "not an integer"), not as
    inconclusive (mutation review 29: dropping ``k_int`` from ``open_`` made it exit 4)."""
    sp, rep = example
    p = rep.parameters
    p = Parameters({**{k: p[k] for k in p}, "K": fmpq(127, 2), "dtau": fmpq(127, 2) * p["dT"]})
    c = {c.id: c for c in api.certify(sp, p)}["K-rule"]
    assert c.status == ClaimStatus.FAILED and c.float_ok is False
    assert "not an integer" in c.detail


@pytest.mark.parametrize(("side", "K"), [("dn", 62), ("up", 63)])
def test_K_rule_margin_of_a_wrong_K_is_negative(side: str, K: int) -> None:
    """The margin a failed K-rule records is the proved distance (negative) on the side that
    fails: lower bound − K·ΔT·L_f when K is too large, (K+1)·ΔT·L_f − upper bound when a
    larger K also keeps the rule. At the near tie the enclosure (about 1e-36 wide) is far
    wider than the 1e-58 gap, so the other end of the enclosure gives a POSITIVE margin for
    a failed claim (mutation review 29: both swaps passed every test)."""
    from fractions import Fraction

    c = _tie_claims(side, K)["K-rule"]
    assert c.status == ClaimStatus.FAILED and not c.float_ok
    assert Fraction(c.margin) < 0, c.margin


def test_K_rule_for_kappa_at_most_L_h_is_false_for_K_above_one(example) -> None:
    """κ ≤ L_h: the rule's K is 1, so a report with K = 2 fails K-rule as false (float_ok
    False), not as inconclusive (mutation review 29: ``open_ = True`` in that branch passed)."""
    sp, rep = example
    p = dict((k, rep.parameters[k]) for k in rep.parameters)
    p["kappa"] = fmpq(1)  # = L_h
    p["K"] = fmpq(2)
    p["dtau"] = 2 * p["dT"]
    c = {c.id: c for c in api.certify(sp, Parameters(p))}["K-rule"]
    assert c.status == ClaimStatus.FAILED and c.float_ok is False
    assert "κ ≤ L_h" in c.detail


def test_lemma2_excess_at_a_near_tie_is_a_true_lower_bound() -> None:
    """K = 63 on the 'up' side: L_f·Δτ exceeds ln 1.5 by about 1e-58; the detail's "by at
    least X" must satisfy X ≤ L_f·Δτ − ln 1.5 (mpmath at 300 digits, independent). Measured
    from the enclosure's lower end it read about 1e-36, a false "at least" (mutation review
    29: the swap passed, the test only checked the sign)."""
    from fractions import Fraction

    import mpmath as mp

    lemma2 = _tie_claims("up", 63)["lemma2-consistency"]
    assert lemma2.status == ClaimStatus.FAILED and not lemma2.float_ok
    shown = lemma2.detail.split("by at least")[1].split()[0]
    shown = shown.replace("−", "-").replace("·10^", "e").rstrip(",;)")
    with mp.workdps(300):
        dT = Fraction(_TIE_GAMMA["up"][0]) / 4  # ΔT = α γ⋆ / (2 L_h f_sup) = γ⋆/4
        true = mp.mpf(63 * dT.numerator) / dT.denominator - mp.log(mp.mpf(3) / 2)
        assert true > 0
        assert mp.mpf(shown) <= true, (shown, mp.nstr(true, 5))


@pytest.mark.parametrize("boxes", [0, -3])
def test_bound_boxes_is_at_least_one(boxes: int) -> None:
    """bound_boxes below 1 is bad input naming the key (mutation review 29: ``min=0`` passed
    every test; only the upper end was tried)."""
    text = SPEC.read_text().replace("[method]\n", f"[method]\nbound_boxes = {boxes}\n", 1)
    with pytest.raises(SpecError, match=r"\[method\.bound_boxes\]"):
        api.load_spec_text(text, "b.toml")
    assert (
        api.load_spec_text(text.replace(f"= {boxes}\n", "= 1\n", 1), "b.toml").options.bound_boxes
        == 1
    )


@pytest.mark.parametrize(("boxes", "ok"), [(20_000, True), (20_001, False)])
def test_schema_agrees_with_the_bound_boxes_cap(boxes: int, ok: bool) -> None:
    """The JSON schema (editors, CI) refuses what the loader refuses: bound_boxes above
    20,000 (mutation review 29: the schema's maximum could be dropped with every test
    passing)."""
    import tomllib

    import jsonschema

    data = tomllib.loads(
        SPEC.read_text().replace("[method]\n", f"[method]\nbound_boxes = {boxes}\n", 1)
    )
    if ok:
        jsonschema.validate(data, api.schema())
    else:
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(data, api.schema())


_LN2_TIE = _scalar_spec(
    "4.40093447974568450423639442195667662270158815466822383568685402852948331409329978162452906e-2",
    "4.40093447974568450423639442195667662270158815466822383568685402852948331409329978162452906e-2",
    "1.999999999999999999999999999999999999999999999999999999999999",
)


def test_gamma_schedule_decides_e_to_the_L_f_dtau_near_2(monkeypatch: pytest.MonkeyPatch) -> None:
    """L_f Δτ within 1e-34 below ln 2 (e^(L_f Δτ)/2 = 1 − 1e-50, checked here with mpmath):
    gamma-schedule failed "e^(L_f Δτ)/2 > 1", exit 1 (re-check trial, session 29). It is
    decided at more bits and certified; capped at 150 bits it is inconclusive (exit 4)."""
    import mpmath as mp

    sp = api.load_spec_text(_LN2_TIE, "ln2.toml")
    rep = api.design(sp)
    x = rep.parameters["L_f"] * rep.parameters["dtau"]
    with mp.workdps(200):
        assert mp.log(2) - mp.mpf(int(x.p)) / int(x.q) > 0  # e^x/2 < 1: the claim is true
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    from obsdesign.methods.searchspace import claims as SC

    monkeypatch.setattr(SC, "MAX_K_BITS", 150)
    monkeypatch.setattr(D, "MAX_K_BITS", 150)
    c = {c.id: c for c in api.certify(sp, rep.parameters)}["gamma-schedule"]
    assert c.status == ClaimStatus.FAILED and c.float_ok and "not decided at 150 bits" in c.detail


def test_gamma_schedule_fails_when_e_to_the_L_f_dtau_exceeds_2() -> None:
    """The must-fail side: L_f Δτ = 7/10 and ln 2 + 1e-50 (above ln 2 ≈ 0.6931) fail
    gamma-schedule, proved (exit 1, not float_ok), "e^(L_f Δτ)/2 > 1"."""
    import mpmath as mp

    sp = api.load_spec_text(_LN2_TIE, "ln2.toml")
    p = api.design(sp).parameters
    with mp.workdps(200):
        above = Q(mp.nstr(mp.log(2) + mp.mpf(10) ** -50, 150))
    for x in (fmpq(7, 10), above):
        p["dtau"] = x / p["L_f"]
        c = {c.id: c for c in api.certify(sp, p)}["gamma-schedule"]
        assert c.status == ClaimStatus.FAILED and not c.float_ok, x
        assert "e^(L_f Δτ)/2 > 1" in c.detail


_LINEAR = """
[system]
time = "continuous"
states = ["x1"]
f = ["{f}"]
h = ["2*x1"]
[method]
key = "search-space"
alpha = 0.000000001
gamma_star = 0.1
gamma0 = 0.5
{given}
E = {{lower = [-1], upper = [1]}}
D = {{lower = [-0.5], upper = [0.5]}}
"""


@pytest.mark.parametrize(
    ("f", "k", "value", "want"),
    [
        ("0", "L_h", "1.999999", ClaimStatus.FAILED),  # 5·10⁻⁷ below: inside float tolerance
        ("0", "L_h", "1.99999999999", ClaimStatus.FAILED),  # 5·10⁻¹² below
        ("0", "L_h", "2", ClaimStatus.CERTIFIED),
        ("1", "f_sup", "0.9999999", ClaimStatus.FAILED),
        ("1", "f_sup", "1", ClaimStatus.CERTIFIED),
        ("0.5*x1", "L_f", "0.49999999", ClaimStatus.FAILED),
        ("0.5*x1", "L_f", "0.5", ClaimStatus.CERTIFIED),
        # the secant shrunk towards the derivative: 10⁻⁹ below the constant 3 of x1² on
        # [0, 3/2] was numerical with the 2·10⁻⁶ secant alone (re-check trial, session 31)
        ("x1^2@", "L_h", "2.999999997", ClaimStatus.FAILED),
        ("x1^2@", "L_h", "3", ClaimStatus.CERTIFIED),
    ],
)
def test_a_given_constant_below_a_proved_quotient_fails(
    f: str, k: str, value: str, want: ClaimStatus
) -> None:
    """Session 31 (search-space trial): a given L_h = 1.999999 for h = 2·x1 (constant exactly
    2) was 5·10⁻⁷ below the sampled 2, inside the 10⁻⁶ float tolerance of the safety net, so
    L_h-bound stayed "numerical" beside claims built on it, exit 0, and `simulate` lost the
    state. The best sample is now proved at its exact points: a given value below it fails,
    with the points in the detail; the true constant itself is certified."""
    text = _LINEAR.format(f=f, given=f"{k} = {value}")
    if f == "x1^2@":  # h = x1² on E = [0, 3/2]
        text = _LINEAR.format(f="0", given=f"{k} = {value}").replace('"2*x1"', '"x1^2"')
        text = text.replace("lower = [-1], upper = [1]", "lower = [0], upper = [1.5]")
        text = text.replace("lower = [-0.5], upper = [0.5]", "lower = [0], upper = [0.5]")
    assert _constant_status(text, k, Q(value)) == want
    if want == ClaimStatus.FAILED:
        rep = api.design(api.load_spec_text(text, "g.toml"))
        claim = next(c for c in rep.claims if c.id == f"{k}-bound")
        assert claim.status == ClaimStatus.FAILED and rep.exit_code() == 1
        assert "(exact interval evaluation)" in claim.detail


def test_a_schedule_entry_within_the_113_bit_enclosure_is_decided_at_more_bits() -> None:
    """γ₁ rounded up from γ₀ e^(L_f Δτ)/2 by less than 10⁻⁴⁰ (a true entry: the rule allows
    10⁻¹² relative) lies inside the 113-bit enclosure of the target, and verify refused it
    "is not …" with the entry inside the printed interval (search-space trial, session 31).
    The enclosure is refined (doubled up to MAX_K_BITS): the entry certifies, and an entry
    10⁻⁴⁰ below the target still fails."""
    from obsdesign.certify import interval as I
    from obsdesign.certify.claim import Claims
    from obsdesign.certify.interval import iv
    from obsdesign.methods.searchspace import claims as C

    L_f, dtau, g_star = fmpq(1), fmpq(1, 10), fmpq(1, 100)
    lo, hi = I.bounds(iv.exp, L_f * dtau, bits=1024)
    scale = 10**40
    up = fmpq(-((-hi.p * scale // 2) // hi.q), scale)  # ⌈e^x/2 · 10⁴⁰⌉ / 10⁴⁰ (γ₀ = 1)
    down = fmpq((lo.p * scale // 2) // lo.q - 1, scale)  # below e^x/2 by at least 10⁻⁴⁰
    e_hi = D.exp_upper(L_f * dtau)
    assert lo / 2 < up < e_hi / 2  # inside the 113-bit enclosure: undecided at 113 bits

    def claim_of(g1: fmpq):  # noqa: ANN202
        c = Claims()
        C._schedule(c, [fmpq(1), *D.schedule(g1, g_star, L_f, dtau)], g_star, L_f, dtau)
        (claim,) = c
        return claim

    assert claim_of(up).status == ClaimStatus.CERTIFIED
    bad = claim_of(down)
    assert bad.status == ClaimStatus.FAILED
    # by how much, from the enclosure that decided (the 113-bit interval printed alone
    # looked as if it held the entry; re-check trial, session 31)
    m = re.search(r"below the rule's value by at least (\S+)$", bad.detail)
    assert m is not None and Q(m[1]) > 0 and Q(m[1]) <= lo / 2 - down


def test_a_schedule_with_a_ratio_within_1e_14_of_one_still_reaches_gamma_star() -> None:
    """e^(L_f Δτ)/2 = 1 − 1.1·10⁻¹⁶ (Δτ = 0.6931471805599452, just below ln 2, L_f = 1): the
    14-digit rounding gave γ_i back, the schedule stalled at γ₀ for 100,000 entries and the
    design said "shrinks too slowly" (exit 1), where the rule reaches γ⋆ in about 9,000
    steps (re-check trial, session 31). More digits where 14 make no progress: it reaches γ⋆,
    strictly decreasing, and the claim certifies it."""
    _reaches_and_certifies(Q("0.1000000000001"), fmpq(1, 10), fmpq(1), Q("0.6931471805599452"))


def _reaches_and_certifies(g0: fmpq, g_star: fmpq, L_f: fmpq, dtau: fmpq) -> None:
    """The design's schedule from γ₀ reaches γ⋆ within the cap, strictly decreasing, and the
    gamma-schedule claim certifies it."""
    gam = D.schedule(g0, g_star, L_f, dtau)
    assert gam[-1] == g_star and len(gam) < D.MAX_SCHEDULE
    assert all(a > b for a, b in zip(gam, gam[1:], strict=False))
    c = Claims()
    C._schedule(c, gam, g_star, L_f, dtau)
    (claim,) = c
    assert claim.status == ClaimStatus.CERTIFIED, claim.detail


def test_a_refuted_constant_prints_a_bound_above_it() -> None:
    """h = sin(x1), given L_h = 0.999999999: refuted, and the detail's proved bound was
    printed "≥ 0.99999999" (8 digits, below the value it refutes; re-check trial, session 31).
    It takes as many digits as show it above the value."""
    text = _LINEAR.format(f="0", given="L_h = 0.999999999").replace('"2*x1"', '"sin(x1)"')
    rep = api.design(api.load_spec_text(text, "s.toml"))
    claim = next(c for c in rep.claims if c.id == "L_h-bound")
    assert claim.status == ClaimStatus.FAILED
    m = re.search(r"the difference quotient ≥ (\S+) between", claim.detail)
    assert m is not None and Q(m[1]) > Q("0.999999999")


def test_a_refuted_irrational_constant_prints_enough_digits() -> None:
    """h = (x1 + x2, x1 − x2) has every quotient √2; a given L_h 1.7·10⁻²¹ below it is
    refuted, and the printed bound came from a square root good to 10⁻¹² only, below the
    value (re-check trial, session 31). The root is taken to the digits printed."""
    text = (
        '[system]\ntime = "continuous"\nstates = ["x1", "x2"]\nf = ["-x1", "-x2"]\n'
        'h = ["x1 + x2", "x1 - x2"]\n[method]\nkey = "search-space"\nalpha = 0.5\n'
        "gamma_star = 0.1\ngamma0 = 1\nL_h = 1.4142135623730950488\n"
        "E = {lower = [-1, -1], upper = [1, 1]}\nD = {lower = [-0.5, -0.5], upper = [0.5, 0.5]}\n"
    )
    rep = api.design(api.load_spec_text(text, "s.toml"))
    claim = next(c for c in rep.claims if c.id == "L_h-bound")
    assert claim.status == ClaimStatus.FAILED
    m = re.search(r"the difference quotient ≥ (\S+) between", claim.detail)
    assert m is not None and Q(m[1]) > Q("1.4142135623730950488")


#: e^(L_f Δτ)/2 = 1 − 5·10⁻¹³¹: the exact rule reaches γ⋆ in 2,000 steps
RATIO_NEAR_ONE = (
    '[system]\ntime = "continuous"\nstates = ["x1"]\nf = ["-x1"]\nh = ["x1"]\n'
    '[method]\nkey = "search-space"\nalpha = 1e-133\ngamma_star = 0.1\n'
    f"gamma0 = 0.1{'0' * 126}1\nkappa = 1.{'9' * 130}\n"
    "E = {lower = [-1], upper = [1]}\nD = {lower = [-0.5], upper = [0.5]}\n"
)


def test_a_ratio_within_1e_130_of_one_is_bounded_below_one_at_more_bits() -> None:
    """The 113-bit upper bound of e^(L_f Δτ)/2 = 1 − 5·10⁻¹³¹ is above 1: the design listed
    γ₀ alone and ended exit 1 with no reason, and its note said "γ reaches γ⋆ after 0
    switches" (re-check trial, session 31). The bound is taken at more bits: the schedule
    reaches γ⋆ in 2,000 steps, certified, and verify agrees."""
    rep = api.design(api.load_spec_text(RATIO_NEAR_ONE, "near.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    gam = list(rep.parameters.get("gamma_schedule"))
    assert len(gam) == 2001 and gam[-1] == fmpq(1, 10)
    assert any("γ reaches γ⋆ after 2000 switches" in n for n in rep.notes)
    assert api.verify(rep).exit_code() == 0
    # ln 2 cut after 70 digits: e^x/2 ≈ 1 − 3·10⁻⁷¹, above 1 at 113 bits, below at more
    x = Q("0.6931471805599453094172321214581765680755001343602552541206800094933936")
    r = D.schedule_ratio(x)
    assert D.exp_upper(x) / 2 >= 1 and r is not None and r < 1 and 1 - r < Q("1e-70")


def test_a_schedule_the_design_stopped_says_why() -> None:
    """A schedule that ends before γ⋆ without reaching the cap said only "ends at γ₀, not at
    γ⋆" (re-check trial, session 31): the claim now names the reason, the ratio too close to
    1 when e^(L_f Δτ)/2 < 1, else that γ⋆ is not a fixed point."""
    from obsdesign.certify.claim import Claims
    from obsdesign.methods.searchspace import claims as C

    g0, g_star = Q("0.2"), fmpq(1, 10)
    for dtau, why in (
        (Q("0.5"), "the design stopped after 1 entries"),
        (Q("0.7"), "not shown below 1"),
    ):
        c = Claims()
        C._schedule(c, [g0], g_star, fmpq(1), dtau)
        (claim,) = c
        assert claim.status == ClaimStatus.FAILED and why in claim.detail, claim.detail
    assert D.schedule_ratio(Q("0.7")) is None and D.schedule_ratio(Q("0.5")) < 1


def test_long_entries_only_where_the_schedule_is_short() -> None:
    """Entries of up to 1,024 digits where few reach γ⋆ (γ₀ within 10⁻¹²⁸ of γ⋆, factor
    1 − 5·10⁻¹³¹), but 112 where the schedule would be long (γ₀ = 2γ⋆ with the factor
    1 − 10⁻²⁰⁰ needs ~10²⁰⁰ entries): 100,000 entries of 1,000 digits make a report of
    hundreds of MB. There the schedule stops at once and the claim says why."""
    near = 1 - Q("5e-131")
    assert D._most_digits(Q("0.1") + Q("1e-128"), fmpq(1, 10), near) == D.SCHEDULE_MAX_DIGITS
    far = 1 - Q("1e-200")
    assert D._most_digits(Q("0.2"), fmpq(1, 10), far) == D.SCHEDULE_LONG_DIGITS
    assert D._most_digits(Q("0.2"), fmpq(1, 10), None) == D.SCHEDULE_DIGITS
    assert D._most_digits(Q("0.2"), fmpq(1, 10), 1 - Q("1e-400")) == D.SCHEDULE_LONG_DIGITS


def test_a_schedule_far_beyond_the_cap_is_refused_before_listing() -> None:
    """κ = 2(1 − 10⁻¹²) makes e^(L_f Δτ)/2 ≈ 1 − 10⁻¹²: from γ₀ = 2γ⋆ the rule needs ~7·10¹¹
    entries. Listed up to the 100,000-entry cap such schedules were failed reports of up to
    70 MB after 20 s (session 32); the design now stops at once, exit 1, saying how many
    entries the rule needs. _steps_estimate is within a factor 2 above the true count."""
    text = RATIO_NEAR_ONE.replace(f"gamma0 = 0.1{'0' * 126}1", "gamma0 = 0.2").replace(
        f"kappa = 1.{'9' * 130}", "kappa = 1.999999999998"
    )
    assert "gamma0 = 0.2" in text and "kappa = 1.999999999998" in text
    with pytest.raises(InfeasibleError, match=r"needs about 6\.9e\+11 entries .* 100,000"):
        api.design(api.load_spec_text(text, "far.toml"))
    r = fmpq(9, 10)
    est = D._steps_estimate(fmpq(2), fmpq(1), r)
    k = next(k for k in range(100) if r**k <= fmpq(1, 2))  # the rule's exact count
    assert k - 1 <= est <= 2 * k


def test_a_given_constant_of_an_expression_beyond_the_float_range_is_refuted() -> None:
    """h = (x1 + 2^1100) − 2^1100 is exactly x1: with a given L_h = 0.5 the float samples
    were all inf − inf, the claim stayed numerical and the design certified 13 claims on it,
    exit 0 (soundness trial, session 33). The exact quotient across E refutes it, and the
    design without L_h still certifies L_h = 1."""
    text = (
        '[system]\ntime = "continuous"\nstates = ["x1"]\nf = ["-x1"]\n'
        'h = ["(x1 + 2^1100) - 2^1100"]\n[method]\nkey = "search-space"\nalpha = 0.9\n'
        "gamma_star = 0.05\ngamma0 = 1\nL_h = 0.5\n"
        "E = {lower = [-1], upper = [1]}\nD = {lower = [0], upper = [0.5]}\n"
    )
    rep = api.design(api.load_spec_text(text, "big.toml"))
    claim = next(c for c in rep.claims if c.id == "L_h-bound")
    assert claim.status == ClaimStatus.FAILED and rep.exit_code() == 1
    assert "the difference quotient ≥ 1 between (-1.0) and (1.0)" in claim.detail, claim.detail
    rep = api.design(api.load_spec_text(text.replace("L_h = 0.5\n", ""), "big2.toml"))
    assert rep.exit_code() == 0 and rep.parameters["L_h"] == 1


def test_a_tiny_signed_power_in_h_is_certified() -> None:
    """h = x1 + (x1 + 3)^(−700) was certified until signed literals took the integer-power
    rule, then exit 1 "no finite interval bound" (re-check trial, session 33): certified
    again, L_h = 1 (rounded up)."""
    text = (
        '[system]\ntime = "continuous"\nstates = ["x1", "x2"]\nf = ["x2", "-x1"]\n'
        'h = ["x1 + (x1+3)^(-700)"]\n[method]\nkey = "search-space"\nalpha = 0.9\n'
        "gamma_star = 0.05\ngamma0 = 1\n"
        "E = {lower = [-1, -1], upper = [1, 1]}\nD = {lower = [-0.5, -0.5], upper = [0.5, 0.5]}\n"
    )
    rep = api.design(api.load_spec_text(text, "neg.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    assert rep.parameters["L_h"] == 1


OVERFLOW_BASE = (
    '[system]\ntime = "continuous"\nstates = ["x1", "x2"]\nF\nH\nU_SIG\n[method]\n'
    'key = "search-space"\nalpha = 0.9\ngamma_star = 0.05\ngamma0 = 1\nGIVEN\n'
    "E = {lower = [-1, -1], upper = [1, 1]}\nD = {lower = [0, -0.5], upper = [0, 0.5]}\nU_SET\n"
)


def _overflow_spec(f: str, h: str, given: str, inputs: bool = False) -> str:
    return (
        OVERFLOW_BASE.replace("F", f"f = [{f}]")
        .replace("H", f"h = [{h}]")
        .replace("GIVEN", given)
        .replace("U_SIG", 'u = ["0.5+0.5*sin(t)"]' if inputs else "")
        .replace("U_SET", "U = {lower = [0], upper = [1]}\nhorizon = 2" if inputs else "")
    )


@pytest.mark.parametrize(
    "f, h, given, true, inputs, claim",
    [
        # f exactly (x2, −x1), |f| = √2 at a corner, 0 at the midpoint the fallback took
        (
            '"(x2 + 2^1100) - 2^1100", "-x1"',
            '"x1"',
            "f_sup = 0.5",
            "f_sup = 1.4142135623730951",
            False,
            "f_sup",
        ),
        # h exactly x1 + x1² (L_h = 3), floats finite only for |x1| < 0.134
        ('"x2", "-x1"', '"x1 + (x1*10^300)*(x1*10^10)/10^310"', "L_h = 2", "L_h = 3", False, "L_h"),
        # f exactly u1·(x2, −x1): L_f = 1 at u1 = 1, 1/2 at the input's midpoint
        (
            '"u1*((x2 + 2^1100) - 2^1100)", "-u1*((x1 + 2^1100) - 2^1100)"',
            '"x1"',
            "L_f = 0.7\nf_sup = 1.5",
            "L_f = 1\nf_sup = 1.5",
            True,
            "L_f",
        ),
    ],
)
def test_given_constants_where_floats_overflow_on_part_of_the_box_are_refuted(
    f: str, h: str, given: str, true: str, inputs: bool, claim: str
) -> None:
    """The fallback of session 33 proved only the sampled witness, or the box's midpoint
    where every sample overflowed: a given f_sup, an L_h reached where floats overflow, and
    an L_f reached at an input's extreme stayed numerical beside 12-13 certified claims, exit
    0 (re-check trial, session 33). Where floats overflowed the box's corners are proved too:
    refuted, exit 1; the true constants are not."""
    rep = api.design(api.load_spec_text(_overflow_spec(f, h, given, inputs), "o.toml"))
    c = next(c for c in rep.claims if c.id == f"{claim}-bound")
    assert c.status == ClaimStatus.FAILED and rep.exit_code() == 1, c.detail
    assert "exact interval evaluation" in c.detail
    rep = api.design(api.load_spec_text(_overflow_spec(f, h, true, inputs), "t.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]


def test_a_schedule_whose_entries_need_more_digits_than_allowed_is_refused() -> None:
    """γ₀ = γ⋆ + 2·10⁻¹²⁷ with e^(L_f Δτ)/2 = 1 − 5·10⁻¹³¹: the rule reaches γ⋆ in ~40,000
    entries of ~134 digits, above the digits a design lists, so entries are cut to 112 digits,
    at which γ r rounds up to γ. The design listed γ₀ alone and the claim blamed "1,024
    significant digits" (re-check trial, session 32, F5); it is now refused before listing,
    exit 1, with the count and the digits the rule needs. _places works below the float
    range (a float of 1 − r was 0 there and math.log10 raised)."""
    text = RATIO_NEAR_ONE.replace(f"gamma0 = 0.1{'0' * 126}1", f"gamma0 = 0.1{'0' * 125}2")
    assert f"gamma0 = 0.1{'0' * 125}2" in text
    with pytest.raises(
        InfeasibleError, match=r"needs about 4e\+04 entries of about 133 significant digits"
    ):
        api.design(api.load_spec_text(text, "long.toml"))
    assert D._places(fmpq(3, 4)) == pytest.approx(math.log10(4))
    tiny = fmpq(1, 10**400)
    assert D._places(1 - tiny) == pytest.approx(400)
    assert D._most_digits(fmpq(1, 10) + tiny, fmpq(1, 10), 1 - tiny) == D.SCHEDULE_MAX_DIGITS


def test_a_schedule_between_twice_and_ten_times_the_cap_is_refused_before_listing() -> None:
    """The rule needs at least est/2 entries: est ≈ 5·10⁵ (γ₀ = 2γ⋆, 1 − e^(L_f Δτ)/2 ≈
    1.4·10⁻⁶) cannot reach γ⋆ within the 100,000 listed; at 10× the cap such schedules were
    listed to it, 25 s and a 50 MB failed report (re-check trial, session 33). Beyond the float
    range the count reads "more than 10³⁰⁸" (it read "about inf"), and 1 − r below it "10^-N"."""
    import mpmath

    with pytest.raises(InfeasibleError, match=r"needs about 5e\+05 entries"):
        D.schedule(fmpq(2, 10), fmpq(1, 10), fmpq(1), Q("0.6931458"))
    with mpmath.workdps(340):
        x = Q(mpmath.nstr(mpmath.log(2), 330, strip_zeros=False)[:322])
    with pytest.raises(InfeasibleError, match="needs more than 10³⁰⁸ entries"):
        D.schedule(fmpq(2, 10), fmpq(1, 10), fmpq(1), x)
    assert D._gap(1 - fmpq(1, 10**400)) == "10^-400"


def test_a_K_beyond_the_float_range_is_named() -> None:
    """alpha = 3·10⁻³⁰⁸ makes ΔT ≈ 10⁻³⁰⁹ and K ≈ 10³⁰⁸: the report's float view overflowed
    in a claim, exit 4 "a number is beyond the float range (integer division result too large
    for a float)", naming none (re-check trial, session 33). It is refused naming K."""
    from obsdesign.errors import InconclusiveError

    text = RATIO_NEAR_ONE.replace("alpha = 1e-133", "alpha = 3e-308")
    assert "alpha = 3e-308" in text
    with pytest.raises(InconclusiveError, match=r"K ≈ 10\^308 samples per Δτ .* a larger alpha"):
        api.design(api.load_spec_text(text, "k.toml"))
    # a K of 1,024 bits below 1.8·10³⁰⁸ has a double: designed (a bit count refused it)
    assert D._fits_float(2**1023 + 2**1000) and not D._fits_float(2**1024)


def test_the_entries_estimate_takes_ratios_beyond_the_float_range() -> None:
    """γ₀/γ⋆ = 10⁴⁰⁰ at r = 3/4 needs ln(10⁴⁰⁰)/ln(4/3) ≈ 3,200 entries: the float ratio made
    the estimate inf and the design refused it, "needs about inf entries", exit 1 (a
    regression of the refusal beyond 10× the cap; re-check trial, session 32). Ratios and
    gaps below the float range are estimated from their exact quotient."""
    est = D._steps_estimate(fmpq(10**400), fmpq(1), fmpq(3, 4))
    assert 3000 < est < 2 * 3300
    tiny = fmpq(1, 10**400)
    assert D._steps_estimate(1 + tiny, fmpq(1), 1 - tiny * 1000) == pytest.approx(0.001)
    gam = D.schedule(fmpq(10**400), fmpq(1), fmpq(1), Q("0.4"))
    assert gam[-1] == 1 and len(gam) < 10_000


# -- mutation review 32 (session 31's checks) ----------------------------------------
def _ceil(x: fmpq, scale: int) -> fmpq:
    return fmpq(-((-x.p * scale) // x.q), scale)


def _floor(x: fmpq, scale: int) -> fmpq:
    return fmpq((x.p * scale) // x.q, scale)


def test_follows_decides_the_upper_side_inside_the_113_bit_enclosure() -> None:
    """Kills C23 (sure_high with e_hi: accepts an entry above the allowed maximum that lies
    within the 113-bit enclosure) and C25 (not_high with e_lo: refuses an entry below it that
    lies within the enclosure). γ = 1, x = 1/10: the allowed maximum is
    e^x/2·(1 + SCHEDULE_RTOL); entries 10⁻⁴⁰ above / below it are undecided at 113 bits."""
    g, g_star, x = fmpq(1), fmpq(1, 100), fmpq(1, 10)
    e_lo, e_hi = I.bounds(iv.exp, x, bits=I.PREC)
    lo, hi = I.bounds(iv.exp, x, bits=1024)
    r = 1 + D.SCHEDULE_RTOL
    scale = 10**40
    above = _ceil(hi / 2 * r, scale) + fmpq(1, scale)
    below = _floor(lo / 2 * r, scale) - fmpq(1, scale)
    assert e_lo / 2 * r < below < above < e_hi / 2 * r  # both inside the 113-bit enclosure
    assert C._follows(g, above, g_star, x, e_lo, e_hi)[0] is False
    assert C._follows(g, below, g_star, x, e_lo, e_hi)[0] is True


def test_sqrt_down_is_a_lower_bound_within_the_digits() -> None:
    """Kills C15 (isqrt + 1: above √x) and C18 (√p/√d taken separately: not √(p/d))."""
    for x in (Fraction(4), Fraction(2), Fraction(2, 3), Fraction(1, 10**30), Fraction(10**30, 7)):
        for d in (4, 12, 30):
            s = C._sqrt_down(x, d)
            sq = Fraction(int(s.p), int(s.q)) ** 2
            assert sq <= x, (x, d)
            assert sq > x * (1 - Fraction(3, 10**d)), (x, d)
    assert C._sqrt_down(Fraction(4), 12) == 2 and C._sqrt_down(Fraction(9, 4), 12) == fmpq(3, 2)


def test_coord_marks_only_a_non_float_coordinate() -> None:
    """Kills C13 (the ≈ mark inverted) and C14 (never marked)."""
    assert C._coord(Fraction(1, 2)) == "0.5"
    assert C._coord(Fraction(1, 3)) == "≈" + repr(1 / 3)


def test_proved_above_names_both_points_of_the_pair() -> None:
    """Kills C12 (the first point printed twice): a quotient proved between 1/2 and 1/3."""
    proof = (Fraction(4), ((Fraction(1, 2),), (Fraction(1, 3),)))
    text = C._proved_above("L_h", proof, Q("1.999999"))
    assert "between (0.5) and (≈" + repr(1 / 3) + ")" in text
    assert text.startswith("the difference quotient ≥ 2 ")


def test_follows_undecided_at_the_bit_cap_is_none(monkeypatch) -> None:  # noqa: ANN001
    """Kills C30/C31 (an undecided step reported as refuted / as following the rule): with
    the cap at 113 bits an entry 10⁻⁴⁰ from e^x/2 is neither proved nor refuted."""
    monkeypatch.setattr(C, "MAX_K_BITS", I.PREC)
    g, g_star, x = fmpq(1), fmpq(1, 100), fmpq(1, 10)
    e_lo, e_hi = I.bounds(iv.exp, x, bits=I.PREC)
    lo, hi = I.bounds(iv.exp, x, bits=1024)
    up = _ceil(hi / 2, 10**40)
    assert e_lo / 2 < up < e_hi / 2
    assert C._follows(g, up, g_star, x, e_lo, e_hi)[0] is None


def test_schedule_claim_undecided_at_the_cap_is_inconclusive(monkeypatch) -> None:  # noqa: ANN001
    """Kills C34 (an undecided step reported as false, exit 1, not inconclusive, exit 4) and
    C30/C31 through the claim: with the cap at 113 bits, γ₁ 10⁻⁴⁰ above γ₀ e^x/2 fails as
    not decided, its float check passing (inconclusive)."""
    from obsdesign.certify.claim import Claims, ClaimStatus

    monkeypatch.setattr(C, "MAX_K_BITS", I.PREC)
    L_f, dtau, g_star = fmpq(1), fmpq(1, 10), fmpq(1, 100)
    lo, hi = I.bounds(iv.exp, L_f * dtau, bits=1024)
    up = _ceil(hi / 2, 10**40)
    c = Claims()
    C._schedule(c, [fmpq(1), *D.schedule(up, g_star, L_f, dtau)], g_star, L_f, dtau)
    (claim,) = c
    assert claim.status == ClaimStatus.FAILED
    assert "not decided" in claim.detail
    assert claim.float_ok is True


# -- mutation review 32 (session 31's checks) ----------------------------------------
def test_a_schedule_with_a_ratio_within_1e_32_of_one_doubles_past_28_digits() -> None:
    ln2_lo, _ = I.bounds(iv.log, 2, bits=1024)
    L_f, dtau = fmpq(1), ln2_lo - fmpq(1, 10**32)  # e^(L_f Δτ)/2 ≈ 1 − 10⁻³²
    r = D.exp_upper(L_f * dtau) / 2
    assert 1 - fmpq(1, 10**31) < r < 1
    _reaches_and_certifies(fmpq(1, 10) + fmpq(1, 10**30), fmpq(1, 10), L_f, dtau)


# -- mutation review 33 (session 32's checks) ----------------------------------------
def test_a_schedule_just_beyond_ten_times_the_cap_is_refused() -> None:
    """L_f Δτ = 0.69314688 makes e^(L_f Δτ)/2 ≈ 1 − 3.0·10⁻⁷: from γ₀ = 2γ⋆ the rule needs
    ~2.3·10⁶ entries (between 10× and 100× MAX_SCHEDULE). The design refuses it before
    listing (kills M09, which raised the threshold to 100× and listed 100,000 entries)."""
    with pytest.raises(InfeasibleError, match=r"needs about 2\.3e\+06 entries"):
        D.schedule(fmpq(2), fmpq(1), Q("0.69314688"), fmpq(1))


def test_the_digit_budget_counts_the_margin_of_three_digits() -> None:
    """r = 1 − 10⁻⁴ from γ₀/γ⋆ = 10³⁵: ~8.06·10⁵ entries of about 4 + 3 digits = 5.6·10⁶ >
    SCHEDULE_MAX_CHARS, so 112 digits at most (kills M04, need = places without the +3:
    3.2·10⁶ ≤ 4·10⁶ gave 1,024)."""
    r = 1 - fmpq(1, 10**4)
    assert D._most_digits(fmpq(10**35), fmpq(1), r) == D.SCHEDULE_LONG_DIGITS
    assert D._most_digits(fmpq(10**20), fmpq(1), r) == D.SCHEDULE_MAX_DIGITS


def test_steps_estimate_is_ln_ratio_over_the_gap() -> None:
    """ln(γ₀/γ⋆)/(1 − r) as documented: γ₀/γ⋆ = 1.9 at r = 0.9 is ln 1.9/0.1 (kills T01,
    which took (ratio − 1)/(1 − r) for every ratio below 2), and a non-integer ratio beyond
    the float range (10⁴⁰⁰ + 1)/10²⁰⁰ is ln(p) − ln(q) (kills T03, + in place of −)."""
    import math

    assert D._steps_estimate(Q("1.9"), fmpq(1), Q("0.9")) == pytest.approx(math.log(1.9) / 0.1)
    est = D._steps_estimate(fmpq(10**400 + 1, 10**200), fmpq(1), fmpq(3, 4))
    assert est == pytest.approx(200 * math.log(10) / 0.25, rel=1e-9)


def test_steps_estimate_overflowing_quotient_is_inf() -> None:
    """γ₀/γ⋆ = 1.5 with 1 − r = 10⁻⁴⁰⁰: (ratio − 1)/(1 − r) = 5·10³⁹⁹ has no float: inf, and
    the design refuses the schedule (kills T07, which returned 0.0 there: no refusal, and
    1,024-digit entries allowed)."""
    import math

    r = 1 - fmpq(1, 10**400)
    assert D._steps_estimate(Q("1.5"), fmpq(1), r) == math.inf
    assert D._most_digits(Q("1.5"), fmpq(1), r) == D.SCHEDULE_LONG_DIGITS


_SIN = """
[system]
time = "continuous"
states = ["x1"]
f = ["F"]
h = ["H"]
[method]
key = "search-space"
alpha = 0.000000001
gamma_star = 0.1
gamma0 = 0.5
E = {lower = [-1], upper = [1]}
D = {lower = [-0.5], upper = [0.5]}
"""


def _spec(h: str, f: str = "0"):  # noqa: ANN202
    from obsdesign import api
    from obsdesign.api import bind

    return bind(api.load_spec_text(_SIN.replace("H", h).replace("F", f), "s.toml"))


def test_proofs_are_cached_per_spec_text() -> None:
    """proved_lower for h = 2·x1 (L_h = 2) and then for h = sin(x1) (L_h = 1) at the same
    value 1.5: the second proof is sin's own, never above its true constant (kills Q02: a
    cache key without the spec text handed sin the proof of 2·x1, a false refutation)."""
    D._PROOFS.clear()
    a = D.proved_lower("L_h", _spec("2*x1"), Q("1.5"))
    assert a is not None and a[0] > Fraction("1.5") ** 2
    b = D.proved_lower("L_h", _spec("sin(x1)"), Q("1.5"))
    assert b is None or b[0] <= 1


def test_proofs_are_cached_per_value() -> None:
    """A proof computed for a small value (stopping at its first pair above it) is not
    reused for a larger one: h = x1² on E = [0, 3/2] (L_h = 3): after a proof for 2 (the
    first secant, ≈ 3 − 2·10⁻⁶, suffices), L_h = 2.999999997 needs the pair shrunk towards
    the derivative (kills Q01, a cache key without the value)."""
    D._PROOFS.clear()
    from obsdesign import api
    from obsdesign.api import bind

    text = (
        _SIN.replace("H", "x1^2")
        .replace("F", "0")
        .replace("lower = [-1], upper = [1]", "lower = [0], upper = [1.5]")
        .replace("lower = [-0.5], upper = [0.5]", "lower = [0], upper = [0.5]")
    )
    sp = bind(api.load_spec_text(text, "s.toml"))
    assert D.proved_lower("L_h", sp, Q("2")) is not None
    b = D.proved_lower("L_h", sp, Q("2.999999997"))
    assert b is not None and b[0] > Fraction("2.999999997") ** 2
    D._PROOFS.clear()


def test_proofs_are_cached_per_constant() -> None:
    """f = 3·x1 (L_f = 3), h = sin(x1) (L_h = 1): the proof for L_f at 1.5 is not L_h's
    (kills Q06, a cache key without the constant's kind: L_h = 1.5 refuted by f's quotient)."""
    D._PROOFS.clear()
    sp = _spec("sin(x1)", "3*x1")
    a = D.proved_lower("L_f", sp, Q("1.5"))
    assert a is not None and a[0] > Fraction("1.5") ** 2
    b = D.proved_lower("L_h", sp, Q("1.5"))
    assert b is None or b[0] <= 1
    D._PROOFS.clear()


def test_the_printed_refuting_bound_is_below_the_proved_square_root() -> None:
    """h = sin(x1), given L_h = 0.9: refuted; the detail's "difference quotient ≥ b" must be
    true, b² ≤ the proved square (kills Q12: the first b rounded up, above the proof)."""
    import re

    from obsdesign import api
    from obsdesign.certify.claim import ClaimStatus

    D._PROOFS.clear()
    text = (
        _SIN.replace("H", "sin(x1)")
        .replace("F", "0")
        .replace("gamma0 = 0.5\n", "gamma0 = 0.5\nL_h = 0.9\n")
    )
    rep = api.design(api.load_spec_text(text, "s.toml"))
    claim = next(c for c in rep.claims if c.id == "L_h-bound")
    assert claim.status == ClaimStatus.FAILED
    m = re.search(r"the difference quotient ≥ (\S+) between", claim.detail)
    assert m is not None
    from obsdesign.api import bind

    proof = D.proved_lower("L_h", bind(api.load_spec_text(text, "s.toml")), Q("0.9"))
    assert proof is not None
    b = Q(m[1])
    assert Q("0.9") < b and b * b <= fmpq(proof[0].numerator, proof[0].denominator)


# -- mutation review 34 (session 33's checks) ----------------------------------------
def test_a_schedule_between_twice_and_three_times_the_cap_is_refused() -> None:
    """Kills D02 (refusal at 3× the cap): L_f Δτ = 0.6931444 makes 1 − e^(L_f Δτ)/2 ≈ 2.8·10⁻⁶;
    from γ₀ = 2γ⋆ the estimate is ≈ 2.5·10⁵ (between 2× and 3× MAX_SCHEDULE): refused."""
    with pytest.raises(InfeasibleError, match=r"needs about 2\.\de\+05 entries"):
        D.schedule(fmpq(2, 10), fmpq(1, 10), fmpq(1), Q("0.6931444"))


@pytest.mark.parametrize("factor", [1, 1 + 1e-10])
def test_an_estimate_of_exactly_twice_the_cap_is_not_refused(monkeypatch, factor) -> None:  # noqa: ANN001
    """Kills D04 (tolerance 1 − 10⁻⁹) and D05 (est ≥ 2·MAX_SCHEDULE): the rule needs at least
    est/2 entries, so at est = 2·MAX_SCHEDULE (within the 10⁻⁹ float tolerance) the schedule
    may still fit and is listed, not refused."""
    monkeypatch.setattr(D, "_steps_estimate", lambda *a: 2 * D.MAX_SCHEDULE * factor)
    gam = D.schedule(fmpq(2), fmpq(1), fmpq(1), Q("0.1"))
    assert gam[-1] == 1


def test_the_digit_refusal_is_at_one_digit_below_the_long_entries(monkeypatch) -> None:  # noqa: ANN001
    """Kills D08 (places > 113), D09 (places > 109) and D10 (places ≥ 112): entries of
    SCHEDULE_LONG_DIGITS = 112 digits decrease only when 1 − r > 10^(1−112). With
    1 − r = 5·10⁻¹¹² (places ≈ 111.3) the rule cannot progress: refused before listing; with
    1 − r = 10⁻¹¹⁰ (places = 110) it can: ~4·10⁴ entries are listed and reach γ⋆."""
    g_star = fmpq(1, 10)
    monkeypatch.setattr(D, "schedule_ratio", lambda x: 1 - fmpq(5, 10**112))
    g0 = g_star * (1 + fmpq(4, 10**107))
    assert D._most_digits(g0, g_star, 1 - fmpq(5, 10**112)) == D.SCHEDULE_LONG_DIGITS
    with pytest.raises(InfeasibleError, match="significant digits each"):
        D.schedule(g0, g_star, fmpq(1), fmpq(1, 10))
    monkeypatch.setattr(D, "schedule_ratio", lambda x: 1 - fmpq(1, 10**110))
    g0 = g_star * (1 + fmpq(4, 10**106))
    assert D._most_digits(g0, g_star, 1 - fmpq(1, 10**110)) == D.SCHEDULE_LONG_DIGITS
    gam = D.schedule(g0, g_star, fmpq(1), fmpq(1, 10))
    assert gam[-1] == g_star and len(gam) > 30_000


def test_the_digit_budget_margin_is_exactly_three_digits() -> None:
    """Kills D13 (need = places + 2): r = 1 − 10⁻⁴ from γ₀/γ⋆ = 10²⁷ needs ~6.2·10⁵ entries;
    at 4 + 3 digits that is 4.35·10⁶ > SCHEDULE_MAX_CHARS (112 digits at most), at 4 + 2 it
    would be 3.7·10⁶ (1,024)."""
    r = 1 - fmpq(1, 10**4)
    assert D._most_digits(fmpq(10**27), fmpq(1), r) == D.SCHEDULE_LONG_DIGITS


def test_gap_prints_the_float_gap_when_it_has_one() -> None:
    """Kills D21 (_gap always "10^-N"): 1 − r with a double is printed as it (.3g)."""
    assert D._gap(fmpq(3, 4)) == "0.25"
    assert D._gap(1 - fmpq(1, 10**400)) == "10^-400"


OVERFLOW_F = (
    '[system]\ntime = "continuous"\nstates = ["x1", "x2"]\n'
    'f = ["(x2 + 2^1100) - 2^1100", "-x1"]\nh = ["x1"]\n[method]\n'
    'key = "search-space"\nalpha = 0.9\ngamma_star = 0.05\ngamma0 = 1\nGIVEN\n'
    "E = {lower = [-1, -1], upper = [1, 2]}\nD = {lower = [0, -0.5], upper = [0, 0.5]}\n"
)


def test_the_corners_go_on_past_an_improvement_below_the_target() -> None:
    """Kills D31 (the corner loop stops at the first corner that improves on the proof):
    |f|² = x1² + x2² overflows floats everywhere (midpoint witness: 1/4); the first corner
    (−1, −1) proves 2, below 2.1² = 4.41, and only the second, (−1, 2), proves 5: a given
    f_sup = 2.1 is refuted (exit 1), the true √5 is not."""
    from obsdesign import api
    from obsdesign.certify.claim import ClaimStatus

    D._PROOFS.clear()
    rep = api.design(api.load_spec_text(OVERFLOW_F.replace("GIVEN", "f_sup = 2.1"), "o.toml"))
    c = next(c for c in rep.claims if c.id == "f_sup-bound")
    assert c.status == ClaimStatus.FAILED and rep.exit_code() == 1, c.detail
    assert "at (-1.0, 2.0)" in c.detail
    rep = api.design(
        api.load_spec_text(OVERFLOW_F.replace("GIVEN", "f_sup = 2.2360679775"), "t.toml")
    )
    assert rep.exit_code() == 0


def test_corners_are_tried_only_where_floats_overflowed(monkeypatch) -> None:  # noqa: ANN001
    """Kills D29 (corners tried whenever the sampled witness does not refute): h = 2·x1 has
    finite float samples, so a value above L_h = 2 is proved at the sampled witness only."""
    from obsdesign import api
    from obsdesign.methods.searchspace import bounds as B

    calls: list[object] = []
    real = B.corner_witnesses
    monkeypatch.setattr(B, "corner_witnesses", lambda *a: calls.append(a) or real(*a))
    text = (
        '[system]\ntime = "continuous"\nstates = ["x1"]\nf = ["-x1"]\nh = ["2*x1"]\n'
        '[method]\nkey = "search-space"\nalpha = 0.5\ngamma_star = 0.1\ngamma0 = 1\n'
        "E = {lower = [-1], upper = [1]}\nD = {lower = [-0.5], upper = [0.5]}\n"
    )
    D._PROOFS.clear()
    got = D.proved_lower("L_h", api.load_spec_text(text, "s.toml"), fmpq(3))
    assert got is not None and got[0] <= 9
    assert calls == []


@pytest.mark.parametrize(
    ("f1", "u1", "L_f"),
    [
        ("x2*step(cosh(1e39))", "0.5", 2),  # step read as 0: L_f = 1 certified
        ("x2*sign(sinh(1e39))", "0.5", 2),
        ("0", "0.5*sign(-sinh(1e39)) - 0.75", None),  # u = −1.25 ∉ U, sign read as 0
        ("0", "max(0.5, cosh(1e39))", None),  # max(0.5, NaN) kept 0.5
        ("0", "sat(-cosh(1e39)) + 0.5*step(cosh(1e39)) - 0.75", None),  # u = −1.25
    ],
)
def test_a_function_beyond_the_float_range_proves_nothing_from_nan(
    f1: str, u1: str, L_f: int | None
) -> None:
    """sinh / cosh of an argument beyond 2¹²⁸ came back NaN from the interval kernel
    (python-flint's ball overflows), and max(a, NaN) kept a while step / sign read every
    comparison with NaN as false: L_f = 1 was certified for f1 = x2 + x2·step(cosh(1e39))
    (true 2), and u = max(0.5, cosh(1e39)) in U = [−1, 1] (false certificates, search-space
    trial, session 35). A NaN end point now proves nothing, and arb's NaN ball is (−∞, ∞)."""
    text = UNDEFINED.replace("F1", f1).replace("U1", u1)
    sp = api.load_spec_text(text, "nan.toml")
    try:
        rep = api.design(sp)
    except (InfeasibleError, SpecError) as e:
        assert "no finite" in e.message or "not defined" in e.message, e.message
        return
    certified = {c.id for c in rep.claims if c.status == ClaimStatus.CERTIFIED}
    if L_f is None:
        assert "input-range" not in certified
        assert rep.exit_code() != 0
    else:
        assert "L_f-bound" in certified  # true and provable once step reads 1
        assert rep.parameters.float("L_f") >= L_f


UNDEFINED = """[system]
time = "continuous"
states = ["x1", "x2"]
f = ["x2 + F1", "-x1 + u1"]
h = ["x1"]
u = ["U1"]
[system.parameters]
k = 0
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 1
[method.E]
lower = [-2, -2]
upper = [2, 2]
[method.D]
lower = [-1, -1]
upper = [1, 1]
[method.U]
lower = [-1]
upper = [1]
[simulate]
horizon = 2
x0 = [0.5, 0.5]
xhat0 = [0, 0]
"""


@pytest.mark.parametrize(
    ("f1", "u1", "undefined"),
    [
        ("0", "sin(1/t)", "u"),  # undefined at t = 0
        ("0", "sat(1/(t - 1), 1)", "u"),
        ("0", "0.5 + k*tan(t)", "u"),  # a pole at π/2 inside [0, 2]: k = 0 hid it
        ("0", "(1/0)^0", "u"),  # sympy's zoo^0 = 1 decided the constant (re-check 34)
        ("0", "(0^-1)^0", "u"),
        ("0", "(0/0)^0", "u"),  # sympy's nan^0 = 1 too (mutation review 35, E1)
        ("0", "(k/k)^0", "u"),
        ("k*(1/x1)", "0.5", "f"),  # undefined at x1 = 0 in E
        ("k*tan(x1)", "0.5", "f"),
        ("(1/x1)^0", "0.5", "f"),
        ("0*log(x1 + 2)", "0.5", "f"),  # log 0 at x1 = −2, E's edge
    ],
)
def test_an_expression_undefined_somewhere_on_its_set_certifies_nothing(
    f1: str, u1: str, undefined: str
) -> None:
    """Interval division by an interval holding 0, tan at a pole and log at 0 gave "any
    real", which sin, sat, step or an exact factor 0 then bounded: u = sin(1/t) was certified
    in [−1, 1] for t ∈ [0, 2], and L_f, sup |f| of k·(1/x1) with k = 0 on an E holding 0,
    verified ok (false certificates; expression soundness trial, session 34). Undefined
    somewhere is now refused, as sqrt and log below 0 were."""
    text = UNDEFINED.replace("F1", f1).replace("U1", u1)
    sp = api.load_spec_text(text, "undefined.toml")
    try:
        rep = api.design(sp)
    except (InfeasibleError, SpecError) as e:
        assert "not defined" in e.message or "no finite" in e.message, e.message
        return
    assert rep.exit_code() != 0
    ids = {"u": ("input-range",), "f": ("L_f-bound", "f_sup-bound")}[undefined]
    bad = [c.id for c in rep.claims if c.status == ClaimStatus.CERTIFIED and c.id in ids]
    assert not bad, bad


def test_an_estimate_beyond_the_float_range_refutes_the_value(monkeypatch) -> None:
    """Mutation review 36: _constant's `not math.isfinite(b.lower_est)` branch. An infinite
    sampled lower estimate (a norm beyond the largest float) is above every value: the claim
    fails, even with an interval bound below the value — Q(inf) would raise, and skipping
    the non-finite estimate would certify. (hypot_lo / proved_quotient cap at the largest
    float today, so this pins the guard for any other producer of lower_est.)"""
    from pathlib import Path

    from obsdesign import api
    from obsdesign.api import bind
    from obsdesign.certify.claim import Claims, ClaimStatus
    from obsdesign.methods.searchspace import claims as C
    from obsdesign.methods.searchspace.bounds import Bound

    sp = api.load_spec(
        Path(__file__).resolve().parents[1] / "specs" / "hernandez-garcia-example.toml"
    )
    monkeypatch.setattr(C, "interval_bound", lambda k, spec: Bound(0.5, math.inf, 1))
    c = Claims()
    C._constant(c, bind(sp), "L_h", fmpq(1))
    (claim,) = c
    assert claim.id == "L_h-bound" and claim.status == ClaimStatus.FAILED, claim.detail


_CANCEL = """
[system]
time = "continuous"
states = ["x1", "x2"]
f = ["x2", "-x1 - 1e25*(exp(p) - 1 - p)*x2"]
h = ["x1"]
[system.parameters]
p = 9.094947017729282379150390625e-13
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 0.5
[method.E]
lower = [-2, -2]
upper = [2, 2]
[method.D]
lower = [-1, -1]
upper = [1, 1]
"""


def test_an_exp_cancellation_gets_a_true_lipschitz_bound() -> None:
    """f₂ = −x1 − c·x2 with c = 10²⁵(e^p − 1 − p), p = 2⁻⁴⁰: c ≈ 4.136, but mpmath's interval
    exp gave e^p = 1 + 2⁻⁴⁰ exactly, so c was enclosed as 0 and L_f = 1, ‖f_u‖ = 2.83 were
    certified (search-space soundness trial, session 38). With Fractions: e^p − 1 − p ≥ p²/2,
    so the difference quotient between (0, 0) and (0, 1) is ≥ √(1 + c²) ≥ 4.255 and
    |f(2, 2)| ≥ 10.46: the certified L_f and f_sup are at least that (loose, but true)."""
    from fractions import Fraction as F

    rep = api.design(api.load_spec_text(_CANCEL, "cancel.toml"))
    p = F(1, 2**40)
    c = 10**25 * p**2 / 2
    L = Q(rep.parameters["L_f"])
    Lf = F(int(L.p), int(L.q))
    S = Q(rep.parameters["f_sup"])
    assert Lf**2 >= 1 + c**2
    assert F(int(S.p), int(S.q)) ** 2 >= 4 + (2 + 2 * c) ** 2


_SCHEDULE_EXP = """
[system]
time = "continuous"
states = ["x1", "x2"]
f = ["x2", "-x1"]
h = ["x1"]
[method]
key = "search-space"
alpha = 0.00000000000000000021684043449710088680149056017398834228515625
gamma_star = 1.000000000000000000108420217248550443400745280086994171142578125
gamma0 = 2
K = 1
f_sup = 1.000000000000000000108420217248550443400745280086994171142578125
[method.E]
lower = [-0.5, -0.5]
upper = [0.5, 0.5]
[method.D]
lower = [-0.25, -0.25]
upper = [0.25, 0.25]
"""


def test_a_schedule_entry_at_a_wrong_upper_bound_of_exp_fails(tmp_path: Path) -> None:
    """L_f·Δτ = 2⁻⁶³ and γ⋆ = 1 + 2⁻⁶³, the end mpmath's interval exp gave as an upper bound
    of e^(2⁻⁶³) at 113 bits (it is below: e^x > 1 + x). γ₁ = max(γ₀e^x/2, γ⋆) = e^x with
    γ₀ = 2, so a schedule entry γ₁ = γ⋆ is below the rule, and the gamma-schedule claim passed
    with mpmath's bound (search-space soundness trial, session 38); with arb's it fails. The
    designed schedule holds the rule, checked with Fractions (e^x ≥ 1 + x + x²/2)."""
    from fractions import Fraction as F

    sp = api.load_spec_text(_SCHEDULE_EXP, "sched.toml")
    rep = api.design(sp)
    p = rep.parameters
    x = F(int(Q(p["L_f"] * p["dtau"]).p), int(Q(p["L_f"] * p["dtau"]).q))
    assert x == F(1, 2**63)
    g = [F(int(Q(a).p), int(Q(a).q)) for a in p["gamma_schedule"]]
    assert rep.exit_code() == 0 and g[1] >= g[0] * (1 + x + x * x / 2) / 2
    v = {k: p[k] for k in p.keys()}
    sched = list(p["gamma_schedule"])
    sched[1] = p["gamma_star"]  # 1 + 2⁻⁶³ < e^(2⁻⁶³)
    v["gamma_schedule"] = sched
    v["eps_schedule"] = [a / p["kappa"] for a in sched]
    assert _failed(_report_with(rep, v, tmp_path)) == {"gamma-schedule"}


def test_the_schedule_checks_retry_enclosure_is_rigorous() -> None:
    """The doubling retry of the γ-schedule check (an entry undecided at 113 bits): x = 2⁻¹⁵⁰
    and the entry γ₁ = 1 + x with γ₀ = 2, below the rule γ₀e^x/2 = e^x > 1 + x. mpmath's
    interval exp at 226 bits gives the upper end 1 + x exactly, which would accept the entry;
    arb's does not, and at 452 bits the entry is refuted (putting iv.exp back on that line
    passed every test: before-stop review, session 39)."""
    from obsdesign.methods.searchspace import claims as ssc

    x = fmpq(1, 2**150)
    verdict, _, _ = ssc._follows(fmpq(2), 1 + x, fmpq(1, 2), x, fmpq(1), 1 + 2 * x)
    assert verdict is False


def test_a_bound_beyond_the_float_range_is_named_as_such() -> None:
    """f = −cosh(x1) on x1 ∈ [−1000, 1000] is Lipschitz with a constant past 10³⁰⁸; the
    refusal said only "not Lipschitz/bounded" (CLI review, session 40)."""
    from pathlib import Path

    text = (Path(__file__).parents[1] / "specs" / "hernandez-garcia-pendulum.toml").read_text()
    text = text.replace('"-sin(x1) - 0.2*x2 + u1"', '"-cosh(x1) - 0.2*x2 + u1"')
    text = text.replace("lower = [-3, -3]", "lower = [-1000, -3]")
    text = text.replace("upper = [3, 3]", "upper = [1000, 3]")
    assert "cosh" in text and "-1000" in text
    with pytest.raises(InfeasibleError, match=r"beyond the float range.*give \[method\]\.L_f"):
        api.design(api.load_spec_text(text, "cosh.toml"))


def test_the_bound_caches_are_keyed_by_the_data_not_the_text() -> None:
    """The interval bounds and proofs were cached by the spec's text: a spec object with the
    same text and f five times larger (dataclasses.replace) was certified "L_f ≤ 1" and
    "‖f_u‖ ≤ 3.53554" — the difference quotient along e₂ is 5 and |f(−5/2, −5/2, u = 1)|² =
    625/2 (API review, session 42). Keyed by what the constants are computed from."""
    text = SPEC.read_text(encoding="utf-8")
    spec = api.load_spec_text(text, "ex.toml")
    rep = api.design(spec)
    assert rep.exit_code() == 0
    f5 = api.load_spec_text(
        text.replace('f = ["u1*x2", "-u1*x1"]', 'f = ["5*u1*x2", "-5*u1*x1"]'), "f5.toml"
    ).system.f
    other = dataclasses.replace(spec, system=dataclasses.replace(spec.system, f=f5))
    status = {c.id: c.ok for c in api.certify(other, rep.parameters)}
    assert status["L_f-bound"] is False and status["f_sup-bound"] is False
    assert all(c.ok for c in api.certify(spec, rep.parameters))  # the designed spec: cached


def test_the_bound_caches_are_keyed_by_the_parsed_expression_not_its_source() -> None:
    """The caches were keyed by each expression's source while the bounds are computed from
    its parsed tree: an Expr whose source was edited in place ("1.2*u1*x2", tree of "u1*x2")
    stored L_f = 1 under the new text, and a later spec with f = 1.2·u1·x2 was certified
    "L_f ≤ 1" (the quotient along e₂ is 6/5; API review, session 43). Keyed by the tree, and
    an Expr is frozen."""
    import dataclasses

    text = SPEC.read_text(encoding="utf-8")
    assert 'f = ["u1*x2", "-u1*x1"]' in text
    spec = api.load_spec_text(text, "ex.toml")
    ex = spec.system.f[0]
    with pytest.raises(dataclasses.FrozenInstanceError):
        ex.source = "1.2*u1*x2"  # type: ignore[misc]
    object.__setattr__(ex, "source", "1.2*u1*x2")  # past the guard, as the review did
    api.design(spec)
    other = text.replace('f = ["u1*x2", "-u1*x1"]', 'f = ["1.2*u1*x2", "-u1*x1"]')
    rep = api.design(api.load_spec_text(other, "f12.toml"))
    assert Q(rep.parameters["L_f"]) >= Q(6) / 5


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("L_h", fmpq(1, 2**1074)),
        ("f_sup", fmpq(1, 2**1074)),
        ("f_sup", -fmpq(1, 2**1074)),
        ("L_f", -fmpq(int(1.7976931348623157e308))),
        ("dtau", -fmpq(10**308)),
    ],
)
def test_forged_extreme_constants_fail_their_claims_not_the_run(key: str, value: fmpq) -> None:
    """A report with L_h = 2⁻¹⁰⁷⁴ stopped verify with "a number is beyond the float range"
    (ΔT's rule ≈ 10³²² as a float) and one with L_f = −1.8e308 with "beyond exact
    arithmetic" (e^(L_f Δτ)), both exit 4 blaming the spec, where a forged constant is a
    failed claim, exit 1 (float pre-screen review, session 43)."""
    spec = api.load_spec(SPEC)
    rep = api.design(spec)
    params = Parameters(dict(rep.parameters))
    params[key] = value
    claims = api.certify(spec, params)
    assert any(not c.ok for c in claims)


def test_two_literals_of_one_double_do_not_share_their_bounds() -> None:
    """1.00000000000000000 and 1.00000000000000009 are one double but two exact values: keyed
    by the parsed tree alone, the second spec got the first's bounds in the same process and
    `check` certified L_f = 1 where the coefficient is exactly 10 (re-check review, session
    43). The key holds the source too."""
    text = SPEC.read_text(encoding="utf-8")
    old = 'f = ["u1*x2", "-u1*x1"]'
    assert old in text

    def spec(lit: str) -> str:
        return text.replace(old, f'f = ["(1 + ({lit} - 1)*100000000000000000)*u1*x2", "-u1*x1"]')

    one = api.design(api.load_spec_text(spec("1.00000000000000000"), "a.toml"))
    ten = api.design(api.load_spec_text(spec("1.00000000000000009"), "b.toml"))
    assert Q(one.parameters["L_f"]) < 2 and Q(ten.parameters["L_f"]) >= 10


@pytest.mark.parametrize("key", ["L_f", "L_h", "f_sup", "kappa"])
def test_a_zero_constant_fails_a_claim_that_says_so(key: str) -> None:
    """A report's L_f, L_h, f_sup or κ = 0: the rules divide by them, and the only failed
    claim read "parameters-wellformed: ZeroDivisionError" (re-check review, session 43)."""
    spec = api.load_spec(SPEC)
    rep = api.design(spec)
    params = Parameters(dict(rep.parameters))
    params[key] = fmpq(0)
    failed = {c.id: c.detail for c in api.certify(spec, params) if not c.ok}
    assert set(failed) == {"constants-positive"} and f"{key} = 0" in failed["constants-positive"]


def test_each_expression_is_bounded_with_its_own_parameters() -> None:
    """f = (k·u1·x2, −u1·x1) assembled from two specs' expressions (k = 10 in the first, k = 1
    in the second): the interval bounds merged the expressions' parameter dicts, the last
    winning, and certified L_f = 1 and ‖f_u‖ ≤ 3.53554 for an f whose first component is
    10·u1·x2 (API review, session 43). Each expression is bounded with its own."""
    import copy
    import dataclasses

    text = SPEC.read_text(encoding="utf-8")
    old = 'f = ["u1*x2", "-u1*x1"]'
    assert old in text
    with_k = text.replace(old, 'f = ["k*u1*x2", "-u1*x1"]').replace(
        "[method]", "[system.parameters]\nk = KVALUE\n\n[method]", 1
    )
    a = api.load_spec_text(with_k.replace("KVALUE", "1"), "a.toml")
    b = api.load_spec_text(with_k.replace("KVALUE", "10"), "b.toml")
    mix = copy.copy(a)
    mix.system = dataclasses.replace(a.system, f=[b.system.f[0], a.system.f[1]])
    # api.design refuses the copy (its text says k = 1 throughout; API review, session 44):
    # the method layer designs it, and api.certify checks its bounds
    d = get_method("search-space").design(api.bind(mix), None)
    assert Q(d.parameters["L_f"]) >= 10
    with pytest.raises(InputError, match=r"\[system\] of the spec object was replaced"):
        api.design(mix)
