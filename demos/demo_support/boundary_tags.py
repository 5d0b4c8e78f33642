"""Facet tags of a mesh's boundary from predicates on the coordinates (the demos'
scenes mark their gmsh and DOLFINx meshes this way)."""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np
from dolfinx import mesh


def tag_boundary_facets(domain: mesh.Mesh,
                        marks: Sequence[tuple[int, Callable[[np.ndarray], np.ndarray]]]
                        ) -> mesh.MeshTags:
    """The boundary facets where each predicate holds, tagged with its tag.

    Parameters
    ----------
    domain
        The mesh.
    marks
        ``(tag, where)`` pairs; ``where(x)`` takes coordinates of shape (3, n) and
        returns a boolean array, as for ``dolfinx.mesh.locate_entities_boundary``.
        A facet that several predicates mark gets the first one's tag.

    Returns
    -------
    dolfinx.mesh.MeshTags
        The facet tags, sorted by facet.
    """
    fdim = domain.topology.dim - 1
    facets = [mesh.locate_entities_boundary(domain, fdim, where) for _, where in marks]
    values = np.concatenate([np.full(len(f), tag, np.int32) for f, (tag, _) in zip(facets, marks)])
    # np.unique keeps each facet's first occurrence: the first predicate's tag
    facets, first = np.unique(np.concatenate(facets), return_index=True)
    return mesh.meshtags(domain, fdim, facets.astype(np.int32), values[first])
