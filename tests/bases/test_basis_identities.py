"""The identities of docs/DESIGN.md, §Bases, for every kind on B-spline, NURBS and Lagrange
slave surfaces, and on axisymmetric (r, z) lines, where every integral carries
2πr (docs/AXISYMMETRIC.md): the identities hold for the weighted measure.

Integrals are taken with the basis's own quadrature rule, so the discrete
identities hold to round-off (a quadrature error would not hide a wrong basis:
every test below fails by O(1) if a coefficient is wrong).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

from dolfinx_mortar import KIND_NAMES, MortarBasis, basis, nurbs
from dolfinx_mortar.kinds import is_partition_of_unity, unstarred_partner, kind_name

from support.surfaces import curved_line, curved_patch

TOL = 1e-11


def _rng_weights(shape, seed=3):
    return np.random.default_rng(seed).uniform(0.5, 2.0, shape)


def _quarter_circle():
    # Exact quarter circle of radius 2 as a quadratic NURBS, refined by knot insertion-free
    # construction: 2 elements with a repeated middle arc (two exact quarter arcs of 45°).
    c, r = np.cos(np.pi / 8), 2.0
    pts = r * np.array([[1, 0], [1, np.tan(np.pi / 8)], [np.cos(np.pi / 4), np.sin(np.pi / 4)],
                        [np.tan(np.pi / 8), 1], [0, 1]])
    w = np.array([1, c, 1, c, 1])
    knots = [0, 0, 0, 0.5, 0.5, 1, 1, 1]
    return nurbs.BSplineCurve(degree=2, knots=knots, weights=w, control_points=pts)


SURFACES = {
    "bspline-p1": lambda: nurbs.BSplineCurve(degree=1, n_elements=6),
    "bspline-p2": lambda: nurbs.BSplineCurve(degree=2, n_elements=5),
    "bspline-p3": lambda: nurbs.BSplineCurve(degree=3, n_elements=7),
    "nurbs-p2-rational": lambda: nurbs.BSplineCurve(degree=2, n_elements=6,
                                                    weights=_rng_weights(8)),
    "nurbs-p3-rational-curved": lambda: nurbs.BSplineCurve(
        degree=3, n_elements=5, weights=_rng_weights(8),
        control_points=np.column_stack([np.linspace(0, 1, 8), 0.3 * np.sin(np.arange(8))])),
    "nurbs-quarter-circle": _quarter_circle,
    "nurbs-surface-p2": lambda: nurbs.BSplineSurface(degree=2, n_elements=(3, 4)),
    "nurbs-surface-p12-rational-curved": lambda: nurbs.BSplineSurface(
        degree=(1, 2), n_elements=(3, 3), weights=_rng_weights((4, 5)),
        control_points=np.stack([*np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 5),
                                              indexing="ij"),
                                 0.2 * np.random.default_rng(5).uniform(size=(4, 5))], axis=-1)),
    "P1-line": lambda: curved_line(1),
    "P2-line": lambda: curved_line(2),
    "P1-line-axisymmetric": lambda: curved_line(1, axisymmetric=True),
    "P2-line-axisymmetric": lambda: curved_line(2, axisymmetric=True),
    "P1-triangle": lambda: curved_patch("triangle", 1),
    "P2-triangle-transformed": lambda: curved_patch("triangle", 2, quadratic_transform=True),
    "Q1-quad": lambda: curved_patch("quadrilateral", 1),
    "Q2-quad": lambda: curved_patch("quadrilateral", 2),
    "Q8-quad-transformed": lambda: curved_patch("quadrilateral", 2, serendipity=True,
                                                quadratic_transform=True),
}


@lru_cache(maxsize=None)
def surface_data(name):
    """Surface, quadrature points as (cells, phi), weights, and N densely at them."""
    surface = SURFACES[name]()
    tab = surface.tabulate(surface.default_quadrature_degree())
    nc, nq, nd = tab.phi.shape
    cells = np.repeat(np.arange(nc), nq)
    phi = tab.phi.reshape(-1, nd)
    n = surface.layout.size_local
    N = np.zeros((nc * nq, n))
    np.add.at(N, (np.repeat(np.arange(nc * nq), nd), surface.cells[cells].ravel()), phi.ravel())
    return surface, cells, phi, tab.weights.ravel(), N


@lru_cache(maxsize=None)
def mortar_values(name, kind):
    surface, cells, phi, _, _ = surface_data(name)
    b = MortarBasis(kind, surface)
    return b, b.evaluate(cells, phi)


@pytest.mark.parametrize("name", SURFACES)
@pytest.mark.parametrize("kind", KIND_NAMES)
def test_partition_of_unity_or_unit_integral(name, kind):
    _, _, _, w, _ = surface_data(name)
    _, M = mortar_values(name, kind)
    if is_partition_of_unity(kind):
        assert np.max(np.abs(M.sum(axis=1) - 1.0)) < TOL
    else:
        assert np.max(np.abs(w @ M - 1.0)) < TOL
        # ... and not a partition of unity: the test above is not vacuous
        assert np.max(np.abs(M.sum(axis=1) - 1.0)) > 1e-3


@pytest.mark.parametrize("name", SURFACES)
@pytest.mark.parametrize("kind", ["GLS*", "LmLS*", "LcLS*"])
def test_starred_is_unstarred_times_lumped_weights(name, kind):
    b_star, M_star = mortar_values(name, kind)
    _, M = mortar_values(name, kind_name(unstarred_partner(kind)))
    W = b_star.lumped_weights
    scale = np.max(np.abs(M_star))
    assert np.max(np.abs(M_star - M * W[None, :])) < TOL * scale


@pytest.mark.parametrize("name", SURFACES)
def test_dual_kind_is_elementwise_biorthogonal(name):
    surface, cells, _, w, N = surface_data(name)
    b, M = mortar_values(name, "LcLS*")
    for e in range(b.cells.shape[0]):
        at = cells == e
        nodes = b.cells[e]
        gram = (M[at][:, nodes] * w[at, None]).T @ N[at][:, nodes]  # ∫_e M_A N_B
        expected = np.diag(b.element_weights[e])
        assert np.max(np.abs(gram - expected)) < TOL * np.sum(b.element_weights[e])


@pytest.mark.parametrize("name", SURFACES)
def test_gls_star_is_globally_biorthogonal(name):
    _, _, _, w, N = surface_data(name)
    b, M = mortar_values(name, "GLS*")
    gram = (M * w[:, None]).T @ N
    assert np.max(np.abs(gram - np.diag(b.lumped_weights))) < TOL * np.max(b.lumped_weights)


@pytest.mark.parametrize("name", SURFACES)
def test_standard_kind_is_the_slave_basis(name):
    _, _, _, _, N = surface_data(name)
    _, M = mortar_values(name, "LmLS*")
    assert np.array_equal(M, N) or np.max(np.abs(M - N)) < 1e-15


@pytest.mark.parametrize("name", SURFACES)
def test_gls_smoothed_pressure_is_the_L2_projection(name):
    surface, cells, phi, w, N = surface_data(name)
    tab = surface.tabulate(surface.default_quadrature_degree())
    x = tab.points.reshape(-1, tab.points.shape[-1])

    def p(x):
        return np.maximum(0.0, 0.3 - np.sum((x - 0.4) ** 2, axis=0)) + 0.1 * np.cos(x[0])

    pq = p(x.T)
    # Independent L2 projection: dense normal equations at the same quadrature points.
    L = (N * w[:, None]).T @ N
    projection = np.linalg.solve(L, N.T @ (w * pq))
    pA = basis.nodal_pressures("GLS", surface, p)
    assert np.max(np.abs(pA - projection)) < TOL * np.max(np.abs(projection))
    # Galerkin orthogonality of p̂ - p to every N_B
    assert np.max(np.abs(N.T @ (w * (N @ pA - pq)))) < TOL


@pytest.mark.parametrize("name", ["bspline-p2", "nurbs-p2-rational", "P1-line", "Q1-quad"])
@pytest.mark.parametrize("kind", KIND_NAMES)
def test_nodal_pressures_are_integrals_against_mortar_functions(name, kind):
    surface, _, _, w, _ = surface_data(name)
    b, M = mortar_values(name, kind)
    tab = b.tabulation
    f = np.cos(3 * tab.points[..., 0]).ravel()
    assert np.allclose(b.nodal_values(f.reshape(tab.weights.shape)), M.T @ (w * f),
                       rtol=0, atol=TOL * np.max(np.abs(M.T @ (w * np.abs(f)))))


@pytest.mark.parametrize("kind", KIND_NAMES)
def test_mortar_coefficients_reproduce_pointwise_sum(kind):
    surface, cells, phi, _, _ = surface_data("nurbs-p2-rational")
    b, M = mortar_values("nurbs-p2-rational", kind)
    pA = np.random.default_rng(7).uniform(size=surface.num_functions)
    q = b.mortar_coefficients(pA)
    assert np.allclose(np.einsum("rb,rb->r", phi, q[cells]), M @ pA, atol=1e-12)


def test_quarter_circle_weights_sum_to_arc_length():
    surface, _, _, w, _ = surface_data("nurbs-quarter-circle")
    b, _ = mortar_values("nurbs-quarter-circle", "LmLS*")
    # rational quadratic arcs are exact circles: only quadrature error remains
    assert abs(b.lumped_weights.sum() - np.pi) < 1e-6


@pytest.mark.parametrize("degree", [1, 2, 3])
def test_gls_projection_converges_at_order_p_plus_one(degree):
    errors = []
    for n in (8, 16, 32):
        curve = nurbs.BSplineCurve(degree=degree, n_elements=n)
        b = MortarBasis("GLS", curve, quadrature_degree=2 * degree + 6)
        pA = b.nodal_values(lambda x: np.sin(2 * np.pi * x[0]))
        tab = b.tabulation
        p_hat = np.einsum("cqb,cb->cq", tab.phi, pA[curve.cells])
        err = np.sqrt(np.sum(tab.weights * (p_hat - np.sin(2 * np.pi * tab.points[..., 0])) ** 2))
        errors.append(err)
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(rates > degree + 0.9), rates


@pytest.mark.parametrize("cell, serendipity, vertex, edge", [
    ("triangle", False, 2 / 15, 1 / 5), ("quadrilateral", True, 1 / 20, 1 / 5)])
def test_transformed_quadratic_basis_has_positive_integrals(cell, serendipity, vertex, edge):
    from dolfinx_mortar.surfaces.lagrange import ReferenceLagrange
    import basix
    ref = ReferenceLagrange(cell, 2, serendipity=serendipity, quadratic_transform=True)
    X, wq = basix.make_quadrature(ref.cell_type, 6)
    N, _ = ref.tabulate(X)
    area = wq.sum()
    integrals = wq @ N / area
    nv = 3 if cell == "triangle" else 4
    assert np.allclose(integrals[:nv], vertex) and np.allclose(integrals[nv:], edge)
    assert np.allclose(N.sum(axis=1), 1.0)
    plain = ReferenceLagrange(cell, 2, serendipity=serendipity)
    N0, _ = plain.tabulate(X)
    assert np.max(wq @ N0[:, :nv]) <= 1e-15  # why the transform is needed


@pytest.mark.parametrize("degree", [1, 2])
def test_axisymmetric_weights_are_the_swept_areas(degree):
    """A flat meridian r ∈ [0, 1] sweeps the unit disk: Σ W_A = π; the node on
    the axis carries the small ring of its first element."""
    from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
    from dolfinx_mortar.surfaces.structured import line_chain
    n = 8
    s, cells = line_chain(np.linspace(0.0, 1.0, n + 1), degree)
    flat = LagrangeSurface("interval", degree, np.column_stack([s, np.zeros_like(s)]), cells,
                           axisymmetric=True)
    W = MortarBasis("LmLS*", flat).lumped_weights
    assert abs(W.sum() - np.pi) < TOL
    h = 1.0 / n
    axis = int(np.argmin(s))
    if degree == 1:
        assert abs(W[axis] - 2 * np.pi * h ** 2 / 6) < TOL
        # the plane measure would give h/2: the weight is really 2πr ds
        assert abs(W[axis] - h / 2) > 0.1 * h
    else:
        # the plain P2 vertex has ∫N 2πr ds = 0 there; the transformed basis
        # (always used on axisymmetric P2 lines) gives 2πh²/15
        assert flat.reference.transform is not None
        assert abs(W[axis] - 2 * np.pi * h ** 2 / 15) < TOL
