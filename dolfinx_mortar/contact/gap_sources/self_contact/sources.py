"""Self-contact: a surface that is its own master, in two passes
(docs/SELF_CONTACT.md).

Every node of the surface is a slave node with its own mortar gap against the
rest of the surface, whose facet neighbours are excluded from the pairs
(:func:`~dolfinx_mortar.mortar.facet_search.near_in_surface`). Each contact
is so seen twice, once from either side, and the potential is the mean of the
two passes, ``Π = ½ Σ_A (ω_A/2)⟨d̄_A⟩²`` over all nodes of the surface: no side
is preferred, and the answer does not depend on which one the user would have
called slave. Where the two sides are mirror images, each pass carries half
the force and the traction on either side is ``ε⟨d̄_A⟩``, the single-pass
pressure of a slave–master pair with the same penalty. What a node reports
is the traction its body receives from both passes
(:class:`~dolfinx_mortar.contact.gap_sources.self_contact.two_pass.TwoPassPressures`).
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.gap_sources.current import CurrentMortarGap
from dolfinx_mortar.contact.gap_sources.frozen import MortarGap
from dolfinx_mortar.contact.gap_sources.global_gap import GlobalGap
from dolfinx_mortar.contact.gap_sources.self_contact.two_pass import (TwoPassPressures,
                                                                      half_penalty)
from dolfinx_mortar.contact.laws import PenaltyLaw
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.kinds import BasisKind
from dolfinx_mortar.layout import MassMatrixSolver
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.mortar.surface_normals import averaged_nodal_normals
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

FloatArray = npt.NDArray[np.float64]


class SelfContactGap(TwoPassPressures, MortarGap):
    """The frozen mortar gaps of a surface against itself, two-pass (see the module).

    Parameters as for :class:`~dolfinx_mortar.contact.gap_sources.frozen.MortarGap`;
    ``coupling`` must pair the surface with itself without neighbours
    (``MortarCoupling(surface, surface, self_contact=True)``).
    """

    def __init__(self, coupling: MortarCoupling, law: PenaltyLaw,
                 reference: Optional[PETSc.Vec] = None, boundary_modification: bool = False):
        super().__init__(coupling, half_penalty(law), reference, boundary_modification)

    def _node_geometry(self, state: ContactState) -> tuple[FloatArray, FloatArray]:
        """The segmentation's nodal normals and ``W_A = ∫ N_A`` over the whole
        surface (frozen with the bases; not the covered part's)."""
        return self.coupling.normals, self.basis.lumped_weights


class SelfContactGlobalGap(TwoPassPressures, GlobalGap):
    """GLS and GLS* on a surface against itself, two-pass: ``d̄ = L⁻¹ĝ`` of each
    node's own pass, with ``L`` over the covered part of the whole surface.

    ``inner`` is the :class:`SelfContactGap` of kind LmLS* that gives ``ĝ`` and
    ``Ĝ`` (already with the half penalty), ``law`` the term's law (halved here,
    as the potential's own weights ``ω_A`` come from it). A node reports its
    own pass's pressure times two (``D̄ = L`` is not diagonal, so the force it
    receives over ``W_A`` would be a smoothed pressure).
    """

    def __init__(self, inner: SelfContactGap, law: PenaltyLaw,
                 mass: tuple[MassMatrixSolver, FloatArray]):
        super().__init__(inner, half_penalty(law), mass)

    @property
    def _reports_received(self) -> bool:
        return False


class CurrentSelfContactGap(TwoPassPressures, CurrentMortarGap):
    """The same on the current surface, exactly linearized (parameters as for
    :class:`~dolfinx_mortar.contact.gap_sources.current.CurrentMortarGap`, with
    the slave surface as its own master)."""

    def __init__(self, surface: LagrangeSurface, kind: BasisKind, law: PenaltyLaw,
                 search_radius: Optional[float] = None):
        # no boundary modification: refused in self-contact here (ContactOptions.of)
        super().__init__(surface, surface, kind, half_penalty(law), search_radius)

    def _node_geometry(self, state: ContactState) -> tuple[FloatArray, FloatArray]:
        """The averaged nodal normals and ``W_A`` of the current surface at ``state``."""
        x = np.zeros((self.slave.layout.size_local, self.slave.gdim))
        x[self.slave.cells] = state.data.x
        return averaged_nodal_normals(self.slave, x), state.lumped_weights
