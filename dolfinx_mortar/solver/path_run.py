"""One run along a load path: its load factors, what it reached, what failed,
its output.

A failed attempt halves the step (:class:`~dolfinx_mortar.solver.load_stepping.LoadStepper`)
with one warning through :mod:`logging` (logger ``dolfinx_mortar.solver.load_path``, on
rank 0) and is recorded in :attr:`SolveResult.cut_backs
<dolfinx_mortar.solver.step_results.SolveResult.cut_backs>`; too many, and
:class:`~dolfinx_mortar.solver.newton.convergence.ContactDivergenceError` names every
attempt's cause with its residual history. A converged step is recorded
(:class:`~dolfinx_mortar.solver.step_results.StepResult`), written to XDMF and handed to
the user's ``on_step``.
"""
from __future__ import annotations

import logging
from pathlib import Path
from typing import Callable, Optional, Sequence, Union

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar.io.contact_output import ContactOutput
from dolfinx_mortar.solver.load_stepping import LoadStepper
from dolfinx_mortar.solver.newton import (ContactDivergenceError, FailedAttempt,
                                          NewtonOutcome)
from dolfinx_mortar.solver.step_results import SolveResult, StepResult

# the load path's logger, as it always was
logger = logging.getLogger("dolfinx_mortar.solver.load_path")


class PathRun:
    """The record of one :meth:`LoadPathSolver.solve
    <dolfinx_mortar.solver.load_path.LoadPathSolver.solve>`.

    Parameters
    ----------
    contacts
        The problem's contact terms.
    u
        The displacement.
    stepper
        The load factors of the run.
    output, progress, on_step
        As for :meth:`LoadPathSolver.solve`.
    """

    def __init__(self, contacts: Sequence, u: fem.Function, stepper: LoadStepper,
                 output: Optional[Union[str, Path]] = None, progress: bool = False,
                 on_step: Optional[Callable[[StepResult], None]] = None):
        self._contacts, self._stepper, self._on_step = list(contacts), stepper, on_step
        self._comm: MPI.Comm = u.function_space.mesh.comm
        self._writer = ContactOutput(Path(output), u, contacts) if output is not None else None
        #: what the run returns
        self.result = SolveResult()
        # the failed attempts since the last converged step
        self._failures: list[FailedAttempt] = []
        # each term's deepest penetration over the converged steps (warned about at the end)
        self._deepest = [(-np.inf, 0.0, [])] * len(self._contacts)
        self._bar = None
        if progress and self._comm.rank == 0:
            from tqdm import tqdm
            self._bar = tqdm(total=stepper.load_steps, desc="load steps", unit="step")

    def failed(self, target: float, outcome: NewtonOutcome) -> None:
        """The attempt at load factor ``target`` failed: cut the step back, or
        raise :class:`ContactDivergenceError` where the stepper is exhausted."""
        attempt = FailedAttempt(target, outcome.reason, outcome.residuals, outcome.cause)
        self._failures.append(attempt)
        self._stepper.failed()
        if self._stepper.exhausted:
            raise ContactDivergenceError(target, self._failures)
        self.result.cut_backs.append(attempt)
        if self._comm.rank == 0:
            logger.warning("load step to t = %.6g failed after %d Newton iterations (%s); "
                           "cut back to t = %.6g", target, outcome.iterations, outcome.cause,
                           self._stepper.target())

    def converged(self, target: float, outcome: NewtonOutcome, states: Sequence,
                  wall_time: float) -> None:
        """The step to ``target`` converged with the contact ``states`` (one per
        term, at the accepted u): record, write and report it."""
        self._failures = []
        contacts = self._contacts
        self._deepest = [max(worst, term.results.penetration(state), key=lambda d: d[0])
                         for worst, term, state in zip(self._deepest, contacts, states)]
        active = sum(term.results.active_nodes(state) for term, state in zip(contacts, states))
        step = StepResult(target, outcome.iterations, outcome.residuals, wall_time, active,
                          outcome.phases, outcome.reference, outcome.linear_iterations,
                          [term.results.friction_summary(state)
                           for term, state in zip(contacts, states)])
        self.result.steps.append(step)
        before = self._stepper.fraction_of_steps
        self._stepper.succeeded()
        if self._bar is not None:
            self._bar.update(self._stepper.fraction_of_steps - before)
        if self._writer is not None:
            self._writer.write(target, states)
        if self._on_step is not None:
            self._on_step(step)

    def end(self) -> None:
        """The path reached load factor 1: each term checks the path's deepest
        penetration (collective)."""
        for term, worst in zip(self._contacts, self._deepest):
            term.check_path(worst)

    def close(self) -> None:
        """Close the progress bar (also after an error)."""
        if self._bar is not None:
            self._bar.close()
