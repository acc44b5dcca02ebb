"""Float-only mode of ``set-invariant`` (issue 4 item 1): without ``cdd.gmp`` the design runs
and every claim is ``numerical``, never ``certified``. The switch is
``obsdesign.sets.polytope_ops.HAVE_GMP``; here it is turned off with monkeypatch."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from obsdesign import api
from obsdesign.api import load_spec, load_spec_text
from obsdesign.certify.claim import ClaimStatus
from obsdesign.errors import SpecError
from obsdesign.methods.setinvariant import numerical
from obsdesign.params import Parameters
from obsdesign.sets import polytope_ops as po
from obsdesign.sets.polytope import check_polytope_q, vertices_exact

SPEC71 = Path(__file__).resolve().parents[1] / "specs" / "dorea-pimenta-7-1.toml"
Q2 = np.array([[-0.4412, 0.5588], [-0.8333, 0.1667], [0.9, 0.0]])


@pytest.fixture
def nogmp(monkeypatch):
    monkeypatch.setattr(po, "HAVE_GMP", False)


def _rows_up_to_sign(G: np.ndarray) -> set[tuple[float, ...]]:
    out = set()
    for r in np.asarray(G, dtype=float):
        r = r if (r[np.nonzero(np.abs(r) > 1e-12)[0][0]] > 0) else -r
        out.add(tuple(np.round(r, 4) + 0.0))
    return out


def test_example_71_without_gmp_is_numerical(nogmp, tmp_path):
    out = tmp_path / "r71.json"
    rep = api.design(SPEC71, out)
    assert rep.exit_code() == 0
    ids = {c.id for c in rep.claims}
    assert {"polyhedron-forms", "omega-contained", "theorem-3.1", "linear-law-user"} <= ids
    assert all(c.status == ClaimStatus.NUMERICAL for c in rep.claims)
    assert any("cdd.gmp is not installed" in n for n in rep.notes)
    # same polyhedron as the exact design: Q² of the paper, 2 iterations, factor 0.9
    assert rep.parameters["iterations"] == 2
    assert _rows_up_to_sign(rep.parameters.float("G")) == _rows_up_to_sign(Q2)
    assert abs(rep.parameters.float("contractivity") - 0.9) <= 1e-9
    # no fake exact values in the report
    assert "G" not in json.loads(out.read_text())["parameters"]["exact"]
    # verify (still without gmp) re-checks in floats: numerical again
    ver = api.verify(out)
    assert ver.exit_code() == 0
    assert all(c.status == ClaimStatus.NUMERICAL for c in ver.claims)
    assert {c.id for c in ver.claims} == ids


def test_tampered_G_is_caught_without_gmp(nogmp, tmp_path):
    out = tmp_path / "r71.json"
    api.design(SPEC71, out)
    d = json.loads(out.read_text())
    d["parameters"]["G"][0] = [1.1 * x for x in d["parameters"]["G"][0]]  # shrink one facet
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    rep = api.verify(bad)
    assert rep.exit_code() != 0
    assert any(c.id == "polyhedron-forms" and c.status == ClaimStatus.FAILED for c in rep.claims)
    # a worse injection at a breakpoint fails Theorem 3.1 (in floats)
    d = json.loads(out.read_text())
    d["parameters"]["v_breakpoints"][0][0] = 3.0
    bad.write_text(json.dumps(d))
    rep = api.verify(bad)
    assert any(c.id == "theorem-3.1" and c.status == ClaimStatus.FAILED for c in rep.claims)


def test_loader_without_gmp_checks_polytopes_by_lp(nogmp):
    spec = load_spec(SPEC71)  # loads (Ω checked by LPs)
    G, g = spec.sets["omega"].h_form_q()
    assert check_polytope_q(G, g) == (True, True, False)
    with pytest.raises(po.PolytopeError):
        vertices_exact(G, g)
    text = SPEC71.read_text()
    with pytest.raises(SpecError, match="unbounded"):
        load_spec_text(text.replace("Q = [[1, 0], [0, 1]]", "Q = [[1, 0]]"))
    empty = text.replace(
        'type = "symmetric-polytope"\nQ = [[1, 0], [0, 1]]',
        'type = "polytope"\nG = [[1, 0], [-1, 0], [0, 1], [0, -1]]\ng = [-1, -1, 1, 1]',
    )
    with pytest.raises(SpecError, match="empty"):
        load_spec_text(empty)


def test_with_gmp_claims_are_certified_again(monkeypatch, tmp_path):
    # the Makefile installs libcdd-dev/libgmp-dev, so pycddlib always has cdd.gmp here
    assert po.HAVE_GMP, "cdd.gmp is not installed: the set-up (make install) is broken"
    monkeypatch.setattr(po, "HAVE_GMP", False)
    out = tmp_path / "r71.json"
    api.design(SPEC71, out)
    monkeypatch.undo()
    assert po.HAVE_GMP
    rep = api.design(SPEC71)
    assert rep.exit_code() == 0
    assert all(c.status == ClaimStatus.CERTIFIED for c in rep.claims)
    assert not any("cdd.gmp is not installed" in n for n in rep.notes)
    # a float-only report does not pass the exact verify: G has no exact value
    ver = api.verify(out)
    assert ver.exit_code() != 0
    assert not any(c.status == ClaimStatus.CERTIFIED for c in ver.claims)
    assert numerical.TOL <= 1e-9


def _float_failed(d: dict, tmp_path: Path) -> set[str]:
    """Failed ids of the float certificate; verify (still without gmp) must exit 1."""
    from obsdesign.report.model import Report

    rep, problems = Report.from_dict(d)
    assert not problems, problems
    spec = load_spec_text(rep.spec, rep.spec_file)
    ids = {c.id for c in api.certify(spec, rep.parameters) if not c.ok}
    path = tmp_path / "t.json"
    path.write_text(json.dumps(d))
    assert api.verify(path).exit_code() == 1
    return ids


def test_float_backend_checks_the_spec_L(nogmp, tmp_path):
    """Issue 15 item 1 without gmp: the report's L_user replaced by the designed gain."""
    from obsdesign.certify.exact import Q

    spec = load_spec_text(SPEC71.read_text().replace("L = [-0.7, -0.2212]", "L = [0.5, 0.5]"))
    out = tmp_path / "r.json"
    rep = api.design(spec, out)
    assert {c.id for c in rep.failed} == {"linear-law-user"}
    d = json.loads(out.read_text())
    L = d["parameters"]["L"]
    d["parameters"]["L_user"] = L
    d["parameters"]["exact"]["L_user"] = [[str(Q(x)) for x in r] for r in L]
    assert _float_failed(d, tmp_path) == {"linear-law-user", "L_user-matches-spec"}


def test_float_backend_checks_the_whole_table(nogmp, tmp_path):
    """Issue 15 item 2 without gmp: an extra breakpoint z = 1/3 with v = (100, 100)."""
    from obsdesign.methods.setinvariant import laws

    out = tmp_path / "r.json"
    api.design(SPEC71, out)
    d = json.loads(out.read_text())
    p = d["parameters"]
    zs, vs = list(p["breakpoints"]), [list(v) for v in p["v_breakpoints"]]
    k = next(i for i, z in enumerate(zs) if z > 1 / 3)
    zs.insert(k, 1 / 3)
    vs.insert(k, [100.0, 100.0])
    Ls, ws = laws.pieces(zs, vs)
    p["breakpoints"], p["v_breakpoints"] = zs, vs
    p["L_pieces"], p["w_pieces"] = Ls, ws
    assert _float_failed(d, tmp_path) == {"injection-table"}
    # a tampered segment
    d = json.loads(out.read_text())
    d["parameters"]["w_pieces"][1][0] += 1e-6
    assert _float_failed(d, tmp_path) == {"injection-table"}


NODIST = (SPEC71.parents[1] / "tests" / "specs" / "setinvariant-nodist.toml").read_text()


def _tamper_float(d: dict, how: str) -> None:
    p = d["parameters"]
    if how == "omega-contained":  # shrink by 1e-6 (no disturbance: only Ω ⊆ C breaks)
        s = 1 - 1e-6
        p["G"] = [[x / s for x in r] for r in p["G"]]
        for k in ("V", "v_breakpoints", "w_pieces"):
            p[k] = [[x * s for x in r] for r in p[k]]
        p["breakpoints"] = [x * s for x in p["breakpoints"]]
    elif how == "injection-table":  # reversed order of the table
        p["breakpoints"] = p["breakpoints"][::-1]
        p["v_breakpoints"] = p["v_breakpoints"][::-1]
    elif how == "contractivity-value":
        p["contractivity"] *= 1 - 1e-6
    elif how == "linear-law":
        p["L"][1][0] = 0.0823529 + 1e-6  # beyond 7/85
    elif how == "polyhedron-forms":
        p["V"][0] = [x * (1 + 1e-6) for x in p["V"][0]]


@pytest.mark.parametrize(
    "claim,spec",
    [
        ("omega-contained", NODIST),
        ("injection-table", None),
        ("contractivity-value", None),
        ("linear-law", None),
        ("polyhedron-forms", None),
    ],
)
def test_float_backend_tamper_per_claim(nogmp, tmp_path, claim, spec):
    out = tmp_path / "r.json"
    api.design(load_spec_text(spec) if spec else SPEC71, out)
    d = json.loads(out.read_text())
    _tamper_float(d, claim)
    if claim == "injection-table":  # the reversed table: L^j, w^j of the reversed order
        from obsdesign.methods.setinvariant import laws

        Ls, ws = laws.pieces(d["parameters"]["breakpoints"], d["parameters"]["v_breakpoints"])
        d["parameters"]["L_pieces"], d["parameters"]["w_pieces"] = Ls, ws
    if claim == "linear-law":
        d["parameters"].pop("L_factor", None)
    assert _float_failed(d, tmp_path) == {claim}


def test_float_backend_necessary_condition(nogmp):
    text = api.template("set-invariant").replace('algorithm = "symmetric"', 'algorithm = "none"')
    rep = api.design(load_spec_text(text, "none.toml"))
    assert {c.id for c in rep.failed} == {"necessary-condition", "theorem-3.1"}


def test_float_backend_checks_gain_vertices(monkeypatch, tmp_path):
    """A report made with cdd.gmp, verified without it: each listed gain vertex must be
    admissible and a vertex of the admissible set (in float64)."""
    from obsdesign.certify.exact import Q

    out = tmp_path / "r.json"
    api.design(SPEC71, out)
    monkeypatch.setattr(po, "HAVE_GMP", False)
    base = json.loads(out.read_text())
    from obsdesign.report.model import Report

    rep, _ = Report.from_dict(base)
    claims = api.certify(load_spec(SPEC71), rep.parameters)
    assert all(c.status == ClaimStatus.NUMERICAL for c in claims)
    assert "linear-gains-vertices" in {c.id for c in claims}
    for l2 in ("7/85 + 1/1000000", "7/85 - 1/1000000"):  # outside; inside but not a vertex
        d = json.loads(out.read_text())
        V = d["parameters"]["exact"]["L_admissible_vertices"]
        i = next(k for k, r in enumerate(V) if r[1] == "7/85")
        q = Q(7) / 85 + (Q(1) if "+" in l2 else Q(-1)) / 10**6
        V[i][1] = str(q)
        d["parameters"]["L_admissible_vertices"][i][1] = float(q)
        assert _float_failed(d, tmp_path) == {"linear-gains-vertices"}


def test_float_backend_gain_vertex_of_the_arrangement(monkeypatch, tmp_path):
    """An intersection of two constraint lines of the admissible set that violates a third
    constraint is not admissible (it passes the vertex test alone)."""
    from itertools import combinations

    from obsdesign.certify.exact import Q
    from obsdesign.methods.setinvariant.problem import build

    out = tmp_path / "r.json"
    api.design(SPEC71, out)
    monkeypatch.setattr(po, "HAVE_GMP", False)
    d = json.loads(out.read_text())
    p = d["parameters"]
    G, V = np.array(p["G"]), np.array(p["V"])
    Af, bf = numerical.gain_constraints(build(load_spec(SPEC71)).fl, 0.9, G, V)
    for i, j in combinations(range(len(Af)), 2):
        M = Af[[i, j]]
        if abs(np.linalg.det(M)) < 1e-6:
            continue
        x = np.linalg.solve(M, bf[[i, j]])
        if (bf - Af @ x).min() < -1e-3:
            break
    else:
        raise AssertionError("no infeasible arrangement vertex")
    p["L_admissible_vertices"][0] = [float(t) for t in x]
    p["exact"]["L_admissible_vertices"][0] = [str(Q(float(t))) for t in x]
    assert _float_failed(d, tmp_path) == {"linear-gains-vertices"}


def test_float_backend_linear_gain_lp_beyond_float_range(nogmp):
    """C = [[1e300, 1]] (the CLI fuzzer's spec): without gmp the linear-gain LP's row norms
    overflowed and scipy's linprog raised ValueError (exit 3); the float backend now says
    that the LP is out of range and designs no linear law."""
    rep = api.design(SPEC71.parents[1] / "tests" / "specs" / "setinvariant-huge-C.toml")
    assert "L" not in rep.parameters
    assert any("beyond a float LP's range" in n for n in rep.notes)


def test_float_stage_keeps_the_new_vertices_of_a_small_omega(nogmp):
    """Example 7.1 with the state in units 1e9 (Ω = {|e|∞ <= 1e-9}, B1 = 1e-9·[1, 1]): the
    float stage took every new vertex within an absolute 1e-9 of one of Ω's for a copy of
    it and proved Ω itself (factor 0.98 > 0.9); the threshold is now relative to Ω's
    extent, and the polyhedron is Example 7.1's Q², scaled by 1e-9, with factor 0.9."""
    text = SPEC71.read_text(encoding="utf-8")
    old = ("B1 = [1, 1]", "Q = [[1, 0], [0, 1]]", "\nL = [-0.7, -0.2212]")
    assert all(o in text for o in old)
    text = text.replace(old[0], "B1 = [1e-9, 1e-9]").replace(old[1], "Q = [[1e9, 0], [0, 1e9]]")
    rep = api.design(load_spec_text(text.replace(old[2], ""), "small.toml"))
    assert rep.exit_code() == 0
    assert all(c.status == ClaimStatus.NUMERICAL for c in rep.claims)
    assert _rows_up_to_sign(1e-9 * rep.parameters.float("G")) == _rows_up_to_sign(Q2)
    assert abs(rep.parameters.float("contractivity") - 0.9) <= 1e-9


def test_without_gmp_the_gain_vertices_claim_says_what_it_checks(monkeypatch):
    """Without cdd.gmp the reported gain vertices are checked one by one, not enumerated: an
    exact report with one of Example 7.1's two vertices dropped verified (numerical, as it
    must) while the claim said "exact vertex enumeration (cdd.gmp)" and "1 vertices, exactly
    those of the admissible set", and linear-law said "certified factor" (statement audit,
    session 43)."""
    assert po.HAVE_GMP
    rep = api.design(SPEC71)
    V = rep.parameters["L_admissible_vertices"]
    assert len(V) == 2
    params = Parameters(dict(rep.parameters))
    params["L_admissible_vertices"] = V[:1]
    monkeypatch.setattr(po, "HAVE_GMP", False)
    claims = {c.id: c for c in api.certify(load_spec(SPEC71), params)}
    vc = claims["linear-gains-vertices"]
    assert vc.status == ClaimStatus.NUMERICAL
    assert "exact vertex enumeration" not in vc.check and "not checked" in vc.check
    assert "exactly those" not in vc.detail and "1 reported points" in vc.detail
    assert "certified" not in claims["linear-law"].detail
