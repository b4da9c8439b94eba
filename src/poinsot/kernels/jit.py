"""How kernels are compiled: numba's ``njit`` with the on-disk cache, and their Python twins.

Every function of the kernel layer is written in the subset of Python and NumPy that numba
compiles in nopython mode, and decorated with :func:`kernel`. Numba is imported by this module,
so by the kernel modules, never by ``import poinsot``.

Three mechanisms live here:

* :func:`kernel`: ``numba.njit(cache=True, nogil=True)``; ``inline=True`` inlines a small
  formula into its callers at numba's IR level (the hot loop then holds no calls at all).
* :func:`generic`: a function dispatched on the type of its first argument, the *system*.
  Systems are named tuples of plain arrays (see :mod:`poinsot.kernels.systems`); each system
  type registers its implementation, and compiled callers (steppers, drivers) are specialised
  per system type at compile time, through :func:`numba.extending.overload`. Called from
  Python, the same function dispatches on ``type(system)``, or calls the method of the same name
  of a Python system object (the Python backend, which holds user callables).
* :func:`python_twin`: the same source code as a plain Python function, in which every kernel
  that takes a ``system`` argument is replaced by its own twin. The Python backend runs the
  compiled drivers' and steppers' own code this way, with a Python system, so the two backends
  share every line and agree to round-off.

Why not pass the vector field as a function argument: numba cannot cache a function that takes
another compiled function as an argument, anywhere in its call chain, so every process would pay
the compilation again. Dispatching on the system's type keeps the whole engine cacheable.
"""

from __future__ import annotations

import hashlib
import inspect
import types
import warnings
from functools import cache
from pathlib import Path

import numba
from numba.core.registry import CPUDispatcher
from numba.extending import overload

# numba's SSA pass runs a "pedantic" self-check after inlining (``inline="always"``) and warns
# that a name assigned in both arms of an ``if`` is "not in scope"; the generated code is
# correct (every such kernel is compared with its Python twin in tests/kernels/test_numba.py).
# The check is about numba's own IR, not about the user's code, so poinsot silences exactly it.
warnings.filterwarnings(
    "ignore",
    message=r"variable '.*' is not in scope",
    category=numba.core.errors.NumbaIRAssumptionWarning,
)

__all__ = ["accepts_sequences", "generic", "jit", "kernel", "kernel_layer_stamp", "python_twin"]

_KERNELS = Path(__file__).resolve().parent


@cache
def kernel_layer_stamp() -> str:
    """One hash of every source file of the kernel layer (and numba's version).

    Numba's disk cache checks only the source file of the function it caches, but our compiled
    engine inlines kernels from several files: an edit to one of them would leave stale
    machine code in the others' caches. Every kernel's cache is stamped with this hash instead,
    so any change to the kernel layer recompiles it.
    """
    digest = hashlib.sha256(numba.__version__.encode())
    for path in sorted(_KERNELS.glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _install_cache_locator():
    """Put a locator for the kernel layer in front of numba's own (see
    :func:`kernel_layer_stamp`); it stores the cache where numba would (``NUMBA_CACHE_DIR`` or
    the package's ``__pycache__``)."""
    from numba.core import caching

    found = []
    for name in ("InTreeCacheLocator", "UserProvidedCacheLocator"):  # inserted in front, in turn
        base = getattr(caching, name, None) or getattr(caching, "_" + name, None)
        if base is not None:
            found.append(base)
    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
    if impl is None or not found:  # pragma: no cover - a numba without these internals
        return
    for base in found:

        class KernelLayerLocator(base):
            @classmethod
            def from_function(cls, py_func, py_file):
                if Path(py_file).resolve().parent != _KERNELS:
                    return None
                return super().from_function(py_func, py_file)

            def get_source_stamp(self):
                return kernel_layer_stamp()

        KernelLayerLocator.__name__ = "Poinsot" + base.__name__.lstrip("_")
        impl._locator_classes.insert(0, KernelLayerLocator)


_install_cache_locator()

#: Options every kernel is compiled with. ``nogil`` lets threads run kernels concurrently;
#: ``fastmath`` stays off, so compiled and Python evaluation round identically.
KERNEL_OPTIONS = {"cache": True, "nogil": True, "error_model": "numpy"}


def kernel(fn=None, *, inline: bool = False):
    """Compile ``fn`` with numba in nopython mode, cached on disk.

    ``inline=True`` inlines the function into compiled callers (used for the small formulas
    of the hot loop; it makes no difference when called from Python).
    """

    def wrap(f):
        return numba.njit(inline="always" if inline else "never", **KERNEL_OPTIONS)(f)

    return wrap if fn is None else wrap(fn)


def accepts_sequences(compiled):
    """A Python entry to the compiled batched kernel ``compiled`` that first turns lists and
    tuples into float arrays (numba cannot type a list that mixes ints and floats). Only for
    kernels called from Python: compiled code calls the ``*_into`` kernels instead."""
    import functools

    import numpy as np

    @functools.wraps(compiled.py_func)
    def entry(*args):
        return compiled(*(np.asarray(a, dtype=float) if isinstance(a, list | tuple) else a
                          for a in args))  # fmt: skip

    entry.__wrapped__ = compiled
    entry.py_func = compiled.py_func
    return entry


def jit(fn, **options):
    """``numba.njit(fn, **options)`` of a kernel's Python source (tests, user code)."""
    return numba.njit(**options)(getattr(fn, "py_func", fn))


def generic(fn):
    """Declare ``fn(system, ...)`` generic over the type of its first argument (a system, or
    another named tuple such as an observer); see the module docstring.

    Returns a plain function with the signature of ``fn`` (numba resolves overloads by the
    function object, and matches signatures by name) and a ``register(type)`` decorator.
    The body of ``fn`` is never run: it documents the contract.
    """
    params = list(inspect.signature(fn).parameters)
    if not params:
        raise TypeError(f"generic {fn.__name__}() needs an argument to dispatch on")
    first = params[0]
    impls: dict = {}
    args = ", ".join(params)
    rest = ", ".join(params[1:])
    source = (
        f"def {fn.__name__}({args}):\n"
        f"    impl = _impls.get(type({first}))\n"
        f"    if impl is not None:\n"
        f"        return impl({args})\n"
        f"    method = getattr({first}, {fn.__name__!r}, None)\n"
        f"    if method is None:\n"
        f"        raise TypeError(type({first}).__name__ + ' does not provide {fn.__name__}()')\n"
        f"    return method({rest})\n"
        f"def typer({args}):\n"
        f"    return _wrapper_for(getattr({first}, 'instance_class', None))\n"
    )
    wrappers: dict = {}

    def wrapper_for(system_type):
        # The overload must return a function of its own (not the kernel's source): numba
        # caches what it compiles under the function's file and name, and the kernel compiled
        # for an overload must not take the place of the kernel called from Python.
        impl = impls.get(system_type)
        if impl is None:
            return None
        if system_type not in wrappers:
            name = f"_{fn.__name__}_for_{system_type.__name__}"
            code = f"def {name}({args}):\n    return _impl({args})\n"
            scope = {"_impl": impl}
            exec(code, scope)
            wrappers[system_type] = scope[name]
        return wrappers[system_type]

    namespace = {"_impls": impls, "_wrapper_for": wrapper_for}
    exec(source, namespace)  # the two functions need the contract's exact parameter names
    dispatcher = namespace[fn.__name__]
    dispatcher.__doc__ = fn.__doc__
    dispatcher.__module__ = fn.__module__
    dispatcher.__qualname__ = fn.__qualname__
    dispatcher.impls = impls

    def register(system_type):
        """Decorator: ``impl`` is the implementation of this function for ``system_type``."""

        def deco(impl):
            impls[system_type] = impl
            return impl

        return deco

    dispatcher.register = register
    options = {k: v for k, v in KERNEL_OPTIONS.items() if k != "cache"}  # callers are cached
    overload(dispatcher, inline="always", jit_options=options)(namespace["typer"])
    return dispatcher


_TWINS: dict = {}


def _takes_system(fn) -> bool:
    try:
        params = inspect.signature(fn).parameters
    except (TypeError, ValueError):  # pragma: no cover - builtins
        return False
    return "system" in params


def python_twin(fn):
    """The pure-Python version of the kernel ``fn``: same code, Python execution, and every
    kernel it calls that takes a ``system`` replaced by its twin (recursively).

    Kernels that take no system (formulas on arrays) stay compiled: they are called with
    arrays, which compiled code accepts. Generic functions stay as they are: called from Python
    they dispatch to a Python system's own methods.
    """
    py = getattr(fn, "py_func", fn)
    twin = _TWINS.get(py)
    if twin is not None:
        return twin
    namespace = dict(py.__globals__)
    twin = types.FunctionType(py.__code__, namespace, py.__name__, py.__defaults__, py.__closure__)
    twin.__doc__ = py.__doc__
    twin.__wrapped__ = py
    _TWINS[py] = twin
    for name, value in py.__globals__.items():
        if isinstance(value, CPUDispatcher) and _takes_system(value.py_func):
            namespace[name] = python_twin(value)
    return twin
