"""The kernel ``current_pair_gaps``: the templated segmentation instantiated with
Jets gives the values of the double instantiation (``mortar_integrals``) to
round-off, and exact gradients and Hessians (against central differences), for
every facet type it supports, on wavy, tilted surfaces with curved pieces."""
from __future__ import annotations

import basix
import numpy as np
import pytest

from dolfinx_mortar import _kernels

FT = _kernels.FacetType
MASTER_ID_OFFSET = 1000


def _grid(kind: str):
    """A structured surface patch: node coordinates in the plane and cells, in
    Basix's node order, oriented so that the natural normal points to +z (3D)
    or -y (2D, cells left to right)."""
    if kind in ("P1_line", "P2_line"):
        n = 4
        if kind == "P1_line":
            x = np.linspace(0, 1, n + 1)[:, None]
            cells = np.array([[i, i + 1] for i in range(n)])
        else:
            x = np.linspace(0, 1, 2 * n + 1)[:, None]
            cells = np.array([[2 * i, 2 * i + 2, 2 * i + 1] for i in range(n)])
        return x, cells
    m = 3
    if kind == "Q1_quadrilateral":
        g = np.linspace(0, 1, m + 1)
        X, Y = np.meshgrid(g, g, indexing="xy")
        x = np.column_stack([X.ravel(), Y.ravel()])
        idx = np.arange((m + 1) ** 2).reshape(m + 1, m + 1)
        cells = np.array([[idx[j, i], idx[j, i + 1], idx[j + 1, i], idx[j + 1, i + 1]]
                          for j in range(m) for i in range(m)])
        return x, cells
    g = np.linspace(0, 1, m + 1)
    X, Y = np.meshgrid(g, g, indexing="xy")
    x = np.column_stack([X.ravel(), Y.ravel()])
    idx = np.arange((m + 1) ** 2).reshape(m + 1, m + 1)
    cells = []
    for j in range(m):
        for i in range(m):
            a, b, c, d = idx[j, i], idx[j, i + 1], idx[j + 1, i], idx[j + 1, i + 1]
            cells += [[a, b, d], [a, d, c]]
    return x, np.array(cells)


def _surfaces(kind: str, rng):
    """Slave patch and a finer master patch, facing each other, wavy and shifted."""
    x, cells = _grid(kind)
    gdim = x.shape[1] + 1
    def lift(x, height, shift, wave):
        if gdim == 2:
            s = x[:, 0] * 1.1 + shift
            return np.column_stack([s, height + wave * np.sin(5 * s) + 0.01 * s ** 2])
        s, t = x[:, 0] * 1.1 + shift, x[:, 1] * 0.9 + 0.5 * shift
        return np.column_stack([s, t, height + wave * np.sin(4 * s) * np.cos(3 * t)
                                + 0.05 * s * t])
    xs = lift(x, 0.0, 0.0, 0.02) + 0.004 * rng.uniform(-1, 1, (len(x), gdim))
    xm = lift(x, -0.015, 0.13, 0.015) + 0.004 * rng.uniform(-1, 1, (len(x), gdim))
    # the master faces the slave: reversed orientation
    if gdim == 2:
        mcells = cells[:, [1, 0] + list(range(2, cells.shape[1]))]
    elif kind == "Q1_quadrilateral":
        mcells = cells[:, [0, 2, 1, 3]]
    else:
        mcells = cells[:, [0, 2, 1]]
    return xs, cells, xm, mcells


def _gathered(x, cells):
    """One node copy per cell (as gather_surface), with the node ids."""
    return x[cells].reshape(-1, x.shape[1]), np.arange(cells.size, dtype=np.int32).reshape(
        cells.shape), cells.ravel().astype(np.int64)


class _Pairs:
    def __init__(self, kind):
        rng = np.random.default_rng(7)
        self.kind = getattr(FT, kind)
        self.xs, self.cs, self.xm, self.cm = _surfaces(kind, rng)
        self.gdim = self.xs.shape[1]
        tdim = self.gdim - 1
        degree = 2 if kind == "P2_line" else (2 if kind == "Q1_quadrilateral" else 1)
        cell = basix.CellType.interval if tdim == 1 else basix.CellType.triangle
        self.points, self.weights = basix.make_quadrature(cell, 2 * degree)
        both = np.concatenate([self.xs, self.xm])
        self.length_scale = float(max(np.max(np.abs(both)), np.ptp(both, axis=0).max()))
        self.zero = 1e-10 * self.length_scale

    def normals(self, xs):
        cell_normals = _kernels.element_node_normals(self.kind, xs, self.cs.astype(np.int32),
                                                     size_weighted=True)
        summed = np.zeros_like(xs)
        np.add.at(summed, self.cs, cell_normals)
        return summed / np.linalg.norm(summed, axis=1)[:, None]

    def values(self, xs, xm, candidates):
        """The double instantiation: mortar_integrals' ∫ N_A d per pair."""
        r = _kernels.mortar_integrals(self.kind, xs, self.cs.astype(np.int32), self.normals(xs),
                                      self.kind, xm, self.cm.astype(np.int32),
                                      candidates.astype(np.int32), self.points, self.weights,
                                      True, length_scale=self.length_scale)
        return r["pairs"], r["gap"]

    def jets(self, xs, xm, pairs):
        gx, gc, gid = _gathered(xs, self.cs)
        mx, mc, mid = _gathered(xm, self.cm)
        return _kernels.current_pair_gaps(self.kind, gx, gc, gid, self.kind, mx, mc,
                                          mid + MASTER_ID_OFFSET, pairs.astype(np.int32),
                                          self.points, self.weights, self.zero)


def _moved(case, node_id: int, k: int, h: float):
    xs, xm = case.xs.copy(), case.xm.copy()
    if node_id >= MASTER_ID_OFFSET:
        xm[node_id - MASTER_ID_OFFSET, k] += h
    else:
        xs[node_id, k] += h
    return xs, xm


@pytest.mark.parametrize("kind", ["P1_line", "P2_line", "P1_triangle", "Q1_quadrilateral"])
def test_jet_values_equal_the_double_kernel_and_derivatives_are_exact(kind):
    case = _Pairs(kind)
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
    case = _Pairs("P1_triangle")
    gx, gc, gid = _gathered(case.xs, case.cs)
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
    case = _Pairs("P1_triangle")
    x = np.zeros((6, 3))
    cells = np.arange(6, dtype=np.int32).reshape(1, 6)
    with pytest.raises(ValueError, match="P2 triangle"):
        _kernels.current_pair_gaps(FT.P2_triangle, x, cells, np.arange(6), FT.P2_triangle, x,
                                   cells, np.arange(6), np.zeros((1, 2), dtype=np.int32),
                                   case.points, case.weights, case.zero)
