"""Exact observability and detectability of a pair (C, A), discrete or continuous time.

Everything is decided over Q (python-flint ``fmpq_mat`` / ``fmpq_poly``); floats are taken at
their exact binary value, so a pair that floats call unobservable (C = [1e-320, 0]) is decided
correctly.

1. The observable row space V is the row space of the observability matrix
   [C; CA; …; CA^{n−1}], reduced exactly (fraction-free Gaussian elimination over Z after
   clearing denominators); (C, A) is observable iff dim V = n (Kalman rank test).
2. The unobservable subspace N = ker V (the largest A-invariant subspace in ker C) has the basis
   read off the reduced row echelon form of V: one vector per free column, equal to 1 there and 0
   at the other free columns. A N = N A_u (invariance), so the restriction A_u = (A N)[free rows]
   exactly.
3. (C, A) is detectable iff every eigenvalue of A_u is stable (Hautus): all roots of the
   characteristic polynomial χ(A_u) (``fmpq_poly``, exact) in |z| < 1 (discrete time: Schur–Cohn
   recursion) or in Re s < 0 (continuous time: Routh array, i.e. the Hurwitz criterion).

Both polynomial tests are exact decisions without degenerate cases: Schur–Cohn stops with
"not stable" only when |a₀| ≥ |a_d| (then the product of the root moduli is ≥ 1), and the Routh
test stops with "not stable" only when a first-column entry is ≤ 0 (then a Hurwitz determinant,
the product of the first-column entries so far, is ≤ 0). A zero in the Routh array, a root on
the unit circle or on the imaginary axis all give a proved "not detectable".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

from flint import fmpq, fmpq_mat, fmpq_poly, fmpz_mat, fmpz_poly

from obsdesign.certify.exact import qmat

Time = Literal["discrete", "continuous"]


@dataclass(frozen=True)
class Detectability:
    """Outcome of :func:`detectability`: exact verdicts and the reason in words."""

    observable: bool
    detectable: bool
    unobservable_dim: int
    reason: str

    def __bool__(self) -> bool:
        return self.detectable


def _to_fmat(M: Any) -> fmpq_mat:
    arr = qmat(M)
    r, c = arr.shape
    return fmpq_mat(r, c, list(arr.flat))


def _to_zmat(M: fmpq_mat) -> fmpz_mat:
    """D·M with D the least common denominator of M's entries: an integer matrix with the same
    row space and kernel (and, for A, the same Krylov row spaces: C (D A)^k = D^k C A^k)."""
    D = math.lcm(*[int(v.q) for v in M.entries()])
    return fmpz_mat(M.nrows(), M.ncols(), [int(v.p) * (D // int(v.q)) for v in M.entries()])


def observable_rowspace(A: Any, C: Any) -> fmpq_mat:
    """Reduced row echelon basis (r × n) of the row space of the observability matrix
    [C; CA; …; CA^{n−1}] of (C, A), computed exactly (fraction-free over Z)."""
    Af, Cf = _to_fmat(A), _to_fmat(C)
    n = Af.nrows()
    if Af.ncols() != n:
        raise ValueError(f"A must be square, got {Af.nrows()}x{Af.ncols()}")
    if Cf.ncols() != n:
        raise ValueError(f"C must have {n} columns (A is {n}x{n}), got {Cf.ncols()}")
    Az, block = _to_zmat(Af), _to_zmat(Cf)
    entries: list[Any] = []
    for _ in range(n):
        entries += block.entries()
        block = block * Az
    rows = Cf.nrows() * n
    if rows == 0:
        return fmpq_mat(0, n)
    R, den, rank = fmpz_mat(rows, n, entries).rref()
    return fmpq_mat(rank, n, [fmpq(R[i, j], den) for i in range(rank) for j in range(n)])


def unobservable_restriction(A: Any, C: Any) -> tuple[fmpq_mat, fmpq_mat]:
    """(N, A_u): a basis N (n × k) of the unobservable subspace and A restricted to it,
    A N = N A_u exactly (k = n − rank of the observability matrix)."""
    Af = _to_fmat(A)
    n = Af.nrows()
    V = observable_rowspace(A, C)
    r = V.nrows()
    pivots: list[int] = []
    for i in range(r):
        pivots.append(next(j for j in range(n) if V[i, j] != 0))
    free = [j for j in range(n) if j not in pivots]
    k = len(free)
    N = fmpq_mat(n, k)
    for c, f in enumerate(free):
        N[f, c] = fmpq(1)
        for i, p in enumerate(pivots):
            N[p, c] = -V[i, f]
    AN = Af * N
    Au = fmpq_mat(k, k, [AN[f, c] for f in free for c in range(k)])
    return N, Au


def schur_stable(p: fmpq_poly) -> tuple[bool, str]:
    """Exact Schur–Cohn test: are all roots of p in the open unit disk |z| < 1?

    With |a₀| < |a_d|, p is Schur stable iff p₁ = (a_d p − a₀ p*)/z is (p* the reversed
    polynomial; Rouché on |z| = 1, where |p*| = |p|), and deg p₁ = d − 1. With |a₀| ≥ |a_d| the
    product of the root moduli |a₀/a_d| is ≥ 1: not stable. A nonzero constant is stable."""
    first = [fmpq(v) for v in p.coeffs()]
    if not first:
        raise ValueError("the zero polynomial has no roots to test")
    # in integers (the numerator; a constant factor keeps the roots), each step divided by
    # its content: the rational recursion (each step made monic) grew its denominators so
    # that a degree-44 test took 1.4 s (lyapunov at n = 44, session 41)
    c = fmpq_poly(first).numer()
    step = 0
    while c.degree() > 0:
        a0, ad = c[0], c[c.degree()]
        if abs(a0) >= abs(ad):
            # the message's numbers as the rational recursion gave them: the given
            # coefficients at step 0, the monic polynomial's (|a_d| = 1) after
            shown = (first[0], first[-1]) if step == 0 else (fmpq(a0) / ad, fmpq(1))
            return False, (
                f"Schur–Cohn step {step}: |a0| = {abs(shown[0])} >= |a_d| = {abs(shown[1])}, "
                "so a root has |z| >= 1"
            )
        rev = fmpz_poly(c.coeffs()[::-1])
        new = fmpz_poly((ad * c - a0 * rev).coeffs()[1:])  # ÷ z: its constant term is 0
        c = new / new.content()
        step += 1
    return True, f"Schur–Cohn: all {step} steps with |a0| < |a_d|"


def hurwitz_stable(p: fmpq_poly) -> tuple[bool, str]:
    """Exact Routh test: are all roots of p in the open left half-plane Re s < 0?

    The first column of the Routh array is Δ₁, Δ₂/Δ₁, …, Δ_d/Δ_{d−1} (Hurwitz determinants Δ_k,
    leading coefficient made positive); p is Hurwitz stable iff all Δ_k > 0, i.e. iff every
    first-column entry is > 0. The first entry ≤ 0 (a zero included: a root on the imaginary
    axis or a symmetric pair) proves instability, so no ε-perturbation is needed."""
    c = [fmpq(v) for v in p.coeffs()]
    if not c:
        raise ValueError("the zero polynomial has no roots to test")
    d = len(c) - 1
    hi = c[::-1]  # a_d, a_{d-1}, ..., a_0
    if hi[0] < 0:
        hi = [-v for v in hi]
    prev = hi[0::2]
    cur = hi[1::2]
    for k in range(1, d + 1):
        cur = cur + [fmpq(0)] * (len(prev) - len(cur))
        if cur[0] <= 0:
            return False, f"Routh array: first-column entry {k} is {cur[0]} <= 0"
        nxt = [(cur[0] * prev[j + 1] - prev[0] * cur[j + 1]) / cur[0] for j in range(len(prev) - 1)]
        prev, cur = cur, nxt
    return True, f"Routh array: all {d} first-column entries after a_d are > 0"


def detectability(A: Any, C: Any, time: Time = "discrete") -> Detectability:
    """Exact observability and detectability of (C, A) for x⁺ = A x (``time="discrete"``) or
    ẋ = A x (``time="continuous"``), y = C x.

    Parameters: ``A`` an n × n matrix, ``C`` a p × n matrix (a length-n vector is one row);
    entries anything :func:`obsdesign.certify.exact.Q` converts (floats exactly)."""
    if time not in ("discrete", "continuous"):
        raise ValueError(f"time must be 'discrete' or 'continuous', not {time!r}")
    N, Au = unobservable_restriction(A, C)
    n, k = N.nrows(), N.ncols()
    if k == 0:
        return Detectability(
            True, True, 0, f"observable: the observability matrix has full rank {n}"
        )
    chi = Au.charpoly()
    if time == "discrete":
        stable, why = schur_stable(chi)
        region = "|z| < 1"
    else:
        stable, why = hurwitz_stable(chi)
        region = "Re s < 0"
    verdict = "detectable" if stable else "not detectable"
    return Detectability(
        False,
        stable,
        k,
        f"{verdict}: rank of the observability matrix {n - k} < {n}; the unobservable modes "
        f"(roots of {chi}) {'all satisfy' if stable else 'do not all satisfy'} {region} ({why})",
    )


def is_observable(A: Any, C: Any) -> bool:
    """Exact Kalman rank test of (C, A)."""
    return observable_rowspace(A, C).nrows() == _to_fmat(A).nrows()


def is_detectable(A: Any, C: Any, time: Time = "discrete") -> bool:
    """Exact detectability of (C, A) (see :func:`detectability`)."""
    return detectability(A, C, time).detectable
