"""Set-invariant estimators (Dórea & Pimenta, paper 003): method key ``set-invariant``.

Modules: :mod:`.lps` (LPs of Section III), :mod:`.algorithms` (Sections V and VI),
:mod:`.certificate` (exact Theorem 3.1 and linear-law checks), :mod:`.linear` (Proposition
7.1 and the admissible set of linear gains), :mod:`.laws` (injection laws of Section IV and
the runtime observer), :mod:`.problem` (spec → data), :mod:`.method` (the Method object),
:mod:`.sim` and :mod:`.plots` (simulation and figures).
"""

from obsdesign.methods.setinvariant.method import METHOD

__all__ = ["METHOD"]
