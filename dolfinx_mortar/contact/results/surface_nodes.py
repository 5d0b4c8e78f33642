"""What the pressure and the friction reports share: values at the slave
surface's nodes with the nodes' coordinates (per rank or gathered), and the
resultant of a residual on the slave body."""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.tolerance import length_scale, zero_length

FloatArray = npt.NDArray[np.float64]


def at_surface_nodes(term, gather: bool, *values: np.ndarray) -> tuple:
    """The slave surface's nodes' coordinates, ``values`` there and the nodes' global indices.

    Collective if ``gather``.

    Parameters
    ----------
    term
        The :class:`~dolfinx_mortar.contact.term.ContactTerm` reporting.
    gather
        False: the surface nodes this rank owns, in local order. True: every surface node
        of all ranks, on every rank, sorted by coordinates (x first, then y, then z).
    *values
        Arrays over the local slave-layout nodes.

    Returns
    -------
    tuple
        ``(x, *values at the nodes, global indices)``.
    """
    slave = term.slave
    layout = slave.layout
    nodes = slave.owned_nodes
    part = (slave.x[nodes], [v[nodes] for v in values], layout.global_indices[nodes])
    if not gather:
        return (part[0], *part[1], part[2])
    parts = term.comm.allgather(part)
    x = np.concatenate([q[0] for q in parts]).reshape(-1, slave.gdim)
    # coordinates equal up to round-off (a mesh generator's 0 may be -2e-18) are equal
    # here, so that the order does not depend on where round-off lands
    zero = zero_length(length_scale(x))
    order = np.lexsort(np.round(x / zero).T[::-1])
    gathered = [np.concatenate([q[1][k] for q in parts])[order] for k in range(len(values))]
    return (x[order], *gathered, np.concatenate([q[2] for q in parts])[order])


def slave_resultant(term, residual: PETSc.Vec, tag: Optional[int] = None) -> FloatArray:
    """``−Σ residual`` over the slave nodes' owned dofs, summed over all ranks
    (``tag``: over the nodes of the slave facets with that tag only).

    Parameters
    ----------
    term
        The :class:`~dolfinx_mortar.contact.term.ContactTerm` reporting.
    residual
        A residual in the displacement space (blocked by gdim).
    tag
        One of the term's slave facet tags, or None (the whole slave surface).

    Returns
    -------
    FloatArray
        A gdim-vector, the same on every rank.
    """
    slave = term.slave
    gdim = slave.gdim
    R = residual.array_r.reshape(-1, gdim)
    if tag is None:
        nodes = slave.owned_nodes
    else:
        tags = (term.slave_tag,) if np.ndim(term.slave_tag) == 0 else term.slave_tag
        if tag not in tags:
            raise ValueError(f"tag {tag!r} is not one of the term's slave facet tags {tags}")
        nodes = slave.layout.owned_on_cells(slave.cells[slave.cell_tags == tag])
    local = -R[nodes].sum(axis=0) if len(nodes) else np.zeros(gdim)
    return np.asarray(term.comm.allreduce(local))
