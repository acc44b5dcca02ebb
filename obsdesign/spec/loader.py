"""Load and validate a spec file (TOML).

Numbers are parsed as ``decimal.Decimal`` so that every value is exact; validation checks
dimensions and meaning (square A, C columns = states, sets bounded and non-empty, lower <
upper, E symmetric positive definite); every error names the file and the TOML key.
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import re
import tomllib
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np

from obsdesign.certify.exact import qeye, qzeros
from obsdesign.certify.psd import check_pd
from obsdesign.errors import ObsdesignError, SpecError
from obsdesign.limits import data_problem, int_digits, limits, read_input, values_problem
from obsdesign.sets import Box, Ellipsoid, Polytope, SymmetricPolytope
from obsdesign.sets.base import ConvexSet
from obsdesign.sets.polytope import check_polytope_q
from obsdesign.spec.expr import parse_expr
from obsdesign.spec.models import SimulateSpec, Spec, System
from obsdesign.spec.reader import Table, Value
from obsdesign.spec.signals import parse_signal

#: top-level tables kept raw for the method to read
EXTRA_TABLES = ("nonlinearity",)
SET_TYPES = ("box", "polytope", "symmetric-polytope", "ellipsoid")


def read_spec(path: str | Path) -> Spec:
    """Read, parse and validate the generic parts of the spec at ``path`` (no method bound:
    see :func:`obsdesign.api.load_spec`)."""
    p = Path(path)
    raw = read_input(p, "spec")  # a regular file within the size limit, or InputError
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise SpecError(str(p), "", "is not UTF-8 text") from None
    return read_spec_text(text, str(p))


def _looks_like_report(text: str) -> bool:
    """Whether ``text`` reads as the start of an obsdesign report: a JSON object whose first
    keys are a report's (``schema_version``, ``tool``)."""
    head = text.lstrip()[:400]
    return head.startswith("{") and '"schema_version"' in head and '"spec_sha256"' in text


def read_spec_text(text: str, file: str = "<spec>") -> Spec:
    """Parse and validate the generic parts of spec text; ``file`` is used in error messages.

    Returns a :class:`Spec` whose ``method_table`` (and ``simulate.table``) are raw: the API
    binds the method, which reads its own keys."""
    if isinstance(file, os.PathLike):  # a Path kept as the file made reports unwritable
        file = os.fspath(file)  # (re-check review, session 44; api.load_spec_text did it)
    if text.startswith("\ufeff"):  # tomllib said "Invalid statement (line 1, column 1)"
        raise SpecError(
            file,
            "",
            "starts with a byte-order mark (U+FEFF, 'UTF-8 with BOM'): TOML is UTF-8 without "
            "one; save the file as plain UTF-8",
        )
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as e:
        # a lone surrogate (a non-UTF-8 byte passed through a shell argument, sweep --set
        # title=["\xff"]) was a bare UnicodeEncodeError at the hash, exit 3 (CLI review 46)
        line = text.count("\n", 0, e.start) + 1
        raise SpecError(
            file,
            "",
            f"line {line}: holds a character that is not valid Unicode "
            f"({ascii(text[e.start : e.end])}, a byte that is not UTF-8?); the spec is UTF-8 text",
        ) from None
    data = _parse_toml(text, file)
    method = data.get("method")
    declared = method.get("key") if isinstance(method, dict) else None
    try:
        return _spec(data, text, file)
    except ObsdesignError as e:
        if isinstance(declared, str) and e.method_key is None:
            e.method_key = declared
        raise


def _spec(data: dict[str, Any], text: str, file: str) -> Spec:
    """:func:`read_spec_text` on the parsed ``data`` of ``text``."""
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    root = Table(data, file, checked=True)  # _parse_toml walked every number
    title = root.str("title", default="")
    root.str("description", default="")
    root.str("reference", default="")
    st = root.table("system", required=True)
    assert st is not None
    system = _system(st)
    sets = {name: _set(t, system.n) for name, t in root.tables("sets").items()}
    mt = root.table("method", required=True)
    assert mt is not None
    key = mt.str("key")
    _old_spelling(root, mt)
    tables = {name: t for name in EXTRA_TABLES if (t := root.table(name)) is not None}
    spec = Spec(file, text, sha, title, system, sets, key, None, None, tables, mt)
    sim = root.table("simulate")
    if sim is not None:
        spec.simulate = _simulate(sim, system)
    root.done()
    spec.origin = spec.read_state()
    spec.read_limits = limits()
    return spec


#: the last successful parse: (text, limits) → data. ``verify`` re-reads the spec that
#: ``design`` read moments before in the same process (``check``, the API); the parse is a
#: pure function of the text and the limits, so byte-identical text under the same limits
#: gets a copy of the same data (the stdlib's pure-Python TOML parser is ~70 ms on the 10⁴
#: numbers of a 100-state plant). Every check is still recomputed from that data. One entry:
#: memory stays that of one spec within the limits.
_LAST_PARSE: tuple[tuple[str, Any], dict[str, Any]] | None = None


def _parse_toml(text: str, file: str) -> dict[str, Any]:
    """TOML → data (floats as Decimal), within the limits (:mod:`obsdesign.limits`): size,
    nesting depth, digits and exponent of every number, checked before any number is turned
    into a rational. Errors name the file and the key (or the line). A fresh copy of the
    containers every time (the numbers and strings in them are immutable)."""
    global _LAST_PARSE
    key = (text, limits())
    last = _LAST_PARSE
    if last is not None and last[0] == key:
        return _copy_tree(last[1])
    data = _parse_toml_fresh(text, file)
    _LAST_PARSE = (key, data)
    return _copy_tree(data)


def _copy_tree(x: Any) -> Any:
    """A copy of TOML data: new dicts and lists, the leaves (numbers, strings, dates) shared."""
    if isinstance(x, dict):
        return {k: _copy_tree(v) for k, v in x.items()}
    if isinstance(x, list):
        if any(isinstance(v, (list, dict)) for v in x):
            return [_copy_tree(v) for v in x]
        return x[:]
    return x


def _dotted_too_deep(text: str, depth: int) -> bool:
    """Whether ``text`` holds a run of more than ``depth`` dot-separated key parts
    (``a.b.c…``, bare or quoted, as a dotted key or table name), found in linear time
    (possessive quantifiers: no backtracking on a long word); a number has one dot."""
    import re

    part = r"""(?:[A-Za-z0-9_\-]++|"[^"\n]*+"|'[^'\n]*+')"""
    # a match starts only at the start of a chain (not inside a word, not after a dot): from
    # inside one, every start position would rescan the rest (quadratic on 4 MB of letters)
    start = r"(?<![A-Za-z0-9_\-.])"
    return re.search(rf"{start}(?:{part}[ \t]*+\.[ \t]*+){{{depth},}}{part}", text) is not None


def _parse_toml_fresh(text: str, file: str) -> dict[str, Any]:
    """:func:`_parse_toml` without the memo."""
    lim = limits()
    if len(text) > lim.max_file_bytes:
        raise SpecError(file, "", f"is above the limit of {lim.max_file_bytes} bytes")
    said = values_problem(text.count(","))
    if said:
        raise SpecError(file, "", said)
    lines = text.count("\n")
    if lines >= lim.max_values:
        # 1.6 million empty table headers (16 MiB) took tomllib 60 s and 1.7 GB before the
        # "[system] is missing" (CLI trial, session 40): the commas counted nothing there
        raise SpecError(
            file,
            "",
            f"has {lines + 1} lines, above the limit of {lim.max_values} (--limit max_values=N)",
        )
    if _dotted_too_deep(text, lim.max_depth):
        # a dotted key of 40,000 parts on one line (80 kB, no comma, one line) took tomllib
        # 19 s, and 4 MB of them minutes, before the depth limit below could refuse it
        # (re-check trial, session 40)
        raise SpecError(
            file,
            "",
            f"has a dotted key or table name of more than {lim.max_depth} parts: it is nested "
            f"more than {lim.max_depth} levels deep (--limit max_depth=N)",
        )
    try:
        with int_digits():
            data = tomllib.loads(text, parse_float=Decimal)
    except tomllib.TOMLDecodeError as e:
        if _looks_like_report(text):
            # check or design given a report said only "Invalid statement (line 1)" (tamper
            # review 46)
            raise SpecError(
                file, "", "is an obsdesign report (JSON), not a spec: obsdesign verify reads it"
            ) from None
        raise SpecError(file, "", f"is not valid TOML ({e})") from None
    except RecursionError:
        raise SpecError(
            file,
            "",
            # not "more than max_depth levels": the parser's recursion ran out first, which
            # with a raised limit was below it ("more than 1000000 levels" at 500 levels)
            "is nested too deeply for the TOML reader (Python's recursion limit)",
        ) from None
    except ValueError:  # an integer beyond Python's int-string limit (4300 digits)
        raise SpecError(file, _long_number_line(text), _too_many_digits()) from None
    except ArithmeticError:
        # decimal.InvalidOperation: an exponent past Decimal's own range (0.1e+10^20) was
        # exit 3 "internal failure: InvalidOperation" naming no file (CLI review 45)
        raise SpecError(
            file,
            # 18 digits: 100e999999999999999999 is past Decimal's range once normalized
            _line_of(text, r"[eE][+-]?[\d_]{18,}"),
            f"has a number whose exponent is beyond ±{limits().max_exponent} (max_exponent)",
        ) from None
    bad = data_problem(data)
    if bad is not None:
        raise SpecError(file, bad[0], bad[1])
    return data


def _too_many_digits() -> str:
    return f"has a number with more than {limits().max_digits} digits (--limit max_digits=N)"


def _long_number_line(text: str) -> str:
    """'line N (key K)' of the first run of digits longer than the digit limit."""
    return _line_of(text, r"\d[\d_]{" + str(limits().max_digits) + ",}")


def _line_of(text: str, pattern: str) -> str:
    """'line N, key K' of the first match of ``pattern`` in a value of ``text``, outside
    comments and strings ('' when none), found with the statement lexer
    (:mod:`obsdesign.spec.tomltext`): a title holding "e" and 19 digits was named in place of
    the number on line 32 (re-check review 45), and a line scan with quotes counted took an
    apostrophe in a title, or a multi-line title, for a value (re-check review 46)."""
    from obsdesign.spec.tomltext import statements, string_end

    rx = re.compile(pattern)
    for st in statements(text):
        if st.kind != "keyval":
            continue
        i, end = st.value_start, st.value_end
        while i < end:
            c = text[i]
            if c in "\"'":
                i = string_end(text, i)
                continue
            if c == "#":
                nl = text.find("\n", i, end)
                i = end if nl < 0 else nl
                continue
            stop = i
            while stop < end and text[stop] not in "\"'#":
                stop += 1
            m = rx.search(text, i, stop)
            if m is not None:
                line = text.count("\n", 0, m.start()) + 1
                key = ".".join(st.key) if st.key else ""
                return f"line {line}" + (f", key {key}" if key else "")
            i = stop
    return ""


def _old_spelling(root: Table, mt: Table) -> None:
    """A spec in the spelling before the one plant model: say where the key lives now."""
    for k in ("f", "h"):
        if mt.has(k):
            raise mt.error(k, f"has moved: the plant's {k} is now [system] {k}")
    nl = root.data.get("nonlinearity")
    if isinstance(nl, dict) and "psi" in nl:
        raise SpecError(root.file, "nonlinearity.psi", "has moved: ψ is now [system] psi")


# -- [system] -----------------------------------------------------------------------------
def _state_names(t: Table, sys: System) -> None:
    """Refuse a state name that an expression would read as something else: ``t`` (a state
    named t was accepted, then its uses in f reported as "uses t" under [method.key]:
    outsider trial, session 22), a function (``sin``), or the name of one of this plant's
    inputs, disturbances or noises (``u1``, ``d2``, ``v1``: the state and the signal would
    share one name; ``v1`` is a free state name when the plant has no noise input)."""
    signals = {*sys.inputs, *sys.disturbances, *sys.noises}
    for s in sys.states:
        unread = _not_normal(s)
        if unread is not None:
            raise t.error("states", f"the state name {unread}")
        what = _reserved_name(s) or ("an input, disturbance or noise" if s in signals else None)
        if what is not None:
            raise t.error(
                "states",
                f"the state name {s!r} is reserved: expressions read it as {what} (reserved: "
                "t, the function names, Python's keywords, and this plant's inputs "
                "u1…, disturbances d1…, noises v1…)",
            )


def _not_normal(name: str) -> str | None:
    """Why an expression cannot name ``name`` as it is written (None when it can): Python
    reads identifiers in NFKC form, so in an expression the fullwidth ``ｘ`` is ``x``, ``ℓ``
    is ``l`` and ``ｔ`` is the time ``t``. States ``["ｘ", "x"]`` passed as distinct while
    ``f = ["u1", "ｘ*ｘ"]`` was read as ``x*x``, and a search-space report certified L_f and
    sup |f| for that other plant (false certificate; CLI hostile-input trial, session 34)."""
    import unicodedata

    normal = unicodedata.normalize("NFKC", name)
    if normal == name:
        return None

    def shown(s: str) -> str:
        # code points where the two forms look alike (a decomposed é read as 'é' is 'é';
        # re-check trial, session 34)
        return repr(s) if s.isascii() else f"{s!r} ({' '.join(f'U+{ord(c):04X}' for c in s)})"

    return (
        f"{shown(name)} is read as {shown(normal)} in expressions (Python reads identifiers in "
        f"NFKC form): write it as {normal!r}"
    )


def _reserved_name(name: str) -> str | None:
    """What an expression reads ``name`` as when it cannot name a state or a parameter (None
    when it can): the time ``t``, a function (``sin``) or a Python keyword (``lambda``,
    ``None``). A parameter named ``cos`` made ``cos(cos*t)`` valid; a state named ``lambda``
    failed as "invalid syntax" under [system.f] (hostile-input trial, session 24). The
    constants ``pi`` and ``e`` may be named: a state or parameter of that name shadows the
    constant in every evaluator (the numeric closures, sympy, the interval enclosures), and
    ``e`` is a natural name for an error state."""
    import keyword

    from obsdesign.spec.expr import FUNCTIONS

    if name == "t":
        return "the time t"
    if name in FUNCTIONS:
        return "a function"
    if keyword.iskeyword(name):
        return "a Python keyword"
    return None


def _signal_count(t: Any, key: str, count: int) -> None:
    """Refuse more inputs, disturbances or outputs than ``max_states`` (the state limit, 100
    by default): the ISS and disturbance matrices are square in them, and ``inputs = 10¹²``
    asked for 14.6 TiB while ``disturbances = 10⁷`` ran 30 s into 1.4 GB before an internal
    failure (hostile-input trial, session 24)."""
    cap = limits().max_states
    if count > cap:
        raise t.error(
            key,
            f"{count:,} signals, above the limit of {cap} (--limit max_states, which bounds "
            "states, inputs, outputs and disturbances alike)",
        )


def _system(t: Table) -> System:
    time = t.str("time", choices=("discrete", "continuous"))
    _check_dimension(t)
    has_f = t.has("f")
    A = t.matrix("A") if (t.has("A") or not has_f) else None
    if A is not None and A.shape[1] != A.shape[0]:
        raise t.error("A", f"expected a square matrix, got {A.shape[0]}×{A.shape[1]}")
    states = t._get("states", None)
    if A is not None:
        n = A.shape[0]
    elif isinstance(states, list) and states:
        n = len(states)
    else:
        n = _expr_count(t, "f")
    if states is None:
        states = [f"x{i + 1}" for i in range(n)]
    elif not (
        isinstance(states, list)
        and len(states) == n
        and all(isinstance(s, str) and s.isidentifier() for s in states)
        and len(set(states)) == n
    ):
        raise t.error("states", f"expected a list of {n} distinct state names (identifiers)")
    C = t.matrix("C", cols=n) if (t.has("C") or not t.has("h")) else None
    p = C.shape[0] if C is not None else _expr_count(t, "h")
    if t.has("B"):
        B = t.matrix("B", rows=n, vector_as="column")
    else:
        m = t.int("inputs", default=None, min=0) if t.has("inputs") else None
        if m is not None:
            _signal_count(t, "inputs", m)
        if m is None:
            m = _expr_count(t, "u") if t.has("u") else 0
        B = Value.of(qzeros((n, m)))
    if t.has("B") and t.has("inputs"):
        raise t.error("inputs", "give the number of inputs by B or by inputs, not both")
    m = B.shape[1]
    _signal_count(t, "B" if t.has("B") else "inputs", m)
    _signal_count(t, "C" if C is not None else "h", p)
    D = (
        t.matrix("D", rows=p, cols=m, vector_as="row" if p == 1 else "column")
        if t.has("D")
        else Value.of(qzeros((p, m)))
    )
    bd_key = "Bd" if t.has("Bd") else "B1"
    if t.has("Bd") and t.has("B1"):
        raise t.error("B1", "give the disturbance input as Bd or B1, not both")
    if t.has(bd_key):
        Bd = t.matrix(bd_key, rows=n, vector_as="column")
        _signal_count(t, bd_key, Bd.shape[1])
    else:
        nd = t.int("disturbances", default=0, min=0)
        _signal_count(t, "disturbances", nd)
        Bd = Value.of(qzeros((n, nd)))
    t.mark("B1", "Bd")
    Dn = t.matrix("Dn", rows=p, vector_as="column") if t.has("Dn") else Value.of(qeye(p))
    if t.has("Dn"):
        # 40,000 noise channels were blamed on [simulate.noise.windows] (hostile-input trial)
        _signal_count(t, "Dn", Dn.shape[1])
    sample_time = t.scalar("sample_time", default=None, min=0, strict_min=True)
    params: dict[str, Value] = {}
    pt = t.table("parameters")
    if pt is not None:
        for k in list(pt.data):
            if not k.isidentifier():
                raise pt.error(k, "expected an identifier as parameter name")
            unread = _not_normal(k)
            if unread is not None:
                raise pt.error(k, f"the parameter name {unread}")
            why = _reserved_name(k)
            if why is not None:
                raise pt.error(
                    k, f"the parameter name {k!r} is reserved: expressions read it as {why}"
                )
            params[k] = pt.scalar(k)
    sys = System(time, A, B, C, D, Bd, Dn, sample_time, list(states), n, p, params)
    _state_names(t, sys)
    if has_f and t.has("psi"):
        raise t.error(
            "psi", "give the plant as f (whole right-hand side) or as A x + psi, not both"
        )
    if t.has("psi") and A is None:
        raise t.error("psi", "is the additive term of A x + psi: A is missing")
    exact = sys.exact_parameters()
    x_u_d_t = [*sys.states, *sys.inputs, *sys.disturbances, "t"]
    sys = dataclasses.replace(  # System is frozen
        sys,
        f=_exprs(t, "f", n, x_u_d_t, exact),
        psi=_exprs(t, "psi", n, x_u_d_t, exact),
        h=_exprs(t, "h", p, [*sys.states, *sys.inputs, *sys.noises, "t"], exact),
        u_signal=_exprs(t, "u", m, ["t"], exact),
    )
    t.done()
    return sys


def _check_dimension(t: Table) -> None:
    """Refuse a state dimension above every method's limit before any number is converted
    (the method's own, lower limit is checked when it is bound)."""
    cap = limits().max_states
    for k in ("A", "states", "f"):
        raw = t.data.get(k)
        if isinstance(raw, list) and len(raw) > cap:
            raise t.error(
                k,
                f"gives {len(raw)} states, above the limit of {cap} (--limit max_states=N)",
            )


def _expr_count(t: Table, k: str) -> int:
    raw = t.data.get(k)
    if isinstance(raw, str):
        return 1
    if not isinstance(raw, list) or not raw:
        raise t.error(k, "expected a non-empty list of expression strings")
    return len(raw)


def _exprs(t: Table, k: str, length: int, variables: list[str], params: dict[str, Any]) -> Any:
    """``k = ["expr", ...]`` with ``length`` entries over ``variables``, or None when absent."""
    if not t.has(k):
        return None
    raw = t._get(k, None)
    if isinstance(raw, str):
        raw = [raw]
    if not isinstance(raw, list) or len(raw) != length or not all(isinstance(e, str) for e in raw):
        raise t.error(k, f"expected a list of {length} expression strings")
    return [parse_expr(e, variables, params, t.file, t.key(f"{k}[{i}]")) for i, e in enumerate(raw)]


# -- [sets.NAME] --------------------------------------------------------------------------
def _set(t: Table, n: int) -> ConvexSet:
    """One ``[sets.NAME]``; its dimension is the state dimension unless ``dim`` says. Without
    ``dim``, a size error names it: a 1-D disturbance polytope G = [[1], [-1]] said only
    "[sets.D.G] expected shape ?×2, got 2×1" (set-invariant review, session 41)."""
    if t.has("dim"):
        return _set_of_dim(t, t.int("dim", min=1))
    try:
        return _set_of_dim(t, n)
    except SpecError as e:
        if not re.match(r"expected (shape |\d+ numbers?, got)", e.expected) or e.key.endswith(".g"):
            raise  # not a size error, or g's, whose length follows G's rows, not the dimension
        raise SpecError(
            e.file,
            e.key,
            f"{e.expected} (without dim, a set has the state dimension {n}; a set of "
            "another dimension, such as a disturbance set, gives dim)",
        ) from None


def _set_of_dim(t: Table, n: int) -> ConvexSet:
    """One ``[sets.NAME]`` of dimension ``n``."""
    kind = t.str("type", choices=SET_TYPES)
    s: ConvexSet
    if kind == "box":
        lo = t.vector("lower", n=n)
        hi = t.vector("upper", n=n)
        for i in range(n):
            if not lo.q[i] < hi.q[i]:
                raise t.error("upper", f"expected lower < upper in every coordinate (index {i})")
        s = Box(lo.q, hi.q)
    elif kind == "ellipsoid":
        E = t.matrix("E", rows=n, cols=n)
        Eq = E.q
        if any(Eq[i, j] != Eq[j, i] for i in range(n) for j in range(n)):
            raise t.error("E", "expected a symmetric matrix")
        if not check_pd(Eq):
            raise t.error("E", "expected a positive definite matrix")
        c = t.vector("center", n=n) if t.has("center") else Value.of(qzeros((n,)))
        s = Ellipsoid(Eq, np.asarray(c.q, dtype=object))
    elif kind == "polytope":
        G = t.matrix("G", cols=n)
        g = t.vector("g", n=G.shape[0])
        s = Polytope(G.q, np.asarray(g.q, dtype=object))
        _check_polytope(t, s, "G")
    else:
        Qm = t.matrix("Q", cols=n)
        s = SymmetricPolytope.from_Q(Qm.q)
        _check_polytope(t, s, "Q")
    t.done()
    return s


def _check_polytope(t: Table, s: Polytope, key: str) -> None:
    """Non-empty and bounded: decided exactly with cdd.gmp, else by float LPs (HiGHS)."""
    nonempty, bounded, _exact = check_polytope_q(s.G_q, s.g_q)
    if not nonempty:
        raise t.error(key, "describes an empty set")
    if not bounded:
        raise t.error(key, "describes an unbounded set (expected a bounded polytope)")


# -- [simulate] ---------------------------------------------------------------------------
def _simulate(t: Table, system: System) -> SimulateSpec:
    n = system.n
    if system.discrete:
        horizon = Value.of(_pos_int(t, "horizon"))
        dt = given = None
    else:
        horizon = t.scalar("horizon", min=0, strict_min=True)
        dt = t.scalar("dt", default=None, min=0, strict_min=True)
        if dt is None:
            dt = system.sample_time or Value.of(horizon.q / 1000)
        dt, given = _whole_steps(horizon, dt)
    x0 = t.vector("x0", n=n)
    xhat0 = t.vector("xhat0", n=n)
    seed = t.int("seed", default=0, min=0)
    u = parse_signal(t.table("u"), system.m)
    d = parse_signal(t.table("disturbance"), system.nd)
    v = parse_signal(t.table("noise"), system.nv)
    sim = SimulateSpec(horizon, dt, x0, xhat0, u, d, v, seed, t)
    sim.dt_given = given
    return sim


def _whole_steps(horizon: Value, dt: Value) -> tuple[Value, Value | None]:
    """The output step of a continuous-time simulation: ``dt`` when the horizon is a whole
    number K of steps (to 10⁻⁹ relative and 10⁻⁶ of a step, so that 10 / 0.1 counts as 100
    although the double 0.1 is not 1/10), else horizon / ⌈horizon / dt⌉, the largest step below ``dt`` that ends
    the grid at the horizon: with dt = 0.3 the grid of horizon 1 stopped at 0.9, and with
    dt = 5 it held t = 0 alone (independent simulate review). Returns the step and the
    given ``dt`` when it was changed (else None)."""
    from flint import fmpq

    r = horizon.q / dt.q
    k = int(round(float(r))) if r < 2**52 else None
    if r.q == 1 or (k is not None and k >= 1 and abs(r - k) <= min(r / 10**9, fmpq(1, 10**6))):
        return dt, None
    K = max(int(r.p // r.q) + 1, 1)  # ⌈r⌉ for r not an integer
    return Value.of(horizon.q / K), dt


def _pos_int(t: Table, k: str) -> Any:
    from flint import fmpq

    return fmpq(t.int(k, min=1))
