"""Adaptive 8th-order Dormand–Prince with error control and dense output, in the core.

The tableau, the error estimators and the dense-output coefficients are data
(``crates/core/src/tableaux.rs``); the step, the scaled error norm, the interpolant and the
standard step-size controller (:class:`~poinsot.integrate.control.StepSizeController`;
Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4 and §II.10) are the core's
(``steppers.rs``). SciPy's ``solve_ivp(method="DOP853")`` runs the same method and serves as
the cross-check in the tests; it is not the engine.
"""

from __future__ import annotations

from .base import Solver, register

__all__ = ["DEFAULT_ATOL", "DEFAULT_RTOL", "DOP853"]

DEFAULT_RTOL = 1e-10
DEFAULT_ATOL = 1e-12


@register
class DOP853(Solver):
    """Explicit Runge–Kutta of order 8(5,3) with adaptive steps (the default method).

    ``rtol``/``atol`` default to 1e-10/1e-12; ``dt`` (optional) is the first step and
    ``max_step`` (a solver option) caps the step size.
    """

    name = "dop853"  # order, kind and tableau: the core's registry (spec.rs)
    error_order = 7
