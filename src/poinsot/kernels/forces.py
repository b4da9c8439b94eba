"""The built-in forces as formulas on lowered data (``docs/theory.md`` §1, eqs (07)–(08)).

A force is lowered (by :mod:`poinsot.forces`) to a kind code and a row of
:data:`~poinsot.kernels.layout.FORCE_PARAMS` numbers; body points and body-fixed vectors are
expressed, at lowering, in the frame the state uses (the principal frame inside the engine),
relative to the centre of mass. Each ``*_wrench`` kernel **adds** its force ``F`` (space frame)
and its torque ``τ`` about the centre of mass (body frame) to ``F`` and ``tau``; each
``*_potential`` returns its potential energy. The parameter rows are:

================  =====================================================================
kind              parameters
================  =====================================================================
gravity           ``g`` (0:3)
central_gravity   ``μ`` (0), centre (1:4), gradient terms on/off (4)
spring            body point ``b`` (0:3), anchor (3:6), stiffness ``k`` (6), rest length
                  ``ℓ₀`` (7), damping ``c`` (8), tether on/off (9)
linear_drag       ``c`` (0), rotational ``c_rot`` (1)
quadratic_drag    ``c`` (0), rotational ``c_rot`` (1)
point_force       body point ``b`` (0:3), force ``f`` (3:6), ``f`` body-fixed (6)
torque            torque (0:3), body-fixed (3)
================  =====================================================================
"""

from __future__ import annotations

import math

import numpy as np

from .jit import kernel
from .layout import FORCE_KINDS, INERTIA_COM, MASS, OMEGA_AT, Q_AT, R_AT, V_AT

__all__ = [
    "CENTRAL_GRAVITY",
    "GRAVITY",
    "LINEAR_DRAG",
    "POINT_FORCE",
    "QUADRATIC_DRAG",
    "SPRING",
    "TORQUE",
    "builtin_potential",
    "builtin_wrench",
    "central_gravity_potential",
    "central_gravity_wrench",
    "force_potential",
    "force_potential_of",
    "force_wrench",
    "force_wrench_of",
    "gravity_potential",
    "gravity_wrench",
    "linear_drag_wrench",
    "moment_about_center",
    "point_force_wrench",
    "potential_energies",
    "quadratic_drag_wrench",
    "spring_potential",
    "spring_wrench",
    "torque_wrench",
]

GRAVITY = FORCE_KINDS["gravity"]
CENTRAL_GRAVITY = FORCE_KINDS["central_gravity"]
SPRING = FORCE_KINDS["spring"]
LINEAR_DRAG = FORCE_KINDS["linear_drag"]
QUADRATIC_DRAG = FORCE_KINDS["quadratic_drag"]
POINT_FORCE = FORCE_KINDS["point_force"]
TORQUE = FORCE_KINDS["torque"]


@kernel(inline=True)
def moment_about_center(b0, b1, b2, y, Fx, Fy, Fz):
    """``b × Qᵀ F``: the torque about the centre of mass (body frame) of the force ``F``
    (space frame) applied at the body point ``b`` (body frame, from the centre of mass),
    eq. (08). Returns a 3-tuple."""
    c0 = y[Q_AT] * Fx + y[Q_AT + 3] * Fy + y[Q_AT + 6] * Fz
    c1 = y[Q_AT + 1] * Fx + y[Q_AT + 4] * Fy + y[Q_AT + 7] * Fz
    c2 = y[Q_AT + 2] * Fx + y[Q_AT + 5] * Fy + y[Q_AT + 8] * Fz
    return b1 * c2 - b2 * c1, b2 * c0 - b0 * c2, b0 * c1 - b1 * c0


@kernel(inline=True)
def _body_point(b0, b1, b2, y):
    """Space position ``R + Q b`` of the body point ``b``. Returns a 3-tuple."""
    return (
        y[R_AT] + y[Q_AT] * b0 + y[Q_AT + 1] * b1 + y[Q_AT + 2] * b2,
        y[R_AT + 1] + y[Q_AT + 3] * b0 + y[Q_AT + 4] * b1 + y[Q_AT + 5] * b2,
        y[R_AT + 2] + y[Q_AT + 6] * b0 + y[Q_AT + 7] * b1 + y[Q_AT + 8] * b2,
    )


# --------------------------------------------------------------------------- uniform gravity
@kernel(inline=True)
def gravity_wrench(P, i, body, t, y):
    """Uniform gravity ``g = P[i, 0:3]``: ``F = M g`` at the centre of mass and no torque
    about it (``Σ m_i g`` over the particles, and ``Σ u_i × Qᵀ m_i g = 0`` since
    ``Σ m_i u_i = 0``). Returns ``(Fx, Fy, Fz, τx, τy, τz)``."""
    M = body[MASS]
    return M * P[i, 0], M * P[i, 1], M * P[i, 2], 0.0, 0.0, 0.0


@kernel(inline=True)
def gravity_potential(P, i, body, t, y):
    """``U = −M g·R``."""
    return -body[MASS] * (P[i, 0] * y[R_AT] + P[i, 1] * y[R_AT + 1] + P[i, 2] * y[R_AT + 2])


# --------------------------------------------------------------------------- central gravity
@kernel(inline=True)
def central_gravity_wrench(P, i, body, t, y):
    """Gravity of a point mass ``μ = G M_c`` (``P[i, 0]``) at ``P[i, 1:4]``, with MacCullagh's
    gravity-gradient terms when ``P[i, 4] ≠ 0``.

    With ``r`` from the centre to the centre of mass, ``b = Qᵀ r`` its body components and
    ``A`` the inertia about the centre of mass: ``F = −μM r/|r|³ − 3μ/(2|r|⁵) tr(A) r
    − 3μ/|r|⁵ Q A b + 15μ/(2|r|⁷) (b·Ab) r`` (``−∇U`` of :func:`central_gravity_potential`)
    and the gravity-gradient torque ``τ = 3μ/|r|⁵ b × A b`` (Hughes, *Spacecraft Attitude
    Dynamics*, §8.2). A body at the centre gives non-finite values (the engine stops there).
    """
    mu = P[i, 0]
    rx = y[R_AT] - P[i, 1]
    ry = y[R_AT + 1] - P[i, 2]
    rz = y[R_AT + 2] - P[i, 3]
    r2 = rx * rx + ry * ry + rz * rz
    r = math.sqrt(r2)
    r3 = r2 * r
    k = -mu * body[MASS] / r3
    Fx = k * rx
    Fy = k * ry
    Fz = k * rz
    tx = 0.0
    ty = 0.0
    tz = 0.0
    if P[i, 4] != 0.0:
        A = INERTIA_COM
        b0 = y[Q_AT] * rx + y[Q_AT + 3] * ry + y[Q_AT + 6] * rz
        b1 = y[Q_AT + 1] * rx + y[Q_AT + 4] * ry + y[Q_AT + 7] * rz
        b2 = y[Q_AT + 2] * rx + y[Q_AT + 5] * ry + y[Q_AT + 8] * rz
        a0 = body[A] * b0 + body[A + 1] * b1 + body[A + 2] * b2
        a1 = body[A + 3] * b0 + body[A + 4] * b1 + body[A + 5] * b2
        a2 = body[A + 6] * b0 + body[A + 7] * b1 + body[A + 8] * b2
        bAb = b0 * a0 + b1 * a1 + b2 * a2
        trA = body[A] + body[A + 4] + body[A + 8]
        r5 = r3 * r2
        r7 = r5 * r2
        radial = -1.5 * mu * trA / r5 + 7.5 * mu * bAb / r7
        s0 = y[Q_AT] * a0 + y[Q_AT + 1] * a1 + y[Q_AT + 2] * a2  # Q A b
        s1 = y[Q_AT + 3] * a0 + y[Q_AT + 4] * a1 + y[Q_AT + 5] * a2
        s2 = y[Q_AT + 6] * a0 + y[Q_AT + 7] * a1 + y[Q_AT + 8] * a2
        Fx += radial * rx - 3.0 * mu * s0 / r5
        Fy += radial * ry - 3.0 * mu * s1 / r5
        Fz += radial * rz - 3.0 * mu * s2 / r5
        g = 3.0 * mu / r5
        tx = g * (b1 * a2 - b2 * a1)
        ty = g * (b2 * a0 - b0 * a2)
        tz = g * (b0 * a1 - b1 * a0)
    return Fx, Fy, Fz, tx, ty, tz


@kernel(inline=True)
def central_gravity_potential(P, i, body, t, y):
    """MacCullagh's formula: ``U = −μM/|r| − μ/(2|r|³) (tr A − 3 n̂·A n̂)``, ``n̂ = Qᵀ r/|r|``
    (the last term only with the gradient terms on)."""
    mu = P[i, 0]
    rx = y[R_AT] - P[i, 1]
    ry = y[R_AT + 1] - P[i, 2]
    rz = y[R_AT + 2] - P[i, 3]
    r2 = rx * rx + ry * ry + rz * rz
    r = math.sqrt(r2)
    U = -mu * body[MASS] / r
    if P[i, 4] != 0.0:
        A = INERTIA_COM
        b0 = y[Q_AT] * rx + y[Q_AT + 3] * ry + y[Q_AT + 6] * rz
        b1 = y[Q_AT + 1] * rx + y[Q_AT + 4] * ry + y[Q_AT + 7] * rz
        b2 = y[Q_AT + 2] * rx + y[Q_AT + 5] * ry + y[Q_AT + 8] * rz
        bAb = (
            b0 * (body[A] * b0 + body[A + 1] * b1 + body[A + 2] * b2)
            + b1 * (body[A + 3] * b0 + body[A + 4] * b1 + body[A + 5] * b2)
            + b2 * (body[A + 6] * b0 + body[A + 7] * b1 + body[A + 8] * b2)
        )
        trA = body[A] + body[A + 4] + body[A + 8]
        U -= mu / (2.0 * r2 * r) * (trA - 3.0 * bAb / r2)
    return U


# --------------------------------------------------------------------------- spring / tether
@kernel(inline=True)
def spring_wrench(P, i, body, t, y):
    """A linear spring (or elastic tether) from the body point ``b = P[i, 0:3]`` to the fixed
    anchor ``P[i, 3:6]``.

    ``d = anchor − (R + Q b)``, ``ℓ = |d|``; tension ``T = k (ℓ − ℓ₀) − c (d̂·v_b)`` with
    ``v_b = V + Q (ω × b)`` the point's velocity; ``F = T d̂`` at the point. A tether
    (``P[i, 9] ≠ 0``) pulls only when stretched; at ``ℓ = 0`` the direction is undefined and the
    spring exerts nothing.
    """
    b0 = P[i, 0]
    b1 = P[i, 1]
    b2 = P[i, 2]
    x0, x1, x2 = _body_point(b0, b1, b2, y)
    dx = P[i, 3] - x0
    dy = P[i, 4] - x1
    dz = P[i, 5] - x2
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    stretch = length - P[i, 7]
    tension = 0.0
    ux = 0.0
    uy = 0.0
    uz = 0.0
    if length > 0.0 and (P[i, 9] == 0.0 or stretch > 0.0):
        ux = dx / length
        uy = dy / length
        uz = dz / length
        tension = P[i, 6] * stretch
        if P[i, 8] != 0.0:
            w0 = y[OMEGA_AT]
            w1 = y[OMEGA_AT + 1]
            w2 = y[OMEGA_AT + 2]
            c0 = w1 * b2 - w2 * b1
            c1 = w2 * b0 - w0 * b2
            c2 = w0 * b1 - w1 * b0
            vx = y[V_AT] + y[Q_AT] * c0 + y[Q_AT + 1] * c1 + y[Q_AT + 2] * c2
            vy = y[V_AT + 1] + y[Q_AT + 3] * c0 + y[Q_AT + 4] * c1 + y[Q_AT + 5] * c2
            vz = y[V_AT + 2] + y[Q_AT + 6] * c0 + y[Q_AT + 7] * c1 + y[Q_AT + 8] * c2
            tension -= P[i, 8] * (ux * vx + uy * vy + uz * vz)
    Fx = tension * ux
    Fy = tension * uy
    Fz = tension * uz
    tx, ty, tz = moment_about_center(b0, b1, b2, y, Fx, Fy, Fz)
    return Fx, Fy, Fz, tx, ty, tz


@kernel(inline=True)
def spring_potential(P, i, body, t, y):
    """``U = ½ k (ℓ − ℓ₀)²``; zero while a tether is slack (the damper has no potential)."""
    x0, x1, x2 = _body_point(P[i, 0], P[i, 1], P[i, 2], y)
    dx = P[i, 3] - x0
    dy = P[i, 4] - x1
    dz = P[i, 5] - x2
    stretch = math.sqrt(dx * dx + dy * dy + dz * dz) - P[i, 7]
    if P[i, 9] != 0.0 and stretch <= 0.0:
        return 0.0
    return 0.5 * P[i, 6] * stretch * stretch


# --------------------------------------------------------------------------- drag
@kernel(inline=True)
def linear_drag_wrench(P, i, body, t, y):
    """Linear (Stokes) drag: ``F = −c V`` on the centre of mass (``−(c/M) Σ m_i ṙ_i``) and the
    rotational model ``τ = −c_rot ω``."""
    c = P[i, 0]
    r = P[i, 1]
    return (
        -c * y[V_AT],
        -c * y[V_AT + 1],
        -c * y[V_AT + 2],
        -r * y[OMEGA_AT],
        -r * y[OMEGA_AT + 1],
        -r * y[OMEGA_AT + 2],
    )


@kernel(inline=True)
def quadratic_drag_wrench(P, i, body, t, y):
    """Quadratic drag: ``F = −c |V| V`` on the centre of mass and ``τ = −c_rot |ω| ω``."""
    v = math.sqrt(y[V_AT] ** 2 + y[V_AT + 1] ** 2 + y[V_AT + 2] ** 2)
    w = math.sqrt(y[OMEGA_AT] ** 2 + y[OMEGA_AT + 1] ** 2 + y[OMEGA_AT + 2] ** 2)
    c = P[i, 0] * v
    r = P[i, 1] * w
    return (
        -c * y[V_AT],
        -c * y[V_AT + 1],
        -c * y[V_AT + 2],
        -r * y[OMEGA_AT],
        -r * y[OMEGA_AT + 1],
        -r * y[OMEGA_AT + 2],
    )


# --------------------------------------------------------------------------- point force, torque
@kernel(inline=True)
def point_force_wrench(P, i, body, t, y):
    """A constant force ``f = P[i, 3:6]`` at the body point ``b = P[i, 0:3]``: ``F = f`` (space
    frame) or ``F = Q f`` (body-fixed, ``P[i, 6] ≠ 0``), with its moment ``b × Qᵀ F``."""
    f0 = P[i, 3]
    f1 = P[i, 4]
    f2 = P[i, 5]
    Fx = f0
    Fy = f1
    Fz = f2
    if P[i, 6] != 0.0:
        Fx = y[Q_AT] * f0 + y[Q_AT + 1] * f1 + y[Q_AT + 2] * f2
        Fy = y[Q_AT + 3] * f0 + y[Q_AT + 4] * f1 + y[Q_AT + 5] * f2
        Fz = y[Q_AT + 6] * f0 + y[Q_AT + 7] * f1 + y[Q_AT + 8] * f2
    tx, ty, tz = moment_about_center(P[i, 0], P[i, 1], P[i, 2], y, Fx, Fy, Fz)
    return Fx, Fy, Fz, tx, ty, tz


@kernel(inline=True)
def torque_wrench(P, i, body, t, y):
    """A pure couple ``τ = P[i, 0:3]``: body-fixed (``P[i, 3] ≠ 0``), or fixed in space, whose
    body components are ``Qᵀ τ``."""
    t0 = P[i, 0]
    t1 = P[i, 1]
    t2 = P[i, 2]
    if P[i, 3] != 0.0:
        return 0.0, 0.0, 0.0, t0, t1, t2
    return (
        0.0,
        0.0,
        0.0,
        y[Q_AT] * t0 + y[Q_AT + 3] * t1 + y[Q_AT + 6] * t2,
        y[Q_AT + 1] * t0 + y[Q_AT + 4] * t1 + y[Q_AT + 7] * t2,
        y[Q_AT + 2] * t0 + y[Q_AT + 5] * t1 + y[Q_AT + 8] * t2,
    )


# --------------------------------------------------------------------------- dispatch
@kernel(inline=True)
def force_wrench_of(kind, P, i, body, t, y):
    """The wrench ``(Fx, Fy, Fz, τx, τy, τz)`` of the lowered force ``i`` of kind ``kind`` (a
    code of :data:`~poinsot.kernels.layout.FORCE_KINDS`); zero for an unknown kind."""
    if kind == GRAVITY:
        return gravity_wrench(P, i, body, t, y)
    if kind == CENTRAL_GRAVITY:
        return central_gravity_wrench(P, i, body, t, y)
    if kind == SPRING:
        return spring_wrench(P, i, body, t, y)
    if kind == LINEAR_DRAG:
        return linear_drag_wrench(P, i, body, t, y)
    if kind == QUADRATIC_DRAG:
        return quadratic_drag_wrench(P, i, body, t, y)
    if kind == POINT_FORCE:
        return point_force_wrench(P, i, body, t, y)
    if kind == TORQUE:
        return torque_wrench(P, i, body, t, y)
    return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


@kernel(inline=True)
def force_potential(kind, P, i, body, t, y):
    """Potential energy of the lowered force ``i`` (zero for kinds without a potential)."""
    if kind == GRAVITY:
        return gravity_potential(P, i, body, t, y)
    if kind == CENTRAL_GRAVITY:
        return central_gravity_potential(P, i, body, t, y)
    if kind == SPRING:
        return spring_potential(P, i, body, t, y)
    return 0.0


@kernel
def builtin_wrench(force_kind, force_params, body, t, y):
    """Total wrench of the lowered forces, about the centre of mass: a 6-tuple.

    Deliberately a call of its own, not inlined into the vector field: compiled once for every
    system type, it keeps the engine's compilation short; the torque-free system, whose speed
    matters most, does not call it at all."""
    Fx = 0.0
    Fy = 0.0
    Fz = 0.0
    tx = 0.0
    ty = 0.0
    tz = 0.0
    for i in range(force_kind.shape[0]):
        w = force_wrench_of(force_kind[i], force_params, i, body, t, y)
        Fx += w[0]
        Fy += w[1]
        Fz += w[2]
        tx += w[3]
        ty += w[4]
        tz += w[5]
    return Fx, Fy, Fz, tx, ty, tz


@kernel(inline=True)
def builtin_potential(force_kind, force_params, body, t, y):
    """Total potential energy of the lowered forces."""
    U = 0.0
    for i in range(force_kind.shape[0]):
        U += force_potential(force_kind[i], force_params, i, body, t, y)
    return U


@kernel
def force_wrench(kind, params, body, t, y):
    """``(F (3,), τ (3,))`` of one lowered force (``params`` its row) at the state ``y`` (18,),
    for Python callers."""
    P = params.reshape((1, params.shape[0]))
    w = force_wrench_of(kind, P, 0, body, t, y)
    return np.array([w[0], w[1], w[2]]), np.array([w[3], w[4], w[5]])


@kernel
def force_potential_of(kind, params, body, t, y):
    """Potential energy of one lowered force (``params`` its row) at ``y`` (18,), for Python
    callers."""
    P = params.reshape((1, params.shape[0]))
    return force_potential(kind, P, 0, body, t, y)


@kernel
def potential_energies(force_kind, force_params, body, t, Y):
    """Total potential energy of the lowered forces at each sample: t (n,), Y (n, 18) → (n,)."""
    out = np.empty(t.shape[0])
    for i in range(t.shape[0]):
        out[i] = builtin_potential(force_kind, force_params, body, t[i], Y[i])
    return out
