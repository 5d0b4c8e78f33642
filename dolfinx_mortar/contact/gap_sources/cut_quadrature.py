"""Quadrature on the penetrating part {d > 0} of facets cut by the contact boundary.

The pointwise active set integrates ``M_A ε⟨d⟩`` (docs/DESIGN.md, §Active sets), whose kink at
``d = 0`` spoils Gauss rules on cut cells. Each cut cell is divided into
sub-simplices in reference coordinates (lines: ``k`` pieces; triangles and
quadrilaterals: ``k²`` or ``2k²`` triangles); on every sub-edge that changes
sign the zero of the true gap is found by bisection, the positive part of each
sub-simplex is cut along the chord between those zeros and integrated with a
Basix rule. On lines the split is exact; on surfaces the zero level is
approximated by chords of length ``h/k``. No library offers level-set cut
quadrature on facets in this stack, hence this module.
"""
from __future__ import annotations

from typing import Callable

import basix
import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

#: gap_at(cells, X) -> d: the gap at reference points X (n, tdim) of cells (n,)
GapFunction = Callable[[IntArray, FloatArray], FloatArray]


def reference_subdivision(cell: str, k: int) -> tuple[FloatArray, IntArray]:
    """Vertices (nv, tdim) and sub-simplices (ns, tdim + 1) of a reference cell."""
    t = np.linspace(0.0, 1.0, k + 1)
    if cell == "interval":
        return t[:, None], np.stack([np.arange(k), np.arange(1, k + 1)], axis=1)
    if cell == "quadrilateral":
        X = np.array([[x, y] for y in t for x in t])
        i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
        v0 = (j * (k + 1) + i).ravel()
        v1, v2, v3 = v0 + 1, v0 + k + 1, v0 + k + 2
        return X, np.concatenate([np.stack([v0, v1, v3], 1), np.stack([v0, v3, v2], 1)])
    if cell == "triangle":
        index = {}
        X = []
        for j in range(k + 1):
            for i in range(k + 1 - j):
                index[i, j] = len(X)
                X.append([i / k, j / k])
        simplices = []
        for j in range(k):
            for i in range(k - j):
                simplices.append([index[i, j], index[i + 1, j], index[i, j + 1]])
                if i + j < k - 1:
                    simplices.append([index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]])
        return np.array(X), np.array(simplices)
    raise ValueError(f"no subdivision for cell '{cell}'")


def _zero_on_edges(cells: IntArray, A: FloatArray, B: FloatArray, gap_at: GapFunction,
                   steps: int) -> FloatArray:
    """Points on segments A (d > 0) → B (d ≤ 0) where d = 0, by bisection."""
    lo, hi = np.zeros(len(cells)), np.ones(len(cells))
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        positive = gap_at(cells, A + mid[:, None] * (B - A)) > 0
        lo = np.where(positive, mid, lo)
        hi = np.where(positive, hi, mid)
    s = 0.5 * (lo + hi)
    return A + s[:, None] * (B - A)


def positive_part_rule(cell: str, cells: IntArray, gap_at: GapFunction, degree: int,
                       subdivisions: int = 4, bisection_steps: int = 30
                       ) -> tuple[IntArray, FloatArray, FloatArray, FloatArray]:
    """A quadrature rule on {d > 0} of each cell in ``cells``.

    Parameters
    ----------
    cell
        ``"interval"``, ``"triangle"`` or ``"quadrilateral"``.
    cells
        The cells to integrate (typically those where d changes sign).
    gap_at
        The gap at reference points of cells.
    degree
        Degree of the Basix rule on every positive piece.
    subdivisions
        Pieces per reference edge.
    bisection_steps
        Bisection steps for each zero (the error is 2⁻ˢᵗᵉᵖˢ of a sub-edge).

    Returns
    -------
    owner, X, weights, vertex_gaps
        The cell (index into ``cells``) of every point, its reference
        coordinates (n, tdim), its reference weight, and d at every sub-vertex
        of every cell (len(cells), nv), which tells fully positive and fully
        negative cells apart.
    """
    cells = np.asarray(cells, dtype=np.int64)
    V, S = reference_subdivision(cell, subdivisions)
    tdim = V.shape[1]
    nc, nv = len(cells), len(V)
    vertex_gaps = gap_at(np.repeat(cells, nv), np.tile(V, (nc, 1))).reshape(nc, nv)
    simplex_cell = np.repeat(np.arange(nc), len(S))
    verts = np.tile(S, (nc, 1))                         # (nc·ns, tdim + 1)
    d = vertex_gaps[simplex_cell[:, None], verts]
    positive = d > 0
    npos = positive.sum(axis=1)
    pieces_cell, pieces = [simplex_cell[npos == tdim + 1]], [V[verts[npos == tdim + 1]]]

    if tdim == 1:
        cut = np.flatnonzero(npos == 1)
        p = np.where(positive[cut, 0], verts[cut, 0], verts[cut, 1])
        q = np.where(positive[cut, 0], verts[cut, 1], verts[cut, 0])
        z = _zero_on_edges(cells[simplex_cell[cut]], V[p], V[q], gap_at, bisection_steps)
        pieces_cell.append(simplex_cell[cut])
        pieces.append(np.stack([V[p], z], axis=1))
    else:
        # order each cut triangle so that its lone vertex (the one whose sign
        # differs from the other two) comes first
        for count in (1, 2):
            cut = np.flatnonzero(npos == count)
            lone_is_positive = count == 1
            lone = np.argmax(positive[cut] == lone_is_positive, axis=1)
            order = (lone[:, None] + np.arange(3)[None, :]) % 3
            v = np.take_along_axis(verts[cut], order, axis=1)
            owner = cells[simplex_cell[cut]]
            a, b, c = V[v[:, 0]], V[v[:, 1]], V[v[:, 2]]
            if lone_is_positive:   # positive part: triangle (a, z_ab, z_ac)
                zab = _zero_on_edges(owner, a, b, gap_at, bisection_steps)
                zac = _zero_on_edges(owner, a, c, gap_at, bisection_steps)
                pieces_cell.append(simplex_cell[cut])
                pieces.append(np.stack([a, zab, zac], axis=1))
            else:                  # positive part: quadrilateral (b, c, z_ca, z_ba)
                zba = _zero_on_edges(owner, b, a, gap_at, bisection_steps)
                zca = _zero_on_edges(owner, c, a, gap_at, bisection_steps)
                pieces_cell += [simplex_cell[cut]] * 2
                pieces += [np.stack([b, c, zca], axis=1), np.stack([b, zca, zba], axis=1)]

    piece_cell = np.concatenate(pieces_cell)
    P = np.concatenate(pieces).reshape(-1, tdim + 1, tdim)
    simplex = basix.CellType.interval if tdim == 1 else basix.CellType.triangle
    Xq, wq = basix.make_quadrature(simplex, degree)
    edges = P[:, 1:, :] - P[:, :1, :]                  # (np, tdim, tdim): rows are edges
    jac = np.abs(np.linalg.det(edges)) if tdim == 2 else np.abs(edges[:, 0, 0])
    X = P[:, None, 0, :] + np.einsum("qi,pij->pqj", Xq, edges)
    owner = np.repeat(piece_cell, len(wq))
    weights = (jac[:, None] * wq[None, :]).ravel()
    return owner, X.reshape(-1, tdim), weights, vertex_gaps
