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
- ``plant_expressions``: the expression keys of ``[system]`` (``f``, ``psi``, ``h``, ``u``)
  the method reads or diagnoses itself; the API refuses the others (exit 2), so that no
  certificate silently ignores part of the plant;
- ``required_params``: parameters a report must carry (checked once, generically, before
  ``certify`` runs);
- ``summary_fields``: what ``summary()`` shows (label, parameter, format), with
  ``summary_format`` the format of the fields that name none;
- ``sim_options``: the ``--option KEY=VALUE`` keys of ``simulate`` (validated centrally);
- ``plot_design`` / ``plot_simulation``: plot hooks, None when the method has none.

Implemented by each method's package, found by the base class's defaults (override them only
where the facade must decide something itself): ``options.parse_options(table, spec) ->
Options``, ``options.parse_simulate(table, spec) -> SimOptions`` (when ``SimOptions`` is
declared; returns, never mutates the spec), ``options.options_schema(key)`` and
``options.simulate_schema()``, ``design.design(spec, progress) -> Design``,
``claims.certify(spec, params) -> list[Claim]`` (never looks at solver output or stored
statuses), ``sim.simulate(spec, params, **options)``.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, ClassVar

from obsdesign.errors import InputError, value_text
from obsdesign.limits import INT_MAX

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
    """One item of the one-line summary: ``label = value`` with ``value`` (each entry of a
    vector or matrix) formatted by ``fmt`` (a format spec such as ``.6g``; None: the method's
    ``summary_format``); skipped when the parameter is absent. ``param`` defaults to the
    label."""

    label: str
    param: str = ""
    fmt: str | None = None
    #: "up" when the statements stay true with a larger value in its place (an upper bound
    #: such as v_max, T_min), "down" when with a smaller one (T_max, γ): a rounded value is
    #: then shown rounded that way, "label ≤ text" / "label ≥ text", never on its unsafe
    #: side ("T_max ≈ 2.476e-07" for T_max = 2.4755274e-7; soundness trial, session 32)
    side: str = ""

    def __post_init__(self) -> None:
        if not self.param:
            object.__setattr__(self, "param", self.label)


def _nonzero_text(text: str) -> bool:
    """Whether a number's text is exactly nonzero (``1e-400``, which floats read as 0)."""
    from decimal import Decimal, InvalidOperation

    try:
        return not Decimal(text.strip().replace("_", "")).is_zero()
    except InvalidOperation:
        return False


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
                if v == 0 and _nonzero_text(text):
                    # gamma=1e-400 said "expected a positive number, got 0.0" (CLI review,
                    # session 44); -1e-400 passed a min = 0 as −0.0
                    raise InputError(
                        f"{what}: {text.strip()} is below the float range (it would read as 0)"
                    )
            elif self.kind == "bool":
                low = text.strip().lower()
                if low not in ("true", "false", "1", "0", "yes", "no"):
                    raise ValueError
                v = low in ("true", "1", "yes")
            elif self.kind == "path":
                if not text.strip():
                    # Path("") is ".": "sampling_file=" read the working directory and said
                    # ".: is a directory" (CLI review, session 40)
                    raise ValueError
                v = Path(text)
            else:
                v = text
        except ValueError:
            raise InputError(f"{what}: expected {_KIND[self.kind]}, got {text!r}") from None
        self._in_range(what, v, repr(text), text)
        return v

    def _in_range(self, what: str, v: Any, shown: str, number: str) -> None:
        """``choices`` / ``min`` / ``max`` of a parsed or given value (``shown`` / ``number``:
        how the message quotes it)."""
        if self.choices is not None and v not in self.choices:
            raise InputError(f"{what}: expected one of {', '.join(self.choices)}, got {shown}")
        if self.kind == "int" and self.name != "seed" and abs(v) > INT_MAX:  # numpy takes any seed
            # max_centres = 10**400 reached a float conversion: exit 4 blaming the spec's
            # numbers (API review, session 44)
            raise InputError(f"{what}: expected an integer of at most 2^63 − 1, got {number}")
        if self.min is not None and v < self.min:
            raise InputError(f"{what}: expected a value >= {self.min:g}, got {number}")
        if self.max is not None and v > self.max:
            raise InputError(f"{what}: expected a value <= {self.max:g}, got {number}")

    def check_value(self, v: Any) -> Any:
        """A typed value given to :func:`obsdesign.api.simulate` as a keyword, checked as
        :meth:`parse` checks a text: ``time_limit='x'`` was a bare ValueError, ``-1`` ran out
        of time at once (exit 3 where the CLI says exit 2) and NaN ran without a limit
        (hostile-input trial, session 38). A text is parsed as ``--option`` parses it; numbers
        may be any real type (numpy, Decimal, Fraction, a 0-d array; an integer option takes
        3.0, a true/false one 0 and 1), and one beyond the float range or a NaN is an
        InputError; a ``str`` option takes any value, as before (``theta_m=10``; re-check
        trials, session 38).
        Returns the value (a number as int / float, a path as a Path)."""
        import decimal
        import numbers
        import os

        import numpy as np

        what = f"simulate: {self.name}"
        if isinstance(v, str) and self.kind not in ("str", "path"):
            try:
                return self.parse(v)
            except InputError as e:
                raise InputError(str(e).replace(f"--option {self.name}", what, 1)) from None
        if isinstance(v, np.ndarray) and v.ndim == 0:
            v = v.item()
        number = isinstance(v, (numbers.Real, decimal.Decimal, bool, np.bool_))
        try:
            # 10**400 overflows and Decimal('sNaN') refuses float(): bare errors before
            f = float(v) if number else math.nan
        except (OverflowError, ValueError):
            f = math.nan
        if self.kind == "float" and number and f == 0 and not isinstance(v, float):
            try:
                tiny = v != 0  # an exact value (Decimal, Fraction) that floats read as 0
            except (ArithmeticError, TypeError):
                tiny = False
            if tiny:  # gamma=Decimal('1e-400') said "got 0.0" (re-check review, session 44)
                raise InputError(f"{what}: {v!r} is below the float range (it would read as 0)")
        whole = isinstance(v, numbers.Integral) and not isinstance(v, (bool, np.bool_))

        def exactly(g: int) -> bool:
            # the value itself, not its double: seed=Decimal('1E-400') ran with seed 0 and
            # Fraction(10**20 + 1, 10**20) with seed 1 (re-check review 45)
            try:
                return bool(v == g)
            except (ArithmeticError, TypeError):
                return False

        exact_int = _exact_integer(v)  # a whole Decimal or Fraction, of any size
        if self.kind == "int" and exact_int is not None:
            out: Any = exact_int
        elif self.kind == "int" and (
            whole
            or (
                number
                and not isinstance(v, (bool, np.bool_))  # seed=True ran as seed 1 (45)
                and math.isfinite(f)
                and f == int(f)
                and exactly(int(f))
            )
        ):
            out = int(v) if whole else int(f)
        elif self.kind == "float" and number and math.isfinite(f):
            out = f
        elif self.kind == "bool" and number and f in (0.0, 1.0) and exactly(int(f)):
            out = bool(f)
        elif self.kind == "str":
            out = v
        elif (
            self.kind == "path"
            and isinstance(v, (str, os.PathLike))
            and "\0" not in os.fspath(v)
            and os.fspath(v).strip()
        ):
            out = Path(v)
        else:
            raise InputError(f"{what}: expected {_KIND[self.kind]}, got {value_text(v)}")
        if self.kind in ("int", "float"):
            self._in_range(what, out, value_text(v), value_text(v))
        elif self.choices is not None and out not in self.choices:
            raise InputError(
                f"{what}: expected one of {', '.join(self.choices)}, got {value_text(v)}"
            )
        return out


_KIND = {
    "int": "an integer",
    "float": "a finite number",
    "bool": "true or false",
    "str": "a string",
    "path": "a path",
}


class Method:
    """Base class of the design methods (one package each under ``obsdesign.methods``).

    The defaults of ``parse_options``, ``parse_simulate``, ``design``, ``certify``,
    ``simulate``, ``options_schema`` and ``simulate_schema`` delegate to the modules of the
    method's package (see the module docstring), imported on first use."""

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
    #: expression keys of ``[system]`` (f, psi, h, u) this method reads or diagnoses itself
    plant_expressions: ClassVar[frozenset[str]] = frozenset()
    #: parameters every report of this method carries (checked before ``certify``)
    required_params: ClassVar[tuple[str, ...]] = ()
    #: what ``summary()`` prints, and the format of the fields that give none
    summary_fields: ClassVar[tuple[SummaryField, ...]] = ()
    summary_format: ClassVar[str] = ".6g"
    #: ``simulate --option`` keys
    sim_options: ClassVar[tuple[SimOption, ...]] = ()
    #: a run's grid is ``[simulate]`` horizon / dt steps (discrete time: horizon), so its
    #: length is known from the spec before the run (``simulate --plot`` refuses a long one
    #: then); False where the grid follows the method's own sampling instead
    sim_grid_from_dt: ClassVar[bool] = True
    #: plot hooks: ``plot_design(spec, params, path)``, ``plot_simulation(spec, result, path)``
    plot_design: Callable[..., Any] | None = None
    plot_simulation: Callable[..., Any] | None = None

    def part(self, name: str) -> ModuleType:
        """The module ``name`` (``options``, ``design``, ``claims``, ``sim``) of the method's
        package, imported on first use."""
        pkg = type(self).__module__.rsplit(".", 1)[0]
        return importlib.import_module(f"{pkg}.{name}")

    def parse_options(self, table: Table, spec: Spec) -> Any:
        """Typed options from ``[method]`` (``options.parse_options``, which calls
        ``table.done()`` at the end)."""
        return self.part("options").parse_options(table, spec)

    def parse_simulate(self, table: Table, spec: Spec) -> Any:
        """The method's own ``[simulate]`` keys as its ``SimOptions`` (``options.parse_simulate``;
        None when the method declares no ``SimOptions``). Returns the options; never mutates the
        spec."""
        if self.SimOptions is None:
            return None
        return self.part("options").parse_simulate(table, spec)

    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        """Compute the observer parameters (floats from solvers, rounded to exact values):
        ``design.design``."""
        return self.part("design").design(spec, progress)

    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        """Recompute every claim from spec + parameters; exact where it says certified
        (``claims.certify``).

        Anything the spec fixes is read from the spec (and compared exactly with the report's
        copy, where the report carries one)."""
        return self.part("claims").certify(spec, params)

    def simulate(self, spec: Spec, params: Parameters, **options: Any) -> SimResult:
        """Run plant + observer over the spec's ``[simulate]`` scenario (``sim.simulate``)."""
        try:
            sim = self.part("sim")
        except ModuleNotFoundError as e:
            if e.name != f"{type(self).__module__.rsplit('.', 1)[0]}.sim":
                raise
            raise InputError(f"method '{self.key}' has no simulation") from None
        return sim.simulate(spec, params, **options)

    def sim_run_count(self, runs: int, options: dict[str, Any]) -> int:
        """The runs a simulation with these typed ``simulate`` options makes, for messages
        (default: ``runs``, the option's or the spec's).

        :param runs: the run count asked; :param options: the typed options."""
        return runs

    def sim_bytes(self, spec: Spec, runs: int, steps: float, options: dict[str, Any]) -> float:
        """Bytes a simulation of ``runs`` runs × ``steps`` steps needs, estimated before
        anything is allocated (checked by the API against ``max_sim_bytes``). Default: every
        run's trajectories are kept (plant, estimate, error, output, input per step).

        :param spec: the bound spec; :param runs: runs; :param steps: steps per run;
        :param options: the typed ``simulate`` options."""
        s = spec.system
        return 8.0 * float(runs) * (steps + 1.0) * sim_width(s)

    # -- generic parts ----------------------------------------------------------------------
    def summary(self, params: Parameters) -> str:
        """One short line of the key results (from ``summary_fields``): scalars formatted, a
        vector or matrix as ``[a, b; c, d]`` (rows separated by ';'); ``label ≈ …`` when the
        decimal shown is not the value held (:mod:`obsdesign.report.shown`: "κ = 2, κ_n = 2"
        for κ = 1.99999185 < κ_n = 1.99999385 read as condition (22) failing; rendering
        trial, session 27)."""
        from obsdesign.report.shown import item

        out = []
        for f in self.summary_fields:
            if f.param not in params:
                continue
            fmt = f.fmt or self.summary_format
            raw = params[f.param]
            try:
                if isinstance(raw, (bool, str, bytes)):
                    raise TypeError("not a number")
                out.append(item(f.label, raw, params.float(f.param), fmt, f.side))
            except (TypeError, ValueError):
                out.append(f"{f.label} = {raw}")
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
        """JSON schema of the ``[method]`` table (``options.options_schema(key)``)."""
        return self.part("options").options_schema(self.key)

    def simulate_schema(self) -> dict[str, Any]:
        """JSON-schema properties of the method's own ``[simulate]`` keys
        (``options.simulate_schema()``; none when the method declares no ``SimOptions``)."""
        if self.SimOptions is None:
            return {}
        return self.part("options").simulate_schema()


def table_schema(
    key: str, properties: dict[str, Any], required: tuple[str, ...] = ()
) -> dict[str, Any]:
    """JSON schema of a method's ``[method]`` table: ``key`` (the method's key, always
    required) and the method's own ``properties`` (``required`` besides ``key``), no other
    key.

    :param key: the method key; :param properties: JSON-schema properties of the other keys;
    :param required: the keys besides ``key`` a spec must give."""
    return {
        "type": "object",
        "required": ["key", *required],
        "additionalProperties": False,
        "properties": {"key": {"const": key}, **properties},
    }


def _did_you_mean(word: str, known: list[str]) -> str:
    import difflib

    m = difflib.get_close_matches(word, known, n=1)
    return f" (did you mean '{m[0]}'?)" if m else ""


def sim_width(s: Any) -> int:
    """Floats a run keeps per step: the plant, estimate, error and stepped state (4n), the
    output (p), and the signals u, d, v twice (as drawn, then joined for the step: 2(m + r +
    q)), plus 2. The disturbance and noise channels were left out, and a spec with 100 of each
    took 3.2 GB against an 88 MB estimate (simulate trial, session 27)."""
    return int(4 * s.n + s.p + 2 * (s.m + s.nd + s.nv) + 2)


def _exact_integer(v: Any) -> int | None:
    """``v`` as an int when it is a whole Decimal or Fraction (its double may not be: a seed
    of Decimal(2**60 + 1) was refused as "expected an integer", re-check review 45), else
    None. A Decimal past 10^4300 is not expanded (Decimal('1E+999999999') would build a
    billion-digit int): None, so the value is refused by the checks that follow."""
    import decimal
    from fractions import Fraction

    if isinstance(v, Fraction):
        return int(v) if v.denominator == 1 else None
    if isinstance(v, decimal.Decimal):
        if not v.is_finite() or v.adjusted() > 4300:
            return None
        if v == v.to_integral_value():
            return int(v)
    return None
