"""Polytope layer of the set-invariant method: float (qhull, outward-fixed) vs exact (cdd.gmp)."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from obsdesign.sets import polytope_ops as po


def _cloud(seed: int, n: int, k: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(k, n))
    return np.vstack([P, -np.eye(n), np.eye(n)])  # the origin is interior


@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.integers(0, 10**6), st.sampled_from([2, 3, 4]), st.integers(5, 40))
def test_hull_contains_points_and_matches_exact(seed, n, k):
    P = _cloud(seed, n, k)
    st_ = po.hull(P)
    # outward fix: every point satisfies every row (never shrinks)
    assert (P @ st_.G.T).max() <= 1 + 1e-12
    # every row is tight at some point (it is a facet, not a loose bound)
    assert np.allclose((P @ st_.G.T).max(axis=0), 1.0)
    # exact hull of the same (float-exact) points has the same facets
    Gx = po.exact_v_to_h(po.qarray(P))
    assert len(Gx) == len(st_.G)
    assert np.allclose(np.sort(po.qfloat(Gx), axis=0), np.sort(st_.G, axis=0), atol=1e-9)


@settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.integers(0, 10**6), st.sampled_from([2, 3]), st.integers(5, 30))
def test_h_to_v_matches_exact_and_slices(seed, n, k):
    G = po.hull(_cloud(seed, n, k)).G
    vr = po.h_to_v(G)
    ex = po.exact_h_to_v(po.qarray(G))
    # a vertex where more than n facets meet may split, in exact arithmetic on the float
    # rows, into a cluster of vertices ~1e-15 apart; the two sets agree up to that
    Vf = po.qfloat(ex.V)
    for v in vr.V:
        assert np.min(np.abs(Vf - v).max(axis=1)) < 1e-9
    for v in Vf:
        assert np.min(np.abs(vr.V - v).max(axis=1)) < 1e-9
    # slice points lie in the polytope and on the slab; max of a linear function over the
    # slice equals the LP value
    from scipy.optimize import linprog

    rng = np.random.default_rng(seed)
    c = rng.normal(size=n)
    a = rng.normal(size=n)
    cv = vr.V @ c
    z = rng.uniform(cv.min(), cv.max())
    S = po.slice_points(vr.V, vr.edges, c, z - 0.01, z + 0.01)
    assert (S @ G.T).max() <= 1 + 1e-9
    assert np.all(np.abs(S @ c - z) <= 0.01 + 1e-9)
    res = linprog(
        -a,
        A_ub=np.vstack([G, c, -c]),
        b_ub=np.concatenate([np.ones(len(G)), [z + 0.01, 0.01 - z]]),
        bounds=(None, None),
        method="highs",
    )
    assert abs(-res.fun - (S @ a).max()) < 1e-7


def test_exact_roundtrip_canonical_and_redundancy():
    Q = po.qarray([[1, 0], [0, 1], [1, 1]])
    G = np.vstack([Q, -Q])
    G2 = np.vstack([G, po.qarray([[fmpq(1, 2), 0]]), G[:1]])  # a redundant row and a duplicate
    R = po.exact_remove_redundant(G2)
    assert len(R) == 6
    vr = po.exact_h_to_v(R)
    assert len(vr.V) == 6 and len(vr.edges) == 6
    H = po.exact_v_to_h(vr.V)
    assert [list(r) for r in H] == [list(r) for r in po.canonical(R)]
    # canonical form divides by the right-hand side
    C = po.canonical(po.qarray([[2, 0], [0, 4], [-2, 0], [0, -4]]), po.qarray([2, 2, 2, 2]))
    assert {tuple(r) for r in C} == {(1, 0), (0, 2), (-1, 0), (0, -2)}


def test_errors_unbounded_empty_origin():
    with pytest.raises(po.PolytopeError, match="unbounded"):
        po.exact_h_to_v(po.qarray([[1, 0], [-1, 0]]))
    with pytest.raises(po.PolytopeError, match="empty"):
        po.exact_h_to_v(po.qarray([[1, 0], [-1, 0]]), po.qarray([-1, -1]))
    with pytest.raises(po.PolytopeError, match="unbounded"):
        po.h_to_v(np.array([[1.0, 0], [-1.0, 0], [0, 1.0]]))
    with pytest.raises(po.PolytopeError, match="origin"):
        po.hull(np.array([[1.0, 1], [2, 1], [1, 2]]))
    with pytest.raises(po.PolytopeError, match="origin"):
        po.canonical(po.qarray([[1, 0]]), po.qarray([0]))


def test_snap_and_rationalize():
    assert po.snap(10 / 9) == fmpq(10, 9)
    x = 0.123456789012345
    assert float(po.snap(x)) == x  # no simple rational nearby: the float exactly
    R = po.rationalize(np.array([[1 / 3, 0.1234567890123]]), bits=20)
    assert R[0, 0] == fmpq(1, 3)
    assert abs(float(R[0, 1]) - 0.1234567890123) < 2**-19


def test_exact_slicer_matches_float():
    G = po.hull(_cloud(3, 3, 20)).G
    ex = po.exact_h_to_v(po.qarray(G))
    c = po.qarray([1, 2, -1])
    s = po.ExactSlicer(ex.V, ex.edges, c)
    pts = s.points(fmpq(0), fmpq(1, 10))
    P = po.qfloat(np.array(pts, dtype=object))
    assert np.all((P @ G.T) <= 1 + 1e-9)
    cf = po.qfloat(c)
    assert np.all((P @ cf >= -1e-12) & (P @ cf <= 0.1 + 1e-12))


def test_cold_import_pulls_no_heavy_module():
    """Issue 12 item 3: ``import obsdesign.api`` loads neither scipy.spatial (qhull), cdd,
    cvxpy nor matplotlib; polytope_ops imports qhull and pycddlib on first use; tool_info
    reads the dependency versions once per process."""
    import subprocess
    import sys

    code = """
import sys
import obsdesign.api
heavy = ("scipy.spatial", "cdd", "cvxpy", "matplotlib")
print([m for m in heavy if m in sys.modules])
from obsdesign.sets import polytope_ops as po
print(po.HAVE_GMP is True, "cdd" in sys.modules)
po.hull([[1, 0], [0, 1], [-1, -1]])
print("scipy.spatial" in sys.modules)
from importlib import metadata
from obsdesign.report import model
calls = []
real = metadata.version
metadata.version = lambda d: calls.append(d) or real(d)
a, b = model.tool_info(), model.tool_info()
a["dependencies"]["numpy"] = "changed"
print(len(calls) <= len(model.DEPS) + 1, b == model.tool_info(), model.tool_info() != a)
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stdout.split("\n")[:4] == ["[]", "True True", "True", "True True True"], r.stdout
