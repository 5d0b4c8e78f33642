"""The exact friction Jacobian: central differences of the residual against it,
with sticking and slipping nodes at once, before and after a step's forces
became history, for rigid obstacles and two bodies, 2D, 3D and axisymmetric,
on frozen bases and on the current surface (where the cone's normal force
moves with W as well as with the gap)."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar import ContactProblem, CoulombFriction, RigidPlane, RigidSphere
from dolfinx_mortar.contact.laws import SLIP, STICK
from support import load_demo
from support.jacobian_check import jacobian_error, newton_step_error
from support.scenes import LOCAL_KINDS, block_on_plane

#: central differences of an exact Jacobian agree to about 1e-9 here; a wrong
#: term (a sign, a missing coupling of the normal force) gives 1e-2 … 1
TOLERANCE = 1e-6


def friction(penalty: float) -> CoulombFriction:
    """μ = 0.3 with ε_T = ε: the scenes' shear then slips at the ends and
    sticks in the middle (the tangent does not depend on the choice)."""
    return CoulombFriction(0.3, tangential_penalty=penalty)


def count_states(problem) -> tuple[int, int]:
    """Sticking and slipping slave nodes on all ranks at the present u; checks
    that no node sits on the cone, where central differences straddle the kink
    (a scene chosen with round numbers put one there exactly)."""
    state = problem.contact.evaluate()
    friction = state.friction
    n = problem.slave.layout.num_owned
    trial = friction.projected_history + friction.tangential_weights[:, None] * \
        friction.slip_increment
    limit = problem.contact.friction.law.mu * state.force
    active = friction.mapping.state[:n] > 0
    comm = problem.mesh.comm
    scale = comm.allreduce(float(np.max(limit[:n], initial=0.0)), op=MPI.MAX)
    margin = np.abs(np.linalg.norm(trial, axis=1) - limit)[:n][active]
    assert comm.allreduce(float(np.min(margin, initial=np.inf)), op=MPI.MIN) > 1e-3 * scale
    states = friction.mapping.state[:n]
    return (comm.allreduce(int(np.sum(states == STICK))),
            comm.allreduce(int(np.sum(states == SLIP))))


def set_displacement(problem, values, cells=None) -> None:
    problem.u.x.array[:] = 0.0
    problem.u.interpolate(values, cells0=cells) if cells is not None else \
        problem.u.interpolate(values)
    problem.u.x.scatter_forward()


def augmented_step_error(problem) -> float:
    """GLS kinds (no assembled contact Jacobian): the augmented system's Newton
    step against central differences, once the stick/slip states have
    repeated (the first Jacobian at a point takes the slip secant)."""
    x0 = problem.u.x.petsc_vec.copy()
    b = problem.problem.vector().duplicate()
    problem.problem.F(x0, b)
    problem.problem.J(x0, problem.problem.matrix())
    # the GLS residual goes through L⁻¹ solves, whose round-off the differences
    # divide by their step: measured 3e-6 at a step of 1e-7, 4e-7 at 1e-6 and
    # 3e-8 at 1e-5 (∝ 1/step) on the block on a disk, seed scaling
    return newton_step_error(problem, size=1e-5)


def check_both_branches(problem, first, second, cells=None) -> None:
    """Exact at ``first`` (no history) and, after accepting it, at ``second``;
    both with sticking and slipping nodes."""
    error = (augmented_step_error if problem.contact.traits.takes_the_linear_solve
             else jacobian_error)
    set_displacement(problem, first, cells)
    stick, slip = count_states(problem)
    assert stick > 0 and slip > 0, (stick, slip)
    assert error(problem) < TOLERANCE
    problem.contact.accept_step()
    set_displacement(problem, second, cells)
    stick, slip = count_states(problem)
    assert stick > 0 and slip > 0, (stick, slip)
    assert error(problem) < TOLERANCE


def block(obstacle, kind="LcLS*", scaling="consistent", axisymmetric=False,
          configuration="initial") -> ContactProblem:
    V, tags = block_on_plane(n=(8, 4))
    problem = ContactProblem(V, tags, 1, obstacle=obstacle, E=1.0, nu=0.3, kind=kind,
                             scaling=scaling, penalty=50.0, tractions={2: [0.002, -0.01]},
                             axisymmetric=axisymmetric, basis_configuration=configuration,
                             friction=friction(50.0))
    problem.set_load(1.0)
    return problem


def first_2d(x):
    """Pressed in, sheared about the middle: the middle sticks, the ends slip."""
    return np.vstack([0.0031 * (x[0] - 0.47), -0.00213 - 0.00397 * x[0]])


def second_2d(x):
    """Further in and further sheared: the ends slip on, the middle sticks."""
    return np.vstack([0.0053 * (x[0] - 0.47), -0.00261 - 0.00397 * x[0]])


def obstacle_2d(name: str):
    return RigidPlane([0, 0], [0, 1]) if name == "plane" else RigidSphere([0.5, -50.0], 50.0)


@pytest.mark.parametrize("kind", LOCAL_KINDS + ["GLS", "GLS*"])
@pytest.mark.parametrize("scaling", ["consistent", "seed"])
@pytest.mark.parametrize("obstacle", ["plane", "disk"])
def test_block_on_an_obstacle(kind, scaling, obstacle):
    check_both_branches(block(obstacle_2d(obstacle), kind, scaling), first_2d, second_2d)


@pytest.mark.parametrize("kind", ["LcLS*", "LmLS"])
@pytest.mark.parametrize("obstacle", ["plane", "disk"])
def test_block_on_an_obstacle_current(kind, obstacle):
    check_both_branches(block(obstacle_2d(obstacle), kind, configuration="current"),
                        first_2d, second_2d)


def on_the_axis(values):
    """``values`` with u_r = 0 on the axis (r = x = 0), where the surface must
    stay (the current surface is checked for r ≥ 0)."""
    def scaled(x):
        u = values(x)
        u[0] *= 2 * x[0]
        return u
    return scaled


@pytest.mark.parametrize("configuration", ["initial", "previous", "current"])
def test_axisymmetric_block_on_a_plane(configuration):
    # the dual kinds on the current axisymmetric surface are refused
    kind = "LmLS" if configuration == "current" else "LcLS*"
    check_both_branches(block(RigidPlane([0, 0], [0, 1]), kind=kind, axisymmetric=True,
                              configuration=configuration),
                        on_the_axis(first_2d), on_the_axis(second_2d))


def box(obstacle, kind: str, configuration: str = "initial") -> ContactProblem:
    domain = mesh.create_box(MPI.COMM_WORLD, [[0, 0, 0], [1, 1, 0.5]], [4, 4, 2])
    fdim = 2
    marks = [(1, lambda x: np.isclose(x[2], 0.0)), (2, lambda x: np.isclose(x[2], 0.5))]
    facets, values = [], []
    for tag, where in marks:
        found = mesh.locate_entities_boundary(domain, fdim, where)
        facets.append(found)
        values.append(np.full(len(found), tag, dtype=np.int32))
    order = np.argsort(np.concatenate(facets))
    tags = mesh.meshtags(domain, fdim, np.concatenate(facets)[order],
                         np.concatenate(values)[order])
    V = fem.functionspace(domain, ("Lagrange", 1, (3,)))
    problem = ContactProblem(V, tags, 1, obstacle=obstacle, E=1.0, nu=0.3, kind=kind,
                             penalty=50.0, tractions={2: [0.002, 0.0, -0.01]},
                             basis_configuration=configuration, friction=friction(50.0))
    problem.set_load(1.0)
    return problem


def first_3d(x):
    return np.vstack([0.0031 * (x[0] - 0.47), 0.0013 * (x[1] - 0.53),
                      -0.00213 - 0.00397 * x[0]])


def second_3d(x):
    return np.vstack([0.0053 * (x[0] - 0.47), 0.0021 * (x[1] - 0.53),
                      -0.00261 - 0.00397 * x[0]])


@pytest.mark.parametrize("kind", ["LcLS*", "LmLS"])
@pytest.mark.parametrize("obstacle", ["plane", "sphere"])
def test_box_on_an_obstacle(kind, obstacle):
    shape = (RigidPlane([0, 0, 0], [0, 0, 1]) if obstacle == "plane"
             else RigidSphere([0.5, 0.5, -50.0], 50.0))
    check_both_branches(box(shape, kind), first_3d, second_3d)


@pytest.mark.parametrize("obstacle", ["plane", "sphere"])
def test_box_on_an_obstacle_current(obstacle):
    shape = (RigidPlane([0, 0, 0], [0, 0, 1]) if obstacle == "plane"
             else RigidSphere([0.5, 0.5, -50.0], 50.0))
    check_both_branches(box(shape, "LcLS*", "current"), first_3d, second_3d)


def two_blocks(dim: int, kind: str, configuration: str) -> tuple[ContactProblem, np.ndarray]:
    """The patch test's non-matching blocks; the upper one's cells."""
    demo = load_demo("patch_test")
    h = (0.09, 0.14) if dim == 2 else (0.25, 0.35)
    domain, tags = demo.build_mesh(dim, *h, 1, MPI.COMM_WORLD)
    V = fem.functionspace(domain, ("Lagrange", 1, (dim,)))
    load = [0.002] + [0.0] * (dim - 2) + [-0.01]
    problem = ContactProblem(V, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, E=1.0,
                             nu=0.3, kind=kind, penalty=1e3, basis_configuration=configuration,
                             fixed={demo.BOTTOM: {k: 0.0 for k in range(dim)}},
                             tractions={demo.TOP: load}, friction=friction(1e3))
    problem.set_load(1.0)
    tdim = domain.topology.dim
    cells = np.arange(domain.topology.index_map(tdim).size_local, dtype=np.int32)
    height = mesh.compute_midpoints(domain, tdim, cells)[:, dim - 1]
    return problem, cells[height > 0]


@pytest.mark.parametrize("kind, configuration",
                         [(kind, configuration) for kind in LOCAL_KINDS
                          for configuration in ("initial", "previous", "current")]
                         + [("GLS", "initial"), ("GLS*", "previous")])
def test_two_blocks_2d(kind, configuration):
    problem, upper = two_blocks(2, kind, configuration)
    check_both_branches(
        problem, lambda x: np.vstack([3.1e-4 * (x[0] - 0.47), -1.07e-4 - 2.03e-4 * x[0]]),
        lambda x: np.vstack([5.3e-4 * (x[0] - 0.47), -1.31e-4 - 2.03e-4 * x[0]]), upper)


@pytest.mark.parametrize("kind, configuration", [("LcLS*", "initial"), ("LmLS*", "initial"),
                                                 ("LmLS*", "current")])
def test_two_blocks_3d(kind, configuration):
    problem, upper = two_blocks(3, kind, configuration)
    check_both_branches(
        problem, lambda x: np.vstack([3.1e-4 * (x[0] - 0.47), 1.1e-4 * (x[1] - 0.53),
                                      -1.07e-4 - 2.03e-4 * x[0]]),
        lambda x: np.vstack([5.3e-4 * (x[0] - 0.47), 2.1e-4 * (x[1] - 0.53),
                             -1.31e-4 - 2.03e-4 * x[0]]), upper)
