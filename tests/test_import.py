"""Importing the library leaves the interpreter as it was, and names what it offers."""
from __future__ import annotations

import subprocess
import sys

import pytest
from mpi4py import MPI

from support import child_environment

SCRIPT = """
import logging
root = logging.getLogger()
before = (root.level, list(root.handlers), list(root.filters))
import dolfinx_mortar
from dolfinx_mortar import ContactTerm, NonlinearContactProblem, LoadPathSolver
assert (root.level, list(root.handlers), list(root.filters)) == before, "root logger changed"
names = set(dir(dolfinx_mortar))
missing = {"ContactTerm", "NonlinearContactProblem", "LoadPathSolver", "ContactProblem",
           "NewtonSolver", "RigidPlane", "RigidSphere", "RigidCylinder", "SurfacePressure",
           "DegenerateGeometryError", "__version__"} - names
assert not missing, missing
print(dolfinx_mortar.__version__)
"""


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="one subprocess per machine is enough")
def test_import_leaves_the_root_logger_alone_and_lists_the_main_classes():
    # a fresh interpreter: this one has imported the library long ago
    run = subprocess.run([sys.executable, "-P", "-c", SCRIPT], capture_output=True, text=True,
                         timeout=300, env=child_environment())
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip()


WARNING = """
import warnings
import dolfinx
from dolfinx_mortar import ContactProblem
warnings.warn("the contact misses them", RuntimeWarning)
"""


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="one subprocess per machine is enough")
def test_warnings_are_shown_after_dolfinx_is_imported():
    """FFCx 0.9's package init sent every Python warning to a logger with a
    NullHandler: a script saw none of the library's warnings in Debian 13 (pytest,
    which catches them itself, did). Python's default shows them once on stderr."""
    run = subprocess.run([sys.executable, "-P", "-c", WARNING], capture_output=True, text=True,
                         timeout=300, env=child_environment())
    assert run.returncode == 0, run.stderr
    assert "RuntimeWarning: the contact misses them" in run.stderr


SHOWN_ONCE = """
import warnings
import numpy as np
from mpi4py import MPI
from dolfinx import fem, mesh
from dolfinx_mortar import ContactTerm, ContactWarning, RigidPlane

domain = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
facets = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 0.0))
tags = mesh.meshtags(domain, 1, facets, np.full(len(facets), 1, dtype=np.int32))
u = fem.Function(V)


def term():
    # its normal points into the body: a warning from within the term's checks
    return ContactTerm(u, tags, 1, obstacle=RigidPlane([0.0, 2.0], [0.0, -1.0]), penalty=1e3)


term()                                  # the default filters
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")     # what a test or a user asking for them sees
    term()
print(MPI.COMM_WORLD.rank, *[w.category.__name__ for w in caught
                             if issubclass(w.category, ContactWarning)], flush=True)
"""


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="one child run of 2 ranks is enough")
def test_a_warning_of_all_ranks_is_shown_once_and_issued_on_each():
    """Under mpirun every rank printed each of the library's warnings (16 copies
    on 16 ranks). The first rank of the communicator shows it; the others issue
    a copy that the default filters ignore, and that a filter asking for
    warnings ("always", "error", pytest.warns) sees on every rank, so that an
    error raises on all of them together. A warning names the user's line that
    called into the library."""
    env = {**child_environment(), "OMPI_MCA_btl": "self,sm"}   # the Makefile's transport
    run = subprocess.run(["mpirun", "-n", "2", "--oversubscribe", sys.executable, "-P", "-c",
                          SHOWN_ONCE], capture_output=True, text=True, timeout=300, env=env)
    assert run.returncode == 0, run.stderr
    assert run.stderr.count("faces away from the slave surface") == 1, run.stderr
    # named at the user's line (the script's), not at a line of the library's call path
    assert "<string>:" in run.stderr and "dolfinx_mortar/" not in run.stderr, run.stderr
    ranks = sorted(line for line in run.stdout.splitlines() if line[:1].isdigit())
    assert ranks == ["0 ContactWarning", "1 ContactWarningCopy"], run.stdout
