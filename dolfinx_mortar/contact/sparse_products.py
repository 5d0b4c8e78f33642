"""Sparse products of the contact operators, in one place."""
from __future__ import annotations

from typing import Optional

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


def transpose_mat_mult(A: PETSc.Mat, B: PETSc.Mat) -> PETSc.Mat:
    """``Aᵀ B`` as a new matrix.

    PETSc 3.18's MatTransposeMatMult for parallel AIJ matrices was 7× slower
    on 2 ranks than on 1 (0.14 s against 0.02 s for G of Hertz 3D at 30k
    dofs); it made the contact Jacobian 5× slower on 2 ranks. An explicit
    transpose followed by MatMatMult gives the same matrix in 0.03 s on
    2 ranks and costs the same on 1. ``A.transpose()`` without an argument
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
        self._product: Optional[PETSc.Mat] = None

    def __call__(self, A: PETSc.Mat, B: PETSc.Mat) -> PETSc.Mat:
        patterns = (_pattern(A), _pattern(B))
        same = (self._patterns is not None
                and all(np.array_equal(new, old)
                        for pair_new, pair_old in zip(patterns, self._patterns)
                        for new, old in zip(pair_new, pair_old)))
        if not A.getComm().tompi4py().allreduce(bool(same), op=MPI.LAND):
            self._product = transpose_mat_mult(A, B)
            self._patterns = patterns
            return self._product
        At = PETSc.Mat()
        A.transpose(At)
        At.matMult(B, result=self._product)
        At.destroy()
        return self._product


class PatternTrackingAdd:
    """``A += K`` for a contact stiffness ``K`` whose pattern may change between
    Newton iterations (pairs come and go as the surfaces move).

    Added with SUBSET_NONZERO_PATTERN, every entry of ``K`` that ``A`` lacks
    is a malloc inside PETSc, and each one reallocates the row storage: 2.3 s
    for one Jacobian of Hertz 3D at 30k dofs, ten times the bulk assembly.
    When ``K``'s pattern differs from the last one added (compared exactly,
    on every rank), ``A`` is rebuilt once with the union pattern; otherwise
    ``K``'s entries are already in ``A``. The rebuild keeps ``A``'s handle, so
    SNES and the KSP keep using it; what the rebuild drops (the
    near-nullspace, the permission to allocate new entries) is put back.

    The union is formed in a copy (MatAXPY with DIFFERENT_NONZERO_PATTERN)
    and poured into ``A`` by a new preallocation. MatAXPY straight into ``A``
    swaps its storage without raising its nonzero state (PETSc 3.22 and
    3.25): a KSP that had factorized ``A`` then kept MUMPS's analysis of the
    old pattern and solved a different matrix, silently (a 6×6 test: residual
    3.3 instead of 1e-15) or with MUMPS reporting a singular matrix (the
    current configuration against an elastic master). A new preallocation
    raises the nonzero state, and the preconditioner is set up afresh.
    """

    def __init__(self) -> None:
        self._rows: Optional[np.ndarray] = None
        self._cols: Optional[np.ndarray] = None

    def __call__(self, A: PETSc.Mat, K: PETSc.Mat) -> None:
        rows, cols, _ = K.getValuesCSR()
        same = (self._rows is not None and np.array_equal(rows, self._rows)
                and np.array_equal(cols, self._cols))
        # MatAXPY is collective: every rank must take the same branch
        if A.getComm().tompi4py().allreduce(bool(same), op=MPI.LAND):
            A.axpy(1.0, K, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            return
        nullspace = A.getNearNullSpace()
        union = A.duplicate(copy=True)
        union.axpy(1.0, K, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        indptr, indices, values = union.getValuesCSR()
        union.destroy()
        A.setPreallocationCSR((indptr, indices))
        A.setValuesCSR(indptr, indices, values)
        A.assemble()
        A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        if nullspace is not None and nullspace.handle:
            A.setNearNullSpace(nullspace)
        self._rows, self._cols = rows.copy(), cols.copy()

    def reset(self) -> None:
        """Forget the last pattern (the next add rebuilds ``A``'s pattern)."""
        self._rows = self._cols = None
