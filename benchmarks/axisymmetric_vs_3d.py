"""Hertz sphere on a rigid plane: the (r, z) axisymmetric model against the 3D one.

Runs ``demos/hertz_axisymmetric.py`` and ``demos/hertz3d.py`` (their ``main``,
same sphere, load, material, kind and penalty rule) at several mesh levels in
one process and tabulates the errors of the peak pressure p0 and of the contact
radius a against Hertz, the L2 error of the pressure, the dofs and the wall
time, so that the two can be compared at equal accuracy or equal time.

    OMP_NUM_THREADS=1 python3 benchmarks/axisymmetric_vs_3d.py [--out DIR]

Writes ``axisymmetric_vs_3d.{csv,md,png}`` into ``--out`` (default
``benchmarks/results/``).
"""
from __future__ import annotations

import argparse
import gc
import os
from pathlib import Path
from typing import Optional, Sequence

from mpi4py import MPI

from demo_support.scripts import load_demo
from dolfinx_mortar.io.output import save_figure, write_atomically, write_csv

HERE = Path(__file__).resolve().parent
COLUMNS = ("model", "refine", "dofs", "p0_error", "a_error", "l2_error", "newton_iterations",
           "wall_time")


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--axisymmetric-refine", type=float, nargs="+",
                        default=[0.25, 0.5, 1.0, 2.0])
    parser.add_argument("--3d-refine", dest="refine_3d", type=float, nargs="+",
                        default=[0.5, 1.0, 1.5])
    parser.add_argument("--out", default=str(HERE / "results"))
    return parser.parse_args(argv)


def markdown(rows: list[dict]) -> str:
    lines = ["Hertz sphere on a rigid plane (R = 1, E = 1, ν = 0.3, F = 0.0015, LcLS*, "
             f"ε = 1e3 E/h), {MPI.COMM_WORLD.size} rank(s); 1-minute load average before the "
             f"run {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores.", "",
             "| model | refine | dofs | p0 error | a error | L2 error | Newton | wall s |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['model']} | {r['refine']:g} | {r['dofs']} | {100 * r['p0_error']:+.2f}% "
                     f"| {100 * r['a_error']:+.2f}% | {100 * r['l2_error']:.2f}% "
                     f"| {r['newton_iterations']} | {r['wall_time']:.1f} |")
    return "\n".join(lines) + "\n"


def plot(path: Path, rows: list[dict]) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for model, marker in (("axisymmetric", "o"), ("3D", "s")):
        own = [r for r in rows if r["model"] == model]
        ax.loglog([r["wall_time"] for r in own], [abs(r["p0_error"]) for r in own],
                  marker=marker, label=f"{model}: |p0 error|")
    ax.set_xlabel("wall time of the solve (s)")
    ax.set_ylabel("|p0 / p0_Hertz − 1|")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    ax.set_title("Hertz sphere: speed against error")
    save_figure(path, fig, dpi=120)
    plt.close(fig)


def main(argv: Optional[Sequence[str]] = None) -> list[dict]:
    args = parse_args(argv)
    runs = ([("axisymmetric", "hertz_axisymmetric", r) for r in args.axisymmetric_refine]
            + [("3D", "hertz3d", r) for r in args.refine_3d])
    demos = {name: load_demo(name) for _, name, _ in runs}
    rows = []
    for model, name, refine in runs:
        figures = demos[name].main(["--refine", str(refine)])
        rows.append({"model": model, "refine": refine,
                     **{key: figures[key] for key in COLUMNS if key in figures}})
        gc.collect()
    out = Path(args.out)
    if MPI.COMM_WORLD.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
        table = markdown(rows)
        print(table)
        write_csv(out / "axisymmetric_vs_3d.csv", rows, COLUMNS)
        write_atomically(out / "axisymmetric_vs_3d.md", lambda tmp: Path(tmp).write_text(table))
        plot(out / "axisymmetric_vs_3d.png", rows)
    return rows


if __name__ == "__main__":
    main()
