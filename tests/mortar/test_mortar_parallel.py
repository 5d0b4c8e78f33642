"""Mortar operators of two DOLFINx meshes in contact, on 1 and 2 ranks.

Run under ``mpirun -n 2``: the distributed D and M are compared entry by entry
(matched by node coordinates) with a serial computation on COMM_SELF copies.
"""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI
from scipy.spatial import cKDTree

from dolfinx_mortar.surfaces.facet_surface import facet_surface, nodal_displacement
from dolfinx_mortar.mortar.coupling import MortarCoupling
from support.meshes import MASTER, SLAVE, two_blocks



def entries(mat, row_coords, col_coords):
    """All (row xyz, col xyz, value) of a distributed matrix, on every rank."""
    lo, _ = mat.getOwnershipRange()
    indptr, indices, data = mat.getValuesCSR()
    rows = np.repeat(np.arange(len(indptr) - 1) + lo, np.diff(indptr))
    # roundoff-level entries (e.g. the dual D's off-diagonal) exist or are exactly
    # zero depending on summation order: compare only the significant ones
    scale = mat.comm.tompi4py().allreduce(np.max(np.abs(data), initial=0.0), op=MPI.MAX)
    keep = np.abs(data) > 1e-13 * scale
    local = np.hstack([row_coords[rows[keep]], col_coords[indices[keep]], data[keep, None]])
    return np.vstack(mat.comm.tompi4py().allgather(local))


def global_coordinates(V):
    """Coordinates of every node by global index, on every rank."""
    im = V.dofmap.index_map
    n = im.size_local
    x = V.tabulate_dof_coordinates()[:n]
    ids = np.arange(im.local_range[0], im.local_range[1])
    all_x = np.vstack(V.mesh.comm.allgather(x))
    all_ids = np.concatenate(V.mesh.comm.allgather(ids))
    out = np.empty_like(all_x)
    out[all_ids] = all_x
    return out


def operators(comm, dim, degree, kind):
    (Vs, ts), (Vm, tm) = two_blocks(comm, dim, degree)
    slave = facet_surface(Vs, ts, SLAVE)
    master = facet_surface(Vm, tm, MASTER)
    u = fem.Function(Vm)  # push the master down by 0.01 + 0.02 x: a tilted contact
    u.interpolate(lambda x: np.vstack([np.zeros_like(x[0])] * (dim - 1)
                                      + [-0.01 - 0.02 * x[0]]))
    c = MortarCoupling(slave, master, master_displacement=nodal_displacement(master, u))
    op = c.operators(kind)
    xs, xm = global_coordinates(Vs), global_coordinates(Vm)
    gap = op.nodal_gap()[: slave.layout.num_owned]
    gaps = np.vstack(comm.allgather(np.hstack([
        Vs.tabulate_dof_coordinates()[: slave.layout.num_owned], gap[:, None]])))
    return (entries(op.D, xs, xs), entries(op.M, xs, xm), gaps,
            c.total_covered_area, comm.allgather(len(slave.cells)))


def same(a, b, tol):
    """Entry sets equal up to tol (matched by coordinates)."""
    assert a.shape == b.shape, (a.shape, b.shape)
    keys = a.shape[1] - 1
    tree = cKDTree(b[:, :keys])
    distance, index = tree.query(a[:, :keys])
    assert np.max(distance) < 1e-10
    assert len(np.unique(index)) == len(index)
    scale = np.max(np.abs(b[:, -1]))
    assert np.max(np.abs(a[:, -1] - b[index, -1])) <= tol * scale


@pytest.mark.parametrize("dim, degree", [(2, 1), (2, 2), (3, 1)])
@pytest.mark.parametrize("kind", ["LcLS*", "GLS", "LmLS"])
def test_operators_agree_on_one_and_all_ranks(dim, degree, kind):
    D, M, gap, area, counts = operators(MPI.COMM_WORLD, dim, degree, kind)
    D0, M0, gap0, area0, _ = operators(MPI.COMM_SELF, dim, degree, kind)
    # two ranks or more own slave facets: the parallel path is used (on 8 ranks
    # some own none, and the operators must not depend on that either)
    assert sum(c > 0 for c in counts) >= min(2, len(counts))
    expected = 0.7 if dim == 2 else 0.7 * 0.8
    assert area == pytest.approx(expected, rel=1e-12) and area0 == pytest.approx(expected, rel=1e-12)
    same(D, D0, 1e-12)
    same(M, M0, 1e-12)
    same(gap, gap0, 1e-10)
    # the master moved down 0.01 + 0.02 x onto the slave at z = 0: penetrating,
    # which the positive LmLS functions show at every covered node
    covered = gap0[:, -1] != 0
    if kind == "LmLS":
        assert np.all(gap0[covered, -1] > 0)


def test_wrong_displacement_space_is_reported():
    (Vs, ts), (Vm, tm) = two_blocks(MPI.COMM_WORLD, 2, 1)
    slave = facet_surface(Vs, ts, SLAVE)
    with pytest.raises(ValueError, match="numbers its nodes differently"):
        nodal_displacement(slave, fem.Function(Vm))


def one_mesh_two_bodies(comm):
    """Two rectangles in one gmsh model, meshed independently (non-matching):
    lower [0,1]x[-0.5,0] (slave on top, h=0.1), upper [0.2,1.3]x[0,0.4] (master at
    the bottom, h=0.17)."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            lower = occ.addRectangle(0, -0.5, 0, 1, 0.5)
            upper = occ.addRectangle(0.2, 0, 0, 1.1, 0.4)
            occ.synchronize()
            gmsh.model.addPhysicalGroup(2, [lower], 1)
            gmsh.model.addPhysicalGroup(2, [upper], 2)
            for surface, tag, y in ((lower, SLAVE, 0.0), (upper, MASTER, 0.0)):
                edges = [e[1] for e in gmsh.model.getBoundary([(2, surface)], oriented=False)
                         if abs(gmsh.model.occ.getCenterOfMass(1, e[1])[1] - y) < 1e-9]
                gmsh.model.addPhysicalGroup(1, edges, tag)
            for surface, h in ((lower, 0.1), (upper, 0.17)):
                points = gmsh.model.getBoundary([(2, surface)], recursive=True)
                gmsh.model.mesh.setSize(points, h)
            gmsh.model.mesh.generate(2)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    return domain, facet_tags


def test_one_mesh_with_two_bodies():
    results = []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        domain, tags = one_mesh_two_bodies(comm)
        V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
        slave, master = facet_surface(V, tags, SLAVE), facet_surface(V, tags, MASTER)
        c = MortarCoupling(slave, master)
        assert c.total_covered_area == pytest.approx(0.8, rel=1e-12)
        op = c.operators("LcLS*")
        x = global_coordinates(V)
        # a linear field on the master is reproduced on the covered slave nodes
        um = op.M.createVecRight()
        lo, hi = um.getOwnershipRange()
        um.array[:] = 1 + 2 * x[lo:hi, 0]
        us = op.transfer(um)
        n = slave.layout.num_owned
        xs = V.tabulate_dof_coordinates()[:n]
        on_slave = np.zeros(n, dtype=bool)
        on_slave[slave.owned_nodes] = True
        # nodes whose whole support is covered (the master starts at x = 0.2, h = 0.1)
        inside = on_slave & (xs[:, 0] > 0.2 + 0.1 + 1e-12)
        assert np.max(np.abs(us.array[inside] - (1 + 2 * xs[inside, 0])), initial=0) < 1e-12
        results.append((entries(op.M, x, x), c.slave.layout.comm.allgather(len(slave.cells))))
    (M, counts), (M0, _) = results
    same(M, M0, 1e-12)
