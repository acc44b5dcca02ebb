"""The set-invariant design hands its exact hull and Theorem 3.1 result to ``certify`` of
the same Parameters object (issue 12 item 2, :mod:`obsdesign.methods.setinvariant.memo`);
``verify`` (a report read from JSON, in this process or another) recomputes everything; a
tampered parameter or spec never hits; the time budget stops the iterations with a reason."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from flint import fmpq

from obsdesign import api
from obsdesign.certify.claim import ClaimStatus
from obsdesign.errors import SolverError
from obsdesign.methods.setinvariant import memo
from obsdesign.methods.setinvariant.spectext import spec_text
from obsdesign.params import Parameters
from obsdesign.report.model import Report

ROOT = Path(__file__).resolve().parents[1]
SPEC71 = ROOT / "specs" / "dorea-pimenta-7-1.toml"

# the general algorithm as benchmarks/bench_setinvariant.py runs it
BENCH_KEYS: dict[str, object] = dict(
    algorithm="general", mirror=True, delta_tol=0.001, max_iterations=60
)

# a random 3-state system of benchmarks/bench_setinvariant.py (seed 2): one output, noise,
# a disturbance, the general algorithm
RANDOM = spec_text(
    [[0.0536, -0.1483, -0.1172], [-0.6924, 0.5104, 0.3245], [-0.0923, 0.2195, 0.0798]],
    [-0.0396, 0.0227, -0.005],
    [[0.9776, -0.3106, -0.3288]],
    0.8979,
    **BENCH_KEYS,
)


def _summary(claims: list) -> list[tuple]:
    return [(c.id, c.status, c.statement, c.detail, str(c.margin)) for c in claims]


def _hits() -> int:
    return memo.STATS["hits"]


@pytest.fixture(scope="module")
def designed() -> tuple:
    sp = api.load_spec_text(RANDOM, "random-2.toml")
    rep = api.design(sp)
    assert rep.exit_code() == 0
    return sp, rep


def test_design_records_and_certify_hits(designed: tuple) -> None:
    sp, rep = designed
    h0 = _hits()
    hit = api.certify(sp, rep.parameters)
    assert _hits() == h0 + 2  # forms and Theorem 3.1
    fresh = api.certify(sp, Parameters(dict(rep.parameters.items())))  # another object
    assert _hits() == h0 + 2
    assert _summary(hit) == _summary(fresh)
    assert all(c.status == ClaimStatus.CERTIFIED for c in hit)
    assert _summary(hit) == _summary(rep.claims)


def test_verify_recomputes_in_process(designed: tuple, tmp_path: Path) -> None:
    sp, rep = designed
    out = tmp_path / "r.json"
    out.write_text(rep.to_json())
    h0 = _hits()
    for src in (out, rep, Report.load(out)[0]):
        v = api.verify(src)
        assert v.exit_code() == 0
    assert _hits() == h0  # no lookup of a report read back, or of verify's tracked copy


def test_verify_in_a_new_process(tmp_path: Path) -> None:
    out = tmp_path / "r.json"
    api.design(SPEC71, out)
    exe = Path(sys.executable).parent / "obsdesign"
    r = subprocess.run([str(exe), "verify", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


def _tamper_same_object(rep: Report, key: str, i: int, delta: fmpq) -> None:
    """Change one entry of ``key`` in the design's own Parameters object (exact and float
    consistently: the array holds fmpq, floats are derived)."""
    a = np.array(rep.parameters[key], dtype=object, copy=True)
    flat = a.reshape(-1)
    flat[i] = flat[i] + delta
    rep.parameters[key] = a


@pytest.mark.parametrize(
    ("key", "claim"),
    [("G", "polyhedron-forms"), ("v_breakpoints", "theorem-3.1")],
)
def test_tampered_parameter_never_hits(key: str, claim: str) -> None:
    sp = api.load_spec_text(RANDOM, "random-2.toml")
    rep = api.design(sp)
    if key == "v_breakpoints":  # push the worst breakpoint's v above λ
        i = 0
        delta = fmpq(1)
    else:
        i, delta = 0, fmpq(1, 10**6)
    _tamper_same_object(rep, key, i, delta)
    h0, m0 = memo.STATS["hits"], memo.STATS["misses"]
    claims = api.certify(sp, rep.parameters)
    failed = {c.id for c in claims if c.status == ClaimStatus.FAILED}
    assert claim in failed
    if key == "G":
        assert _hits() == h0  # the forms lookup missed and nothing after it ran
    else:
        assert _hits() == h0 + 1  # forms (untouched) hits, Theorem 3.1 misses
        assert memo.STATS["misses"] == m0 + 1


def test_changed_spec_never_hits(designed: tuple) -> None:
    sp, rep = designed
    other = api.load_spec_text(RANDOM.replace("lambda = 0.8979", "lambda = 0.8978"), "b.toml")
    h0, m0 = _hits(), memo.STATS["misses"]
    claims = api.certify(other, rep.parameters)
    assert _hits() == h0 + 1  # forms does not depend on the spec; Theorem 3.1 does
    assert memo.STATS["misses"] == m0 + 1
    assert "lambda-matches-spec" in {c.id for c in claims if c.status == ClaimStatus.FAILED}


def test_fingerprint_is_exact() -> None:
    a = np.array([[fmpq(1, 3), fmpq(2)]], dtype=object)
    b = np.array([[fmpq(1, 3), fmpq(2)]], dtype=object)
    c = np.array([[fmpq(1, 3) + fmpq(1, 10**30), fmpq(2)]], dtype=object)
    assert memo.fingerprint(a) == memo.fingerprint(b)
    assert memo.fingerprint(a) != memo.fingerprint(c)
    assert memo.fingerprint(a) != memo.fingerprint(a.reshape(2, 1))
    assert memo.fingerprint([fmpq(1, 2)]) != memo.fingerprint([0.5])
    assert memo.fingerprint(np.array([0.1])) != memo.fingerprint(np.array([0.1 + 2**-56]))


def test_record_dropped_with_its_object() -> None:
    p = Parameters({"x": 1})
    rec = memo.Recorder()
    rec.put("k", ("a",), 42)
    memo.attach(p, rec)
    assert memo.recall(p, "k", ("a",)) == 42
    assert memo.recall(Parameters({"x": 1}), "k", ("a",)) is None
    i = id(p)
    del p
    assert i not in memo._MEMO


# seed 0 of the benchmark: converges in 2 iterations
SEED0 = spec_text(
    [[0.0752, -0.079, 0.3832], [0.0628, -0.3205, 0.2163], [0.7802, 0.5666, -0.421]],
    [-0.0109, -0.0623, -0.0366],
    [[-0.6233, 0.0413, -2.325]],
    0.9604,
    **BENCH_KEYS,
)


def test_time_budget_refuses_with_reason() -> None:
    sp = api.load_spec_text(SEED0.replace("max_iterations = 60", "time_limit = 1e-9"), "t.toml")
    with pytest.raises(
        SolverError,
        match=r"not converged within 1e-09 s .* / 0 iterations: the budget was used up before",
    ):
        api.design(sp)
    rep = api.design(api.load_spec_text(SEED0, "s0.toml"))  # the default budget: converges
    assert rep.exit_code() == 0 and rep.parameters["iterations"] == 2
    # iterations done, no time left for the exact stage
    from obsdesign.methods.setinvariant.design import final_stage
    from obsdesign.methods.setinvariant.problem import build

    sp = api.load_spec_text(RANDOM.replace("max_iterations = 60", "time_limit = 1e-9"), "r.toml")
    with pytest.raises(SolverError, match=r"exact certificate not started within 1e-09 s"):
        final_stage(build(sp), np.zeros((0, 3)), True, 0.8979, 0.0, sp.options)


def test_time_budget_inside_the_exact_theorem31_loop():
    from obsdesign.methods.setinvariant import certificate as ce
    from obsdesign.methods.setinvariant import lps
    from obsdesign.methods.setinvariant.problem import build
    from obsdesign.sets import polytope_ops as po

    sp = api.load_spec_text(RANDOM, "r.toml")
    ex = build(sp).ex
    G, vrep = po.exact_hull(ex.Vo)
    with pytest.raises(ce.BudgetExceeded):
        ce.theorem31(ex, G, v_solver=lps.eps_batch, vrep=vrep, deadline=0.0)
    assert ce.theorem31(ex, G, v_solver=lps.eps_batch, vrep=vrep, deadline=None).zs


def test_time_budget_stops_the_exact_hull_of_the_final_stage(monkeypatch):
    """The one uninterruptible exact step (a cdd.gmp hull, needed when the incidence proof
    of the float hull fails: switched off here) runs in a child process that the budget
    kills: 150 points on a 4-sphere (about a minute in cdd.gmp) with 1 s left are refused
    within the budget plus the child's start, with the reason."""
    import dataclasses
    import time

    from obsdesign.methods.setinvariant.design import final_stage
    from obsdesign.methods.setinvariant.problem import build
    from obsdesign.sets import polytope_ops as po

    sp = api.load_spec_text(
        spec_text(np.diag([0.5, 0.4, 0.3, 0.2]), [0.0] * 4, [[1.0, 1.0, 0.5, 0.2]], 0.9),
        "four.toml",
    )
    S = np.random.default_rng(7).normal(size=(150, 4))
    P = 3 * S / np.linalg.norm(S, axis=1)[:, None]
    monkeypatch.setattr(po, "_float_facets", lambda P, check=None: None)
    t0 = time.perf_counter()
    with pytest.raises(
        SolverError, match=r"exact certificate not finished within 1 s .*exact hull"
    ):
        final_stage(
            build(sp),
            P,
            True,
            0.9,
            t0 + 1.0,
            dataclasses.replace(sp.options, time_limit=1.0),
        )
    assert time.perf_counter() - t0 < 1.0 + 2.0


def _levels(ex, G, vrep, zs, vs) -> list[fmpq]:
    """Brute force: the exact level max_i(φ_i(z) + G_i v + δ_i) at every breakpoint, φ from
    every exact slice point (no float prefilter)."""
    from obsdesign.methods.setinvariant import certificate as ce
    from obsdesign.sets import polytope_ops as po

    GA = ce.qmatmul(G, ex.A)
    dl = ce.delta_exact(G, ex.B1, ex.Dv)
    cv = [po.qdot(ex.C[0], v) for v in vrep.V]
    out = []
    for z, v in zip(zs, vs, strict=True):
        S = po.exact_slice_points(vrep.V, vrep.edges, cv, z - ex.eta, z + ex.eta)
        out.append(
            max(max(po.qdot(GA[i], p) for p in S) + po.qdot(G[i], v) + dl[i] for i in range(len(G)))
        )
    return out


def test_theorem31_factor_is_the_max_over_every_breakpoint():
    """Theorem 3.1 evaluates exactly only the breakpoints whose float bracket can reach λ or
    the maximum. Known answer: the factor is the brute-force maximum; and a breakpoint far
    below it (skipped before), raised exactly to just above λ, fails the check, and raised
    to between the factor and λ, becomes the certified factor."""
    from obsdesign.methods.setinvariant import certificate as ce
    from obsdesign.methods.setinvariant.problem import build
    from obsdesign.sets import polytope_ops as po

    sp = api.load_spec_text(SEED0, "s0.toml")
    p = api.design(sp).parameters
    ex = build(sp).ex
    G = np.asarray(p["G"], dtype=object)
    ok, _, vrep = po.exact_check_forms(G, np.asarray(p["V"], dtype=object))
    zs = list(p["breakpoints"])
    vs = [list(r) for r in p["v_breakpoints"]]
    lv = _levels(ex, G, vrep, zs, vs)
    res = ce.theorem31(ex, G, vs=vs, zs_given=zs, vrep=vrep)
    assert ok and res.ok and res.factor == max(lv) == p["contractivity"]
    l = min(range(len(zs)), key=lambda k: lv[k])
    assert float(lv[l]) < float(res.factor) - 1e-3  # far below: its float bracket is too
    u = list(G[0])

    def raised(target: fmpq) -> list[list[fmpq]]:
        # v^l + s G_0 with the smallest s at which some row's term reaches ``target``
        base = _levels(ex, G, vrep, [zs[l]], [vs[l]])[0]
        rows = [(po.qdot(G[i], u), i) for i in range(len(G))]
        s = min((target - base) / gu for gu, i in rows if gu > 0)
        for _ in range(50):  # the level of v + s u is reached by one row at exactly target
            w = [a + s * b for a, b in zip(vs[l], u, strict=True)]
            lev = _levels(ex, G, vrep, [zs[l]], [w])[0]
            if lev == target:
                break
            s += (target - lev) / max(gu for gu, _ in rows)
        assert lev == target
        return vs[:l] + [w] + vs[l + 1 :]

    bad = raised(ex.lam * (1 + fmpq(1, 10**12)))
    r1 = ce.theorem31(ex, G, vs=bad, zs_given=zs, vrep=vrep)
    assert not r1.ok and r1.factor == ex.lam * (1 + fmpq(1, 10**12)) and r1.worst == l
    mid = (res.factor + ex.lam) / 2
    r2 = ce.theorem31(ex, G, vs=raised(mid), zs_given=zs, vrep=vrep)
    assert r2.ok and r2.factor == mid and r2.worst == l


def test_time_budget_inside_an_iteration():
    """The budget is checked inside an iteration too (between slices and LP blocks), not
    only between iterations: a deadline already past stops the first iteration."""
    from obsdesign.methods.setinvariant import algorithms as al
    from obsdesign.methods.setinvariant import lps
    from obsdesign.methods.setinvariant.budget import Timeout
    from obsdesign.methods.setinvariant.problem import build

    fl = build(api.load_spec_text(SEED0, "s0.toml")).fl
    r = al.general(fl, 0.9604, 0.9604, 60, True, deadline=0.0)
    assert r.timed_out and r.iterations == 0 and not r.converged
    assert al.general(fl, 0.9604 / 1.001, 0.9604, 60, True, deadline=None).converged
    G = fl.G0
    with pytest.raises(Timeout):
        lps.eps_batch(G, np.zeros((3, len(G))), np.zeros(len(G)), deadline=0.0)
    with pytest.raises(Timeout):
        lps.phi_at(G, fl.A, np.eye(3), np.zeros((0, 2), dtype=int), fl.C[0], 0.01, np.zeros(1), 0.0)


def test_time_budget_inside_the_hull_and_the_point_screening(monkeypatch):
    """The hull of the grown cloud and the screening of the new points are checked too (a
    4-state design grew from 5,676 to 43,564 facets in one iteration and ran 17 s against
    time_limit = 8: random-spec fuzzer): past the deadline in the second iteration's hull,
    the run stops with the first iteration's polyhedron, timed out; the screening and the
    blocks of outward_fix raise at a past deadline."""
    from obsdesign.methods.setinvariant import algorithms as al
    from obsdesign.methods.setinvariant.budget import Timeout
    from obsdesign.methods.setinvariant.problem import build
    from obsdesign.sets import polytope_ops as po

    fl = build(api.load_spec_text(SEED0, "s0.toml")).fl
    real = po.hull
    calls: list[bool] = []

    def hull(P, with_edges=True, check=None):
        calls.append(check is not None)
        if len(calls) == stop_at:  # the budget runs out inside this hull
            raise Timeout
        return real(P, with_edges, check)

    monkeypatch.setattr(po, "hull", hull)
    stop_at = 2
    r = al.general(fl, 0.9604, 0.9604, 60, True, deadline=1e18)
    assert calls == [True, True]  # the first hull is checked too (session 47)
    assert r.timed_out and r.iterations == 1 and not r.converged and len(r.G)
    calls.clear()
    stop_at = 1  # in the first hull: no polyhedron (algorithms._unfinished)
    r = al.general(fl, 0.9604, 0.9604, 60, True, deadline=1e18)
    assert r.timed_out and r.iterations == 0 and r.G.shape == (0, 3) and len(r.P) == 8
    monkeypatch.undo()
    G = fl.G0
    with pytest.raises(Timeout):
        al._drop_inside(np.ones((5, G.shape[1])), G, 1e-10, deadline=0.0)
    assert len(al._drop_inside(np.ones((5, G.shape[1])) * 9, G, 1e-10, deadline=None)) == 5

    def stop() -> None:
        raise Timeout

    with pytest.raises(Timeout):
        po.outward_fix(G, np.eye(G.shape[1]), stop)


def test_lp9_on_the_merged_float_rows_then_on_all_rows_where_tight():
    """The design solves LP (9) on the float hull's merged rows (fewer than the exact hull's)
    and again on all exact rows only where that v^l is tight (within 10⁻⁹ of λ); the exact
    check decides. Seed 0 of the benchmark: 44 merged rows, 48 exact facets; with λ set to
    the factor the merged rows give, the worst breakpoint is tight and re-solved."""
    import dataclasses

    from obsdesign.methods.setinvariant import certificate as ce
    from obsdesign.methods.setinvariant import lps
    from obsdesign.methods.setinvariant.design import _merged
    from obsdesign.methods.setinvariant.problem import build
    from obsdesign.sets import polytope_ops as po

    sp = api.load_spec_text(SEED0, "s0.toml")
    ex = build(sp).ex
    V = np.asarray(api.design(sp).parameters["V"], dtype=object)
    G, vrep = po.exact_hull(V)
    Gm = _merged(V)
    assert Gm is not None and len(Gm) < len(G)
    calls: list[int] = []

    def solver(Gf, phi, dl, deadline=None):
        calls.append(len(Gf))
        return lps.eps_batch(Gf, phi, dl, deadline=deadline)

    merged = ce.theorem31(ex, G, v_solver=solver, vrep=vrep, v_rows=Gm)
    assert calls == [len(Gm)] and merged.ok  # nothing tight at the spec's λ
    tight = dataclasses.replace(ex, lam=merged.factor)
    calls.clear()
    again = ce.theorem31(tight, G, v_solver=solver, vrep=vrep, v_rows=Gm)
    assert calls == [len(Gm), len(G)] and again.ok and again.factor <= merged.factor


def test_budget_message_says_how_far_the_run_got() -> None:
    """The three ends of a run stopped by the budget: in its first hull (no polyhedron), in
    its first iteration's LPs (a hull, no ε), after an iteration (its ε)."""
    from obsdesign.methods.setinvariant import algorithms as al
    from obsdesign.methods.setinvariant.design import _budget, _Run
    from obsdesign.methods.setinvariant.problem import build

    sp = api.load_spec_text(SEED0, "s0.toml")
    fl = build(sp).fl
    run = _Run(None, 0, True)
    ends = {
        "the first hull of 8 points did not finish": al._unfinished(np.ones((8, 3)), 0, []),
        # a continuation begun past the budget (after a long exact check): no hull ran
        "0 iterations: the budget was used up before this run began": al._unfinished(
            np.ones((8, 3)), 0, [], spent=True
        ),
        "no iteration finished, 6 facets": al.IterResult(
            fl.G0, fl.G0, np.inf, 0, False, timed_out=True
        ),
        "last ε ≈ 0.97 > λ = 0.9604 with 6 facets": al.IterResult(
            fl.G0, fl.G0, 0.97, 3, False, timed_out=True
        ),
    }
    for said, r in ends.items():
        with pytest.raises(SolverError, match=r"within \d+ s .* iterations: .*") as e:
            _budget(r, sp.options, run)
        assert said in e.value.message, e.value.message


def test_omegas_exact_vertices_are_held_to_the_time_budget(monkeypatch) -> None:
    """Ω's exact vertices (a child process from 8 states) were found before the budget
    started: an 8-state spec ran 150 s against time_limit = 5 (responsiveness review 47).
    The budget starts with the design; past it, Ω's enumeration is not started and the
    design stops (exit 3) saying so; within it, the vertices are those found in-process."""
    import time

    from obsdesign.methods.setinvariant import problem
    from obsdesign.methods.setinvariant.budget import Timeout
    from obsdesign.sets import polytope_ops as po

    monkeypatch.setattr(po, "H_TO_V_CHILD_DIM", 2)  # Ω of SEED0 (3 states) in a child
    problem._omega_vertices.cache_clear()
    G0 = problem.omega_rows(api.load_spec_text(SEED0, "s0.toml").sets["omega"])
    with pytest.raises(Timeout):
        problem.omega_vertices(G0, time.perf_counter() - 1)
    V = problem.omega_vertices(G0, time.perf_counter() + 60)
    assert sorted(map(tuple, V)) == sorted(map(tuple, po._exact_h_to_v(G0).V))
    problem._omega_vertices.cache_clear()
    sp = api.load_spec_text(SEED0.replace("max_iterations = 60", "time_limit = 1e-9"), "t.toml")
    with pytest.raises(SolverError, match="Ω's exact vertices were not found"):
        api.design(sp)
    problem._omega_vertices.cache_clear()


def test_the_merged_hull_and_the_eps_profile_look_at_the_budget() -> None:
    """The float hull of the exact points (LP (9)'s rows) ran 49-56 s unchecked on the
    9-cube, and the ε profile of a note ran minutes and to 24 GB (re-check review 47): both
    stop past the deadline."""
    import time

    from obsdesign.methods.setinvariant import design as des
    from obsdesign.methods.setinvariant import lps
    from obsdesign.methods.setinvariant.budget import Timeout
    from obsdesign.methods.setinvariant.problem import build

    data = build(api.load_spec_text(SEED0, "s0.toml"))
    Pq = data.ex.Vo
    past = time.perf_counter() - 1
    with pytest.raises(Timeout):
        des._merged(Pq, past)
    assert des._merged(Pq) is not None
    fl = data.fl
    with pytest.raises(Timeout):
        lps.epsilon_profile(fl.G0, fl.A, fl.B1, fl.C[0], fl.Dv, fl.eta, deadline=past)
    assert len(lps.epsilon_profile(fl.G0, fl.A, fl.B1, fl.C[0], fl.Dv, fl.eta)[1])
