"""Assembly of the current-surface gaps with the dual basis rebuilt over the
covered part (:mod:`~dolfinx_mortar.contact.gap_sources.current.covered_dual`):
the pairs' Jets of ``c`` and ``L`` from the kernel (``with_mass``), combined
per slave cell with its coefficients, dealt out over the ranks as the
unmodified gaps' are (:meth:`CurrentMortarGap._gap
<dolfinx_mortar.contact.gap_sources.current.mortar.CurrentMortarGap>`)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.gap_sources.current.covered_dual import CoveredDual
from dolfinx_mortar.contact.gap_sources.current.finite_deformation import SourceGaps
from dolfinx_mortar.layout import NodeLayout, assemble_global_blocks
from dolfinx_mortar.linalg.sparse_products import transpose_mat_mult
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.mortar.pair_share import deal_evenly

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


@dataclass
class CoveredPairs:
    """What the Hessian of one evaluation needs: the coupling, its pairs' slave
    cells, which pairs were kept for derivatives, the cells' rebuilt bases, and
    Q, the gradients of every cell's ``(c, L)`` (rows: cell quantities in
    ``quantities``, columns: dofs)."""

    coupling: MortarCoupling
    pair_cells: IntArray
    kept: npt.NDArray[np.bool_]
    dual: CoveredDual
    quantities: NodeLayout
    Q: PETSc.Mat
    #: global dofs of the variables of the kept pairs dealt to this rank (the pattern)
    dofs: IntArray

    @property
    def pairs(self) -> IntArray:
        """The kept pairs' indices in the coupling's pairs."""
        return np.flatnonzero(self.kept)


def _quantity_rows(layout: NodeLayout, cells: IntArray, nf: int) -> IntArray:
    """Global rows of the cells' nf quantities, (cells, nf)."""
    return layout.offset + cells[:, None] * nf + np.arange(nf)


def covered_gap(source, coupling: MortarCoupling, W: FloatArray,
                element_weights: FloatArray) -> SourceGaps:
    """ĝ and W over the covered part, with their first derivatives (``source``:
    the CurrentMortarGap; ``W`` its whole nodal W, for the near-contact margin)."""
    slave = source.slave
    layout, comm = slave.layout, slave.layout.comm
    nc, ns = slave.cells.shape
    pair_cells = coupling.pairs[:, 0]
    D, _, gap = coupling.raw_pairs
    dual = CoveredDual.of(pair_cells, D, gap, element_weights)
    nf = dual.num_functions
    g_cells, W_cells = dual.gaps()
    covered = np.flatnonzero(dual.covered)
    g = layout.sum_at_functions(slave.cells[covered], g_cells[covered])
    W_cov = layout.sum_at_functions(slave.cells[covered], W_cells[covered])
    near = source.near_contact(g, W)
    kept = np.any(near[slave.cells[pair_cells]], axis=1)
    Gamma, Omega = dual.gap_rows()
    quantities = NodeLayout(comm, nc * nf, np.zeros(0, dtype=np.int64))
    cells = pair_cells[kept]
    # each pair's coefficients travel with it: they are its slave cell's, on
    # the rank that found the pair
    dealt = deal_evenly(coupling, kept, Gamma[cells].reshape(len(cells), ns * nf),
                        Omega[cells].reshape(len(cells), ns * nf),
                        _quantity_rows(quantities, cells, nf).astype(np.float64))
    r = source.dealt_pair_derivatives(dealt, coupling.zero_length, with_hessian=False,
                                      with_mass=True)
    n = len(dealt.pairs)
    dofs = source._variable_dofs(r.nodes, n)
    nv = dofs.shape[1]
    grad = r.gradient.reshape(n, nf, nv)
    G_rows, O_rows, q_rows = dealt.values
    G_g = assemble_global_blocks(layout, dealt.rows, dofs, np.einsum(
        "paf,pfn->pan", G_rows.reshape(n, ns, nf), grad), cols=source.dofs)
    G_W = assemble_global_blocks(layout, dealt.rows, dofs, np.einsum(
        "paf,pfn->pan", O_rows.reshape(n, ns, nf), grad), cols=source.dofs)
    Q = assemble_global_blocks(quantities, q_rows.reshape(n, nf).astype(np.int64), dofs,
                               grad, cols=source.dofs)
    data = CoveredPairs(coupling, pair_cells, kept, dual, quantities, Q, dofs)
    return SourceGaps(g, G_g, layout.on_cells(slave.cells[pair_cells]), data=data,
                      coefficients=dual.coefficients(source.C), covered_weights=W_cov,
                      G_covered_weights=G_W)


def covered_hessian(source, data: CoveredPairs, Fg: Optional[FloatArray],
                    FW: Optional[FloatArray]) -> PETSc.Mat:
    """``Σ_A F_g,A ∂²ĝ_A + F_W,A ∂²W_A`` over the covered part: the pairs' own
    second derivatives of c and L, weighted, plus ``Qᵀ B Q`` (``Fg=None``: every
    entry it may have)."""
    cells_nodes = source.slave.cells
    dual, nf = data.dual, data.dual.num_functions
    if Fg is None:
        # the pattern: each kept pair's variables couple with each other, and the
        # quantities of every rebuilt cell with each other
        width = data.dofs.shape[1]
        H = assemble_global_blocks(source.dofs, data.dofs, data.dofs,
                                   np.zeros((len(data.dofs), width, width)))
        rebuilt = np.flatnonzero(dual.covered & ~dual.sliver)
        B = np.ones((len(rebuilt), nf, nf))
    else:
        F, FWc = Fg[cells_nodes], FW[cells_nodes]
        weights = dual.pair_weights(F, FWc)
        # a pair adds nothing where no node of its cell has F_g or F_W ≠ 0 (the
        # positive part's own zero: see CurrentMortarGap._gap_hessian)
        active = np.any((F != 0.0) | (FWc != 0.0), axis=1)
        which = data.kept & active[data.pair_cells]
        dealt = deal_evenly(data.coupling, which, weights[data.pair_cells[which]])
        r = source.dealt_pair_derivatives(dealt, data.coupling.zero_length, with_hessian=True,
                                          node_weights=dealt.values[0], with_mass=True)
        n = len(dealt.pairs)
        dofs = source._variable_dofs(r.nodes, n)
        nv = dofs.shape[1]
        H = assemble_global_blocks(source.dofs, dofs, dofs, r.hessian.reshape(n, nv, nv))
        rebuilt = np.flatnonzero(active & dual.covered & ~dual.sliver)
        B = dual.cross_blocks(F)[rebuilt]
    # products of first derivatives of one cell's pairs: Qᵀ B Q
    rows = _quantity_rows(data.quantities, rebuilt, nf)
    B_mat = assemble_global_blocks(data.quantities, rows, rows, B, cols=data.quantities)
    BQ = B_mat.matMult(data.Q)
    H.axpy(1.0, transpose_mat_mult(data.Q, BQ),
           structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    return H
