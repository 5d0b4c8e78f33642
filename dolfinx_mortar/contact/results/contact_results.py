"""What a contact term reports (``term.results``): gaps, pressures, tractions,
forces, slip and penetration. The friction figures are
:mod:`~dolfinx_mortar.contact.results.friction_results`', handed on here. The
warnings about a configuration that has left the model's range are
:mod:`~dolfinx_mortar.contact.checks.range_checks`.

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

from dolfinx_mortar.contact.results.friction_results import FrictionResults, SurfaceFriction
from dolfinx_mortar.contact.results.surface_nodes import at_surface_nodes, slave_resultant
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.mortar.surface_normals import normal_clusters, sum_over_clusters
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement

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


class ContactResults:
    """What a :class:`~dolfinx_mortar.contact.term.ContactTerm` reports at the
    present u (or at a state it evaluated): ``term.results``."""

    def __init__(self, term):
        self.term = term
        # the friction figures are a part of their own, handed on below
        self._friction = FrictionResults(term)
        self._node_lengths: Optional[FloatArray] = None

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
        x, p, index = at_surface_nodes(self.term, gather, self.nodal_pressures(state))
        return SurfacePressure(x, p, index)

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

    def contact_force(self, state: Optional[ContactState] = None,
                      tag: Optional[int] = None) -> FloatArray:
        """The resultant of the contact traction on the slave body, a gdim-vector:
        ``−Σ R_c`` over the slave nodes' dofs, summed over all ranks (collective).

        Parameters
        ----------
        state
            A contact state; by default the one at the present u.
        tag
            One of the term's slave facet tags: the resultant on the nodes of
            those facets only (a node on facets of two tags counts in both).
            Over a self-contact surface, or several bodies under one term, the
            whole resultant is 0 (the forces are internal); per tag it is the
            force one body's face receives from the others.
        """
        return slave_resultant(self.term, (state or self.term.evaluate()).residual, tag)

    def active_nodes(self, state: Optional[ContactState] = None) -> int:
        """The number of slave nodes with a positive pressure, over all ranks."""
        p = self.nodal_pressures(state)
        return int(self.term.comm.allreduce(
            int(np.sum(p[: self.term.slave.layout.num_owned] > 0))))

    # -- friction: FrictionResults' figures, handed on ----------------------------------
    def tangential_tractions(self, state: Optional[ContactState] = None) -> FloatArray:
        """The tangential tractions ``q_A`` (:meth:`.FrictionResults.tangential_tractions`)."""
        return self._friction.tangential_tractions(state)

    def slip_states(self, state: Optional[ContactState] = None) -> npt.NDArray[np.int8]:
        """The stick/slip state per node (:meth:`.FrictionResults.slip_states`)."""
        return self._friction.slip_states(state)

    def surface_friction(self, state: Optional[ContactState] = None,
                         gather: bool = False) -> SurfaceFriction:
        """``q_A`` and the stick/slip states with the nodes' coordinates
        (:meth:`.FrictionResults.surface_friction`). Collective."""
        return self._friction.surface_friction(state, gather)

    def tangential_force(self, state: Optional[ContactState] = None,
                         tag: Optional[int] = None) -> FloatArray:
        """The resultant of the friction traction (:meth:`.FrictionResults.tangential_force`)."""
        return self._friction.tangential_force(state, tag)

    def dissipation(self) -> float:
        """The frictional dissipation so far (:meth:`.FrictionResults.dissipation`)."""
        return self._friction.dissipation()

    def friction_summary(self, state: Optional[ContactState] = None) -> Optional[dict]:
        """The friction figures of a step (:meth:`.FrictionResults.friction_summary`)."""
        return self._friction.friction_summary(state)

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

    def node_lengths(self) -> FloatArray:
        """Each local slave node's element length (collective; of the reference
        surface, found once): the largest of its cells' on any rank, and at a
        node of a normal cluster (nodes joined by a facet of vanishing size,
        :func:`~dolfinx_mortar.mortar.surface_normals.normal_clusters`) the
        largest around the cluster. Not of this rank's cells alone: on 8 ranks
        a node owned where none of its facets are had length 0, and its slip
        read 1.9e305 element lengths. Not of the node's own cells alone: the end
        node of a corner chamfer 7e-7 h long read the penalty's penetration of
        1e-3 h as 1.4e3 of its element lengths, and warned of a low penalty."""
        if self._node_lengths is None:
            slave = self.term.slave
            cell_length = slave.tabulate().ds_weights.sum(axis=1) ** (1.0 / slave.tdim)
            at_nodes = np.repeat(cell_length[:, None], slave.cells.shape[1], axis=1)
            lengths = slave.layout.max_at_functions(slave.cells, at_nodes)
            clusters = normal_clusters(slave, slave.x)
            if clusters:                 # the same dict on every rank
                lengths = np.maximum(lengths, sum_over_clusters(
                    slave, clusters, np.zeros((len(lengths), 0)), maxima=at_nodes))
            lengths.flags.writeable = False
            self._node_lengths = lengths
        return self._node_lengths

    def deepest(self, depth: FloatArray) -> tuple[float, float, list]:
        """The largest ``depth`` in slave element lengths over the owned nodes of
        every rank: (ratio, depth, node coordinates)."""
        slave = self.term.slave
        n = slave.layout.num_owned
        length = self.node_lengths()
        # a function on no slave facet (none of its ranks' cells) has no length
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
