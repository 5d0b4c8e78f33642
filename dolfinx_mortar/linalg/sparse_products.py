"""Sparse products of the contact operators, in one place."""
from __future__ import annotations

from typing import Optional

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.linalg import aij_blocks
from dolfinx_mortar.linalg.in_place_add import InPlaceAdd


def transpose_mat_mult(A: PETSc.Mat, B: PETSc.Mat) -> PETSc.Mat:
    """``Aᵀ B`` as a new matrix.

    PETSc 3.18's MatTransposeMatMult for parallel AIJ matrices was 7× slower
    on 2 ranks than on 1 (0.14 s against 0.02 s for G of Hertz 3D at 30k
    dofs); it made the contact Jacobian 5× slower on 2 ranks. An explicit
    transpose followed by MatMatMult gives the same matrix in 0.03 s on
    2 ranks and costs the same on 1. Measured again with PETSc 3.22 and 3.25
    (``benchmarks/transpose_product.py``, Gᵀ G at 29k dofs): the same on one
    rank, 4.1× and 4.4× faster than MatTransposeMatMult on 2 (7.9 against
    32.8 ms, 5.9 against 25.8 ms). ``A.transpose()`` without an argument
    crashed petsc4py 3.18 (SEGV), hence the explicit target.
    """
    At = PETSc.Mat()
    A.transpose(At)
    product = At.matMult(B)
    At.destroy()
    return product


def _pattern(M: PETSc.Mat) -> tuple[np.ndarray, np.ndarray]:
    rows, cols, _ = M.getValuesCSR()
    return rows.copy(), cols.copy()


class TransposeProduct:
    """``Aᵀ B`` that keeps PETSc's symbolic product while the patterns of
    ``A`` and ``B`` stay the same, as they do between Newton iterations once
    the contact pairs stop changing.

    The symbolic phase of MatMatMult walks every row of ``Aᵀ``, that is every
    dof of the mesh, and was 85% of a fresh product: 27.5 ms against 4.1 ms
    numeric only for the contact stiffness of Hertz 3D at 81k dofs. PETSc
    cannot tell a changed pattern on reuse and would then compute wrong
    entries silently, so the patterns are compared exactly, on every rank,
    and the decision is collective.

    The returned matrix belongs to this object and is overwritten by the
    next call: copy it before changing it or keeping it.
    """

    def __init__(self) -> None:
        self._patterns: Optional[tuple] = None
        self._mats: list[PETSc.Mat] = []     # A, B, Aᵀ, the product: the product's own

    def __call__(self, A: PETSc.Mat, B: PETSc.Mat) -> PETSc.Mat:
        patterns = (_pattern(A), _pattern(B))
        same = (self._patterns is not None
                and all(np.array_equal(new, old)
                        for pair_new, pair_old in zip(patterns, self._patterns)
                        for new, old in zip(pair_new, pair_old)))
        # A product remembers the matrices it was made of, and PETSc reuses
        # it only with those very objects (a new transpose each call left it
        # pointing at a freed matrix: PETSc 3.22 crashed in parallel when it
        # was destroyed). So it is made of copies kept here, refilled in place.
        if not A.getComm().tompi4py().allreduce(bool(same), op=MPI.LAND):
            self._destroy()
            A_kept, B_kept = A.duplicate(copy=True), B.duplicate(copy=True)
            At = PETSc.Mat()
            A_kept.transpose(At)
            self._mats = [A_kept, B_kept, At, At.matMult(B_kept)]
            self._patterns = patterns
            return self._mats[3]
        A_kept, B_kept, At, product = self._mats
        A.copy(A_kept, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        B.copy(B_kept, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        A_kept.transpose(At)
        At.matMult(B_kept, result=product)
        return product

    def _destroy(self) -> None:
        for M in self._mats:
            M.destroy()
        self._mats = []


class PatternTrackingAdd:
    """``A += K`` for a contact stiffness ``K`` whose pattern may change between
    Newton iterations (pairs come and go as the surfaces move).

    Added with SUBSET_NONZERO_PATTERN, every entry of ``K`` that ``A`` lacks
    is a malloc inside PETSc, and each one reallocates the row storage: 2.3 s
    for one Jacobian of Hertz 3D at 30k dofs, ten times the bulk assembly.
    Where ``K`` has an entry that ``A`` lacks (on any rank), ``A`` is rebuilt
    once with the union pattern; otherwise ``K``'s values are added in place
    (:class:`~dolfinx_mortar.linalg.in_place_add.InPlaceAdd`). The rebuild keeps ``A``'s handle, so
    SNES and the KSP keep using it; what the rebuild drops (the
    near-nullspace, the permission to allocate new entries) is put back.

    The rebuild swaps ``A``'s storage (MatHeaderMerge) without raising its
    nonzero state (PETSc 3.22 and 3.25), so a KSP that had factorized ``A``
    keeps MUMPS's analysis of the old pattern and solves another matrix:
    silently wrong (a residual of 4e7 on a 40×40 test), a MUMPS "singular"
    error, or a crash in parallel. Pouring the union into ``A`` by a new
    preallocation was right in serial but not on 2 ranks. So the call
    returns whether the pattern changed, and the owner of the KSP resets its
    preconditioner then (:meth:`NonlinearContactProblem.J`).
    """

    def __init__(self) -> None:
        self._in_place = InPlaceAdd()
        #: K's pattern at the last rebuild, for matrices whose arrays cannot be reached
        self._last: Optional[tuple[np.ndarray, np.ndarray]] = None

    def __call__(self, A: PETSc.Mat, K: PETSc.Mat) -> bool:
        # every entry of K already in A (the pattern of an earlier add, or a
        # subset of the union): the values only, in place
        if aij_blocks.supports(A) and aij_blocks.supports(K):
            if self._in_place(A, K):
                return False
        else:
            # not AIJ (a user's BAIJ matrix, say): K's pattern is compared with
            # the last one merged, and PETSc adds the values
            pattern = _pattern(K)
            same = (self._last is not None and np.array_equal(pattern[0], self._last[0])
                    and np.array_equal(pattern[1], self._last[1]))
            if A.getComm().tompi4py().allreduce(bool(same), op=MPI.LAND):
                A.axpy(1.0, K, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
                return False
            self._last = pattern
        nullspace = A.getNearNullSpace()
        A.axpy(1.0, K, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        if nullspace is not None and nullspace.handle:
            A.setNearNullSpace(nullspace)
        self._in_place.reset()
        return True

    def reset(self) -> None:
        """Forget the last patterns (the positions are found again)."""
        self._in_place.reset()
        self._last = None


def kron_identity(L: PETSc.Mat, bs: int) -> PETSc.Mat:
    """``L ⊗ I_bs`` (row and column i·bs + k from i), on the owned rows."""
    indptr, cols, values = L.getValuesCSR()
    n = len(indptr) - 1
    counts = np.diff(indptr)
    starts = np.zeros(n * bs + 1, dtype=PETSc.IntType)
    starts[1:] = np.cumsum(np.repeat(counts, bs))
    row = np.repeat(np.arange(n), counts)
    within = np.arange(len(cols)) - indptr[row]
    new_cols = np.empty(len(cols) * bs, dtype=PETSc.IntType)
    new_values = np.empty(len(cols) * bs)
    for k in range(bs):
        at = starts[row * bs + k] + within
        new_cols[at] = cols * bs + k
        new_values[at] = values
    (m, M), _ = L.getSizes()
    return PETSc.Mat().createAIJ(size=((m * bs, M * bs), (m * bs, M * bs)),
                                 csr=(starts, new_cols, new_values), comm=L.comm)
