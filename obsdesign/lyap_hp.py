"""The Lyapunov-equation P in high precision, for the error dynamics the float solve cannot
serve: a badly scaled or strongly non-normal A − LC (entries of 10⁵ around a spectral
radius of 0.02, found by the soundness audit), where the float P's residual in the decay
LMI exceeds the LMI's own size and no rounding of it certifies, however far the rate is
from the spectral bound.

The exact Lyapunov P of a feasible rate certifies by construction: λ²P − AclᵀPAcl = I
(discrete) or −((Acl + αI)ᵀP + P(Acl + αI)) = I (continuous) gives the decay matrix I and
P ⪰ I/λ² (discrete; P ≻ 0 in both), so every margin δ < 1 holds, and the rounded P keeps
that when the rounding is fine enough. Here the n² × n² Kronecker form of the equation is
solved by python-flint's ``arb_mat`` at ``prec`` bits (approximate solve: no error bounds
are needed, the exact check of the result decides), and the midpoints are the exact dyadic
P. Cost: the Kronecker system is (n²)³/3 operations at ``prec`` bits, ~70 ms at n = 12, so
it is a fallback for n ≤ :data:`MAX_N` only. Eq. (4)-(6), Section 5 of the
constrained-redesign paper (Astolfi et al., NOLCOS 2019), with Q = I.
"""

from __future__ import annotations

from typing import Any

from flint import arb_mat, ctx, fmpq, fmpq_mat

#: the largest state dimension the high-precision solve is tried at (n² unknowns)
MAX_N = 16

#: the working precisions tried, in bits
PRECISIONS = (128, 320)

#: one more precision up to :data:`WIDE_MAX_N` states (:func:`precisions`): a 20-state
#: dead-beat closed loop (‖A − LC‖ ≈ 1.8·10⁵, nilpotent) has Lyapunov Ps whose doubling
#: needs it at rates whose 1/λ is not dyadic (λ = 0.09: residual 3.4 at 320 bits, 10⁻²¹²
#: at 1024), so the best-rate search stopped at 0.0883 where 0.01 certifies (hard-plant
#: review, session 41)
WIDE_PRECISION = 1024
#: the largest state dimension :data:`WIDE_PRECISION` is tried at (its cost grows as n³)
WIDE_MAX_N = 40


def precisions(n: int) -> tuple[int, ...]:
    """The working precisions of the high-precision Lyapunov solve at ``n`` states."""
    return PRECISIONS + ((WIDE_PRECISION,) if n <= WIDE_MAX_N else ())


#: the largest state dimension the exact rational solve is tried at (n² unknowns over Q)
EXACT_MAX_N = 8

#: the relative precisions, in bits, the exact solution is rounded to (each kept only when
#: its exact strings fit the report's ``max_digits``)
EXACT_BITS = (512, 1024, 2048)


def kronecker_fmat(Acl: fmpq_mat, rate: fmpq, discrete: bool) -> fmpq_mat:
    """The n² × n² matrix K of the Lyapunov equation in row-major vec form, exactly:
    K·vec(P) = vec(λ²P − AclᵀPAcl) (discrete) or vec(−(FᵀP + PF)), F = Acl + αI
    (continuous); eq. (4)-(6), constrained-redesign paper, with the decay matrix on the
    left-hand side.

    :param Acl: A − LC (exact); :param rate: λ or α (exact); :param discrete: time domain."""
    n = Acl.nrows()
    a = [[Acl[i, j] for j in range(n)] for i in range(n)]
    N = n * n
    K = [[fmpq(0)] * N for _ in range(N)]
    if discrete:
        r2 = rate * rate
        for i in range(n):
            for j in range(n):
                row = K[i * n + j]
                row[i * n + j] += r2
                for k in range(n):
                    aki = a[k][i]
                    if aki == 0:
                        continue
                    for m in range(n):
                        if a[m][j] != 0:
                            row[k * n + m] -= aki * a[m][j]  # (AᵀPA)_ij = Σ A_ki P_km A_mj
    else:
        f = [[a[i][j] + (rate if i == j else 0) for j in range(n)] for i in range(n)]
        for i in range(n):
            for j in range(n):
                row = K[i * n + j]
                for k in range(n):
                    row[k * n + j] -= f[k][i]  # (FᵀP)_ij = Σ F_ki P_kj
                    row[i * n + k] -= f[k][j]  # (PF)_ij = Σ P_ik F_kj
    return fmpq_mat(N, N, [x for row in K for x in row])


def lyapunov_P_hp(Acl: fmpq_mat, rate: Any, discrete: bool, prec: int) -> fmpq_mat | None:
    """The Lyapunov-equation P with decay matrix I (see the module docstring), solved at
    ``prec`` bits and symmetrized exactly: an exact dyadic ``fmpq_mat``, or None when the
    system is singular at that precision (a rate on the spectrum) or the solve is not
    finite. Never a proof: the caller's exact check decides.

    :param Acl: A − LC (exact); :param rate: λ or α; :param discrete: time domain;
    :param prec: working precision in bits."""
    n = Acl.nrows()
    K = kronecker_fmat(Acl, fmpq(rate) if not isinstance(rate, fmpq) else rate, discrete)
    rhs = [1 if i == j else 0 for i in range(n) for j in range(n)]
    with ctx.workprec(prec):
        try:
            x = arb_mat(K).solve(arb_mat(n * n, 1, rhs), algorithm="approx")
        except (ZeroDivisionError, ValueError):
            return None
        vals = []
        for k in range(n * n):
            v = x[k, 0]
            if not v.is_finite():
                return None
            m, e = v.mid().man_exp()  # the midpoint m·2^e, exactly
            e = int(e)
            vals.append(fmpq(int(m) << e) if e >= 0 else fmpq(int(m), 1 << -e))
    P = fmpq_mat(n, n, vals)
    return (P + P.transpose()) * fmpq(1, 2)


#: the largest state dimension the doubling solve (:func:`lyapunov_P_doubling`) is tried at,
#: above :data:`MAX_N` (n³ work a step instead of the Kronecker system's n⁶; 0.1-0.3 s a
#: solve at n = 64; 40 until session 41, as :data:`obsdesign.riccati.HP_MAX_N` was 24)
DOUBLING_MAX_N = 64

#: the most squaring steps of the doubling solve (2⁶⁴ terms of the series)
DOUBLING_STEPS = 64


def _to_fmpq(v: Any) -> fmpq:
    """The midpoint of an arb ball, exactly (m·2^e)."""
    m, e = v.mid().man_exp()
    e = int(e)
    return fmpq(int(m) << e) if e >= 0 else fmpq(int(m), 1 << -e)


def lyapunov_P_doubling(Acl: fmpq_mat, rate: Any, discrete: bool, prec: int) -> fmpq_mat | None:
    """The Lyapunov-equation P with decay matrix I (as :func:`lyapunov_P_hp`), for
    ``MAX_N < n ≤ DOUBLING_MAX_N``, by Smith's doubling at ``prec`` bits: discrete,
    λ²P − AclᵀPAcl = I is P = λ⁻² Σ_k (Fᵀ)^k F^k with F = Acl/λ, summed as S ← S + GᵀSG,
    G ← G² (2^j terms after j steps); continuous, FᵀP + PF = −I with F = Acl + αI goes to
    that form by the Cayley transform G = (I − hF)⁻¹(I + hF), Q = 2h(I − hF)⁻ᵀ(I − hF)⁻¹
    (h = 1/‖F‖_F). Eq. (4)-(6), constrained-redesign paper. A 20-state Jordan block at 1
    with its Riccati gain (ρ(A − LC) = 0.84) was exit 4 at λ = 0.95: the float P fails the
    exact check and the Kronecker solve stopped at 16 states (lyapunov trial, session 40).
    None when the series does not settle in :data:`DOUBLING_STEPS` steps (a rate on or below
    the spectrum) or a value is not finite; never a proof: the caller's exact check decides.

    :param Acl: A − LC (exact); :param rate: λ or α; :param discrete: time domain;
    :param prec: working precision in bits."""
    from flint import arb

    n = Acl.nrows()
    r = fmpq(rate) if not isinstance(rate, fmpq) else rate
    eye = fmpq_mat(n, n, [1 if i == j else 0 for i in range(n) for j in range(n)])
    with ctx.workprec(prec):
        if discrete:
            if r == 0:
                return None
            G = arb_mat(Acl * (1 / r))
            S = arb_mat(eye * (1 / (r * r)))
        else:
            F = Acl + eye * r
            fro = sum((float(F[i, j]) ** 2 for i in range(n) for j in range(n)), 0.0) ** 0.5
            hf = 1.0 / fro if 0 < fro < float("inf") else 1.0
            if not 0 < hf < float("inf"):
                return None
            h = fmpq(*hf.as_integer_ratio())  # any h > 0 does: this one balances G
            try:
                Minv = arb_mat(eye - F * h).inv()
            except (ZeroDivisionError, ValueError):
                return None
            G = Minv * arb_mat(eye + F * h)
            S = Minv.transpose() * Minv * arb(2 * h)
        for _ in range(DOUBLING_STEPS):
            step = G.transpose() * S * G
            S = (S + step).mid()
            G = (G * G).mid()
            big = max(abs(float(S[i, i].mid())) for i in range(n))
            # step = GᵀSG is positive semidefinite (S is), so its largest entry is on its
            # diagonal (|s_ij| ≤ √(s_ii s_jj)): n conversions, not n² (4.9 s of a 64-state
            # design went to reading every entry; session 41)
            small = max(abs(float(step[i, i].mid())) for i in range(n))
            if not (big > 0 and big < float("inf")):
                return None
            if small <= big * 2.0 ** (-prec):
                break
        else:
            return None
        vals = []
        for i in range(n):
            for j in range(n):
                v = S[i, j]
                if not v.is_finite():
                    return None
                vals.append(_to_fmpq(v))
    P = fmpq_mat(n, n, vals)
    return (P + P.transpose()) * fmpq(1, 2)


def lyapunov_P_exact(Acl: fmpq_mat, rate: Any, discrete: bool) -> fmpq_mat | None:
    """The Lyapunov-equation P with decay matrix exactly I, by an exact rational solve of the
    Kronecker system (python-flint ``fmpq_mat.solve``; symmetric, the solution being unique),
    or None when the system is singular (a rate on the spectrum). For n ≤
    :data:`EXACT_MAX_N`: where 320 bits were not enough — A − LC with ‖A − LC‖ ≈ 9·10¹¹
    around a spectral radius of 0.0028 at n = 6, exit 4 at λ = 0.01 although the exact P
    solves in 10 ms (lyapunov trial, session 39). Its entries can have ~1000 digits:
    :func:`round_relative` makes the candidates the caller checks.

    :param Acl: A − LC (exact); :param rate: λ or α; :param discrete: time domain."""
    n = Acl.nrows()
    K = kronecker_fmat(Acl, fmpq(rate) if not isinstance(rate, fmpq) else rate, discrete)
    rhs = fmpq_mat(n * n, 1, [1 if i == j else 0 for i in range(n) for j in range(n)])
    try:
        x = K.solve(rhs)
    except ZeroDivisionError:
        return None
    return fmpq_mat(n, n, [x[k, 0] for k in range(n * n)])


def round_relative(P: fmpq_mat, bits: int) -> fmpq_mat:
    """Every entry of ``P`` rounded to the nearest multiple of 2^(⌊log₂ max |P_ij|⌋ − bits),
    exactly (dyadic), then symmetrized. Never a proof: the caller's exact check decides.

    :param P: a rational matrix; :param bits: the relative precision."""
    from flint import fmpz

    n = P.nrows()
    entries = [P[i, j] for i in range(n) for j in range(n)]
    top = max((abs(v) for v in entries), default=fmpq(0))
    if top == 0:
        return P
    lg = top.p.bit_length() - top.q.bit_length()  # ⌊log₂ top⌋ or one below
    e = bits - lg  # the grid 2^-e
    step = fmpq(fmpz(1) << e) if e >= 0 else fmpq(1, fmpz(1) << -e)
    vals = []
    for v in entries:
        x = v * step
        vals.append(fmpq((2 * x.p + x.q) // (2 * x.q)) / step)
    R = fmpq_mat(n, n, vals)
    return (R + R.transpose()) * fmpq(1, 2)
