"""The method contract: every design method offers the same few things.

- ``parse_options(table, spec)``: its ``[method]`` section as a typed options object
  (raising :class:`SpecError` on bad input);
- ``design(spec)``: solvers → :class:`Design` (parameters, solver info, notes);
- ``certify(spec, params)``: the list of :class:`Claim` recomputed from the spec and the
  parameters only (exact arithmetic where the claim says *certified*). ``design`` and
  ``verify`` both call it; it never looks at solver output or stored statuses;
- ``simulate(spec, params)``: plant + observer over the spec's scenario (optional);
- ``template()``: a commented spec template (``obsdesign init KEY``);
- ``options_schema()``: JSON schema of its ``[method]`` section (``obsdesign schema``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from obsdesign.errors import InputError

if TYPE_CHECKING:
    from obsdesign.certify.claim import Claim
    from obsdesign.params import Parameters
    from obsdesign.simulate.result import SimResult
    from obsdesign.spec.models import Spec
    from obsdesign.spec.reader import Table

Progress = Callable[[str], None]


@dataclass
class Design:
    """What ``design`` returns: parameters (exact where certified), solver info and notes."""

    parameters: Parameters
    solver: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


class Method(ABC):
    """Base class of the design methods (one module each under ``obsdesign.methods``)."""

    key: str = ""
    title: str = ""
    paper: str = ""
    #: top-level spec tables (besides system/sets/method/simulate) this method reads
    extra_tables: tuple[str, ...] = ()

    @abstractmethod
    def parse_options(self, table: Table, spec: Spec) -> Any:
        """Typed options from ``[method]``; call ``table.done()`` at the end."""

    @abstractmethod
    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        """Compute the observer parameters (floats from solvers, rounded to exact values)."""

    @abstractmethod
    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        """Recompute every claim from spec + parameters; exact where it says certified."""

    def parse_simulate(self, table: Table, spec: Spec) -> Any:
        """Method-specific keys of ``[simulate]`` (none by default)."""
        return None

    def simulate(self, spec: Spec, params: Parameters, **kwargs: Any) -> SimResult:
        """Run plant + observer over the spec's ``[simulate]`` scenario."""
        raise InputError(f"method '{self.key}' has no simulation")

    def summary(self, params: Parameters) -> str:
        """One short line of the key results, for the ``check`` table."""
        return ""

    def template(self) -> str:
        """A commented spec template for ``obsdesign init``."""
        return ""

    def options_schema(self) -> dict[str, Any]:
        """JSON schema of the ``[method]`` table."""
        return {"type": "object", "properties": {"key": {"const": self.key}}}
