"""Design methods, one module each, all following :class:`obsdesign.methods.base.Method`.

The registry maps a spec's ``[method] key`` to ``module:attribute``; modules are imported
lazily so the CLI starts fast.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from obsdesign.methods.base import Method

REGISTRY: dict[str, str] = {
    "lyapunov": "obsdesign.methods.lyapunov:METHOD",
    "constrained": "obsdesign.methods.constrained:METHOD",
    "impulsive": "obsdesign.methods.impulsive:METHOD",
    "set-invariant": "obsdesign.methods.setinvariant:METHOD",
    "search-space": "obsdesign.methods.searchspace:METHOD",
    "stubborn": "obsdesign.methods.stubborn:METHOD",
}


def method_keys() -> list[str]:
    """The method keys this build knows."""
    return sorted(REGISTRY)


def get_method(key: str) -> Method:
    """The method object for ``key`` (KeyError if unknown)."""
    mod, attr = REGISTRY[key].split(":")
    return getattr(importlib.import_module(mod), attr)
