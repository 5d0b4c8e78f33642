"""Reading gmsh files: the geometric dimension is the mesh's own unless given."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar import ContactProblem, RigidPlane
from dolfinx_mortar.io.gmsh_io import model_dimension, read_gmsh

BODY, BOTTOM, TOP, LEFT = 1, 2, 3, 4


def rectangle_model(z: float = 0.0) -> None:
    """A [0,1]×[0,0.5] rectangle in the plane at height z, meshed, with the
    named physical groups body, bottom, top, left (on this rank's gmsh)."""
    import gmsh
    occ = gmsh.model.occ
    occ.addRectangle(0, 0, z, 1, 0.5)
    occ.synchronize()
    for line in gmsh.model.getEntities(1):
        x, y, _ = occ.getCenterOfMass(*line)
        for tag, name, on in ((BOTTOM, "bottom", np.isclose(y, 0)),
                              (TOP, "top", np.isclose(y, 0.5)), (LEFT, "left", np.isclose(x, 0))):
            if on:
                gmsh.model.addPhysicalGroup(1, [line[1]], tag)
                gmsh.model.setPhysicalName(1, tag, name)
    gmsh.model.addPhysicalGroup(2, [1], BODY)
    gmsh.model.setPhysicalName(2, BODY, "body")
    gmsh.option.setNumber("Mesh.CharacteristicLengthMax", 0.125)
    gmsh.model.mesh.generate(2)


def test_a_2d_msh_file_is_read_as_2d_and_solves(tmp_path_factory):
    """read_gmsh without gdim gave a mesh in 3D for a 2D file (DOLFINx's
    default), and the contact problem on it failed; now it is 2D."""
    import gmsh
    comm = MPI.COMM_WORLD
    path = comm.bcast(str(tmp_path_factory.mktemp("msh") / "rectangle.msh")
                      if comm.rank == 0 else None)
    if comm.rank == 0:
        gmsh.initialize(["", "-v", "0"])
        try:
            rectangle_model()
            gmsh.write(path)
        finally:
            gmsh.finalize()
    comm.barrier()
    domain, _, facet_tags, names = read_gmsh(path, comm)
    assert domain.geometry.dim == 2
    assert names[1] == {"bottom": BOTTOM, "top": TOP, "left": LEFT}
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    problem = ContactProblem(V, facet_tags, names[1]["bottom"],
                             obstacle=RigidPlane([0, 0], [0, 1]), E=1.0, nu=0.3,
                             kind="LcLS*", penalty=1e3, fixed={LEFT: {0: 0.0}},
                             tractions={TOP: [0.0, -0.01]})
    problem.solve(load_steps=1)
    # the plane carries the load on the top face (width 1)
    assert problem.contact_force() == pytest.approx([0.0, 0.01], abs=1e-10)
    # given, the dimension is taken as it is
    assert read_gmsh(path, comm, gdim=3)[0].geometry.dim == 3


@pytest.mark.parametrize("z, expected", [(0.0, 2), (0.5, 3)])
def test_model_dimension_of_a_plane_mesh(z, expected):
    """In the plane z = 0 a 2D mesh is 2D; lifted off it, a surface in space."""
    import gmsh
    gmsh.initialize(["", "-v", "0"])
    try:
        if MPI.COMM_WORLD.rank == 0:
            rectangle_model(z)
        assert model_dimension(gmsh.model, MPI.COMM_WORLD, 0) == expected
    finally:
        gmsh.finalize()
