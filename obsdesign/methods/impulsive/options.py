"""The ``[method]``, ``[nonlinearity]`` and ``[simulate]`` keys of the ``impulsive`` method
(Schaum, Feketa, Meurer, Moreno, "Robust nonlinear observer design based on impulsive
dissipativity", MTNS 2020).

The plant is ẋ = A x + ψ(x) with ψ from ``[system] psi``; ``[nonlinearity]`` holds only the
data of Assumption 1 (``lipschitz_x``, or ``[nonlinearity.o]`` / ``[nonlinearity.n]``) and the
optional falsification box ``[nonlinearity.falsify]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.exact import Q, qvec
from obsdesign.certify.linalg import qrank
from obsdesign.certify.printing import fmt_exact
from obsdesign.certify.psd import check_pd, check_psd
from obsdesign.errors import SpecError
from obsdesign.methods.base import table_schema
from obsdesign.simulate.budget import DEFAULT_LIMIT, TIME_LIMIT_SCHEMA, parse_time_limit
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

from .core import MAX_DIGITS, BlockData, LipschitzX, Problem
from .dissipativity import QSR, qsr_lipschitz, qsr_sector

#: most sampled pairs of the falsification
MAX_SAMPLES = 1_000_000


@dataclass
class FalsifySpec:
    """``[nonlinearity.falsify]``: the box [lower, upper] in x, the number of sampled pairs, the
    seed, and what a violation does (``fail``: a failed numerical claim; ``warn``: a note)."""

    lower: np.ndarray
    upper: np.ndarray
    samples: int
    seed: int
    on_violation: str


@dataclass
class Options:
    """Typed ``[method]`` + ``[nonlinearity]`` of ``impulsive``: the exact problem and the
    optional falsification pass."""

    problem: Problem
    falsify: FalsifySpec | None


@dataclass
class SimOptions:
    """The method's own ``[simulate]`` keys: ``runs`` (sampling sequences), ``sampling_file``
    (intervals from a file, one run), ``rtol`` (RK45 relative tolerance), ``time_limit``
    (seconds the simulation may run, checked after every sampling interval)."""

    runs: int = 20
    sampling_file: Path | None = None
    rtol: float = 1e-7
    time_limit: float = DEFAULT_LIMIT


def parse_options(table: Table, spec: Spec) -> Options:
    """Read and validate ``[method]`` and ``[nonlinearity]`` (every error names file and key).

    ``table``: the ``[method]`` table; ``spec``: the spec (its ``[system]`` and raw tables)."""
    s = spec.system
    if s.discrete:
        raise SpecError(spec.file, "system.time", 'the impulsive method needs time = "continuous"')
    for key, v in (("f", s.f), ("h", s.h), ("u", s.u_signal)):
        if v is not None:
            raise SpecError(
                spec.file,
                f"system.{key}",
                "is not used by the impulsive method: the plant is ẋ = A x + psi(x), "
                "y_k = C x(t_k) + w_k",
            )
    n, m = s.n, s.p
    if not m < n:
        raise SpecError(
            spec.file, "system.C", f"expected fewer outputs than states (m = {m}, n = {n})"
        )
    if qrank(s.C.q) < m:
        raise SpecError(spec.file, "system.C", f"expected rank(C) = m = {m} (full row rank)")
    if s.m or s.nd:
        raise SpecError(
            spec.file, "system.B", "the impulsive method has no inputs or disturbances (B, Bd)"
        )
    L = _diag_gain(table, m)
    gamma = fmpq(1) - max(fmpq(1) - v for v in L)
    alpha = table.scalar("alpha", min=0, strict_min=True).q
    if not alpha > gamma:
        raise table.error(
            # exact values: "expected α > γ = 0.8, got 0.8" for α = 0.8 − 10⁻¹⁰ (review, 43)
            "alpha",
            f"expected α > γ = {fmt_exact(gamma)} (Theorem 2), got {fmt_exact(alpha)}",
        )
    w_bar = table.scalar("noise_bound", min=0).q
    Mv: Any = "orthonormal"
    if table.has("M"):
        if isinstance(table.data["M"], str):
            Mv = table.str("M", choices=("orthonormal", "optimize"))
        else:
            Mv = table.matrix("M", rows=n - m, cols=n).q
            if qrank(np.vstack([s.C.q, Mv])) < n:
                raise table.error(
                    "M", "expected T = [C; M] invertible (M must complement the rows of C)"
                )
    kappa: Any = "max"
    if table.has("kappa") and isinstance(table.data["kappa"], str):
        kappa = table.str("kappa", choices=("max", "widest"))
    elif table.has("kappa"):
        kappa = table.scalar("kappa", min=0, strict_min=True).q
    scaling = table.str("qsr_scaling", default="optimize", choices=("optimize", "as-given"))
    digits = table.int("digits", default=None, min=1)
    if digits is not None and digits > MAX_DIGITS:
        raise table.error("digits", f"expected at most {MAX_DIGITS} decimals, got {digits}")
    table.done()
    nl = spec.tables.get("nonlinearity")
    if nl is None:
        raise SpecError(spec.file, "nonlinearity", "is missing (the data of Assumption 1)")
    if s.psi is None:
        raise SpecError(spec.file, "system.psi", "is missing (ẋ = A x + ψ(x), eq. (1a))")
    if any(e.uses("t") for e in s.psi):
        raise SpecError(spec.file, "system.psi", "expected ψ(x) without t (eq. (1a))")
    data = _assumption1(nl, table, Mv, m, n)
    fz = _falsify(nl, n)
    nl.done()
    prob = Problem(s.A.q, s.C.q, L, alpha, w_bar, Mv, data, kappa, scaling == "optimize", digits)
    return Options(prob, fz)


def _assumption1(nl: Table, table: Table, Mv: Any, m: int, n: int) -> BlockData | LipschitzX:
    """The data of Assumption 1: ``lipschitz_x`` or the two blocks in z = T x."""
    if nl.has("lipschitz_x"):
        if nl.has("o") or nl.has("n"):
            raise nl.error(
                "lipschitz_x",
                "give either lipschitz_x or the tables [nonlinearity.o] / [nonlinearity.n], "
                "not both",
            )
        return LipschitzX(nl.scalar("lipschitz_x", min=0).q)
    if isinstance(Mv, str):
        raise table.error(
            "M",
            "per-block data ([nonlinearity.o], [nonlinearity.n]) are in the coordinates "
            "z = T x, so M must be given as a matrix (or use nonlinearity.lipschitz_x)",
        )
    to, tn = nl.table("o", required=True), nl.table("n", required=True)
    assert to is not None and tn is not None
    q_o, l_on = _block(to, m)
    q_n, l_no = _block(tn, n - m)
    if not check_pd(-q_o.Q):
        raise to.error(
            "Q" if to.has("Q") else "sector",
            "expected Q_o negative definite (Lemma 2 needs Q_o ≺ 0)",
        )
    if not check_psd(-q_n.Q):
        raise tn.error("Q", "expected Q_n negative semidefinite (Assumption 1 needs Q_n ⪯ 0)")
    for t, q, name in ((to, q_o, "o"), (tn, q_n, "n")):
        _satisfiable(t, q, name)
    return BlockData(q_o, q_n, l_on, l_no)


def _satisfiable(t: Table, q: QSR, name: str) -> None:
    """Refuse given (Q, S, R), Q ⪯ 0, that no nonlinearity satisfies. The largest supply
    φᵀQφ + 2φᵀSε + εᵀRε over φ is +∞ when Sε leaves the range of Q, else εᵀRε − vᵀQv for any
    v with Qv = Sε (at φ = −v; εᵀ(R − SᵀQ⁻¹S)ε for Q ≺ 0). So the data hold for some φ at
    every ε iff εᵀRε − vᵀQv ≥ 0 on the subspace {(ε, v) : Qv = Sε}: checked exactly, on an
    integer basis of that null space. Q = R = −1, S = 0 designed and verified a window,
    vacuously, for an observer that diverges (impulsive review, session 43); a singular Q_n
    (Q = diag(−1, 0), S = diag(0, −1), R = diag(−1000, 0)) still did (tamper review). A sector
    or Lipschitz block always passes."""
    if not t.has("Q"):
        return
    from flint import fmpz_mat

    k = q.k
    M = np.hstack([-np.asarray(q.S, dtype=object), np.asarray(q.Q, dtype=object)])  # k × 2k
    rows = []
    for r in M:  # each row times its denominators' lcm: the same null space, over Z
        d = 1
        for v in r:
            d = d * int(Q(v).q) // math.gcd(d, int(Q(v).q))
        rows.append([int(Q(v) * d) for v in r])
    X, nullity = fmpz_mat(rows).nullspace()
    if nullity == 0:
        return
    W = np.array([[fmpq(int(X[i, j])) for j in range(nullity)] for i in range(2 * k)], dtype=object)
    F = np.zeros((2 * k, 2 * k), dtype=object)
    F[:] = fmpq(0)
    F[:k, :k] = np.asarray(q.R, dtype=object)
    F[k:, k:] = -np.asarray(q.Q, dtype=object)
    G = W.T @ F @ W
    G = (G + G.T) * fmpq(1, 2)  # the quadratic form's symmetric part (R given symmetric)
    if not check_psd(G):
        raise t.error(
            "R",
            f"Assumption 1's data of block {name} hold for no nonlinearity: for some error ε "
            "every φ gives φᵀQφ + 2φᵀSε + εᵀRε < 0 (R − SᵀQ⁺S is not ⪰ 0 where Sε lies in the "
            "range of Q), so the certificate would hold only vacuously",
        )


def _falsify(nl: Table, n: int) -> FalsifySpec | None:
    ft = nl.table("falsify")
    if ft is None:
        return None
    lo, hi = ft.vector("lower", n=n), ft.vector("upper", n=n)
    if not all(lo.q[i] < hi.q[i] for i in range(n)):
        raise ft.error("upper", "expected lower < upper in every coordinate")
    samples = ft.int("samples", default=20000, min=10)
    if samples > MAX_SAMPLES:
        raise ft.error("samples", f"expected at most {MAX_SAMPLES} sampled pairs, got {samples}")
    fz = FalsifySpec(
        lo.f,
        hi.f,
        samples,
        ft.int("seed", default=0, min=0),
        ft.str("on_violation", default="fail", choices=("fail", "warn")),
    )
    ft.done()
    return fz


def parse_simulate(table: Table, spec: Spec) -> SimOptions:
    """The method's ``[simulate]`` keys (``runs``, ``sampling_file`` relative to the spec's
    folder, ``rtol``) as :class:`SimOptions`; never mutates the spec.

    ``table``: the ``[simulate]`` table; ``spec``: the spec (for the file's folder)."""
    runs = table.int("runs", default=20, min=1)
    if runs > 100_000:  # the bound of --option runs
        raise table.error("runs", "expected at most 100,000 runs")
    sf = None
    if table.has("sampling_file"):
        text = table.str("sampling_file")
        if not text.strip() or "\0" in text:
            # "" was the spec's folder ("is a directory"), a NUL an internal ValueError, exit
            # 3 (re-check trial, session 41), as for --option sampling_file
            raise table.error("sampling_file", f"expected a file path, got {text!r}")
        p = Path(text)
        sf = p if p.is_absolute() else Path(spec.file).resolve().parent / p
    # the bounds of ``--option rtol`` (1e-14 … 1e-2): rtol = 1 was accepted here (review)
    rtol = float(
        table.scalar("rtol", default=fmpq(1, 10**7), min=fmpq(1, 10**14), max=fmpq(1, 100)).f
    )
    limit = parse_time_limit(table)  # the bound of --option time_limit (1 ms)
    return SimOptions(runs, sf, rtol, limit)


def _diag_gain(table: Table, m: int) -> np.ndarray:
    """L as its diagonal: a list of m numbers, or an m×m matrix that must be diagonal; every
    eigenvalue of I − L must lie in (0, 1) (text after (18))."""
    raw = table.data.get("L")
    if isinstance(raw, list) and raw and isinstance(raw[0], list):
        Lm = table.matrix("L", rows=m, cols=m).q
        if any(Lm[i, j] != 0 for i in range(m) for j in range(m) if i != j):
            raise table.error("L", "expected a diagonal correction gain L (eq. (11b))")
        d = qvec([Lm[i, i] for i in range(m)])
    else:
        d = table.vector("L", n=m).q
    for i, v in enumerate(d):
        if not (0 < 1 - v < 1):
            raise table.error(
                "L",
                f"expected every eigenvalue of I − L in (0, 1), i.e. 0 < L_ii < 1; "
                f"L[{i}] = {fmt_exact(v)}",
            )
    return np.asarray(d, dtype=object)


def _block(t: Table, k: int) -> tuple[QSR, fmpq]:
    """One block of Assumption 1: exactly one of ``sector = [k1, k2]``, ``lipschitz = ℓ`` or
    ``Q``, ``S``, ``R`` (k×k), plus ``cross`` (ℓ_ij of the split reading, default 0)."""
    given = [key for key in ("sector", "lipschitz", "Q") if t.has(key)]
    if len(given) != 1:
        raise t.error("", "expected exactly one of sector = [k1, k2], lipschitz = ℓ, or Q/S/R")
    if given[0] == "sector":
        v = t.vector("sector", n=2).q
        if not v[0] <= v[1]:
            raise t.error("sector", "expected k1 ≤ k2")
        q = qsr_sector(v[0], v[1], k)
    elif given[0] == "lipschitz":
        q = qsr_lipschitz(t.scalar("lipschitz", min=0).q, k)
    else:
        Qm, S, R = (t.matrix(key, rows=k, cols=k).q for key in ("Q", "S", "R"))
        for key, X in (("Q", Qm), ("R", R)):
            if any(X[i, j] != X[j, i] for i in range(k) for j in range(k)):
                raise t.error(key, "expected a symmetric matrix")
        q = QSR(Qm, S, R, "given (Q, S, R)")
    cross = t.scalar("cross", default=fmpq(0), min=0).q
    t.done()
    return q, Q(cross)


def options_schema(key: str) -> dict[str, Any]:
    """JSON schema of the ``[method]`` table of ``impulsive``."""
    from obsdesign.spec.schema import MAT, NUM

    return table_schema(
        key,
        {
            "L": MAT,
            "alpha": {**NUM, "exclusiveMinimum": 0},
            "noise_bound": {**NUM, "minimum": 0},
            "M": {"anyOf": [MAT, {"enum": ["orthonormal", "optimize"]}]},
            "kappa": {"anyOf": [{**NUM, "exclusiveMinimum": 0}, {"enum": ["max", "widest"]}]},
            "qsr_scaling": {"enum": ["optimize", "as-given"]},
            "digits": {"type": "integer", "minimum": 1, "maximum": MAX_DIGITS},
        },
        ("L", "alpha", "noise_bound"),
    )


def simulate_schema() -> dict[str, Any]:
    """JSON-schema properties of the method's own ``[simulate]`` keys."""
    return {
        "runs": {"type": "integer", "minimum": 1, "maximum": 100_000},
        "sampling_file": {"type": "string"},
        "rtol": {"type": "number", "minimum": 1e-14, "maximum": 0.01},
        "time_limit": TIME_LIMIT_SCHEMA,
    }
