"""Two equal bodies pressed together, and one of them on a rigid plane: the mirror test.

The upper body is the box [0, W]^(dim-1) x [f, H] whose bottom f = R - sqrt(R² - |x|²) is a
circle (2D, plane strain), a sphere (3D), or a sphere seen in its (r, z) half-plane
(axisymmetric), touching z = 0 at the origin. It is held on its symmetry planes (x = 0, and
y = 0 in 3D; the axis r = 0) and its top is moved down by d. The lower body is its mirror image
in z = 0, moved up by d. By symmetry the two-body interface stays on z = 0 and the upper body
deforms exactly as when it alone is moved down by d against the frictionless rigid plane z = 0,
with twice the penalty (the two-body gap is the sum of both bodies' approaches). The upper mesh
is the same in both problems, so the contact pressures compare node by node.

The meshes are structured (quadrilaterals, hexahedra), graded towards the contact point, and
made by DOLFINx alone, so the mirror image is exact.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import fem, mesh
from mpi4py import MPI

from demo_support.boundary_tags import tag_boundary_facets
from dolfinx_mortar import ContactProblem, RigidPlane, SurfacePressure

R, W, H = 1.0, 0.5, 0.5
#: facet tags of a body: its moved top, the contact surface, its symmetry planes
TOP, CONTACT, SYMMETRY_X, SYMMETRY_Y = 1, 2, 3, 4
#: the lower body's tags in the merged mesh are offset by this (the symmetry planes shared)
LOWER_OFFSET = 10
GRADING = 1.5


def body(comm: MPI.Comm, n: int, dim: int, mirrored: bool = False, lift: float = 0.0):
    """The upper body (or its mirror image) on n cells per direction, lifted by ``lift``
    away from z = 0: mesh and facet tags."""
    if dim == 2:
        domain = mesh.create_rectangle(comm, [[0.0, 0.0], [1.0, 1.0]], [n, n],
                                       cell_type=mesh.CellType.quadrilateral)
    else:
        domain = mesh.create_box(comm, [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]], [n, n, n],
                                 cell_type=mesh.CellType.hexahedron)
    x = domain.geometry.x
    plane = W * x[:, : dim - 1] ** GRADING
    bottom = R - np.sqrt(R**2 - np.sum(plane**2, axis=1))
    height = lift + bottom + (H - bottom) * x[:, dim - 1] ** GRADING
    x[:, : dim - 1] = plane
    x[:, dim - 1] = -height if mirrored else height
    top = -(H + lift) if mirrored else H + lift

    def on_sphere(p):
        radial = np.sum(p[: dim - 1] ** 2, axis=0)
        return np.isclose(np.abs(p[dim - 1]), lift + R - np.sqrt(np.maximum(R**2 - radial, 0.0)))

    marks = [(TOP, lambda p: np.isclose(p[dim - 1], top)), (CONTACT, on_sphere),
             (SYMMETRY_X, lambda p: np.isclose(p[0], 0.0))]
    if dim == 3:
        marks.append((SYMMETRY_Y, lambda p: np.isclose(p[1], 0.0)))
    return domain, tag_boundary_facets(domain, marks)


def _supports(dim: int, d: float, lower: bool = False) -> dict:
    offset = LOWER_OFFSET if lower else 0
    fixed = {TOP + offset: {dim - 1: d if lower else -d}}
    fixed[SYMMETRY_X] = {0: 0.0}
    if dim == 3:
        fixed[SYMMETRY_Y] = {1: 0.0}
    return fixed


@dataclass
class MirrorResult:
    """The rigid-plane and the two-body solutions on the upper body's contact surface."""

    alone: SurfacePressure
    pair: SurfacePressure
    force_alone: float
    force_pair: float

    @property
    def pressure_difference(self) -> float:
        """Relative L2 difference of the nodal pressures (node by node)."""
        return float(np.linalg.norm(self.pair.p - self.alone.p) / np.linalg.norm(self.alone.p))

    @property
    def force_difference(self) -> float:
        """Relative difference of the contact forces on the upper body."""
        return (self.force_pair - self.force_alone) / self.force_alone


def mirror(n: int, d: float, *, dim: int = 2, axisymmetric: bool = False, penalty: float,
           load_steps: int = 4, comm: MPI.Comm = MPI.COMM_WORLD, gap: float = 0.0,
           **options) -> MirrorResult:
    """Solve both problems; ``options`` go to :class:`ContactProblem` (E and nu default to
    1 and 0.3). ``penalty`` is the rigid-plane problem's; the pair gets half of it.
    ``gap``: the bodies start this far apart (each lifted by half of it off z = 0), and
    each is moved by ``d`` more than half of it."""
    options = {"E": 1.0, "nu": 0.3, **options}
    lift, d = gap / 2, d + gap / 2
    upper, upper_tags = body(comm, n, dim, lift=lift)
    V = fem.functionspace(upper, ("Lagrange", 1, (dim,)))
    normal = np.zeros(dim)
    normal[-1] = 1.0
    alone = ContactProblem(V, upper_tags, CONTACT, obstacle=RigidPlane(np.zeros(dim), normal),
                           fixed=_supports(dim, d), penalty=penalty, axisymmetric=axisymmetric,
                           **options)
    alone.solve(load_steps=load_steps)
    upper, upper_tags = body(comm, n, dim, lift=lift)
    lower, lower_tags = body(comm, n, dim, mirrored=True, lift=lift)
    shared = [SYMMETRY_X, SYMMETRY_Y] if dim == 3 else [SYMMETRY_X]
    pair = ContactProblem.from_two_meshes(
        upper, upper_tags, CONTACT, lower, lower_tags, CONTACT, tag_offset=LOWER_OFFSET,
        shared_tags=shared, fixed={**_supports(dim, d), **_supports(dim, d, lower=True)},
        penalty=penalty / 2, axisymmetric=axisymmetric, **options)
    pair.solve(load_steps=load_steps)
    a, b = alone.surface_pressure(gather=True), pair.surface_pressure(gather=True)
    if a.x.shape != b.x.shape or not np.allclose(a.x, b.x, rtol=0, atol=1e-12 * R):
        raise RuntimeError("the upper contact surface differs between the two meshes")
    return MirrorResult(a, b, float(alone.contact_force()[dim - 1]),
                        float(pair.contact_force()[dim - 1]))
