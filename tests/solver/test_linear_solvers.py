"""The linear solvers of a Newton step: the iterative path (Krylov, multigrid,
exact contact block) gives the direct path's solution, stays robust in the
penalty, and the rigid-body modes are exact null vectors of the bulk."""
import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.small_strain.elastic import linear_elastic_residual
from dolfinx_mortar.linalg.linear_solver import ITERATIVE_FROM_DOFS, choose_linear_solver
from dolfinx_mortar.linalg.near_nullspace import body_labels, rigid_body_modes
from support import POINTWISE_WITH_A_DUAL_KIND, load_demo
from support.scenes import pressed_block


def test_auto_goes_iterative_for_large_3d_problems_only():
    assert choose_linear_solver("auto", ITERATIVE_FROM_DOFS, 3, False) == "iterative"
    assert choose_linear_solver("auto", ITERATIVE_FROM_DOFS - 1, 3, False) == "direct"
    assert choose_linear_solver("auto", 10 * ITERATIVE_FROM_DOFS, 2, False) == "direct"
    assert choose_linear_solver("auto", 10 * ITERATIVE_FROM_DOFS, 3, True) == "direct"
    assert choose_linear_solver("iterative", 10, 2, False) == "iterative"
    with pytest.raises(ValueError, match="linear_solver must be one of"):
        choose_linear_solver("krylov", 10, 2, False)
    with pytest.raises(NotImplementedError, match="GLS kinds"):
        choose_linear_solver("iterative", 10, 2, True)


def _two_cubes(comm):
    """Two unit cubes side by side, not touching: two bodies of one mesh."""
    domain = mesh.create_box(comm, [[0, 0, 0], [2.5, 1, 1]], [5, 2, 2])
    keep = mesh.locate_entities(domain, 3, lambda x: np.abs(x[0] - 1.25) > 0.5 - 1e-9)
    domain.topology.create_connectivity(3, 0)
    sub, _, _, _ = mesh.create_submesh(domain, 3, keep)
    return sub


@pytest.mark.parametrize("gdim", [2, 3])
def test_rigid_body_modes_are_null_vectors_of_the_bulk(gdim):
    comm = MPI.COMM_WORLD
    if gdim == 3:
        domain = _two_cubes(comm)
    else:
        domain = mesh.create_rectangle(comm, [[0, 0], [2.5, 1]], [10, 4])
        keep = mesh.locate_entities(domain, 2, lambda x: np.abs(x[0] - 1.25) > 0.5 - 1e-9)
        domain, _, _, _ = mesh.create_submesh(domain, 2, keep)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    labels = body_labels(V)
    bodies = np.unique(np.concatenate(comm.allgather(np.unique(labels))))
    assert len(bodies) == 2
    # the labels are the same on both copies of a shared dof block
    u = fem.Function(V)
    modes = rigid_body_modes(V).getVecs()
    assert len(modes) == 2 * (3 if gdim == 2 else 6)
    F = linear_elastic_residual(u, 1.0, 0.3)
    K = fem_petsc.assemble_matrix(fem.form(ufl.derivative(F, u, ufl.TrialFunction(V))))
    K.assemble()
    scale = K.norm(PETSc.NormType.NORM_INFINITY)
    for mode in modes:
        Km = K.createVecLeft()
        K.mult(mode, Km)
        assert Km.norm(PETSc.NormType.NORM_INFINITY) < 1e-12 * scale * mode.norm(
            PETSc.NormType.NORM_INFINITY)
    # and they are orthonormal
    gram = np.array([[a.dot(b) for b in modes] for a in modes])
    assert np.allclose(gram, np.eye(len(modes)), atol=1e-12)


def test_body_labels_agree_across_ranks():
    comm = MPI.COMM_WORLD
    cubes = _two_cubes(comm)
    V = fem.functionspace(cubes, ("Lagrange", 1, (cubes.geometry.dim,)))
    labels = body_labels(V)
    # owners and ghosts of one dof block agree on its body
    imap = V.dofmap.index_map
    vec = fem.Function(fem.functionspace(V.mesh, ("Lagrange", 1)))
    vec.x.array[:] = labels.astype(float)
    before = vec.x.array.copy()
    vec.x.scatter_forward()
    assert np.array_equal(vec.x.array, before)
    assert len(labels) == imap.size_local + imap.num_ghosts


def _hertz3d(linear_solver: str, penalty: float, options: dict,
             configuration: str = "initial", load_steps: int = 3):
    demo = load_demo("hertz3d")
    args = demo.parse_args(["--obstacle", "elastic", "--refine", "0.5", "--penalty",
                            str(penalty), "--linear-solver", linear_solver,
                            "--basis-configuration", configuration,
                            "--load-steps", str(load_steps)])
    problem, context = demo.build_problem(args, MPI.COMM_WORLD)
    db = PETSc.Options()
    for key, value in options.items():
        db["dolfinx_mortar_" + key] = value
    try:
        result = problem.solve(load_steps=args.load_steps)
    finally:
        for key in options:
            db.delValue("dolfinx_mortar_" + key)
    return problem, result


def test_iterative_path_in_the_current_configuration_matches_mumps():
    """Hertz 3D, two bodies, on the current surface. With DOLFINx 0.9/0.11 every
    Krylov solve of the current phase stopped at iteration 0 with NaN: the
    contact pairs change the matrix's pattern there, and BoomerAMG was set up
    again on the structure it had converted before. The preconditioner now
    resets its multigrid with the PC (ContactBlockPreconditioner.reset)."""
    direct, _ = _hertz3d("direct", 1e3, {}, "current", 1)
    iterative, result = _hertz3d("iterative", 1e3, {"snes_ksp_ew": "false"}, "current", 1)
    assert iterative.solver.linear_solver == "iterative"
    assert len(result.cut_backs) == 0
    for norm in (PETSc.NormType.NORM_1, PETSc.NormType.NORM_2, PETSc.NormType.NORM_INFINITY):
        assert iterative.u.x.petsc_vec.norm(norm) == pytest.approx(direct.u.x.petsc_vec.norm(norm),
                                                              rel=1e-6)


@pytest.mark.slow
def test_iterative_path_matches_mumps_and_is_robust_in_the_penalty():
    """Hertz 3D, two bodies, ε = 1e4·E/h: CG + contact block + BoomerAMG with
    a fixed Krylov tolerance gives MUMPS's displacement to the Krylov
    tolerance, in few Krylov iterations per Newton iteration (BoomerAMG alone
    needs several times more at this penalty)."""
    direct, _ = _hertz3d("direct", 1e4, {})
    iterative, result = _hertz3d("iterative", 1e4, {"snes_ksp_ew": "false"})
    assert iterative.solver.linear_solver == "iterative"
    # each build meshes and partitions anew: compare what the dof order does not change
    for norm in (PETSc.NormType.NORM_1, PETSc.NormType.NORM_2, PETSc.NormType.NORM_INFINITY):
        assert iterative.u.x.petsc_vec.norm(norm) == pytest.approx(direct.u.x.petsc_vec.norm(norm),
                                                              rel=1e-6)
    assert abs(iterative.normal_force() / direct.normal_force() - 1) < 1e-6
    per_newton = result.linear_iterations / result.newton_iterations
    assert per_newton < 40, per_newton
    _, plain = _hertz3d("iterative", 1e4, {"snes_ksp_ew": "false", "pc_type": "hypre",
                                            "pc_hypre_type": "boomeramg"})
    assert plain.linear_iterations / plain.newton_iterations > 2 * per_newton


@pytest.mark.parametrize("option", ["pc_type", "amg_pc_type"])
def test_gamg_gets_the_rigid_body_modes_of_each_body(option):
    """GAMG, asked for in place of the default multigrid or as the whole
    preconditioner, coarsens with the 3 rigid-body modes of the 2D block."""
    from dolfinx_mortar import RigidPlane
    problem = pressed_block(RigidPlane([0.0, -0.001], [0.0, 1.0]), "LcLS*",
                            linear_solver="iterative", petsc_options={option: "gamg"})
    problem.set_load(0.0)
    problem.solve(load_steps=1)
    # the Jacobian matrix of the solver's SNES
    with problem.solver.options():
        snes = problem.solver.create_snes()
        modes = snes.getJacobian()[0].getNearNullSpace().getVecs()
        snes.destroy()
    assert len(modes) == 3


@POINTWISE_WITH_A_DUAL_KIND
def test_iterative_path_in_2d_with_an_obstacle():
    """Pointwise active set (GMRES) and nodal (CG) against a rigid plane match
    their direct solutions."""
    from dolfinx_mortar import RigidPlane
    for active_set in ("nodal", "pointwise"):
        solutions = []
        for linear_solver in ("direct", "iterative"):
            problem = pressed_block(RigidPlane([0.0, -0.001], [0.0, 1.0]), "LcLS",
                                    active_set=active_set, linear_solver=linear_solver)
            problem.set_load(0.0)
            problem.solve(load_steps=2)
            solutions.append(problem.u.x.array.copy())
        ksp_type = "cg" if active_set == "nodal" else "gmres"
        assert problem.solver.default_options()["ksp_type"] == ksp_type
        scale = MPI.COMM_WORLD.allreduce(np.max(np.abs(solutions[0])), op=MPI.MAX)
        difference = MPI.COMM_WORLD.allreduce(np.max(np.abs(solutions[0] - solutions[1])),
                                              op=MPI.MAX)
        assert difference < 1e-6 * scale


def test_gls_refuses_the_iterative_path_by_name():
    from dolfinx_mortar import RigidPlane
    with pytest.raises(NotImplementedError, match="augmented"):
        pressed_block(RigidPlane([0.0, -0.001], [0.0, 1.0]), "GLS", linear_solver="iterative")


@pytest.mark.parametrize("kind", ["LmLS", "LcLS*"])
def test_iterative_path_on_two_blocks_pressed_by_a_displacement(kind):
    """Two separately meshed blocks (two bodies, 2 × 3 rigid-body modes), the
    upper one's top moved down on a face that the partition crosses under
    mpirun: the iterative path gives the exact uniform pressure, and the top
    face's reaction balances it."""
    from dolfinx_mortar import ContactProblem
    from support.meshes import rectangle
    comm = MPI.COMM_WORLD
    push, penalty, e_plane = 0.01, 7e3, 1.0 / (1 - 0.3 ** 2)
    lower, ltags = rectangle(comm, -0.5, 0.0, (7, 3), bottom=1, top=2, left=3)
    upper, utags = rectangle(comm, 0.0, 0.5, (5, 3), bottom=11, top=12, left=3)
    problem = ContactProblem.from_two_meshes(
        lower, ltags, 2, upper, utags, 11, shared_tags=[3], E=1.0, nu=0.3, kind=kind,
        penalty=penalty, fixed={3: {0: 0.0}, 1: {1: 0.0}, 12: {1: -push}},
        linear_solver="iterative", petsc_options={"snes_ksp_ew": False, "ksp_rtol": 1e-12})
    result = problem.solve(load_steps=2)
    assert result.linear_iterations > result.newton_iterations  # Krylov, not LU
    exact = e_plane * push / 1.0 / (1 + e_plane / (1.0 * penalty))
    assert problem.normal_force() == pytest.approx(exact, rel=1e-8)
    assert -problem.reaction_force(12)[1] == pytest.approx(exact, rel=1e-8)
