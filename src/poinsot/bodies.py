"""Rigid bodies and their mass properties (docs/theory.md §1, eqs (04), (10)–(15)).

A :class:`RigidBody` is its mass, centre of mass and inertia operator about the centre of mass,
expressed in the reference frame in which it was built (the body frame at ``Q = I``). Bodies
built from particles also keep the particles, so the offsets ``u_i`` of eq. (04) and the
particle forces of eq. (08) are available. Bodies are immutable: every array they return is
read-only.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable
from functools import cached_property

import numpy as np

from ._bindings import inertia as core_inertia
from ._validation import (
    as_array,
    as_positive_array,
    as_positive_scalar,
    as_rotation_matrix,
    as_vector3,
)

__all__ = ["SYMMETRY_CLASSES", "RigidBody", "UnphysicalInertiaWarning"]

#: Relative tolerance (to the largest principal moment) used to accept inertia matrices typed in
#: by hand (symmetry of the matrix, positive semi-definiteness, the triangle inequality).
DEFAULT_RTOL = 1e-9
#: Two principal moments closer than this, relative to the largest, are equal (one tolerance for
#: every class: ``crates/core/src/inertia.rs``).
SYMMETRY_RTOL = core_inertia.SYMMETRY_RTOL
SYMMETRY_CLASSES = core_inertia.SYMMETRY_CLASSES


class UnphysicalInertiaWarning(UserWarning):
    """Principal moments that no mass distribution has (accepted with ``allow_unphysical``)."""


class UnphysicalInertiaError(ValueError):
    """Principal moments that no mass distribution has, refused. ``str()`` says how to accept
    them anyway from Python (``allow_unphysical=True``); ``reason`` is the message without
    that advice, for callers that offer their own way (a scenario's ``allow_unphysical``
    key, a command-line option)."""

    def __init__(self, reason: str, how: str = "allow_unphysical=True"):
        self.reason = reason
        super().__init__(f"{reason} ({how} to study the equations anyway)")


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


def check_inertia(J, name: str = "inertia", *, rtol: float = DEFAULT_RTOL,
                  allow_unphysical: bool = False, each: bool = False,
                  definite: bool = False):  # fmt: skip
    """The one check of inertia tensors (the core's ``check_inertia``, ``inertia.rs``):
    finite, symmetric, positive semi-definite, with principal moments that satisfy
    ``I1 + I2 ≥ I3`` (eq. (10)), to ``rtol``. ``J`` is one (3, 3) tensor, or with ``each``
    many (N, 3, 3), named ``name[i]`` in the errors. Returns the ascending moments ((3,) or
    (N, 3)). Moments that break the triangle inequality raise
    :class:`UnphysicalInertiaError`, or warn with ``allow_unphysical``; with ``definite``, the
    inertia of mass on a line (``I1 ≈ 0``: no dynamics about that line) is refused too.

    >>> check_inertia([[2.0, 0, 0], [0, 3.0, 0], [0, 0, 4.0]])
    array([2., 3., 4.])
    """
    J = np.asarray(J, dtype=float)
    codes, moments, asym, line = core_inertia.check_inertia(J, float(rtol))
    codes, moments = np.atleast_1d(codes), moments.reshape(-1, 3)
    asym, line = np.atleast_1d(asym), np.atleast_1d(line)
    for i in np.flatnonzero(codes):
        where = f"`{name}[{i}]`" if each else f"`{name}`"
        I1, I2, I3 = moments[i]
        code = int(codes[i])
        if code == 1:
            raise ValueError(f"{where} must be finite, found {J.reshape(-1, 3, 3)[i].tolist()}")
        if code == 2:
            raise ValueError(f"{where} must be symmetric, found max|J − Jᵀ| = {asym[i]:.3g}")
        if code == 3:
            raise ValueError(f"{where} must be positive semi-definite: principal moments are "
                             f"{I1:.6g}, {I2:.6g}, {I3:.6g}")  # fmt: skip
        message = (
            f"{where}: principal moments must satisfy I1 + I2 ≥ I3 (no mass distribution has "
            f"one moment exceeding the sum of the others), found I1 + I2 = {I1 + I2:.6g} < "
            f"I3 = {I3:.6g}"
        )
        if not allow_unphysical:
            raise UnphysicalInertiaError(message)
        warnings.warn(message + ": accepted with allow_unphysical", UnphysicalInertiaWarning,
                      stacklevel=3)  # fmt: skip
    if definite and line.any():
        i = int(np.flatnonzero(line)[0])
        where = f"`{name}[{i}]`" if each else f"`{name}`"
        raise ValueError(
            f"{where} must be positive definite (mass on a line has no dynamics about it): "
            "principal moments " + ", ".join(f"{x:.6g}" for x in moments[i])
        )
    return moments if each else moments[0]


def _check_inertia(inertia, name: str = "inertia", allow_unphysical: bool = False) -> np.ndarray:
    J = as_array(inertia, name, (3, 3))
    check_inertia(J, name, allow_unphysical=allow_unphysical)
    return 0.5 * (J + J.T)


def _placement(position, orientation) -> tuple[np.ndarray, np.ndarray]:
    pos = np.zeros(3) if position is None else as_vector3(position, "position")
    rot = np.eye(3) if orientation is None else as_rotation_matrix(orientation, "orientation")
    return pos, rot


class RigidBody:
    """A rigid body: mass, centre of mass and inertia about the centre of mass.

    Parameters
    ----------
    mass : float
        Total mass ``M > 0``.
    inertia : array_like, shape (3, 3)
        Inertia operator ``A`` about the centre of mass (eq. (13)): symmetric, positive
        semi-definite, with principal moments satisfying ``I1 + I2 ≥ I3``.
    center_of_mass : array_like, shape (3,), optional
        Position ``R`` of the centre of mass in the reference frame.
    allow_unphysical : bool
        Accept principal moments that break the triangle inequality ``I1 + I2 ≥ I3``, with an
        :class:`UnphysicalInertiaWarning`: Euler's equations stay well posed, and the standard
        test problems of the literature use such moments (Hairer, Lubich & Wanner,
        *Geometric Numerical Integration*, §IV.1: ``I = (2, 1, 2/3)``).

    Examples
    --------
    The notebook's worked example, three unit masses (docs/theory.md §1):

    >>> body = RigidBody.from_particles([1, 1, 1], [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> body.principal_moments.round(6).tolist()
    [0.333333, 1.0, 1.333333]
    >>> body.center_of_mass.round(6).tolist()
    [0.333333, 0.333333, 0.0]
    """

    def __init__(self, mass, inertia, center_of_mass=(0.0, 0.0, 0.0), *, allow_unphysical=False):
        self._mass = as_positive_scalar(mass, "mass")
        self._inertia = _readonly(_check_inertia(inertia, allow_unphysical=bool(allow_unphysical)))
        self._com = _readonly(as_vector3(center_of_mass, "center_of_mass"))
        self._particle_masses = None
        self._particle_offsets = None

    # ----------------------------------------------------------------- constructors
    @classmethod
    def _build(cls, mass, inertia, com, particle_masses=None, offsets=None) -> RigidBody:
        with np.errstate(over="ignore", invalid="ignore"):
            inertia = 0.5 * (inertia + inertia.T)
        if not (np.isfinite(mass) and np.isfinite(inertia).all() and np.isfinite(com).all()):
            raise ValueError(
                "the body's mass properties overflow double precision (mass "
                f"{float(mass):.3g}, inertia finite: {bool(np.isfinite(inertia).all())}, centre "
                "of mass finite: "
                f"{bool(np.isfinite(com).all())}); choose units that keep them below ~1e300"
            )
        body = cls.__new__(cls)
        body._mass = float(mass)
        body._inertia = _readonly(inertia)
        body._com = _readonly(com)
        body._particle_masses = None if particle_masses is None else _readonly(particle_masses)
        body._particle_offsets = None if offsets is None else _readonly(offsets)
        return body

    @classmethod
    def from_particles(cls, masses, positions) -> RigidBody:
        """A body of point masses ``masses`` (N,) at ``positions`` (N, 3), eq. (04).

        Examples
        --------
        >>> RigidBody.from_particles([2.0], [[1.0, 2.0, 3.0]]).is_degenerate
        True
        """
        m = as_positive_array(masses, "masses", (None,))
        r = as_array(positions, "positions", (None, 3))
        if len(m) == 0:
            raise ValueError("`masses` must hold at least one particle, found N = 0")
        if len(m) != len(r):
            raise ValueError(
                f"`masses` and `positions` must have the same length, found {len(m)} and {len(r)}"
            )
        with np.errstate(over="ignore", invalid="ignore"):  # overflow is refused by _build
            com = core_inertia.center_of_mass(m, r)
            u = r - com
            return cls._build(m.sum(), core_inertia.particle_inertia(m, u), com, m, u)

    @classmethod
    def _primitive(cls, mass, inertia_local, position, orientation) -> RigidBody:
        pos, rot = _placement(position, orientation)
        return cls._build(mass, core_inertia.rotate_inertia(inertia_local, rot), pos)

    @classmethod
    def box(cls, mass, size, *, position=None, orientation=None) -> RigidBody:
        """Uniform box with edge lengths ``size = (a, b, c)`` along its x, y, z axes.

        ``A = M/12 · diag(b² + c², a² + c², a² + b²)``.

        Examples
        --------
        >>> RigidBody.box(12.0, (1.0, 2.0, 3.0)).principal_moments.tolist()
        [5.0, 10.0, 13.0]
        """
        m = as_positive_scalar(mass, "mass")
        size = as_positive_array(size, "size", (3,))
        return cls._primitive(m, core_inertia.box_inertia(m, size), position, orientation)

    @classmethod
    def sphere(cls, mass, radius, *, position=None, orientation=None) -> RigidBody:
        """Uniform solid sphere: ``A = 2/5 M r² 𝟙``."""
        m = as_positive_scalar(mass, "mass")
        r = as_positive_scalar(radius, "radius")
        return cls._primitive(m, core_inertia.sphere_inertia(m, r), position, orientation)

    @classmethod
    def spherical_shell(cls, mass, radius, *, position=None, orientation=None) -> RigidBody:
        """Thin uniform spherical shell: ``A = 2/3 M r² 𝟙``."""
        m = as_positive_scalar(mass, "mass")
        r = as_positive_scalar(radius, "radius")
        return cls._primitive(m, core_inertia.spherical_shell_inertia(m, r), position, orientation)

    @classmethod
    def cylinder(cls, mass, radius, height, *, position=None, orientation=None) -> RigidBody:
        """Uniform solid cylinder with its axis along z."""
        m = as_positive_scalar(mass, "mass")
        r = as_positive_scalar(radius, "radius")
        h = as_positive_scalar(height, "height")
        return cls._primitive(m, core_inertia.cylinder_inertia(m, r, h), position, orientation)

    @classmethod
    def ellipsoid(cls, mass, semi_axes, *, position=None, orientation=None) -> RigidBody:
        """Uniform solid ellipsoid with semi-axes ``(a, b, c)`` along x, y, z."""
        m = as_positive_scalar(mass, "mass")
        ax = as_positive_array(semi_axes, "semi_axes", (3,))
        return cls._primitive(m, core_inertia.ellipsoid_inertia(m, ax), position, orientation)

    @classmethod
    def rod(cls, mass, length, *, position=None, orientation=None) -> RigidBody:
        """Thin uniform rod along z: the degenerate (collinear) body, ``I1 = 0``."""
        m = as_positive_scalar(mass, "mass")
        length = as_positive_scalar(length, "length")
        return cls._primitive(m, core_inertia.rod_inertia(m, length), position, orientation)

    @classmethod
    def cone(cls, mass, radius, height, *, position=None, orientation=None) -> RigidBody:
        """Uniform solid cone, axis z, apex up; its centre of mass sits h/4 above the base."""
        m = as_positive_scalar(mass, "mass")
        r = as_positive_scalar(radius, "radius")
        h = as_positive_scalar(height, "height")
        return cls._primitive(m, core_inertia.cone_inertia(m, r, h), position, orientation)

    @classmethod
    def from_mesh(cls, mesh, *, mass=None, density=None) -> RigidBody:
        """A uniform solid bounded by a closed triangle mesh (exact polyhedral integrals).

        Parameters
        ----------
        mesh : path, ``trimesh.Trimesh`` or ``(vertices, faces)``
            A watertight, consistently wound mesh, in the units of the body.
        mass, density : float, optional
            Give at most one. With neither, the density is 1 (mass equals the volume).
        """
        from .mesh import mesh_mass_properties

        if mass is not None and density is not None:
            raise ValueError("give `mass` or `density`, not both")
        volume, centroid, unit_inertia = mesh_mass_properties(mesh)
        if mass is not None:
            rho = as_positive_scalar(mass, "mass") / volume
        else:
            rho = 1.0 if density is None else as_positive_scalar(density, "density")
        return cls._build(rho * volume, rho * unit_inertia, centroid)

    @classmethod
    def compose(cls, parts: Iterable) -> RigidBody:
        """One body made of ``parts``: bodies and particles ``(mass, position)``, rigidly joined.

        Mass adds, the centre of mass is the mass-weighted mean and inertias add after the
        parallel-axis shift to the common centre of mass. When every part is a particle or a
        particle body the result keeps the particles (so ``u`` is defined).
        """
        bodies = []
        for i, part in enumerate(parts):
            if isinstance(part, RigidBody):
                bodies.append(part)
            elif isinstance(part, tuple | list) and len(part) == 2:
                m = as_positive_scalar(part[0], f"parts[{i}] mass")
                r = as_vector3(part[1], f"parts[{i}] position")
                bodies.append(cls._build(m, np.zeros((3, 3)), r, np.array([m]), np.zeros((1, 3))))
            else:
                raise TypeError(
                    f"`parts[{i}]` must be a RigidBody or a (mass, position) particle, "
                    f"found {type(part).__name__}"
                )
        if not bodies:
            raise ValueError("`parts` must contain at least one body or particle")
        masses = np.array([b.mass for b in bodies])
        coms = np.array([b.center_of_mass for b in bodies])
        com = core_inertia.center_of_mass(masses, coms)
        total = sum(
            core_inertia.parallel_axis(b.inertia, b.mass, b.center_of_mass - com) for b in bodies
        )
        if all(b.has_particles for b in bodies):
            pm = np.concatenate([b.particle_masses for b in bodies])
            pos = np.concatenate([b.particle_positions for b in bodies])
            return cls._build(masses.sum(), total, com, pm, pos - com)
        return cls._build(masses.sum(), total, com)

    def placed(self, position=None, orientation=None) -> RigidBody:
        """This body rotated by ``orientation`` about its centre of mass, moved to ``position``.

        ``position`` defaults to the current centre of mass, ``orientation`` to the identity.
        """
        pos = self._com if position is None else as_vector3(position, "position")
        rot = np.eye(3) if orientation is None else as_rotation_matrix(orientation, "orientation")
        offsets = None if self._particle_offsets is None else self._particle_offsets @ rot.T
        return type(self)._build(
            self._mass,
            core_inertia.rotate_inertia(self._inertia, rot),
            pos,
            self._particle_masses,
            offsets,
        )

    # ----------------------------------------------------------------- properties
    @property
    def mass(self) -> float:
        """Total mass ``M``."""
        return self._mass

    @property
    def center_of_mass(self) -> np.ndarray:
        """Centre of mass ``R`` (3,) in the reference frame."""
        return self._com

    @property
    def inertia(self) -> np.ndarray:
        """Inertia operator ``A`` (3, 3) about the centre of mass, eq. (13)."""
        return self._inertia

    def inertia_about(self, point) -> np.ndarray:
        """Inertia (3, 3) about ``point`` (3,), by the parallel-axis theorem."""
        p = as_vector3(point, "point")
        return core_inertia.parallel_axis(self._inertia, self._mass, p - self._com)

    @cached_property
    def _principal(self) -> tuple[np.ndarray, np.ndarray]:
        moments, axes = core_inertia.principal_decomposition(self._inertia)
        return _readonly(moments), _readonly(axes)

    @property
    def principal_moments(self) -> np.ndarray:
        """Principal moments ``(I1, I2, I3)``, ascending, eqs (10)–(11)."""
        return self._principal[0]

    @property
    def principal_axes(self) -> np.ndarray:
        """Principal axes (3, 3), columns ``e1, e2, e3``: orthonormal and right-handed.

        Sign rule: ``e1`` and ``e2`` have their largest-magnitude component positive and
        ``e3 = e1 × e2``. For repeated moments, any orthonormal basis of the eigenspace.
        """
        return self._principal[1]

    def moment_of_inertia(self, axis, point=None) -> float:
        """Moment of inertia ``I(v) = v·Av / v·v`` about the axis along ``axis`` through
        ``point`` (default: the centre of mass); ``I1 ≤ I(v) ≤ I3`` through the centre of mass.
        """
        v = as_vector3(axis, "axis")
        vv = float(v @ v)
        if vv == 0:
            raise ValueError("`axis` must be a non-zero vector")
        J = self._inertia if point is None else self.inertia_about(point)
        return float(v @ J @ v) / vv

    @property
    def planar_inertia(self) -> np.ndarray:
        """Planar inertia tensor ``J' = Σ m ρρᵀ = ½ tr(J) 𝟙 − J`` (paper eqs (3)–(4))."""
        return _readonly(core_inertia.planar_inertia(self._inertia))

    @property
    def equivalent_box_half_extents(self) -> np.ndarray:
        """Half extents ``(a1, a2, a3)`` along ``e1, e2, e3`` of the uniform box with this body's
        mass and principal moments, ``I1 = m (a2² + a3²) / 3`` and cyclically; a side is 0 where
        the moments allow none (``equivalent_box_half_extents`` of ``crates/core/src/shapes.rs``).

        >>> RigidBody.box(12.0, (2.0, 4.0, 6.0)).equivalent_box_half_extents
        array([3., 2., 1.])
        """
        return _readonly(
            core_inertia.equivalent_box_half_extents(self.principal_moments, self._mass)
        )

    @property
    def is_degenerate(self) -> bool:
        """True when ``A`` is singular (I1 ≈ 0): all the mass lies on one line."""
        return bool(
            core_inertia.is_degenerate(self.principal_moments, core_inertia.DEGENERATE_RTOL)
        )

    def classify_symmetry(self, rtol: float = SYMMETRY_RTOL) -> str:
        """``"spherical"`` (I1 = I3), ``"oblate"`` (I1 = I2 < I3), ``"prolate"`` (I1 < I2 = I3)
        or ``"asymmetric"``, with moments equal when they differ by ≤ ``rtol · I3``
        (``symmetry_code`` of ``crates/core/src/inertia.rs``)."""
        return SYMMETRY_CLASSES[core_inertia.symmetry_code(self.principal_moments, float(rtol))]

    @property
    def symmetry(self) -> str:
        """Symmetry class at the default tolerance; see :meth:`classify_symmetry`."""
        return self.classify_symmetry()

    @property
    def has_particles(self) -> bool:
        """True for bodies built from particles (``u`` is defined)."""
        return self._particle_offsets is not None

    def _require_particles(self, what: str) -> None:
        if self._particle_offsets is None:
            raise AttributeError(
                f"`{what}` is defined only for bodies built from particles "
                "(RigidBody.from_particles or compose of particles)"
            )

    @property
    def u(self) -> np.ndarray:
        """Particle offsets ``u_i`` (N, 3) from the centre of mass, eq. (04); ``Σ m_i u_i = 0``."""
        self._require_particles("u")
        return self._particle_offsets

    @property
    def particle_masses(self) -> np.ndarray:
        """Particle masses (N,)."""
        self._require_particles("particle_masses")
        return self._particle_masses

    @property
    def particle_positions(self) -> np.ndarray:
        """Particle positions (N, 3) in the reference configuration, ``R + u_i``."""
        self._require_particles("particle_positions")
        return _readonly(self._com + self._particle_offsets)

    @property
    def n_particles(self) -> int:
        """Number of particles (0 for a body given by its mass properties)."""
        return 0 if self._particle_offsets is None else len(self._particle_offsets)

    def mass_properties(self) -> dict:
        """The mass properties as a JSON-ready dict: mass, centre of mass, inertia, principal
        moments and axes, symmetry class, degeneracy and number of particles."""
        return {
            "mass": self._mass,
            "center_of_mass": self._com.tolist(),
            "inertia": self._inertia.tolist(),
            "principal_moments": self.principal_moments.tolist(),
            "principal_axes": self.principal_axes.tolist(),
            "symmetry": self.symmetry,
            "degenerate": self.is_degenerate,
            "particles": self.n_particles,
        }

    # ----------------------------------------------------------------- display
    def __repr__(self) -> str:
        fmt = np.array2string
        kind = f", particles={self.n_particles}" if self.has_particles else ""
        return (
            f"RigidBody(mass={self._mass:.6g}, center_of_mass={fmt(self._com, precision=6)}, "
            f"principal_moments={fmt(self.principal_moments, precision=6)}, "
            f"symmetry={self.symmetry!r}{kind})"
        )

    def _repr_html_(self) -> str:
        def row(name, value, unit=""):
            return (f"<tr><th style='text-align:left'>{name}</th><td>{value}</td>"
                    f"<td style='color:#555'>{unit}</td></tr>")  # fmt: skip

        def mat(a):
            return "<br>".join(np.array2string(r, precision=6) for r in np.atleast_2d(a))

        rows = [
            row("mass", f"{self._mass:.6g}", "kg"),
            row("centre of mass (body frame)", mat(self._com), "m"),
            row("inertia about the centre of mass (body frame)", mat(self._inertia), "kg·m²"),
            row("principal moments I₁ ≤ I₂ ≤ I₃", mat(self.principal_moments), "kg·m²"),
            row("principal axes e₁, e₂, e₃ (columns, body frame)", mat(self.principal_axes), "1"),
            row("symmetry", self.symmetry + (" (degenerate)" if self.is_degenerate else "")),
        ]
        if self.has_particles:
            rows.append(row("particles", str(self.n_particles)))
        return ("<table><caption>RigidBody</caption><tr><th></th><th>value</th><th>unit</th>"
                "</tr>" + "".join(rows) + "</table>")  # fmt: skip
