"""Any number of bodies: meshes of N bodies merged in one call
(:func:`~dolfinx_mortar.meshes.merge_meshes.merge_bodies`), and all their contact surfaces in
one self-contact term whose pairs between the bodies are found by the search."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

import ufl

from dolfinx_mortar import (ContactTerm, LoadPathSolver, NonlinearContactProblem,
                            RigidPlane)
from dolfinx_mortar.meshes.merge_meshes import merge_bodies
from dolfinx_mortar.small_strain.elastic import linear_elastic_residual
from support.meshes import (BLOCK_BOTTOM, BLOCK_LEFT, BLOCK_OFFSET, BLOCK_TOP, rectangle,
                           stacked_rectangles)

#: each block's tags before the offset: bottom, top, left
BOTTOM, TOP, LEFT = BLOCK_BOTTOM, BLOCK_TOP, BLOCK_LEFT
OFFSET = BLOCK_OFFSET


def three_blocks(comm, across: int = 8):
    """Three blocks [0,1] x [k/4, (k+1)/4] on 8, 9 and 10 cells across (non-matching):
    the default search radius, the largest facet (1/8), is below a block's thickness."""
    return stacked_rectangles(comm, [across + k for k in range(3)])


def test_three_meshes_merge_in_one_call():
    comm = MPI.COMM_WORLD
    domain, facet_tags, cell_tags = three_blocks(comm)
    cells = [comm.allreduce(int(np.sum(cell_tags.values == k + 1))) for k in range(3)]
    assert cells == [2 * 8 * 2, 2 * 9 * 2, 2 * 10 * 2]         # triangles of each block
    present = {int(v) for part in comm.allgather(np.unique(facet_tags.values)) for v in part}
    assert present == {LEFT} | {t + OFFSET * k for k in range(3) for t in (BOTTOM, TOP)}


def test_ranks_that_hold_no_tagged_facet_merge_too():
    """One tagged facet in all: on several ranks the others hold none (they got an
    array without rows' width, which the merge once failed to reshape)."""
    comm = MPI.COMM_WORLD
    meshes = []
    for k in range(2):
        domain = mesh.create_rectangle(comm, [[0, k], [1, k + 1]], [6, 6])
        corner = mesh.locate_entities_boundary(
            domain, 1, lambda x: np.isclose(x[1], 0) & (x[0] < 0.2)) if k == 0 else []
        meshes.append((domain, mesh.meshtags(domain, 1, np.asarray(corner, dtype=np.int32),
                                             np.full(len(corner), BOTTOM, dtype=np.int32))))
    domain, facet_tags, _ = merge_bodies([m for m, _ in meshes], [t for _, t in meshes])
    owned = facet_tags.indices < domain.topology.index_map(1).size_local
    assert comm.allreduce(int(np.sum(facet_tags.values[owned] == BOTTOM))) == 1


def test_a_tag_that_marks_two_of_three_bodies_is_named():
    comm = MPI.COMM_WORLD
    meshes = [rectangle(comm, k / 4, (k + 1) / 4, (4, 2), bottom=BOTTOM, top=TOP, left=LEFT)
              for k in range(3)]
    with pytest.raises(ValueError, match=r"\[1, 2\] mark facets of both meshes .*"
                                         r"meshes\[0\] and meshes\[2\]"):
        merge_bodies([m for m, _ in meshes], [t for _, t in meshes],
                     tag_offsets=[0, 10, 0], shared_tags=[LEFT])


def test_a_wall_thinner_than_the_search_radius_is_named():
    """Blocks two cells and 0.25 thick with facets 0.25 long: the default radius
    reaches through a block to its own other face, which reads as an overlap;
    the error says so and what to pass."""
    domain, facet_tags, _ = three_blocks(MPI.COMM_WORLD, across=4)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    faces = [TOP, BOTTOM + OFFSET, TOP + OFFSET, BOTTOM + 2 * OFFSET]
    with pytest.raises(ValueError, match="thinner than the search radius"):
        ContactTerm(fem.Function(V), facet_tags, faces, self_contact=True, penalty=1e3)
    ContactTerm(fem.Function(V), facet_tags, faces, self_contact=True, penalty=1e3,
                search_radius=0.2)


def test_a_stack_of_three_merged_bodies_under_one_term_carries_the_pressure():
    """The three blocks on a rigid plane, pressed by q on the top: the four faces
    of the two interfaces in one self-contact term carry q at every node to
    round-off, and the ground the whole load (a patch test); each face's own
    resultant (``contact_force(tag=...)``) is q."""
    comm, q = MPI.COMM_WORLD, 0.01
    domain, facet_tags, _ = three_blocks(comm)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    F = linear_elastic_residual(u, 1.0, 0.3) + q * v[1] * ufl.Measure(
        "ds", domain=domain, subdomain_data=facet_tags)(TOP + 2 * OFFSET)
    left = fem.locate_dofs_topological(V.sub(0), 1, facet_tags.find(LEFT))
    penalty = 1e3 * 16
    ground = ContactTerm(u, facet_tags, BOTTOM, obstacle=RigidPlane([0.0, 0.0], [0.0, 1.0]),
                         penalty=penalty)
    faces = [TOP, BOTTOM + OFFSET, TOP + OFFSET, BOTTOM + 2 * OFFSET]
    interfaces = ContactTerm(u, facet_tags, faces, self_contact=True, penalty=penalty)
    problem = NonlinearContactProblem(F, u, [ground, interfaces],
                                      [fem.dirichletbc(0.0, left, V.sub(0))])
    LoadPathSolver(problem).solve(lambda t: None, load_steps=1)
    pressure = interfaces.results.surface_pressure(gather=True)
    on_faces = pressure.x[:, 1] > 0
    # the interface faces' nodes: 9 + 10 (top of the lowest, bottom of the middle), 10 + 11
    assert on_faces.sum() == 9 + 10 + 10 + 11
    assert np.allclose(pressure.p[on_faces], q, rtol=1e-9, atol=0)
    assert ground.results.contact_force()[1] == pytest.approx(q, rel=1e-12)
    # each body's face: pushed up by q from below, down by q from above
    for tag, sign in zip(faces, (-1, 1, -1, 1)):
        fx, fy = interfaces.results.contact_force(tag=tag)
        assert fy == pytest.approx(sign * q, rel=1e-12) and abs(fx) < 1e-12 * q
    with pytest.raises(ValueError, match=f"tag {LEFT} is not one of the term's slave facet tags"):
        interfaces.results.contact_force(tag=LEFT)
