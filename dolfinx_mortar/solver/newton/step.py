"""One load step's Newton solve: where it starts, its phases, how it ended.

With ``basis_configuration="current"`` a step is first solved with the
surface frozen where the step starts (the "previous" model: piecewise
linear, robust), then on the current surface with the exact Jacobian.
Started from the current surface directly, the first iterations overshoot
to pressures whose geometric stiffness is larger than the bulk's, and
Newton cycled or diverged (Hertz 2D).
"""
from __future__ import annotations

import math
import time
from contextlib import ExitStack
from dataclasses import dataclass
from typing import TYPE_CHECKING, Optional

from petsc4py import PETSc

from dolfinx_mortar.solver.newton.convergence import (EquilibriumTest, carried_force,
                                                      describe_failure)
from dolfinx_mortar.solver.newton.line_search import FullStepFirst
from dolfinx_mortar.solver.newton.start import close_gaps

if TYPE_CHECKING:
    from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem

_SNES = PETSc.SNES.ConvergedReason


@dataclass
class NewtonOutcome:
    """How one load step's Newton solve ended (:meth:`StepNewton.solve`)."""

    #: the SNES converged reason of the last solve (> 0: converged)
    reason: int
    #: residual norms per SNES solve (two with ``"current"``: frozen, then current surface)
    phases: list
    #: Newton iterations over all phases
    iterations: int
    #: what stopped it, in words ("" when it converged)
    cause: str
    #: the step's force scale F (the out-of-balance force where it started)
    reference: float
    #: Krylov iterations of its linear solves
    linear_iterations: int

    @property
    def converged(self) -> bool:
        return self.reason > 0

    @property
    def residuals(self) -> list:
        """Residual norms of every Newton iterate, the phases one after another."""
        return [r for phase in self.phases for r in phase]


class StepNewton:
    """The Newton solve of one load step with a load path's SNES.

    Parameters
    ----------
    problem
        The problem whose residual and Jacobian the SNES evaluates.
    equilibrium
        The SNES's convergence test.
    line_search
        The library's line search on the SNES (None: the user chose another).
    two_phases
        Whether a contact term follows u (``"current"``): a frozen phase first.
    timings
        Where the wall time inside SNES solves is added (``"snes_solve"``).
    """

    def __init__(self, problem: "NonlinearContactProblem", equilibrium: EquilibriumTest,
                 line_search: Optional[FullStepFirst], two_phases: bool,
                 timings: dict[str, float]):
        self.problem, self.equilibrium = problem, equilibrium
        self.line_search, self.two_phases, self.timings = line_search, two_phases, timings

    def solve(self, snes: PETSc.SNES, x: PETSc.Vec, A: PETSc.Mat,
              increment: Optional[PETSc.Vec] = None) -> NewtonOutcome:
        """Newton from x (plus a predictor's ``increment``), A the SNES's matrix.

        The step is accepted when ``‖R‖ ≤ rtol·F``
        (:class:`~dolfinx_mortar.solver.newton.convergence.EquilibriumTest`) with F the
        residual norm at x before the gap-closing start: the force out of
        balance when the step starts, whatever Newton starts from.
        """
        phases: list = []
        iterations = linear = 0
        reference = self._start(x, increment)
        for frozen in ([True, False] if self.two_phases else [False]):
            reason = self._phase(snes, x, A, frozen)
            phases.append([float(r) for r in snes.getConvergenceHistory()[0]])
            iterations += snes.getIterationNumber()
            linear += snes.getLinearSolveIterations()
            if reason <= 0:
                cause = describe_failure(snes, self.equilibrium, self.problem.evaluation_error)
                if self.equilibrium.cause is not None or reason == _SNES.DIVERGED_MAX_IT:
                    # Newton ran and got nowhere (not a failed linear solve or residual)
                    cause += self._contact_hint()
                return NewtonOutcome(reason, phases, iterations, cause, reference, linear)
            if frozen:
                for term in self.problem.contacts:
                    term.check_current_surface()
        return NewtonOutcome(reason, phases, iterations, "", reference, linear)

    def _start(self, x: PETSc.Vec, increment: Optional[PETSc.Vec]) -> float:
        """The step's force scale F at x; then x moved by the predictor's
        ``increment`` where the residual stays finite there."""
        b = self.problem.vector()
        self.problem.F(x, b)
        reference = self.equilibrium.step_reference(b.norm())
        self.equilibrium.start(reference, carried_force(self.problem.contacts))
        if increment is not None:
            x.axpy(1.0, increment)
            self.problem.F(x, b)
            if not math.isfinite(b.norm()):
                # the extrapolation left the law's domain (J ≤ 0 under ln J) or
                # collapsed a surface: start from the last converged state
                x.axpy(-1.0, increment)
            elif not self.two_phases:
                # the gap-closing start evaluates the same model at the same x
                # (with "current" it runs on the frozen surface: another residual)
                self.problem.line_search.offer(x, b)
        return reference

    def _phase(self, snes: PETSc.SNES, x: PETSc.Vec, A: PETSc.Mat, frozen: bool) -> int:
        """One SNES solve from x, on the frozen surfaces or not; its reason."""
        with ExitStack() as stack:
            if frozen:
                for term in self.problem.contacts:
                    stack.enter_context(term.frozen())
                if self.line_search is not None:
                    stack.enter_context(self.line_search.frozen_phase())
            close_gaps(self.problem, snes.getKSP(), x, A)
            snes.setConvergenceHistory(reset=True)
            clock = time.perf_counter()
            snes.solve(None, x)
            self.timings["snes_solve"] = (self.timings.get("snes_solve", 0.0)
                                          + time.perf_counter() - clock)
        return snes.getConvergedReason()

    def _contact_hint(self) -> str:
        """What the contact says about a failed Newton solve, from its state at
        the last iterate: nothing touching means a body that only the contact
        holds has no stiffness (collective)."""
        if self.problem.evaluation_error is not None:
            return ""
        contacts = self.problem.contacts
        # u holds the last iterate; the frozen phase's states are gone with its model
        states = [term.state if term.state is not None else term.evaluate() for term in contacts]
        if sum(term.results.active_nodes(state) for term, state in zip(contacts, states)) > 0:
            return ""
        return ("; no slave node was in contact at the last iterate: if only the contact "
                "holds the body, the load pulls it away from the master or obstacle, or "
                "nothing is within reach (check the load's sign, which surface is the "
                "slave and which the master, and the obstacle's position)")
