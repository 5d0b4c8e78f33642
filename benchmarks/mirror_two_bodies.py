"""The mirror test as a table: two equal bodies pressed together against one of them on a
rigid plane (demos/demo_support/mirror.py), node by node, at several mesh sizes.

    python3 benchmarks/mirror_two_bodies.py [--dim 2|3] [--axisymmetric] [--sizes 20 40 80]
        [--kinds LcLS* ...] [--active-sets nodal pointwise] [--configurations initial ...]

Prints one row per kind, active set and basis configuration: the relative L2 difference of
the nodal pressures, the difference of the contact forces and the wall time of both solves,
per size; writes the rows as CSV (--csv).
"""
from __future__ import annotations

import argparse
import time

from mpi4py import MPI

from demo_support.mirror import mirror
from dolfinx_mortar import KIND_NAMES
from dolfinx_mortar.io.output import write_csv


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dim", type=int, default=2, choices=(2, 3))
    parser.add_argument("--axisymmetric", action="store_true")
    parser.add_argument("--sizes", type=int, nargs="+", default=[20, 40, 80])
    parser.add_argument("--d", type=float, default=0.02, help="pressed distance d (0.02)")
    parser.add_argument("--kinds", nargs="+", default=list(KIND_NAMES))
    parser.add_argument("--active-sets", nargs="+", default=["nodal", "pointwise"])
    parser.add_argument("--configurations", nargs="+",
                        default=["initial", "previous", "current"])
    parser.add_argument("--csv", default=None, help="write the rows here")
    args = parser.parse_args()
    rows = []
    for kind in args.kinds:
        for active_set in args.active_sets:
            for configuration in args.configurations:
                cells = []
                for n in args.sizes:
                    clock = time.perf_counter()
                    row = dict(dim=args.dim, axisymmetric=args.axisymmetric, kind=kind,
                               active_set=active_set, configuration=configuration, n=n)
                    try:
                        r = mirror(n, args.d, dim=args.dim, axisymmetric=args.axisymmetric,
                                   penalty=1e3 * n, kind=kind, active_set=active_set,
                                   basis_configuration=configuration)
                        row.update(pressure_difference=r.pressure_difference,
                                   force_difference=r.force_difference)
                        cell = f"{r.pressure_difference:8.1e} (F {r.force_difference:+.0e})"
                    except Exception as err:   # a failed combination is a row, not the end
                        row.update(error=f"{type(err).__name__}: {err}"[:200])
                        cell = f"failed: {type(err).__name__}"
                    row["wall_time"] = time.perf_counter() - clock
                    rows.append(row)
                    cells.append(f"{cell} {row['wall_time']:4.1f} s")
                if MPI.COMM_WORLD.rank == 0:
                    print(f"{kind:6s} {active_set:9s} {configuration:9s} | "
                          + " | ".join(cells), flush=True)
    if args.csv and MPI.COMM_WORLD.rank == 0:
        write_csv(args.csv, rows, columns=["dim", "axisymmetric", "kind", "active_set",
                                           "configuration", "n", "pressure_difference",
                                           "force_difference", "wall_time", "error"])


if __name__ == "__main__":
    main()
