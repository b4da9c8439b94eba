"""``simulate``: integrate a rigid body's motion under forces, free or about a fixed point.

The front-end in two steps, as every front-end: :func:`prepare` checks the run (span, method,
step or tolerances, sampling, step budget, events) and lowers the body and its forces for the
compiled core, once; :meth:`PreparedRun.run` runs it from an initial state, as often as wanted
(other initial states, another method on the same problem). :func:`simulate` is the two in one
call. A scenario file's loader prepares its run when it reads the file and runs that.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from ._validation import _rotation_input, as_frame
from .dynamics import RigidBodySystem, rigid_velocity_from_particles
from .integrate.base import CORE_METHODS, get_solver
from .integrate.driver import IntegrationError, check_backend, check_solver_fits, integrate
from .integrate.solve import (
    RunSettings,
    SimulationError,
    StepBudgetError,
    check_budget,
    check_event_resolution,
    check_run,
    solve,
)
from .trajectory import Trajectory

__all__ = [
    "ForceUndefinedError",
    "PreparedRun",
    "SimulationError",
    "StepBudgetError",
    "prepare",
    "simulate",
]

#: The methods a rigid body's run takes, by name: the core's registry, in its order (a motion
#: relative to a carrier takes those of any vector field, and refuses the others itself).
METHODS = tuple(CORE_METHODS)


def prepare(
    body,
    t_span,
    *,
    forces=(),
    pivot=None,
    method="dop853",
    dt=None,
    rtol=None,
    atol=None,
    t_eval=None,
    save_every=1,
    backend=None,
    events=None,
    event_resolution=None,
    max_steps=None,
    sensitivities=None,
    control_sensitivities=True,
) -> PreparedRun:
    """Check a rigid body's run and lower it for the compiled core, once: the
    :class:`PreparedRun` that :func:`simulate` runs. The arguments are :func:`simulate`'s
    (less the initial state and ``progress``), checked here with the same errors.

    Examples
    --------
    One prepared run, two initial spins:

    >>> from poinsot import RigidBody
    >>> run = prepare(RigidBody.box(1.0, (1, 2, 3)), (0, 1), method="rk4", dt=1e-3)
    >>> [round(float(run.run(omega0=w).omega[-1, 1]), 6) for w in ((0, 1, 0), (0, 2, 0))]
    [1.0, 2.0]
    """
    settings = check_run(t_span, method, dt=dt, rtol=rtol, atol=atol, t_eval=t_eval,
                         save_every=save_every, max_steps=max_steps)  # fmt: skip
    if isinstance(forces, str) or not hasattr(forces, "__iter__"):
        raise TypeError(f"`forces` must be a sequence of Force objects, found {forces!r}")
    system = RigidBodySystem(body, forces, pivot)
    check_solver_fits(settings.solver, system)
    check_backend(backend, system)
    if events is not None:
        from .integrate.events import normalize_events

        normalize_events(events)  # refused here, naming the event, before any step
        events = tuple(events) if isinstance(events, list | tuple) else (events,)
    event_resolution = check_event_resolution(event_resolution, events is not None)
    from .sensitivity import check_control

    dirs = None
    control = check_control(control_sensitivities, settings.solver, sensitivities is not None)
    if sensitivities is not None:
        dirs = _check_sensitivities(system, settings.solver, sensitivities, events, backend)
    return PreparedRun(system, settings, backend, events, event_resolution, dirs,
                       control)  # fmt: skip


def _check_sensitivities(system, solver, wrt, events, backend):
    """The directions of a run's ``sensitivities``, refused where the run cannot carry them."""
    from .sensitivity import check_directions, directions
    from .sensitivity import check_run as check_sensitive

    check_sensitive(system, solver, backend)
    if events is not None:
        raise ValueError("`sensitivities` and `events` cannot be combined yet")
    dirs = directions(system, wrt)
    check_directions(system, solver, dirs)
    return dirs


@dataclass(frozen=True)
class PreparedRun:
    """A rigid body's run, checked and lowered (:func:`prepare`): :meth:`run` integrates it
    from an initial state; :meth:`with_method` is the same problem with another method.

    Attributes
    ----------
    system : RigidBodySystem
        The body, its forces lowered for the core and the pivot.
    settings : RunSettings
        The checked span, method, sampling, step or tolerances and step budget.
    backend : str or None
        ``"compiled"``, ``"python"`` or None (chosen from the forces).
    events : tuple of callables or None
    event_resolution : int
    sensitivities : poinsot.sensitivity.Directions or None
        The directions of the run's sensitivities, when it carries them.
    control_sensitivities : bool
        DOP853's error control weighs the sensitivities too.
    """

    system: RigidBodySystem
    settings: RunSettings
    backend: str | None = None
    events: tuple | None = None
    event_resolution: int = 2001
    sensitivities: object = None
    control_sensitivities: bool = True

    @property
    def t_span(self) -> tuple[float, float]:
        return self.settings.t0, self.settings.t1

    def with_method(self, method) -> PreparedRun:
        """The same problem (system, span, sampling, step or tolerances) with ``method``,
        checked as :func:`prepare` checks it; nothing is lowered again."""
        solver = get_solver(method)
        s = self.settings
        budget = check_budget(solver, s.t0, s.t1, s.dt, s.max_steps)
        check_solver_fits(solver, self.system)
        from .sensitivity import check_control

        check_control(self.control_sensitivities, solver, self.sensitivities is not None)
        if self.sensitivities is not None:
            _check_sensitivities(self.system, solver, self.sensitivities.names, None, self.backend)
        return dataclasses.replace(
            self, settings=dataclasses.replace(s, solver=solver, max_steps=budget)
        )

    def initial_state(self, *, omega0=None, Q0=None, R0=None, V0=None, omega_frame="body",
                      particle_velocities=None, scalar_first=True) -> np.ndarray:  # fmt: skip
        """The initial body-frame state (18,) of :meth:`run`'s arguments, checked, with every
        force evaluated there once (:class:`ForceUndefinedError` names one that is not
        finite)."""
        body, pivot = self.system.body, self.system.pivot
        if particle_velocities is not None:
            if omega0 is not None or V0 is not None:
                raise ValueError("give `particle_velocities` or `omega0`/`V0`, not both")
            if Q0 is not None:
                raise ValueError("`particle_velocities` assume the reference attitude: omit `Q0`")
            V0, omega0 = initial_velocities(body, particle_velocities, pivot)
        elif omega0 is None:
            raise ValueError("`omega0` must be given (or `particle_velocities`)")
        if Q0 is not None:  # a Rotation, or SciPy's quaternion order, as an array
            Q0 = _rotation_input(Q0, "Q0", scalar_first)
        elif not scalar_first:
            raise ValueError("`scalar_first` applies to a quaternion `Q0`; none is given: omit it")
        y0 = self.system.initial_state(omega0=omega0, Q0=Q0, R0=R0, V0=V0,
                                       omega_frame=omega_frame)  # fmt: skip
        _check_forces_at_start(self.system, self.settings.t0, y0)
        return y0

    def run(self, *, omega0=None, Q0=None, R0=None, V0=None, omega_frame="body",
            particle_velocities=None, scalar_first=True, y0=None,
            progress=None) -> Trajectory:  # fmt: skip
        """Integrate from the initial state (:func:`simulate`'s arguments, or ``y0``, a state
        from :meth:`initial_state`): a :class:`~poinsot.trajectory.Trajectory`.

        ``y0`` is the whole body-frame state (18,), checked as a start (finite, its ``Q`` a
        rotation, its ``V`` the pivot's where there is one), in place of the other initial
        arguments, which are then refused; ``omega_frame`` then only says the frame of the
        ``omega0`` sensitivities' columns, and is refused without them."""
        if y0 is None:
            y0 = self.initial_state(omega0=omega0, Q0=Q0, R0=R0, V0=V0, omega_frame=omega_frame,
                                    particle_velocities=particle_velocities,
                                    scalar_first=scalar_first)  # fmt: skip
        else:
            if not scalar_first:
                raise ValueError("`scalar_first` has no effect with `y0` (Q is a matrix in "
                                 "it): omit it")  # fmt: skip
            y0 = self._given_state(y0, omega0=omega0, Q0=Q0, R0=R0, V0=V0,
                                   particle_velocities=particle_velocities,
                                   omega_frame=omega_frame)  # fmt: skip
        if self.sensitivities is not None:
            return self._run_sensitive(y0, omega_frame == "space", progress)
        if self.events is not None:
            return _simulate_events(self.system, self.settings, y0, self.backend, self.events,
                                    self.event_resolution)  # fmt: skip
        return solve(self.system, y0, self.settings,
                     trajectory=lambda r: _trajectory(r, self.system), progress=progress,
                     backend=self.backend)  # fmt: skip

    def _given_state(self, y0, omega_frame, **others) -> np.ndarray:
        """``run(y0=...)``: the state checked whole, the arguments it replaces refused."""
        given = [name for name, value in others.items() if value is not None]
        if given:
            raise ValueError(f"give `y0` or {', '.join(f'`{n}`' for n in given)}, not both: "
                             "`y0` is the whole initial state")  # fmt: skip
        if as_frame(omega_frame) != "body" and self.sensitivities is None:
            raise ValueError("`omega_frame` has no effect with `y0` (a body-frame state) and "
                             "no sensitivities: omit it")  # fmt: skip
        y0 = self.system.checked_state(y0)
        _check_forces_at_start(self.system, self.settings.t0, y0)
        return y0

    def _run_sensitive(self, y0, omega_space, progress) -> Trajectory:
        """The run with its sensitivities: the augmented system through the same driver."""
        from .sensitivity import SensitiveSystem, split

        aug = SensitiveSystem(self.system, self.sensitivities, omega_space=omega_space,
                              control_all=self.control_sensitivities)  # fmt: skip

        def trajectory(result):
            y, sens = split(result.y, self.sensitivities, t0=self.settings.t0)
            traj = _trajectory(dataclasses.replace(result, y=y), self.system)
            traj.sensitivities = dataclasses.replace(
                sens, omega_frame="space" if omega_space else "body"
            )
            return traj

        try:
            return solve(aug, y0, self.settings, trajectory=trajectory, progress=progress)
        except SimulationError as exc:
            if self.settings.solver.kind != "exact-splitting" or "sensitivities" not in str(exc):
                raise
            raise SimulationError(
                f"{exc}: an exact-flow splitting differentiates each free flow's closed form, "
                "which has no derivative on the separatrix (the motion through the unstable "
                "intermediate axis); use 'rkmk4', 'rk4' or 'dop853' for this start",
                exc.trajectory,
            ) from None


def simulate(
    body,
    t_span,
    *,
    omega0=None,
    Q0=None,
    R0=None,
    V0=None,
    forces=(),
    pivot=None,
    method="dop853",
    dt=None,
    rtol=None,
    atol=None,
    t_eval=None,
    omega_frame="body",
    particle_velocities=None,
    save_every=1,
    progress=None,
    backend=None,
    scalar_first=True,
    events=None,
    event_resolution=None,
    max_steps=None,
    sensitivities=None,
    control_sensitivities=True,
) -> Trajectory:
    """Integrate the motion of ``body`` under ``forces``: eqs (07) ``M R̈ = F``,
    (08) ``A ω̇ + ω × Aω = Σ u_i × Qᵀ F_i`` and (09) ``Q̇ = QΩ``.

    Parameters
    ----------
    body : RigidBody
    t_span : (float, float)
        Start and end time.
    omega0 : array_like (3,)
        Initial angular velocity, in the body frame (or the space frame with
        ``omega_frame="space"``). Omit it when giving ``particle_velocities``.
    Q0 : (3, 3) matrix, (4,) quaternion or ``scipy.spatial.transform.Rotation``, optional
        Initial attitude; identity by default. A quaternion is read scalar-first (w, x, y, z)
        unless ``scalar_first=False`` (SciPy's (x, y, z, w)).
    R0, V0 : array_like (3,), optional
        Initial centre of mass (default: the body's) and its velocity (default: zero).
    forces : sequence of :class:`~poinsot.forces.Force`
    pivot : array_like (3,), optional
        A body point (reference configuration) held fixed: the body turns about it with the
        inertia and torques about it (heavy top, gyroscope, compound pendulum).
    method : str or Solver class
        ``"dop853"`` (default, adaptive), ``"rk4"``, ``"rkmk4"``, ``"splitting"``,
        ``"exact-splitting"``, ``"exact-splitting4"``, ``"exact-splitting6"`` (the exact
        torque-free flow and kicks: for bodies under small, position-only torques), or any
        registered name or :class:`~poinsot.integrate.Solver` subclass.
    dt : float, optional
        Step of fixed-step methods (required for them); first step of adaptive ones. A fixed
        step is shortened to land exactly on each sample time and on the end, so the samples
        (``t_eval``) take part in a fixed-step run's accuracy.
    rtol, atol : float, optional
        Tolerances of adaptive methods (default 1e-10, 1e-12).
    t_eval : array_like (n,), optional
        Sample times (increasing, inside ``t_span``). Only these are stored.
    particle_velocities : array_like (N, 3), optional
        Initial particle velocities of a particle body, turned into ``V0`` and ``omega0`` by
        the notebook's rules (``Q(0) = I``, particles at their reference positions); refused
        when they are not a rigid motion.
    save_every : int
        Without ``t_eval``, keep every ``save_every``-th step.
    progress : callable, optional
        Called with the current time as the run advances (progress bars).
    backend : {"compiled", "python"}, optional
        ``"compiled"`` (the default whenever every force is built-in) runs the whole time loop
        in one compiled call; ``"python"`` runs the same steps from Python and is used for
        forces given by Python callables (:class:`~poinsot.forces.ParticleForce`,
        :class:`~poinsot.forces.CustomForce`, callables of t): the slow path.
    events : callable or sequence of callables, optional
        Functions ``g(t, y)`` of the flat body-frame state ``y`` (18,) = ``[R, V, Q
        (row-major), ω]`` whose zeros are located, as in :func:`scipy.integrate.solve_ivp`
        (attributes ``terminal`` and ``direction``): ``traj.t_events``, ``traj.y_events``. A
        terminal event ends the run there (:mod:`poinsot.integrate.events`).
    event_resolution : int, optional
        Grid points on which events are detected before they are located exactly (default
        2001); refused without ``events``, where it would have no effect.
    max_steps : int, optional
        The most steps the run may take (default
        :data:`~poinsot.integrate.solve.DEFAULT_MAX_STEPS`): a fixed-step run that needs more
        is refused before it starts; an adaptive one that reaches it stops with a
        :class:`SimulationError`.
    sensitivities : str or sequence of str, optional
        Parameters to differentiate the motion with respect to (forward sensitivities,
        :mod:`poinsot.sensitivity`): ``"omega0"``, ``"Q0"`` (a rotation vector), ``"R0"``,
        ``"V0"``, ``"inertia"`` (the principal moments), ``"forces[i]"`` or
        ``"forces[i].name"``. The variational equations are integrated with the motion by the
        same method and steps (``"rk4"``, ``"dop853"``, explicit tableaux; ``"rkmk4"`` and
        ``"splitting"`` differentiate their discrete steps); then
        ``traj.sensitivity(output, wrt)`` gives ``∂output(tᵢ)/∂wrt``.
    control_sensitivities : bool
        With ``"dop853"``, whether the error control weighs the sensitivities too (default,
        as CVODES' ``errconS``); ``False`` steps on the motion's error alone.

    Returns
    -------
    Trajectory

    Raises
    ------
    SimulationError
        When the state becomes non-finite (or a force fails) mid-run; its ``trajectory`` holds
        the samples computed until then.

    Examples
    --------
    The notebook's 27-particle body falling under gravity (docs/theory.md §1):

    >>> import numpy as np
    >>> from poinsot import RigidBody, simulate
    >>> from poinsot.forces import Gravity
    >>> grid = [(i, 2*j, 3*k) for i in (0, .5, 1) for j in (0, .5, 1) for k in (0, .5, 1)]
    >>> body = RigidBody.from_particles(np.full(27, 10 / 27), grid)
    >>> traj = simulate(body, (0, 20), omega0=(0, 1, 1), forces=[Gravity((0, 0, -9.8))],
    ...                 method="rk4", dt=0.2, t_eval=np.linspace(0, 20, 101))
    >>> round(float(traj.R[-1, 2] - traj.R[0, 2]), 6)
    -1960.0
    """
    prepared = prepare(body, t_span, forces=forces, pivot=pivot, method=method, dt=dt,
                       rtol=rtol, atol=atol, t_eval=t_eval, save_every=save_every,
                       backend=backend, events=events, event_resolution=event_resolution,
                       max_steps=max_steps, sensitivities=sensitivities,
                       control_sensitivities=control_sensitivities)  # fmt: skip
    return prepared.run(omega0=omega0, Q0=Q0, R0=R0, V0=V0, omega_frame=omega_frame,
                        particle_velocities=particle_velocities, scalar_first=scalar_first,
                        progress=progress)  # fmt: skip


def _simulate_events(system, run, y0, backend, events, resolution) -> Trajectory:
    """:func:`simulate` watching ``events``: the run restarted from grid states to locate
    their zeros (:func:`poinsot.integrate.events.integrate_with_events`)."""
    from .integrate.events import integrate_with_events

    solver, dt, rtol, atol = run.solver, run.dt, run.rtol, run.atol
    t0, t1 = run.t0, run.t1
    times = np.linspace(t0, t1, 201) if run.t_eval is None else run.t_eval
    stats = {"nfev": 0, "nsteps": 0, "backend": "", "method": ""}

    def segment(ta, ya, tb, tt):
        if tb <= ta:
            return np.repeat(np.asarray(ya, float)[None], len(tt), axis=0)
        try:
            out = integrate(system, solver, (ta, tb), ya, t_eval=tt, dt=dt, rtol=rtol,
                            atol=atol, backend=backend, max_steps=run.max_steps)  # fmt: skip
        except IntegrationError as exc:
            raise SimulationError(str(exc), _trajectory(exc.partial, system)) from exc
        stats["nfev"] += out.nfev
        stats["nsteps"] += out.nsteps
        stats["backend"], stats["method"] = out.backend, out.method
        return out.y

    start = time.perf_counter()
    t, y, log = integrate_with_events(segment, events, t0, y0, t1, times, resolution=resolution)
    traj = Trajectory(t, y, system, method=stats["method"], nfev=stats["nfev"],
                      nsteps=stats["nsteps"], wall_time=time.perf_counter() - start,
                      message="terminal event" if log.terminated_by is not None else "finished",
                      backend=stats["backend"])  # fmt: skip
    traj.t_events, traj.y_events = log.t_events, log.y_events
    return traj


class ForceUndefinedError(ValueError):
    """A force whose wrench is not finite at the initial state; ``index`` is its place in
    ``forces``."""

    def __init__(self, index: int, name: str):
        self.index, self.force_name = index, name
        super().__init__(
            f"`forces[{index}]` ({name}) is undefined at the initial state (non-finite wrench; "
            "e.g. a body at the centre of a central gravity field)"
        )

    @property
    def reason(self) -> str:
        return str(self).split(") ", 1)[1]


def initial_velocities(body, particle_velocities, pivot):
    """``(V0, omega0)`` of a body given by its particles' velocities (``V0`` None about a
    pivot, where it follows from ω)."""
    V0, omega0 = rigid_velocity_from_particles(body, particle_velocities)
    return (None if pivot is not None else V0), omega0


def _check_forces_at_start(system, t0, y0):
    """Evaluate every force once at the start, so that a broken callable, or a force that is
    undefined there (central gravity at its centre), is refused before any step, named."""
    with np.errstate(all="ignore"):
        wrenches = system.force_wrenches(t0, y0)
    for i, (f, (F, tau)) in enumerate(zip(system.forces, wrenches, strict=True)):
        if not (np.all(np.isfinite(F)) and np.all(np.isfinite(tau))):
            raise ForceUndefinedError(i, f.name)
    if system.c_forces:  # called by address in the core's loops only: rhs cannot call them
        return
    with np.errstate(all="ignore"):
        rates = system.rhs(t0, y0)
    if not np.all(np.isfinite(rates)):  # the forces are finite: the motion's own terms overflow
        from .layout import STATE_SLICES

        part = next(k for k, sl in STATE_SLICES.items() if not np.all(np.isfinite(rates[sl])))
        raise ValueError(f"the rate of {part} is not finite at the initial state: the state "
                         "is beyond the double range (ω × Iω, or ω², overflows); choose other "
                         "units")  # fmt: skip


def _trajectory(result, system) -> Trajectory:
    """A :class:`Trajectory` from an integration result (complete or partial)."""
    return Trajectory(
        result.t,
        result.y,
        system,
        method=result.method,
        nfev=result.nfev,
        nsteps=result.nsteps,
        wall_time=result.wall_time,
        message=result.message,
        success=result.success,
        backend=result.backend,
    )
