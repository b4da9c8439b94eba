"""The quantities of a sampled motion: energies, angular momenta, ω in space, the attitude's
orthogonality error, a symmetric top's axis (``crates/core/src/invariants.rs``).
"""

from .._core import (
    angular_momenta,
    kinetic_energies,
    omega_space,
    orthogonality_errors,
    potential_energies,
    rotational_energies,
    symmetric_top_axis,
)

__all__ = [
    "angular_momenta",
    "kinetic_energies",
    "omega_space",
    "orthogonality_errors",
    "potential_energies",
    "rotational_energies",
    "symmetric_top_axis",
]
