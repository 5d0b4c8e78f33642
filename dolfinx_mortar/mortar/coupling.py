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
from petsc4py import PETSc

from dolfinx_mortar import _kernels
from dolfinx_mortar.bases.basis import MortarBasis
from dolfinx_mortar.kinds import BasisKind, KindLike, is_global, kind_name, parse_kind
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import assemble_blocks
from dolfinx_mortar.mortar.dealt_segmentation import dealt_segmentation, segmenter
from dolfinx_mortar.mortar.degenerate_facets import raise_on_degenerate_facets
from dolfinx_mortar.mortar.facet_search import candidate_pairs, near_in_surface, search_boxes
# the surfaces' copies live in surface_exchange, their geometry in surface_normals;
# these names stay importable here
from dolfinx_mortar.mortar.surface_exchange import (  # noqa: F401
    NearSurface, SurfaceCopy, gather_surface, largest_facet, whole_surface)
from dolfinx_mortar.mortar.surface_normals import (  # noqa: F401
    averaged_nodal_normals, cluster_diameters, clusters_and_bytes, current_coordinates,
    interface_nodal_normals, normal_clusters, swept_facet_boxes)
from dolfinx_mortar.tolerance import length_scale, zero_length

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


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
        The surfaces; the slave's cells must be owned by this rank; of the
        master, each rank receives the facets its slave facets may reach.
    slave_displacement, master_displacement
        Nodal displacements (local nodes, gdim) giving the configuration;
        ``None`` means the surfaces' own coordinates.
    search_radius
        How far along its normal a slave facet reaches for master facets;
        default the largest slave facet diameter (:func:`swept_facet_boxes`).
    facet_search_factor
        Instead of one ``search_radius``, pair each slave facet with the master
        facets within this multiple of its own diameter. On a graded mesh the
        largest facet sets the default radius for all (Hertz 3D, 52k dofs: 812k
        candidates for 6.9k pairs, against 70k with a factor of 2).
    quadrature_degree
        Degree of the rule on each segment; the default integrates the
        products of slave and master functions exactly on affine facets
        (triangles, lines, parallelograms). On other quadrilaterals the
        segments are mapped back through the bilinear inverse, the integrands
        are not polynomials and the integrals are exact only up to quadrature.
    opposing_normals_only
        Skip master facets that face the same way as the slave facet.
    keep_points
        Also keep every segment quadrature point (weight, gap, normal, basis
        values) in :attr:`points`, for the pointwise active set.
    interface_normals
        Measure gaps along the bisector of the slave normal and the opposite
        master normal instead of the slave normal alone
        (:func:`interface_nodal_normals`): the segmentation runs twice. For a
        configuration frozen before the bodies have flattened against each other.
    self_contact
        ``master`` is ``slave`` (a surface that may touch itself): pairs of facets
        that are neighbours on the surface are never candidates
        (:func:`~dolfinx_mortar.mortar.facet_search.near_in_surface`).
    whole_master
        Gather every rank's master facets on every rank (for comparisons), not
        only those the slave facets' search boxes meet, with a band (:class:`NearSurface`).
    deal_segmentation
        Segment all ranks' candidates in equal shares and return the pairs to
        their slave facets' ranks (:mod:`~dolfinx_mortar.mortar.dealt_segmentation`).
    keep_slivers
        Keep overlaps of any positive width, not only those wider than
        :attr:`zero_length` (the current configuration; docs/DESIGN.md, §Tolerances).

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
                 interface_normals: bool = False, self_contact: bool = False,
                 whole_master: bool = False, deal_segmentation: bool = False,
                 keep_slivers: bool = False):
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
        clusters, slave_near = clusters_and_bytes(slave, xs)
        #: the slave's normal clusters (global id → root id, the same on every
        #: rank); the slave cells near this rank's (all around its nodes, and a
        #: band), its own from ``first_own_slave_cell`` on: what its pairs' Jets read
        self.clusters = clusters
        self.slave_copy, self.first_own_slave_cell = slave_near.copy, slave_near.first_own_cell
        self.normals = averaged_nodal_normals(slave, xs, clusters)
        slave_cells = slave.cells.astype(np.int32)
        self.search_radius, slave_boxes = search_boxes(
            slave, xs, slave_cells, clusters, search_radius, facet_search_factor)
        if whole_master:
            master_copy, master_bytes = whole_surface(master, xm, with_volume=self_contact)
        else:
            near = NearSurface(master, xm, slave_boxes, largest_facet(master, xm),
                               with_volume=self_contact)
            master_copy, master_bytes = near.copy, near.received_bytes
        self.received_bytes = slave_near.received_bytes + master_bytes
        self.timings["normals_and_gather"] = time.perf_counter() - clock
        clock = time.perf_counter()
        #: the master facets this rank's slave facets may reach, with a band, one
        #: node copy per cell; ``received_bytes``: what this rank received for
        #: them, the slave's normal clusters and any dealt segmentation
        self.master_copy = master_copy
        self.master_global_ids, self.master_cells = master_copy.global_ids, master_copy.cells
        candidates = candidate_pairs(slave_boxes, master_copy)
        if self_contact:
            # a surface against itself: a facet's neighbours are never its partners
            candidates = candidates[~near_in_surface(slave, master_copy, candidates)]
        self.timings["search"] = time.perf_counter() - clock
        clock = time.perf_counter()
        degree = quadrature_degree or (polynomial_degree(slave)
                                       + max(polynomial_degree(slave),
                                             polynomial_degree(master)))
        points, weights = segment_quadrature(slave.tdim, degree)
        #: the length scale of every geometric decision, reduced over the ranks
        self.length_scale = max(length_scale(xs, comm),
                                length_scale(xm[np.unique(master.cells)], comm))
        #: lengths at or below this are zero (docs/DESIGN.md, §Tolerances)
        self.zero_length = zero_length(self.length_scale)
        def segment(normals: FloatArray, keep: bool, along_normals: bool):
            kernel = segmenter(slave, master, points, weights, opposing_normals_only,
                               self.length_scale, along_normals, keep_slivers)
            if deal_segmentation and comm.size > 1:
                dealt = dealt_segmentation(comm, kernel, xs, slave_cells, normals, master_copy,
                                           candidates, keep)
                self.received_bytes += dealt.received_bytes
                return dealt
            return kernel(xs, slave_cells, normals, master_copy.x, master_copy.cells,
                          candidates, keep)

        r = segment(self.normals, keep_points and not interface_normals, False)
        if interface_normals:
            # pairing and gap along the interface normals, not the facets' own
            raise_on_degenerate_facets(r, xs, slave_cells, master_copy, comm,
                                       self.zero_length, self.length_scale)
            self.normals = interface_nodal_normals(slave, self.normals, master_copy,
                                                   r.pairs, r.area, clusters)
            r = segment(self.normals, keep_points, True)
        raise_on_degenerate_facets(r, xs, slave_cells, master_copy, comm, self.zero_length,
                                   self.length_scale)
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
