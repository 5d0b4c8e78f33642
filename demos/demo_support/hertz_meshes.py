"""The gmsh meshes of the 2D Hertz scenes (plane strain and axisymmetric).

A quarter disk {x ≥ 0, y ≤ R, x² + (y − R)² ≤ R²} touching y = 0 at the
origin: in plane strain the quarter of a cylinder, in (r, z) axisymmetry the
lower half of a sphere. Below it either nothing (a rigid obstacle, not
meshed), an elastic block [0, 2R] × [−2R, 0], or a second quarter disk
mirrored about y = 0 (two equal bodies). Graded towards the contact point.
"""
from __future__ import annotations

from mpi4py import MPI

SLAVE, MASTER, SYMMETRY, LOAD, FIXED = 1, 2, 3, 4, 5
LOWER_BODIES = ("none", "block", "disk")


def quarter_disk_mesh(radius: float, a: float, h_contact: float, lower: str, degree: int,
                      comm: MPI.Comm):
    """Mesh and facet tags of the scene.

    Parameters
    ----------
    radius
        R.
    a
        The expected contact size: the mesh has size ``h_contact`` within
        1.5a of the contact point and grows to R/8 beyond 1.5a + 5R.
    h_contact
        Element size at the contact.
    lower
        ``"none"``, ``"block"`` or ``"disk"`` (see the module docstring).
    degree
        Geometry degree, 1 or 2.
    comm
        The communicator to distribute the mesh on.

    Returns
    -------
    The DOLFINx mesh and its facet tags: SLAVE (the upper arc), MASTER (the
    lower body's top), SYMMETRY (x = 0), LOAD (y = R), FIXED (the lower
    body's bottom).
    """
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    from dolfinx_mortar.io.gmsh_io import grade_towards_point
    if lower not in LOWER_BODIES:
        raise ValueError(f"lower body must be one of {LOWER_BODIES}, got {lower!r}")
    R = radius
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            quarter, _ = occ.intersect([(2, occ.addDisk(0, R, 0, R, R))],
                                       [(2, occ.addRectangle(0, 0, 0, R, R))])
            surfaces = [quarter[0][1]]
            bottom = None
            if lower == "block":
                surfaces.append(occ.addRectangle(0, -2 * R, 0, 2 * R, 2 * R))
                bottom = -2 * R
            elif lower == "disk":
                mirrored, _ = occ.intersect([(2, occ.addDisk(0, -R, 0, R, R))],
                                            [(2, occ.addRectangle(0, -R, 0, R, R))])
                surfaces.append(mirrored[0][1])
                bottom = -R
            occ.synchronize()
            tags: dict = {SLAVE: [], MASTER: [], SYMMETRY: [], LOAD: [], FIXED: []}
            tol = 1e-6 * R
            for _, curve in gmsh.model.getEntities(1):
                x, y, _ = occ.getCenterOfMass(1, curve)
                if abs(x) < tol:
                    tags[SYMMETRY].append(curve)      # x = 0 of both bodies
                elif abs(y - R) < tol:
                    tags[LOAD].append(curve)
                elif bottom is not None and abs(y - bottom) < tol:
                    tags[FIXED].append(curve)
                elif y > 0:
                    tags[SLAVE].append(curve)         # the upper arc
                else:
                    tags[MASTER].append(curve)        # the block's top or the lower arc
            for tag, curves in tags.items():
                if curves:
                    gmsh.model.addPhysicalGroup(1, curves, tag)
            for i, s in enumerate(surfaces):
                gmsh.model.addPhysicalGroup(2, [s], 10 + i)
            grade_towards_point((0, 0, 0), h_contact, R / 8, 1.5 * a, 1.5 * a + 40 * (R / 8))
            gmsh.model.mesh.generate(2)
            if degree == 2:
                gmsh.model.mesh.setOrder(2)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    return domain, facet_tags


def half_disk_pair_mesh(radius: float, a: float, h_contact: float, degree: int,
                        comm: MPI.Comm):
    """Two equal half disks touching at the origin: the upper one
    {y ≤ R, x² + (y − R)² ≤ R²} and its mirror about y = 0, graded towards the
    contact point as :func:`quarter_disk_mesh` (without a symmetry plane: a
    tangential load is not symmetric).

    Returns the DOLFINx mesh and its facet tags: SLAVE (the upper arc), MASTER
    (the lower arc), LOAD (y = R), FIXED (y = −R).
    """
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    from dolfinx_mortar.io.gmsh_io import grade_towards_point
    R = radius
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            upper, _ = occ.intersect([(2, occ.addDisk(0, R, 0, R, R))],
                                     [(2, occ.addRectangle(-R, 0, 0, 2 * R, R))])
            lower, _ = occ.intersect([(2, occ.addDisk(0, -R, 0, R, R))],
                                     [(2, occ.addRectangle(-R, -R, 0, 2 * R, R))])
            occ.synchronize()
            tags: dict = {SLAVE: [], MASTER: [], LOAD: [], FIXED: []}
            tol = 1e-6 * R
            for _, curve in gmsh.model.getEntities(1):
                _, y, _ = occ.getCenterOfMass(1, curve)
                if abs(y - R) < tol:
                    tags[LOAD].append(curve)
                elif abs(y + R) < tol:
                    tags[FIXED].append(curve)
                elif y > 0:
                    tags[SLAVE].append(curve)
                else:
                    tags[MASTER].append(curve)
            for tag, curves in tags.items():
                gmsh.model.addPhysicalGroup(1, curves, tag)
            gmsh.model.addPhysicalGroup(2, [upper[0][1]], 10)
            gmsh.model.addPhysicalGroup(2, [lower[0][1]], 11)
            grade_towards_point((0, 0, 0), h_contact, R / 8, 1.5 * a, 1.5 * a + 40 * (R / 8))
            gmsh.model.mesh.generate(2)
            if degree == 2:
                gmsh.model.mesh.setOrder(2)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=2)
    finally:
        gmsh.finalize()
    return domain, facet_tags


#: the symmetry plane y = 0 of :func:`half_sphere_pair_mesh`
SYMMETRY_Y = 6


def half_sphere_pair_mesh(radius: float, a: float, h_contact: float, comm: MPI.Comm):
    """Two equal hemispheres touching at the origin, cut in half by the plane
    y = 0 (a lateral load along x keeps that symmetry): the upper one
    {z ≤ R, |x − (0, 0, R)| ≤ R, y ≥ 0} and its mirror about z = 0, graded
    towards the contact point from ``h_contact`` within 1.3a to R/5.

    Returns the DOLFINx mesh and its facet tags: SLAVE (the upper sphere),
    MASTER (the lower one), LOAD (z = R), FIXED (z = −R), SYMMETRY_Y (y = 0).
    """
    import gmsh
    from dolfinx_mortar.io.gmsh_io import grade_towards_point, model_to_mesh
    R = radius
    gmsh.initialize(["", "-v", "0"])
    try:
        if comm.rank == 0:
            occ = gmsh.model.occ
            upper, _ = occ.intersect([(3, occ.addSphere(0, 0, R, R))],
                                     [(3, occ.addBox(-R, 0, 0, 2 * R, R, R))])
            lower, _ = occ.intersect([(3, occ.addSphere(0, 0, -R, R))],
                                     [(3, occ.addBox(-R, 0, -R, 2 * R, R, R))])
            occ.synchronize()
            tags: dict = {SLAVE: [], MASTER: [], LOAD: [], FIXED: [], SYMMETRY_Y: []}
            tol = 1e-6 * R
            for body, curved in ((upper, SLAVE), (lower, MASTER)):
                for _, s in gmsh.model.getBoundary(body, oriented=False):
                    _, y, z = occ.getCenterOfMass(2, s)
                    if abs(y) < tol:
                        tags[SYMMETRY_Y].append(s)
                    elif abs(z - R) < tol:
                        tags[LOAD].append(s)
                    elif abs(z + R) < tol:
                        tags[FIXED].append(s)
                    else:
                        tags[curved].append(s)
            for tag, surfaces in tags.items():
                gmsh.model.addPhysicalGroup(2, surfaces, tag)
            gmsh.model.addPhysicalGroup(3, [upper[0][1]], 10)
            gmsh.model.addPhysicalGroup(3, [lower[0][1]], 11)
            grade_towards_point((0, 0, 0), h_contact, R / 5, 1.3 * a, 1.3 * a + 12 * (R / 5))
            gmsh.model.mesh.generate(3)
        domain, _, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=3)
    finally:
        gmsh.finalize()
    return domain, facet_tags
