"""Importing the library leaves the interpreter as it was, and names what it offers."""
from __future__ import annotations

import subprocess
import sys

import pytest
from mpi4py import MPI

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
                         timeout=300, env={k: v for k, v in __import__("os").environ.items()
                                           if not k.startswith(("OMPI_", "PMIX_"))})
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
                         timeout=300, env={k: v for k, v in __import__("os").environ.items()
                                           if not k.startswith(("OMPI_", "PMIX_"))})
    assert run.returncode == 0, run.stderr
    assert "RuntimeWarning: the contact misses them" in run.stderr
