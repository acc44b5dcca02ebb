"""The ``[method]`` keys of the ``lyapunov`` method (typed options and their parser)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q
from obsdesign.certify.psd import check_pd, check_psd
from obsdesign.simulate.budget import DEFAULT_LIMIT, TIME_LIMIT_SCHEMA, parse_time_limit
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table


@dataclass
class Options:
    """Typed ``[method]`` of ``lyapunov`` (field order kept: callers build it positionally).

    ``L``: the exact n×p gain, or None to design it; ``rate``: the λ (discrete) / α
    (continuous) asked for, or None for the best one found; ``rate_tol``: width of the
    best-rate bracket; ``rate_cap``: the largest α tried when designing L in continuous time;
    ``iss_gain``: also certify the ISS gain μ; ``margin``: δ of the strict checks M ⪰ δ·I;
    ``design``: how L is designed when omitted (``riccati`` default, ``place``, ``lmi``);
    ``riccati_Q`` / ``riccati_R``: the Riccati weights (None: identity); ``poles``: the
    closed-loop poles of ``place`` (None: the stated defaults of :mod:`.design`).
    """

    L: np.ndarray | None
    rate: fmpq | None
    rate_tol: fmpq
    rate_cap: fmpq
    iss_gain: bool
    margin: fmpq
    design: str = "riccati"
    riccati_Q: np.ndarray | None = None
    riccati_R: np.ndarray | None = None
    poles: np.ndarray | None = None


#: the gain designs of ``design = ...`` (L omitted)
DESIGNS = ("riccati", "place", "lmi")


def _poles_meet_the_rate(table: Any, poles: Any, rate: Any, discrete: bool) -> None:
    """Refuse poles that the asked rate excludes: the placed A − LC has them as eigenvalues,
    and a rate λ (α) needs every eigenvalue with |z| < λ (Re z < −α), Section 5 of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019). Before, the design ran and
    blamed the plant's conditioning (exit 4; random-spec fuzzer)."""
    key = "lambda" if discrete else "alpha"
    slow = [z for z in poles if (abs(z) >= rate if discrete else z >= -rate)]
    if slow:
        need = (
            f"|pole| < {key} = {float(rate):g}"
            if discrete
            else f"poles < −{key} = {-float(rate):g}"
        )
        raise table.error(
            "poles",
            f"pole {float(slow[0]):g} cannot meet {key} = {float(rate):g} (A − LC has it as an "
            f"eigenvalue; {need} are needed): give faster poles or a "
            # a slower discrete rate is a larger λ (it said "a smaller lambda" in both times;
            # soundness trial, session 32)
            f"{'larger' if discrete else 'smaller'} {key}",
        )


def _poles_placeable(table: Any, poles: Any, C: Any) -> None:
    """Refuse a pole repeated more than rank(C) times: pole placement (the dual of placing
    the eigenvalues of A − BK with B = Cᵀ) can give an eigenvalue at most rank(C) independent
    eigenvectors, and scipy's place_poles refuses it (exit 4 before — lyapunov review).

    :param table: ``[method]``; :param poles: the exact poles; :param C: the exact C."""
    if C is None:
        return
    from flint import fmpq_mat

    Ca = np.asarray(C, dtype=object)
    rank = fmpq_mat(Ca.shape[0], Ca.shape[1], [Q(v) for v in Ca.ravel()]).rank()
    counts: dict[Any, int] = {}
    for z in poles:
        counts[Q(z)] = counts.get(Q(z), 0) + 1
    over = [z for z, k in counts.items() if k > rank]
    if over:
        raise table.error(
            "poles",
            f"repeats the pole {float(over[0]):g} {counts[over[0]]} times, more than rank(C) = "
            f"{rank}: placement cannot give it that many independent eigenvectors; make the "
            "poles distinct",
        )


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
    design = table.str("design", default="riccati", choices=DESIGNS)
    if L is not None:
        for k in ("design", "riccati_Q", "riccati_R", "poles", "rate_cap"):
            if table.has(k):
                raise table.error(k, "designs L: omit L, or omit this key")
    if table.has("rate_cap") and (s.discrete or design != "lmi"):
        # it caps the continuous LMI gain search only; accepted and ignored before (review)
        raise table.error(
            "rate_cap",
            'is used by the continuous-time LMI gain design only (design = "lmi", '
            'time = "continuous"): omit it',
        )
    if table.has("rate_cap") and rate is not None:
        # an asked α is solved directly, no bisection to cap (alpha = 4 with rate_cap = 1
        # certified α_best = 4.9 silently: review 19)
        raise table.error(
            "rate_cap",
            "caps the LMI bisection for the best rate, which does not run with an asked "
            "alpha: omit rate_cap or alpha",
        )
    keys = {"riccati": ("riccati_Q", "riccati_R"), "place": ("poles",), "lmi": ()}
    for k in ("riccati_Q", "riccati_R", "poles"):
        if table.has(k) and k not in keys[design]:
            raise table.error(k, f"is not used by design = {design!r}")
    wq = wr = poles = None
    if table.has("riccati_Q"):
        wq = table.matrix("riccati_Q", rows=s.n, cols=s.n).q
        if not all(wq[i, j] == wq[j, i] for i in range(s.n) for j in range(s.n)):
            raise table.error("riccati_Q", "expected a symmetric matrix")
        if not check_psd(wq).ok:  # the Riccati weights' premise, exactly (exit 4 before)
            raise table.error("riccati_Q", "expected a positive semidefinite matrix")
    if table.has("riccati_R"):
        wr = table.matrix("riccati_R", rows=s.p, cols=s.p).q
        if not all(wr[i, j] == wr[j, i] for i in range(s.p) for j in range(s.p)):
            raise table.error("riccati_R", "expected a symmetric matrix")
        if not check_pd(wr).ok:
            raise table.error("riccati_R", "expected a positive definite matrix")
    if table.has("poles"):
        poles = table.vector("poles", n=s.n).q
        if s.discrete and any(abs(z) >= 1 for z in poles):
            raise table.error("poles", "expected poles of modulus < 1 in discrete time")
        if not s.discrete and any(z >= 0 for z in poles):
            raise table.error("poles", "expected negative poles in continuous time")
        if rate is not None:
            _poles_meet_the_rate(table, poles, rate.q, s.discrete)
        _poles_placeable(table, poles, s.C.q if s.C is not None else None)
    table.done()
    return Options(
        L,
        None if rate is None else rate.q,
        tol.q,
        cap.q,
        iss,
        margin.q,
        design,
        wq,
        wr,
        poles,
    )


@dataclass
class SimOptions:
    """The ``lyapunov`` method's own ``[simulate]`` keys: ``runs`` Monte Carlo runs (None, not
    given: the spec's single scenario; 1 is one Monte Carlo run, run 0 of any N) and
    ``initial_error``, the name of a set of ``[sets]`` each run draws its initial error
    x̂0 − x0 from (None: xhat0 − x0 for every run)."""

    runs: int | None = None
    initial_error: str | None = None
    #: seconds the simulation may run (exit 3 past it)
    time_limit: float = DEFAULT_LIMIT


def parse_simulate(table: Table, spec: Spec) -> SimOptions:
    """``[simulate] runs`` and ``initial_error`` (a set of ``[sets]`` of dimension n, see
    :func:`obsdesign.simulate.montecarlo.parse_initial_error`); never mutates the spec.

    :param table: the ``[simulate]`` table; :param spec: the spec."""
    from obsdesign.simulate.montecarlo import parse_initial_error

    runs = table.int("runs", default=None, min=1)
    ie = parse_initial_error(table, spec)
    return SimOptions(runs, ie, parse_time_limit(table))


def simulate_schema() -> dict[str, Any]:
    """JSON-schema properties of the ``lyapunov`` method's own ``[simulate]`` keys."""
    return {
        "runs": {"type": "integer", "minimum": 1},
        "initial_error": {"type": "string"},
        "time_limit": TIME_LIMIT_SCHEMA,
    }


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
            "design": {"enum": list(DESIGNS)},
            "riccati_Q": MAT,
            "riccati_R": MAT,
            "poles": {"type": "array", "items": NUM},
        },
    }
