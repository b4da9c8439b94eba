"""Motion relative to a moving carrier frame (``docs/relative.md``; paper eqs (1)–(18)).

A body moves relative to a *carrier* frame that turns with the transport angular velocity
``ω_e`` and angular acceleration ``ε_e`` and whose origin accelerates by ``a_O``. Body-frame
components throughout, ``J`` the inertia about the centre of mass, ``ω_r`` the body's angular
velocity relative to the carrier:

* the transport inertia moment ``M_e = −J ε_e + Jω_e × ω_e`` (2): :func:`transport_moment_of`;
* the Coriolis inertia moment in its compact form ``M_c = 2 ω_r × (J' ω_e)`` (5), with the
  planar inertia tensor ``J' = ½ tr(J) 𝟙 − J`` (3)–(4)
  (:func:`poinsot.kernels.inertia.planar_inertia`):
  :func:`coriolis_moment_of`; its three-term form (2) :func:`coriolis_three_term_of` and its
  definition as a particle sum (6) :func:`coriolis_moment_particles`, the independent routes
  the tests compare it with;
* the compact relative Euler equation (11), in principal components (12):
  ``J ω̇_r = Jω_r × ω_r + M_e + M_c + M(F)`` (:func:`relative_rates`).

The relative state (:data:`RELATIVE_STATE_SIZE` = 33 components)::

    [r (3), v (3), Q_r (9), ω_r (3), Q_c (9), X_O (3), V_O (3)]

``r``, ``v`` the centre of mass relative to the carrier's origin and its velocity relative to
the carrier (carrier components); ``Q_r`` the attitude (body → carrier, row-major) and ``ω_r``
(body components; the principal frame inside the engine); ``Q_c`` the carrier's attitude
(carrier → inertial), integrated along with the body from ``Q̇_c = Q_c Ω_e``; ``X_O``, ``V_O``
the carrier origin's position and velocity (inertial). The carrier's *motion* at a time is the
9-tuple ``(ω_e, ε_e, a_O)`` in carrier components (:data:`MOTION_SIZE`): a piecewise polynomial
(:func:`carrier_motion_ppoly`; a constant is one of degree 0) or a compiled function of t.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel
from .layout import INV_MASS, INV_MOMENTS, MOMENTS, OMEGA_AT, Q_AT, R_AT, V_AT
from .rigid import attitude_rate, omega_dot_principal

__all__ = [
    "BALANCE_TRANSPORT",
    "CARRIER_Q_AT",
    "HOLD_COM",
    "MOTION_SIZE",
    "OPTIONS_SIZE",
    "ORIGIN_AT",
    "ORIGIN_V_AT",
    "RELATIVE_STATE_SIZE",
    "absolute_state_of",
    "absolute_states",
    "carrier_motion_ppoly",
    "carrier_motions_ppoly",
    "coriolis_moment",
    "coriolis_moment_of",
    "coriolis_moment_particles",
    "coriolis_moment_three_term",
    "coriolis_three_term_of",
    "planar_inertia_particles",
    "relative_rates",
    "transport_moment",
    "transport_moment_of",
]

RELATIVE_STATE_SIZE = 33
CARRIER_Q_AT = 18  #: the carrier's attitude Q_c (9, row-major), carrier → inertial
ORIGIN_AT = 27  #: the carrier origin's position X_O (3), inertial
ORIGIN_V_AT = 30  #: its velocity V_O (3), inertial
MOTION_SIZE = 9  #: (ω_e, ε_e, a_O), carrier components

# options (a float vector)
BALANCE_TRANSPORT = 0  #: 1.0: the physical moment cancels the transport moment, case (16)
HOLD_COM = 1  #: 1.0: the centre of mass is held at its place in the carrier (a gimbal mount)
OPTIONS_SIZE = 2


# --------------------------------------------------------------------------- the moments
@kernel(inline=True)
def _times(J, x0, x1, x2):
    """``J x`` (3-tuple) for J (3, 3)."""
    return (
        J[0, 0] * x0 + J[0, 1] * x1 + J[0, 2] * x2,
        J[1, 0] * x0 + J[1, 1] * x1 + J[1, 2] * x2,
        J[2, 0] * x0 + J[2, 1] * x1 + J[2, 2] * x2,
    )


@kernel(inline=True)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@kernel(inline=True)
def transport_moment_of(J, w0, w1, w2, e0, e1, e2):
    """The transport inertia moment ``M_e = −J ε_e + Jω_e × ω_e`` (paper eq. (2)) of one
    ``ω_e``, ``ε_e`` (body components); a 3-tuple."""
    j0, j1, j2 = _times(J, w0, w1, w2)
    c0, c1, c2 = _cross(j0, j1, j2, w0, w1, w2)
    k0, k1, k2 = _times(J, e0, e1, e2)
    return c0 - k0, c1 - k1, c2 - k2


@kernel(inline=True)
def coriolis_moment_of(J, r0, r1, r2, w0, w1, w2):
    """The Coriolis inertia moment in the compact form ``M_c = 2 ω_r × (J' ω_e)`` (paper eq.
    (5)), ``J' = ½ tr(J) 𝟙 − J`` the planar inertia tensor; a 3-tuple."""
    half = 0.5 * (J[0, 0] + J[1, 1] + J[2, 2])
    j0, j1, j2 = _times(J, w0, w1, w2)
    p0 = half * w0 - j0  # J' ω_e
    p1 = half * w1 - j1
    p2 = half * w2 - j2
    c0, c1, c2 = _cross(r0, r1, r2, p0, p1, p2)
    return 2.0 * c0, 2.0 * c1, 2.0 * c2


@kernel(inline=True)
def coriolis_three_term_of(J, r0, r1, r2, w0, w1, w2):
    """The Coriolis inertia moment in its three-term form
    ``M_c = Jω_r × ω_e + Jω_e × ω_r + J(ω_r × ω_e)`` (paper eq. (2)); a 3-tuple."""
    a0, a1, a2 = _times(J, r0, r1, r2)
    b0, b1, b2 = _times(J, w0, w1, w2)
    x0, x1, x2 = _cross(r0, r1, r2, w0, w1, w2)
    d0, d1, d2 = _times(J, x0, x1, x2)
    u0, u1, u2 = _cross(a0, a1, a2, w0, w1, w2)
    v0, v1, v2 = _cross(b0, b1, b2, r0, r1, r2)
    return u0 + v0 + d0, u1 + v1 + d1, u2 + v2 + d2


@kernel
def _vectors(a):
    return np.ascontiguousarray(np.asarray(a)).reshape((-1, 3)).astype(np.float64)


@kernel
def transport_moment(J, omega_e, epsilon_e):
    """``M_e = −J ε_e + Jω_e × ω_e`` (paper eq. (2)): J (3, 3), ``omega_e``, ``epsilon_e``
    (..., 3) in body components → (..., 3).

    Examples
    --------
    >>> import numpy as np
    >>> transport_moment(np.diag([1.0, 2.0, 3.0]), np.array([1.0, 1.0, 0.0]),
    ...                  np.zeros(3)).tolist()   # Jω_e × ω_e = (1, 2, 0) × (1, 1, 0)
    [0.0, 0.0, -1.0]
    """
    w = _vectors(omega_e)
    e = _vectors(epsilon_e)
    if w.shape[0] != e.shape[0]:
        raise ValueError("`omega_e` and `epsilon_e` must have the same shape")
    out = np.empty_like(w)
    for i in range(w.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = transport_moment_of(
            J, w[i, 0], w[i, 1], w[i, 2], e[i, 0], e[i, 1], e[i, 2]
        )
    return out.reshape(np.asarray(omega_e).shape)


@kernel
def coriolis_moment(J, omega_r, omega_e):
    """``M_c = 2 ω_r × (J' ω_e)`` (paper eq. (5)): J (3, 3), ``omega_r``, ``omega_e`` (..., 3)
    in body components → (..., 3).

    Examples
    --------
    >>> import numpy as np
    >>> coriolis_moment(np.diag([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 1.0]),
    ...                 np.array([1.0, 0.0, 0.0])).tolist()   # 2 e3 × (A' e1), A' = 2
    [0.0, 4.0, 0.0]
    """
    r = _vectors(omega_r)
    w = _vectors(omega_e)
    if w.shape[0] != r.shape[0]:
        raise ValueError("`omega_r` and `omega_e` must have the same shape")
    out = np.empty_like(w)
    for i in range(w.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = coriolis_moment_of(
            J, r[i, 0], r[i, 1], r[i, 2], w[i, 0], w[i, 1], w[i, 2]
        )
    return out.reshape(np.asarray(omega_r).shape)


@kernel
def coriolis_moment_three_term(J, omega_r, omega_e):
    """``M_c = Jω_r × ω_e + Jω_e × ω_r + J(ω_r × ω_e)`` (paper eq. (2)), (..., 3) → (..., 3)."""
    r = _vectors(omega_r)
    w = _vectors(omega_e)
    if w.shape[0] != r.shape[0]:
        raise ValueError("`omega_r` and `omega_e` must have the same shape")
    out = np.empty_like(w)
    for i in range(w.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = coriolis_three_term_of(
            J, r[i, 0], r[i, 1], r[i, 2], w[i, 0], w[i, 1], w[i, 2]
        )
    return out.reshape(np.asarray(omega_r).shape)


@kernel
def coriolis_moment_particles(masses, rho, omega_r, omega_e):
    """The definition of the Coriolis inertia moment (paper eq. (6)): the moment about the
    centre of mass of the Coriolis inertia forces ``−2 m ω_e × (ω_r × ρ)`` of the particles,
    ``M_c = −2 Σ m ρ × (ω_e × (ω_r × ρ))``. ``masses`` (N,), ``rho`` (N, 3) the particles from
    the centre of mass, ``omega_r``, ``omega_e`` (..., 3) body components → (..., 3)."""
    r = _vectors(omega_r)
    w = _vectors(omega_e)
    if w.shape[0] != r.shape[0]:
        raise ValueError("`omega_r` and `omega_e` must have the same shape")
    out = np.zeros_like(w)
    for i in range(w.shape[0]):
        for k in range(masses.shape[0]):
            v0, v1, v2 = _cross(r[i, 0], r[i, 1], r[i, 2], rho[k, 0], rho[k, 1], rho[k, 2])
            a0, a1, a2 = _cross(w[i, 0], w[i, 1], w[i, 2], v0, v1, v2)
            m0, m1, m2 = _cross(rho[k, 0], rho[k, 1], rho[k, 2], a0, a1, a2)
            out[i, 0] -= 2.0 * masses[k] * m0
            out[i, 1] -= 2.0 * masses[k] * m1
            out[i, 2] -= 2.0 * masses[k] * m2
    return out.reshape(np.asarray(omega_r).shape)


@kernel
def planar_inertia_particles(masses, rho):
    """The planar inertia tensor by its definition (paper eqs (3)–(4)), ``J' = Σ m ρ ρᵀ``:
    the planar moments ``Σ m x²``, … on the diagonal, the products ``Σ m x y``, … off it.
    ``masses`` (N,), ``rho`` (N, 3) from the centre of mass → (3, 3)."""
    out = np.zeros((3, 3))
    for k in range(masses.shape[0]):
        for a in range(3):
            for b in range(3):
                out[a, b] += masses[k] * rho[k, a] * rho[k, b]
    return out


# --------------------------------------------------------------------------- carrier motion
@kernel(inline=True)
def _interval(breaks, t):
    """The index i of the piece ``breaks[i] <= t < breaks[i + 1]``, clipped to the pieces (a
    time outside them uses the first or last piece, as ``scipy.interpolate.PPoly`` does)."""
    m = breaks.shape[0] - 1
    i = np.searchsorted(breaks, t, side="right") - 1
    if i < 0:
        i = 0
    if i > m - 1:
        i = m - 1
    return i


@kernel(inline=True)
def _ppoly_value(breaks, coeffs, t, col):
    """Value and first derivative of column ``col`` of a piecewise polynomial (scipy's
    ``PPoly`` layout: ``coeffs`` (k + 1, m, cols), highest power first), by Horner's rule."""
    i = _interval(breaks, t)
    x = t - breaks[i]
    k = coeffs.shape[0] - 1
    v = coeffs[0, i, col]
    d = 0.0
    for j in range(1, k + 1):
        d = d * x + v
        v = v * x + coeffs[j, i, col]
    return v, d


@kernel(inline=True)
def carrier_motion_ppoly(w_breaks, w_coeffs, a_breaks, a_coeffs, t):
    """The carrier's motion ``(ω_e, ε_e, a_O)`` (9-tuple, carrier components) at ``t``: ω_e a
    piecewise polynomial (``w_coeffs`` (k + 1, m, 3)) and ε_e its exact derivative; a_O
    another (``a_coeffs`` (k' + 1, m', 3)). A constant is one piece of degree 0."""
    w0, e0 = _ppoly_value(w_breaks, w_coeffs, t, 0)
    w1, e1 = _ppoly_value(w_breaks, w_coeffs, t, 1)
    w2, e2 = _ppoly_value(w_breaks, w_coeffs, t, 2)
    a0, _ = _ppoly_value(a_breaks, a_coeffs, t, 0)
    a1, _ = _ppoly_value(a_breaks, a_coeffs, t, 1)
    a2, _ = _ppoly_value(a_breaks, a_coeffs, t, 2)
    return w0, w1, w2, e0, e1, e2, a0, a1, a2


@kernel
def carrier_motions_ppoly(w_breaks, w_coeffs, a_breaks, a_coeffs, t):
    """:func:`carrier_motion_ppoly` at the times ``t`` (n,) → (n, 9)."""
    out = np.empty((t.shape[0], MOTION_SIZE))
    for i in range(t.shape[0]):
        m = carrier_motion_ppoly(w_breaks, w_coeffs, a_breaks, a_coeffs, t[i])
        for k in range(MOTION_SIZE):
            out[i, k] = m[k]
    return out


# --------------------------------------------------------------------------- the state
@kernel(inline=True)
def absolute_state_of(y, motion):
    """The absolute 18-state ``[R, V, Q, ω]`` of a relative state ``y`` (33,) under the
    carrier's ``motion`` (9-tuple), as an 18-tuple:

    ``R = X_O + Q_c r``, ``V = V_O + Q_c (v + ω_e × r)``, ``Q = Q_c Q_r``,
    ``ω = ω_r + Q_rᵀ ω_e`` (eq. (15): ω_e projected on the body axes)."""
    c = CARRIER_Q_AT
    q = Q_AT
    we0 = motion[0]
    we1 = motion[1]
    we2 = motion[2]
    r0 = y[R_AT]
    r1 = y[R_AT + 1]
    r2 = y[R_AT + 2]
    x0, x1, x2 = _cross(we0, we1, we2, r0, r1, r2)
    u0 = y[V_AT] + x0
    u1 = y[V_AT + 1] + x1
    u2 = y[V_AT + 2] + x2
    R0 = y[ORIGIN_AT] + y[c] * r0 + y[c + 1] * r1 + y[c + 2] * r2
    R1 = y[ORIGIN_AT + 1] + y[c + 3] * r0 + y[c + 4] * r1 + y[c + 5] * r2
    R2 = y[ORIGIN_AT + 2] + y[c + 6] * r0 + y[c + 7] * r1 + y[c + 8] * r2
    V0 = y[ORIGIN_V_AT] + y[c] * u0 + y[c + 1] * u1 + y[c + 2] * u2
    V1 = y[ORIGIN_V_AT + 1] + y[c + 3] * u0 + y[c + 4] * u1 + y[c + 5] * u2
    V2 = y[ORIGIN_V_AT + 2] + y[c + 6] * u0 + y[c + 7] * u1 + y[c + 8] * u2
    Q00 = y[c] * y[q] + y[c + 1] * y[q + 3] + y[c + 2] * y[q + 6]
    Q01 = y[c] * y[q + 1] + y[c + 1] * y[q + 4] + y[c + 2] * y[q + 7]
    Q02 = y[c] * y[q + 2] + y[c + 1] * y[q + 5] + y[c + 2] * y[q + 8]
    Q10 = y[c + 3] * y[q] + y[c + 4] * y[q + 3] + y[c + 5] * y[q + 6]
    Q11 = y[c + 3] * y[q + 1] + y[c + 4] * y[q + 4] + y[c + 5] * y[q + 7]
    Q12 = y[c + 3] * y[q + 2] + y[c + 4] * y[q + 5] + y[c + 5] * y[q + 8]
    Q20 = y[c + 6] * y[q] + y[c + 7] * y[q + 3] + y[c + 8] * y[q + 6]
    Q21 = y[c + 6] * y[q + 1] + y[c + 7] * y[q + 4] + y[c + 8] * y[q + 7]
    Q22 = y[c + 6] * y[q + 2] + y[c + 7] * y[q + 5] + y[c + 8] * y[q + 8]
    w0 = y[OMEGA_AT] + y[q] * we0 + y[q + 3] * we1 + y[q + 6] * we2
    w1 = y[OMEGA_AT + 1] + y[q + 1] * we0 + y[q + 4] * we1 + y[q + 7] * we2
    w2 = y[OMEGA_AT + 2] + y[q + 2] * we0 + y[q + 5] * we1 + y[q + 8] * we2
    return (R0, R1, R2, V0, V1, V2, Q00, Q01, Q02, Q10, Q11, Q12, Q20, Q21, Q22, w0, w1, w2)


@kernel
def absolute_states(Y, motions):
    """:func:`absolute_state_of` for relative states ``Y`` (n, 33) and the carrier's motions
    ``motions`` (n, 9) at the same times → (n, 18)."""
    out = np.empty((Y.shape[0], 18))
    for i in range(Y.shape[0]):
        m = motions[i]
        s = absolute_state_of(Y[i], (m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8]))
        for k in range(18):
            out[i, k] = s[k]
    return out


@kernel(inline=True)
def relative_rates(body, inertia, options, y, motion, Fx, Fy, Fz, tx, ty, tz):
    """``ẏ`` (33-tuple) of the relative state ``y`` (principal frame) under the carrier's
    ``motion`` (9-tuple, carrier components), the physical force ``F`` (inertial) and its
    moment ``τ`` about the centre of mass (principal frame); ``inertia`` is diag(A, B, C).

    * the compact relative Euler equation (11) in principal components (12):
      ``J ω̇_r = Jω_r × ω_r + M_e + M_c + M(F)``, ``M_e`` omitted when the physical moment
      balances it (case (16), ``options[BALANCE_TRANSPORT]``);
    * ``Q̇_r = Q_r Ω_r`` and ``Q̇_c = Q_c Ω_e`` (eq. (09) for the body and for the carrier);
    * the centre of mass relative to the carrier:
      ``M a_r = Q_cᵀ F − M (a_O + ε_e × r + ω_e × (ω_e × r) + 2 ω_e × v)``, or at rest in
      the carrier (``options[HOLD_COM]``, a gimbal mount);
    * the carrier's origin: ``Ẋ_O = V_O``, ``V̇_O = Q_c a_O``.
    """
    q = Q_AT
    c = CARRIER_Q_AT
    we0, we1, we2, ee0, ee1, ee2, ao0, ao1, ao2 = motion
    # ω_e and ε_e on the body axes (eq. (15)): Q_rᵀ ω_e
    wb0 = y[q] * we0 + y[q + 3] * we1 + y[q + 6] * we2
    wb1 = y[q + 1] * we0 + y[q + 4] * we1 + y[q + 7] * we2
    wb2 = y[q + 2] * we0 + y[q + 5] * we1 + y[q + 8] * we2
    eb0 = y[q] * ee0 + y[q + 3] * ee1 + y[q + 6] * ee2
    eb1 = y[q + 1] * ee0 + y[q + 4] * ee1 + y[q + 7] * ee2
    eb2 = y[q + 2] * ee0 + y[q + 5] * ee1 + y[q + 8] * ee2
    wr0 = y[OMEGA_AT]
    wr1 = y[OMEGA_AT + 1]
    wr2 = y[OMEGA_AT + 2]
    m0, m1, m2 = coriolis_moment_of(inertia, wr0, wr1, wr2, wb0, wb1, wb2)
    if options[BALANCE_TRANSPORT] == 0.0:
        t0, t1, t2 = transport_moment_of(inertia, wb0, wb1, wb2, eb0, eb1, eb2)
        m0 += t0
        m1 += t1
        m2 += t2
    d0, d1, d2 = omega_dot_principal(
        body[MOMENTS], body[MOMENTS + 1], body[MOMENTS + 2],
        body[INV_MOMENTS], body[INV_MOMENTS + 1], body[INV_MOMENTS + 2],
        wr0, wr1, wr2, tx + m0, ty + m1, tz + m2,
    )  # fmt: skip
    ar = attitude_rate(
        y[q], y[q + 1], y[q + 2], y[q + 3], y[q + 4], y[q + 5], y[q + 6], y[q + 7], y[q + 8],
        wr0, wr1, wr2,
    )  # fmt: skip
    ac = attitude_rate(
        y[c], y[c + 1], y[c + 2], y[c + 3], y[c + 4], y[c + 5], y[c + 6], y[c + 7], y[c + 8],
        we0, we1, we2,
    )  # fmt: skip
    # the carrier origin's acceleration, inertial: Q_c a_O
    g0 = y[c] * ao0 + y[c + 1] * ao1 + y[c + 2] * ao2
    g1 = y[c + 3] * ao0 + y[c + 4] * ao1 + y[c + 5] * ao2
    g2 = y[c + 6] * ao0 + y[c + 7] * ao1 + y[c + 8] * ao2
    if options[HOLD_COM] != 0.0:
        r0 = r1 = r2 = 0.0
        v0 = v1 = v2 = 0.0
    else:
        r0 = y[V_AT]
        r1 = y[V_AT + 1]
        r2 = y[V_AT + 2]
        im = body[INV_MASS]
        f0 = (y[c] * Fx + y[c + 3] * Fy + y[c + 6] * Fz) * im  # Q_cᵀ F / M
        f1 = (y[c + 1] * Fx + y[c + 4] * Fy + y[c + 7] * Fz) * im
        f2 = (y[c + 2] * Fx + y[c + 5] * Fy + y[c + 8] * Fz) * im
        p0 = y[R_AT]
        p1 = y[R_AT + 1]
        p2 = y[R_AT + 2]
        x0, x1, x2 = _cross(ee0, ee1, ee2, p0, p1, p2)  # Euler: ε_e × r
        n0, n1, n2 = _cross(we0, we1, we2, p0, p1, p2)
        u0, u1, u2 = _cross(we0, we1, we2, n0, n1, n2)  # centripetal: ω_e × (ω_e × r)
        k0, k1, k2 = _cross(we0, we1, we2, r0, r1, r2)  # Coriolis: ω_e × v
        v0 = f0 - ao0 - x0 - u0 - 2.0 * k0
        v1 = f1 - ao1 - x1 - u1 - 2.0 * k1
        v2 = f2 - ao2 - x2 - u2 - 2.0 * k2
    return (
        r0, r1, r2, v0, v1, v2,
        ar[0], ar[1], ar[2], ar[3], ar[4], ar[5], ar[6], ar[7], ar[8], d0, d1, d2,
        ac[0], ac[1], ac[2], ac[3], ac[4], ac[5], ac[6], ac[7], ac[8],
        y[ORIGIN_V_AT], y[ORIGIN_V_AT + 1], y[ORIGIN_V_AT + 2], g0, g1, g2,
    )  # fmt: skip
