"""Calls into generated, compiled code by address: how the steppers run a system whose vector
field is written per model (the compiled Lagrangian engine, :mod:`poinsot.lagrange.engine`).

A model's equations are generated and compiled once per model, into a module of their own
(``numba.cfunc``, cached on disk); what the steppers receive is the *address* of its C-callable
entry points, an ``int64`` in the system's named tuple. The drivers are then compiled once for
the system *type* (:data:`~poinsot.kernels.systems.NativeSystem`), whatever the model, and stay
in numba's disk cache: no model's code is part of theirs.

Why not a first-class function: numba cannot cache a function that takes a compiled function as
an argument (each process would compile the drivers again, seconds per run); and a system type
per model would put every model ever compiled into the drivers' cache index. An address is a
number: the machine code calls through it, and the generated module keeps the function alive.

The entry points' C signatures (the generated module defines them; every pointer is to float64
data of the stated length, C order):

* ``rhs(t, y*, p*, u*, alpha, beta, out*) -> void``: ``out = ẏ(t, y)`` for the parameters
  ``p``, the inputs ``u`` and the constraint stabilisation gains ``alpha``, ``beta``;
* ``project(t, y*, p*, u*) -> int64``: put ``y`` on the constraint manifold in place; 1 when the
  model is constrained, 0 otherwise.
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.extending import intrinsic

__all__ = ["call_project", "call_rhs"]


def _float_arrays(*arrays) -> bool:
    return all(
        isinstance(a, types.Array) and a.dtype == types.float64 and a.layout == "C" for a in arrays
    )


def _data(context, builder, array_type, value):
    return context.make_array(array_type)(context, builder, value).data


@intrinsic
def call_rhs(typingctx, address, t, y, p, u, alpha, beta, out):
    """``out = ẏ``: the generated ``rhs`` at ``address`` (int64) on contiguous float64 arrays
    ``y``, ``p``, ``u``, ``out`` (other layouts do not type: they would be read wrongly)."""
    if not (isinstance(address, types.Integer) and _float_arrays(y, p, u, out)):
        return None
    sig = types.void(address, types.float64, y, p, u, types.float64, types.float64, out)

    def codegen(context, builder, signature, args):
        double = ir.DoubleType()
        ptr = double.as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [double, ptr, ptr, ptr, double, double, ptr])
        fn = builder.inttoptr(args[0], fnty.as_pointer())
        t_, alpha_, beta_ = (context.cast(builder, args[i], signature.args[i], types.float64)
                             for i in (1, 5, 6))  # fmt: skip
        data = [_data(context, builder, signature.args[i], args[i]) for i in (2, 3, 4, 7)]
        builder.call(fn, [t_, data[0], data[1], data[2], alpha_, beta_, data[3]])
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def call_project(typingctx, address, t, y, p, u):
    """The generated ``project`` at ``address`` (int64): ``y`` put on the constraint manifold
    in place; returns 1 when the model is constrained."""
    if not (isinstance(address, types.Integer) and _float_arrays(y, p, u)):
        return None
    sig = types.int64(address, types.float64, y, p, u)

    def codegen(context, builder, signature, args):
        double = ir.DoubleType()
        ptr = double.as_pointer()
        fnty = ir.FunctionType(ir.IntType(64), [double, ptr, ptr, ptr])
        fn = builder.inttoptr(args[0], fnty.as_pointer())
        t_ = context.cast(builder, args[1], signature.args[1], types.float64)
        data = [_data(context, builder, signature.args[i], args[i]) for i in (2, 3, 4)]
        return builder.call(fn, [t_, *data])

    return sig, codegen
