"""The slave and master surfaces' geometry that a coupling needs: gathered
copies, averaged and interface nodal normals, the clusters of nodes that share
a normal, and the facets' swept search boxes (docs/DESIGN.md, §Segmentation)."""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt

from dolfinx_mortar import _kernels
from dolfinx_mortar.mortar.surface_exchange import NearSurface, SurfaceCopy, largest_facet
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.tolerance import GEOMETRIC_TOLERANCE

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


def current_coordinates(surface: LagrangeSurface,
                        displacement: Optional[FloatArray] = None) -> FloatArray:
    """Node coordinates plus a nodal displacement (local nodes, gdim)."""
    if displacement is None:
        return surface.x
    u = np.asarray(displacement, dtype=np.float64)
    if u.shape != surface.x.shape:
        raise ValueError(f"nodal displacement has shape {u.shape}, expected "
                         f"{surface.x.shape} (local nodes, gdim)")
    if not np.all(np.isfinite(u)):
        raise ValueError("the displacement contains NaN or infinite values")
    return surface.x + u


def averaged_nodal_normals(surface: LagrangeSurface, x: FloatArray,
                           clusters: Optional[dict[int, int]] = None) -> FloatArray:
    """Unit averages of the adjacent cells' normals at every local node.

    Each cell's normal is weighted by its size (|J| at the node: the length
    of a P1 line, twice the area of a P1 triangle), so that a facet of
    vanishing size, as mesh generators make at corners, cannot tilt its
    nodes' normals (unweighted, a 1e-6 h facet at 45° tilted them by 22°).
    Nodes joined by such a facet share one normal, that of all the cells
    around any of them (``clusters``, default :func:`normal_clusters` of
    ``x``): a node whose only facet is a vanishing chamfer at the surface's
    corner takes the surface's normal, not the chamfer's 45° (which put its
    pressure 8-40% off). Nodes on no cell get a zero vector. Summed across
    ranks, so a node shared by facets on two ranks gets the same normal on both.
    """
    cell_normals = _kernels.element_node_normals(surface.facet_type, x,
                                                 surface.cells.astype(np.int32),
                                                 size_weighted=True)
    summed = np.column_stack([surface.layout.sum_at_functions(surface.cells,
                                                              cell_normals[..., k])
                              for k in range(x.shape[1])])
    if clusters is None:
        clusters = normal_clusters(surface, x)
    summed = sum_over_clusters(surface, clusters, summed)
    length = np.linalg.norm(summed, axis=1)
    return np.divide(summed, length[:, None], out=np.zeros_like(summed),
                     where=length[:, None] > 0)  # exactly 0 only on nodes of no cell


def normal_clusters(surface: LagrangeSurface, x: FloatArray) -> dict[int, int]:
    """The nodes that share one averaged normal: global id → the smallest
    global id of its cluster, for the nodes of a cluster only.

    Two nodes of a cell closer than ``NEGLIGIBLE_FACET_RATIO`` times the
    largest cell around them (dolfinx_mortar/tolerance.py) are one cluster:
    the facet between them is a meshing artifact, not a feature. Decided by
    the kernel on the cells near this rank's (collective), so the same on every
    rank and the same as the current configuration's exact derivatives.
    """
    return clusters_and_bytes(surface, x)[0]


def clusters_and_bytes(surface: LagrangeSurface, x: FloatArray
                       ) -> tuple[dict[int, int], NearSurface]:
    """:func:`normal_clusters`, and the copy of the surface near this rank's
    cells they were found on (every cell around its nodes, and a band), with
    the bytes it cost."""
    # the cells around this rank's nodes and a band beyond: a cluster is a few
    # facets a thousandth of their neighbours long, well inside the band
    own = (_kernels.facet_bounding_boxes(surface.facet_type, x, surface.cells.astype(np.int32),
                                         0.0) if len(surface.cells) else np.zeros((0, 6)))
    near = NearSurface(surface, x, own, 2.0 * largest_facet(surface, x))
    copy = near.copy
    ids = copy.global_ids.astype(np.int64)
    roots = _kernels.normal_clusters(surface.facet_type, copy.x, copy.cells, ids)
    members = np.isin(roots, roots[roots != ids])
    local = dict(zip(ids[members].tolist(), roots[members].tolist()))
    # the union over the ranks (clusters are rare): the same dict on every rank,
    # so that every rank takes the same collective branches on it
    clusters: dict[int, int] = {}
    for part in surface.layout.comm.allgather(local):
        clusters.update(part)
    return clusters, near


def cluster_diameters(surface: LagrangeSurface, clusters: dict[int, int],
                      diameters: FloatArray) -> FloatArray:
    """Each local cell's diameter, or for a cell touching a cluster the largest
    diameter of the cells around that cluster: a facet that is a meshing
    artifact (a corner chamfer 1e-6 h long) searches as far as the surface
    around it, not a millionth of that (it found no master in the current
    configuration). Collective."""
    if not clusters:
        return diameters
    layout = surface.layout
    nn = surface.cells.shape[1]
    largest = sum_over_clusters(surface, clusters, np.zeros((layout.size_local, 0)),
                                maxima=np.repeat(diameters[:, None], nn, axis=1))
    return np.maximum(diameters, largest[surface.cells].max(axis=1))


def sum_over_clusters(surface: LagrangeSurface, clusters: dict[int, int],
                      values: FloatArray, maxima: Optional[FloatArray] = None
                      ) -> FloatArray:
    """Nodal totals (local nodes, k), each node of a cluster given the sum over
    its cluster's nodes. With ``maxima`` (local cells, nodes per cell), instead
    the largest of these cell values around each cluster (0 off the clusters).
    Collective (a cluster may span ranks)."""
    if not clusters:                 # the same on every rank
        return values
    layout = surface.layout
    ids = layout.global_indices
    in_cluster = np.isin(ids, np.fromiter(clusters, dtype=np.int64))
    roots = np.array([clusters[int(i)] for i in ids[in_cluster]], dtype=np.int64)
    if maxima is not None:
        # every local cell's value at its nodes of a cluster (cells are owned once)
        cell_ids = ids[surface.cells]
        at = np.isin(cell_ids, np.fromiter(clusters, dtype=np.int64))
        mine = (np.array([clusters[int(i)] for i in cell_ids[at]], dtype=np.int64),
                np.asarray(maxima)[at])
    else:
        owned = np.flatnonzero(in_cluster) < layout.num_owned   # each node counted once
        mine = (roots[owned], values[in_cluster][owned])
    parts = layout.comm.allgather(mine)
    all_roots = np.concatenate([r for r, _ in parts])
    cluster_ids, which = np.unique(all_roots, return_inverse=True)
    if maxima is not None:
        result = np.zeros(len(cluster_ids))
        np.maximum.at(result, which.ravel(), np.concatenate([v for _, v in parts]))
        out = np.zeros(layout.size_local)
    else:
        result = np.zeros((len(cluster_ids),) + values.shape[1:])
        np.add.at(result, which.ravel(), np.concatenate([v for _, v in parts]))
        out = values.copy()
    out[in_cluster] = result[np.searchsorted(cluster_ids, roots)]
    return out


def interface_nodal_normals(slave: LagrangeSurface, slave_normals: FloatArray,
                            master: SurfaceCopy, pairs: npt.NDArray, areas: FloatArray,
                            clusters: Optional[dict[int, int]] = None) -> FloatArray:
    """Unit bisectors of each slave node's normal and the normal of the master opposite it.

    Where two curved bodies touch, their deformed surfaces coincide, and the common normal
    lies between the two undeformed ones: exactly halfway for two equal bodies. A gap
    measured along the slave normal of the undeformed configuration is measured along a
    direction tilted by the whole angle between the two surfaces, which at the edge of a
    Hertz contact of two equal cylinders with a = R/10 made the pressure 2.5% off the
    mirror problem (rigid plane) and p0 0.7% high; along the bisector the tilt is half the
    angle, and zero for two equal bodies.

    The master normal opposite node A is the mean of the normals of the master facets paired
    with A's slave facets, weighted by the paired areas, summed over all ranks. Nodes without
    a master keep their own normal. The nodes of a cluster (:func:`normal_clusters`)
    share one opposite normal, over the pairs of all their cells: a node whose only
    facet is a vanishing one sees the master beyond its neighbours, not the
    master's own vanishing facet opposite.

    Parameters
    ----------
    slave
        The slave surface.
    slave_normals
        Its unit nodal normals (local nodes, gdim).
    master
        The gathered master surface the pairs index.
    pairs, areas
        (slave cell, master cell) of every pair and its covered area, from a segmentation
        along ``slave_normals``.
    clusters
        The slave's :func:`normal_clusters` (default: none).
    """
    gdim = slave_normals.shape[1]
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    # the normals of the paired master facets only: the gathered master is every rank's
    paired, which = np.unique(pairs[:, 1], return_inverse=True)
    facet_normals = _kernels.element_node_normals(
        master.facet_type, master.x, np.ascontiguousarray(master.cells[paired]),
        size_weighted=False).mean(axis=1).reshape(len(paired), gdim)
    facet_normals /= np.linalg.norm(facet_normals, axis=1)[:, None]
    slave_cells = slave.cells[pairs[:, 0]]
    weighted = facet_normals[which.ravel()] * np.asarray(areas)[:, None]
    opposite = np.column_stack([
        slave.layout.sum_at_functions(
            slave_cells, np.repeat(weighted[:, k, None], slave_cells.shape[1], axis=1))
        for k in range(gdim)])
    # A node whose opposite normals cancel, or whose bisector vanishes (a master facing its
    # own way), keeps its own normal: the sum is judged against the paired area it sums,
    # the bisector of unit vectors against the dimensionless tolerance.
    paired_area = slave.layout.sum_at_functions(
        slave_cells, np.repeat(np.asarray(areas, dtype=np.float64)[:, None],
                               slave_cells.shape[1], axis=1))
    # a cluster's nodes share their normal: they face the master of all its cells
    summed = sum_over_clusters(slave, clusters, np.column_stack([opposite, paired_area]))
    opposite, paired_area = summed[:, :gdim], summed[:, gdim]
    length = np.linalg.norm(opposite, axis=1)
    usable = (slave.layout.on_cells(slave_cells)
              & (length > GEOMETRIC_TOLERANCE * paired_area))
    unit_opposite = np.divide(opposite, length[:, None], out=np.zeros_like(opposite),
                              where=usable[:, None])
    bisector = slave_normals - unit_opposite
    length = np.linalg.norm(bisector, axis=1)
    usable &= length > GEOMETRIC_TOLERANCE
    return np.where(usable[:, None],
                    bisector / np.where(usable, length, 1.0)[:, None], slave_normals)


def swept_facet_boxes(surface: LagrangeSurface, x: FloatArray, cells: npt.NDArray[np.int32],
                      reach: float, diameters: FloatArray) -> FloatArray:
    """Bounding boxes (cells, 6) of each facet swept ``reach`` both ways along
    its own normal and enlarged by its own diameter, within the facet's box
    enlarged by ``reach`` (the search before: it never finds a pair that
    search did not).

    The segmentation pairs a master facet with a slave facet when its
    projection along the slave facet's normal overlaps it, at any distance:
    the search decides the distance. A master point that projects onto an
    affine facet from at most ``reach`` away lies in the prism of its nodes
    ± reach·n, whose box this contains; the diameter covers curved facets'
    turning normals. A box enlarged by ``reach`` in every direction, as
    before, holds (reach/diameter)² times the candidates of a small facet
    next to a large one: 16.2M candidates for 29.7k pairs on Hertz 3D at
    311k dofs, 13 s of segmentation.
    """
    gdim = x.shape[1]
    nodes = x[cells]                                             # (cells, nodes, gdim)
    normals = _kernels.element_node_normals(surface.facet_type, x, cells).reshape(nodes.shape)
    swept = np.concatenate([nodes - reach * normals, nodes + reach * normals], axis=1)
    facet = _kernels.facet_bounding_boxes(surface.facet_type, x, cells, 0.0)
    margin = diameters[:, None]
    boxes = facet.copy()
    boxes[:, :gdim] = np.minimum(boxes[:, :gdim], swept.min(axis=1))
    boxes[:, 3:3 + gdim] = np.maximum(boxes[:, 3:3 + gdim], swept.max(axis=1))
    boxes[:, :3] = np.maximum(boxes[:, :3] - margin, facet[:, :3] - reach)
    boxes[:, 3:] = np.minimum(boxes[:, 3:] + margin, facet[:, 3:] + reach)
    return boxes
