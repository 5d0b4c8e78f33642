"""Small tagged DOLFINx meshes shared by the tests."""
from __future__ import annotations

import numpy as np
from dolfinx import fem, mesh


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


#: the facet tags of :func:`two_blocks`
SLAVE, MASTER = 1, 2


def two_blocks(comm, dim, degree):
    """A lower block (slave face on top) and a coarser, shifted upper block."""
    if dim == 2:
        lower = mesh.create_rectangle(comm, [[0, -0.5], [1, 0]], [7, 3],
                                      cell_type=mesh.CellType.triangle)
        upper = mesh.create_rectangle(comm, [[0.3, 0.0], [1.4, 0.5]], [4, 2],
                                      cell_type=mesh.CellType.quadrilateral)
    else:
        lower = mesh.create_box(comm, [[0, 0, -0.5], [1, 1, 0]], [5, 4, 2],
                                cell_type=mesh.CellType.tetrahedron)
        upper = mesh.create_box(comm, [[0.3, -0.2, 0], [1.4, 0.8, 0.5]], [3, 3, 2],
                                cell_type=mesh.CellType.hexahedron)
    out = []
    for domain, tag, where in ((lower, SLAVE, 0.0), (upper, MASTER, 0.0)):
        fdim = dim - 1
        facets = mesh.locate_entities_boundary(domain, fdim,
                                               lambda x: np.isclose(x[dim - 1], where))
        tags = mesh.meshtags(domain, fdim, np.sort(facets).astype(np.int32),
                             np.full(len(facets), tag, dtype=np.int32))
        V = fem.functionspace(domain, ("Lagrange", degree, (domain.geometry.dim,)))
        out.append((V, tags))
    return out


#: the tags of each block of :func:`stacked_rectangles`, before its offset
BLOCK_BOTTOM, BLOCK_TOP, BLOCK_LEFT, BLOCK_RIGHT = 1, 2, 3, 4
#: block k's tags are the above plus k·BLOCK_OFFSET
BLOCK_OFFSET = 10


def stacked_rectangles(comm, cells_across, right: bool = False):
    """Blocks [0,1] × [k/4, (k+1)/4], block k on ``cells_across[k]`` cells across (non-
    matching where they differ), merged in one call: mesh, facet tags and cell tags. Each
    block's bottom, top (and ``right``) faces tagged as above, the left faces (and right)
    shared."""
    from dolfinx_mortar.meshes.merge_meshes import merge_bodies
    sides = dict(right=BLOCK_RIGHT) if right else {}
    meshes = [rectangle(comm, k / 4, (k + 1) / 4, (n, 2), bottom=BLOCK_BOTTOM, top=BLOCK_TOP,
                        left=BLOCK_LEFT, **sides) for k, n in enumerate(cells_across)]
    shared = [BLOCK_LEFT] + ([BLOCK_RIGHT] if right else [])
    return merge_bodies([m for m, _ in meshes], [t for _, t in meshes],
                        tag_offsets=[BLOCK_OFFSET * k for k in range(len(meshes))],
                        shared_tags=shared)
