"""The ``stubborn`` method (paper 002: Astolfi, Alessandri, Zaccarian, stubborn observers):
design + exact certificate of LMIs (1)-(3) / (7)-(9), tamper tests per claim id, the outlier
study's qualitative result, bad input."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from flint import fmpq
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.certify.claim import ClaimStatus
from obsdesign.certify.exact import Q, qparse, qstr, to_float
from obsdesign.cli import app
from obsdesign.errors import InconclusiveError, InfeasibleError, SpecError
from obsdesign.methods.stubborn import sim
from obsdesign.methods.stubborn.sim import study
from obsdesign.report import Report

SPECS = Path(__file__).resolve().parents[1] / "specs"
EX1 = SPECS / "astolfi-stubborn-example1.toml"
EX3 = SPECS / "astolfi-stubborn-example3.toml"
EX4 = SPECS / "astolfi-stubborn-example4.toml"


@pytest.fixture(scope="module")
def ex1() -> Report:
    return api.design(EX1)


@pytest.fixture(scope="module")
def ex4() -> Report:
    return api.design(EX4)


def _certified(rep: Report) -> None:
    """Every claim certified, except the λ bracket's far end (re-solved: numerical)."""
    want = {c.id: ClaimStatus.CERTIFIED for c in rep.claims}
    if "lambda-max-bracket" in want:
        want["lambda-max-bracket"] = ClaimStatus.NUMERICAL
    bad = [(c.id, c.detail) for c in rep.claims if c.status != want[c.id]]
    assert not bad


def test_example1_design_certified(ex1: Report) -> None:
    _certified(ex1)
    ids = {c.id for c in ex1.claims}
    assert ids == {
        "gain-relation", "P-positive", "U-positive", "W-positive", "R-positive",
        "lambda-range", "lambda-choice", "lmi-global", "lmi-regional", "lmi-sector",
        "gain-bound", "lambda-max-certified", "lambda-max-bracket",
    }  # fmt: skip
    p = ex1.parameters
    for k in ("K", "P", "X", "U", "W", "Y", "R", "lambda", "lambda_max", "criterion"):
        assert k in p
    # λ = fraction·λ_max exactly (fraction 1/2 from the spec)
    assert p["lambda"] == fmpq(1, 2) * p["lambda_max"]
    # X = P K exactly, K = P⁻¹X
    assert (p["P"] @ p["K"] == p["X"]).all()
    # with ‖X‖₂ ≤ 100 and P ⪰ I the best λ of Example 1 is ≈ 7.5. Clarabel answers
    # 'optimal' up to ≈ 7.51, inaccurate or fails on ≈ 7.52 … 7.55 (a certificate exists at
    # 7.53: stubborn review), 'infeasible' beyond: the far end is where it says infeasible,
    # so the bracket is wider than lambda_tol = 0.1 % (≈ 0.7 % here) and a note says so
    lo, hi = p["lambda_bracket"]
    assert lo == p["lambda_max"]
    assert Q("7.3") < lo < hi <= lo * fmpq(102, 100)
    assert any("wider than lambda_tol" in n for n in ex1.notes) == (hi > lo * fmpq(1001, 1000))
    K = p.float("K").ravel()
    assert np.linalg.norm(K) <= 100
    assert (
        max(
            np.linalg.eigvals(
                p.float("P") @ np.zeros((2, 2)) + np.array([[0, 1], [-1, 0]]) - np.outer(K, [1, 1])
            ).real
        )
        < 0
    )


def test_example1_verify_cli(ex1: Report, tmp_path: Path) -> None:
    out = tmp_path / "ex1.json"
    out.write_text(ex1.to_json())
    r = CliRunner().invoke(app, ["verify", str(out)])
    assert r.exit_code == 0, r.output


def test_example4_discrete_l2(ex4: Report) -> None:
    _certified(ex4)
    p = ex4.parameters
    assert "l2-gain" in {c.id for c in ex4.claims}
    lam, best = p["lambda"], p["lambda_max"]
    assert 0 < best < lam < 1
    assert 1 - lam == fmpq(1, 2) * (1 - best)  # discrete: 1 − λ = fraction·(1 − λ_best)
    A = np.array([[1, 1, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1], [0, 0, 0, 1.0]])
    C = np.array([[1, 0, 0, 0], [0, 0, 1, 0.0]])
    assert max(abs(np.linalg.eigvals(A - p.float("K") @ C))) < 1


# -- tamper tests: every claim id must fail when its quantity is made false ----------------
def _set(d: dict[str, Any], key: str, value: Any) -> None:
    d["parameters"]["exact"][key] = qstr(value)
    f = to_float(value)
    d["parameters"][key] = f if isinstance(f, float) else np.asarray(f).tolist()


def _get(d: dict[str, Any], key: str) -> Any:
    return qparse(d["parameters"]["exact"][key])


def _failed(d: dict[str, Any]) -> set[str]:
    rep, problems = Report.from_dict(json.loads(json.dumps(d)))
    assert not problems
    ver = api.verify(rep)
    assert ver.exit_code() != 0 or not any(c.status == ClaimStatus.FAILED for c in ver.claims)
    # the method's own recomputed claims (verify adds report-alters:<id> / report-verdict when
    # the stored claims differ from the recomputed ones)
    return {
        c.id
        for c in ver.claims
        if c.status == ClaimStatus.FAILED and not c.id.startswith("report-")
    }


TINY = fmpq(1, 2**80)


def _tampered(rep: Report, name: str) -> dict[str, Any]:
    d = rep.to_dict()
    P, K, Y, u, w = (_get(d, k) for k in ("P", "K", "Y", "U", "W"))
    if name == "gain-relation":
        X = _get(d, "X")
        X[0, 0] += TINY
        _set(d, "X", X)
    elif name == "P-positive":  # P singular (det = 0): the smallest change that breaks P ≻ 0
        P[0, 0] = P[0, 1] * P[1, 0] / P[1, 1]
        _set(d, "P", P)
        _set(d, "X", P @ K)
    elif name == "U-positive":
        u[0] = fmpq(0)
        _set(d, "U", u)
    elif name == "W-positive":
        w[0] = fmpq(0)
        _set(d, "W", w)
    elif name == "R-positive":
        _set(d, "R", _get(d, "R") * 0)
    elif name == "lambda-range":  # λ = 0 (then λ ≠ fraction·λ_max too: λ_max is certified)
        _set(d, "lambda", fmpq(0))
    elif name == "lambda-choice":
        _set(d, "lambda", _get(d, "lambda") + TINY)
    elif name == "lmi-global":  # R just below the smallest R for which (1) holds
        R = _r_star(d) * (1 - fmpq(1, 10**9))
        _set(d, "R", np.array([[R]], dtype=object))
    elif name == "lmi-regional":  # −Y keeps (3) (quadratic in Y) and breaks (2)
        _set(d, "Y", -Y)
    elif name == "lambda-max-certified":  # a singular P at λ_max
        Pm = _get(d, "P_at_max")
        Pm[0, 0] = Pm[0, 1] * Pm[1, 0] / Pm[1, 1]
        _set(d, "P_at_max", Pm)
    elif name == "lambda-max-bracket":  # far end 2⁻⁸⁰ past the certified λ_max: feasible
        lo = _get(d, "lambda_max")
        _set(d, "lambda_bracket", np.array([lo, lo + TINY], dtype=object))
    elif name == "lmi-sector":  # Y_1 scaled just past Y_1 P⁻¹ Y_1ᵀ = w_1
        q = (Y @ _inv2(P) @ Y.T)[0, 0]
        c = Q(float(np.sqrt(float(w[0] / q)))) * (1 + fmpq(1, 10**9))
        assert c * c * q > w[0]
        _set(d, "Y", Y * c)
    else:
        raise AssertionError(name)
    return d


def _inv2(P: np.ndarray) -> np.ndarray:
    a, b, c, e = P[0, 0], P[0, 1], P[1, 0], P[1, 1]
    det = a * e - b * c
    return np.array([[e / det, -b / det], [-c / det, a / det]], dtype=object)


def _r_star(d: dict[str, Any]) -> fmpq:
    """The smallest R (p = 1) with LMI (1) for the reported P, X, U, λ: M1(R) = M1(0) − R·E,
    E = diag(CᵀC, 0); float bisection, then the exact check decides the tampered value."""
    from obsdesign.methods.stubborn import lmis

    A = np.array([[0, 1], [-1, 0.0]])
    C = np.array([[1, 1.0]])
    P, X, u = (np.asarray(to_float(_get(d, k)), float) for k in ("P", "X", "U"))
    lam = float(to_float(_get(d, "lambda")))

    def ok(r: float) -> bool:
        M = lmis.global_sector(A, C, P, X, u.reshape(-1), np.array([[r]]), lam, False).astype(float)
        return bool(np.linalg.eigvalsh(-M).min() > 0)

    lo, hi = 0.0, float(to_float(_get(d, "R"))[0, 0])
    for _ in range(80):
        mid = (lo + hi) / 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return Q(hi)


EXPECTED = {
    "gain-relation": {"gain-relation"},
    # a singular P breaks every LMI that carries P (all three here)
    "P-positive": {"P-positive", "lmi-sector", "lmi-regional", "lmi-global"},
    "U-positive": {"U-positive", "lmi-global"},
    "W-positive": {"W-positive", "lmi-regional", "lmi-sector"},
    "R-positive": {"R-positive", "lmi-global"},
    "lambda-range": {"lambda-range", "lambda-choice"},
    "lambda-choice": {"lambda-choice"},
    "lmi-global": {"lmi-global"},
    "lmi-regional": {"lmi-regional"},
    "lmi-sector": {"lmi-sector"},
    "lambda-max-certified": {"lambda-max-certified"},
    "lambda-max-bracket": {"lambda-max-bracket"},
}


def test_tamper_gain_bound(ex1: Report) -> None:
    """The spec's gain bound just below ‖K‖₂ (embedded spec and its hash changed): the report's
    copy differs and ‖K‖₂ ≤ bound fails (the λ_max point has ‖K‖₂ ≈ 100: it fails too)."""
    import hashlib

    d = ex1.to_dict()
    K = _get(d, "K")
    n2 = (K.T @ K)[0, 0]
    b = Q(float(np.sqrt(float(n2))) * (1 - 1e-12))
    assert b * b < n2
    d["spec"] = d["spec"].replace("gain_bound = 100", f"gain_bound = {float(b)!r}")
    d["spec_sha256"] = hashlib.sha256(d["spec"].encode()).hexdigest()
    # and the solver's problem, with the smaller bound, is no longer feasible at λ_max
    assert _failed(d) == {
        "gain-bound",
        "gain_bound-matches-spec",
        "lambda-max-certified",
        "lambda-max-bracket",
    }


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_tamper_each_claim(ex1: Report, name: str) -> None:
    assert _failed(_tampered(ex1, name)) == EXPECTED[name]


def test_tamper_verify_cli_exit_1(ex1: Report, tmp_path: Path) -> None:
    out = tmp_path / "t.json"
    out.write_text(json.dumps(_tampered(ex1, "lmi-global")))
    r = CliRunner().invoke(app, ["verify", str(out)])
    assert r.exit_code == 1, r.output


@pytest.mark.parametrize(
    "bracket, why",
    [
        (lambda lo, hi: [lo, lo - TINY], "far end on the wrong side"),
        (lambda lo, hi: [lo + TINY, hi], "does not start at λ_max"),
        (lambda lo, hi: [lo, hi, hi], "not a pair"),
        (lambda lo, hi: [lo, -hi], "far end on the wrong side"),
    ],
)
def test_tamper_lambda_bracket_shapes(ex1: Report, bracket: Any, why: str) -> None:
    """Each condition of the bracket claim fails on its own (a far end beyond the float range
    or negative is refused without a solve, not a crash)."""
    d = ex1.to_dict()
    lo, hi = _get(d, "lambda_bracket")
    _set(d, "lambda_bracket", np.array(bracket(lo, hi), dtype=object))
    rep, problems = Report.from_dict(json.loads(json.dumps(d)))
    assert not problems
    ver = api.verify(rep)
    (claim,) = [c for c in ver.claims if c.id == "lambda-max-bracket"]
    assert claim.status == ClaimStatus.FAILED and why in claim.detail, claim.detail


def test_tamper_lambda_bracket_beyond_the_float_range(ex1: Report, tmp_path: Path) -> None:
    """A far end of 10⁴⁰⁰ (no float view: no report carries one) is bad input naming the
    report and the key (exit 2), not an internal failure (exit 3, before)."""
    d = ex1.to_dict()
    lo = d["parameters"]["exact"]["lambda_bracket"][0]
    d["parameters"]["exact"]["lambda_bracket"] = [lo, str(10**400)]
    out = tmp_path / "big.json"
    out.write_text(json.dumps(d))
    r = CliRunner().invoke(app, ["verify", str(out)])
    assert r.exit_code == 2, r.output
    assert "parameters.exact.lambda_bracket" in r.output and "beyond the float range" in r.output
    assert "Traceback" not in r.output


def test_far_end_needs_the_solvers_infeasibility_certificate() -> None:
    """The search's far end is a λ where Clarabel says 'infeasible', moved outward past
    inaccurate answers; the bisection stops at adjacent floats (lambda_tol 1e-17 hung)."""
    from obsdesign.methods.stubborn import design as dz

    answers = {1.0: "optimal", 1.5: "optimal_inaccurate", 2.0: "solver failure", 3.0: "infeasible"}

    def feas(lam: float) -> tuple[bool, str]:
        st = next(v for k, v in sorted(answers.items(), reverse=True) if lam >= k)
        return st == "optimal", st

    good, bad, st, known = dz._bisect(feas, 1.0, 4.0, "infeasible", 1e-17)  # type: ignore[arg-type]
    assert good < 1.5 <= bad and np.nextafter(good, np.inf) == bad
    assert st == "optimal_inaccurate" and known == 4.0
    far, st2 = dz._far_end(feas, good, bad, st, known, False)  # type: ignore[arg-type]
    assert st2 == "infeasible" and 3.0 <= far <= known
    # discrete: outward is down
    far, st3 = dz._far_end(
        lambda lam: (False, "infeasible" if lam < 0.2 else "x"), 0.5, 0.4, "x", None, True
    )  # type: ignore[arg-type]
    assert st3 == "infeasible" and far < 0.2


def test_tamper_l2_gain(ex4: Report) -> None:
    d = ex4.to_dict()
    g = _get(d, "gamma2")
    _set(d, "gamma2", g * fmpq(9, 10))
    assert _failed(d) == {"l2-gain"}


def test_tamper_discrete_lambda_range(ex4: Report) -> None:
    d = ex4.to_dict()
    _set(d, "lambda", fmpq(1))
    assert _failed(d) == {"lambda-range", "lambda-choice"}


def test_missing_parameter(ex1: Report) -> None:
    d = ex1.to_dict()
    del d["parameters"]["Y"]
    del d["parameters"]["exact"]["Y"]
    assert _failed(d) == {"Y-present"}


# -- what the spec fixes is read from the spec ---------------------------------------------
PAPER_K1 = """
[system]
time = "continuous"
A = [[0, 1], [-1, 0]]
C = [[1, 1]]
[method]
key = "stubborn"
K = [-11.9944, 20.4153]
lambda = 5
"""


def test_redesign_with_paper_gain_and_spec_binding() -> None:
    sp = api.load_spec_text(PAPER_K1, "k.toml")
    rep = api.design(sp)
    _certified(rep)
    p = rep.parameters
    assert p["lambda"] == 5
    assert (p["K"] == np.array([[Q("-11.9944")], [Q("20.4153")]], dtype=object)).all()
    d = rep.to_dict()
    K = _get(d, "K")
    K[0, 0] += TINY
    _set(d, "K", K)  # X stays P·K_spec: only the comparison with the spec's K fails
    assert _failed(d) == {"K-matches-spec"}
    d = rep.to_dict()
    _set(d, "lambda", fmpq(5) - TINY)
    assert _failed(d) == {"lambda-matches-spec"}
    d = rep.to_dict()
    d["parameters"]["criterion"] = "K"
    assert _failed(d) == {"criterion-matches-spec"}


def test_paper_gain_example3_redesign() -> None:
    """The slides' Example 3 gain K = (−6.7510, 11.7510) certifies LMIs (1)-(3) at λ = 3.7
    (its best λ ≈ 3.77; the slides' K, R, W triple is feasible up to λ ≈ 3.74)."""
    text = PAPER_K1.replace("[-1, 0]]", "[0, 0.1]]").replace(
        "K = [-11.9944, 20.4153]", "K = [-6.7510, 11.7510]"
    )
    rep = api.design(api.load_spec_text(text.replace("lambda = 5", "lambda = 3.7"), "k3.toml"))
    _certified(rep)


def test_defaults_only_system_and_key() -> None:
    text = '[system]\ntime = "continuous"\nA = [[0, 1], [-2, -1]]\nC = [[1, 0]]\n[method]\nkey = "stubborn"\nlambda_tol = 0.05\n'
    rep = api.design(api.load_spec_text(text, "d.toml"))
    _certified(rep)
    assert rep.parameters["criterion"] == "R"


def test_undetectable_exit_1_names_detectability() -> None:
    text = '[system]\ntime = "continuous"\nA = [[1, 0], [0, -1]]\nC = [[0, 1]]\n[method]\nkey = "stubborn"\nlambda = 1\n'
    with pytest.raises(InfeasibleError, match="not detectable"):
        api.design(api.load_spec_text(text, "u.toml"))


def test_an_unobservable_oscillator_is_refused_before_any_lmi(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Two undamped oscillators, one seen (random-spec fuzzer): the solver called a tiny λ
    feasible and the design ended with exit 4; the exact detectability test now runs first
    (exit 1) and no LMI is solved."""
    from obsdesign.methods.stubborn import design as D

    def no_lmi(*a: Any, **k: Any) -> Any:
        raise AssertionError("an LMI was solved")

    monkeypatch.setattr(D, "_problem", no_lmi)
    text = (
        '[system]\ntime = "continuous"\n'
        "A = [[0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 3], [0, 0, -3, 0]]\n"
        'C = [[0, 0, 0, 1]]\n[method]\nkey = "stubborn"\n'
    )
    with pytest.raises(InfeasibleError, match="not detectable.*x\\^2 \\+ 1"):
        api.design(api.load_spec_text(text, "osc.toml"))


@pytest.mark.parametrize(
    "a, bound, lam, says",
    [
        (2.6, 10**6, None, "does not suffice"),
        (2.4, 1, None, "raise gain_bound"),
        (2.6, 10**6, 0.99, "does not suffice"),  # given λ: no λ < 1 helps either
        ("[[1, 1], [0, 1]]", 100, 0.1, r"try a larger λ \(closer to 1\)"),
    ],
)
def test_discrete_infeasible_says_whether_a_bound_is_the_cause(
    a: float | str, bound: int, lam: float | None, says: str
) -> None:
    """A = a, C = 1 (detectable): at a = 2.6 LMIs (7)-(9) have no solution whatever the gain
    bound or λ, and the message says detectability does not suffice in discrete time (it said
    'raise gain_bound (now 1e+06)', and with λ given 'try a smaller λ'); at a = 2.4 they are
    feasible without the bound, so a tight bound is named; a given λ too small asks for a
    larger one (the double integrator with ‖K‖ ≤ 100 at λ = 0.1; (7) weakens as λ → 1 and
    the hint said "smaller": random-spec fuzzer)."""
    A, C = (a, "[[1, 0]]") if isinstance(a, str) else (f"[[{a}]]", "[[1]]")
    text = (
        f'[system]\ntime = "discrete"\nA = {A}\nC = {C}\n'
        f'[method]\nkey = "stubborn"\ngain_bound = {bound}\n'
        + (f"lambda = {lam}\n" if lam is not None else "")
    )
    with pytest.raises(InfeasibleError, match=says) as ei:
        api.design(api.load_spec_text(text, "s.toml"))
    assert ("does not suffice" in ei.value.message) == (a == 2.6)
    assert "smaller λ" not in ei.value.message


@pytest.mark.parametrize(
    "extra, key",
    [
        ('criterion = "nope"', "criterion"),
        ("lambda = -1", "lambda"),
        ('criterion = "l2"', "criterion"),
        ("gain_bound = 0", "gain_bound"),
    ],
)
def test_bad_input(extra: str, key: str) -> None:
    text = f'[system]\ntime = "continuous"\nA = [[0, 1], [-1, 0]]\nC = [[1, 1]]\n[method]\nkey = "stubborn"\n{extra}\n'
    with pytest.raises(SpecError, match=key):
        api.load_spec_text(text, "b.toml")


# -- the outlier study: the slides' qualitative result ------------------------------------
@pytest.mark.parametrize("spec", [EX1, EX3])
def test_outlier_study_qualitative(spec: Path, ex1: Report) -> None:
    from obsdesign.methods.stubborn import sim

    # a coarser grid (dt = 2 ms) keeps the default suite fast; the slow test runs the specs as shipped
    sp = api.load_spec_text(spec.read_text().replace("dt = 0.001", "dt = 0.002"), str(spec))
    params = ex1.parameters if spec == EX1 else api.design(sp).parameters
    med = sim.study(sp, params, runs=16)["median_rmse"]
    for a in ("100", "1000"):
        for s in ("x1", "x2"):
            assert med["luenberger"][a][s] >= 5 * med["stubborn"][a][s], (a, s)
    for a in ("0.1", "1"):
        for s in ("x1", "x2"):
            assert med["stubborn"][a][s] <= 2 * med["luenberger"][a][s], (a, s)


def test_template_designs_and_verifies(tmp_path: Path) -> None:
    runner = CliRunner()
    res = runner.invoke(app, ["init", "stubborn"])
    assert res.exit_code == 0
    spec = tmp_path / "t.toml"
    spec.write_text(res.output)
    out = tmp_path / "t.json"
    r = runner.invoke(app, ["design", str(spec), "-o", str(out), "--format", "json"])
    assert r.exit_code == 0, r.output
    assert runner.invoke(app, ["verify", str(out), "--format", "json"]).exit_code == 0


def test_schema_lists_stubborn_keys() -> None:
    sch = json.dumps(api.schema())
    for k in ("lambda_fraction", "gain_bound", "lipschitz", "outlier_rate"):
        assert k in sch


def test_printed_numbers_are_true(ex1: Report, ex4: Report) -> None:
    """Numbers printed in statements: λ exactly, γ² rounded up (the statement 'γ² ≤ v' holds)."""
    import re

    def num(stmt: str, before: str) -> fmpq:
        m = re.search(re.escape(before) + r"\s*(-?[0-9./e+-]+)", stmt)
        assert m, stmt
        return Q(m.group(1))

    for rep in (ex1, ex4):
        by = {c.id: c.statement for c in rep.claims}
        assert num(by["lambda-range"], "λ =") == rep.parameters["lambda"]
        assert num(by["lambda-max-certified"], "λ_max =") == rep.parameters["lambda_max"]
    g = num({c.id: c.statement for c in ex4.claims}["l2-gain"], "γ² ≤")
    assert g >= ex4.parameters["gamma2"]


@pytest.mark.parametrize("how", [["--option", "study=outliers"], ["--study", "outliers"]])
def test_study_option_via_cli_json(tmp_path: Path, how: list[str]) -> None:
    text = EX1.read_text().replace("runs = 100", "runs = 3").replace("horizon = 10", "horizon = 2")
    f = tmp_path / "s.toml"
    f.write_text(text)
    r = CliRunner().invoke(app, ["simulate", str(f), *how, "--format", "json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.output)
    assert "outlier_study" in out and "stubborn" in out["outlier_study"]
    # the table says what its numbers are (outsider trial, session 29)
    assert (
        out["outlier_study"]
        .lstrip("\n")
        .startswith("median RMSE of each state's error over 3 runs")
    )


def test_study_table_prints_as_lines_in_text(tmp_path: Path) -> None:
    """The median-RMSE table of the outlier study is printed one row per line in text: each
    line escaped on its own (escaped whole, its newlines printed as a literal \\n and the
    table as one line: simulate trial, session 27)."""
    text = EX1.read_text().replace("runs = 100", "runs = 3").replace("horizon = 10", "horizon = 2")
    f = tmp_path / "s.toml"
    f.write_text(text)
    r = CliRunner().invoke(app, ["simulate", str(f), "--study", "outliers", "--width", "200"])
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert "\\n" not in r.output
    assert any(line.startswith("luenberger ") for line in lines)
    assert any(line.startswith("stubborn ") for line in lines)


def test_study_unknown_to_the_method_is_bad_input(tmp_path: Path) -> None:
    r = CliRunner().invoke(app, ["simulate", str(EX1), "--study", "nonesuch"])
    assert r.exit_code == 2


@pytest.mark.slow
@pytest.mark.parametrize("i", [1, 2, 3, 4])
def test_outlier_study_long(i: int) -> None:
    """The shipped specs' study (100 runs each): stubborn ≥ 5× better than Luenberger at
    amplitudes ≥ 100 and within 2× at ≤ 1, every state."""
    sp = api.load_spec(SPECS / f"astolfi-stubborn-example{i}.toml")
    rep = api.design(sp)
    _certified(rep)
    res = api.simulate(sp, rep, options={"study": "outliers"})
    med = res.extra["study"]["median_rmse"]
    for s in sp.system.states:
        for a in ("100", "1000"):
            assert med["luenberger"][a][s] >= 5 * med["stubborn"][a][s], (a, s)
        for a in ("0.1", "1"):
            assert med["stubborn"][a][s] <= 2 * med["luenberger"][a][s], (a, s)


# -- the LMI formulas against the slides' He(Z) forms, written independently ----------------
def _q(rows: list[list[Any]]) -> np.ndarray:
    from obsdesign.certify.exact import qmat

    return qmat(rows)


def _he_blocks(Z: list[list[np.ndarray]]) -> np.ndarray:
    M = np.block(Z)
    return M + M.T


def test_lmi_formulas_match_the_slides() -> None:
    from obsdesign.methods.stubborn import lmis

    h = fmpq(1, 2)
    A = _q([[0, 1], [-1, fmpq(1, 10)]])
    C = _q([[1, 1]])
    P = _q([[3, 1], [1, 2]])
    X = _q([[fmpq(1, 3)], [-2]])
    u = np.array([fmpq(5, 7)], dtype=object)
    w = np.array([fmpq(9, 4)], dtype=object)
    Y = _q([[fmpq(-1, 5), fmpq(2, 3)]])
    R = _q([[fmpq(11, 3)]])
    lam = fmpq(3, 2)
    U, W = _q([[u[0]]]), _q([[w[0]]])
    Z0 = np.zeros((2, 1), dtype=object) * fmpq(0)
    G = P @ A - X @ C
    # (1): He[[PA − XC + ½(λP − CᵀRC), X], [UC, −U]]
    want1 = _he_blocks([[G + h * (lam * P - C.T @ R @ C), X], [U @ C, -U]])
    assert (lmis.global_sector(A, C, P, X, u, R, lam, False) == want1).all()
    # (2): He[[PA − XC, X], [WC + Y, −W]]
    want2 = _he_blocks([[G, X], [W @ C + Y, -W]])
    assert (lmis.regional_sector(A, C, P, X, w, Y, False) == want2).all()
    # (7): He[[−½(λP + CᵀRC), 0, 0], [UC, −U, 0], [PA − XC, X, −½P]]
    Z22 = np.full((2, 2), fmpq(0), dtype=object)
    want7 = _he_blocks(
        [
            [-h * (lam * P + C.T @ R @ C), Z0, Z22],
            [U @ C, -U, Z0.T],
            [G, X, -h * P],
        ]
    )
    assert (lmis.global_sector(A, C, P, X, u, R, lam, True) == want7).all()
    # (8): He[[−½P, 0, 0], [WC + Y, −W, 0], [PA − XC, X, −½P]]
    want8 = _he_blocks([[-h * P, Z0, Z22], [W @ C + Y, -W, Z0.T], [G, X, -h * P]])
    assert (lmis.regional_sector(A, C, P, X, w, Y, True) == want8).all()
    # (3) / (9): [[P, Y_1ᵀ], [Y_1, w_1]]
    assert (lmis.sector(P, Y, w, 0) == np.block([[P, Y.T], [Y, W]])).all()


def test_l2_formula_known_answer() -> None:
    """ė = −e + d has L2 gain exactly 1: the bounded-real-lemma matrix certifies γ² = 1 + 2⁻²⁰
    (P = 1) and no P gives γ² = 1 (det = −(P − 1)² ≤ 0)."""
    from obsdesign.certify.psd import check_pd
    from obsdesign.methods.stubborn import lmis

    A, C, Bd = _q([[-1]]), _q([[0]]), _q([[1]])
    X = _q([[0]])
    assert check_pd(-lmis.l2_gain(A, C, Bd, _q([[1]]), X, 1 + fmpq(1, 2**20), False)).ok
    for p in (fmpq(1, 2), fmpq(1), fmpq(2)):
        assert not check_pd(-lmis.l2_gain(A, C, Bd, _q([[p]]), X, fmpq(1), False)).ok


def test_l2_formula_known_answer_discrete() -> None:
    """e⁺ = e/2 + d has L2 gain 1/(1 − 1/2) = 2 (γ² = 4, at z = 1): the discrete bounded-real-
    lemma matrix certifies γ² = 4(1 + 2⁻¹⁰) with P = 2, and no P gives γ² = 4 or 3. Only the
    continuous formula had a known answer, and the discrete one without its +I certified
    γ² ≤ 4 on Example 4, whose true γ² is at least 4.33 (mutation review, session 40)."""
    from obsdesign.certify.psd import check_pd
    from obsdesign.methods.stubborn import lmis

    A, C, Bd = _q([[fmpq(1, 2)]]), _q([[0]]), _q([[1]])
    X = _q([[0]])
    assert check_pd(-lmis.l2_gain(A, C, Bd, _q([[2]]), X, 4 * (1 + fmpq(1, 2**10)), True)).ok
    for g in (fmpq(4), fmpq(3)):
        for p in (fmpq(1, 100), fmpq(1, 2), fmpq(1), fmpq(2), fmpq(5, 2)):
            assert not check_pd(-lmis.l2_gain(A, C, Bd, _q([[p]]), X, g, True)).ok


def test_r_bound_instead_of_gain_bound() -> None:
    """r_bound alone (no gain bound) also makes the best λ finite; R ⪯ r_bound·I is certified
    and a reported R just above the bound fails exactly that claim."""
    text = EX1.read_text().replace("gain_bound = 100", "r_bound = 100\nlambda_tol = 0.01")
    rep = api.design(api.load_spec_text(text, "r.toml"))
    _certified(rep)
    ids = {c.id for c in rep.claims}
    assert "r-bound" in ids and "gain-bound" not in ids
    assert rep.parameters["r_bound"] == 100
    d = rep.to_dict()
    _set(d, "R", np.array([[fmpq(100) + TINY]], dtype=object))
    assert _failed(d) == {"r-bound"}


@pytest.mark.parametrize("mode", ["full", "redesign"])
def test_linear_modes_refuse_an_expression_plant(mode: str) -> None:
    """LMIs (1)-(3)/(7)-(9) certify the linear plant: psi in full or redesign mode exits 2
    naming system.psi instead of being ignored."""
    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "astolfi-stubborn-example1.toml").read_text()
    i = text.index("[system]") + len("[system]\n")
    text = text[:i] + 'psi = ["0.001*sin(x1)", "0"]\n' + text[i:]
    if mode == "redesign" and "mode" not in text:
        text = text.replace(
            'key = "stubborn"', 'key = "stubborn"\nmode = "redesign"\nK = [[1], [1]]'
        )
    with pytest.raises(api.SpecError, match=r"system\.psi.*not read in (full|redesign) mode"):
        api.load_spec_text(text, "psi.toml")


STUB_D = """[system]
time = "{time}"
A = [[{a}]]
C = [[1]]
Bd = [[1]]
[method]
key = "stubborn"
mode = "redesign"
K = [[{k}]]
lambda = 0.5
[simulate]
horizon = {horizon}
{dt}x0 = [0]
xhat0 = [0]
noise_std = 0
outlier_rate = 0
[simulate.disturbance]
kind = "constant"
value = [1]
"""


@pytest.mark.parametrize("time", ["discrete", "continuous"])
def test_the_disturbance_enters_the_simulated_error(time: str) -> None:
    """d = 1 constant, unknown to the observer: the simulated estimate must be the observer's
    own recursion x̂⁺ = A x̂ + K sat_σ(y − x̂), σ̄⁺ = λσ̄ + R e_y², driven by the plant's y
    (written out here), not x − e with e blind to d (which gave e ≡ 0: random-spec fuzzer)."""
    disc = time == "discrete"
    text = STUB_D.format(
        time=time,
        a="0.5" if disc else "-1",
        k="0.25" if disc else "2",
        horizon=50 if disc else 5,
        dt="" if disc else "dt = 0.001\n",
    )
    sp = api.load_spec_text(text, "d.toml")
    rep = api.design(sp)
    assert rep.exit_code() == 0
    res = api.simulate(sp, rep)
    p = rep.parameters
    R, W, lam = float(p.float("R")[0][0]), float(p.float("W")[0]), float(p.float("lambda"))
    A, K = (0.5, 0.25) if disc else (-1.0, 2.0)
    assert float(res.x[-1, 0]) == pytest.approx(2.0 if disc else 1.0, rel=1e-2)
    if disc:
        x, xh, sb = 0.0, 0.0, 0.0
        for _ in range(50):
            ey = x - xh
            s = (sb / W) ** 0.5
            xh, sb, x = A * xh + K * min(s, max(-s, ey)), lam * sb + R * ey * ey, A * x + 1
        assert float(res.xhat[-1, 0]) == pytest.approx(xh, rel=1e-12, abs=1e-15)
    err = res.x[:, 0] - res.xhat[:, 0]
    assert np.abs(err).max() > 0.01  # d moves the plant; the estimate cannot follow at once


def _redesign_run(K: float, lam: float, dt: float) -> tuple[Any, Any, list[str]]:
    """A certified continuous redesign of ẋ = −x, y = x with the given K and λ, and the
    warnings of its noise-free single run at step ``dt``: (spec, report, warnings)."""
    text = (
        '[system]\ntime = "continuous"\nA = [[-1]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
        f'mode = "redesign"\nK = [[{K}]]\nlambda = {lam}\n[simulate]\nhorizon = 0.05\n'
        f"dt = {dt}\nx0 = [1]\nxhat0 = [0]\nnoise_std = 0\noutlier_rate = 0\nruns = 2\n"
    )
    sp = api.load_spec_text(text, "h.toml")
    rep = api.design(sp)
    assert rep.exit_code() == 0
    return sp, rep, api.simulate(sp, rep).info.get("warnings", [])


def test_a_step_too_large_for_heun_is_warned() -> None:
    """K = 10⁴ (given), dt = 10⁻³: dt·|eig(A − KC)| ≈ 10 > 2, so Heun's method is unstable
    and the simulated error may grow although the design is certified: simulate says so and
    gives the largest safe dt. At dt = 10⁻⁵ no warning."""
    for dt, warned in ((0.001, True), (0.00001, False)):
        _, _, notes = _redesign_run(10000, 1, dt)
        hit = [w for w in notes if "too large for this gain" in w]
        assert bool(hit) is warned, notes
        if warned:
            assert "use dt ≤ 0.0002" in hit[0]


#: discrete, K given, l2 at λ = λ_max (fraction 1): Clarabel fails the l2 step there
L2_AT_MAX = (
    '[system]\ntime = "discrete"\nA = [[0.2, -0.2], [-1, -0.7]]\nC = [[-1.4, 1]]\n'
    'Bd = [[0.9], [0.1]]\n[method]\nkey = "stubborn"\nK = [[-0.18], [-0.63]]\n'
    'lambda_fraction = 1.0\ncriterion = "l2"\n'
)


def test_l2_step_failing_falls_back_on_a_certified_bound() -> None:
    """The l2 step fails at λ_max (the solver gives up at the feasibility boundary): the
    design used to end in exit 4 although a certified point exists (random-spec fuzzer). Now
    the feasibility point, scaled by a power of two (the LMIs are homogeneous), carries a
    certified L2-gain bound γ² (not minimized: said in the notes). The bound is a true one:
    at least the H∞ norm² of e⁺ = (A − KC)e + B_d d (5.479 on a 20,001-point grid), and the
    same γ² 10 % lower fails the exact l2 check."""
    from obsdesign.api import load_spec_text

    rep = api.design(load_spec_text(L2_AT_MAX, "l2max.toml"))
    assert rep.exit_code() == 0
    assert any("γ² is a certified bound" in n for n in rep.notes)
    assert {c.id: c.status for c in rep.claims}["l2-gain"] == ClaimStatus.CERTIFIED
    g2 = float(rep.parameters["gamma2"])
    A = np.array([[0.2, -0.2], [-1, -0.7]])
    Acl = A - np.array([[-0.18], [-0.63]]) @ np.array([[-1.4, 1]])
    h = max(
        np.linalg.norm(np.linalg.solve(np.exp(1j * w) * np.eye(2) - Acl, [[0.9], [0.1]]), 2)
        for w in np.linspace(0, np.pi, 20001)
    )
    assert g2 >= h * h
    assert api.verify(rep).exit_code() == 0
    d = rep.to_dict()
    _set(d, "gamma2", _get(d, "gamma2") * fmpq(9, 10))
    assert "l2-gain" in _failed(d)


#: a redesign whose λ = 1000 is beyond A's own decay on ker C (hard-case fuzzer)
HARD_REDESIGN = """[system]
time = "continuous"
A = [[-99.91073, 2.76064, 0.23936], [1.36144, -98.99884, 1.99884], [0.1685, 0.03, -101.03]]
C = [[-1, -2, 2], [2, -2, 2]]
[method]
key = "stubborn"
K = [[0.05003, 0.06965], [-0.4542, -0.04638], [-0.3995, -0.1155]]
lambda = 1e3
"""


def test_infeasible_with_a_given_K_points_at_lambda_too() -> None:
    """Continuous, A ≈ −100·I, a given K and λ = 1000 (hard-case fuzzer): the message blamed
    the given K alone, but on ker C the (1,1) block of (1) does not depend on K; it now also
    says to try a smaller λ, raise r_bound, or omit K."""
    from obsdesign import api
    from obsdesign.errors import InfeasibleError

    text = HARD_REDESIGN + "r_bound = 1\n"
    with pytest.raises(InfeasibleError) as e:
        api.design(api.load_spec_text(text, "k.toml"))
    msg = e.value.message
    assert "with the given K" in msg and "try a smaller λ" in msg
    assert "raise r_bound (now 1)" in msg and "omit K" in msg


@pytest.mark.parametrize(
    "A, K, discrete, stable",
    [
        ("[[1]]", "[0.5]", False, False),  # A − KC = 0.5: not Hurwitz (review's spec)
        ("[[1]]", "[1]", False, False),  # A − KC = 0: on the boundary, not Hurwitz
        ("[[1]]", "[1.000001]", False, True),  # −10⁻⁶: Hurwitz, the smallest margin
        ("[[1.5]]", "[0.5]", True, False),  # A − KC = 1: on the unit circle, not Schur
        ("[[1.5]]", "[0.500001]", True, True),
    ],
)
def test_redesign_with_an_unstable_A_minus_KC_says_so(
    A: str, K: str, discrete: bool, stable: bool
) -> None:
    """Redesign with a K that leaves A − KC unstable: no λ can help (LMI (2)/(8) needs it
    Hurwitz/Schur), and the gain bound is not the redesign's to raise. The message said "try a
    smaller λ or raise gain_bound (now 100)" (stubborn review); the exact test decides."""
    from obsdesign.errors import InfeasibleError

    time = "discrete" if discrete else "continuous"
    lam = "0.9" if discrete else "1"
    text = (
        f'[system]\ntime = "{time}"\nA = {A}\nC = [[1]]\n[method]\nkey = "stubborn"\n'
        f"K = {K}\nlambda = {lam}\n"
    )
    spec = api.load_spec_text(text, "r.toml")
    from obsdesign.methods.stubborn.design import _stable_gain

    assert _stable_gain(spec, spec.options.K, discrete) == stable
    if stable:
        return
    with pytest.raises(InfeasibleError) as e:
        api.design(spec)
    msg = e.value.message
    assert "A − KC is not " + ("Schur" if discrete else "Hurwitz") in msg
    assert "gain_bound" not in msg and "smaller λ" not in msg


@pytest.mark.parametrize(
    "change, key",
    [
        (('time = "continuous"', 'time = "discrete"'), "[system.time]"),
        (("C = [[1, 0]]", "C = [[0, 1]]"), "[system.C]"),
        (("C = [[1, 0]]", "C = [[1, 1e-30]]"), "[system.C]"),
    ],
)
def test_high_gain_mode_refuses_what_it_would_ignore(change: tuple[str, str], key: str) -> None:
    """High-gain mode is the continuous-time redesign with y = x1: a discrete spec was
    certified (with the continuous ℓ-bound) and crashed in simulate, and C = [[0, 1]] was
    ignored (the observer measured x1) — stubborn review. Both are bad input naming the key."""
    text = (SPECS / "astolfi-stubborn-duffing.toml").read_text()
    assert change[0] in text
    api.load_spec_text(text, "hg.toml")  # as shipped: accepted
    with pytest.raises(SpecError) as e:
        api.load_spec_text(text.replace(change[0], change[1], 1), "hg.toml")
    assert key in str(e.value)


def test_runs_without_the_outlier_study_is_refused(ex1: Report) -> None:
    """``simulate --runs N`` without ``--study outliers`` printed one run and ignored N."""
    from obsdesign.errors import InputError

    with pytest.raises(InputError, match="--study outliers"):
        api.simulate(EX1, report=ex1, runs=3)


def test_stubborn_state_limit() -> None:
    """25 states exceed the method's limit (24: the SDPs ran past 300 s with 9.7 GB at
    n = 100 — stubborn review); the refusal names the spec and the override."""
    n = 25
    A = (
        "["
        + ", ".join(
            "[" + ", ".join("-1" if i == j else "0" for j in range(n)) + "]" for i in range(n)
        )
        + "]"
    )
    C = "[[" + ", ".join("1" for _ in range(n)) + "]]"
    text = f'[system]\ntime = "continuous"\nA = {A}\nC = {C}\n[method]\nkey = "stubborn"\n'
    with pytest.raises(SpecError) as e:
        api.design(api.load_spec_text(text, "big.toml"))
    assert "24" in str(e.value) and "max_states" in str(e.value)


def test_outlier_study_run_r_does_not_depend_on_the_number_of_runs(ex1: Report) -> None:
    """Run r draws from child r of SeedSequence(seed + 1): the RMSEs of runs 0-2 are the
    same in a study of 3 runs and in one of 5 (one generator for all runs made them
    depend on the count)."""
    from obsdesign.methods.stubborn import sim

    text = EX1.read_text().replace("dt = 0.001", "dt = 0.01")
    sp = api.load_spec_text(text, str(EX1))
    a = sim.study(sp, ex1.parameters, runs=3)["rmse"]
    b = sim.study(sp, ex1.parameters, runs=5)["rmse"]
    assert a.shape[2] == 3 and b.shape[2] == 5
    np.testing.assert_array_equal(a, b[:, :, :3])
    assert not np.array_equal(b[:, :, 3], b[:, :, 4])  # the runs differ


def test_design_notes_how_fast_the_unsaturated_error_decays() -> None:
    """The LMIs bound no decay rate for e (λ is σ̄'s): criterion K on A = 0 gives K ≈ −2.4·10⁻⁷,
    certified, and the error hardly moves (stubborn review). The note states the spectral
    abscissa of A − KC, as computed from the reported K."""
    text = (
        '[system]\ntime = "continuous"\nA = [[0]]\nC = [[-1.06729423297199477]]\n'
        '[method]\nkey = "stubborn"\nlambda = 2.5\ngain_bound = 0.5\ncriterion = "K"\n'
    )
    rep = api.design(api.load_spec_text(text, "k.toml"))
    K = rep.parameters.float("K").ravel()[0]
    want = -K * -1.06729423297199477
    (note,) = [n for n in rep.notes if n.startswith("A − KC: spectral abscissa")]
    got = float(note.split("≈ ")[1].split(" ")[0])
    assert got == pytest.approx(want, rel=1e-3) and abs(got) < 1e-3


def test_asymmetric_P_fails_every_LMI_that_carries_it(ex1: Report) -> None:
    """Continuous LMI (2) is He(PA − XC)-shaped: symmetric whatever P is, so P + 2⁻⁸⁰ on one
    off-diagonal entry (X = P K kept exact) left lmi-regional certified (audit). Every LMI
    carrying P now fails with P-positive."""
    d = ex1.to_dict()
    P, K = _get(d, "P"), _get(d, "K")
    P[0, 1] += TINY
    _set(d, "P", P)
    _set(d, "X", P @ K)
    assert {"P-positive", "lmi-global", "lmi-regional", "lmi-sector"} <= _failed(d)


def test_asymmetric_P_fails_the_l2_gain() -> None:
    """Criterion l2, continuous: the bounded-real-lemma matrix with PBd and its transpose is
    symmetric for any P; an asymmetric P certified γ² ≤ 1 against a true 19.6 (audit). A
    2⁻⁸⁰ asymmetry now fails l2-gain."""
    text = (
        EX1.read_text()
        .replace('criterion = "R"', 'criterion = "l2"')
        .replace("C = [[1, 1]]", "C = [[1, 1]]\nBd = [[0], [1]]")
    )
    rep = api.design(api.load_spec_text(text, "l2.toml"))
    assert rep.exit_code() == 0
    d = rep.to_dict()
    P, K = _get(d, "P"), _get(d, "K")
    P[1, 0] += TINY
    _set(d, "P", P)
    _set(d, "X", P @ K)
    assert "l2-gain" in _failed(d)


@pytest.mark.parametrize("key", ["lambda", "lambda_max"])
def test_a_scalar_given_as_two_numbers_is_refused(ex1: Report, tmp_path: Path, key: str) -> None:
    """λ = [x, anything] was cut to x and verified with exit 0 (audit): a failed
    ``parameters-wellformed`` claim naming the key, exit 1, as for a matrix of another shape
    (it was exit 2 until session 42, the one malformed parameter that was bad input)."""
    d = ex1.to_dict()
    x = d["parameters"]["exact"][key]
    d["parameters"]["exact"][key] = [x, "12345"]
    d["parameters"][key] = [d["parameters"][key], 12345.0]
    out = tmp_path / "two.json"
    # [x] and [[x]] too: read as x until session 41 (shape review)
    f0 = d["parameters"][key][0]
    for one, got in (([x, "12345"], "2"), ([x], "1"), ([[x]], "1×1")):
        d["parameters"]["exact"][key] = one
        d["parameters"][key] = f0
        out.write_text(json.dumps(d))
        r = CliRunner().invoke(app, ["verify", str(out), "--format", "json"])
        assert r.exit_code == 1, r.output
        claims = json.loads(r.output)["claims"]
        bad = [c for c in claims if c["id"] == "parameters-wellformed"]
        assert bad and bad[0]["status"] == "failed"
        assert f"parameters.{key}: expected shape a scalar, got {got}" in bad[0]["detail"]


def test_the_single_run_reports_the_error_from_its_recursion() -> None:
    """The single run's metrics and CSV take x̂ − x from the error recursion (res.error), not
    x − (x − E): that lost the error's digits for a large state (x0 = 1e17 printed final |e|
    0.0 for 0.0052: simulate review 19). At an ordinary state both agree."""
    from obsdesign import api

    res = api.simulate(EX1)
    assert res.error is not None
    np.testing.assert_allclose(res.error, res.xhat - res.x, atol=1e-12)


def test_a_single_run_is_not_refused_by_the_study_memory_estimate() -> None:
    """A single run of 10⁶ steps was refused by the memory estimate of the outlier study's
    100 runs ("100 run(s) … 8.94 GiB"; independent simulate review): without ``study`` the
    estimate is one run's; with it, the study's runs, refused as before."""
    from obsdesign.errors import InputError

    text = (SPECS / "astolfi-stubborn-example1.toml").read_text()
    sp = api.load_spec_text(text.replace("horizon = 10\n", "horizon = 1000\n"), "long.toml")
    api.check_sim_memory(sp, {})
    api.check_sim_memory(sp, {"study": "outliers"})  # the study keeps no trajectories
    # ... but steps 4 observers × amplitudes × runs at once: 10,000 amplitudes took 4.3 GB
    huge = api.load_spec_text(text.replace("horizon = 10\n", "horizon = 100000\n"), "h.toml")
    with pytest.raises(InputError, match=r"h\.toml: simulating 1 run\(s\) × 1e\+08 steps"):
        api.check_sim_memory(huge, {})  # one run, as the estimate (it said "100 run(s)")
    many = "amplitudes = [" + ", ".join(["1"] * 10_000) + "]"
    sp = api.load_spec_text(text.replace("amplitudes = [", many + "\n#", 1), "many.toml")
    api.check_sim_memory(sp, {})
    with pytest.raises(InputError, match=r"many\.toml: simulating 100 run\(s\)"):
        api.check_sim_memory(sp, {"study": "outliers"})


STUDY = {"study": "outliers", "runs": "2"}


@pytest.mark.parametrize(
    "spec, options, still, where",
    [
        ("astolfi-stubborn-example1.toml", {}, 1, "the plant at step 0 of 10,000"),
        ("astolfi-stubborn-example1.toml", {}, 11, "the stubborn observer at step 0 of 10,000"),
        (
            "astolfi-stubborn-example1.toml",
            STUDY,
            21,
            "the nominal run of the outlier study at step 0 of 10,000",
        ),
        (
            "astolfi-stubborn-example1.toml",
            STUDY,
            31,
            r"the outlier study \(2 runs an amplitude\) at step 0 of 10,000",
        ),
        ("astolfi-stubborn-duffing.toml", {}, 1, "the high-gain observers at step 0 of 10,000"),
    ],
)
def test_simulate_time_limit_stops_every_scenario(spec, options, still, where, slow_clock):
    """``[simulate] time_limit`` / ``--option time_limit`` bound the single run (plant and
    observer), the outlier study (its nominal run and its runs) and the high-gain scenario: a
    single run of 10⁶ steps took 114 s with no way to stop it (review 19). The clock stands
    still for the first ``still`` looks (the budget's start and the loops before the one
    tested: one look per 1024 steps, per chunk in the study), then jumps past the budget:
    exit 3 naming the key and how far the run got."""
    from obsdesign.errors import SolverError

    sp = api.load_spec(SPECS / spec)
    rep = api.design(sp)
    slow_clock(still - 1)
    with pytest.raises(SolverError, match=rf"within 999 s \(\[simulate\] time_limit\): {where}"):
        api.simulate(sp, rep, options={**options, "time_limit": "999"})


def test_simulate_time_limit_key_is_read_and_checked() -> None:
    """``[simulate] time_limit`` is a key of the method (it was an unknown key), > 0."""
    from obsdesign.errors import SpecError

    text = (SPECS / "astolfi-stubborn-example1.toml").read_text()
    sp = api.load_spec_text(text.replace("[simulate]\n", "[simulate]\ntime_limit = 12.5\n"))
    assert sp.simulate.options.time_limit == 12.5
    with pytest.raises(SpecError, match=r"\[simulate\.time_limit\]"):
        api.load_spec_text(text.replace("[simulate]\n", "[simulate]\ntime_limit = 0\n"))


# -- mutation review 20: conditions that no test decided before --------------------------
def _always_infeasible(monkeypatch: pytest.MonkeyPatch) -> None:
    """The far end's solver answer forced to 'infeasible' (the near end, re-solved since
    session 43, to 'optimal': the first solve of each verify is the far end's): the side
    conditions of the bracket must decide on their own (a solver that says infeasible
    anywhere must not widen them)."""
    from obsdesign.methods.stubborn import design as dz

    def feasibility(pl: Any, o: Any) -> Any:
        calls: list[float] = []

        def solve(lam: float) -> tuple[bool, str]:
            calls.append(lam)
            return (False, dz.INFEASIBLE) if len(calls) == 1 else (True, "optimal")

        return solve

    monkeypatch.setattr(dz, "Feasibility", feasibility)


def _bracket_claim(d: dict[str, Any]) -> Any:
    rep, problems = Report.from_dict(json.loads(json.dumps(d)))
    assert not problems
    (claim,) = [c for c in api.verify(rep).claims if c.id == "lambda-max-bracket"]
    return claim


@pytest.mark.parametrize(
    "which, lam_max, bracket, ok",
    [
        # continuous: the far end strictly above λ_max, λ_max strictly above 0
        ("ex1", None, lambda lo: [lo, lo], False),
        ("ex1", fmpq(0), lambda lo: [fmpq(0), fmpq(1)], False),
        # a continuous λ_max ≤ 1 is a valid rate: the side check must accept it
        ("ex1", fmpq(1, 2), lambda lo: [fmpq(1, 2), fmpq(1)], True),
        # discrete: the far end strictly between 0 and λ_max
        ("ex4", None, lambda lo: [lo, lo], False),
        ("ex4", None, lambda lo: [lo, fmpq(0)], False),
    ],
    ids=["cont-equal", "cont-zero", "cont-below-one", "disc-equal", "disc-zero"],
)
def test_bracket_sides_are_strict_whatever_the_solver_says(
    ex1: Report,
    ex4: Report,
    monkeypatch: pytest.MonkeyPatch,
    which: str,
    lam_max: Any,
    bracket: Any,
    ok: bool,
) -> None:
    """0 < λ_max < far (continuous), 0 < far < λ_max (discrete), each strict, with the
    solver's answer forced to 'infeasible'; a continuous λ_max below 1 is on the right side."""
    _always_infeasible(monkeypatch)
    d = (ex1 if which == "ex1" else ex4).to_dict()
    if lam_max is not None:
        _set(d, "lambda_max", lam_max)
    lo = _get(d, "lambda_max")
    _set(d, "lambda_bracket", np.array(bracket(lo), dtype=object))
    claim = _bracket_claim(d)
    if ok:
        assert claim.status == ClaimStatus.NUMERICAL, claim.detail
    else:
        assert claim.status == ClaimStatus.FAILED and "far end on the wrong side" in claim.detail


def test_a_reported_X_of_the_wrong_shape_is_refused(ex1: Report) -> None:
    """X = P K must be n × p: an extra column (P K beside zeros) is malformed, not a match of
    its first p columns."""
    d = ex1.to_dict()
    X = _get(d, "X")
    n, p = X.shape
    wide = np.array(
        [[X[i, j] if j < p else fmpq(0) for j in range(p + 1)] for i in range(n)], dtype=object
    )
    _set(d, "X", wide)
    assert _failed(d) == {"parameters-wellformed"}


def test_point_failures_names_each_failed_check(ex1: Report, ex4: Report) -> None:
    """The design's self-check (a rounded candidate is kept only when it names no failure)
    lists the failed checks: none for a certified point, U-positive and lmi-global for u₁ = 0,
    l2-gain for a γ² below the certified one."""
    from obsdesign.api import bind
    from obsdesign.methods.stubborn.claims import point_failures

    def cand(rep: Report) -> dict[str, Any]:
        p = rep.parameters
        out = {k: np.asarray(p[k], dtype=object) for k in ("P", "K", "Y", "R")}
        out["U"] = np.asarray(p["U"], dtype=object).reshape(-1)
        out["W"] = np.asarray(p["W"], dtype=object).reshape(-1)
        out["lambda"] = p["lambda"]
        if "gamma2" in p:
            out["gamma2"] = p["gamma2"]
        return out

    sp1, sp4 = bind(api.load_spec(EX1)), bind(api.load_spec(EX4))
    c1 = cand(ex1)
    assert point_failures(sp1, c1, False) == []
    c1["U"] = c1["U"].copy()
    c1["U"][0] = fmpq(0)
    assert point_failures(sp1, c1, False) == ["U-positive", "lmi-global"]
    c4 = cand(ex4)
    assert point_failures(sp4, c4, True) == []
    c4["gamma2"] = c4["gamma2"] * fmpq(9, 10)
    assert point_failures(sp4, c4, True) == ["l2-gain"]


def test_the_reported_r_bound_is_the_specs() -> None:
    """The report's copy of [method].r_bound is compared with the spec (like gain_bound): a
    report claiming another bound fails r_bound-matches-spec."""
    text = EX1.read_text().replace("gain_bound = 100", "r_bound = 100\nlambda_tol = 0.01")
    rep = api.design(api.load_spec_text(text, "r.toml"))
    d = rep.to_dict()
    _set(d, "r_bound", fmpq(101))
    assert _failed(d) == {"r_bound-matches-spec"}


def test_the_search_cap_is_said_with_the_right_side_and_no_bracket() -> None:
    """n = 1, C = 1 (outsider trial, session 22): the LMIs hold for every λ, so the search
    stops at its cap. Continuous time: 'best λ ≥ 524288', no bracket; discrete time, where the
    best λ is the smallest, the note said '≥ 1e-06' — it is '≤'. Both say the search stopped at
    its cap, and every claim is still certified."""
    # the bound rounded outward: "≤ 1e-06" was below the certified 1.0000003e-6 (session 43)
    for time, A, side, at in (
        ("continuous", 1, "≥", "524288"),
        ("discrete", 2, "≤", "0.00000100001"),
    ):
        text = (
            f'[system]\ntime = "{time}"\nA = [[{A}]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
            "gain_bound = 10\n"
        )
        rep = api.design(api.load_spec_text(text, f"cap-{time}.toml"))
        assert rep.exit_code() == 0
        note = next(n for n in rep.notes if n.startswith("best λ"))
        assert note.startswith(f"best λ {side} {at} ") and "stops at its cap" in note, note
        assert "lambda_bracket" not in rep.parameters
        assert "lambda-max-bracket" not in {c.id for c in rep.claims}


def test_a_step_too_large_for_the_adaptive_level_is_warned() -> None:
    """λ = 1000 given, ‖K‖ small, dt = 10⁻² (outsider trial, session 22): dt·λ = 10 > 2, so
    the Heun step of σ̄' = −λσ̄ + e_yᵀRe_y is unstable (at λ = 262144, dt = 10⁻³ it sent σ̄ to 0
    at once and the outlier study's constant levels were 0), while dt·|eig(A − KC)| = 0.03 is
    fine. The single run and the outlier study both warn, naming λ; at dt = 10⁻³ neither."""
    for dt, warned in ((0.01, True), (0.001, False)):
        sp, rep, notes = _redesign_run(2, 1000, dt)
        hit = [w for w in notes if "the rate λ of the adaptive level" in w]
        assert bool(hit) is warned, notes
        if warned:
            assert "dt·λ ≈ 10 > 2" in hit[0] and "use dt ≤ 0.002" in hit[0]
        with warnings.catch_warnings(record=True) as caught:  # the study on its own
            warnings.simplefilter("always")
            study(sp, rep.parameters, runs=2)
        said = [str(w.message) for w in caught if "adaptive level" in str(w.message)]
        assert bool(said) is warned, said


def test_a_slow_continuous_plant_finds_its_best_lambda_below_1e_6() -> None:
    """A plant at time scale 10⁹ (A, C of size 10⁻⁹): the best λ is about 10⁻⁹. The search
    stopped at 10⁻⁶ and said "LMIs (1)-(3) infeasible for every λ tried: raise gain_bound"
    (exit 1), though λ = 10⁻¹¹ certifies (unusual-spec trial, session 24). It now goes down
    by 10⁴ a step (to 10⁻³⁰) and certifies λ_max ≈ 10⁻⁹; verify agrees."""
    text = (
        '[system]\ntime = "continuous"\nA = [[0, 1e-9], [-1e-9, -1e-9]]\nC = [[1e-9, 0]]\n'
        '[method]\nkey = "stubborn"\n'
    )
    rep = api.design(api.load_spec_text(text, "slow.toml"))
    assert rep.exit_code() == 0
    lam_max = float(rep.parameters.float("lambda_max"))
    assert 1e-10 < lam_max < 1e-8
    assert api.verify(rep).exit_code() == 0


def test_a_gain_bound_too_small_for_every_lambda_is_infeasible() -> None:
    """The downward search ends at its floor: A = 1, C = 1 needs |K| > 1 for A − KC
    Hurwitz, so with gain_bound = 1/2 no λ > 0 is feasible; exit 1 naming the bound."""
    from obsdesign.errors import InfeasibleError

    text = (
        '[system]\ntime = "continuous"\nA = [[1]]\nC = [[1]]\n'
        '[method]\nkey = "stubborn"\ngain_bound = 0.5\n'
    )
    with pytest.raises(InfeasibleError, match="every λ tried.*gain_bound"):
        api.design(api.load_spec_text(text, "bound.toml"))


U_PULSE = """
[system]
time = "continuous"
A = [[0, 1], [-1, -0.5]]
B = [[0], [1]]
C = [[1, 0]]
[method]
key = "stubborn"
K = [[1], [1]]
lambda = 1
[simulate]
horizon = 1
dt = 0.1
x0 = [0, 0]
xhat0 = [0, 0]
[simulate.u]
kind = "windows"
windows = [{ start = START, stop = STOP, value = [10] }]
[simulate.noise]
kind = "zero"
"""


@pytest.mark.parametrize("k", [4, 5, 6, 7])
def test_a_sampled_input_is_held_over_its_step(k: int) -> None:
    """[simulate.u] in continuous time: the sample u_k drives the plant over [t_k, t_{k+1})
    in every RK4 stage (the stages looked up round(t/dt), and round-half-even gave a
    one-sample pulse its full impulse at an even index and a third of it at an odd one:
    x₂(1) = 0.996 / 0.225 / 0.725 / 0.797 for k = 4..7 against 0.637 / 0.713 / 0.785 / 0.854;
    simulate-correctness trial, session 25). Compared with the exact zero-order hold."""
    from scipy.linalg import expm

    text = U_PULSE.replace("START", f"{k / 10 - 0.05:.2f}").replace("STOP", f"{k / 10 + 0.05:.2f}")
    res = api.simulate(api.load_spec_text(text, "pulse.toml"))
    A, B, dt = np.array([[0, 1], [-1, -0.5]]), np.array([[0.0], [1.0]]), 0.1
    G = expm(np.block([[A, B], [np.zeros((1, 3))]]) * dt)
    x = np.zeros(2)
    for j in range(10):
        x = G[:2, :2] @ x + G[:2, 2] * (10.0 if j == k else 0.0)
        assert np.allclose(res.x[j + 1], x, atol=1e-5), (j, res.x[j + 1], x)


def test_an_explicit_zero_noise_is_zero() -> None:
    """[simulate.noise] kind = "zero" given: y = C x exactly (it was taken for a missing
    table and replaced by the outlier noise of amplitude 10; simulate-correctness trial,
    session 25). Without the table the outlier model still runs."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0.9, 0.2], [-0.1, 0.8]]\nC = [[1, 0]]\n'
        '[method]\nkey = "stubborn"\n[simulate]\nhorizon = 20\nx0 = [1, 0]\nxhat0 = [0, 0]\n'
    )
    zero = api.simulate(api.load_spec_text(text + '[simulate.noise]\nkind = "zero"\n', "z.toml"))
    assert np.array_equal(zero.y[:, 0], zero.x[:, 0])
    default = api.simulate(api.load_spec_text(text, "z.toml"))
    assert not np.array_equal(default.y[:, 0], default.x[:, 0])


def test_constant_levels_are_taken_after_the_first_step(ex1: Report) -> None:
    """The constant-saturation levels of the outlier study are the mean and max of σ_i(t)
    over t = dt … T (a documented choice, docs/methods/stubborn.md): σ(0) = sigma0 is the
    initialization, and a huge sigma0 does not become the max level."""
    from obsdesign.methods.stubborn.options import SimOptions
    from obsdesign.methods.stubborn.sim import Gains, sigma_levels

    sp = api.load_spec_text(EX1.read_text(), "ex1.toml")
    g = Gains.of(sp, ex1.parameters)
    so = sp.simulate.options or SimOptions()
    e0 = np.asarray(sp.simulate.x0.f, float) - np.asarray(sp.simulate.xhat0.f, float)
    big = SimOptions(so.noise_std, so.outlier_rate, so.amplitudes, so.runs, 1e6)
    sig, mean, mx = sigma_levels(g, e0, big, 200, 0.01, 0)
    assert sig.shape == (200, g.C.shape[0])
    assert np.all(mx < np.sqrt(1e6 / g.w))  # σ_i(0) = √(σ̄(0)/w_i) is not among them
    assert np.array_equal(mx, sig.max(axis=0)) and np.array_equal(mean, sig.mean(axis=0))


def test_no_bracket_without_an_infeasible_far_end(monkeypatch) -> None:
    """A far end the solver answered other than 'infeasible' (infeasible_inaccurate up to the
    cap) was still reported as the bracket, and the design failed its own
    lambda-max-bracket claim: exit 1 on a valid design (soundness trial, session 25). Such
    a search now reports λ_max with no bracket and says why."""
    from obsdesign.methods.stubborn import design as D

    real = D.search_lambda

    def inaccurate(pl, o):  # noqa: ANN001, ANN202
        good, bad, _ = real(pl, o)
        return good, bad, "infeasible_inaccurate"

    monkeypatch.setattr(D, "search_lambda", inaccurate)
    rep = api.design(api.load_spec_text(EX1.read_text(), "ex1.toml"))
    assert rep.exit_code() == 0 and "lambda_bracket" not in rep.parameters
    assert "lambda-max-bracket" not in {c.id for c in rep.claims}
    assert any("infeasible nowhere up to the cap" in n for n in rep.notes), rep.notes
    assert api.verify(rep).exit_code() == 0


def _certified_or_inconclusive(text: str) -> Report | None:
    """Design ``text``: a certified report that verifies, or None for exit 4 (no verdict);
    an InfeasibleError (exit 1) fails the test — these specs are feasible (exact
    certificates of the session-25 soundness trial)."""
    try:
        rep = api.design(api.load_spec_text(text, "feasible.toml"))
    except InfeasibleError as e:
        raise AssertionError(f"a false infeasibility verdict: {e}") from None
    except InconclusiveError:
        return None
    assert rep.exit_code() == 0 and api.verify(rep).exit_code() == 0
    return rep


def test_a_given_lambda_the_solver_is_unsure_of_is_no_infeasibility_verdict() -> None:
    """Example 1 at λ = 7.53: Clarabel answers inaccurately there, and the design said "LMIs
    (1)-(3) infeasible at the given λ" (exit 1), where a certificate exists (the method
    page's own reproduced numbers; soundness trial, session 25). Only the solver's
    'infeasible' is a verdict; the certification decides otherwise (here: certified)."""
    text = (
        '[system]\ntime = "continuous"\nA = [[0, 1], [-1, 0]]\nC = [[1, 1]]\n'
        '[method]\nkey = "stubborn"\nlambda = 7.53\n'
    )
    _certified_or_inconclusive(text)


L2_BIG_BD = """
[system]
time = "continuous"
A = [[0.346, -0.582, -0.521, -1.923], [-1.174, -0.674, 0.108, 1.52],
     [0.269, 0.091, 0.348, -1.401], [0.048, -0.868, -0.574, 2.036]]
C = [[1.847, 0.977, 0.543, 0.504]]
Bd = [[-965.1, -1255], [334.7, -447.2], [-776.7, -80.32], [-72.47, 189.2]]
[method]
key = "stubborn"
criterion = "l2"
gain_bound = 1000
lambda_fraction = 0.9
"""


def test_an_infeasible_criterion_step_falls_back_on_the_feasibility_point() -> None:
    """Criterion l2 with B_d ~ 10³: the criterion step's SDP (He(G) + I ≺ 0 with ‖X‖ ≤
    gain_bound) came back infeasible and the design said "LMIs (1)-(3) infeasible at λ = …
    with the criterion step" (exit 1), at a λ below the certified λ_max (soundness trial,
    session 25). As documented, the certified feasibility point at that λ is reported, with
    a certified γ² for it."""
    rep = _certified_or_inconclusive(L2_BIG_BD)
    assert rep is None or "gamma2" in rep.parameters


def test_a_slow_plant_is_no_infeasibility_verdict() -> None:
    """A, C of size 10⁻⁹ with the default gain bound: the fixed margin δ = 10⁻⁶ needs P ~ 10³
    to lift LMI entries of size 10⁻⁹ above it, and X = PK then passes the gain bound; every
    λ was 'infeasible' and the design said exit 1, where exact certificates exist (soundness
    trial, session 25). The margin is now δ·min(1, λ) in continuous time; what the solver
    does not settle is exit 4, never exit 1."""
    text = (
        '[system]\ntime = "continuous"\nA = [[1e-9, 2e-9], [-3e-9, 1e-9]]\nC = [[1e-9, 0]]\n'
        '[method]\nkey = "stubborn"\n'
    )
    _certified_or_inconclusive(text)


def test_a_single_run_with_outliers_of_1e160_stays_finite() -> None:
    """Every sample an outlier of amplitude 10¹⁶⁰: σ̄ ≈ a²‖R‖ overflowed, and the single run
    printed nan for every metric and "leaves the float range" while the Luenberger run gave
    |e| ≈ 6·10¹⁵⁹ (soundness trial, session 33). With the level carried as √σ̄ the run is
    finite: σ finite, |e| about the Luenberger observer's size."""
    text = (
        '[system]\ntime = "discrete"\nA = [[1.2, 1, 0, 0], [0, 0.9, 0.3, 0], [0, 0, 1.05, 1], '
        '[0.1, 0, 0, 0.5]]\nC = [[1, 0, 0, 0], [0, 0, 1, 0]]\n[method]\nkey = "stubborn"\n'
        'criterion = "K"\ngain_bound = 10\n[simulate]\nhorizon = 20\nx0 = [1, -1, 2, 0.5]\n'
        'xhat0 = [-3, 4, 0, 0]\n[simulate.noise]\nkind = "outliers"\namplitude = 1e160\n'
        "rate = 1\nbound = 0\n"
    )
    sp = api.load_spec_text(text, "single.toml")
    rep = api.design(sp)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = api.simulate(sp, rep)
    lu = api.simulate(sp, rep, options={"observer": "luenberger"})
    err, err_lu = np.abs(res.error).max(), np.abs(lu.error).max()
    assert np.all(np.isfinite(res.error)) and np.all(np.isfinite(res.extra["sigma"]))
    assert 1e158 < err < 1e162 and 1e158 < err_lu < 1e162
    assert np.isinf(res.extra["sigma_bar"]).any()  # σ̄ itself is beyond the float range


def test_outliers_near_the_float_range_give_inf_not_nan() -> None:
    """Outliers of amplitude 10³⁰⁰ at every sample: the squares overflowed, and the study
    printed numpy's RuntimeWarnings and a NaN RMSE (inf − inf) for the stubborn observer
    (soundness trial, session 25). Since the level is carried as √σ̄ (session 33) such runs
    are finite and scale with the amplitude (the error dynamics are positively homogeneous:
    e, ν → c·e, c·ν with σ̄ → c²σ̄), where σ̄ ≈ a²‖R‖ made the stubborn RMSE inf from
    a ≈ 10¹⁵⁴ on. An error that does leave the float range (a = 1.7·10³⁰⁸) is inf, said
    once, never NaN."""
    from obsdesign.methods.stubborn.sim import study

    def run(amp: str) -> tuple[dict, list]:
        text = (
            '[system]\ntime = "continuous"\nA = [[0, 1], [0, 0]]\nC = [[1, 0]]\n'
            '[method]\nkey = "stubborn"\n[simulate]\nhorizon = 1\ndt = 0.001\nx0 = [1, 0]\n'
            f"xhat0 = [0, 0]\nsigma0 = 0\nnoise_std = 0\noutlier_rate = 1\namplitudes = [{amp}]\n"
            "runs = 2\n"
        )
        sp = api.load_spec_text(text, "amp.toml")
        rep = api.design(sp)
        with warnings.catch_warnings(record=True) as got:
            warnings.simplefilter("always")
            st = study(sp, rep.parameters)
        assert not [w for w in got if issubclass(w.category, RuntimeWarning)], got
        return st["median_rmse"], got

    big, got = run("1e300")
    small, _ = run("1e150")
    assert not got
    for ob in ("luenberger", "stubborn"):
        for x in ("x1", "x2"):
            assert big[ob]["1e+300"][x] == pytest.approx(small[ob]["1e+150"][x] * 1e150, rel=1e-9)
    huge, got = run("1.7e308")
    assert any("left the float range" in str(w.message) for w in got)
    vals = [v for ob in huge.values() for a in ob.values() for v in a.values()]
    assert not any(np.isnan(v) for v in vals) and np.inf in vals
    assert huge["stubborn"]["1.7e+308"]["x1"] == np.inf


@pytest.mark.parametrize(
    "time, A, C, lam",
    [
        ("discrete", "[[1e-8, 1], [0, 1e-8]]", "[[1e8, 0]]", None),
        ("discrete", "[[0, 1], [0, 0]]", "[[1000000, 0]]", None),
        ("continuous", "[[1e-8, 1e8], [-1e-8, 1e-8]]", "[[1, 0]]", None),
        ("continuous", "[[1e-8, 1e8], [-1e-8, 1e-8]]", "[[1, 0]]", 0.1),
    ],
)
def test_solver_infeasible_on_badly_scaled_data_is_no_verdict(
    time: str, A: str, C: str, lam: float | None
) -> None:
    """Clarabel answered `infeasible` on these feasible LMIs (exit 1): A = [[1e-8, 1],
    [0, 1e-8]] is Schur, and K = 0 with P = diag(2c², 6c²), U = R = W = 1, Y = −WC, λ = 1/2
    satisfies (7)-(9) exactly for C = [[c, 0]] (edge-shape trial, session 26, its exact
    witness). With the nonzero entries of A and C spanning more than 10⁵ the status is no
    proof: exit 4 (inconclusive), saying so; well-scaled plants keep their exit-1 verdicts
    (the test above)."""
    text = f'[system]\ntime = "{time}"\nA = {A}\nC = {C}\n[method]\nkey = "stubborn"\n' + (
        f"lambda = {lam}\n" if lam is not None else ""
    )
    try:
        rep = api.design(api.load_spec_text(text, "s.toml"))
    except InconclusiveError as e:
        # or the solver's own answer was not `infeasible` (the discrete search kept
        # "infeasible" whatever it said, until session 30)
        assert "no proof of infeasibility" in e.message or "not a verdict" in e.message
    else:  # a solver that copes certifies it
        assert rep.exit_code() == 0


def test_solver_infeasible_with_a_badly_scaled_given_gain_is_no_verdict() -> None:
    """The redesign of the double integrator with the slow K = (10⁻⁵, 10⁻¹⁰) was exit 1
    ("infeasible for every λ tried"), yet K = (a, a²) is the unit gain (1, 1) in the
    coordinates diag(1, 1/a)·e and time a·t, and the unit design's certificate rescaled
    certifies it (search-space/stubborn trial, session 31): the spread rule looked at A and C
    only. The given K counts now: exit 4, naming it; K = (1, 1) still designs."""
    text = (
        '[system]\ntime = "continuous"\nA = [[0, 1], [0, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "stubborn"\nK = {K}\n'
    )
    with pytest.raises(InconclusiveError, match="entries of A, C and the given K span a factor"):
        api.design(api.load_spec_text(text.format(K="[[0.00001], [0.0000000001]]"), "s.toml"))
    assert api.design(api.load_spec_text(text.format(K="[[1], [1]]"), "s.toml")).exit_code() == 0


@pytest.mark.parametrize(
    ("A", "C", "K", "time"),
    [
        ("[[0, 1], [0, 0]]", "[[1, 0]]", "[1, 0]", "continuous"),  # s(s + 1): an eigenvalue 0
        ("[[0, 1], [-1, 0]]", "[[1, 0]]", "[0, 0.5]", "continuous"),  # s² + 3/2: ±i√(3/2)
        ("[[0.5, 1], [0, 0.5]]", "[[1, 0]]", "[1.5, 0]", "discrete"),  # eigenvalue −1
    ],
)
def test_a_given_gain_on_the_stability_boundary_is_infeasible(
    A: str, C: str, K: str, time: str
) -> None:
    """A given K with A − KC on the stability boundary ended with exit 4 ("the solver's
    best λ ≈ 0.0018 could not be certified"): the exact Hurwitz test ran only after a solver
    said "infeasible" (constrained/stubborn soundness trial, session 28). It runs first."""
    text = f'[system]\ntime = "{time}"\nA = {A}\nC = {C}\n[method]\nkey = "stubborn"\nK = {K}\n'
    with pytest.raises(InfeasibleError, match="A − KC is not (Hurwitz|Schur).*for the given K"):
        api.design(api.load_spec_text(text, "marginal.toml"))


def test_a_given_schur_gain_of_a_discrete_plant_is_not_refused() -> None:
    """Mutation review 28: obsdesign.methods.stubborn.design.x_design_params__mutmut_16 (``_stable_gain(spec,
    o.K, None)``: a discrete plant's A − KC tested for Hurwitz, not Schur): a given K with
    A − KC Schur stable (eigenvalues 0.5, 0.5, not Hurwitz) is designed, not refused "at
    every λ"; every given-K test had a gain on the boundary (refused either way)."""
    from obsdesign.errors import ObsdesignError

    text = (
        '[system]\ntime = "discrete"\nA = [[0.5, 1], [0, 0.5]]\nC = [[1, 0]]\n'
        '[method]\nkey = "stubborn"\nK = [0.25, 0]\n'
    )
    try:
        rep = api.design(api.load_spec_text(text, "schur.toml"))
    except ObsdesignError as e:
        assert "for the given K" not in str(e), str(e)
    else:
        assert rep.exit_code() in (0, 4)


@pytest.mark.parametrize("amp", [1e160, 1e-200])
def test_outlier_study_rmse_of_errors_beyond_the_squares_range(amp: float) -> None:
    """Outliers of 1e160 made the Luenberger RMSE inf (its error stays below ~1e161) and
    outliers of 1e-200 made it 0 (re-check trial, session 29): the sum of squares is kept
    scaled, so the median RMSE is finite and positive, of the amplitude's order."""
    from obsdesign import api

    text = (
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
        "[simulate]\nhorizon = 40\nx0 = [0]\nxhat0 = [0]\nruns = 3\nnoise_std = 0\n"
        f"outlier_rate = 0.5\namplitudes = [{amp!r}]\n"
    )
    m = api.simulate(api.load_spec_text(text, "s.toml"), study="outliers").metrics()
    med = m["outlier_study_median_rmse"]["luenberger"][f"{amp:g}"]["x1"]
    assert math.isfinite(med) and 0 < med and amp * 1e-3 < med < amp * 10


REDESIGN_DOUBLE_INTEGRATOR = """
[system]
time = "continuous"
A = [[0, 1], [0, 0]]
C = [[1, 0]]
[method]
key = "stubborn"
K = [2, 1]
lambda_fraction = 0.5
"""


def test_redesign_lambda_max_point_is_the_spec_gain() -> None:
    """verify took a redesign report whose λ_max certificate (``*_at_max``) came from another
    gain: "LMIs (1)-(3) hold at λ_max = 4 … with the given K", false for K = (2, 1), whose LMIs
    are infeasible at every λ ≥ 4 (soundness trial, session 30). K_at_max must be the spec's K,
    and the λ_max point is checked with it."""
    sp = api.load_spec_text(REDESIGN_DOUBLE_INTEGRATOR, "r.toml")
    rep = api.design(sp)
    _certified(rep)
    d = rep.to_dict()
    K = _get(d, "K_at_max")
    K[0, 0] += TINY  # the smallest change: only the comparison with the spec fails
    _set(d, "K_at_max", K)
    assert _failed(d) == {"K_at_max-matches-spec"}
    # the trial's forgery: a full design's certificate at λ = 4 (another gain) as *_at_max
    full = api.design(
        api.load_spec_text(
            REDESIGN_DOUBLE_INTEGRATOR.replace("K = [2, 1]\nlambda_fraction = 0.5", "lambda = 4"),
            "f.toml",
        )
    )
    _certified(full)
    fd = full.to_dict()
    d = rep.to_dict()
    for k in ("K", "P", "U", "W", "Y", "R"):
        _set(d, f"{k}_at_max", _get(fd, k))
    _set(d, "lambda_max", fmpq(4))
    assert {"K_at_max-matches-spec", "lambda-max-certified"} <= _failed(d)


def _scalar_discrete(a: str, extra: str = "") -> str:
    return (
        f'[system]\ntime = "discrete"\nA = [[{a}]]\nC = [[1]]\n[method]\nkey = "stubborn"\n{extra}'
    )


def test_discrete_search_keeps_the_solvers_status_at_its_most_lenient_lambda(monkeypatch):
    """The discrete search returned the status "infeasible" whenever λ = 1 − 10⁻⁶ was not
    found feasible, whatever the solver said: A = 2.414213, C = 1 (just inside the limit
    1 + √2, strictly feasible) was exit 1 "infeasible for every λ tried" on an
    `optimal_inaccurate` answer (soundness trial, session 30). The status is the solver's."""
    from obsdesign.methods.stubborn import design as sd

    sp = api.load_spec_text(_scalar_discrete("0.5"), "s.toml")
    monkeypatch.setattr(sd.Feasibility, "__call__", lambda self, lam: (False, "odd status"))
    assert sd.search_lambda(sd.Plant.of(sp), sp.options) == (1.0, 1 - 1e-6, "odd status")
    monkeypatch.undo()
    near = api.load_spec_text(_scalar_discrete("2.414213"), "s.toml")
    with pytest.raises(InconclusiveError, match="did not report them infeasible"):
        sd.design_params(near)  # the first pass: no verdict
    # the design then tries the gain bound scale-free, which certifies (session 40)
    rep = api.design(near)
    assert rep.exit_code() == 0 and rep.parameters["gain_normalization"] == "scale-free"
    assert api.verify(rep).exit_code() == 0


def test_an_infeasible_answer_that_a_smaller_margin_overturns_is_exit_4() -> None:
    """Clarabel's `infeasible` is for the problem tightened by the margin δ (F ⪯ −δI): for
    A = 2.41421356, C = 1 (2·10⁻⁹ inside the limit 1 + √2) it answered so with δ = 10⁻⁶ at every
    λ, and the design said "infeasible … even without gain_bound and at any λ < 1" (exit 1),
    though exact solutions exist (soundness trial, session 30). The answer is re-asked with
    δ/1000; feasible there, it is exit 4 naming the margin to set. A = 2.6 (beyond the limit)
    stays exit 1."""
    with pytest.raises(InconclusiveError, match=r"set \[method\] margin = 1e-9"):
        api.design(api.load_spec_text(_scalar_discrete("2.41421356"), "s.toml"))
    with pytest.raises(InfeasibleError, match="detectability does not suffice"):
        api.design(api.load_spec_text(_scalar_discrete("2.6"), "s.toml"))


def test_a_solver_failure_without_bounds_is_not_infeasible_at_any_lambda() -> None:
    """A detectable discrete plant whose C is ~10⁻³ needs a gain ≈ 1.2·10⁴: infeasible at
    gain_bound = 100 (the solver's `infeasible`), and without any bound the solver fails
    ("solver failure"), which was read as infeasible: "infeasible … at any λ ≤ 1 − 10⁻⁶:
    detectability does not suffice", exit 1, though an exact witness satisfies LMIs (7)-(9)
    at λ = 1/2 (stubborn review, session 42). Only `infeasible` is that verdict: the
    message names the gain bound."""
    text = (
        '[system]\ntime = "discrete"\n'
        "A = [[-1.0870920121814378, -0.9364996025654619], "
        "[-1.0129275696226316, -0.48433555014060464]]\n"
        "C = [[0.0014472801153936389, -0.0016013138916154473]]\n"
        '[method]\nkey = "stubborn"\n'
    )
    with pytest.raises(InfeasibleError) as ei:
        api.design(api.load_spec_text(text, "s.toml"))
    assert "raise gain_bound (now 100)" in ei.value.message
    assert "does not suffice" not in ei.value.message


def test_a_stable_mode_near_the_unit_circle_makes_discrete_infeasible_no_verdict() -> None:
    """A = diag(0.9999999, 1.5), C = (0, 1): the unseen mode needs λ > 0.9999998, beyond the
    search's most lenient 1 − 10⁻⁶, and the design said "infeasible … at any λ < 1" (exit 1),
    though an exact witness exists at λ = 0.9999999 (search-space/stubborn trial, session
    31). A stable mode within 10⁻⁵ of the unit circle makes it exit 4, naming |μ|²; with the
    mode at 0.99 it designs, and A = 2.6 keeps its exit 1, now saying "λ ≤ 1 − 10⁻⁶"."""
    text = (
        '[system]\ntime = "discrete"\nA = [[{a}, 0], [0, 1.5]]\nC = [[0, 1]]\n'
        '[method]\nkey = "stubborn"\n'
    )
    with pytest.raises(InconclusiveError, match=r"\|μ\|² ≈ 0\.9999998 \(float\), within 1e-05"):
        api.design(api.load_spec_text(text.format(a="0.9999999"), "s.toml"))
    assert api.design(api.load_spec_text(text.format(a="0.99"), "s.toml")).exit_code() == 0
    with pytest.raises(InfeasibleError, match=r"at any λ ≤ 1 − 10⁻⁶ \(the search's most"):
        api.design(api.load_spec_text(_scalar_discrete("2.6"), "s.toml"))


def test_the_bound_to_raise_is_named_with_the_spec_value() -> None:
    """`gain_bound = 1.0000001` was echoed "raise gain_bound (now 1)" (%g; soundness trial,
    session 30): the hint names the value as given."""
    text = (
        '[system]\ntime = "continuous"\nA = [[1]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
        "gain_bound = 1.0000001\n"
    )
    with pytest.raises(InfeasibleError, match=r"raise gain_bound \(now 1\.0000001\)"):
        api.design(api.load_spec_text(text, "s.toml"))


@pytest.mark.parametrize(("bound", "code"), [("1.56", 1), ("1.562501", 4), ("1.5625017", 0)])
def test_a_gain_bound_at_the_limit_is_not_called_infeasible(bound: str, code: int) -> None:
    """A = C = 1 (continuous): the LMIs are feasible iff gain_bound > 25/16 (exact witness:
    P = 1, K = k ∈ (25/16, gain_bound]). The solver keeps ‖X‖ 10⁻⁶ inside the bound, so
    gain_bound = 1.562501 was exit 1 "raise gain_bound" (re-check trial, session 30): the
    `infeasible` is re-asked with the bound tightened by 10⁻⁹ only, and is exit 4 when that
    is feasible. 1.56 (below 25/16) stays exit 1."""
    text = (
        '[system]\ntime = "continuous"\nA = [[1]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
        f"gain_bound = {bound}\n"
    )
    sp = api.load_spec_text(text, "g.toml")
    if code == 0:
        assert api.design(sp).exit_code() == 0
        return
    err = InconclusiveError if code == 4 else InfeasibleError
    with pytest.raises(err) as e:
        api.design(sp)
    assert ("at the feasibility limit" in e.value.message) == (code == 4)


def test_the_given_lambda_is_named_as_given() -> None:
    """λ = 2.99999999 was refused "infeasible at the given λ = 3" (%g; re-check trial,
    session 30)."""
    text = REDESIGN_DOUBLE_INTEGRATOR.replace("lambda_fraction = 0.5", "lambda = 2.99999999")
    with pytest.raises(InfeasibleError, match=r"at the given λ = 2\.99999999:"):
        api.design(api.load_spec_text(text, "l.toml"))


# -- mutation review 30 (docs/mutation.md)


# --- Mutation review 30: stubborn _unless_feasible_with_less_margin and its call sites
# (ready to append to tests/test_stubborn.py)


def _margin_sensitive_solver(monkeypatch, feasible_at: Any) -> list[tuple[float, float]]:
    """Feasibility answering `infeasible` at the spec's [method] margin everywhere and, with
    that margin divided by 1000, `optimal` where ``feasible_at(λ, calls)``: the list of calls
    (λ, [method] margin) is returned."""
    from obsdesign.methods.stubborn import design as sd

    calls: list[tuple[float, float]] = []

    def fake(self: Any, lam: float) -> tuple[bool, str]:
        m = float(self.o.margin)
        ok = m < 1e-7 and feasible_at(float(lam), calls)
        calls.append((float(lam), m))
        return (True, "optimal") if ok else (False, sd.INFEASIBLE)

    monkeypatch.setattr(sd.Feasibility, "__call__", fake)
    return calls


def test_the_smaller_margin_is_asked_at_the_given_lambda(monkeypatch) -> None:
    """Mutation review 30 (stubborn.design_params: the re-ask of a given λ's `infeasible`
    dropped, or asked at another λ): with λ given, an `infeasible` that the margin / 1000
    overturns at that λ is exit 4 naming the margin and the λ, not exit 1."""
    calls = _margin_sensitive_solver(monkeypatch, lambda lam, calls: lam == 0.75)
    sp = api.load_spec_text(_scalar_discrete("0.5", "lambda = 0.75\n"), "s.toml")
    with pytest.raises(InconclusiveError, match=r"feasible at λ = 0\.75 with margin 1e-9"):
        api.design(sp)
    assert [lam for lam, m in calls if m < 1e-7] == [0.75]


@pytest.mark.parametrize("time", ["discrete", "continuous"])
def test_the_smaller_margin_is_asked_at_the_most_lenient_lambda_tried(monkeypatch, time) -> None:
    """Mutation review 30 (stubborn.design_params: the re-ask after "infeasible for every λ
    tried" made at the search's good end, 1 or 0, a λ never tried, or at half the λ): it is
    asked at the most lenient λ the search tried (discrete 1 − 10⁻⁶, continuous the smallest),
    and there an answer `optimal` makes it exit 4."""

    def lenient(lam: float, calls: list[tuple[float, float]]) -> bool:
        tried = [x for x, m in calls if m >= 1e-7]
        return lam == (max(tried) if time == "discrete" else min(tried))

    calls = _margin_sensitive_solver(monkeypatch, lenient)
    text = (
        _scalar_discrete("0.5")
        if time == "discrete"
        else '[system]\ntime = "continuous"\nA = [[0, 1], [0, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "stubborn"\n'
    )
    with pytest.raises(
        InconclusiveError, match=r"infeasible for every λ tried .*set \[method\] margin"
    ):
        api.design(api.load_spec_text(text, "s.toml"))
    tried = [x for x, m in calls if m >= 1e-7]
    small = [x for x, m in calls if m < 1e-7]
    assert small == [1 - 1e-6 if time == "discrete" else min(tried)]
    assert (max(tried) == 1 - 1e-6) if time == "discrete" else (min(tried) < 1e-20)


def test_a_redesign_without_r_bound_is_not_told_to_raise_gain_bound() -> None:
    """Mutation review 30 (stubborn._bounds_too_tight: ``o.gain_bound if o.K is None else
    None`` → ``o.gain_bound``): a redesign without r_bound carries the default gain_bound 100,
    a key the redesign refuses (exit 2); the hint must not ask to raise it."""
    text = HARD_REDESIGN
    with pytest.raises(InfeasibleError) as e:
        api.design(api.load_spec_text(text, "k.toml"))
    msg = e.value.message
    assert "with the given K" in msg and "try a smaller λ" in msg and "omit K" in msg
    assert "gain_bound" not in msg


def test_the_bracket_names_the_solver_problem_its_far_end_is_infeasible_for() -> None:
    """With margin = 1 the bracket said "the largest λ with LMIs (1)-(3) feasible lies between
    4.814 and 4.818", but 6.756 certifies (the default margin's design): its far end is where
    the solver's problem is infeasible, not (1)-(3) (search-space/stubborn trial, session 31).
    Naming δ alone was still false: (1)-(3) are homogeneous, so a scaled solution meets any
    δ, and the normalization P ⪰ I, W ⪰ I with the gain bound limit it (re-check trial). The
    statement names the whole problem; the default margin's bracket lies above margin 1's."""
    text = (
        '[system]\ntime = "continuous"\nA = [[0, 1], [-1, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "stubborn"\n'
    )
    big = api.design(api.load_spec_text(text + "margin = 1\n", "m.toml"))
    small = api.design(api.load_spec_text(text, "d.toml"))
    b_big, b_small = (
        next(c for c in r.claims if c.id == "lambda-max-bracket") for r in (big, small)
    )
    assert "solver's problem is feasible (LMIs (1)-(3) with margin δ = 1·min(1, λ) (each" in (
        b_big.statement
    )
    # δ as the solver takes it (times min(1, λ) in continuous time) and the bound kept 10⁻⁶
    # inside (re-check trial, session 31)
    assert "margin δ = 0.000001·min(1, λ) (each ⪯ −δI; [method] margin), P ⪰ I, W ⪰ I, " in (
        b_small.statement
    )
    assert "‖X‖₂ ≤ gain_bound·(1 − 10⁻⁶), gain_bound = 100" in b_small.statement
    assert small.parameters["lambda_max"] > big.parameters["lambda_bracket"][-1]


# -- mutation review 32 (session 31's checks) ----------------------------------------
@pytest.mark.parametrize("m", ["1", "0.5"])
def test_discrete_infeasible_with_a_mode_not_near_one_inside_is_a_verdict(m: str) -> None:
    text = (
        f'[system]\ntime = "discrete"\nA = [[{m}, 0], [0, 2.6]]\nC = [[1, 1]]\n'
        '[method]\nkey = "stubborn"\ngain_bound = 1000000\n'
    )
    with pytest.raises(InfeasibleError, match="does not suffice"):
        api.design(api.load_spec_text(text, "s.toml"))


def test_problem_text_names_r_bound_and_a_given_K() -> None:
    """Kills S15 (the r_bound part dropped) and S16 ("the given K" dropped): the bracket's
    statement names every constraint of the solver's problem."""
    from types import SimpleNamespace

    import numpy as np
    from flint import fmpq

    from obsdesign.methods.stubborn.claims import _problem_text

    o = SimpleNamespace(
        margin=fmpq(1, 10**6),
        K=None,
        gain_bound=fmpq(100),
        r_bound=fmpq(5),
        scale_free_gain=False,
    )
    t = _problem_text(o, "(1)-(3)", False)
    assert "R ⪯ r_bound·(1 − 10⁻⁶), r_bound = 5" in t and "gain_bound = 100" in t
    assert "‖X‖₂ ≤ gain_bound·(1 − 10⁻⁶)" in t and "s·I" not in t
    o.scale_free_gain = True  # the design's retry (session 40)
    t = _problem_text(o, "(1)-(3)", False)
    assert "‖X‖₂ ≤ gain_bound·s·(1 − 10⁻⁶) with P ⪰ s·I, gain_bound = 100" in t
    o = SimpleNamespace(
        margin=fmpq(1, 10**6),
        K=np.array([[1.0]]),
        gain_bound=fmpq(100),
        r_bound=None,
        scale_free_gain=False,
    )
    t = _problem_text(o, "(7)-(9)", True)
    assert t.endswith("the given K") and "gain_bound" not in t and "r_bound" not in t


# -- mutation review 34 (session 33's checks) ----------------------------------------
def _g(w: list[float], discrete: bool = False) -> sim.Gains:
    p = len(w)
    return sim.Gains(
        -np.eye(2), np.eye(p, 2), 0.5 * np.eye(2, p), 1.0, np.eye(p), np.asarray(w, float), discrete
    )


def test_root0_weighs_the_output_error_by_the_square_root_of_w() -> None:
    """Kills T02 (w·|e_y| in place of √w·|e_y|) and T03 (no |·|): √σ̄(0) = max_i √w_i |(Ce₀)_i|,
    so σ̄(0) = max_i w_i (Ce₀)_i² (default_sigma0): with w = (4, 1), e₀ = (−1, −3) it is 3
    (σ̄ = 9), where w·|e_y| gives 4."""
    g = _g([4.0, 1.0])
    e0 = np.array([-1.0, -3.0])
    assert sim.root0_of(g, e0, None) == 3.0
    assert sim.default_sigma0(g, e0) == 9.0
    assert sim.root0_of(g, np.array([-2.0, 0.5]), None) == 4.0  # √4·|−2|
    assert sim.root0_of(g, e0, 2.25) == 1.5
    assert sim.root0_of(g, e0, -1.0) == 0.0


def test_the_adaptive_level_is_rho_over_root_w() -> None:
    """Kills T05 (ρ·√w_i in place of ρ/√w_i): σ_i = √(σ̄/w_i); one discrete step from
    e = (0, 0) with ν = (10, 10), ρ = 2, w = (4, 1): the injected output error is clipped
    at σ = (1, 2), so e₁ = −K·clip = −0.5·(1, 2)."""
    g = _g([4.0, 1.0], discrete=True)
    g.A[:] = 0.0
    _, e, _ = sim.run_errors(
        g,
        np.zeros(2),
        lambda a, b: np.full((b - a, 2), 10.0),
        1,
        1.0,
        np.full(2, np.inf),
        np.array(True),
        2.0,
    )
    assert e == pytest.approx([-0.5, -1.0])


def test_one_heun_step_uses_the_predicted_level_at_the_second_stage() -> None:
    """Kills T09 (the second stage clipped at ρ(0), not at the predicted √σ̄): scalar plant
    ė = −K sat(e + ν), K = 1, λ = 1, R = w = 1, e(0) = 0, ν = 10, ρ(0) = 1, dt = 0.1. By hand
    (σ̄ in units of M² = 100): stage 1 clips 10 at 1, de = −1, dσ̄/M² = −0.01 + 1 = 0.99;
    e₂ = −0.1, σ̄₂/M² = 0.109, so stage 2 clips 9.9 at 10·√0.109; then
    e = −0.05·(1 + 10√0.109) and ρ = 10·√(0.01 + 0.05·(0.99 − 0.109 + 0.99²))."""
    g = sim.Gains(np.zeros((1, 1)), np.eye(1), np.eye(1), 1.0, np.eye(1), np.ones(1), False)
    _, e, rho = sim.run_errors(
        g,
        np.zeros(1),
        lambda a, b: np.full((b - a, 1), 10.0),
        1,
        0.1,
        np.full(1, np.inf),
        np.array(True),
        1.0,
    )
    assert float(e[0]) == pytest.approx(-0.05 * (1 + 10 * math.sqrt(0.109)), rel=1e-12)
    assert float(rho) == pytest.approx(
        10 * math.sqrt(0.01 + 0.05 * (0.99 - 0.109 + 0.99**2)), rel=1e-12
    )


def test_the_single_runs_sigma_is_root_of_sigma_bar_over_w() -> None:
    """Kills T11 (σ = √(ρ/w) from ρ = √σ̄, a unit slip): the run's σ_i(t)² w_i = σ̄(t)
    (σ_i = √(σ̄/w_i), the slides' definition) at every step, on a shipped example."""

    from obsdesign import api

    spec = SPECS / "astolfi-stubborn-example1.toml"
    sp = api.load_spec(spec)
    rep = api.design(sp)
    res = api.simulate(sp, rep)
    w = np.asarray(rep.parameters.float("W"), float).ravel()
    sig, sb = res.extra["sigma"], res.extra["sigma_bar"]
    assert sig.shape[1] == w.size and np.all(sb > 0)
    assert sig**2 * w == pytest.approx(np.broadcast_to(sb[:, None], sig.shape), rel=1e-9)


#: the slides' printed design results (WUDS 2017 slides, Examples 1 and 3): K, R, W
SLIDES_KRW = {
    EX1: ((-11.9944, 20.4153), 3.3256e3, 528.2705),
    EX3: ((-6.7510, 11.7510), 3.0895e3, 512.6717),
}
#: ours (default criterion R, fraction 1/2, gain bound 100; docs/methods/stubborn.md)
OURS_KRW = {EX1: ((-2.56, 8.40), 32.0, 24.9), EX3: ((-1.31, 4.98), 29.2, 15.9)}


@pytest.mark.parametrize("spec", [EX1, EX3])
def test_slides_K_R_W_are_not_reproduced(spec: Path, ex1: Report) -> None:
    """Not reproduced, and why (docs/methods/stubborn.md, "Reproduced numbers"): the slides
    print K, R, W without the bound, the fraction or the normalization used. We get the docs'
    values (to the 3 digits printed there: Clarabel's last digits may move), far from the
    slides'; only K, λ and R/W define the observer, and R/W is 1.28 / 1.84 for us against the
    slides' 6.30 / 6.03."""
    rep = ex1 if spec == EX1 else api.design(spec)
    p = rep.parameters
    K, R, W = p.float("K").ravel(), float(p.float("R").item()), float(p.float("W").item())
    (k1, k2), r, w = OURS_KRW[spec]
    assert K == pytest.approx([k1, k2], rel=5e-3, abs=5e-3)
    assert (R, W) == pytest.approx((r, w), rel=5e-3)
    (s1, s2), sr, sw = SLIDES_KRW[spec]
    assert abs(K[0] - s1) > 4 and abs(K[1] - s2) > 6 and sr / R > 90 and sw / W > 20
    assert round(sr / sw, 2) == (6.30 if spec == EX1 else 6.03)
    assert round(R / W, 2) == (1.28 if spec == EX1 else 1.84)


#: the slides' Luenberger row of Example 1 at outlier amplitudes 0.1 and 1000 (x1, x2)
SLIDES_LUENBERGER_EX1 = {"0.1": (0.11, 0.12), "1000": (18.01, 29.97)}


def test_slides_rmse_tables_are_not_reproduced_and_examples_1_2_agree(ex1: Report) -> None:
    """The slides' RMSE tables are not reproduced (docs/methods/stubborn.md): their noise
    level, outlier rate, horizon, x̂(0) and "(max. abs. 10)" are not stated. With our gain
    and outlier model the Luenberger RMSE is ≈ 0.03 at amplitude 0.1 (slides 0.11 / 0.12) and
    ≈ 2 / 5 at 1000 (slides 18.01 / 29.97). With the slides' own K and an outlier rate of 0.05
    (our guess, fitted to that row, not the slides' statement) the 1000 column comes within
    10 % of the printed one at this test's dt = 2 ms (an outlier per integration step, held for
    dt: at the shipped 1 ms it is 12.1 / 20.1, 33 % below; what is fitted is rate·dt, papers
    and docs reviews 46), while the 0.1 column stays ≈ 0.03: the base level is not
    explained. Example 2 differs from Example 1 only in u, which the error does not see, so
    its table is Example 1's (to rounding), where the slides' two tables differ slightly."""
    from obsdesign.methods.stubborn import sim

    def study(spec: Path, edit: tuple = (), params: Any = None) -> dict:
        text = spec.read_text().replace("dt = 0.001", "dt = 0.002")
        for old, new in edit:
            assert old in text
            text = text.replace(old, new)
        sp = api.load_spec_text(text, str(spec))
        return sim.study(sp, params or api.design(sp).parameters, runs=16)["median_rmse"]

    ex1_dt = study(EX1, params=ex1.parameters)
    ex2_dt = study(SPECS / "astolfi-stubborn-example2.toml", params=ex1.parameters)
    for obs, row in ex1_dt.items():
        for a, by_state in row.items():
            for s, v in by_state.items():
                assert ex2_dt[obs][a][s] == pytest.approx(v, rel=1e-9), (obs, a, s)
    lu = ex1_dt["luenberger"]
    for s, slides in zip(("x1", "x2"), SLIDES_LUENBERGER_EX1["0.1"], strict=True):
        assert 0.02 < lu["0.1"][s] < 0.04 < slides
    for s, slides in zip(("x1", "x2"), SLIDES_LUENBERGER_EX1["1000"], strict=True):
        assert lu["1000"][s] < slides / 3
    gain = (
        'lambda_fraction = 0.5\ngain_bound = 100\ncriterion = "R"',
        "K = [-11.9944, 20.4153]\nlambda = 5",
    )
    fitted = study(EX1, (gain, ("outlier_rate = 0.01", "outlier_rate = 0.05")))["luenberger"]
    for s, slides in zip(("x1", "x2"), SLIDES_LUENBERGER_EX1["1000"], strict=True):
        assert fitted["1000"][s] == pytest.approx(slides, rel=0.1)
    for s, slides in zip(("x1", "x2"), SLIDES_LUENBERGER_EX1["0.1"], strict=True):
        assert fitted["0.1"][s] < slides / 3


def test_example_2_designs_example_1s_observer(ex1: Report) -> None:
    """The slides on Example 2: "Design results: of course, the same of Example 1" — the
    plants differ only in u, which the error does not see. The exact parameters are equal
    (the outlier study above took Example 1's for Example 2; papers review 46)."""
    ex2 = api.design(api.load_spec(SPECS / "astolfi-stubborn-example2.toml"))
    assert ex2.exit_code() == 0
    assert ex2.parameters.to_json() == ex1.parameters.to_json()


@pytest.mark.parametrize("bound", ["1e-12", "1e-300"])
def test_a_tiny_gain_bound_shrinks_the_gain_into_it(bound: str) -> None:
    """A stable plant with gain_bound = 10⁻¹² (or 10⁻³⁰⁰): the solver keeps ‖X‖₂ within the
    bound only to its own accuracy, every rounded point failed the gain bound, and the design
    was exit 4 although K = 0 certifies (independent fuzz, session 38). The gain is shrunk into
    the bound (or set to 0) and the exact checks decide: exit 0, ‖K‖_F ≤ bound by Fractions."""
    from fractions import Fraction as F

    text = (
        '[system]\ntime = "discrete"\nA = [[0.8, 0.5], [-0.5, 0.8]]\nC = [[1, 0.5]]\n'
        f'[method]\nkey = "stubborn"\ngain_bound = {bound}\n'
    )
    rep = api.design(api.load_spec_text(text, "gb.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    K = [F(int(k.p), int(k.q)) for k in np.asarray(rep.parameters["K"], dtype=object).ravel()]
    assert sum(k * k for k in K) <= F(bound) ** 2
    assert {c.id: c.status for c in rep.claims}["gain-bound"] == ClaimStatus.CERTIFIED


def test_the_simulated_output_has_the_D_u_term() -> None:
    """[system] D is accepted: the printed and CSV y left out D u (y = C x), while the
    observer and observer_statespace take D u off (interop trial, session 39)."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0.9, 0.2], [-0.1, 1.05]]\nC = [[1, 0]]\n'
        'B = [[1], [0.5]]\nD = [[0.2]]\nsample_time = 0.1\n[method]\nkey = "stubborn"\n'
        "[simulate]\nhorizon = 30\nx0 = [1, -1]\nxhat0 = [0, 0]\n"
        '[simulate.u]\nkind = "constant"\nvalue = [0.3]\n[simulate.noise]\nkind = "zero"\n'
    )
    res = api.simulate(api.load_spec_text(text, "d.toml"))
    np.testing.assert_allclose(res.y[:, 0], res.x[:, 0] + 0.2 * 0.3, rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    "time, a, c",
    [
        ("continuous", 0.5, 1000),
        ("discrete", 1.25, 1000),
        ("continuous", 0.1, 2000),
        # exit 4 first (the data span above 10⁵ is no verdict), not exit 1: retried too
        # (re-check trial, session 40)
        ("continuous", 0.5, 99000),
    ],
)
def test_a_gain_bound_that_only_the_normalization_breaks_is_met_scale_free(
    time: str, a: float, c: float
) -> None:
    """A = a, C = c ≈ 10³: with P ⪰ I, W ⪰ I the LMIs need P ≳ 10⁶, so ‖X‖₂ = ‖P K‖₂ ≳ 500
    above the default gain_bound 100 although K ≈ 0.01 certifies; the design said "LMIs
    infeasible for every λ tried: raise gain_bound (now 100)", exit 1 (stubborn trial,
    session 40). It now retries with ‖X‖₂ ≤ gain_bound·s, P ⪰ s·I (still ‖K‖₂ ≤ gain_bound),
    says so in a note and in gain_normalization, and verify agrees."""
    text = f'[system]\ntime = "{time}"\nA = [[{a}]]\nC = [[{c}]]\n[method]\nkey = "stubborn"\n'
    rep = api.design(api.load_spec_text(text, "s.toml"))
    assert rep.exit_code() == 0
    assert rep.parameters["gain_normalization"] == "scale-free"
    assert any("designed with ‖X‖₂ ≤ gain_bound·s and P ⪰ s·I" in n for n in rep.notes)
    K = np.asarray(to_float(rep.parameters["K"]), dtype=float)
    assert np.linalg.norm(K, 2) <= 100
    claims = {cl.id: cl.status for cl in rep.claims}
    assert claims["gain-bound"] == ClaimStatus.CERTIFIED
    assert api.verify(rep).exit_code() == 0


def test_the_scale_free_retry_keeps_the_first_verdict_when_it_fails_too() -> None:
    """A = 2.4, C = 1 in discrete time with gain_bound = 1: |2.4 − K| < 1 needs K > 1.4, so
    the bound is the cause under any normalization: the retry fails and the first message
    ("raise gain_bound") stands, exit 1."""
    text = '[system]\ntime = "discrete"\nA = [[2.4]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
    with pytest.raises(InfeasibleError, match="raise gain_bound"):
        api.design(api.load_spec_text(text + "gain_bound = 1\n", "s.toml"))


def test_the_slow_plant_search_goes_down_to_its_floor(monkeypatch: pytest.MonkeyPatch) -> None:
    """Below 10⁻⁶ the continuous λ search steps down by 10⁴ to LAMBDA_FLOOR = 10⁻²⁶, the
    floor included although 10⁻⁶ / (10⁴)⁵ is 9.99…·10⁻²⁷ in floats (the docs said 10⁻³⁰,
    which a plain < never reached: 10⁻⁶ / (10⁴)⁶ is 9.99…·10⁻³¹; stubborn trial, session
    40)."""
    from obsdesign.methods.stubborn import design as d

    tried: list[float] = []

    def never(self: Any, lam: float) -> tuple[bool, str]:
        tried.append(lam)
        return False, d.INFEASIBLE

    monkeypatch.setattr(d.Feasibility, "__call__", never)
    text = '[system]\ntime = "continuous"\nA = [[-1]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
    spec = api.load_spec_text(text, "s.toml")
    good, bad, st = d.search_lambda(d.Plant.of(spec), spec.options)
    assert good == 0.0 and st == d.INFEASIBLE
    assert min(tried) == pytest.approx(d.LAMBDA_FLOOR, rel=1e-9, abs=0)


def test_the_gain_bound_retry_ends_with_k_zero(monkeypatch: pytest.MonkeyPatch) -> None:
    """_within_gain_bound yields K scaled into ‖K‖_F ≤ gain_bound (exactly), then K = 0 with
    X = P K rebuilt; end to end, a stable plant whose scaled candidate fails too is certified
    with K = 0 (the fallback of session 38 that no test reached: note 39)."""
    from dataclasses import replace

    from obsdesign.methods.stubborn import design as d

    text = '[system]\ntime = "continuous"\nA = [[-1]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
    spec = api.load_spec_text(text + "gain_bound = 0.5\n", "s.toml")
    o = spec.options
    P = np.array([[fmpq(3)]], dtype=object)
    K = np.array([[fmpq(2)]], dtype=object)
    fits = list(d._within_gain_bound({"K": K, "P": P, "X": P @ K}, o))
    assert len(fits) == 2
    k1 = fits[0]["K"][0, 0]
    assert 0 < k1 <= fmpq(1, 2) and k1 * k1 <= Q(o.gain_bound) ** 2
    assert fits[0]["X"][0, 0] == 3 * k1
    assert fits[1]["K"][0, 0] == 0 and fits[1]["X"][0, 0] == 0
    assert list(d._within_gain_bound({"K": K, "P": P}, replace(o, gain_bound=None))) == []
    # end to end: every candidate but K = 0 fails the gain bound (the solver's K, then the
    # scaled one); the stable plant certifies with K = 0
    real = d._claims.point_failures

    def only_zero_gain(spec: Any, cand: dict[str, Any], l2: bool) -> list[str]:
        if any(k != 0 for k in cand["K"].ravel()):
            return ["gain-bound"]
        return real(spec, cand, l2)

    monkeypatch.setattr(d._claims, "point_failures", only_zero_gain)
    rep = api.design(spec)
    assert rep.exit_code() == 0
    assert all(k == 0 for k in np.asarray(rep.parameters["K"]).ravel())


def test_a_tampered_gain_normalization_fails_verify() -> None:
    """A = [[0.5, 1], [0, 0.3]], C = [[1000, 0]]: designed with the scale-free gain bound and
    a λ bracket of that problem. Removing gain_normalization, or giving another value, makes
    verify re-solve and name the other problem: the bracket claim's statement differs from
    the report's, exit 1 (the claims reading it must be seen failing; session 40)."""
    text = (
        '[system]\ntime = "continuous"\nA = [[0.5, 1], [0, 0.3]]\nC = [[1000, 0]]\n'
        '[method]\nkey = "stubborn"\n'
    )
    rep = api.design(api.load_spec_text(text, "s.toml"))
    assert rep.exit_code() == 0 and rep.parameters["gain_normalization"] == "scale-free"
    assert "lambda_bracket" in rep.parameters
    assert api.verify(rep).exit_code() == 0
    for value in (None, "foo"):
        d = rep.to_dict()
        if value is None:
            del d["parameters"]["gain_normalization"]
        else:
            d["parameters"]["gain_normalization"] = value
        ver = api.verify(Report.from_dict(json.loads(json.dumps(d)))[0])
        assert ver.exit_code() == 1
        assert any(c.id == "report-alters:lambda-max-bracket" for c in ver.failed), [
            c.id for c in ver.failed
        ]


@pytest.mark.parametrize(
    "keys",
    [("K", "X", "K_at_max"), ("P",), ("Y", "Y_at_max"), ("U",), ("lambda_bracket",)],
)
def test_report_matrices_of_another_shape_are_not_reshaped(ex4: Report, keys) -> None:
    """Example 4's 4×2 K, X (and their _at_max forms) written as 2×4 with the same entries
    row-major verified with exit 0, 13 claims certified: the check reshaped them back, while
    A − KᵀC is not Schur (shape review, session 41: a false certificate). Every matrix of a
    point is read at its exact shape; a flat or nested-deeper one fails parameters-wellformed."""
    d = ex4.to_dict()
    for k in keys:
        ex = np.asarray(d["parameters"]["exact"][k], dtype=object)
        fl = np.asarray(d["parameters"][k], dtype=float)
        if ex.ndim == 2 and ex.shape[0] == ex.shape[1]:  # a square one flat (row-major)
            new_ex, new_fl = ex.reshape(-1), fl.reshape(-1)
        elif ex.ndim == 2:  # the other shape, the same entries row-major
            new_ex, new_fl = ex.reshape(ex.shape[::-1]), fl.reshape(fl.shape[::-1])
        else:  # a vector as a column
            new_ex, new_fl = ex.reshape(-1, 1), fl.reshape(-1, 1)
        d["parameters"]["exact"][k] = new_ex.tolist()
        d["parameters"][k] = new_fl.tolist()
    rep = api.verify(Report.from_dict(d)[0])
    assert rep.exit_code() != 0
    bad = [c for c in rep.claims if c.id == "parameters-wellformed"]
    assert bad and "expected shape" in bad[0].detail, [(c.id, c.detail) for c in rep.failed]


def test_high_gain_report_matrices_are_read_at_their_shape() -> None:
    """The high-gain claims reshaped K (n×1) and P (n×n) too: a flat K or P is malformed."""
    rep = api.design(SPECS / "astolfi-stubborn-duffing.toml")
    assert rep.exit_code() == 0
    for k in ("K", "P"):
        d = rep.to_dict()
        d["parameters"]["exact"][k] = np.asarray(d["parameters"]["exact"][k]).reshape(-1).tolist()
        d["parameters"][k] = np.asarray(d["parameters"][k], dtype=float).reshape(-1).tolist()
        ver = api.verify(Report.from_dict(d)[0])
        bad = [c for c in ver.claims if c.id == "parameters-wellformed"]
        assert ver.exit_code() != 0 and bad and f"parameters.{k}: expected shape" in bad[0].detail


def test_the_best_lambda_note_at_the_search_cap_rounds_its_bound_outward() -> None:
    """Discrete A = 0, C = 1: the best λ is the search's cap; the note said "best λ ≤ 1e-06"
    for a certified λ_max = 1.0000003·10⁻⁶ (the bound printed below the value it bounds) and
    "λ = 1/1e+06" (statement audit, session 43)."""
    import re

    text = '[system]\ntime = "discrete"\nA = [[0]]\nC = [[1]]\n[method]\nkey = "stubborn"\n'
    rep = api.design(api.load_spec_text(text, "d1.toml"))
    note = next(n for n in rep.notes if n.startswith("best λ"))
    m = re.match(r"best λ ≤ ([0-9.e+-]+) ", note)
    assert m is not None, note
    assert Q(m.group(1)) >= Q(rep.parameters["lambda_max"])
    assert "cap λ = 1e-06" in note and "1/1e" not in note


def test_the_bracket_near_end_is_re_solved_too() -> None:
    """A = −1, C = 1, r_bound = 10: every point of the solver's problem (P ⪰ I, R ⪯ r_bound)
    has λ < R/P − 2 ≤ 12. The λ_max certificate scaled by 1/100 (the LMIs are homogeneous, so
    it still certifies them) with λ_max = 512 and the bracket [512, 1024] verified, exit 0,
    saying the problem's best λ lies in [512, 1024] (stubborn review, session 43): the near
    end is re-solved as the far end is."""
    from obsdesign.methods.stubborn.claims import lambda_max_claims
    from obsdesign.params import Parameters

    text = (
        '[system]\ntime = "continuous"\nA = [[-1]]\nC = [[1]]\n'
        '[method]\nkey = "stubborn"\nr_bound = 10\n'
    )
    spec = api.load_spec_text(text, "scalar.toml")
    rep = api.design(spec)
    assert rep.exit_code() == 0
    ok = {c.id: c.ok for c in lambda_max_claims(spec, rep.parameters)}
    assert ok["lambda-max-bracket"] and ok["lambda-max-certified"]
    p = Parameters(dict(rep.parameters))
    s = fmpq(1, 100)
    for k in ("P", "U", "W", "Y"):
        p[f"{k}_at_max"] = np.asarray(rep.parameters[f"{k}_at_max"], dtype=object) * s
    p["lambda_max"] = fmpq(512)
    p["lambda_bracket"] = np.array([fmpq(512), fmpq(1024)], dtype=object)
    ok = {c.id: c.ok for c in lambda_max_claims(spec, p)}
    assert ok["lambda-max-certified"]  # the LMIs do hold at 512 with the scaled point
    assert not ok["lambda-max-bracket"]


def test_scale_free_gain_holds_between_its_two_candidates_and_not_past_them() -> None:
    """The scale-free gain constraint ‖X‖₂ ≤ g·s with P ⪰ s·I (some s > 0), proved exactly:
    ‖X‖₂ = 1.9·g with λ_min(P) = 2 holds; ‖X‖₂ = 2·g·(1 + 2⁻⁴⁰) does not (the smallest
    false margin: no s has both), nor does a bound g ≤ 0."""
    from obsdesign.methods.stubborn.claims import _scale_free_gain_holds

    P = np.diag([fmpq(2), fmpq(3)]).astype(object)
    g = fmpq(1, 3)
    assert _scale_free_gain_holds(P, np.array([[g * fmpq(19, 10)], [0]], dtype=object), g)
    over = g * 2 * (1 + fmpq(1, 2**40))
    assert not _scale_free_gain_holds(P, np.array([[over], [0]], dtype=object), g)
    assert not _scale_free_gain_holds(P, np.array([[fmpq(0)], [0]], dtype=object), fmpq(0))


def _near_end_proved_exactly(text: str) -> Report:
    """The design of ``text``, asserted exit 0 with its lambda-max-bracket's near end proved
    by the λ_max certificate itself (not a re-solve)."""
    rep = api.design(api.load_spec_text(text, "near.toml"))
    (claim,) = [c for c in rep.claims if c.id == "lambda-max-bracket"]
    assert claim.ok and "certificate lies in the problem (exact)" in claim.detail, claim.detail
    assert rep.exit_code() == 0
    return rep


def test_a_scale_free_near_end_is_proved_by_its_own_certificate() -> None:
    """The exact near-end check skipped the scale-free gain normalization (P ⪰ s·I, ‖X‖₂ ≤
    gain_bound·s), so such designs fell back on the cold re-solve, which answered
    "optimal_inaccurate" for this plant: exit 1 on its own lambda-max-bracket (re-check
    review, session 44)."""
    text = (
        '[system]\ntime = "continuous"\n'
        "A = [[-0.486, -0.123, 0.652], [-1.336, -0.418, -0.927], [-0.359, -1.11, -0.397]]\n"
        "C = [[1.87, -1.9, 1.49], [0.28, 1.26, -0.99]]\n"
        '[method]\nkey = "stubborn"\ncriterion = "K"\ngain_bound = 0.5\nr_bound = 0.5\n'
    )
    _near_end_proved_exactly(text)


def test_an_honest_near_end_is_proved_by_its_own_certificate() -> None:
    """Since the near end was re-solved, a cold Clarabel solve at the rounded λ_max answered
    "optimal_inaccurate" for this random discrete plant and the design failed its own
    lambda-max-bracket claim, exit 1 — though the λ_max certificate lies strictly inside the
    solver's problem (re-check review, session 43). That point is checked exactly first."""
    text = (
        '[system]\ntime = "discrete"\n'
        "A = [[0.291, 0.3233, -0.3233], [-1.6328, 0.3395, 0.2102], [-1.1397, 0.6224, -0.5658]]\n"
        "C = [[0.1, -0.18, 0.2], [-1.61, 1.81, -0.6]]\n"
        '[method]\nkey = "stubborn"\ncriterion = "K"\n'
    )
    rep = _near_end_proved_exactly(text)
    # the exact check refuses a point outside the problem: the same certificate scaled by
    # 1/100 still meets the homogeneous LMIs, not P ⪰ I, w ≥ 1 or the margin
    from obsdesign.certify.claim import Claims
    from obsdesign.methods.stubborn.claims import _in_problem, _read_point

    spec = api.load_spec_text(text, "d.toml")
    pt = _read_point(rep.parameters, Claims(), spec, "_at_max")
    lm = Q(rep.parameters["lambda_max"])
    assert pt is not None and _in_problem(spec, spec.options, pt, lm)
    small = {k: (v if k == "K" else v * fmpq(1, 100)) for k, v in pt.items()}
    assert not _in_problem(spec, spec.options, small, lm)


def test_an_inaccurate_re_solve_at_the_far_end_is_inconclusive_not_failed(
    ex1: Report, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A cold re-solve at the bracket's far end answering "infeasible_inaccurate" failed
    lambda-max-bracket and verify was exit 1, "NOT verified", for a true statement (tamper
    review, session 44): inconclusive now, exit 4, the claim and the differences it makes in
    the comparison float-ok; an answer of "optimal" there is still a refutation, exit 1."""
    from obsdesign.methods.stubborn import design as sd

    assert api.verify(ex1).exit_code() == 0
    real = sd.Feasibility.__call__
    far = float(ex1.parameters["lambda_bracket"][-1])

    def answer(status: str):
        def call(self, lam):
            return (False, status) if lam == far else real(self, lam)

        return call

    monkeypatch.setattr(sd.Feasibility, "__call__", answer("infeasible_inaccurate"))
    ver = api.verify(ex1)
    assert ver.exit_code() == 4, [(c.id, c.detail) for c in ver.failed]
    assert {c.id for c in ver.failed} >= {"lambda-max-bracket", "report-verdict"}
    for refuting in ("optimal", "optimal_inaccurate", "solver_error"):
        monkeypatch.setattr(sd.Feasibility, "__call__", answer(refuting))
        assert api.verify(ex1).exit_code() == 1, refuting
    # the claim relabelled "certified" (it is a solver check, numerical when it passes):
    # exit 1 whatever the far end's re-solve answers — with an inaccurate answer there it was
    # exit 4 (re-check review 45: a far end moved by 10⁻¹² draws that answer)
    d = ex1.to_dict()
    for c in d["claims"]:
        if c["id"] == "lambda-max-bracket":
            assert c["status"] == "numerical"
            c["status"] = "certified"
    relabelled, _ = Report.from_dict(d)
    monkeypatch.setattr(sd.Feasibility, "__call__", answer("infeasible_inaccurate"))
    ver = api.verify(relabelled)
    assert ver.exit_code() == 1, [(c.id, c.float_ok) for c in ver.failed]
    alters = next(c for c in ver.failed if c.id == "report-alters:lambda-max-bracket")
    assert not alters.float_ok


def test_no_lambda_found_names_the_bounds_in_force() -> None:
    """A 3-state plant with r_bound = 12.9: the solver found the LMIs feasible at no λ and
    answered infeasible_inaccurate; exit 4 suggested a smaller margin or a rescaled plant,
    while r_bound = 1000 certifies (census review 45; also gain_bound at its default 100).
    The message names the bounds in force beside the margin."""
    from obsdesign.errors import InconclusiveError

    text = (
        '[system]\ntime = "continuous"\n'
        "A = [[-0.105, 0.201, 0.11], [0.101, 0.177, -0.091], [0.146, 0.466, 0.135]]\n"
        "C = [[1.188, -0.866, -0.449]]\n"
        '[method]\nkey = "stubborn"\nr_bound = 12.9\ncriterion = "R"\n'
    )
    with pytest.raises(InconclusiveError, match="feasible at no λ tried") as ei:
        api.design(api.load_spec_text(text, "s021.toml"))
    assert "a larger r_bound (now 12.9)" in str(ei.value), str(ei.value)
    ok = api.design(api.load_spec_text(text.replace("12.9", "1000"), "s021.toml"))
    assert ok.exit_code() == 0
