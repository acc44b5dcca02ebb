"""Figures: the polyhedra with the error trajectory (Fig. 1 of paper 003) and ε(z) against z
(Fig. 2). Two states: the sets themselves; three and more: projections on coordinate pairs."""

from __future__ import annotations

from itertools import combinations
from pathlib import Path
from typing import Any

import numpy as np

from obsdesign.params import Parameters
from obsdesign.sets import polytope_ops as po
from obsdesign.spec.models import Spec

from . import lps
from .problem import build


def _polygon(ax: Any, V: np.ndarray, i: int, j: int, **kw: Any) -> None:
    from scipy.spatial import ConvexHull

    P = V[:, [i, j]]
    try:
        h = ConvexHull(P)
        idx = list(h.vertices) + [h.vertices[0]]
    except Exception:  # degenerate projection
        idx = list(range(len(P)))
    ax.plot(P[idx, 0], P[idx, 1], **kw)


def _axes(n: int) -> list[tuple[int, int]]:
    return [(0, 1)] if n == 2 else list(combinations(range(n), 2))[:3]


def _figure(k: int) -> tuple[Any, list[Any]]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, k, figsize=(5 * k, 4.5))
    return fig, list(np.atleast_1d(axes))


def draw_sets(
    axes: list[Any],
    pairs: list[tuple[int, int]],
    spec: Spec,
    G: np.ndarray,
    extra: dict[str, np.ndarray] | None = None,
) -> None:
    d = build(spec)
    Vo = po.h_to_v(d.fl.G0).V
    V = po.h_to_v(G).V
    for ax, (i, j) in zip(axes, pairs, strict=False):
        _polygon(ax, V, i, j, color="C0", lw=1.6, label="{G e <= 1}")
        _polygon(ax, Vo, i, j, color="k", lw=1.0, ls="--", label="Ω")
        for name, Ve in (extra or {}).items():
            _polygon(ax, Ve, i, j, color="C2", lw=1.0, ls=":", label=name)
        ax.set_xlabel(f"e{i + 1}")
        ax.set_ylabel(f"e{j + 1}")
        ax.grid(alpha=0.3)


def plot_simulation(spec: Spec, res: Any, path: str | Path) -> Path:
    """Polyhedra and the error trajectory e(k) = x − x̂ (projections for n >= 3)."""
    from obsdesign.simulate.plot import plain, save_figure

    n = spec.system.n
    e = res.extra["e_paper"]
    if n == 1:
        # one state: no coordinate pair to project on (it was exit 3, "Number of columns
        # must be a positive integer, not 0": simulate-correctness trial, session 25); e(k)
        # against k between the ends of the interval {G e <= 1} and of Ω
        fig, axes = _figure(1)
        ax = axes[0]
        ax.plot(np.arange(len(e)), e[:, 0], "r.-", lw=0.8, ms=4, label="error e(k)")
        for V, kw in (
            (po.h_to_v(res.extra["G"]).V, {"color": "C0", "lw": 1.6, "label": "{G e <= 1}"}),
            (po.h_to_v(build(spec).fl.G0).V, {"color": "k", "lw": 1.0, "ls": "--", "label": "Ω"}),
        ):
            for i, v in enumerate((V[:, 0].min(), V[:, 0].max())):
                ax.axhline(v, **(kw if i == 0 else {**kw, "label": None}))
        ax.set_xlabel("k")
        ax.set_ylabel("e1")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
        fig.suptitle(plain(f"{spec.title or spec.file}: max gauge {res.info['max_gauge']:.4f}"))
        fig.tight_layout()
        return save_figure(fig, path)
    pairs = _axes(n)
    fig, axes = _figure(len(pairs))
    draw_sets(axes, pairs, spec, res.extra["G"])
    for ax, (i, j) in zip(axes, pairs, strict=False):
        ax.plot(e[:, i], e[:, j], "r.-", lw=0.8, ms=4, label="error e(k)")
        ax.legend(fontsize=8, loc="best")
    fig.suptitle(plain(f"{spec.title or spec.file}: max gauge {res.info['max_gauge']:.4f}"))
    fig.tight_layout()
    return save_figure(fig, path)


def plot_design(spec: Spec, params: Parameters, path: str | Path) -> Path:
    """ε(z) against z (LP (9), Fig. 2 of the paper) for the designed polyhedron, and for the
    symmetric C_K^∞ when the design fell back from it; plus the polyhedra."""
    from obsdesign.simulate.plot import plain, save_figure

    s = spec.system
    d = build(spec).fl
    G = params.float("G").reshape(-1, s.n)
    pairs = _axes(s.n)
    fig, axes = _figure(1 + len(pairs))
    ax = axes[0]
    lam = float(spec.options.lam)
    if s.p == 1:
        curves = [("designed polyhedron", G)]
        if "symmetric_G" in params:
            curves.insert(0, ("symmetric C_K^∞", params.float("symmetric_G").reshape(-1, s.n)))
        for label, Gc in curves:
            st = po.h_to_v(Gc)
            zd = lps.z_d(st.V, d.C[0], d.eta)
            zs = np.unique(np.concatenate([zd, np.linspace(zd[0], zd[-1], 400)]))
            z, eps = lps.epsilon_profile(Gc, d.A, d.B1, d.C[0], d.Dv, d.eta, zs)
            ax.plot(z, eps, lw=1.4, label=f"ε(z), {label} (max {eps.max():.4f})")
        ax.axhline(lam, color="k", ls="--", lw=1, label=f"λ = {lam:g}")
        ax.set_xlabel("z")
        ax.set_ylabel("ε(z)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    else:
        ax.text(0.1, 0.5, "ε(z) is defined for one output", transform=ax.transAxes)
    extra = {}
    if "symmetric_G" in params:
        extra["symmetric C_K^∞"] = po.h_to_v(params.float("symmetric_G").reshape(-1, s.n)).V
    draw_sets(axes[1:], pairs, spec, G, extra)
    for a in axes[1:]:
        a.legend(fontsize=8)
    fig.suptitle(plain(spec.title or spec.file))
    fig.tight_layout()
    return save_figure(fig, path)
