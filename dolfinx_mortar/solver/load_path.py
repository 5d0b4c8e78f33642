"""The load-path driver: Newton (PETSc SNES) along the user's load path.

The user passes a function of pseudo-time ``t ∈ (0, 1]`` that updates their
own Constants and Functions — Dirichlet values, tractions, body forces, a
rigid obstacle's position (``obstacle.move_to``). Each step is solved by SNES
(options prefix ``dolfinx_mortar_`` unless told otherwise, plus the
``petsc_options`` given); a step that fails is halved and retried (one
warning through :mod:`logging` per cut-back, each recorded in
:attr:`SolveResult.cut_backs`), cut steps regrow after successes, and after
too many failures :class:`~dolfinx_mortar.solver.convergence.ContactDivergenceError`
names every attempt's cause with its residual history. Converged steps go to XDMF.
"""
from __future__ import annotations

import logging
import math
import time
from pathlib import Path
from typing import Callable, Optional, Union

import numpy as np
from petsc4py import PETSc

from dolfinx_mortar.input_checks import collective_checks, unused_petsc_options
from dolfinx_mortar.io.contact_output import ContactOutput
from dolfinx_mortar.solver.convergence import (ContactDivergenceError, EquilibriumTest,
                                               FailedAttempt, describe_failure)
from dolfinx_mortar.linalg.contact_block_pc import ContactBlockPreconditioner
from dolfinx_mortar.linalg.linear_solver import (DIRECT_OPTIONS, choose_linear_solver,
                                                 iterative_options)
from dolfinx_mortar.solver.line_search import FullStepFirst, library_line_search
from dolfinx_mortar.solver.load_stepping import LoadStepper
from dolfinx_mortar.solver.newton_start import PathExtrapolation, close_gaps
from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem
from dolfinx_mortar.solver.petsc_options import DEFAULT_OPTIONS, TemporaryOptions
from dolfinx_mortar.solver.step_results import NewtonOutcome, SolveResult, StepResult

logger = logging.getLogger(__name__)
_SNES = PETSc.SNES.ConvergedReason


class LoadPathSolver:
    """Solves a :class:`NonlinearContactProblem` along a load path.

    Parameters
    ----------
    problem
        The user's model with its contact terms.
    petsc_options
        PETSc options for this solver's SNES, KSP and PC, without the prefix
        (``{"snes_max_it": 60, "ksp_type": "preonly"}``); they take precedence
        over the options database for this solver and are removed from it
        after each solve.
    prefix
        The options prefix (command-line options ``-<prefix>snes_…`` apply).
    linear_solver
        ``"direct"`` (MUMPS), ``"iterative"`` (CG/GMRES with multigrid and an
        exact contact block) or ``"auto"`` (iterative for large 3D problems;
        :mod:`dolfinx_mortar.linalg.linear_solver`). Options under the prefix
        still override each choice.
    """

    def __init__(self, problem: NonlinearContactProblem,
                 petsc_options: Optional[dict] = None, prefix: str = "dolfinx_mortar_",
                 linear_solver: str = "auto"):
        self.problem = problem
        self.prefix = prefix
        augmented = any(term.traits.takes_the_linear_solve for term in problem.contacts)
        gdim = problem.u.function_space.mesh.geometry.dim
        #: "direct" or "iterative", as chosen for this problem
        self.linear_solver = choose_linear_solver(linear_solver, problem.num_dofs, gdim,
                                                  augmented)
        #: the iterative path's preconditioner, once made
        self.preconditioner: Optional[ContactBlockPreconditioner] = None
        self.petsc_options = dict(petsc_options or {})
        self.comm = problem.u.function_space.mesh.comm
        self.equilibrium = EquilibriumTest()
        self._options_checked = False
        #: which options the user set in the database when solve() began
        self._user_options: dict[str, bool] = {}
        #: wall time (s) inside SNES solves, callbacks included (accumulated)
        self.timings: dict[str, float] = {}
        #: the line search of the last :meth:`create_snes` (None where the user
        #: chose one: :meth:`library_line_search`)
        self.line_search: Optional[FullStepFirst] = None

    @property
    def contacts(self):
        return self.problem.contacts

    def default_options(self) -> dict:
        """The solver's defaults (:data:`DEFAULT_OPTIONS`), with the iterative
        linear solver's options where it was chosen.

        The line search is ``basic`` with
        :class:`~dolfinx_mortar.solver.line_search.FullStepFirst` as its
        pre-check, unless the user chose a line search (:meth:`library_line_search`).
        """
        defaults = dict(DEFAULT_OPTIONS)
        if self.linear_solver == "iterative":
            for key in DIRECT_OPTIONS:
                defaults.pop(key)
            defaults.update(iterative_options(self.problem.symmetric))
        return defaults

    def options(self) -> TemporaryOptions:
        """This solver's options in the database for the duration of a ``with``
        block: its defaults where the database does not set them, then
        ``petsc_options``. Nothing stays behind, so that no later solver takes
        these for options of its own."""
        db = PETSc.Options()
        merged = {key: value for key, value in self.default_options().items()
                  if not db.hasName(self.prefix + key)}
        merged.update(self.petsc_options)
        return TemporaryOptions(self.prefix, merged)

    def create_snes(self) -> PETSc.SNES:
        """A SNES with the problem's callbacks, configured from the options
        database (inside :meth:`options` for this solver's own)."""
        snes = PETSc.SNES().create(self.comm)
        snes.setOptionsPrefix(self.prefix)
        self.problem.configure_snes(snes)
        snes.setConvergenceHistory()
        self._configure_from_options(snes)
        self.line_search = (library_line_search(self.problem, snes)
                            if self.library_line_search() else None)
        return snes

    def _configure_from_options(self, snes: PETSc.SNES) -> None:
        """Read the options database into ``snes``, then put back what the
        solver sets in code (the convergence test, the preconditioners)."""
        snes.setFromOptions()
        snes.setConvergenceTest(self.equilibrium)
        self._configure_preconditioner(snes.getKSP())
        self.problem.configure_ksp(snes.getKSP())

    def library_line_search(self) -> bool:
        """Whether the library's line search
        (:class:`~dolfinx_mortar.solver.line_search.FullStepFirst`) runs: the
        user set no ``snes_linesearch_type``.

        It halves steps whose residual is not finite (a finite-strain law past
        J = 0) in every phase, and shortens full steps that do not lower
        ``‖F‖`` to ``l2``'s length on the current surface (the second phase of
        a ``"current"`` step) and, for a bulk law that is nonlinear in u, in
        every phase (:attr:`shortens_frozen_steps`).
        """
        key = "snes_linesearch_type"
        return not (key in self.petsc_options or self._user_options.get(key, False))

    @property
    def shortens_frozen_steps(self) -> bool:
        """Whether the line search shortens steps on frozen surfaces too: the
        bulk residual is nonlinear in u.

        A frozen surface is the piecewise-linear "previous" model. With a
        linear bulk, shortened steps only slowed the active set down (Newton
        iterations, full steps against shortened ones: Hertz 2D 22 against 28,
        with an elastic block 23/33, Hertz 3D 16/24); a neo-Hookean bulk
        needs them (a disk pressed into a block and slid sideways, 12 steps
        requested: 12 steps and no cut-back against 24 steps and 7
        cut-backs; ironing 2D 800 against 1387 Newton iterations).
        """
        return not self.problem.bulk_is_linear

    @property
    def current(self) -> bool:
        """Whether a contact term uses the current configuration (two phases per step)."""
        return self.problem.current

    def _configure_preconditioner(self, ksp: PETSc.KSP) -> None:
        """The contact-block preconditioner for ``pc_type python`` (the
        iterative default) and the rigid-body modes for multigrid."""
        pc = ksp.getPC()
        if pc.getType() == "gamg":
            self.problem.attach_near_nullspace = True
            self.problem.matrix().setNearNullSpace(self.problem.near_nullspace())
        if pc.getType() == "python" and self.linear_solver == "iterative":
            if self.preconditioner is None:
                self.preconditioner = ContactBlockPreconditioner(
                    self.problem.contact_rows, self.prefix, self.problem.near_nullspace)
            pc.setPythonContext(self.preconditioner)

    def solve(self, update: Callable[[float], None], load_steps: int = 1,
              output: Optional[Union[str, Path]] = None, max_cuts: int = 5,
              progress: bool = False,
              on_step: Optional[Callable[[StepResult], None]] = None,
              predictor: str = "none") -> SolveResult:
        """Follow the load path from t = 0 to 1 in ``load_steps`` steps.

        Parameters
        ----------
        update
            ``update(t)`` sets the user's Constants, Functions and obstacles to
            pseudo-time t (it is called again with a smaller t after a cut).
        load_steps
            Equal steps when nothing fails (a positive integer).
        output
            XDMF path of every converged step (:mod:`dolfinx_mortar.io.contact_output`).
        max_cuts
            Failures in a row before :class:`ContactDivergenceError`.
        progress
            A tqdm progress bar on rank 0.
        on_step
            Called with each converged step's :class:`StepResult`.
        predictor
            Where Newton starts a step: ``"none"`` from the last converged u,
            ``"linear"`` from u extrapolated linearly in t through the last
            two converged steps (fewer iterations on a smooth path such as a
            sliding obstacle; a kink of the path costs one poor start).
        """
        if predictor not in ("none", "linear"):
            raise ValueError(f"predictor must be 'none' or 'linear', not {predictor!r}")
        stepper = LoadStepper(load_steps, max_cuts)
        self.equilibrium.force_scale = 0.0
        u = self.problem.u
        with collective_checks(self.comm):
            if not np.all(np.isfinite(u.x.array)):
                raise ValueError("the displacement contains NaN or infinite values")
        writer = ContactOutput(Path(output), u, self.contacts) if output is not None else None
        result = SolveResult()
        failures: list[FailedAttempt] = []
        # each term's deepest penetration over the converged steps (warned about at the end)
        deepest = [(-np.inf, 0.0, [])] * len(self.contacts)
        path = PathExtrapolation() if predictor == "linear" else None
        bar = None
        if progress and self.comm.rank == 0:
            from tqdm import tqdm
            bar = tqdm(total=stepper.load_steps, desc="load steps", unit="step")
        db = PETSc.Options()
        self._user_options = {"snes_linesearch_type":
                              db.hasName(self.prefix + "snes_linesearch_type")}
        with self.options():
            self._options_checked = False
            snes = self.create_snes()
            try:
                while not stepper.done:
                    target = stepper.target()
                    update(target)
                    if any([term.begin_step() for term in self.contacts]):
                        snes.setJacobian(lambda _s, x, A, P: self.problem.J(x, A, _s.getKSP()),
                                         self.problem.refresh_matrix())
                    saved = u.x.petsc_vec.copy()
                    clock = time.perf_counter()
                    x = u.x.petsc_vec.copy()
                    increment = path.increment(target) if path is not None else None
                    outcome = self.newton_step(snes, x, increment)
                    if not outcome.converged:
                        attempt = FailedAttempt(target, outcome.reason, outcome.residuals,
                                                outcome.cause)
                        failures.append(attempt)
                        stepper.failed()
                        if stepper.exhausted:
                            raise ContactDivergenceError(target, failures)
                        result.cut_backs.append(attempt)
                        if self.comm.rank == 0:
                            logger.warning("load step to t = %.6g failed after %d Newton "
                                           "iterations (%s); cut back to t = %.6g",
                                           target, outcome.iterations, outcome.cause,
                                           stepper.target())
                        saved.copy(u.x.petsc_vec)
                        u.x.scatter_forward()
                        continue
                    failures = []
                    x.copy(u.x.petsc_vec)
                    u.x.scatter_forward()
                    states = [term.evaluate() for term in self.contacts]
                    if any([term.widen_search_radius(state)
                            for term, state in zip(self.contacts, states)]):
                        # the bases were cut off by the search radius: the same step again
                        saved.copy(u.x.petsc_vec)
                        u.x.scatter_forward()
                        snes.setJacobian(lambda _s, x, A, P: self.problem.J(x, A, _s.getKSP()),
                                         self.problem.refresh_matrix())
                        continue
                    for term, state in zip(self.contacts, states):
                        term.accept_step(state)
                    if path is not None:
                        path.converged(target, u.x.petsc_vec)
                    deepest = [max(worst, term.results.penetration(state), key=lambda d: d[0])
                               for worst, term, state in zip(deepest, self.contacts, states)]
                    active = sum(t.results.active_nodes(s) for t, s in zip(self.contacts, states))
                    step = StepResult(target, outcome.iterations, outcome.residuals,
                                      time.perf_counter() - clock, active, outcome.phases,
                                      outcome.reference, outcome.linear_iterations,
                                      [t.results.friction_summary(s)
                                       for t, s in zip(self.contacts, states)])
                    result.steps.append(step)
                    before = stepper.fraction_of_steps
                    stepper.succeeded()
                    if bar is not None:
                        bar.update(stepper.fraction_of_steps - before)
                    if writer is not None:
                        writer.write(target, states)
                    if on_step is not None:
                        on_step(step)
                for term, worst in zip(self.contacts, deepest):
                    term.check_path(worst)
            finally:
                if bar is not None:
                    bar.close()
                snes.destroy()
        return result

    def newton_step(self, snes: PETSc.SNES, x: PETSc.Vec,
                    increment: Optional[PETSc.Vec] = None) -> NewtonOutcome:
        """One load step's Newton solve from x (plus a predictor's ``increment``).

        The step is accepted when ``‖R‖ ≤ rtol·F``
        (:class:`~dolfinx_mortar.solver.convergence.EquilibriumTest`) with F the
        residual norm at x before the gap-closing start: the force out of
        balance when the step starts, whatever Newton starts from.

        With ``basis_configuration="current"`` the step is first solved with
        the surface frozen where the step starts (the "previous" model:
        piecewise linear, robust), then on the current surface with the exact
        Jacobian. Started from the current surface directly, the first
        iterations overshoot to pressures whose geometric stiffness is larger
        than the bulk's, and Newton cycled or diverged (Hertz 2D).
        """
        phases: list = []
        iterations = linear = 0
        b = self.problem.vector()
        self.problem.F(x, b)
        reference = self.equilibrium.step_reference(b.norm())
        self.equilibrium.start(reference, self.problem.carried_force())
        if increment is not None:
            x.axpy(1.0, increment)
            self.problem.F(x, b)
            if not math.isfinite(b.norm()):
                # the extrapolation left the law's domain (J ≤ 0 under ln J) or
                # collapsed a surface: start from the last converged state
                x.axpy(-1.0, increment)
            elif not self.current:
                # the gap-closing start evaluates the same model at the same x
                # (with "current" it runs on the frozen surface: another residual)
                self.problem.offer_residual(x, b)
        for frozen in ([True, False] if self.current else [False]):
            reason = self._solve_phase(snes, x, frozen)
            phases.append([float(r) for r in snes.getConvergenceHistory()[0]])
            iterations += snes.getIterationNumber()
            linear += snes.getLinearSolveIterations()
            if reason <= 0:
                cause = describe_failure(snes, self.equilibrium, self.problem.evaluation_error)
                if self.equilibrium.cause is not None or reason == _SNES.DIVERGED_MAX_IT:
                    # Newton ran and got nowhere (not a failed linear solve or residual)
                    cause += self._contact_hint()
                return NewtonOutcome(reason, phases, iterations, cause, reference, linear)
        return NewtonOutcome(reason, phases, iterations, "", reference, linear)

    def _contact_hint(self) -> str:
        """What the contact says about a failed Newton solve, from its state at
        the last iterate: nothing touching means a body that only the contact
        holds has no stiffness (collective)."""
        if self.problem.evaluation_error is not None:
            return ""
        # u holds the last iterate; the frozen phase's states are gone with its model
        states = [term.state if term.state is not None else term.evaluate()
                  for term in self.contacts]
        if sum(term.results.active_nodes(state) for term, state in zip(self.contacts, states)) > 0:
            return ""
        return ("; no slave node was in contact at the last iterate: if only the contact "
                "holds the body, the load pulls it away from the master or obstacle, or "
                "nothing is within reach (check the load's sign, which surface is the "
                "slave and which the master, and the obstacle's position)")

    def _solve_phase(self, snes: PETSc.SNES, x: PETSc.Vec, frozen: bool) -> int:
        from contextlib import ExitStack
        with ExitStack() as stack:
            if frozen:
                for term in self.contacts:
                    stack.enter_context(term.frozen())
            if frozen and self.line_search is not None and not self.shortens_frozen_steps:
                stack.enter_context(self.line_search.full_steps_only())
            close_gaps(self.problem, snes.getKSP(), x)
            snes.setConvergenceHistory(reset=True)
            clock = time.perf_counter()
            snes.solve(None, x)
            self.timings["snes_solve"] = (self.timings.get("snes_solve", 0.0)
                                          + time.perf_counter() - clock)
        if not self._options_checked:
            # every option is read by the first solve: once per solve() is enough
            self._check_petsc_options()
            self._options_checked = True
        return snes.getConvergedReason()

    def _check_petsc_options(self) -> None:
        """Refuse options under the prefix that no PETSc object read (misspelled)."""
        unused = unused_petsc_options(self.prefix,
                                      ignore={**DEFAULT_OPTIONS, **iterative_options(True)})
        if unused:
            raise ValueError(f"PETSc option(s) {', '.join(unused)} were set but not used by "
                             f"any solver of this problem: misspelled, or meant for another "
                             f"prefix? (options prefix '{self.prefix}')")
