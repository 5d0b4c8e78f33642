"""The README's headline figures, re-measured on this machine's DOLFINx, beside DOLFINx 0.5.2's.

Each scene runs as its own process (a cold start, as a user's run), one after the other, with
``OMP_NUM_THREADS=1``; the table gives the accuracy and the wall time, and the ratio of the wall
time to the one measured with DOLFINx 0.5.2 (Debian 12, PETSc 3.18, same 2-core machine kind;
the figures of the README and docs/GUIDE.md before the move to DOLFINx 0.9-0.11).

    OMP_NUM_THREADS=1 python3 benchmarks/headline_figures.py [--scenes hertz2d ...] [--out DIR]
    python3 benchmarks/headline_figures.py --ranks 2      # each scene under mpirun -n 2

Writes ``DIR/headline_<dolfinx version>_<ranks>ranks.csv`` and ``.md`` (default DIR:
benchmarks/results).
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import dolfinx
from petsc4py import PETSc

from dolfinx_mortar.io.output import write_atomically, write_csv

ROOT = Path(__file__).resolve().parents[1]

#: scene: (command after the interpreter, the figures' file, how to read it); the arguments are
#: those of the 0.5.2 figures (Hertz 3D at refine 1.5, ironing with die elements of 0.05)
SCENES = {
    "hertz2d": (["demos/hertz2d.py"], "json"),
    "hertz2d-elastic": (["demos/hertz2d.py", "--obstacle", "elastic"], "json"),
    "axisymmetric": (["demos/hertz_axisymmetric.py"], "json"),
    "hertz3d": (["demos/hertz3d.py", "--refine", "1.5"], "json"),
    "ironing2d": (["demos/ironing2d.py", "--h-die", "0.05"], "json"),
    "current-cost": (["benchmarks/current_contact_cost.py", "--refine", "1.5"], "csv"),
}

#: DOLFINx 0.5.2 (README and docs/GUIDE.md up to 2026-11-25): wall time s, and figures
REFERENCE_0_5_2 = {
    "hertz2d": {"p0_error": -0.0016, "a_error": 0.0014, "l2_error": 0.0076,
                "newton_iterations": 22},
    "hertz2d-elastic": {"p0_error": 0.0107, "a_error": -0.0059, "wall_time": 5.2},
    "axisymmetric": {"p0_error": -0.0039, "a_error": 0.0012, "wall_time": 4.2},
    "hertz3d": {"wall_time": 37.0},
    "ironing2d": {"steady_normal_force": 1.649, "newton_iterations": 1083, "wall_time": 19.3},
    "current-cost": {"newton_iterations": 24, "contact_over_bulk": 0.72, "wall_time": 44.0},
}

COLUMNS = ("scene", "dofs", "newton_iterations", "p0_error", "a_error", "l2_error",
           "steady_normal_force", "contact_over_bulk", "wall_time", "process_time",
           "wall_time_0_5_2", "time_ratio")


def run_scene(name: str, scratch: Path, ranks: int) -> dict:
    command, kind = SCENES[name]
    out = scratch / name
    extra = (["--json", str(out) + ".json"] if kind == "json" else ["--out", str(out)])
    environment = {**os.environ, "OMP_NUM_THREADS": "1"}
    clock = time.perf_counter()
    launcher = [] if ranks == 1 else ["mpirun", "-n", str(ranks), "--oversubscribe"]
    run = subprocess.run([*launcher, sys.executable, *command, *extra], cwd=ROOT,
                         env=environment, capture_output=True, text=True)
    elapsed = time.perf_counter() - clock
    if run.returncode != 0:
        raise RuntimeError(f"{name} failed:\n{run.stderr[-3000:]}")
    if kind == "json":
        figures = json.loads(Path(str(out) + ".json").read_text())
    else:
        with open(str(out) + ".csv") as f:
            rows = {row["configuration"]: row for row in csv.DictReader(f)}
        current = rows["current"]
        figures = {"dofs": int(current["dofs"]), "newton_iterations": int(current["newton"]),
                   "wall_time": float(current["wall_time"]),
                   "contact_over_bulk": float(current["contact_over_bulk"]),
                   "p0_error": float(current["p0_error"]),
                   "a_error": float(current["a_error"])}
    row = {key: figures.get(key) for key in COLUMNS if key in figures}
    if name == "ironing2d":
        row["steady_normal_force"] = figures.get("normal_mean", figures.get("steady_normal_force"))
    row["scene"] = name
    row["process_time"] = elapsed
    reference = REFERENCE_0_5_2.get(name, {}).get("wall_time")
    row["wall_time_0_5_2"] = reference
    wall = row.get("wall_time") or elapsed
    row["time_ratio"] = wall / reference if reference else None
    return row


def _format(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results"))
    parser.add_argument("--ranks", type=int, default=1, help="MPI ranks of each scene (1)")
    args = parser.parse_args()
    version = dolfinx.__version__
    petsc = ".".join(str(v) for v in PETSc.Sys.getVersion())
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for name in args.scenes:
            rows.append(run_scene(name, Path(scratch), args.ranks))
            print(json.dumps(rows[-1]), flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    # not with_suffix: the version's dots would be taken for one
    stem = f"headline_{version}_{args.ranks}ranks"
    write_csv(out / f"{stem}.csv", [{key: row.get(key) for key in COLUMNS} for row in rows],
              columns=COLUMNS)
    lines = [f"DOLFINx {version}, PETSc {petsc}, Python {sys.version.split()[0]}, "
             f"{args.ranks} rank(s); "
             f"load average {os.getloadavg()[0]:.2f} at the end", "",
             "| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(_format(row.get(key)) for key in COLUMNS) + " |" for row in rows]
    write_atomically(out / f"{stem}.md",
                     lambda tmp: Path(tmp).write_text("\n".join(lines) + "\n"))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
