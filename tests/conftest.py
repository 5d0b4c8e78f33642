"""Shared pytest set-up.

- The test helpers live in ``tests/support``; the test folders mirror the
  package's subpackages, so put ``tests/`` on the path once, here, and
  ``demos/`` for the scenes the demos share (``demo_support``, not part of
  the installed library).
- Each MPI rank runs its own pytest session: give each its own temporary root.
  pytest prunes old numbered folders under /tmp/pytest-of-<user>; two ranks
  sharing that root can delete each other's files mid-test.
- On several ranks Python's automatic cycle collector is off and cycles are
  collected after each test, on every rank at once: collected on one rank
  alone, a Function's PETSc vector left the ranks in different collectives
  (dolfinx_mortar/solver/lockstep_gc.py; the 2-rank suite hung in
  test_hard_cases.py in sid).
"""
from __future__ import annotations

import gc
import sys
import tempfile
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(Path(__file__).resolve().parents[1] / "demos"))


def pytest_collection_finish(session):
    """On several ranks: what exists once the tests are collected (modules,
    the test items) is left out of every later collection (``gc.freeze``), so
    that the collection after each test reads only what the tests made."""
    from mpi4py import MPI
    if MPI.COMM_WORLD.size > 1:
        gc.collect()
        gc.freeze()


@pytest.fixture(autouse=True)
def cycles_collected_in_lockstep():
    """On several ranks: no automatic cycle collection during a test, a
    collection on every rank after it (see the module)."""
    from mpi4py import MPI
    if MPI.COMM_WORLD.size > 1:
        gc.disable()
    yield
    if MPI.COMM_WORLD.size > 1:
        gc.collect()


def pytest_configure(config):
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    if comm.size > 1 and not config.option.basetemp:
        root = Path(tempfile.gettempdir()) / "dolfinx_mortar_pytest"
        root.mkdir(parents=True, exist_ok=True)  # pytest creates basetemp, not its parent
        config.option.basetemp = str(root / f"rank{comm.rank}")
