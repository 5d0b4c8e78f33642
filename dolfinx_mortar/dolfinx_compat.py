"""Every difference between the DOLFINx releases the library supports (0.9, 0.10, 0.11).

The rest of the package is written once, in the idiom of DOLFINx 0.10+, and
calls this module wherever the releases differ. Each difference is decided by
feature detection (does the module, attribute or keyword exist), never by
parsing a version string, so that a release in between or a patched build
takes the path its features allow.

======================================  =====================  ==========================
what                                    0.9                    0.10 / 0.11
======================================  =====================  ==========================
gmsh models                             ``io.gmshio``, tuple   ``io.gmsh``, ``MeshData``
``create_mesh`` arguments               ``(cells, x, e)``      ``(cells, e, x)``
cell partitioner from a graph one       ``(part, mode)``       ``(part, mode, max_links)``
geometry dofmap, coordinate element     ``dofmap``, ``cmap``   ``dofmaps[0]``, ``cmaps[0]``
``meshtags_from_entities`` entities     C++ adjacency list     ``graph.AdjacencyList``
Python warnings after FFCx's import     captured (hidden)      shown (FFCx 0.11)
======================================  =====================  ==========================
"""
from __future__ import annotations

import contextlib
import importlib.util
import logging
import os
import warnings
from pathlib import Path
from typing import Callable, Optional

import dolfinx
import dolfinx.graph
import dolfinx.io
import dolfinx.la
import dolfinx.mesh
import numpy as np
import numpy.typing as npt
from dolfinx import cpp as _cpp
from mpi4py import MPI
from petsc4py import PETSc



def _show_warnings_ffcx_hid() -> None:
    """Show Python warnings again where FFCx's package init hid them.

    FFCx 0.9 (Debian 13) calls ``logging.captureWarnings(True)`` when it is
    imported, and DOLFINx imports it. Python's warnings then go to the
    "py.warnings" logger, which gets a NullHandler where nothing handles it:
    in a script that does not configure logging every warning vanished, the
    library's too ("the contact misses them", "the penalty is too low"), while
    pytest, which catches warnings itself, saw them all (FEniCS/ffcx#712; FFCx
    0.11 does it in its command line only). Undone where FFCx's own init does
    it, decided on its source rather than its version.
    """
    captured = getattr(warnings.showwarning, "__module__", None) == "logging"
    spec = importlib.util.find_spec("ffcx")
    if not captured or spec is None or spec.origin is None:
        return
    with contextlib.suppress(OSError):
        if "captureWarnings(capture=True)" in Path(spec.origin).read_text():
            logging.captureWarnings(False)


_show_warnings_ffcx_hid()

__all__ = ["model_to_mesh", "create_mesh", "create_cell_partitioner", "geometry_dofmap",
           "coordinate_element", "adjacency_list", "cpp_adjacency_list", "ghosted_vector",
           "tags_belong_to", "newton_solver_class", "gmsh_module"]


def gmsh_module():
    """DOLFINx's gmsh interface module: ``dolfinx.io.gmsh`` (0.10+) or ``dolfinx.io.gmshio``."""
    try:
        from dolfinx.io import gmsh as module
    except ImportError:
        from dolfinx.io import gmshio as module
    if not hasattr(module, "model_to_mesh"):   # a gmsh *package* shadowing the name
        from dolfinx.io import gmshio as module
    return module


def model_to_mesh(model, comm: MPI.Comm, rank: int = 0, gdim: int = 3,
                  partitioner: Optional[Callable] = None):
    """A gmsh model as ``(mesh, cell_tags, facet_tags)``, whatever DOLFINx returns.

    Parameters
    ----------
    model
        The gmsh model, built on ``rank``.
    comm, rank, gdim, partitioner
        As for DOLFINx's ``model_to_mesh``.
    """
    kwargs = {"gdim": gdim}
    if partitioner is not None:
        kwargs["partitioner"] = partitioner
    with _scotch_without_threads():
        result = gmsh_module().model_to_mesh(model, comm, rank, **kwargs)
    if hasattr(result, "mesh"):          # 0.10+: a MeshData
        return result.mesh, result.cell_tags, result.facet_tags
    return tuple(result)[:3]


def create_mesh(comm: MPI.Comm, cells: npt.NDArray[np.int64], x: npt.NDArray[np.floating],
                element, partitioner: Optional[Callable] = None) -> dolfinx.mesh.Mesh:
    """``dolfinx.mesh.create_mesh``; the keywords keep the argument order of
    0.9 (cells, x, e) and 0.10+ (cells, e, x) apart."""
    with _scotch_without_threads():
        return dolfinx.mesh.create_mesh(comm, cells, x=x, e=element, partitioner=partitioner)


@contextlib.contextmanager
def _scotch_without_threads():
    """PT-Scotch 7 partitions with threads that call MPI collectives of their own; on
    Debian sid (Scotch 7.0.16, Open MPI 6.0.0rc2) those hung for good in a loop of
    merges on 4 ranks on 2 cores (tools/scotch_thread_hang.py). One
    thread per rank (``SCOTCH_PTHREAD_NUMBER``, read at each partition) unless the
    user chose a number."""
    chosen = os.environ.get("SCOTCH_PTHREAD_NUMBER")
    if chosen is None:
        os.environ["SCOTCH_PTHREAD_NUMBER"] = "1"
    try:
        yield
    finally:
        if chosen is None:
            os.environ.pop("SCOTCH_PTHREAD_NUMBER", None)


def _takes_max_links(function) -> bool:
    return "max_facet_to_cell_links" in (function.__doc__ or "")


def create_cell_partitioner(graph_partitioner: Callable,
                            ghost_mode=dolfinx.mesh.GhostMode.none) -> Callable:
    """A cell partitioner for :func:`create_mesh` from a graph partitioner
    ``(comm, nparts, graph, ghosting) -> AdjacencyList_int32``."""
    make = _cpp.mesh.create_cell_partitioner
    if _takes_max_links(make):
        return make(graph_partitioner, ghost_mode, 2)   # 2: facets of a non-branching mesh
    return make(graph_partitioner, ghost_mode)


def geometry_dofmap(mesh: dolfinx.mesh.Mesh) -> npt.NDArray[np.int32]:
    """The geometry dofmap of a single-cell-type mesh, (cells, nodes per cell)."""
    geometry = mesh.geometry
    if hasattr(type(geometry), "dofmaps"):
        return geometry.dofmaps[0]
    return geometry.dofmap


def coordinate_element(mesh: dolfinx.mesh.Mesh):
    """The coordinate element of a single-cell-type mesh."""
    geometry = mesh.geometry
    if hasattr(type(geometry), "cmaps"):
        return geometry.cmaps[0]
    return geometry.cmap


def adjacency_list(data: npt.NDArray[np.int32], offsets: npt.NDArray[np.int32]):
    """An int32 adjacency list as ``dolfinx.mesh.meshtags_from_entities`` takes it."""
    return dolfinx.graph.adjacencylist(np.asarray(data, dtype=np.int32),
                                       np.asarray(offsets, dtype=np.int32))


def cpp_adjacency_list(data: npt.NDArray[np.int32],
                       offsets: npt.NDArray[np.int32]) -> _cpp.graph.AdjacencyList_int32:
    """An int32 adjacency list as a partitioner returns it (the C++ object)."""
    return _cpp.graph.AdjacencyList_int32(np.asarray(data, dtype=np.int32),
                                          np.asarray(offsets, dtype=np.int32))


def ghosted_vector(index_map, bs: int) -> PETSc.Vec:
    """A ghosted PETSc vector with the layout of ``index_map`` and block size ``bs``.

    Made with petsc4py alone: DOLFINx's own helpers for this moved and changed
    signature between releases (``la.create_petsc_vector``,
    ``la.petsc.create_vector``, ``fem.petsc.create_vector`` of a form or a space).
    """
    ghosts = np.asarray(index_map.ghosts, dtype=PETSc.IntType)
    size = (index_map.size_local * bs, index_map.size_global * bs)
    return PETSc.Vec().createGhost(ghosts, size=size, bsize=bs, comm=index_map.comm)


def _cpp_object(wrapper):
    return getattr(wrapper, "_cpp_object", wrapper)


def tags_belong_to(tags: dolfinx.mesh.MeshTags, mesh: dolfinx.mesh.Mesh) -> bool:
    """Whether ``tags`` were made on ``mesh``'s topology (the same C++ object)."""
    return _cpp_object(tags.topology) is _cpp_object(mesh.topology)


def newton_solver_class():
    """DOLFINx's ``NewtonSolver`` (``dolfinx.nls.petsc``), or None where it is gone."""
    try:
        from dolfinx.nls.petsc import NewtonSolver
    except ImportError:
        return None
    return NewtonSolver
