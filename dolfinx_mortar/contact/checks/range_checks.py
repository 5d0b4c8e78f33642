"""The contact term's checks of its own range: a configuration that has left
what the model can represent is warned about (or, for the search radius,
acted on) instead of solved silently.

Each check is a method of :class:`RangeChecks`, which a term holds as
the term's: the term where it is made, a load-path driver after each
converged step and at the end of a solve.
"""
from __future__ import annotations

import logging
from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI

from dolfinx_mortar.collective_warnings import warn
from dolfinx_mortar.contact.checks.missed_contact import MissedContact
from dolfinx_mortar.contact.checks.setup_checks import (check_initial_overlap,
                                                        refuse_a_self_overlap,
                                                        warn_if_the_obstacle_faces_away)
from dolfinx_mortar.contact.checks.thresholds import (BODY_PENETRATION, DEEP_PENETRATION,
                                                      MAX_RADIUS_WIDENINGS, PENALTY_PENETRATION,
                                                      SLIP_LIMIT, SUGGESTED_PENETRATION)
from dolfinx_mortar.contact.gap_sources import pairing_options
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.kinds import DUAL_KINDS, is_global
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.tolerance import length_scale, zero_length

FloatArray = npt.NDArray[np.float64]

#: the checks' logger is named after the package, where users look for it
logger = logging.getLogger("dolfinx_mortar.contact.checks")


def body_penetration(term) -> tuple[float, float, list]:
    """The deepest penetration into the rigid obstacle of a node of u off the
    slave surface, at the present u of the contact term ``term``, over every
    rank: (in lengths of the node's largest cell, as a length, the node's
    reference coordinates).

    The contact holds only the slave surface's nodes
    (:meth:`~dolfinx_mortar.contact.results.contact_results.ContactResults.penetration`);
    the rest of the mesh may pass through the obstacle where the slave
    surface does not reach, or when the body folds through itself under a
    load far beyond a small-strain model's range (a cylinder on a plane at
    1000× the Hertz load: the slave nodes 0.005 elements deep, the
    cylinder's top 3.4 radii through the plane). Only nodes that started
    outside the obstacle count; without one (an elastic master), nothing
    is measured: (-inf, 0, []).
    """
    obstacle = term.obstacle
    comm = term.comm
    if obstacle is None:
        return (-np.inf, 0.0, [])
    V = term.u.function_space
    gdim = term.slave.gdim
    owned = V.dofmap.index_map.size_local
    X_all = V.tabulate_dof_coordinates()[:, :gdim]
    X = X_all[:owned]
    u = term.u.x.array.reshape(-1, gdim)[:owned]
    # where the obstacle started (a moved obstacle is a translated one)
    start = np.asarray(getattr(obstacle, "displacement", np.zeros(gdim)))
    outside = obstacle.signed_distance(X + start) >= -zero_length(length_scale(X, comm))
    outside[term.slave.owned_nodes] = False  # u's nodes
    depth = np.where(outside, -obstacle.signed_distance(X + u), -np.inf)
    # each node's length: the largest diameter of its cells (of their nodes' spread)
    dofs = V.dofmap.list
    corners = X_all[dofs]
    size = np.linalg.norm(corners[:, :, None] - corners[:, None], axis=-1).max(axis=(1, 2),
                                                                              initial=0.0)
    length = np.zeros(len(X_all))
    np.maximum.at(length, dofs, np.repeat(size[:, None], dofs.shape[1], axis=1))
    ratio = depth / np.maximum(length[:owned], np.finfo(float).tiny)
    worst = int(np.argmax(ratio)) if owned else -1
    local = ((float(ratio[worst]), float(depth[worst]), X[worst].tolist())
             if owned and np.isfinite(ratio[worst]) else (-np.inf, 0.0, []))
    return max(comm.allgather(local), key=lambda item: item[0])


class RangeChecks:
    """The checks of one contact term (the term's); each warns once."""

    def __init__(self, term, configuration):
        self.term = term
        #: where the term's bases live (whether its pairs are found once, follow u, …)
        self.configuration = configuration
        self._slip_warned = False
        self._body_warned = False
        #: (coupling, slave nodes a four times wider search pairs) of the last check
        self._beyond_radius: Optional[tuple] = None
        #: the check for contact that the pairs missed
        self.missed = MissedContact(term, configuration)
        #: times the default search radius was widened, and whether reaching it was warned
        self._radius_widenings = 0
        self._radius_warned = False

    def of_a_new_term(self) -> None:
        """The checks of a term just made: a deep initial penetration, an
        obstacle that faces away, bodies that overlap beyond the search radius
        (an error), no master in reach (collective)."""
        term = self.term
        self.warn_deep_initial_penetration()
        if term.obstacle is not None:
            warn_if_the_obstacle_faces_away(term.obstacle, term.slave, term.comm)
        coupling = self.configuration.segmentation(term.source)
        check_initial_overlap(term, coupling, self.configuration.built_at_u)
        self.warn_if_no_master_is_in_reach(coupling)

    def warn_deep_initial_penetration(self) -> None:
        """Warn when the configuration penetrates by more than DEEP_PENETRATION
        slave element lengths (a rigid plane placed 0.2 deep into a 0.5-high
        block solved without a word)."""
        state = self.term.evaluate()
        slave = self.term.slave
        # nodes of this rank's cells (on_cells also counts other ranks' cells)
        on_local_cell = np.zeros(slave.layout.size_local, dtype=bool)
        on_local_cell[slave.cells] = True
        covered = state.covered & on_local_cell
        ratio, gap, x = self.term.results.deepest(np.where(covered, state.gaps, -np.inf))
        if self.term.options.self_contact:
            refuse_a_self_overlap(ratio, gap, x, is_global(self.term.options.kind))
        if ratio > DEEP_PENETRATION:
            hint = ""
            options = self.term.options
            if (self.term.master is not None and options.kind in DUAL_KINDS
                    and not options.boundary_modification):
                # the dual functions are negative near the far node of a facet:
                # a facet covered only there by the master "sees" a penetration
                hint = ("; or, with a dual kind against an elastic master, a slave facet only "
                        "partly covered by the master (at the edge of the search radius or "
                        "of the master) shows a false penetration: pass "
                        "boundary_modification=True")
            warn(f"the initial configuration penetrates by {gap:.3g} ({ratio:.3g} "
                 f"slave element lengths) at the slave node {x}: check the "
                 "obstacle's position and normal, or the tags of slave and master"
                 + hint, self.term.comm)

    def warn_if_the_penalty_is_low(self, deepest: tuple[float, float, list]) -> None:
        """Warn when the deepest :meth:`penetration` of a solve exceeds
        PENALTY_PENETRATION slave element lengths, naming the penalty and one
        that would bring it to SUGGESTED_PENETRATION.

        The penetration falls about as 1/ε, exactly so under a prescribed
        force. A penalty 1000 times too low penetrated by 5.5% of an element
        without a word.

        A load-path driver calls it at the end of a solve, and
        :meth:`warn_if_the_body_passed_through` for the nodes off the slave
        surface, which this check, on the slave nodes' ``p_A/ε``, does not see.
        """
        ratio, depth, x = deepest
        if ratio <= PENALTY_PENETRATION:
            return
        penalty = self.term.options.penalty
        suggested = penalty * ratio / SUGGESTED_PENETRATION
        warn(f"at convergence the slave surface penetrates by {depth:.3g} "
             f"({ratio:.2g} slave element lengths) at the node {x}: the penalty "
             f"{penalty:.3g} is low for this mesh; about {suggested:.3g} would "
             f"bring the penetration to {SUGGESTED_PENETRATION:g} element lengths "
             "(it falls about as 1/penalty)", self.term.comm)

    def warn_if_the_body_passed_through(self) -> None:
        """Log a warning (once, collective) when at the present u a node off the
        slave surface has passed through the rigid obstacle by more than
        BODY_PENETRATION lengths of its cells
        (:func:`body_penetration`).

        A cylinder on a rigid plane under 1000× its Hertz load, in small-strain
        elasticity, converged with the top of the cylinder 3.4 radii through
        the plane and no word: the penalty check saw only the slave nodes,
        held 0.005 elements deep.
        """
        if self._body_warned:
            return
        ratio, depth, x = body_penetration(self.term)
        if ratio <= BODY_PENETRATION:
            return
        self._body_warned = True
        held, _, _ = self.term.results.penetration()
        if self.term.comm.rank == 0:
            where = ", ".join(f"{c:.4g}" for c in x)
            logger.warning(
                "at convergence a node off the slave surface has passed through the obstacle "
                "by %.3g (%.3g lengths of its cells; reference point (%s)), while the slave "
                "surface's nodes penetrate by at most %.2g element lengths: the body has "
                "folded past its own slave surface (cells turned inside out under a load far "
                "beyond a small-strain model's range), or the slave surface does not cover "
                "all of the body that meets the obstacle. Check the load and the slave tag; "
                "with a large-deformation material take more load steps; where the slave "
                "surface itself sinks in, a larger penalty (now %.3g)",
                depth, ratio, where, max(held, 0.0), self.term.options.penalty)

    def warn_if_slipped_too_far(self, state: Optional[ContactState] = None) -> None:
        """With ``basis_configuration="initial"``: warn (once) past SLIP_LIMIT
        element lengths of slip (:meth:`slip`). A press-then-slide run gave a
        normal force growing 3× and a frictionless tangential force of 33% of
        it without a word. Against a rigid obstacle the gap is exact in u
        whatever the slip (no segmentation is frozen): no warning."""
        if (not self.configuration.pairs_found_once or self.term.obstacle is not None
                or self._slip_warned):
            return
        s = self.term.results.slip(state)
        if s > SLIP_LIMIT:
            self._slip_warned = True
            warn(f"contact surfaces slipped {s:.3g} element lengths past the "
                 "configuration of the bases (basis_configuration='initial', valid "
                 "to about one element of slip): the forces are no longer reliable; "
                 "use basis_configuration='previous' or 'current'",
                 self.term.comm)

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
        if self.term.master is None or self.term.options.self_contact:
            return  # self-contact starting apart is the usual case (MissedContact pairs it later)
        comm = self.term.comm
        radius = self.term.options.search_radius
        if coupling is None:        # the current surface: one segmentation for this check
            coupling = MortarCoupling(self.term.slave, self.term.master, search_radius=radius)
        if comm.allreduce(len(coupling.pairs)) > 0:
            return
        radius = coupling.search_radius
        either_way = MortarCoupling(self.term.slave, self.term.master, search_radius=radius,
                                    opposing_normals_only=False)
        if comm.allreduce(len(either_way.pairs)) > 0:
            warn(f"the master surface faces away from the slave: within the search "
                 f"radius {radius:.3g} the slave facets find only master facets "
                 "whose outward normals point the same way as theirs, and those "
                 "are never paired. The master must be the surface of the other "
                 "body that faces the slave: check the master_tag, and that "
                 "slave and master tags are not swapped", comm)
            return
        never = (" With basis_configuration='initial' the pairs are found only here, so "
                 "it never will." if self.configuration.pairs_found_once else "")
        warn(f"no slave facet finds a master facet within the search radius "
             f"{radius:.3g} along its normal: the contact cannot act until the "
             f"surfaces come within it.{never} Check the slave and master tags and "
             "the bodies' positions, or pass a larger search_radius", comm)

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
        if self.term.master is None or self.configuration.follows_u:
            return False
        model, slave = self.term.source, self.term.slave
        comm = self.term.comm
        state = state or self.term.evaluate()
        covered = state.covered
        cells = slave.cells
        # p is ε⟨d̄⟩: exactly 0 off the active set
        active = self.term.results.nodal_pressures(state) > 0
        at_edge = (active[cells].any(axis=1) & ~covered[cells].all(axis=1)
                   if len(cells) else np.zeros(0, dtype=bool))
        if not comm.allreduce(bool(at_edge.any()), op=MPI.LOR):
            return False
        coupling = model.coupling
        cached = self._beyond_radius
        if cached is None or cached[0] is not coupling:
            # one wider segmentation per frozen configuration, not one per step; paired
            # as the term pairs (its normals, a self-contact surface without its neighbours)
            wider = MortarCoupling(coupling.slave, coupling.master,
                                   search_radius=4 * coupling.search_radius,
                                   **pairing_options(self.term.options))
            cached = (coupling, slave.layout.on_cells(slave.cells[wider.pairs[:, 0]]))
            self._beyond_radius = cached
        reached = cached[1] & ~covered
        near_edge = np.zeros(slave.layout.size_local, dtype=bool)
        near_edge[cells[at_edge].ravel()] = True
        return bool(comm.allreduce(bool(np.any(reached & near_edge)), op=MPI.LOR))

    def wider_search_radius(self, state: Optional[ContactState] = None) -> Optional[float]:
        """After a converged step: the search radius the term's bases need, None
        where the present one serves: where the contact zone reached the radius
        (:meth:`radius_reached`) or where slave nodes passed through the master
        outside the pairs (:class:`~dolfinx_mortar.contact.checks.missed_contact.MissedContact`;
        collective)."""
        state = state or self.term.evaluate()
        # contact the pairs missed first: it overrides even a radius the user gave
        radius = self.missed.wider_radius(state)
        return radius if radius is not None else self.radius_reached(state)

    def radius_reached(self, state: Optional[ContactState] = None) -> Optional[float]:
        """After a converged step: where the contact zone reached slave nodes
        that found no master within the search radius though one lies beyond it
        (:meth:`contact_reached_the_search_radius`), four times the radius, for
        the term to rebuild its bases with (the step must be solved again, with
        a new matrix pattern); None otherwise. A radius the user gave is kept,
        with a warning; so is one already widened MAX_RADIUS_WIDENINGS times
        (collective)."""
        if self._radius_warned or not self.contact_reached_the_search_radius(state):
            return None
        term = self.term
        radius = term.source.coupling.search_radius
        widenings = self._radius_widenings
        if term.options.search_radius is None or widenings > 0:
            if widenings < MAX_RADIUS_WIDENINGS:
                self._radius_widenings = widenings + 1
                if term.comm.rank == 0:
                    logger.info("the contact zone reached slave nodes with no master within "
                                "the search radius %.3g: bases rebuilt with %.3g, step "
                                "solved again", radius, 4 * radius)
                return 4 * radius
        self._radius_warned = True
        warn(f"the contact zone reached slave nodes that found no master within "
             f"the search radius {radius:.3g}, though a master lies beyond it: the "
             f"pressure is cut off there. Pass a larger search_radius (e.g. "
             f"{4 * radius:.3g}) or basis_configuration='previous'",
             term.comm)
        return None
