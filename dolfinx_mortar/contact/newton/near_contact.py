"""Which slave nodes get contact stiffness, and the gap-closing Newton start.

Both concern the moment before anything touches: with positive mortar
functions a body that touches at a point has d̄ < 0 at every node, so the
exact Jacobian has no contact stiffness at all and Newton's linear model,
stiff only from the current gap on, creeps towards the obstacle.
"""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.laws import PenaltyLaw
from dolfinx_mortar.contact.gap_sources import GapSource
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.tolerance import NEAR_CONTACT

FloatArray = npt.NDArray[np.float64]



def penetrates(model: GapSource, state: ContactState) -> bool:
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


def stiffened_nodes(model: GapSource, state: ContactState,
                    near_contact: bool = True) -> FloatArray:
    """Nodes that get contact stiffness in the Jacobian (H(d̄) as 0/1).

    The generalized derivative of ⟨·⟩ at 0 is taken as 1, so touching nodes
    stiffen without pushing. If ``near_contact`` and no node on any rank
    penetrates (:func:`penetrates`), the covered nodes within NEAR_CONTACT of
    their element length of contact get stiffness too: where only the contact
    can hold the body, the rigid-body mode it must hold otherwise makes the
    Jacobian singular (:class:`NearContactStiffness` says where). Once a node
    is active the Jacobian is exact again. Nodes with nothing below them have
    no gap and are never active.
    """
    covered = state.covered
    active = covered & PenaltyLaw.active(state.gaps)
    if near_contact and not penetrates(model, state):
        active = covered & (state.gaps >= -NEAR_CONTACT * model.node_lengths)
    return active.astype(np.float64)


class NearContactStiffness:
    """Whether the nodes near contact need stiffness while nothing touches.

    Stiffness without force is right only where nothing but the contact can
    hold the body: a force-controlled Hertz cylinder has a singular Jacobian
    until a node penetrates. Where the bulk holds it (a block pushed by a
    prescribed displacement, started a fraction of an element above the
    plane), the stiffened matrix is ε·h/E times stiffer than the residual,
    whose contact force is zero, and every Newton step is that much too
    short: a load step that ended 0.02 h short of contact stalled (issue 35).

    Which of the two holds is decided from the bulk, not guessed: the rigid
    motions of the bodies that neither the Dirichlet conditions nor the
    user's form resist (``free``, :meth:`RigidModes.free_motions
    <dolfinx_mortar.linalg.near_nullspace.RigidModes.free_motions>`)
    are the ones the contact must hold; from the second Newton Jacobian in
    a row at which nothing penetrates (:meth:`due`), the near nodes are
    stiffened only if one of them changes their gaps. The decision holds
    until a node penetrates or the next load step starts.

    The gap-closing start (:func:`gap_closing_force`) stiffens them always
    (:attr:`closing`): it only chooses where Newton starts, and a start at
    contact keeps an exact Newton from overshooting through the obstacle
    (the pointwise active set then cycled: a cylinder pressed on a plane).
    """

    #: a free motion moves the near nodes' gaps when it changes one by more
    #: than this fraction of the motion's largest displacement (round-off
    #: is 1e-16 of it; a rotation about a point contact moves them by the
    #: distance ratio, far above)
    MOVES = 1e-8

    def __init__(self) -> None:
        #: None: not decided since the last contact; True: the bulk holds the
        #: body (no stiffness without force); False: only the contact can
        self.bulk_holds: Optional[bool] = None
        #: inside the gap-closing start: the near nodes stiffen whatever holds the body
        self.closing = False
        #: Newton Jacobians in a row at which nothing penetrated
        self.apart = 0

    def mask(self, model: GapSource, state: ContactState) -> FloatArray:
        """:func:`stiffened_nodes`, with the near nodes stiffened unless the
        bulk holds the body (collective)."""
        return stiffened_nodes(model, state,
                               near_contact=self.closing or not self.bulk_holds)

    def reset(self) -> None:
        """Decide again at the next approach (a new load step)."""
        self.bulk_holds = None
        self.apart = 0

    def due(self, model: GapSource, state: ContactState) -> bool:
        """Count a Newton Jacobian and say whether a decision is due (collective).

        One is due at the second Jacobian in a row at which nothing
        penetrates and some node is near contact, if none was taken since
        the last penetration. The first is stiffened as it always was: an
        iterate that lost contact for one step (a disk slid over a
        neo-Hookean block, "previous") is held near the obstacle, and the
        next one touches again; exact steps there made Newton cycle. A
        second one in a row is what a solution short of contact looks like.
        """
        if self.closing:
            return False
        if penetrates(model, state):
            self.bulk_holds, self.apart = None, 0
            return False
        self.apart += 1
        if self.bulk_holds is not None or self.apart < 2:
            return False
        n = model.slave.layout.num_owned
        near = stiffened_nodes(model, state)[:n]
        return model.slave.layout.comm.allreduce(int(np.sum(near))) > 0

    def decide(self, model: GapSource, state: ContactState,
               free: Sequence[PETSc.Vec]) -> bool:
        """Record whether the bulk holds the body: no ``free`` rigid motion
        (dof vectors) changes a near node's gap; returns it (collective)."""
        layout = model.slave.layout
        n = layout.num_owned
        near = stiffened_nodes(model, state)[:n] > 0
        moves = False
        for motion in free:
            change = state.G.createVecLeft()
            state.G.mult(motion, change)
            # the gaps' change: G r for the local kinds, L⁻¹ Ĝ r for GLS
            gaps = model.nodal_force(layout.to_local(change))[:n]
            largest = layout.comm.allreduce(float(np.max(np.abs(gaps[near]), initial=0.0)),
                                            op=MPI.MAX)
            moves |= largest > self.MOVES * motion.norm(PETSc.NormType.NORM_INFINITY)
        self.bulk_holds = not moves
        return self.bulk_holds


def gap_closing_force(model: GapSource, state: ContactState) -> Optional[PETSc.Vec]:
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
