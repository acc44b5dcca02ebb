"""Certified bounds of paper 000 (v_max (13), v_min (21), ε_max / X̂_max (15), δ, γ (24), θ (22))
checked against sampling: a bound that a sample beats is wrong."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from obsdesign.certify.exact import Q, dyadic, qeye, qmat, symmetrize, to_float
from obsdesign.certify.linalg import qinv
from obsdesign.methods.constrained import bounds as B
from obsdesign.methods.constrained.cmap import (
    ConstraintMap,
    box_map,
    ellipsoid_map,
    polytope_map,
)
from obsdesign.sets import Box


def _rand_P(rng, n):
    M = rng.standard_normal((n, n))
    return symmetrize(dyadic(M @ M.T + 0.2 * np.eye(n), 20))


def _box(lo, hi):
    return Box(
        np.array([Q(v) for v in lo], dtype=object), np.array([Q(v) for v in hi], dtype=object)
    )


def _ellipsoid_samples(rng, P, v, k):
    """k points on the boundary {eᵀPe = v}."""
    L = np.linalg.cholesky(np.linalg.inv(P))
    u = rng.standard_normal((k, P.shape[0]))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return np.sqrt(v) * u @ L.T


def test_round_sig():
    assert B.round_sig(fmpq(123456789, 1000), 3, up=True) == fmpq(124000)
    assert B.round_sig(fmpq(123456789, 1000), 3, up=False) == fmpq(123000)
    assert B.round_sig(fmpq(-1, 3), 2, up=True) == fmpq(-33, 100)
    assert B.round_sig(fmpq(2, 3) / 10**6, 2, up=False) == fmpq(66, 10**8)


def test_theta_exact_ceiling():
    # (v_max − v_min)/(γ ε²) = (10 − 1)/(3·(1/10)²) = 300 exactly: no rounding up beyond
    assert B.theta_of(10, 1, 3, fmpq(1, 10)) == 300
    assert B.theta_of(10, fmpq(999, 1000), 3, fmpq(1, 10)) == 301
    assert B.theta_of(1, 2, 3, fmpq(1, 10)) == 0  # Remark 2


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(2, 3), st.integers(0, 2**31 - 1))
def test_lambda_min_and_gen_eig(n, seed):
    rng = np.random.default_rng(seed)
    P = _rand_P(rng, n)
    Qm = _rand_P(rng, n)
    ell = B.lambda_min_lower(P)
    assert 0 < float(ell) <= np.linalg.eigvalsh(np.asarray(to_float(P), float)).min()
    k = B.gen_eig_upper(Qm, P)
    Pf, Qf = (np.asarray(to_float(M), float) for M in (P, Qm))
    assert float(k) >= np.linalg.eigvals(np.linalg.solve(Pf, Qf)).real.max() * (1 - 1e-12)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.integers(2, 3),
    st.integers(0, 2**31 - 1),
    st.floats(0.05, 1.0),
    st.floats(0.001, 0.5),
    st.sampled_from(["euclidean", "max"]),
)
def test_v_min_is_sound(n, seed, pad, eps, norm):
    """Every x̂ with V(x̂ − x) ≤ v_min, x ∈ X, is in C_min (eq. (21))."""
    rng = np.random.default_rng(seed)
    P = _rand_P(rng, n)
    X = _box(-np.ones(n), np.ones(n))
    cm = box_map([-1 - pad] * n, [1 + pad] * n, norm)
    eps_q = Q(round(eps, 6))
    vb = B.v_min_lower(cm, P, qinv(P), X, eps_q)
    Pf = np.asarray(to_float(P), float)
    xs = rng.uniform(-1, 1, (200, n))
    xs[:8] = rng.choice([-1.0, 1.0], (8, n))  # vertices matter most
    pts = xs + _ellipsoid_samples(rng, Pf, float(vb.value), 200)
    assert np.all(cm.norm_c(pts) <= float(eps_q) * (1 + 1e-9))
    assert B.v_min_condition(cm, P, qinv(P), X, eps_q, vb.value)
    if norm == "max":  # exact: slightly above v_min some point of some ellipsoid leaves C_min
        assert vb.exact
        assert not B.v_min_condition(cm, P, qinv(P), X, eps_q, vb.value * fmpq(1001, 1000))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(2, 3), st.integers(0, 2**31 - 1), st.floats(0.05, 1.0), st.floats(0.5, 50.0))
def test_Xhat_max_and_delta_are_sound(n, seed, pad, v):
    """sup |c| over X̂_max (15) and δ over C_max (Assumption 3(4)) are upper bounds."""
    rng = np.random.default_rng(seed)
    P = _rand_P(rng, n)
    X = _box(-np.ones(n), np.ones(n))
    for cm in (
        box_map([-1 - pad] * n, [1 + pad] * n),
        polytope_map(
            qmat(np.vstack([np.eye(n), -np.eye(n), np.ones((1, n))])),
            np.array([Q(1 + pad)] * (2 * n) + [Q(n + pad)], dtype=object),
        ),
        ellipsoid_map(qeye(n), Q(n + pad)),
    ):
        vq = dyadic(v, 20)
        sup = B.sup_norm_c_over_Xhat_max(cm, P, qinv(P), X, vq)
        Pf = np.asarray(to_float(P), float)
        xs = rng.choice([-1.0, 1.0], (300, n))
        pts = xs + _ellipsoid_samples(rng, Pf, float(vq), 300)
        assert cm.norm_c(pts).max() <= float(sup) * (1 + 1e-9) + 1e-12
        eps_max = B.round_sig(max(sup, fmpq(1, 100)), 6, up=True)
        dsq = B.delta_sq_upper(cm, eps_max)
        # sample points of C_max and the norm of the Jacobian there
        J = _jacobian_norms(cm, pts[cm.norm_c(pts) <= float(eps_max)])
        if J.size:
            assert J.max() ** 2 <= float(dsq.value) * (1 + 1e-9)


def _jacobian_norms(cm, pts):
    out = []
    for x in pts:
        p = np.maximum(cm.phi(x), 0.0)
        if cm.affine:
            Jm = (2 * p)[:, None] * cm.G
        else:
            Jm = (2 * p[0] * 2 * cm.Qf @ x / cm.r)[None, :]
        out.append(np.linalg.norm(Jm, 2))
    return np.asarray(out)


def test_box_delta_exact_and_gamma_check():
    cm = box_map([-1.1, -1.1], [1.1, 1.1])
    d = B.delta_sq_upper(cm, fmpq(9))
    assert d.value == 36 and d.exact
    ok, _ = B.delta_sq_valid(cm, fmpq(9), fmpq(36))
    assert ok
    ok, _ = B.delta_sq_valid(cm, fmpq(9), fmpq(35))
    assert not ok
    P = qmat([[2, 0], [0, 3]])
    assert B.gamma_ok(P, fmpq(2, 36), 36)[0]
    assert not B.gamma_ok(P, fmpq(2, 36) + fmpq(1, 10**12), 36)[0]
    assert B.gamma_bound(P, 36) <= fmpq(2, 36)


def test_v_max_exact_for_boxes():
    P = qmat([[2, 1], [1, 3]])
    X = _box([-1, -1], [1, 1])
    Xh = _box([-2, -2], [2, 2])
    vb = B.v_max_bound(P, fmpq(1, 2), 4, X, Xh, 9)
    # max over the box [-3, 3]² of eᵀPe is at (3, 3): 9·(2 + 2 + 3) = 63
    assert vb.exact and vb.value == fmpq(63, 2) + 36


@pytest.mark.parametrize("n", [2, 3])
def test_v_max_ellipsoid_bound_is_sound(n):
    from obsdesign.sets import Ellipsoid

    rng = np.random.default_rng(n)
    P = _rand_P(rng, n)
    E = _rand_P(rng, n)
    X = _box(-np.ones(n), np.ones(n))
    Xh = Ellipsoid(E, np.array([fmpq(0)] * n, dtype=object))
    vb = B.max_V_diff(P, X, Xh)
    Ef = np.asarray(to_float(E), float)
    Pf = np.asarray(to_float(P), float)
    pts = _ellipsoid_samples(rng, Ef, 1.0, 2000)
    xs = rng.choice([-1.0, 1.0], (2000, n))
    d = pts - xs
    assert np.einsum("ij,jk,ik->i", d, Pf, d).max() <= float(vb.value)


@given(st.integers(1, 10**700), st.integers(1, 10**50))
def test_floor_log10_is_exact_beyond_the_float_range(p: int, q: int) -> None:
    """⌊log10(p/q)⌋ exactly, also where p/q is beyond the float range (no float used)."""
    a = fmpq(p, q)
    e = B.floor_log10(a)
    assert fmpq(10) ** e <= a < fmpq(10) ** (e + 1)


def test_floor_log10_at_powers_of_ten_and_round_sig_beyond_floats() -> None:
    for k in (-400, -1, 0, 1, 308, 309, 600):
        t = fmpq(10) ** k
        assert B.floor_log10(t) == k
        assert B.floor_log10(t - t / 10**30) == k - 1
    # 1e600 + 1 to 6 significant digits, up: 1.00001e600 (exact, no float overflow)
    assert B.round_sig(fmpq(10) ** 600 + 1, 6, up=True) == fmpq(100001) * fmpq(10) ** 595
    assert B.round_sig(fmpq(10) ** 600 + 1, 6, up=False) == fmpq(10) ** 600


def test_a_set_edge_at_1e300_is_inconclusive_not_an_internal_failure(tmp_path) -> None:
    """c's box edge at 1e300 (found by the spec fuzzer): the exact bounds reach ~1e600,
    beyond the float range of the report's float view. exit 4 with an error report, not
    "internal failure: OverflowError" (exit 3)."""
    import json
    from pathlib import Path

    from obsdesign import api
    from obsdesign.errors import InconclusiveError

    text = (
        Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5.toml"
    ).read_text()
    old = '[method.c]\ntype = "box"\nlower = [-1.1, -1.1]\nupper = [1.1, 1.1]\n'
    assert old in text
    spec = tmp_path / "s.toml"
    spec.write_text(text.replace(old, old.replace("upper = [1.1,", "upper = [1e300,")))
    out = tmp_path / "r.json"
    with pytest.raises(InconclusiveError, match="beyond the float range") as e:
        api.design(spec, out)
    assert e.value.exit_code == 4
    rep = json.loads(out.read_text())
    assert rep["verdict"] == "error" and rep["error"]["exit_code"] == 4


def test_faces_with_the_same_direction_are_bounded_together():
    """A polytope map with a redundant face in the direction of another (−x ≤ 1 and
    −½x ≤ ½: both violated left of −1; found by the random-spec fuzzer). At the worst points
    — x at X's left end, e at the left end of {V(e) ≤ v} — both faces are violated, and v_min
    (21), sup |c| over X̂_max (15) and δ (Assumption 3(4)) must still hold. Putting the two
    faces in one antipodal class (at most one violated) under-estimated all three: v_min
    0.24999999 where |c| = 0.0103 > ε_min = 0.01, sup |c| 0.49 where it is 0.505, δ² 4ε_max
    where it is 4.12ε_max."""
    cm = polytope_map(qmat([[1], [-1], [fmpq(-1, 2)]]), np.array([Q(1), Q(1), fmpq(1, 2)]))
    assert cm.classes == [[0, 1], [2]]
    P = qmat([[fmpq(25, 4)]])
    X = _box([fmpq(-9, 10)], [fmpq(9, 10)])
    eps = fmpq(1, 100)
    vb = B.v_min_lower(cm, P, qinv(P), X, eps)
    worst = -0.9 - np.sqrt(float(vb.value) / 6.25)
    assert cm.norm_c(np.array([worst])) <= 0.01 * (1 + 1e-12)
    v = fmpq(4)
    sup = B.sup_norm_c_over_Xhat_max(cm, P, qinv(P), X, v)
    worst = -0.9 - np.sqrt(4 / 6.25)
    assert cm.norm_c(np.array([worst])) <= float(sup) * (1 + 1e-12)
    dsq = B.delta_sq_upper(cm, sup)
    xs = np.linspace(-3, 3, 60001)[:, None]
    J = _jacobian_norms(cm, xs[cm.norm_c(xs) <= float(sup)])
    assert J.max() ** 2 <= float(dsq.value) * (1 + 1e-12)


# -- mutation review 22 (bounds.py, cmap.py) ---------------------------------------------------


def test_antipodal_classes_pair_only_opposite_faces():
    """Each face is in exactly one class, paired only with the first unpaired face whose
    normal is a negative multiple of its own (any factor, e.g. 2x <= 1 with −x <= 1): the
    triangle's three faces stay single; the square's opposite sides pair up; a face with
    the same direction as a paired one (−x, −2x) stays single; a positive multiple (x, 2x)
    or a factor in (0, 1) never pairs; a zero row pairs with nothing."""
    from obsdesign.methods.constrained.cmap import _negative_multiple, antipodal_classes

    tri = qmat([[1, 0], [-1, 2], [-1, -2]])
    assert antipodal_classes(tri) == [[0], [1], [2]]
    sq = qmat([[1, 0], [0, 1], [-1, 0], [0, -1]])
    assert antipodal_classes(sq) == [[0, 2], [1, 3]]
    assert antipodal_classes(qmat([[1, 0], [-1, 0], [-2, 0]])) == [[0, 1], [2]]
    assert antipodal_classes(qmat([[0, 0], [1, 0], [-1, 0]])) == [[0], [1, 2]]
    q = qmat([[2, 0], [-1, 0], [1, 0], [2, 0], [fmpq(1, 2), 0], [0, 1], [-1, 1]])
    assert _negative_multiple(q[0], q[1]) and _negative_multiple(q[1], q[0])
    assert _negative_multiple(q[1], q[2])  # b[k] == 1: still a negative multiple
    assert not _negative_multiple(q[2], q[3])  # x and 2x: the same direction
    assert not _negative_multiple(q[0], q[4])  # 2x and x/2: a factor in (0, 1)
    assert not _negative_multiple(q[2], q[5])  # b[k] == 0
    assert not _negative_multiple(q[5], q[6])  # same leading sign pattern, not parallel
    assert not _negative_multiple(qmat([[0, 0]])[0], q[1])  # a zero row


def _fake_eigh_low(monkeypatch, factor):
    """The float eigenvalue solvers return ``factor`` times the true value (a float error
    far beyond the first candidate's 10⁻⁹ margin)."""
    import scipy.linalg as sl

    real_sl, real_np = sl.eigh, np.linalg.eigvalsh
    monkeypatch.setattr(sl, "eigh", lambda a, b=None, **kw: real_sl(a, b, **kw) * factor)
    monkeypatch.setattr(np.linalg, "eigvalsh", lambda a: real_np(a) * factor)


@pytest.mark.parametrize("low", [5e-7, 5e-4, 0.05, 0.4])
def test_gen_eig_upper_is_proved_and_tight_when_the_float_estimate_is_low(monkeypatch, low):
    """κ with A ⪯ κB: each candidate is proved by the exact LDLᵀ of κB − A, so an estimate
    that is too low (here by a factor 1 − low) is passed over, and the first candidate of the
    ladder 1 + 10⁻⁹, 10⁻⁶, 10⁻³, 10⁻¹, 1 above the true value is taken. A = diag(1, 2), B = I:
    λ_max = 2."""
    _fake_eigh_low(monkeypatch, 1 - low)
    A, Bm = qmat([[1, 0], [0, 2]]), qeye(2)
    kap = B.gen_eig_upper(A, Bm)
    assert kap >= 2  # the proof: κB − A ⪰ 0
    step = next(f for f in (1e-9, 1e-6, 1e-3, 1e-1, 1.0) if (1 - low) * (1 + f) >= 1)
    assert float(kap) <= 2 * (1 - low) * (1 + step) * (1 + 1e-8)


def test_gen_eig_upper_is_tight_for_small_and_large_eigenvalues():
    """κ is within 10⁻⁸ (relative) of λ_max(B⁻¹A) above it, also below 1 (no floor at 1) and
    never 2× or +1 off: A = diag(1/4, 1/8), B = diag(1, 1/2) (λ_max = 1/4)."""
    kap = B.gen_eig_upper(qmat([[fmpq(1, 4), 0], [0, fmpq(1, 8)]]), qmat([[1, 0], [0, fmpq(1, 2)]]))
    assert fmpq(1, 4) <= kap <= fmpq(1, 4) * (1 + fmpq(1, 10**8))


@pytest.mark.parametrize("low", [5e-7, 5e-4, 0.05, 0.4])
def test_lambda_min_lower_is_proved_and_tight_when_the_float_estimate_is_high(monkeypatch, low):
    """ℓ ≤ λ_min(P) proved by the exact LDLᵀ of P − ℓI: a float estimate too high by a factor
    1 + low is passed over down the ladder 1 − 10⁻⁹, 10⁻⁶, 10⁻³, 10⁻¹, ½, and the first proved
    candidate is taken. P = diag(3, 5): λ_min = 3."""
    _fake_eigh_low(monkeypatch, 1 + low)
    ell = B.lambda_min_lower(qmat([[3, 0], [0, 5]]))
    assert ell <= 3  # the proof: P − ℓI ⪰ 0
    step = next(f for f in (1e-9, 1e-6, 1e-3, 1e-1, 0.5) if (1 + low) * (1 - f) <= 1)
    assert float(ell) >= 3 * (1 + low) * (1 - step) * (1 - 1e-8)
    assert B.lambda_min_lower(qmat([[1, 0], [0, -1]])) == 0  # not positive definite


def test_box_quad_bound_and_the_outer_box_fallback(monkeypatch):
    """max (x̂ − x)ᵀP(x̂ − x) over X̂ × X with P = [[2, 1], [1, 3]], A = [−1, 0] × [−2, −1],
    B = [1, 2] × [1, 3]: exact at the vertices of the box X̂ − X (boxes), or of the vertex
    pairs (polytopes): 123 at ±(3, 5), in both roles; above MAX_PAIRS pairs (forced to 0) the
    bound Σ|P_ij| m_i m_j with m = max(|lo|, |hi|) over the enclosing box of X̂ − X, from the
    polytopes' exact vertices: m = (3, 5), 2·9 + 2·15 + 3·25 = 123 again, flagged as a bound;
    and _box_quad_bound by hand with m = (2, 3): 2·4 + 2·6 + 3·9 = 47."""
    from obsdesign.sets import Polytope

    P = qmat([[2, 1], [1, 3]])
    b = B._box_quad_bound(P, [Q(-2), Q(-1)], [Q(1), Q(3)])
    assert b.value == 47 and b.exact is False
    G = qmat([[1, 0], [-1, 0], [0, 1], [0, -1]])
    boxes = {"A": _box([-1, -2], [0, -1]), "B": _box([1, 1], [2, 3])}
    polys = {
        "A": Polytope(G, np.array([Q(0), Q(1), Q(-1), Q(2)], dtype=object)),
        "B": Polytope(G, np.array([Q(2), Q(-1), Q(3), Q(-1)], dtype=object)),
    }
    lo, hi = B.outer_box_q(polys["A"])
    assert list(lo) == [-1, -2] and list(hi) == [0, -1]
    for x, xh in (("A", "B"), ("B", "A")):
        for sets in (boxes, polys):
            r = B.max_V_diff(P, sets[x], sets[xh])
            assert r.exact and r.value == 123, (x, xh)
    monkeypatch.setattr(B, "MAX_PAIRS", 0)
    for x, xh in (("A", "B"), ("B", "A")):
        r = B.max_V_diff(P, polys[x], polys[xh])
        assert r.value == 123 and not r.exact, (x, xh)


def test_v_max_over_an_ellipsoid_is_the_triangle_bound():
    """X̂ an ellipsoid: max V(x̂ − x) ≤ max over the vertices v of X of (√V(c − v) + √κ)²,
    κ ≥ λ_max(E⁻¹P) (here 1). P = E = I: the bound is the true maximum (|c − v| + 1)²; with
    c = (2, 0) and X = [0, 1]² the farthest vertex is (0, 1), |c − v|² = 5, so 6 + 2√5; and
    (√2/4 + 1/4)² < 1 for the ball of radius 1/4 at 0 and X = [0, 1/4]²."""
    from obsdesign.sets import Ellipsoid

    far = np.array([Q(2), Q(0)], dtype=object)
    zero = np.array([Q(0), Q(0)], dtype=object)
    cases = [
        (far, qeye(2), _box([0, 0], [1, 1]), 6 + 2 * 5**0.5),
        (zero, qeye(2) * 16, _box([0, 0], [fmpq(1, 4)] * 2), ((2**0.5 + 1) / 4) ** 2),
    ]
    for c, E, X, want in cases:
        r = B.max_V_diff(qeye(2), X, Ellipsoid(E, c))
        assert not r.exact
        assert want * (1 - 1e-12) <= float(r.value) <= want * (1 + 1e-7)


def test_gamma_ok_refuses_a_nonpositive_gamma():
    """Eq. (24) needs γ > 0: γ = 0 or γ < 0 is a failed check (P − γδ²I ⪰ 0 would hold);
    γδ² = λ_min(P) passes, above it fails."""
    P = qmat([[3, 0], [0, 5]])
    assert B.gamma_ok(P, fmpq(3, 4), Q(4))[0]
    assert not B.gamma_ok(P, fmpq(3, 4) + fmpq(1, 10**9), Q(4))[0]
    for g in (Q(0), Q(-1)):
        ok, detail = B.gamma_ok(P, g, Q(4))
        assert not ok and "must be > 0" in detail


def test_delta_sq_valid_refuses_a_nonpositive_eps_max():
    """δ² is checked as (δ²/(4 ε_max))·I − H ⪰ 0 only for ε_max > 0; ε_max = 0 or < 0 is a
    failed check, never a pass or a division by zero."""
    cm = box_map([Q(-1), Q(-1)], [Q(1), Q(1)])
    assert B.delta_sq_valid(cm, Q(1), Q(4))[0]
    assert not B.delta_sq_valid(cm, Q(1), fmpq(39, 10))[0]
    for e in (Q(0), Q(-1)):
        ok, detail = B.delta_sq_valid(cm, e, Q(4))
        assert not ok and detail == "ε_max must be > 0"


def test_phi_and_norm_c_exactly_at_rational_points():
    """φ and |c|² at rational points, by hand: the ellipsoid map xᵀQx/r − 1 with
    Q = diag(1, 4), r = 2 (−1 at the centre, 3/2 at (1, 1)); the box map of [−1, 1]² at
    (3/2, 5/4), where two faces are violated by 1/2 and 1/4: |c|² = (1/2)⁴ + (1/4)⁴ = 17/256
    (Euclidean) or max = 1/16 (max-norm), and 0 inside."""
    from obsdesign.methods.constrained.cmap import ellipsoid_map

    em = ellipsoid_map(qmat([[1, 0], [0, 4]]), 2)
    assert em.phi_q(np.array([Q(0), Q(0)], dtype=object)) == [-1]
    assert em.phi_q(np.array([Q(1), Q(1)], dtype=object)) == [fmpq(3, 2)]
    assert em.norm_c_sq_q(np.array([Q(1), Q(1)], dtype=object)) == fmpq(3, 2) ** 4
    x = np.array([fmpq(3, 2), fmpq(5, 4)], dtype=object)
    inside = np.array([Q(0), fmpq(1, 2)], dtype=object)
    eu = box_map([Q(-1), Q(-1)], [Q(1), Q(1)])
    mx = box_map([Q(-1), Q(-1)], [Q(1), Q(1)], norm="max")
    assert eu.phi_q(x) == [fmpq(-5, 2), fmpq(1, 2), fmpq(-9, 4), fmpq(1, 4)]
    assert eu.norm_c_sq_q(x) == fmpq(17, 256) and mx.norm_c_sq_q(x) == fmpq(1, 16)
    assert eu.norm_c_sq_q(inside) == 0 and mx.norm_c_sq_q(inside) == 0


def test_the_eigenvalue_ladders_end_safely(monkeypatch):
    """When no candidate of its ladder is proved (the float estimate 3× off), λ_min's lower
    bound comes from P's exact inverse, proved (the ladder on P⁻¹'s float λ_max passes at
    ≈ 1, and 1/‖P⁻¹‖_∞ = 3 would too): never above λ_min = 3, and 0 (never 1) for a P that
    is not definite; κ's upper bound comes from the next guide, the eigenvalues of the exact
    B⁻¹A in floats (session 35; it was refused, ArithmeticError)."""
    _fake_eigh_low(monkeypatch, 3.0)
    ell = B.lambda_min_lower(qmat([[3, 0], [0, 5]]))
    assert 0 < ell <= 3
    assert B.lambda_min_lower(qmat([[3, 0], [0, -5]])) == 0
    monkeypatch.undo()
    _fake_eigh_low(monkeypatch, 0.3)
    kap = B.gen_eig_upper(qmat([[1, 0], [0, 2]]), qeye(2))
    assert 2 <= kap <= 2 * (1 + fmpq(1, 10**8))


def test_v_min_condition_at_its_exact_boundaries():
    """Eq. (21) by hand. Affine: the box map of [−1, 1] over X = [−½, ½] with P = 1 and
    v = 1 gives max φ + √v = ½ and |c|² = (½)⁴ = ε_min² for ε_min = ¼: equality holds
    (≤, not <). Ellipsoid map |x|² ≤ 4 over X = [−½, ½]² with P = 4I (κ = ¼):
    (√½ + √(v/4))² ≤ 4(1 + √ε_min) with ε_min = ¼ holds up to v* = 4(√6 − √½)² ≈ 12.1436."""
    from obsdesign.methods.constrained.cmap import ellipsoid_map

    cm = box_map([Q(-1)], [Q(1)])
    P = qmat([[1]])
    X = _box([fmpq(-1, 2)], [fmpq(1, 2)])
    assert B.v_min_condition(cm, P, qinv(P), X, fmpq(1, 4), Q(1))
    assert not B.v_min_condition(cm, P, qinv(P), X, fmpq(1, 4), Q(1) + fmpq(1, 10**6))
    em = ellipsoid_map(qeye(2), 4)
    P4 = qeye(2) * 4
    X2 = _box([fmpq(-1, 2)] * 2, [fmpq(1, 2)] * 2)
    assert B.v_min_condition(em, P4, qinv(P4), X2, fmpq(1, 4), fmpq(1214, 100))
    assert not B.v_min_condition(em, P4, qinv(P4), X2, fmpq(1, 4), fmpq(1215, 100))


def test_max_phi_over_a_box_and_delta_matrix_by_hand():
    """b_i = max over the box X of φ_i: for φ = −x − 2y − 1 over [−2, 3] × [−1, ½] the corner
    (−2, −1) gives 3 (the closed form Σ_j max(g_j l_j, g_j u_j) − h agrees with the vertices);
    H of δ takes the longest normal of each antipodal class: rows (2, 0) and (−1, 0) form one
    class, H = (2, 0)ᵀ(2, 0) = diag(4, 0), whatever the order of the rows."""
    cm = polytope_map(qmat([[-1, -2]]), np.array([Q(1)], dtype=object))
    X = _box([-2, -1], [3, fmpq(1, 2)])
    assert B.max_phi_over(cm, X) == [3]
    assert max(cm.phi_q(v)[0] for v in X.vertices_q()) == 3
    for rows in ([[2, 0], [-1, 0]], [[-1, 0], [2, 0]]):
        cm2 = polytope_map(qmat(rows), np.array([Q(1), Q(1)], dtype=object))
        assert cm2.classes == [[0, 1]]
        assert B.delta_matrix(cm2).tolist() == [[4, 0], [0, 0]]


def test_max_phi_of_the_ellipsoid_map_over_a_large_box(monkeypatch):
    """Over a box with more than MAX_PAIRS vertices (forced to 0 here) the ellipsoid map's
    max xᵀQx/r − 1 is bounded by Σ|Q_ij| m_i m_j / r − 1: Q = [[2, 1], [1, 2]], r = 3,
    X = [−1, 1] × [0, 1] (m = (1, 1)) give 6/3 − 1 = 1, the exact maximum at the corner
    (1, 1) here (and at (−1, 1) for the off-diagonal −1)."""
    from obsdesign.methods.constrained.cmap import ellipsoid_map

    cm = ellipsoid_map(qmat([[2, 1], [1, 2]]), 3)
    X = _box([-1, 0], [1, 1])
    exact = B.max_phi_over(cm, X)
    assert exact == [1]
    monkeypatch.setattr(B, "MAX_PAIRS", 0)
    assert B.max_phi_over(cm, X) == [1]
    cm2 = ellipsoid_map(qmat([[2, -1], [-1, 2]]), 3)  # the same maximum, at (−1, 1)
    assert B.max_phi_over(cm2, X) == [1]


# -- mutation review 23 -----------------------------------------------------------------------
def _count_v_min_conditions(monkeypatch: pytest.MonkeyPatch, limit: int = 400) -> list[fmpq]:
    """Route v_min_lower's calls of :func:`B.v_min_condition` and :func:`B.round_sig` through
    a counter that fails the test after ``limit`` calls (a loop that never ends fails at once
    instead of hanging); returns the list of the values of v asked about."""
    real, real_round = B.v_min_condition, B.round_sig
    asked: list[fmpq] = []
    rounded: list[int] = []

    def counted(
        cm: ConstraintMap, P: np.ndarray, Pinv: np.ndarray, X: Box, eps_min: fmpq, v: fmpq
    ) -> bool:
        asked.append(Q(v))
        assert len(asked) <= limit, "v_min_lower does not end"
        return real(cm, P, Pinv, X, eps_min, v)

    def counted_round(x: fmpq, digits: int, up: bool) -> fmpq:
        rounded.append(1)
        assert len(rounded) <= limit, "v_min_lower does not end"
        return real_round(x, digits, up)

    monkeypatch.setattr(B, "v_min_condition", counted)
    monkeypatch.setattr(B, "round_sig", counted_round)
    return asked


def test_v_min_lower_is_zero_when_X_leaves_or_touches_C_min(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """v_min of eq. (21) is 0 — a safe lower bound, flagged as such — when X ⊄ int C_min
    (mutation review 23). X = [−2, 2]² and the box map of [−1, 1]² with ε_min = 1/100: the
    vertex (2, 2) of X has |c| = √2 > ε_min, so no v > 0 (nor v = 0) keeps x̂ = x in C_min.
    X = [−3/2, 3/2] and the box map of [−1, 1] with ε_min = 1/4: |c| = (1/2)² = ε_min at the
    vertices of X (the condition holds at v = 0 with equality and fails for every v > 0), so
    the bisection never leaves 0 and v_min = 0 exactly — not 1, not an error, and the
    function ends (at most a few dozen exact checks)."""
    asked = _count_v_min_conditions(monkeypatch)
    P = qmat([[2, 1], [1, 3]])
    cm = box_map([Q(-1)] * 2, [Q(1)] * 2)
    X = _box([-2, -2], [2, 2])
    assert max(cm.norm_c_sq_q(v) for v in X.vertices_q()) == 2 > fmpq(1, 100) ** 2
    vb = B.v_min_lower(cm, P, qinv(P), X, fmpq(1, 100))
    assert vb.value == 0 and vb.exact is False
    P1 = qmat([[1]])
    cm1 = box_map([Q(-1)], [Q(1)])
    X1 = _box([fmpq(-3, 2)], [fmpq(3, 2)])
    assert B.v_min_condition(cm1, P1, qinv(P1), X1, fmpq(1, 4), Q(0))
    assert not B.v_min_condition(cm1, P1, qinv(P1), X1, fmpq(1, 4), fmpq(1, 10**30))
    asked.clear()
    vb = B.v_min_lower(cm1, P1, qinv(P1), X1, fmpq(1, 4))
    assert vb.value == 0
    assert len(asked) <= 70


def test_v_min_lower_grows_its_bracket_past_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """The bisection of v_min_lower first grows its bracket (×4 from 1) until the condition
    fails, so a v_min far above 1 is found, in a few dozen exact checks (mutation review 23).
    One class, P = 1, X = [−1, 1], the box map of [−10, 10], ε_min = 1/4: max_X φ = −9, and
    −9 + √v ≤ √ε_min = 1/2 ⟺ v ≤ 9.5² = 90.25, the exact v_min (the 8-digit rounding down of
    the bisection's end); the ellipsoid map's bound is flagged as a bound."""
    asked = _count_v_min_conditions(monkeypatch)
    P = qmat([[1]])
    cm = box_map([Q(-10)], [Q(10)])
    vb = B.v_min_lower(cm, P, qinv(P), _box([-1], [1]), fmpq(1, 4))
    assert vb.exact
    assert fmpq(9025, 100) * (1 - fmpq(1, 10**7)) <= vb.value <= fmpq(9025, 100)
    assert len(asked) <= 100
    # the ellipsoid map x²/100 − 1 (κ = 1): (1 + √v)² ≤ 100(1 + √(1/4)) ⟺ v ≤ (√150 − 1)²,
    # a certified lower bound of v_min, not its exact value (the triangle inequality)
    asked.clear()
    vb = B.v_min_lower(ellipsoid_map(P, 100), P, qinv(P), _box([-1], [1]), fmpq(1, 4))
    want = (150**0.5 - 1) ** 2
    assert vb.exact is False
    assert want * (1 - 1e-7) <= float(vb.value) <= want * (1 + 1e-12)
    assert len(asked) <= 100


def test_v_min_lower_steps_down_when_its_rounded_candidate_is_refused(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The bisection's end, rounded down to 8 digits, is re-checked by the exact condition;
    if refused (the outward rounding need not be monotone in v), v_min_lower steps down by
    ×999/1000 and rounds down again until a candidate is proved (mutation review 23). The
    max-norm box map of [−3/2, 3/2]² over X = [−1, 1]², P = [[2, 1], [1, 3]], ε_min = 1/100:
    v_min = (√ε_min + 1/2)²/max_i g_iᵀP⁻¹g_i = 0.6²/(3/5) = 3/5 exactly; refusing the clean
    candidate r0 (and nothing else) must give round_sig(r0·999/1000, 8, down), proved."""
    P = qmat([[2, 1], [1, 3]])
    cm = box_map([fmpq(-3, 2)] * 2, [fmpq(3, 2)] * 2, norm="max")
    X = _box([-1, -1], [1, 1])
    eps = fmpq(1, 100)
    real = B.v_min_condition
    asked = _count_v_min_conditions(monkeypatch)
    counted = B.v_min_condition
    r0 = B.v_min_lower(cm, P, qinv(P), X, eps).value
    assert fmpq(3, 5) * (1 - fmpq(1, 10**7)) <= r0 <= fmpq(3, 5) and r0 < 1
    asked.clear()

    def refuse_r0(
        cm: ConstraintMap, P: np.ndarray, Pinv: np.ndarray, X: Box, eps_min: fmpq, v: fmpq
    ) -> bool:
        ok = counted(cm, P, Pinv, X, eps_min, v)
        return ok and Q(v) != r0

    monkeypatch.setattr(B, "v_min_condition", refuse_r0)
    r1 = B.v_min_lower(cm, P, qinv(P), X, eps).value
    assert r1 == B.round_sig(r0 * fmpq(999, 1000), 8, up=False)
    assert real(cm, P, qinv(P), X, eps, r1)
    assert len(asked) <= 100


def test_a_max_norm_polytope_map_keeps_its_norm() -> None:
    """``polytope_map(G, h, norm)`` keeps the norm of eq. (16) (mutation review 23): the
    polytope {|x_i| ≤ 3/2} is the box [−3/2, 3/2]², and with the same norm the two maps give
    the same |c| and the same v_min. With the max norm, C_min is exactly the polytope
    {φ_i ≤ √ε_min}, so v_min = min_i (√ε_min − max_X φ_i)²/g_iᵀP⁻¹g_i = (√(1/10) + 1/2)²/(3/5)
    for X = [−1, 1]², P = [[2, 1], [1, 3]] (P⁻¹ = [[3, −1], [−1, 2]]/5), exact up to the
    8-digit rounding down; the Euclidean norm gives a smaller v_min (about 1.0953 < 1.1104)."""
    import mpmath

    G = qmat([[1, 0], [-1, 0], [0, 1], [0, -1]])
    h = np.array([fmpq(3, 2)] * 4, dtype=object)
    P = qmat([[2, 1], [1, 3]])
    X = _box([-1, -1], [1, 1])
    eps = fmpq(1, 10)
    x = np.array([fmpq(2), fmpq(7, 4)], dtype=object)
    got = {}
    for norm in ("max", "euclidean"):
        pm = polytope_map(G, h, norm)
        bm = box_map([fmpq(-3, 2)] * 2, [fmpq(3, 2)] * 2, norm)
        assert pm.norm == norm
        assert pm.norm_c_sq_q(x) == bm.norm_c_sq_q(x)
        a = B.v_min_lower(pm, P, qinv(P), X, eps)
        assert a == B.v_min_lower(bm, P, qinv(P), X, eps)
        got[norm] = a
    assert polytope_map(G, h, "max").norm_c_sq_q(x) == fmpq(1, 2) ** 4
    with mpmath.workdps(40):
        want = (mpmath.sqrt(mpmath.mpf(1) / 10) + mpmath.mpf(1) / 2) ** 2 / (mpmath.mpf(3) / 5)
    v = got["max"].value
    assert got["max"].exact
    assert float(want) * (1 - 1e-7) <= float(v) and mpmath.mpf(int(v.p)) / int(v.q) <= want
    assert got["euclidean"].value < v * fmpq(99, 100)
    assert got["euclidean"].exact is False  # two classes: a bound, not the exact v_min


def test_sup_norm_c_over_a_box_exact_at_vertices_or_per_face(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """sup |c| over a box X̂ (mutation review 23): exact at its vertices up to 2^dim ≤
    MAX_PAIRS vertices, else the per-face bound √(Σ_classes max (b_i⁺)⁴). The map
    φ = (x + y, x − y) over [0, 1]² peaks at different vertices: |c|² is 16 at (1, 1) and 2 at
    (1, 0), so sup |c| = 4 exactly, while the per-face maxima b = (2, 1) give √17. In 3-D
    ([0, 1]³, 8 vertices) with MAX_PAIRS = 6 the per-face bound √17 (rounded up) is taken,
    still ≥ the true 4. The ellipsoid map |x|²·3/4 − 1 over [−1, 1]² (max φ = 1/2 at the
    corners) gives (1/2)² = 1/4 either way; a box inside C_0 gives 0."""
    from mpmath import iv

    from obsdesign.certify.interval import upper

    cm = polytope_map(qmat([[1, 1], [1, -1]]), np.array([Q(0), Q(0)], dtype=object))
    S = _box([0, 0], [1, 1])
    assert max(cm.norm_c_sq_q(v) for v in S.vertices_q()) == 16
    root17 = upper(iv.sqrt, fmpq(17))
    assert 17 <= root17**2 <= 17 * (1 + fmpq(1, 10**20))
    for pairs in (4096, 6, 4):  # 4 vertices: exact while 2^dim ≤ MAX_PAIRS
        monkeypatch.setattr(B, "MAX_PAIRS", pairs)
        assert B.sup_norm_c_over_set(cm, S) == 4, pairs
    cm3 = polytope_map(qmat([[1, 1, 0], [1, -1, 0]]), np.array([Q(0), Q(0)], dtype=object))
    S3 = _box([0, 0, 0], [1, 1, 1])
    monkeypatch.setattr(B, "MAX_PAIRS", 8)
    assert B.sup_norm_c_over_set(cm3, S3) == 4
    monkeypatch.setattr(B, "MAX_PAIRS", 6)  # 8 > 6 vertices: the per-face bound
    assert B.sup_norm_c_over_set(cm3, S3) == root17
    em = ellipsoid_map(qeye(2), fmpq(4, 3))
    S2 = _box([-1, -1], [1, 1])
    for pairs in (4096, 0):
        monkeypatch.setattr(B, "MAX_PAIRS", pairs)
        assert B.sup_norm_c_over_set(em, S2) == fmpq(1, 4), pairs
        assert B.sup_norm_c_over_set(box_map([Q(-2)] * 2, [Q(2)] * 2), S2) == 0, pairs


def test_sup_norm_c_of_an_affine_map_over_an_ellipsoid() -> None:
    """sup |c| over an ellipsoid X̂ = {(x − c)ᵀE(x − c) ≤ 1} for an affine map
    (mutation review 23): φ_i ≤ g_iᵀc − h_i + √(g_iᵀE⁻¹g_i) (the support function), then the
    per-class sum. The box map of [−1, 1]² over the disk of radius 2 centred at (1, 0): the rows
    (−x, x, −y, y) give b = (−2 + 2, 0 + 2, −1 + 2, −1 + 2) = (0, 2, 1, 1), so per antipodal
    class |c|² ≤ 2⁴ + 1⁴ = 17; the true sup is 4 (|c| = (3 − 1)² at (3, 0)), below the bound,
    as samples of the circle agree."""
    from mpmath import iv

    from obsdesign.certify.interval import upper
    from obsdesign.sets import Ellipsoid

    cm = box_map([Q(-1)] * 2, [Q(1)] * 2)
    S = Ellipsoid(qeye(2) * fmpq(1, 4), np.array([Q(1), Q(0)], dtype=object))
    got = B.sup_norm_c_over_set(cm, S)
    assert got == upper(iv.sqrt, fmpq(17))
    t = np.linspace(0, 2 * np.pi, 2001)
    pts = np.c_[1 + 2 * np.cos(t), 2 * np.sin(t)]
    assert 4 - 1e-9 <= cm.norm_c(pts).max() <= float(got)


def test_sup_norm_c_of_the_ellipsoid_map_over_an_off_centre_ellipsoid() -> None:
    """sup |c| of the ellipsoid map φ = |x|²/r − 1 over the unit disk centred at (2, 0)
    (mutation review 23): |x| ≤ |centre| + 1 = 3 (the triangle bound √(cᵀQc) + √κ, κ = 1, is
    attained at (3, 0)), so sup |c| = (9/r − 1)⁺², exact up to κ's proof slack: 3.5² = 12.25
    for r = 2, (1/8)² = 1/64 for r = 8, and 0 for r = 10 (the disk inside C_0)."""
    from obsdesign.sets import Ellipsoid

    S = Ellipsoid(qeye(2), np.array([Q(2), Q(0)], dtype=object))
    for r, want in ((2, fmpq(49, 4)), (8, fmpq(1, 64))):
        em = ellipsoid_map(qeye(2), r)
        assert em.norm_c_sq_q(np.array([Q(3), Q(0)], dtype=object)) == want**2
        got = B.sup_norm_c_over_set(em, S)
        assert want <= got <= want * (1 + fmpq(1, 10**7)), r
    assert B.sup_norm_c_over_set(ellipsoid_map(qeye(2), 10), S) == 0


def test_delta_sq_upper_by_hand() -> None:
    """δ² = sup over C_max of |dc/dx|² (Assumption 3(4)), by hand (mutation review 23).
    Polytope rows (2, 0), (−1, 0) (one antipodal class, longest normal (2, 0)) and (0, 1):
    H = diag(4, 1), δ² ≤ 4 ε_max λ_max(H) = 16 ε_max, a bound (not flagged exact), tight up
    to λ's proof slack. Ellipsoid map Q = diag(1, 3), r = 1/2, ε_max = 1/4: the bound
    16 ε_max λ_max(Q)(1 + √ε_max)/r = 36 is attained at x = (0, 1/2) on ∂C_max (φ = 1/2,
    |dc/dx| = 2φ·2|Qx|/r = 6)."""
    cm = polytope_map(qmat([[2, 0], [-1, 0], [0, 1]]), np.array([Q(1)] * 3, dtype=object))
    assert cm.classes == [[0, 1], [2]]
    d = B.delta_sq_upper(cm, fmpq(1, 4))
    assert d.exact is False
    assert 4 <= d.value <= 4 * (1 + fmpq(1, 10**7))
    em = ellipsoid_map(qmat([[1, 0], [0, 3]]), fmpq(1, 2))
    x = np.array([0.0, 0.5])
    phi = float(em.phi(x)[0])
    assert phi == 0.5
    J = 2 * phi * 2 * np.linalg.norm(em.Qf @ x) / em.r
    assert J == 6.0
    d = B.delta_sq_upper(em, fmpq(1, 4))
    assert d.exact is False
    assert 36 <= d.value <= 36 * (1 + fmpq(1, 10**7))


def test_sup_norm_c_over_Xhat_max_by_hand() -> None:
    """sup |c| over X̂_max = {x + e : x ∈ X, V(e) ≤ v_max}, eq. (15), by hand
    (mutation review 23). Affine: the box map of [−1, 1]² over X = [−½, ½]², P = diag(4, 1), v = 4:
    φ_i ≤ max_X φ_i + √(v g_iᵀP⁻¹g_i) = −½ + √(4·¼) = ½ (x faces), −½ + √4 = 3/2 (y faces),
    so |c|² ≤ (½)⁴ + (3/2)⁴ = 41/8 (Euclidean, the sum over the two classes) or (3/2)⁴ (max
    norm: sup |c| = 9/4 exactly, at x = (0, ½) + (0, 2)); with v = 0, sup |c| over X ⊂ C_0 is 0.
    Ellipsoid map |x|²/r − 1 over X = [0, 1]², P = 2I, v = 4 (|e| ≤ √2, κ = ½): |x + e| ≤
    √2 + √(vκ) = 2√2, attained at (1, 1) + (1, 1), so sup |c| = (8/r − 1)⁺²: 9 for r = 2,
    1/9 for r = 6, 0 for r = 9 — exact up to κ's proof slack; samples stay below."""
    from mpmath import iv

    from obsdesign.certify.interval import upper

    rng = np.random.default_rng(23)
    X = _box([fmpq(-1, 2)] * 2, [fmpq(1, 2)] * 2)
    P = qmat([[4, 0], [0, 1]])
    for norm, want in (("euclidean", upper(iv.sqrt, fmpq(41, 8))), ("max", fmpq(9, 4))):
        cm = box_map([Q(-1)] * 2, [Q(1)] * 2, norm)
        got = B.sup_norm_c_over_Xhat_max(cm, P, qinv(P), X, Q(4))
        assert got == want, norm
        assert B.sup_norm_c_over_Xhat_max(cm, P, qinv(P), X, Q(0)) == 0
        xs = rng.uniform(-0.5, 0.5, (400, 2))
        xs[:4] = [[-0.5, -0.5], [-0.5, 0.5], [0.5, -0.5], [0.5, 0.5]]
        pts = xs + _ellipsoid_samples(rng, np.diag([4.0, 1.0]), 4.0, 400)
        assert cm.norm_c(pts).max() <= float(got)
    cm = box_map([Q(-1)] * 2, [Q(1)] * 2, "max")
    assert cm.norm_c_sq_q(np.array([Q(0), fmpq(5, 2)], dtype=object)) == fmpq(9, 4) ** 2
    X01 = _box([0, 0], [1, 1])
    P2 = qeye(2) * 2
    for r, want in ((2, fmpq(9)), (6, fmpq(1, 9))):
        em = ellipsoid_map(qeye(2), r)
        assert em.norm_c_sq_q(np.array([Q(2), Q(2)], dtype=object)) == want**2
        got = B.sup_norm_c_over_Xhat_max(em, P2, qinv(P2), X01, Q(4))
        assert want <= got <= want * (1 + fmpq(1, 10**7)), r
    assert B.sup_norm_c_over_Xhat_max(ellipsoid_map(qeye(2), 9), P2, qinv(P2), X01, Q(4)) == 0


def test_lambda_min_lower_beyond_float_resolution() -> None:
    """P = R diag(10²⁰, 1) Rᵀ (R an exact rotation) is positive definite with λ_min = 1, but
    its float λ_min is 0: lambda_min_lower returned 0 and the design said "no γ > 0
    satisfies (24)" (exit 1) for λ near ρ(A − LC) (unusual-spec trial, session 24). The
    bound now comes from P's exact inverse and is proved by P − ℓI ⪰ 0; an indefinite or
    singular P still gets 0."""
    R = qmat([[fmpq(3, 5), fmpq(4, 5)], [fmpq(-4, 5), fmpq(3, 5)]])
    P = R.dot(qmat([[10**20, 0], [0, 1]])).dot(R.T)
    assert np.linalg.eigvalsh(np.asarray(P, dtype=float)).min() <= 0  # the float view fails
    ell = B.lambda_min_lower(P)
    assert fmpq(1, 2) <= ell <= 1
    assert B.lambda_min_lower(R.dot(qmat([[10**20, 0], [0, -1]])).dot(R.T)) == 0
    assert B.lambda_min_lower(R.dot(qmat([[10**20, 0], [0, 0]])).dot(R.T)) == 0


def test_v_min_is_found_at_any_scale() -> None:
    """The Section 5 plant with X, c, D scaled by 10⁻¹⁰ and ε_min by 10⁻²⁰: v_min scales by
    10⁻²⁰ (V is quadratic in the error). The bisection started on [0, 1] and stopped after 60
    halvings near 10⁻¹⁸, reporting v_min = 0 under a note saying "exact closed form"
    (constrained soundness trial, session 25)."""
    from pathlib import Path

    from obsdesign import api

    one = (
        Path(__file__).resolve().parents[1] / "specs" / "constrained-redesign-sec5.toml"
    ).read_text()
    one = one.split("\n[simulate]\n")[0]
    small = one
    for a, b in (
        ("[-1, -1]", "[-1e-10, -1e-10]"),
        ("[1, 1]", "[1e-10, 1e-10]"),
        ("[-1.1, -1.1]", "[-1.1e-10, -1.1e-10]"),
        ("[1.1, 1.1]", "[1.1e-10, 1.1e-10]"),
        ("[-3]", "[-3e-10]"),
        ("[3]", "[3e-10]"),
        ("eps_min = 0.01", "eps_min = 1e-22"),
    ):
        assert a in small
        small = small.replace(a, b)
    v1 = api.design(api.load_spec_text(one, "one.toml")).parameters["v_min"]
    vs = api.design(api.load_spec_text(small, "small.toml")).parameters["v_min"]
    assert v1 > 0 and vs > 0
    assert abs(vs * 10**20 / v1 - 1) < fmpq(1, 10**6), (v1, vs)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(2, 3), st.integers(0, 2**31 - 1), st.floats(0.05, 1.0), st.floats(0.5, 50.0))
def test_the_float_estimate_from_below_is_below_the_safe_bounds(n, seed, pad, v):
    """sup_norm_c_float_lower (which tells an undecided inclusion in C_max from a false one,
    session 30) is a value of |c| at points of the set: never above the safe upper bounds
    of sup |c| over X̂_max and over a box, a polytope or an ellipsoid X̂, and close to them
    where they are exact (the vertices of a box)."""
    from obsdesign.sets import Ellipsoid, Polytope

    rng = np.random.default_rng(seed)
    P = _rand_P(rng, n)
    X = _box(-np.ones(n), np.ones(n))
    G = qmat(np.vstack([np.eye(n), -np.eye(n), np.ones((1, n))]))
    g = np.array([Q(1 + pad)] * (2 * n) + [Q(n + pad)], dtype=object)
    sets = (X, Polytope(G, g), Ellipsoid(_rand_P(rng, n), np.array([Q(pad)] * n, dtype=object)))
    vq = dyadic(v, 20)
    for cm in (box_map([-1 - pad] * n, [1 + pad] * n), polytope_map(G, g)):
        up = float(B.sup_norm_c_over_Xhat_max(cm, P, qinv(P), X, vq))
        low = B.sup_norm_c_float_lower(cm, X, P, vq)
        assert 0 <= low <= up * (1 + 1e-9) + 1e-12
        for S in sets:
            up = float(B.sup_norm_c_over_set(cm, S))
            low = B.sup_norm_c_float_lower(cm, S)
            assert 0 <= low <= up * (1 + 1e-9) + 1e-12
            if S is X:  # exact at the vertices
                assert low >= up * (1 - 1e-9)


# -- mutation review 30 (docs/mutation.md)


# --- Mutation review 30: bounds._set_points_f, _ellipsoid_boundary_f,
# sup_norm_c_float_lower (ready to append to tests/test_constrained_bounds.py)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_float_estimate_from_below_is_tight_where_the_bound_is_exact(seed: int) -> None:
    """Mutation review 30 (_set_points_f: a polytope's vertices cut to one, an ellipsoid's
    boundary points dropped or shrunk; sup_norm_c_float_lower: the map's face normals
    dropped): the estimate from below reaches the safe bound at a polytope's vertices (exact
    there) and comes within 30 % / 20 % of the per-face bounds of |c|₂ over an ellipsoid and
    over X ⊕ {eᵀPe ≤ v} (loose there)."""
    from obsdesign.sets import Ellipsoid, Polytope

    rng = np.random.default_rng(seed)
    n = 3
    G = qmat(np.vstack([np.eye(n), -np.eye(n), np.ones((1, n))]))
    g = np.array([Q(1)] * (2 * n) + [Q(2)], dtype=object)  # a cut cube: 10 vertices
    poly = Polytope(G, g)
    ell = Ellipsoid(_rand_P(rng, n), np.array([Q("0.1")] * n, dtype=object))
    cm = box_map([Q("-0.5")] * n, [Q("0.5")] * n)
    up = float(B.sup_norm_c_over_set(cm, poly))
    assert B.sup_norm_c_float_lower(cm, poly) >= up * (1 - 1e-9)
    lop_g = np.array([Q(1)] * n + [Q("0.2")] * n + [Q(2)], dtype=object)
    for k in range(n):  # lopsided, turned: the farthest vertex is not always the first listed
        turned = Polytope(np.asarray(G, dtype=object)[:, np.roll(np.arange(n), k)], lop_g)
        up = float(B.sup_norm_c_over_set(cm, turned))
        assert B.sup_norm_c_float_lower(cm, turned) >= up * (1 - 1e-9)
    up = float(B.sup_norm_c_over_set(cm, ell))  # per-face bound: not exact for |c|₂
    assert B.sup_norm_c_float_lower(cm, ell) >= 0.7 * up
    P = _rand_P(rng, n)
    X = _box(-np.ones(n), np.ones(n))
    pm = polytope_map(G, np.array([Q(3)] * (2 * n) + [Q(4)], dtype=object))
    vq = dyadic(2.0, 20)
    up = float(B.sup_norm_c_over_Xhat_max(pm, P, qinv(P), X, vq))
    assert B.sup_norm_c_float_lower(pm, X, P, vq) >= 0.8 * up


def test_set_points_of_a_box_are_its_vertices_all_or_sampled() -> None:
    """Mutation review 30 (_set_points_f: ``2**n <= LOWER_POINTS`` → ``<``; the sampled
    corners all the lower one): a box of 8 dimensions gives its 256 vertices; of 10, 256
    sampled vertices, not all the same."""
    rng = np.random.default_rng(0)
    pts = B._set_points_f(_box(-np.ones(8), np.ones(8)), rng)
    assert pts.shape == (256, 8) and len({tuple(p) for p in pts}) == 256
    pts = B._set_points_f(_box(-np.ones(10), np.ones(10)), rng)
    assert pts.shape == (256, 10) and len({tuple(p) for p in pts}) > 200
    assert set(np.unique(pts)) == {-1.0, 1.0}


def test_the_float_estimate_skips_nan_and_keeps_an_overflowing_norm() -> None:
    """Mutation review 30 (sup_norm_c_float_lower: the filter dropped; 0 for no value): NaN
    is no evidence and none at all is 0 — undecided, never a refutation. +inf counts since
    session 42: the norm is taken scaled, so an infinite |c| is a component (φ_i⁺)² beyond
    the float range, the inclusion false at that point (X̂ = [−1e80, 1e80]², ε_max = 100 was
    "undecided", exit 4; float pre-screen review); a representable |c| ≈ 1.4e160 from
    components near 1e80² is not inf."""

    class Stub:
        affine = False

        def __init__(self, vals):
            self.vals = vals

        def norm_c(self, pts):
            return np.resize(np.asarray(self.vals, float), len(pts))

    X = _box(-np.ones(2), np.ones(2))
    assert B.sup_norm_c_float_lower(Stub([1.0, np.nan, 2.0, np.inf]), X) == np.inf
    assert B.sup_norm_c_float_lower(Stub([1.0, np.nan, 2.0, 1.5]), X) == 2.0
    assert B.sup_norm_c_float_lower(Stub([np.nan, np.nan]), X) == 0.0

    class Comp(Stub):  # components c_i = 1e160: |c| = 1.41e160, representable
        norm = "euclidean"

        def c(self, pts):
            return np.full((len(pts), 2), 1e160)

    assert B.sup_norm_c_float_lower(Comp([np.inf]), X) == pytest.approx(2**0.5 * 1e160)


def _psd2(M: np.ndarray) -> bool:
    """2×2 symmetric M ⪰ 0 by its diagonal and determinant (exact, independent of psd.py)."""
    a, b, d = Q(M[0, 0]), Q(M[0, 1]), Q(M[1, 1])
    return a >= 0 and d >= 0 and a * d - b * b >= 0


@pytest.mark.parametrize("guide", ["eigh", "eigvals", "norms"])
def test_gen_eig_upper_of_an_ill_conditioned_ellipsoid(monkeypatch, guide: str) -> None:
    """An ellipsoid X̂ with eigenvalues 10⁸ and 6·10⁻⁹ has a float E that is not positive
    definite: scipy's eigh raised LinAlgError, exit 3 "internal failure" for a valid spec
    (batch trial, session 35). The guides after it — the exact E⁻¹P's eigenvalues in floats,
    then ‖P‖_∞·‖E⁻¹‖_∞ — each give a κ that is proved (κE − P ⪰ 0, checked here by hand)."""
    import numpy.linalg as nl

    E = qmat(
        [
            [Q("50000000.000000003"), Q("49999999.999999997")],
            [Q("49999999.999999997"), Q("50000000.000000003")],
        ]
    )
    P = qmat([[2, Q("0.5")], [Q("0.5"), 1]])
    if guide in ("eigvals", "norms"):
        monkeypatch.setattr(
            "scipy.linalg.eigh", lambda *a, **k: (_ for _ in ()).throw(nl.LinAlgError("x"))
        )
    if guide == "norms":
        monkeypatch.setattr(np.linalg, "eigvals", lambda a: (_ for _ in ()).throw(ValueError))
    kap = B.gen_eig_upper(P, E)
    assert _psd2(symmetrize(E * kap - P))
    assert not _psd2(symmetrize(E * (kap / 2) - P)) or guide == "norms"


def test_gen_eig_upper_says_when_nothing_is_proved(monkeypatch) -> None:
    """No candidate proved (a singular E here): exit 4 with a reason, never a bare
    ArithmeticError (exit 3)."""
    from obsdesign.errors import InconclusiveError

    with pytest.raises(InconclusiveError, match="generalized eigenvalue"):
        B.gen_eig_upper(qmat([[1, 0], [0, 1]]), qmat([[1, 0], [0, 0]]))
