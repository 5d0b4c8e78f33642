"""Small contact scenes shared by tests of several layers (public API only)."""
from __future__ import annotations

import pytest
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar import ContactProblem
from support import load_demo
from support.meshes import rectangle

LOCAL_KINDS = ["LmLS", "LmLS*", "LcLS*", "LcLS"]
ALL_KINDS = ["GLS", "GLS*"] + LOCAL_KINDS


def block_on_plane(comm=MPI.COMM_WORLD, n=(8, 4)):
    """[0,1]x[0,0.5]; tags: 1 bottom (slave), 2 top (load), 3 left (u_x = 0)."""
    domain, tags = rectangle(comm, 0.0, 0.5, n, bottom=1, top=2, left=3)
    return fem.VectorFunctionSpace(domain, ("Lagrange", 1)), tags


def pressed_block(obstacle, kind: str, n=(6, 3), **options) -> ContactProblem:
    """The block of :func:`block_on_plane` against ``obstacle``, fixed sideways on
    its left, pushed down on its top (penalty 50), at full load."""
    V, tags = block_on_plane(n=n)
    problem = ContactProblem(V, tags, 1, obstacle=obstacle, E=1.0, nu=0.3, kind=kind,
                             penalty=50.0, fixed={3: {0: 0.0}}, tractions={2: [0.0, -0.01]},
                             **options)
    problem.set_load(1.0)
    return problem


def assert_same_hertz2d_figures_on_one_and_all_ranks(argv: list, make_problem) -> None:
    """Solve the Hertz 2D scene of ``argv`` on all ranks and on this rank alone
    (``make_problem(demo, V, tags, h)`` builds the problem, two load steps)."""
    demo = load_demo("hertz2d")
    args = demo.parse_args(argv)
    results = []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        ref = demo.hertz(args)
        domain, tags, h = demo.build_mesh(args, ref["a"], comm)
        problem = make_problem(demo, fem.VectorFunctionSpace(domain, ("Lagrange", 1)), tags, h)
        problem.solve(load_steps=2)
        results.append(demo.contact_results(problem, ref))
    for key in ("p0", "a", "l2_error", "contact_force"):
        assert results[0][key] == pytest.approx(results[1][key], rel=1e-8), key
