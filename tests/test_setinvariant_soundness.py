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
    # the detail says by how much the factor is above λ: "= ≈ 0.9 (λ = 0.9)" alone read as a
    # pass (independent fuzz, session 38)
    rep, _ = Report.from_dict(d)
    spec = api.load_spec_text(rep.spec, rep.spec_file)
    (c,) = [c for c in api.certify(spec, rep.parameters) if c.id == "theorem-3.1"]
    m = re.search(r"\(λ = 9/10\), above λ by ([^;]+);", c.detail)
    assert m, c.detail
    excess = m.group(1).split(" ≈ ")[0].lstrip("≈ ")
    assert float(excess) == pytest.approx(float(f - fmpq(9, 10)), rel=1e-6)


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


# -- mutation review 21: certificate.py (kills the verdict-changing survivors) -----------------


def test_exact_lp9_known_answer() -> None:
    """LP (9) min ε s.t. φ + G v + δ <= ε 1 on the unit box rows, φ = (1, 0, 0, 0),
    δ = (0, 0, 1/2, 1/2): the unique optimum is v = (−1/2, 0), ε = 1/2 (1 + v₁ = −v₁,
    v₂ + 1/2 = −v₂ + 1/2), and the returned v attains ε."""
    q = fmpq
    G = np.array([[q(1), q(0)], [q(-1), q(0)], [q(0), q(1)], [q(0), q(-1)]], dtype=object)
    phi = [q(1), q(0), q(0), q(0)]
    dl = [q(0), q(0), q(1, 2), q(1, 2)]
    e, v = ce.exact_lp9(G, phi, dl)
    assert (e, v) == (q(1, 2), [q(-1, 2), q(0)])
    assert max(phi[i] + ce.po.qdot(G[i], v) + dl[i] for i in range(len(G))) == e
    # one dimension, max(2v − 1, −2v − 1, v, −v): the epigraph has the vertices (±1, 1) and
    # (0, 0); only the objective picks the minimum (0, 0), not just a feasible vertex
    G = np.array([[q(2)], [q(-2)], [q(1)], [q(-1)]], dtype=object)
    assert ce.exact_lp9(G, [q(-1), q(-1), q(0), q(0)], [q(0)] * 4) == (q(0), [q(0)])


def test_noise_vertices_are_every_sign_pattern() -> None:
    """The noise box {|η_k| <= η̄} has the 2^p vertices (±η̄, ..., ±η̄); the admissible gains
    (linear.gain_vertices) are constrained at each of them."""
    q = fmpq
    eta = q(1, 10)
    got = ce.noise_vertices(2, eta)
    assert len(got) == 4
    assert set(map(tuple, got)) == {(a, b) for a in (-eta, eta) for b in (-eta, eta)}
    assert ce.noise_vertices(1, eta) == [(-eta,), (eta,)]


def test_lp9_on_fewer_rows_without_disturbance(base_nodist: dict[str, Any]) -> None:
    """The design's LP (9) on the float hull's merged rows (``v_rows``, fewer than the exact
    G) must work without a disturbance (B1 with no columns, no D vertices: δ = 0 on those
    rows): the example without disturbance, one row dropped, still certifies λ = 9/10."""
    from obsdesign.methods.setinvariant import lps

    ex = build(api.load_spec_text(base_nodist["spec"], "nodist.toml")).ex
    assert ex.B1.shape[1] == 0 and len(ex.Dv) == 0
    G = exact(base_nodist, "G")
    vrep = ce.po.exact_h_to_v(G)
    res = ce.theorem31(ex, G, v_solver=lps.eps_batch, vrep=vrep, v_rows=ce.po.qfloat(G)[:-1])
    assert res.ok and res.factor == fmpq(9, 10)


@pytest.mark.parametrize("c", [1e-9, 1e-15, 1e-300, 1e9])
def test_theorem31_does_not_depend_on_the_scale_of_C(base71: dict[str, Any], c: float) -> None:
    """Without noise, C and c·C give the same estimator (z scales by c, v^l does not): on
    Example 7.1's polyhedron the design-mode check certifies 9/10 with the same v^l at
    Z_d = c·Z_d. The slices' float prefilter had an absolute floor (1e-9·max(1, |c·V|)):
    with C = [[1e-9, 1e-9]] every vertex fell in every slab, the float φ and so the LP (9)
    injections came from the whole polytope, and the factor was 1.18 (reviewer's report)."""
    from obsdesign.methods.setinvariant import lps

    G = exact(base71, "G")
    vrep = ce.po.exact_h_to_v(G)
    text = base71["spec"]
    assert "\nC = [[1, 1]]\n" in text
    ex1 = build(api.load_spec_text(text, "c1.toml")).ex
    exc = build(
        api.load_spec_text(text.replace("C = [[1, 1]]", f"C = [[{c!r}, {c!r}]]"), "c.toml")
    ).ex
    q = exc.C[0][0]  # the spec's decimal, exactly
    r1 = ce.theorem31(ex1, G, v_solver=lps.eps_batch, vrep=vrep)
    rc = ce.theorem31(exc, G, v_solver=lps.eps_batch, vrep=vrep)
    assert r1.ok and r1.factor == fmpq(9, 10) and r1.exact_lp == 0
    assert rc.ok and rc.factor == fmpq(9, 10) and rc.exact_lp == 0
    assert rc.zs == [q * z for z in r1.zs]
    assert rc.vs == r1.vs


def test_theorem31_missing_breakpoint_is_not_ok(base71: dict[str, Any]) -> None:
    """ce.theorem31 itself (not only the claim, which reads the note) says not ok when a
    point of Z_d is missing from the table."""
    ex = build(api.load_spec(SPEC71)).ex
    G, zs, vs = exact(base71, "G"), exact(base71, "breakpoints"), exact(base71, "v_breakpoints")
    keep = [0, 1, 3, 4]
    res = ce.theorem31(
        ex,
        G,
        vs=[list(vs[k]) for k in keep],
        zs_given=[zs[k] for k in keep],
        vrep=ce.po.exact_h_to_v(G),
    )
    assert res.ok is False and res.notes and "missing" in res.notes[0]


def _interval(lam: fmpq, d: tuple[fmpq, fmpq] | None) -> ce.ExactProblem:
    """e⁺ = 0·e + d + v, z = e, |η| <= 1/2, on the interval {|e| <= 1} (G = (1, −1)):
    φ = 0 exactly (A = 0: no float radius), δ = (d_hi, −d_lo) for D = [d_lo, d_hi], so the
    level at z^l is max(v^l + δ₁, −v^l + δ₂) and the float tolerance of a row is
    _FILTER·(|G_i||v| + |δ_i| + 1)."""
    q = fmpq
    return ce.ExactProblem(
        A=np.array([[q(0)]], dtype=object),
        B1=np.array([[q(1)]] if d else np.zeros((1, 0)), dtype=object),
        C=np.array([[q(1)]], dtype=object),
        G0=np.array([[q(1)], [q(-1)]], dtype=object),
        Vo=np.array([[q(1)], [q(-1)]], dtype=object),
        Dv=np.array([[d[0]], [d[1]]] if d else np.zeros((0, 0)), dtype=object),
        eta=q(1, 2),
        lam=lam,
    )


def _interval_theorem31(ex: ce.ExactProblem, v_at: dict[fmpq, fmpq]) -> ce.Theorem31Result:
    """Theorem 3.1 (verify) on the interval with v^l given at some points of Z_d; elsewhere
    the lowest level, v = (δ₂ − δ₁)/2; Z_d = {±1/2, ±3/2}."""
    G = np.array([[fmpq(1)], [fmpq(-1)]], dtype=object)
    vrep = ce.po.exact_h_to_v(G)
    zs, _ = ce.exact_zd(vrep.V, ex.C[0], ex.eta)
    assert zs == [fmpq(-3, 2), fmpq(-1, 2), fmpq(1, 2), fmpq(3, 2)]
    d1, d2 = ce.delta_exact(G, ex.B1, ex.Dv)
    vs = [[v_at.get(z, (d2 - d1) / 2)] for z in zs]
    return ce.theorem31(ex, G, vs=vs, zs_given=zs, vrep=vrep)


TINY_LEVEL = fmpq(1, 10**10)  # far below the float prefilter's margin (~10⁻⁷ relative)


@pytest.mark.parametrize(
    "lam, d, v",
    [
        # no disturbance, λ = 1/2: level |v| = 1/2 + 10⁻¹⁰ (|G||v| + 1 < 2 |v| + ...)
        (fmpq(1, 2), None, -(fmpq(1, 2) + TINY_LEVEL)),
        # no disturbance, λ = 3: the term |G||v| = 3 is larger than everything else
        (fmpq(3), None, -(fmpq(3) + TINY_LEVEL)),
        # D = [−7/2, 1/10], λ = 2: row 2 tight, −v + 7/2 = 2 + 10⁻¹⁰, |δ₂| = 7/2 > |v| + 1
        (fmpq(2), (fmpq(-7, 2), fmpq(1, 10)), fmpq(3, 2) - TINY_LEVEL),
    ],
)
def test_theorem31_float_bracket_holds_at_a_level_just_above_lambda(
    lam: fmpq, d: tuple[fmpq, fmpq] | None, v: fmpq
) -> None:
    """One breakpoint's exact level exceeds λ by 10⁻¹⁰: the float bracket of every row
    (up = φ_up + G v + δ + tol, low = φ_low + G v + δ − tol, tol = _FILTER·(|φ_up| + |G||v|
    + |δ| + 1) >= 0) must reach it, so the breakpoint is evaluated exactly and fails,
    whatever term of tol is the largest."""
    ex = _interval(lam, d)
    res = _interval_theorem31(ex, {fmpq(1, 2): v})
    assert not res.ok
    assert res.factor == lam + TINY_LEVEL and res.zs[res.worst] == fmpq(1, 2)


def test_theorem31_skips_only_breakpoints_bracketed_below_the_others() -> None:
    """D = [−3/2, 1/10], λ = 1: at z = 1/2 the level is 1 + 10⁻¹⁰ (row 2 tight, tol ≈
    3·10⁻⁷), at z = −1/2 it is 1 − 10⁻¹⁰ (row 1 tight, tol ≈ 2·10⁻⁷): an upper float bound
    that does not add its tolerance would leave z = 1/2 below λ and below the other
    breakpoint's lower bound, skip it and certify λ."""
    q = fmpq
    ex = _interval(q(1), (q(-3, 2), q(1, 10)))
    res = _interval_theorem31(ex, {q(1, 2): q(1, 2) - TINY_LEVEL, q(-1, 2): q(9, 10) - TINY_LEVEL})
    assert not res.ok and res.factor == 1 + TINY_LEVEL


def test_theorem31_factor_is_exact_when_a_larger_tolerance_sits_just_below() -> None:
    """The certified factor (contractivity-value) is the exact maximum, also far below λ = 2
    (no breakpoint evaluated for reaching λ): at z = −1/2 the level is 1 − 10⁻¹⁰ (row 1
    tight, tol ≈ 2·10⁻⁷), at z = 1/2 it is 1 − 2·10⁻¹⁰ (row 2 tight, tol ≈ 3·10⁻⁷); a
    lower float bound raised by its tolerance would put z = 1/2's above z = −1/2's upper
    bound, skip z = −1/2 and report 1 − 2·10⁻¹⁰."""
    q = fmpq
    ex = _interval(q(2), (q(-3, 2), q(1, 10)))
    res = _interval_theorem31(
        ex, {q(1, 2): q(1, 2) + 2 * TINY_LEVEL, q(-1, 2): q(9, 10) - TINY_LEVEL}
    )
    assert res.ok and res.factor == 1 - TINY_LEVEL and res.zs[res.worst] == q(-1, 2)


@pytest.mark.parametrize("shift", [1e-12, -1e-12])
def test_design_repairs_a_rounded_v_with_the_exact_lp9(
    base71: dict[str, Any], shift: float
) -> None:
    """Design mode: Example 7.1's float LP (9) optimum is λ = 0.9 at every breakpoint; with
    every float v^l moved by 10⁻¹² the rounded v misses λ at some breakpoint, and the exact
    LP (9) (cdd.gmp) must replace it there: certified with factor 9/10, and verify (the
    table recomputed from the returned v^l) agrees."""
    from obsdesign.methods.setinvariant import lps

    ex = build(api.load_spec(SPEC71)).ex
    G = exact(base71, "G")
    vrep = ce.po.exact_h_to_v(G)

    def solver(Gf: np.ndarray, phi: np.ndarray, dl: np.ndarray, deadline: Any = None) -> Any:
        er = lps.eps_batch(Gf, phi, dl, deadline=deadline)
        assert abs(float(er.eps.max()) - float(ex.lam)) < 1e-12  # tight: the exact LP is needed
        er.v = er.v + shift
        return er

    res = ce.theorem31(ex, G, v_solver=solver, vrep=vrep)
    assert res.exact_lp >= 1 and res.ok and res.factor == fmpq(9, 10)
    again = ce.theorem31(ex, G, vs=res.vs, zs_given=res.zs, vrep=vrep)
    assert again.ok and again.factor == res.factor and again.eps == res.eps


def test_omega_contained_prefilter_keeps_pairs_within_float_error() -> None:
    """Ω ⊆ {G e <= 1}: two rows of size ~10⁶ whose products with Ω's vertex are exactly
    1 + 10⁻¹³ (row 0: not contained) and 1 − 10⁻¹³ (row 1), while in floats (error ~10⁻¹⁰
    from rounding entries of size 10⁶) row 1 is ~7·10⁻¹⁰ above row 0: the prefilter's margin
    (relative to max |G||V|) must keep row 0, so the exact max is 1 + 10⁻¹³."""
    q = fmpq
    x, y = q(7, 3), q(7, 3) + q(1, 10**6)
    a, c = q(1000000713587629, 1000000007), q(1000000997137014, 1000000007)
    b, d = (a * x - 1 - q(1, 10**13)) / y, (c * x - 1 + q(1, 10**13)) / y
    G = np.array([[a, -b], [c, -d]], dtype=object)
    Vo = np.array([[x, y]], dtype=object)
    M = ce.po.qfloat(G) @ ce.po.qfloat(Vo).T
    assert M[1, 0] - M[0, 0] > 1e-10  # the float order is the wrong way round
    assert ce.omega_contained(G, Vo) == (False, 1 + q(1, 10**13))


def test_theorem31_float_bracket_covers_the_rounding_of_large_cancelling_terms() -> None:
    """A thin parallelogram (rows ±(10⁶, −10⁶ + 1/3), ±(1, 1)), A = 0, λ = 1: at one
    breakpoint row 0 gives exactly 1 + 10⁻¹³ from terms of size ~10⁶ whose float sum is
    ~1 − 7·10⁻¹¹, at another exactly 1 − 10⁻¹³ computed as ~1 + 9·10⁻¹¹. The float bracket's
    margin must grow with the size of the terms (_FILTER·|G||v|), or the first breakpoint is
    bracketed below the second, skipped, and λ certified."""
    q = fmpq
    K = q(10**6)
    G = np.array([[K, -K + q(1, 3)], [-K, K - q(1, 3)], [q(1), q(1)], [q(-1), q(-1)]], dtype=object)
    ex = _undisturbed(np.zeros((2, 2), dtype=object) + q(0), [q(1), q(0)], G, q(1, 10))
    vrep = ce.po.exact_h_to_v(G)
    zs, _ = ce.exact_zd(vrep.V, ex.C[0], ex.eta)

    def v_for(level: fmpq, y: fmpq) -> list[fmpq]:  # row 0 reaches ``level`` exactly
        return [y + (level - y / 3) / K, y]

    t = q(1, 10**13)
    vs = [[q(0), q(0)] for _ in zs]
    vs[0] = v_for(1 + t, q(276899738, 1000000007))
    vs[1] = v_for(1 - t, q(367919309, 1000000007))
    Gf = ce.po.qfloat(G)
    fl = [float(Gf[0] @ ce.po.qfloat(np.array(v, dtype=object))) for v in vs[:2]]
    assert fl[0] < 1 - 5e-11 and fl[1] > 1 + 5e-11  # the floats order them the wrong way
    res = ce.theorem31(ex, G, vs=vs, zs_given=zs, vrep=vrep)
    assert not res.ok and res.factor == 1 + t


def test_delta_of_a_single_point_disturbance_set() -> None:
    """A disturbance set D = {1/4} (a polytope of one point, accepted by the spec) has one
    vertex, and δ_i = G_i B1 (1/4) must still count it (it is not "no disturbance")."""
    text = SPEC71.read_text().replace(
        'type = "box"\ndim = 1\nlower = [-1]\nupper = [1]',
        'type = "polytope"\ndim = 1\nG = [[1], [-1]]\ng = [0.25, -0.25]',
    )
    ex = build(api.load_spec_text(text, "point.toml")).ex
    assert ex.Dv.shape == (1, 1) and ex.Dv[0, 0] == fmpq(1, 4)
    G = ex.G0
    want = [ce.po.qdot(G[i], ex.B1[:, 0]) * fmpq(1, 4) for i in range(len(G))]
    assert ce.delta_exact(G, ex.B1, ex.Dv) == want
    assert max(want) == fmpq(1, 4)


def test_row_bounds_hold_for_a_sure_crossing_on_an_edge_nearly_level_in_c() -> None:
    """The quadrilateral (−1, −1), (1 − δ, −1), (1 + δ, 1), (−1, 1) with δ = 2·10⁻⁹: its
    right edge spans 4·10⁻⁹ in c = (1, 0), too level for a precise float weight (error bound
    > _PRECISE: its own radius), yet crossed strictly by z = 1 (the crossing (1, 0) certainly
    exists), and neither end is within the vertex tolerance of z. The slice at z = 1 is the
    segment (1, 0)–(1, 1); for the row −y the maximum 0 is only at that crossing. The bounds
    must contain every exact φ_i and phi_exact must be it."""
    q = fmpq
    d = q(2, 10**9)
    G = np.array([[q(0), q(-1)], [q(-1), q(0)], [q(0), q(1)], [q(1), -d]], dtype=object)
    ex = _undisturbed(np.array([[q(1), q(0)], [q(0), q(1)]], dtype=object), [q(1), q(0)], G, q(0))
    vrep = ce.po.exact_h_to_v(G)
    assert sorted(map(tuple, vrep.V)) == sorted(
        [(q(-1), q(-1)), (1 - d, q(-1)), (1 + d, q(1)), (q(-1), q(1))]
    )
    _, cv = ce.exact_zd(vrep.V, ex.C[0], ex.eta)
    sl = ce._Slices(ex, G, vrep, [q(1)], cv)
    _, err, sure = sl.ends[0]
    assert (err > ce._PRECISE).any() and (sure & (err > ce._PRECISE)).any()
    up, low = sl.row_bounds(0)
    pts = [(q(1), q(0)), (q(1), q(1))]
    for i in range(len(G)):
        phi = max(ce.po.qdot(sl.GA[i], p) for p in pts)
        assert low[i] <= float(phi) <= up[i], (i, low[i], float(phi), up[i])
    assert sl.phi_exact(0) == {i: max(ce.po.qdot(sl.GA[i], p) for p in pts) for i in range(len(G))}


@pytest.mark.parametrize(
    "sign, K, d",
    [(1, 1, fmpq(1, 10**12)), (-1, 1, fmpq(1, 10**12)), (1, 10**4, fmpq(1, 10**13))],
)
def test_phi_ignores_a_vertex_just_outside_the_slab(sign: int, K: int, d: fmpq) -> None:
    """The quadrilateral K·(−1, −1), K·(1, −1), (K + d, K), K·(−1, 1), η̄ = K/10,
    c = ±(1, 0): at the breakpoint whose slab ends exactly at the vertex (K + d, K) (from
    above for c = (1, 0), from below for c = (−1, 0)) the slice is that vertex alone, and
    (K, −K) lies d outside the slab (inside the float tolerance, so a float candidate; for
    K = 10⁴, d = 10⁻¹³ even the same float as the slab's end), but it must not count as
    certainly in the slice: its G_i A e is 2 above the slice's for the row −y/K. φ_i is
    G_i A (K + d, K) for every row."""
    q = fmpq
    K = q(K)
    P3 = (K + d, K)
    # rows (rhs 1): bottom, left, top, and the right edge through (K, −K) and (K + d, K)
    r = K + d / 2
    G = np.array(
        [[q(0), -1 / K], [-1 / K, q(0)], [q(0), 1 / K], [1 / r, -(d / 2) / K / r]],
        dtype=object,
    )
    ex = _undisturbed(
        np.array([[q(1), q(0)], [q(0), q(1)]], dtype=object), [q(sign), q(0)], G, K / 10
    )
    vrep = ce.po.exact_h_to_v(G)
    assert sorted(map(tuple, vrep.V)) == sorted([(-K, -K), (K, -K), P3, (-K, K)])
    zs, cv = ce.exact_zd(vrep.V, ex.C[0], ex.eta)
    l = zs.index(sign * (K + d) + sign * ex.eta)  # the slab beyond (K + d, K)
    sl = ce._Slices(ex, G, vrep, zs, cv)
    up, low = sl.row_bounds(l)
    want = {i: ce.po.qdot(sl.GA[i], P3) for i in range(len(G))}
    for i in range(len(G)):
        assert low[i] <= float(want[i]) <= up[i], (i, low[i], float(want[i]), up[i])
    assert sl.phi_exact(l) == want


ASYMMETRIC_OMEGA = spec_text(
    [[0.5495, 0.0393], [-1.466, 0.9347]], [-0.00175, -0.00236], [[0.62, 1.84]], 0.9369,
    eta_bar=0, omega=([-0.00118, -0.0694], [0.0325, 0.0254]), algorithm="general",
    mirror=True, delta_tol=0.001, max_iterations=25,
)  # fmt: skip


def test_an_asymmetric_polyhedron_needs_only_a_translate_of_B1_D_inside() -> None:
    """Ω = [−0.00118, 0.0325] × [−0.0694, 0.0254] is contractive (Theorem 3.1 certified,
    factor 0.68), but max_i δ_i = 175/118 > λ: the centred inclusion λΩ ⊇ B1·D is necessary
    only for a polyhedron symmetric about 0, and the design ended with exit 1 (set-invariant
    scaling trial, session 26). Only a translate must fit (the injection at e = 0 may shift
    B1·D): the claim then says so and is decided by an exact LP."""
    rep = api.design(api.load_spec_text(ASYMMETRIC_OMEGA, "asym.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    (nc,) = [c for c in rep.claims if c.id == "necessary-condition"]
    assert "B1·D + v for some v" in nc.statement and nc.status == ClaimStatus.CERTIFIED
    assert api.verify(rep).exit_code() == 0


@pytest.mark.parametrize(("lam", "holds"), [(fmpq(19, 20), True), (fmpq(19, 20) - TINY, False)])
def test_the_translated_necessary_condition_at_its_exact_boundary(lam: fmpq, holds: bool) -> None:
    """P = [−1, 3] × [−1, 1], B1·D = [−1.9, 1.9] × {0}: the centred inclusion needs
    1.9 <= λ (fails at λ = 0.95), a translate needs width 3.8 <= 4λ: min over v of
    max_i (G_i v + δ_i) = 0.95 exactly (v = 0.95); 10⁻¹² below λ fails."""
    from obsdesign.methods.setinvariant.claims import ExactBackend

    q = fmpq
    G = np.array([[q(1, 3), q(0)], [q(-1), q(0)], [q(0), q(1)], [q(0), q(-1)]], dtype=object)
    B1 = np.array([[q(19, 10)], [q(0)]], dtype=object)
    Dv = np.array([[q(-1)], [q(1)]], dtype=object)
    A = np.array([[q(0), q(0)], [q(0), q(0)]], dtype=object)
    C = np.array([[q(1), q(0)]], dtype=object)
    ex = ce.ExactProblem(A, B1, C, G, ce.po.exact_h_to_v(G).V, Dv, q(0), lam)
    b = ExactBackend(ex, None)
    assert b.necessary(G) == (False, q(19, 10))
    ok, eps = b.necessary_shifted(G)
    assert eps == q(19, 20) and ok is holds


def test_admissibility_reads_noise_and_disturbance_at_their_own_scale() -> None:
    """Session 37 (after re-check trial 36): the scenario's admissibility took |η| ≤ η̄ + 10⁻¹²
    and the float ``D.contains`` with an absolute 10⁻¹², so η = 5·10⁻¹³ was admissible for
    η̄ = 10⁻¹⁵ and a disturbance four strip widths outside a thin sheared D at d₁ ≈ 3·10¹³ was
    in D — leaving Ω under either was exit 1, a "violation" by an inadmissible scenario.
    η̄ itself (the float of 10⁻¹⁵, above the exact bound by a rounding), and a point of D,
    stay admissible; the next float above 10⁻¹⁵ is not."""
    from types import SimpleNamespace

    from obsdesign.certify.exact import qmat, qvec
    from obsdesign.methods.setinvariant.sim import _admissible
    from obsdesign.sets import Polytope

    D = Polytope(
        qmat([[fmpq(1, 10), fmpq(3, 10)], [fmpq(-1, 10), fmpq(-3, 10)], [1, 0], [-1, 0]]),
        qvec([fmpq(1, 10**4), fmpq(1, 10**4), 30000000000001, -29999999999999]),
    )
    inside = np.array([[3e13, -1e13]])
    # (e1 + 3e2)/10 = −3.9·10⁻⁴: 4 strip widths out, but within the point's own rounding
    # (|G|·ulp(x)/2 ≈ 4.9·10⁻⁴ at 3·10¹³): the nearest float of an admissible value, so
    # admissible by the documented choice (session 37b); the float test read it inside too
    near = np.array([[30000000000000.746, -10000000000000.25]])
    assert D.contains(near, 1e-12).all()
    out = np.array([[3e13, -1e13 + 0.0078125]])  # (e1 + 3e2)/10 = 2.3·10⁻³: beyond rounding
    for eta, v in [(1e-15, 1e-15), (0.0, 0.0), (0.25, 0.25)]:
        spec = SimpleNamespace(options=SimpleNamespace(eta_bar=fmpq(0), D=None))
        spec.options.eta_bar = Q(str(eta)) if eta else fmpq(0)
        assert _admissible(spec, np.zeros((0, 0)), np.array([[v]]))
    spec = SimpleNamespace(options=SimpleNamespace(eta_bar=Q("1e-15"), D=None))
    assert not _admissible(spec, np.zeros((0, 0)), np.array([[5e-13]]))
    over = 1e-15 + np.spacing(1e-15)
    assert not _admissible(spec, np.zeros((0, 0)), np.array([[over]]))
    spec = SimpleNamespace(options=SimpleNamespace(eta_bar=fmpq(0), D=D))
    assert _admissible(spec, inside, np.zeros((1, 1)))
    assert _admissible(spec, near, np.zeros((1, 1)))
    assert not _admissible(spec, out, np.zeros((1, 1)))


@pytest.mark.parametrize("law", ["linear", "interpolated"])
def test_an_initial_error_just_outside_omega_is_no_violation(law: str) -> None:
    """Re-check trial 37: e(0) = (1 + 1.9·10⁻⁹, −1 − 1.9·10⁻⁹) is outside Ω (the vertex
    (1, −1) it shares with the polyhedron), yet "e(0) ∈ Ω" read it inside with 10⁻⁹ of the
    face's width (2·10⁻⁹) while the gauge allowed only 10⁻⁹: exit 1, "left the polyhedron",
    for a run the guarantee does not cover. e(0) ∈ Ω is now read to four float spacings."""
    text = SPEC71.read_text(encoding="utf-8").replace(
        "x0 = [0, 0]", "x0 = [1.0000000019, -1.0000000019]"
    )
    text = re.sub(r"\[simulate\.disturbance\]\nkind = .*\nvalues = .*\n", "", text)
    assert "1.0000000019" in text and "simulate.disturbance" not in text
    sp = api.load_spec_text(text, "e0.toml")
    res = api.simulate(sp, api.design(sp), law=law)
    assert res.info["e0_in_omega"] is False and res.info["max_gauge"] > 1 + 1e-9
    assert res.info.get("exit_code", 0) == 0


_FAR_FACES = """[system]
time = "discrete"
A = [[0.5, 0], [0, 0.5]]
{B1}C = [[1, 0]]
[sets.omega]
type = "polytope"
G = [[1, 0], [-1, 0], [0, 1], [0, -1]]
g = [{top}, {bottom}, 1, 1]
{D}[method]
key = "set-invariant"
omega = "omega"
{dist}eta_bar = 0
lambda = 0.9
algorithm = "none"
L = [0, 0]
[simulate]
horizon = 3
x0 = [{x0}, 0]
xhat0 = [0, 0]
{seq}"""


@pytest.mark.parametrize("case", ["e0", "d"])
def test_admissibility_reads_a_face_at_its_own_offset(case: str) -> None:
    """Re-check trial 37b: "four float spacings of a face's magnitude" — the largest |G_i v| over
    the set, here 10⁸ and 10⁷ — let e(0)₁ = 5.9·10⁻⁸ into e₁ ≤ 10⁻⁸ of Ω = [−10⁸, 10⁻⁸] × [−1, 1]
    and d₀ = 1.7·10⁻⁸ into D = [−10⁷, 10⁻⁸]: exit 1, "left the polyhedron", for runs the
    guarantee does not cover. e(0) ∈ Ω and d_k ∈ D now ask that the float be within its own
    rounding of each face (``contains_rounded``): not admissible, exit 0."""
    if case == "e0":
        kw = {"B1": "", "top": "1e-8", "bottom": "1e8", "D": "", "dist": "", "x0": "5.9e-8"}
        kw["seq"] = ""
    else:
        kw = {"B1": "B1 = [1, 0]\n", "top": "2.5e-8", "bottom": "2.5e7", "x0": "2.4e-8"}
        kw["D"] = '[sets.D]\ntype = "box"\ndim = 1\nlower = [-1e7]\nupper = [1e-8]\n'
        kw["dist"] = 'disturbance = "D"\n'
        kw["seq"] = '[simulate.disturbance]\nkind = "sequence"\nvalues = [1.7e-8, 0, 0]\n'
    sp = api.load_spec_text(_FAR_FACES.format(**kw), "far.toml")
    rep = api.design(sp)
    assert rep.exit_code() == 0
    res = api.simulate(sp, rep)
    assert res.info["max_gauge"] > 1.1
    key = "e0_in_omega" if case == "e0" else "admissible_scenario"
    assert res.info[key] is False and res.info.get("exit_code", 0) == 0


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([fmpq(1, 20), fmpq(1, 3), fmpq(2)]))
def test_phi_exact_is_the_max_over_the_slab_by_cdd(seed: int, eta: fmpq) -> None:
    """φ_i(z) of LP (6) with η̄ > 0, against an independent slice: cdd.gmp's vertices of
    {G e ≤ 1, z − η̄ ≤ c·e ≤ z + η̄} (no obsdesign code), on random 2- and 3-D polytopes.
    Dropping the edge crossings of the upper plane c·e = z + η̄ survived every test and
    certified a factor 0.9499 where the true level is 1.0024 (Example 7.1 with η̄ = 0.05,
    λ = 0.95; mutation review, session 40)."""
    import cdd
    import cdd.gmp as cddg

    q = fmpq
    rng = np.random.default_rng(seed)
    n = 2 + seed % 2
    pts = np.vstack([rng.integers(-20, 21, size=(10, n)), 21 * np.eye(n), -21 * np.eye(n)])
    G, vrep = ce.po.exact_hull(np.array([[q(int(x)) for x in p] for p in pts], dtype=object))
    Aq = np.array(
        [[q(int(x), 7) for x in row] for row in rng.integers(-5, 6, (n, n))], dtype=object
    )
    cq = [q(int(x)) for x in rng.integers(-3, 4, n)]
    if all(x == 0 for x in cq):
        return
    ex = _undisturbed(Aq, cq, G, eta)
    zs, cv = ce.exact_zd(vrep.V, ex.C[0], ex.eta)
    sl = ce._Slices(ex, G, vrep, zs, cv)

    def fr(x: fmpq) -> Fraction:
        return Fraction(int(x.p), int(x.q))

    GA = [[sum((fr(G[i, k]) * fr(Aq[k, j]) for k in range(n)), Fraction(0)) for j in range(n)]
          for i in range(len(G))]  # fmt: skip
    for l, z in enumerate(zs):
        rows = [[Fraction(1)] + [-fr(x) for x in G[i]] for i in range(len(G))]
        rows.append([fr(z + eta)] + [-fr(x) for x in cq])  # c·e ≤ z + η̄
        rows.append([-fr(z - eta)] + [fr(x) for x in cq])  # c·e ≥ z − η̄
        p = cddg.polyhedron_from_matrix(
            cddg.matrix_from_array(rows, rep_type=cdd.RepType.INEQUALITY)
        )
        verts = [[x / r[0] for x in r[1:]] for r in cddg.copy_generators(p).array if r[0] != 0]
        phis = sl.phi_exact(l)
        for i in range(len(G)):
            want = max(sum((GA[i][j] * v[j] for j in range(n)), Fraction(0)) for v in verts)
            assert fr(phis[i]) == want, (l, i)


def test_linear_law_takes_every_vertex_of_a_non_symmetric_polytope() -> None:
    """Proposition 7.1 on the triangle x ≥ −1, y ≥ −1, x + y ≤ 1 with A = diag(½, ¼), L = 0:
    the factor is max over rows and vertices of G_i A e = 3/4 (row x + y at the vertex
    (2, −1), listed last). Skipping the last vertex gave 1/2 ≤ λ = 3/5 and no test failed:
    every linear-law test had a symmetric polytope, where a vertex's mirror stands in for it
    (mutation review, session 40)."""
    q = fmpq
    ex = ce.ExactProblem(
        A=np.array([[q(1, 2), q(0)], [q(0), q(1, 4)]], dtype=object),
        B1=np.zeros((2, 0), dtype=object),
        C=np.array([[q(1), q(0)]], dtype=object),
        G0=np.zeros((0, 2), dtype=object),
        Vo=np.zeros((0, 2), dtype=object),
        Dv=np.zeros((0, 0), dtype=object),
        eta=q(0),
        lam=q(3, 5),
    )
    G = np.array([[q(-1), q(0)], [q(0), q(-1)], [q(1), q(1)]], dtype=object)
    V = np.array([[q(-1), q(-1)], [q(-1), q(2)], [q(2), q(-1)]], dtype=object)
    L = np.array([[q(0)], [q(0)]], dtype=object)
    assert ce.linear_law(ex, G, V, L) == (False, q(3, 4))
    assert ce.linear_law(ex, G, V[::-1], L) == (False, q(3, 4))


def test_linear_law_bounds_the_noise_by_the_sum_of_absolute_values() -> None:
    """Two outputs (C = I) and L = [[1, −1], [0, 0]] on the box |x|, |y| ≤ 1: the rows ±(1, 0)
    have G_i L = ±(1, −1), so their worst noise term is (|1| + |−1|)·η̄ = 2η̄, not
    |1 − 1|·η̄ = 0 (the mutant |Σ_k G_i L_k|·η̄ survived every test, all with one output;
    mutation review, session 40). With A = 0 and η̄ = 1/10 the factor is 2 + 2/10."""
    q = fmpq
    I2 = np.array([[q(1), q(0)], [q(0), q(1)]], dtype=object)
    ex = ce.ExactProblem(
        A=np.array([[q(0), q(0)], [q(0), q(0)]], dtype=object),
        B1=np.zeros((2, 0), dtype=object),
        C=I2,
        G0=np.zeros((0, 2), dtype=object),
        Vo=np.zeros((0, 2), dtype=object),
        Dv=np.zeros((0, 0), dtype=object),
        eta=q(1, 10),
        lam=q(21, 10),
    )
    G = np.array([[q(a), q(b)] for a, b in ((1, 0), (-1, 0), (0, 1), (0, -1))], dtype=object)
    V = np.array([[q(a), q(b)] for a, b in ((1, 1), (1, -1), (-1, 1), (-1, -1))], dtype=object)
    L = np.array([[q(1), q(-1)], [q(0), q(0)]], dtype=object)
    assert ce.linear_law(ex, G, V, L) == (False, q(11, 5))


@pytest.mark.parametrize("delta_tol", ["1e-09", "5e-09"])
def test_the_strict_retry_goes_on_past_the_float_lps_accuracy(delta_tol: str) -> None:
    """λ = 1 and delta_tol = 1e-9: the one retry with the hull scaled by λ/(1 + Δδ) was judged
    by the float LP (9) alone, ended "converged", and the exact factor was 1.0000000208 > λ
    — design exit 1 with converged = true (census 46). The retry goes on with a margin twice
    the float-vs-exact gap, and the design is certified."""
    from pathlib import Path

    from obsdesign import api

    # 5e-9: the retry's entry guard, factor ≤ λ(1 + 2Δδ), kept it from starting at all
    # (re-check review 46)
    text = (Path(__file__).parent / "specs" / "setinvariant-float-gap.toml").read_text("utf-8")
    spec = api.load_spec_text(text.replace("delta_tol = 1e-09", f"delta_tol = {delta_tol}"), "g")
    rep = api.design(spec)
    assert rep.exit_code() == 0, [c.detail for c in rep.failed]
    again = any("is still above λ" in n and "iterating again" in n for n in rep.notes)
    assert again == (delta_tol == "1e-09")  # at 5e-9 the first retry is enough
    assert api.verify(rep).exit_code() == 0


def test_a_strict_retry_out_of_time_leaves_the_finished_polyhedron(monkeypatch) -> None:
    """The strict retry's own time-budget stop replaced a finished exit-1 design (the factor
    6.7e-8 above λ, its polyhedron and notes) by exit 3 with no polyhedron (re-check review
    46): the polyhedron before the retry is reported, with a note."""
    from pathlib import Path

    from obsdesign import api
    from obsdesign.errors import SolverError
    from obsdesign.methods.setinvariant import design as des

    calls = []
    real = des.al.general

    def general(*a, **k):  # the strict retry (it stops at λ(1 − 1e-12)) runs out of time
        if abs(float(a[2]) - (1 - 1e-12)) < 1e-15:
            calls.append(1)
            raise SolverError("not converged within 1 s ([method] time_limit)")
        return real(*a, **k)

    monkeypatch.setattr(des.al, "general", general)
    spec = api.load_spec(Path(__file__).parent / "specs" / "setinvariant-float-gap.toml")
    rep = api.design(spec)
    assert rep.exit_code() == 1 and rep.error is None and "G" in rep.parameters
    assert [c.id for c in rep.failed] == ["theorem-3.1"]
    said = "the strict retry stopped (not converged within 1 s ([method] time_limit))"
    assert any(said in n for n in rep.notes), rep.notes
    assert len(calls) == 1


@pytest.mark.parametrize("how", ["max_iterations", "diverges", "hull", "lp-range"])
def test_a_strict_retry_that_fails_otherwise_leaves_the_finished_polyhedron(
    monkeypatch, how: str
) -> None:
    """A strict retry that reached max_iterations and whose exact check then ran out of time
    still dropped the finished polyhedron (exit 1, no polyhedron); a float hull failing in a
    retry was exit 4 with none; a dropped retry left its iterations in history_facets and a
    "diverges" note beside the converged polyhedron reported (re-check review 47). The
    polyhedron before the retry is reported, its history as it was, a note saying why."""
    import dataclasses
    from pathlib import Path

    from obsdesign import api
    from obsdesign.errors import InconclusiveError, SolverError
    from obsdesign.methods.setinvariant import design as des
    from obsdesign.sets import polytope_ops as po

    real, real_final = des.al.general, des.final_stage
    retry = []

    def general(*a, **k):
        if abs(float(a[2]) - (1 - 1e-12)) < 1e-15:  # the strict retry
            retry.append(1)
            if how == "hull":
                raise po.PolytopeError("the points are not full-dimensional")
            if how == "lp-range":  # exit 4 with no polyhedron (re-check review 47)
                raise InconclusiveError("LP (9) is out of a float LP's range")
            r = real(*a[:3], 1, *a[4:], **k)  # one iteration (it needs two)
            return dataclasses.replace(r, converged=False, diverged=how == "diverges")
        return real(*a, **k)

    def final_stage(*a, **k):  # a retry's exact check runs out of time
        if retry:
            raise SolverError("exact certificate not finished within 45 s ([method] time_limit)")
        return real_final(*a, **k)

    monkeypatch.setattr(des.al, "general", general)
    monkeypatch.setattr(des, "final_stage", final_stage)
    rep = api.design(api.load_spec(Path(__file__).parent / "specs" / "setinvariant-float-gap.toml"))
    assert rep.exit_code() == 1 and rep.error is None and "G" in rep.parameters
    assert [c.id for c in rep.failed] == ["theorem-3.1"] and retry == [1]
    p = rep.parameters
    assert p["converged"] and len(p["history_facets"]) == len(p["history_eps"]) == p["iterations"]
    said = {
        "max_iterations": "the strict retry reached its max_iterations",
        "diverges": "the strict retry diverges",
        "hull": "the strict retry stopped (a float polytope computation failed",
        "lp-range": "the strict retry stopped (LP (9) is out of a float LP's range)",
    }[how]
    assert any(n.startswith(said) for n in rep.notes), rep.notes
    assert not any(n.startswith("the general algorithm diverges") for n in rep.notes)
