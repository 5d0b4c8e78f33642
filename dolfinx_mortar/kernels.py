"""The C++ kernels, as Python sees them.

Facet geometry (shape functions, normals, bounding boxes), segmentation and
the mortar integrals, and the per-element basis coefficients: array in, array
out, no DOLFINx. The Python layers above call these; they are public so that a
user (and the tests) can check a kernel on its own. The compiled module is
``dolfinx_mortar._kernels``; this module is its documented name.
"""
from dolfinx_mortar import _kernels

__all__ = [name for name in dir(_kernels) if not name.startswith("_")]
globals().update({name: getattr(_kernels, name) for name in __all__})
