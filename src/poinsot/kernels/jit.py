"""Compile kernels with numba on demand (numba is imported here, and only here).

``jit(fn)`` returns ``numba.njit(fn)``. Kernels call one another, and numba can call only
functions it knows, so the first call registers every public kernel with
``numba.extending.register_jitable`` and rebinds the kernel modules' references to the registered
versions — which behave identically when called from Python. ``import poinsot`` never imports
numba.
"""

from __future__ import annotations

import importlib

__all__ = ["jit"]

_MODULES = ("so3", "rigid", "inertia", "elliptic")
_ENABLED = False


def _enable():
    global _ENABLED
    if _ENABLED:
        return
    from numba.extending import register_jitable

    modules = [importlib.import_module(f"poinsot.kernels.{m}") for m in _MODULES]
    registered = {}
    for mod in modules:
        for name in mod.__all__:
            fn = getattr(mod, name)
            if callable(fn):
                registered[name] = register_jitable(getattr(fn, "py_func", fn))
    for mod in modules:
        for name, fn in registered.items():
            if name in vars(mod):
                setattr(mod, name, fn)
    _ENABLED = True


def jit(fn, **options):
    """``numba.njit(fn, **options)`` with every kernel callable from compiled code."""
    import numba

    _enable()
    return numba.njit(**options)(getattr(fn, "py_func", fn))
