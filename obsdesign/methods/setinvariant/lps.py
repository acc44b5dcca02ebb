"""The linear programs of Section III (Dórea & Pimenta, paper 003), in float64.

For ``Ω = {e : G e <= 1}`` with vertices ``e^j`` and edges:

* δ_i = max_{d ∈ D} G_i B1 d (Section III; ξ (13) in the symmetric case), from D's vertices;
* φ_i(z) = max G_i A e s.t. G e <= 1, |C e − z| <= η̄ (LP (6)); computed as the max of
  ``G A`` over the vertices of the slice, which are explicit (vertices in the slab and edge
  crossings), so no LP is needed;
* Z_d(Ω) = {C e^j ± η̄} sorted (Section III);
* ε(z) = min_{ε, v} ε s.t. φ(z) + G v <= ε 1 − δ (LP (9)), for all z^l in one block-diagonal
  HiGHS LP (the blocks are independent, so minimizing the sum minimizes each).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from obsdesign.errors import InconclusiveError, SolverError
from obsdesign.sets import polytope_ops as po

from .budget import check_deadline


def delta(G: np.ndarray, B1: np.ndarray, Dv: np.ndarray) -> np.ndarray:
    """δ_i = max_{d ∈ D} G_i B1 d (Section III), exact over the vertices ``Dv`` of D."""
    if B1.shape[1] == 0 or len(Dv) == 0:
        return np.zeros(len(G))
    return (G @ B1 @ Dv.T).max(axis=1)


def z_d(V: np.ndarray, c: np.ndarray, eta: float) -> np.ndarray:
    """Z_d(Ω) = {C e^j − η̄, C e^j + η̄ : j} sorted, near-duplicates merged (Section III)."""
    cv = V @ c
    z = np.sort(np.concatenate([cv - eta, cv + eta]) if eta > 0 else cv)
    if len(z) == 0:
        return z
    tol = 1e-12 * float(np.abs(z).max())  # relative: z = C e has the scale of C (not of 1)
    return z[np.concatenate([[True], np.diff(z) > tol])]


#: the largest table of φ(z) values (breakpoints × facets, float64) :func:`phi_at` makes
PHI_MAX_BYTES = 2 * 1024**3


def phi_at(
    G: np.ndarray,
    A: np.ndarray,
    V: np.ndarray,
    edges: np.ndarray,
    c: np.ndarray,
    eta: float,
    zs: np.ndarray,
    deadline: float | None = None,
) -> tuple[np.ndarray, list[np.ndarray]]:
    """φ(z) of LP (6) for each z in ``zs`` (rows), and the slice points used for each z
    (:class:`Timeout` past ``deadline``, checked every 32 slices). A table of φ larger than
    :data:`PHI_MAX_BYTES` is a SolverError saying so (a 7-state design reached 949,004 facets
    and 4,834 breakpoints: an internal failure, MemoryError for 34.2 GiB; session 47)."""
    need = 8 * len(zs) * len(G)
    if need > PHI_MAX_BYTES:
        raise SolverError(
            f"the polyhedron grew to {len(G):,} facets with {len(zs):,} breakpoints: LP (6)'s "
            f"table would take {need / 2**30:.1f} GiB (at most {PHI_MAX_BYTES / 2**30:g}; a "
            "larger λ or Δδ, or fewer states)"
        )
    GA = G @ A
    out = np.empty((len(zs), len(G)))
    slices = []
    for l, z in enumerate(zs):
        if l % 32 == 0:
            check_deadline(deadline)
        S = po.slice_points(V, edges, c, z - eta, z + eta)
        if len(S) == 0:  # z outside Z(Ω) by rounding: take the nearest vertex
            S = V[[int(np.argmin(np.abs(V @ c - z)))]]
        slices.append(S)
        out[l] = (GA @ S.T).max(axis=1)
    return out, slices


@dataclass
class EpsResult:
    """ε(z^l) (LP (9)) and the optimal injections v^l, one row per z^l."""

    eps: np.ndarray
    v: np.ndarray


def eps_batch(
    G: np.ndarray,
    phi: np.ndarray,
    dlt: np.ndarray,
    rows_per_lp: int = 20000,
    deadline: float | None = None,
) -> EpsResult:
    """ε(z^l) and v^l of LP (9) for all l, in block-diagonal HiGHS LPs of about
    ``rows_per_lp`` rows each (measured: 1248 blocks of 314 rows take 4.3 s as one LP,
    1.5 s in chunks of 100 blocks, 6.3 s one LP at a time); :class:`Timeout` past
    ``deadline``, checked before each block.

    ε is recomputed from the returned v as max_i(φ_i + δ_i + G_i v), so it is the true
    level of that v (never below the solver's value by more than rounding).
    """
    nz, g = phi.shape
    n = G.shape[1]
    if nz == 0:
        return EpsResult(np.zeros(0), np.zeros((0, n)))
    chunk = max(1, rows_per_lp // max(g, 1))
    if nz > chunk:
        parts = []
        for i in range(0, nz, chunk):
            check_deadline(deadline)
            parts.append(_eps_block(G, phi[i : i + chunk], dlt, deadline))
        return EpsResult(np.concatenate([p.eps for p in parts]), np.vstack([p.v for p in parts]))
    check_deadline(deadline)
    return _eps_block(G, phi, dlt, deadline)


#: HiGHS takes matrix entries above 1e15 and right-hand sides from 1e20 on as infinite and
#: then stops with "Model error": LP data beyond these are out of a float LP's range
HIGHS_MATRIX_MAX = 1e15
HIGHS_INFINITY = 1e20


def lp_in_range(A: np.ndarray, b: np.ndarray) -> bool:
    """Whether the float LP data ``A``, ``b`` are finite and inside what HiGHS reads as finite
    (scipy's ``linprog`` raises ValueError on inf/nan; HiGHS stops with "Model error" above
    :data:`HIGHS_MATRIX_MAX` / :data:`HIGHS_INFINITY`).

    :param A: the constraint matrix (dense); :param b: the right-hand side."""
    a = float(np.max(np.abs(A), initial=0.0))
    r = float(np.max(np.abs(b), initial=0.0))
    return bool(np.isfinite(a) and np.isfinite(r) and a <= HIGHS_MATRIX_MAX and r < HIGHS_INFINITY)


#: a right-hand side of LP (9) beyond which a HiGHS failure is put down to the data (its
#: gauge values are O(1) for a polyhedron near Ω; 10¹² is past HiGHS's feasibility
#: tolerance 10⁻⁷ by more than the 53 bits of a double)
WIDE_RHS = 1e12


def check_lp_range(A: np.ndarray, b: np.ndarray, what: str) -> None:
    """Raise InconclusiveError (exit 4) when the float LP ``what`` has data that HiGHS would
    read as infinite, or no finite data at all, instead of its "Model error" (exit 3).

    :param A: the constraint matrix (dense); :param b: the right-hand side."""
    if not lp_in_range(A, b):
        a = float(np.max(np.abs(A), initial=0.0))
        r = float(np.max(np.abs(b), initial=0.0))
        raise InconclusiveError(
            f"{what} is out of a float LP's range (largest |coefficient| {a:.3g}, largest "
            f"|right-hand side| {r:.3g}; HiGHS takes values above {HIGHS_MATRIX_MAX:g} and "
            f"{HIGHS_INFINITY:g} as infinite): the spec's numbers (A, C, B1, the sets) or the "
            "growth of the iterates under A are too large for the float design"
        )


def _eps_block(
    G: np.ndarray, phi: np.ndarray, dlt: np.ndarray, deadline: float | None = None
) -> EpsResult:
    """One block-diagonal HiGHS LP (9) for the rows of ``phi``; each HiGHS call gets the
    budget's remaining seconds as its time limit and the budget is checked before each
    retry, so a struggling solver stops at ``deadline`` (:class:`Timeout`) instead of
    splitting and retrying for minutes (found by the soundness audit: a 3-state spec with
    ``time_limit = 30`` still running at 300 s, inside these retries)."""
    nz, g = phi.shape
    n = G.shape[1]
    b_ub = (-dlt[None, :] - phi).reshape(-1)
    Gs, s = unit_columns(G)
    check_lp_range(Gs, b_ub, "LP (9)")
    Ablk = sp.kron(sp.eye(nz, format="csr"), sp.csr_matrix(Gs))
    Eblk = -sp.kron(sp.eye(nz, format="csr"), sp.csr_matrix(np.ones((g, 1))))
    A_ub = sp.hstack([Ablk, Eblk]).tocsr()
    cost = np.concatenate([np.zeros(nz * n), np.ones(nz)])
    res = _linprog(cost, A_ub, b_ub, "highs", deadline)
    if res.status != 0 and nz > 1:
        # HiGHS occasionally reports "Solve error" on a large block LP (seen on a random
        # 3-state system): the blocks are independent, so split and retry
        check_deadline(deadline)
        half = nz // 2
        a = _eps_block(G, phi[:half], dlt, deadline)
        b = _eps_block(G, phi[half:], dlt, deadline)
        return EpsResult(np.concatenate([a.eps, b.eps]), np.vstack([a.v, b.v]))
    for method in ("highs-ds", "highs-ipm"):
        if res.status == 0:
            break
        check_deadline(deadline)
        res = _linprog(cost, A_ub, b_ub, method, deadline)
    if res.status != 0:
        check_deadline(deadline)  # stopped by the time limit: the budget's, not a failure
        r = float(np.max(np.abs(b_ub), initial=0.0))
        if r > WIDE_RHS:
            # A = [[0.7, 2^53 + 1], [−0.7, 0.7]]: HiGHS "status not recognized", exit 3 as an
            # internal failure, where it is data beyond the float design (CLI review, 44)
            raise InconclusiveError(
                f"HiGHS failed on LP (9) ({res.message}) with right-hand sides up to {r:.3g}: "
                "the spec's numbers (A, C, B1, the sets) or the growth of the iterates under "
                "A are too large for the float design"
            )
        raise SolverError(f"HiGHS failed on LP (9): {res.message}")
    v = res.x[: nz * n].reshape(nz, n) * s
    eps = (phi + dlt[None, :] + v @ G.T).max(axis=1)
    return EpsResult(eps, v)


def unit_columns(G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(G·diag(s), s)`` with s_k a power of two (exact) that brings the largest |G_ik| of
    each column into [1/2, 1) (s_k = 1 for a zero column): LP (9) is solved for u = v / s.
    Its rows (right-hand side 1) and φ, δ, ε are gauge values, free of units, but G's columns
    carry 1 / (the state's units): with Ω = {|e_k| <= 1e9} the entries are ~1e-9, which HiGHS
    drops as zeros (``small_matrix_value``), and its tolerances are absolute; LP (9) then gave
    ε(z) = 2.4 where it is 1 (a pure rescaling of the state changed the design)."""
    cmax = np.abs(G).max(axis=0) if len(G) else np.ones(G.shape[1])
    s = np.ldexp(1.0, -np.frexp(np.where(cmax > 0, cmax, 1.0))[1])
    return G * s, s


def _linprog(
    cost: np.ndarray, A_ub: Any, b_ub: np.ndarray, method: str, deadline: float | None
) -> Any:
    """scipy's HiGHS ``linprog`` of LP (9) (free variables), with the budget's remaining
    seconds (at least 10 ms) as HiGHS's own time limit when there is a budget."""
    opts = None
    if deadline is not None:
        opts = {"time_limit": max(deadline - time.perf_counter(), 0.01)}
    return linprog(cost, A_ub=A_ub, b_ub=b_ub, bounds=(None, None), method=method, options=opts)


def epsilon_profile(
    G: np.ndarray,
    A: np.ndarray,
    B1: np.ndarray,
    c: np.ndarray,
    Dv: np.ndarray,
    eta: float,
    zs: np.ndarray | None = None,
    deadline: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(z, ε(z)) for a polytope: at Z_d, or at the given ``zs`` (Fig. 2 of the paper);
    :class:`Timeout` past ``deadline`` (a 6-state design's note ran minutes and to 24 GB
    with none; re-check review 47)."""
    st = po.h_to_v(G)
    if zs is None:
        zs = z_d(st.V, c, eta)
    phi, _ = phi_at(G, A, st.V, st.edges, c, eta, zs, deadline)
    return zs, eps_batch(G, phi, delta(G, B1, Dv), deadline=deadline).eps


def phi_slice_general(
    G: np.ndarray, A: np.ndarray, C: np.ndarray, eta: float
) -> tuple[np.ndarray, np.ndarray]:
    """φ_q(0) of Lemma 6.1 for any number of outputs: max G_i A e over the slice
    ``{G e <= 1, |C e| <= η̄}`` (componentwise), returned with the slice's vertices.

    With η̄ = 0 the slice ``Ω ∩ ker C`` is parametrized by a basis of ker C; with η̄ > 0 it is
    a full-dimensional polytope containing the origin, written with right-hand side 1.
    """
    n = G.shape[1]
    if eta > 0:
        H = np.vstack([G, C / eta, -C / eta])
        S = po.h_to_v(H).V
    else:
        _, s, Vt = np.linalg.svd(C)
        rank = int((s > 1e-12 * s.max()).sum())  # relative: C = 1e-13·C has C's kernel
        N = Vt[rank:].T  # n × (n - rank)
        if N.shape[1] == 0:
            S = np.zeros((1, n))
        else:
            T = po.h_to_v(G @ N).V
            S = T @ N.T
    return (G @ A @ S.T).max(axis=1), S
