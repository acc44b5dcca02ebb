"""The scenario signals of ``[simulate]`` (obsdesign/spec/signals.py): windows by binary
search give the per-window mask's numbers, on any grid."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign.spec import signals as S


def _mask(grid: np.ndarray, windows: list[S.Window], dim: int) -> np.ndarray:
    out = np.zeros((len(grid), dim))
    for w in windows:
        out[(grid >= w.start) & (grid <= w.stop)] += w.value
    return out


windows = st.lists(
    st.tuples(
        st.floats(-5, 40, allow_nan=False),
        st.floats(0, 30, allow_nan=False),
        st.floats(-3, 3, allow_nan=False),
    ),
    max_size=12,
)


@settings(max_examples=200, deadline=None)
@given(windows, st.booleans(), st.integers(1, 60))
def test_windows_match_the_mask_per_window(ws, integer_grid, k) -> None:
    """Sorted grids (sample indices, or times with a fractional step) and unsorted ones: the
    same numbers as one mask per window, to the bit."""
    grid = np.arange(k, dtype=float) if integer_grid else np.arange(k) * 0.37
    wins = [S.Window(a, a + length, np.array([v, -v])) for a, length, v in ws]
    want = _mask(grid, wins, 2)
    sig = S.Signal("windows", 2, windows=wins)
    np.testing.assert_array_equal(sig.evaluate(grid, np.random.default_rng(0)), want)
    rev = grid[::-1].copy()
    np.testing.assert_array_equal(sig.evaluate(rev, np.random.default_rng(0)), _mask(rev, wins, 2))


def test_many_overlapping_windows_take_one_pass() -> None:
    """12,000 windows over 5·10⁶ samples made one full pass each (past 90 s; review). Windows
    that together cover more than 64 grids go through one running sum: the mask's numbers
    to rounding, quickly."""
    grid = np.arange(1000, dtype=float)
    wins = [S.Window(float(i % 7), 990.0 - i % 5, np.array([0.25 * (i % 3)])) for i in range(100)]
    out = np.zeros((1000, 1))
    S._add_windows(out, grid, wins)
    np.testing.assert_allclose(out, _mask(grid, wins, 1), rtol=1e-12, atol=1e-12)
    big = np.arange(5 * 10**6, dtype=float)
    many = [S.Window(float(i), float(5 * 10**6), np.array([1.0])) for i in range(12_000)]
    out = np.zeros((big.size, 1))
    S._add_windows(out, big, many)  # seconds at most (the per-window mask: minutes)
    assert out[-1, 0] == 12_000 and out[0, 0] == 1
