"""Two materials in one user form: subdomains of one mesh, each with its own law.

The patch-test mesh (two independently meshed blocks, non-matching at the
interface) with a different Young's modulus and Poisson's ratio in each block,
written by the user as ``Σ_i ∫_{Ω_i} σ_i(u) : ε(v) dx(i)`` on cell tags, loaded
by a traction on the top and supported on the bottom and a symmetry side. The
contact is frictionless, so each block expands sideways by its own Poisson
effect and the exact solution is piecewise linear: σ = −p e_y ⊗ e_y in both
blocks, u_x = ν(1+ν) p x / E and u_y linear in y with slope −(1−ν²) p / E in
each block, and the penalty's penetration p/ε across the interface. Linear
elements and a mortar method that passes the patch test reproduce it.
"""
from __future__ import annotations

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import (KIND_NAMES, ContactTerm, LoadPathSolver, NonlinearContactProblem,
                            reaction_force)
from support import load_demo

LOWER, UPPER = 11, 12
MATERIALS = {LOWER: (1.0, 0.3), UPPER: (5.0, 0.1)}   # (E, ν): different stiffness and Poisson


def elastic_stress(u, E: float, nu: float):
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    eps = ufl.sym(ufl.grad(u))
    return 2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(2)


def in_lower_block(domain) -> np.ndarray:
    """Which cells (owned and ghost) are the lower block's, by their midpoints:
    every cell lies wholly on one side of the interface y = 0."""
    tdim = domain.topology.dim
    index_map = domain.topology.index_map(tdim)
    cells = np.arange(index_map.size_local + index_map.num_ghosts, dtype=np.int32)
    return mesh.compute_midpoints(domain, tdim, cells)[:, 1] < 0


def exact_displacement(x: np.ndarray, lower: np.ndarray, p: float, penalty: float) -> np.ndarray:
    """The piecewise linear solution at points x (rows), in the block ``lower`` says."""
    (E_l, nu_l), (E_u, nu_u) = MATERIALS[LOWER], MATERIALS[UPPER]
    lateral = np.where(lower, nu_l * (1 + nu_l) * p / E_l, nu_u * (1 + nu_u) * p / E_u)
    slope_l, slope_u = (1 - nu_l ** 2) * p / E_l, (1 - nu_u ** 2) * p / E_u
    interface_top = -0.5 * slope_l - p / penalty   # the upper block's bottom
    uy = np.where(lower, -slope_l * (x[:, 1] + 0.5), interface_top - slope_u * x[:, 1])
    return np.column_stack([lateral * x[:, 0], uy])


@pytest.mark.parametrize("kind", KIND_NAMES)
def test_two_materials_in_one_form_reproduce_the_piecewise_linear_solution(kind):
    demo = load_demo("patch_test")
    fine = 0.09
    domain, facet_tags = demo.build_mesh(2, fine, 0.14, 1, MPI.COMM_WORLD)
    lower_cells = in_lower_block(domain)
    owned_cells = np.arange(domain.topology.index_map(2).size_local, dtype=np.int32)
    cell_tags = mesh.meshtags(domain, 2, owned_cells,
                             np.where(lower_cells[owned_cells], LOWER, UPPER).astype(np.int32))
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    dx = ufl.Measure("dx", domain=domain, subdomain_data=cell_tags)
    ds = ufl.Measure("ds", domain=domain, subdomain_data=facet_tags)
    traction = fem.Constant(domain, PETSc.ScalarType((0.0, 0.0)))
    F = sum(ufl.inner(elastic_stress(u, E, nu), ufl.sym(ufl.grad(v))) * dx(tag)
            for tag, (E, nu) in MATERIALS.items()) - ufl.dot(traction, v) * ds(demo.TOP)
    bcs = [fem.dirichletbc(PETSc.ScalarType(0.0),
                          fem.locate_dofs_topological(V.sub(c), 1, facet_tags.find(tag)), V.sub(c))
           for tag, c in ((demo.SYM_X, 0), (demo.BOTTOM, 1))]
    penalty = 1e3 / fine
    contact = ContactTerm(u, facet_tags, demo.LOWER_TOP, master_tag=demo.UPPER_BOTTOM, kind=kind,
                          penalty=penalty)
    problem = NonlinearContactProblem(F, u, contact, bcs)
    p = 0.01

    def press(t: float) -> None:
        traction.value[:] = (0.0, -p * t)

    LoadPathSolver(problem).solve(press, load_steps=1)

    pressures = contact.results.surface_pressure(gather=True).p
    assert np.max(np.abs(pressures / p - 1)) < 1e-8

    # every node of each block where the exact solution puts it
    nodes = V.tabulate_dof_coordinates()
    owned = V.dofmap.index_map.size_local
    lower = np.zeros(len(nodes), dtype=bool)
    cell_nodes = V.dofmap.list.reshape(-1, 3)
    lower[cell_nodes[lower_cells].ravel()] = True   # the blocks share no node
    exact = exact_displacement(nodes, lower, p, penalty)
    error = np.max(np.abs(u.x.array.reshape(-1, 2)[:owned] - exact[:owned]), initial=0.0)
    scale = domain.comm.allreduce(np.max(np.abs(exact[:owned]), initial=0.0), op=MPI.MAX)
    assert domain.comm.allreduce(error, op=MPI.MAX) < 1e-8 * scale

    # the load goes through: the upper block pushes the lower one (the slave)
    # down by p over the unit width, and the bottom support pushes back
    assert contact.results.contact_force()[1] == pytest.approx(-p, rel=1e-8)
    assert reaction_force(problem, facet_tags, demo.BOTTOM)[1] == pytest.approx(p, rel=1e-8)
