"""Mortar operators between a slave and a master surface (docs/DESIGN.md, §Segmentation).

:class:`MortarCoupling` segments one slave–master pair in one configuration and
keeps the integrals in the slave basis N. Every mortar basis is ``M = N C`` on a
slave cell, so :meth:`MortarCoupling.operators` turns them into the operators
of any kind by ``Cᵀ·(…)`` without redoing the geometry:

- ``D_AB = ∫ M_A N_B`` (slave × slave),
- ``M_AC = ∫ M_A N^m_C∘χ`` (slave × master, master columns in the master
  layout's global numbering),
- ``g_A = ∫ M_A d`` with the gap ``d = (x_s − x_m)·n``, positive when penetrating.

For GLS and GLS*, ``M_A`` has global support: their operators are
``S·D_N``, ``S·M_N``, ``S·g_N`` with ``S = L⁻¹`` or ``W L⁻¹``, and only the
sparse factors are assembled (docs/DESIGN.md, §Bases: never a dense slave block).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Optional

import basix
import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import _kernels
from dolfinx_mortar.errors import DegenerateGeometryError
from dolfinx_mortar.bases.basis import MortarBasis
from dolfinx_mortar.kinds import BasisKind, KindLike, is_global, kind_name, parse_kind
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import assemble_blocks
from dolfinx_mortar.tolerance import GEOMETRIC_TOLERANCE, length_scale, zero_length

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


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
    """

    facet_type: _kernels.FacetType
    x: FloatArray
    cells: npt.NDArray[np.int32]
    global_ids: IntArray


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
    the kernel on the gathered surface (collective), so the same on every
    rank and the same as the current configuration's exact derivatives.
    """
    copy = gather_surface(surface, x)
    ids = copy.global_ids.astype(np.int64)
    roots = _kernels.normal_clusters(surface.facet_type, copy.x, copy.cells, ids)
    members = np.isin(roots, roots[roots != ids])
    return dict(zip(ids[members].tolist(), roots[members].tolist()))


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


def gather_surface(surface: LagrangeSurface, x: FloatArray) -> SurfaceCopy:
    """All ranks' cells of a surface, with one copy of the nodes per cell.

    The master side needs every master facet that may lie below this rank's
    slave facets; gathering the (small) master surface is the simple way
    (docs/DESIGN.md, §Parallel).
    """
    comm = surface.layout.comm
    global_ids = surface.layout.global_indices[surface.cells]
    coords = x[surface.cells]
    if comm.size > 1:
        global_ids = np.concatenate(comm.allgather(global_ids)).reshape(-1, surface.cells.shape[1])
        coords = np.concatenate(comm.allgather(coords)).reshape(-1, *coords.shape[1:])
    nc, nd = global_ids.shape
    return SurfaceCopy(surface.facet_type, coords.reshape(nc * nd, -1),
                       np.arange(nc * nd, dtype=np.int32).reshape(nc, nd),
                       global_ids.ravel())


def polynomial_degree(surface: LagrangeSurface) -> int:
    """Total degree of the basis in reference coordinates (Q_k: 2k)."""
    k = surface.reference.degree
    return 2 * k if surface.reference.cell == "quadrilateral" else k


def segment_quadrature(tdim: int, degree: int) -> tuple[FloatArray, FloatArray]:
    cell = basix.CellType.interval if tdim == 1 else basix.CellType.triangle
    return basix.make_quadrature(cell, degree)


@dataclass(frozen=True)
class SegmentPoints:
    """The segment quadrature points of a coupling (``keep_points``): for each, its
    pair (index into the pairs), weight, gap d, unit normal n, and the standard slave
    basis N and master basis N^m there."""

    pairs: npt.NDArray[np.int32]
    weights: FloatArray
    gap: FloatArray
    normals: FloatArray
    slave_N: FloatArray
    master_N: FloatArray

    @classmethod
    def of(cls, r: "_kernels.MortarIntegrals") -> "SegmentPoints":
        return cls(r.point_pairs, r.point_weights, r.point_gap, r.point_normals,
                   r.point_slave_N, r.point_master_N)


class MortarCoupling:
    """Segmentation and slave-basis mortar integrals of a slave–master pair.

    Parameters
    ----------
    slave, master
        The surfaces; the slave's cells must be owned by this rank, the master
        is gathered from all ranks.
    slave_displacement, master_displacement
        Nodal displacements (local nodes, gdim) giving the configuration;
        ``None`` means the surfaces' own coordinates.
    search_radius
        How far along its normal a slave facet reaches for master facets;
        default the largest slave facet diameter (:func:`swept_facet_boxes`).
    facet_search_factor
        Instead of one ``search_radius``, pair each slave facet with the master
        facets within this multiple of its own diameter. On a graded mesh the
        largest facet sets the default radius for all: on Hertz 3D at 52k
        dofs it made 812k candidates for 6.9k pairs (0.70 s of segmentation),
        against 70k candidates with a factor of 2 (the same pairs wherever
        the surfaces are closer than two local element lengths).
    quadrature_degree
        Degree of the rule on each segment; the default integrates the
        products of slave and master functions exactly on affine facets
        (triangles, lines, parallelograms). On other quadrilaterals the
        segments are mapped back through the bilinear inverse, the integrands
        are not polynomials and the integrals are exact only up to quadrature.
    opposing_normals_only
        Skip master facets that face the same way as the slave facet.
    keep_points
        Also keep every segment quadrature point (weight, gap, normal, slave
        and master basis values) in :attr:`points`, for the pointwise active set.
    interface_normals
        Measure gaps along the bisector of the slave normal and the opposite
        master normal instead of the slave normal alone
        (:func:`interface_nodal_normals`): the segmentation runs twice. For a
        configuration frozen before the bodies have flattened against each other.

    Raises
    ------
    ValueError
        On every rank, when a slave or master facet is degenerate (its length,
        or its height in 3D, below :attr:`zero_length`), naming the facet and
        its node coordinates; or when a coordinate is NaN or infinite.
    """

    def __init__(self, slave: LagrangeSurface, master: LagrangeSurface,
                 slave_displacement: Optional[FloatArray] = None,
                 master_displacement: Optional[FloatArray] = None,
                 search_radius: Optional[float] = None,
                 quadrature_degree: Optional[int] = None,
                 opposing_normals_only: bool = True, keep_points: bool = False,
                 facet_search_factor: Optional[float] = None,
                 interface_normals: bool = False):
        if slave.gdim != master.gdim:
            raise ValueError(f"slave ({slave.gdim}D) and master ({master.gdim}D) surfaces "
                             "live in different dimensions")
        if slave.tdim != slave.gdim - 1 or master.tdim != master.gdim - 1:
            raise ValueError("contact surfaces must be facets: lines in 2D, "
                             "triangles or quadrilaterals in 3D")
        if getattr(slave, "axisymmetric", False) != getattr(master, "axisymmetric", False):
            raise ValueError("slave and master must both be axisymmetric (r, z) surfaces, or "
                             "neither")
        self.slave, self.master = slave, master
        #: wall time in seconds of each phase on this rank
        self.timings: dict[str, float] = {}
        clock = time.perf_counter()
        comm = slave.layout.comm
        xs = current_coordinates(slave, slave_displacement)
        xm = current_coordinates(master, master_displacement)
        clusters = normal_clusters(slave, xs)
        self.normals = averaged_nodal_normals(slave, xs, clusters)
        master_copy = gather_surface(master, xm)
        self.timings["normals_and_gather"] = time.perf_counter() - clock
        clock = time.perf_counter()
        #: the gathered master surface (all ranks' cells, one node copy per cell)
        self.master_copy = master_copy
        self.master_global_ids = master_copy.global_ids
        self.master_cells = master_copy.cells

        # each slave facet's diameter (its largest coordinate extent)
        diameters = cluster_diameters(
            slave, clusters, np.max(np.ptp(xs[slave.cells], axis=1), axis=1, initial=0.0))
        if search_radius is None:
            search_radius = comm.allreduce(float(np.max(diameters, initial=0.0)), op=MPI.MAX)
        if not np.isfinite(search_radius) or search_radius < 0:
            raise ValueError(f"search radius must be finite and non-negative, got {search_radius}")
        self.search_radius = float(search_radius)
        slave_cells = slave.cells.astype(np.int32)
        if facet_search_factor is None:
            slave_boxes = swept_facet_boxes(slave, xs, slave_cells, self.search_radius,
                                            diameters)
        else:
            if not (np.isfinite(facet_search_factor) and facet_search_factor > 0):
                raise ValueError("facet_search_factor must be positive and finite, got "
                                 f"{facet_search_factor!r}")
            slave_boxes = _kernels.facet_bounding_boxes(slave.facet_type, xs, slave_cells, 0.0)
            margin = facet_search_factor * diameters[:, None]
            slave_boxes[:, :3] -= margin
            slave_boxes[:, 3:] += margin
        master_boxes = _kernels.facet_bounding_boxes(master.facet_type, master_copy.x,
                                                     master_copy.cells, 0.0)
        candidates = _kernels.overlapping_box_pairs(slave_boxes, master_boxes)
        self.timings["search"] = time.perf_counter() - clock
        clock = time.perf_counter()
        degree = quadrature_degree or (polynomial_degree(slave)
                                       + max(polynomial_degree(slave),
                                             polynomial_degree(master)))
        points, weights = segment_quadrature(slave.tdim, degree)
        #: the length scale of every geometric decision, the same on every rank
        #: (the master copy is global, the slave's points are reduced)
        self.length_scale = max(length_scale(xs, comm),
                                length_scale(master_copy.x) if len(master_copy.x) else 0.0)
        #: lengths at or below this are zero (docs/DESIGN.md, §Tolerances)
        self.zero_length = zero_length(self.length_scale)
        def segment(normals: FloatArray, keep_points: bool,
                    along_normals: bool) -> _kernels.MortarIntegrals:
            return _kernels.mortar_integrals(slave.facet_type, xs, slave_cells, normals,
                                             master.facet_type, master_copy.x,
                                             master_copy.cells, candidates, points, weights,
                                             opposing_normals_only,
                                             length_scale=self.length_scale,
                                             keep_points=keep_points,
                                             axisymmetric=slave.axisymmetric,
                                             project_along_normals=along_normals)

        r = segment(self.normals, keep_points and not interface_normals, False)
        if interface_normals:
            # pairing and gap along the interface normals, not the facets' own
            self._raise_on_degenerate_facets(r, xs, slave_cells, master_copy)
            self.normals = interface_nodal_normals(slave, self.normals, master_copy,
                                                   r.pairs, r.area, clusters)
            r = segment(self.normals, keep_points, True)
        self._raise_on_degenerate_facets(r, xs, slave_cells, master_copy)
        self.timings["segmentation"] = time.perf_counter() - clock
        self.num_candidates = len(candidates)
        self.failed_projections = comm.allreduce(int(r.failed_projections))
        #: (pairs, 2) slave cell, master cell (index into the gathered master)
        self.pairs = r.pairs.astype(np.int64)
        #: integrals of the standard slave basis N per pair: ∫N N, ∫N N^m, ∫N d
        self.raw_pairs = (r.D, r.M, r.gap)
        T = slave.reference.transform
        if T is not None:
            # integrals of the transformed basis Ñ = N T (docs/DESIGN.md, §Quadratic elements)
            self.D_pairs = np.einsum("ba,pbc,cd->pad", T, r.D, T)
            self.M_pairs = np.einsum("ba,pbc->pac", T, r.M)
            self.gap_pairs = np.einsum("ba,pb->pa", T, r.gap)
        else:
            self.D_pairs, self.M_pairs, self.gap_pairs = r.D, r.M, r.gap
        self.area_pairs = r.area
        #: per segment quadrature point (keep_points): pair, weight, gap d,
        #: unit normal n, standard slave basis N, master basis N^m; else None
        self.points: Optional[SegmentPoints] = (SegmentPoints.of(r) if keep_points else None)
        #: covered area of every local slave cell
        self.covered_area = np.bincount(self.pairs[:, 0], weights=self.area_pairs,
                                        minlength=len(slave.cells))
        self._bases: dict[BasisKind, MortarBasis] = {}
        self._covered_mass: Optional[tuple] = None

    def _raise_on_degenerate_facets(self, r: _kernels.MortarIntegrals, xs: FloatArray,
                                    slave_cells,
                                    master_copy: SurfaceCopy) -> None:
        """A degenerate facet covers nothing: rather than let it vanish from the
        integrals, stop on every rank with the facets named."""
        comm = self.slave.layout.comm
        lines = [f"slave facet {c} (local cell index on rank {comm.rank}) with nodes "
                 f"{np.array2string(xs[slave_cells[c]], precision=17, separator=', ')}"
                 for c in r.degenerate_slave_facets[:5]]
        lines = [line for rank_lines in comm.allgather(lines) for line in rank_lines]
        # the master copy is the same on every rank: so is its list
        lines += [f"master facet {c} (index in the gathered master surface) with nodes "
                  f"{np.array2string(master_copy.x[master_copy.cells[c]], precision=17, separator=', ')}"
                  for c in r.degenerate_master_facets[:5]]
        if lines:
            raise DegenerateGeometryError(
                f"degenerate contact facets (length or height at most the zero length "
                f"{self.zero_length:.3g} = tolerance × length scale {self.length_scale:.3g}): "
                + "; ".join(lines))

    @property
    def total_covered_area(self) -> float:
        """Covered slave area summed over all ranks."""
        return self.slave.layout.comm.allreduce(float(np.sum(self.area_pairs)))

    def basis(self, kind: KindLike) -> MortarBasis:
        """The mortar basis of ``kind`` on the slave surface (cached)."""
        kind = parse_kind(kind)
        if kind not in self._bases:
            self._bases[kind] = MortarBasis(kind, self.slave)
        return self._bases[kind]

    def covered_element_mass(self) -> tuple[FloatArray, IntArray, FloatArray]:
        """``∫_cov N_A N_B`` of every slave cell, the covered cells, and the nodal
        ``W_A = ∫_cov N_A`` summed over all ranks (computed once)."""
        if self._covered_mass is None:
            slave = self.slave
            nd = slave.cells.shape[1]
            L = np.zeros((len(slave.cells), nd, nd))
            np.add.at(L, self.pairs[:, 0], self.D_pairs)
            covered = np.unique(self.pairs[:, 0])   # the kernel keeps pairs of positive area
            W = slave.layout.sum_at_functions(slave.cells[covered], L[covered].sum(axis=2))
            self._covered_mass = (L, covered, W)
        return self._covered_mass

    def covered_coefficients(self, kind: BasisKind) -> FloatArray:
        """Dual coefficients rebuilt on the covered part of every covered cell
        (consistent boundary modification, Popp et al. 2013).

        Fully covered cells get their usual coefficients back (up to roundoff);
        rebuilding them too keeps LcLS's nodal W_A the same on every cell that
        shares a node.
        """
        C = self.basis(kind).coefficients.copy()
        L_cov, covered, W_nodal = self.covered_element_mass()
        W_cov = L_cov.sum(axis=2)  # Σ_B ∫_cov N_A N_B = ∫_cov N_A
        try:
            C[covered] = _kernels.basis_coefficients(kind, L_cov[covered], W_cov[covered],
                                                     W_nodal[self.slave.cells[covered]])
        except ValueError as err:
            raise ValueError(f"consistent boundary modification of {kind_name(kind)}: {err}"
                             ) from None
        return C

    def operators(self, kind: KindLike, boundary_modification: bool = False
                  ) -> "MortarOperators":
        """Assembled mortar operators of one basis kind.

        Parameters
        ----------
        kind
            The basis kind.
        boundary_modification
            For the dual kinds (LcLS*, LcLS): rebuild the basis over the covered
            part of partly covered slave cells.
        """
        kind = parse_kind(kind)
        slave = self.slave
        rows = slave.cells[self.pairs[:, 0]]
        master_cols = self.master_global_ids[self.master_cells[self.pairs[:, 1]]]
        basis = self.basis(kind)
        if boundary_modification:
            if kind not in (BasisKind.LcLS_star, BasisKind.LcLS):
                raise ValueError("the consistent boundary modification applies to the dual "
                                 f"kinds LcLS* and LcLS, not {kind_name(kind)}")
            C = self.covered_coefficients(kind)
        else:
            C = basis.coefficients
        if C is None:  # global kinds: integrals in N, applied through L⁻¹ later
            D, M, g = self.D_pairs, self.M_pairs, self.gap_pairs
        else:
            Cp = C[self.pairs[:, 0]]
            D = np.einsum("pba,pbc->pac", Cp, self.D_pairs)
            M = np.einsum("pba,pbc->pac", Cp, self.M_pairs)
            g = np.einsum("pba,pb->pa", Cp, self.gap_pairs)
        master_layout = self.master.layout
        D_mat = assemble_blocks(slave.layout, rows, slave.layout,
                                slave.layout.global_indices[rows], D, unit_diagonal=True)
        M_mat = assemble_blocks(slave.layout, rows, master_layout, master_cols, M)
        gap = slave.layout.sum_at_functions(rows, g)
        touched = slave.layout.on_cells(rows)
        return MortarOperators(kind, basis, D_mat, M_mat, gap, touched)


@dataclass
class MortarOperators:
    """Mortar operators of one kind.

    For the local kinds ``D``, ``M`` and ``gap`` are the operators themselves.
    For GLS/GLS* they are the slave-basis factors ``D_N``, ``M_N``, ``g_N``;
    the operators are ``S·D_N`` etc. with ``S = L⁻¹`` (GLS) or ``W L⁻¹`` (GLS*),
    applied by :meth:`nodal_gap` and :meth:`apply_S`. ``D`` carries a unit
    diagonal on rows no segment touches.
    """

    kind: BasisKind
    basis: MortarBasis
    D: PETSc.Mat
    M: PETSc.Mat
    gap_factor: FloatArray
    touched: npt.NDArray[np.bool_]

    @property
    def is_global(self) -> bool:
        return is_global(self.kind)

    def apply_S(self, values: FloatArray) -> FloatArray:
        """``S v`` for the global kinds (identity for the local ones)."""
        if not self.is_global:
            return values
        x = self.basis.mass_solver.solve(values)
        return x * self.basis.lumped_weights if self.kind == BasisKind.GLS_star else x

    def nodal_gap(self) -> FloatArray:
        """``g_A = ∫ M_A d`` at the local slave functions (zero off the contact)."""
        return self.apply_S(self.gap_factor)

    def transfer(self, master_values: PETSc.Vec) -> PETSc.Vec:
        """Slave values ``u_s`` with ``D u_s = M u_m`` (the mortar projection).

        For the global kinds ``S`` cancels, so ``D_N u_s = M_N u_m`` is solved.
        Rows of slave functions no segment touches keep 0.
        """
        rhs = self.D.createVecLeft()
        self.M.mult(master_values, rhs)
        ksp = PETSc.KSP().create(self.D.comm)
        ksp.setOperators(self.D)
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.setOptionsPrefix("dolfinx_mortar_transfer_")
        ksp.setFromOptions()
        out = self.D.createVecRight()
        ksp.solve(rhs, out)
        ksp.destroy()
        return out


def to_scipy(mat: PETSc.Mat):
    """A serial PETSc AIJ matrix as a SciPy CSR matrix (for inspection)."""
    import scipy.sparse
    if mat.comm.size > 1:
        raise ValueError("to_scipy needs a serial matrix; gather first")
    indptr, indices, data = mat.getValuesCSR()
    return scipy.sparse.csr_matrix((data, indices, indptr), shape=mat.getSize())
