"""The TOML layout lexer (obsdesign/spec/tomltext.py): statements and exact value spans."""

from __future__ import annotations

import json
import time
import tomllib

from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.spec import tomltext as tt


def _spans(text: str) -> list[tuple[str, tuple[str, ...] | None, str]]:
    out = []
    for s in tt.statements(text):
        v = text[s.value_start : s.value_end] if s.kind == "keyval" else ""
        out.append((s.kind, s.key, v))
    return out


def test_statements_of_a_spec_like_text() -> None:
    text = (
        'title = \'a """ b\'  # c\n'
        'description = """\nx = 1\n[not.a.table]\n"""\n'
        "[system]\n"
        "A = [\n  [0, 1],  # ] not the end\n  [1, 0]\n]\n"
        '"quoted.key" = "v#w"\n'
        "a.b = {x = 1, y = [2]}\n"
        "[[runs]]\nk = 1\n"
        "[ method . sub ]  # header comment\n"
        "lam = 0.9\r\n"
    )
    assert _spans(text) == [
        ("keyval", ("title",), '\'a """ b\''),
        ("keyval", ("description",), '"""\nx = 1\n[not.a.table]\n"""'),
        ("table", ("system",), ""),
        ("keyval", ("A",), "[\n  [0, 1],  # ] not the end\n  [1, 0]\n]"),
        ("keyval", ("quoted.key",), '"v#w"'),
        ("keyval", ("a", "b"), "{x = 1, y = [2]}"),
        ("aot", ("runs",), ""),
        ("keyval", ("k",), "1"),
        ("table", ("method", "sub"), ""),
        ("keyval", ("lam",), "0.9"),
    ]
    tomllib.loads(text)  # the text is valid TOML


def test_multiline_strings_with_quotes_next_to_the_delimiter() -> None:
    for v in ['"""a""""', '"""a"""""', "'''a''''", '"""\\""""', '""""""', '"""a\\\\"""']:
        text = f"k = {v}  # c\nz = 1\n"
        assert tomllib.loads(text)["z"] == 1
        assert _spans(text)[0][2] == v


def test_an_unclosed_value_runs_to_the_end_of_the_text() -> None:
    assert tt.value_end("[1, [2", 0) == 6
    assert tt.value_end('"abc', 0) == 4
    assert tt.value_end('"""abc\n', 0) == 7


def test_deep_nesting_and_long_values_are_linear_and_do_not_recurse() -> None:
    deep = "k = " + "[" * 100_000 + "]" * 100_000 + "\n"
    t0 = time.perf_counter()
    (s,) = tt.statements(deep)
    assert s.value_end == len(deep) - 1
    hashes = 'k = "' + "#" * 200_000 + '"  # c\n'
    assert tt.statements(hashes)[0].value_end == len(hashes) - 6
    assert time.perf_counter() - t0 < 5  # a guard against a quadratic scan, not a benchmark


def test_key_parts() -> None:
    assert tt.key_parts(" a . b ") == ("a", "b")
    assert tt.key_parts('"a.b".c') == ("a.b", "c")
    assert tt.key_parts("a b") is None
    assert tt.key_parts("") is None


_scalars = st.one_of(
    st.integers(-(10**6), 10**6).map(str),
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    st.booleans().map(lambda b: "true" if b else "false"),
    st.text(st.characters(blacklist_categories=("Cs", "Cc")), max_size=12).map(
        lambda s: json.dumps(s, ensure_ascii=False)
    ),
    st.text(st.sampled_from('ab#"[]{} '), max_size=8).map(lambda s: "'" + s + "'"),
    st.text(st.sampled_from("ab#'[]{}\n "), max_size=8).map(lambda s: '"""' + s + '"""'),
)


def _array(children: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    seps = st.sampled_from([", ", ",\n  ", ",  # a ] comment [\n  "])
    return st.tuples(st.lists(children, max_size=4), seps).map(
        lambda t: "[" + t[1].join(t[0]) + "]"
    )


_values = st.recursive(_scalars, _array, max_leaves=12)


@settings(max_examples=300, deadline=None)
@given(v=_values, after=_values)
def test_the_span_of_any_value_is_exactly_its_text(v: str, after: str) -> None:
    """Property: for any TOML value (strings of all kinds with '#', brackets and quotes
    inside, arrays nested with comments and newlines), the statement's value span is the
    value's text, whatever value follows on the next lines."""
    text = f"[t]\nk = {v}  # c [\nnext = {after}\n"
    want = tomllib.loads(text)["t"]
    sp = _spans(text)
    assert sp[1] == ("keyval", ("k",), v)
    assert sp[2] == ("keyval", ("next",), after)
    assert tomllib.loads(f"x = {sp[1][2]}")["x"] == want["k"]
