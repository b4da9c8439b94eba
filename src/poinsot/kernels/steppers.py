"""The integrators' steps: pure functions of (system, time, state, step), compiled.

Each step reads a state and writes the next one into a preallocated array; it keeps nothing
between calls (diffrax's "pure step"). Every driver (compiled or Python, single body or
ensemble) calls these same functions. The methods, by code (:data:`METHOD_CODES`):

* ``erk_step``: an explicit Runge–Kutta method given by its tableau (RK4 and any user tableau).
* ``rkmk_step``: Runge–Kutta–Munthe-Kaas on R⁹ × SO(3): the attitude advances as
  ``Q = Q_n exp(θ̂)`` with ``θ̇ = dexp⁻¹_{−θ}(ω)``, so every Q is a product of exact rotations
  (Munthe-Kaas 1999, BIT 39; Iserles et al. 2000, Acta Numerica §5).
* ``splitting_step``: kick–drift–kick, the exact free-rotor flow between two half kicks of the
  forces (Dullweber, Leimkuhler & McLachlan 1997, J. Chem. Phys. 107). It works on the state
  ``[R, V, Q, π]`` (body momentum in place of ω, so |L| is not disturbed by ω ↔ π round trips):
  see :func:`solver_init_into` and :func:`solver_output_into`.
* ``dop853_step``: Dormand–Prince 8(5,3) with its 5th/3rd-order error estimate
  (:func:`dop853_error_norm`) and 7th-order dense output (:func:`dop853_dense_into`,
  :func:`dop853_interpolate_into`); step-size control by :func:`step_size_factor`.
"""

from __future__ import annotations

import math

from .jit import kernel
from .layout import (
    HAS_PIVOT,
    INV_MASS,
    INV_MOMENTS,
    MOMENTS,
    OMEGA_AT,
    Q_AT,
    R_AT,
    STATE_SIZE,
    V_AT,
)
from .rigid import free_rotor_step_into, project_onto_pivot
from .so3 import dexpinv3, exp_so3_into
from .systems import body_parameters, rates, state_size, vector_field, wrench
from .tableaux import (
    DOP853_A,
    DOP853_C,
    DOP853_D,
    DOP853_E3,
    DOP853_E5,
    DOP853_STAGES,
    DOP853_STAGES_EXTENDED,
)
from .tuples import tuple_axpy, tuple_rk4_combine

__all__ = [
    "ATOL",
    "CONTROL_SIZE",
    "DOP853",
    "ERK",
    "FIRST_STEP",
    "MAX_FACTOR",
    "MAX_STEP",
    "METHOD_CODES",
    "MIN_FACTOR",
    "RK4",
    "RKMK",
    "RTOL",
    "SAFETY",
    "SPLITTING",
    "dop853_dense_into",
    "dop853_error_norm",
    "dop853_interpolate_into",
    "dop853_step",
    "erk_step",
    "evaluate",
    "hermite_interpolate_into",
    "initial_step_size",
    "rk4_tuple_step",
    "rkmk_step",
    "solver_init_into",
    "solver_output_into",
    "splitting_step",
    "step_size_factor",
]

# method codes (the compiled drivers branch on them)
RK4 = 0  #: classical RK4 with its tableau frozen into the code
ERK = 1  #: any explicit Runge–Kutta tableau passed at run time
RKMK = 2  #: Runge–Kutta–Munthe-Kaas with the tableau passed at run time
SPLITTING = 3  #: kick–drift–kick with the exact free-rotor flow
DOP853 = 4  #: adaptive Dormand–Prince 8(5,3)
METHOD_CODES = {"rk4": RK4, "erk": ERK, "rkmk": RKMK, "splitting": SPLITTING, "dop853": DOP853}

# step-size controller parameters (the float vector ``control``)
RTOL = 0
ATOL = 1
SAFETY = 2
MIN_FACTOR = 3
MAX_FACTOR = 4
MAX_STEP = 5
FIRST_STEP = 6  #: 0 selects the first step automatically (Hairer, Nørsett & Wanner §II.4)
CONTROL_SIZE = 7


# --------------------------------------------------------------------------- one evaluation
@kernel
def evaluate(system, t, y, out):
    """``out = ẏ(t, y)`` as a call of its own, for the drivers' cold paths (the first
    derivative, and the derivative after a projection): the steps inline the vector field in
    their one hot call site, and every inlined copy costs seconds of compilation."""
    vector_field(system, t, y, out)


# --------------------------------------------------------------------------- explicit RK
@kernel(inline=True)
def erk_step(system, A, B, C, t, y, h, K, ytmp, out):
    """One step of the explicit Runge–Kutta method (A, B, C): stages
    ``k_i = f(t + C_i h, y + h Σ_j A_ij k_j)``, result ``y + h Σ_i B_i k_i`` in ``out``.

    ``K`` (s, n) receives the stage derivatives, ``ytmp`` (n,) is work space.
    """
    s = B.shape[0]
    n = state_size(system, y)
    for i in range(s):
        for idx in range(n):
            acc = 0.0
            for m in range(i):
                acc += A[i, m] * K[m, idx]
            ytmp[idx] = y[idx] + h * acc
        vector_field(system, t + C[i] * h, ytmp, K[i])
    for idx in range(n):
        acc = 0.0
        for i in range(s):
            acc += B[i] * K[i, idx]
        out[idx] = y[idx] + h * acc


@kernel(inline=True)
def rk4_tuple_step(system, t, y, h, lane):
    """One step of classical RK4 for member ``lane`` of a rigid-body system, on its state held
    as a tuple (in registers): the tableau :data:`~poinsot.kernels.tableaux.RK4_A`, ``RK4_B``,
    ``RK4_C``, whose only non-zero ``A`` entries lie on the first subdiagonal, written for that
    pattern::

        k1 = f(t, y),  k2 = f(t + h/2, y + h/2 k1),  k3 = f(t + h/2, y + h/2 k2),
        k4 = f(t + h, y + h k3),  y + h/6 (k1 + 2 k2 + 2 k3 + k4)

    It exists for speed alone: on registers, with the loop over an ensemble's members around it,
    the compiler vectorises the step across members. The tests check it against
    :func:`erk_step` with the RK4 tableau to round-off.
    """
    half = 0.5 * h
    k1 = rates(system, t, y, lane)
    k2 = rates(system, t + half, tuple_axpy(y, half, k1), lane)
    k3 = rates(system, t + half, tuple_axpy(y, half, k2), lane)
    k4 = rates(system, t + h, tuple_axpy(y, h, k3), lane)
    return tuple_rk4_combine(y, h / 6.0, k1, k2, k3, k4)


# --------------------------------------------------------------------------- Lie group
@kernel(inline=True)
def _rotate_attitude_into(y, E, out):
    """``Q_out = Q_y E`` on the attitude blocks of two states."""
    for r in range(3):
        q0 = y[Q_AT + 3 * r]
        q1 = y[Q_AT + 3 * r + 1]
        q2 = y[Q_AT + 3 * r + 2]
        for k in range(3):
            out[Q_AT + 3 * r + k] = q0 * E[0, k] + q1 * E[1, k] + q2 * E[2, k]


@kernel(inline=True)
def rkmk_step(system, A, B, C, t, y, h, K, ytmp, kth, E, out):
    """One Runge–Kutta–Munthe-Kaas step of the rigid-body state with tableau (A, B, C).

    ``R, V, ω`` follow the tableau in their vector space; the attitude follows it in the Lie
    algebra: ``θ_i = h Σ_j A_ij κ_j``, ``Q_i = Q exp(θ̂_i)``, ``κ_i = dexp⁻¹_{−θ_i}(ω_i)``, and
    ``Q_new = Q exp(h Σ B_i κ_i)``. Work space: ``K`` (s, n), ``ytmp`` (n,), ``kth`` (s, 3),
    ``E`` (3, 3).
    """
    s = B.shape[0]
    n = state_size(system, y)
    for i in range(s):
        for idx in range(n):
            acc = 0.0
            for m in range(i):
                acc += A[i, m] * K[m, idx]
            ytmp[idx] = y[idx] + h * acc
        th0 = 0.0
        th1 = 0.0
        th2 = 0.0
        for m in range(i):
            th0 += A[i, m] * kth[m, 0]
            th1 += A[i, m] * kth[m, 1]
            th2 += A[i, m] * kth[m, 2]
        th0 *= h
        th1 *= h
        th2 *= h
        exp_so3_into(th0, th1, th2, E)
        _rotate_attitude_into(y, E, ytmp)
        vector_field(system, t + C[i] * h, ytmp, K[i])
        k0, k1, k2 = dexpinv3(
            -th0, -th1, -th2, ytmp[OMEGA_AT], ytmp[OMEGA_AT + 1], ytmp[OMEGA_AT + 2]
        )
        kth[i, 0] = k0
        kth[i, 1] = k1
        kth[i, 2] = k2
    for idx in range(n):
        acc = 0.0
        for i in range(s):
            acc += B[i] * K[i, idx]
        out[idx] = y[idx] + h * acc
    th0 = 0.0
    th1 = 0.0
    th2 = 0.0
    for i in range(s):
        th0 += B[i] * kth[i, 0]
        th1 += B[i] * kth[i, 1]
        th2 += B[i] * kth[i, 2]
    exp_so3_into(h * th0, h * th1, h * th2, E)
    _rotate_attitude_into(y, E, out)


# --------------------------------------------------------------------------- splitting
@kernel(inline=True)
def _momentum_to_velocity(body, z, y):
    """``y`` = ``z`` with ω = π/I in the ω slot (zero along a zero moment)."""
    for idx in range(STATE_SIZE):
        y[idx] = z[idx]
    for k in range(3):
        y[OMEGA_AT + k] = z[OMEGA_AT + k] * body[INV_MOMENTS + k]


@kernel(inline=True)
def _kick(system, body, t, z, h, ytmp):
    """Momentum kick by the forces over ``h``, in place: ``V += h F/M`` (a free body; about a
    pivot its reaction balances F) and ``π += h τ``."""
    _momentum_to_velocity(body, z, ytmp)
    Fx, Fy, Fz, tx, ty, tz = wrench(system, t, ytmp)
    if body[HAS_PIVOT] == 0.0:
        c = h * body[INV_MASS]
        z[V_AT] += c * Fx
        z[V_AT + 1] += c * Fy
        z[V_AT + 2] += c * Fz
    z[OMEGA_AT] += h * tx
    z[OMEGA_AT + 1] += h * ty
    z[OMEGA_AT + 2] += h * tz


@kernel(inline=True)
def _slave_to_pivot(body, z, ytmp):
    """About a pivot, reset ``R, V`` of the momentum state ``z`` from its attitude and ω."""
    _momentum_to_velocity(body, z, ytmp)
    project_onto_pivot(body, ytmp)
    for k in range(3):
        z[R_AT + k] = ytmp[R_AT + k]
        z[V_AT + k] = ytmp[V_AT + k]


@kernel(inline=True)
def splitting_step(system, t, z, h, ytmp, E, P, out):
    """One kick–drift–kick step on the momentum state ``z = [R, V, Q, π]`` (principal frame).

    ``kick(h/2) ∘ drift(h) ∘ kick(h/2)``: the drift is the exact free rotor
    (:func:`~poinsot.kernels.rigid.free_rotor_step_into`) and ``R += h V`` (or, about a pivot,
    ``R, V`` slaved to the attitude). Second order and symplectic for forces that depend on
    ``(t, R, Q)`` only; torque-free it keeps ``|L|``, the spatial ``L`` and ``QᵀQ = I`` to
    round-off. Work space: ``ytmp`` (18,), ``E``, ``P`` (3, 3).
    """
    body = body_parameters(system)
    for idx in range(STATE_SIZE):
        out[idx] = z[idx]
    for half in range(2):
        _kick(system, body, t + half * h, out, 0.5 * h, ytmp)
        if half == 0:
            free_rotor_step_into(body, out, h, E, P)
            if body[HAS_PIVOT] == 0.0:
                for k in range(3):
                    out[R_AT + k] += h * out[V_AT + k]
    if body[HAS_PIVOT] != 0.0:
        _slave_to_pivot(body, out, ytmp)


@kernel(inline=True)
def solver_init_into(method, system, y, z):
    """The solver's state from the system's state: ``z = y``, except for the splitting method,
    which carries the body momentum ``π = I ω`` in place of ω."""
    for idx in range(y.shape[0]):
        z[idx] = y[idx]
    if method == SPLITTING:
        body = body_parameters(system)
        for k in range(3):
            z[OMEGA_AT + k] = body[MOMENTS + k] * y[OMEGA_AT + k]


@kernel(inline=True)
def solver_output_into(method, system, z, y):
    """The system's state from the solver's (the inverse of :func:`solver_init_into`)."""
    if method == SPLITTING:
        _momentum_to_velocity(body_parameters(system), z, y)
    else:
        for idx in range(z.shape[0]):
            y[idx] = z[idx]


# --------------------------------------------------------------------------- DOP853
@kernel(inline=True)
def dop853_step(system, t, y, f, h, K, ytmp, out_y, out_f):
    """One Dormand–Prince 8(5,3) step from ``(t, y)`` with ``f = ẏ(t, y)`` (first same as last).

    ``out_y`` receives the 8th-order solution and ``out_f`` its derivative; ``K``
    (DOP853_STAGES_EXTENDED, n) keeps the 12 stages and ``out_f`` (row 12) for
    :func:`dop853_error_norm` and :func:`dop853_dense_into`.
    """
    n = state_size(system, y)
    for idx in range(n):
        K[0, idx] = f[idx]
    for s in range(1, DOP853_STAGES + 1):
        # rows 1–11: the stages; row 12: the derivative at the new point (B is row 12 of A)
        for idx in range(n):
            acc = 0.0
            for m in range(s):
                acc += DOP853_A[s, m] * K[m, idx]
            ytmp[idx] = y[idx] + h * acc
        if s == DOP853_STAGES:
            for idx in range(n):
                out_y[idx] = ytmp[idx]
        vector_field(system, t + DOP853_C[s] * h, ytmp, K[s])
    for idx in range(n):
        out_f[idx] = K[DOP853_STAGES, idx]


@kernel(inline=True)
def dop853_error_norm(K, h, y, y_new, rtol, atol):
    """The scaled error of the last DOP853 step: Hairer's combination of the 5th- and
    3rd-order estimators, ``|h| Σe5² / √((Σe5² + 0.01 Σe3²) n)`` with ``e = (Σ_i E_i k_i)/sc``,
    ``sc = atol + rtol max(|y|, |y_new|)``. A step is accepted when it is below 1."""
    n = y.shape[0]
    e5 = 0.0
    e3 = 0.0
    for idx in range(n):
        scale = atol + max(abs(y[idx]), abs(y_new[idx])) * rtol
        a5 = 0.0
        a3 = 0.0
        for i in range(DOP853_STAGES + 1):
            a5 += DOP853_E5[i] * K[i, idx]
            a3 += DOP853_E3[i] * K[i, idx]
        a5 /= scale
        a3 /= scale
        e5 += a5 * a5
        e3 += a3 * a3
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * n)


@kernel
def dop853_dense_into(system, t_old, h, y_old, y, f, K, ytmp, F):
    """The coefficients ``F`` (7, n) of the 7th-order interpolant over the last step
    ``[t_old, t_old + h]`` from ``y_old`` to ``y`` (``f = ẏ`` at the end): three more stages
    (rows 13–15 of ``K``) and the dense-output matrix ``D``."""
    n = state_size(system, y)
    for s in range(DOP853_STAGES + 1, DOP853_STAGES_EXTENDED):
        for idx in range(n):
            acc = 0.0
            for m in range(s):
                acc += DOP853_A[s, m] * K[m, idx]
            ytmp[idx] = y_old[idx] + h * acc
        vector_field(system, t_old + DOP853_C[s] * h, ytmp, K[s])
    for idx in range(n):
        dy = y[idx] - y_old[idx]
        F[0, idx] = dy
        F[1, idx] = h * K[0, idx] - dy
        F[2, idx] = 2.0 * dy - h * (f[idx] + K[0, idx])
        for r in range(4):
            acc = 0.0
            for s in range(DOP853_STAGES_EXTENDED):
                acc += DOP853_D[r, s] * K[s, idx]
            F[3 + r, idx] = h * acc


@kernel(inline=True)
def dop853_interpolate_into(F, y_old, x, out):
    """The DOP853 interpolant at the fraction ``x`` ∈ [0, 1] of the step, into ``out``:
    ``y_old + x(F0 + (1−x)(F1 + x(F2 + (1−x)(F3 + …))))``."""
    n = y_old.shape[0]
    p = F.shape[0]
    for idx in range(n):
        acc = 0.0
        for i in range(p):
            acc += F[p - 1 - i, idx]
            acc *= x if i % 2 == 0 else 1.0 - x
        out[idx] = y_old[idx] + acc


@kernel(inline=True)
def hermite_interpolate_into(y0, f0, y1, f1, h, x, out):
    """Cubic Hermite interpolant of a step (third order), at the fraction ``x`` ∈ [0, 1]."""
    x2 = x * x
    x3 = x2 * x
    h00 = 2.0 * x3 - 3.0 * x2 + 1.0
    h10 = x3 - 2.0 * x2 + x
    h01 = -2.0 * x3 + 3.0 * x2
    h11 = x3 - x2
    for idx in range(y0.shape[0]):
        out[idx] = h00 * y0[idx] + h10 * h * f0[idx] + h01 * y1[idx] + h11 * h * f1[idx]


# --------------------------------------------------------------------------- step size
@kernel(inline=True)
def step_size_factor(error_norm, error_order, rejected, control):
    """The standard controller (Hairer, Nørsett & Wanner §II.4): the next step is the last
    one times ``safety · err^(−1/(q+1))``, clipped to ``[min_factor, max_factor]`` (and not
    above 1 right after a rejection); ``q`` the order of the error estimator."""
    exponent = -1.0 / (error_order + 1.0)
    if error_norm < 1.0:
        if error_norm == 0.0:
            factor = control[MAX_FACTOR]
        else:
            factor = min(control[MAX_FACTOR], control[SAFETY] * error_norm**exponent)
        if rejected:
            factor = min(1.0, factor)
        return factor
    return max(control[MIN_FACTOR], control[SAFETY] * error_norm**exponent)


@kernel
def initial_step_size(system, t0, y0, f0, t_end, order, control, ytmp, ftmp):
    """An empirical first step (Hairer, Nørsett & Wanner §II.4, as SciPy's
    ``select_initial_step``): ``h0 = 0.01 |y0|/|f0|`` in the scaled RMS norm, then
    ``h1 = (0.01/max(|f0|, |f'|))^(1/(q+1))``, the smaller of ``100 h0``, ``h1``, the interval
    and ``max_step``. One more evaluation of the vector field."""
    n = state_size(system, y0)
    interval = abs(t_end - t0)
    if interval == 0.0:
        return 0.0
    rtol = control[RTOL]
    atol = control[ATOL]
    d0 = 0.0
    d1 = 0.0
    for idx in range(n):
        scale = atol + abs(y0[idx]) * rtol
        d0 += (y0[idx] / scale) ** 2
        d1 += (f0[idx] / scale) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, interval)
    for idx in range(n):
        ytmp[idx] = y0[idx] + h0 * f0[idx]
    vector_field(system, t0 + h0, ytmp, ftmp)
    d2 = 0.0
    for idx in range(n):
        scale = atol + abs(y0[idx]) * rtol
        d2 += ((ftmp[idx] - f0[idx]) / scale) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1.0))
    return min(100.0 * h0, h1, interval, control[MAX_STEP])
