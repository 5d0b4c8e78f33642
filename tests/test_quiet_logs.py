"""A first run on a cold FFCx cache keeps the terminal quiet unless asked."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from mpi4py import MPI

SCRIPT = """
import dolfinx_mortar, ufl
from mpi4py import MPI
from dolfinx import fem, mesh
m = mesh.create_unit_square(MPI.COMM_SELF, 2, 2)
V = fem.FunctionSpace(m, ("Lagrange", 2))
fem.form(ufl.inner(ufl.TrialFunction(V), ufl.TestFunction(V)) * 1.25 * ufl.dx)
"""


def compile_on_cold_cache(tmp_path: Path, **env: str) -> str:
    environment = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache"),
                   "PYTHONPATH": str(Path(__file__).resolve().parents[1]), **env}
    # a fresh interpreter outside mpirun: its own cold cache, its own logging setup
    for key in [k for k in environment if k.startswith(("OMPI_", "PMIX_"))]:
        del environment[key]
    run = subprocess.run([sys.executable, "-c", SCRIPT], env=environment, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    return run.stderr


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="one subprocess per machine is enough")
def test_ffcx_build_lines_are_hidden_unless_asked(tmp_path):
    assert "running build_ext" not in compile_on_cold_cache(tmp_path / "quiet")
    loud = compile_on_cold_cache(tmp_path / "loud", DOLFINX_MORTAR_BUILD_LOGS="1")
    assert "running build_ext" in loud
