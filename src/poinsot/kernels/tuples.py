"""Small fixed-length states held in registers: arithmetic on tuples of floats.

The fixed-step engine keeps one body's state in a tuple of scalars while it takes a step, so
that a step is straight-line code on registers; over an ensemble chunk the loop over members is
innermost and the compiler vectorises it across members. These helpers do the elementwise
arithmetic of a step on tuples of any length (numba generates the code for each length).
"""

from __future__ import annotations

from numba import types
from numba.extending import overload

from .jit import KERNEL_OPTIONS

__all__ = ["tuple_axpy", "tuple_rk4_combine"]

_OPTIONS = {k: v for k, v in KERNEL_OPTIONS.items() if k != "cache"}  # compiled into callers


def tuple_axpy(y, a, k):
    """``y + a k`` elementwise, for tuples ``y``, ``k`` of floats and a float ``a``."""
    return tuple(yi + a * ki for yi, ki in zip(y, k, strict=True))


def tuple_rk4_combine(y, c, k1, k2, k3, k4):
    """``y + c (k1 + 2 k2 + 2 k3 + k4)`` elementwise: the update of classical RK4 (with
    ``c = h/6``), in exactly the order of operations of the array step."""
    return tuple(
        yi + c * (a + 2.0 * b + 2.0 * d + e)
        for yi, a, b, d, e in zip(y, k1, k2, k3, k4, strict=True)
    )


def _generate(name, n, expression, params):
    terms = ", ".join(expression.format(i=i) for i in range(n))
    source = f"def {name}({params}):\n    return ({terms},)\n"
    scope: dict = {}
    exec(source, scope)  # elementwise code for a tuple of length n
    return scope[name]


@overload(tuple_axpy, inline="always", jit_options=_OPTIONS)
def _ol_tuple_axpy(y, a, k):
    if isinstance(y, types.UniTuple):
        return _generate("axpy", y.count, "y[{i}] + a * k[{i}]", "y, a, k")
    return None


@overload(tuple_rk4_combine, inline="always", jit_options=_OPTIONS)
def _ol_tuple_rk4_combine(y, c, k1, k2, k3, k4):
    if isinstance(y, types.UniTuple):
        return _generate(
            "combine",
            y.count,
            "y[{i}] + c * (k1[{i}] + 2.0 * k2[{i}] + 2.0 * k3[{i}] + k4[{i}])",
            "y, c, k1, k2, k3, k4",
        )
    return None
