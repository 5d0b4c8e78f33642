"""Reading gmsh models and files into DOLFINx, with the names of their
physical groups, optionally with the contact surfaces spread over the ranks.

DOLFINx 0.5.2's ``gmshio.read_from_msh`` finalizes gmsh and then returns an
undefined name on the reading rank, so it cannot be used; this opens the file
on one rank and hands the model to ``gmshio.model_to_mesh`` itself.
"""
from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Callable, Iterator, Optional, Sequence, Union

import numpy as np
from mpi4py import MPI


@contextlib.contextmanager
def _gmshio_create_mesh(replacement: Callable) -> Iterator[None]:
    """Make ``gmshio.model_to_mesh`` create its mesh with ``replacement``.

    DOLFINx 0.5.2's ``model_to_mesh`` has no partitioner argument (0.6 added
    one) and calls the ``create_mesh`` of its module's namespace, so that
    name is swapped for the duration of the call instead of copying the
    function's 90 lines.
    """
    from dolfinx.io import gmshio
    original = gmshio.create_mesh
    gmshio.create_mesh = replacement
    try:
        yield
    finally:
        gmshio.create_mesh = original


def model_to_mesh(model, comm: MPI.Comm, rank: int = 0, gdim: int = 3,
                  balance_facets: Optional[Sequence[int]] = None):
    """``dolfinx.io.gmshio.model_to_mesh``, optionally with the cells next to
    some facets spread evenly over the ranks.

    Parameters
    ----------
    model
        The gmsh model, built on ``rank``.
    comm, rank, gdim
        As for ``gmshio.model_to_mesh``.
    balance_facets
        Physical tags of the facet groups (the contact surfaces) whose
        adjacent cells every rank should get an equal share of
        (:func:`~dolfinx_mortar.io.contact_partitioner.contact_balanced_partitioner`).
        ``None`` uses DOLFINx's graph partitioner alone.

    Returns
    -------
    The mesh, its cell tags and its facet tags.

    Raises
    ------
    ValueError
        If a tag in ``balance_facets`` is no physical group of facets.
    """
    from dolfinx.io import gmshio
    if balance_facets is None:
        return gmshio.model_to_mesh(model, comm, rank, gdim=gdim)
    tags = [int(t) for t in balance_facets]
    surface_nodes = None
    error = None
    if comm.rank == rank:
        tdim = max(dim for dim, _ in model.getPhysicalGroups())
        present = {tag for dim, tag in model.getPhysicalGroups() if dim == tdim - 1}
        missing = sorted(set(tags) - present)
        if missing:
            error = (f"balance_facets {missing} are no physical groups of facets "
                     f"(dimension {tdim - 1}) of the gmsh model; present: {sorted(present)}")
        else:
            # gmsh numbers nodes from 1, model_to_mesh from 0
            surface_nodes = [model.mesh.getNodesForPhysicalGroup(tdim - 1, tag)[0].astype(
                np.int64) - 1 for tag in tags]
    error = comm.bcast(error, root=rank)
    if error:
        raise ValueError(error)
    if comm.size == 1:
        return gmshio.model_to_mesh(model, comm, rank, gdim=gdim)

    def create_mesh(comm_, cells, x, domain, **kwargs):
        from dolfinx import cpp as _cpp
        from dolfinx.mesh import create_mesh as dolfinx_create_mesh
        from dolfinx_mortar.io.contact_partitioner import (cells_near_contact,
                                                           contact_balanced_partitioner)
        cell_type = _cpp.mesh.to_type(domain.ufl_cell().cellname())
        vertices = np.asarray(cells)[:, :_cpp.mesh.cell_num_vertices(cell_type)]
        facet_type = _cpp.mesh.cell_entity_type(cell_type, _cpp.mesh.cell_dim(cell_type) - 1, 0)
        contact = cells_near_contact(vertices, x, surface_nodes or [],
                                     _cpp.mesh.cell_num_vertices(facet_type))
        centroids = x[vertices].mean(axis=1) if len(vertices) else np.empty((0, x.shape[1]))
        partitioner = contact_balanced_partitioner(comm, contact, centroids)
        return dolfinx_create_mesh(comm_, cells, x, domain, partitioner=partitioner, **kwargs)

    with _gmshio_create_mesh(create_mesh):
        return gmshio.model_to_mesh(model, comm, rank, gdim=gdim)


def read_gmsh(path: Union[str, Path], comm: MPI.Comm, gdim: int = 3,
              balance_facets: Optional[Sequence[str]] = None):
    """Mesh, cell tags, facet tags and ``{dim: {name: tag}}`` of a .msh file.

    ``balance_facets`` names physical facet groups (the contact surfaces)
    whose adjacent cells every rank should get an equal share of
    (:func:`model_to_mesh`).

    Raises
    ------
    FileNotFoundError
        If the file does not exist (checked on every rank).
    """
    import gmsh
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
        tags = None
        if balance_facets is not None:
            facet_groups = names.get(max(names, default=1) - 1, {})
            unknown = sorted(set(balance_facets) - set(facet_groups))
            if unknown:
                raise ValueError(f"balance_facets {unknown} are no named facet groups of "
                                 f"{path}; present: {sorted(facet_groups)}")
            tags = [facet_groups[name] for name in balance_facets]
        domain, cell_tags, facet_tags = model_to_mesh(gmsh.model, comm, 0, gdim=gdim,
                                                      balance_facets=tags)
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
