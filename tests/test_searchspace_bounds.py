"""Norm bounds of the search-space constants (:mod:`obsdesign.methods.searchspace.bounds`):
squares taken after scaling, so constants near the ends of the float range are bounded
(search-space trial, session 27: L_h = 10¹⁶⁰ was refused as "not Lipschitz (a jump?)")."""

from __future__ import annotations

import itertools
import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from obsdesign import api
from obsdesign.methods.searchspace import bounds as B

_mag = st.floats(min_value=0.0, max_value=1e307, allow_nan=False, allow_infinity=False)


def _bounds_tightly(r: float, xs: list[float]) -> bool:
    """r² ≥ Σ x² exactly (never below the root), and r² ≤ (1 + 10⁻¹³)·Σ x² unless the root
    is near the subnormal range (where one least subnormal is the rounding)."""
    s = sum(Fraction(x) ** 2 for x in xs)
    if Fraction(r) ** 2 < s:
        return False
    return r <= 1e-290 or Fraction(r) ** 2 <= s * (1 + Fraction(1, 10**13))


@given(st.lists(_mag, min_size=1, max_size=6))
def test_hypot_hi_is_a_tight_upper_bound_anywhere_in_the_float_range(xs: list[float]) -> None:
    r = B.hypot_hi(xs)
    assert r == math.inf or _bounds_tightly(r, xs)
    assert r < math.inf or sum(Fraction(x) ** 2 for x in xs) > Fraction(1.7e308) ** 2


def test_hypot_hi_at_the_ends_of_the_float_range() -> None:
    """1e160 squared overflows and 1e-300 squared underflows; scaled, both are bounded
    tightly. A root just below each (the smallest false margin, 2⁻⁵⁰ relative) is not."""
    for xs in ([1e160], [3e200, 4e200], [1e-300], [5e-324, 5e-324], [1e300, 1e-300]):
        r = B.hypot_hi(xs)
        assert _bounds_tightly(r, xs), (xs, r)
        assert not _bounds_tightly(r * (1 - 2**-50), xs) or r <= 1e-290
    assert B.hypot_hi([]) == 0.0 and B.hypot_hi([0.0, 0.0]) == 0.0
    assert B.hypot_hi([0.0, math.inf]) == math.inf
    assert B.hypot_hi([1.7e308, 1.7e308]) == math.inf  # √2·1.7·10³⁰⁸ is beyond the range


def test_norm_upper_of_huge_entries_is_finite() -> None:
    r = B.norm_upper([[1e160, 0.0], [0.0, 1e160]])
    assert 1e160 <= r <= 1e160 * (1 + 1e-14)
    r = B.norm_upper([[1e200, 1e200], [1e200, 1e200]])
    assert 2e200 <= r <= 2e200 * (1 + 1e-14)


def test_sampled_norms_do_not_overflow() -> None:
    V = np.array([[3e200, 4e200], [0.0, 0.0], [math.inf, 1.0]])
    n = B._norms(V)
    assert math.isclose(n[0], 5e200, rel_tol=1e-15) and n[1] == 0.0 and n[2] == math.inf


_HUGE = """[system]
time = "continuous"
states = ["x1"]
f = ["-x1"]
h = ["1e160*x1"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 1
[method.E]
lower = [-1]
upper = [1]
[method.D]
lower = [-0.5]
upper = [0.5]
"""


def test_a_constant_above_1e154_is_certified() -> None:
    rep = api.design(api.load_spec_text(_HUGE, "huge.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    L_h = Fraction(str(rep.parameters["L_h"]))
    assert 10**160 <= L_h <= Fraction(100001, 100000) * 10**160


# -- mutation review 27: hypot_hi stays exact where it can, _norms scales small rows ----------
def test_hypot_hi_is_exact_when_the_root_is_a_float() -> None:
    """mutation review 27 (kills bounds.x_hypot_hi__mutmut_26: a quotient stepped up when it
    is exact instead of when it underflowed; x_hypot_hi__mutmut_42: the result always
    stepped up; x_hypot_hi__mutmut_49: `ldexp(out, −e) >= r` → `>`). The power-of-two
    scaling is exact, so a root that is a float is returned as it is (3-4-5, a single entry,
    a subnormal pair); each mutant returned a larger float. An entry whose quotient
    underflows still moves the bound above the root."""
    assert B.hypot_hi([3.0, 4.0]) == 5.0
    assert B.hypot_hi([1.0]) == 1.0 and B.hypot_hi([2.0**600]) == 2.0**600
    assert B.hypot_hi([3e200, 4e200]) == B.hypot_hi([4e200, 3e200])
    assert B.hypot_hi([3.0 * 2**-1074, 4.0 * 2**-1074]) == 5.0 * 2**-1074
    r = B.hypot_hi([1.0, 2.0**-1074])  # 2⁻¹⁰⁷⁵ underflows: rounded up, not to 0
    assert r > 1.0 and Fraction(r) ** 2 >= 1 + Fraction(2) ** -2148


def test_sampled_norms_of_tiny_rows_do_not_underflow() -> None:
    """mutation review 27 (kills bounds.x__norms__mutmut_24: rows scaled only when their
    largest entry is above 1, `m > 0` → `m > 1`). The squares of 3·10⁻²⁰⁰ and 4·10⁻²⁰⁰
    underflow to 0: unscaled, the sampled estimate of ‖(3, 4)·10⁻²⁰⁰‖ was 0, not 5·10⁻²⁰⁰
    (a given constant below the true value could not be refuted)."""
    n = B._norms(np.array([[3e-200, 4e-200], [0.0, 3e-170], [0.5, 0.0]]))
    assert math.isclose(n[0], 5e-200, rel_tol=1e-15)
    assert n[1] == 3e-170 and n[2] == 0.5


def _ex(*src: str, names: tuple[str, ...] = ("x1",)) -> list:
    from obsdesign.spec.expr import parse_expr

    return [parse_expr(s, list(names)) for s in src]


def _sq(r: tuple | None) -> Fraction | None:
    """The proved square of :func:`B.proved_lower_sq` (None stays None)."""
    return None if r is None else r[0]


def test_proved_lower_sq_is_the_exact_quotient_of_rational_expressions() -> None:
    """Session 31: the witness of a sampled estimate proved exactly. h = 2·x1 between 1/2
    and 1/4 gives the quotient² 4 exactly; f = x1 − 3 at x1 = 1 gives |f|² = 4; two outputs
    add their squares (‖(2Δ, Δ)‖²/Δ² = 5)."""
    E = ([Fraction(-1)], [Fraction(1)])
    w = (np.array([0.5]), np.array([0.25]))
    assert _sq(B.proved_lower_sq(_ex("2*x1"), ["x1"], ["x1"], *E, w)) == 4
    assert _sq(B.proved_lower_sq(_ex("x1 - 3"), ["x1"], [], *E, (np.array([1.0]),))) == 4
    assert _sq(B.proved_lower_sq(_ex("2*x1", "x1"), ["x1"], ["x1"], *E, w)) == 5


def test_proved_lower_sq_of_a_smooth_function_is_a_lower_bound() -> None:
    """sin(x1) from the pair (10⁻³, 0): the proved square lies below sin's squared Lipschitz
    constant 1 on [−1, 1] and, the pair shrunk towards 0 (where cos = 1), within 10⁻⁹ of it
    (the float enclosure of sin is a few ulps wide, so the shortest secants prove less); the
    proof's pair lies on the witness segment."""
    w = (np.array([1e-3]), np.array([0.0]))
    got = B.proved_lower_sq(_ex("sin(x1)"), ["x1"], ["x1"], [Fraction(-1)], [Fraction(1)], w)
    assert got is not None
    sq, ((a,), (b,)) = got
    assert 1 - Fraction(1, 10**9) < sq < 1
    assert 0 <= b < a <= Fraction(1e-3)


def test_proved_lower_sq_refuses_what_proves_nothing() -> None:
    """No bound (None) from a witness that proves nothing about the constant on the box: a
    point outside the exact box (E = [0, 1/10], and the float 0.1 is above 1/10), points
    that differ in a variable the quotient holds fixed (u), equal points, no witness, or an
    expression undefined at the point (log(0))."""
    E = ([Fraction(0)], [Fraction(1, 10)])
    assert (
        B.proved_lower_sq(_ex("x1"), ["x1"], ["x1"], *E, (np.array([0.1]), np.array([0.0]))) is None
    )
    assert B.proved_lower_sq(_ex("x1"), ["x1"], [], *E, (np.array([0.1]),)) is None
    assert B.proved_lower_sq(_ex("x1"), ["x1"], [], *E, (np.array([0.05]),)) is not None
    box2 = ([Fraction(-1)] * 2, [Fraction(1)] * 2)
    ex = _ex("x1 + u1", names=("x1", "u1"))
    w = (np.array([0.5, 0.5]), np.array([0.25, 0.0]))
    assert B.proved_lower_sq(ex, ["x1", "u1"], ["x1"], *box2, w) is None
    assert B.proved_lower_sq(ex, ["x1", "u1"], ["x1", "u1"], *box2, w) is not None
    same = (np.array([0.5]), np.array([0.5]))
    assert B.proved_lower_sq(_ex("x1"), ["x1"], ["x1"], [Fraction(-1)], [Fraction(1)], same) is None
    assert B.proved_lower_sq(_ex("x1"), ["x1"], ["x1"], [Fraction(-1)], [Fraction(1)], None) is None
    assert B.proved_lower_sq(_ex("log(x1)"), ["x1"], [], *E, (np.array([0.0]),)) is None


def test_bounds_keep_their_best_sample_as_witness() -> None:
    """The witness is the sample of the lower estimate: its quotient is that estimate."""
    b = B.lipschitz(_ex("x1^2"), ["x1"], ["x1"], [Fraction(-1)], [Fraction(2)], 64, 1e-6)
    assert b.witness is not None and len(b.witness) == 2
    a, c = (float(w[0]) for w in b.witness)
    assert math.isclose(abs(a * a - c * c) / abs(a - c), b.lower_est, rel_tol=1e-9)
    assert b.lower_est > 3.9  # |2 x1| up to 4 on [−1, 2]
    s = B.sup_norm(_ex("x1 - 3"), ["x1"], [Fraction(-1)], [Fraction(2)], 64, 1e-6)
    assert s.witness is not None and s.lower_est == abs(float(s.witness[0][0]) - 3) == 4


def test_expressions_beyond_the_float_range_still_get_a_witness() -> None:
    """h = (x1 + 2^1100) − 2^1100 is exactly x1, but every float sample is inf − inf: the
    bound had no witness, and a given L_h = 0.5 stayed numerical, exit 0 (soundness trial,
    session 33). The witness is then the pair across the box in the variables of the
    quotient (the others at the midpoint), or the midpoint for a sup, and the exact
    evaluation proves the quotient 1 (and |h| = 2 at x1 = 2 for the sup)."""
    lo, hi = [Fraction(-1), Fraction(0)], [Fraction(1), Fraction(2)]
    ex = _ex("(x1 + 2^1100) - 2^1100 + 0*x2", names=("x1", "x2"))
    b = B.lipschitz(ex, ["x1", "x2"], ["x1"], lo, hi, 16, 1e-6)
    assert b.lower_est == 0 and b.witness is not None
    (a1, a2), (c1, c2) = (tuple(float(v) for v in w) for w in b.witness)
    assert (a1, c1) == (-1.0, 1.0) and a2 == c2 == 1.0
    proof = B.proved_lower_sq(ex, ["x1", "x2"], ["x1"], lo, hi, b.witness)
    assert proof is not None and proof[0] == 1
    s = B.sup_norm(_ex("x1*10^400/10^400 + 2"), ["x1"], [Fraction(-1)], [Fraction(1)], 16, 1e-6)
    assert s.lower_est == 0 and s.witness is not None and float(s.witness[0][0]) == 0.0
    proof = B.proved_lower_sq(
        _ex("x1*10^400/10^400 + 2"), ["x1"], [], [Fraction(-1)], [Fraction(1)], s.witness
    )
    assert proof is not None and proof[0] == 4


def test_proved_lower_sq_shrinks_the_pair_towards_the_derivative() -> None:
    """x1² on [0, 3/2], witness pair (1.5, 1.4999975): the secant gives 2.9999975, which
    refutes only values 10⁻⁶ below the constant 3 (a given 2.999999997 stayed numerical;
    re-check trial, session 31). The pair shrunk towards 1.5 by 10⁻¹² proves 3 − 3·10⁻¹⁸,
    and the proof names the shrunk pair; a proved square never exceeds 9 (the true L²)."""
    w = (np.array([1.5]), np.array([1.4999975]))
    got = B.proved_lower_sq(_ex("x1^2"), ["x1"], ["x1"], [Fraction(0)], [Fraction(3, 2)], w)
    assert got is not None
    sq, pts = got
    assert (3 - Fraction(1, 10**15)) ** 2 < sq < 9
    (a,), (b,) = pts
    assert (a + b) ** 2 == sq  # the quotient of x² between a and b is a + b
    assert 0 < abs(a - b) < Fraction(1, 10**15) and max(a, b) == Fraction(3, 2)


def test_proved_lower_sq_stops_at_the_first_pair_above_the_target() -> None:
    """With a target the proof stops at the first pair whose square exceeds it (the witness
    pair itself here: (1.5 + 1.4999975)² > 8.9), where without one the shrunk pairs go on to
    the best; a target no pair exceeds gives that best."""
    w = (np.array([1.5]), np.array([1.4999975]))
    args = (_ex("x1^2"), ["x1"], ["x1"], [Fraction(0)], [Fraction(3, 2)], w)
    first = B.proved_lower_sq(*args, target=Fraction(89, 10))
    best = B.proved_lower_sq(*args)
    assert first is not None and best is not None
    assert Fraction(89, 10) < first[0] == (Fraction(3, 2) + Fraction(1.4999975)) ** 2 < best[0]
    assert B.proved_lower_sq(*args, target=Fraction(9)) == best


def test_the_exact_proof_runs_only_for_a_value_the_enclosure_does_not_prove(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Every constant was proved at its witness at design time, 37 exact evaluations each,
    and specs with many long polynomials took 2.8× as long (re-check trial, session 31).
    Computed constants (rounded-up bounds) need no proof; a given value below the enclosure
    does, and is refuted by it."""
    from obsdesign import api
    from obsdesign.methods.searchspace import design as D

    calls: list[str] = []
    real = B.proved_lower_sq

    def counting(*a: object, **k: object) -> object:
        calls.append("x")
        return real(*a, **k)

    monkeypatch.setattr(B, "proved_lower_sq", counting)
    text = (
        '[system]\ntime = "continuous"\nstates = ["x1"]\nf = ["-x1"]\nh = ["2*x1"]\n'
        '[method]\nkey = "search-space"\nalpha = 0.5\ngamma_star = 0.1\ngamma0 = 1\n'
        "E = {lower = [-1], upper = [1]}\nD = {lower = [-0.5], upper = [0.5]}\n"
    )
    D._PROOFS.clear()
    assert api.design(api.load_spec_text(text, "s.toml")).exit_code() == 0
    assert calls == []
    given = text.replace("gamma0 = 1\n", "gamma0 = 1\nL_h = 1.999999\n")
    rep = api.design(api.load_spec_text(given, "g.toml"))
    claim = next(c for c in rep.claims if c.id == "L_h-bound")
    assert calls and claim.status.value == "failed" and "difference quotient ≥" in claim.detail


# -- mutation review 32 (session 31's checks) ----------------------------------------
def _ex_p(*src: str, names: tuple[str, ...] = ("x1",), params: dict | None = None) -> list:
    from obsdesign.spec.expr import parse_expr

    return [parse_expr(s, list(names), params) for s in src]


E = ([Fraction(-1)], [Fraction(1)])


def test_proved_lower_sq_malformed_witness_is_none_not_an_error() -> None:
    """Kills B1 (3 points accepted: unpacking error), B3 (a point of the wrong length:
    zip(strict) error), B4 (a nan/inf point: Fraction(nan) error)."""
    p = np.array([0.5])
    assert B.proved_lower_sq(_ex_p("x1"), ["x1"], ["x1"], *E, (p, p / 2, p / 4)) is None
    assert B.proved_lower_sq(_ex_p("x1"), ["x1"], [], *E, (np.array([0.5, 0.5]),)) is None
    assert B.proved_lower_sq(_ex_p("x1"), ["x1"], [], *E, (np.array([np.nan]),)) is None
    assert B.proved_lower_sq(_ex_p("x1"), ["x1"], [], *E, (np.array([np.inf]),)) is None


def test_proved_lower_sq_refuses_a_point_below_the_exact_box() -> None:
    """Kills B6 (lower end of the box not checked). The float −0.1 lies below −1/10."""
    box = ([Fraction(-1, 10)], [Fraction(1)])
    assert B.proved_lower_sq(_ex_p("x1 - 3"), ["x1"], [], *box, (np.array([-0.1]),)) is None
    assert B.proved_lower_sq(_ex_p("x1 - 3"), ["x1"], [], *box, (np.array([0.5]),)) is not None


def test_proved_lower_sq_needs_every_held_variable_equal() -> None:
    """Kills B15 (any → all): the pair differs in u1 (held fixed) but not in u2."""
    names = ["x1", "u1", "u2"]
    box = ([Fraction(-1)] * 3, [Fraction(1)] * 3)
    ex = _ex_p("x1 + u1 + u2", names=tuple(names))
    w = (np.array([0.5, 0.5, 0.0]), np.array([0.25, 0.0, 0.0]))
    assert B.proved_lower_sq(ex, names, ["x1"], *box, w) is None


def test_proved_lower_sq_shrinks_towards_the_midpoint() -> None:
    """Kills B18 (mid = (a+b)/3) and B22 (no shrinking towards the midpoint): sin(x1 − 1)
    between 0 and 2 has its largest slope (cos 0 = 1) at the midpoint 1; the secant gives
    sin(1)² ≈ 0.708 and the ends cos(1)² ≈ 0.29."""
    w = (np.array([0.0]), np.array([2.0]))
    got = B.proved_lower_sq(_ex_p("sin(x1 - 1)"), ["x1"], ["x1"], [Fraction(0)], [Fraction(2)], w)
    assert got is not None
    sq, ((a,), (b,)) = got
    assert 1 - Fraction(1, 10**9) < sq < 1
    assert a + b == 2  # a pair shrunk around the midpoint


def test_proved_lower_sq_keeps_the_whole_pair_when_it_is_best() -> None:
    """Kills B28 (the witness pair itself not tried): x1 − sin(12 x1)/12 has slope
    1 − cos(12 x1), 0 at 0, π/6 and π/3 (the pair's ends and midpoint) and average 1 over
    [0, π/3]: only the whole pair proves ≈ 1 (every shrunk copy < 0.06)."""
    w = (np.array([0.0]), np.array([1.0471975511965976]))
    got = B.proved_lower_sq(
        _ex_p("x1 - sin(12*x1)/12"), ["x1"], ["x1"], [Fraction(0)], [Fraction(2)], w
    )
    assert got is not None
    sq, pts = got
    assert sq > Fraction(99, 100)
    assert pts == ((Fraction(0),), (Fraction(1.0471975511965976),))


def test_proved_lower_sq_shrinks_by_exactly_ten_to_the_minus_shrink_steps() -> None:
    """Kills B20 (the last shrink step 10⁻ᴷ dropped): for x1² the shortest secant at 3/2 is
    the best, so the proof's pair is the witness pair shrunk by exactly 10⁻¹²."""
    w = (np.array([1.5]), np.array([1.4999975]))
    got = B.proved_lower_sq(_ex_p("x1^2"), ["x1"], ["x1"], [Fraction(0)], [Fraction(3, 2)], w)
    assert got is not None
    (a,), (b,) = got[1]
    assert abs(a - b) == (Fraction(1.5) - Fraction(1.4999975)) / 10**B.SHRINK_STEPS


def test_proved_lower_sq_skips_a_shrunk_pair_it_cannot_evaluate() -> None:
    """Kills B26 (an evaluation error on a shrunk pair returns None): 1/(x1 − 1) is defined
    at the witness 0 and 10 but not at the shrunk point 1 = 0 + (10 − 0)/10."""
    w = (np.array([0.0]), np.array([10.0]))
    got = B.proved_lower_sq(_ex_p("1/(x1 - 1)"), ["x1"], ["x1"], [Fraction(0)], [Fraction(10)], w)
    assert got is not None and got[0] >= Fraction(100, 81)


def test_proved_lower_sq_uses_the_exact_parameter_values() -> None:
    """Kills B41 (a parameter p/q taken as q/p): k·x1 with k = 2 has quotient² 4."""
    w = (np.array([0.5]), np.array([0.25]))
    got = B.proved_lower_sq(_ex_p("k*x1", params={"k": 2}), ["x1"], ["x1"], *E, w)
    assert got is not None and got[0] == 4


def test_sup_norm_witness_is_in_the_exact_box() -> None:
    """Kills B35 (samples not clipped into the exact box) and B37 (clipped to the outward
    float box): E = [−1/10, 1/10] has float ends outside it; |x1 − 3| peaks at −1/10, and the
    witness must be a point of E so that it proves something."""
    lo, hi = [Fraction(-1, 10)], [Fraction(1, 10)]
    s = B.sup_norm(_ex_p("x1 - 3"), ["x1"], lo, hi, 64, 1e-6)
    assert s.witness is not None and lo[0] <= Fraction(float(s.witness[0][0])) <= hi[0]
    assert B.proved_lower_sq(_ex_p("x1 - 3"), ["x1"], [], lo, hi, s.witness) is not None


def test_witness_follows_the_best_sample_of_the_subdivision() -> None:
    """Kills B33 (the witness not updated when a sub-box samples more): a narrow peak at
    0.3371 is found only after splitting; the witness is the point of lower_est."""
    s = B.sup_norm(
        _ex_p("1/(1 + 100*(x1 - 0.3371)^2)"), ["x1"], [Fraction(0)], [Fraction(1)], 64, 1e-6
    )
    assert s.witness is not None
    z = float(s.witness[0][0])
    assert s.lower_est > 0.99
    assert math.isclose(s.lower_est, 1 / (1 + 100 * (z - 0.3371) ** 2), rel_tol=1e-12)


def test_corner_witnesses_cover_the_box_corners_and_the_held_corners() -> None:
    """Where floats overflowed, the refutation also proves points at the box's corners
    (re-check trial, session 33): for a sup every corner; for a Lipschitz constant in (x1, x2)
    with an input u held, the pair across the box at both of u's ends and each coordinate's
    own pair at u's midpoint, every point inside the exact box."""
    lo, hi = [Fraction(-1), Fraction(0), Fraction(2)], [Fraction(1), Fraction(3), Fraction(5)]
    sup = B.corner_witnesses(["x1", "x2", "u"], [], lo, hi)
    assert len(sup) == 8 and all(len(w) == 1 for w in sup)
    assert {tuple(w[0]) for w in sup} == {
        (a, b, c) for a in (-1.0, 1.0) for b in (0.0, 3.0) for c in (2.0, 5.0)
    }
    lip = B.corner_witnesses(["x1", "x2", "u"], ["x1", "x2"], lo, hi)
    assert len(lip) == 2 + 2 * 2  # across at u's two ends; each coordinate at u's midpoint
    assert sorted(float(p[2]) for p, _ in lip) == [2.0, 3.5, 3.5, 3.5, 3.5, 5.0]
    for p, q in lip:
        assert p[2] == q[2]  # the held input equal in both points
        assert np.all(p >= [-1, 0, 2]) and np.all(q <= [1, 3, 5])
    assert any(tuple(p[:2]) == (-1.0, 0.0) and tuple(q[:2]) == (1.0, 3.0) for p, q in lip)
    assert any(tuple(p[:2]) == (-1.0, 3.0) and tuple(q[:2]) == (1.0, 3.0) for p, q in lip)
    # one variable: the pair across it, no duplicate per-coordinate pairs
    assert len(B.corner_witnesses(["x1"], ["x1"], lo[:1], hi[:1])) == 1


def test_a_zero_width_side_without_a_double_is_its_exact_value() -> None:
    """E = [−1, 1] × {1/10}: the floats beside 1/10 lie outside the exact box, so every
    witness was refused and a false L_h = 2 (h = x1 + x1², L_h = 3) or f_sup = 0.5 stayed
    numerical, exit 0 (re-check trial, session 33). A float within an ulp of a zero-width
    side stands for its exact value; elsewhere the box still refuses a point outside it."""
    lo, hi = [Fraction(-1), Fraction(1, 10)], [Fraction(1), Fraction(1, 10)]
    ex = _ex("x1 + x1**2 + 0*x2", names=("x1", "x2"))
    pair = (np.array([0.9, 0.1]), np.array([1.0, 0.1]))
    proof = B.proved_lower_sq(ex, ["x1", "x2"], ["x1"], lo, hi, pair)
    assert proof is not None and proof[0] > 4 and proof[1][0][1] == Fraction(1, 10)
    far = (np.array([0.9, 0.1000001]), np.array([1.0, 0.1000001]))
    assert B.proved_lower_sq(ex, ["x1", "x2"], ["x1"], lo, hi, far) is None


# -- mutation review 34 (session 33's checks) ----------------------------------------
def test_sup_corners_span_max_corner_vars_plus_one_variables() -> None:
    """Kills B13 (free = held[:MAX_CORNER_VARS]): for a sup the corners of the first
    MAX_CORNER_VARS + 1 = 5 variables are tried (32 points); the 6th sits at its midpoint."""
    names = [f"x{i}" for i in range(1, 7)]
    lo, hi = [Fraction(-1)] * 6, [Fraction(1)] * 6
    sup = B.corner_witnesses(names, [], lo, hi)
    assert len(sup) == 2 ** (B.MAX_CORNER_VARS + 1) == 32
    got = {tuple(float(v) for v in w[0]) for w in sup}
    assert got == {(*c, 0.0) for c in itertools.product((-1.0, 1.0), repeat=5)}


def test_the_sampled_quotient_is_not_float_noise_over_an_ulp() -> None:
    """Branch and bound narrowed a corner box to a few ulps and the sampled pair, clipped
    into it, was 5.6·10⁻¹⁷ apart: its float quotient 1.0 (exactly 0.7 at that pair) failed
    a true L_f = 0.8724 — exit 1 in design and verify (expression soundness trial, session
    34). f = (x1·x2 + x1/10, x1/3) on [0, 0.7] × [0, 0.3] has L_f = ‖J(0.7, 0.3)‖₂ =
    0.825339…; the sampled estimate stays below it and the enclosure above."""
    ex = _ex("x1*x2 + 0.1*x1", "x1/3", names=("x1", "x2"))
    lo, hi = [Fraction(0), Fraction(0)], [Fraction(7, 10), Fraction(3, 10)]
    b = B.lipschitz(ex, ["x1", "x2"], ["x1", "x2"], lo, hi, 300, 1e-6)
    # ‖[[0.4, 0.7], [1/3, 0]]‖₂ = 0.82533934…, between these two
    assert b.lower_est <= 0.8253394 and b.upper >= 0.8253393
    p, q = b.witness
    assert np.linalg.norm(np.asarray(p) - np.asarray(q)) > 1e-9


# -- Lipschitz-pair review 35 (619f3a7's two halves, each alone) --------------------------
def test_a_sampled_pair_squeezed_by_a_zero_width_side_of_e_is_not_a_quotient() -> None:
    """E = [0, 1] × {1}: a zero-width side in a differenced variable. h = x1 + 10⁴·x2 is
    x1 + 10⁴ on E, so L_h^E = 1 exactly; the finite-difference direction is almost all x2
    (v ≈ (10⁻⁴, 1)), and clipped into E the pair is 2·10⁻¹⁰ apart, where the rounding of
    h ≈ 10⁴ (ulp 1.8·10⁻¹²) made a "quotient" of 1.00044 (exact quotient at those points: 1):
    with the pair kept at any distance > 0 (or > 10⁻⁹·δ) a true given L_h = 1 failed,
    exit 1. A pair closer than 10⁻³·δ is skipped."""
    ex = _ex("x1 + 1e4*x2", names=("x1", "x2"))
    lo, hi = [Fraction(0), Fraction(1)], [Fraction(1), Fraction(1)]
    b = B.lipschitz(ex, ["x1", "x2"], ["x1", "x2"], lo, hi, 300, 1e-3)
    assert b.lower_est <= 1  # a proved lower bound since session 36
    assert b.upper >= 1
    if b.lower_est > 0:
        p, q = b.witness
        assert np.linalg.norm(np.asarray(p) - np.asarray(q)) > 1e-9


def test_a_pair_clipped_into_a_narrow_corner_box_is_not_a_quotient() -> None:
    """h = x1² + 3000.7 on [0, 7/10]: L_h = 1.4 exactly (at x1 = 0.7). With rtol 10⁻⁹ the
    branch and bound narrows the corner box to 10⁻⁸ … 10⁻⁷; a pair clipped into it (4.2·10⁻⁸
    apart) divided the rounding of h ≈ 3000 (ulp 4.5·10⁻¹³) by that: 1.4000048 (exact
    quotient at the pair 1.39999987), which failed a true given L_h = 1.4, exit 1. Kept δ
    apart in E, the pair's rounding is 3·10⁻⁷ of the quotient at most."""
    ex = _ex("x1^2 + 3000.7")
    b = B.lipschitz(ex, ["x1"], ["x1"], [Fraction(0)], [Fraction(7, 10)], 300, 1e-9)
    assert b.upper >= 1.4
    assert Fraction(b.lower_est) <= Fraction(7, 5)  # a proved lower bound since session 36
    p, q = b.witness
    assert np.linalg.norm(np.asarray(p) - np.asarray(q)) > 1e-6


# -- the sampled estimate is a proved lower bound (Lipschitz-pair review 35, §5) -----------
@pytest.mark.parametrize("c", ["300", "500", "700"])
def test_a_pair_above_the_skip_distance_is_not_float_noise(c: str) -> None:
    """E = [0, 1] × {1}, h = x1 + c·x2 (L_h^E = 1 exactly): the pair, 5.7 … 8·10⁻⁹ apart,
    passes the 10⁻³·δ skip, and the float quotient was 1.0000035 … 1.000013 — a true given
    L_h = 1 failed, exit 1. The quotient is bounded below from the enclosures at the pair."""
    ex = _ex(f"x1 + {c}*x2", names=("x1", "x2"))
    lo, hi = [Fraction(0), Fraction(1)], [Fraction(1), Fraction(1)]
    b = B.lipschitz(ex, ["x1", "x2"], ["x1", "x2"], lo, hi, 300, 1e-3)
    assert 0.99 < b.lower_est <= 1


@pytest.mark.parametrize("offset", ["1e6", "1e7", "1e8"])
def test_a_large_offset_is_not_a_steeper_slope(offset: str) -> None:
    """h = x1 + 10⁶ on [0, 1]: L_h = 1 exactly, and the interval bound is 1; the float
    quotient over 4·10⁻⁶ of values near 10⁶ was 1.0000076 (10⁷: 1.00024), and the design's
    own L_h = 1 failed its claim, design and verify exit 1 (Lipschitz-pair review, session 35)."""
    ex = _ex(f"x1 + {offset}")
    b = B.lipschitz(ex, ["x1"], ["x1"], [Fraction(0)], [Fraction(1)], 300, 1e-3)
    assert b.upper == 1.0
    assert 0.9 < b.lower_est <= 1


def test_a_sup_norm_sample_is_not_cancellation_noise() -> None:
    """f = (x1 + 10¹⁷ + 8.1) − 10¹⁷ − x1 − 8 is 1/10 everywhere; floats evaluate it as about
    8 (10¹⁷ + 8.1 rounds to 10¹⁷ + 16), which as a sampled |f| refuted a true bound. The
    estimate is the enclosure's lower end at the sample: at most 1/10."""
    ex = _ex("(x1 + 1e17 + 8.1) - 1e17 - x1 - 8")
    s = B.sup_norm(ex, ["x1"], [Fraction(0)], [Fraction(1)], 50, 1e-3)
    assert Fraction(s.lower_est) <= Fraction(1, 10)
    assert s.upper >= 0.1


def test_proved_quotient_and_norm_bound_the_exact_values() -> None:
    """At float points, the proved quotient and norm are ≤ the exact ones and within a few
    float spacings of them for a well-conditioned expression; an expression that cannot be
    enclosed (log at 0) gives 0, and so do equal points."""
    ex = _ex("x1^2 + 3000.7")
    p, q = np.array([0.7]), np.array([0.6999])
    exact = (Fraction(0.7) ** 2 - Fraction(0.6999) ** 2) / (Fraction(0.7) - Fraction(0.6999))
    got = B.proved_quotient(ex, ["x1"], p, q)
    assert Fraction(got) <= exact and got > float(exact) * (1 - 1e-8)  # ulp(3000)/10⁻⁴
    assert B.proved_quotient(ex, ["x1"], p, p) == 0.0
    assert B.proved_quotient(_ex("log(x1)"), ["x1"], np.array([0.0]), np.array([1.0])) == 0.0
    n = B.proved_norm_at(_ex("x1 - 3"), ["x1"], np.array([0.5]))
    assert n == 2.5
    assert B.proved_norm_at(_ex("x1 - 3"), ["x1"], np.array([3.0])) == 0.0


@pytest.mark.parametrize(
    "xs",
    [[3.0, 4.0], [1e-300, 1e-300], [1e300, 1e300, 1e300], [0.1, 0.2, 0.3], [5e-324], [0.0]],
)
def test_hypot_lo_is_at_most_the_exact_norm(xs: list[float]) -> None:
    """hypot_lo ≤ √Σx² (checked exactly on the squares) and hypot_hi ≥ it, without overflow
    or underflow of the squares."""
    lo, hi = B.hypot_lo(xs), B.hypot_hi(xs)
    sq = sum(Fraction(x) ** 2 for x in xs)
    assert Fraction(lo) ** 2 <= sq <= Fraction(hi) ** 2
    assert lo == 0 or hi / lo < 1 + 1e-15


ZW = """[system]
time = "continuous"
states = ["x1", "x2"]
f = ["x2", "2e17*(0.1000000000000000055511151231257827021181583404541015625 - u1)*x1"]
h = ["x1"]
u = ["0.1"]
[method]
key = "search-space"
alpha = 0.9
gamma_star = 0.05
gamma0 = 1
L_f = LF
[method.E]
lower = [-1, -1]
upper = [1, 1]
[method.D]
lower = [0, -0.5]
upper = [0, 0.5]
[method.U]
lower = [0.1]
upper = [0.1]
"""


@pytest.mark.parametrize(
    ("lf", "status"), [("2", "numerical"), ("1.12", "numerical"), ("1.1", "failed")]
)
def test_a_quotient_on_a_zero_width_side_without_a_double_is_proved_at_its_value(
    lf: str, status: str
) -> None:
    """U = {1/10}, which has no double: the samples' u1 is the float next to 1/10, and f2 =
    2·10¹⁷(0.1 as a double − u1)·x1 has slope 1.11 at u1 = 1/10 but 2.78 at the float below
    it; the quotient proved at that float point failed a true given L_f = 2, exit 1 (re-check
    trial, session 36). The side's exact value is enclosed instead; a false L_f = 1.1 is still
    refuted (exactly, at the value), and the true 1.12 stays numerical."""
    rep = api.design(api.load_spec_text(ZW.replace("LF", lf), "zw.toml"))
    c = next(c for c in rep.claims if c.id == "L_f-bound")
    assert c.status.value == status, c.detail


def test_a_side_narrower_than_an_ulp_is_enclosed_whole() -> None:
    """[1/10, 1/10 + 10⁻³⁰] holds no float either (re-check trial, session 36): it is enclosed
    by its tight interval, as a zero-width side without a double is; a side holding a float
    is not."""
    lo = [Fraction(1, 10), Fraction(0), Fraction(1)]
    hi = [Fraction(1, 10) + Fraction(1, 10**30), Fraction(1), Fraction(1)]
    fx = B.fixed_sides(lo, hi)
    assert list(fx) == [0]
    assert fx[0].lo < Fraction(1, 10) and Fraction(1, 10) + Fraction(1, 10**30) < fx[0].hi


@pytest.mark.parametrize(
    "xs",
    [
        [0.38655710476146987, 2.9000000000000004, 0.4],  # Σ rounded up would pass the root
        [1e-323, 1e-323],  # 2√2 least subnormals: rounding the result to nearest gives 3
    ],
)
def test_hypot_lo_rounds_every_step_down(xs: list[float]) -> None:
    """Mutation review 36: hypot_lo ≤ √Σx² exactly needs the sum of squares rounded down
    (add_hi/mul_hi gave 2.952867486908543 > √Σx² for the first list) and the subnormal
    result stepped down where ldexp rounded it up (2√2·2⁻¹⁰⁷⁴ rounds to 3·2⁻¹⁰⁷⁴)."""
    lo = B.hypot_lo(xs)
    assert Fraction(lo) ** 2 <= sum(Fraction(x) ** 2 for x in xs)
    assert lo > 0


def test_hypot_lo_beyond_the_float_range_is_the_largest_float() -> None:
    """Mutation review 36: a norm beyond the largest float is bounded below by the largest
    float, never by +∞ (∞ is no lower bound of a real number: proved_norm_at's estimate
    would be "above" every value)."""
    assert B.hypot_lo([1.7e308, 1.7e308]) == 1.7976931348623157e308


def test_proved_norm_at_a_point_without_an_enclosure_is_zero() -> None:
    """Mutation review 36: where F cannot be enclosed at the sample (log at 0), the proved
    sup-norm estimate is 0 (no claim), as proved_quotient's is."""
    assert B.proved_norm_at(_ex("log(x1)"), ["x1"], np.array([0.0])) == 0.0


def test_proved_norm_at_is_the_near_end_of_the_enclosure() -> None:
    """Mutation review 36: the proved |F(z)| is the end of F's enclosure nearest 0, rounded
    down. (x1 + 10¹⁷ + 0.1) − 10¹⁷ + 100 is exactly 100.6 at x1 = 0.5, enclosed as about
    [84, 116]: the far end would refute a true sup-norm bound; and 0.1·x1 is exactly 1/20 at 0.5,
    whose enclosure's upper end 0.05 is above 1/20 (hypot_hi of the near end reaches it)."""
    r = B.proved_norm_at(_ex("(x1 + 1e17 + 0.1) - 1e17 + 100"), ["x1"], np.array([0.5]))
    assert 0 < Fraction(r) <= Fraction(1006, 10)
    r = B.proved_norm_at(_ex("0.1*x1"), ["x1"], np.array([0.5]))
    assert 0.0499 < r and Fraction(r) <= Fraction(1, 20)


def test_proved_quotient_of_a_gap_enclosing_zero_is_zero() -> None:
    """Mutation review 36: h = (x1 + 10¹⁷ + 0.1) − 10¹⁷ − x1 is the constant 1/10 (L = 0),
    but its enclosure at a float point is about [0, 16]; the difference of two such
    enclosures contains 0, and only then is the gap 0 — its nearer end (16) over |p − q|
    would be a "proved" quotient of 64 for a constant."""
    ex = _ex("(x1 + 1e17 + 0.1) - 1e17 - x1")
    assert B.proved_quotient(ex, ["x1"], np.array([0.5]), np.array([0.25])) == 0.0


def test_proved_quotient_rounds_its_numerator_and_quotient_down_and_its_distance_up() -> None:
    """Mutation review 36: |F(p) − F(q)| bounded below (hypot_lo), |p − q| above (hypot_hi),
    and the quotient rounded down (_div_lo). For h = x1 at p = (1/2, 0), q = (0, y) the
    gap 1/2 is exact, so hypot_lo of the distance (y = 0.463…) or a nearest-rounded
    quotient (y = 0.795…) is above the exact quotient; 5.3·x1 over p = 0, q = 1 needs the
    gap rounded down (hypot_hi gave 5.300000000000001 > 53/10); x1 over 0.5, 0.25 is exactly
    1, and rounding it up gives 1 + 2⁻⁵²."""
    ex = _ex("x1", names=("x1", "x2"))
    for y in (0.46300735781502145, 0.7951042385853743):
        r = B.proved_quotient(ex, ["x1", "x2"], np.array([0.5, 0.0]), np.array([0.0, y]))
        assert r > 0 and Fraction(r) ** 2 * (Fraction(1, 4) + Fraction(y) ** 2) <= Fraction(1, 4)
    r = B.proved_quotient(_ex("5.3*x1"), ["x1"], np.array([0.0]), np.array([1.0]))
    assert 5.29 < r and Fraction(r) <= Fraction(53, 10)
    assert B.proved_quotient(_ex("x1"), ["x1"], np.array([0.5]), np.array([0.25])) == 1.0
