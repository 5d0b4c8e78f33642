"""The tangential slip operator a gap source gives friction (docs/FRICTION.md).

Over a load step, the slip increment of slave node A is the mortar-weighted
relative displacement increment projected on the node's tangent plane where
the step starts, ``Δy_T,A = P_A (Σ_B D̄_AB Δu_B − Σ_C M̄_AC Δu_C)``; against a
rigid obstacle ``−(∫ M̄_A) Δc`` replaces the master part. Each gap source
makes it from its own frozen mortar integrals
(:meth:`GapSource.slip_operator
<dolfinx_mortar.contact.gap_sources.source.GapSource.slip_operator>`), so that
friction never needs to know which source it works with.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt
from petsc4py import PETSc

from dolfinx_mortar.kinds import dual_partner
from dolfinx_mortar.layout import MassMatrixSolver, NodeLayout, assemble_blocks

FloatArray = npt.NDArray[np.float64]


@dataclass
class StepStart:
    """Where a load step starts: what a slip operator is made about.

    Attributes
    ----------
    u_nodes
        The nodal displacement at the local slave-layout nodes, (nodes, gdim).
    u
        The same displacement as a dof vector.
    obstacle_displacement
        The rigid obstacle's translation then (None against an elastic master).
    """

    u_nodes: FloatArray
    u: PETSc.Vec
    obstacle_displacement: Optional[FloatArray]


@dataclass
class SlipOperator:
    """The linear map of a step: ``Δy_T = to_local(G_T Δu) − obstacle_weights Δc``;
    with ``mass`` (GLS, GLS*) ``Δy_T = P L⁻¹(Ĝ_T Δu − (∫N) Δc)``, G_T then
    the standard basis's unprojected ``Ĝ_T``."""

    G_T: PETSc.Mat
    projectors: FloatArray              # P_A, (nodes, gdim, gdim)
    obstacle_weights: Optional[FloatArray]  # (∫ M̄_A) P_A for the obstacle's motion
    weights: FloatArray                 # ω = ε W^m of the source it was made from
    dofs: NodeLayout                    # the layout of G_T's rows (node·gdim + i)
    mass: Optional[MassMatrixSolver] = None  # L of the global kinds


def tangent_projectors(normals: FloatArray) -> FloatArray:
    """``P_A = I − n_A ⊗ n_A`` per node, (nodes, gdim, gdim)."""
    gdim = normals.shape[1]
    return np.eye(gdim)[None] - normals[:, :, None] * normals[:, None, :]


def stacked_identities(projectors: FloatArray) -> FloatArray:
    """Identities shaped like ``projectors`` (GLS: projected after L⁻¹)."""
    return np.broadcast_to(np.eye(projectors.shape[1]), projectors.shape)


def lumped_slave_part(blocks: FloatArray, slave_nodes: int) -> FloatArray:
    """The scalar slip couplings against a rigid obstacle (cells, rows,
    columns) lumped onto their diagonal (row sums ``∫ M̄_A`` kept): LmLS and
    LmLS* measure a node's slip from its own displacement there.

    Their ``D̄_AB = ∫ M̄_A N_B`` couples each node to its neighbours (a
    row-scaled consistent mass), and with it the nodal Coulomb conditions are
    set on an average of the neighbours' slips, which made Newton's stick/slip
    iteration run away (:func:`dual_slip_blocks`).
    The obstacle's part ``−(∫ M̄_A) Δc`` is a rigid motion, so the lumped slip
    is still none for every motion the two sides share. Against an elastic
    master the dual basis measures the slip instead.
    """
    slave, master = blocks[:, :, :slave_nodes], blocks[:, :, slave_nodes:]
    diagonal = np.zeros_like(slave)
    rows = np.arange(slave.shape[1])
    diagonal[:, rows, rows] = slave.sum(axis=2)
    return np.concatenate([diagonal, master], axis=2)


def dual_slip_blocks(source) -> tuple:
    """LmLS, LmLS* against an elastic master: ``source.pair_operators`` with the
    scalar couplings ``[D̄ | −M̄]`` of the dual basis of the same ``∫ M̄_A``.

    Their own ``D̄`` (a row-scaled consistent mass) sets each node's Coulomb
    condition on an average of its neighbours' slips, on which Newton ran
    away; lumping it beside the mortar ``M̄`` (until 2026-12-08) read a shared,
    non-uniform motion as slip, ``(W − D̄)u`` (3.7% on the pressure of two
    blocks widening alike). The dual basis keeps ``D̄`` diagonal where a facet
    is covered, sees no slip in a shared motion and passes a uniform traction
    on (docs/FRICTION.md, §The slip of LmLS and LmLS*).
    """
    coupling = source.coupling
    C = coupling.basis(dual_partner(source.basis.kind)).coefficients
    C = source.slave.reference.standard_coefficients(C)[coupling.pairs[:, 0]]
    Dn, Mn, _ = coupling.raw_pairs
    cells, cols, _ = source.pair_operators
    return cells, cols, np.concatenate([np.einsum("pba,pbc->pac", C, Dn),
                                        -np.einsum("pba,pbc->pac", C, Mn)], axis=2)


def assemble_slip(dofs: NodeLayout, gdim: int, cells: npt.NDArray[np.int32],
                  cols: npt.NDArray[np.int64], blocks: FloatArray,
                  projectors: FloatArray) -> PETSc.Mat:
    """``G_T`` from scalar node couplings ``blocks`` (cells, rows, cols) times P_A."""
    nc, nr = cells.shape
    values = np.einsum("can,caik->caink", blocks, projectors[cells])
    rows = (cells[..., None] * gdim + np.arange(gdim)).reshape(nc, nr * gdim)
    return assemble_blocks(dofs, rows, dofs, cols, values.reshape(nc, nr * gdim, cols.shape[1]))


def mortar_slip_operator(source, project: bool) -> SlipOperator:
    """The slip operator of a source frozen against an elastic master (its
    pair operators ``[D̄ | −M̄]`` and the segmentation's nodal normals)."""
    cells, cols, blocks = source.slip_pair_operators(project)
    projectors = tangent_projectors(source.coupling.normals)
    applied = projectors if project else stacked_identities(projectors)
    G_T = assemble_slip(source.dofs, source.slave.gdim, cells, cols, blocks, applied)
    return SlipOperator(G_T, projectors, None, source.weights, source.dofs)


def obstacle_slip_operator(source, obstacle, start: StepStart, lumped: bool,
                           project: bool) -> SlipOperator:
    """The slip operator against a rigid obstacle: the tangent planes of the
    obstacle below each node where the step starts (the obstacle translated
    back to where it was then)."""
    u_nodes = start.u_nodes if source.reference is None else start.u_nodes - source.reference
    slave = source.slave
    tab, cells = source.tabulation, slave.cells
    nodes = np.unique(cells)
    back = np.asarray(obstacle.displacement) - start.obstacle_displacement
    normals = np.zeros_like(u_nodes)
    normals[nodes] = obstacle.gradient(slave.x[nodes] + u_nodes[nodes] + back)
    projectors = tangent_projectors(normals)
    blocks = np.einsum("cq,cqa,cqb->cab", tab.weights, source.Mbar, tab.phi)
    if lumped and project:
        blocks = lumped_slave_part(blocks, blocks.shape[2])
    nc, nd = cells.shape
    cols = source.node_dofs(cells).reshape(nc, nd * slave.gdim)
    mass = slave.layout.sum_at_functions(cells, blocks.sum(axis=2))
    applied = projectors if project else stacked_identities(projectors)
    G_T = assemble_slip(source.dofs, slave.gdim, cells, cols, blocks, applied)
    return SlipOperator(G_T, projectors, mass[:, None, None] * applied, source.weights,
                        source.dofs)
