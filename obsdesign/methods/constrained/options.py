"""The ``[method]`` and ``[simulate]`` keys of the ``constrained`` method (paper 000)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q
from obsdesign.certify.psd import check_pd
from obsdesign.errors import SpecError, value_text
from obsdesign.limits import INT_MAX
from obsdesign.methods.base import table_schema
from obsdesign.methods.constrained.cmap import (
    KINDS,
    ConstraintMap,
    box_map,
    ellipsoid_map,
    polytope_map,
)
from obsdesign.sets import Box, Ellipsoid, Polytope, vertices_exact
from obsdesign.sets.base import ConvexSet
from obsdesign.simulate.budget import DEFAULT_LIMIT, TIME_LIMIT_SCHEMA, parse_time_limit
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


@dataclass
class Options:
    """Typed ``[method]`` of ``constrained``.

    Lyapunov data: either computed (``lam`` given or best, ρ = ``rho`` or λ²) or given by the
    user (``P``, ``rho``, ``mu``). Sets: X (box/polytope, from ``[sets]``), X̂ (optional set;
    default: the outer polytope/ellipsoid of C_min), D (box of w = (d, v)).
    """

    L: np.ndarray | None
    lam: fmpq | None
    rho: fmpq | None
    P: np.ndarray | None
    mu: fmpq | None
    X_name: str
    X: ConvexSet
    Xhat_name: str | None
    Xhat: ConvexSet | None
    cmap: ConstraintMap
    D_lower: np.ndarray
    D_upper: np.ndarray
    eps_min: fmpq
    eps_max: fmpq | None
    gamma: fmpq | None
    gamma_uncertified: bool
    margin: fmpq
    rate_tol: fmpq
    X0: ConvexSet | None = None
    Xhat0: ConvexSet | None = None
    file: str = ""
    #: expression-defined f, h, F (nonlinear.Model); None entries mean linear
    model: Any = None
    U_lower: np.ndarray = field(default_factory=lambda: np.zeros(0))
    U_upper: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass
class SimOptions:
    """Method keys of ``[simulate]`` (Section 5, Table 1 of the constrained-redesign paper,
    Astolfi et al., NOLCOS 2019): the step budgets θ_m (one modified observer each), a
    simulation-only γ, the saturation level r of the naive observer (29), and the seconds the
    simulation may run (``time_limit``, exit 3 past it)."""

    theta_m: list[int] = field(default_factory=list)
    gamma: fmpq | None = None
    saturation_r: np.ndarray | None = None
    time_limit: float = DEFAULT_LIMIT


def parse_options(table: Table, spec: Spec) -> Options:
    """Read and validate ``[method]`` (every error names file and key).

    Assumptions 1-3 of the constrained-redesign paper (Astolfi et al., NOLCOS 2019): the sets
    X, X̂, the map c (eq. (18)/(19)/polytope), ε_min < ε_max, the Lyapunov data of eq. (4)-(6).

    :param table: the raw ``[method]`` table; :param spec: the spec (its ``[system]`` and
    ``[sets]`` are already parsed). Returns the typed :class:`Options`."""
    s = spec.system
    for old in ("f", "h"):
        if table.has(old):
            raise table.error(
                old,
                f"has moved: the plant's {old} lives in [system] ({old} = [...]); "
                "only the observer map F stays in [method]",
            )
    if not s.discrete:
        raise table.error(
            "key",
            'the constrained redesign (Astolfi et al.) is for discrete time: set [system] time = "discrete"',
        )
    n = s.n
    from obsdesign.methods.constrained.nonlinear import parse_model

    model = parse_model(table, spec)
    for k, v, expr in (("A", s.A, model.f), ("C", s.C, model.h)):
        if v is None and (expr is None or model.F is None):
            raise SpecError(
                spec.file,
                f"system.{k}",
                "is missing: the linear plant/observer needs A and C "
                "(give f, h in [system] and F in [method] for an expression-defined one)",
            )
    if model.F is None or table.has("L"):
        L = table.matrix("L", rows=n, cols=s.p, vector_as="column").q
    else:
        L = None
    if model.nonlinear and not table.has("P"):
        raise table.error(
            "P",
            "is missing: with f, h or F expressions give the Lyapunov data P, rho and mu (Assumption 2); "
            "inequality (5) is then checked on samples",
        )
    P = mu = lam = rho = None
    if table.has("P"):
        if table.has("lambda"):
            raise table.error(
                "lambda", "give either lambda (P computed) or P, rho, mu (P given), not both"
            )
        P = table.matrix("P", rows=n, cols=n).q
        if any(P[i, j] != P[j, i] for i in range(n) for j in range(n)):
            raise table.error("P", "expected a symmetric matrix")
        if not check_pd(P):
            raise table.error(
                "P", "expected a positive definite matrix (V(e) = eᵀPe must be positive, eq. (4))"
            )
        rho = table.scalar("rho", min=0, max=1, strict_max=True).q
        mu = table.scalar("mu", min=0).q
    else:
        v = table.scalar("lambda", default=None, min=0, max=1, strict_min=True, strict_max=True)
        lam = None if v is None else v.q
        r = table.scalar("rho", default=None, min=0, max=1, strict_min=True, strict_max=True)
        rho = None if r is None else r.q
        if table.has("mu"):
            raise table.error(
                "mu", "mu is computed when P is computed; give P, rho and mu together to set it"
            )
        if rho is not None and lam is not None and rho < lam * lam:
            raise table.error(
                "rho",
                f"expected rho >= lambda² = {float(lam * lam):g} (the design builds P for the "
                "rate λ and certifies β(v, d) = ρv + μ|d|² for ρ ≥ λ²; for a smaller rho give "
                "lambda <= √rho)",
            )
    X_name, X = _set_ref(table, "X", spec, ("box", "polytope"))
    Xhat_name, Xhat = (None, None)
    if table.has("Xhat"):
        Xhat_name, Xhat = _set_ref(table, "Xhat", spec, ("box", "polytope", "ellipsoid"))
    X0 = _set_ref(table, "X0", spec, ("box", "polytope"))[1] if table.has("X0") else None
    Xhat0 = _set_ref(table, "Xhat0", spec, ("box", "polytope"))[1] if table.has("Xhat0") else None
    if (X0 is None) != (Xhat0 is None):
        raise table.error(
            "X0" if X0 is None else "Xhat0",
            "give both X0 and Xhat0 (initial states and estimates) or neither",
        )
    ct = table.table("c", required=True)
    assert ct is not None
    cm = parse_cmap(ct, n)
    nw = s.nd + s.nv
    dt = table.table("D")
    if dt is None:
        if nw:
            raise table.error(
                "D",
                f"is missing: expected a table with lower/upper bounds of w = (d, v) ({_count(nw)})",
            )
        Dl = Du = np.zeros(0, dtype=object)
    else:
        Dl = dt.vector("lower", n=nw).q
        Du = dt.vector("upper", n=nw).q
        if any(not a <= b for a, b in zip(Dl, Du, strict=True)):
            raise dt.error("upper", "expected lower <= upper in every coordinate")
        dt.done()
    Ul = Uh = np.zeros(0)
    ut = table.table("U")
    if ut is not None:
        Ul = ut.vector("lower", n=s.m).f
        Uh = ut.vector("upper", n=s.m).f
        if np.any(Ul > Uh):
            raise ut.error("upper", "expected lower <= upper in every coordinate")
        ut.done()
    elif model.nonlinear and s.m:
        raise table.error(
            "U",
            f"is missing: expected a table with lower/upper bounds of the input u ({_count(s.m)})",
        )
    eps_min = table.scalar("eps_min", min=0, strict_min=True).q
    em = table.scalar("eps_max", default=None, min=0, strict_min=True)
    eps_max = None if em is None else em.q
    if eps_max is not None and not eps_max > eps_min:
        raise table.error(
            "eps_max", f"expected eps_max > eps_min = {float(eps_min):g} (Assumption 3)"
        )
    g = table.scalar("gamma", default=None, min=0, strict_min=True)
    unc = table.bool("gamma_uncertified", default=False)
    margin = table.scalar("margin", default=fmpq(1, 10**9), min=0).q
    tol = table.scalar("rate_tol", default=fmpq(1, 10000), min=0, strict_min=True).q
    table.done()
    o = Options(
        L,
        lam,
        rho,
        P,
        mu,
        X_name,
        X,
        Xhat_name,
        Xhat,
        cm,
        Dl,
        Du,
        eps_min,
        eps_max,
        None if g is None else g.q,
        unc,
        margin,
        tol,
        X0,
        Xhat0,
        spec.file,
    )
    o.model, o.U_lower, o.U_upper = model, Ul, Uh
    return o


def _count(k: int, what: str = "number") -> str:
    """ "k numbers", "1 number" ("1 numbers" in three messages; re-check trial, session 41)."""
    return f"{k} {what}{'' if k == 1 else 's'}"


def _set_ref(table: Table, key: str, spec: Spec, kinds: tuple[str, ...]) -> tuple[str, ConvexSet]:
    name = table.str(key)
    if name not in spec.sets:
        known = ", ".join(sorted(spec.sets)) or "none"
        raise table.error(
            key, f"expected the name of a set in [sets] (known: {known}); got {name!r}"
        )
    S = spec.sets[name]
    if S.kind not in kinds and not (S.kind == "symmetric-polytope" and "polytope" in kinds):
        raise table.error(
            key, f"expected a set of type {' or '.join(kinds)}; [sets.{name}] is {_a(S.kind)}"
        )
    n = spec.system.n
    if S.dim != n:
        # X, X̂, X0 and X̂0 are sets of states: a 1-D box [−1, 1] given with dim = 1 for a
        # 2-state plant was broadcast by numpy over both coordinates and certified v_min
        # = 1.027 where the 2-D box gives 0.908 (a false certificate, re-check trial,
        # session 41); other dimensions were exit 3
        raise table.error(
            key, f"expected a set of the state dimension {n}; [sets.{name}] has dimension {S.dim}"
        )
    return name, S


def parse_cmap(t: Table, n: int) -> ConstraintMap:
    """``[method.c]``: the constraint map of Assumption 3 (box (19), ellipsoid (18), polytope)."""
    kind = t.str("type")
    if kind not in KINDS:
        raise t.error(
            "type",
            f"expected one of {', '.join(KINDS)} (each gives a convex c, Assumption 3(3)); got {kind!r}",
        )
    norm = t.str("norm", default="euclidean", choices=("euclidean", "max"))
    if kind == "box":
        lo = t.vector("lower", n=n).q
        hi = t.vector("upper", n=n).q
        for i in range(n):
            if not lo[i] < hi[i]:
                raise t.error("upper", f"expected lower < upper in every coordinate (index {i})")
        cm = box_map(lo, hi, norm)
    elif kind == "polytope":
        G = t.matrix("G", cols=n).q
        h = t.vector("h", n=G.shape[0]).q
        verts, bounded = vertices_exact(G, np.asarray(h, dtype=object))
        if len(verts) == 0 or not bounded:
            raise t.error("G", "expected a non-empty bounded polytope {x : G x <= h} for C_0")
        cm = polytope_map(G, np.asarray(h, dtype=object), norm)
    else:
        Qm = t.matrix("Q", rows=n, cols=n).q
        if any(Qm[i, j] != Qm[j, i] for i in range(n) for j in range(n)):
            raise t.error("Q", "expected a symmetric matrix")
        if not check_pd(Qm):
            raise t.error(
                "Q",
                "expected a positive definite Q: otherwise c of eq. (18) is not convex (Assumption 3(3))",
            )
        r = t.scalar("r", min=0, strict_min=True).q
        cm = ellipsoid_map(Qm, r)
    t.done()
    return cm


def parse_simulate(table: Table, spec: Spec) -> SimOptions:
    """``[simulate]`` keys of this method: theta_m (int or list), gamma, saturation_r,
    time_limit (Section 5 / Table 1 and eq. (29) of the constrained-redesign paper, Astolfi et al.,
    NOLCOS 2019).

    :param table: the raw ``[simulate]`` table; :param spec: the spec (for n). Returns the
    options; the spec is not modified."""
    out = SimOptions()
    if table.has("theta_m"):
        v = table.data["theta_m"]
        vals = v if isinstance(v, list) else [v]
        if not vals or not all(
            isinstance(x, int) and not isinstance(x, bool) and x >= 0 for x in vals
        ):
            raise table.error("theta_m", "expected a non-negative integer or a list of them")
        big = [x for x in vals if x > INT_MAX]
        if big:  # as every integer key (the schema said so and the loader took it; re-check 46)
            raise table.error(
                "theta_m", f"expected integers of at most 2^63 − 1, got {value_text(big[0])}"
            )
        table.mark("theta_m")
        out.theta_m = [int(x) for x in vals]
    g = table.scalar("gamma", default=None, min=0, strict_min=True)
    out.gamma = None if g is None else g.q
    if table.has("saturation_r"):
        out.saturation_r = table.vector("saturation_r").f
        if len(out.saturation_r) not in (1, spec.system.n) or np.any(out.saturation_r <= 0):
            raise table.error(
                "saturation_r",
                f"expected a positive number or {_count(spec.system.n, 'positive number')}",
            )
    out.time_limit = parse_time_limit(table)
    return out


def default_Xhat(cm: ConstraintMap, eps_min: Any) -> ConvexSet:
    """X̂ when not given: the outer set of C_min, {φ_i ≤ t} with t ≥ √ε_min rational (a box for
    the box map, a polytope for a polytope map, an ellipsoid for the ellipsoid map); it contains
    C_min (Assumption 3(1))."""
    from obsdesign.certify.interval import sqrt_upper

    t = sqrt_upper(Q(eps_min))
    t = _short_up(t)
    if cm.kind == "box":
        n = cm.dim
        lo = np.array([-cm.h_q[2 * i] - t for i in range(n)], dtype=object)
        hi = np.array([cm.h_q[2 * i + 1] + t for i in range(n)], dtype=object)
        return Box(lo, hi)
    if cm.affine:
        return Polytope(cm.G_q, np.array([h + t for h in cm.h_q], dtype=object))
    return Ellipsoid(
        cm.Q_q * (1 / (Q(cm.r_q) * (1 + t))), np.array([fmpq(0)] * cm.dim, dtype=object)
    )


def _short_up(t: fmpq) -> fmpq:
    """A short rational ≥ t (12 significant digits), so the default X̂ prints nicely."""
    from obsdesign.methods.constrained.bounds import round_sig

    return round_sig(t, 12, up=True)


def options_schema(key: str) -> dict[str, Any]:
    """JSON schema of ``[method]`` (the shared NUM / VEC / MAT / EXPRS fragments)."""
    from obsdesign.spec.schema import BOUND, EXPRS, MAT, NUM, VEC

    bounds = {
        "type": "object",
        "required": ["lower", "upper"],
        "additionalProperties": False,
        "properties": {"lower": BOUND, "upper": BOUND},
    }
    return table_schema(
        key,
        {
            "L": MAT,
            "lambda": {**NUM, "exclusiveMinimum": 0, "exclusiveMaximum": 1},
            "rho": {**NUM, "minimum": 0, "exclusiveMaximum": 1},
            "P": MAT,
            "mu": {**NUM, "minimum": 0},
            "X": {"type": "string"},
            "Xhat": {"type": "string"},
            "X0": {"type": "string"},
            "Xhat0": {"type": "string"},
            "eps_min": {**NUM, "exclusiveMinimum": 0},
            "eps_max": {**NUM, "exclusiveMinimum": 0},
            "gamma": {**NUM, "exclusiveMinimum": 0},
            "gamma_uncertified": {"type": "boolean"},
            "margin": {**NUM, "minimum": 0},
            "rate_tol": {**NUM, "exclusiveMinimum": 0},
            "c": {
                "type": "object",
                "required": ["type"],
                "additionalProperties": False,
                "properties": {
                    "type": {"enum": list(KINDS)},
                    "norm": {"enum": ["euclidean", "max"]},
                    "lower": BOUND,
                    "upper": BOUND,
                    "G": MAT,
                    "h": VEC,
                    "Q": MAT,
                    "r": {**NUM, "exclusiveMinimum": 0},
                },
            },
            "D": bounds,
            "U": bounds,
            "F": {**EXPRS, "description": "observer map x̂⁺ = F(x̂, u, y) (x1_hat…, u1…, y1…)"},
        },
        ("X", "c", "eps_min"),
    )


def simulate_schema() -> dict[str, Any]:
    """JSON-schema properties of the method's own ``[simulate]`` keys."""
    from obsdesign.spec.schema import NUM, VEC

    return {
        "theta_m": {
            "anyOf": [
                {"type": "integer", "minimum": 0},
                {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 1},
            ],
            "description": "refining steps per sample (one modified observer per value)",
        },
        "gamma": {**NUM, "exclusiveMinimum": 0, "description": "simulation-only γ"},
        "saturation_r": {
            "anyOf": [
                {**NUM, "exclusiveMinimum": 0},
                {**VEC, "items": {**NUM, "exclusiveMinimum": 0}},
            ],
            "description": "level r of the saturated observer (29)",
        },
        "time_limit": TIME_LIMIT_SCHEMA,
    }


def _a(word: str) -> str:
    """``word`` with its indefinite article ("an ellipsoid", "a box")."""
    return ("an " if word[:1] in "aeiou" else "a ") + word
