"""An output that cannot be written raises the same error on every rank (no rank left
waiting in a collective): rank 0 alone prepares the folder and writes the index of an
XDMF series (dolfinx_mortar.io.xdmf_series, dolfinx_mortar.io.output.on_rank0).

A gmsh file that rank 0 cannot read raises on every rank too.

The unwritable places stop root too (a chmod does not): a path under a regular
file, and sysfs, where nobody creates files."""
from __future__ import annotations

import os
from pathlib import Path

import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar import RigidPlane
from dolfinx_mortar.io.xdmf_series import XdmfSeries
from support.scenes import pressed_block

comm = MPI.COMM_WORLD


def shared_folder(tmp_path_factory, name: str) -> Path:
    folder = tmp_path_factory.mktemp(name) if comm.rank == 0 else None
    return Path(comm.bcast(folder))


def errors_on_every_rank(call) -> list:
    """The error each rank raised from ``call()``, gathered on every rank."""
    with pytest.raises(OSError) as info:
        call()
    return comm.allgather((type(info.value).__name__, str(info.value)))


@pytest.fixture(scope="module")
def problem():
    return pressed_block(RigidPlane([0, 0], [0, 1]), "LcLS*", n=(4, 2))


def under_a_file(folder: Path) -> Path:
    if comm.rank == 0:
        (folder / "results").write_text("a file, not a folder\n")
    comm.barrier()
    return folder / "results" / "block.xdmf"


def under_a_file_deeper(folder: Path) -> Path:
    return under_a_file(folder).parent / "run" / "block.xdmf"


def in_sysfs(folder: Path) -> Path:
    if not os.path.ismount("/sys"):   # else root could create the folder
        pytest.skip("sysfs is not mounted at /sys")
    return Path("/sys/dolfinx_mortar_test_output/block.xdmf")


@pytest.mark.parametrize("place, error", [(under_a_file, "NotADirectoryError"),
                                          (under_a_file_deeper, "NotADirectoryError"),
                                          (in_sysfs, None)])
def test_unwritable_output_folder_raises_on_every_rank(problem, tmp_path_factory, place, error):
    output = place(shared_folder(tmp_path_factory, "unwritable"))
    errors = errors_on_every_rank(lambda: problem.solve(load_steps=1, output=output))
    assert len(set(errors)) == 1, errors
    kind, message = errors[0]
    if error is not None:
        assert kind == error, errors[0]
    assert str(output.parent) in message or str(output.parent.parent) in message, message
    assert "block.xdmf" in message, message   # which output failed


def test_index_that_cannot_be_replaced_raises_on_every_rank(tmp_path_factory):
    """A step's index is written by rank 0 alone; here its path became a folder."""
    folder = shared_folder(tmp_path_factory, "index")
    domain = mesh.create_unit_square(comm, 2, 2)
    u = fem.Function(fem.functionspace(domain, ("Lagrange", 1)), name="u")
    series = XdmfSeries(folder / "u.xdmf", domain)
    series.write([u], 0.5)
    if comm.rank == 0:
        (folder / "u.xdmf").unlink()
        (folder / "u.xdmf").mkdir()
        (folder / "u.xdmf" / "keep").touch()   # a folder that os.replace cannot remove
    comm.barrier()
    errors = errors_on_every_rank(lambda: series.write([u], 1.0))
    assert len(set(errors)) == 1, errors
    assert errors[0][0] == "IsADirectoryError" and "u.xdmf" in errors[0][1], errors[0]


def test_gmsh_file_that_does_not_parse_raises_on_every_rank(tmp_path_factory):
    """Rank 0 alone opens the file (dolfinx_mortar.io.gmsh_io.read_gmsh)."""
    from dolfinx_mortar.io.gmsh_io import read_gmsh
    folder = shared_folder(tmp_path_factory, "gmsh")
    if comm.rank == 0:
        (folder / "broken.msh").write_text("$MeshFormat\nnot a mesh\n")
    comm.barrier()
    with pytest.raises(RuntimeError) as info:
        read_gmsh(folder / "broken.msh", comm, gdim=2)
    errors = comm.allgather(str(info.value))
    assert len(set(errors)) == 1 and "broken.msh" in errors[0], errors
