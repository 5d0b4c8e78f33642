"""Press and slide over the six basis kinds × three basis configurations.

Runs ``demos/press_and_slide.py`` (its ``main``) at a coarse setting for every
kind (GLS, GLS*, LmLS, LmLS*, LcLS*, LcLS) and ``basis_configuration``
(initial, previous, current) and tabulates, for the steady part of the
slide, the tangential force's ripple (max−min and standard deviation) and
mean relative to the mean normal force, the normal force's ripple, the
Newton iterations and the wall time. A combination the library refuses
(``NotImplementedError``: the GLS kinds on the current surface) or that
diverges (``ContactDivergenceError``) is a row with its reason, not a gap.

    OMP_NUM_THREADS=1 python3 benchmarks/press_and_slide_table.py
    ... --refine 1 --out /tmp/slide    # the demo's default mesh, ~18 runs × 20 s

Writes ``press_and_slide_table.csv`` and ``press_and_slide_table.md`` into
``--out`` (default ``benchmarks/results/``).
"""
from __future__ import annotations

import argparse
import gc
import time
import warnings
from pathlib import Path
from typing import Optional, Sequence

from mpi4py import MPI

from dolfinx_mortar import ContactDivergenceError
from demo_support.scripts import load_demo
from dolfinx_mortar.io.output import write_atomically, write_csv

HERE = Path(__file__).resolve().parent
KINDS = ("GLS", "GLS*", "LmLS", "LmLS*", "LcLS*", "LcLS")
CONFIGURATIONS = ("initial", "previous", "current")
COLUMNS = ("kind", "configuration", "status", "tangential_oscillation", "tangential_std",
           "tangential_mean", "normal_oscillation", "normal_mean", "newton_iterations",
           "max_newton_per_step", "max_terminal_iterations", "load_steps", "requested_steps", "wall_time", "dofs", "h",
           "reason")


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--refine", type=float, default=0.5,
                        help="the demo's --refine (0.5: h = 0.1, a 15-element slide)")
    parser.add_argument("--penalty", type=float, default=1e2,
                        help="the demo's --penalty, a multiple of E/h (1e2)")
    parser.add_argument("--slide-steps", type=int, default=None,
                        help="the demo's --slide-steps (default: its own, 4 per element)")
    parser.add_argument("--predictor", default="linear", choices=("none", "linear"),
                        help="the demo's --predictor (linear)")
    parser.add_argument("--kinds", nargs="+", default=list(KINDS))
    parser.add_argument("--configurations", nargs="+", default=list(CONFIGURATIONS),
                        choices=CONFIGURATIONS)
    parser.add_argument("--out", default=str(HERE / "results"),
                        help="folder of the CSV and markdown tables (benchmarks/results)")
    return parser.parse_args(argv)


def run(demo, kind: str, configuration: str, args: argparse.Namespace) -> dict:
    """One demo run as a table row; refusals and divergence become the row's status."""
    argv = ["--kind", kind, "--configuration", configuration, "--refine", str(args.refine),
            "--penalty", str(args.penalty), "--quiet"]
    if args.slide_steps is not None:
        argv += ["--slide-steps", str(args.slide_steps)]
    argv += ["--predictor", args.predictor]
    row = {"kind": kind, "configuration": configuration}
    clock = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            figures = demo.main(argv)
        except NotImplementedError as error:
            row.update(status="not implemented", reason=str(error))
        except ContactDivergenceError as error:
            last = error.history[-1]
            row.update(status="diverged",
                       reason=f"at t = {error.load_factor:.4g} after {len(error.history)} "
                              f"attempts; last: {last.cause}")
        else:
            row.update({key: figures.get(key) for key in COLUMNS if key in figures})
            row["status"] = "ok" if "normal_mean" in figures else "no steady sliding"
            row["reason"] = "; ".join(sorted({str(w.message).split(":")[0] for w in caught}))
    row["wall_time"] = time.perf_counter() - clock
    return row


def fmt(value, spec: str) -> str:
    return "" if value is None else format(value, spec)


def markdown_table(rows: list[dict], args: argparse.Namespace) -> str:
    h = next((r["h"] for r in rows if r.get("h")), "?")
    lines = [
        f"Press and slide, refine {args.refine:g} (h = {h}), "
        f"ε = {args.penalty:g} E/h, {MPI.COMM_WORLD.size} rank(s), the library's default "
        f"line search (basic; l2 for current), predictor {args.predictor}. Steady sliding: "
        "past 2 element lengths of "
        "slide; F_t, N: tangential and normal force on the obstacle, relative to the mean "
        "normal force N over the slide distance. Steps: converged (requested); more "
        "converged than requested means cut steps. n: the most Newton iterations a step took "
        "after its residual fell to 1e-3 of the step's out-of-balance force (quadratic "
        "convergence: 2–3; a linear rate of 0.1: 8).",
        "",
        "| kind | configuration | status | F_t max−min / N | F_t std / N | F_t mean / N "
        "| N max−min / N | N | Newton (max/step) | n | steps (requested) | wall s | note |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        newton = (f"{r['newton_iterations']} ({r['max_newton_per_step']})"
                  if r.get("newton_iterations") is not None else "")
        steps = (f"{r['load_steps']} ({r['requested_steps']})"
                 if r.get("load_steps") is not None else "")
        lines.append(
            f"| {r['kind']} | {r['configuration']} | {r['status']} "
            f"| {fmt(r.get('tangential_oscillation'), '.2e')} "
            f"| {fmt(r.get('tangential_std'), '.2e')} | {fmt(r.get('tangential_mean'), '+.2e')} "
            f"| {fmt(r.get('normal_oscillation'), '.2e')} | {fmt(r.get('normal_mean'), '.5f')} "
            f"| {newton} | {fmt(r.get('max_terminal_iterations'), 'd')} | {steps} | {r['wall_time']:.1f} | {r.get('reason') or ''} |")
    return "\n".join(lines)


def main(argv: Optional[Sequence[str]] = None) -> list[dict]:
    args = parse_args(argv)
    comm = MPI.COMM_WORLD
    demo = load_demo("press_and_slide")
    rows = []
    out = Path(args.out)
    for kind in args.kinds:
        for configuration in args.configurations:
            row = run(demo, kind, configuration, args)
            rows.append(row)
            if comm.rank == 0:
                print(f"{kind:6s} {configuration:9s} {row['status']:16s} "
                      f"F_t max-min/N {fmt(row.get('tangential_oscillation'), '.2e'):>9s} "
                      f"Newton {row.get('newton_iterations') or '':>5} "
                      f"{row['wall_time']:6.1f} s", flush=True)
                # partial results survive an interrupted run
                write_csv(out / "press_and_slide_table.csv", rows, COLUMNS)
            gc.collect()   # free the previous run's PETSc objects before the next mesh
    if comm.rank == 0:
        table = markdown_table(rows, args)
        print()
        print(table)
        write_atomically(out / "press_and_slide_table.md",
                         lambda tmp: Path(tmp).write_text(table + "\n"))
        print(f"\nwrote {out / 'press_and_slide_table.csv'} and "
              f"{out / 'press_and_slide_table.md'}")
    return rows


if __name__ == "__main__":
    main()
