"""The integrator contract and the registry of methods (cf. ``scipy.integrate._ivp.base``).

Writing a new integrator:

1. Subclass :class:`Solver`; set the class attributes ``name``, ``order`` (the global order of
   accuracy, checked by ``tests/integrate/test_order.py``), ``adaptive``, ``conserves`` (the
   invariants it keeps to round-off, from :data:`INVARIANTS`) and ``requires`` (``"ode"`` for
   any ``system.rhs(t, y)``, ``"rigid"`` when it needs a
   :class:`~poinsot.dynamics.RigidBodySystem`).
2. Fixed-step methods implement ``_step_impl(t, y, h) → y_new``; adaptive methods override
   :meth:`Solver._advance` and :meth:`Solver._dense_output_impl`.
3. Add it to :data:`METHODS` with :func:`register`; every registered method then runs through
   the order and conservation tests.

The public driver is :func:`poinsot.integrate.driver.integrate`; users select a method by name or
by class: ``simulate(..., method="rkmk4")`` or ``method=RKMK4``.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

__all__ = ["INVARIANTS", "METHODS", "Solver", "get_solver", "register"]

#: Invariants a method may declare it keeps to round-off.
INVARIANTS = frozenset(
    {
        "orthogonality",  # Q stays on SO(3)
        "angular_momentum",  # |L| and spatial L, torque-free
        "symplectic",  # bounded energy error, no drift
    }
)


class Solver:
    """Base class of poinsot's integrators.

    Parameters
    ----------
    system
        The vector field: an object with ``rhs(t, y) → ẏ`` (and, for ``requires = "rigid"``,
        a :class:`~poinsot.dynamics.RigidBodySystem`).
    t0, y0, t_bound
        Start time, initial state (1-D), end time (``t_bound > t0``).
    dt : float, optional
        Step size for fixed-step methods (required); first step for adaptive ones.
    rtol, atol : float, optional
        Tolerances of adaptive methods.

    Attributes
    ----------
    t, y : current time and state; ``t_old``, ``y_old`` the previous ones.
    status : ``"running"`` or ``"finished"``.
    nfev : number of right-hand-side evaluations.
    """

    name: ClassVar[str] = ""
    order: ClassVar[int] = 0
    adaptive: ClassVar[bool] = False
    conserves: ClassVar[frozenset[str]] = frozenset()
    requires: ClassVar[str] = "ode"
    _projects_itself: ClassVar[bool] = False

    def __init__(self, system, t0, y0, t_bound, *, dt=None, rtol=None, atol=None):
        if not t_bound > t0:
            raise ValueError(f"`t_span` must increase, found t0 = {t0}, t1 = {t_bound}")
        if not self.adaptive and dt is None:
            raise ValueError(f"method {self.name!r} is fixed-step: `dt` must be given")
        if dt is not None and not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"`dt` must be a positive number, found {dt}")
        self.system = system
        self.t = float(t0)
        self.y = np.array(y0, dtype=float)
        self.t_bound = float(t_bound)
        self.dt = dt
        self.rtol, self.atol = rtol, atol
        self.t_old = None
        self.y_old = None
        self.nfev = 0
        self.status = "running"
        # system.projector(y0), if present, returns None or a map (y, t) -> y onto the
        # constraint manifold, applied after every step
        projector = getattr(system, "projector", None)
        self._project = projector(self.y) if projector is not None else None

    def fun(self, t, y):
        """The system's right-hand side, counted in ``nfev``."""
        self.nfev += 1
        return self.system.rhs(t, y)

    def step(self, h=None):
        """Advance one step: ``h`` (fixed-step methods; default ``dt``), never past ``t_bound``."""
        if self.status != "running":
            raise RuntimeError("solver has finished: no further steps")
        self.t_old, self.y_old = self.t, self.y
        self._advance(h)
        if self._project is not None and not self._projects_itself:
            self.y = self._project(self.y, self.t)
            self._after_projection()
        if self.t >= self.t_bound - 1e-12 * max(1.0, abs(self.t_bound)):
            self.t = self.t_bound
            self.status = "finished"

    def _after_projection(self):
        """Hook: adaptive methods that keep their own state take the projected ``y`` back."""

    def _advance(self, h):
        h = self.dt if h is None else h
        h = min(h, self.t_bound - self.t)
        self.y = self._step_impl(self.t, self.y, h)
        self.t = self.t + h

    def _step_impl(self, t, y, h):  # pragma: no cover - abstract
        raise NotImplementedError

    def dense_output(self):
        """Interpolant ``f(t)`` over the last step ``[t_old, t]``.

        Fixed-step methods give the cubic Hermite interpolant of the flat state (third order; a
        rotation-matrix block is then within O(h⁴) of SO(3)). :func:`~poinsot.simulate` does not
        need it for them: fixed steps are shortened to land on every sample time.
        """
        if self.t_old is None:
            raise RuntimeError("dense output needs at least one step")
        return self._dense_output_impl()

    def _dense_output_impl(self):
        t0, t1, y0, y1 = self.t_old, self.t, self.y_old, self.y
        f0, f1 = self.fun(t0, y0), self.fun(t1, y1)
        h = t1 - t0

        def interpolant(t):
            s = (np.asarray(t, dtype=float) - t0) / h
            s = s[..., None] if np.ndim(s) else s
            h00 = 2 * s**3 - 3 * s**2 + 1
            h10 = s**3 - 2 * s**2 + s
            h01 = -2 * s**3 + 3 * s**2
            h11 = s**3 - s**2
            return h00 * y0 + h10 * h * f0 + h01 * y1 + h11 * h * f1

        return interpolant


METHODS: dict[str, type[Solver]] = {}


def register(cls: type[Solver]) -> type[Solver]:
    """Add a :class:`Solver` subclass to :data:`METHODS` under ``cls.name`` (decorator)."""
    if not (isinstance(cls, type) and issubclass(cls, Solver)) or not cls.name:
        raise TypeError("only named Solver subclasses can be registered")
    unknown = cls.conserves - INVARIANTS
    if unknown:
        raise ValueError(f"{cls.__name__}.conserves names unknown invariants {sorted(unknown)}")
    METHODS[cls.name] = cls
    return cls


def get_solver(method) -> type[Solver]:
    """The solver class for ``method``: a registered name or a :class:`Solver` subclass."""
    if isinstance(method, type) and issubclass(method, Solver):
        return method
    if isinstance(method, str) and method in METHODS:
        return METHODS[method]
    raise ValueError(
        f"`method` must be one of {{{', '.join(repr(m) for m in sorted(METHODS))}}} "
        f"or a Solver class, found {method!r}"
    )
