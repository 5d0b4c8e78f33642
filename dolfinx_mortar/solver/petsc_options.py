"""A SNES's set-up: the default PETSc options, options given per solver, the
problem's callbacks and what the contact terms need of the linear solver.

The defaults are set under the prefix unless the options database has them
(so the command line wins); options given to a solver
(``petsc_options={...}``) win over both and are removed again after its
solve, so that they do not leak into the next solver with the same prefix.
"""
from __future__ import annotations

from typing import Any, Mapping, Optional, Protocol, Sequence

from petsc4py import PETSc

from dolfinx_mortar.linalg.linear_solver import DIRECT_OPTIONS

#: PETSc options set unless the options database already has them
DEFAULT_OPTIONS = {
    "snes_type": "newtonls",
    "snes_linesearch_type": "basic",
    # relative to the out-of-balance force where the step starts
    # (dolfinx_mortar.solver.newton.convergence.EquilibriumTest)
    "snes_rtol": 1e-11,
    # absolute residuals depend on the units: rely on the relative test
    "snes_atol": 1e-15,
    # a Newton step at round-off size ends the iteration, as a failure unless
    # the residual test holds
    "snes_stol": 1e-13,
    "snes_max_it": 40,
    # the first step of a contact problem often overshoots into the obstacle
    # before the active set settles: do not call that divergence
    "snes_divergence_tolerance": -1,
    # the linear solver: MUMPS unless the solver goes iterative
    # (dolfinx_mortar.linalg.linear_solver)
    **DIRECT_OPTIONS,
}


def _as_option(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return "" if value is None else str(value)


class TemporaryOptions:
    """Options under a prefix for the duration of a ``with`` block; what they
    replaced (or their absence) is restored after it."""

    def __init__(self, prefix: str, options: Mapping[str, Any]):
        for key in options:
            if not isinstance(key, str) or key.startswith("-") or key.startswith(prefix):
                raise ValueError(f"petsc_options keys are option names without '-' and "
                                 f"without the prefix '{prefix}', got {key!r}")
        self.prefix, self.options = prefix, dict(options)
        self._saved: dict[str, Any] = {}

    def __enter__(self) -> "TemporaryOptions":
        db = PETSc.Options()
        for key, value in self.options.items():
            name = self.prefix + key
            self._saved[name] = db.getString(name) if db.hasName(name) else None
            db[name] = _as_option(value)
        return self

    def __exit__(self, *exc) -> None:
        db = PETSc.Options()
        for name, old in self._saved.items():
            if old is None:
                db.delValue(name)
            else:
                db[name] = old
        self._saved = {}


class Callbacks(Protocol):
    """What a SNES calls of a problem
    (:class:`~dolfinx_mortar.solver.nonlinear_problem.NonlinearContactProblem`)."""

    def F(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        """The residual at ``x`` into ``b``."""

    def J(self, x: PETSc.Vec, A: PETSc.Mat, ksp: Optional[PETSc.KSP] = None) -> None:
        """The Jacobian at ``x`` into ``A`` (``ksp``: the solver that will use it)."""

    def vector(self) -> PETSc.Vec:
        """The residual vector."""


def set_callbacks(snes: PETSc.SNES, problem: Callbacks, A: PETSc.Mat) -> None:
    """Give ``snes`` the problem's residual and Jacobian, with ``A`` (a matrix
    with the contact pattern) as its Jacobian matrix."""
    snes.setFunction(lambda _snes, x, b: problem.F(x, b), problem.vector())
    snes.setJacobian(lambda _snes, x, J, P: problem.J(x, J, _snes.getKSP()), A)


def configure_contact_ksp(ksp: PETSc.KSP, contacts: Sequence) -> None:
    """What the contact terms need of the linear solver (GLS kinds: the exact
    augmented step as a python PC); call after ``setFromOptions``."""
    for term in contacts:
        term.configure_ksp(ksp)
