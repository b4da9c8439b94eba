"""Adaptive 8th-order Dormand–Prince with error control and dense output, in the kernel layer.

The tableau, the error estimators and the dense-output coefficients are data
(:mod:`poinsot.kernels.tableaux`); the step, the scaled error norm and the interpolant are
kernels (:func:`~poinsot.kernels.steppers.dop853_step`,
:func:`~poinsot.kernels.steppers.dop853_error_norm`,
:func:`~poinsot.kernels.steppers.dop853_dense_into`), and the standard step-size controller is
:class:`~poinsot.integrate.control.StepSizeController` (Hairer, Nørsett & Wanner, *Solving ODEs
I*, §II.4 and §II.10). SciPy's ``solve_ivp(method="DOP853")`` runs the same method and serves as
the cross-check in the tests; it is not the engine.
"""

from __future__ import annotations

import numpy as np

from .. import _core
from .base import Solver, SolverState, _kernel_for, register

__all__ = ["DEFAULT_ATOL", "DEFAULT_RTOL", "DOP853"]

DEFAULT_RTOL = 1e-10
DEFAULT_ATOL = 1e-12


@register
class DOP853(Solver):
    """Explicit Runge–Kutta of order 8(5,3) with adaptive steps (the default method).

    ``rtol``/``atol`` default to 1e-10/1e-12; ``dt`` (optional) is the first step and
    ``max_step`` (a solver option) caps the step size.
    """

    name = "dop853"
    order = 8
    error_order = 7
    adaptive = True
    kind = "dop853"
    driver = "run_adaptive"
    A, B, C = _core.tableau("dop853")

    def init(self, system, t0, y0):
        from ..kernels.steppers import evaluate

        state = super().init(system, t0, y0)
        f = np.empty_like(state.z)
        _kernel_for(evaluate, system)(system, state.t, state.z, f)
        return SolverState(state.t, state.z, f)

    def step(self, system, state, h, controller=None):
        from ..kernels import steppers as _st
        from .control import StepSizeController

        controller = controller or StepSizeController()
        z = state.z
        n = z.size
        from ..kernels import tableaux

        K = np.empty((tableaux.DOP853_STAGES_EXTENDED, n))
        out_y = np.empty_like(z)
        out_f = np.empty_like(z)
        step = _kernel_for(_st.dop853_step, system)
        step(system, state.t, z, state.f, float(h), K, np.empty_like(z), out_y, out_f)
        error = float(
            _st.dop853_error_norm(K, float(h), z, out_y, controller.rtol, controller.atol)
        )
        return SolverState(state.t + h, out_y, out_f), error
