"""Plots of a simulation: states and estimates, and the estimation error (matplotlib, Agg)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from obsdesign.simulate.result import SimResult


def plot_result(res: SimResult, path: str | Path, title: str = "") -> Path:
    """Write a PNG/SVG (by suffix) with x vs x̂ per state and the errors; atomic write."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = res.x.shape[1]
    fig, axes = plt.subplots(n + 1, 1, figsize=(8, 2.2 * (n + 1)), sharex=True)
    names = res.states or [f"x{i + 1}" for i in range(n)]
    for i in range(n):
        ax = axes[i]
        ax.plot(res.t, res.x[:, i], "k-", lw=1.2, label=names[i])
        ax.plot(res.t, res.xhat[:, i], "r--", lw=1.2, label=f"{names[i]} estimate")
        for label, series in res.extra.get("estimates", {}).items():
            ax.plot(res.t, series[:, i], lw=1, alpha=0.8, label=label)
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(alpha=0.3)
    ax = axes[-1]
    for i in range(n):
        ax.plot(res.t, res.e[:, i], lw=1, label=f"e{i + 1}")
    ax.set_ylabel("error")
    ax.set_xlabel("k" if res.info.get("time", "discrete") == "discrete" else "t")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save_figure(fig, path)


def save_figure(fig: object, path: str | Path) -> Path:
    """Save a matplotlib figure atomically (temp file + rename) and close it."""
    import matplotlib.pyplot as plt

    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=p.parent, suffix=p.suffix or ".png")
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=110)  # type: ignore[attr-defined]
        os.replace(tmp, p)
    finally:
        plt.close(fig)  # type: ignore[arg-type]
        if os.path.exists(tmp):
            os.unlink(tmp)
    return p
