"""The integrator contract and the registry of methods (cf. ``scipy.integrate._ivp.base``).

A method is a declaration and its data; its step lives once, in the compiled core
(``crates/core/src/steppers.rs``: pure steps, diffrax's ``step``), and its time loop in the
core's drivers (``drivers.rs``). The core's registry (``crates/core/src/spec.rs``,
``poinsot._core.METHODS``) declares each method it runs by name: its kind of step, order,
tableau, the invariants it keeps and whether it takes kicks. :func:`register` takes a named
class's declaration from there, and every method of the core's registry without a class of its
own here gets one (:func:`register_core_methods`), so a method the core adds is a method of
this registry with nothing written in Python.

Writing a new integrator in Python, on the core's steps (a new tableau):

1. Subclass :class:`Solver` and set the class attributes ``name``, ``order`` (the global order
   of accuracy, checked by ``tests/integrate/test_order.py``), ``adaptive``, ``conserves`` (the
   invariants it keeps to round-off, from :data:`INVARIANTS`) and ``requires`` (``"ode"`` for
   any vector field, ``"rigid"`` when it needs the rigid-body structure).
2. Give its data and name its step: an explicit Runge–Kutta method is its tableau ``A``,
   ``B``, ``C`` on the core's general step (:attr:`Solver.kind` ``"erk"``,
   :class:`~poinsot.integrate.rk.ExplicitRungeKutta`); the other kinds are the core's own
   steps (``"rk4"`` in registers, ``"rkmk"`` with a tableau, ``"splitting"``, ``"dop853"``).
3. Add it to :data:`METHODS` with :func:`register`; every registered method then runs through
   the order and conservation tests. A system offers the kinds its structure allows
   (:class:`~poinsot.integrate.problem.NativeProblem`).

Users select a method by name (any case) or by class: ``simulate(..., method="rkmk4")`` or
``method=RKMK4``. Step-size control and sampling are separate small objects
(:mod:`poinsot.integrate.control`, :mod:`poinsot.integrate.saveat`).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from .._bindings import runs as core_runs

__all__ = ["INVARIANTS", "METHODS", "Solver", "get_solver", "register", "register_core_methods"]

#: Invariants a method may declare it keeps to round-off.
INVARIANTS = frozenset(
    {
        "orthogonality",  # Q stays on SO(3)
        "angular_momentum",  # |L| and spatial L, torque-free
        "symplectic",  # bounded energy error, no drift
    }
)


class Solver:
    """Base class of poinsot's integrators; see the module docstring for the contract.

    Attributes
    ----------
    name, order, adaptive, conserves, requires
        The declaration of the method.
    kind : str
        The compiled core's step that runs it: ``"rk4"``, ``"erk"``, ``"rkmk"``,
        ``"splitting"`` or ``"dop853"``.
    A, B, C : ndarray
        The tableau (explicit Runge–Kutta methods and their relatives); empty for the others.
    flows, kicks : ndarray
        The composition of an exact-flow splitting (kind ``"exact-splitting"``): the free
        flows' and the kicks' fractions of a step, in the order they run; empty for the others.
    kick_first : bool
        The composition starts with a kick (``kicks`` one longer than ``flows``) or with a
        flow (``flows`` one longer).
    """

    name: ClassVar[str] = ""
    order: ClassVar[int] = 0
    adaptive: ClassVar[bool] = False
    conserves: ClassVar[frozenset[str]] = frozenset()
    requires: ClassVar[str] = "ode"
    kind: ClassVar[str] = ""
    #: it takes kicks from the forces: each must depend on time, position and attitude only
    needs_position_only_forces: ClassVar[bool] = False
    A: ClassVar[np.ndarray] = np.zeros((0, 0))
    B: ClassVar[np.ndarray] = np.zeros(0)
    C: ClassVar[np.ndarray] = np.zeros(0)
    flows: ClassVar[np.ndarray] = np.zeros(0)
    kicks: ClassVar[np.ndarray] = np.zeros(0)
    kick_first: ClassVar[bool] = True

    @classmethod
    def method_data(cls) -> dict[str, Any]:
        """What the core's kind of step needs beyond its name, as keyword arguments of
        :class:`poinsot._core.RunSpec`: the tableau (``"erk"``, ``"rkmk"``), the composition
        (``"exact-splitting"``) or nothing."""
        f64 = lambda x: np.ascontiguousarray(x, dtype=float)  # noqa: E731
        if cls.kind in ("erk", "rkmk"):
            B = f64(cls.B)
            return {"tableau": (f64(cls.A).reshape(len(B), len(B)), B, f64(cls.C))}
        if cls.kind == "exact-splitting":
            return {"composition": (f64(cls.flows), f64(cls.kicks), bool(cls.kick_first))}
        return {}

    def __repr__(self):
        return f"{type(self).__name__}()"


METHODS: dict[str, type[Solver]] = {}


def register(cls: type[Solver]) -> type[Solver]:
    """Add a :class:`Solver` subclass to :data:`METHODS` under ``cls.name`` (decorator)."""
    if not (isinstance(cls, type) and issubclass(cls, Solver)) or not cls.name:
        raise TypeError("only named Solver subclasses can be registered")
    entry = CORE_METHODS.get(cls.name)
    if entry is not None:
        _declare(cls, entry)
    unknown = cls.conserves - INVARIANTS
    if unknown:
        raise ValueError(f"{cls.__name__}.conserves names unknown invariants {sorted(unknown)}")
    METHODS[cls.name] = cls
    return cls


#: The core's registry by name: ``{name, kind, order, tableau, conserves, kicks, adaptive,
#: summary}`` for each method it runs by name.
CORE_METHODS: dict[str, dict[str, Any]] = {e["name"]: e for e in core_runs.METHODS}


def _declare(cls: type[Solver], entry: dict[str, Any]) -> None:
    """Set a class's declaration from its entry in the core's registry."""
    cls.kind = entry["kind"]
    cls.order = entry["order"]
    cls.adaptive = entry["adaptive"]
    cls.conserves = frozenset(entry["conserves"])
    cls.requires = "ode" if entry["kind"] in core_runs.FIELD_KINDS else "rigid"
    cls.needs_position_only_forces = entry["kicks"]
    if entry["kind"] == "exact-splitting":
        cls.flows, cls.kicks, cls.kick_first = core_runs.composition(entry["tableau"])
    elif entry["tableau"]:
        cls.A, cls.B, cls.C = core_runs.tableau(entry["tableau"])


def register_core_methods() -> None:
    """Register a class for every method of the core's registry that has none here (named
    after it: ``"exact-splitting4"`` is ``ExactSplitting4``, its docstring the entry's
    summary)."""
    for name, entry in CORE_METHODS.items():
        if name not in METHODS:
            title = "".join(part.capitalize() for part in name.replace("_", "-").split("-"))
            register(type(title, (Solver,), {"name": name, "__doc__": entry["summary"],
                                              "__module__": __name__}))  # fmt: skip


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
