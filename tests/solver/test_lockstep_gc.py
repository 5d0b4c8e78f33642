"""Python's cycle collector during a solve on several ranks
(:mod:`dolfinx_mortar.solver.lockstep_gc`): DOLFINx destroys a Function's PETSc
vector when the Function is freed, and a collection on one rank alone left the
ranks in different collectives (``tools/uneven_gc_deadlock.py`` shows it hang).
Run on 1 and 2 ranks."""
from __future__ import annotations

import gc

from mpi4py import MPI

from dolfinx_mortar import RigidPlane
from support.scenes import pressed_block


def test_a_solve_collects_cycles_only_where_every_rank_is():
    """During a solve on several ranks the automatic collector is off (the
    solver collects at each load step, on every rank at once) and afterwards it
    is as it was; on one rank it is left alone."""
    problem = pressed_block(RigidPlane([0.0, 0.0], [0.0, 1.0]), "LcLS*")
    seen = []
    was = gc.isenabled()
    gc.enable()
    try:
        problem.solve(load_steps=2, on_step=lambda _, step: seen.append(gc.isenabled()))
        after = gc.isenabled()
    finally:
        if not was:
            gc.disable()
    assert seen == [MPI.COMM_WORLD.size == 1] * 2
    assert after
