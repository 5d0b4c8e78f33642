"""PETSc's C library, for the few public functions petsc4py does not wrap."""
from __future__ import annotations

import ctypes
from functools import cache
from typing import Optional

from petsc4py import PETSc


@cache
def petsc_library() -> Optional[ctypes.CDLL]:
    """The PETSc library that petsc4py itself loaded, or None if it cannot be
    opened. Callers set each function's argument and result types.

    Through petsc4py's own extension module first: it links libpetsc, and a
    symbol is looked up through its dependencies, whatever libpetsc's file is
    called; then by Debian's names for this version."""
    major, minor, _ = PETSc.Sys.getVersion()
    for name in (PETSc.__file__, f"libpetsc_real.so.{major}.{minor}",
                 f"libpetsc.so.{major}.{minor}"):
        try:
            lib = ctypes.CDLL(name)
            lib.MatGetSize    # a symbol of libpetsc (or AttributeError)
            return lib
        except (OSError, AttributeError):
            continue
    return None
