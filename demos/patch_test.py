"""Contact patch test: two non-matching blocks under a uniform pressure.

The lower block [0,1]^d−1 × [−½, 0] and the upper block [0,1]^d−1 × [0, ½] are
meshed independently in one gmsh model (so their nodes do not match at the
interface) and pressed together by a uniform traction p on the top. Symmetry
planes x = 0 (and y = 0 in 3D) carry u_x = 0 (u_y = 0), the bottom u_z = 0 (u_y
in 2D). The exact solution is a uniform stress σ = −p; a mortar method passes
the test when every contact node carries exactly p.

    python3 demos/patch_test.py --dim 2 --json results/patch_test_2d.json
"""
from __future__ import annotations

import argparse
from typing import Optional, Sequence

import numpy as np
from mpi4py import MPI

from demo_support.cli import parse_args_and_petsc_options, solver_demo_parser
from dolfinx_mortar.io.output import write_json

LOWER_TOP, UPPER_BOTTOM, TOP, BOTTOM, SYM_X, SYM_Y = 1, 2, 3, 4, 5, 6
ALL_KINDS = ("GLS", "GLS*", "LmLS", "LmLS*", "LcLS*", "LcLS")


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = solver_demo_parser(__doc__)
    parser.add_argument("--dim", type=int, default=2, choices=(2, 3))
    parser.add_argument("--degree", type=int, default=1, choices=(1, 2))
    parser.add_argument("--fine", type=float, default=0.09, help="finer element size (0.09)")
    parser.add_argument("--coarse", type=float, default=0.14, help="coarser size (0.14)")
    parser.add_argument("--orientation", default="both",
                        choices=("finer-slave", "finer-master", "both"))
    parser.add_argument("--kinds", nargs="+", default=list(ALL_KINDS))
    parser.add_argument("--scalings", nargs="+", default=["consistent", "seed"])
    parser.add_argument("--active-set", default="nodal", choices=("nodal", "pointwise"),
                        help="penalty on the nodal gaps (nodal) or on ⟨d⟩ (pointwise)")
    parser.add_argument("--basis-configuration", default="initial",
                        choices=("initial", "previous", "current"),
                        help="configuration of the bases and the segmentation (initial)")
    parser.add_argument("--pressure", type=float, default=0.01, help="applied pressure (0.01)")
    parser.add_argument("--penalty", type=float, default=1e3,
                        help="ε as a multiple of E / fine size (1e3)")
    parser.add_argument("--json", default=None, help="write the results as JSON here")
    return parse_args_and_petsc_options(parser, argv)


def build_mesh(dim: int, h_lower: float, h_upper: float, degree: int, comm: MPI.Comm):
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            if dim == 2:
                lower = occ.addRectangle(0, -0.5, 0, 1, 0.5)
                upper = occ.addRectangle(0, 0, 0, 1, 0.5)
            else:
                lower = occ.addBox(0, 0, -0.5, 1, 1, 0.5)
                upper = occ.addBox(0, 0, 0, 1, 1, 0.5)
            occ.synchronize()
            fdim, up = dim - 1, dim - 1  # facet dimension, vertical axis
            tags: dict = {k: [] for k in (LOWER_TOP, UPPER_BOTTOM, TOP, BOTTOM, SYM_X, SYM_Y)}
            for body, h in ((lower, h_lower), (upper, h_upper)):
                for _, f in gmsh.model.getBoundary([(dim, body)], oriented=False):
                    c = occ.getCenterOfMass(fdim, f)
                    if abs(c[0]) < 1e-9:
                        tags[SYM_X].append(f)
                    elif dim == 3 and abs(c[1]) < 1e-9:
                        tags[SYM_Y].append(f)
                    elif abs(c[up] - 0.5) < 1e-9:
                        tags[TOP].append(f)
                    elif abs(c[up] + 0.5) < 1e-9:
                        tags[BOTTOM].append(f)
                    elif abs(c[up]) < 1e-9:
                        tags[LOWER_TOP if body == lower else UPPER_BOTTOM].append(f)
                points = gmsh.model.getBoundary([(dim, body)], recursive=True)
                gmsh.model.mesh.setSize(points, h)
            for tag, entities in tags.items():
                if entities:
                    gmsh.model.addPhysicalGroup(fdim, entities, tag)
            gmsh.model.addPhysicalGroup(dim, [lower], 11)
            gmsh.model.addPhysicalGroup(dim, [upper], 12)
            gmsh.model.mesh.generate(dim)
            if degree == 2:
                gmsh.model.mesh.setOrder(2)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=dim)
    finally:
        gmsh.finalize()
    return domain, facet_tags


def run(args, orientation: str, kind: str, scaling: str, comm=MPI.COMM_WORLD) -> dict:
    from dolfinx import fem
    from dolfinx_mortar import ContactProblem
    fine, coarse = args.fine, args.coarse
    # the slave is the lower block's top
    h_lower, h_upper = (fine, coarse) if orientation == "finer-slave" else (coarse, fine)
    domain, facet_tags = build_mesh(args.dim, h_lower, h_upper, args.degree, comm)
    V = fem.functionspace(domain, ("Lagrange", args.degree, (domain.geometry.dim,)))
    d = args.dim
    fixed = {SYM_X: {0: 0.0}, BOTTOM: {d - 1: 0.0}}
    if d == 3:
        fixed[SYM_Y] = {1: 0.0}
    traction = [0.0] * (d - 1) + [-args.pressure]
    problem = ContactProblem(V, facet_tags, LOWER_TOP, master_tag=UPPER_BOTTOM, E=args.E,
                             nu=args.nu, kind=kind, scaling=scaling,
                             penalty=args.penalty * args.E / fine, fixed=fixed,
                             active_set=args.active_set,
                             basis_configuration=args.basis_configuration,
                             tractions={TOP: traction},
                             quadratic_transform=(args.degree == 2 and d == 3))
    result = problem.solve(load_steps=1)
    state = problem.contact.evaluate()
    n = problem.slave.layout.num_owned
    values = problem.surface_pressure(state, gather=True).p
    # the uniform pressure that carries the applied force over the slave surface
    # the bases live on (the unit face, or in the current configuration the
    # face stretched sideways by the Poisson effect)
    area = comm.allreduce(float(np.sum(state.lumped_weights[:n])))
    deviation = float(np.max(np.abs(values * area / args.pressure - 1.0)))
    return {"dim": d, "degree": args.degree, "orientation": orientation, "kind": kind,
            "scaling": scaling, "max_relative_deviation": deviation,
            "newton_iterations": result.newton_iterations, "slave_nodes": int(len(values))}


def main(argv: Optional[Sequence[str]] = None) -> list:
    args = parse_args(argv)
    orientations = (["finer-slave", "finer-master"] if args.orientation == "both"
                    else [args.orientation])
    rows = [run(args, o, k, s) for o in orientations for s in args.scalings for k in args.kinds]
    if MPI.COMM_WORLD.rank == 0:
        print(f"Patch test {args.dim}D, P{args.degree}: max |p_A / p − 1| over the contact nodes")
        print(f"{'orientation':>13s} {'scaling':>11s} " + " ".join(f"{k:>9s}" for k in args.kinds))
        for o in orientations:
            for s in args.scalings:
                row = {r["kind"]: r["max_relative_deviation"] for r in rows
                       if r["orientation"] == o and r["scaling"] == s}
                print(f"{o:>13s} {s:>11s} " + " ".join(f"{row[k]:9.1e}" for k in args.kinds))
        if args.json:
            write_json(args.json, rows)
    return rows


if __name__ == "__main__":
    main()
