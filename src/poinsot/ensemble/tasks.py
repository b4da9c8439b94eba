"""One chunk of an ensemble: what travels to a thread or a Dask worker, and what comes back.

An :class:`EnsembleSpec` (shared by every chunk: the body's parameters, the lowered forces, the
method's tableau, the sample times) and a :class:`ChunkTask` (the chunk's members) are plain
arrays and numbers, so a chunk pickles cheaply; :func:`run_chunk` makes one call of the
compiled core (``poinsot._core.run_ensemble``, ``crates/core/src/ensemble.rs``), which runs
the members in parallel. It holds no physics.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "ChunkOutput",
    "ChunkSamples",
    "ChunkTask",
    "ChunkViews",
    "EnsembleSpec",
    "run_chunk",
]


@dataclass(frozen=True)
class EnsembleSpec:
    """What every chunk shares. ``kind`` is ``"free"`` (torque-free, one inertia),
    ``"free_varied"`` (torque-free, an inertia per member) or ``"rigid"`` (built-in forces,
    or a pivot)."""

    kind: str
    method_kind: str  # the core's name of the method's step: rk4, erk, rkmk, splitting, dop853
    method_name: str
    method_data: dict  # the tableau or composition (Solver.method_data)
    controller: object  # a StepSizeController (DOP853), or None
    t0: float
    t1: float
    dt: float
    t_eval: np.ndarray
    mass: float
    com: np.ndarray
    inertia: np.ndarray  # (1, 3, 3) the shared inertia about the centre of mass, body frame
    c: np.ndarray  # centre of mass − reference point, body frame
    pivot: np.ndarray
    has_pivot: bool
    body_params: np.ndarray  # (BODY_SIZE,) the shared body's parameters (pivot not placed)
    axes: np.ndarray  # (1, 3, 3) its principal axes
    force_kind: np.ndarray
    force_params: np.ndarray  # (n_forces, FORCE_PARAMS) lowered in the shared principal frame
    flips: bool
    reductions: dict = field(default_factory=dict)
    keep_states: bool = True
    top: object = None  # the heavy symmetric top the body, pivot and forces make (tops.heavy_top)
    max_steps: int = 100_000_000  # steps each member may take (integrate.solve.DEFAULT_MAX_STEPS)


@dataclass(frozen=True)
class ChunkTask:
    """Members ``start … stop − 1``: their initial conditions (rows per member, or one shared
    row; ``R``/``V`` with no rows take the defaults), their inertias when they differ and their
    lowered forces when those depend on each member's axes."""

    start: int
    stop: int
    omega: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    V: np.ndarray
    inertia: np.ndarray | None = None
    force_params: np.ndarray | None = None


@dataclass(frozen=True)
class ChunkViews:
    """Where a chunk run in this process writes its states in place (MuJoCo's ``rollout``
    style, no copy): views of the result's arrays for its members, samples ``Y``
    (m, n, 18, or None when the states are not kept) and final states (m, 18), all
    C-contiguous."""

    Y: np.ndarray | None
    final: np.ndarray


@dataclass
class ChunkOutput:
    """What a chunk returns: samples ``Y`` (m, n, 18, body frame; None unless the states are
    kept), final states (m, 18), initial states ``Y0`` (m, 18), per-member statistics and run
    counters, and the user reductions. ``in_place``: the states were written to the
    :class:`ChunkViews` given, and ``Y``, ``final`` and ``Y0`` are those views."""

    start: int
    stop: int
    Y: np.ndarray | None
    final: np.ndarray
    Y0: np.ndarray
    energy: np.ndarray
    momentum: np.ndarray
    orthogonality: np.ndarray
    first_flip: np.ndarray
    last_flip: np.ndarray
    flip_count: np.ndarray
    status: np.ndarray
    nsteps: np.ndarray
    nfev: np.ndarray
    reductions: dict
    in_place: bool = False


@dataclass(frozen=True)
class ChunkSamples:
    """A chunk's samples as a user reduction sees them: ``members`` (m,) their indices,
    ``t`` (n,), ``omega`` (m, n, 3) body frame, ``Q`` (m, n, 3, 3), ``R`` and ``V`` (m, n, 3)."""

    members: np.ndarray
    t: np.ndarray
    omega: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    V: np.ndarray


def _native(x):
    """``x`` as the core reads arrays: C-contiguous and aligned. An array unpickled on a
    Dask worker can sit at an unaligned offset of the message's buffer; it is copied then,
    else passed as it is (None too)."""
    return None if x is None else np.require(x, requirements=("C", "A"))


def initial_states(spec: EnsembleSpec, task: ChunkTask) -> np.ndarray:
    """The body-frame initial states (m, 18) of a chunk's members, from their inputs (the
    core's ``initial_states``: the reference point's velocity from a pivot, and so on).
    A chunk computes them to run; the result computes them again on demand
    (:attr:`~poinsot.ensemble.EnsembleResult.initial_state`) instead of keeping them."""
    from .._bindings import rigid as core_rigid

    line = [0.0] * 3  # degenerate bodies are refused before any chunk runs
    a = _native
    return core_rigid.initial_states(a(task.Q), a(task.omega), a(task.R), a(task.V),
                                     list(spec.com), list(spec.c), list(spec.pivot),
                                     spec.has_pivot, line)  # fmt: skip


def run_chunk(
    spec: EnsembleSpec, task: ChunkTask, threads: int = 1, out: ChunkViews | None = None
) -> ChunkOutput:
    """Integrate one chunk in one call of the compiled core (:func:`poinsot._core.run_ensemble`,
    the members in parallel on ``threads`` threads): initial states, bodies and forces by
    member, the run, the statistics streamed per member. With ``out``, the states are written
    to its views (a run in this process); else new arrays are returned (a Dask worker)."""
    from .._bindings import ensemble as core_ensemble
    from ..integrate.driver import run_spec

    a = _native  # arrays that crossed to a Dask worker may come unaligned
    Y0 = initial_states(spec, task)
    if task.inertia is not None:
        bodies, axes, _ = core_ensemble.member_bodies(spec.mass, a(task.inertia),
                                                      list(spec.c), spec.has_pivot)  # fmt: skip
        inertia = task.inertia
    else:
        bodies, axes, inertia = spec.body_params[None], spec.axes, spec.inertia
    params = spec.force_params[None] if task.force_params is None else task.force_params
    keep = spec.keep_states or bool(spec.reductions)
    in_place = out is not None
    Y_out = out.Y if in_place and spec.keep_states else None
    run = run_spec(spec.method_kind, t_end=spec.t1, dt=spec.dt, data=spec.method_data,
                   controller=spec.controller, t_eval=spec.t_eval,
                   max_steps=spec.max_steps)  # fmt: skip
    (Y, final, energy, momentum, orthogonality, first, last, count, status, nsteps,
     nfev) = core_ensemble.run_ensemble(
        run, spec.t0, a(inertia), a(bodies), a(axes), a(spec.force_kind), a(params), Y0,
        flips=spec.flips, keep_samples=keep, threads=threads, samples_out=Y_out,
        finals_out=out.final if in_place else None,
    )  # fmt: skip
    if Y_out is not None:
        Y = Y_out
    if in_place:
        final = out.final
    return ChunkOutput(
        task.start, task.stop, Y if spec.keep_states else None, final, Y0, energy, momentum,
        orthogonality, first, last, count, status, nsteps, nfev,
        _user_reductions(spec, task, Y), in_place,
    )  # fmt: skip


def _user_reductions(spec, task, Y) -> dict:
    out = {}
    if not spec.reductions:
        return out
    from ..layout import STATE_SLICES

    def block(name):
        return Y[..., STATE_SLICES[name]]

    samples = ChunkSamples(
        np.arange(task.start, task.stop),
        spec.t_eval,
        block("omega"),
        block("Q").reshape(*Y.shape[:2], 3, 3),
        block("R"),
        block("V"),
    )
    for name, fn in spec.reductions.items():
        if _is_compiled(fn):
            out[name] = _evaluate_compiled(fn, spec.t_eval, Y)
            continue
        value = np.asarray(fn(samples))
        if value.ndim == 0 or value.shape[0] != Y.shape[0]:
            raise ValueError(
                f"`reductions[{name!r}]` must return one row per member of the chunk "
                f"({Y.shape[0]}), found shape {value.shape}"
            )
        out[name] = value
    return out


def _is_compiled(fn) -> bool:
    return type(fn).__module__.startswith("numba") and hasattr(fn, "py_func")


_EVALUATORS: dict = {}


def _evaluate_compiled(fn, t, Y):
    """``f(t_k, Y[i, k])`` for every member and sample, in one compiled loop (compiled once
    per process for the user's function: it cannot be cached on disk)."""
    import numba

    loop = _EVALUATORS.get(fn)
    if loop is None:

        def evaluate(t, Y):
            out = np.empty(Y.shape[:2])
            for i in range(Y.shape[0]):
                for k in range(Y.shape[1]):
                    out[i, k] = fn(t[k], Y[i, k])
            return out

        loop = _EVALUATORS[fn] = numba.njit(nogil=True)(evaluate)
    return loop(t, Y)
