"""Load and validate a spec file (TOML).

Numbers are parsed as ``decimal.Decimal`` so that every value is exact; validation checks
dimensions and meaning (square A, C columns = states, sets bounded and non-empty, lower <
upper, E symmetric positive definite); every error names the file and the TOML key.
"""

from __future__ import annotations

import hashlib
import tomllib
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np

from obsdesign.certify.exact import qeye, qzeros
from obsdesign.certify.psd import check_pd
from obsdesign.errors import InputError, SpecError
from obsdesign.sets import Box, Ellipsoid, Polytope, SymmetricPolytope
from obsdesign.sets.base import ConvexSet
from obsdesign.sets.polytope import check_polytope_q
from obsdesign.spec.models import SimulateSpec, Spec, System
from obsdesign.spec.reader import Table, Value
from obsdesign.spec.signals import parse_signal

TOP_KEYS = ("title", "description", "reference", "system", "sets", "method", "simulate")
SET_TYPES = ("box", "polytope", "symmetric-polytope", "ellipsoid")


def load_spec(path: str | Path) -> Spec:
    """Read, parse and validate the spec at ``path``."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise InputError(f"{p}: no such spec file") from None
    except OSError as e:
        raise InputError(f"{p}: cannot read ({e.strerror})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise SpecError(str(p), "", "is not UTF-8 text") from None
    return load_spec_text(text, str(p))


def load_spec_text(text: str, file: str = "<spec>") -> Spec:
    """Parse and validate spec text; ``file`` is used in error messages."""
    try:
        data = tomllib.loads(text, parse_float=Decimal)
    except tomllib.TOMLDecodeError as e:
        raise SpecError(file, "", f"is not valid TOML ({e})") from None
    sha = hashlib.sha256(text.encode("utf-8")).hexdigest()
    root = Table(data, file)
    title = root.str("title", default="")
    root.str("description", default="")
    root.str("reference", default="")
    system = _system(root.table("system", required=True))  # type: ignore[arg-type]
    sets = {name: _set(t, system.n) for name, t in root.tables("sets").items()}

    mt = root.table("method", required=True)
    assert mt is not None
    from obsdesign.methods import get_method, method_keys

    key = mt.str("key")
    if key not in method_keys():
        raise mt.error("key", f"expected one of {', '.join(method_keys())}; got {key!r}")
    method = get_method(key)
    extra = {name: t for name in method.extra_tables if (t := root.table(name)) is not None}
    spec = Spec(file, text, sha, title, system, sets, key, None, None, extra)
    spec.options = method.parse_options(mt, spec)
    st = root.table("simulate")
    if st is not None:
        spec.simulate = _simulate(st, system)
        spec.simulate.options = method.parse_simulate(st, spec)
        st.done()
    root.done()
    return spec


# -- [system] -----------------------------------------------------------------------------
def _system(t: Table) -> System:
    time = t.str("time", choices=("discrete", "continuous"))
    A = t.matrix("A")
    n = A.shape[0]
    if A.shape[1] != n:
        raise t.error("A", f"expected a square matrix, got {A.shape[0]}×{A.shape[1]}")
    C = t.matrix("C", cols=n)
    p = C.shape[0]
    B = t.matrix("B", rows=n, vector_as="column") if t.has("B") else Value.of(qzeros((n, 0)))
    m = B.shape[1]
    D = (
        t.matrix("D", rows=p, cols=m, vector_as="row" if p == 1 else "column")
        if t.has("D")
        else Value.of(qzeros((p, m)))
    )
    bd_key = "Bd" if t.has("Bd") else "B1"
    if t.has("Bd") and t.has("B1"):
        raise t.error("B1", "give the disturbance input as Bd or B1, not both")
    Bd = t.matrix(bd_key, rows=n, vector_as="column") if t.has(bd_key) else Value.of(qzeros((n, 0)))
    t.mark("B1", "Bd")
    Dn = t.matrix("Dn", rows=p, vector_as="column") if t.has("Dn") else Value.of(qeye(p))
    sample_time = t.scalar("sample_time", default=None, min=0, strict_min=True)
    states = t._get("states", None)
    if states is None:
        states = [f"x{i + 1}" for i in range(n)]
    elif not (
        isinstance(states, list)
        and len(states) == n
        and all(isinstance(s, str) and s.isidentifier() for s in states)
    ):
        raise t.error("states", f"expected a list of {n} state names (identifiers)")
    params: dict[str, Value] = {}
    pt = t.table("parameters")
    if pt is not None:
        for k in list(pt.data):
            if not k.isidentifier():
                raise pt.error(k, "expected an identifier as parameter name")
            params[k] = pt.scalar(k)
    t.done()
    return System(time, A, B, C, D, Bd, Dn, sample_time, list(states), params)


# -- [sets.NAME] --------------------------------------------------------------------------
def _set(t: Table, n: int) -> ConvexSet:
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
        dt = None
    else:
        horizon = t.scalar("horizon", min=0, strict_min=True)
        dt = t.scalar("dt", default=None, min=0, strict_min=True)
        if dt is None:
            dt = system.sample_time or Value.of(horizon.q / 1000)
    x0 = t.vector("x0", n=n)
    xhat0 = t.vector("xhat0", n=n)
    seed = t.int("seed", default=0, min=0)
    u = parse_signal(t.table("u"), system.m)
    d = parse_signal(t.table("disturbance"), system.nd)
    v = parse_signal(t.table("noise"), system.nv)
    return SimulateSpec(horizon, dt, x0, xhat0, u, d, v, seed, t)


def _pos_int(t: Table, k: str) -> Any:
    from flint import fmpq

    return fmpq(t.int(k, min=1))
