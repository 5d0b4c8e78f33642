"""DOLFINx's ``NewtonSolver`` for a contact problem, without the extra set-up.

DOLFINx 0.9's ``dolfinx.nls.petsc.NewtonSolver(comm, problem)`` makes its
Jacobian matrix from the bulk form alone; the contact stiffness needs a
matrix with the contact's pattern too (:meth:`NonlinearContactProblem.matrix`),
and the GLS kinds their exact augmented step in the linear solver
(:meth:`ContactTerm.configure_ksp <dolfinx_mortar.contact.term.ContactTerm.configure_ksp>`).
This subclass sees to both, so that code written for the 0.9-style path runs
as it is::

    problem = NonlinearContactProblem(F, u, contact, bcs)
    solver = NewtonSolver(comm, problem)
    solver.solve(u)

DOLFINx 0.10 deprecates its ``NewtonSolver`` in favour of SNES, which
:meth:`NonlinearContactProblem.solve` uses.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from dolfinx import fem
from mpi4py import MPI

from dolfinx_mortar.dolfinx_compat import newton_solver_class

if TYPE_CHECKING:
    from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem

_Base = newton_solver_class()
if _Base is None:       # pragma: no cover - a DOLFINx without NewtonSolver
    raise ImportError("this DOLFINx has no dolfinx.nls.petsc.NewtonSolver: use "
                      "NonlinearContactProblem.solve() or LoadPathSolver")


class NewtonSolver(_Base):
    """``dolfinx.nls.petsc.NewtonSolver`` with the contact problem's Jacobian matrix.

    Parameters
    ----------
    comm
        The mesh's communicator.
    problem
        The contact problem; its :meth:`~NonlinearContactProblem.F`,
        :meth:`~NonlinearContactProblem.J` and
        :meth:`~NonlinearContactProblem.form` are the callbacks.
    """

    def __init__(self, comm: MPI.Intracomm, problem: "NonlinearContactProblem"):
        super().__init__(comm, problem)
        # not in place of the base class's own matrix: its __del__ destroys that one
        self._problem = problem
        self.setJ(lambda x, A: problem.J(x, A, self.krylov_solver), problem.matrix())

    @property
    def A(self):
        """The Jacobian matrix (the problem's, with the contact pattern)."""
        return self._problem.matrix()

    def solve(self, u: fem.Function):
        """Solve from ``u``; returns DOLFINx's ``(iterations, converged)``.

        First the contact terms configure :attr:`krylov_solver` (GLS kinds:
        their exact augmented step, in place of whatever was set on it):
        here, so that the user's own settings of the KSP come before.
        """
        for term in self._problem.contacts:
            term.configure_ksp(self.krylov_solver)
        return super().solve(u)
