"""The vector field of a rigid body under forces, free or about a fixed point (eqs (07)–(09)).

:class:`RigidBodySystem` is the "term" the integrators step: it knows the body, its forces and
an optional pivot, and evaluates

* ``M R̈ = F`` (07) for a free body, or ``R = P + Q c`` for a body turning about the fixed point
  ``P`` (``c`` the centre of mass relative to the pivot, body frame);
* ``A ω̇ + ω × Aω = τ`` (08), with ``A`` and ``τ`` about the centre of mass (free body) or the
  pivot;
* ``Q̇ = Q Ω`` (09).

It also builds initial states, including the notebook's rules from particle velocities.
"""

from __future__ import annotations

import warnings
from typing import ClassVar

import numpy as np

from ._validation import as_array, as_rotation_matrix, as_vector3
from .forces import Force, ForceContext
from .kernels import inertia as kin_inertia
from .kernels import rigid
from .kernels.so3 import hat

__all__ = ["DegenerateBodyWarning", "RigidBodySystem", "rigid_velocity_from_particles"]

#: Relative tolerance on particle velocities that must form a rigid motion.
RIGIDITY_RTOL = 1e-9


class DegenerateBodyWarning(UserWarning):
    """The body's mass lies on a line: its spin about that line is undefined."""


class RigidBodySystem:
    """One rigid body, the forces on it, and an optional fixed point.

    Parameters
    ----------
    body : RigidBody
    forces : sequence of Force
    pivot : array_like (3,), optional
        A body point (reference configuration) held fixed in space.
    """

    #: Names of the blocks of the flat state, for diagnostics.
    state_slices: ClassVar[dict[str, slice]] = {
        "R": slice(0, 3),
        "V": slice(3, 6),
        "Q": slice(6, 15),
        "omega": slice(15, 18),
    }

    def __init__(self, body, forces=(), pivot=None):
        self.body = body
        self.forces = tuple(forces)
        for i, f in enumerate(self.forces):
            if not isinstance(f, Force):
                raise TypeError(
                    f"`forces[{i}]` must be a poinsot Force (e.g. Gravity, ParticleForce, "
                    f"CustomForce), found {type(f).__name__}"
                )
            f.bind(body)
        self.mass = body.mass
        if pivot is None:
            self.pivot = None
            self.c = np.zeros(3)
            self.inertia = np.array(body.inertia)
        else:
            self.pivot = as_vector3(pivot, "pivot")
            self.c = body.center_of_mass - self.pivot
            self.inertia = body.inertia_about(self.pivot)
        moments, axes = kin_inertia.principal_decomposition(self.inertia)  # right-handed axes
        self.principal_moments = moments
        self.principal_axes = axes
        self.degenerate = bool(moments[0] <= 1e-12 * max(moments[2], 1e-300))
        if self.degenerate:
            # minimum-norm solution: no angular acceleration about the body's line
            self.inertia_inv = np.linalg.pinv(self.inertia, rcond=1e-12, hermitian=True)
            self.principal_moments = np.where(moments <= 1e-12 * moments[2], 0.0, moments)
        else:
            self.inertia_inv = np.linalg.inv(self.inertia)

    # ----------------------------------------------------------------- evaluation
    @property
    def position_only(self) -> bool:
        """True when every force is position-only (the splitting integrator applies)."""
        return all(f.position_only for f in self.forces)

    @property
    def has_potential(self) -> bool:
        return all(f.has_potential for f in self.forces)

    def context(self, t, R, V, Q, omega) -> ForceContext:
        return ForceContext(self.body, t, R, V, Q, omega)

    def wrench(self, t, R, V, Q, omega):
        """Total force (space) and torque (body frame) about the reference point.

        The reference point is the centre of mass, or the pivot when there is one:
        ``τ_P = τ_G + c × Qᵀ F``.
        """
        F = np.zeros(3)
        tau = np.zeros(3)
        if self.forces:
            ctx = self.context(t, R, V, Q, omega)
            for f in self.forces:
                Fi, ti = f.wrench(ctx)
                F = F + Fi
                tau = tau + ti
        if self.pivot is not None:
            tau = tau + np.cross(self.c, Q.T @ F)
        return F, tau

    def omega_dot(self, tau, omega):
        return rigid.euler_omega_dot(self.inertia, self.inertia_inv, omega, tau)

    def rhs(self, t, y):
        """Time derivative of the flat 18-state ``[R, V, Q, ω]``."""
        R, V, Q, omega = rigid.unpack_state(y)
        F, tau = self.wrench(t, R, V, Q, omega)
        wdot = self.omega_dot(tau, omega)
        if self.pivot is None:
            acc = F / self.mass
        else:  # R = P + Q c  ⇒  R̈ = Q (ω̇ × c + ω × (ω × c))
            acc = Q @ (np.cross(wdot, self.c) + np.cross(omega, np.cross(omega, self.c)))
        dy = np.empty(rigid.STATE_SIZE)
        dy[0:3] = V
        dy[3:6] = acc
        dy[6:15] = (Q @ hat(omega)).reshape(9)
        dy[15:18] = wdot
        return dy

    def pivot_point(self, y) -> np.ndarray:
        """The fixed point ``P = R − Q c`` in space (only with a pivot)."""
        R, _, Q, _ = rigid.unpack_state(y)
        return R - Q @ self.c

    def projector(self, y0):
        """``None`` for a free body; with a pivot, a map ``y ↦ y`` that resets ``R, V`` from
        ``Q, ω`` with the pivot held where it is in ``y0`` (used by the integrators)."""
        if self.pivot is None:
            return None
        point = self.pivot_point(y0)
        return lambda y, t=None: self.constrain(y, point)

    def constrain(self, y, pivot_point) -> np.ndarray:
        """With a pivot, reset ``R, V`` from ``Q, ω`` so the pivot stays exactly fixed."""
        if self.pivot is None:
            return y
        y = y.copy()
        _, _, Q, omega = rigid.unpack_state(y)
        y[0:3] = pivot_point + Q @ self.c
        y[3:6] = Q @ np.cross(omega, self.c)
        return y

    # ----------------------------------------------------------------- initial state
    def initial_state(self, *, omega0, Q0=None, R0=None, V0=None, omega_frame="body"):
        """The flat initial state.

        ``Q0`` defaults to the identity. Free body: ``R0`` defaults to the body's centre of mass
        and ``V0`` to zero. With a pivot the pivot stays where the body has it (``R0`` then sets
        the initial centre of mass instead, and ``V0`` must be omitted: it follows from ω).
        """
        Q = np.eye(3) if Q0 is None else as_rotation_matrix(Q0, "Q0")
        w = as_vector3(omega0, "omega0")
        if omega_frame == "space":
            w = Q.T @ w
        elif omega_frame != "body":
            raise ValueError(f"`omega_frame` must be 'body' or 'space', found {omega_frame!r}")
        if self.pivot is None:
            R = np.array(self.body.center_of_mass) if R0 is None else as_vector3(R0, "R0")
            V = np.zeros(3) if V0 is None else as_vector3(V0, "V0")
        else:
            if V0 is not None:
                raise ValueError("`V0` must be omitted with a `pivot`: it follows from `omega0`")
            R = self.pivot + Q @ self.c if R0 is None else as_vector3(R0, "R0")
            V = Q @ np.cross(w, self.c)
        if self.degenerate:
            line = self.principal_axes[:, 0]
            spin = float(w @ line)
            if abs(spin) > 1e-12 * max(np.linalg.norm(w), 1e-300):
                warnings.warn(
                    "the body is degenerate (all mass on a line): its spin about that line is "
                    f"undefined and is dropped (component {spin:.6g} of omega0)",
                    DegenerateBodyWarning,
                    stacklevel=3,
                )
                w = w - spin * line
        return rigid.pack_state(R, V, Q, w)


def rigid_velocity_from_particles(body, velocities):
    """``(V0, omega0)`` from particle velocities by the notebook's rules (THEORY.md §1).

    ``Ṙ(0) = Σ m_i ṙ_i / M`` and ``A ω(0) = L(0) − M R(0) × Ṙ(0)``, ``L(0) = Σ m_i r_i × ṙ_i``,
    with the particles at their reference positions (``Q(0) = I``). Velocities that are not a
    rigid motion (``ṙ_i ≠ Ṙ + ω × u_i``) are refused with the largest residual. For a
    degenerate body the minimum-norm ω is returned (the spin about its line is undefined) and a
    :class:`DegenerateBodyWarning` is issued.
    """
    if not body.has_particles:
        raise ValueError("particle velocities need a body built from particles")
    v = as_array(velocities, "particle_velocities", (body.n_particles, 3))
    m = body.particle_masses
    r = body.particle_positions
    M = body.mass
    Rc = body.center_of_mass
    V = (m[:, None] * v).sum(0) / M
    L = (m[:, None] * np.cross(r, v)).sum(0)
    rhs = L - M * np.cross(Rc, V)
    A = body.inertia
    if body.is_degenerate:
        warnings.warn(
            "the body is degenerate (all mass on a line): its spin about that line is undefined; "
            "using the minimum-norm omega",
            DegenerateBodyWarning,
            stacklevel=2,
        )
        omega = np.linalg.pinv(A, rcond=1e-12, hermitian=True) @ rhs
    else:
        omega = np.linalg.solve(A, rhs)
    residual = v - (V + np.cross(omega, body.u))
    norms = np.linalg.norm(residual, axis=1)
    worst = int(np.argmax(norms))
    scale = max(float(np.max(np.linalg.norm(v, axis=1))), 1e-300)
    if norms[worst] > RIGIDITY_RTOL * scale + 1e-300:
        raise ValueError(
            "`particle_velocities` are not a rigid motion: largest residual "
            f"|ṙ_i − (Ṙ + ω × u_i)| = {norms[worst]:.3g} at particle {worst}"
        )
    return V, omega
