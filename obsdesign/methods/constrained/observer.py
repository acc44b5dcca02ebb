"""The modified observer (8)-(10) with the refining map (23), constrained-redesign paper (000).

At each sample: x̂_{k,1} = F(x̂_k, u_k, y_k) (eq. (8)); then at most θ_m refining steps
x̂_{k,i+1} = G(x̂_{k,i}) (eq. (10)) with

    G(x̂) = x̂ + M(x̂)  if x̂ ∈ C_max \\ C_min,   x̂ otherwise            (23)
    M(x̂) = −γ P⁻¹ (dc/dx)(x̂)ᵀ c(x̂)                                    (20)

and x̂_{k+1} = the last iterate (eq. (9)). Once G is the identity it stays so, hence the loop
stops there: the number of steps used per sample is recorded (Fig. 3b). Outside C_max the
paper's G is the identity (this is the literal reading of (23); with a γ that satisfies (24)
the iterates never leave X̂_max ⊆ C_max, Lemma 3). The naive saturated observer (29),
x̂⁺ = sat_r(F(x̂)), is here for comparison.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from obsdesign.methods.constrained.cmap import ConstraintMap


@dataclass
class LinearF:
    """F of eq. (2) for the linear observer x̂⁺ = A x̂ + B u + L (y − C x̂ − D u)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    L: np.ndarray

    def __call__(self, xh: np.ndarray, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Vectorized over leading axes of ``xh``, ``u``, ``y``."""
        innov = y - xh @ self.C.T - u @ self.D.T
        return xh @ self.A.T + u @ self.B.T + innov @ self.L.T


@dataclass
class Refiner:
    """The refining map G of eq. (23) with M of eq. (20) (floats, vectorized)."""

    cm: ConstraintMap
    Pinv: np.ndarray
    gamma: float
    eps_min: float
    eps_max: float

    def active(self, xh: np.ndarray) -> np.ndarray:
        """x̂ ∈ C_max \\ C_min, i.e. ε_min < |c(x̂)| ≤ ε_max (eq. (16), (23))."""
        nc = self.cm.norm_c(xh)
        return (nc > self.eps_min) & (nc <= self.eps_max)

    def M(self, xh: np.ndarray) -> np.ndarray:
        """M(x̂) = −γ P⁻¹ (dc/dx)ᵀ c, eq. (20)."""
        return -self.gamma * (self.cm.jtc(xh) @ self.Pinv.T)

    def G(self, xh: np.ndarray) -> np.ndarray:
        """G of eq. (23) for one point or a batch (rows)."""
        act = self.active(xh)
        return np.where(act[..., None], xh + self.M(xh), xh)

    def refine(
        self, xh: np.ndarray, theta_m: int, path: PathLog | list[np.ndarray] | None = None
    ) -> tuple[np.ndarray, int]:
        """Apply G at most θ_m times to one point; stop when G is the identity.

        Returns the refined point and the number of steps used; appends each new iterate
        x̂_{k,i}, i ≥ 2, to ``path`` when given. (Affine maps take a fused fast path: φ is
        computed once per step for both the membership test and M.)
        """
        steps = 0
        x = np.asarray(xh, dtype=float)
        cm = self.cm
        if cm.affine:
            G, h, Pg = cm.G, cm.h, self.gamma * self.Pinv
            lo2, hi2 = self.eps_min**2, self.eps_max**2
            while steps < theta_m:
                p = G @ x - h
                np.maximum(p, 0.0, out=p)
                p2 = p * p
                # numpy's square: a plant past 1e77 made Python's float power raise
                # OverflowError, exit 4 "too large", where the Euclidean norm gives inf and
                # stops the refinement (census 46)
                with np.errstate(over="ignore"):
                    nc2 = float(np.square(p2.max()) if cm.norm == "max" else p2 @ p2)
                if not (lo2 < nc2 <= hi2):
                    break
                x = x - Pg @ (G.T @ (2.0 * p2 * p))
                steps += 1
                if _record(path, x):
                    break
            return x, steps
        while steps < theta_m and bool(self.active(x)):
            x = x + self.M(x)
            steps += 1
            if _record(path, x):
                break
        return x, steps

    def refine_batch(
        self, X: np.ndarray, theta_m: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Vectorized :meth:`refine` over rows of X (B, n).

        Returns (refined X, steps per row, sup over the iterates of |x̂| per row and state).
        """
        X = X.copy()
        steps = np.zeros(len(X), dtype=np.int64)
        sup = np.abs(X)
        idx = np.arange(len(X))
        for _ in range(int(min(theta_m, np.iinfo(np.int64).max))):
            act = self.active(X[idx])
            idx = idx[act]
            if idx.size == 0:
                break
            X[idx] = X[idx] + self.M(X[idx])
            steps[idx] += 1
            sup[idx] = np.maximum(sup[idx], np.abs(X[idx]))
        return X, steps, sup


def sat(x: np.ndarray, r: np.ndarray | float) -> np.ndarray:
    """sat_r componentwise, the saturation of eq. (29)."""
    r = np.asarray(r, dtype=float)
    return np.clip(x, -r, r)


#: iterates x̂_{k,i} kept per observer (for the path of Fig. 3c); past them only the running
#: sup and the largest V increase are kept (θ_m = 10⁷ kept every iterate: gigabytes)
MAX_KEPT_ITERATES = 200_000
#: the time budget is looked at every this many refining steps (and samples)
CHECK_EVERY = 4096


@dataclass
class PathLog:
    """What one observer run keeps of its iterates x̂_{k,1}, x̂_{k,2}, … (eq. (8)-(10),
    constrained-redesign paper): the first :data:`MAX_KEPT_ITERATES` of them, the running sup
    of |x̂_{k,i}| over all of them (Table 1), and the largest relative increase of
    V(x̂_{k,i} − x_{k+1}) over a refining step (Lemma 3 says it is ≤ 0) when the plant's
    x_{k+1} and P are given. ``check`` (the time budget) is called every
    :data:`CHECK_EVERY` iterates."""

    n: int
    x_next: np.ndarray | None = None
    P: np.ndarray | None = None
    check: Callable[[], None] | None = None
    kept: list[list[np.ndarray]] = field(default_factory=list)
    count: int = 0
    sup: np.ndarray = field(default_factory=lambda: np.zeros(0))
    worst: float = -np.inf
    truncated: bool = False
    _V: float | None = None
    _k: int = 0

    def __post_init__(self) -> None:
        self.sup = np.zeros(self.n)

    def start(self, k: int, x1: np.ndarray) -> None:
        """Sample k begins at x̂_{k,1} = F(x̂_k, u_k, y_k), eq. (8)."""
        self._k = k
        self._V = None
        self.kept.append([])
        self.append(x1)

    def append(self, x: np.ndarray) -> None:
        """The next iterate x̂_{k,i} of sample k (eq. (10))."""
        self.sup = np.maximum(self.sup, np.abs(x))
        if self.count < MAX_KEPT_ITERATES:
            self.kept[-1].append(x)
        else:
            self.truncated = True
        self.count += 1
        if self.x_next is not None and self.P is not None:
            e = x - self.x_next[self._k + 1]
            with np.errstate(over="ignore", invalid="ignore"):
                V = float(e @ self.P @ e)
                if self._V is not None:
                    inc = (V - self._V) / max(self._V, 1e-300)
                    self.worst = max(self.worst, inc) if np.isfinite(inc) else np.inf
            self._V = V
        if self.check is not None and self.count % CHECK_EVERY == 0:
            self.check()


@dataclass
class Trace:
    """One observer run: estimates x̂_k (N+1, n), the iterates x̂_{k,i} per sample (the first
    :data:`MAX_KEPT_ITERATES`; ``truncated`` when more were made), steps per sample, the sup
    of |x̂_{k,i}| over every iterate and the largest V increase over a refining step
    (−inf when none was measured)."""

    xhat: np.ndarray
    iterates: list[list[np.ndarray]]
    steps: np.ndarray
    sup_iterates: np.ndarray | None = None
    v_increase: float = -np.inf
    truncated: bool = False
    #: whether the budget θ_m stopped a refining that G would have continued at some sample
    #: (the point still in C_max \ C_min after θ_m steps; θ_m = 0 included)
    cut: bool = False

    def sup_k(self) -> np.ndarray:
        """sup over k of |x̂_k^i| per component (Table 1, first row of each block)."""
        return np.max(np.abs(self.xhat), axis=0)

    def sup_ki(self) -> np.ndarray:
        """sup over (k, i) of |x̂_{k,i}^j|: x̂_k and every intermediate iterate (Table 1)."""
        if self.sup_iterates is not None:
            return np.maximum(self.sup_k(), self.sup_iterates)
        pts = [self.xhat] + [np.array(p) for p in self.iterates if p]
        return np.max(np.abs(np.vstack(pts)), axis=0)


@dataclass(frozen=True)
class Observer:
    """One observer of the comparison: x̂_{k,1} = F(x̂_k, u_k, y_k) (eq. (2) / (8)); with a
    ``refiner`` and θ_m > 0, at most θ_m refining steps G of eq. (23) (the modified observer
    (8)-(10)); with ``sat_r``, x̂_{k+1} = sat_r(·) (the saturated observer (29)). Without
    either it is the unmodified observer (2)."""

    F: LinearF
    refiner: Refiner | None = None
    theta_m: int = 0
    sat_r: np.ndarray | float | None = None

    def run(
        self,
        u: np.ndarray,
        y: np.ndarray,
        xhat0: np.ndarray,
        x: np.ndarray | None = None,
        P: np.ndarray | None = None,
        check: Callable[[int, int], None] | None = None,
    ) -> Trace:
        """One trajectory: inputs and outputs in rows k = 0..N; the estimate has N+1 rows
        (x̂_0 … x̂_N); the iterates x̂_{k,i} are kept as :class:`PathLog` keeps them, the steps
        per sample all. With the plant's states ``x`` and P, the largest V increase over a
        refining step is measured (Lemma 3); ``check(k, N)`` (the time budget) is called every
        :data:`CHECK_EVERY` samples and refining steps."""
        N = len(y) - 1
        n = len(xhat0)
        xh = np.zeros((N + 1, n))
        xh[0] = xhat0
        k = 0
        log = PathLog(n, x, P, None if check is None else (lambda: check(k, N)))
        steps = np.zeros(N, dtype=np.int64)
        cut = False
        for k in range(N):
            if check is not None and k % CHECK_EVERY == 0:
                check(k, N)
            x1 = self.F(xh[k], u[k], y[k])
            log.start(k, x1)
            if self.refiner is not None and self.theta_m > 0:
                x1, steps[k] = self.refiner.refine(x1, self.theta_m, log)
            if self.refiner is not None and not cut and steps[k] >= self.theta_m:
                cut = bool(np.all(np.isfinite(x1))) and bool(self.refiner.active(x1))
            if self.sat_r is not None:
                x1 = sat(x1, self.sat_r)
            xh[k + 1] = x1
        return Trace(xh, log.kept, steps, log.sup, log.worst, log.truncated, cut)

    def run_batch(
        self, U: np.ndarray, Y: np.ndarray, Xh0: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """A batch of trajectories at once: ``U`` (B, N+1, m), ``Y`` (B, N+1, p), ``Xh0``
        (B, n). Returns the estimates (B, N+1, n) and the steps used (B, N). Each sample is one
        vectorized F and at most θ_m vectorized refining passes over the rows still in
        C_max \\ C_min."""
        Bn, N1 = Y.shape[0], Y.shape[1]
        n = Xh0.shape[1]
        out = np.empty((Bn, N1, n))
        out[:, 0] = Xh0
        steps = np.zeros((Bn, N1 - 1), dtype=np.int64)
        for k in range(N1 - 1):
            x1 = self.F(out[:, k], U[:, k], Y[:, k])
            if self.refiner is not None and self.theta_m > 0:
                x1, steps[:, k], _ = self.refiner.refine_batch(x1, self.theta_m)
            if self.sat_r is not None:
                x1 = sat(x1, self.sat_r)
            out[:, k + 1] = x1
        return out, steps


def _record(path: PathLog | list | None, x: np.ndarray) -> bool:
    """Append the iterate x̂_{k,i} to ``path`` (when kept); True when it is no longer finite
    (the refining loop then stops)."""
    if path is not None:
        path.append(x)
    return not bool(np.all(np.isfinite(x)))
