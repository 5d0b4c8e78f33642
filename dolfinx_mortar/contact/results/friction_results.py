"""What a contact term with Coulomb friction reports: the tangential tractions,
the stick/slip states, the tangential force and the dissipation
(:class:`FrictionResults`, whose figures
:class:`~dolfinx_mortar.contact.results.contact_results.ContactResults` hands on).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt

from dolfinx_mortar.contact.results.surface_nodes import at_surface_nodes, slave_resultant
from dolfinx_mortar.contact.state import ContactState, FrictionState

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class SurfaceFriction:
    """The tangential traction and the stick/slip state at the nodes of a slave
    surface, in the form of
    :class:`~dolfinx_mortar.contact.results.contact_results.SurfacePressure`.

    Attributes
    ----------
    x
        Reference (undeformed) coordinates of the nodes, shape (n, gdim).
    q
        The tangential traction ``q_A`` on the slave body at them, shape (n, gdim)
        (:meth:`FrictionResults.tangential_tractions`); 0 where separated.
    stick_slip
        Their state, shape (n,): 0 separated, 1 stick, 2 slip
        (:meth:`FrictionResults.slip_states`).
    global_index
        The nodes' global indices in the displacement space's node numbering.
    """

    x: FloatArray
    q: FloatArray
    stick_slip: npt.NDArray[np.int8]
    global_index: npt.NDArray[np.int64]


class FrictionResults:
    """The friction figures of a :class:`~dolfinx_mortar.contact.term.ContactTerm`
    at the present u (or at a state it evaluated).

    Parameters
    ----------
    term
        The contact term.
    """

    def __init__(self, term):
        self.term = term

    def _friction(self, state: Optional[ContactState]) -> FrictionState:
        """The friction state of ``state`` (default: at the present u); a frictionless
        term has none to report."""
        if self.term.friction is None:
            raise ValueError("this contact term has no friction (ContactTerm(..., "
                             "friction=CoulombFriction(mu)))")
        return (state or self.term.evaluate()).friction

    def tangential_tractions(self, state: Optional[ContactState] = None) -> FloatArray:
        """``q_A = −f_T,A / W_A^k``: the coefficients of the tangential traction
        on the slave body in the partition-of-unity basis, as ``p_A`` is of the
        pressure, at the local slave-layout nodes, (nodes, gdim); it opposes
        the slave's slip relative to what it touches, and ``|q_A| ≤ μ p_A``.
        With the nodes' coordinates: :meth:`surface_friction`."""
        state = state or self.term.evaluate()
        self._friction(state)
        return self.term.source.tangential_tractions(state)

    def slip_states(self, state: Optional[ContactState] = None) -> npt.NDArray[np.int8]:
        """Per local slave-layout node: 0 separated, 1 stick, 2 slip
        (:data:`~dolfinx_mortar.contact.laws.coulomb.STICK`, …). With the
        nodes' coordinates: :meth:`surface_friction`."""
        return self._friction(state).mapping.state.copy()

    def surface_friction(self, state: Optional[ContactState] = None,
                         gather: bool = False) -> SurfaceFriction:
        """The tangential traction and the stick/slip state at the slave
        surface's nodes, with their coordinates (as
        :meth:`~dolfinx_mortar.contact.results.contact_results.ContactResults.surface_pressure`).

        Collective.

        Parameters
        ----------
        state
            A contact state; by default the one at the present u.
        gather
            False: the surface nodes this rank owns, in local order. True: every surface node
            of all ranks, on every rank, sorted by coordinates (x first, then y, then z).

        Raises
        ------
        ValueError
            If the term has no friction.
        """
        state = state or self.term.evaluate()
        x, q, stick_slip, index = at_surface_nodes(
            self.term, gather, self.tangential_tractions(state), self.slip_states(state))
        return SurfaceFriction(x, q, stick_slip, index)

    def tangential_force(self, state: Optional[ContactState] = None,
                         tag: Optional[int] = None) -> FloatArray:
        """The resultant of the tangential (friction) traction on the slave
        body, a gdim-vector over all ranks: ``−Σ G_Tᵀ f_T`` over the slave
        nodes' dofs (``tag``: of one of the term's slave tags only), as
        :meth:`~dolfinx_mortar.contact.results.contact_results.ContactResults.contact_force`
        is of the whole traction."""
        return slave_resultant(self.term, self._friction(state).residual, tag)

    def dissipation(self) -> float:
        """The frictional dissipation ``Σ_steps Σ_A f_T,A · Δy_p,A`` over the
        accepted steps, over all ranks."""
        if self.term.friction is None:
            return 0.0
        return self.term.friction.history.dissipation

    def friction_summary(self, state: Optional[ContactState] = None) -> Optional[dict]:
        """The friction figures of a step, for the load path's history: None
        without friction, else ``tangential_force`` (list), ``dissipation``
        (total), ``step_dissipation``, ``stick_nodes``, ``slip_nodes``,
        ``tangential_energy`` (the tangential springs' stored energy)."""
        if self.term.friction is None:
            return None
        state = state or self.term.evaluate()
        n = self.term.slave.layout.num_owned
        states = self.slip_states(state)[:n]
        comm = self.term.comm
        history = self.term.friction.history
        return {"tangential_force": self.tangential_force(state).tolist(),
                "dissipation": history.dissipation,
                "step_dissipation": history.step_dissipation,
                "stick_nodes": int(comm.allreduce(int(np.sum(states == 1)))),
                "slip_nodes": int(comm.allreduce(int(np.sum(states == 2)))),
                "tangential_energy": self.term.friction.stored_energy(state.friction)}
