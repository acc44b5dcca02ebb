"""Exact inverse, rank and spectral-norm bounds (obsdesign.certify.linalg)."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.certify.exact import Q, dyadic, qeye, qmat
from obsdesign.certify.linalg import norm_bound_holds, norm_upper, qinv, qrank

F = fmpq


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 6), st.integers(0, 2**31 - 1))
def test_inverse_and_rank(n: int, seed: int):
    rng = np.random.default_rng(seed)
    B = rng.integers(-4, 5, size=(n, n))
    M = qmat(B) / 3
    r = qrank(M)
    assert r == np.linalg.matrix_rank(B)
    if r == n:
        assert (M @ qinv(M) == qeye(n)).all()


def test_inverse_known_answers():
    inv = qinv(qmat([[2, 1], [1, 1]]))
    assert (inv == qmat([[1, -1], [-1, 2]])).all()
    assert all(isinstance(v, fmpq) for v in inv.flat)
    # float input is inverted exactly (0.1 is its binary value)
    inv = qinv([[0.1]])
    assert inv[0, 0] == 1 / Q(0.1)
    inv = qinv([[F(1, 3), 0], [0, 4]])
    assert (inv == qmat([[3, 0], [0, F(1, 4)]])).all()
    with pytest.raises(ZeroDivisionError):
        qinv(qmat([[1, 2], [2, 4]]))


def test_rank_known_answers():
    assert qrank([[1, 2, 3], [2, 4, 6]]) == 1
    assert qrank([[1, 2, 3], [2, 4, 7]]) == 2
    assert qrank(qmat([[1, 1], [1, 1 + F(1, 2**80)]])) == 2  # float rank would say 1
    assert qrank([[1.0, 1.0], [1.0, 1.0 + 2.0**-52]]) == 2
    assert qrank(np.empty((0, 3), dtype=object)) == 0
    assert qrank(np.empty((3, 0), dtype=object)) == 0
    assert qrank([[0, 0], [0, 0]]) == 0
    assert qrank([[0, 0, 1]]) == 1
    assert isinstance(qrank([[1]]), int)


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 5), st.integers(1, 5), st.integers(0, 2**31 - 1))
def test_norm_upper_is_a_tight_proved_bound(r: int, c: int, seed: int):
    X = np.random.default_rng(seed).standard_normal((r, c))
    Xq = qmat(X)
    u = norm_upper(Xq)
    assert norm_bound_holds(Xq, u)
    assert norm_bound_holds(X, u)  # float input: converted exactly, same answer
    f = np.linalg.norm(X, 2)
    assert f <= float(u) <= f * (1 + 1e-6) + 1e-9
    assert not norm_bound_holds(Xq, u * fmpq(999, 1000)) or f < 1e-9


def test_norm_bound_known_answers():
    X = qmat([[3, 0], [0, 4]])  # ‖X‖ = 4
    assert norm_bound_holds(X, 4)
    assert not norm_bound_holds(X, 4 - F(1, 10**40))
    assert norm_bound_holds(X, F(9, 2))
    X = qmat([[1, 1], [0, 0]])  # ‖X‖ = √2
    assert norm_bound_holds(X, F(99, 70)) and not norm_bound_holds(X, F(140, 99))
    X = qmat([[1, 2, 2]])  # a non-square matrix, ‖X‖ = 3 (Gram is 3x3)
    assert norm_bound_holds(X, 3) and not norm_bound_holds(X, 3 - F(1, 10**30))
    assert norm_bound_holds(X.T, 3) and not norm_bound_holds(X.T, 3 - F(1, 10**30))
    # a negative u is never a bound, not even of the zero matrix (callers pass λ − ℓ)
    assert not norm_bound_holds(qmat([[0, 0]]), -F(1, 10**30))
    assert not norm_bound_holds(qmat([[0, 0]]), -1)
    assert not norm_bound_holds(np.empty((0, 2), dtype=object), -1)
    assert not norm_bound_holds(qmat([[1]]), -1)  # |−1| ≥ 1 would pass u² ≥ 1
    assert not norm_bound_holds(qmat([[F(1, 2)]]), -1)
    assert norm_bound_holds(qmat([[0, 0]]), 0)
    assert norm_bound_holds(np.empty((0, 2), dtype=object), 0)
    assert norm_bound_holds(qmat([[1]]), 1) and not norm_bound_holds(qmat([[1]]), F(1, 2))
    assert norm_bound_holds(qmat([[F(1, 2)]]), 1)
    # u given as a float or a string is exact as well
    assert norm_bound_holds([[0.1]], 0.1) and not norm_bound_holds([[0.1]], "0.1")
    assert isinstance(norm_bound_holds(qmat([[1]]), 1), bool)


def test_norm_upper_known_values():
    """The first candidate is f(1 + 2^-30) on a 40-bit dyadic grid, relative to the norm: an
    absolute 2^-40 beside it was 90 % of the bound of a block of norm 10^-12 (re-check trial,
    session 28)."""
    assert norm_upper(qmat([[1]])) == 1 + F(1, 2**30)
    assert norm_upper(qmat([[2**-50]])) == F(1, 2**50) * (1 + F(1, 2**30))
    assert norm_upper(qmat([[F(3, 10**12)]])) <= F(3, 10**12) * (1 + F(1, 2**20))
    assert norm_upper(qmat([[0, 0]])) == 0
    assert norm_upper(np.empty((0, 2), dtype=object)) == 0
    # a nonzero matrix whose float image is zero gets the exact Frobenius bound
    tiny = qmat([[F(1, 10**400)]])
    u = norm_upper(tiny)
    assert norm_bound_holds(tiny, u) and u <= F(1, 10**400) * (1 + F(1, 10**9))
    assert norm_upper([[3.0, 0.0], [0.0, -4.0]]) >= 4


def _schedule(u0: fmpq, steps: int) -> list[fmpq]:
    out = [u0]
    for _ in range(steps):
        out.append(out[-1] * F(1025, 1024))
    return out


def test_norm_upper_recovers_from_a_low_float_estimate(monkeypatch):
    """When the float norm is too low, the candidate grows by 1025/1024 per step."""
    monkeypatch.setattr(np.linalg, "norm", lambda *a, **k: 0.98)
    u = norm_upper(qmat([[1]]))
    sched = _schedule(Q(dyadic(0.98 * (1 + 2.0**-30), 40)), 39)
    first = next(i for i, v in enumerate(sched) if v >= 1)
    assert u == sched[first] and u >= 1 and sched[first - 1] < 1


def test_norm_upper_falls_back_on_the_frobenius_norm_after_40_candidates(monkeypatch):
    """A float estimate so low that 40 candidates stay below the norm: the exact Frobenius
    bound (it raised ArithmeticError before session 28); an infinite one likewise."""
    X = qmat([[1, 1], [1, 1]])  # ‖X‖₂ = 2, ‖X‖_F = 2
    for bad in (0.5, float("inf"), float("nan")):
        monkeypatch.setattr(np.linalg, "norm", lambda *a, b=bad, **k: b)
        u = norm_upper(X)
        assert norm_bound_holds(X, u) and 2 <= u <= 2 * (1 + F(1, 2**30))


def test_not_above_accepts_the_norm_rounded_up_and_refuses_more() -> None:
    """u ≤ (1 + 10⁻⁶)‖X‖₂ + 10⁻⁹ exactly: ‖diag(3, 4)‖ = 4."""
    from flint import fmpq

    from obsdesign.certify.linalg import not_above

    X = [[3, 0], [0, 4]]
    line = 4 * (1 + fmpq(1, 10**6)) + fmpq(1, 10**9)
    assert not_above(X, 4) and not_above(X, line) and not not_above(X, line + fmpq(1, 2**100))
    assert not_above([[0, 0]], fmpq(1, 10**9)) and not not_above([[0, 0]], fmpq(2, 10**9))
    assert not_above(X, -1)  # below the norm: not above it (norm_bound_holds refuses it)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.fractions(min_value=-(10**6), max_value=10**6, max_denominator=10**12),
        min_size=1,
        max_size=9,
    ),
    st.integers(min_value=-400, max_value=400),
)
def test_frobenius_fallback_is_a_tight_proved_bound(entries: list, exp: int) -> None:
    """norm_upper's fallback (session 28): u ≥ ‖X‖_F ≥ ‖X‖₂ exactly, and u is the first point
    of its 2^-shift grid above ‖X‖_F (one grid step lower is not a bound), at any scale."""
    from fractions import Fraction

    from obsdesign.certify.linalg import _frobenius_upper

    xs = [x * Fraction(2) ** exp for x in entries]
    X = qmat([[fmpq(x.numerator, x.denominator) for x in xs]])
    f2 = sum((x * x for x in xs), Fraction(0))
    u = _frobenius_upper(X)
    U = Fraction(int(u.p), int(u.q))
    assert U * U >= f2 and norm_bound_holds(X, u)
    if f2:
        assert (U - Fraction(1, U.denominator)) ** 2 < f2  # the next grid point down fails


def test_frobenius_fallback_just_above_a_square() -> None:
    """‖[[1 + 2^-100]]‖: scaled by 4^40 the square is just above the perfect square 2^80, so a
    floor where the ceiling belongs gives u = 1, below the norm."""
    from obsdesign.certify.linalg import _frobenius_upper

    X = qmat([[1 + fmpq(1, 2**100)]])
    u = _frobenius_upper(X)
    assert u > 1 and norm_bound_holds(X, u) and u == 1 + fmpq(1, 2**40)


def test_norm_upper_of_a_norm_just_above_a_power_of_two_is_rounded_up_within_1e6() -> None:
    """X = (1, 5·10⁻¹⁸)ᵀ (an impulsive block of a given M with an entry 10⁻¹⁷): ‖X‖ is 1 +
    1.25·10⁻³⁵, its float 1.0; on a 30-bit grid f(1 + 2⁻³⁰) rounded back to 1, which failed,
    and the next step (×1025/1024) gave 1.00098 — above "‖X‖ rounded up" (10⁻⁶), so the
    design failed its own lambda_no claim, exit 1 (impulsive review, session 42)."""
    from obsdesign.certify.linalg import not_above

    X = qmat([[1], [F(5, 10**18)]])
    u = norm_upper(X)
    assert norm_bound_holds(X, u) and not_above(X, u)
    assert u == 1 + F(1, 2**30)


def test_norm_upper_of_entries_beyond_the_float_range() -> None:
    """X = [[10⁴⁰⁰, 1]]: the float norm raised OverflowError (an impulsive spec with such a
    block was exit 4) where the exact Frobenius bound holds (primitives review, session 43)."""
    X = np.array([[fmpq(10**400), fmpq(1)]], dtype=object)
    u = norm_upper(X)
    assert u >= 0 and u * u >= fmpq(10**800) + 1
    assert u <= fmpq(10**400) * (1 + fmpq(1, 2**30))
    # proved by the exact check, which refuses a bound below √(10⁸⁰⁰ + 1)
    assert norm_bound_holds(X, u) and not norm_bound_holds(X, fmpq(10**400))
