"""A body that has passed through a rigid obstacle at convergence is warned
about, also where the contact term does not hold it (off the slave surface)."""
from __future__ import annotations

import logging
import re

import pytest
from mpi4py import MPI

from dolfinx_mortar import ContactProblem, RigidPlane
from support.scenes import block_on_plane

CHECKS = "dolfinx_mortar.contact.checks"


def pressed(traction: float) -> ContactProblem:
    """The 8×4 block [0,1]×[0,0.5] (h = 1/8) on the plane y = 0 with a
    penalty that holds its bottom (1e5: a 0.01 traction sinks it 1e-7)."""
    V, tags = block_on_plane()
    return ContactProblem(V, tags, 1, obstacle=RigidPlane([0, 0], [0, 1]), E=1.0, nu=0.3,
                          kind="LcLS*", penalty=1e5, fixed={3: {0: 0.0}},
                          tractions={2: [0.0, -traction]})


def test_a_body_folded_through_the_obstacle_is_logged_once(caplog):
    """Under a traction of 10 E the small-strain block's top passes 4 through
    the plane while its bottom, the slave surface, is held 1e-4 deep: the
    penalty check of the slave nodes saw nothing, and the solve ended without
    a word. Now it is logged once, naming the depth in cell lengths."""
    problem = pressed(10.0)
    with caplog.at_level(logging.WARNING, logger=CHECKS):
        problem.solve(load_steps=1)
        problem.contact.check_path(problem.contact.results.penetration())  # not logged again
    records = [r.getMessage() for r in caplog.records if r.name == CHECKS]
    if MPI.COMM_WORLD.rank:                          # rank 0 logs
        assert records == []
        return
    [message] = records
    depth, ratio = map(float, re.search(r"passed through the obstacle by (\S+) \((\S+) "
                                        r"lengths of its cells", message).groups())
    # plane strain, free sideways: the top (at 0.5) moves down by 0.5·10·(1−ν²)
    assert depth == pytest.approx(0.5 * 10 * (1 - 0.3 ** 2) - 0.5, rel=1e-3)
    # its largest cell's diameter is the diagonal of a 1/8 square
    assert ratio == pytest.approx(depth / (2 ** 0.5 / 8), rel=1e-3)
    assert "reference point (" in message and ", 0.5)" in message
    # the slave nodes: 10/ε = 1e-4 deep, 8e-4 element lengths
    assert "slave surface's nodes penetrate by at most 0.0008 " in message
    assert "more load steps" in message and "larger penalty" in message


def test_a_body_that_stays_outside_is_not_logged(caplog):
    problem = pressed(0.01)
    with caplog.at_level(logging.WARNING, logger=CHECKS):
        problem.solve(load_steps=1)
    assert not [r for r in caplog.records if r.name == CHECKS]
