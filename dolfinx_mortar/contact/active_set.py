"""Which slave nodes get contact stiffness, and the gap-closing Newton start.

Both concern the moment before anything touches: with positive mortar
functions a body that touches at a point has d̄ < 0 at every node, so the
exact Jacobian has no contact stiffness at all and Newton's linear model,
stiff only from the current gap on, creeps towards the obstacle.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.penalty_law import PenaltyLaw
from dolfinx_mortar.contact.state import ContactState, GapModel

FloatArray = npt.NDArray[np.float64]

#: nodes within this fraction of their element length of contact stiffen when none touches
NEAR_CONTACT = 0.1


def penetrates(model: GapModel, state: ContactState) -> bool:
    """Whether a slave node on any rank penetrates by more than the geometry's
    zero length (collective).

    Not "d̄ ≥ 0" nor "⟨d̄⟩ ≠ 0": where a sphere touches a block at a node,
    that node's gap is 0 on one rank and ±1e-19 on two, and the decisions
    below went different ways (Hertz 3D: one node stiffened instead of 25, no
    gap-closing start, 24 Newton iterations on 2 ranks against 16 on one).
    """
    slave = model.slave
    comm = slave.layout.comm
    n = slave.layout.num_owned
    zero = slave.zero_length
    if state.gaps_plus is not None:
        # d̄⁺ integrates ⟨d⟩ with the basis, which may be negative (dual kinds)
        deep = np.abs(state.gaps_plus[:n]) > zero
    else:
        deep = state.covered[:n] & (state.gaps[:n] > zero)
    return bool(comm.allreduce(bool(np.any(deep)), op=MPI.LOR))


def stiffened_nodes(model: GapModel, state: ContactState) -> FloatArray:
    """Nodes that get contact stiffness in the Jacobian (H(d̄) as 0/1).

    The generalized derivative of ⟨·⟩ at 0 is taken as 1, so touching nodes
    stiffen without pushing. If no node on any rank penetrates
    (:func:`penetrates`), the covered nodes within NEAR_CONTACT of their
    element length of contact get stiffness too: otherwise the rigid-body
    mode that the contact must hold makes the Jacobian singular. Once a node
    is active the Jacobian is exact again. Nodes with nothing below them have
    no gap and are never active.
    """
    covered = state.covered
    active = covered & PenaltyLaw.active(state.gaps)
    if not penetrates(model, state):
        active = covered & (state.gaps >= -NEAR_CONTACT * model.basis.node_lengths)
    return active.astype(np.float64)


def gap_closing_force(model: GapModel, state: ContactState) -> Optional[PETSc.Vec]:
    """``Gᵀ f`` with ``f`` from ``ω d̄`` on the nodes near contact when nothing
    penetrates yet (:func:`penetrates`; None otherwise).

    Added to the residual of a linear solve with the Jacobian (which already
    stiffens those nodes, :func:`stiffened_nodes`), it gives the step that
    closes their gaps: it overshoots by about the largest of those gaps (a
    tenth of an element), which Newton then takes back. Pulling only the
    closest node instead left rotations about it free (singular on a grazing
    disk). It changes where Newton starts, not the solution.
    """
    slave = model.slave
    comm = slave.layout.comm
    n = slave.layout.num_owned
    if penetrates(model, state):
        return None
    near = stiffened_nodes(model, state)
    if comm.allreduce(int(np.sum(near[:n]))) == 0:
        return None
    force = model.nodal_force(state.weights * near * state.gaps)
    pull = state.G.createVecRight()
    state.G.multTranspose(slave.layout.vector(force), pull)
    return pull
