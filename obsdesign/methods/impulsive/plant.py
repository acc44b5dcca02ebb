"""The plant ẋ = A x + ψ(x) of the impulsive method (eq. (1a), paper 001), vectorized.

ψ is ``[system] psi`` (the safe expression language), evaluated on arrays of states.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from obsdesign.spec.models import Spec

Field = Callable[[np.ndarray], np.ndarray]


def psi_callable(spec: Spec) -> Field:
    """ψ as a vectorized map (N, n) → (N, n) from the spec's ``[system] psi``."""
    assert spec.system.psi is not None
    fs = [e.on(spec.system.states) for e in spec.system.psi]

    def psi(X: np.ndarray) -> np.ndarray:
        return np.stack([f(X) for f in fs], axis=-1)

    return psi


def plant_field(spec: Spec) -> Field:
    """f(x) = A x + ψ(x), vectorized (eq. (1a))."""
    A = spec.system.A.f
    psi = psi_callable(spec)
    return lambda X: X @ A.T + psi(X)
