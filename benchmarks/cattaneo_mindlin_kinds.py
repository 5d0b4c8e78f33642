"""Cattaneo–Mindlin's stick zone for every kind at two mesh sizes.

Runs demos/cattaneo_mindlin.py (two equal cylinders, Q/μP = 0.5) for each
kind and refinement asked for and prints c against (1 − Q/μP)^½ a, the
contact half-width against Hertz, the L2 error of the tangential traction
against Johnson's profile, the Newton iterations and the wall time, in one
run so that the rows compare like with like. Writes one CSV row per run.

    python3 benchmarks/cattaneo_mindlin_kinds.py --csv results/cattaneo_mindlin_kinds.csv
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "demos"))
import cattaneo_mindlin  # noqa: E402

from dolfinx_mortar import ContactDivergenceError  # noqa: E402
from dolfinx_mortar.io.output import write_csv  # noqa: E402

KINDS = ("LcLS*", "LcLS", "LmLS*", "LmLS", "GLS", "GLS*")
COLUMNS = ("kind", "refine", "dofs", "a_error", "c_error", "q_l2_error", "newton_iterations",
           "wall_time")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kinds", nargs="+", default=list(KINDS))
    parser.add_argument("--refine", nargs="+", default=["0.5", "1"])
    parser.add_argument("--geometry", default="cylinder", choices=("cylinder", "sphere"))
    parser.add_argument("--csv", default=None)
    args = parser.parse_args()
    rows = []
    for refine in args.refine:
        for kind in args.kinds:
            demo_args = cattaneo_mindlin.parse_args(["--kind", kind, "--refine", refine,
                                                     "--geometry", args.geometry])
            try:
                f = cattaneo_mindlin.run(demo_args, MPI.COMM_WORLD)
            except ContactDivergenceError as error:
                if MPI.COMM_WORLD.rank == 0:
                    print(f"{kind} refine {refine}: Newton failed ({error.args[0][:80]})")
                continue
            rows.append({"kind": kind, "refine": refine, **{k: f[k] for k in COLUMNS[2:]}})
    if MPI.COMM_WORLD.rank != 0:
        return
    print(f"Cattaneo–Mindlin, {args.geometry}, Q/μP = 0.5, {MPI.COMM_WORLD.size} rank(s)")
    print(f"{'kind':7} {'refine':>6} {'dofs':>8} {'a error':>8} {'c error':>8} {'q L2':>7} "
          f"{'Newton':>6} {'wall':>7}")
    for r in rows:
        print(f"{r['kind']:7} {r['refine']:>6} {r['dofs']:>8} {100 * r['a_error']:+7.2f}% "
              f"{100 * r['c_error']:+7.2f}% {100 * r['q_l2_error']:6.2f}% "
              f"{r['newton_iterations']:>6} {r['wall_time']:6.1f}s")
    if args.csv:
        write_csv(args.csv, rows, COLUMNS)


if __name__ == "__main__":
    main()
