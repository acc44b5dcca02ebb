"""The scenario signals of ``[simulate]`` (obsdesign/spec/signals.py): windows by binary
search give the per-window mask's numbers, on any grid."""

from __future__ import annotations

import numpy as np
import pytest
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


def test_many_overlapping_windows_are_summed_per_segment_exactly() -> None:
    """12,000 windows over 5·10⁶ samples made one full pass each (past 90 s; review). Windows
    that together cover more than 64 grids are summed once per segment between their ends,
    in order: the mask's numbers to the bit — a running sum of jumps lost 70 unit windows
    beside one of 10³⁰⁰ (re-check review) — and more than MAX_OVERLAPPING_WINDOWS such
    windows are refused."""
    import pytest

    from obsdesign.errors import InputError

    grid = np.arange(1000, dtype=float)
    wins = [S.Window(float(i % 7), 990.0 - i % 5, np.array([0.1 * (i % 3)])) for i in range(100)]
    out = np.zeros((1000, 1))
    S._add_windows(out, grid, wins)
    np.testing.assert_array_equal(out, _mask(grid, wins, 1))
    big = [S.Window(0.0, 999.0, np.array([1e300]))]
    unit = [S.Window(10.0, 999.0, np.array([1.0])) for _ in range(70)]
    neg = [S.Window(0.0, 999.0, np.array([-1e300]))]
    for ws in (big + unit + neg, big + neg + unit):
        out = np.zeros((1000, 1))
        S._add_windows(out, grid, ws)
        np.testing.assert_array_equal(out, _mask(grid, ws, 1))
    assert out[-1, 0] == 70.0  # ±1e300 first, then the 70 units
    many = [S.Window(float(i), 5e6, np.array([1.0])) for i in range(5_000)]
    huge = np.arange(5 * 10**6, dtype=float)
    out = np.zeros((huge.size, 1))
    S._add_windows(out, huge, many)  # seconds at most (a mask per window: minutes)
    assert out[-1, 0] == 5_000 and out[0, 0] == 1 and out[4_999, 0] == 5_000
    too_many = [S.Window(0.0, 999.0, np.array([1.0]))] * (S.MAX_OVERLAPPING_WINDOWS + 1)
    with pytest.raises(InputError, match=r"windows: 10,001 windows that together cover"):
        S._add_windows(np.zeros((1000, 1)), grid, too_many)


@pytest.mark.parametrize(("kind", "key"), [("uniform", "bound"), ("outliers", "amplitude")])
def test_a_uniform_bound_whose_width_overflows_is_bad_input(kind: str, key: str) -> None:
    """bound = 1e308: numpy draws from the width 2b, which overflows; that was exit 4 naming
    neither the key nor the number (simulate trial, session 27). Exit 2 naming the key; the
    largest bound that works, max/2, loads."""
    from obsdesign.api import load_spec_text
    from obsdesign.errors import SpecError
    from obsdesign.spec.signals import MAX_UNIFORM

    base = (
        '[system]\ntime = "discrete"\nA = [[0.5]]\nC = [[1]]\n[method]\nkey = "lyapunov"\n'
        f'[simulate]\nhorizon = 5\nx0 = [1]\nxhat0 = [0]\n[simulate.noise]\nkind = "{kind}"\n'
        + ("rate = 0.1\n" if kind == "outliers" else "")
    )
    with pytest.raises(SpecError, match=rf"\[simulate\.noise\.{key}\] expected at most"):
        load_spec_text(base + f"{key} = 1e308\n", "s.toml")
    load_spec_text(base + f"{key} = {MAX_UNIFORM!r}\n", "s.toml")
