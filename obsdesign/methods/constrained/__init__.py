"""Constrained-estimate redesign (paper 000): small one-job modules.

- :mod:`.cmap`     the constraint maps c of Assumption 3 (box (19), ellipsoid (18), polytope);
- :mod:`.lyap`     Assumption 2: P (from the ``lyapunov`` method), ρ, μ, the ISS inequality (5);
- :mod:`.bounds`   v_max (13), v_min (21), ε_max, δ, γ (24), θ (22), exact or safe;
- :mod:`.design`   the design pipeline; :mod:`.claims` the certificate;
- :mod:`.observer` the runtime F, M (20), G (23), θ_m budget, saturation (29);
- :mod:`.sim`      simulation hooks (Table 1, Fig. 3); :mod:`.method` the Method object.
"""

from obsdesign.methods.constrained.method import METHOD

__all__ = ["METHOD"]
