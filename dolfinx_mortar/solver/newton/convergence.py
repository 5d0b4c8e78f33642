"""When a Newton solve of a load step has reached equilibrium, and why it failed.

PETSc's default test accepts a step when ``‖R‖ ≤ rtol ‖R₀‖`` with ``R₀`` the
residual where Newton starts, or when the Newton step is small
(``CONVERGED_SNORM_RELATIVE``). Neither means equilibrium here: the
gap-closing start (:func:`~dolfinx_mortar.solver.newton.start.close_gaps`) can raise ``‖R₀‖`` to
1e8 times the load, and with a huge penalty the Newton step reaches round-off
while ``‖R‖`` is still a percent of the load (the force balance was then off
by 0.4 … 1.8%, silently). :class:`EquilibriumTest` accepts a step only when
``‖R‖ ≤ max(atol, rtol·F)`` with ``F`` a force fixed before Newton starts (the
residual of the previous equilibrium under the new load: the out-of-balance
load), and stops early when Newton stagnates (its step at round-off, or a
stall), accepting the round-off floor only when it is an equilibrium to
``floor_rtol`` and naming the cause in words otherwise. The tolerances are
PETSc's own options (``-<prefix>snes_rtol``, ``snes_atol``, ``snes_stol``,
``snes_max_it``).
"""
from __future__ import annotations

import math
from typing import NamedTuple, Optional, Sequence

from petsc4py import PETSc

_SNES = PETSc.SNES.ConvergedReason
#: a residual with NaN or Inf: PETSc 3.25 calls it DIVERGED_FUNCTION_NANORINF, 3.22 DIVERGED_FNORM_NAN
DIVERGED_NAN = getattr(_SNES, "DIVERGED_FUNCTION_NANORINF", None)
if DIVERGED_NAN is None:
    DIVERGED_NAN = _SNES.DIVERGED_FNORM_NAN
_KSP = PETSc.KSP.ConvergedReason


def reason_name(reason: int, kind: type = _SNES) -> str:
    """The PETSc name of a SNES (or, with ``kind=PETSc.KSP.ConvergedReason``,
    KSP) converged reason, e.g. ``DIVERGED_LINEAR_SOLVE``."""
    for name in dir(kind):
        if not name.startswith("_") and name != "ITERATING" and getattr(kind, name) == reason:
            return name
    return f"reason {reason}"


class EquilibriumTest:
    """SNES convergence test against a force that does not depend on the Newton start.

    Install with ``snes.setConvergenceTest(test)``; call :meth:`start` before
    every ``snes.solve``. A step converges when ``‖R‖ ≤ max(atol, rtol·F)``.
    When Newton stagnates — its step is at round-off (``‖Δu‖ ≤ stol·‖u‖``) or
    it stalls (below) — the residual is at the floor that double precision
    allows for this problem: that floor is accepted as equilibrium when
    ``‖R‖ ≤ floor_rtol·max(F, S, C)``, with S the largest force a step of the
    path started with (:attr:`force_scale`) and C the norm of the contact
    forces carried where the solve started (:attr:`carried`): the round-off
    of the forces already carried, which a small step cannot go below
    (Cattaneo–Mindlin on the current surface reached 1.7e-15 = 1.4e-8 of its
    step's F and was cut back again and again); the solve fails, with the
    cause in words, otherwise. A residual that cycles, or is still wandering
    at ``snes_max_it``, entirely below that floor is converged too: its
    last digits are round-off (two blocks shifted by 1e8 on the current
    surface cycled between 7e-15 and 3e-14 with F = 1e-5 on DOLFINx 0.11). (An elastic master at ε = 1e3 E/h stagnates at 3e-11 F; at
    ε = 1e12 E/h a block on a tilted plane stagnates at 3e-5 F.)

    Parameters
    ----------
    floor_rtol
        The largest residual, relative to F, accepted from a stagnating Newton.
    window
        Newton has stalled when its residual has stayed within a band of
        ``1 / reduction`` (11%) for ``window`` iterations. A creep of 0.015%
        per iteration (GLS, issue 10) is caught after ``window`` iterations;
        a linear rate of 0.95 per iteration (a factor 1.5 over 8) is not, nor
        an active-set search whose residual jumps by orders of magnitude for
        20 iterations before it converges (the grazing disk of
        ``benchmarks/hard_case_scenes.py``): a lower bound on the reduction
        over the window stopped that one, which ``snes_max_it`` bounds anyway.
        Newton cycles when the last ``window`` residuals repeat with a period
        of 2 to 4 iterations (to 1e-6): GLS against a disk cycled between
        three active sets for 40 iterations.
    reduction
        See ``window``.
    """

    def __init__(self, floor_rtol: float = 1e-8, window: int = 8, reduction: float = 0.9):
        self.floor_rtol = floor_rtol
        self.window = window
        self.reduction = reduction
        self._given: Optional[float] = None
        self.reference = 0.0
        self.norms: list[float] = []
        #: why the last solve was stopped by this test without convergence
        self.cause: Optional[str] = None
        #: the largest out-of-balance force a step of the path started with
        self.force_scale = 0.0
        #: the contact forces carried where the present solve started
        self.carried = 0.0

    def step_reference(self, out_of_balance: float) -> float:
        """The force F of a load step that starts ``out_of_balance``: that force,
        or for a step that changes nothing (a hold, Q = 0 after P), which starts
        at the round-off floor of the forces met so far, their scale. Its own
        round-off residual is no scale to reduce (such a step failed at stol)."""
        if out_of_balance <= self.floor_rtol * self.force_scale:
            return self.force_scale
        self.force_scale = max(self.force_scale, out_of_balance)
        return out_of_balance

    def start(self, reference: Optional[float], carried: float = 0.0) -> None:
        """A new Newton solve; ``reference`` is the force ``F`` of ``‖R‖ ≤ rtol·F``
        (None, also without a call: the first residual of each solve, PETSc's own rule);
        ``carried``, the norm of the contact forces already carried where it starts."""
        self._given = None if reference is None else float(reference)
        self.carried = float(carried)
        self.norms = []
        self.cause = None

    def __call__(self, snes: PETSc.SNES, its: int, norms: Sequence[float]) -> int:
        xnorm, step_norm, fnorm = norms
        if its == 0:
            self.norms = []
            self.cause = None
            self.reference = fnorm if self._given is None else self._given
        self.norms.append(fnorm)
        rtol, atol, stol, max_it = snes.getTolerances()
        if not math.isfinite(fnorm):
            return DIVERGED_NAN
        if fnorm <= atol:
            return _SNES.CONVERGED_FNORM_ABS
        if fnorm <= rtol * self.reference:
            return _SNES.CONVERGED_FNORM_RELATIVE
        stagnation, accepted = None, _SNES.CONVERGED_ITERATING
        if its > 0 and step_norm <= stol * xnorm:
            stagnation = (f"Newton step at round-off (|du| = {step_norm:.3e} <= stol·|u| = "
                          f"{stol * xnorm:.3e})")
            accepted = _SNES.CONVERGED_SNORM_RELATIVE
        elif its >= self.window:
            band = self.norms[-self.window - 1:]
            if max(band) * self.reduction < min(band):
                stagnation = (f"stalled: the residual changed by only "
                              f"{100 * (max(band) / min(band) - 1):.3g}% over the last "
                              f"{self.window} iterations ({band[0]:.3e} to {band[-1]:.3e})")
                accepted = _SNES.CONVERGED_ITS
            period = self._period()
            if stagnation is None and period and max(self.norms[-period:]) <= self.floor():
                # a cycle in the last digits: the residual is round-off
                return _SNES.CONVERGED_ITS
            if stagnation is None and period:
                self.cause = (f"cycling: the residual repeats every {period} iterations "
                              f"({', '.join(f'{r:.3e}' for r in self.norms[-period:])}): the "
                              "active set does not settle")
                return _SNES.DIVERGED_DTOL
        if stagnation is not None:
            # the floor of double precision is the whole problem's: a step
            # whose increment is small (a tangential load after the normal
            # one) stagnates at round-off of the forces already carried
            if fnorm <= self.floor():
                return accepted
            self.cause = (f"{stagnation}, |R| = {fnorm:.3e} = {self._relative(fnorm)} of the "
                          f"reference force {self.reference:.3e} (accepted: {self.floor_rtol:g} "
                          f"of it, or of the forces carried, "
                          f"{max(self.force_scale, self.carried):.3e}): "
                          "Newton cannot reduce the residual further (a cycling active set, "
                          "or an ill-conditioned Newton matrix, e.g. a penalty far above E/h)")
            return _SNES.DIVERGED_DTOL
        if its >= max_it and max(self.norms[-self.window:]) <= self.floor():
            # the last iterations wandered in round-off: nothing left to reduce
            return _SNES.CONVERGED_ITS
        if its >= max_it:
            self.cause = (f"maximum Newton iterations ({max_it}) reached with |R| = "
                          f"{fnorm:.3e} = {self._relative(fnorm)} of the reference force "
                          f"{self.reference:.3e}")
            return _SNES.DIVERGED_MAX_IT
        return _SNES.CONVERGED_ITERATING

    def floor(self) -> float:
        """The residual that double precision cannot go below here: ``floor_rtol``
        times the step's force, the path's largest, or the contact forces carried."""
        return self.floor_rtol * max(self.reference, self.force_scale, self.carried)

    def _period(self) -> int:
        """The period (2 to 4) with which the last ``window`` residuals repeat, or 0."""
        last = self.norms[-self.window:]
        for period in (2, 3, 4):
            if all(abs(a - b) <= 1e-6 * max(a, b) for a, b in zip(last[period:], last)):
                return period
        return 0

    def _relative(self, fnorm: float) -> str:
        return f"{fnorm / self.reference:.2e}" if self.reference > 0 else "inf"


def carried_force(contacts: Sequence) -> float:
    """The norm of the contact terms' residual at their last evaluation: the
    forces the contact carries, the scale of its round-off (``carried`` of
    :meth:`EquilibriumTest.start`; collective)."""
    states = [term.state for term in contacts if term.state is not None]
    if not states:
        return 0.0
    total = states[0].residual.copy()
    for state in states[1:]:
        total.axpy(1.0, state.residual)
    norm = total.norm()
    total.destroy()
    return norm


def describe_failure(snes: PETSc.SNES, test: EquilibriumTest,
                     evaluation_error: Optional[str] = None) -> str:
    """What stopped a failed Newton solve, in words: the SNES reason's name and,
    for a failed linear solve, the KSP's reason and iteration count; for a
    NaN residual that the problem could not evaluate, its
    ``evaluation_error``."""
    reason = snes.getConvergedReason()
    name = reason_name(reason)
    if test.cause is not None:   # stopped by the test itself: its words say more
        return test.cause
    if evaluation_error is not None:
        return f"{name}: the residual could not be evaluated at a Newton iterate: {evaluation_error}"
    if reason == _SNES.DIVERGED_LINEAR_SOLVE:
        ksp = snes.getKSP()
        return (f"{name}: linear solve failed: KSP "
                f"{reason_name(ksp.getConvergedReason(), _KSP)} after "
                f"{ksp.getIterationNumber()} iterations")
    if reason == _SNES.DIVERGED_LINE_SEARCH:
        return f"{name}: line search failed"
    if reason == _SNES.DIVERGED_MAX_IT:
        return f"{name}: maximum Newton iterations ({snes.getTolerances()[3]}) reached"
    if reason == DIVERGED_NAN:
        return f"{name}: the residual is NaN or infinite"
    return name


class FailedAttempt(NamedTuple):
    """One failed Newton solve of a load step."""

    load_factor: float
    reason: int
    residuals: list
    cause: str


class ContactDivergenceError(RuntimeError):
    """Newton failed at a load step even after the step was cut back.

    Attributes
    ----------
    load_factor
        The load factor that could not be reached.
    history
        One :class:`FailedAttempt` (load factor, SNES reason, residual norms,
        cause in words) per failed attempt.
    """

    def __init__(self, load_factor: float, history: Sequence[FailedAttempt]):
        self.load_factor = load_factor
        self.history = list(history)
        lines = [f"  load {a.load_factor:.6g}: {a.cause}\n    residuals "
                 + ", ".join(f"{r:.3e}" for r in a.residuals) for a in self.history]
        super().__init__(f"Newton failed at load factor {load_factor:.6g} after "
                         f"{len(self.history)} attempts:\n" + "\n".join(lines))
