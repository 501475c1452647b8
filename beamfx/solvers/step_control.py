"""One step controller for load steps, arc-length steps and time steps.

A :class:`StepControl` holds the current step size between ``smallest`` and ``largest``.
After a rejected step it cuts back (halves, or by the error estimate); after an accepted one
a growth policy sizes the next step:

* :class:`EasyGrowth`: grow by ``factor`` after ``run`` accepted steps in a row that took at
  most ``easy`` Newton iterations (and, with ``clean``, no cut-back);
* :class:`IterationRatio`: Crisfield's ``sqrt(desired / iterations)``, within
  [``least``, ``most``];
* :class:`ErrorBased`: ``safety · error^(−1/(order+1))`` within [``least``, ``most``], from
  a local error estimate scaled so that 1 is the tolerance (also sizes cut-backs).
"""

import math
from dataclasses import dataclass


class StepTooSmall(Exception):
    """A cut-back would take the step below the smallest size allowed."""


@dataclass
class EasyGrowth:
    """Grow by ``factor`` after ``run`` easy steps in a row (see the module docstring)."""

    factor: float = 1.5
    easy: int = 4
    run: int = 1
    clean: bool = False
    _streak: int = 0

    def ratio(self, iterations, cutbacks, error):
        """Factor of the next step size after an accepted step."""
        self._streak = self._streak + 1 if iterations <= self.easy else 0
        grow = self._streak >= self.run and not (self.clean and cutbacks)
        return self.factor if grow else 1.0


@dataclass
class IterationRatio:
    """Crisfield's ``sqrt(desired / iterations)`` within [``least``, ``most``]."""

    desired: int = 4
    least: float = 0.5
    most: float = 2.0

    def ratio(self, iterations, cutbacks, error):
        """Factor of the next step size after an accepted step."""
        return min(self.most, max(self.least, math.sqrt(self.desired / max(iterations, 1))))


@dataclass
class ErrorBased:
    """``safety · error^(−1/(order+1))`` within [``least``, ``most``] (error 1: the tolerance)."""

    order: int = 2
    safety: float = 0.9
    least: float = 0.2  # of a cut-back
    most: float = 2.0

    def _factor(self, error):
        return self.safety * error ** (-1.0 / (self.order + 1))

    def ratio(self, iterations, cutbacks, error):
        """Factor of the next step size after an accepted step with the scaled ``error``."""
        return min(self.most, self._factor(max(error, 1e-10)))

    def shrink(self, error):
        """Factor of a cut-back after a step rejected with the scaled ``error``."""
        return max(self.least, self._factor(error))


@dataclass
class StepControl:
    """The step size of a march and its policies (see the module docstring).

    Attributes:
        size: the next step to try.
        largest: never grown beyond this.
        smallest: a halving below this raises :class:`StepTooSmall`; an error-based cut-back
            stops at it (the step is then taken).
        growth: the policy after an accepted step.
        reach_smallest: a halving that would go below ``smallest`` from a larger size tries
            ``smallest`` itself first (so the smallest step allowed is the last one tried).
    """

    size: float
    largest: float
    smallest: float
    growth: object
    reach_smallest: bool = False

    def accepted(self, iterations, cutbacks=0, error=None):
        """Size the next step after one accepted with ``iterations`` Newton iterations after
        ``cutbacks`` cut-backs (``error``: its error estimate, for :class:`ErrorBased`)."""
        ratio = self.growth.ratio(iterations, cutbacks, error)
        self.size = min(self.largest, self.size * ratio) if ratio != 1.0 else self.size
        return self.size

    def rejected(self, error=None):
        """Cut back after a rejected step: by the error estimate if given (not below
        ``smallest``), else by half (raising :class:`StepTooSmall` below ``smallest``)."""
        if error is not None:
            self.size = max(self.size * self.growth.shrink(error), self.smallest)
            return self.size
        above = self.size > self.smallest * (1 + 1e-12)
        self.size /= 2
        if self.size < self.smallest:
            if not (self.reach_smallest and above):
                raise StepTooSmall(self.size)
            self.size = self.smallest
        return self.size


__all__ = ["EasyGrowth", "ErrorBased", "IterationRatio", "StepControl", "StepTooSmall"]
