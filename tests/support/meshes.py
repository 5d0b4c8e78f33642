"""Small tagged DOLFINx meshes shared by the tests."""
from __future__ import annotations

import numpy as np
from dolfinx import mesh


def rectangle(comm, y0, y1, n, bottom, top, left, cell_type=mesh.CellType.triangle,
              right=None):
    """[0,1]×[y0,y1] by dolfinx.mesh.create_rectangle, with bottom/top/left (and
    ``right``, if given) facet tags."""
    domain = mesh.create_rectangle(comm, [[0, y0], [1, y1]], list(n), cell_type=cell_type)
    marks = [(bottom, lambda x: np.isclose(x[1], y0)), (top, lambda x: np.isclose(x[1], y1)),
             (left, lambda x: np.isclose(x[0], 0))]
    if right is not None:
        marks.append((right, lambda x: np.isclose(x[0], 1)))
    facets, values = [], []
    for tag, where in marks:
        f = mesh.locate_entities_boundary(domain, 1, where)
        facets.append(f)
        values.append(np.full(len(f), tag, dtype=np.int32))
    facets, values = np.concatenate(facets), np.concatenate(values)
    order = np.argsort(facets)
    return domain, mesh.meshtags(domain, 1, facets[order].astype(np.int32), values[order])
