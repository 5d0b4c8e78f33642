"""Curved, non-uniform slave surfaces built from arrays, for the basis tests."""
from __future__ import annotations

import numpy as np

from dolfinx_mortar.lagrange import LagrangeSurface


def _compact(x: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drop nodes that no cell uses and renumber."""
    used, inverse = np.unique(cells, return_inverse=True)
    return x[used], inverse.reshape(cells.shape)


def curved_line(degree: int, n: int = 7, seed: int = 0) -> LagrangeSurface:
    """A wavy, non-uniform chain of P1/P2 line elements in 2D."""
    rng = np.random.default_rng(seed)
    breaks = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0.05, 0.95, n - 1)]))
    if degree == 1:
        s = breaks
        cells = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    else:
        s = np.empty(2 * n + 1)
        s[0::2] = breaks
        s[1::2] = 0.5 * (breaks[:-1] + breaks[1:])
        cells = np.column_stack([2 * np.arange(n), 2 * np.arange(n) + 2,
                                 2 * np.arange(n) + 1])
    x = np.column_stack([s, 0.1 * np.sin(3.0 * s)])
    return LagrangeSurface("interval", degree, x, cells)


def curved_patch(cell: str, degree: int, n: int = 4, serendipity: bool = False,
                 quadratic_transform: bool = False, seed: int = 1) -> LagrangeSurface:
    """A curved patch of triangles or quadrilaterals in 3D.

    Nodes sit on a (degree·n + 1)² lattice; interior vertices are jittered so
    that elements are not affine.
    """
    k = degree
    m = k * n + 1
    s, t = np.meshgrid(np.linspace(0, 1, m), np.linspace(0, 1, m), indexing="ij")
    rng = np.random.default_rng(seed)
    jitter = rng.uniform(-0.15, 0.15, (2, m, m)) / (n * k)
    jitter[:, [0, -1], :] = 0
    jitter[:, :, [0, -1]] = 0
    if k == 2:  # keep mid-edge nodes in the middle of their (jittered) vertices
        jitter[:, 1::2, :] = 0
        jitter[:, :, 1::2] = 0
    s, t = s + jitter[0], t + jitter[1]
    x = np.column_stack([s.ravel(), t.ravel(),
                         (0.15 * np.sin(2.0 * s) * np.cos(1.5 * t)).ravel()])

    def node(i, j):
        return i * m + j

    cells = []
    for i in range(n):
        for j in range(n):
            I, J = k * i, k * j
            v00, v10, v01, v11 = node(I, J), node(I + k, J), node(I, J + k), node(I + k, J + k)
            if cell == "triangle":
                if k == 1:
                    cells += [[v00, v10, v01], [v11, v01, v10]]
                else:
                    # Basix P2 triangle: vertices, then edge i opposite vertex i.
                    cells += [[v00, v10, v01, node(I + 1, J + 1), node(I, J + 1), node(I + 1, J)],
                              [v11, v01, v10, node(I + 1, J + 1), node(I + 2, J + 1),
                               node(I + 1, J + 2)]]
            else:
                c = [v00, v10, v01, v11]
                if k == 2:
                    # Basix quadrilateral edges: (0,1), (0,2), (1,3), (2,3)
                    c += [node(I + 1, J), node(I, J + 1), node(I + 2, J + 1), node(I + 1, J + 2)]
                    if not serendipity:
                        c += [node(I + 1, J + 1)]
                cells.append(c)
    x, cells = _compact(x, np.array(cells))
    return LagrangeSurface(cell, degree, x, cells, serendipity=serendipity,
                           quadratic_transform=quadratic_transform)
