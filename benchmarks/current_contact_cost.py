"""The contact work of a Newton iteration against the bulk assembly's, on Hertz 3D
with two elastic bodies: ``basis_configuration="current"`` (segmentation, exact
gradients and Hessians from ``current_pair_gaps``, contact assembly) and, for
comparison on the same mesh, ``"initial"``.

    OMP_NUM_THREADS=1 python3 benchmarks/current_contact_cost.py --refine 1.5
"""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from mpi4py import MPI

from demo_support.scripts import load_demo
from dolfinx_mortar.io.output import write_csv

COLUMNS = ("configuration", "dofs", "newton", "wall_time", "contact_time", "bulk_time",
           "contact_per_newton", "bulk_per_newton", "contact_over_bulk",
           "contact_residual_per_newton", "contact_jacobian_per_newton", "full_steps",
           "cut_steps", "p0_error", "a_error")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--refine", type=float, default=1.5)
    parser.add_argument("--load-steps", type=int, default=1)
    parser.add_argument("--configurations", nargs="+", default=["current", "initial"])
    parser.add_argument("--partitioner", default="graph", choices=("graph", "contact"),
                        help="hertz3d --partitioner, for runs on several ranks (graph)")
    parser.add_argument("--out", default="benchmarks/results/current_contact_cost")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    demo = load_demo("hertz3d")
    load = os.getloadavg()[0]
    rows = []
    for configuration in args.configurations:
        dargs = demo.parse_args(["--obstacle", "elastic", "--refine", str(args.refine),
                                 "--basis-configuration", configuration,
                                 "--load-steps", str(args.load_steps),
                                 "--partitioner", args.partitioner])
        clock = time.perf_counter()
        problem, context = demo.build_problem(dargs, comm)
        result = problem.solve(load_steps=dargs.load_steps)
        wall = time.perf_counter() - clock
        figures = demo.key_figures(dargs, problem, result, context, wall)
        t = problem.timings
        contact = comm.allreduce(sum(v for k, v in t.items() if k.startswith("contact_")),
                                 op=MPI.MAX)
        bulk = comm.allreduce(t.get("bulk_residual", 0.0) + t.get("bulk_jacobian", 0.0),
                              op=MPI.MAX)
        newton = max(result.newton_iterations, 1)
        parts = {key: comm.allreduce(t.get(f"contact_{key}", 0.0), op=MPI.MAX) / newton
                 for key in ("residual", "jacobian")}
        # the current-surface line search: steps taken in full and cut
        line_search = problem.solver.line_search
        rows.append({"configuration": configuration, "dofs": figures["dofs"],
                     "newton": result.newton_iterations, "wall_time": wall,
                     "contact_time": contact, "bulk_time": bulk,
                     "contact_per_newton": contact / newton, "bulk_per_newton": bulk / newton,
                     "contact_over_bulk": contact / bulk,
                     "contact_residual_per_newton": parts["residual"],
                     "contact_jacobian_per_newton": parts["jacobian"],
                     "full_steps": line_search.full_steps if line_search else 0,
                     "cut_steps": line_search.cut_steps if line_search else 0,
                     "p0_error": figures["p0_error"],
                     "a_error": figures["a_error"]})
        if comm.rank == 0:
            print(rows[-1], flush=True)
    if comm.rank == 0:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        write_csv(args.out + ".csv", rows, COLUMNS)
        lines = [f"Hertz 3D, two bodies, refine {args.refine}, {args.load_steps} load step(s), "
                 f"{comm.size} rank(s), {args.partitioner} partition; load average {load:.2f} at the start", "",
                 "| configuration | dofs | Newton | wall s | contact s / Newton (residuals + "
                 "Jacobian) | bulk assembly s / Newton | contact / bulk | full / cut steps | "
                 "p0 err | a err |",
                 "|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            lines.append(f"| {r['configuration']} | {r['dofs']} | {r['newton']} | "
                         f"{r['wall_time']:.1f} | {r['contact_per_newton']:.3f} "
                         f"({r['contact_residual_per_newton']:.3f} + "
                         f"{r['contact_jacobian_per_newton']:.3f}) | "
                         f"{r['bulk_per_newton']:.3f} | {r['contact_over_bulk']:.2f} | "
                         f"{r['full_steps']} / {r['cut_steps']} | "
                         f"{100 * r['p0_error']:+.2f}% | {100 * r['a_error']:+.2f}% |")
        Path(args.out + ".md").write_text("\n".join(lines) + "\n")
        print("\n".join(lines))


if __name__ == "__main__":
    main()
