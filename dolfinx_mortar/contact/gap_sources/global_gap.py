"""The gap model of GLS and GLS*: nodal gaps through the global mass matrix.

``d̄ = L⁻¹ ĝ(u)`` with ``ĝ_B = ∫ N_B d`` (docs/DESIGN.md, §Augmented step). ``M_A`` has global
support, so ``G = L⁻¹ Ĝ`` is dense: only the sparse ``Ĝ = ∂ĝ/∂u`` and ``L``
are assembled, and the Newton step solves the augmented system
(:class:`~dolfinx_mortar.contact.newton.augmented.AugmentedNewtonStep`).
"""
from __future__ import annotations

from dataclasses import replace
from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.bases.basis import MortarBasis
from dolfinx_mortar.contact.gap_sources.frozen import GapSourceBase, tangential_tractions
from dolfinx_mortar.contact.laws import PenaltyLaw
from dolfinx_mortar.contact.gap_sources.slip import SlipOperator, StepStart
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.kinds import BasisKind
from dolfinx_mortar.layout import MassMatrixSolver
from dolfinx_mortar.mortar.coupling import MortarCoupling

FloatArray = npt.NDArray[np.float64]


def covered_mass(coupling: MortarCoupling) -> tuple[MassMatrixSolver, FloatArray]:
    """``L_AB = ∫_cov N_A N_B`` over the covered slave area, factorized, and its
    row sums ``W_A = ∫_cov N_A``. Nodes with no covered support get a unit row
    (their gap is 0 and their weight 0)."""
    slave = coupling.slave
    L, covered_cells, W = coupling.covered_element_mass()
    matrix = slave.layout.assemble_matrix(slave.cells[covered_cells], L[covered_cells])
    return MassMatrixSolver(slave.layout, matrix), W


class GlobalGap:
    """Nodal gaps of GLS and GLS*: ``d̄ = L⁻¹ ĝ(u)``.

    ``inner`` is a standard-basis gap model with frozen bases
    (:class:`~dolfinx_mortar.contact.gap_sources.frozen.ObstacleGap` or
    :class:`~dolfinx_mortar.contact.gap_sources.frozen.MortarGap` of kind LmLS*) that gives
    ``ĝ`` and ``Ĝ``; ``mass`` the factorized ``L`` and ``lumped_weights`` its
    row sums (over the covered part against an elastic master: with L over
    the whole surface the uncovered part counts as d = 0 and the gaps ring
    past the covered zone — a node beyond it got d̄ = +0.31 h on two touching
    cylinders at zero load).
    """

    moving_pattern = False

    def __init__(self, inner: GapSourceBase, law: PenaltyLaw,
                 mass: Optional[tuple[MassMatrixSolver, FloatArray]] = None):
        self.inner = inner
        self.law = law
        self.slave = inner.slave
        self.coupling = inner.coupling
        self.basis = MortarBasis(BasisKind.GLS, self.slave)
        self.mass, W = mass if mass is not None else (self.basis.mass_solver,
                                                      self.basis.lumped_weights)
        #: W_A = ∫ N_A over the part that enters the projection
        self.lumped_weights = W
        self.dofs = inner.dofs
        self.covered = inner.covered
        #: owned local nodes of the slave surface (the rows the Newton step needs)
        self.surface_rows = self.slave.owned_nodes
        # Π_c = Σ (ω_A/2)⟨d̄_A⟩² in terms of the GLS gap d̄ (∫M_A = 1)
        self.weights = np.where(self.covered, law.weights(W), 0.0)

    def evaluate(self, u, mask: Optional[PETSc.Vec]) -> ContactState:
        """``d̄ = L⁻¹ĝ``, Ĝ, and ``z = L⁻¹ω⟨d̄⟩`` (pointwise: ``L⁻¹ω d̄⁺``)."""
        g, G, x, g_plus, G_plus = self.inner.raw_gaps(u)
        gaps = self.mass.solve(g)
        gaps_plus = None if g_plus is None else self.mass.solve(g_plus)
        force = self.mass.solve(self.law.force(self.weights, gaps, gaps_plus))
        K_curv = self.inner.curvature(force, x) if x is not None else None
        return replace(self.inner.state(gaps, G, force, mask, gaps_plus, G_plus, K_curv),
                       weights=self.weights, lumped_weights=self.lumped_weights)

    def any_penetration(self, gaps_plus: FloatArray) -> bool:
        """Whether the pointwise ``d̄⁺`` is nonzero anywhere (collective)."""
        return self.inner.any_penetration(gaps_plus)

    @property
    def node_lengths(self) -> FloatArray:
        """An element length per slave node."""
        return self.basis.node_lengths

    @property
    def slip_operator_per_step(self) -> bool:
        """As the standard-basis source's."""
        return self.inner.slip_operator_per_step

    def slip_operator(self, start: StepStart, project: bool = True) -> SlipOperator:
        """The standard basis's unprojected integrals ``Ĝ_T``, with L: the slip
        is ``P L⁻¹(Ĝ_T Δu − (∫N)Δc)`` (projected after L⁻¹)."""
        operator = self.inner.slip_operator(start, project=False)
        operator.mass, operator.weights = self.mass, self.weights
        return operator

    def nodal_force(self, values: FloatArray) -> FloatArray:
        """``z = L⁻¹ values``: the nodal force of ``R_c = Ĝᵀ z``."""
        return self.mass.solve(values)

    def nodal_pressures(self, state: ContactState) -> FloatArray:
        """``p_A = ω_A⟨d̄_A⟩/W_A`` (pointwise: ``ω_A d̄⁺_A/W_A``), the
        coefficients of the traction in the PU basis GLS*."""
        return self.law.pressure(state.weights, state.lumped_weights, state.gaps,
                                 state.gaps_plus)

    def tangential_tractions(self, state: ContactState) -> FloatArray:
        """``q_A = −f_T,A / W_A^k`` (as the frozen sources)."""
        return tangential_tractions(self.law, state)

    def mortar_traction(self, state: ContactState) -> FloatArray:
        """``p* = Σ_A f_A (N L⁻¹)_A = Σ_B N_B z_B`` at the nodes of every slave cell."""
        return state.force[self.slave.cells]
