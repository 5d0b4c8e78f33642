"""Press and slide: a rigid cylinder pressed into a neo-Hookean block, then slid sideways.

Plane strain. The block [0, L] × [0, H] (compressible neo-Hookean, E, ν) is
fixed at its bottom; its top face is the slave surface. A rigid cylinder
(a disk of radius R, not meshed) first touches the top at x0, is pressed
down by the depth d along the first part of the load path, then slides
frictionlessly by the distance s along the rest. The mesh (gmsh) has the
size h = h0/refine in a band under the sliding track and grows away from it.

What the demo measures: the forces on the obstacle at each converged step,
normal (y) and tangential (x). Without friction and far from the block's
ends, steady sliding should need no tangential force: its mean is
``−dW/ds`` with W the stored energy, which does not depend on the position
on a uniform layer, and the track is symmetric about the block's centre.
What is left is the discretization's ripple as slave nodes pass under the
cylinder: the oscillation figures are its size relative to the normal force.

    python3 demos/press_and_slide.py --csv results/slide.csv --png results/slide.png
"""
from __future__ import annotations

import argparse
import time
from typing import Optional, Sequence

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import (ContactDivergenceError, ContactTerm, LoadPathSolver,
                            NonlinearContactProblem, RigidSphere)
from demo_support.cli import parse_args_and_petsc_options, solver_demo_parser
from demo_support.laws import neo_hookean_residual
from dolfinx_mortar.io.output import save_figure, write_csv, write_json

TOP, BOTTOM = 1, 2
#: the block [0, LENGTH] × [0, HEIGHT]
LENGTH, HEIGHT = 4.0, 1.0
#: element length at the top face for refine = 1
H0 = 0.05
#: sliding begins to be counted as steady after this many element lengths of slide
STEADY_AFTER = 2.0
#: default slide steps per element length
STEPS_PER_ELEMENT = 4
COLUMNS = ("step", "t", "phase", "obstacle_x", "obstacle_y", "slide", "normal_force",
           "tangential_force", "pressure_integral", "active_nodes", "newton_iterations",
           "terminal_iterations")


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    """The demo's options (PETSc options with a single dash go to the database)."""
    parser = solver_demo_parser(__doc__)
    parser.add_argument("--radius", type=float, default=0.5, help="cylinder radius R (0.5)")
    parser.add_argument("--depth", type=float, default=0.1,
                        help="indentation depth d as a fraction of R (0.1)")
    parser.add_argument("--slide", type=float, default=1.5, help="slide distance s (1.5)")
    parser.add_argument("--refine", type=float, default=1.0,
                        help=f"mesh density factor: element length {H0}/refine at the top (1)")
    parser.add_argument("--kind", default="LcLS*", help="mortar basis kind (LcLS*)")
    parser.add_argument("--configuration", default="current",
                        choices=("initial", "previous", "current"),
                        help="basis_configuration of the contact term (current)")
    parser.add_argument("--penalty", type=float, default=1e2,
                        help="penalty ε as a multiple of E/h (1e2)")
    parser.add_argument("--press-steps", type=int, default=4, help="load steps pressing (4)")
    parser.add_argument("--slide-steps", type=int, default=None,
                        help="load steps sliding (default: 4 per element length h, so "
                             "that the ripple of period h is resolved)")
    parser.add_argument("--linesearch", default=None, choices=("basic", "bt", "l2", "cp"),
                        help="SNES line search (default: the library's, l2 for 'current')")
    parser.add_argument("--predictor", default="linear", choices=("none", "linear"),
                        help="Newton's start in each step: the last solution, or extrapolated "
                             "linearly from the last two (linear)")
    parser.add_argument("--histories", action="store_true",
                        help="print every step's Newton residual history")
    parser.add_argument("--output", default=None, help="XDMF file of the steps")
    parser.add_argument("--csv", default=None, help="per-step forces as CSV")
    parser.add_argument("--png", default=None, help="force history figure")
    parser.add_argument("--json", default=None, help="key figures as JSON")
    parser.add_argument("--quiet", action="store_true", help="no printout, no progress bar")
    args = parse_args_and_petsc_options(parser, argv)
    if args.slide_steps is None:
        # steps of one element length sample the ripple at one phase only and
        # hide it (nodes are h apart): a few steps per element resolve it
        args.slide_steps = max(1, int(np.ceil(STEPS_PER_ELEMENT * args.slide * args.refine / H0
                                              - 1e-9)))
    return args


def track(args: argparse.Namespace) -> tuple[float, float]:
    """Where the cylinder's centre starts and ends: centred on the block."""
    x0 = 0.5 * (LENGTH - args.slide)
    return x0, x0 + args.slide


def build_mesh(args: argparse.Namespace, comm: MPI.Comm):
    """The block meshed by gmsh on rank 0 and distributed.

    Triangles of size h in a band under the track, growing to H/4 away from it.

    Returns
    -------
    domain, facet_tags, h
        The mesh, its facet tags (top face TOP, bottom BOTTOM) and h.
    """
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    h = H0 / args.refine
    x_start, x_end = track(args)
    # the band holds the contact zone (half-width below sqrt(2Rd)) all along the track
    margin = 2.0 * np.sqrt(2.0 * args.radius * args.depth * args.radius) + 2 * h
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            surface = occ.addRectangle(0, 0, 0, LENGTH, HEIGHT)
            occ.synchronize()
            for _, curve in gmsh.model.getEntities(1):
                x, y, _ = occ.getCenterOfMass(1, curve)
                if abs(y - HEIGHT) < 1e-9:
                    gmsh.model.addPhysicalGroup(1, [curve], TOP)
                elif abs(y) < 1e-9:
                    gmsh.model.addPhysicalGroup(1, [curve], BOTTOM)
            gmsh.model.addPhysicalGroup(2, [surface], 1)
            field = gmsh.model.mesh.field
            box = field.add("Box")
            field.setNumber(box, "VIn", h)
            field.setNumber(box, "VOut", HEIGHT / 4)
            field.setNumber(box, "XMin", max(0.0, x_start - margin))
            field.setNumber(box, "XMax", min(LENGTH, x_end + margin))
            field.setNumber(box, "YMin", HEIGHT - max(margin, 4 * h))
            field.setNumber(box, "YMax", HEIGHT)
            field.setNumber(box, "Thickness", 0.5 * HEIGHT)
            field.setAsBackgroundMesh(box)
            for option in ("MeshSizeExtendFromBoundary", "MeshSizeFromPoints",
                           "MeshSizeFromCurvature"):
                gmsh.option.setNumber(f"Mesh.{option}", 0)
            gmsh.model.mesh.generate(2)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    return domain, facet_tags, h


def load_path(args: argparse.Namespace, cylinder: RigidSphere):
    """``update(t)``: press over t ∈ (0, t_press], slide over the rest; and t_press.

    The split follows the step counts, so that equal load steps are the
    requested press and slide steps.
    """
    t_press = args.press_steps / (args.press_steps + args.slide_steps)
    depth = args.depth * args.radius

    def update(t: float) -> None:
        if t <= t_press:
            cylinder.move_to([0.0, -depth * t / t_press])
        else:
            cylinder.move_to([args.slide * (t - t_press) / (1 - t_press), -depth])
    return update, t_press


def steady_figures(rows: list[dict], h: float) -> dict:
    """Forces on the obstacle during steady sliding (past STEADY_AFTER·h of slide),
    relative to the mean normal force.

    Means and standard deviations are averages over the slide distance
    (trapezoidal weights), not over the steps: a cut step adds samples where
    Newton struggled, which would otherwise weigh that phase of the ripple more.
    """
    steady = sorted((r for r in rows if r["phase"] == "slide"
                     and r["slide"] >= STEADY_AFTER * h), key=lambda r: r["slide"])
    if len(steady) < 2:
        return {"steady_steps": len(steady)}
    s = np.array([r["slide"] for r in steady])
    weights = np.zeros_like(s)
    weights[1:] += 0.5 * np.diff(s)
    weights[:-1] += 0.5 * np.diff(s)

    def mean(f: np.ndarray) -> float:
        return float(np.sum(weights * f) / np.sum(weights))

    def std(f: np.ndarray) -> float:
        return float(np.sqrt(mean((f - mean(f)) ** 2)))

    normal = np.array([r["normal_force"] for r in steady])
    tangential = np.array([r["tangential_force"] for r in steady])
    mean_n = mean(normal)
    return {
        "steady_steps": len(steady),
        "normal_mean": mean_n,
        "normal_oscillation": float(np.ptp(normal) / mean_n),
        "normal_std": std(normal) / mean_n,
        "tangential_mean": mean(tangential) / mean_n,
        "tangential_oscillation": float(np.ptp(tangential) / mean_n),
        "tangential_std": std(tangential) / mean_n,
        "tangential_max_abs": float(np.max(np.abs(tangential)) / mean_n),
    }


def plot(path: str, rows: list[dict], figures: dict, h: float, title: str) -> None:
    """Normal and tangential force on the obstacle against the slide distance
    (each on its own scale: the tangential one is a ripple about zero)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    # the last pressed state is where the slide starts
    shown = [r for r in rows if r["phase"] == "press"][-1:] + [
        r for r in rows if r["phase"] == "slide"]
    s = np.array([r["slide"] for r in shown])
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    top.plot(s, [r["normal_force"] for r in shown], "o-", ms=2.5, label="normal $F_y$")
    bottom.plot(s, [r["tangential_force"] for r in shown], "s-", ms=2.5, color="C1",
                label="tangential $F_x$")
    for axis in (top, bottom):
        axis.axvspan(STEADY_AFTER * h, max(s[-1], STEADY_AFTER * h), color="0.92",
                     label="steady sliding")
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    bottom.axhline(0.0, color="k", lw=0.5)
    top.set_ylabel("normal force on the obstacle")
    bottom.set_ylabel("tangential force on the obstacle")
    bottom.set_xlabel("slide distance")
    if "normal_mean" in figures:
        title += (f"\nsteady sliding, relative to the mean normal force N = "
                  f"{figures['normal_mean']:.4g}: $F_x$ mean {figures['tangential_mean']:+.2e}, "
                  f"max−min {figures['tangential_oscillation']:.2e}")
    top.set_title(title, fontsize=9)
    fig.tight_layout()
    save_figure(path, fig, dpi=120)
    plt.close(fig)


def main(argv: Optional[Sequence[str]] = None) -> dict:
    """Run the demo; returns the key figures (and the per-step rows under "steps")."""
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    clock = time.perf_counter()
    domain, facet_tags, h = build_mesh(args, comm)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    u = fem.Function(V, name="u")
    bottom = fem.locate_dofs_topological(V, 1, facet_tags.find(BOTTOM))
    bcs = [fem.dirichletbc(np.zeros(2, dtype=PETSc.ScalarType), bottom, V)]
    x0, _ = track(args)
    cylinder = RigidSphere([x0, HEIGHT + args.radius], args.radius)
    contact = ContactTerm(u, facet_tags, TOP, obstacle=cylinder, kind=args.kind,
                          penalty=args.penalty * args.E / h,
                          basis_configuration=args.configuration)
    problem = NonlinearContactProblem(neo_hookean_residual(u, args.E, args.nu), u, contact,
                                      bcs)
    update, t_press = load_path(args, cylinder)
    rows: list[dict] = []

    def record(step) -> None:
        # the force on the obstacle is minus the resultant on the block
        force = -contact.results.contact_force()
        sliding = step.load_factor > t_press * (1 + 1e-12)
        rows.append({
            "step": len(rows) + 1, "t": step.load_factor,
            "phase": "slide" if sliding else "press",
            "obstacle_x": float(cylinder.center[0]), "obstacle_y": float(cylinder.center[1]),
            "slide": float(cylinder.displacement[0]),
            "normal_force": float(force[1]), "tangential_force": float(force[0]),
            "pressure_integral": contact.results.normal_force(), "active_nodes": step.active_nodes,
            "newton_iterations": step.newton_iterations,
            "terminal_iterations": step.terminal_iterations(), "residuals": step.phases})

    options = {"snes_linesearch_type": args.linesearch} if args.linesearch else None
    solver = LoadPathSolver(problem, petsc_options=options)
    steps = args.press_steps + args.slide_steps
    try:
        result = solver.solve(update, load_steps=steps, output=args.output,
                              progress=not args.quiet and comm.rank == 0, on_step=record,
                              predictor=args.predictor)
    except ContactDivergenceError as error:
        if comm.rank == 0 and not args.quiet:
            print(f"press and slide: Newton failed after {len(rows)} converged steps\n{error}")
        raise
    wall = time.perf_counter() - clock
    figures = steady_figures(rows, h)
    dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    figures.update({
        "kind": args.kind, "configuration": args.configuration, "penalty": args.penalty,
        "refine": args.refine, "h": h, "slide_in_elements": args.slide / h,
        "radius": args.radius, "depth": args.depth * args.radius, "dofs": int(dofs),
        "load_steps": len(result.steps), "requested_steps": steps,
        "cut_backs": len(result.cut_backs),
        "newton_iterations": result.newton_iterations,
        "max_newton_per_step": max(r["newton_iterations"] for r in rows),
        "predictor": args.predictor,
        "max_terminal_iterations": max(r["terminal_iterations"] for r in rows),
        "wall_time": wall, "ranks": comm.size, "steps": rows})
    title = (f"{args.kind}, basis_configuration={args.configuration}, "
             f"ε = {args.penalty:g} E/h, h = {h:g}")
    if comm.rank == 0:
        if not args.quiet:
            report(figures, args.histories)
        if args.csv:
            write_csv(args.csv, rows, COLUMNS)
        if args.json:
            write_json(args.json, figures)
        if args.png:
            plot(args.png, rows, figures, h, title)
    return figures


def report(f: dict, histories: bool = False) -> None:
    """Print the key figures of :func:`main` (and every step's residual norms)."""
    if histories:
        print("Newton residual norms per step (| separates the solves on the frozen and "
              "the current surface); n: iterations after the residual fell to 1e-3 F")
        for r in f["steps"]:
            norms = " | ".join(" ".join(f"{x:.1e}" for x in phase) for phase in r["residuals"])
            print(f"  {r['step']:4d} t = {r['t']:.4f} {r['phase']:5s} "
                  f"n = {r['terminal_iterations']}: {norms}")
    print(f"Press and slide ({f['kind']}, {f['configuration']}, {f['dofs']} dofs, "
          f"h = {f['h']:g}, slide {f['slide_in_elements']:.3g} h, {f['ranks']} rank(s))")
    if "normal_mean" in f:
        print(f"  steady sliding ({f['steady_steps']} steps): mean normal force "
              f"{f['normal_mean']:.6g}, its oscillation (max-min)/mean "
              f"{f['normal_oscillation']:.3e}")
        print(f"  tangential / mean normal: mean {f['tangential_mean']:+.3e}, max-min "
              f"{f['tangential_oscillation']:.3e}, std {f['tangential_std']:.3e}")
    print(f"  Newton iterations {f['newton_iterations']} in {f['load_steps']} steps "
          f"(at most {f['max_newton_per_step']} per step, predictor {f['predictor']}), "
          f"wall time {f['wall_time']:.2f} s")
    print(f"  every step converged within {f['max_terminal_iterations']} iterations once its "
          f"residual was 1e-3 of the out-of-balance force (quadratic: 2-3, linear rate 0.1: 8)")


if __name__ == "__main__":
    main()
