"""Plots of the stubborn method: estimation errors and the saturation level of one run; for
the high-gain redesign, |x̂ − x| of the standard vs the stubborn high-gain observer (as in the
slides' Duffing figure)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from obsdesign.simulate.result import SimResult
from obsdesign.spec.models import Spec


def plot_simulation(spec: Spec, res: SimResult, path: str | Path) -> Path:
    """Write the simulation plot to ``path`` (PNG/SVG by suffix)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from obsdesign.simulate.plot import plain

    fig: Any
    if "error_norm" in res.extra:
        err = res.extra["error_norm"]
        fig, ax = plt.subplots(figsize=(8, 4))
        ax.semilogy(res.t, np.maximum(err[:, 0], 1e-12), color="red", label="standard high-gain")
        ax.semilogy(res.t, np.maximum(err[:, 1], 1e-12), color="blue", label="stubborn high-gain")
        ax.set_xlabel("t")
        ax.set_ylabel("|x̂(t) − x(t)|")
        ax.legend()
        ax.set_title(plain(spec.title or "stubborn high-gain observer"))
    else:
        fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        e = res.e
        for i, s in enumerate(res.states):
            a1.plot(res.t, e[:, i], label=f"x̂_{i + 1} − x_{i + 1} ({s})")
        a1.set_ylabel("estimation error")
        a1.legend()
        sig = res.extra.get("sigma")
        if sig is not None:
            for i in range(sig.shape[1]):
                a2.semilogy(res.t, np.maximum(sig[:, i], 1e-12), label=f"σ_{i + 1}")
            a2.set_ylabel("saturation level σ_i")
            a2.legend()
        a2.set_xlabel("t")
        a1.set_title(plain(spec.title or "stubborn observer"))
    fig.tight_layout()
    from obsdesign.simulate.plot import save_figure

    return save_figure(fig, path, dpi=100)
