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

import numpy as np
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


def _two_blocks():
    """A block (mesh size 0.05) 0.1 above a wider one (0.07): its displacement space and
    facet tags (2: its bottom, the slave; 3: the lower block's top; 1, 4: the bottom
    and the top)."""
    from dolfinx import fem

    from demo_support.stack import stacked_blocks

    mesh, tags = stacked_blocks(MPI.COMM_WORLD, [(0.0, 1.0, 0.0, 1.0, 0.07),
                                                 (0.2, 0.8, 1.1, 2.1, 0.05)], (1, 2), (3, 4), 5)
    return fem.functionspace(mesh, ("Lagrange", 1, (2,))), tags


def _blocks_pressed(load_steps: int, sideways: float = 0.0, friction=None,
                    search_radius=None) -> tuple[np.ndarray, int]:
    """The upper block's top moved 0.22 down (and ``sideways``), its bottom face
    the slave, on the current surface (LmLS*): the contact force and the Newton
    iterations."""
    from dolfinx_mortar import ContactProblem

    V, tags = _two_blocks()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # nothing within reach at the start
        problem = ContactProblem(V, tags, 2, master_tag=3, E=1.0, nu=0.3, kind="LmLS*",
                                 penalty=1e3 / 0.05, basis_configuration="current",
                                 friction=friction, search_radius=search_radius,
                                 fixed={1: {0: 0.0, 1: 0.0}, 4: {0: sideways, 1: -0.22}})
        result = problem.solve(load_steps=load_steps)
    return problem.contact_force(), result.newton_iterations


def test_current_surface_faces_driven_through_each_other_in_one_step(caplog):
    """On the current surface each slave facet searches two of its own
    diameters (0.1 here): one load step that drives the faces 0.12 through each
    other left them unpaired, and the force was exactly 0 after one Newton
    iteration. The check finds the nodes behind the master, widens the search
    and solves the step again: the force of four steps (4.78e-2)."""
    with caplog.at_level(logging.INFO, logger=CHECKS):
        force = _blocks_pressed(1)[0][1]
    reference = _blocks_pressed(4)[0][1]
    assert reference > 0.04, reference
    assert abs(force - reference) < 1e-6 * reference, (force, reference)
    logged = [r.getMessage() for r in caplog.records if r.name == CHECKS]
    if MPI.COMM_WORLD.rank == 0:
        assert any("passed through the master outside the pairs" in m for m in logged), logged


def _assert_widened(caplog) -> None:
    logged = [r.getMessage() for r in caplog.records if r.name == CHECKS]
    if MPI.COMM_WORLD.rank == 0:
        assert any("passed through the master outside the pairs" in m for m in logged), logged


def test_driven_through_each_other_with_friction_as_if_in_reach_from_the_start(caplog):
    """The same step with Coulomb friction (μ = 0.3) and the top moved 0.03
    sideways as well: the widened search gives the force of a search radius that
    reaches across the gap from the start, both components."""
    from dolfinx_mortar import CoulombFriction

    with caplog.at_level(logging.INFO, logger=CHECKS):
        force, _ = _blocks_pressed(1, 0.03, CoulombFriction(0.3))
    reference, _ = _blocks_pressed(1, 0.03, CoulombFriction(0.3), search_radius=0.5)
    assert reference[1] > 0.04 and abs(reference[0]) > 1e-3 * reference[1], reference
    assert np.allclose(force, reference, rtol=0, atol=1e-6 * reference[1]), (force, reference)
    _assert_widened(caplog)


def test_driven_through_each_other_at_finite_strain_as_if_in_reach_from_the_start(caplog):
    """A neo-Hookean bulk (the user's own residual, :class:`NonlinearContactProblem`)
    in the same step: the widened search gives the force of a search radius that
    reaches across the gap from the start."""
    from dolfinx import fem
    from petsc4py import PETSc

    from demo_support.laws import neo_hookean_residual
    from dolfinx_mortar import ContactTerm, LoadPathSolver, NonlinearContactProblem

    forces = []
    for search_radius in (None, 0.5):
        V, tags = _two_blocks()
        u = fem.Function(V)
        down = fem.Constant(V.mesh, PETSc.ScalarType(0.0))
        bcs = [fem.dirichletbc(value, fem.locate_dofs_topological(V.sub(c), 1, tags.find(tag)),
                               V.sub(c))
               for tag, c, value in ((1, 0, PETSc.ScalarType(0.0)), (1, 1, PETSc.ScalarType(0.0)),
                                     (4, 0, PETSc.ScalarType(0.0)), (4, 1, down))]

        def press(t: float) -> None:
            down.value = -0.22 * t

        with caplog.at_level(logging.INFO, logger=CHECKS), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)   # nothing within reach at the start
            contact = ContactTerm(u, tags, 2, master_tag=3, kind="LmLS*", penalty=1e3 / 0.05,
                                  basis_configuration="current", search_radius=search_radius)
            problem = NonlinearContactProblem(neo_hookean_residual(u, 1.0, 0.3), u, contact, bcs)
            LoadPathSolver(problem).solve(press, load_steps=1)
        forces.append(contact.results.contact_force())
        if search_radius is None:
            _assert_widened(caplog)
    force, reference = forces
    assert reference[1] > 0.04, reference
    assert np.allclose(force, reference, rtol=0, atol=1e-6 * reference[1]), (force, reference)
