"""The rigid body under forces, eqs. (07)–(09): its parameter vector, built-in forces and their
wrench, states, the pivot constraint, and its run (``crates/core/src/system.rs``,
``forces.rs``, ``rigid.rs``, ``layout.rs``).
"""

from .._core import (
    body_vector,
    force_wrench_potential,
    initial_states,
    integrate_rigid,
    particle_motion,
    pivot_point,
    project_onto_pivot,
    rigid_body_parameters,
    rigid_motion_from_particles,
    rigid_rates,
    states_principal,
)

__all__ = [
    "body_vector",
    "force_wrench_potential",
    "initial_states",
    "integrate_rigid",
    "particle_motion",
    "pivot_point",
    "project_onto_pivot",
    "rigid_body_parameters",
    "rigid_motion_from_particles",
    "rigid_rates",
    "states_principal",
]
