"""Runtime pieces of paper 000: the maps c (18)/(19), M (20), G (23), the θ_m loop, the
vectorized batch and the saturation (29)."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.certify.exact import Q, qeye, qmat
from obsdesign.methods.constrained.cmap import (
    antipodal_classes,
    box_map,
    ellipsoid_map,
    polytope_map,
)
from obsdesign.methods.constrained.observer import LinearF, Observer, Refiner, sat

MAPS = [
    box_map([-1, -2], [1, 2]),
    polytope_map(
        qmat([[1, 0], [0, 1], [-1, 0], [0, -1], [1, 1]]),
        np.array([Q(v) for v in (1, 1, 1, 1, 1.5)], dtype=object),
    ),
    ellipsoid_map(qmat([[2, 0.5], [0.5, 1]]), Q(3)),
]


def test_box_map_matches_eq19():
    cm = MAPS[0]
    x = np.array([1.5, -2.5])
    # (c̲_1, c̄_1, c̲_2, c̄_2) = (0, 0.5², 0.5², 0)
    np.testing.assert_allclose(cm.c(x), [0, 0.25, 0.25, 0])
    assert cm.classes == [[0, 1], [2, 3]]
    assert cm.norm_c_sq_q(np.array([fmpq(3, 2), fmpq(-5, 2)], dtype=object)) == fmpq(1, 16) * 2


def test_antipodal_classes():
    G = qmat([[1, 0], [0, 1], [-2, 0], [0, -1], [1, 1], [-1, -1]])
    assert antipodal_classes(G) == [[0, 2], [1, 3], [4, 5]]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2), st.floats(-4, 4), st.floats(-4, 4))
def test_jtc_is_gradient_of_half_norm_squared(i, a, b):
    """(dc/dx)ᵀ c = ∇(|c|²/2): checked by central differences."""
    cm = MAPS[i]
    x = np.array([a, b])
    g = cm.jtc(x)
    h = 1e-6
    num = np.array(
        [(np.sum(cm.c(x + h * e) ** 2) - np.sum(cm.c(x - h * e) ** 2)) / (4 * h) for e in np.eye(2)]
    )
    np.testing.assert_allclose(g, num, rtol=1e-4, atol=1e-6)


def test_G_is_eq23():
    cm = MAPS[0]
    Pinv = np.array([[0.5, 0.1], [0.1, 0.25]])
    ref = Refiner(cm, Pinv, 0.2, 0.01, 4.0)
    inside = np.array([1.05, 0.0])  # |c| = 0.0025 ≤ ε_min: identity
    np.testing.assert_array_equal(ref.G(inside), inside)
    far = np.array([10.0, 0.0])  # |c| = 81 > ε_max: identity (outside C_max)
    np.testing.assert_array_equal(ref.G(far), far)
    mid = np.array([2.0, 0.0])  # |c| = 1: x̂ − γ P⁻¹ (dc/dx)ᵀ c, (dc/dx)ᵀc = (2·1³, 0)
    np.testing.assert_allclose(ref.G(mid), mid - 0.2 * Pinv @ np.array([2.0, 0.0]))
    y, steps = ref.refine(mid, 1000)
    assert cm.norm_c(y) <= 0.01 and 0 < steps < 1000
    y3, s3 = ref.refine(mid, 3)
    assert s3 == 3 and cm.norm_c(y3) > 0.01


def test_batch_matches_loop():
    rng = np.random.default_rng(0)
    for cm in MAPS:
        ref = Refiner(cm, np.array([[0.3, 0.05], [0.05, 0.2]]), 0.05, 0.01, 50.0)
        X = rng.uniform(-4, 4, (200, 2))
        Y, steps, sup = ref.refine_batch(X, 25)
        for j in range(len(X)):
            path: list[np.ndarray] = []
            y, s = ref.refine(X[j], 25, path)
            np.testing.assert_allclose(Y[j], y, rtol=1e-12, atol=1e-12)
            assert steps[j] == s
            np.testing.assert_allclose(sup[j], np.max(np.abs(np.vstack([X[j]] + path)), axis=0))


def test_observer_batch_run_matches_single_runs():
    """Observer.run_batch (vectorized over trajectories) gives each trajectory's run: same
    estimates and refining steps per sample, with and without the saturation (29)."""
    rng = np.random.default_rng(1)
    A = np.array([[0.9, 0.2], [0.0, 0.8]])
    C = np.array([[1.0, 0.0]])
    F = LinearF(A, np.zeros((2, 0)), C, np.zeros((1, 0)), np.array([[0.5], [0.1]]))
    ref = Refiner(MAPS[0], np.array([[0.3, 0.05], [0.05, 0.2]]), 0.05, 0.01, 50.0)
    B, N = 6, 12
    Y = rng.uniform(-2, 2, (B, N + 1, 1))
    U = np.zeros((B, N + 1, 0))
    X0 = rng.uniform(-3, 3, (B, 2))
    for ob in (Observer(F, ref, 4), Observer(F, ref, 4, sat_r=1.5), Observer(F)):
        est, steps = ob.run_batch(U, Y, X0)
        for b in range(B):
            tr = ob.run(U[b], Y[b], X0[b])
            np.testing.assert_allclose(est[b], tr.xhat, rtol=1e-12, atol=1e-12)
            np.testing.assert_array_equal(steps[b], tr.steps)
        assert ob.refiner is None or steps.sum() > 0


def test_saturated_observer_eq29():
    A = np.array([[0.0, 1], [1, 0]])
    C = np.array([[1.0, 0]])
    F = LinearF(A, np.zeros((2, 0)), C, np.zeros((1, 0)), np.array([[-1.87], [1.874]]))
    N = 50
    y = np.tile([-1.0], (N + 1, 1))
    u = np.zeros((N + 1, 0))
    tr = Observer(F, sat_r=2.0).run(u, y, np.array([1.0, 1.0]))
    np.testing.assert_array_equal(tr.xhat[1:], np.tile([2.0, -2.0], (N, 1)))
    np.testing.assert_array_equal(sat(np.array([3.0, -5.0, 0.5]), 1.0), [1.0, -1.0, 0.5])


def test_ellipsoid_map_values():
    cm = ellipsoid_map(qeye(2), Q(2))
    x = np.array([2.0, 0.0])  # xᵀx/r − 1 = 1 → c = 1
    np.testing.assert_allclose(cm.c(x), [1.0])
    np.testing.assert_allclose(cm.jtc(x), 4 * 1 * x / 2)


def test_antipodal_classes_never_hold_two_faces_of_one_direction():
    """A face pairs with at most one negative multiple: −x ≤ 1 and −½x ≤ ½ can be violated
    together, so they are never in one class (the bounds assume one violated face per class)."""
    assert antipodal_classes(qmat([[1], [-1], [fmpq(-1, 2)]])) == [[0, 1], [2]]
    assert antipodal_classes(qmat([[1], [2], [-1], [-3]])) == [[0, 2], [1, 3]]


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.sampled_from([(1, 0), (0, 1), (1, 1), (2, -1)]), st.integers(-3, 3)),
        min_size=1,
        max_size=8,
    ).filter(lambda rows: all(k != 0 for _, k in rows)),
    st.lists(st.tuples(st.floats(-9, 9), st.floats(-9, 9)), min_size=1, max_size=20),
)
def test_at_most_one_face_per_class_is_violated(rows, points):
    """Random faces (multiples of a few directions, h = 1: the polytope holds 0), random
    points: no class ever has two violated faces."""
    G = qmat([[k * d[0], k * d[1]] for d, k in rows])
    cm = polytope_map(G, np.array([fmpq(1)] * len(rows), dtype=object))
    phi = cm.phi(np.asarray(points, dtype=float))
    for cls in cm.classes:
        assert len(cls) <= 2
        assert np.all((phi[:, cls] > 0).sum(axis=1) <= 1)


def test_path_log_keeps_sup_and_v_increase_past_its_cap(monkeypatch):
    """The iterates x̂_{k,i} are kept up to MAX_KEPT_ITERATES (θ_m = 10⁷ kept every one:
    gigabytes); the sup over (k, i) and the largest V increase over a refining step are taken
    over all of them, as from the full path, and the time budget is looked at every
    CHECK_EVERY refining steps."""
    from obsdesign.methods.constrained import observer as obs

    A = np.array([[0.9, 0.2], [0.0, 0.8]])
    C = np.array([[1.0, 0.0]])
    F = LinearF(A, np.zeros((2, 0)), C, np.zeros((1, 0)), np.array([[0.5], [0.1]]))
    ref = Refiner(MAPS[0], np.array([[0.3, 0.05], [0.05, 0.2]]), 0.05, 0.01, 50.0)
    rng = np.random.default_rng(3)
    N = 15
    Y = rng.uniform(-4, 4, (N + 1, 1))
    U = np.zeros((N + 1, 0))
    x = rng.uniform(-1, 1, (N + 1, 2))
    P = np.array([[2.0, 0.3], [0.3, 1.0]])
    full = Observer(F, ref, 6).run(U, Y, np.array([3.0, -3.0]), x, P)
    assert not full.truncated and sum(map(len, full.iterates)) > 20
    worst = -np.inf
    for k, path in enumerate(full.iterates):
        E = np.asarray(path) - x[k + 1]
        V = np.einsum("ij,jk,ik->i", E, P, E)
        if len(V) > 1:
            worst = max(worst, float(np.max(np.diff(V) / V[:-1])))
    assert full.v_increase == pytest.approx(worst, rel=1e-12)
    monkeypatch.setattr(obs, "MAX_KEPT_ITERATES", 5)
    calls = []
    monkeypatch.setattr(obs, "CHECK_EVERY", 3)
    cut = Observer(F, ref, 6).run(
        U, Y, np.array([3.0, -3.0]), x, P, lambda k, n: calls.append((k, n))
    )
    assert cut.truncated and sum(map(len, cut.iterates)) == 5
    np.testing.assert_array_equal(cut.sup_ki(), full.sup_ki())
    assert cut.v_increase == full.v_increase
    steps = sum(map(len, full.iterates))
    assert len(calls) == steps // 3 + (N + 2) // 3 and all(n == N for _, n in calls)


def test_the_max_norm_refinement_past_the_float_range_stops_as_the_euclidean_one() -> None:
    """x⁺ = 2x leaves X and grows past 1e77: with norm = "max" the refinement squared the
    largest |c|² with Python's float power, OverflowError, and simulate was exit 4 "the
    spec's numbers are too large", where the Euclidean norm's inf stops the refinement and
    the run warns that the plant leaves X (census 46). Both run now."""
    from pathlib import Path

    from obsdesign import api

    text = (Path(__file__).parent / "specs" / "constrained-maxnorm-overflow.toml").read_text(
        encoding="utf-8"
    )
    for norm in ("max", "euclidean"):
        spec = api.load_spec_text(text.replace('norm = "max"', f'norm = "{norm}"'), f"{norm}.toml")
        res = api.simulate(spec)
        assert not np.isfinite(res.x[-1, 0]) or abs(res.x[-1, 0]) > 1e77
        assert any("X" in w for w in res.info.get("warnings", [])), res.info
