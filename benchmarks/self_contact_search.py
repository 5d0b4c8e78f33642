"""The cost of a surface's search against itself (self-contact) against its size S.

Two parallel square plates 1 apart (n×n squares of two triangles each, the lower facing up and
the upper down, 0.02 of a cell apart... see SEPARATION), given as ONE surface searched against
itself (``MortarCoupling(surface, surface, self_contact=True)``): the facets of each plate face
the other plate's. The table gives, per S = 4n² facets, the wall time of the candidate search
(bounding boxes, the kernels' box pairing, and the exclusion of each facet's neighbours), of the
segmentation and mortar integrals, the candidates and the pairs, and the search time per facet:
O(S log S) shows as a slowly growing time per facet.

    python3 benchmarks/self_contact_search.py [--sizes 16 50 158] [--csv F] [--png F]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from dolfinx_mortar.layout import NodeLayout
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

#: the plates' distance in cell sizes
SEPARATION = 0.5


def plates(n: int) -> LagrangeSurface:
    """The two plates as one P1 triangle surface, normals facing each other."""
    h = 1.0 / n
    g = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(g, g, indexing="ij")
    grid = np.column_stack([X.ravel(), Y.ravel()])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    up = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])     # normal +z
    lower = np.column_stack([grid, np.zeros(len(grid))])
    upper = np.column_stack([grid, np.full(len(grid), SEPARATION * h)])
    x = np.vstack([lower, upper])
    cells = np.vstack([up, up[:, ::-1] + len(grid)])                               # normal −z
    return LagrangeSurface("triangle", 1, x, cells, layout=NodeLayout.serial(len(x)))


def main(argv=None) -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[16, 50, 158])
    parser.add_argument("--csv")
    parser.add_argument("--png")
    args = parser.parse_args(argv)
    rows = []
    for n in args.sizes:
        surface = plates(n)
        clock = time.perf_counter()
        coupling = MortarCoupling(surface, surface, self_contact=True)
        total = time.perf_counter() - clock
        S = len(surface.cells)
        t = coupling.timings
        rows.append({"facets": S, "search_s": t["search"],
                     "segmentation_s": total - t["search"] - t["normals_and_gather"],
                     "normals_s": t["normals_and_gather"], "total_s": total,
                     "candidates": coupling.num_candidates, "pairs": len(coupling.pairs),
                     "search_us_per_facet": 1e6 * t["search"] / S})
        r = rows[-1]
        print(f"S = {S:7d}: search {r['search_s']:.3f} s ({r['search_us_per_facet']:.1f} µs/facet), "
              f"segmentation {r['segmentation_s']:.3f} s, candidates {r['candidates']}, "
              f"pairs {r['pairs']}", flush=True)
    if args.csv:
        from dolfinx_mortar.io.output import write_csv
        write_csv(args.csv, rows)
    if args.png:
        import matplotlib.pyplot as plt
        from dolfinx_mortar.io.output import save_figure
        fig, ax = plt.subplots(figsize=(5, 3.5))
        S = [r["facets"] for r in rows]
        ax.loglog(S, [r["search_s"] for r in rows], "o-", label="search (boxes, pairing, neighbours)")
        ax.loglog(S, [r["segmentation_s"] for r in rows], "s-", label="segmentation, integrals")
        ax.set(xlabel="facets S", ylabel="wall time (s)")
        ax.legend()
        fig.tight_layout()
        save_figure(args.png, fig)
    return rows


if __name__ == "__main__":
    main()
