"""The arguments of a Lagrangian run, checked once at the boundary: parameters by symbol or
name, coordinates and velocities keyed by coordinate, the inputs (numbers, functions of t or
of the state, SymPy expressions compiled with the model), and the initial state completed and
checked against the constraints (by whatever evaluates the model: the compiled engine in the
library, the reference oracle in the tests)."""

from __future__ import annotations

import numpy as np

from .._validation import as_scalar

__all__ = ["as_params", "consistent_initial_state", "input_function", "input_values"]


def _keyed(values, system, name, allow_missing):
    """Array (n,) from ``{coordinate: value}``; missing → NaN (to be solved for)."""
    out = np.full(system.n_coordinates, np.nan)
    if values is None:
        return out
    if not isinstance(values, dict):
        raise TypeError(
            f"`{name}` must be a dict {{coordinate: value}}, found {type(values).__name__}"
        )
    index = {c: i for i, c in enumerate(system.coordinates)}  # hashing: no SymPy comparison
    for key, value in values.items():
        i = index.get(key)
        if i is None:
            raise ValueError(
                f"`{name}`: {key} is not a coordinate of the system "
                f"(coordinates: {system.coordinates})"
            )
        if type(value) is float and np.isfinite(value):  # the common case, without a label
            out[i] = value
        else:
            out[i] = as_scalar(value, f"{name}[{key}]")
    if not allow_missing and np.any(np.isnan(out)):
        missing = [str(system.coordinates[i]) for i in np.nonzero(np.isnan(out))[0]]
        raise ValueError(
            f"`{name}` must give every coordinate of an unconstrained system: "
            f"missing {', '.join(missing)}"
        )
    return out


def as_params(params, system) -> dict:
    """``{symbol: float}`` from ``params`` given by symbol or by name (``{"g": 9.81}``);
    unknown names and non-numbers are refused, named."""
    if params is None:
        return {}
    if not isinstance(params, dict):
        raise TypeError(
            "`params` must be a dict {parameter: value} (symbols or their names), found "
            f"{type(params).__name__}"
        )
    by_name = {str(p): p for p in system.parameters}
    known = set(system.parameters)
    out = {}
    for key, value in params.items():
        symbol = key if key in known else by_name.get(str(key))  # by symbol or by name
        if symbol is None:
            raise ValueError(
                f"`params`: {key!r} is not a parameter of the system (parameters: "
                f"{', '.join(by_name) or 'none'})"
            )
        x = as_scalar(value, f"params[{key}]")
        if 0 < abs(x) < np.finfo(float).tiny:
            raise ValueError(f"`params[{key}]` = {x:g} is below the range of double precision "
                             "(subnormal: products with it lose their digits); choose other "
                             "units, or give 0")  # fmt: skip
        if symbol in out and out[symbol] != x:
            raise ValueError(f"`params`: {symbol} is given twice with two values, "
                             f"{out[symbol]} and {x}")  # fmt: skip
        out[symbol] = x
        # the equations were derived under the symbol's assumptions (√(l²) = l for l > 0)
        if symbol.is_positive and not out[symbol] > 0:
            raise ValueError(f"`params[{key}]` must be positive ({symbol} is declared "
                             f"positive), found {out[symbol]}")  # fmt: skip
        if symbol.is_nonnegative and not out[symbol] >= 0:
            raise ValueError(f"`params[{key}]` must be non-negative ({symbol} is declared "
                             f"non-negative), found {out[symbol]}")  # fmt: skip
    return out


def input_function(inputs, system):
    """``(t, q, q̇) → values (k,)`` of the system's inputs from ``inputs`` ({input: number,
    f(t) or f(t, q, q̇)}, by function or name), or None for a system without inputs; missing,
    unknown and ill-typed inputs are refused, named."""
    import inspect

    names = list(system.inputs)
    if inputs is not None and not isinstance(inputs, dict):
        raise TypeError(f"`inputs` must be a dict {{input: value}}, found {type(inputs).__name__}")
    if not names:
        if inputs:
            raise ValueError("`inputs`: the system has no inputs (functions of t that are "
                             "neither coordinates nor parameters)")  # fmt: skip
        return None
    by_name = {str(u).replace("(t)", ""): u for u in names}
    given = {}
    for key, value in (inputs or {}).items():
        u = by_name.get(key) if isinstance(key, str) else key
        if u not in names:
            raise ValueError(f"`inputs`: {key!r} is not an input of the system (inputs: "
                             f"{', '.join(by_name)})")  # fmt: skip
        given[u] = value
    missing = [str(u) for u in names if u not in given]
    if missing:
        raise ValueError(
            f"`inputs` must give every input of the system: missing {', '.join(missing)} "
            "(a number, a function of t, or a function of (t, q, qd))"
        )
    funcs, constants, exprs = [], [], []
    sp = _sympy_if_needed(given.values())
    for u in names:
        value, label = given[u], f"inputs[{str(u).replace('(t)', '')}]"
        if sp is not None and isinstance(value, sp.Basic) and not value.is_Number:
            exprs.append(_input_expression(value, system, label))
            funcs.append(None)
        elif callable(value):
            try:
                arity = len(inspect.signature(value).parameters)
            except (TypeError, ValueError):
                arity = 1
            if arity not in (1, 3):
                raise TypeError(f"`{label}` must take (t) or (t, q, qd), found {arity} parameters")
            funcs.append((lambda f: lambda t, q, qd: f(t))(value) if arity == 1 else value)
        else:
            c = as_scalar(value, label)
            funcs.append(lambda t, q, qd, c=c: c)
            constants.append(c)
            exprs.append(c)
    compiled = None
    if len(exprs) == len(names) and len(constants) < len(names):
        from ..expressions import compile_expressions

        plain = system.plain
        args = [system.t, *plain.q, *plain.v]
        compiled = compile_expressions([sp.sympify(plain.of(e)) for e in exprs], args)
        n = system.n_coordinates

        def evaluate(t, q, qd):
            row = np.concatenate([[t], np.asarray(q, float), np.asarray(qd, float)])
            return compiled(row.reshape(1, 1 + 2 * n))[0]

        def component(i):
            return lambda t, q, qd: evaluate(t, q, qd)[i]

        funcs = [component(i) if f is None else f for i, f in enumerate(funcs)]

    labels = [f"inputs[{str(u).replace('(t)', '')}]" for u in names]

    def u_of(t, q, qd):
        return np.array([_input_value(f, label, t, q, qd)
                         for f, label in zip(funcs, labels, strict=True)])  # fmt: skip

    #: the values when every input is a constant (the core takes them), else None
    u_of.constant = np.array(constants) if len(constants) == len(names) else None
    #: the inputs as compiled expressions of [t, q, q̇] when each is a number or a SymPy
    #: expression (the core evaluates them), else None
    u_of.compiled = compiled
    return u_of


class InputError(ValueError):
    """An input of a Lagrangian system (a user's function, or an expression) raised, or gave
    something other than a finite real number: the message names the input and the time t,
    and the original exception is the cause."""


def _input_value(f, label, t, q, qd) -> float:
    """The value of the input ``label`` at ``(t, q, q̇)``: a finite real number, or an
    :class:`InputError` naming the input, the time and what was wrong (the user's own
    exception kept as the cause; an interrupt passes through untouched)."""
    try:
        value = f(t, q, qd)
    except Exception as exc:
        raise InputError(f"`{label}` raised {type(exc).__name__} at t = {float(t):.17g}: "
                         f"{exc}") from exc  # fmt: skip
    if np.iscomplexobj(value) and np.imag(value) != 0:
        raise InputError(f"`{label}` returned the complex number {complex(value)} at t = "
                         f"{float(t):.17g}: an input must be real")  # fmt: skip
    try:
        x = float(np.real(value))
    except (TypeError, ValueError):
        raise InputError(f"`{label}` returned {value!r} at t = {float(t):.17g}: an input must "
                         "be a number") from None  # fmt: skip
    if not np.isfinite(x):
        raise InputError(f"`{label}` returned {x} at t = {float(t):.17g}: an input must be "
                         "finite")  # fmt: skip
    return x


def _sympy_if_needed(values):
    """SymPy, when one of ``values`` is a SymPy object (without importing it otherwise)."""
    import sys

    sp = sys.modules.get("sympy")
    if sp is None:
        return None
    return sp if any(isinstance(v, sp.Basic) for v in values) else None


def _input_expression(value, system, label):
    """A SymPy input: an expression in t, the coordinates and their speeds, checked."""
    import sympy as sp

    allowed = {system.t, *system.coordinates, *system.speeds}
    atoms = (value.atoms(sp.Symbol) | value.atoms(sp.core.function.AppliedUndef)
             | value.atoms(sp.Derivative))  # fmt: skip
    stray = sorted(str(a) for a in atoms - allowed)
    if stray:
        raise ValueError(
            f"`{label}` = {value} may depend only on t, the coordinates and their speeds; "
            f"found {', '.join(stray)}"
        )
    return value


def consistent_initial_state(system, num, t0, q0, qd0, guess=None, tol=1e-9):
    """Complete and check ``q0``, ``qd0`` (arrays with NaN where omitted) against the
    constraints: omitted coordinates solve ``g(q) = 0`` by Newton from ``guess`` (default 0),
    omitted velocities solve ``G q̇ + b = 0``; given values that violate the constraints by more
    than ``tol`` (scaled) are refused with the residual."""
    n, m, nh = system.n_coordinates, system.n_constraints, system.n_holonomic
    q = q0.copy()
    free_q = np.isnan(q)
    if free_q.any():
        if free_q.sum() > nh:
            raise ValueError(
                f"`q0` leaves {int(free_q.sum())} coordinates to solve for but "
                f"there are only {nh} holonomic constraints"
            )
        q[free_q] = 0.0 if guess is None else guess[free_q]
        q[free_q & np.isnan(q)] = 0.0
        zeros = np.zeros(n)
        for _ in range(50):
            g = num.mat(num.g, q, zeros, t0, (nh,))
            if np.max(np.abs(g)) <= 1e-14 * (1 + np.max(np.abs(q))):
                break
            J = num.mat(num.G, q, zeros, t0, (m, n))[:nh][:, free_q]
            q[free_q] -= np.linalg.lstsq(J, g, rcond=None)[0]
    qd = qd0.copy()
    if nh:
        g = num.mat(num.g, q, np.zeros(n), t0, (nh,))
        scale = 1 + np.max(np.abs(q))
        if np.max(np.abs(g)) > tol * scale:
            solved = " (the coordinates solved for from `guess`)" if free_q.any() else ""
            raise ValueError(
                f"`q0`: inconsistent initial conditions: the holonomic constraints are "
                f"violated by max |g(q0)| = {np.max(np.abs(g)):.3g}{solved}"
            )
    free_v = np.isnan(qd)
    if m:
        G = num.mat(num.G, q, np.zeros(n), t0, (m, n))
        b = num.mat(num.b, q, np.zeros(n), t0, (m,))
        if free_v.any():
            known = np.where(free_v, 0.0, qd)
            sol = np.linalg.lstsq(G[:, free_v], -(G @ known + b), rcond=None)[0]
            qd = known.copy()
            qd[free_v] = sol
        r = G @ qd + b
        if np.max(np.abs(r)) > tol * (1 + np.max(np.abs(qd))):
            raise ValueError(
                f"`qd0`: inconsistent initial conditions: the velocity constraints are "
                f"violated by max |G q̇0 + b| = {np.max(np.abs(r)):.3g}"
            )
    elif free_v.any():
        qd[free_v] = 0.0
    try:  # the equations of motion must be solvable here
        qdd, _ = num.accelerations(t0, q, qd)
    except np.linalg.LinAlgError:
        qdd = np.array([np.nan])
    if not np.isfinite(qdd).all():
        raise ValueError(
            "`q0`, `params`: the equations of motion cannot be solved at the initial state: "
            "the mass matrix "
            "(with the constraint Jacobian) is singular — zero masses or inertia, or a "
            "coordinate that does not enter the kinetic energy"
        )
    return q, qd


def input_values(u_of, t, y, n, k):
    """The inputs ``u_of`` at samples ``t`` (S,), ``y`` (S, 2n): (S, k)."""
    constant = getattr(u_of, "constant", None)
    if u_of is None:
        out = np.zeros((len(t), 0))
    elif constant is not None:
        out = np.tile(constant, (len(t), 1))
    else:  # the user's functions, sample by sample
        rows = zip(t, np.asarray(y)[:, :n], np.asarray(y)[:, n:], strict=True)
        out = np.array([u_of(ti, qi, qdi) for ti, qi, qdi in rows])
    return out.reshape(len(t), k)
