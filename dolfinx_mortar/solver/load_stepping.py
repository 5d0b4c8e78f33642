"""The load path: equal steps, halved when Newton fails, regrown after successes.

Halving a failed step and never growing it back again kept the halved step to
the end of the run (34 steps instead of 6; a sliding run took 528 instead of
20). :class:`LoadStepper` doubles the step after ``grow_after`` successes in a
row, up to the step the user asked for, and lands exactly on load factor 1.
"""
from __future__ import annotations

import numbers

import numpy as np


def check_load_steps(load_steps: object) -> int:
    """``load_steps`` as an int; a ValueError naming it unless it is a positive integer.

    1.5 used to run 2 steps and NaN one: a number of steps is a count.
    """
    if (isinstance(load_steps, bool) or not isinstance(load_steps, numbers.Integral)
            or load_steps < 1):
        raise ValueError(f"load_steps must be a positive integer, got {load_steps!r}")
    return int(load_steps)


class LoadStepper:
    """Load factors from 0 to 1 in ``load_steps`` steps, cut back on failure.

    Parameters
    ----------
    load_steps
        The number of equal steps when nothing fails (a positive integer).
    max_cuts
        How many failures in a row are allowed; one more means the load
        cannot be reached (:attr:`exhausted`).
    grow_after
        Successes in a row after which a cut step is doubled (never beyond
        ``1 / load_steps``).

    Use: ``target = stepper.target()``, solve at it, then
    ``stepper.succeeded()`` or ``stepper.failed()``, while ``not stepper.done``.
    """

    def __init__(self, load_steps: int, max_cuts: int = 5, grow_after: int = 2):
        self.load_steps = check_load_steps(load_steps)
        if max_cuts < 0:
            raise ValueError(f"max_cuts must be at least 0, got {max_cuts!r}")
        self.full_step = 1.0 / self.load_steps
        self.step = self.full_step
        self.max_cuts = max_cuts
        self.grow_after = grow_after
        self.reached = 0.0
        self.failures = 0
        self.successes = 0
        # a target this close to 1 is 1: far below the smallest step the cuts
        # can reach, above the round-off of the sum of the steps
        self._snap = max(1e-9 * self.full_step * 0.5 ** max_cuts, 1e-14)

    @property
    def done(self) -> bool:
        """Whether load factor 1 has been reached."""
        return self.reached >= 1.0

    @property
    def exhausted(self) -> bool:
        """Whether more than ``max_cuts`` failures came in a row."""
        return self.failures > self.max_cuts

    def target(self) -> float:
        """The load factor of the next attempt; exactly 1.0 for the last step."""
        target = self.reached + self.step
        return 1.0 if target >= 1.0 - self._snap else float(target)

    def succeeded(self) -> float:
        """Record that :meth:`target` was reached; returns it."""
        self.reached = self.target()
        self.failures = 0
        self.successes += 1
        if self.step < self.full_step and self.successes >= self.grow_after:
            self.step = min(self.full_step, 2 * self.step)
            self.successes = 0
        return self.reached

    def failed(self) -> None:
        """Record that :meth:`target` was not reached: halve the step."""
        self.failures += 1
        self.successes = 0
        self.step /= 2

    @property
    def fraction_of_steps(self) -> float:
        """Progress in units of the requested steps (for a progress bar)."""
        return float(np.clip(self.reached, 0.0, 1.0)) * self.load_steps
