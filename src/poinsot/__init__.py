"""poinsot: dynamics of rigid bodies and constrained mechanical systems.

The top-level names are loaded lazily (PEP 562), so ``import poinsot`` costs only NumPy; SciPy,
SymPy and matplotlib are imported by the functions that need them; the physics is the compiled
core ``poinsot._core``, built with the package.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing (mypy and pyright read it)

__version__ = "0.1.0"

# public name -> module that defines it
_LAZY = {
    "RigidBody": "poinsot.bodies",
    "simulate": "poinsot.simulation",
    "SimulationError": "poinsot.simulation",
    "Trajectory": "poinsot.trajectory",
    "Gravity": "poinsot.forces",
    "CentralGravity": "poinsot.forces",
    "ParticleForce": "poinsot.forces",
    "PointForce": "poinsot.forces",
    "Torque": "poinsot.forces",
    "Spring": "poinsot.forces",
    "LinearDrag": "poinsot.forces",
    "QuadraticDrag": "poinsot.forces",
    "CustomForce": "poinsot.forces",
    "FreeRigidBody": "poinsot.torquefree",
    "LagrangianSystem": "poinsot.lagrange",
    "PointMass": "poinsot.lagrange",
}

__all__ = ["__version__", *sorted(_LAZY)]

if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs only
    from .bodies import RigidBody as RigidBody
    from .forces import CentralGravity as CentralGravity
    from .forces import CustomForce as CustomForce
    from .forces import Gravity as Gravity
    from .forces import LinearDrag as LinearDrag
    from .forces import ParticleForce as ParticleForce
    from .forces import PointForce as PointForce
    from .forces import QuadraticDrag as QuadraticDrag
    from .forces import Spring as Spring
    from .forces import Torque as Torque
    from .lagrange import LagrangianSystem as LagrangianSystem
    from .lagrange import PointMass as PointMass
    from .simulation import SimulationError as SimulationError
    from .simulation import simulate as simulate
    from .torquefree import FreeRigidBody as FreeRigidBody
    from .trajectory import Trajectory as Trajectory


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'poinsot' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
