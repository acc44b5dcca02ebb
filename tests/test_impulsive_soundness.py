"""Soundness of the impulsive certificate (issue 15): every claim fails when its quantity is
false by the smallest margin, statements print true numbers, and the spec binds the checks.

Each tamper changes report parameters consistently (exact value and its nearest double, as
``Parameters.to_json`` writes them) and asserts the exact set of failed claim ids of the
method (``api.certify``), then that ``obsdesign verify`` of the forged report exits 1.
Thresholds are exact closed forms for example (30)-(31) of the paper (Schaum, Feketa,
Meurer, Moreno, MTNS 2020) with M = [−3, 1]: Ā = [[0, 0], [0, −1]], so with the sector
±k of ψ̃_o, N(−ϖ) ⪯ 0 ⇔ ϖ ≥ θ_o k² + 1/θ_o, and with ψ̃_n = 0, N(κ) ⪯ 0 ⇔ κ ≤ 2 − 1/θ_n.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mpmath
import numpy as np
import pytest
from flint import fmpq
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.certify.claim import Claims
from obsdesign.certify.exact import Q, qmat
from obsdesign.cli import app
from obsdesign.errors import InputError, SpecError
from obsdesign.methods import get_method
from obsdesign.methods.impulsive.claims import _ball
from obsdesign.methods.impulsive.core import BlockData
from obsdesign.methods.impulsive.dissipativity import QSR
from obsdesign.params import Parameters
from obsdesign.report.model import Report
from obsdesign.spec.models import Spec

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "specs" / "schaum-impulsive-example.toml"
SPEC3 = ROOT / "specs" / "impulsive-sector-3state.toml"
K = Q("1.9822152")  # the sector ±k of ψ̃_o in the shipped example
TINY = fmpq(1, 2**100)
runner = CliRunner()

#: impulsive with ``lipschitz_x`` data (also tests/test_claims_entrywise.py)
LIPSCHITZ = (ROOT / "tests" / "specs" / "impulsive-lipschitz-x.toml").read_text(encoding="utf-8")


def example_text(**method: str) -> str:
    """The shipped example with ``[method]`` keys replaced or added."""
    lines = EXAMPLE.read_text(encoding="utf-8").splitlines()
    for k, v in method.items():
        lines = [ln for ln in lines if not ln.startswith(f"{k} = ")]
        i = lines.index('key = "impulsive"')
        lines.insert(i + 1, f"{k} = {v}")
    return "\n".join(lines) + "\n"


_CACHE: dict[str, tuple[Spec, Report]] = {}


def designed(name: str) -> tuple[Spec, Report]:
    """(spec, report) of a named variant, designed once per session."""
    if name not in _CACHE:
        text = {
            "example": EXAMPLE.read_text(encoding="utf-8"),
            "kappa": example_text(kappa="0.4923"),
            "as-given": example_text(qsr_scaling='"as-given"'),
            "lipschitz": LIPSCHITZ,
            "3state": SPEC3.read_text(encoding="utf-8"),
            "stable-o": SPEC3.read_text(encoding="utf-8").replace(
                "A = [[0, 0.01, 0]", "A = [[-5, 0.01, 0]"
            ),
            "square": example_text(noise_bound="0.12"),
            "cross": SPEC3.read_text(encoding="utf-8")
            .replace("sector = [-0.2, 0.2]", "sector = [-0.2, 0.2]\ncross = 0.05")
            .replace("sector = [0, 0.3]", "sector = [0, 0.3]\ncross = 0.05"),
        }[name]
        spec = api.load_spec_text(text, f"{name}.toml")
        rep = api.design(spec)
        assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
        _CACHE[name] = (spec, rep)
    return _CACHE[name]


def _with(params: Parameters, changes: dict[str, Any]) -> Parameters:
    """A copy of ``params`` with ``changes`` (exact values), round-tripped through the JSON
    form so that every float is the nearest double of its exact value."""
    new = Parameters(dict(params.items()))
    for k, v in changes.items():
        new[k] = v
    back, problems = Parameters.from_json(json.loads(json.dumps(new.to_json())))
    assert not problems
    return back


def failed_ids(spec: Spec, params: Parameters) -> set[str]:
    return {c.id for c in api.certify(spec, params) if not c.ok}


def forged_verify_exit(tmp_path: Path, rep: Report, params: Parameters, spec: Spec) -> int:
    """Exit code of ``obsdesign verify`` on a forged report: the tampered parameters with the
    claims recomputed for them but every status written as certified (what a forger writes)."""
    d = json.loads(rep.to_json())
    d["parameters"] = json.loads(json.dumps(params.to_json()))
    claims = []
    for c in api.certify(spec, params):
        cd = c.to_dict()
        cd["status"] = "certified"
        claims.append(cd)
    d["claims"] = claims
    path = tmp_path / "forged.json"
    path.write_text(json.dumps(d), encoding="utf-8")
    res = runner.invoke(app, ["verify", str(path)])
    return res.exit_code


def _mat(params: Parameters, key: str, i: int, j: int, delta: fmpq) -> np.ndarray:
    X = np.array(params[key], dtype=object, copy=True)
    X[i, j] = X[i, j] + delta
    return X


def _varpi_star(p: Parameters) -> fmpq:
    th = Q(p["theta_o"])
    return th * K * K + 1 / th


def _kappa_star(p: Parameters) -> fmpq:
    return 2 - 1 / Q(p["theta_n"])


def _tmax_true(p: Parameters) -> Any:
    with mpmath.workdps(100):
        g = mpmath.mpf(1) - mpmath.mpf(4) / 5
        den = sum(
            mpmath.mpf(int(Q(p[k]).p)) / int(Q(p[k]).q) for k in ("varpi_o", "kappa", "lambda_no")
        ) + 25 * mpmath.mpf(int(Q(p["lambda_on"]).p)) / int(Q(p["lambda_on"]).q)
        return -mpmath.log(g * g) / den


def _tmin_true(p: Parameters) -> Any:
    with mpmath.workdps(100):
        k = mpmath.mpf(int(Q(p["kappa"]).p)) / int(Q(p["kappa"]).q)
        return -mpmath.log((3 - mpmath.mpf(4) / 5) / 3) / k


def _above(x: Any) -> fmpq:
    """A rational strictly above the irrational ``x`` by at most 1e-60 (far below the width
    of the 113-bit enclosures, so any widening of a check by more than that is caught)."""
    with mpmath.workdps(100):
        return fmpq(int(mpmath.ceil(x * mpmath.mpf(10) ** 60)), 10**60)


def _below(x: Any) -> fmpq:
    """A rational strictly below the irrational ``x`` by at most 1e-60."""
    with mpmath.workdps(100):
        return fmpq(int(mpmath.floor(x * mpmath.mpf(10) ** 60)), 10**60)


def _sqrt(x: Any) -> Any:
    with mpmath.workdps(100):
        return mpmath.sqrt(mpmath.mpf(x))


Tamper = Callable[[Parameters], dict[str, Any]]

# (variant, name, tamper, exact set of failed claim ids)
TAMPERS: list[tuple[str, str, Tamper, set[str]]] = [
    ("example", "T", lambda p: {"T": _mat(p, "T", 1, 0, TINY)}, {"T"}),
    ("example", "T (C row)", lambda p: {"T": _mat(p, "T", 0, 1, TINY)}, {"T"}),
    ("lipschitz", "T (C row, M free)", lambda p: {"T": _mat(p, "T", 0, 0, TINY)}, {"T"}),
    ("example", "Abar", lambda p: {"Abar": _mat(p, "Abar", 1, 1, TINY)}, {"Abar"}),
    (
        "example",
        "varpi_o below ϖ* = θk² + 1/θ",
        lambda p: {"varpi_o": _varpi_star(p) - TINY},
        {"varpi_o"},
    ),
    (
        "example",
        "kappa_n above κ* = 2 − 1/θ_n",
        lambda p: {"kappa_n": _kappa_star(p) + TINY},
        {"kappa_n"},
    ),
    ("example", "lambda_no < ‖Ā_no‖ + ℓ_no = 0", lambda p: {"lambda_no": -TINY}, {"lambda_no"}),
    ("example", "lambda_on < ‖Ā_on‖ + ℓ_on = 0", lambda p: {"lambda_on": -TINY}, {"lambda_on"}),
    (
        "cross",
        "lambda_no < ‖Ā_no‖ + ℓ_no = 1 + 0.05",
        lambda p: {"lambda_no": 1 + Q("0.05") - TINY},
        {"lambda_no"},
    ),
    (
        "cross",
        "lambda_on < ‖Ā_on‖ + ℓ_on = 0.01 + 0.05",
        lambda p: {"lambda_on": Q("0.06") - TINY},
        {"lambda_on"},
    ),
    (
        "cross",
        "ell_no (cross given)",
        lambda p: {"ell_no": Q("0.05") - TINY},
        {"ell_no-matches-spec"},
    ),
    (
        "stable-o",
        "varpi_o < 0 where the LMI would allow it (Assumption 2 fails, ϖ_o = 0 is used)",
        lambda p: {"varpi_o": -TINY},
        {"varpi_o"},
    ),
    ("example", "gamma", lambda p: {"gamma": fmpq(4, 5) + TINY}, {"gamma-beta"}),
    ("example", "beta", lambda p: {"beta": 25 - TINY}, {"gamma-beta"}),
    (
        "example",
        "kappa_n = λ*_no (Lemma 1 and (22) fail together)",
        lambda p: {"kappa_n": fmpq(0)},
        {"lemma1-iss", "condition-22"},
    ),
    (
        "example",
        "kappa_n = λ*_no + βλ*_on + κ",
        lambda p: {"kappa_n": Q(p["kappa"])},
        {"condition-22"},
    ),
    (
        "example",
        "kappa = 0 ((22) needs κ > 0, (26c) is undefined)",
        lambda p: {"kappa": fmpq(0)},
        {"condition-22", "T_min"},
    ),
    ("example", "T_max above (26b)", lambda p: {"T_max": _above(_tmax_true(p))}, {"T_max"}),
    ("example", "T_min below (26c)", lambda p: {"T_min": _below(_tmin_true(p))}, {"T_min"}),
    ("example", "T_min = T_max", lambda p: {"T_min": Q(p["T_max"])}, {"window"}),
    (
        "example",
        "ball_radius² < α w̄",
        lambda p: {"ball_radius": _below(_sqrt("0.3"))},
        {"ball_radius"},
    ),
    (
        "example",
        "ball_radius negative (r_B² ≥ α w̄ but r_B < 0)",
        lambda p: {"ball_radius": -_above(_sqrt("0.3"))},
        {"ball_radius"},
    ),
    (
        "square",
        "ball_radius² = α w̄ − 2⁻¹⁰⁰·…",
        lambda p: {"ball_radius": fmpq(3, 5) - TINY},
        {"ball_radius"},
    ),
    (
        "example",
        "denominator of (26b) = 0 (ValueError must fail T_max)",
        lambda p: {"varpi_o": -Q(p["kappa"])},
        {"varpi_o", "T_max"},
    ),
    ("example", "alpha", lambda p: {"alpha": 3 + TINY}, {"alpha-matches-spec"}),
    ("example", "w_bar", lambda p: {"w_bar": fmpq(1, 10) + TINY}, {"w_bar-matches-spec"}),
    ("example", "ell_no", lambda p: {"ell_no": TINY}, {"ell_no-matches-spec"}),
    ("example", "ell_on", lambda p: {"ell_on": TINY}, {"ell_on-matches-spec"}),
    ("kappa", "kappa given", lambda p: {"kappa": Q("0.4923") + TINY}, {"kappa-matches-spec"}),
    ("as-given", "theta_o", lambda p: {"theta_o": 1 + TINY}, {"theta_o-matches-spec"}),
    ("as-given", "theta_n", lambda p: {"theta_n": 1 + TINY}, {"theta_n-matches-spec"}),
    (
        "lipschitz",
        "norm_C below ‖C‖ = 1 (ℓ_on changed consistently)",
        lambda p: {
            "norm_C": 1 - TINY,
            "ell_on": (1 - TINY) * Q("0.005") * Q(p["norm_Pn"]),
        },
        {"lipschitz-x-blocks"},
    ),
]


@pytest.mark.parametrize(
    ("variant", "name", "tamper", "expected"), TAMPERS, ids=[t[1] for t in TAMPERS]
)
def test_tamper_fails_exactly_that_claim(
    tmp_path: Path, variant: str, name: str, tamper: Tamper, expected: set[str]
) -> None:
    spec, rep = designed(variant)
    assert failed_ids(spec, rep.parameters) == set()
    params = _with(rep.parameters, tamper(rep.parameters))
    assert failed_ids(spec, params) == expected
    assert forged_verify_exit(tmp_path, rep, params, spec) == 1


def test_thresholds_are_tight() -> None:
    """The closed-form thresholds used above are the certified values' neighbours: the design
    sits on the safe side of each, within 1e-6 (so the tampers are the smallest false ones)."""
    _, rep = designed("example")
    p = rep.parameters
    assert _varpi_star(p) <= Q(p["varpi_o"]) <= _varpi_star(p) + fmpq(1, 10**6)
    assert _kappa_star(p) - fmpq(1, 10**6) <= Q(p["kappa_n"]) <= _kappa_star(p)
    spec, _ = designed("example")
    # ... and the thresholds themselves still certify (exact boundary of the LMI)
    at = _with(p, {"varpi_o": _varpi_star(p), "kappa_n": _kappa_star(p)})
    assert failed_ids(spec, at) == set()


def test_ball_radius_on_the_boundary_certifies() -> None:
    """α w̄ = 3 · 0.12 = 0.36 = 0.6²: r_B = 0.6 exactly is a true bound (≥, not >)."""
    spec, rep = designed("square")
    assert failed_ids(spec, _with(rep.parameters, {"ball_radius": fmpq(3, 5)})) == set()


def test_every_claim_id_has_a_tamper() -> None:
    covered = set().union(*(t[3] for t in TAMPERS)) | {
        "Q_o-negative-definite",
        "Q_n-negative-semidefinite",
        "assumption1-falsification",
    }
    seen: set[str] = set()
    for v in ("example", "kappa", "lipschitz", "3state", "stable-o"):
        seen |= {c.id for c in designed(v)[1].claims}
    assert seen <= covered, seen - covered


def test_claim_ids_of_the_example() -> None:
    """Known answer: the claim list of the shipped example, in order (a deleted claim fails)."""
    _, rep = designed("example")
    assert [c.id for c in rep.claims] == [
        "T",
        "Abar",
        "Q_o-negative-definite",
        "Q_n-negative-semidefinite",
        "varpi_o",
        "kappa_n",
        "lambda_no",
        "lambda_on",
        "gamma-beta",
        "lemma1-iss",
        "condition-22",
        "T_max",
        "T_min",
        "window",
        "ball_radius",
        "assumption1-falsification",
    ]
    assert [c.status.value for c in rep.claims] == ["certified"] * 14 + ["numerical"] * 2


def test_a_warned_violation_of_assumption_1_is_a_claim_verify_recomputes() -> None:
    """on_violation = "warn" with Assumption 1 violated (the shipped example): the violation
    was only a note, and a report whose note was deleted verified with nothing saying the
    window holds only given the declared data (rendering trial, session 27). It is a numerical
    claim now, whose statement says so; a report that drops it, or rewrites it to "holds",
    fails verify."""
    from obsdesign.report.model import Report

    _, rep = designed("example")
    c = next(c for c in rep.claims if c.id == "assumption1-falsification")
    assert "violated" in c.statement and c.status.value == "numerical"
    assert api.verify(Report.from_dict(rep.to_dict())[0]).exit_code() == 0
    d = rep.to_dict()
    d["claims"] = [x for x in d["claims"] if x["id"] != "assumption1-falsification"]
    d["notes"] = []
    ver = api.verify(Report.from_dict(d)[0])
    assert ver.exit_code() == 1
    assert any(x.id == "report-omits:assumption1-falsification" for x in ver.claims)
    d = rep.to_dict()
    for x in d["claims"]:
        if x["id"] == "assumption1-falsification":
            x["statement"] = (
                "Assumption 1 (split reading) holds at every sampled pair of the region"
            )
    assert api.verify(Report.from_dict(d)[0]).exit_code() == 1


def test_ball_invariance_is_never_certified_and_fails_when_a_jump_leaves_B() -> None:
    """B = {‖ε‖ ≤ r_B} rests on the paper's jump bound (24b), which (13b) does not give, so the
    claim is numerical at best. r_B < w̄: from ε = r_B e_i a jump with w = w̄ e_i gives
    ‖ε⁺‖ = (1 − L_i) r_B + L_i w̄ > r_B, so B is not invariant and the claim fails — at the
    smallest false margin (r_B = w̄ − 10⁻³⁰ with α w̄ ≤ r_B²); r_B = w̄ is numerical. The
    random-spec fuzzer's case (α = 1.5, w̄ = 2, L = 0.99: the error peaks at 1.99 > r_B = 1.73)
    fails through the design, and verify agrees."""
    w = fmpq(2)
    for rad, alpha, status in (
        (w, fmpq(2), "numerical"),
        (w - TINY, (w - TINY) ** 2 / w, "failed"),
        (w - TINY, fmpq(3, 2), "failed"),
        (w + TINY, fmpq(2), "numerical"),
    ):
        c = Claims()
        _ball(c, rad, alpha, w)
        assert [(x.id, x.status.value) for x in c] == [("ball_radius", status)], (rad, alpha)
    c = Claims()
    _ball(c, w - TINY, fmpq(2), w)  # r_B² < α w̄: the arithmetic fails first, exactly
    assert [x.status.value for x in c] == ["failed"] and "r_B² ≥ α w̄" in list(c)[0].check
    text = (
        '[system]\ntime = "continuous"\nA = [[-1, 0], [0, -2]]\nC = [[1, 0]]\n'
        'states = ["x1", "x2"]\npsi = ["0", "0"]\n[nonlinearity.o]\nlipschitz = 0\n'
        '[nonlinearity.n]\nlipschitz = 0\n[method]\nkey = "impulsive"\nL = [0.99]\n'
        'alpha = 1.5\nnoise_bound = 2\nM = [[0, 1]]\nkappa = "widest"\n'
    )
    rep = api.design(load_spec_text(text, "ball.toml"))
    assert [c.id for c in rep.claims if c.status.value == "failed"] == ["ball_radius"]
    assert rep.exit_code() == 1 and api.verify(rep).exit_code() == 1


def _with_data(spec: Spec, **kw: Any) -> Spec:
    """A copy of a bound spec whose Assumption 1 data are replaced (bypassing the loader's own
    checks, to test the certificate's)."""
    import copy

    sp = copy.copy(spec)
    sp.options = copy.deepcopy(spec.options)
    d: BlockData = sp.options.problem.data
    for k, v in kw.items():
        setattr(d, k, v)
    return sp


def test_singular_Q_o_fails_only_its_claim() -> None:
    """Q_o = 0 (⪯ 0 but not ≺ 0) with S_o = −1/θ_o, R_o = 0: N(−ϖ_o) = diag(−ϖ_o, 0) ⪯ 0 still
    holds, so exactly Q_o-negative-definite fails (check_psd in place of check_pd would pass)."""
    spec, rep = designed("example")
    th = Q(rep.parameters["theta_o"])
    q = QSR(qmat([[0]]), qmat([[-1 / th]]), qmat([[0]]), "test")
    assert failed_ids(_with_data(spec, qsr_o=q), rep.parameters) == {"Q_o-negative-definite"}


def test_positive_Q_n_fails_its_claim() -> None:
    """Q_n = 2⁻¹⁰⁰ > 0: Q_n ⪯ 0 fails; N(κ_n) has θ_n Q_n in its corner, so kappa_n fails with
    it (Q_n ⪯ 0 is implied by N(κ_n) ⪯ 0: no tamper can fail it alone)."""
    spec, rep = designed("example")
    q = QSR(qmat([[TINY]]), qmat([[0]]), qmat([[0]]), "test")
    got = failed_ids(_with_data(spec, qsr_n=q), rep.parameters)
    assert got == {"Q_n-negative-semidefinite", "kappa_n"}


def test_negative_theta_is_not_a_scaling() -> None:
    """A QSR triple may be scaled by θ > 0 only. With Q_n = 0, S_n = 2²⁰, R_n = 2²², the
    scaling θ_n = −2⁻²⁰ makes I + θS_n = 0 and θR_n = −4, so N(κ) ⪯ 0 would "hold" for κ = 3:
    the claim must fail on θ_n ≤ 0 alone (the LMI does not catch it here)."""
    spec, rep = designed("example")
    q = QSR(qmat([[0]]), qmat([[2**20]]), qmat([[2**22]]), "test")
    params = _with(rep.parameters, {"theta_n": -fmpq(1, 2**20), "kappa_n": fmpq(3)})
    assert failed_ids(_with_data(spec, qsr_n=q), params) == {"kappa_n"}
    params = _with(rep.parameters, {"theta_n": fmpq(0)})
    assert failed_ids(spec, params) == {"kappa_n"}


def test_float_only_parameter_is_not_certified() -> None:
    spec, rep = designed("example")
    p = Parameters(dict(rep.parameters.items()))
    p["varpi_o"] = float(p.float("varpi_o"))
    ids = [c.id for c in api.certify(spec, p) if not c.ok]
    assert ids == ["varpi_o-exact"]


# -- statements print true numbers ---------------------------------------------------------
NUM = r"(-?[0-9.]+(?:e-?[0-9]+)?|-?[0-9]+/[0-9]+)"


def _num(stmt: str, pattern: str) -> fmpq:
    m = re.search(pattern.replace("NUM", NUM), stmt)
    assert m, (pattern, stmt)
    return Q(m.group(1))


def _check_statements(rep: Report) -> None:
    p = {k: Q(v) for k, v in rep.parameters.items() if isinstance(v, fmpq)}
    st = {c.id: c.statement for c in rep.claims}
    assert _num(st["varpi_o"], r"ϖ_o ≤ NUM") >= p["varpi_o"]
    assert _num(st["kappa_n"], r"κ_n ≥ NUM") <= p["kappa_n"]
    assert _num(st["lambda_no"], r"ℓ_no ≤ NUM") >= p["lambda_no"]
    assert _num(st["lambda_on"], r"ℓ_on ≤ NUM") >= p["lambda_on"]
    g, b = p["gamma"], p["beta"]
    assert _num(st["gamma-beta"], r"λ_max\(I − L\) = NUM") == 1 - g
    assert _num(st["gamma-beta"], r"β = 1/\(1 − γ\)² = NUM") == b
    assert _num(st["lemma1-iss"], r"κ_n − λ\*_no ≥ NUM") <= p["kappa_n"] - p["lambda_no"]
    assert _num(st["condition-22"], r"κ ≥ NUM") <= p["kappa"]
    slack = p["kappa_n"] - p["lambda_no"] - b * p["lambda_on"] - p["kappa"]
    assert _num(st["condition-22"], r"− κ ≥ NUM") <= slack
    assert _num(st["T_max"], r"T_max = NUM") == p["T_max"]
    assert _num(st["T_min"], r"T_min = NUM") == p["T_min"]
    assert _num(st["T_min"], r"α = NUM") == p["alpha"]
    assert _num(st["window"], r"\(NUM <") == p["T_min"]
    assert _num(st["ball_radius"], r"r_B ≤ NUM") >= p["ball_radius"]
    if "lipschitz-x-blocks" in st:
        for sym, k in (("C", "norm_C"), ("M", "norm_M"), ("P_o", "norm_Po"), ("P_n", "norm_Pn")):
            assert _num(st["lipschitz-x-blocks"], rf"‖{sym}‖ ≤ NUM") >= p[k]


@pytest.mark.parametrize(
    "variant", ["example", "kappa", "lipschitz", "3state", "cross", "stable-o"]
)
def test_printed_numbers_are_true(variant: str) -> None:
    _check_statements(designed(variant)[1])


def test_issue15_reproduction_lambda_no_printed_up() -> None:
    """A[1][0] = 1.0000004, T = I: ‖Ā_no‖ = 1.0000004 exactly; the statement must not print
    "≤ 1" (it printed f"{x:.6g}" before)."""
    txt = (
        EXAMPLE.read_text(encoding="utf-8")
        .replace("A = [[0, 0], [3, -1]]", "A = [[0, 0], [1.0000004, -1]]")
        .replace("M = [[-3, 1]]", "M = [[0, 1]]")
    )
    rep = api.design(api.load_spec_text(txt, "repro.toml"))
    assert rep.exit_code() == 0
    _check_statements(rep)
    st = {c.id: c.statement for c in rep.claims}
    assert _num(st["lambda_no"], r"ℓ_no ≤ NUM") >= Q("1.0000004")
    assert not st["lambda_no"].endswith("≤ 1")


# -- falsification: NaN and inf are violations (issue 11 item 2) ---------------------------
@pytest.mark.parametrize("psi", ['["0*9**9**9", "0"]', '["x1**1e308", "0"]'])
def test_falsification_nan_inf_is_a_violation(psi: str) -> None:
    txt = (
        EXAMPLE.read_text(encoding="utf-8")
        .replace('psi = ["x1*x2*(x2^2 - a^2)/(1 + x2^4)", "0"]', f"psi = {psi}")
        .replace('on_violation = "warn"', 'on_violation = "fail"')
        .replace("samples = 20000", "samples = 200")
    )
    rep = api.design(api.load_spec_text(txt, "nan.toml"))
    assert rep.exit_code() == 1
    bad = [c for c in rep.claims if not c.ok]
    assert [c.id for c in bad] == ["assumption1-falsification"]
    assert "ψ finite on the region" in bad[0].detail and "at x = (" in bad[0].detail


def test_falsification_lipschitz_x_nan() -> None:
    txt = LIPSCHITZ.replace('psi = ["0.005*sin(x2)", "0"]', 'psi = ["0*9**9**9", "0"]')
    rep = api.design(api.load_spec_text(txt, "nan.toml"))
    assert [c.id for c in rep.claims if not c.ok] == ["assumption1-falsification"]


def test_falsification_passes_on_the_3state_spec() -> None:
    _, rep = designed("3state")
    c = next(c for c in rep.claims if c.id == "assumption1-falsification")
    assert c.status.value == "numerical" and "no violation" in c.detail


@pytest.mark.parametrize(("scale", "sector", "code"), [("1e200", "0.2", 0), ("1e200", "0.19", 1)])
def test_falsification_reads_a_huge_box_without_overflow(scale: str, sector: str, code: int):
    """The 3-state spec with x1 ∈ ±10²⁰⁰: ε ≈ 2·10¹⁹⁷ squared to inf, inf − inf gave NaN and a
    true Assumption 1 (ψ_1 = 0.2 sin x1 in the sector ±0.2) was "violated", exit 1 — and a
    false numerical "violated" claim verified with on_violation = "warn" (non-finite
    expressions trial, session 35). (15) is read on φ, ε scaled row-wise; ψ_1 = 0.2·x1 with
    a sector ±0.19 is still found violated there, with a finite worst value."""
    txt = (
        SPEC3.read_text(encoding="utf-8")
        .replace("lower = [-4, -4, -4]", f"lower = [-{scale}, -4, -4]")
        .replace("upper = [4, 4, 4]", f"upper = [{scale}, 4, 4]")
        .replace("samples = 20000", "samples = 2000")
    )
    assert scale in txt
    if sector != "0.2":  # ψ_1 = 0.2·x1 violates the sector ±0.19 at every scale
        txt = txt.replace("[-0.2, 0.2]", f"[-{sector}, {sector}]").replace("0.2*sin(x1)", "0.2*x1")
        assert f"-{sector}" in txt and "0.2*x1" in txt
    rep = api.design(api.load_spec_text(txt, "bigbox.toml"))
    c = next(c for c in rep.claims if c.id == "assumption1-falsification")
    assert rep.exit_code() == code, c.detail
    assert "nan" not in c.detail
    if code:
        assert "(15) own part, i = o" in c.detail


@pytest.mark.parametrize(
    ("sector", "error", "text"),
    [
        ("1e160", "InfeasibleError", "κ_n = -2.00000000187e160 ≤ λ*_no"),
        ("1e200", "InfeasibleError", "κ_n = -2.00000000187e200 ≤ λ*_no"),
        ("1e300", "InconclusiveError", "the float search of κ_n gave"),
    ],
)
def test_a_huge_sector_is_reported_for_what_it_is(sector: str, error: str, text: str) -> None:
    """Sector [0, s] of block n: κ_n = max_θ −λ_max(Ā_n + Ā_nᵀ + (1 + θs)²/θ) = 6 − 4s. With
    s = 10¹⁶⁰ the whole first θ grid overflowed, its NaN was taken as the minimum and the
    design said "I + S_n ∉ range Q_n" (false: Q_n = −I); with 10²⁰⁰ it printed κ_n =
    −5.8·10³⁰⁷ (non-finite expressions trial, session 35). Now the search steps past the
    overflow: κ_n = −2s exactly as printed; where no θ within e^±600 avoids it (10³⁰⁰), the
    design is inconclusive, exit 4, saying so."""
    from obsdesign.errors import InconclusiveError, InfeasibleError

    txt = SPEC3.read_text(encoding="utf-8").replace("sector = [0, 0.3]", f"sector = [0, {sector}]")
    assert sector in txt
    sp = api.load_spec_text(txt, "huge.toml")
    errors = {"InfeasibleError": InfeasibleError, "InconclusiveError": InconclusiveError}
    with pytest.raises(errors[error]) as ei:
        api.design(sp)
    assert text in str(ei.value) and "range Q_n" not in str(ei.value)


def test_row_norms_do_not_overflow() -> None:
    from obsdesign.methods.impulsive.falsify import _rows, _scaled

    a = np.array([[3e200, 4e200], [0.0, 0.0], [np.inf, 1.0], [3e-200, 4e-200]])
    got = _rows(a)
    assert got[0] == pytest.approx(5e200) and got[1] == 0 and got[2] == np.inf
    assert got[3] == pytest.approx(5e-200)
    ph, e, sc = _scaled(a[:, :1], a[:, 1:])
    assert sc.tolist() == [4e200, 1.0, 1.0, 4e-200] and ph[0, 0] == 0.75 and e[0, 0] == 1.0


# -- shipped numbers (issue 8: no printed number changes) ----------------------------------
def test_shipped_numbers() -> None:
    p = designed("example")[1].parameters
    assert (p["T_min"], p["T_max"]) == (Q("0.1551"), Q("0.5396"))
    assert p["gamma"] == fmpq(4, 5) and p["beta"] == 25 and p["kappa_n"] <= 2
    assert abs(p.float("varpi_o") - 2 * 1.98221516) < 1e-5
    p3 = designed("3state")[1].parameters
    assert (p3["T_min"], p3["T_max"]) == (Q("0.4176"), Q("1.3452"))
    s = api.method("impulsive").summary(p)
    assert "T_min = 0.1551" in s and "T_max = 0.5396" in s


def test_simulate_option_errors_exit_2(tmp_path: Path) -> None:
    spec = tmp_path / "s.toml"
    spec.write_text(SPEC3.read_text(encoding="utf-8"), encoding="utf-8")
    for opt in ("runs=abc", "runs=0", "nosuchkey=1", "rtol=abc"):
        res = runner.invoke(app, ["simulate", str(spec), "--option", opt])
        assert res.exit_code == 2, (opt, res.output)


def test_a_plant_entry_of_1e308_is_inconclusive_not_an_internal_failure(tmp_path: Path) -> None:
    """A = [[1e308, …]] overflows the float ssd rate of Lemma 2 (Ā + Āᵀ): exit 4, one line, an
    error report (it was exit 3, "cannot round a non-finite number": review 19)."""
    text = SPEC3.read_text(encoding="utf-8").replace("A = [[0, 0.01, 0]", "A = [[1e308, 0.01, 0]")
    assert "1e308" in text
    spec = tmp_path / "s.toml"
    spec.write_text(text, encoding="utf-8")
    out = tmp_path / "r.json"
    res = runner.invoke(app, ["design", str(spec), "-o", str(out)])
    assert res.exit_code == 4, res.output
    assert "overflows float64" in res.output and "Traceback" not in res.output
    err = json.loads(out.read_text(encoding="utf-8"))  # the error report of a stopped design
    assert err["verdict"] == "error" and err["error"]["exit_code"] == 4


@pytest.mark.parametrize("gamma_exp", [300, 100, 30])
def test_window_bounds_stay_sound_and_positive_for_a_tiny_gamma(gamma_exp: int) -> None:
    """T_max_lower (26b) and T_min_upper (26c) at γ = 10^-k: positive, on the safe side of
    the value at 400 digits and within 10⁻⁹ of it (the interval's lower end of (26b) was
    negative at γ = 10⁻³⁰⁰, and the empty-window message printed T_max = −2.4·10⁻³⁴)."""
    from obsdesign.methods.impulsive.window import T_max_lower, T_min_upper

    g = fmpq(1, 10**gamma_exp)
    varpi, kappa, lam_no, lam_on = Q("0.5"), Q("0.9"), Q("0.3"), Q("0.2")
    beta = 1 / ((1 - g) * (1 - g))
    lo = T_max_lower(g, varpi, kappa, lam_no, lam_on, beta)
    hi = T_min_upper(Q(3), g, kappa)
    with mpmath.workdps(400):
        f = lambda q: mpmath.mpf(int(q.p)) / int(q.q)  # noqa: E731
        den = f(varpi) + f(kappa) + f(lam_no) + f(beta) * f(lam_on)
        t_max = -mpmath.log((1 - f(g)) ** 2) / den
        t_min = -mpmath.log((3 - f(g)) / 3) / f(kappa)
        assert 0 < f(lo) <= t_max and f(lo) >= t_max * (1 - mpmath.mpf(10) ** -9)
        assert t_min <= f(hi) <= t_min * (1 + mpmath.mpf(10) ** -9)


def test_a_window_too_narrow_for_its_digits_says_so() -> None:
    """L = 1e-300: the window (3.4·10⁻³⁰¹, 8.4·10⁻³⁰¹) is not empty but holds no pair of
    30-decimal bounds (digits not given: as many as the window needs, at most 30): exit 1
    saying so (it said "empty window: T_min ≥ T_max" with a negative T_max); with digits = 4
    given, it names digits."""
    from obsdesign.errors import InfeasibleError

    text = SPEC3.read_text(encoding="utf-8").replace("L = [0.8]", "L = [1e-300]")
    assert "1e-300" in text
    with pytest.raises(InfeasibleError) as ei:
        api.design(load_spec_text(text, "tiny.toml"))
    msg = ei.value.message
    assert "is not empty, but it holds no pair of 30-decimal bounds" in msg
    assert "raise [method] digits" not in msg and "T_max = -" not in msg
    text = text.replace('key = "impulsive"', 'key = "impulsive"\ndigits = 4')
    with pytest.raises(InfeasibleError) as ei:
        api.design(load_spec_text(text, "tiny4.toml"))
    msg = ei.value.message
    assert "is not empty, but it holds no pair of 4-decimal bounds" in msg
    assert "raise [method] digits (at most 30)" in msg


FAST = """
[system]
time = "continuous"
A = [[2000, 1000], [5000, -20000]]
C = [[1, 0]]
psi = ["0", "0"]
[nonlinearity.o]
lipschitz = 0
[nonlinearity.n]
lipschitz = 0
[method]
key = "impulsive"
L = [0.8]
alpha = 3
noise_bound = 0
M = [[0, 1]]
"""


def test_a_fast_plant_gets_the_decimals_its_window_needs() -> None:
    """A plant 10⁴ times faster than a slow one: window [3.1016·10⁻⁵, 7.3156·10⁻⁵] (mpmath
    below). With 4 decimals it held no pair of bounds and was exit 1 "infeasible" although the
    design is feasible (independent fuzz, session 38). Not given, digits is 4 significant
    digits of T_max below 1: T_min = 0.00003102, T_max = 0.00007315, certified, with a note;
    digits = 4 given is still exit 1 naming digits."""
    from obsdesign.errors import InfeasibleError

    rep = api.design(load_spec_text(FAST, "fast.toml"))
    assert rep.exit_code() == 0
    assert rep.parameters["T_min"] == Q("0.00003102") and rep.parameters["T_max"] == Q("0.00007315")
    assert any("have 8 decimals" in n for n in rep.notes)
    # the bounds of (26c) and (26b) in mpmath: κ and the λ*'s from the report, exact enough
    mpmath.mp.dps = 30
    kq = Q(rep.parameters["kappa"])
    kappa = mpmath.mpf(int(kq.p)) / int(kq.q)
    assert float(-mpmath.log(1 - mpmath.mpf("0.8") / 3) / kappa) == pytest.approx(
        3.1016e-5, rel=1e-4
    )
    with pytest.raises(
        InfeasibleError, match="no pair of 4-decimal bounds.*raise \\[method\\] digits"
    ):
        api.design(
            load_spec_text(FAST.replace("M = [[0, 1]]", "M = [[0, 1]]\ndigits = 4"), "f4.toml")
        )
    for slow in ("schaum-impulsive-example.toml", "impulsive-sector-3state.toml"):
        p = api.design(ROOT / "specs" / slow).parameters  # T_max > 0.1: 4 decimals as before
        assert all(len(str(Q(p[k]) * 10**4).split("/")) == 1 for k in ("T_min", "T_max"))


@pytest.mark.parametrize("alpha", ["3.3", "2.7"])
def test_the_window_details_round_their_bounds_the_safe_way(alpha: str) -> None:
    """The T_min / T_max details print the interval bound rounded up / down: with `.10g` to
    nearest, digits = 14 and α = 3.3 printed "T_min = 0.13881643365317 ≥ 0.1388164337", false
    as printed though the claim holds (rendering trial, session 27). Checked against mpmath
    at 50 digits, and the detail's own inequality exactly."""
    text = (
        (ROOT / "specs" / "schaum-impulsive-example.toml")
        .read_text(encoding="utf-8")
        .replace("alpha = 3\n", f"alpha = {alpha}\ndigits = 14\n", 1)
    )
    assert "digits = 14" in text
    rep = api.design(load_spec_text(text, "digits14.toml"))
    assert rep.exit_code() == 0
    mpmath.mp.dps = 50
    for cid, sign in (("T_min", 1), ("T_max", -1)):
        c = next(c for c in rep.claims if c.id == cid)
        m = re.fullmatch(rf"{cid} = (\S+) (≥|≤) (\S+) \(rounded (up|down)\)", c.detail)
        assert m, c.detail
        t, bound = Q(m[1]), Q(m[3])
        assert (t >= bound) if sign > 0 else (t <= bound)
    hi = next(c for c in rep.claims if c.id == "T_min").detail.split("≥ ")[1].split(" ")[0]
    kappa, gamma = rep.parameters["kappa"], rep.parameters["gamma"]
    a = mpmath.mpf(alpha)

    def f(q: object) -> mpmath.mpf:
        qq = Q(q)
        return mpmath.mpf(int(qq.p)) / int(qq.q)

    t_min = -mpmath.log((a - f(gamma)) / a) / f(kappa)
    assert f(hi) >= t_min  # the printed bound is above the exact one


# -- falsification: rounding is not a violation (review 21) -----------------------------------
TIGHT = Path(__file__).resolve().parent / "specs" / "impulsive-tight-cross.toml"


@pytest.mark.parametrize(("cross", "code"), [("1.55", 0), ("1.5499999", 1), ("1.54", 1)])
def test_falsification_allows_rounding_not_a_violation(cross: str, code: int) -> None:
    """ψ linear with c_n = −1.55·ε_o exactly (in z = T x, T = [C; M]): ‖c_n‖ = ℓ_no‖ε_o‖ holds
    with equality, and the design with cross = 1.55 and on_violation = "fail" failed with a
    "violation" of 2.5e-9 — the rounding of a difference of ψ̄ values at a pair with tiny ε_o
    (review 21). Each pair's tolerance now adds its first-order rounding; a bound 10⁻⁷ too
    small (relative) is still found, at most pairs."""
    txt = TIGHT.read_text(encoding="utf-8").replace("cross = 1.55", f"cross = {cross}")
    rep = api.design(api.load_spec_text(txt, "tight.toml"))
    assert rep.exit_code() == code
    c = next(c for c in rep.claims if c.id == "assumption1-falsification")
    if code == 0:
        assert c.status.value == "numerical" and "no violation" in c.detail
    else:
        assert not c.ok and "cross bound ‖c_n‖ ≤ ℓ_no‖ε_o‖" in c.detail


@pytest.mark.parametrize(("ell", "violated"), [(3.0, False), (3.0 * (1 - 1e-6), True)])
def test_lipschitz_x_falsification_allows_rounding(ell: float, violated: bool) -> None:
    """ψ = 3x on [10⁶, 10⁶ + 1]: ‖ψ(x̂) − ψ(x)‖/‖x̂ − x‖ = 3 exactly, but in floats the
    difference of two values near 3·10⁶ over |x̂ − x| ≈ 10⁻⁴ is off by ~10⁻⁵: it was a
    violation of ℓ = 3. A bound 10⁻⁶ too small (relative) is still a violation."""
    from obsdesign.methods.impulsive.falsify import falsify_lipschitz_x

    lo, hi = np.array([1e6]), np.array([1e6 + 1])
    f = falsify_lipschitz_x(lambda X: 3.0 * X, ell, lo, hi, 2000, 0)
    assert bool(f.violated) == violated


@pytest.mark.parametrize(
    ("key", "norm", "ell"), [("lambda_no", 1, "0.05"), ("lambda_on", "0.01", "0.05")]
)
def test_lambda_star_is_the_norm_rounded_up_not_any_larger_bound(key, norm, ell) -> None:
    """λ*_no = ‖Ā_no‖ + ℓ_no is stated as an equality (rounded up); a larger λ* is
    conservative everywhere else but made that statement false, and was accepted
    (report-edit trial, session 26). On the "cross" plant (‖Ā_no‖ = 1, ‖Ā_on‖ = 0.01 exactly)
    λ* may be at most (1 + 10⁻⁶)‖Ā‖ + 10⁻⁹ + ℓ: the line itself passes, one 2⁻¹⁰⁰ above fails."""
    spec, rep = designed("cross")
    top = (1 + fmpq(1, 10**6)) * Q(norm) + fmpq(1, 10**9) + Q(ell)
    assert Q(rep.parameters[key]) <= top
    assert key not in failed_ids(spec, _with(rep.parameters, {key: top}))
    assert key in failed_ids(spec, _with(rep.parameters, {key: top + TINY}))


def test_ball_radius_is_the_root_rounded_up_not_any_larger_radius() -> None:
    """r_B was only checked from below (r_B² ≥ α w̄): with α = 2, w̄ = 3 the design's
    r_B ≈ √6 fails the escape test (r_B < w̄, exit 1), but a report with r_B = 3 silenced it
    and verified, and simulate used that ball (parameter audit, session 26). r_B may exceed
    √(α w̄) by a factor 1 + 10⁻⁶ at most: on "square" (α w̄ = 0.36, √ = 0.6 exactly) the line
    itself passes, 2⁻¹⁰⁰ above it fails."""
    spec, rep = designed("square")
    line = fmpq(3, 5) * (1 + fmpq(1, 10**6))
    assert failed_ids(spec, _with(rep.parameters, {"ball_radius": line})) == set()
    assert failed_ids(spec, _with(rep.parameters, {"ball_radius": line + TINY})) == {"ball_radius"}
    assert failed_ids(spec, _with(rep.parameters, {"ball_radius": fmpq(10)})) == {"ball_radius"}


# -- mutation review 27: the T_min / T_max details ------------------------------------------
def test_window_details_print_true_inequalities_rounded_the_safe_way() -> None:
    """mutation review 27 (kills impulsive.claims.x__window_detail__mutmut_3, 14, 15, 16, 19,
    20, 25, 47, 50, 51, 52, 55). The detail of each branch, exactly: a passed T_min (T_max)
    shows its bound rounded up (down) to 10 digits under ≥ (≤) — mutant 3 rounded T_max's up,
    47 printed T_max ≥; a failed one the strict opposite inequality — 19 / 20 printed the
    wrong one, 25 printed "10" for the bound; a T_max not above 0 says so — 14 / 15 sent
    T_max = −0.1 and T_max = bound = 0 to "T_max = 0 > 0", 16 raised; within 10⁻⁵⁰ of the
    bound no 10–40-digit decimal is on the safe side and the bound is printed exactly —
    50 / 55 raised there, 51 / 52 printed the wrong inequality. No test reached the
    "is not > 0" or the exact branch, nor checked the inequality sign of a passed T_max."""
    from obsdesign.certify.printing import fmt_exact
    from obsdesign.methods.impulsive.claims import _window_detail as wd

    third = fmpq(1, 3)
    assert wd("T_min", fmpq(1, 2), third, True, up=True) == (
        "T_min = 0.5 ≥ 0.3333333334 (rounded up)"
    )
    assert wd("T_max", fmpq(3, 10), third, True, up=False) == (
        "T_max = 0.3 ≤ 0.3333333333 (rounded down)"
    )
    assert wd("T_min", fmpq(3, 10), third, False, up=True) == (
        "T_min = 0.3 < 0.3333333334 (rounded up)"
    )
    assert wd("T_max", fmpq(1, 2), third, False, up=False) == (
        "T_max = 0.5 > 0.3333333333 (rounded down)"
    )
    assert wd("T_max", fmpq(-1, 10), third, False, up=False) == "T_max = -0.1 is not > 0"
    assert wd("T_max", fmpq(0), fmpq(0), False, up=False) == "T_max = 0 is not > 0"
    eps = fmpq(1, 10**50)
    t = third + eps
    assert wd("T_min", t, third, True, up=True) == f"T_min = {fmt_exact(t)} ≥ 1/3 (exact)"
    t = third - eps
    assert wd("T_max", t, third, True, up=False) == f"T_max = {fmt_exact(t)} ≤ 1/3 (exact)"


#: 3 states, 2 outputs, QSR given; the true κ_max of (22) is 5.6 − (√0.2 + 0.01) −
#: 4(√0.05 + 0.05) = 4.04835921350013…
KAPPA_NEAR_MAX = """[system]
time = "continuous"
A = [[-1, 0.5, 0.2], [0.3, -2, 0.1], [0.4, 0.2, -3]]
C = [[1, 0, 0], [0, 1, 0]]
states = ["x1", "x2", "x3"]
psi = ["0.1*sin(x1)", "0.1*sin(x2)", "0.2*tanh(x3)"]
[nonlinearity.o]
Q = [[-1, 0.1], [0.1, -2]]
S = [[0.05, 0], [0, 0.05]]
R = [[0.01, 0], [0, 0.01]]
cross = 0.05
[nonlinearity.n]
sector = [0, 0.2]
cross = 0.01
[method]
key = "impulsive"
L = [[0.5, 0], [0, 0.9]]
alpha = 2
noise_bound = 0.05
M = [[0, 0, 1]]
kappa = KAPPA
digits = 30
"""


@pytest.mark.parametrize(
    ("kappa", "code"),
    [("4.048359213", 4), ("4.0483592135002", 1), ("4.04835", 0), ("0.4063118917", 4)],
)
def test_a_given_kappa_between_the_certified_and_the_true_kappa_max_is_inconclusive(
    kappa: str, code: int
) -> None:
    """κ = 4.048359213 lies 5·10⁻¹⁰ below the true κ_max of (22) but above the certified one
    (‖Ā_no‖, ‖Ā_on‖ rounded up by 2⁻³⁰ relative, ×β = 4): it was exit 1 "condition (22)
    fails" (soundness trial, session 32). The retry with float values now also takes the
    float norms: exit 4, no proof either way. A κ above the true κ_max is still exit 1, and
    one well inside certifies. κ = 0.4063118917 leaves a nonempty window (shown exactly by
    the trial) that the certified values close: "empty window" was exit 1, now exit 4."""
    from obsdesign.errors import ObsdesignError

    spec = load_spec_text(KAPPA_NEAR_MAX.replace("KAPPA", kappa), "k.toml")
    try:
        got = api.design(spec).exit_code()
    except ObsdesignError as e:
        got = e.exit_code
        assert "certified κ_max ≤ 4.048359208" in e.message or "empty window" in e.message
    assert got == code


@pytest.mark.parametrize(("kappa", "code"), [("1.9499999963", 4), ("1.9500000139", 1)])
def test_a_given_kappa_near_kappa_max_with_lipschitz_x_data(kappa: str, code: int) -> None:
    """With `lipschitz_x`, the template's plant with ℓ = 0.1 has κ_max = 1.95 (certified
    1.94999999436): a κ 4·10⁻⁹ below it is exit 4 (no proof either way), one 10⁻⁸ above it
    exit 1."""
    import re

    from obsdesign.errors import ObsdesignError

    t = api.template("impulsive").replace("[nonlinearity]\n", "[nonlinearity]\nlipschitz_x = 0.1\n")
    t = re.sub(r"\[nonlinearity\.o\].*?(?=\[method\])", "", t, flags=re.S)
    t = t.replace('kappa = "max"', f"kappa = {kappa}")
    try:
        got = api.design(load_spec_text(t, "lx.toml")).exit_code()
    except ObsdesignError as e:
        got = e.exit_code
    assert got == code


def test_the_float_retry_derives_lipschitz_x_block_data_from_float_norms(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The block data of `lipschitz_x` come from norm bounds rounded up; the retry that
    tells exit 4 from exit 1 derives them again from the float norms. With the bounds
    inflated by 10⁻³ (a stand-in for the rounding), κ = 1.9499999 below the true κ_max = 1.95
    of the template's plant is exit 4, where the rounded data alone said exit 1."""
    import re

    from obsdesign.errors import ObsdesignError
    from obsdesign.methods.impulsive import design as D

    real = D.norm_bounds
    monkeypatch.setattr(
        D, "norm_bounds", lambda co: {k: v * fmpq(1001, 1000) for k, v in real(co).items()}
    )
    t = api.template("impulsive").replace("[nonlinearity]\n", "[nonlinearity]\nlipschitz_x = 0.1\n")
    t = re.sub(r"\[nonlinearity\.o\].*?(?=\[method\])", "", t, flags=re.S)
    t = t.replace('kappa = "max"', "kappa = 1.9499999")
    with pytest.raises(ObsdesignError) as e:
        api.design(load_spec_text(t, "lx.toml"))
    assert e.value.exit_code == 4, e.value.message


OPTIMIZE_M = """[system]
time = "continuous"
A = [[-2, 1, 0, 0], [0, -3, 1, 0], [0, 0, -4, 1], [1, 0, 0, -5]]
C = [[1, 1, 0, 0], [0, 0, 1, 0]]
states = ["x1", "x2", "x3", "x4"]
psi = ["0.05*sin(x1)", "0", "0.05*sin(x4)", "0"]
[nonlinearity]
lipschitz_x = 0.05
[method]
kappa = KAPPA
key = "impulsive"
L = [0.7, 0.6]
alpha = 5
noise_bound = 0.01
M = "optimize"
digits = 12
"""


@pytest.mark.parametrize(
    ("kappa", "code"),
    # 0.389275 and 0.77855 stopped at Ms whose certified κ_max was ~10⁻⁵ below κ with a
    # 10⁻⁶ margin (second re-check trial, session 32)
    [("0.7785", 0), ("0.5", 0), ("0.389275", 0), ("0.77855", 0), ("100", 1)],
)
def test_m_optimize_with_a_given_kappa_keeps_to_ms_that_admit_it(kappa: str, code: int) -> None:
    """M = "optimize" scored an M by the window's formulas even where (22) does not admit the
    given κ: for κ = 0.7785 it chose an M with κ_max ≈ 8·10⁻⁷, exit 1, where the M it picks
    for κ = "max" certifies that κ (re-check trial, session 32). Such an M now scores by how
    far (22) is from admitting κ, with the margin "max" keeps: κ = 0.7785 and 0.5 certify; κ
    = 100, above every κ_max, is exit 1 naming the given κ."""
    from obsdesign.errors import ObsdesignError

    try:
        got = api.design(load_spec_text(OPTIMIZE_M.replace("KAPPA", kappa), "m.toml")).exit_code()
    except ObsdesignError as e:
        got = e.exit_code
        assert "for the given κ = 100" in e.message
    assert got == code


def test_the_float_norm_of_the_retry_is_the_spectral_norm() -> None:
    """_float_norm gives ‖X‖₂ of a block (the value λ*_no, λ*_on of Lemma 1 use), not the
    Frobenius norm: every test plant had single-row or single-column off-diagonal blocks,
    where the two agree, so the Frobenius mutant survived (mutation review 33, I08). On
    [[3, 0], [0, 4]] they differ (4 against 5); an empty block is 0."""
    from flint import fmpq

    from obsdesign.methods.impulsive.design import _float_norm

    def q(rows: list[list[int]]) -> np.ndarray:
        return np.array([[fmpq(x) for x in r] for r in rows], dtype=object).reshape(-1, 2)

    assert _float_norm(q([[3, 0], [0, 4]])) == 4
    assert _float_norm(q([[1, 1], [1, 1]])) == 2
    assert _float_norm(q([])) == 0


def test_rows_of_a_non_finite_row_are_infinite() -> None:
    """Mutation review 36, falsify._rows: a row with a NaN (or ±inf) entry has the norm +inf,
    never NaN — a NaN row norm compares false everywhere and would drop that sample from
    the ratio and rounding checks instead of flagging it."""
    from obsdesign.methods.impulsive.falsify import _rows

    out = _rows(np.array([[np.nan, 1.0], [np.inf, 0.0], [3e200, 4e200], [0.0, 0.0]]))
    assert out[0] == math.inf and out[1] == math.inf
    assert out[2] == pytest.approx(5e200) and out[3] == 0.0


@pytest.mark.parametrize("ell", [0.5, 0.49])
def test_lipschitz_x_falsification_reads_a_huge_box(ell: float) -> None:
    """Mutation review 36, falsify_lipschitz_x on _rows: ψ(x) = x/2 on the box ±10²⁰⁰ is
    exactly ½-Lipschitz. Norms squared unscaled overflow there (‖x̂ − x‖ = inf, the ratio
    inf/inf = NaN for every independent pair): every wide pair must still be tested, with no
    violation of ℓ = ½ and a finite worst value, and ℓ = 0.49 is found violated."""
    from obsdesign.methods.impulsive.falsify import falsify_lipschitz_x

    lo, hi = np.full(2, -1e200), np.full(2, 1e200)
    f = falsify_lipschitz_x(lambda X: 0.5 * X, ell, lo, hi, 200, 0)
    (v,) = [v for v in f.items if v.name == "Lipschitz bound of ψ in x"]
    assert v.tested == 200 and math.isfinite(v.worst)
    assert (v.count > 0) == (ell < 0.5), f.summary()


def test_best_rate_takes_an_infinite_rate_as_the_worst_theta(monkeypatch) -> None:
    """Mutation review 36, best_rate's neg: a θ where the float rate search overflowed to
    κ = +inf (−κ = −inf) is the worst value, like NaN — not the best one, which would return
    the overflowing θ. Faked here: κ(θ) = −(log θ)² (optimum θ = 1), +inf beyond θ = e³."""
    from obsdesign.certify.exact import to_float
    from obsdesign.methods.impulsive import dissipativity as dv

    def fake(A, Qm, S, R):
        t = float(Qm[0, 0])
        return (math.inf, 0.0, 0.0) if t > math.exp(3) else (-(math.log(t) ** 2), 0.0, 0.0)

    monkeypatch.setattr(dv, "_rate_resid_scale", fake)
    monkeypatch.setattr(dv, "range_theta", lambda qsr: None)
    one = np.array([[fmpq(1)]], dtype=object)
    qsr = dv.QSR(one, np.array([[fmpq(0)]], dtype=object), -one, "test")
    r, theta, _ = dv.best_rate(np.eye(1), qsr, True)
    assert abs(math.log(float(to_float(theta)))) < 0.1 and r > -0.01


def test_a_non_finite_lemma1_residual_is_inconclusive(monkeypatch) -> None:
    """Mutation review 36, design_window's second Lemma 1 branch: a NaN range residual (the
    float search overflowed) with a finite κ_n is not a design — it is "the float search of
    κ_n gave …" (InconclusiveError), never passed on to certified_rate as if the range
    condition held (NaN > 10⁻⁷ is false, so the first branch lets it through)."""
    from pathlib import Path

    from obsdesign import api
    from obsdesign.errors import InconclusiveError
    from obsdesign.methods.impulsive import design as dmod

    real = dmod.best_rate
    calls = []

    def fake(A, qsr, opt):
        calls.append(1)
        r, th, res = real(A, qsr, opt)
        return (r, th, math.nan) if len(calls) == 2 else (r, th, res)

    monkeypatch.setattr(dmod, "best_rate", fake)
    spec = Path(__file__).resolve().parents[1] / "specs" / "impulsive-sector-3state.toml"
    with pytest.raises(InconclusiveError, match="float search of κ_n"):
        api.design(api.load_spec(spec))


@pytest.mark.parametrize(("scale", "slack"), [(1e200, 1.0), (1e200, 0.99), (1.0, 0.99)])
def test_block_cross_bounds_read_a_huge_box(scale: float, slack: float) -> None:
    """Mutation review 36 (X1–X3): the cross parts of the split (15) on ψ(x) = (3x₂, 5x₁),
    T = I, m = 1: c_o = ψ_o(ẑ) − ψ_o(ẑ_o, z_n) = 3ε_n and c_n = 5ε_o exactly, so ℓ_on = 3,
    ℓ_no = 5 hold with the ratios 3 and 5, and 0.99 of them is violated. On the box ±10²⁰⁰
    the norms ‖c_o‖, ‖c_n‖, ‖ε‖ squared unscaled overflow (inf/inf = NaN for every pair):
    every pair must still be read, with the measured ratios 3 and 5."""
    from obsdesign.methods.impulsive.falsify import falsify_blocks

    def psi(X: np.ndarray) -> np.ndarray:
        return np.stack([3 * X[:, 1], 5 * X[:, 0]], axis=1)

    one, zero = np.ones((1, 1)), np.zeros((1, 1))
    qsr = (one, zero, zero)  # ω = |ε|² ≥ 0: the own parts hold
    lo, hi = np.full(2, -scale), np.full(2, scale)
    f = falsify_blocks(psi, np.eye(2), 1, qsr, qsr, 3 * slack, 5 * slack, lo, hi, 300, 0)
    cross = [v for v in f.items if v.name.startswith("cross bound")]
    assert len(cross) == 2 and all(v.tested > 250 for v in cross), f.summary()
    lit = f.literal_cross
    assert lit["o"] == pytest.approx(3, rel=1e-6) and lit["n"] == pytest.approx(5, rel=1e-6)
    assert all((v.count > 0) == (slack < 1) for v in cross), f.summary()


def _first_row_zero_spec(M: str) -> str:
    """The impulsive trial's 4-state plant (session 40): A's first row is 0, so C·A = 0 and
    the coupling terms of (22) can be driven to 0 by M."""
    return f"""
[system]
time = "continuous"
A = [[0.0, 0.0, 0.0, 0.0], [0.0077549, -5.55029, 3.64544, 2.25169],
     [-0.0175328, -3.64544, -5.55029, -1.39966], [-0.0379486, 0.959081, -0.897898, -6.2409]]
C = [[1, 0, 0, 0]]
states = ["x1", "x2", "x3", "x4"]
psi = ["0", "0", "0", "0"]
[nonlinearity]
lipschitz_x = 0
[method]
key = "impulsive"
L = [0.817636]
alpha = 8.17636
noise_bound = 0
M = {M}
"""


def test_m_optimize_does_not_walk_to_the_edge_of_condition_22() -> None:
    """M = "optimize" scored the window's width, unbounded where C·A = 0 (it grows like 1/κ
    as κ → 0): on this plant the search chose an M scoring 6.6·10¹⁴ whose rounded κ_n was
    negative, "Lemma 1 fails" (exit 1), where the orthonormal M certifies [0.0137, 0.4372]
    with κ ≈ 7.74; on the 3-state one it certified [238048, 2070405] with κ = 1.3·10⁻⁶
    (impulsive trial, session 40). The score is now ln(T_max / T_min): both certify with a
    κ no smaller than half the orthonormal M's and a window no narrower in ratio."""
    opt = api.design(load_spec_text(_first_row_zero_spec('"optimize"'), "opt.toml"))
    orth = api.design(load_spec_text(_first_row_zero_spec('"orthonormal"'), "orth.toml"))
    assert opt.exit_code() == 0 and orth.exit_code() == 0
    k_opt, k_orth = (float(r.parameters.float("kappa")) for r in (opt, orth))
    assert k_opt >= 0.5 * k_orth

    def ratio(r: Any) -> float:
        return float(r.parameters.float("T_max")) / float(r.parameters.float("T_min"))

    assert ratio(opt) >= ratio(orth) * (1 - 1e-3)
    assert api.verify(opt).exit_code() == 0
    three = (
        '[system]\ntime = "continuous"\nA = [[0, 0, 0], [1, -1, 0.5], [0, -0.5, -1]]\n'
        'C = [[1, 0, 0]]\nstates = ["x1", "x2", "x3"]\npsi = ["0", "0", "0"]\n'
        "[nonlinearity]\nlipschitz_x = 0\n"
        '[method]\nkey = "impulsive"\nL = [0.8]\nalpha = 3\nnoise_bound = 0\nM = "optimize"\n'
    )
    rep = api.design(load_spec_text(three, "three.toml"))
    assert rep.exit_code() == 0
    assert float(rep.parameters.float("kappa")) > 0.1  # was 1.3e-6
    assert float(rep.parameters.float("T_max")) < 100  # was 2070405


def test_m_optimize_falls_back_to_the_orthonormal_m(monkeypatch: pytest.MonkeyPatch) -> None:
    """A searched M that fails the exact conditions (here: one the search is made to return,
    with its last row nearly a copy of C's) is replaced by the orthonormal complement the
    search started from, with a note; the design was exit 1 on the searched M alone."""
    from obsdesign.errors import InfeasibleError
    from obsdesign.methods.impulsive import design as dmod

    def edge(p: Any, seed: int = 0, starts: int = 6) -> np.ndarray:
        return np.array([[0.0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, 1e-9]])

    monkeypatch.setattr(dmod, "optimize_M", edge)
    rep = api.design(load_spec_text(_first_row_zero_spec('"optimize"'), "opt.toml"))
    assert rep.exit_code() == 0
    assert any('M = "optimize": the searched M failed the exact conditions' in n for n in rep.notes)
    assert rep.parameters["M_source"] == "orthonormal"
    assert api.verify(rep).exit_code() == 0

    def fails(p: Any) -> Any:
        searched = isinstance(p.M, str) and p.M == "optimize"
        raise dmod.Infeasible("searched M fails" if searched else "orthonormal fails")

    monkeypatch.setattr(dmod, "design_window", fails)
    with pytest.raises(InfeasibleError, match="searched M fails"):  # the searched M's error
        api.design(load_spec_text(_first_row_zero_spec('"optimize"'), "opt.toml"))


def test_a_near_point_sector_is_not_lemma1_fails_at_a_noise_theta() -> None:
    """A sector 7·10⁻¹⁸ wide on the unmeasured block: κ*(θ) rises to its supremum 9.1 as
    θ → ∞ and is flat in floats from θ ≈ e¹⁰ on; the θ search followed rounding noise to
    θ ≈ 4·10²⁰ (float rate −128, certified κ_n −1042) and the design said "Lemma 1 fails",
    exit 1, where a certificate with κ_n = 9.09 exists (impulsive review, session 42). The
    search now weighs κ*(θ)'s float error: κ_n ≈ 9.1 certifies, and verify agrees."""
    from obsdesign import api

    text = (
        '[system]\ntime = "continuous"\nA = [[-1.5, -0.2], [0.03, -4.5]]\nC = [[1, 0]]\n'
        'states = ["x1", "x2"]\npsi = ["-0.05*x1", "-0.05*x2"]\n'
        "[nonlinearity.o]\nsector = [-0.05, -0.05]\n"
        "[nonlinearity.n]\nsector = [-0.049888315228288321, -0.049888315228288314]\n"
        '[method]\nkey = "impulsive"\nL = [0.8]\nalpha = 3\nnoise_bound = 0.1\n'
        'kappa = "max"\nM = [[0, 1]]\n'
    )
    rep = api.design(api.load_spec_text(text, "s.toml"))
    assert rep.exit_code() == 0
    assert 9.09 < float(rep.parameters["kappa_n"]) <= 9.1
    assert api.verify(rep).exit_code() == 0


def test_an_edited_M_source_label_fails_verify() -> None:
    """M_source was read and passed on unchecked: a report of a given M edited to
    "optimized" verified (impulsive review, session 42). It must be what the spec's
    [method].M gives: "given" here; the shipped example (M given) verifies unedited."""
    from obsdesign import api
    from obsdesign.report import Report

    rep = api.design(api.load_spec(ROOT / "specs" / "impulsive-sector-3state.toml"))
    assert rep.parameters["M_source"] == "given"
    assert api.verify(rep).exit_code() == 0
    for label in ("optimized", "orthonormal", "Given"):
        d = rep.to_dict()
        d["parameters"]["M_source"] = label
        ver = api.verify(Report.from_dict(d)[0])
        bad = [c.id for c in ver.claims if not c.ok]
        assert ver.exit_code() == 1 and "M_source-matches-spec" in bad, (label, bad)


def test_a_copied_spec_with_another_system_is_bound_to_that_system() -> None:
    """The impulsive options hold A and C of the system they were parsed from: a copy of the
    3-state spec with A = diag(0, 1, 1) (spec.system replaced) had every exact claim certified
    for the old A — Ā, κ_n ≥ 5.39999, Lemma 1's ISS — and designed with exit 0, while
    ``simulate`` ran the new A, whose (A, C) is not even detectable (API review, session 43).
    The copy is bound again to its own system."""
    import copy
    import dataclasses

    from obsdesign.errors import InfeasibleError
    from obsdesign.spec.reader import Value

    spec, rep = designed("3state")
    other = copy.copy(spec)
    A = np.array([[fmpq(int(i == j and i > 0)) for j in range(3)] for i in range(3)], dtype=object)
    other.system = dataclasses.replace(spec.system, A=Value.of(A))
    failed = {c.id for c in api.certify(other, rep.parameters) if not c.ok}
    assert {"Abar", "kappa_n", "lambda_no", "lambda_on"} <= failed
    with pytest.raises(InfeasibleError, match="Lemma 1 fails"):
        get_method("impulsive").design(api.bind(other), None)
    # api.design refuses the copy: a report would embed the text of the old A (session 44)
    with pytest.raises(InputError, match=r"\[system\] of the spec object was replaced"):
        api.design(other)
    assert all(c.ok for c in api.certify(spec, rep.parameters))  # the original: unchanged
    assert spec.options.problem.A is spec.system.A.q


def test_assumption1_data_no_nonlinearity_satisfies_are_refused() -> None:
    """[nonlinearity.o] Q = R = −1, S = 0 reads −φ² − ε² ≥ 0, which no function satisfies at
    ε ≠ 0: the design certified a window (vacuously: "given the declared data") for an
    observer whose error grows (spectral radius 2.93 over a sampling interval; impulsive
    review, session 43). R − SᵀQ⁻¹S ⪰ 0 is required (exit 2 naming the key); R = 0, the
    smallest satisfiable R for Q = −1, S = 0, loads."""
    text = SPEC3.read_text(encoding="utf-8")
    old = "[nonlinearity.o]\nsector = [-0.2, 0.2]"
    assert old in text
    bad = text.replace(old, "[nonlinearity.o]\nQ = [[-1]]\nS = [[0]]\nR = [[-1]]")
    with pytest.raises(SpecError, match=r"\[nonlinearity\.o\.R\].*hold for no nonlinearity"):
        load_spec_text(bad, "vac.toml")
    load_spec_text(bad.replace("R = [[-1]]", "R = [[0]]"), "edge.toml")
    # with S: R − S²/Q = R + S² for Q = −1; S = 1/2 makes R = −1/4 the edge
    edge = text.replace(old, "[nonlinearity.o]\nQ = [[-1]]\nS = [[0.5]]\nR = [[-0.25]]")
    load_spec_text(edge, "edge.toml")
    with pytest.raises(SpecError, match="hold for no nonlinearity"):
        load_spec_text(edge.replace("R = [[-0.25]]", "R = [[-0.2500001]]"), "vac.toml")
    # a singular Q_n passed the Q ≺ 0 test unchecked: Q = diag(−1, 0), S = diag(0, −1),
    # R = diag(−1000, 0) has supply −φ₁² − 1000 at ε = (1, 0) for every φ, and designed and
    # verified a window for an observer with an eigenvalue +5 (tamper review, session 43)
    old_n = "[nonlinearity.n]\nsector = [0, 0.3]"
    assert old_n in text
    sing = "[nonlinearity.n]\nQ = [[-1, 0], [0, 0]]\nS = [[0, 0], [0, -1]]\nR = [[{r}, 0], [0, 0]]"
    with pytest.raises(SpecError, match=r"\[nonlinearity\.n\.R\].*hold for no nonlinearity"):
        load_spec_text(text.replace(old_n, sing.format(r=-1000)), "vac.toml")
    # R₁₁ = 0 is satisfiable (φ = 0 at ε = (1, 0); along ε₂ the supply is unbounded above)
    load_spec_text(text.replace(old_n, sing.format(r=0)), "edge.toml")


ORTH = """[system]
time = "continuous"
A = [[-1, 0.5, 0.2], [0.3, -4, 0.1], [0.1, 0.2, -5]]
C = [[1, 0, 0]]
states = ["x1", "x2", "x3"]
psi = ["0.1*sin(x1)", "0.1*sin(x2)", "0.1*sin(x3)"]
[nonlinearity]
lipschitz_x = 0.1
[method]
key = "impulsive"
L = [0.5]
alpha = 2
noise_bound = 0.01
M = "orthonormal"
"""


def test_an_orthonormal_label_needs_an_orthonormal_M() -> None:
    """A report with M = [[0.3, 1, 0], [0, 0, 1]] (T, Ā and every bound recomputed for it)
    labelled M_source = "orthonormal" verified, exit 0: another observer than the spec's
    orthonormal complement (impulsive review, session 43). The label's M must be orthonormal
    and orthogonal to C's rows (up to its 20-bit rounding)."""
    from obsdesign.methods.impulsive.claims import _m_source_claim

    spec = load_spec_text(ORTH, "orth.toml")
    rep = api.design(spec)
    assert rep.exit_code() == 0 and rep.parameters["M_source"] == "orthonormal"
    p = spec.options.problem
    c = Claims()
    _m_source_claim(c, p, "orthonormal", rep.parameters["T"])
    assert not list(c)
    forged = qmat([[1, 0, 0], ["0.3", 1, 0], [0, 0, 1]])
    _m_source_claim(c, p, "orthonormal", forged)
    (claim,) = list(c)
    assert claim.id == "M_source-matches-spec" and not claim.ok
    assert "not the orthonormal complement" in claim.detail
