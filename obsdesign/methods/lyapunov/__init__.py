"""The ``lyapunov`` method (a linear observer with a certified quadratic Lyapunov function).

- :mod:`.options` the ``[method]`` keys; :mod:`.design` gain, P, best rate, μ;
- :mod:`.claims` the certificate; :mod:`.method` the Method object; ``template.toml``.

The Lyapunov maths itself is shared, in :mod:`obsdesign.lyap`.
"""

from obsdesign.methods.lyapunov.method import METHOD

__all__ = ["METHOD"]
