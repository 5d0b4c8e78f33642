"""Each MPI rank runs its own pytest session: give each its own temporary root.

pytest prunes old numbered folders under /tmp/pytest-of-<user>; two ranks
sharing that root can delete each other's files mid-test.
"""
from __future__ import annotations

import tempfile
from pathlib import Path


def pytest_configure(config):
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    if comm.size > 1 and not config.option.basetemp:
        root = Path(tempfile.gettempdir()) / "dolfinx_mortar_pytest"
        root.mkdir(parents=True, exist_ok=True)  # pytest creates basetemp, not its parent
        config.option.basetemp = str(root / f"rank{comm.rank}")
