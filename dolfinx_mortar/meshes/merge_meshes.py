"""Two DOLFINx meshes as one mesh with two disconnected bodies (DOLFINx 0.9 to 0.11).

:class:`~dolfinx_mortar.small_strain.elastic.ContactProblem` takes an elastic master as a
second body of the *same* mesh. Bodies meshed separately (two gmsh models, two
``create_rectangle`` calls, two files) are merged here into one mesh: the nodes
of body b are numbered after those of body a, the cells of both are handed to
``dolfinx.mesh.create_mesh``, and the facet tags travel by their nodes, as
``dolfinx.io.gmshio.model_to_mesh`` does with its tags. The inputs may be
distributed over the ranks in any way; the merged mesh is partitioned anew.

Tag values
----------
The facet tags of a keep their values. A value v of b becomes ``v + tag_offset``
(``tag_offset=0`` by default), except the values listed in ``shared_tags``,
which stay v: a tag meant to mark facets of both bodies (e.g. one symmetry
plane through both). If a value (after the offset) marks facets in both meshes
and is not shared, the merge raises a ValueError: the tags would not tell the
bodies apart.
"""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np
import numpy.typing as npt
from dolfinx import cpp
from mpi4py import MPI

from dolfinx_mortar import dolfinx_compat

#: cell tag values of the two bodies in the merged mesh
BODY_A, BODY_B = 1, 2


def _owned_node_data(domain):
    """Owned node coordinates and the owned cells and their global node numbers."""
    geometry = domain.geometry
    gdim = geometry.dim
    node_map = geometry.index_map()
    num_cells = domain.topology.index_map(domain.topology.dim).size_local
    # nodes per cell from the element: a rank may hold no cell of a small mesh
    dofmap = dolfinx_compat.geometry_dofmap(domain).reshape(
        -1, dolfinx_compat.coordinate_element(domain).create_dof_layout().num_dofs)
    x = geometry.x[:node_map.size_local, :gdim]
    local_to_global = np.asarray(node_map.local_to_global(
        np.arange(node_map.size_local + node_map.num_ghosts, dtype=np.int32)), dtype=np.int64)
    return x, local_to_global, dofmap[:num_cells]


def _owned_tagged_facets(domain, facet_tags):
    """Local node numbers and values of the tagged facets owned by this rank
    (so that each facet is sent once). The nodes are all nodes of the facet in
    the coordinate element's closure order (vertices first), as
    ``distribute_entity_data`` reads them: ``entities_to_geometry`` gives only
    the vertices, which is wrong for quadratic geometry."""
    topology = domain.topology
    tdim = topology.dim
    fdim = tdim - 1
    topology.create_entities(fdim)
    topology.create_connectivity(fdim, tdim)
    topology.create_connectivity(tdim, fdim)
    owned = facet_tags.indices < topology.index_map(fdim).size_local
    facets = np.asarray(facet_tags.indices[owned], dtype=np.int32)
    layout = dolfinx_compat.coordinate_element(domain).create_dof_layout()
    num_facets = cpp.mesh.cell_num_entities(topology.cell_type, fdim)
    closure = np.array([layout.entity_closure_dofs(fdim, i) for i in range(num_facets)],
                       dtype=np.int32)
    geometry = dolfinx_compat.geometry_dofmap(domain)
    f_to_c, c_to_f = topology.connectivity(fdim, tdim), topology.connectivity(tdim, fdim)
    nodes = np.empty((len(facets), len(layout.entity_closure_dofs(fdim, 0))), dtype=np.int32)
    for row, f in enumerate(facets):
        c = f_to_c.links(f)[0]
        local = int(np.flatnonzero(c_to_f.links(c) == f)[0])
        nodes[row] = geometry[c][closure[local]]
    return nodes, np.asarray(facet_tags.values[owned], dtype=np.int32)


def _adjacency(domain, dim: int, entities: npt.NDArray) -> object:
    """Rows of entity vertices as the adjacency list ``meshtags_from_entities`` takes.

    The row width comes from the entity type, not from ``entities``: a rank that
    holds none of the tagged entities gets an empty array without a second axis."""
    width = cpp.mesh.cell_num_vertices(cpp.mesh.cell_entity_type(domain.topology.cell_type, dim, 0))
    entities = np.asarray(entities, dtype=np.int32).reshape(-1, width)
    offsets = np.arange(len(entities) + 1, dtype=np.int32) * entities.shape[1]
    return dolfinx_compat.adjacency_list(entities.ravel(), offsets)


def _global_values(comm: MPI.Comm, values: npt.ArrayLike) -> set:
    return {int(v) for part in comm.allgather(np.unique(values)) for v in part}


def merge_meshes(mesh_a, facet_tags_a, mesh_b, facet_tags_b, comm: Optional[MPI.Comm] = None,
                 *, tag_offset: int = 0, shared_tags: Sequence[int] = ()):
    """One mesh holding the bodies of ``mesh_a`` and ``mesh_b``, disconnected:
    :func:`merge_bodies` of the two, b's tag values shifted by ``tag_offset``.

    Returns
    -------
    mesh, facet_tags, cell_tags
        The merged mesh; its facet tags (a's values, b's values shifted except
        ``shared_tags``); cell tags :data:`BODY_A` = 1 on a's cells and
        :data:`BODY_B` = 2 on b's cells.
    """
    return merge_bodies([mesh_a, mesh_b], [facet_tags_a, facet_tags_b], comm,
                        tag_offsets=[0, tag_offset], shared_tags=shared_tags)


def merge_bodies(meshes: Sequence, facet_tags: Sequence, comm: Optional[MPI.Comm] = None,
                 *, tag_offsets: Optional[Sequence[int]] = None,
                 shared_tags: Sequence[int] = ()):
    """One mesh holding the bodies of all ``meshes``, disconnected, in one call.

    Parameters
    ----------
    meshes
        DOLFINx meshes with the same cell type, geometric dimension and
        geometry degree, distributed over the same ranks (any distribution).
    facet_tags
        Their facet meshtags (int32), one per mesh.
    comm
        Communicator of the merged mesh; default the first mesh's. Must hold the
        same ranks in the same order as the meshes' communicators.
    tag_offsets
        Added to every facet tag value of each mesh except ``shared_tags``
        (default: none).
    shared_tags
        Values that may mark facets of several bodies; kept as they are.

    Returns
    -------
    mesh, facet_tags, cell_tags
        The merged mesh; its facet tags; cell tags k + 1 on the cells of ``meshes[k]``.

    Raises
    ------
    ValueError
        If the meshes differ in cell type, geometric dimension or geometry
        degree, the communicators differ, a tag object is not a facet tag of
        its mesh, or a tag value (after the offsets) marks facets of two
        bodies without being in ``shared_tags``.
    """
    import ufl
    from dolfinx.io import distribute_entity_data
    from dolfinx.mesh import meshtags_from_entities

    meshes, facet_tags = list(meshes), list(facet_tags)
    if len(meshes) < 1 or len(meshes) != len(facet_tags):
        raise ValueError(f"need one facet tag object per mesh, got {len(meshes)} meshes and "
                         f"{len(facet_tags)} tag objects")
    offsets_in = [0] * len(meshes) if tag_offsets is None else [int(t) for t in tag_offsets]
    if len(offsets_in) != len(meshes):
        raise ValueError(f"need one tag offset per mesh, got {len(offsets_in)}")
    first = meshes[0]
    comm = first.comm if comm is None else comm
    names = ["mesh_a", "mesh_b"] if len(meshes) == 2 else [f"meshes[{k}]" for k in range(len(meshes))]
    tag_names = (["facet_tags_a", "facet_tags_b"] if len(meshes) == 2
                 else [f"facet_tags[{k}]" for k in range(len(meshes))])
    for name, domain in zip(names, meshes):
        if MPI.Comm.Compare(comm, domain.comm) not in (MPI.IDENT, MPI.CONGRUENT):
            raise ValueError(f"{name} lives on another communicator than the merged mesh")
    cell_a, degree, gdim = (first.topology.cell_type,
                            dolfinx_compat.coordinate_element(first).degree, first.geometry.dim)
    for domain in meshes[1:]:
        if domain.topology.cell_type != cell_a:
            raise ValueError(f"cannot merge a {cell_a.name} mesh with a "
                             f"{domain.topology.cell_type.name} mesh: both meshes need the "
                             "same cell type")
        if dolfinx_compat.coordinate_element(domain).degree != degree:
            raise ValueError(f"cannot merge geometry degree {degree} with geometry degree "
                             f"{dolfinx_compat.coordinate_element(domain).degree}: both meshes "
                             "need the same coordinate element")
        if domain.geometry.dim != gdim:
            raise ValueError(f"cannot merge a {gdim}D mesh with a {domain.geometry.dim}D mesh")
    tdim = first.topology.dim
    for name, tags, domain in zip(tag_names, facet_tags, meshes):
        if tags.dim != tdim - 1 or not dolfinx_compat.tags_belong_to(tags, domain):
            raise ValueError(f"{name} must be facet tags (dim {tdim - 1}) of its own mesh, "
                             f"got dim {tags.dim}")

    # each body's tag values, and the clash check on the values present on any rank
    shared = {int(t) for t in shared_tags}
    values = []
    for tags, offset in zip(facet_tags, offsets_in):
        v = np.asarray(tags.values, dtype=np.int64)
        v = np.where(np.isin(v, list(shared)), v, v + offset)
        if v.size and (v.max() > np.iinfo(np.int32).max or v.min() < np.iinfo(np.int32).min):
            raise ValueError(f"tag_offset {offset} pushes tag values beyond int32")
        values.append(v)
    present = [_global_values(comm, v) - shared for v in values]
    for k in range(1, len(values)):
        for other in range(k):
            clash = sorted(present[other] & present[k])
            if clash:
                # name the later body's values as the user wrote them, not only as shifted
                offset = offsets_in[k]
                written = (f" ({names[k]}'s {[v - offset for v in clash]} shifted by "
                           f"tag_offset {offset})" if offset else "")
                bodies = "" if len(values) == 2 else f" ({names[other]} and {names[k]})"
                raise ValueError(f"facet tag values {clash} mark facets of both meshes"
                                 f"{written}{bodies}; pass tag_offset= to shift the values, "
                                 "or list the values in shared_tags= if they are meant to "
                                 "mark both bodies")

    # Merged node numbering: rank r holds the rows [offset_r, offset_r + Σ_k n_k,r)
    # (create_mesh numbers the rows of x contiguously by rank): each body's owned nodes in turn.
    data = [_owned_node_data(domain) for domain in meshes]
    counts = np.array(comm.allgather([len(x) for x, _, _ in data]),
                      dtype=np.int64).reshape(-1, len(meshes))
    offsets = np.concatenate([[0], np.cumsum(counts.sum(axis=1))[:-1]])
    new_numbers = []
    for k, (domain, (_, l2g, _)) in enumerate(zip(meshes, data)):
        starts = np.array(comm.allgather(domain.geometry.index_map().local_range[0]),
                          dtype=np.int64)
        shift = counts[:, :k].sum(axis=1)
        # owner of each node from the owners' ranges, then its row in the merged x
        owner = np.searchsorted(starts, l2g, side="right") - 1
        new_numbers.append(l2g - starts[owner] + offsets[owner] + shift[owner])
    cells = np.vstack([new[cells_k] for new, (_, _, cells_k) in zip(new_numbers, data)]
                      ).astype(np.int64)
    x = np.vstack([x_k for x_k, _, _ in data])
    # a new UFL domain: create_mesh ties the one it gets to the new mesh
    ufl_domain = ufl.Mesh(first.ufl_domain().ufl_coordinate_element())
    domain = dolfinx_compat.create_mesh(comm, cells, x, ufl_domain)

    # cell tags: every owned input cell with its body
    body = np.concatenate([np.full(len(cells_k), k + 1, dtype=np.int32)
                           for k, (_, _, cells_k) in enumerate(data)])
    entities, cell_values = distribute_entity_data(domain, tdim, cells, body)
    domain.topology.create_connectivity(tdim, 0)
    cell_tags = meshtags_from_entities(domain, tdim, _adjacency(domain, tdim, entities),
                                       cell_values.astype(np.int32))
    cell_tags.name = "Cell tags"

    # facet tags: by their nodes in the merged numbering
    nodes, tag_values = [], []
    for mesh_k, tags, v, new in zip(meshes, facet_tags, values, new_numbers):
        facets_k, _ = _owned_tagged_facets(mesh_k, tags)
        owned = tags.indices < mesh_k.topology.index_map(tdim - 1).size_local
        nodes.append(new[facets_k])
        tag_values.append(v[owned])
    facet_nodes = np.vstack(nodes).astype(np.int64)
    entities, facet_values = distribute_entity_data(domain, tdim - 1, facet_nodes,
                                                    np.concatenate(tag_values).astype(np.int32))
    domain.topology.create_connectivity(tdim - 1, tdim)
    merged_tags = meshtags_from_entities(domain, tdim - 1,
                                         _adjacency(domain, tdim - 1, entities),
                                         facet_values.astype(np.int32))
    merged_tags.name = "Facet tags"
    return domain, merged_tags, cell_tags
