"""Convex sets used by specs: Box, Polytope (H-form G x <= g), SymmetricPolytope
(|Q x| <= 1), Ellipsoid ((x-c)' E (x-c) <= 1). Exact data (fmpq) and float views."""

from obsdesign.sets.base import ConvexSet
from obsdesign.sets.box import Box
from obsdesign.sets.ellipsoid import Ellipsoid
from obsdesign.sets.polytope import Polytope, SymmetricPolytope, vertices_exact, vertices_float

__all__ = [
    "Box",
    "ConvexSet",
    "Ellipsoid",
    "Polytope",
    "SymmetricPolytope",
    "vertices_exact",
    "vertices_float",
]
