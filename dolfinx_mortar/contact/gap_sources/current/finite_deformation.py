"""Contact against a rigid obstacle with the bases in the current configuration.

``basis_configuration="current"`` (docs/DESIGN.md, §Finite deformation): the slave
surface, its area element, its lumped weights W and therefore its mortar
functions follow the displacement u; the gap ``d = −φ(x + u)`` is exact. For
the local kinds every nodal gap is ``y_A = ĝ_A W_A^{−k}`` with
``ĝ_A = ∫ (N C)_A d da`` and ``W_A = ∫ N_A da`` on the current surface, and

    Π_c(u) = Σ_A (ε/2) W_A^m ⟨y_A⟩²

(consistent scaling: k = m = 1; seed scaling: k = 0 for the starred kinds,
k = 1 for the others, m = 0). C is the identity for LmLS/LmLS* and
``L_ref⁻¹ diag(W_ref)`` for the dual kinds — exact on affine facets only, so
the dual kinds need P1 lines or triangles here. The residual is ∂Π/∂u and
the Jacobian its exact second derivative, including the variation of the
area element and of W.

The derivatives are not written here: the area element, W and an obstacle's
gap are one templated C++ function of the cell's node coordinates
(``kernels/include/dolfinx_mortar/current_surface.h``), and its Jet
instantiation gives their exact gradients and Hessians, as the pair kernel
does for a master's gap; the law's derivatives in ĝ and W are
:class:`~dolfinx_mortar.contact.laws.penalty.PenaltyLaw`'s. This module
assembles them.

:class:`CurrentSurfaceGap` holds what does not depend on where the gap comes
from (W, the nodal energy, residual and Jacobian assembly);
:class:`CurrentObstacleGap` takes d from a rigid obstacle and
:class:`~dolfinx_mortar.contact.gap_sources.current.mortar.CurrentMortarGap` from an elastic
master. GLS/GLS* (L depends on u through every facet) are not covered.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Optional

import basix
import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar import _kernels
from dolfinx_mortar.contact.gap_sources.current.exact_jacobian import exact_jacobian
from dolfinx_mortar.contact.gap_sources.frozen import GapSourceBase
from dolfinx_mortar.contact.laws import PenaltyLaw, positive_part, safe_weights
from dolfinx_mortar.contact.gap_sources.slip import SlipOperator, StepStart
from dolfinx_mortar.contact.gap_sources.source import GapSource
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement
from dolfinx_mortar.kinds import DUAL_KINDS, BasisKind, is_global, kind_name
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import assemble_blocks
from dolfinx_mortar.tolerance import local_origin

FloatArray = npt.NDArray[np.float64]



@dataclass
class ObstaclePoints:
    """A rigid obstacle's gap ``d = −φ(x)`` at the quadrature points of every
    slave cell, with its derivatives with respect to the point."""

    d: FloatArray            #: (cells, points)
    gradient: FloatArray     #: (cells, points, gdim)
    hessian: FloatArray      #: (cells, points, gdim, gdim)

    def kernel_arguments(self) -> dict:
        return {"obstacle_d": self.d, "obstacle_gradient": self.gradient,
                "obstacle_hessian": self.hessian}


@dataclass
class SourceGaps:
    """What a gap source gives at one displacement: ``ĝ_A`` (summed over
    ranks), ``∂ĝ/∂u`` (slave rows × dofs, Dirichlet columns not yet dropped),
    the pointwise set's ``ĝ⁺`` and ``∂ĝ⁺/∂u`` (None with the nodal set), the
    slave nodes with something to touch, and what its Hessian needs."""

    g: FloatArray
    G_g: PETSc.Mat
    covered: npt.NDArray[np.bool_]
    g_plus: Optional[FloatArray] = None
    G_g_plus: Optional[PETSc.Mat] = None
    data: Any = None
    #: C of the gap basis φ = N C on every slave cell (None: the source's one C)
    coefficients: Optional[FloatArray] = None
    #: with a basis rebuilt over the covered part: ``W_A = ∫_cov N_A`` (0 where no
    #: pair covers the node), which replaces W where it is not 0, and ∂W/∂u there
    covered_weights: Optional[FloatArray] = None
    G_covered_weights: Optional[PETSc.Mat] = None

    def lumped_weights(self, W: FloatArray, G_W: Optional[PETSc.Mat] = None,
                       layout=None) -> tuple[FloatArray, FloatArray]:
        """The law's W: the cells' ``W`` (its derivative ``G_W``), with the covered
        part's where the source gives it; and per node, 1 where W is the cells' and
        0 where it is the pairs'. ``G_W``'s rows are made the same (in place)."""
        if self.covered_weights is None:
            return W, np.ones_like(W)
        on = self.covered_weights > 0      # 0 exactly where no pair covers the node
        from_cells = (~on).astype(np.float64)
        if G_W is not None:
            G_W.diagonalScale(layout.vector(from_cells), None)
            G_W.axpy(1.0, self.G_covered_weights,
                     structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        return np.where(on, self.covered_weights, W), from_cells


@dataclass
class CurrentState:
    """Nodal quantities and their derivatives at one displacement."""

    g: FloatArray            #: ĝ_A
    W: FloatArray            #: W_A on the current surface (its covered part: SourceGaps)
    y: FloatArray            #: nodal gaps ĝ_A W_A^{−k}
    G_g: PETSc.Mat           #: ∂ĝ/∂u
    G_W: PETSc.Mat           #: ∂W/∂u
    G_y: PETSc.Mat           #: ∂y/∂u
    residual: PETSc.Vec      #: ∂Π/∂u
    Fg: FloatArray           #: ∂F/∂ĝ_A at the local nodes
    FW: FloatArray           #: ∂F/∂W_A at the local nodes
    #: ∂F/∂W_A where W_A comes from the cells' own W (FW elsewhere: from the pairs)
    FW_cells: FloatArray
    x: FloatArray            #: (cells, nodes, gdim) the slave cells' current nodes
    obstacle: Optional[ObstaclePoints]  #: an obstacle's gap at their points
    source: SourceGaps       #: what the gap's source gave
    weights: FloatArray      #: ω = ε W^m on the current surface
    coefficients: FloatArray  #: M̄ = φ W^{−k} on every slave cell (the traction's)
    #: pointwise active set: y⁺ = ĝ⁺ W^{−k} with ĝ⁺_A = ∫ φ_A ⟨d⟩ da, and ∂y⁺/∂u
    y_plus: Optional[FloatArray] = None
    G_y_plus: Optional[PETSc.Mat] = None


class CurrentSurfaceGap(GapSourceBase):
    """Penalty contact with the bases on the current slave surface (base class).

    Subclasses give ``ĝ_A = ∫ φ_A d da`` and its derivatives
    (:meth:`_gap`, :meth:`_gap_hessian`); this class adds W, the nodal
    energy ``Σ_A (ε/2) W_A^m ⟨ĝ_A W_A^{−k}⟩²`` and its exact derivatives.

    Parameters
    ----------
    slave
        The slave surface in the reference configuration.
    kind
        The mortar kind; GLS kinds are not supported, dual kinds only on P1
        lines and triangles.
    law
        The penalty law (:class:`~dolfinx_mortar.contact.laws.penalty.PenaltyLaw`).
        With its pointwise active set (docs/DESIGN.md, §Active sets) the nodal
        pressures come from ``ĝ⁺_A = ∫ φ_A ⟨d⟩ da`` evaluated at the quadrature
        points (cells and segments are not split at d = 0). It has no
        potential; its virtual work is the nodal one with ``⟨y_A⟩`` replaced by
        ``y⁺_A = ĝ⁺_A W_A^{−k}``, so that it is the nodal model wherever every
        point of a node's support penetrates, and the Jacobian is its exact
        (unsymmetric) derivative.
    quadrature_degree
        Degree of the rule for W on every slave facet (default 2p + 2).
    """

    #: friction measures each step's slip on the source frozen where it starts
    slip_operator_per_step = True
    #: makes that source from a nodal displacement and the same as a vector
    #: (set where the source is chosen: :func:`~dolfinx_mortar.contact.gap_sources.choice.current_model`)
    frozen_at: Optional[Callable[[FloatArray, PETSc.Vec], GapSource]] = None

    def slip_operator(self, start: StepStart, project: bool = True) -> SlipOperator:
        """The slip operator of the source frozen where the step starts: Δy_T
        stays linear within a step, and a rotation within one step is seen as
        slip to first order in the step's rotation (docs/FRICTION.md)."""
        return self.frozen_at(start.u_nodes, start.u.copy()).slip_operator(start, project)

    def __init__(self, slave: LagrangeSurface, kind: BasisKind, law: PenaltyLaw,
                 quadrature_degree=None):
        if is_global(kind):
            raise NotImplementedError(
                f"basis_configuration='current' with {kind_name(kind)}: L(u) couples every "
                "slave facet and its linearization is not implemented; use a local kind")
        super().__init__(slave, law)
        #: the pointwise active set's virtual work instead of the nodal potential
        self.pointwise = law.pointwise
        self.kind = kind
        #: the geometry is computed relative to this point, so that x − o + u keeps
        #: u's digits far from the origin (translations change no gap or derivative)
        self.origin = local_origin(slave.x, slave.layout.comm, slave.axisymmetric)
        self.local_x = slave.x - self.origin
        ref = slave.reference
        affine = ref.degree == 1 and ref.cell in ("interval", "triangle")
        if self.kind in DUAL_KINDS and not affine:
            raise NotImplementedError(
                f"basis_configuration='current' with {kind_name(self.kind)} needs P1 lines or "
                f"triangles (the dual coefficients of a {ref.name} change with its shape)")
        if ref.transform is not None:
            raise NotImplementedError("basis_configuration='current' with the transformed "
                                      "quadratic basis is not implemented")
        if slave.axisymmetric and self.kind in DUAL_KINDS:
            raise NotImplementedError(
                f"basis_configuration='current' with axisymmetric=True and "
                f"{kind_name(self.kind)}: under 2πr ds the dual coefficients (L^e)⁻¹W^e "
                "change with u_r and their derivatives are not implemented; use LmLS or "
                "LmLS*, or 'initial'/'previous'")
        X, self.wq = basix.make_quadrature(ref.cell_type, quadrature_degree or 2 * ref.degree + 2)
        self.N, self.dN = ref.tabulate(X, transformed=False)       # (q, nd), (q, tdim, nd)
        if self.kind in DUAL_KINDS:
            L_ref = np.einsum("q,qa,qb->ab", self.wq, self.N, self.N)
            W_ref = self.wq @ self.N
            self.C = np.linalg.solve(L_ref, np.diag(W_ref))
        else:
            self.C = np.eye(self.N.shape[1])
        self.phi = self.N @ self.C                                 # φ_A = (N C)_A
        self.covered = slave.layout.on_cells(slave.cells)
        cells, gdim = slave.cells, slave.gdim
        nc, nd = cells.shape
        #: local and global dofs of every slave cell's nodes, (cells, nd·gdim)
        self.cell_dofs_local = (cells[..., None] * gdim + np.arange(gdim)).reshape(nc, nd * gdim)
        self.cell_dofs = self.node_dofs(cells).reshape(nc, nd * gdim)

    # -- what a gap source provides ------------------------------------------------------
    def _obstacle_at(self, x: FloatArray) -> Optional[ObstaclePoints]:
        """A rigid obstacle's gap at the quadrature points of the cells with
        current nodes ``x`` (cells, nodes, gdim); None where the gap comes
        from a master."""
        return None

    def _gap(self, u_nodes: FloatArray, W: FloatArray,
             cells: _kernels.SurfaceCellDerivatives) -> SourceGaps:
        """The gaps at ``u_nodes`` (local nodes); ``W`` the lumped weights there and
        ``cells`` the kernel's cell quantities (with the obstacle's gaps)."""
        raise NotImplementedError

    def _gap_hessian(self, source: SourceGaps, Fg: Optional[FloatArray],
                     FW: Optional[FloatArray] = None) -> Optional[PETSc.Mat]:
        """``Σ_A F_g,A ∂²ĝ_A/∂u²`` where it does not come with the cells' own
        (dofs × dofs, Dirichlet rows not yet dropped), and ``Σ_A F_W,A ∂²W_A``
        where W comes from the source (``source.covered_weights``); ``Fg=None``:
        a matrix with every entry it may have (values arbitrary). None: nothing
        beyond the cells'."""
        return None

    # -- cell quantities ---------------------------------------------------------------
    def _cells_at(self, u_nodes: FloatArray
                  ) -> tuple[FloatArray, Optional[ObstaclePoints],
                             _kernels.SurfaceCellDerivatives]:
        """The slave cells' current nodes (relative to :attr:`origin`), an
        obstacle's gap at their points, and
        W = ∫ N_a J (with an obstacle also ĝ = ∫ φ_a J d) of every cell with
        exact gradients (the kernels' Jets; the Hessians on demand, in
        :meth:`_cell_hessians`)."""
        x = np.ascontiguousarray((self.local_x + u_nodes)[self.slave.cells])
        obstacle = self._obstacle_at(x)
        extra = obstacle.kernel_arguments() if obstacle is not None else {}
        cells = _kernels.current_surface_cells(
            x, self.N, self.dN, self.wq, self.phi, self.slave.axisymmetric,
            positive_part=self.pointwise and obstacle is not None, **extra)
        return x, obstacle, cells

    def _cell_hessians(self, x: FloatArray, obstacle: Optional[ObstaclePoints],
                       FW: FloatArray, Fg: FloatArray) -> FloatArray:
        """``Σ_a F_W,a ∂²W_a (+ F_g,a ∂²ĝ_a against an obstacle)`` of every
        cell, (cells, variables, variables)."""
        cells = self.slave.cells
        extra = {}
        if obstacle is not None:
            extra = {**obstacle.kernel_arguments(), "gap_weights": Fg[cells]}
        return _kernels.current_surface_hessians(
            x, self.N, self.dN, self.wq, self.phi, FW[cells], self.slave.axisymmetric,
            **extra)

    def _lumped_weights(self, cells: _kernels.SurfaceCellDerivatives) -> FloatArray:
        """``W_A = ∫ N_A da`` summed at the nodes."""
        return self.slave.layout.sum_at_functions(self.slave.cells, cells.W)

    def evaluate(self, u, mask: Optional[PETSc.Vec]) -> ContactState:
        """The contact state at the displacement Function ``u``
        (:class:`CurrentState` in ``data``)."""
        current = self.evaluate_nodes(nodal_displacement(self.slave, u), mask)
        return ContactState(current.y, current.G_y,
                            self.law.force(current.weights, current.y, current.y_plus),
                            current.residual, gaps_plus=current.y_plus,
                            G_plus=current.G_y_plus, data=current, weights=current.weights,
                            lumped_weights=current.W, covered=current.source.covered,
                            coefficients=current.coefficients)

    def evaluate_nodes(self, u_nodes: FloatArray, mask: Optional[PETSc.Vec]) -> CurrentState:
        """Nodal gaps, their derivatives and the residual at ``u_nodes`` (local nodes).

        ``mask``: 1 on free dofs, 0 on Dirichlet dofs (columns to drop).
        """
        # a trial point that collapses a facet is refused by name, not by a
        # singular metric inside the area element
        self.slave.check_displaced(u_nodes)
        x, obstacle, surface = self._cells_at(u_nodes)
        cells, layout = self.slave.cells, self.slave.layout
        nc, nd = cells.shape
        W = self._lumped_weights(surface)
        G_W = assemble_blocks(layout, cells, self.dofs, self.cell_dofs, surface.W_gradient)
        source = self._gap(u_nodes, W, surface)
        W, from_cells = source.lumped_weights(W, G_W, layout)
        g, G_g, G_g_plus = source.g, source.G_g, source.G_g_plus
        if mask is not None:
            G_g.diagonalScale(None, mask)
            G_W.diagonalScale(None, mask)
            if G_g_plus is not None:
                G_g_plus.diagonalScale(None, mask)
        law, Wsafe = self.law, safe_weights(W)
        y, Fg, FW, _, _, _ = law.nodal_coefficients(g, Wsafe, np.zeros_like(g))
        y_plus = G_y_plus = None
        if self.pointwise:
            # the nodal virtual work with ⟨y⟩ replaced by y⁺ (see the class)
            y_plus = law.nodal_gaps(source.g_plus, Wsafe)
            Fg, FW = law.pointwise_coefficients(y_plus, Wsafe)[:2]
            G_y_plus = self._nodal_gap_derivative(G_g_plus, G_W, y_plus, Wsafe)
        residual = G_g.createVecRight()
        tmp = G_W.createVecRight()
        G_g.multTranspose(layout.vector(Fg), residual)
        G_W.multTranspose(layout.vector(FW), tmp)
        residual.axpy(1.0, tmp)
        G_y = self._nodal_gap_derivative(G_g, G_W, y, Wsafe)
        # M̄ = φ W^{-k}: the functions whose integrals are the nodal gaps y
        C = (source.coefficients if source.coefficients is not None
             else np.broadcast_to(self.C, (nc, nd, nd)))
        coefficients = law.nodal_gaps(C, Wsafe[cells][:, None, :])
        return CurrentState(g, W, y, G_g, G_W, G_y, residual, Fg, FW, FW * from_cells, x,
                            obstacle, source, law.weights(Wsafe), coefficients, y_plus,
                            G_y_plus)

    def _nodal_gap_derivative(self, G_g: PETSc.Mat, G_W: PETSc.Mat, y: FloatArray,
                              Wsafe: FloatArray) -> PETSc.Mat:
        """∂y/∂u of ``y = ĝ W^{−k}`` (also for y⁺ from ĝ⁺)."""
        layout = self.slave.layout
        by_g, by_W = self.law.nodal_gap_factors(y, Wsafe)
        G_y = G_g.copy()
        G_y.diagonalScale(layout.vector(by_g), None)
        if by_W is not None:
            scaled = G_W.copy()
            scaled.diagonalScale(layout.vector(by_W), None)
            G_y.axpy(1.0, scaled, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        return G_y

    def normal_force_derivative(self, state: ContactState, active: FloatArray) -> PETSc.Mat:
        """``∂f_N/∂u`` of ``f_N = ε W^m ⟨y⟩`` on the current surface:
        ``diag(ωH) ∂y/∂u + diag(ε m W^(m−1) ⟨y⟩) ∂W/∂u`` (``active`` as H(y))."""
        current, layout = state.data, self.slave.layout
        D = current.G_y.copy()
        D.diagonalScale(layout.vector(state.weights * active), None)
        by_W = self.law.weight_derivative(safe_weights(current.W)) * positive_part(current.y)
        scaled = current.G_W.copy()
        scaled.diagonalScale(layout.vector(by_W), None)
        D.axpy(1.0, scaled, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        scaled.destroy()
        return D

    def jacobian(self, state: ContactState, active: FloatArray, mask: Optional[PETSc.Vec],
                 geometric: bool = True) -> PETSc.Mat:
        """∂²Π/∂u² with ``active`` (0/1 per node) as the generalized H(y).

        ``geometric=False`` keeps only ``G_yᵀ diag(ωH) G_y``, the part that a
        frozen surface would give: positive semi-definite, for the iterations
        in which the active set still moves (see ContactTerm.assemble_jacobian).
        """
        return exact_jacobian(self, state, active, mask, geometric, structure_only=False)

    def pattern(self, state: ContactState) -> PETSc.Mat:
        """The exact Jacobian with every node active: every entry it may have."""
        return exact_jacobian(self, state, np.ones_like(state.gaps), None, True,
                              structure_only=True)

    def energy(self, u_nodes: FloatArray) -> float:
        """Π_c summed over all ranks (for checking the residual)."""
        _, _, surface = self._cells_at(u_nodes)
        W = self._lumped_weights(surface)
        source = self._gap(u_nodes, W, surface)
        g = source.g
        W = safe_weights(source.lumped_weights(W)[0])
        n = self.slave.layout.num_owned
        local = np.sum(self.law.energy(g, W)[:n])
        return float(self.slave.layout.comm.allreduce(local))
