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

import ast
import difflib
import hashlib

import numpy as np

from ._bindings import lagrange as core_lagrange

__all__ = ["ExpressionError", "compile_expressions", "lower", "parse"]

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
        compiled = core_lagrange.Expressions(codes, values, len(inputs), len(exprs))
        _CACHE[key] = compiled
    return compiled


# --------------------------------------------------------------------------- text → SymPy
#: The functions an expression written as text may call: name in the text → SymPy's name.
TEXT_FUNCTIONS = {
    name: name
    for name in (
        "sin",
        "cos",
        "tan",
        "asin",
        "acos",
        "atan",
        "sinh",
        "cosh",
        "tanh",
        "asinh",
        "acosh",
        "atanh",
        "exp",
        "log",
        "sqrt",
        "Abs",
        "sign",
        "atan2",
        "Min",
        "Max",
    )
}
TEXT_FUNCTIONS |= {"abs": "Abs", "min": "Min", "max": "Max"}
#: Constants by name.
TEXT_CONSTANTS = ("pi", "E")
#: The longest text accepted (a bound on parsing time and memory).
MAX_TEXT = 20_000
_ARITY = {"atan2": (2, 2), "Min": (2, 64), "Max": (2, 64)}


#: The syntax a text may not hold, in words, by node type (others are named by their type).
_REFUSED_NODES = {
    ast.Attribute: "an attribute",
    ast.Subscript: "an index",
    ast.Compare: "a comparison",
    ast.Lambda: "a lambda",
    ast.BoolOp: "and/or",
}


class _TextReader:
    """The SymPy expression of a parsed text, built node by node from its syntax tree; every
    refusal names ``where`` (see :func:`parse`)."""

    def __init__(self, text: str, source: str, names: dict, where: str):
        import sympy as sp

        self.text, self.source, self.names, self.where = text, source, names, where
        self.known = {**names, **{c: getattr(sp, c) for c in TEXT_CONSTANTS}}
        self.binary = {ast.Add: sp.Add, ast.Sub: lambda a, b: a - b, ast.Mult: sp.Mul,
                       ast.Div: lambda a, b: a / b, ast.Pow: None}  # fmt: skip

    def refuse(self, node, what):
        """Refuse ``what`` (a kind of syntax) at ``node``, quoting it."""
        raise ValueError(f"{self.where}: {what} is not allowed in an expression (numbers, "
                         f"names, + - * / ^, parentheses and functions such as sin only): "
                         f"{ast.get_source_segment(self.source, node) or self.text!r}")  # fmt: skip

    def power(self, a, b):
        """``a**b``, refused for a power of numbers with an exponent beyond 256."""
        if a.is_Number and b.is_Number and abs(float(b)) > 256:
            raise ValueError(
                f"{self.where}: a power of numbers with an exponent beyond 256: {self.text!r}"
            )
        return a**b

    def build(self, node, depth=0):
        """The SymPy expression of the syntax-tree ``node``, ``depth`` levels down."""
        if depth > 200:
            raise ValueError(f"{self.where}: the expression is nested too deeply")
        if isinstance(node, ast.Constant):
            return self.number(node)
        if isinstance(node, ast.Name):
            return self.name(node)
        if isinstance(node, ast.BinOp) and type(node.op) in self.binary:
            a, b = self.build(node.left, depth + 1), self.build(node.right, depth + 1)
            op = self.binary[type(node.op)]
            return self.power(a, b) if op is None else op(a, b)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            a = self.build(node.operand, depth + 1)
            return -a if isinstance(node.op, ast.USub) else a
        if isinstance(node, ast.Call):
            fn = self.function(node)
            return fn(*(self.build(a, depth + 1) for a in node.args))
        self.refuse(node, _REFUSED_NODES.get(type(node), f"{type(node).__name__.lower()}"))
        return None  # pragma: no cover

    def number(self, node):
        """The SymPy number of a constant: an integer or a finite float, nothing else."""
        import sympy as sp

        v = node.value
        if isinstance(v, bool) or not isinstance(v, int | float):
            self.refuse(node, f"the constant {v!r}")
        if isinstance(v, float) and not np.isfinite(v):
            raise ValueError(
                f"{self.where}: the number {self.source[node.col_offset : node.end_col_offset]}"
                " is beyond the double range"
            )
        return sp.Integer(v) if isinstance(v, int) else sp.Float(repr(v))

    def name(self, node):
        """The object of a known name; an unknown one is refused with the nearest known."""
        known, names, where = self.known, self.names, self.where
        if node.id in known:
            return known[node.id]
        if node.id in TEXT_FUNCTIONS:
            raise ValueError(f"{where}: {node.id!r} is a function: call it, "
                             f"{node.id}(...)")  # fmt: skip
        near = difflib.get_close_matches(node.id, [*known, *TEXT_FUNCTIONS], n=1,
                                         cutoff=0.6)  # fmt: skip
        hint = (
            f" (did you mean {near[0]!r}?)"
            if near
            else (f" (known: {', '.join(sorted(names))})" if names else "")
        )
        raise ValueError(f"{where}: unknown name {node.id!r}{hint}")

    def function(self, node):
        """SymPy's function that a call calls, after checking that it is one of
        :data:`TEXT_FUNCTIONS`, called by name with the right number of arguments."""
        import sympy as sp

        where = self.where
        if not isinstance(node.func, ast.Name) or node.func.id not in TEXT_FUNCTIONS:
            name = node.func.id if isinstance(node.func, ast.Name) else None
            if name is None:
                self.refuse(node, "calling anything but a function by its name")
            near = difflib.get_close_matches(name, list(TEXT_FUNCTIONS), n=1, cutoff=0.6)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise ValueError(f"{where}: unknown function {name!r}{hint}")
        if node.keywords:
            self.refuse(node, "a keyword argument")
        fn = TEXT_FUNCTIONS[node.func.id]
        lo, hi = _ARITY.get(fn, (1, 1))
        if not lo <= len(node.args) <= hi or any(isinstance(a, ast.Starred)
                                                  for a in node.args):  # fmt: skip
            raise ValueError(f"{where}: {node.func.id}() takes "
                             + (f"{lo}" if lo == hi else f"{lo} or more")
                             + f" argument(s), found {len(node.args)}")  # fmt: skip
        return getattr(sp, fn)


def parse(text: str, names: dict, where: str = "expression"):
    """The SymPy expression of ``text``, read from its syntax tree without ``eval``.

    ``text`` may hold numbers, the ``names`` given (``{name: SymPy object}``: coordinates,
    parameters, t), ``pi``, ``E``, the operators ``+ - * / ** ^`` (``^`` is a power, as in
    mathematics), parentheses and the calls of :data:`TEXT_FUNCTIONS`. Anything else — an
    attribute (``().__class__``), an index, a keyword, ``__import__``, a name not given — is
    refused with :class:`ValueError` naming ``where`` and what was found, with the nearest
    known name for a misspelt one.

    Examples
    --------
    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> parse("2*sin(x)^2 + pi", {"x": x})
    2*sin(x)**2 + pi
    >>> parse("sni(x)", {"x": x}, "potential")
    Traceback (most recent call last):
    ...
    ValueError: potential: unknown function 'sni' (did you mean 'sin'?)
    """
    import sympy as sp

    if not isinstance(text, str):
        raise ValueError(f"{where}: expected an expression as text, found {text!r}")
    if len(text) > MAX_TEXT:
        raise ValueError(f"{where}: an expression of at most {MAX_TEXT} characters, found "
                         f"{len(text)}")  # fmt: skip
    source = text.strip().replace("^", "**")  # x^2/3 is x²/3, as in mathematics
    try:
        tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        raise ValueError(f"{where}: not an expression: {text!r} ({exc.msg})") from None
    except (RecursionError, MemoryError):
        raise ValueError(f"{where}: the expression is nested too deeply") from None
    reader = _TextReader(text, source, names, where)
    try:
        expr = reader.build(tree.body)
    except (RecursionError, MemoryError):
        raise ValueError(f"{where}: the expression is nested too deeply") from None
    except (TypeError, ZeroDivisionError, OverflowError) as exc:
        raise ValueError(f"{where}: cannot be read as an expression: {text!r} ({exc})") from None
    if not isinstance(expr, sp.Expr):
        raise ValueError(f"{where}: expected a scalar expression, found {text!r}")
    return expr
