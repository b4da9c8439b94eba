"""The torque-free rotation in closed form (``docs/theory.md`` §1, "Torque-free body",
eqs (20)–(33); ``docs/torque_free.md``).

Every function works in the *sorted principal frame*: moments ascending ``I1 ≤ I2 ≤ I3``
(``I`` (3,)), ω in those axes. The Python layer (:mod:`poinsot.torquefree`) maps to and from
the body frame.

**The regime.** Everything the closed form needs of one initial ω is computed once by
:func:`regime_into` into a row of :data:`REGIME_SIZE` numbers (named offsets below):

* the invariants (30)–(31): ``k`` (``2k = Σ I_i ω_i²``) and ``a = |L|``;
* the case: :data:`SPHERICAL` (ω constant), :data:`FIXED` (a fixed point: ω constant),
  :data:`PRECESSION` (a symmetric body: ``π = Aω`` turns about the symmetry axis ``s`` at the
  rate ``−ν``, ``ν = (1/I_s − 1/I⊥) π_s``), or, for three distinct moments,
  :data:`AROUND_E3`, :data:`AROUND_E1` (the polhode circles e3 or e1) and :data:`SEPARATRIX`;
* for the last three, the Jacobi form ``ω = (σ1 α1 cn u, σ2 α2 sn u, σ3 α3 dn u)`` (pole e3)
  or ``(σ1 α1 dn u, σ2 α2 sn u, σ3 α3 cn u)`` (pole e1), ``u = u0 + λt``, parameter ``m`` and
  its complement ``m1`` (formed without cancellation, so the solution stays accurate
  arbitrarily close to the separatrix), and the quarter period ``K(m)``.

The invariants' combinations ``P3 = 2k I3 − a² ≥ 0`` and ``P1 = a² − 2k I1 ≥ 0`` are formed as
sums of squares (no cancellation), through ``hypot`` and after scaling ω by a power of two, so
that the solution is scale invariant over the whole floating-point range and components as
small as 1e-160 of the others keep their relative precision.

**The attitude.** z-x-z Euler angles ``(ψ, θ, φ)`` of the body relative to the invariable
frame (z along L), with pole the axis the polhode circles (e3, or e1 through the right-handed
relabelling ``(e3, −e2, e1)``): ``cos θ = π_pole/a``, ``tan φ = π_1'/π_2'`` and
``ψ(t) = a t/I_p + a (I_p − I_q)/(I_p I_q λ) [Π(u) − Π(u0)]``,
``Π(u) = ∫₀^u du/(1 − n sn² u)``, ``n = −I_p (I2 − I1)/(I1 (I3 − I2))`` (pole e3; swap 1 ↔ 3
for pole e1), n < 0 (Landau & Lifshitz, *Mechanics*, §37; Whittaker, *Analytical Dynamics*,
§69; re-derived, because published versions contain sign errors). Symmetric bodies:
``Q(t) = exp(t L̂/I⊥) Q0 exp(ν t ê_s)``; fixed points: ``Q0 exp(Ω t)``.
"""

from __future__ import annotations

import math

import numpy as np

from .elliptic import (
    ellipk_m1,
    first_kind_from_sn_cn,
    jacobi_reduced_scalar,
    third_kind_u_scalar,
)
from .jit import kernel
from .so3 import exp_so3_into, zxz_matrix_into

__all__ = [
    "AROUND_E1",
    "AROUND_E3",
    "ATTITUDE_SIZE",
    "CASE_NAMES",
    "FIXED",
    "NEAR_UNSTABLE_AXIS",
    "PRECESSION",
    "REGIME_SIZE",
    "SEPARATRIX",
    "SPHERICAL",
    "attitude_at_into",
    "attitude_setup_into",
    "exact_attitudes",
    "exact_omegas",
    "flip_interval_of",
    "flip_intervals",
    "omega_at",
    "period_of",
    "periods",
    "regime_into",
    "regimes",
]

# cases
SPHERICAL = 0
PRECESSION = 1
FIXED = 2
AROUND_E3 = 3
AROUND_E1 = 4
SEPARATRIX = 5
#: The polhode family of each case, as :meth:`poinsot.torquefree.FreeRigidBody.classify`
#: names it.
CASE_NAMES = ("spherical", "symmetric", "fixed point", "around e3", "around e1", "separatrix")

# the regime row
CASE = 0
ENERGY = 1
MOMENTUM = 2
ALPHA = 3  # 3 entries
LAM = 6
M = 7
M1 = 8
SIGNS = 9  # 3 entries
U0 = 12
POLE = 13
QUARTER = 14  # K(m)
NU = 15
AXIS = 16
I_PERP = 17
REGIME_SIZE = 18

# the attitude row (what the attitude needs beyond the regime)
P0 = 0  # 9 entries: the invariable frame → space, row-major
N_CHAR = 9
I_POLE = 10
I_OTHER = 11
PI_U0 = 12
ATTITUDE_SIZE = 13

#: ω within this relative distance of the intermediate axis is taken as that fixed point:
#: leaving it takes longer than ln(1e140)/σ ≈ 322/σ, and the invariants' differences that set
#: the orbit underflow in double precision.
NEAR_UNSTABLE_AXIS = 1e-140


@kernel
def regime_into(I, symmetry, w0, w1, w2, out):
    """Fill ``out`` (REGIME_SIZE,) with the regime of the motion from ``ω(0) = (w0, w1, w2)``
    (sorted principal frame; ``symmetry`` the code of
    :func:`poinsot.kernels.inertia.symmetry_code`). See the module docstring."""
    for j in range(REGIME_SIZE):
        out[j] = 0.0
    big = max(abs(w0), abs(w1), abs(w2))
    if symmetry == 3:
        out[CASE] = SPHERICAL
    elif big == 0.0:
        out[CASE] = FIXED
    if big == 0.0:
        return
    # scale ω by a power of two (exactly) so that squares neither underflow nor overflow
    e = math.frexp(big)[1]
    sc = math.ldexp(1.0, -e)
    x0 = w0 * sc
    x1 = w1 * sc
    x2 = w2 * sc
    p0 = I[0] * x0
    p1 = I[1] * x1
    p2 = I[2] * x2
    out[ENERGY] = math.ldexp(0.5 * (p0 * x0 + p1 * x1 + p2 * x2), 2 * e)
    out[MOMENTUM] = math.ldexp(math.sqrt(p0 * p0 + p1 * p1 + p2 * p2), e)
    if symmetry == 3:
        return
    if symmetry != 0:  # prolate (1): axis e1, I⊥ = I3; oblate (2): axis e3, I⊥ = I1
        s = 2 if symmetry == 2 else 0
        i_perp = I[0] if symmetry == 2 else I[2]
        ws = w2 if s == 2 else w0
        nu = (1.0 / I[s] - 1.0 / i_perp) * I[s] * ws
        transverse_zero = (w0 == 0.0 and w1 == 0.0) if s == 2 else (w1 == 0.0 and w2 == 0.0)
        out[CASE] = FIXED if (nu == 0.0 or transverse_zero) else PRECESSION
        out[NU] = nu
        out[AXIS] = s
        out[I_PERP] = i_perp
        return
    I1 = I[0]
    I2 = I[1]
    I3 = I[2]
    if max(abs(x0), abs(x2)) <= NEAR_UNSTABLE_AXIS * abs(x1):
        out[CASE] = FIXED
        return
    r13 = math.sqrt(I1 * (I3 - I1))
    r23 = math.sqrt(I2 * (I3 - I2))
    r12 = math.sqrt(I2 * (I2 - I1))
    r33 = math.sqrt(I3 * (I3 - I1))
    q3 = math.hypot(r13 * x0, r23 * x1)  # √P3, P3 = 2k I3 − a² (scaled)
    q1 = math.hypot(r12 * x1, r33 * x2)  # √P1, P1 = a² − 2k I1
    if q3 == 0.0 or q1 == 0.0:  # on e3 or on e1
        out[CASE] = FIXED
        return
    D2 = I3 * (I3 - I2) * x2 * x2 - I1 * (I2 - I1) * x0 * x0  # a² − 2k I2
    if D2 >= 0.0:  # around e3, or the separatrix (D2 = 0)
        a0 = q3 / r13
        a1 = q3 / r23
        a2 = q1 / r33
        lam = q1 * math.sqrt((I3 - I2) / (I1 * I2 * I3))
        ratio = q3 / q1
        m = (I2 - I1) / (I3 - I2) * ratio * ratio
        m1 = (I3 - I1) * D2 / ((I3 - I2) * q1 * q1)
        pole = 2
    else:  # around e1
        a0 = q3 / r13
        a1 = q1 / r12
        a2 = q1 / r33
        lam = q3 * math.sqrt((I2 - I1) / (I1 * I2 * I3))
        ratio = q1 / q3
        m = (I3 - I2) / (I2 - I1) * ratio * ratio
        m1 = (I3 - I1) * (-D2) / ((I2 - I1) * q3 * q3)
        pole = 0
    m = min(max(m, 0.0), 1.0)
    m1 = min(max(m1, 0.0), 1.0)
    if m1 < 1e-300:  # subnormal: the separatrix is the orbit to within O(m1)
        m = 1.0
        m1 = 0.0
    s1 = 1.0 if x0 > 0.0 else -1.0
    s3 = 1.0 if x2 > 0.0 else -1.0
    # Signs: the ODE needs σ1 = σ2 σ3. Off the separatrix cn takes both signs, so the sign of
    # the cn-component is +1 (absorbed in the phase); on the separatrix cn = sech u > 0 and
    # each of the four arcs keeps the signs of both ω1 and ω3.
    if pole == 2:
        if m1 != 0.0:
            s1 = 1.0
        sn0 = s1 * s3 * x1 / a1
        cn0 = s1 * x0 / a0
    else:
        if m1 != 0.0:
            s3 = 1.0
        sn0 = s1 * s3 * x1 / a1
        cn0 = s3 * x2 / a2
    out[U0] = first_kind_from_sn_cn(sn0, cn0, m, m1)
    out[CASE] = SEPARATRIX if m1 == 0.0 else (AROUND_E3 if pole == 2 else AROUND_E1)
    out[ALPHA] = math.ldexp(a0, e)
    out[ALPHA + 1] = math.ldexp(a1, e)
    out[ALPHA + 2] = math.ldexp(a2, e)
    out[LAM] = math.ldexp(lam, e)
    out[M] = m
    out[M1] = m1
    out[SIGNS] = s1
    out[SIGNS + 1] = s1 * s3
    out[SIGNS + 2] = s3
    out[POLE] = pole
    out[QUARTER] = ellipk_m1(m1)


@kernel(inline=True)
def _turn_about_axis(s, angle, x0, x1, x2):
    """The vector ``(x0, x1, x2)`` turned by ``angle`` about principal axis ``s``."""
    c = math.cos(angle)
    n = math.sin(angle)
    if s == 0:
        return x0, c * x1 - n * x2, n * x1 + c * x2
    if s == 1:
        return n * x2 + c * x0, x1, c * x2 - n * x0
    return c * x0 - n * x1, n * x0 + c * x1, x2


@kernel
def omega_at(I, reg, w0, w1, w2, t):
    """ω(t) (a 3-tuple, sorted principal frame) of the motion from ``(w0, w1, w2)`` with the
    regime ``reg`` (:func:`regime_into`)."""
    case = reg[CASE]
    if case == SPHERICAL or case == FIXED:
        return w0, w1, w2
    if case == PRECESSION:
        pi0, pi1, pi2 = _turn_about_axis(
            int(reg[AXIS]), -reg[NU] * t, I[0] * w0, I[1] * w1, I[2] * w2
        )
        return pi0 / I[0], pi1 / I[1], pi2 / I[2]
    sn, cn, dn, _, _ = jacobi_reduced_scalar(reg[U0] + reg[LAM] * t, reg[M], reg[M1], reg[QUARTER])
    if reg[POLE] == 2.0:
        return (
            reg[SIGNS] * reg[ALPHA] * cn,
            reg[SIGNS + 1] * reg[ALPHA + 1] * sn,
            reg[SIGNS + 2] * reg[ALPHA + 2] * dn,
        )
    return (
        reg[SIGNS] * reg[ALPHA] * dn,
        reg[SIGNS + 1] * reg[ALPHA + 1] * sn,
        reg[SIGNS + 2] * reg[ALPHA + 2] * cn,
    )


@kernel
def period_of(reg):
    """The period of ω(t): ``4K(m)/λ`` (three distinct moments), ``2π/|ν|`` (symmetric);
    ``inf`` on the separatrix, NaN where ω is constant (fixed points, spherical bodies)."""
    case = reg[CASE]
    if case == PRECESSION:
        return 2.0 * math.pi / abs(reg[NU])
    if case == AROUND_E1 or case == AROUND_E3:
        return 4.0 * reg[QUARTER] / reg[LAM]
    if case == SEPARATRIX:
        return math.inf
    return math.nan


@kernel
def flip_interval_of(reg):
    """Time between successive sign changes of ω2 (the tennis-racket flips): ``2K(m)/λ``;
    ``inf`` on the separatrix, NaN where there is no flip (symmetric bodies, fixed points)."""
    case = reg[CASE]
    if case == AROUND_E1 or case == AROUND_E3:
        return 2.0 * reg[QUARTER] / reg[LAM]
    if case == SEPARATRIX:
        return math.inf
    return math.nan


@kernel
def periods(regs):
    """:func:`period_of` of every regime row: (N, REGIME_SIZE) → (N,)."""
    out = np.empty(regs.shape[0])
    for i in range(regs.shape[0]):
        out[i] = period_of(regs[i])
    return out


@kernel
def flip_intervals(regs):
    """:func:`flip_interval_of` of every regime row: (N, REGIME_SIZE) → (N,)."""
    out = np.empty(regs.shape[0])
    for i in range(regs.shape[0]):
        out[i] = flip_interval_of(regs[i])
    return out


@kernel(inline=True)
def _relabelled_angles(pole, pi0, pi1, pi2):
    """``(θ, φ)`` of the body relative to the invariable frame from the body momentum ``π``:
    relabelled as ``(π3, −π2, π1)`` when the pole is e1."""
    if pole == 0.0:
        b0 = pi2
        b1 = -pi1
        b2 = pi0
    else:
        b0 = pi0
        b1 = pi1
        b2 = pi2
    return math.atan2(math.hypot(b0, b1), b2), math.atan2(b0, b1)


@kernel
def attitude_setup_into(I, reg, w0, w1, w2, Q0, out):
    """Fill ``out`` (ATTITUDE_SIZE,) with what the elliptic attitude needs beyond the regime,
    for ``Q(0) = Q0`` (3, 3) (sorted principal frame → space): the invariable frame ``P0``
    (``Q(t) = P0 Rzxz(ψ, θ, φ) B``), the characteristic ``n``, ``I_p``, ``I_q`` and
    ``Π(u0)``. Unused (zeros) outside the elliptic cases."""
    for j in range(ATTITUDE_SIZE):
        out[j] = 0.0
    case = reg[CASE]
    if case != AROUND_E1 and case != AROUND_E3 and case != SEPARATRIX:
        return
    I1 = I[0]
    I2 = I[1]
    I3 = I[2]
    pole = reg[POLE]
    if pole == 2.0:
        ip = I3
        iq = I1
        n = -I3 * (I2 - I1) / (I1 * (I3 - I2))
    else:
        ip = I1
        iq = I3
        n = -I1 * (I3 - I2) / (I3 * (I2 - I1))
    theta, phi = _relabelled_angles(pole, I1 * w0, I2 * w1, I3 * w2)
    R0 = np.empty((3, 3))
    zxz_matrix_into(0.0, theta, phi, R0)
    # P0 = Q0 Bᵀ R0ᵀ: Q(0) = Q0 with ψ(0) = 0
    QB = np.empty((3, 3))
    for r in range(3):
        if pole == 2.0:
            QB[r, 0] = Q0[r, 0]
            QB[r, 1] = Q0[r, 1]
            QB[r, 2] = Q0[r, 2]
        else:  # Bᵀ = B = [[0, 0, 1], [0, −1, 0], [1, 0, 0]]
            QB[r, 0] = Q0[r, 2]
            QB[r, 1] = -Q0[r, 1]
            QB[r, 2] = Q0[r, 0]
    for r in range(3):
        for c in range(3):
            out[P0 + 3 * r + c] = QB[r, 0] * R0[c, 0] + QB[r, 1] * R0[c, 1] + QB[r, 2] * R0[c, 2]
    out[N_CHAR] = n
    out[I_POLE] = ip
    out[I_OTHER] = iq
    out[PI_U0] = third_kind_u_scalar(n, reg[U0], reg[M], reg[M1], reg[QUARTER])


@kernel
def attitude_at_into(I, reg, att, w0, w1, w2, Q0, t, R, out):
    """``Q(t)`` (3, 3) into ``out``: the attitude (sorted principal frame → space) of the
    motion from ``ω(0) = (w0, w1, w2)``, ``Q(0) = Q0``, with the regime ``reg`` and the
    attitude row ``att`` (:func:`attitude_setup_into`); ``R`` (3, 3) is scratch space."""
    case = reg[CASE]
    if case == SPHERICAL or case == FIXED:
        exp_so3_into(t * w0, t * w1, t * w2, R)
        for r in range(3):
            for c in range(3):
                out[r, c] = Q0[r, 0] * R[0, c] + Q0[r, 1] * R[1, c] + Q0[r, 2] * R[2, c]
        return
    if case == PRECESSION:
        # Q(t) = exp(t L/I⊥) Q0 exp(ν t e_s), L = Q0 (I w) in space
        s = int(reg[AXIS])
        pi0 = I[0] * w0
        pi1 = I[1] * w1
        pi2 = I[2] * w2
        f = t / reg[I_PERP]
        L0 = f * (Q0[0, 0] * pi0 + Q0[0, 1] * pi1 + Q0[0, 2] * pi2)
        L1 = f * (Q0[1, 0] * pi0 + Q0[1, 1] * pi1 + Q0[1, 2] * pi2)
        L2 = f * (Q0[2, 0] * pi0 + Q0[2, 1] * pi1 + Q0[2, 2] * pi2)
        exp_so3_into(L0, L1, L2, R)
        # out = R Q0, then the body turn about e_s: columns (s+1, s+2) rotated by ν t
        for r in range(3):
            for c in range(3):
                out[r, c] = R[r, 0] * Q0[0, c] + R[r, 1] * Q0[1, c] + R[r, 2] * Q0[2, c]
        angle = reg[NU] * t
        cs = math.cos(angle)
        sn = math.sin(angle)
        a = (s + 1) % 3
        b = (s + 2) % 3
        for r in range(3):
            x = out[r, a]
            y = out[r, b]
            out[r, a] = cs * x + sn * y
            out[r, b] = -sn * x + cs * y
        return
    v0, v1, v2 = omega_at(I, reg, w0, w1, w2, t)
    pole = reg[POLE]
    theta, phi = _relabelled_angles(pole, I[0] * v0, I[1] * v1, I[2] * v2)
    ip = att[I_POLE]
    iq = att[I_OTHER]
    lam = reg[LAM]
    a = reg[MOMENTUM]
    u = reg[U0] + lam * t
    Pi = third_kind_u_scalar(att[N_CHAR], u, reg[M], reg[M1], reg[QUARTER]) - att[PI_U0]
    psi = a * t / ip + a * (ip - iq) / (ip * iq * lam) * Pi  # ψ(0) = 0
    zxz_matrix_into(psi, theta, phi, R)
    # out = P0 R B
    for r in range(3):
        x0 = (
            att[P0 + 3 * r] * R[0, 0]
            + att[P0 + 3 * r + 1] * R[1, 0]
            + att[P0 + 3 * r + 2] * R[2, 0]
        )
        x1 = (
            att[P0 + 3 * r] * R[0, 1]
            + att[P0 + 3 * r + 1] * R[1, 1]
            + att[P0 + 3 * r + 2] * R[2, 1]
        )
        x2 = (
            att[P0 + 3 * r] * R[0, 2]
            + att[P0 + 3 * r + 1] * R[1, 2]
            + att[P0 + 3 * r + 2] * R[2, 2]
        )
        if pole == 2.0:
            out[r, 0] = x0
            out[r, 1] = x1
            out[r, 2] = x2
        else:  # columns of (P0 R) B: (x2, −x1, x0)
            out[r, 0] = x2
            out[r, 1] = -x1
            out[r, 2] = x0


# --------------------------------------------------------------------------- batched, body frame
@kernel(inline=True)
def _to_sorted(S, W, i):
    """Row ``i`` of body-frame ω ``W`` in the sorted principal frame: ``Sᵀ ω``."""
    return (
        S[0, 0] * W[i, 0] + S[1, 0] * W[i, 1] + S[2, 0] * W[i, 2],
        S[0, 1] * W[i, 0] + S[1, 1] * W[i, 1] + S[2, 1] * W[i, 2],
        S[0, 2] * W[i, 0] + S[1, 2] * W[i, 1] + S[2, 2] * W[i, 2],
    )


@kernel
def regimes(I, S, symmetry, W):
    """The regimes (N, REGIME_SIZE) of the motions from the body-frame ω ``W`` (N, 3), for a
    body with sorted moments ``I`` and sorted axes ``S`` (columns, body coordinates)."""
    out = np.empty((W.shape[0], REGIME_SIZE))
    for i in range(W.shape[0]):
        w0, w1, w2 = _to_sorted(S, W, i)
        regime_into(I, symmetry, w0, w1, w2, out[i])
    return out


@kernel
def exact_omegas(I, S, symmetry, W, T):
    """ω(t) (N, n, 3), body frame, of the torque-free motions from the body-frame ω ``W``
    (N, 3), at the times ``T`` (n,) (from t = 0). One pass: regime, then every time."""
    N = W.shape[0]
    out = np.empty((N, T.shape[0], 3))
    reg = np.empty(REGIME_SIZE)
    for i in range(N):
        w0, w1, w2 = _to_sorted(S, W, i)
        regime_into(I, symmetry, w0, w1, w2, reg)
        for j in range(T.shape[0]):
            v0, v1, v2 = omega_at(I, reg, w0, w1, w2, T[j])
            for r in range(3):
                out[i, j, r] = S[r, 0] * v0 + S[r, 1] * v1 + S[r, 2] * v2
    return out


@kernel
def exact_attitudes(I, S, symmetry, W, Q0, T):
    """Q(t) (N, n, 3, 3) (body → space) of the torque-free motions from the body-frame ω
    ``W`` (N, 3) and attitudes ``Q0`` (N, 3, 3) or one shared (1, 3, 3), at the times ``T``."""
    N = W.shape[0]
    out = np.empty((N, T.shape[0], 3, 3))
    reg = np.empty(REGIME_SIZE)
    att = np.empty(ATTITUDE_SIZE)
    Q0s = np.empty((3, 3))
    R = np.empty((3, 3))
    Qs = np.empty((3, 3))
    for i in range(N):
        q = Q0[i if Q0.shape[0] > 1 else 0]
        for r in range(3):  # Q0 S: sorted principal frame → space
            for c in range(3):
                Q0s[r, c] = q[r, 0] * S[0, c] + q[r, 1] * S[1, c] + q[r, 2] * S[2, c]
        w0, w1, w2 = _to_sorted(S, W, i)
        regime_into(I, symmetry, w0, w1, w2, reg)
        attitude_setup_into(I, reg, w0, w1, w2, Q0s, att)
        for j in range(T.shape[0]):
            attitude_at_into(I, reg, att, w0, w1, w2, Q0s, T[j], R, Qs)
            for r in range(3):  # Q = Qs Sᵀ
                for c in range(3):
                    out[i, j, r, c] = Qs[r, 0] * S[c, 0] + Qs[r, 1] * S[c, 1] + Qs[r, 2] * S[c, 2]
    return out
