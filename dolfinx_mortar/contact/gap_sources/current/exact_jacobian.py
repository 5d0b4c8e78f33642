"""The exact Jacobian of the contact potential with the bases on the current
surface: the outer products of the first derivatives of ĝ and W and their
second derivatives from the cells and the pairs (docs/DESIGN.md, §Finite deformation)."""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.laws import safe_weights
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.layout import assemble_blocks
from dolfinx_mortar.linalg.sparse_products import transpose_mat_mult

FloatArray = npt.NDArray[np.float64]


def exact_jacobian(source, state: ContactState, active: FloatArray, mask: Optional[PETSc.Vec],
                   geometric: bool, structure_only: bool) -> PETSc.Mat:
    """∂²Π/∂u² of a current-surface source
    (:meth:`CurrentSurfaceGap.jacobian
    <dolfinx_mortar.contact.gap_sources.current.finite_deformation.CurrentSurfaceGap.jacobian>`);
    ``structure_only``: every entry it may have, with the gap's second
    derivatives as structural zeros (not computed)."""
    weights, state = state.weights, state.data
    layout = source.slave.layout
    # pointwise: while nothing penetrates, G⁺ = 0 and the nodal form
    # (non-geometric) stiffens the touching nodes instead, as when frozen
    pointwise = (source.pointwise and not structure_only
                 and source.any_penetration(state.y_plus))
    if source.pointwise and not structure_only and not pointwise:
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
        _, _, a1, b1, a2, b2 = source.law.pointwise_coefficients(state.y_plus,
                                                               safe_weights(state.W))
        left = scaled(state.G_y_plus, a1)
        left.axpy(1.0, scaled(state.G_W, b1), structure=Different)
        right = scaled(state.G_y_plus, a2)
        right.axpy(1.0, scaled(state.G_W, b2), structure=Different)
    else:
        _, _, _, Fgg, FgW, FWW = source.law.nodal_coefficients(state.g, safe_weights(state.W),
                                                             active)
        # outer products: G_gᵀ(Fgg G_g + FgW G_W) + G_Wᵀ(FgW G_g + FWW G_W)
        left = scaled(state.G_g, Fgg)
        left.axpy(1.0, scaled(state.G_W, FgW), structure=Different)
        right = scaled(state.G_g, FgW)
        right.axpy(1.0, scaled(state.G_W, FWW), structure=Different)
    K = transpose_mat_mult(state.G_g, left)
    K.axpy(1.0, transpose_mat_mult(state.G_W, right), structure=Different)
    # second derivatives: Σ_A F_W,A ∂²W_A (and an obstacle's Σ_A F_g,A ∂²ĝ_A)
    # from the cells, a master's Σ_A F_g,A ∂²ĝ_A from the pairs
    if structure_only:
        width = source.cell_dofs.shape[1]
        blocks = np.zeros((len(source.cell_dofs), width, width))
    else:
        blocks = source._cell_hessians(state.x, state.obstacle, state.FW_cells, state.Fg)
    K_el = assemble_blocks(source.dofs, source.cell_dofs_local, source.dofs, source.cell_dofs,
                           blocks)
    pairs = source._gap_hessian(state.source, None if structure_only else state.Fg,
                                None if structure_only else state.FW)
    if pairs is not None:
        K_el.axpy(1.0, pairs, structure=Different)
    if mask is not None:
        K_el.diagonalScale(mask, mask)
        K.diagonalScale(mask, mask)
    K.axpy(1.0, K_el, structure=Different)
    return K
