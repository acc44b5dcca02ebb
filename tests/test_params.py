"""Parameters: JSON form and exact values for certificates (obsdesign.params)."""

from __future__ import annotations

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import qmat
from obsdesign.params import Parameters, exact_param


def test_exact_param_paths():
    p = Parameters({"P": qmat([[1, 2], [3, 4]]), "f": 0.5, "v": np.array([0.25, 1.0])})
    claims: list = []
    assert (exact_param(p, "P", claims) == qmat([[1, 2], [3, 4]])).all()
    assert exact_param(p, "f", claims) == fmpq(1, 2)  # a float at its binary value
    assert (exact_param(p, "v", claims) == np.array([fmpq(1, 4), fmpq(1)], dtype=object)).all()
    assert claims == []
    assert exact_param(p, "missing", claims) is None and claims[-1].id == "missing-present"
    assert exact_param(p, "f", claims, accept_float=False) is None and claims[-1].id == "f-exact"
    assert all(c.status.value == "failed" for c in claims)


def test_json_round_trip_3d_exact():
    cube = np.empty((2, 1, 2), dtype=object)
    for i, idx in enumerate(np.ndindex(2, 1, 2)):
        cube[idx] = fmpq(i, 7)
    back, problems = Parameters.from_json(Parameters({"Lp": cube}).to_json())
    assert problems == [] and back["Lp"].shape == (2, 1, 2) and (back["Lp"] == cube).all()
