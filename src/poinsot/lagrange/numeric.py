"""Numerical integration of a :class:`~poinsot.lagrange.system.LagrangianSystem`.

The model's expressions are compiled to machine code once per model
(:mod:`poinsot.lagrange.engine`), and the core integrates them: no Python runs per step. Each
evaluation solves the index-1 system (``crates/core/src/lagrange.rs``)

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

import re
import warnings
from dataclasses import dataclass, replace

import numpy as np

from .._validation import as_gains
from .arguments import _keyed, as_params, consistent_initial_state, input_function
from .engine import _floats
from .solution import LagrangianSolution

__all__ = [
    "CONSTRAINT_RESIDUAL_BOUND",
    "DEFAULT_TOLERANCES",
    "ConstraintDriftWarning",
    "PreparedLagrangianRun",
    "prepare",
    "simulate",
]

DEFAULT_BAUMGARTE = (10.0, 10.0)
#: The adaptive method's ``(rtol, atol)`` for a constrained system unless given.
DEFAULT_TOLERANCES = (1e-10, 1e-12)
#: The largest constraint residual max |g(q, t)| a solution keeps without a warning, relative
#: to the size of its coordinates (times 1 + max |q|): at the default tolerances the residual
#: stays near 1e-10; a solution past this bound no longer satisfies its constraints.
CONSTRAINT_RESIDUAL_BOUND = 1e-6


class ConstraintDriftWarning(UserWarning):
    """A solution's constraint residual exceeds :data:`CONSTRAINT_RESIDUAL_BOUND`: its
    coordinates have left the constraint surface (tolerances too loose, or a step too
    large, for the stabilisation to hold them)."""


def warn_on_drift(solution, rtol, atol, dt) -> None:
    """Warn (:class:`ConstraintDriftWarning`) when ``solution``'s constraint residual
    exceeds the bound, naming the residual, the bound and the settings that let it drift."""
    g = np.abs(solution.constraint_residual)
    if not g.size or not np.isfinite(g).any():
        return
    worst = float(np.nanmax(g))
    scale = 1.0 + float(np.nanmax(np.abs(solution.q), initial=0.0))
    bound = CONSTRAINT_RESIDUAL_BOUND * scale
    if worst > bound:
        how = f"rtol = {rtol:g}, atol = {atol:g}" if rtol is not None else f"dt = {dt:g}"
        warnings.warn(
            f"the constraints drifted: max |g(q, t)| = {worst:.3g}, above the bound "
            f"{bound:.3g} ({CONSTRAINT_RESIDUAL_BOUND:g} × (1 + max |q|)); with {how} the "
            "solution has left its constraints (tighten the tolerances or the step, or use "
            "stabilization='projection')",
            ConstraintDriftWarning,
            stacklevel=4,
        )


class _EngineNumeric:
    """A system's compiled model (:mod:`poinsot.lagrange.engine`) under one parameter
    assignment: the parts ``M, f, G, b, γ, g, h`` as functions of ``(q, q̇, t, u)``, and the
    accelerations, projection and :meth:`batch` computed by the core.
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

    def mat(self, fn, q, qd, t, shape):
        """The part ``fn`` (one of :attr:`M`, :attr:`f`, ...) at ``(q, q̇, t)``, shaped."""
        u = self.u_of(t, q, qd) if self.u_of is not None else ()
        return np.asarray(fn(q, qd, t, u), dtype=float).reshape(shape)

    def bound(self, u_of):
        """A copy evaluating the system's inputs with ``u_of(t, q, q̇) → (k,)``."""
        import copy

        out = copy.copy(self)
        out.u_of = u_of
        return out

    def residuals(self, t, q, qd):
        """``(g(q, t) (n_hol,), G q̇ + b (m,))``."""
        m = self.m
        if not m:
            return np.zeros(0), np.zeros(0)
        G = self.mat(self.G, q, qd, t, (m, len(q)))
        vel = G @ qd + self.mat(self.b, q, qd, t, (m,))
        pos = self.mat(self.g, q, qd, t, (self.n_hol,)) if self.n_hol else np.zeros(0)
        return pos, vel

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


class _NativeODE:
    """The system integrated by the core (:class:`~poinsot.integrate.problem.NativeProblem`):
    the compiled model, its parameters, its inputs (constants, compiled expressions of
    ``[t, q, q̇]``, or a Python callable ``(t, q, qd)``: the slow path), Baumgarte's gains, the
    projection and the constraints in play. No Python runs per step unless an input is a
    Python callable."""

    def __init__(self, num, stabilization, baumgarte, engine, inputs, events=None):
        self.num = num
        self.n = num.system.n_coordinates
        self.state_slices = {"q": slice(0, self.n), "qd": slice(self.n, 2 * self.n)}
        self.engine = engine
        self._p = engine.parameter_vector(num.params)
        self._gains = tuple(baumgarte) if stabilization == "baumgarte" else (0, 0)
        self._inputs = inputs
        self._projection = stabilization == "projection" and num.m > 0
        self.events = events  # the core's events tuple (see _CoreEvents), or None

    def problem(self, y0):
        from .._bindings import lagrange as core_lagrange
        from ..integrate.problem import GENERAL_METHODS, NativeProblem

        active = getattr(self.num, "active", None)
        slow = ("inputs given as Python functions",) if callable(self._inputs) else ()
        if self.events is not None and self.events[2]:
            slow += ("events given as Python functions",)
        data = (self.engine.model, self._p, self._inputs, float(self._gains[0]),
                float(self._gains[1]), self._projection, active)  # fmt: skip
        keywords = {} if self.events is None else {"events": self.events}
        return NativeProblem(core_lagrange.integrate_lagrange, data, GENERAL_METHODS, slow,
                             keywords=keywords)  # fmt: skip

    def to_internal(self, y):
        return np.array(y, dtype=float)

    from_internal = to_internal


class _SensitiveODE:
    """The system with its forward sensitivities, integrated by the core: the augmented state
    ``[q, q̇, S (2n × P, row-major)]``, the model's compiled Jacobian, constant inputs, every
    constraint in play (``crates/core/src/lagrange/sensitivity.rs``)."""

    def __init__(self, num, stabilization, baumgarte, tangent, p, u, seeds, control_all):
        n = num.system.n_coordinates
        self.state_slices = {"q": slice(0, n), "qd": slice(n, 2 * n)}
        gains = tuple(baumgarte) if stabilization == "baumgarte" else (0, 0)
        projection = stabilization == "projection" and num.m > 0
        self._data = (tangent, p, u, float(gains[0]), float(gains[1]), projection, seeds,
                      bool(control_all))  # fmt: skip

    def problem(self, y0):
        from .._bindings import lagrange as core_lagrange
        from ..integrate.problem import GENERAL_METHODS, NativeProblem

        return NativeProblem(core_lagrange.integrate_lagrange_sensitivities, self._data,
                             GENERAL_METHODS)  # fmt: skip

    def to_internal(self, y):
        return np.array(y, dtype=float)

    from_internal = to_internal


def check_engine(engine) -> None:
    """Refuse an ``engine`` other than ``"compiled"``; ``"numpy"`` with where it went."""
    if engine == "numpy":
        raise ValueError(
            "`engine='numpy'` was removed: SymPy's lambdify with NumPy per step is now the "
            "tests' reference oracle (tests/lagrange/oracle.py); the compiled engine runs "
            "every system (engine='compiled', the default)"
        )
    if engine != "compiled":
        raise ValueError(f"`engine` must be 'compiled', found {engine!r}")


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
    rtol=None,
    atol=None,
    t_eval=None,
    stabilization="baumgarte",
    baumgarte=None,
    guess=None,
    inputs=None,
    events=None,
    event_resolution=None,
    engine="compiled",
    max_steps=None,
    sensitivities=None,
    control_sensitivities=True,
) -> LagrangianSolution:
    """Integrate the equations of motion of ``system``.

    Parameters
    ----------
    t_span : (t0, t1)
    q0, qd0 : dict {coordinate: value}
        Initial coordinates and velocities, by coordinate or by name (``{"x": 0.6}``, as
        ensembles read them). With constraints, dependent coordinates and velocities may be
        omitted and are solved for (``guess`` {coordinate: value} starts the Newton iteration
        for omitted coordinates, from 0 where it gives none; a guess for a coordinate given
        in ``q0``, or for a system without holonomic constraints, has no effect and is
        refused); given values inconsistent with the constraints are refused with the
        residual, and a failed solve with where it started. Omitted velocities of an
        unconstrained system are zero.
    params : dict {symbol: number}
        Values of every parameter (``system.parameters``).
    method, dt, rtol, atol, t_eval
        As for :func:`poinsot.simulate` (``rk4`` or ``dop853``; the Lie-group and splitting
        methods are for rigid bodies). The adaptive method's tolerances default to
        ``rtol = 1e-10``, ``atol = 1e-12`` (``DEFAULT_TOLERANCES``); a fixed-step method
        given them refuses them. A solution whose constraint residual exceeds
        ``CONSTRAINT_RESIDUAL_BOUND`` = 1e-6 times one plus the largest coordinate warns
        (:class:`ConstraintDriftWarning`), whatever the tolerances that let it drift.
    stabilization : {"baumgarte", "projection", None}
    baumgarte : (alpha, beta), optional
        Baumgarte gains in s⁻¹ (default (10, 10): critically damped); refused with another
        ``stabilization``, which does not use them.
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
        Every event is located inside the core's time loop (a Python function is called
        back from it: the slow path).
    event_resolution : int, optional
        Events, and the release of one-sided constraints (``system.unilateral``), are
        detected at the steps' ends and at points no further apart than a grid of this many
        points on the run (default 2001), then located to the integrator's accuracy (Brent's
        method on the step's dense output or restarted step: :mod:`poinsot.integrate.events`);
        ``sol.releases`` lists the releases. Refused by a run that watches neither, where it
        would have no effect.
    engine : {"compiled"}
        How the equations are evaluated: the model's expressions (M, f, G, b, γ, g, h with
        shared subexpressions, parameters and inputs as runtime arguments) compiled to
        machine code in the core in milliseconds (:mod:`poinsot.lagrange.engine`), and the
        KKT solve, stabilisation and projection in the core: no Python per step, unless an
        input is a Python function (the slow path). The former ``"numpy"`` engine (SymPy's
        ``lambdify`` and NumPy per step) is refused with a message: it is now the tests'
        reference oracle (``tests/lagrange/oracle.py``), which the compiled engine is held to.
    sensitivities : str or sequence of str, optional
        Parameters to differentiate the motion with respect to (forward sensitivities,
        :mod:`poinsot.lagrange.sensitivity`): ``"q0"`` (the coordinates given in ``q0``;
        those solved from the constraints follow), ``"qd0"`` (the velocities given, every
        velocity of an unconstrained system), ``"params"`` (in the order of
        ``system.parameters``), or one column of them (``"q0[theta]"``, ``"params[L]"``).
        The model's Jacobian is derived by SymPy and compiled with it once; the
        differentiated KKT system is integrated with the motion by the same method and steps
        (``rk4``, ``dop853`` or an explicit tableau; constant inputs, no events; a one-sided
        constraint must hold throughout: a run in which its multiplier turns negative at a
        sample is refused). ``sol.sensitivity(output, wrt)`` gives ``∂output(tᵢ)/∂wrt``.
    control_sensitivities : bool
        With ``"dop853"``, whether the error control weighs the sensitivities too (default,
        as CVODES' ``errconS``), or the motion alone.

    Examples
    --------
    >>> from poinsot.models import pendulum_on_cart
    >>> mdl = pendulum_on_cart()
    >>> sol = mdl.simulate((0, 1), method="rk4", dt=1e-3, sensitivities=("q0", "params"))
    >>> sol.sensitivity("q", "params").shape      # (samples, coordinates, parameters)
    (201, 2, 4)
    """
    prepared = prepare(system, t_span, params=params, method=method, dt=dt, rtol=rtol,
                       atol=atol, t_eval=t_eval, stabilization=stabilization,
                       baumgarte=baumgarte, inputs=inputs, events=events,
                       event_resolution=event_resolution, engine=engine,
                       max_steps=max_steps, sensitivities=sensitivities,
                       control_sensitivities=control_sensitivities)  # fmt: skip
    return prepared.run(q0=q0, qd0=qd0, guess=guess)


def prepare(system, t_span, *, params=None, method="dop853", dt=None, rtol=None, atol=None,
            t_eval=None, stabilization="baumgarte", baumgarte=None, inputs=None,
            events=None, event_resolution=None, engine="compiled",
            max_steps=None, sensitivities=None,
            control_sensitivities=True) -> PreparedLagrangianRun:  # fmt: skip
    """Check a Lagrangian system's run and lower it for the core, once: the compiled model,
    its parameters, inputs and events, the method, sampling and budget. The arguments are
    :func:`simulate`'s less the initial state, checked here with the same errors; the
    :class:`PreparedLagrangianRun` runs from any initial state, or with other parameters.

    Examples
    --------
    >>> from poinsot.models import pendulum_polar
    >>> mdl = pendulum_polar()
    >>> th = mdl.symbols["theta"]
    >>> run = mdl.system.prepare((0, 1), params=mdl.params, t_eval=[0, 1])
    >>> [round(float(run.run(q0={th: a}).q[-1, 0]), 6) for a in (0.1, 0.2)]
    [-0.099993, -0.19997]
    """
    from .engine import compile_system

    settings = check_settings(t_span, method=method, dt=dt, rtol=rtol, atol=atol,
                              t_eval=t_eval, stabilization=stabilization, baumgarte=baumgarte,
                              event_resolution=event_resolution, max_steps=max_steps,
                              watched=bool(events) or bool(system.unilateral))  # fmt: skip
    check_engine(engine)
    params = as_params(params, system)
    compiled = compile_system(system)
    num = _EngineNumeric(system, params, compiled)
    u_of = input_function(inputs, system)
    if u_of is not None:
        num = num.bound(u_of)
    watched = _expression_events(events, system, params)
    settings = replace(settings, events=watched)
    wrt = _check_sensitivities(system, settings, sensitivities, control_sensitivities, events,
                               u_of)  # fmt: skip
    return PreparedLagrangianRun(system, num, compiled, u_of, settings, events, wrt,
                                 bool(control_sensitivities))  # fmt: skip


def _check_sensitivities(system, settings, wrt, control, events, u_of):
    """The checked names of a run's ``sensitivities`` (None without), refused where the run
    cannot carry them."""
    from ..sensitivity import check_control
    from .sensitivity import check_run, parse

    check_control(control, settings.solver, wrt is not None)
    if wrt is None:
        return None
    check_run(settings.solver, events=events, inputs=u_of)
    return parse(wrt, system)


def check_settings(t_span, *, method, dt, rtol, atol, t_eval, stabilization, baumgarte,
                   event_resolution, max_steps, watched=True) -> _Settings:  # fmt: skip
    """A Lagrangian run's settings, checked once (single runs and ensembles): the span, the
    method (one for general ODEs) with ``dt`` (a fixed-step method's step, the adaptive
    method's first step), tolerances, sample times (201 by default), the stabilisation and
    Baumgarte's gains, the events' detection grid and the step budget."""
    from ..integrate.solve import (
        check_budget,
        check_event_resolution,
        check_no_silent_tolerances,
        check_sampling,
        check_t_span,
        check_tolerances,
    )

    t0, t1 = check_t_span(t_span)
    solver = check_run_options(method, stabilization)
    check_no_silent_tolerances(solver, rtol=rtol, atol=atol)
    t_eval, _, dt = check_sampling(t_eval, t0, t1, 1, dt)
    rtol, atol = check_tolerances(*(d if v is None else v
                                    for v, d in zip((rtol, atol), DEFAULT_TOLERANCES,
                                                    strict=True)))  # fmt: skip
    budget = check_budget(solver, t0, t1, dt, max_steps)
    if baumgarte is not None and stabilization != "baumgarte":
        raise ValueError(f"`baumgarte` has no effect with stabilization={stabilization!r} (the "
                         "gains are Baumgarte's stabilisation's): drop it, or use "
                         "stabilization='baumgarte'")  # fmt: skip
    gains = as_gains(DEFAULT_BAUMGARTE if baumgarte is None else baumgarte, "baumgarte")
    resolution = check_event_resolution(event_resolution, watched)
    times = np.linspace(t0, t1, 201) if t_eval is None else np.asarray(t_eval, float)
    return _Settings(solver, (t0, t1), times, dt, rtol, atol, budget, stabilization, gains, [],
                     resolution)  # fmt: skip


@dataclass(frozen=True)
class _Settings:
    solver: type
    t_span: tuple
    t_eval: np.ndarray
    dt: float | None
    rtol: float
    atol: float
    budget: int
    stabilization: str | None
    gains: tuple
    events: list
    event_resolution: int


@dataclass(frozen=True)
class PreparedLagrangianRun:
    """A Lagrangian system's run, checked and lowered (:func:`prepare`): :meth:`run`
    integrates it from an initial state; :meth:`with_params` is the same run with other
    parameters (the compiled model is kept: parameters are runtime arguments).

    Attributes
    ----------
    system : LagrangianSystem
    num : the compiled model under the run's parameters (and inputs)
    compiled : CompiledSystem
    u_of : the inputs' function ``(t, q, q̇) → (k,)``, or None
    settings : the checked span, method, sampling, tolerances, stabilisation and budget
    given_events : the events as given (compiled again by :meth:`with_params`)
    sensitivities : the checked names of the run's sensitivities, or None
    control_sensitivities : whether DOP853's error control weighs them
    """

    system: object
    num: object
    compiled: object
    u_of: object
    settings: _Settings
    given_events: object = None
    sensitivities: tuple | None = None
    control_sensitivities: bool = True

    @property
    def params(self) -> dict:
        return dict(self.num.params)

    def with_params(self, params) -> PreparedLagrangianRun:
        """The same run with ``params`` (checked; events written in the parameters are
        compiled with the new values); nothing else is lowered again."""
        params = as_params(params, self.system)
        num = _EngineNumeric(self.system, params, self.compiled)
        if self.u_of is not None:
            num = num.bound(self.u_of)
        watched = _expression_events(self.given_events, self.system, params)
        return replace(self, num=num, settings=replace(self.settings, events=watched))

    def run(self, *, q0, qd0=None, guess=None) -> LagrangianSolution:
        """Integrate from ``q0``, ``qd0`` (dicts {coordinate: value}; dependent ones may be
        omitted and are solved from the constraints, ``guess`` starting the Newton
        iteration), as :func:`simulate` does."""
        from ..integrate.driver import IntegrationError, integrate
        from ..integrate.solve import SimulationError

        system, num, st = self.system, self.num, self.settings
        t0, t1 = st.t_span
        q_init = _keyed(q0, system, "q0", allow_missing=system.n_holonomic > 0)
        qd_init = _keyed(qd0, system, "qd0", allow_missing=True)
        given = ~np.isnan(q_init), ~np.isnan(qd_init) | (system.n_constraints == 0)
        guess_arr = _keyed(guess, system, "guess", allow_missing=True) if guess else None
        q_init, qd_init = consistent_initial_state(system, num, t0, q_init, qd_init, guess_arr)
        solver = st.solver

        def run(ode, ta, ya, tb, times):
            if tb <= ta:
                return np.repeat(np.asarray(ya, dtype=float)[None], len(times), axis=0)
            try:
                tol = {"rtol": st.rtol, "atol": st.atol} if solver.adaptive else {}
                out = integrate(ode, solver, (ta, tb), ya, t_eval=times, dt=st.dt,
                                max_steps=st.budget, **tol)  # fmt: skip
            except IntegrationError as exc:
                _blame_inputs(self.u_of, exc, len(system.coordinates))
                n = len(system.coordinates)
                raise SimulationError(_at_start(exc, ta, np.asarray(ya)[: 2 * n], n),
                                      None) from exc  # fmt: skip
            run.nfev += out.nfev
            run.method = out.method
            return out.y

        run.nfev, run.method = 0, solver.name
        inputs = _core_inputs(self.u_of)

        def ode_of(anum, events=None):
            """The integrated system of ``anum``: the core's, with ``events`` located in its
            time loop."""
            return _NativeODE(anum, st.stabilization, st.gains, self.compiled, inputs, events)

        y_init = np.concatenate([q_init, qd_init])
        if self.sensitivities is not None:
            solution = self._run_sensitive(run, y_init, *given)
        elif not st.events and not system.unilateral:  # one run, no event to watch
            out_y = run(ode_of(num), t0, y_init, t1, st.t_eval)
            solution = LagrangianSolution(system, st.t_eval, out_y, num, method=run.method,
                                          nfev=run.nfev,
                                          stabilization=st.stabilization)  # fmt: skip
        else:
            solution = _simulate_phases(system, num, run, ode_of, y_init, t0, t1, st.t_eval,
                                        st.events, st.event_resolution,
                                        st.stabilization)  # fmt: skip
        tol = (st.rtol, st.atol) if solver.adaptive else (None, None)
        warn_on_drift(solution, *tol, st.dt)
        return solution

    def _run_sensitive(self, run, y_init, given_q, given_v) -> LagrangianSolution:
        """The run with its sensitivities: the augmented system (the model's compiled
        Jacobian, :func:`~poinsot.lagrange.engine.compile_tangent`) through the same driver,
        from the directions' initial columns; a one-sided constraint's multiplier must stay
        non-negative at the samples (else the constraint would have let go)."""
        from .._bindings import lagrange as core_lagrange
        from .engine import compile_tangent
        from .sensitivity import columns, sensitivities

        system, st = self.system, self.settings
        n, t0 = system.n_coordinates, st.t_span[0]
        dirs = columns(self.sensitivities, system, given_q, given_v)
        tangent = compile_tangent(system)
        p = self.compiled.parameter_vector(self.num.params)
        u = _core_inputs(self.u_of)
        seeds = np.ascontiguousarray(dirs.seeds)
        if seeds.shape[1] == 0:
            seeds = np.zeros((dirs.size, 0))
        try:
            y0 = core_lagrange.lagrange_sensitivity_start(tangent, t0, y_init, p, u, dirs.kinds,
                                                          dirs.components, seeds, ~given_q,
                                                          ~given_v)  # fmt: skip
        except ValueError as exc:
            raise ValueError(_named_direction(str(exc), dirs.labels)) from None
        ode = _SensitiveODE(self.num, st.stabilization, st.gains, tangent, p, u, seeds,
                            self.control_sensitivities)  # fmt: skip
        y, sens = sensitivities(run(ode, t0, y0, st.t_span[1], st.t_eval), dirs, n, t0)
        solution = LagrangianSolution(system, st.t_eval, y, self.num, method=run.method,
                                      nfev=run.nfev, stabilization=st.stabilization)  # fmt: skip
        for k in system.unilateral:
            below = np.nonzero(solution.multipliers[:, k] < 0)[0]
            if len(below):
                raise ValueError(
                    f"`sensitivities`: the one-sided constraint {system.holonomic[k]} ≥ 0 lets "
                    f"go by t = {solution.t[below[0]]:.6g} (its multiplier turns negative); "
                    "sensitivities across a release are not computed: end the run before it"
                )
        solution.sensitivities = sens
        return solution


def _named_direction(message, labels) -> str:
    """The core's message about the initial column of direction ``j`` with the column's label
    (``'q0[x]'``) in place of its index."""
    m = re.search(r"direction (\d+): ", message)
    if m is None or int(m.group(1)) >= len(labels):
        return message
    label = labels[int(m.group(1))]
    return message.replace(m.group(0), f"the column {label!r}: ", 1)


def _at_start(exc, t0, y0, n) -> str:
    """The message of a run that failed: where it failed before its first step, the initial
    state it could not leave is named (``qd0 = 1e300`` read as a singular mass matrix)."""
    if exc.t is None or exc.t != t0:
        return str(exc)
    y0 = np.asarray(y0, dtype=float)
    q, v = np.abs(y0[:n]).max(initial=0.0), np.abs(y0[n:]).max(initial=0.0)
    return (f"{exc}; the run could not take its first step from the initial state "
            f"(largest |q0| = {q:.3g}, largest |qd0| = {v:.3g}): check `q0`, `qd0` and "
            "`params`")  # fmt: skip


def _blame_inputs(u_of, exc, n) -> None:
    """Re-raise a failed run as the :class:`~poinsot.lagrange.arguments.InputError` of an
    input that is not a finite real number where it failed, or just after (``sqrt(2 - t)``
    stalls the step size as t nears 2, where it stops being real: the input, not the step,
    is the cause), when the state there is finite; else return."""
    from .arguments import InputError

    if u_of is None or exc.t is None or exc.y is None or not np.isfinite(exc.y).all():
        return
    y = np.asarray(exc.y, dtype=float)
    for t in (exc.t, exc.t + 1e-6 * (1.0 + abs(exc.t))):
        try:
            u_of(t, y[:n], y[n:])
        except InputError as bad:
            raise bad from exc


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


def _simulate_phases(system, num, run, ode_of, y0, t0, t1, t_eval, events, resolution,
                     stabilization):  # fmt: skip
    """The run as phases between releases of one-sided constraints: in each, the user's
    events and a "release" event per one-sided constraint in play (its multiplier falling
    through zero) are watched, every one located inside the core's time loop
    (:func:`_core_phase`); at a release the run goes on with that constraint's row masked."""
    from ..integrate.events import normalize_events

    user = normalize_events(events)
    n_user = len(user)
    t_all, y_all, phases = [], [], []
    t_events = [[] for _ in user]
    y_events = [[] for _ in user]
    releases = []
    mask = np.ones(system.n_constraints, dtype=bool)  # the constraints in play
    ta, ya, stop = t0, y0, False
    while True:
        anum = num if mask.all() else num.with_active(mask)
        one_sided = [k for k in system.unilateral if mask[k]]
        times = t_eval[(t_eval >= ta) & (t_eval <= t1)]
        t, y, log = _core_phase(system, ode_of, anum, run, user, one_sided, ta, ya, t1, times,
                                resolution)  # fmt: skip
        for k in range(n_user):
            t_events[k] += list(log.t_events[k])
            y_events[k] += list(log.y_events[k])
        phases.append((ta, anum))
        if log.terminated_by is None or log.terminated_by < n_user:  # the end, or a user's stop
            t_all.append(t)
            y_all.append(y)
            stop = log.terminated_by is not None
            break
        gone = one_sided[log.terminated_by - n_user]  # a one-sided constraint lets go
        t_all.append(t[:-1])  # the release instant is not a requested sample
        y_all.append(y[:-1])
        ta, ya = float(t[-1]), y[-1]
        releases.append((ta, str(system.holonomic[gone]), ya.copy()))
        mask[gone] = False
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
