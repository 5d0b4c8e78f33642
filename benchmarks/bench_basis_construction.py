"""Construction time of the six mortar bases, per slave element, from 1e3 to 1e6 elements.

For each slave surface (a curved Q1 Lagrange sheet and a quadratic B-spline
surface), each size and each basis kind, this times

- the whole ``MortarBasis(kind, surface)`` constructor, and
- the same steps called one by one, to split the time into phases:

  ``tabulate``      ``surface.tabulate(q)`` (quadrature points, basis values, |J|);
  ``kernels``       ``_kernels.element_integrals`` + ``_kernels.element_mass_matrices``;
  ``W``             the global lumped weights ``layout.sum_at_functions``, their
                    gather to the elements and ``_kernels.check_lumped_weights``;
  ``coeffs/L asm``  ``_kernels.basis_coefficients`` (local kinds) or
                    ``layout.assemble_matrix`` of the global ``L`` (GLS, GLS*);
  ``factorize``     ``MassMatrixSolver`` (MUMPS Cholesky of ``L``; GLS, GLS* only).

It prints a markdown table with the growth rate between consecutive sizes,
``log(t2/t1)/log(n2/n1)`` (1.0 = linear), and the least-squares exponent over
all sizes per surface and kind, and writes a CSV and a PNG.

Run with Debian's interpreter, single process::

    python3 benchmarks/bench_basis_construction.py --help
"""
from __future__ import annotations

import argparse
import csv
import gc
import math
import os
import resource
import sys
import time
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

import numpy as np
from tqdm import tqdm

from dolfinx_mortar import KIND_NAMES, MortarBasis, _kernels, nurbs
from dolfinx_mortar.kinds import is_global, parse_kind
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import MassMatrixSolver
from dolfinx_mortar.io.output import save_figure, write_atomically

DEFAULT_CSV = Path("results/bench_basis_construction.csv")
DEFAULT_PNG = Path("results/bench_basis_construction.png")

#: Phase names in the order the constructor runs them.
PHASES: tuple[str, ...] = ("tabulate", "kernels", "W", "coeffs/L asm", "factorize")
#: Peak resident memory above which the run is reported as too hungry.
MEMORY_LIMIT_GIB = 10.0


# -- slave surfaces -----------------------------------------------------------------
def lagrange_q1_sheet(m: int) -> LagrangeSurface:
    """An m×m Q1 quadrilateral sheet z = 0.1 sin(2x) cos(y) over [0, 1]².

    Parameters
    ----------
    m
        Elements per direction.

    Returns
    -------
    The surface, m² elements, (m + 1)² nodes, cells in Basix quad vertex order
    [v00, v10, v01, v11].
    """
    s = np.linspace(0.0, 1.0, m + 1)
    x, y = np.meshgrid(s, s, indexing="ij")  # node (i, j) has index i*(m+1) + j
    nodes = np.column_stack([x.ravel(), y.ravel(),
                             (0.1 * np.sin(2.0 * x) * np.cos(y)).ravel()])
    i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
    v00 = (i * (m + 1) + j).ravel()
    cells = np.column_stack([v00, v00 + (m + 1), v00 + 1, v00 + (m + 1) + 1])
    return LagrangeSurface("quadrilateral", 1, nodes, cells)


def bspline_p2_surface(m: int) -> nurbs.BSplineSurface:
    """A quadratic B-spline surface on [0, 1]² with m×m elements.

    Parameters
    ----------
    m
        Elements per direction.
    """
    return nurbs.BSplineSurface(degree=2, n_elements=(m, m))


#: Surface name -> builder taking elements per direction.
SURFACES: dict[str, Callable[[int], Any]] = {
    "lagrange-q1": lagrange_q1_sheet,
    "bspline-p2": bspline_p2_surface,
}


# -- timing -------------------------------------------------------------------------
@dataclass
class RunResult:
    """Timings of one surface, size and kind (minimum over the repeats), in seconds."""

    surface: str
    elements: int
    functions: int
    kind: str
    repeats: int
    total: float
    tabulate: float
    kernels: float
    W: float
    coeffs_or_assembly: float
    factorize: float
    peak_rss_gib: float
    growth: Optional[float] = None

    @property
    def phase_times(self) -> tuple[float, ...]:
        """Phase times in the order of :data:`PHASES`."""
        return (self.tabulate, self.kernels, self.W, self.coeffs_or_assembly,
                self.factorize)

    @property
    def phase_sum(self) -> float:
        return sum(self.phase_times)

    @property
    def us_per_element(self) -> float:
        return 1e6 * self.total / self.elements


def time_constructor(kind: str, surface: Any) -> float:
    """Wall time of ``MortarBasis(kind, surface)``, the object freed afterwards."""
    start = time.perf_counter()
    basis = MortarBasis(kind, surface)
    elapsed = time.perf_counter() - start
    _release_solver(basis.mass_solver)
    del basis
    gc.collect()
    return elapsed


def time_phases(kind: str, surface: Any) -> tuple[float, ...]:
    """Wall time of each phase of the constructor, called step by step.

    Mirrors ``MortarBasis.__init__`` (dolfinx_mortar/basis.py) so that the sum of
    the phases can be checked against :func:`time_constructor`.

    Returns
    -------
    Times in the order of :data:`PHASES`; ``factorize`` is 0 for local kinds.
    """
    basis_kind = parse_kind(kind)
    layout = surface.layout
    cells = np.asarray(surface.cells, dtype=np.int64)
    clock = [time.perf_counter()]

    def lap() -> None:
        clock.append(time.perf_counter())

    tab = surface.tabulate(surface.default_quadrature_degree())
    lap()
    element_weights = _kernels.element_integrals(tab.phi, tab.weights)
    element_mass = _kernels.element_mass_matrices(tab.phi, tab.weights)
    lap()
    lumped = layout.sum_at_functions(cells, element_weights)
    nodal_at_cells = lumped[cells]
    _kernels.check_lumped_weights(basis_kind, element_weights, nodal_at_cells)
    lap()
    solver = None
    if is_global(basis_kind):
        matrix = layout.assemble_matrix(cells, element_mass)
        matrix.setOption(matrix.Option.SYMMETRIC, True)
        lap()
        solver = MassMatrixSolver(layout, matrix)
        lap()
    else:
        _kernels.basis_coefficients(basis_kind, element_mass, element_weights,
                                    nodal_at_cells)
        lap()
        clock.append(clock[-1])  # local kinds factorize nothing
    _release_solver(solver)
    del tab, element_weights, element_mass, lumped, nodal_at_cells
    gc.collect()
    return tuple(np.diff(clock))


def _release_solver(solver: Optional[MassMatrixSolver]) -> None:
    # MUMPS needs ~2 GB for a 1e6-function B-spline L (INFOG(22)); free it now rather
    # than whenever the garbage collector gets to the petsc4py objects.
    if solver is not None:
        solver.ksp.destroy()
        solver.matrix.destroy()


def peak_rss_gib() -> float:
    """Peak resident set size of this process so far (Linux: ru_maxrss in KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20


def benchmark_one(surface_name: str, surface: Any, kind: str, repeats: int) -> RunResult:
    """Minimum over ``repeats`` of the constructor time and of each phase time."""
    totals, phases = [], []
    for _ in range(repeats):
        totals.append(time_constructor(kind, surface))
        phases.append(time_phases(kind, surface))
    best = np.min(np.array(phases), axis=0)
    return RunResult(surface_name, len(surface.cells), surface.layout.size_local, kind,
                     repeats, min(totals), *best, peak_rss_gib())


def touch_memory(surface: Any) -> None:
    """Tabulate once, untimed, before the first timed run at a new size.

    The first allocation of a new high-water mark of memory is much slower than
    later ones (measured: 1e6 B-spline elements, ``tabulate`` 18 s the first
    time in a process, 6.6-9 s after), which would be billed to whichever kind
    runs first, and with one repeat at the largest size nothing absorbs it.
    The tabulation is the largest allocation of the constructor.
    """
    tab = surface.tabulate(surface.default_quadrature_degree())
    del tab
    gc.collect()


def warm_up(kinds: Sequence[str]) -> None:
    """Construct every kind once on a tiny surface.

    Keeps one-off costs (first MUMPS call, lazy imports, Basix caches) out of
    the smallest size, which is timed with few repeats.
    """
    for builder in SURFACES.values():
        surface = builder(4)
        for kind in kinds:
            time_constructor(kind, surface)


# -- sizes and growth -----------------------------------------------------------------
def elements_per_direction(min_elements: float, max_elements: float) -> list[int]:
    """m for every decade n = 10^k in [min_elements, max_elements], m = round(√n)."""
    low, high = math.ceil(math.log10(min_elements) - 1e-9), math.floor(
        math.log10(max_elements) + 1e-9)
    return [round(math.sqrt(10.0**k)) for k in range(low, high + 1)]


def growth_rate(n1: int, t1: float, n2: int, t2: float) -> float:
    """Local exponent log(t2/t1)/log(n2/n1); 1.0 means time linear in n."""
    return math.log(t2 / t1) / math.log(n2 / n1)


def fitted_exponent(n: Sequence[float], t: Sequence[float]) -> float:
    """Least-squares slope of log t against log n (NaN for fewer than 2 sizes)."""
    n, t = np.asarray(n, dtype=float), np.asarray(t, dtype=float)
    keep = t > 0
    if keep.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(n[keep]), np.log(t[keep]), 1)[0])


def fill_growth(results: list[RunResult]) -> None:
    """Set the growth rate of each result against the next smaller size."""
    previous: dict[tuple[str, str], RunResult] = {}
    for r in sorted(results, key=lambda r: (r.surface, r.kind, r.elements)):
        before = previous.get((r.surface, r.kind))
        if before is not None:
            r.growth = growth_rate(before.elements, before.total, r.elements, r.total)
        previous[(r.surface, r.kind)] = r


# -- output ---------------------------------------------------------------------------
def markdown_table(results: list[RunResult]) -> str:
    """The results as a markdown table, phase times in seconds."""
    header = (["surface", "elements", "kind", "total [s]", "µs/element"]
              + [f"{p} [s]" for p in PHASES] + ["Σphases/total", "growth"])
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join("---:" if i > 2 else "---" for i in range(len(header))) + "|"]
    for r in results:
        row = ([r.surface, f"{r.elements:,}", r.kind, f"{r.total:.4g}",
                f"{r.us_per_element:.3g}"]
               + [f"{t:.3g}" if t > 0 else "-" for t in r.phase_times]
               + [f"{r.phase_sum / r.total:.2f}",
                  "" if r.growth is None else f"{r.growth:.2f}"])
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def exponent_lines(results: list[RunResult]) -> list[str]:
    """One line per surface and kind: fitted exponent of the total and of each phase."""
    lines = []
    for (surface, kind), group in _groups(results).items():
        n = [r.elements for r in group]
        phase_exps = []
        for k, name in enumerate(PHASES):
            t = [r.phase_times[k] for r in group]
            if any(v > 0 for v in t):
                phase_exps.append(f"{name} {fitted_exponent(n, t):.2f}")
        total = fitted_exponent(n, [r.total for r in group])
        lines.append(f"{surface:12s} {kind:6s} total ∝ n^{total:.2f}"
                     f"  ({', '.join(phase_exps)}; n = {n[0]:,}..{n[-1]:,})")
    return lines


def _groups(results: list[RunResult]) -> dict[tuple[str, str], list[RunResult]]:
    groups: dict[tuple[str, str], list[RunResult]] = {}
    for r in results:
        groups.setdefault((r.surface, r.kind), []).append(r)
    for group in groups.values():
        group.sort(key=lambda r: r.elements)
    return groups


def write_csv(results: list[RunResult], path: Path) -> None:
    """One row per run: all :class:`RunResult` fields plus derived columns (seconds)."""
    names = [f.name for f in fields(RunResult)]

    def write(tmp: str) -> None:
        with open(tmp, "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(names + ["us_per_element", "phase_sum"])
            for r in results:
                writer.writerow([getattr(r, name) if getattr(r, name) is not None else ""
                                 for name in names] + [r.us_per_element, r.phase_sum])
    write_atomically(path, write)


def write_png(results: list[RunResult], path: Path) -> None:
    """Time per element against elements, one panel per surface, one line per kind."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    surfaces = list(dict.fromkeys(r.surface for r in results))
    fig, axes = plt.subplots(1, len(surfaces), figsize=(6 * len(surfaces), 4.5),
                             squeeze=False, sharey=False)
    groups = _groups(results)
    for ax, surface in zip(axes[0], surfaces):
        for (s, kind), group in groups.items():
            if s == surface:
                ax.plot([r.elements for r in group], [r.us_per_element for r in group],
                        marker="o", label=kind)
        ax.set_xscale("log")
        ax.set_ylim(bottom=0)
        ax.set_xlabel("slave elements")
        ax.set_ylabel("construction time per element [µs]")
        ax.set_title(surface)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle("MortarBasis construction time per slave element")
    fig.tight_layout()
    save_figure(path, fig, dpi=150)
    plt.close(fig)


# -- command line ---------------------------------------------------------------------
def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument("--min-elements", type=float, default=1e3,
                        help="smallest size (elements, rounded to a decade)")
    parser.add_argument("--max-elements", type=float, default=1e6,
                        help="largest size (elements, rounded to a decade)")
    parser.add_argument("--surfaces", nargs="+", choices=list(SURFACES),
                        default=list(SURFACES), help="slave surfaces to time")
    parser.add_argument("--kinds", nargs="+", choices=list(KIND_NAMES),
                        default=list(KIND_NAMES), help="mortar basis kinds to time")
    parser.add_argument("--repeat", type=int, default=3,
                        help="repeats per run, minimum taken (all sizes but the largest)")
    parser.add_argument("--repeat-largest", type=int, default=1,
                        help="repeats at the largest size")
    parser.add_argument("--csv", type=Path, default=DEFAULT_CSV, help="CSV output path")
    parser.add_argument("--png", type=Path, default=DEFAULT_PNG, help="PNG output path")
    args = parser.parse_args(argv)
    if args.min_elements > args.max_elements or args.min_elements < 1:
        parser.error("need 1 <= --min-elements <= --max-elements")
    if args.repeat < 1 or args.repeat_largest < 1:
        parser.error("repeats must be at least 1")
    return args


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = parse_args(argv)
    sizes = elements_per_direction(args.min_elements, args.max_elements)
    if not sizes:
        print("no decade between --min-elements and --max-elements", file=sys.stderr)
        return 1
    load_at_start = os.getloadavg()[0]
    warm_up(args.kinds)
    results: list[RunResult] = []
    with tqdm(total=len(args.surfaces) * len(sizes) * len(args.kinds), file=sys.stderr,
              unit="run") as progress:
        for surface_name in args.surfaces:
            for m in sizes:
                progress.set_description(f"{surface_name} {m * m:,}: building")
                surface = SURFACES[surface_name](m)
                touch_memory(surface)
                repeats = args.repeat_largest if m == sizes[-1] else args.repeat
                for kind in args.kinds:
                    progress.set_description(f"{surface_name} {m * m:,} {kind}")
                    results.append(benchmark_one(surface_name, surface, kind, repeats))
                    progress.update()
                del surface
                gc.collect()
    fill_growth(results)
    print(markdown_table(results))
    print()
    print("Fitted exponents (least squares of log t on log n; 1.0 = linear):")
    print("\n".join(exponent_lines(results)))
    write_csv(results, args.csv)
    write_png(results, args.png)
    peak = peak_rss_gib()
    print()
    print(f"peak RSS: {peak:.2f} GiB"
          + ("" if peak <= MEMORY_LIMIT_GIB else f"  (above the {MEMORY_LIMIT_GIB} GiB budget)"))
    # This process adds ~1 to the load; more means other work shared the cores.
    print(f"1-min load average: {load_at_start:.2f} at start, "
          f"{os.getloadavg()[0]:.2f} at end ({os.cpu_count()} cores)")
    print(f"wrote {args.csv} and {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
