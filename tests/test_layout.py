"""NodeLayout's sums over the ranks, used many times over (its ghosted vector
is made once and kept, so each use must start from its own values only)."""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from dolfinx_mortar.layout import NodeLayout, assemble_blocks

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


def test_the_largest_at_a_function_owned_where_none_of_its_elements_are():
    """Each rank holds one element, on the ghost it sees (the next rank's first
    function); the owner of that function holds none of its elements. The
    largest must still reach the owner (a node length of 0 there read as a
    slip of 1.9e305 element lengths on 8 ranks)."""
    layout = _ring()
    comm = layout.comm
    first_of_next = layout.size_local - 1 if comm.size > 1 else 0
    value = 1.0 + comm.rank
    largest = layout.max_at_functions(np.array([[first_of_next]]), np.array([[value]]))
    everyone = comm.allgather(value)
    expected = np.zeros(layout.size_local)
    expected[0] = everyone[(comm.rank - 1) % comm.size]
    if comm.size > 1:
        expected[-1] = value
    assert np.array_equal(largest, expected)


def test_blocks_into_columns_that_a_rank_owns_none_of():
    """A slave row block against master columns all owned by rank 0: the other
    ranks own rows but no columns (8 ranks gave a master surface such a rank,
    and PETSc refused the matrix: "nnz cannot be greater than row length")."""
    rows = _ring()
    comm = rows.comm
    cols = NodeLayout(comm, 2 if comm.rank == 0 else 0, [] if comm.rank == 0 else [0, 1])
    blocks = np.array([[[1.0, 2.0]]])
    mat = assemble_blocks(rows, np.array([[0]]), cols, np.array([[0, 1]]), blocks)
    dense = np.zeros((rows.size_global, cols.size_global))
    start, end = mat.getOwnershipRange()
    for row in range(start, end):
        columns, values = mat.getRow(row)
        dense[row, columns] = values
    dense = comm.allreduce(dense)
    expected = np.zeros_like(dense)
    expected[::OWNED] = [1.0, 2.0]
    assert np.array_equal(dense, expected)
