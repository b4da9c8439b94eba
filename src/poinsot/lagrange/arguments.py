"""The arguments of a Lagrangian run, checked once at the boundary: parameters by symbol or
name, coordinates and velocities keyed by coordinate, the inputs (numbers, functions of t or
of the state, SymPy expressions compiled with the model), and the initial state completed and
checked against the constraints (by whatever evaluates the model: the compiled engine in the
library, the reference oracle in the tests)."""

from __future__ import annotations

import numpy as np

from .._validation import as_scalar

__all__ = [
    "as_params",
    "consistent_initial_state",
    "input_function",
    "input_values",
    "key_index",
    "key_name",
    "refuse_off_constraints",
]


def key_name(key) -> str:
    """The name a coordinate, an input or a parameter is given by: ``x(t)`` → ``'x'``."""
    return str(key).replace("(t)", "")


def key_index(keys):
    """``key → position in keys`` (None when it is none of them) for a key given as itself (a
    coordinate, an input, a parameter's symbol) or by its name, a string (:func:`key_name`):
    the one reading of dict keys by single runs, ensembles and linearisations. ``.names`` lists
    the names accepted, for the error that refuses another."""
    by_key = {k: i for i, k in enumerate(keys)}  # hashing: no SymPy comparison
    by_name = {key_name(k): i for i, k in enumerate(keys)}

    def index(key):
        if isinstance(key, str):
            return by_name.get(key)
        try:
            return by_key.get(key)
        except TypeError:  # unhashable: none of the keys
            return None

    index.names = list(by_name)
    return index


def named(names) -> str:
    """``'x', 'y'``: the names a dict may be keyed by, quoted as a user writes them."""
    return ", ".join(map(repr, names)) or "none"


def _keyed(values, system, name, allow_missing):
    """Array (n,) from ``{coordinate: value}`` (by coordinate or by name, :func:`key_index`);
    missing → NaN (to be solved for)."""
    out = np.full(system.n_coordinates, np.nan)
    if values is None:
        return out
    if not isinstance(values, dict):
        raise TypeError(
            f"`{name}` must be a dict {{coordinate: value}}, found {type(values).__name__}"
        )
    index = key_index(system.coordinates)
    for key, value in values.items():
        i = index(key)
        if i is None:
            raise ValueError(
                f"`{name}`: {key!r} is not a coordinate of the system (coordinates: "
                f"{', '.join(map(str, system.coordinates))}, or by name {named(index.names)})"
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
    index = key_index(names)
    given = {}
    for key, value in (inputs or {}).items():
        i = index(key)
        if i is None:
            raise ValueError(f"`inputs`: {key!r} is not an input of the system (inputs: "
                             f"{', '.join(index.names)})")  # fmt: skip
        given[names[i]] = value
    missing = [str(u) for u in names if u not in given]
    if missing:
        raise ValueError(
            f"`inputs` must give every input of the system: missing {', '.join(missing)} "
            "(a number, a function of t, or a function of (t, q, qd))"
        )
    funcs, constants, exprs = [], [], []
    sp = _sympy_if_needed(given.values())
    for u in names:
        value, label = given[u], f"inputs[{key_name(u)}]"
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

    labels = [f"inputs[{key_name(u)}]" for u in names]

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


def consistent_initial_state(system, num, t0, q0, qd0, guess=None, tol=1e-9, *,
                             guessable=True):  # fmt: skip
    """Complete and check ``q0``, ``qd0`` (arrays with NaN where omitted) against the
    constraints: omitted coordinates solve ``g(q) = 0`` by Newton from ``guess`` (default 0),
    omitted velocities solve ``G q̇ + b = 0``; given values that violate the constraints by more
    than ``tol`` (scaled) are refused with the residual (:func:`refuse_off_constraints`), and
    a failed solve with where it started. A ``guess`` for a coordinate given in ``q0`` (or for
    a system without holonomic constraints, where nothing is solved for) is refused: it would
    have no effect. ``guessable``: whether the caller takes a ``guess`` (an ensemble does not),
    for the advice of a failed solve."""
    n, m, nh = system.n_coordinates, system.n_constraints, system.n_holonomic
    q = q0.copy()
    free_q = np.isnan(q)
    if guess is not None:
        idle = ~np.isnan(guess) & ~free_q
        if idle.any() and not nh:
            raise ValueError("`guess`: the system has no holonomic constraints, so no coordinate "
                             "is solved for and a guess has no effect: drop it")  # fmt: skip
        if idle.any():
            names = ", ".join(str(system.coordinates[i]) for i in np.flatnonzero(idle))
            verb = "is" if idle.sum() == 1 else "are"
            raise ValueError(f"`guess`: {names} {verb} given in `q0`, so not solved for: a "
                             "guess starts only the coordinates `q0` omits; drop it from "
                             "`guess`")  # fmt: skip
    note = ""
    if free_q.any():
        if free_q.sum() > nh:
            raise ValueError(
                f"`q0` leaves {int(free_q.sum())} coordinates to solve for but "
                f"there are only {nh} holonomic constraints"
            )
        defaulted = free_q if guess is None else free_q & np.isnan(guess)
        q[free_q] = 0.0 if guess is None else guess[free_q]
        q[defaulted] = 0.0
        note = _solve_note(system, q, free_q, defaulted, guess is not None, guessable)
        zeros = np.zeros(n)
        for _ in range(50):
            g = num.mat(num.g, q, zeros, t0, (nh,))
            if np.max(np.abs(g)) <= 1e-14 * (1 + np.max(np.abs(q))):
                break
            J = num.mat(num.G, q, zeros, t0, (m, n))[:nh][:, free_q]
            q[free_q] -= np.linalg.lstsq(J, g, rcond=None)[0]
    refuse_off_constraints(num, t0, q, None, tol=tol, notes=(note, ""))
    qd = qd0.copy()
    free_v = np.isnan(qd)
    if m:
        G = num.mat(num.G, q, np.zeros(n), t0, (m, n))
        b = num.mat(num.b, q, np.zeros(n), t0, (m,))
        if free_v.any():
            known = np.where(free_v, 0.0, qd)
            sol = np.linalg.lstsq(G[:, free_v], -(G @ known + b), rcond=None)[0]
            qd = known.copy()
            qd[free_v] = sol
        refuse_off_constraints(num, t0, q, qd, tol=tol)
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


def _solve_note(system, start, free, defaulted, guessed, guessable) -> str:
    """What a failed solve for the coordinates ``free`` adds to its message: the coordinates,
    the start of Newton's method (``start``: from ``guess``, or the default 0 where
    ``defaulted``) and what to do."""
    coords = system.coordinates

    def values(mask):
        return ", ".join(f"{coords[i]} = {start[i]:.6g}" for i in np.flatnonzero(mask))

    starts = []
    if (free & ~defaulted).any():
        starts.append(f"`guess` {values(free & ~defaulted)}")
    if defaulted.any() and guessable:
        why = "not in `guess`" if guessed else "no `guess` given"
        starts.append(f"the default start {values(defaulted)}, {why}")
    elif defaulted.any():
        starts.append(f"{values(defaulted)}")
    solved = ", ".join(str(coords[i]) for i in np.flatnonzero(free))
    example = ", ".join(f"{key_name(coords[i])!r}: ..." for i in np.flatnonzero(free))
    if not guessable:
        advice = f"give {solved} in `q0` (an ensemble takes no `guess`)"
    elif defaulted.any():
        advice = f"pass `guess`={{{example}}} near a solution"
    else:
        advice = "pass another `guess` nearer a solution"
    return f" ({solved} solved for by Newton's method from {' and '.join(starts)}: {advice})"


def refuse_off_constraints(num, t, q, qd, *, tol=1e-9, names=("q0", "qd0"),
                           point="initial conditions", at="0", notes=("", "")):  # fmt: skip
    """Refuse coordinates ``q`` off the holonomic constraints, max |g(q, t)| above ``tol`` ×
    (1 + max |q|), then velocities ``qd`` (unless None) off the velocity constraints,
    max |G q̇ + b| above ``tol`` × (1 + max |q̇|): the engine's residuals
    (``num.residuals``), one rule for initial states and operating points. The error names
    the argument (``names``: of the coordinates, of the velocities), the ``point`` and the
    size of the violation, with ``notes`` (how the values were completed) after it."""
    pos, vel = num.residuals(t, q, np.zeros(len(q)) if qd is None else qd)
    checks = [(pos, q, f"holonomic constraints are violated by max |g(q{at})|")]
    if qd is not None:
        checks.append((vel, qd, f"velocity constraints are violated by max |G q̇{at} + b|"))
    for name, note, (residual, values, what) in zip(names, notes, checks, strict=False):
        worst = float(np.max(np.abs(residual), initial=0.0))
        if not worst <= tol * (1 + float(np.max(np.abs(values), initial=0.0))):  # NaN too
            raise ValueError(f"`{name}`: inconsistent {point}: the {what} = {worst:.3g}{note}")


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
