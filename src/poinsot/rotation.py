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
from typing import NamedTuple

import numpy as np

from ._bindings import rotations as core_rotations
from ._validation import as_array

__all__ = [
    "EULER_SEQUENCES",
    "EULER_SINGULAR",
    "EulerSeries",
    "body_rates_from_euler",
    "euler_from_matrix",
    "euler_from_quat",
    "euler_rates_from_body",
    "euler_series",
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
    return core_rotations.matrix_to_quat(matrix_from_euler(angles, seq, degrees=degrees))


def euler_from_quat(q, seq: str = "ZXZ", *, degrees: bool = False) -> np.ndarray:
    """Euler angles (..., 3) of scalar-first unit quaternions (..., 4)."""
    return euler_from_matrix(
        core_rotations.quat_to_matrix(core_rotations.quat_normalize(q)), seq, degrees=degrees
    )


def matrix_from_quat(q) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of scalar-first quaternions (..., 4) (normalised first)."""
    return core_rotations.quat_to_matrix(core_rotations.quat_normalize(q))


def quat_from_matrix(R) -> np.ndarray:
    """Scalar-first unit quaternions (..., 4) with w ≥ 0 (Shepperd's method)."""
    return core_rotations.matrix_to_quat(R)


def matrix_from_rotvec(rotvec) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of rotation vectors (..., 3) (Rodrigues)."""
    return core_rotations.exp_so3(rotvec)


def rotvec_from_matrix(R) -> np.ndarray:
    """Rotation vectors (..., 3), angle in [0, π], of rotation matrices (..., 3, 3)."""
    return core_rotations.log_so3(R)


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
    return core_rotations.zxz_body_rates(a, d)


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
    return core_rotations.zxz_angle_rates(a, w)


#: ``|sin θ|`` below which the z-x-z angles are flagged singular (gimbal lock, θ = 0 or π): ψ and
#: φ are then not separately defined (only ψ ± φ is), and their rates are infinite.
EULER_SINGULAR = 1e-6


class EulerSeries(NamedTuple):
    """z-x-z Euler angles along a motion (:func:`euler_series`).

    Attributes
    ----------
    angles : ndarray, shape (n, 3)
        ``(ψ, θ, φ)`` in radians: θ in [0, π]; ψ and φ unwrapped (continuous in time, not
        folded into (−π, π]), so that ``ψ(t)`` shows the accumulated precession.
    rates : ndarray, shape (n, 3)
        ``(ψ̇, θ̇, φ̇)`` in rad/s from the body rates by eq. (13) (the core's
        ``zxz_angle_rates``); NaN at the singular samples.
    singular : ndarray of bool, shape (n,)
        Samples within :data:`EULER_SINGULAR` of θ = 0 or π, where ψ and φ are not separately
        defined (poinsot then sets the third angle as :func:`euler_from_matrix` does).
    """

    angles: np.ndarray
    rates: np.ndarray
    singular: np.ndarray


def euler_series(Q, omega, t=None) -> EulerSeries:
    """z-x-z Euler angles ``(ψ, θ, φ)`` of the attitudes ``Q`` (n, 3, 3) of a motion with body
    angular velocity ``omega`` (n, 3), their rates (eq. (13)) and the singular samples.

    The angles come from :func:`euler_from_matrix` (intrinsic ``"ZXZ"``, ``Q = Rz(ψ) Rx(θ)
    Rz(φ)``), the rates from the inverse of eq. (13) in the compiled core. ψ and φ are then
    made continuous: between two samples each changes by the multiple of 2π that brings the
    change nearest to the integral of its rate (trapezoidal rule, with the sample times ``t``;
    without ``t`` or where a rate is undefined, nearest to no change). So a fast spin sampled
    coarsely (φ̇ Δt > π) still unwraps correctly.

    Examples
    --------
    A steady spin about the space z axis, sampled every 0.1 s at 40 rad/s (4 rad per sample):

    >>> import numpy as np
    >>> t = np.linspace(0, 1, 11)
    >>> Q = matrix_from_euler(np.column_stack([0 * t, 0 * t + 0.5, 40 * t]))
    >>> s = euler_series(Q, np.tile([0.0, 0.0, 40.0], (11, 1)), t)
    >>> bool(np.allclose(s.angles[:, 2], 40 * t)), bool(np.allclose(s.rates[:, 2], 40.0))
    (True, True)
    """
    Q = np.asarray(Q, dtype=float)
    w = np.ascontiguousarray(omega, dtype=float)
    if Q.ndim != 3 or Q.shape[1:] != (3, 3) or w.shape != (len(Q), 3):
        raise ValueError(
            f"`Q` and `omega` must have shapes (n, 3, 3) and (n, 3), found {Q.shape}, {w.shape}"
        )
    angles = np.ascontiguousarray(euler_from_matrix(Q, "ZXZ"))
    singular = np.abs(np.sin(angles[:, 1])) < EULER_SINGULAR
    with np.errstate(divide="ignore", invalid="ignore"):
        rates = np.asarray(core_rotations.zxz_angle_rates(angles, w), dtype=float)
    rates[singular] = np.nan
    if len(angles) > 1:
        dt = np.zeros(len(angles) - 1) if t is None else np.diff(np.asarray(t, dtype=float))
        for k in (0, 2):
            step = np.diff(angles[:, k])
            expected = 0.5 * (rates[1:, k] + rates[:-1, k]) * dt
            expected = np.where(np.isfinite(expected), expected, 0.0)
            turns = np.round((expected - step) / (2 * np.pi))
            angles[1:, k] = angles[0, k] + np.cumsum(step + 2 * np.pi * turns)
    return EulerSeries(angles, rates, singular)
