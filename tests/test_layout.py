"""NodeLayout's sums over the ranks, used many times over (its ghosted vector
is made once and kept, so each use must start from its own values only)."""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from dolfinx_mortar.layout import NodeLayout

OWNED = 3


def _ring() -> NodeLayout:
    """Each rank owns OWNED functions and sees the next rank's first as a ghost."""
    comm = MPI.COMM_WORLD
    ghosts = [((comm.rank + 1) % comm.size) * OWNED] if comm.size > 1 else []
    return NodeLayout(comm, OWNED, ghosts)


def _expected(layout: NodeLayout, partial: np.ndarray) -> np.ndarray:
    """The exact totals at the local functions, from every rank's partial values."""
    totals = np.zeros(layout.size_global)
    for indices, values in layout.comm.allgather((layout.global_indices, partial)):
        np.add.at(totals, indices, values)
    return totals[layout.global_indices]


def test_complete_and_to_local_start_afresh_at_each_use():
    layout = _ring()
    for call in range(3):
        partial = (call + 1) * 10.0 ** np.arange(layout.size_local) + layout.comm.rank
        out = layout.complete(partial)
        assert np.array_equal(out, _expected(layout, partial))
        # the owned totals back to owned and ghosts through a distributed vector
        assert np.array_equal(layout.to_local(layout.vector(out)), out)
