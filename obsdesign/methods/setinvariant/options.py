"""The ``[method]`` keys of ``set-invariant`` (Dórea & Pimenta, "Design of set-invariant
estimators for linear discrete-time systems"): typed options and their parser.

Sets are declared under ``[sets]`` and referenced by name: Ω (``omega``, state dimension) and
the disturbance set D (``disturbance``, declared with ``dim`` = columns of ``B1``, e.g.
``[sets.D] type = "box"; dim = 1; lower = [-1]; upper = [1]``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.errors import SpecError
from obsdesign.sets import Box, Polytope
from obsdesign.simulate.budget import DEFAULT_LIMIT, TIME_LIMIT_SCHEMA, parse_time_limit
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

ALGORITHMS = ("symmetric", "general", "none")
FALLBACKS = ("general", "none")
LAWS = ("interpolated", "time-varying", "online-lp", "linear")


@dataclass
class Options:
    """Typed ``[method]`` of ``set-invariant``.

    ``omega``: name of Ω in ``[sets]``; ``disturbance`` / ``D``: name and set of D (None when
    the system has no disturbance input); ``eta_bar``: noise bound η̄; ``lam``: contraction
    rate λ; ``algorithm``: symmetric (Section VI), general (Section V) or none (check Ω);
    ``delta_tol``: Δδ of the stopping rule; ``max_iterations``; ``mirror``: also add the
    mirrored images (general algorithm); ``strict``: the certified factor must be ≤ λ;
    ``fallback``: what follows a symmetric C_K^∞ that fails Theorem 3.1; ``L``: a linear gain
    to certify (n×p, exact); ``linear_law``: compute the admissible linear gains (p = n − 1);
    ``time_limit``: seconds the design may run (default :data:`TIME_LIMIT`): past it (checked
    between slices, LP blocks, iterations and breakpoints of the exact Theorem 3.1 check; a
    cdd.gmp hull runs in a child process killed at the deadline) it stops with "not
    converged within N s / K iterations" or "exact certificate not started / not finished
    within N s" (exit 3).
    """

    omega: str
    disturbance: str | None
    D: Box | Polytope | None
    eta_bar: fmpq
    lam: fmpq
    algorithm: str
    delta_tol: fmpq
    max_iterations: int
    mirror: bool
    strict: bool
    fallback: str
    L: np.ndarray | None
    linear_law: bool
    time_limit: float = 45.0


#: default time budget of a design, in seconds (``[method] time_limit``): the float
#: iterations and the exact stage check it; a cdd.gmp hull runs in a child process it kills
TIME_LIMIT = 45.0


def _spec_error(spec: Spec, key: str, expected: str) -> SpecError:
    return SpecError(spec.file, key, expected)


def _named_set(table: Table, spec: Spec, key: str, kinds: tuple[type, ...], what: str) -> Any:
    name = table.str(key)
    if name not in spec.sets:
        raise table.error(key, f"expected the name of a set in [sets]; got {name!r}")
    s = spec.sets[name]
    if not isinstance(s, kinds):
        raise table.error(key, f"expected a box or (symmetric-)polytope set ({what})")
    return name, s


def parse_disturbance(table: Table, spec: Spec) -> tuple[str | None, Box | Polytope | None]:
    """``disturbance``: the name of the set D in ``[sets]`` (dimension = columns of B1, given
    with ``dim``). The old spelling, an inline table in ``[method]``, is refused in one line
    naming the new place."""
    nd = spec.system.nd
    if not table.has("disturbance"):
        if nd > 0:
            raise table.error(
                "disturbance",
                f"expected the name of the disturbance set D in [sets] (the system has B1 with "
                f"{nd} column(s); declare [sets.D] with dim = {nd})",
            )
        return None, None
    if not isinstance(table.data["disturbance"], str):
        raise table.error(
            "disturbance",
            f'has moved: declare D under [sets.D] with dim = {max(nd, 1)} and write disturbance = "D"',
        )
    name, D = _named_set(table, spec, "disturbance", (Box, Polytope), "D must be a polyhedron")
    if nd == 0:
        raise table.error(
            "disturbance",
            "the system has no disturbance input B1: remove disturbance (or give [system] B1)",
        )
    if D.dim != nd:
        raise table.error(
            "disturbance",
            f"expected a set of dimension {nd} (columns of B1), got [sets.{name}] of "
            f"dimension {D.dim}",
        )
    return name, D


def _check_noise_map(spec: Spec) -> None:
    s = spec.system
    if s.p == 0:
        return
    Dn = np.asarray(s.Dn.q, dtype=object)
    # the shape first: a 2×1 Dn (two outputs, one noise channel) was an IndexError, exit 3
    # (shape review, session 41)
    square = Dn.shape == (s.p, s.p)
    eye = square and all(Dn[i, j] == (1 if i == j else 0) for i in range(s.p) for j in range(s.p))
    if not eye:
        raise _spec_error(
            spec,
            "system.Dn",
            "expected the identity (the noise is η in z = C e + η, |η| <= eta_bar)",
        )


def parse_options(table: Table, spec: Spec) -> Options:
    """Typed options from ``[method]`` (see :class:`Options`); the output count decides which
    results apply: one output (Theorem 3.1, Proposition 4.1) or p = n − 1 outputs without noise
    (Proposition 7.1, symmetric algorithm)."""
    from .problem import omega_rows

    s = spec.system
    if not s.discrete:
        raise _spec_error(
            spec, "system.time", "expected time = 'discrete' (the method is discrete-time)"
        )
    omega, om = _named_set(table, spec, "omega", (Box, Polytope), "Ω must be a polyhedron")
    if om.dim != s.n:  # a set with an explicit dim other than n (it was exit 3 in numpy)
        raise table.error(
            "omega",
            f"expected a set of dimension {s.n} (the states), got [sets.{omega}] of dimension "
            f"{om.dim}",
        )
    try:
        omega_rows(om)
    except ValueError as e:
        raise table.error("omega", f"Ω: {e}") from None
    dist, D = parse_disturbance(table, spec)
    eta = table.scalar("eta_bar", default=fmpq(0), min=0).q
    _check_noise_map(spec)
    lam = table.scalar("lambda", min=0, max=1, strict_min=True).q
    algorithm = table.str("algorithm", default="symmetric", choices=ALGORITHMS)
    dtol = table.scalar("delta_tol", default=fmpq(1, 10**6), min=0, strict_min=True).q
    maxit = table.int("max_iterations", default=100, min=1)
    mirror = table.bool("mirror", default=False)
    strict = table.bool("strict", default=True)
    fallback = table.str("fallback", default="general", choices=FALLBACKS)
    L = table.matrix("L", rows=s.n, cols=s.p, vector_as="column").q if table.has("L") else None
    linear_law = table.bool("linear_law", default=True)
    time_limit = float(
        table.scalar("time_limit", default=fmpq(int(TIME_LIMIT)), min=0, strict_min=True).q
    )
    if s.p != 1:
        if s.p != s.n - 1:
            raise _spec_error(
                spec,
                "system.C",
                f"has {s.p} outputs with n = {s.n} states: Theorem 3.1 and Proposition 4.1 cover "
                "single-output systems and Proposition 7.1 covers p = n − 1 outputs (linear law); "
                "this system is neither",
            )
        if eta != 0:
            raise table.error(
                "eta_bar",
                f"expected 0: with p = {s.p} = n − 1 outputs only Proposition 7.1 applies, and "
                "it assumes no noise",
            )
        if algorithm != "symmetric":
            raise table.error(
                "algorithm",
                f"expected 'symmetric': with p = {s.p} > 1 outputs only the symmetric algorithm "
                "and the linear law (Proposition 7.1) apply",
            )
        if not linear_law and L is None:
            # the piecewise-affine table (Proposition 4.1) needs one output: without the
            # linear law and without a given L nothing could certify an injection
            raise table.error(
                "linear_law",
                f"expected true (or a given [method] L): with p = {s.p} > 1 outputs the linear "
                "law of Proposition 7.1 is the only injection law (the piecewise-affine table "
                "needs one output)",
            )
    table.done()
    return Options(
        omega=omega,
        disturbance=dist,
        D=D,
        eta_bar=eta,
        lam=lam,
        algorithm=algorithm,
        delta_tol=dtol,
        max_iterations=maxit,
        mirror=mirror,
        strict=strict,
        fallback=fallback,
        L=L,
        linear_law=linear_law,
        time_limit=time_limit,
    )


def options_schema(key: str) -> dict[str, Any]:
    """JSON schema of ``[method]`` (``obsdesign schema``)."""
    num = {"type": "number"}
    mat = {"type": "array", "items": {"anyOf": [num, {"type": "array", "items": num}]}}
    return {
        "type": "object",
        "required": ["key", "omega", "lambda"],
        "additionalProperties": False,
        "properties": {
            "key": {"const": key},
            "omega": {"type": "string", "description": "name of the initial-error set Ω in [sets]"},
            "disturbance": {
                "type": "string",
                "description": "name of the disturbance set D in [sets] (with dim = columns of B1)",
            },
            "eta_bar": {**num, "minimum": 0},
            "lambda": {**num, "exclusiveMinimum": 0, "maximum": 1},
            "algorithm": {"enum": list(ALGORITHMS)},
            "delta_tol": {**num, "exclusiveMinimum": 0},
            "max_iterations": {"type": "integer", "minimum": 1},
            "mirror": {"type": "boolean"},
            "strict": {"type": "boolean"},
            "fallback": {"enum": list(FALLBACKS)},
            "L": mat,
            "linear_law": {"type": "boolean"},
            "time_limit": {
                **num,
                "exclusiveMinimum": 0,
                "description": "seconds the design may run (default 45)",
            },
        },
    }


@dataclass
class SimOptions:
    """The method's own ``[simulate]`` key: ``time_limit``, the seconds the simulation may run
    (exit 3 past it; the ``online-lp`` law solves LP (9) of Dórea and Pimenta (CDC-ECC 2005)
    at every step, so a long horizon ran for hours)."""

    time_limit: float = DEFAULT_LIMIT


def parse_simulate(table: Table, spec: Spec) -> SimOptions:
    """``[simulate] time_limit`` (> 0, default 300 s).

    :param table: the ``[simulate]`` table; :param spec: the spec (unused)."""
    return SimOptions(parse_time_limit(table))


def simulate_schema() -> dict[str, Any]:
    """JSON-schema properties of the method's own ``[simulate]`` keys."""
    return {"time_limit": TIME_LIMIT_SCHEMA}
