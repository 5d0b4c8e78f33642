"""What a contact term reports: gaps, pressures, tractions, forces, and the
warnings about a configuration that has left the model's range.

Each figure, with what it is:

- :meth:`ContactResults.nodal_pressures`: ``p_A``, the coefficients of the
  contact pressure in the partition-of-unity basis (``ε⟨d̄_A⟩``);
- :meth:`ContactResults.surface_pressure`: the same ``p_A`` at the slave surface's
  nodes only, with their coordinates (per rank or gathered);
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

import warnings
from dataclasses import dataclass
from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.kinds import DUAL_KINDS
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement
from dolfinx_mortar.tolerance import length_scale, zero_length

FloatArray = npt.NDArray[np.float64]

#: an initial penetration deeper than this many slave element lengths is warned about
DEEP_PENETRATION = 0.5
#: a penetration at convergence deeper than this many slave element lengths is
#: warned about: the penalty is low for the mesh (ε 1000× too low gave 0.055)
PENALTY_PENETRATION = 0.01
#: the penetration, in element lengths, that the suggested penalty aims at
SUGGESTED_PENETRATION = 1e-3
#: basis_configuration="initial" is warned about past this many element lengths of slip
SLIP_LIMIT = 1.0


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
    """Results of a :class:`~dolfinx_mortar.contact.term.ContactTerm` at the present u."""

    def evaluate(self) -> ContactState:
        """The contact state at the present u with every dof kept (results)."""
        self.u.x.scatter_forward()
        return self.model.evaluate(self.u, None)

    def nodal_gaps(self) -> FloatArray:
        """``d̄_A`` (penetration positive) at the local slave-layout nodes."""
        return self.evaluate().gaps

    def nodal_pressures(self, state: Optional[ContactState] = None) -> FloatArray:
        """Contact pressure ``p_A`` at the local slave-layout nodes (0 off the surface)."""
        return self.model.nodal_pressures(state or self.evaluate())

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
        slave = self.slave
        layout = slave.layout
        n = layout.num_owned
        nodes = np.flatnonzero(layout.on_cells(slave.cells)[:n])
        part = SurfacePressure(slave.x[nodes], self.nodal_pressures(state)[nodes],
                               layout.global_indices[nodes])
        if not gather:
            return part
        parts = self.mesh.comm.allgather(part)
        x = np.concatenate([q.x for q in parts]).reshape(-1, slave.gdim)
        # coordinates equal up to round-off (a mesh generator's 0 may be -2e-18) are equal
        # here, so that the order does not depend on where round-off lands
        zero = zero_length(length_scale(x))
        order = np.lexsort(np.round(x / zero).T[::-1])
        return SurfacePressure(x[order], np.concatenate([q.p for q in parts])[order],
                               np.concatenate([q.global_index for q in parts])[order])

    def mortar_traction(self, state: Optional[ContactState] = None) -> FloatArray:
        """The contact traction ``p*`` at the nodes of every slave cell, (cells, nodes):
        one set per cell, since ``p*`` of the dual kinds jumps between cells."""
        return self.model.mortar_traction(state or self.evaluate())

    def normal_force(self, state: Optional[ContactState] = None) -> float:
        """``∫ p dA = Σ_A W_A p_A`` over all ranks (a scalar)."""
        n = self.slave.layout.num_owned
        state = state or self.evaluate()
        p = self.nodal_pressures(state)
        return float(self.mesh.comm.allreduce(float(np.sum((state.lumped_weights * p)[:n]))))

    def contact_force(self, state: Optional[ContactState] = None) -> FloatArray:
        """The resultant of the contact traction on the slave body, a gdim-vector:
        ``−Σ R_c`` over the slave nodes' dofs, summed over all ranks."""
        state = state or self.evaluate()
        gdim = self.slave.gdim
        R = state.residual.array_r.reshape(-1, gdim)
        nodes = np.unique(self.slave.cells)
        nodes = nodes[nodes < self.slave.layout.num_owned]
        local = -R[nodes].sum(axis=0) if len(nodes) else np.zeros(gdim)
        return np.asarray(self.mesh.comm.allreduce(local))

    def active_nodes(self, state: Optional[ContactState] = None) -> int:
        """The number of slave nodes with a positive pressure, over all ranks."""
        p = self.nodal_pressures(state)
        return int(self.mesh.comm.allreduce(
            int(np.sum(p[: self.slave.layout.num_owned] > 0))))

    # -- range of the model ------------------------------------------------------------
    def _node_lengths(self) -> FloatArray:
        """Each local slave node's element length: the largest of its cells'."""
        slave = self.slave
        cell_length = slave.tabulate().ds_weights.sum(axis=1) ** (1.0 / slave.tdim)
        length = np.zeros(slave.layout.size_local)
        np.maximum.at(length, slave.cells, np.repeat(cell_length[:, None],
                                                     slave.cells.shape[1], axis=1))
        return length

    def warn_deep_initial_penetration(self) -> None:
        """Warn when the configuration penetrates by more than DEEP_PENETRATION
        slave element lengths (a rigid plane placed 0.2 deep into a 0.5-high
        block solved without a word)."""
        state = self.evaluate()
        slave = self.slave
        # nodes of this rank's cells (on_cells also counts other ranks' cells)
        on_local_cell = np.zeros(slave.layout.size_local, dtype=bool)
        on_local_cell[slave.cells] = True
        covered = state.covered & on_local_cell
        ratio, gap, x = self._deepest(np.where(covered, state.gaps, -np.inf))
        if ratio > DEEP_PENETRATION:
            hint = ""
            options = self.options
            if (self.master is not None and options.kind in DUAL_KINDS
                    and not options.boundary_modification):
                # the dual functions are negative near the far node of a facet:
                # a facet covered only there by the master "sees" a penetration
                hint = ("; or, with a dual kind against an elastic master, a slave facet only "
                        "partly covered by the master (at the edge of the search radius or "
                        "of the master) shows a false penetration: pass "
                        "boundary_modification=True")
            warnings.warn(f"the initial configuration penetrates by {gap:.3g} ({ratio:.3g} "
                          f"slave element lengths) at the slave node {x}: check the "
                          "obstacle's position and normal, or the tags of slave and master"
                          + hint, RuntimeWarning, stacklevel=3)

    def _deepest(self, depth: FloatArray) -> tuple[float, float, list]:
        """The largest ``depth`` in slave element lengths over the owned nodes of
        every rank: (ratio, depth, node coordinates)."""
        slave = self.slave
        n = slave.layout.num_owned
        length = self._node_lengths()
        # a node on no local cell has no length here: its own rank judges it
        ratio = np.full(len(length), -np.inf)
        np.divide(depth, length, out=ratio, where=length > 0)
        ratio = ratio[:n]
        worst = int(np.argmax(ratio)) if n else -1
        local = ((float(ratio[worst]), float(depth[worst]), slave.x[worst].tolist())
                 if n else (-np.inf, 0.0, []))
        return max(self.mesh.comm.allgather(local), key=lambda item: item[0])

    def penetration(self, state: Optional[ContactState] = None) -> tuple[float, float, list]:
        """The deepest penetration at convergence over every rank: (in slave
        element lengths, as a length, the node's coordinates).

        The penetration is ``p_A / ε``, the mortar-weighted gap of an active
        node in either scaling.
        """
        return self._deepest(self.nodal_pressures(state) / self.options.penalty)

    def warn_if_the_penalty_is_low(self, deepest: tuple[float, float, list]) -> None:
        """Warn when the deepest :meth:`penetration` of a solve exceeds
        PENALTY_PENETRATION slave element lengths, naming the penalty and one
        that would bring it to SUGGESTED_PENETRATION.

        The penetration falls about as 1/ε, exactly so under a prescribed
        force. A penalty 1000 times too low penetrated by 5.5% of an element
        without a word.
        """
        ratio, depth, x = deepest
        if ratio <= PENALTY_PENETRATION:
            return
        penalty = self.options.penalty
        suggested = penalty * ratio / SUGGESTED_PENETRATION
        warnings.warn(f"at convergence the slave surface penetrates by {depth:.3g} "
                      f"({ratio:.2g} slave element lengths) at the node {x}: the penalty "
                      f"{penalty:.3g} is low for this mesh; about {suggested:.3g} would "
                      f"bring the penetration to {SUGGESTED_PENETRATION:g} element lengths "
                      "(it falls about as 1/penalty)", RuntimeWarning, stacklevel=3)

    def slip(self, state: Optional[ContactState] = None) -> float:
        """The largest tangential slip of an active slave node since the bases
        were built, in element lengths of that node (over all ranks).

        Slip is the node's displacement relative to what it touches (the
        obstacle's motion, or the mean displacement of the master nodes of the
        master cells its cells were paired with), without the normal part.
        """
        state = state or self.evaluate()
        slave = self.slave
        u_nodes = nodal_displacement(slave, self.u)
        other = self._partner_displacement(u_nodes)
        measure = slave.tabulate().ds_weights.sum(axis=1)
        weighted = slave.cell_normals() * measure[:, None, None]
        normals = np.stack([slave.layout.sum_at_functions(slave.cells, weighted[..., k])
                            for k in range(slave.gdim)], axis=1)
        size = np.linalg.norm(normals, axis=1)
        normals = normals / np.where(size > 0, size, 1.0)[:, None]
        relative = u_nodes - other
        tangential = relative - np.einsum("ak,ak->a", relative, normals)[:, None] * normals
        active = (self.model.nodal_pressures(state) > 0)
        ratio = np.where(active, np.linalg.norm(tangential, axis=1)
                         / np.maximum(self._node_lengths(), np.finfo(float).tiny), 0.0)
        n = slave.layout.num_owned
        return float(self.mesh.comm.allreduce(float(np.max(ratio[:n], initial=0.0)),
                                               op=MPI.MAX))

    def _partner_displacement(self, u_nodes: FloatArray) -> FloatArray:
        """What each slave node touches moves by: the obstacle's displacement, or
        the mean displacement of the master nodes paired with the node's cells
        (master nodes may live on other ranks: fetched by global index)."""
        if self.obstacle is not None:
            return np.broadcast_to(self.obstacle.displacement, u_nodes.shape)
        coupling = self.model.coupling
        gdim = self.slave.gdim
        pairs = coupling.pairs
        nodes = coupling.master_global_ids[coupling.master_cells[pairs[:, 1]]]
        dofs = (nodes[..., None] * gdim + np.arange(gdim)).ravel().astype(PETSc.IntType)
        values = _gather_entries(self.u.x.petsc_vec, dofs).reshape(nodes.shape + (gdim,))
        master_mean = values.mean(axis=1)
        count = np.zeros(self.slave.layout.size_local)
        total = np.zeros_like(u_nodes)
        for b in range(self.slave.cells.shape[1]):
            ends = self.slave.cells[pairs[:, 0], b]
            np.add.at(total, ends, master_mean)
            np.add.at(count, ends, 1.0)
        return total / np.maximum(count, 1.0)[:, None]

    def warn_if_slipped_too_far(self, state: Optional[ContactState] = None) -> None:
        """With ``basis_configuration="initial"``: warn (once) past SLIP_LIMIT
        element lengths of slip (:meth:`slip`). A press-then-slide run gave a
        normal force growing 3× and a frictionless tangential force of 33% of
        it without a word. Against a rigid obstacle the gap is exact in u
        whatever the slip (no segmentation is frozen): no warning."""
        if (not self.configuration.pairs_found_once or self.obstacle is not None
                or getattr(self, "_slip_warned", False)):
            return
        s = self.slip(state)
        if s > SLIP_LIMIT:
            self._slip_warned = True
            warnings.warn(f"contact surfaces slipped {s:.3g} element lengths past the "
                          "configuration of the bases (basis_configuration='initial', valid "
                          "to about one element of slip): the forces are no longer reliable; "
                          "use basis_configuration='previous' or 'current'",
                          RuntimeWarning, stacklevel=3)

    def warn_if_no_master_is_in_reach(self, coupling: Optional[MortarCoupling] = None) -> None:
        """Against an elastic master, warn when no slave facet finds a master
        facet within the search radius, saying whether the master faces away.

        Both ended in "maximum Newton iterations" or "stalled" with no word on
        the cause: a master surface whose outward normal points the same way
        as the slave's (the far side of the other body, or tags swapped) is
        never paired, since only opposing facets are; a master beyond the
        search radius is not paired either, and in the initial configuration
        it never will be. ``coupling``: a segmentation of this configuration
        already made (None: one is made here).
        """
        if self.master is None:
            return
        comm = self.mesh.comm
        radius = self.options.search_radius
        if coupling is None:        # the current surface: one segmentation for this check
            coupling = MortarCoupling(self.slave, self.master, search_radius=radius)
        if comm.allreduce(len(coupling.pairs)) > 0:
            return
        radius = coupling.search_radius
        either_way = MortarCoupling(self.slave, self.master, search_radius=radius,
                                    opposing_normals_only=False)
        if comm.allreduce(len(either_way.pairs)) > 0:
            warnings.warn(f"the master surface faces away from the slave: within the search "
                          f"radius {radius:.3g} the slave facets find only master facets "
                          "whose outward normals point the same way as theirs, and those "
                          "are never paired. The master must be the surface of the other "
                          "body that faces the slave: check the master_tag, and that "
                          "slave and master tags are not swapped", RuntimeWarning,
                          stacklevel=3)
            return
        never = (" With basis_configuration='initial' the pairs are found only here, so "
                 "it never will." if self.configuration.pairs_found_once else "")
        warnings.warn(f"no slave facet finds a master facet within the search radius "
                      f"{radius:.3g} along its normal: the contact cannot act until the "
                      f"surfaces come within it.{never} Check the slave and master tags and "
                      "the bodies' positions, or pass a larger search_radius", RuntimeWarning,
                      stacklevel=3)

    def contact_reached_the_search_radius(self, state: Optional[ContactState] = None) -> bool:
        """With bases frozen against an elastic master: whether the contact zone
        reaches slave nodes that found no master within the search radius, though
        a master lies within four times it (collective).

        The pairs are found once per frozen configuration, along the normal and
        within the search radius (the largest slave facet by default); where the
        surfaces were further apart then, the pressure is cut off, with a peak
        at the last paired node. Two equal cylinders with a = R/10 on a mesh
        graded to h = a/40 lost the outer fifth of the contact zone that way and
        had the pressure 51% off.
        """
        if self.master is None or self.configuration.follows_u:
            return False
        model, slave = self.model, self.slave
        comm = self.mesh.comm
        state = state or self.evaluate()
        covered = state.covered
        cells = slave.cells
        # p is ε⟨d̄⟩: exactly 0 off the active set
        active = self.nodal_pressures(state) > 0
        at_edge = (active[cells].any(axis=1) & ~covered[cells].all(axis=1)
                   if len(cells) else np.zeros(0, dtype=bool))
        if not comm.allreduce(bool(at_edge.any()), op=MPI.LOR):
            return False
        coupling = model.coupling
        cached = getattr(self, "_beyond_radius", None)
        if cached is None or cached[0] is not coupling:
            # one wider segmentation per frozen configuration, not one per step
            wider = MortarCoupling(coupling.slave, coupling.master,
                                   search_radius=4 * coupling.search_radius)
            cached = (coupling, slave.layout.on_cells(slave.cells[wider.pairs[:, 0]]))
            self._beyond_radius = cached
        reached = cached[1] & ~covered
        near_edge = np.zeros(slave.layout.size_local, dtype=bool)
        near_edge[cells[at_edge].ravel()] = True
        return bool(comm.allreduce(bool(np.any(reached & near_edge)), op=MPI.LOR))


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
