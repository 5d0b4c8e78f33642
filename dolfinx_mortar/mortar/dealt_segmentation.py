"""A coupling's segmentation dealt out evenly over the ranks (docs/DESIGN.md, §Parallel).

The current configuration segments again at every evaluation, and the slave
facets sit where the bulk's partition put them: on the ironing scene one rank
holds them all, and its segmentation (3.2 s of its 8.7 s of contact CPU at 16
ranks) did not divide. Each candidate pair's segmentation reads only its slave
cell's nodes and nodal normals and its master cell's nodes, so the candidates
are dealt out in equal shares with those (a rank keeps what its share holds of
its own: ``pair_share.dealt_items``), segmented where they land, and the pairs
found come back to the rank that owns their slave facet, in the order of its
candidates: what the kernel gives on one rank, computed by all of them.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar import _kernels
from dolfinx_mortar.mortar.pair_share import share_owners
from dolfinx_mortar.mortar.surface_exchange import SurfaceCopy

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
#: the kernel's per-pair and per-point results, in the order they are carried
PAIR_FIELDS = ("D", "M", "gap", "area")
POINT_FIELDS = ("point_weights", "point_gap", "point_normals", "point_slave_N",
                "point_master_N")
#: ``segment(xs, slave_cells, normals, master_x, master_cells, candidates, keep_points)``
Segment = Callable[..., "_kernels.MortarIntegrals"]


@dataclass
class Segmentation:
    """The fields of the kernel's ``MortarIntegrals`` that a coupling reads, for
    this rank's candidates, whichever rank segmented them."""

    pairs: npt.NDArray[np.int32]
    D: FloatArray
    M: FloatArray
    gap: FloatArray
    area: FloatArray
    failed_projections: int
    degenerate_slave_facets: npt.NDArray[np.int32]
    degenerate_master_facets: npt.NDArray[np.int32]
    point_pairs: npt.NDArray[np.int32] = field(default_factory=lambda: np.zeros(0, np.int32))
    point_weights: FloatArray = field(default_factory=lambda: np.zeros(0))
    point_gap: FloatArray = field(default_factory=lambda: np.zeros(0))
    point_normals: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    point_slave_N: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    point_master_N: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    #: bytes this rank received from the others: candidates to segment, and pairs back
    received_bytes: int = 0


def segmenter(slave, master, points: FloatArray, weights: FloatArray,
              opposing_normals_only: bool, length_scale: float,
              along_normals: bool, keep_slivers: bool = False) -> Segment:
    """The kernel's segmentation of the ``slave`` and ``master`` surfaces' facet
    types with these settings, of any of their cells (``keep_slivers``: see
    :class:`~dolfinx_mortar.mortar.coupling.MortarCoupling`)."""
    def segment(xs, cells, normals, master_x, master_cells, candidates, keep_points):
        return _kernels.mortar_integrals(
            slave.facet_type, xs, cells, normals, master.facet_type, master_x, master_cells,
            candidates, points, weights, opposing_normals_only, length_scale=length_scale,
            keep_points=keep_points, axisymmetric=slave.axisymmetric,
            project_along_normals=along_normals, keep_slivers=keep_slivers)
    return segment


def dealt_segmentation(comm: MPI.Comm, segment: Segment, xs: FloatArray,
                       slave_cells: npt.NDArray[np.int32], normals: FloatArray,
                       master: SurfaceCopy, candidates: npt.NDArray,
                       keep_points: bool) -> Segmentation:
    """Segment all ranks' ``candidates`` (slave cell, master cell of ``master``)
    in equal shares, and return this rank's pairs (collective)."""
    destination = share_owners(comm, len(candidates))
    outgoing, kept = [], []
    for rank in range(comm.size):
        chosen = np.flatnonzero(destination == rank)
        slave, slave_index = _used(candidates[chosen, 0], len(slave_cells))
        masters, master_index = _used(candidates[chosen, 1], len(master.cells))
        # what travels: the cells once each, and 8 bytes a candidate
        outgoing.append((xs[slave_cells[slave]], normals[slave_cells[slave]],
                         master.x[master.cells[masters]],
                         np.column_stack([slave_index, master_index]).astype(np.int32)))
        kept.append((chosen, slave, masters))
    incoming = comm.alltoall(outgoing)
    replies = comm.alltoall(_segment_parts(incoming, segment, keep_points))
    received = sum(_nbytes(part) for rank, part in enumerate(incoming + replies)
                   if rank % comm.size != comm.rank)
    # back in this rank's numbering: candidates, slave cells, master cells
    replies = [(chosen[r[0]], *r[1:6], slave[r[6]], masters[r[7]], *r[8:])
               for (chosen, slave, masters), r in zip(kept, replies)]
    result = _collect(replies, candidates, keep_points)
    result.received_bytes = int(received)
    return result


def _nbytes(part: tuple) -> int:
    """Bytes of the arrays in an exchanged part."""
    return sum(np.asarray(a).nbytes for a in part)


def _used(cells: npt.NDArray, count: int) -> tuple[IntArray, IntArray]:
    """The distinct cells among ``cells`` (of ``count``), ascending, and each
    entry's place among them: ``np.unique(..., return_inverse=True)`` in O(n)
    (a quarter of the segmentation's own time went to sorting them)."""
    used = np.zeros(count, dtype=bool)
    used[cells] = True
    place = np.cumsum(used) - 1
    return np.flatnonzero(used), place[cells]


def _segment_parts(parts: list[tuple], segment: Segment, keep_points: bool) -> list[tuple]:
    """Segment the candidates every rank sent in one kernel call, and split the
    pairs found (in the senders' numbering) by sender."""
    ns, nm = parts[0][0].shape[1], parts[0][2].shape[1]
    gdim = parts[0][0].shape[2]
    slave_x = np.concatenate([p[0] for p in parts]).reshape(-1, gdim)
    normals = np.concatenate([p[1] for p in parts]).reshape(-1, gdim)
    master_x = np.concatenate([p[2] for p in parts]).reshape(-1, gdim)
    slave_first = np.cumsum([0] + [len(p[0]) for p in parts])
    master_first = np.cumsum([0] + [len(p[2]) for p in parts])
    candidates = np.concatenate([p[3] + [slave_first[k], master_first[k]]
                                 for k, p in enumerate(parts)]).reshape(-1, 2)
    cells = (np.arange(len(slave_x), dtype=np.int32).reshape(-1, ns),
             np.arange(len(master_x), dtype=np.int32).reshape(-1, nm))
    if len(candidates):
        r = segment(slave_x, cells[0], normals, master_x, cells[1],
                    candidates.astype(np.int32), keep_points)
    else:
        r = _nothing(ns, nm, gdim)
    pairs = np.asarray(r.pairs, dtype=np.int64).reshape(-1, 2)
    sender = np.searchsorted(slave_first, pairs[:, 0], side="right") - 1
    # the candidate each pair came from: (slave, master) are distinct among them
    key = candidates[:, 0].astype(np.int64) * (len(master_x) + 1) + candidates[:, 1]
    by_key = np.argsort(key, kind="stable")   # runs by slave cell: timsort is near linear
    which = by_key[np.searchsorted(key[by_key], pairs[:, 0] * (len(master_x) + 1) + pairs[:, 1])]
    candidate_first = np.cumsum([0] + [len(p[3]) for p in parts])
    bad_slave = np.asarray(r.degenerate_slave_facets, dtype=np.int64)
    bad_master = np.asarray(r.degenerate_master_facets, dtype=np.int64)
    points = np.asarray(r.point_pairs, dtype=np.int64) if keep_points else None
    replies = []
    for k, part in enumerate(parts):
        mine = np.flatnonzero(sender == k)
        # in the sender's part: its candidate, its slave and master cells
        reply = [(which[mine] - candidate_first[k]).astype(np.int32)]
        reply += [np.asarray(getattr(r, name))[mine] for name in PAIR_FIELDS]
        reply.append(int(r.failed_projections) if k == 0 else 0)
        in_part = (bad_slave >= slave_first[k]) & (bad_slave < slave_first[k + 1])
        reply.append(bad_slave[in_part] - slave_first[k])
        in_part = (bad_master >= master_first[k]) & (bad_master < master_first[k + 1])
        reply.append(bad_master[in_part] - master_first[k])
        if keep_points:
            at = np.isin(points, mine)
            reply.append(np.searchsorted(mine, points[at]))
            reply += [np.asarray(getattr(r, name))[at] for name in POINT_FIELDS]
        replies.append(tuple(reply))
    return replies


def _nothing(ns: int, nm: int, gdim: int) -> Segmentation:
    """The kernel's answer to no candidates."""
    return Segmentation(np.zeros((0, 2), np.int32), np.zeros((0, ns, ns)), np.zeros((0, ns, nm)),
                        np.zeros((0, ns)), np.zeros(0), 0, np.zeros(0, np.int32),
                        np.zeros(0, np.int32), point_normals=np.zeros((0, gdim)),
                        point_slave_N=np.zeros((0, ns)), point_master_N=np.zeros((0, nm)))


def _collect(replies: list[tuple], candidates: npt.NDArray, keep_points: bool) -> Segmentation:
    """The pairs of this rank's candidates from every rank that segmented some,
    in the order of the candidates (as one kernel call gives them)."""
    candidate = np.concatenate([r[0] for r in replies]).astype(np.int64)
    order = np.argsort(candidate, kind="stable")
    pair_first = np.cumsum([0] + [len(r[0]) for r in replies])
    fields = {name: np.concatenate([r[1 + i] for r in replies])[order]
              for i, name in enumerate(PAIR_FIELDS)}
    result = Segmentation(
        pairs=np.asarray(candidates)[candidate[order]].reshape(-1, 2).astype(np.int32),
        failed_projections=sum(r[5] for r in replies),
        degenerate_slave_facets=np.unique(np.concatenate([r[6] for r in replies])).astype(
            np.int32),
        degenerate_master_facets=np.unique(np.concatenate([r[7] for r in replies])).astype(
            np.int32), **fields)
    if keep_points:
        # a point's pair, renumbered from its reply's pairs to the sorted ones
        rank_of = np.empty(len(order), dtype=np.int64)
        rank_of[order] = np.arange(len(order))
        point_pairs = np.concatenate([rank_of[r[8] + pair_first[k]]
                                      for k, r in enumerate(replies)])
        point_order = np.argsort(point_pairs, kind="stable")
        result.point_pairs = point_pairs[point_order].astype(np.int32)
        for i, name in enumerate(POINT_FIELDS):
            setattr(result, name, np.concatenate([r[9 + i] for r in replies])[point_order])
    return result
