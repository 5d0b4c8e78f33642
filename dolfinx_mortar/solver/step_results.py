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
    #: (:class:`~dolfinx_mortar.solver.convergence.EquilibriumTest`)
    reference: float = float("nan")
    #: residual norms below this are round-off (the equilibrium test's floor)
    floor: float = 0.0

    def quadratic_constant(self) -> float:
        """C in ``e_(k+1) = C·e_k²``, ``e = ‖R‖/F``, at the last Newton iterate
        that started above the round-off floor.

        Newton with the exact Jacobian near the solution has C of order one
        (times the conditioning); a linearly converging solve (an inexact
        Jacobian) has a C that grows as e_k falls. ``nan`` without such an
        iterate (the step started converged).
        """
        pairs = [(r[k], r[k + 1]) for r in self.phases for k in range(len(r) - 1)
                 if r[k] > self.floor]
        if not pairs or not self.reference > 0:
            return float("nan")
        r, r_next = pairs[-1]
        return (r_next / self.reference) / (r / self.reference) ** 2


@dataclass
class SolveResult:
    """All converged steps."""

    steps: list = field(default_factory=list)

    @property
    def newton_iterations(self) -> int:
        return sum(s.newton_iterations for s in self.steps)
