"""Typed models of a spec: the plant, the sets, the method options, the simulation scenario."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from obsdesign.sets.base import ConvexSet
from obsdesign.spec.reader import Table, Value
from obsdesign.spec.signals import Signal


@dataclass
class System:
    """``[system]``: x⁺ = A x + B u + Bd d (or ẋ = ...), y = C x + D u + Dn v.

    ``d`` is the disturbance input, ``v`` the measurement noise. Unused inputs have zero
    columns.
    """

    time: str
    A: Value
    B: Value
    C: Value
    D: Value
    Bd: Value
    Dn: Value
    sample_time: Value | None
    states: list[str]
    parameters: dict[str, Value] = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.A.shape[0]

    @property
    def p(self) -> int:
        return self.C.shape[0]

    @property
    def m(self) -> int:
        return self.B.shape[1]

    @property
    def nd(self) -> int:
        return self.Bd.shape[1]

    @property
    def nv(self) -> int:
        return self.Dn.shape[1]

    @property
    def discrete(self) -> bool:
        return self.time == "discrete"


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


@dataclass
class Spec:
    """A whole spec file, validated. ``options`` is the method's own typed options object."""

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

    def set(self, name: str) -> ConvexSet:
        return self.sets[name]
