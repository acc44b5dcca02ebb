"""The time grid of a continuous-time simulation: t_k = k·dt, each the double nearest to the
exact product.

``np.arange(0, T + dt/2, dt)`` and ``np.arange(K + 1) * dt`` give k·fl(dt), which drifts above
or below the exact k·dt (12·0.1 → 1.2000000000000002): a signal window [0.3, 1.2] then lost
its last sample at t = 1.2, about a third of the grid points at dt = 0.1 were above their
decimal, and continuous-time metrics changed with it (simulate-correctness trial, session 25).
With every t_k correctly rounded, the inclusive window test fl(start) ≤ t_k ≤ fl(stop) agrees
with the exact start ≤ k·dt ≤ stop whenever the two sides differ by more than the rounding
of one double (rounding is monotone; equal exact values round alike).
"""

from __future__ import annotations

import numpy as np
from flint import fmpq

#: integers up to this are doubles exactly (so k·p and q are, and fl(k·p / q) is one
#: correctly rounded division)
_EXACT_INT = 2**53


def steps_of(horizon: fmpq, dt: fmpq) -> int:
    """K = the horizon over dt rounded to the nearest integer (half up), at least 0: the
    number of steps of the grid 0, dt, …, K·dt.

    :param horizon: the exact horizon; :param dt: the exact step (> 0)."""
    r = horizon / dt
    return max(int((2 * r.p + r.q) // (2 * r.q)), 0)


def time_grid(horizon: fmpq, dt: fmpq) -> np.ndarray:
    """Times t_k = k·dt for k = 0..K (:func:`steps_of`), each the double nearest to the
    exact k·dt: one integer product and one correctly rounded division per point when k·p
    and q (dt = p/q) fit in 53 bits, else k·fl(dt) (a step with more than ~16 significant
    digits, whose grid was never exact in doubles).

    :param horizon: the exact horizon; :param dt: the exact step (> 0)."""
    dt = fmpq(dt)
    K = steps_of(fmpq(horizon), dt)
    p, q = int(dt.p), int(dt.q)
    if K * abs(p) < _EXACT_INT and q < _EXACT_INT:
        return (np.arange(K + 1, dtype=np.int64) * p).astype(float) / float(q)
    return np.arange(K + 1, dtype=float) * float(p / q)
