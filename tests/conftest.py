"""Shared pytest fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

# The default suite is deterministic (CI must not fail on a newly drawn example); run
# `make test-explore` (HYPOTHESIS_PROFILE=explore) to search fresh random examples.
settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"


def pytest_sessionstart(session: pytest.Session) -> None:
    """Under mutmut (``MUTANT_UNDER_TEST`` set) the search-space interval bounds are computed
    afresh: ``design._CACHE`` keeps them per process, and mutmut forks each mutant's pytest
    session from a process whose cache already held the correct bounds, so no mutant of
    ``searchspace/bounds.py`` was seen (mutation review 21). Cleared at the session's start,
    before any fixture (a module-scoped fixture built before a per-test clearing still used
    the old bounds); within the session every bound is the mutant's own. Likewise the
    set-invariant method's exact vertices of Ω (an lru_cache of ``exact_h_to_v``)."""
    if os.environ.get("MUTANT_UNDER_TEST"):
        import sys

        mod = sys.modules.get("obsdesign.methods.searchspace.design")
        if mod is not None:
            mod._CACHE.clear()
            mod._PROOFS.clear()  # the exact refutations, kept per process likewise
        # the exact vertices of Ω (``po.exact_h_to_v``), kept per process by an lru_cache:
        # a mutant of polytope_ops would else be handed the clean run's vertices
        prob = sys.modules.get("obsdesign.methods.setinvariant.problem")
        if prob is not None:
            prob._omega_vertices.cache_clear()


@pytest.fixture
def specs_dir() -> Path:
    return SPECS


@pytest.fixture
def write_spec(tmp_path: Path):
    """Write spec text to a temp file and return its path."""

    def _w(text: str, name: str = "spec.toml") -> Path:
        p = tmp_path / name
        p.write_text(text, encoding="utf-8")
        return p

    return _w


@pytest.fixture(scope="module")
def dask_client(request: pytest.FixtureRequest):
    """A Dask client on a LocalCluster of 2 worker processes (one thread each), shared by the
    test module (starting one costs seconds). One task per worker thread at a time
    (``worker-saturation`` 1, as obsdesign's own LocalCluster), so only the running task is
    suspected when its worker dies; a module adds dask settings in ``DASK_CONFIG``."""
    pytest.importorskip("dask.distributed")
    import dask
    from dask.distributed import Client, LocalCluster

    cfg = {"distributed.scheduler.worker-saturation": 1.0}
    cfg.update(getattr(request.module, "DASK_CONFIG", {}))
    with dask.config.set(cfg):
        cluster = LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            silence_logs=40,
        )
        client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
            cluster.close()


@pytest.fixture
def slow_clock(monkeypatch: pytest.MonkeyPatch):
    """``slow_clock(still=0)``: the simulations' time budget (obsdesign.simulate.budget) reads
    a clock that stands at 0 for its first ``still`` looks, then is 1000 s later at every look
    — a budget of 999 s (or 1000.5) runs out at a chosen look, deterministically. Calling it
    again restarts the clock; ``monkeypatch.undo()`` gives the real clock back."""
    from obsdesign.simulate import budget

    def start(still: int = 0) -> None:
        ticks = iter([0] * still + list(range(0, 10**6, 1000)))

        class Clock:
            @staticmethod
            def perf_counter() -> float:
                return float(next(ticks))

        monkeypatch.setattr(budget, "time", Clock)

    return start


@pytest.fixture
def jordan_in_disguise():
    """``make(z, n, scale)``: S J S⁻¹ exactly (``fmpq_mat``), J the n×n Jordan block of z,
    S = I + scale·(subdiagonal ones): a defective, strongly non-normal matrix whose float
    eigenvalues are off by ~(u‖·‖)^(1/n)."""
    from flint import fmpq, fmpq_mat

    def make(z: fmpq, n: int, scale: int) -> fmpq_mat:
        J = fmpq_mat(
            n, n, [z if i == j else (1 if j == i + 1 else 0) for i in range(n) for j in range(n)]
        )
        S = fmpq_mat(
            n,
            n,
            [1 if i == j else (scale if i == j + 1 else 0) for i in range(n) for j in range(n)],
        )
        return S * J * S.inv()

    return make
