"""Explicit Runge–Kutta methods as data (Butcher tableaux), on flat state vectors."""

from __future__ import annotations

import numpy as np

from .. import _core
from .base import Solver, SolverState, _drivers, _kernel_for, register

__all__ = ["RK4", "ExplicitRungeKutta"]


class ExplicitRungeKutta(Solver):
    """A fixed-step explicit Runge–Kutta method given by its tableau ``A``, ``B``, ``C``.

    Stages ``k_i = f(t + C_i h, y + h Σ_j A_ij k_j)``, update ``y + h Σ_i B_i k_i``
    (:func:`poinsot.kernels.steppers.erk_step`). Subclass it with a new tableau to get a new
    method: the tests check every registered tableau's consistency (``Σ B = 1``,
    ``Σ_j A_ij = C_i``, ``A`` strictly lower triangular) and its convergence order.
    """

    kind = "erk"
    driver = "run_erk"

    def step(self, system, state, h, controller=None):
        from ..kernels import steppers as _st

        z = state.z
        K = np.empty((len(self.B), z.size))
        out = np.empty_like(z)
        erk = _kernel_for(_st.erk_step, system)
        erk(system, self.A, self.B, self.C, state.t, z, float(h), K, np.empty_like(z), out)
        return SolverState(state.t + h, out), None


@register
class RK4(ExplicitRungeKutta):
    """Classical fourth-order Runge–Kutta on the flat 18-component state, as the notebook does.

    It conserves nothing exactly: ``Q`` drifts off SO(3) and energy drifts, at O(h⁴) per unit
    time; :class:`~poinsot.trajectory.Trajectory` reports both so the drift can be shown. The
    compiled engine runs it with the stages unrolled
    (:func:`poinsot.kernels.steppers.rk4_tuple_step`), equal to the tableau's step to round-off.
    """

    name = "rk4"
    order = 4
    kind = "rk4"
    driver = "run_rk4"
    A, B, C = _core.tableau("rk4")

    def driver_function(self, system):
        """Rigid bodies: RK4 in registers (:func:`~poinsot.kernels.steppers.rk4_tuple_step`);
        any other system: the tableau's general step."""
        if _is_rigid(system):
            return super().driver_function(system)
        return _kernel_for(_drivers().run_erk, system)

    def step(self, system, state, h, controller=None):
        from ..kernels import steppers as _st

        if not _is_rigid(system):
            return super().step(system, state, h, controller)
        from ..kernels.layout import load_state, store_state

        step = _kernel_for(_st.rk4_tuple_step, system)
        y = step(system, state.t, load_state(state.z, 0, 1), float(h), 0)
        out = np.empty_like(state.z)
        store_state(out, 0, 1, y)
        return SolverState(state.t + h, out), None


def _is_rigid(system) -> bool:
    """True for the rigid-body systems, which step in registers (a ``rates`` method)."""
    from ..kernels.systems import REGISTER_SYSTEMS

    return type(system) in REGISTER_SYSTEMS or hasattr(system, "rates")
