"""Motion relative to a moving carrier: the carrier's motion, the transport and Coriolis moments,
the relative equations and their run (``crates/core/src/relative.rs``).
"""

from .._core import (
    MOTION_SIZE,
    RELATIVE_STATE_SIZE,
    absolute_states,
    carrier_motions,
    coriolis_moments,
    coriolis_moments_particles,
    coriolis_moments_three_term,
    integrate_relative,
    relative_rhs,
    transport_moments,
)

__all__ = [
    "MOTION_SIZE",
    "RELATIVE_STATE_SIZE",
    "absolute_states",
    "carrier_motions",
    "coriolis_moments",
    "coriolis_moments_particles",
    "coriolis_moments_three_term",
    "integrate_relative",
    "relative_rhs",
    "transport_moments",
]
