"""Reading gmsh models and files into DOLFINx, with the names of their
physical groups, optionally with the contact surfaces spread over the ranks.

The model is opened on one rank and handed to DOLFINx's ``model_to_mesh``
(through :mod:`dolfinx_mortar.dolfinx_compat`, which hides where that lives
and what it returns in each DOLFINx release). Unlike DOLFINx's, whose
``gdim`` is 3 unless given, the geometric dimension is by default the
model's own (:func:`model_dimension`): a 2D .msh read with gdim 3 made a
mesh that failed deep inside the contact term.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Optional, Sequence, Union

import numpy as np
from mpi4py import MPI

from dolfinx_mortar import dolfinx_compat
from dolfinx_mortar.io.output import on_rank0
from dolfinx_mortar.tolerance import length_scale, zero_length


def model_dimension(model, comm: MPI.Comm, rank: int = 0) -> int:
    """The geometric dimension of a gmsh model's mesh (collective).

    The topological dimension ``tdim`` is that of the highest physical group
    (the cells DOLFINx makes); the geometric dimension is ``tdim`` when every
    node's coordinates beyond the first ``tdim`` are zero on the scale of the
    mesh (a 2D mesh in the plane z = 0), else 3 (a surface in space).

    Parameters
    ----------
    model
        The gmsh model with its mesh, built on ``rank``.
    comm, rank
        The communicator and the rank that holds the model.
    """
    gdim = None
    if comm.rank == rank:
        groups = model.getPhysicalGroups()
        tdim = max((dim for dim, _ in groups), default=model.getDimension())
        x = model.mesh.getNodes()[1].reshape(-1, 3)
        beyond = np.abs(x[:, tdim:])
        flat = not beyond.size or beyond.max() <= zero_length(length_scale(x))
        gdim = int(tdim) if flat and tdim > 0 else 3
    return comm.bcast(gdim, root=rank)


def model_to_mesh(model, comm: MPI.Comm, rank: int = 0, gdim: Optional[int] = None,
                  balance_facets: Optional[Sequence[int]] = None):
    """DOLFINx's ``model_to_mesh`` as ``(mesh, cell_tags, facet_tags)`` in
    every supported release, optionally with the cells next to some facets
    spread evenly over the ranks.

    Parameters
    ----------
    model
        The gmsh model, built on ``rank``.
    comm, rank
        As for DOLFINx's ``model_to_mesh``.
    gdim
        The geometric dimension; None (default): the model's own
        (:func:`model_dimension`: 2 for a mesh in the plane z = 0).
    balance_facets
        Physical tags of the facet groups (the contact surfaces) whose
        adjacent cells every rank should get an equal share of
        (:func:`~dolfinx_mortar.meshes.contact_partitioner.contact_balanced_partitioner`).
        ``None`` uses DOLFINx's graph partitioner alone.

    Returns
    -------
    The mesh, its cell tags and its facet tags.

    Raises
    ------
    ValueError
        If a tag in ``balance_facets`` is no physical group of facets.
    """
    if gdim is None:
        gdim = model_dimension(model, comm, rank)
    if balance_facets is None:
        return dolfinx_compat.model_to_mesh(model, comm, rank, gdim=gdim)
    tags = [int(t) for t in balance_facets]
    surface_nodes = None
    x = None
    error = None
    if comm.rank == rank:
        tdim = max(dim for dim, _ in model.getPhysicalGroups())
        present = {tag for dim, tag in model.getPhysicalGroups() if dim == tdim - 1}
        missing = sorted(set(tags) - present)
        if missing:
            error = (f"balance_facets {missing} are no physical groups of facets "
                     f"(dimension {tdim - 1}) of the gmsh model; present: {sorted(present)}")
        else:
            # gmsh numbers nodes from 1, model_to_mesh's rows of x from 0
            surface_nodes = [model.mesh.getNodesForPhysicalGroup(tdim - 1, tag)[0].astype(
                np.int64) - 1 for tag in tags]
            node_tags, coordinates, _ = model.mesh.getNodes()
            x = np.empty((len(node_tags), gdim))
            x[node_tags.astype(np.int64) - 1] = coordinates.reshape(-1, 3)[:, :gdim]
    error = comm.bcast(error, root=rank)
    if error:
        raise ValueError(error)
    if comm.size == 1:
        return dolfinx_compat.model_to_mesh(model, comm, rank, gdim=gdim)
    partitioner = _contact_cell_partitioner(comm, x, surface_nodes or [], gdim)
    return dolfinx_compat.model_to_mesh(model, comm, rank, gdim=gdim, partitioner=partitioner)


def _contact_cell_partitioner(comm: MPI.Comm, x: Optional[np.ndarray],
                              surface_nodes: list, gdim: int) -> Callable:
    """A cell partitioner that finds the contact cells among the cells it is
    given (their vertices, numbered as the rows of the model's nodes ``x``)
    and balances them (:func:`contact_balanced_partitioner`)."""
    from dolfinx import cpp as _cpp

    from dolfinx_mortar.meshes.contact_partitioner import (cells_near_contact,
                                                       contact_balanced_partitioner)

    def partition(comm_wrapper, nparts: int, cell_types, cells):
        cell_type = cell_types[0]
        num_vertices = _cpp.mesh.cell_num_vertices(cell_type)
        vertices = np.asarray(cells[0], dtype=np.int64).reshape(-1, num_vertices)
        if len(vertices):
            facet_type = _cpp.mesh.cell_entity_type(cell_type, _cpp.mesh.cell_dim(cell_type) - 1, 0)
            contact = cells_near_contact(vertices, x, surface_nodes,
                                         _cpp.mesh.cell_num_vertices(facet_type))
            centroids = x[vertices].mean(axis=1)
        else:
            contact, centroids = np.zeros(0, dtype=bool), np.empty((0, gdim))
        balanced = contact_balanced_partitioner(comm, contact, centroids)
        return balanced(comm_wrapper, nparts, cell_types, cells)

    return partition


def read_gmsh(path: Union[str, Path], comm: MPI.Comm, gdim: Optional[int] = None,
              balance_facets: Optional[Sequence[str]] = None):
    """Mesh, cell tags, facet tags and ``{dim: {name: tag}}`` of a .msh file.

    ``gdim`` is by default the mesh's own (2 for a mesh in the plane z = 0,
    :func:`model_dimension`). ``balance_facets`` names physical facet groups (the contact surfaces)
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
        names: dict = {}

        def read() -> None:
            gmsh.open(str(path))
            for dim, tag in gmsh.model.getPhysicalGroups():
                names.setdefault(dim, {})[gmsh.model.getPhysicalName(dim, tag)] = tag
        # a file gmsh cannot read raises on every rank, not on rank 0 alone
        on_rank0(comm, read, f"gmsh file {path}")
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
