"""A model's own SymPy expressions, compiled at run time to machine code (no C compiler).

:func:`compile_expressions` lowers expressions in a few input symbols to a postfix program
(common subexpressions shared through SymPy's ``cse``), and the core compiles that program to
machine code with the ``symjit`` crate (``poinsot._core.Expressions``; interpreted where a
platform forbids run-time code). Nothing here is physics: only the expressions a model
brings (a carrier's ``ω_e(t)``, ``ε_e(t)``, ``a_O(t)``) are lowered.

A program is cached by its content: a model seen before in the process is not compiled again.

Examples
--------
>>> import numpy as np, sympy as sp
>>> t = sp.Symbol("t")
>>> f = compile_expressions([sp.sin(t) * t, t**2 + 1], [t])
>>> f(np.array([[0.5]])).round(12).tolist()
[[0.239712769302, 1.25]]
"""

from __future__ import annotations

import hashlib

import numpy as np

from . import _core

__all__ = ["ExpressionError", "compile_expressions", "lower"]

# the core's instruction codes (crates/core/src/expressions.rs)
CONST, INPUT, LOAD, STORE, OUTPUT, ADD, MUL, POW = range(8)
UNARY, BINARY = 100, 200
UNARY_NAMES = ("sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh",
               "acosh", "atanh", "exp", "log", "sqrt", "Abs", "sign")  # fmt: skip
BINARY_NAMES = ("atan2", "Min", "Max")

_CACHE: dict[str, object] = {}
#: At most this many instructions per program (a bound on compile time and memory).
MAX_INSTRUCTIONS = 200_000


class ExpressionError(ValueError):
    """An expression the core cannot compile (a function it does not know, a symbol that is
    not an input, a complex or non-finite number)."""


def lower(exprs, inputs) -> tuple[np.ndarray, np.ndarray]:
    """The postfix program ``(codes, values)`` of ``exprs`` in the symbols ``inputs``.

    SymPy's ``cse`` names the common subexpressions, which become temporaries. ``Add`` and
    ``Mul`` with many arguments become chains of binary operations, ``x - y`` is
    ``x + (-1)·y`` and ``x / y`` is ``x · y^(-1)``, as SymPy itself represents them.
    """
    import sympy as sp

    exprs = [sp.sympify(e) for e in exprs]
    index = {s: i for i, s in enumerate(inputs)}
    subs, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_cse"), optimizations=None)
    temps: dict = {}
    codes: list[int] = []
    values: list[float] = []

    def emit(code, value=0.0):
        codes.append(code)
        values.append(value)
        if len(codes) > MAX_INSTRUCTIONS:
            raise ExpressionError(f"the expressions need more than {MAX_INSTRUCTIONS} instructions")

    def walk(e):
        # iterative post-order walk: deep expressions do not exhaust Python's stack
        stack = [(e, False)]
        while stack:
            node, done = stack.pop()
            if done:
                op(node)
                continue
            if node in temps or node in index or node.is_Number or node.is_NumberSymbol:
                op(node)
                continue
            stack.append((node, True))
            for a in reversed(node.args):
                stack.append((a, False))

    def op(node):
        if node in temps:
            emit(LOAD, temps[node])
        elif node in index:
            emit(INPUT, index[node])
        elif node.is_Number or node.is_NumberSymbol:
            value = complex(node)
            if value.imag != 0 or not np.isfinite(value.real):
                raise ExpressionError(f"the number {node} is not a finite real number")
            emit(CONST, value.real)
        elif node.is_Add or node.is_Mul:
            for _ in range(len(node.args) - 1):
                emit(ADD if node.is_Add else MUL)
        elif node.is_Pow:
            emit(POW)
        else:
            name = type(node).__name__
            if name in UNARY_NAMES and len(node.args) == 1:
                emit(UNARY + UNARY_NAMES.index(name))
            elif name in BINARY_NAMES and len(node.args) == 2:
                emit(BINARY + BINARY_NAMES.index(name))
            elif node.is_Symbol:
                names = ", ".join(str(s) for s in inputs)
                raise ExpressionError(f"the symbol {node} is not one of the inputs ({names})")
            else:
                known = ", ".join((*UNARY_NAMES, *BINARY_NAMES))
                raise ExpressionError(
                    f"{name} cannot be compiled: use arithmetic, powers and {known}"
                )

    for symbol, value in subs:
        walk(value)
        temps[symbol] = len(temps)
        emit(STORE, temps[symbol])
    for e in reduced:
        walk(e)
        emit(OUTPUT)
    return np.array(codes, dtype=np.int64), np.array(values, dtype=float)


def compile_expressions(exprs, inputs):
    """``exprs`` (SymPy expressions in the symbols ``inputs``) as one compiled function of the
    rows of an (n, len(inputs)) array → (n, len(exprs)); cached by the program's content.

    Raises
    ------
    ExpressionError
        An expression uses a function or symbol the core cannot compile.
    """
    codes, values = lower(exprs, inputs)
    shape = f"{len(inputs)},{len(exprs)};".encode()
    key = hashlib.sha256(shape + codes.tobytes() + values.tobytes()).hexdigest()
    compiled = _CACHE.get(key)
    if compiled is None:
        compiled = _core.Expressions(codes, values, len(inputs), len(exprs))
        _CACHE[key] = compiled
    return compiled
