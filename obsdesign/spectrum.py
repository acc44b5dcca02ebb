"""The eigenvalues of an exact matrix as a *guide* (never a proof): where the best-rate search of
a quadratic Lyapunov function starts, which rates are worth a high-precision Lyapunov solve,
and the "≈" figures of messages and notes. Every verdict that uses them is decided by an exact
test elsewhere (:func:`obsdesign.lyap.rate_feasibility`, :func:`obsdesign.lyap.certified_P`).

The float eigenvalues (LAPACK through numpy) are taken when their first-order error bound
u·‖A‖_F·κ_F(V) (V the eigenvectors, κ_F(V) = ‖V‖_F‖V⁻¹‖_F; Bauer–Fike) is small against the
spectrum's size. Otherwise — a strongly non-normal or nearly defective matrix, such as the
error dynamics A − LC of a Kalman-type gain on a plant with ρ(A) ≈ 10³ (a float spectral
radius of 15 for an exactly Schur matrix whose radius is 0.88) — the eigenvalues are computed
from the exact entries, up to :data:`HP_MAX_N` states, as the roots of the exact
characteristic polynomial (python-flint), else by ``acb_mat.eig`` at :data:`PRECISIONS` bits
until two precisions agree.

The spectral radius (discrete time) and spectral abscissa (continuous time) bound the decay
rates of V = eᵀPe for the error dynamics e⁺ = (A − LC)e of Section 5 of the
constrained-redesign paper (Astolfi et al., NOLCOS 2019), eq. (4)-(6).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from flint import acb_mat, arb_mat, ctx, fmpq_mat

#: the largest state dimension at which inaccurate float eigenvalues are redone in high
#: precision (~1 ms at n = 8, ~15 ms at n = 24, ~50 ms at n = 64 at 128 bits; 24 until session 41)
HP_MAX_N = 64
#: working precisions of the high-precision eigenvalues, in bits
PRECISIONS = (128, 320, 1024)
#: float eigenvalues are taken when their error bound is at most this, relative to
#: max(1, the largest |eigenvalue|)
FLOAT_TOL = 1e-9
#: two precisions agree when their spectral radii and abscissae differ by at most this,
#: relative to max(1, the radius)
AGREE_TOL = 1e-12
#: the source of float eigenvalues, for messages
FLOAT_SOURCE = "float eigenvalues"


@dataclass
class Spectrum:
    """Eigenvalues ``w`` of a matrix (a guide), where they come from (``source``, for
    messages), and, for float ones, the eigenvectors ``V`` and ``Vi`` = V⁻¹ when their
    inverse is finite (None otherwise)."""

    w: np.ndarray
    source: str
    V: np.ndarray | None = None
    Vi: np.ndarray | None = None

    def bound(self, discrete: bool) -> float:
        """The spectral radius (discrete time) or spectral abscissa (continuous time): the
        infimum of λ, resp. −supremum of α, in eq. (4)-(6) of the constrained-redesign paper
        (Section 5) for this error dynamics. ``-inf`` / 0 for an empty matrix."""
        if self.w.size == 0:
            return 0.0 if discrete else -np.inf
        return float(np.max(np.abs(self.w))) if discrete else float(np.max(self.w.real))

    def figure(self, discrete: bool) -> str:
        """The spectral radius / largest real part as a message's "≈" figure, naming where it
        comes from unless it is accurate float eigenvalues ("spectral radius ≈ 6064.19" was
        printed for an exact radius of 0.9 at n = 40, unlabelled; lyapunov trial, session
        34)."""
        b = self.bound(discrete)
        what = f"spectral radius ≈ {b:.6g}" if discrete else f"largest real part ≈ {b:.6g}"
        return what if self.source == FLOAT_SOURCE else f"{what} from {self.source}"


def spectrum(Am: fmpq_mat, Af: np.ndarray) -> Spectrum:
    """The eigenvalues of the exact matrix ``Am`` (e.g. A − LC of eq. (3), constrained-redesign
    paper) as a guide: float ones when their Bauer–Fike error bound is below
    :data:`FLOAT_TOL` (relative), else high-precision ones (:func:`eig_hp`, up to
    :data:`HP_MAX_N` states; the float ones, however poor, above it or when that fails).

    :param Am: the exact matrix; :param Af: its float copy (correctly rounded)."""
    n = Af.shape[0]
    w = V = Vi = None
    err = np.inf
    with np.errstate(all="ignore"):
        try:
            w, V = np.linalg.eig(Af)
            Vi = np.linalg.inv(V)
        except (np.linalg.LinAlgError, ValueError):
            Vi = None
        if w is not None and V is not None and Vi is not None:
            if np.all(np.isfinite(Vi)) and np.all(np.isfinite(w)):
                kappa = np.linalg.norm(V) * np.linalg.norm(Vi)
                err = float(np.finfo(float).eps * np.linalg.norm(Af) * kappa)
            else:
                Vi = None
    if w is not None and np.all(np.isfinite(w)):
        size = max(1.0, float(np.max(np.abs(w)))) if n else 1.0
        if err <= FLOAT_TOL * size or n > HP_MAX_N:
            src = FLOAT_SOURCE if err <= FLOAT_TOL * size else inaccurate_source(err)
            return Spectrum(w, src, V if Vi is not None else None, Vi)
    hp = eig_hp(Am) if 0 < n <= HP_MAX_N else None
    if hp is not None:
        return Spectrum(hp[0], hp[1])
    if w is None:
        w = np.linalg.eigvals(np.nan_to_num(Af))
    return Spectrum(w, inaccurate_source(err))


def inaccurate_source(err: float) -> str:
    """The source of float eigenvalues whose error bound ``err`` (absolute) is not met."""
    bound = f"≈ {err:.2g}" if math.isfinite(err) else "not finite"
    return f"{FLOAT_SOURCE}, not reliable here: their Bauer–Fike error bound is {bound}"


def eig_hp(Am: fmpq_mat) -> tuple[np.ndarray, str] | None:
    """The eigenvalues of the exact matrix ``Am``: the roots of its exact characteristic
    polynomial (:func:`charpoly_roots`), else python-flint's ``acb_mat.eig`` (approximate,
    midpoints only) at the precisions of :data:`PRECISIONS` until two in a row agree on the
    spectral radius and abscissa (:data:`AGREE_TOL`), the last computed when none do.

    ``acb_mat.eig`` came first until session 32, and it is not reliable beside a Jordan
    block: on a 4×4 block next to a complex pair it was right at 128 bits and far off at 320
    and 1024 (the guide said "spectral abscissa ≈ 3.02" for a Hurwitz A − LC, skipped the
    high-precision Lyapunov solve and certifiable rates ended exit 4), and with a 5×5 block
    320 and 1024 bits agreed on radius and abscissa while both misplaced the pair (radius
    0.1875 for 0.938; soundness and re-check trials, session 32). The characteristic
    polynomial's roots are isolated with their multiplicities, 4-54 ms at n = 24.
    Returns (eigenvalues as complex floats, where they come from, for messages), or None
    when nothing gives finite eigenvalues.

    :param Am: the exact matrix (n ≥ 1)."""
    roots = charpoly_roots(Am)
    if roots is not None:
        return roots, CHARPOLY_SOURCE
    last: tuple[np.ndarray, int] | None = None
    for prec in PRECISIONS:
        with ctx.workprec(prec):
            try:
                ev = acb_mat(arb_mat(Am)).eig(algorithm="approx")
            except (ValueError, ZeroDivisionError):
                continue
            w = np.array([complex(z.mid()) for z in ev], dtype=complex)
        if not np.all(np.isfinite(w)):
            continue
        if last is not None and _agree(last[0], w):
            return w, f"python-flint eigenvalues at {prec} bits"
        last = (w, prec)
    return None if last is None else (last[0], f"python-flint eigenvalues at {last[1]} bits")


#: :func:`charpoly_roots` is skipped when n times the bits of the entries' common denominator
#: exceeds this: a 24×24 matrix whose 7×7 block had distinct 30-bit denominators took 58-77 s
#: (second re-check trial, session 32); a spec's A − LC has decimal and dyadic entries, whose
#: common denominator 2^a·10^b stays a few hundred bits
CHARPOLY_MAX_BITS = 20_000


def _denominator_bits(Am: fmpq_mat) -> int:
    """Bits of the least common denominator of the entries of ``Am``."""
    d = 1
    for i in range(Am.nrows()):
        for j in range(Am.ncols()):
            d = math.lcm(d, int(Am[i, j].q))
    return d.bit_length()


#: the source of :func:`charpoly_roots`, for messages
CHARPOLY_SOURCE = "roots of the exact characteristic polynomial"


def charpoly_roots(Am: fmpq_mat) -> np.ndarray | None:
    """The eigenvalues of the exact matrix ``Am`` as the roots of its exact characteristic
    polynomial (python-flint's ``charpoly`` and ``complex_roots``: isolated with
    multiplicities, so a defective eigenvalue is found as well as a simple one), as complex
    floats (the balls' midpoints); None when they are not finite or flint fails."""
    if Am.nrows() * _denominator_bits(Am) > CHARPOLY_MAX_BITS:
        return None
    try:
        roots = Am.charpoly().complex_roots()
        w = np.array([complex(r.mid()) for r, m in roots for _ in range(m)], dtype=complex)
    except (ValueError, ZeroDivisionError, OverflowError):
        return None
    return w if w.size == Am.nrows() and np.all(np.isfinite(w)) else None


def _agree(a: np.ndarray, b: np.ndarray) -> bool:
    ra, rb = float(np.max(np.abs(a))), float(np.max(np.abs(b)))
    sa, sb = float(np.max(a.real)), float(np.max(b.real))
    scale = max(1.0, ra, rb)
    return abs(ra - rb) <= AGREE_TOL * scale and abs(sa - sb) <= AGREE_TOL * scale
