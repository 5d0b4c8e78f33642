"""Contact as a term in the user's own DOLFINx model (public API only).

The user's residual form (linear or neo-Hookean, body forces), their
Dirichlet conditions and load path; the contact term, the nonlinear problem
(driven by DOLFINx's NewtonSolver or the library's load-path solver), moving
obstacles, the contact resultant and the reactions.
"""
from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pytest
import ufl
from dolfinx import fem
from support.meshes import rectangle
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import (ContactDivergenceError, ContactProblem, ContactTerm, KIND_NAMES,
                            LoadPathSolver, NewtonSolver, NonlinearContactProblem, RigidPlane,
                            RigidSphere, reaction_force)
from dolfinx_mortar.io.read_series import read_xdmf_series
from dolfinx_mortar.small_strain.elastic import linear_elastic_residual
from demo_support.laws import neo_hookean_residual
from support import load_demo

BOTTOM, TOP, LEFT = 1, 2, 3
E, NU, H = 1.0, 0.3, 0.5
E_PLANE = E / (1 - NU ** 2)   # plane strain, free sideways


def block(n=(8, 4), degree=1):
    domain, tags = rectangle(MPI.COMM_WORLD, 0.0, H, n, bottom=BOTTOM, top=TOP, left=LEFT)
    V = fem.functionspace(domain, ("Lagrange", degree, (domain.geometry.dim,)))
    return domain, tags, V


def dirichlet(V, tags, tag, component, value):
    dofs = fem.locate_dofs_topological(V.sub(component), 1, tags.find(tag))
    return fem.dirichletbc(PETSc.ScalarType(value), dofs, V.sub(component))


def jacobian_error(problem: NonlinearContactProblem, seed: int = 3) -> float:
    """Central differences of problem.F against problem.J at the present u."""
    x0 = problem.u.x.petsc_vec.copy()
    A = problem.matrix()
    b = problem.vector().duplicate()
    problem.F(x0, b)
    problem.J(x0, A)
    problem.J(x0, A)   # "current": exact once the active set is the previous call's
    dx = x0.duplicate()
    dx.array[:] = np.random.default_rng(seed + MPI.COMM_WORLD.rank).normal(size=dx.array.shape)
    fem.petsc.set_bc(dx, problem.bcs, alpha=0.0)
    Jdx = b.duplicate()
    A.mult(dx, Jdx)
    h = 1e-6 / dx.norm()
    residuals = []
    for sign in (1, -1):
        x = x0.copy()
        x.axpy(sign * h, dx)
        r = b.duplicate()
        problem.F(x, r)
        residuals.append(r)
    fd = residuals[0] - residuals[1]
    fd.scale(1 / (2 * h))
    fd.axpy(-1.0, Jdx)
    x0.copy(problem.u.x.petsc_vec)
    problem.u.x.scatter_forward()
    return fd.norm() / Jdx.norm()


@pytest.mark.parametrize("configuration", ["initial", "current"])
@pytest.mark.parametrize("kind", ["LmLS*", "LcLS"])
def test_neo_hookean_user_form_has_the_exact_jacobian(kind, configuration):
    """A nonlinear material with a body force, written by the user in UFL, plus
    the contact term against a rigid disk: J is the derivative of F."""
    domain, tags, V = block(n=(6, 3))
    u = fem.Function(V)
    g = fem.Constant(domain, PETSc.ScalarType((0.0, -0.05)))   # a body force
    F = (neo_hookean_residual(u, E, NU)
         - ufl.dot(g, ufl.TestFunction(V)) * ufl.dx)
    contact = ContactTerm(u, tags, BOTTOM, obstacle=RigidSphere([0.5, -2.0], 2.0), kind=kind,
                          penalty=50.0, basis_configuration=configuration)
    bcs = [dirichlet(V, tags, LEFT, 0, 0.0), dirichlet(V, tags, TOP, 1, -0.01)]
    problem = NonlinearContactProblem(F, u, contact, bcs)
    u.interpolate(lambda x: np.vstack([0.02 * x[1] + 0.01 * x[0] ** 2,
                                       -0.004 + 0.004 * x[0] ** 2 - 0.02 * x[1]]))
    # a state that meets the BCs, as Newton's iterates do (DOLFINx's lifting
    # of a nonlinear form is only differentiated there)
    fem.petsc.set_bc(u.x.petsc_vec, bcs)
    u.x.scatter_forward()
    p = contact.results.nodal_pressures()
    n = contact.slave.layout.num_owned
    assert domain.comm.allreduce(int(np.sum(p[:n] > 0))) > 0   # partly in contact
    assert domain.comm.allreduce(int(np.sum(p[:n] == 0))) > 0
    assert jacobian_error(problem) < 1e-7


def uniform_pressure(delta: float, penalty: float) -> float:
    """The block pushed by δ onto its fixed top: p = δ/(H/E' + 1/ε) (penalty compliance)."""
    return delta / (H / E_PLANE + 1 / penalty)


@pytest.mark.parametrize("driver", ["NewtonSolver", "solve"])
@pytest.mark.parametrize("kind", KIND_NAMES)
def test_dolfinx_newton_solver_drives_the_contact_problem(kind, driver):
    """The two ways DOLFINx users drive a nonlinear problem, with the contact
    problem: the 0.9-style NewtonSolver (the library's drop-in, no extra set-up)
    and the 0.10+-style ``problem.solve()`` on the problem's own SNES. The
    plane moved up by δ (a moving obstacle) presses the block onto its fixed top."""
    domain, tags, V = block()
    u = fem.Function(V)
    plane = RigidPlane([0.0, 0.0], [0.0, 1.0])
    penalty, delta = 1e3, 0.01
    contact = ContactTerm(u, tags, BOTTOM, obstacle=plane, kind=kind, penalty=penalty)
    bcs = [dirichlet(V, tags, LEFT, 0, 0.0), dirichlet(V, tags, TOP, 1, 0.0)]
    plane.move_to([0.0, delta])
    if driver == "NewtonSolver":
        problem = NonlinearContactProblem(linear_elastic_residual(u, E, NU), u, contact, bcs)
        solver = NewtonSolver(domain.comm, problem)
        solver.krylov_solver.setType("preonly")
        solver.krylov_solver.getPC().setType("lu")
        solver.rtol, solver.atol = 1e-12, 1e-14
        iterations, converged = solver.solve(u)
        assert converged
    else:
        problem = NonlinearContactProblem(
            linear_elastic_residual(u, E, NU), u, contact, bcs,
            petsc_options_prefix=f"open_model_{kind.replace('*', 'star')}_",
            petsc_options={"snes_rtol": 1e-12, "snes_atol": 1e-14})
        assert problem.solve() is u
        assert problem.solver.getConvergedReason() > 0
    p_exact = uniform_pressure(delta, penalty)
    p = contact.results.surface_pressure(gather=True).p
    error = float(np.max(np.abs(p - p_exact), initial=0.0))
    assert error < 1e-8 * p_exact
    # the resultant on the slave pushes up; the top's support pulls down as much
    force = contact.results.contact_force()
    assert force[1] == pytest.approx(p_exact, rel=1e-8) and abs(force[0]) < 1e-10 * p_exact
    assert contact.results.normal_force() == pytest.approx(p_exact, rel=1e-8)
    assert reaction_force(problem, tags, TOP)[1] == pytest.approx(-p_exact, rel=1e-8)


def block_under_a_moving_plane() -> tuple[NonlinearContactProblem, RigidPlane]:
    """The block, its top held, over a rigid plane the load path moves up (LcLS*,
    ε = 1e3): the problem and the plane."""
    domain, tags, V = block()
    u = fem.Function(V)
    plane = RigidPlane([0.0, 0.0], [0.0, 1.0])
    contact = ContactTerm(u, tags, BOTTOM, obstacle=plane, kind="LcLS*", penalty=1e3)
    bcs = [dirichlet(V, tags, LEFT, 0, 0.0), dirichlet(V, tags, TOP, 1, 0.0)]
    return NonlinearContactProblem(linear_elastic_residual(u, E, NU), u, contact, bcs), plane


def test_load_path_moves_the_obstacle_and_takes_petsc_options(tmp_path):
    """The user's callback moves the obstacle along the load path; petsc_options
    reach the solver and leave the options database afterwards."""
    problem, plane = block_under_a_moving_plane()
    contact, u, domain = problem.contacts[0], problem.u, problem.u.function_space.mesh
    solver = LoadPathSolver(problem, petsc_options={"snes_max_it": 7}, prefix="open_path_")
    seen = []
    output = Path(domain.comm.bcast(str(tmp_path / "path.xdmf"), root=0))  # one file for all ranks
    result = solver.solve(lambda t: plane.move_to([0.0, 0.01 * t]), load_steps=3,
                          output=output,
                          on_step=lambda step: seen.append(contact.results.contact_force()[1]))
    assert [s.load_factor for s in result.steps] == pytest.approx([1 / 3, 2 / 3, 1.0])
    p = [uniform_pressure(0.01 * t, 1e3) for t in (1 / 3, 2 / 3, 1.0)]
    assert seen == pytest.approx(p, rel=1e-8)
    assert not PETSc.Options().hasName("open_path_snes_max_it")
    domain.comm.barrier()
    if domain.comm.rank == 0:   # read back what was written: every step, the right pressure
        times, written = read_xdmf_series(output).field("contact_pressure")
        assert times == pytest.approx([1 / 3, 2 / 3, 1.0])
        assert written[:, :, 0].max(axis=1) == pytest.approx(p, rel=1e-8)
        times, p_hat = read_xdmf_series(output.with_name("path_slave.xdmf")).field("p_hat")
        assert p_hat[-1].max() == pytest.approx(p[-1], rel=1e-8)
    # an option no solver reads is named, not ignored
    misspelled = LoadPathSolver(problem, petsc_options={"snes_max_itt": 7}, prefix="open_bad_")
    with pytest.raises(ValueError, match="snes_max_itt"):
        misspelled.solve(lambda t: plane.move_to([0.0, 0.01]), load_steps=1)
    # and a limit that cannot be met fails with the history
    strict = LoadPathSolver(problem, petsc_options={"snes_max_it": 0}, prefix="open_zero_")
    u.x.array[:] = 0.0
    with pytest.raises(ContactDivergenceError):
        strict.solve(lambda t: plane.move_to([0.0, 0.02 * t]), load_steps=1, max_cuts=1)


@pytest.mark.parametrize("configuration", ["initial", "previous"])
def test_initial_configuration_warns_past_an_element_of_slip(configuration):
    """Two blocks, the upper one slid by about three element lengths: the frozen
    "initial" segmentation is warned about, the rebuilt "previous" one is not."""
    demo = load_demo("patch_test")
    domain, tags = demo.build_mesh(2, 0.09, 0.14, 1, MPI.COMM_WORLD)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, E=1.0,
                             nu=0.3, kind="LcLS*", penalty=1e3,
                             basis_configuration=configuration,
                             fixed={demo.BOTTOM: {0: 0.0, 1: 0.0},
                                    demo.TOP: {0: 0.3, 1: -0.002}})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        problem.solve(load_steps=3)
    slipped = [w for w in caught if "slipped" in str(w.message)]
    assert len(slipped) == (1 if configuration == "initial" else 0)
    assert problem.contact.results.slip() > (1.0 if configuration == "initial" else -1.0)


def test_contact_term_refuses_bad_input():
    domain, tags, V = block(n=(4, 2))
    u = fem.Function(V)
    with pytest.raises(TypeError, match="Function"):
        ContactTerm(V, tags, BOTTOM, obstacle=RigidPlane([0, 0], [0, 1]), penalty=1.0)
    with pytest.raises(ValueError, match="penalty"):
        ContactTerm(u, tags, BOTTOM, obstacle=RigidPlane([0, 0], [0, 1]), penalty=-1.0)
    with pytest.raises(ValueError, match="exactly one"):
        ContactTerm(u, tags, BOTTOM, penalty=1.0)
    with pytest.raises(ValueError, match="marks no facets"):
        ContactTerm(u, tags, 99, obstacle=RigidPlane([0, 0], [0, 1]), penalty=1.0)
    with pytest.raises(ValueError, match="displacement"):
        RigidPlane([0, 0], [0, 1]).move_to([0.0, np.nan])
    contact = ContactTerm(u, tags, BOTTOM, obstacle=RigidPlane([0, 0], [0, 1]), penalty=1.0)
    other = fem.Function(V)
    with pytest.raises(ValueError, match="problem's u"):
        NonlinearContactProblem(linear_elastic_residual(other, E, NU), other, contact)
    with pytest.raises(ValueError, match="without '-'"):
        LoadPathSolver(NonlinearContactProblem(linear_elastic_residual(u, E, NU), u, contact),
                       petsc_options={"-snes_max_it": 3}).solve(lambda t: None)


@pytest.mark.parametrize("predictor", ["none", "linear"])
def test_linear_predictor_starts_a_linear_path_at_its_solution(predictor):
    """On a path whose solution is linear in t (the plane moved up at a constant
    rate, the contact already closed), the linear predictor lands on the
    solution of every step after the second: Newton has nothing left to do."""
    problem, plane = block_under_a_moving_plane()
    contact = problem.contacts[0]
    forces = []
    result = LoadPathSolver(problem).solve(
        lambda t: plane.move_to([0.0, 0.01 * (1 + t)]), load_steps=5, predictor=predictor,
        on_step=lambda step: forces.append(contact.results.contact_force()[1]))
    assert forces == pytest.approx([uniform_pressure(0.01 * (1 + t), 1e3)
                                    for t in (0.2, 0.4, 0.6, 0.8, 1.0)], rel=1e-8)
    iterations = [step.newton_iterations for step in result.steps]
    if predictor == "linear":
        assert iterations[2:] == [0, 0, 0]
    else:
        assert min(iterations[2:]) >= 1
    for step in result.steps:
        # a linear problem (the active set does not change): one Newton step
        # from the step's start reaches round-off
        assert step.reference > 0 and step.terminal_iterations() == 0
    with pytest.raises(ValueError, match="predictor"):
        LoadPathSolver(problem).solve(lambda t: None, predictor="quadratic")


def resident_megabytes() -> float:
    """This process's resident memory (Linux), MB."""
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


@pytest.mark.parametrize("configuration", ["initial", "current"])
def test_repeated_evaluations_do_not_pile_up_petsc_objects(configuration):
    """petsc4py defers the destruction of a parallel PETSc object whose handle
    dies to a collective garbage_cleanup, which nothing else calls. Without
    one per evaluation, every residual and Jacobian left its matrices and
    vectors behind: ironing 3D grew to 5 GB at 2k dofs on PETSc 3.18, and this
    block grew by 0.5 MB per evaluation on 2 ranks of PETSc 3.22 (50 MB in 100)."""
    domain, tags, V = block()
    u = fem.Function(V)
    plane = RigidPlane([0.0, 0.0], [0.0, 1.0])
    contact = ContactTerm(u, tags, BOTTOM, obstacle=plane, kind="LmLS*", penalty=1e3,
                          basis_configuration=configuration)
    bcs = [dirichlet(V, tags, LEFT, 0, 0.0), dirichlet(V, tags, TOP, 1, 0.0)]
    problem = NonlinearContactProblem(linear_elastic_residual(u, E, NU), u, contact, bcs)
    u.interpolate(lambda x: np.vstack([0.0 * x[0], -0.01 + 0.002 * x[0]]))
    x, A, b = u.x.petsc_vec.copy(), problem.matrix(), problem.vector().duplicate()

    def evaluate() -> None:
        problem.F(x, b)
        problem.J(x, A)

    for _ in range(5):          # warm-up: caches, first allocations
        evaluate()
    before = resident_megabytes()
    for _ in range(60):
        evaluate()
    growth = domain.comm.allreduce(resident_megabytes() - before, op=MPI.MAX)
    assert growth < 5.0, f"{growth:.1f} MB more after 60 evaluations"
