"""Small contact scenes shared by tests of several layers (public API only)."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar import ContactProblem
from support import load_demo
from support.meshes import rectangle

LOCAL_KINDS = ["LmLS", "LmLS*", "LcLS*", "LcLS"]
ALL_KINDS = ["GLS", "GLS*"] + LOCAL_KINDS


def block_on_plane(comm=MPI.COMM_WORLD, n=(8, 4)):
    """[0,1]x[0,0.5]; tags: 1 bottom (slave), 2 top (load), 3 left (u_x = 0)."""
    domain, tags = rectangle(comm, 0.0, 0.5, n, bottom=1, top=2, left=3)
    return fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,))), tags


def pressed_block(obstacle, kind: str, n=(6, 3), **options) -> ContactProblem:
    """The block of :func:`block_on_plane` against ``obstacle``, fixed sideways on
    its left, pushed down on its top (penalty 50), at full load."""
    V, tags = block_on_plane(n=n)
    problem = ContactProblem(V, tags, 1, obstacle=obstacle, E=1.0, nu=0.3, kind=kind,
                             penalty=50.0, fixed={3: {0: 0.0}}, tractions={2: [0.0, -0.01]},
                             **options)
    problem.set_load(1.0)
    return problem


def assert_same_hertz2d_figures_on_one_and_all_ranks(argv: list, make_problem) -> None:
    """Solve the Hertz 2D scene of ``argv`` on all ranks and on this rank alone
    (``make_problem(demo, V, tags, h)`` builds the problem, two load steps)."""
    demo = load_demo("hertz2d")
    args = demo.parse_args(argv)
    results = []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        ref = demo.hertz(args)
        domain, tags, h = demo.build_mesh(args, ref["a"], comm)
        problem = make_problem(demo, fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,))), tags, h)
        problem.solve(load_steps=2)
        results.append(demo.contact_results(problem, ref))
    for key in ("p0", "a", "l2_error", "contact_force"):
        assert results[0][key] == pytest.approx(results[1][key], rel=1e-8), key


def sheared_blocks(kind: str, scaling: str = "consistent", degree: int = 1,
                   comm=MPI.COMM_WORLD, active_set: str = "nodal",
                   push: float = 0.0, mesh_and_tags=None) -> ContactProblem:
    """The 2D patch-test blocks in the current configuration, the upper one
    tilted, slid and bent into the lower one (and lowered by ``push`` more),
    the lower one waved: part of the interface in contact, every pair moved by
    a fair part of an element from where it started. ``mesh_and_tags``: the
    mesh of another such problem (``(problem.mesh, problem.facet_tags)``), so
    that two problems share dofs."""
    demo = load_demo("patch_test")
    domain, tags = mesh_and_tags or demo.build_mesh(2, 0.09, 0.14, degree, comm)
    V = fem.functionspace(domain, ("Lagrange", degree, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, E=1.0,
                             nu=0.3, kind=kind, penalty=1e3, scaling=scaling,
                             basis_configuration="current", active_set=active_set,
                             fixed={demo.SYM_X: {0: 0.0}, demo.BOTTOM: {1: 0.0}},
                             tractions={demo.TOP: [0.0, -0.01]})
    problem.set_load(1.0)
    tdim = domain.topology.dim
    cells = np.arange(domain.topology.index_map(tdim).size_local, dtype=np.int32)
    midpoints = mesh.compute_midpoints(domain, tdim, cells)[:, 1]
    problem.u.interpolate(lambda x: np.vstack([0.01 * x[1] + 0.03 * x[0] ** 2,
                                               -0.002 * (x[0] - 0.4) + 0.004 * x[0] ** 2
                                               - push]),
                          cells0=cells[midpoints > 0])
    problem.u.interpolate(lambda x: np.vstack([0.004 * x[0] ** 2, 0.003 * np.sin(3 * x[0])]),
                          cells0=cells[midpoints < 0])
    problem.u.x.scatter_forward()
    return problem


def sheared_boxes(kind: str, scaling: str = "consistent",
                  active_set: str = "nodal") -> ContactProblem:
    """The 3D patch-test boxes (coarse) in the current configuration, bent,
    twisted and slid into each other."""
    demo = load_demo("patch_test")
    domain, tags = demo.build_mesh(3, 0.25, 0.35, 1, MPI.COMM_WORLD)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, E=1.0,
                             nu=0.3, kind=kind, penalty=1e3, scaling=scaling,
                             basis_configuration="current", active_set=active_set,
                             fixed={demo.SYM_X: {0: 0.0}, demo.SYM_Y: {1: 0.0},
                                    demo.BOTTOM: {2: 0.0}},
                             tractions={demo.TOP: [0.0, 0.0, -0.01]})
    problem.set_load(1.0)
    cells = np.arange(domain.topology.index_map(3).size_local, dtype=np.int32)
    height = mesh.compute_midpoints(domain, 3, cells)[:, 2]
    problem.u.interpolate(lambda x: np.vstack([0.01 * x[2] + 0.03 * x[0] ** 2,
                                               0.02 * x[0] * x[1],
                                               -0.002 * (x[0] - 0.4) + 0.004 * x[1] ** 2]),
                          cells0=cells[height > 0])
    problem.u.interpolate(lambda x: np.vstack([0.004 * x[0] ** 2, 0.003 * x[1] ** 2,
                                               0.003 * np.sin(3 * x[0]) * np.cos(2 * x[1])]),
                          cells0=cells[height < 0])
    problem.u.x.scatter_forward()
    return problem


#: the gap between the blocks of :func:`overhanging_blocks`
OVERHANG_GAP = 0.05


def overhanging_blocks(comm=MPI.COMM_WORLD):
    """A wide lower block [0,1]×[−½,0] and a narrower upper block
    [0.23,0.73]×[OVERHANG_GAP,½] above it: the master (upper bottom) ends inside slave
    facets (lower top). Tags: 1 slave, 2 master, 3 lower bottom, 4 upper top,
    5 upper left."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            lower = occ.addRectangle(0, -0.5, 0, 1, 0.5)
            upper = occ.addRectangle(0.23, OVERHANG_GAP, 0, 0.5, 0.5 - OVERHANG_GAP)
            occ.synchronize()
            groups = {k: [] for k in range(1, 6)}
            for body in (lower, upper):
                for _, c in gmsh.model.getBoundary([(2, body)], oriented=False):
                    x, y, _ = occ.getCenterOfMass(1, c)
                    if abs(y) < 1e-9:
                        groups[1].append(c)
                    elif abs(y - OVERHANG_GAP) < 1e-9:
                        groups[2].append(c)
                    elif abs(y + 0.5) < 1e-9:
                        groups[3].append(c)
                    elif abs(y - 0.5) < 1e-9:
                        groups[4].append(c)
                    elif abs(x - 0.23) < 1e-9:
                        groups[5].append(c)
            for tag, curves in groups.items():
                gmsh.model.addPhysicalGroup(1, curves, tag)
            gmsh.model.addPhysicalGroup(2, [lower], 11)
            gmsh.model.addPhysicalGroup(2, [upper], 12)
            gmsh.model.mesh.setSize(gmsh.model.getBoundary([(2, lower)], recursive=True), 0.09)
            gmsh.model.mesh.setSize(gmsh.model.getBoundary([(2, upper)], recursive=True), 0.13)
            gmsh.model.mesh.generate(2)
        domain, _, tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    return fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,))), tags
