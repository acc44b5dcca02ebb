"""Simulation: plants, scenarios, runners, metrics and plots. Methods plug their observer in
through :func:`run_discrete` / :func:`run_continuous` or their own runner."""

from obsdesign.simulate.result import SimResult, metrics
from obsdesign.simulate.runner import run_continuous, run_discrete

__all__ = ["SimResult", "metrics", "run_continuous", "run_discrete"]
