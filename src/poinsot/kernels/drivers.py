"""Time loops: the whole integration of a system in one compiled call.

A driver advances the solver's state until the end time, keeping only the samples asked for,
and returns a status code. It allocates its work space once per call and nothing per step, and
it is *resumable*: the time, the next step size, the state (and the FSAL derivative) live in
arrays the caller owns, and ``max_steps`` bounds the steps per call, so the Python layer can
report progress, grow an output buffer or stop, between calls, at no cost per step.

Sampling (diffrax's ``SaveAt``): with sample times ``t_eval`` (increasing), fixed-step methods
shorten a step to land on each sample, the adaptive method interpolates with its dense output;
without them, the start, every ``save_every``-th step and the end are kept.

``counters`` (int64) holds :data:`STATUS`, :data:`N_OUT` (samples written), :data:`NEXT_SAMPLE`
(index into ``t_eval``), :data:`N_STEPS`, :data:`N_FEV` and :data:`N_REJECTED`; ``clock``
(float64) holds the current time and, for the adaptive method, the next step size.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel
from .layout import load_state, store_state
from .observers import observe
from .steppers import (
    ATOL,
    DOP853,
    ERK,
    FIRST_STEP,
    MAX_STEP,
    RK4,
    RKMK,
    RTOL,
    SPLITTING,
    dop853_dense_into,
    dop853_error_norm,
    dop853_interpolate_into,
    dop853_step,
    erk_step,
    evaluate,
    initial_step_size,
    rk4_tuple_step,
    rkmk_step,
    solver_output_into,
    splitting_step,
    step_size_factor,
)
from .systems import constrain, lanes, project, state_size
from .tableaux import (
    DOP853_INTERPOLATOR_POWER,
    DOP853_STAGES,
    DOP853_STAGES_EXTENDED,
)

__all__ = [
    "CHECK_EVERY",
    "CLOCK_SIZE",
    "COUNTERS_SIZE",
    "FINISHED",
    "NEXT_SAMPLE",
    "NONFINITE",
    "N_FEV",
    "N_OUT",
    "N_REJECTED",
    "N_STEPS",
    "OUTPUT_FULL",
    "RUNNING",
    "STATUS",
    "STEP_TOO_SMALL",
    "run_adaptive",
    "run_erk",
    "run_rk4",
    "run_rkmk",
    "run_splitting",
]

# status codes
RUNNING = 0  #: stopped after ``max_steps`` steps; call again to continue
FINISHED = 1
NONFINITE = 2  #: the state became NaN or infinite (left in ``z`` for the diagnosis)
STEP_TOO_SMALL = 3  #: the adaptive step fell below 10 ulps of t
OUTPUT_FULL = 4  #: no room for the next sample; grow the output and call again

# counters
STATUS = 0
N_OUT = 1
NEXT_SAMPLE = 2
N_STEPS = 3
N_FEV = 4
N_REJECTED = 5
COUNTERS_SIZE = 6
CLOCK_SIZE = 2
#: Fixed-step drivers check the state for non-finite values every this many steps (and before
#: saving a sample); a failure is then pinned to its exact step by replaying from the last
#: verified state.
CHECK_EVERY = 32


@kernel(inline=True)
def _finite(z, n):
    """True when every entry is finite (``x − x`` is 0 for finite x, NaN otherwise). The
    tests are independent and OR-ed, so the compiler vectorises them: a floating-point sum
    would be a serial chain, as it may not reorder additions."""
    bad = False
    for idx in range(n):
        bad |= z[idx] - z[idx] != 0.0
    return not bad


@kernel(inline=True)
def _save(method, system, t, z, out_t, out_y, n):
    out_t[n] = t
    solver_output_into(method, system, z, out_y[n])


@kernel(inline=True)
def _run_fixed(
    system,
    observer,
    method,
    A,
    B,
    C,
    clock,
    z,
    t_end,
    dt,
    t_eval,
    save_every,
    out_t,
    out_y,
    counters,
    max_steps,
):
    """Integrate with a fixed-step method from ``clock[0]`` to ``t_end``, resumably.

    ``method`` is :data:`~poinsot.kernels.steppers.RK4`, ``ERK`` or ``RKMK`` (with the tableau
    ``A, B, C``) or ``SPLITTING``; ``z`` (n,) is the solver's state (see
    :func:`~poinsot.kernels.steppers.solver_init_into`) and is advanced in place; samples go to
    ``out_t`` (m,) and ``out_y`` (m, n). Steps are ``dt``, shortened to land exactly on every
    sample time and on ``t_end``. Returns the status.

    """
    n = state_size(system, z)
    L = lanes(system) if method == RK4 else 1  # any other system holds one body
    s = 4 if method == RK4 else B.shape[0]
    K = np.empty((max(s, 1), n))
    ytmp = np.empty(n)
    cur = z  # the two state buffers swap roles every step; ``z`` gets the last one at the end
    nxt = np.empty(n)
    checkpoint = z.copy()  # the last state verified finite
    kth = np.empty((max(s, 1), 3))
    E = np.empty((3, 3))
    P = np.empty((3, 3))
    n_eval = t_eval.shape[0]
    use_eval = n_eval > 0
    t = clock[0]
    nout = counters[N_OUT]
    k = counters[NEXT_SAMPLE]
    nsteps = counters[N_STEPS]
    nfev = counters[N_FEV]
    if nsteps == 0 and nout == 0:  # the start
        if use_eval:
            while k < n_eval and t_eval[k] <= t:
                _save(method, system, t_eval[k], z, out_t, out_y, nout)
                nout += 1
                k += 1
        else:
            _save(method, system, t, z, out_t, out_y, nout)
            nout += 1
    status = RUNNING
    if t >= t_end or (use_eval and k >= n_eval):
        status = FINISHED
    taken = 0
    per_step = 4 if method == RK4 else (2 if method == SPLITTING else s)
    slack = dt * (1.0 + 1e-9)
    exact = False
    while status == RUNNING and taken < max_steps:
        if not use_eval and nout >= out_t.shape[0]:
            status = OUTPUT_FULL
            break
        # plan: ``run`` whole steps of dt, then (``lands``) one step onto the target; the run
        # ends early at a finiteness check, at ``max_steps`` or at a ``save_every`` sample
        target = t_end if not use_eval else t_eval[k]
        budget = min(1 if exact else CHECK_EVERY, max_steps - taken)
        if not use_eval:
            budget = min(budget, save_every - nsteps % save_every)
        run = 0
        tt = t
        while run < budget and target - tt > slack:
            tt += dt
            run += 1
        lands = run < budget
        t_checked = t
        for idx in range(n):
            checkpoint[idx] = cur[idx]
        # the hot loop: steps only (a single call site of the step)
        for i in range(run + 1 if lands else run):
            h = dt if i < run else target - t
            if method == RK4:  # in registers, member by member (the innermost loop)
                for lane in range(L):
                    y0 = load_state(cur, lane, L)
                    y1 = constrain(system, t + h, rk4_tuple_step(system, t, y0, h, lane), lane)
                    observe(observer, lane, t, y0, t + h, y1)
                    store_state(nxt, lane, L, y1)
            elif method == ERK:
                erk_step(system, A, B, C, t, cur, h, K, ytmp, nxt)
            elif method == RKMK:
                rkmk_step(system, A, B, C, t, cur, h, K, ytmp, kth, E, nxt)
            else:
                splitting_step(system, t, cur, h, ytmp, E, P, nxt)
            if method != SPLITTING and method != RK4:  # those project themselves
                project(system, t + h, nxt)
            if method != RK4:
                observe(observer, 0, t, cur, t + h, nxt)
            cur, nxt = nxt, cur
            t = t + h if i < run else target
        done = run + 1 if lands else run
        if not _finite(cur, n):
            if exact:  # a replayed single step: this is where it stopped being finite
                nsteps += done
                nfev += done * per_step
                status = NONFINITE
                break
            # replay from the last verified state one checked step at a time, to report the
            # exact step where the state stopped being finite
            for idx in range(n):
                cur[idx] = checkpoint[idx]
            t = t_checked
            exact = True
            continue
        nsteps += done
        taken += done
        nfev += done * per_step
        if use_eval:
            tol = 1e-12 * max(1.0, abs(t))
            while k < n_eval and t_eval[k] <= t + tol:
                _save(method, system, t_eval[k], cur, out_t, out_y, nout)
                nout += 1
                k += 1
            if k >= n_eval:
                status = FINISHED
        elif nsteps % save_every == 0 or t >= t_end:
            _save(method, system, t, cur, out_t, out_y, nout)
            nout += 1
        if t >= t_end:
            status = FINISHED
    if cur is not z:
        for idx in range(n):
            z[idx] = cur[idx]
    clock[0] = t
    counters[STATUS] = status
    counters[N_OUT] = nout
    counters[NEXT_SAMPLE] = k
    counters[N_STEPS] = nsteps
    counters[N_FEV] = nfev
    return status


_FIXED_DOC = """Integrate with {what} from ``clock[0]`` to ``t_end``, resumably.

    ``z`` (n,) is the solver's state (see :func:`~poinsot.kernels.steppers.solver_init_into`)
    and is advanced in place; samples go to ``out_t`` (m,) and ``out_y`` (m, n). Steps are
    ``dt``, shortened to land exactly on every sample time and on ``t_end``. ``A, B, C`` is the
    tableau ({tableau}). Returns the status (and fills ``clock`` and ``counters``).
    """


@kernel
def run_rk4(
    system,
    observer,
    A,
    B,
    C,
    clock,
    z,
    t_end,
    dt,
    t_eval,
    save_every,
    out_t,
    out_y,
    counters,
    max_steps,
):
    return _run_fixed(
        system,
        observer,
        RK4,
        A,
        B,
        C,
        clock,
        z,
        t_end,
        dt,
        t_eval,
        save_every,
        out_t,
        out_y,
        counters,
        max_steps,
    )


@kernel
def run_erk(
    system,
    observer,
    A,
    B,
    C,
    clock,
    z,
    t_end,
    dt,
    t_eval,
    save_every,
    out_t,
    out_y,
    counters,
    max_steps,
):
    return _run_fixed(
        system,
        observer,
        ERK,
        A,
        B,
        C,
        clock,
        z,
        t_end,
        dt,
        t_eval,
        save_every,
        out_t,
        out_y,
        counters,
        max_steps,
    )


@kernel
def run_rkmk(
    system,
    observer,
    A,
    B,
    C,
    clock,
    z,
    t_end,
    dt,
    t_eval,
    save_every,
    out_t,
    out_y,
    counters,
    max_steps,
):
    return _run_fixed(
        system,
        observer,
        RKMK,
        A,
        B,
        C,
        clock,
        z,
        t_end,
        dt,
        t_eval,
        save_every,
        out_t,
        out_y,
        counters,
        max_steps,
    )


@kernel
def run_splitting(
    system,
    observer,
    A,
    B,
    C,
    clock,
    z,
    t_end,
    dt,
    t_eval,
    save_every,
    out_t,
    out_y,
    counters,
    max_steps,
):
    return _run_fixed(
        system,
        observer,
        SPLITTING,
        A,
        B,
        C,
        clock,
        z,
        t_end,
        dt,
        t_eval,
        save_every,
        out_t,
        out_y,
        counters,
        max_steps,
    )


run_rk4.__doc__ = _FIXED_DOC.format(what="classical RK4", tableau="ignored: RK4's own")
run_erk.__doc__ = _FIXED_DOC.format(what="an explicit Runge–Kutta method", tableau="its own")
run_rkmk.__doc__ = _FIXED_DOC.format(what="Runge–Kutta–Munthe-Kaas", tableau="in the algebra")
run_splitting.__doc__ = _FIXED_DOC.format(what="the splitting method", tableau="ignored")


@kernel
def run_adaptive(
    system,
    observer,
    clock,
    z,
    f,
    t_end,
    control,
    t_eval,
    save_every,
    out_t,
    out_y,
    counters,
    max_steps,
):
    """Integrate with adaptive Dormand–Prince 8(5,3) from ``clock[0]`` to ``t_end``, resumably.

    ``z`` (n,) and its derivative ``f`` are advanced in place; ``clock[1]`` is the next step
    size (0 before the first step: chosen by
    :func:`~poinsot.kernels.steppers.initial_step_size`, or ``control[FIRST_STEP]``).
    ``control`` holds the tolerances and the controller's parameters
    (:mod:`poinsot.kernels.steppers`). Constrained systems are projected after every step and
    at every interpolated sample. Returns the status.
    """
    n = state_size(system, z)
    K = np.empty((DOP853_STAGES_EXTENDED, n))
    Fd = np.empty((DOP853_INTERPOLATOR_POWER, n))
    ytmp = np.empty(n)
    znew = np.empty(n)
    fnew = np.empty(n)
    sample = np.empty(n)
    rtol = control[RTOL]
    atol = control[ATOL]
    max_step = control[MAX_STEP]
    n_eval = t_eval.shape[0]
    use_eval = n_eval > 0
    t = clock[0]
    h_abs = clock[1]
    nout = counters[N_OUT]
    k = counters[NEXT_SAMPLE]
    nsteps = counters[N_STEPS]
    nfev = counters[N_FEV]
    nrej = counters[N_REJECTED]
    if nfev == 0:  # the start
        evaluate(system, t, z, f)
        nfev += 1
        if use_eval:
            while k < n_eval and t_eval[k] <= t:
                _save(DOP853, system, t_eval[k], z, out_t, out_y, nout)
                nout += 1
                k += 1
        else:
            _save(DOP853, system, t, z, out_t, out_y, nout)
            nout += 1
        if h_abs == 0.0:
            if control[FIRST_STEP] > 0.0:
                h_abs = control[FIRST_STEP]
            else:
                h_abs = initial_step_size(system, t, z, f, t_end, 7, control, ytmp, fnew)
                nfev += 1
    status = RUNNING
    if t >= t_end or (use_eval and k >= n_eval):
        status = FINISHED
    taken = 0
    while status == RUNNING and taken < max_steps:
        if not use_eval and nout >= out_t.shape[0]:
            status = OUTPUT_FULL
            break
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        rejected = False
        t_new = t
        h = 0.0
        while True:
            if h_abs < min_step:
                status = STEP_TOO_SMALL
                break
            t_new = t + h_abs
            if t_new > t_end:
                t_new = t_end
            h = t_new - t
            h_abs = abs(h)
            dop853_step(system, t, z, f, h, K, ytmp, znew, fnew)
            nfev += DOP853_STAGES
            err = dop853_error_norm(K, h, z, znew, rtol, atol)
            h_abs *= step_size_factor(err, 7, rejected, control)
            if err < 1.0:
                break
            rejected = True
            nrej += 1
        if status != RUNNING:
            break
        if project(system, t_new, znew):
            evaluate(system, t_new, znew, fnew)
            nfev += 1
        nsteps += 1
        taken += 1
        observe(observer, 0, t, z, t_new, znew)
        if not _finite(znew, n):
            for idx in range(n):
                z[idx] = znew[idx]
            t = t_new
            status = NONFINITE
            break
        if use_eval:
            dense = False
            while k < n_eval and t_eval[k] <= t_new:
                if t_eval[k] == t_new:
                    _save(DOP853, system, t_new, znew, out_t, out_y, nout)
                else:
                    if not dense:
                        dop853_dense_into(system, t, h, z, znew, fnew, K, ytmp, Fd)
                        nfev += DOP853_STAGES_EXTENDED - DOP853_STAGES - 1
                        dense = True
                    dop853_interpolate_into(Fd, z, (t_eval[k] - t) / h, sample)
                    project(system, t_eval[k], sample)
                    _save(DOP853, system, t_eval[k], sample, out_t, out_y, nout)
                nout += 1
                k += 1
            if k >= n_eval:
                status = FINISHED
        elif nsteps % save_every == 0 or t_new >= t_end:
            _save(DOP853, system, t_new, znew, out_t, out_y, nout)
            nout += 1
        for idx in range(n):
            z[idx] = znew[idx]
            f[idx] = fnew[idx]
        t = t_new
        if t >= t_end:
            status = FINISHED
    clock[0] = t
    clock[1] = h_abs
    counters[STATUS] = status
    counters[N_OUT] = nout
    counters[NEXT_SAMPLE] = k
    counters[N_STEPS] = nsteps
    counters[N_FEV] = nfev
    counters[N_REJECTED] = nrej
    return status
