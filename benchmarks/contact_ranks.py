"""Contact work per MPI rank in CPU time, at 1 … 16 ranks (issue 38, today's code).

Runs the scene of :mod:`contact_parallel` (``demos/hertz3d.py --obstacle
elastic``: LcLS*, nodal active set, 3 load steps, the iterative solver) and
reports, for every rank, the CPU time of its contact phases (setup: normals
and gather, search, segmentation, the rest; residual evaluations; Jacobians)
next to its bulk assembly, what it holds of the contact (owned slave nodes,
slave facets, master facets in its master copy, candidate and segmented
pairs) and the bytes it received from other ranks for the surfaces. Ranks may
outnumber the cores (``--oversubscribe``), so times are process CPU time,
not wall time. ``--scene ironing3d`` runs a small sliding scene instead
(``demos/ironing3d.py``: a die pressed into a slab and slid along it, on the
current configuration), where the pairs are found again at every residual
evaluation: its search and segmentation are summed over all the couplings
made and are part of the residual time.

    export OMP_NUM_THREADS=1 OMPI_MCA_mpi_yield_when_idle=1
    for P in 1 2 4 8 16; do
        mpirun --oversubscribe -n $P nice python3 benchmarks/contact_ranks.py --refine 1.5
    done
    ... benchmarks/contact_ranks.py --scene ironing3d    # a sliding scene, small

Each run writes its ranks' rows to ``contact_ranks_{scene}_n{P}.csv`` in
``--out`` (default ``benchmarks/results/``) and then rewrites, from all such
files of the scene there, the summary ``contact_ranks_{scene}.csv`` (one row
per rank count: max/mean/total of the contact CPU time over the ranks, the
holdings of the rank with the most segmented pairs, bytes received, bulk CPU)
and the markdown tables ``contact_ranks_{scene}.md``. ``--summarize`` only rewrites them (no MPI).

How the CPU times are taken: the library times these phases itself, with
``time.perf_counter``, into ``coupling.timings`` (normals and gather, search,
segmentation), the term's ``timings`` (setup, residual, Jacobian) and the
problem's ``timings`` (bulk residual and Jacobian). During the run this script
replaces the name ``time`` in those three modules (``mortar/coupling.py``,
``contact/term.py``, ``solver/nonlinear_problem.py``) with a stand-in whose
``perf_counter`` is ``time.process_time``: the library's own timing code then
adds up each rank's CPU time, phase by phase, and nothing in the library
changes. The Hertz rows are :func:`contact_parallel.rank_row`'s. The
``MortarCoupling`` constructor is wrapped, to sum the phases and bytes of every
coupling made and keep the last one.

How the bytes are counted: every ``MortarCoupling`` reports
``received_bytes``, what its rank received from the other ranks for it (its
share of the master surface, ``NearSurface``, or the whole master with
``whole_master``; and the slave facets near its own for the normal
clusters). The script wraps ``MortarCoupling.__init__`` during the run and
adds them up over every coupling made (``coupling_bytes``). The current
configuration also deals its pairs' Jet work out over the ranks, with the
facets each pair reads, outside any coupling (``pair_share.deal_evenly``):
the script wraps ``deal_evenly`` in ``contact/gap_sources/current/mortar.py``
and adds the ``received_bytes`` of each call (``gathers`` counts these calls;
before 2026-11-27 they were gathers of the whole slave surface, counted the
same way). ``bytes_received`` is the sum of both. Pickling adds about 150
bytes per array and rank, not counted.

Waiting costs CPU time too: a rank waiting in a collective polls. Run with
``OMPI_MCA_mpi_yield_when_idle=1``: a test rank waiting 2 s for another was
charged 1.98 s of CPU time without it at 2 ranks on 2 cores (Open MPI spins
when the ranks do not outnumber the cores), 0.02 s with it, and 0.00-0.12 s
at 16 ranks. Some waiting may still be counted, so a rank without contact
shows a small contact time.
"""
from __future__ import annotations

import argparse
import csv
import functools
import importlib
import os
import time
import types
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Callable, Iterator, Optional, Sequence

import numpy as np

from contact_parallel import rank_row
from dolfinx_mortar.io.output import write_atomically, write_csv

HERE = Path(__file__).resolve().parent
#: the modules whose phase timings are read, and the one whose ``deal_evenly``
#: calls exchange surface data outside any coupling
CLOCKED = ("dolfinx_mortar.mortar.coupling", "dolfinx_mortar.contact.term",
           "dolfinx_mortar.solver.nonlinear_problem")
GATHERING = ("dolfinx_mortar.contact.gap_sources.current.mortar",)
RANK_COLUMNS = ("rank", "dofs", "newton", "krylov", "owned_slave_nodes", "slave_facets",
                "master_facets", "candidates", "pairs", "normals_and_gather", "search",
                "segmentation", "setup_rest", "setup", "residual", "jacobian",
                "contact_total", "bulk", "cpu", "wall", "gathers", "bytes_received",
                "coupling_bytes", "couplings")
TIMES = ("normals_and_gather", "search", "segmentation", "setup_rest", "setup", "residual",
         "jacobian", "contact_total", "bulk", "cpu", "wall")
HOLDINGS = ("owned_slave_nodes", "slave_facets", "master_facets", "candidates", "pairs")
SUMMARY_COLUMNS = (("ranks", "dofs", "newton", "krylov", "contact_max", "contact_mean",
                    "contact_total", "busiest_rank", "busiest_contact")
                   + tuple(f"busiest_{h}" for h in HOLDINGS)
                   + ("bytes_max", "bytes_mean", "bytes_total", "bulk_max", "bulk_mean",
                      "cpu_max", "cpu_mean", "contact_share", "wall"))


def parse_args(argv: Optional[Sequence[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default="hertz3d", choices=("hertz3d", "ironing3d"))
    parser.add_argument("--refine", type=float, default=1.0, help="hertz3d --refine (1)")
    parser.add_argument("--h", type=float, default=1.0, help="ironing3d --h (1)")
    parser.add_argument("--press-steps", type=int, default=3, help="ironing3d (3)")
    parser.add_argument("--slide-steps", type=int, default=4, help="ironing3d (4)")
    parser.add_argument("--penalty", type=float, default=1e3,
                        help="hertz3d: ε as a multiple of E/h (1e3)")
    parser.add_argument("--partitioner", default="graph", choices=("graph", "contact"))
    parser.add_argument("--summarize", action="store_true",
                        help="only rewrite the summary from the per-rank files in --out")
    parser.add_argument("--out", default=str(HERE / "results"))
    return parser.parse_args(argv)


class _ProcessClock(types.ModuleType):
    """``time`` with ``perf_counter`` reading the process CPU clock."""

    def __init__(self) -> None:
        super().__init__("time")
        self.perf_counter = time.process_time

    def __getattr__(self, name: str):
        return getattr(time, name)


@contextmanager
def replaced(owners: Sequence, name: str, make: Callable) -> Iterator[None]:
    """Each owner's attribute ``name`` is ``make(old value)`` inside the block
    (an owner is a module, by name, or any object such as a class)."""
    objects = [importlib.import_module(m) if isinstance(m, str) else m for m in owners]
    saved = [(o, getattr(o, name)) for o in objects]
    try:
        for module, old in saved:
            setattr(module, name, make(old))
        yield
    finally:
        for module, old in saved:
            setattr(module, name, old)


class ExchangeCount:
    """Calls of ``deal_evenly`` (outside any coupling) on this rank and the
    bytes they received."""

    def __init__(self) -> None:
        self.calls, self.bytes = 0, 0

    def wrap(self, deal: Callable) -> Callable:
        @functools.wraps(deal)
        def counted(*args, **kwargs):
            dealt = deal(*args, **kwargs)
            self.calls += 1
            self.bytes += dealt.received_bytes
            return dealt
        return counted


class CouplingLog:
    """Every ``MortarCoupling`` made on this rank: the last one, the CPU time of
    each phase and the bytes received, summed over all (the current
    configuration makes one per residual evaluation)."""

    def __init__(self) -> None:
        self.last, self.made, self.timings, self.bytes = None, 0, {}, 0

    def wrap(self, init: Callable) -> Callable:
        @functools.wraps(init)
        def made(coupling, *args, **kwargs):
            init(coupling, *args, **kwargs)
            self.last, self.made = coupling, self.made + 1
            self.bytes += coupling.received_bytes
            for key, value in coupling.timings.items():
                self.timings[key] = self.timings.get(key, 0.0) + value
        return made


@contextmanager
def measured(count: ExchangeCount, couplings: CouplingLog) -> Iterator[None]:
    """The library's phase clocks on process time, its exchanges outside the
    couplings counted and its couplings logged, inside the block."""
    from dolfinx_mortar.mortar.coupling import MortarCoupling
    with ExitStack() as stack:
        stack.enter_context(replaced(CLOCKED, "time", lambda _: _ProcessClock()))
        stack.enter_context(replaced(GATHERING, "deal_evenly", count.wrap))
        stack.enter_context(replaced([MortarCoupling], "__init__", couplings.wrap))
        yield


def hertz3d(args: argparse.Namespace, comm) -> dict:
    """Hertz 3D with two bodies (initial configuration): this rank's row."""
    from demo_support.scripts import load_demo
    demo = load_demo("hertz3d")
    demo_args = demo.parse_args(["--obstacle", "elastic", "--refine", str(args.refine),
                                 "--penalty", str(args.penalty), "--linear-solver",
                                 "iterative", "--partitioner", args.partitioner])
    count, couplings = ExchangeCount(), CouplingLog()
    with measured(count, couplings):
        comm.Barrier()
        wall, cpu = time.perf_counter(), time.process_time()
        problem, _ = demo.build_problem(demo_args, comm)
        result = problem.solve(load_steps=demo_args.load_steps)
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    row = rank_row(problem, result, wall)
    coupling = problem.contact.source.coupling
    row.update(master_facets=len(coupling.master_copy.cells),
               setup=problem.timings.get("contact_setup", 0.0), cpu=cpu,
               gathers=count.calls, bytes_received=count.bytes + couplings.bytes,
               couplings=couplings.made, coupling_bytes=couplings.bytes)
    return row


def ironing3d(args: argparse.Namespace, comm) -> dict:
    """Ironing 3D (a die pressed into a slab and slid along it, current
    configuration, ``demos/ironing3d.py``): this rank's row. The segmentation
    runs inside every residual evaluation: its phases are summed over all the
    couplings made and are part of the residual time."""
    from demo_support import ironing
    problems: list = []

    def recording(cls: type) -> Callable:
        def made(*a, **k):
            problems.append(cls(*a, **k))
            return problems[-1]
        return made
    demo_args = ironing.parse_args(ironing.__doc__, 3, [
        "--h", str(args.h), "--press-steps", str(args.press_steps),
        "--slide-steps", str(args.slide_steps), "--quiet"])
    count, couplings = ExchangeCount(), CouplingLog()
    with measured(count, couplings), replaced(["demo_support.ironing"],
                                              "NonlinearContactProblem", recording):
        comm.Barrier()
        wall, cpu = time.perf_counter(), time.process_time()
        figures = ironing.run(demo_args, comm)
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    problem = problems[0]
    term = problem.contacts[0]
    slave, last = term.slave, couplings.last
    t = dict(problem.timings)
    t.update({f"contact_{k}": v for k, v in term.timings.items()})
    row = {"rank": comm.rank, "dofs": figures["dofs"], "newton": figures["newton_iterations"],
           "krylov": 0, "owned_slave_nodes": len(slave.owned_nodes),
           "slave_facets": len(slave.cells), "master_facets": len(last.master_copy.cells),
           "candidates": last.num_candidates, "pairs": len(last.pairs),
           "setup": t.get("contact_setup", 0.0), "setup_rest": 0.0,
           "residual": t.get("contact_residual", 0.0),
           "jacobian": t.get("contact_jacobian", 0.0),
           "bulk": t.get("bulk_residual", 0.0) + t.get("bulk_jacobian", 0.0),
           "cpu": cpu, "wall": wall, "gathers": count.calls,
           "bytes_received": count.bytes + couplings.bytes, "couplings": couplings.made,
           "coupling_bytes": couplings.bytes}
    row.update({k: couplings.timings.get(k, 0.0)
                for k in ("normals_and_gather", "search", "segmentation")})
    row["contact_total"] = sum(v for k, v in t.items() if k.startswith("contact_"))
    return row


def read_rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def summary(rows: list[dict]) -> dict:
    """One row for a rank count from its ranks' rows."""
    def column(key: str) -> np.ndarray:
        return np.array([r[key] for r in rows])
    contact, cpu = column("contact_total"), column("cpu")
    busiest = rows[int(np.argmax(column("pairs")))]      # the rank holding most contact
    out = {"ranks": len(rows), "dofs": int(rows[0]["dofs"]), "newton": int(rows[0]["newton"]),
           "krylov": int(rows[0]["krylov"]), "contact_max": contact.max(),
           "contact_mean": contact.mean(), "contact_total": contact.sum(),
           "busiest_rank": int(busiest["rank"]), "busiest_contact": busiest["contact_total"]}
    out.update({f"busiest_{h}": int(busiest[h]) for h in HOLDINGS})
    received = column("bytes_received")
    out.update(bytes_max=int(received.max()), bytes_mean=int(received.mean()),
               bytes_total=int(received.sum()), bulk_max=column("bulk").max(),
               bulk_mean=column("bulk").mean(), cpu_max=cpu.max(), cpu_mean=cpu.mean(),
               contact_share=contact.sum() / cpu.sum(), wall=column("wall").max())
    return out


def markdown(stem: str, per_count: dict[int, list[dict]]) -> str:
    """The summary table and each rank count's per-rank table."""
    rows = [summary(per_count[p]) for p in sorted(per_count)]
    lines = [f"# {stem}", "", "CPU times (process clock) in s, bytes received from other ranks "
             "for the surfaces in kB; the busiest rank is the one with the most segmented pairs.", "",
             "| ranks | dofs | Newton | contact CPU max | mean | busiest rank: contact CPU | "
             "owned slave nodes | slave facets | master copy facets | candidates | pairs | "
             "kB received max | mean | bulk CPU max | mean | CPU max | contact share | wall s |",
             "|" + "---|" * 18]
    lines += [f"| {r['ranks']} | {r['dofs']} | {r['newton']} | {r['contact_max']:.2f} | "
              f"{r['contact_mean']:.2f} | {r['busiest_contact']:.2f} | "
              f"{r['busiest_owned_slave_nodes']} | "
              f"{r['busiest_slave_facets']} | {r['busiest_master_facets']} | "
              f"{r['busiest_candidates']} | {r['busiest_pairs']} | {r['bytes_max'] / 1e3:.0f} | "
              f"{r['bytes_mean'] / 1e3:.0f} | {r['bulk_max']:.2f} | {r['bulk_mean']:.2f} | "
              f"{r['cpu_max']:.1f} | {100 * r['contact_share']:.0f}% | {r['wall']:.0f} |"
              for r in rows]
    keys = ("rank", "owned_slave_nodes", "slave_facets", "master_facets", "candidates",
            "pairs", "normals_and_gather", "search", "segmentation", "setup_rest",
            "residual", "jacobian", "contact_total", "bulk", "cpu", "gathers",
            "bytes_received")
    for p in sorted(per_count):
        lines += ["", f"## {p} rank(s)", "", "| " + " | ".join(keys) + " |",
                  "|" + "---|" * len(keys)]
        lines += ["| " + " | ".join(f"{r[k]:.2f}" if k in TIMES else f"{int(r[k])}"
                                    for k in keys) + " |" for r in per_count[p]]
    return "\n".join(lines) + "\n"


def summarize(out: Path, stem: str) -> list[dict]:
    """Rewrite ``{stem}.csv`` and ``{stem}.md`` from the per-rank files in ``out``."""
    per_count = {}
    for path in out.glob(f"{stem}_n*.csv"):
        rows = read_rows(path)
        per_count[len(rows)] = rows
    if not per_count:
        raise FileNotFoundError(f"no {stem}_n*.csv in {out}")
    rows = [summary(per_count[p]) for p in sorted(per_count)]
    write_csv(out / f"{stem}.csv", rows, SUMMARY_COLUMNS)
    text = markdown(stem, per_count)
    write_atomically(out / f"{stem}.md", lambda tmp: Path(tmp).write_text(text))
    return rows


def main(argv: Optional[Sequence[str]] = None) -> list[dict]:
    args = parse_args(argv)
    out = Path(args.out)
    stem = (f"contact_ranks_hertz3d_r{args.refine:g}_{args.partitioner}"
            if args.scene == "hertz3d" else
            f"contact_ranks_ironing3d_h{args.h:g}_s{args.press_steps}+{args.slide_steps}")
    if args.summarize:
        return summarize(out, stem)
    from mpi4py import MPI
    comm = MPI.COMM_WORLD
    load = os.getloadavg()[0]
    rows = comm.gather((hertz3d if args.scene == "hertz3d" else ironing3d)(args, comm))
    if comm.rank != 0:
        return []
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / f"{stem}_n{comm.size}.csv", rows, RANK_COLUMNS)
    result = summarize(out, stem)
    print(f"{stem}: {comm.size} rank(s), 1-minute load before the run {load:.2f} on "
          f"{os.cpu_count()} cores")
    print(markdown(stem, {comm.size: rows}))
    return result


if __name__ == "__main__":
    main()
