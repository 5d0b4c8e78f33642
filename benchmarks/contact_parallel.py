"""Where the contact work goes on each MPI rank: Hertz 3D with two bodies.

Runs the scene of ``demos/hertz3d.py --obstacle elastic`` (LcLS*, nodal
active set, 3 load steps, the iterative linear solver) once and prints, for
every rank, what it holds of the contact (owned slave nodes, slave facets,
candidate and segmented pairs) and how long its contact phases took: the
master surface gathered and the normals averaged, the box search, the
segmentation, the rest of the setup (bases, the gap operator G), the residual
evaluations and the Jacobian assembly, next to its bulk assembly. A rank that
holds the contact zone alone shows here as the one whose contact time does
not fall with the rank count.

    OMP_NUM_THREADS=1 python3 benchmarks/contact_parallel.py --refine 2
    mpirun -n 2 python3 benchmarks/contact_parallel.py --refine 2 [--profile]

``--partitioner graph`` uses DOLFINx's graph partition alone, as before the
contact-balanced partitioner (the default).

Writes ``contact_parallel_{partitioner}_n{ranks}.csv`` into ``--out`` (default
``benchmarks/results/``); ``--profile`` also writes each rank's cProfile of
the solve (cumulative, the 40 most expensive) as
``contact_parallel_{partitioner}_n{ranks}_rank{r}.txt``.
"""
from __future__ import annotations

import argparse
import cProfile
import io
import os
import pstats
import time
from pathlib import Path
from typing import Optional, Sequence

from mpi4py import MPI

from demo_support.scripts import load_demo
from dolfinx_mortar.io.output import write_csv

HERE = Path(__file__).resolve().parent
PHASES = ("normals_and_gather", "search", "segmentation", "setup_rest", "residual",
          "jacobian", "contact_total", "bulk", "wall")
#: the printed table: title, row key, format
TABLE = [("rank", "rank", "d"), ("owned slave nodes", "owned_slave_nodes", "d"),
         ("slave facets", "slave_facets", "d"), ("candidates", "candidates", "d"),
         ("pairs", "pairs", "d"), ("gather+normals", "normals_and_gather", ".2f"),
         ("search", "search", ".2f"), ("segmentation", "segmentation", ".2f"),
         ("rest of setup", "setup_rest", ".2f"), ("residuals", "residual", ".2f"),
         ("Jacobians", "jacobian", ".2f"), ("contact", "contact_total", ".2f"),
         ("bulk", "bulk", ".2f"), ("wall", "wall", ".1f")]
COLUMNS = ("rank", "dofs", "newton", "krylov", "owned_slave_nodes", "slave_facets",
           "candidates", "pairs") + PHASES


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--refine", type=float, default=1.0, help="hertz3d --refine (1)")
    parser.add_argument("--penalty", type=float, default=1e3, help="ε as a multiple of E/h")
    parser.add_argument("--linear-solver", default="iterative",
                        choices=("iterative", "direct"))
    parser.add_argument("--partitioner", default="graph", choices=("graph", "contact"),
                        help="hertz3d --partitioner: contact cells dealt out evenly "
                             "(contact) or DOLFINx's graph partition alone (graph)")
    parser.add_argument("--profile", action="store_true",
                        help="also write each rank's cProfile of the solve")
    parser.add_argument("--out", default=str(HERE / "results"))
    return parser.parse_args(argv)


def rank_row(problem, result, wall: float) -> dict:
    """This rank's contact holdings and phase times (s), with the solve's size
    and iteration counts."""
    contact = problem.contact
    coupling = contact.source.coupling
    t = problem.timings
    split = dict(coupling.timings) if coupling is not None else {}
    setup = t.get("contact_setup", 0.0)
    V = problem.V
    row = {"rank": problem.mesh.comm.rank,
           "dofs": V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
           "newton": result.newton_iterations, "krylov": result.linear_iterations,
           "owned_slave_nodes": len(problem.slave.owned_nodes),
           "slave_facets": len(problem.slave.cells),
           "candidates": getattr(coupling, "num_candidates", 0),
           "pairs": len(coupling.pairs) if coupling is not None else 0,
           "normals_and_gather": split.get("normals_and_gather", 0.0),
           "search": split.get("search", 0.0),
           "segmentation": split.get("segmentation", 0.0),
           "setup_rest": max(setup - sum(split.values()), 0.0),
           "residual": t.get("contact_residual", 0.0),
           "jacobian": t.get("contact_jacobian", 0.0),
           "bulk": t.get("bulk_residual", 0.0) + t.get("bulk_jacobian", 0.0),
           "wall": wall}
    row["contact_total"] = sum(v for k, v in t.items() if k.startswith("contact_"))
    return row


def table(rows: list[dict], load: float, partitioner: str) -> str:
    r0 = rows[0]
    lines = [f"Hertz 3D two bodies, {r0['dofs']} dofs, {len(rows)} rank(s), {partitioner} "
             f"partition, "
             f"{r0['newton']} Newton and {r0['krylov']} Krylov iterations; 1-minute load "
             f"average before the run {load:.2f} on {os.cpu_count()} cores; times in s", "",
             "| " + " | ".join(title for title, _, _ in TABLE) + " |",
             "|" + "---|" * len(TABLE)]
    lines += ["| " + " | ".join(f"{r[key]:{spec}}" for _, key, spec in TABLE) + " |"
              for r in rows]
    return "\n".join(lines) + "\n"


def main(argv: Optional[Sequence[str]] = None) -> list[dict]:
    args, comm, load = parse_args(argv), MPI.COMM_WORLD, os.getloadavg()[0]
    demo = load_demo("hertz3d")
    demo_args = demo.parse_args(["--obstacle", "elastic", "--refine", str(args.refine),
                                 "--penalty", str(args.penalty),
                                 "--linear-solver", args.linear_solver,
                                 "--partitioner", args.partitioner])
    profiler = cProfile.Profile() if args.profile else None
    comm.Barrier()
    clock = time.perf_counter()
    if profiler:
        profiler.enable()
    problem, _ = demo.build_problem(demo_args, comm)
    result = problem.solve(load_steps=demo_args.load_steps)
    if profiler:
        profiler.disable()
    wall = time.perf_counter() - clock
    rows = comm.gather(rank_row(problem, result, wall))
    out = Path(args.out)
    stem = f"contact_parallel_{args.partitioner}_n{comm.size}"
    if profiler:
        text = io.StringIO()
        pstats.Stats(profiler, stream=text).sort_stats("cumulative").print_stats(40)
        out.mkdir(parents=True, exist_ok=True)
        (out / f"{stem}_rank{comm.rank}.txt").write_text(text.getvalue())
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
        write_csv(out / f"{stem}.csv", rows, COLUMNS)
        print(table(rows, load, args.partitioner))
    return rows or []


if __name__ == "__main__":
    main()
