"""Table of the hard cases (issue 5): one row per case, variant and kind.

Runs the scenes of hard_case_scenes.py, checks each against its pass
criterion (the same as tests/contact/test_hard_cases.py), prints a table and writes
results/hard_cases.csv (metric, value, criterion, verdict per row).

    python3 benchmarks/hard_cases.py [--skip-slow] [--cases sweep penalty ...]
"""
from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent))
import hard_case_scenes as scenes  # noqa: E402

K = scenes.ALL_KINDS
CASES = ("sweep", "sweep-elastic", "quadratic", "ratio", "penalty", "grazing", "coincident",
         "spurious-gap", "cylinders", "spheres")
SLOW = ("spheres",)
#: kinds not run for a case (with the reason printed in the table)
NOT_RUN: dict = {}


def rows_of(case: str):
    """(criterion case, variant, row) triples of one case."""
    if case == "sweep":
        for r in scenes.sweep():
            v = "modified" if r["boundary_modification"] else "plain"
            yield "sweep-jacobian", v, r
            yield "sweep-contact-block", v, r
            if r["boundary_modification"]:
                yield "sweep-modified-coefficients", v, r
    elif case == "sweep-elastic":
        for dim in (2, 3):
            for kind, modified in ([(k, False) for k in K]
                                   + [(k, True) for k in scenes.DUAL_KINDS]):
                r = scenes.elastic_sweep(kind, modified, dim=dim)
                v = f"{dim}D " + ("modified" if modified else "plain")
                yield "sweep-elastic", v, r
                yield "sweep-elastic-pressure", v, r
    elif case == "quadratic":
        for kind in K:
            for v in ("P2-triangle", "Q8", "Q9"):
                yield "quadratic-identities", v, scenes.quadratic_identities(kind, v)
        for kind in K:
            for o in ("finer-slave", "finer-master"):
                yield "patch", f"P2-tet {o}", scenes.patch_test_run(kind, 3, 2, 0.35, 0.5, o)
    elif case == "ratio":
        for kind in K:
            for o in ("finer-slave", "finer-master"):
                yield "patch", f"1:10 {o}", scenes.patch_test_run(kind, 2, 1, 0.02, 0.2, o)
    elif case == "penalty":
        for kind in K:
            yield "penalty", "hertz2d eps=1e1..1e4 E/h", scenes.penalty_sweep(kind)
    elif case == "grazing":
        for kind in K:
            yield "grazing", "disk on plane + shear", scenes.grazing(kind)
    elif case == "coincident":
        for kind in K:
            for cell, mirror in (("tetrahedron", False), ("tetrahedron", True),
                                 ("hexahedron", False)):
                r = scenes.coincident_patch(kind, cell, mirror)
                yield "coincident", r["variant"], r
    elif case == "spurious-gap":
        for kind in K:
            yield "spurious-gap", "cylinders, zero load", scenes.spurious_gap(kind)
    elif case in ("cylinders", "spheres"):
        for kind in K:
            if (case, kind) in NOT_RUN:
                yield case, NOT_RUN[case, kind], {"kind": kind, "skipped": True}
                continue
            f = scenes.two_cylinders if case == "cylinders" else scenes.two_spheres
            yield case, "Hertz", f(kind)


def summary(case: str, row: dict) -> str:
    """A few key numbers of a row for the printed table."""
    if row.get("skipped"):
        return ""
    if case.startswith("sweep-elastic"):
        return ("cond J " + ", ".join(f"{c:.2e}" for c in row["cond_J"])
                + "; max|p|/median p " + ", ".join(f"{r:.3g}" for r in row["p_ratio"])
                + f" (slivers {row['slivers']})")
    if case.startswith("sweep"):
        cJ, cD = row["cond_J"], row["cond_D"]
        c = np.asarray(row["max_coefficient"])
        return (f"cond J {min(cJ):.2e}..{max(cJ):.2e}; cond D {min(cD):.2e}..{max(cD):.2e}; "
                f"max|C| {np.nanmin(c):.2g}..{np.nanmax(c):.2g}")
    if case == "penalty":
        return ("pen " + ", ".join(f"{p:.2e}" for p in row["penetration"])
                + "; cond J " + ", ".join(f"{c:.1e}" for c in row["cond_J"])
                + f"; Newton {row['newton']}")
    if case == "grazing":
        if not row["converged"]:
            return f"diverged at load {row['failed_load']:.3g}"
        return (f"Newton {row['newton']} (first step {row['first_step_iterations']}); "
                f"p in [{row['p_min']:.2g}, {row['p_max']:.3g}]; "
                f"centre {row['pressure_centre']:+.4f}")
    if case == "spheres":
        return (f"Newton {row['newton']}, dofs {row['dofs']}, {row['wall_time']:.0f} s; "
                f"largest nodal p {100 * row['p0_max_error']:+.0f}% of p0")
    if case == "cylinders":
        return f"Newton {row['newton']}, dofs {row['dofs']}"
    if case == "patch":
        return f"Newton {row['newton_iterations']}, slave nodes {row['slave_nodes']}"
    return ""


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=CASES)
    parser.add_argument("--skip-slow", action="store_true", help=f"skip {SLOW}")
    parser.add_argument("--csv", default="results/hard_cases.csv")
    args = parser.parse_args(argv)
    rank0 = MPI.COMM_WORLD.rank == 0
    records = []
    for case in args.cases:
        if args.skip_slow and case in SLOW:
            continue
        clock = time.perf_counter()
        for crit, variant, row in rows_of(case):
            if row.get("skipped"):
                records.append((crit, variant, row["kind"], "-", "", "", "NOT RUN", ""))
                continue
            checks = scenes.check(crit, row)
            verdict = "pass" if all(c[4] for c in checks) else "FAIL"
            metrics = "; ".join(f"{m}={v:.3g}" for m, v, *_ in checks)
            criteria = "; ".join(f"{m}{op}{lim:g}" for m, _, op, lim, _ in checks)
            records.append((crit, variant, row["kind"], metrics, criteria, "",
                            verdict, summary(crit, row)))
        if rank0:
            print(f"[{case}: {time.perf_counter() - clock:.1f} s]", flush=True)
    if rank0:
        print(f"\n{'case':<28s} {'variant':<24s} {'kind':<6s} {'verdict':<7s} metrics | details")
        for crit, variant, kind, metrics, criteria, _, verdict, extra in records:
            print(f"{crit:<28s} {variant[:24]:<24s} {kind:<6s} {verdict:<7s} {metrics}"
                  + (f" | {extra}" if extra else ""))
        path = Path(args.csv)
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["case", "variant", "kind", "metrics", "criteria", "verdict", "details"])
            for crit, variant, kind, metrics, criteria, _, verdict, extra in records:
                w.writerow([crit, variant, kind, metrics, criteria, verdict, extra])
        print(f"\nwritten {path}")
    return records


if __name__ == "__main__":
    main()
