"""Ensembles: many bodies integrated in one compiled call per chunk (``docs/ensembles.md``).

An ensemble *chunk* is a set of members (initial states, and bodies and lowered forces where
they differ) held in one named tuple of :mod:`poinsot.kernels.systems` (the *template*):

* :data:`~poinsot.kernels.systems.TorqueFreeLanes`: free bodies sharing one inertia;
* :data:`~poinsot.kernels.systems.TorqueFreeLanesVaried`: free bodies, each with its own;
* :data:`~poinsot.kernels.systems.RigidLanes`: bodies under built-in forces, free or about a
  pivot, each with its own parameter vector (the pivot's place in space differs by member).

Nothing here is a formula of its own. A chunk runs the single-body drivers of
:mod:`poinsot.kernels.drivers` on systems cut from the template:

* classical RK4 steps a *block* of up to :data:`BLOCK` members together, their states stored
  component-major, the member loop innermost so that the compiler vectorises the step
  (:func:`block_system`); a block that fails (a non-finite state) is run again member by
  member, so every member gets its own status, and its neighbours their exact results;
* every other method steps one member at a time (:func:`member_system`), each with its own
  step-size control for the adaptive method.

Samples are written in the body frame into the chunk's output (m, n, 18), and reductions over
the samples are computed per member by :func:`chunk_statistics`, so that a caller that keeps
only statistics never stores a trajectory.
"""

from __future__ import annotations

import numpy as np

from .drivers import (
    CLOCK_SIZE,
    COUNTERS_SIZE,
    FINISHED,
    N_FEV,
    N_STEPS,
    run_adaptive,
    run_erk,
    run_rk4,
    run_rkmk,
    run_splitting,
)
from .inertia import parallel_axis, principal_decomposition
from .jit import generic, kernel
from .layout import BODY_SIZE, PIVOT, STATE_SIZE, load_state, store_state
from .observers import FlipObserver, NoObserver
from .rigid import (
    angular_momentum_com_of,
    kinetic_energy_of,
    orthogonality_error_of,
    pivot_point_of,
    rigid_body_parameters,
    state_from_principal_into,
    state_to_principal_into,
)
from .steppers import DOP853, ERK, RKMK, SPLITTING, solver_init_into
from .systems import (
    NativeLanes,
    NativeSystem,
    RigidLanes,
    RigidSystem,
    TorqueFreeLanes,
    TorqueFreeLanesVaried,
    TorqueFreeSystem,
    potential,
)

__all__ = [
    "BLOCK",
    "block_observer",
    "block_system",
    "chunk_dop853",
    "chunk_erk",
    "chunk_rk4",
    "chunk_rkmk",
    "chunk_splitting",
    "chunk_states_dop853",
    "chunk_states_erk",
    "chunk_statistics",
    "member_bodies",
    "member_observer",
    "member_system",
    "principal_members",
]

#: Members stepped together by the RK4 chunk (the width of the vectorised member loop).
BLOCK = 64


@kernel(inline=True)
def _axes_of(axes, i):
    return axes[i if axes.shape[0] > 1 else 0]


# --------------------------------------------------------------------------- members
@kernel
def member_bodies(mass, inertia_com, c, has_pivot):
    """Parameter vectors of bodies that share their mass and centre of mass but each have
    their own inertia: ``(bodies (m, BODY_SIZE), axes (m, 3, 3), degenerate (m,))``.

    ``inertia_com`` (m, 3, 3) about the centre of mass, body frame; ``c`` (3,) the centre of
    mass seen from the reference point (zero for free bodies; about a pivot the inertia is
    moved there by Huygens–Steiner). The pivot's place in space is filled in by
    :func:`principal_members`.
    """
    m = inertia_com.shape[0]
    bodies = np.empty((m, BODY_SIZE))
    axes = np.empty((m, 3, 3))
    degenerate = np.zeros(m, dtype=np.bool_)
    for i in range(m):
        A = np.ascontiguousarray(inertia_com[i])
        about = parallel_axis(A, mass, c) if has_pivot else A
        moments, E = principal_decomposition(about)
        params, deg = rigid_body_parameters(mass, moments, E, c, A, has_pivot)
        bodies[i] = params
        axes[i] = E
        degenerate[i] = deg
    return bodies, axes, degenerate


@kernel
def principal_members(bodies, axes, Y0, has_pivot):
    """The members' initial states in their principal frames, and their bodies:
    ``(Z0 (m, 18), bodies (m, BODY_SIZE))``. ``bodies`` (1 or m, BODY_SIZE), ``axes`` (1 or m,
    3, 3), ``Y0`` (m, 18) body frame. About a pivot, each member's pivot is held where its
    initial state puts it, ``P = R − Q c``."""
    m = Y0.shape[0]
    Z0 = np.empty((m, STATE_SIZE))
    out = np.empty((m, BODY_SIZE))
    for i in range(m):
        state_to_principal_into(_axes_of(axes, i), Y0[i], Z0[i])
        out[i] = bodies[i if bodies.shape[0] > 1 else 0]
        if has_pivot:
            p0, p1, p2 = pivot_point_of(out[i], Z0[i])
            out[i, PIVOT] = p0
            out[i, PIVOT + 1] = p1
            out[i, PIVOT + 2] = p2
    return Z0, out


# --------------------------------------------------------------------------- cutting templates
@generic
def member_system(template, i):
    """The one-body system of member ``i`` of a chunk template."""


@generic
def block_system(template, i0, width):
    """The lane system of members ``i0 … i0 + width − 1`` of a chunk template."""


@member_system.register(TorqueFreeLanes)
@kernel(inline=True)
def _free_member(template, i):
    return TorqueFreeSystem(template.body)


@member_system.register(TorqueFreeLanesVaried)
@kernel(inline=True)
def _varied_member(template, i):
    return TorqueFreeSystem(template.bodies[i])


@member_system.register(RigidLanes)
@kernel(inline=True)
def _rigid_member(template, i):
    return RigidSystem(template.bodies[i], template.force_kind, template.force_params[i])


@member_system.register(NativeLanes)
@kernel(inline=True)
def _native_member(template, i):
    return NativeSystem(template.rhs, template.project, template.P[i], template.U[i],
                        template.gains)  # fmt: skip


@block_system.register(TorqueFreeLanes)
@kernel(inline=True)
def _free_block(template, i0, width):
    return TorqueFreeLanes(template.body, width)


@block_system.register(TorqueFreeLanesVaried)
@kernel(inline=True)
def _varied_block(template, i0, width):
    return TorqueFreeLanesVaried(template.bodies[i0 : i0 + width], width)


@block_system.register(RigidLanes)
@kernel(inline=True)
def _rigid_block(template, i0, width):
    return RigidLanes(
        template.bodies[i0 : i0 + width],
        template.force_kind,
        template.force_params[i0 : i0 + width],
        width,
    )


@generic
def block_observer(observer, i0, width):
    """The observer of members ``i0 … i0 + width − 1`` (lanes 0 … width − 1)."""


@generic
def member_observer(observer, i):
    """The observer of member ``i`` alone (lane 0)."""


@block_observer.register(NoObserver)
@kernel(inline=True)
def _no_block_observer(observer, i0, width):
    return observer


@member_observer.register(NoObserver)
@kernel(inline=True)
def _no_member_observer(observer, i):
    return observer


@block_observer.register(FlipObserver)
@kernel(inline=True)
def _flip_block_observer(observer, i0, width):
    return FlipObserver(observer.first, observer.last, observer.count, i0)


@member_observer.register(FlipObserver)
@kernel(inline=True)
def _flip_member_observer(observer, i):
    return FlipObserver(observer.first, observer.last, observer.count, i)


# --------------------------------------------------------------------------- samples
@kernel(inline=True)
def _store_sample(axes, i, z, out):
    """Member ``i``'s principal-frame sample ``z`` (array) into ``out`` in the body frame."""
    state_from_principal_into(_axes_of(axes, i), z, out)


# --------------------------------------------------------------------------- the RK4 chunk
@kernel(inline=True)
def _rk4_block(template, observer, A, B, C, Z0, i0, width, t0, t1, dt, t_eval, save_every):
    """Run members ``i0 … i0 + width − 1`` as one lane system; ``(status, nsteps, samples,
    out_y)`` with the samples component-major."""
    system = block_system(template, i0, width)
    obs = block_observer(observer, i0, width)
    z = np.empty(STATE_SIZE * width)
    for lane in range(width):
        store_state(z, lane, width, load_state(Z0[i0 + lane], 0, 1))
    n = t_eval.shape[0]
    out_t = np.empty(n)
    out_y = np.empty((n, STATE_SIZE * width))
    clock = np.zeros(CLOCK_SIZE)
    clock[0] = t0
    counters = np.zeros(COUNTERS_SIZE, dtype=np.int64)
    status = run_rk4(
        system, obs, A, B, C, clock, z, t1, dt, t_eval, save_every, out_t, out_y, counters, 2**62
    )
    return status, counters[N_STEPS], counters[N_FEV], out_y


@kernel
def chunk_rk4(template, observer, A, B, C, axes, Z0, t0, t1, dt, t_eval, Y, status, nsteps, nfev):
    """Integrate the chunk's members with classical RK4, :data:`BLOCK` members at a time.

    ``Z0`` (m, 18) the initial states in each member's principal frame, ``axes`` (1 or m,
    3, 3) the principal axes (columns, body coordinates), ``t_eval`` (n,) the sample times (the
    last one ``t1``). Writes the body-frame samples ``Y`` (m, n, 18) and, per member,
    ``status`` (a driver status code), ``nsteps`` and ``nfev``. A block whose state stops
    being finite is run again one member at a time.
    """
    m = Z0.shape[0]
    n = t_eval.shape[0]
    tmp = np.empty(STATE_SIZE)
    for i0 in range(0, m, BLOCK):
        width = min(BLOCK, m - i0)
        st, ns, nf, out_y = _rk4_block(
            template, observer, A, B, C, Z0, i0, width, t0, t1, dt, t_eval, 2**62
        )
        if st == FINISHED:
            for lane in range(width):
                i = i0 + lane
                status[i] = st
                nsteps[i] = ns
                nfev[i] = nf
                for k in range(n):
                    store_state(tmp, 0, 1, load_state(out_y[k], lane, width))
                    _store_sample(axes, i, tmp, Y[i, k])
            continue
        for lane in range(width):  # one member at a time: each its own status
            i = i0 + lane
            st, ns, nf, out_y = _rk4_block(
                template, observer, A, B, C, Z0, i, 1, t0, t1, dt, t_eval, 2**62
            )
            status[i] = st
            nsteps[i] = ns
            nfev[i] = nf
            for k in range(n):
                if st == FINISHED:
                    _store_sample(axes, i, out_y[k], Y[i, k])
                else:
                    for c in range(STATE_SIZE):
                        Y[i, k, c] = np.nan


# --------------------------------------------------------------------------- any other method
# One kernel per method, so that a run compiles only the driver it uses. Each steps the chunk's
# members one at a time; arguments and outputs as in :func:`chunk_rk4`, and a member that fails
# gets NaN samples and its status.
@kernel(inline=True)
def _member_start(template, observer, method, Z0, i, t0, z, clock, counters):
    system = member_system(template, i)
    solver_init_into(method, system, Z0[i], z)
    clock[0] = t0
    clock[1] = 0.0
    counters[:] = 0
    return system, member_observer(observer, i)


@kernel(inline=True)
def _member_finish(axes, i, st, counters, out_y, Y, status, nsteps, nfev):
    status[i] = st
    nsteps[i] = counters[N_STEPS]
    nfev[i] = counters[N_FEV]
    for k in range(Y.shape[1]):
        if st == FINISHED:
            _store_sample(axes, i, out_y[k], Y[i, k])
        else:
            for c in range(STATE_SIZE):
                Y[i, k, c] = np.nan


@kernel(inline=True)
def _workspace(n):
    return (
        np.empty(STATE_SIZE),
        np.empty(n),
        np.empty((n, STATE_SIZE)),
        np.zeros(CLOCK_SIZE),
        np.zeros(COUNTERS_SIZE, dtype=np.int64),
    )


@kernel
def chunk_erk(template, observer, A, B, C, axes, Z0, t0, t1, dt, t_eval, Y, status, nsteps, nfev):
    """The chunk's members one at a time with the explicit Runge–Kutta tableau ``A, B, C``."""
    z, out_t, out_y, clock, counters = _workspace(t_eval.shape[0])
    for i in range(Z0.shape[0]):
        system, obs = _member_start(template, observer, ERK, Z0, i, t0, z, clock, counters)
        st = run_erk(system, obs, A, B, C, clock, z, t1, dt, t_eval, 2**62, out_t, out_y,
                     counters, 2**62)  # fmt: skip
        _member_finish(axes, i, st, counters, out_y, Y, status, nsteps, nfev)


@kernel
def chunk_rkmk(template, observer, A, B, C, axes, Z0, t0, t1, dt, t_eval, Y, status, nsteps, nfev):
    """The chunk's members one at a time with Runge–Kutta–Munthe-Kaas (tableau ``A, B, C``)."""
    z, out_t, out_y, clock, counters = _workspace(t_eval.shape[0])
    for i in range(Z0.shape[0]):
        system, obs = _member_start(template, observer, RKMK, Z0, i, t0, z, clock, counters)
        st = run_rkmk(system, obs, A, B, C, clock, z, t1, dt, t_eval, 2**62, out_t, out_y,
                      counters, 2**62)  # fmt: skip
        _member_finish(axes, i, st, counters, out_y, Y, status, nsteps, nfev)


@kernel
def chunk_splitting(
    template, observer, A, B, C, axes, Z0, t0, t1, dt, t_eval, Y, status, nsteps, nfev
):
    """The chunk's members one at a time with the splitting method (free-rotor flows and
    kicks)."""
    z, out_t, out_y, clock, counters = _workspace(t_eval.shape[0])
    for i in range(Z0.shape[0]):
        system, obs = _member_start(template, observer, SPLITTING, Z0, i, t0, z, clock, counters)
        st = run_splitting(system, obs, A, B, C, clock, z, t1, dt, t_eval, 2**62, out_t, out_y,
                           counters, 2**62)  # fmt: skip
        _member_finish(axes, i, st, counters, out_y, Y, status, nsteps, nfev)


@kernel
def chunk_dop853(template, observer, control, axes, Z0, t0, t1, t_eval, Y, status, nsteps, nfev):
    """The chunk's members one at a time with adaptive DOP853, each with its own step sizes
    (``control``: the controller's parameters)."""
    z, out_t, out_y, clock, counters = _workspace(t_eval.shape[0])
    f = np.empty(STATE_SIZE)
    for i in range(Z0.shape[0]):
        system, obs = _member_start(template, observer, DOP853, Z0, i, t0, z, clock, counters)
        st = run_adaptive(system, obs, clock, z, f, t1, control, t_eval, 2**62, out_t, out_y,
                          counters, 2**62)  # fmt: skip
        _member_finish(axes, i, st, counters, out_y, Y, status, nsteps, nfev)


# --------------------------------------------------------------------------- any state
# Chunks of systems whose state is a plain vector of any length (the generated models of
# :mod:`poinsot.kernels.native`): ``Z0`` (m, d) the initial states, ``Y`` (m, n, d) the samples
# at ``t_eval`` as they are; a member that fails gets NaN samples and its status.
@kernel(inline=True)
def _states_member_finish(i, st, counters, out_y, Y, status, nsteps, nfev):
    status[i] = st
    nsteps[i] = counters[N_STEPS]
    nfev[i] = counters[N_FEV]
    for k in range(Y.shape[1]):
        for c in range(Y.shape[2]):
            Y[i, k, c] = out_y[k, c] if st == FINISHED else np.nan


@kernel(inline=True)
def _states_workspace(d, n):
    """The state ``z`` (d,), its derivative, the samples ``out_t`` (n,), ``out_y`` (n, d), the
    clock and the counters of one member's run."""
    return (np.empty(d), np.empty(d), np.empty(n), np.empty((n, d)), np.zeros(CLOCK_SIZE),
            np.zeros(COUNTERS_SIZE, dtype=np.int64))  # fmt: skip


@kernel(inline=True)
def _states_member_start(template, Z0, i, t0, z, clock, counters):
    for c in range(z.shape[0]):
        z[c] = Z0[i, c]
    clock[0] = t0
    clock[1] = 0.0
    counters[:] = 0
    return member_system(template, i)


@kernel
def chunk_states_erk(template, observer, A, B, C, Z0, t0, t1, dt, t_eval, Y, status, nsteps,
                     nfev):  # fmt: skip
    """The chunk's members one at a time with the explicit Runge–Kutta tableau ``A, B, C``."""
    z, _, out_t, out_y, clock, counters = _states_workspace(Z0.shape[1], t_eval.shape[0])
    for i in range(Z0.shape[0]):
        system = _states_member_start(template, Z0, i, t0, z, clock, counters)
        st = run_erk(system, observer, A, B, C, clock, z, t1, dt, t_eval, 2**62, out_t, out_y,
                     counters, 2**62)  # fmt: skip
        _states_member_finish(i, st, counters, out_y, Y, status, nsteps, nfev)


@kernel
def chunk_states_dop853(template, observer, control, Z0, t0, t1, t_eval, Y, status, nsteps,
                        nfev):  # fmt: skip
    """The chunk's members one at a time with adaptive DOP853, each with its own step sizes."""
    z, f, out_t, out_y, clock, counters = _states_workspace(Z0.shape[1], t_eval.shape[0])
    for i in range(Z0.shape[0]):
        system = _states_member_start(template, Z0, i, t0, z, clock, counters)
        st = run_adaptive(system, observer, clock, z, f, t1, control, t_eval, 2**62, out_t,
                          out_y, counters, 2**62)  # fmt: skip
        _states_member_finish(i, st, counters, out_y, Y, status, nsteps, nfev)


# --------------------------------------------------------------------------- reductions
@kernel
def chunk_statistics(template, axes, inertia, mass, t0, Y0, t, Y, energy, momentum, orthogonality):
    """Per member, the largest errors over its samples ``Y`` (m, n, 18, body frame) at times
    ``t`` (n,) relative to its initial state ``Y0`` (m, 18) at ``t0``:

    * ``energy``: ``max |E(t_k) − E(t0)| / |E(t0)|`` (absolute where ``E(t0) = 0``), with
      ``E = K + U``, K the kinetic energy (12) and U the potential of the built-in forces;
    * ``momentum``: ``max |L(t_k) − L(t0)| / |L(t0)|``, L about the centre of mass in space
      (``Q A ω``), zero drift for a torque-free body;
    * ``orthogonality``: ``max |QᵀQ − I|``.

    ``inertia`` (1 or m, 3, 3) about the centre of mass, body frame. Members with NaN samples
    (failed runs) get NaN.
    """
    m = Y.shape[0]
    z = np.empty(STATE_SIZE)
    for i in range(m):
        system = member_system(template, i)
        A = inertia[i if inertia.shape[0] > 1 else 0]
        E_axes = _axes_of(axes, i)
        state_to_principal_into(E_axes, Y0[i], z)
        e0 = kinetic_energy_of(A, mass, Y0[i]) + potential(system, t0, z)
        L0x, L0y, L0z = angular_momentum_com_of(A, Y0[i])
        scale_e = abs(e0) if e0 != 0.0 else 1.0
        l0 = np.sqrt(L0x * L0x + L0y * L0y + L0z * L0z)
        scale_l = l0 if l0 != 0.0 else 1.0
        de = 0.0
        dl = 0.0
        do = 0.0
        for k in range(Y.shape[1]):
            y = Y[i, k]
            state_to_principal_into(E_axes, y, z)
            e = kinetic_energy_of(A, mass, y) + potential(system, t[k], z)
            Lx, Ly, Lz = angular_momentum_com_of(A, y)
            dx = Lx - L0x
            dy = Ly - L0y
            dz = Lz - L0z
            de = max(de, abs(e - e0) / scale_e)
            dl = max(dl, np.sqrt(dx * dx + dy * dy + dz * dz) / scale_l)
            do = max(do, orthogonality_error_of(y))
            if e != e:  # NaN: a failed member
                de = np.nan
                dl = np.nan
                do = np.nan
                break
        energy[i] = de
        momentum[i] = dl
        orthogonality[i] = do
