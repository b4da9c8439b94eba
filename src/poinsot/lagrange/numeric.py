"""Numerical integration of a :class:`~poinsot.lagrange.system.LagrangianSystem`.

The symbolic matrices are turned into NumPy functions once per system and parameter set
(``sympy.lambdify`` with common-subexpression elimination; cached), so no SymPy runs per step.
Each step solves the index-1 system

    [ M   −Gᵀ ] [ q̈ ]   [ f             ]
    [ G    0  ] [ λ  ] = [ −γ − stab(q, q̇) ]

with ``stab`` the constraint stabilisation:

* ``"baumgarte"`` (default): ``2α (G q̇ + b) + β² g`` (the position term on holonomic rows), so the
  residual obeys ``ë + 2α ė + β² e = 0`` — critically damped with the defaults
  ``α = β = 10 s⁻¹`` (``baumgarte=(alpha, beta)`` to change them; Baumgarte 1972);
* ``"projection"``: after every step, coordinates are projected onto ``g(q, t) = 0`` by
  Gauss–Newton minimum-norm corrections and velocities onto ``G q̇ + b = 0``;
* ``None``: neither — the drift shows in ``constraint_residual``.
"""

from __future__ import annotations

import numpy as np

from .._validation import as_gains, as_scalar
from ..display import Displayable
from .engine import _floats

__all__ = ["LagrangianSolution", "simulate"]

DEFAULT_BAUMGARTE = (10.0, 10.0)
_CACHE_ATTR = "_poinsot_numeric_cache"


class _Numeric:
    """NumPy functions of ``(q, qd, t)`` for one system and one parameter assignment."""

    def __init__(self, system, params: dict):
        import sympy as sp

        self.system = system
        self.params = dict(params)
        names = system.plain
        t = system.t
        self.u_of = None  # bound per simulation: (t, q, q̇) → input values (k,)

        values = {k: sp.Float(v) for k, v in params.items()}

        def plain(expr):
            # a flat list of entries (row-major): one function serves a sample and, with
            # arrays of samples, all of them at once (:meth:`batch`)
            entries = list(sp.Matrix(expr)) if hasattr(expr, "shape") else [expr]
            return [names.of(e).xreplace(values) for e in entries]

        missing = [str(p) for p in system.parameters if p not in params]
        if missing:
            raise ValueError(
                f"`params` must give a number for every parameter: missing {', '.join(missing)}"
            )
        args = (names.q, names.v, t, names.u)
        lam = lambda expr: sp.lambdify(args, plain(expr), modules="numpy", cse=True)  # noqa: E731
        self.M = lam(system.mass_matrix)
        self.f = lam(system.forcing)
        self.m = system.n_constraints
        self.n_hol = system.n_holonomic
        if self.m:
            self.G = lam(system.constraint_jacobian)
            self.b = lam(system.constraint_rhs)
            self.gamma = lam(system.constraint_gamma)
            self.g = lam(sp.Matrix(system.holonomic)) if self.n_hol else None
        self.energy = lam(system.energy_function)

    def mat(self, fn, q, qd, t, shape):
        u = self.u_of(t, q, qd) if self.u_of is not None else ()
        return np.asarray(fn(q, qd, t, u), dtype=float).reshape(shape)

    def batch(self, t, q, qd, u) -> dict:
        """:meth:`accelerations` (physical multipliers), ``Gᵀλ``, :meth:`residuals` and the
        energy at every sample at once: ``t`` (S,), ``q``, ``qd`` (S, n), inputs ``u`` (S, j);
        the keys of :meth:`poinsot.lagrange.engine.CompiledSystem.samples`. Vectorised: each
        lambdified function is called once with arrays, and the KKT systems are solved as a
        stack."""
        S, n, m = len(t), q.shape[1], self.m
        args = (q.T, qd.T, np.asarray(t, float), np.asarray(u, float).T)

        def ev(fn, *shape):
            cols = [np.broadcast_to(np.asarray(c, dtype=float), (S,)) for c in fn(*args)]
            return (np.stack(cols, axis=-1) if cols else np.zeros((S, 0))).reshape(S, *shape)

        M, f = ev(self.M, n, n), ev(self.f, n)
        if m:
            G, gamma = ev(self.G, m, n), ev(self.gamma, m)
            K = np.zeros((S, n + m, n + m))
            K[:, :n, :n] = M
            K[:, :n, n:] = -np.swapaxes(G, 1, 2)
            K[:, n:, :n] = G
            x = _solve_stack(K, np.concatenate([f, -gamma], axis=1))
            qdd, lam = x[:, :n], x[:, n:]
            forces = np.einsum("skj,sk->sj", G, lam)
            vel = np.einsum("skj,sj->sk", G, qd) + ev(self.b, m)
            pos = ev(self.g, self.n_hol) if self.n_hol else np.zeros((S, 0))
        else:
            qdd, lam = _solve_stack(M, f), np.zeros((S, 0))
            forces, vel, pos = np.zeros((S, n)), np.zeros((S, 0)), np.zeros((S, 0))
        return {"qdd": qdd, "lam": lam, "constraint_forces": forces, "g": pos,
                "velocity_residual": vel, "energy": ev(self.energy)}  # fmt: skip

    def bound(self, u_of):
        """A copy evaluating the system's inputs with ``u_of(t, q, q̇) → (k,)``."""
        import copy

        out = copy.copy(self)
        out.u_of = u_of
        return out

    def accelerations(self, t, q, qd, stab=None):
        """``(q̈, λ)`` from the index-1 system; ``stab`` (m,) is added to ``−γ``."""
        n, m = len(q), self.m
        M = self.mat(self.M, q, qd, t, (n, n))
        f = self.mat(self.f, q, qd, t, (n,))
        if not m:
            return np.linalg.solve(M, f), np.zeros(0)
        G = self.mat(self.G, q, qd, t, (m, n))
        rhs2 = -self.mat(self.gamma, q, qd, t, (m,))
        if stab is not None:
            rhs2 = rhs2 - stab
        K = np.zeros((n + m, n + m))
        K[:n, :n] = M
        K[:n, n:] = -G.T
        K[n:, :n] = G
        sol = np.linalg.solve(K, np.concatenate([f, rhs2]))
        return sol[:n], sol[n:]

    def residuals(self, t, q, qd):
        """``(g(q, t) (n_hol,), G q̇ + b (m,))``."""
        m = self.m
        if not m:
            return np.zeros(0), np.zeros(0)
        G = self.mat(self.G, q, qd, t, (m, len(q)))
        vel = G @ qd + self.mat(self.b, q, qd, t, (m,))
        pos = self.mat(self.g, q, qd, t, (self.n_hol,)) if self.n_hol else np.zeros(0)
        return pos, vel

    def project(self, t, q, qd, tol=1e-13, max_iter=20):
        """Nearest consistent state: Gauss–Newton on ``g(q) = 0`` (minimum-norm corrections,
        holonomic rows of G), then ``q̇ ← q̇ − G⁺ (G q̇ + b)``."""
        q = np.array(q, dtype=float)
        n = len(q)
        if self.n_hol:
            for _ in range(max_iter):
                g = self.mat(self.g, q, qd, t, (self.n_hol,))
                if np.max(np.abs(g)) <= tol * (1 + np.max(np.abs(q))):
                    break
                Gh = self.mat(self.G, q, qd, t, (self.m, n))[: self.n_hol]
                q = q - np.linalg.lstsq(Gh, g, rcond=None)[0]
        if self.m:
            G = self.mat(self.G, q, qd, t, (self.m, n))
            r = G @ qd + self.mat(self.b, q, qd, t, (self.m,))
            qd = qd - np.linalg.lstsq(G, r, rcond=None)[0]
        return q, qd


class _EngineNumeric(_Numeric):
    """The interface of :class:`_Numeric` on a system's compiled model
    (:mod:`poinsot.lagrange.engine`): the same functions of ``(q, q̇, t, u)`` without
    ``lambdify``, the accelerations, projection and :meth:`batch` computed by the core.
    ``active`` (m,) masks the constraints in play (a released one-sided constraint is out)."""

    def __init__(self, system, params: dict, engine, active=None):
        self.system = system
        self.params = dict(params)
        self.engine = engine
        self.u_of = None
        self.m = system.n_constraints
        self.n_hol = system.n_holonomic
        self.active = None if active is None else np.asarray(active, dtype=bool)
        self._p = engine.parameter_vector(params)
        model = engine.model

        def part(k):
            def fn(q, qd, t, u):
                return model.parts(float(t), _floats(q), _floats(qd), self._p, _floats(u))[k]

            return fn

        self.M, self.f, self.G, self.b, self.gamma, self.g, self.energy = map(part, range(7))

    def _u(self, t, q, qd):
        return _floats(self.u_of(t, q, qd) if self.u_of is not None else ())

    def with_active(self, active):
        """A copy with the constraints in play ``active`` (m,)."""
        import copy

        out = copy.copy(self)
        out.active = None if active is None else np.asarray(active, dtype=bool)
        return out

    def accelerations(self, t, q, qd, stab=None):
        """``(q̈, λ)`` with the physical multipliers (``stab`` is not taken: the compiled
        engine adds Baumgarte's terms itself); ``λ`` of the constraints in play."""
        if stab is not None:
            raise ValueError("the compiled engine takes the stabilisation as gains")
        q, qd = _floats(q), _floats(qd)
        qdd, lam = self.engine.model.accelerations(float(t), q, qd, self._p, self._u(t, q, qd),
                                                   self.active)  # fmt: skip
        return qdd, (lam if self.active is None else lam[self.active])

    def project(self, t, q, qd, tol=1e-13, max_iter=20):
        q, qd = _floats(q), _floats(qd)
        q, qd, _ = self.engine.model.project(float(t), q, qd, self._p, self._u(t, q, qd),
                                             self.active, tol, max_iter)  # fmt: skip
        return q, qd

    def batch(self, t, q, qd, u) -> dict:
        y = np.concatenate([q, qd], axis=1)
        return self.engine.samples(t, y, self._p, np.asarray(u, float), self.active)


def _solve_stack(K, r):
    """``K[s] x[s] = r[s]`` for every s; NaN rows where K[s] is singular."""
    try:
        return np.linalg.solve(K, r[..., None])[..., 0]
    except np.linalg.LinAlgError:
        out = np.full(r.shape, np.nan)
        for s in range(len(K)):
            try:
                out[s] = np.linalg.solve(K[s], r[s])
            except np.linalg.LinAlgError:
                pass
        return out


def _numeric(system, params):
    key = tuple(sorted((str(k), float(v)) for k, v in params.items()))
    cache = system.__dict__.setdefault(_CACHE_ATTR, {})
    if key not in cache:
        cache[key] = _Numeric(system, params)
    return cache[key]


class _ODE:
    """The first-order system ``y = [q, q̇]`` seen by poinsot's integrators."""

    def __init__(self, num, stabilization, baumgarte, engine=None):
        self.num = num
        self.n = num.system.n_coordinates
        self.stabilization = stabilization
        self.alpha, self.beta = baumgarte
        self.state_slices = {"q": slice(0, self.n), "qd": slice(self.n, 2 * self.n)}
        self.engine = engine  # a CompiledSystem (the core's model), or None: NumPy per step
        if engine is not None:
            self._p = engine.parameter_vector(num.params)
            self._gains = (self.alpha, self.beta) if stabilization == "baumgarte" else (0, 0)

    def stab(self, t, q, qd):
        if self.stabilization != "baumgarte" or not self.num.m:
            return None
        pos, vel = self.num.residuals(t, q, qd)
        s = 2 * self.alpha * vel
        s[: len(pos)] += self.beta**2 * pos
        return s

    def rhs(self, t, y):
        q, qd = y[: self.n], y[self.n :]
        qdd, _ = self.num.accelerations(t, q, qd, self.stab(t, q, qd))
        return np.concatenate([qd, qdd])

    def projector(self, y0):
        if self.stabilization != "projection" or not self.num.m:
            return None

        def project(y, t=None):
            q, qd = self.num.project(0.0 if t is None else t, y[: self.n], y[self.n :])
            return np.concatenate([q, qd])

        return project


class _NativeODE(_ODE):
    """The system integrated by the core (:class:`~poinsot.integrate.problem.NativeProblem`):
    the compiled model, its parameters, its inputs (constants, compiled expressions of
    ``[t, q, q̇]``, or a Python callable ``(t, q, qd)``: the slow path), Baumgarte's gains, the
    projection and the constraints in play. No Python runs per step unless an input is a
    Python callable."""

    def __init__(self, num, stabilization, baumgarte, engine, inputs, events=None):
        super().__init__(num, stabilization, baumgarte, engine)
        self._inputs = inputs
        self._projection = stabilization == "projection" and num.m > 0
        self.events = events  # the core's events tuple (see _CoreEvents), or None

    def problem(self, y0):
        from .. import _core
        from ..integrate.problem import GENERAL_METHODS, NativeProblem

        active = getattr(self.num, "active", None)
        slow = ("inputs given as Python functions",) if callable(self._inputs) else ()
        if self.events is not None and self.events[2]:
            slow += ("events given as Python functions",)
        data = (self.engine.model, self._p, self._inputs, float(self._gains[0]),
                float(self._gains[1]), self._projection, active)  # fmt: skip
        keywords = {} if self.events is None else {"events": self.events}
        return NativeProblem(_core.integrate_lagrange, data, GENERAL_METHODS, slow,
                             keywords=keywords)  # fmt: skip

    def to_internal(self, y):
        return np.array(y, dtype=float)

    from_internal = to_internal


class LagrangianSolution(Displayable):
    """Samples of a Lagrangian motion (with the notebook displays and figures of every
    result: ``_repr_html_``, ``.plot()``, ``.show()``).

    Attributes
    ----------
    t : (n_samples,)
    q, qd : (n_samples, n_coordinates), in the order the coordinates were given
    multipliers : (n_samples, n_constraints), holonomic first, sign as in (6.60)
    constraint_forces : (n_samples, n_coordinates): ``Σ_k λ_k G_kj`` (generalized; for Cartesian
        coordinates of a point, the physical reaction force on it)
    constraint_residual : (n_samples, n_holonomic): g(q, t) (NaN for a released one-sided
        constraint, whose g is then a gap, not an error)
    constraint_velocity_residual : (n_samples, n_constraints): G q̇ + b (NaN likewise)
    energy : (n_samples,): the Jacobi integral ``h = Σ q̇ ∂L/∂q̇ − L``
    accelerations : (n_samples, n_coordinates)
    t_events, y_events : lists, one array per event (runs with ``events=``)
    releases : list of (t, constraint, state)
        The one-sided constraints that let go, when, and the state ``[q, q̇]`` then (their
        multipliers are zero after).
    """

    t_events: tuple = ()
    y_events: tuple = ()
    releases: tuple = ()
    terminated = False

    def __init__(self, system, t, y, num, *, method, nfev, stabilization, phases=None):
        n = system.n_coordinates
        self.system = system
        self.params = dict(num.params)
        #: values of the system's inputs at each sample (n_samples, k)
        self.inputs = _input_values(num.u_of, t, y, n, len(system.inputs))
        self.coordinates = list(system.coordinates)
        self.t = np.asarray(t, dtype=float)
        self.q = np.asarray(y)[:, :n]
        self.qd = np.asarray(y)[:, n:]
        self.method, self.nfev, self.stabilization = method, nfev, stabilization
        m, nh = system.n_constraints, system.n_holonomic
        self.multipliers = np.zeros((len(self.t), m))
        self.accelerations = np.zeros((len(self.t), n))
        self.constraint_forces = np.zeros((len(self.t), n))
        self.constraint_residual = np.zeros((len(self.t), nh))
        self.constraint_velocity_residual = np.zeros((len(self.t), m))
        self.energy = np.zeros(len(self.t))
        phases = phases or [(self.t[0] if len(self.t) else 0.0, num, list(range(nh)))]
        starts = np.array([p[0] for p in phases])
        which = np.maximum(np.searchsorted(starts, self.t, side="right") - 1, 0)
        y = np.asarray(y, dtype=float)
        for k, (_, pnum, rows) in enumerate(phases):
            at = np.nonzero(which == k)[0]
            if not len(at):
                continue
            out = pnum.batch(self.t[at], self.q[at], self.qd[at], self.inputs[at])
            self.accelerations[at] = out["qdd"]
            self.energy[at] = out["energy"]
            if getattr(pnum, "active", None) is not None:
                # the compiled engine, constraints masked: multipliers zero for the released
                # ones, their residuals NaN (a gap, not an error)
                gone = ~pnum.active
                lam = out["lam"].copy()
                lam[:, gone] = 0.0
                self.multipliers[at] = lam
                self.constraint_forces[at] = out["constraint_forces"]
                pos, vel = out["g"].copy(), out["velocity_residual"].copy()
                pos[:, gone[:nh]] = np.nan
                vel[:, gone] = np.nan
                self.constraint_residual[at] = pos
                self.constraint_velocity_residual[at] = vel
                continue
            if pnum is num:
                self.multipliers[at] = out["lam"]
                self.constraint_forces[at] = out["constraint_forces"]
                self.constraint_residual[at] = out["g"]
                self.constraint_velocity_residual[at] = out["velocity_residual"]
                continue
            # a phase after releases: its multipliers, zero for the released constraints; the
            # original system's residuals, NaN for a released constraint (a gap, not an error)
            lam = np.zeros((len(at), m))
            lam[:, rows] = out["lam"][:, : len(rows)]
            lam[:, nh:] = out["lam"][:, len(rows) :]
            self.multipliers[at] = lam
            full = num.batch(self.t[at], self.q[at], self.qd[at], self.inputs[at])
            G = _jacobians(num, self.t[at], self.q[at], self.qd[at], self.inputs[at])
            self.constraint_forces[at] = np.einsum("skj,sk->sj", G, lam)
            gone = [i for i in range(nh) if i not in rows]
            pos, vel = full["g"].copy(), full["velocity_residual"].copy()
            pos[:, gone] = np.nan
            vel[:, gone] = np.nan
            self.constraint_residual[at] = pos
            self.constraint_velocity_residual[at] = vel

    def evaluate(self, expr):
        """A SymPy expression (or a sequence of them) in the coordinates, their speeds, t, the
        multipliers :attr:`~poinsot.lagrange.LagrangianSystem.lam_vec` and the parameters, at
        every sample: array (n_samples,) (or (n_samples, k)). One vectorised ``lambdify``.

        Examples
        --------
        >>> from poinsot.models import pendulum_cartesian
        >>> model = pendulum_cartesian()
        >>> sol = model.simulate((0, 1), t_eval=[0, 0.5, 1])
        >>> x, y = model.system.coordinates
        >>> bool(abs(sol.evaluate(x**2 + y**2) - 1).max() < 1e-6)
        True
        """
        import sympy as sp

        system = self.system
        many = not isinstance(expr, sp.Basic)
        exprs = list(expr) if many else [expr]
        names = system.plain
        values = {k: sp.Float(v) for k, v in self.params.items()}
        body = [names.of(e).xreplace(values) for e in exprs]
        fn = sp.lambdify((system.t, names.q, names.v, names.lam, names.u), body, modules="numpy",
                         cse=True)  # fmt: skip
        cols = fn(self.t, self.q.T, self.qd.T, self.multipliers.T, self.inputs.T)
        out = np.column_stack([np.broadcast_to(np.asarray(c, float), self.t.shape) for c in cols])
        return out if many else out[:, 0]

    @property
    def invariants(self):
        """The system's :meth:`~poinsot.lagrange.LagrangianSystem.constants_of_motion` along
        this motion, as :class:`~poinsot.conservation.Invariant` objects (all conserved by
        the problem; their change is integration error)."""
        import sympy as sp

        from ..conservation import Invariant

        out = []
        for name, symbol, unit, expr, reason in self.system.constants_of_motion():
            values = self.evaluate(expr)
            terms = sp.Add.make_args(sp.expand(expr))
            size = np.abs(self.evaluate(terms)).sum(axis=1).max()  # when x(0) = 0
            scale = float(abs(values[0])) or float(size) or 1.0
            out.append(Invariant(name, symbol, unit, values, True, reason, scale))
        return out

    def __getitem__(self, coordinate):
        """The samples (n_samples,) of one coordinate: ``sol[x]``."""
        return self.q[:, self.coordinates.index(coordinate)]

    def __repr__(self):
        return (
            f"LagrangianSolution(n={len(self.t)}, coordinates={self.coordinates}, "
            f"method={self.method!r}, stabilization={self.stabilization!r})"
        )


def _jacobians(num, t, q, qd, u):
    """``G`` (S, m, n) at every sample (vectorised)."""
    S, n = q.shape
    cols = num.G(q.T, qd.T, np.asarray(t, float), np.asarray(u, float).T)
    cols = [np.broadcast_to(np.asarray(c, dtype=float), (S,)) for c in cols]
    return np.stack(cols, axis=-1).reshape(S, num.m, n)


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

    def u_of(t, q, qd):
        return np.array([float(f(t, q, qd)) for f in funcs])

    #: the values when every input is a constant (the core takes them), else None
    u_of.constant = np.array(constants) if len(constants) == len(names) else None
    #: the inputs as compiled expressions of [t, q, q̇] when each is a number or a SymPy
    #: expression (the core evaluates them), else None
    u_of.compiled = compiled
    return u_of


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


def check_run_options(method, stabilization):
    """The solver class of ``method`` (one for general ODEs), with ``stabilization`` checked."""
    from ..integrate.base import get_solver

    if stabilization not in ("baumgarte", "projection", None):
        raise ValueError(
            f"`stabilization` must be 'baumgarte', 'projection' or None, found {stabilization!r}"
        )
    solver = get_solver(method)
    if solver.requires != "ode":
        raise ValueError(
            f"`method` {solver.name!r} integrates rigid bodies; use 'dop853' or "
            "'rk4' for Lagrangian systems"
        )
    return solver


def simulate(
    system,
    t_span,
    *,
    q0,
    qd0=None,
    params=None,
    method="dop853",
    dt=None,
    rtol=1e-10,
    atol=1e-12,
    t_eval=None,
    stabilization="baumgarte",
    baumgarte=DEFAULT_BAUMGARTE,
    guess=None,
    inputs=None,
    events=None,
    event_resolution=2001,
    engine="compiled",
    max_steps=None,
) -> LagrangianSolution:
    """Integrate the equations of motion of ``system``.

    Parameters
    ----------
    t_span : (t0, t1)
    q0, qd0 : dict {coordinate: value}
        Initial coordinates and velocities. With constraints, dependent coordinates and
        velocities may be omitted and are solved for (``guess`` {coordinate: value} starts the
        Newton iteration for omitted coordinates); given values inconsistent with the
        constraints are refused with the residual. Omitted velocities of an unconstrained
        system are zero.
    params : dict {symbol: number}
        Values of every parameter (``system.parameters``).
    method, dt, rtol, atol, t_eval
        As for :func:`poinsot.simulate` (``rk4`` or ``dop853``; the Lie-group and splitting
        methods are for rigid bodies).
    stabilization : {"baumgarte", "projection", None}
    baumgarte : (alpha, beta)
        Baumgarte gains in s⁻¹ (default (10, 10): critically damped).
    inputs : dict {input: value}, optional
        A value for every specified input of the system (``system.inputs``, by function or
        name): a number, a function of ``t``, or a function of ``(t, q, q̇)`` (feedback; ``q``
        and ``q̇`` arrays in the order of the coordinates). A missing input is refused, named.
    events : callable, expression, Event or a sequence of them, optional
        Functions ``g(t, y)`` of the state ``y = [q, q̇]`` whose zeros are located, as in
        :func:`scipy.integrate.solve_ivp` (attributes ``terminal`` and ``direction``), or
        SymPy expressions in the coordinates, their derivatives, time and the parameters
        (options by :class:`~poinsot.integrate.events.Event`), compiled to machine code;
        found in ``sol.t_events``, ``sol.y_events``. A terminal event ends the run there.
        The compiled engine locates every event inside the core's time loop (a Python
        function is called back from it: the slow path); the NumPy engine on a grid.
    event_resolution : int
        Events, and the release of one-sided constraints (``system.unilateral``), are
        detected at the steps' ends and at points no further apart than a grid of this many
        points on the run, then located to the integrator's accuracy (Brent's method on the
        step's dense output or restarted step: :mod:`poinsot.integrate.events`);
        ``sol.releases`` lists the releases.
    engine : {"compiled", "numpy"}
        How the equations are evaluated. ``"compiled"`` (default): the model's expressions
        (M, f, G, b, γ, g, h with shared subexpressions, parameters and inputs as runtime
        arguments) compiled to machine code in the core in milliseconds
        (:mod:`poinsot.lagrange.engine`), and the KKT solve, stabilisation and projection in
        the core: no Python per step, unless an input is a Python function (the slow path).
        ``"numpy"``: SymPy's ``lambdify`` and NumPy per step, the independent route the
        compiled engine is tested against.
    """
    from ..integrate.driver import IntegrationError, integrate
    from ..integrate.solve import (
        SimulationError,
        check_budget,
        check_sampling,
        check_t_span,
        check_tolerances,
    )

    t0, t1 = check_t_span(t_span)
    if engine not in ("numpy", "compiled"):
        raise ValueError(f"`engine` must be 'compiled' or 'numpy', found {engine!r}")
    solver = check_run_options(method, stabilization)
    params = as_params(params, system)
    t_eval, _, dt = check_sampling(t_eval, t0, t1, 1, dt)
    rtol, atol = check_tolerances(rtol, atol)
    budget = check_budget(solver, t0, t1, dt, max_steps)
    gains = as_gains(baumgarte, "baumgarte")
    if engine == "compiled":
        from .engine import compile_system

        compiled = compile_system(system)
        num = _EngineNumeric(system, params, compiled)
    else:
        compiled = None
        num = _numeric(system, params)
    u_of = input_function(inputs, system)
    if u_of is not None:
        num = num.bound(u_of)
    events = _expression_events(events, system, params)
    q_init = _keyed(q0, system, "q0", allow_missing=system.n_holonomic > 0)
    qd_init = _keyed(qd0, system, "qd0", allow_missing=True)
    guess_arr = _keyed(guess, system, "guess", allow_missing=True) if guess else None
    q_init, qd_init = consistent_initial_state(system, num, t0, q_init, qd_init, guess_arr)
    if t_eval is None:
        t_eval = np.linspace(t0, t1, 201)
    adaptive = solver.adaptive

    def run(ode, ta, ya, tb, times):
        if tb <= ta:
            return np.repeat(np.asarray(ya, dtype=float)[None], len(times), axis=0)
        try:
            tol = {"rtol": rtol, "atol": atol} if adaptive else {}
            out = integrate(ode, solver, (ta, tb), ya, t_eval=times, dt=dt, max_steps=budget,
                            **tol)  # fmt: skip
        except IntegrationError as exc:
            raise SimulationError(str(exc), None) from exc
        run.nfev += out.nfev
        run.method = out.method
        return out.y

    run.nfev, run.method = 0, solver.name

    def ode_of(anum, events=None):
        """The integrated system of ``anum``: the core's (compiled engine, with ``events``
        located in its time loop), or NumPy's."""
        if compiled is None:
            return _ODE(anum, stabilization, gains)
        return _NativeODE(anum, stabilization, gains, compiled, _core_inputs(u_of), events)

    y_init = np.concatenate([q_init, qd_init])
    if not events and not system.unilateral:  # one run, no event to watch
        out_y = run(ode_of(num), t0, y_init, t1, t_eval)
        return LagrangianSolution(system, t_eval, out_y, num, method=run.method, nfev=run.nfev,
                                  stabilization=stabilization)  # fmt: skip
    times = np.asarray(t_eval, float)
    return _simulate_phases(system, num, params, u_of, run, ode_of, y_init, t0, t1, times,
                            events, event_resolution, stabilization)  # fmt: skip


def _expression_events(events, system, params):
    """``events`` with each SymPy expression (bare, or the ``g`` of an
    :class:`~poinsot.integrate.events.Event`) compiled to machine code in the state
    ``[q, q̇]``, time and the parameters' values: a function ``g(t, y)`` with its options
    and a ``batch(t, Y)`` that evaluates the whole detection grid in one call. Functions pass
    through; an expression in anything else (an input, an unknown symbol) is refused,
    named."""
    import sympy as sp

    from ..expressions import ExpressionError, compile_expressions
    from ..integrate.events import Event, event_items

    names = system.plain
    inputs = [*names.q, *names.v, system.t]
    out = []
    for i, item in enumerate(event_items(events)):
        g = item.g if isinstance(item, Event) else item
        if callable(g) or not isinstance(g, sp.Basic):
            out.append(item)  # a function, or refused by normalize_events
            continue
        expr = names.of(g).xreplace({k: sp.Float(v) for k, v in params.items()})
        try:
            fn = compile_expressions([expr], inputs)
        except ExpressionError as exc:
            strangers = sorted(map(str, expr.free_symbols - set(inputs)))
            allowed = ", ".join(str(c) for c in (*system.coordinates, *system.parameters))
            reason = (
                f"{strangers[0]} is not a coordinate, its derivative, t or a parameter ({allowed})"
                if strangers
                else str(exc)
            )
            raise ValueError(f"`events[{i}]` = {g}: {reason}") from None

        def many(t, Y, fn=fn):
            x = np.column_stack([np.asarray(Y, dtype=float), np.asarray(t, dtype=float)])
            return fn(x)[:, 0]

        def one(t, y, many=many):
            return float(many(np.array([t], dtype=float), np.asarray(y, dtype=float)[None])[0])

        one.batch = many
        one.expression = expr  # compiled with the run's other expressions in the core
        one.terminal = bool(getattr(item, "terminal", False))
        one.direction = float(getattr(item, "direction", 0.0))
        out.append(one)
    return out


def _input_values(u_of, t, y, n, k):
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


def _core_inputs(u_of):
    """The inputs as the core takes them: constants (an array), compiled expressions, or the
    Python function ``(t, q, qd)`` (the slow path)."""
    if u_of is None:
        return np.zeros(0)
    if u_of.constant is not None:
        return np.ascontiguousarray(u_of.constant, dtype=float)
    if u_of.compiled is not None:
        return u_of.compiled
    return u_of


def _simulate_phases(system, num, params, u_of, run, ode_of, y0, t0, t1, t_eval, events,
                     resolution, stabilization):  # fmt: skip
    """The run as phases between releases of one-sided constraints: in each, the user's
    events and a "release" event per active one-sided constraint (its multiplier falling
    through zero) are watched; at a release the run goes on without that constraint (the
    compiled engine masks its row; the NumPy path derives the released system). The compiled
    engine locates every event inside the core's time loop (:func:`_core_phase`); the NumPy
    engine on a detection grid (:func:`_numpy_phase`)."""
    from ..integrate.events import normalize_events

    user = normalize_events(events)
    n_user = len(user)
    t_all, y_all, phases = [], [], []
    t_events = [[] for _ in user]
    y_events = [[] for _ in user]
    releases = []
    compiled = isinstance(num, _EngineNumeric)
    active = system  # the system of this phase (NumPy path)
    mask = np.ones(system.n_constraints, dtype=bool)  # the constraints in play (compiled)
    labels = list(range(system.n_holonomic))  # this phase's holonomic rows → the original's
    ta, ya, stop = t0, y0, False
    while True:
        if compiled:
            anum = num if mask.all() else num.with_active(mask)
            one_sided = [k for k in system.unilateral if mask[k]]
        else:
            anum = _numeric(active, params)
            if u_of is not None:
                anum = anum.bound(u_of)
            one_sided = list(active.unilateral)
        times = t_eval[(t_eval >= ta) & (t_eval <= t1)]
        if compiled:  # every event located inside the core's time loop
            t, y, log = _core_phase(system, ode_of, anum, run, user, one_sided, ta, ya, t1,
                                    times, resolution)  # fmt: skip
        else:
            t, y, log = _numpy_phase(anum, run, ode_of, u_of, system, user, one_sided, ta, ya,
                                     t1, times, resolution)  # fmt: skip
        for k in range(n_user):
            t_events[k] += list(log.t_events[k])
            y_events[k] += list(log.y_events[k])
        phases.append((ta, anum, list(labels)))
        if log.terminated_by is None or log.terminated_by < n_user:  # the end, or a user's stop
            t_all.append(t)
            y_all.append(y)
            stop = log.terminated_by is not None
            break
        gone = one_sided[log.terminated_by - n_user]  # a one-sided constraint lets go
        t_all.append(t[:-1])  # the release instant is not a requested sample
        y_all.append(y[:-1])
        ta, ya = float(t[-1]), y[-1]
        if compiled:
            releases.append((ta, str(system.holonomic[gone]), ya.copy()))
            mask[gone] = False
            labels.remove(gone)
        else:
            releases.append((ta, str(active.holonomic[gone]), ya.copy()))
            active = active.released(gone)
            labels.pop(gone)
    t_out = np.concatenate(t_all)
    y_out = np.vstack(y_all)
    sol = LagrangianSolution(system, t_out, y_out, num, method=run.method, nfev=run.nfev,
                             stabilization=stabilization, phases=phases)  # fmt: skip
    sol.t_events = [np.array(v) for v in t_events]
    sol.y_events = [np.array(v).reshape(len(v), -1) for v in y_events]
    sol.releases = releases
    sol.terminated = stop
    return sol


def _core_phase(system, ode_of, anum, run, user, one_sided, ta, ya, t1, times, resolution):
    """One phase on the compiled engine with its events located inside the core's time loop
    (``poinsot_core::events``): the user's expressions compiled together in ``[q, q̇, t]``,
    the user's functions called back (the slow path), and per one-sided constraint in play its
    multiplier falling through zero (terminal). Detection points are no further apart than
    the grid of ``resolution`` points on ``[ta, t1]``. Returns the samples ``t``, ``y`` (a
    terminal zero's time and state appended last) and an
    :class:`~poinsot.integrate.events.EventLog` (user events first, then the releases)."""
    from ..expressions import compile_expressions
    from ..integrate.events import EventLog

    names = system.plain
    exprs, callables, sources, terminal, direction = [], [], [], [], []
    for g, term, sense in user:
        expr = getattr(g, "expression", None)
        if expr is not None:
            sources.append((0, len(exprs)))
            exprs.append(expr)
        else:
            sources.append((1, len(callables)))
            callables.append(g)
        terminal.append(term)
        direction.append(sense)
    for k in one_sided:
        sources.append((2, k))
        terminal.append(True)
        direction.append(-1.0)
    compiled = compile_expressions(exprs, [*names.q, *names.v, system.t]) if exprs else None
    found = []
    spacing = (t1 - ta) / (max(int(resolution), 2) - 1) if t1 > ta else np.inf
    events = (compiled, np.array(sources, dtype=np.int64).reshape(-1, 2), callables,
              np.array(terminal, dtype=bool), np.array(direction, dtype=float),
              float(spacing), found)  # fmt: skip
    y = np.asarray(run(ode_of(anum, events), ta, ya, t1, times), dtype=float)
    t = np.asarray(times[: len(y)], dtype=float)
    n_events = len(sources)
    log = EventLog([[] for _ in range(n_events)], [[] for _ in range(n_events)])
    for k, tz, yz in found:
        log.t_events[k].append(float(tz))
        log.y_events[k].append(np.asarray(yz, dtype=float))
        if terminal[k] and log.terminated_by is None:
            log.terminated_by, stop = int(k), (float(tz), np.asarray(yz, dtype=float))
    dim = len(ya)
    log.t_events = [np.array(v, dtype=float) for v in log.t_events]
    log.y_events = [np.array(v, dtype=float).reshape(len(v), dim) for v in log.y_events]
    if log.terminated_by is not None:
        tz, yz = stop
        before = t < tz
        t = np.append(t[before], tz)
        y = np.vstack([y[before].reshape(-1, dim), yz])
    return t, y.reshape(len(t), dim), log


def _numpy_phase(anum, run, ode_of, u_of, system, user, one_sided, ta, ya, t1, times,
                 resolution):  # fmt: skip
    """One phase on the NumPy engine (the cross-check): the events and the releases located
    on a grid by :func:`~poinsot.integrate.events.integrate_with_events`."""
    from ..integrate.events import integrate_with_events

    ode = ode_of(anum)
    watch = [g for g, _, _ in user]
    for k in one_sided:  # numbered in the phase's (released) system

        def release(t, y, k=k, n=system.n_coordinates):
            return anum.accelerations(t, y[:n], y[n:])[1][k]

        def released(t, Y, k=k, n=system.n_coordinates):
            # every grid state's multipliers in one call
            u = _input_values(u_of, t, Y, n, len(system.inputs))
            return anum.batch(t, Y[:, :n], Y[:, n:], u)["lam"][:, k]

        release.terminal, release.direction, release.batch = True, -1, released
        watch.append(release)
    return integrate_with_events(
        lambda a, ya_, b, tt: run(ode, a, ya_, b, tt), watch, ta, ya, t1, times,
        resolution=resolution)  # fmt: skip
