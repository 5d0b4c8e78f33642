"""The slip limit over a grid of slopes, friction coefficients, kinds and configurations.

Runs demos/slip_limit.py for every tan α ∈ {0, 0.2, 0.5}, μ ∈ {0.1, 0.3, 0.5},
kind and basis configuration asked for, and prints per kind and configuration
how many runs converged, their Newton iterations per step and the largest
error of F/G at full slip against (tan α + μ)/(1 − μ tan α). Writes one CSV row
per run (docs/FRICTION.md cites the counts).

    python3 benchmarks/slip_limit_grid.py --csv results/slip_limit_grid.csv
    python3 benchmarks/slip_limit_grid.py --kinds GLS GLS* --configurations initial
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "demos"))
import slip_limit  # noqa: E402

from dolfinx_mortar import ContactDivergenceError  # noqa: E402
from dolfinx_mortar.io.output import write_csv  # noqa: E402

TAN_ALPHAS = (0.0, 0.2, 0.5)
MUS = (0.1, 0.3, 0.5)
COLUMNS = ("kind", "configuration", "tan_alpha", "mu", "converged", "all_slip",
           "slip_ratio_error", "newton_per_step", "wall_time")


def run_one(kind: str, configuration: str, tan_alpha: float, mu: float,
            push_steps: int) -> dict:
    args = slip_limit.parse_args(["--tan-alpha", str(tan_alpha), "--mu", str(mu), "--kind",
                                  kind, "--basis-configuration", configuration,
                                  "--push-steps", str(push_steps)])
    row = {"kind": kind, "configuration": configuration, "tan_alpha": tan_alpha, "mu": mu}
    failed = {"all_slip": False, "slip_ratio_error": float("nan"),
              "newton_per_step": float("nan"), "wall_time": float("nan")}
    try:
        f = slip_limit.run(args, MPI.COMM_WORLD)
    except ContactDivergenceError:
        return {**row, "converged": False, **failed}
    except NotImplementedError:         # GLS kinds on the current surface
        return {**row, "converged": None, **failed}
    return {**row, "converged": True, "all_slip": bool(f["all_slip"]),
            "slip_ratio_error": float(f["slip_ratio_error"]),
            "newton_per_step": f["newton_iterations"] / len(f["steps"]),
            "wall_time": float(f["wall_time"])}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kinds", nargs="+", default=["LcLS*", "LcLS", "LmLS*", "LmLS"])
    parser.add_argument("--configurations", nargs="+", default=["initial", "previous"])
    parser.add_argument("--push-steps", type=int, default=12)
    parser.add_argument("--csv", default=None)
    args = parser.parse_args()
    rows = [run_one(kind, configuration, tan_alpha, mu, args.push_steps)
            for configuration in args.configurations for kind in args.kinds
            for tan_alpha in TAN_ALPHAS for mu in MUS]
    if MPI.COMM_WORLD.rank != 0:
        return
    print(f"{'kind':7} {'configuration':13} {'converged':>9} {'Newton/step':>11} "
          f"{'max |F/G error|':>15}  failed (tan α, μ)")
    for configuration in args.configurations:
        for kind in args.kinds:
            mine = [r for r in rows if r["kind"] == kind and r["configuration"] == configuration]
            if all(r["converged"] is None for r in mine):
                print(f"{kind:7} {configuration:13} not supported")
                continue
            ok = [r for r in mine if r["converged"]]
            failed = [(r["tan_alpha"], r["mu"]) for r in mine if not r["converged"]]
            per_step = sum(r["newton_per_step"] for r in ok) / max(len(ok), 1)
            worst = max((abs(r["slip_ratio_error"]) for r in ok), default=float("nan"))
            print(f"{kind:7} {configuration:13} {len(ok):>5}/{len(mine):<3} {per_step:11.1f} "
                  f"{worst:15.2e}  {failed}")
    supported = [r for r in rows if r["converged"] is not None]
    print(f"converged {sum(r['converged'] for r in supported)} of {len(supported)}")
    if args.csv:
        write_csv(args.csv, rows, COLUMNS)


if __name__ == "__main__":
    main()
