"""Tests of obsdesign.lyap_hp: the Lyapunov-equation P in high precision, the fallback of
lyap.certified_P for a badly conditioned A − LC."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from flint import fmpq, fmpq_mat
from hypothesis import given
from hypothesis import strategies as st

from obsdesign import api, lyap, lyap_hp
from obsdesign.certify.exact import Q, qmat
from obsdesign.certify.psd import check_pd
from obsdesign.spectrum import Spectrum

#: the soundness audit's spec (session 11): a Riccati gain makes A − LC entries of ~1e5
#: around a spectral radius of 0.02; the float P failed at every rate (exit 4)
AUDIT = (
    '[system]\ntime = "discrete"\nA = [[-125123, -127590.0], [107378, 1.180e+05]]\n'
    'C = [[1.74345, -1.769e-01]]\n[method]\nkey = "lyapunov"\nlambda = 9.9e-1\n'
    "rate_tol = 1e-6\niss_gain = true\n"
)

_q = st.builds(fmpq, st.integers(-40, 40), st.integers(1, 9))


@given(st.integers(1, 3), st.booleans(), st.data())
def test_kronecker_form_is_the_decay_matrix(n: int, discrete: bool, data: st.DataObject) -> None:
    """K·vec(P) = vec(λ²P − AᵀPA) (discrete) or vec(−((A + αI)ᵀP + P(A + αI))), exactly,
    for random A, symmetric or not P, rate."""
    A = fmpq_mat(n, n, [data.draw(_q) for _ in range(n * n)])
    P = fmpq_mat(n, n, [data.draw(_q) for _ in range(n * n)])
    r = data.draw(_q)
    K = lyap_hp.kronecker_fmat(A, r, discrete)
    v = K * fmpq_mat(n * n, 1, [P[i, j] for i in range(n) for j in range(n)])
    if discrete:
        D = r * r * P - A.transpose() * P * A
    else:
        F = A + fmpq_mat(n, n, [r if i == j else 0 for i in range(n) for j in range(n)])
        D = -(F.transpose() * P + P * F)
    assert [v[k, 0] for k in range(n * n)] == [D[i, j] for i in range(n) for j in range(n)]


def _audit_system() -> tuple[object, object, object, fmpq_mat]:
    from obsdesign.methods.lyapunov.design import design_gain

    sp = api.load_spec_text(AUDIT, "audit.toml")
    Lf, _, _ = design_gain(sp, sp.options, None)
    Lm, _ = lyap.dyadic_fmat(Lf, lyap.BITS)
    A, C, L = sp.system.A.q, sp.system.C.q, lyap.as_array(Lm)
    return A, C, L, lyap.closed_loop_fmat(A, C, L)


def test_badly_conditioned_rate_certifies_only_through_the_fallback(monkeypatch) -> None:
    """λ = 0.99 against ρ ≈ 0.01: the float P fails the exact check (the fallback switched
    off: None), the high-precision P passes it; below the exact spectral radius nothing does
    (ρ of the rounded A − LC is 0.0106 with the doubling solver's Riccati gain, 0.02 with
    scipy's: the rate 0.01 is below both, and the exact test confirms it)."""
    A, C, L, Acl = _audit_system()
    r, d = fmpq(99, 100), fmpq(1, 10**9)
    P = lyap.certified_P(A, C, L, True, r, d, Acl=Acl)
    assert P is not None
    Pm = lyap.fmat(P)
    D = r * r * Pm - Acl.transpose() * Pm * Acl
    E = D - d * fmpq_mat(2, 2, [1, 0, 0, 1])
    assert E[0, 0] > 0 and E[0, 0] * E[1, 1] - E[0, 1] * E[1, 0] > 0  # Sylvester, exactly
    monkeypatch.setattr(lyap_hp, "MAX_N", 0)
    monkeypatch.setattr(lyap_hp, "DOUBLING_MAX_N", 0)  # no high-precision solve at all
    assert lyap.certified_P(A, C, L, True, r, d, Acl=Acl) is None
    monkeypatch.undo()
    low = fmpq(1, 100)
    assert not lyap.rate_feasibility(lyap.as_array(Acl), low, True)[0]  # ρ > 0.01, exactly
    assert lyap.certified_P(A, C, L, True, low, d, Acl=Acl) is None


def test_hp_P_at_an_infeasible_rate_fails_the_exact_check(monkeypatch) -> None:
    """The spectrum's skip switched off (a guide of zero eigenvalues), a rate just below the
    spectral radius: the high-precision solve runs and its P is refused by the exact check
    (not ≻ 0). With the true spectrum as guide the solve is skipped there."""
    Acl = lyap.fmat(qmat([[fmpq(1, 2), 1], [0, fmpq(1, 3)]]))
    zeros = Spectrum(np.zeros(2, dtype=complex), "a wrong guide")
    calls: list[int] = []
    real = lyap_hp.lyapunov_P_hp
    monkeypatch.setattr(lyap_hp, "lyapunov_P_hp", lambda *a: calls.append(a[-1]) or real(*a))
    got = lyap._certified_P_hp(Acl, fmpq(49, 100), True, fmpq(0), None, None, zeros)
    assert got is None and calls == list(lyap_hp.precisions(2)) == [128, 320, 1024]
    got = lyap._certified_P_hp(Acl, fmpq(51, 100), True, fmpq(0), None, None, zeros)
    assert got is not None and calls[-1] == lyap_hp.PRECISIONS[0]
    calls.clear()
    assert lyap._certified_P_hp(Acl, fmpq(49, 100), True, fmpq(0), None, None) is None
    assert calls == []  # the true spectrum (ρ = ½) puts 0.49 clearly on the infeasible side


def test_singular_equation_and_large_margin() -> None:
    """A rate with λ² = w_i·w_j (a singular Kronecker system) gives None, no exception; a
    margin δ ≥ ½ scales P by a power of two c ≥ 2δ and still certifies."""
    Acl = lyap.fmat(qmat([[fmpq(1, 2), 0], [0, fmpq(1, 2)]]))
    assert lyap_hp.lyapunov_P_hp(Acl, fmpq(1, 2), True, 128) is None
    P = lyap._certified_P_hp(Acl, fmpq(3, 4), True, fmpq(3), None, None)
    assert P is not None
    Pm = lyap.fmat(P)
    D = fmpq(9, 16) * Pm - Acl.transpose() * Pm * Acl
    # c = 8 ≥ 2δ = 6: decay matrix c·I up to the 128-bit solve (P = 8·16/5 is not dyadic)
    assert all(
        abs(D[i, j] - (8 if i == j else 0)) < fmpq(1, 2**100) for i in (0, 1) for j in (0, 1)
    )


def test_continuous_badly_conditioned() -> None:
    """Continuous time: a strongly non-normal Hurwitz A − LC (|entries| 10⁶, eigenvalues
    −1, −2) certifies α = 1/2 through the fallback."""
    k = 10**6
    Acl = lyap.fmat(qmat([[-1, k], [0, -2]]))
    P = lyap._certified_P_hp(Acl, fmpq(1, 2), False, fmpq(1, 10**9), None, None)
    assert P is not None
    Pm = lyap.fmat(P)
    F = Acl + fmpq_mat(2, 2, [fmpq(1, 2), 0, 0, fmpq(1, 2)])
    D = -(F.transpose() * Pm + Pm * F)
    assert D[0, 0] > 0 and D[0, 0] * D[1, 1] - D[0, 1] ** 2 > 0


def test_audit_spec_designs_and_verifies(tmp_path: Path) -> None:
    """The audit's spec end to end: exit 0, every claim certified, verify agrees."""
    spec = tmp_path / "audit.toml"
    spec.write_text(AUDIT)
    rep = api.design(spec)
    assert rep.exit_code() == 0
    assert all(c.status.value == "certified" for c in rep.claims)
    out = tmp_path / "r.json"
    out.write_text(rep.to_json())
    assert api.verify(out).exit_code() == 0
    assert float(rep.parameters.float("lambda_best")) < 0.021


@pytest.mark.parametrize("n", [lyap_hp.DOUBLING_MAX_N + 1])
def test_beyond_max_n_no_fallback(n: int) -> None:
    """Beyond the doubling solve's DOUBLING_MAX_N (the Kronecker solve's MAX_N before
    session 40) there is no high-precision fallback; at MAX_N + 1 the doubling solve runs."""
    Acl = lyap.fmat(qmat(np.diag([fmpq(1, 2)] * n).tolist()))
    assert lyap._certified_P_hp(Acl, fmpq(3, 4), True, fmpq(0), None, None) is None
    for m in (lyap_hp.MAX_N + 1, 48):  # 48: beyond the doubling's old limit of 40
        Acl = lyap.fmat(qmat(np.diag([fmpq(1, 2)] * m).tolist()))
        assert lyap._certified_P_hp(Acl, fmpq(3, 4), True, fmpq(0), None, None) is not None


def test_float_spectrum_far_off_does_not_skip_the_fallback(tmp_path: Path) -> None:
    """The audit's continuous example: A ~ 1e-5, a given L ~ 1e9, ‖A − LC‖ ≈ 3·10¹⁰. The
    float eigenvalues have real parts up to +2.7·10⁻³ (not Hurwitz) although the exact test
    says Hurwitz; the best α ≈ 0.1501 certifies through the fallback (the float spectrum
    put every candidate rate on the infeasible side, and the skip used to trust it)."""
    text = (Path(__file__).parent / "specs" / "lyapunov-nonnormal-continuous.toml").read_text()
    sp = api.load_spec_text(text, "nn.toml")
    Af = lyap.mat_float(lyap.closed_loop_fmat(sp.system.A.q, sp.system.C.q, sp.options.L))
    assert np.max(np.linalg.eigvals(Af).real) > 0
    rep = api.design(sp)
    assert rep.exit_code() == 0
    assert all(c.status.value == "certified" for c in rep.claims)
    assert rep.parameters["alpha_bracket_kind"] == "infeasible"
    assert fmpq(15, 100) < rep.parameters["alpha_best"] < fmpq(16, 100)
    out = tmp_path / "r.json"
    out.write_text(rep.to_json())
    assert api.verify(out).exit_code() == 0


@pytest.mark.parametrize("margin", ["0.1", "1"])
def test_margin_scale_sees_lambda_min_of_an_ill_conditioned_P(margin: str) -> None:
    """The same audit example with a margin: the high-precision P has entries up to ~10²⁶ and
    λ_min ≈ 0.07, which float eigvalsh cannot resolve (it gave −8.9·10⁷), so P was not scaled
    and missed the margin (exit 4 with a certificate at hand — lyapunov review). λ_min now
    comes from the exact inverse; margin_scale without it keeps the old guess."""
    text = (Path(__file__).parent / "specs" / "lyapunov-nonnormal-continuous.toml").read_text()
    sp = api.load_spec_text(text + f"margin = {margin}\n", "nn.toml")
    rep = api.design(sp)
    assert rep.exit_code() == 0
    assert all(c.status.value == "certified" for c in rep.claims)
    P = rep.parameters["P"]
    Pm = lyap.fmat(P)
    Pf = lyap.mat_float(Pm)
    # the guide: with the exact P the scale is at least 2δ/λ_min, without it only 2δ
    lmin = lyap._lambda_min_by_inverse(Pm, -1.0)
    assert lmin > 0
    assert lyap.margin_scale(Pf, Q(margin), Pm) >= lyap.margin_scale(Pf, Q(margin))


# -- mutation review 22 (obsdesign/lyap_hp.py) -------------------------------------------------
@pytest.mark.parametrize(
    "acl, rate, discrete, want",
    [
        ([[0, 0], [0, 0]], fmpq(1, 2), True, [[4, 0], [0, 4]]),
        ([[0, 0], [0, 0]], 1, True, [[1, 0], [0, 1]]),
        ([["-17/8", 0], [0, "-9/4"]], 2, False, [[4, 0], [0, 2]]),
    ],
)
def test_hp_P_with_integer_entries_is_exact(acl: list, rate: object, discrete: bool, want: list):
    """Kills `lyapunov_P_hp` 51 (`m << e` → `m >> e`: an entry m·2^e with e > 0, an even
    integer, lost its exponent: 4 became 0) and 11 (a rate given as a Python int converted as
    fmpq(None)): the Lyapunov P with decay matrix I of a diagonal Acl, at rates where it is
    an integer matrix (λ = 1/2, Acl = 0: 4I; continuous, F = Acl + 2I = diag(−1/8, −1/4):
    diag(4, 2)), comes back exactly, and its decay matrix is I exactly."""
    Am = lyap.fmat(qmat(acl))
    P = lyap_hp.lyapunov_P_hp(Am, rate, discrete, 128)
    assert P == fmpq_mat(want)
    assert lyap.decay_fmat(Am, P, Q(rate), discrete) == fmpq_mat([[1, 0], [0, 1]])


#: the lyapunov trial's 6-state plant (session 39): ‖A − LC‖ ≈ 9·10¹¹ around a spectral
#: radius of 0.0028 (entries 10⁻⁸ … 10⁸); 128 and 320 bits gave no P at λ = 0.01 (exit 4)
SCALES = Path(__file__).parent / "data" / "lyapunov-scales-6state.toml"


def test_the_exact_solve_certifies_where_320_bits_do_not(monkeypatch) -> None:
    """λ = 0.01 for the 6-state plant: the exact rational P (decay matrix exactly I) rounded
    to 512 relative bits passes the exact checks; without the exact fallback (EXACT_MAX_N =
    0) nothing does, as before; below the spectral radius (λ = 0.0027) nothing does either
    (the exact P is then not ≻ 0). The 1024-bit solve (session 41) is switched off: this is
    the exact fallback's test."""
    monkeypatch.setattr(lyap_hp, "WIDE_MAX_N", 0)
    sp = api.load_spec(SCALES)
    s = sp.system
    L = lyap.fmat(sp.options.L)
    Acl = lyap.closed_loop_fmat(s.A.q, s.C.q, L)
    Lq = lyap.as_array(L)
    d = fmpq(1, 10**9)
    P = lyap.certified_P(s.A.q, s.C.q, Lq, True, fmpq(1, 100), d, Acl=Acl)
    assert P is not None
    Pm = lyap.fmat(P)
    r = fmpq(1, 100)
    eye = fmpq_mat(6, 6, [int(i == j) for i in range(6) for j in range(6)])
    assert check_pd(lyap.as_array(Pm - d * eye)).ok  # P − δI ≻ 0 and the decay LMI, exactly
    assert check_pd(lyap.as_array(r * r * Pm - Acl.transpose() * Pm * Acl - d * eye)).ok
    assert lyap.certified_P(s.A.q, s.C.q, Lq, True, fmpq(27, 10000), d, Acl=Acl) is None
    monkeypatch.setattr(lyap_hp, "EXACT_MAX_N", 0)
    assert lyap.certified_P(s.A.q, s.C.q, Lq, True, fmpq(1, 100), d, Acl=Acl) is None


def test_exact_P_has_the_decay_matrix_I_and_rounding_stays_close() -> None:
    Acl = lyap.fmat(qmat([[fmpq(1, 2), 1000], [0, fmpq(-1, 3)]]))
    r = fmpq(3, 5)
    P = lyap_hp.lyapunov_P_exact(Acl, r, True)
    assert P is not None and P == P.transpose()
    assert r * r * P - Acl.transpose() * P * Acl == fmpq_mat(2, 2, [1, 0, 0, 1])
    R = lyap_hp.round_relative(P, 64)
    top = max(abs(P[i, j]) for i in (0, 1) for j in (0, 1))
    assert all(abs(R[i, j] - P[i, j]) <= top / 2**62 for i in (0, 1) for j in (0, 1))
    assert (
        lyap_hp.lyapunov_P_exact(
            lyap.fmat(qmat([[fmpq(1, 2), 0], [0, fmpq(1, 2)]])), fmpq(1, 2), True
        )
        is None
    )


def test_an_exact_P_beyond_the_reports_digits_is_not_taken(monkeypatch) -> None:
    """A candidate whose exact strings exceed max_digits would make a report verify cannot
    read back: with max_digits = 60 the 6-state plant's fallback gives nothing."""
    from obsdesign.limits import limits, reset_limits, set_limits

    sp = api.load_spec(SCALES)
    s = sp.system
    L = lyap.fmat(sp.options.L)
    Acl = lyap.closed_loop_fmat(s.A.q, s.C.q, L)
    old = set_limits(max_digits=60)
    try:
        assert limits().max_digits == 60
        got = lyap._certified_P_exact(
            Acl, fmpq(1, 100), True, fmpq(1, 10**9), None, lyap.mat_float(Acl)
        )
        assert got is None
    finally:
        reset_limits(old)


@pytest.mark.parametrize("wide", [0, 40])
def test_an_exact_P_beyond_the_float_range_is_scaled_into_it(monkeypatch, wide: int) -> None:
    """A 4×4 Jordan block (0.5, superdiagonal 10⁶) at λ = ½ + 10⁻⁴⁰, margin 10⁻²⁰: the exact
    fallback's P had entries beyond the float range, and the design stopped with exit 4 "an
    exact value lies beyond the float range" (re-check trial, session 39). Scaled down to
    about 2^1020 it still passes the exact checks; the report verifies. With the 1024-bit
    solve (session 41; wide = 40) its P reaches the same block and is scaled the same way
    (without that it was exit 4 again); wide = 0 tests the exact fallback."""
    monkeypatch.setattr(lyap_hp, "WIDE_MAX_N", wide)
    text = (
        '[system]\ntime = "discrete"\nA = [[0.5, 1000000, 0, 0], [0, 0.5, 1000000, 0], '
        "[0, 0, 0.5, 1000000], [0, 0, 0, 0.5]]\nC = [[1, 0, 0, 0]]\n[method]\n"
        'key = "lyapunov"\nL = [0, 0, 0, 0]\n'
        "lambda = 0.50000000000000000000000000000000000000001\nmargin = 1e-20\n"
    )
    rep = api.design(api.load_spec_text(text, "jd4.toml"))
    assert rep.exit_code() == 0, [(c.id, c.detail) for c in rep.failed]
    P = np.asarray(rep.parameters.float("P"), dtype=float)
    assert np.all(np.isfinite(P)) and np.max(np.abs(P)) > 1e300
    assert api.verify(rep).exit_code() == 0


def _jordan(n: int, mu: int) -> str:
    """A discrete / continuous spec of the n-state Jordan block at mu, C = e₁."""
    rows = ", ".join(
        "[" + ", ".join(str(mu if i == j else int(j == i + 1)) for j in range(n)) + "]"
        for i in range(n)
    )
    t = "discrete" if mu == 1 else "continuous"
    c = ", ".join(["1"] + ["0"] * (n - 1))
    return f'[system]\ntime = "{t}"\nA = [{rows}]\nC = [[{c}]]\n[method]\nkey = "lyapunov"\n'


@pytest.mark.parametrize("discrete", [True, False])
def test_the_doubling_solve_solves_the_lyapunov_equation(discrete: bool) -> None:
    """lyapunov_P_doubling (Smith's doubling; continuous through the Cayley transform) on an
    18-state matrix with spectral radius 0.9 / abscissa −0.1 and a rate beyond it: the exact
    residual of λ²P − AᵀPA = I (or FᵀP + PF = −I) is below 2⁻²⁰⁰ of |P|; a rate on the wrong
    side of the spectrum gives None."""
    rng = np.random.default_rng(7)
    n = 18
    M = rng.standard_normal((n, n))
    M *= 0.9 / np.max(np.abs(np.linalg.eigvals(M)))
    if not discrete:
        M = M - 1.0 * np.eye(n)  # abscissa ≤ −0.1
    A = fmpq_mat(n, n, [Q(float(x)) for x in M.ravel()])
    rate = fmpq(95, 100) if discrete else fmpq(1, 20)
    P = lyap_hp.lyapunov_P_doubling(A, rate, discrete, 320)
    assert P is not None and P == P.transpose()
    eye = fmpq_mat(n, n, [int(i == j) for i in range(n) for j in range(n)])
    if discrete:
        R = P * (rate * rate) - A.transpose() * P * A - eye
    else:
        F = A + eye * rate
        R = F.transpose() * P + P * F + eye
    big = max(abs(P[i, j]) for i in range(n) for j in range(n))
    assert max(abs(R[i, j]) for i in range(n) for j in range(n)) < big * fmpq(1, 2**200)
    wrong = fmpq(1, 2) if discrete else fmpq(2)  # inside the spectrum
    assert lyap_hp.lyapunov_P_doubling(A, wrong, discrete, 128) is None


def test_a_20_state_jordan_block_certifies_beyond_the_kronecker_solve() -> None:
    """The 20-state Jordan block at 1 (discrete, C = e₁) with its Riccati gain: "A − LC is
    Schur (exact test) but no decay rate λ < 1 could be certified", exit 4 — the float P
    fails the exact check and the high-precision (Kronecker) solve stopped at 16 states
    (lyapunov trial, session 40). The doubling solve, for 16 < n ≤ 40, certifies it; the
    rates stay exact claims and verify agrees."""
    rep = api.design(api.load_spec_text(_jordan(20, 1), "j20.toml"))
    assert rep.exit_code() == 0
    assert float(rep.parameters.float("lambda_best")) < 1
    assert api.verify(rep).exit_code() == 0
