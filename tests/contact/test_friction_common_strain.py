"""Bodies that deform together carry no friction: a patch test with Poisson's
ratio, where both blocks widen alike under a uniform pressure and nothing
slips. Friction's slip must vanish for every motion the two sides share, not
only for rigid translations (docs/FRICTION.md, §The slip of LmLS and LmLS*)."""
from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from dolfinx import fem

from dolfinx_mortar import ContactProblem, CoulombFriction
from support.meshes import BLOCK_BOTTOM, BLOCK_LEFT, BLOCK_OFFSET, BLOCK_TOP, stacked_rectangles

#: the pressure on the upper block's top; Coulomb's μ
Q, MU = 0.01, 0.3


def widening_blocks(kind: str, configuration: str, self_contact: bool) -> ContactProblem:
    """[0,1]×[0,1/4] on 8 cells across under [0,1]×[1/4,1/2] on 11, ν = 0.3,
    pressed by Q: the left edges on a symmetry line (u_x = 0), the bottom on
    rollers, the right edges free. The stress is −Q in y everywhere, so both
    blocks widen by the same u_x = ν(1 + ν)Q x / E (plane strain), which P1
    represents exactly: the faces touch at every point with pressure Q and no
    tangential traction. As a slave–master pair, or as one self-contact term."""
    domain, tags, _ = stacked_rectangles(MPI.COMM_WORLD, [8, 11])
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    faces = dict(slave_tag=[BLOCK_TOP, BLOCK_BOTTOM + BLOCK_OFFSET], self_contact=True) \
        if self_contact else dict(slave_tag=BLOCK_TOP, master_tag=BLOCK_BOTTOM + BLOCK_OFFSET)
    problem = ContactProblem(V, tags, **faces, E=1.0, nu=0.3, kind=kind,
                             basis_configuration=configuration, penalty=1e3 * 11,
                             fixed={BLOCK_BOTTOM: {1: 0.0}, BLOCK_LEFT: {0: 0.0}},
                             tractions={BLOCK_TOP + BLOCK_OFFSET: [0.0, -Q]},
                             friction=CoulombFriction(MU))
    problem.solve(load_steps=1)
    return problem


@pytest.mark.parametrize("self_contact", [False, True], ids=["slave-master", "self-contact"])
@pytest.mark.parametrize("kind", ["LcLS*", "LcLS", "LmLS*", "LmLS", "GLS*", "GLS"])
def test_blocks_that_widen_together_stick_without_friction(kind, self_contact):
    """Every node of the contact faces carries Q and no tangential traction,
    sticking. LmLS(*) measured each node's slip with its slave part lumped
    and its master part not, until their slip was measured in the dual basis:
    the shared widening read as slip at the held edge, whose node sat on the
    Coulomb cone (q = μp at x = 0), and the pressure was 3.7% off Q as a
    slave–master pair, 4.1% as one self-contact term."""
    problem = widening_blocks(kind, "initial", self_contact)
    pressure = problem.surface_pressure(gather=True)
    friction = problem.contact.results.surface_friction(gather=True)
    assert len(pressure.p) == (9 + 12 if self_contact else 9)
    assert np.allclose(pressure.p, Q, rtol=1e-9, atol=0)
    assert np.allclose(friction.q, 0.0, rtol=0, atol=1e-9 * Q)
    assert np.all(friction.stick_slip == 1)
