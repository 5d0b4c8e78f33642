"""One Newton iteration of Hertz 3D with two bodies, MUMPS against the
iterative path on the same mesh: its wall time, its linear solve and the peak
memory of the process.

For the sizes where a whole MUMPS solve takes hours (about 2.6 h near 500k
dofs: every Newton iteration is a new factorization), one iteration tells
whether MUMPS fits in memory and what each of its iterations costs next to
the iterative path's; a whole solve is that times its Newton iterations.
The iteration is the first of the first load step, from u = 0 (the gap-closing
start of the load-path solver is not applied).

    OMP_NUM_THREADS=1 python3 benchmarks/first_newton_iteration.py --refine 5 \\
        --solver direct

Appends a row to ``first_newton_iteration.{csv,md}`` in ``--out``
(default ``benchmarks/results/``).
"""
from __future__ import annotations

import argparse
import csv
import os
import resource
import time
from pathlib import Path

from mpi4py import MPI

from demo_support.scripts import load_demo
from dolfinx_mortar.io.output import write_atomically, write_csv

HERE = Path(__file__).resolve().parent
COLUMNS = ("solver", "refine", "ranks", "dofs", "setup_s", "iteration_s", "linear_s",
           "krylov", "peak_memory_gb", "load_average", "reason")


def peak_memory_gb(comm: MPI.Comm) -> float:
    """The peak resident memory of all ranks' processes, summed, in GB."""
    return comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0 ** 2)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--refine", type=float, default=2.0, help="hertz3d --refine (2)")
    parser.add_argument("--solver", default="direct", choices=("direct", "iterative"))
    parser.add_argument("--out", default=str(HERE / "results"))
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    load = os.getloadavg()[0]
    demo = load_demo("hertz3d")
    dargs = demo.parse_args(["--obstacle", "elastic", "--refine", str(args.refine),
                             "--linear-solver", args.solver])
    clock = time.perf_counter()
    problem, context = demo.build_problem(dargs, comm)
    setup = comm.allreduce(time.perf_counter() - clock, op=MPI.MAX)
    problem.set_load(1.0 / dargs.load_steps)
    solver = problem.solver
    with solver.options():
        snes = solver.create_snes()
        snes.setTolerances(max_it=1)
        x = problem.u.x.petsc_vec.copy()
        comm.Barrier()
        clock = time.perf_counter()
        snes.solve(None, x)
        iteration = comm.allreduce(time.perf_counter() - clock, op=MPI.MAX)
        krylov = snes.getLinearSolveIterations()
        reason = f"{snes.getConvergedReason()}/{snes.getKSP().getConvergedReason()}"
        if args.solver == "direct":
            # MUMPS's own verdict: INFOG(1) < 0 is a failure (e.g. -9, -13:
            # not enough memory), INFOG(17)/INFOG(16) its memory estimates (MB)
            factor = snes.getKSP().getPC().getFactorMatrix()
            reason += (f" INFOG(1)={factor.getMumpsInfog(1)} INFO(2)={factor.getMumpsInfo(2)}"
                       f" INFOG(17)={factor.getMumpsInfog(17)}MB")
        snes.destroy()
    t = problem.timings
    callbacks = sum(v for k, v in t.items() if k.startswith(("contact_", "bulk_"))
                    and k != "contact_setup")
    row = {"solver": "MUMPS" if args.solver == "direct" else "iterative",
           "refine": args.refine, "ranks": comm.size, "dofs": problem.u.x.petsc_vec.getSize(),
           "setup_s": setup, "iteration_s": iteration,
           "linear_s": comm.allreduce(max(iteration - callbacks, 0.0), op=MPI.MAX),
           "krylov": krylov, "peak_memory_gb": peak_memory_gb(comm), "load_average": load,
           "reason": reason}
    if comm.rank == 0:
        out = Path(args.out)
        csv_path = out / "first_newton_iteration.csv"
        rows = []
        if csv_path.exists():
            with open(csv_path, newline="") as f:
                rows = list(csv.DictReader(f))
        rows.append(row)
        write_csv(csv_path, rows, COLUMNS)
        table = ["| solver | refine | ranks | dofs | setup s | iteration s | linear solve s | "
                 "Krylov | peak memory GB | load average | SNES/KSP reason |",
                 "|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            table.append(f"| {r['solver']} | {float(r['refine']):g} | {r['ranks']} | {r['dofs']} | "
                         f"{float(r['setup_s']):.1f} | {float(r['iteration_s']):.1f} | "
                         f"{float(r['linear_s']):.1f} | {r['krylov']} | "
                         f"{float(r['peak_memory_gb']):.2f} | {float(r['load_average']):.2f} | "
                         f"{r.get('reason', '')} |")
        markdown = "\n".join(table) + "\n"
        write_atomically(out / "first_newton_iteration.md",
                         lambda tmp: Path(tmp).write_text(markdown))
        print(markdown, flush=True)

if __name__ == "__main__":
    main()
