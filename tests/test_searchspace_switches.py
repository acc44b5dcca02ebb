"""The switch readings of obsdesign.methods.searchspace.switches: a product with a step or sign
whose argument's factors it has is read as G·max(B, 0), G·min(B, 0) or s·G·|B|. Each reading
must be an identity of real functions (checked exactly, with rationals, at random points,
B = 0 included), and the products it must not touch are left as written."""

from __future__ import annotations

import ast
from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.methods.searchspace import switches


def _split(text: str) -> switches.Split | None:
    return switches.split(ast.parse(text, mode="eval").body, text)


def _value(node: ast.AST, env: dict[str, Fraction]) -> Fraction:
    """Exact value of a product / sum / step / sign tree (step(0) = sign(0) = 0)."""
    if isinstance(node, ast.Constant):
        return Fraction(str(node.value))
    if isinstance(node, ast.Name):
        return env[node.id]
    if isinstance(node, ast.UnaryOp):
        v = _value(node.operand, env)
        return -v if isinstance(node.op, ast.USub) else v
    if isinstance(node, ast.BinOp):
        a, b = _value(node.left, env), _value(node.right, env)
        ops = {ast.Add: a + b, ast.Sub: a - b, ast.Mult: a * b}
        if isinstance(node.op, ast.Div):
            return a / b
        return ops[type(node.op)]
    assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
    v = _value(node.args[0], env)
    if node.func.id in ("step", "heaviside"):
        return Fraction(int(v > 0))
    assert node.func.id == "sign"
    return Fraction((v > 0) - (v < 0))


def _reading(sp: switches.Split, env: dict[str, Fraction]) -> Fraction:
    """The value of the split's reading: sign · Π rest · Π f(Π core)."""
    out = Fraction(sp.sign)
    for f in sp.rest:
        out *= _value(f, env)
    for sw in sp.switches:
        b = Fraction(1)
        for f in sw.core:
            b *= _value(f, env)
        out *= {"max": max(b, 0), "min": min(b, 0), "abs": abs(b)}[sw.kind]
    return out


@pytest.mark.parametrize(
    ("text", "kinds", "sign"),
    [
        ("x1*step(x1)", ["max"], 1),
        ("-x1*step(x1)", ["max"], -1),
        ("step(x1)*(-x1)", ["max"], -1),
        ("2*x1*step(x1)", ["max"], 1),
        ("1.001*x2*step(x2)", ["max"], 1),
        ("x1*step(-x1)", ["min"], 1),
        ("x1*x2*step(x1)", ["max"], 1),
        ("x1/2*step(2*x1)", ["max"], 1),
        ("x*sign(x)", ["abs"], 1),
        ("-x*sign(-x)", ["abs"], 1),
        ("x*sign(-x)", ["abs"], -1),
        ("(x1 - x2)*step(x1 - x2)*3", ["max"], 1),
        ("x1*step(x1)*x2*heaviside(x2)", ["max", "max"], 1),
        ("x1*x2*step(x1*x2)", ["max"], 1),
        ("(x1 - 1)*step(1 - x1)", ["max"], -1),  # = −max(1 − x1, 0)
        ("(x2 - x1)*sign(x1 - x2)", ["abs"], -1),
        # mutation review 23 (switches.py): constants in (0, 1] and 1/c inside the step,
        # unary plus, a constant switch or an unmatched one before the matched one
        ("x1*step(0.5*x1)", ["max"], 1),
        ("x1*step(x1/2)", ["max"], 1),
        ("+x1*step(x1)", ["max"], 1),
        ("step(2)*x1*step(x1)", ["max"], 1),
        ("x1*step(x2)*x1*step(x1)", ["max"], 1),
    ],
)
def test_products_that_vanish_at_their_switch_are_read(text: str, kinds: list, sign: int) -> None:
    sp = _split(text)
    assert sp is not None and [s.kind for s in sp.switches] == kinds and sp.sign == sign


@pytest.mark.parametrize(
    "text",
    [
        "x1*step(x2)",  # jumps in x2 where x1 ≠ 0
        "x1*step(x1 + 1)",  # x1 is not a factor of x1 + 1
        "x1*step(0*x1)",  # a zero constant is not dropped as positive
        "x1*step(k*x1)",  # a parameter's sign is not known from the syntax
        "x1*step(x1)*step(x1)",  # the second step has no factor left to vanish with
        "x1*floor(x1)",
        "x1 + step(x1)",
        "x1*step(x1/0)",  # not a positive literal divisor: left as written
        "step(x1)",  # not a product
    ],
)
def test_products_that_keep_their_jump_are_not_read(text: str) -> None:
    sp = _split(text)
    if text == "x1*step(x1)*step(x1)":
        assert sp is not None and len(sp.switches) == 1 and len(sp.rest) == 1
    else:
        assert sp is None


_ATOMS = ["x1", "x2", "(x1 - x2)", "(x2 - x1)", "2", "0.5", "3", "x1/2", "(x1 - x2)/3"]


@st.composite
def _products(draw: st.DrawFn) -> str:
    """A random product of atoms, negations, divisions by literals and switches of
    sub-products (some of them sharing factors with the product, some not)."""
    fs = draw(st.lists(st.sampled_from(_ATOMS), min_size=1, max_size=4))
    n_sw = draw(st.integers(1, 2))
    out = list(fs)
    for _ in range(n_sw):
        arg = draw(st.lists(st.sampled_from(_ATOMS), min_size=1, max_size=3))
        neg = draw(st.booleans())
        fn = draw(st.sampled_from(["step", "heaviside", "sign"]))
        out.append(f"{fn}({'-' if neg else ''}{'*'.join(arg)})")
    out = draw(st.permutations(out))
    text = "*".join(out)
    if draw(st.booleans()):
        text = f"-{text}"
    if draw(st.booleans()):
        text = f"{text}/4"
    return text


@settings(max_examples=300, deadline=None)
@given(_products(), st.lists(st.integers(-4, 4), min_size=2, max_size=2))
def test_every_reading_is_an_identity(text: str, point: list[int]) -> None:
    """Wherever split reads a product, the reading equals the product exactly, at integer and
    half-integer points (so x1 = 0, x2 = 0 and x1 = x2, where the switches switch, occur)."""
    env = {"x1": Fraction(point[0], 2), "x2": Fraction(point[1], 2)}
    node = ast.parse(text, mode="eval").body
    sp = switches.split(node, text)
    if sp is not None:
        assert _reading(sp, env) == _value(node, env), text


def test_literals_match_at_their_exact_value() -> None:
    """0.1 and 0.10000000000000001 are one double but two numbers: ``(x1 - 0.1)*step(x1 -
    0.10000000000000001)`` jumps by 10⁻¹⁷ and was read as max(x1 − 0.1, 0), certified
    Lipschitz (search-space trial, session 24). Literals now match by their source text's
    exact value; the same literal still matches."""
    assert _split("(x1 - 0.1)*step(x1 - 0.10000000000000001)") is None
    assert _split("(x1 - 0.1)*step(x1 - 0.1)") is not None
    assert _split("(x1 - 0.10)*step(x1 - 0.1)") is not None  # 0.10 = 0.1 exactly
    a = ast.parse("x1 - 0.1", mode="eval").body
    b = ast.parse("x1 - 0.10000000000000001", mode="eval").body
    assert ast.dump(a) == ast.dump(b)  # what the old match compared
    assert switches.exact_key(a, "x1 - 0.1") != switches.exact_key(b, "x1 - 0.10000000000000001")
