"""The kernel ``current_pair_gaps``: the templated segmentation instantiated with
Jets gives the values of the double instantiation (``mortar_integrals``) to
round-off, and exact gradients and Hessians (against central differences), for
every facet type it supports, on wavy, tilted surfaces with curved pieces."""
from __future__ import annotations

import numpy as np
import pytest

from dolfinx_mortar import _kernels
from dolfinx_mortar.demo_support.pair_scenes import FT, MASTER_ID_OFFSET, PairScene, gathered


def _moved(case, node_id: int, k: int, h: float):
    xs, xm = case.xs.copy(), case.xm.copy()
    if node_id >= MASTER_ID_OFFSET:
        xm[node_id - MASTER_ID_OFFSET, k] += h
    else:
        xs[node_id, k] += h
    return xs, xm


@pytest.mark.parametrize("kind", ["P1_line", "P2_line", "P1_triangle", "Q1_quadrilateral"])
def test_jet_values_equal_the_double_kernel_and_derivatives_are_exact(kind):
    case = PairScene(kind)
    candidates = np.array([(i, j) for i in range(len(case.cs)) for j in range(len(case.cm))])
    pairs, gaps = case.values(case.xs, case.xm, candidates)
    assert len(pairs) >= 6
    r = case.jets(case.xs, case.xm, pairs)
    # values: the same algorithm in two scalar types, equal to round-off
    scale = np.max(np.abs(gaps))
    assert scale > 0 and np.max(np.abs(r["value"] - gaps)) <= 1e-13 * scale
    # curved or tilted pieces: the gaps are not linear in the nodes
    assert np.max(np.abs(r["hessian"])) > 1e-3 * np.max(np.abs(r["gradient"]))
    gdim, h = case.gdim, 1e-6
    worst_grad = worst_hess = 0.0
    for p in range(0, len(pairs), max(1, len(pairs) // 6)):
        nodes = r["nodes"][p]
        grad, hess = r["gradient"][p], r["hessian"][p]
        fd_grad = np.zeros_like(grad)
        fd_hess = np.zeros_like(hess)
        for v, node_id in enumerate(nodes):
            if node_id < 0:
                continue
            for k in range(gdim):
                column = v * gdim + k
                plus = case.jets(*_moved(case, node_id, k, h), pairs[p:p + 1])
                minus = case.jets(*_moved(case, node_id, k, -h), pairs[p:p + 1])
                fd_grad[:, column] = (plus["value"][0] - minus["value"][0]) / (2 * h)
                # the perturbed pair's variables are the same nodes in the same
                # order (alone, it is not padded)
                width = plus["gradient"].shape[2]
                assert np.array_equal(plus["nodes"][0], nodes[:width // gdim])
                assert np.all(nodes[width // gdim:] < 0)
                fd_hess[:, :width, column] = (plus["gradient"][0]
                                              - minus["gradient"][0]) / (2 * h)
        worst_grad = max(worst_grad, np.max(np.abs(fd_grad - grad)) / np.max(np.abs(grad)))
        worst_hess = max(worst_hess, np.max(np.abs(fd_hess - hess)) / np.max(np.abs(hess)))
    assert worst_grad <= 1e-8, worst_grad
    assert worst_hess <= 1e-8, worst_hess


def test_averaged_normal_derivatives_are_exact():
    case = PairScene("P1_triangle")
    gx, gc, gid = gathered(case.xs, case.cs)
    node = 5                                    # an interior node: six triangles around it
    r = _kernels.averaged_normal_derivatives(case.kind, gx, gc, gid, node)
    assert np.allclose(r["value"], case.normals(case.xs)[node], rtol=0, atol=1e-15)
    assert len(r["star"]) == 7
    h = 1e-6
    for j, star_node in enumerate(r["star"]):
        for k in range(3):
            values = []
            for sign in (1, -1):
                xs = case.xs.copy()
                xs[star_node, k] += sign * h
                values.append(case.normals(xs)[node])
            fd = (values[0] - values[1]) / (2 * h)
            assert np.max(np.abs(fd - r["gradient"][:, 3 * j + k])) <= 1e-8 * np.max(
                np.abs(r["gradient"]))


def test_unsupported_facets_are_named():
    case = PairScene("P1_triangle")
    x = np.zeros((6, 3))
    cells = np.arange(6, dtype=np.int32).reshape(1, 6)
    with pytest.raises(ValueError, match="P2 triangle"):
        _kernels.current_pair_gaps(FT.P2_triangle, x, cells, np.arange(6), FT.P2_triangle, x,
                                   cells, np.arange(6), np.zeros((1, 2), dtype=np.int32),
                                   case.points, case.weights, case.zero)
