"""Central differences of a problem's residual against its Jacobian (public API only:
``problem.problem`` is the NonlinearContactProblem of a ContactProblem)."""
from __future__ import annotations

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.surfaces.facet_surface import nodal_displacement


def random_direction(problem, rng_seed: int):
    """A random vector of the problem's space, zero on its Dirichlet dofs
    (each rank draws its own part)."""
    v = problem.u.x.petsc_vec.duplicate()
    v.array[:] = np.random.default_rng(rng_seed + MPI.COMM_WORLD.rank).normal(
        size=v.array.shape)
    fem.petsc.set_bc(v, problem.bcs, alpha=0.0)
    return v


def has_gaps_of_both_signs(problem) -> bool:
    """Some slave node penetrates and some is apart (on any rank): the active
    set ends inside the surface, where a derivative check is worth most."""
    gaps = problem.nodal_gaps()
    n = problem.slave.layout.num_owned
    comm = problem.mesh.comm
    return (comm.allreduce(int(np.sum(gaps[:n] > 0))) > 0
            and comm.allreduce(int(np.sum(gaps[:n] < 0))) > 0)


def jacobian_error(problem, rng_seed: int = 1) -> float:
    """‖(R(x + h dx) − R(x − h dx))/2h − J dx‖ / ‖J dx‖ at the current u."""
    x0 = problem.u.x.petsc_vec.copy()
    J = problem.problem.matrix()
    b0 = problem.problem.vector().duplicate()
    problem.problem.F(x0, b0)
    problem.problem.J(x0, J)
    # basis_configuration="current" gives the exact Jacobian once the active
    # set is the one of the previous call
    problem.problem.J(x0, J)
    dx = random_direction(problem, rng_seed)
    Jdx = b0.duplicate()
    J.mult(dx, Jdx)
    fd = residual_difference(problem, x0, dx)
    fd.axpy(-1.0, Jdx)
    return fd.norm() / Jdx.norm()


def newton_step_error(problem, rng_seed: int = 2, size: float = 1e-6) -> float:
    """‖R'(x)Δu − r‖/‖r‖ for the Newton step Δu the problem's own linear solve
    gives for a random r (the augmented system of the GLS kinds), R' by
    central differences, at the current u."""
    x0 = problem.u.x.petsc_vec.copy()
    b0 = problem.problem.vector().duplicate()
    problem.problem.F(x0, b0)
    J = problem.problem.matrix()
    problem.problem.J(x0, J)
    r = random_direction(problem, rng_seed)
    du = r.duplicate()
    ksp = PETSc.KSP().create(problem.mesh.comm)
    ksp.setOperators(J)
    for term in problem.problem.contacts:    # the exact step of the augmented system
        term.configure_ksp(ksp)
    ksp.solve(r, du)
    ksp.destroy()
    fd = residual_difference(problem, x0, du, size)
    fd.axpy(-1.0, r)
    return fd.norm() / r.norm()


def residual_difference(problem, x0, direction, size: float = 1e-6):
    """(R(x0 + h v) − R(x0 − h v)) / 2h with ‖h v‖ = size: R′(x0)·v."""
    h = size / direction.norm()
    residuals = []
    for sign in (1, -1):
        x = x0.copy()
        x.axpy(sign * h, direction)
        b = problem.problem.vector().duplicate()
        problem.problem.F(x, b)
        residuals.append(b)
    # the residual left u at x0 − h v: back to x0 for whatever the caller does next
    x0.copy(problem.u.x.petsc_vec)
    problem.u.x.scatter_forward()
    fd = residuals[0].copy()
    fd.axpy(-1.0, residuals[1])
    fd.scale(1 / (2 * h))
    return fd


def newton_history(start, problem, prefix: str) -> np.ndarray:
    """Residual norms of ``problem``'s Newton solve at full load, started from
    the solution of ``start`` (a problem on the same function space)."""
    problem.set_load(1.0)
    start.u.x.petsc_vec.copy(problem.u.x.petsc_vec)
    problem.u.x.scatter_forward()
    problem.solver.prefix = prefix
    with problem.solver.options():
        snes = problem.solver.create_snes()
        x = problem.u.x.petsc_vec.copy()
        snes.setConvergenceHistory(reset=True)
        snes.solve(None, x)
        r = np.array(snes.getConvergenceHistory()[0])
        snes.destroy()
    return r


def convergence_order(r: np.ndarray) -> float:
    """log e_k / log e_(k−1), e = r/r_0, at the last iterate that made progress
    above round-off (2 for quadratic convergence)."""
    e = r / r[0]
    k = np.flatnonzero((e[1:] < 0.5 * e[:-1]) & (e[1:] > 1e-11))[-1] + 1
    return float(np.log(e[k]) / np.log(e[k - 1])) if k >= 2 else 0.0


def energy_gradient_error(problem) -> float:
    """|Π(u + h v) − Π(u − h v)|/2h against R_c·v: the residual is ∂Π/∂u."""
    model = problem.gap_model
    x0 = problem.u.x.petsc_vec.copy()
    Rc = problem.contact.update(problem.bcs).residual
    v = x0.duplicate()
    v.array[:] = np.random.default_rng(5 + MPI.COMM_WORLD.rank).normal(size=v.array.shape)
    fem.petsc.set_bc(v, problem.bcs, alpha=0.0)
    h = 1e-6 / v.norm()
    energies = []
    for sign in (1, -1):
        x0.copy(problem.u.x.petsc_vec)
        problem.u.x.petsc_vec.axpy(sign * h, v)
        problem.u.x.scatter_forward()
        energies.append(model.energy(nodal_displacement(problem.slave, problem.u)))
    x0.copy(problem.u.x.petsc_vec)
    problem.u.x.scatter_forward()
    exact = Rc.dot(v)
    return abs((energies[0] - energies[1]) / (2 * h) - exact) / abs(exact)
