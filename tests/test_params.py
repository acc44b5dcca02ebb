"""Parameters: JSON form and exact values for certificates (obsdesign.params)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from flint import fmpq
from hypothesis import example, given, settings
from hypothesis import strategies as st

from obsdesign.certify.exact import qmat
from obsdesign.errors import InputError
from obsdesign.params import Parameters, exact_param


def test_exact_param_paths():
    p = Parameters({"P": qmat([[1, 2], [3, 4]]), "f": 0.5, "v": np.array([0.25, 1.0])})
    claims: list = []
    assert (exact_param(p, "P", claims) == qmat([[1, 2], [3, 4]])).all()
    assert exact_param(p, "f", claims) == fmpq(1, 2)  # a float at its binary value
    assert (exact_param(p, "v", claims) == np.array([fmpq(1, 4), fmpq(1)], dtype=object)).all()
    assert claims == []
    assert exact_param(p, "missing", claims) is None and claims[-1].id == "missing-present"
    assert exact_param(p, "f", claims, accept_float=False) is None and claims[-1].id == "f-exact"
    assert all(c.status.value == "failed" for c in claims)


def test_json_round_trip_3d_exact():
    cube = np.empty((2, 1, 2), dtype=object)
    for i, idx in enumerate(np.ndindex(2, 1, 2)):
        cube[idx] = fmpq(i, 7)
    back, problems = Parameters.from_json(Parameters({"Lp": cube}).to_json())
    assert problems == [] and back["Lp"].shape == (2, 1, 2) and (back["Lp"] == cube).all()


def test_shared_value_written_once_read_as_two():
    """P and P_best holding one array: both keys written, lists not shared; read back as two
    arrays (editing one leaves the other), and an edit of either copy is still seen."""
    P = qmat([[2, fmpq(1, 3)], [fmpq(1, 3), 5]])
    d = Parameters({"P": P, "P_best": P}).to_json()
    assert d["P"] == d["P_best"] and d["exact"]["P"] == d["exact"]["P_best"]
    assert d["P"] is not d["P_best"] and d["P"][0] is not d["P_best"][0]
    assert d["exact"]["P"][0] is not d["exact"]["P_best"][0]
    back, problems = Parameters.from_json(d)
    assert problems == [] and (back["P"] == P).all() and (back["P_best"] == P).all()
    back["P"][0, 0] = fmpq(7)
    assert back["P_best"][0, 0] == 2
    # the float of the second copy edited: caught although the exact strings are the same
    d["P_best"][1][1] = 5.5
    assert Parameters.from_json(d)[1] == [
        "parameter 'P_best': float value differs from its exact value"
    ]
    # the exact string of the second copy edited: parsed as its own value
    d["P_best"][1][1] = 5.0
    d["exact"]["P_best"][1][1] = "6"
    back, problems = Parameters.from_json(d)
    assert back["P_best"][1, 1] == 6 and back["P"][1, 1] == 5
    assert problems == ["parameter 'P_best': float value differs from its exact value"]


_num = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**400), max_value=10**400),
)
_leaf = st.one_of(_num, st.booleans(), st.just("1/2"), st.none())


@given(
    a=st.lists(st.lists(_num, min_size=0, max_size=3), min_size=0, max_size=3),
    b=st.lists(st.lists(_leaf, min_size=0, max_size=3), min_size=0, max_size=3),
    copy=st.booleans(),
)
@example(a=[[1.0, 2.0]], b=[[1.0, 2.0 * (1 + 3e-12)]], copy=False)  # just outside
@example(a=[[1.0, 2.0]], b=[[1.0, 2.0 * (1 + 5e-13)]], copy=False)  # just inside
@example(a=[[0.0]], b=[[1e-301]], copy=False)
@example(a=[[0.0]], b=[[2e-300]], copy=False)
@example(a=[[1.0]], b=[[True]], copy=False)
@example(a=[[1.0], [2.0]], b=[[1.0], [2.0, 3.0]], copy=False)
@settings(max_examples=300, deadline=None)
def test_same_vectorized_agrees_with_entrywise(a, b, copy):
    """The vectorized float comparison of a report's float lists (``b``, anything a report
    may hold) with the floats of the exact values (``a``) gives the entry-by-entry verdict
    (ragged lists, booleans, strings, non-finite and huge numbers included)."""
    from obsdesign import params as pm

    if copy:
        b = [list(r) for r in a]

    def entrywise(x, y):
        if isinstance(x, list) or isinstance(y, list):
            if not (isinstance(x, list) and isinstance(y, list)) or len(x) != len(y):
                return False
            return all(entrywise(u, v) for u, v in zip(x, y, strict=True))
        if isinstance(x, bool) or isinstance(y, bool):
            return x == y
        if not isinstance(y, (int, float)):
            return False
        return math.isclose(float(x), float(y), rel_tol=1e-12, abs_tol=1e-300)

    try:
        want = entrywise(a, b)
    except OverflowError:
        want = "overflow"
    try:
        got = pm._same(a, b)
    except (OverflowError, TypeError, ValueError):
        got = "overflow"
    if want == "overflow":
        assert got in ("overflow", False)
    else:
        assert got == want


@given(
    a=st.lists(st.lists(_leaf, min_size=0, max_size=3), min_size=0, max_size=3),
    b=st.lists(st.lists(_leaf, min_size=0, max_size=3), min_size=0, max_size=3),
    copy=st.booleans(),
)
@example(a=[[1.0, 2.0]], b=[[1.0, 2.0000000000000004]], copy=False)  # one ulp
@example(a=[[0.0]], b=[[-0.0]], copy=False)
@example(a=[[1.0]], b=[[1]], copy=False)
@settings(max_examples=300, deadline=None)
def test_same_bits_vectorized_agrees_with_entrywise(a, b, copy):
    """verify's bit-for-bit float check (same_bits) gives the entry-by-entry verdict."""
    from obsdesign.params import same_bits

    if copy:
        b = [list(r) for r in a]

    def entrywise(x, y):
        if isinstance(x, list) and isinstance(y, list):
            return len(x) == len(y) and all(entrywise(u, v) for u, v in zip(x, y, strict=True))
        if isinstance(x, (bool, list)) or isinstance(y, (bool, list)):
            return False
        if not isinstance(x, (int, float)) or not isinstance(y, (int, float)):
            return False
        try:
            u, v = float(x), float(y)
        except OverflowError:  # an integer beyond the float range is no double: unequal
            return False
        return u == v and math.copysign(1.0, u) == math.copysign(1.0, v)  # −0.0 ≠ +0.0

    assert same_bits(a, b) == entrywise(a, b)


def test_same_bits_tells_the_sign_of_zero():
    """−0.0 is not the nearest double to an exact 0 (+0.0): bit for bit, as the docs say
    (verify took it: rendering trial, session 29)."""
    from obsdesign.params import same_bits

    assert not same_bits(-0.0, 0) and not same_bits([[0.0, 1.0]], [[-0.0, 1.0]])
    assert same_bits(0.0, 0) and same_bits([[-0.0]], [[-0.0]])


def test_float_forms_kept_from_reading_and_dropped_on_change():
    """from_json keeps the float forms it made for its check; float_json hands out copies,
    and setting the key again drops the kept form."""
    d = Parameters({"P": qmat([[1, fmpq(1, 3)], [fmpq(1, 3), 2]])}).to_json()
    back, _ = Parameters.from_json(d)
    f1 = back.float_json("P")
    assert f1 == d["P"]
    f1[0][0] = 99.0
    assert back.float_json("P")[0][0] == 1.0
    back["P"] = qmat([[5, 0], [0, 5]])
    assert back.float_json("P") == [[5.0, 0.0], [0.0, 5.0]]


def test_report_errors_name_the_report_file(tmp_path) -> None:
    """The CLI fuzzer found verify errors about 'parameters' that said "report:" instead of
    the report's path."""
    import json
    from pathlib import Path

    from obsdesign import api
    from obsdesign.errors import InputError
    from obsdesign.report.model import Report

    spec = Path(__file__).resolve().parent / "specs" / "lyapunov-minimal.toml"
    d = api.design(api.load_spec(spec)).to_dict()
    key = next(iter(d["parameters"]["exact"]))
    cases = [
        ({**d, "parameters": {**d["parameters"], "exact": []}}, "'parameters.exact' must be"),
        (
            {**d, "parameters": {**d["parameters"], "exact": {key: "1/0x"}}},
            f"parameters.exact.{key}: not an exact value",
        ),
    ]
    for i, (bad, msg) in enumerate(cases):
        f = tmp_path / f"r{i}.json"
        f.write_text(json.dumps(bad))
        with pytest.raises(InputError) as e:
            Report.load(f)
        assert e.value.message.startswith(f"{f}: ") and msg in e.value.message


@pytest.mark.parametrize("exact", [str(10**400), [["1/3", str(-(10**309))]]])
def test_from_json_refuses_an_exact_value_beyond_the_float_range(exact: object) -> None:
    """No report carries an exact value beyond the float range (its float view would be
    infinite); a hand-edited one was an internal failure (OverflowError, exit 3). It is bad
    input naming the report and the key."""
    from obsdesign.errors import InputError

    fl = [[0.0, 0.0]] if isinstance(exact, list) else 0.0
    with pytest.raises(InputError) as e:
        Parameters.from_json({"v": fl, "exact": {"v": exact}}, "r.json")
    assert "r.json: parameters.exact.v" in str(e.value) and "beyond the float range" in str(e.value)


def test_from_json_parses_the_largest_float_range_values() -> None:
    """2¹⁰²³ (inside the float range) still parses, consistent with its float."""
    back, problems = Parameters.from_json({"v": float(2**1023), "exact": {"v": str(2**1023)}})
    assert back["v"] == fmpq(2**1023) and not problems


def test_a_float_view_beyond_the_float_range_is_a_consistency_problem() -> None:
    """A JSON integer of 401 digits where the float of an exact "3" belongs (scalar and in a
    list): not equal as doubles, a parameters-consistent problem, not an OverflowError (exit
    3 in verify: report fuzz, review 19)."""
    from obsdesign.params import Parameters, same_bits

    big = 10**400
    assert not same_bits(big, 3.0) and not same_bits([big, 1.0], [3.0, 1.0])
    vals, problems = Parameters.from_json({"beta": big, "exact": {"beta": "3"}}, "r.json")
    assert problems == ["parameter 'beta': float value differs from its exact value"]
    vals, problems = Parameters.from_json({"v": [big, 1.0], "exact": {"v": ["3", "1"]}}, "r.json")
    assert problems == ["parameter 'v': float value differs from its exact value"]


@pytest.mark.parametrize("exact", [0.5, [["1/2", 0.25]], [[0.5, "1/4"]], [0.1, "1/3"], -0.0, 1e300])
def test_from_json_refuses_a_float_as_an_exact_value(exact: object) -> None:
    """A report's exact value is a string: a JSON number such as 0.1 does not say whether
    1/10 or the double nearest to it is meant (verify took the double's binary value and
    certified that). Bad input naming the key; integers and decimal strings are exact."""
    from fractions import Fraction

    from obsdesign.errors import InputError

    def fl(x: object) -> object:
        return [fl(v) for v in x] if isinstance(x, list) else float(Fraction(x))

    with pytest.raises(InputError) as e:
        Parameters.from_json({"v": fl(exact), "exact": {"v": exact}}, "r.json")
    assert str(e.value).startswith("r.json: parameters.exact.v: not an exact value (the float")
    back, problems = Parameters.from_json({"v": [0.5, 3.0], "exact": {"v": ["0.5", 3]}})
    assert list(back["v"]) == [fmpq(1, 2), fmpq(3)] and not problems


def test_parameters_are_a_read_only_mapping_with_identity_equality() -> None:
    """Parameters said "ordered mapping" but len(p), dict(p) and p.keys() failed (outsider
    trial, session 22). It is a collections.abc.Mapping now; equality and hashing stay by
    identity (value equality would compare numpy arrays)."""
    from collections.abc import Mapping

    import numpy as np

    from obsdesign.params import Parameters

    p = Parameters({"a": np.eye(2), "b": 1.5})
    assert isinstance(p, Mapping) and len(p) == 2 and list(p.keys()) == ["a", "b"]
    assert dict(p)["b"] == 1.5 and list(p.values())[1] == 1.5
    q = Parameters({"a": np.eye(2), "b": 1.5})
    assert p != q and p == p and len({p, q}) == 2


def test_shape_of_says_what_a_parameter_holds() -> None:
    """The words of simulate's wrong-shape error (session 28)."""
    from obsdesign.params import Parameters

    p = Parameters(
        {"a": 1.5, "b": [[1.0], [2.0]], "c": "x", "d": True, "e": [[1.0], [1.0, 2.0]], "f": None}
    )
    assert [p.shape_of(k) for k in "abcdefg"] == [
        "a number",
        "2×1 array",
        "text",
        "a boolean",
        "a ragged list",
        "null",
        "missing",
    ]


def test_traced_parameters_record_reads_in_order() -> None:
    from obsdesign.params import Parameters

    t = Parameters({"L": [[1.0]], "P": [[2.0]], "x": 3.0}).traced()
    t.float("P")
    t["L"]
    t.get("x")
    t.get("nope")
    assert t.read == ["P", "L", "x", "nope"]
    assert t.float("P").tolist() == [[2.0]]


def test_a_trace_without_finite_returns_non_finite_floats() -> None:
    """Mutation review 28: obsdesign.params.xǁReadTraceǁfloat__mutmut_6 (``... or True``) and _8 (``finite or
    isinstance``): only ``traced(finite=True)`` (simulate --report) refuses inf / nan;
    verify's trace (finite=False) hands the value to the checks, whose failed claim says
    what is wrong."""
    from obsdesign.params import Parameters

    p = Parameters({"L": [[math.inf], [1.0]], "x": math.nan})
    t = p.traced()
    assert np.isinf(np.asarray(t.float("L"))[0, 0])
    assert math.isnan(t.float("x"))
    assert t.read == ["L", "x"]
    with pytest.raises(InputError, match=r"parameters\.L: a value is not a finite number \(inf\)"):
        p.traced(finite=True).float("L")


def test_shaped_takes_the_shape_or_a_vector_and_refuses_a_transpose() -> None:
    """A 2×3 L in a report for a 3×2 gain was reshaped row-major into another matrix and
    simulated with exit 0 (re-check trial, session 28)."""
    p = Parameters(
        {
            "L": [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]],
            "c": [[1.0], [2.0], [3.0]],
            "v": [1.0, 2.0, 3.0],
            "r": [[1.0, 2.0, 3.0]],
            "s": 2.5,
            "G": [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]],
        }
    )
    with pytest.raises(InputError, match=r"parameters\.L has shape 2×3, expected 3×2"):
        p.shaped("L", (3, 2))
    assert p.shaped("L", (2, 3)).tolist() == [[1, 2, 3], [4, 5, 6]]
    for k in ("c", "v", "r"):  # a vector stands for any one-dimensional shape
        assert p.shaped(k, (3, 1)).ravel().tolist() == [1, 2, 3]
        assert p.shaped(k, (3,)).tolist() == [1, 2, 3]
    assert p.shaped("s", (1, 1)).tolist() == [[2.5]]
    assert p.shaped("G", (-1, 2)).shape == (3, 2)
    with pytest.raises(InputError, match=r"has shape 3×2, expected N×3"):
        p.shaped("G", (-1, 3))
    with pytest.raises(InputError, match="expected 2×2"):
        p.shaped("v", (2, 2))


def test_shaped_refuses_every_other_shape() -> None:
    """params.shaped: exactly the shape (None: any length), a named ValueError otherwise."""
    import numpy as np
    import pytest

    from obsdesign.params import shaped

    assert shaped([[1, 2], [3, 4]], (2, 2), "P").shape == (2, 2)
    assert shaped([1, 2, 3], (None,), "b").shape == (3,)
    for bad, shape in (([1, 2, 3, 4], (2, 2)), ([[1, 2]], (2, 1)), ([[1], [2]], (2,)), (5, (1,))):
        with pytest.raises(ValueError, match=r"^parameters\.P: expected shape "):
            shaped(bad, shape, "P")
    with pytest.raises(ValueError, match="expected shape 2×2, got 1×4"):
        shaped(np.zeros((1, 4)), (2, 2), "P")
