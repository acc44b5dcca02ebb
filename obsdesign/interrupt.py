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

import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import logging

_requested = False
#: the signal recorded (SIGINT 2, or one of cli._STOP_SIGNALS: SIGTERM 15, SIGHUP 1, ...),
#: 0 when none
_signum = 0


def handler(signum: int, frame: object) -> None:
    """SIGINT / SIGTERM / SIGHUP / ... (cli._STOP_SIGNALS) handler of a command body: record
    the interrupt, then raise KeyboardInterrupt as Python does for SIGINT, so the same
    cleanup runs (temp files removed). SIGTERM (what ``timeout`` sends) killed the process at once and left a hidden
    half-written ``.NAME.XXXX.csv`` beside the output (simulate trial, session 27)."""
    global _requested, _signum, _first_at
    now = time.monotonic()
    if _requested and now - _first_at < REPEAT_GRACE_S:
        # a second stop right after the first (a double Ctrl-C, SIGTERM twice): the first's
        # KeyboardInterrupt is on its way, and raising again could cut the cleanup it runs (a
        # second SIGTERM as write_via's finally began skipped the temp file's removal;
        # re-check trial, session 40); recorded only
        return
    _requested = True
    _signum = signum
    _first_at = now
    if _deferred:
        return  # inside :func:`deferred`: raised when the block ends
    raise KeyboardInterrupt


#: seconds after a stop during which another stop signal is recorded but not raised again
#: (:func:`handler`); later, one is raised again (the first may have been swallowed)
REPEAT_GRACE_S = 1.0
#: ``time.monotonic()`` of the recorded stop
_first_at = 0.0


#: depth of :func:`deferred` blocks open (the handler records but does not raise inside)
_deferred = 0


@contextmanager
def deferred() -> Iterator[None]:
    """A block that a stop must not cut (a temp file's creation up to the ``try`` that removes
    it, and that removal): :func:`handler` only records a signal landing inside, and the block
    raises KeyboardInterrupt as it ends. A stop as the probe of an output folder or the temp
    file of an output appeared left a hidden empty ``.NAME.XXXXXXXX`` behind (4 of 25
    ``design -o`` runs under SIGTERM; CLI trial, session 40). A flag, not a signal mask: a
    process-directed signal that the main thread blocks goes to another thread (rich's
    refresh thread, a Dask thread), and Python runs the handler in the main thread anyway."""
    global _deferred
    before = _requested
    _deferred += 1
    try:
        yield
    finally:
        _deferred -= 1
    if _requested and not before and not _deferred:
        raise KeyboardInterrupt


def requested() -> bool:
    """Whether :func:`handler` ran since the last :func:`reset`."""
    return _requested


def signal_number() -> int:
    """The signal :func:`handler` recorded (0 when none): the exit code is 128 + it."""
    return _signum


def reset() -> None:
    """Forget a recorded interrupt (at the start of each command body)."""
    global _requested, _signum
    _requested = False
    _signum = 0


def check() -> None:
    """Raise KeyboardInterrupt when an interrupt was recorded (call between units of work)."""
    if _requested:
        raise KeyboardInterrupt


def quiet_unraisable(hook: Callable[[Any], object]) -> Callable[[Any], None]:
    """A ``sys.unraisablehook`` that drops the KeyboardInterrupt of a recorded interrupt and
    passes anything else to ``hook``. :func:`handler` raises it wherever the signal lands,
    also in a callback whose exception Python cannot propagate (an import lock's weakref
    callback): Python then printed "Exception ignored in …" with a traceback after
    `check`'s one-line "interrupted" (a full-suite run under load, session 31). The interrupt
    is recorded, so the command still ends with exit 130.

    :param hook: the hook to pass other exceptions to (normally ``sys.unraisablehook``)."""

    def quiet(args: Any) -> None:
        if isinstance(args.exc_value, KeyboardInterrupt) and _requested:
            return
        hook(args)

    return quiet


def install_quiet_unraisable() -> None:
    """Install :func:`quiet_unraisable` over the current ``sys.unraisablehook`` (once), and
    :func:`quiet_after_interrupt` on the loggers of :data:`QUIET_LOGGERS` (once each)."""
    if not getattr(sys.unraisablehook, "_obsdesign_quiet", False):
        q = quiet_unraisable(sys.unraisablehook)
        q._obsdesign_quiet = True  # type: ignore[attr-defined]
        sys.unraisablehook = q
    import logging  # here: `obsdesign --help` does not import it

    for name in QUIET_LOGGERS:
        log = logging.getLogger(name)
        if quiet_after_interrupt not in log.filters:
            log.addFilter(quiet_after_interrupt)


#: loggers that report an interrupt as something else: cvxpy catches what a signal raises
#: inside a solver's import (an extension module's init turns the KeyboardInterrupt into a
#: SystemError) and logs "Encountered unexpected exception importing solver HIGHS" over
#: several lines before the command's one-line "interrupted" (re-check trial, session 34)
QUIET_LOGGERS = ("__cvxpy__",)


def quiet_after_interrupt(record: logging.LogRecord) -> bool:
    """A logging filter: drop every record once an interrupt is recorded (:func:`handler`);
    the command is ending with 128 + the signal and says so itself."""
    return not _requested
