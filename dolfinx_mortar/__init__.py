"""dolfinx_mortar: penalty mortar contact for FEniCSx.

The six mortar bases for the contact pressure of Duong, De Lorenzis and Sauer
(GLS, GLS*, LmLS, LmLS*, LcLS*, LcLS) on B-spline/NURBS and Lagrange slave
surfaces; see docs/DESIGN.md for the mathematics.

Subpackages, one per layer of the Python library:

- :mod:`~dolfinx_mortar.surfaces`: slave and master surfaces (Lagrange, NURBS,
  DOLFINx facets);
- :mod:`~dolfinx_mortar.bases`: the six mortar bases;
- :mod:`~dolfinx_mortar.mortar`: segmentation and mortar operators;
- :mod:`~dolfinx_mortar.contact`: gap models, rigid obstacles and the contact
  term that adds penalty contact to a DOLFINx model;
- :mod:`~dolfinx_mortar.solver`: the nonlinear problem, Newton and the load path;
- :mod:`~dolfinx_mortar.linalg`: the linear solver's choice, the contact block
  preconditioner, the near-nullspace, sparse products;
- :mod:`~dolfinx_mortar.small_strain`: linear elasticity (plane, 3D,
  axisymmetric) and ``ContactProblem``, the short path;
- :mod:`~dolfinx_mortar.meshes`: merging two bodies' meshes, the contact partitioner;
- :mod:`~dolfinx_mortar.io`: XDMF series, gmsh, result files;
- :mod:`~dolfinx_mortar.kernels`: the C++ kernels (facet geometry,
  segmentation, mortar integrals, basis coefficients).

The names that need DOLFINx (``ContactTerm``, ``NonlinearContactProblem``,
``LoadPathSolver``, ``ContactProblem``, the obstacles) are imported on first
use, so that the bases and kernels work without it.
"""
from importlib import import_module
from importlib.metadata import PackageNotFoundError, version


def _package_version() -> str:
    # the one version string is the package metadata's (pyproject.toml)
    try:
        return version("dolfinx_mortar")
    except PackageNotFoundError:      # a source tree that was never installed
        return "unknown"


# first: a missing compiled module is explained here (an install, or the source tree on sys.path)
from dolfinx_mortar import kernels as _kernels_check  # noqa: F401
from dolfinx_mortar import kinds
from dolfinx_mortar.bases import basis
from dolfinx_mortar.bases.basis import MortarBasis
from dolfinx_mortar.collective_warnings import ContactWarning
from dolfinx_mortar.errors import DegenerateGeometryError
from dolfinx_mortar.kinds import KIND_NAMES, parse_kind
from dolfinx_mortar.surfaces import lagrange, nurbs

_LAZY = {
    "ContactTerm": "dolfinx_mortar.contact.term",
    "NonlinearContactProblem": "dolfinx_mortar.solver",
    "reaction_force": "dolfinx_mortar.solver",
    "NewtonSolver": "dolfinx_mortar.solver",
    "LoadPathSolver": "dolfinx_mortar.solver",
    "read_xdmf_series": "dolfinx_mortar.io.read_series",
    "ContactProblem": "dolfinx_mortar.small_strain.elastic",
    "ContactDivergenceError": "dolfinx_mortar.solver",
    "RigidPlane": "dolfinx_mortar.contact.obstacles",
    "RigidSphere": "dolfinx_mortar.contact.obstacles",
    "RigidCylinder": "dolfinx_mortar.contact.obstacles",
    "SurfacePressure": "dolfinx_mortar.contact.results",
    "SurfaceFriction": "dolfinx_mortar.contact.results",
    "CoulombFriction": "dolfinx_mortar.contact.laws",
}

__all__ = ["basis", "kinds", "lagrange", "nurbs", "MortarBasis", "KIND_NAMES",
           "parse_kind", "DegenerateGeometryError", "ContactWarning", *_LAZY]
__version__ = _package_version()


def __getattr__(name: str):
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'dolfinx_mortar' has no attribute '{name}'")


def __dir__() -> list[str]:
    # the lazily imported names too: dir(dolfinx_mortar) shows what the package offers
    return sorted(set(globals()) | set(__all__))
