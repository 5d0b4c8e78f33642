"""Where each rank's contact Jacobian time goes: the parts of ``A += K_c``.

Runs :mod:`contact_ranks` (same arguments) with the library's own
``AssembledEntry.assemble`` given timed stand-ins for what it calls, each part
charged to the rank's process clock: the geometric stiffness's decision, the
product ``K = Gᵀ diag(ωH) G`` (``model.jacobian``), the rows it stiffens,
``A += K`` (PETSc's MatAXPY with a subset pattern), the wait for the slowest
rank (a barrier added here before ``A.assemble()``, so that waiting is not
charged to it) and ``A.assemble()``. Prints one row per rank after
contact_ranks' own tables. The library is not changed; the GLS kinds
(augmented step) are not covered.

    export OMP_NUM_THREADS=1 OMPI_MCA_btl=self,sm OMPI_MCA_mpi_yield_when_idle=1
    mpirun --oversubscribe -n 16 python3 benchmarks/contact_jacobian_parts.py --refine 1.5
"""
from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Callable, Optional

from mpi4py import MPI

from dolfinx_mortar.contact.newton import entry

sys.path.insert(0, str(Path(__file__).parent))
import contact_ranks  # noqa: E402

PARTS = ("geometric", "product", "stiffened_rows", "add_stiffness", "wait", "assemble")
spent = dict.fromkeys(PARTS, 0.0)


def timed(call: Callable, part: str, before: Optional[Callable] = None) -> Callable:
    """``call``, its process time charged to ``part`` (``before`` first, its
    time charged to "wait")."""
    def charged(*args, **kwargs):
        if before is not None:
            since = time.process_time()
            before()
            spent["wait"] += time.process_time() - since
        since = time.process_time()
        try:
            return call(*args, **kwargs)
        finally:
            spent[part] += time.process_time() - since
    return charged


class Timed:
    """Forwards every attribute of ``target``; the methods named in ``parts``
    come timed (:func:`timed`)."""

    def __init__(self, target, parts: dict[str, str], before: Optional[Callable] = None):
        self._target, self._parts, self._before = target, parts, before

    def __getattr__(self, name: str):
        value = getattr(self._target, name)
        part = self._parts.get(name)
        return value if part is None else timed(value, part, self._before)


def timed_entry(assemble: Callable) -> Callable:
    """``AssembledEntry.assemble`` as it is, called with timed stand-ins for the
    model, the configuration and the matrix it adds into."""
    def charged(self, A, model, state, active, mask, configuration, friction=None):
        return assemble(self, Timed(A, {"assemble": "assemble"}, before=self.comm.Barrier),
                        Timed(model, {"jacobian": "product"}), state, active, mask,
                        Timed(configuration, {"geometric_stiffness": "geometric",
                                              "add_stiffness": "add_stiffness"}), friction)
    return charged


def main(argv=None) -> None:
    entry.AssembledEntry.assemble = timed_entry(entry.AssembledEntry.assemble)
    entry.stiffened_rows = timed(entry.stiffened_rows, "stiffened_rows")
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
