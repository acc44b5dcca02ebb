"""Plots of a simulation: states and estimates, and the estimation error (matplotlib, Agg)."""

from __future__ import annotations

from pathlib import Path

from obsdesign.simulate.result import SimResult


def plain(text: str) -> str:
    """``text`` as matplotlib draws it literally: a ``$`` starts math text there, so a spec
    titled "costs $5 to $10" was drawn "costs 5to10" in math italics and a title with a bad
    ``$\\frac{`` ended a finished simulation with exit 3 (CLI hostile-input trial, session
    34). User text (titles, file names, swept values) goes through this."""
    return str(text).replace("$", r"\$")


def plot_result(res: SimResult, path: str | Path, title: str = "") -> Path:
    """Write a PNG/SVG (by suffix) with x vs x̂ per state and the errors (:func:`save_figure`:
    not atomic by itself)."""
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
        fig.suptitle(plain(title))
    fig.tight_layout()
    return save_figure(fig, path)


def save_figure(fig: object, path: str | Path, dpi: int = 110) -> Path:
    """Render a matplotlib figure in the format its suffix names (PNG without one), write the
    bytes into ``path`` and close the figure. The bytes are made in memory first, so a FIFO or
    a device receives one write and nothing is left half-made; atomic replacement is the
    caller's (:func:`obsdesign.report.model.write_via`). This used its own temp file and
    rename, so ``--plot FIFO --force`` replaced the FIFO (or, through a link, a device node)
    with a regular file (simulate trial, session 27)."""
    import io
    import logging

    import matplotlib.pyplot as plt

    p = Path(path)
    buf = io.BytesIO()
    # matplotlib's logger, not warnings: "The PostScript backend does not support
    # transparency" reached stderr through -q (output trial, session 30); the PS/EPS
    # backends draw translucent bands opaque, which docs/reliability.md says
    log = logging.getLogger("matplotlib")
    level = log.level
    log.setLevel(logging.ERROR)
    try:
        fig.savefig(buf, dpi=dpi, format=p.suffix.lstrip(".").lower() or "png")  # type: ignore[attr-defined]
    finally:
        log.setLevel(level)
        plt.close(fig)  # type: ignore[arg-type]
    with open(p, "wb") as f:
        f.write(buf.getvalue())
    return p
