"""The nonlinear problem (user form + contact) and the load-path driver
(``nonlinear_problem``, ``load_path``, with the record of a run: ``path_run``,
``load_stepping``, ``step_results``; a SNES's set-up: ``petsc_options``), and
Newton's method for one load step (:mod:`~dolfinx_mortar.solver.newton`).

``NewtonSolver`` (DOLFINx's, with the contact's matrix) is imported on first
use: DOLFINx 0.10 deprecates it."""
from importlib import import_module

from dolfinx_mortar.solver.load_path import LoadPathSolver
from dolfinx_mortar.solver.newton import ContactDivergenceError, FailedAttempt
from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem, reaction_force
from dolfinx_mortar.solver.step_results import SolveResult, StepResult

__all__ = ["ContactDivergenceError", "FailedAttempt", "LoadPathSolver", "NewtonSolver",
           "NonlinearContactProblem", "SolveResult", "StepResult", "reaction_force"]


def __getattr__(name: str):
    if name == "NewtonSolver":
        return import_module("dolfinx_mortar.solver.newton.newton_solver").NewtonSolver
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
