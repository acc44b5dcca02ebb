"""Simulation results and the standard metrics: sup |e_i|, RMSE per state, final |e|."""

from __future__ import annotations

from collections.abc import Iterator
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
        """The estimation error x̂ − x (``error`` when the method keeps its own): past the
        float range inf − inf is nan, without numpy's "invalid value" warning (it reached
        the test log; the divergence is said once, by the simulation's own warning)."""
        if self.error is not None:
            return self.error
        with np.errstate(invalid="ignore", over="ignore"):
            return self.xhat - self.x

    def metrics(self) -> dict[str, Any]:
        m = metrics(self.e, self.states)
        names = self.states or [f"x{i + 1}" for i in range(self.x.shape[1])]
        m["sup_abs_estimate"] = {
            s: float(np.max(np.abs(self.xhat[:, i]))) for i, s in enumerate(names)
        }
        return {**m, **self.info}

    def csv_text(self) -> str:
        """The trajectories as CSV: one row per grid point, columns ``t``, ``x_<state>``,
        ``xhat_<state>``, ``e_<state>`` (the error the metrics use) and ``y<j>``; floats by
        their shortest round-trip repr, so a reader gets the simulated doubles back. For a
        Monte Carlo run, the trajectory the method keeps (its run 0)."""
        return "".join(self.csv_chunks())

    def csv_chunks(self, rows: int = 4096) -> Iterator[str]:
        """:meth:`csv_text` in pieces of ``rows`` rows (the header first), so that a file of
        10⁷ rows is written without the whole text in memory (``--csv`` of a 2·10⁷-step run
        passed 3.4 GB; independent simulate review)."""
        n = self.x.shape[1]
        names = self.states or [f"x{i + 1}" for i in range(n)]
        cols = [np.asarray(self.t, dtype=float).reshape(-1, 1), self.x, self.xhat, self.e]
        head = ["t", *(f"x_{s}" for s in names), *(f"xhat_{s}" for s in names)]
        head += [f"e_{s}" for s in names]
        if self.y is not None:
            y = np.asarray(self.y, dtype=float).reshape(len(self.t), -1)
            cols.append(y)
            head += [f"y{j + 1}" for j in range(y.shape[1])]
        yield ",".join(_csv_name(h) for h in head) + "\n"
        for a in range(0, len(self.t), rows):
            table = np.hstack([np.asarray(c, dtype=float)[a : a + rows] for c in cols])
            yield "".join(",".join(map(repr, row)) + "\n" for row in table.tolist())


def _csv_name(name: str) -> str:
    """A CSV header cell: quoted when a state name holds a comma, quote or line break."""
    if any(c in name for c in ',"\n\r'):
        return '"' + name.replace('"', '""') + '"'
    return name


def metrics(e: np.ndarray, states: list[str] | None = None) -> dict[str, Any]:
    """sup_k |e_i(k)|, RMSE of each e_i, and the final Euclidean |e|; the RMSE and the norm
    scaled by the largest entry, so that errors near 10³⁰⁰ do not overflow to inf in e²
    (independent simulate review)."""
    e = np.asarray(e, dtype=float)
    names = states or [f"x{i + 1}" for i in range(e.shape[1])]
    return {
        "sup_abs_error": {s: float(np.max(np.abs(e[:, i]))) for i, s in enumerate(names)},
        "rmse": {s: _rms(e[:, i]) for i, s in enumerate(names)},
        "final_error_norm": _scaled(e[-1], lambda v: float(np.linalg.norm(v))),
    }


def _rms(v: np.ndarray) -> float:
    """sqrt(mean(v²)) without overflow of v² (scaled by max |v|)."""
    return _scaled(v, lambda w: float(np.sqrt(np.mean(w * w))))


def _scaled(v: np.ndarray, f: Any) -> float:
    """``f(v)`` for a norm-like ``f`` as ``f(v / s) · s`` with s = max |v| (the same value,
    without the overflow of v² near 10¹⁵⁴ nor its underflow near 10⁻¹⁵⁴: errors of 10⁻²⁰⁰ had
    RMSE 0.0 beside sup |e| = 1.2·10⁻¹⁹⁹, simulate trial, session 27); ``f(v)`` when an entry
    is not finite or all are 0."""
    with np.errstate(all="ignore"):
        s = float(np.max(np.abs(v))) if np.size(v) else 0.0
        if not SAFE_LO <= s <= SAFE_HI:  # 0 and non-finite entries fail both: as they are
            if s == 0.0 or not np.isfinite(s):
                return f(v)
            return f(v / s) * s
        return f(v)  # squares safe: unscaled, bit for bit what it always was


#: the range of max |v| in which v² neither overflows nor loses digits to underflow
SAFE_LO, SAFE_HI = 1e-150, 1e150


def norms(a: np.ndarray) -> np.ndarray:
    """Euclidean norms along the last axis without overflow of the squares near 10¹⁵⁴ nor
    underflow near 10⁻¹⁵⁴: a vector whose largest |entry| is outside [SAFE_LO, SAFE_HI] is
    scaled by it, the others are not (bit for bit ``np.linalg.norm``). A Monte Carlo final
    |e| of 1.8·10¹⁹⁵ was inf and of 1.8·10⁻²⁰⁵ was 0 (simulate trial, session 27); an
    infinite sampled estimate of a search-space constant would refute any given one."""
    a = np.asarray(a, dtype=float)
    if a.shape[-1] == 0:
        return np.zeros(a.shape[:-1])
    with np.errstate(all="ignore"):
        m = np.max(np.abs(a), axis=-1, keepdims=True)
        s = np.where((m > 0) & np.isfinite(m) & ((m < SAFE_LO) | (m > SAFE_HI)), m, 1.0)
        return np.asarray(np.linalg.norm(a / s, axis=-1) * s[..., 0])
