"""Reaction forces that minimal coordinates hide (``docs/theory.md`` §3, eqs (6.49)–(6.61)).

A model written in minimal coordinates has no multiplier for the constraints its coordinates
satisfy by construction: the double pendulum in its two angles keeps its rods' lengths, so it
has no rod tensions. To get such a force, free the constraint: write the model with an
*auxiliary coordinate* ``ρ(t)`` where the constraint holds it (the rod's length, the pivot's
position, the table's height) and declare it with :class:`HiddenConstraint` (``ρ = value``).
poinsot then keeps two systems:

* the model itself, in the minimal coordinates, with ``ρ = value`` substituted after the
  Lagrangian is formed (so it is exactly the minimal model);
* the *augmented* system, in the coordinates and ρ, with the holonomic constraint
  ``ρ − value = 0``, whose multiplier λ is the generalized constraint force conjugate to ρ
  (6.60): for ρ a length along which the bodies beyond the joint move, the force along that
  direction — the named physical force ``sign · λ``.

:meth:`~poinsot.lagrange.LagrangianSystem.reaction_forces` evaluates the augmented system's
multipliers at the states of a run of the minimal one (or at an equilibrium): no second
integration, so the forces belong to exactly the motion computed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["HiddenConstraint", "reaction_forces"]


@dataclass(frozen=True)
class HiddenConstraint:
    """A constraint the minimal coordinates satisfy by construction, freed to give its force.

    Parameters
    ----------
    coordinate : SymPy function of t
        The auxiliary coordinate ρ(t) (``dynamicsymbols``) that the model's positions use where
        the constraint holds it: a rod's length, a pivot's coordinate, a table's height.
    value : SymPy expression or number
        What the constraint holds ρ at (a parameter such as the rod length ``l``, a number,
        or a function of t and the coordinates).
    name : str
        The force's name, e.g. ``"rod 1 tension T1"``.
    unit : str
        Its unit (``"N"`` for a length or position ρ; ``"N·m"`` for an angle).
    sign : float
        The named force is ``sign · λ``, λ the generalized force on ρ (6.60): +1 for the
        force pushing along increasing ρ (a pivot's push, a table's normal force), −1 for a
        tension (a rod pulling its bob back, toward decreasing length).
    meaning : str
        What the force is, in words.
    """

    coordinate: object
    value: object
    name: str
    unit: str = "N"
    sign: float = 1.0
    meaning: str = ""


def _check(hidden, coordinates, t):
    """The declarations, checked: distinct auxiliary functions of t, not coordinates, with
    values free of every auxiliary coordinate."""
    import sympy as sp

    out = []
    for i, h in enumerate(hidden):
        if not isinstance(h, HiddenConstraint):
            raise TypeError(f"`hidden[{i}]` must be a HiddenConstraint, found {type(h).__name__}")
        rho = h.coordinate
        if not (isinstance(rho, sp.Function | sp.core.function.AppliedUndef) and rho.args == (t,)):
            raise ValueError(
                f"`hidden[{i}].coordinate` = {rho} must be a function of time (dynamicsymbols)"
            )
        if rho in coordinates:
            raise ValueError(
                f"`hidden[{i}].coordinate` = {rho} is one of the coordinates: the auxiliary "
                "coordinate is the one the constraint holds fixed"
            )
        if not (isinstance(h.sign, int | float) and h.sign in (1, -1, 1.0, -1.0)):
            raise ValueError(f"`hidden[{i}].sign` must be +1 or -1, found {h.sign!r}")
        out.append(h)
    aux = [h.coordinate for h in out]
    if len(set(aux)) != len(aux):
        raise ValueError("`hidden`: the auxiliary coordinates must be distinct")
    for i, h in enumerate(out):
        if any(sp.sympify(h.value).has(a) for a in aux):
            raise ValueError(f"`hidden[{i}].value` must not contain an auxiliary coordinate")
    return tuple(out)


def _held(expr, hidden):
    """``expr`` with every auxiliary coordinate replaced by the value its constraint holds it
    at (derivatives of ρ by the derivatives of the value)."""
    import sympy as sp

    e = sp.sympify(expr)
    for h in hidden:
        e = e.subs(h.coordinate, sp.sympify(h.value))
    return e.doit() if e.has(sp.Derivative) else e


class _Evaluator:
    """NumPy functions of ``(t, q, v, u)`` (arrays of samples) giving the augmented system's
    index-1 matrix and right-hand side and the auxiliary coordinates' values and rates."""

    def __init__(self, minimal, augmented, params):
        import sympy as sp

        names = augmented.plain
        t = augmented.t
        values = {k: sp.Float(v) for k, v in params.items()}
        missing = [str(p) for p in augmented.parameters if p not in params]
        if missing:
            raise ValueError(
                f"`params` must give a number for every parameter: missing {', '.join(missing)}"
            )

        def entries(m):
            return [names.of(e).xreplace(values) for e in list(m)]

        args = (t, names.q, names.v, names.u)
        self.K = sp.lambdify(args, entries(augmented.augmented_matrix), "numpy", cse=True)
        self.F = sp.lambdify(args, entries(augmented.augmented_forcing), "numpy", cse=True)
        # the auxiliary coordinates as the minimal state holds them: ρ = value, ρ̇ = d value/dt
        low = minimal.plain
        held = [sp.sympify(h.value) for h in minimal.hidden]
        rates = [sp.diff(v, t) for v in held]
        low_args = (t, low.q, low.v, low.u)
        self.rho = sp.lambdify(low_args, [low.of(v).xreplace(values) for v in held], "numpy")
        self.rho_dot = sp.lambdify(low_args, [low.of(v).xreplace(values) for v in rates],
                                   "numpy")  # fmt: skip
        self.n, self.m = augmented.n_coordinates, augmented.n_constraints

    @staticmethod
    def _columns(fn, args, S):
        cols = fn(*args)
        return np.stack([np.broadcast_to(np.asarray(c, float), (S,)) for c in cols], axis=-1)

    def multipliers(self, t, q, qd, u):
        """λ (S, m) of the augmented system at the minimal states (S samples)."""
        S = len(t)
        low = (t, q.T, qd.T, u.T)
        rho = self._columns(self.rho, low, S)
        rho_dot = self._columns(self.rho_dot, low, S)
        Q = np.concatenate([q, rho], axis=1)
        V = np.concatenate([qd, rho_dot], axis=1)
        args = (t, Q.T, V.T, u.T)
        N = self.n + self.m
        K = self._columns(self.K, args, S).reshape(S, N, N)
        F = self._columns(self.F, args, S)
        x = np.linalg.solve(K, F[..., None])[..., 0]
        return x[:, self.n :]


def _evaluator(system, params) -> _Evaluator:
    key = tuple(sorted((str(k), float(v)) for k, v in params.items()))
    cache = system.__dict__.setdefault("_poinsot_reaction_cache", {})
    if key not in cache:
        cache[key] = _Evaluator(system, system.augmented, params)
    return cache[key]


def _state(values, system, name, *, required, keys=None):
    """Array of ``values`` ({key: number}) in the order of ``keys`` (default: the
    coordinates); a missing key is refused (``required``) or zero."""
    from .._validation import as_scalar

    keys = list(system.coordinates if keys is None else keys)
    if not isinstance(values, dict):
        raise TypeError(f"`{name}` must be a dict {{coordinate: value}}, found "
                        f"{type(values).__name__}")  # fmt: skip
    index = {k: i for i, k in enumerate(keys)}
    by_name = {str(k).replace("(t)", ""): i for i, k in enumerate(keys)}
    out = np.full(len(keys), np.nan if required else 0.0)
    for key, value in values.items():
        i = index.get(key, by_name.get(str(key)))
        if i is None:
            raise ValueError(f"`{name}`: {key} is not one of {', '.join(map(str, keys))}")
        out[i] = as_scalar(value, f"{name}[{key}]")
    if np.isnan(out).any():
        missing = [str(keys[i]) for i in np.nonzero(np.isnan(out))[0]]
        raise ValueError(f"`{name}` must give a value for {', '.join(missing)}")
    return out


def _params(params, system) -> dict:
    """``{symbol: float}`` from parameters given by symbol or by name."""
    from .._validation import as_scalar

    by_name = {str(p): p for p in system.augmented.parameters}
    out = {}
    for key, value in (params or {}).items():
        symbol = by_name.get(key) if isinstance(key, str) else key
        if symbol is None:
            raise ValueError(f"`params`: {key!r} is not a parameter of the system")
        out[symbol] = as_scalar(value, f"params[{key}]")
    return out


def reaction_forces(system, at, *, names=None, params=None, qd=None, t=0.0, inputs=None):
    """The forces of ``system``'s hidden constraints (:class:`HiddenConstraint`), by name.

    Parameters
    ----------
    system : LagrangianSystem
        Declared with ``hidden=``.
    at : LagrangianSolution or dict
        A run of ``system`` (the forces at every sample, arrays (n_samples,)), or a state
        ``{coordinate: value}`` such as an equilibrium (the forces there, floats).
    names : sequence of str, optional
        The forces wanted (default: all).
    params : dict, optional
        The parameters' values, for a state (a run carries its own).
    qd : dict, optional
        The speeds of a state (default zero: at rest).
    t : float
        The time of a state.
    inputs : dict, optional
        The values of the system's inputs at a state (numbers).

    Returns
    -------
    dict
        ``name → values``.
    """
    from .solution import LagrangianSolution

    hidden = getattr(system, "hidden", ())
    if not hidden:
        raise ValueError(
            "the system declares no hidden constraint: write the model with an auxiliary "
            "coordinate where the constraint holds it and pass hidden=[HiddenConstraint(...)] "
            "(see poinsot.lagrange.reactions)"
        )
    wanted = [h.name for h in hidden] if names is None else list(names)
    known = {h.name: k for k, h in enumerate(hidden)}
    for name in wanted:
        if name not in known:
            raise ValueError(f"`names`: {name!r} is not a hidden constraint of the system "
                             f"(known: {', '.join(known)})")  # fmt: skip
    if isinstance(at, LagrangianSolution):
        if at.system is not system:
            raise ValueError("`at` is a run of another system")
        if at.releases:
            raise ValueError("`at`: a run in which a one-sided constraint let go has another "
                             "set of constraints after the release; not supported")  # fmt: skip
        ev = _evaluator(system, at.params)
        lam = ev.multipliers(at.t, at.q, at.qd, at.inputs)
        single = False
    elif isinstance(at, dict):
        q = _state(at, system, "at", required=True)[None]
        v = _state(qd or {}, system, "qd", required=False)[None]
        u = _state(inputs or {}, system, "inputs", required=True, keys=system.inputs)[None]
        ev = _evaluator(system, _params(params, system))
        lam = ev.multipliers(np.array([float(t)]), q, v, u)
        single = True
    else:
        raise TypeError(
            f"`at` must be a LagrangianSolution or a state {{coordinate: value}}, found "
            f"{type(at).__name__}"
        )
    first = system.augmented.n_holonomic - len(system.augmented.unilateral) - len(hidden)
    out = {}
    for name in wanted:
        k = known[name]
        values = hidden[k].sign * lam[:, first + k]
        out[name] = float(values[0]) if single else values
    return out
