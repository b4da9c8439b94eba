"""Adaptive 8th-order Dormand–Prince with dense output, through SciPy's implementation.

We use :class:`scipy.integrate.DOP853` rather than our own tableau: it is well tested, has the
7th-order dense output, and its step-size control is the standard one (Hairer, Nørsett & Wanner,
*Solving ODEs I*, §II.10).
"""

from __future__ import annotations

from .base import Solver, register

__all__ = ["DOP853"]

DEFAULT_RTOL = 1e-10
DEFAULT_ATOL = 1e-12


@register
class DOP853(Solver):
    """Explicit Runge–Kutta of order 8(5,3) with adaptive steps (the default method).

    ``rtol``/``atol`` default to 1e-10/1e-12; ``dt`` (optional) is the first step and
    ``max_step`` (keyword) caps the step size.
    """

    name = "dop853"
    order = 8
    adaptive = True

    def __init__(self, system, t0, y0, t_bound, *, dt=None, rtol=None, atol=None, max_step=None):
        super().__init__(system, t0, y0, t_bound, dt=dt, rtol=rtol, atol=atol)
        from scipy.integrate import DOP853 as _ScipyDOP853

        self._inner = _ScipyDOP853(
            self.fun,
            t0,
            self.y,
            t_bound,
            rtol=DEFAULT_RTOL if rtol is None else rtol,
            atol=DEFAULT_ATOL if atol is None else atol,
            first_step=dt,
            max_step=float("inf") if max_step is None else max_step,
        )

    def _advance(self, h):
        message = self._inner.step()
        if self._inner.status == "failed":
            raise RuntimeError(f"dop853 failed at t = {self._inner.t}: {message}")
        self.t = self._inner.t
        self.y = self._inner.y.copy()

    def _after_projection(self):
        # continue from the projected state; FSAL caches f(t, y), so recompute it
        self._inner.y = self.y.copy()
        self._inner.f = self._inner.fun(self._inner.t, self._inner.y)

    def _dense_output_impl(self):
        return self._inner.dense_output()
