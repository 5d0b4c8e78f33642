"""Penalty mortar contact as a term of the user's own DOLFINx model.

:class:`ContactTerm` adds the contact residual and Jacobian of one slave
surface (against an elastic master in the same mesh or a rigid analytic
obstacle) to PETSc vectors and matrices that already hold the user's bulk
forms — in the style of :mod:`dolfinx.fem.petsc`::

    contact = ContactTerm(u, facet_tags, slave_tag=3, obstacle=RigidPlane(...),
                          kind="LcLS*", penalty=1e3 * E / h)
    A = contact.create_matrix(fem.form(J))       # bulk ∪ contact pattern
    ...
    contact.assemble_residual(b, bcs)            # b += R_c(u)
    contact.assemble_jacobian(A, bcs)            # A += K_c(u)

:class:`~dolfinx_mortar.solver.nonlinear_problem.NonlinearContactProblem`
does exactly this around the user's residual form.
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import replace
from typing import Iterator, Optional, Sequence

import numpy as np
import numpy.typing as npt
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.checks import (RangeChecks, check_initial_overlap,
                                           check_penalty_represents_a_force,
                                           warn_if_the_obstacle_faces_away)
from dolfinx_mortar.contact.friction import Friction
from dolfinx_mortar.contact.gap_sources import ContactState, GapSource, configuration_of
from dolfinx_mortar.contact.laws import TangentialLaw, check_tangential_law
from dolfinx_mortar.contact.newton import (JacobianAssembly, NearContactStiffness, NewtonTraits,
                                           entry_of, gap_closing_force)
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.options import ContactOptions
from dolfinx_mortar.contact.results import ContactResults
from dolfinx_mortar.dolfinx_compat import ghosted_vector
from dolfinx_mortar.input_checks import (check_cells, check_contact_arguments,
                                         check_contact_tags, collective_checks,
                                         communicator_of)
from dolfinx_mortar.io.contact_output import check_term_name
from dolfinx_mortar.kinds import KindLike
from dolfinx_mortar.surfaces.facet_surface import facet_surface

FloatArray = npt.NDArray[np.float64]


class ContactTerm:
    """The penalty mortar contact term of one slave surface.

    Parameters
    ----------
    u
        The displacement, a vector Lagrange Function of degree 1 or 2 (the
        unknown of the user's model).
    facet_tags
        Facet meshtags of u's mesh.
    slave_tag
        Tag of the slave facets.
    master_tag
        Tag of the master facets in the same mesh (two bodies), or None.
    obstacle
        A rigid analytic obstacle instead of a master surface
        (:mod:`dolfinx_mortar.contact.obstacles.analytic`); it may be moved between
        load steps (``obstacle.move_to``).
    kind
        Mortar basis kind, any of the six (docs/DESIGN.md, §Bases).
    penalty
        ε, pressure per length (consistent scaling).
    scaling
        ``"consistent"`` (default) or ``"seed"`` (docs/DESIGN.md, §Scalings).
    active_set
        ``"nodal"`` (default, penalty on ⟨d̄_A⟩) or ``"pointwise"``
        (``p_A = ε∫M̄_A⟨d⟩``, unsymmetric exact Jacobian).
    basis_configuration
        ``"initial"`` (default): bases and segmentation in the reference
        configuration, good up to about one element of slip;
        ``"previous"``: rebuilt when a load step starts (:meth:`begin_step`);
        ``"current"``: on the current surfaces at every evaluation, with the
        exact linearization (local kinds).
    quadratic_transform
        Transformed basis on quadratic triangle facets (always on axisymmetric
        P2 lines, see ``axisymmetric``).
    boundary_modification
        Elastic master, dual kinds: the basis rebuilt over the covered part of
        partly covered slave facets (Popp et al. 2013). ``None`` (default):
        on for the dual kinds against an elastic master with the nodal active
        set in the "initial" and "previous" configurations, where it is
        implemented. Without it, a slave facet that the master covers only
        near its far node reads a separation as a penetration (the dual
        functions are negative there).
    search_radius
        How far along its normal a slave facet reaches for master facets to
        pair with (default the largest slave facet diameter).
    axisymmetric
        The mesh is the (r, z) half-plane r ≥ 0 of a body of revolution (x the
        radius, y the axis): every contact integral carries 2πr, so that
        forces are those on the whole body (docs/AXISYMMETRIC.md). The user's bulk form
        must be axisymmetric too
        (:func:`~dolfinx_mortar.small_strain.elastic.axisymmetric_elastic_residual`).
    friction
        A friction law: Coulomb friction
        (:class:`~dolfinx_mortar.contact.laws.CoulombFriction`: μ and the
        tangential penalty) or any :class:`~dolfinx_mortar.contact.laws.TangentialLaw`;
        None: frictionless (default). Its
        history moves on in :meth:`accept_step` (docs/FRICTION.md).
    name
        The term's name, which names its output file ``<output>_<name>.xdmf``
        (letters, digits, ``_``, ``-``). None (default): ``<output>_slave.xdmf``
        when it is a problem's only term, ``<output>_slave<slave_tag>.xdmf``
        among several (:mod:`dolfinx_mortar.io.contact_output`).
    """

    def __init__(self, u: fem.Function, facet_tags, slave_tag: int, *,
                 master_tag: Optional[int] = None, obstacle: Optional[RigidObstacle] = None,
                 kind: KindLike = "LcLS*", penalty: float, scaling: str = "consistent",
                 active_set: str = "nodal", basis_configuration: str = "initial",
                 quadratic_transform: bool = False,
                 boundary_modification: Optional[bool] = None,
                 search_radius: Optional[float] = None, axisymmetric: bool = False,
                 friction: Optional[TangentialLaw] = None, name: Optional[str] = None):
        # one decision of all ranks: an argument bad on one rank only raises on every rank
        with collective_checks(communicator_of(u)):
            check_contact_arguments(u, master_tag, obstacle, axisymmetric)
            #: the name of the term's output (None: from the slave tag)
            self.name: Optional[str] = check_term_name(name)
            check_tangential_law(friction)
            options = ContactOptions.checked(kind, penalty, scaling, active_set,
                                             basis_configuration, boundary_modification,
                                             search_radius, master_tag is not None,
                                             axisymmetric)
        V = u.function_space
        check_cells(V.mesh)
        check_contact_tags(V.mesh, facet_tags, slave_tag, master_tag)
        #: the slave facets' tag
        self.slave_tag = int(slave_tag)
        #: the displacement
        self.u = u
        self._V = V
        #: the rigid obstacle (None: an elastic master)
        self.obstacle = obstacle
        #: the slave surface (its nodes, cells and their layout over the ranks)
        self.slave = facet_surface(V, facet_tags, slave_tag, quadratic_transform, axisymmetric)
        #: the master surface (None against an obstacle)
        self.master = (facet_surface(V, facet_tags, master_tag, axisymmetric=axisymmetric)
                       if master_tag is not None else None)
        check_penalty_represents_a_force(options.penalty, self.slave, self.comm)
        #: the checked options (kind, penalty law, configuration, …)
        self.options = options
        self._configuration = configuration_of(options, self.slave, self.master, obstacle)
        self._entry = entry_of(options.kind, self.comm, V.dofmap.index_map_bs)
        #: wall times of the contact work by part, seconds (accumulated)
        self.timings: dict[str, float] = {}
        self._state: Optional[ContactState] = None
        self._masks: dict = {}
        #: what the term reports (pressures, forces, slip, …)
        self.results = ContactResults(self)
        self._checks = RangeChecks(self, self._configuration)
        #: Coulomb friction and its history (None: frictionless)
        self.friction: Optional[Friction] = (None if friction is None else
                                             Friction(friction, options, u, self.slave, obstacle))
        self._near_contact = NearContactStiffness()
        #: the gap source (:class:`~dolfinx_mortar.contact.gap_sources.GapSource`)
        self.source: GapSource = self._timed_build(self._configuration.build, options)
        self._checks.warn_deep_initial_penetration()
        if obstacle is not None:
            warn_if_the_obstacle_faces_away(obstacle, self.slave, self.comm)
        coupling = self._configuration.segmentation(self.source)
        check_initial_overlap(self, coupling, self._configuration.built_at_u)
        self._checks.warn_if_no_master_is_in_reach(coupling)

    @property
    def comm(self) -> MPI.Comm:
        """The mesh's communicator."""
        return self._V.mesh.comm

    @property
    def basis_configuration(self) -> str:
        """``"initial"``, ``"previous"`` or ``"current"``."""
        return self._configuration.name

    @property
    def traits(self) -> NewtonTraits:
        """What a Newton solver needs to know of this term (:class:`NewtonTraits`)."""
        follows_u = self._configuration.follows_u
        return NewtonTraits(
            symmetric=not (self.options.law.pointwise or follows_u or self.friction is not None),
            moving_pattern=self.source.moving_pattern, follows_u=follows_u,
            takes_the_linear_solve=self._entry.takes_the_linear_solve,
            frictional=self.friction is not None)

    @property
    def state(self) -> Optional[ContactState]:
        """The contact state of the last :meth:`update` (None: none since the
        gap source was made)."""
        return self._state

    # -- the gap source through a load path ------------------------------------------
    def _timed_build(self, build, options: ContactOptions) -> Optional[GapSource]:
        """``build(options, u)``; where it makes a new source (not None), the
        state of the old one is dropped."""
        clock = time.perf_counter()
        source = build(options, self.u)
        if source is not None:
            self._state = None
            self._configuration.forget()
            self.timings["setup"] = time.perf_counter() - clock
        return source

    def begin_step(self) -> bool:
        """Called by a load-path driver when a load step starts.

        With ``basis_configuration="previous"`` the bases (and segmentation)
        are rebuilt in the configuration of the last converged step if u moved
        since they were built; returns True then (the contact pattern may have
        changed: :meth:`create_matrix` again).
        """
        self._near_contact.reset()
        source = self._timed_build(self._configuration.begin_step, self.options)
        if source is None:
            return False
        self.source = source
        return True

    def rebuild(self, search_radius: float) -> None:
        """The bases and segmentation made again with another search radius, in
        the configuration they were built in."""
        self.options = replace(self.options, search_radius=search_radius)
        self.source = self._timed_build(self._configuration.rebuild, self.options)

    @contextmanager
    def frozen(self) -> Iterator[None]:
        """With ``basis_configuration="current"``: the source frozen at the present u
        (the "previous" one) inside the block. A load-path driver solves each
        step with it first; other configurations are unchanged."""
        frozen = self._configuration.frozen_model(self.options, self.u)
        if frozen is None:
            yield
            return
        current, self.source = self.source, frozen
        try:
            yield
        finally:
            self.source, self._state = current, None
            self._configuration.forget()

    def widen_search_radius(self, state: Optional[ContactState] = None) -> bool:
        """Called by a load-path driver after a converged step, before
        :meth:`accept_step`: where the contact zone reached the default search
        radius, the bases are rebuilt with a wider one and True is returned
        (the step must be solved again, with :meth:`create_matrix` again;
        :meth:`RangeChecks.widen_search_radius
        <dolfinx_mortar.contact.checks.RangeChecks.widen_search_radius>`; collective)."""
        return self._checks.widen_search_radius(state)

    def accept_step(self, state: Optional[ContactState] = None) -> None:
        """The present u is a converged load step: friction's history (the
        tangential forces, the step's dissipation) moves on to it, and the slip
        is checked. A load-path driver calls it once per accepted step, never
        after a failed one, so that a cut-back retries from the same history."""
        state = state or self.evaluate()
        if self.friction is not None:
            self.friction.accept(state.friction, self.u)
        self._checks.warn_if_slipped_too_far(state)

    def check_path(self, deepest: tuple[float, float, list]) -> None:
        """Called when a load path ends: warn if the penalty let the bodies
        penetrate too deep (``deepest``: the path's deepest penetration,
        :meth:`ContactResults.penetration
        <dolfinx_mortar.contact.results.ContactResults.penetration>`) or a body
        passed through a rigid obstacle (each warned once; collective)."""
        self._checks.warn_if_the_penalty_is_low(deepest)
        self._checks.warn_if_the_body_passed_through()

    # -- evaluation ------------------------------------------------------------------
    def evaluate(self) -> ContactState:
        """The contact state at the present u with every dof kept (results)."""
        self.u.x.scatter_forward()
        return self._with_friction(self.source.evaluate(self.u, None), None)

    def _with_friction(self, state: ContactState, mask: Optional[PETSc.Vec]) -> ContactState:
        """The state with friction's forces in its residual (as it is without friction)."""
        if self.friction is None:
            return state
        if mask is None and self.friction.at_accepted_step(self.u):
            # a result at a converged step: its own return mapping, not one
            # with its forces already made history
            friction = self.friction.history.accepted
        else:
            friction = self.friction.evaluate(self.source, state, self.u,
                                              self._near_contact.mask(self.source, state), mask)
        state.residual.axpy(1.0, friction.residual)
        state.friction = friction
        return state

    def update(self, bcs: Sequence = ()) -> ContactState:
        """The contact state at the present values of u (ghosts updated here),
        with the Dirichlet columns of ``bcs`` dropped."""
        clock = time.perf_counter()
        self.u.x.scatter_forward()
        self._state = None
        # petsc4py defers the destruction of a parallel PETSc object whose
        # Python handle dies to a collective garbage_cleanup, which nothing
        # else calls: the matrices of each evaluation piled up (ironing 3D at
        # 2k dofs grew by 15 MB/s to over 5 GB with PETSc 3.18; a small block
        # on 2 ranks of 3.22 by 0.5 MB per evaluation). An evaluation is
        # collective, so every rank reaches this point together.
        PETSc.garbage_cleanup(self.comm)
        mask = self._mask(bcs)
        self._state = self._with_friction(self.source.evaluate(self.u, mask), mask)
        self._add("residual", clock)
        return self._state

    # -- PETSc assembly --------------------------------------------------------------
    def _mask(self, bcs: Sequence[fem.DirichletBC] = ()) -> PETSc.Vec:
        """1 on free dofs, 0 on the dofs of ``bcs`` (the contact terms skip those)."""
        key = tuple(id(bc) for bc in bcs)
        if key not in self._masks:
            m = ghosted_vector(self._V.dofmap.index_map, self._V.dofmap.index_map_bs)
            m.set(1.0)
            fem_petsc.set_bc(m, list(bcs), alpha=0.0)
            self._masks[key] = m
        return self._masks[key]

    def assemble_residual(self, b: PETSc.Vec, bcs: Sequence = ()) -> None:
        """``b += R_c(u)`` on the owned entries (R_c = 0 on the dofs of ``bcs``).

        Evaluates the contact state at u (:meth:`update`); call it before
        :meth:`assemble_jacobian`, as Newton does.
        """
        b.axpy(1.0, self.update(bcs).residual)

    def assemble_jacobian(self, A: PETSc.Mat, bcs: Sequence = ()) -> JacobianAssembly:
        """``A += K_c`` at the state of the last :meth:`update` (A assembled after).

        GLS kinds: A is left as it is (the bulk) and the exact Newton step of
        the augmented system is prepared instead (:meth:`configure_ksp`).
        Returns what a solver may need of it (:class:`JacobianAssembly`).
        """
        if self._state is None:
            self.update(bcs)
        clock = time.perf_counter()
        state = self._state
        changed = self._entry.assemble(A, self.source, state,
                                       self._near_contact.mask(self.source, state),
                                       self._mask(bcs), self._configuration, self.friction)
        if self._entry.step is not None:
            self.timings["augmented_factorization"] = self._entry.step.factorization_time
        self._add("jacobian", clock)
        return JacobianAssembly(changed, self._entry.stiffened_rows)

    def configure_ksp(self, ksp: PETSc.KSP) -> None:
        """Make ``ksp`` apply the exact Newton step (GLS kinds: the augmented
        system, a python PC; other kinds: nothing to do)."""
        self._entry.configure_ksp(ksp)

    def create_matrix(self, a: fem.Form, bcs: Sequence = ()) -> PETSc.Mat:
        """A matrix whose pattern holds the bilinear form ``a`` and the contact
        stiffness (of every active set), with ``a`` assembled in it."""
        A = fem_petsc.create_matrix(a)
        fem_petsc.assemble_matrix(A, a, list(bcs))
        A.assemble()
        self._entry.add_pattern(A, self.source, self._state or self.update(bcs), self.friction)
        self._configuration.new_matrix()
        if self.source.moving_pattern or self._configuration.pattern_grows:
            # the pairs, and so the pattern, change with u: new entries are
            # allocated as they come
            A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        return A

    # -- before anything touches -----------------------------------------------------
    def settle_near_contact(self, free_motions) -> None:
        """Called once per Newton Jacobian, before the contact is assembled.
        Where nothing touches yet and some node is near contact, decide
        whether those nodes need stiffness without force: only if one of the
        bodies' ``free_motions`` (a callable giving the rigid motions that
        the bulk does not resist, as dof vectors) changes their gaps
        (:class:`~dolfinx_mortar.contact.newton.NearContactStiffness`;
        collective)."""
        if self._state is not None and self._near_contact.due(self.source, self._state):
            self._near_contact.decide(self.source, self._state, free_motions())

    @contextmanager
    def closing_gaps(self) -> Iterator[Optional[PETSc.Vec]]:
        """The pull that closes the gaps near contact when nothing touches yet
        (:func:`~dolfinx_mortar.contact.newton.gap_closing_force`; None when
        something touches or nothing is near); inside the block the Jacobian
        stiffens the nodes near contact whatever holds the body: the
        gap-closing start's linear model."""
        self._near_contact.closing = True
        try:
            yield gap_closing_force(self.source, self._state)
        finally:
            self._near_contact.closing = False

    def _add(self, name: str, since: float) -> None:
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - since
