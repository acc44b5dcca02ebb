"""Impulsive dissipative observer (method key ``impulsive``), impulsive-dissipativity paper (001).

Schaum, Feketa, Meurer, Moreno, "Robust nonlinear observer design based on impulsive
dissipativity" (MTNS 2020). One job per module:

- :mod:`.coordinates`   T = [C; M], Ā = T A T⁻¹ and its blocks (eqs. (9)-(10c));
- :mod:`.dissipativity` QSR data (Assumption 1, split reading), ssd LMI, κ_n and ϖ_o;
- :mod:`.window`        γ, β, (22), T_max (26b), T_min (26c), radius of B, safe rounding;
- :mod:`.core`          the design pipeline and the certificate;
- :mod:`.falsify`       numerical falsification of (15) on a region;
- :mod:`.hybrid`        the hybrid observer (11) on many sampling sequences at once;
- :mod:`.method`        the spec section, the Method object, simulation and plots.
"""

from obsdesign.methods.impulsive.method import METHOD, Impulsive

__all__ = ["METHOD", "Impulsive"]
