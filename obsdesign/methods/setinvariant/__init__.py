"""Set-invariant estimators (Dórea & Pimenta, "Design of set-invariant estimators for linear
discrete-time systems"): method key ``set-invariant``.

Modules: :mod:`.method` (the facade), :mod:`.options` (``[method]``), :mod:`.design`
(iterations → exact parameters), :mod:`.claims` (one claim table, exact and float backends),
:mod:`.lps` (LPs of Section III), :mod:`.algorithms` (Sections V and VI),
:mod:`.certificate` (exact Theorem 3.1 and linear-law checks), :mod:`.numerical` (float64
counterparts without cdd.gmp), :mod:`.linear` (Proposition 7.1 and the admissible set of
linear gains), :mod:`.laws` (injection laws of Section IV and the runtime observer),
:mod:`.problem` (spec → data), :mod:`.sim` and :mod:`.plots` (simulation and figures).
"""

from obsdesign.methods.setinvariant.method import METHOD

__all__ = ["METHOD"]
