"""Pairs per second per core of the pair kernels: the values (``mortar_integrals``,
the double instantiation of the pair segmentation), values + gradients and
values + gradients + Hessians (``current_pair_gaps``, the Jet instantiations; also the one
node-weighted Hessian per pair that a Newton matrix asks for),
per facet type, on the wavy patches of :mod:`demo_support.pair_scenes`.

``--before COMMIT`` also times the Python Jets that the kernels replaced (3D P1
triangles, ``pair_gap_3d`` of ``dolfinx_mortar/contact/current_mortar_3d.py`` at
that commit, e.g. 3558d26) on the same pairs.

    OMP_NUM_THREADS=1 python3 benchmarks/current_pair_speed.py --before 3558d26
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from demo_support.pair_scenes import PairScene
from dolfinx_mortar.io.output import write_csv

KINDS = ("P1_line", "P2_line", "P1_triangle", "Q1_quadrilateral")


def median_time(call, repeats: int = 7, budget: float = 0.3) -> float:
    """Median over ``repeats`` runs of the mean time of ``call`` over at least
    ``budget`` seconds (one slow run from a busy machine cannot move it)."""
    samples = []
    for _ in range(repeats):
        n, start = 0, time.perf_counter()
        while True:
            call()
            n += 1
            elapsed = time.perf_counter() - start
            if elapsed >= budget:
                break
        samples.append(elapsed / n)
    return float(np.median(samples))


def python_jets_before(commit: str, scene: PairScene, pairs: np.ndarray) -> float:
    """Seconds per pair of the old Python Jets on the same 3D P1 pairs."""
    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as folder:
        for name in ("jet.py", "current_mortar_3d.py"):
            source = subprocess.run(["git", "-C", str(root), "show",
                                     f"{commit}:dolfinx_mortar/contact/{name}"],
                                    check=True, capture_output=True, text=True).stdout
            source = source.replace("from dolfinx_mortar.contact.jet import",
                                    "from jet import").replace(
                "from dolfinx_mortar.mortar.coupling import MortarCoupling, gather_surface\n", "")
            Path(folder, name).write_text(source)
        sys.path.insert(0, folder)
        try:
            import current_mortar_3d as old
        finally:
            sys.path.remove(folder)
        # each pair's variables as the old code took them: the slave cell's
        # nodes, the other nodes of the triangles around its vertices, the
        # master's; the normals' cells as triples of those
        xs, cells, xm, mcells = scene.xs, scene.cs, scene.xm, scene.cm
        around = {}
        for c, row in enumerate(cells):
            for node in row:
                around.setdefault(int(node), []).append(c)
        jobs = []
        for cs, cm in pairs:
            own = [int(v) for v in cells[cs]]
            order = {v: k for k, v in enumerate(own)}
            normal_cells = []
            for v in own:
                triples = []
                for c in around[v]:
                    triple = []
                    for w in cells[c]:
                        order.setdefault(int(w), len(order))
                        triple.append(order[int(w)])
                    triples.append(tuple(triple))
                normal_cells.append(triples)
            nodes = sorted(order, key=order.get)
            values = np.concatenate([xs[nodes], xm[mcells[cm]]]).ravel()
            jobs.append((values, normal_cells, len(nodes)))

        def run_all():
            for values, normal_cells, n in jobs:
                old.pair_gap_3d(values, normal_cells, n, scene.points, scene.weights, scene.zero)
        return median_time(run_all, repeats=3, budget=1.0) / len(pairs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--before", default=None,
                        help="a commit whose Python Jets to time too (3D P1 triangles)")
    parser.add_argument("--out", default="benchmarks/results/current_pair_speed")
    args = parser.parse_args()
    load = os.getloadavg()[0]
    rows = []
    for kind in KINDS:
        scene = PairScene(kind)
        candidates = np.array([(i, j) for i in range(len(scene.cs))
                               for j in range(len(scene.cm))])
        pairs, _ = scene.values(scene.xs, scene.xm, candidates)
        n = len(pairs)
        values = median_time(lambda: scene.values(scene.xs, scene.xm, pairs)) / n
        gradients = median_time(lambda: scene.jets(scene.xs, scene.xm, pairs, False)) / n
        hessians = median_time(lambda: scene.jets(scene.xs, scene.xm, pairs, True)) / n
        # what a Newton matrix asks for: Σ_A w_A ∂²c_A, one Hessian per pair
        weights = np.ones((n, scene.cs.shape[1]))
        weighted = median_time(lambda: scene.jets(scene.xs, scene.xm, pairs, True,
                                                  node_weights=weights)) / n
        width = scene.jets(scene.xs, scene.xm, pairs[:1]).gradient.shape[2]
        row = {"facet": kind, "pairs": n, "variables_per_pair": width,
               "values_per_s": 1 / values, "gradients_per_s": 1 / gradients,
               "hessians_per_s": 1 / hessians, "weighted_hessians_per_s": 1 / weighted,
               "python_jets_per_s": ""}
        if args.before and kind == "P1_triangle":
            row["python_jets_per_s"] = 1 / python_jets_before(args.before, scene, pairs)
        rows.append(row)
    columns = list(rows[0])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_csv(args.out + ".csv", rows, columns)
    lines = [f"Pairs per second on one core (median of 7; load average {load:.2f} at the start)",
             "", "| facet | pairs | variables (first pair) | values | + gradients | + Hessians | "
             "+ weighted Hessian | Python Jets (before) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        before = (f"{r['python_jets_per_s']:.0f}" if r["python_jets_per_s"] != "" else "—")
        lines.append(f"| {r['facet']} | {r['pairs']} | {r['variables_per_pair']} | "
                     f"{r['values_per_s']:.0f} | {r['gradients_per_s']:.0f} | "
                     f"{r['hessians_per_s']:.0f} | {r['weighted_hessians_per_s']:.0f} | "
                     f"{before} |")
    text = "\n".join(lines)
    Path(args.out + ".md").write_text(text + "\n")
    print(text)


if __name__ == "__main__":
    main()
