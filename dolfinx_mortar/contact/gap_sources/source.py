"""The gap-source interface, and what every gap source returns: the contact state at one displacement.

All gap models — rigid obstacle, elastic master, GLS/GLS*, pointwise active
set, current configuration — answer the same three questions
(:class:`GapSource`): the state at a displacement (:meth:`GapSource.evaluate`),
the contact stiffness at that state (:meth:`GapSource.jacobian`), and the
pressures and traction it carries. The contact term
(:class:`~dolfinx_mortar.contact.term.ContactTerm`) only talks to this
interface.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Protocol

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

FloatArray = npt.NDArray[np.float64]


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
    data: Any = None
    weights: Optional[FloatArray] = None
    lumped_weights: Optional[FloatArray] = None
    covered: Optional[npt.NDArray[np.bool_]] = None
    coefficients: Optional[FloatArray] = None
    #: friction at this displacement (a
    #: :class:`~dolfinx_mortar.contact.friction.tangential.FrictionState`; None: frictionless)
    friction: Any = None


class GapSource(Protocol):
    """The one interface of the gap models (:mod:`~dolfinx_mortar.contact.gap_sources.frozen`,
    :mod:`~dolfinx_mortar.contact.gap_sources.global_gap`,
    :mod:`~dolfinx_mortar.contact.gap_sources.current.finite_deformation`,
    :mod:`~dolfinx_mortar.contact.gap_sources.current.mortar`)."""

    #: the pairs, and so the matrix pattern, change inside a Newton solve
    moving_pattern: bool

    def evaluate(self, u: Any, mask: Optional[PETSc.Vec]) -> ContactState:
        """The state at the displacement Function ``u``; ``mask`` is 1 on free
        dofs and 0 on Dirichlet dofs (None: keep every column)."""

    def jacobian(self, state: ContactState, active: FloatArray, mask: Optional[PETSc.Vec],
                 geometric: bool = True) -> PETSc.Mat:
        """The contact stiffness with ``active`` (0/1 per node) as H(d̄)."""

    def pattern(self, state: ContactState) -> PETSc.Mat:
        """A matrix with every entry :meth:`jacobian` may have at this state."""

    def nodal_pressures(self, state: ContactState) -> FloatArray: ...

    def mortar_traction(self, state: ContactState) -> FloatArray: ...

    def normal_force_derivative(self, state: ContactState, active: FloatArray) -> PETSc.Mat:
        """``∂f_N/∂u`` of the nodal normal forces (slave nodes × dofs), ``active`` as H."""

    def nodal_force(self, values: FloatArray) -> FloatArray:
        """The nodal force f of ``R_c = Gᵀ f`` for nodal values ω⟨d̄⟩."""
