"""The ``[method]`` keys of the ``lyapunov`` method (typed options and their parser)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


@dataclass
class Options:
    """Typed ``[method]`` of ``lyapunov`` (field order kept: callers build it positionally).

    ``L``: the exact n×p gain, or None to design it; ``rate``: the λ (discrete) / α
    (continuous) asked for, or None for the best one found; ``rate_tol``: width of the
    best-rate bracket; ``rate_cap``: the largest α tried when designing L in continuous time;
    ``iss_gain``: also certify the ISS gain μ; ``margin``: δ of the strict checks M ⪰ δ·I.
    """

    L: np.ndarray | None
    rate: fmpq | None
    rate_tol: fmpq
    rate_cap: fmpq
    iss_gain: bool
    margin: fmpq


def parse_options(table: Table, spec: Spec) -> Options:
    """:class:`Options` from ``[method]``; λ in (0, 1) is discrete-only, α > 0
    continuous-only (the other one is an error naming the key).

    :param table: the ``[method]`` table; :param spec: the spec (its ``[system]`` is parsed)."""
    s = spec.system
    L = None
    if table.has("L"):
        L = table.matrix("L", rows=s.n, cols=s.p, vector_as="column").q
    if s.discrete:
        rate = table.scalar("lambda", default=None, min=0, max=1, strict_min=True, strict_max=True)
        if table.has("alpha"):
            raise table.error("alpha", "is for continuous time; use lambda in discrete time")
    else:
        rate = table.scalar("alpha", default=None, min=0, strict_min=True)
        if table.has("lambda"):
            raise table.error("lambda", "is for discrete time; use alpha in continuous time")
    tol = table.scalar("rate_tol", default=fmpq(1, 10000), min=0, strict_min=True)
    cap = table.scalar("rate_cap", default=fmpq(10), min=0, strict_min=True)
    iss = table.bool("iss_gain", default=False)
    margin = table.scalar("margin", default=fmpq(1, 10**9), min=0)
    table.done()
    return Options(L, None if rate is None else rate.q, tol.q, cap.q, iss, margin.q)


def schema(key: str) -> dict[str, Any]:
    """JSON schema of the ``[method]`` table of ``lyapunov``.

    :param key: the method key (``const`` of ``key``)."""
    from obsdesign.spec.schema import MAT, NUM

    return {
        "type": "object",
        "required": ["key"],
        "additionalProperties": False,
        "properties": {
            "key": {"const": key},
            "L": MAT,
            "lambda": {**NUM, "exclusiveMinimum": 0, "exclusiveMaximum": 1},
            "alpha": {**NUM, "exclusiveMinimum": 0},
            "rate_tol": {**NUM, "exclusiveMinimum": 0},
            "rate_cap": {**NUM, "exclusiveMinimum": 0},
            "iss_gain": {"type": "boolean"},
            "margin": {**NUM, "minimum": 0},
        },
    }
