"""A body that touches itself, and its half on a rigid plane: the self-contact mirror test.

The body is a C in plane strain: two arms, mirror images in y = 0, whose inner faces are the
circle arcs y = ±(R − sqrt(R² − x²)) for 0 ≤ x ≤ W, touching at the origin; the slot between
them is closed by the segments x = W, |y| ≤ f(W), and a bridge [W, W + L] x [−H, H] joins the
arms. Its top is moved down by d and its bottom up by d, so that the arms press against each
other; one self-contact term holds its whole inner surface (both arcs and the slot's end).
By symmetry the plane y = 0 stays where it is, and the upper half deforms exactly as when it
alone is pressed on the frictionless rigid plane y = 0, held on y = 0 along the bridge. The
upper half's mesh is the same in both problems (the lower half is its mirror image, joined to
it along the bridge), so the contact pressures compare node by node.
"""
from __future__ import annotations

from dataclasses import dataclass

import basix.ufl
import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from demo_support.boundary_tags import tag_boundary_facets
from dolfinx_mortar import ContactProblem, RigidPlane, SurfacePressure
from dolfinx_mortar.dolfinx_compat import create_mesh

R, W, H, L = 1.0, 0.5, 0.5, 0.25
#: facet tags: the inner surface, the moved tops (upper, lower), the symmetry x = 0, the bridge's
#: plane y = 0 (half body only)
CONTACT, TOP, BOTTOM, SYMMETRY_X, BRIDGE, SLAB = 1, 2, 3, 4, 5, 6


def arc(x):
    return R - np.sqrt(np.maximum(R**2 - x**2, 0.0))


def half_triangles(h: float, thickness: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The upper half's triangles by gmsh (rank 0): nodes (n, 2) and cells (m, 3); with a
    ``thickness``, the slab of that thickness in z: tetrahedra, nodes (n, 3)."""
    import gmsh
    gmsh.initialize(["", "-v", "0"])
    try:
        gmsh.model.add("half")
        geo = gmsh.model.geo
        # a circle arc: its mesh nodes lie on the circle
        arc_points = [geo.addPoint(0.0, 0.0, 0.0, h), geo.addPoint(W, arc(W), 0.0, h)]
        centre = geo.addPoint(0.0, R, 0.0, h)
        corners = [geo.addPoint(*p, 0.0, h) for p in ((W, 0.0), (W + L, 0.0), (W + L, H), (0.0, H))]
        lines = [geo.addCircleArc(arc_points[0], centre, arc_points[1])]
        loop = [arc_points[-1], corners[0], corners[1], corners[2], corners[3], arc_points[0]]
        lines += [geo.addLine(a, b) for a, b in zip(loop[:-1], loop[1:])]
        surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        dim = 2
        if thickness:
            layers = max(1, int(round(thickness / h)))
            volume = [e for e in geo.extrude([(2, surface)], 0, 0, thickness, [layers]) if e[0] == 3]
            dim = 3
        geo.synchronize()
        gmsh.model.addPhysicalGroup(dim, [1 if dim == 2 else volume[0][1]], 1)
        gmsh.model.mesh.generate(dim)
        tags, x, _ = gmsh.model.mesh.getNodes()
        order = np.argsort(tags)
        x = x.reshape(-1, 3)[order, :dim]
        index = np.empty(int(tags.max()) + 1, dtype=np.int64)
        index[tags[order].astype(np.int64)] = np.arange(len(order))
        _, cell_nodes = gmsh.model.mesh.getElementsByType(2 if dim == 2 else 4)
        cells = index[cell_nodes.astype(np.int64)].reshape(-1, dim + 1)
        return x, cells
    finally:
        gmsh.finalize()


def build(comm: MPI.Comm, h: float, whole: bool, thickness: float = 0.0):
    """The C body (``whole``) or its upper half, on triangles of size h (with a
    ``thickness``: the slab, on tetrahedra): mesh and facet tags."""
    dim = 3 if thickness else 2
    x = np.zeros((0, dim))
    cells = np.zeros((0, dim + 1), dtype=np.int64)
    if comm.rank == 0:
        x, cells = half_triangles(h, thickness)
        if whole:
            # the mirror image, its nodes on the bridge's plane y = 0 shared with the half
            shared = (x[:, 1] == 0.0) & (x[:, 0] >= W)
            image = np.where(shared, np.arange(len(x)), len(x) + np.cumsum(~shared) - 1)
            flip = np.ones(dim)
            flip[1] = -1.0
            x = np.vstack([x, x[~shared] * flip])
            cells = np.vstack([cells, image[cells]])
    cell = "triangle" if dim == 2 else "tetrahedron"
    element = ufl.Mesh(basix.ufl.element("Lagrange", cell, 1, shape=(dim,)))
    domain = create_mesh(comm, cells, x, element)
    tol = 1e-9

    def inner(p):
        on_arc = (p[0] <= W + tol) & np.isclose(np.abs(p[1]), arc(p[0]))
        slot_end = np.isclose(p[0], W) & (np.abs(p[1]) <= arc(W) + tol)
        bridge = (p[0] > W - tol) & np.isclose(p[1], 0.0)
        return (on_arc | slot_end) & (~bridge if not whole else True)

    marks = [(TOP, lambda p: np.isclose(p[1], H)), (SYMMETRY_X, lambda p: np.isclose(p[0], 0.0)),
             (CONTACT, inner)]
    if whole:
        marks.append((BOTTOM, lambda p: np.isclose(p[1], -H)))
    else:
        marks.append((BRIDGE, lambda p: np.isclose(p[1], 0.0) & (p[0] > W - tol)))
    if dim == 3:
        marks.append((SLAB, lambda p: np.isclose(p[2], 0.0) | np.isclose(p[2], thickness)))
    return domain, tag_boundary_facets(domain, marks)


@dataclass
class SelfMirrorResult:
    """The rigid-plane and the self-contact pressures on the upper arc."""

    alone: SurfacePressure
    whole: SurfacePressure

    @property
    def pressure_difference(self) -> float:
        """Relative L2 difference of the nodal pressures on the upper arc (node by node)."""
        return float(np.linalg.norm(self.whole.p - self.alone.p) / np.linalg.norm(self.alone.p))


def upper_arc(p: SurfacePressure) -> SurfacePressure:
    """The nodes of the upper arc (y > 0, x < W), sorted by their coordinates."""
    keep = (p.x[:, 1] > 0.0) & (p.x[:, 0] < W)
    order = np.lexsort(p.x[keep].T)
    return SurfacePressure(p.x[keep][order], p.p[keep][order], p.global_index[keep][order])


def self_mirror(h: float, d: float, *, penalty: float, load_steps: int = 2,
                comm: MPI.Comm = MPI.COMM_WORLD, thickness: float = 0.0,
                **options) -> SelfMirrorResult:
    """Solve both problems; ``options`` go to :class:`ContactProblem` (E = 1, nu = 0.3 by
    default). ``penalty`` is the rigid-plane problem's; the self-contact gets half of it
    (its gap is the sum of both arms' approaches). ``thickness``: the slab in 3D, held
    on its faces z = 0 and z = thickness in z."""
    options = {"E": 1.0, "nu": 0.3, **options}
    dim = 3 if thickness else 2
    slab = {SLAB: {2: 0.0}} if thickness else {}
    half, half_tags = build(comm, h, whole=False, thickness=thickness)
    V = fem.functionspace(half, ("Lagrange", 1, (dim,)))
    normal = np.zeros(dim)
    normal[1] = 1.0
    alone = ContactProblem(V, half_tags, CONTACT, obstacle=RigidPlane(np.zeros(dim), normal),
                           fixed={TOP: {1: -d}, SYMMETRY_X: {0: 0.0}, BRIDGE: {1: 0.0}, **slab},
                           penalty=penalty, **options)
    alone.solve(load_steps=load_steps)
    body, body_tags = build(comm, h, whole=True, thickness=thickness)
    V = fem.functionspace(body, ("Lagrange", 1, (dim,)))
    whole = ContactProblem(V, body_tags, CONTACT, self_contact=True, penalty=penalty / 2,
                           fixed={TOP: {1: -d}, BOTTOM: {1: d}, SYMMETRY_X: {0: 0.0}, **slab},
                           **options)
    whole.solve(load_steps=load_steps)
    a = upper_arc(alone.surface_pressure(gather=True))
    b = upper_arc(whole.surface_pressure(gather=True))
    if a.x.shape != b.x.shape or not np.allclose(a.x, b.x, rtol=0, atol=1e-12):
        raise RuntimeError("the upper arc differs between the two meshes")
    return SelfMirrorResult(a, b)
