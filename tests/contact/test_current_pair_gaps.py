"""The kernel ``current_pair_gaps``: the templated segmentation instantiated with
Jets gives the values of the double instantiation (``mortar_integrals``) to
round-off, and exact gradients and Hessians (against central differences), for
every facet type it supports, on wavy, tilted surfaces with curved pieces."""
from __future__ import annotations

import basix
import numpy as np
import pytest

from dolfinx_mortar import _kernels
from demo_support.pair_scenes import FT, MASTER_ID_OFFSET, PairScene, gathered


def _moved(case, node_id: int, k: int, h: float):
    xs, xm = case.xs.copy(), case.xm.copy()
    if node_id >= MASTER_ID_OFFSET:
        xm[node_id - MASTER_ID_OFFSET, k] += h
    else:
        xs[node_id, k] += h
    return xs, xm


@pytest.mark.parametrize("with_mass", [False, True], ids=["gaps", "gaps-and-mass"])
@pytest.mark.parametrize("kind", ["P1_line", "P2_line", "P1_triangle", "Q1_quadrilateral"])
def test_jet_values_equal_the_double_kernel_and_derivatives_are_exact(kind, with_mass):
    """``with_mass``: also the covered mass ∫ N_A N_B of each pair (the dual basis
    rebuilt over the covered part on the current surface), after the gaps."""
    case = PairScene(kind)
    candidates = np.array([(i, j) for i in range(len(case.cs)) for j in range(len(case.cm))])
    pairs, gaps = case.values(case.xs, case.xm, candidates, with_mass)
    assert len(pairs) >= 6
    r = case.jets(case.xs, case.xm, pairs, with_mass=with_mass)
    ns = case.cs.shape[1]
    assert r.value.shape == (len(pairs), ns + (ns * ns if with_mass else 0))
    # values: the same algorithm in two scalar types, equal to round-off
    scale = np.max(np.abs(gaps))
    assert scale > 0 and np.max(np.abs(r.value - gaps)) <= 1e-13 * scale
    # curved or tilted pieces: the gaps are not linear in the nodes
    assert np.max(np.abs(r.hessian)) > 1e-3 * np.max(np.abs(r.gradient))
    gdim, h = case.gdim, 1e-6
    worst_grad = worst_hess = 0.0
    for p in range(0, len(pairs), max(1, len(pairs) // 6)):
        nodes = r.nodes[p]
        grad, hess = r.gradient[p], r.hessian[p]
        fd_grad = np.zeros_like(grad)
        fd_hess = np.zeros_like(hess)
        for v, node_id in enumerate(nodes):
            if node_id < 0:
                continue
            for k in range(gdim):
                column = v * gdim + k
                plus = case.jets(*_moved(case, node_id, k, h), pairs[p:p + 1],
                                 with_mass=with_mass)
                minus = case.jets(*_moved(case, node_id, k, -h), pairs[p:p + 1],
                                  with_mass=with_mass)
                fd_grad[:, column] = (plus.value[0] - minus.value[0]) / (2 * h)
                # the perturbed pair's variables are the same nodes in the same
                # order (alone, it is not padded)
                width = plus.gradient.shape[2]
                assert np.array_equal(plus.nodes[0], nodes[:width // gdim])
                assert np.all(nodes[width // gdim:] < 0)
                fd_hess[:, :width, column] = (plus.gradient[0]
                                              - minus.gradient[0]) / (2 * h)
        worst_grad = max(worst_grad, np.max(np.abs(fd_grad - grad)) / np.max(np.abs(grad)))
        worst_hess = max(worst_hess, np.max(np.abs(fd_hess - hess)) / np.max(np.abs(hess)))
    assert worst_grad <= 1e-8, worst_grad
    assert worst_hess <= 1e-8, worst_hess


def test_averaged_normal_derivatives_are_exact():
    case = PairScene("P1_triangle")
    gx, gc, gid = gathered(case.xs, case.cs)
    node = 5                                    # an interior node: six triangles around it
    r = _kernels.averaged_normal_derivatives(case.kind, gx, gc, gid, node)
    assert np.allclose(r.value, case.normals(case.xs)[node], rtol=0, atol=1e-15)
    assert len(r.star) == 7
    h = 1e-6
    for j, star_node in enumerate(r.star):
        for k in range(3):
            values = []
            for sign in (1, -1):
                xs = case.xs.copy()
                xs[star_node, k] += sign * h
                values.append(case.normals(xs)[node])
            fd = (values[0] - values[1]) / (2 * h)
            assert np.max(np.abs(fd - r.gradient[:, 3 * j + k])) <= 1e-8 * np.max(
                np.abs(r.gradient))


def test_unsupported_facets_are_named():
    case = PairScene("P1_triangle")
    x = np.zeros((6, 3))
    cells = np.arange(6, dtype=np.int32).reshape(1, 6)
    with pytest.raises(ValueError, match="P2 triangle"):
        _kernels.current_pair_gaps(FT.P2_triangle, x, cells, np.arange(6), FT.P2_triangle, x,
                                   cells, np.arange(6), np.zeros((1, 2), dtype=np.int32),
                                   case.points, case.weights, case.zero)


@pytest.mark.parametrize("kind", ["P1_line", "P2_line", "P1_triangle", "Q1_quadrilateral"])
@pytest.mark.parametrize("with_mass", [False, True], ids=["gaps", "gaps-and-mass"])
def test_weighted_sum_equals_the_sum_of_the_weighted_functions(kind, with_mass):
    """``node_weights``: the kernel's one function Σ_A w_A c_A per pair (what a
    Newton matrix needs) is the weighted sum of the ns functions, value, gradient
    and Hessian; with the mass, of its ns + ns² functions."""
    case = PairScene(kind)
    candidates = np.array([(i, j) for i in range(len(case.cs)) for j in range(len(case.cm))])
    pairs, _ = case.values(case.xs, case.xm, candidates)
    ns = case.cs.shape[1]
    weights = np.random.default_rng(3).uniform(-1, 2, (len(pairs),
                                                       ns + (ns * ns if with_mass else 0)))
    apart = case.jets(case.xs, case.xm, pairs, with_mass=with_mass)
    summed = case.jets(case.xs, case.xm, pairs, node_weights=weights, with_mass=with_mass)
    assert np.array_equal(summed.nodes, apart.nodes)
    for key in ("value", "gradient", "hessian"):
        whole, parts = getattr(summed, key), getattr(apart, key)
        expected = np.einsum("pa,pa...->p...", weights, parts)
        assert whole.shape == (len(pairs), 1) + parts.shape[2:]
        scale = np.max(np.abs(expected))
        assert scale > 0
        assert np.max(np.abs(whole[:, 0] - expected)) <= 1e-13 * scale, key
    # the gradients alone, too
    alone = case.jets(case.xs, case.xm, pairs, with_hessian=False, node_weights=weights,
                      with_mass=with_mass)
    assert np.allclose(alone.gradient, summed.gradient, rtol=0,
                       atol=1e-13 * np.max(np.abs(summed.gradient)))


def test_weights_of_the_wrong_shape_are_refused():
    case = PairScene("P1_triangle")
    pairs = np.array([[0, 0], [1, 1]])
    with pytest.raises(ValueError, match="node_weights must have shape"):
        case.jets(case.xs, case.xm, pairs, node_weights=np.ones((2, 2)))


def _quadratic_copy(kind: str, x: np.ndarray, cells: np.ndarray):
    """The same straight-sided cells as P2 facets (new mid-edge nodes at the
    midpoints, Basix order), and T with N^{P1} = T N^{P2} on every cell."""
    if kind == "P1_line":
        edges = [(0, 1)]
    else:
        edges = [(1, 2), (0, 2), (0, 1)]        # Basix: the edge opposite each vertex
    nv = cells.shape[1]
    points, cells2 = [x], []
    for row in cells:
        mids = [(x[row[a]] + x[row[b]]) / 2 for a, b in edges]
        start = sum(len(p) for p in points)
        points.append(np.array(mids))
        cells2.append(list(row) + list(range(start, start + len(edges))))
    T = np.zeros((nv, nv + len(edges)))
    T[:, :nv] = np.eye(nv)
    for e, (a, b) in enumerate(edges):
        T[a, nv + e] = T[b, nv + e] = 0.5
    return np.concatenate(points), np.array(cells2, dtype=np.int32), T


@pytest.mark.parametrize("kind", ["P1_line", "P1_triangle"])
def test_affine_pairs_match_the_general_segmentation(kind):
    """Affine slave and master cells take their own path (everything affine in
    the slave plane, interpolated from the integration cells' vertices); the
    same flat cells as P2 facets take the general one (projections at every
    point). With a uniform normal field every integrand is a polynomial that
    the rule integrates exactly, so both must give D, M, the gaps and the
    areas to round-off, through N^{P1} = T N^{P2}."""
    case = PairScene(kind)
    gdim = case.gdim
    normal = np.array([0.1, -1.0]) if gdim == 2 else np.array([0.1, -0.2, 1.0])
    normal /= np.linalg.norm(normal)
    cell = basix.CellType.interval if gdim == 2 else basix.CellType.triangle
    points, weights = basix.make_quadrature(cell, 4)   # exact for P2 x P2 and P2 x affine
    candidates = np.array([(i, j) for i in range(len(case.cs))
                           for j in range(len(case.cm))], dtype=np.int32)

    def integrals(kind_, xs, cs, xm, cm):
        return _kernels.mortar_integrals(kind_, xs, cs, np.tile(normal, (len(xs), 1)), kind_,
                                         xm, cm, candidates, points, weights, True,
                                         length_scale=case.length_scale)

    flat = integrals(case.kind, case.xs, case.cs.astype(np.int32), case.xm,
                     case.cm.astype(np.int32))
    xs2, cs2, Ts = _quadratic_copy(kind, case.xs, case.cs)
    xm2, cm2, Tm = _quadratic_copy(kind, case.xm, case.cm)
    general = integrals(FT.P2_line if gdim == 2 else FT.P2_triangle, xs2, cs2, xm2, cm2)
    assert len(flat.pairs) >= 6
    assert np.array_equal(flat.pairs, general.pairs)
    expected = {"D": np.einsum("ab,pbc,dc->pad", Ts, general.D, Ts),
                "M": np.einsum("ab,pbc,dc->pad", Ts, general.M, Tm),
                "gap": general.gap @ Ts.T, "area": general.area}
    for key, value in expected.items():
        scale = np.max(np.abs(value))
        assert scale > 0
        assert np.max(np.abs(getattr(flat, key) - value)) <= 1e-13 * scale, key
