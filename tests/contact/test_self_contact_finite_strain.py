"""Self-contact with a finite-strain law (docs/SELF_CONTACT.md): the neo-Hookean C body
squeezed until its arms press on each other, against its upper half on a rigid plane, node
by node, as the small-strain mirror of tests/contact/test_self_contact.py."""
from __future__ import annotations

import numpy as np
import pytest
from dolfinx import fem
from mpi4py import MPI

from demo_support.laws import neo_hookean_residual
from demo_support.self_mirror import (BOTTOM, BRIDGE, CONTACT, SYMMETRY_X, TOP, build,
                                      upper_arc)
from dolfinx_mortar import ContactTerm, LoadPathSolver, NonlinearContactProblem, RigidPlane

#: the half's penalty (the whole body's is half of it: its gap closes from both arms)
PENALTY = 2e4


def squeezed(kind: str, whole: bool, h: float, squeeze: float):
    """The upper arc's nodal pressures of the whole C body in self-contact, or of its
    upper half on the rigid plane y = 0, each arm moved towards the other by
    ``squeeze`` in four load steps ("previous")."""
    body, tags = build(MPI.COMM_WORLD, h, whole=whole)
    V = fem.functionspace(body, ("Lagrange", 1, (2,)))
    u = fem.Function(V)

    def held(tag: int, component: int, value) -> fem.DirichletBC:
        dofs = fem.locate_dofs_topological(V.sub(component), 1, tags.find(tag))
        return fem.dirichletbc(value, dofs, V.sub(component))

    approach = fem.Constant(body, 0.0)
    bcs = [held(TOP, 1, approach), held(SYMMETRY_X, 0, 0.0)]
    if whole:
        opposite = fem.Constant(body, 0.0)
        bcs.append(held(BOTTOM, 1, opposite))
        term = ContactTerm(u, tags, CONTACT, self_contact=True, kind=kind,
                           penalty=PENALTY / 2, basis_configuration="previous")
    else:
        bcs.append(held(BRIDGE, 1, 0.0))
        term = ContactTerm(u, tags, CONTACT, obstacle=RigidPlane([0.0, 0.0], [0.0, 1.0]),
                           kind=kind, penalty=PENALTY, basis_configuration="previous")
    problem = NonlinearContactProblem(neo_hookean_residual(u, 1.0, 0.3), u, [term], bcs)

    def load(t: float) -> None:
        approach.value = -squeeze * t
        if whole:
            opposite.value = squeeze * t

    LoadPathSolver(problem).solve(load, load_steps=4)
    return upper_arc(term.results.surface_pressure(gather=True))


@pytest.mark.parametrize("kind", ["LmLS*", "GLS*"])
def test_a_neo_hookean_body_pressed_against_itself_matches_its_half(kind):
    """Squeezed by 0.06 (h = 0.05, five nodes of the arc in contact): the same
    pressures node by node (measured: LmLS* 9.9e-5, GLS* 1.7e-4)."""
    alone = squeezed(kind, False, 0.05, 0.06)
    whole = squeezed(kind, True, 0.05, 0.06)
    assert np.allclose(alone.x, whole.x, rtol=0, atol=1e-12)
    assert np.count_nonzero(alone.p > 0) >= 5
    assert np.linalg.norm(whole.p - alone.p) < 1e-3 * np.linalg.norm(alone.p)
