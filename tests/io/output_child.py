"""A small contact run with many load steps and XDMF output, to be killed.

Run by tests/io/test_output_crash.py (``python output_child.py <output.xdmf> <steps>``,
on one rank or under mpirun). Prints ``ready <pid of every rank>`` once the
problem is built, so that the killer knows the output is about to start.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

from dolfinx import fem
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/, for support
sys.path.insert(1, str(Path(__file__).resolve().parents[2] / "demos"))  # demo_support
from support.meshes import rectangle  # noqa: E402
from dolfinx_mortar.contact.obstacles import RigidPlane  # noqa: E402
from dolfinx_mortar import ContactProblem  # noqa: E402

output, steps = sys.argv[1], int(sys.argv[2])
domain, tags = rectangle(MPI.COMM_WORLD, 0.0, 0.5, (8, 4), bottom=1, top=2, left=3)
V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
problem = ContactProblem(V, tags, 1, obstacle=RigidPlane([0, 0], [0, 1]), E=1.0, nu=0.3,
                         kind="LcLS*", penalty=1e4, fixed={3: {0: 0.0}},
                         tractions={2: [0.0, -0.01]})
pids = MPI.COMM_WORLD.gather(os.getpid())
if MPI.COMM_WORLD.rank == 0:
    print("ready " + " ".join(str(pid) for pid in pids), flush=True)
problem.solve(load_steps=steps, output=output)
if MPI.COMM_WORLD.rank == 0:
    print("done", flush=True)
