"""The pointwise active set with the bases in the current configuration: ĝ⁺_A = ∫ φ_A ⟨d⟩
from the templated kernel (against a master) or at the quadrature points (against an
obstacle), and the exact Jacobian of its virtual work."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx_mortar import ContactProblem, RigidSphere
from support import load_demo
from support.jacobian_check import jacobian_error
from support.scenes import pressed_block, sheared_blocks, sheared_boxes

POINTWISE_KINDS = ("LmLS", "LmLS*")


def _residual(problem: ContactProblem) -> np.ndarray:
    b = problem.problem.vector().duplicate()
    problem.problem.F(problem.u.x.petsc_vec, b)
    return b.array.copy()


def _owned_count(problem, values: np.ndarray, sign: int) -> int:
    n = problem.slave.layout.num_owned
    return problem.mesh.comm.allreduce(int(np.sum(sign * values[:n] > 0)))


@pytest.mark.parametrize("scaling", ["consistent", "seed"])
@pytest.mark.parametrize("kind", POINTWISE_KINDS)
def test_current_pointwise_jacobian_is_exact_against_a_master(kind, scaling):
    problem = sheared_blocks(kind, scaling, active_set="pointwise")
    state = problem.contact.evaluate()
    # the contact edge lies inside the surface: some nodes' supports penetrate
    # in part (0 < ĝ⁺ while ĝ < 0), others not at all
    assert _owned_count(problem, state.gaps_plus, 1) > 0
    assert _owned_count(problem, np.where(state.gaps_plus > 0, state.gaps, 0.0), -1) > 0
    assert jacobian_error(problem) < 1e-8


def test_kernel_positive_part_is_the_points_sum():
    """c⁺_A from the Jet kernel equals Σ_q w_q ⟨d_q⟩ N_A(q) of the double
    segmentation's points to round-off, pair by pair."""
    problem = sheared_blocks("LmLS", active_set="pointwise")
    state = problem.contact.evaluate()
    model = problem.gap_model
    data = state.data.source.data
    points = data.coupling.points
    expected = np.zeros((len(data.coupling.pairs), model.slave.cells.shape[1]))
    np.add.at(expected, points.pairs,
              (points.weights * np.maximum(points.gap, 0.0))[:, None] * points.slave_N)
    kernel = model.pair_derivatives(data.coupling, data.kept,
                                    with_hessian=False, with_positive_part=True).value_plus
    comm = problem.mesh.comm
    scale = comm.allreduce(float(np.max(np.abs(expected), initial=0.0)), op=MPI.MAX)
    error = comm.allreduce(float(np.max(np.abs(kernel - expected[data.kept]),
                                        initial=0.0)), op=MPI.MAX)
    assert scale > 0 and error <= 1e-12 * scale
    # every pair with a penetrating point got derivatives
    penetrating = np.zeros(len(data.coupling.pairs), dtype=bool)
    penetrating[points.pairs[points.gap > 0]] = True
    assert np.all(data.kept[penetrating])


@pytest.mark.parametrize("kind", POINTWISE_KINDS)
def test_current_pointwise_is_the_nodal_model_where_everything_penetrates(kind):
    """With every point of the interface penetrating, ⟨d⟩ = d: the same residual
    and the same Jacobian as the nodal set, to round-off."""
    pointwise = sheared_blocks(kind, active_set="pointwise", push=0.02)
    nodal = sheared_blocks(kind, push=0.02,
                           mesh_and_tags=(pointwise.mesh, pointwise.facet_tags))
    state = pointwise.contact.evaluate()
    points = state.data.source.data.coupling.points
    comm = pointwise.mesh.comm
    assert comm.allreduce(int(np.sum(points.gap <= 0))) == 0
    r_p, r_n = _residual(pointwise), _residual(nodal)
    scale = comm.allreduce(float(np.max(np.abs(r_n))), op=MPI.MAX)
    assert comm.allreduce(float(np.max(np.abs(r_p - r_n))), op=MPI.MAX) <= 1e-12 * scale
    J_p, J_n = pointwise.problem.matrix(), nodal.problem.matrix()
    for problem, J in ((pointwise, J_p), (nodal, J_n)):
        problem.problem.J(problem.u.x.petsc_vec, J)
        problem.problem.J(problem.u.x.petsc_vec, J)      # the active set settled: geometric
    J_p.axpy(-1.0, J_n)
    assert J_p.norm() <= 1e-12 * J_n.norm()


def test_current_pointwise_jacobian_is_exact_against_an_obstacle():
    """⟨d⟩ at the cell quadrature points of the current surface, a disk below."""
    problem = pressed_block(RigidSphere([0.5, -2.0], 2.01), "LmLS", n=(8, 3),
                            basis_configuration="current", active_set="pointwise")
    problem.u.interpolate(lambda x: np.vstack([0.05 * x[1] + 0.1 * x[0] ** 2,
                                               -0.02 + 0.003 * x[0] ** 2 + 0.004 * x[0]]))
    problem.u.x.scatter_forward()
    state = problem.contact.evaluate()
    assert _owned_count(problem, state.gaps_plus, 1) >= 3
    assert _owned_count(problem, np.where(state.gaps_plus > 0, state.gaps, 0.0), -1) > 0
    assert jacobian_error(problem) < 1e-7


def test_current_pointwise_solves_the_patch_test():
    """Non-matching blocks under a uniform traction: the pointwise set on the
    current surface transmits the pressure as the nodal set does."""
    demo = load_demo("patch_test")
    args = demo.parse_args(["--basis-configuration", "current", "--active-set", "pointwise"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = demo.run(args, "finer-slave", "LmLS", "consistent")
    assert r["max_relative_deviation"] < 2e-5, r


@pytest.mark.slow
def test_current_pointwise_jacobian_is_exact_in_3d():
    """P1 triangles against a master: c⁺ and its gradient from the Jet kernel."""
    problem = sheared_boxes("LmLS", active_set="pointwise")
    state = problem.contact.evaluate()
    assert _owned_count(problem, state.gaps_plus, 1) > 0
    assert _owned_count(problem, np.where(state.gaps_plus > 0, state.gaps, 0.0), -1) > 0
    assert jacobian_error(problem) < 1e-8


@pytest.mark.parametrize("obstacle", ["rigid", "elastic"])
def test_current_pointwise_hertz2d_converges_quadratically_and_matches_hertz(obstacle):
    """Hertz 2D, LmLS, pointwise set on the current surfaces, 4 load steps: every
    step ends quadratically (at most 3 iterations from 1e-3 of its force) and
    the contact half-width is Hertz's."""
    demo = load_demo("hertz2d")
    args = demo.parse_args(["--refine", "0.4", "--kind", "LmLS", "--obstacle", obstacle,
                            "--basis-configuration", "current", "--active-set", "pointwise"])
    problem, ref, h = demo.build_problem(args, MPI.COMM_WORLD)
    result = problem.solve(load_steps=4)
    assert all(0 <= step.terminal_iterations() <= 3 for step in result.steps), \
        [step.phases[-1] for step in result.steps]
    figures = demo.key_figures(args, problem, result, ref, h, 0.0)
    assert abs(figures["a_error"]) < 0.02, figures        # -0.3% / -0.7% at refine 0.5
    assert abs(figures["force_error"]) < 2e-3, figures
