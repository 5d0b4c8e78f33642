"""Where a contact term's bases and segmentation live, and when they move.

One object per configuration (docs/DESIGN.md, §Configurations) answers every
question that depends on it, so that nothing after construction asks the
configuration's name:

- :class:`InitialConfiguration`: bases and pairs frozen in the reference
  configuration, built once;
- :class:`PreviousConfiguration`: frozen in the configuration of the last
  converged step, rebuilt when a load step starts;
- :class:`CurrentConfiguration`: on the current surfaces at every evaluation,
  with the exact Jacobian; a load step is solved first on the surface frozen
  where it starts (the "previous" model), then on the current one.

A configuration builds the gap model (:mod:`~dolfinx_mortar.contact.gap_sources.choice`
chooses the gap source), says what happens when a step starts, and how the
contact stiffness enters the Newton matrix.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
import numpy.typing as npt
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.gap_sources.choice import (current_model, frozen_model, moved,
                                           refuse_false_penetration)
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.options import ContactOptions
from dolfinx_mortar.linalg.sparse_products import PatternTrackingAdd
from dolfinx_mortar.contact.gap_sources.source import GapSource
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.surfaces.facet_surface import nodal_displacement
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

FloatArray = npt.NDArray[np.float64]


class InitialConfiguration:
    """Bases and segmentation frozen in the reference configuration, built once.

    Good up to about one element of slip (the term warns past it); against a
    rigid obstacle the gap stays exact in u whatever the slip.
    """

    name = "initial"
    #: whether the bases are built where u has moved the surfaces (not in the reference)
    built_at_u = False
    #: the bases follow u at every evaluation (a step is solved in two phases)
    follows_u = False
    #: the pairs are found once, where the term is made
    pairs_found_once = True
    #: the Newton matrix may gain entries between load steps
    pattern_grows = False

    def __init__(self, slave: LagrangeSurface, master: Optional[LagrangeSurface],
                 obstacle: Optional[RigidObstacle]):
        self.slave, self.master, self.obstacle = slave, master, obstacle
        #: the nodal displacement the frozen bases were built at, and the
        #: displacement vector they are linearized about (None: zero)
        self.built_at: Optional[FloatArray] = None
        self.built_vector: Optional[PETSc.Vec] = None
        #: adds K to the Newton matrix (in place where its entries are there)
        self._add = PatternTrackingAdd()

    def build(self, options: ContactOptions, u) -> GapSource:
        """The gap model where the term is made (u: the displacement Function)."""
        return self.rebuild(options, u)

    def rebuild(self, options: ContactOptions, u) -> GapSource:
        """The model again with new options (a widened search radius), in the
        configuration the bases were built in."""
        return frozen_model(options, self.slave, self.master, self.obstacle, self.built_at,
                            self.built_vector)

    def begin_step(self, options: ContactOptions, u) -> Optional[GapSource]:
        """A new model when a load step starts, or None to keep the present one."""
        return None

    def frozen_model(self, options: ContactOptions, u) -> Optional[GapSource]:
        """The model frozen at the present u for a step's first phase (None:
        the present model is frozen already)."""
        return None

    def segmentation(self, model: GapSource) -> Optional[MortarCoupling]:
        """A segmentation of this configuration already made, for the term's
        checks (None against an obstacle)."""
        return model.coupling

    def geometric_stiffness(self, active: FloatArray, comm: MPI.Comm) -> bool:
        """Whether the Jacobian takes the stiffness of the surface's geometry
        (frozen bases have none beyond an obstacle's curvature)."""
        return True

    def add_stiffness(self, A: PETSc.Mat, K: PETSc.Mat) -> bool:
        """``A += K``; returns whether A's nonzero pattern changed in a way PETSc
        does not see (the KSP must then be reset). The frozen configurations
        made A with every entry K can have, so theirs never changes."""
        return self._add(A, K)

    def new_matrix(self) -> None:
        """A new Newton matrix was made (its pattern holds every active set)."""
        self._add.reset()

    def forget(self) -> None:
        """The state of the last evaluation no longer applies (a new model)."""

    def check_current_surface(self, options: ContactOptions, model: GapSource, u) -> None:
        """A frozen phase converged (only the current configuration has one)."""



class PreviousConfiguration(InitialConfiguration):
    """Bases and segmentation frozen in the configuration of the last converged
    step: rebuilt when a load step starts if u moved since."""

    name = "previous"
    built_at_u = True
    pairs_found_once = False
    pattern_grows = True

    def begin_step(self, options: ContactOptions, u) -> Optional[GapSource]:
        u_nodes = nodal_displacement(self.slave, u)
        if not moved(u_nodes, self.built_at, self.slave.layout.comm):
            return None
        self.built_at, self.built_vector = u_nodes.copy(), u.x.petsc_vec.copy()
        return self.rebuild(options, u)


class CurrentConfiguration(InitialConfiguration):
    """Bases and segmentation on the current surfaces at every evaluation, with
    the exact Jacobian (local kinds).

    Far from the solution the pressure on the current surface can be many
    times its final value, and so its geometric stiffness: full Newton steps
    then cycled between active sets (Hertz 2D). While the active set moves
    the frozen-surface part alone gives the step; once it settles the exact
    Jacobian converges quadratically (:meth:`geometric_stiffness`).
    """

    name = "current"
    built_at_u = True
    follows_u = True
    pairs_found_once = False
    pattern_grows = True

    def __init__(self, slave: LagrangeSurface, master: Optional[LagrangeSurface],
                 obstacle: Optional[RigidObstacle]):
        super().__init__(slave, master, obstacle)
        self._last_active: Optional[FloatArray] = None
        self._checked: Optional[MortarCoupling] = None

    def build(self, options: ContactOptions, u) -> GapSource:
        model = current_model(options, self.slave, self.master, self.obstacle)
        self._checked = refuse_false_penetration(options, self.slave, self.master, model, u,
                                                 nodal_displacement(self.slave, u))
        return model

    def rebuild(self, options: ContactOptions, u) -> GapSource:
        return current_model(options, self.slave, self.master, self.obstacle)

    def frozen_model(self, options: ContactOptions, u) -> Optional[GapSource]:
        return frozen_model(options.frozen_phase(), self.slave, self.master, self.obstacle,
                            nodal_displacement(self.slave, u), u.x.petsc_vec.copy())

    def check_current_surface(self, options: ContactOptions, model: GapSource, u) -> None:
        """At the end of a load step's frozen phase, before the current surface
        takes over: refuse a dual kind that reads a penetration the frozen model
        does not (NotImplementedError). The check where the term is made sees
        only where the surfaces start; a collapsing tube's faces met 15 steps
        later, the current surface read 2.6 element lengths of false
        penetration there, and Newton diverged to NaN without a word why."""
        refuse_false_penetration(options, self.slave, self.master, model, u,
                                 nodal_displacement(self.slave, u), in_contact=True)

    def segmentation(self, model: GapSource) -> Optional[MortarCoupling]:
        return self._checked

    def geometric_stiffness(self, active: FloatArray, comm: MPI.Comm) -> bool:
        settled = comm.allreduce(bool(self._last_active is not None
                                      and np.array_equal(active, self._last_active)),
                                 op=MPI.LAND)
        self._last_active = active
        return settled

    def forget(self) -> None:
        self._last_active = None


CONFIGURATION_CLASSES = {c.name: c for c in (InitialConfiguration, PreviousConfiguration,
                                             CurrentConfiguration)}


def configuration_of(options: ContactOptions, slave: LagrangeSurface,
                     master: Optional[LagrangeSurface],
                     obstacle: Optional[RigidObstacle]) -> InitialConfiguration:
    """The configuration object of checked options."""
    return CONFIGURATION_CLASSES[options.basis_configuration](slave, master, obstacle)
