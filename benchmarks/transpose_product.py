"""``Gᵀ G`` of the contact operator two ways: PETSc's MatTransposeMatMult, and the library's
explicit transpose followed by MatMatMult (:func:`dolfinx_mortar.linalg.sparse_products.
transpose_mat_mult`, written for PETSc 3.18, whose MatTransposeMatMult was 7× slower on 2 ranks).

    OMP_NUM_THREADS=1 [mpirun -n 2] python3 benchmarks/transpose_product.py [--refine 1]

G is the gap derivative of Hertz 3D with two bodies (``demos/hertz3d.py --obstacle elastic``)
at full load; the table gives the best of ``--repeat`` fresh products (symbolic and numeric),
the slowest rank's time, and checks that both give the same matrix.
"""
from __future__ import annotations

import argparse
import time

from mpi4py import MPI
from petsc4py import PETSc

from demo_support.scripts import load_demo
from dolfinx_mortar.linalg.sparse_products import transpose_mat_mult


def best_time(product, repeat: int, comm: MPI.Comm) -> tuple[float, PETSc.Mat]:
    best, result = float("inf"), None
    for _ in range(repeat):
        if result is not None:
            result.destroy()
        comm.Barrier()
        clock = time.perf_counter()
        result = product()
        best = min(best, comm.allreduce(time.perf_counter() - clock, op=MPI.MAX))
    return best, result


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
    explicit, first = best_time(lambda: transpose_mat_mult(G, G), args.repeat, comm)
    petsc, second = best_time(lambda: G.transposeMatMult(G), args.repeat, comm)
    second.axpy(-1.0, first)
    difference = second.norm(PETSc.NormType.FROBENIUS) / first.norm(PETSc.NormType.FROBENIUS)
    nonzeros = G.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)["nz_used"]    # collective
    if comm.rank == 0:
        rows, cols = G.getSize()
        print(f"PETSc {'.'.join(map(str, PETSc.Sys.getVersion()))}, {comm.size} rank(s), "
              f"G {rows} x {cols}, {nonzeros:.0f} nonzeros")
        print("| product | best of %d (ms) |" % args.repeat)
        print("|---|---|")
        print(f"| explicit transpose + MatMatMult | {1e3 * explicit:.2f} |")
        print(f"| MatTransposeMatMult | {1e3 * petsc:.2f} |")
        print(f"relative difference of the products: {difference:.1e}")


if __name__ == "__main__":
    main()
