"""The ``[method]`` and ``[simulate]`` keys of the ``search-space`` method (Hernández &
García, "An alternative approach to the state observation problem for Lipschitz continuous
systems with controls").

``[method]``: the ambient box E, the initial search space D (a box that may be degenerate:
the paper's D is a segment of h⁻¹(y(t₀))), the input range U (the spec layer has no input
range key, so it is read here), the horizon of interest, α, κ, γ⋆ (or ε⋆), γ₀, optional K and
optional user-given constants L_f, L_h, f_sup (then marked "given" in the certificate), and the
budget of the interval subdivision.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.errors import SpecError
from obsdesign.sets import Box
from obsdesign.simulate.budget import DEFAULT_LIMIT, TIME_LIMIT_SCHEMA, parse_time_limit
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

REFINE = ("recover", "paper")


@dataclass
class Options:
    """Typed ``[method]`` of ``search-space`` (exact numbers are fmpq)."""

    E: Box
    E_where: str
    D: Box
    D_where: str
    U: Box | None
    horizon: fmpq | None
    alpha: fmpq
    kappa: fmpq | None
    gamma_star: fmpq | None
    eps_star: fmpq | None
    gamma0: fmpq
    K: int | None
    L_f: fmpq | None
    L_h: fmpq | None
    f_sup: fmpq | None
    bound_boxes: int
    bound_rtol: float
    digits: int
    t0: fmpq


@dataclass
class SimOptions:
    """Method keys of ``[simulate]``: the memory cap (live centres), the refinement scheme at
    the switches, RK4 steps per sample (0: automatic), how often centres are stored and the
    seconds the simulation may run (checked after every sample and inside the refinement)."""

    max_centres: int = 2_000_000
    refine: str = "recover"
    substeps: int = 0
    store_every: int = 1
    time_limit: float = DEFAULT_LIMIT


def _box(table: Table, k: str, spec: Spec, dim: int, strict: bool) -> tuple[Box, str]:
    """A box from a set name in ``[sets]`` or from an inline table {lower, upper}."""
    raw = table.data.get(k)
    if isinstance(raw, str):
        name = table.str(k)
        if name not in spec.sets:
            raise table.error(
                k, f"names no set in [sets] (known: {', '.join(spec.sets) or 'none'})"
            )
        s = spec.sets[name]
        if not isinstance(s, Box):
            raise table.error(k, f"[sets.{name}] must be a box for the search-space method")
        if s.dim != dim:
            raise table.error(k, f"[sets.{name}] has dimension {s.dim}, expected {dim}")
        return s, f"[sets.{name}]"
    t = table.table(k, required=True)
    assert t is not None
    lo = t.vector("lower", n=dim)
    hi = t.vector("upper", n=dim)
    t.done()
    for i in range(dim):
        bad = lo.q[i] >= hi.q[i] if strict else lo.q[i] > hi.q[i]
        if bad:
            rel = "<" if strict else "<="
            raise t.error("upper", f"expected lower {rel} upper in every coordinate (index {i})")
    return Box(np.array(lo.q, dtype=object), np.array(hi.q, dtype=object)), f"[method.{k}]"


def _opt_pos(table: Table, k: str) -> fmpq | None:
    v = table.scalar(k, default=None, min=0, strict_min=True)
    return None if v is None else v.q


def parse_options(table: Table, spec: Spec) -> Options:
    """Read and validate ``[method]`` (every error names the file and the key)."""
    s = spec.system
    if s.discrete:
        raise table.error(
            "key",
            'the search-space observer (Hernández & García) is for continuous time: set [system] time = "continuous"',
        )
    if s.f is None or s.h is None:
        raise table.error("key", "the search-space method needs the plant as [system] f and h")
    for k, v in (("A", s.A), ("C", s.C)):
        if v is not None:  # was accepted and silently ignored (soundness trial, session 23)
            raise SpecError(
                spec.file,
                f"system.{k}",
                "is not read by the search-space method (the plant is ẋ = f(x, u), y = h(x)): "
                "remove it, or write its terms into f / h",
            )
    for i, ex in enumerate(s.f):
        for v in (*s.disturbances, "t"):
            if ex.uses(v):
                # the key is [system.f], where the term is (it named [method.key]: outsider
                # trial, session 22)
                raise SpecError(
                    spec.file,
                    "system.f",
                    f"f[{i}] uses {v}: the search-space method takes ẋ = f(x, u) (time enters "
                    "through u(t))",
                )
    for i, ex in enumerate(s.h):
        for v in (*s.inputs, *s.noises, "t"):
            if ex.uses(v):
                raise SpecError(
                    spec.file, "system.h", f"h[{i}] uses {v}: the paper's output is y = h(x)"
                )
    if s.m > 0 and s.u_signal is None:
        raise table.error(
            "key", "the plant has inputs: give the open-loop input as [system] u = [...] (of t)"
        )
    n = s.n
    E, E_where = _box(table, "E", spec, n, strict=False)
    D, D_where = _box(table, "D", spec, n, strict=False)
    U = None
    if s.m > 0:
        U, _ = _box(table, "U", spec, s.m, strict=False)
    horizon = table.scalar("horizon", default=None, min=0, strict_min=True)
    if horizon is None and spec.simulate is not None:
        horizon = spec.simulate.horizon
    alpha = table.scalar("alpha", min=0, strict_min=True).q
    kappa = _opt_pos(table, "kappa")
    gamma_star = _opt_pos(table, "gamma_star")
    eps_star = _opt_pos(table, "eps_star")
    if (gamma_star is None) == (eps_star is None):
        raise table.error("gamma_star", "give exactly one of gamma_star and eps_star (ε⋆ = γ⋆/κ)")
    gamma0 = table.scalar("gamma0", min=0, strict_min=True).q
    K = table.int("K", default=None, min=1)
    opts = Options(
        E=E,
        E_where=E_where,
        D=D,
        D_where=D_where,
        U=U,
        horizon=None if horizon is None else horizon.q,
        alpha=alpha,
        kappa=kappa,
        gamma_star=gamma_star,
        eps_star=eps_star,
        gamma0=gamma0,
        K=K,
        L_f=_opt_pos(table, "L_f"),
        L_h=_opt_pos(table, "L_h"),
        f_sup=_opt_pos(table, "f_sup"),
        bound_boxes=_bound_boxes(table),
        bound_rtol=float(table.scalar("bound_rtol", default=fmpq(1, 1000), min=0).f),
        digits=_digits(table),
        t0=table.scalar("t0", default=fmpq(0)).q,
    )
    table.done()
    return opts


#: sub-boxes per constant at most (``[method] bound_boxes``): about 1,500 a second, so 10⁸
#: ran for hours in design and in verify of a 3-KB report (search-space trial, session 29);
#: this many take about 15 s per constant
MAX_BOUND_BOXES = 20_000


def _bound_boxes(table: Table) -> int:
    """``[method] bound_boxes``: 1 … :data:`MAX_BOUND_BOXES`."""
    n = int(table.int("bound_boxes", default=300, min=1))
    if n > MAX_BOUND_BOXES:
        raise table.error(
            "bound_boxes",
            f"expected at most {MAX_BOUND_BOXES:,} sub-boxes per constant (about 15 s each); "
            "give L_f, L_h or f_sup in [method] for a bound the branch and bound cannot reach",
        )
    return n


#: RK4 substeps a sample at most (``[simulate] substeps``): 10⁹ built one Python tuple per
#: substep and took the machine's memory (independent simulate review)
MAX_SUBSTEPS = 100_000


def _substeps(table: Table) -> int:
    """``[simulate] substeps``: 0 (automatic) … :data:`MAX_SUBSTEPS`."""
    n = int(table.int("substeps", default=0, min=0))
    if n > MAX_SUBSTEPS:
        raise table.error("substeps", f"expected at most {MAX_SUBSTEPS:,} RK4 steps a sample")
    return n


def parse_sim(table: Table, spec: Spec) -> SimOptions:
    """The method's own ``[simulate]`` keys."""
    return SimOptions(
        max_centres=table.int("max_centres", default=2_000_000, min=1),
        refine=table.str("refine", default="recover", choices=REFINE),
        substeps=_substeps(table),
        store_every=table.int("store_every", default=1, min=1),
        time_limit=parse_time_limit(table),
    )


def options_schema(key: str) -> dict[str, Any]:
    """JSON schema of ``[method]``."""
    num = {"type": "number"}
    pos = {"type": "number", "exclusiveMinimum": 0}
    vec = {
        "anyOf": [num, {"type": "array", "items": num, "minItems": 1}]
    }  # a scalar: one coordinate
    box = {
        "anyOf": [
            {"type": "string"},
            {
                "type": "object",
                "properties": {"lower": vec, "upper": vec},
                "required": ["lower", "upper"],
                "additionalProperties": False,
            },
        ]
    }
    return {
        "type": "object",
        "required": ["key", "E", "D", "alpha", "gamma0"],
        "additionalProperties": False,
        "properties": {
            "key": {"const": key},
            "E": box,
            "D": box,
            "U": box,
            "horizon": pos,
            "t0": num,
            "alpha": pos,
            "kappa": pos,
            "gamma_star": pos,
            "eps_star": pos,
            "gamma0": pos,
            "K": {"type": "integer", "minimum": 1},
            "L_f": pos,
            "L_h": pos,
            "f_sup": pos,
            "bound_boxes": {"type": "integer", "minimum": 1, "maximum": MAX_BOUND_BOXES},
            "bound_rtol": {"type": "number", "minimum": 0},
            "digits": {"type": "integer", "minimum": 2, "maximum": MAX_DIGITS},
        },
    }


def simulate_schema() -> dict[str, Any]:
    """JSON-schema properties of the method's ``[simulate]`` keys."""
    return {
        "max_centres": {"type": "integer", "minimum": 1},
        "refine": {"enum": list(REFINE)},
        "substeps": {"type": "integer", "minimum": 0, "maximum": MAX_SUBSTEPS},
        "store_every": {"type": "integer", "minimum": 1},
        "time_limit": TIME_LIMIT_SCHEMA,
    }


#: most significant digits of the reported constants (``digits``): 100000 ended in Python's
#: 4300-digit limit of int-to-string conversion, exit 3 (review 19); 30 is the impulsive
#: method's limit too
MAX_DIGITS = 30


def _digits(table: Any) -> int:
    """``[method] digits``: an integer in [2, MAX_DIGITS] (the constants of Lemmas 1-2 and
    Theorem 1 are rounded up to that many significant digits)."""
    digits: int = table.int("digits", default=6, min=2)
    if digits > MAX_DIGITS:
        raise table.error("digits", f"expected at most {MAX_DIGITS} digits, got {digits}")
    return digits
