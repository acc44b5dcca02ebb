"""Exact work done once per process (issue 12 item 2): the design stage's exact hull and its
Theorem 3.1 result (Dórea & Pimenta, "Design of set-invariant estimators for linear
discrete-time systems", CDC-ECC 2005, Section III and Theorem 3.1) handed to ``certify``.

``api.design`` certifies the very :class:`~obsdesign.params.Parameters` object the design
returned. The design records what it proved exactly, keyed by the *exact inputs* of each
check (the exact problem built from the spec: A, B1, C, Ω, D, η̄, λ; and the reported G, V,
breakpoints, v^l), and attaches the record to that object (by identity, through a weak
reference). ``certify`` looks a check up only for the same object and the same exact inputs:

* any other object (a report read from JSON, ``api.verify``'s tracked copy, a new process)
  finds nothing and recomputes everything;
* a parameter changed after the design (the same object, tampered) changes the key, so the
  lookup misses and the check is recomputed from the tampered value.

A recorded value is what the check returns on those inputs: ``forms`` is the outcome of
:func:`~obsdesign.sets.polytope_ops.exact_check_forms` (the design's last
:func:`~obsdesign.sets.polytope_ops.exact_hull` ran on exactly the reported vertices and
found every one extreme, with the reported rows as its canonical facets), ``theorem31`` the
exact maximum over Z_d and the rows of φ_i(z^l) + G_i v^l + δ_i for the reported v^l.
"""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np
from flint import fmpq

#: id(params) → (weak reference to params, {(kind, key): value})
_MEMO: dict[int, tuple[weakref.ref, dict[tuple, Any]]] = {}
#: lookups that found a recorded value (for tests and benchmarks)
STATS = {"hits": 0, "misses": 0}


def _value(x: Any) -> Any:
    """An exact, cheaply hashed stand-in for one value: an fmpq by its numerator and
    denominator (fmpz hash in C; hashing an fmpq itself goes through Fraction, ~7 µs), other
    values by type and value (by text when unhashable)."""
    if isinstance(x, fmpq):
        return (x.p, x.q)
    try:
        hash(x)
    except TypeError:
        return (type(x).__name__, str(x))
    return (type(x).__name__, x)


def fingerprint(*parts: Any) -> tuple:
    """A hashable key equal only for exactly equal inputs: arrays by shape, dtype and every
    entry (:func:`_value`: exact values, with the types keeping 1, 1.0 and fmpq(1) apart),
    lists and tuples element by element, other values likewise."""
    out: list[Any] = []
    for x in parts:
        if isinstance(x, np.ndarray):
            out.append(("a", x.shape, str(x.dtype), tuple(map(_value, x.reshape(-1).tolist()))))
        elif isinstance(x, (list, tuple)):
            out.append(("l", fingerprint(*x)))
        else:
            out.append(_value(x))
    return tuple(out)


def problem_key(ex: Any) -> tuple:
    """The exact problem's data (everything a check reads from the spec)."""
    return fingerprint(ex.A, ex.B1, ex.C, ex.G0, ex.Vo, ex.Dv, ex.eta, ex.lam)


class Recorder:
    """What one design proved, before its Parameters object exists."""

    def __init__(self) -> None:
        self.entries: dict[tuple, Any] = {}

    def put(self, kind: str, key: tuple, value: Any) -> None:
        """Record the value of check ``kind`` on the exact inputs ``key``."""
        self.entries[(kind, key)] = value


def attach(params: Any, rec: Recorder) -> None:
    """Hand the record to ``params`` (the object the design returns); dropped with it."""
    i = id(params)
    _MEMO[i] = (weakref.ref(params, lambda _r, i=i: _MEMO.pop(i, None)), dict(rec.entries))


def recall(params: Any, kind: str, key: tuple) -> Any | None:
    """The recorded value of check ``kind`` on ``key`` for this very ``params`` object, or
    None (then the caller computes it)."""
    ent = _MEMO.get(id(params))
    if ent is None or ent[0]() is not params:
        STATS["misses"] += 1
        return None
    v = ent[1].get((kind, key))
    STATS["hits" if v is not None else "misses"] += 1
    return v


def clear() -> None:
    """Forget every record (tests)."""
    _MEMO.clear()
