"""The ``lyapunov`` method (a linear observer with a certified quadratic Lyapunov function).

- :mod:`.options` the ``[method]`` keys; :mod:`.design` gain, P, best rate, μ;
- :mod:`.claims` the certificate; :mod:`.method` the Method object; ``template.toml``.

The Lyapunov maths itself is shared, in :mod:`obsdesign.lyap`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from obsdesign import lyap
from obsdesign.lyap import certified_P, decay_matrix
from obsdesign.methods.lyapunov.method import METHOD
from obsdesign.methods.lyapunov.options import Options


def best_rate(
    A: np.ndarray, C: np.ndarray, L: np.ndarray, discrete: bool, o: Options, limit: float
) -> tuple[Any, np.ndarray]:
    """Transitional: the old ``lyapunov.best_rate`` signature (``constrained`` still calls it);
    use :func:`obsdesign.lyap.best_rate` (explicit numbers, with the bracket) instead."""
    br = lyap.best_rate(A, C, L, discrete, tol=o.rate_tol, margin=o.margin)
    return br.best, br.P


__all__ = ["METHOD", "Options", "best_rate", "certified_P", "decay_matrix"]
