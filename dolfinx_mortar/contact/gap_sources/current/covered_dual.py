"""The dual basis rebuilt over the covered part of each slave cell, on the
current surface, with its exact derivatives (the boundary modification of
Popp et al. 2013, as the frozen configurations build it).

A dual function is negative near its cell's far node: a cell that the master
covers only there reads a separation as a penetration. Rebuilt over the
covered part, the cell's gap functions are ``φ = N C`` with
``C = L⁻¹ diag(W)``, ``L_ab = ∫_cov N_a N_b`` and ``W = L·1`` (``∫_cov N_a``).
Per slave cell, with ``c_b = ∫_cov N_b d``, its gaps are

    ĝ_a = Σ_b C_ba c_b = W_a z_a,    z = L⁻¹ c,

and the law's weight of a covered node is ``W_A = Σ_cells W_a``. Which part is
covered changes with u: L and c are sums over the cell's pairs, whose exact
derivatives the pair kernel gives (``with_mass``), and ĝ's derivatives follow:

    dĝ_a = dW_a z_a + W_a [L⁻¹ (dc − dL z)]_a,

linear in the pairs' own gradients (``gap_rows``). The second derivative of
``Σ_a F_a ĝ_a + Σ_a F_W,a W_a`` has the pairs' own second derivatives of c and
L (``pair_weights``, one weighted function per pair) and products of first
derivatives of different pairs of one cell, ``qᵀ B q`` with q the cell's
``(c, L)`` gradients (``cross_blocks``).

A cell whose covered part is a sliver (a covered integral below
:data:`SLIVER` of the cell, where L is singular to round-off) takes the
positive functions N there (C = I, ĝ = c), of the sliver's size.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: a covered integral ∫_cov N_a below this part of its cell makes the covered part a
#: sliver: the covered mass matrix's condition number grows as its inverse square in 2D
SLIVER = 1e-8


@dataclass
class CoveredDual:
    """The rebuilt basis of every slave cell at one displacement (values from
    the double segmentation: ``L`` (cells, nd, nd) and ``c`` (cells, nd),
    summed over each cell's pairs)."""

    L: FloatArray
    c: FloatArray
    #: cells with a pair
    covered: npt.NDArray[np.bool_]
    #: covered cells whose covered part is a sliver (C = I there)
    sliver: npt.NDArray[np.bool_]

    @classmethod
    def of(cls, pair_cells: IntArray, L_pairs: FloatArray, c_pairs: FloatArray,
           element_weights: FloatArray) -> "CoveredDual":
        """From the pairs' slave cells and their ``∫ N_a N_b`` and ``∫ N_a d``;
        ``element_weights``: ``∫ N_a`` over each whole cell (the sliver's scale)."""
        nc, nd = element_weights.shape
        L = np.zeros((nc, nd, nd))
        c = np.zeros((nc, nd))
        np.add.at(L, pair_cells, L_pairs)
        np.add.at(c, pair_cells, c_pairs)
        covered = np.zeros(nc, dtype=bool)
        covered[pair_cells] = True
        measure = element_weights.sum(axis=1)
        sliver = covered & np.any(L.sum(axis=2) <= SLIVER * measure[:, None], axis=1)
        return cls(L, c, covered, sliver)

    @property
    def num_functions(self) -> int:
        """The pair kernel's functions: nd gaps c, then the nd² entries of L."""
        nd = self.c.shape[1]
        return nd + nd * nd

    @cached_property
    def _dual(self):
        """W, L⁻¹ and z = L⁻¹c of the rebuilt cells (identity and c on the others),
        and which cells are rebuilt: inverted once, asked by every method below."""
        nc, nd = self.c.shape
        W = self.L.sum(axis=2)
        Linv = np.broadcast_to(np.eye(nd), (nc, nd, nd)).copy()
        dual = self.covered & ~self.sliver
        Linv[dual] = np.linalg.inv(self.L[dual])
        z = np.einsum("eab,eb->ea", Linv, self.c)
        return W, Linv, z, dual

    def gaps(self) -> tuple[FloatArray, FloatArray]:
        """Per cell: ``ĝ_a`` and ``W_a = ∫_cov N_a``, (cells, nd) each."""
        W, _, z, dual = self._dual
        g = np.where(dual[:, None], W * z, self.c)
        return g, W

    def coefficients(self, reference: FloatArray) -> FloatArray:
        """C of every cell (``reference`` where nothing is covered), (cells, nd, nd)."""
        nc, nd = self.c.shape
        W, Linv, _, dual = self._dual
        C = np.broadcast_to(reference, (nc, nd, nd)).copy()
        C[dual] = Linv[dual] * W[dual][:, None, :]             # L⁻¹ diag(W)
        C[self.sliver] = np.eye(nd)
        return C

    def gap_rows(self) -> tuple[FloatArray, FloatArray]:
        """The coefficients of ĝ's and W's gradients in the kernel's functions,
        (cells, nd, nd + nd²) each: ``dĝ_a = Σ_f Γ_af dq_f``, ``dW_a = Σ_f Ω_af dq_f``."""
        nc, nd = self.c.shape
        W, Linv, z, dual = self._dual
        eye = np.eye(nd)
        Omega = np.zeros((nc, nd, self.num_functions))
        Omega[:, :, nd:] = np.repeat(eye[:, :, None], nd, axis=2).reshape(nd, nd * nd)
        Gamma = np.zeros_like(Omega)
        # α_ab = W_a L⁻¹_ab;  β_a,bc = δ_ab z_a − W_a L⁻¹_ab z_c
        alpha = W[:, :, None] * Linv
        beta = (np.einsum("ab,ea,c->eabc", eye, z, np.ones(nd))
                - np.einsum("eab,ec->eabc", alpha, z))
        Gamma[:, :, :nd] = alpha
        Gamma[:, :, nd:] = beta.reshape(nc, nd, nd * nd)
        Gamma[~dual, :, :nd] = eye
        Gamma[~dual, :, nd:] = 0.0
        return Gamma, Omega

    def pair_weights(self, F: FloatArray, FW: FloatArray) -> FloatArray:
        """Per cell, the weights of the kernel's functions in
        ``Σ_a F_a ∂²ĝ_a + F_W,a ∂²W_a`` that come from c's and L's own second
        derivatives, (cells, nd + nd²). ``F``, ``FW``: (cells, nd) at the cells' nodes."""
        nc, nd = self.c.shape
        W, Linv, z, dual = self._dual
        lam = np.zeros((nc, self.num_functions))
        # ∂²W_a = Σ_c ∂²L_ac, weighted F_W,a, and F_a z_a where ĝ = W∘z
        row = FW + np.where(dual[:, None], F * z, 0.0)
        L_weights = np.repeat(row[:, :, None], nd, axis=2)
        mu = np.einsum("eab,ea->eb", Linv, F * W)              # L⁻¹(F∘W)
        L_weights -= np.where(dual[:, None, None], np.einsum("eb,ec->ebc", mu, z), 0.0)
        lam[:, :nd] = np.where(dual[:, None], mu, F)
        lam[:, nd:] = L_weights.reshape(nc, nd * nd)
        return lam

    def cross_blocks(self, F: FloatArray) -> FloatArray:
        """Per cell, B of the products of first derivatives in ``Σ_a F_a ∂²ĝ_a``:
        ``qᵀ B q`` with q the cell's (c, L) gradients, (cells, nf, nf); zero on
        sliver cells (ĝ = c is linear in q there)."""
        nc, nd = self.c.shape
        nf = self.num_functions
        W, Linv, z, dual = self._dual
        eye = np.eye(nd)
        U = np.zeros((nd, nf))                                  # dW_a = Σ_c dL_ac
        U[:, nd:] = np.repeat(eye[:, :, None], nd, axis=2).reshape(nd, nd * nd)
        # dz = L⁻¹ [I | −Z] dq with (Z dq_L)_b = Σ_c dL_bc z_c
        IZ = np.zeros((nc, nd, nf))
        IZ[:, :, :nd] = eye
        IZ[:, :, nd:] = -np.einsum("ab,ec->eabc", eye, z).reshape(nc, nd, nd * nd)
        V = np.einsum("eab,ebf->eaf", Linv, IZ)
        mu = np.einsum("eab,ea->eb", Linv, F * W)
        UFV = np.einsum("af,ea,eag->efg", U, F, V)
        R = np.zeros((nc, nf, nf))
        R[:, nd:, :] = np.einsum("eb,ecg->ebcg", mu, V).reshape(nc, nd * nd, nf)
        B = UFV + UFV.transpose(0, 2, 1) - R - R.transpose(0, 2, 1)
        B[~dual] = 0.0
        return B
