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

from typing import Any, Optional, Protocol

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.gap_sources.slip import SlipOperator, StepStart
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.layout import MassMatrixSolver, NodeLayout
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface


FloatArray = npt.NDArray[np.float64]


class GapSource(Protocol):
    """The one interface of the gap sources: everything outside
    :mod:`~dolfinx_mortar.contact.gap_sources` asks a source through these
    members only (``tools/architecture_counts.py`` counts the others read).

    Implemented by :class:`~dolfinx_mortar.contact.gap_sources.frozen.ObstacleGap`,
    :class:`~dolfinx_mortar.contact.gap_sources.frozen.MortarGap`,
    :class:`~dolfinx_mortar.contact.gap_sources.global_gap.GlobalGap` and the
    current-surface sources of :mod:`~dolfinx_mortar.contact.gap_sources.current`.
    A new source implements them and is chosen in
    :mod:`~dolfinx_mortar.contact.gap_sources.choice` (docs/DESIGN.md, §Architecture).
    """

    #: the pairs, and so the matrix pattern, change inside a Newton solve
    moving_pattern: bool
    #: the slave surface (its node layout, cells and coordinates)
    slave: LagrangeSurface
    #: the layout of the slave nodes' displacement dofs (node·gdim + i)
    dofs: NodeLayout
    #: the segmentation against an elastic master it was built on (None: none)
    coupling: Optional[MortarCoupling]
    #: friction's slip operator is made again at every load step
    slip_operator_per_step: bool

    @property
    def node_lengths(self) -> FloatArray:
        """An element length per slave node (the scale of "near contact")."""

    def evaluate(self, u: Any, mask: Optional[PETSc.Vec]) -> ContactState:
        """The state at the displacement Function ``u``; ``mask`` is 1 on free
        dofs and 0 on Dirichlet dofs (None: keep every column)."""

    def jacobian(self, state: ContactState, active: FloatArray, mask: Optional[PETSc.Vec],
                 geometric: bool = True) -> PETSc.Mat:
        """The contact stiffness with ``active`` (0/1 per node) as H(d̄)."""

    def pattern(self, state: ContactState) -> PETSc.Mat:
        """A matrix with every entry :meth:`jacobian` may have at this state."""

    def nodal_pressures(self, state: ContactState) -> FloatArray:
        """The nodal pressures ``p_A`` of the law at ``state``."""

    def mortar_traction(self, state: ContactState) -> FloatArray:
        """The traction's values at the nodes of every slave cell, (cells, nodes)."""

    def tangential_tractions(self, state: ContactState) -> FloatArray:
        """The tangential traction ``q_A`` on node A's body at a state with
        friction, (nodes, gdim)."""

    def normal_force_derivative(self, state: ContactState, active: FloatArray) -> PETSc.Mat:
        """``∂f_N/∂u`` of the nodal normal forces (slave nodes × dofs), ``active`` as H."""

    def nodal_force(self, values: FloatArray) -> FloatArray:
        """The nodal force f of ``R_c = Gᵀ f`` for nodal values ω⟨d̄⟩."""

    def slip_operator(self, start: StepStart, project: bool = True) -> SlipOperator:
        """Friction's tangential slip operator for the step that starts at
        ``start`` (:mod:`~dolfinx_mortar.contact.gap_sources.slip`; ``project``
        False: the unprojected integrals, for GLS's L⁻¹)."""


class GlobalGapSource(GapSource, Protocol):
    """A source of the GLS kinds (``d̄ = L⁻¹ ĝ``), as the augmented Newton
    step needs it (:class:`~dolfinx_mortar.contact.newton.augmented.AugmentedNewtonStep`)."""

    #: the standard-basis source of ``ĝ`` and ``Ĝ``
    inner: GapSource
    #: the factorized L
    mass: MassMatrixSolver
    #: owned local nodes of the slave surface (the rows the Newton step needs)
    surface_rows: npt.NDArray[np.int32]

    def any_penetration(self, gaps_plus: FloatArray) -> bool:
        """Whether the pointwise ``d̄⁺`` is nonzero anywhere (collective)."""
