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

from dolfinx_mortar.contact.laws import ReturnMapping
from dolfinx_mortar.contact.options import ContactOptions
from dolfinx_mortar.layout import MassMatrixSolver

FloatArray = npt.NDArray[np.float64]


def check_friction_options(options: ContactOptions) -> None:
    """NotImplementedError naming a combination friction does not support, and why."""
    if options.law.pointwise:
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
    accepted: Optional["FrictionState"] = None


@dataclass
class FrictionState:
    """Friction at one displacement (part of a
    :class:`~dolfinx_mortar.contact.gap_sources.source.ContactState`).

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
class SlipOperator:
    """The linear map of a step: ``Δy_T = to_local(G_T Δu) − obstacle_weights Δc``;
    with ``mass`` (GLS, GLS*) ``Δy_T = P L⁻¹(Ĝ_T Δu − (∫N) Δc)``, G_T then
    the standard basis's unprojected ``Ĝ_T``."""

    G_T: PETSc.Mat
    projectors: FloatArray              # P_A, (nodes, gdim, gdim)
    obstacle_weights: Optional[FloatArray]  # (∫ M̄_A) P_A for the obstacle's motion
    weights: FloatArray                 # ω = ε W^m of the model it was made from
    mass: Optional[MassMatrixSolver] = None  # L of the global kinds


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


def tangent_projectors(normals: FloatArray) -> FloatArray:
    gdim = normals.shape[1]
    return np.eye(gdim)[None] - normals[:, :, None] * normals[:, None, :]


def stacked_identities(projectors: FloatArray) -> FloatArray:
    return np.broadcast_to(np.eye(projectors.shape[1]), projectors.shape)


def solve_components(mass: MassMatrixSolver, values: FloatArray) -> FloatArray:
    """``L⁻¹`` applied to each component of nodal vectors (nodes, gdim)."""
    return np.stack([mass.solve(values[:, i]) for i in range(values.shape[1])], axis=1)


def lumped_slave_part(blocks: FloatArray, slave_nodes: int) -> FloatArray:
    """The scalar slip couplings ``[D̄ | −M̄]`` (cells, rows, columns) with the
    slave part ``D̄`` lumped onto its diagonal (row sums ``∫ M̄_A`` kept).

    For LmLS and LmLS* ``D̄_AB = ∫ M̄_A N_B`` couples each node to its
    neighbours (a row-scaled consistent mass, 1/6 : 2/3 : 1/6 on a uniform
    line), and with it the nodal Coulomb conditions are set on an average of
    the neighbours' slips. Newton's stick/slip iteration then ran away: on a
    block pushed sideways at 0.2 of its load (μ = 0.3, ε = 1e3 E/h) the slip
    of the slipping zone reversed from one iteration to the next, hundreds of
    stick bands deep, and it stalled at every increment (a first step from
    rest is the same problem at any load). The dual kinds' D̄ is diagonal
    already (biorthogonality) and they converged in 4–5 iterations; lumped,
    LmLS(*) converge in the same (docs/FRICTION.md). The row sums keep the
    slip objective for rigid translations, and the master part stays the
    mortar integral.
    """
    slave, master = blocks[:, :, :slave_nodes], blocks[:, :, slave_nodes:]
    diagonal = np.zeros_like(slave)
    rows = np.arange(slave.shape[1])
    diagonal[:, rows, rows] = slave.sum(axis=2)
    return np.concatenate([diagonal, master], axis=2)
