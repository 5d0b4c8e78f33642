"""A stack of rectangular blocks in one gmsh mesh, non-matching at their interfaces
(demos/stack_of_blocks.py, demos/stack_one_term.py)."""
from __future__ import annotations

from typing import Sequence

import gmsh
import numpy as np
from mpi4py import MPI

from dolfinx_mortar.io.gmsh_io import model_to_mesh


def stacked_blocks(comm: MPI.Comm, blocks: Sequence[tuple], bottom: Sequence[int],
                   top: Sequence[int], left: int):
    """The blocks ``(x0, x1, y0, y1, h)``, bottom to top, each meshed with its own size h:
    mesh and facet tags (each block's bottom and top face, and all left edges)."""
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            groups = {tag: [] for tag in (*bottom, *top, left)}
            for k, (x0, x1, y0, y1, h) in enumerate(blocks):
                block = gmsh.model.occ.addRectangle(x0, y0, 0, x1 - x0, y1 - y0)
                gmsh.model.occ.synchronize()
                for _, line in gmsh.model.getBoundary([(2, block)], oriented=False):
                    x, y, _ = gmsh.model.occ.getCenterOfMass(1, line)
                    for tag, on in ((bottom[k], np.isclose(y, y0)), (top[k], np.isclose(y, y1)),
                                    (left, np.isclose(x, x0))):
                        if on:
                            groups[tag].append(line)
                gmsh.model.addPhysicalGroup(2, [block], 10 + k)
                gmsh.model.mesh.setSize(gmsh.model.getBoundary([(2, block)], recursive=True), h)
            for tag, lines in groups.items():
                gmsh.model.addPhysicalGroup(1, lines, tag)
            gmsh.model.mesh.generate(2)
        mesh, _, facet_tags = model_to_mesh(gmsh.model, comm, 0)   # the model's dimension: 2
    finally:
        gmsh.finalize()
    return mesh, facet_tags
