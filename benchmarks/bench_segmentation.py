"""Segmentation speed: slave–master pairs per second per core, and time per slave facet.

Flat, non-matching, jittered slave and master surfaces (the master ~0.77× as
fine per direction, so ~0.6× the facets) for 2D lines and 3D triangles and
quadrilaterals of degree 1 and 2, from 1e3 to 1e5 slave facets. The segmentation
kernel is single-threaded, so its rate is a rate per core.

    python3 benchmarks/bench_segmentation.py [--max-facets 1e5]
"""
from __future__ import annotations

import argparse
import csv
import math
import resource
import sys
import time
from typing import Optional, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from tqdm import tqdm  # noqa: E402

from dolfinx_mortar.mortar.coupling import MortarCoupling  # noqa: E402
from dolfinx_mortar.io.output import save_figure, write_atomically  # noqa: E402
from dolfinx_mortar.surfaces.structured import flat_line, flat_patch  # noqa: E402

#: name: (cell, degree, facets per lattice square)
CASES = {
    "2D P1 line": ("interval", 1, 1),
    "2D P2 line": ("interval", 2, 1),
    "3D P1 triangle": ("triangle", 1, 2),
    "3D P2 triangle": ("triangle", 2, 2),
    "3D Q1 quad": ("quadrilateral", 1, 1),
    "3D Q2 quad": ("quadrilateral", 2, 1),
}
MASTER_RATIO = 0.77


def surfaces(case: str, facets: int):
    """Slave (normal up) and master (facing down, a tenth of an element above)."""
    cell, degree, per_square = CASES[case]
    if cell == "interval":
        n = facets
        slave = flat_line(degree, n, jitter=0.2)
        master = flat_line(degree, max(1, round(MASTER_RATIO * n)), bounds=(-0.01, 1.01),
                           y=0.1 / n, up=False, jitter=0.2, seed=1)
        return slave, master
    n = max(1, round(math.sqrt(facets / per_square)))
    m = max(1, round(MASTER_RATIO * n))
    slave = flat_patch(cell, degree, n, n, jitter=0.2)
    master = flat_patch(cell, degree, m, m, bounds=(-0.01, 1.01, -0.01, 1.01), z=0.1 / n,
                        up=False, jitter=0.2, seed=1)
    return slave, master


def run(case: str, facets: int) -> dict:
    slave, master = surfaces(case, facets)
    clock = time.perf_counter()
    coupling = MortarCoupling(slave, master)
    total = time.perf_counter() - clock
    t = coupling.timings
    pairs = len(coupling.pairs)
    assert abs(coupling.total_covered_area - 1.0) < 1e-9, coupling.total_covered_area
    return {"case": case, "slave_facets": len(slave.cells), "master_facets": len(master.cells),
            "candidates": coupling.num_candidates, "pairs": pairs,
            "search_s": t["search"], "segmentation_s": t["segmentation"], "total_s": total,
            "pairs_per_s": pairs / t["segmentation"],
            "us_per_slave_facet": 1e6 * (t["search"] + t["segmentation"]) / len(slave.cells)}


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--max-facets", type=float, default=1e5, help="largest slave size (1e5)")
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    parser.add_argument("--csv", default="results/bench_segmentation.csv")
    parser.add_argument("--png", default="results/bench_segmentation.png")
    return parser.parse_args(argv)


def main(argv: Optional[Sequence[str]] = None) -> list[dict]:
    args = parse_args(argv)
    sizes = [s for s in (1e3, 1e4, 1e5, 1e6) if s <= args.max_facets]
    runs = [(c, int(s)) for c in args.cases for s in sizes]
    rows = [run(c, s) for c, s in tqdm(runs, file=sys.stderr, desc="segmentation")]
    print("| case | slave facets | master facets | pairs | search s | segmentation s "
          "| pairs/s/core | µs per slave facet |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['case']} | {r['slave_facets']} | {r['master_facets']} | {r['pairs']} "
              f"| {r['search_s']:.3f} | {r['segmentation_s']:.3f} | {r['pairs_per_s']:.3g} "
              f"| {r['us_per_slave_facet']:.1f} |")

    def write_csv(tmp: str) -> None:
        with open(tmp, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    write_atomically(args.csv, write_csv)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for case in args.cases:
        rs = [r for r in rows if r["case"] == case]
        ax.semilogx([r["slave_facets"] for r in rs], [r["us_per_slave_facet"] for r in rs],
                    "o-", label=case)
    ax.set_xlabel("slave facets")
    ax.set_ylabel("search + segmentation, µs per slave facet")
    ax.set_title("Segmentation cost per slave facet (1 core)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(args.png, fig, dpi=120)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\nwrote {args.csv} and {args.png}; peak memory {rss:.0f} MiB")
    return rows


if __name__ == "__main__":
    main()
