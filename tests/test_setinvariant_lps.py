"""obsdesign.methods.setinvariant.lps: the float LPs' range check (LP (9))."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from obsdesign import api
from obsdesign.errors import InconclusiveError
from obsdesign.methods.setinvariant import lps

ROOT = Path(__file__).resolve().parents[1]


def test_lp_range_edges() -> None:
    """Matrix entries up to 1e15 and right-hand sides below 1e20 pass; one float beyond
    either, or a non-finite value, is out of HiGHS's range."""
    ok_A, ok_b = np.array([[lps.HIGHS_MATRIX_MAX, 1.0]]), np.array([1.0])
    lps.check_lp_range(ok_A, ok_b, "LP")
    lps.check_lp_range(np.ones((1, 2)), np.array([np.nextafter(lps.HIGHS_INFINITY, 0)]), "LP")
    bad = [
        (np.array([[np.nextafter(lps.HIGHS_MATRIX_MAX, np.inf), 1.0]]), ok_b),
        (np.array([[-np.nextafter(lps.HIGHS_MATRIX_MAX, np.inf), 1.0]]), ok_b),
        (np.ones((1, 2)), np.array([-lps.HIGHS_INFINITY])),
        (np.ones((1, 2)), np.array([np.nan])),
        (np.array([[np.inf, 1.0]]), ok_b),
    ]
    for A, b in bad:
        with pytest.raises(InconclusiveError, match="out of a float LP's range"):
            lps.check_lp_range(A, b, "LP")


def test_a_huge_disturbance_gain_is_inconclusive_not_a_solver_failure() -> None:
    """B1 = [1e50, 1] (found by the spec fuzzer): LP (9)'s right-hand side reaches 5e49,
    which HiGHS reads as infinite ("Model error", exit 3 before); now exit 4 naming LP (9)."""
    text = (ROOT / "specs" / "dorea-pimenta-7-1.toml").read_text()
    assert "\nB1 = [1, 1]\n" in text
    spec = api.load_spec_text(text.replace("\nB1 = [1, 1]\n", "\nB1 = [1e50, 1]\n"), "t.toml")
    with pytest.raises(InconclusiveError, match=r"LP \(9\) is out of a float LP's range") as e:
        api.design(spec)
    assert e.value.exit_code == 4
