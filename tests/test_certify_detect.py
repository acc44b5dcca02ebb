"""Exact observability / detectability (obsdesign.certify.detect)."""

from __future__ import annotations

import time

import numpy as np
import pytest
from flint import fmpq, fmpq_mat, fmpq_poly
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from obsdesign.certify.detect import (
    Detectability,
    detectability,
    hurwitz_stable,
    is_detectable,
    is_observable,
    observable_rowspace,
    schur_stable,
    unobservable_restriction,
)
from obsdesign.certify.exact import Q, qmat

F = fmpq


def poly(*coeffs_high_to_low) -> fmpq_poly:
    return fmpq_poly([F(c) if not isinstance(c, fmpq) else c for c in coeffs_high_to_low][::-1])


def companion(p: fmpq_poly) -> np.ndarray:
    """A matrix whose characteristic polynomial is the monic p."""
    c = [F(v) for v in p.coeffs()]
    d = len(c) - 1
    M = qmat(np.zeros((d, d), dtype=int))
    for i in range(1, d):
        M[i, i - 1] = F(1)
    for i in range(d):
        M[i, d - 1] = -c[i] / c[d]
    return M


def with_hidden(p_hidden: fmpq_poly, visible: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """(A, C) with one observable mode `visible` and the unobservable block companion(p)."""
    H = companion(p_hidden)
    d = H.shape[0]
    A = qmat(np.zeros((d + 1, d + 1), dtype=int))
    A[0, 0] = Q(visible)
    A[1:, 1:] = H
    A[1:, 0] = F(1)  # the hidden block is driven by the visible state, not seen by y
    C = qmat([[1] + [0] * d])
    return A, C


# ---------------------------------------------------------------- the examples


def test_tiny_entries_observable_exactly():
    A = [[0, 1], [-1e-320, 0]]
    C = [1e-320, 0]
    r = detectability(A, C)
    assert r == Detectability(True, True, 0, "observable: the observability matrix has full rank 2")
    assert is_observable(A, C) and is_detectable(A, C, "continuous")


def test_huge_and_tiny_entries_observable_exactly():
    A = [[1e150, 1], [1, 1e-150]]
    C = [1, 1]
    r = detectability(A, C, "continuous")
    assert r.observable and r.detectable and r.unobservable_dim == 0
    assert observable_rowspace(A, C).nrows() == 2
    B = qmat(A)
    B[1, 1] = B[0, 0]  # then C A = (1e150 + 1)·C: unobservable
    assert not is_observable(B, C)
    assert detectability(B, C, "continuous").unobservable_dim == 1


# ------------------------------------------------------------------- known answers


def test_undetectable_discrete_detectable_continuous():
    A, C = [[-2, 0], [0, 0.5]], [[0, 1]]
    d = detectability(A, C, "discrete")
    assert (d.observable, d.detectable, d.unobservable_dim) == (False, False, 1)
    assert d.reason.startswith("not detectable: rank of the observability matrix 1 < 2")
    assert "x + 2" in d.reason and "|z| < 1" in d.reason and "do not all satisfy" in d.reason
    c = detectability(A, C, "continuous")
    assert (c.observable, c.detectable, c.unobservable_dim) == (False, True, 1)
    assert c.reason.startswith("detectable:") and "all satisfy Re s < 0" in c.reason
    assert bool(c) and not bool(d)


def test_undetectable_continuous_detectable_discrete():
    A, C = [[0.5, 0], [0, 3]], [[0, 1]]  # hidden mode 1/2: stable in discrete time only
    assert is_detectable(A, C, "discrete")
    assert not is_detectable(A, C, "continuous")
    assert not is_observable(A, C)


@pytest.mark.parametrize(
    ("hidden", "discrete", "continuous"),
    [
        (poly(1, F(-1, 2)), True, False),  # z = 1/2
        (poly(1, F(1, 2)), True, True),  # z = -1/2
        (poly(1, -1), False, False),  # z = 1: on the circle / right half-plane
        (poly(1, 1), False, True),  # z = -1: on the circle, stable in continuous time
        (poly(1, 0), True, False),  # z = 0: deadbeat, on the imaginary axis
        (poly(1, 0, 1), False, False),  # ±i: on the circle and on the axis
        (poly(1, -1, 1), False, False),  # e^{±iπ/3}: on the circle, Re = 1/2
        (poly(1, F(-1, 2), 1, F(-1, 2)), False, False),  # (z - 1/2)(z² + 1)
        (poly(1, 1, 1, 1), False, False),  # (s + 1)(s² + 1): zero in the Routh array
        (poly(1, 2, 1, 2), False, False),  # (s + 2)(s² + 1): a whole zero row
        (poly(1, 0, 3, 0, 2), False, False),  # (s² + 1)(s² + 2)
        (poly(1, 3, 3, 1), False, True),  # (s + 1)³
        (poly(1, 6, 11, 6), False, True),  # (s+1)(s+2)(s+3)
        (poly(1, 1, 2, 8), False, False),  # Routh: 1, 1, -6, 8 (two roots in Re > 0)
        (poly(1, F(1, 2), F(1, 4), F(1, 8)), True, False),  # roots -1/2, ±i/2
        (poly(1, F(-3, 2), F(11, 16), F(-3, 32)), True, False),  # (z-1/4)(z-1/2)(z-3/4)
        (poly(1, F(9, 10), F(1, 10)), True, True),  # roots ≈ -0.13, -0.77
        (poly(1, -2, 1), False, False),  # double root at 1
        (poly(1, 2, 1), False, True),  # double root at -1
        (poly(1, 0, F(-1, 4)), True, False),  # ±1/2
    ],
)
def test_hidden_modes_known_answers(hidden: fmpq_poly, discrete: bool, continuous: bool):
    A, C = with_hidden(hidden)
    k = hidden.degree()
    d = detectability(A, C, "discrete")
    c = detectability(A, C, "continuous")
    assert d.unobservable_dim == c.unobservable_dim == k
    assert not d.observable and not c.observable
    assert d.detectable is discrete and c.detectable is continuous
    assert schur_stable(hidden)[0] is discrete and hurwitz_stable(hidden)[0] is continuous
    N, Au = unobservable_restriction(A, C)
    assert Au.charpoly() == hidden


def test_polynomial_test_details():
    ok, why = schur_stable(poly(1, F(-1, 2)))
    assert ok and why == "Schur–Cohn: all 1 steps with |a0| < |a_d|"
    ok, why = schur_stable(poly(2, 0, -2))
    assert not ok and why == "Schur–Cohn step 0: |a0| = 2 >= |a_d| = 2, so a root has |z| >= 1"
    ok, why = schur_stable(poly(1, F(-1, 2), 1, F(-1, 2)))
    assert not ok and why.startswith("Schur–Cohn step 1:")
    assert schur_stable(poly(5)) == (True, "Schur–Cohn: all 0 steps with |a0| < |a_d|")
    assert schur_stable(poly(-3, 1)) == (True, "Schur–Cohn: all 1 steps with |a0| < |a_d|")
    assert not schur_stable(poly(-1, 3))[0]
    ok, why = hurwitz_stable(poly(1, 1, 1, 1))
    assert not ok and why == "Routh array: first-column entry 2 is 0 <= 0"
    ok, why = hurwitz_stable(poly(1, 1, 2, 8))
    assert not ok and why == "Routh array: first-column entry 2 is -6 <= 0"
    ok, why = hurwitz_stable(poly(1, 6, 11, 6))
    assert ok and why == "Routh array: all 3 first-column entries after a_d are > 0"
    assert hurwitz_stable(poly(-1, -6, -11, -6))[0]  # a negative leading coefficient
    assert not hurwitz_stable(poly(-1, 6, -11, 6))[0]
    assert hurwitz_stable(poly(-2, -1))[0] and not hurwitz_stable(poly(-2, 1))[0]
    assert not hurwitz_stable(poly(1, 0, 1))[0]
    assert hurwitz_stable(poly(7)) == (
        True,
        "Routh array: all 0 first-column entries after a_d are > 0",
    )
    ok, why = hurwitz_stable(poly(1, 2, 3, 4, 5))  # Routh: 1, 2, 1, -6, 5
    assert not ok and why == "Routh array: first-column entry 3 is -6 <= 0"
    ok, why = hurwitz_stable(poly(1, 2, 3, 1))  # Routh: 1, 2, 5/2, 1
    assert ok
    ok, why = hurwitz_stable(poly(1, 4, 6, 4, 1))  # (s+1)^4: Routh 1, 4, 5, 16/5, 1
    assert ok
    ok, why = hurwitz_stable(poly(1, 4, 6, 4, 5))  # Routh 1, 4, 5, 0: entry 3 is 0
    assert not ok and why == "Routh array: first-column entry 3 is 0 <= 0"
    ok, why = hurwitz_stable(poly(1, 4, 6, 4, F(49, 10)))  # Routh 1, 4, 5, 2/25, 49/10
    assert ok
    ok, why = hurwitz_stable(poly(1, 4, 6, 4, F(51, 10)))  # Routh 1, 4, 5, -2/25
    assert not ok and why == "Routh array: first-column entry 3 is -2/25 <= 0"
    for bad in (schur_stable, hurwitz_stable):
        with pytest.raises(ValueError, match=r"^the zero polynomial has no roots to test$"):
            bad(fmpq_poly([]))


def test_shapes_and_errors():
    with pytest.raises(ValueError, match=r"^A must be square, got 2x3$"):
        detectability([[1, 2, 3], [4, 5, 6]], [[1, 0, 0]])
    with pytest.raises(ValueError, match=r"^C must have 2 columns \(A is 2x2\), got 3$"):
        detectability([[1, 0], [0, 1]], [[1, 0, 0]])
    with pytest.raises(
        ValueError, match=r"^time must be 'discrete' or 'continuous', not 'sampled'$"
    ):
        detectability([[1]], [[1]], "sampled")
    # no output at all: everything is unobservable
    r = detectability([[F(1, 2), 0], [0, F(-1, 3)]], np.empty((0, 2), dtype=object))
    assert (r.observable, r.detectable, r.unobservable_dim) == (False, True, 2)
    # C given as a vector, several outputs, zero output rows
    assert is_observable([[0, 1], [0, 0]], [1, 0])
    assert not is_observable([[0, 1], [0, 0]], [0, 1])
    assert is_observable([[2, 0], [0, 3]], [[1, 0], [0, 1]])
    assert not is_observable([[2, 0], [0, 3]], [[1, 0], [0, 0]])
    assert is_observable([[2, 0], [0, 3]], [[0, 0], [1, 1]])
    r = detectability([[2, 0], [0, 2]], [[1, 1]])  # repeated eigenvalue, one output
    assert r.unobservable_dim == 1 and not r.detectable
    r = detectability([[F(1, 2), 0], [0, F(1, 2)]], [[1, 1]])
    assert r.unobservable_dim == 1 and r.detectable
    assert "rank of the observability matrix 1 < 2" in r.reason


def test_restriction_is_exact():
    A = qmat([[1, 2, 0], [0, 3, 0], [1, 1, F(1, 3)]])
    C = qmat([[1, 0, 0]])
    N, Au = unobservable_restriction(A, C)
    Af = fmpq_mat(3, 3, list(A.flat))
    Cf = fmpq_mat(1, 3, list(C.flat))
    assert N.ncols() == 1 and Af * N == N * Au
    assert all(v == 0 for v in (Cf * N).entries())
    assert Au.entries() == [F(1, 3)]
    V = observable_rowspace(A, C)
    assert V.nrows() == 2 and V * N == fmpq_mat(2, 1)


# ------------------------------------------------------------- property tests


def _cayley(p: fmpq_poly) -> fmpq_poly:
    """q(z) = (z + 1)^d p((z − 1)/(z + 1)): Re s < 0 ⟺ |z| < 1."""
    c = [F(v) for v in p.coeffs()]
    d = len(c) - 1
    zm, zp = fmpq_poly([-1, 1]), fmpq_poly([1, 1])
    q = fmpq_poly([])
    for k, a in enumerate(c):
        q += a * zm**k * zp ** (d - k)
    return q


small = st.integers(-12, 12)  # coefficients in quarters: c/4


@settings(max_examples=120, deadline=None)
@given(st.lists(small, min_size=2, max_size=7))
def test_routh_agrees_with_cayley_schur(coeffs):
    p = fmpq_poly([F(c, 4) for c in coeffs])
    assume(p.degree() >= 1)
    c1 = sum(F(v) for v in p.coeffs())  # p(1)
    h = hurwitz_stable(p)[0]
    if c1 == 0:
        assert not h  # a root at s = 1
    else:
        assert h is schur_stable(_cayley(p))[0]


def _roots_decide(p: fmpq_poly, inside) -> bool | None:
    """Stability from flint's certified root balls (None when a ball touches the boundary)."""
    verdicts = []
    for r, _mult in p.complex_roots():
        v = inside(r)
        if v is None:
            return None
        verdicts.append(v)
    return all(verdicts)


def _in_disk(r):
    a = abs(r)
    if a < 1:
        return True
    if a > 1 or a == 1:
        return False
    return None  # undecided: the ball contains 1


def _in_left(r):
    re = r.real
    if re < 0:
        return True
    if re >= 0:
        return False
    return None


@settings(max_examples=100, deadline=None)
@given(st.lists(small, min_size=2, max_size=8))
def test_polynomial_tests_agree_with_root_isolation(coeffs):
    p = fmpq_poly([F(c, 4) for c in coeffs])
    assume(p.degree() >= 1)
    want = _roots_decide(p, _in_disk)
    if want is not None:
        assert schur_stable(p)[0] is want
    want = _roots_decide(p, _in_left)
    if want is not None:
        assert hurwitz_stable(p)[0] is want


def _float_pbh(A: np.ndarray, C: np.ndarray, discrete: bool) -> tuple[int, bool] | None:
    """Float PBH test on a well-conditioned system: (number of unobservable modes, detectable),
    or None when the float decision is not clear-cut."""
    n = A.shape[0]
    lam = np.linalg.eigvals(A)
    if n > 1 and min(abs(a - b) for i, a in enumerate(lam) for b in lam[i + 1 :]) < 1e-3:
        return None  # repeated eigenvalues: PBH counts are not dimensions
    hidden = []
    for z in lam:
        s = np.linalg.svd(np.vstack([A - z * np.eye(n), C]), compute_uv=False)
        if 1e-9 < s[-1] < 1e-5:
            return None
        if s[-1] <= 1e-9:
            hidden.append(z)
    stab = [abs(z) if discrete else z.real for z in hidden]
    edge = 1.0 if discrete else 0.0
    if any(abs(v - edge) < 1e-6 for v in stab):
        return None
    return len(hidden), all(v < edge for v in stab)


@settings(max_examples=60, deadline=None)
@given(
    st.integers(1, 3),
    st.integers(0, 3),
    st.integers(1, 2),
    st.booleans(),
    st.integers(0, 2**31 - 1),
)
def test_random_systems_against_float_pbh(
    n_obs: int, n_hid: int, p: int, discrete: bool, seed: int
):
    """A = T [[A11, 0], [A21, A22]] T⁻¹, C = [C1, 0] T⁻¹ with T unimodular: the A22 block is
    exactly the unobservable part when (C1, A11) is observable."""
    rng = np.random.default_rng(seed)
    n = n_obs + n_hid
    A11 = rng.integers(-3, 4, size=(n_obs, n_obs)) / 2
    A22 = rng.integers(-3, 4, size=(n_hid, n_hid)) / 2
    A21 = rng.integers(-2, 3, size=(n_hid, n_obs))
    C1 = rng.integers(-2, 3, size=(p, n_obs))
    Ab = np.block([[A11, np.zeros((n_obs, n_hid))], [A21, A22]])
    Cb = np.hstack([C1, np.zeros((p, n_hid))])
    T = np.eye(n) + np.tril(rng.integers(-1, 2, size=(n, n)), -1)  # det 1, integer inverse
    Ti = np.round(np.linalg.inv(T))
    A = T @ Ab @ Ti
    C = Cb @ Ti
    res = detectability(A, C, "discrete" if discrete else "continuous")
    Ob = np.vstack([C1 @ np.linalg.matrix_power(A11, k) for k in range(n_obs)])
    if np.linalg.matrix_rank(Ob) == n_obs:  # (C1, A11) observable: hidden part is exactly A22
        assert res.unobservable_dim == n_hid
    f = _float_pbh(A, C, discrete)
    if f is not None:
        assert res.unobservable_dim == f[0]
        assert res.detectable is f[1]
    assert res.observable is (res.unobservable_dim == 0)
    if res.observable:
        assert res.detectable
    N, Au = unobservable_restriction(A, C)
    Af = fmpq_mat(n, n, list(qmat(A).flat))
    assert Af * N == N * Au and N.ncols() == res.unobservable_dim
    Cf = fmpq_mat(qmat(C).tolist())
    assert all(v == 0 for v in (Cf * N).entries())  # N spans a subspace of ker C
    if N.ncols():
        assert N.rank() == N.ncols()


def test_n20_is_fast():
    rng = np.random.default_rng(3)
    n = 20
    A = rng.standard_normal((n, n))
    C = rng.standard_normal((2, n))
    A[:12, 12:] = 0
    C[:, 12:] = 0
    t = time.perf_counter()
    for kind in ("discrete", "continuous"):
        r = detectability(A, C, kind)
        assert r.unobservable_dim == 8 and not r.observable
        s = detectability(A.T, C[:, ::-1].copy(), kind)
        assert s.unobservable_dim <= n
    assert time.perf_counter() - t < 5.0


def test_reasons_defaults_and_small_sizes():
    A, C = [[-2, 0], [0, 0.5]], [[0, 1]]
    assert detectability(A, C).reason == (
        "not detectable: rank of the observability matrix 1 < 2; the unobservable modes "
        "(roots of x + 2) do not all satisfy |z| < 1 (Schur–Cohn step 0: |a0| = 2 >= |a_d| = 1, "
        "so a root has |z| >= 1)"
    )
    assert detectability(A, C, "continuous").reason == (
        "detectable: rank of the observability matrix 1 < 2; the unobservable modes "
        "(roots of x + 2) all satisfy Re s < 0 (Routh array: all 1 first-column entries after "
        "a_d are > 0)"
    )
    assert not is_detectable(A, C) and is_detectable(A, C, "continuous")  # default: discrete
    assert is_detectable([[F(1, 2), 0], [0, 3]], [[0, 1]])
    # several Schur–Cohn steps are counted
    assert schur_stable(poly(1, F(-3, 2), F(11, 16), F(-3, 32))) == (
        True,
        "Schur–Cohn: all 3 steps with |a0| < |a_d|",
    )
    ok, why = schur_stable(poly(1, 0, 0, F(1, 2), F(-1, 4), 1))  # a0 = 1 at step 0
    assert not ok and why.startswith("Schur–Cohn step 0:")
    ok, why = schur_stable(poly(1, F(1, 10), F(1, 10), 5, F(1, 10)))  # fails at a later step
    assert not ok and why.startswith("Schur–Cohn step ") and not why.startswith("Schur–Cohn step 0")
    # 1×1 and 0×0 systems
    assert is_observable([[2]], [[1]]) and not is_observable([[2]], [[0]])
    r = detectability([[F(1, 2)]], [[0]])
    assert (r.observable, r.detectable, r.unobservable_dim) == (False, True, 1)
    r = detectability(np.empty((0, 0), dtype=object), np.empty((1, 0), dtype=object))
    assert (r.observable, r.detectable, r.unobservable_dim) == (True, True, 0)


def test_rational_echelon_form_and_kernel():
    """A row space whose reduced echelon form is not integral (den ≠ 1 over Z)."""
    A = qmat([[0, 0, 0], [0, 0, 0], [0, 0, 0]])
    C = qmat([[2, 1, 0], [0, 3, 4]])
    V = observable_rowspace(A, C)
    assert V.tolist() == [[1, 0, F(-2, 3)], [0, 1, F(4, 3)]]
    N, Au = unobservable_restriction(A, C)
    assert N.tolist() == [[F(2, 3)], [F(-4, 3)], [1]]
    Cf = fmpq_mat(C.tolist())
    assert (Cf * N).tolist() == [[0], [0]]
    A2 = qmat([[F(1, 2), 0, 1], [0, F(1, 3), 0], [0, 0, F(1, 5)]])
    N2, Au2 = unobservable_restriction(A2, [[0, 0, 1]])
    A2f = fmpq_mat(A2.tolist())
    assert A2f * N2 == N2 * Au2 and N2.ncols() == 2
    assert (fmpq_mat([[0, 0, 1]]) * N2).tolist() == [[0, 0]]


def _schur_cohn_rational(p: fmpq_poly) -> tuple[bool, str]:
    """The rational Schur–Cohn recursion (each step made monic), as schur_stable ran it
    until session 41: the reference of the integer one."""
    c = [fmpq(v) for v in p.coeffs()]
    step = 0
    while len(c) > 1:
        a0, ad = c[0], c[-1]
        if abs(a0) >= abs(ad):
            return False, (
                f"Schur–Cohn step {step}: |a0| = {abs(a0)} >= |a_d| = {abs(ad)}, "
                "so a root has |z| >= 1"
            )
        rev = c[::-1]
        new = [ad * c[i] - a0 * rev[i] for i in range(1, len(c))]
        c = [v / new[-1] for v in new]
        step += 1
    return True, f"Schur–Cohn: all {step} steps with |a0| < |a_d|"


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.fractions(min_value=-3, max_value=3, max_denominator=12), min_size=1, max_size=9
    ).filter(lambda c: c[-1] != 0)
)
def test_integer_schur_cohn_agrees_with_the_rational_recursion(coeffs) -> None:
    """Same verdict and same message as the rational recursion, on random polynomials
    (roots inside, on and outside the unit circle; zero constant terms)."""
    p = fmpq_poly([fmpq(c.numerator, c.denominator) for c in coeffs])
    assert schur_stable(p) == _schur_cohn_rational(p)


def test_integer_schur_cohn_decides_a_degree_44_product_of_close_roots() -> None:
    """(z − 0.999)^22 (z + 0.9991)^22: stable, and decided; every root moved by 10⁻³ out of
    the disk is not."""
    inside = fmpq_poly([fmpq(-999, 1000), 1]) ** 22 * fmpq_poly([fmpq(9991, 10000), 1]) ** 22
    assert schur_stable(inside)[0]
    outside = fmpq_poly([fmpq(-1001, 1000), 1]) * inside
    assert not schur_stable(outside)[0]
