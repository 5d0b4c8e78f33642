"""Self-contact (docs/SELF_CONTACT.md): a body that touches itself against its half on a
rigid plane, node by node (demos/demo_support/self_mirror.py); two bodies under one term
against the two-body mirror; the pairs a surface makes with itself; and what is refused."""
from __future__ import annotations

import logging
import warnings

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI

from demo_support import mirror as two_bodies
from demo_support.self_mirror import CONTACT, build, self_mirror
from dolfinx_mortar import ContactProblem, ContactTerm, RigidPlane
from dolfinx_mortar.meshes.merge_meshes import merge_meshes
from dolfinx_mortar.mortar.coupling import MortarCoupling
from dolfinx_mortar.surfaces.facet_surface import facet_surface

LOCAL_KINDS = ["LcLS*", "LcLS", "LmLS*", "LmLS"]
#: GLS and GLS*: the two passes' L is the covered part of the surface against itself
GLOBAL_KINDS = ["GLS*", "GLS"]
#: the relative L2 difference of the nodal pressures on the arc, at three mesh sizes
TOLERANCE = 3e-3


@pytest.mark.parametrize("h", [0.1, 0.05, 0.025])
@pytest.mark.parametrize("configuration", ["initial", "previous"])
@pytest.mark.parametrize("kind", LOCAL_KINDS + GLOBAL_KINDS)
def test_a_body_pressed_against_itself_matches_its_half_on_a_plane(kind, configuration, h):
    """The C body squeezed until its arms press on each other, with one self-contact
    term on its whole inner surface, against its upper half pressed on a rigid
    plane: the same pressures node by node (measured: 3e-7 to 3.7e-4; GLS and
    GLS* 3.2e-5 to 7.4e-4)."""
    result = self_mirror(h, 0.02, penalty=2e4, kind=kind, basis_configuration=configuration)
    assert result.alone.p.max() > 0
    assert result.pressure_difference < TOLERANCE, result.pressure_difference


@pytest.mark.parametrize("h", [0.1, 0.05, 0.025])
@pytest.mark.parametrize("kind", ["LcLS*", "LmLS*", "GLS*"])
def test_a_body_of_revolution_pressed_against_itself_matches_its_half(kind, h):
    """The same C section as the meridian of a body of revolution about x = 0
    (its slot a toroidal cavity): 4e-5 to 7.7e-4 (GLS* 1.8e-3, 8.9e-4, 2.4e-4)."""
    result = self_mirror(h, 0.02, penalty=2e4, kind=kind, axisymmetric=True)
    assert result.pressure_difference < TOLERANCE, result.pressure_difference


@pytest.mark.parametrize("h", [0.1, 0.05])
@pytest.mark.parametrize("configuration", ["initial", "previous"])
@pytest.mark.parametrize("kind", ["LcLS*", "LmLS*"])
def test_a_3d_slab_pressed_against_itself_matches_its_half(kind, configuration, h):
    """The C extruded into a slab 0.1 thick (tetrahedra, its faces held in z): a
    3D surface of triangles in contact with itself (measured 4e-5 to 1.6e-4)."""
    result = self_mirror(h, 0.02, penalty=2e4, kind=kind, basis_configuration=configuration,
                         thickness=0.1)
    assert result.alone.p.max() > 0
    assert result.pressure_difference < TOLERANCE, result.pressure_difference


def test_the_search_radius_check_pairs_as_the_bases_pair(caplog):
    """The slab with LcLS* at h = 0.05: the check "the contact zone reached the
    search radius" once searched with the slave's own normals, where the bases
    pair with the interface normals. By the slot's concave corners it found, at
    every radius, masters the bases never pair: the radius went 0.05 → 3.2 (the
    body is 1 across), each step was solved four times, and it warned that the
    pressure was cut off. Now one widening, and no warning."""
    with caplog.at_level(logging.INFO, logger="dolfinx_mortar.contact.checks"), \
            warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        result = self_mirror(0.05, 0.02, penalty=2e4, kind="LcLS*",
                             basis_configuration="initial", thickness=0.1)
    widened = [r for r in caplog.records if "bases rebuilt" in r.getMessage()]
    assert len(widened) <= 1          # logged on rank 0 only
    assert result.pressure_difference < TOLERANCE, result.pressure_difference


@pytest.mark.parametrize("h", [0.05, 0.025, 0.0125])
def test_a_body_pressed_against_itself_on_the_current_surface(h):
    """basis_configuration="current" (LmLS*: the dual kinds read a false penetration
    there, refused where the term is made; with their basis rebuilt over the covered
    part, refused in self-contact, the C body squeezed 0.01 read 6e-3 at the nodes
    where its arc meets its arms, whose facets its own surface covers over a small
    piece only): 1.25e-4, 1.9e-4, 3.1e-5 (4.9e-3 at h = 0.1, five facets on the arc)."""
    result = self_mirror(h, 0.02, penalty=2e4, kind="LmLS*", basis_configuration="current")
    assert result.pressure_difference < TOLERANCE, result.pressure_difference


@pytest.mark.parametrize("shape", [{"thickness": 0.1}, {"axisymmetric": True}])
def test_self_contact_on_the_current_surface_in_3d_and_axisymmetric(shape):
    """The slab (1.6e-4) and the body of revolution (1.25e-4) at h = 0.05."""
    result = self_mirror(0.05, 0.02, penalty=2e4, kind="LmLS*", basis_configuration="current",
                         **shape)
    assert result.pressure_difference < TOLERANCE, result.pressure_difference


@pytest.mark.parametrize("kind", ["LmLS*", "LmLS", "GLS*"])
def test_self_contact_with_the_pointwise_active_set(kind):
    result = self_mirror(0.05, 0.02, penalty=2e4, kind=kind, active_set="pointwise")
    assert result.pressure_difference < TOLERANCE, result.pressure_difference


@pytest.mark.parametrize("dim, n, axisymmetric, kind, configuration", [
    (2, 12, False, "LcLS*", "initial"), (2, 12, True, "LcLS*", "initial"),
    (3, 6, False, "LcLS*", "initial"), (3, 6, False, "LmLS*", "previous"),
    (2, 12, False, "GLS*", "previous"), (3, 6, False, "GLS*", "initial")])
def test_two_bodies_under_one_term_match_the_two_body_mirror(dim, n, axisymmetric, kind,
                                                              configuration):
    """Two separately meshed bodies, their contact surfaces given to one
    self-contact term as a list of tags (no slave or master named), in plane
    strain, axisymmetric and 3D: the pressures on the upper body match its
    rigid-plane problem node by node (measured 1.7e-4 to 2.6e-4), and the
    contact forces inside the pair cancel."""
    comm, d = MPI.COMM_WORLD, 0.02
    options = dict(E=1.0, nu=0.3, kind=kind, basis_configuration=configuration,
                   axisymmetric=axisymmetric)
    normal = np.zeros(dim)
    normal[-1] = 1.0
    upper, upper_tags = two_bodies.body(comm, n, dim)
    V = fem.functionspace(upper, ("Lagrange", 1, (dim,)))
    alone = ContactProblem(V, upper_tags, two_bodies.CONTACT, penalty=2e4,
                           obstacle=RigidPlane(np.zeros(dim), normal),
                           fixed=two_bodies._supports(dim, d), **options)
    alone.solve(load_steps=2)
    upper, upper_tags = two_bodies.body(comm, n, dim)
    lower, lower_tags = two_bodies.body(comm, n, dim, mirrored=True)
    offset = two_bodies.LOWER_OFFSET
    shared = [two_bodies.SYMMETRY_X] + ([two_bodies.SYMMETRY_Y] if dim == 3 else [])
    domain, tags, _ = merge_meshes(upper, upper_tags, lower, lower_tags, tag_offset=offset,
                                   shared_tags=shared)
    V = fem.functionspace(domain, ("Lagrange", 1, (dim,)))
    pair = ContactProblem(V, tags, [two_bodies.CONTACT, two_bodies.CONTACT + offset],
                          self_contact=True, penalty=1e4,
                          fixed={**two_bodies._supports(dim, d),
                                 **two_bodies._supports(dim, d, lower=True)}, **options)
    pair.solve(load_steps=2)
    a, b = alone.surface_pressure(gather=True), pair.surface_pressure(gather=True)
    # the upper body's nodes (the apex is on both bodies: compared without it)
    upper_a, upper_b = a.x[:, -1] > 1e-12, b.x[:, -1] > 1e-12
    order_a, order_b = np.lexsort(a.x[upper_a].T), np.lexsort(b.x[upper_b].T)
    assert np.allclose(a.x[upper_a][order_a], b.x[upper_b][order_b], rtol=0, atol=1e-12)
    difference = np.linalg.norm(a.p[upper_a][order_a] - b.p[upper_b][order_b])
    assert difference < TOLERANCE * np.linalg.norm(a.p[upper_a])
    assert np.linalg.norm(pair.contact_force()) < 1e-10 * alone.contact_force()[-1]


def c_body_surface():
    domain, tags = build(MPI.COMM_WORLD, 0.05, whole=True)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    return V, tags, facet_surface(V, tags, CONTACT)


def test_a_surface_pairs_with_itself_only_away_from_its_neighbours_and_face_to_face():
    """The C body's inner surface at rest, searched against itself with a radius
    of four facets: no pair of facets that share a node or a neighbour (at the
    slot's corners they face each other at zero distance), and every pair faces
    each other (the arcs' facets face their own neighbours' backs)."""
    _, _, surface = c_body_surface()
    coupling = MortarCoupling(surface, surface, search_radius=0.2, self_contact=True,
                              interface_normals=True)
    pairs = coupling.pairs
    slave_nodes = surface.layout.global_indices[surface.cells[pairs[:, 0]]]
    master_nodes = coupling.master_global_ids[coupling.master_cells[pairs[:, 1]]]
    shared = [bool(set(s) & set(m)) for s, m in zip(slave_nodes, master_nodes)]
    assert not any(shared)
    total = MPI.COMM_WORLD.allreduce(len(pairs))
    assert total > 0          # the arms face each other across the slot
    def normals(x, cells):          # a line's normal: its tangent turned (one orientation)
        t = x[cells[:, 1]] - x[cells[:, 0]]
        return np.stack([t[:, 1], -t[:, 0]], axis=1)

    slave_normal = normals(surface.x, surface.cells[pairs[:, 0]])
    master_normal = normals(coupling.master_copy.x, coupling.master_cells[pairs[:, 1]])
    assert np.all(np.einsum("pi,pi->p", slave_normal, master_normal) < 0)


@pytest.mark.parametrize("arguments, error, match", [
    ({"master_tag": 3}, ValueError, "self_contact=True takes no master_tag"),
    ({"obstacle": RigidPlane([0.0, 0.0], [0.0, 1.0])}, ValueError, "takes no master_tag"),
    ({"kind": "GLS", "basis_configuration": "current"}, NotImplementedError,
     "'current' with GLS: L\\(u\\) couples every slave facet"),
    ({"kind": "LcLS*", "active_set": "pointwise"}, NotImplementedError, "dual kind"),
    ({"kind": "LcLS", "basis_configuration": "current", "boundary_modification": True},
     NotImplementedError, "current surface with the boundary modification"),
])
def test_what_self_contact_refuses_is_named(arguments, error, match):
    V, tags, _ = c_body_surface()
    u = fem.Function(V)
    with pytest.raises(error, match=match), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ContactTerm(u, tags, CONTACT, self_contact=True, penalty=1e3,
                    **{"kind": "LcLS*", **arguments})


def test_a_gls_kind_that_reads_a_sliver_as_an_overlap_says_so():
    """The C slab in 3D with GLS*: the node at the slot's corner, whose facets the
    surface covers over 1% only, reads 6.9 element lengths deep through the
    covered part's nearly singular L (LmLS* reads it 1.4 apart). The start is
    refused as an overlap, and the error names that cause and the way out."""
    with pytest.raises(ValueError, match=r"overlaps itself at the start.*GLS kind.*over a "
                       r"sliver only.*a local kind reads the true gap"):
        self_mirror(0.1, 0.02, penalty=2e4, kind="GLS*", thickness=0.1)


def test_a_body_that_overlaps_itself_at_the_start_is_refused_naming_where():
    """The C body with its lower arm bent up into the upper one by 0.04 at the
    apex (0.8 of its facets): an error on every rank naming a node, where two
    bodies would get a warning only."""
    V, tags, _ = c_body_surface()
    x = V.mesh.geometry.x
    lower = x[:, 1] < 0
    x[lower, 1] += 0.04 * np.maximum(0.0, 1.0 - x[lower, 0] / 0.5) ** 2
    V = fem.functionspace(V.mesh, ("Lagrange", 1, (2,)))
    with pytest.raises(ValueError, match=r"overlaps itself at the start: the node \[") as err:
        ContactTerm(fem.Function(V), tags, CONTACT, self_contact=True, penalty=1e3)
    assert "element lengths" in str(err.value)


def test_the_output_covers_both_sides_of_a_self_contact(tmp_path):
    """The XDMF series of a self-contact term: the pressure p̂ on every node of
    the surface, whichever side of a pair it was on (both arms carry it, equal
    by symmetry within the mesh's asymmetry)."""
    from dolfinx_mortar import read_xdmf_series
    from demo_support.self_mirror import BOTTOM, SYMMETRY_X, TOP
    folder = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    domain, tags = build(MPI.COMM_WORLD, 0.05, whole=True)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    problem = ContactProblem(V, tags, CONTACT, self_contact=True, E=1.0, nu=0.3, penalty=1e4,
                             fixed={TOP: {1: -0.02}, BOTTOM: {1: 0.02}, SYMMETRY_X: {0: 0.0}})
    problem.solve(load_steps=1, output=f"{folder}/run.xdmf")
    pressures = problem.surface_pressure(gather=True)
    data = read_xdmf_series(f"{folder}/run_slave.xdmf")
    _, p_hat = data.field("p_hat")
    upper, lower = pressures.p[pressures.x[:, 1] > 0], pressures.p[pressures.x[:, 1] < 0]
    assert upper.max() > 0 and lower.max() > 0
    assert upper.max() == pytest.approx(lower.max(), rel=0.05)
    # the file's nodes (one copy per facet) on both arms carry the pressure
    y, written = data.geometry[:, 1], p_hat[-1].reshape(len(data.geometry), -1)[:, 0]
    assert written[y > 0].max() == pytest.approx(upper.max(), rel=1e-12)
    assert written[y < 0].max() == pytest.approx(lower.max(), rel=1e-12)


def test_a_self_contact_tag_that_marks_nothing_is_named():
    V, tags, _ = c_body_surface()
    with pytest.raises(ValueError, match="17"):
        ContactTerm(fem.Function(V), tags, [CONTACT, 17], self_contact=True, penalty=1e3)
