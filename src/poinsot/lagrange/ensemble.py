"""Parameter ensembles of a Lagrangian system: N parameter sets × initial states in compiled
calls, like the rigid-body ensembles (``docs/lagrange.md``, "Ensembles").

The model is compiled once (:mod:`poinsot.lagrange.engine`); every member is the same
compiled model with its own parameter vector, inputs and initial state. Members are cut into
chunks, and a chunk runs in one call of the core
(``poinsot._core.LagrangianModel.run_ensemble``), its members in parallel on the core's
threads with the GIL released and Ctrl-C honoured. No Python runs per member or per step:
Python checks shapes, builds the arrays and collects the results. A member's result depends
on its own data only: the same bit for bit whatever the chunking or the number of threads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import as_scalar
from .arguments import key_index, key_name
from .numeric import check_settings

__all__ = [
    "LagrangianEnsemble",
    "PreparedLagrangianEnsemble",
    "prepare_ensemble",
    "simulate_ensemble",
]


def _column(value, where):
    """A number or a 1-D array of numbers, as a float array (1,) or (N,)."""
    if isinstance(value, np.ndarray | list | tuple):
        a = np.asarray(value)
        if a.ndim != 1 or a.size == 0:
            raise ValueError(f"`{where}` must be a number or a 1-D array of numbers, found "
                             f"shape {a.shape}")  # fmt: skip
        if not np.issubdtype(a.dtype, np.number) or np.iscomplexobj(a):
            raise TypeError(f"`{where}` must hold real numbers, found {a.dtype}")
        a = a.astype(float)
        bad = np.nonzero(~np.isfinite(a))[0]
        if len(bad):
            raise ValueError(f"`{where}[{bad[0]}]` must be finite, found {a[bad[0]]}")
        return a
    return np.array([as_scalar(value, where)])


def _by_key(values, keys, name, required):
    """``{key: column}`` for a dict given by key or by name
    (:func:`~poinsot.lagrange.arguments.key_index`); unknown keys refused, named."""
    if values is None:
        values = {}
    if not isinstance(values, dict):
        raise TypeError(f"`{name}` must be a dict, found {type(values).__name__}")
    index = key_index(keys)
    out = {}
    for key, value in values.items():
        i = index(key)
        if i is None:
            raise ValueError(f"`{name}`: {key!r} is not one of {', '.join(index.names) or 'none'}")
        k = keys[i]
        if callable(value):
            raise TypeError(f"`{name}[{key}]`: an ensemble takes numbers (one or one per "
                            "member), not functions")  # fmt: skip
        out[k] = _column(value, f"{name}[{key}]")
        tiny = (out[k] != 0) & (np.abs(out[k]) < np.finfo(float).tiny) & (name == "params")
        if tiny.any():
            i = int(np.argmax(tiny))
            raise ValueError(
                f"`{name}[{key}]` = {out[k][i]:g} (member {i}) is below the range "
                "of double precision (subnormal); choose other units, or give 0"
            )
        # a parameter's declared sign, under which the equations were derived (as `simulate`)
        sign = "positive" if getattr(k, "is_positive", None) else (
            "non-negative" if getattr(k, "is_nonnegative", None) else None)  # fmt: skip
        if sign and np.any(out[k] <= 0 if sign == "positive" else out[k] < 0):
            i = int(np.argmax(out[k] <= 0 if sign == "positive" else out[k] < 0))
            raise ValueError(f"`{name}[{key}]` must be {sign} ({k} is declared {sign}), found "
                             f"{out[k][i]} (member {i})")  # fmt: skip
    missing = [key_name(k) for k in keys if k not in out]
    if required and missing:
        raise ValueError(f"`{name}` must give every {required}: missing {', '.join(missing)}")
    return out


def _members(*tables) -> int:
    """The number of members: the one length of the per-member arrays of ``tables``
    (``(name, {key: column})``: params, inputs, q0, qd0; q0 and qd0 share their keys)."""
    columns = [(f"{name}[{key_name(k)}]", c)
               for name, cols in tables for k, c in cols.items()]  # fmt: skip
    sizes = {len(c) for _, c in columns} - {1}
    if len(sizes) > 1:
        lengths = ", ".join(f"{label}: {len(c)}" for label, c in columns if len(c) > 1)
        raise ValueError(f"the per-member arrays must have one length, found {lengths}")
    return sizes.pop() if sizes else 1


class LagrangianEnsemble:
    """The members of a parameter ensemble, sampled at common times.

    Attributes
    ----------
    t : (S,) sample times
    q, qd : (N, S, n) coordinates and velocities (NaN for a member whose run failed)
    parameters : dict {symbol: (N,)} every member's parameter values
    inputs : dict {input: (N,)} every member's (constant) input values
    status : (N,) int, the driver's status (1: finished; 2: non-finite state; 3: step too small;
        0: stopped at ``max_steps``)
    nfev, nsteps : (N,) int
    releases : (N, len(system.unilateral)) float
        When each member's one-sided constraints let go (their multiplier falling through
        zero, located inside the core's time loop); NaN for one that held.
    """

    def __init__(self, system, engine, t, Y, P, U, status, nsteps, nfev, method, stabilization,
                 releases=None):  # fmt: skip
        n = system.n_coordinates
        self.system, self.engine = system, engine
        self.coordinates = list(system.coordinates)
        self.t = t
        self.q, self.qd = Y[:, :, :n], Y[:, :, n:]
        self._P, self._U = P, U
        self.parameters = {s: P[:, i] for i, s in enumerate(engine.parameters)}
        self.inputs = {s: U[:, i] for i, s in enumerate(engine.inputs)}
        self.status, self.nsteps, self.nfev = status, nsteps, nfev
        self.method, self.stabilization = method, stabilization
        k = len(system.unilateral)
        self.releases = np.full((len(Y), k), np.nan) if releases is None else releases

    def __len__(self):
        return self.q.shape[0]

    @property
    def success(self) -> np.ndarray:
        """(N,) bool: the members whose run finished."""
        from .._bindings import runs as core_runs

        return self.status == core_runs.FINISHED

    def samples(self, i: int) -> dict:
        """Member ``i``'s accelerations, multipliers (``lam``), generalized constraint forces,
        residuals and energy at every sample (one compiled loop; see
        :meth:`poinsot.lagrange.engine.CompiledSystem.samples`)."""
        i = int(i)
        if not -len(self) <= i < len(self):
            raise IndexError(f"member {i} of an ensemble of {len(self)}")
        y = np.concatenate([self.q[i], self.qd[i]], axis=1)
        U = np.repeat(self._U[i][None], len(self.t), axis=0)
        pairs = zip(self.releases[i], self.system.unilateral, strict=True)
        released = [(float(tr), c) for tr, c in pairs if np.isfinite(tr)]
        if not released:
            return self.engine.samples(self.t, y, self._P[i], U)
        # the phases between releases, as a single run's solution: a sample at a release
        # instant belongs to the phase after it; a released constraint's multiplier is zero
        # and its residuals NaN (a gap, not an error)
        released.sort()
        nh = self.system.n_holonomic
        parts = []
        for j in range(len(released) + 1):
            lo = released[j - 1][0] if j else -np.inf
            hi = released[j][0] if j < len(released) else np.inf
            at = np.nonzero((self.t >= lo) & (self.t < hi))[0]
            active = np.ones(self.system.n_constraints, dtype=bool)
            active[[c for _, c in released[:j]]] = False
            out = self.engine.samples(self.t[at], y[at], self._P[i], U[at], active)
            out["lam"][:, ~active] = 0.0
            out["g"][:, ~active[:nh]] = np.nan
            out["velocity_residual"][:, ~active] = np.nan
            parts.append(out)
        return {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}

    @property
    def energy(self) -> np.ndarray:
        """(N, S): every member's Jacobi integral ``h`` at every sample."""
        return np.array([self.samples(i)["energy"] for i in range(len(self))])

    def __getitem__(self, coordinate):
        """(N, S): one coordinate of every member: ``ens[x]``."""
        return self.q[:, :, self.coordinates.index(coordinate)]

    def __repr__(self):
        return (f"LagrangianEnsemble(members={len(self)}, samples={len(self.t)}, "
                f"coordinates={self.coordinates}, method={self.method!r})")  # fmt: skip


def simulate_ensemble(
    system,
    t_span,
    *,
    q0,
    qd0=None,
    params=None,
    inputs=None,
    method="dop853",
    dt=None,
    rtol=None,
    atol=None,
    t_eval=None,
    stabilization="baumgarte",
    baumgarte=None,
    threads=None,
    chunk_size=None,
    tol=1e-9,
    max_steps=None,
    event_resolution=None,
) -> LagrangianEnsemble:
    """Integrate N members of ``system``, each with its own parameters, inputs and initial
    state, with the compiled engine.

    Parameters
    ----------
    system : LagrangianSystem
    t_span : (t0, t1)
    q0, qd0 : dict {coordinate: number or (N,) array}
        Every member's initial state, by coordinate (or its name). As for ``simulate``,
        dependent coordinates and velocities of a constrained system may be omitted and are
        solved for, member by member (a set-up cost); omitted velocities of an unconstrained
        system are zero. The states must satisfy the constraints (checked for every member in
        one compiled loop; the first violation is refused with its member index).
    params : dict {parameter: number or (N,) array}
        Every parameter of the system; a number is shared by all members.
    inputs : dict {input: number or (N,) array}, optional
        Constant inputs (a function of time runs with :meth:`LagrangianSystem.simulate`).
    method, dt, rtol, atol, t_eval, stabilization, baumgarte
        As for :func:`poinsot.lagrange.numeric.simulate` (``"projection"`` included);
        ``t_eval`` defaults to 201 samples.
    threads : int, optional
        Chunks run on this many threads (default: the CPUs available).
    chunk_size : int, optional
        Members per chunk (default: the members spread over the threads, 1000 at most).
    tol : float
        Largest relative constraint residual accepted in an initial state.
    max_steps : int, optional
        The most steps a member may take (default
        :data:`~poinsot.integrate.solve.DEFAULT_MAX_STEPS`): with a fixed-step method, a run
        whose members need more is refused before it starts, with the count; an adaptive
        member that reaches it stops there (status 0, NaN samples). With one-sided
        constraints, per phase between releases (as :meth:`LagrangianSystem.simulate`).
    event_resolution : int, optional
        The one-sided constraints' releases (``system.unilateral``) are detected at the
        steps' ends and at points no further apart than a grid of this many points on the
        run (default 2001; refused by a system without one-sided constraints, where it
        would have no effect), and
        located inside the core's time loop, member by member, as
        :meth:`LagrangianSystem.simulate` does: each member equals its single run bit for bit;
        ``ens.releases`` holds the instants.

    Returns
    -------
    LagrangianEnsemble

    Examples
    --------
    Pendulums of three lengths released from 0.01 rad: after a quarter of the small-amplitude
    period of the middle one, ``(π/2)√(l/g)``, it passes the bottom, the shorter one is already
    on the other side and the longer one still on its way.

    >>> import numpy as np
    >>> from poinsot.models import pendulum_polar
    >>> model = pendulum_polar()
    >>> th, l, g = (model.symbols[k] for k in ("theta", "l", "g"))
    >>> quarter = np.pi / 2 * np.sqrt(1.0 / model.params[g])
    >>> ens = model.system.simulate_ensemble(
    ...     (0, quarter), q0={th: 0.01}, params={**model.params, l: [0.5, 1.0, 2.0]})
    >>> np.sign(ens[th][:, -1].round(5)).tolist()
    [-1.0, 0.0, 1.0]
    """
    prepared = prepare_ensemble(system, t_span, method=method, dt=dt, rtol=rtol, atol=atol,
                                t_eval=t_eval, stabilization=stabilization,
                                baumgarte=baumgarte, threads=threads, chunk_size=chunk_size,
                                max_steps=max_steps,
                                event_resolution=event_resolution)  # fmt: skip
    return prepared.run(q0=q0, qd0=qd0, params=params, inputs=inputs, tol=tol)


def prepare_ensemble(system, t_span, *, method="dop853", dt=None, rtol=None, atol=None,
                     t_eval=None, stabilization="baumgarte", baumgarte=None, threads=None,
                     chunk_size=None, max_steps=None,
                     event_resolution=None) -> PreparedLagrangianEnsemble:  # fmt: skip
    """Check an ensemble's run and lower it for the core, once: the compiled model, the
    method, sampling, tolerances, stabilisation, budget and the run specification. The
    arguments are :func:`simulate_ensemble`'s less the members (initial states, parameters,
    inputs), checked here with the same errors; :meth:`PreparedLagrangianEnsemble.run` runs
    any members.

    Examples
    --------
    >>> from poinsot.models import pendulum_polar
    >>> model = pendulum_polar()
    >>> th, l = model.symbols["theta"], model.symbols["l"]
    >>> prepared = model.system.prepare_ensemble((0, 1), t_eval=[0, 1])
    >>> ens = prepared.run(q0={th: [0.1, 0.2]}, params={**model.params, l: 2.0})
    >>> ens[th].shape
    (2, 2)
    """
    from ..integrate.control import StepSizeController
    from ..integrate.driver import run_spec
    from .engine import compile_system

    # the run's settings, checked as a single run checks them (the budget is per member)
    st = check_settings(t_span, method=method, dt=dt, rtol=rtol, atol=atol, t_eval=t_eval,
                        stabilization=stabilization, baumgarte=baumgarte,
                        event_resolution=event_resolution, max_steps=max_steps,
                        watched=bool(system.unilateral))  # fmt: skip
    if threads is not None and (not isinstance(threads, int) or threads < 1):
        raise ValueError(f"`threads` must be a positive integer, found {threads!r}")
    if chunk_size is not None and (not isinstance(chunk_size, int) or chunk_size < 1):
        raise ValueError(f"`chunk_size` must be a positive integer, found {chunk_size!r}")
    t1 = st.t_span[1]
    times = np.array([t1]) if len(st.t_eval) == 0 else st.t_eval  # none: the run to t1
    control = None
    if st.solver.adaptive:  # dt: the first step, as for a single run
        control = StepSizeController(st.rtol, st.atol, first_step=st.dt)
        run = run_spec(st.solver.kind, t_end=t1, controller=control, t_eval=times,
                       max_steps=st.budget)  # fmt: skip
    else:
        run = run_spec(st.solver.kind, t_end=t1, dt=st.dt, data=st.solver.method_data(),
                       t_eval=times, max_steps=st.budget)  # fmt: skip
    return PreparedLagrangianEnsemble(system, compile_system(system), st, run, control,
                                      threads, chunk_size)  # fmt: skip


@dataclass(frozen=True)
class PreparedLagrangianEnsemble:
    """A Lagrangian ensemble's run, checked and lowered (:func:`prepare_ensemble`):
    :meth:`run` integrates any members (parameters, inputs, initial states) with it, lowering
    nothing again.

    Attributes
    ----------
    system : LagrangianSystem
    compiled : CompiledSystem
        The compiled model; parameters and inputs are runtime arguments.
    settings : the checked span, method, sampling, tolerances, stabilisation and budget
    spec : RunSpec
        The core's run specification, shared by every chunk.
    controller : StepSizeController or None
        The adaptive method's step control (for the members' cost estimate).
    threads, chunk_size : int or None
    """

    system: object
    compiled: object
    settings: object
    spec: object
    controller: object
    threads: int | None
    chunk_size: int | None

    def run(self, *, q0, qd0=None, params=None, inputs=None, tol=1e-9) -> LagrangianEnsemble:
        """Integrate the members given by ``q0``, ``qd0``, ``params`` and ``inputs`` (as
        :func:`simulate_ensemble` takes them; ``tol`` is the largest relative constraint
        residual accepted in an initial state)."""
        from .._threads import available_cpus

        system, engine, st = self.system, self.compiled, self.settings
        P, U, Z0 = _member_tables(system, engine, q0, qd0, params, inputs)
        t0 = st.t_span[0]
        if np.isnan(Z0).any():
            _complete_states(system, engine, t0, Z0, P, U, tol)
        _check_consistent(engine, t0, Z0, P, U, tol)
        gains = st.gains if st.stabilization == "baumgarte" else (0.0, 0.0)
        projection = st.stabilization == "projection" and system.n_constraints > 0
        workers = self.threads or available_cpus()
        N = len(Z0)
        chunk = self.chunk_size or max(1, min(1000, -(-N // workers)))
        if self.controller is not None:  # each member's steps, estimated before the run
            _check_members_budget(engine, self.controller, st, P, U, Z0, gains, projection,
                                  system, N)  # fmt: skip
        parts = [engine.model.run_ensemble(
            P[i0:i0 + chunk], U[i0:i0 + chunk], Z0[i0:i0 + chunk], gains[0], gains[1],
            projection, self.spec, t0, workers, list(system.unilateral), st.event_resolution)
            for i0 in range(0, N, chunk)]  # fmt: skip
        Y, status, nsteps, nfev, releases = (np.concatenate(c) for c in zip(*parts, strict=True))
        times = st.t_eval
        if len(times) == 0:  # the run to t1, none of its states
            Y = Y[:, :0]
        return LagrangianEnsemble(system, engine, times, Y, P, U, status, nsteps, nfev,
                                  st.solver.name, st.stabilization, releases)  # fmt: skip


def _member_tables(system, engine, q0, qd0, params, inputs):
    """The members' tables ``(P, U, Z0)``, one row per member: parameters and inputs in the
    compiled model's order, and the initial states ``[q, q̇]`` (NaN where a coordinate or a
    velocity is omitted and must be solved from the constraints)."""
    m = system.n_constraints
    P_cols = _by_key(params, system.parameters, "params", "parameter")
    U_cols = _by_key(inputs, system.inputs, "inputs", "input")
    Q_cols = _by_key(q0, system.coordinates, "q0", None if system.n_holonomic else "coordinate")
    V_cols = _by_key(qd0, system.coordinates, "qd0", None)
    N = _members(("params", P_cols), ("inputs", U_cols), ("q0", Q_cols), ("qd0", V_cols))

    def table(keys, cols, default=None):
        out = np.empty((N, len(keys)))
        for j, k in enumerate(keys):
            out[:, j] = cols[k] if k in cols else default
        return out

    Z0 = np.concatenate([table(system.coordinates, Q_cols, np.nan),
                         table(system.coordinates, V_cols, 0.0 if not m else np.nan)],
                        axis=1)  # fmt: skip
    return table(engine.parameters, P_cols), table(engine.inputs, U_cols), Z0


def _check_members_budget(engine, control, st, P, U, Z0, gains, projection, system, N) -> None:
    """Refuse an adaptive ensemble whose members cannot end within the step budget: the
    steps of the first member and of the fastest moving one (largest |q̇₀|), each estimated
    from its own short runs (:func:`~poinsot.integrate.driver.estimate_steps_by_spans`)."""
    from .._bindings import runs as core_runs
    from ..integrate.driver import estimate_steps_by_spans, pilot_members, run_spec
    from ..integrate.solve import StepBudgetError

    (t0, t1), n = st.t_span, len(system.coordinates)
    with np.errstate(over="ignore", invalid="ignore"):
        speed = np.linalg.norm(Z0[:, n:], axis=1)
    for i in pilot_members(speed):

        def run_to(t, cap, i=i):
            pilot = run_spec(st.solver.kind, t_end=t, controller=control, t_eval=[t],
                             max_steps=cap)  # fmt: skip
            _, status, nsteps, _, _ = engine.model.run_ensemble(
                P[i : i + 1], U[i : i + 1], Z0[i : i + 1], gains[0], gains[1], projection,
                pilot, t0, 1, list(system.unilateral), st.event_resolution)  # fmt: skip
            finished = {core_runs.FINISHED: True, core_runs.TERMINATED: True, 0: False}
            return int(nsteps[0]), finished.get(int(status[0]))

        needed = estimate_steps_by_spans(run_to, t0, t1)
        if needed > st.budget:
            what = f"member {i} of {N} (estimated from its first steps)"
            raise StepBudgetError(needed, st.budget, None, t0, t1, what)


def _complete_states(system, engine, t0, Z0, P, U, tol):
    """Solve every member's omitted coordinates and velocities from the constraints, in place
    (:func:`~poinsot.lagrange.arguments.consistent_initial_state` on the compiled module, member
    by member: a set-up cost in Python, none per step)."""
    from .arguments import consistent_initial_state
    from .numeric import _EngineNumeric

    n = system.n_coordinates
    for i in range(len(Z0)):
        num = _EngineNumeric(system, dict(zip(engine.parameters, P[i], strict=True)), engine)
        constant = U[i]
        num.u_of = lambda t, q, qd, c=constant: c
        try:
            q, qd = consistent_initial_state(system, num, t0, Z0[i, :n].copy(),
                                             Z0[i, n:].copy(), tol=tol,
                                             guessable=False)  # fmt: skip
        except ValueError as exc:
            raise ValueError(f"member {i}: {exc}") from None
        Z0[i, :n], Z0[i, n:] = q, qd


def _check_consistent(engine, t0, Z0, P, U, tol):
    """Refuse the first member whose initial state violates the constraints (or whose
    equations cannot be solved there), naming it; one compiled loop over the members."""
    pos, vel, solvable = engine.model.starts(float(t0), Z0, P, U)
    n = engine.n
    scale_q = 1 + np.max(np.abs(Z0[:, :n]), axis=1)
    scale_v = 1 + np.max(np.abs(Z0[:, n:]), axis=1)
    for bad, what, value in ((pos > tol * scale_q, "holonomic constraints are violated by "
                              "max |g(q0)|", pos),
                             (vel > tol * scale_v, "velocity constraints are violated by "
                              "max |G q̇0 + b|", vel)):  # fmt: skip
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(f"member {i}: inconsistent initial state, the {what} = "
                             f"{value[i]:.3g}")  # fmt: skip
    if not solvable.all():
        i = int(np.argmin(solvable))
        raise ValueError(f"member {i}: the equations of motion cannot be solved at the initial "
                         "state (a singular mass matrix: zero masses or inertia?)")  # fmt: skip
