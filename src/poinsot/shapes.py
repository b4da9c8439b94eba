"""Closed-form inertia of uniform solids, about the centre of mass, in the solid's own axes.

Each function returns the 3×3 inertia of a solid of mass ``m`` centred on its centre of mass,
aligned with x, y, z (the symmetry axis, where there is one, along z). Values from
Goldstein, Poole & Safko, *Classical Mechanics* (3rd ed.), and Meriam & Kraige, *Engineering
Mechanics: Dynamics*, Appendix B ("Properties of homogeneous solids"). The tests check each
against a converging particle discretisation of the same solid.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "box_inertia",
    "cone_inertia",
    "cylinder_inertia",
    "ellipsoid_inertia",
    "rod_inertia",
    "sphere_inertia",
    "spherical_shell_inertia",
]


def box_inertia(m: float, size) -> np.ndarray:
    """Box with edges ``(a, b, c)`` along x, y, z: ``m/12 · diag(b²+c², a²+c², a²+b²)``."""
    a, b, c = size
    return m / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def sphere_inertia(m: float, r: float) -> np.ndarray:
    """Solid sphere: ``2/5 m r²`` about every axis."""
    return 0.4 * m * r * r * np.eye(3)


def spherical_shell_inertia(m: float, r: float) -> np.ndarray:
    """Thin spherical shell: ``2/3 m r²`` about every axis."""
    return 2.0 / 3.0 * m * r * r * np.eye(3)


def cylinder_inertia(m: float, r: float, h: float) -> np.ndarray:
    """Solid circular cylinder, axis z: ``Ixx = Iyy = m(3r² + h²)/12``, ``Izz = m r²/2``."""
    t = m * (3 * r * r + h * h) / 12.0
    return np.diag([t, t, 0.5 * m * r * r])


def ellipsoid_inertia(m: float, semi_axes) -> np.ndarray:
    """Solid ellipsoid of semi-axes ``(a, b, c)``: ``m/5 · diag(b²+c², a²+c², a²+b²)``."""
    a, b, c = semi_axes
    return m / 5.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def rod_inertia(m: float, length: float) -> np.ndarray:
    """Thin rod along z: ``Ixx = Iyy = m l²/12``, ``Izz = 0`` (the degenerate, collinear body)."""
    t = m * length * length / 12.0
    return np.diag([t, t, 0.0])


def cone_inertia(m: float, r: float, h: float) -> np.ndarray:
    """Solid right circular cone, axis z, about its centre of mass.

    The centre of mass lies ``h/4`` above the base, so in these axes the base is the disc at
    ``z = −h/4`` and the apex is at ``z = 3h/4``. ``Izz = 3/10 m r²``,
    ``Ixx = Iyy = 3/20 m r² + 3/80 m h²``.
    """
    t = 3.0 / 20.0 * m * r * r + 3.0 / 80.0 * m * h * h
    return np.diag([t, t, 0.3 * m * r * r])
