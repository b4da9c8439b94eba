"""SO(3) and unit-quaternion kernels: arrays in, arrays out, batched over leading axes.

Conventions (used throughout poinsot):

* ``hat(w) @ v == cross(w, v)``; ``vee`` is its inverse, with ``vee(B) = (−B23, B13, −B12)``
  for any skew ``B`` as in THEORY.md §1 (0-based: ``(B[2,1], B[0,2], B[1,0])``).
* Quaternions are **scalar first**, ``q = (w, x, y, z)``, Hamilton product, and act on vectors
  as ``q v q*`` (active rotation). ``matrix_to_quat`` returns the representative with ``w ≥ 0``.
* Rotation vectors ``θ n`` have ``0 ≤ θ ≤ π``.

Every function here works on ``(..., 3)``/``(..., 4)``/``(..., 3, 3)`` arrays and is accurate to
round-off near the singular angles: small-angle series near θ = 0, and the log is taken through
a quaternion extracted by Shepperd's method, which stays accurate near θ = π where the
``arccos((tr R − 1)/2)`` route loses half the digits.

We do not route these through :class:`scipy.spatial.transform.Rotation` because the integrator
steps call them on single 3-vectors millions of times (object construction would dominate) and
because Rotation lacks ``dexp⁻¹``; ``tests/kernels/test_so3.py`` checks them against Rotation.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "dexpinv",
    "exp_so3",
    "hat",
    "hat3",
    "log_so3",
    "matrix_to_quat",
    "quat_conjugate",
    "quat_multiply",
    "quat_normalize",
    "quat_rotate",
    "quat_to_matrix",
    "quat_to_rotvec",
    "rodrigues",
    "rotvec_to_quat",
    "vee",
]

# Below this angle the closed forms are replaced by Taylor series (errors ~θ^6 ≪ 1e-16).
_SMALL = 1e-4


def hat(w):
    """Skew matrix of ``w``: ``hat(w) @ v = w × v``. Shape (..., 3) → (..., 3, 3)."""
    w = np.asarray(w, dtype=float)
    z = np.zeros_like(w[..., 0])
    x, y, zz = w[..., 0], w[..., 1], w[..., 2]
    return np.stack(
        [
            np.stack([z, -zz, y], axis=-1),
            np.stack([zz, z, -x], axis=-1),
            np.stack([-y, x, z], axis=-1),
        ],
        axis=-2,
    )


def vee(B):
    """Vector of the skew part of ``B``: inverse of :func:`hat`. Shape (..., 3, 3) → (..., 3).

    Uses the antisymmetric part, ``vee(B) = vee((B − Bᵀ)/2)``, so round-off in ``B`` does not
    bias the result.
    """
    B = np.asarray(B, dtype=float)
    return 0.5 * np.stack(
        [B[..., 2, 1] - B[..., 1, 2], B[..., 0, 2] - B[..., 2, 0], B[..., 1, 0] - B[..., 0, 1]],
        axis=-1,
    )


def _rodrigues_coefficients(theta):
    """``sin θ/θ`` and ``(1 − cos θ)/θ²`` with series below :data:`_SMALL`."""
    t2 = theta * theta
    small = theta < _SMALL
    safe = np.where(small, 1.0, theta)
    a = np.where(small, 1.0 - t2 / 6.0 + t2 * t2 / 120.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, (1.0 - np.cos(safe)) / (safe * safe))
    return a, b


def exp_so3(w):
    """Rotation matrix ``exp(hat(w))`` by Rodrigues' formula. Shape (..., 3) → (..., 3, 3).

    ``exp(Ŵ) = I + (sin θ/θ) Ŵ + ((1 − cos θ)/θ²) Ŵ²``, θ = |w|; this is the closed form of
    ``Q(t) = exp(Ω t)`` at a fixed point of Euler's equation (THEORY.md §1).

    Examples
    --------
    >>> import numpy as np
    >>> R = exp_so3([0.0, 0.0, np.pi / 2])
    >>> np.allclose(R @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    True
    """
    w = np.asarray(w, dtype=float)
    theta = np.linalg.norm(w, axis=-1)
    a, b = _rodrigues_coefficients(theta)
    W = hat(w)
    return np.eye(3) + a[..., None, None] * W + b[..., None, None] * (W @ W)


def quat_multiply(p, q):
    """Hamilton product ``p ⊗ q`` of scalar-first quaternions. Shapes broadcast, (..., 4)."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    pw, px, py, pz = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    qw, qx, qy, qz = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        axis=-1,
    )


def quat_conjugate(q):
    """Conjugate ``(w, −x, −y, −z)``; the inverse of a unit quaternion. Shape (..., 4)."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quat_normalize(q):
    """Unit quaternion ``q/|q|``. Shape (..., 4). Raises ``ValueError`` on a zero quaternion."""
    q = np.asarray(q, dtype=float)
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(n == 0):
        raise ValueError("`q` must be non-zero to be normalised")
    return q / n


def quat_rotate(q, v):
    """Rotate vectors ``v`` (..., 3) by unit quaternions ``q`` (..., 4): ``q v q*``."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    u = q[..., 1:]
    w = q[..., :1]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def quat_to_matrix(q):
    """Rotation matrix of a unit quaternion (w, x, y, z). Shape (..., 4) → (..., 3, 3)."""
    q = np.asarray(q, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def matrix_to_quat(R):
    """Unit quaternion (w ≥ 0) of a rotation matrix, by Shepperd's method. (..., 3, 3) → (..., 4).

    For each matrix the largest of ``w², x², y², z²`` is computed from the diagonal and the other
    components from off-diagonal sums, so no branch divides by a small number.
    """
    R = np.asarray(R, dtype=float)
    tr = R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2]
    # candidates 4w², 4x², 4y², 4z² (each ≥ 0 up to round-off)
    cand = np.stack(
        [
            1 + tr,
            1 + 2 * R[..., 0, 0] - tr,
            1 + 2 * R[..., 1, 1] - tr,
            1 + 2 * R[..., 2, 2] - tr,
        ],
        axis=-1,
    )
    k = np.argmax(cand, axis=-1)
    s = np.sqrt(np.maximum(np.take_along_axis(cand, k[..., None], -1)[..., 0], 0.0))  # 2|q_k|
    d21 = R[..., 2, 1] - R[..., 1, 2]
    d02 = R[..., 0, 2] - R[..., 2, 0]
    d10 = R[..., 1, 0] - R[..., 0, 1]
    s01 = R[..., 0, 1] + R[..., 1, 0]
    s02 = R[..., 0, 2] + R[..., 2, 0]
    s12 = R[..., 1, 2] + R[..., 2, 1]
    # rows: quaternion (times 2|q_k|) for each choice of k
    opts = np.stack(
        [
            np.stack([s * s, d21, d02, d10], -1),
            np.stack([d21, s * s, s01, s02], -1),
            np.stack([d02, s01, s * s, s12], -1),
            np.stack([d10, s02, s12, s * s], -1),
        ],
        axis=-2,
    )
    q = np.take_along_axis(opts, k[..., None, None], axis=-2)[..., 0, :] / (2.0 * s[..., None])
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return np.where(q[..., :1] < 0, -q, q)


def rotvec_to_quat(w):
    """Unit quaternion of the rotation vector ``w`` (angle |w| about w/|w|). (..., 3) → (..., 4)."""
    w = np.asarray(w, dtype=float)
    theta = np.linalg.norm(w, axis=-1)
    half = 0.5 * theta
    small = theta < _SMALL
    safe = np.where(small, 1.0, theta)
    # sin(θ/2)/θ with its series 1/2 − θ²/48 + θ⁴/3840
    s = np.where(small, 0.5 - theta**2 / 48.0 + theta**4 / 3840.0, np.sin(0.5 * safe) / safe)
    return np.concatenate([np.cos(half)[..., None], s[..., None] * w], axis=-1)


def quat_to_rotvec(q):
    """Rotation vector (angle in [0, π]) of a unit quaternion. (..., 4) → (..., 3).

    ``θ = 2 atan2(|v|, |w|)``: accurate at every angle, including near 0 and π.
    """
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., :1] < 0, -q, q)
    v = q[..., 1:]
    sv = np.linalg.norm(v, axis=-1)
    w = q[..., 0]
    theta = 2.0 * np.arctan2(sv, w)
    small = sv < 1e-12
    factor = np.where(small, 2.0 / np.where(w == 0, 1.0, w), theta / np.where(small, 1.0, sv))
    return factor[..., None] * v


def log_so3(R):
    """Rotation vector ``w`` with ``exp_so3(w) = R`` and ``|w| ≤ π``. (..., 3, 3) → (..., 3)."""
    return quat_to_rotvec(matrix_to_quat(R))


def dexpinv(u, v):
    """Inverse of the derivative of the exponential map on so(3), applied to ``v``.

    ``dexp⁻¹_u(v) = v − ½ u × v + c(θ) u × (u × v)``, ``c = (1 − (θ/2) cot(θ/2))/θ²`` (series
    ``1/12 + θ²/720 + θ⁴/30240`` near 0), θ = |u| (Iserles, Munthe-Kaas, Nørsett & Zanna 2000,
    Acta Numerica, §2.4). Used by Runge–Kutta–Munthe-Kaas steps. Shapes (..., 3).
    """
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    theta = np.linalg.norm(u, axis=-1)
    small = theta < 1e-3
    safe = np.where(small, 1.0, theta)
    half = 0.5 * safe
    c = np.where(
        small,
        1.0 / 12.0 + theta**2 / 720.0 + theta**4 / 30240.0,
        (1.0 - half * np.cos(half) / np.sin(half)) / (safe * safe),
    )
    uxv = np.cross(u, v)
    return v - 0.5 * uxv + c[..., None] * np.cross(u, uxv)


def hat3(w):
    """Skew matrix of one 3-vector (scalar code, numba-compilable). (3,) → (3, 3)."""
    out = np.zeros((3, 3))
    out[0, 1] = -w[2]
    out[0, 2] = w[1]
    out[1, 0] = w[2]
    out[1, 2] = -w[0]
    out[2, 0] = -w[1]
    out[2, 1] = w[0]
    return out


def rodrigues(w):
    """``exp(hat(w))`` for one 3-vector (scalar code, numba-compilable); same formula and
    small-angle series as :func:`exp_so3`. (3,) → (3, 3)."""
    t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
    theta = np.sqrt(t2)
    if theta < _SMALL:
        a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0
        b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0
    else:
        a = np.sin(theta) / theta
        b = (1.0 - np.cos(theta)) / t2
    W = hat3(w)
    return np.eye(3) + a * W + b * (W @ W)
