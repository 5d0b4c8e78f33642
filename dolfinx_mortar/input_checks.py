"""Checks of the user's input that name the problem (DOLFINx 0.9 to 0.11).

Bad input must fail early with a message that points at the offending entity,
not later inside FFCx, the compiler or MUMPS.
"""
from __future__ import annotations

import builtins
import ctypes
import importlib
from contextlib import contextmanager
from typing import Callable, Iterable, Iterator, Optional, Sequence

import dolfinx
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import dolfinx_compat
from dolfinx_mortar.collective_warnings import deciding
from dolfinx_mortar.linalg.petsc_library import petsc_library
from dolfinx_mortar.tolerance import length_scale, zero_length


@contextmanager
def collective_checks(comm: MPI.Comm) -> Iterator[None]:
    """Make the checks in the block one decision of all ranks of ``comm``.

    The block must not communicate. If it raises on any rank, every rank
    raises: the rank that failed first (lowest rank) raises its own
    exception, the others an exception of the same type with the same
    message. A check that failed on one rank only (a NaN penalty on rank 1)
    used to raise there while the other ranks went on into the next
    collective and waited for ever. Collective: every rank must enter the
    block. A library warning issued in the block belongs to ``comm``
    (:func:`~dolfinx_mortar.collective_warnings.warn`).
    """
    failure: Optional[BaseException] = None
    try:
        with deciding(comm):
            yield
    except Exception as error:      # noqa: BLE001 - re-raised below, on every rank
        failure = error
    first = comm.allreduce(comm.rank if failure is not None else comm.size, op=MPI.MIN)
    if first == comm.size:
        return
    kind = (type(failure).__module__, type(failure).__qualname__, str(failure)) \
        if comm.rank == first else None
    module, name, message = comm.bcast(kind, root=first)
    if comm.rank == first:
        raise failure
    raise _exception_like(module, name, message)


def communicator_of(u) -> MPI.Comm:
    """The communicator of the mesh of ``u`` (a Function or a function space);
    ``MPI.COMM_WORLD`` for anything else, so that the checks that refuse it are
    collective too."""
    space = getattr(u, "function_space", u)
    comm = getattr(getattr(space, "mesh", None), "comm", None)
    return comm if isinstance(comm, MPI.Comm) else MPI.COMM_WORLD


def _exception_like(module: str, name: str, message: str) -> BaseException:
    """An exception of the class ``module.name`` with ``message`` (a RuntimeError
    naming the class where it cannot be made from a message alone)."""
    try:
        cls = getattr(builtins if module == "builtins" else importlib.import_module(module),
                      name)
        return cls(message)
    except Exception:               # noqa: BLE001 - a class that takes other arguments
        return RuntimeError(f"{module}.{name} on another rank: {message}")


def load_data(forms: Sequence, u, bcs: Sequence) -> list[tuple[str, Callable]]:
    """What a load path may set in the user's model, each with a description and
    a function that returns its present local values: the Constants and the
    Functions other than ``u`` of the UFL ``forms``, and the values of the
    Dirichlet conditions ``bcs``."""
    data: list[tuple[str, Callable]] = []
    constants = {id(c): c for form in forms for c in form.constants()}
    for k, c in enumerate(constants.values()):
        data.append((f"Constant {k} of the residual form", lambda c=c: c.value))
    coefficients = {id(f): f for form in forms for f in form.coefficients() if f is not u}
    for f in coefficients.values():
        name = getattr(f, "name", "")
        data.append((f"the Function '{name}' of the residual form",
                     lambda f=f: f.x.array))
    for k, bc in enumerate(bcs):
        g = bc.g
        data.append((f"the value of Dirichlet condition {k}",
                     (lambda g=g: g.value) if hasattr(g, "value") else (lambda g=g: g.x.array)))
    return data


def non_finite_input(comm: MPI.Comm, x: PETSc.Vec,
                     data: Sequence[tuple[str, Callable]]) -> tuple[bool, Optional[str]]:
    """Whether the iterate ``x`` is finite, and what in it or in the model's
    ``data`` (:func:`load_data`) is NaN or infinite (None: nothing), the same
    on every rank (collective)."""
    message = None
    for description, values in data:
        v = np.asarray(values())
        if not np.all(np.isfinite(v)):
            shown = v.tolist() if v.size <= 3 else "an array"
            message = (f"{description} is NaN or infinite ({shown}): the residual is not "
                       "finite after the load update; the load path (its update(t)) set a "
                       "non-finite load")
            break
    finite = bool(np.all(np.isfinite(x.array_r)))
    gathered = comm.allgather((finite, message))
    iterate_finite = all(f for f, _ in gathered)
    messages = [m for _, m in gathered if m]
    if messages:
        return iterate_finite, messages[0]
    return iterate_finite, (None if iterate_finite
                            else "the Newton iterate has NaN or infinite values")


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
    """Refuse NaN or infinite node coordinates, cells of zero size and tangled
    (folded) cells, on every rank (collective).

    Across every facet that two local cells share, their centroids must lie
    on opposite sides of the facet, each further than the zero length
    (:mod:`dolfinx_mortar.tolerance`) from it. Exact for simplices; for
    quadrilaterals and hexahedra the facet's plane is that of its first
    three vertices. Facets on a partition boundary with no ghost cell are not
    seen by either rank.

    Raises
    ------
    ValueError
        Naming a non-finite node, or the two cells and the facet's vertices.
    """
    with collective_checks(mesh.comm):
        _check_finite_coordinates(mesh)
        message = _bad_cells_message(mesh) if mesh.geometry.dim == mesh.topology.dim else None
        if message:
            raise ValueError(message)


def _check_finite_coordinates(mesh: dolfinx.mesh.Mesh) -> None:
    """Refuse NaN or infinite node coordinates, naming a node (they were reported
    as "a cell of zero size" at the finite vertices of a facet next to it)."""
    gdim = mesh.geometry.dim
    x = mesh.geometry.x[:, :gdim]
    bad = np.flatnonzero(~np.isfinite(x).all(axis=1))
    if len(bad):
        node_map = mesh.geometry.index_map()
        global_node = int(node_map.local_to_global(bad[:1].astype(np.int32))[0])
        raise ValueError(f"the mesh has NaN or infinite node coordinates: node {global_node} "
                         f"(global geometry node number) is at {x[bad[0]].tolist()}; "
                         f"{len(bad)} such node(s) on rank {mesh.comm.rank}")


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


def _option_used_query() -> Optional[Callable[[str], bool]]:
    """``name -> whether an object read the option`` (name without the '-')."""
    db = PETSc.Options()
    if hasattr(db, "used"):            # petsc4py 3.25 (not 3.22)
        return lambda name: bool(db.used(name))
    # older petsc4py: PetscOptionsUsed of the library petsc4py itself loaded
    lib = petsc_library()
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
    with collective_checks(mesh.comm):
        if not np.issubdtype(np.asarray(facet_tags.values).dtype, np.integer):
            raise TypeError(f"facet tag values must be integers, got "
                            f"{np.asarray(facet_tags.values).dtype}")
        if facet_tags.dim != mesh.topology.dim - 1:
            raise ValueError(f"the meshtags have dimension {facet_tags.dim}; contact needs "
                             f"facet tags (dimension {mesh.topology.dim - 1})")
        tags = [tag for tag in tags if tag is not None]
        for tag in tags:
            if not isinstance(tag, (int, np.integer)):
                raise TypeError(f"tags must be integers, got {tag!r} ({type(tag).__name__})")
    present = {int(t) for values in mesh.comm.allgather(np.unique(facet_tags.values))
               for t in values}
    with collective_checks(mesh.comm):
        for tag in tags:
            if tag not in present:
                raise ValueError(f"facet tag {tag} marks no facets (tags present: "
                                 f"{sorted(present)})")


def check_contact_tags(mesh, facet_tags, slave_tag, master_tag: Optional[int]) -> None:
    """Slave tag (or tags) and master tag as :func:`check_tags`, and no facet carrying both."""
    slave_tags = [slave_tag] if np.ndim(slave_tag) == 0 else list(slave_tag)
    if not slave_tags:
        raise ValueError("no slave tag: give one facet tag or a list of them")
    check_tags(mesh, facet_tags, [*slave_tags, master_tag])
    if master_tag is not None:
        a = np.concatenate([facet_tags.find(t) for t in slave_tags])
        b = facet_tags.find(master_tag)
        if mesh.comm.allreduce(len(np.intersect1d(a, b))) > 0:
            raise ValueError(f"slave tag {slave_tag} and master tag {master_tag} "
                             "overlap: a facet cannot be both")


def check_contact_arguments(u, master_tag: Optional[int], obstacle,
                            axisymmetric: bool, self_contact: bool = False) -> None:
    """The displacement, the master or obstacle (or self-contact) and the mesh's
    dimension given to a contact term."""
    if not isinstance(u, dolfinx.fem.Function):
        raise TypeError(f"u must be a dolfinx.fem.Function (the displacement), got "
                        f"{type(u).__name__}")
    V = u.function_space
    gdim = V.mesh.geometry.dim
    if gdim < 2 or V.mesh.topology.dim < 2:
        # it failed with a numpy IndexError in the check of the cells
        raise ValueError(f"contact needs a 2D or 3D mesh, got a mesh of topological "
                         f"dimension {V.mesh.topology.dim} in {gdim}D")
    if V.dofmap.index_map_bs != gdim:
        raise ValueError(f"u must be a vector Function with {gdim} components per node")
    if self_contact and (master_tag is not None or obstacle is not None):
        raise ValueError("self_contact=True takes no master_tag and no obstacle: the slave "
                         "surface is its own master")
    if not self_contact and (master_tag is None) == (obstacle is None):
        raise ValueError("give exactly one of master_tag (elastic master) and obstacle "
                         "(rigid analytic obstacle), or self_contact=True")
    if obstacle is not None and not all(hasattr(obstacle, name) for name in
                                        ("gdim", "signed_distance", "gradient", "hessian")):
        raise TypeError(f"the obstacle must be a rigid obstacle (RigidPlane, RigidSphere, "
                        f"RigidCylinder, …), got {type(obstacle).__name__}")
    if obstacle is not None and obstacle.gdim != gdim:
        raise ValueError(f"a {obstacle.gdim}D obstacle in a {gdim}D mesh: the option "
                         "does not fit the mesh's dimension")
    if axisymmetric and gdim != 2:
        raise ValueError(f"axisymmetric contact needs a 2D (r, z) mesh, got a {gdim}D one")

