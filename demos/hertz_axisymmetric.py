"""Hertz in (r, z) axisymmetry: an elastic sphere on a rigid plane, on an elastic
block, or on a second sphere, solved as a 2D problem.

The meridian of the lower half of the sphere (radius R, centre (0, R); x is the
radius r, y the axis z) carries the load F as a uniform traction F/(πR²) on its
flat top z = R, the same load as ``demos/hertz3d.py``. Below it: the analytic
rigid plane z = 0 (``--obstacle rigid``, not meshed), an elastic cylinder
r ≤ 2R, −2R ≤ z ≤ 0 fixed at its bottom (``elastic``), or the mirrored
half-sphere fixed on its flat bottom z = −R (``sphere``, two equal spheres).
u_r = 0 on the axis. The bulk is axisymmetric small-strain elasticity (2πr dx)
and the contact term integrates with 2πr ds, so forces are those on the whole
body. The gmsh mesh is graded to a/(40·refine) at the contact.

Hertz: E* = E/(1−ν²) (rigid plane) or E/(2(1−ν²)) (two equal bodies), the
effective radius R (plane, block) or R/2 (two spheres), a = (3FR_eff/(4E*))^⅓,
p0 = 3F/(2πa²), p(r) = p0 √(1 − r²/a²).

    python3 demos/hertz_axisymmetric.py --json results/hertz_axisymmetric.json
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

LOWER_BODY = {"rigid": "none", "elastic": "block", "sphere": "disk"}


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = solver_demo_parser(__doc__)
    parser.add_argument("--radius", type=float, default=1.0, help="sphere radius R (1)")
    parser.add_argument("--force", type=float, default=0.0015,
                        help="total force F on the sphere (0.0015: a ≈ 0.1 R, as hertz3d)")
    parser.add_argument("--refine", type=float, default=1.0,
                        help="mesh density factor: contact size a/(40·refine) (1)")
    parser.add_argument("--degree", type=int, default=1, choices=(1, 2),
                        help="displacement degree (1)")
    parser.add_argument("--kind", default="LcLS*", help="mortar basis kind (LcLS*)")
    add_contact_options(parser)
    parser.add_argument("--penalty", type=float, default=1e3,
                        help="penalty ε as a multiple of E/h_contact (1e3)")
    parser.add_argument("--obstacle", default="rigid", choices=tuple(LOWER_BODY),
                        help="rigid plane, elastic block, or a second sphere (rigid)")
    parser.add_argument("--load-steps", type=int, default=3, help="load steps (3)")
    parser.add_argument("--output", default=None, help="XDMF file for the steps")
    parser.add_argument("--json", default=None, help="write the key figures as JSON here")
    return parse_args_and_petsc_options(parser, argv)


def hertz(args) -> dict:
    """Hertz's contact radius and peak pressure of the scene."""
    E_star = args.E / (1 - args.nu ** 2)
    R_eff = args.radius
    if args.obstacle != "rigid":
        E_star /= 2
    if args.obstacle == "sphere":
        R_eff /= 2
    a = (3 * args.force * R_eff / (4 * E_star)) ** (1 / 3)
    return {"E_star": E_star, "R_eff": R_eff, "a": a,
            "p0": 3 * args.force / (2 * np.pi * a ** 2)}


def contact_results(problem, ref: dict, radius: float) -> dict:
    """Peak pressure and contact radius (the Hertz profile fitted to the nodal
    pressures, :func:`~demo_support.hertz_fit.fit_hertz_profile`)
    and the L2 error of the pressure over the swept contact zone."""
    comm = problem.mesh.comm
    slave = problem.slave
    p = problem.nodal_pressures()
    surface = problem.surface_pressure(gather=True)
    rs, ps = surface.x[:, 0], surface.p
    fit = fit_hertz_profile(rs, ps, ref["a"])
    p0, a_fit = fit.p0, fit.a
    # L2 error of p̂ = Σ N_A p_A over r < 1.5 a, weighted by the swept area 2πr ds
    tab = slave.tabulate(6, transformed=False)
    p_hat = np.einsum("cqb,cb->cq", tab.phi, p[slave.cells])
    rq = tab.points[..., 0]
    exact = ref["p0"] * np.sqrt(np.maximum(0.0, 1 - (rq / ref["a"]) ** 2))
    near = (rq < 1.5 * ref["a"]) & (tab.points[..., 1] < 0.5 * radius)
    err2 = comm.allreduce(float(np.sum((tab.weights * (p_hat - exact) ** 2)[near])))
    ref2 = comm.allreduce(float(np.sum((tab.weights * exact ** 2)[near])))
    return {"p0": p0, "a": a_fit, "hertz_p0": ref["p0"], "hertz_a": ref["a"],
            "p0_error": p0 / ref["p0"] - 1, "a_error": a_fit / ref["a"] - 1,
            "l2_error": float(np.sqrt(err2 / ref2)), "p_max": fit.p_max,
            "active_nodes": int(np.count_nonzero(ps > 0))}


def build_problem(args: argparse.Namespace, comm: MPI.Comm):
    """The mesh and the axisymmetric contact problem (not solved yet); returns
    the problem, the Hertz reference and the contact element size."""
    from dolfinx import fem
    from dolfinx_mortar import ContactProblem
    from dolfinx_mortar.contact.obstacles import RigidPlane
    ref = hertz(args)
    h_contact = ref["a"] / (40 * args.refine)
    domain, facet_tags = quarter_disk_mesh(args.radius, ref["a"], h_contact,
                                           LOWER_BODY[args.obstacle], args.degree, comm)
    V = fem.functionspace(domain, ("Lagrange", args.degree, (domain.geometry.dim,)))
    fixed = {SYMMETRY: {0: 0.0}}     # u_r = 0 on the axis
    kwargs: dict = {}
    if args.obstacle == "rigid":
        kwargs["obstacle"] = RigidPlane([0.0, 0.0], [0.0, 1.0])
    else:
        kwargs["master_tag"] = MASTER
        fixed[FIXED] = {0: 0.0, 1: 0.0}
    traction = [0.0, -args.force / (np.pi * args.radius ** 2)]
    problem = ContactProblem(V, facet_tags, SLAVE, E=args.E, nu=args.nu, kind=args.kind,
                             penalty=args.penalty * args.E / h_contact,
                             active_set=args.active_set,
                             basis_configuration=args.basis_configuration,
                             boundary_modification=args.boundary_modification,
                             linear_solver=args.linear_solver,
                             fixed=fixed, tractions={LOAD: traction}, axisymmetric=True,
                             **kwargs)
    return problem, ref, h_contact


def key_figures(args: argparse.Namespace, problem, result, ref: dict, h_contact: float,
                wall: float) -> dict:
    """Errors against Hertz and the run's size and cost, on every rank (the
    keys of ``demos/hertz3d.py``)."""
    comm = problem.mesh.comm
    figures = contact_results(problem, ref, args.radius)
    V = problem.V
    dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    # the resultant on the sphere, which balances F exactly; Σ W_A p_A (the
    # "normal force") exceeds it by the tilt of the normals, 0.3% here
    contact_force = float(problem.contact_force()[1])
    figures.update({"dofs": int(dofs), "newton_iterations": result.newton_iterations,
                    "load_steps": len(result.steps), "wall_time": wall,
                    "h_contact": h_contact, "contact_force": contact_force,
                    "force": args.force, "force_error": contact_force / args.force - 1,
                    "normal_force": problem.normal_force(),
                    "kind": args.kind, "obstacle": args.obstacle, "refine": args.refine,
                    "degree": args.degree, "ranks": comm.size,
                    "active_set": args.active_set,
                    "basis_configuration": args.basis_configuration,
                    "boundary_modification": problem.contact.options.boundary_modification})
    return figures


def run(args: argparse.Namespace, comm: MPI.Comm) -> dict:
    """Solve the scene on ``comm``; the key figures on every rank."""
    clock = time.perf_counter()
    problem, ref, h_contact = build_problem(args, comm)
    result = problem.solve(load_steps=args.load_steps, output=args.output,
                           progress=comm.rank == 0)
    return key_figures(args, problem, result, ref, h_contact, time.perf_counter() - clock)


def main(argv: Optional[Sequence[str]] = None) -> dict:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    figures = run(args, comm)
    if comm.rank == 0:
        scene = {"rigid": "sphere on a rigid plane", "elastic": "sphere on an elastic block",
                 "sphere": "two spheres"}[args.obstacle]
        print(f"Hertz axisymmetric ({scene}, {args.kind}, P{args.degree}, "
              f"{figures['dofs']} dofs, {comm.size} rank(s))")
        print(f"  peak pressure p0 = {figures['p0']:.6g}  (Hertz {figures['hertz_p0']:.6g}, "
              f"error {100 * figures['p0_error']:+.3f}%)")
        print(f"  contact radius a = {figures['a']:.6g}  (Hertz {figures['hertz_a']:.6g}, "
              f"error {100 * figures['a_error']:+.3f}%)")
        print(f"  L2 error of the pressure over the contact zone: "
              f"{100 * figures['l2_error']:.3f}%")
        print(f"  contact force {figures['contact_force']:.6g} (applied {args.force:.6g}); "
              f"h at contact {figures['h_contact']:.3g}; Newton iterations "
              f"{figures['newton_iterations']}; wall time {figures['wall_time']:.2f} s")
    if args.json and comm.rank == 0:
        write_json(args.json, figures)
    return figures


if __name__ == "__main__":
    main()
