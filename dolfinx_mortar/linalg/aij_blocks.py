"""The local blocks of a PETSc AIJ matrix, with their value arrays in place.

petsc4py copies a matrix's entries out (``getValuesCSR``) and back in
(``setValuesCSR``, ``MatSetValues`` underneath), and does not wrap the
functions that give an AIJ matrix's own arrays. Those are PETSc's public C
API (``MatMPIAIJGetSeqAIJ``, ``MatGetRowIJ``, ``MatSeqAIJGetArray``), called
here through ctypes on the library that petsc4py itself loaded, so that the
contact stiffness can be added into the Newton matrix's value arrays
directly (:class:`~dolfinx_mortar.linalg.in_place_add.InPlaceAdd`).
"""
from __future__ import annotations

import ctypes
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Iterator, Optional

import numpy as np
from petsc4py import PETSc

from dolfinx_mortar.linalg.petsc_library import petsc_library

#: the matrix types whose local blocks are SeqAIJ (serial, and diagonal plus off-diagonal)
SEQ_TYPES = ("seqaij",)
MPI_TYPES = ("mpiaij",)

_Int = np.ctypeslib.as_ctypes_type(np.dtype(PETSc.IntType))
_IntP = ctypes.POINTER(_Int)
_ScalarP = ctypes.POINTER(ctypes.c_double)
_Handle = ctypes.c_void_p


def _library() -> Optional[ctypes.CDLL]:
    lib = petsc_library()
    if lib is None or np.dtype(PETSc.ScalarType) != np.float64:
        return None
    try:
        signatures = {
            "MatMPIAIJGetSeqAIJ": [_Handle, ctypes.POINTER(_Handle), ctypes.POINTER(_Handle),
                                   ctypes.POINTER(_IntP)],
            "MatGetRowIJ": [_Handle, _Int, ctypes.c_int, ctypes.c_int, _IntP,
                            ctypes.POINTER(_IntP), ctypes.POINTER(_IntP), ctypes.POINTER(ctypes.c_int)],
            "MatRestoreRowIJ": [_Handle, _Int, ctypes.c_int, ctypes.c_int, _IntP,
                                ctypes.POINTER(_IntP), ctypes.POINTER(_IntP),
                                ctypes.POINTER(ctypes.c_int)],
            "MatGetSize": [_Handle, _IntP, _IntP],
            "MatSeqAIJGetArray": [_Handle, ctypes.POINTER(_ScalarP)],
            "MatSeqAIJRestoreArray": [_Handle, ctypes.POINTER(_ScalarP)],
        }
        for name, argtypes in signatures.items():
            function = getattr(lib, name)
            function.argtypes, function.restype = argtypes, ctypes.c_int
        return lib
    except AttributeError:
        return None


_LIB = _library()


def _call(name: str, *args) -> None:
    code = getattr(_LIB, name)(*args)
    if code != 0:
        raise RuntimeError(f"PETSc's {name} returned error code {code}")


@dataclass(frozen=True)
class Block:
    """One SeqAIJ block: its handle, its pattern (copies) and, for the
    off-diagonal block, the global column of each of its columns."""
    handle: int
    indptr: np.ndarray
    indices: np.ndarray
    #: where PETSc keeps the pattern (a changed pattern is new storage or a new count)
    storage: tuple[int, ...]
    global_columns: Optional[np.ndarray] = None

    @property
    def nnz(self) -> int:
        return int(self.indptr[-1])


def supports(M: PETSc.Mat) -> bool:
    """Whether ``M``'s local blocks can be reached (an AIJ matrix of reals)."""
    return _LIB is not None and M.getType() in SEQ_TYPES + MPI_TYPES


@contextmanager
def _row_ij(handle: int) -> Iterator[tuple[np.ndarray, np.ndarray, tuple[int, ...]]]:
    """The SeqAIJ block's row pointers and columns, in place (read only, valid
    inside the block), and where PETSc keeps them."""
    n, done = _Int(0), ctypes.c_int(0)
    ia, ja = _IntP(), _IntP()
    _call("MatGetRowIJ", handle, 0, 0, 0, ctypes.byref(n), ctypes.byref(ia), ctypes.byref(ja),
          ctypes.byref(done))
    try:
        if not done.value:
            raise RuntimeError("PETSc's MatGetRowIJ gave no pattern for an AIJ block")
        indptr = np.ctypeslib.as_array(ia, shape=(n.value + 1,))
        nnz = int(indptr[-1])
        indices = (np.ctypeslib.as_array(ja, shape=(nnz,)) if nnz
                   else np.zeros(0, dtype=PETSc.IntType))
        yield indptr, indices, (handle, ctypes.cast(ia, ctypes.c_void_p).value or 0,
                                ctypes.cast(ja, ctypes.c_void_p).value or 0, n.value, nnz)
    finally:
        _call("MatRestoreRowIJ", handle, 0, 0, 0, ctypes.byref(n), ctypes.byref(ia),
              ctypes.byref(ja), ctypes.byref(done))


def block_handles(M: PETSc.Mat) -> tuple[int, Optional[int], Optional[np.ndarray]]:
    """The handles of ``M``'s diagonal and off-diagonal blocks (None in serial),
    and the global columns of the off-diagonal one's columns."""
    if M.getType() in SEQ_TYPES:
        return M.handle, None, None
    diagonal, off, colmap = _Handle(), _Handle(), _IntP()
    _call("MatMPIAIJGetSeqAIJ", M.handle, ctypes.byref(diagonal), ctypes.byref(off),
          ctypes.byref(colmap))
    rows, columns = _Int(0), _Int(0)
    _call("MatGetSize", off, ctypes.byref(rows), ctypes.byref(columns))
    global_columns = (np.ctypeslib.as_array(colmap, shape=(columns.value,)).copy()
                      if columns.value else np.zeros(0, dtype=PETSc.IntType))
    return diagonal.value, off.value, global_columns


def blocks(M: PETSc.Mat) -> list[Block]:
    """``M``'s local blocks with copies of their patterns: the diagonal block
    first (a serial matrix has only that one)."""
    diagonal, off, global_columns = block_handles(M)
    found = []
    for handle, columns in ((diagonal, None), (off, global_columns)):
        if handle is not None:
            with _row_ij(handle) as (indptr, indices, where):
                found.append(Block(handle, indptr.copy(), indices.copy(), where, columns))
    return found


def has_pattern(M: PETSc.Mat, known: list[Block]) -> bool:
    """Whether ``M``'s local blocks have exactly the patterns of ``known``
    (compared entry by entry, without copying them)."""
    diagonal, off, global_columns = block_handles(M)
    handles = [h for h in (diagonal, off) if h is not None]
    if len(handles) != len(known):
        return False
    if off is not None and not np.array_equal(global_columns, known[1].global_columns):
        return False
    for handle, block in zip(handles, known):
        with _row_ij(handle) as (indptr, indices, _):
            if not (np.array_equal(indptr, block.indptr)
                    and np.array_equal(indices, block.indices)):
                return False
    return True


def storage(M: PETSc.Mat) -> tuple[tuple[int, ...], ...]:
    """Where ``M``'s local blocks keep their patterns, and their sizes (what
    :func:`blocks` gives as ``Block.storage``), without copying the patterns.

    PETSc's AIJ matrices keep a pattern until new entries come, and then
    allocate new arrays while the old ones still exist, or (entries that fill
    preallocated room) change the count. So an unchanged storage is an
    unchanged pattern, except where entries are removed from a matrix, which
    the library never does to its Newton matrix."""
    found = []
    for handle in block_handles(M)[:2]:
        if handle is not None:
            with _row_ij(handle) as (_, _, where):
                found.append(where)
    return tuple(found)


@contextmanager
def values(handle: int, nnz: int) -> Iterator[np.ndarray]:
    """The value array of the SeqAIJ block ``handle``, in place (writing to it
    changes the matrix; PETSc is told when the block is given back)."""
    array = _ScalarP()
    _call("MatSeqAIJGetArray", handle, ctypes.byref(array))
    try:
        # as float64, not ctypes' own dtype: np.add.at takes its fast path only then
        # (1.4 ms against 25 ms for 670k entries)
        yield (np.ctypeslib.as_array(array, shape=(nnz,)).view(np.float64) if nnz
               else np.zeros(0, dtype=np.float64))
    finally:
        _call("MatSeqAIJRestoreArray", handle, ctypes.byref(array))
