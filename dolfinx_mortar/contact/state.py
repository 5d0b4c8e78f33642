"""What the contact is at one displacement: the state of the normal contact
(:class:`ContactState`, which every gap source returns) and of friction
(:class:`FrictionState`). Shared by the gap sources, friction, the Newton entry
and the results, so it belongs to none of them."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.laws import ReturnMapping

FloatArray = npt.NDArray[np.float64]


@dataclass
class FrictionState:
    """Friction at one displacement (part of a
    :class:`ContactState`).

    Attributes
    ----------
    slip_increment
        ``Δy_T`` per local node since the last accepted step, (nodes, gdim).
    mapping
        The return mapping's forces, derivatives and stick/slip states.
    G_T
        ``∂Δy_T/∂u`` (rows: node·gdim + i), Dirichlet columns dropped.
    tangential_weights
        ``ω_T = ε_T W^m`` per node.
    projected_history
        ``P_A f_T,A^n``: the last accepted forces in the present tangent planes.
    residual
        ``G_Tᵀ f_T``, friction's part of the contact residual.
    """

    slip_increment: FloatArray
    mapping: ReturnMapping
    G_T: PETSc.Mat
    tangential_weights: FloatArray
    projected_history: FloatArray
    residual: Optional[PETSc.Vec] = None



@dataclass
class ContactState:
    """The contact terms at one displacement.

    The contact residual is ``residual = Gᵀ force``. ``G`` is the derivative
    of the nodal gaps d̄ with respect to the displacement dofs, with the
    Dirichlet columns dropped (for GLS kinds Ĝ of ĝ, and ``force`` is
    z = L⁻¹ω⟨d̄⟩). ``gaps_plus`` and ``G_plus`` are the pointwise active set's
    d̄⁺ and its derivative (None with the nodal set); ``K_curv`` the obstacle's
    curvature stiffness (None if flat); ``data`` what a model's Jacobian
    needs beyond that (the current configuration's).

    What the surface was at this displacement is part of the state, not of
    the model: ``weights`` (ω of the law), ``lumped_weights`` (W),
    ``covered`` (the slave nodes with something to touch) and
    ``coefficients`` (M̄ on every slave cell in the displacement's basis, for
    the traction) are the model's constants with frozen bases and follow u on
    the current surface.
    """

    gaps: FloatArray
    G: PETSc.Mat
    force: FloatArray
    residual: PETSc.Vec
    K_curv: Optional[PETSc.Mat] = None
    gaps_plus: Optional[FloatArray] = None
    G_plus: Optional[PETSc.Mat] = None
    #: the current-surface sources' own state (their
    #: :class:`~dolfinx_mortar.contact.gap_sources.current.finite_deformation.CurrentState`)
    data: Optional[object] = None
    weights: Optional[FloatArray] = None
    lumped_weights: Optional[FloatArray] = None
    covered: Optional[npt.NDArray[np.bool_]] = None
    coefficients: Optional[FloatArray] = None
    #: friction at this displacement (None: frictionless)
    friction: Optional[FrictionState] = None
