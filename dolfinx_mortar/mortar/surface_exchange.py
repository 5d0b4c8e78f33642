"""Each rank's share of a distributed surface: the facets near where it searches
(docs/DESIGN.md, §Parallel).

A coupling needs, on each rank, the master facets that its slave facets may
reach, not the whole master surface. Each rank describes where it searches by a
few boxes (its slave facets' search boxes, grouped by recursive coordinate
bisection and padded by a band), the boxes are shared (a few numbers per
rank), and every rank sends each other rank only its own facets whose boxes
meet that rank's. What a rank receives then grows with its share of the
contact zone, not with the whole surface. The band (at least the largest
facet) brings in every facet that shares a node with a facet the rank may
pair: what the self-contact neighbour test and the interface normals need.

MPI's own collectives do the exchange: DOLFINx offers no distributed search
over a facet subset of another rank's boxes, and its bounding-box trees are
built over whole meshes.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar import _kernels
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: the most boxes by which a rank describes where it searches
REGION_BOXES = 16


@dataclass
class SurfaceCopy:
    """What segmentation needs of a (possibly gathered) surface.

    Attributes
    ----------
    facet_type
        The kernels' facet type.
    x
        Node coordinates in the configuration of interest, (nodes, gdim).
    cells
        Node indices of each cell, (cells, nodes per cell).
    global_ids
        Global function index of each node in the surface's layout.
    volume_ids
        Per cell, the global indices (in the surface's layout) of the nodes of
        the volume cell it bounds, where asked for (self-contact) and the
        surface knows them (``LagrangeSurface.volume_nodes``); else None.
    """

    facet_type: _kernels.FacetType
    x: FloatArray
    cells: npt.NDArray[np.int32]
    global_ids: IntArray
    volume_ids: Optional[IntArray] = None


def gather_surface(surface: LagrangeSurface, x: FloatArray,
                   with_volume: bool = False) -> SurfaceCopy:
    """All ranks' cells of a surface, with one copy of the nodes per cell.

    What the current configuration's shared-out Jet work needs: both surfaces,
    the same on every rank. A frozen coupling receives only the master facets
    near its slave facets (:class:`~dolfinx_mortar.mortar.surface_exchange.NearSurface`).
    """
    comm = surface.layout.comm
    global_ids = surface.layout.global_indices[surface.cells]
    coords = x[surface.cells]
    volume = volume_ids(surface) if with_volume else None
    if comm.size > 1:
        global_ids = np.concatenate(comm.allgather(global_ids)).reshape(-1, surface.cells.shape[1])
        coords = np.concatenate(comm.allgather(coords)).reshape(-1, *coords.shape[1:])
        if volume is not None:
            volume = np.concatenate(comm.allgather(volume)).reshape(-1, volume.shape[1])
    nc, nd = global_ids.shape
    return SurfaceCopy(surface.facet_type, coords.reshape(nc * nd, -1),
                       np.arange(nc * nd, dtype=np.int32).reshape(nc, nd),
                       global_ids.ravel(), volume)


def volume_ids(surface: LagrangeSurface) -> Optional[IntArray]:
    """The global indices of each local cell's volume cell nodes (None where unknown)."""
    if surface.volume_nodes is None:
        return None
    return surface.layout.global_indices[surface.volume_nodes]


def bisected_boxes(boxes: FloatArray, pieces: int = REGION_BOXES) -> FloatArray:
    """At most ``pieces`` boxes covering ``boxes`` (n, 6: lower then upper
    corner): the boxes' centres split in halves along their widest axis,
    recursively, and each group's bounding box. Empty for no box."""
    if len(boxes) == 0:
        return np.zeros((0, 6))
    groups = [np.arange(len(boxes))]
    centres = 0.5 * (boxes[:, :3] + boxes[:, 3:])
    while len(groups) < pieces:
        sizes = [len(g) for g in groups]
        widest = int(np.argmax(sizes))
        group = groups[widest]
        if len(group) < 2:
            break
        c = centres[group]
        axis = int(np.argmax(np.ptp(c, axis=0)))
        order = group[np.argsort(c[:, axis], kind="stable")]
        half = len(order) // 2
        groups[widest:widest + 1] = [order[:half], order[half:]]
    return np.array([np.concatenate([boxes[g, :3].min(axis=0), boxes[g, 3:].max(axis=0)])
                     for g in groups])


def meeting(facet_boxes: FloatArray, region: FloatArray) -> npt.NDArray[np.bool_]:
    """Which facet boxes meet any box of ``region`` (closed boxes), by the
    kernels' bounding-box tree over the region."""
    chosen = np.zeros(len(facet_boxes), dtype=bool)
    if len(region) and len(facet_boxes):
        pairs = np.asarray(_kernels.overlapping_box_pairs(
            np.ascontiguousarray(facet_boxes), np.ascontiguousarray(region))).reshape(-1, 2)
        chosen[pairs[:, 0]] = True
    return chosen


def facet_extents(surface: LagrangeSurface, x: FloatArray) -> FloatArray:
    """Each local facet's extent, its largest coordinate range, at the node
    coordinates ``x``: the diameter every search radius is measured in."""
    return np.max(np.ptp(x[surface.cells], axis=1), axis=1, initial=0.0)


def largest_facet(surface: LagrangeSurface, x: FloatArray) -> float:
    """The largest facet's extent (:func:`facet_extents`) over all ranks:
    the band that brings every neighbour of a reachable facet along."""
    local = float(np.max(facet_extents(surface, x), initial=0.0))
    return surface.layout.comm.allreduce(local, op=MPI.MAX)


def whole_surface(surface: LagrangeSurface, x: FloatArray,
                  with_volume: bool = False) -> tuple[SurfaceCopy, int]:
    """Every rank's facets on every rank (collective), and the bytes received
    from the other ranks."""
    copy = gather_surface(surface, x, with_volume)
    own = x[surface.cells].nbytes + surface.cells.size * copy.global_ids.itemsize
    received = copy.x.nbytes + copy.global_ids.nbytes - own
    if copy.volume_ids is not None:
        received += copy.volume_ids.nbytes - surface.volume_nodes.size * copy.volume_ids.itemsize
    return copy, int(received)


class NearSurface:
    """The facets of a distributed surface that a rank's search boxes may reach,
    with what the exchange cost (collective).

    Parameters
    ----------
    surface
        The surface, each rank with its own cells.
    x
        Its local nodes' coordinates in the configuration of the search.
    search_boxes
        This rank's search boxes (n, 6): where its facets may find a partner.
    band
        How far beyond the boxes facets are still wanted (at least the
        largest facet, so that the neighbours of every facet a box meets come
        along).
    with_volume
        Also send each facet's volume cell nodes (what the self-contact
        neighbour test needs), where the surface knows them.

    Attributes
    ----------
    copy
        The facets received (this rank's own included), as a
        :class:`~dolfinx_mortar.mortar.surface_normals.SurfaceCopy`.
    received_bytes
        Bytes of coordinates and node ids received from other ranks.
    first_own_cell
        Where this rank's own cells start in ``copy``: they all meet its
        boxes, and follow in their order.
    """

    def __init__(self, surface: LagrangeSurface, x: FloatArray, search_boxes: FloatArray,
                 band: float, with_volume: bool = False):
        comm: MPI.Comm = surface.layout.comm
        self.first_own_cell = 0
        if comm.size == 1:
            self.copy, self.received_bytes = gather_surface(surface, x, with_volume), 0
            return
        region = bisected_boxes(np.asarray(search_boxes, dtype=np.float64).reshape(-1, 6))
        region[:, :3] -= band
        region[:, 3:] += band
        regions = comm.allgather(region)
        cells = surface.cells
        ids = surface.layout.global_indices[cells]
        coords = x[cells]
        volume = volume_ids(surface) if with_volume else None
        facet_boxes = (_kernels.facet_bounding_boxes(surface.facet_type, x,
                                                     cells.astype(np.int32), 0.0)
                       if len(cells) else np.zeros((0, 6)))
        outgoing = []
        for boxes in regions:
            chosen = meeting(facet_boxes, boxes)
            outgoing.append((ids[chosen], coords[chosen],
                             None if volume is None else volume[chosen]))
        incoming = comm.alltoall(outgoing)
        self.received_bytes = int(sum(sum(a.nbytes for a in part if a is not None)
                                      for rank, part in enumerate(incoming)
                                      if rank != comm.rank))
        nd = cells.shape[1]
        self.first_own_cell = int(sum(len(part[0]) for part in incoming[:comm.rank]))
        global_ids = np.concatenate([part[0] for part in incoming]).reshape(-1, nd)
        nc = len(global_ids)
        xs = np.concatenate([part[1] for part in incoming]).reshape(nc * nd, x.shape[1])
        received_volume = None
        if volume is not None:
            received_volume = np.concatenate([part[2] for part in incoming]).reshape(
                nc, volume.shape[1])
        self.copy = SurfaceCopy(surface.facet_type, xs,
                                np.arange(nc * nd, dtype=np.int32).reshape(nc, nd),
                                global_ids.ravel(), received_volume)
