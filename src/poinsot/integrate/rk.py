"""Explicit Runge–Kutta methods as data (Butcher tableaux), on flat state vectors."""

from __future__ import annotations

from .base import Solver, register

__all__ = ["RK4", "ExplicitRungeKutta"]


class ExplicitRungeKutta(Solver):
    """A fixed-step explicit Runge–Kutta method given by its tableau ``A``, ``B``, ``C``.

    Stages ``k_i = f(t + C_i h, y + h Σ_j A_ij k_j)``, update ``y + h Σ_i B_i k_i`` (the core's
    ``erk_step``). Subclass it with a new tableau to get a new method: the tests check every
    registered tableau's consistency (``Σ B = 1``, ``Σ_j A_ij = C_i``, ``A`` strictly lower
    triangular) and its convergence order.
    """

    kind = "erk"


@register
class RK4(ExplicitRungeKutta):
    """Classical fourth-order Runge–Kutta on the flat 18-component state, as the notebook does.

    It conserves nothing exactly: ``Q`` drifts off SO(3) and energy drifts, at O(h⁴) per unit
    time; :class:`~poinsot.trajectory.Trajectory` reports both so the drift can be shown. The
    core runs it on rigid bodies with the state in registers (``rk4_rigid_step``) and on any
    other system as its tableau, equal to round-off.
    """

    name = "rk4"  # order, kind and tableau: the core's registry (spec.rs)
