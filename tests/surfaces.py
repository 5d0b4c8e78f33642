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
    if k == 2:  # mid-edge nodes stay put while vertices move: curved elements
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


def _lattice_cells(cell: str, k: int, nx: int, ny: int, serendipity: bool) -> np.ndarray:
    """Cells on a (k·nx + 1) × (k·ny + 1) node lattice, Basix ordering, normal +z."""
    m = k * ny + 1

    def node(i, j):
        return i * m + j

    cells = []
    for i in range(nx):
        for j in range(ny):
            I, J = k * i, k * j
            v00, v10, v01, v11 = node(I, J), node(I + k, J), node(I, J + k), node(I + k, J + k)
            if cell == "triangle":
                if k == 1:
                    cells += [[v00, v10, v01], [v11, v01, v10]]
                else:
                    cells += [[v00, v10, v01, node(I + 1, J + 1), node(I, J + 1), node(I + 1, J)],
                              [v11, v01, v10, node(I + 1, J + 1), node(I + 2, J + 1),
                               node(I + 1, J + 2)]]
            else:
                c = [v00, v10, v01, v11]
                if k == 2:
                    c += [node(I + 1, J), node(I, J + 1), node(I + 2, J + 1), node(I + 1, J + 2)]
                    if not serendipity:
                        c += [node(I + 1, J + 1)]
                cells.append(c)
    return np.array(cells)


def flat_patch(cell: str, degree: int, nx: int, ny: int, bounds=(0.0, 1.0, 0.0, 1.0),
               z: float = 0.0, up: bool = True, jitter: float = 0.0, seed: int = 0,
               serendipity: bool = False, quadratic_transform: bool = False) -> LagrangeSurface:
    """A flat, straight-sided patch of triangles or quadrilaterals in the plane z.

    Interior vertices are jittered by up to ``jitter`` element sizes; mid-edge
    and centre nodes sit at the means of their vertices, so every element is
    affine (triangles) or bilinear (quadrilaterals). ``up`` gives normals +z.
    """
    k = degree
    x0, x1, y0, y1 = bounds
    mx, my = k * nx + 1, k * ny + 1
    X, Y = np.meshgrid(np.linspace(x0, x1, mx), np.linspace(y0, y1, my), indexing="ij")
    rng = np.random.default_rng(seed)
    J = rng.uniform(-jitter, jitter, (2, mx, my)) * np.array([(x1 - x0) / nx, (y1 - y0) / ny])[:, None, None]
    J[:, [0, -1], :] = 0
    J[:, :, [0, -1]] = 0
    X, Y = X + J[0], Y + J[1]
    if k == 2:
        for A in (X, Y):
            A[1::2, ::2] = 0.5 * (A[0:-1:2, ::2] + A[2::2, ::2])
            A[::2, 1::2] = 0.5 * (A[::2, 0:-1:2] + A[::2, 2::2])
            if cell == "triangle":  # midpoint of the diagonal from (i+1, j) to (i, j+1)
                A[1::2, 1::2] = 0.5 * (A[2::2, 0:-1:2] + A[0:-1:2, 2::2])
            else:                   # centre of the bilinear quadrilateral
                A[1::2, 1::2] = 0.25 * (A[0:-1:2, 0:-1:2] + A[2::2, 0:-1:2]
                                        + A[0:-1:2, 2::2] + A[2::2, 2::2])
    x = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, z)])
    cells = _lattice_cells(cell, k, nx, ny, serendipity)
    x, cells = _compact(x, cells)
    surface = LagrangeSurface(cell, degree, x, cells, serendipity=serendipity,
                              quadratic_transform=quadratic_transform)
    return surface if up else surface.reflected(np.ones(len(cells), dtype=bool))


def flat_line(degree: int, n: int, bounds=(0.0, 1.0), y: float = 0.0, up: bool = True,
              jitter: float = 0.0, seed: int = 0) -> LagrangeSurface:
    """A straight chain of P1/P2 lines on y = const in 2D; ``up`` gives normals +y."""
    x0, x1 = bounds
    rng = np.random.default_rng(seed)
    breaks = np.linspace(x0, x1, n + 1)
    breaks[1:-1] += rng.uniform(-jitter, jitter, n - 1) * (x1 - x0) / n
    if degree == 1:
        s = breaks
        cells = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    else:
        s = np.empty(2 * n + 1)
        s[0::2] = breaks
        s[1::2] = 0.5 * (breaks[:-1] + breaks[1:])
        cells = np.column_stack([2 * np.arange(n), 2 * np.arange(n) + 2, 2 * np.arange(n) + 1])
    x = np.column_stack([s, np.full(len(s), y)])
    surface = LagrangeSurface("interval", degree, x, cells)
    # left-to-right lines have normal (t_y, -t_x) = -y
    return surface.reflected(np.ones(n, dtype=bool)) if up else surface
