"""The set-invariant method (paper 003, Dórea & Pimenta): Examples 7.1 and 7.2, the laws,
bad input, and property tests (Proposition 4.1) on random systems."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from flint import fmpq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from obsdesign import api
from obsdesign.api import load_spec, load_spec_text
from obsdesign.certify.claim import ClaimStatus
from obsdesign.certify.exact import Q, qmat
from obsdesign.errors import (
    InconclusiveError,
    InfeasibleError,
    InputError,
    SolverError,
    SpecError,
)
from obsdesign.methods.setinvariant import laws
from obsdesign.methods.setinvariant.linear import _affine_dim
from obsdesign.methods.setinvariant.spectext import spec_text as matrix_spec_text


def _design_example(tmp_path_factory, example: str):
    """Design ``specs/dorea-pimenta-<example>.toml``; returns (report, path of its JSON)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    out = tmp_path_factory.mktemp("r") / f"r{example.replace('-', '')}.json"
    rep = api.design(root / "specs" / f"dorea-pimenta-{example}.toml", out)
    return rep, out


@pytest.fixture(scope="module")
def rep71(tmp_path_factory):
    return _design_example(tmp_path_factory, "7-1")


@pytest.fixture(scope="module")
def rep72(tmp_path_factory):
    return _design_example(tmp_path_factory, "7-2")


def _rows_up_to_sign(G: np.ndarray) -> set[tuple[float, ...]]:
    out = set()
    for r in np.round(G, 4):
        r = r + 0.0
        if r[np.flatnonzero(r)[0]] < 0:
            r = -r
        out.add(tuple(float(x) + 0.0 for x in r))
    return out


def test_example_71_Q2_iterations_and_vertices(rep71):
    rep, _ = rep71
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    p = rep.parameters
    assert p["iterations"] == 2
    # the first check of (14) gives 2.4, the second passes with 0.9
    assert np.allclose(p["history_eps"], [2.4, 0.9])
    Q2 = np.array([[-0.4412, 0.5588], [-0.8333, 0.1667], [0.9, 0.0]])
    assert _rows_up_to_sign(p.float("G")) == _rows_up_to_sign(Q2)
    # exact rows: 15/34, 19/34, 5/6, 1/6, 9/10 and exact factor 9/10
    assert {abs(x) for x in np.asarray(p["G"]).reshape(-1)} == {
        fmpq(15, 34),
        fmpq(19, 34),
        fmpq(5, 6),
        fmpq(1, 6),
        fmpq(9, 10),
        fmpq(0),
    }
    assert p["contractivity"] == fmpq(9, 10)


def test_example_71_linear_gains(rep71):
    """Two rows of Q² tie in Ω ∩ ker C: the Prop. 7.1 gains are the ends of the admissible
    segment L = [−0.7, l2], l2 ∈ [−7/15, 7/85] (≈ [−0.4667, 0.0824]); the paper's
    L = [−0.7, −0.2212] lies inside and certifies, but is not reproduced: it is neither end
    nor the midpoint −49/255 (docs/methods/set-invariant.md; papers review 46)."""
    rep, _ = rep71
    p = rep.parameters
    L = np.asarray(p["L"]).reshape(-1)
    assert L[0] == fmpq(-7, 10)
    V = np.asarray(p["L_admissible_vertices"])
    ends = sorted(V[:, 1])
    assert ends == [fmpq(-7, 15), fmpq(7, 85)]
    assert all(v == fmpq(-7, 10) for v in V[:, 0])
    assert ends[0] < L[1] < ends[1] and L[1] == fmpq(-49, 255)
    assert all(round(float(v), 4) != -0.2212 for v in (*ends, L[1]))
    user = next(c for c in rep.claims if c.id == "linear-law-user")
    assert user.status == ClaimStatus.CERTIFIED
    assert any("Proposition 7.1 with Q_I" in n for n in rep.notes)


def test_proposition_71_notes_count_the_rows_of_G_from_1(rep71):
    """ "Q_I = row i of G" names row i of the report's G counted from 1, as the paper counts:
    L = A [Q_I; C]⁻¹ [0; −I] rebuilt from that row gives the printed L. The notes counted from
    0, so "row 1" read as (−0.9, 0) gave L = (−0.7, −0.7), which is not admissible
    (paper-reproduction review, session 42)."""
    import re

    from flint import fmpq_mat

    rep, _ = rep71
    G = np.asarray(rep.parameters["G"], dtype=object)
    spec = load_spec_text(rep.spec, rep.spec_file)
    A, C = spec.system.A.q, spec.system.C.q
    notes = [n for n in rep.notes if n.startswith("Proposition 7.1 with Q_I = row")]
    assert len(notes) >= 2
    for note in notes:
        m = re.match(
            r"Proposition 7.1 with Q_I = row (\d+) of G \(counted from 1\) gives L = ≈?\[(.*)\]",
            note,
        )
        assert m, note
        i = int(m.group(1))
        M = fmpq_mat([list(G[i - 1]), *[list(r) for r in C]])
        L = fmpq_mat([list(r) for r in A]) * M.inv() * fmpq_mat([[0], [-1]])
        shown = [float(v) for v in m.group(2).split(",")]
        assert [float(L[0, 0]), float(L[1, 0])] == pytest.approx(shown, abs=1e-4)


def test_example_71_verify_and_simulate(rep71, tmp_path):
    rep, out = rep71
    v = api.verify(out)
    assert v.exit_code() == 0
    from pathlib import Path

    from obsdesign.api import load_spec

    spec = load_spec(Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml")
    res = api.simulate(spec, out)
    assert res.info["error_in_polyhedron"] and res.info["admissible_scenario"]
    assert res.info["max_gauge"] <= 1 + 1e-9
    from obsdesign.methods import get_method

    png = get_method("set-invariant").plot_simulation(spec, res, tmp_path / "fig1.png")
    assert png.exists() and png.stat().st_size > 1000
    # the paper's linear gain (the spec's [method].L, Fig. 1's law) gives a trajectory in the
    # polyhedron too; it is the gain simulated, not the design's midpoint L = [-0.7, -49/255]
    # that ran in its place (papers review 46): e⁺ = A e + B1 d + L (C e + η), eq. (3)
    res2 = api.simulate(spec, out, law="linear")
    assert res2.info["error_in_polyhedron"]
    assert res2.info["linear_gain"] == "[method].L of the spec"
    from obsdesign.simulate.runner import signals

    s, L = spec.system, np.array([[-0.7], [-0.2212]])
    e = res2.extra["e_paper"]
    _, d, eta = signals(spec, np.arange(len(e)))
    want = [e[0]]
    for k in range(len(e) - 1):
        z = s.C.f @ want[-1] + s.Dn.f @ eta[k]
        want.append(s.A.f @ want[-1] + s.Bd.f @ d[k] + L @ z)
    np.testing.assert_allclose(e, np.array(want), rtol=0, atol=1e-12)
    assert e[2][1] == pytest.approx(-1.4424, abs=5e-5)  # the design's midpoint L: -1.384314
    # the law is named as the option names it (it printed the class, LinearLaw: docs audit)
    assert res.info["law"] == "interpolated" and res2.info["law"] == "linear"


def test_verify_rejects_tampered_breakpoint(rep71, tmp_path):
    _, out = rep71
    d = json.loads(out.read_text())
    v = d["parameters"]["exact"]["v_breakpoints"]
    v[0][0] = "3"  # a worse injection at the first breakpoint
    d["parameters"]["v_breakpoints"][0][0] = 3.0
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    rep = api.verify(bad)
    assert rep.exit_code() != 0
    assert any(c.id == "theorem-3.1" and c.status == ClaimStatus.FAILED for c in rep.claims)


def test_example_72_symmetric_fails_general_certifies(rep72, tmp_path):
    """C_K^∞ meets (14) but max ε(z) ≈ 1.06 > 1 (Fig. 2); the general algorithm then gives
    a polyhedron whose certified factor is <= λ = 1."""
    rep, out = rep72
    p = rep.parameters
    assert (
        1.06 < p["symmetric_contractivity"] < 1.065
    )  # paper: "ε(z) > 1 for some z", Fig. 2 ≈ 1.06
    assert p["converged"] is True
    assert p["contractivity"] <= 1
    # reproduced (in Ω-unit coordinates, design.scaling): 3 symmetric + 32 general checks,
    # 60 facets, 32 vertices, factor 0.99999967 (33, 56, 30 and 0.999999654 in the spec's)
    assert (p["iterations"], p["facets"], p["vertices"]) == (35, 60, 32)
    assert len(np.asarray(p["G"]).reshape(-1, 3)) == 60 and len(np.asarray(p["V"])) == 32
    assert fmpq(999999669, 10**9) < p["contractivity"] < fmpq(999999670, 10**9)
    assert p["symmetric_iterations"] == 3 and len(np.asarray(p["symmetric_G"])) == 70
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    assert api.verify(out).exit_code() == 0
    from pathlib import Path

    from obsdesign.api import load_spec
    from obsdesign.methods import get_method

    spec = load_spec(Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-2.toml")
    png = get_method("set-invariant").plot_design(spec, rep.parameters, tmp_path / "fig2.png")
    assert png.stat().st_size > 1000


# -- bad input ------------------------------------------------------------------------------
BASE = """
[system]
time = "{time}"
A = {A}
B1 = {B1}
C = {C}

[sets.omega]
{omega}

[sets.D]
type = "box"
dim = 1
lower = [-0.1]
upper = [0.1]

[method]
key = "set-invariant"
omega = "omega"
disturbance = "D"
eta_bar = {eta}
lambda = {lam}
algorithm = "{alg}"
max_iterations = {maxit}
"""


def spec_text(**kw: object) -> str:
    d = dict(
        time="discrete",
        A="[[0.7, 0.7], [-0.7, 0.7]]",
        B1="[1, 1]",
        C="[[1, 1]]",
        omega='type = "symmetric-polytope"\nQ = [[1, 0], [0, 1]]',
        eta="0",
        lam="0.9",
        alg="symmetric",
        maxit="50",
    )
    d.update({k: str(v) for k, v in kw.items()})
    return BASE.format(**d)


@pytest.mark.parametrize(
    "kw,key",
    [
        ({"lam": "0"}, "method.lambda"),
        ({"lam": "-0.5"}, "method.lambda"),
        ({"lam": "1.1"}, "method.lambda"),
        ({"omega": 'type = "polytope"\nG = [[1, 0], [-1, 0]]\ng = [1, 1]'}, "sets.omega.G"),
        (
            {
                "omega": 'type = "polytope"\nG = [[1, 0], [-1, 0], [0, 1], [0, -1]]\ng = [1, -2, 1, 1]'
            },
            "sets.omega.G",
        ),
        (
            {
                "omega": 'type = "polytope"\nG = [[1, 0], [-1, 0], [0, 1], [0, -1]]\ng = [2, -1, 1, 1]'
            },
            "method.omega",
        ),
        ({"time": "continuous"}, "system.time"),
        (
            {
                "C": "[[1, 0], [0, 1], [1, 1]]",
                "A": "[[0.5, 0, 0], [0, 0.5, 0], [0, 0, 0.5]]",
                "B1": "[1, 1, 1]",
                "omega": 'type = "box"\nlower = [-1, -1, -1]\nupper = [1, 1, 1]',
            },
            "system.C",
        ),
        ({"eta": "-1"}, "method.eta_bar"),
    ],
)
def test_bad_input_names_the_key(kw, key):
    with pytest.raises(SpecError) as e:
        load_spec_text(spec_text(**kw), "bad.toml")
    assert e.value.exit_code == 2
    assert f"[{key}]" in e.value.message


def test_multi_output_needs_p_equal_n_minus_1_and_no_noise():
    three = dict(
        A="[[0.5, 0.1, 0], [0, 0.5, 0], [0, 0, 0.5]]",
        B1="[1, 1, 1]",
        C="[[1, 0, 0], [0, 1, 0]]",
        omega='type = "box"\nlower = [-1, -1, -1]\nupper = [1, 1, 1]',
    )
    with pytest.raises(SpecError, match="Proposition 7.1"):
        load_spec_text(spec_text(eta="0.1", **three), "bad.toml")
    with pytest.raises(SpecError, match="symmetric"):
        load_spec_text(spec_text(alg="general", **three), "bad.toml")
    # p = n − 1 = 2 with η̄ = 0: symmetric algorithm and a linear law (Proposition 7.1)
    rep = api.design(load_spec_text(spec_text(**three), "ok.toml"))
    assert rep.exit_code() == 0
    assert any(c.id == "linear-law" and c.status == ClaimStatus.CERTIFIED for c in rep.claims)


def test_linear_law_off_with_several_outputs_needs_a_given_L() -> None:
    """p = n − 1 = 2 with linear_law = false (random-spec fuzzer): no injection law would be
    left, and the design failed a 'linear-law' claim saying no gain was found although no
    search ran. Now a spec error naming the key; with a given L the user's law is certified
    and no 'linear-law' claim is made."""
    base = (
        '[system]\ntime = "discrete"\nA = [[0.1, 0, 0.2], [0, 0.1, 0], [0, 0, 0.4]]\n'
        'C = [[1, 0, 0], [0, 1, 0]]\n[sets.omega]\ntype = "box"\nlower = [-1, -1, -1]\n'
        'upper = [1, 1, 1]\n[method]\nkey = "set-invariant"\nomega = "omega"\n'
        "lambda = 0.9\nlinear_law = false\n"
    )
    with pytest.raises(SpecError, match=r"\[method\.linear_law\] expected true"):
        load_spec_text(base, "off.toml")
    rep = api.design(load_spec_text(base + "L = [[-0.1, 0], [0, -0.1], [0, 0]]\n", "L.toml"))
    ids = {c.id: c.status for c in rep.claims}
    assert rep.exit_code() == 0 and "linear-law" not in ids
    assert ids["linear-law-user"] == ClaimStatus.CERTIFIED
    assert api.verify(rep).exit_code() == 0


def test_not_detectable_exit_1():
    # the mode 1.2 of e2 is not seen by C = [1, 0]
    sp = load_spec_text(spec_text(A="[[0.5, 0], [0, 1.2]]", C="[[1, 0]]"), "nd.toml")
    with pytest.raises(InfeasibleError, match="not detectable"):
        api.design(sp)
    sp = load_spec_text(spec_text(A="[[0.5, 0], [0, 0.95]]", C="[[1, 0]]"), "slow.toml")
    with pytest.raises(InfeasibleError, match="λ"):
        api.design(sp)


def test_unobservable_mode_at_lambda_goes_on_to_the_algorithm() -> None:
    """The soundness audit's example: μ = 1 unobservable with λ = 1, not excited (B1 = [0.1,
    0]): the box Ω is invariant, so it is not refused; it certifies and verifies. The same
    mode with λ = 0.9 (|μ| > λ) and μ = 1.0000001 with λ = 1 are refused exactly as before;
    a mode exactly at λ = 0.95 goes on to the algorithm (no up-front refusal)."""
    from obsdesign.methods.setinvariant.problem import check_detectable

    box = 'type = "box"\nlower = [-1, -1]\nupper = [1, 1]'
    kw = dict(A="[[0.5, 0], [0, 1]]", C="[[1, 0]]", B1="[0.1, 0]", omega=box, alg="none")
    rep = api.design(load_spec_text(spec_text(lam="1", **kw), "marginal.toml"))
    assert rep.exit_code() == 0
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    with pytest.raises(InfeasibleError, match="λ"):
        api.design(load_spec_text(spec_text(lam="0.9", **kw), "slow.toml"))
    A = qmat([[fmpq(1, 2), 0], [0, fmpq(10000001, 10000000)]])
    with pytest.raises(InfeasibleError, match="not detectable"):
        check_detectable(A, qmat([[1, 0]]), fmpq(1))
    A = qmat([[fmpq(1, 2), 0], [0, fmpq(19, 20)]])
    check_detectable(A, qmat([[1, 0]]), fmpq(19, 20))  # |μ| = λ exactly: not refused
    with pytest.raises(InfeasibleError, match="λ"):
        check_detectable(A, qmat([[1, 0]]), fmpq(19, 20) - fmpq(1, 10**6))
    check_detectable(A, qmat([[1, 1]]), fmpq(1, 10))  # observable: nothing to refuse


@pytest.mark.parametrize(
    "diag",
    [
        ["3/10", "9/10", "9/10"],  # a double unobservable mode at λ
        ["3/10", "-9/10", "-9/10"],
        ["3/10", "9/10", "9/10", "9/10"],  # triple: np.roots split it by ~1e-5
    ],
)
def test_a_repeated_diagonal_unobservable_mode_at_lambda_is_not_refused(diag: list[str]) -> None:
    """A = diag(0.3, 0.9, 0.9), C = (1, 0, 0), λ = 0.9: the float roots of χ split the double
    root by ~10⁻⁸ and the design was refused, "|μ| = 0.9 > λ = 0.9", though the box Ω is
    0.9-contractive with L = (−0.3, 0, 0) (set-invariant soundness trial, session 25). The
    rigorous root balls of the minimal polynomial (0.9 is a simple root there) pass it on."""
    from obsdesign.methods.setinvariant.problem import check_detectable

    n = len(diag)
    A = qmat([[Q(diag[i]) if i == j else 0 for j in range(n)] for i in range(n)])
    C = qmat([[1] + [0] * (n - 1)])
    check_detectable(A, C, fmpq(9, 10))
    with pytest.raises(InfeasibleError, match="λ"):
        check_detectable(A, C, fmpq(9, 10) - fmpq(1, 10**30))  # just below: refused


def test_a_defective_unobservable_mode_at_lambda_is_refused_and_named() -> None:
    """A Jordan block at μ = λ = 0.9 (unobservable) has powers k·0.9ᵏ: no polyhedron is
    0.9-contractive; refused exactly (multiplicity 2 in the minimal polynomial). μ =
    0.9000001 is refused with its modulus to 17 digits (the message said "|μ| = 0.9 >
    λ = 0.9")."""
    from obsdesign.methods.setinvariant.problem import check_detectable

    nine = fmpq(9, 10)
    J = qmat([[fmpq(3, 10), 0, 0], [0, nine, 1], [0, 0, nine]])
    C = qmat([[1, 0, 0]])
    with pytest.raises(InfeasibleError, match="defective"):
        check_detectable(J, C, nine)
    check_detectable(J, C, nine + fmpq(1, 10**6))  # λ above the block's |μ|: passed on
    B = qmat([[fmpq(3, 10), 0], [0, fmpq(9000001, 10**7)]])
    with pytest.raises(InfeasibleError, match=r"\|μ\| ≈ 0\.9000001 > λ = 0\.9"):
        check_detectable(B, qmat([[1, 0]]), nine)
    # as few digits as show it above λ: 19/20 was "0.94999999999999996" (session 30)
    B = qmat([[fmpq(1, 2), 0], [0, fmpq(19, 20)]])
    with pytest.raises(InfeasibleError, match=r"μ ≈ 0\.95 has \|μ\| ≈ 0\.95 > λ = 0\.9:"):
        check_detectable(B, qmat([[1, 0]]), nine)
    with pytest.raises(InfeasibleError, match=r"μ ≈ -1\.5 \(\|μ\| ≈ 1\.5 > 1\)"):
        check_detectable(qmat([[fmpq(1, 2), 0], [0, fmpq(-3, 2)]]), qmat([[1, 0]]), nine)
    # beyond a double: 1 + 10⁻¹⁷ was "|μ| ≈ 1 > 1" (re-check trial, session 30)
    tiny = fmpq(1) + fmpq(1, 10**17)
    with pytest.raises(InfeasibleError, match=r"\|μ\| ≈ 1\.00000000000000001 > 1\)"):
        check_detectable(qmat([[fmpq(1, 2), 0], [0, tiny]]), qmat([[1, 0]]), nine)
    # a complex pair (0.6 ± 0.8i)·(1 + 10⁻⁷), |μ| > 1, shown with its imaginary part
    k = fmpq(1) + fmpq(1, 10**7)
    r = qmat([[fmpq(1, 2), 0, 0], [0, k * 6 / 10, -k * 8 / 10], [0, k * 8 / 10, k * 6 / 10]])
    with pytest.raises(
        InfeasibleError, match=r"μ ≈ 0\.6[0-9]*[+-]0\.8[0-9]*j \(\|μ\| ≈ 1\.0000001 > 1"
    ):
        check_detectable(r, qmat([[1, 0, 0]]), nine)


def test_necessary_condition_and_not_converged():
    # algorithm "none" checks Ω itself: λΩ does not contain B1·D = ±0.5·(1, 1) -> failed claim
    t = spec_text(alg="none").replace("lower = [-0.1]\nupper = [0.1]", "lower = [-1]\nupper = [1]")
    rep = api.design(load_spec_text(t, "none.toml"))
    nec = next(c for c in rep.claims if c.id == "necessary-condition")
    assert nec.status == ClaimStatus.FAILED and "Section II" in nec.statement
    assert rep.exit_code() == 1
    # iteration cap: not converged, the last polyhedron is reported, exit 1
    rep = api.design(load_spec_text(spec_text(alg="general", maxit=1), "cap.toml"))
    assert rep.parameters["converged"] is False and "G" in rep.parameters
    assert rep.exit_code() == 1
    # the count is over every algorithm that ran, the cap per algorithm ("after 150
    # iterations (max_iterations = 100)" read as a broken cap; unusual-spec trial, session 24)
    conv = next(c for c in rep.claims if c.id == "converged")
    assert "iterations in all (max_iterations = 1 for each algorithm that ran)" in conv.detail


# -- property tests (Proposition 4.1) ------------------------------------------------------
@st.composite
def systems(draw):
    n = draw(st.sampled_from([2, 3]))
    seed = draw(st.integers(0, 10**6))
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    A *= rng.uniform(0.4, 1.2) / max(abs(np.linalg.eigvals(A)))
    A = np.round(A, 3)
    C = np.round(rng.normal(size=(1, n)), 3)
    B1 = np.round(rng.normal(size=(n, 1)) * 0.1, 3)
    b = float(np.round(rng.uniform(0.1, 1.0), 2))
    eta = float(np.round(rng.uniform(0, 0.05), 3))
    return A, B1, C, b, eta, seed


@settings(max_examples=6, deadline=None, suppress_health_check=list(HealthCheck))
@given(systems())
def test_property_error_stays_in_polyhedron(sys_):
    """Every certified design keeps e(k) in {G e <= 1} for random admissible d, η over 200
    steps (interpolated law (12)), and e(k) → 0 with d = η = 0 (time-varying law (10))."""
    # at most 6 iterations: a random system that needs more (or never converges) is skipped
    # as "not converged"; 10-25 iterations cost up to minutes on non-converging systems
    _check_system(sys_)


def test_property_body_runs_on_a_certified_design():
    """The property test's body on a fixed system that certifies (so it cannot pass vacuously)."""
    A = np.array([[0.7, 0.7], [-0.7, 0.7]])
    B1 = np.array([[0.1], [0.2]])
    C = np.array([[1.0, 0.5]])
    assert _check_system((A, B1, C, 0.5, 0.02, 7), maxit=25)


def _check_system(sys_, maxit: int = 6) -> bool:
    """Design, and if certified simulate; returns whether the simulation part ran."""
    A, B1, C, b, eta, seed = sys_
    n = A.shape[0]
    text = matrix_spec_text(
        A,
        B1,
        C,
        0.9,
        bound=b,
        eta_bar=eta,
        algorithm="general",
        mirror=True,
        delta_tol=0.001,
        max_iterations=maxit,
    )
    try:
        sp = load_spec_text(text, "prop.toml")
        rep = api.design(sp)
    except InfeasibleError:
        return False
    except SolverError as e:  # refused by [method] time_limit (a slow or loaded machine)
        assert "within" in e.message and "time_limit" in e.message
        return False
    if rep.exit_code() != 0:
        assert rep.parameters["converged"] is False  # only a non-converged run may fail
        return False
    p = rep.parameters
    G = p.float("G").reshape(-1, n)
    z = p.float("breakpoints").reshape(-1)
    v = p.float("v_breakpoints").reshape(len(z), n)
    rng = np.random.default_rng(seed)
    from obsdesign.sets import polytope_ops as po

    V = po.h_to_v(G).V
    law = laws.PiecewiseAffineLaw(z, v, 0.9)
    for _ in range(3):
        e0 = V[rng.integers(len(V))] * rng.uniform(0.3, 1.0)
        d = rng.choice([-b, b], size=(200, 1)) * rng.uniform(0.5, 1, size=(200, 1))
        et = rng.uniform(-eta, eta, size=(200, 1))
        e = laws.simulate_error(A, B1, C, law, e0, d, et)
        assert (e @ G.T).max() <= 1 + 1e-7
    tv = laws.PiecewiseAffineLaw(z, v, 0.9, "time-varying")
    e = laws.simulate_error(A, B1, C, tv, V[0], np.zeros((200, 1)), np.zeros((200, 1)))
    assert (e @ G.T).max() <= 1 + 1e-7
    assert np.abs(e[-1]).max() < 1e-6
    return True


def test_template_designs():
    rep = api.design(load_spec_text(api.template("set-invariant"), "template.toml"))
    assert rep.exit_code() == 0


def test_template_options_uncommented_still_load():
    """Every commented-out key of the template is valid when uncommented (one at a time and
    all together) and validates against ``obsdesign schema``."""
    import re
    import tomllib

    import jsonschema

    text = api.template("set-invariant")
    lines = text.splitlines()
    opts = [i for i, ln in enumerate(lines) if re.match(r"^# [A-Za-z_]+ = ", ln)]
    assert len(opts) >= 5
    variants = [[i] for i in opts] + [opts]
    for idx in variants:
        t = "\n".join(ln[2:] if i in idx else ln for i, ln in enumerate(lines))
        jsonschema.validate(tomllib.loads(t), api.schema())
        load_spec_text(t, "template.toml")


def test_spec_text_builder_round_trips_exact_values():
    """``spectext.spec_text`` writes every matrix entry, bound, η̄, λ and method key so that
    the loaded spec holds exactly those values."""
    text = matrix_spec_text(
        np.array([[0.5, 0.1], [0.0, 0.5]]),
        [1, 0.25],
        [[1, 0]],
        0.9,
        bound=0.1,
        algorithm="general",
        mirror=True,
        max_iterations=5,
    )
    sp = load_spec_text(text, "built.toml")
    assert sp.system.A.q.tolist() == [[fmpq(1, 2), fmpq(1, 10)], [0, fmpq(1, 2)]]
    o = sp.options
    assert list(o.D.lower_q) == [fmpq(-1, 10)] and list(o.D.upper_q) == [fmpq(1, 10)]
    assert (o.eta_bar, o.lam) == (fmpq(1, 100), fmpq(9, 10))
    assert (o.algorithm, o.mirror, o.max_iterations) == ("general", True, 5)
    assert "eta_bar" not in matrix_spec_text([[0.5]], [1], [[1]], 0.9, eta_bar=None)


def test_a_set_too_thin_for_floats_is_inconclusive_not_an_internal_failure() -> None:
    """Ω = {|Q e|∞ <= 1} with Q = [[1e50, 0], [0, 1]] (found by the spec fuzzer) is 10⁻⁵⁰
    wide: qhull cannot build its float hull. That is exit 4 naming the float polytope
    computation, not exit 3 "internal failure: PolytopeError"."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml").read_text()
    assert "\nQ = [[1, 0], [0, 1]]\n" in text
    spec = load_spec_text(
        text.replace("\nQ = [[1, 0], [0, 1]]\n", "\nQ = [[1e50, 0], [0, 1]]\n"), "t.toml"
    )
    with pytest.raises(InconclusiveError, match="float polytope computation failed") as e:
        api.design(spec)
    assert e.value.exit_code == 4 and "\n" not in e.value.message


def test_diverging_general_algorithm_is_not_converged_exit_1() -> None:
    """The soundness audit's A = [[0.14, 0], [726.54, 0.12]] (Ω a 4-facet polytope, λ = 0.9):
    the general algorithm's polyhedron grows without bound; it used to reach 10²⁰ and end
    with exit 4 ("out of a float LP's range"). It now stops when a new vertex passes
    GROWTH_MAX times Ω's size: not converged (exit 1), the last polyhedron reported, a note
    saying why."""
    from obsdesign.methods.setinvariant import algorithms as al

    text = (
        '[system]\ntime = "discrete"\nA = [[0.14, 0.0], [726.54, 0.12]]\nC = [[-0.54, 0.36]]\n'
        '[sets.omega]\ntype = "polytope"\n'
        "G = [[1.30, 0.95], [-0.70, -1.27], [-0.62, 0.04], [-0.05, 0.26]]\n"
        'g = [2.00, 0.50, 0.50, 2.00]\n[method]\nkey = "set-invariant"\nomega = "omega"\n'
        'eta_bar = 0.0\nlambda = 0.90\nalgorithm = "general"\nmax_iterations = 40\n'
    )
    rep = api.design(load_spec_text(text, "diverge.toml"))
    assert rep.exit_code() == 1
    assert rep.parameters["converged"] is False and rep.parameters["iterations"] < 40
    assert any("diverges" in n and f"{al.GROWTH_MAX:g}" in n for n in rep.notes)
    assert {c.id: c.status for c in rep.claims}["converged"] == ClaimStatus.FAILED


def test_simulated_error_of_an_unstable_plant_keeps_its_digits() -> None:
    """x⁺ = 3x with v = −2.5 z (e⁺ = 0.5 e): over 40 steps x reaches 3⁴⁰ ≈ 10¹⁹, so x − x̂
    would have no correct digit left; the error is stepped by its own recursion (eq. (3)),
    so it is 0.5^(k+1) to rounding and the run stays in the polyhedron (a certified design
    'left' it in simulation before; random-spec fuzzer)."""
    text = (
        '[system]\ntime = "discrete"\nA = [[3]]\nC = [[1]]\n[sets.omega]\ntype = "box"\n'
        'lower = [-1]\nupper = [1]\n[method]\nkey = "set-invariant"\nomega = "omega"\n'
        "lambda = 0.9\nL = [-2.5]\n[simulate]\nhorizon = 40\nx0 = [1]\nxhat0 = [0.5]\n"
    )
    sp = load_spec_text(text, "u.toml")
    rep = api.design(sp)
    assert rep.exit_code() == 0
    res = api.simulate(sp, rep, law="linear")
    e = res.extra["e_paper"][:, 0]
    np.testing.assert_allclose(e, 0.5 ** np.arange(1, 42), rtol=1e-12)
    assert res.x[-1, 0] == pytest.approx(3.0**40)
    assert res.info["error_in_polyhedron"] and "exit_code" not in res.info


THIN_OMEGA = spec_text(
    A="[[0.5, 0.2], [0.1, 0.4]]",
    B1="[0.01, 0]",
    omega='type = "polytope"\nG = [[1, -1], [-1, 1], [1, 1], [-1, -1]]\ng = [1e-12, 1e-12, 1, 1]',
    alg="general",
)


def test_a_set_too_thin_for_float_hulls_is_inconclusive_naming_the_file_and_sets() -> None:
    """Ω = {|e₁ − e₂| ≤ 10⁻¹², |e₁ + e₂| ≤ 1}: qhull cannot build the float hull, exit 4
    with one line naming the spec file and the sets (it named neither; fuzz report, session
    17). (The session-17 Ω, {|e₁| ≤ 10⁻⁹, |e₂| ≤ 1}, is thin only along an axis: the design
    now runs it in Ω-unit coordinates, scaling.py; a diagonal sliver stays too thin.)"""
    from obsdesign.errors import InconclusiveError

    with pytest.raises(InconclusiveError) as e:
        api.design(load_spec_text(THIN_OMEGA, "thin.toml"))
    msg = str(e.value)
    assert msg.startswith("thin.toml: a float polytope computation failed")
    assert "[sets.omega], [sets.D]" in msg and "\n" not in msg


@pytest.mark.parametrize(
    ("old", "new", "key", "says"),
    [
        (  # Ω of dimension 3 for 2 states (explicit dim): numpy matmul failure, exit 3
            'type = "symmetric-polytope"\nQ = [[1, 0], [0, 1]]',
            'type = "box"\ndim = 3\nlower = [-1, -1, -1]\nupper = [1, 1, 1]',
            "method.omega",
            "expected a set of dimension 2 (the states), got [sets.omega] of dimension 3",
        ),
        (  # Ω names the 1-dimensional D
            'omega = "omega"',
            'omega = "D"',
            "method.omega",
            "got [sets.D] of dimension 1",
        ),
        (  # D of dimension 2 for one column of B1: the message printed "set dim = 1"
            "dim = 1\nlower = [-0.1]\nupper = [0.1]",
            "dim = 2\nlower = [-0.1, -0.1]\nupper = [0.1, 0.1]",
            "method.disturbance",
            "expected a set of dimension 1 (columns of B1), got [sets.D] of dimension 2",
        ),
        (  # no B1 but a disturbance set: it said "expected a set of dimension 0"
            "B1 = [1, 1]\n",
            "",
            "method.disturbance",
            "the system has no disturbance input B1: remove disturbance",
        ),
    ],
)
def test_set_dimensions_are_checked_against_the_plant(old, new, key, says) -> None:
    """Set-invariant review 19: Ω and D of the wrong dimension are exit 2 naming the key and
    the set, for every algorithm (Ω's was an internal failure in numpy, exit 3)."""
    text = spec_text()
    assert old in text
    text = text.replace(old, new, 1)
    for alg in ("symmetric", "general", "none"):
        with pytest.raises(SpecError) as e:
            load_spec_text(
                text.replace('algorithm = "symmetric"', f'algorithm = "{alg}"'), "s.toml"
            )
        assert f"[{key}]" in str(e.value) and says in str(e.value), str(e.value)


def test_an_excess_below_float_resolution_is_not_printed_as_equal_numbers() -> None:
    """Example 7.1 with A₁₁ = 0.7 + 10⁻⁶¹: the symmetric polyhedron misses Theorem 3.1 by
    ~10⁻⁶² (exact); the note said "max ε(z) = 0.9 > λ = 0.9" (review 19), it now says the
    floats cannot show the excess."""
    path = Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml"
    text = path.read_text(encoding="utf-8").replace(
        "A = [[0.7, 0.7]", "A = [[0.7" + "0" * 60 + "1, 0.7]"
    )
    rep = api.design(load_spec_text(text, "long.toml"))
    notes = " ".join(rep.notes)
    assert "max ε(z) = λ = 0.9 in floats, exceeded in exact arithmetic" in notes
    assert "0.9 > λ = 0.9" not in notes


def test_simulated_error_keeps_its_digits_for_a_large_state() -> None:
    """Example 7.1 shifted to x0 = x̂0 = (10¹⁷, 10¹⁷): the error dynamics do not depend on the
    state, so the metrics equal those from the origin (final |e| 2.17 both ways); they were
    computed as x − (x − e) and read 1.0 (simulate review 19)."""
    path = Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml"
    text = path.read_text(encoding="utf-8")
    base = api.simulate(load_spec_text(text, "a.toml")).metrics()
    far = text.replace("x0 = [0, 0]", "x0 = [1e17, 1e17]").replace(
        "xhat0 = [0, 0]", "xhat0 = [1e17, 1e17]"
    )
    assert "1e17" in far
    shifted = api.simulate(load_spec_text(far, "b.toml")).metrics()
    assert shifted["final_error_norm"] == pytest.approx(base["final_error_norm"], rel=1e-12)


@pytest.mark.parametrize("law", [None, "online-lp", "linear"])
def test_simulate_time_limit_stops_the_run(rep71, law, monkeypatch, slow_clock) -> None:
    """``[simulate] time_limit`` / ``--option time_limit`` (default 300 s) bound the
    simulation (online-lp solves an LP at every step: a long horizon ran for hours). A clock
    past the budget stops it with exit 3 naming the key, the law and the step; the key is read
    from the spec (it was unknown) and must be > 0."""
    from pathlib import Path

    from obsdesign.errors import SolverError, SpecError

    _, out = rep71
    path = Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml"
    text = path.read_text()
    timed = api.load_spec_text(text.replace("[simulate]", "[simulate]\ntime_limit = 999", 1))
    assert timed.simulate.options.time_limit == 999
    spec = api.load_spec(path)  # the report's own spec; the budget as an option
    slow_clock()  # every look at the clock is 1000 s later
    name = law or "interpolated"
    with pytest.raises(SolverError, match=rf"within 999 s .*: the {name} law at step 0 of 17"):
        api.simulate(spec, out, law=law, time_limit=999)
    monkeypatch.undo()
    assert api.simulate(spec, out, law=law, time_limit=999).info["law"] == name
    with pytest.raises(SpecError, match=r"\[simulate\.time_limit\]"):
        api.load_spec_text(text.replace("[simulate]", "[simulate]\ntime_limit = -1", 1))


def test_simulate_time_limit_is_looked_at_every_step(rep71, monkeypatch) -> None:
    """The budget was looked at every 1,024 steps, each online-lp step an LP: time_limit = 3
    ran 55 s (responsiveness review 47). It is looked at every step."""
    from pathlib import Path

    from obsdesign.errors import SolverError
    from obsdesign.simulate.budget import TimeBudget

    _, out = rep71
    spec = api.load_spec(Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml")
    looks = []

    def expired(self) -> bool:  # the deadline passes at the third look
        looks.append(1)
        return len(looks) >= 3

    monkeypatch.setattr(TimeBudget, "expired", expired)
    with pytest.raises(SolverError, match=r"the online-lp law at step 2 of 17"):
        api.simulate(spec, out, law="online-lp", time_limit=999)


@pytest.mark.parametrize("law", ["online-lp", "interpolated", "time-varying"])
def test_one_output_laws_with_two_outputs_are_input_errors(law: str) -> None:
    """p = n − 1 = 2 (outsider trial, session 22): `--option law=online-lp` crashed inside
    slice_points with a broadcast error (exit 3, internal failure); LP (9) slices Ω along a
    scalar output. Each one-output law is now exit 2 naming the output count; the linear law
    runs."""
    text = (
        '[system]\ntime = "discrete"\nA = [[0.1, 0, 0.2], [0, 0.1, 0], [0, 0, 0.4]]\n'
        'C = [[1, 0, 0], [0, 1, 0]]\n[sets.omega]\ntype = "box"\nlower = [-1, -1, -1]\n'
        'upper = [1, 1, 1]\n[method]\nkey = "set-invariant"\nomega = "omega"\nlambda = 0.9\n'
        "[simulate]\nhorizon = 5\nx0 = [0.5, -0.5, 0.5]\nxhat0 = [0, 0, 0]\n"
    )
    spec = load_spec_text(text, "p2.toml")
    rep = api.design(spec)
    assert rep.exit_code() == 0
    with pytest.raises(InputError, match="one output") as e:
        api.simulate(spec, report=rep, law=law)
    assert e.value.exit_code == 2
    assert api.simulate(spec, report=rep, law="linear").info["law"] == "linear"


def _scaled_71(c: str, q: str = "1", b: str = "1", algorithm: str = "symmetric") -> str:
    """Example 7.1 (without its L) with C = [[c, c]], Ω = {|q e|∞ <= 1}, B1 = [b, b]: the
    reviewer's spec of the C-scaling report is c = 1e-9."""
    return f"""
[system]
time = "discrete"
A = [[0.7, 0.7], [-0.7, 0.7]]
B1 = [{b}, {b}]
C = [[{c}, {c}]]
[sets.omega]
type = "symmetric-polytope"
Q = [[{q}, 0], [0, {q}]]
[sets.D]
type = "box"
dim = 1
lower = [-1]
upper = [1]
[method]
key = "set-invariant"
omega = "omega"
disturbance = "D"
eta_bar = 0
lambda = 0.9
algorithm = "{algorithm}"
"""


@pytest.mark.parametrize(
    ("c", "q", "b", "algorithm"),
    [
        ("1e-9", "1", "1", "symmetric"),  # the reviewer's spec
        ("1e-15", "1", "1", "symmetric"),
        ("1e-15", "1", "1", "general"),
        ("1e9", "1", "1", "symmetric"),
        ("1", "1e9", "1e-9", "symmetric"),  # the state in units 1e9 (Ω of size 1e-9)
        ("1e-9", "1e-9", "1e9", "symmetric"),  # the state in units 1e-9, C unchanged
    ],
)
def test_a_pure_scaling_of_C_or_of_the_state_certifies_the_same_lambda(
    c: str, q: str, b: str, algorithm: str
) -> None:
    """Without noise, C and c·C (z scaled by c), or the state in other units (Ω, B1 and C
    rescaled), give the same estimator. C = [[1e-9, 1e-9]] failed Theorem 3.1 (1.18 > 0.9:
    the slices' float prefilter had an absolute floor of 1 on the scale of z); C = 1e-15
    with the general algorithm merged all of Z_d (absolute 1e-12); the state scaled by 1e±9
    failed with 2.15 (HiGHS drops LP (9)'s entries ~1e-9) or 0.98 (an absolute 1e-9 took
    the new vertices of an Ω of size 1e-9 for copies of Ω's). Now Theorem 3.1 is certified
    with λ = 9/10 in each; where only C changed, the polyhedron, the claims and the factor
    are those of C = [[1, 1]] and the linear gains scale by 1/c."""
    base = api.design(load_spec_text(_scaled_71("1", algorithm=algorithm), "base.toml"))
    rep = api.design(load_spec_text(_scaled_71(c, q, b, algorithm), "scaled.toml"))
    status = {x.id: x.status for x in rep.claims}
    assert status["theorem-3.1"] == ClaimStatus.CERTIFIED
    assert rep.parameters["contractivity"] <= fmpq(9, 10)
    if q == "1":  # only C scaled: the same polyhedron, claims and factor; L scales by 1/c
        assert status == {x.id: x.status for x in base.claims}
        for key in ("G", "V", "contractivity"):
            assert np.array_equal(rep.parameters[key], base.parameters[key]), key
        if algorithm == "symmetric":
            assert rep.parameters["contractivity"] == fmpq(9, 10)
            k = fmpq(1) / qmat([[c]])[0, 0]
            assert np.array_equal(rep.parameters["L"], base.parameters["L"] * k)
    else:  # the state rescaled: vertices rationalized at another scale, factor <= λ
        assert rep.exit_code() == 0 and set(status.values()) == {ClaimStatus.CERTIFIED}


def test_simulate_plot_of_a_one_state_plant(tmp_path: Path) -> None:
    """n = 1 has no coordinate pair: simulate --plot was exit 3 ("Number of columns must be a
    positive integer, not 0"; simulate-correctness trial, session 25). It draws e(k)
    against k between the interval's ends."""
    from typer.testing import CliRunner

    from obsdesign.cli import app

    spec = tmp_path / "n1.toml"
    spec.write_text(
        '[system]\ntime = "discrete"\nA = [[1.1]]\nC = [[1]]\n[sets.omega]\ntype = "box"\n'
        'lower = [-1]\nupper = [1]\n[method]\nkey = "set-invariant"\nomega = "omega"\n'
        "eta_bar = 0.1\nlambda = 0.9\n[simulate]\nhorizon = 10\nx0 = [0.5]\nxhat0 = [0]\n"
    )
    png = tmp_path / "n1.png"
    res = CliRunner().invoke(app, ["simulate", str(spec), "--plot", str(png)])
    assert res.exit_code == 0, res.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("k,admissible", [(17, True), (16, False)])
def test_admissibility_counts_only_the_samples_the_run_uses(k: int, admissible: bool) -> None:
    """η_17 at the horizon (17) enters no step of e; counted, it made admissible_scenario
    False and turned the exit-1 guard off (simulate-correctness trial, session 25). η_16
    > η̄ is inadmissible."""
    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "dorea-pimenta-7-1.toml").read_text()
    assert "horizon = 17" in text and "[simulate.noise]" not in text
    text += (
        f'\n[simulate.noise]\nkind = "windows"\nwindows = [{{ start = {k}, stop = {k}, '
        "value = [0.5] }]\n"
    )
    res = api.simulate(load_spec_text(text, "last.toml"))
    assert res.info["admissible_scenario"] is admissible


@pytest.mark.parametrize("law", ["time-varying", "interpolated"])
def test_the_time_varying_law_is_judged_only_without_disturbance(law: str) -> None:
    """Example 7.1 with e(0) = (1, −1) ∈ Ω and d_k = 1 ∈ D: the time-varying law (10), proved
    for d = η = 0 only, leaves Ω (gauge 1.057) and exited 1 beside "admissible_scenario: True"
    (simulate trial, session 27); that scenario is not admissible for it now. The interpolated
    law (12), proved for admissible d, stays inside."""
    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "dorea-pimenta-7-1.toml").read_text()
    old = "values = [1, -1, -1, 1, 1, -1, 1, -1, -1, -1, 1, -1, 1, -1, -1, -1, 1]"
    assert old in text and "xhat0 = [0, 0]" in text
    text = text.replace(old, "values = [" + ", ".join(["1"] * 17) + "]")
    text = text.replace("xhat0 = [0, 0]", "xhat0 = [-1, 1]")
    res = api.simulate(load_spec_text(text, "tv.toml"), options={"law": law})
    if law == "time-varying":
        assert res.info["max_gauge"] > 1.05 and not res.info["admissible_scenario"]
        assert res.info.get("exit_code", 0) == 0
    else:
        assert res.info["error_in_polyhedron"] and res.info["admissible_scenario"]


DIVERGING = matrix_spec_text(
    [[-0.1534, -0.6418, -0.604], [0.1031, 0.2395, 0.5455], [-0.3251, -0.03657, 0.6603]],
    [-0.0146, -0.0388, 0.0569], [[0.452, -2.03, 0.463]], 0.9914, eta_bar=0,
    omega=([-0.173, -0.94, -0.00421], [0.705, 0.147, 0.0017]), algorithm="general",
    mirror=False, delta_tol=0.001, max_iterations=25, time_limit=60,
)  # fmt: skip


def test_a_diverging_iteration_is_not_converged_exit_1_not_a_solver_failure() -> None:
    """The general algorithm grows this polyhedron to ~10⁹ Ω-units, where HiGHS fails on LP
    (9): that ended with exit 3 "HiGHS failed on LP (9)" (scaling trial, session 26). An LP
    failure past algorithms.LP_GROWTH times Ω's size is the iteration diverging, and a final
    stage that cannot finish for a run that did not converge is "not converged", exit 1."""
    with pytest.raises(InfeasibleError, match="not converged: the iteration diverges after"):
        api.design(load_spec_text(DIVERGING, "diverging.toml"))


def test_a_small_delta_tol_does_not_force_a_linear_law_with_two_outputs() -> None:
    """docs/methods/set-invariant.md said "use a small delta_tol" when the linear-law claim
    fails for p = n − 1. With λ = 0.995 this 3-state system stops at ε ≈ λ + 9·10⁻¹⁰
    (delta_tol = 10⁻⁹) with no admissible linear gain, which exact dual certificates confirm
    (set-invariant soundness trial, session 28): the claim fails, exit 1, and the docs now say
    so."""
    text = """
[system]
time = "discrete"
A = [[0.5, 0.3, 0.1], [-0.2, 0.6, 0.2], [0.1, 0.0, 0.99]]
C = [[1, 0, 0], [0, 1, 0]]
B1 = [0.02, 0.01, 0.03]
[sets.omega]
type = "polytope"
G = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1], [1, 1, 1]]
g = [1, 1, 1, 1, 1, 1, 1.5]
[sets.D]
type = "box"
dim = 1
lower = [-1]
upper = [0.5]
[method]
key = "set-invariant"
omega = "omega"
disturbance = "D"
eta_bar = 0
lambda = 0.995
algorithm = "symmetric"
delta_tol = 1e-9
"""
    rep = api.design(load_spec_text(text, "two-outputs.toml"))
    assert rep.exit_code() == 1
    law = next(c for c in rep.claims if c.id == "linear-law")
    assert law.status == ClaimStatus.FAILED and "no admissible linear gain" in law.detail
    eps = float(rep.parameters.float("history_eps")[-1])
    assert 0.995 < eps <= 0.995 * (1 + 1e-9)


def test_exact_details_show_short_decimals_alone() -> None:
    """A detail's exact value with a short finite decimal is shown alone ("0.9", not
    "9/10 ≈ 0.9"), else p/q beside its float, else the float marked ≈ (session 29)."""
    from fractions import Fraction

    from obsdesign.methods.setinvariant.claims import ExactBackend

    assert ExactBackend.show(Fraction(9, 10)) == "0.9"
    assert ExactBackend.show(Fraction(1)) == "1"
    assert ExactBackend.show(Fraction(1, 3)) == "1/3 ≈ 0.333333333333"
    assert ExactBackend.show(Fraction(10**30 + 1, 3)).startswith("≈ 3.33333333333e+29")


def test_the_gain_set_dimension_is_exact_and_rounded_vertices_are_marked() -> None:
    """Four vertices of a gain polygon 10⁻²⁴ wide were reported "dimension 1" (a float rank
    with an absolute tolerance of 10⁻¹²) beside the note that the set has an interior, and
    printed as two equal pairs without "≈" (set-invariant trial, session 31). The dimension
    is the exact rank; a rounded entry is marked."""
    from flint import fmpq

    from obsdesign.methods.setinvariant.design import _vec_text
    from obsdesign.methods.setinvariant.linear import _affine_dim

    t = fmpq(1, 10**24)
    sq = [
        np.array([fmpq(a), fmpq(b) * t], dtype=object) for a, b in [(0, 0), (1, 0), (1, 1), (0, 1)]
    ]
    assert _affine_dim(sq) == 2
    assert _affine_dim(sq[:2]) == 1 and _affine_dim(sq[:1]) == 0
    line = [np.array([fmpq(k), fmpq(k)], dtype=object) for k in range(3)]
    assert _affine_dim(line) == 1
    assert _vec_text(np.array([fmpq(2, 5), fmpq(-7, 5)], dtype=object)) == "[0.4, -1.4]"
    assert _vec_text(np.array([fmpq(2, 5) + t, fmpq(1)], dtype=object)) == "≈[0.4, 1]"


def test_notes_print_lambda_as_given_and_epsilon_on_its_side() -> None:
    """Example 7.2 with λ = 0.9999999: the note printed "max ε(z) = 1.06169 > λ = 1" (λ
    rounded by {:g}, unmarked; re-check trial, session 31). λ is printed as given and the
    float ε with "≈" and digits on its side of λ."""
    path = Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-2.toml"
    text = path.read_text(encoding="utf-8").replace("lambda = 1\n", "lambda = 0.9999999\n")
    assert "lambda = 0.9999999" in text
    rep = api.design(load_spec_text(text, "lam.toml"))
    notes = " ".join(rep.notes)
    assert "max ε(z) ≈ 1.0616869 > λ = 0.9999999" in notes, notes
    assert "λ = 1 " not in notes and "λ = 1)" not in notes


def test_eps_vs_lam_shows_the_side_exactly() -> None:
    """The printed ε lies on the side of the exact λ that the float ε lies on, with the
    fewest digits from 6; within 4 ulps and not above, "= λ in floats"."""
    from obsdesign.methods.setinvariant.design import eps_vs_lam

    lam = Q("0.9999999")
    assert eps_vs_lam("ε", 0.99999990004, lam) == "ε ≈ 0.99999990004 > λ = 0.9999999"
    assert eps_vs_lam("ε", 0.9999999500001, lam) == "ε ≈ 0.99999995 > λ = 0.9999999"
    assert eps_vs_lam("ε", 0.9000000000000002, Q("0.9")) == "ε = λ = 0.9 in floats"
    assert eps_vs_lam("ε", 0.5, Q("0.9")) == "ε ≈ 0.5 ≤ λ = 0.9"
    assert eps_vs_lam("ε", 0.9, Q("0.9")) == "ε = λ = 0.9 in floats"
    assert eps_vs_lam("ε", 0.95, Q("0.9")) == "ε ≈ 0.95 > λ = 0.9"


# -- mutation review 32 (session 31's checks) ----------------------------------------
def test_affine_dim_of_collinear_points_off_the_origin() -> None:
    pts = [np.array([fmpq(a), fmpq(b)], dtype=object) for a, b in [(1, 0), (0, 1), (2, -1)]]
    assert _affine_dim(pts) == 1
    tri = [np.array([fmpq(a), fmpq(b)], dtype=object) for a, b in [(1, 1), (2, 1), (1, 2)]]
    assert _affine_dim(tri) == 2


@pytest.mark.parametrize("lam", ["1e-17", "1e-20"])
def test_a_tiny_lambda_is_inconclusive_not_an_internal_failure(lam: str) -> None:
    """Example 7.1 with λ = 1e-17: the polytope's slice had no point in floats and numpy's
    "zero-size array to reduction" was exit 3, internal failure (set-invariant trial,
    session 39); λ = 1e-12 already gave the documented exit 4."""
    from obsdesign.errors import InconclusiveError

    spec = Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml"
    text = re.sub(r"(?m)^lambda = .*$", f"lambda = {lam}", spec.read_text(), count=1)
    with pytest.raises(InconclusiveError, match="a float polytope computation failed"):
        api.design(api.load_spec_text(text, "tiny.toml"))


@pytest.mark.parametrize("dn", ["[1, 1]", "[[1, 0, 0], [0, 1, 0]]", "[[1, 0], [0, 2]]"])
def test_a_noise_map_that_is_not_the_identity_is_bad_input(dn: str) -> None:
    """Two outputs with Dn = [1, 1] (2×1: one noise channel) was an IndexError, exit 3 (shape
    review, session 41); a 2×3 or a non-identity 2×2 Dn is the same refusal."""
    from obsdesign.errors import SpecError

    text = (
        '[system]\ntime = "discrete"\nA = [[0.5, 0.2, 0], [0, 0.5, 0.2], [0.1, 0, 0.5]]\n'
        f"C = [[1, 0, 0], [0, 1, 0]]\nDn = {dn}\n"
        '[sets.omega]\ntype = "box"\nlower = [-1, -1, -1]\nupper = [1, 1, 1]\n'
        '[method]\nkey = "set-invariant"\nomega = "omega"\neta_bar = 0\nlambda = 0.9\n'
        'algorithm = "symmetric"\n'
    )
    with pytest.raises(SpecError, match=r"\[system\.Dn\] expected the identity"):
        api.design(load_spec_text(text, "dn.toml"))


@pytest.mark.parametrize(
    "key, how",
    [
        ("G", "transpose"),  # 6×2 written 2×6: verified with exit 0 (false certificate)
        ("V", "flat"),
        ("v_breakpoints", "transpose"),
        ("breakpoints", "column"),
        ("L", "transpose"),
        ("L_admissible_vertices", "flat"),
    ],
)
def test_report_matrices_of_another_shape_fail_verify(key: str, how: str) -> None:
    """Example 7.1's report with one matrix written in another shape (the same entries
    row-major): the checks reshaped them back, and a 6×2 G written 2×6 verified with "10
    claims certified" — Ω ⊆ {G e ≤ 1} is false for the matrix as written (shape review,
    session 41). Now a failed parameters-wellformed claim naming the key."""
    from obsdesign.report.model import Report

    path = Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml"
    rep = api.design(load_spec(path))
    assert rep.exit_code() == 0
    d = rep.to_dict()
    ex = np.asarray(d["parameters"]["exact"][key], dtype=object)
    fl = np.asarray(d["parameters"][key], dtype=float)
    change = {
        "transpose": lambda a: a.reshape(a.shape[::-1]),
        "flat": lambda a: a.reshape(-1),
        "column": lambda a: a.reshape(-1, 1),
    }[how]
    d["parameters"]["exact"][key] = change(ex).tolist()
    d["parameters"][key] = change(fl).tolist()
    ver = api.verify(Report.from_dict(d)[0])
    assert ver.exit_code() != 0
    bad = [c for c in ver.claims if c.id == "parameters-wellformed"]
    assert bad and f"parameters.{key}: expected shape" in bad[0].detail, [
        (c.id, c.detail) for c in ver.failed
    ]


def test_a_gain_set_with_lines_has_no_vertices_to_report() -> None:
    """C = 0, η̄ = 0: every L gives the factor 1/2, so the admissible set of linear gains is the
    whole plane, with no vertices; cdd's one point of it, (0, 0), was reported and certified
    "exactly the vertices of the set of linear gains" (degenerate-sizes review, session 42).
    No vertices are reported, and a report listing (0, 0) fails the claim."""
    from obsdesign.report import Report

    text = (
        '[system]\ntime = "discrete"\nA = [[0.5, 0], [0, 0.5]]\nC = [[0, 0]]\n'
        '[sets.omega]\ntype = "box"\nlower = [-1, -1]\nupper = [1, 1]\n'
        '[method]\nkey = "set-invariant"\nomega = "omega"\neta_bar = 0\nlambda = 0.6\n'
    )
    rep = api.design(load_spec_text(text, "c0.toml"))
    assert rep.exit_code() == 0
    assert "L_admissible_vertices" not in rep.parameters
    d = rep.to_dict()
    d["parameters"]["L_admissible_vertices"] = [[0.0, 0.0]]
    d["parameters"]["exact"]["L_admissible_vertices"] = [["0", "0"]]
    ver = api.verify(Report.from_dict(d)[0])
    bad = [c.id for c in ver.claims if not c.ok]
    assert ver.exit_code() == 1 and "linear-gains-vertices" in bad, bad


def test_a_nan_float_bracket_is_evaluated_exactly_not_skipped() -> None:
    """An injection value (M, M) with M = 1e308 at z = 0 (a tampered report, its table
    recomputed exactly) made G v = 10M − 10M = inf − inf = NaN in the float pre-screen: every
    comparison with NaN is False, no breakpoint was evaluated exactly, the factor fell back to
    0 and verify certified theorem-3.1 and contractivity-value = 0, exit 0, for a true level of
    20M + 1/2 ≈ 2·10³⁰⁹ (statement-vs-check review, session 42). Now exit 1, theorem-3.1
    failed."""
    from fractions import Fraction as F

    from obsdesign.report import Report

    text = (
        '[system]\ntime = "discrete"\nA = [[0.5, 0], [0, 0.5]]\nC = [[10000, 0]]\n'
        '[sets.omega]\ntype = "symmetric-polytope"\nQ = [[10, 10], [10, -10]]\n'
        '[method]\nkey = "set-invariant"\nomega = "omega"\neta_bar = 0\nlambda = 0.9\n'
        'algorithm = "none"\nlinear_law = false\n'
    )
    rep = api.design(load_spec_text(text, "diamond.toml"))
    assert rep.exit_code() == 0
    d = json.loads(rep.to_json())
    p, ex = d["parameters"], d["parameters"]["exact"]
    zs = [F(z) for z in ex["breakpoints"]]
    vs = [[F(x) for x in r] for r in ex["v_breakpoints"]]
    vs[zs.index(0)] = [F(1e308), F(1e308)]
    Ls = [[(vs[j + 1][k] - vs[j][k]) / (zs[j + 1] - zs[j]) for k in range(2)] for j in range(2)]
    ws = [[vs[j][k] - zs[j] * Ls[j][k] for k in range(2)] for j in range(2)]
    for key, M in (("v_breakpoints", vs), ("L_pieces", Ls), ("w_pieces", ws)):
        ex[key] = [[str(x) for x in r] for r in M]
        p[key] = [[float(x) for x in r] for r in M]
    ex["contractivity"], p["contractivity"] = "0", 0.0
    ver = api.verify(Report.from_dict(d)[0])
    bad = [c.id for c in ver.claims if not c.ok]
    assert ver.exit_code() == 1 and "theorem-3.1" in bad and "contractivity-value" in bad, bad


def test_omega_contained_with_a_nan_float_product_is_exact() -> None:
    """G_0 v = 1e308·2 + 1e308·2 overflows to inf, and so does the prefilter's tolerance:
    max − tol = inf − inf = NaN compared False with every entry, no candidate was left (max
    of an empty sequence, an internal error) — the float prefilter must not decide anything
    then; the exact maximum over all pairs is 4·10³⁰⁸, so Ω ⊄ {G e ≤ 1}."""
    from obsdesign.methods.setinvariant.certificate import omega_contained

    G = np.array([[fmpq(10**308), fmpq(10**308)], [fmpq(1), fmpq(0)]], dtype=object)
    V = np.array([[fmpq(2), fmpq(2)]], dtype=object)
    ok, m = omega_contained(G, V)
    assert not ok and m == 4 * 10**308


def test_an_overflowing_slice_product_is_no_proof() -> None:
    """A report's polytope with a vertex p* = (T, −T), T = 10²⁹⁹, where G_i A p* = (K + 1)T −
    KT = T/2 exactly: the float product overflowed to −inf (the sign of the first overflowing
    term), its bound was NaN, p* was never evaluated exactly and φ_i came from the smallest
    point: verify certified theorem-3.1 at ≈ 0.5 for a true level of 10²⁹⁹ (float pre-screen
    review, session 42). Rows whose float products are not finite now keep every candidate."""
    from fractions import Fraction as F

    from obsdesign.report import Report

    K, T = 10**10, F(10**299)
    text = (
        f'[system]\ntime = "discrete"\nA = [[{K}, {K + 1}], [0, 0]]\nC = [[1, 1]]\n'
        '[sets.omega]\ntype = "symmetric-polytope"\nQ = [[1, 0], [0, 1]]\n'
        '[method]\nkey = "set-invariant"\nomega = "omega"\neta_bar = 0\nlambda = 0.9\n'
        'algorithm = "none"\nlinear_law = false\n'
    )
    d = json.loads(api.design(load_spec_text(text, "s.toml")).to_json())
    p, ex = d["parameters"], d["parameters"]["exact"]
    G = [[F(0), F(1)], [F(-1), F(0)], [(T + 1) / (2 * T), (T - 1) / (2 * T)]]
    G.append([-(T - 1) / (2 * T), -(T + 1) / (2 * T)])
    V = [[F(-1), F(1)], [F(1), F(1)], [T, -T], [F(-1), F(-1)]]
    zs = [F(-2), F(0), F(2)]
    vs = [[F(2 * K + 1), F(0)], [F(0), F(0)], [F(-(2 * K + 1)), F(0)]]
    Ls = [[(vs[j + 1][k] - vs[j][k]) / (zs[j + 1] - zs[j]) for k in range(2)] for j in range(2)]
    ws = [[vs[j][k] - zs[j] * Ls[j][k] for k in range(2)] for j in range(2)]
    for key, M in (("G", G), ("V", V), ("v_breakpoints", vs), ("L_pieces", Ls), ("w_pieces", ws)):
        ex[key] = [[str(x) for x in r] for r in M]
        p[key] = [[float(x) for x in r] for r in M]
    ex["breakpoints"], p["breakpoints"] = [str(z) for z in zs], [float(z) for z in zs]
    p["facets"], p["vertices"] = 4, 4
    ex["contractivity"], p["contractivity"] = str((T + 1) / (2 * T)), 0.5
    ver = api.verify(Report.from_dict(d)[0])
    status = {c.id: c.ok for c in ver.claims}
    assert ver.exit_code() == 1 and status["theorem-3.1"] is False, status


def test_subnormal_entries_of_GA_widen_the_slice_prescreen() -> None:
    """G A with subnormal entries (A = 1.5·10⁻²³ I, a polygon scaled to ~10³⁰⁰): rounding them
    to doubles is an absolute error of up to 2⁻¹⁰⁷⁵ (25 % relative), which the relative slack
    did not cover; the float order of a slice's two ends reversed, the true maximizer was
    skipped, and a tampered report (injection chosen to put the computed level exactly at λ)
    certified theorem-3.1 at 0.9 for an exact 0.9 + 4.75·10⁻²⁵ (re-check review, session 42).
    Built as the review built it; now exit 1."""
    from fractions import Fraction as F

    from obsdesign.report import Report

    u, a, lam = F(1, 2**1074), F(15, 10**24), F(9, 10)
    X = a / (3 * u)
    text = (
        '[system]\ntime = "discrete"\nA = [[1.5e-23, 0], [0, 1.5e-23]]\nC = [[1.1, 1]]\n'
        '[sets.omega]\ntype = "symmetric-polytope"\nQ = [[1, 0], [0, 1]]\n'
        '[method]\nkey = "set-invariant"\nomega = "omega"\neta_bar = 0\nlambda = 0.9\n'
        'algorithm = "none"\nlinear_law = false\n'
    )
    Bp, Cp, Dp = (F(0), F(11, 10)), (F(8, 10), F(1)), (F(12, 10), F(-1))
    t, s = F(305, 1000) / F(1835, 1000), F(153, 100) / F(386, 100)
    C1 = (Bp[0] + t * (Cp[0] - Bp[0]), Bp[1] + t * (Cp[1] - Bp[1]))
    C2 = (Cp[0] + s * (Dp[0] - Cp[0]), Cp[1] + s * (Dp[1] - Cp[1]))
    V = [(X * x, X * y) for x, y in [(F(-1), F(1)), Bp, C1, C2, Dp, (F(-1), F(-1))]]

    def facet(p, q):  # the row g with g·p = g·q = 1
        det = p[0] * q[1] - q[0] * p[1]
        return ((q[1] - p[1]) / det, (p[0] - q[0]) / det)

    G = [facet(V[k], V[(k + 1) % len(V)]) for k in range(len(V))]
    c = (F(11, 10), F(1))
    zs = sorted({c[0] * v[0] + c[1] * v[1] for v in V})
    zstar = c[0] * V[1][0] + c[1] * V[1][1]
    phi_float_max = a * (G[2][0] * X)  # the level the pre-screen kept: the point (X, 0)
    q = ((C1[0] + C2[0]) / 2 * X, (C1[1] + C2[1]) / 2 * X)  # G_2 q = 1
    vstar = ((lam - phi_float_max) * q[0], (lam - phi_float_max) * q[1])
    vs = [list(vstar) if z == zstar else [F(0), F(0)] for z in zs]
    Ls = [[(vs[j + 1][k] - vs[j][k]) / (zs[j + 1] - zs[j]) for k in range(2)] for j in range(5)]
    ws = [[vs[j][k] - zs[j] * Ls[j][k] for k in range(2)] for j in range(5)]
    d = json.loads(api.design(load_spec_text(text, "s.toml")).to_json())
    p, ex = d["parameters"], d["parameters"]["exact"]
    for key, M in (("G", G), ("V", V), ("v_breakpoints", vs), ("L_pieces", Ls), ("w_pieces", ws)):
        ex[key] = [[str(x) for x in r] for r in M]
        p[key] = [[float(x) for x in r] for r in M]
    ex["breakpoints"], p["breakpoints"] = [str(z) for z in zs], [float(z) for z in zs]
    p["facets"], p["vertices"] = len(G), len(V)
    ex["contractivity"], p["contractivity"] = str(lam), float(lam)
    ver = api.verify(Report.from_dict(d)[0])
    status = {c.id: c.ok for c in ver.claims}
    assert ver.exit_code() == 1 and status["theorem-3.1"] is False, status


NO_LINEAR_LAW = """[system]
time = "discrete"
A = [[1.44, -0.0457, -1.02, 1.51], [-0.112, 1.16, 0.879, 0.843], [0.225, -0.843, 0.267, -0.165], [-0.738, 0.738, 2.6, -0.808]]
C = [[0, 0, 0, 1], [1, 0, 0, 0], [0, 0, 1, 0]]
B1 = [-0.17, 0.6, 0.27, -0.56]

[sets.omega]
type = "symmetric-polytope"
Q = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1], [0.5, 0.25, -0.38, -0.15]]

[sets.D]
type = "box"
dim = 1
lower = [-0.071]
upper = [0.071]

[method]
key = "set-invariant"
omega = "omega"
disturbance = "D"
eta_bar = 0
lambda = 0.8
algorithm = "symmetric"
max_iterations = 60
time_limit = 90
mirror = true

[simulate]
horizon = 20
x0 = [0, 0, 0, 0]
xhat0 = [0.077, 0.13, -0.16, 0.27]
time_limit = 60
"""


def test_simulate_of_a_spec_whose_design_has_no_linear_gain_exits_1(tmp_path: Path) -> None:
    """Three outputs, λ = 0.8: the design finds no admissible linear gain (exit 1), and
    ``simulate SPEC`` said "the report has no linear gain L", exit 2 (bad input), although
    no report was given (census, session 44): exit 1, the design's own infeasibility."""
    p = tmp_path / "nolaw.toml"
    p.write_text(NO_LINEAR_LAW, encoding="utf-8")
    from typer.testing import CliRunner

    from obsdesign.cli import app

    r = CliRunner().invoke(app, ["simulate", str(p)])
    assert r.exit_code == 1, r.output
    assert "found no admissible linear gain" in r.output and "give [method] L" in r.output


def test_law_linear_where_the_design_makes_no_linear_law_is_bad_input(tmp_path: Path) -> None:
    """``simulate --option law=linear`` of Dórea–Pimenta 7.1 with linear_law = false (and no
    L) said the design "found no admissible linear gain", exit 1, though it never looks for
    one (re-check review, session 44; the census fix made every missing L exit 1): exit 2,
    naming the law."""
    from typer.testing import CliRunner

    from obsdesign.cli import app

    root = Path(__file__).resolve().parents[1]
    text = (root / "specs" / "dorea-pimenta-7-1.toml").read_text(encoding="utf-8")
    assert "L = [-0.7, -0.2212]" in text
    p = tmp_path / "nolin.toml"
    p.write_text(text.replace("L = [-0.7, -0.2212]", "linear_law = false"), encoding="utf-8")
    r = CliRunner().invoke(app, ["simulate", str(p), "-q", "--option", "law=linear"])
    assert r.exit_code == 2, r.output
    assert "law 'linear' needs a linear gain" in r.output
