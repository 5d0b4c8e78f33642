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
from typing import ContextManager, Iterator, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.checks import RangeChecks, check_penalty_represents_a_force
from dolfinx_mortar.contact.friction import Friction
from dolfinx_mortar.contact.gap_sources import GapSource, configuration_of
from dolfinx_mortar.contact.state import ContactState
from dolfinx_mortar.contact.laws import TangentialLaw, check_tangential_law
from dolfinx_mortar.contact.newton import JacobianAssembly, NewtonTraits, TermAssembly
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.options import ContactOptions
from dolfinx_mortar.contact.results import ContactResults
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
    facet_tags, slave_tag
        Facet meshtags of u's mesh; the slave facets' tag, or a list of tags.
    master_tag
        Tag of the master facets in the same mesh, or None.
    obstacle
        A rigid obstacle (:mod:`dolfinx_mortar.contact.obstacles`) instead of a
        master surface; it may be moved between load steps (``obstacle.move_to``).
    kind
        Mortar basis kind, any of the six (docs/DESIGN.md, §Bases).
    penalty
        ε, pressure per length (consistent scaling).
    scaling, active_set
        ``"consistent"`` (default) or ``"seed"`` (docs/DESIGN.md, §Scalings); ``"nodal"``
        (default, ε on ⟨d̄_A⟩) or ``"pointwise"`` (``p_A = ε∫M̄_A⟨d⟩``).
    basis_configuration
        ``"initial"`` (default): bases and segmentation in the reference
        configuration, good up to about one element of slip; ``"previous"``:
        rebuilt when a load step starts (:meth:`begin_step`); ``"current"``: on
        the current surfaces, exactly linearized (local kinds).
    quadratic_transform
        Transformed basis on quadratic triangle facets (always on axisymmetric P2 lines).
    boundary_modification
        Elastic master, dual kinds: the basis rebuilt over the covered part of
        partly covered slave facets (docs/DESIGN.md, §Boundary modification).
        ``None`` (default): on wherever it is implemented.
    search_radius
        How far a slave facet reaches for master facets (default: the largest
        slave facet; widened where contact needs it).
    axisymmetric
        The mesh is the (r, z) half-plane of a body of revolution: contact
        integrals carry 2πr (docs/AXISYMMETRIC.md; the bulk form too).
    friction
        A friction law (:class:`~dolfinx_mortar.contact.laws.CoulombFriction`, or any
        :class:`~dolfinx_mortar.contact.laws.TangentialLaw`); None: frictionless.
    self_contact
        The slave surface is its own master: a body that may touch itself, or
        several bodies under one term (docs/SELF_CONTACT.md).
    name
        Names the term's output file ``<output>_<name>.xdmf`` (letters, digits,
        ``_``, ``-``); None: from the slave tag (:mod:`dolfinx_mortar.io.contact_output`).
    """

    def __init__(self, u: fem.Function, facet_tags, slave_tag: Union[int, Sequence[int]], *,
                 master_tag: Optional[int] = None, obstacle: Optional[RigidObstacle] = None,
                 kind: KindLike = "LcLS*", penalty: float, scaling: str = "consistent",
                 active_set: str = "nodal", basis_configuration: str = "initial",
                 quadratic_transform: bool = False,
                 boundary_modification: Optional[bool] = None,
                 search_radius: Optional[float] = None, axisymmetric: bool = False,
                 friction: Optional[TangentialLaw] = None, name: Optional[str] = None,
                 self_contact: bool = False):
        # one decision of all ranks: an argument bad on one rank only raises on every rank
        with collective_checks(communicator_of(u)):
            check_contact_arguments(u, master_tag, obstacle, axisymmetric, self_contact)
            check_tangential_law(friction)
            #: the name of the term's output (None: from the slave tag)
            self.name: Optional[str] = check_term_name(name)
            options = ContactOptions.checked(
                kind, penalty, scaling, active_set, basis_configuration,
                boundary_modification, search_radius, master_tag is not None or self_contact,
                axisymmetric, self_contact)
        V = u.function_space
        check_cells(V.mesh)
        check_contact_tags(V.mesh, facet_tags, slave_tag, master_tag)
        #: the slave facets' tag (or tags)
        self.slave_tag = int(slave_tag) if np.ndim(slave_tag) == 0 else tuple(map(int, slave_tag))
        #: the displacement
        self.u = u
        self._V = V
        #: the rigid obstacle (None: an elastic master)
        self.obstacle = obstacle
        #: the slave surface (its nodes, cells and their layout over the ranks)
        self.slave = facet_surface(V, facet_tags, slave_tag, quadratic_transform, axisymmetric)
        #: the master surface (None against an obstacle; the slave's own in self-contact)
        self.master = (self.slave if self_contact else None if master_tag is None
                       else facet_surface(V, facet_tags, master_tag, axisymmetric=axisymmetric))
        check_penalty_represents_a_force(options.penalty, self.slave, self.comm)
        #: the checked options (kind, penalty law, configuration, …)
        self.options = options
        self._configuration = configuration_of(options, self.slave, self.master, obstacle)
        self._newton = TermAssembly(V, options.kind, self._configuration)
        #: wall times of the contact work by part, seconds (accumulated)
        self.timings: dict[str, float] = {}
        #: what the term reports (pressures, forces, slip, …)
        self.results = ContactResults(self)
        self._checks = RangeChecks(self, self._configuration)
        #: Coulomb friction and its history (None: frictionless)
        self.friction: Optional[Friction] = (None if friction is None else
                                             Friction(friction, options, u, self.slave, obstacle))
        #: the gap source (:class:`~dolfinx_mortar.contact.gap_sources.GapSource`)
        self.source: GapSource
        clock = time.perf_counter()
        self._take(self._configuration.build(options, u), clock)
        self._checks.of_a_new_term()

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
        return self._newton.traits(self.options.law, self.source, self.friction is not None)

    @property
    def state(self) -> Optional[ContactState]:
        """The contact state of the last :meth:`update` (None: none since the source was made)."""
        return self._newton.state

    # -- the gap source through a load path ------------------------------------------
    def _take(self, source: Optional[GapSource], since: Optional[float] = None) -> bool:
        """Make ``source`` the term's (None: keep the present one; ``since``: timed)."""
        if source is None:
            return False
        self.source, self._newton.state = source, None
        self._configuration.forget()
        if since is not None:
            self.timings["setup"] = time.perf_counter() - since
        return True

    def begin_step(self) -> bool:
        """An attempt at a load step starts ("previous": the bases rebuilt where the last
        converged step left u; then True, the pattern may change: :meth:`create_matrix`)."""
        self._newton.near_contact.reset()
        if self.friction is not None:
            self.friction.begin_attempt()
        clock = time.perf_counter()
        return self._take(self._configuration.begin_step(self.options, self.u), clock)

    def _rebuild(self, search_radius: float) -> bool:
        """The bases made again with another search radius, in their configuration."""
        self.options = replace(self.options, search_radius=search_radius)
        clock = time.perf_counter()
        return self._take(self._configuration.rebuild(self.options, self.u), clock)

    @contextmanager
    def frozen(self) -> Iterator[None]:
        """With ``basis_configuration="current"``: the source frozen at the present
        u (the "previous" one) inside the block, with which a load-path driver
        solves each step first; other configurations are unchanged."""
        current = self.source
        if not self._take(self._configuration.frozen_model(self.options, self.u)):
            yield
            return
        try:
            yield
        finally:
            self._take(current)

    def check_current_surface(self) -> None:
        """A step's frozen phase converged ("current"): refuse a false penetration."""
        self._configuration.check_current_surface(self.options, self.source, self.u)

    def widen_search_radius(self, state: Optional[ContactState] = None) -> bool:
        """After a converged step, before :meth:`accept_step`: True where the
        contact zone reached the default search radius and the bases were
        rebuilt with a wider one (solve the step again; collective)."""
        radius = self._checks.wider_search_radius(state)
        return radius is not None and self._rebuild(radius)

    def accept_step(self, state: Optional[ContactState] = None) -> None:
        """The present u is a converged load step: friction's history and the
        missed-contact check's start move on to it, and the slip is checked.
        Never called after a failed step: a cut-back retries from the same history."""
        state = state or self.evaluate()
        if self.friction is not None:
            self.friction.accept(state.friction, self.u)
        self._checks.warn_if_slipped_too_far(state)
        self._checks.missed.step_accepted()

    def check_path(self, deepest: tuple[float, float, list]) -> None:
        """Called when a load path ends: warn if the penalty let the bodies
        penetrate too deep (``deepest``: the path's deepest ``results.penetration()``)
        or a body passed through a rigid obstacle (each once; collective)."""
        self._checks.warn_if_the_penalty_is_low(deepest)
        self._checks.warn_if_the_body_passed_through()

    def evaluate(self) -> ContactState:
        """The contact state at the present u with every dof kept (results)."""
        return self._newton.evaluate(self.source, self.friction, self.u)

    def update(self, bcs: Sequence = ()) -> ContactState:
        """The contact state at the present values of u (ghosts updated here),
        with the Dirichlet columns of ``bcs`` dropped."""
        clock = time.perf_counter()
        state = self._newton.update(self.source, self.friction, self.u, bcs)
        self._add("residual", clock)
        return state

    def assemble_residual(self, b: PETSc.Vec, bcs: Sequence = ()) -> None:
        """``b += R_c(u)`` on the owned entries (R_c = 0 on the dofs of ``bcs``).
        Evaluates the contact state at u (:meth:`update`); call it before
        :meth:`assemble_jacobian`, as Newton does."""
        b.axpy(1.0, self.update(bcs).residual)

    def assemble_jacobian(self, A: PETSc.Mat, bcs: Sequence = ()) -> JacobianAssembly:
        """``A += K_c`` at the state of the last :meth:`update` (A assembled
        after; GLS kinds: A is left as it is and the exact Newton step is
        prepared, :meth:`configure_ksp`). Returns a :class:`JacobianAssembly`."""
        if self._newton.state is None:
            self.update(bcs)
        clock = time.perf_counter()
        assembly = self._newton.jacobian(A, self.source, self.friction, bcs, self.timings)
        self._add("jacobian", clock)
        return assembly

    def configure_ksp(self, ksp: PETSc.KSP) -> None:
        """Make ``ksp`` apply the exact Newton step (GLS: the augmented system's PC)."""
        self._newton.entry.configure_ksp(ksp)

    def create_matrix(self, a: fem.Form, bcs: Sequence = ()) -> PETSc.Mat:
        """A matrix whose pattern holds the bilinear form ``a`` and the contact
        stiffness (of every active set), with ``a`` assembled in it."""
        A = fem_petsc.create_matrix(a)
        fem_petsc.assemble_matrix(A, a, list(bcs))
        A.assemble()
        if self._newton.state is None:
            self.update(bcs)
        self._newton.add_pattern(A, self.source, self.friction)
        return A

    def settle_near_contact(self, free_motions) -> None:
        """Called once per Newton Jacobian, before the contact is assembled:
        decide whether the nodes near contact need stiffness without force
        (``free_motions()``: the rigid motions the bulk does not resist;
        :class:`~dolfinx_mortar.contact.newton.NearContactStiffness`; collective)."""
        self._newton.settle(self.source, free_motions)

    def closing_gaps(self) -> ContextManager[Optional[PETSc.Vec]]:
        """A context giving the pull that closes the gaps near contact while
        nothing touches (:func:`~dolfinx_mortar.contact.newton.gap_closing_force`;
        None otherwise); inside it the Jacobian stiffens the nodes near contact."""
        return self._newton.closing(self.source)

    def _add(self, name: str, since: float) -> None:
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - since


def checked_contact_terms(u, contact) -> list:
    """The contact term or terms given to a
    :class:`~dolfinx_mortar.solver.nonlinear_problem.NonlinearContactProblem`
    on ``u``, as a list, checked on every rank together (collective)."""
    with collective_checks(communicator_of(u)):
        contacts = [contact] if isinstance(contact, ContactTerm) else list(contact)
        if not contacts:
            raise ValueError("no contact term: use dolfinx.fem.petsc.NonlinearProblem")
        for term in contacts:
            if not isinstance(term, ContactTerm):
                raise TypeError(f"contact terms must be ContactTerms, got "
                                f"{type(term).__name__}")
            if term.u is not u:
                raise ValueError("every contact term must be built on the problem's u")
        if len(contacts) > 1 and any(term.traits.takes_the_linear_solve for term in contacts):
            raise NotImplementedError("a GLS kind (augmented Newton step) must be the only "
                                      "contact term of a problem")
    return contacts
