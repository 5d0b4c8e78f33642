"""A scene far from the origin is the scene at the origin (docs/DESIGN.md, §Tolerances).

Two elastic blocks 1/64 wide pressed together, once at the origin and once shifted
by 1e6 (2D) or 1e8 (3D): the nodal pressures agree node by node. The blocks' nodes lie
on a dyadic grid that the shift keeps exact, so the shifted scene is the same scene,
not a rounded copy. Before the tolerance followed the extent and the kernels worked in
local coordinates, the zero length was 1e-10 |x| (1e-4 at 1e6, a tenth of the facets).
"""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import mesh
from mpi4py import MPI

from dolfinx_mortar import ContactProblem

SIZE = 1.0 / 64                       # the blocks' width
SLAVE, BOTTOM, MASTER, TOP = 1, 2, 3, 4


def tagged_block(gdim: int, lower: bool, shift: float):
    """A block [0, SIZE]^(gdim-1) × [-SIZE/2, 0] (lower) or, offset by SIZE/32 sideways,
    × [0, SIZE/2] (upper), its nodes moved by ``shift`` in every coordinate."""
    comm = MPI.COMM_WORLD
    h = SIZE / 2
    offset = 0.0 if lower else SIZE / 32
    y0, y1 = (-h, 0.0) if lower else (0.0, h)
    lo = [offset] * (gdim - 1) + [y0]
    hi = [offset + SIZE] * (gdim - 1) + [y1]
    n = ([8] * (gdim - 1) + [2]) if lower else ([4] * (gdim - 1) + [2])
    if gdim == 2:
        domain = mesh.create_rectangle(comm, [lo, hi], n)
    else:
        domain = mesh.create_box(comm, [lo, hi], n)
    fdim = gdim - 1
    marks = [(SLAVE if lower else MASTER, y1 if lower else y0),
             (BOTTOM if lower else TOP, y0 if lower else y1)]
    facets, values = [], []
    for tag, level in marks:
        f = mesh.locate_entities_boundary(domain, fdim,
                                          lambda x, v=level: np.isclose(x[fdim], v))
        facets.append(f)
        values.append(np.full(len(f), tag, dtype=np.int32))
    facets, values = np.concatenate(facets), np.concatenate(values)
    order = np.argsort(facets)
    tags = mesh.meshtags(domain, fdim, facets[order].astype(np.int32), values[order])
    # on the dyadic grid of SIZE/128 (create_* leaves 2e-19 here and there), which
    # the shift keeps exact
    grid = SIZE / 128
    x = domain.geometry.x
    x[:, :gdim] = np.round(x[:, :gdim] / grid) * grid + shift
    return domain, tags


def pressures(gdim: int, shift: float, kind: str) -> tuple[np.ndarray, np.ndarray]:
    """The slave nodes' pressures and coordinates (less the shift), sorted by coordinates."""
    lower, lower_tags = tagged_block(gdim, True, shift)
    upper, upper_tags = tagged_block(gdim, False, shift)
    down = {**{k: 0.0 for k in range(gdim - 1)}, gdim - 1: -1e-3 * SIZE}
    problem = ContactProblem.from_two_meshes(
        lower, lower_tags, SLAVE, upper, upper_tags, MASTER, kind=kind, E=1.0, nu=0.3,
        penalty=1e2 / SIZE, fixed={BOTTOM: {k: 0.0 for k in range(gdim)}, TOP: down})
    problem.solve(load_steps=1)
    surface = problem.surface_pressure(gather=True)
    x = surface.x - shift                # exact, as the shift was
    order = np.lexsort(x.T[::-1])        # the partition, and so the numbering, may differ
    return surface.p[order], x[order]


@pytest.mark.parametrize("gdim, shift, kind", [(2, 1e6, "LcLS*"), (2, 1e6, "GLS"),
                                               (3, 1e8, "LcLS*"), (3, 1e8, "LmLS")])
def test_a_shifted_scene_has_the_pressures_of_the_scene_at_the_origin(gdim, shift, kind):
    p0, x0 = pressures(gdim, 0.0, kind)
    p1, x1 = pressures(gdim, shift, kind)
    assert np.array_equal(x0, x1)
    peak = np.max(np.abs(p0))
    assert peak > 0 and np.count_nonzero(p0) > 4
    assert np.max(np.abs(p1 - p0)) <= 1e-6 * peak, np.max(np.abs(p1 - p0)) / peak
