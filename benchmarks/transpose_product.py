"""``Gᵀ G`` of the contact operator three ways: the library's explicit transpose followed by
MatMatMult (:func:`dolfinx_mortar.linalg.sparse_products.transpose_mat_mult`, written for PETSc
3.18, whose MatTransposeMatMult was 7× slower on 2 ranks), PETSc's MatTransposeMatMult, and
MatTransposeMatMult after G's rows are dealt out evenly over the ranks (a contact layout for the
product, tried here and not in the library: see docs/SCALING.md, "Dealing out the contact
stiffness product").

    OMP_NUM_THREADS=1 [mpirun -n 2] python3 benchmarks/transpose_product.py [--refine 1]

G is the gap derivative of Hertz 3D with two bodies (``demos/hertz3d.py --obstacle elastic``)
at full load. The first table gives the best of ``--repeat`` fresh products (symbolic and
numeric), the second the Newton loop's case, the same pattern again (numeric phase only): the
slowest rank's wall time, each rank's process time (max and mean over the ranks: the work per
rank, also with more ranks than cores), and the difference from the first way.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from demo_support.scripts import load_demo
from dolfinx_mortar.linalg.sparse_products import TransposeProduct, transpose_mat_mult


def best_time(product, repeat: int, comm: MPI.Comm) -> tuple[float, float, float, PETSc.Mat]:
    """The best wall time of the slowest rank, the ranks' best process times
    (max, mean), and the last result."""
    best, cpu, result = float("inf"), float("inf"), None
    for _ in range(repeat):
        comm.Barrier()
        clock, process = time.perf_counter(), time.process_time()
        result = product()
        cpu = min(cpu, time.process_time() - process)
        best = min(best, comm.allreduce(time.perf_counter() - clock, op=MPI.MAX))
    return best, comm.allreduce(cpu, op=MPI.MAX), comm.allreduce(cpu) / comm.size, result


def balanced_rows(A: PETSc.Mat, B: PETSc.Mat) -> PETSc.IS:
    """Rows for each rank so that the outer products of ``Aᵀ B`` (row r costs
    nnz(A_r)·nnz(B_r) multiply-adds) divide evenly: the global row order cut
    into contiguous ranges at equal shares of the summed cost (collective)."""
    comm = A.getComm().tompi4py()
    cost = (np.diff(A.getValuesCSR()[0]) * np.diff(B.getValuesCSR()[0])).astype(np.float64)
    before = comm.exscan(float(cost.sum())) or 0.0
    total = comm.allreduce(float(cost.sum()))
    midpoints = before + np.cumsum(cost) - 0.5 * cost
    owner = np.minimum((midpoints * comm.size / total).astype(np.int64), comm.size - 1)
    counts = comm.allreduce(np.bincount(owner, minlength=comm.size))
    return PETSc.IS().createStride(int(counts[comm.rank]), first=int(counts[:comm.rank].sum()),
                                   step=1, comm=comm)


class DealtProduct:
    """``Aᵀ B`` by MatTransposeMatMult, which sums the outer products of the
    rows where the rows are, after moving A's and B's rows to
    :func:`balanced_rows` (MatCreateSubMatrix); kept for reuse like
    :class:`TransposeProduct`."""

    def __init__(self, A: PETSc.Mat, B: PETSc.Mat) -> None:
        start, end = A.getOwnershipRangeColumn()
        self.rows = balanced_rows(A, B)
        self.columns = PETSc.IS().createStride(end - start, first=start, step=1,
                                               comm=A.getComm())
        self.A = A.createSubMatrix(self.rows, self.columns)
        self.B = B.createSubMatrix(self.rows, self.columns)
        self.product = self.A.transposeMatMult(self.B)

    def __call__(self, A: PETSc.Mat, B: PETSc.Mat) -> PETSc.Mat:
        A.createSubMatrix(self.rows, self.columns, submat=self.A)
        B.createSubMatrix(self.rows, self.columns, submat=self.B)
        self.A.transposeMatMult(self.B, result=self.product)
        return self.product


def table(title: str, times: dict, reference: PETSc.Mat, repeat: int, comm: MPI.Comm) -> None:
    scale = reference.norm(PETSc.NormType.FROBENIUS)
    differences = {}
    for name, (*_, result) in times.items():
        difference = result.duplicate(copy=True)
        difference.axpy(-1.0, reference, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        differences[name] = difference.norm(PETSc.NormType.FROBENIUS) / scale
    if comm.rank == 0:
        print(f"\n{title}, best of {repeat}")
        print("| product | slowest rank's wall (ms) | process time (ms), max / mean over the "
              "ranks | max / mean | difference from the first |")
        print("|---|---|---|---|---|")
        for name, (wall, cpu_max, cpu_mean, _) in times.items():
            print(f"| {name} | {1e3 * wall:.2f} | {1e3 * cpu_max:.2f} / {1e3 * cpu_mean:.2f} | "
                  f"{cpu_max / cpu_mean:.2f} | {differences[name]:.1e} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--refine", type=float, default=1.0)
    parser.add_argument("--repeat", type=int, default=10)
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    demo = load_demo("hertz3d")
    problem, _ = demo.build_problem(demo.parse_args(
        ["--obstacle", "elastic", "--refine", str(args.refine)]), comm)
    problem.set_load(1.0)
    G = problem.contact.evaluate().G

    fresh = {"explicit transpose + MatMatMult": lambda: transpose_mat_mult(G, G),
             "MatTransposeMatMult": lambda: G.transposeMatMult(G),
             "rows dealt out + MatTransposeMatMult": lambda: DealtProduct(G, G).product}
    fresh_times = {name: best_time(way, args.repeat, comm) for name, way in fresh.items()}
    explicit, dealt, petsc_product = TransposeProduct(), DealtProduct(G, G), G.transposeMatMult(G)
    explicit(G, G)
    again = {"explicit transpose + MatMatMult (TransposeProduct)": lambda: explicit(G, G),
             "MatTransposeMatMult": lambda: G.transposeMatMult(G, result=petsc_product),
             "rows dealt out + MatTransposeMatMult": lambda: dealt(G, G)}
    again_times = {name: best_time(way, args.repeat, comm) for name, way in again.items()}

    nonzeros = G.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)["nz_used"]    # collective
    rows_held = comm.gather(int(np.count_nonzero(np.diff(G.getValuesCSR()[0]))))
    rows_dealt = comm.gather(int(np.count_nonzero(np.diff(dealt.A.getValuesCSR()[0]))))
    if comm.rank == 0:
        rows, cols = G.getSize()
        print(f"PETSc {'.'.join(map(str, PETSc.Sys.getVersion()))}, {comm.size} rank(s), "
              f"G {rows} x {cols}, {nonzeros:.0f} nonzeros; G's non-empty rows on the ranks: "
              f"{rows_held}, dealt out: {rows_dealt}")
    table("Fresh products (symbolic and numeric)", fresh_times,
          fresh_times["explicit transpose + MatMatMult"][3], args.repeat, comm)
    table("The same pattern again (numeric only)", again_times,
          fresh_times["explicit transpose + MatMatMult"][3], args.repeat, comm)


if __name__ == "__main__":
    main()
