"""Friction in whole solves: μ = 0 is frictionless, the history moves only with
accepted steps, the energy of a load–unload cycle balances, the output carries
the friction fields, and what is not supported says so."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import (ContactProblem, ContactTerm, CoulombFriction, LoadPathSolver,
                            RigidPlane, read_xdmf_series)
from dolfinx_mortar.small_strain.elastic import linear_elastic_residual
from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem
from support.scenes import ALL_KINDS, block_on_plane

PLANE = [0.0, 0.0], [0.0, 1.0]


def pressed(friction, configuration: str = "initial", mesh=None, **solver) -> ContactProblem:
    """The block pressed on the plane; ``mesh`` (space, tags) to solve on one
    already made: two builds may be partitioned differently on more than two
    ranks, and then their arrays differ node by node."""
    V, tags = mesh or block_on_plane(n=(8, 4))
    return ContactProblem(V, tags, 1, obstacle=RigidPlane(*PLANE), E=1.0, nu=0.3,
                          penalty=50.0, fixed={3: {0: 0.0}}, tractions={2: [0.002, -0.01]},
                          basis_configuration=configuration, friction=friction, **solver)


def test_every_kind_converges_with_partial_slip():
    """A block held on its left, pressed and pushed sideways at 0.2 of the
    load (μ = 0.3, ε = 1e3 E/h): its right end slips, the rest sticks. Every
    kind converges in a few Newton iterations per step, with the dual kind's
    stick/slip states. LmLS and LmLS* stalled here while their slip averaged
    the neighbours' (issue 35); a first step from rest stalls at any load, so
    cut-backs cannot help."""
    runs = {}
    for kind in ALL_KINDS:
        V, tags = block_on_plane(n=(8, 4))
        problem = ContactProblem(V, tags, 1, obstacle=RigidPlane(*PLANE), E=1.0, nu=0.3,
                                 kind=kind, penalty=1e3 * 8, fixed={3: {0: 0.0}},  # 1e3 E/h
                                 tractions={2: [0.002, -0.01]}, friction=CoulombFriction(0.3))
        result = problem.solve(load_steps=2, max_cuts=0)
        summary = result.steps[-1].friction[0]
        runs[kind] = (result.newton_iterations, summary["stick_nodes"], summary["slip_nodes"])
    iterations, stick, slip = runs["LcLS*"]
    assert stick > 0 and slip > 0
    for kind, (its, *states) in runs.items():
        assert states == [stick, slip], kind
        assert its <= iterations + 2, (kind, its, iterations)


@pytest.mark.parametrize("configuration", ["initial", "current"])
def test_no_friction_coefficient_is_the_frictionless_problem(configuration):
    """μ = 0 runs the friction machinery and must change nothing, node by node."""
    results, mesh = [], block_on_plane(n=(8, 4))
    for friction in (None, CoulombFriction(0.0)):
        problem = pressed(friction, configuration, mesh)
        problem.solve(load_steps=2)
        results.append((problem.u.x.array.copy(), problem.nodal_pressures()))
    assert np.allclose(results[0][0], results[1][0], rtol=0, atol=1e-14)
    assert np.allclose(results[0][1], results[1][1], rtol=0, atol=1e-14)


@pytest.mark.parametrize("configuration", ["initial", "current"])
def test_the_iterative_path_solves_the_unsymmetric_friction_jacobian(configuration):
    """The iterative linear path (GMRES, as friction's Jacobian is unsymmetric,
    with multigrid and an exact contact block) gives the direct path's
    solution and stick/slip states, with sticking and slipping nodes."""
    runs, mesh = [], block_on_plane(n=(8, 4))
    for linear_solver in ("direct", "iterative"):
        problem = pressed(CoulombFriction(0.15), configuration, mesh,
                          linear_solver=linear_solver,
                          petsc_options={"snes_ksp_ew": False, "ksp_rtol": 1e-12})
        result = problem.solve(load_steps=2)
        runs.append((problem.u.x.array.copy(), problem.contact.results.slip_states(),
                     problem.solver.default_options().get("ksp_type"), result))
    (u_direct, states_direct, _, _), (u_krylov, states_krylov, ksp, result) = runs
    assert ksp == "gmres"
    assert result.linear_iterations > result.newton_iterations      # Krylov, not LU
    comm = MPI.COMM_WORLD
    assert comm.allreduce(int(np.sum(states_direct == 1))) > 0     # sticking
    assert comm.allreduce(int(np.sum(states_direct == 2))) > 0     # and slipping
    assert np.array_equal(states_direct, states_krylov)
    scale = comm.allreduce(float(np.max(np.abs(u_direct))), op=MPI.MAX)
    difference = comm.allreduce(float(np.max(np.abs(u_direct - u_krylov))), op=MPI.MAX)
    assert difference < 1e-8 * scale


def test_the_history_moves_only_with_an_accepted_step():
    """A Newton iterate, or a failed step, leaves nothing behind: evaluated
    again where it was accepted, the term reports the accepted forces."""
    problem = pressed(CoulombFriction(0.3))
    problem.solve(load_steps=2)
    contact = problem.contact
    accepted = contact.results.tangential_tractions().copy()
    version = contact.friction.history.version
    saved = problem.u.x.array.copy()
    problem.u.x.array[:] += 1e-3 * np.sin(np.arange(len(saved)))
    contact.update(problem.bcs)                  # as a Newton iterate does
    assert contact.friction.history.version == version
    problem.u.x.array[:] = saved
    assert np.array_equal(contact.results.tangential_tractions(), accepted)


#: the energy balance's tolerance: the Newton tolerance on frozen bases; on the
#: current surface the tangential springs' stiffness ω_T = ε_T W^m follows W
#: from step to step, and a spring that keeps its force changes its energy
BALANCE = {"initial": 1e-8, "current": 1e-4}


@pytest.mark.parametrize("configuration", ["initial", "current"])
def test_a_load_unload_cycle_balances_its_energy(configuration):
    """A block pressed on a plane by G, then pushed sideways by Q up to 0.9
    μG, back to −0.9 μG and to 0 (partial slip, held by friction alone): the
    work of the loads (trapezoidal rule) equals the strain energy plus the
    penalty springs' energy plus the frictional dissipation, to the Newton
    tolerance. A friction force out of step with the residual, or a
    dissipation counted on the wrong slip, breaks it by percents."""
    V, tags = block_on_plane(n=(8, 4))
    u = fem.Function(V)
    contact = ContactTerm(u, tags, 1, obstacle=RigidPlane(*PLANE), penalty=50.0,
                          basis_configuration=configuration, friction=CoulombFriction(0.3))
    normal = fem.Constant(V.mesh, PETSc.ScalarType(0.0))
    shear = fem.Constant(V.mesh, PETSc.ScalarType(0.0))
    v = ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=V.mesh, subdomain_data=tags)
    load = (shear * v[0] - normal * v[1]) * ds(2)
    problem = NonlinearContactProblem(linear_elastic_residual(u, 1.0, 0.3) - load, u, contact)
    solver = LoadPathSolver(problem)
    load_form = fem.form(load)
    # ½ a(u, u): the residual's bilinear form with u for the test function
    strain = fem.form(0.5 * ufl.replace(linear_elastic_residual(u, 1.0, 0.3), {v: u}))
    comm = V.mesh.comm
    previous = {"f": fem.petsc.assemble_vector(load_form), "u": u.x.petsc_vec.copy()}
    work = [0.0]

    def record(_step) -> None:
        f = fem.petsc.assemble_vector(load_form)
        f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        du = u.x.petsc_vec.copy()
        du.axpy(-1.0, previous["u"])
        mean = f.copy()
        mean.axpy(1.0, previous["f"])
        work[0] += 0.5 * mean.dot(du)
        previous["f"], previous["u"] = f, u.x.petsc_vec.copy()

    previous["f"].ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    G, Q = 0.01, 0.0027
    path = [(normal, 0.0, G, 3), (shear, 0.0, Q, 4), (shear, Q, -Q, 8), (shear, -Q, 0.0, 4)]
    for constant, start, end, steps in path:
        def update(t, c=constant, a=start, b=end):
            c.value = a + t * (b - a)
        solver.solve(update, load_steps=steps, on_step=record)
    stored = comm.allreduce(fem.assemble_scalar(strain)) + contact.results.stored_energy()
    dissipation = contact.results.dissipation()
    assert dissipation > 1e-3 * work[0]           # it did slip
    assert work[0] == pytest.approx(stored + dissipation, rel=BALANCE[configuration])


def test_the_output_carries_the_tangential_traction_and_the_states(tmp_path_factory):
    folder = tmp_path_factory.mktemp("friction") if MPI.COMM_WORLD.rank == 0 else None
    folder = Path(MPI.COMM_WORLD.bcast(folder))
    problem = pressed(CoulombFriction(0.3))
    problem.solve(load_steps=2, output=folder / "block.xdmf")
    data = read_xdmf_series(folder / "block_slave.xdmf")
    names = set(data.steps[-1][1])
    assert {"p_hat", "p_star", "q_hat_x", "q_hat_y", "stick_slip"} <= names
    _, states = data.field("stick_slip")
    assert set(np.unique(states[-1])) <= {0.0, 1.0, 2.0}
    _, q = data.field("q_hat_x")
    # the traction on the block opposes the push Q = 0.002 (per unit length); a node
    # that carries none reads ±round-off (6e-20 with another CPU's BLAS)
    scale = np.max(np.abs(q[-1]))
    assert scale > 1e-4 and np.all(q[-1] <= 1e-12 * scale)


@pytest.mark.parametrize("options, message", [
    ({"active_set": "pointwise", "kind": "LmLS*"}, "pointwise")])
def test_unsupported_combinations_say_why(options, message):
    V, tags = block_on_plane(n=(4, 2))
    u = fem.Function(V)
    with pytest.raises(NotImplementedError, match=message):
        ContactTerm(u, tags, 1, obstacle=RigidPlane(*PLANE), penalty=50.0,
                    friction=CoulombFriction(0.3), **options)


def test_friction_must_be_a_coulomb_law():
    V, tags = block_on_plane(n=(4, 2))
    with pytest.raises(TypeError, match="CoulombFriction"):
        ContactTerm(fem.Function(V), tags, 1, obstacle=RigidPlane(*PLANE), penalty=50.0,
                    friction=0.3)


def test_results_of_a_frictionless_term_name_the_missing_friction():
    problem = pressed(None)
    with pytest.raises(ValueError, match="no friction"):
        problem.contact.results.tangential_tractions()
    assert problem.contact.results.friction_summary() is None
