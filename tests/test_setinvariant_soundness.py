"""Soundness of the set-invariant certificate (issue 15): for every claim id a tampered
parameter (exact and float changed consistently, by a small margin that makes the claim
false) fails exactly that claim, ``verify`` exits 1; the two reproductions of the issue;
known answers that kill the listed mutants of ``certificate.py``; statements print exact
numbers."""

from __future__ import annotations

import copy
import json
import re
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from flint import fmpq
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from obsdesign import api
from obsdesign.certify.claim import ClaimStatus
from obsdesign.certify.exact import Q, qparse
from obsdesign.cli import app
from obsdesign.errors import SpecError
from obsdesign.methods.setinvariant import certificate as ce
from obsdesign.methods.setinvariant import laws
from obsdesign.methods.setinvariant.claims import TABLE
from obsdesign.methods.setinvariant.problem import build, necessary_condition
from obsdesign.methods.setinvariant.spectext import spec_text
from obsdesign.params import Parameters
from obsdesign.report.model import Report

ROOT = Path(__file__).resolve().parents[1]
SPEC71 = ROOT / "specs" / "dorea-pimenta-7-1.toml"
runner = CliRunner()

# Example 7.1 without disturbance (only Ω ⊆ {G e <= 1} can be made false by shrinking)
NODIST = (ROOT / "tests" / "specs" / "setinvariant-nodist.toml").read_text()

TINY = fmpq(1, 10**12)  # relative size of every tamper: false in exact AND in float64


# -- helpers --------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def base71(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("s") / "r71.json"
    rep = api.design(SPEC71, out)
    assert rep.exit_code() == 0
    return json.loads(out.read_text())


@pytest.fixture(scope="module")
def base_nodist(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("s") / "nodist.json"
    rep = api.design(api.load_spec_text(NODIST, "nodist.toml"), out)
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    return json.loads(out.read_text())


def exact(d: dict[str, Any], key: str) -> Any:
    """The exact value of a report parameter (fmpq or object array)."""
    return qparse(d["parameters"]["exact"][key])


def put(d: dict[str, Any], **values: Any) -> dict[str, Any]:
    """A copy of report ``d`` with parameters replaced, exact and float forms consistent."""
    d = copy.deepcopy(d)
    for k, v in values.items():
        if isinstance(v, (bool, int)) and not isinstance(v, fmpq):
            d["parameters"][k] = v
            continue
        js = Parameters({k: np.asarray(v, dtype=object) if isinstance(v, list) else v}).to_json()
        d["parameters"][k] = js[k]
        d["parameters"]["exact"][k] = js["exact"][k]
    return d


def failed_certify(d: dict[str, Any]) -> set[str]:
    """Failed claim ids of the method's certify on the report's parameters."""
    rep, problems = Report.from_dict(d)
    assert not problems, problems
    spec = api.load_spec_text(rep.spec, rep.spec_file)
    return {c.id for c in api.certify(spec, rep.parameters) if c.status == ClaimStatus.FAILED}


def assert_only(d: dict[str, Any], ids: set[str], tmp_path: Path) -> None:
    """Exactly ``ids`` fail (certify), verify's own failures are ``ids`` plus report-vs-fresh
    differences about them, and ``obsdesign verify`` exits 1."""
    assert failed_certify(d) == ids
    path = tmp_path / "tampered.json"
    path.write_text(json.dumps(d))
    ver = api.verify(path)
    core = {c.id for c in ver.failed if not c.id.startswith("report-")}
    assert core == ids
    assert ver.exit_code() == 1
    res = runner.invoke(app, ["verify", str(path)])
    assert res.exit_code == 1, res.output


def scaled(d: dict[str, Any], s: fmpq) -> dict[str, Any]:
    """The report's polyhedron scaled by s (G/s, V·s, breakpoints·s, v·s, w·s): the same
    design for a problem without disturbance (φ, G v are homogeneous of degree 0)."""
    G, V = exact(d, "G"), exact(d, "V")
    new: dict[str, Any] = {"G": G * (1 / s), "V": V * s}
    for k in ("breakpoints", "v_breakpoints", "w_pieces"):
        new[k] = exact(d, k) * s
    return put(d, **new)


# -- one tamper per claim id ------------------------------------------------------------------
def test_table_lists_every_claim_id() -> None:
    assert set(TABLE) == {
        "polyhedron-forms",
        "omega-contained",
        "necessary-condition",
        "theorem-3.1",
        "contractivity-value",
        "injection-table",
        "linear-law",
        "linear-factor-value",
        "linear-gains-vertices",
        "linear-law-user",
        "converged",
    }


def test_untampered_reports_verify(base71: dict[str, Any], base_nodist: dict[str, Any]) -> None:
    assert failed_certify(base71) == set()
    assert failed_certify(base_nodist) == set()
    rep, _ = Report.from_dict(base71)
    assert {c.id for c in rep.claims} == set(TABLE) - {"converged"}


def test_lambda_matches_spec(base71: dict[str, Any], tmp_path: Path) -> None:
    d = put(base71, **{"lambda": fmpq(9, 10) * (1 + TINY)})
    assert_only(d, {"lambda-matches-spec"}, tmp_path)


def test_L_user_matches_spec(base71: dict[str, Any], tmp_path: Path) -> None:
    L = exact(base71, "L_user")
    L[1, 0] = L[1, 0] * (1 + TINY)
    assert_only(put(base71, L_user=L), {"L_user-matches-spec"}, tmp_path)


def test_polyhedron_forms_vertex(base71: dict[str, Any], tmp_path: Path) -> None:
    V = exact(base71, "V")
    V[0] = V[0] * (1 + TINY)  # pushed out of {G e <= 1}: the hull of V has other facets
    assert_only(put(base71, V=V), {"polyhedron-forms"}, tmp_path)


def test_polyhedron_forms_facet(base71: dict[str, Any], tmp_path: Path) -> None:
    G = exact(base71, "G")
    G[0] = G[0] * (1 + TINY)
    assert_only(put(base71, G=G), {"polyhedron-forms"}, tmp_path)


def test_polyhedron_forms_counts(base71: dict[str, Any], tmp_path: Path) -> None:
    assert_only(put(base71, facets=7), {"polyhedron-forms"}, tmp_path)


def test_omega_contained(base_nodist: dict[str, Any], tmp_path: Path) -> None:
    """Ω's vertex (1, −1) is on the boundary; the polyhedron shrunk by 1 − 10⁻¹² leaves it
    outside, everything else (scale-invariant without disturbance) still holds."""
    d = scaled(base_nodist, 1 - TINY)
    assert_only(d, {"omega-contained"}, tmp_path)
    assert failed_certify(scaled(base_nodist, 1 + TINY)) == set()


def test_necessary_condition_boundary(base71: dict[str, Any]) -> None:
    """Example 7.1 is tight: max_i δ_i = 9/10 = λ exactly; 10⁻¹² more fails."""
    spec = api.load_spec(SPEC71)
    ex = build(spec).ex
    G = exact(base71, "G")
    ok, m = necessary_condition(G, ex.B1, ex.Dv, ex.lam)
    assert ok and m == fmpq(9, 10)
    ok, m = necessary_condition(G, ex.B1, ex.Dv * (1 + TINY), ex.lam)
    assert not ok and m == fmpq(9, 10) * (1 + TINY)


def test_necessary_condition_fails_with_theorem31(tmp_path: Path) -> None:
    """λ·{G e <= 1} ⊇ B1·D is implied by Theorem 3.1 when D is symmetric, so it cannot fail
    alone: Ω itself (algorithm none) with |d| <= 1 fails both, and nothing else."""
    text = api.template("set-invariant").replace('algorithm = "symmetric"', 'algorithm = "none"')
    out = tmp_path / "none.json"
    rep = api.design(api.load_spec_text(text, "none.toml"), out)
    assert {c.id for c in rep.failed} == {"necessary-condition", "theorem-3.1"}
    assert rep.exit_code() == 1
    assert runner.invoke(app, ["verify", str(out)]).exit_code == 1


def _worse_v(d: dict[str, Any]) -> dict[str, Any]:
    """v^l at the worst z moved so that one row exceeds λ by ~10⁻¹²; L_pieces, w_pieces and
    contractivity recomputed consistently (only Theorem 3.1 can then fail)."""
    spec = api.load_spec_text(d["spec"])
    ex = build(spec).ex
    G, zs, vs = exact(d, "G"), exact(d, "breakpoints"), exact(d, "v_breakpoints")
    vrep = ce.po.exact_h_to_v(G)
    for i in range(len(G)):
        for l in range(len(zs)):
            w = vs.copy()
            w[l] = w[l] + G[i] * TINY
            res = ce.theorem31(ex, G, vs=[list(r) for r in w], zs_given=list(zs), vrep=vrep)
            if not res.ok:
                Ls, ws = laws.pieces(list(zs), [list(r) for r in w])
                return put(
                    d,
                    v_breakpoints=w,
                    L_pieces=np.array(Ls, dtype=object),
                    w_pieces=np.array(ws, dtype=object),
                    contractivity=res.factor,
                )
    raise AssertionError("no tamper made Theorem 3.1 fail")


def test_theorem31(base71: dict[str, Any], tmp_path: Path) -> None:
    d = _worse_v(base71)
    f = exact(d, "contractivity")
    assert fmpq(9, 10) < f < fmpq(9, 10) * (1 + 10 * TINY)
    assert_only(d, {"theorem-3.1"}, tmp_path)


def test_theorem31_missing_breakpoint(base71: dict[str, Any], tmp_path: Path) -> None:
    zs, vs = exact(base71, "breakpoints"), exact(base71, "v_breakpoints")
    keep = [0, 1, 3, 4]  # drop the middle point of Z_d
    z2, v2 = zs[keep], vs[keep]
    Ls, ws = laws.pieces(list(z2), [list(r) for r in v2])
    d = put(
        base71,
        breakpoints=z2,
        v_breakpoints=v2,
        L_pieces=np.array(Ls, dtype=object),
        w_pieces=np.array(ws, dtype=object),
    )
    assert failed_certify(d) == {"theorem-3.1"}


def test_contractivity_value(base71: dict[str, Any], tmp_path: Path) -> None:
    assert_only(
        put(base71, contractivity=fmpq(9, 10) * (1 - TINY)), {"contractivity-value"}, tmp_path
    )


def test_injection_table_reproduction_2(base71: dict[str, Any], tmp_path: Path) -> None:
    """Issue 15 item 2: a breakpoint z = 1/3 with v = (100, 100), L_pieces / w_pieces
    recomputed consistently: Theorem 3.1 still holds at Z_d, the table does not."""
    zs, vs = list(exact(base71, "breakpoints")), [list(r) for r in exact(base71, "v_breakpoints")]
    k = next(i for i, z in enumerate(zs) if z > fmpq(1, 3))
    zs.insert(k, fmpq(1, 3))
    vs.insert(k, [fmpq(100), fmpq(100)])
    Ls, ws = laws.pieces(zs, vs)
    d = put(
        base71,
        breakpoints=np.array(zs, dtype=object),
        v_breakpoints=np.array(vs, dtype=object),
        L_pieces=np.array(Ls, dtype=object),
        w_pieces=np.array(ws, dtype=object),
    )
    assert_only(d, {"injection-table"}, tmp_path)


def test_injection_table_segment(base71: dict[str, Any], tmp_path: Path) -> None:
    w = exact(base71, "w_pieces")
    w[1, 0] = w[1, 0] + TINY
    assert_only(put(base71, w_pieces=w), {"injection-table"}, tmp_path)


def test_injection_table_order(base71: dict[str, Any]) -> None:
    zs, vs = exact(base71, "breakpoints"), exact(base71, "v_breakpoints")
    rev = list(range(len(zs)))[::-1]
    Ls, ws = laws.pieces(list(zs[rev]), [list(r) for r in vs[rev]])
    d = put(
        base71,
        breakpoints=zs[rev],
        v_breakpoints=vs[rev],
        L_pieces=np.array(Ls, dtype=object),
        w_pieces=np.array(ws, dtype=object),
    )
    assert failed_certify(d) == {"injection-table"}


def test_linear_law(base71: dict[str, Any], tmp_path: Path) -> None:
    """The admissible gains are L = [−7/10, l₂], l₂ ∈ [−7/15, 7/85]: l₂ = 7/85 (1 + 10⁻¹²)
    is outside; its factor (recomputed) exceeds 9/10."""
    spec = api.load_spec(SPEC71)
    ex = build(spec).ex
    G, V = exact(base71, "G"), exact(base71, "V")
    L = np.array([[fmpq(-7, 10)], [fmpq(7, 85) * (1 + TINY)]], dtype=object)
    ok, f = ce.linear_law(ex, G, V, L)
    assert not ok and f > fmpq(9, 10)
    d = put(base71, L=L, L_factor=f)
    assert_only(d, {"linear-law"}, tmp_path)
    # the failed claim states the exact excess, not "certified factor ≈ 0.9" (fuzzer)
    rep, _ = Report.from_dict(d)
    spec_ = api.load_spec_text(rep.spec, rep.spec_file)
    claim = next(c for c in api.certify(spec_, rep.parameters) if c.id == "linear-law")
    assert "certified" not in claim.detail and "exceeds λ = 9/10 by" in claim.detail


def test_linear_factor_value(base71: dict[str, Any], tmp_path: Path) -> None:
    d = put(base71, L_factor=fmpq(9, 10) * (1 - TINY))
    assert_only(d, {"linear-factor-value"}, tmp_path)


def test_linear_gains_vertices(base71: dict[str, Any], tmp_path: Path) -> None:
    Vs = exact(base71, "L_admissible_vertices")
    i = next(k for k in range(len(Vs)) if Vs[k, 1] == fmpq(7, 85))
    Vs[i, 1] = fmpq(7, 85) * (1 - TINY)  # admissible, but not a vertex
    assert_only(put(base71, L_admissible_vertices=Vs), {"linear-gains-vertices"}, tmp_path)
    assert failed_certify(put(base71, L_admissible_vertices=Vs[:1])) == {"linear-gains-vertices"}


def _spec71_with_L(L: str) -> str:
    return SPEC71.read_text().replace("L = [-0.7, -0.2212]", f"L = {L}")


def test_linear_law_user_boundary() -> None:
    """The spec's L at the end of the admissible segment certifies (factor 9/10 exactly);
    10⁻⁵ beyond it fails exactly that claim (design exit 1)."""
    rep = api.design(api.load_spec_text(_spec71_with_L("[-0.7, 0.08235]"), "in.toml"))
    assert rep.exit_code() == 0  # 0.08235 < 7/85 = 0.0823529...
    rep = api.design(api.load_spec_text(_spec71_with_L("[-0.7, 0.08236]"), "out.toml"))
    assert {c.id for c in rep.failed} == {"linear-law-user"}
    assert rep.exit_code() == 1


def test_linear_law_user_reproduction_1(tmp_path: Path) -> None:
    """Issue 15 item 1: with the spec's L = [0.5, 0.5] the design fails (factor 4.98 > 0.9);
    replacing the report's L_user by the designed gain must not make verify pass."""
    out = tmp_path / "r.json"
    rep = api.design(api.load_spec_text(_spec71_with_L("[0.5, 0.5]"), "u.toml"), out)
    user = next(c for c in rep.claims if c.id == "linear-law-user")
    assert user.status == ClaimStatus.FAILED and "4.98" in user.detail
    assert rep.exit_code() == 1
    d = json.loads(out.read_text())
    assert d["parameters"]["exact"]["L"] == [["-7/10"], ["-49/255"]]
    d = put(d, L_user=exact(d, "L"))
    assert failed_certify(d) == {"linear-law-user", "L_user-matches-spec"}
    path = tmp_path / "t.json"
    path.write_text(json.dumps(d))
    assert api.verify(path).exit_code() == 1
    assert runner.invoke(app, ["verify", str(path)]).exit_code == 1


def test_converged(base71: dict[str, Any], tmp_path: Path) -> None:
    assert_only(put(base71, converged=False), {"converged"}, tmp_path)


def test_missing_parameters(base71: dict[str, Any]) -> None:
    d = copy.deepcopy(base71)
    for k in ("breakpoints",):
        del d["parameters"][k]
        del d["parameters"]["exact"][k]
    assert failed_certify(d) == {"theorem-3.1"}
    d = copy.deepcopy(base71)
    del d["parameters"]["exact"]["G"]  # float only: not certifiable
    rep, _ = Report.from_dict(d)
    spec = api.load_spec(SPEC71)
    assert {c.id for c in api.certify(spec, rep.parameters) if not c.ok} == {"G-exact"}


# -- known answers (kill the mutants of issue 15 item 5) -------------------------------------
def test_known_answers_example_71(base71: dict[str, Any]) -> None:
    spec = api.load_spec(SPEC71)
    ex = build(spec).ex
    G, V = exact(base71, "G"), exact(base71, "V")
    # Ω ⊆ {G e <= 1} with max exactly 1 (Ω's corners (1, −1), (−1, 1) are vertices)
    assert ce.omega_contained(G, ex.Vo) == (True, fmpq(1))
    # a polyhedron that misses one corner of Ω by 10⁻¹²
    assert ce.omega_contained(G * (1 + TINY), ex.Vo) == (False, 1 + TINY)
    # δ_i = max over D of G_i B1 d: rows ±(−15/34, 19/34), ±(−5/6, 1/6), ±(9/10, 0)
    assert sorted(set(ce.delta_exact(G, ex.B1, ex.Dv))) == [
        fmpq(2, 17),
        fmpq(2, 3),
        fmpq(9, 10),
    ]
    # the linear law: the paper's L and both ends of the segment give exactly 9/10; the
    # factor is the max over vertices (+ δ), so it is 9/10 for every admissible L
    for l2 in (fmpq(-2212, 10000), fmpq(-7, 15), fmpq(7, 85)):
        L = np.array([[fmpq(-7, 10)], [l2]], dtype=object)
        assert ce.linear_law(ex, G, V, L) == (True, fmpq(9, 10))
    L = np.array([[fmpq(-7, 10)], [fmpq(-7, 15) * (1 + TINY)]], dtype=object)
    ok, f = ce.linear_law(ex, G, V, L)
    assert not ok and f > fmpq(9, 10)
    # without the δ term the factor of the paper's L would be smaller than 9/10
    L = np.array([[fmpq(-7, 10)], [fmpq(-2212, 10000)]], dtype=object)
    GM = ce.qmatmul(G, ex.A + ce.qmatmul(L, ex.C))
    no_delta = max(ce.po.qdot(GM[i], v) for i in range(len(G)) for v in V)
    assert no_delta < fmpq(9, 10)


def test_linear_law_counts_delta_and_worst_vertex() -> None:
    """One row, two vertices: the factor is max over vertices of G(A + LC)e plus δ."""
    ex = ce.ExactProblem(
        A=np.array([[fmpq(1, 2)]], dtype=object),
        B1=np.array([[fmpq(1)]], dtype=object),
        C=np.array([[fmpq(0)]], dtype=object),
        G0=np.array([[fmpq(1)], [fmpq(-1)]], dtype=object),
        Vo=np.array([[fmpq(1)], [fmpq(-1)]], dtype=object),
        Dv=np.array([[fmpq(-1, 10)], [fmpq(1, 10)]], dtype=object),
        eta=fmpq(0),
        lam=fmpq(3, 5),
    )
    G = np.array([[fmpq(1)], [fmpq(-1)]], dtype=object)
    V = np.array([[fmpq(1)], [fmpq(-1)]], dtype=object)
    L = np.array([[fmpq(0)]], dtype=object)
    assert ce.linear_law(ex, G, V, L) == (True, fmpq(3, 5))  # 1/2 + 1/10
    ex.lam = fmpq(3, 5) - TINY
    assert ce.linear_law(ex, G, V, L) == (False, fmpq(3, 5))
    # with an output and noise: A + L C = 1/4, |G L| η̄ = 1/20, δ = 1/10 -> 2/5
    ex.C = np.array([[fmpq(1)]], dtype=object)
    ex.eta = fmpq(1, 5)
    ex.lam = fmpq(2, 5)
    L = np.array([[fmpq(-1, 4)]], dtype=object)
    assert ce.linear_law(ex, G, V, L) == (True, fmpq(2, 5))


# -- statements print exact numbers ----------------------------------------------------------
def test_statements_print_exact_spec_values(base71: dict[str, Any]) -> None:
    rep, _ = Report.from_dict(base71)
    for c in rep.claims:
        for m in re.finditer(r"λ = ([0-9./-]+)", c.statement):
            assert Q(m.group(1)) == fmpq(9, 10), c.statement
    user = next(c for c in rep.claims if c.id == "linear-law-user")
    m = re.search(r"L = \[([^\]]*)\]", user.statement)
    assert m is not None
    assert [Q(x.strip()) for x in m.group(1).split(",")] == [fmpq(-7, 10), fmpq(-553, 2500)]


# -- the disturbance set lives in [sets] ------------------------------------------------------
def test_inline_disturbance_is_the_old_spelling() -> None:
    text = SPEC71.read_text().replace(
        'disturbance = "D"', 'disturbance = { type = "box", lower = [-1], upper = [1] }'
    )
    with pytest.raises(SpecError) as e:
        api.load_spec_text(text, "old.toml")
    assert e.value.exit_code == 2
    assert "[method.disturbance]" in e.value.message and "[sets.D]" in e.value.message
    assert "dim = 1" in e.value.message and "\n" not in e.value.message


def test_disturbance_set_dimension_is_checked() -> None:
    text = SPEC71.read_text().replace(
        "dim = 1\nlower = [-1]\nupper = [1]", "dim = 2\nlower = [-1, -1]\nupper = [1, 1]"
    )
    with pytest.raises(SpecError, match="dimension 1"):
        api.load_spec_text(text, "dim.toml")
    text = SPEC71.read_text().replace('disturbance = "D"\n', "")
    with pytest.raises(SpecError, match=r"\[sets.D\] with dim = 1"):
        api.load_spec_text(text, "none.toml")


def test_injection_table_shape(base71: dict[str, Any]) -> None:
    L = exact(base71, "L_pieces")
    assert failed_certify(put(base71, L_pieces=L.reshape(2, -1))) == {"injection-table"}


def test_linear_gains_vertex_listed_twice(base71: dict[str, Any]) -> None:
    Vs = exact(base71, "L_admissible_vertices")
    d = put(base71, L_admissible_vertices=np.vstack([Vs, Vs[:1]]))
    assert failed_certify(d) == {"linear-gains-vertices"}


def _undisturbed(A: np.ndarray, c: list[fmpq], G: np.ndarray, eta: fmpq) -> ce.ExactProblem:
    """An ExactProblem without disturbance (B1, Dv empty) or Ω vertices, single output c,
    λ = 1: what the slice and φ tests need."""
    n = A.shape[0]
    return ce.ExactProblem(
        A=A,
        B1=np.zeros((n, 0), dtype=object),
        C=np.array([c], dtype=object),
        G0=G,
        Vo=np.zeros((0, n), dtype=object),
        Dv=np.zeros((0, 0), dtype=object),
        eta=eta,
        lam=fmpq(1),
    )


def test_phi_is_the_max_over_the_slice_even_for_near_ties() -> None:
    """LP (6) φ_i(z) = max over the slice of G_i A e: two slice points whose values differ by
    2·10⁻¹⁰ relative (inside the float prefilter's tolerance, so both are evaluated exactly)
    must give the larger one."""
    q = fmpq
    eps = q(1, 10**10)
    G = np.array([[q(1), q(0)], [q(-1), q(0)], [q(0), q(1)], [q(0), q(-1)]], dtype=object)
    ex = _undisturbed(np.array([[q(1), eps], [q(0), q(1)]], dtype=object), [q(1), q(0)], G, q(0))
    vrep = ce.po.exact_h_to_v(G)
    zs, cv = ce.exact_zd(vrep.V, ex.C[0], ex.eta)
    assert zs == [q(-1), q(1)]
    sl = ce._Slices(ex, G, vrep, [q(1, 2)], cv)
    phi = sl.phi_exact(0)
    # the slice at z = 1/2 is {1/2} × [−1, 1]: row (1, 0) A e = 1/2 + 10⁻¹⁰ e₂, max at e₂ = 1
    assert phi[0] == q(1, 2) + eps
    assert phi[1] == -q(1, 2) + eps
    assert phi[2] == 1 and phi[3] == 1


def test_zd_includes_both_noise_shifts() -> None:
    """Z_d = {c·v ± η̄ : v vertex} (Section III): with η̄ = 1/10 on the unit box, 4 points."""
    q = fmpq
    V = np.array([[q(a), q(b)] for a in (-1, 1) for b in (-1, 1)], dtype=object)
    c = np.array([q(1), q(0)], dtype=object)
    zs, cv = ce.exact_zd(V, c, q(1, 10))
    assert zs == [q(-11, 10), q(-9, 10), q(9, 10), q(11, 10)]
    assert sorted(set(cv)) == [q(-1), q(1)]


def test_disturbance_name_must_be_a_polyhedron_in_sets() -> None:
    text = SPEC71.read_text()
    with pytest.raises(SpecError, match=r"\[method.disturbance\] expected the name of a set"):
        api.load_spec_text(text.replace('disturbance = "D"', 'disturbance = "nope"'), "n.toml")
    ell = text.replace(
        'type = "box"\ndim = 1\nlower = [-1]\nupper = [1]', 'type = "ellipsoid"\ndim = 1\nE = [[1]]'
    )
    with pytest.raises(SpecError, match=r"\[method.disturbance\] expected a box or"):
        api.load_spec_text(ell, "e.toml")
    # a polytope D of dimension 1 is accepted and designs the same polyhedron
    poly = text.replace(
        'type = "box"\ndim = 1\nlower = [-1]\nupper = [1]',
        'type = "polytope"\ndim = 1\nG = [[1], [-1]]\ng = [1, 1]',
    )
    rep = api.design(api.load_spec_text(poly, "p.toml"))
    assert rep.exit_code() == 0 and rep.parameters["contractivity"] == fmpq(9, 10)


def test_multi_output_needs_its_linear_law(tmp_path: Path) -> None:
    """p = n − 1 = 2 outputs: the linear law is the only injection; a report without L (or
    with L just outside the admissible set) fails linear-law."""
    text = spec_text(
        [[0.5, 0.1, 0], [0, 0.5, 0], [0, 0, 0.5]],
        [1, 1, 1],
        [[1, 0, 0], [0, 1, 0]],
        0.9,
        bound=0.1,
        eta_bar=None,
    )
    out = tmp_path / "m.json"
    rep = api.design(api.load_spec_text(text, "m.toml"), out)
    assert rep.exit_code() == 0
    d = json.loads(out.read_text())
    base = copy.deepcopy(d)
    for k in ("L", "L_factor", "L_admissible_vertices"):
        d["parameters"].pop(k, None)
        d["parameters"]["exact"].pop(k, None)
    assert failed_certify(d) == {"linear-law"}
    # the designed L scaled until its factor exceeds λ
    spec = api.load_spec_text(text, "m.toml")
    ex = build(spec).ex
    G, V, L = exact(base, "G"), exact(base, "V"), exact(base, "L")
    s = fmpq(2)
    for _ in range(60):
        ok, f = ce.linear_law(ex, G, V, L * s)
        if not ok:
            break
        s *= 2
    assert not ok
    d = put(base, L=L * s, L_factor=f)
    assert failed_certify(d) == {"linear-law"}


@pytest.mark.parametrize("spec", ["dorea-pimenta-7-1.toml", "dorea-pimenta-7-2.toml"])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_theorem31_holds_with_float_crossings_off_by_their_error_bound(
    spec: str, sign: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The certificate's float prefilter widens each edge crossing's φ value by the bound on
    its float weight's error (_weight_error): with every float crossing moved along its edge
    by that whole bound, verify gives the same claims."""
    root = Path(__file__).resolve().parents[1]
    rep = api.design(api.load_spec(root / "specs" / spec))
    before = [(c.id, c.status, c.statement) for c in api.verify(rep).claims]
    init = ce._Slices.__init__
    moved = []

    def shifted(self, *args: Any, **kwargs: Any) -> None:
        init(self, *args, **kwargs)
        for l, (dirs, err, _) in enumerate(self.ends):
            self.ptsf[l] = self.ptsf[l] + sign * err[:, None] * dirs
            moved.append(float(np.abs(err[:, None] * dirs).max(initial=0.0)))

    monkeypatch.setattr(ce._Slices, "__init__", shifted)
    after = [(c.id, c.status, c.statement) for c in api.verify(rep).claims]
    assert moved and after == before
    assert all(s == ClaimStatus.CERTIFIED for _, s, _ in after)


@given(
    st.fractions(-10, 10, max_denominator=10**30),
    st.fractions(-10, 10, max_denominator=10**30),
    st.floats(0.0, 1.0),
    st.integers(0, 60),
)
def test_weight_error_bounds_the_float_crossing_weight(
    a: Fraction, b: Fraction, frac: float, level: int
) -> None:
    """|w − w*| ≤ _weight_error for the float weight of an edge crossing, checked exactly,
    including edges nearly level in c (b − a down to 2⁻⁶⁰ relative)."""
    b = a + (b - a) / 2**level
    if a == b:
        return
    t_exact = a + (b - a) * Fraction(frac)
    if not (min(a, b) < t_exact < max(a, b)):
        return
    t, ca, cb = float(t_exact), np.array([float(a)]), np.array([float(b)])
    den = cb - ca
    with np.errstate(divide="ignore", invalid="ignore"):
        w = float(np.where(den == 0, 0.5, np.clip((t - ca) / den, 0.0, 1.0))[0])
    w_exact = (t_exact - a) / (b - a)
    bound = float(ce._weight_error(t, ca, cb, den)[0])
    assert abs(Fraction(w) - w_exact) <= Fraction(bound)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_row_bounds_hold_for_a_crossing_on_an_edge_nearly_level_in_c(sign: float) -> None:
    """The prefilter's bounds (row_bounds, cand_up) must contain the exact φ_i(z) even where
    the float crossing is as far from the exact one as its weight-error bound allows. The
    quadrilateral's right edge runs from (1, −1) to (1 + 10⁻²⁰, 1): in floats it is level in
    c = (1, 0) (error bound 1: anywhere on the edge); the slice at z = r = 1 + 10⁻²⁰/2 is the
    segment from (r, 0) (on that edge) to (r, 1) (on the top edge). The float crossing on
    the level edge is moved to an end of the edge (y = ±2 off): the bounds must still hold,
    checked against the exact points."""
    q = fmpq
    tiny = q(1, 10**20)
    r = q(1) + tiny / 2
    G = np.array(
        [[q(0), q(-1)], [q(-1), q(0)], [q(0), q(1)], [q(1) / r, -tiny / 2 / r]], dtype=object
    )
    ex = _undisturbed(np.array([[q(1), q(0)], [q(0), q(1)]], dtype=object), [q(1), q(0)], G, q(0))
    vrep = ce.po.exact_h_to_v(G)
    assert sorted(map(tuple, vrep.V)) == sorted(
        [(q(-1), q(-1)), (q(1), q(-1)), (q(1) + tiny, q(1)), (q(-1), q(1))]
    )
    _, cv = ce.exact_zd(vrep.V, ex.C[0], ex.eta)
    sl = ce._Slices(ex, G, vrep, [r], cv)
    dirs, err, _ = sl.ends[0]
    assert err.max() == 1.0  # the level edge: the float weight may be anywhere
    sl.ptsf[0] = sl.ptsf[0] + sign * err[:, None] * dirs
    up, low = sl.row_bounds(0)
    exact_pts = [sl._exact_point(0, sl._cand(0, j)) for j in range(len(err))]
    assert sorted(p for p in exact_pts if p is not None) == [(r, q(0)), (r, q(1))]
    for i in range(len(G)):
        phi = max(ce.po.qdot(sl.GA[i], p) for p in exact_pts if p is not None)
        assert low[i] <= float(phi) <= up[i]
        cu = sl.cand_up(0, np.array([i]))[0]
        for j, p in enumerate(exact_pts):
            if p is not None:
                assert cu[j] >= float(ce.po.qdot(sl.GA[i], p))
    assert sl.phi_exact(0) == {
        i: max(ce.po.qdot(sl.GA[i], (r, y)) for y in (q(0), q(1))) for i in range(len(G))
    }


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_row_bounds_contain_the_exact_phi_on_random_polytopes(seed: int) -> None:
    """On random 3-D polytopes (hulls of random integer points around the origin, random A
    and c), at every breakpoint:
    phi_low ≤ the exact φ_i(z) (max of G_i A e over the exact slice points) ≤ phi_up, and
    phi_exact equals that brute-force maximum."""
    q = fmpq
    rng = np.random.default_rng(seed)
    pts = np.vstack([rng.integers(-20, 21, size=(12, 3)), 21 * np.eye(3), -21 * np.eye(3)])
    G, vrep = ce.po.exact_hull(np.array([[q(int(x)) for x in p] for p in pts], dtype=object))
    Aq = np.array(
        [[q(int(x), 7) for x in row] for row in rng.integers(-5, 6, (3, 3))], dtype=object
    )
    cq = np.array([[q(int(x)) for x in rng.integers(-3, 4, 3)]], dtype=object)
    if all(x == 0 for x in cq[0]):
        return
    ex = _undisturbed(Aq, list(cq[0]), G, q(1, 3))
    zs, cv = ce.exact_zd(vrep.V, ex.C[0], ex.eta)
    sl = ce._Slices(ex, G, vrep, zs, cv)
    for l in range(len(zs)):
        up, low = sl.row_bounds(l)
        exact_pts = [sl._exact_point(l, sl._cand(l, j)) for j in range(len(sl.ends[l][1]))]
        exact_pts = [p for p in exact_pts if p is not None]
        phis = sl.phi_exact(l)
        for i in range(len(G)):
            phi = max(ce.po.qdot(sl.GA[i], p) for p in exact_pts)
            assert low[i] <= float(phi) <= up[i]
            assert phis[i] == phi
