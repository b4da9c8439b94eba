"""Inertia from gyro logs: the gyrostat's regressor and motion, and the lever arm's accelerations
(``crates/core/src/gyrostat.rs``).
"""

from .._core import (
    gyrostat_omega_dot,
    gyrostat_omegas,
    gyrostat_regressor,
    gyrostat_sensitivities,
    point_acceleration_matrices,
)

__all__ = [
    "gyrostat_omega_dot",
    "gyrostat_omegas",
    "gyrostat_regressor",
    "gyrostat_sensitivities",
    "point_acceleration_matrices",
]
