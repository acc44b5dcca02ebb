"""Ctrl-C that is never lost in a command body.

Python's own handler only raises KeyboardInterrupt in the main thread at the next bytecode,
and that exception can vanish before it reaches :func:`obsdesign.cli._run`: C code that
runs Python callbacks and clears their errors (attribute and dict lookups, finalizers)
drops it, so ``obsdesign check`` once ran every spec to the end and exited 0 after a Ctrl-C.
:func:`handler` therefore also *records* the interrupt; the CLI checks the record between
specs (:func:`check`) and when the command body returns, so a recorded Ctrl-C always ends
in exit 130. A native solver that installs its own SIGINT handler while it runs (SCS) is
covered in :func:`obsdesign.lmi.solve`.
"""

from __future__ import annotations

_requested = False


def handler(signum: int, frame: object) -> None:
    """SIGINT handler of a command body: record the interrupt, then raise as Python does."""
    global _requested
    _requested = True
    raise KeyboardInterrupt


def requested() -> bool:
    """Whether :func:`handler` ran since the last :func:`reset`."""
    return _requested


def reset() -> None:
    """Forget a recorded interrupt (at the start of each command body)."""
    global _requested
    _requested = False


def check() -> None:
    """Raise KeyboardInterrupt when an interrupt was recorded (call between units of work)."""
    if _requested:
        raise KeyboardInterrupt
