"""Spec text of a set-invariant problem built from matrices (for scripts, tests and benchmarks).

The setting is the paper's own test (Section VII, Dórea & Pimenta, "Design of set-invariant
estimators for linear discrete-time systems"): a discrete-time plant e⁺ = A e + B1 d with
one scalar disturbance |d| <= ``bound``, the error set Ω = {|e|∞ <= 1}, measurement noise
|η| <= η̄ and contraction rate λ.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def matrix_text(M: np.ndarray | Sequence[Sequence[float]]) -> str:
    """A matrix as a TOML array of rows, each entry ``repr(float(x))`` (round-trips exactly).

    Args:
        M: a matrix (a vector is read as one row).

    Returns:
        For example ``"[[0.7, 0.7], [-0.7, 0.7]]"``.
    """
    rows = np.atleast_2d(np.asarray(M, dtype=float))
    return "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in r) + "]" for r in rows) + "]"


def _row_text(v: Sequence[float]) -> str:
    """A vector as a TOML array, each entry ``repr(float(x))``."""
    return "[" + ", ".join(repr(float(x)) for x in v) + "]"


def _value_text(v: object) -> str:
    """A TOML value: bool → true/false, str → quoted, int as is, other numbers ``repr(float)``."""
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    return repr(float(v))  # type: ignore[arg-type]


def spec_text(
    A: np.ndarray,
    B1: np.ndarray,
    C: np.ndarray,
    lam: float,
    bound: float = 1,
    eta_bar: float | None = 0.01,
    omega: tuple[Sequence[float], Sequence[float]] | None = None,
    **method_keys: object,
) -> str:
    """The TOML spec of a set-invariant design for the plant (A, B1, C).

    Ω is the box [-1, 1]ⁿ (or ``omega``), the disturbance set D = [-bound, bound] (one disturbance through
    the column B1), λ the contraction rate of eq. (5) and η̄ the noise bound of eq. (2).

    Args:
        A: the n×n state matrix.
        B1: the n×1 disturbance column (any shape with n entries).
        C: the p×n output matrix.
        lam: λ in (0, 1), written as ``lambda = <lam>``.
        bound: the disturbance bound (D = [-bound, bound]).
        eta_bar: η̄ (``None`` leaves ``eta_bar`` out: no noise).
        omega: Ω's box as (lower, upper) bounds; default [-1, 1]ⁿ.
        **method_keys: further ``[method]`` keys in order, e.g. ``algorithm="general",
            mirror=True, delta_tol=0.001, max_iterations=60`` (bool → true/false, str →
            quoted, numbers by ``repr``).

    Returns:
        The spec text, ready for :func:`obsdesign.api.load_spec_text`.
    """
    n = np.asarray(A).shape[0]
    b1 = ", ".join(repr(float(v)) for v in np.asarray(B1, dtype=float).reshape(-1))
    lines = [
        "[system]",
        'time = "discrete"',
        f"A = {matrix_text(A)}",
        f"B1 = [{b1}]",
        f"C = {matrix_text(C)}",
        "[sets.omega]",
        'type = "box"',
        f"lower = {_row_text(omega[0] if omega else [-1.0] * n)}",
        f"upper = {_row_text(omega[1] if omega else [1.0] * n)}",
        "[sets.D]",
        'type = "box"',
        "dim = 1",
        f"lower = [{_value_text(-bound)}]",
        f"upper = [{_value_text(bound)}]",
        "[method]",
        'key = "set-invariant"',
        'omega = "omega"',
        'disturbance = "D"',
    ]
    if eta_bar is not None:
        lines.append(f"eta_bar = {_value_text(eta_bar)}")
    lines.append(f"lambda = {_value_text(lam)}")
    lines += [f"{k} = {_value_text(v)}" for k, v in method_keys.items()]
    return "\n".join(lines) + "\n"
