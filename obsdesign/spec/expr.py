"""A small, safe expression language for nonlinear terms in specs.

Strings like ``x1*x2*(x2+a)*(x2-a)/(1+x2^4)`` over declared variables (states, inputs, time)
and named parameters. Parsing uses Python's :mod:`ast` with a whitelist: numbers, the declared
names, ``+ - * / ^ ** %``, unary minus, and calls of the whitelisted functions. Attribute
access, subscripts, lambdas, comprehensions, keywords, strings and every other construct are
rejected with a message naming the construct. Spec text is never passed to ``eval``/``exec``
or ``sympify``: it is compiled into numpy closures walking the checked tree, and into a sympy
expression built node by node (for exact Jacobians). ``^`` means power.

Functions: sin cos tan exp log sqrt abs tanh atan sinh cosh min max sat sign step heaviside
floor mod. ``sat(x) = clip(x, -1, 1)``, ``sat(x, r) = max(-r, min(r, x))`` (``clip(x, -r, r)``
for r >= 0, the constant -r for r < 0), ``step(x) =
heaviside(x) = 1 if x > 0 else 0``, ``mod(a, b) = a - b*floor(a/b)``. Constants ``pi``, ``e``.
"""

from __future__ import annotations

import ast
import functools
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from obsdesign.errors import SpecError
from obsdesign.spec.frozen import ReadOnlyDict


def source_segment(src: str | None, node: ast.AST) -> str | None:
    """The text of ``node`` in ``src`` (``ast.get_source_segment``), or None without a source
    or a position. Cached by position: ``ast.get_source_segment`` splits the whole source at
    every call, and the interval enclosures ask it for every literal in every sub-box — a sum of
    190 terms (2,169 characters) took 63 s to design, a product of 700, 9,687 characters, more
    than 10 minutes (hostile-input review, session 38)."""
    if src is None or getattr(node, "end_col_offset", None) is None:
        return None
    return _segment(src, node.lineno, node.col_offset, node.end_lineno, node.end_col_offset)  # type: ignore[attr-defined]


@functools.lru_cache(maxsize=1 << 16)
def _segment(src: str, l0: int, c0: int, l1: int, c1: int) -> str | None:
    pos = ast.Constant(value=None, lineno=l0, col_offset=c0, end_lineno=l1, end_col_offset=c1)
    return ast.get_source_segment(src, pos)


Env = dict[str, Any]
Fn = Callable[[Env], Any]


def _sat(x: Any, r: Any = 1.0) -> Any:
    """max(−r, min(r, x)): clip(x, −r, r) for r ≥ 0, and −r for r < 0, as the interval and
    sympy evaluators take it (numpy's clip gave r there: sat(x1, −1) ≡ −1 at run time but +1
    in the certified enclosures, and search-space certified a false sup |f|, review 19)."""
    return np.maximum(np.negative(r), np.minimum(r, x))


def _step(x: Any) -> Any:
    return np.where(np.asarray(x) > 0, 1.0, 0.0)


def _mod(a: Any, b: Any) -> Any:
    return a - b * np.floor(a / b)


#: one-argument functions that numpy and sympy name as the spec language does
_ALIKE = ("sin", "cos", "tan", "exp", "log", "sqrt", "tanh", "sinh", "cosh", "sign", "floor")
#: the whitelisted functions: name → (numpy function, allowed numbers of arguments)
FUNCTIONS: dict[str, tuple[Callable[..., Any], tuple[int, ...]]] = {
    **{name: (getattr(np, name), (1,)) for name in _ALIKE},
    "abs": (np.abs, (1,)),
    "atan": (np.arctan, (1,)),
    "min": (np.minimum, (2,)),
    "max": (np.maximum, (2,)),
    "sat": (_sat, (1, 2)),
    "step": (_step, (1,)),
    "heaviside": (_step, (1,)),
    "mod": (_mod, (2,)),
}
CONSTANTS = {"pi": np.pi, "e": np.e}

_BINOPS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: np.add,
    ast.Sub: np.subtract,
    ast.Mult: np.multiply,
    ast.Div: np.divide,
    ast.Pow: np.power,
    ast.BitXor: np.power,
    ast.Mod: _mod,
}
_FORBIDDEN = {
    ast.Attribute: "attribute access is",
    ast.Subscript: "subscripts are",
    ast.Lambda: "lambda is",
    **dict.fromkeys(
        (ast.ListComp, ast.GeneratorExp, ast.DictComp, ast.SetComp), "comprehensions are"
    ),
    ast.Compare: "comparisons are (use step(x))",
    ast.BoolOp: "boolean operators are",
    ast.IfExp: "conditional expressions are",
    ast.NamedExpr: "assignment expressions are",
    ast.Starred: "starred arguments are",
    ast.List: "lists are",
    ast.Tuple: "tuples are",
    ast.Dict: "dicts are",
    ast.JoinedStr: "strings are",
    ast.Await: "await is",
    ast.Yield: "yield is",
}


@dataclass(frozen=True)
class Expr:
    """A checked expression: evaluate it vectorized, differentiate it exactly (sympy).

    Frozen: ``source``, the parsed ``tree`` and the compiled callable belong together (an
    in-place ``source`` edit left the tree and the callable of the old text; API review,
    session 43)."""

    source: str
    tree: ast.Expression
    variables: tuple[str, ...]
    parameters: dict[str, Any]
    _fn: Fn = field(repr=False, default=lambda env: 0.0)
    #: ``ast.dump`` of the tree as parsed (:meth:`intact`)
    _dump: str = field(repr=False, default="", compare=False)
    #: the names the tree as parsed uses (:meth:`uses`)
    _names: frozenset[str] = field(repr=False, default=frozenset(), compare=False)

    def __post_init__(self) -> None:
        # read-only: the parameters belong to the source text as the tree does (session 44)
        if not isinstance(self.parameters, ReadOnlyDict):
            object.__setattr__(self, "parameters", ReadOnlyDict(self.parameters))
        object.__setattr__(self, "_dump", ast.dump(self.tree))
        names = frozenset(n.id for n in ast.walk(self.tree) if isinstance(n, ast.Name))
        object.__setattr__(self, "_names", names)

    def intact(self) -> bool:
        """Whether the tree is still the one parsed from ``source``: an AST is mutable, and a
        node edited in place (``u1*x2`` made ``0.2*x2``) designed claims for another f while
        the compiled callable and the text kept the old one (re-check review, session 44)."""
        return ast.dump(self.tree) == self._dump

    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its source (and variables, parameters), compiled again when loaded: the
        compiled callable is a closure, and every spec with an expression failed to pickle
        ("Can't pickle local object"; API review, session 44)."""
        return (_rebuild_expr, (self.source, self.variables, dict(self.parameters)))

    def __call__(self, **values: Any) -> Any:
        """Evaluate with variables given by name (arrays broadcast: a batch at once)."""
        env: Env = {**CONSTANTS, **{k: float(v) for k, v in self.parameters.items()}}
        env.update({k: np.asarray(v, dtype=float) for k, v in values.items()})
        missing = [v for v in self.variables if v not in env and self.uses(v)]
        if missing:
            raise KeyError(f"no value for {missing[0]}")
        return self._fn(env)

    def uses(self, name: str) -> bool:
        """Whether the expression (as parsed and compiled) reads ``name``: a set made once —
        the tree walked per name and per call was 40% of an impulsive simulation (census
        46)."""
        return name in self._names

    def on(self, order: list[str]) -> Callable[[np.ndarray], np.ndarray]:
        """Callable on an array whose last axis holds ``order`` (shape (..., len(order)))."""

        def f(X: np.ndarray) -> np.ndarray:
            X = np.asarray(X, dtype=float)
            out = self(**{name: X[..., i] for i, name in enumerate(order)})
            return np.broadcast_to(out, X.shape[:-1]).astype(float)

        return f

    def sympy(self) -> Any:
        """The expression as a sympy object, built node by node (parameters exact)."""
        return _to_sympy(self.tree.body, self)

    def exact_sympy(self) -> Any:
        """:meth:`sympy` with every constant power taken exactly: :class:`InexactPower` where
        it would be taken in floats (for exact decisions: a float inf or 0.0 is absorbed by
        sympy, ``pi**1000000/10**100000`` became an exact 0)."""
        return _to_sympy(self.tree.body, self, strict=True)

    def derivative(self, name: str) -> Callable[..., Any]:
        """∂/∂name as a vectorized callable of the same variables (exact symbolic derivative)."""
        import sympy as sp

        d = sp.diff(self.sympy(), sp.Symbol(name))
        if d.has(sp.Derivative):
            raise ValueError(f"'{self.source}' is not differentiable in {name}")

        def f(**values: Any) -> Any:
            env = {k: np.asarray(v, dtype=float) for k, v in values.items()}
            return _eval_sympy(d, env)

        return f

    def jacobian(self, order: list[str]) -> Callable[[np.ndarray], np.ndarray]:
        """Gradient w.r.t. ``order`` on arrays of shape (..., len(order)) → (..., len(order))."""
        parts = [self.derivative(v) for v in order]

        def J(X: np.ndarray) -> np.ndarray:
            X = np.asarray(X, dtype=float)
            vals = {name: X[..., i] for i, name in enumerate(order)}
            return np.stack([np.broadcast_to(p(**vals), X.shape[:-1]) for p in parts], axis=-1)

        return J


def _rebuild_expr(text: str, variables: tuple[str, ...], parameters: dict[str, Any]) -> Expr:
    """An unpickled :class:`Expr`: its source was checked when it was first parsed, so the
    input limits of the process that loads it (a Dask worker's defaults) do not apply — a
    spec read with ``--limit max_expr_chars=20000`` failed to deserialize on the workers of
    ``simulate --workers 2`` (re-check review, session 44)."""
    from obsdesign.limits import CEILINGS, ensure_recursion_limit, raised

    # raised for this thread only (the process's limits, raised and restored, could be left
    # raised by two threads; API review 46)
    with raised(
        max_expr_chars=len(text),
        max_expr_depth=CEILINGS["max_expr_depth"],
        max_exponent=CEILINGS["max_exponent"],
    ):
        ensure_recursion_limit()
        return parse_expr(text, variables, parameters)


def parse_expr(
    text: str,
    variables: list[str] | tuple[str, ...],
    parameters: dict[str, Any] | None = None,
    file: str = "<expr>",
    key: str = "",
) -> Expr:
    """Parse and check ``text``; raise :class:`SpecError` (file, key) on anything not allowed.

    ``parameters`` maps names to exact values (fmpq, int, Decimal, float).
    """
    from obsdesign.limits import limits

    parameters = dict(parameters or {})
    if not isinstance(text, str):
        raise SpecError(file, key, "expected an expression string")
    lim = limits()
    if len(text) > lim.max_expr_chars:
        raise SpecError(
            file,
            key,
            f"expression is {len(text)} characters long, above the limit of "
            f"{lim.max_expr_chars} (--limit max_expr_chars=N)",
        )
    if "#" in text:
        # Python's parser reads '#' as a comment: "-u1*x1 # - 100*x1^3" was the certified
        # plant -u1*x1, with the rest of the text silently dropped (CLI trial, session 40)
        raise SpecError(
            file,
            key,
            "has '#': an expression has no comments (Python would ignore everything after it)",
        )
    depth = nesting_depth(text, stop=lim.max_expr_depth)
    if depth > lim.max_expr_depth:
        raise SpecError(file, key, _too_deep())
    try:
        # ``^`` is power here; Python's ^ binds looser than * and +, so rewrite it as ** first
        tree = ast.parse(text.strip().replace("^", "**"), mode="eval")
    except SyntaxError as e:
        raise SpecError(file, key, f"is not a valid expression ({e.msg})") from None
    except (RecursionError, MemoryError):  # a backstop: nesting_depth bounds the depth first
        raise SpecError(
            file, key, "expression is nested too deeply to parse (Python's recursion limit)"
        ) from None
    except ValueError as e:  # e.g. an integer literal beyond the int-string limit
        raise SpecError(file, key, f"is not a valid expression ({e})") from None
    tree_depth = _tree_depth(tree)
    if tree_depth > lim.max_expr_depth:
        raise SpecError(file, key, _too_deep())
    for m in _EXPONENT.finditer(text):
        if abs(int(m.group(1))) > lim.max_exponent:
            raise SpecError(
                file,
                key,
                f"has the constant {m.group(0).strip()[:40]}: decimal exponent {int(m.group(1))}, "
                f"outside ±{lim.max_exponent} (--limit max_exponent=N)",
            )
    known = set(variables) | set(parameters) | set(CONSTANTS)
    clash = set(variables) & (set(parameters) | set(FUNCTIONS))
    if clash:
        raise SpecError(
            file, key, f"name {sorted(clash)[0]!r} is both a variable and a parameter/function"
        )
    fn = _compile(tree.body, known, file, key)
    return Expr(text, tree, tuple(variables), parameters, fn)


def _too_deep() -> str:
    """The refusal of an expression deeper than ``max_expr_depth``: "more than the limit",
    as the scan stops once past it (the depth it had reached then was printed: a 201-long
    minus chain said "201 levels", one of 199 "202"; docs review, session 41)."""
    from obsdesign.limits import limits

    return (
        f"expression nests more than {limits().max_expr_depth} levels deep "
        f"(--limit max_expr_depth=N)"
    )


#: a decimal exponent in a numeric literal, bounded by the ``max_exponent`` limit as the
#: spec's numbers are: the exact value of a literal (the interval enclosures and the sympy
#: form take decimal literals exactly) is otherwise a power of ten with that many digits
#: (u = "1e-99999999*sin(t)" hung the input-range check)
_EXPONENT = re.compile(r"(?<![\w.])(?:\d+\.?\d*|\.\d+)[eE]([+-]?\d+)")

_TOKEN = re.compile(
    r"\s*(?:(\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)|([A-Za-z_]\w*)|(\*\*|[-+*/%^(),]))"
)
_PREC = {"+": 1, "-": 1, "*": 2, "/": 2, "%": 2, "u": 3, "**": 4, "^": 4}


def nesting_depth(text: str, stop: int | None = None) -> int:
    """The depth of the syntax tree ``text`` would parse to (operators by precedence, ``**``
    right-associative, unary signs, calls and parentheses), computed iteratively with an
    operator-precedence scan, so that a 4000-long ``-`` or ``**`` chain is measured without
    recursion before :func:`ast.parse` sees it. Text it cannot tokenize gets the depth of
    what came before (``ast.parse`` then reports the syntax error). With ``stop``, returns as
    soon as the depth exceeds it."""
    vals: list[int] = []  # depth of each pending operand
    ops: list[str] = []  # operators, "(" and "call("
    marks: list[int] = []  # len(vals) at each open parenthesis
    prev = "start"  # kind of the previous token: start, name, value, op, open, comma

    top = [0]  # the deepest operand built so far

    def apply(op: str) -> None:
        if op == "u":
            vals.append((vals.pop() if vals else 0) + 1)
        else:
            b = vals.pop() if vals else 0
            a = vals.pop() if vals else 0
            vals.append(max(a, b) + 1)
        top[0] = max(top[0], vals[-1])

    def unwind() -> None:
        while ops and ops[-1] in _PREC:
            apply(ops.pop())

    pos, deepest = 0, 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            break
        pos = m.end()
        num, name, op = m.groups()
        if num is not None or name is not None:
            vals.append(1)
            prev = "name" if name is not None else "value"
        elif op == "(":
            ops.append("call(" if prev == "name" else "(")
            marks.append(len(vals))
            prev = "open"
        elif op == ",":
            unwind()
            prev = "comma"
        elif op == ")":
            unwind()
            if ops:
                kind = ops.pop()
                mark = marks.pop()
                args = vals[mark:]
                del vals[mark:]
                if kind == "call(" and vals:
                    vals.pop()  # the function name
                vals.append(max(args, default=0) + (1 if kind == "call(" else 0))
                top[0] = max(top[0], vals[-1])
            prev = "value"
        elif op in _PREC:
            if op in "+-" and prev in ("start", "op", "open", "comma"):
                ops.append("u")
            else:
                p = _PREC[op]
                right = op in ("**", "^")
                while (
                    ops
                    and ops[-1] in _PREC
                    and (_PREC[ops[-1]] > p or (_PREC[ops[-1]] == p and not right))
                ):
                    apply(ops.pop())
                ops.append(op)
            prev = "op"
        deepest = max(deepest, len(ops), top[0])
        if stop is not None and deepest > stop:
            return deepest
    while ops:
        op = ops.pop()
        if op in _PREC:
            apply(op)
    return max(deepest, top[0], max(vals, default=0))


def _tree_depth(tree: ast.AST) -> int:
    """Depth of a parsed tree as :func:`nesting_depth` counts it (a name or number 1, each
    operator, call or unary sign one more; the ``Expression`` wrapper and the load contexts
    not counted: they made the tree 2 deeper than the scan, so a 198-long minus chain passed
    the scan and was refused as "201 levels"; docs review, session 41), walked with an
    explicit stack (no recursion)."""
    deepest = 0
    root = tree.body if isinstance(tree, ast.Expression) else tree
    stack: list[tuple[ast.AST, int]] = [(root, 1)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend(
            (c, d + 1) for c in ast.iter_child_nodes(node) if not isinstance(c, ast.expr_context)
        )
    return deepest


def _compile(node: ast.AST, known: set[str], file: str, key: str) -> Fn:
    def bad(what: str) -> SpecError:
        return SpecError(
            file,
            key,
            f"{what} not allowed in expressions".replace(
                "(use step(x)) not allowed", "not allowed (use step(x))"
            ),
        )

    for t, what in _FORBIDDEN.items():
        if isinstance(node, t):
            raise bad(what)
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise bad(f"the constant {node.value!r} is")
        try:
            # an int of 1024 bits near 2^1024 rounds past the largest double: OverflowError,
            # exit 4 naming no file or key, where 2^1024 itself was this exit 2 (expression
            # soundness trial, session 34)
            c = float(node.value)
        except OverflowError:
            raise SpecError(file, key, "has an integer constant beyond the float range") from None
        if not math.isfinite(c):
            raise SpecError(file, key, "has a constant beyond the float range")
        return lambda env: c
    if isinstance(node, ast.Name):
        name = node.id
        if name.startswith("__") or name not in known:
            if name in FUNCTIONS:
                raise SpecError(file, key, f"'{name}' is a function: call it, e.g. {name}(x1)")
            raise SpecError(file, key, f"unknown name '{name}' (known: {', '.join(sorted(known))})")
        return lambda env: env[name]
    if isinstance(node, ast.UnaryOp):
        arg = _compile(node.operand, known, file, key)
        if isinstance(node.op, ast.USub):
            return lambda env: -arg(env)
        if isinstance(node.op, ast.UAdd):
            return arg
        raise bad(f"the operator {type(node.op).__name__} is")
    if isinstance(node, ast.BinOp):
        op = _BINOPS.get(type(node.op))
        if op is None:
            raise bad(f"the operator {type(node.op).__name__} is")
        left = _compile(node.left, known, file, key)
        right = _compile(node.right, known, file, key)
        return lambda env: op(left(env), right(env))
    if isinstance(node, ast.Call):
        if not isinstance(node.func, ast.Name):
            raise bad("calling anything but a named function is")
        fname = node.func.id
        if fname not in FUNCTIONS:
            raise SpecError(
                file, key, f"unknown function '{fname}' (allowed: {', '.join(sorted(FUNCTIONS))})"
            )
        if node.keywords:
            raise bad("keyword arguments are")
        f, arities = FUNCTIONS[fname]
        if len(node.args) not in arities:
            raise SpecError(
                file, key, f"{fname}() takes {' or '.join(map(str, arities))} argument(s)"
            )
        args = [_compile(a, known, file, key) for a in node.args]
        return lambda env: f(*(a(env) for a in args))
    raise bad(f"the construct {type(node).__name__} is")


# -- sympy, built from the checked tree ---------------------------------------------------
@functools.cache
def _sympy_functions() -> dict[str, Any]:
    """Spec function name → sympy function, for those sympy has (not sat, step, mod)."""
    import sympy as sp

    alike = {name: getattr(sp, name) for name in _ALIKE}
    return {**alike, "abs": sp.Abs, "atan": sp.atan, "min": sp.Min, "max": sp.Max}


@functools.cache
def _numpy_of_sympy() -> dict[Any, Callable[[Any], Any]]:
    """sympy one-argument function → numpy function (sympy's sqrt is a power: never met)."""
    import sympy as sp

    alike = {getattr(sp, name): getattr(np, name) for name in _ALIKE}
    return {**alike, sp.Abs: np.abs, sp.atan: np.arctan}


class InexactPower(ArithmeticError):
    """A constant power too large to take exactly (:func:`_sympy_pow`), met by
    :meth:`Expr.exact_sympy`."""


def _to_sympy(node: ast.AST, ex: Expr, strict: bool = False) -> Any:
    """The sympy form of ``node``; with ``strict`` (exact decisions) a node whose value is
    undefined (1/0 is sympy's zoo, 0/0 its nan) raises ArithmeticError: sympy absorbs it
    further up ((1/0)^0 = 1), and u = (1/0)^0 was certified in U (re-check trial, session
    34)."""
    out = _sympy_node(node, ex, strict)
    if strict:
        import sympy as sp

        if out.has(sp.zoo, sp.nan) or out in (sp.oo, -sp.oo):
            raise ArithmeticError(f"{ast.unparse(node)} is undefined (a division by zero)")
    return out


def _sympy_node(node: ast.AST, ex: Expr, strict: bool = False) -> Any:
    import sympy as sp

    if isinstance(node, ast.Constant):
        if not isinstance(node.value, float):
            return sp.Integer(node.value)
        # the decimal literal's exact value, from the text the tree was parsed from (as the
        # interval enclosures take it); sp.nsimplify made 43.191 a product of surds that only
        # approximates it (found comparing a constant input with its bound exactly)
        seg = source_segment(ex.source.strip().replace("^", "**"), node)
        try:
            return sp.Rational(Fraction(seg.replace("_", "")) if seg else Fraction(node.value))
        except (ValueError, ZeroDivisionError):
            return sp.Rational(Fraction(node.value))
    if isinstance(node, ast.Name):
        if node.id in ex.parameters:
            from obsdesign.certify.exact import Q

            q = Q(ex.parameters[node.id])
            return sp.Rational(int(q.p), int(q.q))
        if node.id in ex.variables:  # a state named e or pi shadows the constant, as in the
            return sp.Symbol(node.id)  # numeric closures and the interval enclosures
        if node.id == "pi":
            return sp.pi
        if node.id == "e":
            return sp.E
        return sp.Symbol(node.id)
    if isinstance(node, ast.UnaryOp):
        a = _to_sympy(node.operand, ex, strict)
        return -a if isinstance(node.op, ast.USub) else a
    if isinstance(node, ast.BinOp):
        a, b = _to_sympy(node.left, ex, strict), _to_sympy(node.right, ex, strict)
        op = type(node.op)
        if op is ast.Add:
            return a + b
        if op is ast.Sub:
            return a - b
        if op is ast.Mult:
            return a * b
        if op is ast.Div:
            return a / b
        if op in (ast.Pow, ast.BitXor):
            return _sympy_pow(a, b, strict)
        return a - b * sp.floor(a / b)
    assert isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
    args = [_to_sympy(a, ex, strict) for a in node.args]
    name = node.func.id
    table = _sympy_functions()
    if name in table:
        return table[name](*args)
    if name == "sat":
        r = args[1] if len(args) == 2 else sp.Integer(1)
        return sp.Max(-r, sp.Min(r, args[0]))
    if name in ("step", "heaviside"):
        return sp.Heaviside(args[0], 0)
    return args[0] - args[1] * sp.floor(args[0] / args[1])  # mod


def _sympy_pow(a: Any, b: Any, strict: bool = False) -> Any:
    """``a**b``, except that a constant power whose exact value would have more than 10^4
    bits (``9**9**9``) is taken in floating point (inf when it overflows): sympy would
    otherwise compute the huge integer exactly and never return. A rational base counts the
    bits of its numerator and denominator, not its magnitude: (1 + 1/10^6)^(10^8) is only
    e¹⁰⁰ but has 2·10⁹ bits exactly (it hung the search-space design; trial, session 24).
    The float fallback is a ``sympy.Float``, which sympy may absorb (X/oo = 0): exact
    decisions use ``strict``, which raises :class:`InexactPower` instead."""
    import math

    import sympy as sp

    if getattr(a, "is_Number", False) and getattr(b, "is_Number", False):
        fa, fb = abs(float(a)), abs(float(b))
        size = fb * abs(math.log2(fa)) if fa not in (0.0, 1.0) and math.isfinite(fa) else 0.0
        if getattr(a, "is_Rational", False) and abs(a) not in (0, 1):
            size = max(size, fb * max(math.log2(abs(int(a.p))), math.log2(int(a.q))))
        if not math.isfinite(fb) or size > 10_000:
            if strict:
                raise InexactPower(f"{a}**{b} is too large to take exactly")
            with np.errstate(all="ignore"):
                return sp.Float(float(np.power(float(a), float(b))))
    return a**b


def _eval_sympy(e: Any, env: dict[str, Any]) -> Any:
    """Evaluate a sympy expression with numpy by walking its tree (no lambdify/eval)."""
    import sympy as sp

    if e.is_Symbol:
        return env[e.name]
    if e.is_Number or e.is_NumberSymbol:
        return float(e)
    args = [_eval_sympy(a, env) for a in e.args]
    if e.is_Add:
        out = args[0]
        for a in args[1:]:
            out = out + a
        return out
    if e.is_Mul:
        out = args[0]
        for a in args[1:]:
            out = out * a
        return out
    if e.is_Pow:
        return np.power(args[0], args[1])
    fn = _numpy_of_sympy().get(e.func)
    if fn is not None:
        return fn(args[0])
    if e.func is sp.Heaviside:
        return np.where(np.asarray(args[0]) > 0, 1.0, 0.0)
    if e.func is sp.DiracDelta:
        return np.zeros_like(np.asarray(args[0], dtype=float))
    if e.func is sp.Min:
        return np.minimum.reduce(np.broadcast_arrays(*args))
    if e.func is sp.Max:
        return np.maximum.reduce(np.broadcast_arrays(*args))
    if e.func is sp.sec:
        return 1 / np.cos(args[0])
    raise ValueError(f"cannot evaluate {e.func} numerically")
