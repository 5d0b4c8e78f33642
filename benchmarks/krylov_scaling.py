"""Linear solvers on Hertz 3D with two elastic bodies: Krylov iterations
against mesh size and penalty, time and memory against MUMPS.

Runs the scene of ``demos/hertz3d.py --obstacle elastic`` (sphere octant on
an elastic block, LcLS*, nodal active set, 3 load steps or ``--load-steps``) for every mesh level
× penalty × linear solver given, in this process, and tabulates per run: dofs,
Newton iterations, Krylov iterations per Newton iteration, wall time of the
whole solve and its parts (contact, bulk assembly, the rest = linear solves),
peak memory of the process so far, and the p0 / a / L2 errors against Hertz.

Linear solvers (``--solvers``):

- ``block``: the iterative default, CG + contact block + BoomerAMG, with
  Eisenstat–Walker forcing capped at 0.01;
- ``block-fixed``: the same with a fixed Krylov tolerance 1e-8 (no forcing);
- ``block-ew-petsc``, ``block-ew0.1``: PETSc's default forcing (from 0.3, up
  to 0.9), or forcing capped at 0.1;
- ``block-gamg``: CG + contact block + GAMG with the rigid-body modes;
- ``gamg``: CG + GAMG with the rigid-body modes, no contact block;
- ``boomeramg``: CG + BoomerAMG, no contact block;
- ``direct``: MUMPS LU every Newton iteration;
- ``direct-reuse``: GMRES preconditioned by the MUMPS factorization of the
  first Newton matrix of each SNES solve (``snes_lag_preconditioner``).

    OMP_NUM_THREADS=1 python3 benchmarks/krylov_scaling.py \\
        [--levels 0.5 1 2] [--penalties 1e1 1e2 1e3 1e4] [--solvers block direct] [--out DIR]
    mpirun -n 2 python3 benchmarks/krylov_scaling.py --levels 3 --penalties 1e3 \\
        --tag n2            # the same under MPI

Writes ``krylov_scaling[_TAG].{csv,md}`` into ``--out`` (default
``benchmarks/results/``).
"""
from __future__ import annotations

import argparse
import gc
import os
import resource
import time
from pathlib import Path
from typing import Optional, Sequence

from mpi4py import MPI
from petsc4py import PETSc

from demo_support.scripts import load_demo
from dolfinx_mortar.io.output import write_atomically, write_csv

HERE = Path(__file__).resolve().parent
PREFIX = "dolfinx_mortar_"

SOLVERS = {
    "block": ("iterative", {}),
    "block-fixed": ("iterative", {"snes_ksp_ew": "false"}),
    "block-ew-petsc": ("iterative", {"snes_ksp_ew_rtol0": 0.3, "snes_ksp_ew_rtolmax": 0.9}),
    "block-ew0.1": ("iterative", {"snes_ksp_ew_rtol0": 0.1, "snes_ksp_ew_rtolmax": 0.1}),
    "block-gamg": ("iterative", {"amg_pc_type": "gamg"}),
    "gamg": ("iterative", {"pc_type": "gamg"}),
    "boomeramg": ("iterative", {"pc_type": "hypre", "pc_hypre_type": "boomeramg",
                                "pc_hypre_boomeramg_strong_threshold": 0.7}),
    "direct": ("direct", {}),
    "direct-reuse": ("direct", {"ksp_type": "gmres", "ksp_pc_side": "right",
                                "ksp_rtol": 1e-8, "ksp_max_it": 200,
                                "snes_lag_preconditioner": 1000}),
}
COLUMNS = ("solver", "refine", "penalty", "ranks", "dofs", "newton", "krylov",
           "krylov_per_newton", "wall_time", "contact_time", "bulk_time", "linear_time",
           "contact_share", "peak_memory_mb", "p0_error", "a_error", "l2_error")


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--levels", type=float, nargs="+", default=[0.5, 1.0, 2.0],
                        help="mesh levels (hertz3d --refine)")
    parser.add_argument("--penalties", type=float, nargs="+", default=[1e1, 1e2, 1e3, 1e4],
                        help="ε as multiples of E/h")
    parser.add_argument("--solvers", nargs="+", default=["block", "gamg", "direct"],
                        choices=sorted(SOLVERS))
    parser.add_argument("--load-steps", type=int, default=None,
                        help="load steps (the demo's default, 3)")
    parser.add_argument("--tag", default="", help="suffix of the result files")
    parser.add_argument("--out", default=str(HERE / "results"))
    return parser.parse_args(argv)


def run_one(demo, solver: str, refine: float, penalty: float,
            load_steps: Optional[int] = None) -> dict:
    """One solve of the scene; its row of the table (on every rank)."""
    comm = MPI.COMM_WORLD
    linear_solver, options = SOLVERS[solver]
    db = PETSc.Options()
    for key, value in options.items():
        db[PREFIX + key] = value
    try:
        args = demo.parse_args(["--obstacle", "elastic", "--refine", str(refine),
                                "--penalty", str(penalty), "--linear-solver", linear_solver]
                               + ([] if load_steps is None else ["--load-steps", str(load_steps)]))
        comm.Barrier()
        clock = time.perf_counter()
        problem, context = demo.build_problem(args, comm)
        result = problem.solve(load_steps=args.load_steps)
        wall = comm.allreduce(time.perf_counter() - clock, op=MPI.MAX)
        figures = demo.key_figures(args, problem, result, context, wall)
    finally:
        for key in options:
            db.delValue(PREFIX + key)
    t = problem.timings
    contact = sum(v for k, v in t.items() if k.startswith("contact_"))
    bulk = t.get("bulk_residual", 0.0) + t.get("bulk_jacobian", 0.0)
    # inside SNES: callbacks (contact, bulk) plus the linear solves
    linear = max(t.get("snes_solve", 0.0) - contact - bulk + t.get("contact_setup", 0.0), 0.0)
    timings = {name: comm.allreduce(value, op=MPI.MAX)
               for name, value in (("contact", contact), ("bulk", bulk), ("linear", linear))}
    memory = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    newton = max(result.newton_iterations, 1)
    return {"solver": solver, "refine": refine, "penalty": penalty, "ranks": comm.size,
            "dofs": figures["dofs"], "newton": result.newton_iterations,
            "krylov": result.linear_iterations,
            "krylov_per_newton": result.linear_iterations / newton,
            "wall_time": wall, "contact_time": timings["contact"],
            "bulk_time": timings["bulk"], "linear_time": timings["linear"],
            "contact_share": timings["contact"] / max(wall, 1e-300),
            "peak_memory_mb": memory, "p0_error": figures["p0_error"],
            "a_error": figures["a_error"], "l2_error": figures["l2_error"]}


def markdown(rows: list[dict], load: float, load_steps: int) -> str:
    lines = [f"Hertz 3D, sphere octant on an elastic block (LcLS*, nodal, {load_steps} load "
             f"step{'s' if load_steps > 1 else ''}), "
             f"{MPI.COMM_WORLD.size} rank(s); 1-minute load average before the run "
             f"{load:.2f} on {os.cpu_count()} cores. Times in s; memory is the peak "
             "resident size of the process(es) so far, summed over ranks.", "",
             "| solver | refine | ε·h/E | ranks | dofs | Newton | Krylov | Krylov/Newton "
             "| wall s | contact s | bulk s | linear s | contact share | peak MB "
             "| p0 err | a err | L2 err |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(
            f"| {r['solver']} | {r['refine']:g} | {r['penalty']:.0e} | {r['ranks']} "
            f"| {r['dofs']} | {r['newton']} | {r['krylov']} | {r['krylov_per_newton']:.1f} "
            f"| {r['wall_time']:.1f} | {r['contact_time']:.1f} | {r['bulk_time']:.1f} "
            f"| {r['linear_time']:.1f} | {100 * r['contact_share']:.0f}% "
            f"| {r['peak_memory_mb']:.0f} | {100 * r['p0_error']:+.2f}% "
            f"| {100 * r['a_error']:+.2f}% | {100 * r['l2_error']:.2f}% |")
    return "\n".join(lines) + "\n"


def main(argv: Optional[Sequence[str]] = None) -> list[dict]:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    load = os.getloadavg()[0]
    demo = load_demo("hertz3d")
    rows = []
    for refine in args.levels:
        for penalty in args.penalties:
            for solver in args.solvers:
                try:
                    rows.append(run_one(demo, solver, refine, penalty, args.load_steps))
                except Exception as error:  # a solver that fails is a result too
                    if comm.rank == 0:
                        print(f"{solver} refine {refine:g} ε {penalty:.0e}: FAILED: "
                              f"{str(error).splitlines()[0]}", flush=True)
                    continue
                if comm.rank == 0:
                    write_results(rows, args, load, load_steps_of(args, demo))  # a long study
                    r = rows[-1]
                    print(f"{solver} refine {refine:g} ε {penalty:.0e}: {r['dofs']} dofs, "
                          f"Newton {r['newton']}, Krylov/Newton {r['krylov_per_newton']:.1f}, "
                          f"{r['wall_time']:.1f} s", flush=True)
                gc.collect()
    if comm.rank == 0:
        print(markdown(rows, load, load_steps_of(args, demo)))
    return rows


def load_steps_of(args: argparse.Namespace, demo) -> int:
    """The load steps of the runs: ``--load-steps``, or the demo's default."""
    return args.load_steps or demo.parse_args([]).load_steps


def write_results(rows: list[dict], args: argparse.Namespace, load: float,
                  load_steps: int) -> None:
    """The table so far as CSV and markdown (atomically: an interrupted study
    leaves the rows it finished)."""
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    stem = "krylov_scaling" + (f"_{args.tag}" if args.tag else "")
    table = markdown(rows, load, load_steps)
    write_csv(out / f"{stem}.csv", rows, COLUMNS)
    write_atomically(out / f"{stem}.md", lambda tmp: Path(tmp).write_text(table))


if __name__ == "__main__":
    main()
