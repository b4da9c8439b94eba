"""The contract between a system and the compiled core's integrators.

A system that the core can integrate says so with ``problem(y0)``, returning a
:class:`NativeProblem`: which engine of :mod:`poinsot._core` runs it, the system's data in the
order that engine takes it, the kinds of method it offers (its structure), and whether any
Python runs inside (the slow path, with the names of what keeps it there). The driver
(:func:`poinsot.integrate.driver.integrate`) needs nothing else of a system to run it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from .._bindings import runs as core_runs

__all__ = ["GENERAL_METHODS", "RIGID_METHODS", "NativeProblem"]

#: The core's kinds of method for any vector field: the adaptive DOP853 and explicit tableaux
#: (classical RK4's included).
GENERAL_METHODS = frozenset(core_runs.FIELD_KINDS)
#: ... and for a rigid body, every kind: those that use its structure too (RKMK on SO(3), the
#: splitting method with the free-rotor flows; RK4 with the state in registers).
RIGID_METHODS = frozenset(core_runs.METHOD_KINDS)


@dataclass(frozen=True)
class NativeProblem:
    """What a system hands the compiled core.

    Attributes
    ----------
    engine : callable
        The core's function that integrates it (``poinsot._core.integrate_rigid``, ...); it
        takes ``*data``, then the method and the run's buffers.
    data : tuple
        The system's arrays (and callbacks), in the order ``engine`` takes them.
    methods : frozenset of str
        The kinds of method (:attr:`poinsot.integrate.base.Solver.kind`) the system offers.
    slow : tuple of str
        What the core must call back in Python (named in errors for ``backend='compiled'``);
        empty when the whole run is compiled code.
    observes_flips : bool
        The engine can count flips of the angular velocity (ensembles).
    keywords : dict
        Keyword arguments of ``engine`` beyond the run's buffers (a constrained system's
        events, located inside the core's time loop).
    """

    engine: Callable
    data: tuple
    methods: frozenset
    slow: tuple = ()
    observes_flips: bool = False
    keywords: dict = field(default_factory=dict)

    @property
    def compiled(self) -> bool:
        """True when no Python runs inside the core's call."""
        return not self.slow

    def kind_of(self, kind: str) -> str | None:
        """The core's kind for a solver's ``kind``: itself when the system offers it, else
        None."""
        return kind if kind in self.methods else None
