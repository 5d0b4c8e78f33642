"""The geometric tolerance, in one place for the kernels and the Python layer.

Every decision "is this length, area or distance zero?" is taken against
``GEOMETRIC_TOLERANCE × length scale``, where the length scale is the
geometry's own extent, its bounding-box diagonal (docs/DESIGN.md,
§Tolerances). It does not grow with the distance from the origin: the
kernels take every decision in coordinates relative to a local origin (a
cell's first node), where round-off is a few 1e-16 of the cells' size, so a
scene shifted far from the origin keeps its decisions. A computed float is
never compared with exact zero or with a tolerance relative to itself. The
constant is the C++ kernels' own
(``kernels/include/dolfinx_mortar/geometric_tolerance.h``).
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar import _kernels

#: relative tolerance of every geometric decision (the kernels' constant)
GEOMETRIC_TOLERANCE: float = _kernels.geometric_tolerance

#: a facet edge this much shorter than the largest facet around its nodes is a
#: meshing artifact: its nodes share one averaged normal (the kernels' constant;
#: dolfinx_mortar.mortar.surface_normals.normal_clusters)
NEGLIGIBLE_FACET_RATIO: float = _kernels.negligible_facet_ratio


#: nodes within this fraction of their element length of contact are near contact (they
#: stiffen when nothing touches yet, and the current surface keeps their pairs)
NEAR_CONTACT = 0.1


def length_scale(x: npt.ArrayLike, comm: Optional[MPI.Comm] = None) -> float:
    """Bounding-box diagonal of points ``x`` (their extent; 0 for one point).

    With ``comm`` the scale is taken over every rank's points, so that a
    decision does not depend on how the mesh is partitioned.
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2:
        raise ValueError(f"points must have shape (points, gdim), got {x.shape}")
    if comm is None or comm.size == 1:
        return float(_kernels.length_scale(np.ascontiguousarray(x))) if len(x) else 0.0
    # the bounding box over all ranks (a rank may hold no point)
    gdim = x.shape[1]
    lo = x.min(axis=0) if len(x) else np.full(gdim, np.inf)
    hi = x.max(axis=0) if len(x) else np.full(gdim, -np.inf)
    lo = np.min(comm.allgather(lo), axis=0)
    hi = np.max(comm.allgather(hi), axis=0)
    if not np.all(np.isfinite(lo)):
        return 0.0
    return float(np.linalg.norm(hi - lo))


def zero_length(scale: float) -> float:
    """The length below which a length is zero for a geometry of ``scale``."""
    return max(GEOMETRIC_TOLERANCE * scale, np.finfo(np.float64).tiny)


def local_origin(x: npt.ArrayLike, comm: Optional[MPI.Comm] = None,
                 axisymmetric: bool = False) -> npt.NDArray[np.float64]:
    """A point to measure a geometry's coordinates from: the lower corner of
    the bounding box of points ``x`` rounded to a multiple of the power of two
    above their extent (over every rank with ``comm``, so that every rank
    takes the same).

    ``X − origin`` is exact far from the origin (both lie on the grid of X's
    last digit) and else rounded at the extent's scale, and
    ``(X − origin) + u`` keeps the digits of a displacement ``u`` that ``X + u``
    loses far from the origin (at |X| = 1e6, 1e-10 of every position: 1e-5 of
    a 1e-5 gap). A geometry within its extent of the origin gets the origin
    (its arithmetic does not change); a shifted copy of it on the same grid
    gets the same coordinates. Translations change no gap, normal or
    derivative. Axisymmetric: only the axis coordinate moves (r is the radius
    of 2πr).
    """
    x = np.asarray(x, dtype=np.float64)
    lo = x.min(axis=0) if len(x) else np.full(x.shape[1], np.inf)
    if comm is not None and comm.size > 1:
        lo = np.min(comm.allgather(lo), axis=0)
    extent = length_scale(x, comm)
    if not (np.all(np.isfinite(lo)) and extent > 0):
        return np.zeros(x.shape[1])
    unit = 2.0 ** np.ceil(np.log2(extent))
    origin = np.round(lo / unit) * unit
    if axisymmetric:
        origin[0] = 0.0
    return origin
