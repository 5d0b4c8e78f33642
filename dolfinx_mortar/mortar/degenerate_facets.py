"""A degenerate contact facet stops the coupling, named on every rank
(docs/DESIGN.md, §Tolerances)."""
from __future__ import annotations

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar import _kernels
from dolfinx_mortar.errors import DegenerateGeometryError
from dolfinx_mortar.mortar.surface_exchange import SurfaceCopy

FloatArray = npt.NDArray[np.float64]


def raise_on_degenerate_facets(r: _kernels.MortarIntegrals, xs: FloatArray,
                               slave_cells: npt.NDArray[np.int32], master_copy: SurfaceCopy,
                               comm: MPI.Comm, zero_length: float, length_scale: float) -> None:
    """A degenerate facet covers nothing: rather than let it vanish from the
    integrals, stop on every rank with the facets named (collective). A master
    facet near several ranks' slave facets is named once, by its nodes."""
    lines = [f"slave facet {c} (local cell index on rank {comm.rank}) with nodes "
             f"{np.array2string(xs[slave_cells[c]], precision=17, separator=', ')}"
             for c in r.degenerate_slave_facets[:5]]
    lines = [line for rank_lines in comm.allgather(lines) for line in rank_lines]
    master_lines: dict[str, str] = {}
    for rank_lines in comm.allgather(
            [(np.array2string(master_copy.x[master_copy.cells[c]], precision=17,
                              separator=', '), c) for c in r.degenerate_master_facets[:5]]):
        for nodes, c in rank_lines:
            master_lines.setdefault(nodes, f"master facet {c} (index in the received "
                                           f"master facets) with nodes {nodes}")
    lines += list(master_lines.values())
    if lines:
        raise DegenerateGeometryError(
            f"degenerate contact facets (length or height at most the zero length "
            f"{zero_length:.3g} = tolerance × length scale {length_scale:.3g}): "
            + "; ".join(lines))
