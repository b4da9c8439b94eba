"""poinsot: dynamics of rigid bodies and constrained mechanical systems.

The top-level names are loaded lazily (PEP 562), so ``import poinsot`` costs only NumPy; SciPy,
SymPy, matplotlib and numba are imported by the functions that need them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

__version__ = "0.1.0"

# public name -> module that defines it
_LAZY = {
    "RigidBody": "poinsot.bodies",
}

__all__ = ["__version__", *sorted(_LAZY)]

if TYPE_CHECKING:  # pragma: no cover
    from .bodies import RigidBody as RigidBody


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'poinsot' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
