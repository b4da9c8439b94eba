"""Mass properties: inertia tensors of shapes and particle sets, the principal decomposition, the
one validity check of an inertia tensor, symmetry classes and the equivalent box
(``crates/core/src/inertia.rs``, ``shapes.rs``).
"""

from .._core import (
    DEGENERATE_RTOL,
    SYMMETRY_CLASSES,
    SYMMETRY_RTOL,
    box_inertia,
    center_of_mass,
    check_inertia,
    cone_inertia,
    cylinder_inertia,
    ellipsoid_inertia,
    equivalent_box_half_extents,
    is_degenerate,
    parallel_axis,
    particle_inertia,
    planar_inertia,
    planar_inertia_particles,
    polyhedron_mass_properties,
    principal_decomposition,
    rod_inertia,
    rotate_inertia,
    sphere_inertia,
    spherical_shell_inertia,
    symmetry_code,
)

__all__ = [
    "DEGENERATE_RTOL",
    "SYMMETRY_CLASSES",
    "SYMMETRY_RTOL",
    "box_inertia",
    "center_of_mass",
    "check_inertia",
    "cone_inertia",
    "cylinder_inertia",
    "ellipsoid_inertia",
    "equivalent_box_half_extents",
    "is_degenerate",
    "parallel_axis",
    "particle_inertia",
    "planar_inertia",
    "planar_inertia_particles",
    "polyhedron_mass_properties",
    "principal_decomposition",
    "rod_inertia",
    "rotate_inertia",
    "sphere_inertia",
    "spherical_shell_inertia",
    "symmetry_code",
]
