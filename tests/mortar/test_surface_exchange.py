"""Each rank's share of the master surface (:mod:`dolfinx_mortar.mortar.surface_exchange`):
what a coupling finds with it is what it finds with the whole surface gathered, pair for
pair, and the band brings every neighbour of a paired facet; and the pairs' Jet work dealt
out over the ranks (:mod:`dolfinx_mortar.mortar.pair_share`). Run on 1, 2 and 3 ranks."""
from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from demo_support.self_mirror import CONTACT, build
from dolfinx import fem
from dolfinx_mortar.mortar.coupling import MortarCoupling, polynomial_degree, segment_quadrature
from dolfinx_mortar.mortar.pair_share import deal_evenly, dealt_items, own_pairs
from dolfinx_mortar.mortar.surface_exchange import bisected_boxes
from dolfinx_mortar.surfaces.facet_surface import facet_surface
from support.meshes import MASTER, SLAVE, two_blocks


def test_bisected_boxes_cover_every_box_with_at_most_the_pieces_asked():
    rng = np.random.default_rng(3)
    lower = rng.random((500, 3))
    boxes = np.hstack([lower, lower + 0.05 * rng.random((500, 3))])
    for pieces in (1, 5, 16):
        cover = bisected_boxes(boxes, pieces)
        assert 1 <= len(cover) <= pieces
        inside = np.all(boxes[:, None, :3] >= cover[None, :, :3], axis=2) & \
            np.all(boxes[:, None, 3:] <= cover[None, :, 3:], axis=2)
        assert np.all(inside.any(axis=1))
    assert bisected_boxes(np.zeros((0, 6))).shape == (0, 6)


def facet_keys(global_ids, cells):
    """Each facet as the sorted tuple of its global node ids."""
    return [tuple(sorted(ids)) for ids in global_ids[cells]]


def two_block_surfaces():
    (Vs, ts), (Vm, tm) = two_blocks(MPI.COMM_WORLD, 3, 1)
    return facet_surface(Vs, ts, SLAVE), facet_surface(Vm, tm, MASTER), {}


def quadratic_block_surfaces():
    (Vs, ts), (Vm, tm) = two_blocks(MPI.COMM_WORLD, 3, 2)
    return facet_surface(Vs, ts, SLAVE), facet_surface(Vm, tm, MASTER), {}


def c_body():
    domain, tags = build(MPI.COMM_WORLD, 0.05, whole=True)
    surface = facet_surface(fem.functionspace(domain, ("Lagrange", 1, (2,))), tags, CONTACT)
    return surface, surface, {"self_contact": True, "search_radius": 0.2}


@pytest.mark.parametrize("scene", [two_block_surfaces, c_body], ids=["3d-blocks", "self"])
def test_a_rank_pairs_its_share_of_the_master_as_the_whole_master(scene):
    """Two 3D blocks, and the C body's surface against itself: the pairs and
    their integrals with the rank's share of the master are those with every
    master facet gathered, every master facet that shares a node with a paired
    one came along (the band), and what a rank receives is no more."""
    slave, master, options = scene()
    share = MortarCoupling(slave, master, interface_normals=True, **options)
    whole = MortarCoupling(slave, master, interface_normals=True, whole_master=True, **options)
    assert len(share.pairs) == len(whole.pairs)
    keys = [facet_keys(c.master_global_ids, c.master_cells[c.pairs[:, 1]])
            for c in (share, whole)]
    order = [sorted(range(len(k)), key=lambda i, c=c, k=k: (c.pairs[i, 0], k[i]))
             for c, k in zip((share, whole), keys)]
    assert [keys[0][i] for i in order[0]] == [keys[1][i] for i in order[1]]
    assert np.array_equal(share.pairs[order[0], 0], whole.pairs[order[1], 0])
    for a, b in zip(share.raw_pairs, whole.raw_pairs):
        scale = max(np.max(np.abs(b), initial=0.0), 1e-300)
        assert np.allclose(a[order[0]], b[order[1]], rtol=0, atol=1e-13 * scale)
    # the band: every neighbour of a paired master facet is in the share
    received = set(facet_keys(share.master_global_ids, share.master_cells))
    paired = {key for key in keys[0]}
    for key in facet_keys(whole.master_global_ids, whole.master_cells):
        if any(set(key) & set(p) for p in paired):
            assert key in received
    assert share.received_bytes <= whole.received_bytes
    if MPI.COMM_WORLD.size == 1:
        assert share.received_bytes == whole.received_bytes == 0


def contracted(jets, gdim: int) -> np.ndarray:
    """Each pair's gradients contracted with a field of the global dofs: the
    same whatever order the kernel lists a pair's variable nodes in."""
    nodes = np.maximum(jets.nodes, 0)
    # the width spelled out: a rank without pairs (8 ranks) has no -1 to infer
    field = np.sin(1.0 + (nodes[..., None] * gdim + np.arange(gdim))).reshape(
        len(nodes), nodes.shape[1] * gdim)
    return np.einsum("pak,pk->pa", jets.gradient, field)


@pytest.mark.parametrize("scene", [two_block_surfaces, c_body], ids=["3d-blocks", "self"])
def test_pairs_dealt_to_another_rank_have_the_jets_their_own_rank_computes(scene):
    """The current configuration's Jet work dealt out over the ranks
    (:func:`~dolfinx_mortar.mortar.pair_share.deal_evenly`): every pair is dealt
    once, in shares that differ by at most one, and on the rank it is dealt to
    each pair's gap and gradient are those its own rank computes with every
    slave cell around it: the cells dealt along are enough for the averaged
    normals and their derivatives; nothing else arrives."""
    slave, master, options = scene()
    comm = MPI.COMM_WORLD
    coupling = MortarCoupling(slave, master, **options)
    points, weights = segment_quadrature(slave.tdim, 2 * polynomial_degree(slave))
    jets = {"axisymmetric": slave.axisymmetric, "with_hessian": False}
    # the pairs of every other slave cell: the cells around theirs are not theirs
    which = coupling.pairs[:, 0] % 2 == 0
    own = own_pairs(coupling, which).gap_jets(points, weights, coupling.zero_length, **jets)
    dealt = deal_evenly(coupling, which, own.value, contracted(own, slave.gdim))
    here = dealt.gap_jets(points, weights, coupling.zero_length, **jets)
    shares = comm.allgather(len(dealt.pairs))
    assert sum(shares) == comm.allreduce(int(np.sum(which))) > 0
    assert max(shares) - min(shares) <= 1
    value, gradient = dealt.values
    scale = comm.allreduce(float(np.max(np.abs(own.value), initial=0.0)), op=MPI.MAX)
    assert np.allclose(here.value, value, rtol=0, atol=1e-12 * scale)
    scale = comm.allreduce(float(np.max(np.abs(gradient), initial=0.0)), op=MPI.MAX)
    assert np.allclose(contracted(here, slave.gdim), gradient, rtol=0, atol=1e-12 * scale)
    assert np.array_equal(dealt.rows, dealt.slave.global_ids[dealt.slave.cells[dealt.pairs[:, 0]]])
    if comm.size == 1:     # one rank keeps its pairs and its copies
        assert dealt.received_bytes == 0
        return
    # what arrives is what the dealt pairs read, and no more: the cells around
    # their slave nodes (these scenes have no normal clusters) and their master cells
    ids = dealt.slave.global_ids[dealt.slave.cells]
    assert np.all(np.isin(ids, dealt.rows).any(axis=1))
    assert np.array_equal(np.unique(dealt.pairs[:, 1]), np.arange(len(dealt.master.cells)))


@pytest.mark.parametrize("scene", [two_block_surfaces, quadratic_block_surfaces, c_body],
                         ids=["3d-blocks", "3d-quadratic-blocks", "self"])
def test_segmentation_dealt_out_gives_each_rank_the_pairs_it_segments_itself(scene):
    """All ranks' candidates segmented in equal shares and sent back
    (``deal_segmentation``, what every configuration uses): each rank gets the
    pairs, integrals, points and failed projections that segmenting its own
    candidates gives, in the same order, with the interface normals' two
    passes; with quadratic facets (P2 triangles against 9-node quadrilaterals) too."""
    slave, master, options = scene()
    comm = MPI.COMM_WORLD
    here, dealt = (MortarCoupling(slave, master, interface_normals=True, keep_points=True,
                                  deal_segmentation=deal, **options) for deal in (False, True))
    assert comm.allreduce(len(here.pairs)) > 0
    assert np.array_equal(here.pairs, dealt.pairs)
    assert here.failed_projections == dealt.failed_projections
    # what travels for the segmentation is counted (where every rank's
    # candidates are its share already, only the replies' counters travel)
    counts = comm.allgather(here.num_candidates)
    travel = any(np.any(dealt_items(counts, r) != r) for r in range(comm.size))
    extra = comm.allreduce(dealt.received_bytes - here.received_bytes)
    assert extra >= 0 and (extra > 64 * comm.size or not travel)
    for a, b in zip(here.raw_pairs + (here.area_pairs,), dealt.raw_pairs + (dealt.area_pairs,)):
        scale = comm.allreduce(float(np.max(np.abs(a), initial=0.0)), op=MPI.MAX)
        assert np.allclose(a, b, rtol=0, atol=1e-14 * scale)
    assert np.array_equal(here.points.pairs, dealt.points.pairs)
    for name in ("weights", "gap", "normals", "slave_N", "master_N"):
        a, b = getattr(here.points, name), getattr(dealt.points, name)
        scale = comm.allreduce(float(np.max(np.abs(a), initial=0.0)), op=MPI.MAX)
        assert np.allclose(a, b, rtol=0, atol=1e-14 * scale), name


@pytest.mark.parametrize("counts", [[7], [0, 0], [10, 0], [0, 9, 1], [5, 5, 5],
                                    [30, 1, 0, 2, 13], [1, 2, 3, 4, 5, 6, 7, 100]])
def test_dealing_keeps_each_ranks_own_items_up_to_its_share(counts):
    """Equal shares (differing by one at most), every item dealt once, and a
    rank keeps as many of its own as its share holds: only the rest travel
    (dealing by position in rank order sent a busy rank's own items away and
    brought it others')."""
    owners = [dealt_items(counts, rank) for rank in range(len(counts))]
    taken = np.bincount(np.concatenate(owners), minlength=len(counts))
    assert taken.sum() == sum(counts) and taken.max() - taken.min() <= 1
    for rank, mine in enumerate(owners):
        assert len(mine) == counts[rank]
        assert np.sum(mine == rank) == min(counts[rank], taken[rank])
        # a rank sends only where it keeps its whole share, and receives only where it sends none
        assert np.all(mine == rank) or taken[rank] == np.sum(mine == rank)


def test_blocks_apart_deal_out_no_pair_and_no_candidate():
    """Surfaces apart: no candidate to segment and no pair to deal, on any rank
    (the current configuration evaluates such states before the bodies meet)."""
    slave, master, _ = two_block_surfaces()
    apart = master.moved(np.full_like(master.x, 10.0))
    coupling = MortarCoupling(slave, apart, deal_segmentation=True)
    assert coupling.num_candidates == 0 and len(coupling.pairs) == 0
    assert coupling.D_pairs.shape[1:] == (slave.cells.shape[1],) * 2
    dealt = deal_evenly(coupling, np.zeros(0, dtype=bool))
    assert dealt.pairs.shape == (0, 2)
    if MPI.COMM_WORLD.size > 1:
        assert len(dealt.slave.cells) == 0 and len(dealt.master.cells) == 0
