"""Design of the ``lyapunov`` method: the gain (given, or designed by a Riccati equation, by
pole placement or by an LMI), the certified P at the asked rate, the best rate with its
bracket, the ISS gain μ.

The Lyapunov function is the linear case of eq. (4)-(7), Section 5 of Astolfi, Bernard,
Postoyan, Marconi, "Redesign of discrete-time nonlinear observers with state estimate
constraints guaranteed in prescribed convex set", NOLCOS 2019; the maths is in
:mod:`obsdesign.lyap`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from flint import fmpq, fmpq_mat

from obsdesign import lyap
from obsdesign.certify.detect import Detectability, detectability, unobservable_restriction
from obsdesign.certify.printing import fmt_exact
from obsdesign.certify.psd import check_pd
from obsdesign.errors import (
    InconclusiveError,
    InfeasibleError,
    ObsdesignError,
    SolverError,
    SpecError,
)
from obsdesign.methods.base import Design, Progress, SolverResult, SolverStatus
from obsdesign.methods.lyapunov.options import Options
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec
from obsdesign.spectrum import spectrum


def _float_viewable(key: str, P: Any, rate: Any, name: str, o: Options) -> None:
    """InconclusiveError (exit 4) naming the rate and what to change when an entry of the
    certified P is beyond the float range, so that the report cannot show it. The decay LMI
    with the margin δ (eq. (4)-(6), constrained-redesign paper) needs λ²P − (A − LC)ᵀP(A − LC)
    ⪰ δI: at a rate near 0 (a dead-beat gain, rate_tol = 1e-100: λ = 10⁻¹⁰⁰) that P reaches
    10⁴⁰⁰, and the design ended with the report's generic "parameter 'P': integer division
    result too large for a float" (degenerate-sizes review, session 42)."""
    if not lyap.beyond_float(P):
        return
    # P is at the asked rate when one is given, P_best at the best one, which rate_tol sets
    # (the P_best message said "a larger [method].lambda" with λ given; re-check review)
    asked = key == "P" and o.rate is not None
    which = (
        f"a larger [method].{name}"
        if asked
        else f"a larger [method].rate_tol (now {fmt_exact(o.rate_tol)})"
        + ("" if o.rate is not None else f" or [method].{name}")
    )
    at = name if key == "P" else f"{name}_best"
    raise InconclusiveError(
        f"the certificate {key} at {at} = {fmt_exact(rate)} has entries beyond the float "
        f"range (the decay LMI with margin δ = {fmt_exact(o.margin)} needs a P that large at "
        "that rate), so the report cannot give its float view: a smaller [method].margin "
        f"(margin = 0 is allowed), or {which}"
    )


def rate_name(discrete: bool) -> str:
    """``lambda`` (discrete, eq. (6): ρ = λ²) or ``alpha`` (continuous), the parameter name of
    the decay rate of V (Section 5, constrained-redesign paper).

    :param discrete: time domain."""
    return "lambda" if discrete else "alpha"


class NoRiccatiGain(InconclusiveError):
    """The float Riccati solvers gave no finite gain although (C, A) is detectable (exit 4,
    unless the high-precision solve gives one). ``hinted``: its message already says what to
    try (an extreme rate, :func:`_extreme_rate`)."""

    hinted = False


def design(spec: Spec, progress: Progress | None = None) -> Design:
    """Parameters of the ``lyapunov`` method: L, P at the asked (or best) rate, the best rate
    with its bracket (``<rate>_best``, ``<rate>_bracket``, ``<rate>_bracket_kind``) and μ.

    Decay LMI eq. (4)-(6), ISS inequality eq. (5)-(7), Section 5 of the constrained-redesign
    paper (Astolfi et al., NOLCOS 2019). A rate given in the spec is checked directly, before
    any search; the best-rate search then never reports a worse rate.

    :param spec: the bound spec (``spec.options`` is :class:`Options`);
    :param progress: callback for progress messages."""
    o: Options = spec.options
    s = spec.system
    notes: list[str] = []
    solver = SolverResult(
        lyap.lyapunov_solver_name(s.n, s.discrete),
        SolverStatus.CLOSED_FORM,
        "L given; P from one Lyapunov equation per rate, checked exactly",
        extra={"gain_design": "given"},
    )
    if o.L is None:
        try:
            return _designed(spec, o, progress)
        except InconclusiveError as e:
            if o.design != "lmi":
                raise
            return _lmi_fallback(spec, o, e, progress)
    return _design_for(spec, o.L, None, solver, notes, progress)


def _designed(spec: Spec, o: Options, progress: Progress | None) -> Design:
    """The design with a designed gain (``o.design``): the float gain rounded to 40 bits,
    else the high-precision Riccati gain (discrete ``riccati`` only), each certified by
    :func:`_design_for` (eq. (4)-(6), constrained-redesign paper, Section 5).

    :param spec: the bound spec; :param o: the options to design by (``o.design``);
    :param progress: callback."""
    asked = o.rate is not None
    first: InconclusiveError
    try:
        Lf, solver, how = design_gain(spec, o, progress)
    except NoRiccatiGain as e:  # no float gain at all
        first = e
    else:
        Lm, _ = lyap.dyadic_fmat(Lf, lyap.BITS)  # = dyadic(Lf, BITS), in flint
        try:
            return _design_rounded(spec, Lm, lyap.BITS, solver, how, progress)
        except InfeasibleError as e:
            first = designed_gain_failed(e, how, Lm, asked, o)
        except InconclusiveError as e:
            _keep_gain(e, Lm)
            raise
    # the float Riccati gain is missing or failed the exact tests: the high-precision one
    hp = riccati_retry_hp(spec, o)
    if hp is None:
        raise _hp_outcome(first, spec, o) from None
    Lm, bits, solver, how = hp
    try:
        return _design_rounded(spec, Lm, bits, solver, how, progress)
    except InfeasibleError as e2:
        raise designed_gain_failed(e2, how, Lm, asked, o) from None
    except InconclusiveError as e3:
        _keep_gain(e3, Lm)
        raise


def _hp_outcome(e: InconclusiveError, spec: Spec, o: Options) -> InconclusiveError:
    """``e`` (the float Riccati gain's failure) saying what the high-precision retry
    (:func:`riccati_retry_hp`) did: found no gain that certifies, or did not run (more than
    :data:`obsdesign.riccati.HP_MAX_N` states). The message read as if only the float solve
    had run (lyapunov trial, session 40). Other designs (``place``) have no such retry.

    :param e: the error to raise; :param spec: the bound spec; :param o: its options."""
    from obsdesign.riccati import HP_MAX_N

    if o.design != "riccati":
        return e
    n = spec.system.n
    said = (
        f"; the high-precision Riccati retry runs up to {HP_MAX_N} states (n = {n})"
        if n > HP_MAX_N
        else "; the high-precision Riccati retry found no gain that certifies either"
    )
    if isinstance(e, NoRiccatiGain) and not e.hinted:
        # the designed-gain failure says what to try; this one said nothing (re-check
        # trial, session 41)
        said += '; give L, or try design = "lmi" or other weights (riccati_Q, riccati_R)'
    e.message = e.message + said
    e.args = (e.message,)
    return e


def _keep_gain(e: ObsdesignError, Lm: fmpq_mat) -> ObsdesignError:
    """``e`` with the designed gain it failed on as its candidate: the error report (``-o``)
    holds that L, not certified, so that a user can give it in the spec and check it at
    another rate or margin (an error report held no L: lyapunov trial, session 38)."""
    e.candidate = Parameters({"L": lyap.as_array(Lm)})
    return e


def _lmi_fallback(
    spec: Spec, o: Options, lmi_error: InconclusiveError, progress: Progress | None
) -> Design:
    """design = "lmi" when the LMI gave no gain that certifies (Clarabel fails on badly
    scaled or badly conditioned plants; review 19: 15 of 167 LMI designs were exit 4 where
    the default design certifies): the default Riccati design (its float and high-precision
    gains, shifted to an asked rate), reported as such — ``solver.gain_design`` stays
    ``"lmi"`` with ``lmi_fallback = "riccati"``, and a note gives the LMI's failure. The
    LMI's own error is raised when the Riccati design fails too. Decay LMI eq. (4)-(6),
    Section 5 of the constrained-redesign paper (Astolfi et al., NOLCOS 2019).

    :param spec: the bound spec; :param o: its options; :param lmi_error: why the LMI design
    failed; :param progress: callback."""
    import dataclasses

    ric = dataclasses.replace(o, design="riccati", riccati_Q=None, riccati_R=None)
    why = lmi_error.message.split(_LMI_HINT)[0]
    try:
        d = _designed(spec, ric, progress)
    except (InconclusiveError, InfeasibleError) as e:
        # the LMI error's own hint ("omit design") cannot help once Riccati failed too
        # (lyapunov fuzz, session 38)
        both = type(lmi_error)(f"{why}; the Riccati design failed too: {e.message}")
        both.candidate = e.candidate  # the Riccati L it failed on, if any
        raise both from None
    d.notes.insert(0, f"the LMI gain design gave no certified gain ({why}): L is the Riccati gain")
    if isinstance(d.solver, SolverResult):
        d.solver.extra.update(gain_design="lmi", lmi_fallback="riccati")
        d.solver.message = "LMI found no certified gain; " + d.solver.message
    return d


def _design_rounded(
    spec: Spec,
    Lm: fmpq_mat,
    bits: int,
    solver: SolverResult,
    how: str,
    progress: Progress | None,
) -> Design:
    """:func:`_design_for` a designed gain rounded to ``bits`` significant bits (the rounded
    values are the gain certified and reported).

    :param spec: the bound spec; :param Lm: the rounded gain (exact); :param bits: its bits;
    :param solver: its solver result; :param how: the path that designed it;
    :param progress: callback."""
    notes = [f"L designed by {how}; certified with L rounded to {bits} bits"]
    return _design_for(spec, lyap.as_array(Lm), Lm, solver, notes, progress)


def designed_gain_failed(
    e: InfeasibleError, how: str, Lm: fmpq_mat, rate_asked: bool, o: Options | None = None
) -> InconclusiveError:
    """The error for a *designed* L that misses the asked rate or is not Schur / Hurwitz at
    all: inconclusive (exit 4), not infeasible. :func:`design_gain` proved exactly that
    (C, A) is detectable and that its unobservable modes meet an asked rate, so some L
    reaches it (the observable part's poles are assignable); only this float design failed —
    in practice on a badly conditioned plant, e.g. a 3-state plant with ρ(A) ≈ 2000 and one
    output, where the float Riccati solution (scipy's QZ and the doubling alike) or the
    placement is wrong (found by the spec fuzzer). The decay LMI is eq. (4)-(6), Section 5
    of the constrained-redesign paper (Astolfi et al., NOLCOS 2019).

    :param e: the exact verdict about the designed L; :param how: the design path;
    :param Lm: the gain (exact); :param rate_asked: whether the spec asks a rate;
    :param o: the options (a singular ``riccati_Q`` is named as the likelier cause)."""
    also = " and its unobservable modes meet the rate" if rate_asked else ""
    big = f"max |L| ≈ {float(np.abs(lyap.mat_float(Lm)).max()):.3g}"
    if o is not None and o.riccati_Q is not None and not check_pd(o.riccati_Q):
        # Q = 0 on a rotation (|z| = 1) gives L = 0, as the Riccati equation should: the
        # message blamed a "badly conditioned plant" (soundness trial, session 30)
        why = (
            f"the Riccati gain for the singular riccati_Q ({big}) leaves the modes of A that Q "
            "does not weight where they are, and modes on the stability boundary then stay "
            "there; give a positive definite riccati_Q, L, or another design"
        )
    else:
        why = (
            f"the float design by {how} is inaccurate on this badly conditioned plant ({big}); "
            "give L, or try another design or weights"
        )
    err = InconclusiveError(
        f"the designed gain fails: {e.message}; yet some L succeeds ((C, A) is detectable"
        f"{also}, proved exactly): {why}"
    )
    return _keep_gain(err, Lm)


def _design_for(
    spec: Spec,
    L: Any,
    Lm: Any,
    solver: SolverResult,
    notes: list[str],
    progress: Progress | None,
) -> Design:
    """:func:`design` for the gain L (given, or designed and rounded: then ``Lm`` is its
    ``fmpq_mat``): P at the asked or best rate, the bracket and μ, eq. (4)-(7) of the
    constrained-redesign paper (Section 5). InfeasibleError when L misses the asked rate or
    is not Schur / Hurwitz (proved exactly).

    :param spec: the bound spec; :param L: the gain (exact object array);
    :param Lm: L as an ``fmpq_mat`` or None; :param solver: the solver result so far;
    :param notes: the design notes so far; :param progress: callback."""
    o: Options = spec.options
    s = spec.system
    A, C = s.A.q, s.C.q
    memo = lyap.ExactMemo()  # the exact verdicts, reused by certify in this process only
    Lm = lyap.fmat(L) if Lm is None else Lm
    Acl = lyap.closed_loop_fmat(A, C, Lm)
    # A − LC for this L and A, C with these very entries (copies, compared entry by entry
    # in certify: 0.8 ms at n = 100); keyed by L alone, a copy of the spec given another A
    # reused it and api.certify certified a decay LMI false for that A, and so did an A
    # edited through its writable base array after identity was checked (API and re-check
    # reviews, session 42)
    memo.put(lyap.CLOSED_LOOP_KEY, (Lm,), (A.copy(), C.copy(), Acl))
    Af = lyap.mat_float(Acl)  # converted once: the float guide of every step below
    # the eigenvalues, a guide (float ones, or high-precision ones when those are inaccurate)
    guide = spectrum(Acl, Af)
    bound = guide.bound(s.discrete)
    params = Parameters({"L": L})
    name = rate_name(s.discrete)
    sym = "λ" if s.discrete else "α"
    if s.discrete:
        params["spectral_radius"] = bound  # ρ(A − LC), informational
    else:
        params["spectral_abscissa"] = bound  # max Re λ_i(A − LC), informational
    lim = guide.figure(s.discrete)
    known = None
    if o.rate is not None:
        # the asked rate first, directly: no search can make it fail
        P = lyap.certified_P(A, C, L, s.discrete, o.rate, o.margin, memo=memo, Acl=Acl, guide=guide)
        if P is None:
            ok, how = lyap.rate_feasibility(Acl, o.rate, s.discrete, memo, Af)
            if not ok:
                raise InfeasibleError(
                    f"{lyap.infeasible_head(o.margin)} decay rate {sym} = {fmt_exact(o.rate)}: "
                    "A − LC has an "
                    f"eigenvalue {'of modulus ≥ λ' if s.discrete else 'with real part ≥ −α'} "
                    f"({how}; {lim})" + lyap.nonstrict_note(o.margin, s.discrete)
                )
            raise InconclusiveError(
                f"decay rate {sym} = {fmt_exact(o.rate)} is feasible "
                f"({how}) but the "
                f"rounded Lyapunov-equation P fails the exact check with margin "
                f"{fmt_exact(o.margin)} (the rate is too close to the limit, or A − LC too "
                f"badly conditioned: {lim}, ‖A − LC‖ ≈ {np.linalg.norm(Af, 2):.3g})"
            )
        known = (o.rate, P)
    elif bound >= 1 - 1e-6 if s.discrete else bound >= -1e-6:
        # (a float bound clearly inside: the certified best rate below proves Schur / Hurwitz)
        ok, how = lyap.rate_feasibility(Acl, 1 if s.discrete else 0, s.discrete, memo, Af)
        if not ok:
            raise InfeasibleError(
                f"A − LC is not {'Schur' if s.discrete else 'Hurwitz'}: {lim} ({how})"
                + ("" if o.L is None else " (the given L does not stabilize the error)")
            )
    try:
        br = lyap.best_rate(
            A,
            C,
            L,
            s.discrete,
            tol=o.rate_tol,
            margin=o.margin,
            known=known,
            progress=progress,
            memo=memo,
            Acl=Acl,
            Af=Af,
            guide=guide,
        )
    except lyap.RateResolutionError as e:
        raise SpecError(spec.file, "method.rate_tol", e.hint()) from None
    rate, P = (br.best, br.P) if known is None else known
    _float_viewable("P", P, rate, name, o)
    if br.P is not P:
        _float_viewable("P_best", br.P, br.best, name, o)
    solver.extra["best_rate_exact_checks"] = br.exact_checks
    params["P"] = P
    params[name] = rate
    params["P_best"] = br.P
    params[f"{name}_best"] = br.best
    params[f"{name}_bracket"] = br.other
    params[f"{name}_bracket_kind"] = br.kind
    if o.iss_gain:
        Bw = lyap.error_input(s.Bd.q, s.Dn.q, L)
        rho = lyap.decay_factor(rate, s.discrete)
        # 10⁻⁶ above the float μ: the verified float check decides it (lyap.iss_mu)
        params["mu"] = lyap.iss_mu(
            lyap.as_array(Acl),
            Bw,
            P,
            rho,
            s.discrete,
            strict=True,
            rel=ISS_MU_REL,
            # the message named no key and ended mid-sentence (re-check review, session 43)
            remedy=(
                f"give a larger [method].{name} (or [method].rate_tol when {name} is the best "
                "rate), or iss_gain = false (no ISS gain)"
            ),
        )
    why = (
        "no P ≻ 0 gives strict decay there (proved exactly, see the bracket claim)"
        if br.kind == lyap.INFEASIBLE
        else "feasible, but the rounded Lyapunov-equation P fails the exact check there, so "
        "the best rate is not proven to within the tolerance"
    )
    best = "best rate" if br.kind == lyap.INFEASIBLE else "best certified rate"
    notes.append(
        f"{best} {name} = {fmt_exact(br.best)} for this L (bracket tolerance "
        f"{fmt_exact(o.rate_tol)}); {name} = {fmt_exact(br.other)} is {br.kind}: {why}; "
        + (f"infimum ≈ {bound:.6g}" if s.discrete else f"supremum ≈ {-bound:.6g}")
        + f" ({guide.source})"
    )
    note = _float_gain_note(s, Af, L, rate, bound, guide)
    if note is not None:
        notes.append(note)
    lyap.attach_memo(spec, memo)
    return Design(params, solver, notes)


def _float_gain_note(
    s: Any, Af: np.ndarray, L: np.ndarray, rate: Any, bound: float, guide: Any
) -> str | None:
    """A note when L in doubles does not keep the certified rate (what ``simulate`` steps and
    ``observer_statespace`` exports; both check it exactly): the certificate is about the
    exact L, and on ill-conditioned plants the doubles lose it (certified ρ = 0.17, ρ = 1.06
    for the float gain; lyapunov trial, session 39). Decided exactly by
    :func:`obsdesign.lyap.float_realization`, skipped when the eigenvalues are accurate float
    ones and the rate's margin is far above what rounding L, A and C can move them
    (Bauer–Fike with the guide's error bound; a guide, the exact checks are downstream).

    :param s: the plant; :param Af: A − LC (float); :param L: the gain (exact); :param rate:
    the certified rate; :param bound: the spectral radius / abscissa (guide); :param guide:
    the :class:`~obsdesign.spectrum.Spectrum` of A − LC (its error bound is relative to
    max(1, the largest |eigenvalue|), not to the abscissa: a continuous abscissa of 10⁻³
    beside an eigenvalue of −10⁷ skipped a check the doubles fail; re-check trial, session
    39)."""
    from obsdesign.certify.exact import to_float
    from obsdesign.spectrum import FLOAT_SOURCE, FLOAT_TOL

    Lf = np.asarray(to_float(np.asarray(L, dtype=object)), dtype=float)  # the report's doubles
    Af_plant, Cf = np.asarray(s.A.f, float), np.asarray(s.C.f, float)
    margin = float(rate) - bound if s.discrete else -bound - float(rate)
    # the guide overflows where L·C does (‖C‖ = inf): numpy's warnings were report notes
    # ("RuntimeWarning: overflow encountered in dot"; re-check review 45); a nan scale takes
    # the exact check below
    with np.errstate(all="ignore"):
        scale = 1.0 + (np.linalg.norm(Af_plant) + np.linalg.norm(Lf) * np.linalg.norm(Cf)) / max(
            float(np.linalg.norm(Af)), np.finfo(float).tiny
        )
    size = max(1.0, float(np.max(np.abs(guide.w)))) if guide.w.size else 1.0
    if guide.source == FLOAT_SOURCE and margin > 10 * FLOAT_TOL * size * scale:
        return None
    with np.errstate(all="ignore"):
        Ao = Af_plant - Lf @ Cf
    if not np.all(np.isfinite(Ao)):
        # L·C past the float range, A − LC small exactly (re-check review, session 44): an
        # internal failure, ValueError "not a finite number", before
        return (
            "warning: A − LC formed in doubles overflows (L·C is beyond the float range): the "
            "certificate is about the exact A − LC (parameters.exact.L); simulate and "
            "observer_statespace(), which use doubles, cannot run this observer"
        )
    verdict = lyap.float_realization(Ao, s.discrete, rate)
    if verdict == "ok":
        return None
    what = "is not stable" if verdict == "unstable" else "is stable but slower than the rate"
    return (
        f"warning: A − LC with L in doubles {what}: the certificate is about the exact L "
        "(parameters.exact.L), and this plant is too badly conditioned for a float64 gain to "
        "keep it; simulate and observer_statespace() use the doubles (simulate warns, "
        "observer_statespace refuses an unstable one)"
    )


#: default Riccati weights (the Kalman-filter reading: process noise covariance Q, output
#: noise covariance R)
DEFAULT_WEIGHTS = "Q = I (n×n), R = I (p×p)"
#: slack of a designed gain below an asked rate (the rounded gain then certifies robustly)
SLACK_DISCRETE, SLACK_CONTINUOUS = 0.98, 1.02


def default_poles(n: int, discrete: bool, target: float | None) -> np.ndarray:
    """The stated default poles of ``design = "place"``: discrete t·(0.2 + 0.4·i/n),
    continuous −t − (1 + i/n), i = 0 … n−1, with t the asked rate with 2 % slack (1 in
    discrete time, 0 in continuous time when no rate is asked): n distinct real poles inside
    the asked decay region (Section 5 of the constrained-redesign paper asks only for
    A − LC Schur).

    :param n: state dimension; :param discrete: time domain; :param target: the asked rate."""
    i = np.arange(n, dtype=float)
    if discrete:
        t = 1.0 if target is None else target * SLACK_DISCRETE
        return t * (0.2 + 0.4 * i / n)
    t = 0.0 if target is None else target * SLACK_CONTINUOUS
    return -t - (1.0 + i / n)


def riccati_gain(
    A: np.ndarray,
    C: np.ndarray,
    discrete: bool,
    Qw: np.ndarray,
    Rw: np.ndarray,
    rate: float | None,
) -> tuple[np.ndarray, str]:
    """A Kalman-type gain from the dual algebraic Riccati equation (floats), and the name of
    the Riccati solver that ran.

    Discrete: X = DARE(Āᵀ, Cᵀ, Q, R) (:func:`obsdesign.riccati.solve_dare`: the
    structure-preserving doubling algorithm, scipy's ``solve_discrete_are`` as its fallback)
    with Ā = A/λₛ, L = λₛ Ā X Cᵀ (R + C X Cᵀ)⁻¹, so that
    Ā − (L/λₛ)C is Schur and ρ(A − LC) < λₛ (λₛ = 1 without an asked rate: the steady-state
    Kalman predictor gain). Continuous: X = CARE((A + αₛI)ᵀ, Cᵀ, Q, R)
    (:func:`obsdesign.riccati.solve_care`: the doubling after a Cayley transform, scipy's
    ``solve_continuous_are`` as its fallback), L = X Cᵀ R⁻¹, so
    that A + αₛI − LC is Hurwitz (αₛ = 0 without an asked rate). The error dynamics
    e⁺ = (A − LC)e is that of the linear observer of Section 5 of the constrained-redesign
    paper (Astolfi et al., NOLCOS 2019).

    :param A, C: float plant; :param discrete: time domain; :param Qw, Rw: weights (n×n ⪰ 0,
    p×p ≻ 0); :param rate: λₛ or αₛ, or None."""
    n = A.shape[0]
    if discrete:
        from obsdesign.riccati import solve_dare

        s = 1.0 if rate is None else rate
        Ab = A / s
        X, name = solve_dare(Ab.T, C.T, Qw, Rw)
        return s * (Ab @ X @ C.T @ np.linalg.inv(Rw + C @ X @ C.T)), name
    from obsdesign.riccati import solve_care

    a = 0.0 if rate is None else rate
    X, name = solve_care((A + a * np.eye(n)).T, C.T, Qw, Rw)
    return X @ C.T @ np.linalg.inv(Rw), name


def _gain_certifies(s: Any, Lm: fmpq_mat, rate: fmpq) -> bool:
    """Whether the exact gain ``Lm`` gives decay rate ``rate`` (λ, or α in continuous time: α = 0
    for Hurwitz), proved as the
    design proves it (:func:`obsdesign.lyap.certified_P`: the Lyapunov-equation P, in high
    precision for a badly conditioned A − LC, checked exactly; eq. (4)-(6), Section 5 of the
    constrained-redesign paper). Only a proof accepts: float eigenvalues of such a closed loop
    can be far off (a 5-state plant with ρ(A) ≈ 6000: a good 64-bit gain looked unstable).

    :param s: the spec's system; :param Lm: the gain (exact); :param rate: λ (exact)."""
    Acl = lyap.closed_loop_fmat(s.A.q, s.C.q, Lm)
    L = lyap.as_array(Lm)
    return lyap.certified_P(s.A.q, s.C.q, L, s.discrete, rate, fmpq(0), Acl=Acl) is not None


def riccati_gain_hp(
    A: Any,
    C: Any,
    Qw: Any,
    Rw: Any,
    rate: float | None,
    good: Callable[[fmpq_mat], bool],
    discrete: bool = True,
) -> tuple[fmpq_mat, int, str] | None:
    """:func:`riccati_gain` with the Riccati equation solved by the doubling algorithm in
    high precision (python-flint ``arb_mat``) from the exact A, C, weights and shift, and the
    gain formed at the same precision: discrete, :func:`obsdesign.riccati.dare_sda_hp` and
    L = λₛ Ā X Cᵀ (R + C X Cᵀ)⁻¹ (Ā = A/λₛ); continuous, :func:`obsdesign.riccati.care_sda_hp`
    on ((A + αₛI)ᵀ, Cᵀ) and L = X Cᵀ R⁻¹ (an integer companion plant of order 10 had no float
    solution at all: review 19). For badly conditioned plants whose float Riccati solution
    gives no gain or a wrong one. The precisions of :data:`obsdesign.riccati.HP_PRECISIONS` are
    tried in turn, and at each the gain rounded to each of :data:`GAIN_BITS` significant bits
    (no more than the precision) until it is ``good``: at too low a precision the doubling can
    meet its step criterion far from the solution, and the closed loop of such a plant can be
    so sensitive that 40 bits of L are not enough (a 7-state plant with ρ(A) ≈ 97 and one
    output: ρ(A − LC) ≈ 57 at 128 bits; at 320 bits 0.03, and 0.28 with L rounded to 53 bits).
    Returns (the rounded gain, exact; its bits; the solver's name), or None above
    :data:`obsdesign.riccati.HP_MAX_N` states or when nothing is good.

    :param A, C: exact plant (object arrays); :param Qw, Rw: exact weights or None (I);
    :param rate: λₛ or αₛ, or None (1, resp. 0); :param good: the acceptance test of a
    rounded gain; :param discrete: time domain."""
    from flint import arb_mat, ctx

    from obsdesign.certify.exact import Q
    from obsdesign.riccati import HP_MAX_N, HP_PRECISIONS, care_sda_hp, dare_sda_hp

    Aq, Cq = lyap.fmat(A), lyap.fmat(C)
    n, p = Aq.nrows(), Cq.nrows()
    if n > HP_MAX_N:
        return None
    Qq = fmpq_mat(n, n, [int(i == j) for i in range(n) for j in range(n)])
    Rq = fmpq_mat(p, p, [int(i == j) for i in range(p) for j in range(p)])
    if Qw is not None:
        Qq = lyap.fmat(Qw)
    if Rw is not None:
        Rq = lyap.fmat(Rw)
    sq = fmpq(1) if rate is None else Q(rate)
    shifted = (
        Aq / sq
        if discrete
        else Aq
        + fmpq_mat(n, n, [int(i == j) for i in range(n) for j in range(n)])
        * (fmpq(0) if rate is None else Q(rate))
    )
    old = ctx.prec
    try:
        for prec in HP_PRECISIONS:
            ctx.prec = prec
            try:
                solve = dare_sda_hp if discrete else care_sda_hp
                X = solve(shifted.transpose(), Cq.transpose(), Qq, Rq, prec)
                if X is None:
                    continue
                Ch = arb_mat(Cq)
                XC = X * Ch.transpose()
                if discrete:
                    L = arb_mat(Aq) * (arb_mat(Rq) + Ch * XC).solve(XC.transpose()).transpose()
                else:
                    L = arb_mat(Rq).solve(XC.transpose()).transpose()  # X Cᵀ R⁻¹
            except (ZeroDivisionError, ValueError):
                continue
            mids = [L[i, j].mid().man_exp() for i in range(n) for j in range(p)]
            ctx.prec = old  # the acceptance test computes at the caller's precision
            for bits in GAIN_BITS:
                if bits > prec:
                    break
                Lm = fmpq_mat(n, p, [_round_bits(int(m), int(e), bits) for m, e in mids])
                if good(Lm):
                    name = f"structure-preserving doubling at {prec} bits (python-flint arb_mat)"
                    return Lm, bits, name
    finally:
        ctx.prec = old
    return None


#: the significant bits a high-precision gain is rounded to, fewest first
GAIN_BITS = (lyap.BITS, 64, 96, 128, 192, 256)


def _round_bits(man: int, exp: int, bits: int) -> fmpq:
    """man·2^exp rounded half-to-even to ``bits`` significant bits, exactly.

    :param man, exp: the exact value's mantissa and exponent; :param bits: ≥ 1."""
    extra = abs(man).bit_length() - bits
    if extra > 0:
        q, r = divmod(man, 1 << extra)  # floor division: r ≥ 0
        half = 1 << (extra - 1)
        if r > half or (r == half and q & 1):
            q += 1
        man, exp = q, exp + extra
    return fmpq(man << exp) if exp >= 0 else fmpq(man, 1 << -exp)


def placed_gain(A: np.ndarray, C: np.ndarray, poles: np.ndarray) -> np.ndarray:
    """L with eig(A − LC) = poles, by ``scipy.signal.place_poles`` on the dual pair (Aᵀ, Cᵀ)
    (floats): the error dynamics of the linear observer of Section 5 of the constrained-redesign
    paper (Astolfi et al., NOLCOS 2019) with prescribed poles.

    Placement needs independent outputs: with a C of lower row rank (a repeated row) scipy
    refused (exit 4 — lyapunov review), so it runs on a maximal set of independent rows of C
    and the other columns of L are 0 (A − LC is the same matrix).

    :param A, C: float plant ((C, A) observable); :param poles: n real poles (a pole may
    repeat at most rank(C) times)."""
    from scipy.signal import place_poles

    keep: list[int] = []
    for i in range(C.shape[0]):
        if np.linalg.matrix_rank(C[[*keep, i]]) > len(keep):
            keep.append(i)
    L = np.zeros((A.shape[0], C.shape[0]))
    L[:, keep] = np.asarray(place_poles(A.T, C[keep].T, poles).gain_matrix, dtype=float).T
    return L


def design_gain(
    spec: Spec, o: Options, progress: Progress | None
) -> tuple[np.ndarray, SolverResult, str]:
    """Design L (float) by ``o.design``: ``riccati`` (default, :func:`riccati_gain`),
    ``place`` (:func:`placed_gain`) or ``lmi`` (:func:`lmi_gain`); the exact detectability of
    (C, A) and the unobservable modes' bound on an asked rate are checked first (they hold for
    every L). The decay LMI is eq. (4)-(6), Section 5 of the constrained-redesign paper
    (Astolfi et al., NOLCOS 2019).

    :param spec: the bound spec; :param o: its options; :param progress: callback.
    Returns (L, solver result, a note naming the path that ran)."""
    import time as _time

    s = spec.system
    time = "discrete" if s.discrete else "continuous"
    what = "Schur" if s.discrete else "Hurwitz"
    if lyap.observable_mod_p(s.A.q, s.C.q):
        det = Detectability(
            True,
            True,
            0,
            f"observable: the observability matrix has rank {s.n} modulo the prime 2^61 − 1",
        )
        Au = fmpq_mat(0, 0)
    else:
        det = detectability(s.A.q, s.C.q, time)
        if not det.detectable:
            raise InfeasibleError(f"no gain L makes A − LC {what}: (C, A) is {det.reason}")
        _, Au = unobservable_restriction(s.A.q, s.C.q)
    if o.rate is not None and Au.nrows():
        # the unobservable modes are eigenvalues of A − LC for every L (exact)
        ok, how = lyap.rate_feasibility(lyap.as_qarray(Au), o.rate, s.discrete)
        if not ok:
            raise InfeasibleError(
                f"no gain L gives decay rate {fmt_exact(o.rate)}: an unobservable mode of "
                f"(C, A) (a root of {Au.charpoly()}) is an eigenvalue of A − LC for every L "
                f"and fails the rate ({how})"
            )
    A, C = s.A.f, s.C.f
    n, p = s.n, s.p
    target = None if o.rate is None else float(o.rate)
    if o.design == "lmi":
        Lf, res = lmi_gain(spec, o, det.reason, Au, progress)
        return Lf, res, 'the LMI in (P, X = P L) (design = "lmi", Clarabel)'
    t0 = _time.perf_counter()
    if o.design == "place":
        poles = (
            default_poles(n, s.discrete, target)
            if o.poles is None
            else np.array([float(z) for z in o.poles])
        )
        if not det.observable:
            # decided exactly: a request this plant cannot meet, bad input naming the key
            # (it was exit 4, "inconclusive" — lyapunov review)
            raise SpecError(
                spec.file,
                "method.design",
                f"'place' needs (C, A) observable, but it is {det.reason} (an unobservable "
                'mode cannot be placed): use design = "riccati" (the default) or "lmi"',
            )
        try:
            Lf = placed_gain(A, C, poles)
        except ValueError as e:
            raise InconclusiveError(f"scipy.signal.place_poles failed: {e}") from e
        shown = ", ".join(f"{z:.6g}" for z in poles)
        res = SolverResult(
            "scipy.signal.place_poles",
            SolverStatus.CLOSED_FORM,
            f"pole placement at {shown}",
            seconds=_time.perf_counter() - t0,
            extra={"gain_design": "place"},
        )
        src = "given" if o.poles is not None else "default"
        return Lf, res, f'pole placement (design = "place", {src} poles {shown})'
    Qw = np.eye(n) if o.riccati_Q is None else np.asarray(o.riccati_Q, dtype=float)
    Rw = np.eye(p) if o.riccati_R is None else np.asarray(o.riccati_R, dtype=float)
    weights = weights_text(o)
    tries: list[float | None] = [None]
    if target is not None:
        tries = [target * (SLACK_DISCRETE if s.discrete else SLACK_CONTINUOUS), target]
    last = ""
    for shift in tries:
        try:
            with np.errstate(all="ignore"):
                Lf, are = riccati_gain(A, C, s.discrete, Qw, Rw, shift)
        except (np.linalg.LinAlgError, ValueError) as e:
            last = str(e)
            continue
        if np.all(np.isfinite(Lf)):
            break
        last = "non-finite gain"
    else:
        extreme = _extreme_rate(A, s.discrete, target)
        err = NoRiccatiGain(
            f"the Riccati equation gave no gain ({last}) although (C, A) is {det.reason}" + extreme
        )
        err.hinted = bool(extreme)
        raise err
    return _riccati_result(Lf, are, s.discrete, weights, shift, _time.perf_counter() - t0)


#: the ratio of the asked rate's shift to the plant's scale past which the float Riccati
#: equation of :func:`riccati_gain` is hopeless in double precision
EXTREME_SHIFT = 1e100


def _extreme_rate(A: np.ndarray, discrete: bool, target: float | None) -> str:
    """The reason a Riccati gain failed when the asked rate is extreme for the plant: the
    discrete shift divides A by λ (λ = 1e-300 made entries near 1e300 and the failure blamed
    the Riccati solver alone: lyapunov review 43), the continuous one adds αI to A. Empty
    when the rate is not extreme.

    :param A: float plant; :param discrete: time domain; :param target: the asked rate."""
    if target is None:
        return ""
    scale = float(np.max(np.abs(A))) if A.size else 0.0
    with np.errstate(all="ignore"):
        ratio = scale / target if discrete else abs(target) / max(scale, 1e-300)
    if discrete and target > 0 and not ratio < EXTREME_SHIFT:
        return (
            f" — the rate λ = {target:.6g} scales A by 1/λ (entries near {ratio:.3g}), past "
            'what a double-precision Riccati solve can do: give L, try design = "place", '
            "or ask a larger rate"
        )
    if not discrete and not ratio < EXTREME_SHIFT:
        return (
            f" — the rate {target:.6g} shifts A by {abs(target):.3g}·I, {ratio:.3g} times its "
            "entries, past what a double-precision Riccati solve can do: give L, try design = "
            '"place", or ask a rate nearer the plant\'s'
        )
    return ""


def _riccati_result(
    Lf: Any, are: str, discrete: bool, weights: str, shift: float | None, seconds: float
) -> tuple[np.ndarray, SolverResult, str]:
    """(L, the solver result, the note naming the path) of a Riccati gain.

    :param Lf: the gain; :param are: the solver that ran; :param discrete: time domain;
    :param weights: the weights' description; :param shift: the rate shift or None;
    :param seconds: the time taken."""
    how = (
        f"the {'discrete' if discrete else 'continuous'} Riccati equation "
        f'(design = "riccati", {are}, {weights}'
        + ("" if shift is None else f", shifted to the rate {shift:.6g}")
        + ")"
    )
    res = SolverResult(
        are, SolverStatus.CLOSED_FORM, how, seconds=seconds, extra={"gain_design": "riccati"}
    )
    return Lf, res, how


def riccati_retry_hp(spec: Spec, o: Options) -> tuple[fmpq_mat, int, SolverResult, str] | None:
    """After a float Riccati gain failed the exact tests (or gave none): the gain of the
    same equation solved in high precision (:func:`riccati_gain_hp`) at the first shift the
    float design tries (0.98 λ / 1.02 α with an asked rate, else none), rounded to the
    fewest bits of :data:`GAIN_BITS` with which it provably gives the asked rate (λ = 1, i.e.
    Schur, or α = 0, Hurwitz, without one: :func:`_gain_certifies`); the design's exact tests
    then run on it. Returns (the rounded gain, its bits, the solver result, the path's note).
    None when there is none (not the Riccati design, or nothing certifies). The error
    dynamics e⁺ = (A − LC)e are those of the linear observer of Section 5 of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019), eq. (4)-(6).

    :param spec: the bound spec; :param o: its options."""
    import time as _time

    s = spec.system
    if o.design != "riccati":
        return None
    t0 = _time.perf_counter()
    slack = SLACK_DISCRETE if s.discrete else SLACK_CONTINUOUS
    shift = None if o.rate is None else float(o.rate) * slack
    need = (fmpq(1) if s.discrete else fmpq(0)) if o.rate is None else o.rate
    hp = riccati_gain_hp(
        s.A.q,
        s.C.q,
        o.riccati_Q,
        o.riccati_R,
        shift,
        lambda L: _gain_certifies(s, L, need),
        s.discrete,
    )
    if hp is None:
        return None
    Lm, bits, are = hp
    _, res, how = _riccati_result(
        None, are, s.discrete, weights_text(o), shift, _time.perf_counter() - t0
    )
    return Lm, bits, res, how


def weights_text(o: Options) -> str:
    """How the Riccati weights were chosen, for the notes (the defaults, or the spec's): the
    Kalman-type design of the observer gain of Section 5 of the constrained-redesign paper.

    :param o: the options."""
    if o.riccati_Q is None and o.riccati_R is None:
        return DEFAULT_WEIGHTS
    return "Q, R from riccati_Q / riccati_R"


#: the solver name of :func:`lmi_gain`'s result when no LMI answer beat the Riccati start
RICCATI_START = "Riccati gain (LMI bisection start)"

#: the way out of a failed LMI gain search (the SDP solver's conditioning, not the plant:
#: the default Riccati design certified 9 specs where design = "lmi" was exit 4 — review)
#: relative step of the ISS gain μ above its float value (:func:`obsdesign.lyap.iss_mu`)
ISS_MU_REL = 1e-6

_LMI_HINT = '; the default design = "riccati" (or "place") needs no SDP solver: omit design'


def lmi_gain(
    spec: Spec, o: Options, reason: str, Au: Any, progress: Progress | None
) -> tuple[np.ndarray, SolverResult]:
    """Design L through the LMI in (P, X = P L), bisecting on the rate (float gain).

    Discrete: [[λ²P, (PA − XC)ᵀ], [PA − XC, P]] ⪰ δ I, the Schur complement of the decay LMI
    λ²P − (A−LC)ᵀP(A−LC) ≻ 0 of eq. (4)-(6) (constrained-redesign paper, Astolfi et al.,
    NOLCOS 2019, Section 5); continuous: −(AᵀP + PA − CᵀXᵀ − XC + 2αP) ⪰ δ I. With I ⪯ P ⪯ tI,
    minimal t. The bisection is bracketed by spectral bounds: the unobservable modes bound
    every rate (no solve beyond them), and the Riccati gain's rate is a feasible start; each
    rate is solved once (no re-solve of the final point).

    An answer is a candidate gain whenever its float closed loop has the rate,
    "optimal_inaccurate" included (the gain only proposes L: the rate of the rounded gain is
    certified exactly afterwards); a candidate whose float rate beats the solved rate moves
    that end of the bracket to it. Without an asked rate the Riccati gain (Q = I, R = I) is
    the first candidate, so the LMI design returns it when no LMI answer beats its float rate
    (the SDP solver fails on badly scaled plants where the Riccati gain certifies: 7 of 80
    random LMI designs were exit 4); the solver message then says so.

    :param spec: the bound spec; :param o: its options; :param reason: the detectability
    verdict (for messages); :param Au: the exact unobservable restriction of A;
    :param progress: callback."""
    import cvxpy as cp

    from obsdesign.lmi import solve, sym

    s = spec.system
    A, C = s.A.f, s.C.f
    n, p = s.n, s.p
    P = cp.Variable((n, n), symmetric=True)
    X = cp.Variable((n, p))
    r = cp.Parameter(nonneg=True)
    delta = 1e-6
    if s.discrete:
        PAc = P @ A - X @ C
        M = cp.bmat([[r * P, PAc.T], [PAc, P]])
    else:
        M = -(A.T @ P + P @ A - C.T @ X.T - X @ C + 2 * r * P)
    t = cp.Variable()
    # I ⪯ P ⪯ t·I, minimal t: a well-conditioned P keeps the gain moderate and the problem
    # bounded (minimizing ‖X‖ alone leaves solvers "optimal_inaccurate")
    cons = [P >> np.eye(n), P << t * np.eye(n), sym(M) >> delta * np.eye(M.shape[0])]
    prob = cp.Problem(cp.Minimize(t), cons)
    tol = float(o.rate_tol)
    best: tuple[np.ndarray, str, float] | None = None
    total = 0.0
    solves = 0
    seen: dict[float, bool] = {}

    def feasible(rate: float) -> bool:
        nonlocal best, total, solves
        if rate in seen:  # never re-solve a solved point
            return seen[rate]
        r.value = rate**2 if s.discrete else rate
        solves += 1
        try:
            res = solve(prob, ("CLARABEL",))  # SCS is slow and loose at the boundary
        except SolverError:
            seen[rate] = False
            return False
        total += res.seconds
        got = _candidate_rate(res.status, P.value, X.value, A, C, s.discrete)
        # the decay LMI at `rate` implies this rate; a solver answer that breaks it is not
        # trusted (an inaccurate answer that keeps it is a candidate: L is certified later)
        ok = got is not None and (
            got[1] <= rate * (1 + 1e-6) if s.discrete else got[1] >= rate * (1 - 1e-6)
        )
        if ok and got is not None:
            better = best is None or (got[1] < best[2] if s.discrete else got[1] > best[2])
            if better:
                best = (got[0], res.solver, got[1])
        seen[rate] = ok
        return ok

    def achieved() -> float:
        """The best float rate of a candidate so far (a bracket end the gain reaches)."""
        assert best is not None
        return best[2]

    # spectral bounds: every L keeps the unobservable modes; the Riccati gain is a start
    ueig = np.linalg.eigvals(np.asarray(lyap.as_qarray(Au), dtype=float)) if Au.nrows() else []
    try:
        with np.errstate(all="ignore"):
            Lr, _ = riccati_gain(A, C, s.discrete, np.eye(n), np.eye(p), None)
        reig = np.linalg.eigvals(A - Lr @ C)
    except (np.linalg.LinAlgError, ValueError):
        reig = None
    if reig is not None and np.isfinite(reig).all() and np.isfinite(Lr).all():
        ric = float(np.abs(reig).max()) if s.discrete else float(-reig.real.max())
        if o.rate is None and (ric < 1.0 if s.discrete else ric > 0.0):
            best = (Lr, RICCATI_START, ric)
    if o.rate is not None:
        # design with some slack (2 %) so the rounded gain certifies robustly at the asked rate
        slack = float(o.rate) * (SLACK_DISCRETE if s.discrete else SLACK_CONTINUOUS)
        if not feasible(slack) and not feasible(float(o.rate)):
            raise InconclusiveError(
                f"the LMI solver found no gain at rate {fmt_exact(o.rate)}, although no "
                f"unobservable mode of (C, A) rules it out (checked exactly; {reason})" + _LMI_HINT
            )
    elif s.discrete:
        lo = float(np.abs(ueig).max()) if len(ueig) else 0.0
        hi = 1.0 - tol
        if reig is not None and np.isfinite(reig).all():
            start = min(hi, float(np.abs(reig).max()) + tol)
            if start > lo and feasible(start):
                hi = start
        if best is None and not feasible(hi):
            raise InconclusiveError(
                f"the LMI solver found no gain with λ ≤ {1.0 - tol:g} ({reason})" + _LMI_HINT
            )
        hi = min(hi, achieved())
        while hi - lo > tol:
            mid = (lo + hi) / 2
            if progress:
                progress(f"bisection λ = {mid:.6f}")
            if feasible(mid):
                hi = min(mid, achieved())
            else:
                lo = mid
    else:
        hi = float(o.rate_cap)
        if len(ueig):
            hi = min(hi, -float(np.real(ueig).max()))
        lo = tol
        if reig is not None and np.isfinite(reig).all():
            start = min(hi, -float(reig.real.max()) - tol)
            if start > lo and feasible(start):
                lo = start
        if best is None and not feasible(lo):
            raise InconclusiveError(
                f"the LMI solver found no gain with α ≥ {tol:g} ({reason})" + _LMI_HINT
            )
        lo = max(lo, min(hi, achieved()))
        if lo < hi and feasible(hi):
            lo = hi
        while hi - lo > tol:
            mid = (lo + hi) / 2
            if progress:
                progress(f"bisection α = {mid:.6f}")
            if feasible(mid):
                lo = max(mid, min(hi, achieved()))
            else:
                hi = mid
    assert best is not None
    Lf, name, rate = best
    msg = f"LMI bisection: {solves} solves, best float rate {rate:.6g}"
    if name == RICCATI_START:
        msg = (
            f"LMI bisection: {solves} solves, none beat the float rate {rate:.6g} of the "
            "Riccati gain (Q = I, R = I, the bisection's start): L is that gain"
        )
    return Lf, SolverResult(
        name,
        SolverStatus.OPTIMAL,
        msg,
        seconds=total,
        extra={"gain_design": "lmi", "lmi_solves": solves},
    )


def _candidate_rate(
    status: str, Pv: Any, Xv: Any, A: np.ndarray, C: np.ndarray, discrete: bool
) -> tuple[np.ndarray, float] | None:
    """(L = P⁻¹X, its float rate: max |eig(A − LC)| discrete, −max Re eig continuous) of an
    SDP answer of the decay LMI (eq. (4)-(6), constrained-redesign paper, Astolfi et al.,
    NOLCOS 2019, Section 5), for "optimal" and "optimal_inaccurate" answers with finite
    values; None otherwise.

    :param status: the solver status; :param Pv, Xv: the values of P and X = P L;
    :param A, C: the plant; :param discrete: time domain."""
    if status not in ("optimal", "optimal_inaccurate") or Pv is None or Xv is None:
        return None
    try:
        with np.errstate(all="ignore"):
            Lc = np.linalg.solve(np.asarray(Pv, dtype=float), np.asarray(Xv, dtype=float))
            eig = np.linalg.eigvals(A - Lc @ C)
    except (np.linalg.LinAlgError, ValueError):
        return None
    if not (np.all(np.isfinite(Lc)) and np.all(np.isfinite(eig))):
        return None
    return Lc, float(np.abs(eig).max()) if discrete else float(-eig.real.max())
