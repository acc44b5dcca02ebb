"""Tests of obsdesign/spectrum.py: the eigenvalue guide (float eigenvalues when their
Bauer–Fike bound is small, python-flint ones otherwise)."""

from __future__ import annotations

import numpy as np
import pytest
from flint import fmpq, fmpq_mat
from hypothesis import given, settings
from hypothesis import strategies as st

from obsdesign import lyap, spectrum
from obsdesign.certify.exact import Q
from obsdesign.spectrum import FLOAT_SOURCE, Spectrum, eig_hp


def _exact(M: list[list[int | fmpq]]) -> fmpq_mat:
    return fmpq_mat([[fmpq(x) for x in row] for row in M])


def test_a_well_conditioned_matrix_keeps_its_float_eigenvalues() -> None:
    Am = _exact([[fmpq(1, 2), 1], [0, fmpq(-1, 3)]])
    g = spectrum.spectrum(Am, lyap.mat_float(Am))
    assert g.source == FLOAT_SOURCE and g.V is not None and g.Vi is not None
    assert g.bound(True) == pytest.approx(0.5, abs=1e-15)
    assert g.bound(False) == pytest.approx(0.5, abs=1e-15)


def test_a_defective_non_normal_matrix_takes_high_precision_eigenvalues(jordan_in_disguise) -> None:
    """A triple eigenvalue 0.9 in disguise: numpy's radius is off (here by more than 10⁻⁶);
    the guide's is 0.9 to 10⁻¹², from the exact characteristic polynomial (python-flint),
    with no float eigenvectors."""
    Am = jordan_in_disguise(fmpq(9, 10), 3, 1000)
    Af = lyap.mat_float(Am)
    assert abs(float(np.max(np.abs(np.linalg.eigvals(Af)))) - 0.9) > 1e-6
    g = spectrum.spectrum(Am, Af)
    assert g.source == spectrum.CHARPOLY_SOURCE and g.V is None
    assert g.bound(True) == pytest.approx(0.9, abs=1e-12)
    assert g.bound(False) == pytest.approx(0.9, abs=1e-12)


def test_above_the_size_limit_the_float_eigenvalues_stay(
    monkeypatch: pytest.MonkeyPatch, jordan_in_disguise
) -> None:
    Am = jordan_in_disguise(fmpq(9, 10), 3, 1000)
    monkeypatch.setattr(spectrum, "HP_MAX_N", 2)
    g = spectrum.spectrum(Am, lyap.mat_float(Am))
    # labelled: "spectral radius ≈ 6064.19" was printed for an exact 0.9 (session 34)
    assert g.source.startswith(FLOAT_SOURCE + ", not reliable here: their Bauer–Fike error")
    assert abs(g.bound(True) - 0.9) > 1e-6  # the poor float answer, as documented


def test_the_characteristic_polynomial_first_else_agreeing_precisions(
    monkeypatch: pytest.MonkeyPatch, jordan_in_disguise
) -> None:
    """The exact characteristic polynomial's roots decide; without them (monkeypatched away)
    two precisions of acb_mat.eig in a row must agree, else the last is taken."""
    Am = jordan_in_disguise(fmpq(1, 2), 2, 10)
    w, src = eig_hp(Am)  # type: ignore[misc]
    assert src == spectrum.CHARPOLY_SOURCE and np.allclose(w, 0.5, atol=1e-15)
    monkeypatch.setattr(spectrum, "charpoly_roots", lambda Am: None)
    w, src = eig_hp(Am)  # type: ignore[misc]
    assert src == f"python-flint eigenvalues at {spectrum.PRECISIONS[1]} bits"
    assert np.allclose(w, 0.5, atol=1e-15)
    monkeypatch.setattr(spectrum, "AGREE_TOL", -1.0)  # never agree
    w, src = eig_hp(Am)  # type: ignore[misc]
    assert src == f"python-flint eigenvalues at {spectrum.PRECISIONS[-1]} bits"


def _jordan_beside_a_pair() -> fmpq_mat:
    """T J T⁻¹ with J = diag(−0.1 ± 3i as a real 2×2 block, a 4×4 Jordan block at −0.5) and
    T an integer unimodular matrix of 30 seeded elementary steps: the trial's A − LC, on
    which acb_mat.eig at 320 and 1024 bits is far off."""
    n = 6
    J = [[fmpq(0)] * n for _ in range(n)]
    J[0][0], J[0][1], J[1][0], J[1][1] = fmpq(-1, 10), fmpq(3), fmpq(-3), fmpq(-1, 10)
    for i in range(2, 6):
        J[i][i] = fmpq(-1, 2)
        if i < 5:
            J[i][i + 1] = fmpq(1)
    T = fmpq_mat(n, n, [1 if i == j else 0 for i in range(n) for j in range(n)])
    rng = np.random.default_rng(0)
    for _ in range(30):
        i, j = rng.choice(n, 2, replace=False)
        E = fmpq_mat(n, n, [1 if a == b else 0 for a in range(n) for b in range(n)])
        E[int(i), int(j)] = int(rng.integers(-3, 4))
        T = T * E
    return T * fmpq_mat(J) * T.inv()


def test_a_jordan_block_beside_a_pair_gets_its_true_spectrum() -> None:
    """The guide of the trial's A − LC (exact spectrum −0.1 ± 3i, −0.5 four times) is within
    10⁻³ of it, whatever source decided (it said abscissa +3.02 before)."""
    Am = _jordan_beside_a_pair()
    g = spectrum.spectrum(Am, lyap.mat_float(Am))
    assert g.bound(False) == pytest.approx(-0.1, abs=1e-3)
    assert g.bound(True) == pytest.approx(abs(complex(-0.1, 3)), abs=1e-3)
    w = spectrum.charpoly_roots(Am)
    assert w is not None and sorted(np.round(w.real, 9)) == [-0.5] * 4 + [-0.1] * 2


def test_empty_spectrum_bounds() -> None:
    g = Spectrum(np.zeros(0, dtype=complex), FLOAT_SOURCE)
    assert g.bound(True) == 0.0 and g.bound(False) == -np.inf


@settings(max_examples=30, deadline=None)
@given(
    st.integers(1, 6).flatmap(
        lambda n: st.lists(
            st.lists(st.integers(-20, 20), min_size=n, max_size=n), min_size=n, max_size=n
        )
    ),
    st.integers(0, 4),
)
def test_the_guide_agrees_with_high_precision_eigenvalues(rows: list[list[int]], k: int) -> None:
    """Random integer matrices, scaled by 10^k (badly scaled ones included): whichever source
    the guide takes, its radius and abscissa agree with python-flint's 1024-bit eigenvalues
    to its documented tolerance (float: relative 10⁻⁹ when its error bound allows it)."""
    Am = _exact(rows) * 10**k
    Af = lyap.mat_float(Am)
    g = spectrum.spectrum(Am, Af)
    ref = eig_hp(Am)
    assert ref is not None
    w = ref[0]
    size = max(1.0, float(np.max(np.abs(w))))
    tol = 1e-7 * size  # a defective eigenvalue at 128 bits agrees to ~u^(1/n) of 2^-128
    assert abs(g.bound(True) - float(np.max(np.abs(w)))) <= tol
    assert abs(g.bound(False) - float(np.max(w.real))) <= tol


#: the trial's (5/16)·T J T⁻¹, J = (−0.1 ± 3i, a 5×5 Jordan block at 0.6), T unimodular
MISPLACED_PAIR = [
    [53.84375, -31.09375, 13.46875, -6.40625, -17.25, 246.3125, 254.21875],
    [-105.9375, -469.09375, -26.25, -93.8125, -190.125, 1008.71875, -471.5625],
    [-45.875, 127.5, -11.5, 26.25, 56.5, -498.0625, -216.25],
    [-7.8125, 1037.03125, -3.125, 207.375, 439.0625, -2943.59375, -97.5],
    [130, 373.4375, 32.5, 74.6875, 148, -667.1875, 589.6875],
    [-18.75, -37.5, -4.6875, -7.5, -14.375, 50.5, -86.25],
    [5, 29.6875, 1.25, 5.9375, 12.1875, -68.75, 21.75],
]


def test_agreeing_precisions_that_misplace_a_pair_do_not_decide() -> None:
    """On this matrix acb_mat.eig at 320 and 1024 bits agreed on radius and abscissa (both
    set by the Jordan block at 0.1875) while misplacing the pair, and the guide said radius
    0.1875 for 0.938 (re-check trial, session 32). The exact characteristic polynomial gives
    0.938 = (5/16)·|−0.1 ± 3i|."""
    Am = fmpq_mat([[Q(str(x)) for x in row] for row in MISPLACED_PAIR])
    g = spectrum.spectrum(Am, lyap.mat_float(Am))
    assert g.bound(True) == pytest.approx(abs(complex(-0.1, 3)) * 5 / 16, abs=1e-6)


def test_the_characteristic_polynomial_is_skipped_for_huge_common_denominators() -> None:
    """Distinct 40-bit denominators in a 24×24 matrix made the exact characteristic
    polynomial's roots take a minute (second re-check trial, session 32): above
    CHARPOLY_MAX_BITS (n × the common denominator's bits) they are skipped and acb_mat.eig
    decides; a decimal matrix's small common denominator keeps them."""
    n = 24
    rng = np.random.default_rng(3)
    odd = [
        fmpq(int(rng.integers(-(2**40), 2**40)), int(rng.integers(2**40, 2**41)))
        for _ in range(n * n)
    ]
    Am = fmpq_mat(n, n, odd)
    assert n * spectrum._denominator_bits(Am) > spectrum.CHARPOLY_MAX_BITS
    assert spectrum.charpoly_roots(Am) is None
    got = eig_hp(Am)
    assert got is not None and got[1].startswith("python-flint eigenvalues at")
    dec = fmpq_mat(n, n, [fmpq(int(rng.integers(-999, 1000)), 1000) for _ in range(n * n)])
    assert spectrum.charpoly_roots(dec) is not None


# -- mutation review 33 (session 32's checks) ----------------------------------------
def test_charpoly_roots_beyond_the_float_range_are_none() -> None:
    """An eigenvalue 10⁴⁰⁰ has no float: charpoly_roots gives None (kills P08, which
    returned [inf] and let eig_hp report a non-finite spectrum as exact roots)."""
    Am = fmpq_mat([[fmpq(10**400)]])
    assert spectrum.charpoly_roots(Am) is None
    got = spectrum.eig_hp(Am)
    assert got is None or got[1] != spectrum.CHARPOLY_SOURCE


def test_figure_names_its_source_unless_accurate_floats(
    monkeypatch: pytest.MonkeyPatch, jordan_in_disguise
) -> None:
    """The "≈" figure of messages names where it comes from: nothing for accurate float
    eigenvalues, the exact characteristic polynomial where floats are poor (n ≤ 24), and
    "not reliable here" with the Bauer–Fike bound above 24 states ("spectral radius ≈
    6064.19" was printed unlabelled for an exact radius of 0.9; lyapunov trial, session 34)."""
    diag = lyap.fmat(np.diag([0.5, -0.25]))
    g = spectrum.spectrum(diag, lyap.mat_float(diag))
    assert g.figure(True) == "spectral radius ≈ 0.5"
    assert g.figure(False) == "largest real part ≈ 0.5"
    Am = jordan_in_disguise(fmpq(1, 2), 3, 1000)
    g = spectrum.spectrum(Am, lyap.mat_float(Am))
    assert (
        g.figure(True) == "spectral radius ≈ 0.5 from roots of the exact characteristic polynomial"
    )
    monkeypatch.setattr(spectrum, "HP_MAX_N", 2)
    g = spectrum.spectrum(Am, lyap.mat_float(Am))
    assert g.figure(True).startswith("spectral radius ≈ 0.5")
    assert " from float eigenvalues, not reliable here: their Bauer–Fike error bound is ≈ " in (
        g.figure(True)
    )


# -- mutation review 34 (session 33's checks) ----------------------------------------
def test_agree_compares_the_abscissa_too() -> None:
    """Kills P05 (_agree on the spectral radius alone): {1, −0.5} and {−1, 0.5} have the same
    radius 1 but abscissas 1 and 0.5: two precisions giving them do not agree (the stability
    verdict is read from the abscissa)."""
    a = np.array([1.0 + 0j, -0.5 + 0j])
    b = np.array([-1.0 + 0j, 0.5 + 0j])
    assert not spectrum._agree(a, b)
    assert spectrum._agree(a, a.copy())


def test_agree_compares_the_radius_too() -> None:
    """Kills P06 (_agree on the abscissa alone): {0.5, −1} and {0.5, −2}."""
    assert not spectrum._agree(np.array([0.5 + 0j, -1 + 0j]), np.array([0.5 + 0j, -2 + 0j]))


def test_high_precision_eigenvalues_up_to_64_states() -> None:
    """A 48-state Jordan block at 1/2 (defective: float eigenvalues are off by ~u^(1/48), their
    error bound is useless) gets its eigenvalues from the exact characteristic polynomial: the
    radius 1/2. Until session 41 the limit was 24 states, and a 64-state continuous Jordan
    plant's search took a float abscissa of −0.0166 for −0.0483."""
    n = 48
    A = np.diag([0.5] * n) + np.diag([1.0] * (n - 1), 1)
    Am = lyap.fmat(A)
    g = spectrum.spectrum(Am, A)
    assert g.source.startswith("roots of the exact characteristic polynomial"), g.source
    assert abs(g.bound(True) - 0.5) < 1e-12
