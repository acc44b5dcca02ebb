"""Quadratic Lyapunov functions of a linear observer's error dynamics, shared by the methods.

Linear observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u) (or its continuous analogue) on the plant
x⁺ = A x + B u + Bd d, y = C x + D u + Dn v: the error e = x̂ − x obeys

    e⁺ = Acl e + B_w w,   Acl = A − L C,   w = (d, v),   B_w = [−Bd, L Dn]

(ė = … in continuous time). This is the linear case of the quadratic Lyapunov function
V(e) = eᵀ P e of eq. (4) and the dissipation inequality V(Δ(x, e, w)) ≤ β(V(e), w) of eq. (5)
with β(v, w) = ρ v + μ |w|² (eq. (6)), ρ = λ², as in Section 5 of Astolfi, Bernard,
Postoyan, Marconi, "Redesign of discrete-time nonlinear observers with state estimate
constraints guaranteed in prescribed convex set", NOLCOS 2019 (the "constrained-redesign
paper"). Continuous time uses the analogue V̇ ≤ −2α V + μ |w|².

Every function takes explicit numbers (matrices, rates, margins, tolerances), never a method's
options object. Exact functions take and return ``fmpq`` object arrays (see
:mod:`obsdesign.certify.exact`); the float helpers say so.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq, fmpq_mat, fmpq_poly, fmpz, fmpz_mat

from obsdesign.certify.detect import hurwitz_stable, schur_stable
from obsdesign.certify.exact import Q, dyadic, float_or_inf, qeye, symmetrize
from obsdesign.certify.psd import check_pd_fast, check_psd, negative_direction, to_fmpq_mat
from obsdesign.errors import InconclusiveError, InfeasibleError
from obsdesign.spectrum import Spectrum, spectrum

#: reference printed in claims that check these formulas
REF = (
    "decay LMI, eq. (4)-(7) and Section 5 of Astolfi, Bernard, Postoyan, Marconi, "
    "NOLCOS 2019 (constrained-redesign paper)"
)
#: dyadic rounding of P (significant bits relative to its largest entry)
BITS = 40

INFEASIBLE = "infeasible"
NOT_CERTIFIABLE = "not-certifiable"


# -- exact matrices ------------------------------------------------------------------------
def closed_loop(A: np.ndarray, C: np.ndarray, L: np.ndarray) -> np.ndarray:
    """Acl = A − L C, the error dynamics matrix of eq. (3) for a linear observer (exact;
    the product runs in flint).

    :param A: n×n state matrix; :param C: p×n output matrix; :param L: n×p gain."""
    if A.shape[0] == 0 or C.shape[0] == 0:
        return A - L @ C
    return as_array(fmat(A) - fmat(L) * fmat(C))


def closed_loop_fmat(A: Any, C: Any, L: Any) -> fmpq_mat:
    """Acl = A − L C as an ``fmpq_mat`` (exact): :func:`closed_loop` without the conversion
    back to an object array, for the exact checks of eq. (4)-(6) (constrained-redesign paper,
    Astolfi et al., NOLCOS 2019) that take it again and again.

    :param A: n×n state matrix; :param C: p×n output matrix; :param L: n×p gain."""
    if isinstance(A, fmpq_mat) and isinstance(C, fmpq_mat) and isinstance(L, fmpq_mat):
        return A - L * C
    if _rows(A) == 0 or _rows(C) == 0:  # no states or no outputs: L C = 0
        return fmat(A)
    return fmat(A) - fmat(L) * fmat(C)


def _rows(M: Any) -> int:
    """Rows of a flint matrix or of anything numpy reads as a matrix (a mix of the two
    raised IndexError in :func:`closed_loop_fmat`)."""
    return M.nrows() if isinstance(M, (fmpq_mat, fmpz_mat)) else int(np.shape(M)[0])


def dyadic_fmat(x: Any, bits: int) -> tuple[fmpq_mat, np.ndarray]:
    """:func:`obsdesign.certify.exact.dyadic` of a float matrix (each float rounded
    half-to-even to ``bits`` ≤ 62 significant bits; beyond 53 the float itself) as an
    ``fmpq_mat``, and the float copy of those values, built from one integer matrix over a
    common power of two (no per-entry rational): the rounded P, X and L of eq. (4)-(6)
    (constrained-redesign paper, Section 5) at n = 100 in milliseconds.

    The float copy holds the rounded values themselves (exact in the normal range; ``ldexp``
    rounds correctly below it), i.e. the correctly rounded copy that
    :mod:`obsdesign.certify.enclosure` needs.

    :param x: finite float matrix; :param bits: significant bits (1 … 62)."""
    if not 1 <= bits <= 62:
        raise ValueError("bits must be in 1 … 62")
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 2 or not np.all(np.isfinite(arr)):
        raise ValueError("cannot round a non-finite number (or not a matrix)")
    r, c = arr.shape
    m, e = np.frexp(arr)
    num = np.rint(np.ldexp(m, bits)).astype(np.int64)  # |num| ≤ 2^bits ≤ 2^62, exact scaling
    k = (bits - e).astype(np.int64)  # value = num · 2^-k
    flo = np.ldexp(num.astype(float), -k)
    nz = num != 0
    if not nz.any():
        return fmpq_mat(r, c), flo
    K = max(int(k[nz].max()), 0)
    sh = K - k  # ≥ 0 on the nonzero entries: value · 2^K = num · 2^sh
    if int(sh[nz].max()) <= 62 - bits:
        ints = np.where(nz, np.left_shift(num, np.where(nz, sh, 0)), 0).ravel().tolist()
    else:
        ints = [
            a << b if a else 0
            for a, b in zip(num.ravel().tolist(), sh.ravel().tolist(), strict=True)
        ]
    F = fmpq_mat(fmpz_mat(r, c, ints))
    return (F / fmpz(2) ** K if K else F), flo


class ExactMemo:
    """Exact verdicts the design made, for ``certify`` within the same process: a verdict is
    returned only for exactly the same inputs (the matrices are compared exactly, entry by
    entry in flint), so it is the verdict a recomputation would give. ``verify`` loads the
    spec anew and never sees it (it recomputes everything)."""

    def __init__(self) -> None:
        self._d: dict[tuple[Any, ...], tuple[tuple[fmpq_mat, ...], Any]] = {}

    def __reduce__(self) -> tuple[type, tuple[()]]:
        # a copied or pickled spec (e.g. sent to a Dask worker) gets an empty memo: the
        # verdicts stay in this process (and flint matrices do not pickle)
        return (ExactMemo, ())

    def put(self, key: tuple[Any, ...], mats: tuple[fmpq_mat, ...], value: Any) -> None:
        """Record ``value`` for ``key`` (exact scalars and flags) and the exact ``mats``."""
        self._d[key] = (mats, value)

    def get(self, key: tuple[Any, ...], mats: tuple[fmpq_mat, ...]) -> Any:
        """The recorded value when ``key`` and every matrix match exactly, else None."""
        hit = self._d.get(key)
        if hit is None or len(hit[0]) != len(mats):
            return None
        for a, b in zip(hit[0], mats, strict=True):
            if a.nrows() != b.nrows() or a.ncols() != b.ncols() or a != b:
                return None
        return hit[1]


#: the :class:`ExactMemo` key of A − LC: the matrix L compared exactly, the value (copies of
#: A and C, A − LC) used only for A and C with exactly these entries
CLOSED_LOOP_KEY = ("closed-loop",)

#: the attribute of a bound spec under which the design leaves its :class:`ExactMemo`
MEMO_ATTR = "_lyapunov_exact_memo"


def memo_of(spec: Any) -> ExactMemo | None:
    """The :class:`ExactMemo` the design left on this very spec object, if any."""
    m = getattr(spec, MEMO_ATTR, None)
    return m if isinstance(m, ExactMemo) else None


def attach_memo(spec: Any, memo: ExactMemo) -> None:
    """Leave ``memo`` on the spec object for ``certify`` in the same process (best effort)."""
    try:
        setattr(spec, MEMO_ATTR, memo)
    except (AttributeError, TypeError):
        pass


def decay_verdict(
    Acl: fmpq_mat,
    P: Any,
    rate: Any,
    discrete: bool,
    margin: Any,
    memo: ExactMemo | None = None,
    Pm: fmpq_mat | None = None,
    Af: np.ndarray | None = None,
    Pf: np.ndarray | None = None,
) -> tuple[Any, bool]:
    """The exact verdict on the decay LMI of eq. (4)-(6) (constrained-redesign paper, Astolfi
    et al., NOLCOS 2019) — :func:`decay_fmat` − margin·I ≻ 0 by :func:`decay_pd` (the
    tests of :func:`obsdesign.certify.psd.check_pd_fast` on the integer matrix) — and the
    float verdict beside it
    (λ_min of the float matrix > 0), looked up in / recorded into ``memo``.

    :param Acl: exact A − LC; :param P: symmetric n×n (exact); :param rate: λ or α;
    :param discrete: time domain; :param margin: δ; :param memo: verdicts of this process;
    :param Pm: ``P`` as an ``fmpq_mat`` when already converted; :param Af: :func:`mat_float`
    of Acl, when already made; :param Pf: the correctly rounded float copy of P, when
    already made."""
    Pm = fmat(P) if Pm is None else Pm
    key = ("decay", Q(rate), Q(margin), discrete)
    if memo is not None:
        hit = memo.get(key, (Acl, Pm))
        if hit is not None:
            return hit
    r, H = decay_pd(Acl, Pm, rate, discrete, margin, Af, Pf)
    fl = bool(np.linalg.eigvalsh(H).min() > 0) if H is not None and H.size else True
    if memo is not None:
        memo.put(key, (Acl, Pm), (r, fl))
    return r, fl


def pd_verdict(
    P: Any,
    margin: Any,
    memo: ExactMemo | None = None,
    Pm: fmpq_mat | None = None,
    Pf: np.ndarray | None = None,
) -> Any:
    """P − margin·I ≻ 0 exactly: V = eᵀPe of eq. (4) (constrained-redesign paper) is positive
    definite; looked up in / recorded into ``memo``. With the correctly rounded float copy
    ``Pf`` (e.g. :func:`dyadic_fmat`'s, the values themselves), the verified Cholesky of
    :mod:`obsdesign.certify.vchol` runs on it first (step 1 of its theorem is what correct
    rounding gives); otherwise, and whenever that does not prove, :func:`pd_int` decides.

    :param P: symmetric matrix; :param margin: δ; :param memo: verdicts of this process;
    :param Pm: ``P`` as an ``fmpq_mat`` when already converted; :param Pf: its correctly
    rounded float copy, when already made."""
    Pm = fmat(P) if Pm is None else Pm
    key = ("pd", Q(margin))
    if memo is not None:
        hit = memo.get(key, (Pm,))
        if hit is not None:
            return hit
    r = pd_small(Pm, margin)
    if r is None and Pf is not None:
        r = _pd_float(Pm, Q(margin), Pf)
    if r is None:
        r = pd_int(Pm, margin)
    if memo is not None:
        memo.put(key, (Pm,), r)
    return r


def _pd_float(Pm: fmpq_mat, m: fmpq, Pf: np.ndarray) -> Any:
    """The proof of :func:`pd_verdict` by the verified Cholesky of the float copy, or None."""
    from obsdesign.certify import vchol
    from obsdesign.certify.exact import float_or_inf
    from obsdesign.certify.psd import PSDResult

    n = Pm.nrows()
    if m < 0 or n == 0 or Pf.shape != (n, n) or Pm != Pm.transpose():
        return None
    if not (np.all(np.isfinite(Pf)) and np.array_equal(Pf, Pf.T)):
        return None
    v = vchol.verified_pd_float(Pf, m)
    if v is None:
        return None
    return PSDResult(True, float_or_inf(v.bound), v.detail, "verified-float")


def pd_small(Pm: fmpq_mat, margin: Any) -> Any:
    """P − margin·I ≻ 0 decided exactly by the fraction-free LDLᵀ of the integer matrix
    b·P_z − a·d·I (as :func:`pd_int`) when that is the cheap proof
    (:func:`obsdesign.certify.psd.fflu_cheap`: small n, short entries, where the verified
    float Cholesky's fixed cost dominates); None otherwise (eq. (4) of the
    constrained-redesign paper, Astolfi et al., NOLCOS 2019: V = eᵀPe positive definite).

    :param Pm: symmetric P (exact); :param margin: δ ≥ 0 (exact)."""
    from obsdesign.certify.psd import fflu_cheap, fraction_free_int

    if Pm.nrows() > FFLU_MAX_N or Pm.nrows() == 0 or Pm != Pm.transpose():
        return None
    Z, c = _minus_margin(*Pm.numer_denom(), margin)
    return fraction_free_int(Z, c) if fflu_cheap(Z) else None


def pd_int(Pm: fmpq_mat, margin: Any) -> Any:
    """P − margin·I ≻ 0 exactly, decided on the integer matrix b·P_z − a·d·I (P = P_z/d,
    margin a/b; the same matrix times the positive 1/(bd)) by
    :func:`obsdesign.certify.psd.check_pd_int`: the verdict of
    :func:`obsdesign.certify.psd.check_pd_fast` without P's rational entries (eq. (4) of the
    constrained-redesign paper, Astolfi et al., NOLCOS 2019: V = eᵀPe positive definite).

    :param Pm: P (exact); :param margin: δ ≥ 0 (exact)."""
    from obsdesign.certify.psd import (
        _square_symmetric,
        check_pd_int,
        common_denominator,
        too_costly,
    )

    early = _square_symmetric(Pm)  # before the common denominator (see :func:`decay_pd`)
    if early is not None:
        return early
    got = common_denominator(Pm)
    if got is None:
        return too_costly("P")
    return check_pd_int(*_minus_margin(*got, margin))[0]


def _minus_margin(Z: fmpz_mat, D: Any, margin: Any) -> tuple[fmpz_mat, fmpq]:
    """(Z', c) with Z/D − margin·I = c·Z' (c > 0): Z' = b·Z − a·D·I for margin a/b."""
    m = Q(margin)
    if m != 0:
        Z = Z * m.q
        sub = m.p * D
        for i in range(Z.nrows()):
            Z[i, i] = Z[i, i] - sub
    return Z, fmpq(1) / (fmpq(D) * m.q)


#: the largest n at which :func:`pd_small` and :func:`decay_pd` try the fraction-free LDLᵀ
#: first (:func:`obsdesign.certify.psd.fflu_cheap` then decides by the entries' size); 0
#: turns that path off (the float proofs run first, as for larger n)
FFLU_MAX_N = 10


#: the prime of :func:`observable_mod_p` (2⁶¹ − 1, a Mersenne prime)
PRIME = 2**61 - 1


def observable_mod_p(A: Any, C: Any) -> bool:
    """A fast proof that (C, A) is observable (True), or no conclusion (False).

    With D_A, D_C the common denominators, the integer blocks C_z A_z^k = D_C D_A^k C A^k span
    the same row space as the observability matrix [C; CA; …; CA^{n−1}]; their rank modulo the
    prime :data:`PRIME` is at most the rank over Q (a minor that is nonzero mod p is nonzero),
    so rank n mod p proves the Kalman rank condition. False means only "not proved" (the
    exact test of :mod:`obsdesign.certify.detect` then decides). The observer of Section 5 of
    the constrained-redesign paper (Astolfi et al., NOLCOS 2019) needs (C, A) detectable.

    :param A: n×n matrix; :param C: p×n matrix (exact or floats, converted exactly)."""
    from flint import nmod_mat

    Af, Cf = fmat(A), fmat(C)
    n = Af.nrows()
    if n == 0:
        return True
    if Cf.nrows() == 0:
        return False
    Az, _ = Af.numer_denom()
    Cz, _ = Cf.numer_denom()
    Am = nmod_mat(Az, PRIME)  # reduced modulo the prime in flint
    p = Cf.nrows()
    Cm = nmod_mat(Cz, PRIME)
    # first one fixed combination c = Σ (i+1)·C_z[i] of the outputs: its Krylov rows
    # c, cA, …, cA^{n−1} lie in the row space, so rank n of that n×n matrix is enough
    # (generic A); else all p·n rows
    for block in (nmod_mat(1, p, list(range(1, p + 1)), PRIME) * Cm, Cm):
        rows: list[Any] = []
        for _ in range(n):
            rows += block.entries()
            block = block * Am
        if nmod_mat(len(rows) // n, n, [int(v) for v in rows], PRIME).rank() == n:
            return True
    return False


def fmat(M: Any) -> fmpq_mat:
    """An exact object array (or any matrix :func:`obsdesign.certify.exact.Q` converts) as a
    flint ``fmpq_mat``: products of n = 100 matrices run in C instead of n³ Python ``fmpq``
    operations (the Lyapunov maths of Section 5, constrained-redesign paper, at scale).

    :param M: the matrix."""
    return to_fmpq_mat(M)


def as_array(M: fmpq_mat) -> np.ndarray:
    """An ``fmpq_mat`` back as an exact object array (see :func:`fmat`).

    :param M: the flint matrix."""
    r, c = M.nrows(), M.ncols()
    return np.array(M.entries(), dtype=object).reshape(r, c)


def _sym(M: fmpq_mat) -> fmpq_mat:
    return (M + M.transpose()) * fmpq(1, 2)


def decay_int(Acl: Any, P: Any, rate: Any, discrete: bool) -> tuple[fmpz_mat, fmpz]:
    """(Z, D) with :func:`decay_fmat` = Z / D exactly: an integer matrix and a positive
    integer, the decay matrix of eq. (5)-(6) with w = 0 (constrained-redesign paper, Astolfi
    et al., NOLCOS 2019) before any rational entry is formed.

    With Acl = A_z/d_A, P = P_z/d_P and the rate p/q: λ²P − AclᵀPAcl =
    (p² d_A² P_z − q² A_zᵀP_zA_z) / (q² d_A² d_P) (discrete) and −(AclᵀP + PAcl + 2αP) =
    −(q (A_zᵀP_z + P_zA_z) + 2p d_A P_z) / (q d_A d_P) (continuous); when P_z is not
    symmetric, Z + Zᵀ over 2D, i.e. (M + Mᵀ)/2.

    :param Acl: the error dynamics matrix; :param P: n×n (exact); :param rate: λ or α;
    :param discrete: time domain."""
    Am, Pm = fmat(Acl), fmat(P)
    r = Q(rate)
    Az, da = Am.numer_denom()
    Pz, dp = Pm.numer_denom()
    rp, rq = r.p, r.q
    if discrete:
        Z = Pz * (rp * rp * da * da) - (Az.transpose() * Pz * Az) * (rq * rq)
        D = rq * rq * da * da * dp
    else:
        Z = -((Az.transpose() * Pz + Pz * Az) * rq + Pz * (2 * rp * da))
        D = rq * da * dp
    if Pz != Pz.transpose():
        Z, D = Z + Z.transpose(), 2 * D
    return Z, fmpz(D)


def decay_fmat(Acl: Any, P: Any, rate: Any, discrete: bool) -> fmpq_mat:
    """:func:`decay_matrix` for a given Acl = A − LC, as an ``fmpq_mat`` (exact, fast):
    λ²P − AclᵀPAcl (discrete, eq. (5)-(6) with w = 0, constrained-redesign paper, Astolfi et
    al., NOLCOS 2019) or −(AclᵀP + PAcl + 2αP) (continuous), symmetrized as (M + Mᵀ)/2;
    the products run over Z (:func:`decay_int`).

    :param Acl: the error dynamics matrix; :param P: symmetric n×n; :param rate: λ or α;
    :param discrete: time domain."""
    Z, D = decay_int(Acl, P, rate, discrete)
    return fmpq_mat(Z) / D


def decay_pd(
    Acl: Any,
    P: Any,
    rate: Any,
    discrete: bool,
    margin: Any,
    Af: np.ndarray | None = None,
    Pf: np.ndarray | None = None,
) -> tuple[Any, Any]:
    """:func:`decay_fmat` − margin·I ≻ 0, decided exactly: eq. (4)-(6) of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019).

    First the float enclosure of :mod:`obsdesign.certify.enclosure` (BLAS products of the
    correctly rounded A − LC and P with a rigorous error bound e, and a verified Cholesky with
    the margin raised by e; it can only prove), else the integer matrix Z·b − a·D·I (margin
    a/b, decay matrix Z/D from :func:`decay_int`; the same matrix times the positive 1/(bD))
    by :func:`obsdesign.certify.psd.check_pd_int`, which decides either way.

    :param Acl, P, rate, discrete: as in :func:`decay_int`; :param margin: δ ≥ 0 (exact);
    :param Af: the correctly rounded float copy of Acl (:func:`mat_float`, which is
    :func:`obsdesign.certify.vchol.to_float` whenever it returns), when already made: the
    enclosure's error bound assumes it; :param Pf: the same for P (e.g. from
    :func:`dyadic_fmat`). Returns the verdict and the float matrix beside it (≈ the decay matrix − δI, or a
    positive multiple of it), as :func:`obsdesign.certify.psd.check_pd_fast_float`."""
    from obsdesign.certify.psd import (
        check_pd_int,
        common_denominator,
        diag_dominant_int,
        fflu_cheap,
        fraction_free_int,
        too_costly,
    )
    from obsdesign.certify.vchol import int_to_float

    Am, Pm = fmat(Acl), fmat(P)
    if _decay_small(Am, Pm, Q(rate), discrete, Q(margin), Af):
        Zm, c = _minus_margin(*decay_int(Am, Pm, rate, discrete), margin)
        dd = diag_dominant_int(Zm, c)  # ≈ c·I when P solves the Lyapunov equation
        if dd is not None:
            return dd, None
        if fflu_cheap(Zm):  # the exact LDLᵀ costs less than the enclosure here
            r = fraction_free_int(Zm, c)
            return r, (None if r.ok else int_to_float(Zm)[0])
    hit = _enclosure_pd(Am, Pm, Q(rate), discrete, Q(margin), Af, Pf)
    if hit is not None:
        return hit
    for M, what in ((Am, "A − LC"), (Pm, "P")):  # decay_int's common denominators
        if common_denominator(M) is None:
            return too_costly(what), None
    Z, D = decay_int(Am, Pm, rate, discrete)
    return check_pd_int(*_minus_margin(Z, D, margin))


#: :func:`_decay_small`'s bound on the estimated bits of the integer decay matrix's entries
DECAY_SMALL_BITS = 4096


def _decay_small(
    Am: fmpq_mat, Pm: fmpq_mat, r: fmpq, discrete: bool, m: fmpq, Af: np.ndarray | None
) -> bool:
    """Whether :func:`decay_pd` should form the integer decay matrix (:func:`decay_int`)
    before the float enclosure, for the exact diagonal-dominance proof
    (:func:`obsdesign.certify.psd.diag_dominant_int`) or the fraction-free LDLᵀ: n at most
    :data:`FFLU_MAX_N` and an estimate of its entries' bits (from those of A − LC, P, the
    rate and the margin, as :func:`decay_int` and :func:`_minus_margin` combine them) at most
    :data:`DECAY_SMALL_BITS`. A speed choice only (measured in a whole design + verify: at
    n = 8 and 10 the four decay checks cost half of what the enclosures do; at n = 12 and 16
    more)."""
    n = Am.nrows()
    if not 0 < n <= FFLU_MAX_N or m < 0 or (discrete and r <= 0) or Pm != Pm.transpose():
        return False
    Pz = Pm.numer_denom()[0]
    da = Am.numer_denom()[1]
    top = float(np.max(np.abs(Af))) if Af is not None and Af.size else 0.0
    a_bits = int(da).bit_length() + (math.frexp(top)[1] if 0 < top < math.inf else 64)
    p_bits = max(Pz[i, i].bit_length() for i in range(n))
    r_bits = max(int(r.p).bit_length(), int(r.q).bit_length())
    m_bits = int(m.q).bit_length() if m else 0
    return 2 * a_bits + p_bits + 2 * r_bits + m_bits <= DECAY_SMALL_BITS


def _enclosure_pd(
    Am: fmpq_mat,
    Pm: fmpq_mat,
    r: fmpq,
    discrete: bool,
    m: fmpq,
    Af: np.ndarray | None,
    Pf: np.ndarray | None = None,
) -> tuple[Any, np.ndarray] | None:
    """The proof of :func:`decay_pd` through the float enclosure, or None (not proved)."""
    from obsdesign.certify import vchol
    from obsdesign.certify.enclosure import decay_enclosure
    from obsdesign.certify.exact import float_or_inf
    from obsdesign.certify.psd import PSDResult

    if Am.nrows() == 0 or m < 0 or (discrete and r <= 0):
        return None
    if Af is None or not np.all(np.isfinite(Af)):
        Af = vchol.to_float(Am)  # correctly rounded, or None beyond the float range
    if Pf is None or Pf.shape != (Pm.nrows(), Pm.ncols()) or not np.all(np.isfinite(Pf)):
        Pf = vchol.to_float(Pm)
    if Af is None or Pf is None:
        return None
    enc = decay_enclosure(Af, Pf, r, discrete)
    if enc is None:
        return None
    H, e = enc
    v = vchol.verified_pd_float(H, m + e)
    if v is None:
        return None
    n = H.shape[0]
    detail = (
        f"float enclosure ‖M − V‖₂ ≤ {float_or_inf(e):.3g} (V the float matrix); verified "
        f"float Cholesky of V: "
        f"λ_min(M − δI) ≥ {float_or_inf(v.bound):.3g} > 0 (n = {n})"
    )
    Hm = H - float(m) * np.eye(n)
    return PSDResult(True, float_or_inf(v.bound), detail, "float-enclosure"), Hm


def decay_matrix(
    A: np.ndarray, C: np.ndarray, L: np.ndarray, P: np.ndarray, rate: Any, discrete: bool
) -> np.ndarray:
    """The matrix that is ⪰ 0 exactly when V = eᵀPe decays at ``rate`` (exact).

    Discrete: λ² P − Aclᵀ P Acl, i.e. eq. (5) with w = 0 and β(v, 0) = ρ v, ρ = λ² (eq. (6));
    continuous: −(Aclᵀ P + P Acl + 2α P), i.e. V̇ ≤ −2α V. Section 5 of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019) certifies its P this way.
    Computed through :func:`decay_fmat` (flint), returned as an object array.

    :param A, C, L: plant and gain (exact); :param P: symmetric n×n (exact);
    :param rate: λ (discrete) or α (continuous); :param discrete: time domain."""
    return as_array(decay_fmat(fmat(A) - fmat(L) * fmat(C), P, rate, discrete))


def error_input(Bd: np.ndarray, Dn: np.ndarray, L: np.ndarray) -> np.ndarray:
    """B_w = [−Bd, L Dn] (exact): how w = (d, v) enters the error dynamics, eq. (3) of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019) for a linear observer.

    :param Bd: n×k process-disturbance input (k may be 0); :param Dn: p×q output-noise input
    (q may be 0); :param L: n×p gain. Returns n×(k+q), zero columns when both are empty."""
    n = L.shape[0]
    parts = []
    if Bd.shape[1]:
        parts.append(-Bd)
    if Dn.shape[1]:
        parts.append(L @ Dn)
    if not parts:
        return np.full((n, 0), fmpq(0), dtype=object)
    return np.hstack(parts)


def iss_matrix(
    Acl: np.ndarray, Bw: np.ndarray, P: np.ndarray, rho: Any, mu: Any, discrete: bool = True
) -> np.ndarray:
    """Block matrix that is ⪰ 0 exactly when the ISS inequality holds (exact).

    Discrete, eq. (5) with β(v, w) = ρ v + μ|w|² (eq. (6)) of the constrained-redesign paper
    (Astolfi et al., NOLCOS 2019): [[ρP − AclᵀPAcl, −AclᵀPB_w], [−B_wᵀPAcl, μI − B_wᵀPB_w]].
    Continuous, V̇ ≤ −ρ V + μ|w|² (ρ = 2α): [[−(AclᵀP + PAcl + ρP), −PB_w], [−B_wᵀP, μI]].

    :param Acl: A − LC; :param Bw: error input (:func:`error_input`); :param P: the Lyapunov
    matrix; :param rho: decay factor of V (λ² discrete, 2α continuous); :param mu: ISS gain."""
    k = Bw.shape[1]
    r = Q(rho)
    Am, Pm = fmat(Acl), fmat(P)
    if discrete:
        S = _sym(Pm * r - Am.transpose() * Pm * Am)
    else:
        S = _sym(-(Am.transpose() * Pm + Pm * Am + Pm * r))
    if k == 0:
        return as_array(S)
    Bm = fmat(Bw)
    if discrete:
        off = -(Am.transpose() * Pm * Bm)
        low = fmpq_mat(k, k, [Q(mu) if i == j else fmpq(0) for i in range(k) for j in range(k)])
        low = low - Bm.transpose() * Pm * Bm
    else:
        off = -(Pm * Bm)
        low = fmpq_mat(k, k, [Q(mu) if i == j else fmpq(0) for i in range(k) for j in range(k)])
    S_, off_, low_ = as_array(S), as_array(off), as_array(low)
    return symmetrize(np.block([[S_, off_], [off_.T, low_]]))


def decay_factor(rate: Any, discrete: bool) -> fmpq:
    """ρ of β(v, w) = ρ v + μ|w|² (eq. (6), constrained-redesign paper) for a decay rate:
    λ² (discrete) or 2α (continuous, V̇ ≤ −2αV + μ|w|²).

    :param rate: λ or α; :param discrete: time domain."""
    r = Q(rate)
    return r * r if discrete else 2 * r


def iss_mu(
    Acl: np.ndarray,
    Bw: np.ndarray,
    P: np.ndarray,
    rho: Any,
    discrete: bool = True,
    strict: bool = False,
    rel: float = 1e-9,
    remedy: str = "give a larger [method].lambda (or [method].rate_tol when λ is the best rate)",
) -> fmpq:
    """Smallest ISS gain μ (rounded up, then certified exactly) for the given ρ.

    Schur complement of :func:`iss_matrix` (eq. (5)-(6) of the constrained-redesign paper,
    Astolfi et al., NOLCOS 2019): μ ≥ λ_max(B_wᵀPB_w + B_wᵀPAcl S⁻¹ AclᵀPB_w) with
    S = ρP − AclᵀPAcl ≻ 0 (discrete), μ ≥ λ_max(B_wᵀP S⁻¹ P B_w) with
    S = −(AclᵀP + PAcl + ρP) (continuous). The float value raised by ``rel`` (relative) is
    rounded up to 30 bits and raised by 10 % steps until the exact check passes. The lyapunov
    method asks rel = 10⁻⁶: at 10⁻⁹ the block matrix was so close to singular that the
    verified float Cholesky could not decide it and a 100-state plant went to exact
    elimination, twice (design and certify), 12.6 s instead of 1.2 s (lyapunov fuzz, session
    38); the constrained method keeps 10⁻⁹ (its μ enters v_max, ε_max, γ).

    :param Acl, Bw, P, rho, discrete: as in :func:`iss_matrix`;
    :param strict: certify the block matrix ≻ 0 (``check_pd``) instead of ⪰ 0 (``check_psd``);
    :param rel: the relative step above the float μ;
    :param remedy: what the message of a float-singular S tells the user to change.
    Returns μ (0 when B_w has no column). Raises :class:`InconclusiveError` when no μ certifies.
    """
    if Bw.shape[1] == 0:
        return fmpq(0)
    Af, Bf, Pf = (np.asarray(M, dtype=float) for M in (Acl, Bw, P))
    r = Q(rho)
    S = np.asarray(iss_matrix(Acl, Bw[:, :0], P, r, 0, discrete), dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):  # a non-finite G is OverflowError below
        try:
            if discrete:
                G = Bf.T @ Pf @ Bf + Bf.T @ Pf @ Af @ np.linalg.solve(S, Af.T @ Pf @ Bf)
            else:
                G = Bf.T @ Pf @ np.linalg.solve(S, Pf @ Bf)
        except np.linalg.LinAlgError:
            # S singular in floats: ρ = λ² = 10⁻⁶⁰⁰ underflows to 0 (constrained, A − LC
            # nilpotent, λ = 1e-300, margin = 0: exit 3 "Singular matrix"; re-check review,
            # session 42)
            raise InconclusiveError(
                "the ISS gain μ of eq. (5): S = ρP − (A − LC)ᵀP(A − LC) is singular in floats "
                f"(ρ = {float(r):.3g}): a rate this close to 0 leaves the float range; " + remedy
            ) from None
    # G/2 + Gᵀ/2, not (G + Gᵀ)/2: the sum overflowed for entries above 9e307, half the float
    # range, and a μ ≈ 9.96e307 that certifies was refused (re-check trial, session 29)
    H = G / 2 + G.T / 2
    mu_f = float(np.linalg.eigvalsh(H).max()) if np.all(np.isfinite(H)) else np.inf
    if not math.isfinite(mu_f * (1 + 1e-9)):
        # Bd = 1e150 made μ ≈ 1e311: "cannot round a non-finite number", exit 3 (rendering
        # soundness trial, session 29); OverflowError is exit 4 (api.captured_warnings)
        raise OverflowError("the ISS gain μ of eq. (5) is beyond the float range")
    # the first step and the raise are relative to the data: a fixed +1e-12 / +1e-9 made the
    # μ of a plant with |B_w|²‖P‖ ≈ 1e-20 about 10¹¹ times too large (still true, not tight)
    floor = fmpq(1, 2**40) * _mu_scale(Bf, Pf, mu_f)
    mu = dyadic(max(mu_f, 0.0) * (1 + rel) + float(floor), 30)
    check = check_pd_fast if strict else check_psd
    for _ in range(80):
        if check(iss_matrix(Acl, Bw, P, r, mu, discrete)):
            return mu
        mu = mu * fmpq(11, 10) + floor
    raise InconclusiveError(
        "could not certify the ISS gain μ of eq. (5) (rate too close to its limit?)"
    )


def _mu_scale(Bf: np.ndarray, Pf: np.ndarray, mu_f: float) -> fmpq:
    """The size of the terms of the ISS gain μ (eq. (5)-(6), constrained-redesign paper):
    max(μ̃, ‖B_w‖²_F·‖P‖_F) as an exact dyadic (1 when both are 0), so that the first rounding
    step of :func:`iss_mu` and its raises scale with the plant, not with 1.

    :param Bf, Pf: B_w and P in floats; :param mu_f: the float μ."""
    s = max(abs(mu_f), float(np.sum(Bf * Bf)) * float(np.linalg.norm(Pf)))
    if not (math.isfinite(s) and s > 0):
        return fmpq(1)
    return dyadic(s, 30)


# -- exact stability tests (the infeasible end of a rate bracket) ---------------------------
def _charpoly(M: np.ndarray) -> fmpq_poly:
    return fmat(M).charpoly()


#: significant bits of the rounded Lyapunov solution used as an inertia certificate
INERTIA_BITS = 60


#: up to this state dimension the Lyapunov equations are solved as one n²×n² linear system
#: (numpy), above it by scipy's Schur-based solvers
KRONECKER_MAX_N = 8


def solve_lyapunov(Acl: np.ndarray, rate: float, discrete: bool) -> np.ndarray:
    """Float X with λ²X − AclᵀXAcl = I (discrete; λ = ``rate``) or
    −((Acl+αI)ᵀX + X(Acl+αI)) = I (continuous; α = ``rate``): the Lyapunov equations of the
    certificates (eq. (4)-(6), constrained-redesign paper, with Q = I).

    Up to :data:`KRONECKER_MAX_N` states the equation is solved as its n²×n² linear system,
    (λ²I − Aclᵀ⊗Aclᵀ) vec X = vec I or −(M⊗I + I⊗M) vec X = vec I with M = (Acl+αI)ᵀ, by
    numpy's LU: a few microseconds, where importing scipy.linalg costs ~0.3 s of a cold
    command (scipy's own ``solve_discrete_lyapunov`` takes this direct route below 10
    states; the residuals are as small as scipy's on random systems up to 8 states). A
    singular system (eigenvalues of the operator at 0, e.g. α between two modes of a
    continuous Acl) gets numpy's least-squares solution, as scipy's solvers perturb and go on.
    Larger systems use scipy's ``solve_discrete_lyapunov`` / ``solve_continuous_lyapunov``
    (O(n³)). Either way X is only a candidate: the exact checks decide. Raises numpy's
    LinAlgError (or ValueError) when the solver fails or the operator overflows float64.

    :param Acl: the float closed-loop matrix; :param rate: λ or α; :param discrete: time domain."""
    Af = np.asarray(Acl, dtype=float)
    n = Af.shape[0]
    eye = np.eye(n)
    if n <= KRONECKER_MAX_N:
        # the Kronecker products by broadcasting (np.kron's own overhead was ~3× the work);
        # an overflow is caught by the finiteness test below
        with np.errstate(over="ignore", invalid="ignore"):
            if discrete:
                At = Af.T
                K = -(At[:, None, :, None] * At[None, :, None, :]).reshape(n * n, n * n)
                K.flat[:: n * n + 1] += rate * rate  # λ²I − Aclᵀ⊗Aclᵀ
            else:
                M = (Af + rate * eye).T
                idx = np.arange(n)
                K4 = np.zeros((n, n, n, n))
                K4[:, idx, :, idx] = M  # M⊗I: entry ((a, i), (b, i)) = M[a, b]
                K4[idx, :, idx, :] += M  # I⊗M: entry ((i, a), (i, b)) = M[a, b]
                K = -K4.reshape(n * n, n * n)
        if not np.all(np.isfinite(K)):
            # ‖Acl‖² beyond the float range: LAPACK's least-squares SVD never returns on an
            # inf entry (hard-case fuzzer: A = [[0.5, 1e200], [0, 0.5]] hung, past Ctrl-C and
            # check --timeout); the callers take this as "no float solution"
            raise np.linalg.LinAlgError("the Lyapunov operator overflows float64")
        rhs = eye.reshape(-1)
        try:
            return np.linalg.solve(K, rhs).reshape(n, n)
        except np.linalg.LinAlgError:
            return np.linalg.lstsq(K, rhs, rcond=None)[0].reshape(n, n)
    from scipy.linalg import solve_continuous_lyapunov, solve_discrete_lyapunov

    if discrete:
        return solve_discrete_lyapunov((Af / rate).T, eye / rate**2)
    return solve_continuous_lyapunov((Af + rate * eye).T, -eye)


def lyapunov_solver_name(n: int, discrete: bool) -> str:
    """The solver :func:`solve_lyapunov` uses for ``n`` states, as reports name it.

    :param n: state dimension; :param discrete: time domain."""
    if n <= KRONECKER_MAX_N:
        return "Lyapunov equation: numpy, one n²×n² linear system"
    return f"Lyapunov equation: scipy solve_{'discrete' if discrete else 'continuous'}_lyapunov"


def sym_part(M: np.ndarray) -> np.ndarray:
    """(M + Mᵀ)/2 of a float matrix as M/2 + Mᵀ/2: no overflow for entries near the float
    range (M + Mᵀ overflowed to inf there: a plant with entries of 1e150 made the Lyapunov
    solution X of eq. (4)-(6), constrained-redesign paper, non-finite and exit 3; unusual-spec
    trial, session 24); the same bits as (M + Mᵀ)/2 unless an entry is subnormal."""
    return M / 2 + M.T / 2


def _lyap_solution(Acl: np.ndarray, rate: float, discrete: bool) -> np.ndarray | None:
    """Float X of :func:`solve_lyapunov`, whatever the stability of Acl (an unstable Acl
    gives an indefinite X); None when the solver fails."""
    import warnings

    try:
        # a near-singular equation warns and perturbs; the exact check judges the answer
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            X = solve_lyapunov(Acl, rate, discrete)
    except (np.linalg.LinAlgError, ValueError):
        return None
    if not np.all(np.isfinite(X)):
        return None
    S = sym_part(X)
    return S if np.all(np.isfinite(S)) else None


def infeasible_head(margin: Any) -> str:
    """How an "infeasible rate" message starts: "no P ≻ 0 gives" (strict decay, margin > 0),
    or "no P ≻ 0 from the Lyapunov equation gives" when the margin is 0 and some P might
    meet the non-strict claim (:func:`nonstrict_note`).

    :param margin: the spec's margin (exact)."""
    return "no P ≻ 0 gives" if margin != 0 else "no P ≻ 0 from the Lyapunov equation gives"


def nonstrict_note(margin: Any, discrete: bool) -> str:
    """The clause an "infeasible rate" message adds when the margin is 0: the decay claim is
    then non-strict (⪰ 0), which a P can meet at an eigenvalue exactly on the limit (a
    diagonalizable A − LC with ρ = λ: the constrained soundness trial's exact P, session 25),
    while the design's P solves the Lyapunov equation, which needs every eigenvalue strictly
    inside; "" for a positive margin.

    :param margin: the spec's margin (exact); :param discrete: the time domain."""
    if margin != 0:
        return ""
    where = "|z| = λ" if discrete else "Re z = −α"
    return (
        f" (with margin = 0 the decay claim is non-strict, and a P may meet it at an eigenvalue "
        f"with {where} when A − LC is diagonalizable there; the design's P solves the "
        "Lyapunov equation, which needs every eigenvalue strictly inside)"
    )


def rate_feasibility(
    Acl: Any,
    rate: Any,
    discrete: bool,
    memo: ExactMemo | None = None,
    Af: np.ndarray | None = None,
) -> tuple[bool, str]:
    """Whether some P ≻ 0 makes :func:`decay_matrix` ≻ 0 at ``rate``, decided exactly, and how.

    Feasible iff every eigenvalue z of Acl has |z| < λ (discrete) / Re z < −α (continuous).
    Decided by the first proof that goes through:

    1. *Lyapunov inertia certificate* (cheap at n = 100): X solves the Lyapunov equation with
       right-hand side I in floats and is rounded to a dyadic rational X; if the exact
       decay matrix D(X) ≻ 0 (:func:`obsdesign.certify.psd.check_pd_fast`), then X ≻ 0 proves
       the rate feasible (X is a certificate), and X ⊁ 0 proves it infeasible: were Acl/λ
       Schur (Acl + αI Hurwitz), the equation λ²Y − AclᵀYAcl = D(X) would have the unique
       solution Y = Σ_k (Acl/λ)ᵀᵏ (D(X)/λ²) (Acl/λ)ᵏ ≻ 0 (continuous: ∫ e^{Bᵀt} D(X) e^{Bt} dt,
       B = Acl + αI), and Y = X. Whether X ≻ 0 is decided by the fraction-free LDLᵀ at small
       n (:func:`pd_small`), else by a rational direction v with vᵀXv < 0 or :func:`pd_int`.
    2. Otherwise the exact Schur–Cohn test of det(zI − Acl/λ) (continuous: Routh test of
       det(sI − Acl − αI)), from :mod:`obsdesign.certify.detect` (slow beyond n ≈ 20).

    Necessity of the eigenvalue condition: for Acl v = z v, v*(λ²P − AclᵀPAcl)v =
    (λ² − |z|²) v*Pv. This decides the decay LMI of eq. (4)-(6), Section 5 of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019), for a fixed gain.

    :param Acl: A − LC (exact; object array or ``fmpq_mat``); :param rate: λ or α (exact);
    :param discrete: time domain; :param memo: verdicts already made in this process;
    :param Af: :func:`mat_float` of Acl, when already made (it only guides the proof).
    Returns (verdict, the proof used)."""
    r = Q(rate)
    Am = fmat(Acl)
    n = Am.nrows()
    if n == 0:
        return True, "empty matrix"
    if discrete and r == 0:
        return False, "λ = 0: −(A − LC)ᵀP(A − LC) ≻ 0 has no solution"
    if discrete and r < 0:
        # the LMI holds λ² only: λ < 0 is feasible iff ρ(A − LC) < |λ|. "Infeasible (λ ≤ 0)"
        # verified a forged bracket end λ = −0.00004 for A − LC = 0, where P = 1 satisfies
        # the decay LMI strictly (lyapunov/impulsive soundness trial, session 28)
        r = -r
    key = ("feasible", r, discrete)
    if memo is not None:
        hit = memo.get(key, (Am,))
        if hit is not None:
            return hit  # type: ignore[no-any-return]
    out = _rate_feasibility(Am, r, discrete, Af)
    if memo is not None:
        memo.put(key, (Am,), out)
    return out


def _rate_feasibility(
    Am: fmpq_mat, r: fmpq, discrete: bool, Af: np.ndarray | None = None
) -> tuple[bool, str]:
    n = Am.nrows()
    Af = mat_float(Am) if Af is None else Af
    X = _lyap_solution(Af, float(r), discrete)
    if X is not None and np.any(X != 0):
        Xq, Xq_f = dyadic_fmat(X, INERTIA_BITS)  # = dyadic(X), in flint, and its float copy
        if Xq != Xq.transpose():  # (X is symmetric: never)
            Xq, Xq_f = _sym(Xq), None
        if decay_pd(Am, Xq, r, discrete, 0, Af, Xq_f)[0]:
            # X ⊁ 0 shown by a rational direction first (the float X guides, exact product
            # decides), else the full exact test
            small = pd_small(Xq, 0)
            if small is not None:
                ok = small.ok
            else:
                neg = negative_direction(Xq, X) if np.linalg.eigvalsh(X)[0] < 0 else None
                ok = False if neg is not None else pd_int(Xq, 0).ok
            return ok, "exact Lyapunov inertia certificate (D(X) ≻ 0, X " + (
                "≻ 0)" if ok else "⊁ 0)"
            )
    Acl = as_array(Am)
    if discrete:
        return schur_stable(_charpoly(Acl * (1 / r)))[0], stability_test(True)
    return hurwitz_stable(_charpoly(Acl + qeye(n) * r))[0], stability_test(False)


def mat_float(Am: fmpq_mat) -> np.ndarray:
    """The nearest float matrix of an exact one (correctly rounded entry by entry), e.g. the
    error dynamics A − LC of eq. (3) (constrained-redesign paper) for its spectrum.

    :param Am: the exact matrix."""
    from obsdesign.certify.vchol import to_float

    H = to_float(Am)
    if H is None:  # beyond the float range: ±inf there (float() raised OverflowError, and
        # certify with such an L raised instead of deciding: mutation review 22); the float
        # guides then decline and the exact checks decide
        from obsdesign.certify.exact import float_or_inf

        return np.array([float_or_inf(x) for x in Am.entries()], dtype=float).reshape(
            Am.nrows(), Am.ncols()
        )
    return H


def rate_feasible(
    Acl: Any,
    rate: Any,
    discrete: bool,
    memo: ExactMemo | None = None,
    Af: np.ndarray | None = None,
) -> bool:
    """Whether some P ≻ 0 makes :func:`decay_matrix` ≻ 0 at ``rate``, decided exactly
    (:func:`rate_feasibility` without the proof's name): eq. (4)-(6), Section 5 of the
    constrained-redesign paper (Astolfi et al., NOLCOS 2019), for a fixed gain.

    :param Acl: A − LC (exact); :param rate: λ or α (exact); :param discrete: time domain;
    :param memo: verdicts already made in this process; :param Af: :func:`mat_float` of
    Acl, when already made."""
    return rate_feasibility(Acl, rate, discrete, memo, Af)[0]


def float_closed_loop(A: np.ndarray, G: np.ndarray, C: np.ndarray, who: str) -> np.ndarray:
    """A − G·C formed in doubles, the observer's error matrix as a simulation or an exported
    state-space system runs it (the linear observer of Section 5, constrained-redesign paper);
    :class:`~obsdesign.errors.InconclusiveError` (exit 4) when it overflows: a certificate
    about the exact A − LC can stand where G·C is past the float range (re-check reviews 44,
    45: simulate was an internal failure, ``observer_statespace()`` a bare ValueError).

    :param A, G, C: float matrices; :param who: what cannot run it ("a simulation in
    doubles")."""
    with np.errstate(all="ignore"):
        Ao = np.asarray(A, float) - np.asarray(G, float) @ np.asarray(C, float)
    if not np.all(np.isfinite(Ao)):
        from obsdesign.errors import InconclusiveError

        raise InconclusiveError(
            "A − LC formed in doubles overflows (L·C is beyond the float range): the "
            f"certificate is about the exact A − LC, and {who} cannot run this observer"
        )
    return Ao


def float_realization(Ao: np.ndarray, discrete: bool, rate: Any = None) -> str:
    """How the closed-loop matrix in doubles ``Ao`` (A − LC formed in floats: what a user
    deploys and what ``simulate`` steps) stands to the certificate, which is about the exact
    gain: "ok" when every eigenvalue is within ``rate`` (λ or α of eq. (4)-(6); None:
    stability), "slower" when it is stable but not within ``rate``, "unstable" otherwise —
    each decided exactly by :func:`rate_feasibility` on the doubles' exact values. On an
    ill-conditioned plant (ρ(A − LC) = 0.647 certified) the doubles gave ρ ≈ 3.5 (interop
    trial, session 39).

    :param Ao: the float matrix; :param discrete: time domain; :param rate: the certified
    rate (exact), or None."""
    Aq = np.vectorize(Q, otypes=[object])(np.asarray(Ao, dtype=float))
    if rate is not None and rate_feasibility(Aq, rate, discrete)[0]:
        return "ok"
    if rate_feasibility(Aq, Q(1) if discrete else Q(0), discrete)[0]:
        return "ok" if rate is None else "slower"
    return "unstable"


def exact_closed_loop(A: Any, G: Any, C: Any) -> Any:
    """A − G·C in exact arithmetic (object arrays of fmpq; the observer's error matrix of
    Section 5, constrained-redesign paper) from exact entries (spec values, report exact
    parameters), or None when one is not a number (a malformed report is refused elsewhere).

    :param A, G, C: n×n, n×p, p×n arrays of exact numbers."""
    to_q = np.vectorize(Q, otypes=[object])
    try:
        Aq, Cq = to_q(np.asarray(A, dtype=object)), to_q(np.asarray(C, dtype=object))
        Gq = to_q(np.asarray(G, dtype=object)).reshape(Aq.shape[0], Cq.shape[0])
    except (ValueError, TypeError, ArithmeticError):
        return None
    return Aq - Gq @ Cq


def exact_within(Acl: Any, discrete: bool, rate: Any = None) -> bool:
    """Whether the exact closed loop ``Acl`` (A − LC of a report's exact gain) keeps ``rate``
    (None: stability), decided by :func:`rate_feasibility` — the check behind a float
    realization that fails, to tell a gain that is itself too slow or unstable (the report's
    claims cannot hold) from doubles that lose a certified gain (tamper review 46).

    :param Acl: exact matrix; :param discrete: time domain; :param rate: exact rate or None."""
    unit = Q(1) if discrete else Q(0)
    return bool(rate_feasibility(Acl, unit if rate is None else rate, discrete)[0])


def stability_test(discrete: bool) -> str:
    """The name of the exact polynomial test behind :func:`rate_feasible` when the inertia
    certificate does not decide (for messages and claims).

    :param discrete: time domain (Schur–Cohn, Section 5 setting of the constrained-redesign
    paper) or continuous (Routh)."""
    return "exact Schur–Cohn test" if discrete else "exact Routh test"


def feasibility_check(discrete: bool) -> str:
    """The ``check`` wording of :func:`rate_feasibility` (both proofs it may use).

    :param discrete: time domain (eq. (4)-(6), constrained-redesign paper)."""
    poly = "det(zI − (A−LC)/λ)" if discrete else "det(sI − (A−LC) − αI)"
    return (
        "exact Lyapunov inertia certificate (dyadic X with D(X) ≻ 0; X ≻ 0 iff feasible), "
        f"else {stability_test(discrete)} of {poly}"
    )


def as_qarray(M: fmpq_mat) -> np.ndarray:
    """An ``fmpq_mat`` as an exact object array (the form the functions here take), e.g. the
    unobservable restriction A_u whose modes bound every rate of eq. (4)-(6).

    :param M: a flint rational matrix."""
    return as_array(M)


# -- P from the Lyapunov equation, certified -----------------------------------------------
def lyapunov_P(
    A: np.ndarray, C: np.ndarray, L: np.ndarray, rate: float, discrete: bool
) -> np.ndarray:
    """P solving (A−LC)ᵀP(A−LC) − λ²P = −I (discrete; the paper's P of Section 5,
    constrained-redesign paper, Astolfi et al., NOLCOS 2019) or
    (A−LC+αI)ᵀP + P(A−LC+αI) = −I (continuous), in floats.

    :param A, C, L: float matrices; :param rate: λ or α; :param discrete: time domain."""
    P = solve_lyapunov(A - L @ C, rate, discrete)
    return sym_part(P)


def _float_P(
    A: np.ndarray,
    C: np.ndarray,
    L: np.ndarray,
    discrete: bool,
    r: fmpq,
    floats: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> Any:
    Af, Cf, Lf = floats or tuple(np.asarray(x, dtype=float) for x in (A, C, L))
    if Cf.size:
        with np.errstate(all="ignore"):
            overflow = not np.all(np.isfinite(Af - Lf @ Cf))
        if overflow and A.dtype == object:
            # L·C past the float range while A − LC is small exactly (A = diag(5e307, 0.5),
            # C = [[1e308, 0], [1.5e308, 0]], L = [[2, −1], [0, 0]]: A − LC = diag(0, 0.5)):
            # the float problem from the exact closed loop, rounded (re-check review, 44)
            Acl = mat_float(closed_loop_fmat(A, C, L))
            if np.all(np.isfinite(Acl)):
                n = Acl.shape[0]
                Af, Cf, Lf = Acl, np.zeros((0, n)), np.zeros((n, 0))
    try:
        Pf = lyapunov_P(Af, Cf, Lf, float(r), discrete)
    except (np.linalg.LinAlgError, ValueError):
        return None
    if not np.all(np.isfinite(Pf)):
        return None
    return Pf


def certified_P(
    A: np.ndarray,
    C: np.ndarray,
    L: np.ndarray,
    discrete: bool,
    rate: Any,
    margin: Any,
    bits: int = BITS,
    memo: ExactMemo | None = None,
    Acl: fmpq_mat | None = None,
    floats: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    Af: np.ndarray | None = None,
    guide: Spectrum | None = None,
) -> np.ndarray | None:
    """A rational P (the Lyapunov-equation P rounded to ``bits`` dyadic bits) with
    P − margin·I ≻ 0 and :func:`decay_matrix` − margin·I ≻ 0 exactly, or None.

    Eq. (4)-(6) and Section 5 of the constrained-redesign paper (Astolfi et al., NOLCOS 2019).
    One Lyapunov equation (scipy) and two exact checks
    (:func:`obsdesign.certify.psd.check_pd_fast`); no SDP.

    :param A, C, L: exact plant and gain; :param discrete: time domain; :param rate: λ or α
    (exact); :param margin: δ of the strict checks; :param bits: rounding of P;
    :param memo: records the exact verdicts (for ``certify`` in the same process);
    :param Acl: A − LC as an ``fmpq_mat``, when already made; :param floats: A, C, L as
    float arrays (``np.asarray(x, dtype=float)``), when already made; :param Af:
    :func:`mat_float` of A − LC, when already made; :param guide: the
    :func:`~obsdesign.spectrum.spectrum` of A − LC, when already made (it decides only
    whether the high-precision fallback is worth running)."""
    r = Q(rate)
    if (discrete and r <= 0) or A.shape[0] == 0:
        return None
    Pf = _float_P(A, C, L, discrete, r, floats)
    if Pf is None:
        return None
    Pm, Pq_f = dyadic_fmat(Pf, bits)  # = dyadic(Pf, bits), in flint, and its float copy
    if Pm != Pm.transpose():  # (Pf is symmetric: never, but the checks need a symmetric P)
        Pm, Pq_f = _sym(Pm), None
    P = as_array(Pm)
    Am = closed_loop_fmat(A, C, L) if Acl is None else Acl
    if _passes(Am, P, Pm, r, discrete, margin, memo, Af, Pq_f):
        return P
    c = margin_scale(Pf, margin)
    if c != 1:  # the margin asks for a larger P (its decay matrix is c·I)
        # float_or_inf: a margin of 1e308 makes c itself overflow (the float P is then
        # infinite and skipped below; it raised OverflowError, the generic exit-4 text)
        P = _dyadic_certified(Am, Pf * float_or_inf(c), bits, r, discrete, margin, memo, Af)
        if P is not None:
            return P
    return _certified_P_hp(Am, r, discrete, margin, memo, Af, guide, Pf if bits < 53 else None)


def _dyadic_certified(
    Am: fmpq_mat,
    Pf: np.ndarray,
    bits: int,
    r: fmpq,
    discrete: bool,
    margin: Any,
    memo: ExactMemo | None,
    Af: np.ndarray | None,
) -> np.ndarray | None:
    """The float P rounded to ``bits`` (53: the floats themselves), symmetrized, when it passes
    both exact checks of eq. (4)-(6) (constrained-redesign paper, Astolfi et al., NOLCOS 2019)
    — P − δI ≻ 0 and the decay matrix − δI ≻ 0 — else None."""
    if not np.all(np.isfinite(Pf)):  # P scaled for a margin of 1e307 overflowed: no float P
        return None  # (it raised "cannot round a non-finite number", exit 3; re-check review)
    Pm, _ = dyadic_fmat(Pf, bits)
    Pm = Pm if Pm == Pm.transpose() else _sym(Pm)
    P = as_array(Pm)
    return P if _passes(Am, P, Pm, r, discrete, margin, memo, Af) else None


def _passes(
    Am: fmpq_mat,
    P: np.ndarray,
    Pm: fmpq_mat,
    r: fmpq,
    discrete: bool,
    margin: Any,
    memo: ExactMemo | None,
    Af: np.ndarray | None,
    Pq_f: np.ndarray | None = None,
) -> bool:
    """Both exact checks of a candidate P, eq. (4)-(6) (constrained-redesign paper, Astolfi
    et al., NOLCOS 2019): P − δI ≻ 0 and the decay matrix − δI ≻ 0 (``Pq_f``: P's correctly
    rounded float copy, when at hand)."""
    return bool(
        pd_verdict(P, margin, memo, Pm, Pq_f)
        and decay_verdict(Am, P, r, discrete, margin, memo, Pm, Af, Pq_f)[0]
    )


def margin_scale(Pf: np.ndarray, margin: Any, Pm: fmpq_mat | None = None) -> fmpq:
    """The power of two c by which the Lyapunov-equation P (decay matrix I, eq. (4)-(6) of
    the constrained-redesign paper, Astolfi et al., NOLCOS 2019, with Q = I) is scaled so
    that both strict checks can hold with the margin δ: c·I ⪰ 2δ·I and c·λ_min(P) ≥ 2δ
    (float λ_min, a guide only: the exact checks decide). 1 when δ = 0 or P is not positive
    definite in floats. Before, only c ≥ 2δ was used (in the fallback): a continuous plant
    with λ_min(P) = ⅙ and δ = 0.4 was refused (exit 4) with a valid P = diag(½, 1) at hand
    (random-spec fuzzer).

    With the exact P (``Pm``) and a float λ_min that floats cannot resolve (at most 10⁻¹²·
    λ_max), λ_min = 1/λ_max(P⁻¹) from the exact inverse, whose largest eigenvalue floats get
    right: a non-normal continuous plant's high-precision P had entries up to 4.6·10²⁴ and
    λ_min ≈ 0.07, float eigvalsh gave −8.9·10⁷, P was not scaled and missed margin = 0.1
    (exit 4 with a certificate at hand — lyapunov review).

    :param Pf: the float P; :param margin: δ; :param Pm: the exact P, when at hand."""
    d = Q(margin)
    c = fmpq(1)
    if d <= 0:
        return c
    with np.errstate(all="ignore"):
        try:
            ev = np.linalg.eigvalsh(sym_part(Pf))
            lmin = float(ev[0])
            if Pm is not None and not lmin > 1e-12 * float(ev[-1]):
                lmin = _lambda_min_by_inverse(Pm, lmin)
        except np.linalg.LinAlgError:
            lmin = 0.0
    need = 2 * d if not lmin > 0 else 2 * d / Q(min(1.0, lmin))
    while c < need:
        c *= 2
    return c


#: working precisions (bits) of :func:`_inverse_float`'s ball-arithmetic inverse
INVERSE_PRECISIONS = (128, 512, 2048)


def _inverse_float(Pm: fmpq_mat) -> np.ndarray | None:
    """P⁻¹ in floats, every entry within 2⁻⁶⁰ of the largest: python-flint's ``arb_mat``
    inverse at the first precision of :data:`INVERSE_PRECISIONS` whose balls are that narrow
    (the radii are rigorous), else the exact
    ``fmpq_mat`` inverse. The exact inverse alone took 1.8 s at n = 44 for a 320-bit P (the
    high-precision Lyapunov P of a Jordan block; session 41). None when P is singular.
    A guide only (:func:`margin_scale`): nothing here is a proof."""
    from flint import arb_mat, ctx

    n = Pm.nrows()
    for prec in INVERSE_PRECISIONS:
        with ctx.workprec(prec):
            try:
                inv = arb_mat(Pm).inv()
            except (ZeroDivisionError, ValueError):
                continue  # not proved invertible at this precision
            out = np.array([[float(inv[i, j].mid()) for j in range(n)] for i in range(n)])
            rad = max(float(inv[i, j].rad()) for i in range(n) for j in range(n))
            top = float(np.max(np.abs(out))) if out.size else 0.0
            # λ_max(P⁻¹) to ~50 bits needs the entries to ~50 bits of the largest one
            if np.all(np.isfinite(out)) and rad <= 2.0**-60 * top:
                return out
    try:
        return mat_float(Pm.inv())
    except ZeroDivisionError:
        return None


def _lambda_min_by_inverse(Pm: fmpq_mat, fallback: float) -> float:
    """λ_min(P) = 1/λ_max(P⁻¹) for a positive definite P, P⁻¹ from :func:`_inverse_float`
    (ball arithmetic, else exact), its largest
    eigenvalue in floats (well resolved, while P⁻¹'s smallest may not be: P⁻¹ is as
    ill-conditioned as P); a guide for :func:`margin_scale` only (for a P that is not positive
    definite it may mislead; the exact checks decide). ``fallback`` when P is singular or
    λ_max(P⁻¹) is not a positive float."""
    try:
        inv = _inverse_float(Pm)
        if inv is None:
            return fallback
        top = float(np.linalg.eigvalsh(sym_part(inv))[-1])
    except (ZeroDivisionError, np.linalg.LinAlgError, OverflowError):
        return fallback
    if not (math.isfinite(top) and top > 0):
        return fallback
    return 1.0 / top


def _certified_P_hp(
    Am: fmpq_mat,
    r: fmpq,
    discrete: bool,
    margin: Any,
    memo: ExactMemo | None,
    Af: np.ndarray | None,
    guide: Spectrum | None = None,
    Pf: np.ndarray | None = None,
) -> np.ndarray | None:
    """:func:`certified_P`'s fallback when the rounded float P fails: first the float P
    itself (``Pf``, every double exact: 53 bits, when the rounding was shorter), then the
    Lyapunov-equation P in high precision (:mod:`obsdesign.lyap_hp`, n ≤ its ``MAX_N``),
    each scaled by :func:`margin_scale` (its decay matrix is c·I), checked by the same exact
    tests. Skipped for a rate the spectrum (:func:`obsdesign.spectrum.spectrum`: float
    eigenvalues when their error bound is small, else high-precision ones) puts clearly on
    the infeasible side (the exact check would refuse it: the solve would be wasted). The
    unrounded P: a random 100-state continuous plant's P (max |P| ≈ 2·10⁷, ‖A − LC‖ ≈ 7·10⁴)
    failed at 40 bits and passed at 53 — beyond MAX_N there was no other fallback, exit 4
    (lyapunov review)."""
    from obsdesign import lyap_hp

    n = Am.nrows()
    if n > lyap_hp.DOUBLING_MAX_N and Pf is None:
        return None
    Af = mat_float(Am) if Af is None else Af
    if guide is None:
        guide = spectrum(Am, Af)
    # a small slack beyond the guide's own accuracy (float eigenvalues of a non-normal matrix
    # are off by far more than u·‖A − LC‖: the guide takes high-precision ones then; the
    # audit's continuous example: ‖A − LC‖ ≈ 3·10¹⁰, float real parts +2.7·10⁻³ for an
    # exactly Hurwitz matrix)
    rf = float(r)
    slack = 1e-8 * max(1.0, float(np.max(np.abs(Af))) * n)
    bound = guide.bound(discrete)
    if (bound - rf if discrete else bound + rf) > slack:
        return None
    if Pf is not None:
        P = _dyadic_certified(
            Am, Pf * float_or_inf(margin_scale(Pf, margin)), 53, r, discrete, margin, memo, Af
        )
        if P is not None:
            return P
    if n > lyap_hp.DOUBLING_MAX_N:
        return None
    solve = lyap_hp.lyapunov_P_hp if n <= lyap_hp.MAX_N else lyap_hp.lyapunov_P_doubling
    for prec in lyap_hp.precisions(n):
        Pm = solve(Am, r, discrete, prec)
        if Pm is None:
            continue
        Pm = Pm * margin_scale(mat_float(Pm), margin, Pm)
        view = _into_float_view(Pm)
        # the P scaled into the float range first; when that loses the margin, the P itself
        # (a true certificate the report then cannot show: exit 4 naming P, as before)
        for cand in (view, Pm) if view is not Pm else (Pm,):
            P = as_array(cand)
            if _passes(Am, P, cand, r, discrete, margin, memo, Af):
                return P
    return _certified_P_exact(Am, r, discrete, margin, memo, Af)


def beyond_float(M: Any) -> bool:
    """Whether some entry of the exact matrix ``M`` (e.g. a certified P of eq. (4)-(6),
    constrained-redesign paper) is beyond the float range: a report cannot show its float
    view (a rate near 0 with a margin δ > 0 needs P ~ δ/λ^(2k))."""
    try:  # numpy's conversion of an fmpq array (p / q per entry): fast, raises on overflow
        return not bool(np.all(np.isfinite(np.asarray(M, dtype=float))))
    except OverflowError:
        return True


#: the largest binary exponent of an entry of the exact fallback's P (a float view's margin)
FLOAT_VIEW_BITS = 1020


def _into_float_view(Pm: fmpq_mat) -> fmpq_mat:
    """``Pm`` scaled down by a power of two to about 2^:data:`FLOAT_VIEW_BITS` when an entry
    is beyond the float range (the report would have no float view of it: exit 4, "an exact
    value lies beyond the float range"); the exact checks decide whether the margin still
    holds (re-check trial, session 39: a 4×4 Jordan block at λ = ρ + 10⁻⁴⁰). For the exact
    fallback's P and, since session 41, the high-precision one (at 1024 bits it reaches that
    block too)."""
    n = Pm.nrows()
    top = max(
        (Pm[i, j].p.bit_length() - Pm[i, j].q.bit_length() for i in range(n) for j in range(n)),
        default=0,
    )
    return Pm * fmpq(1, 2 ** (top - FLOAT_VIEW_BITS)) if top > FLOAT_VIEW_BITS else Pm


def _certified_P_exact(
    Am: fmpq_mat, r: fmpq, discrete: bool, margin: Any, memo: ExactMemo | None, Af: np.ndarray
) -> np.ndarray | None:
    """The last fallback of :func:`certified_P` (n ≤ ``lyap_hp.EXACT_MAX_N``): the exact
    rational Lyapunov P (decay matrix exactly I, :func:`obsdesign.lyap_hp.lyapunov_P_exact`),
    rounded to 512, 1024, 2048 relative bits, scaled for the margin and checked by the same
    exact tests; a candidate whose exact strings would exceed the report's ``max_digits``
    (verify could not read it back) is not taken. Eq. (4)-(6), constrained-redesign paper."""
    from obsdesign import lyap_hp
    from obsdesign.limits import limits

    if Am.nrows() > lyap_hp.EXACT_MAX_N:
        return None
    Pe = lyap_hp.lyapunov_P_exact(Am, r, discrete)
    if Pe is None:
        return None
    most = limits().max_digits
    for bits in lyap_hp.EXACT_BITS:
        Pm = lyap_hp.round_relative(Pe, bits)
        Pm = _into_float_view(Pm * margin_scale(mat_float(Pm), margin, Pm))
        n = Pm.nrows()
        if any(
            len(str(abs(Pm[i, j].p))) > most or len(str(Pm[i, j].q)) > most
            for i in range(n)
            for j in range(n)
        ):
            break
        P = as_array(Pm)
        if _passes(Am, P, Pm, r, discrete, margin, memo, Af):
            return P
    return None


class _Forecast:
    """Float forecast of :func:`certified_P` along the rate search (a guess that steers the
    search, never a proof): the Lyapunov-equation P at each rate, then both matrices' smallest
    eigenvalues must exceed the margin by a clear relative gap.

    With Acl = VΛV⁻¹ (one eigendecomposition, when V is well conditioned), the P of
    :func:`lyapunov_P` is V⁻ᴴYV⁻¹ with Y_ij = G_ij/(λ² − w̄_i w_j) (discrete) or
    −G_ij/(w̄_i + w_j + 2α) (continuous), G = VᴴV: two products per rate instead of a
    Schur-based solve (eq. (4)-(6) of the constrained-redesign paper, Astolfi et al., NOLCOS
    2019, Section 5, with Q = I). Otherwise scipy solves each rate.

    :param Af: float A − LC; :param discrete: time domain; :param margin: δ;
    :param guide: the :func:`~obsdesign.spectrum.spectrum` of A − LC (its float
    eigendecomposition is used when it has one)."""

    def __init__(self, Af: np.ndarray, discrete: bool, margin: Any, guide: Spectrum) -> None:
        self.Af, self.discrete, self.m = Af, discrete, float(margin)
        self.V: np.ndarray | None = None
        n = Af.shape[0]
        w, V, Vi = guide.w, guide.V, guide.Vi
        if V is not None and Vi is not None and np.linalg.norm(V) * np.linalg.norm(Vi) < 1e8 * n:
            self.w, self.V, self.Vi, self.G = w, V, Vi, V.conj().T @ V

    def P(self, rf: float) -> np.ndarray | None:
        """The float Lyapunov-equation P at rate ``rf`` (None when it cannot be had)."""
        if self.V is None:
            n = self.Af.shape[0]
            z = np.zeros((0, n)) if n else np.zeros((0, 0))
            return _float_P(self.Af, z, z.T, self.discrete, Q(rf))
        wc = self.w.conj()[:, None]
        with np.errstate(all="ignore"):
            if self.discrete:
                Y = self.G / (rf * rf - wc * self.w[None, :])
            else:
                Y = -self.G / (wc + self.w[None, :] + 2 * rf)
            P = (self.Vi.conj().T @ Y @ self.Vi).real
        if not np.all(np.isfinite(P)):
            return None
        P = sym_part(P)
        return P if np.all(np.isfinite(P)) else None

    def __call__(self, r: fmpq) -> bool:
        """Whether :func:`certified_P` is expected to succeed at the rate ``r``."""
        rf = float(r)
        if self.discrete and rf <= 0:
            return False
        Pf = self.P(rf)
        if Pf is None:
            return False
        Acl = self.Af
        if self.discrete:
            M = rf * rf * Pf - Acl.T @ Pf @ Acl
        else:
            M = -(Acl.T @ Pf + Pf @ Acl + 2 * rf * Pf)
        M = sym_part(M)
        m = self.m
        gap = 1e-6
        wp = np.linalg.eigvalsh(Pf)
        wm = np.linalg.eigvalsh(M)
        if m > 0 and (wp[0] <= m or wm[0] <= m):  # certified_P scales P for the margin
            c = float_or_inf(margin_scale(Pf, self.m))
            wp, wm = wp * c, wm * c
        return bool(
            wp[0] - m > gap * abs(wp[-1]) and wm[0] - m > gap * max(abs(wm[-1]), abs(wm[0]), 1.0)
        )


# -- the best rate, bracketed --------------------------------------------------------------
@dataclass
class RateBracket:
    """The best certified decay rate for a fixed gain and the other end of its bracket.

    ``best`` (λ or α) is certified with ``P``; ``other`` is the closest rate on the other side
    that was ``kind`` = ``"infeasible"`` (proved by :func:`rate_feasible`: no P ≻ 0 exists)
    or ``"not-certifiable"`` (feasible, but the rounded Lyapunov-equation P failed the exact
    check with the margin); |best − other| ≤ tol unless the search stopped on the grid.
    ``exact_checks`` counts the exact :func:`certified_P` calls the search made."""

    best: fmpq
    P: np.ndarray
    other: fmpq
    kind: str
    tol: fmpq
    exact_checks: int = 0


def _grid(tol: fmpq) -> fmpq:
    digits = max(0, -int(np.floor(np.log10(float(tol))))) + 1
    return fmpq(1, 10**digits)


def _snap(x: fmpq, grid: fmpq, up: bool) -> fmpq:
    q = x / grid
    return (fmpq(int(q.ceil())) if up else fmpq(int(q.floor()))) * grid


#: the most exact :func:`certified_P` calls one :func:`best_rate` search may make
MAX_EXACT_CHECKS = 40


class RateResolutionError(InconclusiveError):
    """The best-rate bisection cannot narrow its bracket to ``rate_tol``: the float midpoint of
    the two ends is one of them (the width is at the float resolution of the rate, where the
    float Lyapunov solve cannot tell the ends apart). ``width`` is the narrowest bracket
    reached, as a float; the design refuses the tolerance (a spec error naming
    ``[method] rate_tol``) rather than report a bracket wider than asked."""

    def __init__(self, tol: fmpq, width: fmpq, rate: fmpq) -> None:
        super().__init__(
            f"rate_tol = {float(tol):.3g} is below the float resolution of the rate near "
            f"{float(rate):.6g}: the narrowest bracket reached has width {float(width):.3g}"
        )
        self.tol, self.width, self.rate = tol, width, rate

    def hint(self) -> str:
        """The spec error's wording: what was asked, what is reachable. The suggested least
        ``rate_tol`` is the width rounded *up* (it said "≥ 2.1e-16" for a width of
        2.109·10⁻¹⁶, a value itself refused; lyapunov review, session 41)."""
        from obsdesign.certify.printing import fmt_up

        # at the resolution itself the search can still run out of exact checks (a width of
        # 2.2e-16 at λ = 0.95 did, exit 4; re-check trial, session 41): a safe value too
        return (
            f"rate_tol = {float(self.tol):.3g} cannot be met: the best-rate bracket cannot be "
            f"narrower than {float(self.width):.3g} near the rate {float(self.rate):.6g} (the "
            f"float resolution there); expected rate_tol ≥ {fmt_up(self.width, 2)} (at that "
            f"width the search may run out of exact checks: {fmt_up(self.width * 10, 1)} or "
            "more is safe)"
        )


def best_rate(
    A: np.ndarray,
    C: np.ndarray,
    L: np.ndarray,
    discrete: bool,
    *,
    tol: Any,
    margin: Any,
    known: tuple[Any, np.ndarray] | None = None,
    progress: Callable[[str], None] | None = None,
    forecast: bool = True,
    memo: ExactMemo | None = None,
    Acl: fmpq_mat | None = None,
    Af: np.ndarray | None = None,
    guide: Spectrum | None = None,
) -> RateBracket:
    """Bisection for the best certified rate of V = eᵀPe: the smallest λ (discrete) or the
    largest α (continuous) at which :func:`certified_P` succeeds, bracketed.

    The certified/feasible side of eq. (4)-(6) (constrained-redesign paper, Astolfi et al.,
    NOLCOS 2019, Section 5) is searched on a decimal grid of step tol/10. The bracket starts
    from the spectral bound: the grid point just beyond ρ(Acl) (resp. −max Re eig(Acl)) proved
    infeasible by :func:`rate_feasible`. The rate tol beyond it is tried first: certified, it
    ends the search with a bracket of width tol (the usual case: one check); refused, it
    becomes the other end. Otherwise the certified end is 1 − grid (resp. grid), or finer
    candidates when those fail. Each midpoint is decided by :func:`certified_P`; a midpoint
    that fails is the new infeasible / not-certifiable end. ``known`` = (rate, P), a rate
    already certified (the user's), keeps the result at least as good: the search never reports
    a worse rate.

    Cost: every step is one Lyapunov equation, no SDP. A float forecast
    (:class:`_Forecast`) stands in for the exact check at the midpoints it calls
    clearly certified; the exact check runs at the midpoints it calls failed and at the final
    certified end. If that final check fails, the search is rerun with exact checks at every
    midpoint. Both reported ends are always decided exactly; the bracket equals that of the
    all-exact bisection whenever certification is monotone in the rate (a forecast that
    wrongly calls a midpoint certified goes unnoticed only if a lower rate then certifies
    exactly). At most
    :data:`MAX_EXACT_CHECKS` exact checks (then :class:`InconclusiveError`). A bracket that
    cannot be narrowed to ``tol`` in float midpoints raises :class:`RateResolutionError`.

    :param A, C, L: exact plant and gain; :param discrete: time domain; :param tol: bracket
    width; :param margin: δ of the checks; :param known: a certified (rate, P);
    :param progress: callback for messages; :param forecast: let the float forecast stand in
    for exact checks (False: an exact check at every midpoint; the rerun uses it);
    :param memo: records the exact verdicts (for ``certify`` in the same process);
    :param Acl: A − LC as an ``fmpq_mat``, when already made; :param Af: its
    :func:`mat_float`, when already made; :param guide: the
    :func:`~obsdesign.spectrum.spectrum` of A − LC, when already made (where the search
    starts; the forecast's eigendecomposition).
    Raises :class:`InfeasibleError` when Acl is not Schur / Hurwitz (exact) and
    :class:`InconclusiveError` when it is but nothing certifies."""
    Acl = closed_loop_fmat(A, C, L) if Acl is None else Acl
    tol_q = Q(tol)
    grid = _grid(tol_q)
    if Af is None:  # correctly rounded, as np.asarray(closed_loop(A, C, L), dtype=float)
        Af = mat_float(Acl)
    if guide is None:
        guide = spectrum(Acl, Af)
    floats = (np.asarray(A, dtype=float), np.asarray(C, dtype=float), np.asarray(L, dtype=float))
    guess = _Forecast(Af, discrete, margin, guide) if forecast else None
    # r-space: r = λ (discrete) or r = −α (continuous); smaller r is better in both
    sign = 1 if discrete else -1
    checks = 0
    pending = object()  # a forecast "certified", exact check deferred

    def rate(r: fmpq) -> fmpq:
        return r * sign

    def exact(r: fmpq) -> np.ndarray | None:
        nonlocal checks
        checks += 1
        if checks > MAX_EXACT_CHECKS:
            raise InconclusiveError(
                f"best-rate search: more than {MAX_EXACT_CHECKS} exact checks without a bracket "
                f"of width rate_tol = {float(tol_q):.3g}: near the best rate the rounded "
                "certificates keep failing their exact checks (A − LC ill-conditioned there, or "
                "a width near the float resolution of the rate, ~1e-16 relative): raise rate_tol"
            )
        return certified_P(
            A,
            C,
            L,
            discrete,
            rate(r),
            margin,
            memo=memo,
            Acl=Acl,
            floats=floats,
            Af=Af,
            guide=guide,
        )

    def cert(r: fmpq) -> Any:
        if guess is not None and guess(rate(r)):
            return pending
        return exact(r)

    def feasible(r: fmpq) -> bool:
        return rate_feasible(Acl, rate(r), discrete, memo, Af)

    bound = guide.bound(discrete)
    resolution = Q(abs(bound)) / 2**52  # about one ulp of the rate
    if tol_q < resolution:  # no bisection in float midpoints gets there
        # the rate as the user writes it: α = −(spectral abscissa) in continuous time (the
        # message said "near the rate -10293.1"; lyapunov trial, session 24)
        raise RateResolutionError(tol_q, resolution, rate(Q(bound)))
    lo = _snap(Q(max(bound, 0.0)) if discrete else Q(bound), grid, False)
    # float error put the spectral bound above a feasible grid point. That error is about
    # u·ρ for a simple eigenvalue but u^(1/k) for a k-fold one (a triple pole at 0.5: 3·10⁻⁶),
    # i.e. any number of grid steps when rate_tol is small (10³⁰⁶ of them at rate_tol =
    # 1e-320, found by the spec fuzzer; one exact test each). Step down from the float
    # resolution at the bound, doubling: O(log) tests, lo stays on the grid, λ stays ≥ 0
    # (λ = 0 is never feasible); the bisection below then narrows the wider bracket.
    step = max(grid, _snap(max(abs(lo), fmpq(1)) / 2**52, grid, True))
    while feasible(lo):
        lo = max(lo - step, fmpq(0)) if discrete else lo - step
        step *= 2
    lo_kind = INFEASIBLE
    edge = fmpq(1) if discrete else fmpq(0)  # r must stay below it
    if lo >= edge:
        what = "Schur" if discrete else "Hurwitz"
        lim = guide.figure(discrete)
        raise InfeasibleError(f"A − LC is not {what}: {lim} ({stability_test(discrete)})")
    known_r = None if known is None else Q(known[0]) * sign
    hi, P = edge - grid, None
    # first the rate one bracket width beyond the infeasible end: certified there, the
    # bracket is already within tol (the usual case, one check instead of ~13 midpoints
    # from the edge); refused there, it is the new other end, as a refused midpoint is.
    # Forecast and all-exact searches probe it alike, so they still agree.
    near = _snap(lo + tol_q, grid, False)
    if lo < near < hi:
        P = cert(near)
        if P is not None:
            hi = near
        elif known_r is not None and known_r < near:
            hi, P = known_r, known[1]  # type: ignore[index]
        else:
            lo, lo_kind = near, (NOT_CERTIFIABLE if feasible(near) else INFEASIBLE)
    if P is None and hi > lo:
        P = cert(hi)
    k = 1
    while P is None and k <= 12:
        if known_r is not None:
            hi, P = known_r, known[1]  # type: ignore[index]
            break
        cand = edge - grid / 10**k
        k += 1
        if cand > lo:
            P = cert(cand)
            hi = cand
    if P is None:
        what = "λ < 1" if discrete else "α > 0"
        # the stability margin below the finest candidate names rate_tol: A = −1e-150·I said
        # only "no decay rate could be certified", where rate_tol = 1e-151 certifies (float
        # pre-screen review, session 43)
        gap = (1 - abs(bound)) if discrete else -bound
        finest = float(grid) / 10**12
        name = "1 − ρ(A − LC)" if discrete else "−max Re eig(A − LC)"
        where = (
            f"is below the search's finest candidate, {finest:.3g} from the limit on the grid "
            f"of rate_tol = {float(tol_q):.3g}"
        )
        hint = (
            f"; its stability margin ({name} ≈ {gap:.3g}) {where}: give a [method].rate_tol "
            f"below {gap:.1g}"
            if 0 < gap < finest
            # below the float resolution (A = 0.99999999999999999 is 1.0 as a float): no
            # estimate, the same remedy (re-check review, session 43)
            # rate_tol cannot go below ~2.3e-16: past that, only a given rate helps (A = 1 −
            # 1e-40 looped on the hint; re-check review, session 43)
            else f"; its stability margin ({name}) is 0 in floats and {where}: give a "
            f"smaller [method].rate_tol, or a rate [method].{'lambda' if discrete else 'alpha'}"
            " itself (written with enough digits) when the margin is below the float "
            "resolution"
            if gap <= 0
            else ""
        )
        raise InconclusiveError(
            f"A − LC is {'Schur' if discrete else 'Hurwitz'} (exact test) but no decay rate "
            f"{what} could be certified{hint}"
        )
    while hi - lo > tol_q:
        # the midpoint through float64 (as the search always did: same candidates, same result)
        mid = _snap(Q(float((lo + hi) / 2)), grid, True)
        if mid >= hi or mid <= lo:
            raise RateResolutionError(tol_q, hi - lo, rate(hi))
        if progress:
            progress(f"bisection {'λ' if discrete else 'α'} = {float(rate(mid)):.6g}")
        Pm = cert(mid)
        if Pm is not None:
            hi, P = mid, Pm
        elif known_r is not None and known_r < mid:
            hi, P = known_r, known[1]  # type: ignore[index]
        else:
            lo, lo_kind = mid, (NOT_CERTIFIABLE if feasible(mid) else INFEASIBLE)
    if known_r is not None and known_r < hi:
        hi, P = known_r, known[1]  # type: ignore[index]
    if P is pending:
        P = exact(hi)
        if P is None:  # the forecast called a rate certified that the exact check refuses
            return best_rate(
                A,
                C,
                L,
                discrete,
                tol=tol,
                margin=margin,
                known=known,
                progress=progress,
                forecast=False,
                memo=memo,
                Acl=Acl,
                Af=Af,
                guide=guide,
            )
    return RateBracket(rate(hi), P, rate(lo), lo_kind, tol_q, checks)
