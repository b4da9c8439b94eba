"""``simulate_ensemble``: many initial conditions (and inertias) of one body, in compiled chunks.

The thin layer of MuJoCo's ``rollout``: check shapes once, cut the ensemble into chunks, make
one call of the compiled core per chunk (``poinsot._core.run_ensemble``,
``crates/core/src/ensemble.rs``), which writes the states into the preallocated result in
place. No Python object per member and no Python per step. A chunk's members run in
parallel on the core's threads (the GIL released), or chunks run on the workers of a Dask
cluster; every member's arithmetic is independent of the chunk it falls in, so the results
do not depend on ``chunk_size``, ``threads`` or ``client``, bit for bit.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass

import numpy as np

from .. import layout
from .._validation import as_rotation_matrices, as_sample_times, as_scalar, as_vectors
from ..bodies import check_inertia
from ..dynamics import RigidBodySystem
from ..forces import BodyFrame
from ..integrate.base import get_solver
from ..integrate.driver import check_solver_fits
from ..integrate.problem import RIGID_METHODS
from ..integrate.solve import (
    StepBudgetError,
    check_budget,
    check_max_steps,
    check_no_silent_tolerances,
    check_t_span,
    check_tolerances,
)
from .executors import run_chunks
from .result import EnsembleResult
from .tasks import ChunkTask, EnsembleSpec

__all__ = ["PreparedEnsemble", "prepare_ensemble", "simulate_ensemble"]

#: Bytes of samples one chunk may hold (m · n · 18 · 8): bounds the memory of a run whatever N.
CHUNK_BYTES = 32 * 2**20
#: The smallest default chunk (members per call of the core).
MIN_CHUNK = 64
#: Relative tolerance of the checks on per-member inertias (as for one body).
INERTIA_RTOL = 1e-9


def simulate_ensemble(
    body,
    t_span,
    *,
    omega0,
    Q0=None,
    R0=None,
    V0=None,
    moments=None,
    inertia=None,
    forces=(),
    pivot=None,
    method="rk4",
    dt=None,
    rtol=None,
    atol=None,
    t_eval=None,
    chunk_size=None,
    threads=None,
    client=None,
    progress=None,
    flips=True,
    keep_states=True,
    reductions=None,
    max_steps=None,
) -> EnsembleResult:
    """Integrate N motions of ``body`` at once: eqs (07)–(09) for every member, in compiled
    chunks (``docs/ensembles.md``).

    Parameters
    ----------
    body : RigidBody
        The body every member shares (its mass and centre of mass always; its inertia unless
        ``moments`` or ``inertia`` is given).
    t_span : (float, float)
    omega0 : array_like (N, 3)
        Initial angular velocities, body frame: one row per member.
    Q0 : (3, 3) or (4,), or (N, 3, 3) or (N, 4), optional
        Initial attitudes: one shared, or one per member (identity by default).
    R0, V0 : (3,) or (N, 3), optional
        Initial centre of mass and velocity, shared or per member (as in
        :func:`~poinsot.simulate`: with a ``pivot``, ``V0`` follows from ω and must be omitted).
    moments : (N, 3), optional
        Each member's principal moments along the body's x, y, z axes (its inertia
        ``diag(moments)``).
    inertia : (N, 3, 3), optional
        Each member's inertia about the centre of mass, body frame (instead of ``moments``).
    forces : sequence of built-in :class:`~poinsot.forces.Force`
        Gravity, central gravity (with its gradient torque), springs, drag, point forces and
        torques; forces given by Python callables are refused (they cannot run in a chunk).
    pivot : (3,), optional
        A body point held fixed (heavy tops); each member's pivot stays where its initial
        state puts it.
    method : str or Solver class
        Any method of :func:`~poinsot.simulate`: ``"rk4"`` (default), ``"rkmk4"``,
        ``"splitting"``, ``"dop853"`` (each member its own step sizes) or a registered one.
    dt : float
        Step of fixed-step methods (required for them); first step of adaptive ones.
    rtol, atol : float, optional
        Tolerances of adaptive methods.
    t_eval : array_like (n,), optional
        Sample times. Without them only the final state is kept (n = 1, at ``t_span[1]``);
        an empty array keeps no samples (n = 0; the final states and statistics remain).
    chunk_size : int, optional
        Members per compiled call (default: about 32 MiB of samples per chunk, and at least
        four chunks per thread when N is large).
    threads : int, optional
        Threads running each chunk's members (default: the CPUs this process may use).
    client : dask.distributed.Client, optional
        Run the chunks on a Dask cluster instead; only arrays travel. Dask is imported only
        when this is given.
    progress : bool or callable, optional
        A progress bar (tqdm) over members; ``None`` shows it when standard error is a
        terminal and the run has more than one chunk, ``False`` never. A callable is called
        with ``(members done, N)``.
    flips : bool
        Record each member's flips: the sign changes of ω along the intermediate principal
        axis, with their first and last times and their count (every step is observed).
    keep_states : bool
        Keep the samples (N, n, 18). ``False`` keeps only the final states and the
        reductions: any N then runs in memory bounded by the chunks.
    reductions : dict, optional
        User reductions, name → function. A numba-compiled function ``f(t, y) -> float`` of
        a body-frame state ``y`` (18,) is evaluated at every sample (result (N, n)); a Python
        function ``g(chunk) -> array (m, ...)`` receives each chunk's
        :class:`~poinsot.ensemble.ChunkSamples` and returns one row per member.
    max_steps : int, optional
        Steps each member may take (default :data:`~poinsot.integrate.solve.DEFAULT_MAX_STEPS`).
        A fixed-step run that needs more is refused before it starts; an adaptive one is
        refused when its members' steps, estimated from a short run of the first member and
        of the fastest spinning one (:func:`~poinsot.integrate.driver.estimate_steps`), exceed
        it; a member that still reaches it stops there (status 0, NaN samples).

    Returns
    -------
    EnsembleResult

    Examples
    --------
    >>> import numpy as np
    >>> from poinsot import RigidBody
    >>> from poinsot.ensemble import simulate_ensemble
    >>> body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    >>> rng = np.random.default_rng(0)
    >>> omega0 = np.c_[rng.normal(0, 1e-2, 100), np.ones(100), rng.normal(0, 1e-2, 100)]
    >>> res = simulate_ensemble(body, (0, 50), omega0=omega0, dt=1e-2)
    >>> res.omega.shape, bool(res.success.all())
    ((100, 1, 3), True)
    >>> bool((res.flip_count >= 1).all())   # every member near the intermediate axis flips
    True
    """
    prepared = prepare_ensemble(body, t_span, forces=forces, pivot=pivot, method=method, dt=dt,
                                rtol=rtol, atol=atol, t_eval=t_eval, flips=flips,
                                keep_states=keep_states, reductions=reductions,
                                max_steps=max_steps)  # fmt: skip
    return prepared.run(omega0=omega0, Q0=Q0, R0=R0, V0=V0, moments=moments, inertia=inertia,
                        chunk_size=chunk_size, threads=threads, client=client,
                        progress=progress)  # fmt: skip


def prepare_ensemble(body, t_span, *, forces=(), pivot=None, method="rk4", dt=None, rtol=None,
                     atol=None, t_eval=None, flips=True, keep_states=True,
                     reductions=None, max_steps=None) -> PreparedEnsemble:  # fmt: skip
    """Check an ensemble's run and lower its body and forces once: the
    :class:`PreparedEnsemble` that :func:`simulate_ensemble` runs. The arguments are
    :func:`simulate_ensemble`'s less the members (``omega0``, ``Q0``, ``R0``, ``V0``,
    ``moments``, ``inertia``) and how they run (``chunk_size``, ``threads``, ``client``,
    ``progress``), checked here with the same errors (an adaptive run's members are
    estimated by :meth:`PreparedEnsemble.run`, which knows them).

    Examples
    --------
    >>> import numpy as np
    >>> from poinsot import RigidBody
    >>> run = prepare_ensemble(RigidBody(1.0, np.diag([1.0, 2.0, 3.0])), (0, 1), dt=1e-2)
    >>> [run.run(omega0=[[0, w, 0]]).omega[0, -1, 1].round(9) for w in (1.0, 2.0)]
    [np.float64(1.0), np.float64(2.0)]
    """
    no_samples = isinstance(t_eval, list | tuple | np.ndarray) and len(t_eval) == 0
    if no_samples and reductions:
        raise ValueError("`reductions` are evaluated at the samples: an empty `t_eval` has none")
    spec, system = _prepare(body, t_span, forces, pivot, method, dt, rtol, atol,
                            None if no_samples else t_eval, flips, reductions,
                            keep_states, max_steps)  # fmt: skip
    return PreparedEnsemble(body, system, spec, no_samples)


@dataclass(frozen=True)
class PreparedEnsemble:
    """An ensemble's run, checked and lowered (:func:`prepare_ensemble`): :meth:`run`
    integrates any set of members.

    Attributes
    ----------
    body : RigidBody
    system : RigidBodySystem
        The body, its forces lowered for the core and the pivot.
    spec : EnsembleSpec
        What every chunk shares: the method, the span and samples, the body's parameters and
        the lowered forces.
    """

    body: object
    system: RigidBodySystem
    spec: EnsembleSpec
    no_samples: bool = False

    def run(self, *, omega0, Q0=None, R0=None, V0=None, moments=None, inertia=None,
            chunk_size=None, threads=None, client=None,
            progress=None) -> EnsembleResult:  # fmt: skip
        """Integrate the members given as :func:`simulate_ensemble` takes them; nothing is
        lowered again (but the forces of members with their own principal axes)."""
        start = time.perf_counter()
        spec, members = _members(self.spec, self.system, omega0, Q0, R0, V0, moments, inertia)
        N = members.n
        if spec.controller is not None:  # adaptive: each member's steps, estimated up front
            _check_members_budget(spec, self.system, members)
        n = len(spec.t_eval)
        chunk = _chunk_size(chunk_size, N, n, threads, client)
        result = EnsembleResult.allocate(spec, N, spec.keep_states, self.body, members)
        tasks = (members.task(i0, min(i0 + chunk, N)) for i0 in range(0, N, chunk))
        run_chunks(spec, tasks, N, chunk, result.absorb, threads=threads, client=client,
                   progress=progress, views=result.views)  # fmt: skip
        if self.no_samples:
            result.drop_samples()
        result.wall_time = time.perf_counter() - start
        return result


# --------------------------------------------------------------------------- preparation
@dataclass
class _Members:
    """The per-member inputs, validated; cut into :class:`ChunkTask` s on demand."""

    omega: np.ndarray  # (N, 3)
    Q: np.ndarray  # (1 | N, 3, 3)
    R: np.ndarray  # (0 | 1 | N, 3)
    V: np.ndarray  # (0 | 1 | N, 3)
    inertia: np.ndarray | None  # (N, 3, 3) per-member inertia about the centre of mass
    system: RigidBodySystem
    lower_per_member: bool

    @property
    def n(self) -> int:
        return len(self.omega)

    def _cut(self, a, i0, i1):
        return a if len(a) <= 1 else a[i0:i1]

    def task(self, i0, i1) -> ChunkTask:
        inertia = None if self.inertia is None else self.inertia[i0:i1]
        force_params = None
        if self.lower_per_member:  # forces with body points, on bodies with their own axes
            from .._bindings import ensemble as core_ensemble

            _, axes, _ = core_ensemble.member_bodies(
                float(self.system.mass), np.ascontiguousarray(inertia),
                [float(x) for x in self.system.c], self.system.pivot is not None,
            )  # fmt: skip
            force_params = _lower_per_member(self.system, axes)
        return ChunkTask(
            i0,
            i1,
            np.ascontiguousarray(self.omega[i0:i1]),
            np.ascontiguousarray(self._cut(self.Q, i0, i1)),
            np.ascontiguousarray(self._cut(self.R, i0, i1)),
            np.ascontiguousarray(self._cut(self.V, i0, i1)),
            None if inertia is None else np.ascontiguousarray(inertia),
            force_params,
        )


def _check_members_budget(spec, system, members) -> None:
    """Refuse an adaptive ensemble whose members cannot end within the step budget: the steps
    of the first member and of the fastest spinning one, each estimated from its own first
    steps (:func:`~poinsot.integrate.driver.estimate_steps`, on the shared body), before any
    chunk runs."""
    from ..integrate.driver import estimate_steps, pilot_members

    c = spec.controller
    with np.errstate(over="ignore", invalid="ignore"):
        rates = np.linalg.norm(members.omega, axis=1)
    for i in pilot_members(rates):
        row = {k: None if len(a) == 0 else a[0 if len(a) == 1 else i]
               for k, a in (("Q0", members.Q), ("R0", members.R), ("V0", members.V))}  # fmt: skip
        y0 = system.initial_state(omega0=members.omega[i], **row)
        needed = estimate_steps(system, spec.method_name, (spec.t0, spec.t1), y0,
                                dt=c.first_step, rtol=c.rtol, atol=c.atol)  # fmt: skip
        if needed > spec.max_steps:
            what = f"member {i} of {members.n} (estimated from its first steps)"
            raise StepBudgetError(needed, spec.max_steps, None, spec.t0, spec.t1, what)


def _lower_per_member(system, axes):
    """Lowered forces (m, n_forces, FORCE_PARAMS) for members with their own principal axes:
    each force's own :meth:`~poinsot.forces.Force.lower`, in each member's frame."""
    builtin = [f for f in system.forces if f.compiled]
    com = np.asarray(system.body.center_of_mass, dtype=float)
    out = np.empty((len(axes), len(builtin), layout.FORCE_PARAMS))
    for i, E in enumerate(axes):
        frame = BodyFrame(com, E)
        for j, f in enumerate(builtin):
            out[i, j] = f.lower(frame)
    return out


def _prepare(body, t_span, forces, pivot, method, dt, rtol, atol, t_eval, flips, reductions,
             keep_states, max_steps=None):  # fmt: skip
    """The run's :class:`EnsembleSpec` (its kind that of members sharing the body's inertia)
    and the body's system, checked and lowered once."""
    from ..bodies import RigidBody
    from ..tops import heavy_top

    if not isinstance(body, RigidBody):
        raise TypeError(f"`body` must be a poinsot RigidBody, found {type(body).__name__}")
    t0, t1 = check_t_span(t_span)
    solver = get_solver(method)
    if isinstance(forces, str) or not hasattr(forces, "__iter__"):
        raise TypeError(f"`forces` must be a sequence of Force objects, found {forces!r}")
    system = RigidBodySystem(body, forces, pivot)
    if not system.compiled or system.c_forces:
        names = ", ".join(f.name for f in system.python_forces + system.c_forces)
        raise ValueError(
            "`forces`: an ensemble runs built-in forces only (Gravity, CentralGravity, Spring, "
            f"LinearDrag, QuadraticDrag, PointForce, Torque); these are user callables: {names}"
        )
    check_solver_fits(solver, system)
    if solver.kind not in RIGID_METHODS:
        raise ValueError(f"`method` {solver.name!r} has no step in the compiled core")
    check_no_silent_tolerances(solver, rtol=rtol, atol=atol)
    rtol, atol = check_tolerances(rtol, atol)
    budget = check_max_steps(max_steps)
    if solver.adaptive:
        from ..integrate.control import StepSizeController
        from ..integrate.dop853 import DEFAULT_ATOL, DEFAULT_RTOL

        controller = StepSizeController(
            DEFAULT_RTOL if rtol is None else rtol,
            DEFAULT_ATOL if atol is None else atol,
            first_step=None if dt is None else as_scalar(dt, "dt"),
        )
        step = 0.0
    else:
        if dt is None:
            raise ValueError(f"`method` {solver.name!r} is fixed-step: `dt` must be given")
        step = as_scalar(dt, "dt")
        if not step > 0:
            raise ValueError(f"`dt` must be a positive number, found {step}")
        check_budget(solver, t0, t1, step, budget)  # each member's steps within the budget
        controller = None
    times = np.array([t1]) if t_eval is None else as_sample_times(t_eval, t0, t1)
    if len(times) == 0:
        raise ValueError("`t_eval` must hold at least one time")
    kind = "rigid" if (pivot is not None or len(system.force_kind)) else "free"
    spec = EnsembleSpec(
        kind=kind,
        method_kind=solver.kind,
        method_name=solver.name,
        method_data=solver.method_data(),
        controller=controller,
        t0=t0,
        t1=t1,
        dt=step,
        t_eval=np.ascontiguousarray(times),
        mass=float(body.mass),
        com=np.asarray(body.center_of_mass, dtype=float),
        inertia=np.ascontiguousarray(np.asarray(body.inertia, dtype=float)[None]),
        c=system.c.copy(),
        pivot=np.zeros(3) if system.pivot is None else system.pivot.copy(),
        has_pivot=system.pivot is not None,
        body_params=system.body_parameters(np.zeros(3) if system.pivot is not None else None),
        axes=np.ascontiguousarray(system.principal_axes[None]),
        force_kind=system.force_kind,
        force_params=np.ascontiguousarray(system.force_params),
        flips=bool(flips),
        reductions=_check_reductions(reductions),
        keep_states=bool(keep_states),
        top=heavy_top(body, pivot, list(forces)) if pivot is not None else None,
        max_steps=budget,
    )
    return spec, system


def _members(spec, system, omega0, Q0, R0, V0, moments, inertia):
    """The members' inputs, checked, and the spec for them (torque-free members with their
    own inertia run as ``"free_varied"``)."""
    from dataclasses import replace

    omega = as_vectors(omega0, "omega0", single_ok=False)
    N = len(omega)
    if N == 0:
        raise ValueError("`omega0` must hold at least one member, found shape (0, 3)")
    Q = as_rotation_matrices(np.eye(3) if Q0 is None else Q0, "Q0", N)
    R = np.zeros((0, 3)) if R0 is None else as_vectors(R0, "R0", N)
    if V0 is not None and system.pivot is not None:
        raise ValueError("`V0` must be omitted with a `pivot`: it follows from `omega0`")
    V = np.zeros((0, 3)) if V0 is None else as_vectors(V0, "V0", N)
    member_inertia = _member_inertia(moments, inertia, N)
    if member_inertia is None and system.degenerate:
        raise ValueError(
            "`body` is degenerate (all mass on a line): the spin of its members about that "
            "line is undefined; give each member a full inertia (`moments` or `inertia`)"
        )
    if spec.kind == "free" and member_inertia is not None:
        spec = replace(spec, kind="free_varied")
    lower = member_inertia is not None and any(
        f.compiled and _depends_on_frame(f, system) for f in system.forces
    )
    return spec, _Members(omega, Q, R, V, member_inertia, system, lower)


def _depends_on_frame(force, system) -> bool:
    """Whether the force's lowered form depends on the body's principal axes."""
    com = np.asarray(system.body.center_of_mass, dtype=float)
    rng = np.random.default_rng(0)
    E, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return not np.array_equal(
        force.lower(BodyFrame(com, np.eye(3))), force.lower(BodyFrame(com, E))
    )


def _member_inertia(moments, inertia, N):
    """Per-member inertia (N, 3, 3) from ``moments`` or ``inertia``, checked member by member
    (symmetric, positive definite, the triangle inequality), or None."""
    if moments is not None and inertia is not None:
        raise ValueError("give `moments` or `inertia`, not both")
    if moments is not None:
        I = as_vectors(moments, "moments", N, single_ok=False)
        J = np.zeros((N, 3, 3))
        J[:, [0, 1, 2], [0, 1, 2]] = I
        name = "moments"
    elif inertia is not None:
        J = np.asarray(inertia, dtype=float)
        if J.shape != (N, 3, 3):
            raise ValueError(
                f"`inertia` must have shape ({N}, 3, 3) (one per member), found {J.shape}"
            )
        name = "inertia"
    else:
        return None
    check_inertia(J, name, rtol=INERTIA_RTOL, each=True, definite=True)  # the core's check
    J = 0.5 * (J + J.transpose(0, 2, 1))
    return np.ascontiguousarray(J)


def _check_reductions(reductions):
    if reductions is None:
        return {}
    if not isinstance(reductions, dict):
        raise TypeError(f"`reductions` must be a dict name → function, found {reductions!r}")
    for name, fn in reductions.items():
        if not isinstance(name, str) or not name.isidentifier():
            raise ValueError(f"`reductions`: names must be identifiers, found {name!r}")
        if not callable(fn):
            raise TypeError(f"`reductions[{name!r}]` must be callable, found {fn!r}")
    return dict(reductions)


def _chunk_size(chunk_size, N, n, threads, client):
    if chunk_size is not None:
        if not isinstance(chunk_size, int | np.integer) or chunk_size < 1:
            raise ValueError(f"`chunk_size` must be a positive integer, found {chunk_size!r}")
        return int(chunk_size)
    by_memory = max(1, CHUNK_BYTES // (n * layout.STATE_SIZE * 8))
    workers = threads or (2 if client is not None else len(os.sched_getaffinity(0)))
    by_balance = math.ceil(N / (4 * max(1, workers)))
    size = max(MIN_CHUNK, min(by_memory, by_balance))
    return int(min(size, by_memory, N) if N > MIN_CHUNK else N)
