"""Impulsive dissipative observer (method key ``impulsive``), impulsive-dissipativity paper.

Schaum, Feketa, Meurer, Moreno, "Robust nonlinear observer design based on impulsive
dissipativity" (MTNS 2020). One job per module:

- :mod:`.coordinates`   T = [C; M], Ā = T A T⁻¹ and its blocks (eqs. (9)-(10c));
- :mod:`.dissipativity` QSR data (Assumption 1, split reading), ssd LMI, κ_n and ϖ_o;
- :mod:`.window`        γ, β, (22), T_max (26b), T_min (26c), radius of B, safe rounding;
- :mod:`.core`          the problem data (what the spec fixes) and the derived block data;
- :mod:`.options`       ``[method]``, ``[nonlinearity]`` and ``[simulate]`` keys;
- :mod:`.design`        the design pipeline (floats choose, exact values are reported);
- :mod:`.claims`        the certificate, rebuilt from spec + exact parameters;
- :mod:`.plant`         ẋ = A x + ψ(x) from ``[system] psi``;
- :mod:`.falsify`       numerical falsification of (15) on a region;
- :mod:`.hybrid`        the hybrid observer (11) on many sampling sequences at once;
- :mod:`.sim`           the simulation scenarios and plots;
- :mod:`.method`        the facade (the Method object and its declarations).
"""

from obsdesign.methods.impulsive.method import METHOD, Impulsive

__all__ = ["METHOD", "Impulsive"]
