"""The short path: a linear elastic body (or two in one mesh) in contact.

:class:`ContactProblem` is a few lines on top of the open model: the
small-strain linear elastic form (plane strain in 2D) with tractions and
prescribed displacements scaled by one load factor, a
:class:`~dolfinx_mortar.contact.term.ContactTerm`, a
:class:`~dolfinx_mortar.solver.nonlinear_problem.NonlinearContactProblem` and a
:class:`~dolfinx_mortar.solver.load_path.LoadPathSolver`. A model of one's own
(another material, body forces, a load path) uses those directly.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Optional, Sequence, Union

import numpy as np
import ufl
from dolfinx import fem
from petsc4py import PETSc

from dolfinx_mortar.collective_warnings import warn
from dolfinx_mortar.contact.laws import CoulombFriction
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.term import ContactTerm
from dolfinx_mortar.contact.checks import check_penalty_against_stiffness
from dolfinx_mortar.input_checks import (check_boundary_data, check_tags, collective_checks,
                                         communicator_of)
from dolfinx_mortar.kinds import KindLike
from dolfinx_mortar.small_strain.axisymmetric import axisymmetric_elastic_residual, circumference
from dolfinx_mortar.solver.load_path import LoadPathSolver, SolveResult, StepResult
from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem, reaction_force

#: above this Poisson's ratio linear elements lock (warned about)
NEARLY_INCOMPRESSIBLE = 0.45


def linear_elastic_residual(u: fem.Function, E: float, nu: float) -> ufl.Form:
    """``∫ σ(u) : ε(v) dx`` of small-strain isotropic elasticity (plane strain in 2D)."""
    gdim = u.function_space.mesh.geometry.dim
    mu = E / (2 * (1 + nu))
    lmbda = E * nu / ((1 + nu) * (1 - 2 * nu))
    v = ufl.TestFunction(u.function_space)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    sigma = 2 * mu * eps(u) + lmbda * ufl.tr(eps(u)) * ufl.Identity(gdim)
    return ufl.inner(sigma, eps(v)) * ufl.dx


class ContactProblem:
    """A linear elastic body (or two in one mesh) in penalty mortar contact.

    Parameters
    ----------
    V
        Vector Lagrange function space of degree 1 or 2 for the displacement.
    facet_tags, slave_tag, master_tag, obstacle, kind, penalty, scaling, active_set,
    basis_configuration, quadratic_transform, boundary_modification, search_radius, friction,
    self_contact
        The contact term's (:class:`~dolfinx_mortar.contact.term.ContactTerm`).
    E, nu
        Young's modulus and Poisson's ratio.
    fixed
        ``{tag: {component: value}}``: prescribed displacement components at
        load factor 1 (scaled by the load factor).
    tractions
        ``{tag: vector}``: surface tractions at load factor 1.
    petsc_options, linear_solver
        Options and the linear solver ("auto", "direct", "iterative") of the
        solver (:class:`~dolfinx_mortar.solver.load_path.LoadPathSolver`).
    axisymmetric
        V lives on the (r, z) half-plane of a body of revolution: the bulk is
        :func:`~dolfinx_mortar.small_strain.axisymmetric.axisymmetric_elastic_residual`,
        tractions act on the swept surfaces (∫ t·v 2πr ds) and the contact
        term is axisymmetric; forces are those on the whole body.
    """

    def __init__(self, V: fem.FunctionSpace, facet_tags, slave_tag, *,
                 master_tag: Optional[int] = None, obstacle: Optional[RigidObstacle] = None,
                 E: float, nu: float, kind: KindLike = "LcLS*", penalty: float,
                 scaling: str = "consistent", active_set: str = "nodal",
                 basis_configuration: str = "initial",
                 fixed: Optional[dict] = None, tractions: Optional[dict] = None,
                 quadratic_transform: bool = False,
                 boundary_modification: Optional[bool] = None,
                 search_radius: Optional[float] = None, petsc_options: Optional[dict] = None,
                 axisymmetric: bool = False, linear_solver: str = "auto",
                 friction: Optional[CoulombFriction] = None, self_contact: bool = False):
        # one decision of all ranks: an argument bad on one rank only raises on every rank
        with collective_checks(communicator_of(V)):
            mesh = V.mesh
            gdim = mesh.geometry.dim
            if not (np.isfinite(E) and E > 0 and -1 < nu < 0.5):
                raise ValueError(f"need a finite E > 0 and -1 < nu < 0.5, got E={E}, nu={nu}")
            if nu > NEARLY_INCOMPRESSIBLE and V.ufl_element().degree == 1:
                warn(f"nu = {nu} with linear (P1) elements: the displacement-only "
                     "formulation locks as nu → 0.5 (nu = 0.4999 gave 35× the "
                     "contact force of nu = 0.3); use quadratic elements or a "
                     "mixed form")
            fixed, tractions = fixed or {}, tractions or {}
            check_boundary_data(fixed, tractions, gdim)
        check_tags(mesh, facet_tags, [*fixed, *tractions])
        self.V, self.mesh, self.facet_tags = V, mesh, facet_tags
        self.u = fem.Function(V, name="displacement")
        self.contact = ContactTerm(
            self.u, facet_tags, slave_tag, master_tag=master_tag, obstacle=obstacle,
            kind=kind, penalty=penalty, scaling=scaling, active_set=active_set,
            basis_configuration=basis_configuration, quadratic_transform=quadratic_transform,
            boundary_modification=boundary_modification, search_radius=search_radius,
            axisymmetric=axisymmetric, friction=friction, self_contact=self_contact)
        check_penalty_against_stiffness(self.contact.options.penalty, E, self.contact.slave,
                                        mesh.comm)
        #: the load factor, 0 … 1
        self.load = fem.Constant(mesh, PETSc.ScalarType(0.0))
        v = ufl.TestFunction(V)
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
        if axisymmetric:
            F = axisymmetric_elastic_residual(self.u, E, nu)
            weight = circumference(mesh)
        else:
            F = linear_elastic_residual(self.u, E, nu)
            weight = 1.0
        for tag, t in tractions.items():
            F -= (self.load * ufl.inner(ufl.as_vector([float(c) for c in t]), v) * weight
                  * ds(tag))
        fdim = mesh.topology.dim - 1
        self._bc_values = []
        self.bcs = []
        for tag, components in fixed.items():
            facets = facet_tags.find(tag)
            for k, value in components.items():
                dofs = fem.locate_dofs_topological(V.sub(k), fdim, facets)
                c = fem.Constant(mesh, PETSc.ScalarType(0.0))
                self._bc_values.append((c, float(value)))
                self.bcs.append(fem.dirichletbc(c, dofs, V.sub(k)))
        self.problem = NonlinearContactProblem(F, self.u, self.contact, self.bcs)
        self.solver = LoadPathSolver(self.problem, petsc_options, linear_solver=linear_solver)

    # -- the parts, for users who go further ---------------------------------------------
    @property
    def slave(self):
        return self.contact.slave

    @property
    def master(self):
        return self.contact.master

    @property
    def gap_model(self):
        """The contact term's gap model (:class:`~dolfinx_mortar.contact.gap_sources.source.GapSource`)."""
        return self.contact.source

    @property
    def timings(self) -> dict:
        """Wall times (s) by part, accumulated: ``bulk_residual``, ``bulk_jacobian``,
        ``contact_residual``, ``contact_jacobian``, ``contact_setup`` (bases and
        segmentation), ``snes_solve`` (everything inside SNES, callbacks included)."""
        t = dict(self.problem.timings)
        t.update({f"contact_{k}": v for k, v in self.contact.timings.items()})
        t.update(self.solver.timings)
        return t

    def reset_timings(self) -> None:
        """Start the accumulated :attr:`timings` again (the setup time is kept)."""
        self.problem.timings.clear()
        self.solver.timings.clear()
        setup = self.contact.timings.get("setup", 0.0)
        self.contact.timings.clear()
        self.contact.timings["setup"] = setup

    def set_load(self, factor: float) -> None:
        """Scale tractions and prescribed displacements to ``factor`` of their values."""
        self.load.value = factor
        for c, value in self._bc_values:
            c.value = factor * value

    def solve(self, load_steps: int = 1, output: Optional[Union[str, Path]] = None,
              max_cuts: int = 5, progress: bool = False, prefix: Optional[str] = None,
              on_step: Optional[Callable[["ContactProblem", StepResult], None]] = None,
              predictor: str = "none") -> SolveResult:
        """Apply the load in ``load_steps`` equal steps
        (:meth:`~dolfinx_mortar.solver.load_path.LoadPathSolver.solve`, where
        ``predictor`` is described); ``on_step(problem, step)`` after each
        converged step."""
        if prefix is not None:
            self.solver.prefix = prefix
        callback = None if on_step is None else (lambda step: on_step(self, step))
        return self.solver.solve(self.set_load, load_steps, output, max_cuts, progress,
                                 callback, predictor)

    # -- results ---------------------------------------------------------------------
    def nodal_gaps(self):
        return self.contact.results.nodal_gaps()

    def nodal_pressures(self, state=None):
        return self.contact.results.nodal_pressures(state)

    def surface_pressure(self, state=None, gather: bool = False):
        """The contact pressure at the slave nodes with their coordinates
        (:meth:`~dolfinx_mortar.contact.results.contact_results.ContactResults.surface_pressure`)."""
        return self.contact.results.surface_pressure(state, gather)

    def mortar_traction(self, state=None):
        return self.contact.results.mortar_traction(state)

    def normal_force(self) -> float:
        return self.contact.results.normal_force()

    def contact_force(self):
        return self.contact.results.contact_force()

    def reaction_force(self, tag: int):
        """The force of the supports on facets ``tag`` on the body
        (:func:`~dolfinx_mortar.solver.nonlinear_problem.reaction_force`)."""
        return reaction_force(self.problem, self.facet_tags, tag)

    @classmethod
    def from_two_meshes(cls, mesh_a, facet_tags_a, slave_tag: int, mesh_b, facet_tags_b,
                        master_tag: int, degree: int = 1, *, tag_offset: int = 0,
                        shared_tags: Sequence[int] = (), **kwargs) -> "ContactProblem":
        """The contact of a slave body and an elastic master meshed separately.

        Merges the meshes into one (:func:`dolfinx_mortar.meshes.merge_meshes.merge_meshes`:
        same cell type and geometry degree, any MPI distribution), builds the
        vector Lagrange space of ``degree`` on it and returns the problem.
        b's tag values enter the merged mesh as ``v + tag_offset``, except
        ``shared_tags``; the keys of ``fixed`` and ``tractions`` are merged
        values. The merged facet and cell tags (1 on a's cells, 2 on b's) are
        kept as ``problem.facet_tags`` and ``problem.cell_tags``.
        """
        from dolfinx_mortar.meshes.merge_meshes import merge_meshes
        # the tags as the user wrote them, before b's are shifted by tag_offset: a
        # wrong master_tag 7 was named as the merged tag 17
        for name, tag, domain, tags in (("slave_tag", slave_tag, mesh_a, facet_tags_a),
                                        ("master_tag", master_tag, mesh_b, facet_tags_b)):
            try:
                check_tags(domain, tags, [tag])
            except (TypeError, ValueError) as error:
                body = "mesh_a" if domain is mesh_a else "mesh_b"
                raise type(error)(f"{name} {tag!r} of {body}: {error}") from None
        mesh, facet_tags, cell_tags = merge_meshes(mesh_a, facet_tags_a, mesh_b, facet_tags_b,
                                                   tag_offset=tag_offset,
                                                   shared_tags=shared_tags)
        if master_tag not in {int(t) for t in shared_tags}:
            master_tag = master_tag + tag_offset
        V = fem.functionspace(mesh, ("Lagrange", degree, (mesh.geometry.dim,)))
        problem = cls(V, facet_tags, slave_tag, master_tag=master_tag, **kwargs)
        problem.cell_tags = cell_tags
        return problem
