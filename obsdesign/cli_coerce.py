"""Command-line values coerced without pydantic (cold start, issue 12 item 3).

typer ≥ 0.2x coerces every command-line value through a pydantic ``TypeAdapter`` built per
parameter when a command runs; importing pydantic and building the adapters costs ~150 ms of
a ~0.5 s cold ``obsdesign design``. :class:`FastParam` coerces the values of the plain types
this CLI declares (a str, a Path, a decimal int within min/max, an enum member or its name;
``--timeout`` is a str read by its callback since session 44, so no float option is left)
to what pydantic gives; anything else, and every value typer would refuse, goes through
typer's own adapter, so results and error messages are typer's. Installed by
:func:`obsdesign.cli._fast_runtime_param`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from typer import _coercion

#: "take typer's own path" (see :func:`fast_value`)
SLOW = object()


def fast_leaf(ann: Any, info: Any, value: Any, param: Any, ctx: Any) -> Any:
    """``value`` coerced to ``ann`` as typer's pydantic adapter would, for the plain cases
    (a str, a Path, a decimal int within min/max, an enum member or its name); ``SLOW``
    for anything else, which typer then handles itself, with its own error message."""
    from enum import Enum

    from typer import _param_types as pt

    if ann is str:
        return value if type(value) is str else SLOW
    if ann is int and not info.clamp:
        if type(value) is str:
            digits = value.removeprefix("-")
            if not (digits.isascii() and digits.isdigit() and len(digits) <= 18):
                return SLOW
            value = int(value)
        if type(value) is not int:
            return SLOW
        if (info.min is not None and value < info.min) or (
            info.max is not None and value > info.max
        ):
            return SLOW
        return value
    if isinstance(ann, type) and issubclass(ann, Enum):
        try:
            return pt.coerce_cli_choice(
                value, choices=tuple(ann), case_sensitive=info.case_sensitive, ctx=ctx
            )
        except ValueError:
            return SLOW
    if isinstance(ann, type) and issubclass(ann, Path) and info.path_type is None:
        if type(value) is str:
            value = ann(value)  # what pydantic's Path validator returns for a str
        if not isinstance(value, ann):
            return SLOW
        try:
            return pt.coerce_cli_path(value, info, path_type=ann, param=param, ctx=ctx)
        except Exception:  # noqa: BLE001 - typer's own path raises its own message
            return SLOW
    return SLOW


def fast_value(desc: Any, value: Any, param: Any, ctx: Any) -> Any:
    """A command-line value coerced without pydantic where :func:`fast_leaf` can (lists
    item by item, as typer's list adapter does), else ``SLOW``."""
    from typing import get_args, get_origin

    info = desc.parameter_info
    if info.parser is not None or desc.file_annotation is not None:
        return SLOW
    if get_origin(desc.annotation) is list and isinstance(value, (list, tuple)):
        (item,) = get_args(desc.annotation)
        out = [fast_leaf(item, info, v, param, ctx) for v in value]
        return SLOW if any(o is SLOW for o in out) else out
    return fast_leaf(desc.annotation, info, value, param, ctx)


class FastParam(_coercion.RuntimeParam):
    """typer's runtime parameter with the direct path first (a plain subclass of its frozen
    dataclass: creating a dataclass costs milliseconds)."""

    def __init__(self, descriptor: Any) -> None:
        super().__init__(descriptor.parameter_info, descriptor.annotation)
        object.__setattr__(self, "descriptor", descriptor)  # frozen dataclass

    def _coerce_value(self, value: Any, param: Any, ctx: Any) -> Any:
        out = fast_value(self.descriptor, value, param, ctx)  # type: ignore[attr-defined]
        if out is SLOW:
            slow = _coercion.build_runtime_param(self.descriptor)  # type: ignore[attr-defined]
            out = slow._coerce_value(value, param=param, ctx=ctx)
        return out
