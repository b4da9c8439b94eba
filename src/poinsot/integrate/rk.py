"""Explicit Runge–Kutta methods as data (Butcher tableaux), on flat state vectors."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from .base import Solver, register

__all__ = ["RK4", "ExplicitRungeKutta"]


class ExplicitRungeKutta(Solver):
    """A fixed-step explicit Runge–Kutta method given by its tableau ``A``, ``B``, ``C``.

    Stages ``k_i = f(t + C_i h, y + h Σ_j A_ij k_j)``, update ``y + h Σ_i B_i k_i``.
    The tableau's consistency (``Σ B = 1``, ``Σ_j A_ij = C_i``, ``A`` strictly lower triangular)
    is checked by the tests for every subclass.
    """

    A: ClassVar[np.ndarray]
    B: ClassVar[np.ndarray]
    C: ClassVar[np.ndarray]

    def _step_impl(self, t, y, h):
        A, B, C = self.A, self.B, self.C
        k = np.empty((len(B), y.size))
        for i in range(len(B)):
            yi = y + h * (A[i, :i] @ k[:i]) if i else y
            k[i] = self.fun(t + C[i] * h, yi)
        return y + h * (B @ k)


@register
class RK4(ExplicitRungeKutta):
    """Classical fourth-order Runge–Kutta on the flat 18-component state, as the notebook does.

    It conserves nothing exactly: ``Q`` drifts off SO(3) and energy drifts, at O(h⁴) per unit
    time; :class:`~poinsot.trajectory.Trajectory` reports both so the drift can be shown.
    """

    name = "rk4"
    order = 4
    A = np.array([[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1, 0]], dtype=float)
    B = np.array([1, 2, 2, 1], dtype=float) / 6
    C = np.array([0, 0.5, 0.5, 1], dtype=float)
