"""The lyapunov method: the paper's P (constrained-redesign paper, Section 5), the bracketed
best rate, the claims bound to the spec, and a tamper test for every claim id."""

from __future__ import annotations

import json
import re
import tomllib
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from flint import fmpq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from obsdesign import api, lyap
from obsdesign.api import load_spec_text
from obsdesign.certify.claim import ClaimStatus
from obsdesign.certify.exact import Q, qmat
from obsdesign.certify.psd import check_pd
from obsdesign.cli import app
from obsdesign.errors import InconclusiveError, InfeasibleError
from obsdesign.params import Parameters

ROOT = Path(__file__).resolve().parents[1]
SEC5 = ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml"
runner = CliRunner()
EPS = fmpq(1, 2**60)


def _fmt(M: np.ndarray | str) -> str:
    """A matrix as a TOML array of rows (``repr`` of each float: exact round trip); a string
    is taken as already written."""
    if isinstance(M, str):
        return M
    return "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in r) + "]" for r in M) + "]"


def _designed(
    A: np.ndarray | str, C: np.ndarray | str, time: str = "discrete", extra: str = ""
) -> str:
    """A lyapunov spec for (A, C); ``extra`` holds further ``[method]`` lines."""
    return (
        f'[system]\ntime = "{time}"\nA = {_fmt(A)}\nC = {_fmt(C)}\n'
        f'[method]\nkey = "lyapunov"\n{extra}'
    )


IDS = [
    "P-positive-definite",
    "decay-lmi",
    "P_best-positive-definite",
    "decay-lmi_best",
    "lambda_best-bracket",
    "iss-gain",
]


def test_paper_P_and_Pinv(specs_dir):
    """Paper 000 prints P = 1e5·[[1.259, 1.319], [1.319, 1.381]] and
    P⁻¹ = [[0.039, -0.037], [-0.037, 0.036]] for λ = 0.955."""
    rep = api.design(specs_dir / "constrained-redesign-sec5-lyapunov.toml")
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    P = rep.parameters.float("P")
    np.testing.assert_array_equal(np.round(P / 1e5, 3), [[1.259, 1.319], [1.319, 1.381]])
    Pinv = np.linalg.inv(P)
    np.testing.assert_array_equal(np.round(Pinv, 3), [[0.039, -0.037], [-0.037, 0.036]])
    assert rep.parameters["lambda"] == fmpq(955, 1000)
    # best rate: the infimum is max|eig(A − LC)| = 0.95, found to the tolerance 1e-4
    best = float(rep.parameters.float("lambda_best"))
    assert 0.95 < best <= 0.95 + 1e-4 + 1e-9
    assert "mu" in rep.parameters


def test_shipped_spec_key_results_exact() -> None:
    """specs/constrained-redesign-sec5-lyapunov.toml: every number as before the package
    split (P, λ, P_best, λ_best, μ), plus the bracket; the exact claim list."""
    rep = api.design(SEC5)
    ex = json.loads(rep.to_json())["parameters"]["exact"]
    assert ex["L"] == [["-187/100"], ["937/500"]]
    assert ex["P"] == [
        ["528192554325/4194304", "553027016189/4194304"],
        ["553027016189/4194304", "579147225821/4194304"],
    ]
    assert ex["lambda"] == "191/200"
    # P_best, λ_best: the search's first candidate, one rate_tol above the infeasible end
    # (0.95006 from a bisection from the stability edge before session 11)
    assert ex["P_best"] == [
        ["632376363209/65536", "665588140049/65536"],
        ["665588140049/65536", "175136653153/16384"],
    ]
    assert ex["lambda_best"] == "9501/10000"
    assert ex["lambda_bracket"] == "19/20"
    assert rep.parameters["lambda_bracket_kind"] == "infeasible"
    # 10⁻⁶ above the float infimum (256225114.2), so the verified float check decides it
    # (10⁻⁹ sent n = 100 to exact elimination: 12.6 s, not 1.2 s; lyapunov fuzz, session 38)
    assert ex["mu"] == "512450741/2"
    assert [c.id for c in rep.claims] == IDS
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    st = {c.id: c.statement for c in rep.claims}
    assert st["decay-lmi"] == "(A−LC)ᵀP(A−LC) ⪯ λ²·P with λ = 0.955"
    assert st["decay-lmi_best"] == "(A−LC)ᵀP_best(A−LC) ⪯ λ_best²·P_best with λ_best = 0.9501"
    # was "μ = 2.56225e+08", below the certified μ: now exact
    assert st["iss-gain"] == "V(e⁺) ≤ λ²V(e) + μ|v|² with μ = 256225370.5"
    assert st["lambda_best-bracket"].startswith("λ_best = 0.9501 is best to within 0.0001: ")
    assert rep.solver["status"] == "closed_form"
    assert rep.solver["name"] == "Lyapunov equation: numpy, one n²×n² linear system"
    assert api.method("lyapunov").summary(rep.parameters) == (
        "lambda = 0.955, best = 0.9501, mu ≤ 2.563e+08"
    )


_NUM = re.compile(r"(λ_best|α_best|λ|α|μ) = ([-0-9./e+]+)(?: ≤ ([-0-9.e+]+))?")


@pytest.mark.parametrize(
    "extra",
    [
        "",
        "\n[system]\ntime = 'continuous'\nA = [[0, 1], [-2, -0.1]]\nC = [[1, 0]]\n"
        "[method]\nkey = 'lyapunov'\nL = [3, 2]\nalpha = 0.5\niss_gain = true\n",
        "\n[system]\ntime = 'discrete'\nA = [[0, 1], [-0.5, 0.3]]\nC = [[1, 0]]\n"
        "Bd = [[0.1], [0.2]]\n[method]\nkey = 'lyapunov'\nL = [0.5, 0.1]\nlambda = 0.9\n"
        "iss_gain = true\n",
    ],
)
def test_printed_numbers_are_exact_or_safe(extra: str) -> None:
    """Every number printed in a statement is the exact value, or (μ) an upper bound."""
    rep = api.design(SEC5 if not extra else load_spec_text(extra, "x.toml"))
    key = {"λ": "lambda", "α": "alpha", "λ_best": "lambda_best", "α_best": "alpha_best"}
    seen = 0
    for c in rep.claims:
        for sym, val, up in _NUM.findall(c.statement):
            seen += 1
            if sym == "μ":
                mu = Q(rep.parameters["mu"])
                assert Q(val) == mu and (not up or Q(up) >= mu), c.statement
            elif not any(  # else the bracket's other end
                w in c.statement.split(f"{sym} = {val}")[0]
                for w in ("gives", "strictly at", "not proven")
            ):
                assert Q(val) == Q(rep.parameters[key[sym]]), c.statement
    assert seen >= 4


def test_asked_rate_just_above_the_spectral_radius() -> None:
    """ρ(A − LC) = 0.9999999 and λ = 0.99999991: checked directly (was refused: "no decay
    rate below 1 certifies"); the best rate is the asked one, bracketed by 0.99999."""
    text = _designed(
        "[[0.9999999, 0], [0, 0.5]]", "[[0, 1]]", extra="L = [0, 0]\nlambda = 0.99999991\n"
    )
    rep = api.design(load_spec_text(text))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    p = rep.parameters
    assert p["lambda"] == fmpq(99999991, 10**8) == p["lambda_best"]
    assert p["lambda_bracket"] == fmpq(99999, 100000)
    assert p["lambda_bracket_kind"] == "infeasible"


def test_best_never_worse_than_the_asked_rate(monkeypatch: pytest.MonkeyPatch) -> None:
    """A certifier that fails on (0.6, 0.99) except at the asked 0.955: the design reports
    λ_best ≤ 0.955 (was: a best rate worse than a certified asked rate)."""
    real = lyap.certified_P

    def flaky(A, C, L, discrete, rate, margin, bits=lyap.BITS, **kw):  # noqa: ANN001, ANN003, ANN202
        if fmpq(6, 10) < rate < fmpq(99, 100) and rate != fmpq(955, 1000):
            return None
        return real(A, C, L, discrete, rate, margin, bits, **kw)

    monkeypatch.setattr(lyap, "certified_P", flaky)
    rep = api.design(SEC5)
    assert rep.parameters["lambda_best"] <= fmpq(955, 1000)
    assert rep.exit_code() == 0


def test_template_with_every_key_line_uncommented() -> None:
    text = api.template("lyapunov")
    lines = [re.sub(r"^# (\w+ = )", r"\1", ln) for ln in text.splitlines()]
    full = "\n".join(lines) + "\n"
    tomllib.loads(full)
    assert "Bd = " in full and "\n# Bd" not in full
    rep = api.design(load_spec_text(full, "template-uncommented.toml"))
    assert rep.exit_code() == 0
    assert "w = (d, v)" in {c.id: c.statement for c in rep.claims}["iss-gain"]


# -- tamper tests: every claim id fails alone, by the smallest margin -----------------------
CONT = """
[system]
time = "continuous"
A = [[-10, 0], [0, -1]]
C = [[1, 1]]
[method]
key = "lyapunov"
L = [0, 0]
alpha = 0.9
margin = 0.01
"""


def _edge(ok: Callable[[fmpq], bool], good: fmpq, bad: fmpq) -> fmpq:
    """The failing end of a bisection to 60 bits: ok(good), not ok(result), and the result
    within |bad − good|·2⁻⁶⁰ of a passing value."""
    assert ok(good) and not ok(bad)
    for _ in range(60):
        mid = (good + bad) / 2
        if ok(mid):
            good = mid
        else:
            bad = mid
    return bad


def _decay_ok(spec, name: str, rate_key: str):  # noqa: ANN001, ANN202
    s = spec.system
    o = spec.options

    def ok(P: np.ndarray, rate: fmpq) -> bool:
        M = lyap.decay_matrix(s.A.q, s.C.q, o.L, P, rate, s.discrete)
        return bool(check_pd(M, o.margin))

    return ok


def _tamper_decay(p: Parameters, spec, pkey: str, rkey: str, row: int = 0) -> None:  # noqa: ANN001
    """P − t·eᵢeᵢᵀ (i = row) with t just past the edge of the decay LMI."""
    P0, rate = p[pkey], Q(p[rkey])  # the untampered rate (equal to the spec's when it asks one)
    ok = _decay_ok(spec, pkey, rkey)
    E = qmat([[1 - row, 0], [0, row]])

    def at(t: fmpq) -> np.ndarray:
        return P0 - E * t

    t = _edge(lambda t: ok(at(t), rate), fmpq(0), fmpq(1000))
    p[pkey] = at(t)


def _tamper_rate_edge(p: Parameters, spec) -> None:  # noqa: ANN001
    ok = _decay_ok(spec, "P", "lambda")
    p["lambda"] = _edge(lambda r: ok(p["P"], r), Q(p["lambda"]), fmpq(0))


def _tamper_mu_edge(p: Parameters, spec) -> None:  # noqa: ANN001
    s, o = spec.system, spec.options
    Acl = lyap.closed_loop(s.A.q, s.C.q, o.L)
    Bw = lyap.error_input(s.Bd.q, s.Dn.q, o.L)
    rho = lyap.decay_factor(o.rate, True)

    def ok(mu: fmpq) -> bool:
        return bool(check_pd(lyap.iss_matrix(Acl, Bw, p["P"], rho, mu, True)))

    p["mu"] = _edge(ok, Q(p["mu"]), fmpq(0))


def _set(key: str, f: Callable) -> Callable:  # noqa: ANN001
    def t(p: Parameters, spec) -> None:  # noqa: ANN001
        p[key] = f(p[key], spec)

    return t


def _diag_first(v: fmpq) -> Callable:
    def f(P: np.ndarray, spec) -> np.ndarray:  # noqa: ANN001
        Q2 = P.copy()
        Q2[0, 0] = v
        return Q2

    return f


TAMPERS: list[tuple[str, str, Callable, set[str]]] = [
    # without iss_gain: the ISS block contains the decay matrix (its edge breaks μ too)
    ("decay-lmi", "noiss", lambda p, s: _tamper_decay(p, s, "P", "lambda"), {"decay-lmi"}),
    (
        "decay-lmi_best",
        "sec5",
        lambda p, s: _tamper_decay(p, s, "P_best", "lambda_best"),
        {"decay-lmi_best"},
    ),
    ("decay-lmi by lambda", "best", _tamper_rate_edge, {"decay-lmi"}),
    ("P-positive-definite", "cont", _set("P", _diag_first(fmpq(1, 100))), {"P-positive-definite"}),
    (
        "P_best-positive-definite",
        "cont",
        _set("P_best", _diag_first(fmpq(1, 100))),
        {"P_best-positive-definite"},
    ),
    (
        "bracket end feasible",
        "sec5",
        _set("lambda_bracket", lambda v, s: v + EPS),
        {"lambda_best-bracket"},
    ),
    (
        "bracket too wide",
        "sec5",
        _set(
            "lambda_bracket",
            lambda v, s: Q(s.options.rate_tol) * -1 + EPS * -1 + fmpq(9501, 10000),
        ),
        {"lambda_best-bracket"},
    ),
    (
        "bracket kind",
        "sec5",
        _set("lambda_bracket_kind", lambda v, s: "not-certifiable"),
        {"lambda_best-bracket"},
    ),
    (
        "best worse than asked",
        "wide",
        _set("lambda_best", lambda v, s: fmpq(955, 1000) + EPS),
        {"lambda_best-bracket"},
    ),
    (
        "alpha bracket end feasible",
        "cont",
        _set("alpha_bracket", lambda v, s: fmpq(1) - EPS),
        {"alpha_best-bracket"},
    ),
    ("iss-gain", "sec5", _tamper_mu_edge, {"iss-gain"}),
    # an asymmetric P (2⁻⁶⁰ on one off-diagonal entry): V = eᵀPe needs P = Pᵀ; the decay and
    # ISS claims were recomputed as certified (lyapunov review)
    (
        "asymmetric P",
        "sec5",
        _set("P", lambda P, s: P + qmat([[0, EPS], [0, 0]])),
        {"P-positive-definite", "decay-lmi", "iss-gain"},
    ),
    (
        "asymmetric P_best",
        "cont",
        _set("P_best", lambda P, s: P + qmat([[0, 0], [EPS, 0]])),
        {"P_best-positive-definite", "decay-lmi_best"},
    ),
    (
        "L-matches-spec",
        "sec5",
        _set("L", lambda L, s: L + qmat([[EPS], [0]])),
        {"L-matches-spec"},
    ),
    ("lambda-matches-spec", "sec5", _set("lambda", lambda v, s: v + EPS), {"lambda-matches-spec"}),
    ("alpha-matches-spec", "cont", _set("alpha", lambda v, s: v + EPS), {"alpha-matches-spec"}),
    (
        "decay-lmi continuous",
        "cont",
        lambda p, s: _tamper_decay(p, s, "P", "alpha", row=1),
        {"decay-lmi"},
    ),
    # far off: the checks must use the spec's rate, not the report's
    (
        "lambda-matches-spec far",
        "sec5",
        _set("lambda", lambda v, s: fmpq(1, 2)),
        {"lambda-matches-spec"},
    ),
    # no asked rate: P = P_best and λ = λ_best share one exact check; a P tampered alone
    # must still fail alone
    (
        "decay-lmi, P = P_best shared",
        "best",
        lambda p, s: _tamper_decay(p, s, "P", "lambda"),
        {"decay-lmi"},
    ),
    (
        "decay-lmi_best, P = P_best shared",
        "best",
        lambda p, s: _tamper_decay(p, s, "P_best", "lambda_best"),
        {"decay-lmi_best"},
    ),
    # zero width: the end equals the certified rate (feasible), so only the (0, rate_tol]
    # width check catches it (kills the `0 < width` → `0 <= width` mutant, docs/mutation.md)
    (
        "bracket of zero width",
        "sec5",
        lambda p, s: (
            p.__setitem__("lambda_bracket_kind", "not-certifiable"),
            p.__setitem__("lambda_bracket", Q(p["lambda_best"])),
        ),
        {"lambda_best-bracket"},
    ),
    (
        "bracket on the wrong side",
        "sec5",
        lambda p, s: (
            p.__setitem__("lambda_bracket_kind", "not-certifiable"),
            p.__setitem__("lambda_bracket", Q(p["lambda_best"]) + EPS),
        ),
        {"lambda_best-bracket"},
    ),
]


def _case_spec(which: str, tmp_path: Path) -> Path:
    if which == "sec5":
        return SEC5
    text = {
        "noiss": SEC5.read_text().replace("iss_gain = true", "iss_gain = false"),
        "best": SEC5.read_text()
        .replace("lambda = 0.955\n", "")
        .replace("iss_gain = true", "iss_gain = false"),
        "wide": SEC5.read_text().replace("rate_tol = 0.0001", "rate_tol = 0.1"),
        "cont": CONT,
    }[which]
    path = tmp_path / f"{which}.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("name", "which", "tamper", "expected"), TAMPERS, ids=[t[0] for t in TAMPERS]
)
def test_tamper_fails_exactly_that_claim(
    name: str, which: str, tamper: Callable, expected: set[str], tmp_path: Path
) -> None:
    path = _case_spec(which, tmp_path)
    rep = api.design(path)
    assert rep.exit_code() == 0
    assert api.verify(rep).exit_code() == 0  # untampered: verifies (statements deterministic)
    spec = api.load_spec(path)
    tamper(rep.parameters, spec)
    failed = {c.id for c in api.certify(spec, rep.parameters) if not c.ok}
    assert failed == expected
    # the same report through the CLI: exit 1 and the recomputed claim failed
    out = tmp_path / "tampered.json"
    out.write_text(rep.to_json(), encoding="utf-8")
    res = runner.invoke(app, ["verify", str(out), "--format", "json"])
    assert res.exit_code == 1
    fresh = {c["id"]: c["status"] for c in json.loads(res.output)["claims"]}
    assert all(fresh.get(i) == "failed" for i in expected)


def test_missing_mu_fails_when_the_spec_asks_for_it() -> None:
    rep = api.design(SEC5)
    p = Parameters({k: v for k, v in rep.parameters.items() if k != "mu"})
    failed = {c.id for c in api.certify(api.load_spec(SEC5), p) if not c.ok}
    assert failed == {"mu-present"}


def _spec(A, C, L, extra=""):
    return load_spec_text(_designed(A, C, extra=f"L = {_fmt(L)}\n{extra}\n"), "prop.toml")


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(2, 4), st.integers(0, 2**31 - 1), st.floats(0.05, 0.9))
def test_random_schur_error_dynamics_certify(n: int, seed: int, radius: float):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    C = rng.standard_normal((1, n))
    # choose L = 0 and scale A so that A − LC = A has the given spectral radius
    A *= radius / max(np.abs(np.linalg.eigvals(A)).max(), 1e-9)
    L = np.zeros((n, 1))
    rep = api.design(_spec(A, C, L))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    rho = np.abs(np.linalg.eigvals(_spec(A, C, L).system.A.f)).max()
    assert float(rep.parameters.float("lambda_best")) >= rho - 1e-12


@settings(max_examples=15, deadline=None)
@given(st.integers(2, 4), st.integers(0, 2**31 - 1), st.floats(1.001, 3.0))
def test_unstable_error_dynamics_exit_1(n: int, seed: int, radius: float):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A *= radius / np.abs(np.linalg.eigvals(A)).max()
    with pytest.raises(InfeasibleError) as ei:
        api.design(_spec(A, np.ones((1, n)), np.zeros((n, 1))))
    assert ei.value.exit_code == 1 and "not Schur" in ei.value.message


def test_requested_rate_below_spectral_radius_is_infeasible():
    A = np.array([[0.0, 1.0], [1.0, 0.0]])
    with pytest.raises(InfeasibleError, match="spectral radius"):
        api.design(_spec(A, np.array([[1.0, 0.0]]), np.array([[-1.87], [1.874]]), "lambda = 0.94"))


def test_designed_gain_discrete_and_undetectable():
    text = _designed("[[1.1, 1], [0, 0.9]]", "[[1, 0]]", extra="lambda = 0.5\n")
    rep = api.design(load_spec_text(text))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    L = rep.parameters.float("L")
    assert (
        np.abs(np.linalg.eigvals(np.array([[1.1, 1], [0, 0.9]]) - L @ np.array([[1.0, 0]]))).max()
        < 0.5
    )
    # (C, A) not detectable: the unobservable mode 1.2 is unstable
    bad = text.replace("A = [[1.1, 1], [0, 0.9]]", "A = [[0.5, 0], [0, 1.2]]").replace(
        "lambda = 0.5\n", ""
    )
    with pytest.raises(InfeasibleError, match="detectable"):
        api.design(load_spec_text(bad))


def test_continuous_given_gain_and_iss():
    text = _designed(
        "[[0, 1], [-2, -0.1]]",
        "[[1, 0]]",
        "continuous",
        "L = [3, 2]\nalpha = 0.5\niss_gain = true\n",
    )
    rep = api.design(load_spec_text(text))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    eig = np.linalg.eigvals(
        np.array([[0, 1], [-2, -0.1]]) - np.array([[3.0], [2.0]]) @ np.array([[1.0, 0]])
    )
    assert float(rep.parameters.float("alpha_best")) <= -eig.real.max() + 1e-12
    assert float(rep.parameters.float("alpha_best")) >= -eig.real.max() - 2e-4


def test_verify_catches_tampered_P():
    A = np.array([[0.0, 1.0], [1.0, 0.0]])
    rep = api.design(
        _spec(A, np.array([[1.0, 0.0]]), np.array([[-1.87], [1.874]]), "lambda = 0.955")
    )
    P = rep.parameters["P"].copy()
    P[0, 0] = P[0, 0] / 2  # no longer a certificate
    rep.parameters["P"] = P
    ver = api.verify(rep)
    assert ver.exit_code() == 1
    assert any(c.id == "decay-lmi" and c.status == ClaimStatus.FAILED for c in ver.claims)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(2, 4), st.integers(0, 2**31 - 1), st.sampled_from(["discrete", "continuous"]))
def test_designed_gain_random_observable_systems(n: int, seed: int, time: str):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n)) * 1.2 / np.sqrt(n)
    C = rng.standard_normal((1, n))
    text = _designed(A, C, time)
    rep = api.design(load_spec_text(text))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    L = rep.parameters.float("L")
    eig = np.linalg.eigvals(A - L @ C)
    if time == "discrete":
        assert np.abs(eig).max() <= float(rep.parameters.float("lambda")) + 1e-9
    else:
        assert -eig.real.max() >= float(rep.parameters.float("alpha")) - 1e-9


def test_designed_gain_exact_detectability_reasons() -> None:
    """(C, A) with the unobservable mode 0.9: λ = 0.8 is proved impossible for every L (exit 1,
    naming the mode); λ = 0.95 designs and certifies; continuous, unstable unobservable mode 1/2:
    not detectable (exact test)."""
    base = _designed("[[0.5, 0], [0, 0.9]]", "[[1, 0]]")
    with pytest.raises(InfeasibleError, match="unobservable mode") as ei:
        api.design(load_spec_text(base + "lambda = 0.8\n"))
    assert ei.value.exit_code == 1
    rep = api.design(load_spec_text(base + "lambda = 0.95\n"))
    assert rep.exit_code() == 0
    assert rep.parameters["lambda_best"] <= fmpq(95, 100)
    cont = base.replace('"discrete"', '"continuous"').replace(
        "[[0.5, 0], [0, 0.9]]", "[[-1, 0], [0, 0.5]]"
    )
    with pytest.raises(InfeasibleError, match="not detectable"):
        api.design(load_spec_text(cont))


def test_asked_rate_feasible_but_not_certifiable_is_inconclusive(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """λ = 0.9500000001 > ρ = 0.95: feasible (exact test) but the 40-bit P fails: the
    unrounded float P or the high-precision P certifies it; without those fallbacks, exit 4
    naming both causes."""
    from obsdesign import lyap

    text = SEC5.read_text().replace("lambda = 0.955", "lambda = 0.9500000001")
    assert api.design(load_spec_text(text, "x.toml")).exit_code() == 0
    monkeypatch.setattr(lyap, "_certified_P_hp", lambda *a: None)
    with pytest.raises(InconclusiveError, match="feasible.*too close.*badly conditioned") as ei:
        api.design(load_spec_text(text, "x.toml"))
    assert ei.value.exit_code == 4
    monkeypatch.undo()
    with pytest.raises(InfeasibleError, match="exact Schur–Cohn test"):
        api.design(load_spec_text(SEC5.read_text().replace("lambda = 0.955", "lambda = 0.95")))


# -- issue 12 item 1: the gain designs (riccati default, place, lmi) ------------------------
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.integers(1, 10),
    st.integers(0, 2),
    st.integers(0, 2**31 - 1),
    st.sampled_from(["discrete", "continuous"]),
)
def test_riccati_path_certifies_random_detectable_systems(
    m: int, k: int, seed: int, time: str
) -> None:
    """Random detectable (C, A), n = m + k ≤ 12: an observable m-block and k stable modes the
    output never sees (A = [[A₁, 0], [A₂₁, A₂]], C = [C₁, 0]). The default (Riccati) design
    certifies every claim, verifies, and reports its path."""
    rng = np.random.default_rng(seed)
    n = m + k
    A = np.zeros((n, n))
    A[:m, :m] = rng.standard_normal((m, m)) * 1.3 / np.sqrt(m)
    A[m:, :m] = rng.standard_normal((k, m))
    if k:
        A2 = rng.standard_normal((k, k))
        if time == "discrete":
            A2 *= 0.8 / max(np.abs(np.linalg.eigvals(A2)).max(), 1e-9)
        else:
            A2 -= (np.linalg.eigvals(A2).real.max() + 0.5) * np.eye(k)
        A[m:, m:] = A2
    C = np.zeros((max(1, m // 3), n))
    C[:, :m] = rng.standard_normal((C.shape[0], m))
    rep = api.design(load_spec_text(_designed(A, C, time), "prop.toml"))
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    assert rep.solver["gain_design"] == "riccati"
    assert api.verify(rep).exit_code() == 0
    L = rep.parameters.float("L")
    eig = np.linalg.eigvals(A - L @ C)
    name = "lambda" if time == "discrete" else "alpha"
    lam = float(rep.parameters.float(f"{name}_best"))
    if time == "discrete":
        assert np.abs(eig).max() < lam <= np.abs(eig).max() + 1e-4 + 1e-9
    else:
        assert -eig.real.max() - 1e-4 - 1e-9 <= lam < -eig.real.max()


A_UO = np.array([[1.1, 1.0], [0.0, 0.9]])
C_UO = np.array([[1.0, 0.0]])


def test_design_modes_report_their_path() -> None:
    """riccati (default; an asked λ = 0.5 shifts the equation; the doubling solver), place (default and given
    poles), lmi (bracketed bisection, each rate solved once): each certifies and names its
    path in the solver result."""
    rep = api.design(load_spec_text(_designed(A_UO, C_UO, extra="lambda = 0.5\n")))
    assert rep.exit_code() == 0 and rep.solver["gain_design"] == "riccati"
    assert "shifted to the rate 0.49" in rep.solver["message"]
    assert rep.solver["name"] == "structure-preserving doubling (numpy)"  # discrete: SDA
    rep = api.design(load_spec_text(_designed(A_UO, C_UO, extra='design = "place"\n')))
    assert rep.exit_code() == 0 and rep.solver["gain_design"] == "place"
    eig = np.sort(np.linalg.eigvals(A_UO - rep.parameters.float("L") @ C_UO).real)
    assert np.allclose(eig, [0.2, 0.4], atol=1e-9)  # default poles 0.2 + 0.4·i/n
    text = _designed(A_UO, C_UO, extra='design = "place"\npoles = [0.1, -0.3]\n')
    rep = api.design(load_spec_text(text))
    eig = np.sort(np.linalg.eigvals(A_UO - rep.parameters.float("L") @ C_UO).real)
    assert np.allclose(eig, [-0.3, 0.1], atol=1e-9)
    rep = api.design(load_spec_text(_designed(A_UO, C_UO, extra='design = "lmi"\n')))
    assert rep.exit_code() == 0 and rep.solver["gain_design"] == "lmi"
    assert rep.solver["lmi_solves"] <= 16
    rep = api.design(SEC5)
    assert rep.solver["gain_design"] == "given"


#: a badly conditioned plant (found by the spec fuzzer): ρ(A) ≈ 2000, one output; the float
#: Riccati solution (scipy's QZ; the doubling refuses it) gives an L with ρ(A − LC) ≈ 34
BAD_A = np.array([[-2104.0, -581.0, 0.0], [1189.0, -1014.0, 667.0], [795.0, -699.0, -188.0]])
BAD_C = np.array([[1.8, 1.7, 0.9]])


def test_a_badly_conditioned_plant_takes_the_high_precision_riccati() -> None:
    """The float Riccati gain of BAD_A is not Schur; the doubling in 128-bit arithmetic gives
    one that is, rounded to 40 bits: certified, verified, the path named."""
    rep = api.design(load_spec_text(_designed(BAD_A, BAD_C)))
    assert rep.exit_code() == 0
    assert rep.solver["name"] == "structure-preserving doubling at 128 bits (python-flint arb_mat)"
    assert float(rep.parameters.float("lambda_best")) < 0.2
    assert api.verify(rep).exit_code() == 0


def test_a_huge_spectral_radius_certifies_through_the_high_precision_spectrum(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The 5-state plant of tests/data (ρ(A) ≈ 6000, one output): the 320-bit Riccati gain
    (rounded to 64 bits) gives an exactly Schur A − LC of radius 0.6466 whose float
    eigenvalues say 4.7 (‖A − LC‖ ≈ 2·10⁴, strongly non-normal). The spectral guide takes
    the exact characteristic polynomial's roots (python-flint), so the high-precision Lyapunov P is tried at the right rates:
    certified, the bracket's infeasible end proved, verified. The note names the guide.
    With the high-precision spectrum switched off the same design is exit 4 (the float guide
    puts every rate below 4.7 on the infeasible side)."""
    from obsdesign import spectrum

    path = Path(__file__).parent / "data" / "lyapunov-rho-6000-5state.toml"
    rep = api.design(load_spec_text(path.read_text(), str(path)))
    assert rep.exit_code() == 0
    lam = float(rep.parameters.float("lambda_best"))
    assert 0.6465 < lam < 0.6468
    assert abs(float(rep.parameters.float("spectral_radius")) - 0.646557) < 1e-6
    assert any("(roots of the exact characteristic polynomial)" in n for n in rep.notes)
    assert api.verify(rep).exit_code() == 0
    monkeypatch.setattr(spectrum, "HP_MAX_N", 0)
    with pytest.raises(InconclusiveError, match="the designed gain fails") as ei:
        api.design(load_spec_text(path.read_text(), str(path)))
    assert ei.value.exit_code == 4


def test_a_sensitive_closed_loop_keeps_more_bits_of_the_gain() -> None:
    """The 8-state plant of tests/data (ρ(A) ≈ 87, one output): the 128-bit doubling converges
    to a wrong X, the 320-bit one to a gain that is unstable rounded to 40 bits; rounded to 64
    bits it certifies, and verify agrees (the report's exact L has 64 significant bits).
    Pole placement on the same plant fails (exit 4, not 1: some L succeeds)."""
    from flint import fmpq

    from obsdesign.errors import InconclusiveError

    path = Path(__file__).parent / "data" / "lyapunov-ill-conditioned-8state.toml"
    rep = api.design(load_spec_text(path.read_text(), str(path)))
    assert rep.exit_code() == 0
    assert rep.solver["name"] == "structure-preserving doubling at 320 bits (python-flint arb_mat)"
    assert any("certified with L rounded to 64 bits" in n for n in rep.notes)
    L = rep.parameters["L"]
    assert max(abs(int(fmpq(v).p)).bit_length() for v in L.ravel()) > 53  # beyond a double
    assert api.verify(rep).exit_code() == 0
    text = "".join(
        line.replace('key = "lyapunov"', 'key = "lyapunov"\ndesign = "place"')
        for line in path.read_text().splitlines(keepends=True)
        if not line.startswith("riccati_Q")
    )
    with pytest.raises(InconclusiveError, match="pole placement") as ei:
        api.design(load_spec_text(text, str(path)))
    assert ei.value.exit_code == 4 and "the designed gain fails" in ei.value.message


def test_the_error_report_of_a_failed_designed_gain_holds_that_gain(tmp_path: Path) -> None:
    """Pole placement on the ill-conditioned 8-state plant fails (exit 4): the error report
    at -o held no L, so a user could not give it back at another rate (lyapunov trial,
    session 38). It now holds the L tried, as "not verified", with a note; verify still
    reports the error (exit 4), and simulate and the observer export refuse it. Given back
    in the spec, that L is checked (exit 1: A − LC is not Schur, proved exactly)."""
    from obsdesign.errors import InputError
    from obsdesign.report.model import Report

    path = Path(__file__).parent / "data" / "lyapunov-ill-conditioned-8state.toml"
    text = "".join(
        line.replace('key = "lyapunov"', 'key = "lyapunov"\ndesign = "place"')
        for line in path.read_text().splitlines(keepends=True)
        if not line.startswith("riccati_Q")
    )
    spec = tmp_path / "place.toml"
    spec.write_text(text)
    out = tmp_path / "r.json"
    res = CliRunner().invoke(app, ["design", str(spec), "-o", str(out)])
    assert res.exit_code == 4
    assert "its parameters: L tried, not certified" in res.output
    d = json.loads(out.read_text())
    assert d["verdict"] == "error" and d["error"]["exit_code"] == 4
    assert np.asarray(d["parameters"]["L"], dtype=float).shape == (8, 1)
    assert any("NOT certified (L)" in n and "float values are exact" in n for n in d["notes"])
    # a value that is not a double: the note says the floats are rounded (lyapunov trial,
    # session 40: the exact p/q strings are not spec input)
    third = api.error_report(
        api.load_spec_text(text, "p.toml"),
        4,
        "x",
        Parameters({"L": np.array([[fmpq(1, 3)]] * 8, dtype=object)}),
    )
    assert "float values are rounded" in third.notes[0]
    ver = api.verify(out)
    assert ver.exit_code() == 4 and ver.unverified == ["L"]
    with pytest.raises(InputError, match="no observer"):
        Report.load(out)[0].observer_statespace()
    L = ", ".join(f"[{float(v)!r}]" for v in np.asarray(d["parameters"]["L"]).ravel())
    given = text.replace('design = "place"', f"L = [{L}]")
    with pytest.raises(InfeasibleError, match="the given L does not stabilize the error"):
        api.design(load_spec_text(given, "given.toml"))  # the user's L: exit 1, not 4


def test_no_float_riccati_gain_takes_the_high_precision_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The 4-state plant of tests/data: no float solver gives a gain; the 128-bit doubling
    does and λ = 0.3 certifies. With the high-precision path off, the design is exit 4 naming
    the Riccati equation (not exit 1)."""
    from obsdesign import riccati
    from obsdesign.errors import InconclusiveError

    path = Path(__file__).parent / "data" / "lyapunov-no-float-riccati-4state.toml"
    rep = api.design(load_spec_text(path.read_text(), str(path)))
    assert rep.exit_code() == 0
    assert rep.solver["name"] == "structure-preserving doubling at 128 bits (python-flint arb_mat)"
    assert api.verify(rep).exit_code() == 0
    monkeypatch.setattr(riccati, "HP_MAX_N", 0)
    with pytest.raises(InconclusiveError, match="the Riccati equation gave no gain") as ei:
        api.design(load_spec_text(path.read_text(), str(path)))
    assert ei.value.exit_code == 4
    # the message says what the high-precision retry did (it read as if only floats ran)
    assert str(ei.value).endswith(
        "the high-precision Riccati retry runs up to 0 states (n = 4); give L, or try "
        'design = "lmi" or other weights (riccati_Q, riccati_R)'
    )
    monkeypatch.setattr(riccati, "HP_MAX_N", 24)
    monkeypatch.setattr(riccati, "HP_PRECISIONS", (24,))  # too coarse to give a good gain
    with pytest.raises(InconclusiveError, match="the Riccati equation gave no gain") as ei:
        api.design(load_spec_text(path.read_text(), str(path)))
    assert "high-precision Riccati retry found no gain that certifies either; give L" in str(
        ei.value
    )


def test_an_extreme_rate_is_named_as_the_reason_the_riccati_gain_failed() -> None:
    """λ = 1e-300 asked of a 2-state plant was exit 4 blaming the Riccati solver ("too far
    from generalized Schur form") and suggesting other weights (lyapunov review 43): the
    message names the rate's scaling of A as the reason and what to try instead; a rate
    the float solve handles (λ = 1e-3) still designs."""
    from obsdesign.errors import InconclusiveError
    from obsdesign.methods.lyapunov.design import _extreme_rate

    text = (
        '[system]\ntime = "discrete"\nA = [[0, 1], [1, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nlambda = {lam}\n'
    )
    with pytest.raises(InconclusiveError, match="the Riccati equation gave no gain") as ei:
        api.design(load_spec_text(text.format(lam="1e-300"), "x.toml"))
    msg = str(ei.value)
    assert "the rate λ = 1e-300 scales A by 1/λ (entries near 1e+300)" in msg, msg
    assert 'try design = "place"' in msg and "other weights" not in msg, msg
    assert api.design(load_spec_text(text.format(lam="1e-3"), "x.toml")).exit_code() == 0
    A = np.array([[0.0, 1.0], [1.0, 0.0]])
    assert _extreme_rate(A, True, 1.01e-100) == "" and _extreme_rate(A, True, 1e-100) != ""
    assert (
        _extreme_rate(A, True, None) == "" and _extreme_rate(np.zeros((2, 2)), True, 1e-300) == ""
    )
    assert _extreme_rate(A, False, 1e99) == "" and "shifts A by 1e+100·I" in _extreme_rate(
        A, False, -1e100
    )


@pytest.mark.parametrize(
    ("man", "exp", "bits", "want"),
    [
        (0b1011, 0, 3, 12),  # 11 → 12 (half up to even: 101|1 → 110)
        (0b1001, 0, 3, 8),  # 9 → 8 (half to even: 100|1 → 100)
        (0b1101, -2, 3, 3),  # 13/4 = 3.25, a tie: 110|1 → 110 (even), ·2⁻¹ = 3
        (0b11011, -3, 3, fmpq(7, 2)),  # 27/8 = 3.375 above the tie: 110|11 → 111, ·2⁻¹
        (-0b1011, 0, 3, -12),  # sign symmetric
        (-0b1001, 0, 3, -8),
        (5, 10, 8, 5 * 1024),  # fewer bits than asked: unchanged
        (0b10111, 0, 4, 24),  # above half: up
    ],
)
def test_round_bits(man: int, exp: int, bits: int, want: object) -> None:
    """_round_bits rounds man·2^exp half-to-even to the asked significant bits, exactly."""
    from flint import fmpq

    from obsdesign.methods.lyapunov.design import _round_bits

    expected = want if isinstance(want, fmpq) else fmpq(want)
    assert _round_bits(man, exp, bits) == expected


def test_a_designed_gain_that_fails_is_inconclusive_not_infeasible(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """(C, A) observable, so some L makes A − LC Schur: a designed L that does not (here the
    float Riccati gain of BAD_A, the high-precision solve switched off) is the design's
    failure (exit 4, naming the path), not an infeasible problem (exit 1). The same plant with
    a given non-stabilizing L stays infeasible (exit 1)."""
    from obsdesign import riccati
    from obsdesign.errors import InconclusiveError

    monkeypatch.setattr(riccati, "HP_MAX_N", 0)
    with pytest.raises(InconclusiveError) as ei:
        api.design(load_spec_text(_designed(BAD_A, BAD_C)))
    msg = ei.value.message
    assert ei.value.exit_code == 4
    assert "the designed gain fails: A − LC is not Schur" in msg
    assert "Riccati" in msg and "(C, A) is detectable, proved exactly" in msg
    with pytest.raises(InconclusiveError, match="meet the rate"):
        api.design(load_spec_text(_designed(BAD_A, BAD_C, extra="lambda = 0.5\n")))
    with pytest.raises(InfeasibleError) as ei:
        api.design(_spec(BAD_A, BAD_C, np.zeros((3, 1))))
    assert ei.value.exit_code == 1 and "not Schur" in ei.value.message


def test_place_needs_observability() -> None:
    """An unobservable (detectable) plant cannot have its poles placed: decided exactly, so
    exit 2 naming [method.design] (it was exit 4); the default Riccati design works."""
    from obsdesign.errors import SpecError

    A = np.array([[0.5, 0.0], [0.0, 0.9]])
    with pytest.raises(
        SpecError, match=r"\[method\.design\] 'place' needs \(C, A\) observable"
    ) as ei:
        api.design(load_spec_text(_designed(A, C_UO, extra='design = "place"\n')))
    assert ei.value.exit_code == 2
    rep = api.design(load_spec_text(_designed(A, C_UO)))  # detectable: riccati works
    assert rep.exit_code() == 0
    # not detectable: no gain of any design exists, and that verdict (exit 1) comes first
    A_nd = np.array([[0.5, 0.0], [0.0, 1.5]])
    for design in ("place", "riccati", "lmi"):
        with pytest.raises(InfeasibleError, match="is not detectable") as ei:
            api.design(load_spec_text(_designed(A_nd, C_UO, extra=f'design = "{design}"\n')))
        assert ei.value.exit_code == 1


@pytest.mark.parametrize(
    ("extra", "key", "why"),
    [
        ('L = [1, 1]\ndesign = "riccati"\n', "design", "designs L"),
        ("poles = [0.1, 0.2]\n", "poles", "not used by design = 'riccati'"),
        ('design = "place"\nriccati_Q = [[1, 0], [0, 1]]\n', "riccati_Q", "not used"),
        ('design = "place"\npoles = [0.1, 1.0]\n', "poles", "modulus < 1"),
        ("riccati_Q = [[1, 2], [0, 1]]\n", "riccati_Q", "symmetric"),
        ('design = "magic"\n', "design", "one of"),
        # lyapunov review: accepted and ignored, or exit 4, before
        ("L = [1, 1]\nrate_cap = 5\n", "rate_cap", "designs L"),
        ('design = "lmi"\nrate_cap = 5\n', "rate_cap", "continuous-time LMI gain design only"),
        ("rate_cap = 5\n", "rate_cap", "continuous-time LMI gain design only"),
        ("riccati_R = [[-1]]\n", "riccati_R", "positive definite"),
        ("riccati_R = [[0]]\n", "riccati_R", "positive definite"),
        ("riccati_Q = [[1, 0], [0, -1e-30]]\n", "riccati_Q", "positive semidefinite"),
        ('design = "place"\npoles = [0.1, 0.1]\n', "poles", "more than rank(C) = 1"),
    ],
)
def test_design_option_errors(extra: str, key: str, why: str) -> None:
    from obsdesign.errors import SpecError

    with pytest.raises(SpecError, match=re.escape(why)) as ei:
        load_spec_text(_designed(A_UO, C_UO, extra=extra))
    assert key in str(ei.value)


@pytest.mark.parametrize(
    ("time", "rate", "slow", "fast"),
    [
        ("discrete", "lambda = 0.5", "[0.1, -0.5]", "[0.1, -0.4999999]"),
        ("continuous", "alpha = 2", "[-3, -2]", "[-3, -2.0000001]"),
    ],
)
def test_place_poles_the_rate_excludes_are_refused(time, rate, slow, fast) -> None:
    """A − LC placed at the given poles has them as eigenvalues, so a pole with |z| ≥ λ
    (Re z ≥ −α) can never meet the asked rate: exit 2 naming [method.poles] (before: exit 4
    blaming the plant's conditioning; random-spec fuzzer). The boundary pole is refused, one
    just inside designs and certifies."""
    from obsdesign.errors import SpecError

    A = A_UO if time == "discrete" else np.array([[1.3, 0.5], [-0.3, 0.8]])
    extra = f'design = "place"\n{rate}\npoles = '
    with pytest.raises(SpecError, match=r"\[method\.poles\] pole .* cannot meet") as ei:
        load_spec_text(_designed(A, C_UO, time, extra + slow + "\n"))
    assert ei.value.exit_code == 2
    # the way out is a slower rate: a larger λ, a smaller α (it said "a smaller lambda" in
    # discrete time; soundness trial, session 32)
    way = "larger lambda" if time == "discrete" else "smaller alpha"
    assert str(ei.value).endswith(f"give faster poles or a {way}")
    rep = api.design(load_spec_text(_designed(A, C_UO, time, extra + fast + "\n")))
    assert rep.exit_code() == 0


def test_design_option_boundaries_are_accepted() -> None:
    """The smallest admissible values next to the refused ones: a PSD (singular) Q, an R of
    10⁻³⁰, distinct poles, rate_cap with the continuous LMI design."""
    for extra in (
        "riccati_Q = [[1, 0], [0, 0]]\n",
        "riccati_R = [[1e-30]]\n",
        'design = "place"\npoles = [0.1, 0.1000001]\n',
    ):
        load_spec_text(_designed(A_UO, C_UO, extra=extra))
    load_spec_text(
        _designed(
            np.array([[1.3, 0.5], [-0.3, 0.8]]),
            C_UO,
            "continuous",
            'design = "lmi"\nrate_cap = 5\n',
        )
    )


def test_place_with_a_repeated_output_row() -> None:
    """C = [[1, 0], [1, 0]] (rank 1, (C, A) observable): scipy refused the placement (exit 4
    — lyapunov review); it now runs on the independent rows and L's other column is 0."""
    A = np.array([[0.0, 1.0], [2.0, 3.0]])
    C = np.array([[1.0, 0.0], [1.0, 0.0]])
    rep = api.design(
        load_spec_text(_designed(A, C, extra='design = "place"\npoles = [-0.12, -0.02]\n'))
    )
    assert rep.exit_code() == 0
    L = rep.parameters.float("L")
    assert np.all(L[:, 1] == 0)
    ev = np.sort(np.linalg.eigvals(A - L @ C).real)
    assert np.allclose(ev, [-0.12, -0.02], atol=1e-9)


def test_riccati_weights_change_the_gain() -> None:
    base = api.design(load_spec_text(_designed(A_UO, C_UO)))
    heavy = api.design(load_spec_text(_designed(A_UO, C_UO, extra="riccati_R = [[100]]\n")))
    assert heavy.exit_code() == 0
    assert "riccati_Q / riccati_R" in heavy.solver["message"]
    assert not np.allclose(base.parameters.float("L"), heavy.parameters.float("L"))


def test_simulate_runs_option(tmp_path: Path) -> None:
    """--runs N / --option runs=N: N batched Monte Carlo runs with quantiles; a bad value is
    exit 2."""
    res = api.simulate(SEC5, options={"runs": "7"})
    assert res.info.get("runs") == 7 and "quantiles" in res.info
    one = api.simulate(SEC5)
    assert "quantiles" not in one.info
    out = runner.invoke(app, ["simulate", str(SEC5), "--runs", "3"])
    assert out.exit_code == 0, out.output
    bad = runner.invoke(app, ["simulate", str(SEC5), "--option", "runs=0"])
    assert bad.exit_code == 2


def test_simulate_runs_and_initial_error_from_the_spec() -> None:
    """[simulate] runs = 6 and initial_error = "E0" (a box of [sets]): six runs, initial errors
    drawn inside the box; an initial_error naming no set is a spec error."""
    from obsdesign.errors import SpecError

    text = SEC5.read_text().replace("[simulate]\n", '[simulate]\nruns = 6\ninitial_error = "E0"\n')
    text += '\n[sets.E0]\ntype = "box"\nlower = [-2, -1]\nupper = [2, 1]\n'
    res = api.simulate(load_spec_text(text, "mc.toml"))
    e0 = res.extra["initial_errors"]
    assert res.info["runs"] == 6 and e0.shape == (6, 2)
    assert np.all(np.abs(e0[:, 0]) <= 2) and np.all(np.abs(e0[:, 1]) <= 1)
    with pytest.raises(SpecError, match="initial_error"):
        load_spec_text(text.replace('initial_error = "E0"', 'initial_error = "F"'), "mc.toml")


def test_initial_error_without_a_run_count_is_one_monte_carlo_run() -> None:
    """As documented (lyapunov.md, spec.md; the docs said otherwise until the session-25
    simulate trial): initial_error without runs is the Monte Carlo study of one run, run 0
    of any N, its initial error drawn from the set (xhat0 not used); without initial_error
    the spec's single scenario starts from xhat0 − x0."""
    text = SEC5.read_text().replace("[simulate]\n", '[simulate]\ninitial_error = "E0"\n')
    text += '\n[sets.E0]\ntype = "box"\nlower = [-0.5, -0.5]\nupper = [0.5, 0.5]\n'
    spec = load_spec_text(text, "mc.toml")
    one = api.simulate(spec)
    assert one.info["runs"] == 1 and one.info["initial_error"] == "E0"
    assert np.all(np.abs(one.extra["initial_errors"]) <= 0.5)  # not xhat0 − x0 = (2, 2)
    three = api.simulate(spec, runs=3)
    assert np.array_equal(one.extra["initial_errors"][0], three.extra["initial_errors"][0])
    assert one.metrics()["final_error_norm"] == three.metrics()["final_error_norm"]
    single = api.simulate(load_spec_text(SEC5.read_text(), "s.toml"))
    assert "runs" not in single.info and np.array_equal(single.e[0], [2, 2])


def test_an_expression_plant_fails_linear_plant_and_still_simulates() -> None:
    """[system] psi makes the plant nonlinear: the decay certificate covers A − LC only, so
    design and verify fail the claim linear-plant (and only it), and simulate still runs the
    observer on the nonlinear plant."""
    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "constrained-redesign-sec5-lyapunov.toml").read_text()
    i = text.index("[system]") + len("[system]\n")
    spec = load_spec_text(text[:i] + 'psi = ["0.001*sin(x1)", "0"]\n' + text[i:], "psi.toml")
    rep = api.design(spec)
    assert [c.id for c in rep.failed] == ["linear-plant"] and rep.exit_code() == 1
    assert "psi" in rep.failed[0].detail
    assert [c.id for c in api.verify(rep).failed] == ["linear-plant"]
    assert np.isfinite(api.simulate(spec, rep).metrics()["final_error_norm"])
    linear = api.design(load_spec_text(text, "lin.toml"))
    assert "linear-plant" not in [c.id for c in linear.claims]


def test_rate_cap_caps_the_gain_design_not_the_reported_rate() -> None:
    """docs/methods/lyapunov.md: rate_cap bounds the LMI bisection that picks L; the best
    certified α of that L may exceed it (the double integrator: α_best ≈ 1.28 > 1; the first
    LMI answer's gain already passes the cap, which ends the search after one solve)."""
    text = (
        '[system]\ntime = "continuous"\nA = [[0, 1], [0, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\ndesign = "lmi"\nrate_cap = 1\n'
    )
    rep = api.design(load_spec_text(text, "cap.toml"))
    assert rep.exit_code() == 0
    assert 1.0 < float(rep.parameters.float("alpha_best")) < 1.5
    assert rep.solver["lmi_solves"] == 1


@pytest.mark.parametrize("tol", ["1e-17", "1e-300"])
def test_rate_tol_below_float_resolution_exit_2(tmp_path: Path, tol: str) -> None:
    """A rate_tol the bisection cannot reach is a spec error naming [method.rate_tol], exit 2,
    no report written (was: a failed bracket claim of the design's own making, exit 1)."""
    spec = tmp_path / "s.toml"
    spec.write_text(_designed("[[0.5, 1], [0, 0.9]]", "[[1, 0]]", extra=f"rate_tol = {tol}\n"))
    out = tmp_path / "r.json"
    res = runner.invoke(app, ["design", str(spec), "-o", str(out)])
    assert res.exit_code == 2, res.output
    assert "[method.rate_tol]" in res.output and "Traceback" not in res.output
    assert not out.exists()
    spec.write_text(_designed("[[0.5, 1], [0, 0.9]]", "[[1, 0]]", extra="rate_tol = 1e-15\n"))
    assert runner.invoke(app, ["design", str(spec), "-o", str(out)]).exit_code == 0


#: a badly scaled 3-state plant (entries up to 5.6·10², lyapunov review): Clarabel finds no
#: LMI gain at any rate, the Riccati gain certifies λ ≈ 0.0099
SCALED = (
    '[system]\ntime = "discrete"\n'
    "A = [[1.6637, 0.052256, 9.4787e-05], [-17.734, 4.0692, 555.38], "
    "[336.33, -5.5198, -57.150]]\nC = [[-1, -1, 2]]\n"
    '[method]\nkey = "lyapunov"\nrate_tol = 1e-10\n'
)


def test_lmi_design_keeps_the_riccati_start_when_no_lmi_answer_beats_it() -> None:
    """design = "lmi" on SCALED: every SDP solve fails, and the design returns the Riccati
    gain that started the bisection, saying so (it was exit 4 "found no gain with λ ≤ 1";
    lyapunov review: 9 of 70 LMI designs were exit 4 where the default design certifies)."""
    rep = api.design(load_spec_text(SCALED + 'design = "lmi"\n'))
    assert rep.exit_code() == 0 and rep.solver["gain_design"] == "lmi"
    assert rep.solver["name"] == "Riccati gain (LMI bisection start)"
    assert "none beat the float rate 0.0099" in rep.solver["message"]
    assert float(rep.parameters.float("lambda_best")) < 0.01
    assert api.verify(rep).exit_code() == 0


def test_lmi_candidate_rates_take_inaccurate_answers_and_refuse_broken_ones() -> None:
    """_candidate_rate: an "optimal_inaccurate" answer proposes L = P⁻¹X with its float rate
    (the rate of the rounded L is certified exactly later); any other status, a missing value
    or a singular P proposes nothing."""
    from obsdesign.methods.lyapunov.design import _candidate_rate

    A, C = np.array([[0.5, 1.0], [0.0, 0.9]]), np.array([[1.0, 0.0]])
    P, L = np.eye(2), np.array([[1.0], [0.5]])
    for status in ("optimal", "optimal_inaccurate"):
        got = _candidate_rate(status, P, P @ L, A, C, True)
        assert got is not None and np.allclose(got[0], L)
        assert got[1] == pytest.approx(np.abs(np.linalg.eigvals(A - L @ C)).max())
    cont = _candidate_rate("optimal", P, P @ L, A - 2 * np.eye(2), C, False)
    assert cont is not None and cont[1] == pytest.approx(
        -np.linalg.eigvals(A - 2 * np.eye(2) - L @ C).real.max()
    )
    assert _candidate_rate("infeasible", P, P @ L, A, C, True) is None
    assert _candidate_rate("optimal", None, P @ L, A, C, True) is None
    assert _candidate_rate("optimal", np.zeros((2, 2)), P @ L, A, C, True) is None


def test_a_failed_lmi_search_falls_back_to_the_riccati_design() -> None:
    """SCALED with an asked rate λ = 0.5 (no Riccati start in the bisection then): the SDP
    solver finds no gain at 2 % slack nor at the rate; the design falls back on the default
    Riccati design and says so (exit 4 before: review 19 found 15 of 167 LMI designs exit 4
    where the default certifies). Also BAD_A without a rate: the float Riccati start is not
    Schur there, the high-precision Riccati gain certifies."""
    rep = api.design(load_spec_text(SCALED + 'lambda = 0.5\ndesign = "lmi"\n'))
    assert rep.exit_code() == 0 and api.verify(rep).exit_code() == 0
    assert rep.solver["gain_design"] == "lmi" and rep.solver["lmi_fallback"] == "riccati"
    assert rep.solver["message"].startswith("LMI found no certified gain; the discrete Riccati")
    assert "the LMI solver found no gain at rate 0.5" in rep.notes[0]
    assert rep.notes[0].endswith("L is the Riccati gain")
    rep = api.design(load_spec_text(_designed(BAD_A, BAD_C, extra='design = "lmi"\n')))
    assert rep.exit_code() == 0 and rep.solver["lmi_fallback"] == "riccati"
    assert "at 128 bits" in rep.solver["name"]


def test_failed_lmi_and_riccati_designs_say_both_failed(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """When the Riccati fallback fails too (here: no Riccati gain at all, patched), the LMI's
    own exit-4 error is raised with the Riccati failure — not its hint "omit design", which
    pointed at the design that had just failed (lyapunov fuzz, session 38)."""
    from obsdesign.methods.lyapunov import design as LD

    def no_gain(*a, **k):  # noqa: ANN002, ANN003, ANN202
        raise np.linalg.LinAlgError("patched")

    monkeypatch.setattr(LD, "riccati_gain", no_gain)
    monkeypatch.setattr(LD, "riccati_gain_hp", lambda *a, **k: None)
    with pytest.raises(InconclusiveError, match="the Riccati design failed too: ") as ei:
        api.design(load_spec_text(SCALED + 'lambda = 0.5\ndesign = "lmi"\n'))
    assert ei.value.exit_code == 4 and "LMI solver found no gain" in ei.value.message
    assert "omit design" not in ei.value.message
    assert "no unobservable mode of (C, A) rules it out" in ei.value.message


def test_rate_cap_with_an_asked_alpha_is_refused() -> None:
    """rate_cap caps the bisection for the best rate, which an asked α skips: alpha = 4 with
    rate_cap = 1 certified α_best = 4.9 and ignored the cap (review 19); exit 2 naming it."""
    from obsdesign.errors import SpecError

    text = (
        '[system]\ntime = "continuous"\nA = [[0, 1], [0, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\ndesign = "lmi"\nrate_cap = 1\n'
    )
    with pytest.raises(SpecError, match=r"\[method.rate_cap\] caps the LMI bisection") as ei:
        load_spec_text(text + "alpha = 4\n", "cap.toml")
    assert ei.value.exit_code == 2
    assert api.design(load_spec_text(text, "cap.toml")).exit_code() == 0


def test_a_continuous_companion_plant_takes_the_high_precision_riccati() -> None:
    """An integer companion plant of order 10, one output, continuous time: scipy and the float
    doubling give no CARE solution ("Failed to find a finite solution", exit 4 with every
    design: review 19); the doubling after the Cayley transform in 128-bit arb_mat gives a
    gain that certifies and verifies."""
    row = "[-3, 9, -1, 9, -2, 0, -9, 7, 4, 6]"
    A = [[int(j == i + 1) for j in range(10)] for i in range(9)]
    text = (
        '[system]\ntime = "continuous"\nA = ['
        + ", ".join(str(r) for r in A)
        + f", {row}]\nC = [[1, 0, 0, 0, 0, 0, 0, 0, 0, 0]]\n"
        '[method]\nkey = "lyapunov"\n'
    )
    rep = api.design(load_spec_text(text, "companion.toml"))
    assert rep.exit_code() == 0, [c.detail for c in rep.failed]
    assert rep.solver["name"] == "structure-preserving doubling at 128 bits (python-flint arb_mat)"
    assert float(rep.parameters.float("alpha_best")) > 0.5
    assert api.verify(rep).exit_code() == 0


# -- mutation review 22 (obsdesign/lyap.py) ---------------------------------------------------
@pytest.mark.parametrize(
    ("name", "which", "tamper", "expected"), TAMPERS, ids=[t[0] for t in TAMPERS]
)
def test_tamper_fails_with_the_designs_memo_at_hand(
    name: str, which: str, tamper: Callable, expected: set[str], tmp_path: Path
) -> None:
    """Every tamper test again, certified on the very spec object the design ran on, so that
    the design's exact verdicts (`ExactMemo`) are at hand: they must be looked up by every
    input of the check, not only by the matrices. Kills `decay_verdict` 6 (the key ("decay",
    rate, margin, time) → None: λ tampered alone past the edge of the decay LMI, P unchanged,
    got the verdict the design recorded for P at its own rate and was certified) and
    `rate_feasibility` 17 (the key ("feasible", rate, time) → None: the bracket's end moved to
    a feasible rate got the design's verdict at another rate, same A − LC)."""
    spec = api.load_spec(_case_spec(which, tmp_path))
    rep = api.design(spec)
    assert rep.exit_code() == 0 and lyap.memo_of(spec) is not None
    assert all(c.ok for c in api.certify(spec, rep.parameters))
    tamper(rep.parameters, spec)
    failed = {c.id for c in api.certify(spec, rep.parameters) if not c.ok}
    assert failed == expected


@pytest.mark.parametrize("time", ["discrete", "continuous"])
def test_a_rate_that_is_not_positive_is_no_decay_rate(time: str) -> None:
    """λ_best = −λ passed the discrete decay LMI (λ² keeps no sign) and the claim was
    certified "with λ_best = −0.9501" through the API (mutation review, session 22). A decay
    claim needs the rate > 0, exactly; the true rate still certifies."""
    A = "[[0.5, 1.0], [0.0, 0.3]]" if time == "discrete" else "[[-1.0, 1.0], [0.0, -2.0]]"
    text = f'[system]\ntime = "{time}"\nA = {A}\nC = [[1.0, 0.0]]\n[method]\nkey = "lyapunov"\n'
    spec = api.load_spec_text(text, "x.toml")
    p = api.design(spec).parameters
    name = "lambda" if time == "discrete" else "alpha"
    ok = {c.id: c for c in api.certify(api.load_spec_text(text, "x.toml"), p)}
    assert ok["decay-lmi_best"].status == ClaimStatus.CERTIFIED
    p[f"{name}_best"] = -p[f"{name}_best"]
    got = {c.id: c for c in api.certify(api.load_spec_text(text, "x.toml"), p)}
    assert got["decay-lmi_best"].status == ClaimStatus.FAILED
    assert "is not positive" in got["decay-lmi_best"].detail


def test_certify_decides_a_gain_beyond_the_float_range() -> None:
    """``certify`` with an exact L = 10⁴⁰⁰ raised OverflowError in ``lyap.mat_float`` (its
    fallback called float() on the entries; mutation review, session 22) instead of failing
    the claims: the float copy is ±inf there and the exact checks decide."""
    from obsdesign.certify.exact import qmat

    text = (
        '[system]\ntime = "discrete"\nA = [[0.5, 1.0], [0.0, 0.3]]\nC = [[1.0, 0.0]]\n'
        '[method]\nkey = "lyapunov"\n'
    )
    p = api.design(api.load_spec_text(text, "x.toml")).parameters
    p["L"] = qmat([[fmpq(10**400)], [0]])
    got = {c.id: c.status for c in api.certify(api.load_spec_text(text, "x.toml"), p)}
    assert got["decay-lmi"] == ClaimStatus.FAILED and got["decay-lmi_best"] == ClaimStatus.FAILED


_GIVEN_L = (
    '[system]\ntime = "discrete"\nA = [[0, 1], [1, 0]]\nC = [[1, 0]]\n'
    '[method]\nkey = "lyapunov"\nL = [-1.87, 1.874]\n'
)


def test_a_not_certifiable_bracket_never_certifies_optimality(tmp_path: Path) -> None:
    """Independent soundness trial (session 23): A − LC has the eigenvalues 0.95 and 0.92, so
    the best rate is 0.95. A report tampered to λ = λ_best = 0.99 (its P still valid there)
    with a bracket end 0.9899 of kind ``not-certifiable`` and verify's own claim list
    verified with "λ_best = 0.99 is best to within 0.0001 … certified": a feasible other end
    proves only that a better rate exists. The claim is now numerical, never certified, and
    says that optimality is not proven; the decay claims at 0.99 stay certified (true)."""
    spec = load_spec_text(_GIVEN_L, "given.toml")
    rep = api.design(spec)
    assert rep.exit_code() == 0 and rep.parameters["lambda_bracket_kind"] == "infeasible"
    # strict: at an eigenvalue of modulus exactly λ a P ≻ 0 may satisfy the non-strict LMI
    (honest,) = [c for c in rep.claims if c.id == "lambda_best-bracket"]
    assert "no P ≻ 0 satisfies the decay LMI strictly at λ = 0.95" in honest.statement
    p = rep.parameters
    for k in ("lambda", "lambda_best"):
        p[k] = fmpq(99, 100)
    p["lambda_bracket"] = fmpq(9899, 10000)
    p["lambda_bracket_kind"] = "not-certifiable"
    claims = {c.id: c for c in api.certify(load_spec_text(_GIVEN_L, "given.toml"), p)}
    br = claims["lambda_best-bracket"]
    assert br.status == ClaimStatus.NUMERICAL and br.ok, br
    assert "λ_best = 0.99 is not proven best to within 0.0001" in br.statement
    assert "is best to within" not in br.statement
    assert "ρ(A − LC) ≈ 0.95" in br.detail
    assert all(c.status == ClaimStatus.CERTIFIED for i, c in claims.items() if i != br.id)
    # the whole tampered report with the recomputed claims: nothing false is certified
    d = rep.to_dict()
    d["claims"] = [c.to_dict() for c in claims.values()]
    out = tmp_path / "t.json"
    out.write_text(json.dumps(d), encoding="utf-8")
    ver = api.verify(out)
    got = {c.id: c.status for c in ver.claims}
    assert got["lambda_best-bracket"] == ClaimStatus.NUMERICAL


def test_the_designs_own_not_certifiable_bracket_is_numerical(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """When no rate below 0.9502 certifies (the rounded P refused there), the search's other end
    is feasible but not certifiable: the design's bracket claim is numerical (exit 0: every
    claim holds, optimality to within rate_tol is not claimed) and the report verifies."""
    real = lyap.certified_P
    below = fmpq(9502, 10000)

    def refusing(A, C, L, discrete, r, *a, **k):  # type: ignore[no-untyped-def]
        return None if Q(r) < below else real(A, C, L, discrete, r, *a, **k)

    monkeypatch.setattr(lyap, "certified_P", refusing)
    rep = api.design(load_spec_text(_GIVEN_L, "given.toml"))
    assert rep.parameters["lambda_bracket_kind"] == "not-certifiable"
    (br,) = [c for c in rep.claims if c.id == "lambda_best-bracket"]
    assert br.status == ClaimStatus.NUMERICAL and rep.exit_code() == 0
    assert any(n.startswith("best certified rate lambda = ") for n in rep.notes), rep.notes
    out = tmp_path / "r.json"
    out.write_text(rep.to_json(), encoding="utf-8")
    assert api.verify(out).exit_code() == 0


_TINY_RATE = """[system]
time = "discrete"
A = [[0, 1], [0, 0]]
C = [[1, 0]]
[method]
key = "lyapunov"
L = [0, 0]
lambda = 1e-300
"""


@pytest.mark.parametrize("flags", [[], ["-q"], ["--format", "md"], ["--format", "json"]])
def test_a_report_with_no_float_view_is_exit_4_in_every_output_mode(tmp_path, flags) -> None:
    """λ = 10⁻³⁰⁰ gives a true certificate with P ≈ 10¹²⁰⁰, beyond a report's float view:
    exit 4 naming P whatever the output mode (it was 3 from the text table's float
    conversion, 4 with -o or --format json, and 0 with -q; unusual-spec trial, session 24);
    since session 42 the message also names the rate and the keys to change."""
    p = tmp_path / "tiny.toml"
    p.write_text(_TINY_RATE)
    with pytest.raises(
        InconclusiveError,
        match=r"certificate P at lambda = 1e-300 .*a smaller \[method\]\.margin .*a larger \[method\]\.lambda",
    ):
        api.design(p)
    res = CliRunner().invoke(app, ["design", str(p), *flags])
    assert res.exit_code == 4, res.output
    assert "float view" in res.output and "Traceback" not in res.output


def test_entries_near_the_float_range_do_not_overflow_the_lyapunov_solution() -> None:
    """A = [[0, 1e150], [0, 0]]: the float Lyapunov solutions have entries near 10³⁰⁷, and
    (X + Xᵀ)/2 overflowed to inf (exit 3 "cannot round a non-finite number" for entries 1e147
    to 1e150; unusual-spec trial, session 24). Now it designs, and verify agrees."""
    text = _TINY_RATE.replace("[[0, 1], [0, 0]]", "[[0, 1e150], [0, 0]]")
    text = text.replace("L = [0, 0]\nlambda = 1e-300\n", "iss_gain = true\n")
    rep = api.design(load_spec_text(text, "big.toml"))
    assert rep.exit_code() == 0
    assert api.verify(rep).exit_code() == 0
    X = np.array([[1e308, 1e308], [1e308, 1e308]])
    assert np.all(np.isfinite(lyap.sym_part(X))) and lyap.sym_part(X)[0, 1] == 1e308


def test_rate_tol_below_the_float_resolution_names_the_rate_with_its_sign() -> None:
    """Continuous time: the refusal of a rate_tol below the float resolution said "near the
    rate -10293.1", the spectral abscissa, where the rate α is +10293.1 (lyapunov trial,
    session 24)."""
    from obsdesign.errors import SpecError

    text = (
        '[system]\ntime = "continuous"\nA = [[-10293.1]]\nC = [[1]]\n'
        '[method]\nkey = "lyapunov"\nL = [0]\nrate_tol = 1e-12\n'
    )
    with pytest.raises(SpecError, match="near the rate 10293.1 "):
        api.design(load_spec_text(text, "rt.toml"))


def test_a_negative_discrete_rate_is_decided_by_the_lmi_it_states() -> None:
    """The decay LMI holds λ² only, so λ < 0 is feasible iff ρ(A − LC) < |λ|. "Infeasible
    (λ ≤ 0)" let verify certify a forged bracket end λ = −0.00004 for A − LC = 0, where P = 1
    satisfies the LMI strictly (lyapunov/impulsive soundness trial, session 28). λ = 0 stays
    infeasible (−(A − LC)ᵀP(A − LC) ≻ 0 has no solution)."""
    from flint import fmpq

    from obsdesign import lyap

    zero = np.array([[fmpq(0)]], dtype=object)
    half = np.array([[fmpq(1, 2)]], dtype=object)
    assert lyap.rate_feasibility(zero, fmpq(-1, 25000), True)[0] is True
    assert lyap.rate_feasibility(zero, fmpq(0), True)[0] is False
    assert lyap.rate_feasibility(half, fmpq(-2, 5), True)[0] is False
    assert lyap.rate_feasibility(half, fmpq(-3, 5), True)[0] is True
    assert lyap.rate_feasibility(half, fmpq(3, 5), True)[0] is True


def test_verify_refuses_a_negative_bracket_end_where_the_lmi_holds() -> None:
    """The forged report of session 28: A − LC = 0, λ_best = 1/20000, bracket end −1/25000
    "infeasible"; the recomputed bracket claim fails (P = 1 satisfies the LMI there)."""
    from obsdesign.report.model import Report

    text = '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[method]\nkey = "lyapunov"\nL = [0.5]\n'
    rep = api.design(api.load_spec_text(text, "deadbeat.toml"))
    assert rep.exit_code() == 0
    d = rep.to_dict()
    for k, q, f in (("lambda_best", "1/20000", 1 / 20000), ("lambda_bracket", "-1/25000", -4e-5)):
        d["parameters"][k] = f
        d["parameters"]["exact"][k] = q
    forged, problems = Report.from_dict(d)
    assert not problems
    ver = api.verify(forged)
    bracket = [c for c in ver.claims if c.id == "lambda_best-bracket"]
    assert bracket and bracket[0].status == ClaimStatus.FAILED, bracket
    assert ver.exit_code() == 1


def test_a_bracket_end_on_the_wrong_side_is_named_so() -> None:
    """A bracket end on the wrong side was refused as "|α_best − α_bracket| = 0.6 is not in
    (0, rate_tol]" with rate_tol = 3 (re-check trial, session 28): the detail names the
    side; a bracket wider than rate_tol names the width."""
    from obsdesign.report.model import Report

    text = '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[method]\nkey = "lyapunov"\nL = [0.25]\n'
    rep = api.design(api.load_spec_text(text, "s.toml"))
    assert rep.exit_code() == 0
    for end, words in (
        ("9/10", "lambda_bracket = 0.9 is not below λ_best"),
        ("1/10", "above rate_tol"),
    ):
        d = rep.to_dict()
        d["parameters"]["lambda_bracket"] = float(Fraction(end))
        d["parameters"]["exact"]["lambda_bracket"] = end
        ver = api.verify(Report.from_dict(d)[0])
        bracket = next(c for c in ver.claims if c.id == "lambda_best-bracket")
        assert (
            bracket.status == ClaimStatus.FAILED and words.replace("lambda", "λ") in bracket.detail
        ), bracket.detail


@pytest.mark.parametrize(
    ("time", "extra", "bd"),
    [
        ("discrete", "L = [-1.87, 1.874]\nlambda = 0.955", "1e150"),
        ("continuous", "L = [2, 2]\nalpha = 0.01", "1e160"),
    ],
)
def test_iss_gain_beyond_the_float_range_is_exit_4(time: str, extra: str, bd: str) -> None:
    """Bd = 1e150 makes μ ≈ 1e311: exit 4 ("beyond the float range"), as the README says for
    a float stage the spec's numbers overflow, not exit 3 "internal failure: cannot round a
    non-finite number" (rendering soundness trial, session 29); Bd = 1e148 certifies."""
    text = (
        f'[system]\ntime = "{time}"\nA = [[0, 1], [1, 0]]\nC = [[1, 0]]\nBd = [[{bd}], [{bd}]]\n'
        f'[method]\nkey = "lyapunov"\n{extra}\niss_gain = true\n'
    )
    with pytest.raises(InconclusiveError, match="beyond the float range") as e:
        api.design(load_spec_text(text, "mu.toml"))
    assert e.value.exit_code == 4
    if time == "discrete":
        ok = api.design(load_spec_text(text.replace(bd, "1e148"), "mu.toml"))
        assert ok.exit_code() == 0
        # μ ≈ 9.96e307 (above half the float range, where G + Gᵀ overflowed: exit 4 for a
        # μ that certifies; re-check trial, session 29)
        ok = api.design(load_spec_text(text.replace(bd, "2.8e148"), "mu.toml"))
        assert ok.exit_code() == 0 and 9e307 < ok.parameters.float("mu") < 1.797e308


def test_riccati_Q_zero_with_an_unstable_plant_certifies() -> None:
    """lyapunov.md said riccati_Q = 0 with an unstable A is still exit 4; A = [[1.5]]
    certifies (outsider trial, session 29): the Riccati gain with Q = 0 mirrors the pole to
    1/1.5, and the certified λ lies just above it."""
    text = (
        '[system]\ntime = "discrete"\nA = [[1.5]]\nC = [[1]]\n'
        '[method]\nkey = "lyapunov"\nriccati_Q = [[0]]\n'
    )
    rep = api.design(load_spec_text(text, "q0.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    pole = abs(Q(3) / 2 - Q(np.asarray(rep.parameters["L"], dtype=object).ravel()[0]))
    best = Q(rep.parameters["lambda_best"])
    assert abs(pole - Q(2) / 3) < fmpq(1, 10**9) and pole < best < Q(2) / 3 + fmpq(1, 1000)


def test_riccati_Q_zero_on_a_rotation_names_the_weights_not_the_conditioning() -> None:
    """Q = 0 on a rotation by 0.6 + 0.8i (|z| = 1) gives the Riccati gain L = 0, as it should
    (a mode that Q does not weight stays where it is): exit 4 blamed "this badly conditioned
    plant" (soundness trial, session 30); it now names the singular riccati_Q. Q = I designs."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0.6, 0.8], [-0.8, 0.6]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nriccati_Q = [[0, 0], [0, 0]]\n'
    )
    with pytest.raises(InconclusiveError, match="singular riccati_Q") as e:
        api.design(load_spec_text(text, "q0.toml"))
    assert "badly conditioned" not in e.value.message
    ok = api.design(load_spec_text(text.replace("[[0, 0], [0, 0]]", "[[1, 0], [0, 1]]"), "q.toml"))
    assert ok.exit_code() == 0


# -- mutation review 30 (docs/mutation.md)


# --- Mutation review 30: lyapunov.designed_gain_failed, the riccati_Q branch (ready to
# append to tests/test_methods_lyapunov.py)


def test_a_failed_gain_under_a_positive_definite_riccati_Q_blames_the_float_design(
    monkeypatch,
) -> None:
    """Mutation review 30 (designed_gain_failed: ``not check_pd(riccati_Q)`` dropped, so any
    given riccati_Q was blamed; the high-precision retry's failure without the options): a
    positive definite riccati_Q is not named; a singular one is, on the retry's failure too."""
    from obsdesign.errors import InfeasibleError
    from obsdesign.methods.lyapunov import design as ld

    text = (
        '[system]\ntime = "discrete"\nA = [[0.6, 0.8], [-0.8, 0.6]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nriccati_Q = [[1, 0], [0, 1]]\n'
    )
    sp = load_spec_text(text, "q.toml")
    Lm = lyap.dyadic_fmat(np.zeros((2, 1)), lyap.BITS)[0]
    err = ld.designed_gain_failed(
        InfeasibleError("A − LC is not Schur"), "Riccati", Lm, False, sp.options
    )
    assert "badly conditioned" in err.message and "riccati_Q" not in err.message
    # the high-precision retry fails as well: its error names the singular riccati_Q too
    q0 = load_spec_text(text.replace("[[1, 0], [0, 1]]", "[[0, 0], [0, 0]]"), "q0.toml")
    real_hp = ld.riccati_retry_hp

    def hp(spec, o):
        got = real_hp(spec, o)
        if got is None:  # no retry here: give it the zero gain, which fails again
            Lz = lyap.dyadic_fmat(np.zeros((2, 1)), lyap.BITS)[0]
            first = ld.design_gain(spec, o, None)
            return Lz, lyap.BITS, first[1], "Riccati (high precision)"
        return got

    monkeypatch.setattr(ld, "riccati_retry_hp", hp)
    with pytest.raises(InconclusiveError, match="singular riccati_Q"):
        api.design(q0)


#: continuous A − LC with spectrum −0.1 ± 3i and a 4×4 Jordan block at −0.5, in disguise
JORDAN_CONTINUOUS = """title = "t"
[system]
time = "continuous"
A = [[-1810.9, -3828.41, -3948.77, 13456.98, 8509.23, 372.17], [114.6, 244.09, 249.23, -838.02, -528.77, -20.83], [1006.4, 2122.76, 2194.42, -7503.08, -4747.08, -203.72], [611.6, 1292.82, 1331.14, -4549.46, -2878.86, -114.94], [-838.4, -1773.44, -1824.68, 6232.92, 3943.82, 158.08], [108.6, 229.18, 237.26, -808.04, -510.74, -23.96]]
C = [[0, -0.1, 0.3, -0.2, 0.3, -0.3]]

[method]
key = "lyapunov"
L = [[0.1], [0.1], [0.4], [-0.2], [0.4], [0.2]]
alpha = 0.05
"""
#: discrete A − LC with spectrum 0.48 ± 0.64i (ρ = 0.8) and a 4×4 Jordan block at 0.5
JORDAN_DISCRETE = """title = "t"
[system]
time = "discrete"
A = [[101.2, 1999.86, -2289.4, -1394, 2404.2, -1141.86], [1291.67, 19.16, -17.43, -12910, -4945.82, 286.32], [-2726.04, -402.98, 455.76, 27318, 9929.44, -389.98], [1063.45, 303.88, -345.35, -10686, -3669.5, 67.02], [-2690.47, -264.5, 296.03, 26935, 9986.52, -463.48], [774.5, 88.1, -99, -7756, -2858, 126.4]]
C = [[0.3, 0, 0.3, 0, 0.2, 0.2]]

[method]
key = "lyapunov"
L = [[0], [-0.1], [0.2], [-0.5], [0.1], [0]]
lambda = 0.9
"""


@pytest.mark.parametrize(
    ("text", "rate", "bound"),
    [(JORDAN_CONTINUOUS, "alpha", -0.1), (JORDAN_DISCRETE, "lambda", 0.8)],
)
def test_a_jordan_block_does_not_mislead_the_spectral_guide(
    text: str, rate: str, bound: float
) -> None:
    """python-flint's eig gave values far from the spectrum at 320 and 1024 bits and the last
    was taken: the guide put α = 0.05 (λ = 0.9) on the infeasible side, skipped the
    high-precision Lyapunov solve, and the design ended exit 4, with "largest real part ≈
    0.114" (spectral radius ≈ 1.04) in its message (soundness trial, session 32). The exact
    characteristic polynomial decides now: certified, the guide at the true spectrum."""
    rep = api.design(api.load_spec_text(text, "j.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    key = "spectral_abscissa" if rate == "alpha" else "spectral_radius"
    assert rep.parameters.float(key) == pytest.approx(bound, abs=1e-6)
    assert api.verify(rep).exit_code() == 0


def test_bracket_detail_gives_the_spectral_guide_not_raw_float_eigenvalues(
    jordan_in_disguise,
) -> None:
    """The bracket claim's "optimal rate ρ(A − LC) ≈ …" came from raw float eigenvalues: 1.4693
    beside a certified λ = 0.98311 for an exact ρ = 0.8525 (lyapunov trial, session 34). It
    is the spectral guide's value, naming its source where floats are poor."""
    from obsdesign.methods.lyapunov.claims import _float_bound

    Am = jordan_in_disguise(fmpq(1, 2), 3, 1000)  # exactly ρ = 1/2, not so in floats
    Af = lyap.mat_float(Am)
    assert abs(float(np.max(np.abs(np.linalg.eigvals(Af)))) - 0.5) > 1e-5
    got = _float_bound(Am, Af, True)
    assert (
        got == "the optimal rate ρ(A − LC) ≈ 0.5 from roots of the exact characteristic polynomial"
    )
    assert _float_bound(Am, None, False) == (
        "the optimal rate −max Re eig(A − LC) ≈ -0.5 from roots of the exact characteristic "
        "polynomial"
    )
    diag = lyap.fmat(np.diag([0.5, 0.25]))
    assert _float_bound(diag, None, True) == "the optimal rate ρ(A − LC) ≈ 0.5 in floats"


def test_simulate_warns_when_the_gain_in_doubles_loses_the_certificate() -> None:
    """The 5-state plant certified at ρ(A − LC) = 0.647 for the exact gain: A − LC in doubles
    is unstable, and simulate ran it to |e| ≈ 10⁴⁰ with exit 0 and no word (interop trial,
    session 39). The shipped spec's doubles keep the rate: no such warning."""
    data = Path(__file__).parent / "data" / "lyapunov-rho-6000-5state.toml"
    text = data.read_text() + "\n[simulate]\nhorizon = 60\nx0 = [1, 0, 0, 0, 0]\n"
    text += "xhat0 = [0, 0, 0, 0, 0]\n"
    res = api.simulate(api.load_spec_text(text, "rho.toml"))
    said = " ".join(res.info.get("warnings", []))
    assert "A − LC in doubles is not stable" in said
    ok = api.simulate(ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml")
    assert not any("in doubles" in w for w in ok.info.get("warnings", []))


def test_design_notes_when_the_gain_in_doubles_loses_the_certificate() -> None:
    """design and verify said nothing while the report's float L made A − LC unstable on an
    ill-conditioned plant (lyapunov trial, session 39): the design notes it (decided exactly
    on the doubles); a well-conditioned design (the shipped spec)
    has no such note."""
    data = Path(__file__).parent / "data" / "lyapunov-rho-6000-5state.toml"
    rep = api.design(api.load_spec(data))
    assert rep.exit_code() == 0
    assert any("A − LC with L in doubles is not stable" in n for n in rep.notes)
    ok = api.design(ROOT / "specs" / "constrained-redesign-sec5-lyapunov.toml")
    assert not any("in doubles" in n for n in ok.notes)


def test_the_float_gain_note_is_not_skipped_by_a_small_continuous_abscissa() -> None:
    """Continuous, α = 0.0009, eigenvalues −0.001 and −10⁷ of the exact A − LC: the doubles
    give +2.8·10⁻⁴, unstable, and the design said nothing — its skip measured the rate's
    margin against the abscissa (10⁻³) instead of the eigenvalues' size (10⁷) that the
    guide's error bound is relative to (re-check trial, session 39)."""
    text = (
        '[system]\ntime = "continuous"\nA = [[690287.999, -13420000000], '
        '[5000000000.997, -10000000]]\nC = [[8000, 0]]\n[method]\nkey = "lyapunov"\n'
        "L = [86.286, 625000.000124625]\nalpha = 0.0009\n"
    )
    rep = api.design(api.load_spec_text(text, "fg1.toml"))
    assert rep.exit_code() == 0
    assert any("A − LC with L in doubles is not stable" in n for n in rep.notes)


def _jordan_spec(n: int, time: str = "discrete") -> str:
    """A Jordan block at 1 (discrete) or 0 (continuous) seen through its first state."""
    d = 1 if time == "discrete" else 0
    A = [[d if i == j else (1 if j == i + 1 else 0) for j in range(n)] for i in range(n)]
    rows = lambda M: "[" + ", ".join(str(r) for r in M) + "]"  # noqa: E731
    C = [[1] + [0] * (n - 1)]
    return f'[system]\ntime = "{time}"\nA = {rows(A)}\nC = {rows(C)}\n[method]\nkey = "lyapunov"\n'


def test_a_28_state_jordan_block_gets_the_high_precision_riccati_gain(tmp_path: Path) -> None:
    """The float Riccati gain of a 28-state Jordan block at 1 is not Schur (ρ ≈ 1.8 in floats)
    and the high-precision retry stopped at 24 states: exit 4. Up to 64 states it runs (with
    the ball-arithmetic λ_min guide and the integer Schur–Cohn test, a 44-state block takes
    ~10 s, 64 states ~50 s): certified, and verify agrees."""
    rep = api.design(load_spec_text(_jordan_spec(28), "j28.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    assert "arb_mat" in rep.solver["name"]
    out = tmp_path / "r.json"
    out.write_text(rep.to_json())
    assert api.verify(out).exit_code() == 0


def test_a_dead_beat_gain_gets_its_best_rate(tmp_path: Path) -> None:
    """A 20-state Jordan block at 1 with the dead-beat L = (C(20, k))ₖ (A − LC nilpotent,
    ‖A − LC‖ ≈ 1.8·10⁵): the Lyapunov P at a rate whose 1/λ is not dyadic needs 1024 bits
    (λ = 0.09: residual 3.4 at 320 bits), so the search stopped at λ = 0.0883, "not
    certifiable", although 0.01 certifies (hard-plant review, session 41). Now the best rate
    is within rate_tol of 0, the bracket's other end infeasible, and verify agrees."""
    import math

    L = ", ".join(str(math.comb(20, k)) for k in range(1, 21))
    rep = api.design(load_spec_text(_jordan_spec(20) + f"L = [{L}]\n", "db20.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    assert rep.parameters["lambda_best"] <= fmpq(1, 1000)
    assert rep.parameters["lambda_bracket_kind"] == "infeasible"
    out = tmp_path / "r.json"
    out.write_text(rep.to_json())
    assert api.verify(out).exit_code() == 0


def test_the_design_memo_is_not_used_for_a_spec_copy_with_another_A() -> None:
    """The memo left on the spec keyed A − LC by L alone: a copy of the designed spec with
    another A (copy.copy shares the memo) was certified with the old A − LC — decay-lmi
    "certified" for A = [[0, 1], [3, 0]], where A − LC has an eigenvalue 2.349 > λ (API
    review, session 42). A − LC is reused for the very same A and C arrays only."""
    import copy
    import dataclasses

    from flint import fmpq

    from obsdesign.spec.reader import Value

    text = (
        '[system]\ntime = "discrete"\nA = [[0, 1], [1, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nL = [-1.87, 1.874]\nlambda = 0.955\niss_gain = false\n'
    )
    spec = api.load_spec_text(text, "s.toml")
    rep = api.design(spec)
    assert rep.exit_code() == 0
    assert all(c.ok for c in api.certify(spec, rep.parameters))  # the memo's own spec
    other = copy.copy(spec)
    A3 = np.array([[fmpq(0), fmpq(1)], [fmpq(3), fmpq(0)]], dtype=object)
    other.system = dataclasses.replace(spec.system, A=Value.of(A3))
    status = {c.id: c.ok for c in api.certify(other, rep.parameters)}
    assert status["decay-lmi"] is False and status["decay-lmi_best"] is False
    # the same array object edited despite read-only (its flag set back by hand): the memo
    # compares entries, not identity (re-check review, session 42)
    A = spec.system.A.q
    for a in (A.base, A):
        if a is not None:
            a.flags.writeable = True
    A[1, 0] = fmpq(3)
    status = {c.id: c.ok for c in api.certify(spec, rep.parameters)}
    assert status["decay-lmi"] is False and status["decay-lmi_best"] is False


def test_a_certificate_beyond_the_float_range_names_the_rate_and_rate_tol() -> None:
    """A dead-beat gain (the double integrator's Riccati gain) with rate_tol = 1e-100: the best
    rate's P with the default margin δ = 1e-9 reaches 10⁴⁰⁰, and the design ended with the
    report's generic "parameter 'P': integer division result too large for a float", naming
    neither the rate nor rate_tol (degenerate-sizes review, session 42). Exit 4 naming them;
    with margin = 0 the same rate certifies."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0, 1], [0, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nrate_tol = 1e-100\n'
    )
    with pytest.raises(InconclusiveError, match=r"P at lambda = 1e-100 has entries beyond"):
        api.design(api.load_spec_text(text, "s.toml"))
    try:
        api.design(api.load_spec_text(text, "s.toml"))
    except InconclusiveError as e:
        assert (
            "[method].rate_tol (now 1e-100)" in e.message and "margin = 0 is allowed" in e.message
        )
    rep = api.design(api.load_spec_text(text + "margin = 0\n", "s.toml"))
    assert rep.exit_code() == 0 and api.verify(rep).exit_code() == 0
    # with λ = 0.5 asked, P_best (at the best rate, which rate_tol sets) is the one beyond:
    # rate_tol is named, not lambda (re-check review, session 42)
    with pytest.raises(InconclusiveError) as ei:
        api.design(api.load_spec_text(text + "lambda = 0.5\n", "s.toml"))
    msg = ei.value.message
    assert "P_best at lambda_best = 1e-100" in msg and "rate_tol (now 1e-100)" in msg
    assert "[method].lambda" not in msg


def test_a_huge_margin_is_exit_4_naming_the_margin() -> None:
    """margin = 1e307: the float P scaled for that margin overflows; it was exit 3 "cannot
    round a non-finite number" (re-check review, session 42). Exit 4, the margin named."""
    text = (
        '[system]\ntime = "continuous"\nA = [[-1, 0], [0, -1]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nL = [0, 0]\nalpha = 0.5\nmargin = 1e307\n'
        "iss_gain = true\n"
    )
    with pytest.raises(
        InconclusiveError, match=r"margin δ = 1e\+?307.*a smaller \[method\]\.margin"
    ):
        api.design(api.load_spec_text(text, "s.toml"))


def test_a_margin_whose_scale_factor_overflows_names_the_margin() -> None:
    """margin = 1e308: the scale factor for the margin itself overflowed before the float P
    did, and the design ended with the generic "integer division result too large for a
    float" (re-check review, session 42). Exit 4 naming the margin."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0, 1], [1, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nL = [-1.87, 1.874]\nlambda = 0.955\nmargin = 1e308\n'
    )
    with pytest.raises(
        InconclusiveError, match=r"margin δ = 1e\+?308.*a smaller \[method\]\.margin"
    ):
        api.design(api.load_spec_text(text, "s.toml"))


def test_a_float_singular_iss_block_names_the_keys_to_change() -> None:
    """λ = 1e-300 with margin = 0 and the ISS gain: S = λ²P − (A − LC)ᵀP(A − LC) is singular
    in floats (ρ = 0), exit 4 — whose message named no key and ended "a larger decay rate"
    (re-check review, session 43). It names [method].lambda and iss_gain = false, and with
    iss_gain = false the same rate certifies."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0, 1], [1, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nL = [0, 1]\nmargin = 0\nlambda = 1e-300\niss_gain = true\n'
    )
    with pytest.raises(InconclusiveError, match=r"is singular in floats") as ei:
        api.design(api.load_spec_text(text, "s.toml"))
    assert ei.value.exit_code == 4
    assert "a larger [method].lambda" in ei.value.message
    assert ei.value.message.endswith("or iss_gain = false (no ISS gain)")
    rep = api.design(api.load_spec_text(text.replace("iss_gain = true", "iss_gain = false"), "s"))
    assert rep.exit_code() == 0


def test_a_stability_margin_below_the_rate_grid_names_rate_tol() -> None:
    """A = diag(−1e-150, −2e-150), L = 0: every candidate rate of the rate_tol grid is above
    α_best ≈ 1e-150, and the exit 4 said only "no decay rate α > 0 could be certified" (float
    pre-screen review, session 43). It names rate_tol, and a rate_tol below the margin
    certifies."""
    text = (
        '[system]\ntime = "continuous"\nA = [[-1e-150, 0], [0, -2e-150]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\nL = [0, 0]\n'
    )
    with pytest.raises(InconclusiveError, match=r"give a \[method\]\.rate_tol below 1e-150"):
        api.design(api.load_spec_text(text, "s.toml"))
    rep = api.design(api.load_spec_text(text + "rate_tol = 1e-151\n", "s.toml"))
    assert rep.exit_code() == 0
    # discrete, a margin below the float resolution (A = 1 − 10⁻¹⁷ is 1.0 as a float): the
    # hint was missing (re-check review, session 43)
    disc = '[system]\ntime = "discrete"\nA = [[0.99999999999999999]]\nC = [[1]]\n[method]\nkey = "lyapunov"\nL = [[0]]\n'
    # rate_tol stops at ~2.3e-16: past that, a given λ (re-check review, session 43)
    with pytest.raises(
        InconclusiveError,
        match=r"is 0 in floats .* a smaller \[method\]\.rate_tol, or a rate \[method\]\.lambda",
    ):
        api.design(api.load_spec_text(disc, "d.toml"))
    assert api.design(api.load_spec_text(disc + "rate_tol = 1e-6\n", "d.toml")).exit_code() == 0


_OVERFLOW = """[system]
time = "discrete"
A = [[5e307, 0], [0, 0.5]]
C = [[1e308, 0], [1.5e308, 0]]
[method]
key = "lyapunov"
L = [[2, -1], [0, 0]]
"""


def test_a_gain_whose_float_product_overflows_is_certified_from_the_exact_loop() -> None:
    """L·C past the float range while A − LC = diag(0, 0.5) exactly: the float P came from
    A − L·C in doubles (inf), exit 4 "holds in floats but the exact check failed", and the
    doubles' note was an internal failure (re-check review, session 44). The float problem
    is made from the exact closed loop, rounded; the report certifies and verifies, and
    says the doubles cannot run it."""
    from obsdesign import api
    from obsdesign.errors import InconclusiveError

    rep = api.design(api.load_spec_text(_OVERFLOW, "o.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    assert api.verify(rep).exit_code() == 0
    assert any("formed in doubles overflows" in n for n in rep.notes), rep.notes
    # numpy's own overflow warnings were notes too (re-check review 45), also in continuous
    # time; observer_statespace() was a bare ValueError "not a finite number: -inf"
    ct = _OVERFLOW.replace('"discrete"', '"continuous"').replace("0.5]]", "-0.5]]")
    ct = ct.replace("L = [[2,", "L = [[2.00000000000000000001,")  # A − LC = diag(−1e288, −0.5)
    for r in (rep, api.design(api.load_spec_text(ct, "ct.toml"))):
        assert r.exit_code() == 0 and not any("RuntimeWarning" in n for n in r.notes), r.notes
        pytest.importorskip("control")
        with pytest.raises(InconclusiveError, match="observer_statespace\\(\\), in doubles"):
            r.observer_statespace()
    # simulate says the same, exit 4 (it was an internal failure, exit 3: re-check review)
    sim = _OVERFLOW + "[simulate]\nhorizon = 5\nx0 = [1, 1]\nxhat0 = [0, 0]\n"
    with pytest.raises(InconclusiveError, match="formed in doubles overflows"):
        api.simulate(api.load_spec_text(sim, "s.toml"))
    text = _OVERFLOW.replace('key = "lyapunov"', 'key = "constrained"\nX = "X"\neps_min = 0.01')
    text += '[method.c]\ntype = "box"\nlower = [-1.1, -1.1]\nupper = [1.1, 1.1]\n'
    text += "[method.D]\nlower = [-3, -3]\nupper = [3, 3]\n"
    text = text.replace(
        "[method]", '[sets.X]\ntype = "box"\nlower = [-1, -1]\nupper = [1, 1]\n[method]'
    )
    assert api.design(api.load_spec_text(text, "c.toml")).exit_code() == 0
