"""Checks of the user's input that name the problem (DOLFINx 0.9 to 0.11).

Bad input must fail early with a message that points at the offending entity,
not later inside FFCx, the compiler or MUMPS.
"""
from __future__ import annotations

import ctypes
from typing import Callable, Iterable, Optional

import dolfinx
import numpy as np
from petsc4py import PETSc

from dolfinx_mortar import dolfinx_compat
from dolfinx_mortar.tolerance import length_scale, zero_length


def check_boundary_data(fixed: dict, tractions: dict, gdim: int) -> None:
    """Prescribed components and tractions: valid components, finite values.

    Raises
    ------
    ValueError
        Naming the tag and component of a bad entry (a NaN traction used to
        end in an FFCx IndexError, a NaN prescribed value in six failed
        attempts with an empty residual list).
    """
    for tag, components in fixed.items():
        if not isinstance(components, dict):
            raise TypeError(f"fixed[{tag}] must be a dict {{component: value}}, "
                            f"got {components!r}")
        for k, value in components.items():
            if not isinstance(k, (int, np.integer)) or not 0 <= k < gdim:
                raise ValueError(f"fixed[{tag}]: component {k!r} does not exist in {gdim}D")
            if not np.isfinite(float(value)):
                raise ValueError(f"fixed[{tag}][{k}] = {value}: a prescribed displacement "
                                 "must be finite")
    for tag, t in tractions.items():
        t = np.asarray(t, dtype=np.float64)
        if t.shape != (gdim,):
            raise ValueError(f"traction on tag {tag} must have {gdim} components, "
                             f"got shape {t.shape}")
        if not np.all(np.isfinite(t)):
            raise ValueError(f"traction on tag {tag} is {t.tolist()}: it must be finite")


def check_cells(mesh: dolfinx.mesh.Mesh) -> None:
    """Refuse cells of zero size and tangled (folded) cells.

    Across every facet that two local cells share, their centroids must lie
    on opposite sides of the facet, each further than the zero length
    (:mod:`dolfinx_mortar.tolerance`) from it. Exact for simplices; for
    quadrilaterals and hexahedra the facet's plane is that of its first
    three vertices. Facets on a partition boundary with no ghost cell are not
    seen by either rank.

    Raises
    ------
    ValueError
        Naming the two cells and the facet's vertices.
    """
    message = _bad_cells_message(mesh) if mesh.geometry.dim == mesh.topology.dim else None
    # every rank raises, so that none waits in a collective for the other
    messages = [m for m in mesh.comm.allgather(message) if m]
    if messages:
        raise ValueError(messages[0])


def _bad_cells_message(mesh: dolfinx.mesh.Mesh) -> Optional[str]:
    tdim = mesh.topology.dim
    fdim = tdim - 1
    gdim = mesh.geometry.dim
    mesh.topology.create_connectivity(fdim, tdim)
    f2c = mesh.topology.connectivity(fdim, tdim)
    interior = np.flatnonzero(np.diff(f2c.offsets) == 2).astype(np.int32)
    if len(interior) == 0:
        return None
    cells = f2c.array[f2c.offsets[interior][:, None] + np.arange(2)]      # (facets, 2)
    x = mesh.geometry.x[:, :gdim]
    cell_nodes = dolfinx_compat.geometry_dofmap(mesh)
    # the facets' vertices' geometry nodes (the first nodes of a facet's closure)
    facet_nodes = dolfinx.mesh.entities_to_geometry(mesh, fdim, interior, False)
    corners = x[facet_nodes[:, :tdim]]                                       # (f, tdim, gdim)
    if gdim == 2:
        t = corners[:, 1] - corners[:, 0]
        normal = np.column_stack([t[:, 1], -t[:, 0]])
    else:
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(normal, axis=1)
    num_vertices = dolfinx.cpp.mesh.cell_num_entities(mesh.topology.cell_type, 0)
    centroids = x[cell_nodes[cells][..., :num_vertices]].mean(axis=2)       # (f, 2, gdim)
    zero = zero_length(length_scale(x))
    with np.errstate(invalid="ignore", divide="ignore"):
        side = np.einsum("fcg,fg->fc", centroids - corners[:, None, 0], normal) / length[:, None]
    degenerate = ~(np.abs(side) > zero).all(axis=1)
    folded = ~degenerate & (np.sign(side[:, 0]) == np.sign(side[:, 1]))
    for bad, what in ((degenerate, "a cell of zero size (or a degenerate facet)"),
                      (folded, "tangled cells (both on the same side of their shared facet)")):
        if np.any(bad):
            f = int(np.flatnonzero(bad)[0])
            return (f"the mesh has {what}: local cells {cells[f].tolist()} across the facet "
                    f"with vertices {corners[f].tolist()}; {int(np.sum(bad))} such facet(s) "
                    f"on rank {mesh.comm.rank}")
    return None


def _petsc_library() -> Optional[ctypes.CDLL]:
    major, minor, _ = PETSc.Sys.getVersion()
    for name in (f"libpetsc_real.so.{major}.{minor}", f"libpetsc.so.{major}.{minor}"):
        try:
            return ctypes.CDLL(name)
        except OSError:
            continue
    return None


def _option_used_query() -> Optional[Callable[[str], bool]]:
    """``name -> whether an object read the option`` (name without the '-')."""
    db = PETSc.Options()
    if hasattr(db, "used"):            # petsc4py 3.25 (not 3.22)
        return lambda name: bool(db.used(name))
    # older petsc4py: PetscOptionsUsed of the library petsc4py itself loaded
    lib = _petsc_library()
    if lib is None:
        return None
    query = lib.PetscOptionsUsed
    query.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.POINTER(ctypes.c_int)]

    def used(name: str) -> bool:
        flag = ctypes.c_int(0)
        return query(None, name.encode(), ctypes.byref(flag)) != 0 or bool(flag.value)

    return used


def unused_petsc_options(prefix: str, ignore: Iterable[str] = ()) -> list[str]:
    """Options under ``prefix`` in PETSc's database that no object has read.

    ``ignore`` names options (without the prefix) that may stay unused, e.g.
    defaults for a solver the user replaced. Returns [] when PETSc cannot be
    asked (a petsc4py without ``Options.used`` whose library is not found).
    """
    used = _option_used_query()
    if used is None:
        return []
    skip = {prefix + name for name in ignore}
    return sorted("-" + name for name in PETSc.Options().getAll()
                  if name.startswith(prefix) and name not in skip and not used(name))


def check_tags(mesh, facet_tags, tags: Iterable) -> None:
    """Integer facet tags that mark facets somewhere (on any rank).

    Raises
    ------
    TypeError
        For non-integer tag values, in the meshtags or among ``tags``.
    ValueError
        For a tag that marks no facet, with the tags present.
    """
    if not np.issubdtype(np.asarray(facet_tags.values).dtype, np.integer):
        raise TypeError(f"facet tag values must be integers, got "
                        f"{np.asarray(facet_tags.values).dtype}")
    if facet_tags.dim != mesh.topology.dim - 1:
        raise ValueError(f"the meshtags have dimension {facet_tags.dim}; contact needs facet "
                         f"tags (dimension {mesh.topology.dim - 1})")
    present = {int(t) for values in mesh.comm.allgather(np.unique(facet_tags.values))
               for t in values}
    for tag in tags:
        if tag is None:
            continue
        if not isinstance(tag, (int, np.integer)):
            raise TypeError(f"tags must be integers, got {tag!r} ({type(tag).__name__})")
        if tag not in present:
            raise ValueError(f"facet tag {tag} marks no facets (tags present: "
                             f"{sorted(present)})")


def check_contact_tags(mesh, facet_tags, slave_tag: int, master_tag: Optional[int]) -> None:
    """Slave and master tags as :func:`check_tags`, and no facet carrying both."""
    check_tags(mesh, facet_tags, [slave_tag, master_tag])
    if master_tag is not None:
        a, b = facet_tags.find(slave_tag), facet_tags.find(master_tag)
        if mesh.comm.allreduce(len(np.intersect1d(a, b))) > 0:
            raise ValueError(f"slave tag {slave_tag} and master tag {master_tag} "
                             "overlap: a facet cannot be both")


def check_contact_arguments(u, master_tag: Optional[int], obstacle,
                            axisymmetric: bool) -> None:
    """The displacement, the master or obstacle and the mesh's dimension given to
    a contact term."""
    if not isinstance(u, dolfinx.fem.Function):
        raise TypeError(f"u must be a dolfinx.fem.Function (the displacement), got "
                        f"{type(u).__name__}")
    V = u.function_space
    gdim = V.mesh.geometry.dim
    if V.dofmap.index_map_bs != gdim:
        raise ValueError(f"u must be a vector Function with {gdim} components per node")
    if (master_tag is None) == (obstacle is None):
        raise ValueError("give exactly one of master_tag (elastic master) and obstacle "
                         "(rigid analytic obstacle)")
    if obstacle is not None and obstacle.gdim != gdim:
        raise ValueError(f"a {obstacle.gdim}D obstacle in a {gdim}D mesh: the option "
                         "does not fit the mesh's dimension")
    if axisymmetric and gdim != 2:
        raise ValueError(f"axisymmetric contact needs a 2D (r, z) mesh, got a {gdim}D one")
