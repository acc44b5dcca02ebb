"""Sets (obsdesign.sets): exact vertices, membership, sampling."""

from __future__ import annotations

import numpy as np
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
