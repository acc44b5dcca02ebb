"""C_min ⊂ X̂ by dual certificates (obsdesign.methods.constrained.dual; Assumption 3(1),
constrained-redesign paper): true inclusions that the outer set's vertices refused are proved,
every false one fails however small its margin, and a tampered certificate (a negative
multiplier, Gᵀy ≠ a, a margin short by 10⁻³⁰) is never accepted."""

from __future__ import annotations

from decimal import Decimal
from fractions import Fraction as F

import hypothesis
import numpy as np
import pytest
from flint import fmpq
from hypothesis import strategies as st
from test_constrained_method import variant

from obsdesign import api
from obsdesign.certify.claim import ClaimStatus
from obsdesign.certify.exact import Q
from obsdesign.methods.constrained import claims as CL
from obsdesign.methods.constrained import dual as D
from obsdesign.methods.constrained.cmap import box_map, polytope_map
from obsdesign.sets import Polytope

TINY = fmpq(1, 10**30)
qv = np.vectorize(Q, otypes=[object])
AXES = qv(np.array([[1, 0], [0, 1], [-1, 0], [0, -1]]))
ONES = np.array([Q(1)] * 4, dtype=object)


def _xhat(extra: list[int], k: str | fmpq, side: str = "6/5") -> Polytope:
    """The box |x_i| ≤ ``side`` and one more face extra·x ≤ k."""
    H = qv(np.array([[1, 0], [0, 1], [-1, 0], [0, -1], extra]))
    kk = Q(Decimal(k)) if isinstance(k, str) else k
    return Polytope(H, np.array([Q(side)] * 4 + [kk], dtype=object))


# support of C_min = {‖(|x| − 1)⁺‖₄ ≤ 1/10} along (1, 1): 2 + 2^{3/4}/10 = 2.16817928305074290860…
@pytest.mark.parametrize(
    ("k", "holds"),
    [("2.1682", True), ("2.17", True), ("2.1999", True), ("2.1681", False), ("2.16817928", False)],
)
def test_euclidean_polytope_map_face_between_cmin_and_its_outer_corner(k: str, holds: bool) -> None:
    """The outer set's corner (1.1, 1.1) is above x1 + x2 ≤ k for every k < 2.2, but the
    Euclidean C_min has no corner there: its support is 2 + 2^{3/4}/10 ≈ 2.1681793. Above it
    the inclusion is proved by duality (it was refused, exit 4); below it, never."""
    cm = polytope_map(AXES, ONES, "euclidean")
    ok, detail = CL.cmin_in_xhat(cm, fmpq(1, 100), _xhat([1, 1], k))
    assert ok is holds, detail
    assert ("dual certificate" in detail) and ("no dual certificate" in detail) is (not holds)


def test_max_norm_face_between_sqrt_eps_and_its_rounding() -> None:
    """Max norm, ε_min = 0.02: C_min = {|x_i| ≤ 1 + √0.02}, √0.02 = 0.14142135623730950488016887
    24209698078569671…; the outer set uses a rational t ≥ √ε_min (2.4·10⁻³⁵ above), so a face
    10⁻³⁹ above C_min was refused; by duality (y = e₁, (b − 1)² ≥ ε exactly) it holds, and a
    face 10⁻³⁹ below C_min does not — for the polytope map and the box map."""
    up = "1.141421356237309504880168872420969807858"
    down = "1.141421356237309504880168872420969807856"
    cm = polytope_map(AXES, ONES, "max")
    box = box_map(np.array([Q(-1)] * 2, dtype=object), np.array([Q(1)] * 2, dtype=object), "max")
    for m in (cm, box):
        ok, detail = CL.cmin_in_xhat(m, fmpq(2, 100), _xhat([1, 0], up))
        assert ok and "dual certificate" in detail, detail
        assert not CL.cmin_in_xhat(m, fmpq(2, 100), _xhat([1, 0], down))[0]


def test_face_holds_refuses_every_tampered_certificate() -> None:
    """Max norm, a = (1, 1), y = (1, 1, 0, 0): b − yᵀh = b − 2 ≥ √ε·Σy = 0.2 exactly at b = 2.2;
    10⁻³⁰ less fails; a negative multiplier (Gᵀy = a still) and Gᵀy ≠ a by 10⁻³⁰ fail."""
    a = qv(np.array([1, 1]))
    e = fmpq(1, 100)
    y = qv(np.array([1, 1, 0, 0]))
    assert D.face_holds(AXES, ONES, "max", e, a, fmpq(22, 10), y) is True
    assert D.face_holds(AXES, ONES, "max", e, a, fmpq(22, 10) - TINY, y) is False
    neg = np.array([fmpq(1, 2), Q(1), fmpq(-1, 2), Q(0)], dtype=object)  # Gᵀneg = (1, 1)
    assert D.face_holds(AXES, ONES, "max", e, a, Q(100), neg) is False
    off = np.array([1 + TINY, Q(1), Q(0), Q(0)], dtype=object)
    assert D.face_holds(AXES, ONES, "max", e, a, Q(100), off) is False
    # every coordinate of Gᵀy = a is compared, the last one too (a check that skipped it
    # survived every test: mutation review, session 39)
    last = np.array([Q(1), 1 + TINY, Q(0), Q(0)], dtype=object)
    assert D.face_holds(AXES, ONES, "max", e, a, Q(100), last) is False
    # Euclidean: b − 2 ≥ √ε·‖y‖_{4/3} = 2^{3/4}/10 = 0.16817928305074290860…
    assert D.face_holds(AXES, ONES, "euclidean", e, a, Q(Decimal("2.1681792830507429087")), y)
    assert not D.face_holds(AXES, ONES, "euclidean", e, a, Q(Decimal("2.1681792830507429086")), y)


def test_holder_below_equal_weights_is_exact_and_ties_pass() -> None:
    """(Σ w^{4/3})³ = m³w⁴ for m equal weights: a tie is decided exactly (it holds)."""
    # one weight: ε²w⁴ ≤ a⁴ ⇔ √ε·w ≤ a, here √(1/4)·1 = 1/2 exactly
    assert D.holder_below(fmpq(1, 4), [Q(1)], fmpq(1, 2)) is True
    assert D.holder_below(fmpq(1, 4), [Q(1)], fmpq(1, 2) - TINY) is False
    assert D.holder_below(fmpq(1, 4), [Q(1), Q(0), Q(1)], fmpq(1, 2)) is False  # 2^{3/4}/2 > 1/2
    assert D.holder_below(fmpq(1, 4), [Q(1), Q(2)], Q(2)) is True  # (1 + 2^{4/3})^{3/4}/2 ≈ 1.42


def test_exact_multipliers_repairs_float_noise_and_reports_inconsistency() -> None:
    """A float y with noise becomes an exact y with Gᵀy = a: on a full-rank support (least-norm
    correction), on a support of one face (a parallel to it), and None when a is not in the
    range of the support's rows."""
    a = qv(np.array([1, 1]))
    y = D.exact_multipliers(AXES, a, np.array([1 + 3e-9, 1 - 2e-9, 1e-12, 0.0]))
    assert y is not None and list(AXES.T @ y) == list(a) and y[2] == 0
    G3 = qv(np.array([[1, 1], [1, -1], [-1, 0]]))
    y = D.exact_multipliers(G3, qv(np.array([2, 2])), np.array([2 + 1e-9, 1e-13, 0.0]))
    assert y is not None and list(G3.T @ y) == [2, 2] and list(y) == [2, 0, 0]
    assert D.exact_multipliers(G3, qv(np.array([1, 0])), np.array([1.0, 0.0, 0.0])) is None


def _point_of_cmin(G: np.ndarray, h: np.ndarray, norm: str, a: list[int]) -> list[F]:
    """A point of C_min (ε_min = 1/100) where a·x is nearly largest, checked with Fractions:
    the float maximizer of the primal problem (cvxpy) pulled towards 0 ∈ C_0 by bisection."""
    import cvxpy as cp

    Gf, hf = np.asarray(G, dtype=float), np.asarray(h, dtype=float)
    x = cp.Variable(2)
    phi = Gf @ x - hf
    con = [phi <= 0.1] if norm == "max" else [cp.pnorm(cp.pos(phi), 4) <= 0.1]
    cp.Problem(cp.Maximize(np.array(a, dtype=float) @ x), con).solve(solver=cp.CLARABEL)
    far = [F(float(v)) for v in x.value]

    def inside(p: list[F]) -> bool:
        pos = [
            max(F(int(G[i, 0])) * p[0] + F(int(G[i, 1])) * p[1] - F(int(h[i])), 0) for i in range(5)
        ]
        return (
            max(pos) ** 2 <= F(1, 100) if norm == "max" else sum(q**4 for q in pos) <= F(1, 10**4)
        )

    lo, hi = F(0), F(1)
    if inside(far):
        return far
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if inside([mid * far[0], mid * far[1]]) else (lo, mid)
    return [lo * far[0], lo * far[1]]


@hypothesis.settings(max_examples=25, deadline=None, derandomize=True)
@hypothesis.given(
    st.lists(st.integers(-9, 9), min_size=2, max_size=2).filter(lambda v: v != [0, 0]),
    st.lists(st.integers(1, 9), min_size=3, max_size=3),
    st.sampled_from(["euclidean", "max"]),
)
@hypothesis.example(a=[-2, -1], extra=[4, 2, 3], norm="max")  # a solver's 4e-9 for a zero
def test_dual_never_proves_a_face_below_the_support(
    a: list[int], extra: list[int], norm: str
) -> None:
    """A random map (the box |x_i| ≤ 1 and a cut extra₀x₁ + extra₁x₂ ≤ extra₂) and face a: a
    point x of C_min (checked with Fractions) with a·x = s close to the support; the dual
    certificate never proves a·x ≤ s − 10⁻⁹ (x violates it), and proves a·x ≤ s + 10⁻⁶(|s| + 1).
    (A solver's 4·10⁻⁹ for a zero multiplier became −3.7·10⁻⁹ in the exact correction: no
    certificate for a true face; now it leaves the support.)"""
    G = qv(np.array([[1, 0], [0, 1], [-1, 0], [0, -1], extra[:2]]))
    h = np.array([Q(1)] * 4 + [Q(extra[2])], dtype=object)
    x = _point_of_cmin(G, h, norm, a)
    val = a[0] * x[0] + a[1] * x[1]
    s = fmpq(val.numerator, val.denominator)
    face = qv(np.array([a]))
    below = np.array([s - fmpq(1, 10**9)], dtype=object)
    assert not D.faces_by_duality(G, h, norm, fmpq(1, 100), face, below)[0]
    above = np.array([s + (abs(s) + 1) / 10**6], dtype=object)
    assert D.faces_by_duality(G, h, norm, fmpq(1, 100), face, above)[0]


def test_design_certifies_a_polytope_map_inclusion_its_outer_set_refused() -> None:
    """The Section 5 plant with the polytope map |x_i| ≤ 1.1 (Euclidean) and X̂ the box 1.2 cut
    by x1 + x2 ≤ k: C_min's support is 2.2 + 2^{3/4}/10 ≈ 2.3681793 (the outer corner 2.4).
    k = 2.3682: certified (it was exit 4); k = 2.3681: not certified."""
    c = 'type = "polytope"\nG = [[1, 0], [0, 1], [-1, 0], [0, -1]]\nh = [1.1, 1.1, 1.1, 1.1]'
    for k, holds in (("2.3682", True), ("2.3681", False)):
        xh = (
            '[sets.Xh]\ntype = "polytope"\nG = [[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1]]\n'
            f"g = [1.2, 1.2, 1.2, 1.2, {k}]\n\n[method]"
        )
        text = variant(add='Xhat = "Xh"', c=c, replace=[("[method]", xh)])
        rep = api.design(api.load_spec_text(text, "xh.toml"))
        (claim,) = [x for x in rep.claims if x.id == "Cmin-in-Xhat"]
        assert (claim.status == ClaimStatus.CERTIFIED) is holds, claim.detail
        assert rep.exit_code() == (0 if holds else 1), [(x.id, x.detail) for x in rep.failed]


@pytest.mark.parametrize("scale", [1, 10**8, fmpq(1, 10**8)])
@pytest.mark.parametrize("norm", ["euclidean", "max"])
def test_rows_and_faces_of_any_scale(scale: object, norm: str) -> None:
    """C_0 = [−2, 2] written as x ≤ 2, −s·x ≤ 2s, and the face written as s·x ≤ s·b: the float
    dual of the unscaled data had no solution for s = 10⁸ (Clarabel: "infeasible"), and a face
    with a 1000 % margin stayed exit 4, as did 10⁻¹⁰x₁ + 10⁻¹⁰x₂ ≤ 2.38·10⁻¹⁰ (re-check trial,
    session 38). Rows and face are normalized for the solve: proved; 10⁻³ below the support
    (2 + √ε_min in both norms, one face violated at a time) still refused."""
    s = Q(scale)
    G = np.array([[Q(1)], [-s]], dtype=object)
    h = np.array([Q(2), 2 * s], dtype=object)
    face = np.array([[s]], dtype=object)
    for b, holds in (
        (Q(22), True),
        (fmpq(21, 10) + fmpq(1, 10**6), True),
        (fmpq(21, 10) - fmpq(1, 10**3), False),
    ):
        ok, _ = D.faces_by_duality(G, h, norm, fmpq(1, 100), face, np.array([s * b], dtype=object))
        assert ok is holds, (b, scale, norm)


def test_face_holds_refuses_wrong_sizes_and_a_huge_eps() -> None:
    """A face with an extra component, or y of the wrong length, is no certificate; an ε_min
    beyond the float range is refused (it raised OverflowError) — re-check trial, session 38."""
    a = qv(np.array([1, 1]))
    y = qv(np.array([1, 1, 0, 0]))
    e = fmpq(1, 100)
    assert D.face_holds(AXES, ONES, "max", e, qv(np.array([1, 1, 5])), Q(100), y) is False
    assert D.face_holds(AXES, ONES, "max", e, a, Q(100), y[:3]) is False
    assert D.face_holds(AXES, ONES, "max", e, a, Q(100), y) is True
    big = fmpq(10) ** 400
    ok, faces = D.faces_by_duality(
        AXES, ONES, "max", big, qv(np.array([a])), np.array([big], dtype=object)
    )
    assert not ok and faces == [0]


def test_a_refutation_by_a_vertex_of_X_names_it() -> None:
    """Polytope map |x_i| ≤ 1.1, X = [−1, 1]², X̂ = the box 1.2 cut by x1 + x2 ≤ 1.9: refuted
    (exit 1) because X's vertex (1, 1) is outside X̂, but the detail said only "no dual
    certificate for faces [4]", which reads as inconclusive (re-check trial, session 38)."""
    c = 'type = "polytope"\nG = [[1, 0], [0, 1], [-1, 0], [0, -1]]\nh = [1.1, 1.1, 1.1, 1.1]'
    xh = (
        '[sets.Xh]\ntype = "polytope"\nG = [[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1]]\n'
        "g = [1.2, 1.2, 1.2, 1.2, 1.9]\n\n[method]"
    )
    text = variant(add='Xhat = "Xh"', c=c, replace=[("[method]", xh)])
    rep = api.design(api.load_spec_text(text, "xv.toml"))
    (claim,) = [x for x in rep.claims if x.id == "Cmin-in-Xhat"]
    assert (
        rep.exit_code() == 1
        and "X's vertex (1, 1) lies in C_0 ⊂ C_min and outside X̂" in claim.detail
    )


@pytest.mark.parametrize("s", [1, fmpq(1, 10**5), fmpq(1, 10**6), fmpq(1, 10**7), 10**6])
def test_one_cmin_written_at_any_scale_is_proved_alike(s: object) -> None:
    """G, h times s and ε_min times s² describe one C_min (c scales with s²). With the weights
    √ε/d outside the norm, s = 10⁻⁶ made Clarabel fail and a face 97 % above the support
    (x2 ≤ 100, C_min's largest x2 ≈ 3) had no certificate (re-check trial, session 38): every
    scale proves it now, and a face below the support stays refused."""
    s = Q(s)
    G = qv(np.array([[2, 5], [3, -4], [-3, 3]])) * s
    h = qv(np.array([4, 3, 4])) * s
    eps = fmpq(1, 10) * s * s
    face = qv(np.array([[0, 1]]))
    for norm in ("euclidean", "max"):
        assert D.faces_by_duality(G, h, norm, eps, face, np.array([Q(100)], dtype=object))[0]
        assert not D.faces_by_duality(G, h, norm, eps, face, np.array([Q(1)], dtype=object))[0]


@pytest.mark.parametrize("norm", ["euclidean", "max"])
@pytest.mark.parametrize("h0", [1, 0])
def test_a_zero_row_of_the_map_gets_the_multiplier_zero(norm: str, h0: int) -> None:
    """A row 0·x ≤ h₀ (h₀ ≥ 0: φ_i = −h₀ ≤ 0 is never positive) leaves C_min as it is; its
    norm 0 made the unit-row scaling give up and every face undecided, exit 4 for a true
    inclusion with a 10⁻³ margin (constrained fuzz, session 39). Its multiplier is 0: the
    same faces are proved with and without it, and none below the support."""
    G = qv(np.array([[1, 0], [0, 1], [-1, 0], [0, -1]]))
    h = np.array([fmpq(11, 10)] * 4, dtype=object)
    Gz = np.vstack([G, qv(np.array([[0, 0]]))])
    hz = np.append(h, Q(h0))
    # support along (1, 1) with ε = 1/100: 2.2 + 2^{3/4}/10 ≈ 2.3681793 (Euclidean),
    # 2.2 + 2/10 (max)
    face = qv(np.array([[1, 1]]))
    s = Q(Decimal("2.36818" if norm == "euclidean" else "2.4"))
    above = np.array([s + fmpq(1, 10**3)], dtype=object)
    below = np.array([s - fmpq(1, 10**3)], dtype=object)
    assert D.faces_by_duality(G, h, norm, fmpq(1, 100), face, above)[0]
    assert D.faces_by_duality(Gz, hz, norm, fmpq(1, 100), face, above)[0]
    assert not D.faces_by_duality(Gz, hz, norm, fmpq(1, 100), face, below)[0]
    yf = D.float_multipliers(
        np.asarray(Gz, dtype=float), np.asarray(hz, dtype=float), norm, 0.01, np.ones(2)
    )
    assert yf is not None and yf[-1] == 0.0


def test_holder_is_exact_for_weights_a_rational_cube_apart() -> None:
    """Weights w_i = w_1·k_i³ (1.728, 3.375, 8 = 1.2³, 1.5³, 2³): (Σ w_i^{4/3})³ = w_1⁴(Σ k_i⁴)³
    is rational, so a face exactly touching C_min is decided (it was "undecided at 1024
    bits", exit 4; mutation review, session 39) — the tie holds, 10⁻⁶⁰ less does not; a
    ratio that is no cube (1, 2) still goes to the balls."""
    w = [Q(Decimal("1.728")), Q(Decimal("3.375")), Q(8)]
    eps = Q(Decimal("0.000481"))
    # √ε·‖w‖_{4/3} = √ε·(1.2⁴ + 1.5⁴ + 2⁴)^{3/4} = √0.000481·(23.1361)^{3/4}
    # = 0.0219317…·10.5453… : the exact a with a⁴ = ε²·(Σ k_i⁴·1.2⁴)³ is 0.01·4.81² = 0.231361
    tie = Q(Decimal("0.231361"))
    assert eps**2 * (Q(Decimal("23.1361"))) ** 3 == tie**4
    assert D.holder_below(eps, w, tie) is True
    assert D.holder_below(eps, w, tie - fmpq(1, 10**60)) is False
    assert D.holder_below(eps, [Q(0), *w, Q(0)], tie) is True  # zeros are skipped
    assert D.holder_below(eps, [Q(0), Q(0)], Q(0)) is True
    # scaled by a non-cube: still a cube apart from each other
    assert D.holder_below(eps * 4, [x * 2 for x in w], tie * 4) is True  # ×256 both sides
    assert D._cube_roots([Q(2)]) is None and D._cube_roots([fmpq(27, 8)]) == [fmpq(3, 2)]


def test_a_face_touching_cmin_with_cube_weights_is_certified() -> None:
    """The 3-state box map R = [−1, 1]³, ε_min = 0.000481 and the X̂ face
    (1.728, 3.375, 8)·x ≤ 13.334361, exactly C_min's support (13.103 + 0.231361): certified
    (exit 4 before); 10⁻³⁰ lower: refused."""
    from obsdesign.methods.constrained.cmap import box_map

    lo = np.array([Q(-1)] * 3, dtype=object)
    hi = np.array([Q(1)] * 3, dtype=object)
    cm = box_map(lo, hi, "euclidean")
    face = np.array([[Q(Decimal("1.728")), Q(Decimal("3.375")), Q(8)]], dtype=object)
    k = Q(Decimal("13.334361"))
    eps = Q(Decimal("0.000481"))
    assert CL.box_l4_faces(cm, eps, face, np.array([k], dtype=object))[0] is True
    low = np.array([k - fmpq(1, 10**30)], dtype=object)
    assert CL.box_l4_faces(cm, eps, face, low)[0] is False
