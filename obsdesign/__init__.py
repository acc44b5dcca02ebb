"""obsdesign: observer design with exact certificates.

    >>> import obsdesign
    >>> r = obsdesign.design("specs/constrained-redesign-sec5-lyapunov.toml")
    >>> [c.status.value for c in r.claims]

The heavy modules (numpy, cvxpy, scipy) load on first use, so ``obsdesign --help`` is fast.
"""

from __future__ import annotations

import _signal  # the C module: ``signal`` itself spends milliseconds building its enums
import os as _os
import sys as _sys


def _early_interrupt(signum: int, frame: object) -> None:  # pragma: no cover - timing
    """Ctrl-C while the command line starts (imports of typer, rich, numpy): one line,
    exit 130, no traceback. :func:`obsdesign.cli._run` restores Python's handler when a
    command body starts, so that cleanup code (temporary files) runs on Ctrl-C."""
    try:  # stderr closed or full: the line is dropped, the code stays 130 (session 34)
        _sys.stderr.write("obsdesign: error: interrupted\n")  # the wording of cli._err
        _sys.stderr.flush()
    except (OSError, ValueError, AttributeError):
        pass
    _os._exit(130)


# Installed here, the first obsdesign code the console script runs (``from obsdesign.cli
# import main`` imports this package first). Only Python's own start-up before any obsdesign
# code (the interpreter, site.py and the .pth files of site-packages) and the few bytecodes of
# this file above the ``if`` (three C-module imports, a def, a constant) can still show a
# traceback on Ctrl-C.
#: set (to "1") in the environment of the Dask worker processes the command line starts
#: (:func:`obsdesign.distributed.client`): they ignore Ctrl-C, which the terminal sends to the
#: whole process group, and the command that started them shuts them down; with the handler
#: below each printed its own "obsdesign: interrupted" (outsider trial, session 22)
WORKER_ENV = "OBSDESIGN_DASK_WORKER"
# the handler first, then the worker's override: the environment lookup before it left a
# window where a Ctrl-C printed a traceback ending in this file (re-check review, session 42)
if _signal.getsignal(_signal.SIGINT) is _signal.default_int_handler and _os.path.basename(
    _sys.argv[0] if _sys.argv else ""
) in ("obsdesign", "cli.py", "-m"):  # "-m": ``python -m obsdesign`` importing this package
    _signal.signal(_signal.SIGINT, _early_interrupt)
if _os.environ.get(WORKER_ENV) == "1":
    _signal.signal(_signal.SIGINT, _signal.SIG_IGN)

# after the handler: ``typing`` takes milliseconds to import, and a Ctrl-C there printed a
# traceback ending in this file (re-check review, session 42)
from typing import TYPE_CHECKING, Any  # noqa: E402

__version__ = "0.1.0"


if TYPE_CHECKING:  # the real signatures for type checkers and IDEs (outsider trial)
    from obsdesign.api import check, design, load_spec, simulate, verify
    from obsdesign.interop import observer_statespace, spec_from_statespace
else:  # at run time thin wrappers: ``import obsdesign`` stays light (``--help`` is fast)

    def design(*args: Any, **kwargs: Any) -> Any:
        """See :func:`obsdesign.api.design`."""
        from obsdesign import api

        return api.design(*args, **kwargs)

    def verify(*args: Any, **kwargs: Any) -> Any:
        """See :func:`obsdesign.api.verify`."""
        from obsdesign import api

        return api.verify(*args, **kwargs)

    def simulate(*args: Any, **kwargs: Any) -> Any:
        """See :func:`obsdesign.api.simulate`."""
        from obsdesign import api

        return api.simulate(*args, **kwargs)

    def check(*args: Any, **kwargs: Any) -> Any:
        """See :func:`obsdesign.api.check`."""
        from obsdesign import api

        return api.check(*args, **kwargs)

    def load_spec(*args: Any, **kwargs: Any) -> Any:
        """See :func:`obsdesign.api.load_spec`."""
        from obsdesign.api import load_spec as _load

        return _load(*args, **kwargs)

    def spec_from_statespace(*args: Any, **kwargs: Any) -> Any:
        """See :func:`obsdesign.interop.spec_from_statespace` (needs ``obsdesign[control]``)."""
        from obsdesign.interop import spec_from_statespace as _from

        return _from(*args, **kwargs)

    def observer_statespace(*args: Any, **kwargs: Any) -> Any:
        """See :func:`obsdesign.interop.observer_statespace` (needs ``obsdesign[control]``)."""
        from obsdesign.interop import observer_statespace as _obs

        return _obs(*args, **kwargs)


def __getattr__(name: str) -> Any:
    """``obsdesign.sweep``: the module :mod:`obsdesign.sweep`, imported on first use and
    callable as :func:`obsdesign.api.sweep` (``obsdesign.sweep(spec, grid, client=None)``).
    A function of that name here would be replaced by the submodule on its import."""
    if name == "sweep":
        import importlib

        return importlib.import_module("obsdesign.sweep")
    raise AttributeError(f"module 'obsdesign' has no attribute {name!r}")
