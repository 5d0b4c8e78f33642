"""Two separately built meshes merged into one (dolfinx_mortar.meshes.merge_meshes) and
the contact problem between them (ContactProblem.from_two_meshes).

Under ``mpirun -n 2`` the inputs are distributed by DOLFINx, and the solver
results are compared with a serial computation on COMM_SELF copies.
"""
from __future__ import annotations

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar.meshes.merge_meshes import BODY_A, BODY_B, merge_meshes
from dolfinx_mortar import ContactProblem
from support.meshes import rectangle

ALL_KINDS = ["GLS", "GLS*", "LmLS", "LmLS*", "LcLS*", "LcLS"]
# patch test tags (as in demos/patch_test.py); LEFT is one symmetry plane through both
LOWER_TOP, UPPER_BOTTOM, TOP, BOTTOM, LEFT = 1, 2, 3, 4, 5
LOWER = dict(y0=-0.5, y1=0.0, bottom=BOTTOM, top=LOWER_TOP, left=LEFT)
UPPER = dict(y0=0.0, y1=0.5, bottom=UPPER_BOTTOM, top=TOP, left=LEFT)
PRESSURE = 0.01


def gmsh_blocks(comm, blocks, degree=1):
    """One gmsh model with the given structured (transfinite) rectangles, each
    meshed independently: the same block gives the same mesh in any model."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            gmsh.model.add("blocks")
            occ = gmsh.model.occ
            surfaces = [occ.addRectangle(0, b["y0"], 0, 1, b["y1"] - b["y0"]) for b in blocks]
            occ.synchronize()
            tags: dict = {}
            for b, s in zip(blocks, surfaces):
                for _, c in gmsh.model.getBoundary([(2, s)], oriented=False):
                    x, y, _ = occ.getCenterOfMass(1, c)
                    horizontal = abs(y - b["y0"]) < 1e-9 or abs(y - b["y1"]) < 1e-9
                    gmsh.model.mesh.setTransfiniteCurve(c, b["nx" if horizontal else "ny"] + 1)
                    side = ("bottom" if abs(y - b["y0"]) < 1e-9 else "top" if abs(y - b["y1"])
                            < 1e-9 else "left" if abs(x) < 1e-9 else None)
                    if side:
                        tags.setdefault(b[side], []).append(c)
                gmsh.model.mesh.setTransfiniteSurface(s)
            for tag, curves in tags.items():
                gmsh.model.addPhysicalGroup(1, curves, tag)
            for i, s in enumerate(surfaces):
                gmsh.model.addPhysicalGroup(2, [s], 11 + i)
            gmsh.model.mesh.generate(2)
            if degree == 2:
                gmsh.model.mesh.setOrder(2)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    return domain, facet_tags


def integral(domain, form) -> float:
    return domain.comm.allreduce(fem.assemble_scalar(fem.form(form)))


def facet_moments(domain, facet_tags, tags):
    """(length, ∫x, ∫y) of each tag: tells which facets carry it."""
    ds = ufl.Measure("ds", domain=domain, subdomain_data=facet_tags)
    x = ufl.SpatialCoordinate(domain)
    one = fem.Constant(domain, 1.0)
    return {t: np.array([integral(domain, f * ds(t)) for f in (one, x[0], x[1])]) for t in tags}


@pytest.mark.parametrize("cell_type", [mesh.CellType.triangle, mesh.CellType.quadrilateral])
def test_merged_mesh_has_both_bodies_and_their_tags(cell_type):
    comm = MPI.COMM_WORLD
    a, tags_a = rectangle(comm, n=(5, 3), cell_type=cell_type, **LOWER)
    b, tags_b = rectangle(comm, n=(7, 4), cell_type=cell_type, **UPPER)
    merged, facet_tags, cell_tags = merge_meshes(a, tags_a, b, tags_b, shared_tags=[LEFT])
    tdim = 2
    per_cell = 2 if cell_type == mesh.CellType.triangle else 1
    assert merged.topology.index_map(tdim).size_global == per_cell * (5 * 3 + 7 * 4)
    assert merged.geometry.index_map().size_global == 6 * 4 + 8 * 5
    assert merged.topology.cell_type == cell_type
    # each body's cells, by volume and count
    dx = ufl.Measure("dx", domain=merged, subdomain_data=cell_tags)
    one = fem.Constant(merged, 1.0)
    y = ufl.SpatialCoordinate(merged)[1]
    assert integral(merged, one * dx(BODY_A)) == pytest.approx(0.5, rel=1e-12)
    assert integral(merged, one * dx(BODY_B)) == pytest.approx(0.5, rel=1e-12)
    assert integral(merged, y * dx(BODY_A)) == pytest.approx(-0.125, rel=1e-12)
    assert integral(merged, y * dx(BODY_B)) == pytest.approx(0.125, rel=1e-12)
    owned = cell_tags.indices < merged.topology.index_map(tdim).size_local
    counts = comm.allreduce(np.bincount(cell_tags.values[owned], minlength=3))
    assert list(counts[1:]) == [per_cell * 15, per_cell * 28]
    # the facet tags: same facets (length and centroid) as in the inputs
    tags = [LOWER_TOP, UPPER_BOTTOM, TOP, BOTTOM, LEFT]
    merged_moments = facet_moments(merged, facet_tags, tags)
    ma = facet_moments(a, tags_a, tags)
    mb = facet_moments(b, tags_b, tags)
    for t in tags:
        np.testing.assert_allclose(merged_moments[t], ma[t] + mb[t], atol=1e-13)
    assert merged_moments[LEFT][0] == pytest.approx(1.0)


@pytest.mark.parametrize("cell_type", [mesh.CellType.tetrahedron, mesh.CellType.hexahedron])
def test_merged_boxes_3d(cell_type):
    comm = MPI.COMM_WORLD

    def box(z0, z1, n):
        domain = mesh.create_box(comm, [[0, 0, z0], [1, 1, z1]], n, cell_type=cell_type)
        facets = mesh.locate_entities_boundary(
            domain, 2, lambda x: np.isclose(x[2], z0) | np.isclose(x[2], z1))
        top = np.isclose(mesh.compute_midpoints(domain, 2, facets)[:, 2], z1)
        return domain, mesh.meshtags(domain, 2, facets, np.where(top, 1, 2).astype(np.int32))

    a, tags_a = box(-0.5, 0.0, [4, 3, 2])
    b, tags_b = box(0.0, 0.5, [3, 5, 2])
    merged, facet_tags, cell_tags = merge_meshes(a, tags_a, b, tags_b, tag_offset=10)
    assert (merged.topology.index_map(3).size_global
            == a.topology.index_map(3).size_global + b.topology.index_map(3).size_global)
    dx = ufl.Measure("dx", domain=merged, subdomain_data=cell_tags)
    ds = ufl.Measure("ds", domain=merged, subdomain_data=facet_tags)
    one, z = fem.Constant(merged, 1.0), ufl.SpatialCoordinate(merged)[2]
    for body in (BODY_A, BODY_B):
        assert integral(merged, one * dx(body)) == pytest.approx(0.5, rel=1e-12)
    for tag, height in ((1, 0.0), (2, -0.5), (11, 0.5), (12, 0.0)):
        assert integral(merged, one * ds(tag)) == pytest.approx(1.0, rel=1e-12)
        assert integral(merged, z * ds(tag)) == pytest.approx(height, abs=1e-12)


def test_quadratic_geometry_keeps_curved_facets():
    """P2 gmsh meshes (a disk and a block): lengths of curved tagged facets survive."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    comm = MPI.COMM_WORLD
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            gmsh.model.add("disk")
            disk = gmsh.model.occ.addDisk(0.5, 0.8, 0, 0.3, 0.3)
            gmsh.model.occ.synchronize()
            curves = [c for _, c in gmsh.model.getBoundary([(2, disk)], oriented=False)]
            gmsh.model.addPhysicalGroup(1, curves, 7)
            gmsh.model.addPhysicalGroup(2, [disk], 1)
            gmsh.option.setNumber("Mesh.MeshSizeMax", 0.1)
            gmsh.model.mesh.generate(2)
            gmsh.model.mesh.setOrder(2)
        disk, _, disk_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    block, block_tags = gmsh_blocks(comm, [dict(LOWER, nx=4, ny=2)], degree=2)
    merged, facet_tags, cell_tags = merge_meshes(block, block_tags, disk, disk_tags,
                                                 tag_offset=100)
    assert merged.ufl_domain().ufl_coordinate_element().degree == 2  # geometry.cmap: deprecated in 0.11
    assert (merged.geometry.index_map().size_global
            == block.geometry.index_map().size_global + disk.geometry.index_map().size_global)
    m = facet_moments(merged, facet_tags, [LOWER_TOP, BOTTOM, 107])
    np.testing.assert_allclose(m[107], facet_moments(disk, disk_tags, [7])[7], atol=1e-13)
    assert m[107][0] == pytest.approx(2 * np.pi * 0.3, rel=1e-3)
    m_block = facet_moments(block, block_tags, [LOWER_TOP, BOTTOM])
    for t in (LOWER_TOP, BOTTOM):
        np.testing.assert_allclose(m[t], m_block[t], atol=1e-13)
    dx = ufl.Measure("dx", domain=merged, subdomain_data=cell_tags)
    one = fem.Constant(merged, 1.0)
    assert integral(merged, one * dx(BODY_B)) == pytest.approx(
        integral(disk, fem.Constant(disk, 1.0) * ufl.dx), rel=1e-12)


def test_tag_values_clash_offset_and_shared():
    comm = MPI.COMM_WORLD
    a, tags_a = rectangle(comm, n=(3, 2), **LOWER)
    b, tags_b = rectangle(comm, n=(4, 2), **UPPER)
    with pytest.raises(ValueError, match=r"facet tag values \[5\] mark facets of both"):
        merge_meshes(a, tags_a, b, tags_b)
    merged, facet_tags, _ = merge_meshes(a, tags_a, b, tags_b, tag_offset=10)
    present = {int(v) for part in comm.allgather(np.unique(facet_tags.values)) for v in part}
    assert present == {LOWER_TOP, BOTTOM, LEFT, UPPER_BOTTOM + 10, TOP + 10, LEFT + 10}
    with pytest.raises(ValueError, match=r"\[1\] mark facets of both"):
        # b's 2 - 1 = 1 is a's slave tag: a clash after the offset
        merge_meshes(a, tags_a, b, tags_b, tag_offset=-1, shared_tags=[LEFT])


def test_bad_input_is_reported():
    comm = MPI.COMM_WORLD
    a, tags_a = rectangle(comm, n=(3, 2), **LOWER)
    q, tags_q = rectangle(comm, n=(4, 2), cell_type=mesh.CellType.quadrilateral, **UPPER)
    with pytest.raises(ValueError, match="same cell type"):
        merge_meshes(a, tags_a, q, tags_q, tag_offset=10)
    p2, tags_p2 = gmsh_blocks(comm, [dict(UPPER, nx=3, ny=2)], degree=2)
    with pytest.raises(ValueError, match="geometry degree 1 with geometry degree 2"):
        merge_meshes(a, tags_a, p2, tags_p2, tag_offset=10)
    b, tags_b = rectangle(comm, n=(4, 2), **UPPER)
    with pytest.raises(ValueError, match="facet_tags_b must be facet tags"):
        merge_meshes(a, tags_a, b, tags_a, tag_offset=10)  # a's tags given for b
    cells = mesh.meshtags(b, 2, np.arange(3, dtype=np.int32), 1)
    with pytest.raises(ValueError, match="facet_tags_b must be facet tags"):
        merge_meshes(a, tags_a, b, cells, tag_offset=10)


def two_mesh_problem(comm, kind, separate=True, shear=0.0):
    """The 2D patch test on non-matching blocks (lower finer: slave); with
    ``separate``, two gmsh models merged, else one model with both blocks."""
    lower, upper = dict(LOWER, nx=7, ny=3), dict(UPPER, nx=5, ny=3)
    common = dict(E=1.0, nu=0.3, kind=kind, penalty=1e3 * 7, fixed={LEFT: {0: 0.0},
                  BOTTOM: {1: 0.0}}, tractions={TOP: [shear * PRESSURE, -PRESSURE]})
    if separate:
        a, tags_a = gmsh_blocks(comm, [lower])
        b, tags_b = gmsh_blocks(comm, [upper])
        return ContactProblem.from_two_meshes(a, tags_a, LOWER_TOP, b, tags_b, UPPER_BOTTOM,
                                              shared_tags=[LEFT], **common)
    domain, tags = gmsh_blocks(comm, [lower, upper])
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    return ContactProblem(V, tags, LOWER_TOP, master_tag=UPPER_BOTTOM, **common)


def slave_pressures(problem):
    """(x, p) of the owned slave nodes of all ranks, sorted by x."""
    surface = problem.surface_pressure(gather=True)
    values = np.column_stack([surface.x[:, 0], surface.p])
    return values[np.argsort(values[:, 0])]


@pytest.mark.parametrize("kind", ALL_KINDS)
def test_patch_test_on_two_meshes_matches_one_mesh(kind):
    results = []
    for separate in (True, False):
        problem = two_mesh_problem(MPI.COMM_WORLD, kind, separate)
        result = problem.solve(load_steps=1)
        results.append((slave_pressures(problem), result.newton_iterations))
    (two, it_two), (one, it_one) = results
    assert len(two) == 8
    assert np.max(np.abs(two[:, 1] / PRESSURE - 1)) <= 1e-8
    np.testing.assert_allclose(two, one, rtol=0, atol=1e-12)
    # the blocks touch with zero gap: whether a node starts active is decided by
    # roundoff, so the Newton path (not the result) may differ between partitions
    assert max(it_two, it_one) <= 4


@pytest.mark.parametrize("kind", ["GLS", "LcLS*"])
def test_two_meshes_same_numbers_on_one_and_all_ranks(kind):
    """A sheared load (uneven pressure): merged on all ranks = one mesh = serial."""
    runs = [two_mesh_problem(MPI.COMM_WORLD, kind, True, shear=0.2),
            two_mesh_problem(MPI.COMM_SELF, kind, True, shear=0.2),
            two_mesh_problem(MPI.COMM_WORLD, kind, False, shear=0.2)]
    results = []
    for problem in runs:
        problem.solve(load_steps=1)
        results.append((slave_pressures(problem), problem.normal_force()))
    spread = np.ptp(results[0][0][:, 1]) / PRESSURE
    assert spread > 0.05  # the test sees an uneven pressure
    for p, force in results[1:]:
        np.testing.assert_allclose(p, results[0][0], rtol=0, atol=1e-10 * PRESSURE)
        assert force == pytest.approx(results[0][1], rel=1e-10)
    assert results[0][1] == pytest.approx(PRESSURE, rel=1e-8)  # Σ W_A p_A = p·1


def test_from_two_meshes_create_rectangle_patch_test():
    """Two dolfinx.mesh.create_rectangle meshes (distributed by DOLFINx)."""
    comm = MPI.COMM_WORLD
    a, tags_a = rectangle(comm, n=(9, 4), **LOWER)
    b, tags_b = rectangle(comm, n=(6, 3), **UPPER)
    problem = ContactProblem.from_two_meshes(
        a, tags_a, LOWER_TOP, b, tags_b, UPPER_BOTTOM, tag_offset=10, E=1.0, nu=0.3,
        kind="LcLS*", penalty=1e3 * 9, fixed={LEFT: {0: 0.0}, LEFT + 10: {0: 0.0},
                                             BOTTOM: {1: 0.0}},
        tractions={TOP + 10: [0.0, -PRESSURE]})
    problem.solve(load_steps=1)
    p = slave_pressures(problem)
    assert len(p) == 10
    assert np.max(np.abs(p[:, 1] / PRESSURE - 1)) <= 1e-8
    assert problem.cell_tags is not None and problem.facet_tags is not None
