"""A coupling's pairs dealt out evenly over the ranks, each with the facets its
Jets read (docs/DESIGN.md, §Parallel).

The exact derivatives of the current configuration's gaps cost 25 (gradients)
to 100–200 (Hessians) times a pair's values, and the pairs sit where the
surfaces press, often on one rank. So each rank keeps the search and the values
of its own slave facets' pairs, and their Jet work is dealt out in equal shares
(a rank keeps what its share holds of its own pairs, the rest go to ranks short
of theirs: :func:`dealt_items`), each pair with what the kernel reads for it —
the pair's slave cell, the slave cells around its nodes and around the other
nodes of their normal clusters (the averaged normals and their derivatives),
and the pair's master cell. A rank receives its share of the work and the
facets of that share, not both whole surfaces (until 2026-11 every rank
gathered both at every evaluation: 28.6 MB per rank at 16 ranks on the ironing
scene).

MPI's ``alltoall`` does the exchange: what travels is a few cells per pair,
chosen by global node ids, which DOLFINx's scatterers (built for a fixed ghost
layout) do not describe.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Protocol

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar import _kernels
from dolfinx_mortar.mortar.surface_exchange import SurfaceCopy


FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


class FoundPairs(Protocol):
    """What dealing reads of a coupling
    (:class:`~dolfinx_mortar.mortar.coupling.MortarCoupling` answers it): its
    pairs (local slave cell, master copy cell), its copies of the slave near
    this rank (own cells from ``first_own_slave_cell`` on) and of the master,
    the slave's normal clusters, and the slave surface."""

    pairs: npt.NDArray[np.int64]
    first_own_slave_cell: int
    slave_copy: SurfaceCopy
    master_copy: SurfaceCopy
    clusters: dict[int, int]
    slave: Any


@dataclass
class DealtPairs:
    """The pairs a rank computes the Jets of, with the facets they read.

    Attributes
    ----------
    slave, master
        The slave cells of the pairs and every slave cell around their nodes
        (each cell once), and the pairs' master cells.
    pairs
        (pairs, 2): slave cell (in ``slave``), master cell (in ``master``).
    values
        The per-pair arrays dealt along with the pairs (weights, ...).
    received_bytes
        Bytes received from the other ranks for them.
    """

    slave: SurfaceCopy
    master: SurfaceCopy
    pairs: npt.NDArray[np.int32]
    values: tuple[npt.NDArray, ...]
    received_bytes: int = 0

    @property
    def rows(self) -> IntArray:
        """Global function ids of each pair's slave cell nodes, (pairs, nodes)."""
        return self.slave.global_ids[self.slave.cells[self.pairs[:, 0]]]

    def gap_jets(self, points: FloatArray, weights: FloatArray, zero_length: float,
                 **options) -> "_kernels.PairGapDerivatives":
        """The kernel's ``c_A = ∫ N_A d`` of these pairs on the current surfaces
        with exact derivatives (``_kernels.current_pair_gaps``; ``options``:
        ``with_hessian``, ``with_positive_part``, ``axisymmetric``,
        ``node_weights``), from the segment quadrature ``points``, ``weights``."""
        slave, master = self.slave, self.master
        return _kernels.current_pair_gaps(
            slave.facet_type, slave.x, slave.cells, slave.global_ids.astype(np.int64),
            master.facet_type, master.x, master.cells, master.global_ids.astype(np.int64),
            self.pairs, points, weights, zero_length, **options)


def own_pairs(coupling: FoundPairs, which: Optional[npt.NDArray[np.bool_]] = None,
              *values: npt.NDArray) -> DealtPairs:
    """The coupling's pairs (those where ``which`` is True) on the rank that
    found them: its slave cells in the coupling's copy of the slave surface
    near this rank, which holds every cell around them. No communication."""
    pairs = coupling.pairs if which is None else coupling.pairs[which]
    local = np.column_stack([pairs[:, 0] + coupling.first_own_slave_cell, pairs[:, 1]])
    return DealtPairs(coupling.slave_copy, coupling.master_copy, local.astype(np.int32),
                      tuple(values))


def deal_evenly(coupling: FoundPairs, which: npt.NDArray[np.bool_],
                *values: npt.NDArray) -> DealtPairs:
    """All ranks' pairs where ``which`` is True, dealt out in equal shares (each
    rank keeps what its share holds of its own: :func:`dealt_items`) with the
    facets they read and ``values`` (one row per kept pair). Collective."""
    comm: MPI.Comm = coupling.slave.layout.comm
    mine = own_pairs(coupling, which, *values)
    if comm.size == 1:
        return mine
    destination = share_owners(comm, len(mine.pairs))
    near = needed_slave_cells(mine.slave, mine.pairs[:, 0], coupling.clusters)
    outgoing = [_pack(mine, destination == rank, near) for rank in range(comm.size)]
    incoming = comm.alltoall(outgoing)
    received = sum(_nbytes(part) for rank, part in enumerate(incoming) if rank != comm.rank)
    return _unpack(incoming, mine.slave, mine.master, len(values), int(received))


def share_owners(comm: MPI.Comm, count: int) -> IntArray:
    """For each of this rank's ``count`` items, the rank that takes it in equal
    shares of all ranks' items (collective; see :func:`dealt_items`)."""
    return dealt_items(comm.allgather(count), comm.rank)


def dealt_items(counts: list[int], rank: int) -> IntArray:
    """For each of ``rank``'s ``counts[rank]`` items, the rank that takes it
    when all ranks' items are dealt in equal shares (differing by one at most).

    Each rank keeps as many of its own items as its share holds (the first
    ones), and only the rest travel, in rank order, to the ranks whose own
    items fall short of their shares. Dealing by position in rank order instead
    sent a busy rank's items away while others' came in: at 16 ranks on Hertz
    3D the busiest rank received its candidates' pairs back and 174 kB of
    other ranks' candidates besides (docs/SCALING.md).
    """
    counts = np.asarray(counts, dtype=np.int64)
    size = len(counts)
    total = int(counts.sum())
    shares = np.diff(np.array([total * r // size for r in range(size + 1)]))
    kept = np.minimum(counts, shares)
    excess, deficit = counts - kept, shares - kept
    # where each rank's excess starts among all excess items, and each rank's
    # deficit among all free places: the excess fills them in rank order
    excess_first = int(excess[:rank].sum())
    deficit_first = np.concatenate([[0], np.cumsum(deficit)[:-1]])
    owners = np.full(int(counts[rank]), rank, dtype=np.int64)
    moved = excess_first + np.arange(int(excess[rank]))
    owners[int(kept[rank]):] = np.searchsorted(deficit_first, moved, side="right") - 1
    return owners


def needed_slave_cells(copy: SurfaceCopy, pair_cells: npt.NDArray,
                       clusters: dict[int, int]):
    """A function of a set of pair slave cells (a mask over ``pair_cells``)
    giving the mask of ``copy``'s cells the kernel reads for them: those with a
    node among the pairs' slave nodes or the other nodes of their normal
    clusters (the averaged normals are taken over the cells around a whole
    cluster, and the kernel finds the cluster again from those cells)."""
    cell_ids = copy.global_ids[copy.cells]
    members = roots = None
    if clusters:
        members = np.fromiter(clusters.keys(), dtype=np.int64, count=len(clusters))
        roots = np.fromiter(clusters.values(), dtype=np.int64, count=len(clusters))

    def mask(chosen: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
        ids = np.unique(cell_ids[pair_cells[chosen]])
        if members is not None:
            hit = np.unique(roots[np.isin(members, ids)])
            ids = np.union1d(ids, np.union1d(hit, members[np.isin(roots, hit)]))
        return np.any(np.isin(cell_ids, ids), axis=1)

    return mask


def _pack(mine: DealtPairs, chosen: npt.NDArray[np.bool_], near) -> tuple:
    """What one destination needs: its pairs (renumbered), their slave cells
    and those around them (ids, coordinates), their master cells."""
    slave, master = mine.slave, mine.master
    pairs = mine.pairs[chosen]
    slave_cells = np.flatnonzero(near(chosen))
    master_cells, master_index = np.unique(pairs[:, 1], return_inverse=True)
    local = np.column_stack([np.searchsorted(slave_cells, pairs[:, 0]),
                             master_index.ravel()]).astype(np.int32)
    return (slave.global_ids[slave.cells[slave_cells]], slave.x[slave.cells[slave_cells]],
            master.global_ids[master.cells[master_cells]], master.x[master.cells[master_cells]],
            local, tuple(v[chosen] for v in mine.values))


def _nbytes(part: tuple) -> int:
    return sum(a.nbytes for a in part[:5]) + sum(v.nbytes for v in part[5])


def _copy(like: SurfaceCopy, ids: IntArray, x: FloatArray) -> SurfaceCopy:
    """A surface copy of cells given by their node ids and coordinates."""
    nc, nd = ids.shape
    return SurfaceCopy(like.facet_type, x.reshape(nc * nd, like.x.shape[1]),
                       np.arange(nc * nd, dtype=np.int32).reshape(nc, nd), ids.ravel())


def _unpack(incoming: list[tuple], slave: SurfaceCopy, master: SurfaceCopy, num_values: int,
            received: int) -> DealtPairs:
    """The parts from all ranks as one set of pairs: slave cells sent by
    several ranks (around nodes near a partition boundary) kept once, as the
    averaged normals count every cell around a node once."""
    ns, nm = slave.cells.shape[1], master.cells.shape[1]
    gdim = slave.x.shape[1]
    slave_ids = np.concatenate([p[0] for p in incoming]).reshape(-1, ns)
    slave_x = np.concatenate([p[1] for p in incoming]).reshape(-1, ns, gdim)
    master_ids = np.concatenate([p[2] for p in incoming]).reshape(-1, nm)
    master_x = np.concatenate([p[3] for p in incoming]).reshape(-1, nm, gdim)
    slave_offsets = np.cumsum([0] + [len(p[0]) for p in incoming])
    master_offsets = np.cumsum([0] + [len(p[2]) for p in incoming])
    pairs = np.concatenate([p[4] + [slave_offsets[r], master_offsets[r]]
                            for r, p in enumerate(incoming)]).reshape(-1, 2)
    # one key per cell whatever the order of its nodes: the same cell from two ranks
    key = np.ascontiguousarray(np.sort(slave_ids, axis=1))
    key = key.view(np.dtype((np.void, key.itemsize * ns))).ravel()
    _, first, which = np.unique(key, return_index=True, return_inverse=True)
    pairs[:, 0] = which.ravel()[pairs[:, 0]]
    values = tuple(np.concatenate([p[5][i] for p in incoming]) for i in range(num_values))
    return DealtPairs(_copy(slave, slave_ids[first], slave_x[first]),
                      _copy(master, master_ids, master_x), pairs.astype(np.int32), values,
                      received)
