"""Contact with an elastic master, bases and segmentation in the current configuration.

``basis_configuration="current"`` with a master surface (docs/DESIGN.md, §Finite
deformation): the segments, the projection χ and the averaged slave normals
all move with u. ``ĝ_A(u) = ∫ φ_A d`` and its exact first and second
derivatives with respect to every node it depends on — the slave cell's, the
nodes of the slave cells around it (through the averaged normals) and the
master cell's — come from the C++ kernel ``current_pair_gaps``: the same
templated segmentation that gives the values (``pair_segmentation.h``),
instantiated with a second-order forward-mode Jet, and chained through the
averaged nodal normals. This module only maps the pairs' variables to dofs and
assembles.

Lines of degree 1 and 2 in 2D; P1 triangles and Q1 quadrilaterals in 3D
(quadratic 3D facets would need Jets of 54–81 variables: not instantiated).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar import _kernels
from dolfinx_mortar.tolerance import NEAR_CONTACT
from dolfinx_mortar.contact.gap_sources.current.covered_assembly import (covered_gap,
                                                                          covered_hessian)
from dolfinx_mortar.contact.gap_sources.current.finite_deformation import CurrentSurfaceGap, SourceGaps
from dolfinx_mortar.contact.laws import PenaltyLaw, safe_weights
from dolfinx_mortar.kinds import BasisKind
from dolfinx_mortar.layout import assemble_blocks, assemble_global_blocks
from dolfinx_mortar.mortar.coupling import MortarCoupling, polynomial_degree, segment_quadrature
from dolfinx_mortar.mortar.pair_share import DealtPairs, deal_evenly, own_pairs
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: facet types with exact derivatives of the current-configuration gap in 3D
SUPPORTED_3D = ("P1 triangle", "Q1 quadrilateral")
#: the search radius of each slave facet, in its own diameters, when no
#: search_radius is given: surfaces further apart than that carry no force or
#: stiffness, and a penetration that deep is far outside a penalty solution
FACET_SEARCH_FACTOR = 2.0


@dataclass
class KeptPairs:
    """The pairs of one evaluation whose derivatives were computed: their slave
    cells, their indices in the coupling's pairs, the coupling they were
    found at, which of the coupling's pairs were kept, and the global dofs of
    their variables."""

    cells: IntArray
    pairs: IntArray
    coupling: MortarCoupling
    kept: npt.NDArray[np.bool_]
    dofs: Optional[IntArray] = None


class CurrentMortarGap(CurrentSurfaceGap):
    """Penalty contact with an elastic master in one mesh, everything on the
    current configuration, exact Jacobian.

    Parameters
    ----------
    slave, master
        The surfaces in the reference configuration (one displacement space).
    kind, law
        As for :class:`~dolfinx_mortar.contact.gap_sources.current.finite_deformation.CurrentSurfaceGap`
        (pointwise: ⟨d⟩ at the segment quadrature points, as with frozen bases).
    search_radius
        As for :class:`~dolfinx_mortar.mortar.coupling.MortarCoupling` (pairs are found
        again at every evaluation); default: each slave facet searches
        :data:`FACET_SEARCH_FACTOR` of its own diameters.
    boundary_modification
        The dual kinds with the nodal active set: their basis rebuilt over the
        covered part of each slave cell at every evaluation, exactly
        differentiated (:mod:`~dolfinx_mortar.contact.gap_sources.current.covered_dual`).
    """

    moving_pattern = True
    #: the segmentation and the Jets keep overlaps of any width, and must agree on it
    #: (a sliver's derivative is not round-off: docs/DESIGN.md, §Tolerances)
    KEEP_SLIVERS = True

    def __init__(self, slave: LagrangeSurface, master: LagrangeSurface, kind: BasisKind,
                 law: PenaltyLaw, search_radius: Optional[float] = None,
                 boundary_modification: bool = False):
        if slave.gdim == 3 and not (slave.reference.name in SUPPORTED_3D
                                    and master.reference.name in SUPPORTED_3D):
            raise NotImplementedError(
                "basis_configuration='current' with an elastic master in 3D is implemented "
                f"for {' and '.join(SUPPORTED_3D)} facets (got {slave.reference.name} and "
                f"{master.reference.name}): quadratic facets would need derivative types of "
                "54-81 variables per pair, which the kernels do not instantiate")
        if master.layout.size_global != slave.layout.size_global:
            raise ValueError("slave and master must share one displacement space (one mesh)")
        super().__init__(slave, kind, law)
        self.master, self.search_radius = master, search_radius
        #: validated with the options (ContactOptions.of): dual kinds, nodal set
        self.boundary_modification = boundary_modification
        #: the slave surface is its own master (pairs without a facet's neighbours)
        self.self_contact = master is slave
        # both surfaces relative to the slave's origin (CurrentSurfaceGap.origin)
        self._local_slave, self._local_master = slave.moved(-self.origin), master.moved(
            -self.origin)
        degree = polynomial_degree(slave) + max(polynomial_degree(slave),
                                                 polynomial_degree(master))
        self.segment_points, self.segment_weights = segment_quadrature(slave.tdim, degree)
    def pair_derivatives(self, coupling: MortarCoupling,
                         which: Optional[npt.NDArray[np.bool_]] = None,
                         with_hessian: bool = True, with_positive_part: bool = False
                         ) -> _kernels.PairGapDerivatives:
        """``c_A = ∫ N_A d`` of this rank's pairs of ``coupling`` (all, or those
        where ``which`` is True) with exact derivatives, computed here
        (:meth:`dealt_pair_derivatives`)."""
        return self.dealt_pair_derivatives(own_pairs(coupling, which), coupling.zero_length,
                                           with_hessian, with_positive_part)

    def dealt_pair_derivatives(self, dealt: DealtPairs, zero_length: float,
                               with_hessian: bool, with_positive_part: bool = False,
                               node_weights: Optional[FloatArray] = None,
                               with_mass: bool = False) -> _kernels.PairGapDerivatives:
        """``c_A = ∫ N_A d`` of the pairs ``dealt`` to this rank (any rank's:
        :func:`~dolfinx_mortar.mortar.pair_share.deal_evenly`) with exact
        derivatives (the Hessians only with ``with_hessian``).

        Returns the kernel's typed result: ``value`` (pairs, ns), ``gradient``
        (pairs, ns, nv), ``hessian`` (pairs, ns, nv, nv) and ``nodes`` (pairs,
        nv / gdim), the global node ids of the variables (slave cell, other
        slave nodes, master cell; −1 pads); with ``with_positive_part`` also
        ``value_plus`` and ``gradient_plus``, the same for ``c⁺_A = ∫ N_A ⟨d⟩``.
        With ``node_weights`` (pairs, ns): those of the one function
        ``Σ_A w_A c_A`` per pair instead (ns = 1), what a Newton matrix needs.
        """
        return dealt.gap_jets(self.segment_points, self.segment_weights, zero_length,
                              with_hessian=with_hessian, with_positive_part=with_positive_part,
                              axisymmetric=self.slave.axisymmetric, node_weights=node_weights,
                              with_mass=with_mass, keep_slivers=self.KEEP_SLIVERS)

    # -- CurrentSurfaceGap hooks ------------------------------------------------------------
    def _gap(self, u_nodes: FloatArray, W: FloatArray,
             surface: _kernels.SurfaceCellDerivatives) -> SourceGaps:
        slave, layout = self.slave, self.slave.layout
        # the pairs are found again at every evaluation, and only those near
        # contact matter: each facet searches two of its own diameters
        # (unless the user set a radius), not the largest facet's; the
        # candidates are segmented in equal shares over the ranks
        coupling = MortarCoupling(self._local_slave.moved(u_nodes),
                                  self._local_master.moved(u_nodes),
                                  search_radius=self.search_radius,
                                  facet_search_factor=(FACET_SEARCH_FACTOR
                                                       if self.search_radius is None
                                                       else None),
                                  keep_points=self.pointwise, self_contact=self.self_contact,
                                  deal_segmentation=True, keep_slivers=self.KEEP_SLIVERS)
        if self.boundary_modification:
            return covered_gap(self, coupling, W, surface.W)
        all_cells = slave.cells[coupling.pairs[:, 0]]
        # the values of every pair from the double kernel; derivatives only
        # where a node may carry contact force or stiffness
        g = layout.sum_at_functions(all_cells, coupling.raw_pairs[2] @ self.C)
        near = self.near_contact(g, W)
        if self.pointwise:
            # every node with a penetrating point in its support has ĝ⁺ ≠ 0,
            # whatever its mean gap: its pairs need derivatives too (decided
            # on the points' values, as the kernel's ⟨d⟩ is)
            points = coupling.points
            penetrating = np.zeros(len(coupling.pairs), dtype=bool)
            penetrating[points.pairs[points.gap > 0]] = True
            near |= layout.on_cells(all_cells[penetrating])
        kept = np.any(near[all_cells], axis=1)
        cells = all_cells[kept]
        ns = cells.shape[1]
        data = KeptPairs(cells, np.flatnonzero(kept), coupling, kept)
        g_plus = G_g_plus = None
        # the residual needs gradients only; _gap_hessian asks for the Hessians
        # when (and if) a Jacobian is assembled at this u
        if self.pointwise:
            # ĝ⁺ is summed at the nodes from the kept pairs' values, on the
            # rank that holds the pairs (not shared out: see _gap_hessian)
            r = self.pair_derivatives(coupling, kept, with_hessian=False,
                                      with_positive_part=True)
            dofs = self._variable_dofs(r.nodes, len(cells))
            nv = dofs.shape[1]
            grad = np.einsum("pbn,ba->pan", r.gradient.reshape(len(cells), ns, nv), self.C)
            G_g = assemble_blocks(layout, cells, self.dofs, dofs, grad)
            # ĝ⁺ from the kept pairs: every pair with a penetrating point is kept
            g_plus = layout.sum_at_functions(cells, r.value_plus @ self.C)
            grad_plus = np.einsum("pbn,ba->pan",
                                  r.gradient_plus.reshape(len(cells), ns, nv), self.C)
            G_g_plus = assemble_blocks(layout, cells, self.dofs, dofs, grad_plus)
        else:
            # the gradients are shared out over the ranks like the Hessians
            # (_gap_hessian): 25 times the cost of the values, where the
            # surfaces press, often on one rank
            dealt = deal_evenly(coupling, kept)
            r = self.dealt_pair_derivatives(dealt, coupling.zero_length, with_hessian=False)
            n = len(dealt.pairs)
            dofs = self._variable_dofs(r.nodes, n)
            nv = dofs.shape[1]
            # φ_a = Σ_b N_b C_ba
            grad = np.einsum("pbn,ba->pan", r.gradient.reshape(n, ns, nv), self.C)
            G_g = assemble_global_blocks(layout, dealt.rows, dofs, grad, cols=self.dofs)
        data.dofs = dofs
        return SourceGaps(g, G_g, layout.on_cells(all_cells), g_plus, G_g_plus, data)

    def near_contact(self, g: FloatArray, W: FloatArray) -> npt.NDArray[np.bool_]:
        """Nodes whose gap derivatives are needed: those that may get contact
        force or stiffness (:func:`~dolfinx_mortar.contact.newton.near_contact.stiffened_nodes`:
        y ≥ −NEAR_CONTACT·length), with a margin of 2 for the change of W
        between the reference and the current surface. The others' rows of
        ∂ĝ/∂u may be incomplete: they are multiplied by zero in the residual
        and in the Jacobian, and every evaluation decides again at its own u.
        Decided from the same ĝ on every rank. (Until 2026-11 the nodes within
        two element lengths were kept too: 5-10 times the pairs on Hertz 3D,
        for no entry that is used.)"""
        y = self.law.nodal_gaps(g, safe_weights(W))
        return y >= -2 * NEAR_CONTACT * self.basis.node_lengths

    def _variable_dofs(self, nodes: IntArray, num_pairs: int) -> IntArray:
        """Global dofs of the kernel's pair variables (``nodes``: pairs × variable
        nodes, −1 pads), shape (pairs, variable nodes · gdim)."""
        gdim = self.slave.gdim
        if nodes.shape[1] == 0:                 # no pair on this rank
            nodes = np.zeros((num_pairs, 1), dtype=np.int64)
        # padding slots carry zero derivatives: any valid dof will do
        nodes = np.where(nodes >= 0, nodes, nodes[:, :1])
        # explicit sizes: a rank may have no pair, and reshape(0, -1) is ambiguous
        return (nodes[..., None] * gdim + np.arange(gdim)).reshape(num_pairs,
                                                                   nodes.shape[1] * gdim)

    def _gap_hessian(self, source: SourceGaps, Fg: Optional[FloatArray],
                     FW: Optional[FloatArray] = None) -> PETSc.Mat:
        data = source.data
        if self.boundary_modification:
            return covered_hessian(self, data, Fg, FW)
        dofs = data.dofs
        if Fg is None:
            # the pattern: each kept pair's variables couple with each other
            blocks = np.zeros((len(dofs), dofs.shape[1], dofs.shape[1]))
            return assemble_global_blocks(self.dofs, dofs, dofs, blocks)
        cells = data.cells
        # Σ_a F_g,a ∂²ĝ_a = Σ_b (C F_g)_b ∂²c_b (C applied to the weights, a
        # small product, instead of to the Hessians)
        weights = Fg[cells] @ self.C.T
        # F_g = ε W^(m-k) max(y, 0) (nodal set) or ε W^(m-k) y⁺ (pointwise, a
        # sum over the penetrating points only) is exactly zero at a node with
        # no penetration: the positive part's own decision, not a tolerance.
        # A pair none of whose nodes has F_g ≠ 0 adds nothing, and its Hessian
        # (100-200 times the cost of its values) is skipped. On Hertz 3D these
        # are most of the pairs kept for the gradients.
        needed = np.any(Fg[cells] != 0.0, axis=1)
        which = np.zeros(len(data.kept), dtype=bool)
        which[data.pairs[needed]] = True
        # The Hessians are most of the contact work, and they sit where the
        # surfaces press, often on one rank: each rank takes an equal share of
        # all ranks' pairs, with the facets they read, instead of its own.
        dealt = deal_evenly(data.coupling, which, weights[needed])
        pairs, (weights,) = dealt.pairs, dealt.values
        # the kernel sums the weighted Hessians (one per pair, not ns)
        r = self.dealt_pair_derivatives(dealt, data.coupling.zero_length, with_hessian=True,
                                        node_weights=weights)
        n = len(pairs)
        dofs = self._variable_dofs(r.nodes, n)
        nv = dofs.shape[1]
        return assemble_global_blocks(self.dofs, dofs, dofs, r.hessian.reshape(n, nv, nv))
