"""Contact in (r, z) axisymmetry: every contact integral carries 2πr.

The scenes are the plane-strain ones read as meridians of bodies of
revolution (x the radius r, y the axis z): the patch-test blocks become two
stacked cylinders of radius 1, the pressed block a cylinder on a rigid plane
or against a rigid sphere centred on the axis. Under a uniform pressure p on
the top, the exact axisymmetric solution is σ_zz = −p, σ_rr = σ_θθ = 0:
u_r = ν p r / E, u_z linear in z, and the penalty's penetration p/ε.
"""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar import KIND_NAMES, ContactProblem, ContactTerm, RigidPlane, RigidSphere
from support import POINTWISE_WITH_A_DUAL_KIND, load_demo
from support.jacobian_check import (energy_gradient_error, has_gaps_of_both_signs,
                                    jacobian_error, newton_step_error)
from support.meshes import rectangle
from support.scenes import block_on_plane

E, NU, P = 1.0, 0.3, 0.01
BOTTOM, TOP, AXIS = 1, 2, 3


def two_cylinders(orientation: str, degree: int = 1):
    """The patch-test mesh: lower and upper cylinder, non-matching at z = 0."""
    demo = load_demo("patch_test")
    fine, coarse = 0.09, 0.14
    h_lower, h_upper = (fine, coarse) if orientation == "finer-slave" else (coarse, fine)
    domain, tags = demo.build_mesh(2, h_lower, h_upper, degree, MPI.COMM_WORLD)
    return demo, fem.functionspace(domain, ("Lagrange", degree, (domain.geometry.dim,))), tags, fine


def deviation_from(problem, p: float) -> float:
    """The largest |p_A/p − 1| over the slave nodes of all ranks."""
    pressures = problem.surface_pressure(gather=True).p
    return float(np.max(np.abs(pressures / p - 1)))


@POINTWISE_WITH_A_DUAL_KIND
@pytest.mark.parametrize("orientation", ["finer-slave", "finer-master"])
@pytest.mark.parametrize("active_set", ["nodal", "pointwise"])
@pytest.mark.parametrize("kind", KIND_NAMES)
def test_patch_test_of_two_cylinders_transmits_the_uniform_pressure(kind, active_set,
                                                                    orientation):
    demo, V, tags, fine = two_cylinders(orientation)
    problem = ContactProblem(V, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, E=E, nu=NU,
                             kind=kind, penalty=1e3 / fine, active_set=active_set,
                             fixed={demo.SYM_X: {0: 0.0}, demo.BOTTOM: {1: 0.0}},
                             tractions={demo.TOP: [0.0, -P]}, axisymmetric=True)
    problem.solve(load_steps=1)
    assert deviation_from(problem, P) < 1e-8
    # the whole circular face carries p π R²; the support below pushes back as much
    assert problem.contact_force()[1] == pytest.approx(-P * np.pi, rel=1e-8)
    assert problem.normal_force() == pytest.approx(P * np.pi, rel=1e-8)
    assert problem.reaction_force(demo.BOTTOM)[1] == pytest.approx(P * np.pi, rel=1e-8)


@pytest.mark.parametrize("kind", KIND_NAMES)
def test_patch_test_with_quadratic_elements_and_a_vertex_on_the_axis(kind):
    """P2: the slave's vertex on the axis has ∫N 2πr ds = 0 in the plain basis;
    the transformed basis (automatic) keeps every kind defined and exact."""
    demo, V, tags, fine = two_cylinders("finer-slave", degree=2)
    problem = ContactProblem(V, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, E=E, nu=NU,
                             kind=kind, penalty=1e3 / fine,
                             fixed={demo.SYM_X: {0: 0.0}, demo.BOTTOM: {1: 0.0}},
                             tractions={demo.TOP: [0.0, -P]}, axisymmetric=True)
    problem.solve(load_steps=1)
    assert deviation_from(problem, P) < 1e-8
    assert problem.reaction_force(demo.BOTTOM)[1] == pytest.approx(P * np.pi, rel=1e-8)


@pytest.mark.parametrize("kind", KIND_NAMES)
def test_seed_scaling_carries_the_load_but_not_the_uniform_pressure(kind):
    """The seed scaling (ε on the integrated gap) is not the patch-test-passing
    one, as in plane strain; the load still goes through."""
    demo, V, tags, fine = two_cylinders("finer-slave")
    problem = ContactProblem(V, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, E=E, nu=NU,
                             kind=kind, penalty=1e3 / fine, scaling="seed",
                             fixed={demo.SYM_X: {0: 0.0}, demo.BOTTOM: {1: 0.0}},
                             tractions={demo.TOP: [0.0, -P]}, axisymmetric=True)
    problem.solve(load_steps=1)
    assert problem.reaction_force(demo.BOTTOM)[1] == pytest.approx(P * np.pi, rel=1e-8)


@pytest.mark.parametrize("kind", KIND_NAMES)
def test_cylinder_on_a_rigid_plane_has_the_exact_axisymmetric_solution(kind):
    V, tags = block_on_plane(n=(10, 4))
    penalty = 1e3
    problem = ContactProblem(V, tags, BOTTOM, obstacle=RigidPlane([0, 0], [0, 1]), E=E, nu=NU,
                             kind=kind, penalty=penalty, fixed={AXIS: {0: 0.0}},
                             tractions={TOP: [0.0, -P]}, axisymmetric=True)
    problem.solve(load_steps=2)
    assert deviation_from(problem, P) < 1e-8
    # u_r = ν p r / E (the hoop strain), u_z = −p/ε − p z / E
    x = V.tabulate_dof_coordinates()
    exact = np.column_stack([NU * P * x[:, 0] / E, -P / penalty - P * x[:, 1] / E])
    owned = V.dofmap.index_map.size_local
    error = np.max(np.abs(problem.u.x.array.reshape(-1, 2)[:owned] - exact[:owned]))
    assert problem.mesh.comm.allreduce(float(error), op=MPI.MAX) < 1e-8 * np.max(np.abs(exact))
    assert problem.contact_force()[1] == pytest.approx(P * np.pi, rel=1e-8)


def pressed_cylinder(obstacle, kind: str, depth: float, active_set: str = "nodal",
                     basis_configuration: str = "initial"):
    """A coarse cylinder against ``obstacle`` at full load, deformed so that its
    bottom penetrates by ``depth`` on the axis and less outwards (the contact
    ends inside the slave surface); returns the problem."""
    V, tags = block_on_plane(n=(6, 3))
    problem = ContactProblem(V, tags, BOTTOM, obstacle=obstacle, E=E, nu=NU, kind=kind,
                             penalty=50.0, fixed={AXIS: {0: 0.0}}, tractions={TOP: [0.0, -P]},
                             active_set=active_set, basis_configuration=basis_configuration,
                             axisymmetric=True)
    problem.set_load(1.0)
    problem.u.interpolate(lambda x: np.vstack([0.001 * x[0] * x[1],
                                               -depth + 0.003 * x[0] ** 2]))
    fem.petsc.set_bc(problem.u.x.petsc_vec, problem.bcs)
    problem.u.x.scatter_forward()
    assert has_gaps_of_both_signs(problem)
    return problem


@pytest.mark.parametrize("kind", ["LmLS", "LcLS*"])
@pytest.mark.parametrize("obstacle", ["plane", "sphere"])
def test_jacobian_matches_finite_differences_against_an_obstacle(kind, obstacle):
    """A sphere centred on the axis: the gap's curvature and the 2πr weight."""
    ob = (RigidPlane([0, -0.0005], [0, 1]) if obstacle == "plane"   # contact for r < 0.71
          else RigidSphere([0.0, -2.0], 2.01))
    assert jacobian_error(pressed_cylinder(ob, kind, depth=0.002)) < 1e-7


@pytest.mark.parametrize("active_set", ["nodal", "pointwise"])
@pytest.mark.parametrize("kind", ["GLS", "GLS*"])
def test_gls_newton_step_inverts_the_residual_derivative(kind, active_set):
    """GLS kinds: the augmented step against R' by differences; the sphere cuts
    slave cells (pointwise: the split cells' rule with 2πr)."""
    problem = pressed_cylinder(RigidSphere([0.0, -2.0], 2.0), kind, depth=0.0031,
                               active_set=active_set)
    assert newton_step_error(problem) < 1e-6


@pytest.mark.parametrize("kind, active_set, configuration",
                         [("LmLS*", "pointwise", "initial"), ("LcLS", "nodal", "initial"),
                          ("LmLS*", "nodal", "current"), ("LmLS", "pointwise", "current")])
def test_jacobian_matches_finite_differences_between_two_bodies(kind, active_set, configuration):
    """"current": the segments' 2πr weights through the Jet kernel, the master
    and the slave moving with u_r."""
    demo, V, tags, fine = two_cylinders("finer-slave")
    problem = ContactProblem(V, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, E=E, nu=NU,
                             kind=kind, penalty=1e2, active_set=active_set,
                             basis_configuration=configuration,
                             fixed={demo.SYM_X: {0: 0.0}, demo.BOTTOM: {1: 0.0}},
                             tractions={demo.TOP: [0.0, -P]}, axisymmetric=True)
    problem.set_load(1.0)
    # tilt the upper body alone (its nodes at z = 0 are its own): contact for r > ½
    domain = problem.mesh
    cells = np.arange(domain.topology.index_map(2).size_local, dtype=np.int32)
    upper = cells[mesh.compute_midpoints(domain, 2, cells)[:, 1] > 0]
    problem.u.interpolate(lambda x: np.vstack([0.002 * x[0], 0.004 * (0.5 - x[0]) + 0.0013]),
                          cells0=upper)
    fem.petsc.set_bc(problem.u.x.petsc_vec, problem.bcs)
    problem.u.x.scatter_forward()
    assert has_gaps_of_both_signs(problem)
    assert jacobian_error(problem) < 1e-7


@pytest.mark.parametrize("active_set", ["nodal", "pointwise"])
@pytest.mark.parametrize("kind", ["LmLS", "LmLS*"])
@pytest.mark.parametrize("obstacle", ["plane", "sphere"])
def test_current_configuration_jacobian_matches_finite_differences(obstacle, kind, active_set):
    """Bases on the current surface of revolution: the measure J·2πr moves with
    u_r, and W, ĝ and their derivatives with it."""
    ob = (RigidPlane([0, -0.0005], [0, 1]) if obstacle == "plane"
          else RigidSphere([0.0, -2.0], 2.01))
    problem = pressed_cylinder(ob, kind, depth=0.002, active_set=active_set,
                               basis_configuration="current")
    if active_set == "nodal":
        assert energy_gradient_error(problem) < 1e-6
    assert jacobian_error(problem) < 1e-7


def test_current_configuration_measure_is_the_swept_area():
    """Σ_A W_A on the current surface is the area its meridian sweeps, 2π ∫ r ds
    (the bottom disk of a cylinder stretched radially by 1%: π·1.01²)."""
    V, tags = block_on_plane(n=(6, 3))
    problem = ContactProblem(V, tags, BOTTOM, obstacle=RigidPlane([0, -1.0], [0, 1]), E=E,
                             nu=NU, kind="LmLS", penalty=50.0, fixed={AXIS: {0: 0.0}},
                             basis_configuration="current", axisymmetric=True)
    problem.u.interpolate(lambda x: np.vstack([0.01 * x[0], 0.0 * x[1]]))
    problem.u.x.scatter_forward()
    W = problem.contact.evaluate().lumped_weights
    n = problem.slave.layout.num_owned
    total = problem.mesh.comm.allreduce(float(np.sum(W[:n])))
    assert abs(total - np.pi * 1.01 ** 2) <= 1e-12 * np.pi


def test_bad_axisymmetric_input_is_named():
    V, tags = block_on_plane(n=(4, 2))
    u = fem.Function(V)
    plane = RigidPlane([0, 0], [0, 1])
    with pytest.raises(NotImplementedError, match="dual coefficients"):
        ContactTerm(u, tags, BOTTOM, obstacle=plane, penalty=1.0, axisymmetric=True,
                    kind="LcLS*", basis_configuration="current")
    # the mesh on the wrong side of the axis
    domain, tags_left = rectangle(MPI.COMM_WORLD, 0.0, 0.5, (4, 2), bottom=1, top=2, left=3)
    domain.geometry.x[:, 0] -= 0.5
    V_left = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    with pytest.raises(ValueError, match="r ≥ 0"):
        ContactTerm(fem.Function(V_left), tags_left, BOTTOM, obstacle=plane, penalty=1.0,
                    axisymmetric=True)
    # a slave facet lying on the axis sweeps nothing
    with pytest.raises(ValueError, match="on the axis"):
        ContactTerm(u, tags, AXIS, obstacle=RigidPlane([-1, 0], [-1, 0]), penalty=1.0,
                    axisymmetric=True)


def test_separated_bodies_feel_no_contact_force():
    """Before contact there is no contact force at all, not even near the axis
    (MOOSE's RZ mortar showed spurious stresses there, idaholab/moose#28980)."""
    demo, V, tags, fine = two_cylinders("finer-master")
    u = fem.Function(V)
    domain = V.mesh
    cells = np.arange(domain.topology.index_map(2).size_local, dtype=np.int32)
    upper = cells[mesh.compute_midpoints(domain, 2, cells)[:, 1] > 0]
    u.interpolate(lambda x: np.vstack([0.01 * x[0], np.full(x.shape[1], 1e-4)]), cells0=upper)
    u.x.scatter_forward()
    contact = ContactTerm(u, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, kind="LcLS*",
                          penalty=1e3 / fine, axisymmetric=True)
    n = contact.slave.layout.num_owned
    gaps = contact.results.nodal_gaps()
    mine = contact.slave.owned_nodes
    assert domain.comm.allreduce(float(np.max(gaps[mine], initial=-np.inf)), op=MPI.MAX) < 0
    # against the force a penetration as deep as the gap would give on the whole face
    scale = 1e3 / fine * 1e-4 * np.pi
    assert np.max(np.abs(contact.results.contact_force())) <= 1e-12 * scale
    pressures = contact.results.nodal_pressures()[:n]
    assert domain.comm.allreduce(float(np.max(np.abs(pressures), initial=0.0)),
                                 op=MPI.MAX) <= 1e-12 * 1e3 / fine * 1e-4


@pytest.mark.parametrize("kind", ["LmLS", "GLS"])
def test_pointwise_gaps_on_cut_cells_carry_the_circumference(kind):
    """p_A = ε ∫ M̄_A ⟨d⟩ 2πr ds against a sphere that cuts a slave cell: the
    cut-cell rule against the basis's own integral with a 60-point rule."""
    V, tags = block_on_plane(n=(10, 4))
    u = fem.Function(V)
    sphere = RigidSphere([0.0, -2.0], 2.02)        # contact out to r = 0.28, inside a cell
    penalty = 10.0
    contact = ContactTerm(u, tags, BOTTOM, obstacle=sphere, kind=kind, penalty=penalty,
                          active_set="pointwise", axisymmetric=True)
    from dolfinx_mortar import MortarBasis
    from dolfinx_mortar.kinds import unstarred_partner
    fine = MortarBasis(unstarred_partner(kind), contact.slave, quadrature_degree=60)

    def depth(x):
        return np.maximum(0.0, 2.02 - np.sqrt(x[0] ** 2 + (x[1] + 2.0) ** 2))
    expected = penalty * fine.nodal_values(depth)
    n = contact.slave.layout.num_owned
    error = np.max(np.abs(contact.results.nodal_pressures()[:n] - expected[:n]), initial=0.0)
    scale = np.max(np.abs(expected))
    # the Gauss rule of the full cells (degree 4) meets the sphere within 3e-5
    assert contact.comm.allreduce(float(error), op=MPI.MAX) < 1e-4 * max(
        contact.comm.allreduce(float(scale), op=MPI.MAX), 1e-300)
