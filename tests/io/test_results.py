"""Results a user can take away: the pressure and the friction read-outs with their
coordinates, exact zeros off the slave surface in the output, and output files other users
can read."""
from __future__ import annotations

import os
import stat
from pathlib import Path

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar import (ContactProblem, CoulombFriction, RigidPlane, SurfaceFriction,
                            SurfacePressure, read_xdmf_series)
from dolfinx_mortar.io.output import write_json
from support.meshes import rectangle

TRACTION = 0.01
N_CELLS = (8, 4)


def pressed_block(degree: int, shear: float = 0.0, friction=None) -> ContactProblem:
    """[0,1]×[0,0.5] pressed by a uniform traction onto the plane y = 0: p = TRACTION
    (sheared by ``shear`` too)."""
    domain, tags = rectangle(MPI.COMM_WORLD, 0.0, 0.5, N_CELLS, bottom=1, top=2, left=3)
    V = fem.functionspace(domain, ("Lagrange", degree, (2,)))
    return ContactProblem(V, tags, 1, obstacle=RigidPlane([0, 0], [0, 1]), E=1.0, nu=0.3,
                          penalty=1e4, fixed={3: {0: 0.0}}, tractions={2: [shear, -TRACTION]},
                          friction=friction)


def shared_folder(tmp_path_factory, name: str) -> Path:
    folder = tmp_path_factory.mktemp(name) if MPI.COMM_WORLD.rank == 0 else None
    return Path(MPI.COMM_WORLD.bcast(folder))


@pytest.mark.parametrize("degree", [1, 2])
def test_surface_pressure_has_the_bottom_nodes_and_their_coordinates(degree):
    problem = pressed_block(degree)
    problem.solve(load_steps=1)
    nodes_on_bottom = degree * N_CELLS[0] + 1
    everything = problem.surface_pressure(gather=True)
    assert isinstance(everything, SurfacePressure)
    assert everything.x.shape == (nodes_on_bottom, 2)
    assert np.allclose(everything.x[:, 0], np.linspace(0.0, 1.0, nodes_on_bottom), atol=1e-14)
    assert np.allclose(everything.x[:, 1], 0.0, atol=1e-14)
    # the uniform traction reaches the plane unchanged (penalty 1e4: to 1e-6 relative)
    assert np.allclose(everything.p, TRACTION, rtol=1e-6)
    assert len(np.unique(everything.global_index)) == nodes_on_bottom
    # the ranks' own parts are a partition of the gathered one
    mine = problem.surface_pressure()
    assert len(mine.p) == len(mine.x) == len(mine.global_index)
    assert MPI.COMM_WORLD.allreduce(len(mine.p)) == nodes_on_bottom
    gathered_by_index = dict(zip(everything.global_index.tolist(), everything.p.tolist()))
    assert all(gathered_by_index[g] == p for g, p in zip(mine.global_index.tolist(),
                                                           mine.p.tolist()))


def test_friction_read_outs_have_the_bottom_nodes_and_their_coordinates():
    """surface_friction gives q_A and the stick/slip state with the nodes'
    coordinates, as surface_pressure gives p_A: each rank's part and the
    gathered whole hold the layout arrays' values at the same nodes."""
    mu = 0.15
    problem = pressed_block(1, shear=0.2 * TRACTION, friction=CoulombFriction(mu))
    problem.solve(load_steps=2)
    results = problem.contact.results
    everything = results.surface_friction(gather=True)
    assert isinstance(everything, SurfaceFriction)
    pressure = problem.surface_pressure(gather=True)
    n = N_CELLS[0] + 1
    assert everything.x.shape == (n, 2) and everything.q.shape == (n, 2)
    assert everything.stick_slip.shape == (n,)
    assert np.array_equal(everything.x, pressure.x)
    assert np.array_equal(everything.global_index, pressure.global_index)
    assert np.all(np.diff(everything.x[:, 0]) > 0)
    # every node presses; the shear makes some stick and some slip, along x only
    assert set(everything.stick_slip.tolist()) == {1, 2}, everything.stick_slip
    assert np.all(np.abs(everything.q[:, 1]) < 1e-12 * TRACTION)
    slipping = everything.stick_slip == 2
    assert np.allclose(np.abs(everything.q[slipping, 0]), mu * pressure.p[slipping], rtol=1e-9)
    assert np.all(np.abs(everything.q[:, 0]) <= mu * pressure.p * (1 + 1e-9))
    # this rank's part: the layout arrays' values at its owned surface nodes
    mine = results.surface_friction()
    q, states = results.tangential_tractions(), results.slip_states()
    layout = problem.contact.slave.layout
    local = {g: i for i, g in enumerate(layout.global_indices[:layout.num_owned].tolist())}
    rows = [local[g] for g in mine.global_index.tolist()]
    assert np.array_equal(mine.q, q[rows]) and np.array_equal(mine.stick_slip, states[rows])
    assert MPI.COMM_WORLD.allreduce(len(rows)) == n
    by_index = dict(zip(everything.global_index.tolist(), everything.q[:, 0].tolist()))
    assert all(by_index[g] == v for g, v in zip(mine.global_index.tolist(),
                                                 mine.q[:, 0].tolist()))
    with pytest.raises(ValueError, match="no friction"):
        pressed_block(1).contact.results.surface_friction()


def pressed_box(degree: int) -> ContactProblem:
    """[0,1]²×[0,0.5] in tetrahedra pressed onto the plane z = 0: p = TRACTION."""
    domain = mesh.create_box(MPI.COMM_WORLD, [[0, 0, 0], [1, 1, 0.5]], [4, 4, 2])
    marks = [(1, lambda x: np.isclose(x[2], 0)), (2, lambda x: np.isclose(x[2], 0.5)),
             (3, lambda x: np.isclose(x[0], 0)), (4, lambda x: np.isclose(x[1], 0))]
    facets = [mesh.locate_entities_boundary(domain, 2, where) for _, where in marks]
    values = np.concatenate([np.full(len(f), tag, np.int32) for f, (tag, _) in zip(facets, marks)])
    facets = np.concatenate(facets)
    order = np.argsort(facets)
    tags = mesh.meshtags(domain, 2, facets[order], values[order])
    V = fem.functionspace(domain, ("Lagrange", degree, (3,)))
    return ContactProblem(V, tags, 1, obstacle=RigidPlane([0, 0, 0], [0, 0, 1]), E=1.0, nu=0.3,
                          penalty=1e4, quadratic_transform=True,
                          fixed={3: {0: 0.0}, 4: {1: 0.0}}, tractions={2: [0, 0, -TRACTION]})


@pytest.mark.parametrize("scene", ["2D-P1", "2D-P2", "3D-P2"])
def test_written_contact_pressure_is_zero_off_the_slave_surface(scene, tmp_path_factory):
    """Zero by construction off the surface, so compared with 0 exactly: with P2 on a P1
    tetrahedral mesh the pressure used to be interpolated to the vertices, which left
    1e-18 at 25 nodes off the surface."""
    folder = shared_folder(tmp_path_factory, "zeros")
    dim, degree = int(scene[0]), int(scene[-1])
    problem = pressed_block(degree) if dim == 2 else pressed_box(degree)
    problem.solve(load_steps=1, output=folder / "block.xdmf")
    data = read_xdmf_series(folder / "block.xdmf")
    _, written = data.field("contact_pressure")
    p = written[-1].ravel()
    on_surface = np.abs(data.geometry[:, dim - 1]) < 1e-14
    assert on_surface.sum() == (N_CELLS[0] + 1 if dim == 2 else 25)   # the vertices there
    assert np.all(p[~on_surface] == 0.0), np.abs(p[~on_surface]).max()
    assert np.allclose(p[on_surface], TRACTION, rtol=1e-6)


@pytest.mark.parametrize("umask", [0o022, 0o027])
def test_output_files_follow_the_umask(umask, tmp_path_factory):
    folder = shared_folder(tmp_path_factory, "umask")
    problem = pressed_block(1)
    previous = os.umask(umask)
    try:
        problem.solve(load_steps=2, output=folder / "block.xdmf")
        if MPI.COMM_WORLD.rank == 0:
            write_json(folder / "result.json", {"steps": 2})
        MPI.COMM_WORLD.barrier()
    finally:
        os.umask(previous)
    files = [f for f in folder.rglob("*") if f.is_file()]
    names = {f.name for f in files}
    assert {"block.xdmf", "block.h5", "block_slave.xdmf", "result.json"} <= names, names
    wrong = {str(f.relative_to(folder)): oct(stat.S_IMODE(f.stat().st_mode)) for f in files
             if stat.S_IMODE(f.stat().st_mode) != 0o666 & ~umask}
    assert not wrong, f"expected {oct(0o666 & ~umask)}: {wrong}"
