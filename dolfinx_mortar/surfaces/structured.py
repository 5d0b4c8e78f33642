"""Structured, flat facet surfaces built from arrays (no DOLFINx, no gmsh).

For tests and benchmarks that need non-matching slave and master surfaces of
any size quickly: everything is vectorized with numpy.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import numpy.typing as npt

from dolfinx_mortar.surfaces.lagrange import LagrangeSurface


def lattice_cells(cell: str, k: int, nx: int, ny: int, serendipity: bool) -> npt.NDArray[np.int64]:
    """Cells on a (k·nx + 1) × (k·ny + 1) node lattice, Basix ordering, normal +z."""
    m = k * ny + 1
    I, J = np.meshgrid(k * np.arange(nx), k * np.arange(ny), indexing="ij")
    I, J = I.ravel(), J.ravel()

    def node(di, dj):
        return (I + di) * m + (J + dj)

    v00, v10, v01, v11 = node(0, 0), node(k, 0), node(0, k), node(k, k)
    if cell == "triangle":
        if k == 1:
            first, second = [v00, v10, v01], [v11, v01, v10]
        else:  # vertices, then edge i opposite vertex i
            first = [v00, v10, v01, node(1, 1), node(0, 1), node(1, 0)]
            second = [v11, v01, v10, node(1, 1), node(2, 1), node(1, 2)]
        return np.stack([np.column_stack(first), np.column_stack(second)], axis=1).reshape(-1, len(first))
    columns = [v00, v10, v01, v11]
    if k == 2:  # edges (0,1), (0,2), (1,3), (2,3), then the centre
        columns += [node(1, 0), node(0, 1), node(2, 1), node(1, 2)]
        if not serendipity:
            columns.append(node(1, 1))
    return np.column_stack(columns)


def compact_nodes(x: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drop nodes that no cell uses and renumber."""
    used, inverse = np.unique(cells, return_inverse=True)
    return x[used], inverse.reshape(cells.shape)


def flat_patch(cell: str, degree: int, nx: int, ny: int,
               bounds: Sequence[float] = (0.0, 1.0, 0.0, 1.0), z: float = 0.0,
               up: bool = True, jitter: float = 0.0, seed: int = 0,
               serendipity: bool = False, quadratic_transform: bool = False) -> LagrangeSurface:
    """A flat, straight-sided patch of triangles or quadrilaterals in the plane z.

    Interior vertices are jittered by up to ``jitter`` element sizes; mid-edge
    and centre nodes sit at the means of their vertices, so every triangle is
    affine and every quadrilateral bilinear. ``up`` gives normals +z.
    """
    k = degree
    x0, x1, y0, y1 = bounds
    mx, my = k * nx + 1, k * ny + 1
    X, Y = np.meshgrid(np.linspace(x0, x1, mx), np.linspace(y0, y1, my), indexing="ij")
    rng = np.random.default_rng(seed)
    size = np.array([(x1 - x0) / nx, (y1 - y0) / ny])[:, None, None]
    J = rng.uniform(-jitter, jitter, (2, mx, my)) * size
    J[:, [0, -1], :] = 0
    J[:, :, [0, -1]] = 0
    X, Y = X + J[0], Y + J[1]
    if k == 2:
        for A in (X, Y):
            A[1::2, ::2] = 0.5 * (A[0:-1:2, ::2] + A[2::2, ::2])
            A[::2, 1::2] = 0.5 * (A[::2, 0:-1:2] + A[::2, 2::2])
            if cell == "triangle":  # midpoint of the diagonal (i+1, j)–(i, j+1)
                A[1::2, 1::2] = 0.5 * (A[2::2, 0:-1:2] + A[0:-1:2, 2::2])
            else:                   # centre of the bilinear quadrilateral
                A[1::2, 1::2] = 0.25 * (A[0:-1:2, 0:-1:2] + A[2::2, 0:-1:2]
                                        + A[0:-1:2, 2::2] + A[2::2, 2::2])
    x = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, z)])
    cells = lattice_cells(cell, k, nx, ny, serendipity)
    if serendipity:
        x, cells = compact_nodes(x, cells)
    surface = LagrangeSurface(cell, degree, x, cells, serendipity=serendipity,
                              quadratic_transform=quadratic_transform)
    return surface if up else surface.reflected(np.ones(len(cells), dtype=bool))


def line_chain(breaks: np.ndarray, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameters of the nodes and the cells (Basix order) of a chain of lines
    between consecutive ``breaks``; P2 lines get their midpoints."""
    n = len(breaks) - 1
    if degree == 1:
        return breaks, np.column_stack([np.arange(n), np.arange(1, n + 1)])
    s = np.empty(2 * n + 1)
    s[0::2] = breaks
    s[1::2] = 0.5 * (breaks[:-1] + breaks[1:])
    return s, np.column_stack([2 * np.arange(n), 2 * np.arange(n) + 2, 2 * np.arange(n) + 1])


def flat_line(degree: int, n: int, bounds: Sequence[float] = (0.0, 1.0), y: float = 0.0,
              up: bool = True, jitter: float = 0.0, seed: int = 0) -> LagrangeSurface:
    """A straight chain of P1/P2 lines on y = const in 2D; ``up`` gives normals +y."""
    x0, x1 = bounds
    rng = np.random.default_rng(seed)
    breaks = np.linspace(x0, x1, n + 1)
    breaks[1:-1] += rng.uniform(-jitter, jitter, n - 1) * (x1 - x0) / n
    s, cells = line_chain(breaks, degree)
    x = np.column_stack([s, np.full(len(s), y)])
    surface = LagrangeSurface("interval", degree, x, cells)
    # left-to-right lines have the normal (t_y, -t_x) = -y
    return surface.reflected(np.ones(n, dtype=bool)) if up else surface
