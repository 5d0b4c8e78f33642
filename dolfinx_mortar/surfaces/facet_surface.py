"""Slave surfaces made of tagged facets of a DOLFINx mesh (DOLFINx 0.9 to 0.11).

One of the few modules that call DOLFINx (docs/DESIGN.md, §Dependencies). The surface's
functions are the (block) dofs of a Lagrange function space, numbered and
distributed as DOLFINx numbers them, so nodal contact quantities line up with
the displacement's dofs without any renumbering.
"""
from __future__ import annotations

from typing import Sequence, Union

import dolfinx
import numpy as np
from dolfinx import fem

from dolfinx_mortar import dolfinx_compat
from dolfinx_mortar.surfaces.lagrange import LagrangeSurface
from dolfinx_mortar.layout import NodeLayout

_FACET_CELL = {"interval": "point", "triangle": "interval",
               "quadrilateral": "interval", "tetrahedron": "triangle",
               "hexahedron": "quadrilateral"}


def facet_surface(space: Union[fem.FunctionSpace, dolfinx.mesh.Mesh],
                  facet_tags: dolfinx.mesh.MeshTags, tag: Union[int, Sequence[int]],
                  quadratic_transform: bool = False,
                  axisymmetric: bool = False) -> LagrangeSurface:
    """The surface of the facets marked ``tag``, owned by this rank.

    Facet nodes are ordered so that the natural normal of every facet points
    out of the body (required by segmentation; harmless for the bases).

    Parameters
    ----------
    space
        A Lagrange function space (scalar or vector: its nodes are the block
        dofs), or a mesh, in which case the space of the mesh's geometry degree
        is used.
    facet_tags
        Facet meshtags.
    tag
        The value marking the slave facets, or several (their facets together).
    quadratic_transform
        Use the transformed quadratic basis on quadratic triangle facets.
    axisymmetric
        The mesh is an (r, z) half-plane: integrate with 2πr ds
        (:class:`~dolfinx_mortar.surfaces.lagrange.LagrangeSurface`).

    Raises
    ------
    ValueError
        If the tags are not facet tags, mark no facet on any rank, or the space
        is not Lagrange of degree 1 or 2.
    """
    if isinstance(space, dolfinx.mesh.Mesh):
        mesh = space
        degree = dolfinx_compat.coordinate_element(mesh).degree
        space = fem.functionspace(mesh, ("Lagrange", degree))
    mesh = space.mesh
    element = space.ufl_element()
    degree = element.degree
    family = element.family_name
    if getattr(element, "discontinuous", False):
        # its dofs belong to the cells, none to the facets: it failed with "P1 line
        # cells need 2 nodes each, got cells of shape (8, 0)"
        raise ValueError(f"contact needs a continuous Lagrange (CG, P1/P2) space, got a "
                         f"discontinuous (DG) {family} space of degree {degree}")
    if family not in ("Lagrange", "Q", "P") or degree not in (1, 2):
        raise ValueError(f"slave surfaces need a Lagrange space of degree 1 or 2, "
                         f"got {family} of degree {degree}")
    tdim = mesh.topology.dim
    fdim = tdim - 1
    if tdim < 2:
        raise ValueError(f"contact surfaces need a 2D or 3D mesh, got a {tdim}D one")
    if facet_tags.dim != fdim:
        raise ValueError(f"the meshtags have dimension {facet_tags.dim}, but the slave "
                         f"surface needs facet tags (dimension {fdim}) of this "
                         f"{tdim}D mesh")
    comm = mesh.comm
    tags = [tag] if np.ndim(tag) == 0 else list(tag)
    facets = np.unique(np.concatenate([facet_tags.find(t) for t in tags]))
    facets = facets[facets < mesh.topology.index_map(fdim).size_local]
    if comm.allreduce(len(facets)) == 0:
        present = sorted({int(v) for values in comm.allgather(np.unique(facet_tags.values))
                          for v in values})
        raise ValueError(f"facet tag {tag} marks no facets of the mesh (tags present: "
                         f"{present})")

    mesh.topology.create_connectivity(fdim, tdim)
    mesh.topology.create_connectivity(tdim, fdim)
    f2c = mesh.topology.connectivity(fdim, tdim)
    c2f = mesh.topology.connectivity(tdim, fdim)
    cell_of_facet = f2c.array[f2c.offsets[facets]]
    # from the cell type: a rank may own no cell at all
    num_facets_per_cell = dolfinx.cpp.mesh.cell_num_entities(mesh.topology.cell_type, fdim)
    cell_facets = c2f.array.reshape(-1, num_facets_per_cell)[cell_of_facet]
    local_facet = np.argmax(cell_facets == facets[:, None], axis=1)

    dof_layout = space.dofmap.dof_layout
    closure = np.array([dof_layout.entity_closure_dofs(fdim, i)
                        for i in range(num_facets_per_cell)], dtype=np.int64)
    cell_dofs = space.dofmap.list.reshape(-1, dof_layout.num_dofs)
    cells = cell_dofs[cell_of_facet[:, None], closure[local_facet]]

    index_map = space.dofmap.index_map
    layout = NodeLayout(comm, index_map.size_local, index_map.ghosts)
    gdim = mesh.geometry.dim
    x = space.tabulate_dof_coordinates()[:, :gdim]
    geometry_dofs = dolfinx_compat.geometry_dofmap(mesh)
    if geometry_dofs.shape[1] == dof_layout.num_dofs and len(cell_dofs):
        # The space's nodes are the geometry's (same Lagrange degree, same local order):
        # take their coordinates as given. Tabulated ones are pushed forward from the
        # reference cell, off by round-off of |x| (1.5e-8 at 1e8), which is no round-off
        # of a small scene far from the origin (docs/DESIGN.md, §Tolerances).
        x = x.copy()
        x[cell_dofs.ravel()] = mesh.geometry.x[geometry_dofs.ravel(), :gdim]
    facet_cell = _FACET_CELL[mesh.topology.cell_type.name]
    surface = LagrangeSurface(facet_cell, degree, x, cells, layout=layout,
                              quadratic_transform=quadratic_transform,
                              axisymmetric=axisymmetric)
    # each facet's volume cell: a self-contact surface never pairs facets whose cells touch
    surface.volume_nodes = cell_dofs[cell_of_facet].astype(np.int64)
    # which of the tags each facet carries (the results of a term over several tags)
    surface.cell_tags = np.zeros(len(facets), dtype=np.int32)
    for t in tags:
        surface.cell_tags[np.isin(facets, facet_tags.find(t))] = t
    if len(cells) == 0:
        return surface
    # Outward: the facet normal must point away from its cell's centroid.
    cell_centres = mesh.geometry.x[geometry_dofs[cell_of_facet], :gdim].mean(axis=1)
    facet_centres = x[cells].mean(axis=1)
    normals = surface.cell_normals().mean(axis=1)
    inward = np.einsum("cg,cg->c", normals, facet_centres - cell_centres) < 0
    return surface.reflected(inward) if np.any(inward) else surface


def nodal_displacement(surface: LagrangeSurface, u: fem.Function) -> np.ndarray:
    """Values of a vector Function at the surface's local nodes, (nodes, gdim).

    ``u`` must live on a space with the surface's node numbering: the space
    the surface was built from, or its vector version on the same mesh.
    """
    space = u.function_space
    index_map = space.dofmap.index_map
    bs = space.dofmap.index_map_bs
    if (index_map.size_local != surface.layout.num_owned
            or index_map.num_ghosts != len(surface.layout.ghosts)):
        raise ValueError("the displacement's function space numbers its nodes differently "
                         "from the surface; build the surface from this space")
    if bs != surface.gdim:
        raise ValueError(f"the displacement has {bs} components per node, the surface "
                         f"lives in {surface.gdim}D")
    u.x.scatter_forward()
    values = u.x.array.reshape(-1, bs)
    if not np.all(np.isfinite(values)):
        raise ValueError("the displacement contains NaN or infinite values")
    return values.copy()
