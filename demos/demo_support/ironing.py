"""The ironing scene of Puso & Laursen (2004), in 2D (plane strain) and 3D.

A neo-Hookean slab (9 × 3 in 2D, 9 × 4 × 3 in 3D; E = 1, ν = 0.3, bottom
fixed) and a half-cylindrical die (a half ring of outer radius 3 and
thickness 0.2, 5.2 wide in 3D), 1000 times stiffer, both meshed. The die's
two flat end faces are driven: down by 1.4, then along the slab by 4.0 (and,
with ``return_slide``, back to where the slide began), on the current
configuration by default. Frictionless by default, or with Coulomb friction
(``--mu 0.3``, the paper's); the slab's top is the slave surface, the die's
outer face the master. The paper's ν = 0.499 locks P1
elements, hence ν = 0.3.

The die's reaction (the force its driven faces need) is the bulk residual
summed over those faces' dofs: at equilibrium it equals the contact force on
the die.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import (ContactDivergenceError, ContactTerm, CoulombFriction,
                            LoadPathSolver, NonlinearContactProblem)
from demo_support.cli import parse_args_and_petsc_options, solver_demo_parser
from demo_support.laws import neo_hookean_energy, neo_hookean_residual
from dolfinx_mortar.io.output import save_figure, write_csv, write_json

#: facet tags
SLAB_TOP, SLAB_BOTTOM, DIE_OUTER, DIE_ENDS = 1, 2, 3, 4
#: cell tags
SLAB, DIE = 1, 2
#: the scene (Puso & Laursen 2004)
LENGTH, DEPTH, HEIGHT = 9.0, 4.0, 3.0
RADIUS, THICKNESS, DIE_WIDTH = 3.0, 0.2, 5.2
PRESS, SLIDE = 1.4, 4.0
E_DIE = 1000.0
#: where the die's lowest point starts (x): the slide is centred on the slab
START_X = 0.5 * (LENGTH - SLIDE)
#: the first slide distance counted as steady (the die has left the pressed state)
STEADY_AFTER = 1.0
COLUMNS = ("step", "t", "phase", "die_x", "die_z", "slide", "normal_reaction",
           "tangential_reaction", "active_nodes", "newton_iterations", "terminal_iterations")


def parse_args(doc: str, dim: int, argv=None) -> argparse.Namespace:
    """The options of an ironing demo (PETSc options with a single dash go to the
    database)."""
    parser = solver_demo_parser(doc)
    default_h = 0.25 if dim == 2 else 0.5
    parser.add_argument("--h", type=float, default=default_h,
                        help=f"element size of the slab at its top ({default_h})")
    parser.add_argument("--h-die", type=float, default=None,
                        help="element size of the die (default: the slab's, at most the "
                             "die's thickness)")
    parser.add_argument("--kind", default="LmLS*", help="mortar basis kind (LmLS*)")
    parser.add_argument("--mu", type=float, default=0.0,
                        help="Coulomb friction coefficient (0: frictionless; Puso and "
                             "Laursen's is 0.3)")
    parser.add_argument("--basis-configuration", default="current",
                        choices=("initial", "previous", "current"),
                        help="the bases' configuration (current)")
    parser.add_argument("--penalty", type=float, default=1e2,
                        help="penalty ε as a multiple of E/h of the slab (1e2)")
    parser.add_argument("--press-steps", type=int, default=10, help="steps pressing (10)")
    parser.add_argument("--slide-steps", type=int, default=None,
                        help="steps sliding 4.0 (default: 4 per slab element)")
    parser.add_argument("--linesearch", default=None, choices=("basic", "bt", "l2", "cp"),
                        help="SNES line search (default: the library's, l2)")
    parser.add_argument("--return-slide", action="store_true",
                        help="slide back to the start (path independence check)")
    parser.add_argument("--output", default=None, help="XDMF file of every step")
    parser.add_argument("--csv", default=None, help="per-step reaction forces as CSV")
    parser.add_argument("--png", default=None, help="reaction force history figure")
    parser.add_argument("--json", default=None, help="key figures as JSON")
    parser.add_argument("--quiet", action="store_true", help="no printout, no progress bar")
    args = parse_args_and_petsc_options(parser, argv)
    if args.h_die is None:
        args.h_die = min(args.h, THICKNESS)
    if args.slide_steps is None:
        args.slide_steps = int(np.ceil(4 * SLIDE / args.h - 1e-9))
    args.dim = dim
    return args


def build_mesh(args: argparse.Namespace, comm: MPI.Comm):
    """Slab and die in one mesh (gmsh on rank 0, distributed): returns the mesh,
    cell tags and facet tags."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    dim = args.dim
    centre_z = HEIGHT + RADIUS          # the die's axis: its lowest point touches the slab
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            if dim == 2:
                slab = occ.addRectangle(0, 0, 0, LENGTH, HEIGHT)
                outer = occ.addDisk(START_X, centre_z, 0, RADIUS, RADIUS)
                inner = occ.addDisk(START_X, centre_z, 0, RADIUS - THICKNESS,
                                    RADIUS - THICKNESS)
                lower = occ.addRectangle(START_X - RADIUS, centre_z - RADIUS, 0, 2 * RADIUS,
                                         RADIUS)
            else:
                slab = occ.addBox(0, 0, 0, LENGTH, DEPTH, HEIGHT)
                y0 = 0.5 * (DEPTH - DIE_WIDTH)
                outer = occ.addCylinder(START_X, y0, centre_z, 0, DIE_WIDTH, 0, RADIUS)
                inner = occ.addCylinder(START_X, y0, centre_z, 0, DIE_WIDTH, 0,
                                        RADIUS - THICKNESS)
                lower = occ.addBox(START_X - RADIUS, y0, centre_z - RADIUS, 2 * RADIUS,
                                   DIE_WIDTH, RADIUS)
            ring, _ = occ.cut([(dim, outer)], [(dim, inner)])
            die, _ = occ.intersect(ring, [(dim, lower)])
            occ.synchronize()
            die_tag = die[0][1]
            gmsh.model.addPhysicalGroup(dim, [slab], SLAB)
            gmsh.model.addPhysicalGroup(dim, [die_tag], DIE)
            groups: dict = {SLAB_TOP: [], SLAB_BOTTOM: [], DIE_OUTER: [], DIE_ENDS: []}
            tol = 1e-6
            for _, b in gmsh.model.getBoundary([(dim, slab)], oriented=False):
                c = occ.getCenterOfMass(dim - 1, b)
                if abs(c[dim - 1] - HEIGHT) < tol:
                    groups[SLAB_TOP].append(b)
                elif abs(c[dim - 1]) < tol:
                    groups[SLAB_BOTTOM].append(b)
            for _, b in gmsh.model.getBoundary([(dim, die_tag)], oriented=False):
                box = gmsh.model.getBoundingBox(dim - 1, b)
                lowest, highest = box[dim - 1], box[3 + dim - 1]
                if highest - lowest < tol:
                    groups[DIE_ENDS].append(b)                  # flat, at the axis
                elif dim == 3 and box[4] - box[1] < tol:
                    continue                                    # a half-ring side face
                elif lowest < centre_z - RADIUS + 0.5 * THICKNESS:
                    groups[DIE_OUTER].append(b)
            for tag, entities in groups.items():
                gmsh.model.addPhysicalGroup(dim - 1, entities, tag)
            # sizes: h_die on the die, h at the slab's top, growing to 2h at its bottom
            field = gmsh.model.mesh.field
            distance = field.add("Distance")
            field.setNumbers(distance, "FacesList" if dim == 3 else "EdgesList",
                             groups[SLAB_TOP])
            threshold = field.add("Threshold")
            field.setNumber(threshold, "InField", distance)
            field.setNumber(threshold, "SizeMin", args.h)
            field.setNumber(threshold, "SizeMax", 2 * args.h)
            field.setNumber(threshold, "DistMin", 0.5)
            field.setNumber(threshold, "DistMax", HEIGHT)
            die_box = field.add("Box")
            field.setNumber(die_box, "VIn", args.h_die)
            field.setNumber(die_box, "VOut", 1e22)
            for key, value in (("XMin", START_X - RADIUS - 0.01), ("XMax", START_X + RADIUS + 0.01),
                               ("YMin", -10.0), ("YMax", 10.0),
                               ("ZMin", -10.0), ("ZMax", 10.0)):
                field.setNumber(die_box, key, value)
            if dim == 2:
                field.setNumber(die_box, "YMin", HEIGHT + 1e-3)
            else:
                field.setNumber(die_box, "ZMin", HEIGHT + 1e-3)
            minimum = field.add("Min")
            field.setNumbers(minimum, "FieldsList", [threshold, die_box])
            field.setAsBackgroundMesh(minimum)
            for option in ("MeshSizeExtendFromBoundary", "MeshSizeFromPoints",
                           "MeshSizeFromCurvature"):
                gmsh.option.setNumber(f"Mesh.{option}", 0)
            gmsh.model.mesh.generate(dim)
        domain, cell_tags, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=dim)
    finally:
        gmsh.finalize()
    return domain, cell_tags, facet_tags



def die_motion(args: argparse.Namespace):
    """``motion(t)``: the die's displacement (x, z) at pseudo-time t, and the
    times where pressing ends and (with a return) the forward slide ends."""
    n_press, n_slide = args.press_steps, args.slide_steps
    total = n_press + n_slide * (2 if args.return_slide else 1)
    t_press, t_forward = n_press / total, (n_press + n_slide) / total

    def motion(t: float) -> tuple[float, float]:
        if t <= t_press:
            return 0.0, -PRESS * t / t_press
        if t <= t_forward:
            return SLIDE * (t - t_press) / (t_forward - t_press), -PRESS
        return SLIDE * (1 - (t - t_forward) / (1 - t_forward)), -PRESS
    return motion, t_press, t_forward, total


def run(args: argparse.Namespace, comm: MPI.Comm) -> dict:
    """Solve the scene; the key figures (and every step's row under "steps")."""
    clock = time.perf_counter()
    dim = args.dim
    domain, cell_tags, facet_tags = build_mesh(args, comm)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    u = fem.Function(V, name="u")
    # Young's modulus per cell: slab and die
    Q = fem.functionspace(domain, ("DG", 0))
    E = fem.Function(Q)
    E.x.array[:] = args.E
    # by the dofmap: a DG0 dof is not its cell's index (DOLFINx 0.9 and later reorder the
    # dofs; with the cell indices the die's stiffness went to cells of the slab)
    E.x.array[Q.dofmap.list[cell_tags.find(DIE)].ravel()] = E_DIE * args.E
    E.x.scatter_forward()
    fdim = dim - 1
    bottom = fem.locate_dofs_topological(V, fdim, facet_tags.find(SLAB_BOTTOM))
    ends = fem.locate_dofs_topological(V, fdim, facet_tags.find(DIE_ENDS))
    drive = fem.Constant(domain, np.zeros(dim, dtype=PETSc.ScalarType))
    bcs = [fem.dirichletbc(np.zeros(dim, dtype=PETSc.ScalarType), bottom, V),
           fem.dirichletbc(drive, ends, V)]
    contact = ContactTerm(u, facet_tags, SLAB_TOP, master_tag=DIE_OUTER, kind=args.kind,
                          penalty=args.penalty * args.E / args.h,
                          basis_configuration=args.basis_configuration,
                          friction=CoulombFriction(args.mu) if args.mu > 0 else None)
    residual = neo_hookean_residual(u, E, args.nu)
    problem = NonlinearContactProblem(residual, u, contact, bcs)
    motion, t_press, t_forward, total = die_motion(args)

    def update(t: float) -> None:
        x, z = motion(t)
        drive.value[0], drive.value[dim - 1] = x, z

    bulk = fem.form(residual)
    owned = ends[ends < V.dofmap.index_map.size_local]
    rows: list[dict] = []
    pressed: dict = {}
    # the work of the die's drive, by the trapezoidal rule over the steps
    drive_work = {"work": 0.0, "force": np.zeros(dim), "at": np.zeros(dim)}

    def reaction() -> np.ndarray:
        """Σ of the bulk residual over the die's driven dofs (all ranks)."""
        b = fem_petsc.assemble_vector(bulk)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        local = b.array_r.reshape(-1, dim)[owned].sum(axis=0)
        b.destroy()
        return np.asarray(comm.allreduce(local))

    def record(step) -> None:
        t = step.load_factor
        x, z = motion(t)
        force = reaction()
        phase = "press" if t <= t_press * (1 + 1e-12) else (
            "slide" if t <= t_forward * (1 + 1e-12) else "return")
        if phase == "press":
            pressed["u"] = u.x.array.copy()
        at = np.array([x] + [0.0] * (dim - 2) + [z])
        drive_work["work"] += 0.5 * float((force + drive_work["force"]) @ (at - drive_work["at"]))
        drive_work["force"], drive_work["at"] = force, at
        # the force the drive applies to the die: down while it presses (reported
        # as a positive pressing force) and along the slab while it slides
        rows.append({"step": len(rows) + 1, "t": t, "phase": phase, "die_x": START_X + x,
                     "die_z": z, "slide": x, "normal_reaction": -float(force[dim - 1]),
                     "tangential_reaction": float(force[0]),
                     "active_nodes": step.active_nodes,
                     "newton_iterations": step.newton_iterations,
                     "terminal_iterations": step.terminal_iterations(),
                     "drive_work": drive_work["work"],
                     "dissipation": contact.results.dissipation(),
                     "residuals": step.phases})

    options = {"snes_linesearch_type": args.linesearch} if args.linesearch else None
    solver = LoadPathSolver(problem, petsc_options=options)
    try:
        result = solver.solve(update, load_steps=total, output=args.output,
                              progress=not args.quiet and comm.rank == 0, on_step=record,
                              predictor="linear")
    except ContactDivergenceError as error:
        if comm.rank == 0 and not args.quiet:
            print(f"ironing: Newton failed after {len(rows)} converged steps\n{error}")
        raise
    figures = steady_figures(rows)
    dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    if args.return_slide:
        n = V.dofmap.index_map.size_local * dim
        difference = comm.allreduce(float(np.max(np.abs(u.x.array[:n] - pressed["u"][:n]),
                                                 initial=0.0)), op=MPI.MAX)
        scale = comm.allreduce(float(np.max(np.abs(pressed["u"][:n]), initial=0.0)),
                               op=MPI.MAX)
        figures["return_difference"] = difference / scale
    # the die's work against what the bodies store and friction dissipates; the
    # trapezoidal rule on a nonlinear bulk leaves an error of the steps' order
    bulk_energy = comm.allreduce(fem.assemble_scalar(fem.form(
        neo_hookean_energy(u, E, args.nu))))
    stored = bulk_energy + contact.results.stored_energy()
    dissipation = contact.results.dissipation()
    figures.update({"dissipation": dissipation, "drive_work": drive_work["work"],
                    "stored_energy": stored,
                    "energy_balance": (drive_work["work"] - stored - dissipation)
                    / drive_work["work"]})
    figures.update({
        "dim": dim, "kind": args.kind, "penalty": args.penalty, "h": args.h,
        "mu": args.mu, "basis_configuration": args.basis_configuration,
        "h_die": args.h_die, "dofs": int(dofs), "load_steps": len(result.steps),
        "requested_steps": total, "newton_iterations": result.newton_iterations,
        "max_newton_per_step": max(r["newton_iterations"] for r in rows),
        "max_terminal_iterations": max(r["terminal_iterations"] for r in rows),
        "wall_time": time.perf_counter() - clock, "ranks": comm.size, "steps": rows})
    if comm.rank == 0:
        if not args.quiet:
            report(figures)
        if args.csv:
            write_csv(args.csv, rows, COLUMNS)
        if args.json:
            write_json(args.json, figures)
        if args.png:
            plot(args.png, rows, figures)
    return figures


def steady_figures(rows: list[dict]) -> dict:
    """The reaction during steady forward sliding (slide ≥ STEADY_AFTER and at
    least STEADY_AFTER from the end): mean normal reaction, and the normal and
    tangential reactions' max − min relative to it."""
    steady = [r for r in rows if r["phase"] == "slide"
              and STEADY_AFTER <= r["slide"] <= SLIDE - STEADY_AFTER]
    if len(steady) < 2:
        return {"steady_steps": len(steady)}
    slide = np.array([r["slide"] for r in steady])
    normal = np.array([r["normal_reaction"] for r in steady])
    tangential = np.array([r["tangential_reaction"] for r in steady])
    mean = float(np.mean(normal))

    def ripple(f: np.ndarray) -> float:
        """max − min of f about a least-squares quadratic in the slide: the
        slab's finite length bends the force history smoothly, and that trend is
        not the discretization's ripple (a line through two steps: a quadratic
        through them is underdetermined, and NumPy warned it poorly conditioned)"""
        trend = np.polyval(np.polyfit(slide, f, min(2, len(slide) - 1)), slide)
        return float(np.ptp(f - trend) / abs(mean))

    return {"steady_steps": len(steady), "normal_mean": mean,
            "normal_oscillation": float(np.ptp(normal) / abs(mean)),
            "normal_ripple": ripple(normal),
            "tangential_mean": float(np.mean(tangential) / abs(mean)),
            "tangential_oscillation": float(np.ptp(tangential) / abs(mean)),
            "tangential_ripple": ripple(tangential)}


def plot(path: str, rows: list[dict], figures: dict) -> None:
    """Normal and tangential reaction of the die against pseudo-time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = [r["t"] for r in rows]
    fig, axis = plt.subplots(figsize=(8, 4.5))
    axis.plot(t, [r["normal_reaction"] for r in rows], "o-", ms=2.5, label="normal (vertical)")
    axis.plot(t, [r["tangential_reaction"] for r in rows], "s-", ms=2.5,
              label="tangential (along the slab)")
    axis.axhline(0.0, color="k", lw=0.5)
    axis.set_xlabel("pseudo-time (press, then slide)")
    axis.set_ylabel("reaction force on the die")
    title = (f"Ironing {figures['dim']}D, {figures['kind']}, h = {figures['h']:g}, "
             f"{figures['dofs']} dofs")
    if "normal_mean" in figures:
        title += (f"\nsteady sliding: normal reaction {figures['normal_mean']:.4g}, "
                  f"(max−min)/mean {figures['normal_oscillation']:.2e}, ripple about its "
                  f"trend {figures['normal_ripple']:.2e}")
    axis.set_title(title, fontsize=9)
    axis.legend(fontsize=8)
    fig.tight_layout()
    save_figure(path, fig, dpi=120)
    plt.close(fig)


def report(f: dict) -> None:
    """Print the key figures of :func:`run`."""
    print(f"Ironing {f['dim']}D ({f['kind']}, h = {f['h']:g}, die h = {f['h_die']:g}, "
          f"{f['dofs']} dofs, {f['ranks']} rank(s))")
    if "normal_mean" in f:
        print(f"  steady sliding ({f['steady_steps']} steps): normal reaction "
              f"{f['normal_mean']:.6g}, (max-min)/mean {f['normal_oscillation']:.3e}, "
              f"ripple about its trend {f['normal_ripple']:.3e}; tangential/normal mean "
              f"{f['tangential_mean']:+.3e}, max-min {f['tangential_oscillation']:.3e}, "
              f"ripple {f['tangential_ripple']:.3e}")
    if "dissipation" in f:
        print(f"  μ = {f['mu']:g} ({f['basis_configuration']}): work of the die "
              f"{f['drive_work']:.6g}, frictional dissipation {f['dissipation']:.6g} "
              f"({100 * f['dissipation'] / f['drive_work']:.1f}% of it), stored "
              f"{f['stored_energy']:.6g}; unbalanced {f['energy_balance']:+.2e} of the work")
    if "return_difference" in f:
        print(f"  back at the start: max |u - u_pressed| / max |u_pressed| = "
              f"{f['return_difference']:.2e}")
    print(f"  Newton iterations {f['newton_iterations']} in {f['load_steps']} steps (at most "
          f"{f['max_newton_per_step']} per step, at most {f['max_terminal_iterations']} once "
          f"the residual was 1e-3 of the step's force); wall time {f['wall_time']:.1f} s")
