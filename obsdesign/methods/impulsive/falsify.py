"""Numerical falsification of Assumption 1 (eq. (15)) on a box of states.

The certificate proves the window *given* the declared nonlinearity data; this pass tries to
break the declared data by sampling. It draws pairs (x, x̂) in the region (half of them far
apart, half close together so that derivative-level violations show), maps them to z = T x,
ẑ = T x̂, ε = ẑ − z, and evaluates, with ψ̄(z) = T ψ(T⁻¹ z):

- own parts (split reading, see :mod:`.dissipativity`): φ_o = ψ̄_o(ẑ_o, z_n) − ψ̄_o(z),
  φ_n = ψ̄_n(z_o, ẑ_n) − ψ̄_n(z); violation of (15) when ω_i = [φ_i; ε_i]ᵀ[[Q,S],[Sᵀ,R]][φ_i; ε_i] < 0,
  reported relative to ‖φ_i‖² + ‖ε_i‖²;
- cross parts: c_o = ψ̄_o(ẑ) − ψ̄_o(ẑ_o, z_n), c_n = ψ̄_n(ẑ) − ψ̄_n(z_o, ẑ_n); violation when
  ‖c_i‖ > ℓ_ij ‖ε_j‖, reported as ‖c_i‖/‖ε_j‖ − ℓ_ij;
- with a Lipschitz bound in x (``lipschitz_x``): ‖ψ(x̂) − ψ(x)‖/‖x̂ − x‖ − ℓ.

Each inequality is violated only beyond the float rounding of its own evaluation (a
first-order estimate, :func:`_rounding`, times a safety factor): the differences of ψ̄ values
cancel when x̂ is close to x, and exactly tight data (a linear ψ at its declared bound) failed
the design with a "violation" of 2.5e-9 that was rounding (review 21). A violation below that
allowance at one pair is not resolvable there; pairs farther apart still show it.

Mixed points such as T⁻¹(ẑ_o, z_n) are kept only when they lie in the region too (the data
are claimed on the region). A value of ψ that is NaN or ±inf at a sampled point, and a NaN or
±inf value of an inequality, is a violation (reported with the point that produced it). The
result is a *numerical* claim: sampling can find a violation but never prove there is none.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from obsdesign.spec.models import Spec

Psi = Callable[[np.ndarray], np.ndarray]  # (N, n) -> (N, n)


@dataclass
class Violation:
    """Worst violation of one inequality: value (> 0 means violated), where, how often."""

    name: str
    worst: float
    count: int
    tested: int
    x: list[float] = field(default_factory=list)
    xhat: list[float] = field(default_factory=list)


@dataclass
class Falsification:
    samples: int
    items: list[Violation]
    literal_cross: dict[str, float]  # sup ‖c_i‖/‖ε_j‖ seen: how far the literal reading is off

    @property
    def violated(self) -> list[Violation]:
        return [v for v in self.items if v.count > 0]

    def summary(self) -> str:
        if not self.violated:
            return f"no violation in {self.samples} sampled pairs"
        parts = [
            f"{v.name}: worst {v.worst:.4g} ({v.count}/{v.tested} pairs"
            + (f", at x = {_pt(v.x)}, x̂ = {_pt(v.xhat)})" if v.x else ")")
            for v in self.violated
        ]
        return "violated — " + "; ".join(parts)


def sample_pairs(
    rng: np.random.Generator, lo: np.ndarray, hi: np.ndarray, n: int
) -> tuple[np.ndarray, np.ndarray]:
    """n pairs in the box [lo, hi]: half independent, half with x̂ − x of size 10^-4..10^-1 of
    the box width (clipped to the box)."""
    d = len(lo)
    x = rng.uniform(lo, hi, size=(n, d))
    xh = rng.uniform(lo, hi, size=(n, d))
    k = n // 2
    scale = 10.0 ** rng.uniform(-4, -1, size=(k, 1)) * (hi - lo)[None, :]
    direction = rng.normal(size=(k, d))
    xh[:k] = np.clip(x[:k] + scale * direction, lo, hi)
    return x, xh


def _qsr_value(
    phi: np.ndarray, e: np.ndarray, Qm: np.ndarray, S: np.ndarray, R: np.ndarray
) -> np.ndarray:
    """ω = φᵀQφ + 2φᵀSε + εᵀRε row-wise (eq. (15))."""
    return (
        np.einsum("ij,jk,ik->i", phi, Qm, phi)
        + 2 * np.einsum("ij,jk,ik->i", phi, S, e)
        + np.einsum("ij,jk,ik->i", e, R, e)
    )


def _pt(v: list[float]) -> str:
    return "(" + ", ".join(f"{a:.4g}" for a in v) + ")"


def _worst(name: str, val: np.ndarray, x: np.ndarray, xh: np.ndarray, tol: Any) -> Violation:
    """Worst value of one inequality (> tol violates, ``tol`` a number or one per pair; NaN
    and ±inf violate too, and a non-finite value is reported first, with its point)."""
    if val.size == 0:
        return Violation(name, float("-inf"), 0, 0)
    bad = ~np.isfinite(val)
    cnt = int(np.sum(bad | (val > tol)))
    i = int(np.argmax(bad)) if bad.any() else int(np.argmax(val))
    return Violation(name, float(val[i]), cnt, int(val.size), x[i].tolist(), xh[i].tolist())


#: safety factor on the first-order rounding estimate of :func:`_rounding`
ROUNDING_SAFETY = 16.0


def _rounding(scale: np.ndarray, denom: np.ndarray, n: int) -> np.ndarray:
    """First-order rounding allowance of a quotient ‖a − b‖/d with a, b computed from
    values of size ``scale`` (row-wise) in dot products of length ``n`` and d = ``denom``:
    ROUNDING_SAFETY · n · u · scale / d (u the float64 unit roundoff). Used as an addition to
    the tolerance of the inequalities of Assumption 1 (eq. (15)); only its size matters (no
    claim is certified from sampling)."""
    u = np.finfo(float).eps / 2
    with np.errstate(all="ignore"):
        return ROUNDING_SAFETY * max(n, 1) * u * scale / denom


def _rows(a: np.ndarray) -> np.ndarray:
    """Euclidean norms of the rows, scaled by each row's largest entry first: squared as
    they were, entries beyond ~10¹⁵⁴ overflowed to inf (and the rounding allowance with
    them; non-finite expressions trial, session 35)."""
    m = np.max(np.abs(a), axis=1, initial=0.0) if a.size else np.zeros(a.shape[0])
    safe = np.where((m > 0) & np.isfinite(m), m, 1.0)
    with np.errstate(all="ignore"):
        out = np.linalg.norm(a / safe[:, None], axis=1) * safe
    return np.where(np.isfinite(m), out, np.inf)


def _scaled(phi: np.ndarray, e: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """φ and ε divided row-wise by their largest entry (1 where that is 0 or not finite),
    and that scale: ω/(‖φ‖² + ‖ε‖²) of (15) is homogeneous of degree 0, and read unscaled
    ε ≈ 2·10¹⁹⁷ squared to inf, inf − inf made NaN and a true Assumption 1 was "violated",
    exit 1 (non-finite expressions trial, session 35)."""
    sc = np.maximum(
        np.max(np.abs(phi), axis=1, initial=0.0), np.max(np.abs(e), axis=1, initial=0.0)
    )
    sc = np.where((sc > 0) & np.isfinite(sc), sc, 1.0)
    return phi / sc[:, None], e / sc[:, None], sc


def _finite(psi_x: np.ndarray, psi_xh: np.ndarray, x: np.ndarray, xh: np.ndarray) -> Violation:
    """ψ must be finite at every sampled point (NaN / ±inf is a violation)."""
    bad = ~(np.all(np.isfinite(psi_x), axis=1) & np.all(np.isfinite(psi_xh), axis=1))
    val = np.where(bad, np.nan, -1.0)
    return _worst("ψ finite on the region", val, x, xh, 0.0)


@np.errstate(all="ignore")
def falsify_blocks(
    psi: Psi,
    T: np.ndarray,
    m: int,
    qsr_o: tuple[np.ndarray, ...],
    qsr_n: tuple[np.ndarray, ...],
    ell_on: float,
    ell_no: float,
    lo: np.ndarray,
    hi: np.ndarray,
    samples: int,
    seed: int,
    tol: float = 1e-9,
) -> Falsification:
    """Falsification of the split reading of (15) with per-block data (see module doc); NumPy
    floating-point warnings are silenced while it runs."""
    rng = np.random.default_rng(seed)
    T = np.asarray(T, dtype=float)
    Ti = np.linalg.inv(T)
    x, xh = sample_pairs(rng, lo, hi, samples)
    z, zh = x @ T.T, xh @ T.T

    def psibar(Z: np.ndarray) -> np.ndarray:
        return psi(Z @ Ti.T) @ T.T

    nT = float(np.linalg.norm(T, 2))
    kT = nT * float(np.linalg.norm(Ti, 2))
    dim = T.shape[0]

    def size(P: np.ndarray, Z: np.ndarray, slope: float) -> np.ndarray:
        """Rounding scale of ψ̄ at Z (row-wise): its value's size through T, and the
        rounding of T⁻¹z (and of z = T x) carried through ψ with the slope ``slope``."""
        return nT * _rows(P @ Ti.T) + kT * (1.0 + slope) * _rows(Z)

    def inside(Z: np.ndarray) -> np.ndarray:
        X = Z @ Ti.T
        return np.all((X >= lo - 1e-12) & (X <= hi + 1e-12), axis=1)

    mix_o = np.concatenate([zh[:, :m], z[:, m:]], axis=1)  # (ẑ_o, z_n)
    mix_n = np.concatenate([z[:, :m], zh[:, m:]], axis=1)  # (z_o, ẑ_n)
    p_z, p_zh, p_mo, p_mn = psibar(z), psibar(zh), psibar(mix_o), psibar(mix_n)
    eo, en = zh[:, :m] - z[:, :m], zh[:, m:] - z[:, m:]
    ok_o, ok_n = inside(mix_o), inside(mix_n)
    items = [_finite(psi(x), psi(xh), x, xh)]
    lit: dict[str, float] = {}
    ell = max(ell_on, ell_no, 0.0)
    s_z = size(p_z, z, ell)

    def own(phi: np.ndarray, e: np.ndarray, qsr: tuple[np.ndarray, ...], s_mix: np.ndarray) -> Any:
        """ω/(‖φ‖² + ‖ε‖²) of (15) and its rounding allowance: the error of φ (a difference
        of ψ̄ values) through the quadratic form, relative to √(‖φ‖² + ‖ε‖²)."""
        ph, es, sc = _scaled(phi, e)
        norm2 = np.maximum(np.sum(ph**2, 1) + np.sum(es**2, 1), 1e-300)
        qn = max(float(np.linalg.norm(np.block([[qsr[0], qsr[1]], [qsr[1].T, qsr[2]]]), 2)), 1.0)
        return _qsr_value(ph, es, *qsr) / norm2, 2 * qn * _rounding(
            s_z + s_mix, np.sqrt(norm2) * sc, dim
        )

    # own parts
    phi_o = p_mo[:, :m] - p_z[:, :m]
    w, r = own(phi_o, eo, qsr_o, size(p_mo, mix_o, ell))
    items.append(_worst("(15) own part, i = o", -w[ok_o], x[ok_o], xh[ok_o], tol + r[ok_o]))
    if T.shape[0] > m:
        phi_n = p_mn[:, m:] - p_z[:, m:]
        w, r = own(phi_n, en, qsr_n, size(p_mn, mix_n, ell))
        items.append(_worst("(15) own part, i = n", -w[ok_n], x[ok_n], xh[ok_n], tol + r[ok_n]))
        # cross parts
        c_o = _rows(p_zh[:, :m] - p_mo[:, :m])
        c_n = _rows(p_zh[:, m:] - p_mn[:, m:])
        ne_n, ne_o = _rows(en), _rows(eo)
        s_zh = size(p_zh, zh, ell)
        sel = ok_o & (ne_n > 1e-12)
        ratio = c_o[sel] / ne_n[sel]
        r = _rounding((s_zh + size(p_mo, mix_o, ell))[sel], ne_n[sel], dim)
        lit["o"] = float(np.nanmax(ratio, initial=0.0))
        items.append(
            _worst("cross bound ‖c_o‖ ≤ ℓ_on‖ε_n‖", ratio - ell_on, x[sel], xh[sel], tol + r)
        )
        sel = ok_n & (ne_o > 1e-12)
        ratio = c_n[sel] / ne_o[sel]
        r = _rounding((s_zh + size(p_mn, mix_n, ell))[sel], ne_o[sel], dim)
        lit["n"] = float(np.nanmax(ratio, initial=0.0))
        items.append(
            _worst("cross bound ‖c_n‖ ≤ ℓ_no‖ε_o‖", ratio - ell_no, x[sel], xh[sel], tol + r)
        )
    return Falsification(samples, items, lit)


def falsify_lipschitz_x(
    psi: Psi, ell: float, lo: np.ndarray, hi: np.ndarray, samples: int, seed: int, tol: float = 1e-9
) -> Falsification:
    """Falsification of ‖ψ(x̂) − ψ(x)‖ ≤ ℓ‖x̂ − x‖ on the region."""
    with np.errstate(all="ignore"):
        rng = np.random.default_rng(seed)
        x, xh = sample_pairs(rng, lo, hi, samples)
        px, pxh = psi(x), psi(xh)
        d = _rows(xh - x)
        sel = d > 1e-12
        ratio = _rows(pxh - px)[sel] / d[sel]
        scale = _rows(px) + _rows(pxh) + (1.0 + ell) * (_rows(x) + _rows(xh))
        r = _rounding(scale[sel], d[sel], x.shape[1])
        items = [
            _finite(px, pxh, x, xh),
            _worst("Lipschitz bound of ψ in x", ratio - ell, x[sel], xh[sel], tol + r),
        ]
    return Falsification(samples, items, {})


def run_falsification(spec: Spec, T: Any) -> Falsification:
    """Falsification pass of Assumption 1 (15) on the spec's ``[nonlinearity.falsify]`` box,
    in the coordinates z = T x of the design (``T`` exact or float, n×n)."""
    from obsdesign.certify.exact import to_float

    from .core import LipschitzX
    from .plant import psi_callable

    o = spec.options
    fz = o.falsify
    assert fz is not None
    psi = psi_callable(spec)
    data = o.problem.data
    if isinstance(data, LipschitzX):
        return falsify_lipschitz_x(psi, float(data.ell), fz.lower, fz.upper, fz.samples, fz.seed)
    Tf = np.asarray(to_float(np.asarray(T, dtype=object)), dtype=float)
    return falsify_blocks(
        psi,
        Tf,
        o.problem.m,
        data.qsr_o.floats(),
        data.qsr_n.floats(),
        float(data.ell_on),
        float(data.ell_no),
        fz.lower,
        fz.upper,
        fz.samples,
        fz.seed,
    )
