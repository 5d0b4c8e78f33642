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
