"""The exact Newton step of the GLS kinds through a sparse augmented system.

GLS and GLS* couple every slave node to every other (``M_A = (N L⁻¹)_A``), so
their contact stiffness is dense. The step is instead taken from a sparse
saddle-point system (docs/DESIGN.md, §Augmented step), factorized with MUMPS and applied as a
PETSc python preconditioner.
"""
from __future__ import annotations

import time
from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.gap_sources import GlobalGapSource
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.linalg.linear_solver import reset_after_failure

FloatArray = npt.NDArray[np.float64]


class AugmentedNewtonStep:
    """Exact Newton step for GLS/GLS* through the sparse augmented system.

    With y = d̄ and z = L⁻¹ ω⟨y⟩ (docs/DESIGN.md, §Augmented step), the Newton matrix
    ``K + Ĝᵀ L⁻¹ diag(ωH) L⁻¹ Ĝ`` is the Schur complement of

        [ K    0     Ĝᵀ ] [Δu]   [r]
        [ 0    ωH   −L  ] [Δy] = [0]
        [ Ĝ   −L     0  ] [Δz]   [0]

    which is sparse: it is assembled (MatNest → AIJ) and factorized (MUMPS by
    default; options prefix ``dolfinx_mortar_augmented_``), and its Δu is the
    step. No dense slave block is formed. Used as a PETSc python PC.

    With friction (docs/FRICTION.md) two more unknowns per slave node and
    direction, ``w = L⁻¹ Ĝ_T Δu`` and ``Δz_T = L⁻¹ Δf_T``, add the rows

        Ĝ_T Δu − L w = 0,    PCP w + PBωH Δy − L Δz_T = 0

    and ``Ĝ_Tᵀ Δz_T`` to the first: their Schur complement is friction's
    ``Ĝ_Tᵀ L⁻¹ P (C P L⁻¹ Ĝ_T + c_TN ωH L⁻¹ Ĝ)`` (unsymmetric; L ⊗ I here).
    """

    def __init__(self, comm: MPI.Comm, prefix: str):
        self.comm = comm
        self.prefix = prefix
        self.ksp: Optional[PETSc.KSP] = None
        #: wall time of the factorizations (a linear-solve cost spent in the Jacobian callback)
        self.factorization_time = 0.0

    def update_from(self, A: PETSc.Mat, state: ContactState, model: GlobalGapSource,
                    active: FloatArray,
                    tangential=None) -> None:
        """:meth:`update` from the bulk matrix ``A`` and a GLS model's state
        (:class:`~dolfinx_mortar.contact.gap_sources.global_gap.GlobalGap`); ``active`` as H(d̄).
        The pointwise set puts Ĝ⁺ in the last row while anything penetrates.
        ``tangential``: friction's blocks
        (:class:`~dolfinx_mortar.contact.friction.tangential.AugmentedFriction`), or None."""
        K = A.copy()
        if state.K_curv is not None:
            K.axpy(1.0, state.K_curv, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        G_right, weights = state.G, state.weights * active
        if state.gaps_plus is not None and model.any_penetration(state.gaps_plus):
            G_right, weights = state.G_plus, state.weights
        self.update(K, state.G, weights, model.mass.matrix, G_right, model.surface_rows,
                    tangential)

    def update(self, K: PETSc.Mat, G: PETSc.Mat, weights: FloatArray, L: PETSc.Mat,
               G_linearized: Optional[PETSc.Mat] = None,
               surface: Optional[npt.NDArray[np.int64]] = None, tangential=None) -> None:
        """Assemble and factorize; ``G_linearized`` replaces Ĝ in the last row
        (the pointwise active set's Ĝ⁺, with ``weights`` = ω).

        ``surface``: the owned rows of L that belong to slave nodes (local
        indices). The slave layout of a DOLFINx surface spans every mesh node;
        the other rows of L are unit rows with Ĝ = 0, their y and z are 0, and
        dropping them halves the augmented system (GLS Jacobians went 5×
        slower than the dual kind's before).
        """
        #: the pieces of the Newton matrix K + Ĝᵀ L⁻¹ diag(ωH) L⁻¹ Ĝ (inspection, benchmarks)
        self.K, self.G, self.weights, self.L = K, G, weights, L
        self.G_linearized = G_linearized
        G_last = G if G_linearized is None else G_linearized
        tangential_blocks = None
        if tangential is not None:
            tangential_blocks = (tangential.G_T, tangential.PCP, tangential.PB, tangential.L)
        if surface is not None:
            offset = L.getOwnershipRange()[0]
            rows = PETSc.IS().createGeneral((offset + surface).astype(PETSc.IntType),
                                            comm=self.comm)
            start, end = G.getOwnershipRangeColumn()
            cols = PETSc.IS().createStride(end - start, first=start, step=1, comm=self.comm)
            if tangential is not None:
                # the same rows for each direction: node·bs + k
                bs = tangential.L.getSize()[0] // L.getSize()[0]
                node_dofs = (offset + surface)[:, None] * bs + np.arange(bs)
                rows_t = PETSc.IS().createGeneral(node_dofs.ravel().astype(PETSc.IntType),
                                                  comm=self.comm)
                G_T, PCP, PB, L_T = tangential_blocks
                tangential_blocks = (G_T.createSubMatrix(rows_t, cols),
                                     PCP.createSubMatrix(rows_t, rows_t),
                                     PB.createSubMatrix(rows_t, rows),
                                     L_T.createSubMatrix(rows_t, rows_t))
            L = L.createSubMatrix(rows, rows)
            G = G.createSubMatrix(rows, cols)
            G_last = G if G_linearized is None else G_linearized.createSubMatrix(rows, cols)
            weights = weights[surface]
        layout_vec = L.createVecLeft()
        layout_vec.array[:] = weights[: layout_vec.getLocalSize()]
        S = PETSc.Mat().createAIJ(L.getSizes(), nnz=(1, 0), comm=L.comm)
        S.setDiagonal(layout_vec)
        S.assemble()
        minus_L = L.copy()
        minus_L.scale(-1.0)
        GT = G.copy().transpose()
        if tangential_blocks is None:
            nest = PETSc.Mat().createNest([[K, None, GT], [None, S, minus_L],
                                           [G_last, minus_L, None]],
                                          comm=self.comm)
        else:
            G_T, PCP, PB, L_T = tangential_blocks
            minus_L_T = L_T.copy()
            minus_L_T.scale(-1.0)
            G_T_transposed = G_T.copy().transpose()
            # unknowns Δu, Δy, Δz, w, Δz_T (see the class)
            nest = PETSc.Mat().createNest(
                [[K, None, GT, None, G_T_transposed], [None, S, minus_L, None, None],
                 [G_last, minus_L, None, None, None], [None, PB, None, PCP, minus_L_T],
                 [G_T, None, None, minus_L_T, None]], comm=self.comm)
        self.index_sets = nest.getNestISs()[0]
        A = nest.convert("aij")
        if self.ksp is None:
            self.ksp = PETSc.KSP().create(self.comm)
            self.ksp.setType("preonly")
            self.ksp.getPC().setType("lu")
            self.ksp.getPC().setFactorSolverType("mumps")
            self.ksp.setOptionsPrefix(self.prefix)
            self.ksp.setFromOptions()
        # a failed factorization (a sliver's nearly singular system) must not
        # leave MUMPS's state to the next one: every later step would be Inf
        reset_after_failure(self.ksp)
        self.ksp.setOperators(A)
        clock = time.perf_counter()
        self.ksp.setUp()
        self.factorization_time += time.perf_counter() - clock
        self.A = A
        self.rhs, self.sol = A.createVecRight(), A.createVecLeft()

    def apply(self, pc: PETSc.PC, x: PETSc.Vec, y: PETSc.Vec) -> None:
        self.rhs.zeroEntries()
        part = self.rhs.getSubVector(self.index_sets[0])
        x.copy(part)
        self.rhs.restoreSubVector(self.index_sets[0], part)
        self.ksp.solve(self.rhs, self.sol)
        part = self.sol.getSubVector(self.index_sets[0])
        part.copy(y)
        self.sol.restoreSubVector(self.index_sets[0], part)
