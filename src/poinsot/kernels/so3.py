"""SO(3) and unit-quaternion kernels, compiled; batched over any leading axes.

Conventions (used throughout poinsot):

* ``hat(w) @ v == cross(w, v)``; ``vee`` is its inverse, with ``vee(B) = (−B23, B13, −B12)``
  for any skew ``B`` as in ``docs/theory.md`` §1 (0-based: ``(B[2,1], B[0,2], B[1,0])``).
* Quaternions are **scalar first**, ``q = (w, x, y, z)``, Hamilton product, and act on vectors
  as ``q v q*`` (active rotation). ``matrix_to_quat`` returns the representative with ``w ≥ 0``.
* Rotation vectors ``θ n`` have ``0 ≤ θ ≤ π``.

Each formula is written once, in a ``*_into`` kernel that reads one item and writes one output
(no allocation: the integrators call these inside their step). The public batched functions
(``exp_so3``, ``quat_multiply``, …) take ``(..., 3)``/``(..., 4)``/``(..., 3, 3)`` arrays and
loop over the items. Near the singular angles the formulas switch to Taylor series (θ → 0), and
the logarithm goes through a quaternion extracted by Shepperd's method, which stays accurate
near θ = π where ``arccos((tr R − 1)/2)`` loses half the digits.

We do not route these through :class:`scipy.spatial.transform.Rotation`: the integrators call
them on single vectors inside compiled loops, and Rotation lacks ``dexp⁻¹``.
``tests/kernels/test_so3.py`` checks them against Rotation.
"""

from __future__ import annotations

import math

import numpy as np

from .jit import accepts_sequences, kernel

__all__ = [
    "axis_rotation",
    "dexpinv",
    "dexpinv3",
    "exp_so3",
    "exp_so3_into",
    "hat",
    "hat_into",
    "log_so3",
    "matrix_to_quat",
    "matrix_to_quat_into",
    "quat_conjugate",
    "quat_multiply",
    "quat_multiply_into",
    "quat_normalize",
    "quat_rotate",
    "quat_to_matrix",
    "quat_to_matrix_into",
    "quat_to_rotvec",
    "quat_to_rotvec_into",
    "rodrigues",
    "rotvec_to_quat",
    "rotvec_to_quat_into",
    "vee",
    "zxz_angle_rates",
    "zxz_body_rates",
    "zxz_matrix_into",
]

#: Below this angle the closed forms are replaced by Taylor series (errors ~θ^6 ≪ 1e-16).
SMALL_ANGLE = 1e-4


@kernel
def _items(a, k):
    """``a`` (..., k) as a contiguous (n, k) array of float64."""
    if a.shape[-1] != k:
        raise ValueError("the last axis has the wrong length for this kernel")
    return np.ascontiguousarray(a).reshape((-1, k)).astype(np.float64)


# --------------------------------------------------------------------------- hat and vee
@kernel(inline=True)
def hat_into(w, out):
    """``out = hat(w)`` for one vector (3,) → (3, 3): ``hat(w) v = w × v``."""
    out[0, 0] = 0.0
    out[0, 1] = -w[2]
    out[0, 2] = w[1]
    out[1, 0] = w[2]
    out[1, 1] = 0.0
    out[1, 2] = -w[0]
    out[2, 0] = -w[1]
    out[2, 1] = w[0]
    out[2, 2] = 0.0


@accepts_sequences
@kernel
def hat(w):
    """Skew matrices of ``w``: ``hat(w) @ v = w × v``. Shape (..., 3) → (..., 3, 3).

    Examples
    --------
    >>> import numpy as np
    >>> hat(np.array([1.0, 2.0, 3.0])) @ np.array([0.0, 0.0, 1.0])
    array([ 2., -1.,  0.])
    """
    w = np.asarray(w)
    items = _items(w, 3)
    out = np.empty((items.shape[0], 3, 3))
    for i in range(items.shape[0]):
        hat_into(items[i], out[i])
    return out.reshape(w.shape[:-1] + (3, 3))


@accepts_sequences
@kernel
def vee(B):
    """Vector of the skew part of ``B``, the inverse of :func:`hat`. (..., 3, 3) → (..., 3).

    ``vee(B) = vee((B − Bᵀ)/2)``, so round-off in ``B`` does not bias the result.
    """
    B = np.asarray(B)
    items = np.ascontiguousarray(B).reshape((-1, 3, 3)).astype(np.float64)
    out = np.empty((items.shape[0], 3))
    for i in range(items.shape[0]):
        M = items[i]
        out[i, 0] = 0.5 * (M[2, 1] - M[1, 2])
        out[i, 1] = 0.5 * (M[0, 2] - M[2, 0])
        out[i, 2] = 0.5 * (M[1, 0] - M[0, 1])
    return out.reshape(B.shape[:-2] + (3,))


# --------------------------------------------------------------------------- exp, log
@kernel(inline=True)
def exp_so3_into(x, y, z, out):
    """``out = exp(hat(w))`` (3, 3) for one rotation vector ``w = (x, y, z)``, by Rodrigues'
    formula.

    ``exp(Ŵ) = I + (sin θ/θ) Ŵ + ((1 − cos θ)/θ²) Ŵ²``, θ = |w|, with the Taylor series of both
    coefficients below :data:`SMALL_ANGLE`.
    """
    t2 = x * x + y * y + z * z
    if t2 < SMALL_ANGLE * SMALL_ANGLE:
        a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    else:
        theta = math.sqrt(t2)
        a = math.sin(theta) / theta
        b = (1.0 - math.cos(theta)) / t2
    # I + a Ŵ + b Ŵ², with Ŵ² = w wᵀ − θ² I
    out[0, 0] = 1.0 + b * (x * x - t2)
    out[1, 1] = 1.0 + b * (y * y - t2)
    out[2, 2] = 1.0 + b * (z * z - t2)
    out[0, 1] = b * x * y - a * z
    out[1, 0] = b * x * y + a * z
    out[0, 2] = b * x * z + a * y
    out[2, 0] = b * x * z - a * y
    out[1, 2] = b * y * z - a * x
    out[2, 1] = b * y * z + a * x


@accepts_sequences
@kernel
def exp_so3(w):
    """Rotation matrices ``exp(hat(w))``. Shape (..., 3) → (..., 3, 3).

    The closed form of ``Q(t) = exp(Ω t)`` at a fixed point of Euler's equation
    (``docs/theory.md`` §1, eqs (22)–(23)).

    Examples
    --------
    >>> import numpy as np
    >>> R = exp_so3(np.array([0.0, 0.0, np.pi / 2]))
    >>> np.allclose(R @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    True
    """
    w = np.asarray(w)
    items = _items(w, 3)
    out = np.empty((items.shape[0], 3, 3))
    for i in range(items.shape[0]):
        exp_so3_into(items[i, 0], items[i, 1], items[i, 2], out[i])
    return out.reshape(w.shape[:-1] + (3, 3))


@accepts_sequences
@kernel
def rodrigues(w):
    """``exp(hat(w))`` for one 3-vector (3,) → (3, 3); the same formula as :func:`exp_so3`."""
    out = np.empty((3, 3))
    exp_so3_into(w[0], w[1], w[2], out)
    return out


@accepts_sequences
@kernel
def log_so3(R):
    """Rotation vectors ``w`` with ``exp_so3(w) = R`` and ``|w| ≤ π``. (..., 3, 3) → (..., 3)."""
    R = np.asarray(R)
    items = np.ascontiguousarray(R).reshape((-1, 3, 3)).astype(np.float64)
    out = np.empty((items.shape[0], 3))
    q = np.empty(4)
    for i in range(items.shape[0]):
        matrix_to_quat_into(items[i], q)
        quat_to_rotvec_into(q, out[i])
    return out.reshape(R.shape[:-2] + (3,))


@kernel(inline=True)
def dexpinv3(u0, u1, u2, v0, v1, v2):
    """``dexp⁻¹_u(v)`` for one pair of vectors ``u``, ``v`` given by components; a 3-tuple.

    ``dexp⁻¹_u(v) = v − ½ u × v + c(θ) u × (u × v)``, ``c = (1 − (θ/2) cot(θ/2))/θ²`` (series
    ``1/12 + θ²/720 + θ⁴/30240`` near 0), θ = |u| (Iserles, Munthe-Kaas, Nørsett & Zanna 2000,
    Acta Numerica, §2.4). Used by Runge–Kutta–Munthe-Kaas steps.
    """
    t2 = u0 * u0 + u1 * u1 + u2 * u2
    if t2 < 1e-6:
        c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    else:
        theta = math.sqrt(t2)
        half = 0.5 * theta
        c = (1.0 - half * math.cos(half) / math.sin(half)) / t2
    a0 = u1 * v2 - u2 * v1
    a1 = u2 * v0 - u0 * v2
    a2 = u0 * v1 - u1 * v0
    b0 = u1 * a2 - u2 * a1
    b1 = u2 * a0 - u0 * a2
    b2 = u0 * a1 - u1 * a0
    return v0 - 0.5 * a0 + c * b0, v1 - 0.5 * a1 + c * b1, v2 - 0.5 * a2 + c * b2


@accepts_sequences
@kernel
def dexpinv(u, v):
    """Inverse of the derivative of the exponential map on so(3), applied to ``v``.

    Shapes: ``u`` and ``v`` (..., 3), equal, or one of them a single (3,). See
    :func:`dexpinv3` for the formula.
    """
    u = np.asarray(u)
    v = np.asarray(v)
    a = _items(u, 3)
    b = _items(v, 3)
    n = max(a.shape[0], b.shape[0])
    if (a.shape[0] != n and a.shape[0] != 1) or (b.shape[0] != n and b.shape[0] != 1):
        raise ValueError("`u` and `v` must have the same shape, or one of them shape (3,)")
    out = np.empty((n, 3))
    for i in range(n):
        p = a[min(i, a.shape[0] - 1)]
        q = b[min(i, b.shape[0] - 1)]
        r = dexpinv3(p[0], p[1], p[2], q[0], q[1], q[2])
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]
    shape = u.shape if a.shape[0] == n else v.shape
    return out.reshape(shape)


@kernel
def axis_rotation(axis, angle):
    """Rotation matrix (3, 3) by ``angle`` about the coordinate axis ``axis`` ∈ {0, 1, 2}."""
    c = math.cos(angle)
    s = math.sin(angle)
    R = np.eye(3)
    i = (axis + 1) % 3
    j = (axis + 2) % 3
    R[i, i] = c
    R[j, j] = c
    R[i, j] = -s
    R[j, i] = s
    return R


# --------------------------------------------------------------------------- quaternions
@kernel(inline=True)
def quat_multiply_into(p, q, out):
    """``out = p ⊗ q``, the Hamilton product of two scalar-first quaternions (4,)."""
    pw, px, py, pz = p[0], p[1], p[2], p[3]
    qw, qx, qy, qz = q[0], q[1], q[2], q[3]
    out[0] = pw * qw - px * qx - py * qy - pz * qz
    out[1] = pw * qx + px * qw + py * qz - pz * qy
    out[2] = pw * qy - px * qz + py * qw + pz * qx
    out[3] = pw * qz + px * qy - py * qx + pz * qw


@accepts_sequences
@kernel
def quat_multiply(p, q):
    """Hamilton products ``p ⊗ q`` (..., 4): equal shapes, or one of them a single (4,)."""
    p = np.asarray(p)
    q = np.asarray(q)
    a = _items(p, 4)
    b = _items(q, 4)
    n = max(a.shape[0], b.shape[0])
    if (a.shape[0] != n and a.shape[0] != 1) or (b.shape[0] != n and b.shape[0] != 1):
        raise ValueError("`p` and `q` must have the same shape, or one of them shape (4,)")
    out = np.empty((n, 4))
    for i in range(n):
        quat_multiply_into(a[min(i, a.shape[0] - 1)], b[min(i, b.shape[0] - 1)], out[i])
    shape = p.shape if a.shape[0] == n else q.shape
    return out.reshape(shape)


@accepts_sequences
@kernel
def quat_conjugate(q):
    """Conjugates ``(w, −x, −y, −z)`` (..., 4): the inverses of unit quaternions."""
    q = np.asarray(q)
    out = _items(q, 4).copy()
    for i in range(out.shape[0]):
        out[i, 1] = -out[i, 1]
        out[i, 2] = -out[i, 2]
        out[i, 3] = -out[i, 3]
    return out.reshape(q.shape)


@accepts_sequences
@kernel
def quat_normalize(q):
    """Unit quaternions ``q/|q|`` (..., 4). Raises ``ValueError`` on a zero quaternion."""
    q = np.asarray(q)
    out = _items(q, 4).copy()
    for i in range(out.shape[0]):
        n = math.sqrt(out[i, 0] ** 2 + out[i, 1] ** 2 + out[i, 2] ** 2 + out[i, 3] ** 2)
        if n == 0.0:
            raise ValueError("`q` must be non-zero to be normalised")
        for k in range(4):
            out[i, k] /= n
    return out.reshape(q.shape)


@kernel(inline=True)
def quat_to_matrix_into(q, out):
    """``out`` (3, 3) = the rotation matrix of one unit quaternion (w, x, y, z)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    out[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    out[0, 1] = 2.0 * (x * y - w * z)
    out[0, 2] = 2.0 * (x * z + w * y)
    out[1, 0] = 2.0 * (x * y + w * z)
    out[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    out[1, 2] = 2.0 * (y * z - w * x)
    out[2, 0] = 2.0 * (x * z - w * y)
    out[2, 1] = 2.0 * (y * z + w * x)
    out[2, 2] = 1.0 - 2.0 * (x * x + y * y)


@accepts_sequences
@kernel
def quat_to_matrix(q):
    """Rotation matrices of unit quaternions (w, x, y, z). (..., 4) → (..., 3, 3)."""
    q = np.asarray(q)
    items = _items(q, 4)
    out = np.empty((items.shape[0], 3, 3))
    for i in range(items.shape[0]):
        quat_to_matrix_into(items[i], out[i])
    return out.reshape(q.shape[:-1] + (3, 3))


@accepts_sequences
@kernel
def quat_rotate(q, v):
    """Rotate vectors ``v`` (..., 3) by unit quaternions ``q`` (..., 4): ``q v q*``.

    ``v + 2w (u × v) + 2 u × (u × v)`` with ``q = (w, u)``. Equal leading shapes, or one of
    them a single item.
    """
    q = np.asarray(q)
    v = np.asarray(v)
    a = _items(q, 4)
    b = _items(v, 3)
    n = max(a.shape[0], b.shape[0])
    if (a.shape[0] != n and a.shape[0] != 1) or (b.shape[0] != n and b.shape[0] != 1):
        raise ValueError("`q` and `v` must have the same leading shape, or one of them a single")
    out = np.empty((n, 3))
    for i in range(n):
        qi = a[min(i, a.shape[0] - 1)]
        vi = b[min(i, b.shape[0] - 1)]
        w, ux, uy, uz = qi[0], qi[1], qi[2], qi[3]
        tx = 2.0 * (uy * vi[2] - uz * vi[1])
        ty = 2.0 * (uz * vi[0] - ux * vi[2])
        tz = 2.0 * (ux * vi[1] - uy * vi[0])
        out[i, 0] = vi[0] + w * tx + (uy * tz - uz * ty)
        out[i, 1] = vi[1] + w * ty + (uz * tx - ux * tz)
        out[i, 2] = vi[2] + w * tz + (ux * ty - uy * tx)
    shape = v.shape if b.shape[0] == n else q.shape[:-1] + (3,)
    return out.reshape(shape)


@kernel(inline=True)
def matrix_to_quat_into(R, out):
    """``out`` (4,) = the unit quaternion (w ≥ 0) of one rotation matrix, by Shepperd's method.

    The largest of ``4w², 4x², 4y², 4z²`` is computed from the diagonal and the other
    components from off-diagonal sums, so no branch divides by a small number.
    """
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    c0 = 1.0 + tr
    c1 = 1.0 + 2.0 * R[0, 0] - tr
    c2 = 1.0 + 2.0 * R[1, 1] - tr
    c3 = 1.0 + 2.0 * R[2, 2] - tr
    k = 0
    big = c0
    if c1 > big:
        k = 1
        big = c1
    if c2 > big:
        k = 2
        big = c2
    if c3 > big:
        k = 3
        big = c3
    s = math.sqrt(max(big, 0.0))  # 2|q_k|
    d21 = R[2, 1] - R[1, 2]
    d02 = R[0, 2] - R[2, 0]
    d10 = R[1, 0] - R[0, 1]
    s01 = R[0, 1] + R[1, 0]
    s02 = R[0, 2] + R[2, 0]
    s12 = R[1, 2] + R[2, 1]
    ss = s * s
    if k == 0:
        w, x, y, z = ss, d21, d02, d10
    elif k == 1:
        w, x, y, z = d21, ss, s01, s02
    elif k == 2:
        w, x, y, z = d02, s01, ss, s12
    else:
        w, x, y, z = d10, s02, s12, ss
    n = math.sqrt(w * w + x * x + y * y + z * z)
    if w < 0.0:
        n = -n
    out[0] = w / n
    out[1] = x / n
    out[2] = y / n
    out[3] = z / n


@accepts_sequences
@kernel
def matrix_to_quat(R):
    """Unit quaternions (w ≥ 0) of rotation matrices, by Shepperd's method.
    (..., 3, 3) → (..., 4)."""
    R = np.asarray(R)
    items = np.ascontiguousarray(R).reshape((-1, 3, 3)).astype(np.float64)
    out = np.empty((items.shape[0], 4))
    for i in range(items.shape[0]):
        matrix_to_quat_into(items[i], out[i])
    return out.reshape(R.shape[:-2] + (4,))


@kernel(inline=True)
def rotvec_to_quat_into(w, out):
    """``out`` (4,) = the unit quaternion of the rotation vector ``w`` (3,).

    ``(cos(θ/2), sin(θ/2) w/θ)``, with ``sin(θ/2)/θ = 1/2 − θ²/48 + θ⁴/3840`` near 0.
    """
    t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
    theta = math.sqrt(t2)
    if theta < SMALL_ANGLE:
        s = 0.5 - t2 / 48.0 + t2 * t2 / 3840.0
    else:
        s = math.sin(0.5 * theta) / theta
    out[0] = math.cos(0.5 * theta)
    out[1] = s * w[0]
    out[2] = s * w[1]
    out[3] = s * w[2]


@accepts_sequences
@kernel
def rotvec_to_quat(w):
    """Unit quaternions of rotation vectors (angle |w| about w/|w|). (..., 3) → (..., 4)."""
    w = np.asarray(w)
    items = _items(w, 3)
    out = np.empty((items.shape[0], 4))
    for i in range(items.shape[0]):
        rotvec_to_quat_into(items[i], out[i])
    return out.reshape(w.shape[:-1] + (4,))


@kernel(inline=True)
def quat_to_rotvec_into(q, out):
    """``out`` (3,) = the rotation vector (angle in [0, π]) of one unit quaternion (4,).

    ``θ = 2 atan2(|v|, |w|)``: accurate at every angle, including near 0 and π.
    """
    sign = -1.0 if q[0] < 0.0 else 1.0
    w = sign * q[0]
    x = sign * q[1]
    y = sign * q[2]
    z = sign * q[3]
    sv = math.sqrt(x * x + y * y + z * z)
    if sv < 1e-12:
        factor = 2.0 / w if w != 0.0 else 2.0
    else:
        factor = 2.0 * math.atan2(sv, w) / sv
    out[0] = factor * x
    out[1] = factor * y
    out[2] = factor * z


@accepts_sequences
@kernel
def quat_to_rotvec(q):
    """Rotation vectors (angle in [0, π]) of unit quaternions. (..., 4) → (..., 3)."""
    q = np.asarray(q)
    items = _items(q, 4)
    out = np.empty((items.shape[0], 3))
    for i in range(items.shape[0]):
        quat_to_rotvec_into(items[i], out[i])
    return out.reshape(q.shape[:-1] + (3,))


# --------------------------------------------------------------------------- Euler angles
@kernel(inline=True)
def zxz_matrix_into(psi, theta, phi, out):
    """``out = Rz(ψ) Rx(θ) Rz(φ)`` (3, 3): the rotation of z-x-z Euler angles (intrinsic, as
    ``scipy.spatial.transform.Rotation.from_euler("ZXZ", ...)``)."""
    cps = math.cos(psi)
    sps = math.sin(psi)
    ct = math.cos(theta)
    st = math.sin(theta)
    cph = math.cos(phi)
    sph = math.sin(phi)
    out[0, 0] = cps * cph - sps * ct * sph
    out[0, 1] = -cps * sph - sps * ct * cph
    out[0, 2] = sps * st
    out[1, 0] = sps * cph + cps * ct * sph
    out[1, 1] = -sps * sph + cps * ct * cph
    out[1, 2] = -cps * st
    out[2, 0] = st * sph
    out[2, 1] = st * cph
    out[2, 2] = ct


@accepts_sequences
@kernel
def zxz_body_rates(angles, rates):
    """Body-frame angular velocity ``(p, q, r)`` from z-x-z Euler angles ``(ψ, θ, φ)`` and their
    rates (paper eq. (13); the same form gives the carrier's ω_e from its angles, eq. (14))::

        p = ψ̇ sin θ sin φ + θ̇ cos φ
        q = ψ̇ sin θ cos φ − θ̇ sin φ
        r = φ̇ + ψ̇ cos θ

    ``angles``, ``rates`` (..., 3) → (..., 3).
    """
    angles = np.asarray(angles)
    a = _items(angles, 3)
    d = _items(np.asarray(rates), 3)
    out = np.empty_like(a)
    for i in range(a.shape[0]):
        st = math.sin(a[i, 1])
        ct = math.cos(a[i, 1])
        sp = math.sin(a[i, 2])
        cp = math.cos(a[i, 2])
        out[i, 0] = d[i, 0] * st * sp + d[i, 1] * cp
        out[i, 1] = d[i, 0] * st * cp - d[i, 1] * sp
        out[i, 2] = d[i, 2] + d[i, 0] * ct
    return out.reshape(angles.shape)


@accepts_sequences
@kernel
def zxz_angle_rates(angles, omega):
    """The inverse of :func:`zxz_body_rates`: ``(ψ̇, θ̇, φ̇)`` from body ``(p, q, r)``::

        ψ̇ = (p sin φ + q cos φ)/sin θ,  θ̇ = p cos φ − q sin φ,  φ̇ = r − ψ̇ cos θ

    Singular at θ = 0, π (sin θ = 0), where the result is infinite or NaN; callers check.
    """
    angles = np.asarray(angles)
    a = _items(angles, 3)
    w = _items(np.asarray(omega), 3)
    out = np.empty_like(a)
    for i in range(a.shape[0]):
        st = math.sin(a[i, 1])
        sp = math.sin(a[i, 2])
        cp = math.cos(a[i, 2])
        psid = (w[i, 0] * sp + w[i, 1] * cp) / st
        out[i, 0] = psid
        out[i, 1] = w[i, 0] * cp - w[i, 1] * sp
        out[i, 2] = w[i, 2] - psid * math.cos(a[i, 1])
    return out.reshape(angles.shape)
