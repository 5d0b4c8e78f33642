"""A hollow O-ring squeezed into a rectangular groove by a flat lid: self-contact, finite
strain and four rigid walls, as a body of revolution.

The ring is a torus whose section is the annulus b ≤ |x − c| ≤ a (a = 1, b = 0.4) around
c = (r_c, a), r_c = 5: a hollow seal. An O-ring pressed evenly all round is a body of
revolution under a load of revolution, so the scene is solved in the (r, z) half-plane
(``axisymmetric=True``: the bulk's energy and every contact integral carry 2πr, and the forces
are those on the whole ring), not in 3D. Compressible neo-Hookean, E = 1, ν = 0.3 by default
(``--nu``; the linear triangles lock as ν → 0.5). The groove is analytic, not meshed: its floor
z = 0, its side walls r = r_c ∓ w/2 (w = 2.3: 0.15 of clearance on each side) and a lid,
first at z = 2a, that moves down by the squeeze s. Nothing holds the ring but contact.

Five contact terms: the ring's outer surface against each of the four walls (one tag in four
terms: each wall's gap is the analytic distance, so the surface need not be split where
nobody knows yet which wall it will touch), and one self-contact term on the hole's surface
(``self_contact=True``: nobody says which side is slave; docs/SELF_CONTACT.md). When the
squeeze has flattened the ring it bulges onto the side walls, the hole's upper and lower
faces meet, and the lid force stiffens.

What the demo writes, per converged step: the squeeze, the lid's and the floor's forces (equal
and opposite: nothing else acts in z), the side walls' radial forces (the radial traction
integrated over the whole cylindrical wall, 2πr ds: the total normal load on it), the lid's
peak pressure (what seals) and the chord of the ring's undeformed surface that touches it, and
the self-contact's peak pressure, where it peaks, its nodes and its resultant (zero: the hole's
faces push on each other). The forces converge as h falls; the hole's peak pressure does not
(it sits where the collapsed hole folds; docs/SELF_CONTACT.md has the figures at three h, and
how the steps change them at the finest). ``--json`` the figures, ``--png`` the forces
and the peak pressures against the squeeze.

    python3 demos/o_ring_groove.py --json results/o_ring.json --png results/o_ring.png
"""
from __future__ import annotations

import argparse
from typing import Optional, Sequence

import gmsh
import numpy as np
from dolfinx import fem
from mpi4py import MPI

from demo_support.boundary_tags import tag_boundary_facets
from demo_support.laws import neo_hookean_residual
from dolfinx_mortar import ContactTerm, LoadPathSolver, NonlinearContactProblem, RigidPlane
from dolfinx_mortar.io.gmsh_io import model_to_mesh
from dolfinx_mortar.io.output import save_figure, write_json

A, B, RC, WIDTH = 1.0, 0.4, 5.0, 2.3
INNER, OUTER = 1, 2


def ring_section(comm: MPI.Comm, h: float):
    """The annulus B ≤ |x − (RC, A)| ≤ A in the (r, z) half-plane, triangles of size h:
    mesh and facet tags (INNER: the hole, OUTER: the outside), found on the geometry."""
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            geo = gmsh.model.geo
            c = geo.addPoint(RC, A, 0, h)
            loops = []
            for rad in (A, B):
                p = [geo.addPoint(RC + rad * np.cos(t), A + rad * np.sin(t), 0, h)
                     for t in np.arange(4) * np.pi / 2]
                arcs = [geo.addCircleArc(p[i], c, p[(i + 1) % 4]) for i in range(4)]
                loops.append(geo.addCurveLoop(arcs))
            section = geo.addPlaneSurface(loops)
            geo.synchronize()
            gmsh.model.addPhysicalGroup(2, [section], 1)
            gmsh.model.mesh.generate(2)
        mesh, _, _ = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    distance = lambda x: np.hypot(x[0] - RC, x[1] - A)     # noqa: E731
    marks = [(INNER, lambda x: np.isclose(distance(x), B, atol=1e-3 * h)),
             (OUTER, lambda x: np.isclose(distance(x), A, atol=1e-3 * h))]
    return mesh, tag_boundary_facets(mesh, marks)


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, default=0.05, help="element size (0.05)")
    parser.add_argument("--squeeze", type=float, default=0.95, help="the lid's travel (0.95)")
    parser.add_argument("--steps", type=int, default=19, help="load steps (19)")
    parser.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio (0.3)")
    parser.add_argument("--kind", default="LmLS*", help="mortar basis kind (LmLS*)")
    parser.add_argument("--configuration", default="previous",
                        choices=("initial", "previous", "current"),
                        help="where the bases and the segmentation are built (previous)")
    parser.add_argument("--json", help="write the figures to this file")
    parser.add_argument("--png", help="write the figure to this file")
    return parser.parse_args(argv)


def touching_extent(term: ContactTerm) -> tuple[float, float, list]:
    """The largest nodal pressure of a term, the chord on the undeformed surface of
    its nodes that carry pressure, and where the largest is (reference coordinates; []
    where nothing touches). Collective."""
    surface = term.results.surface_pressure(gather=True)
    touching = surface.p > 0
    peak = surface.x[np.argmax(surface.p)].tolist() if touching.any() else []
    if touching.sum() < 2:
        return float(surface.p.max(initial=0.0)), 0.0, peak
    x = surface.x[touching]
    return float(surface.p.max()), float(np.linalg.norm(np.ptp(x, axis=0))), peak


def main(argv: Optional[Sequence[str]] = None) -> dict:
    """Squeeze the ring in ``--steps`` load steps; the figures per step (see the module)."""
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    mesh, tags = ring_section(comm, args.h)
    V = fem.functionspace(mesh, ("Lagrange", 1, (2,)))
    u = fem.Function(V, name="u")
    E = 1.0
    F = neo_hookean_residual(u, E, args.nu, axisymmetric=True)
    # 100 E/h keeps the penetration below 1% of an element here (at h = 0.05 and s = 0.95:
    # 0.3% under the lid, 0.5% in the hole)
    options = dict(kind=args.kind, penalty=100 * E / args.h, basis_configuration=args.configuration,
                   axisymmetric=True)
    lid = RigidPlane([0.0, 2 * A], [0.0, -1.0])
    walls = {"lid": lid, "floor": RigidPlane([0.0, 0.0], [0.0, 1.0]),
             "inner_wall": RigidPlane([RC - WIDTH / 2, 0.0], [1.0, 0.0]),
             "outer_wall": RigidPlane([RC + WIDTH / 2, 0.0], [-1.0, 0.0])}
    terms = {name: ContactTerm(u, tags, OUTER, obstacle=wall, name=name, **options)
             for name, wall in walls.items()}
    terms["hole"] = ContactTerm(u, tags, INNER, self_contact=True, name="hole", **options)
    problem = NonlinearContactProblem(F, u, list(terms.values()), [])
    steps = []

    def record(step) -> None:
        """One converged step's figures (collective: the forces and pressures are summed
        and gathered over the ranks)."""
        force = {name: term.results.contact_force() for name, term in terms.items()}
        lid_p, lid_chord, _ = touching_extent(terms["lid"])
        hole_p, _, hole_peak = touching_extent(terms["hole"])
        steps.append({"squeeze": float(-lid.displacement[1]),
                      "lid_force": float(-force["lid"][1]),
                      "floor_force": float(force["floor"][1]),
                      "inner_wall_force": float(force["inner_wall"][0]) + 0.0,  # no -0.0
                      "outer_wall_force": float(-force["outer_wall"][0]) + 0.0,
                      "lid_pressure": lid_p, "lid_contact_chord": lid_chord,
                      "self_contact_pressure": hole_p, "self_contact_peak_at": hole_peak,
                      "self_contact_nodes": terms["hole"].results.active_nodes(),
                      "self_contact_resultant": force["hole"].tolist(),
                      "newton_iterations": step.newton_iterations})

    result = LoadPathSolver(problem).solve(lambda t: lid.move_to([0.0, -args.squeeze * t]),
                                           load_steps=args.steps, on_step=record)
    figures = {"steps": steps, "newton_iterations": result.newton_iterations, "h": args.h,
               "nu": args.nu, "kind": args.kind, "configuration": args.configuration,
               "geometry": {"a": A, "b": B, "r_c": RC, "groove_width": WIDTH}}
    if comm.rank == 0:
        print(f"{result.newton_iterations} Newton iterations over {len(steps)} steps")
        for s in steps:
            print(f"squeeze {s['squeeze']:.3f}: lid {s['lid_force']:.4g} (floor "
                  f"{s['floor_force']:.4g}), walls {s['inner_wall_force']:.3g} / "
                  f"{s['outer_wall_force']:.3g}, lid p_max {s['lid_pressure']:.3g}, chord "
                  f"{s['lid_contact_chord']:.3g}, hole p_max {s['self_contact_pressure']:.3g} "
                  f"on {s['self_contact_nodes']} nodes")
        if args.json:
            write_json(args.json, figures)
        if args.png:
            plot(steps, args.png)
    return figures


def plot(steps: list[dict], path: str) -> None:
    """The forces and the peak pressures against the squeeze."""
    import matplotlib.pyplot as plt
    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.5))
    squeeze = [s["squeeze"] for s in steps]
    for key, label in (("lid_force", "lid"), ("inner_wall_force", "inner wall"),
                       ("outer_wall_force", "outer wall")):
        left.plot(squeeze, [s[key] for s in steps], "o-", label=label)
    left.set(xlabel="squeeze s", ylabel="force on the whole ring")
    left.legend()
    for key, label in (("lid_pressure", "lid"), ("self_contact_pressure", "hole (self-contact)")):
        right.plot(squeeze, [s[key] for s in steps], "o-", label=label)
    right.set(xlabel="squeeze s", ylabel="peak contact pressure")
    right.legend()
    fig.tight_layout()
    save_figure(path, fig)


if __name__ == "__main__":
    main()
