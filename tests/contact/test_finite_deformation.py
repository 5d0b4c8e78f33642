"""basis_configuration="current": exact residual and Jacobian on the current surface."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar.contact.obstacles import RigidPlane, RigidSphere
from dolfinx_mortar import ContactProblem
from support.jacobian_check import (convergence_order, energy_gradient_error, jacobian_error,
                                    newton_history)
from demo_support.boundary_tags import tag_boundary_facets
from support import load_demo
from support.scenes import LOCAL_KINDS, block_on_plane, pressed_block


def _cell_scene(cell: str, degree: int):
    """A curved (P2) or straight cell of a surface pressed into a rigid ball, its
    reference rule and basis, and the obstacle's gap at the points."""
    import basix
    from dolfinx_mortar import _kernels
    cell_type = basix.CellType[cell]
    X, w = basix.make_quadrature(cell_type, 2 * degree + 2)
    element = basix.create_element(basix.ElementFamily.P, cell_type, degree,
                                   basix.LagrangeVariant.gll_warped)
    tab = element.tabulate(1, X)
    N, dN = tab[0, :, :, 0], np.moveaxis(tab[1:, :, :, 0], 0, 1)
    nodes = element.points
    gdim = nodes.shape[1] + 1
    rng = np.random.default_rng(4)
    x = np.zeros((1, len(nodes), gdim))
    x[0, :, :gdim - 1] = nodes + 0.1 * rng.normal(size=nodes.shape)
    x[0, :, -1] = 0.05 * rng.normal(size=len(nodes))
    x[0, :, 0] += 0.5            # a meridian off the axis
    centre, radius = np.full(gdim, 0.5), 1.0
    centre[-1] = -0.95

    def obstacle(x):
        points = np.einsum("qb,cbi->cqi", N, x)
        r = points - centre
        s = np.linalg.norm(r, axis=-1)
        eye = np.eye(gdim)
        hess = -(eye - np.einsum("cqi,cqj->cqij", r, r) / s[..., None, None] ** 2) / s[
            ..., None, None]
        return {"obstacle_d": radius - s, "obstacle_gradient": -r / s[..., None],
                "obstacle_hessian": hess}
    return _kernels, x, N, dN, w, obstacle


@pytest.mark.parametrize("cell, degree, axisymmetric", [("interval", 1, False),
                                                         ("interval", 2, False),
                                                         ("interval", 2, True),
                                                         ("triangle", 1, False),
                                                         ("quadrilateral", 1, False)])
def test_current_surface_cells_derivatives_match_differences(cell, degree, axisymmetric):
    """The cells' W = ∫ N J and obstacle gaps ∫ φ J d from the kernel's Jets: the
    gradients against central differences of the values, the weighted Hessian
    against central differences of the gradients."""
    kernels, x, N, dN, w, obstacle = _cell_scene(cell, degree)
    phi = N @ np.linalg.inv(np.eye(N.shape[1]) + 0.2)   # some basis φ = N C

    def cells(x):
        return kernels.current_surface_cells(x, N, dN, w, phi, axisymmetric, **obstacle(x))
    r = cells(x)
    if not axisymmetric and cell == "interval":
        lengths = np.linalg.norm(np.diff(x[0, :2], axis=0)) if degree == 1 else None
        if lengths is not None:
            assert r.W.sum() == pytest.approx(lengths, rel=1e-14)
    wW, wg = np.linspace(0.5, 1.5, N.shape[1]), np.linspace(-1, 2, N.shape[1])
    H = kernels.current_surface_hessians(x, N, dN, w, phi, wW[None], axisymmetric,
                                         gap_weights=wg[None], **obstacle(x))[0]
    h = 1e-6
    flat = x.reshape(-1)
    for k in range(flat.size):
        e = np.zeros_like(flat)
        e[k] = h
        p, m = cells((flat + e).reshape(x.shape)), cells((flat - e).reshape(x.shape))
        assert np.allclose((p.W - m.W) / (2 * h), r.W_gradient[..., k], atol=1e-8)
        assert np.allclose((p.gap - m.gap) / (2 * h), r.gap_gradient[..., k], atol=1e-8)
        column = (wW @ (p.W_gradient - m.W_gradient)[0] + wg @ (p.gap_gradient
                                                                 - m.gap_gradient)[0]) / (2 * h)
        assert np.allclose(column, H[k], atol=1e-7)


def _deformed_block(kind, scaling, n=(8, 3)):
    """A block pressed into a rigid disk and sheared: several nodes active, and a
    displacement (5% of the block) large enough for the bases to change."""
    problem = pressed_block(RigidSphere([0.5, -2.0], 2.01), kind, n=n, scaling=scaling,
                            basis_configuration="current")
    problem.u.interpolate(lambda x: np.vstack([0.05 * x[1] + 0.1 * x[0] ** 2,
                                               -0.02 + 0.003 * x[0] ** 2 + 0.004 * x[0]]))
    return problem


@pytest.mark.parametrize("scaling", ["consistent", "seed"])
@pytest.mark.parametrize("kind", LOCAL_KINDS)
def test_current_residual_is_the_gradient_and_the_jacobian_is_exact(kind, scaling):
    problem = _deformed_block(kind, scaling)
    gaps = problem.nodal_gaps()
    n = problem.slave.layout.num_owned
    assert problem.mesh.comm.allreduce(int(np.sum(gaps[:n] > 0))) >= 3
    assert energy_gradient_error(problem) < 1e-6
    assert jacobian_error(problem) < 1e-7


def test_current_jacobian_is_exact_on_curved_p2_facets():
    domain = mesh.create_rectangle(MPI.COMM_WORLD, [[0, 0], [1, 0.5]], [6, 3])
    V = fem.functionspace(domain, ("Lagrange", 2, (domain.geometry.dim,)))
    _, tags = block_on_plane(n=(6, 3))
    tags = mesh.meshtags(domain, 1, tags.indices, tags.values)
    problem = ContactProblem(V, tags, 1, obstacle=RigidSphere([0.5, -2.0], 2.01), E=1.0,
                             nu=0.3, kind="LmLS*", penalty=50.0, fixed={3: {0: 0.0}},
                             tractions={2: [0.0, -0.01]}, basis_configuration="current")
    problem.set_load(1.0)
    # a curved slave surface: its area element varies along every facet
    problem.u.interpolate(lambda x: np.vstack([0.05 * x[0] ** 2,
                                               -0.02 + 0.03 * x[0] ** 2 - 0.02 * x[0] ** 3]))
    assert energy_gradient_error(problem) < 1e-6
    assert jacobian_error(problem) < 1e-7


def test_current_jacobian_is_exact_in_3d():
    domain = mesh.create_box(MPI.COMM_WORLD, [[0, 0, 0], [1, 1, 0.5]], [4, 4, 2])
    marks = [(1, lambda x: np.isclose(x[2], 0)), (2, lambda x: np.isclose(x[2], 0.5)),
             (3, lambda x: np.isclose(x[0], 0)), (4, lambda x: np.isclose(x[1], 0))]
    tags = tag_boundary_facets(domain, marks)
    V = fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,)))
    for kind in ("LcLS*", "LmLS"):
        problem = ContactProblem(V, tags, 1, obstacle=RigidSphere([0.5, 0.5, -2.0], 2.01),
                                 E=1.0, nu=0.3, kind=kind, penalty=50.0,
                                 fixed={3: {0: 0.0}, 4: {1: 0.0}},
                                 tractions={2: [0.0, 0.0, -0.01]},
                                 basis_configuration="current")
        problem.set_load(1.0)
        problem.u.interpolate(lambda x: np.vstack([0.05 * x[2] + 0.05 * x[0] * x[1],
                                                   0.03 * x[0], -0.02 + 0.004 * x[1]]))
        assert energy_gradient_error(problem) < 1e-6
        assert jacobian_error(problem) < 1e-7


def _hertz2d_mesh(refine: str = "0.4"):
    demo = load_demo("hertz2d")
    args = demo.parse_args(["--refine", refine])
    domain, tags, h = demo.build_mesh(args, demo.hertz(args)["a"], MPI.COMM_WORLD)
    return demo, fem.functionspace(domain, ("Lagrange", 1, (domain.geometry.dim,))), tags, h


def _hertz2d_problem(mesh_data, configuration: str, traction: float) -> ContactProblem:
    demo, V, tags, h = mesh_data
    return ContactProblem(V, tags, demo.SLAVE, obstacle=RigidPlane([0, 0], [0, 1]), E=1.0,
                          nu=0.3, kind="LcLS*", penalty=1e3 / h,
                          fixed={demo.SYMMETRY: {0: 0.0}},
                          tractions={demo.LOAD: [0.0, -traction]},
                          basis_configuration=configuration)


def test_current_newton_converges_quadratically_from_the_small_deformation_solution():
    """Strains of about 10%: the current surface moves the solution by a few percent."""
    mesh_data = _hertz2d_mesh()       # one mesh: the two problems share its layout
    initial = _hertz2d_problem(mesh_data, "initial", 0.02)
    initial.solve(load_steps=4)
    current = _hertz2d_problem(mesh_data, "current", 0.02)
    r = newton_history(initial, current, "quadratic_test_")
    # once at round-off the residual may bounce within it (1.8e-14 after 3.3e-15
    # with the l2 line search on 2 ranks): judge the best iterate
    assert np.min(r) < 1e-10 * r[0] and len(r) <= 5, r
    assert convergence_order(r) > 1.7, r


def test_previous_configuration_converges_to_current_as_the_steps_shrink():
    """'previous' lags the bases by one load step: its error is first order in the
    step, and it tends to the 'current' solution."""
    mesh_data = _hertz2d_mesh()
    demo = mesh_data[0]
    current = _hertz2d_problem(mesh_data, "current", 0.005)
    current.solve(load_steps=4)
    p_current = demo.contact_results(current, demo.hertz(demo.parse_args([])))["p0"]
    differences = []
    for steps in (4, 16):
        previous = _hertz2d_problem(mesh_data, "previous", 0.005)
        previous.solve(load_steps=steps)
        p0 = demo.contact_results(previous, demo.hertz(demo.parse_args([])))["p0"]
        differences.append(abs(p0 - p_current) / p_current)
    assert differences[1] < 0.35 * differences[0], differences   # ≈ ¼ per 4× steps
    assert differences[1] < 2e-3   # 8.4e-4 measured (16 steps)


def test_current_configuration_reports_what_it_cannot_do():
    V, tags = block_on_plane()
    common = dict(E=1.0, nu=0.3, penalty=10.0, basis_configuration="current")
    with pytest.raises(NotImplementedError, match="GLS"):
        ContactProblem(V, tags, 1, obstacle=RigidPlane([0, 0], [0, 1]), kind="GLS", **common)
    for cell_type, degree, message in ((mesh.CellType.hexahedron, 1, "P1 lines or triangles"),
                                       (mesh.CellType.tetrahedron, 2, "quadratic facets")):
        cube = mesh.create_unit_cube(MPI.COMM_WORLD, 1, 1, 1, cell_type=cell_type)
        faces = [mesh.locate_entities_boundary(cube, 2, lambda x, z=z: np.isclose(x[2], z))
                 for z in (0.0, 1.0)]
        order = np.argsort(np.concatenate(faces))
        cube_tags = mesh.meshtags(cube, 2, np.concatenate(faces)[order].astype(np.int32),
                                  np.concatenate([np.full(len(f), t, dtype=np.int32)
                                                  for f, t in zip(faces, (1, 2))])[order])
        V3 = fem.functionspace(cube, ("Lagrange", degree, (cube.geometry.dim,)))
        with pytest.raises(NotImplementedError, match=message):
            ContactProblem(V3, cube_tags, 1, master_tag=2, kind="LcLS*", **common)
    with pytest.raises(NotImplementedError, match="boundary modification"):
        ContactProblem(V, tags, 1, master_tag=2, kind="LcLS*", boundary_modification=True,
                       active_set="pointwise", **common)
    V2 = fem.functionspace(V.mesh, ("Lagrange", 2, (V.mesh.geometry.dim,)))
    with pytest.raises(NotImplementedError, match="P1 lines or triangles"):
        ContactProblem(V2, tags, 1, obstacle=RigidPlane([0, 0], [0, 1]), kind="LcLS*",
                       **common)
