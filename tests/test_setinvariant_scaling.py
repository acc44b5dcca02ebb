"""The set-invariant design runs in Ω-unit coordinates (obsdesign/methods/setinvariant/scaling.py)
and maps the proved polytope back exactly: a diagonally rescaled spec gives the same design."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from flint import fmpq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from obsdesign import api
from obsdesign.api import load_spec_text
from obsdesign.methods.setinvariant import scaling
from obsdesign.methods.setinvariant.problem import build
from obsdesign.methods.setinvariant.spectext import spec_text

# a random 2-state system (seed 3 of the session-26 scale study): 10 facets certified in
# the spec's units, and "not converged" (8 facets, exit 1) once rescaled by 10⁶ before
A = [[Fraction(289, 400), Fraction(-9047, 10000)], [Fraction(37, 250), Fraction(-201, 1000)]]
B1 = [Fraction(-29, 2500), Fraction(-433, 10000)]
C = [Fraction(-539, 2500), Fraction(-101, 50)]


def _spec(ks: tuple[int, ...], lam: float = 0.7712) -> str:
    """The system in the coordinates x' = S⁻¹x, S = diag(10^k): A' = S⁻¹AS, B1' = S⁻¹B1,
    C' = CS, Ω' = S⁻¹[-1, 1]² (every entry has at most 4 significant digits, so its
    shortest float repr is the exact decimal)."""
    s = [Fraction(10) ** k for k in ks]
    Ap = [[float(A[i][j] * s[j] / s[i]) for j in range(2)] for i in range(2)]
    Bp = [float(B1[i] / s[i]) for i in range(2)]
    Cp = [[float(C[j] * s[j]) for j in range(2)]]
    omega = ([float(-1 / x) for x in s], [float(1 / x) for x in s])
    return spec_text(
        Ap, Bp, Cp, lam, omega=omega, algorithm="general", mirror=True, delta_tol=0.001,
        max_iterations=60,
    )  # fmt: skip


@pytest.fixture(scope="module")
def unit():
    return api.design(load_spec_text(_spec((0, 0)), "unit.toml"))


def _rows(M) -> set[tuple]:
    return {tuple((x.p, x.q) for x in r) for r in np.asarray(M, dtype=object)}


@pytest.mark.parametrize("ks", [(6, 6), (-9, -9), (3, 0), (0, -4)])
def test_a_diagonally_rescaled_spec_gets_the_same_design(unit, ks) -> None:
    """x' = S⁻¹x: the same facets, vertices S⁻¹V, injections S⁻¹v^l and the same exact
    factor; certified, and the independent verify agrees (by 10⁶ this system was not
    converged, exit 1, before the design ran in Ω-unit coordinates)."""
    assert unit.exit_code() == 0
    rep = api.design(load_spec_text(_spec(ks), "scaled.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.claims if c.status != "certified"]
    p, q = rep.parameters, unit.parameters
    assert p["facets"] == q["facets"] and p["contractivity"] == q["contractivity"]
    s = [fmpq(10) ** k if k >= 0 else 1 / fmpq(10) ** -k for k in ks]
    Vs = [[v[i] * s[i] for i in range(2)] for v in np.asarray(p["V"], dtype=object)]
    assert _rows(Vs) == _rows(q["V"])
    vs = [[v[i] * s[i] for i in range(2)] for v in np.asarray(p["v_breakpoints"], dtype=object)]
    assert vs == [list(v) for v in np.asarray(q["v_breakpoints"], dtype=object)]
    assert api.verify(rep).exit_code() == 0


def test_omega_of_unit_extent_is_not_rescaled() -> None:
    """S = I: the design's data are the spec's own (the shipped unit-box specs unchanged)."""
    data = build(api.bind(load_spec_text(_spec((0, 0)), "unit.toml")))
    same, s = scaling.scaled(data)
    assert s is None and same is data


def test_the_extents_are_exact_and_the_scaled_omega_has_unit_extent() -> None:
    data = build(api.bind(load_spec_text(_spec((-3, 5)), "s.toml")))
    work, s = scaling.scaled(data)
    assert s == [fmpq(1000), 1 / fmpq(10**5)]
    assert scaling.omega_extents(work.ex.Vo) == [1, 1]
    # the scaled problem is the unit spec's exactly (diagonal rescaling is undone)
    ref = build(api.bind(load_spec_text(_spec((0, 0)), "unit.toml")))
    for a, b in ((work.ex.A, ref.ex.A), (work.ex.B1, ref.ex.B1), (work.ex.C, ref.ex.C)):
        assert np.array_equal(np.asarray(a, dtype=object), np.asarray(b, dtype=object))
    assert np.array_equal(work.fl.A, ref.fl.A) and np.array_equal(work.fl.C, ref.fl.C)


def test_a_scaled_entry_beyond_the_float_range_keeps_the_spec_units() -> None:
    """Ω's extents 10⁻²⁰⁰ and 10²⁰⁰: S⁻¹AS would hold 10⁴⁰⁰, so the data stay as they are."""
    text = spec_text(A, B1, [C], 0.7712, omega=([-1e-200, -1e200], [1e-200, 1e200]))
    data = build(api.bind(load_spec_text(text, "far.toml")))
    same, s = scaling.scaled(data)
    assert s is None and same is data


def test_unscale_maps_rows_points_and_injections_exactly() -> None:
    s = [fmpq(2), fmpq(1, 3)]
    G = np.array([[fmpq(1), fmpq(3)], [fmpq(-1, 2), fmpq(0)]], dtype=object)
    # {G ẽ <= 1} in e = Sẽ: rows G S⁻¹, in the same order (row indices keep their facet)
    assert scaling.unscale_rows(G, s).tolist() == [[fmpq(1, 2), fmpq(9)], [fmpq(-1, 4), 0]]
    V = np.array([[fmpq(1), fmpq(3)]], dtype=object)
    assert scaling.unscale_points(V, s).tolist() == [[fmpq(2), fmpq(1)]]


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(k1=st.integers(-12, 12), k2=st.integers(-12, 12))
def test_any_diagonal_power_of_ten_gives_the_unit_design(unit, k1: int, k2: int) -> None:
    """Property: for any diagonal rescaling by powers of ten, the same certified factor and
    facet count as in the spec's own units."""
    rep = api.design(load_spec_text(_spec((k1, k2)), "scaled.toml"))
    assert rep.exit_code() == 0
    assert rep.parameters["contractivity"] == unit.parameters["contractivity"]
    assert rep.parameters["facets"] == unit.parameters["facets"]


_POLY = """[system]
time = "discrete"
A = {A}
C = {C}
[sets.omega]
type = "polytope"
G = {G}
g = [12e-1, 628e-3, 599e-3, 184e-3, 283e-2]
[method]
key = "set-invariant"
omega = "omega"
eta_bar = 1e-3
lambda = 0.9349
algorithm = "symmetric"
strict = true
delta_tol = 1e-3
fallback = "general"
linear_law = true
max_iterations = 25
"""


def test_the_designed_linear_gain_maps_with_the_coordinates() -> None:
    """p = n − 1: the admissible gains are found in the design's coordinates and mapped back
    (L = S L̃). The max-margin pick was made in the spec's coordinates and a rescaled spec,
    S = diag(10⁻⁸, 10⁵), got L = [−6.07e7; 1.83e−6] instead of S⁻¹L = [−4.87e7; 1.81e−6]
    (scaling trial, session 26)."""
    unit = _POLY.format(
        A="[[7018e-4, -3243e-4], [-1918e-4, -176e-3]]",
        C="[[105e-2, 694e-3]]",
        G="[[116e-2, -305e-1], [-245e-3, -154e-1], [-476e-3, 170e-0], [-152e-2, -142e-0], "
        "[-924e-3, 978e-1]]",
    )
    scaled = _POLY.format(
        A="[[7018e-4, -3243000000000], [-1918e-17, -176e-3]]",
        C="[[105e-10, 69400]]",
        G="[[116e-10, -3050000], [-245e-11, -1540000], [-476e-11, 17000000], "
        "[-152e-10, -14200000], [-924e-11, 9780000]]",
    )
    a = api.design(load_spec_text(unit, "unit.toml"))
    b = api.design(load_spec_text(scaled, "scaled.toml"))
    assert a.exit_code() == 0 and b.exit_code() == 0
    s = [1 / fmpq(10**8), fmpq(10**5)]
    La = np.asarray(a.parameters["L"], dtype=object)
    Lb = np.asarray(b.parameters["L"], dtype=object)
    assert [[Lb[i, 0] * s[i]] for i in range(2)] == [[La[i, 0]] for i in range(2)]
    assert a.parameters["L_factor"] == b.parameters["L_factor"]
    assert api.verify(b).exit_code() == 0
