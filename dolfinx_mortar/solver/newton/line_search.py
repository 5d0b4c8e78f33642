"""The library's line search: the full Newton step when it lowers the
residual norm, PETSc's ``l2`` step length otherwise, and never a step to a
point where the residual is not finite.

PETSc's ``l2`` line search evaluates the residual three times per Newton
iteration (at λ = 1, at λ = 1/2 and at its secant minimizer), also where the
full step is as good. On the current surface each evaluation repeats the
segmentation and the gradient Jets, and these evaluations were two thirds of
the contact work of a Newton iteration (Hertz 3D, two bodies, 52k dofs: 28
evaluations for 8 Jacobians). ``basic`` (full steps only) diverged or cycled
where a node at the contact edge changes state, and ``bt`` shrank its steps
there. :class:`FullStepFirst` keeps ``l2``'s answer for such steps and takes
the full step, at the cost of one evaluation, when it already lowers ``‖F‖``.

Where ``l2``'s length would be a step at round-off while ``‖F‖`` is above
the convergence test's round-off floor, it takes the full step uphill
instead (:meth:`FullStepFirst._stagnates`): a node held open a hair from
contact, which the Jacobian does not stiffen, stalled Newton otherwise.

Where the full step only needs to stay finite (frozen surfaces under a bulk
law that is linear in u), it takes full steps and halves a step whose
residual is NaN or infinite: a finite-strain law with
``ln J`` is not defined past J = 0, and ``basic`` ended such steps in
``DIVERGED_FUNCTION_NANORINF`` (a neo-Hookean block pressed and slid by a
rigid disk: 72 steps and 60 cut-backs for the 12 requested).

petsc4py cannot define a line search in Python; this one runs as the
pre-check of the ``basic`` line search, which then takes ``x − y`` with the
direction ``y`` the pre-check scaled. The accepted trial residual is offered
to the next residual evaluation (:meth:`FullStepFirst.offer`: the problem's
``F`` asks :meth:`FullStepFirst.take_offer` first), which is the basic line
search's, at the same point: a full step costs no evaluation more than ``basic``.
"""
from __future__ import annotations

import math
from contextlib import contextmanager
from typing import TYPE_CHECKING, Callable, Iterator, Optional, Protocol, Sequence

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

if TYPE_CHECKING:
    from dolfinx_mortar.contact.newton import NewtonTraits

#: sufficient decrease of ``‖F‖²`` for the full step, as in PETSc's ``bt``:
#: ``‖F(x − y)‖² ≤ (1 − 2α) ‖F(x)‖²``
SUFFICIENT_DECREASE = 1e-4
#: PETSc's ``snes_linesearch_minlambda`` and ``snes_linesearch_maxstep`` defaults,
#: the bounds of ``l2``'s step length
MIN_LAMBDA, MAX_STEP = 1e-12, 1e8
#: halvings of a step whose residual is not finite before the step is given up
#: (2⁻¹⁰ of the Newton step; then the basic line search fails and the load
#: step is cut back)
MAX_HALVINGS = 10


def l2_step_length(f0: float, f_mid: float, f1: float) -> float:
    """PETSc ``l2``'s step length from ``‖F‖²`` at λ = 0, 1/2 and 1.

    One secant step on the derivative of the parabola through the three
    values, taken from λ = 1 and always downhill; 1/2 when it falls below
    the minimum step, 1 when it is not finite or too long (``l2`` then keeps
    its initial λ).
    """
    slope_at_1 = 3.0 * f1 - 4.0 * f_mid + f0
    slope_at_0 = -3.0 * f0 + 4.0 * f_mid - f1
    curvature = slope_at_1 - slope_at_0
    if curvature > 0.0:
        step = 1.0 - slope_at_1 / curvature
    else:
        step = 1.0 + slope_at_1 / curvature
    if step < MIN_LAMBDA:
        step = 0.5
    if not math.isfinite(step) or step > MAX_STEP:
        return 1.0
    return step


class Residual(Protocol):
    """What the line search needs of the problem whose steps it checks
    (:class:`~dolfinx_mortar.solver.nonlinear_problem.NonlinearContactProblem`)."""

    def F(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        """Assemble the residual at ``x`` into ``b``."""

    def vector(self) -> PETSc.Vec:
        """A residual vector."""


class FullStepFirst:
    """SNES line-search pre-check: the full step if it lowers ``‖F‖`` enough,
    else the step length of PETSc's ``l2``; a step whose residual is not
    finite is halved first (see the module).

    One per problem: it may be attached to several SNES in turn (the
    problem's own, a load path's), and its counts add up over all of them.

    Parameters
    ----------
    problem
        The problem whose residual SNES evaluates (:class:`Residual`).
    shorten
        Whether a finite full step that does not lower ``‖F‖`` enough is
        shortened to ``l2``'s length; otherwise only steps to non-finite
        residuals are shortened (:meth:`full_steps_only`).
    shortens_frozen_steps
        Whether it shortens steps on frozen surfaces too (:meth:`frozen_phase`).

    Attributes
    ----------
    full_steps, cut_steps, halved_steps
        How many steps it took in full, how many it shortened to ``l2``'s
        length, and how many it halved because the residual was not finite.
    kink_steps
        How many full steps it took uphill because ``l2``'s length was at
        round-off while ``‖F‖`` was not (a node a hair from contact; see the
        module).
    """

    def __init__(self, problem: Residual, shorten: bool = True,
                 shortens_frozen_steps: bool = True):
        self.problem = problem
        self.full_steps = self.cut_steps = self.halved_steps = self.kink_steps = 0
        self.shorten = shorten
        # the residual norm at which a step at round-off is an equilibrium
        # (the convergence test's floor), per attached SNES
        self._round_off: Callable[[], float] = lambda: 0.0
        #: whether it shortens steps on frozen surfaces (:meth:`frozen_phase`)
        self.shortens_frozen_steps = shortens_frozen_steps
        self._offered: Optional[tuple[np.ndarray, PETSc.Vec]] = None

    def attach(self, snes: PETSc.SNES, round_off: Optional[Callable[[], float]] = None
               ) -> None:
        """Run as the pre-check of ``snes``'s line search (which must be ``basic``).

        ``round_off`` gives the residual norm below which ``snes``'s
        convergence test accepts a step at round-off as an equilibrium
        (:meth:`EquilibriumTest.floor
        <dolfinx_mortar.solver.newton.convergence.EquilibriumTest.floor>`);
        none: ``snes_atol``."""
        self._round_off = round_off or (lambda: snes.getTolerances()[1])
        snes.setLineSearchPreCheck(self, args=(snes,))

    @contextmanager
    def full_steps_only(self) -> Iterator[None]:
        """Inside the ``with`` block, full steps unless their residual is not finite.

        The pre-check stays attached: SNESLineSearchSetPreCheck ignores NULL
        arguments, so ``setLineSearchPreCheck(None)`` leaves PETSc calling back
        into the freed Python context (a SEGV on the next solve with PETSc
        3.18 and 3.22, a Python error with 3.25).
        """
        shorten, self.shorten = self.shorten, False
        try:
            yield
        finally:
            self.shorten = shorten

    @contextmanager
    def frozen_phase(self) -> Iterator[None]:
        """Inside the ``with`` block, the rule of a phase on frozen surfaces:
        full steps unless their residual is not finite, except where
        :attr:`shortens_frozen_steps` (a bulk law nonlinear in u, or friction).

        A frozen surface is the piecewise-linear "previous" model. With a
        linear bulk, shortened steps only slowed the active set down (Newton
        iterations, full steps against shortened ones: Hertz 2D 22 against 28,
        with an elastic block 23/33, Hertz 3D 16/24); a neo-Hookean bulk
        needs them (a disk pressed into a block and slid sideways, 12 steps
        requested: 12 steps and no cut-back against 24 steps and 7
        cut-backs; ironing 2D 800 against 1387 Newton iterations). So does
        friction, as on frozen surfaces elsewhere: with full steps the frozen
        phase of LmLS* on a stack of blocks sheared in self-contact cycled at
        half the step's force, and the slip limit at tan α = 0.5, μ = 0.1
        with LcLS* stalled at every cut-back (docs/FRICTION.md).
        """
        if self.shortens_frozen_steps:
            yield
            return
        with self.full_steps_only():
            yield

    # -- the residual evaluated ahead ----------------------------------------------------
    def offer(self, x: PETSc.Vec, b: PETSc.Vec) -> None:
        """Offer the residual ``b`` just assembled at ``x`` to the problem's next ``F``.

        That call copies it instead of assembling again if its point equals
        ``x`` bit for bit on every rank (:meth:`take_offer`); any other point,
        or any later call, assembles as usual. For an evaluation of a point
        made before the solver's own evaluation of the same point, with
        nothing in between that could change the residual (this pre-check, a
        predictor). Collective: every rank offers, or none.
        """
        self._offered = (x.array_r.copy(), b.copy())

    def take_offer(self, x: PETSc.Vec, b: PETSc.Vec) -> bool:
        """Copy the offered residual into ``b`` if it was made at ``x``; the
        offer is gone either way (collective)."""
        offered, self._offered = self._offered, None
        if offered is None:        # on every rank: offers are collective
            return False
        point, residual = offered
        same = x.getComm().tompi4py().allreduce(np.array_equal(point, x.array_r), op=MPI.LAND)
        if same:
            residual.copy(b)
        residual.destroy()
        return same

    # -- the pre-check ---------------------------------------------------------------------
    def _squared_norm_at(self, x: PETSc.Vec, y: PETSc.Vec, step: float,
                         point: PETSc.Vec, residual: PETSc.Vec) -> float:
        point.waxpy(-step, y, x)       # the basic line search's own operation
        self.problem.F(point, residual)
        return residual.norm() ** 2

    def __call__(self, x: PETSc.Vec, y: PETSc.Vec, snes: PETSc.SNES) -> bool:
        """The pre-check of ``snes`` at the iterate ``x`` with the Newton
        direction ``y`` (the basic line search then takes ``x − y``); returns
        whether it scaled ``y``."""
        f0 = snes.getFunctionNorm() ** 2
        point, residual = x.duplicate(), self.problem.vector().duplicate()
        try:
            f1 = self._squared_norm_at(x, y, 1.0, point, residual)
            halvings = 0
            while not math.isfinite(f1) and halvings < MAX_HALVINGS:
                # halving is exact in floating point: the basic line search's
                # x − y is this point bit for bit, and takes the offer below
                y.scale(0.5)
                halvings += 1
                f1 = self._squared_norm_at(x, y, 1.0, point, residual)
            self.halved_steps += halvings > 0
            if not math.isfinite(f1):
                return halvings > 0     # basic fails on it: the load step is cut back
            if not self.shorten or f1 <= (1.0 - 2.0 * SUFFICIENT_DECREASE) * f0:
                self.full_steps += halvings == 0
                self.offer(point, residual)
                return halvings > 0
            # the midpoint in vectors of its own: an uphill full step (below)
            # offers the full step's residual, evaluated once
            mid_point, mid_residual = point.duplicate(), residual.duplicate()
            try:
                f_mid = self._squared_norm_at(x, y, 0.5, mid_point, mid_residual)
            finally:
                mid_point.destroy()
                mid_residual.destroy()
            step = l2_step_length(f0, f_mid, f1)
            if self._stagnates(snes, x, y, step, f0):
                self.kink_steps += 1
                self.offer(point, residual)
                return halvings > 0
            self.cut_steps += 1
            y.scale(step)
            return True
        finally:
            point.destroy()
            residual.destroy()

    def _stagnates(self, snes: PETSc.SNES, x: PETSc.Vec, y: PETSc.Vec, step: float,
                   f0: float) -> bool:
        """Whether ``l2``'s ``step`` is at round-off (``step·‖y‖ ≤ stol·‖x‖``)
        while ``‖F‖`` is above round-off: then the full step is taken uphill.

        Such a step ends the Newton solve (the convergence test's "Newton step
        at round-off"). It happens where a node sits on the kink of ⟨y⟩ on the
        open side, a hair from contact: the Jacobian has no contact stiffness
        there, the Newton step pushes the node deep into penetration, and
        ``‖F‖`` along it is least at the kink, where the iterate already is.
        The full step puts the node in contact, and the next Jacobian sees its
        stiffness (Cattaneo–Mindlin with LcLS* on the current surface: the
        step stalled at 4.9e-6 of residual; with the full step it converged,
        1.3e-2, 5.9e-6, 9.0e-7, 9.1e-7, 1.8e-8, 1.5e-14). Collective: the norms
        are global, and every rank decides alike.
        """
        stol = snes.getTolerances()[2]
        return (step * y.norm() <= stol * x.norm()
                and math.sqrt(f0) > self._round_off())


def library_line_search(problem: Residual, traits: Sequence["NewtonTraits"],
                        bulk_is_linear: bool) -> FullStepFirst:
    """The library's line search for a problem whose contact terms have
    ``traits`` (:class:`~dolfinx_mortar.contact.newton.NewtonTraits`).

    It shortens steps on the current surface, and on frozen surfaces
    (``"initial"``, ``"previous"``, and the frozen phase of a ``"current"``
    step) for a bulk law nonlinear in u (``bulk_is_linear`` False: the
    user's Jacobian form contains u) or with friction
    (:meth:`FullStepFirst.frozen_phase`). Friction needs it: a
    slipping node at the contact edge whose direction turns had full steps
    throw it from side to side (two pressed cylinders, Newton cycling at 2e-3
    of the force)."""
    frictional = any(t.frictional for t in traits)
    shorten = any(t.follows_u for t in traits) or frictional or not bulk_is_linear
    return FullStepFirst(problem, shorten=shorten,
                         shortens_frozen_steps=frictional or not bulk_is_linear)
