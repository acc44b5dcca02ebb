"""Sets (obsdesign.sets): exact vertices, membership, sampling."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.certify.exact import qmat, qvec
from obsdesign.sets import Box, Ellipsoid, Polytope, SymmetricPolytope, vertices_exact


def test_box_vertices_and_h_form():
    b = Box(qvec([-1, 0]), qvec([1, fmpq(1, 3)]))
    V = b.vertices_q()
    assert V.shape == (4, 2) and fmpq(1, 3) in set(V[:, 1])
    G, g = b.h_form_q()
    for v in V:
        assert all(G[i] @ v <= g[i] for i in range(4))


def test_symmetric_polytope_exact_vertices():
    s = SymmetricPolytope.from_Q(qmat([[1, 1], [1, -1]]))
    V = {tuple(v) for v in s.vertices_q()}
    assert V == {(fmpq(1), fmpq(0)), (fmpq(-1), fmpq(0)), (fmpq(0), fmpq(1)), (fmpq(0), fmpq(-1))}


def test_unbounded_detected():
    _, bounded = vertices_exact(qmat([[1, 0], [0, 1]]), qvec([1, 1]))
    assert not bounded


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000))
def test_sampling_stays_inside(seed: int):
    rng = np.random.default_rng(seed)
    P = Polytope(qmat([[1, 1], [-1, 0], [0, -1]]), qvec([1, 0, 0]))  # a triangle
    pts = P.sample(rng, 50)
    assert pts.shape == (50, 2) and np.all(P.contains(pts))
    E = Ellipsoid(qmat([[4, 0], [0, 1]]), qvec([1, 0]))
    pts = E.sample(rng, 30)
    assert np.all(E.contains(pts))
    lo, hi = E.bounding_box()
    np.testing.assert_allclose(lo, [0.5, -1]) and np.testing.assert_allclose(hi, [1.5, 1])


def test_float_views_are_rounded_cached_and_read_only():
    b = Box(qvec([fmpq(-1, 3), 0]), qvec([fmpq(1, 3), 2]))
    assert b.lower.tolist() == [-1 / 3, 0.0] and b.upper.tolist() == [1 / 3, 2.0]
    assert b.lower is b.lower  # computed once: the sets are frozen
    with pytest.raises(ValueError, match="read-only"):
        b.lower[0] = 5.0  # an in-place change would corrupt the set for every later caller
    P = Polytope(qmat([[1, 1], [-1, 0], [0, -1]]), np.array([[fmpq(1)], [0], [0]], dtype=object))
    assert P.g.shape == (3,) and P.G.shape == (3, 2)  # g is flat even from a column
    E = Ellipsoid(qmat([[4, 0], [0, 1]]), qvec([fmpq(1, 10), 0]))
    assert E.center.tolist() == [0.1, 0.0] and not E.E.flags.writeable
