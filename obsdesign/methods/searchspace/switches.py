"""Products with a switch that vanish where it switches: ``a·step(b)``, ``a·sign(b)`` when a
has b's factors, read as the continuous functions they are (the enclosures of
:mod:`~obsdesign.methods.searchspace.intervals` and
:mod:`~obsdesign.methods.searchspace.qintervals`).

The search-space method (Hernández & García, "An alternative approach to the state observation
problem for Lipschitz continuous systems with controls") needs Lipschitz constants of f and h
(Lemma 1, Lemma 2); the paper's own output is y = x₁·[x₁ > 0]. A step is a jump, so its
derivative enclosure is unbounded where its argument may vanish; the product is continuous
when its other factor vanishes there too. Only syntactic factors are used, so every reading
below is an identity of real functions (no simplification is trusted):

- a product tree (``*``, unary ``-``, ``/`` by a numeric literal) is split into its sign, its
  factors and its numeric constants;
- a factor ``step(b)`` / ``heaviside(b)`` / ``sign(b)`` whose argument b = s·c·B (sign s,
  numeric constants c > 0, factors B) has every factor of B among the product's other
  factors (as a multiset of syntax trees; a factor ``R - L`` stands for −(L − R)) is taken
  out with them: with G the remaining factors, a·step(b) = G·B·[s·B > 0] = G·max(B, 0)
  (s = +1) or G·min(B, 0) (s = −1), and a·sign(b) = s·G·|B|;
- this repeats on G, so ``x1*step(x1)*x2*step(x2)`` is max(x1, 0)·max(x2, 0).

At B = 0 both sides are 0 (step(0) = sign(0) = 0). So ``2*x1*step(x1)``, ``x1*step(-x1)``
(= min(x1, 0)), ``(t - 1)*step(1 - t)`` (= min(t − 1, 0)), ``x1*x2*step(x1)``,
``x1/2*step(2*x1)`` and ``x*sign(x)`` (= |x|) are
Lipschitz where they are, and their enclosures say so; ``x1*step(x2)`` keeps its jump.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from obsdesign.spec.expr import source_segment

#: the switches: step(b) = heaviside(b) = [b > 0], sign(b)
_SWITCHES = ("step", "heaviside", "sign")


@dataclass(frozen=True)
class Factors:
    """A product s·Π ``factors``: ``sign`` ±1, ``factors`` the syntax trees multiplied (numeric
    literals and ``1/c`` among them), in their order."""

    sign: int
    factors: tuple[ast.AST, ...]


@dataclass(frozen=True)
class Switch:
    """One switch taken out of a product: ``kind`` "max" (G·max(B, 0)), "min" (G·min(B, 0)) or
    "abs" (G·|B|), B = Π ``core``."""

    kind: str
    core: tuple[ast.AST, ...]


@dataclass(frozen=True)
class Split:
    """A product read as ``sign`` · Π ``rest`` · Π (each switch's function of its core)."""

    sign: int
    rest: tuple[ast.AST, ...]
    switches: tuple[Switch, ...]


def _positive_literal(node: ast.AST) -> bool:
    """A numeric literal > 0 (a literal is never negative in the tree; 0 and one that rounds
    to 0.0 are refused, so nothing is divided by zero or dropped from a step as positive)."""
    return (
        isinstance(node, ast.Constant)
        and isinstance(node.value, (int, float))
        and not isinstance(node.value, bool)
        and node.value > 0
    )


def factors(node: ast.AST) -> Factors:
    """The sign and factors of a product tree: ``*`` and unary ``-`` are opened, ``X / c`` for a
    numeric literal c > 0 gives the factors of X and the factor ``1/c`` (a tree with c's own
    source position, so c keeps its exact decimal value), anything else is one factor."""
    sign = 1
    out: list[ast.AST] = []
    todo = [node]
    while todo:
        n = todo.pop()
        if isinstance(n, ast.UnaryOp) and isinstance(n.op, (ast.USub, ast.UAdd)):
            sign = -sign if isinstance(n.op, ast.USub) else sign
            todo.append(n.operand)
        elif isinstance(n, ast.BinOp) and isinstance(n.op, ast.Mult):
            todo += [n.right, n.left]  # popped left first: the factors keep their order
        elif isinstance(n, ast.BinOp) and isinstance(n.op, ast.Div) and _positive_literal(n.right):
            todo.append(n.left)
            out.append(ast.BinOp(ast.Constant(1), ast.Div(), n.right))
        else:
            out.append(n)
    return Factors(sign, tuple(out))


def _is_constant(node: ast.AST) -> bool:
    """A numeric literal > 0 or a ``1/c`` factor of :func:`factors`."""
    return _positive_literal(node) or (
        isinstance(node, ast.BinOp)
        and isinstance(node.op, ast.Div)
        and isinstance(node.left, ast.Constant)
        and node.left.value == 1
        and _positive_literal(node.right)
    )


def exact_key(node: Any, src: str | None) -> str:
    """A dump of the tree ``node`` in which every literal stands for its exact decimal value
    (its text in ``src``): two trees are the same function iff their keys are equal (as far
    as the syntax shows). ``ast.dump`` alone shows a literal's double, so 0.1 and
    0.10000000000000001 looked alike, and ``(x1 - 0.1)*step(x1 - 0.10000000000000001)``,
    which jumps by 10⁻¹⁷, was read as max(x1 − 0.1, 0) and certified Lipschitz
    (search-space trial, session 24). A literal without a position in ``src`` (the ``1`` of
    a ``1/c`` factor) shows its Python value."""
    if isinstance(node, ast.Constant):
        seg = source_segment(src, node)
        if seg is not None:
            try:
                return f"Q({Fraction(seg.replace('_', ''))})"
            except (ValueError, ZeroDivisionError):
                pass
        return f"C({node.value!r})"
    if isinstance(node, ast.AST):
        inner = ",".join(exact_key(getattr(node, f, None), src) for f in node._fields)
        return f"{type(node).__name__}({inner})"
    if isinstance(node, list):
        return "[" + ",".join(exact_key(x, src) for x in node) + "]"
    return repr(node)


def _negated(node: ast.AST, src: str | None) -> str | None:
    """The key of ``R - L`` for a subtraction ``L - R`` (= −(L − R) exactly), else None."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Sub):
        return exact_key(ast.BinOp(node.right, ast.Sub(), node.left), src)
    return None


def _match(
    others: list[ast.AST], core: list[ast.AST], src: str | None
) -> tuple[list[ast.AST], int] | None:
    """``others`` without one factor for each factor of ``core`` (the same tree, or the
    swapped subtraction ``R - L`` of a core factor ``L - R``; literals compared at their
    exact value in ``src``), in order, and the sign (−1)^(swapped ones) that the taken
    factors' product has against the core's; None when a core factor has no partner."""
    left = [(x, exact_key(x, src)) for x in others]
    sign = 1
    for c in core:
        want, neg = exact_key(c, src), _negated(c, src)
        j = next((k for k, (_, d) in enumerate(left) if d == want), None)
        if j is None and neg is not None:
            j = next((k for k, (_, d) in enumerate(left) if d == neg), None)
            sign = -sign if j is not None else sign
        if j is None:
            return None
        del left[j]
    return [x for x, _ in left], sign


def split(node: ast.AST, src: str | None) -> Split | None:
    """The reading of the product ``node`` with every switch whose argument's factors are
    among the other factors taken out (see the module docstring); None when there is none
    (the product is then enclosed as written). ``src`` is the text the tree was parsed from:
    literals match at their exact decimal value (:func:`exact_key`)."""
    if not (isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult)):
        return None
    f = factors(node)
    sign = f.sign
    rest = list(f.factors)
    taken: list[Switch] = []
    progress = True
    while progress:
        progress = False
        for i, s in enumerate(rest):
            if not (
                isinstance(s, ast.Call)
                and isinstance(s.func, ast.Name)
                and s.func.id in _SWITCHES
                and len(s.args) == 1
            ):
                continue
            b = factors(s.args[0])
            core = [x for x in b.factors if not _is_constant(x)]
            if not core:
                continue
            m = _match(rest[:i] + rest[i + 1 :], core, src)
            if m is None:
                continue
            kept, flip = m
            sign *= flip
            if s.func.id == "sign":
                sign *= b.sign
                taken.append(Switch("abs", tuple(core)))
            else:
                taken.append(Switch("max" if b.sign > 0 else "min", tuple(core)))
            rest = kept
            progress = True
            break
    if not taken:
        return None
    return Split(sign, tuple(rest), tuple(taken))
