"""The method contract: every design method declares the same few things.

A method is a package ``obsdesign/methods/<key>/`` whose ``method.py`` holds one subclass of
:class:`Method` (a thin facade) over ``options.py`` (its typed ``[method]`` / ``[simulate]``
options), ``design.py`` (solvers → parameters), ``claims.py`` (every claim recomputed from spec
+ parameters) and, where it has them, ``sim.py``, ``plots.py`` and ``template.toml``.

Declared by each method (class attributes):

- ``key``, ``title``, ``paper`` (authors, title, venue), ``Options`` / ``SimOptions`` types;
- ``needs_linear``: whether ``[system]`` must give A and C (checked once, by the API);
- ``extra_tables``: top-level tables it reads besides system/sets/method/simulate
  (``nonlinearity``);
- ``required_params``: parameters a report must carry (checked once, generically, before
  ``certify`` runs);
- ``summary_fields``: what ``summary()`` shows (label, parameter, format);
- ``sim_options``: the ``--option KEY=VALUE`` keys of ``simulate`` (validated centrally);
- ``plot_design`` / ``plot_simulation``: plot hooks, None when the method has none.

Implemented by each method: ``parse_options(table, spec) -> Options``,
``parse_simulate(table, spec) -> SimOptions | None`` (returns, never mutates the spec),
``design(spec, progress) -> Design``, ``certify(spec, params) -> list[Claim]`` (never looks at
solver output or stored statuses), ``simulate(spec, params, **options)``.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from obsdesign.errors import InputError

if TYPE_CHECKING:
    from obsdesign.certify.claim import Claim
    from obsdesign.params import Parameters
    from obsdesign.simulate.result import SimResult
    from obsdesign.spec.models import Spec
    from obsdesign.spec.reader import Table

Progress = Callable[[str], None]


class SolverStatus(StrEnum):
    """How a design's numerical stage ended (in the spirit of cvxpy's status map).

    ``optimal``: the solver reported an optimal point; ``closed_form``: no iterative solver
    (equations, exact formulas); ``inaccurate``: the solver's own accuracy flags were not met;
    ``infeasible``: the solver proved infeasibility; ``failed``: it stopped without an answer.
    """

    OPTIMAL = "optimal"
    CLOSED_FORM = "closed_form"
    INACCURATE = "inaccurate"
    INFEASIBLE = "infeasible"
    FAILED = "failed"


@dataclass
class SolverResult:
    """What the numerical stage says about itself (like SciPy's ``OptimizeResult``)."""

    name: str
    status: SolverStatus
    message: str = ""
    seconds: float | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"name": self.name, "status": self.status.value}
        if self.message:
            d["message"] = self.message
        if self.seconds is not None:
            d["seconds"] = round(self.seconds, 4)
        d.update(self.extra)
        return d


@dataclass
class Design:
    """What ``design`` returns: parameters (exact where certified), solver info and notes."""

    parameters: Parameters
    solver: SolverResult | dict[str, Any] = field(
        default_factory=lambda: SolverResult("none", SolverStatus.CLOSED_FORM)
    )
    notes: list[str] = field(default_factory=list)

    def solver_dict(self) -> dict[str, Any]:
        s = self.solver
        return s.to_dict() if isinstance(s, SolverResult) else dict(s)


@dataclass(frozen=True)
class SummaryField:
    """One item of the one-line summary: ``label = value`` with ``value`` formatted by
    ``fmt`` (a format spec such as ``.6g``); skipped when the parameter is absent."""

    label: str
    param: str
    fmt: str = ".6g"


@dataclass(frozen=True)
class SimOption:
    """A ``simulate --option KEY=VALUE`` key: its type, default, range and help.

    ``kind`` is ``int``, ``float``, ``bool``, ``str`` or ``path``; ``choices`` restricts
    strings; ``min``/``max`` bound numbers (inclusive)."""

    name: str
    kind: str
    default: Any
    help: str
    min: float | None = None
    max: float | None = None
    choices: tuple[str, ...] | None = None

    def parse(self, text: str) -> Any:
        """The option's value from its text, or :class:`InputError` naming the key."""
        what = f"--option {self.name}"
        try:
            if self.kind == "int":
                v: Any = int(text)
            elif self.kind == "float":
                v = float(text)
                if not math.isfinite(v):
                    raise ValueError
            elif self.kind == "bool":
                low = text.strip().lower()
                if low not in ("true", "false", "1", "0", "yes", "no"):
                    raise ValueError
                v = low in ("true", "1", "yes")
            elif self.kind == "path":
                v = Path(text)
            else:
                v = text
        except ValueError:
            raise InputError(f"{what}: expected {_KIND[self.kind]}, got {text!r}") from None
        if self.choices is not None and v not in self.choices:
            raise InputError(f"{what}: expected one of {', '.join(self.choices)}, got {text!r}")
        if self.min is not None and v < self.min:
            raise InputError(f"{what}: expected a value >= {self.min:g}, got {text}")
        if self.max is not None and v > self.max:
            raise InputError(f"{what}: expected a value <= {self.max:g}, got {text}")
        return v


_KIND = {
    "int": "an integer",
    "float": "a finite number",
    "bool": "true or false",
    "str": "a string",
    "path": "a path",
}


class Method(ABC):
    """Base class of the design methods (one package each under ``obsdesign.methods``)."""

    key: ClassVar[str] = ""
    title: ClassVar[str] = ""
    #: authors, title, venue of the paper the method implements
    paper: ClassVar[str] = ""
    #: the typed options of ``[method]`` and of the method's ``[simulate]`` keys
    Options: ClassVar[type | None] = None
    SimOptions: ClassVar[type | None] = None
    #: ``[system]`` must give the linear model (A and C)
    needs_linear: ClassVar[bool] = True
    #: top-level spec tables (besides system/sets/method/simulate) this method reads
    extra_tables: ClassVar[tuple[str, ...]] = ()
    #: parameters every report of this method carries (checked before ``certify``)
    required_params: ClassVar[tuple[str, ...]] = ()
    #: what ``summary()`` prints
    summary_fields: ClassVar[tuple[SummaryField, ...]] = ()
    #: ``simulate --option`` keys
    sim_options: ClassVar[tuple[SimOption, ...]] = ()
    #: plot hooks: ``plot_design(spec, params, path)``, ``plot_simulation(spec, result, path)``
    plot_design: Callable[..., Any] | None = None
    plot_simulation: Callable[..., Any] | None = None

    @abstractmethod
    def parse_options(self, table: Table, spec: Spec) -> Any:
        """Typed options from ``[method]``; call ``table.done()`` at the end."""

    def parse_simulate(self, table: Table, spec: Spec) -> Any:
        """The method's own ``[simulate]`` keys as its ``SimOptions`` (None when it has none).
        Returns the options; never mutates the spec."""
        return None

    @abstractmethod
    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        """Compute the observer parameters (floats from solvers, rounded to exact values)."""

    @abstractmethod
    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        """Recompute every claim from spec + parameters; exact where it says certified.

        Anything the spec fixes is read from the spec (and compared exactly with the report's
        copy, where the report carries one)."""

    def simulate(self, spec: Spec, params: Parameters, **options: Any) -> SimResult:
        """Run plant + observer over the spec's ``[simulate]`` scenario."""
        raise InputError(f"method '{self.key}' has no simulation")

    # -- generic parts ----------------------------------------------------------------------
    def summary(self, params: Parameters) -> str:
        """One short line of the key results (from ``summary_fields``)."""
        out = []
        for f in self.summary_fields:
            if f.param not in params:
                continue
            try:
                v = params.float(f.param)
                out.append(f"{f.label} = {format(v, f.fmt)}")
            except (TypeError, ValueError):
                out.append(f"{f.label} = {params[f.param]}")
        return ", ".join(out)

    def parse_sim_options(self, raw: dict[str, str]) -> dict[str, Any]:
        """``--option KEY=VALUE`` pairs validated against ``sim_options``: an unknown key or a
        bad value is an :class:`InputError` naming the key (and the known keys)."""
        known = {o.name: o for o in self.sim_options}
        out: dict[str, Any] = {}
        for k, text in raw.items():
            if k not in known:
                names = ", ".join(sorted(known)) or "none"
                hint = _did_you_mean(k, list(known))
                raise InputError(
                    f"--option {k}: not an option of method '{self.key}'{hint} (known: {names})"
                )
            out[k] = known[k].parse(text)
        return out

    def template(self) -> str:
        """A commented spec template for ``obsdesign init`` (``template.toml`` beside the
        method's module)."""
        import importlib.resources

        pkg = type(self).__module__.rsplit(".", 1)[0]
        return importlib.resources.files(pkg).joinpath("template.toml").read_text("utf-8")

    def options_schema(self) -> dict[str, Any]:
        """JSON schema of the ``[method]`` table."""
        return {"type": "object", "properties": {"key": {"const": self.key}}}

    def simulate_schema(self) -> dict[str, Any]:
        """JSON-schema properties of the method's own ``[simulate]`` keys."""
        return {}


def _did_you_mean(word: str, known: list[str]) -> str:
    import difflib

    m = difflib.get_close_matches(word, known, n=1)
    return f" (did you mean '{m[0]}'?)" if m else ""
