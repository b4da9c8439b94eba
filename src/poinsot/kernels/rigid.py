"""Rigid-body equations, energies, momenta and free-rotor flows (``docs/theory.md`` §1).

* Euler's equation ``A ω̇ + ω × Aω = τ`` (08), in principal components (27)–(29):
  :func:`omega_dot_principal`.
* The motion under a wrench, eqs (07)–(09), free or about a fixed point:
  :func:`free_rigid_derivative`, :func:`rigid_derivative`, with :func:`shift_torque_to_pivot`
  and :func:`project_onto_pivot`.
* Energies and momenta, eqs (03), (12), (30)–(31): :func:`kinetic_energy`,
  :func:`rotational_energy`, :func:`angular_momentum_body`, :func:`angular_momentum_com`,
  :func:`angular_momentum`.
* The exact flows of the free rotor that the splitting integrator composes:
  :func:`free_rotor_step_into`.
* Conversions of states between the body frame and the principal frame in which the compiled
  engine integrates: :func:`states_to_principal`, :func:`states_from_principal`.

The engine's functions read the body from its parameter vector (see
:mod:`poinsot.kernels.layout`) and write into preallocated arrays: no allocation per step.
"""

from __future__ import annotations

import math

import numpy as np

from .inertia import DEGENERATE_RTOL, SYMMETRY_RTOL, is_degenerate, symmetry_code
from .jit import kernel
from .layout import (
    BODY_SIZE,
    COM_OFFSET,
    HAS_PIVOT,
    INV_MASS,
    INV_MOMENTS,
    MOMENTS,
    OMEGA_AT,
    PIVOT,
    Q_AT,
    R_AT,
    ROTOR,
    STATE_SIZE,
    V_AT,
    body_vector,
    store_state,
)
from .so3 import exp_so3_into

__all__ = [
    "angular_momentum",
    "angular_momentum_body",
    "angular_momentum_com",
    "angular_momentum_com_of",
    "attitude_rate",
    "euler_omega_dot",
    "free_rigid_derivative",
    "free_rigid_rates",
    "free_rotor_step",
    "free_rotor_step_into",
    "initial_states",
    "kinetic_energy",
    "kinetic_energy_of",
    "omega_dot_principal",
    "omega_space",
    "orthogonality_error",
    "orthogonality_error_of",
    "particle_positions",
    "particle_trajectories",
    "particle_velocities",
    "pivot_constrained",
    "pivot_point_of",
    "project_onto_pivot",
    "rigid_body_parameters",
    "rigid_derivative",
    "rigid_motion_from_particles",
    "rigid_rates",
    "rotate_pair_into",
    "rotational_energy",
    "rotational_energy_of",
    "rotor_code",
    "shift_torque_to_pivot",
    "state_from_principal_into",
    "state_to_principal_into",
    "states_from_principal",
    "states_to_principal",
]


# --------------------------------------------------------------------------- Euler's equation
@kernel(inline=True)
def omega_dot_principal(I1, I2, I3, J1, J2, J3, w1, w2, w3, t1, t2, t3):
    """``ω̇`` from Euler's equation (08) in principal components, eqs (27)–(29) with a torque::

        I1 ω̇1 = τ1 + (I2 − I3) ω2 ω3,  I2 ω̇2 = τ2 + (I3 − I1) ω3 ω1,  I3 ω̇3 = τ3 + (I1 − I2) ω1 ω2

    ``J_i = 1/I_i``, or 0 where ``I_i = 0`` (a degenerate body: no angular acceleration about
    its line, the minimum-norm solution). Returns a 3-tuple.
    """
    return (
        J1 * (t1 + (I2 - I3) * w2 * w3),
        J2 * (t2 + (I3 - I1) * w3 * w1),
        J3 * (t3 + (I1 - I2) * w1 * w2),
    )


@kernel
def euler_omega_dot(moments, omega, torque):
    """``ω̇`` of Euler's equation (08) for principal ``moments`` (3,) and ``omega``, ``torque``
    in principal components (..., 3) → (..., 3); eqs (27)–(29) when the torque is zero.

    Examples
    --------
    >>> import numpy as np
    >>> w_dot = euler_omega_dot(np.array([1.0, 2.0, 3.0]), np.ones(3), np.zeros(3))
    >>> w_dot.round(6).tolist()   # ((I2 − I3)/I1, (I3 − I1)/I2, (I1 − I2)/I3)
    [-1.0, 1.0, -0.333333]
    """
    omega = np.asarray(omega)
    torque = np.asarray(torque)
    w = np.ascontiguousarray(omega).reshape((-1, 3)).astype(np.float64)
    tau = np.ascontiguousarray(torque).reshape((-1, 3)).astype(np.float64)
    if tau.shape[0] != w.shape[0]:
        raise ValueError("`omega` and `torque` must have the same shape")
    inv = np.zeros(3)
    for k in range(3):
        if moments[k] != 0.0:
            inv[k] = 1.0 / moments[k]
    out = np.empty_like(w)
    for i in range(w.shape[0]):
        a = omega_dot_principal(
            moments[0], moments[1], moments[2], inv[0], inv[1], inv[2],
            w[i, 0], w[i, 1], w[i, 2], tau[i, 0], tau[i, 1], tau[i, 2],
        )  # fmt: skip
        out[i, 0] = a[0]
        out[i, 1] = a[1]
        out[i, 2] = a[2]
    return out.reshape(omega.shape)


# --------------------------------------------------------------------------- eqs (07)–(09)
@kernel(inline=True)
def shift_torque_to_pivot(body, y, Fx, Fy, Fz, tx, ty, tz):
    """The torque about the reference point, ``τ_P = τ_G + c × Qᵀ F`` (``c`` the centre of mass
    seen from the reference point, body frame). A free body has ``c = 0``: no branch is needed.
    Returns a 3-tuple."""
    c0 = body[COM_OFFSET]
    c1 = body[COM_OFFSET + 1]
    c2 = body[COM_OFFSET + 2]
    b0 = y[Q_AT] * Fx + y[Q_AT + 3] * Fy + y[Q_AT + 6] * Fz  # Qᵀ F
    b1 = y[Q_AT + 1] * Fx + y[Q_AT + 4] * Fy + y[Q_AT + 7] * Fz
    b2 = y[Q_AT + 2] * Fx + y[Q_AT + 5] * Fy + y[Q_AT + 8] * Fz
    return tx + c1 * b2 - c2 * b1, ty + c2 * b0 - c0 * b2, tz + c0 * b1 - c1 * b0


@kernel(inline=True)
def attitude_rate(q0, q1, q2, q3, q4, q5, q6, q7, q8, w0, w1, w2):
    """``Q̇ = QΩ`` (09) for ``Q`` given row-major and ω in body (or principal) components:
    row i of ``Q̇`` is ``q_i × ω``. Returns the 9-tuple of ``Q̇`` row-major."""
    return (
        q1 * w2 - q2 * w1,
        q2 * w0 - q0 * w2,
        q0 * w1 - q1 * w0,
        q4 * w2 - q5 * w1,
        q5 * w0 - q3 * w2,
        q3 * w1 - q4 * w0,
        q7 * w2 - q8 * w1,
        q8 * w0 - q6 * w2,
        q6 * w1 - q7 * w0,
    )


@kernel(inline=True)
def free_rigid_rates(body, y, Fx, Fy, Fz, tx, ty, tz):
    """``ẏ`` of a free body under the force ``F`` (space frame) and the torque ``τ`` about its
    centre of mass (principal frame), eqs (07)–(09), as an 18-tuple; ``y`` is the state, an
    array or a tuple.

    * (07) ``M R̈ = F``;
    * (08) ``ω̇`` from Euler's equation in principal components (27)–(29);
    * (09) ``Q̇ = QΩ``.
    """
    w0 = y[OMEGA_AT]
    w1 = y[OMEGA_AT + 1]
    w2 = y[OMEGA_AT + 2]
    a = attitude_rate(
        y[Q_AT], y[Q_AT + 1], y[Q_AT + 2], y[Q_AT + 3], y[Q_AT + 4], y[Q_AT + 5],
        y[Q_AT + 6], y[Q_AT + 7], y[Q_AT + 8], w0, w1, w2,
    )  # fmt: skip
    d0, d1, d2 = omega_dot_principal(
        body[MOMENTS], body[MOMENTS + 1], body[MOMENTS + 2],
        body[INV_MOMENTS], body[INV_MOMENTS + 1], body[INV_MOMENTS + 2],
        w0, w1, w2, tx, ty, tz,
    )  # fmt: skip
    m = body[INV_MASS]
    return (
        y[V_AT], y[V_AT + 1], y[V_AT + 2], Fx * m, Fy * m, Fz * m,
        a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7], a[8], d0, d1, d2,
    )  # fmt: skip


@kernel(inline=True)
def rigid_rates(body, y, Fx, Fy, Fz, tx, ty, tz):
    """``ẏ`` (18-tuple) under the force ``F`` (space frame) and the torque ``τ`` about the
    reference point (principal frame): :func:`free_rigid_rates` for a free body; about a pivot
    ``R = P + Q c`` is slaved to the attitude and ``R̈ = Q (ω̇ × c + ω × (ω × c))`` (the
    pivot's reaction does the rest)."""
    r = free_rigid_rates(body, y, Fx, Fy, Fz, tx, ty, tz)
    v0 = r[3]
    v1 = r[4]
    v2 = r[5]
    if body[HAS_PIVOT] != 0.0:
        w0 = y[OMEGA_AT]
        w1 = y[OMEGA_AT + 1]
        w2 = y[OMEGA_AT + 2]
        d0 = r[OMEGA_AT]
        d1 = r[OMEGA_AT + 1]
        d2 = r[OMEGA_AT + 2]
        c0 = body[COM_OFFSET]
        c1 = body[COM_OFFSET + 1]
        c2 = body[COM_OFFSET + 2]
        u0 = w1 * c2 - w2 * c1  # ω × c
        u1 = w2 * c0 - w0 * c2
        u2 = w0 * c1 - w1 * c0
        a0 = d1 * c2 - d2 * c1 + w1 * u2 - w2 * u1  # ω̇ × c + ω × (ω × c)
        a1 = d2 * c0 - d0 * c2 + w2 * u0 - w0 * u2
        a2 = d0 * c1 - d1 * c0 + w0 * u1 - w1 * u0
        q = Q_AT
        v0 = y[q] * a0 + y[q + 1] * a1 + y[q + 2] * a2
        v1 = y[q + 3] * a0 + y[q + 4] * a1 + y[q + 5] * a2
        v2 = y[q + 6] * a0 + y[q + 7] * a1 + y[q + 8] * a2
    return (
        r[0], r[1], r[2], v0, v1, v2,
        r[6], r[7], r[8], r[9], r[10], r[11], r[12], r[13], r[14], r[15], r[16], r[17],
    )  # fmt: skip


@kernel(inline=True)
def free_rigid_derivative(body, y, Fx, Fy, Fz, tx, ty, tz, out):
    """``out = ẏ`` (18,) of a free body: :func:`free_rigid_rates` stored in an array."""
    store_state(out, 0, 1, free_rigid_rates(body, y, Fx, Fy, Fz, tx, ty, tz))


@kernel(inline=True)
def rigid_derivative(body, y, Fx, Fy, Fz, tx, ty, tz, out):
    """``out = ẏ`` (18,), free or about a pivot: :func:`rigid_rates` stored in an array."""
    store_state(out, 0, 1, rigid_rates(body, y, Fx, Fy, Fz, tx, ty, tz))


@kernel(inline=True)
def pivot_constrained(body, y):
    """The state (18-tuple) with ``R = P + Q c`` and ``V = Q (ω × c)`` reset from the attitude,
    so that the pivot stays exactly fixed; ``y`` unchanged for a free body. ``y`` is an array
    or a tuple."""
    if body[HAS_PIVOT] != 0.0:
        c0 = body[COM_OFFSET]
        c1 = body[COM_OFFSET + 1]
        c2 = body[COM_OFFSET + 2]
        w0 = y[OMEGA_AT]
        w1 = y[OMEGA_AT + 1]
        w2 = y[OMEGA_AT + 2]
        u0 = w1 * c2 - w2 * c1
        u1 = w2 * c0 - w0 * c2
        u2 = w0 * c1 - w1 * c0
        q = Q_AT
        R0 = body[PIVOT] + y[q] * c0 + y[q + 1] * c1 + y[q + 2] * c2
        R1 = body[PIVOT + 1] + y[q + 3] * c0 + y[q + 4] * c1 + y[q + 5] * c2
        R2 = body[PIVOT + 2] + y[q + 6] * c0 + y[q + 7] * c1 + y[q + 8] * c2
        V0 = y[q] * u0 + y[q + 1] * u1 + y[q + 2] * u2
        V1 = y[q + 3] * u0 + y[q + 4] * u1 + y[q + 5] * u2
        V2 = y[q + 6] * u0 + y[q + 7] * u1 + y[q + 8] * u2
    else:
        # Both arms assign every name: numba's inliner keeps them in scope (no IR warnings).
        R0 = y[R_AT]
        R1 = y[R_AT + 1]
        R2 = y[R_AT + 2]
        V0 = y[V_AT]
        V1 = y[V_AT + 1]
        V2 = y[V_AT + 2]
    return (
        R0, R1, R2, V0, V1, V2,
        y[6], y[7], y[8], y[9], y[10], y[11], y[12], y[13], y[14], y[15], y[16], y[17],
    )  # fmt: skip


@kernel(inline=True)
def project_onto_pivot(body, y):
    """With a pivot, reset ``R = P + Q c`` and ``V = Q (ω × c)`` of the array ``y`` in place
    (:func:`pivot_constrained`); a free body's state is written back unchanged."""
    store_state(y, 0, 1, pivot_constrained(body, y))


# --------------------------------------------------------------------------- energy, momentum
@kernel(inline=True)
def rotational_energy_of(inertia, w0, w1, w2):
    """``½ ω·Aω`` of one ω (scalars); inertia (3, 3)."""
    e = 0.0
    for j in range(3):
        wj = w0 if j == 0 else (w1 if j == 1 else w2)
        e += wj * (inertia[j, 0] * w0 + inertia[j, 1] * w1 + inertia[j, 2] * w2)
    return 0.5 * e


@kernel(inline=True)
def kinetic_energy_of(inertia, mass, y):
    """Kinetic energy (12) of one body-frame state ``y`` (array or 18-tuple):
    ``½ Aω·ω + ½ M |Ṙ|²``, inertia (3, 3) about the centre of mass."""
    w = OMEGA_AT
    v = V_AT
    rot = rotational_energy_of(inertia, y[w], y[w + 1], y[w + 2])
    return rot + 0.5 * mass * (y[v] ** 2 + y[v + 1] ** 2 + y[v + 2] ** 2)


@kernel(inline=True)
def angular_momentum_com_of(inertia, y):
    """``Q A ω`` of one body-frame state ``y``: the angular momentum about the centre of mass,
    space frame (the first term of eq. (03)); a 3-tuple."""
    w0 = y[OMEGA_AT]
    w1 = y[OMEGA_AT + 1]
    w2 = y[OMEGA_AT + 2]
    p0 = inertia[0, 0] * w0 + inertia[0, 1] * w1 + inertia[0, 2] * w2
    p1 = inertia[1, 0] * w0 + inertia[1, 1] * w1 + inertia[1, 2] * w2
    p2 = inertia[2, 0] * w0 + inertia[2, 1] * w1 + inertia[2, 2] * w2
    q = Q_AT
    return (
        y[q] * p0 + y[q + 1] * p1 + y[q + 2] * p2,
        y[q + 3] * p0 + y[q + 4] * p1 + y[q + 5] * p2,
        y[q + 6] * p0 + y[q + 7] * p1 + y[q + 8] * p2,
    )


@kernel(inline=True)
def orthogonality_error_of(y):
    """``max |QᵀQ − I|`` of the attitude of one state ``y`` (array or 18-tuple)."""
    worst = 0.0
    q = Q_AT
    for a in range(3):
        for b in range(3):
            s = y[q + a] * y[q + b] + y[q + 3 + a] * y[q + 3 + b] + y[q + 6 + a] * y[q + 6 + b]
            if a == b:
                s -= 1.0
            worst = max(worst, abs(s))
    return worst


@kernel
def _rows(a, k):
    return np.ascontiguousarray(np.asarray(a)).reshape((-1, k)).astype(np.float64)


@kernel
def rotational_energy(inertia, omega):
    """Rotational kinetic energy ``½ ω·Aω`` (the ``k`` of eq. (30)). inertia (3, 3), omega
    (..., 3) → (...)."""
    omega = np.asarray(omega)
    w = _rows(omega, 3)
    out = np.empty(w.shape[0])
    for i in range(w.shape[0]):
        out[i] = rotational_energy_of(inertia, w[i, 0], w[i, 1], w[i, 2])
    return out.reshape(omega.shape[:-1])


@kernel
def kinetic_energy(inertia, mass, omega, V):
    """Kinetic energy, eq. (12): ``K = ½ Aω·ω + ½ M |Ṙ|²`` (erratum corrected: the notebook
    prints ``½ ω·ω``). inertia (3, 3) about the centre of mass, omega and V (..., 3) → (...)."""
    V = np.asarray(V)
    w = _rows(omega, 3)
    v = _rows(V, 3)
    out = np.empty(v.shape[0])
    y = np.zeros(STATE_SIZE)
    for i in range(v.shape[0]):
        for k in range(3):
            y[OMEGA_AT + k] = w[i, k]
            y[V_AT + k] = v[i, k]
        out[i] = kinetic_energy_of(inertia, mass, y)
    return out.reshape(V.shape[:-1])


@kernel
def angular_momentum_body(inertia, omega):
    """Angular momentum in the body frame, ``π = A ω``; its length is the ``a`` of eq. (31).
    inertia (3, 3), omega (..., 3) → (..., 3)."""
    omega = np.asarray(omega)
    w = _rows(omega, 3)
    out = np.empty_like(w)
    for i in range(w.shape[0]):
        for j in range(3):
            out[i, j] = inertia[j, 0] * w[i, 0] + inertia[j, 1] * w[i, 1] + inertia[j, 2] * w[i, 2]
    return out.reshape(omega.shape)


@kernel
def angular_momentum_com(inertia, Q, omega):
    """Angular momentum about the centre of mass in the space frame, ``Q A ω`` (the first term
    of eq. (03)). Q (n, 3, 3), omega (n, 3) → (n, 3)."""
    out = np.empty((omega.shape[0], 3))
    y = np.zeros(STATE_SIZE)
    for i in range(omega.shape[0]):
        for k in range(3):
            y[OMEGA_AT + k] = omega[i, k]
            for j in range(3):
                y[Q_AT + 3 * k + j] = Q[i, k, j]
        out[i, 0], out[i, 1], out[i, 2] = angular_momentum_com_of(inertia, y)
    return out


@kernel
def angular_momentum(inertia, mass, R, V, Q, omega):
    """Angular momentum about the space origin, eq. (03): ``L = Q A ω + M R × Ṙ``.
    R, V, omega (n, 3), Q (n, 3, 3) → (n, 3)."""
    out = angular_momentum_com(inertia, Q, omega)
    for i in range(out.shape[0]):
        out[i, 0] += mass * (R[i, 1] * V[i, 2] - R[i, 2] * V[i, 1])
        out[i, 1] += mass * (R[i, 2] * V[i, 0] - R[i, 0] * V[i, 2])
        out[i, 2] += mass * (R[i, 0] * V[i, 1] - R[i, 1] * V[i, 0])
    return out


@kernel
def omega_space(Q, omega):
    """Angular velocity in the space frame, ``Q ω``. Q (n, 3, 3), omega (n, 3) → (n, 3)."""
    out = np.empty((omega.shape[0], 3))
    for i in range(omega.shape[0]):
        for j in range(3):
            out[i, j] = (
                Q[i, j, 0] * omega[i, 0] + Q[i, j, 1] * omega[i, 1] + Q[i, j, 2] * omega[i, 2]
            )
    return out


@kernel
def orthogonality_error(Q):
    """``max |QᵀQ − I|`` per matrix: how far integration has taken Q off SO(3).
    Q (n, 3, 3) → (n,)."""
    out = np.empty(Q.shape[0])
    y = np.zeros(STATE_SIZE)
    for i in range(Q.shape[0]):
        for r in range(3):
            for k in range(3):
                y[Q_AT + 3 * r + k] = Q[i, r, k]
        out[i] = orthogonality_error_of(y)
    return out


@kernel
def pivot_point_of(body, y):
    """Where the pivot is in space for a state ``y`` of the engine (principal frame) of a body
    with parameters ``body``: ``P = R − Q c`` (a 3-tuple)."""
    c0 = body[COM_OFFSET]
    c1 = body[COM_OFFSET + 1]
    c2 = body[COM_OFFSET + 2]
    q = Q_AT
    return (
        y[R_AT] - (y[q] * c0 + y[q + 1] * c1 + y[q + 2] * c2),
        y[R_AT + 1] - (y[q + 3] * c0 + y[q + 4] * c1 + y[q + 5] * c2),
        y[R_AT + 2] - (y[q + 6] * c0 + y[q + 7] * c1 + y[q + 8] * c2),
    )


@kernel
def initial_states(Q, omega, R, V, com, c, pivot, has_pivot, line):
    """Body-frame initial states (N, 18) of one body's motions, by the rules of
    :func:`poinsot.simulate`: ``Q`` (1 or N, 3, 3) the attitudes, ``omega`` (N, 3) the body-frame
    angular velocities; ``R`` and ``V`` (1 or N, 3, or 0 rows: the default).

    Free body (``has_pivot`` false): ``R`` defaults to the centre of mass ``com``, ``V`` to 0.
    About a pivot (the body point ``pivot``, ``c`` = centre of mass − pivot, body frame):
    ``R`` defaults to ``pivot + Q c`` and ``V = Q (ω × c)`` follows from ω. A degenerate body
    (all mass on the unit ``line``; zeros otherwise) loses its spin about the line, which is
    undefined.
    """
    n = omega.shape[0]
    out = np.empty((n, STATE_SIZE))
    for i in range(n):
        q = Q[i if Q.shape[0] > 1 else 0]
        w0 = omega[i, 0]
        w1 = omega[i, 1]
        w2 = omega[i, 2]
        spin = w0 * line[0] + w1 * line[1] + w2 * line[2]
        w0 -= spin * line[0]
        w1 -= spin * line[1]
        w2 -= spin * line[2]
        for k in range(3):
            if R.shape[0] > 0:
                out[i, R_AT + k] = R[i if R.shape[0] > 1 else 0, k]
            elif has_pivot:
                out[i, R_AT + k] = pivot[k] + q[k, 0] * c[0] + q[k, 1] * c[1] + q[k, 2] * c[2]
            else:
                out[i, R_AT + k] = com[k]
        u0 = w1 * c[2] - w2 * c[1]
        u1 = w2 * c[0] - w0 * c[2]
        u2 = w0 * c[1] - w1 * c[0]
        for k in range(3):
            if has_pivot:
                out[i, V_AT + k] = q[k, 0] * u0 + q[k, 1] * u1 + q[k, 2] * u2
            elif V.shape[0] > 0:
                out[i, V_AT + k] = V[i if V.shape[0] > 1 else 0, k]
            else:
                out[i, V_AT + k] = 0.0
            for j in range(3):
                out[i, Q_AT + 3 * k + j] = q[k, j]
        out[i, OMEGA_AT] = w0
        out[i, OMEGA_AT + 1] = w1
        out[i, OMEGA_AT + 2] = w2
    return out


# --------------------------------------------------------------------------- frames
@kernel(inline=True)
def state_to_principal_into(axes, y, out):
    """A state from the body frame to the principal frame of ``axes`` (columns e1, e2, e3 in
    body coordinates): ``Q_p = Q E``, ``ω_p = Eᵀ ω``; R and V unchanged."""
    for k in range(3):
        out[R_AT + k] = y[R_AT + k]
        out[V_AT + k] = y[V_AT + k]
        out[OMEGA_AT + k] = (
            axes[0, k] * y[OMEGA_AT] + axes[1, k] * y[OMEGA_AT + 1] + axes[2, k] * y[OMEGA_AT + 2]
        )
    for r in range(3):
        for k in range(3):
            out[Q_AT + 3 * r + k] = (
                y[Q_AT + 3 * r] * axes[0, k]
                + y[Q_AT + 3 * r + 1] * axes[1, k]
                + y[Q_AT + 3 * r + 2] * axes[2, k]
            )


@kernel(inline=True)
def state_from_principal_into(axes, z, out):
    """Inverse of :func:`state_to_principal_into`: ``Q = Q_p Eᵀ``, ``ω = E ω_p``."""
    for k in range(3):
        out[R_AT + k] = z[R_AT + k]
        out[V_AT + k] = z[V_AT + k]
        out[OMEGA_AT + k] = (
            axes[k, 0] * z[OMEGA_AT] + axes[k, 1] * z[OMEGA_AT + 1] + axes[k, 2] * z[OMEGA_AT + 2]
        )
    for r in range(3):
        for k in range(3):
            out[Q_AT + 3 * r + k] = (
                z[Q_AT + 3 * r] * axes[k, 0]
                + z[Q_AT + 3 * r + 1] * axes[k, 1]
                + z[Q_AT + 3 * r + 2] * axes[k, 2]
            )


@kernel
def states_to_principal(axes, Y):
    """States (n, 18) from the body frame to the principal frame of ``axes``."""
    out = np.empty((Y.shape[0], STATE_SIZE))
    for i in range(Y.shape[0]):
        state_to_principal_into(axes, Y[i], out[i])
    return out


@kernel
def states_from_principal(axes, Z):
    """States (n, 18) from the principal frame of ``axes`` back to the body frame."""
    out = np.empty((Z.shape[0], STATE_SIZE))
    for i in range(Z.shape[0]):
        state_from_principal_into(axes, Z[i], out[i])
    return out


# --------------------------------------------------------------------------- free rotor
@kernel
def rotor_code(moments, rtol):
    """Which exact free-rotor flow applies to the ascending principal ``moments``: −1 for
    three distinct moments (McLachlan's split), or the index of the symmetry axis (0 for a
    prolate body or a rod, 2 for an oblate or spherical one)."""
    code = symmetry_code(moments, rtol)
    if code == 0:
        return -1
    if code == 1:
        return 0
    return 2


@kernel
def rigid_body_parameters(mass, moments, axes, com_offset, inertia_com, has_pivot):
    """Everything the engine needs of a body, in one call: ``(parameters, degenerate)``.

    ``moments`` (ascending) and ``axes`` (columns) are the principal decomposition of the
    inertia about the reference point; ``com_offset`` (3,) the centre of mass from it and
    ``inertia_com`` (3, 3) the inertia about the centre of mass, both in the body frame. A
    moment below :data:`~poinsot.kernels.inertia.DEGENERATE_RTOL` times the largest (a body on a
    line) is set to zero, so that its line has no angular acceleration (the minimum-norm
    solution); the free-rotor flow is chosen by :func:`rotor_code`.
    """
    m = moments.copy()
    degenerate = is_degenerate(m, DEGENERATE_RTOL)
    if degenerate:
        for k in range(3):
            if m[k] <= DEGENERATE_RTOL * m[2]:
                m[k] = 0.0
    c = axes.T @ com_offset
    A = axes.T @ inertia_com @ axes
    params = body_vector(mass, m, c, A, np.zeros(3), has_pivot, float(rotor_code(m, SYMMETRY_RTOL)))
    return params, degenerate


@kernel(inline=True)
def rotate_pair_into(axis, angle, z):
    """The sub-flow of a rotation by ``angle`` about principal axis ``axis``, in place on the
    momentum state ``z`` (the body momentum π in the ω slot): ``π ← Rotᵀ π``, ``Q ← Q Rot``."""
    c = math.cos(angle)
    s = math.sin(angle)
    i = (axis + 1) % 3
    j = (axis + 2) % 3
    pi_i = z[OMEGA_AT + i]
    pi_j = z[OMEGA_AT + j]
    z[OMEGA_AT + i] = c * pi_i + s * pi_j
    z[OMEGA_AT + j] = -s * pi_i + c * pi_j
    for r in range(3):
        qi = z[Q_AT + 3 * r + i]
        qj = z[Q_AT + 3 * r + j]
        z[Q_AT + 3 * r + i] = c * qi + s * qj
        z[Q_AT + 3 * r + j] = -s * qi + c * qj


@kernel(inline=True)
def free_rotor_step_into(body, z, h, E, P):
    """Advance the torque-free rotor by ``h``, in place, exactly or by a symmetric split.

    ``z`` is the momentum state (π, the body angular momentum in principal axes, in the ω slot;
    Q the attitude of the principal frame); the principal moments (ascending) and the flow to
    use (:func:`rotor_code`) come from the body parameters. ``E``, ``P`` (3, 3) are work space.

    * Symmetric rotor (symmetry axis s, ``I_e`` the repeated moment):
      ``H = |π|²/(2 I_e) + (1/I_s − 1/I_e) π_s²/2``; both terms commute and each flow is a
      rotation: about π itself by ``h|π|/I_e`` (``Q ← Q exp(h π/I_e)``) and about ``e_s`` by
      ``h (1/I_s − 1/I_e) π_s``. Their product is the exact flow. A zero moment (a rod) has
      no spin flow.
    * Otherwise the symmetric composition ``H1(h/2) H2(h/2) H3(h) H2(h/2) H1(h/2)`` of the
      exact flows of ``H_i = π_i²/(2 I_i)`` (McLachlan 1993, Phys. Rev. Lett. 71): second
      order, symplectic, and it keeps ``|π|`` and the spatial momentum ``Q π`` exactly.
      Axes with ``I_i = 0`` carry no flow.
    """
    rotor = int(body[ROTOR])
    if rotor < 0:
        for k in range(5):
            axis = 0 if k == 0 or k == 4 else (1 if k == 1 or k == 3 else 2)
            frac = 1.0 if k == 2 else 0.5
            Ik = body[MOMENTS + axis]
            if Ik > 0.0:
                rotate_pair_into(axis, frac * h * z[OMEGA_AT + axis] / Ik, z)
        return
    s = rotor
    Ie = body[MOMENTS + (s + 1) % 3]
    c = h / Ie
    exp_so3_into(c * z[OMEGA_AT], c * z[OMEGA_AT + 1], c * z[OMEGA_AT + 2], E)
    for r in range(3):
        for k in range(3):
            P[r, k] = (
                z[Q_AT + 3 * r] * E[0, k]
                + z[Q_AT + 3 * r + 1] * E[1, k]
                + z[Q_AT + 3 * r + 2] * E[2, k]
            )
    for r in range(3):
        for k in range(3):
            z[Q_AT + 3 * r + k] = P[r, k]
    Is = body[MOMENTS + s]
    if Is > 0.0:
        rotate_pair_into(s, h * (1.0 / Is - 1.0 / Ie) * z[OMEGA_AT + s], z)


@kernel
def free_rotor_step(moments, pi, Q, h):
    """The torque-free rotor advanced by ``h`` (see :func:`free_rotor_step_into`): returns the
    new ``(pi (3,), Q (3, 3))``; ``moments`` ascending, ``Q`` the principal frame's attitude.

    Examples
    --------
    >>> import numpy as np
    >>> pi, Q = free_rotor_step(np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 3.0]),
    ...                         np.eye(3), np.pi / 2)     # a steady spin about e3 at ω = 1
    >>> np.round(Q @ [1.0, 0.0, 0.0], 12).tolist()
    [0.0, 1.0, 0.0]
    """
    body = np.zeros(BODY_SIZE)
    for k in range(3):
        body[MOMENTS + k] = moments[k]
    body[ROTOR] = rotor_code(moments, SYMMETRY_RTOL)
    z = np.zeros(STATE_SIZE)
    for k in range(3):
        z[OMEGA_AT + k] = pi[k]
        for j in range(3):
            z[Q_AT + 3 * k + j] = Q[k, j]
    free_rotor_step_into(body, z, h, np.empty((3, 3)), np.empty((3, 3)))
    return z[OMEGA_AT : OMEGA_AT + 3].copy(), z[Q_AT : Q_AT + 9].copy().reshape((3, 3))


# --------------------------------------------------------------------------- particles
@kernel
def particle_positions(R, Q, u):
    """Positions of the particles of a rigid motion, ``r_i = Q u_i + R`` (the rigidity theorem
    of ``docs/theory.md`` §1). R (3,), Q (3, 3), offsets u (N, 3) → (N, 3)."""
    out = np.empty((u.shape[0], 3))
    for i in range(u.shape[0]):
        for j in range(3):
            out[i, j] = R[j] + Q[j, 0] * u[i, 0] + Q[j, 1] * u[i, 1] + Q[j, 2] * u[i, 2]
    return out


@kernel
def particle_velocities(V, Q, omega, u):
    """Velocities of the particles, ``ṙ_i = Q(ω × u_i) + Ṙ``. V (3,), Q (3, 3), ω (3,) body
    frame, offsets u (N, 3) → (N, 3)."""
    out = np.empty((u.shape[0], 3))
    for i in range(u.shape[0]):
        c0 = omega[1] * u[i, 2] - omega[2] * u[i, 1]
        c1 = omega[2] * u[i, 0] - omega[0] * u[i, 2]
        c2 = omega[0] * u[i, 1] - omega[1] * u[i, 0]
        for j in range(3):
            out[i, j] = V[j] + Q[j, 0] * c0 + Q[j, 1] * c1 + Q[j, 2] * c2
    return out


@kernel
def particle_trajectories(R, Q, u):
    """:func:`particle_positions` at every sample: R (n, 3), Q (n, 3, 3), u (N, 3) →
    (n, N, 3)."""
    out = np.empty((R.shape[0], u.shape[0], 3))
    for k in range(R.shape[0]):
        out[k] = particle_positions(R[k], Q[k], u)
    return out


@kernel
def rigid_motion_from_particles(masses, positions, velocities, center, inertia_inv):
    """The notebook's initial conditions from particle data (``docs/theory.md`` §1), at
    ``Q(0) = I``: ``Ṙ(0) = Σ m_i ṙ_i / M`` and ``A ω(0) = L(0) − M R(0) × Ṙ(0)`` with
    ``L(0) = Σ m_i r_i × ṙ_i`` (eq. (03)); ``inertia_inv`` is ``A⁻¹`` (a pseudo-inverse for a
    degenerate body: the minimum-norm ω).

    Returns ``(V (3,), ω (3,), residual (N,))``, the residual ``|ṙ_i − (Ṙ + ω × u_i)|`` that is
    zero when the velocities are a rigid motion.
    """
    M = 0.0
    P = np.zeros(3)
    L = np.zeros(3)
    for i in range(masses.shape[0]):
        m = masses[i]
        r = positions[i]
        v = velocities[i]
        M += m
        for j in range(3):
            P[j] += m * v[j]
        L[0] += m * (r[1] * v[2] - r[2] * v[1])
        L[1] += m * (r[2] * v[0] - r[0] * v[2])
        L[2] += m * (r[0] * v[1] - r[1] * v[0])
    V = P / M
    rhs = np.empty(3)
    rhs[0] = L[0] - M * (center[1] * V[2] - center[2] * V[1])
    rhs[1] = L[1] - M * (center[2] * V[0] - center[0] * V[2])
    rhs[2] = L[2] - M * (center[0] * V[1] - center[1] * V[0])
    omega = inertia_inv @ rhs
    u = positions - center
    rigid = particle_velocities(V, np.eye(3), omega, u)
    residual = np.empty(masses.shape[0])
    for i in range(masses.shape[0]):
        d = 0.0
        for j in range(3):
            d += (velocities[i, j] - rigid[i, j]) ** 2
        residual[i] = math.sqrt(d)
    return V, omega, residual
