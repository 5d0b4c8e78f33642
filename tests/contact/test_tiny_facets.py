"""A facet 1e-6 h long at 45° at the end of the slave surface (issue 35).

The patch test of two blocks (demos/patch_test.py) with the lower block's top
right corner cut by a 45° facet 1e-6 h long (a chamfer, as mesh generators
leave at a corner of the geometry), part of the slave surface, or turned up (a
lip that the upper block follows). The chamfer's end node has no other facet:
its own averaged normal is the chamfer's 45°, and the interface normal (the
bisector with the master's) 22.5°, which measured its gap 1/cos 22.5° too long
and off the master's end (GLS 0.14, LmLS 0.36, LcLS* 0.077 in the initial and
previous configurations; in the current one the facet searched two of its own
diameters for a master 1e-4 away: the node untouched, 1.0). Its nodal pressure
is a force over a weight of 1e-6 h, but a vanishing facet should leave the
solution what it is without it: p at every node. The nodes joined by such a
facet share the normal of the cells around them (normal_clusters), and its
search reaches as far as theirs. What is left is the chamfer's real depth t
against the penalty penetration δ = p/ε: t/δ = 5e-4 here.

Every case runs with RuntimeWarnings as errors: the chamfer's end node once
measured its penetration and slip in its own facet's length, 7e-7 h, and each
case warned falsely, of a low penalty ("penetrates by 0.0001 (1.4e+03 slave
element lengths)") or of unreliable forces ("slipped 1.44e+03 element
lengths"); a node of a normal cluster has the cluster's element length.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest
from mpi4py import MPI

ALL_KINDS = ["GLS", "GLS*", "LmLS", "LmLS*", "LcLS*", "LcLS"]
SLAVE, MASTER, TOP, BOTTOM, SYM = 1, 2, 3, 4, 5
H, TINY = 0.1, 5e-8           # element size, and the tiny facet's extent (5e-7 h)
PRESSURE, PENALTY = 0.01, 10.0  # δ = p h / (PENALTY E) = 1e-4: t/δ = 5e-4

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")


@lru_cache(maxsize=None)
def mesh(scene: str):
    """The two blocks [0, 1] × [−½, 0] and [0, 1] × [0, ½] (h = 0.1, 0.14),
    the lower one's corner (1, 0) cut at 45° downward (chamfer) or the upper
    one's bottom turned up with the lower's top (lip) over the last TINY."""
    import gmsh
    from dolfinx_mortar.io.gmsh_io import model_to_mesh
    t = TINY
    lower = {"chamfer": [(0, -.5), (1, -.5), (1, -t), (1 - t, 0), (0, 0)],
             "lip": [(0, -.5), (1, -.5), (1, t), (1 - t, 0), (0, 0)]}[scene]
    upper = {"chamfer": [(0, 0), (1, 0), (1, .5), (0, .5)],
             "lip": [(0, 0), (1 - t, 0), (1, t), (1, .5), (0, .5)]}[scene]
    gmsh.initialize(["", "-v", "0"])
    try:
        if MPI.COMM_WORLD.rank == 0:
            geo = gmsh.model.geo

            def polygon(points, h):
                p = [geo.addPoint(x, y, 0, h) for x, y in points]
                lines = [geo.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]
                return geo.addPlaneSurface([geo.addCurveLoop(lines)]), lines

            low, ll = polygon(lower, H)
            up, ul = polygon(upper, 0.14)
            geo.synchronize()
            gmsh.model.addPhysicalGroup(1, ll[2:4], SLAVE)          # the top, tiny facet included
            gmsh.model.addPhysicalGroup(1, ul[:len(upper) - 3], MASTER)
            gmsh.model.addPhysicalGroup(1, [ul[-2]], TOP)
            gmsh.model.addPhysicalGroup(1, [ll[0]], BOTTOM)
            gmsh.model.addPhysicalGroup(1, [ll[-1], ul[-1]], SYM)
            gmsh.model.addPhysicalGroup(2, [low], 11)
            gmsh.model.addPhysicalGroup(2, [up], 12)
            gmsh.model.mesh.generate(2)
        domain, _, tags = model_to_mesh(gmsh.model, MPI.COMM_WORLD, 0, gdim=2)
    finally:
        gmsh.finalize()
    return domain, tags


def worst_deviation(scene: str, kind: str, configuration: str) -> float:
    """max |p_A / p − 1| over the slave nodes (demos/patch_test.py's measure)."""
    from dolfinx import fem
    from dolfinx_mortar import ContactProblem
    domain, tags = mesh(scene)
    comm = domain.comm
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    problem = ContactProblem(V, tags, SLAVE, master_tag=MASTER, E=1.0, nu=0.3, kind=kind,
                             penalty=PENALTY / H, fixed={SYM: {0: 0.0}, BOTTOM: {1: 0.0}},
                             basis_configuration=configuration,
                             tractions={TOP: [0.0, -PRESSURE]})
    problem.solve(load_steps=1)
    state = problem.contact.evaluate()
    p = problem.surface_pressure(state, gather=True).p
    n = problem.slave.layout.num_owned
    area = comm.allreduce(float(np.sum(state.lumped_weights[:n])))
    return float(np.max(np.abs(p * area / PRESSURE - 1.0)))


CASES = [(kind, configuration) for configuration in ("initial", "previous", "current")
         for kind in ALL_KINDS
         if not (configuration == "current" and kind.startswith("GLS"))]  # refused there


@pytest.mark.parametrize("kind, configuration", CASES)
def test_a_tiny_chamfer_at_the_surface_end_keeps_the_uniform_pressure(kind, configuration):
    assert worst_deviation("chamfer", kind, configuration) < 1e-3


@pytest.mark.parametrize("kind, configuration",
                         [c for c in CASES if c[1] != "current"])
def test_a_tiny_lip_followed_by_the_master_keeps_the_uniform_pressure(kind, configuration):
    """The lip's end node faces the master's own lip: the interface normal took the
    master's 45° facet as the opposite normal (0.08-0.45 off). In the current
    configuration the lip slides by δ/√2 ≫ t along itself and the segmentation,
    along the slave facets' own normals, leaves it uncovered: not solved here."""
    assert worst_deviation("lip", kind, configuration) < 1e-3
