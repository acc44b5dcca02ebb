"""obsdesign: observer design with exact certificates.

    >>> import obsdesign
    >>> r = obsdesign.design("specs/constrained-redesign-sec5-lyapunov.toml")
    >>> [c.status.value for c in r.claims]

The heavy modules (numpy, cvxpy, scipy) load on first use, so ``obsdesign --help`` is fast.
"""

from __future__ import annotations

from typing import Any

__version__ = "0.1.0"


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
