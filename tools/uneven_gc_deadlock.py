"""Why dolfinx_mortar collects Python's reference cycles in lockstep on several
ranks (dolfinx_mortar/solver/lockstep_gc.py): a Function freed by the cycle
collector on one rank only leaves the next PETSc object on its communicator
waiting for ever.

    timeout 60 mpirun -n 2 python3 tools/uneven_gc_deadlock.py even     # ends
    timeout 60 mpirun -n 2 python3 tools/uneven_gc_deadlock.py uneven   # hangs

DOLFINx's ``la.Vector.__del__`` destroys the PETSc vector at once. Freed on
rank 0 only, the vector was the last PETSc object on the space's communicator
there, so PETSc freed its inner communicator on rank 0; the next vector
duplicates it on rank 0 (MPI_Comm_dup) while rank 1 is already in the
layout's MPI_Allgather. Hangs with DOLFINx 0.9 (Debian 13) and 0.11 (sid).
"""
import gc
import sys

from mpi4py import MPI
from dolfinx import fem, mesh

comm = MPI.COMM_WORLD
gc.disable()
V = fem.functionspace(mesh.create_unit_square(comm, 4, 4), ("Lagrange", 1))
g = fem.Function(V)
g.x.petsc_vec           # PETSc's inner communicator of V's index map, on both ranks
g.cycle = g             # only the cycle collector frees g
del g
if comm.rank == 0 and sys.argv[1:] == ["uneven"]:
    gc.collect()        # what an automatic collection on one rank does
h = fem.Function(V)
h.x.petsc_vec
comm.Barrier()
print(f"rank {comm.rank}: the second vector was made", flush=True)
