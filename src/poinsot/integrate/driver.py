"""Running a solver over a time span: one call into the compiled core.

:func:`integrate` asks the system for its :class:`~poinsot.integrate.problem.NativeProblem`,
prepares the arrays the core's drivers read, calls the core for the whole run (in segments
only to report progress or to grow the output of an adaptive run), and turns the status it
returns into results or errors. What is given in Python — forces, carriers or inputs as
Python callables, a right-hand side ``rhs(t, y)`` — is called back from the core: the slow
path, reported as ``backend="python"``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from .base import Solver, get_solver
from .control import StepSizeController
from .saveat import SaveAt

__all__ = [
    "BACKENDS",
    "IntegrationError",
    "IntegrationResult",
    "ODESystem",
    "check_backend",
    "check_solver_fits",
    "integrate",
    "run_spec",
]

BACKENDS = ("compiled", "python")


@dataclass
class IntegrationResult:
    """Samples ``t`` (n,), states ``y`` (n, d) and the run's bookkeeping; ``success`` and
    ``message`` as in :func:`scipy.integrate.solve_ivp`."""

    t: np.ndarray
    y: np.ndarray
    method: str
    nfev: int
    nsteps: int
    wall_time: float
    message: str = "finished"
    options: dict = field(default_factory=dict)
    backend: str = "compiled"
    nrejected: int = 0
    success: bool = True


class IntegrationError(RuntimeError):
    """The run stopped early; ``partial`` holds the samples computed before the failure;
    ``t`` and ``y``, where known, the time and the state (the user's layout) where it
    failed, for a front-end to say why (an input that is not finite there)."""

    def __init__(self, message, partial: IntegrationResult, t=None, y=None):
        super().__init__(message)
        self.partial, self.t, self.y = partial, t, y


class ODESystem:
    """Any object with ``rhs(t, y) → ẏ`` (and optionally ``projector(y0)``, returning ``None``
    or a map ``(y, t) → y`` onto its constraint manifold, and ``state_slices``, the names of
    parts of the state for messages) as a system the core integrates, calling it back (the
    slow path)."""

    structure = "ode"

    def __init__(self, problem, y0):
        self.rhs = problem.rhs
        make = getattr(problem, "projector", None)
        self._project = make(y0) if make is not None else None
        n = np.asarray(y0).size
        self.state_slices = getattr(problem, "state_slices", None) or {"state": slice(0, n)}

    def problem(self, y0):
        from .._bindings import runs as core_runs
        from .problem import GENERAL_METHODS, NativeProblem

        rhs, project = self.rhs, self._project

        def field(t, y):
            return np.asarray(rhs(t, y), dtype=float)

        def onto(y, t):
            return np.asarray(project(y, t), dtype=float)

        data = (field, onto if project is not None else None)
        return NativeProblem(core_runs.integrate_python, data, GENERAL_METHODS,
                             ("the right-hand side rhs(t, y)",))  # fmt: skip

    def to_internal(self, y):
        return np.array(y, dtype=float)

    from_internal = to_internal


def _describe_nonfinite(slices, t, y) -> str:
    bad = [name for name, sl in slices.items() if not np.all(np.isfinite(y[sl]))]
    return f"non-finite {', '.join(bad) or 'state'} at t = {t:.9g}"


def check_solver_fits(cls, system) -> None:
    """Refuse a method that cannot integrate ``system``: one that needs the rigid-body
    structure, or a splitting method with velocity-dependent forces (it takes kicks)."""
    rigid = getattr(system, "structure", None) == "rigid"
    if not rigid and cls.requires == "rigid":
        raise ValueError(f"`method` {cls.name!r} needs a rigid-body system")
    if rigid and getattr(cls, "needs_position_only_forces", False):
        bad = [f.name for f in system.forces if not f.position_only]
        if bad:
            raise ValueError(
                f"`method` {cls.name!r} needs forces that depend only on time, position and "
                f"attitude (kicks); these depend on velocities: {', '.join(bad)}"
            )


def check_backend(backend, system) -> None:
    """Refuse a ``backend`` that is not one of :data:`BACKENDS`, or ``"compiled"`` for a
    system that calls Python back (its forces given as Python callables)."""
    if backend is None:
        return
    if backend not in BACKENDS:
        raise ValueError(f"`backend` must be one of {BACKENDS}, found {backend!r}")
    slow = tuple(f.name for f in getattr(system, "python_forces", ()))
    if backend == "compiled" and slow:
        raise ValueError(
            "`backend='compiled'` needs built-in forces; these are Python "
            f"callables (use backend='python'): {', '.join(slow)}"
        )


def integrate(
    system,
    method,
    t_span,
    y0,
    *,
    t_eval=None,
    dt=None,
    rtol=None,
    atol=None,
    save_every=1,
    solver_options=None,
    progress=None,
    backend=None,
    observer=None,
    max_steps=None,
) -> IntegrationResult:
    """Integrate ``system`` from ``t_span[0]`` to ``t_span[1]`` from ``y0``.

    ``system`` is a :class:`~poinsot.dynamics.RigidBodySystem` (states in the body frame) or
    any object with ``rhs(t, y)``. Samples are kept at ``t_eval`` or, without it, at the start,
    every ``save_every``-th step and the end (:class:`~poinsot.integrate.saveat.SaveAt`);
    ``observer``, an object with float arrays ``first``, ``last``, ``count`` (1,), records the
    flips of ω of a rigid body (the sign changes along its intermediate axis), every step.
    Fixed-step methods take steps of ``dt``; adaptive ones use ``rtol``, ``atol`` (``dt``: the
    first step; ``solver_options={"max_step": ...}``). ``backend`` is ``"compiled"`` (the
    default when every force is built-in) or ``"python"``. A non-finite state or a step size
    that underflows stops the run with an :class:`IntegrationError` naming the time and the
    quantity, carrying the samples computed until then; so does a run that reaches
    ``max_steps`` steps (default: no limit) before ``t_span[1]``. An empty ``t_eval`` asks
    for no samples: the run is integrated to ``t_span[1]`` (its failures raise as usual) and
    the result holds none of its states, as :func:`scipy.integrate.solve_ivp` does.
    """
    if t_eval is not None and np.size(t_eval) == 0:  # the run, none of its states
        full = integrate(system, method, t_span, y0, t_eval=[float(t_span[1])], dt=dt,
                         rtol=rtol, atol=atol, solver_options=solver_options,
                         progress=progress, backend=backend, observer=observer,
                         max_steps=max_steps)  # fmt: skip
        return replace(full, t=full.t[:0], y=full.y[:0])
    cls = get_solver(method)
    solver: Solver = cls()
    options = dict(solver_options or {})
    max_step = options.pop("max_step", math.inf)
    if options:
        raise ValueError(f"unknown `solver_options`: {', '.join(sorted(options))}")
    t0, t1 = float(t_span[0]), float(t_span[1])
    if not t1 > t0:
        raise ValueError(f"`t_span` must increase, found t0 = {t0}, t1 = {t1}")
    check_solver_fits(cls, system)
    if cls.adaptive:
        from .dop853 import DEFAULT_ATOL, DEFAULT_RTOL

        controller = StepSizeController(
            DEFAULT_RTOL if rtol is None else rtol,
            DEFAULT_ATOL if atol is None else atol,
            first_step=dt,
            max_step=max_step,
        )
    else:
        if dt is None:
            raise ValueError(f"`method` {cls.name!r} is fixed-step: `dt` must be given")
        if not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"`dt` must be a positive number, found {dt}")
        controller = None
    saveat = SaveAt(None if t_eval is None else np.asarray(t_eval, dtype=float), save_every)

    y0 = np.array(y0, dtype=float)
    if not hasattr(system, "problem"):
        if not hasattr(system, "rhs"):
            raise TypeError(
                "`system` must be a poinsot system or an object with rhs(t, y), found "
                f"{type(system).__name__}"
            )
        system = ODESystem(system, y0)
    return _integrate_native(system, solver, t0, t1, y0, dt, controller, saveat, progress,
                             backend, observer, max_steps)  # fmt: skip


#: Steps per call of the core when a progress callback is given (progress is reported between).
PROGRESS_CHUNK = 20_000


#: Steps an adaptive run takes before its cost is first estimated; it is estimated again each
#: time the steps double, from the pace of the steps since the last estimate.
PILOT_STEPS = 1000
#: The result of a run is held this many times while it is handed back (the core's buffers,
#: their copy, the front-end's conversion): the samples must fit that many times in memory.
RESULT_COPIES = 3
#: Samples that take less than this are not checked against the memory available (a run's
#: start then reads no system file).
SMALL_BYTES = 64_000_000


def _over_budget(budget, t, t1, result) -> IntegrationError:
    """The error of a run that took its whole step budget before its end."""
    message = (
        f"the run reached `max_steps` = {budget} steps at t = {t:.9g}, short of t = {t1:g} "
        "(raise `max_steps`, or loosen the tolerances)"
    )
    return IntegrationError(message, result(message, False))


def _short_of_memory(samples, dim) -> tuple[str, str] | None:
    """``(needed, available)`` in words when ``samples`` states of ``dim`` numbers, held
    :data:`RESULT_COPIES` times, would not fit in the memory available; None when they fit
    (or take under :data:`SMALL_BYTES`: no system file is read then)."""
    from .._resources import available_memory, format_bytes

    need = RESULT_COPIES * samples * (dim + 1) * 8
    free = available_memory() if need > SMALL_BYTES else None
    if free is None or need <= free:
        return None
    return format_bytes(need), format_bytes(free)


def _out_of_pace(state, t1, budget, since, dim, saveat, result) -> IntegrationError | None:
    """The error of an adaptive run that, at the pace of its steps since ``since`` ``(t,
    steps)``, cannot reach ``t1`` within its step budget, or whose samples (one per
    ``saveat.every`` steps, without ``t_eval``) would not fit in memory; None if it can."""
    t, steps = state.t, state.stats.steps
    needed, pace, taken = _pace(state, t1, since)
    if not math.isfinite(pace):
        return None
    where = (
        f"at t = {t:.9g} after {steps} steps, its steps average {pace:.3g} (over the last "
        f"{taken}), so reaching t = {t1:g} needs about {needed:.3g} more steps"
    )
    if needed > budget - steps:
        message = (
            f"the run was stopped: {where}; the limit is `max_steps` = {budget} (shorten the "
            "span, loosen the tolerances, or raise `max_steps`)"
        )
        return IntegrationError(message, result(message, False))
    if not len(saveat.times):
        samples = (steps + needed) / saveat.every
        short = _short_of_memory(samples, dim)
        if short is not None:
            message = (
                f"the run was stopped: {where}, and keeping {_kept(saveat.every)} "
                f"({samples:.3g} samples) would take about {short[0]}; {short[1]} of memory "
                "is available (raise `save_every`, or ask for samples at chosen times with "
                "`t_eval`)"
            )
            return IntegrationError(message, result(message, False))
    return None


def _check_room(samples, dim, *, t_eval) -> None:
    """Refuse, before any step, a run whose ``samples`` states of ``dim`` numbers would not
    fit in the memory available (a fixed-step run keeps every ``save_every``-th step)."""
    short = _short_of_memory(samples, dim)
    if short is not None:
        knob = "fewer sample times" if t_eval else "a larger `save_every`, or `t_eval`"
        raise ValueError(
            f"the run would keep {samples} samples of {dim} numbers, about {short[0]} with "
            f"the result's copies; {short[1]} of memory is available (ask for {knob})"
        )


def _pace(state, t1, since) -> tuple[float, float, int]:
    """``(needed, pace, taken)``: the steps still needed to reach ``t1`` at the mean step
    ``pace`` of the ``taken`` steps since ``since`` ``(t, steps)`` (inf and nan if none)."""
    taken = state.stats.steps - since[1]
    if taken <= 0 or not state.t > since[0]:
        return math.inf, math.nan, taken
    pace = (state.t - since[0]) / taken
    return (t1 - state.t) / pace, pace, taken


def _kept(every: int) -> str:
    """Which steps' states a run keeps, in words."""
    return "every step's state" if every == 1 else f"the state of one step in {every}"


def _room_for(state, result) -> None:
    """Double the room for samples, or stop the run with a clear error when the doubled
    samples would not fit in the memory available (never a ``MemoryError`` from deep inside)."""
    short = _short_of_memory(2 * state.capacity, len(state.state))
    if short is not None:
        message = (
            f"the run was stopped at t = {state.t:.9g}: its {state.stats.samples} samples would "
            f"need {short[0]} to grow, and {short[1]} of memory is available (raise "
            "`save_every`, or ask for samples at chosen times with `t_eval`)"
        )
        raise IntegrationError(message, result(message, False))
    state.grow()


def estimate_steps(system, method, t_span, y0, *, dt=None, rtol=None, atol=None) -> float:
    """The steps an adaptive run of ``system`` from ``y0`` over ``t_span`` would take: the
    steps of the run itself if it ends within :data:`PILOT_STEPS`, else those taken plus the
    rest of the span at their mean pace (a float; it may exceed any integer); 0 when the
    short run fails (a member that blows up: the run itself reports
    it, member by member). The ensembles estimate their members' cost with it before
    running them.

    >>> from poinsot import RigidBody
    >>> from poinsot.dynamics import RigidBodySystem
    >>> system = RigidBodySystem(RigidBody.box(1.0, (1, 2, 3)))
    >>> y0 = system.initial_state(omega0=(0.1, 1, 0.2))
    >>> f"{estimate_steps(system, 'dop853', (0, 1e9), y0):.1e}"
    '3.3e+09'
    """
    from .control import StepSizeController
    from .dop853 import DEFAULT_ATOL, DEFAULT_RTOL

    cls = get_solver(method)
    if not cls.adaptive:  # a fixed-step run's count is exact: integrate.solve.check_budget
        raise ValueError(f"`method` {cls.name!r} is fixed-step: its steps need no estimate")
    t0, t1 = float(t_span[0]), float(t_span[1])
    controller = StepSizeController(
        DEFAULT_RTOL if rtol is None else rtol,
        DEFAULT_ATOL if atol is None else atol,
        first_step=dt,
    )
    saveat = SaveAt(np.array([t1]), 1)
    try:
        return _integrate_native(system, cls(), t0, t1, np.asarray(y0, dtype=float), dt,
                                 controller, saveat, None, None, None, pilot=True)  # fmt: skip
    except IntegrationError:
        return 0.0


def estimate_steps_by_spans(run_to, t0: float, t1: float) -> float:
    """The steps a run from ``t0`` would take to ``t1``, estimated from short runs of it over
    growing spans ``[t0, t0 + τ]`` until one takes :data:`PILOT_STEPS` steps: ``run_to(t,
    max_steps)`` runs to ``t`` and returns ``(steps, finished)``, the steps it took and
    whether it reached ``t`` within ``max_steps``. The estimate is the last run's steps
    scaled to the span (a float; 0 when a short run fails: the run itself reports why).
    Used where the run cannot be paused and resumed (the ensembles' members in the core).

    >>> steps = estimate_steps_by_spans(  # steps of 1 ms
    ...     lambda t, cap: (min(round(t / 1e-3), cap), t / 1e-3 <= cap), 0.0, 1e6)
    >>> f"{steps:.3g}"
    '1e+09'
    """
    span = t1 - t0
    tau = span * 2.0**-30
    for _ in range(100):
        steps, finished = run_to(t0 + tau, 4 * PILOT_STEPS)
        if finished is None:
            return 0.0
        if finished and (steps >= PILOT_STEPS or tau >= span):
            break
        grow = 2 * PILOT_STEPS / max(steps, 1) if finished else 1e-8  # too far: far shorter
        tau = min(span, tau * min(1e6, grow))
    return steps * span / tau


def _native_backend(problem, backend) -> str:
    """The backend of a run: ``backend`` checked against the problem, by default
    ``"compiled"`` unless the problem calls Python back."""
    if backend is None:
        return "compiled" if problem.compiled else "python"
    if backend not in BACKENDS:
        raise ValueError(f"`backend` must be one of {BACKENDS}, found {backend!r}")
    if backend == "compiled" and not problem.compiled:
        raise ValueError(
            "`backend='compiled'` needs built-in forces; these are Python "
            f"callables (use backend='python'): {', '.join(problem.slow)}"
        )
    return backend


def _first_capacity(saveat, adaptive: bool, t0, t1, dt) -> int:
    """The samples a run makes room for at its start: every ``t_eval`` time, every kept
    step of a fixed-step run, or 256 for an adaptive run to grow from."""
    if len(saveat.times):
        return len(saveat.times)
    if adaptive:
        return 256
    return int(min((t1 - t0) / dt, 1e9)) // saveat.every + 3


def _engine_keywords(problem, observer) -> dict:
    """The keyword arguments of the problem's engine, with the arrays of an ``observer`` that
    counts flips (ensembles)."""
    extra = dict(problem.keywords)
    if observer is not None and hasattr(observer, "first"):  # counts flips (ensembles)
        if not problem.observes_flips:
            raise ValueError("this system's engine does not count flips")
        extra["flips"] = (observer.first, observer.last, observer.count)
    return extra


def _failure(status, state, system, result) -> IntegrationError:
    """The error of a run that stopped with a failing ``status``: a state that is not finite,
    a step that underflows, or an unknown status."""
    from .._bindings import runs as core_runs

    if status == core_runs.NONFINITE:
        where = system.from_internal(state.state)
        message = _describe_nonfinite(system.state_slices, state.t, where)
        return IntegrationError(message, result(message, False), state.t, where)
    if status == core_runs.STEP_TOO_SMALL:
        message = (
            f"the step size fell below the resolution of t = {state.t:.9g} (the problem "
            "may be stiff or singular there, or the tolerances too tight)"
        )
        where = system.from_internal(state.state)
        return IntegrationError(message, result(message, False), state.t, where)
    return IntegrationError(f"the run stopped with status {status}", result("failed", False))


def _integrate_native(system, solver, t0, t1, y0, dt, controller, saveat, progress, backend,
                      observer, budget=None, pilot=False) -> IntegrationResult:  # fmt: skip
    """A system on the compiled core (its :class:`~poinsot.integrate.problem.NativeProblem`):
    the whole run in one call (in chunks only to report progress or to grow the output of an
    adaptive run); forces and carriers given as Python callables are called back from it (the
    slow path)."""
    from .._bindings import runs as core_runs

    cls = type(solver)
    problem = system.problem(y0)
    backend = _native_backend(problem, backend)
    kind = problem.kind_of(solver.kind)
    if kind is None:
        raise ValueError(f"`method` {cls.name!r} has no step in the compiled core for this system")
    budget = 2**62 if budget is None else int(budget)
    spec = run_spec(kind, t_end=t1, dt=dt, data=cls.method_data(), controller=controller,
                    t_eval=saveat.times, save_every=saveat.every,
                    max_steps=budget)  # fmt: skip
    z = system.to_internal(y0)
    capacity = _first_capacity(saveat, cls.adaptive, t0, t1, dt)
    _check_room(capacity, np.size(z), t_eval=len(saveat.times) > 0)
    state = core_runs.RunState(t0, np.ascontiguousarray(z, dtype=float).ravel(), capacity)
    extra = _engine_keywords(problem, observer)
    start = time.perf_counter()
    per_call = PROGRESS_CHUNK if progress is not None else 2**62
    # an adaptive run's cost is estimated at PILOT_STEPS steps, then each time they double
    check_at = PILOT_STEPS if cls.adaptive else 2**62
    since = (t0, 0)

    def result(message, success):
        t, y = state.samples()
        stats = state.stats
        return IntegrationResult(
            t,
            system.from_internal(y),
            cls.name,
            stats.evaluations,
            stats.steps,
            time.perf_counter() - start,
            message,
            {"dt": dt, "rtol": getattr(controller, "rtol", None),
             "atol": getattr(controller, "atol", None)},
            backend,
            stats.rejected,
            success,
        )  # fmt: skip

    while True:
        left = budget - state.stats.steps
        if left <= 0:
            raise _over_budget(budget, state.t, t1, result)
        steps = state.stats.steps
        chunk = min(per_call, left, max(check_at - steps, 1))
        status = problem.engine(*problem.data, spec, state, chunk, **extra)
        if progress is not None:
            progress(state.t)
        if status == core_runs.RUNNING and state.stats.steps >= check_at:
            if pilot:  # the estimate only (estimate_steps)
                return _pace(state, t1, since)[0] + state.stats.steps
            error = _out_of_pace(state, t1, budget, since, len(z), saveat, result)
            if error is not None:
                raise error
            since, check_at = (state.t, state.stats.steps), 2 * state.stats.steps
        if status == core_runs.FINISHED:
            return float(state.stats.steps) if pilot else result("finished", True)
        if status == core_runs.TERMINATED:  # a terminal event (the system's events say which)
            return result("a terminal event", True)
        if status == core_runs.OUTPUT_FULL:
            _room_for(state, result)
            continue
        if status == core_runs.RUNNING:
            continue
        raise _failure(status, state, system, result)


def run_spec(kind, *, t_end, dt=None, data=None, controller=None, t_eval=None,
             save_every=1, max_steps=2**62):  # fmt: skip
    """The core's :class:`poinsot._core.RunSpec` of a run, built (and checked) once: the kind
    of method (:attr:`poinsot.integrate.base.Solver.kind`) with its ``data``
    (:meth:`~poinsot.integrate.base.Solver.method_data`: the tableau of explicit Runge–Kutta
    and RKMK, the composition of an exact-flow splitting) or its ``controller`` (a
    :class:`~poinsot.integrate.control.StepSizeController`, DOP853), the step ``dt`` of a
    fixed-step method, the sampling and the step budget."""
    from .._bindings import runs as core_runs

    options = {"t_end": float(t_end), "dt": float(dt or 0.0), "save_every": int(save_every),
               "max_steps": int(max_steps)}  # fmt: skip
    if t_eval is not None:
        options["t_eval"] = np.ascontiguousarray(t_eval, dtype=float)
    options.update(data or {})
    if controller is not None:
        c = controller
        options.update(rtol=c.rtol, atol=c.atol, safety=c.safety, min_factor=c.min_factor,
                       max_factor=c.max_factor, max_step=c.max_step,
                       first_step=c.first_step or 0.0)  # fmt: skip
    return core_runs.RunSpec(kind, **options)


def pilot_members(speeds) -> tuple[int, ...]:
    """The members of an ensemble whose steps are estimated before it runs: the first, and
    the fastest (the largest of ``speeds`` (N,), |ω₀| or |q̇₀|; non-finite ones ignored).

    >>> pilot_members([1.0, 3.0, float("inf")]), pilot_members([2.0, 1.0])
    ((0, 1), (0,))
    """
    speeds = np.asarray(speeds, dtype=float)
    return tuple(dict.fromkeys((0, int(np.argmax(np.where(np.isfinite(speeds), speeds, -1.0))))))
