"""Mortar bases on tagged facets of DOLFINx meshes, in serial and on 2 ranks.

Run this file under ``mpirun -n 2``: the distributed results are compared with a
serial computation on a ``COMM_SELF`` copy of the same mesh, node by node.
"""
from __future__ import annotations

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from dolfinx.fem.petsc import assemble_matrix, assemble_vector
from mpi4py import MPI
from petsc4py import PETSc
from scipy.spatial import cKDTree

from dolfinx_mortar import KIND_NAMES, MortarBasis
from dolfinx_mortar.surfaces.facet_surface import facet_surface

SLAVE = 7

CASES = {
    "triangle-P1": (mesh.CellType.triangle, 1),
    "triangle-P2": (mesh.CellType.triangle, 2),
    "tetrahedron-P1": (mesh.CellType.tetrahedron, 1),
    "tetrahedron-P2": (mesh.CellType.tetrahedron, 2),
    "hexahedron-Q1": (mesh.CellType.hexahedron, 1),
    "hexahedron-Q2": (mesh.CellType.hexahedron, 2),
}
#: quadratic triangle facets need the transformed basis for the W kinds
TRANSFORMED = {"tetrahedron-P2"}


def build(comm, cell_type, degree):
    """Unit square/cube; slave = the boundary facets with x < 0.8: parts of three
    (2D) or five (3D) sides, with corners and edges where sides meet."""
    if cell_type in (mesh.CellType.triangle, mesh.CellType.quadrilateral):
        domain = mesh.create_unit_square(comm, 6, 5, cell_type=cell_type)
    else:
        domain = mesh.create_unit_cube(comm, 4, 3, 3, cell_type=cell_type)
    fdim = domain.topology.dim - 1
    facets = mesh.locate_entities_boundary(domain, fdim, lambda x: x[0] < 0.8)
    tags = mesh.meshtags(domain, fdim, np.sort(facets).astype(np.int32),
                         np.full(len(facets), SLAVE, dtype=np.int32))
    V = fem.functionspace(domain, ("Lagrange", degree))
    return domain, tags, V


def pressure(x):
    return np.maximum(0.0, 0.2 - (x[0] - 0.3) ** 2 - 0.5 * (x[2] - 0.5) ** 2) + 0.05 * x[0]


def pressure_any_dim(x):
    """The pressure above, on the plane z = 0.5 for 2D points."""
    if x.shape[0] == 2:
        x = np.vstack([x, np.full(x.shape[1], 0.5)])
    return pressure(x)


def owned_by_coordinates(V, values):
    """(coordinates, values) of the owned dofs, gathered on every rank."""
    n = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:n]
    xs = np.vstack(V.mesh.comm.allgather(x))
    vs = np.concatenate(V.mesh.comm.allgather(np.asarray(values)[:n]))
    return xs, vs


@pytest.mark.parametrize("case", CASES)
def test_weights_and_mass_match_dolfinx_facet_forms(case):
    domain, tags, V = build(MPI.COMM_WORLD, *CASES[case])
    surface = facet_surface(V, tags, SLAVE)
    b = MortarBasis("GLS", surface)
    ds = ufl.Measure("ds", domain=domain, subdomain_data=tags)(SLAVE)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    W = assemble_vector(fem.form(v * ds))
    W.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    n = V.dofmap.index_map.size_local
    assert np.allclose(b.lumped_weights[:n], W.array, rtol=0, atol=1e-14)
    total = domain.comm.allreduce(np.sum(b.lumped_weights[:n]))
    area = domain.comm.allreduce(fem.assemble_scalar(fem.form(fem.Constant(domain, 1.0) * ds)))
    assert area > 0.3 and total == pytest.approx(area, rel=1e-12)

    L = assemble_matrix(fem.form(u * v * ds))
    L.assemble()
    r = L.createVecRight()
    r.array[:] = np.random.default_rng(domain.comm.rank).uniform(size=n)
    y_dolfinx, y_mortar = L.createVecLeft(), L.createVecLeft()
    L.mult(r, y_dolfinx)
    b.mass_solver.matrix.mult(r, y_mortar)
    on_surface = W.array > 0
    assert np.allclose(y_mortar.array[on_surface], y_dolfinx.array[on_surface],
                       rtol=0, atol=1e-14)


@pytest.mark.parametrize("case", ["triangle-P1", "triangle-P2", "tetrahedron-P1",
                                  "tetrahedron-P2", "hexahedron-Q2"])
@pytest.mark.parametrize("kind", KIND_NAMES)
def test_nodal_pressures_agree_on_one_and_all_ranks(case, kind):
    comm = MPI.COMM_WORLD
    results, local_cells = [], []
    for c in (comm, MPI.COMM_SELF):
        domain, tags, V = build(c, *CASES[case])
        surface = facet_surface(V, tags, SLAVE, quadratic_transform=case in TRANSFORMED)
        local_cells.append(len(surface.cells))
        values = MortarBasis(kind, surface).nodal_values(pressure_any_dim)
        results.append(owned_by_coordinates(V, values))
    # two ranks at least must hold slave facets, or the ghost exchange went untested (on
    # 3 ranks the partition may leave one rank without any: it then holds 0 of them)
    holding = sum(count > 0 for count in comm.allgather(local_cells[0]))
    assert holding >= min(comm.size, 2), holding
    (x_par, v_par), (x_ser, v_ser) = results
    assert len(x_par) == len(x_ser)
    distance, index = cKDTree(x_ser).query(x_par)
    assert np.max(distance) < 1e-12
    scale = np.max(np.abs(v_ser))
    assert scale > 0
    assert np.max(np.abs(v_par - v_ser[index])) <= 1e-10 * scale


def test_facet_nodes_follow_the_reference_ordering():
    """The isoparametric map at the reference nodes gives back the node coordinates
    (fails if DOLFINx's facet closure ordering differed from Basix's)."""
    for cell_type, degree in CASES.values():
        domain, tags, V = build(MPI.COMM_WORLD, cell_type, degree)
        surface = facet_surface(V, tags, SLAVE)
        ref = surface.reference
        nc = len(surface.cells)
        if nc == 0:
            continue
        cells = np.repeat(np.arange(nc), ref.num_functions)
        X = np.tile(ref.nodes, (nc, 1))
        _, x, _ = surface.tabulate_at(cells, X)
        assert np.allclose(x, surface.x[surface.cells].reshape(-1, surface.gdim), atol=1e-14)


def test_mesh_argument_uses_geometry_degree_on_curved_gmsh_mesh():
    gmsh = pytest.importorskip("gmsh")
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    comm = MPI.COMM_WORLD
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            gmsh.model.add("disk")
            disk = gmsh.model.occ.addDisk(0, 0, 0, 1.0, 1.0)
            gmsh.model.occ.synchronize()
            gmsh.model.addPhysicalGroup(2, [disk], 1)
            boundary = gmsh.model.getBoundary([(2, disk)], oriented=False)
            gmsh.model.addPhysicalGroup(1, [b[1] for b in boundary], SLAVE)
            gmsh.option.setNumber("Mesh.CharacteristicLengthMax", 0.3)
            gmsh.model.mesh.generate(2)
            gmsh.model.mesh.setOrder(2)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    surface = facet_surface(domain, facet_tags, SLAVE)
    assert surface.reference.degree == 2
    b = MortarBasis("LcLS*", surface, quadrature_degree=8)
    n = b.layout.num_owned
    perimeter = comm.allreduce(np.sum(b.lumped_weights[:n]))
    ds = ufl.Measure("ds", domain=domain, subdomain_data=facet_tags)(SLAVE)
    reference = comm.allreduce(fem.assemble_scalar(
        fem.form(fem.Constant(domain, 1.0) * ds(metadata={"quadrature_degree": 8}))))
    assert perimeter == pytest.approx(reference, rel=1e-12)
    assert perimeter == pytest.approx(2 * np.pi, rel=1e-4)  # P2 circle geometry error
