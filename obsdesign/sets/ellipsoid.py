"""Ellipsoids {x : (x - c)ᵀ E (x - c) <= 1} with E symmetric positive definite."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from obsdesign.certify.exact import frac
from obsdesign.sets.base import ConvexSet, float_view


@dataclass(frozen=True, eq=False)
class Ellipsoid(ConvexSet):
    """Ellipsoid with exact shape ``E_q`` (symmetric positive definite) and centre
    ``center_q``, object arrays of fmpq; ``E`` and ``center`` are their float views."""

    E_q: np.ndarray
    center_q: np.ndarray
    kind = "ellipsoid"
    E = float_view("E_q")
    center = float_view("center_q")

    @property
    def dim(self) -> int:
        return self.E_q.shape[0]

    def contains(self, x: np.ndarray, tol: float = 1e-12) -> np.ndarray | bool:
        d = np.asarray(x, dtype=float) - self.center
        return np.einsum("...i,ij,...j->...", d, self.E, d) <= 1 + tol

    def contains_rel(self, x: np.ndarray, rel: float = 1e-9) -> np.ndarray | bool:
        """(x − c)ᵀE(x − c) ≤ 1 + ``rel``: the quadratic form is already relative to the
        set's size (:meth:`ConvexSet.contains_rel`). Decided for the float point x as it is:
        in floats where the form's rounding error cannot reach the threshold, else exactly
        with the spec's E and c. The float form alone read 1.0 for a point at 1.986 of an
        ellipsoid with eigenvalues 10⁸ and 1.5·10⁻⁸ (batch trial, session 35).

        The bound, with d = fl(x − c) and η = ε(|d| + |c|) + the smallest subnormal (the
        rounding of the difference and of the centre): 2(n² + 8)·ε·|d|ᵀ|E||d| (the sums of the
        n² products, E rounded) + 4·ηᵀ|E|(|d| + η) (the error of d through the form) + twice the
        smallest subnormal × (Σ|d|)² (subnormal entries of E, rounded absolutely). It was
        4(n + 8)·ε·aᵀ|E|a with a = |x| + |c|, which for an ellipsoid of radius 10⁻³ centred at
        10⁴ exceeded the threshold everywhere: every point went to exact arithmetic, and
        20,000 Monte Carlo initial errors took 55 s instead of 0.1 s (re-check trial, session
        37); n + 8 was also short of the n² products of the form for n ≥ 8."""
        X = np.asarray(x, dtype=float)
        one = X.ndim == 1
        X2 = X.reshape(-1, self.dim)
        n, eps = self.dim, np.finfo(float).eps
        with np.errstate(all="ignore"):
            d = X2 - self.center
            q = np.einsum("...i,ij,...j->...", d, self.E, d)
            ad, aE = np.abs(d), np.abs(self.E)
            eta = eps * (ad + np.abs(self.center)) + 5e-324
            err = 2 * (n * n + 8) * eps * np.einsum("...i,ij,...j->...", ad, aE, ad)
            err = err + 4 * np.einsum("...i,ij,...j->...", eta, aE, ad + eta)
            # a subnormal E_ij is rounded absolutely (up to half the smallest subnormal)
            err = err + 2 * 5e-324 * np.sum(ad, axis=-1) ** 2
        thr = 1 + rel
        out = q <= thr
        finite = np.isfinite(X2).all(axis=-1)
        unsure = finite & ~(np.abs(q - thr) > err)
        if unsure.any():
            t = Fraction(thr)
            for k in np.flatnonzero(unsure):
                out[k] = self._form_q(X2[k]) <= t
        out &= finite
        return bool(out[0]) if one else out.reshape(X.shape[:-1])

    def contains_exact(self, x: np.ndarray) -> np.ndarray | bool:
        """(x − c)ᵀE(x − c) ≤ 1 exactly for the float point x as it is (:meth:`contains_rel`
        at ``rel = 0``: the threshold has no float slack)."""
        return self.contains_rel(x, rel=0.0)

    def _form_q(self, x: np.ndarray) -> Fraction:
        """(x − c)ᵀE(x − c) exactly, for the float point x as it is."""
        d = [frac(float(v)) - frac(c) for v, c in zip(x, self.center_q, strict=True)]
        E = self.E_q
        return sum(
            (d[i] * frac(E[i, j]) * d[j] for i in range(len(d)) for j in range(len(d))),
            start=Fraction(0),
        )

    def bounding_box(self) -> tuple[np.ndarray, np.ndarray]:
        half = np.sqrt(np.diag(np.linalg.inv(self.E)))
        return self.center - half, self.center + half
