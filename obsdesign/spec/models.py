"""Typed models of a spec: the plant, the sets, the method options, the simulation scenario."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from obsdesign.sets.base import ConvexSet
from obsdesign.spec.expr import Expr
from obsdesign.spec.frozen import ReadOnlyDict
from obsdesign.spec.reader import Table, Value
from obsdesign.spec.signals import Signal


@dataclass(frozen=True)
class System:
    """``[system]``: the one home of the plant.

    Linear data: x⁺ = A x + B u + Bd d (or ẋ = ...), y = C x + D u + Dn v; ``d`` is the
    disturbance input, ``v`` the measurement noise; unused inputs have zero columns.
    Expressions (vectors of :class:`~obsdesign.spec.expr.Expr` over :attr:`variables`):
    ``f`` the whole right-hand side (x⁺ or ẋ), or ``psi`` an additive term
    (x⁺ or ẋ = A x + B u + Bd d + ψ); ``h`` the whole output map; ``u_signal`` an open-loop
    input u(t). A and C are None when only expressions describe the plant.

    Dimensions, fixed when the spec is read: ``n`` states and ``p`` outputs (given by A and
    C, or counted from ``f`` / ``states`` and ``h``), and ``m``, ``nd``, ``nv``, the numbers of
    inputs u, disturbance inputs d and noise inputs v (the columns of B, Bd and Dn).
    """

    time: str
    A: Value | None
    B: Value
    C: Value | None
    D: Value
    Bd: Value
    Dn: Value
    sample_time: Value | None
    states: list[str]
    n: int
    p: int
    parameters: dict[str, Value] = field(default_factory=dict)
    f: list[Expr] | None = None
    psi: list[Expr] | None = None
    h: list[Expr] | None = None
    u_signal: list[Expr] | None = None
    m: int = field(init=False)
    nd: int = field(init=False)
    nv: int = field(init=False)

    def __post_init__(self) -> None:
        # frozen: a field assigned in place (spec.system.A = …) kept the object, so the
        # binding check saw the same system and the impulsive options certified the old A
        # (re-check review, session 43); replace the system (dataclasses.replace) instead
        for k, v in (("m", self.B.shape[1]), ("nd", self.Bd.shape[1]), ("nv", self.Dn.shape[1])):
            object.__setattr__(self, k, v)
        if not isinstance(self.parameters, ReadOnlyDict):  # as each Expr's (session 44)
            object.__setattr__(self, "parameters", ReadOnlyDict(self.parameters))

    @property
    def discrete(self) -> bool:
        return self.time == "discrete"

    @property
    def linear(self) -> bool:
        """A and C given and no expression in the plant."""
        return self.A is not None and self.C is not None and not (self.f or self.psi or self.h)

    @property
    def inputs(self) -> list[str]:
        return [f"u{i + 1}" for i in range(self.m)]

    @property
    def disturbances(self) -> list[str]:
        return [f"d{i + 1}" for i in range(self.nd)]

    @property
    def noises(self) -> list[str]:
        return [f"v{i + 1}" for i in range(self.nv)]

    @property
    def variables(self) -> list[str]:
        """Variables of ``f`` / ``psi`` / ``h``: states, u1.., d1.., v1.., t."""
        return [*self.states, *self.inputs, *self.disturbances, *self.noises, "t"]

    def exact_parameters(self) -> dict[str, Any]:
        return {k: v.q for k, v in self.parameters.items()}


@dataclass
class SimulateSpec:
    """``[simulate]``: horizon (samples in discrete time, seconds in continuous time),
    initial states, and the input, disturbance and noise scenarios."""

    horizon: Value
    dt: Value | None
    x0: Value
    xhat0: Value
    u: Signal
    disturbance: Signal
    noise: Signal
    seed: int
    table: Table
    #: what the method's ``parse_simulate`` returned for its own ``[simulate]`` keys
    options: Any = None
    #: the ``dt`` the spec gave when it does not divide the horizon (``dt`` is then
    #: horizon / ⌈horizon / dt⌉, so that the grid ends at the horizon); None otherwise
    dt_given: Value | None = None


@dataclass
class Spec:
    """A whole spec file, validated in its generic parts.

    The spec layer knows no method: ``method_table`` is the raw ``[method]`` table and
    ``tables`` the raw top-level tables a method may read (``nonlinearity``). The API binds the
    method (:func:`obsdesign.api.bind`), which fills ``options`` (the method's typed options)
    and ``simulate.options``.
    """

    file: str
    text: str
    sha256: str
    title: str
    system: System
    sets: dict[str, ConvexSet]
    method: str
    options: Any
    simulate: SimulateSpec | None
    tables: dict[str, Table] = field(default_factory=dict)
    method_table: Table | None = None
    #: what ``options`` were parsed from (:func:`obsdesign.api.bind`): the system and sets
    #: objects; a spec whose system or a set was replaced since (``copy.copy`` then
    #: ``spec.system = …``, ``dataclasses.replace``) is bound again
    bound_to: tuple[Any, ...] | None = field(default=None, repr=False, compare=False)
    #: what ``text`` describes: :meth:`read_state` as the loader built it, and after binding
    #: the options object with its fields (``api.bind``); ``api.design`` refuses a spec that
    #: differs from it, since the report embeds ``text`` (API review, session 44)
    origin: tuple[Any, ...] | None = field(default=None, repr=False, compare=False)
    bound_options: tuple[Any, list[tuple[str, Any]]] | None = field(
        default=None, repr=False, compare=False
    )
    #: the input limits (:class:`obsdesign.limits.Limits`) in force when the loader read
    #: ``text``: ``verify`` of a report object designed from this spec re-reads the embedded
    #: text with them raised, as the object was accepted under them (a spec read under
    #: ``max_digits = 3000``, designed after the limits were reset or in a spawned process,
    #: gave design exit 0 and verify exit 2; API review 46)
    read_limits: Any = field(default=None, repr=False, compare=False)

    def read_state(self) -> tuple[tuple[str, Any], ...]:
        """The fields read from the text, each as an object (compared by identity): what a
        replaced system or set, an edited text or method key, or a set put into a shared
        ``sets`` dict (``copy.copy`` shares it) changes."""
        return (
            ("text", self.text),
            ("sha256", self.sha256),
            ("[system]", self.system),
            # its lists too: System is frozen, its lists are not (f[0] = another Expr)
            (
                "[system] expressions or state names",
                tuple(
                    tuple(getattr(self.system, k) or ())
                    for k in ("states", "f", "psi", "h", "u_signal")
                ),
            ),
            ("[sets]", tuple(sorted(self.sets.items(), key=lambda kv: kv[0]))),
            ("[method] key", self.method),
            ("[method]", self.method_table),
            ("[simulate]", self.simulate),
            ("tables", tuple(self.tables.items())),
        )

    def changed_since_read(self) -> str | None:
        """What differs from what the text describes (``None``: nothing, or a spec not made
        by the loader): the name of the first field replaced since loading, or the options
        (replaced, or a field of them assigned) since binding."""
        if self.origin is not None:
            for (name, was), (_, now) in zip(self.origin, self.read_state(), strict=True):
                if not _same(was, now):
                    return name
        if self.bound_options is not None:
            o, parts = self.bound_options
            if self.options is not o:
                return "[method] options"
            now = option_parts(o)
            if [k for k, _ in now] != [k for k, _ in parts]:
                return "[method] options"
            for (k, v), (_, w) in zip(parts, now, strict=True):
                if not _same(v, w):
                    return f"[method] option {k!r}"
        for name in ("f", "psi", "h", "u_signal"):
            for i, e in enumerate(getattr(self.system, name) or ()):
                if not e.intact():  # its tree edited in place (re-check review, session 44)
                    return f"[system.{name}][{i}] expression"
        return None

    def binding(self) -> tuple[Any, ...]:
        """The objects the method's options are parsed from: the system and every set (by
        identity; see ``bound_to``)."""
        return (self.system, *sorted(self.sets.items(), key=lambda kv: kv[0]))

    def set(self, name: str) -> ConvexSet:
        return self.sets[name]


def option_parts(obj: Any) -> list[tuple[str, Any]]:
    """Every part of a method's options as (path, object): the fields, and within them the
    fields of nested dataclasses, list and tuple items and dict values (numpy arrays, which
    are read-only, and expressions, which check themselves, are leaves). ``api.design``
    compares them by identity with those at binding: a field of a nested object assigned
    (the impulsive ``options.problem.w_bar = 0``) designed exit 0 with claims false for the
    embedded text (re-check review, session 44)."""
    out: list[tuple[str, Any]] = []
    stack: list[tuple[str, Any, int]] = [("", obj, 0)]
    while stack:
        path, x, depth = stack.pop()
        if depth > 8 or isinstance(x, (np.ndarray, Expr, str, bytes)):
            continue
        if dataclasses.is_dataclass(x) and not isinstance(x, type):
            items = [(f.name, getattr(x, f.name, None)) for f in dataclasses.fields(x)]
        elif isinstance(x, (list, tuple)):
            items = [(str(i), v) for i, v in enumerate(x)]
            out.append((f"{path}#len", len(x)))
        elif isinstance(x, dict):
            items = [(str(k), v) for k, v in x.items()]
            out.append((f"{path}#len", len(x)))
        elif hasattr(x, "__dict__") and depth == 0:
            items = list(vars(x).items())
        else:
            continue
        for k, v in items:
            sub = f"{path}.{k}" if path else k
            out.append((sub, v))
            stack.append((sub, v, depth + 1))
    return out


def _same(a: Any, b: Any) -> bool:
    """Identity, through tuples (the sets and tables as (name, object) pairs); equal values
    of one immutable scalar type count as the same (a pickle does not keep the identity of
    an int or a float: every unpickled set-invariant spec was refused)."""
    if a is b:
        return True
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if type(a) is type(b) and isinstance(a, (bool, int, float, complex, str, bytes)):
        return bool(a == b) or (a != a and b != b)  # NaN is itself
    return False
