"""Small slave and master facet patches facing each other, wavy and shifted, for
checking and timing the pair kernels (``mortar_integrals``, ``current_pair_gaps``)
without a mesh: every facet type's pairs on curved, tilted geometry."""
from __future__ import annotations

import basix
import numpy as np

from dolfinx_mortar import _kernels

FT = _kernels.FacetType
#: master node ids are offset by this, so that slave and master ids differ
MASTER_ID_OFFSET = 1000


def grid(kind: str):
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


def surfaces(kind: str, rng):
    """Slave patch and a finer master patch, facing each other, wavy and shifted."""
    x, cells = grid(kind)
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


def gathered(x, cells):
    """One node copy per cell (as gather_surface), with the node ids."""
    return x[cells].reshape(-1, x.shape[1]), np.arange(cells.size, dtype=np.int32).reshape(
        cells.shape), cells.ravel().astype(np.int64)


class PairScene:
    """Slave and master patches of one facet type, with the segment rule and the
    zero length a coupling would use; ``values`` and ``jets`` call the two
    instantiations of the pair segmentation."""

    def __init__(self, kind: str, seed: int = 7):
        rng = np.random.default_rng(seed)
        self.kind = getattr(FT, kind)
        self.xs, self.cs, self.xm, self.cm = surfaces(kind, rng)
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

    def values(self, xs, xm, candidates, with_mass: bool = False):
        """The double instantiation: mortar_integrals' ∫ N_A d per pair (with
        ``with_mass``, followed by its ∫ N_A N_B, row-major, as the Jets give them)."""
        r = _kernels.mortar_integrals(self.kind, xs, self.cs.astype(np.int32), self.normals(xs),
                                      self.kind, xm, self.cm.astype(np.int32),
                                      candidates.astype(np.int32), self.points, self.weights,
                                      True, length_scale=self.length_scale)
        if with_mass:
            return r.pairs, np.hstack([r.gap, r.D.reshape(len(r.pairs), -1)])
        return r.pairs, r.gap

    def jets(self, xs, xm, pairs, with_hessian: bool = True, node_weights=None,
             with_mass: bool = False):
        """The Jet instantiation: ``current_pair_gaps`` (per node, or the
        ``node_weights``-weighted sum per pair; ``with_mass``: also ∫ N_A N_B)."""
        gx, gc, gid = gathered(xs, self.cs)
        mx, mc, mid = gathered(xm, self.cm)
        return _kernels.current_pair_gaps(self.kind, gx, gc, gid, self.kind, mx, mc,
                                          mid + MASTER_ID_OFFSET, pairs.astype(np.int32),
                                          self.points, self.weights, self.zero,
                                          with_hessian=with_hessian, node_weights=node_weights,
                                          with_mass=with_mass)
