"""Contact that the pairs missed: slave nodes that passed through the master
while the term saw nothing there (issue 37).

Against an elastic master the pairs are searched within a radius of the slave
facets, in the configuration the bases are built in (the reference one with
``basis_configuration="initial"``, where a step starts with ``"previous"``).
Two faces that start further apart than that radius were never paired: the
contact force stayed exactly 0 and the bodies passed through each other
without a word. After each converged step the surfaces are therefore searched
again in the current geometry, with a radius that covers their motion since
the bases were built (where the surfaces moved by less than half the radius
relative to each other, nothing can have been missed, and nothing is searched);
a slave node that lies behind the master by more than
:data:`MISSED_DEPTH` of its element length while the term carries no pressure
there is contact the pairs missed. The term then rebuilds its bases with a
radius that covers the motion and the step is solved again (logged).

On the current surface (``"current"``) the pairs are searched again at every
evaluation, but each slave facet only reaches two of its own diameters: a load
step that drives the surfaces through each other by more than that (a deep
prescribed press in one step) left the nodes behind the master unpaired, the
force exactly 0. The same check runs there with the motion since the last
accepted step and the smallest facet's reach; the term is rebuilt with one
radius that covers the motion.
"""
from __future__ import annotations

import logging
from typing import Optional

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.collective_warnings import warn
from dolfinx_mortar.contact.gap_sources import FACET_SEARCH_FACTOR
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.mortar.surface_exchange import facet_extents
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement
from dolfinx_mortar.tolerance import NEAR_CONTACT

logger = logging.getLogger("dolfinx_mortar.contact.checks")

#: a slave node this many of its element lengths behind the master, where the term carries
#: no pressure, is contact the pairs missed (a node at the edge of the contact zone lies
#: behind the master by round-off and the linearization of frozen bases only)
MISSED_DEPTH = NEAR_CONTACT
#: times the radius is widened for missed contact before the check only warns
MAX_MISSED_WIDENINGS = 4


class MissedContact:
    """The check of one contact term against an elastic master (see the module).

    Parameters
    ----------
    term
        The contact term (:class:`~dolfinx_mortar.contact.term.ContactTerm`).
    configuration
        Its configuration: where its bases were built.
    """

    def __init__(self, term, configuration):
        self.term, self.configuration = term, configuration
        #: the radius the user gave (None: the default), which a widening overrides loudly
        self.given_radius = term.options.search_radius
        self.widenings = 0
        self._warned = False
        #: the radius of the first search (about an element where none was given), below
        #: whose half a node's motion cannot have taken it past the pairs
        self._first_radius: Optional[float] = None
        #: on the current surface: the displacement of the last accepted step
        #: (None: the start), from which a step's motion is measured
        self._accepted: Optional[PETSc.Vec] = None

    def step_accepted(self) -> None:
        """The present u is an accepted step (on the current surface, where the
        next step's motion is measured from)."""
        if self.configuration.follows_u:
            if self._accepted is None:
                self._accepted = self.term.u.x.petsc_vec.copy()
            else:
                self.term.u.x.petsc_vec.copy(self._accepted)

    def motion(self) -> float:
        """The largest displacement of a slave or master node since the pairs
        were searched (since the bases were built; on the current surface, since
        the last accepted step), over all ranks (0 with nothing to compare)."""
        term = self.term
        built = (self._accepted if self.configuration.follows_u
                 else self.configuration.built_vector)
        if built is None:
            relative = term.u
        else:
            relative = fem.Function(term.u.function_space)
            relative.x.petsc_vec.waxpy(-1.0, built, term.u.x.petsc_vec)
            relative.x.scatter_forward()
        local = max(float(np.max(np.abs(nodal_displacement(surface, relative)), initial=0.0))
                    for surface in (term.slave, term.master))
        return term.comm.allreduce(local, op=MPI.MAX)

    def missed(self, state: ContactState, radius: float) -> tuple[int, tuple[float, float, list]]:
        """The slave nodes behind the master in the current geometry, searched
        within ``radius``, where the term carries no pressure: their number
        and the deepest (in element lengths, as a length, where; collective)."""
        term = self.term
        moved = [nodal_displacement(surface, term.u) for surface in (term.slave, term.master)]
        probe = MortarCoupling(term.slave, term.master, *moved, search_radius=radius,
                               self_contact=term.options.self_contact, deal_segmentation=True)
        gap = probe.operators("LmLS*").nodal_gap()          # ∫N_A d over the covered part
        covered = probe.covered_element_mass()[2]           # ∫_cov N_A
        depth = np.full(len(covered), -np.inf)
        np.divide(gap, covered, out=depth, where=covered > 0)
        carried = term.results.nodal_pressures(state) > 0
        lengths = term.results.node_lengths()
        missed = (depth > MISSED_DEPTH * lengths) & ~carried
        n = term.slave.layout.num_owned
        count = term.comm.allreduce(int(np.sum(missed[:n])))
        return count, term.results.deepest(np.where(missed, depth, -np.inf))

    def _missed_for_good(self, count: int, ratio: float, depth: float, where: list,
                         futile: bool) -> str:
        """The warning where wider searches do not pair what was missed."""
        what = (f"{count} slave node(s) passed through the master outside the pairs "
                f"(deepest {depth:.3g}, {ratio:.3g} element lengths, at {where})")
        if not futile:
            return (f"{what} after {self.widenings} wider searches: the contact misses "
                    "them. Pass a larger search_radius or smaller load steps")
        configuration = self.term.options.basis_configuration
        advice = ("smaller load steps" if configuration == "current" else
                  "basis_configuration='current', or smaller load steps" if
                  configuration == "previous" else
                  "basis_configuration='previous' or 'current'")
        return (f"{what}, although the search radius covers their motion since the pairs "
                f"were searched: the pairs, projected along the normals of the "
                f"configuration the bases were built in ('{configuration}'), do not follow "
                f"a motion this large, and the contact misses them. Use {advice}")

    def searched_radius(self) -> float:
        """How far every slave facet surely looked for the master (collective):
        the frozen bases' search radius; on the current surface the radius given,
        or :data:`FACET_SEARCH_FACTOR` diameters of the smallest slave facet
        where it is now (each facet searches that many of its own)."""
        term = self.term
        coupling = (None if self.configuration.follows_u
                    else self.configuration.segmentation(term.source))
        if coupling is not None:
            return coupling.search_radius
        if term.options.search_radius is not None:
            return term.options.search_radius
        slave = term.slave
        extents = facet_extents(slave, slave.x + nodal_displacement(slave, term.u))
        local = float(np.min(extents, initial=np.inf))
        return FACET_SEARCH_FACTOR * term.comm.allreduce(local, op=MPI.MIN)

    def wider_radius(self, state: ContactState) -> Optional[float]:
        """After a converged step: the search radius the bases need where
        contact was missed (:meth:`missed`), None where none was (collective)."""
        term = self.term
        if term.master is None or self._warned:
            return None
        radius = self.searched_radius()
        if self._first_radius is None:
            self._first_radius = radius
        motion = self.motion()
        if 2.0 * motion <= min(radius, self._first_radius):
            # no slave node can have reached a master facet that lay beyond the
            # radius when the pairs were searched, nor moved far from where the
            # pairs project it: nothing to search again. A widened radius alone
            # is not enough: it holds the facets the motion reaches, not the
            # pairs the projection makes there (the tube's hole in "initial":
            # radius 1.96 against a motion of 0.96, no pair across the hole)
            return None
        reach = radius + 2.0 * motion
        count, (ratio, depth, where) = self.missed(state, reach)
        if count == 0:
            return None
        futile = radius >= 2.0 * motion
        if futile or self.widenings >= MAX_MISSED_WIDENINGS:
            self._warned = True
            warn(self._missed_for_good(count, ratio, depth, where, futile), term.comm)
            return None
        self.widenings += 1
        wider = max(4.0 * radius, reach)
        if self.widenings == 1 and self.given_radius is not None:
            warn(f"the search radius {self.given_radius:.3g} that was given missed "
                 f"contact: {count} slave node(s) passed through the master outside "
                 f"the pairs (deepest {depth:.3g} at {where}); the bases are rebuilt "
                 f"with {wider:.3g} and the step solved again",
                 term.comm)
        if term.comm.rank == 0:
            logger.info("%d slave node(s) passed through the master outside the pairs "
                        "(deepest %.3g, %.3g element lengths, at %s): bases rebuilt with the "
                        "search radius %.3g (was %.3g), step solved again", count, depth,
                        ratio, where, wider, radius)
        return wider
