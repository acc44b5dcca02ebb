"""Expression-defined plant and observer for the constrained redesign (paper 000, eq. (1)-(2)):
x⁺ = f(x, u, d), y = h(x, u, v), x̂⁺ = F(x̂, u, y), written in the spec's expression language.

Variables: the state names (``x1``, ``x2``, … or ``[system] states``), inputs ``u1…``,
process disturbance ``d1…``, output noise ``v1…``, outputs ``y1…``; the observer F sees the
estimate as ``<state>_hat`` (``x1_hat``, …). With expressions the Lyapunov data (P, ρ, μ) must
be given, and inequality (5) is checked numerically on samples (claim status ``numerical``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from obsdesign.errors import SpecError
from obsdesign.spec.expr import Expr, parse_expr
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

#: samples used for the numerical check of (5); fixed seed so that verify reproduces it
SAMPLES = 20_000
SEED = 20190911


@dataclass
class Names:
    """Variable names of the expressions."""

    x: list[str]
    u: list[str]
    d: list[str]
    v: list[str]
    y: list[str]

    @property
    def xhat(self) -> list[str]:
        return [s + "_hat" for s in self.x]


def names(spec: Spec) -> Names:
    s = spec.system
    return Names(
        list(s.states),
        [f"u{i + 1}" for i in range(s.m)],
        [f"d{i + 1}" for i in range(s.nd)],
        [f"v{i + 1}" for i in range(s.nv)],
        [f"y{i + 1}" for i in range(s.p)],
    )


@dataclass
class VectorExpr:
    """A vector of expressions over an ordered variable list, evaluated on (..., k) arrays."""

    parts: list[Expr]
    order: list[str]

    def __call__(self, *blocks: np.ndarray) -> np.ndarray:
        Z = np.concatenate([np.asarray(b, dtype=float) for b in blocks], axis=-1)
        return np.stack([e.on(self.order)(Z) for e in self.parts], axis=-1)


def parse_vector(
    table: Table, key: str, length: int, order: list[str], spec: Spec
) -> VectorExpr | None:
    """``key = ["expr", …]`` with ``length`` entries over the variables ``order``."""
    if not table.has(key):
        return None
    raw = table.data[key]
    table.mark(key)
    if isinstance(raw, str):
        raw = [raw]
    if not isinstance(raw, list) or len(raw) != length or not all(isinstance(t, str) for t in raw):
        raise table.error(key, f"expected a list of {length} expression strings")
    params = {k: v.q for k, v in spec.system.parameters.items()}
    parts = [
        parse_expr(t, order, params, table.file, f"{table.key(key)}[{i}]")
        for i, t in enumerate(raw)
    ]
    return VectorExpr(parts, order)


@dataclass
class Model:
    """f, h of (1) and F of (2) as callables (None: the linear default from [system] / L)."""

    f: VectorExpr | None
    h: VectorExpr | None
    F: VectorExpr | None

    @property
    def nonlinear(self) -> bool:
        return self.f is not None or self.h is not None or self.F is not None


def parse_model(table: Table, spec: Spec) -> Model:
    """The plant's ``f``, ``h`` from ``[system]`` and the observer map ``F`` of ``[method]``."""
    nm = names(spec)
    s = spec.system
    if s.psi is not None:
        raise SpecError(
            spec.file, "system.psi", "is not used by the constrained method: give f instead"
        )
    f = None if s.f is None else VectorExpr(s.f, nm.x + nm.u + nm.d)
    h = None if s.h is None else VectorExpr(s.h, nm.x + nm.u + nm.v)
    F = parse_vector(table, "F", s.n, nm.xhat + nm.u + nm.y, spec)
    return Model(f, h, F)


def plant_f(spec: Spec, model: Model) -> Any:
    """x⁺ = f(x, u, d) (vectorized): the expression, or A x + B u + Bd d."""
    s = spec.system
    return model.f if model.f is not None else _affine(s.A.f, s.B.f, s.Bd.f)


def plant_h(spec: Spec, model: Model) -> Any:
    """y = h(x, u, v) (vectorized): the expression, or C x + D u + Dn v."""
    s = spec.system
    return model.h if model.h is not None else _affine(s.C.f, s.D.f, s.Dn.f)


def _affine(M: np.ndarray, N: np.ndarray, K: np.ndarray) -> Any:
    """(x, a, b) ↦ M x + N a + K b on row-stacked arrays."""
    return lambda x, a, b: x @ M.T + a @ N.T + b @ K.T


def check_iss_samples(
    spec: Spec, model: Model, F: Any, P: np.ndarray, rho: float, mu: float, v_scale: float
) -> tuple[bool, float, str]:
    """Inequality (5), V(Δ(x, e, u, w)) ≤ ρ V(e) + μ|w|², on SAMPLES points of X × Rⁿ × U × D.

    x uniform in X (and its vertices), u uniform in U, w uniform in D (and its vertices), e on
    Lyapunov shells V(e) = v with v log-uniform in [10⁻¹²·v_scale, 10·v_scale]. Returns (holds, worst
    relative violation, detail). A sampling check, not a proof: the claim is ``numerical``.
    """
    o = spec.options
    s = spec.system
    rng = np.random.default_rng(SEED)
    n = s.n
    X = o.X.sample(rng, SAMPLES)
    Ul, Uh = o.U_lower.astype(float), o.U_upper.astype(float)
    U = rng.uniform(Ul, Uh, (SAMPLES, s.m)) if s.m else np.zeros((SAMPLES, 0))
    Dl = np.asarray(o.D_lower, dtype=float) if len(o.D_lower) else np.zeros(0)
    Dh = np.asarray(o.D_upper, dtype=float) if len(o.D_upper) else np.zeros(0)
    W = rng.uniform(Dl, Dh, (SAMPLES, len(Dl)))
    k = SAMPLES // 10
    if len(Dl):
        W[:k] = np.where(rng.random((k, len(Dl))) < 0.5, Dl, Dh)
    Lc = np.linalg.cholesky(np.linalg.inv(P))
    z = rng.standard_normal((SAMPLES, n))
    z /= np.linalg.norm(z, axis=1, keepdims=True)
    # shells relative to the scale of V (an absolute floor of 1e-6 reversed the range for a
    # P of size 1e-8 and sampled only errors no solution reaches; constrained trial, session
    # 24): twelve decades below v_scale up to ten times it
    top = v_scale if np.isfinite(v_scale) and v_scale > 0 else 1.0
    v = np.exp(rng.uniform(np.log(top * 1e-12), np.log(10 * top), SAMPLES))
    E = np.sqrt(v)[:, None] * (z @ Lc.T)
    d, w_v = W[:, : s.nd], W[:, s.nd :]
    f, h = plant_f(spec, model), plant_h(spec, model)
    with np.errstate(all="ignore"):
        y = h(X, U, w_v)
        e_next = F(X + E, U, y) - f(X, U, d)
        lhs = np.einsum("ij,jk,ik->i", e_next, P, e_next)
        rhs = rho * np.einsum("ij,jk,ik->i", E, P, E) + mu * np.einsum("ij,ij->i", W, W)
    if not np.all(np.isfinite(lhs)):
        return False, float("inf"), "non-finite values in the sampled error dynamics"
    rel = (lhs - rhs) / np.maximum(rhs, 1e-300)
    worst = float(rel.max())
    ok = worst <= 1e-9
    return (
        ok,
        worst,
        f"{SAMPLES} samples (x ∈ X, e on V-shells up to {10 * v_scale:.3g}, u ∈ U, w ∈ D); worst (lhs−rhs)/rhs = {worst:.3g}",
    )
