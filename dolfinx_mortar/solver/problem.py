"""The penalty mortar contact problem on DOLFINx (DOLFINx 0.5.2 API).

Small-strain linear elasticity (plane strain in 2D) through UFL, penalty mortar
contact against a rigid analytic obstacle or an elastic master in the same
mesh, Newton through PETSc SNES (options prefix ``dolfinx_mortar_``), load steps
that are cut back when Newton fails and regrown after successes, and crash-safe
XDMF output after every converged step.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fem_petsc
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.gaps import GlobalGap, MortarGap, ObstacleGap, gap_kind
from dolfinx_mortar.solver.convergence import (ContactDivergenceError, EquilibriumTest, FailedAttempt,
                                        describe_failure)
from dolfinx_mortar.surfaces.facet_surface import facet_surface, nodal_displacement
from dolfinx_mortar.contact.current_mortar import CurrentMortarGap
from dolfinx_mortar.contact.finite_deformation import CurrentObstacleGap, CurrentState, CurrentSurfaceGap
from dolfinx_mortar.solver.input_checks import check_boundary_data, check_cells, unused_petsc_options
from dolfinx_mortar.kinds import BasisKind, KindLike, is_global, parse_kind
from dolfinx_mortar.solver.load_stepping import LoadStepper
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.layout import assemble_blocks
from dolfinx_mortar.contact.obstacles import RigidObstacle
from dolfinx_mortar.contact.pointwise import obstacle_positive_gaps
from dolfinx_mortar.io.surface_output import SlaveSurfaceOutput, surface_output_path
from dolfinx_mortar.io.xdmf_series import XdmfSeries

FloatArray = npt.NDArray[np.float64]

ACTIVE_SETS = ("nodal", "pointwise")
#: above this Poisson's ratio linear elements lock (warned about)
NEARLY_INCOMPRESSIBLE = 0.45
#: an initial penetration deeper than this many slave element lengths is warned about
DEEP_PENETRATION = 0.5
CONFIGURATIONS = ("initial", "previous", "current")

#: PETSc options set unless the options database already has them
DEFAULT_OPTIONS = {
    "snes_type": "newtonls",
    "snes_linesearch_type": "basic",
    # relative to the out-of-balance force where the step starts
    # (dolfinx_mortar.solver.convergence.EquilibriumTest)
    "snes_rtol": 1e-11,
    # absolute residuals depend on the units: rely on the relative test
    "snes_atol": 1e-15,
    # a Newton step at round-off size ends the iteration, as a failure unless
    # the residual test holds
    "snes_stol": 1e-13,
    "snes_max_it": 40,
    # the first step of a contact problem often overshoots into the obstacle
    # before the active set settles: do not call that divergence
    "snes_divergence_tolerance": -1,
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
    # MUMPS sizes its workspace from the analysis; parallel pivoting can exceed
    # it (INFOG(1) = -9). 100% extra costs memory only.
    "mat_mumps_icntl_14": 100,
}


@dataclass
class ContactState:
    """The contact terms at one displacement.

    ``R_c = Gᵀ force``. ``G`` is the masked derivative of the nodal gaps d̄
    (Ĝ of ĝ for GLS kinds); ``K_curv`` the masked curvature matrix or None.
    With the pointwise active set, ``gaps_plus`` = d̄⁺ and ``G_plus`` its
    derivative; otherwise both are None.
    """

    gaps: FloatArray
    G: PETSc.Mat
    force: FloatArray
    K_curv: Optional[PETSc.Mat]
    gaps_plus: Optional[FloatArray] = None
    G_plus: Optional[PETSc.Mat] = None
    #: basis_configuration="current": the full residual and Jacobian data
    current: Optional[CurrentState] = None


@dataclass
class StepResult:
    """One converged load step."""

    load_factor: float
    newton_iterations: int
    residuals: list
    wall_time: float
    active_nodes: int


@dataclass
class SolveResult:
    """All converged steps and the final state."""

    steps: list = field(default_factory=list)

    @property
    def newton_iterations(self) -> int:
        return sum(s.newton_iterations for s in self.steps)


class ContactProblem:
    """A linear elastic body (or two in one mesh) in penalty mortar contact.

    Parameters
    ----------
    V
        Vector Lagrange function space of degree 1 or 2 for the displacement.
    facet_tags
        Facet meshtags.
    slave_tag
        Tag of the slave facets.
    master_tag
        Tag of the master facets in the same mesh (two bodies), or None.
    obstacle
        A rigid analytic obstacle instead of a master surface.
    E, nu
        Young's modulus and Poisson's ratio.
    kind
        Mortar basis kind, any of the six (GLS/GLS* through the augmented
        Newton step, :class:`AugmentedNewtonStep`).
    penalty
        ε, pressure per length (consistent scaling).
    scaling
        ``"consistent"`` (default) or ``"seed"``.
    active_set
        ``"nodal"`` (default): the penalty acts on ``⟨d̄_A⟩``;
        ``"pointwise"``: ``p_A = ε ∫ M̄_A ⟨d⟩``, integrated only where the slave
        penetrates (cells split at d = 0 against a rigid obstacle; the segment
        quadrature points against an elastic master), with an unsymmetric
        exact Jacobian (:mod:`dolfinx_mortar.contact.pointwise`).
    basis_configuration
        ``"initial"`` (default): bases and segmentation in the reference
        configuration; ``"previous"``: bases (and, for an elastic master, the
        segmentation) rebuilt in the last converged configuration when a load
        step starts; ``"current"``: bases (and, for an elastic master, the
        segmentation and the normals) on the current surfaces at every Newton
        iteration with the exact linearization (local kinds; rigid obstacles
        in 2D and 3D, :mod:`dolfinx_mortar.contact.finite_deformation`; elastic
        masters on lines and P1 triangles, :mod:`dolfinx_mortar.contact.current_mortar`).
    fixed
        ``{tag: {component: value}}``: prescribed displacement components at
        load factor 1 (scaled by the load factor).
    tractions
        ``{tag: vector}``: surface tractions at load factor 1.
    quadratic_transform
        Transformed basis on quadratic triangle facets.
    boundary_modification
        Elastic master, dual kinds (LcLS*, LcLS): rebuild the basis over the
        covered part of partly covered slave facets (Popp et al. 2013).
        Without it a dual function that is negative on the covered part turns
        a separated node's gap positive (false penetration).
    search_radius
        How far apart slave and master facets may be and still be paired
        (:class:`MortarCoupling`; default the largest slave facet diameter).
        A partly covered cell gives the dual kinds spurious positive gaps
        unless ``boundary_modification`` is on.
    """

    def __init__(self, V: fem.FunctionSpace, facet_tags, slave_tag: int, *,
                 master_tag: Optional[int] = None, obstacle: Optional[RigidObstacle] = None,
                 E: float, nu: float, kind: KindLike = "LcLS*", penalty: float,
                 scaling: str = "consistent", active_set: str = "nodal",
                 basis_configuration: str = "initial",
                 fixed: Optional[dict] = None, tractions: Optional[dict] = None,
                 quadratic_transform: bool = False, boundary_modification: bool = False,
                 search_radius: Optional[float] = None):
        mesh = V.mesh
        gdim = mesh.geometry.dim
        if V.dofmap.index_map_bs != gdim:
            raise ValueError(f"V must be a vector space with {gdim} components per node")
        check_cells(mesh)
        if (master_tag is None) == (obstacle is None):
            raise ValueError("give exactly one of master_tag (elastic master) and obstacle "
                             "(rigid analytic obstacle)")
        if not (np.isfinite(E) and E > 0 and -1 < nu < 0.5):
            raise ValueError(f"need a finite E > 0 and -1 < nu < 0.5, got E={E}, nu={nu}")
        if nu > NEARLY_INCOMPRESSIBLE and V.ufl_element().degree() == 1:
            warnings.warn(f"nu = {nu} with linear (P1) elements: the displacement-only "
                          "formulation locks as nu → 0.5 (nu = 0.4999 gave 35× the contact "
                          "force of nu = 0.3); use quadratic elements or a mixed form",
                          RuntimeWarning, stacklevel=2)
        if active_set not in ACTIVE_SETS:
            raise ValueError(f"unknown active set '{active_set}'; expected {ACTIVE_SETS}")
        if basis_configuration not in CONFIGURATIONS:
            raise ValueError(f"unknown basis configuration '{basis_configuration}'; "
                             f"expected {CONFIGURATIONS}")
        if basis_configuration == "current" and boundary_modification:
            raise NotImplementedError("basis_configuration='current' with the boundary "
                                      "modification is not implemented")
        if basis_configuration == "current" and active_set == "pointwise":
            raise NotImplementedError("basis_configuration='current' is implemented for the "
                                      "nodal active set only")
        if obstacle is not None and obstacle.gdim != gdim:
            raise ValueError(f"a {obstacle.gdim}D obstacle in a {gdim}D mesh: the option "
                             "does not fit the mesh's dimension")
        gap_kind(kind, scaling)  # validates kind and scaling early
        if boundary_modification and (master_tag is None or parse_kind(kind) not in (
                BasisKind.LcLS_star, BasisKind.LcLS)):
            raise ValueError("the consistent boundary modification applies to the dual kinds "
                             "(LcLS*, LcLS) with an elastic master (master_tag)")
        self.boundary_modification = boundary_modification
        if active_set == "pointwise" and parse_kind(kind) in (BasisKind.LcLS_star,
                                                              BasisKind.LcLS):
            warnings.warn("the pointwise active set with a dual kind: ∫M̄_A⟨d⟩ is negative "
                          "next to the contact edge, and Newton did not converge on any "
                          "curved contact tested (Hertz 2D); prefer active_set='nodal'",
                          RuntimeWarning, stacklevel=2)
        fixed, tractions = fixed or {}, tractions or {}
        check_boundary_data(fixed, tractions, gdim)
        if not np.issubdtype(np.asarray(facet_tags.values).dtype, np.integer):
            raise TypeError(f"facet tag values must be integers, got "
                            f"{np.asarray(facet_tags.values).dtype}")
        present = {int(t) for values in mesh.comm.allgather(np.unique(facet_tags.values))
                   for t in values}
        for tag in [slave_tag, master_tag, *fixed, *tractions]:
            if tag is not None and not isinstance(tag, (int, np.integer)):
                raise TypeError(f"tags must be integers, got {tag!r} "
                                f"({type(tag).__name__})")
            if tag is not None and tag not in present:
                raise ValueError(f"facet tag {tag} marks no facets (tags present: "
                                 f"{sorted(present)})")
        if master_tag is not None:
            a, b = facet_tags.find(slave_tag), facet_tags.find(master_tag)
            if mesh.comm.allreduce(len(np.intersect1d(a, b))) > 0:
                raise ValueError(f"slave tag {slave_tag} and master tag {master_tag} "
                                 "overlap: a facet cannot be both")
        self.V, self.mesh = V, mesh
        self.kind = parse_kind(kind)
        self.penalty, self.scaling = float(penalty), scaling
        self.basis_configuration = basis_configuration
        self.active_set = active_set
        self.obstacle = obstacle
        self.search_radius = search_radius
        self.load = fem.Constant(mesh, PETSc.ScalarType(0.0))

        # bulk: small strain, plane strain in 2D
        mu = E / (2 * (1 + nu))
        lmbda = E * nu / ((1 + nu) * (1 - 2 * nu))
        self.u = fem.Function(V, name="displacement")
        v, du = ufl.TestFunction(V), ufl.TrialFunction(V)

        def eps(w):
            return ufl.sym(ufl.grad(w))

        def sigma(w):
            return 2 * mu * eps(w) + lmbda * ufl.tr(eps(w)) * ufl.Identity(gdim)

        ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
        F = ufl.inner(sigma(self.u), eps(v)) * ufl.dx
        for tag, t in tractions.items():
            t = np.asarray(t, dtype=np.float64)
            F -= self.load * ufl.inner(ufl.as_vector([float(c) for c in t]), v) * ds(tag)
        self.F_form = fem.form(F)
        self.J_form = fem.form(ufl.derivative(F, self.u, du))

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

        self.slave = facet_surface(V, facet_tags, slave_tag, quadratic_transform)
        self.master = (facet_surface(V, facet_tags, master_tag) if master_tag is not None
                       else None)
        self.gap_model: Union[ObstacleGap, MortarGap]
        self._segment(None)
        self.b = fem_petsc.create_vector(self.F_form)
        self.A_bulk = fem_petsc.create_matrix(self.J_form)
        self.timings: dict[str, float] = {}
        self._output: Optional[XdmfSeries] = None
        self._warn_deep_initial_penetration()

    def _warn_deep_initial_penetration(self) -> None:
        """Warn when the initial configuration already penetrates by more than
        DEEP_PENETRATION slave element lengths (a rigid plane placed 0.2 deep
        into a 0.5-high block solved without a word)."""
        gaps = self.nodal_gaps()
        slave = self.slave
        n = slave.layout.num_owned
        # each node's length: the largest of its local cells' (measure^(1/tdim))
        cell_length = slave.tabulate().weights.sum(axis=1) ** (1.0 / slave.tdim)
        length = np.zeros(slave.layout.size_local)
        np.maximum.at(length, slave.cells, np.repeat(cell_length[:, None],
                                                     slave.cells.shape[1], axis=1))
        on_local_cell = np.zeros(slave.layout.size_local, dtype=bool)
        on_local_cell[slave.cells] = True
        covered = self.gap_model.covered & on_local_cell
        depth = np.where(covered, gaps / np.where(covered, length, 1.0), -np.inf)[:n]
        worst = int(np.argmax(depth)) if n else -1
        local = (float(depth[worst]), float(gaps[worst]), self.slave.x[worst].tolist()) \
            if n else (-np.inf, 0.0, [])
        ratio, gap, x = max(self.mesh.comm.allgather(local), key=lambda item: item[0])
        if ratio > DEEP_PENETRATION:
            warnings.warn(f"the initial configuration penetrates by {gap:.3g} ({ratio:.3g} "
                          f"slave element lengths) at the slave node {x}: check the "
                          "obstacle's position and normal, or the tags of slave and master",
                          RuntimeWarning, stacklevel=3)

    def _check_petsc_options(self, prefix: str) -> None:
        """Refuse options under the prefix that no PETSc object read (misspelled)."""
        unused = unused_petsc_options(prefix, ignore=DEFAULT_OPTIONS)
        if unused:
            raise ValueError(f"PETSc option(s) {', '.join(unused)} were set but not used by "
                             f"any solver of this problem: misspelled, or meant for another "
                             f"prefix? (options prefix '{prefix}')")

    # -- contact -------------------------------------------------------------------
    def _segment(self, u_nodes: Optional[FloatArray]) -> None:
        """(Re)build the gap model; for an elastic master in the configuration u."""
        clock = time.perf_counter()
        if self.basis_configuration == "current":
            self.gap_model = (
                CurrentObstacleGap(self.slave, self.obstacle, self.kind, self.penalty,
                                   self.scaling) if self.obstacle is not None
                else CurrentMortarGap(self.slave, self.master, self.kind, self.penalty,
                                      self.scaling, self.search_radius))
            self._A_total, self._bc_mask, self._last_active = None, None, None
            self.timings_segmentation = time.perf_counter() - clock
            return
        self.gap_model = self._frozen_model(u_nodes)
        #: the nodal displacement the frozen model was built at (None: zero)
        self._segmented_at = None if u_nodes is None else u_nodes.copy()
        self._A_total: Optional[PETSc.Mat] = None
        self._bc_mask: Optional[PETSc.Vec] = None
        self._last_active: Optional[FloatArray] = None
        self.timings_segmentation = time.perf_counter() - clock

    def _frozen_model(self, u_nodes: Optional[FloatArray]):
        """The gap model with bases and segmentation frozen in the configuration
        u_nodes (None: the initial one), linear in u about it."""
        if self.obstacle is not None:
            slave = self.slave if u_nodes is None else self.slave.moved(u_nodes)
            model = ObstacleGap(slave, self.obstacle, self.kind, self.penalty, self.scaling,
                                reference=u_nodes)
        else:
            keep = self.active_set == "pointwise"
            if u_nodes is None:
                coupling = MortarCoupling(self.slave, self.master, keep_points=keep,
                                          search_radius=self.search_radius)
            else:  # bases and segmentation in the configuration u (DESIGN.md §2)
                coupling = MortarCoupling(self.slave.moved(u_nodes), self.master.moved(u_nodes),
                                          keep_points=keep, search_radius=self.search_radius)
            reference = self.u.vector.copy() if u_nodes is not None else None
            model = MortarGap(coupling, self.kind, self.penalty, self.scaling, reference,
                              boundary_modification=self.boundary_modification)
        return (GlobalGap(model, self.kind, self.penalty, self.scaling)
                if is_global(self.kind) else model)

    def _moved_since_segmentation(self) -> bool:
        """Whether u differs from the displacement the frozen model was built at."""
        u_nodes = nodal_displacement(self.slave, self.u)
        moved = (np.any(u_nodes != 0) if self._segmented_at is None
                 else not np.array_equal(u_nodes, self._segmented_at))
        return self.mesh.comm.allreduce(bool(moved), op=MPI.LOR)

    def _mask(self) -> PETSc.Vec:
        """1 on free dofs, 0 on Dirichlet dofs (the contact terms skip those)."""
        if self._bc_mask is None:
            m = self.b.duplicate()
            m.set(1.0)
            fem_petsc.set_bc(m, self.bcs, scale=0.0)
            self._bc_mask = m
        return self._bc_mask

    def _contact(self) -> "ContactState":
        """Contact state at the current u (see :class:`ContactState`)."""
        model = self.gap_model
        if isinstance(model, CurrentSurfaceGap):
            current = model.evaluate(nodal_displacement(self.slave, self.u), self._mask())
            return ContactState(current.y, current.G_y,
                                model.weights * np.maximum(current.y, 0.0), None,
                                current=current)
        inner = model.inner if isinstance(model, GlobalGap) else model
        pointwise = self.active_set == "pointwise"
        x = None
        gaps_plus = G_plus = None
        if isinstance(inner, ObstacleGap):
            u_nodes = nodal_displacement(self.slave, self.u)
            gaps, G, x = inner.evaluate(u_nodes)
            if pointwise:
                gaps_plus, G_plus = obstacle_positive_gaps(inner, u_nodes, x)
        else:
            G = inner.G.copy()
            gaps = inner.evaluate(self.u.vector)
            if pointwise:
                gaps_plus, G_plus = inner.points.positive_gaps(self.u.vector)
        if isinstance(model, GlobalGap):
            gaps = model.mass.solve(gaps)                                  # d̄ = L⁻¹ ĝ
            if pointwise:
                gaps_plus = model.mass.solve(gaps_plus)                    # d̄⁺ = L⁻¹ ĝ⁺
                force = model.mass.solve(model.weights * gaps_plus)        # z = L⁻¹ ω d̄⁺
            else:
                force = model.mass.solve(model.weights * np.maximum(gaps, 0.0))
        else:
            force = model.weights * (gaps_plus if pointwise else np.maximum(gaps, 0.0))
        G.diagonalScale(None, self._mask())
        if G_plus is not None:
            G_plus.diagonalScale(None, self._mask())
        K_curv = None
        if x is not None:
            blocks = inner.curvature_blocks(force, x)
            if blocks is not None:
                nc, nd = self.slave.cells.shape
                width = nd * self.slave.gdim
                dofs = inner._node_dofs(self.slave.cells).reshape(nc, width)
                local = (self.slave.cells[..., None] * self.slave.gdim
                         + np.arange(self.slave.gdim)).reshape(nc, width)
                K_curv = assemble_blocks(inner.dofs, local, inner.dofs, dofs, blocks)
                K_curv.diagonalScale(self._mask(), self._mask())
        return ContactState(gaps, G, force, K_curv, gaps_plus, G_plus)

    # -- SNES callbacks --------------------------------------------------------------
    def _residual(self, snes, x: PETSc.Vec, b: PETSc.Vec) -> None:
        clock = time.perf_counter()
        x.copy(self.u.vector)
        self.u.vector.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with b.localForm() as local:
            local.set(0.0)
        fem_petsc.assemble_vector(b, self.F_form)
        # x0 must carry current ghost values: SNES updates only x's owned
        # entries, and a stale prescribed value on a ghost dof next to the
        # partition boundary acts as a spurious force (a block pressed by u_y
        # on a face the partition crosses gave 0.2% … 8× wrong forces)
        fem_petsc.apply_lifting(b, [self.J_form], [self.bcs], x0=[self.u.vector], scale=-1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self._add("bulk_residual", clock)
        clock = time.perf_counter()
        state = self._state = self._contact()
        if state.current is not None:
            Rc = state.current.residual
        else:
            Rc = state.G.createVecRight()
            state.G.multTranspose(self.slave.layout.vector(state.force), Rc)
        b.axpy(1.0, Rc)
        self._add("contact_residual", clock)
        fem_petsc.set_bc(b, self.bcs, x, -1.0)

    def _jacobian(self, snes, x: PETSc.Vec, J: PETSc.Mat, P: PETSc.Mat) -> None:
        clock = time.perf_counter()
        # The bulk goes straight into the Newton matrix (its pattern holds the
        # bulk's); copying a separate bulk matrix in cost as much as the
        # contact terms (profile of Hertz 3D). GLS kinds need K on its own.
        bulk = self.A_bulk if isinstance(self.gap_model, GlobalGap) else J
        bulk.zeroEntries()
        fem_petsc.assemble_matrix(bulk, self.J_form, self.bcs)
        bulk.assemble()
        self._add("bulk_jacobian", clock)
        clock = time.perf_counter()
        state = self._state
        if state.current is not None:
            # Far from the solution the pressure on the current surface can be
            # many times its final value, and so its geometric stiffness:
            # full Newton steps then cycled between active sets (Hertz 2D).
            # While the active set moves, the frozen-surface part alone gives
            # the step; once it settles, the exact Jacobian converges
            # quadratically.
            active = self._active(state.gaps)
            settled = self.mesh.comm.allreduce(bool(
                self._last_active is not None and np.array_equal(active, self._last_active)),
                op=MPI.LAND)
            self._last_active = active
            Kc = self.gap_model.jacobian(state.current, active, self._mask(), geometric=settled)
            J.axpy(1.0, Kc, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            J.assemble()
            self._add("contact_jacobian", clock)
            return
        G, K_curv = state.G, state.K_curv
        G_right = G
        if state.gaps_plus is not None and self._any_penetration(state.gaps_plus):
            weights = self.gap_model.weights
            G_right = state.G_plus
        else:
            weights = self.gap_model.weights * self._active(state.gaps)
        if isinstance(self.gap_model, GlobalGap):
            K = self.A_bulk.copy()
            if K_curv is not None:
                K.axpy(1.0, K_curv, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            self._augmented.update(K, G, weights, self.gap_model.mass.matrix, G_right,
                                   self.gap_model.surface_rows)
            self._add("contact_jacobian", clock)
            return
        SG = G_right.copy()
        SG.diagonalScale(self.slave.layout.vector(weights), None)
        Kc = G.transposeMatMult(SG)
        J.axpy(1.0, Kc, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        if K_curv is not None:
            J.axpy(1.0, K_curv, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        J.assemble()
        self._add("contact_jacobian", clock)

    def _any_penetration(self, gaps_plus: FloatArray) -> bool:
        """Whether d̄⁺ ≠ 0 anywhere: else G⁺ = 0 and the nodal fallback stiffens."""
        n = self.slave.layout.num_owned
        return bool(self.mesh.comm.allreduce(bool(np.any(gaps_plus[:n] != 0))))

    def _active(self, gaps: FloatArray) -> FloatArray:
        """Nodes that get contact stiffness in the Jacobian (H(d̄) as 0/1).

        The generalized derivative of ⟨·⟩ at 0 is taken as 1, so touching
        nodes stiffen without pushing. If no node on any rank is active — a
        body that only touches at a point, with positive mortar functions, has
        d̄ < 0 everywhere — the covered nodes within a tenth of their element
        length of contact get stiffness too: otherwise the rigid-body mode that
        the contact must hold makes the Jacobian singular. Once a node is
        active the Jacobian is exact again.
        """
        # Nodes with no master below them have no gap (d̄ = 0 because nothing is
        # integrated there): they are never active.
        covered = self.gap_model.covered
        active = covered & (gaps >= 0)
        n = self.slave.layout.num_owned
        if self.mesh.comm.allreduce(int(np.sum(active[:n]))) == 0:
            W = self.gap_model.basis.lumped_weights
            length = np.power(np.maximum(W, 0.0), 1.0 / self.slave.tdim)
            active = covered & (gaps >= -0.1 * length)
        return active.astype(np.float64)

    def _close_gaps(self, snes: PETSc.SNES, x: PETSc.Vec) -> None:
        """Move x into contact when nothing touches yet (a better Newton start).

        With positive mortar functions a body that touches at a point has
        d̄ < 0 at every node, no contact force, and Newton's linear model —
        stiff only from the current gap on — creeps towards the obstacle by
        F/(εA) per iteration. This step solves the linear model in which the
        nodes near contact (:meth:`_active`) carry the force ``ω(d̄ + GΔu)``,
        which closes their gaps: it overshoots by about the largest of those
        gaps (a tenth of an element), which Newton then takes back. Pulling
        only the closest node instead left rotations about it free (singular
        on a grazing disk). It changes only where Newton starts, not the
        solution. For GLS kinds (d̄ = L⁻¹ĝ, G = L⁻¹Ĝ) the pull is
        ``Ĝᵀ L⁻¹ ω(d̄)`` on the near nodes and the step comes from the augmented
        system, whose Jacobian (:meth:`_jacobian`) already stiffens them.
        """
        self._residual(None, x, self.b)
        state = self._state
        n = self.slave.layout.num_owned
        touching = (state.gaps_plus if state.gaps_plus is not None
                    else np.where(self.gap_model.covered, np.maximum(state.gaps, 0.0), 0.0))
        if self.mesh.comm.allreduce(bool(np.any(touching[:n] != 0))):
            return
        near = self._active(state.gaps)
        if self.mesh.comm.allreduce(int(np.sum(near[:n]))) == 0:
            return
        J = self._total_matrix()
        self._jacobian(snes, x, J, J)
        rhs = self.b.copy()
        force = self.gap_model.weights * near * state.gaps
        if isinstance(self.gap_model, GlobalGap):
            force = self.gap_model.mass.solve(force)
        pull = state.G.createVecRight()
        state.G.multTranspose(self.slave.layout.vector(force), pull)
        rhs.axpy(1.0, pull)
        ksp = snes.getKSP()
        ksp.setOperators(J)
        dx = rhs.duplicate()
        ksp.solve(rhs, dx)
        if ksp.getConvergedReason() > 0:
            x.axpy(-1.0, dx)

    def _add(self, name: str, since: float) -> None:
        self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - since

    def _total_matrix(self) -> PETSc.Mat:
        """Bulk pattern ∪ contact pattern, built once per segmentation.

        For GLS kinds the Newton step comes from the augmented system and this
        matrix only carries the bulk pattern (SNES needs a matrix object).
        """
        if self._A_total is None:
            self._residual(None, self.u.vector, self.b)
            G, K_curv = self._state.G, self._state.K_curv
            A = self.A_bulk.duplicate(copy=False)
            fem_petsc.assemble_matrix(A, self.J_form, self.bcs)
            A.assemble()
            if self._state.current is not None:
                ones = np.ones(self.slave.layout.size_local)
                Kc = self.gap_model.jacobian(self._state.current, ones, self._mask())
                A.axpy(1.0, Kc, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
                if isinstance(self.gap_model, CurrentMortarGap):
                    # the pairs, and so the pattern, change with u inside a
                    # Newton solve: new entries are allocated as they come
                    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
            elif not isinstance(self.gap_model, GlobalGap):
                Kc = G.transposeMatMult(G)
                A.axpy(1.0, Kc, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
                if K_curv is not None:
                    A.axpy(1.0, K_curv,
                           structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            self._A_total = A
        return self._A_total

    # -- driver ----------------------------------------------------------------------
    def _snes(self, prefix: str) -> PETSc.SNES:
        opts = PETSc.Options()
        for key, value in DEFAULT_OPTIONS.items():
            if not opts.hasName(prefix + key):
                opts[prefix + key] = value
        snes = PETSc.SNES().create(self.mesh.comm)
        snes.setOptionsPrefix(prefix)
        snes.setFunction(self._residual, self.b)
        snes.setJacobian(self._jacobian, self._total_matrix())
        snes.setConvergenceHistory()
        snes.setFromOptions()
        self._equilibrium = EquilibriumTest()
        snes.setConvergenceTest(self._equilibrium)
        if (self.basis_configuration == "current"
                and not PETSc.Options().hasName(prefix + "snes_linesearch_type")):
            # On the current surface a pressure far above the final one (the first
            # Newton steps of a contact problem overshoot) brings a geometric
            # stiffness of its own size; full steps then cycled on Hertz 2D, the
            # l2 line search converges (quadratically at the end).
            snes.getLineSearch().setType("l2")
        if isinstance(self.gap_model, GlobalGap):
            # The Newton step is the exact solve of the augmented system; the
            # SNES's own KSP only applies it.
            self._augmented = AugmentedNewtonStep(self.mesh.comm, prefix + "augmented_")
            ksp = snes.getKSP()
            ksp.setType("preonly")
            ksp.getPC().setType("python")
            ksp.getPC().setPythonContext(self._augmented)
        return snes

    def _set_load(self, factor: float) -> None:
        self.load.value = factor
        for c, value in self._bc_values:
            c.value = factor * value

    def _newton(self, snes: PETSc.SNES, x: PETSc.Vec) -> tuple[int, list, int, str]:
        """One load step's Newton solve from x: SNES reason, residuals, iterations
        and, if it failed, what stopped it (in words).

        The step is accepted when ``‖R‖ ≤ rtol·F`` (:class:`EquilibriumTest`)
        with F the residual norm at x before the gap-closing start: the force
        out of balance when the step starts, whatever Newton starts from.

        With basis_configuration="current" the step is first solved with the
        surface frozen where the step starts (the "previous" model: piecewise
        linear, robust), then corrected on the current surface with the exact
        Jacobian. Started from the current surface directly, the first
        iterations overshoot to pressures whose geometric stiffness is larger
        than the bulk's, and Newton cycled or diverged (Hertz 2D).
        """
        history: list = []
        iterations = 0
        self._residual(None, x, self.b)
        self._equilibrium.start(self.b.norm())
        current = self.gap_model if self.basis_configuration == "current" else None
        phases = [None, current] if current is not None else [None]
        for phase in phases:
            if current is not None:
                if phase is None:
                    self.gap_model = self._frozen_model(nodal_displacement(self.slave, self.u))
                else:
                    self.gap_model = current
                    self._last_active = None
            try:
                self._close_gaps(snes, x)
                snes.setConvergenceHistory(reset=True)
                solve_clock = time.perf_counter()
                snes.solve(None, x)
                self._add("snes_solve", solve_clock)  # includes the callbacks' times
            finally:
                if current is not None:
                    self.gap_model = current
            if not self._options_checked:
                # every option is read by the first solve: once per solve() is enough
                self._check_petsc_options(snes.getOptionsPrefix())
                self._options_checked = True
            reason = snes.getConvergedReason()
            history += list(snes.getConvergenceHistory()[0])
            iterations += snes.getIterationNumber()
            if reason <= 0:
                return reason, history, iterations, describe_failure(snes, self._equilibrium)
        return reason, history, iterations, ""

    def solve(self, load_steps: int = 1, output: Optional[Union[str, Path]] = None,
              max_cuts: int = 5, progress: bool = False,
              prefix: str = "dolfinx_mortar_",
              on_step: Optional[Callable[["ContactProblem", StepResult], None]] = None
              ) -> SolveResult:
        """Apply the load in ``load_steps`` equal steps.

        A step whose Newton solve fails (no equilibrium, :class:`EquilibriumTest`)
        is halved and retried, at most ``max_cuts`` times in a row; then
        :class:`ContactDivergenceError` is raised with every attempt's cause
        and residual history. After two successes in a row a cut step is
        doubled again, up to ``1 / load_steps``; the last step ends exactly at
        load factor 1 (:class:`dolfinx_mortar.solver.load_stepping.LoadStepper`).
        Each converged step is written to ``output`` (XDMF: displacement and
        ``p̂`` on the mesh) and to ``<output stem>_slave.xdmf`` (``p̂`` and
        ``p*`` on the slave facets, one set of nodes per facet since ``p*``
        may jump) before the next one starts.

        Parameters
        ----------
        load_steps
            A positive integer (numpy integers too).
        """
        stepper = LoadStepper(load_steps, max_cuts)
        if not np.all(np.isfinite(self.u.x.array)):
            raise ValueError("the displacement contains NaN or infinite values")
        if output is not None:
            self._open_output(Path(output))
        snes = self._snes(prefix)
        self._options_checked = False
        result = SolveResult()
        failures: list[FailedAttempt] = []
        bar = None
        if progress and self.mesh.comm.rank == 0:
            from tqdm import tqdm
            bar = tqdm(total=stepper.load_steps, desc="load steps", unit="step")
        while not stepper.done:
            target = stepper.target()
            self._set_load(target)
            if self.basis_configuration == "previous" and self._moved_since_segmentation():
                # "previous": bases and segmentation of the last converged step,
                # rebuilt when a step starts (not when one ends), so that the
                # results after a step come from the model it was solved with
                self._segment(nodal_displacement(self.slave, self.u))
                snes.destroy()
                snes = self._snes(prefix)
            saved = self.u.vector.copy()
            clock = time.perf_counter()
            x = self.u.vector.copy()
            reason, history, iterations, cause = self._newton(snes, x)
            if reason <= 0:
                failures.append(FailedAttempt(target, reason, history, cause))
                stepper.failed()
                if stepper.exhausted:
                    raise ContactDivergenceError(target, failures)
                saved.copy(self.u.vector)
                self.u.vector.ghostUpdate(addv=PETSc.InsertMode.INSERT,
                                          mode=PETSc.ScatterMode.FORWARD)
                continue
            failures = []
            x.copy(self.u.vector)
            self.u.vector.ghostUpdate(addv=PETSc.InsertMode.INSERT,
                                      mode=PETSc.ScatterMode.FORWARD)
            state = self._contact()   # once per converged step: results and output
            pressures = self.nodal_pressures(state)
            active = self.mesh.comm.allreduce(
                int(np.sum(pressures[: self.slave.layout.num_owned] > 0)))
            s = StepResult(target, iterations, history,
                           time.perf_counter() - clock, active)
            result.steps.append(s)
            before = stepper.fraction_of_steps
            stepper.succeeded()
            if bar is not None:
                bar.update(stepper.fraction_of_steps - before)
            if output is not None:
                self._write_step(target, state)
            if on_step is not None:
                on_step(self, s)
        if bar is not None:
            bar.close()
        snes.destroy()
        return result

    # -- results ---------------------------------------------------------------------
    def nodal_gaps(self) -> FloatArray:
        """``d̄_A`` at the local slave-layout nodes for the current u."""
        return self._contact().gaps

    def nodal_pressures(self, state: Optional[ContactState] = None) -> FloatArray:
        """Contact pressure at local nodes: ``p_A = ε⟨d̄_A⟩`` (nodal active set) or
        ``ε d̄⁺_A`` (pointwise), consistent scaling; ``state`` defaults to the
        contact state at the current u."""
        state = state or self._contact()
        if state.gaps_plus is not None:
            return self.gap_model.nodal_pressures(state.gaps_plus, positive_part=False)
        return self.gap_model.nodal_pressures(state.gaps)

    def mortar_traction(self, state: Optional[ContactState] = None) -> FloatArray:
        """The contact traction ``p* = Σ_A f_A M_A`` at the nodes of every slave cell.

        ``f_A = ω_A⟨d̄_A⟩`` (or ``ω_A d̄⁺_A``) and ``M`` the gap basis, so that
        the contact virtual work is ``∫ p* δd``; (cells, nodes) values, one set
        per cell because ``p*`` of the dual kinds jumps between cells.
        """
        state = state or self._contact()
        cells = self.slave.cells
        if isinstance(self.gap_model, GlobalGap):   # Σ_A f_A (N L⁻¹)_A = Σ_B N_B z_B
            return state.force[cells]
        # M_A at node b of cell c is C[c, b, A]: N_std is 1 at its own node
        return np.einsum("cba,ca->cb", self.gap_model.coefficients_std, state.force[cells])

    def contact_force(self) -> float:
        """Total normal contact force ``∫ p* dA = Σ_A W_A p_A`` over all ranks."""
        n = self.slave.layout.num_owned
        p = self.nodal_pressures()
        # the weights of the configuration the bases live in
        W = self.gap_model.lumped_weights
        return float(self.mesh.comm.allreduce(float(np.sum((W * p)[:n]))))

    def _open_output(self, path: Path) -> None:
        self._output = XdmfSeries(path, self.mesh)
        self._surface_output = SlaveSurfaceOutput(self.slave, surface_output_path(path))

    def _write_step(self, t: float, state: ContactState) -> None:
        """Add the step to both files; each is complete on disk after it
        (:mod:`dolfinx_mortar.io.xdmf_series`)."""
        pressures = self.nodal_pressures(state)
        self._output.write(self._output_functions(pressures), t)
        self._surface_output.write({"p_hat": pressures[self.slave.cells],
                                    "p_star": self.mortar_traction(state)}, t)

    def _output_functions(self, pressures: FloatArray) -> tuple[fem.Function, fem.Function]:
        mesh = self.mesh
        if not hasattr(self, "_out_spaces"):
            V1 = fem.VectorFunctionSpace(mesh, ("Lagrange", mesh.geometry.cmap.degree))
            Q, q_to_v = self.V.sub(0).collapse()
            self._out_spaces = (V1, Q, np.asarray(q_to_v) // self.V.dofmap.index_map_bs)
        V1, Q, q_nodes = self._out_spaces
        u1 = fem.Function(V1, name="displacement")
        u1.interpolate(self.u)
        p = fem.Function(Q, name="contact_pressure")
        p.x.array[:] = pressures[q_nodes]
        if Q.ufl_element().degree() != mesh.geometry.cmap.degree:
            Q1 = fem.FunctionSpace(mesh, ("Lagrange", mesh.geometry.cmap.degree))
            p1 = fem.Function(Q1, name="contact_pressure")
            p1.interpolate(p)
            p = p1
        return u1, p

    @classmethod
    def from_two_meshes(cls, mesh_a, facet_tags_a, slave_tag: int, mesh_b, facet_tags_b,
                        master_tag: int, degree: int = 1, *, tag_offset: int = 0,
                        shared_tags: Sequence[int] = (), **kwargs) -> "ContactProblem":
        """The contact of a slave body and an elastic master meshed separately.

        Merges the meshes into one (:func:`dolfinx_mortar.io.merge_meshes.merge_meshes`:
        same cell type and geometry degree, any MPI distribution), builds the
        vector Lagrange space of ``degree`` on it and returns the problem.

        Parameters
        ----------
        mesh_a, facet_tags_a, slave_tag
            The slave body, its facet tags and the tag of its contact facets.
        mesh_b, facet_tags_b, master_tag
            The master body, its facet tags and the tag of its contact facets,
            in mesh_b's own values (shifted by ``tag_offset`` here).
        degree
            Degree of the displacement space.
        tag_offset, shared_tags
            How b's tag values enter the merged mesh: ``v + tag_offset``,
            except ``shared_tags`` (kept); see :mod:`dolfinx_mortar.io.merge_meshes`.
        **kwargs
            Passed to :class:`ContactProblem` (``E``, ``nu``, ``penalty``, ...).
            The keys of ``fixed`` and ``tractions`` are merged tag values.

        The merged facet and cell tags (1 on a's cells, 2 on b's) are kept as
        ``problem.facet_tags`` and ``problem.cell_tags``.
        """
        from dolfinx_mortar.io.merge_meshes import merge_meshes
        mesh, facet_tags, cell_tags = merge_meshes(mesh_a, facet_tags_a, mesh_b, facet_tags_b,
                                                   tag_offset=tag_offset,
                                                   shared_tags=shared_tags)
        if master_tag not in {int(t) for t in shared_tags}:
            master_tag = master_tag + tag_offset
        V = fem.VectorFunctionSpace(mesh, ("Lagrange", degree))
        problem = cls(V, facet_tags, slave_tag, master_tag=master_tag, **kwargs)
        problem.facet_tags, problem.cell_tags = facet_tags, cell_tags
        return problem


class AugmentedNewtonStep:
    """Exact Newton step for GLS/GLS* through the sparse augmented system.

    With y = d̄ and z = L⁻¹ ω⟨y⟩ (DESIGN.md §3), the Newton matrix
    ``K + Ĝᵀ L⁻¹ diag(ωH) L⁻¹ Ĝ`` is the Schur complement of

        [ K    0     Ĝᵀ ] [Δu]   [r]
        [ 0    ωH   −L  ] [Δy] = [0]
        [ Ĝ   −L     0  ] [Δz]   [0]

    which is sparse: it is assembled (MatNest → AIJ) and factorized (MUMPS by
    default; options prefix ``dolfinx_mortar_augmented_``), and its Δu is the
    step. No dense slave block is formed. Used as a PETSc python PC.
    """

    def __init__(self, comm: MPI.Comm, prefix: str):
        self.comm = comm
        self.prefix = prefix
        self.ksp: Optional[PETSc.KSP] = None
        #: wall time of the factorizations (a linear-solve cost spent in the Jacobian callback)
        self.factorization_time = 0.0

    def update(self, K: PETSc.Mat, G: PETSc.Mat, weights: FloatArray, L: PETSc.Mat,
               G_linearized: Optional[PETSc.Mat] = None,
               surface: Optional[npt.NDArray[np.int64]] = None) -> None:
        """Assemble and factorize; ``G_linearized`` replaces Ĝ in the last row
        (the pointwise active set's Ĝ⁺, with ``weights`` = ω).

        ``surface``: the owned rows of L that belong to slave nodes (local
        indices). The slave layout of a DOLFINx surface spans every mesh node;
        the other rows of L are unit rows with Ĝ = 0, their y and z are 0, and
        dropping them halves the augmented system (GLS Jacobians went 5×
        slower than the dual kind's before).
        """
        G_last = G if G_linearized is None else G_linearized
        if surface is not None:
            offset = L.getOwnershipRange()[0]
            rows = PETSc.IS().createGeneral((offset + surface).astype(PETSc.IntType),
                                            comm=self.comm)
            start, end = G.getOwnershipRangeColumn()
            cols = PETSc.IS().createStride(end - start, first=start, step=1, comm=self.comm)
            L = L.createSubMatrix(rows, rows)
            G = G.createSubMatrix(rows, cols)
            G_last = G if G_linearized is None else G_linearized.createSubMatrix(rows, cols)
            weights = weights[surface]
        layout_vec = L.createVecLeft()
        layout_vec.array[:] = weights[: layout_vec.getLocalSize()]
        S = PETSc.Mat().createAIJ(L.getSizes(), nnz=(1, 0), comm=L.comm)
        S.setDiagonal(layout_vec)
        S.assemble()
        minus_L = L.copy()
        minus_L.scale(-1.0)
        GT = G.copy().transpose()
        nest = PETSc.Mat().createNest([[K, None, GT], [None, S, minus_L],
                                       [G_last, minus_L, None]],
                                      comm=self.comm)
        self.index_sets = nest.getNestISs()[0]
        A = nest.convert("aij")
        if self.ksp is None:
            self.ksp = PETSc.KSP().create(self.comm)
            self.ksp.setType("preonly")
            self.ksp.getPC().setType("lu")
            self.ksp.getPC().setFactorSolverType("mumps")
            self.ksp.setOptionsPrefix(self.prefix)
            self.ksp.setFromOptions()
        self.ksp.setOperators(A)
        clock = time.perf_counter()
        self.ksp.setUp()
        self.factorization_time += time.perf_counter() - clock
        self.A = A
        self.rhs, self.sol = A.createVecRight(), A.createVecLeft()

    def apply(self, pc: PETSc.PC, x: PETSc.Vec, y: PETSc.Vec) -> None:
        self.rhs.zeroEntries()
        part = self.rhs.getSubVector(self.index_sets[0])
        x.copy(part)
        self.rhs.restoreSubVector(self.index_sets[0], part)
        self.ksp.solve(self.rhs, self.sol)
        part = self.sol.getSubVector(self.index_sets[0])
        part.copy(y)
        self.sol.restoreSubVector(self.index_sets[0], part)
