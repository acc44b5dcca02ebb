"""Lyapunov data of Assumption 2, constrained-redesign paper (Astolfi, Bernard, Postoyan,
Marconi, NOLCOS 2019): V(e) = eᵀPe (eq. (4)) and β(v, w) = ρ v + μ |w|² (eq. (6)) with
V(Δ(x, e, w)) ≤ β(V(e), w) (eq. (5)).

The linear-observer maths (B_w = [−Bd, L Dn], the ISS block matrix of eq. (5), μ, the decay
matrix, the certified P and the bracketed best rate) is shared with the ``lyapunov`` method in
:mod:`obsdesign.lyap`; this module keeps what is specific to ``constrained``: the bound on |w|²
over the box D of w = (d, v).
"""

from __future__ import annotations

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q


def w_sq_max(lower: np.ndarray, upper: np.ndarray) -> fmpq:
    """max over the box D = [lower, upper] of |w|² (exact): the sup of μ|w|² in β of eq. (6),
    used by v_max of eq. (13).

    :param lower: lower bounds of w = (d, v); :param upper: upper bounds."""
    return sum((max(Q(a) ** 2, Q(b) ** 2) for a, b in zip(lower, upper, strict=True)), fmpq(0))
