"""Why dolfinx_mortar partitions its meshes with one PT-Scotch thread per rank
(dolfinx_compat._scotch_without_threads): PT-Scotch 7 partitions with threads that
call MPI collectives of their own, and in Debian sid (Scotch 7.0.16, Open MPI
6.0.0rc2) a distributed graph's partition then never ended.

    timeout 150 mpirun -n 4 --oversubscribe python3 tools/scotch_thread_hang.py 600 default
    timeout 150 mpirun -n 4 --oversubscribe python3 tools/scotch_thread_hang.py 600

Each step merges two small meshes (merge_meshes: dolfinx.mesh.create_mesh on the
cells every rank holds, partitioned by DOLFINx's default graph partitioner,
PT-Scotch in Debian). "default" switches the library's guard off, so Scotch takes
its default thread number; without it the library sets SCOTCH_PTHREAD_NUMBER=1.
On 2 cores "default" hung (at step 10-420) in seven runs of seven (gdb: each rank's
main thread in Scotch's threadLaunch, a Scotch thread in MPI_Allreduce of
dgraphInducePart); with the guard 600 steps ended in 8.5-12 s, four times of
four. Tidied versions of this script (other names, no tuple unpacking, fewer
prints) ended 600 steps in 28-35 s even with "default", seven times of seven:
the hang depends on timing, and a run that ends proves nothing. This one is kept
as it was when it hung.
"""
import sys, time
import numpy as np
from mpi4py import MPI
import dolfinx
from dolfinx.mesh import create_rectangle, locate_entities_boundary, meshtags, CellType
from dolfinx_mortar.meshes.merge_meshes import merge_meshes

import contextlib
from dolfinx_mortar import dolfinx_compat
if "default" in sys.argv: dolfinx_compat._scotch_without_threads = contextlib.nullcontext
comm = MPI.COMM_WORLD
n = int(sys.argv[1]) if len(sys.argv) > 1 else 50
def body(y0, m):
    d = create_rectangle(comm, [[0, y0], [1, y0 + 1]], [m, m], CellType.triangle)
    d.topology.create_connectivity(1, 2)
    f = locate_entities_boundary(d, 1, lambda x: np.isclose(x[1], y0))
    return d, meshtags(d, 1, np.sort(f).astype(np.int32), np.full(len(f), 1, np.int32))
a = body(0.0, 12); b = body(1.0, 9)
t0 = time.time()
for i in range(n):
    m, ft, ct = merge_meshes(*a, *b, tag_offset=10)
    if comm.rank == 0 and i % 10 == 0:
        print(i, f"{time.time()-t0:.1f}s", flush=True)
print("done", comm.rank, f"{time.time()-t0:.1f}s", flush=True)
