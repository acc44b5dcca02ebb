"""Simulation results and the standard metrics: sup |e_i|, RMSE per state, final |e|."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass
class SimResult:
    """Trajectories on a common grid ``t`` (sample index or time): plant ``x``, estimate
    ``xhat`` (both (len(t), n)), outputs ``y``; ``extra`` holds method-specific series and
    ``info`` method-specific scalar results (printed with the metrics). ``error``: the
    estimation error x̂ − x when the simulation stepped it by its own recursion (then the
    metrics use it: on an unstable plant x̂ − x computed from x and x̂ loses every digit once
    they pass 10¹⁶·|e|); None: x̂ − x."""

    t: np.ndarray
    x: np.ndarray
    xhat: np.ndarray
    y: np.ndarray | None = None
    states: list[str] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)
    error: np.ndarray | None = None

    @property
    def e(self) -> np.ndarray:
        return self.error if self.error is not None else self.xhat - self.x

    def metrics(self) -> dict[str, Any]:
        m = metrics(self.e, self.states)
        names = self.states or [f"x{i + 1}" for i in range(self.x.shape[1])]
        m["sup_abs_estimate"] = {
            s: float(np.max(np.abs(self.xhat[:, i]))) for i, s in enumerate(names)
        }
        return {**m, **self.info}


def metrics(e: np.ndarray, states: list[str] | None = None) -> dict[str, Any]:
    """sup_k |e_i(k)|, RMSE of each e_i, and the final Euclidean |e|."""
    e = np.asarray(e, dtype=float)
    names = states or [f"x{i + 1}" for i in range(e.shape[1])]
    return {
        "sup_abs_error": {s: float(np.max(np.abs(e[:, i]))) for i, s in enumerate(names)},
        "rmse": {s: float(np.sqrt(np.mean(e[:, i] ** 2))) for i, s in enumerate(names)},
        "final_error_norm": float(np.linalg.norm(e[-1])),
    }
