"""What a contact term reports (``term.results``): gaps, pressures, tractions,
forces, slip and penetration. The warnings about a configuration that has left
the model's range are :mod:`~dolfinx_mortar.contact.checks.range_checks`.

Each figure, with what it is:

- :meth:`ContactResults.nodal_pressures`: ``p_A``, the coefficients of the
  contact pressure in the partition-of-unity basis (``ε⟨d̄_A⟩``);
- :meth:`ContactResults.surface_pressure`: the same ``p_A`` at the slave surface's
  nodes only, with their coordinates (per rank or gathered);
- :meth:`ContactResults.surface_friction`: with friction, the tangential
  traction ``q_A`` and the stick/slip state there, in the same form;
- :meth:`ContactResults.mortar_traction`: ``p* = Σ f_A M_A`` per slave cell,
  the traction whose virtual work the residual is;
- :meth:`ContactResults.normal_force`: ``Σ_A W_A p_A``, the integral of the
  pressure (a scalar, on the surface the bases live in);
- :meth:`ContactResults.contact_force`: the resultant vector of the contact
  traction on the slave body, ``−Σ R_c`` over its dofs: what a load cell
  would read. On a curved contact it differs from ``normal_force`` by the
  tilt of the normals (and in the current configuration by the area change).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement
from dolfinx_mortar.tolerance import length_scale, zero_length

FloatArray = npt.NDArray[np.float64]



@dataclass(frozen=True)
class SurfacePressure:
    """The contact pressure at the nodes of a slave surface.

    Attributes
    ----------
    x
        Reference (undeformed) coordinates of the nodes, shape (n, gdim); (r, z) on an
        axisymmetric mesh.
    p
        The contact pressure ``p_A`` at them, shape (n,); exactly 0 where the node is out of
        contact.
    global_index
        The nodes' global indices in the displacement space's node numbering (which depends
        on the partition: match runs on different numbers of ranks by ``x``).
    """

    x: FloatArray
    p: FloatArray
    global_index: npt.NDArray[np.int64]


@dataclass(frozen=True)
class SurfaceFriction:
    """The tangential traction and the stick/slip state at the nodes of a slave
    surface, in the form of :class:`SurfacePressure`.

    Attributes
    ----------
    x
        Reference (undeformed) coordinates of the nodes, shape (n, gdim).
    q
        The tangential traction ``q_A`` on the slave body at them, shape (n, gdim)
        (:meth:`ContactResults.tangential_tractions`); 0 where separated.
    stick_slip
        Their state, shape (n,): 0 separated, 1 stick, 2 slip
        (:meth:`ContactResults.slip_states`).
    global_index
        The nodes' global indices in the displacement space's node numbering.
    """

    x: FloatArray
    q: FloatArray
    stick_slip: npt.NDArray[np.int8]
    global_index: npt.NDArray[np.int64]


class ContactResults:
    """What a :class:`~dolfinx_mortar.contact.term.ContactTerm` reports at the
    present u (or at a state it evaluated): ``term.results``."""

    def __init__(self, term):
        self.term = term

    def nodal_gaps(self) -> FloatArray:
        """``d̄_A`` (penetration positive) at the local slave-layout nodes."""
        return self.term.evaluate().gaps

    def nodal_pressures(self, state: Optional[ContactState] = None) -> FloatArray:
        """Contact pressure ``p_A`` at the local slave-layout nodes (0 off the surface)."""
        return self.term.source.nodal_pressures(state or self.term.evaluate())

    def surface_pressure(self, state: Optional[ContactState] = None,
                         gather: bool = False) -> SurfacePressure:
        """The contact pressure at the slave surface's nodes, with their coordinates.

        Collective.

        Parameters
        ----------
        state
            A contact state; by default the one at the present u.
        gather
            False: the surface nodes this rank owns, in local order. True: every surface node
            of all ranks, on every rank, sorted by coordinates (x first, then y, then z).
        """
        x, p, index = self._at_surface_nodes(gather, self.nodal_pressures(state))
        return SurfacePressure(x, p, index)

    def _at_surface_nodes(self, gather: bool, *values: np.ndarray) -> tuple:
        """The slave surface's nodes' coordinates, ``values`` (arrays over the
        local slave-layout nodes) there and the nodes' global indices: this
        rank's owned surface nodes in local order, or (``gather``) every rank's
        on every rank, sorted by coordinates. Collective if ``gather``."""
        slave = self.term.slave
        layout = slave.layout
        n = layout.num_owned
        nodes = np.flatnonzero(layout.on_cells(slave.cells)[:n])
        part = (slave.x[nodes], [v[nodes] for v in values], layout.global_indices[nodes])
        if not gather:
            return (part[0], *part[1], part[2])
        parts = self.term.comm.allgather(part)
        x = np.concatenate([q[0] for q in parts]).reshape(-1, slave.gdim)
        # coordinates equal up to round-off (a mesh generator's 0 may be -2e-18) are equal
        # here, so that the order does not depend on where round-off lands
        zero = zero_length(length_scale(x))
        order = np.lexsort(np.round(x / zero).T[::-1])
        gathered = [np.concatenate([q[1][k] for q in parts])[order] for k in range(len(values))]
        return (x[order], *gathered, np.concatenate([q[2] for q in parts])[order])

    def mortar_traction(self, state: Optional[ContactState] = None) -> FloatArray:
        """The contact traction ``p*`` at the nodes of every slave cell, (cells, nodes):
        one set per cell, since ``p*`` of the dual kinds jumps between cells."""
        return self.term.source.mortar_traction(state or self.term.evaluate())

    def normal_force(self, state: Optional[ContactState] = None) -> float:
        """``∫ p dA = Σ_A W_A p_A`` over all ranks (a scalar)."""
        n = self.term.slave.layout.num_owned
        state = state or self.term.evaluate()
        p = self.nodal_pressures(state)
        return float(self.term.comm.allreduce(float(np.sum((state.lumped_weights * p)[:n]))))

    def contact_force(self, state: Optional[ContactState] = None) -> FloatArray:
        """The resultant of the contact traction on the slave body, a gdim-vector:
        ``−Σ R_c`` over the slave nodes' dofs, summed over all ranks."""
        return self._slave_resultant((state or self.term.evaluate()).residual)

    def _slave_resultant(self, residual: PETSc.Vec) -> FloatArray:
        """``−Σ residual`` over the slave nodes' owned dofs, summed over all ranks."""
        gdim = self.term.slave.gdim
        R = residual.array_r.reshape(-1, gdim)
        nodes = np.unique(self.term.slave.cells)
        nodes = nodes[nodes < self.term.slave.layout.num_owned]
        local = -R[nodes].sum(axis=0) if len(nodes) else np.zeros(gdim)
        return np.asarray(self.term.comm.allreduce(local))

    def active_nodes(self, state: Optional[ContactState] = None) -> int:
        """The number of slave nodes with a positive pressure, over all ranks."""
        p = self.nodal_pressures(state)
        return int(self.term.comm.allreduce(
            int(np.sum(p[: self.term.slave.layout.num_owned] > 0))))

    # -- friction -----------------------------------------------------------------------
    def _friction(self, state: Optional[ContactState]):
        if self.term.friction is None:
            raise ValueError("this contact term has no friction (ContactTerm(..., "
                             "friction=CoulombFriction(mu)))")
        return (state or self.term.evaluate()).friction

    def tangential_tractions(self, state: Optional[ContactState] = None) -> FloatArray:
        """``q_A = −f_T,A / W_A^k``: the coefficients of the tangential traction
        on the slave body in the partition-of-unity basis, as ``p_A`` is of the
        pressure, at the local slave-layout nodes, (nodes, gdim); it opposes
        the slave's slip relative to what it touches, and ``|q_A| ≤ μ p_A``.
        With the nodes' coordinates: :meth:`surface_friction`."""
        state = state or self.term.evaluate()
        W = state.lumped_weights
        force = -self._friction(state).mapping.force
        if self.term.options.law.k == 0:
            return force.copy()
        q = np.zeros_like(force)
        np.divide(force, W[:, None], out=q, where=(W > 0)[:, None])
        return q

    def slip_states(self, state: Optional[ContactState] = None) -> npt.NDArray[np.int8]:
        """Per local slave-layout node: 0 separated, 1 stick, 2 slip
        (:data:`~dolfinx_mortar.contact.laws.coulomb.STICK`, …). With the
        nodes' coordinates: :meth:`surface_friction`."""
        return self._friction(state).mapping.state.copy()

    def surface_friction(self, state: Optional[ContactState] = None,
                         gather: bool = False) -> SurfaceFriction:
        """The tangential traction and the stick/slip state at the slave
        surface's nodes, with their coordinates (as :meth:`surface_pressure`).

        Collective.

        Parameters
        ----------
        state
            A contact state; by default the one at the present u.
        gather
            False: the surface nodes this rank owns, in local order. True: every surface node
            of all ranks, on every rank, sorted by coordinates (x first, then y, then z).

        Raises
        ------
        ValueError
            If the term has no friction.
        """
        state = state or self.term.evaluate()
        x, q, stick_slip, index = self._at_surface_nodes(
            gather, self.tangential_tractions(state), self.slip_states(state))
        return SurfaceFriction(x, q, stick_slip, index)

    def tangential_force(self, state: Optional[ContactState] = None) -> FloatArray:
        """The resultant of the tangential (friction) traction on the slave
        body, a gdim-vector over all ranks: ``−Σ G_Tᵀ f_T`` over the slave
        nodes' dofs, as :meth:`contact_force` is of the whole traction."""
        return self._slave_resultant(self._friction(state).residual)

    def dissipation(self) -> float:
        """The frictional dissipation ``Σ_steps Σ_A f_T,A · Δy_p,A`` over the
        accepted steps, over all ranks."""
        if self.term.friction is None:
            return 0.0
        return self.term.friction.history.dissipation

    def stored_energy(self, state: Optional[ContactState] = None) -> float:
        """The energy stored in the contact's penalty springs over all ranks:
        ``Σ_A (ω_A/2)⟨y_A⟩²`` (normal) plus, with friction,
        ``Σ_A |f_T,A|²/(2ω_T,A)`` (tangential); for the nodal active set, where
        the normal law has this potential (ω and y of the current surface with
        ``basis_configuration="current"``)."""
        state = state or self.term.evaluate()
        if not self.term.options.law.has_potential:
            raise NotImplementedError("the stored energy is that of the nodal active set: "
                                      "the pointwise one has no potential")
        n = self.term.slave.layout.num_owned
        normal = np.sum(self.term.options.law.potential(state.weights, state.gaps)[:n])
        energy = float(self.term.comm.allreduce(float(normal)))
        if self.term.friction is not None:
            energy += self.term.friction.stored_energy(state.friction)
        return energy

    def friction_summary(self, state: Optional[ContactState] = None) -> Optional[dict]:
        """The friction figures of a step, for the load path's history: None
        without friction, else ``tangential_force`` (list), ``dissipation``
        (total), ``step_dissipation``, ``stick_nodes``, ``slip_nodes``,
        ``tangential_energy`` (the tangential springs' stored energy)."""
        if self.term.friction is None:
            return None
        state = state or self.term.evaluate()
        n = self.term.slave.layout.num_owned
        states = self.slip_states(state)[:n]
        comm = self.term.comm
        history = self.term.friction.history
        return {"tangential_force": self.tangential_force(state).tolist(),
                "dissipation": history.dissipation,
                "step_dissipation": history.step_dissipation,
                "stick_nodes": int(comm.allreduce(int(np.sum(states == 1)))),
                "slip_nodes": int(comm.allreduce(int(np.sum(states == 2)))),
                "tangential_energy": self.term.friction.stored_energy(state.friction)}

    def node_lengths(self) -> FloatArray:
        """Each local slave node's element length: the largest of its cells'."""
        slave = self.term.slave
        cell_length = slave.tabulate().ds_weights.sum(axis=1) ** (1.0 / slave.tdim)
        length = np.zeros(slave.layout.size_local)
        np.maximum.at(length, slave.cells, np.repeat(cell_length[:, None],
                                                     slave.cells.shape[1], axis=1))
        return length

    def deepest(self, depth: FloatArray) -> tuple[float, float, list]:
        """The largest ``depth`` in slave element lengths over the owned nodes of
        every rank: (ratio, depth, node coordinates)."""
        slave = self.term.slave
        n = slave.layout.num_owned
        length = self.node_lengths()
        # a node on no local cell has no length here: its own rank judges it
        ratio = np.full(len(length), -np.inf)
        np.divide(depth, length, out=ratio, where=length > 0)
        ratio = ratio[:n]
        worst = int(np.argmax(ratio)) if n else -1
        local = ((float(ratio[worst]), float(depth[worst]), slave.x[worst].tolist())
                 if n else (-np.inf, 0.0, []))
        return max(self.term.comm.allgather(local), key=lambda item: item[0])

    def penetration(self, state: Optional[ContactState] = None) -> tuple[float, float, list]:
        """The deepest penetration at convergence over every rank: (in slave
        element lengths, as a length, the node's coordinates).

        The penetration is ``p_A / ε``, the mortar-weighted gap of an active
        node in either scaling.
        """
        return self.deepest(self.nodal_pressures(state) / self.term.options.penalty)

    def slip(self, state: Optional[ContactState] = None) -> float:
        """The largest tangential slip of an active slave node since the bases
        were built, in element lengths of that node (over all ranks).

        Slip is the node's displacement relative to what it touches (the
        obstacle's motion, or the mean displacement of the master nodes of the
        master cells its cells were paired with), without the normal part.
        """
        state = state or self.term.evaluate()
        slave = self.term.slave
        u_nodes = nodal_displacement(slave, self.term.u)
        other = self._partner_displacement(u_nodes)
        measure = slave.tabulate().ds_weights.sum(axis=1)
        weighted = slave.cell_normals() * measure[:, None, None]
        normals = np.stack([slave.layout.sum_at_functions(slave.cells, weighted[..., k])
                            for k in range(slave.gdim)], axis=1)
        size = np.linalg.norm(normals, axis=1)
        normals = normals / np.where(size > 0, size, 1.0)[:, None]
        relative = u_nodes - other
        tangential = relative - np.einsum("ak,ak->a", relative, normals)[:, None] * normals
        active = (self.term.source.nodal_pressures(state) > 0)
        ratio = np.where(active, np.linalg.norm(tangential, axis=1)
                         / np.maximum(self.node_lengths(), np.finfo(float).tiny), 0.0)
        n = slave.layout.num_owned
        return float(self.term.comm.allreduce(float(np.max(ratio[:n], initial=0.0)),
                                               op=MPI.MAX))

    def _partner_displacement(self, u_nodes: FloatArray) -> FloatArray:
        """What each slave node touches moves by: the obstacle's displacement, or
        the mean displacement of the master nodes paired with the node's cells
        (master nodes may live on other ranks: fetched by global index)."""
        if self.term.obstacle is not None:
            return np.broadcast_to(self.term.obstacle.displacement, u_nodes.shape)
        coupling = self.term.source.coupling
        gdim = self.term.slave.gdim
        pairs = coupling.pairs
        nodes = coupling.master_global_ids[coupling.master_cells[pairs[:, 1]]]
        dofs = (nodes[..., None] * gdim + np.arange(gdim)).ravel().astype(PETSc.IntType)
        values = _gather_entries(self.term.u.x.petsc_vec, dofs).reshape(nodes.shape + (gdim,))
        master_mean = values.mean(axis=1)
        count = np.zeros(self.term.slave.layout.size_local)
        total = np.zeros_like(u_nodes)
        for b in range(self.term.slave.cells.shape[1]):
            ends = self.term.slave.cells[pairs[:, 0], b]
            np.add.at(total, ends, master_mean)
            np.add.at(count, ends, 1.0)
        return total / np.maximum(count, 1.0)[:, None]


def _gather_entries(vec: PETSc.Vec, indices: npt.NDArray) -> FloatArray:
    """The entries of a distributed vector at global ``indices`` (any rank's)."""
    target = PETSc.Vec().createSeq(len(indices), comm=PETSc.COMM_SELF)
    source = PETSc.IS().createGeneral(indices, comm=PETSc.COMM_SELF)
    scatter = PETSc.Scatter().create(vec, source, target, None)
    scatter.scatter(vec, target, addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    values = target.array.copy()
    for obj in (scatter, source, target):
        obj.destroy()
    return values
