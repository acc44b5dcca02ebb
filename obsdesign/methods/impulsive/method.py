"""The ``impulsive`` method: spec section, design, certificate, simulation (paper 001).

Spec tables: ``[method]`` (L, alpha, noise_bound, M, kappa, qsr_scaling, digits) and
``[nonlinearity]`` (psi expressions; data as ``lipschitz_x`` or per block ``[nonlinearity.o]``,
``[nonlinearity.n]``; optional ``[nonlinearity.falsify]``). See docs/readme-impulsive.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.claim import Claim, numerical_claim
from obsdesign.certify.exact import Q, qvec, to_float
from obsdesign.certify.linalg import qrank
from obsdesign.certify.psd import check_pd, check_psd
from obsdesign.errors import InfeasibleError, SpecError
from obsdesign.methods.base import Design, Method, Progress
from obsdesign.methods.impulsive.core import (
    BlockData,
    Infeasible,
    LipschitzX,
    Problem,
    certify_window,
    design_window,
)
from obsdesign.methods.impulsive.dissipativity import QSR, qsr_lipschitz, qsr_sector
from obsdesign.methods.impulsive.falsify import Falsification, falsify_blocks, falsify_lipschitz_x
from obsdesign.params import Parameters
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

REF = "impulsive-dissipativity paper (001)"
PARAM_KEYS = (
    "T",
    "Abar",
    "theta_o",
    "theta_n",
    "varpi_o",
    "kappa_n",
    "lambda_no",
    "lambda_on",
    "gamma",
    "beta",
    "kappa",
    "T_min",
    "T_max",
    "alpha",
    "w_bar",
    "ball_radius",
)


@dataclass
class FalsifySpec:
    lower: np.ndarray
    upper: np.ndarray
    samples: int
    seed: int
    on_violation: str  # "fail" | "warn"


@dataclass
class Options:
    """``[method]`` + ``[nonlinearity]`` of ``impulsive``, exact where it matters."""

    problem: Problem
    psi: list[Any]  # Expr per state
    falsify: FalsifySpec | None
    runs: int = 20
    sampling_file: Path | None = None
    rtol: float = 1e-7


class Impulsive(Method):
    key = "impulsive"
    title = "Impulsive dissipative observer: sampling window [T_min, T_max]"
    paper = "001 (Schaum, Feketa, Meurer, Moreno, MTNS 2020)"
    extra_tables = ("nonlinearity",)

    # -- spec -------------------------------------------------------------------------------
    def parse_options(self, table: Table, spec: Spec) -> Options:
        s = spec.system
        if s.discrete:
            raise SpecError(
                spec.file, "system.time", 'the impulsive method needs time = "continuous"'
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
                "alpha", f"expected α > γ = {float(gamma):g} (Theorem 2), got {float(alpha):g}"
            )
        w_bar = table.scalar("noise_bound", min=0).q
        Mv: Any = "orthonormal"
        if table.has("M"):
            raw = table.data["M"]
            if isinstance(raw, str):
                Mv = table.str("M", choices=("orthonormal", "optimize"))
            else:
                Mv = table.matrix("M", rows=n - m, cols=n).q
                if qrank(np.vstack([s.C.q, Mv])) < n:
                    raise table.error(
                        "M", "expected T = [C; M] invertible (M must complement the rows of C)"
                    )
        else:
            table.mark("M")
        kappa: Any = "max"
        if table.has("kappa") and isinstance(table.data["kappa"], str):
            kappa = table.str("kappa", choices=("max", "widest"))
        elif table.has("kappa"):
            kappa = table.scalar("kappa", min=0, strict_min=True).q
        else:
            table.mark("kappa")
        scaling = table.str("qsr_scaling", default="optimize", choices=("optimize", "as-given"))
        digits = table.int("digits", default=4, min=1)
        table.done()
        nl = spec.tables.get("nonlinearity")
        if nl is None:
            raise SpecError(spec.file, "nonlinearity", "is missing (the data of Assumption 1)")
        if s.psi is None:
            raise SpecError(spec.file, "system.psi", "is missing (ẋ = A x + ψ(x), eq. (1a))")
        psi = s.psi
        data: BlockData | LipschitzX
        if nl.has("lipschitz_x"):
            if nl.has("o") or nl.has("n"):
                raise nl.error(
                    "lipschitz_x",
                    "give either lipschitz_x or the tables [nonlinearity.o] / [nonlinearity.n], not both",
                )
            data = LipschitzX(nl.scalar("lipschitz_x", min=0).q)
        else:
            if isinstance(Mv, str):
                raise table.error(
                    "M",
                    "per-block data ([nonlinearity.o], [nonlinearity.n]) are in the coordinates "
                    "z = T x, so M must be given as a matrix (or use nonlinearity.lipschitz_x)",
                )
            to, tn = nl.table("o", required=True), nl.table("n", required=True)
            assert to is not None and tn is not None
            q_o, l_on = _block(to, m, "o")
            q_n, l_no = _block(tn, n - m, "n")
            if not check_pd(-q_o.Q):
                raise to.error(
                    "Q" if to.has("Q") else "sector",
                    "expected Q_o negative definite (Lemma 2 needs Q_o ≺ 0)",
                )
            if not check_psd(-q_n.Q):
                raise tn.error(
                    "Q", "expected Q_n negative semidefinite (Assumption 1 needs Q_n ⪯ 0)"
                )
            data = BlockData(q_o, q_n, l_on, l_no)
        fz = None
        ft = nl.table("falsify")
        if ft is not None:
            lo, hi = ft.vector("lower", n=n), ft.vector("upper", n=n)
            if not all(lo.q[i] < hi.q[i] for i in range(n)):
                raise ft.error("upper", "expected lower < upper in every coordinate")
            fz = FalsifySpec(
                lo.f,
                hi.f,
                ft.int("samples", default=20000, min=10),
                ft.int("seed", default=0, min=0),
                ft.str("on_violation", default="fail", choices=("fail", "warn")),
            )
            ft.done()
        nl.done()
        prob = Problem(
            s.A.q, s.C.q, L, alpha, w_bar, Mv, data, kappa, scaling == "optimize", digits
        )
        return Options(prob, psi, fz)

    def parse_simulate(self, table: Table, spec: Spec) -> None:
        o: Options = spec.options
        o.runs = table.int("runs", default=20, min=1)
        if table.has("sampling_file"):
            p = Path(table.str("sampling_file"))
            o.sampling_file = p if p.is_absolute() else Path(spec.file).resolve().parent / p
        o.rtol = float(table.scalar("rtol", default=fmpq(1, 10**7), min=0, strict_min=True).f)

    # -- design -----------------------------------------------------------------------------
    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        o: Options = spec.options
        try:
            vals, notes = design_window(o.problem)
        except Infeasible as e:
            raise InfeasibleError(str(e)) from None
        params = Parameters(vals)
        if o.falsify is not None:
            fr = run_falsification(spec, params)
            params["falsification"] = fr.summary()
            if fr.violated and o.falsify.on_violation == "warn":
                notes.append(
                    f"WARNING: Assumption 1 as declared is violated on the falsification region — {fr.summary()}; "
                    f"literal reading (cross terms) sup ‖c_o‖/‖ε_n‖ = {fr.literal_cross.get('o', 0):.4g}, "
                    f"sup ‖c_n‖/‖ε_o‖ = {fr.literal_cross.get('n', 0):.4g}. The window is certified only "
                    "*given* the declared data."
                )
        return Design(
            params, {"name": "eigenvalue formulas + exact LDLᵀ", "status": "optimal"}, notes
        )

    # -- certificate ------------------------------------------------------------------------
    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        o: Options = spec.options
        missing = [k for k in PARAM_KEYS if k not in params or not _exactish(params[k])]
        if missing:
            return [
                numerical_claim(
                    "parameters",
                    "every parameter of the design is present and exact",
                    REF,
                    "presence",
                    0,
                    False,
                    f"missing or not exact: {', '.join(missing)}",
                )
            ]
        P = {k: params[k] for k in PARAM_KEYS}
        P["M_source"] = params.get("M_source", "given")
        claims = certify_window(o.problem, P)
        if o.falsify is not None and o.falsify.on_violation == "fail":
            fr = run_falsification(spec, params)
            claims.append(
                numerical_claim(
                    "assumption1-falsification",
                    "Assumption 1 (split reading) holds at every sampled pair of the region",
                    f"Assumption 1, eq. (15), {REF}",
                    f"sampling, {fr.samples} pairs (cannot prove, only falsify)",
                    0,
                    not fr.violated,
                    fr.summary(),
                )
            )
        return claims

    # -- simulation -------------------------------------------------------------------------
    def simulate(self, spec: Spec, params: Parameters, **kwargs: Any) -> Any:
        from obsdesign.methods.impulsive.sim import simulate_spec

        return simulate_spec(spec, params, **kwargs)

    def plot_simulation(self, spec: Spec, res: Any, path: str | Path) -> Path:
        from obsdesign.methods.impulsive.sim import plot_simulation

        return plot_simulation(spec, res, path)

    def summary(self, params: Parameters) -> str:
        return (
            f"T_min = {params.float('T_min'):.4g}, T_max = {params.float('T_max'):.4g}, "
            f"κ = {params.float('kappa'):.4g}, κ_n = {params.float('kappa_n'):.4g}, "
            f"ϖ_o = {params.float('varpi_o'):.4g}, r_B = {params.float('ball_radius'):.4g}"
        )

    def template(self) -> str:
        return TEMPLATE

    def options_schema(self) -> dict[str, Any]:
        from obsdesign.spec.schema import MAT as mat
        from obsdesign.spec.schema import NUM as num

        return {
            "type": "object",
            "required": ["key", "L", "alpha", "noise_bound"],
            "additionalProperties": False,
            "properties": {
                "key": {"const": self.key},
                "L": mat,
                "alpha": {**num, "exclusiveMinimum": 0},
                "noise_bound": {**num, "minimum": 0},
                "M": {"anyOf": [mat, {"enum": ["orthonormal", "optimize"]}]},
                "kappa": {"anyOf": [{**num, "exclusiveMinimum": 0}, {"enum": ["max", "widest"]}]},
                "qsr_scaling": {"enum": ["optimize", "as-given"]},
                "digits": {"type": "integer", "minimum": 1},
            },
        }


def _exactish(v: Any) -> bool:
    return isinstance(v, fmpq) or (isinstance(v, np.ndarray) and v.dtype == object)


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
                f"expected every eigenvalue of I − L in (0, 1), i.e. 0 < L_ii < 1; L[{i}] = {float(v):g}",
            )
    return np.asarray(d, dtype=object)


def _block(t: Table, k: int, which: str) -> tuple[QSR, fmpq]:
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


def run_falsification(spec: Spec, params: Parameters) -> Falsification:
    """Falsification pass of (15) on the spec's region with the design's T (numerical)."""
    o: Options = spec.options
    fz = o.falsify
    assert fz is not None
    psi = psi_callable(spec)
    if isinstance(o.problem.data, LipschitzX):
        return falsify_lipschitz_x(
            psi, float(o.problem.data.ell), fz.lower, fz.upper, fz.samples, fz.seed
        )
    d = o.problem.data
    T = np.asarray(to_float(np.asarray(params["T"], dtype=object)), dtype=float)
    return falsify_blocks(
        psi,
        T,
        o.problem.m,
        d.qsr_o.floats(),
        d.qsr_n.floats(),
        float(d.ell_on),
        float(d.ell_no),
        fz.lower,
        fz.upper,
        fz.samples,
        fz.seed,
    )


def psi_callable(spec: Spec) -> Any:
    """ψ as a vectorized map (N, n) → (N, n) from the spec's expressions."""
    o: Options = spec.options
    fs = [e.on(spec.system.states) for e in o.psi]

    def psi(X: np.ndarray) -> np.ndarray:
        return np.stack([f(X) for f in fs], axis=-1)

    return psi


def plant_field(spec: Spec) -> Any:
    """f(x) = A x + ψ(x), vectorized (eq. (1a))."""
    A = spec.system.A.f
    psi = psi_callable(spec)
    return lambda X: X @ A.T + psi(X)


METHOD = Impulsive()

TEMPLATE = """title = "Impulsive dissipative observer (paper 001)"

[system]
time = "continuous"
A = [[0, 0], [3, -1]]          # ẋ = A x + ψ(x)
C = [[1, 0]]                   # y_k = C x(t_k) + w_k, rank C = m < n
states = ["x1", "x2"]
psi = ["x1*x2*(x2^2 - a^2)/(1 + x2^4)", "0"]   # ẋ = A x + ψ(x), safe expression language
[system.parameters]
a = 2

[nonlinearity]
# Data of Assumption 1 (15): either a Lipschitz constant of ψ in x (then M may be optimized) ...
# lipschitz_x = 0.1
# ... or per block in z = T x (split reading: own part QSR + cross Lipschitz constant):
[nonlinearity.o]
sector = [-1.9822152, 1.9822152]   # or lipschitz = ℓ, or Q = .., S = .., R = ..
cross = 0                          # ℓ_on: ‖c_o‖ ≤ ℓ_on ‖ε_n‖
[nonlinearity.n]
lipschitz = 0
cross = 0                          # ℓ_no
[nonlinearity.falsify]             # optional numerical falsification of (15)
lower = [-1.5, -3]
upper = [1.5, 3]
samples = 20000
on_violation = "warn"              # "fail": a violation fails the design

[method]
key = "impulsive"
L = [0.8]            # diagonal correction gain, 0 < L_ii < 1
alpha = 3            # ISS gain, α > γ
noise_bound = 0.1    # ‖w‖∞
M = [[-3, 1]]        # or "orthonormal" / "optimize" (lipschitz_x data only)
kappa = "max"        # or "widest" or a number in (0, κ_max)

[simulate]
horizon = 60
x0 = [1, 1]
xhat0 = [0, 0.5]
runs = 20
seed = 1
[simulate.noise]
kind = "uniform"
bound = 0.1
"""
