"""Bad input gets a clear error that names the problem."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem, mesh
from mpi4py import MPI

from dolfinx_mortar import MortarBasis, basis, kernels, nurbs
from dolfinx_mortar.surfaces.facet_surface import facet_surface
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.mortar.coupling import MortarCoupling

from support.surfaces import curved_patch

W_KINDS = ["GLS*", "LmLS", "LcLS*", "LcLS"]


def test_unknown_kind_is_named():
    curve = nurbs.BSplineCurve(degree=2, n_elements=3)
    with pytest.raises(ValueError, match="unknown mortar basis kind 'LcLS\\*\\*'.*GLS"):
        basis.evaluate("LcLS**", curve, [0.5])
    with pytest.raises(TypeError, match="string"):
        MortarBasis(3, curve)


def test_aliases_are_the_same_bases():
    curve = nurbs.BSplineCurve(degree=2, n_elements=4)
    x = np.linspace(0, 1, 9)
    for alias, kind in [("standard", "LmLS*"), ("weighted", "LmLS"), ("dual", "LcLS*")]:
        assert np.array_equal(basis.evaluate(alias, curve, x), basis.evaluate(kind, curve, x))


@pytest.mark.parametrize("kind", W_KINDS)
@pytest.mark.parametrize("cell, serendipity", [("triangle", False), ("quadrilateral", True)])
def test_singular_lumped_weights_of_quadratic_facets_are_reported(kind, cell, serendipity):
    surface = curved_patch(cell, 2, n=2, serendipity=serendipity)
    with pytest.raises(ValueError, match="transformed quadratic basis") as err:
        MortarBasis(kind, surface)
    assert surface.description in str(err.value)


@pytest.mark.parametrize("kind", ["GLS", "LmLS*"])
def test_kinds_without_lumped_weights_work_on_plain_quadratic_triangles(kind):
    b = MortarBasis(kind, curved_patch("triangle", 2, n=2))
    assert np.all(np.isfinite(b.nodal_values(lambda x: 1.0 + x[0])))


def test_sliver_triangle_is_not_degenerate_and_its_area_is_exact():
    """Aspect 1e8 is a real (if poor) facet: accepted, with the cross-product area."""
    x = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1e-8, 0]])
    surface = LagrangeSurface("triangle", 1, x, [[0, 1, 2]])
    area = surface.tabulate().weights.sum()
    assert area == pytest.approx(0.5e-8, rel=1e-12)


_TILT = np.linalg.qr(np.array([[1.0, 0.3, -0.2], [0.1, 1.0, 0.4], [0.3, -0.5, 1.0]]))[0]
if np.linalg.det(_TILT) < 0:
    _TILT[:, 0] *= -1


def _degenerate_surface(case: str, offset: float, check_cells: bool = False
                        ) -> LagrangeSurface:
    """Cell 1 is degenerate: a zero-length P1 line, or a collinear P1 triangle
    (its third node on the opposite edge). Unchecked by default, so that the
    kernels' own checks behind the surface's are seen too."""
    if case == "zero-length-line":
        x = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
        return LagrangeSurface("interval", 1, x + offset, [[0, 1], [1, 2], [2, 3]],
                               check_cells=check_cells)
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0],
                  [0.5, 0.5, 0.0]])
    # tilted, so that the collinear cell's area is round-off, not exactly 0
    return LagrangeSurface("triangle", 1, x @ _TILT.T + offset,
                           [[0, 1, 2], [0, 4, 3], [1, 3, 2]], check_cells=check_cells)


def _regular_surface(case: str, offset: float) -> LagrangeSurface:
    """A regular surface just below the degenerate one, facing it."""
    if case == "zero-length-line":
        x = np.array([[0.0, -0.01], [1.0, -0.01], [2.0, -0.01]])
        return LagrangeSurface("interval", 1, x + offset, [[1, 0], [2, 1]])
    x = np.array([[0.0, 0.0, -0.01], [1.0, 0.0, -0.01], [0.0, 1.0, -0.01], [1.0, 1.0, -0.01]])
    return LagrangeSurface("triangle", 1, x @ _TILT.T + offset, [[0, 2, 1], [1, 2, 3]])


@pytest.mark.parametrize("offset", [0.0, 1e4])
@pytest.mark.parametrize("case", ["zero-length-line", "collinear-triangle"])
def test_degenerate_facets_are_reported_whatever_the_round_off(case, offset):
    """A degenerate cell measures 0, 5.5e-17 or 1.1e-16 at |x| = 1 depending
    on the BLAS kernels (OPENBLAS_CORETYPE), 1.8e-12 at |x| = 1e4: it is judged
    against the zero length of the geometry, never against 0. Before, the
    basis took such a cell for a real one, and the segmentation dropped it
    without a word."""
    with pytest.raises(ValueError, match="degenerate facet: cell 1 "):
        _degenerate_surface(case, offset, check_cells=True)
    surface = _degenerate_surface(case, offset)
    for kind in ("LmLS*", "LcLS*"):
        with pytest.raises(ValueError, match="degenerate slave element: cell 1 "):
            MortarBasis(kind, surface)
    with pytest.raises(ValueError, match="degenerate contact facets.*slave facet 1 .*nodes"):
        MortarCoupling(surface, _regular_surface(case, offset))
    # a zero-length master facet is a broken mesh too
    with pytest.raises(ValueError, match="degenerate contact facets.*master facet 1 .*nodes"):
        MortarCoupling(_regular_surface(case, offset).reflected([True] * 2),
                       surface.reflected([True] * 3))
    # regular surfaces at the same place are not degenerate
    MortarBasis("LcLS*", _regular_surface(case, offset))


def test_nan_coordinates_are_rejected_by_the_kernels():
    x = np.array([[0.0, 0.0], [1.0, 0.0], [np.nan, 0.0]])
    cells = np.array([[0, 1], [1, 2]], dtype=np.int32)
    with pytest.raises(ValueError, match=r"node 2 has a non-finite coordinate \(nan, 0"):
        kernels.element_node_normals(kernels.FacetType.P1_line, x, cells)
    good = np.array([[0.0, 0.1], [1.0, 0.1], [2.0, 0.1]])
    with pytest.raises(ValueError, match="node 2 has a non-finite coordinate"):
        kernels.mortar_integrals(kernels.FacetType.P1_line, good, cells, np.zeros((3, 2)),
                                  kernels.FacetType.P1_line, x, cells,
                                  np.zeros((0, 2), dtype=np.int32),
                                  np.array([[0.5]]), np.array([1.0]))
    x[2] = [np.inf, 0.0]
    with pytest.raises(ValueError, match="node 2 has a non-finite coordinate"):
        kernels.facet_bounding_boxes(kernels.FacetType.P1_line, x, cells, 0.0)


def test_nan_field_is_reported():
    curve = nurbs.BSplineCurve(degree=2, n_elements=3)
    with pytest.raises(ValueError, match="NaN"):
        basis.nodal_pressures("GLS", curve, lambda x: np.full(x.shape[1], np.nan))


def test_field_of_wrong_shape_is_reported():
    curve = nurbs.BSplineCurve(degree=2, n_elements=3)
    with pytest.raises(ValueError, match="shape"):
        basis.nodal_pressures("LcLS", curve, lambda x: x)


@pytest.mark.parametrize("kwargs, message", [
    (dict(degree=0, n_elements=3), "degree"),
    (dict(degree=2, n_elements=0), "element"),
    (dict(degree=2, n_elements=3, weights=[1, 1, -1, 1, 1]), "positive"),
    (dict(degree=2, n_elements=3, weights=[1, 1, 1]), "shape"),
    (dict(degree=2, knots=[0, 0.5, 1, 1, 1, 1]), "open"),
])
def test_bad_nurbs_input_is_reported(kwargs, message):
    with pytest.raises(ValueError, match=message):
        nurbs.BSplineCurve(**kwargs)


def test_parameters_outside_the_curve_are_reported():
    with pytest.raises(ValueError, match=r"\[0.0, 1.0\]"):
        basis.evaluate("GLS", nurbs.BSplineCurve(degree=2, n_elements=3), [1.5])


def _unit_square_with_tags(values):
    domain = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    facets = mesh.locate_entities_boundary(domain, 1, lambda x: np.isclose(x[1], 0.0))
    tags = mesh.meshtags(domain, 1, np.sort(facets).astype(np.int32),
                         np.full(len(facets), values, dtype=np.int32))
    return domain, tags


def test_empty_tag_is_reported_with_the_tags_present():
    domain, tags = _unit_square_with_tags(3)
    with pytest.raises(ValueError, match=r"facet tag 5 marks no facets.*\[3\]"):
        facet_surface(domain, tags, 5)


def test_cell_tags_instead_of_facet_tags_are_reported():
    domain, _ = _unit_square_with_tags(3)
    cells = np.arange(domain.topology.index_map(2).size_local, dtype=np.int32)
    cell_tags = mesh.meshtags(domain, 2, cells, np.ones_like(cells))
    with pytest.raises(ValueError, match="dimension 2.*facet tags \\(dimension 1\\)"):
        facet_surface(domain, cell_tags, 1)


def test_unsupported_space_is_reported():
    domain, tags = _unit_square_with_tags(3)
    V = fem.functionspace(domain, ("Lagrange", 3))
    with pytest.raises(ValueError, match="degree 1 or 2"):
        facet_surface(V, tags, 3)
