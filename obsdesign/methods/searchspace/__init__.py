"""Search-space (discarding) observers for Lipschitz systems with open-loop inputs (paper 004:
Hernández & García, "An alternative approach to the state observation problem for Lipschitz
continuous systems with controls").

- :mod:`.intervals` outward-rounded intervals with Clarke-gradient enclosures on expressions;
- :mod:`.bounds`    L_f^E, L_h^E, ‖f_u‖_E by branch and bound; the input-range check;
- :mod:`.options`   ``[method]`` / ``[simulate]`` keys; :mod:`.design` the parameter rules;
- :mod:`.claims`    the certificate; :mod:`.sim` the vectorized ε-γ observer;
- :mod:`.plots`     Figs. 3-5; :mod:`.method` the Method object.
"""

from obsdesign.methods.searchspace.method import METHOD

__all__ = ["METHOD"]
