"""One rigid body, its forces and an optional fixed point: the system the integrators step
(``docs/theory.md`` §1, eqs (07)–(09)).

:class:`RigidBodySystem` holds no formula. It prepares what the compiled core needs:

* the reference point (the centre of mass, or the pivot) and the principal frame of the inertia
  about it, in which the compiled engine integrates (Euler's equation then takes its component
  form (27)–(29); states are converted to and from the body frame at the boundary);
* the forces, lowered once to arrays (:meth:`~poinsot.forces.Force.lower`); the forces
  themselves are never modified;
* :meth:`RigidBodySystem.problem`, what the core integrates: the body's parameters, the
  lowered forces, the principal axes, and forces given by Python callables, called back from
  the core (the slow path).

It also builds initial states, including the notebook's rules from particle velocities.
"""

from __future__ import annotations

import warnings
from typing import ClassVar

import numpy as np

from . import layout
from ._bindings import inertia as core_inertia
from ._bindings import invariants as core_invariants
from ._bindings import rigid as core_rigid
from ._validation import as_array, as_frame, as_rotation_matrix, as_vector3
from .forces import BodyFrame, Force, ForceContext, _call_user

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

    Attributes
    ----------
    inertia : (3, 3) about the reference point (the pivot, or the centre of mass), body frame.
    principal_moments, principal_axes : of ``inertia`` (ascending; columns, right-handed); the
        moment along a degenerate body's line is set to exactly zero.
    c : (3,) the centre of mass seen from the reference point, body frame.
    """

    #: Names of the blocks of the flat state, for diagnostics.
    state_slices: ClassVar[dict[str, slice]] = layout.STATE_SLICES
    #: The structure the integrators may use (:mod:`poinsot.integrate.problem`).
    structure: ClassVar[str] = "rigid"

    def __init__(self, body, forces=(), pivot=None):
        self.body = body
        self.forces = tuple(forces)
        for i, f in enumerate(self.forces):
            if not isinstance(f, Force):
                raise TypeError(
                    f"`forces[{i}]` must be a poinsot Force (e.g. Gravity, ParticleForce, "
                    f"CustomForce), found {type(f).__name__}"
                )
            f.check(body)
        self.mass = body.mass
        if pivot is None:
            self.pivot = None
            self.c = np.zeros(3)
            self.inertia = np.array(body.inertia)
        else:
            self.pivot = as_vector3(pivot, "pivot")
            self.c = body.center_of_mass - self.pivot
            self.inertia = body.inertia_about(self.pivot)
        if self.pivot is None:  # the body's own decomposition, computed once and cached
            moments, axes = body.principal_moments, body.principal_axes
        else:
            moments, axes = core_inertia.principal_decomposition(self.inertia)
        self._body_params, degenerate = core_rigid.rigid_body_parameters(
            float(body.mass),
            [float(m) for m in moments],
            np.ascontiguousarray(axes, dtype=float),
            [float(x) for x in self.c],
            np.ascontiguousarray(body.inertia, dtype=float),
            self.pivot is not None,
        )
        self.degenerate = bool(degenerate)
        self.principal_moments = self._body_params[layout.MOMENTS : layout.MOMENTS + 3].copy()
        self.principal_axes = np.array(axes)
        E = axes
        frame = BodyFrame(body.center_of_mass, E)
        builtin = [f for f in self.forces if f.compiled]
        #: forces the core calls by address (a C function), and the rest of the user's
        c = tuple(f for f in self.forces if getattr(f, "address", None) is not None)
        self.jitted_forces = tuple(f for f in self.forces if getattr(f, "jitted", False))
        others = tuple(f for f in self.forces if not f.compiled and f not in c)
        if len(c) > 1 or (c and others):  # one address per run: the C forces summed in Python
            c, others = (), tuple(f for f in self.forces if not f.compiled)
        self.c_forces = c
        #: the forces the core calls back in Python (the slow path)
        self.python_forces = others
        self.force_kind = np.array([layout.FORCE_KINDS[f.kind] for f in builtin], dtype=np.int64)
        self.force_params = np.array([f.lower(frame) for f in builtin]).reshape(
            -1, layout.FORCE_PARAMS
        )

    # ----------------------------------------------------------------- properties
    @property
    def compiled(self) -> bool:
        """True when no force is called back in Python: the whole run is compiled code."""
        return not self.python_forces

    @property
    def position_only(self) -> bool:
        """True when every force is position-only (the splitting integrator applies)."""
        return all(f.position_only for f in self.forces)

    @property
    def has_potential(self) -> bool:
        """True when every force has a potential (``K + U`` is reported)."""
        return all(f.has_potential for f in self.forces)

    @property
    def conservative(self) -> bool:
        """True when every force is conservative: total energy is a constant of the motion."""
        return all(f.conservative for f in self.forces)

    @property
    def inertia_inv(self) -> np.ndarray:
        """Inverse (pseudo-inverse for a degenerate body) of :attr:`inertia`."""
        E = self.principal_axes
        inv = np.array([1.0 / m if m != 0 else 0.0 for m in self.principal_moments])
        return E @ np.diag(inv) @ E.T

    # ----------------------------------------------------------------- frames
    def to_internal(self, y) -> np.ndarray:
        """States (n, 18) (or one state (18,)) from the body frame to the principal frame."""
        y = np.asarray(y, dtype=float)
        axes = np.ascontiguousarray(self.principal_axes, dtype=float)
        rows = np.ascontiguousarray(y.reshape(-1, layout.STATE_SIZE))
        return core_rigid.states_principal(axes, rows).reshape(y.shape)

    def from_internal(self, z) -> np.ndarray:
        """States (or their time derivatives) from the principal frame to the body frame."""
        z = np.asarray(z, dtype=float)
        axes = np.ascontiguousarray(self.principal_axes, dtype=float)
        rows = np.ascontiguousarray(z.reshape(-1, layout.STATE_SIZE))
        return core_rigid.states_principal(axes, rows, inverse=True).reshape(z.shape)

    def pivot_point(self, y) -> np.ndarray:
        """The fixed point ``P = R − Q c`` in space, from a body-frame state (with a pivot)."""
        return np.array(core_rigid.pivot_point(self._body_params, self.to_internal(y)))

    def body_parameters(self, pivot_point=None) -> np.ndarray:
        """The body's parameter vector for the engine, with the pivot held at ``pivot_point``."""
        params = self._body_params.copy()
        if self.pivot is not None:
            params[layout.PIVOT : layout.PIVOT + 3] = pivot_point
        return params

    def native(self, y0):
        """What the compiled core's engine reads, from the initial body-frame state ``y0``
        (which fixes where the pivot is in space): ``(body parameters, force kinds, force
        parameters, principal axes, user)``, ``user`` None when every force is built-in, the
        address of the one C function of a :class:`~poinsot.forces.CustomForce` (called by
        address), else a callable ``(t, y_body) → (Fx, Fy, Fz, τx, τy, τz)`` summing the
        other forces (called back from the core: the slow path)."""
        params = self.body_parameters(self.pivot_point(y0) if self.pivot is not None else None)
        user = self.c_forces[0].address if self.c_forces else None
        others = self.python_forces
        if others:
            body = self.body

            def user(t, y):
                ctx = ForceContext(body, t, y[0:3], y[3:6], y[6:15].reshape(3, 3), y[15:18])
                F = np.zeros(3)
                tau = np.zeros(3)
                for f in others:
                    Fi, ti = _call_user(f, f.python_wrench, ctx)
                    F = F + Fi
                    tau = tau + ti
                return (*F.tolist(), *tau.tolist())

        kinds = np.ascontiguousarray(self.force_kind, dtype=np.int64)
        params_f = np.ascontiguousarray(self.force_params, dtype=float).reshape(
            -1, layout.FORCE_PARAMS
        )
        axes = np.ascontiguousarray(self.principal_axes, dtype=float)
        return np.ascontiguousarray(params, dtype=float), kinds, params_f, axes, user

    def problem(self, y0):
        """The system as the compiled core integrates it
        (:class:`~poinsot.integrate.problem.NativeProblem`), from the initial body-frame state
        ``y0``."""
        from .integrate.problem import RIGID_METHODS, NativeProblem

        return NativeProblem(
            core_rigid.integrate_rigid,
            self.native(y0),
            RIGID_METHODS,
            tuple(f.name for f in self.python_forces),
            observes_flips=True,
        )

    # ----------------------------------------------------------------- body-frame evaluation
    def context(self, t, R, V, Q, omega) -> ForceContext:
        return ForceContext(self.body, t, R, V, Q, omega)

    def _rates(self, t, y):
        """``(ẏ, wrench)`` of a body-frame state, in the principal frame (the core)."""
        body, kinds, params, axes, user = self.native(y)
        z = np.ascontiguousarray(self.to_internal(y))
        return core_rigid.rigid_rates(body, kinds, params, axes, user, float(t), z)

    def force_wrenches(self, t, y) -> list[tuple[np.ndarray, np.ndarray]]:
        """Each force's ``(F (3,) space frame, τ (3,) body frame about the centre of mass)`` at
        the body-frame state ``y``, in the order of :attr:`forces`: the built-in ones from
        their lowered rows (nothing is lowered again), the others called."""
        y = np.asarray(y, dtype=float)
        z = np.ascontiguousarray(self.to_internal(y))
        params = self.body_parameters(self.pivot_point(y) if self.pivot is not None else None)
        rows = iter(zip(self.force_kind, self.force_params, strict=True))
        ctx = None
        out = []
        for f in self.forces:
            if f.compiled:
                kind, row = next(rows)
                (F, tau), _ = core_rigid.force_wrench_potential(
                    int(kind), np.ascontiguousarray(row), params, float(t), z
                )
                out.append((np.array(F), self.principal_axes @ np.array(tau)))
            else:
                ctx = ctx or self.context(t, *layout.unpack_state(y))
                out.append(_call_user(f, f.python_wrench, ctx))
        return out

    def wrench(self, t, R, V, Q, omega):
        """Total force (space) and torque (body frame) about the reference point, at a
        body-frame state: ``τ_P = τ_G + c × Qᵀ F`` with a pivot."""
        y = layout.pack_state(
            as_vector3(R, "R"), as_vector3(V, "V"), np.asarray(Q, float), as_vector3(omega, "w")
        )
        w = self._rates(t, y)[1]
        return np.array(w[:3]), self.principal_axes @ np.array(w[3:])

    def rhs(self, t, y) -> np.ndarray:
        """Time derivative of the body-frame 18-state ``[R, V, Q, ω]``: eqs (07)–(09)."""
        y = np.asarray(y, dtype=float)
        return self.from_internal(self._rates(t, y)[0])

    def potential_energies(self, t, Y) -> np.ndarray:
        """Total potential energy of the forces at samples ``t`` (n,), body-frame ``Y`` (n, 18):
        built-in forces by the core, Python forces by their own ``potential``."""
        t = np.asarray(t, dtype=float)
        Y = np.asarray(Y, dtype=float)
        if not len(t):
            return np.zeros(0)
        params = self.body_parameters(self.pivot_point(Y[0]) if self.pivot is not None else None)
        out = core_invariants.potential_energies(
            params,
            np.ascontiguousarray(self.force_kind, dtype=np.int64),
            np.ascontiguousarray(self.force_params, dtype=float).reshape(-1, layout.FORCE_PARAMS),
            np.ascontiguousarray(t),
            np.ascontiguousarray(self.to_internal(Y)),
        )
        for f in self.python_forces + self.c_forces:
            if f.has_potential:
                for i in range(len(t)):
                    R, V, Q, w = layout.unpack_state(Y[i])
                    ctx = self.context(t[i], R, V, Q, w)
                    out[i] += _call_user(f, f.potential, ctx, "the potential of force")
        return out

    # ----------------------------------------------------------------- constraint
    def projector(self, y0):
        """``None`` for a free body; with a pivot, a map ``y ↦ y`` (body frame) that resets
        ``R, V`` from ``Q, ω`` with the pivot held where it is in ``y0``."""
        if self.pivot is None:
            return None
        point = self.pivot_point(y0)
        return lambda y, t=None: self.constrain(y, point)

    def constrain(self, y, pivot_point) -> np.ndarray:
        """With a pivot, reset ``R, V`` of a body-frame state from ``Q, ω`` so that the pivot
        stays exactly at ``pivot_point``."""
        if self.pivot is None:
            return np.array(y, dtype=float)
        y = np.asarray(y, dtype=float)
        z = np.ascontiguousarray(self.to_internal(y)).reshape(-1, layout.STATE_SIZE)
        z = core_rigid.project_onto_pivot(self.body_parameters(pivot_point), z)
        return self.from_internal(z).reshape(y.shape)

    # ----------------------------------------------------------------- initial state
    def initial_state(self, *, omega0, Q0=None, R0=None, V0=None, omega_frame="body"):
        """The flat body-frame initial state.

        ``Q0`` defaults to the identity. Free body: ``R0`` defaults to the body's centre of mass
        and ``V0`` to zero. With a pivot the pivot stays where the body has it (``R0`` then sets
        the initial centre of mass instead, and ``V0`` must be omitted: it follows from ω).
        """
        Q = np.eye(3) if Q0 is None else as_rotation_matrix(Q0, "Q0")
        w = as_vector3(omega0, "omega0")
        if as_frame(omega_frame) == "space":
            w = Q.T @ w
        if self.pivot is not None and V0 is not None:
            raise ValueError("`V0` must be omitted with a `pivot`: it follows from `omega0`")
        line = self.degenerate_line()
        spin = float(w @ line)
        if abs(spin) > 1e-12 * max(float(np.abs(w).max()), 1e-300):  # |w|² may overflow
            warnings.warn(
                "the body is degenerate (all mass on a line): its spin about that line is "
                f"undefined and is dropped (component {spin:.6g} of omega0)",
                DegenerateBodyWarning,
                stacklevel=3,
            )
        none = np.zeros((0, 3))
        return core_rigid.initial_states(
            np.ascontiguousarray(Q[None], dtype=float),
            np.ascontiguousarray(w[None], dtype=float),
            none if R0 is None else as_vector3(R0, "R0")[None],
            none if V0 is None else as_vector3(V0, "V0")[None],
            [float(x) for x in self.body.center_of_mass],
            [float(x) for x in self.c],
            [0.0] * 3 if self.pivot is None else [float(x) for x in self.pivot],
            self.pivot is not None,
            [float(x) for x in line],
        )[0]

    def checked_state(self, y0, name="y0") -> np.ndarray:
        """A body-frame state (18,) given whole (``R, V, Q`` row by row, ``ω``; as
        :meth:`initial_state` returns it), checked: finite, ``Q`` a rotation (within
        :data:`~poinsot._validation.ROTATION_TOLERANCE`, then projected onto SO(3) as ``Q0``
        is) and, with a pivot, ``V`` the velocity that ``ω`` gives the centre of mass about
        the pivot where ``R`` and ``Q`` put it (to 1e-9 of the state's velocities, then
        reset from ``ω`` exactly)."""
        y = as_array(y0, name, (layout.STATE_SIZE,)).copy()
        q = layout.STATE_SLICES["Q"]
        y[q] = as_rotation_matrix(y[q].reshape(3, 3), f"{name}[6:15] (Q, row by row)").ravel()
        if self.pivot is None:
            return y
        held = self.constrain(y, self.pivot_point(y))
        v = layout.STATE_SLICES["V"]
        off = float(np.abs(held[v] - y[v]).max())
        scale = max(float(np.abs(held[v]).max()), float(np.abs(y[v]).max()), 1e-300)
        if off > 1e-9 * scale:
            raise ValueError(f"`{name}[3:6]` (V): with a pivot the velocity follows from ω, "
                             f"{held[v].tolist()}, found {y[v].tolist()} (off by {off:.3g}); "
                             "give the state that `initial_state` returns")  # fmt: skip
        return held

    def degenerate_line(self) -> np.ndarray:
        """The unit line of a degenerate body (all mass on it), zeros for any other body."""
        return self.principal_axes[:, 0].copy() if self.degenerate else np.zeros(3)


def rigid_velocity_from_particles(body, velocities):
    """``(V0, omega0)`` from particle velocities by the notebook's rules (``docs/theory.md`` §1).

    ``Ṙ(0) = Σ m_i ṙ_i / M`` and ``A ω(0) = L(0) − M R(0) × Ṙ(0)``, ``L(0) = Σ m_i r_i × ṙ_i``,
    with the particles at their reference positions (``Q(0) = I``). Velocities that are not a
    rigid motion (``ṙ_i ≠ Ṙ + ω × u_i``) are refused with the largest residual. For a
    degenerate body the minimum-norm ω is returned (the spin about its line is undefined) and a
    :class:`DegenerateBodyWarning` is issued.
    """
    if not body.has_particles:
        raise ValueError("particle velocities need a body built from particles")
    v = as_array(velocities, "particle_velocities", (body.n_particles, 3))
    A = np.asarray(body.inertia)
    if body.is_degenerate:
        warnings.warn(
            "the body is degenerate (all mass on a line): its spin about that line is undefined; "
            "using the minimum-norm omega",
            DegenerateBodyWarning,
            stacklevel=2,
        )
        A_inv = np.linalg.pinv(A, rcond=1e-12, hermitian=True)
    else:
        A_inv = np.linalg.inv(A)
    V, omega, norms = core_rigid.rigid_motion_from_particles(
        np.ascontiguousarray(body.particle_masses, dtype=float),
        np.ascontiguousarray(body.particle_positions, dtype=float),
        np.ascontiguousarray(v, dtype=float),
        [float(x) for x in body.center_of_mass],
        np.ascontiguousarray(A_inv, dtype=float),
    )
    V, omega = np.array(V), np.array(omega)
    worst = int(np.argmax(norms))
    scale = max(float(np.max(np.linalg.norm(v, axis=1))), 1e-300)
    if norms[worst] > RIGIDITY_RTOL * scale + 1e-300:
        raise ValueError(
            "`particle_velocities` are not a rigid motion: largest residual "
            f"|ṙ_i − (Ṙ + ω × u_i)| = {norms[worst]:.3g} at particle {worst}"
        )
    return V, omega
