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
   ``t``, in place, and say whether the system is constrained (a no-op returning False
   otherwise); the drivers call it after every step and recompute a cached derivative when it
   returns True.
4. ``body_parameters(system)``: the body's parameter vector (:mod:`poinsot.kernels.layout`),
   for the steppers that use the body's structure (the free-rotor flows).
5. ``state_size(system, y)``: the length of the state. A system whose size is fixed returns a
   compile-time constant, so the steppers' loops over the state are unrolled by the compiler
   (for the rigid body this alone makes a step 1.4× faster); others return ``y.shape[0]``.

Rigid-body systems also step in registers (:func:`~poinsot.kernels.steppers.rk4_tuple_step`):

6. ``lanes(system)``: how many bodies the system holds (1, or an ensemble chunk's members,
   whose states are stored component-major: ``z[c · lanes + lane]``).
7. ``rates(system, t, y, lane) -> 18-tuple``: ``ẏ`` of member ``lane`` at its state ``y`` (a
   tuple), and ``constrain(system, t, y, lane) -> 18-tuple``: the state put back on the
   constraint (the pivot), or unchanged.

A Python object with methods of these names is a system too: the Python backend uses it to
mix user callables with the compiled kernels (see :func:`poinsot.kernels.jit.python_twin`).
"""

from __future__ import annotations

from collections import namedtuple

from .forces import builtin_potential, builtin_wrench
from .jit import generic, kernel
from .layout import HAS_PIVOT, STATE_SIZE, load_state, store_state
from .native import call_project, call_rhs
from .relative import (
    RELATIVE_STATE_SIZE,
    absolute_state_of,
    carrier_motion_ppoly,
    relative_rates,
)
from .rigid import (
    free_rigid_rates,
    pivot_constrained,
    project_onto_pivot,
    rigid_rates,
    shift_torque_to_pivot,
    state_from_principal_into,
)

__all__ = [
    "REGISTER_SYSTEMS",
    "NativeLanes",
    "NativeSystem",
    "RelativeSystem",
    "RelativeUserSystem",
    "RigidLanes",
    "RigidSystem",
    "TorqueFreeLanes",
    "TorqueFreeLanesVaried",
    "TorqueFreeSystem",
    "UserForcesSystem",
    "body_parameters",
    "constrain",
    "lanes",
    "native_vector_field",
    "potential",
    "project",
    "rates",
    "relative_motion",
    "relative_vector_field",
    "rigid_potential",
    "rigid_rates_of",
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
#: of mass, body frame; several forces are summed by one such function), ``work`` (2, 18)
#: scratch space. It holds a compiled function, so numba cannot cache its engine: a process
#: compiles it once.
UserForcesSystem = namedtuple(
    "UserForcesSystem", ["body", "force_kind", "force_params", "axes", "user", "work"]
)
#: A free body with no force: Euler's equation (20) and the free flight of its centre of mass.
#: A type of its own so that its vector field is straight-line code (the fastest path).
TorqueFreeSystem = namedtuple("TorqueFreeSystem", ["body"])
#: An ensemble chunk of ``lanes`` free bodies with no force and one body (BODY_SIZE,): the
#: members differ only by their states, and the compiler vectorises the step across them.
TorqueFreeLanes = namedtuple("TorqueFreeLanes", ["body", "lanes"])
#: An ensemble chunk of free bodies with no force, each with its own inertia: ``bodies``
#: (lanes, BODY_SIZE).
TorqueFreeLanesVaried = namedtuple("TorqueFreeLanesVaried", ["bodies", "lanes"])
#: An ensemble chunk of bodies under built-in forces, free or about a pivot: ``bodies``
#: (lanes, BODY_SIZE), ``force_params`` (lanes, n, FORCE_PARAMS) lowered for each member.
RigidLanes = namedtuple("RigidLanes", ["bodies", "force_kind", "force_params", "lanes"])
#: A body moving relative to a carrier frame (:mod:`poinsot.kernels.relative`) whose motion is
#: piecewise polynomial (a constant is one piece): ``body`` (BODY_SIZE,) in its principal
#: frame, ``inertia`` (3, 3) diag(A, B, C), the lowered forces, ``options`` (OPTIONS_SIZE,),
#: ω_e as ``w_breaks`` (m + 1,), ``w_coeffs`` (k + 1, m, 3) and a_O as ``a_breaks``,
#: ``a_coeffs`` (scipy's ``PPoly`` layout; carrier components). Cached like the rigid systems.
RelativeSystem = namedtuple(
    "RelativeSystem",
    ["body", "inertia", "force_kind", "force_params", "options", "w_breaks", "w_coeffs",
     "a_breaks", "a_coeffs"],
)  # fmt: skip
#: The same with the carrier's motion given by a compiled function ``carrier(t)`` → 9-tuple
#: ``(ω_e, ε_e, a_O)`` (generated from SymPy expressions, or the user's own): numba cannot cache
#: an engine that holds a function, so a process compiles it once per carrier.
RelativeUserSystem = namedtuple(
    "RelativeUserSystem", ["body", "inertia", "force_kind", "force_params", "options", "carrier"]
)
#: A system whose vector field is generated and compiled per model (a Lagrangian model of
#: :mod:`poinsot.lagrange.engine`), called through the addresses of its entry points
#: (:mod:`poinsot.kernels.native`): ``rhs`` and ``project`` (int64; ``project`` 0 for none),
#: the model's parameters ``p`` (k,) and inputs ``u`` (j,), and ``gains`` (2,) the constraint
#: stabilisation's (α, β). One type for every model: the drivers compiled for it are cached.
NativeSystem = namedtuple("NativeSystem", ["rhs", "project", "p", "u", "gains"])
#: An ensemble chunk of one generated model: member ``i`` has the parameters ``P[i]`` and the
#: inputs ``U[i]`` (``P`` (m, k), ``U`` (m, j)).
NativeLanes = namedtuple("NativeLanes", ["rhs", "project", "P", "U", "gains"])


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


@generic
def lanes(system):
    """The number of bodies (members) the system holds."""


@generic
def rates(system, t, y, lane):
    """``ẏ`` (18-tuple) of member ``lane`` at its state ``y`` (an 18-tuple)."""


@generic
def constrain(system, t, y, lane):
    """Member ``lane``'s state ``y`` (an 18-tuple) put back on its constraint, or unchanged."""


# --------------------------------------------------------------------------- one rigid body
@kernel(inline=True)
def rigid_wrench_of(body, force_kind, force_params, t, y):
    """Total wrench of the lowered forces about the reference point (the pivot when there is
    one: ``τ_P = τ_G + c × QᵀF``), for a state ``y`` (array or tuple)."""
    Fx, Fy, Fz, tx, ty, tz = builtin_wrench(force_kind, force_params, body, t, y)
    tx, ty, tz = shift_torque_to_pivot(body, y, Fx, Fy, Fz, tx, ty, tz)
    return Fx, Fy, Fz, tx, ty, tz


@kernel(inline=True)
def rigid_rates_of(body, force_kind, force_params, t, y):
    """Eqs (07)–(09) under the lowered forces: ``ẏ`` (18-tuple)."""
    Fx, Fy, Fz, tx, ty, tz = rigid_wrench_of(body, force_kind, force_params, t, y)
    return rigid_rates(body, y, Fx, Fy, Fz, tx, ty, tz)


@wrench.register(RigidSystem)
@kernel(inline=True)
def rigid_wrench(system, t, y):
    """Total wrench of the lowered forces about the reference point: a 6-tuple."""
    return rigid_wrench_of(system.body, system.force_kind, system.force_params, t, y)


@rates.register(RigidSystem)
@kernel(inline=True)
def _rigid_rates(system, t, y, lane):
    return rigid_rates_of(system.body, system.force_kind, system.force_params, t, y)


@vector_field.register(RigidSystem)
@kernel(inline=True)
def rigid_vector_field(system, t, y, out):
    """Eqs (07)–(09) under the lowered forces."""
    store_state(out, 0, 1, rigid_rates_of(system.body, system.force_kind, system.force_params,
                                          t, y))  # fmt: skip


@constrain.register(RigidSystem)
@kernel(inline=True)
def _rigid_constrain(system, t, y, lane):
    return pivot_constrained(system.body, y)


@project.register(RigidSystem)
@kernel(inline=True)
def _rigid_project(system, t, y):
    project_onto_pivot(system.body, y)
    return system.body[HAS_PIVOT] != 0.0


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


@rates.register(TorqueFreeSystem)
@kernel(inline=True)
def _free_rates(system, t, y, lane):
    return free_rigid_rates(system.body, y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@vector_field.register(TorqueFreeSystem)
@kernel(inline=True)
def torque_free_vector_field(system, t, y, out):
    """Eqs (19)–(21): ``M R̈ = 0``, ``A ω̇ + ω × Aω = 0``, ``Q̇ = QΩ``."""
    store_state(out, 0, 1, free_rigid_rates(system.body, y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))


@constrain.register(TorqueFreeSystem)
@kernel(inline=True)
def _free_constrain(system, t, y, lane):
    return y


@project.register(TorqueFreeSystem)
@kernel(inline=True)
def _free_project(system, t, y):
    return False


@potential.register(TorqueFreeSystem)
@kernel(inline=True)
def _free_potential(system, t, y):
    return 0.0


# --------------------------------------------------------------------------- user forces
@wrench.register(UserForcesSystem)
@kernel
def user_forces_wrench(system, t, y):
    """The built-in forces plus the user's compiled ones, evaluated at the body-frame state
    (their torques turned to the principal frame: ``τ_p = Eᵀ τ``), about the reference point."""
    Fx, Fy, Fz, tx, ty, tz = builtin_wrench(
        system.force_kind, system.force_params, system.body, t, y
    )
    yp = system.work[0]
    store_state(yp, 0, 1, load_state(y, 0, 1))
    yb = system.work[1]
    state_from_principal_into(system.axes, yp, yb)
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


@rates.register(UserForcesSystem)
@kernel
def user_forces_rates(system, t, y, lane):
    """Eqs (07)–(09) under the built-in and the user's compiled forces. Not inlined: the engine
    of this system cannot be cached, and one compiled call keeps its compilation short."""
    Fx, Fy, Fz, tx, ty, tz = user_forces_wrench(system, t, y)
    return rigid_rates(system.body, y, Fx, Fy, Fz, tx, ty, tz)


@vector_field.register(UserForcesSystem)
@kernel(inline=True)
def _user_vector_field(system, t, y, out):
    store_state(out, 0, 1, user_forces_rates(system, t, y, 0))


@constrain.register(UserForcesSystem)
@kernel(inline=True)
def _user_constrain(system, t, y, lane):
    return pivot_constrained(system.body, y)


@project.register(UserForcesSystem)
@kernel(inline=True)
def _user_project(system, t, y):
    project_onto_pivot(system.body, y)
    return system.body[HAS_PIVOT] != 0.0


# --------------------------------------------------------------------------- ensemble chunks
@rates.register(TorqueFreeLanes)
@kernel(inline=True)
def _free_lanes_rates(system, t, y, lane):
    return free_rigid_rates(system.body, y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@rates.register(TorqueFreeLanesVaried)
@kernel(inline=True)
def _free_varied_rates(system, t, y, lane):
    return free_rigid_rates(system.bodies[lane], y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@rates.register(RigidLanes)
@kernel(inline=True)
def _rigid_lanes_rates(system, t, y, lane):
    return rigid_rates_of(system.bodies[lane], system.force_kind, system.force_params[lane], t, y)


@constrain.register(TorqueFreeLanes)
@constrain.register(TorqueFreeLanesVaried)
@kernel(inline=True)
def _free_lanes_constrain(system, t, y, lane):
    return y


@constrain.register(RigidLanes)
@kernel(inline=True)
def _rigid_lanes_constrain(system, t, y, lane):
    return pivot_constrained(system.bodies[lane], y)


# --------------------------------------------------------------------------- shared answers
for _type in (RigidSystem, TorqueFreeSystem, UserForcesSystem):

    @body_parameters.register(_type)
    @kernel(inline=True)
    def _one_body_parameters(system):
        return system.body

    @lanes.register(_type)
    @kernel(inline=True)
    def _one_lane(system):
        return 1


for _type in (RigidSystem, TorqueFreeSystem, UserForcesSystem):

    @state_size.register(_type)
    @kernel(inline=True)
    def _rigid_state_size(system, y):
        return STATE_SIZE


for _type in (TorqueFreeLanes, TorqueFreeLanesVaried, RigidLanes):

    @lanes.register(_type)
    @kernel(inline=True)
    def _chunk_lanes(system):
        return system.lanes

    @state_size.register(_type)
    @kernel(inline=True)
    def _chunk_state_size(system, y):
        return STATE_SIZE * system.lanes


# --------------------------------------------------------------------------- relative motion
@generic
def relative_motion(system, t):
    """The carrier's motion ``(ω_e, ε_e, a_O)`` (9-tuple, carrier components) at ``t``."""


@relative_motion.register(RelativeSystem)
@kernel(inline=True)
def _ppoly_motion(system, t):
    return carrier_motion_ppoly(system.w_breaks, system.w_coeffs, system.a_breaks,
                                system.a_coeffs, t)  # fmt: skip


@relative_motion.register(RelativeUserSystem)
@kernel(inline=True)
def _user_motion(system, t):
    return system.carrier(t)


@kernel(inline=True)
def relative_vector_field(system, t, y, out):
    """The compact relative Euler equation (11)–(12) with the carrier's kinematics
    (:func:`~poinsot.kernels.relative.relative_rates`), the physical forces evaluated at the
    absolute state."""
    motion = relative_motion(system, t)
    s = absolute_state_of(y, motion)
    Fx, Fy, Fz, tx, ty, tz = builtin_wrench(system.force_kind, system.force_params,
                                            system.body, t, s)  # fmt: skip
    r = relative_rates(system.body, system.inertia, system.options, y, motion,
                       Fx, Fy, Fz, tx, ty, tz)  # fmt: skip
    for k in range(RELATIVE_STATE_SIZE):
        out[k] = r[k]


@kernel(inline=True)
def _relative_potential(system, t, y):
    s = absolute_state_of(y, relative_motion(system, t))
    return builtin_potential(system.force_kind, system.force_params, system.body, t, s)


@kernel(inline=True)
def _general_no_rates(system, t, y, lane):
    # The rigid-only steps (RK4 in registers, RKMK, splitting) are compiled for every system
    # type but never run for the general ones (relative motion, generated models): the Python
    # layer refuses those methods, and RK4 runs its tableau through the general step.
    if lane >= 0:
        raise TypeError("this system is stepped by the general Runge-Kutta steps")
    return y


@kernel(inline=True)
def _general_no_wrench(system, t, y):
    if t == t:
        raise TypeError("this system has no rigid-body wrench")
    return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


@kernel(inline=True)
def _relative_project(system, t, y):
    return False


@kernel(inline=True)
def _relative_state_size(system, y):
    return RELATIVE_STATE_SIZE


for _type in (RelativeSystem, RelativeUserSystem):
    vector_field.register(_type)(relative_vector_field)
    potential.register(_type)(_relative_potential)
    rates.register(_type)(_general_no_rates)
    constrain.register(_type)(_general_no_rates)
    wrench.register(_type)(_general_no_wrench)
    project.register(_type)(_relative_project)
    state_size.register(_type)(_relative_state_size)
    body_parameters.register(_type)(_one_body_parameters)
    lanes.register(_type)(_one_lane)


# --------------------------------------------------------------------------- native (generated)
@vector_field.register(NativeSystem)
@kernel(inline=True)
def native_vector_field(system, t, y, out):
    """The model's generated ``rhs`` (:func:`~poinsot.kernels.native.call_rhs`)."""
    call_rhs(system.rhs, t, y, system.p, system.u, system.gains[0], system.gains[1], out)


@project.register(NativeSystem)
@kernel(inline=True)
def _native_project(system, t, y):
    if system.project == 0:
        return False
    return call_project(system.project, t, y, system.p, system.u) != 0


@kernel(inline=True)
def _native_state_size(system, y):
    return y.shape[0]


@kernel(inline=True)
def _native_no_potential(system, t, y):
    return 0.0


@kernel(inline=True)
def _native_body_parameters(system):
    return system.gains  # a float vector for the rigid-only branches, which never run


state_size.register(NativeSystem)(_native_state_size)
rates.register(NativeSystem)(_general_no_rates)
constrain.register(NativeSystem)(_general_no_rates)
wrench.register(NativeSystem)(_general_no_wrench)
potential.register(NativeSystem)(_native_no_potential)
body_parameters.register(NativeSystem)(_native_body_parameters)
lanes.register(NativeSystem)(_one_lane)

#: The system types that step in registers (RK4 on 18-tuples): the rigid bodies.
REGISTER_SYSTEMS = (RigidSystem, TorqueFreeSystem, UserForcesSystem, TorqueFreeLanes,
                    TorqueFreeLanesVaried, RigidLanes)  # fmt: skip
