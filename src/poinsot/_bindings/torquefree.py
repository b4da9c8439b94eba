"""The torque-free body in closed form: regimes and families, ω(t) and Q(t) by elliptic functions,
the ellipsoids and cones, fixed points and their linearisation
(``crates/core/src/torque_free/``).
"""

from .._core import (
    NEAR_UNSTABLE_AXIS,
    REGIME_OFFSETS,
    TORQUE_FREE_CASE_NAMES,
    cone_coefficients,
    energy_ellipsoid_semi_axes,
    euler_jacobian,
    euler_omega_dot_free,
    fixed_point_attitudes,
    momentum_ellipsoid_semi_axes,
    principal_invariants,
    rotational_energies_and_momenta,
    torque_free_attitudes,
    torque_free_derivatives,
    torque_free_families,
    torque_free_omegas,
    torque_free_regimes,
)

__all__ = [
    "NEAR_UNSTABLE_AXIS",
    "REGIME_OFFSETS",
    "TORQUE_FREE_CASE_NAMES",
    "cone_coefficients",
    "energy_ellipsoid_semi_axes",
    "euler_jacobian",
    "euler_omega_dot_free",
    "fixed_point_attitudes",
    "momentum_ellipsoid_semi_axes",
    "principal_invariants",
    "rotational_energies_and_momenta",
    "torque_free_attitudes",
    "torque_free_derivatives",
    "torque_free_families",
    "torque_free_omegas",
    "torque_free_regimes",
]
