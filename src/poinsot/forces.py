"""Forces and torques on a rigid body (THEORY.md §1, eqs (07)–(08)).

Every force reports, at a state ``(t, R, V, Q, ω)``, its **wrench**: the total force ``F``
in the space frame and its torque ``τ`` about the **centre of mass** in the **body frame**.
The simulator adds the wrenches, shifts torques to the pivot when there is one, and solves
``M R̈ = F`` (07) and ``A ω̇ + ω × Aω = τ`` (08) with ``τ = Σ u_i × Qᵀ F_i``.

Two flags describe what a force allows:

* ``position_only``: the wrench depends on ``(t, R, Q)`` alone, not on velocities, so the
  force can be applied as a *kick* in the symplectic splitting integrator;
* ``has_potential``: the force derives from a potential ``U(t, R, Q)``
  (:meth:`Force.potential`) and total energy ``K + U`` can be reported.

Body points are given in the body's reference configuration (the frame in which the
:class:`~poinsot.bodies.RigidBody` was built); at attitude ``Q`` the point ``p`` sits at
``R + Q (p − c)`` with ``c`` the reference centre of mass.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ._validation import as_positive_scalar, as_scalar, as_vector3

__all__ = [
    "CentralGravity",
    "CustomForce",
    "Force",
    "ForceContext",
    "ForceError",
    "Gravity",
    "LinearDrag",
    "ParticleForce",
    "PointForce",
    "QuadraticDrag",
    "Spring",
    "Torque",
]

_ZERO = np.zeros(3)


class ForceError(ValueError):
    """A force (usually a user callable) returned something unusable."""


class ForceContext:
    """The state a force sees: time, centre of mass ``R``, its velocity ``V`` (space frame),
    attitude ``Q`` and body angular velocity ``omega``, plus the body. Particle positions and
    velocities are computed on first use."""

    __slots__ = ("Q", "R", "V", "_r", "_v", "body", "omega", "t")

    def __init__(self, body, t, R, V, Q, omega):
        self.body, self.t, self.R, self.V, self.Q, self.omega = body, t, R, V, Q, omega
        self._r = self._v = None

    def point_position(self, offset_body):
        """Space position of the body point at ``offset_body`` (3,) from the centre of mass."""
        return self.R + self.Q @ offset_body

    def point_velocity(self, offset_body):
        """Space velocity ``V + Q(ω × b)`` of the body point at offset ``b``."""
        return self.V + self.Q @ np.cross(self.omega, offset_body)

    @property
    def particle_positions(self):
        """``r_i = Q u_i + R``, shape (N, 3)."""
        if self._r is None:
            self._r = self.body.u @ self.Q.T + self.R
        return self._r

    @property
    def particle_velocities(self):
        """``ṙ_i = Q(ω × u_i) + Ṙ``, shape (N, 3)."""
        if self._v is None:
            self._v = np.cross(self.omega, self.body.u) @ self.Q.T + self.V
        return self._v


class Force:
    """Base class: subclasses implement :meth:`wrench` and, if conservative, :meth:`potential`.

    Attributes
    ----------
    position_only : bool
        True when the wrench depends on ``(t, R, Q)`` only (splitting kicks allowed).
    has_potential : bool
        True when :meth:`potential` is implemented.
    """

    position_only: bool = False
    has_potential: bool = False

    @property
    def name(self) -> str:
        return type(self).__name__

    def bind(self, body) -> None:
        """Check the force applies to ``body`` (called once, before integration)."""

    def wrench(self, ctx: ForceContext) -> tuple[np.ndarray, np.ndarray]:
        """``(F (3,) space frame, τ (3,) body frame about the centre of mass)``."""
        raise NotImplementedError

    def potential(self, ctx: ForceContext) -> float:
        """Potential energy ``U``, defined up to a constant."""
        raise NotImplementedError(f"{self.name} has no potential")

    def __repr__(self) -> str:
        return self.name


def _check_output(value, shape, force: Force, what: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != shape:
        raise ForceError(
            f"force {force.name} returned {what} of shape {arr.shape}, expected {shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise ForceError(f"force {force.name} returned a non-finite {what}: {arr.tolist()}")
    return arr


def _vector_or_callable(value, name: str):
    if callable(value):
        return value
    return as_vector3(value, name)


class Gravity(Force):
    """Uniform gravity ``g`` (3,): ``F = M g`` at the centre of mass, no torque about it.

    ``U = −M g·R``. For a particle body this equals ``F_i = m_i g`` on every particle.

    Examples
    --------
    >>> Gravity((0, 0, -9.8)).g.tolist()
    [0.0, 0.0, -9.8]
    """

    position_only = True
    has_potential = True

    def __init__(self, g=(0.0, 0.0, -9.81)):
        self.g = as_vector3(g, "g")

    def wrench(self, ctx):
        return ctx.body.mass * self.g, _ZERO

    def potential(self, ctx):
        return -ctx.body.mass * float(self.g @ ctx.R)

    def __repr__(self):
        return f"Gravity(g={self.g.tolist()})"


class CentralGravity(Force):
    """Gravity of a point mass ``mu = G M_central`` at ``center``, with the gravity-gradient
    terms of MacCullagh's formula when ``gradient=True``.

    ``U = −μM/r − μ/(2r³) (tr A − 3 n̂·A n̂)``, ``n̂`` the unit vector from the centre to the
    body, in body axes. The torque about the centre of mass is ``τ = 3μ/r³ n̂ × (A n̂)`` (the
    gravity-gradient torque); the force is ``−∇U`` of the same expression, so total energy is
    conserved exactly by the model.
    """

    position_only = True
    has_potential = True

    def __init__(self, mu, center=(0.0, 0.0, 0.0), *, gradient: bool = True):
        self.mu = as_positive_scalar(mu, "mu")
        self.center = as_vector3(center, "center")
        self.gradient = bool(gradient)

    def wrench(self, ctx):
        rv = ctx.R - self.center
        r2 = float(rv @ rv)
        if r2 == 0:
            raise ForceError("force CentralGravity: the body's centre of mass is at the centre")
        r = np.sqrt(r2)
        mu, M = self.mu, ctx.body.mass
        F = -mu * M * rv / (r2 * r)
        if not self.gradient:
            return F, _ZERO
        A = ctx.body.inertia
        As = ctx.Q @ A @ ctx.Q.T
        rAr = float(rv @ As @ rv)
        F = F - (
            1.5 * mu * np.trace(A) * rv / r**5
            + 3.0 * mu * (As @ rv) / r**5
            - 7.5 * mu * rAr * rv / r**7
        )
        n = ctx.Q.T @ rv / r
        tau = 3.0 * mu / (r2 * r) * np.cross(n, A @ n)
        return F, tau

    def potential(self, ctx):
        rv = ctx.R - self.center
        r = float(np.linalg.norm(rv))
        U = -self.mu * ctx.body.mass / r
        if self.gradient:
            A = ctx.body.inertia
            n = ctx.Q.T @ rv / r
            U -= self.mu / (2 * r**3) * (np.trace(A) - 3.0 * float(n @ A @ n))
        return U


class ParticleForce(Force):
    """Forces on every particle from one callable ``func(t, r, v) → F``, arrays (N, 3).

    The total force is ``Σ F_i`` and the torque ``Σ u_i × Qᵀ F_i`` (eq. (08)). Needs a body
    built from particles. ``position_only=True`` declares that ``func`` ignores ``v`` (enables
    the splitting integrator).

    Examples
    --------
    The notebook's gravity, particle by particle:

    >>> import numpy as np
    >>> from poinsot import RigidBody
    >>> body = RigidBody.from_particles([1.0, 2.0], [[0, 0, 0], [1, 0, 0]])
    >>> f = ParticleForce(lambda t, r, v: np.outer([1.0, 2.0], [0, 0, -9.8]), name="weight")
    >>> f.name
    'weight'
    """

    def __init__(self, func: Callable, *, name: str | None = None, position_only: bool = False):
        if not callable(func):
            raise TypeError(f"`func` must be callable, found {type(func).__name__}")
        self.func = func
        self._name = name or getattr(func, "__name__", "ParticleForce")
        self.position_only = bool(position_only)

    @property
    def name(self):
        return self._name

    def bind(self, body):
        if not body.has_particles:
            raise ValueError(f"force {self.name}: ParticleForce needs a body built from particles")

    def wrench(self, ctx):
        u = ctx.body.u
        F_i = _check_output(
            self.func(ctx.t, ctx.particle_positions, ctx.particle_velocities),
            u.shape,
            self,
            "particle forces",
        )
        return F_i.sum(axis=0), np.cross(u, F_i @ ctx.Q).sum(axis=0)


class PointForce(Force):
    """A force applied at a body point.

    Parameters
    ----------
    point : array_like, shape (3,)
        The point of application, in the body's reference configuration.
    force : array_like (3,) or callable ``f(t) → (3,)``
        Constant or time-dependent force.
    frame : {"space", "body"}
        ``"space"``: ``force`` is given in the space frame; ``"body"``: it is body-fixed and
        turns with the body (``F = Q f``).
    """

    position_only = True

    def __init__(self, point, force, *, frame: str = "space"):
        self.point = as_vector3(point, "point")
        self.force = _vector_or_callable(force, "force")
        if frame not in ("space", "body"):
            raise ValueError(f"`frame` must be 'space' or 'body', found {frame!r}")
        self.frame = frame
        self._offset = None

    def bind(self, body):
        self._offset = self.point - body.center_of_mass

    def wrench(self, ctx):
        f = self.force(ctx.t) if callable(self.force) else self.force
        f = _check_output(f, (3,), self, "force") if callable(self.force) else f
        F = ctx.Q @ f if self.frame == "body" else f
        return F, np.cross(self._offset, ctx.Q.T @ F)


class Torque(Force):
    """A pure torque (couple), constant or ``f(t) → (3,)``, in the body or the space frame."""

    position_only = True

    def __init__(self, torque, *, frame: str = "body"):
        self.torque = _vector_or_callable(torque, "torque")
        if frame not in ("space", "body"):
            raise ValueError(f"`frame` must be 'space' or 'body', found {frame!r}")
        self.frame = frame

    def wrench(self, ctx):
        tau = self.torque(ctx.t) if callable(self.torque) else self.torque
        tau = _check_output(tau, (3,), self, "torque") if callable(self.torque) else tau
        return _ZERO, (ctx.Q.T @ tau if self.frame == "space" else tau)


class Spring(Force):
    """A linear spring (or elastic tether) from a body point to a fixed anchor in space.

    Tension ``T = k (ℓ − ℓ₀) + c ℓ̇`` along the spring, ``ℓ`` its length; a ``tether`` goes
    slack (no force) when ``ℓ < ℓ₀``. ``U = ½ k (ℓ − ℓ₀)²`` (zero while a tether is slack).
    Damping ``c > 0`` makes the force velocity-dependent (no potential for the damper).
    """

    def __init__(
        self, point, anchor, stiffness, rest_length=0.0, *, damping=0.0, tether: bool = False
    ):
        self.point = as_vector3(point, "point")
        self.anchor = as_vector3(anchor, "anchor")
        self.stiffness = as_positive_scalar(stiffness, "stiffness")
        self.rest_length = as_scalar(rest_length, "rest_length")
        if self.rest_length < 0:
            raise ValueError(f"`rest_length` must be ≥ 0, found {self.rest_length}")
        self.damping = as_scalar(damping, "damping")
        if self.damping < 0:
            raise ValueError(f"`damping` must be ≥ 0, found {self.damping}")
        self.tether = bool(tether)
        self.position_only = self.damping == 0
        self.has_potential = True
        self._offset = None

    def bind(self, body):
        self._offset = self.point - body.center_of_mass

    def _geometry(self, ctx):
        d = self.anchor - ctx.point_position(self._offset)
        length = float(np.linalg.norm(d))
        return d, length

    def wrench(self, ctx):
        d, length = self._geometry(ctx)
        stretch = length - self.rest_length
        if length == 0 or (self.tether and stretch <= 0):
            return _ZERO, _ZERO
        unit = d / length
        tension = self.stiffness * stretch
        if self.damping:
            tension -= self.damping * float(unit @ ctx.point_velocity(self._offset))
        F = tension * unit
        return F, np.cross(self._offset, ctx.Q.T @ F)

    def potential(self, ctx):
        _, length = self._geometry(ctx)
        stretch = length - self.rest_length
        if self.tether and stretch <= 0:
            return 0.0
        return 0.5 * self.stiffness * stretch * stretch


class _Drag(Force):
    """Drag with a translational ``coefficient`` (on the centre of mass) and a ``rotational``
    one (a torque against ω), both ≥ 0."""

    def __init__(self, coefficient, rotational=0.0):
        self.coefficient = as_scalar(coefficient, "coefficient")
        self.rotational = as_scalar(rotational, "rotational")
        if self.coefficient < 0 or self.rotational < 0:
            raise ValueError("drag coefficients `coefficient` and `rotational` must be ≥ 0")


class LinearDrag(_Drag):
    """Linear (Stokes) drag: ``F = −c V`` on the centre of mass, ``τ = −c_rot ω``."""

    def wrench(self, ctx):
        return -self.coefficient * ctx.V, -self.rotational * ctx.omega


class QuadraticDrag(_Drag):
    """Quadratic drag: ``F = −c |V| V`` on the centre of mass, ``τ = −c_rot |ω| ω``."""

    def wrench(self, ctx):
        V, w = ctx.V, ctx.omega
        return (
            -self.coefficient * np.linalg.norm(V) * V,
            -self.rotational * np.linalg.norm(w) * w,
        )


class CustomForce(Force):
    """Any wrench from a callable ``func(ctx) → (F_space (3,), τ_body (3,))`` about the centre
    of mass, ``ctx`` a :class:`ForceContext`; optionally with ``potential(ctx) → float``."""

    def __init__(self, func, *, potential=None, position_only=False, name=None):
        if not callable(func):
            raise TypeError(f"`func` must be callable, found {type(func).__name__}")
        self.func = func
        self._potential = potential
        self.has_potential = potential is not None
        self.position_only = bool(position_only)
        self._name = name or getattr(func, "__name__", "CustomForce")

    @property
    def name(self):
        return self._name

    def wrench(self, ctx):
        out = self.func(ctx)
        if not isinstance(out, tuple | list) or len(out) != 2:
            raise ForceError(f"force {self.name} must return a pair (force, torque)")
        return (
            _check_output(out[0], (3,), self, "force"),
            _check_output(out[1], (3,), self, "torque"),
        )

    def potential(self, ctx):
        if self._potential is None:
            return super().potential(ctx)
        return float(self._potential(ctx))
