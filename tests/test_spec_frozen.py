"""Read-only spec data (obsdesign/spec/frozen.py): the arrays of a bound spec's sets and method
options, also in copies."""

from __future__ import annotations

import copy
import pickle
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from flint import fmpq

from obsdesign import api
from obsdesign.spec.frozen import freeze_arrays

SPECS = Path(__file__).resolve().parents[1] / "specs"


def test_freeze_walks_dataclasses_containers_and_views() -> None:
    @dataclass
    class Inner:
        a: np.ndarray
        rest: list = field(default_factory=list)

    base = np.arange(6.0)
    obj = {"x": (Inner(base[:3], [np.zeros(2), {"y": np.ones(1)}]),)}
    freeze_arrays(obj)
    inner = obj["x"][0]
    for arr in (inner.a, base, inner.rest[0], inner.rest[1]["y"]):
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 7.0
    loop: list = []
    loop.append(loop)
    freeze_arrays(loop)  # a cycle ends


def test_set_and_option_arrays_of_a_bound_spec_are_read_only() -> None:
    """A polytope's G_q, the search-space box E and the constrained map's G_q were writable:
    editing G_q left the set's float view G at the old value, and an E edited in place
    designed (exit 0) a report whose embedded text said another E (API review, session 43)."""
    om = api.load_spec(SPECS / "dorea-pimenta-7-1.toml").sets["omega"]
    with pytest.raises(ValueError, match="read-only"):
        om.G_q[0, 0] = fmpq(5)
    ss = api.load_spec(SPECS / "hernandez-garcia-example.toml")
    with pytest.raises(ValueError, match="read-only"):
        ss.options.E.upper_q[0] = fmpq(1, 10)
    cs = api.load_spec(SPECS / "constrained-redesign-sec5.toml")
    with pytest.raises(ValueError, match="read-only"):
        cs.options.cmap.G_q[0, 0] = fmpq(5)
    # copies are made writable by numpy; the next API call freezes them again
    other = copy.deepcopy(ss)
    api.bind(other)
    with pytest.raises(ValueError, match="read-only"):
        other.options.E.upper_q[0] = fmpq(1, 10)
    other = pickle.loads(pickle.dumps(cs))
    api.bind(other)
    with pytest.raises(ValueError, match="read-only"):
        other.options.cmap.G_q[0, 0] = fmpq(5)
    # the [simulate] scenario too (its noise bound was writable; re-check review, session 43)
    sim = api.load_spec(SPECS / "impulsive-sector-3state.toml").simulate
    assert isinstance(sim.noise.bound, np.ndarray)
    with pytest.raises(ValueError, match="read-only"):
        sim.noise.bound[0] = 5.0
