"""Hertz 2D: an elastic cylinder (plane strain) pressed onto a rigid plane or an elastic block.

A quarter of the cylinder (radius R, centre (0, R); symmetry u_x = 0 at x = 0)
carries the line load F (per unit thickness) as a uniform traction F/(2R) on its
diametral edge y = R. The rigid plane y = 0 is analytic, not meshed; with
``--obstacle elastic`` the cylinder presses onto an elastic block
[0, 2R] × [−2R, 0] of the same material in the same mesh (fixed at its bottom).
The mesh (gmsh) is graded towards the contact with size a/n_c at the contact,
a the Hertz half-width and n_c = 40·refine.

Hertz (plane strain): E* = E/(1−ν²) (rigid plane) or E/(2(1−ν²)) (two equal
bodies), a = sqrt(4FR/(πE*)), p0 = 2F/(πa), p(x) = p0 sqrt(1 − x²/a²).

    python3 demos/hertz2d.py --json results/hertz2d.json
"""
from __future__ import annotations

import argparse
import time
from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI

from demo_support.cli import (add_contact_options, parse_args_and_petsc_options,
                                solver_demo_parser)
from demo_support.hertz_meshes import (FIXED, LOAD, MASTER, SLAVE, SYMMETRY,
                                                      quarter_disk_mesh)
from demo_support.hertz_fit import fit_hertz_profile
from dolfinx_mortar.io.output import write_json


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = solver_demo_parser(__doc__)
    parser.add_argument("--radius", type=float, default=1.0, help="cylinder radius R (1)")
    parser.add_argument("--force", type=float, default=0.01,
                        help="line load F per unit thickness (0.01: a ≈ 0.11 R)")
    parser.add_argument("--refine", type=float, default=1.0,
                        help="mesh density factor: contact size a/(40·refine) (1)")
    parser.add_argument("--degree", type=int, default=1, choices=(1, 2),
                        help="displacement degree (1)")
    parser.add_argument("--kind", default="LcLS*", help="mortar basis kind (LcLS*)")
    parser.add_argument("--scaling", default="consistent", choices=("consistent", "seed"))
    add_contact_options(parser)
    parser.add_argument("--penalty", type=float, default=1e3,
                        help="penalty ε as a multiple of E/h_contact (1e3)")
    parser.add_argument("--obstacle", default="rigid", choices=("rigid", "elastic"))
    parser.add_argument("--load-steps", type=int, default=4, help="load steps (4)")
    parser.add_argument("--output", default=None, help="XDMF file for the steps")
    parser.add_argument("--json", default=None, help="write the key figures as JSON here")
    return parse_args_and_petsc_options(parser, argv)


def hertz(args) -> dict:
    E_star = args.E / (1 - args.nu ** 2)
    if args.obstacle == "elastic":
        E_star /= 2
    a = np.sqrt(4 * args.force * args.radius / (np.pi * E_star))
    return {"E_star": E_star, "a": a, "p0": 2 * args.force / (np.pi * a)}


def build_mesh(args, a: float, comm: MPI.Comm):
    """Quarter disk (and block), graded towards the contact point (0, 0)."""
    h_contact = a / (40 * args.refine)
    lower = "block" if args.obstacle == "elastic" else "none"
    domain, facet_tags = quarter_disk_mesh(args.radius, a, h_contact, lower, args.degree, comm)
    return domain, facet_tags, h_contact


def contact_results(problem, ref: dict) -> dict:
    """Peak pressure and half-width (the Hertz profile fitted to the nodal
    pressures, :func:`~demo_support.hertz_fit.fit_hertz_profile`)
    and the L2 error."""
    comm = problem.mesh.comm
    slave = problem.slave
    p = problem.nodal_pressures()
    surface = problem.surface_pressure(gather=True)
    xs, ps = surface.x[:, 0], surface.p
    fit = fit_hertz_profile(xs, ps, ref["a"])
    p0, a_fit = fit.p0, fit.a
    # L2 error of p̂ = Σ N_A p_A over [0, a_Hertz] on the slave quadrature points
    tab = slave.tabulate(6, transformed=False)
    p_hat = np.einsum("cqb,cb->cq", tab.phi, p[slave.cells])
    xq = tab.points[..., 0]
    exact = ref["p0"] * np.sqrt(np.maximum(0.0, 1 - (xq / ref["a"]) ** 2))
    near = (xq < 1.5 * ref["a"]) & (tab.points[..., 1] < 0.5 * problem_radius(problem))
    err2 = comm.allreduce(float(np.sum((tab.weights * (p_hat - exact) ** 2)[near])))
    ref2 = comm.allreduce(float(np.sum((tab.weights * exact ** 2)[near])))
    total = problem.normal_force()
    return {"p0": p0, "a": a_fit, "p_max": fit.p_max,
            "a_last_active_node": float(np.max(xs[ps > 0])),
            "l2_error": float(np.sqrt(err2 / ref2)), "contact_force": total,
            "active_nodes": int(np.count_nonzero(ps > 0))}


def problem_radius(problem) -> float:
    return float(problem.mesh.comm.allreduce(np.max(problem.mesh.geometry.x[:, 1]),
                                             op=MPI.MAX))


def build_problem(args: argparse.Namespace, comm: MPI.Comm):
    """The mesh and the contact problem of the scene (not solved yet).

    Returns the problem, the Hertz reference (:func:`hertz`) and the contact
    element size.
    """
    from dolfinx import fem
    from dolfinx_mortar.contact.obstacles import RigidPlane
    from dolfinx_mortar import ContactProblem
    ref = hertz(args)
    domain, facet_tags, h_contact = build_mesh(args, ref["a"], comm)
    V = fem.functionspace(domain, ("Lagrange", args.degree, (domain.geometry.dim,)))
    fixed = {SYMMETRY: {0: 0.0}}
    kwargs = {}
    if args.obstacle == "rigid":
        kwargs["obstacle"] = RigidPlane([0.0, 0.0], [0.0, 1.0])
    else:
        kwargs["master_tag"] = MASTER
        fixed[FIXED] = {0: 0.0, 1: 0.0}
    problem = ContactProblem(V, facet_tags, SLAVE, E=args.E, nu=args.nu, kind=args.kind,
                             penalty=args.penalty * args.E / h_contact, scaling=args.scaling,
                             active_set=args.active_set,
                             basis_configuration=args.basis_configuration,
                             boundary_modification=args.boundary_modification,
                             linear_solver=args.linear_solver,
                             fixed=fixed,
                             tractions={LOAD: [0.0, -args.force / (2 * args.radius)]},
                             **kwargs)
    return problem, ref, h_contact


def key_figures(args: argparse.Namespace, problem, result, ref: dict, h_contact: float,
                wall: float) -> dict:
    """Errors against Hertz and the run's size and cost, on every rank."""
    comm = problem.mesh.comm
    V = problem.V
    figures = contact_results(problem, ref)
    dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    figures.update({
        "hertz_p0": ref["p0"], "hertz_a": ref["a"],
        "p0_error": figures["p0"] / ref["p0"] - 1, "a_error": figures["a"] / ref["a"] - 1,
        "force_error": figures["contact_force"] / (args.force / 2) - 1,
        "dofs": int(dofs), "newton_iterations": result.newton_iterations,
        "load_steps": len(result.steps), "wall_time": wall, "h_contact": h_contact,
        "kind": args.kind, "scaling": args.scaling, "obstacle": args.obstacle,
        "active_set": args.active_set,
        "basis_configuration": args.basis_configuration,
        "degree": args.degree, "refine": args.refine, "ranks": comm.size,
    })
    return figures


def main(argv: Optional[Sequence[str]] = None) -> dict:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    clock = time.perf_counter()
    problem, ref, h_contact = build_problem(args, comm)
    result = problem.solve(load_steps=args.load_steps, output=args.output,
                           progress=comm.rank == 0)
    wall = time.perf_counter() - clock
    figures = key_figures(args, problem, result, ref, h_contact, wall)
    dofs = figures["dofs"]
    if comm.rank == 0:
        print(f"Hertz 2D ({args.obstacle} obstacle, {args.kind}, P{args.degree}, "
              f"{dofs} dofs, {comm.size} rank(s))")
        print(f"  peak pressure p0 = {figures['p0']:.6g}  (Hertz {ref['p0']:.6g}, "
              f"error {100 * figures['p0_error']:+.3f}%)")
        print(f"  half-width a     = {figures['a']:.6g}  (Hertz {ref['a']:.6g}, "
              f"error {100 * figures['a_error']:+.3f}%)")
        print(f"  L2 error of the pressure over the contact zone: "
              f"{100 * figures['l2_error']:.3f}%")
        print(f"  contact force / applied: {1 + figures['force_error']:.8f}")
        print(f"  Newton iterations {result.newton_iterations} in {len(result.steps)} steps, "
              f"wall time {wall:.2f} s")
    if args.json and comm.rank == 0:
        write_json(args.json, figures)
    return figures


if __name__ == "__main__":
    main()
