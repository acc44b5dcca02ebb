"""The continuous-time simulation grid (``obsdesign.simulate.grid``): every t_k the double
nearest to the exact k·dt, so inclusive signal windows keep their end samples."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from flint import fmpq
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign import api
from obsdesign.simulate.grid import steps_of, time_grid

SPEC = """
[system]
time = "continuous"
A = [[-1]]
C = [[1]]
[method]
key = "lyapunov"
L = [1]
[simulate]
horizon = 2
dt = 0.1
x0 = [0]
xhat0 = [0]
[simulate.noise]
kind = "windows"
windows = [{ start = 0.3, stop = 1.2, value = [1] }, { start = 1.7, stop = 1.9, value = [10] }]
"""


@settings(max_examples=200, deadline=None)
@given(
    st.integers(1, 10**6),
    st.integers(0, 6),
    st.integers(1, 3000),
)
def test_every_grid_time_is_the_correctly_rounded_product(p: int, e: int, K: int) -> None:
    """t_k = fl(k·dt) for dt = p/10^e, against Python's correctly rounded int / int."""
    dt = fmpq(p, 10**e)
    t = time_grid(dt * K, dt)
    assert len(t) == K + 1 and steps_of(dt * K, dt) == K
    ks = np.unique(np.r_[0:5, K // 2, K - 2 : K + 1].clip(0, K))
    for k in ks:
        assert t[k] == (k * p) / 10**e  # int true division rounds correctly
    assert t[-1] == float(Fraction(p * K, 10**e))


def test_a_step_beyond_53_bits_falls_back_to_multiples_of_its_double() -> None:
    dt = fmpq(123456789012345678, 10**19)
    t = time_grid(dt * 10, dt)
    assert len(t) == 11 and t[1] == float(Fraction(123456789012345678, 10**19))


def test_steps_round_half_up_and_never_go_negative() -> None:
    assert steps_of(fmpq(5, 2), fmpq(1)) == 3 and steps_of(fmpq(1, 3), fmpq(1)) == 0
    assert steps_of(fmpq(1), fmpq(1, 10)) == 10


def test_a_window_ending_on_a_grid_point_keeps_that_sample() -> None:
    """dt = 0.1: 12·fl(0.1) = 1.2000000000000002 > fl(1.2), and the window [0.3, 1.2] lost its
    sample at t = 1.2 (and [1.7, 1.9] the one at 1.9); about a third of the grid points at
    dt = 0.1 lie above their decimal (simulate-correctness trial, session 25). y = x + v with
    x ≡ 0 shows v."""
    spec = api.load_spec_text(SPEC, "win.toml")
    res = api.simulate(spec)
    v = dict(zip(np.round(res.t, 9), res.y[:, 0], strict=True))
    assert [v[t] for t in (0.2, 0.3, 1.2, 1.3)] == [0, 1, 1, 0]
    assert [v[t] for t in (1.6, 1.7, 1.8, 1.9, 2.0)] == [0, 10, 10, 10, 0]
