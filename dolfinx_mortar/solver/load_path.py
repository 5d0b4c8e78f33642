"""The load-path driver: Newton (PETSc SNES) along the user's load path.

The user passes a function of pseudo-time ``t ∈ (0, 1]`` that updates their
own Constants and Functions — Dirichlet values, tractions, body forces, a
rigid obstacle's position (``obstacle.move_to``). Each step is solved by SNES
(options prefix ``dolfinx_mortar_`` unless told otherwise, plus the
``petsc_options`` given); a step that fails is halved and retried (one
warning through :mod:`logging` per cut-back, each recorded in
:attr:`SolveResult.cut_backs`), cut steps regrow after successes, and after
too many failures :class:`~dolfinx_mortar.solver.newton.convergence.ContactDivergenceError`
names every attempt's cause with its residual history (:mod:`~dolfinx_mortar.solver.path_run`).
Converged steps go to XDMF.
"""
from __future__ import annotations

import time
from pathlib import Path
from typing import Callable, Optional, Union

import numpy as np
from petsc4py import PETSc

from dolfinx_mortar.input_checks import collective_checks, unused_petsc_options
from dolfinx_mortar.linalg.contact_block_pc import ContactBlockPreconditioner
from dolfinx_mortar.linalg.linear_solver import (DIRECT_OPTIONS, choose_linear_solver,
                                                 iterative_options)
from dolfinx_mortar.linalg.near_nullspace import RigidModes
from dolfinx_mortar.solver.load_stepping import LoadStepper
from dolfinx_mortar.solver.lockstep_gc import collect_in_lockstep, lockstep_garbage_collection
from dolfinx_mortar.solver.newton import (EquilibriumTest, FullStepFirst, PathExtrapolation,
                                          StepNewton)
from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem, contact_matrix
from dolfinx_mortar.solver.path_run import PathRun
from dolfinx_mortar.solver.petsc_options import (DEFAULT_OPTIONS, TemporaryOptions,
                                                 configure_contact_ksp, set_callbacks)
from dolfinx_mortar.solver.step_results import SolveResult, StepResult

__all__ = ["LoadPathSolver", "SolveResult", "StepResult"]


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
        #: the problem solved
        self.problem = problem
        #: the options prefix
        self.prefix = prefix
        traits = [term.traits for term in problem.contacts]
        self._two_phases = any(t.follows_u for t in traits)
        self._symmetric = all(t.symmetric for t in traits)
        V = problem.u.function_space
        num_dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
        #: "direct" or "iterative", as chosen for this problem
        self.linear_solver = choose_linear_solver(
            linear_solver, num_dofs, V.mesh.geometry.dim,
            any(t.takes_the_linear_solve for t in traits))
        #: this solver's PETSc options (without the prefix)
        self.petsc_options = dict(petsc_options or {})
        self._comm = V.mesh.comm
        self._equilibrium = EquilibriumTest()
        self._rigid_modes = RigidModes(V)
        # the iterative path's preconditioner, once made
        self._preconditioner: Optional[ContactBlockPreconditioner] = None
        # the Jacobian matrix of the SNES (made again when the contact pattern changes)
        self._A: Optional[PETSc.Mat] = None
        self._gamg = False
        self._options_checked = False
        # which options the user set in the database when solve() began
        self._user_options: dict[str, bool] = {}
        #: wall time (s) inside SNES solves, callbacks included (accumulated)
        self.timings: dict[str, float] = {}
        #: the library's line search on the SNES of the last :meth:`create_snes`
        #: (the problem's, :attr:`NonlinearContactProblem.line_search`), None
        #: where the options choose another (``snes_linesearch_type``)
        self.line_search: Optional[FullStepFirst] = None

    def default_options(self) -> dict:
        """The solver's defaults (:data:`DEFAULT_OPTIONS`), with the iterative
        linear solver's options where it was chosen.

        The line search is ``basic`` with
        :class:`~dolfinx_mortar.solver.newton.line_search.FullStepFirst` as its
        pre-check, unless the user chose a line search (``snes_linesearch_type``).
        """
        defaults = dict(DEFAULT_OPTIONS)
        if self.linear_solver == "iterative":
            for key in DIRECT_OPTIONS:
                defaults.pop(key)
            defaults.update(iterative_options(self._symmetric))
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
        database (inside :meth:`options` for this solver's own): what
        :meth:`solve` solves each load step with."""
        snes = PETSc.SNES().create(self._comm)
        snes.setOptionsPrefix(self.prefix)
        set_callbacks(snes, self.problem, self._matrix())
        snes.setConvergenceHistory()
        snes.setFromOptions()
        snes.setConvergenceTest(self._equilibrium)
        self._configure_preconditioner(snes.getKSP())
        configure_contact_ksp(snes.getKSP(), self.problem.contacts)
        key = "snes_linesearch_type"
        chosen = key in self.petsc_options or self._user_options.get(key, False)
        self.line_search = None if chosen else self.problem.line_search
        if self.line_search is not None:
            self.line_search.attach(snes, round_off=self._equilibrium.floor)
        return snes

    def _matrix(self, new: bool = False) -> PETSc.Mat:
        """The SNES's Jacobian matrix (``new``: made again, the contact pattern
        changed), with the rigid-body modes where GAMG needs them."""
        if new and self._A is not None:
            self._A.destroy()
            self._A = None
        if self._A is None:
            self._A = contact_matrix(self.problem.a, self.problem.bcs, self.problem.contacts)
            if self._gamg:
                self._A.setNearNullSpace(self._rigid_modes.near_nullspace())
        return self._A

    def _configure_preconditioner(self, ksp: PETSc.KSP) -> None:
        """The contact-block preconditioner for ``pc_type python`` (the
        iterative default) and the rigid-body modes for multigrid."""
        pc = ksp.getPC()
        if pc.getType() == "gamg":
            self._gamg = True
            self._matrix().setNearNullSpace(self._rigid_modes.near_nullspace())
        if pc.getType() == "python" and self.linear_solver == "iterative":
            if self._preconditioner is None:
                self._preconditioner = ContactBlockPreconditioner(
                    self.prefix, self._rigid_modes.near_nullspace)
            pc.setPythonContext(self._preconditioner)

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
        self._equilibrium.force_scale = 0.0
        u = self.problem.u
        with collective_checks(self._comm):
            if not np.all(np.isfinite(u.x.array)):
                raise ValueError("the displacement contains NaN or infinite values")
        run = PathRun(self.problem.contacts, u, stepper, output, progress, on_step)
        path = PathExtrapolation() if predictor == "linear" else None
        self._user_options = {"snes_linesearch_type": PETSc.Options().hasName(
            self.prefix + "snes_linesearch_type")}
        # the cycle collector runs only where every rank is (lockstep_gc: a
        # Function freed on one rank only deadlocked the next PETSc object)
        with self.options(), lockstep_garbage_collection(self._comm):
            self._options_checked = False
            snes = self.create_snes()
            newton = StepNewton(self.problem, self._equilibrium, self.line_search,
                                self._two_phases, self.timings)
            try:
                while not stepper.done:
                    self._attempt(snes, newton, update, stepper.target(), run, path)
                run.end()
            finally:
                run.close()
                snes.destroy()
        return run.result

    def _attempt(self, snes: PETSc.SNES, newton: StepNewton, update: Callable[[float], None],
                 target: float, run: PathRun, path: Optional[PathExtrapolation]) -> None:
        """One attempt at the load step to ``target``: converged and accepted,
        solved again (a wider search radius), or cut back."""
        collect_in_lockstep(self._comm)
        update(target)
        if any([term.begin_step() for term in self.problem.contacts]):
            # the bases were rebuilt: the contact pattern may have changed
            set_callbacks(snes, self.problem, self._matrix(new=True))
        u = self.problem.u
        saved = u.x.petsc_vec.copy()
        clock = time.perf_counter()
        x = u.x.petsc_vec.copy()
        increment = path.increment(target) if path is not None else None
        try:
            outcome = newton.solve(snes, x, self._A, increment)
            self._check_petsc_options_once()
            if not outcome.converged:
                run.failed(target, outcome)
                _restore(u, saved)
                return
            states = self._accepted(snes, x, saved)
            if states is None:
                return
            if path is not None:
                path.converged(target, u.x.petsc_vec)
            run.converged(target, outcome, states, time.perf_counter() - clock)
        finally:
            for vector in (saved, x, increment):
                if vector is not None:
                    vector.destroy()

    def _accepted(self, snes: PETSc.SNES, x: PETSc.Vec, saved: PETSc.Vec) -> Optional[list]:
        """The converged ``x`` made u, and the contact states at it, one per
        term; or None: a term widened its search radius (the bases were cut
        off by it), u is back at ``saved`` and the step must be solved again."""
        u = self.problem.u
        x.copy(u.x.petsc_vec)
        u.x.scatter_forward()
        contacts = self.problem.contacts
        states = [term.evaluate() for term in contacts]
        if any([term.widen_search_radius(state) for term, state in zip(contacts, states)]):
            _restore(u, saved)
            set_callbacks(snes, self.problem, self._matrix(new=True))
            return None
        for term, state in zip(contacts, states):
            term.accept_step(state)
        return states

    def _check_petsc_options_once(self) -> None:
        """Refuse options under the prefix that no PETSc object read
        (misspelled), once per :meth:`solve`: every option is read by its
        first SNES solve."""
        if self._options_checked:
            return
        self._options_checked = True
        unused = unused_petsc_options(self.prefix,
                                      ignore={**DEFAULT_OPTIONS, **iterative_options(True)})
        if unused:
            raise ValueError(f"PETSc option(s) {', '.join(unused)} were set but not used by "
                             f"any solver of this problem: misspelled, or meant for another "
                             f"prefix? (options prefix '{self.prefix}')")


def _restore(u, saved: PETSc.Vec) -> None:
    """u back at ``saved`` (a failed or repeated step)."""
    saved.copy(u.x.petsc_vec)
    u.x.scatter_forward()
