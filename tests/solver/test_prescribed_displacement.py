"""Loads by non-zero prescribed displacements on faces that the partition crosses.

Every scene type (rigid plane, rigid disk, elastic master in one mesh, two
meshes) is pressed by a prescribed displacement of a whole face, solved on all
ranks and on a COMM_SELF copy in the same run, and the pressures, the contact
force and the reaction of the prescribed face must agree, and balance. Under
``mpirun -n 2`` the partition crosses the loaded face: the residual once used
stale ghost values of the prescribed dofs there (0.2% … 8× wrong forces, with
Newton reporting convergence).
"""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar.contact.obstacles import RigidPlane, RigidSphere
from dolfinx_mortar import ContactProblem
from support.meshes import rectangle

ALL_KINDS = ["GLS", "GLS*", "LmLS", "LmLS*", "LcLS*", "LcLS"]
BOTTOM, TOP, LEFT = 1, 2, 3
E, NU = 1.0, 0.3
E_PLANE = E / (1 - NU ** 2)  # plane strain, free sideways: σ_yy = E/(1-ν²) ε_yy
PUSH = 0.01


def reaction(problem: ContactProblem, tag: int, component: int) -> float:
    """The support's force on facet ``tag`` along ``component`` (all ranks)."""
    return float(problem.reaction_force(tag)[component])


def slave_pressures(problem: ContactProblem) -> np.ndarray:
    """(x, p) of the owned slave nodes on all ranks, sorted by x."""
    surface = problem.surface_pressure(gather=True)
    values = np.column_stack([surface.x[:, 0], surface.p])
    return values[np.argsort(values[:, 0], kind="stable")]


def block_pressed_on_plane(comm, kind: str, penalty: float) -> ContactProblem:
    """[0,1]×[0,0.5] on the plane y = 0, top face moved down by PUSH."""
    domain, tags = rectangle(comm, 0.0, 0.5, (8, 4), bottom=BOTTOM, top=TOP, left=LEFT)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, BOTTOM, obstacle=RigidPlane([0, 0], [0, 1]), E=E, nu=NU,
                             kind=kind, penalty=penalty,
                             fixed={LEFT: {0: 0.0}, TOP: {1: -PUSH}})
    problem.facet_tags = tags
    return problem


def disk_pressed_into_block(comm, kind: str) -> ContactProblem:
    """A rigid disk resting on [0,1]×[-0.5,0]; the bottom face moved up by PUSH."""
    domain, tags = rectangle(comm, -0.5, 0.0, (12, 6), bottom=BOTTOM, top=TOP, left=LEFT)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, TOP, obstacle=RigidSphere([0.0, 1.0], 1.0), E=E, nu=NU,
                             kind=kind, penalty=1e3, fixed={LEFT: {0: 0.0}, BOTTOM: {1: PUSH}})
    problem.facet_tags = tags
    return problem


def two_blocks_pressed(comm, kind: str) -> ContactProblem:
    """The 2D patch test on two separately meshed, non-matching blocks (merged into
    one mesh), the upper block's top face moved down by PUSH."""
    lower, ltags = rectangle(comm, -0.5, 0.0, (7, 3), bottom=BOTTOM, top=TOP, left=LEFT)
    upper, utags = rectangle(comm, 0.0, 0.5, (5, 3), bottom=11, top=12, left=LEFT)
    return ContactProblem.from_two_meshes(
        lower, ltags, TOP, upper, utags, 11, shared_tags=[LEFT], E=E, nu=NU, kind=kind,
        penalty=1e3 * 7, fixed={LEFT: {0: 0.0}, BOTTOM: {1: 0.0}, 12: {1: -PUSH}})


def figures(problem: ContactProblem, tag: int) -> tuple[np.ndarray, float, float]:
    problem.solve(load_steps=2)
    return slave_pressures(problem), problem.normal_force(), reaction(problem, tag, 1)


@pytest.mark.parametrize("kind", ALL_KINDS)
def test_block_pressed_by_displacement_on_a_plane(kind):
    penalty = 1e4
    runs = [figures(block_pressed_on_plane(c, kind, penalty), TOP)
            for c in (MPI.COMM_WORLD, MPI.COMM_SELF)]
    (p, force, top), (p_self, force_self, top_self) = runs
    # uniform strain, uniform penetration d = p/ε: p = E' (PUSH − p/ε) / 0.5
    exact = E_PLANE * PUSH / 0.5 / (1 + E_PLANE / (0.5 * penalty))
    assert np.max(np.abs(p[:, 1] / exact - 1)) < 1e-9
    np.testing.assert_allclose(p, p_self, rtol=0, atol=1e-12 * exact)
    assert force == pytest.approx(exact, rel=1e-9)          # Σ W_A p_A over width 1
    assert force_self == pytest.approx(force, rel=1e-12)
    assert -top == pytest.approx(force, rel=1e-9)           # the top face holds it
    assert top_self == pytest.approx(top, rel=1e-12)


@pytest.mark.parametrize("kind", ["LmLS*", "LcLS*", "GLS"])
def test_disk_pressed_by_the_block_bottom_displacement(kind):
    (p, force, bottom), (p_self, force_self, bottom_self) = [
        figures(disk_pressed_into_block(c, kind), BOTTOM) for c in (MPI.COMM_WORLD, MPI.COMM_SELF)]
    assert force > 1e-4  # real contact
    np.testing.assert_allclose(p, p_self, rtol=0, atol=1e-10 * np.max(p_self[:, 1]))
    assert bottom == pytest.approx(bottom_self, rel=1e-9)
    assert force == pytest.approx(force_self, rel=1e-9)
    # the bottom reaction balances the vertical contact force, which is below
    # Σ W p by the tilt of the disk's normals over the small contact zone
    assert bottom == pytest.approx(force, rel=2e-2)


@pytest.mark.parametrize("kind", ["GLS", "LmLS", "LcLS*"])
def test_two_blocks_pressed_by_displacement(kind):
    p, force, top = figures(two_blocks_pressed(MPI.COMM_WORLD, kind), 12)
    p_self, force_self, top_self = figures(two_blocks_pressed(MPI.COMM_SELF, kind), 12)
    penalty = 1e3 * 7
    # both blocks (height 0.5 each) strained alike; the interface closes by p/ε
    exact = E_PLANE * PUSH / 1.0 / (1 + E_PLANE / (1.0 * penalty))
    assert np.max(np.abs(p[:, 1] / exact - 1)) < 1e-8
    np.testing.assert_allclose(p, p_self, rtol=0, atol=1e-10 * exact)
    assert -top == pytest.approx(exact, rel=1e-8)
    assert force == pytest.approx(exact, rel=1e-8)
    assert top_self == pytest.approx(top, rel=1e-10)
