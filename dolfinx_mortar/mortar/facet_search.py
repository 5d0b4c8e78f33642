"""Which master facets a slave facet may touch: the bounding-box search that
proposes the candidate pairs a coupling segments (docs/DESIGN.md, §Segmentation)."""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar import _kernels
from dolfinx_mortar.mortar.surface_exchange import SurfaceCopy, facet_extents, volume_ids
from dolfinx_mortar.mortar.surface_normals import cluster_diameters, swept_facet_boxes
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

FloatArray = npt.NDArray[np.float64]


def search_boxes(slave: LagrangeSurface, xs: FloatArray, slave_cells: npt.NDArray[np.int32],
                 clusters: dict[int, int], search_radius: Optional[float],
                 facet_search_factor: Optional[float]) -> tuple[float, FloatArray]:
    """Where each slave facet looks for master facets: the search radius and the
    slave facets' search boxes (cells, 6: lower then upper corner).

    Collective when ``search_radius`` is None (its default is reduced over all ranks).

    Parameters
    ----------
    slave
        The slave surface (this rank's cells).
    xs
        The slave nodes' coordinates in the configuration of the coupling.
    slave_cells
        The slave cells' nodes, as the kernels take them (int32).
    clusters
        The slave nodes that share a normal (:func:`normal_clusters`).
    search_radius
        How far along its normal a slave facet reaches; None: the largest slave
        facet diameter over all ranks.
    facet_search_factor
        Instead of one radius, each slave facet reaches this multiple of its own
        diameter (see :class:`~dolfinx_mortar.mortar.coupling.MortarCoupling`).

    Returns
    -------
    tuple
        The search radius used and the boxes.

    Raises
    ------
    ValueError
        If the search radius is negative or not finite, or the factor not positive
        and finite.
    """
    # each slave facet's diameter (its largest coordinate extent)
    diameters = cluster_diameters(
        slave, clusters, facet_extents(slave, xs))
    if search_radius is None:
        search_radius = slave.layout.comm.allreduce(float(np.max(diameters, initial=0.0)),
                                                    op=MPI.MAX)
    if not np.isfinite(search_radius) or search_radius < 0:
        raise ValueError(f"search radius must be finite and non-negative, got {search_radius}")
    search_radius = float(search_radius)
    if facet_search_factor is None:
        slave_boxes = swept_facet_boxes(slave, xs, slave_cells, search_radius, diameters)
    else:
        if not (np.isfinite(facet_search_factor) and facet_search_factor > 0):
            raise ValueError("facet_search_factor must be positive and finite, got "
                             f"{facet_search_factor!r}")
        slave_boxes = _kernels.facet_bounding_boxes(slave.facet_type, xs, slave_cells, 0.0)
        margin = facet_search_factor * diameters[:, None]
        slave_boxes[:, :3] -= margin
        slave_boxes[:, 3:] += margin
    return search_radius, slave_boxes


def candidate_pairs(slave_boxes: FloatArray, master_copy: SurfaceCopy) -> npt.NDArray:
    """The pairs (slave cell, master cell of ``master_copy``) whose boxes overlap."""
    master_boxes = _kernels.facet_bounding_boxes(master_copy.facet_type, master_copy.x,
                                                 master_copy.cells, 0.0)
    return _kernels.overlapping_box_pairs(slave_boxes, master_boxes)


def near_in_surface(slave: LagrangeSurface, master_copy: SurfaceCopy,
                    candidates: npt.NDArray, rings: int = 2) -> npt.NDArray[np.bool_]:
    """Which candidate pairs of a surface with itself (self-contact) are
    neighbours: the two facets share a node, or (``rings`` = 2) both share one
    with a third facet, or (where the surface knows its volume cells,
    ``volume_nodes``) the cells of the volume mesh they bound share a node.
    Such facets meet at an edge or a corner, where they face each other at zero
    distance, or bound a wall one or two cells thick, whose other side faces
    them through the material; they are never in contact with each other. The
    test is on global node numbers, so it does not depend on where the surface
    has moved. ``master_copy`` must be the surface itself (gathered, or the
    part near this rank's facets with a band of at least one facet).
    """
    import scipy.sparse
    size = slave.layout.size_global
    volume, received = volume_ids(slave), master_copy.volume_ids
    if len(candidates) == 0:
        return np.zeros(0, dtype=bool)

    def incidence(global_nodes: npt.NDArray) -> "scipy.sparse.csr_matrix":
        rows = np.repeat(np.arange(len(global_nodes)), global_nodes.shape[1])
        return scipy.sparse.csr_matrix((np.ones(rows.size), (rows, global_nodes.ravel())),
                                       shape=(len(global_nodes), size))

    S = incidence(slave.layout.global_indices[slave.cells])
    M = incidence(master_copy.global_ids[master_copy.cells])
    near = S @ M.T                     # share a node
    for _ in range(rings - 1):
        near = near @ (M @ M.T)        # … or share one with a facet that does
    if volume is not None and received is not None:
        # … or bound cells that share one
        near = near + incidence(volume) @ incidence(received).T
    values = np.asarray(near[candidates[:, 0], candidates[:, 1]]).ravel()
    return values > 0
