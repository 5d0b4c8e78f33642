"""What a load-path solve returns: each converged step's Newton record."""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class StepResult:
    """One converged load step."""

    load_factor: float
    newton_iterations: int
    #: residual norms of every Newton iterate, the SNES solves one after another
    residuals: list
    wall_time: float
    active_nodes: int
    #: the same norms per SNES solve (two with ``"current"``: frozen surface, then current)
    phases: list = field(default_factory=list)
    #: the step's force scale F: the out-of-balance force where it started
    #: (:class:`~dolfinx_mortar.solver.newton.convergence.EquilibriumTest`)
    reference: float = float("nan")
    #: Krylov iterations of the step's linear solves (1 per Newton iteration with LU)
    linear_iterations: int = 0
    #: per contact term with friction (None without): the tangential force
    #: resultant on the slave body, the step's and the total frictional
    #: dissipation, and the numbers of sticking and slipping nodes
    #: (:meth:`~dolfinx_mortar.contact.results.contact_results.ContactResults.friction_summary`)
    friction: list = field(default_factory=list)

    def terminal_iterations(self, near: float = 1e-3) -> int:
        """Newton iterations of the step's last solve after its residual first
        fell to ``near·F``: the convergence once the active set has settled.

        Quadratic convergence needs 2–3 (1e-3 → 1e-6 → 1e-12); a linear rate
        of 0.1 needs 8 to reach the default tolerance 1e-11·F. Counting
        iterations instead of fitting a rate needs no estimate of where
        round-off begins. -1 if the last solve never got there.
        """
        last = self.phases[-1] if self.phases else self.residuals
        below = [k for k, r in enumerate(last) if r <= near * self.reference]
        return len(last) - 1 - below[0] if below else -1


@dataclass
class SolveResult:
    """All converged steps, and every attempt that failed and was cut back."""

    steps: list = field(default_factory=list)
    #: one :class:`~dolfinx_mortar.solver.newton.convergence.FailedAttempt` (load
    #: factor, SNES reason, residual norms, cause in words) per failed attempt
    #: after which the step was halved and retried, in the order they happened
    cut_backs: list = field(default_factory=list)

    @property
    def newton_iterations(self) -> int:
        return sum(s.newton_iterations for s in self.steps)

    @property
    def linear_iterations(self) -> int:
        """Krylov iterations over all steps."""
        return sum(s.linear_iterations for s in self.steps)
