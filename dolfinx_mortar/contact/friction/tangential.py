"""Coulomb friction of a contact term: the tangential slip, its history, and
the tangential residual and exact Jacobian (docs/FRICTION.md).

The slip increment of slave node A over a load step is the mortar-weighted
relative displacement increment projected on the node's tangent plane where
the step starts:

    Δy_T,A = P_A (Σ_B D̄_AB Δu_B − Σ_C M̄_AC Δu_C),   P_A = I − n_A ⊗ n_A,

with the gap model's own frozen mortar integrals (``D̄_AB = ∫ M̄_A N_B``,
``M̄_AC = ∫ M̄_A N^m_C``; against a rigid obstacle ``−(∫ M̄_A) Δc``, Δc the
obstacle's translation). It is objective in the sense the frozen
configurations are: a rigid translation of both bodies gives no slip, since
the rows of D̄ and M̄ integrate the same function over the covered part, and
the mortar weighting makes it independent of where the master mesh's nodes
lie. Tangential forces follow from the return mapping of
:mod:`~dolfinx_mortar.contact.laws.coulomb`; with ``f_N = ω⟨y⟩`` the
contact's normal nodal forces,

- residual ``R_T = G_Tᵀ f_T`` with ``G_T = ∂Δy_T/∂u`` (linear: frozen
  normals and integrals within a step),
- Jacobian ``K_T = G_Tᵀ (C_TT G_T + c_TN ⊗ ∂f_N/∂u)``, unsymmetric in slip
  (``∂f_N/∂u = ωH G`` on frozen bases).

GLS and GLS* (gaps ``L⁻¹ĝ`` of the standard basis) measure the slip the same
way through L: ``Δy_T = P L⁻¹(Ĝ_T Δu − (∫N) Δc)``, residual ``Ĝ_Tᵀ L⁻¹ f_T``;
their dense tangent is never formed, the augmented Newton system carries it
(:class:`AugmentedFriction`, :mod:`~dolfinx_mortar.contact.newton.augmented`).

On the current surface (``basis_configuration="current"``) the normal contact
follows u and the slip is measured as above on the model frozen where the
step starts (its tangent planes, mortar integrals and ω_T, made again for
each step): Δy_T stays linear within a step, so G_T is constant and the
Jacobian exact for it, with ``∂f_N/∂u`` of the current surface (W moves too).
A rotation of the contact within one step is then seen as slip to first
order in the step's rotation.

The history (the tangential forces and the displacement of the last accepted
step) changes only in :meth:`Friction.accept`, called by the load-path driver
when a step has converged: a cut-back retries from the same history.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.laws import SLIP, ReturnMapping, TangentialLaw
from dolfinx_mortar.contact.friction.state import (AugmentedFriction, FrictionHistory,
                                                   FrictionState, check_friction_options,
                                                   solve_components)
from dolfinx_mortar.contact.gap_sources import GapSource, SlipOperator, StepStart
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.options import ContactOptions
from dolfinx_mortar.layout import assemble_blocks
from dolfinx_mortar.linalg.sparse_products import kron_identity, transpose_mat_mult
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement

FloatArray = npt.NDArray[np.float64]
DIFFERENT = PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN


class Friction:
    """Coulomb friction of one contact term (see the module).

    Friction asks the term's gap source only through the
    :class:`~dolfinx_mortar.contact.gap_sources.GapSource` interface: its
    slip operator (:meth:`~dolfinx_mortar.contact.gap_sources.GapSource.slip_operator`),
    the derivative of its normal forces and its dof layout.

    Parameters
    ----------
    law
        The friction law (:class:`~dolfinx_mortar.contact.laws.TangentialLaw`:
        Coulomb's μ and ε_T, or another).
    options
        The contact term's options (checked here for what friction supports).
    u
        The displacement Function (its present value starts the history).
    slave
        The slave surface (:class:`~dolfinx_mortar.surfaces.lagrange.LagrangeSurface`).
    obstacle
        The term's rigid obstacle, or None.
    """

    def __init__(self, law: TangentialLaw, options: ContactOptions, u, slave,
                 obstacle: Optional[RigidObstacle] = None):
        check_friction_options(options)
        self.law = law
        self.normal_law = options.law
        #: ε_T
        self.penalty = law.penalty(options.penalty)
        self.slave, self.obstacle = slave, obstacle
        self.comm: MPI.Comm = slave.layout.comm
        u.x.scatter_forward()
        self.history = FrictionHistory(
            np.zeros((slave.layout.size_local, slave.gdim)), u.x.petsc_vec.copy(),
            nodal_displacement(slave, u),
            None if obstacle is None else np.array(obstacle.displacement, dtype=float))
        self._operator: Optional[SlipOperator] = None
        #: the states and slip directions of the last Jacobian (exact once states repeat)
        self._jacobian_states: Optional[tuple[npt.NDArray[np.int8], FloatArray]] = None
        #: the source and the step the slip operator was made for
        self._operator_for: tuple = (None, -2)

    def begin_attempt(self) -> None:
        """An attempt at a load step starts on the secant (docs/FRICTION.md)."""
        self._jacobian_states = None

    def _slip_operator(self, source: GapSource) -> SlipOperator:
        """The slip operator of the present step: made again for a new source,
        and for every new step where the source says so (an obstacle's tangent
        planes, the current surface frozen where the step starts)."""
        h = self.history
        key = (source, h.version if source.slip_operator_per_step else -1)
        if self._operator is None or self._operator_for[0] is not key[0] \
                or self._operator_for[1] != key[1]:
            start = StepStart(h.u_nodes, h.u, h.obstacle_displacement)
            self._operator = source.slip_operator(start)
            self._operator_for = key
        return self._operator

    # -- evaluation --------------------------------------------------------------------
    def evaluate(self, source: GapSource, state: ContactState, u, active: FloatArray,
                 mask: Optional[PETSc.Vec]) -> FrictionState:
        """Friction at the displacement Function ``u`` with the normal state
        ``state`` and ``active`` (0/1 per node, the nodes stiffened normally)."""
        operator = self._slip_operator(source)
        h = self.history
        du = u.x.petsc_vec.copy()
        du.axpy(-1.0, h.u)
        Gdu = operator.G_T.createVecLeft()
        operator.G_T.mult(du, Gdu)
        gdim = self.slave.gdim
        slip = operator.dofs.to_local(Gdu).reshape(-1, gdim)
        for v in (du, Gdu):
            v.destroy()
        if operator.obstacle_weights is not None:
            motion = np.asarray(self.obstacle.displacement) - h.obstacle_displacement
            slip -= operator.obstacle_weights @ motion
        if operator.mass is not None:
            slip = np.einsum("aik,ak->ai", operator.projectors,
                             solve_components(operator.mass, slip))
        weights = operator.weights * (self.penalty / self.normal_law.penalty)
        history = np.einsum("aik,ak->ai", operator.projectors, h.forces)
        trial = history + weights[:, None] * slip
        # the cone's normal force ω⟨y⟩ (for GLS state.force is L⁻¹ of it)
        normal = self.normal_law.force(state.weights, state.gaps)
        mapping = self.law.return_mapping(trial, normal, weights, active > 0)
        G_T = operator.G_T.copy()
        if mask is not None:
            G_T.diagonalScale(None, mask)
        f = G_T.createVecLeft()
        force = mapping.force
        if operator.mass is not None:
            # R_T = Ĝ_Tᵀ L⁻¹ P f_T, with P f_T = f_T
            force = solve_components(operator.mass, force)
        f.array[:] = force[: self.slave.layout.num_owned].ravel()
        residual = G_T.createVecRight()
        G_T.multTranspose(f, residual)
        f.destroy()
        return FrictionState(slip, mapping, G_T, weights, history, residual)

    def add_to(self, state: ContactState, source: GapSource, u, active: FloatArray,
               mask: Optional[PETSc.Vec]) -> None:
        """Friction at ``u`` into ``state``: its forces in the residual, its own
        state as ``state.friction``. A result at a converged step (no ``mask``)
        reports that step's return mapping, not one with its forces already
        made history."""
        if mask is None and self.at_accepted_step(u):
            friction = self.history.accepted
        else:
            friction = self.evaluate(source, state, u, active, mask)
        state.residual.axpy(1.0, friction.residual)
        state.friction = friction

    def _node_blocks(self, source: GapSource, values: FloatArray, columns: str) -> PETSc.Mat:
        """A matrix of one block per owned slave-surface node: (gdim × gdim)
        on the dofs (``columns="dofs"``) or (gdim × 1) on the node
        (``columns="nodes"``)."""
        layout, gdim, dofs_layout = self.slave.layout, self.slave.gdim, source.dofs
        nodes = self.slave.owned_nodes
        rows = nodes[:, None] * gdim + np.arange(gdim)
        if columns == "dofs":
            dofs = layout.global_indices[nodes][:, None] * gdim + np.arange(gdim)
            return assemble_blocks(dofs_layout, rows, dofs_layout, dofs, values[nodes])
        return assemble_blocks(dofs_layout, rows, layout, layout.global_indices[nodes][:, None],
                               values[nodes][:, :, None])

    def jacobian(self, source: GapSource, state: ContactState, friction: FrictionState,
                 active: FloatArray) -> PETSc.Mat:
        """``K_T = G_Tᵀ (C_TT G_T + c_TN ⊗ ∂f_N/∂u)`` at ``friction``."""
        mapping = friction.mapping
        tangent = self._tangent(mapping, friction.tangential_weights)
        return self._product(source, friction, tangent, mapping.normal_tangent,
                             source.normal_force_derivative(state, active))

    def augmented_blocks(self, source: GapSource, state: ContactState, friction: FrictionState,
                         active: FloatArray) -> AugmentedFriction:
        """Friction's blocks of the GLS kinds' augmented Newton system at ``friction``."""
        mapping = friction.mapping
        P = self._operator.projectors
        PCP = np.einsum("aij,ajk,akl->ail", P,
                        self._tangent(mapping, friction.tangential_weights), P)
        PB = np.einsum("aij,aj->ai", P, mapping.normal_tangent) * \
            (state.weights * active)[:, None]
        return AugmentedFriction(friction.G_T, self._node_blocks(source, PCP, "dofs"),
                                 self._node_blocks(source, PB, "nodes"),
                                 kron_identity(self._operator.mass.matrix, self.slave.gdim))

    def _tangent(self, mapping: ReturnMapping, tangential_weights: FloatArray) -> FloatArray:
        """The return mapping's tangent for Newton: the secant while the
        stick/slip states change, then exact, and the stick tangent for a
        slipping node that turned back (collective)."""
        states = mapping.state
        # the exact slip tangent (0 along t in 2D) lets a slipping node's
        # direction flip in one Newton step across the tiny stick range μp/ε_T,
        # and the states then cycled (block on a slope: every local kind, 18
        # iterations then cut-backs); the secant along t is taken until the
        # states repeat on every rank, then Newton is exact again
        previous = self._jacobian_states
        settled = self.comm.allreduce(bool(previous is not None
                                           and np.array_equal(states, previous[0])),
                                      op=MPI.LAND)
        self._jacobian_states = (states.copy(), mapping.direction.copy())
        tangent = mapping.tangent if settled else mapping.secant_tangent()
        if previous is None:
            return tangent
        # a node that slipped at both Jacobians but turned back between them
        # straddles its stick band, and with the slip tangent it cycled (states
        # unchanged, period 2: Cattaneo-Mindlin GLS*; LcLS on 2 ranks); the
        # stick tangent ω_T I pulls it into the band. On the slip-limit grid
        # (benchmarks/slip_limit_grid.py): 68 of 72 converge, against 64
        turned = ((states == SLIP) & (previous[0] == SLIP)
                  & (np.einsum("ai,ai->a", mapping.direction, previous[1]) < 0))
        if np.any(turned):
            tangent = tangent.copy()
            tangent[turned] = tangential_weights[turned, None, None] * np.eye(tangent.shape[1])
        return tangent

    def _product(self, source: GapSource, friction: FrictionState, tangent: FloatArray,
                 normal_tangent: FloatArray, D: PETSc.Mat) -> PETSc.Mat:
        """``G_Tᵀ (C G_T + B D)`` with node blocks C = ``tangent`` and B =
        ``normal_tangent``, and ``D = ∂f_N/∂u``."""
        C = self._node_blocks(source, tangent, "dofs")
        B = self._node_blocks(source, normal_tangent, "nodes")
        J = C.matMult(friction.G_T)
        BD = B.matMult(D)
        J.axpy(1.0, BD, structure=DIFFERENT)
        K = transpose_mat_mult(friction.G_T, J)
        for m in (C, B, J, BD, D):
            m.destroy()
        return K

    def pattern(self, source: GapSource, state: ContactState, friction: FrictionState) -> PETSc.Mat:
        """Every entry :meth:`jacobian` may have (stick and slip at every node)."""
        gdim = self.slave.gdim
        n = self.slave.layout.size_local
        return self._product(source, friction, np.ones((n, gdim, gdim)), np.ones((n, gdim)),
                             source.normal_force_derivative(state, np.ones(n)))

    # -- the history -------------------------------------------------------------------
    def accept(self, friction: FrictionState, u) -> None:
        """Make a converged step's forces the history, add the step's
        dissipation and record its displacement.

        The dissipation of a step is the work of the friction forces on the
        plastic slip ``Δy_p = Δy_T − (f_T − P f_T^n)/ω_T``, integrated by the
        trapezoidal rule: ``Σ_A ½(P f_T^n + f_T)_A · Δy_p,A``. With the work of
        the loads integrated the same way, the energy balance of a path closes
        to the Newton tolerance (docs/FRICTION.md); it equals the return
        mapping's ``f_T · Δy_p`` while a node slips at a constant normal force.
        """
        mapping = friction.mapping
        w = friction.tangential_weights
        elastic = np.zeros_like(mapping.force)
        np.divide(mapping.force - friction.projected_history, w[:, None], out=elastic,
                  where=(w > 0)[:, None])
        plastic = np.where((mapping.state > 0)[:, None], friction.slip_increment - elastic, 0.0)
        n = self.slave.layout.num_owned
        mean = 0.5 * (mapping.force[:n] + friction.projected_history[:n])
        local = float(np.einsum("ai,ai->", mean, plastic[:n]))
        step = self.comm.allreduce(local)
        h = self.history
        h.forces = mapping.force.copy()
        u.x.scatter_forward()
        h.u.destroy()
        h.u = u.x.petsc_vec.copy()
        h.u_nodes = nodal_displacement(self.slave, u)
        if self.obstacle is not None:
            h.obstacle_displacement = np.array(self.obstacle.displacement, dtype=float)
        h.step_dissipation = step
        h.dissipation += step
        h.version += 1
        h.accepted = friction

    def at_accepted_step(self, u) -> bool:
        """Whether ``u`` is, bit for bit on every rank, the displacement of the
        last accepted step (collective)."""
        h = self.history
        same = h.accepted is not None and np.array_equal(u.x.petsc_vec.array_r, h.u.array_r)
        return bool(self.comm.allreduce(same, op=MPI.LAND))

    def stored_energy(self, friction: FrictionState) -> float:
        """``Σ_A |f_T,A|² / (2 ω_T,A)`` over all ranks: the elastic energy of
        the tangential penalty springs."""
        w = friction.tangential_weights
        n = self.slave.layout.num_owned
        energy = np.zeros(n)
        np.divide(np.sum(friction.mapping.force[:n] ** 2, axis=1), 2 * w[:n], out=energy,
                  where=w[:n] > 0)
        return float(self.comm.allreduce(float(energy.sum())))
