"""Attitude conversions: rotation matrices, quaternions, rotation vectors, Euler angles.

Conventions
-----------
* Quaternions are scalar first, ``(w, x, y, z)`` (the conventions of ``crates/core/src/so3.rs``,
  called through :mod:`poinsot._core`).
* Euler sequences follow :class:`scipy.spatial.transform.Rotation`: three letters, upper case
  for **intrinsic** rotations about the moving axes (``"ZXZ"``), lower case for **extrinsic**
  rotations about the fixed axes (``"zxz"``); all 12 proper and Tait–Bryan sequences.
* The paper's angles (ψ precession, θ nutation, φ proper rotation; eq. (13)) are the
  intrinsic ``"ZXZ"`` sequence: ``Q = Rz(ψ) Rx(θ) Rz(φ)``.
* Gimbal lock (θ = 0 or π for proper sequences, the middle angle ±π/2 for Tait–Bryan): the
  decomposition is not unique; poinsot sets the **third angle to zero** and puts the whole
  rotation about the repeated axis into the first angle. The result is always finite (never NaN)
  and re-composes to the input rotation. scipy's warning for this case is silenced here because
  the choice is documented.

We wrap :class:`~scipy.spatial.transform.Rotation` for the sequence bookkeeping and write only
what it lacks: the angle-rate kinematics of eq. (13) and its inverse.
"""

from __future__ import annotations

import warnings

import numpy as np

from . import _core as so3
from ._validation import as_array

__all__ = [
    "EULER_SEQUENCES",
    "body_rates_from_euler",
    "euler_from_matrix",
    "euler_from_quat",
    "euler_rates_from_body",
    "matrix_from_euler",
    "matrix_from_quat",
    "matrix_from_rotvec",
    "quat_from_euler",
    "quat_from_matrix",
    "rotvec_from_matrix",
]

_PROPER = ["XYX", "XZX", "YXY", "YZY", "ZXZ", "ZYZ"]
_TAIT_BRYAN = ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]
#: Every accepted sequence: intrinsic (upper case) and extrinsic (lower case).
EULER_SEQUENCES = tuple(_PROPER + _TAIT_BRYAN + [s.lower() for s in _PROPER + _TAIT_BRYAN])


def _check_seq(seq: str) -> str:
    if seq not in EULER_SEQUENCES:
        raise ValueError(
            f"`seq` must be one of {', '.join(EULER_SEQUENCES)} "
            f"(upper case intrinsic, lower case extrinsic), found {seq!r}"
        )
    return seq


def _rotation():
    from scipy.spatial.transform import Rotation

    return Rotation


def matrix_from_euler(angles, seq: str = "ZXZ", *, degrees: bool = False) -> np.ndarray:
    """Rotation matrices (..., 3, 3) from Euler angles (..., 3) in sequence ``seq``.

    Examples
    --------
    >>> import numpy as np
    >>> Q = matrix_from_euler([np.pi / 2, 0.0, 0.0], "ZXZ")
    >>> np.allclose(Q @ [1, 0, 0], [0, 1, 0])
    True
    """
    _check_seq(seq)
    a = np.asarray(angles, dtype=float)
    if a.shape[-1:] != (3,):
        raise ValueError(f"`angles` must have shape (..., 3), found {a.shape}")
    flat = a.reshape(-1, 3)
    R = _rotation().from_euler(seq, flat, degrees=degrees).as_matrix()
    return R.reshape(*a.shape[:-1], 3, 3)


def euler_from_matrix(R, seq: str = "ZXZ", *, degrees: bool = False) -> np.ndarray:
    """Euler angles (..., 3) of rotation matrices (..., 3, 3); gimbal lock: third angle 0.

    Angles lie in (−π, π], except the middle angle: [0, π] for proper sequences and
    [−π/2, π/2] for Tait–Bryan sequences.
    """
    _check_seq(seq)
    R = np.asarray(R, dtype=float)
    flat = R.reshape(-1, 3, 3)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Gimbal lock detected")
        angles = _rotation().from_matrix(flat).as_euler(seq, degrees=degrees)
    return angles.reshape(*R.shape[:-2], 3)


def quat_from_euler(angles, seq: str = "ZXZ", *, degrees: bool = False) -> np.ndarray:
    """Scalar-first unit quaternions (..., 4), w ≥ 0, from Euler angles (..., 3)."""
    return so3.matrix_to_quat(matrix_from_euler(angles, seq, degrees=degrees))


def euler_from_quat(q, seq: str = "ZXZ", *, degrees: bool = False) -> np.ndarray:
    """Euler angles (..., 3) of scalar-first unit quaternions (..., 4)."""
    return euler_from_matrix(so3.quat_to_matrix(so3.quat_normalize(q)), seq, degrees=degrees)


def matrix_from_quat(q) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of scalar-first quaternions (..., 4) (normalised first)."""
    return so3.quat_to_matrix(so3.quat_normalize(q))


def quat_from_matrix(R) -> np.ndarray:
    """Scalar-first unit quaternions (..., 4) with w ≥ 0 (Shepperd's method)."""
    return so3.matrix_to_quat(R)


def matrix_from_rotvec(rotvec) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of rotation vectors (..., 3) (Rodrigues)."""
    return so3.exp_so3(rotvec)


def rotvec_from_matrix(R) -> np.ndarray:
    """Rotation vectors (..., 3), angle in [0, π], of rotation matrices (..., 3, 3)."""
    return so3.log_so3(R)


def body_rates_from_euler(angles, rates) -> np.ndarray:
    """Body-frame angular velocity ``(p, q, r)`` from z-x-z Euler angles and their rates.

    Paper eq. (13)::

        p = ψ̇ sin θ sin φ + θ̇ cos φ
        q = ψ̇ sin θ cos φ − θ̇ sin φ
        r = φ̇ + ψ̇ cos θ

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        ``(ψ, θ, φ)`` of the intrinsic ``"ZXZ"`` sequence, radians.
    rates : array_like, shape (..., 3)
        ``(ψ̇, θ̇, φ̇)``.

    Examples
    --------
    >>> body_rates_from_euler([0.0, 0.0, 0.0], [0.0, 0.0, 2.0]).tolist()
    [0.0, 0.0, 2.0]
    """
    a = as_array(angles, "angles", (*np.shape(angles)[:-1], 3))
    d = as_array(rates, "rates", (*np.shape(rates)[:-1], 3))
    if a.shape != d.shape:
        raise ValueError(
            f"`angles` and `rates` must have the same shape, found {a.shape}, {d.shape}"
        )
    return so3.zxz_body_rates(a, d)


def euler_rates_from_body(angles, omega) -> np.ndarray:
    """Inverse of :func:`body_rates_from_euler`: ``(ψ̇, θ̇, φ̇)`` from body ``(p, q, r)``.

    ``ψ̇ = (p sin φ + q cos φ)/sin θ``, ``θ̇ = p cos φ − q sin φ``, ``φ̇ = r − ψ̇ cos θ``.
    Singular at θ = 0 or π (gimbal lock): raises ``ValueError`` there; integrate attitude with
    quaternions or matrices and convert, as :func:`poinsot.simulate` does.
    """
    a = as_array(angles, "angles", (*np.shape(angles)[:-1], 3))
    w = as_array(omega, "omega", (*np.shape(omega)[:-1], 3))
    if a.shape != w.shape:
        raise ValueError(
            f"`angles` and `omega` must have the same shape, found {a.shape}, {w.shape}"
        )
    if np.any(np.abs(np.sin(a[..., 1])) < 1e-12):
        raise ValueError("`angles`: Euler rates are undefined at θ = 0 or π (gimbal lock)")
    return so3.zxz_angle_rates(a, w)
