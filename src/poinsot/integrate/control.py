"""Step-size control: the fixed step of fixed-step methods, and the standard controller of
adaptive ones (separate from the solvers, as in diffrax)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validation import as_scalar

__all__ = ["ConstantStepSize", "StepSizeController"]


def _positive(value, name) -> float:
    x = as_scalar(value, name)
    if not x > 0:
        raise ValueError(f"`{name}` must be a positive number, found {x}")
    return x


@dataclass(frozen=True)
class ConstantStepSize:
    """Steps of ``dt``, shortened to land exactly on every sample time and on the end."""

    dt: float

    def __post_init__(self):
        object.__setattr__(self, "dt", _positive(self.dt, "dt"))


@dataclass(frozen=True)
class StepSizeController:
    """The standard controller (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4): after a
    step with scaled error ``err``, the next one is the last times
    ``safety · err^(−1/(q+1))``, within ``[min_factor, max_factor]`` (and not above 1 right after
    a rejection); ``q`` is the order of the method's error estimator
    (the core's ``step_size_factor``).

    ``first_step`` (None: chosen automatically) and ``max_step`` bound the steps.
    """

    rtol: float = 1e-10
    atol: float = 1e-12
    first_step: float | None = None
    max_step: float = math.inf
    safety: float = 0.9
    min_factor: float = 0.2
    max_factor: float = 10.0

    def __post_init__(self):
        object.__setattr__(self, "rtol", _positive(self.rtol, "rtol"))
        object.__setattr__(self, "atol", _positive(self.atol, "atol"))
        if self.first_step is not None:
            object.__setattr__(self, "first_step", _positive(self.first_step, "first_step"))
        if not (isinstance(self.max_step, int | float) and self.max_step > 0):
            raise ValueError(f"`max_step` must be a positive number, found {self.max_step!r}")

    def as_array(self) -> np.ndarray:
        """The parameters as the engines read them: ``[rtol, atol, safety, min_factor,
        max_factor, max_step, first_step]`` (``first_step`` 0: chosen automatically)."""
        return np.array(
            [self.rtol, self.atol, self.safety, self.min_factor, self.max_factor,
             self.max_step, self.first_step or 0.0],
            dtype=float,
        )  # fmt: skip
