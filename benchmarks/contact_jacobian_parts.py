"""Where each rank's contact Jacobian time goes: the parts of ``A += K_c``.

Runs :mod:`contact_ranks` (same arguments) with the assembled Newton entry's
``assemble`` replaced by a copy that charges each part to the rank's process
clock: the geometric stiffness's decision, the product ``K = Gᵀ diag(ωH) G``
(``model.jacobian``), the rows it stiffens, ``A += K`` (PETSc's MatAXPY with a
subset pattern), the wait for the slowest rank (a barrier added here, so that
waiting is not charged to the next part) and ``A.assemble()``. Prints one
row per rank after contact_ranks' own tables. The library is not changed; the
GLS kinds (augmented step) and friction are not covered.

    export OMP_NUM_THREADS=1 OMPI_MCA_btl=self,sm OMPI_MCA_mpi_yield_when_idle=1
    mpirun --oversubscribe -n 16 python3 benchmarks/contact_jacobian_parts.py --refine 1.5
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

from mpi4py import MPI

from dolfinx_mortar.contact.newton import entry

sys.path.insert(0, str(Path(__file__).parent))
import contact_ranks  # noqa: E402

PARTS = ("geometric", "product", "stiffened_rows", "add_stiffness", "wait", "assemble")
spent = dict.fromkeys(PARTS, 0.0)


class Clock:
    """Charges the process time since the last call to a part."""

    def __init__(self) -> None:
        self.since = time.process_time()

    def charge(self, part: str) -> None:
        now = time.process_time()
        spent[part] += now - self.since
        self.since = now


def timed_assemble(self, A, model, state, active, mask, configuration, friction=None) -> bool:
    """``AssembledEntry.assemble`` without friction, part by part."""
    if friction is not None:
        raise NotImplementedError("this benchmark times the frictionless Jacobian only")
    clock = Clock()
    geometric = configuration.geometric_stiffness(active, self.comm)
    clock.charge("geometric")
    K = model.jacobian(state, active, mask, geometric=geometric)
    clock.charge("product")
    self.stiffened_rows = entry.stiffened_rows(K, self.bs)
    clock.charge("stiffened_rows")
    changed = configuration.add_stiffness(A, K)
    clock.charge("add_stiffness")
    self.comm.Barrier()
    clock.charge("wait")
    A.assemble()
    clock.charge("assemble")
    return changed


def main(argv=None) -> None:
    entry.AssembledEntry.assemble = timed_assemble
    contact_ranks.main(argv)
    comm = MPI.COMM_WORLD
    rows = comm.gather(dict(spent))
    if comm.rank == 0:
        print("\nContact Jacobian by part, process CPU s per rank (whole solve)\n")
        print("| rank | " + " | ".join(PARTS) + " |")
        print("|---" * (len(PARTS) + 1) + "|")
        for rank, row in enumerate(rows):
            print(f"| {rank} | " + " | ".join(f"{row[part]:.4f}" for part in PARTS) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
