"""The preamble every front-end shares, written once: the time span, the method, the sampling,
the tolerances and the step budget, checked before any step; and one call that runs a system
and turns a failure into a :class:`SimulationError` carrying the samples computed so far.

``simulate``, ``simulate_relative``, the ensembles and the Lagrangian ``simulate`` all check
their run with :func:`check_run`; the single-body front-ends then run it with :func:`solve`.

Two promises hold for every run (documented in ``docs/reliability.md``):

* **A bounded cost.** A run takes at most ``max_steps`` steps (default
  :data:`DEFAULT_MAX_STEPS`). A fixed-step run that needs more is refused before it starts,
  with the count it needs; an adaptive run that reaches the budget stops with an error that
  says how far it got.
* **Tolerances double precision can honour.** ``rtol`` below :data:`RTOL_FLOOR` (100 ε, as
  SciPy's ``solve_ivp``) is raised to it with a warning.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .._validation import as_positive_scalar, as_sample_times, as_scalar
from .base import get_solver

__all__ = [
    "DEFAULT_EVENT_RESOLUTION",
    "DEFAULT_MAX_STEPS",
    "MAX_EVENT_RESOLUTION",
    "RTOL_FLOOR",
    "RunSettings",
    "SimulationError",
    "StepBudgetError",
    "check_budget",
    "check_event_resolution",
    "check_run",
    "solve",
]

#: Steps a run may take unless ``max_steps`` says otherwise.
DEFAULT_MAX_STEPS = 100_000_000
#: The smallest relative tolerance an adaptive method is given (SciPy's 100 ε).
RTOL_FLOOR = 100 * np.finfo(float).eps


class StepBudgetError(ValueError):
    """A run that needs more steps than its budget, refused before it starts: a fixed-step
    run (``dt`` given: the count), or an adaptive one whose steps were estimated from a
    short run (``what`` says whose); :attr:`needed` (a float: it may exceed any integer)
    and :attr:`budget` say by how much."""

    def __init__(self, needed: float, budget: int, dt: float | None, t0: float, t1: float,
                 what: str | None = None):  # fmt: skip
        self.needed, self.budget, self.dt, self.t0, self.t1 = needed, budget, dt, t0, t1
        if dt is not None:
            need, knob = f"{needed:.3g} steps of dt = {dt:g}", "take a larger `dt`"
        else:
            need, knob = f"about {needed:.3g} steps", "loosen the tolerances"
        super().__init__(
            f"the run needs {need} over [{t0:g}, {t1:g}]{f' for {what}' if what else ''}; "
            f"the limit is `max_steps` = {budget} ({knob}, a shorter span, or raise "
            "`max_steps`)"
        )


class SimulationError(RuntimeError):
    """A run stopped early; :attr:`trajectory` holds the samples computed before the failure."""

    def __init__(self, message, trajectory):
        super().__init__(message)
        self.trajectory = trajectory


@dataclass(frozen=True)
class RunSettings:
    """A run's checked settings: the span ``t0 < t1``, the solver class, the sample times
    (or None), ``save_every``, the fixed step ``dt`` (or an adaptive method's first step, or
    None), the tolerances (None: the method's defaults) and the step budget."""

    t0: float
    t1: float
    solver: type
    t_eval: np.ndarray | None
    save_every: int
    dt: float | None
    rtol: float | None
    atol: float | None
    max_steps: int


def check_t_span(t_span) -> tuple[float, float]:
    """``(t0, t1)`` from a pair of real numbers with ``t0 < t1``."""
    from collections.abc import Sequence

    if isinstance(t_span, np.ndarray):
        pair = t_span.shape == (2,)
    else:
        pair = isinstance(t_span, Sequence) and not isinstance(t_span, str | bytes)
        pair = pair and len(t_span) == 2
    if not pair:
        raise ValueError(f"`t_span` must be a pair (t0, t1), found {t_span!r}")
    t0 = as_scalar(t_span[0], "t_span[0]")
    t1 = as_scalar(t_span[1], "t_span[1]")
    if not t1 > t0:
        raise ValueError(f"`t_span` must increase: t0 = {t0}, t1 = {t1}")
    return t0, t1


def check_sampling(t_eval, t0, t1, save_every, dt):
    """``t_eval`` (checked sample times or None), ``save_every`` (int) and ``dt`` (or None)."""
    if t_eval is not None:
        t_eval = as_sample_times(t_eval, t0, t1)
    if not isinstance(save_every, int | np.integer) or save_every < 1:
        raise ValueError(f"`save_every` must be a positive integer, found {save_every!r}")
    if t_eval is not None and save_every != 1:
        raise ValueError(f"`save_every` = {save_every} has no effect with `t_eval`: the run "
                         "keeps the states at those times; drop one of them")  # fmt: skip
    if dt is not None:
        dt = as_positive_scalar(dt, "dt")
    return t_eval, int(save_every), dt


def check_tolerances(rtol, atol):
    """``(rtol, atol)``: each None (the method's default) or a real number, ``0 < rtol < 1``
    and ``atol > 0``; an ``rtol`` below :data:`RTOL_FLOOR` is raised to it, with a warning."""
    if rtol is not None:
        rtol = as_positive_scalar(rtol, "rtol")
        if not rtol < 1:
            raise ValueError(f"`rtol` must be below 1 (a relative error), found {rtol}")
        if rtol < RTOL_FLOOR:
            warnings.warn(
                f"`rtol` = {rtol:.3g} is below what double precision resolves; using "
                f"{RTOL_FLOOR:.3g} (100 ε) instead",
                UserWarning,
                stacklevel=3,
            )
            rtol = RTOL_FLOOR
    if atol is not None:
        atol = as_positive_scalar(atol, "atol")
    return rtol, atol


def check_max_steps(max_steps) -> int:
    """The step budget: None (:data:`DEFAULT_MAX_STEPS`) or a positive integer."""
    if max_steps is None:
        return DEFAULT_MAX_STEPS
    if isinstance(max_steps, bool) or not isinstance(max_steps, int | np.integer) or max_steps < 1:
        raise ValueError(f"`max_steps` must be a positive integer, found {max_steps!r}")
    return int(max_steps)


#: The most detection points a run's events may be watched at (``event_resolution``).
MAX_EVENT_RESOLUTION = 10**7


#: The detection grid's points unless ``event_resolution`` says otherwise.
DEFAULT_EVENT_RESOLUTION = 2001


def check_event_resolution(value, watched: bool = True) -> int:
    """The detection grid's number of points, ``event_resolution``: None (the default,
    :data:`DEFAULT_EVENT_RESOLUTION`) or an integer from 2 to :data:`MAX_EVENT_RESOLUTION`
    (events are looked for at points no further apart than that grid would be). A run that
    watches nothing (``watched`` false: no events, no one-sided constraint) refuses a value,
    which would have no effect."""
    from .._validation import as_count

    if value is None:
        return DEFAULT_EVENT_RESOLUTION
    if not watched:
        raise ValueError(
            "`event_resolution` has no effect: this run watches no events (it is the grid on "
            "which `events`, and the releases of one-sided constraints, are detected); drop "
            "it, or give `events`"
        )
    return as_count(value, "event_resolution", 2, MAX_EVENT_RESOLUTION)


def check_run(t_span, method, *, dt=None, rtol=None, atol=None, t_eval=None, save_every=1,
              max_steps=None) -> RunSettings:  # fmt: skip
    """Check a run's settings before any work (every front-end calls this).

    Raises
    ------
    ValueError
        Naming the argument and the rule broken; for a fixed-step method without ``dt``, and
        for a fixed-step run that would take more than ``max_steps`` steps (with the count).
    """
    t0, t1 = check_t_span(t_span)
    solver = get_solver(method)
    check_no_silent_tolerances(solver, rtol=rtol, atol=atol)
    t_eval, save_every, dt = check_sampling(t_eval, t0, t1, save_every, dt)
    rtol, atol = check_tolerances(rtol, atol)
    budget = check_budget(solver, t0, t1, dt, max_steps)
    return RunSettings(t0, t1, solver, t_eval, save_every, dt, rtol, atol, budget)


def check_no_silent_tolerances(solver, **given) -> None:
    """Refuse a tolerance given to a fixed-step method, which takes steps of ``dt`` and would
    ignore it (issue 44: ``rtol`` with ``method="rk4"`` ran without a word); ``dt`` given to
    an adaptive method is its first step, as SciPy's ``first_step``."""
    if solver.adaptive:
        return
    for name, value in given.items():
        if value is not None:
            from .base import METHODS

            adaptive = ", ".join(repr(m) for m, cls in METHODS.items() if cls.adaptive)
            raise ValueError(f"`{name}` has no effect on the fixed-step method {solver.name!r} "
                             f"(it takes steps of `dt`); the adaptive methods use it "
                             f"({adaptive}): drop `{name}`, or choose one of those")  # fmt: skip


def check_budget(solver, t0, t1, dt, max_steps=None) -> int:
    """The run's step budget (:func:`check_max_steps`); a fixed-step method must have ``dt``,
    and a fixed-step run that needs more steps than the budget is refused, with the count
    (:class:`StepBudgetError`)."""
    budget = check_max_steps(max_steps)
    if not solver.adaptive:
        if dt is None:
            raise ValueError(f"`method` {solver.name!r} is fixed-step: `dt` must be given")
        ratio = (t1 - t0) / dt
        needed = math.ceil(ratio) if math.isfinite(ratio) else math.inf
        if needed > budget:
            raise StepBudgetError(float(needed), budget, dt, t0, t1)
    return budget


def solve(system, y0, run: RunSettings, *, trajectory, progress=None, backend=None):
    """Integrate ``system`` from ``y0`` with the checked ``run``; ``trajectory(result)`` makes
    the front-end's result (also from the partial samples of a failed run, which it raises as
    :class:`SimulationError`)."""
    from .driver import IntegrationError, integrate

    try:
        result = integrate(
            system,
            run.solver,
            (run.t0, run.t1),
            y0,
            t_eval=run.t_eval,
            dt=run.dt,
            rtol=run.rtol,
            atol=run.atol,
            save_every=run.save_every,
            progress=progress,
            backend=backend,
            max_steps=run.max_steps,
        )
    except IntegrationError as exc:
        raise SimulationError(str(exc), trajectory(exc.partial)) from exc
    return trajectory(result)
