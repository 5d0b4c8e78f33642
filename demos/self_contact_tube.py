"""A tube squeezed between two rigid plates until its inner faces meet: self-contact.

Plane strain, compressible neo-Hookean (E = 1, ν = 0.3). The tube's section is the ring
r ≤ |x| ≤ R (R = 1, r = 0.4), of which the right half is meshed (gmsh), held on the cut x = 0
by symmetry. It stands on a rigid plate at y = −R; a second plate, at y = R, moves down by the
squeeze s. Three contact terms: each plate against its half of the outer surface, and one
self-contact term on the whole inner surface (``self_contact=True``: nobody says which side is
slave; docs/SELF_CONTACT.md). When the squeeze has flattened the hole, its upper and lower
faces meet and the plate force stiffens.

What the demo writes, per converged step: the squeeze, the plate force, the self-contact's
largest pressure and the length of its contact zone (on the half, x ≥ 0). ``--json`` the
figures, ``--png`` the force and the contact length against the squeeze.

    python3 demos/self_contact_tube.py --json results/tube.json --png results/tube.png
"""
from __future__ import annotations

import argparse
from typing import Optional, Sequence

import gmsh
import numpy as np
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar import ContactTerm, LoadPathSolver, NonlinearContactProblem, RigidPlane
from demo_support.boundary_tags import tag_boundary_facets
from demo_support.laws import neo_hookean_residual
from dolfinx_mortar.io.gmsh_io import model_to_mesh
from dolfinx_mortar.io.output import save_figure, write_json

R, r = 1.0, 0.4
INNER, OUTER_TOP, OUTER_BOTTOM, CUT, END = 1, 2, 3, 4, 5


def tube(comm: MPI.Comm, h: float, length: float = 0.0):
    """The right half of the ring, triangles of size h (with a ``length``: that much of the
    tube in z, tetrahedra): mesh and facet tags, found on the geometry."""
    gmsh.initialize(["", "-v", "0"])
    dim = 3 if length else 2
    try:
        if comm.rank == 0:
            geo = gmsh.model.geo
            c = geo.addPoint(0, 0, 0, h)
            p = {(s, rad): geo.addPoint(0, s * rad, 0, h) for s in (-1, 1) for rad in (r, R)}
            right = {rad: geo.addPoint(rad, 0, 0, h) for rad in (r, R)}
            outer = [geo.addCircleArc(p[-1, R], c, right[R]), geo.addCircleArc(right[R], c, p[1, R])]
            inner = [geo.addCircleArc(p[1, r], c, right[r]), geo.addCircleArc(right[r], c, p[-1, r])]
            cuts = [geo.addLine(p[1, R], p[1, r]), geo.addLine(p[-1, r], p[-1, R])]
            loop = geo.addCurveLoop([outer[0], outer[1], cuts[0], inner[0], inner[1], cuts[1]])
            section = geo.addPlaneSurface([loop])
            if length:
                layers = max(1, int(round(length / h)))
                body = [e[1] for e in geo.extrude([(2, section)], 0, 0, length, [layers])
                        if e[0] == 3]
            geo.synchronize()
            gmsh.model.addPhysicalGroup(dim, body if length else [section], 1)
            gmsh.model.mesh.generate(dim)
        mesh, _, _ = model_to_mesh(gmsh.model, comm, 0, gdim=dim)
    finally:
        gmsh.finalize()
    radius = lambda x: np.hypot(x[0], x[1])           # noqa: E731
    marks = [(INNER, lambda x: np.isclose(radius(x), r, atol=1e-3 * h)),
             (OUTER_TOP, lambda x: np.isclose(radius(x), R, atol=1e-3 * h) & (x[1] >= 0)),
             (OUTER_BOTTOM, lambda x: np.isclose(radius(x), R, atol=1e-3 * h) & (x[1] <= 0)),
             (CUT, lambda x: np.isclose(x[0], 0.0))]
    if length:
        marks.append((END, lambda x: np.isclose(x[2], 0.0)))
    return mesh, tag_boundary_facets(mesh, marks)


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, default=0.05, help="element size (0.05)")
    parser.add_argument("--squeeze", type=float, default=0.95, help="the plate's travel (0.95)")
    parser.add_argument("--steps", type=int, default=19, help="load steps (19)")
    parser.add_argument("--kind", default="LmLS*", help="mortar basis kind (LmLS*)")
    parser.add_argument("--configuration", default="previous",
                        choices=("initial", "previous", "current"),
                        help="where the bases live (previous)")
    parser.add_argument("--length", type=float, default=0.0,
                        help="0: plane strain; else a tube this long in 3D, held in z at z = 0 "
                             "(a symmetry plane) and free at its other end")
    parser.add_argument("--json", help="write the figures to this file")
    parser.add_argument("--png", help="write the figure to this file")
    return parser.parse_args(argv)


def main(argv: Optional[Sequence[str]] = None) -> dict:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    mesh, tags = tube(comm, args.h, args.length)
    dim = mesh.geometry.dim
    V = fem.functionspace(mesh, ("Lagrange", 1, (dim,)))
    u = fem.Function(V, name="u")
    E, nu = 1.0, 0.3
    F = neo_hookean_residual(u, E, nu)
    cut = fem.locate_dofs_topological(V.sub(0), dim - 1, tags.find(CUT))
    bcs = [fem.dirichletbc(0.0, cut, V.sub(0))]
    if dim == 3:
        end = fem.locate_dofs_topological(V.sub(2), 2, tags.find(END))
        bcs.append(fem.dirichletbc(0.0, end, V.sub(2)))
    penalty = 100 * E / args.h
    options = dict(kind=args.kind, penalty=penalty, basis_configuration=args.configuration)
    def plane(y: float, ny: float) -> RigidPlane:
        return RigidPlane([0.0, y, 0.0][:dim], [0.0, ny, 0.0][:dim])

    top = plane(R, -1.0)
    terms = [ContactTerm(u, tags, OUTER_TOP, obstacle=top, name="top", **options),
             ContactTerm(u, tags, OUTER_BOTTOM, obstacle=plane(-R, 1.0),
                         name="bottom", **options),
             ContactTerm(u, tags, INNER, self_contact=True, name="inner", **options)]
    problem = NonlinearContactProblem(F, u, terms, bcs)
    steps = []

    def record(step) -> None:
        inner = terms[2].results.surface_pressure(gather=True)
        touching = inner.p > 0
        # the contact zone's length on the half: the extent of the touching nodes in x
        length = float(np.ptp(inner.x[touching, 0])) if touching.sum() > 1 else 0.0
        steps.append({"squeeze": float(-top.displacement[1]),
                      "plate_force": float(terms[0].results.contact_force()[1]),
                      "self_contact_pressure": float(inner.p.max()),
                      "self_contact_nodes": int(touching.sum()),
                      "self_contact_length": length, "newton_iterations": step.newton_iterations})

    result = LoadPathSolver(problem).solve(lambda t: top.move_to([0.0, -args.squeeze * t, 0.0][:dim]),
                                           load_steps=args.steps, on_step=record)
    figures = {"steps": steps, "newton_iterations": result.newton_iterations,
               "h": args.h, "kind": args.kind, "configuration": args.configuration, "length": args.length,
               # wall times (s) over the whole path: the self-contact term's work by part,
               # and the bulk's assembly, to compare per Newton iteration
               "self_contact_timings": dict(terms[2].timings),
               "bulk_assembly_s": sum(v for k, v in problem.timings.items()
                                      if k.startswith("bulk_"))}
    if comm.rank == 0:
        work = sum(v for k, v in figures["self_contact_timings"].items() if k != "setup")
        print(f"{result.newton_iterations} Newton iterations: self-contact "
              f"{work / result.newton_iterations * 1e3:.2f} ms per iteration, bulk assembly "
              f"{figures['bulk_assembly_s'] / result.newton_iterations * 1e3:.2f} ms")
        for s in steps:
            print(f"squeeze {s['squeeze']:.3f}: plate force {s['plate_force']:.4g}, "
                  f"self-contact p_max {s['self_contact_pressure']:.3g} on "
                  f"{s['self_contact_nodes']} nodes")
        if args.json:
            write_json(args.json, figures)
        if args.png:
            import matplotlib.pyplot as plt
            fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.5))
            squeeze = [s["squeeze"] for s in steps]
            left.plot(squeeze, [s["plate_force"] for s in steps], "o-")
            left.set(xlabel="squeeze s", ylabel="plate force (half tube)")
            right.plot(squeeze, [s["self_contact_length"] for s in steps], "o-")
            right.set(xlabel="squeeze s", ylabel="inner contact zone length (half)")
            fig.tight_layout()
            save_figure(args.png, fig)
    return figures


if __name__ == "__main__":
    main()
