"""The user's nonlinear model plus contact, in the image of
:class:`dolfinx.fem.petsc.NonlinearProblem`.

The residual form ``F(u; v)`` is the user's: any material law, body forces,
several subdomains, tractions scaled by their own Constants. The contact
terms add their residual and Jacobian. As DOLFINx's own (0.10+) problem, it
owns a PETSc SNES configured from ``petsc_options`` under its options prefix::

    problem = NonlinearContactProblem(F, u, contact, bcs,
                                      petsc_options={"snes_max_it": 30})
    problem.solve()                       # u now holds the solution
    assert problem.solver.getConvergedReason() > 0

:meth:`NonlinearContactProblem.F` and :meth:`NonlinearContactProblem.J` are
the callbacks; DOLFINx's ``NewtonSolver`` path of 0.9 takes them through
:class:`~dolfinx_mortar.solver.newton.newton_solver.NewtonSolver`, and a load path
through :class:`~dolfinx_mortar.solver.load_path.LoadPathSolver`.
"""
from __future__ import annotations

import time
from typing import Optional, Sequence, Union

import numpy as np
import ufl
from ufl.algorithms import expand_derivatives
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from petsc4py import PETSc

from dolfinx_mortar.errors import DegenerateGeometryError
from dolfinx_mortar.io.contact_output import output_names
from dolfinx_mortar.contact.term import ContactTerm, checked_contact_terms
from dolfinx_mortar.dolfinx_compat import ghosted_vector
from dolfinx_mortar.input_checks import load_data, non_finite_input
from dolfinx_mortar.linalg.contact_block_pc import tell_preconditioner
from dolfinx_mortar.linalg.near_nullspace import RigidModes
from dolfinx_mortar.solver.newton.line_search import FullStepFirst, library_line_search
from dolfinx_mortar.solver.petsc_options import (DEFAULT_OPTIONS, TemporaryOptions,
                                                 configure_contact_ksp, set_callbacks)


class NonlinearContactProblem:
    """Residual ``F(u; v) + R_c(u)`` and its exact Jacobian.

    Parameters
    ----------
    F
        The user's residual form (a UFL form, linear in the test function).
    u
        The unknown Function (the displacement the contact terms are built on).
    contact
        One contact term or several (:class:`~dolfinx_mortar.contact.term.ContactTerm`).
    bcs
        Dirichlet conditions; the contact terms skip their dofs.
    J
        The Jacobian form of F (default: its Gateaux derivative in u).
    petsc_options_prefix
        The options prefix of :attr:`solver` (command-line options
        ``-<prefix>snes_…`` apply to it).
    petsc_options
        PETSc options for :attr:`solver`, its KSP and PC, without the prefix;
        over the library's defaults (:data:`~dolfinx_mortar.solver.petsc_options.DEFAULT_OPTIONS`).
    form_compiler_options, jit_options
        Passed to :func:`dolfinx.fem.form`.
    """

    def __init__(self, F: ufl.Form, u: fem.Function,
                 contact: Union[ContactTerm, Sequence[ContactTerm]],
                 bcs: Sequence[fem.DirichletBC] = (), J: Optional[ufl.Form] = None, *,
                 petsc_options_prefix: str = "dolfinx_mortar_nonlinear_",
                 petsc_options: Optional[dict] = None,
                 form_compiler_options: Optional[dict] = None, jit_options: Optional[dict] = None):
        #: the unknown
        self.u = u
        self._prefix = petsc_options_prefix
        self._petsc_options = dict(petsc_options or {})
        self._snes: Optional[PETSc.SNES] = None
        #: the Dirichlet conditions
        self.bcs = list(bcs)
        #: the contact terms
        self.contacts = checked_contact_terms(u, contact)
        # two terms whose output files would clash are refused now, not at output
        output_names(self.contacts)
        fc = form_compiler_options or {}
        jit = jit_options or {}
        #: the residual form, compiled
        self.L = fem.form(F, form_compiler_options=fc, jit_options=jit)
        if J is None:
            J = ufl.derivative(F, u, ufl.TrialFunction(u.function_space))
        #: the Jacobian form, compiled
        self.a = fem.form(J, form_compiler_options=fc, jit_options=jit)
        # what the load path may set (checked to be finite at each F)
        self._load_data = load_data([F, J], u, self.bcs)
        self._A: Optional[PETSc.Mat] = None
        self._b: Optional[PETSc.Vec] = None
        self._rigid_modes = RigidModes(u.function_space)
        #: wall times of the bulk assembly, seconds (the contact's are in each term's timings)
        self.timings: dict[str, float] = {}
        #: why the last :meth:`F` could not be evaluated (its residual is NaN), or None
        self.evaluation_error: Optional[str] = None
        # a bulk residual linear in u (its Jacobian form does not contain u)
        # needs no shortened steps on frozen surfaces
        bulk_is_linear = u not in expand_derivatives(J).coefficients()
        #: the library's line search (:class:`~dolfinx_mortar.solver.newton.line_search.FullStepFirst`):
        #: the pre-check of :attr:`solver` and of a load path's SNES unless their
        #: options choose another line search; its counts add up over both
        self.line_search: FullStepFirst = library_line_search(
            self, [term.traits for term in self.contacts], bulk_is_linear)

    # -- what NewtonSolver and SNES call -----------------------------------------------
    def form(self, x: PETSc.Vec) -> None:
        """Bring x's ghosts up to date (DOLFINx's NewtonSolver calls this first)."""
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def F(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        """Assemble the residual at ``x`` into ``b`` (the contact states are updated).

        Where the contact surfaces have collapsed at ``x``
        (:class:`~dolfinx_mortar.errors.DegenerateGeometryError`, on every rank
        together) or a load is NaN or infinite, ``b`` is NaN and
        :attr:`evaluation_error` says why: SNES sees a failed trial point, not
        an exception inside its callback. A residual the line search has just
        evaluated at ``x`` is copied, not assembled again
        (:meth:`FullStepFirst.offer <dolfinx_mortar.solver.newton.line_search.FullStepFirst.offer>`).
        """
        clock = time.perf_counter()
        self.evaluation_error = None
        if x.handle != self.u.x.petsc_vec.handle:
            x.copy(self.u.x.petsc_vec)
        self.u.x.petsc_vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        if self.line_search.take_offer(x, b):
            # the contact states are those of the offer's evaluation, at this x
            return
        # a NaN load (set by the load path) made SNES raise "error code -1" from
        # inside the contact's evaluation at the NaN iterate that followed
        iterate_finite, self.evaluation_error = non_finite_input(
            self.u.function_space.mesh.comm, x, self._load_data)
        if not iterate_finite:
            _set_nan(b)
            return
        with b.localForm() as local:
            local.set(0.0)
        fem_petsc.assemble_vector(b, self.L)
        # x0 must carry current ghost values: SNES updates only x's owned
        # entries, and a stale prescribed value on a ghost dof next to the
        # partition boundary acts as a spurious force (a block pressed by u_y
        # on a face the partition crosses gave 0.2% … 8× wrong forces)
        fem_petsc.apply_lifting(b, [self.a], [self.bcs], x0=[self.u.x.petsc_vec], alpha=-1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self._add("bulk_residual", clock)
        try:
            for term in self.contacts:
                term.assemble_residual(b, self.bcs)
        except DegenerateGeometryError as error:
            self.evaluation_error = f"the step deformed the contact surfaces too far: {error}"
            _set_nan(b)
            return
        fem_petsc.set_bc(b, self.bcs, self.u.x.petsc_vec, -1.0)
        if self.evaluation_error is not None:     # a non-finite load: see above
            _set_nan(b)

    def J(self, x: PETSc.Vec, A: PETSc.Mat, ksp: Optional[PETSc.KSP] = None) -> None:
        """Assemble the Jacobian at the state of the last :meth:`F` into ``A``.

        A must hold the contact's pattern (:meth:`matrix`). GLS kinds: A gets
        the bulk only, and the KSP applies the exact step
        (:meth:`ContactTerm.configure_ksp <dolfinx_mortar.contact.term.ContactTerm.configure_ksp>`).
        ``ksp``, the solver that will use ``A``, is told what its
        preconditioner needs (:func:`~dolfinx_mortar.linalg.contact_block_pc.tell_preconditioner`):
        a reset where the contact pairs changed ``A``'s pattern in a way PETSc
        does not notice, the rows the contact stiffened.
        """
        clock = time.perf_counter()
        A.zeroEntries()
        fem_petsc.assemble_matrix(A, self.a, self.bcs)
        A.assemble()
        self._add("bulk_jacobian", clock)
        free: list[list[PETSc.Vec]] = []

        def free_motions() -> list[PETSc.Vec]:
            # measured once, and before any contact stiffness is in A
            if not free:
                free.append(self._rigid_modes.free_motions(A, self.bcs))
            return free[0]

        for term in self.contacts:
            term.settle_near_contact(free_motions)
        assemblies = [term.assemble_jacobian(A, self.bcs) for term in self.contacts]
        if ksp is not None:
            tell_preconditioner(ksp, [assembly.stiffened_rows for assembly in assemblies],
                                any(assembly.pattern_changed for assembly in assemblies))

    def matrix(self) -> PETSc.Mat:
        """The Jacobian matrix with the bulk and contact patterns (made once)."""
        if self._A is None:
            self._A = contact_matrix(self.a, self.bcs, self.contacts)
        return self._A

    def vector(self) -> PETSc.Vec:
        """A residual vector."""
        if self._b is None:
            V = self.u.function_space
            self._b = ghosted_vector(V.dofmap.index_map, V.dofmap.index_map_bs)
        return self._b

    # -- the problem's own SNES, as dolfinx.fem.petsc.NonlinearProblem (0.10+) --------
    @property
    def solver(self) -> PETSc.SNES:
        """The problem's SNES (Newton with the library's defaults, under
        the options prefix), made on first use."""
        if self._snes is None:
            snes = PETSc.SNES().create(self.u.function_space.mesh.comm)
            snes.setOptionsPrefix(self._prefix)
            set_callbacks(snes, self, self.matrix())
            db = PETSc.Options()
            key = "snes_linesearch_type"
            chosen = key in self._petsc_options or db.hasName(self._prefix + key)
            options = {key: value for key, value in DEFAULT_OPTIONS.items()
                       if not db.hasName(self._prefix + key)}
            options.update(self._petsc_options)
            with TemporaryOptions(self._prefix, options):
                snes.setFromOptions()
                configure_contact_ksp(snes.getKSP(), self.contacts)
            if not chosen:
                self.line_search.attach(snes)
            self._snes = snes
        return self._snes

    def solve(self) -> fem.Function:
        """Solve ``F(u) + R_c(u) = 0`` by Newton from the present ``u``, at the
        present loads, and return ``u``.

        As with DOLFINx's ``NonlinearProblem.solve``, check
        ``problem.solver.getConvergedReason() > 0`` (or pass
        ``"snes_error_if_not_converged": True``); a load path with cut-back
        on failure is :class:`~dolfinx_mortar.solver.load_path.LoadPathSolver`.
        """
        x = self.u.x.petsc_vec.copy()
        try:
            self.solver.solve(None, x)
            x.copy(self.u.x.petsc_vec)
        finally:
            x.destroy()
        self.u.x.scatter_forward()
        return self.u

    def _add(self, name: str, since: float) -> None:
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - since


def _set_nan(b: PETSc.Vec) -> None:
    with b.localForm() as local:
        local.set(np.nan)


def contact_matrix(a: fem.Form, bcs: Sequence[fem.DirichletBC],
                   contacts: Sequence[ContactTerm]) -> PETSc.Mat:
    """A new Jacobian matrix with the pattern of the bulk form ``a`` and of
    every contact term (:meth:`ContactTerm.create_matrix
    <dolfinx_mortar.contact.term.ContactTerm.create_matrix>`)."""
    A = contacts[0].create_matrix(a, bcs)
    for term in contacts[1:]:
        other = term.create_matrix(a, bcs)
        A.axpy(1.0, other, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        other.destroy()
    return A


def reaction_force(problem: NonlinearContactProblem, facet_tags, tag: int) -> np.ndarray:
    """The force that the supports on the facets ``tag`` exert on the body, a
    gdim-vector summed over all ranks.

    It is the residual ``F(u) + R_c(u)`` without boundary conditions, summed
    over the dofs of those facets: zero on free dofs at equilibrium, the
    support's force on prescribed ones (with a rigid obstacle pressing a
    block onto a fixed base, the base's reaction is minus the obstacle's
    contact force).
    """
    u = problem.u
    V = u.function_space
    mesh = V.mesh
    facets = facet_tags.find(tag)
    if mesh.comm.allreduce(len(facets)) == 0:
        raise ValueError(f"facet tag {tag} marks no facets")
    b = problem.vector().duplicate()
    with b.localForm() as local:
        local.set(0.0)
    u.x.scatter_forward()
    fem_petsc.assemble_vector(b, problem.L)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    for term in problem.contacts:
        b.axpy(1.0, term.evaluate().residual)
    blocks = fem.locate_dofs_topological(V, mesh.topology.dim - 1, facets)
    owned = blocks[blocks < V.dofmap.index_map.size_local]
    bs = V.dofmap.index_map_bs
    local = b.array_r.reshape(-1, bs)[owned].sum(axis=0)
    b.destroy()
    return np.asarray(mesh.comm.allreduce(local))
