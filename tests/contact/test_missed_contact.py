"""Contact that nobody paired: faces that start further apart than the search
radius (:mod:`dolfinx_mortar.contact.checks.missed_contact`).

Tried as a new user would: two faces tagged slave and master, apart at the
start, pressed together by prescribed displacements until they carry load. The
pairs were searched once within the largest slave facet (or where a step
starts, with "previous"), and the contact force stayed exactly 0 while the
bodies passed through each other, without a word.
"""
from __future__ import annotations

import logging
import warnings

import pytest
from mpi4py import MPI

from demo_support.mirror import mirror

CHECKS = "dolfinx_mortar.contact.checks"
#: the upper body's largest contact facet on 12 graded cells is 0.06 long: the faces start
#: about two of them apart
GAP = 0.12


@pytest.mark.parametrize("configuration", ["initial", "previous"])
def test_faces_that_start_apart_are_paired_and_it_is_logged(configuration, caplog):
    """Two curved bodies GAP apart, each moved GAP/2 + 0.02 towards the other in
    one load step, against the upper one moved onto a rigid plane (the mirror
    problem): the same contact force (3.5e-4), and the pressures node by node
    within the frozen configuration's own accuracy at this approach (0.007,
    against 0.00013 when they start touching). Before, the force was exactly 0."""
    with caplog.at_level(logging.INFO, logger=CHECKS), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # the penalty check
        result = mirror(12, 0.02, penalty=2e4, kind="LcLS*", basis_configuration=configuration,
                        load_steps=1, gap=GAP)
    assert abs(result.force_difference) < 2e-3, result.force_difference
    assert result.pressure_difference < 0.02, result.pressure_difference
    logged = [r.getMessage() for r in caplog.records if r.name == CHECKS]
    if MPI.COMM_WORLD.rank == 0:
        assert any("passed through the master outside the pairs" in m for m in logged), logged
