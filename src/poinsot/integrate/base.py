"""The integrator contract and the registry of methods (cf. ``scipy.integrate._ivp.base``).

A solver is stateless: it describes a method and steps a state it is handed, keeping nothing
between calls (diffrax's pure ``step``). Writing a new integrator:

1. Subclass :class:`Solver` and set the class attributes ``name``, ``order`` (the global order
   of accuracy, checked by ``tests/integrate/test_order.py``), ``adaptive``, ``conserves`` (the
   invariants it keeps to round-off, from :data:`INVARIANTS`) and ``requires`` (``"ode"`` for
   any vector field, ``"rigid"`` when it needs the rigid-body structure).
2. Give its data: an explicit Runge–Kutta method is its tableau ``A``, ``B``, ``C``
   (:class:`~poinsot.integrate.rk.ExplicitRungeKutta`); other methods name the kernel step
   they run (:attr:`Solver.kernel` in :mod:`poinsot.kernels.steppers`) and the compiled driver
   that loops over it (:attr:`Solver.driver` in :mod:`poinsot.kernels.drivers`).
3. :meth:`Solver.init` turns a system's state into the solver's state, :meth:`Solver.step`
   advances it by ``h`` and returns ``(new state, error estimate)``, :meth:`Solver.output`
   turns it back. The drivers use the same kernel steps; they never read a solver's fields
   beyond its declared data.
4. Add it to :data:`METHODS` with :func:`register`; every registered method then runs through
   the order and conservation tests.

Users select a method by name (any case) or by class: ``simulate(..., method="rkmk4")`` or
``method=RKMK4``. Step-size control and sampling are separate small objects
(:mod:`poinsot.integrate.control`, :mod:`poinsot.integrate.saveat`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

__all__ = ["INVARIANTS", "METHODS", "Solver", "SolverState", "get_solver", "register"]

#: Invariants a method may declare it keeps to round-off.
INVARIANTS = frozenset(
    {
        "orthogonality",  # Q stays on SO(3)
        "angular_momentum",  # |L| and spatial L, torque-free
        "symplectic",  # bounded energy error, no drift
    }
)


@dataclass(frozen=True)
class SolverState:
    """The state a solver carries from one step to the next: time ``t``, its own state vector
    ``z`` and, for first-same-as-last methods, the derivative ``f`` at ``(t, z)``."""

    t: float
    z: np.ndarray
    f: np.ndarray | None = None


def _drivers():
    from ..kernels import drivers

    return drivers


def _kernel_for(fn, system):
    """The compiled kernel for a compiled system (a named tuple of arrays), its Python twin for
    a Python system."""
    if isinstance(system, tuple):
        return fn
    from ..kernels.jit import python_twin

    return python_twin(fn)


class _KernelCode:
    """The numba engine's code of a method (``kernels.steppers.METHOD_CODES[kind]``), looked
    up on use: the compiled core names methods by :attr:`Solver.kind`."""

    def __get__(self, obj, cls):
        from ..kernels.steppers import METHOD_CODES

        return METHOD_CODES.get(cls.kind, -1)


class Solver:
    """Base class of poinsot's integrators; see the module docstring for the contract.

    Attributes
    ----------
    name, order, adaptive, conserves, requires
        The declaration of the method.
    code : int
        The method's code in :mod:`poinsot.kernels.steppers` (how the kernels convert states).
    driver : str
        The compiled time loop that runs it (a function of :mod:`poinsot.kernels.drivers`).
    """

    name: ClassVar[str] = ""
    order: ClassVar[int] = 0
    adaptive: ClassVar[bool] = False
    conserves: ClassVar[frozenset[str]] = frozenset()
    requires: ClassVar[str] = "ode"
    code = _KernelCode()
    #: The compiled core's step: "rk4", "erk", "rkmk", "splitting" or "dop853".
    kind: ClassVar[str] = ""
    driver: ClassVar[str] = ""
    #: tableau (ExplicitRungeKutta and its relatives); empty arrays for the others
    A: ClassVar[np.ndarray] = np.zeros((0, 0))
    B: ClassVar[np.ndarray] = np.zeros(0)
    C: ClassVar[np.ndarray] = np.zeros(0)

    def driver_function(self, system):
        """The compiled driver for a compiled system, or its Python twin for a Python one."""
        return _kernel_for(getattr(_drivers(), self.driver), system)

    def init(self, system, t0, y0) -> SolverState:
        """The solver's state at ``(t0, y0)`` (``y0`` in the system's own coordinates)."""
        from ..kernels.steppers import SPLITTING, solver_init_into

        y0 = np.asarray(y0, dtype=float)
        if self.code != SPLITTING:  # the solver's state is the system's state
            return SolverState(float(t0), y0.copy())
        z = np.empty_like(y0)
        _kernel_for(solver_init_into, system)(self.code, system, y0, z)
        return SolverState(float(t0), z)

    def output(self, system, state: SolverState) -> np.ndarray:
        """The system's state from the solver's."""
        from ..kernels.steppers import solver_output_into

        y = np.empty_like(state.z)
        _kernel_for(solver_output_into, system)(self.code, system, state.z, y)
        return y

    def step(self, system, state: SolverState, h: float, controller=None):
        """Advance ``state`` by ``h``: ``(new state, error)``. ``error`` is the scaled error
        norm for adaptive methods (``controller`` gives the tolerances; a step is acceptable
        when it is below 1), ``None`` for fixed-step methods."""
        raise NotImplementedError

    def __repr__(self):
        return f"{type(self).__name__}()"


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
    """The solver class for ``method``: a registered name (any case) or a Solver subclass."""
    if isinstance(method, type) and issubclass(method, Solver):
        return method
    if isinstance(method, str) and method.lower() in METHODS:
        return METHODS[method.lower()]
    raise ValueError(
        f"`method` must be one of {{{', '.join(repr(m) for m in sorted(METHODS))}}} "
        f"or a Solver class, found {method!r}"
    )
