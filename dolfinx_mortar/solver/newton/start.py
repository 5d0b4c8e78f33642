"""Where Newton starts a load step: a predictor along the path, and the
gap-closing start for bodies that touch at a point."""
from __future__ import annotations

from contextlib import ExitStack
from typing import TYPE_CHECKING, Optional

from petsc4py import PETSc

if TYPE_CHECKING:
    from dolfinx_mortar.solver.nonlinear_problem import NonlinearContactProblem


class PathExtrapolation:
    """The last two converged states of a load path, and the linear predictor
    through them: ``u(t) ≈ u₁ + (t − t₁)/(t₁ − t₀)·(u₁ − u₀)``."""

    def __init__(self) -> None:
        self.states: list[tuple[float, PETSc.Vec]] = []

    def converged(self, t: float, u: PETSc.Vec) -> None:
        self.states = (self.states + [(t, u.copy())])[-2:]

    def increment(self, t: float) -> Optional[PETSc.Vec]:
        if len(self.states) < 2:
            return None
        (t0, u0), (t1, u1) = self.states
        du = u1.copy()
        du.axpy(-1.0, u0)
        du.scale((t - t1) / (t1 - t0))
        return du


def close_gaps(problem: "NonlinearContactProblem", ksp: PETSc.KSP, x: PETSc.Vec,
               A: PETSc.Mat) -> None:
    """Move x into contact when nothing touches yet (a better Newton start).

    With positive mortar functions a body that touches at a point has
    d̄ < 0 at every node, no contact force, and Newton's linear model —
    stiff only from the current gap on — creeps towards the obstacle by
    F/(εA) per iteration. This step solves the linear model in which the
    nodes near contact carry the force ``ω(d̄ + GΔu)``, which closes their
    gaps: it overshoots by about the largest of those gaps (a tenth of an
    element), which Newton then takes back. It changes only where Newton
    starts, not the solution. ``A`` is the Jacobian matrix of ``ksp``'s
    solves (with the contact pattern).
    """
    b = problem.vector()
    problem.F(x, b)
    with ExitStack() as stack:
        pulls = [stack.enter_context(term.closing_gaps()) for term in problem.contacts]
        if all(p is None for p in pulls):
            return
        problem.J(x, A, ksp)
    rhs = b.copy()
    for pull in pulls:
        if pull is not None:
            rhs.axpy(1.0, pull)
    ksp.setOperators(A)
    dx = rhs.duplicate()
    ksp.solve(rhs, dx)
    if ksp.getConvergedReason() > 0:
        x.axpy(-1.0, dx)
