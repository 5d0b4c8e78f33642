"""The load path: equal steps, halved when Newton fails, regrown after successes.

Halving a failed step and never growing it back again kept the halved step to
the end of the run (34 steps instead of 6; a sliding run took 528 instead of
20). :class:`LoadStepper` doubles the step after ``grow_after`` successes in a
row, up to the step the user asked for, and lands exactly on load factor 1.

Every run ends: a step is never cut below ``2^-max_cuts`` of the requested
one, and the failed attempts of a whole run are counted too. Successes
between failures used to reset the count, so a step that failed five times,
succeeded once at 1/32 and failed again was cut to 1/1024, and so on without
end: 1,114 failed attempts in 100 s with the load factor stuck at 0.159763
(issue 35).
"""
from __future__ import annotations

import numbers
from typing import Optional

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
    max_failures
        Failed attempts allowed over the whole run (default: ``2·max_cuts +
        load_steps``); one more means the load cannot be reached.

    Use: ``target = stepper.target()``, solve at it, then
    ``stepper.succeeded()`` or ``stepper.failed()``, while ``not stepper.done``.
    """

    def __init__(self, load_steps: int, max_cuts: int = 5, grow_after: int = 2,
                 max_failures: Optional[int] = None):
        self.load_steps = check_load_steps(load_steps)
        if (isinstance(max_cuts, bool) or not isinstance(max_cuts, numbers.Integral)
                or max_cuts < 0):
            raise ValueError(f"max_cuts must be an integer of at least 0, got {max_cuts!r}")
        self.full_step = 1.0 / self.load_steps
        self.step = self.full_step
        #: the smallest step a cut may make
        self.min_step = self.full_step * 0.5 ** max_cuts
        self.max_cuts = max_cuts
        self.grow_after = grow_after
        self.max_failures = (2 * max_cuts + self.load_steps if max_failures is None
                             else max_failures)
        self.reached = 0.0
        self.failures = 0
        #: failed attempts over the whole run
        self.total_failures = 0
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
        """Whether the load cannot be reached: more than ``max_cuts`` failures
        in a row, a failure at the smallest step, or more than
        ``max_failures`` in all."""
        return (self.failures > self.max_cuts or self.step < self.min_step
                or self.total_failures > self.max_failures)

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
        """Record that :meth:`target` was not reached: halve the step (the
        next target is always a smaller load factor)."""
        self.failures += 1
        self.total_failures += 1
        self.successes = 0
        self.step /= 2

    @property
    def fraction_of_steps(self) -> float:
        """Progress in units of the requested steps (for a progress bar)."""
        return float(np.clip(self.reached, 0.0, 1.0)) * self.load_steps
