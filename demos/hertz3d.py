"""Hertz 3D: an elastic sphere on a rigid plane, or two elastic bodies from a gmsh file.

Built-in scene: a quarter of the lower half of a sphere (radius R, centre
(0, 0, R); symmetry u_x = 0 at x = 0 and u_y = 0 at y = 0) carries the load F
as a uniform traction F/(πR²) on its flat top z = R and touches the analytic
rigid plane z = 0 (not meshed), or with ``--obstacle elastic`` an elastic
block [0, R]² × [−R, 0] fixed at its bottom. The gmsh mesh is graded to size
a/(8·refine) at the contact, a the Hertz radius; ``--write-mesh`` saves it.

``--mesh FILE.msh`` reads a gmsh mesh instead, with the physical groups
(volumes) ``body_slave``, ``body_master`` and (surfaces) ``slave``,
``master``, ``fixed`` (u = 0), ``load``, ``sym_x`` (u_x = 0), ``sym_y``
(u_y = 0). With a ``master`` group the two bodies are in contact (same
material); without it the slave touches the rigid plane z = 0.
``--load-displacement δ`` prescribes u = (0, 0, −δ) on ``load``; otherwise
``--force F`` is applied as a uniform traction over ``load``.

Hertz: E* = E/(1−ν²) (rigid plane) or E/(2(1−ν²)) (two equal bodies),
a = (3FR/(4E*))^⅓, p0 = 3F/(2πa²). With ``--load-displacement`` the force is
the computed contact force.

    python3 demos/hertz3d.py --json results/hertz3d.json
"""
from __future__ import annotations

import argparse
import time
from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI

from demo_support.cli import (add_contact_options, parse_args_and_petsc_options,
                                solver_demo_parser)
from demo_support.hertz_fit import fit_hertz_profile
from dolfinx_mortar.io.output import write_json

NAMES = ("slave", "master", "fixed", "load", "sym_x", "sym_y")
SLAVE, MASTER, FIXED, LOAD, SYM_X, SYM_Y = range(1, 7)


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = solver_demo_parser(__doc__)
    parser.add_argument("--radius", type=float, default=1.0, help="sphere radius R (1)")
    parser.add_argument("--force", type=float, default=0.0015,
                        help="total force F on the whole sphere (0.0015: a ≈ 0.1 R)")
    parser.add_argument("--load-displacement", type=float, default=None,
                        help="prescribe u_z = −δ on 'load' instead of a force (mesh files)")
    parser.add_argument("--refine", type=float, default=1.0,
                        help="mesh density factor: contact size a/(8·refine) (1)")
    parser.add_argument("--kind", default="LcLS*", help="mortar basis kind (LcLS*)")
    add_contact_options(parser)
    parser.add_argument("--penalty", type=float, default=1e3,
                        help="penalty ε as a multiple of E/h_contact (1e3)")
    parser.add_argument("--obstacle", default="rigid", choices=("rigid", "elastic"),
                        help="built-in scene: rigid plane, or an elastic block [0,R]²×[−R,0]")
    parser.add_argument("--partitioner", default="graph", choices=("graph", "contact"),
                        help="built-in mesh on several ranks: DOLFINx's graph partition "
                             "(graph, the default) or every rank an equal share of the cells "
                             "near contact (contact; pays off when the contact work is large "
                             "next to the bulk's, docs/SCALING.md)")
    parser.add_argument("--mesh", default=None, help="gmsh .msh file with the named groups")
    parser.add_argument("--write-mesh", default=None,
                        help="also write the built-in mesh to this .msh file (for other codes)")
    parser.add_argument("--h-contact", type=float, default=None,
                        help="contact element size of --mesh (for the penalty; default: "
                             "the smallest slave facet)")
    parser.add_argument("--load-steps", type=int, default=3, help="load steps (3)")
    parser.add_argument("--output", default=None, help="XDMF file for the steps")
    parser.add_argument("--json", default=None, help="write the key figures as JSON here")
    return parse_args_and_petsc_options(parser, argv)


def hertz(E_star: float, R: float, F: float) -> dict:
    a = (3 * F * R / (4 * E_star)) ** (1 / 3)
    return {"a": a, "p0": 3 * F / (2 * np.pi * a ** 2)}


def build_octant(args, a: float, comm: MPI.Comm, path: Optional[str] = None):
    """The built-in sphere octant (and block), tagged with the names of a mesh
    file; optionally also written to ``path`` (.msh) so that other codes can
    solve the very same mesh."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import grade_towards_point, model_to_mesh
    R = args.radius
    h_contact = a / (8 * args.refine)
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            sphere = occ.addSphere(0, 0, R, R)
            box = occ.addBox(0, 0, 0, R, R, R)
            body, _ = occ.intersect([(3, sphere)], [(3, box)])
            volumes = {"body_slave": body[0][1]}
            if args.obstacle == "elastic":
                volumes["body_master"] = occ.addBox(0, 0, -R, R, R, R)
            occ.synchronize()
            groups: dict = {tag: [] for tag in range(1, 7)}
            for name, volume in volumes.items():
                for _, s in gmsh.model.getBoundary([(3, volume)], oriented=False):
                    x, y, z = occ.getCenterOfMass(2, s)
                    if abs(x) < 1e-6 * R:
                        groups[SYM_X].append(s)
                    elif abs(y) < 1e-6 * R:
                        groups[SYM_Y].append(s)
                    elif name == "body_master":
                        if abs(z) < 1e-6 * R:
                            groups[MASTER].append(s)
                        elif abs(z + R) < 1e-6 * R:
                            groups[FIXED].append(s)
                    elif abs(z - R) < 1e-6 * R:
                        groups[LOAD].append(s)
                    else:
                        groups[SLAVE].append(s)
            for tag, surfaces in groups.items():
                if surfaces:
                    gmsh.model.addPhysicalGroup(2, surfaces, tag)
                    gmsh.model.setPhysicalName(2, tag, NAMES[tag - 1])
            for i, (name, volume) in enumerate(volumes.items()):
                gmsh.model.addPhysicalGroup(3, [volume], i + 1)
                gmsh.model.setPhysicalName(3, i + 1, name)
            grade_towards_point((0, 0, 0), h_contact, R / 5, 1.3 * a, 1.3 * a + 12 * (R / 5))
            gmsh.model.mesh.generate(3)
            if path is not None:
                gmsh.write(path)
        contact = [SLAVE] + ([MASTER] if args.obstacle == "elastic" else [])
        domain, _, facet_tags = model_to_mesh(
            gmsh.model, comm, 0, gdim=3,
            balance_facets=contact if args.partitioner == "contact" else None)
    finally:
        gmsh.finalize()
    names = {name: i + 1 for i, name in enumerate(NAMES)
             if args.obstacle == "elastic" or name not in ("master", "fixed")}
    return domain, facet_tags, h_contact, names


def read_mesh(path: str, comm: MPI.Comm):
    """A gmsh file and the tag of each named physical surface group present."""
    from dolfinx_mortar.io.gmsh_io import read_gmsh
    domain, _, facet_tags, names = read_gmsh(path, comm, gdim=3)
    tags = names.get(2, {})
    unknown = set(tags) - set(NAMES) - {""}
    if unknown or "slave" not in tags:
        raise ValueError(f"{path}: physical surfaces must be named among {NAMES} and include "
                         f"'slave'; found {sorted(tags)}")
    return domain, facet_tags, tags


def contact_results(problem, E_star: float, R: float, force: float) -> dict:
    """Peak pressure and radius (the Hertz profile fitted to the nodal
    pressures, :func:`~demo_support.hertz_fit.fit_hertz_profile`)
    and the L2 error."""
    comm = problem.mesh.comm
    slave = problem.slave
    p = problem.nodal_pressures()
    surface = problem.surface_pressure(gather=True)
    rs, ps = np.linalg.norm(surface.x[:, :2], axis=1), surface.p
    ref = hertz(E_star, R, force)
    fit = fit_hertz_profile(rs, ps, ref["a"])
    p0, a_fit = fit.p0, fit.a
    # L2 error of p̂ = Σ N_A p_A over the disk r < 1.5 a on the slave quadrature points
    tab = slave.tabulate(6, transformed=False)
    p_hat = np.einsum("cqb,cb->cq", tab.phi, p[slave.cells])
    rq = np.linalg.norm(tab.points[..., :2], axis=-1)
    exact = ref["p0"] * np.sqrt(np.maximum(0.0, 1 - (rq / ref["a"]) ** 2))
    near = (rq < 1.5 * ref["a"]) & (tab.points[..., 2] < 0.5 * R)
    err2 = comm.allreduce(float(np.sum((tab.weights * (p_hat - exact) ** 2)[near])))
    ref2 = comm.allreduce(float(np.sum((tab.weights * exact ** 2)[near])))
    return {"p0": p0, "a": a_fit, "hertz_p0": ref["p0"], "hertz_a": ref["a"],
            "p0_error": p0 / ref["p0"] - 1, "a_error": a_fit / ref["a"] - 1,
            "l2_error": float(np.sqrt(err2 / ref2)), "p_max": fit.p_max,
            "active_nodes": int(np.count_nonzero(ps > 0))}


def build_problem(args: argparse.Namespace, comm: MPI.Comm):
    """The mesh and the contact problem of the scene (not solved yet).

    Returns the problem and a dict of what :func:`key_figures` needs (E*,
    contact element size, symmetry factor).
    """
    from dolfinx import fem
    import ufl
    from dolfinx_mortar.contact.obstacles import RigidPlane
    from dolfinx_mortar import ContactProblem
    E_star = args.E / (1 - args.nu ** 2)
    if args.mesh is None:
        factor = 2.0 if args.obstacle == "elastic" else 1.0  # E* halves for two bodies
        a = hertz(E_star / factor, args.radius, args.force)["a"]
        domain, facet_tags, h_contact, names = build_octant(args, a, comm, args.write_mesh)
    else:
        domain, facet_tags, names = read_mesh(args.mesh, comm)
        h_contact = args.h_contact
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    if h_contact is None:
        from dolfinx_mortar.surfaces.facet_surface import facet_surface
        s = facet_surface(V, facet_tags, names["slave"])
        local = np.min(np.ptp(s.x[s.cells], axis=1).max(axis=1), initial=np.inf)
        h_contact = comm.allreduce(float(local), op=MPI.MIN)
    fixed = {}
    for name, comps in (("sym_x", {0: 0.0}), ("sym_y", {1: 0.0}),
                        ("fixed", {0: 0.0, 1: 0.0, 2: 0.0})):
        if name in names:
            fixed[names[name]] = comps
    tractions = {}
    quarter = 4.0 if "sym_x" in names and "sym_y" in names else 1.0
    if args.load_displacement is not None:
        fixed[names["load"]] = {0: 0.0, 1: 0.0, 2: -args.load_displacement}
    else:
        ds = ufl.Measure("ds", domain=domain, subdomain_data=facet_tags)
        area = comm.allreduce(fem.assemble_scalar(fem.form(
            fem.Constant(domain, 1.0) * ds(names["load"]))))
        tractions[names["load"]] = [0.0, 0.0, -args.force / quarter / area]
    kwargs = ({"master_tag": names["master"]} if "master" in names
              else {"obstacle": RigidPlane([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])})
    if "master" in names:
        E_star /= 2
    problem = ContactProblem(V, facet_tags, names["slave"], E=args.E, nu=args.nu,
                             kind=args.kind, penalty=args.penalty * args.E / h_contact,
                             active_set=args.active_set,
                             basis_configuration=args.basis_configuration,
                             boundary_modification=args.boundary_modification,
                             linear_solver=args.linear_solver,
                             fixed=fixed, tractions=tractions, **kwargs)
    return problem, {"E_star": E_star, "h_contact": h_contact, "quarter": quarter}


def key_figures(args: argparse.Namespace, problem, result, context: dict,
                wall: float) -> dict:
    """Errors against Hertz and the run's size and cost, on every rank."""
    comm = problem.mesh.comm
    contact_force = context["quarter"] * problem.normal_force()
    force = args.force if args.load_displacement is None else contact_force
    figures = contact_results(problem, context["E_star"], args.radius, force)
    V = problem.V
    dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    figures.update({"dofs": int(dofs), "newton_iterations": result.newton_iterations,
                    "linear_iterations": result.linear_iterations,
                    "linear_solver": problem.solver.linear_solver,
                    "load_steps": len(result.steps), "wall_time": wall,
                    "h_contact": context["h_contact"], "contact_force": contact_force,
                    "force": force, "kind": args.kind, "refine": args.refine,
                    "ranks": comm.size, "mesh": args.mesh, "active_set": args.active_set,
                    "basis_configuration": args.basis_configuration})
    return figures


def run(args: argparse.Namespace, comm: MPI.Comm) -> dict:
    """Solve the scene on ``comm``; the key figures on every rank."""
    clock = time.perf_counter()
    problem, context = build_problem(args, comm)
    result = problem.solve(load_steps=args.load_steps, output=args.output,
                           progress=comm.rank == 0)
    return key_figures(args, problem, result, context, time.perf_counter() - clock)


def main(argv: Optional[Sequence[str]] = None) -> dict:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    figures = run(args, comm)
    contact_force, force, h_contact = figures["contact_force"], figures["force"], figures["h_contact"]
    dofs, wall = figures["dofs"], figures["wall_time"]
    if comm.rank == 0:
        scene = ("mesh " + args.mesh if args.mesh else "sphere on an elastic block"
                 if args.obstacle == "elastic" else "sphere on a rigid plane")
        print(f"Hertz 3D ({scene}, "
              f"{args.kind}, {dofs} dofs, {comm.size} rank(s))")
        print(f"  peak pressure p0 = {figures['p0']:.6g}  (Hertz {figures['hertz_p0']:.6g}, "
              f"error {100 * figures['p0_error']:+.2f}%)")
        print(f"  contact radius a = {figures['a']:.6g}  (Hertz {figures['hertz_a']:.6g}, "
              f"error {100 * figures['a_error']:+.2f}%)")
        print(f"  L2 error of the pressure over the contact zone: "
              f"{100 * figures['l2_error']:.2f}%")
        print(f"  contact force {contact_force:.6g} (applied {force:.6g}); h at contact "
              f"{h_contact:.3g}; Newton iterations {figures['newton_iterations']}; "
              f"wall time {wall:.1f} s")
    if args.json and comm.rank == 0:
        write_json(args.json, figures)
    return figures


if __name__ == "__main__":
    main()
