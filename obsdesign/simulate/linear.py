"""The linear observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) (or its continuous analogue)."""

from __future__ import annotations

import numpy as np

from obsdesign.simulate.result import SimResult
from obsdesign.simulate.runner import run_continuous, run_discrete
from obsdesign.spec.models import Spec


def simulate_linear_observer(spec: Spec, L: np.ndarray) -> SimResult:
    """Simulate the linear Luenberger observer with gain L against the spec's plant."""
    s = spec.system
    A, B, C, D = s.A.f, s.B.f, s.C.f, s.D.f
    L = np.asarray(L, dtype=float).reshape(s.n, s.p)

    def innovation(xh: np.ndarray, y: np.ndarray, u: np.ndarray) -> np.ndarray:
        return A @ xh + B @ u + L @ (y - C @ xh - D @ u)

    if s.discrete:
        return run_discrete(spec, lambda k, xh, y, u: innovation(xh, y, u))
    return run_continuous(spec, lambda t, xh, y, u: innovation(xh, y, u))
