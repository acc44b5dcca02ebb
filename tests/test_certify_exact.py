"""Rational conversions (obsdesign.certify.exact)."""

from __future__ import annotations

from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest
from flint import fmpq
from hypothesis import given
from hypothesis import strategies as st

from obsdesign.certify.exact import Q, dyadic, qmat, qparse, qstr, qvec, to_float


def test_decimal_is_exact():
    assert Q(Decimal("0.1")) + Q(Decimal("0.2")) == fmpq(3, 10)
    assert Q(0.1) != fmpq(1, 10)  # a float is its binary value


def test_conversions():
    assert Q(Fraction(-187, 100)) == fmpq(-187, 100)
    assert Q("-187/100") == fmpq(-187, 100)
    assert Q(3) == fmpq(3)
    with pytest.raises(ValueError):
        Q(float("nan"))
    with pytest.raises(ValueError):
        Q(Decimal("inf"))
    with pytest.raises(TypeError):
        Q(True)


def test_qstr_qparse_roundtrip_3d():
    a = qmat([[1, 2], [3, 4]])
    assert (qparse(qstr(a)) == a).all()
    cube = np.empty((2, 2, 2), dtype=object)
    for idx in np.ndindex(2, 2, 2):
        cube[idx] = fmpq(sum(idx) - 1, 3)
    back = qparse(qstr(cube))
    assert back.shape == (2, 2, 2) and (back == cube).all()


@given(st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=6))
def test_dyadic_close_and_exact_grid(xs):
    arr = np.array(xs)
    q = dyadic(arr, 30)
    back = np.asarray(to_float(q), dtype=float)
    assert np.all(np.abs(back - arr) <= np.abs(arr) * 2.0**-30)
    for v in q:
        assert int(v.q) & (int(v.q) - 1) == 0  # denominator is a power of two


# ------------------------------------------------------------ known answers, every branch

F = fmpq


def test_Q_every_input_type():
    assert Q(np.int64(-7)) == -7 and isinstance(Q(np.int64(-7)), fmpq)
    assert Q(np.float32(0.1)) == Q(float(np.float32(0.1)))
    assert Q(0.5) == F(1, 2) and Q(-0.1) == -Q(0.1)
    assert Q(2.0**-1074) == F(1, 2**1074)
    assert Q(" 1/3 ") == F(1, 3) and Q("0.1") == F(1, 10) and Q("1e-3") == F(1, 1000)
    assert Q(Decimal("-2.5")) == F(-5, 2)
    x = F(2, 7)
    assert Q(x) is x
    for bad in (float("inf"), float("-inf"), np.float64("nan")):
        with pytest.raises(ValueError, match=r"^not a finite number: "):
            Q(bad)
    with pytest.raises(ValueError, match=r"^not a finite number: "):
        Q(Decimal("nan"))
    with pytest.raises(TypeError, match=r"^a boolean is not a number$"):
        Q(False)
    with pytest.raises(TypeError, match=r"^cannot convert list to a rational$"):
        Q([1])
    with pytest.raises(TypeError, match=r"^cannot convert complex to a rational$"):
        Q(1j)


def test_qmat_qvec_qeye_qzeros():
    m = qmat([1, 2.5])
    assert m.shape == (1, 2) and m[0, 1] == F(5, 2) and m.dtype == object
    assert all(isinstance(v, fmpq) for v in m.flat)
    m = qmat([[F(1, 3), "2/3"], [0.25, 4]])
    assert m.shape == (2, 2) and (m == np.array([[F(1, 3), F(2, 3)], [F(1, 4), F(4)]])).all()
    for bad in (np.zeros((2, 2, 2)), 5):
        with pytest.raises(ValueError, match=r"^expected a matrix$"):
            qmat(bad)
    v = qvec([[1, 2], [3, 0.5]])
    assert v.shape == (4,) and v[3] == F(1, 2) and v.dtype == object
    assert all(isinstance(x, fmpq) for x in v)
    from obsdesign.certify.exact import qeye, qzeros

    eye = qeye(3)
    assert eye.shape == (3, 3) and eye.dtype == object
    assert all(eye[i, j] == (1 if i == j else 0) for i in range(3) for j in range(3))
    assert all(isinstance(x, fmpq) for x in eye.flat)
    z = qzeros((2, 3))
    assert z.shape == (2, 3) and all(x == 0 and isinstance(x, fmpq) for x in z.flat)


def test_to_float_correctly_rounded():
    assert to_float(F(1, 3)) == 1 / 3 and isinstance(to_float(F(1, 3)), float)
    big = F(3**40, 7**20)  # needs correct rounding, not float(p) / float(q)
    from fractions import Fraction as Fr

    assert to_float(big) == float(Fr(3**40, 7**20))
    a = to_float(qmat([[F(1, 2), F(-3)]]))
    assert a.dtype == float and a.tolist() == [[0.5, -3.0]]
    e = to_float(np.empty((0, 2), dtype=object))
    assert e.shape == (0, 2) and e.dtype == float
    mixed = to_float(np.array([1, 2.5, F(1, 4)], dtype=object))
    assert mixed.tolist() == [1.0, 2.5, 0.25] and mixed.dtype == float


def test_dyadic_known_values():
    assert dyadic(1 / 3, 4) == F(11, 32)
    assert dyadic(1 / 3) == F(11184811, 2**25)  # default 24 bits
    assert dyadic(1e10, 4) == 9 * 2**30
    assert dyadic(2.0**40, 10) == 2**40
    assert dyadic(-0.75, 1) == -1  # round half to even on the 1-bit grid
    assert dyadic(0.0) == 0 and isinstance(dyadic(0.0), fmpq)
    assert dyadic(3.0, 2) == 3 and dyadic(5.0, 2) == 4
    arr = dyadic(np.array([[0.1, -0.2]]), 8)
    assert arr.shape == (1, 2) and arr[0, 0] == F(205, 2048) and arr[0, 1] == F(-205, 1024)
    with pytest.raises(ValueError, match=r"^cannot round a non-finite number$"):
        dyadic([1.0, float("inf")])


def test_symmetrize_qstr_qparse_qmax_abs():
    from obsdesign.certify.exact import qmax_abs, symmetrize

    S = symmetrize(qmat([[1, 2], [0, 3]]))
    assert (S == qmat([[1, 1], [1, 3]])).all()
    assert qstr(F(-187, 100)) == "-187/100" and qstr(5) == "5"
    assert qstr(np.array(F(1, 3), dtype=object)) == "1/3"
    assert qstr(qmat([[1, F(1, 2)]])) == [["1", "1/2"]]
    assert qstr(qvec([1, F(-1, 2)])) == ["1", "-1/2"]
    assert qparse("3/4") == F(3, 4) and qparse(2) == 2 and qparse(0.5) == F(1, 2)
    p = qparse([["1/2", 3], [0.25, "-1"]])
    assert p.shape == (2, 2) and p[1, 0] == F(1, 4) and all(isinstance(v, fmpq) for v in p.flat)
    for bad in (True, None, {"a": 1}, [], [[1, 2], [3]], [1, True], [1, None], [[1], [[2]]]):
        with pytest.raises(ValueError):
            qparse(bad)
    with pytest.raises(ValueError, match=r"^ragged or empty exact array$"):
        qparse([])
    for ragged in ([[1, 2], [3]], [[1], [[2]]], [["1/2", "1"], ["3"]]):  # found in the entries
        with pytest.raises(ValueError, match=r"^ragged or empty exact array$"):
            qparse(ragged)
    with pytest.raises(ValueError, match=r"^not an exact value: "):
        qparse([1, None])
    with pytest.raises(ValueError, match=r"^not an exact value: "):
        qparse(True)
    assert qmax_abs(qmat([[1, -3], [2, 0]])) == 3
    assert qmax_abs(np.empty((0,), dtype=object)) == 0 and isinstance(
        qmax_abs(np.empty((0,), dtype=object)), fmpq
    )


def test_mixed_and_empty_inputs_stay_exact():
    # a float next to a string must keep its binary value (no common string dtype)
    v = qvec([0.1, "1/3"])
    assert v[0] == Q(0.1) and v[0] != F(1, 10) and v[1] == F(1, 3)
    e = qvec([])
    assert e.shape == (0,) and e.dtype == object
    assert dyadic(np.array([F(1, 3)], dtype=object), 4)[0] == F(11, 32)
    assert dyadic([F(-3, 4)], 1)[0] == -1
    p = qparse([1, 2])  # plain ints are exact values
    assert p.tolist() == [F(1), F(2)] and all(isinstance(x, fmpq) for x in p)
    assert qparse([[3], [4]]).shape == (2, 1)
    assert qparse([0.1])[0] == Q(0.1)


@given(st.integers(-(10**40), 10**40), st.integers(1, 10**40))
def test_q_of_ratio_text_and_nearest_float_match_fraction(p: int, q: int) -> None:
    """The integer-parsing fast path of Q and the int/int float of to_float agree with
    Fraction (parse, and correctly rounded float) on canonical and non-canonical texts."""
    fr = Fraction(p, q)
    for text in (f"{p}/{q}", str(fr)):
        x = Q(text)
        assert (int(x.p), int(x.q)) == (fr.numerator, fr.denominator)
        assert to_float(x) == float(fr)
    assert list(to_float(qparse([f"{p}/{q}", str(p)]))) == [float(fr), float(p)]


def test_q_of_text_rejects_zero_denominator_and_keeps_fraction_forms() -> None:
    with pytest.raises(ZeroDivisionError):
        Q("3/0")
    assert Q("1.25") == fmpq(5, 4) and Q(" -2/4 ") == fmpq(-1, 2) and Q("1e2") == 100
    with pytest.raises(ValueError):
        Q("1/2/3")
    for text in ("١", "1/٢", "٣.5", "1\u00a0"):  # digits and spaces beyond ASCII
        with pytest.raises(ValueError, match="non-ASCII"):
            Q(text)


@given(
    st.decimals(allow_nan=False, allow_infinity=False),
    st.floats(allow_nan=False, allow_infinity=False),
)
def test_q_of_decimal_and_float_is_their_exact_value(d: Decimal, f: float) -> None:
    fd, ff = Fraction(d), Fraction(f)
    assert (int(Q(d).p), int(Q(d).q)) == (fd.numerator, fd.denominator)
    assert (int(Q(f).p), int(Q(f).q)) == (ff.numerator, ff.denominator)


@given(
    st.integers(min_value=-(10**40), max_value=10**40),
    st.integers(min_value=1, max_value=10**40),
)
def test_qstr_entries_are_flints_str(p: int, q: int) -> None:
    """qstr's fast entry format is flint's str of the same fmpq (sign, q = 1, big ints)."""
    x = fmpq(p, q)
    assert qstr(np.array([x, -x], dtype=object)) == [str(x), str(-x)]


_ent = st.one_of(
    st.builds(fmpq, st.integers(-(10**30), 10**30), st.integers(1, 10**30)),
    st.builds(lambda e: fmpq(2**e) if e >= 0 else fmpq(1, 2**-e), st.integers(-1100, 1100)),
)


@given(st.lists(_ent, min_size=1, max_size=9), st.sampled_from([(1, -1), (-1, 1), (-1,)]))
def test_qstr_floats_and_qparse_floats_equal_the_separate_passes(xs, shape) -> None:
    """The one-pass forms give qstr / qparse and to_float exactly (floats bit for bit), and
    raise OverflowError where to_float does; non-canonical strings take the general path."""
    from obsdesign.certify.exact import qparse_floats, qstr_floats

    a = np.array(xs, dtype=object).reshape(shape)
    try:
        want_f = np.asarray(to_float(a), dtype=float).tolist()
    except OverflowError:
        with pytest.raises(OverflowError):
            qstr_floats(a)
        with pytest.raises(OverflowError):
            qparse_floats(qstr(a))
        return
    s, f = qstr_floats(a)
    assert s == qstr(a) and np.array(f).tobytes() == np.array(want_f).tobytes()
    q, f2 = qparse_floats(s)
    assert (q == a).all() and np.array(f2).tobytes() == np.array(want_f).tobytes()
    flat = [f"{2 * x.p}/{2 * x.q}" if i % 2 else str(x) for i, x in enumerate(a.flat)]
    odd = np.array(flat, dtype=object).reshape(a.shape).tolist()
    q3, f3 = qparse_floats(odd)  # "2p/2q" entries: not in lowest terms
    assert (q3 == qparse(odd)).all()
    assert np.array(f3).tobytes() == np.asarray(to_float(qparse(odd)), dtype=float).tobytes()


def test_qstr_floats_declines_mixed_arrays_and_qparse_floats_scalars() -> None:
    from obsdesign.certify.exact import qparse_floats, qstr_floats

    assert qstr_floats(np.array([fmpq(1), 2], dtype=object)) is None
    assert qparse_floats("-3/4") == (fmpq(-3, 4), -0.75)
    with pytest.raises(ZeroDivisionError):
        qparse_floats(["1/0"])


@pytest.mark.parametrize(
    ("x", "lo", "hi"),
    [
        ("1/10", 0.09999999999999999, 0.1),
        ("-1/10", -0.1, -0.09999999999999999),
        ("3", 3.0, 3.0),
        ("30000000000000001/1000", 30000000000000.0, 30000000000000.004),
        (f"{10**400}", 1.7976931348623157e308, float("inf")),
        (f"-{10**400}", float("-inf"), -1.7976931348623157e308),
    ],
)
def test_float_floor_and_ceil_bracket_the_exact_number(x: str, lo: float, hi: float) -> None:
    """float_floor / float_ceil: the largest float ≤ x and the smallest ≥ x (the exact box
    test of Box.contains_exact); beyond the float range ±inf on the far side, the largest
    float on the near one."""
    from obsdesign.certify.exact import float_ceil, float_floor

    assert float_floor(Q(x)) == lo and float_ceil(Q(x)) == hi
