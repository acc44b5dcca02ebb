"""Exact certificate kernel: rationals, exact PSD tests, outward-rounded bounds, claims.

Everything a report calls *certified* is decided here, in exact rational arithmetic
(python-flint ``fmpq``) or in interval arithmetic with outward rounding (mpmath ``iv`` for
arithmetic and √, python-flint ``arb`` for exp and log).
"""

from obsdesign.certify.claim import Claim, ClaimStatus
from obsdesign.certify.exact import Q, dyadic, qmat, qstr, qvec, to_float
from obsdesign.certify.psd import PSDResult, check_pd, check_psd, ldl_pivots

__all__ = [
    "Claim",
    "ClaimStatus",
    "PSDResult",
    "Q",
    "check_pd",
    "check_psd",
    "dyadic",
    "ldl_pivots",
    "qmat",
    "qstr",
    "qvec",
    "to_float",
]
