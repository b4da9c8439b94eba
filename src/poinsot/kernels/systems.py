"""Systems: the vector fields the steppers integrate, as plain data, and their generic interface.

A *system* is a named tuple of plain arrays; the steppers and drivers of
:mod:`poinsot.kernels.steppers` and :mod:`poinsot.kernels.drivers` call it only through the
generic functions below, and numba specialises them for each system type at compile time (the
compiled engine of a new kind of system — relative motion, a Lagrangian model — is a new named
tuple with its implementations registered here; no stepper is written again).

The contract (``y`` and ``out`` are float arrays of the system's state size):

1. ``vector_field(system, t, y, out)``: ``out = ẏ``.
2. ``wrench(system, t, y) -> (Fx, Fy, Fz, τx, τy, τz)``: for rigid bodies, the total force
   (space frame) and torque about the reference point (body frame), used by the splitting
   integrator's kicks.
3. ``project(system, t, y) -> bool``: put ``y`` back on the system's constraint manifold at time
   ``t``, in place,
   and say whether the system is constrained (a no-op returning False otherwise); the drivers
   call it after every step and recompute a cached derivative when it returns True.
4. ``body_parameters(system)``: the body's parameter vector (:mod:`poinsot.kernels.layout`),
   for the steppers that use the body's structure (the free-rotor flows).
5. ``state_size(system, y)``: the length of the state. A system whose size is fixed returns a
   compile-time constant, so the steppers' loops over the state are unrolled by the compiler
   (for the rigid body this alone makes a step 1.4× faster); others return ``y.shape[0]``.

A Python object with methods of these names is a system too: the Python backend uses it to
mix user callables with the compiled kernels (see :func:`poinsot.kernels.jit.python_twin`).
"""

from __future__ import annotations

from collections import namedtuple

from .forces import builtin_potential, builtin_wrench
from .jit import generic, kernel
from .layout import HAS_PIVOT, STATE_SIZE
from .rigid import (
    free_rigid_derivative,
    project_onto_pivot,
    rigid_derivative,
    shift_torque_to_pivot,
    state_from_principal_into,
)

__all__ = [
    "RigidSystem",
    "TorqueFreeSystem",
    "UserForcesSystem",
    "body_parameters",
    "potential",
    "project",
    "rigid_potential",
    "rigid_vector_field",
    "rigid_wrench",
    "state_size",
    "torque_free_vector_field",
    "vector_field",
    "wrench",
]

#: One rigid body under built-in forces, free or about a pivot: ``body`` (BODY_SIZE,)
#: parameters in its principal frame, ``force_kind`` (n,) int64 codes and ``force_params``
#: (n, FORCE_PARAMS) lowered forces.
RigidSystem = namedtuple("RigidSystem", ["body", "force_kind", "force_params"])
#: A rigid body under built-in forces and the user's own compiled forces: ``axes`` (3, 3) the
#: principal axes in body coordinates, ``user`` a numba-compiled function
#: ``f(t, y_body) -> (Fx, Fy, Fz, τx, τy, τz)`` of the body-frame state (torque about the centre
#: of mass, body frame; several forces are summed by one such function), ``work`` (18,) scratch
#: space. It holds a compiled function, so numba cannot cache its engine: a process compiles
#: it once.
UserForcesSystem = namedtuple(
    "UserForcesSystem", ["body", "force_kind", "force_params", "axes", "user", "work"]
)
#: A free body with no force: Euler's equation (20) and the free flight of its centre of mass.
#: A type of its own so that its vector field is straight-line code (the fastest path).
TorqueFreeSystem = namedtuple("TorqueFreeSystem", ["body"])


@generic
def vector_field(system, t, y, out):
    """``out = ẏ(t, y)``: the system's right-hand side."""


@generic
def wrench(system, t, y):
    """``(Fx, Fy, Fz, τx, τy, τz)``: the force (space) and the torque about the reference
    point (body)."""


@generic
def project(system, t, y):
    """Put ``y`` on the constraint manifold, in place; True when the system is constrained."""


@generic
def body_parameters(system):
    """The body's parameter vector (BODY_SIZE,), principal frame."""


@generic
def state_size(system, y):
    """The number of state components (a compile-time constant where the system fixes it)."""


@generic
def potential(system, t, y):
    """Potential energy of the system's forces at ``(t, y)``."""


@wrench.register(RigidSystem)
@kernel(inline=True)
def rigid_wrench(system, t, y):
    """Total wrench of the lowered forces about the reference point (the pivot when there is
    one: ``τ_P = τ_G + c × QᵀF``): ``(Fx, Fy, Fz, τx, τy, τz)``."""
    Fx, Fy, Fz, tx, ty, tz = builtin_wrench(
        system.force_kind, system.force_params, system.body, t, y
    )
    tx, ty, tz = shift_torque_to_pivot(system.body, y, Fx, Fy, Fz, tx, ty, tz)
    return Fx, Fy, Fz, tx, ty, tz


@vector_field.register(RigidSystem)
@kernel(inline=True)
def rigid_vector_field(system, t, y, out):
    """Eqs (07)–(09) under the lowered forces."""
    Fx, Fy, Fz, tx, ty, tz = rigid_wrench(system, t, y)
    rigid_derivative(system.body, y, Fx, Fy, Fz, tx, ty, tz, out)


@project.register(RigidSystem)
@kernel(inline=True)
def _rigid_project(system, t, y):
    project_onto_pivot(system.body, y)
    return system.body[HAS_PIVOT] != 0.0


@body_parameters.register(RigidSystem)
@kernel(inline=True)
def _rigid_body_parameters(system):
    return system.body


@potential.register(RigidSystem)
@kernel(inline=True)
def rigid_potential(system, t, y):
    """Total potential energy of the lowered forces."""
    return builtin_potential(system.force_kind, system.force_params, system.body, t, y)


# --------------------------------------------------------------------------- torque-free
@wrench.register(TorqueFreeSystem)
@kernel(inline=True)
def _free_wrench(system, t, y):
    return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


@vector_field.register(TorqueFreeSystem)
@kernel(inline=True)
def torque_free_vector_field(system, t, y, out):
    """Eqs (19)–(21): ``M R̈ = 0``, ``A ω̇ + ω × Aω = 0``, ``Q̇ = QΩ``."""
    free_rigid_derivative(system.body, y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, out)


@project.register(TorqueFreeSystem)
@kernel(inline=True)
def _free_project(system, t, y):
    return False


@body_parameters.register(TorqueFreeSystem)
@kernel(inline=True)
def _free_body_parameters(system):
    return system.body


@potential.register(TorqueFreeSystem)
@kernel(inline=True)
def _free_potential(system, t, y):
    return 0.0


@state_size.register(RigidSystem)
@state_size.register(TorqueFreeSystem)
@kernel(inline=True)
def _rigid_state_size(system, y):
    return STATE_SIZE


# --------------------------------------------------------------------------- user forces
@wrench.register(UserForcesSystem)
@kernel
def user_forces_wrench(system, t, y):
    """The built-in forces plus the user's compiled ones, evaluated at the body-frame state
    (their torques turned to the principal frame: ``τ_p = Eᵀ τ``), about the reference point."""
    Fx, Fy, Fz, tx, ty, tz = builtin_wrench(
        system.force_kind, system.force_params, system.body, t, y
    )
    yb = system.work
    state_from_principal_into(system.axes, y, yb)
    E = system.axes
    w = system.user(t, yb)
    Fx += w[0]
    Fy += w[1]
    Fz += w[2]
    tx += E[0, 0] * w[3] + E[1, 0] * w[4] + E[2, 0] * w[5]
    ty += E[0, 1] * w[3] + E[1, 1] * w[4] + E[2, 1] * w[5]
    tz += E[0, 2] * w[3] + E[1, 2] * w[4] + E[2, 2] * w[5]
    tx, ty, tz = shift_torque_to_pivot(system.body, y, Fx, Fy, Fz, tx, ty, tz)
    return Fx, Fy, Fz, tx, ty, tz


@vector_field.register(UserForcesSystem)
@kernel
def user_forces_vector_field(system, t, y, out):
    """Eqs (07)–(09) under the built-in and the user's compiled forces. Not inlined: the engine
    of this system cannot be cached, and one compiled call keeps its compilation short."""
    Fx, Fy, Fz, tx, ty, tz = user_forces_wrench(system, t, y)
    rigid_derivative(system.body, y, Fx, Fy, Fz, tx, ty, tz, out)


@project.register(UserForcesSystem)
@kernel(inline=True)
def _user_project(system, t, y):
    project_onto_pivot(system.body, y)
    return system.body[HAS_PIVOT] != 0.0


@body_parameters.register(UserForcesSystem)
@kernel(inline=True)
def _user_body_parameters(system):
    return system.body


@state_size.register(UserForcesSystem)
@kernel(inline=True)
def _user_state_size(system, y):
    return STATE_SIZE
