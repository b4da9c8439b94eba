"""Events: functions of the state whose zeros are located along a run, as in
:func:`scipy.integrate.solve_ivp`.

An event is a callable ``g(t, y)`` with optional attributes ``terminal`` (bool: stop the run
at its first zero), ``direction`` (> 0: only rising zeros, < 0: only falling, 0: both) and
``batch`` (``batch(t, Y)`` → the values at many times ``t`` (S,) and states ``Y`` (S, d) at
once, equal to ``g``'s: the grid below is then one call, as for the constrained systems'
release of a one-sided constraint, whose multipliers the core computes for all states).
:func:`integrate_with_events` runs any integrator given as a *segment* function
``segment(ta, ya, tb, times) → states at times`` (the integrator restarted from a state):

1. the run is sampled on a grid of at least ``resolution`` points (and the requested times);
2. a sign change of ``g`` between two grid points (in the event's direction) brackets a zero;
3. the zero is located by Brent's method, each evaluation integrating from the grid point
   before it, so the event time is as accurate as the integrator itself.

Zeros closer together than the grid spacing can be missed (two zeros in one interval leave no
sign change): raise ``resolution`` for fast events. Written here rather than taken from
``solve_ivp``: poinsot's integrators (compiled, constrained, Lie-group) are not
``solve_ivp`` methods, and the segment contract serves all of them.

A :class:`~poinsot.lagrange.LagrangianSystem` run on its compiled engine locates its events
inside the core's time loop instead (``poinsot_core::events``: the same rules, with detection
points at the step ends and no further apart than this grid's, each zero located on the
step's dense output or restarted step); this module remains the route of rigid-body runs and
of the NumPy engine, the cross-check.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Event", "EventLog", "event_items", "integrate_with_events", "normalize_events"]


@dataclass
class EventLog:
    """What :func:`integrate_with_events` found: per event, the times and states of its zeros
    (``t_events[k]`` (m_k,), ``y_events[k]`` (m_k, d)); ``terminated_by``: the index of the
    terminal event that stopped the run, or None."""

    t_events: list = field(default_factory=list)
    y_events: list = field(default_factory=list)
    terminated_by: int | None = None


@dataclass(frozen=True)
class Event:
    """An event and its options, for a function or an expression that cannot carry them as
    attributes.

    Parameters
    ----------
    g : callable or SymPy expression
        ``g(t, y)``, or (for a :class:`~poinsot.lagrange.LagrangianSystem`) an expression in
        its coordinates, their derivatives, time and parameters, compiled to machine code and
        evaluated inside the core's time loop (the compiled engine; on the NumPy engine, on
        the whole detection grid in one call).
    terminal : bool
        Stop the run at the first zero.
    direction : float
        > 0: rising zeros only; < 0: falling zeros only; 0: both.

    Examples
    --------
    >>> import sympy as sp
    >>> from poinsot import models
    >>> from poinsot.integrate.events import Event
    >>> pendulum = models.pendulum_polar()
    >>> theta = pendulum.symbols["theta"]
    >>> sol = pendulum.simulate((0, 10), events=Event(sp.diff(theta), terminal=True,
    ...                                                direction=1))
    >>> bool(0 < sol.t_events[0][0] < 10)
    True
    """

    g: object
    terminal: bool = False
    direction: float = 0.0


def normalize_events(events):
    """A list of ``(g, terminal, direction)`` from a callable, an :class:`Event` or a
    sequence of them; anything else (an expression outside a constrained system's run
    included) is refused, named."""
    out = []
    for i, g in enumerate(event_items(events)):
        terminal, direction = getattr(g, "terminal", False), getattr(g, "direction", 0.0)
        if isinstance(g, Event):
            g = g.g
        if not callable(g):
            hint = (
                "; an expression is compiled only by a constrained system's run "
                "(LagrangianSystem.simulate)"
                if hasattr(g, "free_symbols")
                else ""
            )
            raise TypeError(
                f"`events[{i}]` must be a function g(t, y) or an Event, found "
                f"{type(g).__name__}{hint}"
            )
        if getattr(g, "batch", None) is None:  # a user's function: its failures named
            g = _UserEvent(g, f"events[{i}]")
        out.append((g, bool(terminal), np.sign(float(direction))))
    return out


class EventError(ValueError):
    """An event function raised, or gave something other than a number: the message names
    the event and the time t, and the original exception is the cause."""


class _UserEvent:
    """A user's event ``g(t, y)``, its failures named: an exception is re-raised as an
    :class:`EventError` naming the event and t (the original as its cause; an interrupt
    passes through untouched), and a value that is not a number (NaN, text, an array of
    several values) is refused the same way, where it gave "cannot reshape array of size 0"."""

    __slots__ = ("g", "label")

    def __init__(self, g, label):
        self.g, self.label = g, label

    def __call__(self, t, y):
        try:
            value = self.g(t, y)
        except Exception as exc:
            raise EventError(f"`{self.label}` raised {type(exc).__name__} at t = "
                             f"{float(t):.17g}: {exc}") from exc  # fmt: skip
        try:
            x = float(value)
        except (TypeError, ValueError):
            raise EventError(f"`{self.label}` returned {value!r} at t = {float(t):.17g}: an "
                             "event must return a number") from None  # fmt: skip
        if x != x:
            raise EventError(f"`{self.label}` returned nan at t = {float(t):.17g}: an event "
                             "must return a number (its zeros are located)")  # fmt: skip
        return x


def event_items(events) -> list:
    """The items of ``events``: none for None, one for a single event (a function, an
    :class:`Event`, an expression), else the sequence's."""
    if events is None:
        return []
    return list(events) if isinstance(events, list | tuple) else [events]


def _crossings(G, directions):
    """``hits[i, k]``: event k changes sign in its direction between grid points i and i + 1
    (both values finite and different), for values ``G`` (len(grid), len(events))."""
    a, b = G[:-1], G[1:]
    ok = np.isfinite(a) & np.isfinite(b) & (a != b)
    rising, falling = (a < 0) & (b >= 0), (a > 0) & (b <= 0)
    d = np.asarray(directions, dtype=float).reshape(1, -1)
    return ok & np.where(d > 0, rising, np.where(d < 0, falling, rising | falling))


def integrate_with_events(segment, events, t0, y0, t1, times, *, resolution=2001):
    """Integrate with ``segment`` from ``(t0, y0)`` to ``t1``, sampling at ``times`` and
    locating the zeros of ``events`` (see the module docstring).

    Returns
    -------
    t, y : ndarray
        The samples at ``times`` up to the end, or up to a terminal event, whose time and
        state are appended as the last sample.
    log : EventLog
    """
    from scipy.optimize import brentq

    events = normalize_events(events)
    times = np.asarray(times, dtype=float)
    grid = np.union1d(np.linspace(t0, t1, max(int(resolution), 2)), times)
    Y = np.asarray(segment(t0, np.asarray(y0, dtype=float), t1, grid))
    log = EventLog([[] for _ in events], [[] for _ in events])
    if not events:
        keep = np.isin(grid, times)
        return grid[keep], Y[keep], log
    G = np.empty((len(grid), len(events)))
    for k, (g, _, _) in enumerate(events):
        many = getattr(g, "batch", None)
        if many is not None:  # the whole grid in one call
            G[:, k] = np.asarray(many(grid, Y), dtype=float).reshape(len(grid))
        else:
            G[:, k] = [float(g(t, y)) for t, y in zip(grid, Y, strict=True)]
    stop = None
    hits = _crossings(G, [direction for _, _, direction in events])
    for i in np.flatnonzero(hits.any(axis=1)):  # the grid intervals with a sign change
        for k, (g, terminal, _) in enumerate(events):
            if not hits[i, k]:
                continue
            ta, ya = grid[i], Y[i]

            def value(t, g=g, ta=ta, ya=ya):
                if t == ta:
                    return float(g(ta, ya))
                return float(g(t, segment(ta, ya, t, np.array([ta, t]))[-1]))

            tz = brentq(value, ta, grid[i + 1], xtol=1e-14 * max(1.0, abs(grid[i + 1])),
                        rtol=4 * np.finfo(float).eps)  # fmt: skip
            yz = np.asarray(segment(ta, ya, tz, np.array([ta, tz]))[-1]) if tz > ta else ya
            log.t_events[k].append(tz)
            log.y_events[k].append(yz)
            if terminal and (stop is None or tz < stop[0]):
                stop = (tz, yz, k)
        if stop is not None:
            break
    log.t_events = [np.array(v) for v in log.t_events]
    log.y_events = [np.array(v, dtype=float).reshape(len(v), Y.shape[1]) for v in log.y_events]
    keep = np.isin(grid, times)
    t, y = grid[keep], Y[keep]
    if stop is not None:
        tz, yz, k = stop
        before = t < tz
        t = np.append(t[before], tz)
        y = np.vstack([y[before], yz])
        log.terminated_by = k
        for j in range(len(events)):  # zeros found past the terminal one did not happen
            late = log.t_events[j] > tz
            log.t_events[j], log.y_events[j] = log.t_events[j][~late], log.y_events[j][~late]
    return t, y, log
