"""Output-injection laws and the runtime observer (Section IV and Proposition 7.1, paper 003).

The observer is x̂(k+1) = A x̂(k) − v(z(k)), z(k) = y(k) − C x̂(k) (eq. (2)), so the error
e = x − x̂ follows e(k+1) = A e(k) + B1 d(k) + v(z(k)) (eq. (3)).

Laws:

* ``interpolated`` (default) — eq. (12): v̄(z) = L^j z + w^j on [z^j, z^{j+1}], with
  L^j = (v^{j+1} − v^j)/(z^{j+1} − z^j), w^j = v^j − z^j L^j (proof of Proposition 4.1).
  Time-invariant; keeps e(k+1) ∈ λΩ for every admissible d and η (the certified claim).
* ``time-varying`` — eq. (10): v(z, k) = L^j z + λ^k w^j. The paper proves e(k) ∈ λ^k Ω
  when d = η = 0; its induction needs the segment j of z/λ^k (the scaled output of the
  scaled error), not of z, and we use that (the printed text picks j from z(k), which breaks
  the induction step). With d or η ≠ 0 this law is not covered by the proof.
* ``online-lp`` — Section IV: solve LP (9) at z(k) at every step (float).
* ``linear`` — v = L z (Proposition 7.1 or any certified L).

The segment is found by binary search (``numpy.searchsorted``); outputs outside
[z^1, z^{n_z}] (impossible while e ∈ Ω and |η| <= η̄) use the end segment.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from flint import fmpq

from obsdesign.sets import polytope_ops as po

from . import lps


def pieces(zs: list[fmpq], vs: list[list[fmpq]]) -> tuple[list[list[fmpq]], list[list[fmpq]]]:
    """Exact L^j and w^j of Proposition 4.1 from the breakpoints z^j and injections v^j."""
    Ls, ws = [], []
    for j in range(len(zs) - 1):
        dz = zs[j + 1] - zs[j]
        L = [(b - a) / dz for a, b in zip(vs[j], vs[j + 1], strict=True)]
        w = [vs[j][k] - zs[j] * L[k] for k in range(len(L))]
        Ls.append(L)
        ws.append(w)
    return Ls, ws


@dataclass
class PiecewiseAffineLaw:
    """v(z, k) from the breakpoint table (floats at runtime)."""

    z: np.ndarray  # breakpoints, increasing
    v: np.ndarray  # (n_z, n) injections at the breakpoints
    lam: float
    mode: str = "interpolated"

    def __post_init__(self) -> None:
        nz = len(self.z)
        if nz == 1:
            self.L = np.zeros((1, self.v.shape[1]))
            self.w = self.v[:1].copy()
        else:
            dz = np.diff(self.z)
            self.L = np.diff(self.v, axis=0) / dz[:, None]
            self.w = self.v[:-1] - self.z[:-1, None] * self.L

    def segment(self, z: float) -> int:
        """Index j with z^j <= z <= z^{j+1} (binary search; clamped to the end segments)."""
        j = int(np.searchsorted(self.z, z, side="right")) - 1
        return min(max(j, 0), len(self.L) - 1)

    def __call__(self, z: float, k: int) -> np.ndarray:
        if self.mode == "time-varying":
            s = self.lam**k
            j = self.segment(z / s) if s > 0 else self.segment(0.0)
            return self.L[j] * z + s * self.w[j]
        j = self.segment(z)
        return self.L[j] * z + self.w[j]


@dataclass
class LinearLaw:
    """v = L z (Proposition 7.1)."""

    L: np.ndarray  # (n, p)

    def __call__(self, z: float | np.ndarray, k: int) -> np.ndarray:
        return self.L @ np.atleast_1d(z)


@dataclass
class OnlineLPLaw:
    """v(z) from LP (9) solved at the measured z (Section IV, on-line injection)."""

    G: np.ndarray
    A: np.ndarray
    B1: np.ndarray
    c: np.ndarray
    Dv: np.ndarray
    eta: float

    def __post_init__(self) -> None:
        st = po.h_to_v(self.G)
        self.V, self.edges = st.V, st.edges
        self.dl = lps.delta(self.G, self.B1, self.Dv)

    def __call__(self, z: float, k: int) -> np.ndarray:
        phi, _ = lps.phi_at(self.G, self.A, self.V, self.edges, self.c, self.eta, np.array([z]))
        return lps.eps_batch(self.G, phi, self.dl).v[0]


def simulate_error(
    A: np.ndarray,
    B1: np.ndarray,
    C: np.ndarray,
    law,
    e0: np.ndarray,
    d: np.ndarray,
    eta: np.ndarray,
) -> np.ndarray:
    """Error trajectory of eq. (3) under ``law``: e(k+1) = A e + B1 d(k) + v(C e + η(k), k)."""
    K = len(d)
    e = np.zeros((K + 1, A.shape[0]))
    e[0] = e0
    for k in range(K):
        z = C @ e[k] + eta[k]
        zz = float(z[0]) if C.shape[0] == 1 and not isinstance(law, LinearLaw) else z
        e[k + 1] = A @ e[k] + (B1 @ d[k] if B1.shape[1] else 0.0) + law(zz, k)
    return e
