"""Reading gmsh files into DOLFINx, with the names of their physical groups.

DOLFINx 0.5.2's ``gmshio.read_from_msh`` finalizes gmsh and then returns an
undefined name on the reading rank, so it cannot be used; this opens the file
on one rank and hands the model to ``gmshio.model_to_mesh`` itself.
"""
from __future__ import annotations

from pathlib import Path
from typing import Union

from mpi4py import MPI


def read_gmsh(path: Union[str, Path], comm: MPI.Comm, gdim: int = 3):
    """Mesh, cell tags, facet tags and ``{dim: {name: tag}}`` of a .msh file.

    Raises
    ------
    FileNotFoundError
        If the file does not exist (checked on every rank).
    """
    import gmsh
    from dolfinx.io import gmshio
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no gmsh file at {path}")
    gmsh.initialize(["", "-v", "0"])
    try:
        names = None
        if comm.rank == 0:
            gmsh.open(str(path))
            names = {}
            for dim, tag in gmsh.model.getPhysicalGroups():
                names.setdefault(dim, {})[gmsh.model.getPhysicalName(dim, tag)] = tag
        names = comm.bcast(names)
        domain, cell_tags, facet_tags = gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=gdim)
    finally:
        gmsh.finalize()
    return domain, cell_tags, facet_tags, names


def grade_towards_point(point: tuple, size_min: float, size_max: float,
                        dist_min: float, dist_max: float) -> None:
    """Make the current gmsh model's mesh size grow from ``size_min`` within
    ``dist_min`` of ``point`` to ``size_max`` beyond ``dist_max`` (call on the
    rank that builds the model, before meshing)."""
    import gmsh
    tag = gmsh.model.occ.addPoint(*point)
    gmsh.model.occ.synchronize()
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", [tag])
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", size_min)
    field.setNumber(threshold, "SizeMax", size_max)
    field.setNumber(threshold, "DistMin", dist_min)
    field.setNumber(threshold, "DistMax", dist_max)
    field.setAsBackgroundMesh(threshold)
    # the field alone decides the size
    for option in ("MeshSizeExtendFromBoundary", "MeshSizeFromPoints", "MeshSizeFromCurvature"):
        gmsh.option.setNumber(f"Mesh.{option}", 0)
