"""A cell partitioner that spreads the contact surfaces over the ranks.

A graph partitioner balances cells and cuts few facets; it knows nothing of
contact. On a mesh graded towards a contact zone that is small next to the
bodies (Hertz: a disk at the corner of an octant), it puts the whole zone on
one rank, and that rank then does all of the contact work (search,
segmentation, the contact rows of the Jacobian) while the others wait: the
contact parts do not speed up with the rank count at all.

This partitioner keeps DOLFINx's graph partition for the bulk and deals out
the cells next to the contact facets separately, by recursive coordinate
bisection, so that every rank gets an equal share of them in one compact
piece. Balancing two quantities at once is what METIS calls a
multi-constraint partition; DOLFINx (0.9 to 0.11) exposes no weights to its graph
partitioners (SCOTCH, ParMETIS, KaHIP), so the two are balanced one after the
other here. The contact cells moved off their graph part add ghosts along the
cut of the contact layer only: a layer one cell thick.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from scipy.optimize import linear_sum_assignment
from scipy.spatial import cKDTree

from dolfinx import cpp as _cpp

from dolfinx_mortar import dolfinx_compat

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]


def cells_near_contact(vertices: npt.NDArray[np.int64], x: FloatArray,
                       surfaces: list[npt.NDArray[np.int64]], facet_vertices: int) -> BoolArray:
    """Whether each cell has a facet on one of the ``surfaces`` (given by
    their node indices) and lies within twice its own size of another of
    them: where contact can start.

    A slave surface is often much larger than the zone it touches (the whole
    sphere of a Hertz scene); dealing out all of its cells would not deal
    out the contact work, so with two or more surfaces only the cells close
    to another surface count. With one surface (contact with a rigid
    obstacle the mesh does not hold) all of its cells count.
    """
    points = x[vertices]                                     # (cells, vertices, gdim)
    centroids = points.mean(axis=1)
    sizes = 2.0 * np.linalg.norm(points - centroids[:, None], axis=2).max(axis=1)
    on = [np.isin(vertices, nodes).sum(axis=1) >= facet_vertices for nodes in surfaces]
    if len(surfaces) < 2:
        return on[0] if on else np.zeros(len(vertices), dtype=bool)
    near = np.zeros(len(vertices), dtype=bool)
    for k, mine in enumerate(on):
        others = np.logical_or.reduce([o for j, o in enumerate(on) if j != k]) & ~mine
        if not np.any(mine) or not np.any(others):
            continue
        distance, _ = cKDTree(centroids[others]).query(centroids[mine])
        near[np.flatnonzero(mine)[distance <= 2.0 * sizes[mine]]] = True
    return near


def _robust_axis(points: FloatArray) -> int:
    """The coordinate axis along which the points spread most, judged by
    their interquartile range: a few large facets far from the contact
    zone (graded meshes have them) cannot choose it, as they would choose
    the axis of the largest variance or extent."""
    q1, q3 = np.percentile(points, [25.0, 75.0], axis=0)
    return int(np.argmax(q3 - q1))


def coordinate_bisection(points: FloatArray, nparts: int) -> npt.NDArray[np.int32]:
    """Group index in ``[0, nparts)`` of each point: the points are halved by
    count (in proportion for odd ``nparts``) across the axis of
    :func:`_robust_axis`, and each half is split again, so that the groups
    have equal counts to within one and are compact."""
    groups = np.zeros(len(points), dtype=np.int32)

    def split(indices: npt.NDArray[np.int64], first: int, count: int) -> None:
        if count == 1 or len(indices) == 0:
            groups[indices] = first
            return
        left = count // 2
        axis = _robust_axis(points[indices])
        order = indices[np.argsort(points[indices, axis], kind="stable")]
        cut = (len(order) * left) // count
        split(order[:cut], first, left)
        split(order[cut:], first + left, count - left)

    split(np.arange(len(points)), 0, nparts)
    return groups


def _ghost_ranks(comm: MPI.Comm, graph, owner: npt.NDArray[np.int32]
                 ) -> _cpp.graph.AdjacencyList_int32:
    """Each cell's owner followed by the other owners of its facet
    neighbours in the dual graph (global cell numbers: this rank's offset
    plus the local index), which is the ghost layer of
    ``GhostMode.shared_facet``."""
    counts = comm.allgather(len(owner))
    every_owner = np.empty(sum(counts), dtype=np.int32)
    comm.Allgatherv(owner, (every_owner, counts))
    offsets = graph.offsets
    neighbour_owner = every_owner[graph.array]
    cell_of_link = np.repeat(np.arange(len(owner)), np.diff(offsets))
    foreign = neighbour_owner != owner[cell_of_link]
    pairs = np.unique(np.column_stack([cell_of_link[foreign],
                                       neighbour_owner[foreign]]), axis=0)
    ghosts_per_cell = np.bincount(pairs[:, 0], minlength=len(owner)) if len(pairs) else \
        np.zeros(len(owner), dtype=np.int64)
    dest_offsets = np.zeros(len(owner) + 1, dtype=np.int32)
    dest_offsets[1:] = np.cumsum(1 + ghosts_per_cell)
    dest = np.empty(dest_offsets[-1], dtype=np.int32)
    dest[dest_offsets[:-1]] = owner
    if len(pairs):
        # pairs are sorted by cell: the k-th ghost of a cell follows its owner
        rank_in_cell = np.arange(len(pairs)) - np.repeat(
            np.cumsum(ghosts_per_cell) - ghosts_per_cell, ghosts_per_cell)
        dest[dest_offsets[pairs[:, 0]] + 1 + rank_in_cell] = pairs[:, 1]
    return _cpp.graph.AdjacencyList_int32(dest, dest_offsets)


def contact_balanced_partitioner(comm: MPI.Comm, contact_cells: BoolArray,
                                 centroids: FloatArray) -> Callable:
    """A cell partitioner for :func:`dolfinx.mesh.create_mesh` that gives
    every rank an equal, compact share of the contact cells.

    Parameters
    ----------
    comm
        The communicator the mesh is created on.
    contact_cells
        Whether each cell this rank passes to ``create_mesh`` lies next to a
        contact surface, in the order passed.
    centroids
        The centroid of each of these cells, (cells, gdim).

    Returns
    -------
    A cell partitioner: the graph partition of the dual graph for all cells
    but the contact cells, which go by :func:`coordinate_bisection` to the
    parts that already hold most of each group (an optimal assignment, so
    that as few contact cells as possible leave their graph part).
    """
    contact_cells = np.asarray(contact_cells, dtype=bool)
    centroids = np.asarray(centroids, dtype=np.float64)
    if centroids.shape[0] != len(contact_cells):
        raise ValueError(f"{len(contact_cells)} contact flags for {centroids.shape[0]} "
                         f"centroids")
    graph_partitioner = _cpp.graph.partitioner()

    def partition(comm_wrapper, nparts: int, graph, ghosting: bool):
        if graph.num_nodes != len(contact_cells):
            raise RuntimeError(f"the partitioner was given {graph.num_nodes} cells on rank "
                               f"{comm.rank}, but contact flags for {len(contact_cells)}")
        default = graph_partitioner(comm_wrapper, nparts, graph, False)
        owner = default.array[default.offsets[:-1]].astype(np.int32)
        local = np.flatnonzero(contact_cells)
        counts = comm.allgather(len(local))
        if sum(counts) >= nparts > 1:
            gdim = centroids.shape[1]
            points = np.empty((sum(counts), gdim))
            comm.Allgatherv(np.ascontiguousarray(centroids[local]),
                            (points, [c * gdim for c in counts]))
            groups = coordinate_bisection(points, nparts)
            start = sum(counts[:comm.rank])
            mine = groups[start:start + len(local)]
            overlap = np.zeros((nparts, nparts), dtype=np.int64)
            np.add.at(overlap, (mine, owner[local]), 1)
            overlap = comm.allreduce(overlap)
            group_rows, parts = linear_sum_assignment(overlap, maximize=True)
            part_of_group = np.empty(nparts, dtype=np.int32)
            part_of_group[group_rows] = parts
            owner[local] = part_of_group[mine]
        if not ghosting:
            return _cpp.graph.AdjacencyList_int32(
                owner, np.arange(len(owner) + 1, dtype=np.int32))
        return _ghost_ranks(comm, graph, owner)

    # with its ghost layer (GhostMode.shared_facet), as the module's text and its test say
    return dolfinx_compat.create_cell_partitioner(partition, _cpp.mesh.GhostMode.shared_facet)
