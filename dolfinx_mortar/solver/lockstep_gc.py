"""Python's cycle collector kept in step over the MPI ranks during a solve.

DOLFINx's ``la.Vector.__del__`` destroys its PETSc vector at once, not through
petsc4py's collective garbage. A Function caught in a reference cycle is
freed when Python's cycle collector runs, and that runs after a count of
allocations, which differs from rank to rank. Where it frees the last PETSc
object of a communicator on one rank only, PETSc drops its inner
communicator there, and the next PETSc object made on that communicator
duplicates it (``MPI_Comm_dup``, collective) on that rank alone: the ranks
then wait in different collectives for ever. Found in the 2-rank test suite
(one rank in ``MPI_Comm_dup``, the other in ``MPI_Allgather``, both inside
``VecCreateGhostBlockWithArray``, spinning in ``sched_yield``), and reproduced
in a few lines on DOLFINx 0.9 and 0.11 (tests/solver/test_lockstep_gc.py).
So while the library solves on several ranks the automatic collector is off,
and the cycles are collected where every rank is at the same point of the
same program: at each load-step attempt (the solver's, the first when a
solve starts).
"""
from __future__ import annotations

import gc
from contextlib import contextmanager
from typing import Iterator

from mpi4py import MPI
from petsc4py import PETSc


def collect_in_lockstep(comm: MPI.Comm) -> None:
    """Collect Python's reference cycles and PETSc's parallel garbage on
    every rank at this point (collective; nothing on one rank)."""
    if comm.size > 1:
        gc.collect()
        PETSc.garbage_cleanup(comm)


@contextmanager
def lockstep_garbage_collection(comm: MPI.Comm) -> Iterator[None]:
    """Inside the block, Python's automatic cycle collection is off on a
    communicator of several ranks (collect with :func:`collect_in_lockstep`);
    it is restored as it was afterwards. On one rank nothing changes."""
    if comm.size == 1:
        yield
        return
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
