"""What a self-contact surface's two passes share: each pass's half penalty,
and what the pair reports (docs/SELF_CONTACT.md, §What a node reports)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.laws import PenaltyLaw
from dolfinx_mortar.contact.state import ContactState

FloatArray = npt.NDArray[np.float64]


def half_penalty(law: PenaltyLaw) -> PenaltyLaw:
    """Each pass's law: the mean of the two passes is each with half the penalty."""
    return replace(law, penalty=law.penalty / 2)


class TwoPassPressures:
    """What a two-pass source reports (mixed into a source built with
    :func:`half_penalty`): the traction each node's body receives from both
    passes, not the gap of the node's own pass.

    Where the two sides' meshes do not match and slide past each other, the
    two passes' gaps disagree node by node (the two sets of constraints are
    met only together, as the penalty's compromise): on two non-matching
    blocks slid by 0.07 of an element (tests/contact/test_self_contact_friction.py),
    ``ε⟨d̄_A⟩`` of LcLS*'s own pass was 16% off the uniform pressure in the
    middle, alternating from node to node, while the forces the nodes
    receive were within 0.8% of it. So with the dual kinds on linear facets
    a node reports ``p_A = n_A·r_A / W_A``, with ``r_A`` the normal contact
    force on its dofs from both passes (its own pass as slave, the other as
    master) and ``W_A = ∫ N_A``: where the passes mirror each other that is
    the own pass's ``ε⟨d̄_A⟩`` (``D̄`` is diagonal). LmLS and LmLS* report
    the own pass's pressure (:attr:`_reports_received`), and keep that
    node-to-node scatter where non-matching faces slide (8% there).
    """

    #: each contact is seen from both sides, each pass with half the penalty
    passes = 2

    def nodal_pressures(self, state: ContactState) -> FloatArray:
        """``p_A = n_A·r_A / W_A``: the normal traction node A's body receives
        (where :attr:`_reports_received` is False, the own pass's ``ε⟨d̄_A⟩``)."""
        if not self._reports_received:
            return self.passes * super().nodal_pressures(state)
        normals, _ = self._node_geometry(state)
        received = self._received(state, state.residual, normal_only=True)
        return np.einsum("ai,ai->a", received, normals)

    def tangential_tractions(self, state: ContactState) -> FloatArray:
        """``q_A = −P_A r_T,A / W_A``: the tangential traction node A's body
        receives from the friction forces of both passes."""
        if not self._reports_received:
            return self.passes * super().tangential_tractions(state)
        n, _ = self._node_geometry(state)
        q = -self._received(state, state.friction.residual, normal_only=False)
        return q - np.einsum("ai,ai->a", q, n)[:, None] * n

    @property
    def _reports_received(self) -> bool:
        """Whether a node's received force over ``W_A`` is its pressure: with
        the dual kinds on linear facets, where ``D̄`` is diagonal. Elsewhere
        (LmLS, LmLS*: ``D̄`` is a row-scaled consistent mass; quadratic facets:
        forces of the transformed basis) it would be a smoothed pressure, 11–37%
        off the mirror problem's on the C body, and the own pass's is reported."""
        return self.slave.reference.transform is None and not self.lumped_slip

    def _received(self, state: ContactState, forces: PETSc.Vec, normal_only: bool
                  ) -> FloatArray:
        """``r_A / W_A`` of ``forces`` (a residual vector); ``normal_only``: the
        friction's own forces taken out of them first."""
        layout, gdim = self.slave.layout, self.slave.gdim
        r = self.dofs.to_local(forces).reshape(-1, gdim)
        if normal_only and state.friction is not None:
            r = r - self.dofs.to_local(state.friction.residual).reshape(-1, gdim)
        on_surface = layout.on_cells(self.slave.cells)
        _, W = self._node_geometry(state)
        out = np.zeros_like(r)
        np.divide(r, W[:, None], out=out, where=on_surface[:, None])
        return out

    def mortar_traction(self, state: ContactState) -> FloatArray:
        """The traction of the node's own pass with the whole penalty."""
        return self.passes * super().mortar_traction(state)
