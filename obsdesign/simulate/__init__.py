"""Simulation: plants, scenarios, runners, metrics and plots. Methods plug their observer in
through :func:`run_discrete` / :func:`run_continuous` or their own runner.

This package is also callable: ``obsdesign.simulate(spec, report=None, ...)`` is
:func:`obsdesign.api.simulate`. The package function ``obsdesign.simulate`` is replaced by
this module as soon as any ``obsdesign.simulate.*`` module is imported (Python binds a
subpackage to its parent's attribute), so the module itself must answer the call (the
independent simulate review found the second ``obsdesign.simulate(...)`` raising "'module'
object is not callable")."""

import sys
import types
from typing import Any

from obsdesign.simulate.result import SimResult, metrics
from obsdesign.simulate.runner import run_continuous, run_discrete


class _CallableModule(types.ModuleType):
    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        """See :func:`obsdesign.api.simulate`."""
        from obsdesign import api

        return api.simulate(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule

__all__ = ["SimResult", "metrics", "run_continuous", "run_discrete"]
