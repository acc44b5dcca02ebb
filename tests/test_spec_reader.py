"""Tests of obsdesign.spec.reader: the checked-rows fast path of ``Table.matrix``."""

from __future__ import annotations

from decimal import Decimal

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from obsdesign.certify.exact import Q, to_float
from obsdesign.errors import SpecError
from obsdesign.spec.reader import Table, _checked_rows

_num = st.one_of(
    st.builds(
        lambda m, e: Decimal(f"{m}e{e}"),
        st.integers(-(10**20), 10**20),
        st.integers(-330, 320),
    ),
    st.integers(-(10**30), 10**30),
    st.floats(allow_nan=False, allow_infinity=False).map(lambda f: Decimal(repr(f))),
)


@given(st.integers(1, 4), st.integers(1, 4), st.data())
def test_checked_rows_equal_the_general_path(r: int, c: int, data: st.DataObject) -> None:
    """Exact values equal; floats bit for bit the correctly rounded ones of to_float; a
    number beyond the float range, or nonzero below the normal range (|x| < 2.2e-308), is
    the same SpecError naming the key on both paths."""
    rows = [[data.draw(_num) for _ in range(c)] for _ in range(r)]
    qs = np.array([[Q(x) for x in row] for row in rows], dtype=object)
    try:
        want = np.asarray(to_float(qs), dtype=float)
    except OverflowError:
        for checked in (True, False):
            with pytest.raises(SpecError, match=r"t.toml: \[M\] .*beyond the float range"):
                Table({"M": rows}, "t.toml", checked=checked).matrix("M")
        return
    tiny = np.finfo(float).tiny
    if any(q != 0 and abs(f) < tiny for q, f in zip(qs.flat, want.flat, strict=True)):
        for checked in (True, False):
            with pytest.raises(SpecError, match=r"t.toml: \[M\] .*below the float range"):
                Table({"M": rows}, "t.toml", checked=checked).matrix("M")
        return
    fast = Table({"M": rows}, "t.toml", checked=True).matrix("M")
    assert (fast.q == qs).all()
    assert fast.f.tobytes() == want.tobytes()
    slow = Table({"M": rows}, "t.toml").matrix("M")  # no fast path: per-number checks
    assert (slow.q == fast.q).all() and slow.f.tobytes() == fast.f.tobytes()


@pytest.mark.parametrize(
    "bad",
    [True, Decimal("inf"), Decimal("nan"), Decimal("1e400"), "1", 1.5],
)
def test_checked_rows_decline_what_the_general_path_must_decide(bad: object) -> None:
    """A boolean, a non-finite or beyond-float Decimal, a string, a float: the fast path
    declines (None) and the general path decides."""
    assert _checked_rows([[Decimal(1), bad]]) is None
    with pytest.raises(SpecError, match=r"t.toml: \[M\]"):
        Table({"M": [[1, bad]]}, "t.toml", checked=True).matrix("M")


def test_checked_rows_shape_error_names_the_key() -> None:
    with pytest.raises(SpecError, match=r"t.toml.*M.*expected shape 2×2, got 1×2"):
        Table({"M": [[1, 2]]}, "t.toml", checked=True).matrix("M", rows=2, cols=2)


@pytest.mark.parametrize("checked", [True, False])
def test_a_flat_list_of_the_other_orientation_says_how_to_write_it(checked: bool) -> None:
    """L = [1, 0.5] for n = 1, p = 2 (a column where a 1×2 row is expected) said only
    "expected shape 1×2, got 2×1" (lyapunov review, session 41). Nested lists and flat lists
    that fit neither way get no such hint."""
    t = Table({"L": [1, Decimal("0.5")], "R": [1, 2], "M": [[1, 2]]}, "t.toml", checked=checked)
    with pytest.raises(
        SpecError, match=r"got 2×1 \(a flat list is read as one column: write \[\[a, b"
    ):
        t.matrix("L", rows=1, cols=2, vector_as="column")
    with pytest.raises(
        SpecError, match=r"got 1×2 \(a flat list is read as one row: write \[\[a\], \[b"
    ):
        t.matrix("R", rows=2, cols=1)
    with pytest.raises(SpecError, match=r"expected shape 2×1, got 1×2$"):
        t.matrix("M", rows=2, cols=1)
    with pytest.raises(SpecError, match=r"expected shape 3×1, got 1×2$"):
        t.matrix("R", rows=3, cols=1)


@pytest.mark.parametrize("key", ["A = [[1e309]]", "B = [[-2e308]]", "Dn = [[1e400]]"])
def test_number_beyond_the_float_range_is_bad_input(tmp_path, key: str) -> None:
    """exit 2 naming the file and key, no report (it was exit 4 with no key named)."""
    from typer.testing import CliRunner

    from obsdesign.cli import app

    base = {"A": "A = [[0.5]]", "B": "B = [[1]]", "Dn": "Dn = [[1]]"}
    base[key.split(" ")[0]] = key
    spec = tmp_path / "s.toml"
    spec.write_text(
        '[system]\ntime = "discrete"\n' + "\n".join(base.values()) + "\nC = [[1]]\n"
        '[method]\nkey = "lyapunov"\n'
    )
    out = tmp_path / "r.json"
    res = CliRunner().invoke(app, ["design", str(spec), "-o", str(out)])
    assert res.exit_code == 2, res.output
    assert f"s.toml: [system.{key.split(' ')[0]}] has a number beyond the float range" in (
        res.output
    )
    assert "Traceback" not in res.output and not out.exists()


@pytest.mark.parametrize("empty", [[], [[], []]])
def test_an_empty_matrix_says_to_leave_the_key_out(empty: list) -> None:
    """B = [] (or [[], []]) for a plant without inputs said only "of shape 2×?" (edge-shape
    trial, session 26); the message now says an empty matrix is not one and what to do."""
    with pytest.raises(SpecError, match=r"t.toml.*\[B\].*not matrices .*leaves B, D or Bd out"):
        Table({"B": empty}, "t.toml", checked=True).matrix("B", rows=2)
    with pytest.raises(SpecError) as e:  # a malformed, non-empty matrix: no such hint
        Table({"B": [[1], "x"]}, "t.toml", checked=True).matrix("B", rows=2)
    assert "leave" not in str(e.value)
    # Dn left out is the identity, not "no noise" (lyapunov trial, session 39)
    with pytest.raises(SpecError) as e:
        Table({"Dn": empty}, "t.toml", checked=True).matrix("Dn", rows=2)
    assert "leaves B, D or Bd out" not in str(e.value)
    assert "left out, Dn is the identity" in str(e.value) and "as zeros" in str(e.value)


def test_missing_key_held_by_a_misspelt_sibling_table_names_the_typo() -> None:
    """``[simulte]`` beside a ``[simulate.noise]`` subtable: the key is reported missing in
    [simulate] and the message names the misspelt table that holds it (docs trial, session
    31); with no close sibling holding it there is no hint."""
    root = Table({"simulte": {"horizon": 5}, "simulate": {"noise": {}}}, "s.toml")
    sim = root.table("simulate")
    assert sim is not None
    with pytest.raises(SpecError, match=r"is in \[simulte\]: is 'simulte' a misspelling"):
        sim.int("horizon")
    far = Table({"other": {"horizon": 5}, "simulate": {"noise": {}}}, "s.toml").table("simulate")
    assert far is not None
    with pytest.raises(SpecError) as e:
        far.int("horizon")
    assert "misspelling" not in str(e.value)


def test_an_unknown_key_beside_the_key_it_misspells_gets_the_hint() -> None:
    """``--set method.lambdaa=…`` in a sweep adds lambdaa beside the spec's lambda: the row
    said "is not a known key here" without the hint design gives when lambda is absent
    (docs trial, session 31)."""
    t = Table({"lambda": 1, "lambdaa": 2}, "s.toml", "method")
    t.int("lambda")
    with pytest.raises(
        SpecError, match=r"\[method.lambdaa\] is not a known key here \(did you mean 'lambda'\?\)"
    ):
        t.done()


def test_an_unknown_key_that_differs_in_case_gets_the_hint() -> None:
    """``[method.d]`` for ``[method.D]``: difflib finds no close match between one-letter
    names (re-check trial, session 32); a case-only difference is named first."""
    t = Table({"d": {}}, "s.toml", "method")
    t.table("D")
    with pytest.raises(
        SpecError, match=r"\[method.d\] is not a known key here \(did you mean 'D'\?\)"
    ):
        t.done()


def test_an_unknown_key_with_a_lookalike_character_names_it() -> None:
    """A Cyrillic 'а' in "lambdа" printed exactly like "lambda" (hostile-input trial, session
    38): the message names each non-ASCII character by code point and name."""
    t = Table({"lambd\u0430": 2}, "s.toml", "method")
    t.int("lambda", default=1)
    with pytest.raises(SpecError) as e:
        t.done()
    assert "(did you mean 'lambda'?); it holds non-ASCII characters: U+0430 CYRILLIC SMALL " in str(
        e.value
    )
    t = Table({"lambdaa": 2}, "s.toml", "method")
    t.int("lambda", default=1)
    with pytest.raises(SpecError) as e:
        t.done()
    assert "non-ASCII" not in str(e.value)


# -- mutation review 33 (session 32's checks) ----------------------------------------
def test_misspelt_sibling_among_named_subtables_is_named_by_its_full_path() -> None:
    """[sets.box] lacks "horizon", which its misspelt sibling [sets.bxo] holds: the hint names
    [sets.bxo] (kills D06, tables() giving no parent, so no hint, and D09, the sibling's
    name without its path: "[bxo]")."""
    root = Table({"sets": {"box": {"type": "box"}, "bxo": {"horizon": 5}}}, "s.toml")
    box = root.tables("sets")["box"]
    with pytest.raises(SpecError, match=r"is in \[sets\.bxo\]: is 'bxo' a misspelling of 'box'"):
        box.int("horizon")


def test_a_string_sibling_is_not_a_table_that_holds_the_key() -> None:
    """A sibling *string* containing the key's name is no table holding it (kills D04:
    `k in v` on a string matched a substring and named it)."""
    root = Table({"simulte": "horizon = 5", "simulate": {"noise": {}}}, "s.toml")
    sim = root.table("simulate")
    assert sim is not None
    with pytest.raises(SpecError) as e:
        sim.int("horizon")
    assert "simulte" not in str(e.value)


def test_a_vector_of_one_number_is_named_in_the_singular() -> None:
    """ "expected 1 numbers" (re-check trial, session 41)."""
    with pytest.raises(SpecError, match=r"\[v\] expected 1 number, got 2$"):
        Table({"v": [1, 2]}, "t.toml").vector("v", n=1)


def test_spec_arrays_are_read_only() -> None:
    """A spec's numbers cannot be edited in place: designs keep results for the spec's data
    (the lyapunov memo, caches) and a report embeds the spec's text, so an A edited in place
    after a design was certified with the old A's verdicts (API review, session 42)."""
    import numpy as np
    import pytest

    from obsdesign import api

    spec = api.load_spec_text(
        '[system]\ntime = "discrete"\nA = [[0, 1], [1, 0]]\nC = [[1, 0]]\n'
        '[method]\nkey = "lyapunov"\n',
        "s.toml",
    )
    import copy
    import pickle

    values = (spec.system.A, spec.system.C, spec.system.B, spec.system.Bd, spec.system.Dn)
    copies = [copy.deepcopy(v) for v in values] + [pickle.loads(pickle.dumps(values[1]))]
    for v in (*values, *copies):
        for arr in (v.q, v.f):
            assert isinstance(arr, np.ndarray) and not arr.flags.writeable
            # the array it views too: A edited through ``.base`` kept the design's verdicts
            # (re-check review, session 42); deep copies and pickles were writable
            assert arr.base is None or not arr.base.flags.writeable
            if arr.size:
                with pytest.raises(ValueError, match="read-only"):
                    arr.flat[0] = 3


def test_value_of_leaves_the_callers_array_writable() -> None:
    """``Value.of(arr)`` froze the caller's own object array in place (re-check review,
    session 43): the Value holds a read-only copy."""
    import numpy as np
    from flint import fmpq

    from obsdesign.spec.reader import Value

    arr = np.array([[fmpq(1), fmpq(2)]], dtype=object)
    v = Value.of(arr)
    assert arr.flags.writeable and not v.q.flags.writeable
    arr[0, 0] = fmpq(5)
    assert v.q[0, 0] == 1


def test_value_of_a_float_array_holds_exact_rationals() -> None:
    """``Value.of(np.array([[0.1]]))`` kept Python floats as the "exact" part: three methods
    then stopped with a bare TypeError (API review, session 43). Each float is read at its
    exact binary value."""
    import numpy as np
    from flint import fmpq

    from obsdesign.spec.reader import Value

    v = Value.of(np.array([[0.1, 2]]))
    assert all(isinstance(x, fmpq) for x in v.q.flat)
    assert v.q[0, 0] == fmpq(3602879701896397, 36028797018963968) and v.q[0, 1] == 2
    assert v.f[0, 0] == 0.1


def test_an_integer_key_past_64_bits_is_refused_but_a_seed_is_not() -> None:
    """``[simulate] runs = 10**400`` was exit 3 (OverflowError in the memory estimate) and a
    discrete ``horizon`` of 400 digits exit 4 naming no key (CLI review, session 44): an
    integer key above 2^63 − 1 is refused naming it; 2^63 − 1 passes; a seed takes any size."""
    from obsdesign.limits import INT_MAX

    t = Table({"runs": INT_MAX, "horizon": INT_MAX + 1, "seed": 10**400}, "s.toml", "simulate")
    assert t.int("runs", min=1) == INT_MAX
    with pytest.raises(SpecError, match=r"\[simulate.horizon\] expected an integer of at most 2"):
        t.int("horizon", min=1)
    assert t.int("seed") == 10**400
