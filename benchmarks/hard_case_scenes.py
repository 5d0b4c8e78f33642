"""Scenes and measurements of the hard cases (issue 5: numerical stability).

Every function here builds one hard scene, solves or assembles it and returns
plain numbers; ``benchmarks/hard_cases.py`` prints them as a table and
``tests/contact/test_hard_cases.py`` holds them to pass criteria. Keeping the scenes in
one place means the table and the tests report the very same numbers.

Operator-level cases (the sweep, the quadratic facets) run on ``COMM_SELF`` on
every rank: they measure dense condition numbers, which need the whole matrix,
and each rank gets the same numbers. Problem-level cases run on ``COMM_WORLD``.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from demo_support.hertz_fit import fit_hertz_profile
from dolfinx_mortar.dolfinx_compat import create_mesh, geometry_dofmap
from demo_support.scripts import load_demo

ALL_KINDS = ("GLS", "GLS*", "LmLS", "LmLS*", "LcLS*", "LcLS")
DUAL_KINDS = ("LcLS*", "LcLS")


# -- helpers -------------------------------------------------------------------------
def gather_dense(mat: PETSc.Mat) -> np.ndarray:
    """A (small) distributed PETSc matrix as a dense array on every rank."""
    comm = mat.comm.tompi4py()
    lo, _ = mat.getOwnershipRange()
    indptr, indices, data = mat.getValuesCSR()
    rows = np.repeat(np.arange(len(indptr) - 1) + lo, np.diff(indptr))
    parts = comm.allgather((rows, indices, data))
    out = np.zeros(mat.getSize())
    for r, c, v in parts:
        np.add.at(out, (r, c), v)
    return out


def gather_vector(vec: PETSc.Vec) -> np.ndarray:
    """The owned entries of a distributed vector, in global order, on every rank."""
    comm = vec.comm.tompi4py()
    return np.concatenate(comm.allgather(vec.array.copy()))


def facet_tags_from(domain, marks):
    """Facet meshtags from ``[(tag, where(x) -> bool mask), ...]`` (boundary facets)."""
    from dolfinx import mesh
    fdim = domain.topology.dim - 1
    facets, values = [], []
    for tag, where in marks:
        f = mesh.locate_entities_boundary(domain, fdim, where)
        facets.append(f)
        values.append(np.full(len(f), tag, dtype=np.int32))
    facets, values = np.concatenate(facets), np.concatenate(values)
    facets, first = np.unique(facets, return_index=True)  # first mark wins
    return mesh.meshtags(domain, fdim, facets.astype(np.int32), values[first])


def gather_sparse(mat: PETSc.Mat):
    """A distributed PETSc matrix as a SciPy CSR matrix on every rank."""
    import scipy.sparse
    comm = mat.comm.tompi4py()
    lo, _ = mat.getOwnershipRange()
    indptr, indices, data = mat.getValuesCSR()
    rows = np.repeat(np.arange(len(indptr) - 1) + lo, np.diff(indptr))
    parts = comm.allgather((rows, indices, data))
    r, c, v = (np.concatenate([p[i] for p in parts]) for i in range(3))
    return scipy.sparse.csr_matrix((v, (r, c)), shape=mat.getSize())


def gmsh_mesh(comm: MPI.Comm, dim: int, build):
    """A DOLFINx mesh and facet tags from a gmsh model that ``build()`` makes on
    rank 0 (geometry, physical groups, sizes); meshed in ``dim`` dimensions."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            build()
            gmsh.model.mesh.generate(dim)
        domain, _, tags = model_to_mesh(gmsh.model, comm, 0, gdim=dim)
    finally:
        gmsh.finalize()
    return domain, tags


def newton_matrix(problem):
    """Newton matrix (SciPy sparse, on every rank) at the current u, and the
    mask of its free dofs.

    For the local kinds this is the assembled Jacobian; for GLS/GLS* the
    Schur complement ``K + Ĝᵀ L⁻¹ diag(ωH) L⁻¹ Ĝ`` of the augmented system
    (docs/DESIGN.md, §Augmented step), formed here only to measure it (dense only on the slave
    dofs).
    """
    import scipy.sparse
    u = problem.u.x.petsc_vec
    J = problem.problem.matrix()
    problem.problem.F(u, problem.problem.vector())
    problem.problem.J(u, J)
    cap = problem.contact._newton.entry.step  # the augmented system's own matrices (a diagnostic)
    if cap is not None:
        if cap.G_linearized is not None and cap.G_linearized is not cap.G:
            raise NotImplementedError("condition numbers of the pointwise GLS step")
        K, G, L = gather_sparse(cap.K), gather_sparse(cap.G), gather_dense(cap.L)
        w = np.concatenate(problem.mesh.comm.allgather(
            cap.weights[: problem.slave.layout.num_owned]))
        cols = np.unique(G.indices)
        LG = np.linalg.solve(L, G[:, cols].toarray())
        block = LG.T @ (w[:, None] * LG)
        r, c = np.meshgrid(cols, cols, indexing="ij")
        A = (K + scipy.sparse.csr_matrix((block.ravel(), (r.ravel(), c.ravel())),
                                         shape=K.shape)).tocsr()
    else:
        A = gather_sparse(J)
    free = gather_vector(problem.contact._newton.mask(problem.bcs)) > 0.5
    return A, free


def condition(A, free: Optional[np.ndarray] = None) -> float:
    """2-norm condition number of A (restricted to the free dofs): dense SVD
    for a dense array, extreme eigenvalues for a sparse symmetric positive
    definite matrix (Lanczos; the smallest by shift-invert about 0)."""
    if free is not None:
        A = A[np.ix_(free, free)] if isinstance(A, np.ndarray) else A[free][:, free]
    if isinstance(A, np.ndarray):
        return float(np.linalg.cond(A))
    import scipy.sparse.linalg as sla
    A = A.tocsc()
    asym = abs(A - A.T).max() / abs(A).max()
    if asym > 1e-10:
        raise ValueError(f"the matrix is not symmetric (relative asymmetry {asym:.1e})")
    v0 = np.ones(A.shape[0])  # a fixed start vector: the same numbers on every rank
    big = sla.eigsh(A, k=1, which="LM", v0=v0, return_eigenvectors=False)[0]
    small = sla.eigsh(A, k=1, sigma=0.0, which="LM", v0=v0, return_eigenvectors=False)[0]
    return float(big / small)


def slave_values(problem, values: np.ndarray) -> np.ndarray:
    """Owned values at the slave surface's nodes, gathered on every rank."""
    mine = problem.slave.owned_nodes
    return np.concatenate(problem.mesh.comm.allgather(values[mine]))


def slave_coordinates(problem) -> np.ndarray:
    mine = problem.slave.owned_nodes
    return np.concatenate(problem.mesh.comm.allgather(problem.slave.x[mine]))


def contact_force(problem) -> float:
    """Σ_A ω_A⟨d̄_A⟩ over the owned slave nodes (the total normal contact force)."""
    n = problem.slave.layout.num_owned
    state = problem.contact.evaluate()
    return problem.mesh.comm.allreduce(
        float(np.sum(state.weights[:n] * np.maximum(state.gaps[:n], 0.0))))


# -- 1. contact boundary sweeping across a slave element edge -----------------------
SWEEP_OFFSETS = (-0.5, -0.1, -1e-2, -1e-3, -1e-4, 0.0, 1e-4, 1e-3, 1e-2, 0.1, 0.5)


def _elastic_stiffness(V, E: float, nu: float) -> np.ndarray:
    import ufl
    from dolfinx import fem
    from dolfinx.fem import petsc as fem_petsc
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    a = ufl.inner(2 * mu * eps(u) + lmbda * ufl.tr(eps(u)) * ufl.Identity(len(u)), eps(v))
    A = fem_petsc.assemble_matrix(fem.form(a * ufl.dx))
    A.assemble()
    return gather_dense(A)


def sweep(kinds=ALL_KINDS, nx: int = 8, offsets=SWEEP_OFFSETS, penalty: float = 1e3,
          E: float = 1.0, nu: float = 0.3) -> list[dict]:
    """Move a master block's left end across slave node 3 of an 8-element slave face.

    Slave: [0,1]×[−½,0] (nx×4 triangles), face y = 0, bottom fixed. Master: the
    top face of a coarser block [s,s+1]×[0,½], rigid (its dofs are not
    unknowns). With ``t = (s − x_3)/h``, t → 0⁻ leaves a sliver of length |t|h
    on element [x_2, x_3], so node x_2 is barely touched. Per position:

    - ``cond_D``: the contact block, D over the touched slave nodes (for
      GLS/GLS*: ``S·D_N``);
    - ``cond_J``: the penalty Jacobian ``K + Gᵀ diag(εW) G`` (consistent
      scaling, every touched node active, ε = penalty·E/h) on the free dofs;
    - ``max_coefficient``: the largest |C| of ``M = N C`` on the covered cells.

    Dual kinds also with the consistent boundary modification.
    """
    from dolfinx import fem, mesh
    from dolfinx_mortar.surfaces.facet_surface import facet_surface
    from dolfinx_mortar.kinds import is_partition_of_unity, parse_kind
    from dolfinx_mortar.mortar.coupling import MortarCoupling, to_scipy
    comm = MPI.COMM_SELF
    h = 1.0 / nx
    lower = mesh.create_rectangle(comm, [[0, -0.5], [1, 0]], [nx, 4])
    upper = mesh.create_rectangle(comm, [[0, 0], [1, 0.5]], [5, 2])
    Vs = fem.functionspace(lower, ("Lagrange", 1, (lower.geometry.dim,)))
    Vm = fem.functionspace(upper, ("Lagrange", 1, (upper.geometry.dim,)))
    slave = facet_surface(Vs, facet_tags_from(lower, [(1, lambda x: np.isclose(x[1], 0))]), 1)
    master = facet_surface(Vm, facet_tags_from(upper, [(1, lambda x: np.isclose(x[1], 0))]), 1)
    K = _elastic_stiffness(Vs, E, nu)
    free = np.ones(K.shape[0], dtype=bool)
    bottom = fem.locate_dofs_geometrical(Vs, lambda x: np.isclose(x[1], -0.5))
    free[(bottom[:, None] * 2 + np.arange(2)).ravel()] = False
    eps = penalty * E / h
    x3 = 3 * h
    couplings = []
    for t in offsets:
        shift = np.zeros_like(master.x)
        shift[:, 0] = x3 + t * h
        couplings.append(MortarCoupling(slave, master, master_displacement=shift))
    rows = []
    for kind in kinds:
        for modified in ((False, True) if kind in DUAL_KINDS else (False,)):
            row = {"case": "sweep", "kind": kind, "boundary_modification": modified,
                   "offsets": list(offsets), "cond_D": [], "cond_J": [],
                   "max_coefficient": [], "covered_area": []}
            for c in couplings:
                op = c.operators(kind, boundary_modification=modified)
                touched = op.touched
                D = to_scipy(op.D).toarray()
                D[~touched] = 0.0   # drop the unit diagonal of untouched rows
                if op.is_global:    # D = S D_N, S = L⁻¹ or W L⁻¹
                    D = np.column_stack([op.apply_S(col) for col in D.T])
                W = op.basis.lumped_weights
                Dbar = D[touched] / (W[touched, None] if is_partition_of_unity(kind) else 1.0)
                G = np.zeros((touched.sum(), K.shape[0]))
                G[:, 1::2] = Dbar   # flat interface: n = ±e_y
                J = K + eps * G.T @ (W[touched, None] * G)
                row["cond_D"].append(condition(D[np.ix_(touched, touched)]))
                row["cond_J"].append(condition(J, free))
                if op.is_global:
                    coeff = np.nan
                else:
                    C = (c.covered_coefficients(parse_kind(kind)) if modified
                         else op.basis.coefficients)
                    coeff = float(np.max(np.abs(C[c.covered_area > 0])))
                row["max_coefficient"].append(coeff)
                row["covered_area"].append(c.total_covered_area)
            row["cond_K"] = condition(K, free)
            reference = row["cond_J"][list(offsets).index(0.0)]
            row["J_growth"] = max(row["cond_J"]) / reference
            row["D_growth"] = max(row["cond_D"]) / row["cond_D"][list(offsets).index(0.0)]
            rows.append(row)
    return rows


# -- 2. quadratic slave facets ----------------------------------------------------------
def quadratic_identities(kind: str, slave_type: str) -> dict:
    """D/M identities on a flat, fully covered quadratic slave patch.

    Slave: 3×3 jittered patch of ``slave_type`` ("P2-triangle", "Q8", "Q9";
    P2 triangles and Q8 with the transformed basis), master: a larger,
    non-matching 4×5 Q1 patch facing it. Constants and linear fields must be
    transferred exactly: ``D·f_s = M·f_m`` for f = 1, x, y (for GLS/GLS* on the
    slave-basis factors, S cancels); the covered area must be the slave area.
    """
    from dolfinx_mortar.mortar.coupling import MortarCoupling, to_scipy
    from dolfinx_mortar.surfaces.structured import flat_patch
    cell, serendipity = {"P2-triangle": ("triangle", False), "Q8": ("quadrilateral", True),
                         "Q9": ("quadrilateral", False)}[slave_type]
    transform = slave_type != "Q9"
    slave = flat_patch(cell, 2, 3, 3, jitter=0.2, seed=4, serendipity=serendipity,
                       quadratic_transform=transform)
    master = flat_patch("quadrilateral", 1, 4, 5, bounds=(-0.1, 1.1, -0.1, 1.1), up=False,
                        jitter=0.2, seed=5)
    c = MortarCoupling(slave, master)
    op = c.operators(kind)
    D, M = to_scipy(op.D).toarray(), to_scipy(op.M).toarray()
    D[~op.touched] = 0.0
    worst = 0.0
    for f in (lambda x: np.ones(len(x)), lambda x: x[:, 0], lambda x: x[:, 1]):
        lhs, rhs = D @ f(slave.x), M @ f(master.x)
        worst = max(worst, float(np.max(np.abs(lhs - rhs))) / float(np.max(np.abs(rhs))))
    area = c.total_covered_area
    return {"case": "quadratic-identities", "kind": kind, "variant": slave_type,
            "transfer_error": worst, "area_error": abs(area - 1.0),
            "failed_projections": c.failed_projections}


def patch_test_run(kind: str, dim: int, degree: int, fine: float, coarse: float,
                   orientation: str) -> dict:
    """The contact patch test of demos/patch_test.py (consistent scaling)."""
    demo = load_demo("patch_test")
    args = demo.parse_args(["--dim", str(dim), "--degree", str(degree), "--fine", str(fine),
                            "--coarse", str(coarse)])
    r = demo.run(args, orientation, kind, "consistent")
    r["case"] = "patch"
    return r


# -- 4. penalty sweep ----------------------------------------------------------------
def hertz2d_problem(kind: str, penalty_factor: float, refine: float = 0.3,
                    obstacle: str = "rigid"):
    """The hertz2d demo's scene as a ContactProblem (not yet solved)."""
    from dolfinx import fem
    from dolfinx_mortar.contact.obstacles import RigidPlane
    from dolfinx_mortar import ContactProblem
    demo = load_demo("hertz2d")
    args = demo.parse_args(["--refine", str(refine), "--obstacle", obstacle])
    ref = demo.hertz(args)
    domain, tags, h = demo.build_mesh(args, ref["a"], MPI.COMM_WORLD)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    fixed = {demo.SYMMETRY: {0: 0.0}}
    kwargs = {"obstacle": RigidPlane([0, 0], [0, 1])}
    if obstacle == "elastic":
        kwargs = {"master_tag": demo.MASTER}
        fixed[demo.FIXED] = {0: 0.0, 1: 0.0}
    problem = ContactProblem(V, tags, demo.SLAVE, E=args.E, nu=args.nu, kind=kind,
                             penalty=penalty_factor * args.E / h, fixed=fixed,
                             tractions={demo.LOAD: [0.0, -args.force / (2 * args.radius)]},
                             **kwargs)
    return problem, h, ref


PENALTY_FACTORS = (1e1, 1e2, 1e3, 1e4)


def penalty_sweep(kind: str, factors=PENALTY_FACTORS, refine: float = 0.3) -> dict:
    """Hertz 2D on a rigid plane at ε = factor·E/h: Newton iterations, the
    condition number of the Newton matrix at the solution, the largest
    penetration max d̄_A and its rate against ε (log-log slope)."""
    out = {"case": "penalty", "kind": kind, "factors": list(factors), "newton": [],
           "max_step_iterations": [], "penetration": [], "cond_J": []}
    for f in factors:
        problem, h, ref = hertz2d_problem(kind, f, refine)
        result = problem.solve(load_steps=2)
        out["newton"].append(result.newton_iterations)
        out["max_step_iterations"].append(max(s.newton_iterations for s in result.steps))
        gaps = slave_values(problem, problem.nodal_gaps())
        out["penetration"].append(float(np.max(gaps)))
        A, free = newton_matrix(problem)
        out["cond_J"].append(condition(A, free))
    logs = np.log(np.asarray(factors)), np.log(np.asarray(out["penetration"]))
    out["rate"] = float(np.polyfit(*logs, 1)[0])
    out["local_rates"] = list(np.diff(logs[1]) / np.diff(logs[0]))
    out["cond_rate"] = float(np.polyfit(logs[0], np.log(out["cond_J"]), 1)[0])
    return out


# -- 5. grazing contact ------------------------------------------------------------------
def disk_with_neck_mesh(R: float, h_contact: float, comm: MPI.Comm):
    """The lower half of the disk of radius R about (0, R) with a neck
    [−R, R] × [R, 1.5R] on top, graded towards the touching point (0, 0).

    Tags: 1 the arc (slave), 2 the top y = 1.5R, 3 the left side x = −R.
    """
    import gmsh
    from dolfinx_mortar.io.gmsh_io import grade_towards_point

    def build() -> None:
        occ = gmsh.model.occ
        # two arcs meeting at the touching point, then the neck
        p = [occ.addPoint(*q, 0.0) for q in ((-R, R), (0, 0), (R, R), (R, 1.5 * R),
                                             (-R, 1.5 * R))]
        centre = occ.addPoint(0.0, R, 0.0)
        curves = [occ.addCircleArc(p[0], centre, p[1]), occ.addCircleArc(p[1], centre, p[2]),
                  occ.addLine(p[2], p[3]), occ.addLine(p[3], p[4]), occ.addLine(p[4], p[0])]
        body = [(2, occ.addPlaneSurface([occ.addCurveLoop(curves)]))]
        occ.synchronize()
        groups: dict = {1: [], 2: [], 3: []}
        for _, curve in gmsh.model.getBoundary(body, oriented=False):
            x, y, _ = occ.getCenterOfMass(1, curve)
            if abs(y - 1.5 * R) < 1e-6 * R:
                groups[2].append(curve)
            elif abs(x + R) < 1e-6 * R and y > R:
                groups[3].append(curve)
            elif y < R - 1e-6 * R:
                groups[1].append(curve)
        for tag, curves in groups.items():
            gmsh.model.addPhysicalGroup(1, curves, tag)
        gmsh.model.addPhysicalGroup(2, [body[0][1]], 10)
        grade_towards_point((0.0, 0.0, 0.0), h_contact, R / 6, 0.15 * R,
                            0.15 * R + 30 * R / 6)

    domain, tags = gmsh_mesh(comm, 2, build)
    return domain, tags


def grazing(kind: str, force: float = 0.01, shear: float = 0.1, h_contact: float = 0.01,
            load_steps: int = 3) -> dict:
    """A disk touching a rigid plane at one point, loaded normally (traction
    F/(2R) down on the top) and tangentially (``shear``·F spread over the left
    side of the neck). Frictionless contact cannot carry the tangential load:
    the top is held tangentially (u_x = 0), which removes the sliding mode and
    the rolling about the centre. Equilibrium in y: contact force = F."""
    from dolfinx import fem
    from dolfinx_mortar.contact.obstacles import RigidPlane
    from dolfinx_mortar import ContactDivergenceError, ContactProblem
    R, E, nu = 1.0, 1.0, 0.3
    domain, tags = disk_with_neck_mesh(R, h_contact, MPI.COMM_WORLD)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, 1, obstacle=RigidPlane([0.0, 0.0], [0.0, 1.0]), E=E,
                             nu=nu, kind=kind, penalty=1e3 * E / h_contact,
                             fixed={2: {0: 0.0}},
                             tractions={2: [0.0, -force / (2 * R)],
                                        3: [shear * force / (0.5 * R), 0.0]})
    try:
        result = problem.solve(load_steps=load_steps)
    except ContactDivergenceError as err:
        last = err.history[-1]
        return {"case": "grazing", "kind": kind, "converged": False,
                "failed_load": err.load_factor, "attempts": len(err.history),
                "last_residuals": (last[2][0], last[2][-1]), "newton": np.nan,
                "cut_steps": len(err.history),
                "max_step_iterations": np.nan, "first_step_iterations": np.nan,
                "p_min": np.nan, "p_max": np.nan, "finite": False, "force_error": np.nan}
    p = slave_values(problem, problem.nodal_pressures())
    x = slave_coordinates(problem)[:, 0]
    return {"case": "grazing", "kind": kind, "converged": True,
            "newton": result.newton_iterations, "cut_steps": len(result.steps) - load_steps,
            "max_step_iterations": max(s.newton_iterations for s in result.steps),
            "first_step_iterations": result.steps[0].newton_iterations,
            "p_min": float(np.min(p)), "p_max": float(np.max(p)),
            "finite": bool(np.all(np.isfinite(p))), "active_nodes": int(np.sum(p > 0)),
            "pressure_centre": float(np.sum(x * p) / np.sum(p)),
            "force_error": contact_force(problem) / force - 1.0}


# -- 6. 3D coincident nodes and edges ------------------------------------------------------
LOWER_TOP, UPPER_BOTTOM, TOP, BOTTOM, SYM_X, SYM_Y = 1, 2, 3, 4, 5, 6


def stacked_boxes(cell: str, n: int, mirror_upper: bool, comm: MPI.Comm,
                  noise: float = 0.0, seed: int = 0):
    """Two unit blocks [0,1]²×[−½,0] and [0,1]²×[0,½] in one mesh, not joined:
    their interface meshes are identical (coincident nodes and edges). With
    ``mirror_upper`` the upper block is mirrored in x, so that its interface
    triangles have the other diagonal (coincident nodes, crossing edges).

    ``noise`` moves the upper block's interface nodes in the interface plane by
    up to ``noise`` times the element size, as two separately meshed conforming
    faces differ by round-off. The motion is in-plane: a normal one would be a
    real gap, which the penalty turns into a pressure change ε·δ."""
    import basix.ufl
    import ufl
    from dolfinx import mesh
    cell_type = {"tetrahedron": mesh.CellType.tetrahedron,
                 "hexahedron": mesh.CellType.hexahedron}[cell]
    parts = []
    for z0, mirror in ((-0.5, False), (0.0, mirror_upper)):
        block = mesh.create_box(MPI.COMM_SELF, [[0, 0, z0], [1, 1, z0 + 0.5]], [n, n, 2],
                                cell_type=cell_type)
        x = block.geometry.x.copy()
        if mirror:
            x[:, 0] = 1.0 - x[:, 0]
        if z0 == 0.0 and noise > 0:
            on = x[:, 2] == 0.0
            rng = np.random.default_rng(seed)
            x[on, :2] += noise / n * rng.uniform(-1.0, 1.0, (int(on.sum()), 2))
        cells = geometry_dofmap(block)[:block.topology.index_map(3).size_local]
        if mirror and cell == "tetrahedron":
            cells = cells[:, [1, 0, 2, 3]]   # keep a positive orientation
        if mirror and cell == "hexahedron":
            cells = cells[:, [1, 0, 3, 2, 5, 4, 7, 6]]
        parts.append((x, cells))
    if comm.rank == 0:
        x = np.vstack([parts[0][0], parts[1][0]])
        cells = np.vstack([parts[0][1], parts[1][1] + len(parts[0][0])]).astype(np.int64)
    else:
        x = np.zeros((0, 3))
        cells = np.zeros((0, parts[0][1].shape[1]), dtype=np.int64)
    element = basix.ufl.element("Lagrange", cell, 1, shape=(3,))
    domain = create_mesh(comm, cells, x, ufl.Mesh(element))
    # the interface facets: their (single) cell tells the body
    fdim = 2
    domain.topology.create_connectivity(fdim, 3)
    f2c = domain.topology.connectivity(fdim, 3)
    interface = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[2], 0.0))
    cell_z = mesh.compute_midpoints(domain, 3, np.array([f2c.links(f)[0] for f in interface],
                                                        dtype=np.int32))[:, 2]
    marks = [(SYM_X, lambda x: np.isclose(x[0], 0)), (SYM_Y, lambda x: np.isclose(x[1], 0)),
             (TOP, lambda x: np.isclose(x[2], 0.5)), (BOTTOM, lambda x: np.isclose(x[2], -0.5))]
    facets = [interface[cell_z < 0], interface[cell_z > 0]]
    values = [np.full(len(facets[0]), LOWER_TOP), np.full(len(facets[1]), UPPER_BOTTOM)]
    for tag, where in marks:
        f = mesh.locate_entities_boundary(domain, fdim, where)
        f = np.setdiff1d(f, interface)
        facets.append(f)
        values.append(np.full(len(f), tag))
    facets, values = np.concatenate(facets), np.concatenate(values).astype(np.int32)
    facets, first = np.unique(facets, return_index=True)
    return domain, mesh.meshtags(domain, fdim, facets.astype(np.int32), values[first])


def coincident_patch(kind: str, cell: str = "tetrahedron", mirror_upper: bool = False,
                     n: int = 4, pressure: float = 0.01, noise: float = 0.0) -> dict:
    """Patch test on two stacked blocks with coincident interface meshes (up to
    in-plane ``noise`` relative to the element size on the master's nodes)."""
    from dolfinx import fem
    from dolfinx_mortar.mortar.coupling import MortarCoupling
    from dolfinx_mortar import ContactProblem
    comm = MPI.COMM_WORLD
    domain, tags = stacked_boxes(cell, n, mirror_upper, comm, noise=noise)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    h = 1.0 / n
    problem = ContactProblem(V, tags, LOWER_TOP, master_tag=UPPER_BOTTOM, E=1.0, nu=0.3,
                             kind=kind, penalty=1e3 / h,
                             fixed={SYM_X: {0: 0.0}, SYM_Y: {1: 0.0}, BOTTOM: {2: 0.0}},
                             tractions={TOP: [0.0, 0.0, -pressure]})
    result = problem.solve(load_steps=1)
    p = slave_values(problem, problem.nodal_pressures())
    coupling = MortarCoupling(problem.slave, problem.master)
    return {"case": "coincident", "kind": kind,
            "variant": f"{cell}{'-crossing' if mirror_upper else ''}",
            "noise": noise,
            "max_relative_deviation": float(np.max(np.abs(p / pressure - 1.0))),
            "area_error": abs(coupling.total_covered_area - 1.0),
            "failed_projections": coupling.failed_projections,
            "newton": result.newton_iterations}


# -- 7. curved on curved: Hertz with two elastic bodies ----------------------------------
def _tag_two_bodies(dim: int, upper, lower, flat: list) -> None:
    """Physical groups of the two curved bodies of the curved-on-curved scenes.

    A boundary entity gets the tag of the first ``(tag, test(centre))`` of
    ``flat`` that holds, else 1 (upper body: slave) or 2 (lower body: master);
    the bodies are volumes 10 and 11.
    """
    import gmsh
    groups: dict = {1: [], 2: [], **{tag: [] for tag, _ in flat}}
    for body, curved in ((upper, 1), (lower, 2)):
        for _, entity in gmsh.model.getBoundary(body, oriented=False):
            centre = gmsh.model.occ.getCenterOfMass(dim - 1, entity)
            tag = next((t for t, holds in flat if holds(centre)), curved)
            groups[tag].append(entity)
    for tag, entities in groups.items():
        gmsh.model.addPhysicalGroup(dim - 1, entities, tag)
    gmsh.model.addPhysicalGroup(dim, [upper[0][1]], 10)
    gmsh.model.addPhysicalGroup(dim, [lower[0][1]], 11)


def two_cylinders_mesh(R1: float, R2: float, h_contact: float, a: float, comm: MPI.Comm):
    """Quarter of the lower half of a disk R1 about (0, R1) above a quarter of
    the upper half of a disk R2 about (0, −R2); symmetry x = 0.

    Tags: 1 upper arc (slave), 2 lower arc (master), 3 x = 0, 4 load y = R1,
    5 fixed y = −R2.
    """
    import gmsh
    from dolfinx_mortar.io.gmsh_io import grade_towards_point

    def build() -> None:
        occ = gmsh.model.occ
        upper, _ = occ.intersect([(2, occ.addDisk(0, R1, 0, R1, R1))],
                                 [(2, occ.addRectangle(0, 0, 0, R1, R1))])
        lower, _ = occ.intersect([(2, occ.addDisk(0, -R2, 0, R2, R2))],
                                 [(2, occ.addRectangle(0, -R2, 0, R2, R2))])
        occ.synchronize()
        _tag_two_bodies(2, upper, lower, [(3, lambda c: abs(c[0]) < 1e-6),
                                          (4, lambda c: abs(c[1] - R1) < 1e-6),
                                          (5, lambda c: abs(c[1] + R2) < 1e-6)])
        size_max = min(R1, R2) / 8
        grade_towards_point((0, 0, 0), h_contact, size_max, 1.5 * a,
                            1.5 * a + 40 * size_max)

    domain, tags = gmsh_mesh(comm, 2, build)
    return domain, tags


def two_cylinders(kind: str, R1: float = 1.0, R2: float = 2.0, force: float = 0.01,
                  refine: float = 0.5) -> dict:
    """Two elastic cylinders (plane strain, same material) against Hertz with
    1/R = 1/R1 + 1/R2 and E* = E/(2(1−ν²))."""
    from dolfinx import fem
    from dolfinx_mortar import ContactProblem
    E, nu = 1.0, 0.3
    R = R1 * R2 / (R1 + R2)
    E_star = E / (2 * (1 - nu ** 2))
    a = np.sqrt(4 * force * R / (np.pi * E_star))
    p0 = 2 * force / (np.pi * a)
    h = a / (40 * refine)
    domain, tags = two_cylinders_mesh(R1, R2, h, a, MPI.COMM_WORLD)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, 1, master_tag=2, E=E, nu=nu, kind=kind,
                             penalty=1e3 * E / h, fixed={3: {0: 0.0}, 5: {1: 0.0}},
                             tractions={4: [0.0, -force / (2 * R1)]})
    result = problem.solve(load_steps=3)
    p = slave_values(problem, problem.nodal_pressures())
    x = slave_coordinates(problem)[:, 0]
    fit = fit_hertz_profile(x, p, a)
    return {"case": "cylinders", "kind": kind, "p0_error": fit.p0 / p0 - 1,
            "a_error": fit.a / a - 1, "newton": result.newton_iterations,
            "force_error": contact_force(problem) / (force / 2) - 1,
            "dofs": V.dofmap.index_map.size_global * 2}


def sphere_gap(r: float, R1: float, R2: float) -> float:
    """Initial distance between the two spheres at distance r from the axis."""
    return (R1 - np.sqrt(R1 ** 2 - r ** 2)) + (R2 - np.sqrt(R2 ** 2 - r ** 2))


def two_spheres_mesh(R1: float, R2: float, h_contact: float, a: float, comm: MPI.Comm,
                     cap: Optional[float] = None):
    """Octants: the lower quarter-hemisphere of a sphere R1 about (0,0,R1) above
    the upper quarter-hemisphere of a sphere R2 about (0,0,−R2); symmetry x = 0
    and y = 0. Tags: 1 slave, 2 master, 3 x = 0, 4 y = 0, 5 load z = R1,
    6 fixed z = −R2, 7 free rest of the upper sphere.

    ``cap``: the slave is only the part of the upper sphere within this
    distance of the axis (facet midpoints), the rest gets tag 7. A slave
    reaching where the master falls out of the search radius has partly
    covered cells there, and the dual kinds' negative lobes turn their large
    negative gaps into spurious positive nodal gaps (hundreds of times p0).
    """
    import gmsh
    from dolfinx import mesh as dmesh
    from dolfinx_mortar.io.gmsh_io import grade_towards_point

    def build() -> None:
        occ = gmsh.model.occ
        upper, _ = occ.intersect([(3, occ.addSphere(0, 0, R1, R1))],
                                 [(3, occ.addBox(0, 0, 0, R1, R1, R1))])
        lower, _ = occ.intersect([(3, occ.addSphere(0, 0, -R2, R2))],
                                 [(3, occ.addBox(0, 0, -R2, R2, R2, R2))])
        occ.synchronize()
        _tag_two_bodies(3, upper, lower, [(3, lambda c: abs(c[0]) < 1e-6),
                                          (4, lambda c: abs(c[1]) < 1e-6),
                                          (5, lambda c: abs(c[2] - R1) < 1e-6),
                                          (6, lambda c: abs(c[2] + R2) < 1e-6)])
        size_max = min(R1, R2) / 5
        grade_towards_point((0, 0, 0), h_contact, size_max, 1.3 * a,
                            1.3 * a + 12 * size_max)

    domain, tags = gmsh_mesh(comm, 3, build)
    if cap is not None:
        fdim = domain.topology.dim - 1
        values = tags.values.copy()
        slave = tags.indices[values == 1]
        mid = dmesh.compute_midpoints(domain, fdim, slave)
        values[np.isin(tags.indices, slave[np.linalg.norm(mid[:, :2], axis=1) > cap])] = 7
        tags = dmesh.meshtags(domain, fdim, tags.indices, values)
    return domain, tags


def two_spheres(kind: str, R1: float = 1.0, R2: float = 1.0, force: float = 0.0015,
                refine: float = 1.0, cap: float = 1.5) -> dict:
    """Two elastic spheres against Hertz with R = R1R2/(R1+R2), E* = E/(2(1−ν²)).

    The slave is the cap r < ``cap``·a of the upper sphere (the contact zone
    and a margin), the master the whole lower quarter-hemisphere; the search
    radius reaches twice the spheres' distance at the cap's edge, so that every
    slave cell is fully covered (see :func:`two_spheres_mesh`).
    """
    import time
    from dolfinx import fem
    from dolfinx_mortar import ContactProblem
    clock = time.perf_counter()
    E, nu = 1.0, 0.3
    R = R1 * R2 / (R1 + R2)
    E_star = E / (2 * (1 - nu ** 2))
    a = (3 * force * R / (4 * E_star)) ** (1 / 3)
    p0 = 3 * force / (2 * np.pi * a ** 2)
    h = a / (8 * refine)
    domain, tags = two_spheres_mesh(R1, R2, h, a, MPI.COMM_WORLD, cap=cap * a)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, 1, master_tag=2, E=E, nu=nu, kind=kind,
                             penalty=1e3 * E / h,
                             fixed={3: {0: 0.0}, 4: {1: 0.0}, 6: {2: 0.0}},
                             tractions={5: [0.0, 0.0, -force / (np.pi * R1 ** 2)]},
                             search_radius=2 * sphere_gap(cap * a, R1, R2) + 2 * h)
    result = problem.solve(load_steps=3)
    p = slave_values(problem, problem.nodal_pressures())
    r = np.linalg.norm(slave_coordinates(problem)[:, :2], axis=1)
    fit = fit_hertz_profile(r, p, a)
    return {"case": "spheres", "kind": kind, "p0_error": fit.p0 / p0 - 1,
            "p0_max_error": fit.p_max / p0 - 1,
            "a_error": fit.a / a - 1, "newton": result.newton_iterations,
            "force_error": contact_force(problem) / (force / 4) - 1,
            "dofs": V.dofmap.index_map.size_global * 3,
            "wall_time": time.perf_counter() - clock}


# -- 1b. the master's edge sweeping over a slave facet, elastic master, in the solver ---
SLIVERS = (0.5, 0.1, 1e-2, 1e-3, 1e-4)
SLIVER_GAP = 0.05


def sliver_blocks(sliver: float, comm: MPI.Comm, h: float = 0.1):
    """A lower block [0,1]×[−½,0] meshed with slave nodes every h along its top,
    and an upper block [x0, 0.9]×[GAP, ½] whose bottom (the master) starts at
    x0 = 0.4 − sliver·h: the slave facet [0.3, 0.4] is covered over a length
    sliver·h. Tags: 1 slave, 2 master, 3 lower bottom, 4 upper top."""
    import gmsh

    def build() -> None:
        occ = gmsh.model.occ
        lower = occ.addRectangle(0, -0.5, 0, 1, 0.5)
        x0 = 0.4 - sliver * h
        upper = occ.addRectangle(x0, SLIVER_GAP, 0, 0.9 - x0, 0.5 - SLIVER_GAP)
        occ.synchronize()
        groups: dict = {k: [] for k in range(1, 5)}
        for body in (lower, upper):
            for _, c in gmsh.model.getBoundary([(2, body)], oriented=False):
                _, y, _ = occ.getCenterOfMass(1, c)
                for tag, level in ((1, 0.0), (2, SLIVER_GAP), (3, -0.5), (4, 0.5)):
                    if abs(y - level) < 1e-9:
                        groups[tag].append(c)
                if body == lower:   # the slave nodes every h along the top
                    n = round(1 / h) + 1 if abs(abs(y) - 0.25) > 0.2 else round(0.5 / h) + 1
                    gmsh.model.mesh.setTransfiniteCurve(c, n)
        gmsh.model.mesh.setTransfiniteSurface(lower)
        for tag, curves in groups.items():
            gmsh.model.addPhysicalGroup(1, curves, tag)
        gmsh.model.addPhysicalGroup(2, [lower], 11)
        gmsh.model.addPhysicalGroup(2, [upper], 12)
        gmsh.model.mesh.setSize(gmsh.model.getBoundary([(2, upper)], recursive=True), 0.13)

    domain, tags = gmsh_mesh(comm, 2, build)
    return domain, tags


def sliver_boxes(sliver: float, comm: MPI.Comm, h: float = 0.2):
    """3D version of :func:`sliver_blocks`: a structured lower box [0,1]²×[−½,0]
    (slave nodes every h on its top) and an upper box [x0, 0.9]×[0,1]×[GAP, ½]
    with x0 = 0.4 − sliver·h. Same tags."""
    import gmsh

    def build() -> None:
        occ = gmsh.model.occ
        lower = occ.addBox(0, 0, -0.5, 1, 1, 0.5)
        x0 = 0.4 - sliver * h
        upper = occ.addBox(x0, 0, SLIVER_GAP, 0.9 - x0, 1, 0.5 - SLIVER_GAP)
        occ.synchronize()
        # structured triangles on the slave face only: its nodes every h
        for _, f in gmsh.model.getBoundary([(3, lower)], oriented=False):
            if abs(occ.getCenterOfMass(2, f)[2]) < 1e-9:
                for _, c in gmsh.model.getBoundary([(2, f)], oriented=False):
                    gmsh.model.mesh.setTransfiniteCurve(c, round(1 / h) + 1)
                gmsh.model.mesh.setTransfiniteSurface(f)
        groups: dict = {k: [] for k in range(1, 5)}
        for body in (lower, upper):
            for _, f in gmsh.model.getBoundary([(3, body)], oriented=False):
                _, _, z = occ.getCenterOfMass(2, f)
                for tag, level in ((1, 0.0), (2, SLIVER_GAP), (3, -0.5), (4, 0.5)):
                    if abs(z - level) < 1e-9:
                        groups[tag].append(f)
        for tag, faces in groups.items():
            gmsh.model.addPhysicalGroup(2, faces, tag)
        gmsh.model.addPhysicalGroup(3, [lower], 11)
        gmsh.model.addPhysicalGroup(3, [upper], 12)
        gmsh.model.mesh.setSize(gmsh.model.getEntities(0), 0.27)

    domain, tags = gmsh_mesh(comm, 3, build)
    return domain, tags


def elastic_sweep(kind: str, modification: bool, slivers=SLIVERS, dim: int = 2) -> dict:
    """cond of the Newton matrix at the solution while the master's edge leaves
    a sliver·h of a slave facet covered (upper block pressed 1.5·GAP down)."""
    from dolfinx import fem
    from dolfinx_mortar import ContactProblem
    out = {"case": "sweep-elastic", "kind": kind, "modified": modification, "dim": dim,
           "slivers": list(slivers), "cond_J": [], "newton": [], "p_ratio": []}
    for sliver in slivers:
        build, h = (sliver_blocks, 0.1) if dim == 2 else (sliver_boxes, 0.2)
        domain, tags = build(sliver, MPI.COMM_WORLD)
        V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
        down = {k: 0.0 for k in range(dim - 1)}
        problem = ContactProblem(V, tags, 1, master_tag=2, E=1.0, nu=0.3, kind=kind,
                                 penalty=1e3 / h, boundary_modification=modification,
                                 fixed={3: {k: 0.0 for k in range(dim)},
                                        4: {**down, dim - 1: -1.5 * SLIVER_GAP}})
        result = problem.solve(load_steps=1)
        out["newton"].append(result.newton_iterations)
        A, free = newton_matrix(problem)
        out["cond_J"].append(condition(A.toarray(), free))
        p = slave_values(problem, problem.nodal_pressures())
        # the largest nodal pressure against the typical one: a sliver node that
        # takes far more than its share is the trouble the seed warns about
        out["p_ratio"].append(float(np.max(np.abs(p)) / np.median(p[p > 0])))
    out["J_growth"] = max(out["cond_J"]) / out["cond_J"][0]
    out["p_ratio_max"] = max(out["p_ratio"])
    return out


# -- pass criteria (shared by the tests and the table) ----------------------------------
#: (metric, "<=" or ">=", limit) per case; a row passes when all hold
CRITERIA = {
    "sweep-jacobian": [("J_growth", "<=", 2.0)],
    "sweep-elastic": [("J_growth", "<=", 10.0)],
    "sweep-elastic-pressure": [("p_ratio_max", "<=", 20.0)],
    "sweep-contact-block": [("D_growth", "<=", 1e3)],
    "sweep-modified-coefficients": [("coefficient_growth", "<=", 1e3)],
    "quadratic-identities": [("transfer_error", "<=", 1e-12), ("area_error", "<=", 1e-12)],
    "patch": [("max_relative_deviation", "<=", 1e-8)],
    "penalty": [("rate_deviation", "<=", 0.05), ("max_step_iterations", "<=", 10),
                ("cond_rate", "<=", 1.1)],
    # converged without cutting a load step, pressures non-negative, y-equilibrium
    "grazing": [("converged", ">=", 1), ("cut_steps", "<=", 0), ("p_min", ">=", 0.0),
                ("force_error_abs", "<=", 1e-8)],
    "coincident": [("max_relative_deviation", "<=", 1e-8), ("area_error", "<=", 1e-12),
                   ("failed_projections", "<=", 0)],
    # zero load, bodies touching at one point: no node may penetrate (beyond 1e-6 h)
    "spurious-gap": [("max_gap_over_h", "<=", 1e-6)],
    "cylinders": [("p0_error_abs", "<=", 0.03), ("a_error_abs", "<=", 0.03)],
    # fitted Hertz profile (the largest nodal pressure scatters +31% for LmLS/LmLS*)
    # p0 ≤ 9%: LmLS(*) nodal pressures scatter on tetrahedra, and the fitted
    # profile (zeros at r < 2a included) gives them p0 +8.1%, a −4.1%; the
    # positive nodes alone gave +4.0%, +2.0% (docs/BENCHMARKS.md, estimators)
    "spheres": [("p0_error_abs", "<=", 0.09), ("a_error_abs", "<=", 0.06)],
}


def derived(case: str, row: dict) -> dict:
    """The metrics of CRITERIA[case] from a scene's row."""
    out = dict(row)
    if case == "sweep-modified-coefficients":
        c = np.asarray(row["max_coefficient"])
        out["coefficient_growth"] = float(np.max(c) / c[row["offsets"].index(0.0)])
    if "max_gap" in row:
        out["max_gap_over_h"] = row["max_gap"] / row["h"]
    if isinstance(row.get("max_step_iterations"), list):
        out["max_step_iterations"] = max(row["max_step_iterations"])
    if "rate" in row:
        out["rate_deviation"] = abs(row["rate"] + 1.0)
    for key in ("force_error", "p0_error", "a_error"):
        if key in row:
            out[key + "_abs"] = abs(row[key]) if np.isfinite(row[key]) else np.inf
    if "converged" in row:
        out["converged"] = int(row["converged"])
    return out


def check(case: str, row: dict) -> list[tuple[str, float, str, float, bool]]:
    """(metric, value, op, limit, ok) for every criterion of the case."""
    values = derived(case, row)
    out = []
    for metric, op, limit in CRITERIA[case]:
        v = float(values[metric])
        ok = bool(v <= limit if op == "<=" else v >= limit) and not np.isnan(v)
        out.append((metric, v, op, limit, ok))
    return out


def spurious_gap(kind: str, refine: float = 0.15) -> dict:
    """Largest nodal gap d̄ (penetration) on the two-cylinder slave at zero load.

    The bodies touch at one point only, so no node may penetrate. Reports the
    largest d̄ over all slave nodes and over the nodes with no master below
    them (those get contact forces in the residual but no stiffness)."""
    from dolfinx import fem
    from dolfinx_mortar import ContactProblem
    a = 0.124
    h = a / (40 * refine)
    domain, tags = two_cylinders_mesh(1.0, 2.0, h, a, MPI.COMM_WORLD)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    problem = ContactProblem(V, tags, 1, master_tag=2, E=1.0, nu=0.3, kind=kind,
                             penalty=1e3 / h, fixed={3: {0: 0.0}, 5: {1: 0.0}},
                             tractions={4: [0.0, -0.005]})
    g = problem.nodal_gaps()
    uncovered = ~problem.gap_model.covered
    return {"case": "spurious-gap", "kind": kind,
            "max_gap": float(np.max(slave_values(problem, g))),
            "max_gap_uncovered": float(np.max(slave_values(problem, np.where(
                uncovered, g, -np.inf)))),
            "h": h}
