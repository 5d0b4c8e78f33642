"""Slip limit on an inclined interface: a block pushed up a slope until it slides.

A frictional patch test of the NAFEMS CGS-4 type, in plane strain. An elastic
base (3 × 1, fixed at its bottom) and an elastic block (1 × ½) on it are meshed
independently (non-matching interface) and tilted together by α, so that the
interface rises to the right at tan α. A vertical load G acts on the block's
top (a uniform traction); then the top is pushed horizontally (u_x prescribed,
growing) while G is held. The horizontal force F that the push needs is read
from the contact resultant C on the block (F = −C_x, G = C_y by its
equilibrium). When the whole interface slips, Coulomb's law gives

    F/G = (tan α + μ) / (1 − μ tan α),

exactly for the mortar forces (their tangential and normal resultants are in
the ratio μ at full slip). The demo prints F/G along the push and the
plateau against that value.

    python3 demos/slip_limit.py --tan-alpha 0.2 --mu 0.3 --json results/slip_limit.json
"""
from __future__ import annotations

import argparse
import time
from typing import Callable, Optional, Sequence

import numpy as np
from mpi4py import MPI

from demo_support.cli import parse_args_and_petsc_options, solver_demo_parser
from dolfinx_mortar.io.output import write_json

BASE_BOTTOM, MASTER, SLAVE, BLOCK_TOP = 1, 2, 3, 4


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = solver_demo_parser(__doc__)
    parser.add_argument("--tan-alpha", type=float, default=0.2,
                        help="slope of the interface, tan α (0.2)")
    parser.add_argument("--mu", type=float, default=0.3, help="friction coefficient μ (0.3)")
    parser.add_argument("--kind", default="LcLS*", help="mortar basis kind (LcLS*)")
    parser.add_argument("--basis-configuration", default="initial",
                        choices=("initial", "previous", "current"))
    parser.add_argument("--load", type=float, default=0.01,
                        help="vertical load G on the block (0.01, E = 1)")
    parser.add_argument("--push", type=float, default=0.06,
                        help="horizontal displacement of the block's top at the end (0.06)")
    parser.add_argument("--h-block", type=float, default=0.1, help="block element size (0.1)")
    parser.add_argument("--h-base", type=float, default=0.13, help="base element size (0.13)")
    parser.add_argument("--penalty", type=float, default=1e3,
                        help="penalty ε as a multiple of E/h_block (1e3)")
    parser.add_argument("--tangential-penalty", type=float, default=None,
                        help="ε_T as a multiple of E/h_block (default: the library's, ε/10)")
    parser.add_argument("--load-steps", type=int, default=4, help="steps applying G (4)")
    parser.add_argument("--push-steps", type=int, default=12, help="steps of the push (12)")
    parser.add_argument("--load-path", type=float, nargs="+", default=None,
                        help="the load factors t of the steps, increasing to 1, in place of "
                             "the equal steps of --load-steps and --push-steps (t ≤ share: "
                             "the load G; then the push); to repeat another run's path")
    parser.add_argument("--output", default=None, help="XDMF file for the steps")
    parser.add_argument("--json", default=None, help="write the key figures as JSON here")
    return parse_args_and_petsc_options(parser, argv)


def build_mesh(args: argparse.Namespace, comm: MPI.Comm):
    """The base and the block, meshed independently, tilted by α about the origin."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    alpha = float(np.arctan(args.tan_alpha))
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            base = occ.addRectangle(-1.5, -1.0, 0, 3.0, 1.0)
            block = occ.addRectangle(-0.5, 0.0, 0, 1.0, 0.5)
            occ.rotate([(2, base), (2, block)], 0, 0, 0, 0, 0, 1, alpha)
            occ.synchronize()
            rotation = np.array([[np.cos(alpha), np.sin(alpha)],
                                 [-np.sin(alpha), np.cos(alpha)]])   # back to the flat frame
            groups: dict = {BASE_BOTTOM: [], MASTER: [], SLAVE: [], BLOCK_TOP: []}
            for body, top, bottom in ((base, MASTER, BASE_BOTTOM), (block, BLOCK_TOP, SLAVE)):
                for _, curve in gmsh.model.getBoundary([(2, body)], oriented=False):
                    centre = rotation @ np.array(occ.getCenterOfMass(1, curve)[:2])
                    size = 1e-6
                    if body == base and abs(centre[1]) < size:
                        groups[top].append(curve)
                    elif body == base and abs(centre[1] + 1.0) < size:
                        groups[bottom].append(curve)
                    elif body == block and abs(centre[1]) < size:
                        groups[bottom].append(curve)
                    elif body == block and abs(centre[1] - 0.5) < size:
                        groups[top].append(curve)
            for tag, curves in groups.items():
                gmsh.model.addPhysicalGroup(1, curves, tag)
            gmsh.model.addPhysicalGroup(2, [base], 10)
            gmsh.model.addPhysicalGroup(2, [block], 11)
            for body, h in ((base, args.h_base), (block, args.h_block)):
                points = gmsh.model.getBoundary([(2, body)], recursive=True)
                gmsh.model.mesh.setSize(points, h)
            gmsh.model.mesh.generate(2)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    return domain, facet_tags


def exact_ratio(tan_alpha: float, mu: float) -> float:
    """F/G at the onset of sliding up the slope."""
    if mu * tan_alpha >= 1:
        raise ValueError(f"μ tan α = {mu * tan_alpha:.3g} ≥ 1: the block locks, it never slides")
    return (tan_alpha + mu) / (1 - mu * tan_alpha)


def load_path(args: argparse.Namespace) -> Callable[[float], float]:
    """The load factor t at the solver's pseudo-time s: t = s for equal steps;
    with ``--load-path`` t₁ < … < 1, t is linear in s between s = k/n and
    t_k, so that the solver's n equal steps land on them (and a cut-back
    between two of them halves that step)."""
    if args.load_path is None:
        return lambda s: s
    ts = np.asarray(args.load_path, dtype=float)
    if ts.ndim != 1 or ts[0] <= 0 or np.any(np.diff(ts) <= 0) or ts[-1] != 1.0:
        raise ValueError(f"--load-path must increase from above 0 to 1, got {args.load_path}")
    s_points = np.arange(len(ts) + 1) / len(ts)
    t_points = np.concatenate([[0.0], ts])
    return lambda s: float(np.interp(s, s_points, t_points))


def run(args: argparse.Namespace, comm: MPI.Comm) -> dict:
    import ufl
    from dolfinx import fem
    from petsc4py import PETSc
    from dolfinx_mortar import ContactTerm, CoulombFriction, LoadPathSolver
    from dolfinx_mortar.small_strain.elastic import linear_elastic_residual
    from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem
    ratio_exact = exact_ratio(args.tan_alpha, args.mu)
    clock = time.perf_counter()
    domain, tags = build_mesh(args, comm)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    u = fem.Function(V, name="displacement")
    penalty = args.penalty * args.E / args.h_block
    eps_t = (None if args.tangential_penalty is None
             else args.tangential_penalty * args.E / args.h_block)
    contact = ContactTerm(u, tags, SLAVE, master_tag=MASTER, kind=args.kind, penalty=penalty,
                          basis_configuration=args.basis_configuration,
                          friction=CoulombFriction(args.mu, eps_t))
    load = fem.Constant(domain, PETSc.ScalarType(0.0))
    push = fem.Constant(domain, PETSc.ScalarType(0.0))
    top_length = 1.0  # the block's width, tilted with it
    v = ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=domain, subdomain_data=tags)
    F = (linear_elastic_residual(u, args.E, args.nu)
         + load / top_length * v[1] * ds(BLOCK_TOP))
    fdim = domain.topology.dim - 1
    base_dofs = fem.locate_dofs_topological(V, fdim, tags.find(BASE_BOTTOM))
    top_dofs = fem.locate_dofs_topological(V.sub(0), fdim, tags.find(BLOCK_TOP))
    bcs = [fem.dirichletbc(np.zeros(2, dtype=PETSc.ScalarType), base_dofs, V),
           fem.dirichletbc(push, top_dofs, V.sub(0))]
    problem = NonlinearContactProblem(F, u, contact, bcs)
    solver = LoadPathSolver(problem)
    share = args.load_steps / (args.load_steps + args.push_steps)
    path = load_path(args)

    def update(s: float) -> None:
        t = path(s)
        load.value = args.load * min(t / share, 1.0)
        push.value = args.push * max(t - share, 0.0) / (1 - share)

    rows = []

    def record(step) -> None:
        C = contact.results.contact_force()
        summary = step.friction[0]
        rows.append({"t": path(step.load_factor), "push": float(push.value),
                     "F": float(-C[0]), "G": float(C[1]),
                     "ratio": float(-C[0] / C[1]) if C[1] > 0 else 0.0,
                     "stick_nodes": summary["stick_nodes"], "slip_nodes": summary["slip_nodes"],
                     "dissipation": summary["dissipation"],
                     "newton_iterations": step.newton_iterations,
                     "terminal_iterations": step.terminal_iterations()})

    steps = args.load_steps + args.push_steps if args.load_path is None else len(args.load_path)
    result = solver.solve(update, load_steps=steps,
                          output=args.output, on_step=record)
    wall = time.perf_counter() - clock
    last = rows[-1]
    if ratio_exact == 0:
        error = last["ratio"]
    else:
        error = last["ratio"] / ratio_exact - 1
    return {"slip_ratio": last["ratio"], "slip_ratio_exact": ratio_exact,
            "slip_ratio_error": error,
            "max_ratio": max(r["ratio"] for r in rows),
            "all_slip": last["stick_nodes"] == 0 and last["slip_nodes"] > 0,
            "tan_alpha": args.tan_alpha, "mu": args.mu, "kind": args.kind,
            "basis_configuration": args.basis_configuration,
            "dofs": int(V.dofmap.index_map.size_global * 2),
            "newton_iterations": result.newton_iterations, "wall_time": wall,
            "ranks": comm.size, "steps": rows}


def main(argv: Optional[Sequence[str]] = None) -> dict:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    figures = run(args, comm)
    if comm.rank == 0:
        print(f"Slip limit: tan α = {args.tan_alpha}, μ = {args.mu}, {args.kind}, "
              f"{figures['dofs']} dofs, {comm.size} rank(s)")
        print(f"{'push':>9} {'F/G':>10} {'stick':>6} {'slip':>5} {'Newton':>6}")
        for row in figures["steps"]:
            print(f"{row['push']:9.4f} {row['ratio']:10.6f} {row['stick_nodes']:6d} "
                  f"{row['slip_nodes']:5d} {row['newton_iterations']:6d}")
        print(f"  F/G at the end {figures['slip_ratio']:.8f}, (tan α + μ)/(1 − μ tan α) = "
              f"{figures['slip_ratio_exact']:.8f}, error {figures['slip_ratio_error']:.2e}; "
              f"whole interface slipping: {figures['all_slip']}")
    if args.json and comm.rank == 0:
        write_json(args.json, figures)
    return figures


if __name__ == "__main__":
    main()
