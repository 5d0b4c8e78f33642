"""Hertz 3D with two elastic bodies (``demos/hertz3d.py --obstacle elastic``): the L2 error
of the pressure against Hertz and the wall time for each basis configuration at several
mesh sizes, so that a user can pick one.

    OMP_NUM_THREADS=1 python3 benchmarks/hertz3d_two_bodies.py [--refine 0.75 1 1.5]
        [--configurations initial previous current] [--kind LcLS*] [--csv FILE] [--png FILE]

One row per configuration and size: dofs, L2 error, p0 and a errors of the fitted profile,
Newton iterations, wall time. A configuration the library refuses for the scene is a row
with the refusal, not the end of the table.
"""
from __future__ import annotations

import argparse

from mpi4py import MPI

from demo_support.scripts import load_demo
from dolfinx_mortar.io.output import save_figure, write_csv

COLUMNS = ("configuration", "refine", "dofs", "l2_error", "p0_error", "a_error",
           "newton_iterations", "wall_time", "refused")


def measure(configuration: str, refine: float, kind: str) -> dict:
    hertz3d = load_demo("hertz3d")
    row = {"configuration": configuration, "refine": refine, "refused": ""}
    try:
        figures = hertz3d.run(hertz3d.parse_args(
            ["--obstacle", "elastic", "--refine", str(refine), "--kind", kind,
             "--basis-configuration", configuration]), MPI.COMM_WORLD)
    except NotImplementedError as refusal:
        row["refused"] = str(refusal).split(":")[0]
        return row
    row.update({key: figures[key] for key in COLUMNS if key in figures})
    return row


def plot(path: str, rows: list[dict]) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axis = plt.subplots(figsize=(6, 4))
    for configuration in dict.fromkeys(r["configuration"] for r in rows):
        done = [r for r in rows if r["configuration"] == configuration and not r["refused"]]
        axis.loglog([r["wall_time"] for r in done], [r["l2_error"] for r in done], "o-",
                    label=configuration)
    axis.set_xlabel("wall time (s)")
    axis.set_ylabel("L2 error of the pressure")
    axis.set_title("Hertz 3D, two elastic bodies")
    axis.legend()
    fig.tight_layout()
    save_figure(path, fig, dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--refine", type=float, nargs="+", default=[0.75, 1.0, 1.5])
    parser.add_argument("--configurations", nargs="+",
                        default=["initial", "previous", "current"])
    parser.add_argument("--kind", default="LcLS*")
    parser.add_argument("--csv", default=None)
    parser.add_argument("--png", default=None)
    args = parser.parse_args()
    rows = []
    root = MPI.COMM_WORLD.rank == 0
    if root:
        print("| configuration | refine | dofs | L2 error | p0 error | a error | Newton | wall s |")
        print("|---|---|---|---|---|---|---|---|")
    for configuration in args.configurations:
        for refine in args.refine:
            row = measure(configuration, refine, args.kind)
            rows.append(row)
            if root and row["refused"]:
                print(f"| {configuration} | {refine:g} | refused: {row['refused']} |||||")
            elif root:
                print(f"| {configuration} | {refine:g} | {row['dofs']} | {row['l2_error']:.4f} "
                      f"| {100 * row['p0_error']:+.2f}% | {100 * row['a_error']:+.2f}% "
                      f"| {row['newton_iterations']} | {row['wall_time']:.1f} |", flush=True)
    if root and args.csv:
        write_csv(args.csv, rows, COLUMNS)
    if root and args.png:
        plot(args.png, rows)


if __name__ == "__main__":
    main()
