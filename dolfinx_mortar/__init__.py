"""dolfinx_mortar: penalty mortar contact for FEniCSx.

The six mortar bases for the contact pressure of Duong, De Lorenzis and Sauer
(GLS, GLS*, LmLS, LmLS*, LcLS*, LcLS) on B-spline/NURBS and Lagrange slave
surfaces; see DESIGN.md for the mathematics.
"""
from dolfinx_mortar import basis, kinds, lagrange, nurbs
from dolfinx_mortar.basis import MortarBasis
from dolfinx_mortar.kinds import KIND_NAMES, parse_kind

__all__ = ["basis", "kinds", "lagrange", "nurbs", "MortarBasis", "KIND_NAMES",
           "parse_kind"]
__version__ = "0.1.0"
