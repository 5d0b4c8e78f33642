"""Penalty mortar contact terms for the Newton solver (docs/DESIGN.md, §Penalty contact).

With nodal gaps ``d̄_A`` and their derivative ``G = ∂d̄/∂u`` (a sparse matrix,
slave functions × displacement dofs), the penalty potential
``Π_c = Σ_A (ω_A/2) ⟨d̄_A⟩²`` gives

- residual ``R_c = Gᵀ (ω ⟨d̄⟩)``,
- Jacobian ``K_c = Gᵀ diag(ω H(d̄)) G + Σ_A ω_A ⟨d̄_A⟩ ∂²d̄_A/∂u²``,

exact for the nodal active set (semi-smooth Newton). The scalings:

- ``"consistent"``: ``d̄_A = ∫ M̄_A d`` with the unstarred partner ``M̄`` (a
  length) and ``ω_A = ε W_A``; a kind and its starred partner give the same
  problem;
- ``"seed"``: ``d_A = ∫ M_A d`` with the kind itself and ``ω_A = ε``.

Two gap models with bases frozen in one configuration: :class:`ObstacleGap`
(rigid analytic obstacle, exact and nonlinear in u) and :class:`MortarGap`
(elastic master, segmented once, linear in u). Both implement
:class:`~dolfinx_mortar.contact.gap_sources.source.GapSource`; so do
:class:`~dolfinx_mortar.contact.gap_sources.global_gap.GlobalGap` (GLS kinds) and the
current-configuration models.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.bases.basis import MortarBasis
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.contact.laws import PenaltyLaw
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import NodeLayout, assemble_blocks
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.contact.obstacles import RigidObstacle, relative_to
from dolfinx_mortar.contact.gap_sources.pointwise import point_gaps_of
from dolfinx_mortar.contact.gap_sources.slip import (SlipOperator, StepStart, dual_slip_blocks,
                                                     mortar_slip_operator, obstacle_slip_operator)
from dolfinx_mortar.kinds import DUAL_KINDS, is_global
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement
from dolfinx_mortar.linalg.sparse_products import TransposeProduct, transpose_mat_mult
from dolfinx_mortar.tolerance import local_origin

FloatArray = npt.NDArray[np.float64]


def dof_layout(nodes: NodeLayout, bs: int) -> NodeLayout:
    """The layout of the blocked dofs (node·bs + k) of a node layout."""
    ghosts = (nodes.ghosts[:, None] * bs + np.arange(bs)[None, :]).ravel()
    return NodeLayout(nodes.comm, nodes.num_owned * bs, ghosts)


def tangential_tractions(law: PenaltyLaw, state: ContactState) -> FloatArray:
    """``q_A = −f_T,A / W_A^k`` of the friction forces of ``state``, (nodes, gdim)."""
    force = -state.friction.mapping.force
    if law.k == 0:
        return force.copy()
    q = np.zeros_like(force)
    W = state.lumped_weights
    np.divide(force, W[:, None], out=q, where=(W > 0)[:, None])
    return q


class GapSourceBase:
    """Shared state: the slave surface, the gap basis and the node weights ω,
    and what the models with frozen bases share of
    :class:`~dolfinx_mortar.contact.gap_sources.source.GapSource`."""

    moving_pattern = False
    #: the segmentation against an elastic master (None against an obstacle)
    coupling = None
    #: the slip operator is made again at every load step (False: once per source)
    slip_operator_per_step = False
    def __init__(self, slave: LagrangeSurface, law: PenaltyLaw):
        self.slave = slave
        self.law = law
        self.basis = MortarBasis(law.gap_kind, slave)
        #: ω_A of Π_c = Σ (ω_A/2)⟨d̄_A⟩²
        self.weights = law.weights(self.basis.lumped_weights)
        self.dofs = dof_layout(slave.layout, slave.gdim)
        #: M̄ = N_std C_std on each slave cell (N_std: the displacement's basis)
        self.coefficients_std = slave.reference.standard_coefficients(self.basis.coefficients)
        self._stiffness_product = TransposeProduct()
        #: LmLS, LmLS*: against an obstacle the slip of a node from its own
        #: displacement (:func:`~dolfinx_mortar.contact.gap_sources.slip.lumped_slave_part`);
        #: against an elastic master in the dual basis (:meth:`MortarGap.slip_pair_operators`)
        self.lumped_slip = law.gap_kind not in DUAL_KINDS and not is_global(law.gap_kind)

    @property
    def node_lengths(self) -> FloatArray:
        """An element length per slave node (the scale of "near contact")."""
        return self.basis.node_lengths

    @property
    def lumped_weights(self) -> FloatArray:
        """``W_A = ∫ N_A`` of the configuration the bases live in (over the
        covered part with the boundary modification)."""
        return getattr(self, "_weights_source", self.basis.lumped_weights)

    def nodal_pressures(self, state: ContactState) -> FloatArray:
        """``p_A = ε⟨d̄_A⟩`` (nodal active set) or ``ε d̄⁺_A`` (pointwise),
        consistent scaling (:meth:`PenaltyLaw.pressure
        <dolfinx_mortar.contact.laws.penalty.PenaltyLaw.pressure>`)."""
        return self.law.pressure(state.weights, state.lumped_weights, state.gaps,
                                 state.gaps_plus)

    def tangential_tractions(self, state: ContactState) -> FloatArray:
        """``q_A = −f_T,A / W_A^k``, the coefficients of the tangential traction
        on the slave body, as ``p_A`` is of the pressure."""
        return tangential_tractions(self.law, state)

    def mortar_traction(self, state: ContactState) -> FloatArray:
        """``p* = Σ_A f_A M_A`` at the nodes of every slave cell, (cells, nodes)."""
        # M_A at node b of cell c is C[c, b, A]: N_std is 1 at its own node
        return np.einsum("cba,ca->cb", state.coefficients, state.force[self.slave.cells])

    def state(self, gaps: FloatArray, G: PETSc.Mat, force: FloatArray,
              mask: Optional[PETSc.Vec], gaps_plus: Optional[FloatArray] = None,
              G_plus: Optional[PETSc.Mat] = None,
              K_curv: Optional[PETSc.Mat] = None) -> ContactState:
        """The state from the gaps, their derivative and the nodal force:
        Dirichlet columns dropped, residual ``Gᵀ force``."""
        if mask is not None:
            G.diagonalScale(None, mask)
            if G_plus is not None:
                G_plus.diagonalScale(None, mask)
            if K_curv is not None:
                K_curv.diagonalScale(mask, mask)
        residual = G.createVecRight()
        G.multTranspose(self.slave.layout.vector(force), residual)
        return ContactState(gaps, G, force, residual, K_curv, gaps_plus, G_plus,
                            weights=self.weights, lumped_weights=self.lumped_weights,
                            covered=self.covered, coefficients=self.coefficients_std)

    def jacobian(self, state: ContactState, active: FloatArray, mask: Optional[PETSc.Vec],
                 geometric: bool = True) -> PETSc.Mat:
        """``Gᵀ diag(ωH) G`` (+ curvature); pointwise: ``Gᵀ diag(ω) G⁺``.

        With the pointwise set and no penetration anywhere G⁺ = 0: the nodal
        form with ``active`` stiffens the touching nodes instead.
        """
        G_right, weights = state.G, state.weights * active
        if state.gaps_plus is not None and self.any_penetration(state.gaps_plus):
            G_right, weights = state.G_plus, state.weights
        SG = G_right.copy()
        SG.diagonalScale(self.slave.layout.vector(weights), None)
        K = self._stiffness_product(state.G, SG)
        if state.K_curv is not None:
            K = K.copy()  # the product's own matrix keeps its pattern for the next reuse
            K.axpy(1.0, state.K_curv, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        return K

    def pattern(self, state: ContactState) -> PETSc.Mat:
        """A matrix with every entry the contact stiffness may have (``GᵀG``
        and the curvature: the pointwise ``GᵀG⁺`` and the nodal fallback are in it)."""
        K = transpose_mat_mult(state.G, state.G)
        if state.K_curv is not None:
            K.axpy(1.0, state.K_curv, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        return K

    def normal_force_derivative(self, state: ContactState, active: FloatArray) -> PETSc.Mat:
        """``∂f_N/∂u`` of the nodal normal forces ``f_N = ω⟨y⟩`` (slave nodes ×
        dofs, Dirichlet columns dropped), ``active`` (0/1) as H(y): ``diag(ωH) G``
        with W frozen (friction's cone follows it)."""
        D = state.G.copy()
        D.diagonalScale(self.slave.layout.vector(state.weights * active), None)
        return D

    def nodal_force(self, values: FloatArray) -> FloatArray:
        """The nodal force f of ``R_c = Gᵀ f`` for nodal values ω⟨d̄⟩ (here: themselves)."""
        return values

    def any_penetration(self, gaps_plus: FloatArray) -> bool:
        """Whether d̄⁺ ≠ 0 anywhere: else G⁺ = 0 and the nodal form stiffens."""
        n = self.slave.layout.num_owned
        return bool(self.slave.layout.comm.allreduce(bool(np.any(gaps_plus[:n] != 0))))

    def node_dofs(self, nodes: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
        """Global dofs (node·bs + k) of local nodes, shape nodes.shape + (bs,)."""
        g = self.slave.layout.global_indices[nodes]
        bs = self.slave.gdim
        return g[..., None] * bs + np.arange(bs)


class ObstacleGap(GapSourceBase):
    """Nodal gaps against a rigid analytic obstacle: ``d = −φ(x + u)``.

    Exact in u (no segmentation: the obstacle lies below every slave point).
    """

    #: the tangent planes are the obstacle's where each step starts
    slip_operator_per_step = True

    def __init__(self, slave: LagrangeSurface, obstacle: RigidObstacle, law: PenaltyLaw,
                 quadrature_degree: Optional[int] = None,
                 reference: Optional[FloatArray] = None):
        super().__init__(slave, law)
        #: nodal displacement that moved ``slave`` to its configuration (or None)
        self.reference = reference
        if obstacle.gdim != slave.gdim:
            raise ValueError(f"a {obstacle.gdim}D obstacle cannot touch a {slave.gdim}D body")
        self.obstacle = obstacle
        #: the points are relative to this point (and the obstacle with them), so that
        #: φ keeps the local digits far from the origin (tolerance.local_origin)
        self.origin = local_origin(slave.x, slave.layout.comm, slave.axisymmetric)
        self.tabulation = slave.moved(-self.origin).tabulate(
            quadrature_degree or 2 * slave.reference.degree + 2, transformed=False)
        tab = self.tabulation
        #: M̄_A at the quadrature points, per cell: (cells, points, functions)
        self.Mbar = np.einsum("cqb,cba->cqa", tab.phi, self.coefficients_std)
        #: slave nodes with something below them (here: all; the obstacle is unbounded)
        self.covered = slave.layout.on_cells(slave.cells)
        #: the active set's positive gaps (cells cut at d = 0 for the pointwise set)
        self.points = point_gaps_of(self)

    def slip_operator(self, start: StepStart, project: bool = True) -> SlipOperator:
        """Friction's slip operator of the step from ``start`` (``project``
        False: unprojected, for GLS)."""
        return obstacle_slip_operator(self, self.obstacle, start, self.lumped_slip, project)

    def evaluate(self, u, mask: Optional[PETSc.Vec]) -> ContactState:
        """The contact state at the displacement Function ``u``."""
        gaps, G, x, gaps_plus, G_plus = self.raw_gaps(u)
        force = self.law.force(self.weights, gaps, gaps_plus)
        return self.state(gaps, G, force, mask, gaps_plus, G_plus, self.curvature(force, x))

    def raw_gaps(self, u):
        """Nodal gaps, G, the current quadrature points, and (pointwise) d̄⁺, G⁺,
        at the displacement Function ``u``."""
        u_nodes = nodal_displacement(self.slave, u)
        gaps, G, x = self.nodal_gaps(u_nodes)
        gaps_plus, G_plus = self.points.positive_gaps(u.x.petsc_vec, u_nodes, x)
        return gaps, G, x, gaps_plus, G_plus

    def curvature(self, force: FloatArray, x: FloatArray) -> Optional[PETSc.Mat]:
        """``Σ_A f_A ∂²d̄_A/∂u²`` (None for a flat obstacle)."""
        blocks = self.curvature_blocks(force, x)
        if blocks is None:
            return None
        cells, gdim = self.slave.cells, self.slave.gdim
        nc, nd = cells.shape
        width = nd * gdim
        dofs = self.node_dofs(cells).reshape(nc, width)
        local = (cells[..., None] * gdim + np.arange(gdim)).reshape(nc, width)
        return assemble_blocks(self.dofs, local, self.dofs, dofs, blocks)

    def nodal_gaps(self, u_nodes: FloatArray) -> tuple[FloatArray, PETSc.Mat, FloatArray]:
        """Nodal gaps, G, and the current quadrature points (relative to
        :attr:`origin`).

        ``u_nodes``: displacement at the local slave-layout nodes, (nodes, gdim).
        """
        tab, cells = self.tabulation, self.slave.cells
        if self.reference is not None:  # the surface already carries the reference
            u_nodes = u_nodes - self.reference
        u_q = np.einsum("cqb,cbk->cqk", tab.phi, u_nodes[cells])
        x = (tab.points + u_q).reshape(-1, self.slave.gdim)
        nc, nq, nd = tab.phi.shape
        obstacle = relative_to(self.obstacle, self.origin)
        d = -obstacle.signed_distance(x).reshape(nc, nq)
        nu = obstacle.gradient(x).reshape(nc, nq, self.slave.gdim)
        wd = tab.weights * d
        gaps = self.slave.layout.sum_at_functions(cells, np.einsum("cqa,cq->ca", self.Mbar, wd))
        # ∂d̄_A/∂u_(B,k) = −Σ_q w M̄_A ν_k N_B
        blocks = -np.einsum("cq,cqa,cqk,cqb->cabk", tab.weights, self.Mbar, nu, tab.phi)
        G = assemble_blocks(self.slave.layout, cells, self.dofs,
                            self.node_dofs(cells).reshape(nc, nd * self.slave.gdim),
                            blocks.reshape(nc, nd, nd * self.slave.gdim))
        return gaps, G, x

    def curvature_blocks(self, coefficients: FloatArray, x: FloatArray) -> Optional[FloatArray]:
        """Element matrices of Σ_A c_A ∂²d̄_A/∂u², or None for a flat obstacle."""
        H = relative_to(self.obstacle, self.origin).hessian(x)
        # decided on every rank together: the matrix is assembled collectively, and a
        # rank without slave cells sees no curvature (2 ranks of DOLFINx 0.11 hung)
        if not self.slave.layout.comm.allreduce(bool(np.any(H)), op=MPI.LOR):
            return None
        tab, cells = self.tabulation, self.slave.cells
        nc, nq, nd = tab.phi.shape
        gdim = self.slave.gdim
        cM = np.einsum("ca,cqa->cq", coefficients[cells], self.Mbar) * tab.weights
        blocks = -np.einsum("cq,cqkl,cqb,cqe->cbkel", cM, H.reshape(nc, nq, gdim, gdim),
                            tab.phi, tab.phi)
        return blocks.reshape(nc, nd * gdim, nd * gdim)


class MortarGap(GapSourceBase):
    """Nodal gaps against an elastic master in the same mesh, small deformation.

    Segmented once, in the configuration of ``reference`` (the displacement
    the coupling was built with; None: the undeformed one), and linear about it:
    ``d̄_A(u) = d̄_A⁰ + n_A·(Σ_B D̄_AB Δu_B − Σ_C M̄_AC Δu_C)``, ``Δu = u − reference``.
    """

    def __init__(self, coupling: MortarCoupling, law: PenaltyLaw,
                 reference: Optional[PETSc.Vec] = None, boundary_modification: bool = False):
        self.reference = reference
        super().__init__(coupling.slave, law)
        if coupling.master.layout is not coupling.slave.layout and (
                coupling.master.layout.size_global != coupling.slave.layout.size_global):
            raise ValueError("MortarGap needs slave and master in one mesh (one displacement "
                             "space); two meshes are supported by MortarCoupling only")
        self.coupling = coupling
        self._weights_source = self.basis.lumped_weights
        if boundary_modification:
            # dual basis rebuilt over the covered part of every covered cell
            # (Popp et al. 2013); its ∫_cov M̄_A = 1 pairs it with W_cov
            self.coefficients_std = self.slave.reference.standard_coefficients(
                coupling.covered_coefficients(self.basis.kind))
            _, _, W_cov = coupling.covered_element_mass()
            self._weights_source = W_cov
            self.weights = law.weights(W_cov)
        C = self.coefficients_std[coupling.pairs[:, 0]]
        Dn, Mn, gn = coupling.raw_pairs
        Dg = np.einsum("pba,pbc->pac", C, Dn)        # ∫ M̄_A N_B
        Mg = np.einsum("pba,pbc->pac", C, Mn)        # ∫ M̄_A N^m_C
        g0 = np.einsum("pba,pb->pa", C, gn)
        slave_cells = self.slave.cells[coupling.pairs[:, 0]]
        self.gaps0 = self.slave.layout.sum_at_functions(slave_cells, g0)
        #: slave nodes with master below them; the others have no gap at all
        self.covered = self.slave.layout.on_cells(slave_cells)
        n = coupling.normals[slave_cells]                      # (pairs, ns, gdim)
        master_nodes = coupling.master_global_ids[coupling.master_cells[coupling.pairs[:, 1]]]
        bs = self.slave.gdim
        slave_dofs = self.node_dofs(slave_cells)              # (pairs, ns, bs)
        master_dofs = master_nodes[..., None] * bs + np.arange(bs)
        blocks = np.concatenate([np.einsum("pab,pak->pabk", Dg, n),
                                 -np.einsum("pac,pak->pack", Mg, n)], axis=2)
        npairs, ns = slave_cells.shape
        # explicit sizes: a rank may own no pair, and reshape(0, -1) is ambiguous
        width = (ns + master_nodes.shape[1]) * bs
        cols = np.concatenate([slave_dofs, master_dofs], axis=1).reshape(npairs, width)
        self.G = assemble_blocks(self.slave.layout, slave_cells, self.dofs, cols,
                                 blocks.reshape(npairs, ns, width))
        #: the pairs' slave cells, their columns (slave then master dofs) and
        #: the scalar couplings ``[D̄ | −M̄]`` (pairs, ns, ns + nm): friction's slip
        #: (:meth:`slip_pair_operators`)
        self.pair_operators = (slave_cells, cols, np.concatenate([Dg, -Mg], axis=2))
        #: the active set's positive gaps (the pointwise set's segment points)
        self.points = point_gaps_of(self)

    def slip_pair_operators(self, project: bool) -> tuple:
        """:attr:`pair_operators` in the basis friction measures the slip in: the
        kind's own (and unprojected, for GLS), or for LmLS and LmLS* the dual
        basis of the same ``∫ M̄_A`` (:func:`~dolfinx_mortar.contact.gap_sources.slip.dual_slip_blocks`
        says why)."""
        if self.lumped_slip and project:
            return dual_slip_blocks(self)
        return self.pair_operators

    def slip_operator(self, start: StepStart, project: bool = True) -> SlipOperator:
        """Friction's slip operator (``[D̄ | −M̄]`` of :meth:`slip_pair_operators`
        and the segmentation's normals, frozen with the bases; ``project``
        False: unprojected, for GLS)."""
        return mortar_slip_operator(self, project)

    def evaluate(self, u, mask: Optional[PETSc.Vec]) -> ContactState:
        """The contact state at the displacement Function ``u``."""
        gaps, G, _, gaps_plus, G_plus = self.raw_gaps(u)
        return self.state(gaps, G, self.law.force(self.weights, gaps, gaps_plus), mask,
                          gaps_plus, G_plus)

    def raw_gaps(self, u):
        """Nodal gaps, G (a copy), None (no curvature), and (pointwise) d̄⁺, G⁺."""
        u.x.scatter_forward()
        gaps = self.nodal_gaps(u.x.petsc_vec)
        gaps_plus, G_plus = self.points.positive_gaps(u.x.petsc_vec, None, None)
        return gaps, self.G.copy(), None, gaps_plus, G_plus

    def nodal_gaps(self, u: PETSc.Vec) -> FloatArray:
        """Nodal gaps at the local slave nodes for the displacement vector ``u``."""
        if self.reference is not None:
            u = u.copy()
            u.axpy(-1.0, self.reference)
        Gu = self.G.createVecLeft()
        self.G.mult(u, Gu)
        return self.gaps0 + self.slave.layout.to_local(Gu)
