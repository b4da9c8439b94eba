"""Driving a :class:`~poinsot.integrate.base.Solver` over a time span, keeping only the samples
asked for."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .base import get_solver

__all__ = ["IntegrationError", "IntegrationResult", "integrate"]


@dataclass
class IntegrationResult:
    """Samples ``t`` (n,), states ``y`` (n, d) and the run's bookkeeping."""

    t: np.ndarray
    y: np.ndarray
    method: str
    nfev: int
    nsteps: int
    wall_time: float
    message: str = "finished"
    options: dict = field(default_factory=dict)


class IntegrationError(RuntimeError):
    """The run stopped early; ``partial`` holds the samples computed before the failure."""

    def __init__(self, message, partial: IntegrationResult):
        super().__init__(message)
        self.partial = partial


def _describe_nonfinite(system, t, y) -> str:
    names = getattr(system, "state_slices", None) or {"state": slice(0, len(y))}
    bad = [name for name, sl in names.items() if not np.all(np.isfinite(y[sl]))]
    return f"non-finite {', '.join(bad)} at t = {t:.9g}"


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
) -> IntegrationResult:
    """Integrate ``system`` from ``t_span[0]`` to ``t_span[1]``.

    Samples are kept at ``t_eval`` (fixed-step methods shorten a step to land on each sample;
    adaptive ones use their dense output), or, without ``t_eval``, at the start and every
    ``save_every``-th step and the end. A non-finite state stops the run with an
    :class:`IntegrationError` naming the time and the quantity, carrying the samples so far.
    """
    cls = get_solver(method)
    t0, t1 = float(t_span[0]), float(t_span[1])
    start = time.perf_counter()
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # first-step choice
        solver = cls(system, t0, y0, t1, dt=dt, rtol=rtol, atol=atol, **(solver_options or {}))
    ts, ys = [], []
    nsteps = 0
    if t_eval is not None:
        samples = np.asarray(t_eval, dtype=float)
        k = 0
        while k < len(samples) and samples[k] <= t0:
            ts.append(samples[k])
            ys.append(solver.y.copy())
            k += 1
    else:
        samples = None
        ts.append(t0)
        ys.append(solver.y.copy())

    def partial(message):
        return IntegrationResult(
            np.array(ts),
            np.array(ys).reshape(len(ts), -1),
            cls.name,
            solver.nfev,
            nsteps,
            time.perf_counter() - start,
            message,
        )

    while solver.status == "running":
        h = None
        if not cls.adaptive:
            target = t1 if samples is None or k >= len(samples) else samples[k]
            gap = target - solver.t
            h = gap if gap <= solver.dt * (1 + 1e-9) else solver.dt
            landing = h == gap
        try:
            # overflow/invalid values are detected below and reported with time and quantity
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                solver.step(h)
        except Exception as exc:
            raise IntegrationError(f"{exc} (at t = {solver.t:.9g})", partial(str(exc))) from exc
        nsteps += 1
        if progress is not None:
            progress(solver.t)
        if not cls.adaptive and landing:
            solver.t = target  # exact sample times, no accumulated round-off
            if target == t1:
                solver.status = "finished"
        if not np.all(np.isfinite(solver.y)):
            message = _describe_nonfinite(system, solver.t, solver.y)
            raise IntegrationError(message, partial(message))
        if samples is None:
            if nsteps % save_every == 0 or solver.status != "running":
                ts.append(solver.t)
                ys.append(solver.y.copy())
        elif cls.adaptive:
            j = k
            while j < len(samples) and samples[j] <= solver.t:
                j += 1
            if j > k:
                dense = solver.dense_output()
                project = solver._project  # samples on the constraint manifold too
                for s in samples[k:j]:
                    ts.append(s)
                    if s == solver.t:
                        ys.append(solver.y.copy())
                    else:
                        ys.append(dense(s) if project is None else project(dense(s), s))
                k = j
        else:
            while k < len(samples) and samples[k] <= solver.t + 1e-12 * max(1, abs(solver.t)):
                ts.append(samples[k])
                ys.append(solver.y.copy())
                k += 1
    result = partial("finished")
    result.options = {"dt": dt, "rtol": rtol, "atol": atol}
    return result
