"""Newton's method for one load step: the equilibrium test and the words of a
failure (``convergence``), the library's line search (``line_search``), where
Newton starts (``start``: the predictor, the gap-closing start), one load
step's solve in its phases (``step``), and DOLFINx's ``NewtonSolver`` with the
contact's matrix (``newton_solver``, imported on first use: DOLFINx 0.10
deprecates it)."""
from importlib import import_module

from dolfinx_mortar.solver.newton.convergence import (ContactDivergenceError, EquilibriumTest,
                                                      FailedAttempt, carried_force,
                                                      describe_failure)
from dolfinx_mortar.solver.newton.line_search import FullStepFirst, library_line_search
from dolfinx_mortar.solver.newton.start import PathExtrapolation, close_gaps
from dolfinx_mortar.solver.newton.step import NewtonOutcome, StepNewton

__all__ = ["ContactDivergenceError", "EquilibriumTest", "FailedAttempt", "FullStepFirst",
           "NewtonOutcome", "NewtonSolver", "PathExtrapolation", "StepNewton", "carried_force",
           "close_gaps", "describe_failure", "library_line_search"]


def __getattr__(name: str):
    if name == "NewtonSolver":
        return import_module("dolfinx_mortar.solver.newton.newton_solver").NewtonSolver
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
