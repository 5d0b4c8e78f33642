"""Partitions a graph partitioner rarely makes on few ranks but often on many.

On 8 ranks the 3D patch test with GLS diverged: a rank owned slave nodes
whose slave facets all lay on other ranks (it held only bulk cells around
them), and the code took a rank's slave nodes to be the owned nodes of its own
slave facets. Those nodes were left out of GLS's Newton system, of the contact
force and of the friction blocks. Here the partition is made so on 2 ranks:
every cell with a facet on the slave surface goes to the last rank, every
other cell to rank 0 (ranks in between hold nothing), so the slave nodes that
rank 0 owns have no slave facet there.
"""
from __future__ import annotations

import basix.ufl
import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar import ContactProblem, RigidSphere
from dolfinx_mortar.dolfinx_compat import (cpp_adjacency_list, create_cell_partitioner,
                                           create_mesh)

SLAVE, TOP, LEFT = 1, 2, 3


def block_with_slave_facets_apart(comm: MPI.Comm, n=(8, 4)):
    """[0,1]×[0,0.5] in triangles, the cells with a facet on y = 0 on the last
    rank and all others on rank 0; tags: SLAVE (y = 0), TOP, LEFT."""
    nx, ny = n
    if comm.rank == 0:
        xs, ys = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 0.5, ny + 1))
        x = np.column_stack([xs.ravel(), ys.ravel()])
        corner = (np.arange(ny)[:, None] * (nx + 1) + np.arange(nx)).ravel()
        lower = np.column_stack([corner, corner + 1, corner + nx + 2])   # has the bottom edge
        upper = np.column_stack([corner, corner + nx + 2, corner + nx + 1])
        cells = np.vstack([lower, upper]).astype(np.int64)
        on_slave = np.r_[corner < nx, np.zeros(len(corner), dtype=bool)]
    else:
        x, cells, on_slave = np.zeros((0, 2)), np.zeros((0, 3), np.int64), np.zeros(0, bool)

    def partition(_, nparts, graph, ghosting):
        owner = np.where(on_slave, 0, nparts - 1).astype(np.int32)
        return cpp_adjacency_list(owner, np.arange(len(owner) + 1, dtype=np.int32))

    element = basix.ufl.element("Lagrange", "triangle", 1, shape=(2,))
    partitioner = create_cell_partitioner(partition) if comm.size > 1 else None
    domain = create_mesh(comm, cells, x, element, partitioner)
    marks = [(SLAVE, lambda p: np.isclose(p[1], 0.0)), (TOP, lambda p: np.isclose(p[1], 0.5)),
             (LEFT, lambda p: np.isclose(p[0], 0.0))]
    facets = [mesh.locate_entities_boundary(domain, 1, where) for _, where in marks]
    values = np.concatenate([np.full(len(f), tag, np.int32) for (tag, _), f in zip(marks, facets)])
    facets = np.concatenate(facets)
    order = np.argsort(facets)
    tags = mesh.meshtags(domain, 1, facets[order].astype(np.int32), values[order])
    return fem.functionspace(domain, ("Lagrange", 1, (2,))), tags


@pytest.mark.parametrize("kind", ["GLS", "LmLS*"])
def test_slave_nodes_owned_where_none_of_their_facets_are(kind):
    results = []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        V, tags = block_with_slave_facets_apart(comm)
        problem = ContactProblem(V, tags, SLAVE, obstacle=RigidSphere([0.5, -3.0], 3.0), E=1.0,
                                 nu=0.3, kind=kind, penalty=100.0, fixed={LEFT: {0: 0.0}},
                                 tractions={TOP: [0.0, -0.01]})
        slave = problem.slave
        owned = slave.layout.num_owned
        held = np.unique(slave.cells)
        apart = np.setdiff1d(slave.owned_nodes, held[held < owned])
        problem.solve(load_steps=2)
        results.append((comm.allreduce(len(apart)), problem.surface_pressure(gather=True),
                        problem.contact_force()))
    (apart, spread, force), (_, alone, force_alone) = results
    if MPI.COMM_WORLD.size > 1:
        assert apart > 0   # the partition this test is about
    assert np.allclose(spread.x, alone.x, rtol=0, atol=1e-14)
    assert np.allclose(spread.p, alone.p, rtol=1e-8, atol=1e-10 * np.max(alone.p))
    assert np.allclose(force, force_alone, rtol=1e-8, atol=1e-12)
    assert force[1] == pytest.approx(0.01, rel=1e-6)   # the load on the top
