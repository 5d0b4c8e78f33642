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
area element (``∂J/∂F = J F G⁻¹`` with ``G = FᵀF``) and of W.

:class:`CurrentSurfaceGap` holds what does not depend on where the gap comes
from (W, the nodal energy, residual and Jacobian assembly);
:class:`CurrentObstacleGap` takes d from a rigid obstacle and
:class:`~dolfinx_mortar.contact.current_mortar.CurrentMortarGap` from an elastic
master. GLS/GLS* (L depends on u through every facet) are not covered.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import basix
import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.gaps import GapModelBase
from dolfinx_mortar.contact.penalty_law import PenaltyLaw, safe_weights
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement
from dolfinx_mortar.kinds import DUAL_KINDS, BasisKind, is_global, kind_name
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import assemble_blocks
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.sparse_products import transpose_mat_mult

FloatArray = npt.NDArray[np.float64]



def area_element_derivatives(F: FloatArray, second: bool = True
                             ) -> tuple[FloatArray, FloatArray, Optional[FloatArray]]:
    """``J = sqrt(det FᵀF)`` and its first and second derivatives with respect to F.

    ``F``: (..., gdim, tdim). Returns J (...), dJ (..., gdim, tdim) and
    d2J (..., gdim, tdim, gdim, tdim), or None for d2J unless ``second``.
    With ``P = F G⁻¹``:
    ``∂J/∂F_ia = J P_ia`` and
    ``∂²J/∂F_ia∂F_jb = J (P_ia P_jb + δ_ij G⁻¹_ab − P_ib P_ja − (P Fᵀ)_ij G⁻¹_ab)``.
    """
    G = np.einsum("...ia,...ib->...ab", F, F)
    Ginv = np.linalg.inv(G)
    J = np.sqrt(np.linalg.det(G))
    P = F @ Ginv
    dJ = J[..., None, None] * P
    if not second:
        return J, dJ, None
    gdim = F.shape[-2]
    delta = np.eye(gdim)
    PF = np.einsum("...ia,...ja->...ij", P, F)
    d2J = (np.einsum("...ia,...jb->...iajb", P, P)
           + np.einsum("ij,...ab->...iajb", delta, Ginv)
           - np.einsum("...ib,...ja->...iajb", P, P)
           - np.einsum("...ij,...ab->...iajb", PF, Ginv))
    return J, dJ, J[..., None, None, None, None] * d2J


@dataclass
class CurrentState:
    """Nodal quantities and their derivatives at one displacement."""

    g: FloatArray            #: ĝ_A
    W: FloatArray            #: W_A on the current surface
    y: FloatArray            #: nodal gaps ĝ_A W_A^{−k}
    G_g: PETSc.Mat           #: ∂ĝ/∂u
    G_W: PETSc.Mat           #: ∂W/∂u
    G_y: PETSc.Mat           #: ∂y/∂u
    residual: PETSc.Vec      #: ∂Π/∂u
    Fg: FloatArray           #: ∂F/∂ĝ_A at the local nodes
    FW: FloatArray           #: ∂F/∂W_A at the local nodes
    element: dict            #: area-element arrays the second derivatives of W need
    gap_data: object         #: what the gap's source needs for Σ_A F_g,A ∂²ĝ_A
    weights: FloatArray      #: ω = ε W^m on the current surface
    covered: npt.NDArray[np.bool_]  #: slave nodes with something to touch at this u
    coefficients: FloatArray  #: M̄ = φ W^{−k} on every slave cell (the traction's)
    #: pointwise active set: y⁺ = ĝ⁺ W^{−k} with ĝ⁺_A = ∫ φ_A ⟨d⟩ da, and ∂y⁺/∂u
    y_plus: Optional[FloatArray] = None
    G_y_plus: Optional[PETSc.Mat] = None


class CurrentSurfaceGap(GapModelBase):
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
        The penalty law (:class:`~dolfinx_mortar.contact.penalty_law.PenaltyLaw`).
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

    def __init__(self, slave: LagrangeSurface, kind: BasisKind, law: PenaltyLaw,
                 quadrature_degree=None):
        if is_global(kind):
            raise NotImplementedError(
                f"basis_configuration='current' with {kind_name(kind)}: L(u) couples every "
                "slave facet and its linearization is not implemented; use a local kind")
        super().__init__(slave, law)
        self.kind = kind
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
    def _gap(self, u_nodes: FloatArray, e: dict
             ) -> tuple[FloatArray, PETSc.Mat, object, npt.NDArray[np.bool_]]:
        """``ĝ_A`` at the local nodes (summed over ranks), ``∂ĝ/∂u`` (slave rows ×
        dofs, Dirichlet columns not yet dropped), data for :meth:`_gap_hessian`
        (with :attr:`pointwise` also ``"g_plus"``, ĝ⁺ summed over ranks, and
        ``"G_g_plus"``, ∂ĝ⁺/∂u) and the slave nodes with something to touch at u."""
        raise NotImplementedError

    def _gap_hessian(self, data: object, Fg: Optional[FloatArray]) -> PETSc.Mat:
        """``Σ_A F_g,A ∂²ĝ_A/∂u²`` (dofs × dofs, Dirichlet rows not yet dropped);
        ``Fg=None``: a matrix with every entry it may have (values arbitrary)."""
        raise NotImplementedError

    # -- element quantities ------------------------------------------------------------
    def _elements(self, u_nodes: FloatArray) -> dict:
        """Area element J of every slave cell at the quadrature points, with its
        first derivatives with respect to the cell's node positions; the second
        ones on demand (:meth:`_element_hessians`: a residual needs none, and
        they were 17% of the current configuration's contact work)."""
        x = (self.slave.x + u_nodes)[self.slave.cells]              # (c, nd, gdim)
        F = np.einsum("cbi,qab->cqia", x, self.dN)                  # (c, q, gdim, tdim)
        J, dJdF, _ = area_element_derivatives(F, second=False)
        # chain rule through F = Σ_b x_b ⊗ ∇N_b
        dJ = np.einsum("cqia,qab->cqbi", dJdF, self.dN)             # (c, q, nd, gdim)
        xq = np.einsum("qb,cbi->cqi", self.N, x)
        e = {"F": F, "x": xq, "J": J, "dJ": dJ}
        if self.slave.axisymmetric:
            R, dR = self._revolution(xq)
            e["meridian_dJ"] = dJ                          # of J before the factor 2πr
            e["J"] = J * R
            e["dJ"] = dJ * R[..., None, None] + J[..., None, None] * dR[None]
        return e

    def _element_hessians(self, e: dict) -> FloatArray:
        """∂²J of :meth:`_elements`' ``e`` (c, q, nd, gdim, nd, gdim), computed
        once and kept in ``e``."""
        if "d2J" not in e:
            _, _, d2JdF = area_element_derivatives(e["F"])
            d2J = np.einsum("nqiajc,qab,qce->nqbiej", d2JdF, self.dN, self.dN,
                            optimize=True)
            if self.slave.axisymmetric:
                # (J R)'' = J'' R + J' ⊗ R' + R' ⊗ J' (R is linear in the nodes)
                R, dR = self._revolution(e["x"])
                dJ = e["meridian_dJ"]
                d2J = (d2J * R[..., None, None, None, None]
                       + np.einsum("cqbi,qej->cqbiej", dJ, dR)
                       + np.einsum("qbi,cqej->cqbiej", dR, dJ))
            e["d2J"] = d2J
        return e["d2J"]

    def _revolution(self, xq: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The factor 2πr of an (r, z) meridian's surface of revolution at each
        point, ``r = Σ_b N_b x_b,r`` (clamped at 0 as in
        :meth:`LagrangeSurface.radial_factor`: an axis node may sit at −1e-17),
        and its derivative with respect to the cell's nodes (q, nd, gdim)."""
        R = 2 * np.pi * np.maximum(xq[..., 0], 0.0)                 # (c, q)
        dR = np.zeros(self.N.shape + (self.slave.gdim,))            # (q, nd, gdim)
        dR[..., 0] = 2 * np.pi * self.N
        return R, dR

    def _lumped_weights(self, e: dict) -> FloatArray:
        """``W_A = ∫ N_A da`` on the surface of the element quantities ``e``."""
        return self.slave.layout.sum_at_functions(
            self.slave.cells, np.einsum("cq,qa->ca", self.wq[None, :] * e["J"], self.N))

    def evaluate(self, u, mask: Optional[PETSc.Vec]) -> ContactState:
        """The contact state at the displacement Function ``u``
        (:class:`CurrentState` in ``data``)."""
        current = self.evaluate_nodes(nodal_displacement(self.slave, u), mask)
        return ContactState(current.y, current.G_y,
                            self.law.force(current.weights, current.y, current.y_plus),
                            current.residual, gaps_plus=current.y_plus,
                            G_plus=current.G_y_plus, data=current, weights=current.weights,
                            lumped_weights=current.W, covered=current.covered,
                            coefficients=current.coefficients)

    def evaluate_nodes(self, u_nodes: FloatArray, mask: Optional[PETSc.Vec]) -> CurrentState:
        """Nodal gaps, their derivatives and the residual at ``u_nodes`` (local nodes).

        ``mask``: 1 on free dofs, 0 on Dirichlet dofs (columns to drop).
        """
        # a trial point that collapses a facet is refused by name, not by a
        # singular metric inside the area element
        self.slave.check_displaced(u_nodes)
        e = self._elements(u_nodes)
        cells, layout = self.slave.cells, self.slave.layout
        nc, nd = cells.shape
        gdim = self.slave.gdim
        g, G_g, gap_data, covered = self._gap(u_nodes, e)
        W = self._lumped_weights(e)
        dW_c = np.einsum("q,qa,cqbi->cabi", self.wq, self.N, e["dJ"])
        G_W = assemble_blocks(layout, cells, self.dofs, self.cell_dofs,
                              dW_c.reshape(nc, nd, nd * gdim))
        G_g_plus = gap_data["G_g_plus"] if self.pointwise else None
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
            y_plus = law.nodal_gaps(gap_data["g_plus"], Wsafe)
            Fg, FW = law.pointwise_coefficients(y_plus, Wsafe)[:2]
            G_y_plus = self._nodal_gap_derivative(G_g_plus, G_W, y_plus, Wsafe)
        residual = G_g.createVecRight()
        tmp = G_W.createVecRight()
        G_g.multTranspose(layout.vector(Fg), residual)
        G_W.multTranspose(layout.vector(FW), tmp)
        residual.axpy(1.0, tmp)
        G_y = self._nodal_gap_derivative(G_g, G_W, y, Wsafe)
        # M̄ = φ W^{-k}: the functions whose integrals are the nodal gaps y
        coefficients = law.nodal_gaps(np.broadcast_to(self.C, (nc, nd, nd)),
                                      Wsafe[cells][:, None, :])
        return CurrentState(g, W, y, G_g, G_W, G_y, residual, Fg, FW, e, gap_data,
                            law.weights(Wsafe), covered, coefficients, y_plus, G_y_plus)

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

    def jacobian(self, state: ContactState, active: FloatArray, mask: Optional[PETSc.Vec],
                 geometric: bool = True) -> PETSc.Mat:
        """∂²Π/∂u² with ``active`` (0/1 per node) as the generalized H(y).

        ``geometric=False`` keeps only ``G_yᵀ diag(ωH) G_y``, the part that a
        frozen surface would give: positive semi-definite, for the iterations
        in which the active set still moves (see ContactTerm.assemble_jacobian).
        """
        return self._jacobian(state, active, mask, geometric, structure_only=False)

    def _jacobian(self, state: ContactState, active: FloatArray, mask: Optional[PETSc.Vec],
                  geometric: bool, structure_only: bool) -> PETSc.Mat:
        """:meth:`jacobian`; ``structure_only``: every entry it may have, with
        the gap's second derivatives as structural zeros (not computed)."""
        weights, state = state.weights, state.data
        layout = self.slave.layout
        # pointwise: while nothing penetrates, G⁺ = 0 and the nodal form
        # (non-geometric) stiffens the touching nodes instead, as when frozen
        pointwise = (self.pointwise and not structure_only
                     and self.any_penetration(state.y_plus))
        if self.pointwise and not structure_only and not pointwise:
            geometric = False
        if not geometric:
            right = (state.G_y_plus if pointwise else state.G_y).copy()
            right.diagonalScale(layout.vector(weights * (1.0 if pointwise else active)),
                                None)
            return transpose_mat_mult(state.G_y, right)

        def scaled(M: PETSc.Mat, s: FloatArray) -> PETSc.Mat:
            out = M.copy()
            out.diagonalScale(layout.vector(s), None)
            return out

        Different = PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
        if pointwise:
            # ∂F_g = a1 ∂y⁺ + b1 ∂W and ∂F_W = a2 ∂y⁺ + b2 ∂W of the pointwise
            # virtual work's coefficients
            _, _, a1, b1, a2, b2 = self.law.pointwise_coefficients(state.y_plus,
                                                                   safe_weights(state.W))
            left = scaled(state.G_y_plus, a1)
            left.axpy(1.0, scaled(state.G_W, b1), structure=Different)
            right = scaled(state.G_y_plus, a2)
            right.axpy(1.0, scaled(state.G_W, b2), structure=Different)
        else:
            _, _, _, Fgg, FgW, FWW = self.law.nodal_coefficients(state.g, safe_weights(state.W),
                                                                 active)
            # outer products: G_gᵀ(Fgg G_g + FgW G_W) + G_Wᵀ(FgW G_g + FWW G_W)
            left = scaled(state.G_g, Fgg)
            left.axpy(1.0, scaled(state.G_W, FgW), structure=Different)
            right = scaled(state.G_g, FgW)
            right.axpy(1.0, scaled(state.G_W, FWW), structure=Different)
        K = transpose_mat_mult(state.G_g, left)
        K.axpy(1.0, transpose_mat_mult(state.G_W, right), structure=Different)
        # second derivatives: Σ_A F_W,A ∂²W_A here, Σ_A F_g,A ∂²ĝ_A from the source
        cells = self.slave.cells
        nc, nd = cells.shape
        width = nd * self.slave.gdim
        b = np.einsum("ca,qa->cq", state.FW[cells], self.N)
        blocks = np.einsum("cq,cqbiej->cbiej", self.wq[None, :] * b,
                           self._element_hessians(state.element))
        K_el = assemble_blocks(self.dofs, self.cell_dofs_local, self.dofs, self.cell_dofs,
                               blocks.reshape(nc, width, width))
        K_el.axpy(1.0, self._gap_hessian(state.gap_data, None if structure_only else state.Fg),
                  structure=Different)
        if mask is not None:
            K_el.diagonalScale(mask, mask)
            K.diagonalScale(mask, mask)
        K.axpy(1.0, K_el, structure=Different)
        return K

    def pattern(self, state: ContactState) -> PETSc.Mat:
        """The exact Jacobian with every node active: every entry it may have."""
        return self._jacobian(state, np.ones_like(state.gaps), None, True, structure_only=True)

    def energy(self, u_nodes: FloatArray) -> float:
        """Π_c summed over all ranks (for checking the residual)."""
        e = self._elements(u_nodes)
        g = self._gap(u_nodes, e)[0]
        W = safe_weights(self._lumped_weights(e))
        n = self.slave.layout.num_owned
        local = np.sum(self.law.energy(g, W)[:n])
        return float(self.slave.layout.comm.allreduce(local))



class CurrentObstacleGap(CurrentSurfaceGap):
    """Penalty contact with a rigid obstacle, bases on the current surface.

    ``d = −φ(x + u)`` with φ the obstacle's exact signed distance, integrated
    with the slave cell's own rule. Parameters as for
    :class:`CurrentSurfaceGap`, plus the ``obstacle``.
    """

    def __init__(self, slave: LagrangeSurface, obstacle: RigidObstacle, kind: BasisKind,
                 law: PenaltyLaw, quadrature_degree=None):
        if obstacle.gdim != slave.gdim:
            raise ValueError(f"a {obstacle.gdim}D obstacle cannot touch a {slave.gdim}D body")
        super().__init__(slave, kind, law, quadrature_degree)
        self.obstacle = obstacle

    def _gap(self, u_nodes: FloatArray, e: dict
             ) -> tuple[FloatArray, PETSc.Mat, dict, npt.NDArray[np.bool_]]:
        cells, layout = self.slave.cells, self.slave.layout
        nc, nd = cells.shape
        gdim = self.slave.gdim
        flat = e["x"].reshape(-1, gdim)
        nq = e["x"].shape[1]
        d = -self.obstacle.signed_distance(flat).reshape(nc, nq)
        grad = -self.obstacle.gradient(flat).reshape(nc, nq, gdim)
        hess = -self.obstacle.hessian(flat).reshape(nc, nq, gdim, gdim)
        wJ = self.wq[None, :] * e["J"]
        g = layout.sum_at_functions(cells, np.einsum("cq,qa->ca", wJ * d, self.phi))
        v = np.einsum("cqi,qb->cqbi", grad, self.N)                 # ∇d_i N_b
        dg_c = (np.einsum("q,qa,cq,cqbi->cabi", self.wq, self.phi, d, e["dJ"])
                + np.einsum("q,qa,cq,cqbi->cabi", self.wq, self.phi, e["J"], v))
        G_g = assemble_blocks(layout, cells, self.dofs, self.cell_dofs,
                              dg_c.reshape(nc, nd, nd * gdim))
        data = {"e": e, "d": d, "v": v, "hess": hess}
        if self.pointwise:
            # ⟨d⟩ and its derivative H(d)∇d at the same points (not split at d = 0)
            penetrating = d > 0
            dp = np.where(penetrating, d, 0.0)
            data["g_plus"] = layout.sum_at_functions(
                cells, np.einsum("cq,qa->ca", wJ * dp, self.phi))
            dgp_c = (np.einsum("q,qa,cq,cqbi->cabi", self.wq, self.phi, dp, e["dJ"])
                     + np.einsum("q,qa,cq,cqbi->cabi", self.wq, self.phi,
                                 e["J"] * penetrating, v))
            data["G_g_plus"] = assemble_blocks(layout, cells, self.dofs, self.cell_dofs,
                                               dgp_c.reshape(nc, nd, nd * gdim))
        return g, G_g, data, self.covered

    def _gap_hessian(self, data: dict, Fg: Optional[FloatArray]) -> PETSc.Mat:
        e, d, v = data["e"], data["d"], data["v"]
        if Fg is None:                      # the pattern: every cell's block
            Fg = np.ones(self.slave.layout.size_local)
        cells = self.slave.cells
        nc, nd = cells.shape
        width = nd * self.slave.gdim
        wa = self.wq[None, :] * np.einsum("ca,qa->cq", Fg[cells], self.phi)
        blocks = (np.einsum("cq,cqbiej->cbiej", wa * d, self._element_hessians(e))
                  + np.einsum("cq,cqbi,cqej->cbiej", wa, e["dJ"], v)
                  + np.einsum("cq,cqbi,cqej->cbiej", wa, v, e["dJ"])
                  + np.einsum("cq,cq,cqij,qb,qe->cbiej", wa, e["J"], data["hess"], self.N,
                              self.N))
        return assemble_blocks(self.dofs, self.cell_dofs_local, self.dofs, self.cell_dofs,
                               blocks.reshape(nc, width, width))
