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
    from dolfinx import cpp
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


def _adjacency(entities: npt.NDArray) -> object:
    """Rows of entity vertices as the adjacency list ``meshtags_from_entities`` takes."""
    entities = np.asarray(entities, dtype=np.int32).reshape(len(entities), -1)
    offsets = np.arange(len(entities) + 1, dtype=np.int32) * entities.shape[1]
    return dolfinx_compat.adjacency_list(entities.ravel(), offsets)


def _global_values(comm: MPI.Comm, values: npt.ArrayLike) -> set:
    return {int(v) for part in comm.allgather(np.unique(values)) for v in part}


def merge_meshes(mesh_a, facet_tags_a, mesh_b, facet_tags_b, comm: Optional[MPI.Comm] = None,
                 *, tag_offset: int = 0, shared_tags: Sequence[int] = ()):
    """One mesh holding the bodies of ``mesh_a`` and ``mesh_b``, disconnected.

    Parameters
    ----------
    mesh_a, mesh_b
        DOLFINx meshes with the same cell type, geometric dimension and
        geometry degree, distributed over the same ranks (any distribution).
    facet_tags_a, facet_tags_b
        Their facet meshtags (int32).
    comm
        Communicator of the merged mesh; default ``mesh_a.comm``. Must hold the
        same ranks in the same order as the meshes' communicators.
    tag_offset
        Added to every facet tag value of b except ``shared_tags``.
    shared_tags
        Values that may mark facets of both bodies; kept as they are in b.

    Returns
    -------
    mesh, facet_tags, cell_tags
        The merged mesh; its facet tags (a's values, b's values shifted as
        described above); cell tags :data:`BODY_A` = 1 on a's cells and
        :data:`BODY_B` = 2 on b's cells.

    Raises
    ------
    ValueError
        If the meshes differ in cell type, geometric dimension or geometry
        degree, the communicators differ, a tag object is not a facet tag of
        its mesh, or a tag value (after the offset) marks facets of both
        bodies without being in ``shared_tags``.
    """
    import ufl
    from dolfinx.io import distribute_entity_data
    from dolfinx.mesh import meshtags_from_entities

    comm = mesh_a.comm if comm is None else comm
    for name, domain in (("mesh_a", mesh_a), ("mesh_b", mesh_b)):
        if MPI.Comm.Compare(comm, domain.comm) not in (MPI.IDENT, MPI.CONGRUENT):
            raise ValueError(f"{name} lives on another communicator than the merged mesh")
    cell_a, cell_b = mesh_a.topology.cell_type, mesh_b.topology.cell_type
    if cell_a != cell_b:
        raise ValueError(f"cannot merge a {cell_a.name} mesh with a {cell_b.name} mesh: "
                         "both meshes need the same cell type")
    deg_a, deg_b = (dolfinx_compat.coordinate_element(m).degree for m in (mesh_a, mesh_b))
    if deg_a != deg_b:
        raise ValueError(f"cannot merge geometry degree {deg_a} with geometry degree {deg_b}: "
                         "both meshes need the same coordinate element")
    gdim = mesh_a.geometry.dim
    if mesh_b.geometry.dim != gdim:
        raise ValueError(f"cannot merge a {gdim}D mesh with a {mesh_b.geometry.dim}D mesh")
    tdim = mesh_a.topology.dim
    for name, tags, domain in (("facet_tags_a", facet_tags_a, mesh_a),
                               ("facet_tags_b", facet_tags_b, mesh_b)):
        if tags.dim != tdim - 1 or not dolfinx_compat.tags_belong_to(tags, domain):
            raise ValueError(f"{name} must be facet tags (dim {tdim - 1}) of its own mesh, "
                             f"got dim {tags.dim}")

    # b's tag values, and the clash check on the values present on any rank
    shared = {int(t) for t in shared_tags}
    values_b = np.asarray(facet_tags_b.values, dtype=np.int64)
    values_b = np.where(np.isin(values_b, list(shared)), values_b, values_b + int(tag_offset))
    if values_b.size and (values_b.max() > np.iinfo(np.int32).max
                          or values_b.min() < np.iinfo(np.int32).min):
        raise ValueError(f"tag_offset {tag_offset} pushes tag values beyond int32")
    clash = sorted((_global_values(comm, facet_tags_a.values)
                    & _global_values(comm, values_b)) - shared)
    if clash:
        # name b's values as the user wrote them, not only as shifted
        written = (f" (mesh_b's {[v - int(tag_offset) for v in clash]} shifted by tag_offset "
                   f"{tag_offset})" if tag_offset else "")
        raise ValueError(f"facet tag values {clash} mark facets of both meshes{written}; pass "
                         "tag_offset= to shift mesh_b's values, or list the values in "
                         "shared_tags= if they are meant to mark both bodies")

    # Merged node numbering: rank r holds the rows [offset_r, offset_r + n_a_r + n_b_r)
    # (create_mesh numbers the rows of x contiguously by rank): a's owned nodes, then b's.
    x_a, l2g_a, cells_a = _owned_node_data(mesh_a)
    x_b, l2g_b, cells_b = _owned_node_data(mesh_b)
    counts = np.array(comm.allgather((len(x_a), len(x_b))), dtype=np.int64).reshape(-1, 2)
    offsets = np.concatenate([[0], np.cumsum(counts.sum(axis=1))[:-1]])
    starts_a = np.array(comm.allgather(mesh_a.geometry.index_map().local_range[0]),
                        dtype=np.int64)
    starts_b = np.array(comm.allgather(mesh_b.geometry.index_map().local_range[0]),
                        dtype=np.int64)

    def renumber(global_nodes, starts, shift):
        # owner of each node from the owners' ranges, then its row in the merged x
        owner = np.searchsorted(starts, global_nodes, side="right") - 1
        return global_nodes - starts[owner] + offsets[owner] + shift[owner]

    new_a = renumber(l2g_a, starts_a, np.zeros(len(counts), dtype=np.int64))
    new_b = renumber(l2g_b, starts_b, counts[:, 0])
    cells = np.vstack([new_a[cells_a], new_b[cells_b]]).astype(np.int64)
    x = np.vstack([x_a, x_b])
    # a new UFL domain: create_mesh ties the one it gets to the new mesh
    ufl_domain = ufl.Mesh(mesh_a.ufl_domain().ufl_coordinate_element())
    domain = dolfinx_compat.create_mesh(comm, cells, x, ufl_domain)

    # cell tags: every owned input cell with its body
    body = np.concatenate([np.full(len(cells_a), BODY_A, dtype=np.int32),
                           np.full(len(cells_b), BODY_B, dtype=np.int32)])
    entities, values = distribute_entity_data(domain, tdim, cells, body)
    domain.topology.create_connectivity(tdim, 0)
    cell_tags = meshtags_from_entities(domain, tdim, _adjacency(entities),
                                       values.astype(np.int32))
    cell_tags.name = "Cell tags"

    # facet tags: by their nodes in the merged numbering
    facets_a, tag_values_a = _owned_tagged_facets(mesh_a, facet_tags_a)
    facets_b, _ = _owned_tagged_facets(mesh_b, facet_tags_b)
    owned_b = facet_tags_b.indices < mesh_b.topology.index_map(tdim - 1).size_local
    facet_nodes = np.vstack([new_a[facets_a], new_b[facets_b]]).astype(np.int64)
    facet_values = np.concatenate([tag_values_a, values_b[owned_b]]).astype(np.int32)
    entities, values = distribute_entity_data(domain, tdim - 1, facet_nodes, facet_values)
    domain.topology.create_connectivity(tdim - 1, tdim)
    facet_tags = meshtags_from_entities(domain, tdim - 1, _adjacency(entities),
                                        values.astype(np.int32))
    facet_tags.name = "Facet tags"
    return domain, facet_tags, cell_tags
