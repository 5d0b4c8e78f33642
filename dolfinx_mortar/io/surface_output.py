"""Fields on the slave surface for XDMF output: ``p̂`` and the mortar traction ``p*``.

``p*`` of the dual kinds is discontinuous across slave facets, and DOLFINx's
XDMF writer only takes Lagrange data of the mesh's own degree. So the
slave facets become a *broken* surface mesh — every facet with its own copies
of its nodes — on which a continuous Lagrange function of the facet degree
holds any element-wise field exactly. Every rank keeps its own facets (a
partitioner that moves nothing), so no data travels.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt
import basix.ufl
import ufl
from dolfinx import fem

from dolfinx_mortar import dolfinx_compat
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.io.xdmf_series import XdmfSeries

FloatArray = npt.NDArray[np.float64]


def surface_output_path(path: Path, name: str = "slave") -> Path:
    """The slave-surface file next to a bulk output file: ``run.xdmf`` → ``run_slave.xdmf``
    (``run_<name>.xdmf``)."""
    path = Path(path)
    return path.with_name(f"{path.stem}_{name}{path.suffix}")


class SlaveSurfaceOutput:
    """Writes element-wise nodal fields of a slave surface to an XDMF file.

    Parameters
    ----------
    slave
        The slave surface (this rank's facets).
    path
        The ``.xdmf`` index; it is created with the surface mesh, its data
        files next to it (:class:`dolfinx_mortar.io.xdmf_series.XdmfSeries`).
    """

    def __init__(self, slave: LagrangeSurface, path: Path):
        comm = slave.layout.comm
        self.path = Path(path)
        self.slave = slave
        nc, nd = slave.cells.shape
        gdim = slave.gdim
        offset = comm.scan(nc) - nc
        x = slave.x[slave.cells].reshape(nc * nd, gdim)
        cells = (offset + np.arange(nc, dtype=np.int64))[:, None] * nd + np.arange(nd)
        rank = comm.rank

        def keep_on_this_rank(_comm, _nparts, _cell_types, _cells):
            return dolfinx_compat.cpp_adjacency_list(np.full(nc, rank, dtype=np.int32),
                                                     np.arange(nc + 1, dtype=np.int32))

        element = basix.ufl.element("Lagrange", slave.reference.cell, slave.reference.degree,
                                    shape=(gdim,))
        self.mesh = dolfinx_compat.create_mesh(comm, cells, x, ufl.Mesh(element),
                                               partitioner=keep_on_this_rank)
        self.mesh.name = "slave_surface"
        self.space = fem.functionspace(self.mesh, ("Lagrange", slave.reference.degree))
        num_local = self.mesh.topology.index_map(self.mesh.topology.dim).size_local
        original = np.asarray(self.mesh.topology.original_cell_index[:num_local])
        #: slave cell of every surface-mesh cell, and the dofs of its nodes
        self.source = original - offset
        self.dofs = self.space.dofmap.list.reshape(-1, nd)[:num_local]
        self.series = XdmfSeries(self.path, self.mesh)

    def function(self, name: str, values: FloatArray) -> fem.Function:
        """A function from values at every node of every slave cell, (cells, nd)."""
        u = fem.Function(self.space, name=name)
        u.x.array[self.dofs] = np.asarray(values)[self.source]
        return u

    def write(self, fields: dict[str, FloatArray], t: float) -> None:
        """Add fields (name → (cells, nd) values) at time t; the file is
        complete on disk after every call (:mod:`dolfinx_mortar.io.xdmf_series`)."""
        self.series.write([self.function(name, values) for name, values in fields.items()], t)
