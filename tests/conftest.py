"""Shared pytest set-up.

- The test helpers live in ``tests/support``; the test folders mirror the
  package's subpackages, so put ``tests/`` on the path once, here, and
  ``demos/`` for the scenes the demos share (``demo_support``, not part of
  the installed library).
- Each MPI rank runs its own pytest session: give each its own temporary root.
  pytest prunes old numbered folders under /tmp/pytest-of-<user>; two ranks
  sharing that root can delete each other's files mid-test.
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(Path(__file__).resolve().parents[1] / "demos"))


def pytest_configure(config):
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    if comm.size > 1 and not config.option.basetemp:
        root = Path(tempfile.gettempdir()) / "dolfinx_mortar_pytest"
        root.mkdir(parents=True, exist_ok=True)  # pytest creates basetemp, not its parent
        config.option.basetemp = str(root / f"rank{comm.rank}")
