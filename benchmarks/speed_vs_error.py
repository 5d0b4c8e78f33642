"""Speed against error: Hertz 2D and 3D over refinement × basis kind × penalty.

Every run builds the scene of demos/hertz2d.py or demos/hertz3d.py (same
mesh, loads and defaults), solves it, and records where the wall time goes
and how far the result is from Hertz:

- contact setup: ``search`` (normals, gathering the master, bounding-box
  search; elastic master only), ``segmentation`` (the mortar integrals; elastic
  master only), ``basis`` (construction of the mortar basis of the gap model,
  plus the GLS mass-matrix factorization for GLS/GLS*), ``gap_setup`` (the rest
  of the gap model: tabulation and the constant G of an elastic master) and
  ``pattern`` (the bulk ∪ contact sparsity pattern of the Newton matrix, built
  once);
- per Newton solve: ``contact_assembly`` (contact residual + Jacobian
  callbacks), ``bulk_assembly`` (bulk residual + Jacobian callbacks) and
  ``linear_solve``: the time inside SNESSolve minus all assembly callbacks,
  i.e. the MUMPS factorization and triangular solves plus the SNES's vector
  work (a direct solver: there is no Krylov iteration to monitor). For GLS/GLS*
  the factorization of the augmented system happens inside the Jacobian
  callback; it is moved from contact assembly to the linear solve;
- ``contact_fraction``: contact assembly / (bulk assembly + linear solve)
  summed over all Newton iterations of the run (= the per-iteration ratio);
- errors against Hertz: peak pressure, contact size (half-width / radius) and
  the relative L2 error of the pressure over the contact zone.

``time_s`` (the x axis of the plot) is contact setup + pattern + solve: what
the method costs once the mesh exists. ``wall_s`` also includes meshing (gmsh)
and form compilation.

    python3 benchmarks/speed_vs_error.py            # full run (~25 min on a shared 2-core machine)
    python3 benchmarks/speed_vs_error.py --quick    # ~3–5 min
"""
from __future__ import annotations

import argparse
import gc
import math
import sys
import time
from pathlib import Path
from typing import Optional, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FormatStrFormatter  # noqa: E402
import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from tqdm import tqdm  # noqa: E402

from demo_support.scripts import load_demo
from dolfinx_mortar.io.output import save_figure, write_atomically, write_csv  # noqa: E402

KINDS = ("GLS", "GLS*", "LmLS", "LmLS*", "LcLS*", "LcLS")
DEFAULT_LEVELS = {"2d": [0.5, 1.0, 2.0], "3d": [0.5, 1.0]}
QUICK_LEVELS = {"2d": [0.5], "3d": [0.5]}
DEFAULT_PENALTIES = [1e2, 1e3, 1e4]
ERRORS = {"p0_error": "peak pressure", "a_error": "contact size", "l2_error": "L2 pressure"}
TIMES = ("search", "segmentation", "basis", "gap_setup", "pattern", "contact_assembly",
         "bulk_assembly", "linear_solve")
COLUMNS = ("scene", "obstacle", "refine", "dofs", "slave_nodes", "kind", "penalty", "status",
           "newton_iterations", *[t + "_s" for t in TIMES], "time_s", "wall_s",
           "contact_ms_per_iteration", "bulk_ms_per_iteration", "solve_ms_per_iteration",
           "contact_fraction", "p0_error", "a_error", "l2_error")


def setup_times(problem) -> dict:
    """Contact setup phases of a freshly built problem (seconds, this rank)."""
    from dolfinx_mortar.contact.gap_sources.global_gap import GlobalGap
    model = problem.gap_model
    inner = model.inner if isinstance(model, GlobalGap) else model
    basis = inner.basis.construction_time
    if isinstance(model, GlobalGap):
        basis += model.basis.construction_time
    search = segmentation = 0.0
    coupling = getattr(inner, "coupling", None)
    if coupling is not None:
        search = coupling.timings["normals_and_gather"] + coupling.timings["search"]
        segmentation = coupling.timings["segmentation"]
    return {"search": search, "segmentation": segmentation, "basis": basis,
            "gap_setup": problem.timings["contact_setup"] - search - segmentation - basis}


def run(scene: str, demo, obstacle: str, level: float, kind: str, penalty: float,
        comm: MPI.Comm, max_cuts: int = 2) -> dict:
    """One solve; times are the maximum over ranks."""
    args = demo.parse_args(["--refine", repr(level), "--kind", kind, "--penalty", repr(penalty),
                            "--obstacle", obstacle])
    row = {"scene": scene, "obstacle": obstacle, "refine": level, "kind": kind,
           "penalty": penalty}
    clock = time.perf_counter()
    problem, *context = demo.build_problem(args, comm)
    V = problem.V
    row["dofs"] = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    row["slave_nodes"] = problem.slave.layout.size_global
    times = setup_times(problem)
    contact_setup = problem.timings["contact_setup"]
    # The Newton matrix pattern is built once, on the first SNES setup; build
    # it here so that its residual evaluation does not land in the Newton times.
    t = time.perf_counter()
    problem.problem.matrix()
    times["pattern"] = time.perf_counter() - t
    problem.reset_timings()
    t = time.perf_counter()
    try:
        result = problem.solve(load_steps=args.load_steps, max_cuts=max_cuts)
    except Exception as err:  # a diverged run is a result too
        row.update(status=f"failed: {type(err).__name__}", **{k + "_s": v for k, v in times.items()})
        return row
    solve = time.perf_counter() - t
    tm = problem.timings
    factorization = problem.contact.timings.get("augmented_factorization", 0.0)
    callbacks = sum(tm.get(k, 0.0) for k in ("bulk_residual", "bulk_jacobian",
                                              "contact_residual", "contact_jacobian"))
    times["contact_assembly"] = (tm.get("contact_residual", 0.0)
                                 + tm.get("contact_jacobian", 0.0) - factorization)
    times["bulk_assembly"] = tm.get("bulk_residual", 0.0) + tm.get("bulk_jacobian", 0.0)
    times["linear_solve"] = tm["snes_solve"] - callbacks + factorization
    times = {k: comm.allreduce(v, op=MPI.MAX) for k, v in times.items()}
    total = comm.allreduce(contact_setup + times["pattern"] + solve, op=MPI.MAX)
    figures = demo.key_figures(args, problem, result, *context, 0.0)
    its = max(result.newton_iterations, 1)
    row.update({
        "status": "ok", "newton_iterations": result.newton_iterations,
        **{k + "_s": v for k, v in times.items()},
        "time_s": total, "wall_s": comm.allreduce(time.perf_counter() - clock, op=MPI.MAX),
        "contact_ms_per_iteration": 1e3 * times["contact_assembly"] / its,
        "bulk_ms_per_iteration": 1e3 * times["bulk_assembly"] / its,
        "solve_ms_per_iteration": 1e3 * times["linear_solve"] / its,
        "contact_fraction": times["contact_assembly"]
        / (times["bulk_assembly"] + times["linear_solve"]),
        **{k: abs(figures[k]) for k in ERRORS},
    })
    return row


def pareto(rows: list, error: str) -> list:
    """Runs that no other run beats in both time and error (sorted by time)."""
    ok = sorted((r for r in rows if r["status"] == "ok" and math.isfinite(r[error])),
                key=lambda r: (r["time_s"], r[error]))
    front, best = [], math.inf
    for r in ok:
        if r[error] < best * (1 - 1e-6):  # roundoff-level differences do not count
            front.append(r)
            best = r[error]
    return front


def fmt(v, spec: str) -> str:
    return "" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, spec)


def markdown_table(rows: list) -> str:
    head = ("| scene | refine | dofs | kind | ε·h/E | Newton | search s | segm. s | basis s "
            "| contact asm s | bulk asm s | solve s | time s | contact/(bulk+solve) "
            "| p0 err % | a err % | L2 err % |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        if r["status"] != "ok":
            lines.append(f"| {r['scene']} | {r['refine']:g} | {r.get('dofs', '')} | {r['kind']} "
                         f"| {r['penalty']:.0e} | {r['status']} |" + " |" * 11)
            continue
        lines.append(
            f"| {r['scene']} | {r['refine']:g} | {r['dofs']} | {r['kind']} | {r['penalty']:.0e} "
            f"| {r['newton_iterations']} | {r['search_s']:.3f} | {r['segmentation_s']:.3f} "
            f"| {r['basis_s']:.3f} | {r['contact_assembly_s']:.2f} | {r['bulk_assembly_s']:.2f} "
            f"| {r['linear_solve_s']:.2f} | {r['time_s']:.2f} | {100 * r['contact_fraction']:.1f}% "
            f"| {fmt(100 * r['p0_error'], '.2f')} | {fmt(100 * r['a_error'], '.2f')} "
            f"| {fmt(100 * r['l2_error'], '.2f')} |")
    return "\n".join(lines)


def summary(rows: list) -> str:
    """Which kinds are on each Pareto front, and the contact fraction per level."""
    out = []
    scenes = sorted({(r["scene"], r["obstacle"]) for r in rows})
    for scene, obstacle in scenes:
        rs = [r for r in rows if r["scene"] == scene and r["obstacle"] == obstacle]
        for error, label in ERRORS.items():
            front = pareto(rs, error)
            items = ", ".join(f"{r['kind']} (refine {r['refine']:g}, ε {r['penalty']:.0e}, "
                              f"{r['time_s']:.1f} s, {100 * r[error]:.2f}%)" for r in front)
            out.append(f"- Hertz {scene} ({obstacle}), {label} error front: {items}")
        for level in sorted({r["refine"] for r in rs}):
            ok = [r for r in rs if r["refine"] == level and r["status"] == "ok"]
            failed = [f"{r['kind']} ε {r['penalty']:.0e}" for r in rs
                      if r["refine"] == level and r["status"] != "ok"]
            if failed:
                out.append(f"- Hertz {scene} ({obstacle}), refine {level:g}: diverged: "
                           + ", ".join(failed))
            if not ok:
                continue
            fr = np.array([r["contact_fraction"] for r in ok])
            per_kind = ", ".join(
                f"{k} {100 * np.median([r['contact_fraction'] for r in ok if r['kind'] == k]):.0f}%"
                for k in KINDS if any(r["kind"] == k for r in ok))
            out.append(f"- Hertz {scene} ({obstacle}), refine {level:g} ({ok[0]['dofs']} dofs): "
                       f"contact/(bulk+solve) median {100 * np.median(fr):.0f}% "
                       f"(min {100 * fr.min():.0f}%, max {100 * fr.max():.0f}%); "
                       f"by kind: {per_kind}")
    return "\n".join(out)


def plot(rows: list, path: str) -> None:
    scenes = sorted({(r["scene"], r["obstacle"]) for r in rows})
    fig, axes = plt.subplots(len(scenes), len(ERRORS), figsize=(4.2 * len(ERRORS),
                                                               3.6 * len(scenes)),
                             squeeze=False)
    markers = dict(zip(KINDS, "os^vDP"))
    colors = dict(zip(KINDS, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    for i, (scene, obstacle) in enumerate(scenes):
        rs = [r for r in rows if r["scene"] == scene and r["obstacle"] == obstacle
              and r["status"] == "ok"]
        for j, (error, label) in enumerate(ERRORS.items()):
            ax = axes[i, j]
            for kind in KINDS:
                ks = [r for r in rs if r["kind"] == kind and r[error] > 0]
                if ks:
                    ax.loglog([r["time_s"] for r in ks], [r[error] for r in ks],
                              markers[kind], color=colors[kind], label=kind, alpha=0.75,
                              markersize=5)
            front = [r for r in pareto(rs, error) if r[error] > 0]
            if front:
                ax.step([r["time_s"] for r in front], [r[error] for r in front], "k-",
                        where="post", lw=1, label="Pareto front")
            ax.set_title(f"Hertz {scene} ({obstacle}): {label}", fontsize=10)
            ax.set_xlabel("contact setup + solve time [s]")
            ax.set_ylabel("relative error")
            for axis in (ax.xaxis, ax.yaxis):
                axis.set_major_formatter(FormatStrFormatter("%.3g"))
                axis.set_minor_formatter(FormatStrFormatter("%.3g"))
            ax.grid(True, which="both", alpha=0.3)
    axes[0, -1].legend(fontsize=7)
    fig.tight_layout()
    save_figure(path, fig, dpi=110)
    plt.close(fig)


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="small preset (3–5 min): refine 0.5 in 2D and 3D")
    parser.add_argument("--dims", nargs="+", default=["2d", "3d"], choices=["2d", "3d"])
    parser.add_argument("--levels-2d", nargs="+", type=float, default=None,
                        help="--refine values of hertz2d (0.5 1 2)")
    parser.add_argument("--levels-3d", nargs="+", type=float, default=None,
                        help="--refine values of hertz3d (0.5 1; 1.5 and 2 add ~35 min)")
    parser.add_argument("--kinds", nargs="+", default=list(KINDS))
    parser.add_argument("--penalties", nargs="+", type=float, default=DEFAULT_PENALTIES,
                        help="penalty ε as multiples of E/h_contact (1e2 1e3 1e4)")
    parser.add_argument("--obstacles", nargs="+", default=["rigid"], choices=["rigid", "elastic"],
                        help="rigid plane (no search/segmentation) and/or elastic block")
    parser.add_argument("--max-cuts", type=int, default=2,
                        help="load-step halvings in a row before a run counts as failed (2; "
                             "the demos allow 5, but a diverging run then costs minutes)")
    parser.add_argument("--from-csv", default=None,
                        help="no runs: redo the table, summary and plot from this CSV")
    parser.add_argument("--csv", default=None,
                        help="results/speed_vs_error.csv (--quick: speed_vs_error_quick.csv)")
    parser.add_argument("--png", default=None, help="as --csv, .png")
    parser.add_argument("--markdown", default=None,
                        help="as --csv, .md: the table and the summary as markdown")
    args = parser.parse_args(argv)
    # the quick preset must not overwrite the full study's results
    stem = "results/speed_vs_error" + ("_quick" if args.quick else "")
    for option, suffix in (("csv", ".csv"), ("png", ".png"), ("markdown", ".md")):
        if getattr(args, option) is None:
            setattr(args, option, stem + suffix)
    return args


def read_rows(path: str) -> list:
    """Rows of a CSV written by this script, numbers as numbers."""
    import csv
    rows = []
    with open(path, newline="") as f:
        for raw in csv.DictReader(f):
            row = {}
            for key, value in raw.items():
                if key in ("scene", "obstacle", "kind", "status") or value == "":
                    row[key] = value if value != "" else None
                elif key in ("dofs", "slave_nodes", "newton_iterations"):
                    row[key] = int(value)
                else:
                    row[key] = float(value)
            rows.append(row)
    return rows


def report(rows: list, args: argparse.Namespace) -> None:
    """Print the table and the summary; write the markdown and the plot."""
    table, text = markdown_table(rows), summary(rows)
    print(table)
    print()
    print(text)
    write_atomically(args.markdown, lambda tmp: Path(tmp).write_text(table + "\n\n" + text + "\n"))
    plot(rows, args.png)
    print(f"\nwrote {args.png} and {args.markdown}")


def main(argv: Optional[Sequence[str]] = None) -> list:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    if args.from_csv:
        rows = read_rows(args.from_csv)
        if comm.rank == 0:
            report(rows, args)
        return rows
    levels = dict(QUICK_LEVELS if args.quick else DEFAULT_LEVELS)
    if args.levels_2d:
        levels["2d"] = args.levels_2d
    if args.levels_3d:
        levels["3d"] = args.levels_3d
    demos = {"2d": load_demo("hertz2d"), "3d": load_demo("hertz3d")}
    runs = [(scene, obstacle, level, kind, penalty) for scene in args.dims
            for obstacle in args.obstacles for level in levels[scene]
            for kind in args.kinds for penalty in args.penalties]
    rows = []
    bar = tqdm(runs, file=sys.stderr, desc="speed vs error", disable=comm.rank != 0)
    for scene, obstacle, level, kind, penalty in bar:
        bar.set_postfix_str(f"{scene} {obstacle} refine {level:g} {kind} ε {penalty:.0e}")
        rows.append(run(scene, demos[scene], obstacle, level, kind, penalty, comm,
                        args.max_cuts))
        gc.collect()  # free the previous run's PETSc objects before the next mesh
        if comm.rank == 0:  # partial results survive an interrupted run
            write_csv(args.csv, rows, COLUMNS)
    if comm.rank == 0:
        report(rows, args)
        print(f"wrote {args.csv}")
    return rows


if __name__ == "__main__":
    main()
