"""Figures 3-5 of Hernández & García ("An alternative approach to the state observation problem
for Lipschitz continuous systems with controls"): the search space over time in each state
coordinate (Fig. 3 with the output for x₁, Fig. 4 for x₂) and the estimation error over time
(Fig. 5, footnote 9's coordinate-wise error, with the centroid's error and ε_i)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from obsdesign.simulate.result import SimResult, norms
from obsdesign.spec.models import Spec


def plot_simulation(spec: Spec, res: SimResult, path: str | Path) -> Path:
    """One panel per state coordinate (live centres as dots, the true state as a line, the
    switches as vertical ticks) and one error panel (log scale); written to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from obsdesign.simulate.plot import plain

    n = res.x.shape[1]
    fig, axes = plt.subplots(n + 1, 1, figsize=(8, 2.6 * (n + 1)), sharex=True)
    stored = res.extra.get("stored", [])
    ts = np.concatenate([np.full(len(c), t) for t, c in stored]) if stored else np.zeros(0)
    cs = np.concatenate([c for _, c in stored]) if stored else np.zeros((0, n))
    names = res.states or [f"x{i + 1}" for i in range(n)]
    panels = output_panels(spec, names)
    for i, ax in enumerate(axes[:n]):
        # rasterized: in a vector format (svg, pdf) each of up to millions of centres was its
        # own path (the template's svg was 87 MB); the lines stay vectors
        ax.scatter(
            ts, cs[:, i], s=1, c="tab:blue", alpha=0.35, lw=0, label="search space", rasterized=True
        )
        ax.plot(res.t, res.x[:, i], "k", lw=1.2, label=f"true {names[i]}")
        ax.plot(res.t, res.xhat[:, i], "tab:red", lw=0.8, label="centroid estimate")
        for j in panels.get(i, []) if res.y is not None else []:
            label = "output y" if res.y.shape[1] == 1 else f"output y{j + 1}"
            ax.plot(res.t, res.y[:, j], "tab:green", lw=0.8, ls="--", label=f"{label} = {names[i]}")
        _switches(ax, res)
        ax.set_ylabel(names[i])
        ax.legend(loc="upper right", fontsize=7, markerscale=6)
    ax = axes[n]
    err9 = res.extra["err_fn9"]
    # the floor of the log scale relative to ε⋆ (a fixed 1e-12 put every curve of a plant of
    # size 1e-198 on the bottom edge and ε⋆ off the axis; re-check trial, session 29)
    eps = float(res.info.get("eps_star", 1e-3))
    floor = eps * 1e-6 if math.isfinite(eps) and eps > 0 else 1e-12
    for i in range(n):
        ax.semilogy(res.t, np.maximum(err9[:, i], floor), lw=1, label=f"footnote 9: {names[i]}")
    ax.semilogy(
        res.t,
        np.maximum(norms(res.xhat - res.x), floor),
        "tab:red",
        lw=0.8,
        label="|centroid − x|",
    )
    ax.axhline(res.info.get("eps_star", np.nan), color="gray", ls=":", label="ε⋆")
    _switches(ax, res)
    ax.set_ylim(bottom=max(eps / 100, floor) if math.isfinite(eps) and eps > 0 else floor)
    ax.set_xlabel("t")
    ax.set_ylabel("estimation error")
    ax.legend(loc="upper right", fontsize=7)
    fig.suptitle(plain(spec.title or spec.file), fontsize=9)
    fig.tight_layout()
    from obsdesign.simulate.plot import save_figure

    return save_figure(fig, path, dpi=120)


def output_panels(spec: Spec, names: list[str]) -> dict[int, list[int]]:
    """{state i: the outputs j with y_j = x_i}: an output is drawn on a state's panel only
    when it is that state (h_j the bare name; search-space plants are given by f and h). y₁ was drawn
    on the x₁ panel as "output y" whatever h was (h = [x1 + x2, x1 − x2]: one line, y₂ never
    shown; search-space trial, session 29).

    :param spec: the spec (its h); :param names: the state names in order."""
    import ast

    out: dict[int, list[int]] = {}
    s = spec.system
    if s.h:
        for j, e in enumerate(s.h):
            body = e.tree.body
            if isinstance(body, ast.Name) and body.id in names:
                out.setdefault(names.index(body.id), []).append(j)
    return out


def _switches(ax: Any, res: SimResult) -> None:
    for s in res.extra.get("switches", []):
        ax.axvline(s, color="gray", lw=0.3, alpha=0.5)
