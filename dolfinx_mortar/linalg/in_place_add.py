"""``A += K`` into the Newton matrix's own value arrays."""
from __future__ import annotations

from typing import Optional

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import kernels
from dolfinx_mortar.linalg import aij_blocks
from dolfinx_mortar.linalg.aij_blocks import Block


class InPlaceAdd:
    """``A += K`` for a contact stiffness ``K`` whose entries all lie in the
    Newton matrix ``A``'s pattern, written straight into ``A``'s value arrays.

    PETSc's MatAXPY with SUBSET_NONZERO_PATTERN adds ``K`` row by row through
    MatSetValues, a search per entry: on the busiest of 16 ranks it cost as
    much as the product that makes ``K`` (docs/SCALING.md). Here the position
    of each of ``K``'s entries in ``A``'s local blocks is found once for a
    pair of patterns, and each add is then one indexed sum per block. ``K``'s
    pattern is compared exactly at every call (it changes as pairs come and
    go); ``A``'s by where PETSc stores it (:func:`aij_blocks.storage`).

    A call is collective. Where a rank's ``K`` has an entry that ``A`` lacks,
    or the matrices are not AIJ with the same layout, nothing is added on any
    rank and the call returns False: the caller adds another way.
    """

    def __init__(self) -> None:
        self._A_storage: Optional[tuple] = None
        self._K_blocks: list[Block] = []
        self._positions: Optional[list[np.ndarray]] = None

    def __call__(self, A: PETSc.Mat, K: PETSc.Mat) -> bool:
        usable = (aij_blocks.supports(A) and aij_blocks.supports(K)
                  and A.getOwnershipRangeColumn() == K.getOwnershipRangeColumn()
                  and A.getOwnershipRange() == K.getOwnershipRange())
        positions = self._find(A, K) if usable else None
        if not A.getComm().tompi4py().allreduce(positions is not None, op=MPI.LAND):
            return False
        # A's storage is (handle, row pointers, columns, rows, entries) per block
        for (handle, *_, nnz), block, where in zip(self._A_storage, self._K_blocks, positions):
            if len(where):
                with aij_blocks.values(handle, nnz) as a, \
                        aij_blocks.values(block.handle, block.nnz) as k:
                    np.add.at(a, where, k)   # a and k are float64 views (aij_blocks.values)
        A.stateIncrease()    # the blocks were told; the matrix the KSP holds too
        return True

    def reset(self) -> None:
        """Forget both patterns (the next call finds the positions again)."""
        self.__init__()

    def _find(self, A: PETSc.Mat, K: PETSc.Mat) -> Optional[list[np.ndarray]]:
        """The positions in A's blocks of K's entries, block by block (None:
        some entry of K is not in A's pattern)."""
        storage = aij_blocks.storage(A)
        if (storage == self._A_storage and self._positions is not None
                and aij_blocks.has_pattern(K, self._K_blocks)):
            # K's blocks may be new objects with the same pattern
            self._K_blocks = [Block(handle, old.indptr, old.indices, old.storage,
                                    old.global_columns)
                              for handle, old in zip(aij_blocks.block_handles(K),
                                                     self._K_blocks)]
            return self._positions
        self._A_storage, self._K_blocks = storage, aij_blocks.blocks(K)
        self._positions = _locate(aij_blocks.blocks(A), self._K_blocks)
        return self._positions


def _locate(A_blocks: list[Block], K_blocks: list[Block]) -> Optional[list[np.ndarray]]:
    """Where each of K's entries is in A's block of the same kind (None: one
    is not in A's pattern)."""
    if len(A_blocks) != len(K_blocks):
        return None
    positions = []
    for A_block, block in zip(A_blocks, K_blocks):
        columns = block.indices.astype(np.int64)
        if block.global_columns is not None:
            # K's off-diagonal columns, numbered as A's off-diagonal block numbers them
            columns = _find_sorted(A_block.global_columns, block.global_columns[block.indices])
            if columns is None:
                return None
        where = kernels.positions_in_pattern(A_block.indptr, A_block.indices,
                                             block.indptr.astype(np.int64), columns)
        if where is None:
            return None
        positions.append(where)
    return positions


def _find_sorted(haystack: np.ndarray, needles: np.ndarray) -> Optional[np.ndarray]:
    """The index of each needle in the sorted ``haystack`` (None: one is missing)."""
    if not len(needles):
        return np.zeros(0, dtype=np.int64)
    where = np.searchsorted(haystack, needles)
    if len(haystack) == 0 or np.any(where >= len(haystack)) or np.any(haystack[where] != needles):
        return None
    return where

