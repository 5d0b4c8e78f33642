"""The contact-balanced cell partitioner, on 1 and 2 ranks."""
from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx
from dolfinx import fem
import ufl

from dolfinx_mortar.meshes.contact_partitioner import cells_near_contact, coordinate_bisection
from dolfinx_mortar.io.gmsh_io import grade_towards_point, model_to_mesh, read_gmsh

LOWER, UPPER, MASTER, SLAVE, FAR = 1, 2, 3, 4, 5


def stacked_blocks(comm: MPI.Comm, balance, size: float = 0.12, path=None):
    """Two unit-square blocks, [0,1]²×[−1,0] and [0,1]²×[0,1], meshed
    separately, graded towards the corner (0, 0, 0) of their touching faces
    (MASTER: the lower block's top, SLAVE: the upper block's bottom, FAR:
    the upper block's top)."""
    import gmsh
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            lower = occ.addBox(0, 0, -1, 1, 1, 1)
            upper = occ.addBox(0, 0, 0, 1, 1, 1)
            occ.synchronize()
            for tag, volume, z, name in ((MASTER, lower, 0.0, "master"),
                                         (SLAVE, upper, 0.0, "slave"), (FAR, upper, 1.0, "far")):
                faces = [s for _, s in gmsh.model.getBoundary([(3, volume)], oriented=False)
                         if abs(occ.getCenterOfMass(2, s)[2] - z) < 1e-9]
                gmsh.model.addPhysicalGroup(2, faces, tag)
                gmsh.model.setPhysicalName(2, tag, name)
            gmsh.model.addPhysicalGroup(3, [lower], LOWER)
            gmsh.model.addPhysicalGroup(3, [upper], UPPER)
            grade_towards_point((0, 0, 0), size / 4, size * 2, 0.2, 1.0)
            gmsh.model.mesh.generate(3)
            if path is not None:
                gmsh.write(str(path))
        return model_to_mesh(gmsh.model, comm, 0, gdim=3, balance_facets=balance)
    finally:
        gmsh.finalize()


def owned_facets(mesh, facet_tags, tag: int) -> int:
    owned = mesh.topology.index_map(2).size_local
    facets = facet_tags.find(tag)
    return int(np.count_nonzero(facets < owned))


def test_coordinate_bisection_gives_equal_compact_groups():
    rng = np.random.default_rng(0)
    points = rng.uniform(size=(1001, 3)) * [4.0, 1.0, 0.01]
    for nparts in (2, 3, 4):
        groups = coordinate_bisection(points, nparts)
        counts = np.bincount(groups, minlength=nparts)
        assert counts.max() - counts.min() <= 1, counts
    # two groups: one cut across x, the axis of the largest spread
    groups = coordinate_bisection(points, 2)
    assert points[groups == 0, 0].max() <= points[groups == 1, 0].min()


def test_the_cut_axis_is_not_chosen_by_a_few_outliers():
    """A thin disk in z = 0 and a few points far up (the large facets of a
    graded mesh far from the contact): the cut must split the disk, across x
    or y, not separate the disk from the far points across z."""
    rng = np.random.default_rng(1)
    disk = np.column_stack([rng.uniform(-1, 1, size=(2, 500)).T, np.zeros(500)])
    far = np.column_stack([rng.uniform(-1, 1, size=(2, 40)).T, rng.uniform(50, 100, size=40)])
    groups = coordinate_bisection(np.vstack([disk, far]), 2)
    share = np.bincount(groups[:500], minlength=2)
    assert share.min() >= 200, share


def test_only_cells_close_to_the_other_surface_count():
    """Two touching squares' faces count; the upper block's top (a contact
    surface too, but a body height from the other) does not."""
    x = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0],      # upper: face z = 0
                  [0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, -1.0],     # lower: face z = 0
                  [0, 0, 5], [1, 0, 5], [0, 1, 5], [0, 0, 4.0]])     # far: face z = 5
    cells = np.arange(12).reshape(3, 4)
    surfaces = [np.array([0, 1, 2]), np.array([4, 5, 6, 8, 9, 10])]
    assert list(cells_near_contact(cells, x, surfaces, 3)) == [True, True, False]
    # one surface (a rigid obstacle is not in the mesh): all of its cells
    assert list(cells_near_contact(cells, x, surfaces[1:], 3)) == [False, True, True]


def test_each_rank_gets_a_share_of_the_contact_facets_and_a_complete_ghost_layer():
    comm = MPI.COMM_WORLD
    mesh, cell_tags, facet_tags = stacked_blocks(comm, [SLAVE, MASTER])
    for tag in (SLAVE, MASTER):
        counts = comm.allgather(owned_facets(mesh, facet_tags, tag))
        assert min(counts) >= 0.8 * sum(counts) / comm.size, (tag, counts)
    # the graph partitioner alone leaves a rank with (almost) none of them
    if comm.size == 2:
        graph_mesh, _, graph_tags = stacked_blocks(comm, None)
        counts = comm.allgather(owned_facets(graph_mesh, graph_tags, SLAVE))
        assert min(counts) < 0.3 * sum(counts) / comm.size, counts
    # shared_facet ghosting: every owned interior facet has both cells here
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim - 1, tdim)
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    owned = mesh.topology.index_map(tdim - 1).size_local
    one_cell = np.flatnonzero(np.diff(f2c.offsets)[:owned] == 1)
    exterior = dolfinx.mesh.exterior_facet_indices(mesh.topology)
    assert np.array_equal(np.sort(one_cell), np.sort(exterior[exterior < owned]))
    # the whole mesh is there: volumes and both bodies
    volume = fem.assemble_scalar(fem.form(fem.Constant(mesh, 1.0) * ufl.dx))
    assert comm.allreduce(volume) == pytest.approx(2.0, rel=1e-12)
    for body in (LOWER, UPPER):
        mine = cell_tags.find(body)
        mine = mine[mine < mesh.topology.index_map(tdim).size_local]
        assert comm.allreduce(len(mine)) > 0


def test_balance_tags_must_be_facet_groups():
    with pytest.raises(ValueError, match=r"balance_facets \[9\]"):
        stacked_blocks(MPI.COMM_WORLD, [SLAVE, 9], size=0.5)
    with pytest.raises(ValueError, match=r"balance_facets \[1\]"):  # a volume group
        stacked_blocks(MPI.COMM_WORLD, [LOWER], size=0.5)


def test_a_gmsh_file_is_balanced_by_group_names(tmp_path_factory):
    comm = MPI.COMM_WORLD
    path = comm.bcast(str(tmp_path_factory.mktemp("msh") / "blocks.msh")
                      if comm.rank == 0 else None)
    if comm.rank == 0:
        stacked_blocks(MPI.COMM_SELF, None, path=path)
    comm.barrier()
    mesh, _, facet_tags, names = read_gmsh(path, comm, balance_facets=["slave", "master"])
    assert names[2]["slave"] == SLAVE
    counts = comm.allgather(owned_facets(mesh, facet_tags, SLAVE))
    assert min(counts) >= 0.8 * sum(counts) / comm.size, counts
    with pytest.raises(ValueError, match=r"balance_facets \['top'\]"):
        read_gmsh(path, comm, balance_facets=["slave", "top"])
