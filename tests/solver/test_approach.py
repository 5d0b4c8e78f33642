"""Bodies that approach from a gap: load steps that end short of contact, cut-backs that end.

Issue 35: a load step that ended a fraction of an element short of contact stalled (the
Newton matrix stiffened the nodes near contact while the residual had no contact force), and
in the current configuration the cut-backs went on without end.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar import ContactDivergenceError, ContactProblem, RigidSphere
from dolfinx_mortar.solver.newton.convergence import EquilibriumTest, carried_force
from dolfinx_mortar.solver.load_stepping import LoadStepper
from support import BENCHMARKS, load_script
from support.scenes import ALL_KINDS, block_on_plane

grid = load_script(BENCHMARKS / "approach_grid.py")

#: (gap in element lengths, load steps): a step ending 0.02 h short of contact (0.2 h, 10
#: steps), one ending 0.016 h short in 7 (0.9 h), a near start in many steps (0.05 h, 20)
RUNS = [(0.2, 10), (0.9, 7), (0.05, 20)]
CASES = [(kind, configuration) for kind in ALL_KINDS for configuration in grid.CONFIGURATIONS
         if not (kind.startswith("GLS") and configuration == "current")]


def final_force(kind: str, configuration: str, gap: float, master: str, steps: int) -> float:
    problem = grid.approach(kind, configuration, gap, master)
    problem.solve(load_steps=steps)
    return problem.normal_force()


@pytest.mark.parametrize("master", ["rigid", "elastic"])
@pytest.mark.parametrize("kind, configuration", CASES)
def test_a_body_approaching_from_a_gap_ends_with_the_one_step_force(kind, configuration, master):
    """Every number of load steps ends with the force of one step, to round-off, on
    bases that do not depend on the path ("initial", "current"). Bases rebuilt at
    each step ("previous") follow the surface as it deforms, and their force depends
    on the steps by no more than the current surface's differs from the initial one's
    (with an elastic master LmLS: 0.0256012 in 1 step, 0.0256861 in 20, 0.0257262 on
    the current surface; GLS and LcLS kinds 4e-5 the other way). Before the fix, 10
    steps from 0.2 h failed for every kind."""
    for gap, steps in RUNS:
        one = final_force(kind, configuration, gap, master, 1)
        many = final_force(kind, configuration, gap, master, steps)
        if configuration != "previous":
            assert many == pytest.approx(one, rel=1e-9), (gap, steps)
            continue
        # GLS kinds have no current surface: LcLS*'s, whose force on it differs by
        # the discretization (1e-5 here)
        current = final_force("LcLS*" if kind.startswith("GLS") else kind, "current", gap,
                              master, 1)
        assert abs(many - one) <= abs(current - one) + 1e-4 * one, (gap, steps, one, current)


@pytest.mark.parametrize("configuration", ["initial", "current"])
@pytest.mark.parametrize("variant, kind, options", [
    ("pointwise", "LmLS*", dict(active_set="pointwise")),
    ("axisymmetric", "LmLS*", dict(axisymmetric=True)),
    ("3D", "LcLS*", dict(dim=3))])
def test_the_documented_options_approach_from_a_gap_too(variant, kind, options, configuration):
    """The pointwise active set, an (r, z) body and a 3D box, 10 steps from 0.2 h:
    the one-step force to round-off."""
    forces = [final_force_of(grid.approach(kind, configuration, 0.2, "rigid", **options), steps)
              for steps in (1, 10)]
    assert forces[1] == pytest.approx(forces[0], rel=1e-9)


def final_force_of(problem: ContactProblem, steps: int) -> float:
    problem.solve(load_steps=steps)
    return problem.normal_force()


def test_the_quickstart_disk_lowered_by_a_fifth_of_an_element_in_the_current_configuration():
    """The quickstart's scene with the disk h/5 below the block, 10 steps, on the
    current surface: 1,114 failed attempts in 100 s without an exception before."""
    V, tags = block_on_plane(n=(16, 4))
    h = 1 / 16
    common = dict(E=1.0, nu=0.3, kind="LcLS*", penalty=1e3 / h, fixed={3: {0: 0.0}, 2: {1: -0.02}},
                  basis_configuration="current")
    forces = []
    for steps in (1, 10):
        problem = ContactProblem(V, tags, 1, obstacle=RigidSphere([0.5, -1.0 - h / 5], 1.0),
                                 **common)
        result = problem.solve(load_steps=steps)
        assert result.cut_backs == []
        forces.append(problem.normal_force())
    assert forces[1] == pytest.approx(forces[0], rel=1e-9)


def test_a_run_whose_steps_fail_between_successes_ends():
    """A step that fails five times, succeeds once at a 32nd of itself and fails
    again was cut without bound: the count of failures in a row started again after
    each success (the issue's endless loop). Now a cut never goes below
    2^-max_cuts of the requested step, every cut lowers the load factor, and the
    failures of a whole run are bounded."""
    stepper = LoadStepper(10, max_cuts=5)
    attempts, targets = 0, []
    while not (stepper.done or stepper.exhausted) and attempts < 1000:
        attempts += 1
        target = stepper.target()
        if targets and targets[-1][1] == "failed":
            assert target < targets[-1][0]
        # past 0.15 only every sixth attempt converges
        if target > 0.15 and attempts % 6:
            stepper.failed()
            targets.append((target, "failed"))
        else:
            stepper.succeeded()
            targets.append((target, "converged"))
        assert stepper.step >= stepper.min_step / 2
    assert stepper.exhausted and attempts <= 2 * 5 + 10 + 10


class FailsAbove(ContactProblem):
    """A contact problem whose load above ``limit`` is a NaN traction, except on
    every ``every``-th attempt."""

    limit, every, attempts = 0.3, 6, 0

    def set_load(self, factor: float) -> None:
        super().set_load(factor)
        if factor > self.limit:
            self.attempts += 1
            if self.attempts % self.every:
                self.load.value = np.nan


def test_a_solve_whose_steps_fail_between_successes_raises_naming_its_attempts():
    V, tags = block_on_plane(n=(8, 4))
    problem = FailsAbove(V, tags, 1, obstacle=RigidSphere([0.5, -3.0], 3.0), E=1.0, nu=0.3,
                         kind="LcLS*", penalty=100.0, fixed={3: {0: 0.0}},
                         tractions={2: [0.0, -0.01]})
    with pytest.raises(ContactDivergenceError) as err:
        problem.solve(load_steps=4, max_cuts=3)
    assert 1 <= len(err.value.history) <= 2 * 3 + 4 + 1
    assert "NaN" in str(err.value)


class FakeSNES:
    """The two things EquilibriumTest asks a SNES."""

    def getTolerances(self):
        return 1e-11, 1e-50, 1e-8, 40   # rtol as the library's default


def test_a_step_at_the_round_off_of_the_forces_carried_is_converged():
    """Cattaneo–Mindlin on the current surface: a small step (F = 1.2e-7) reached
    |R| = 1.7e-15, the round-off of the forces the contact carries (1e-3), and was
    refused as 1.4e-8 of its own F: cut back again and again. Measured against the
    forces carried it is converged; a residual far above their round-off is not."""
    test = EquilibriumTest()
    for carried, expected in ((1e-3, PETSc.SNES.ConvergedReason.CONVERGED_SNORM_RELATIVE),
                              (0.0, PETSc.SNES.ConvergedReason.DIVERGED_DTOL)):
        test.start(1.2e-7, carried)
        assert test(FakeSNES(), 0, (1.0, 0.0, 1.2e-7)) == PETSc.SNES.ConvergedReason.ITERATING
        # the Newton step at round-off: |du| ≤ stol |u|
        assert test(FakeSNES(), 1, (1.0, 1e-12, 1.7e-15)) == expected
    test.start(1.2e-7, 1e-3)
    test(FakeSNES(), 0, (1.0, 0.0, 1.2e-7))
    assert test(FakeSNES(), 1, (1.0, 1e-12, 1e-9)) == PETSc.SNES.ConvergedReason.DIVERGED_DTOL
    assert "forces carried" in test.cause


def test_the_forces_carried_are_the_contact_residual():
    """``carried_force`` is the norm of the contact terms' residual: for a block
    pressed on a disk, the nodal forces that balance the applied traction."""
    V, tags = block_on_plane(n=(8, 4))
    problem = ContactProblem(V, tags, 1, obstacle=RigidSphere([0.5, -3.0], 3.0), E=1.0, nu=0.3,
                             kind="LcLS*", penalty=100.0, fixed={3: {0: 0.0}},
                             tractions={2: [0.0, -0.01]})
    problem.solve(load_steps=1)
    nonlinear = problem.solver.problem
    b = nonlinear.vector()
    nonlinear.F(problem.u.x.petsc_vec, b)
    carried = carried_force(nonlinear.contacts)
    # the nodal forces' resultant is the load, 0.01 (nearly vertical): their norm is at
    # least that over the square root of the 9 slave nodes, and at most their sum
    assert 0.01 / math.sqrt(9) <= carried <= 0.02
    assert MPI.COMM_WORLD.allreduce(carried, op=MPI.MAX) == MPI.COMM_WORLD.allreduce(
        carried, op=MPI.MIN)


def test_a_residual_cycling_in_round_off_is_converged():
    """Two blocks shifted by 1e8 on the current surface (DOLFINx 0.11): the
    residual cycled between 7e-15 and 3e-14 with F = 1e-5 and the carried forces
    1e-4, the active set flipping on round-off; it was refused as "cycling" and
    cut back until the run failed. Below the round-off floor of the forces
    carried a cycle is converged, above it a cycle is still a failure."""
    cycle = [6.887e-15, 1.029e-14, 2.791e-14, 2.354e-14]
    for amplitude, expected in ((1.0, PETSc.SNES.ConvergedReason.CONVERGED_ITS),
                                (100.0, PETSc.SNES.ConvergedReason.DIVERGED_DTOL)):
        test = EquilibriumTest()
        test.start(9.8e-6, 1e-4)       # floor 1e-8 · 1e-4 = 1e-12
        reason = test(FakeSNES(), 0, (1.0, 0.0, 9.8e-6))
        its = 0
        while reason == PETSc.SNES.ConvergedReason.ITERATING:
            its += 1
            reason = test(FakeSNES(), its, (1.0, 1e-3, amplitude * cycle[its % 4]))
        assert reason == expected and its == test.window
