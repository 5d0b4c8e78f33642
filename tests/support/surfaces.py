"""Curved, non-uniform slave surfaces built from arrays, for the basis tests."""
from __future__ import annotations

import numpy as np

from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.surfaces.structured import compact_nodes, lattice_cells, line_chain


def curved_line(degree: int, n: int = 7, seed: int = 0,
                axisymmetric: bool = False) -> LagrangeSurface:
    """A wavy, non-uniform chain of P1/P2 line elements in 2D, from x = 0 to 1
    (axisymmetric: a meridian in the (r, z) plane starting on the axis)."""
    rng = np.random.default_rng(seed)
    breaks = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0.05, 0.95, n - 1)]))
    s, cells = line_chain(breaks, degree)
    x = np.column_stack([s, 0.1 * np.sin(3.0 * s)])
    return LagrangeSurface("interval", degree, x, cells, axisymmetric=axisymmetric)


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

    cells = lattice_cells(cell, k, n, n, serendipity)
    x, cells = compact_nodes(x, cells)
    return LagrangeSurface(cell, degree, x, cells, serendipity=serendipity,
                           quadratic_transform=quadratic_transform)

