"""Rotations: SO(3) exponential and logarithm, quaternions, rotation vectors and the z-x-z (ψ, θ,
φ) forms of eqs. (13)–(14) (``crates/core/src/so3.rs``).
"""

from .._core import (
    axis_rotation,
    dexpinv,
    exp_so3,
    hat,
    log_so3,
    matrix_to_quat,
    quat_conjugate,
    quat_multiply,
    quat_normalize,
    quat_rotate,
    quat_to_matrix,
    quat_to_rotvec,
    rotvec_to_quat,
    vee,
    zxz_angle_rates,
    zxz_body_rates,
    zxz_matrix,
)

__all__ = [
    "axis_rotation",
    "dexpinv",
    "exp_so3",
    "hat",
    "log_so3",
    "matrix_to_quat",
    "quat_conjugate",
    "quat_multiply",
    "quat_normalize",
    "quat_rotate",
    "quat_to_matrix",
    "quat_to_rotvec",
    "rotvec_to_quat",
    "vee",
    "zxz_angle_rates",
    "zxz_body_rates",
    "zxz_matrix",
]
