"""Closed-form inertia of uniform solids, about the centre of mass, in the solid's own axes.

Each function returns the 3×3 inertia of a solid of mass ``m`` centred on its centre of mass,
aligned with x, y, z (the symmetry axis, where there is one, along z). Values from
Goldstein, Poole & Safko, *Classical Mechanics* (3rd ed.), and Meriam & Kraige, *Engineering
Mechanics: Dynamics*, Appendix B ("Properties of homogeneous solids"). The tests check each
against a converging particle discretisation of the same solid.

:func:`equivalent_box_half_extents` inverts the box formula: the box with given principal
moments (used to draw a body given only by its mass properties).
"""

from __future__ import annotations

import math

import numpy as np

from .jit import kernel

__all__ = [
    "box_inertia",
    "cone_inertia",
    "cylinder_inertia",
    "ellipsoid_inertia",
    "equivalent_box_half_extents",
    "rod_inertia",
    "sphere_inertia",
    "spherical_shell_inertia",
]


@kernel
def box_inertia(m, size):
    """Box with edges ``(a, b, c)`` along x, y, z: ``m/12 · diag(b²+c², a²+c², a²+b²)``."""
    a, b, c = size[0], size[1], size[2]
    return m / 12.0 * np.diag(np.array([b * b + c * c, a * a + c * c, a * a + b * b]))


@kernel
def sphere_inertia(m, r):
    """Solid sphere: ``2/5 m r²`` about every axis."""
    return 0.4 * m * r * r * np.eye(3)


@kernel
def spherical_shell_inertia(m, r):
    """Thin spherical shell: ``2/3 m r²`` about every axis."""
    return 2.0 / 3.0 * m * r * r * np.eye(3)


@kernel
def cylinder_inertia(m, r, h):
    """Solid circular cylinder, axis z: ``Ixx = Iyy = m(3r² + h²)/12``, ``Izz = m r²/2``."""
    t = m * (3.0 * r * r + h * h) / 12.0
    return np.diag(np.array([t, t, 0.5 * m * r * r]))


@kernel
def ellipsoid_inertia(m, semi_axes):
    """Solid ellipsoid of semi-axes ``(a, b, c)``: ``m/5 · diag(b²+c², a²+c², a²+b²)``."""
    a, b, c = semi_axes[0], semi_axes[1], semi_axes[2]
    return m / 5.0 * np.diag(np.array([b * b + c * c, a * a + c * c, a * a + b * b]))


@kernel
def rod_inertia(m, length):
    """Thin rod along z: ``Ixx = Iyy = m l²/12``, ``Izz = 0`` (the degenerate, collinear body)."""
    t = m * length * length / 12.0
    return np.diag(np.array([t, t, 0.0]))


@kernel
def cone_inertia(m, r, h):
    """Solid right circular cone, axis z, about its centre of mass.

    The centre of mass lies ``h/4`` above the base, so in these axes the base is the disc at
    ``z = −h/4`` and the apex is at ``z = 3h/4``. ``Izz = 3/10 m r²``,
    ``Ixx = Iyy = 3/20 m r² + 3/80 m h²``.
    """
    t = 3.0 / 20.0 * m * r * r + 3.0 / 80.0 * m * h * h
    return np.diag(np.array([t, t, 0.3 * m * r * r]))


@kernel
def equivalent_box_half_extents(moments, mass):
    """Half extents (along e1, e2, e3) of the uniform box with the given principal moments and
    mass: the inverse of :func:`box_inertia`, ``a² = 6 (I2 + I3 − I1)/M`` etc. (real by the
    triangle inequalities; clipped at 0 for round-off)."""
    I1, I2, I3 = moments[0], moments[1], moments[2]
    out = np.empty(3)
    out[0] = 0.5 * math.sqrt(max(6.0 / mass * (I2 + I3 - I1), 0.0))
    out[1] = 0.5 * math.sqrt(max(6.0 / mass * (I1 + I3 - I2), 0.0))
    out[2] = 0.5 * math.sqrt(max(6.0 / mass * (I1 + I2 - I3), 0.0))
    return out
