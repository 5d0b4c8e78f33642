"""Segmentation and mortar integrals on non-matching flat surfaces (docs/DESIGN.md, §Segmentation)."""
from __future__ import annotations

import numpy as np
import pytest
from petsc4py import PETSc

from dolfinx_mortar import KIND_NAMES, kernels
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface, ReferenceLagrange
from dolfinx_mortar.mortar.coupling import MortarCoupling, segment_quadrature, to_scipy

from dolfinx_mortar.surfaces.structured import flat_line, flat_patch

ELEMENTS = {  # name: (cell, degree, serendipity, transform)
    "P1-line": ("interval", 1, False, False),
    "P2-line": ("interval", 2, False, False),
    "P1-triangle": ("triangle", 1, False, False),
    "P2-triangle": ("triangle", 2, False, True),
    "Q1-quad": ("quadrilateral", 1, False, False),
    "Q2-quad": ("quadrilateral", 2, False, False),
    "Q8-quad": ("quadrilateral", 2, True, True),
}
ORIENTATIONS = {"finer-slave": (7, 4), "finer-master": (3, 6)}


def pair(element, orientation, master_bounds, gap=0.01, jitter=0.25, seed=0):
    """Slave on [0,1]^(d-1) with outward normal +z (+y), master above facing down.

    Quadrilaterals get no jitter: only parallelograms are affine, and only on
    affine facets are the segment integrals exact (see MortarCoupling).
    """
    cell, degree, serendipity, transform = ELEMENTS[element]
    if cell == "quadrilateral":
        jitter = 0.0
    ns, nm = ORIENTATIONS[orientation]
    if cell == "interval":
        slave = flat_line(degree, ns, jitter=jitter, seed=seed)
        master = flat_line(degree, nm, bounds=master_bounds[:2], y=gap, up=False,
                           jitter=jitter, seed=seed + 1)
    else:
        slave = flat_patch(cell, degree, ns, ns + 1, jitter=jitter, seed=seed,
                           serendipity=serendipity, quadratic_transform=transform)
        master = flat_patch(cell, degree, nm, nm + 1, bounds=master_bounds, z=gap, up=False,
                            jitter=jitter, seed=seed + 1, serendipity=serendipity)
    return slave, master


PARTIAL = (0.3, 1.4, -0.2, 0.8)   # covers [0.3, 1] (x [0, 0.8])
FULL = (-0.1, 1.2, -0.15, 1.1)    # covers everything


def covered(element, bounds):
    lo, hi = max(bounds[0], 0), min(bounds[1], 1)
    if ELEMENTS[element][0] == "interval":
        return hi - lo
    return (hi - lo) * (min(bounds[3], 1) - max(bounds[2], 0))


@pytest.mark.parametrize("orientation", ORIENTATIONS)
@pytest.mark.parametrize("element", ELEMENTS)
def test_covered_area_is_conserved(element, orientation):
    for bounds in (PARTIAL, FULL):
        c = MortarCoupling(*pair(element, orientation, bounds))
        assert c.failed_projections == 0
        assert abs(c.total_covered_area - covered(element, bounds)) <= 1e-12


@pytest.mark.parametrize("orientation", ORIENTATIONS)
@pytest.mark.parametrize("element", ELEMENTS)
def test_constants_are_tied_exactly(element, orientation):
    """Σ_B D_AB = Σ_C M_AC: both are ∫ M_A over the covered part."""
    c = MortarCoupling(*pair(element, orientation, PARTIAL))
    for kind in KIND_NAMES:
        op = c.operators(kind)
        D, M = to_scipy(op.D), to_scipy(op.M)
        rows = np.flatnonzero(op.touched)
        lhs = op.apply_S(np.asarray(D.sum(axis=1)).ravel() * op.touched)
        rhs = op.apply_S(np.asarray(M.sum(axis=1)).ravel())
        assert np.max(np.abs(lhs[rows] - rhs[rows])) <= 1e-12 * np.max(np.abs(rhs)), kind


@pytest.mark.parametrize("orientation", ORIENTATIONS)
@pytest.mark.parametrize("element", ELEMENTS)
@pytest.mark.parametrize("kind", ["LcLS*", "LcLS", "GLS", "GLS*", "LmLS*"])
def test_linear_master_field_is_transferred_exactly(element, orientation, kind):
    slave, master = pair(element, orientation, FULL)
    op = MortarCoupling(slave, master).operators(kind)

    def field(x):
        return 0.3 + 1.7 * x[:, 0] - 0.9 * x[:, 1 % (x.shape[1] - 1)] * (x.shape[1] == 3)

    um = op.M.createVecRight()
    um.array[:] = field(master.x)
    us = op.transfer(um).array
    T = slave.reference.transform
    if T is not None:  # coefficients of Ñ = N T: nodal values are T c per element
        nodal = np.einsum("ab,cb->ca", T, us[slave.cells])
        assert np.max(np.abs(nodal - field(slave.x)[slave.cells])) < 1e-12
    else:
        assert np.max(np.abs(us - field(slave.x))) < 1e-12


@pytest.mark.parametrize("element", ELEMENTS)
def test_dual_operator_is_diagonal_on_full_coverage(element):
    c = MortarCoupling(*pair(element, "finer-master", FULL))
    D = to_scipy(c.operators("LcLS*").D).toarray()
    off = D - np.diag(np.diag(D))
    assert np.max(np.abs(off)) < 1e-13 * np.max(np.abs(D))
    assert np.allclose(np.diag(D), c.basis("LcLS*").lumped_weights, rtol=1e-12)


@pytest.mark.parametrize("element", ["Q1-quad", "Q2-quad"])
def test_distorted_quads_are_integrated_to_quadrature_accuracy(element):
    """Non-parallelogram quads: the dual D is diagonal only up to the segment
    quadrature error, which falls as the degree rises."""
    cell, degree, *_ = ELEMENTS[element]
    slave = flat_patch(cell, degree, 4, 5, jitter=0.25)
    master = flat_patch(cell, degree, 3, 3, bounds=FULL, z=0.01, up=False, jitter=0.25, seed=1)
    errors = []
    for q in (4, 8, 14):
        D = to_scipy(MortarCoupling(slave, master, quadrature_degree=q)
                     .operators("LcLS*").D).toarray()
        errors.append(np.max(np.abs(D - np.diag(np.diag(D)))) / np.max(np.abs(D)))
    assert errors[2] < 1e-3 * errors[0] and errors[2] < 1e-8, errors


def _rigid(x, rotation, shift):
    return x @ rotation.T + shift


@pytest.mark.parametrize("element", ELEMENTS)
def test_rigid_motion_changes_nothing(element):
    slave, master = pair(element, "finer-slave", PARTIAL)
    gdim = slave.gdim
    rng = np.random.default_rng(11)
    Q, _ = np.linalg.qr(rng.normal(size=(gdim, gdim)))
    if np.linalg.det(Q) < 0:  # a rotation, not a reflection (which flips normals)
        Q[:, 0] *= -1
    shift = rng.normal(size=gdim) * 10
    moved = [LagrangeSurface(s.reference.cell, s.reference.degree, _rigid(s.x, Q, shift),
                             s.cells, serendipity=s.reference.serendipity,
                             quadratic_transform=s.reference.transform is not None)
             for s in (slave, master)]
    a, b = MortarCoupling(slave, master), MortarCoupling(*moved)
    assert a.failed_projections == 0 and b.failed_projections == 0
    for kind in ("LcLS*", "GLS", "LmLS"):
        oa, ob = a.operators(kind), b.operators(kind)
        for A, B in ((oa.D, ob.D), (oa.M, ob.M)):
            A, B = to_scipy(A).toarray(), to_scipy(B).toarray()
            assert np.max(np.abs(A - B)) <= 1e-11 * np.max(np.abs(A))
        assert np.max(np.abs(oa.nodal_gap() - ob.nodal_gap())) <= 1e-11 * 0.01


@pytest.mark.parametrize("element", ELEMENTS)
def test_gap_is_the_normal_distance(element):
    slave, master = pair(element, "finer-slave", FULL, gap=-0.02)  # penetrating by 0.02
    op = MortarCoupling(slave, master).operators("LmLS")  # ∫M_A = 1: nodal gap = average
    assert np.allclose(op.nodal_gap(), 0.02, rtol=1e-12)


def test_boundary_modification_keeps_the_dual_gap_sign():
    """Partly covered dual elements give a nodal gap of the wrong sign; the
    consistent boundary modification removes that."""
    # The element [2/7, 3/7] is covered on its last 20%: for P1 dual functions
    # ∫_cov M_A < 0 once coverage is below 1/3.
    slave = flat_line(1, 7)
    master = flat_line(1, 3, bounds=(0.4, 1.4), y=0.01, up=False)
    c = MortarCoupling(slave, master)
    plain = c.operators("LcLS*").nodal_gap()
    modified = c.operators("LcLS*", boundary_modification=True).nodal_gap()
    assert np.max(plain) > 0                       # separated, yet "penetrating" somewhere
    assert np.max(modified) <= 1e-15               # never positive for a positive gap
    modified_bar = c.operators("LcLS", boundary_modification=True).nodal_gap()
    touched = c.operators("LcLS").touched
    assert np.allclose(modified_bar[touched], -0.01, rtol=1e-12)
    with pytest.raises(ValueError, match="dual kinds"):
        c.operators("GLS", boundary_modification=True)


# -- degenerate input ------------------------------------------------------------------
DEGENERATE = {
    # name: (master bounds, master lattice, expected covered fraction)
    "coincident-nodes": ((0.0, 1.0, 0.0, 1.0), (4, 4), 1.0),
    "node-on-edge": ((0.125, 1.125, 0.0, 1.0), (4, 4), 0.875),
    "touching-edge-only": ((1.0, 2.0, 0.0, 1.0), (3, 3), 0.0),
    "no-overlap": ((3.0, 4.0, 3.0, 4.0), (3, 3), 0.0),
    "tiny-sliver": ((1.0 - 1e-9, 2.0, 0.0, 1.0), (3, 3), 1e-9),
}


@pytest.mark.parametrize("case", DEGENERATE)
@pytest.mark.parametrize("cell", ["triangle", "quadrilateral"])
def test_degenerate_overlaps(case, cell):
    bounds, (nx, ny), fraction = DEGENERATE[case]
    slave = flat_patch(cell, 1, 4, 4)
    master = flat_patch(cell, 1, nx, ny, bounds=bounds, z=0.0, up=False)
    c = MortarCoupling(slave, master, search_radius=0.1)
    assert c.failed_projections == 0
    assert abs(c.total_covered_area - fraction) <= 1e-12
    for kind in ("LcLS*", "LmLS*"):
        op = c.operators(kind)
        assert np.all(np.isfinite(to_scipy(op.D).data)) and np.all(np.isfinite(op.nodal_gap()))


def test_parallel_edges_at_an_angle_and_coincident_surfaces_in_2d():
    slave = flat_line(1, 5)
    master = flat_line(1, 5, y=0.0, up=False)   # same nodes: every edge coincides
    c = MortarCoupling(slave, master)
    assert abs(c.total_covered_area - 1.0) <= 1e-12
    assert np.allclose(c.operators("LmLS").nodal_gap(), 0.0, atol=1e-15)


def test_inverted_normals_conserve_area_when_orientation_is_not_checked():
    slave = flat_patch("triangle", 1, 5, 5, jitter=0.2)
    master = flat_patch("triangle", 1, 4, 3, bounds=PARTIAL, up=True, jitter=0.2)  # same way
    assert MortarCoupling(slave, master).total_covered_area == 0.0     # not facing: no contact
    c = MortarCoupling(slave, master, opposing_normals_only=False)
    assert abs(c.total_covered_area - 0.56) <= 1e-12
    flipped = slave.reflected(np.ones(len(slave.cells), dtype=bool))  # slave inverted too
    c = MortarCoupling(flipped, master)
    assert abs(c.total_covered_area - 0.56) <= 1e-12


def test_far_away_master_behind_the_search_radius_is_ignored():
    slave = flat_patch("quadrilateral", 1, 3, 3)
    master = flat_patch("quadrilateral", 1, 3, 3, z=5.0, up=False)
    assert MortarCoupling(slave, master).total_covered_area == 0.0
    assert MortarCoupling(slave, master, search_radius=6.0).total_covered_area == pytest.approx(1.0)


@pytest.mark.parametrize("name", ELEMENTS)
def test_kernel_shape_functions_match_basix(name):
    import basix
    cell, degree, serendipity, _ = ELEMENTS[name]
    ref = ReferenceLagrange(cell, degree, serendipity=serendipity)
    X = (basix.create_lattice(ref.cell_type, 5, basix.LatticeType.equispaced, True)
         if cell != "interval" else np.linspace(0, 1, 6)[:, None])
    N, dN = ref.tabulate(X)
    Nk, dNk = kernels.facet_shape_functions(ref.facet_type, X)
    assert np.allclose(N, Nk, atol=1e-14) and np.allclose(dN, dNk, atol=1e-13)
    mirrored = ref.nodes[:, ::-1] if cell != "interval" else 1 - ref.nodes
    assert np.allclose(ref.nodes[ref.reflection], mirrored)


def test_candidate_search_matches_brute_force():
    rng = np.random.default_rng(5)
    lo = rng.uniform(0, 10, (300, 3))
    a = np.hstack([lo, lo + rng.uniform(0, 1, (300, 3))])
    lo = rng.uniform(0, 10, (200, 3))
    b = np.hstack([lo, lo + rng.uniform(0, 1, (200, 3))])
    pairs = {tuple(p) for p in kernels.overlapping_box_pairs(a, b)}
    brute = {(i, j) for i in range(300) for j in range(200)
             if np.all(a[i, :3] <= b[j, 3:]) and np.all(b[j, :3] <= a[i, 3:])}
    assert pairs == brute and len(brute) > 0


def test_mismatched_dimensions_are_reported():
    with pytest.raises(ValueError, match="different dimensions"):
        MortarCoupling(flat_line(1, 3), flat_patch("triangle", 1, 2, 2))
    slave = flat_line(1, 3)
    from dolfinx_mortar.mortar.coupling import current_coordinates
    with pytest.raises(ValueError, match="NaN"):
        current_coordinates(slave, np.full(slave.x.shape, np.nan))


def test_transfer_rhs_uses_petsc_vectors():
    slave, master = pair("P1-line", "finer-slave", FULL)
    op = MortarCoupling(slave, master).operators("LcLS*")
    assert isinstance(op.transfer(op.M.createVecRight()), PETSc.Vec)


@pytest.mark.parametrize("degree", [1, 2])
def test_axisymmetric_integrals_carry_the_circumference(degree):
    """Non-matching flat meridians r ∈ [0, 1] overlapping by g: every mortar
    integral is taken over the swept disk, so Σ D = Σ M = π (∫ 2πr dr) and the
    gap integral is g π; the plane measure would give 1 and g."""
    from dolfinx_mortar.surfaces.lagrange import LagrangeSurface

    def axisymmetric(surface):
        return LagrangeSurface("interval", degree, surface.x, surface.cells,
                               axisymmetric=True)
    g = 0.01   # the master's body (normal −y) reaches down to y = −g, into the slave's
    slave = axisymmetric(flat_line(degree, 7, jitter=0.3, seed=2))
    master = axisymmetric(flat_line(degree, 5, y=-g, up=False, jitter=0.3, seed=3))
    coupling = MortarCoupling(slave, master)
    D, M, gap = coupling.raw_pairs
    assert abs(D.sum() - np.pi) < 1e-12 and abs(M.sum() - np.pi) < 1e-12
    assert abs(gap.sum() - g * np.pi) < 1e-12
    with pytest.raises(ValueError, match="both be axisymmetric"):
        MortarCoupling(slave, flat_line(degree, 5, y=-g, up=False))


def _graded_slave() -> LagrangeSurface:
    """Fifty facets of length 0.01 on [0, 0.5], then one of length 2.5 (y = 0, facing +y)."""
    from dolfinx_mortar.surfaces.structured import line_chain
    s, cells = line_chain(np.concatenate([np.linspace(0.0, 0.5, 51), [3.0]]), 1)
    surface = LagrangeSurface("interval", 1, np.column_stack([s, np.zeros_like(s)]), cells)
    return surface.reflected(np.ones(len(cells), dtype=bool))      # normals +y


def test_facet_search_finds_the_close_pairs_from_far_fewer_candidates():
    """Each facet searching two of its own diameters: on a graded slave the
    same pairs as the largest facet's radius wherever the surfaces are close,
    from a fraction of the candidates."""
    slave = _graded_slave()
    master = flat_line(1, 320, bounds=(-0.1, 3.1), y=0.004, up=False)
    default = MortarCoupling(slave, master)
    local = MortarCoupling(slave, master, facet_search_factor=2.0)
    assert {tuple(p) for p in local.pairs} == {tuple(p) for p in default.pairs}
    assert np.allclose(local.covered_area, default.covered_area, rtol=0, atol=1e-14 * 3.0)
    assert abs(np.sum(local.covered_area) - 3.0) <= 1e-12 * 3.0


def test_default_search_sweeps_each_facet_along_its_normal():
    """The largest facet's radius, 2.5, reaches along each facet's normal
    only: a box enlarged by 2.5 every way gave each 0.01-long facet all the
    master facets beside it (16k candidates for 300 pairs); swept along y it
    gets those below it, at most a few per pair."""
    slave = _graded_slave()
    master = flat_line(1, 320, bounds=(-0.1, 3.1), y=0.004, up=False)
    default = MortarCoupling(slave, master)
    assert default.search_radius == pytest.approx(2.5, rel=1e-12)
    assert abs(np.sum(default.covered_area) - 3.0) <= 1e-12 * 3.0
    assert default.num_candidates < 3 * len(default.pairs)


def test_facet_search_ignores_a_master_beyond_two_facet_diameters():
    slave = _graded_slave()
    master = flat_line(1, 320, bounds=(-0.1, 3.1), y=0.1, up=False)   # 10 small facets away
    local = MortarCoupling(slave, master, facet_search_factor=2.0)
    assert not np.any(local.pairs[:, 0] < 50)                         # small facets: no pair
    assert abs(local.covered_area[50] - 2.5) <= 1e-12 * 2.5          # the long facet reaches
    assert abs(np.sum(MortarCoupling(slave, master).covered_area) - 3.0) <= 1e-12 * 3.0
    with pytest.raises(ValueError, match="facet_search_factor"):
        MortarCoupling(slave, master, facet_search_factor=-1.0)


@pytest.mark.parametrize("degree", [1, 2])
def test_swept_boxes_of_no_facets(degree):
    """A rank may hold no slave facet (Hertz 3D on 2 ranks: all on one): no
    boxes, no error (the other rank would wait in a collective)."""
    from dolfinx_mortar.mortar.coupling import swept_facet_boxes
    surface = flat_line(degree, 4)
    cells = np.zeros((0, surface.cells.shape[1]), dtype=np.int32)
    boxes = swept_facet_boxes(surface, surface.x, cells, 1.0, np.zeros(0))
    assert boxes.shape == (0, 6)


def _mirrored_arcs(n: int = 8):
    """P1 arcs y = ±(1 − sqrt(1 − x²)), x in [0, 0.4]: the slave above facing down, the master
    its mirror image facing up, node i of one the mirror of node i of the other."""
    x = np.linspace(0.0, 0.4, n + 1)
    y = 1.0 - np.sqrt(1.0 - x**2)
    cells = np.column_stack([np.arange(n), np.arange(1, n + 1)]).astype(np.int32)
    slave = np.column_stack([x, y])
    master = np.column_stack([x, -y])
    return slave, cells, master, cells[:, ::-1].copy()


@pytest.mark.parametrize("along_normals", [True, False])
def test_projection_along_the_given_normals_pairs_mirror_points(along_normals):
    """With vertical normals on mirrored arcs, projecting along them pairs each slave point
    with its mirror image: ∫N_A N^m_C = ∫N_A N_C and the gap is twice the slave's height, to
    round-off. Projecting along the facets' own (tilted) normals, as for the slave's own
    normals, shifts the master points outward and both are off."""
    xs, cs, xm, cm = _mirrored_arcs()
    n = len(xs)
    normals = np.tile([0.0, -1.0], (n, 1))
    candidates = np.array([(i, j) for i in range(len(cs)) for j in range(len(cm))],
                          dtype=np.int32)
    points, weights = segment_quadrature(1, 2)
    line = kernels.FacetType.P1_line
    r = kernels.mortar_integrals(line, xs, cs, normals, line, xm, cm, candidates, points,
                                 weights, project_along_normals=along_normals)
    D, M, gap = np.zeros((n, n)), np.zeros((n, n)), np.zeros(n)
    for (s, m), Dp, Mp, gp in zip(r.pairs, r.D, r.M, r.gap):
        D[np.ix_(cs[s], cs[s])] += Dp
        M[np.ix_(cs[s], cm[m])] += Mp
        gap[cs[s]] += gp
    tol = 1e-13 * np.max(np.abs(D))
    mirrored = np.max(np.abs(M - D)) < tol and np.max(np.abs(gap + 2 * D @ xs[:, 1])) < tol
    assert mirrored == along_normals, (np.max(np.abs(M - D)), tol)
