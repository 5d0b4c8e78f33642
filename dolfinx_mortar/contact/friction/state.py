"""The pieces of Coulomb friction that are not the term itself: the option
check, the history of accepted steps, a Newton iterate's friction state, the
slip operator's cache, the augmented system's blocks, and the small nodal
algebra they share (:mod:`~dolfinx_mortar.contact.friction.tangential`, docs/FRICTION.md)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.contact.options import ContactOptions
from dolfinx_mortar.contact.state import FrictionState
from dolfinx_mortar.layout import MassMatrixSolver

FloatArray = npt.NDArray[np.float64]


def check_friction_options(options: ContactOptions) -> None:
    """NotImplementedError naming a combination friction does not support, and why."""
    if not options.law.has_potential:
        raise NotImplementedError("friction with active_set='pointwise': the Coulomb cone is "
                                  "set by the nodal normal forces; use active_set='nodal'")


@dataclass
class FrictionHistory:
    """What friction remembers of the last accepted step.

    Attributes
    ----------
    forces
        The tangential nodal forces ``f_T`` at the local slave-layout nodes, (nodes, gdim).
    u
        The displacement vector of that step.
    u_nodes
        The same at the local slave-layout nodes, (nodes, gdim).
    obstacle_displacement
        The rigid obstacle's translation then (None against an elastic master).
    dissipation
        The frictional dissipation since the start, summed over all ranks.
    step_dissipation
        That of the last accepted step.
    version
        Counts the accepted steps.
    accepted
        The friction state of the last accepted step (None before the first):
        what a result at that displacement reports, since evaluated again there
        with its own forces as history every slipping node would sit on the
        cone and count as sticking.
    """

    forces: FloatArray
    u: PETSc.Vec
    u_nodes: FloatArray
    obstacle_displacement: Optional[FloatArray]
    dissipation: float = 0.0
    step_dissipation: float = 0.0
    version: int = 0
    accepted: Optional[FrictionState] = None


@dataclass
class AugmentedFriction:
    """Friction's blocks of the GLS kinds' augmented Newton system (rows and
    columns node·gdim + i of the slave layout; see
    :class:`~dolfinx_mortar.contact.newton.augmented.AugmentedNewtonStep`): with
    ``w = L⁻¹ Ĝ_T Δu`` and ``Δz_T = L⁻¹ Δf_T``, ``Δf_T = PCP w + PBωH Δy``."""

    G_T: PETSc.Mat      #: Ĝ_T, Dirichlet columns dropped
    PCP: PETSc.Mat      #: P C P per node
    PB: PETSc.Mat       #: P c_TN ωH per node (columns: the nodes)
    L: PETSc.Mat        #: L ⊗ I_gdim


def solve_components(mass: MassMatrixSolver, values: FloatArray) -> FloatArray:
    """``L⁻¹`` applied to each component of nodal vectors (nodes, gdim)."""
    return np.stack([mass.solve(values[:, i]) for i in range(values.shape[1])], axis=1)
