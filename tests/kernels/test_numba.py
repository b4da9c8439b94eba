"""Every public kernel compiles in numba's nopython mode and equals its own Python source.

The test enumerates the ``__all__`` of every module of :mod:`poinsot.kernels`: a name is either
a compiled kernel, called here with representative arguments (compiled, then as plain Python,
and the two results compared), or listed in :data:`EXEMPT` with the reason it is not one.
A new kernel without arguments here fails the test.
"""

from __future__ import annotations

import copy
import functools
import importlib
import pkgutil
import types

import numpy as np
import pytest
from numba.core.registry import CPUDispatcher

import poinsot.kernels as kernels_pkg
from poinsot.kernels import layout as L
from poinsot.kernels.jit import jit, python_twin
from poinsot.kernels.observers import NoObserver, flip_observer
from poinsot.kernels.systems import RigidSystem, TorqueFreeSystem

RNG = np.random.default_rng(7)
MODULES = sorted(m.name for m in pkgutil.iter_modules(kernels_pkg.__path__))

# --------------------------------------------------------------------------- sample data
MOMENTS = np.array([1.0, 2.0, 3.0])
Q = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])
Y = np.concatenate([[0.1, -0.2, 0.3], [0.4, 0.1, -0.3], Q.ravel(), [0.3, -0.7, 1.1]])
BODY = L.body_vector(
    2.0, MOMENTS, np.array([0.1, 0.0, -0.2]), np.diag([1.1, 1.9, 2.8]), np.zeros(3), True, -1.0
)
FREE_BODY = L.body_vector(2.0, MOMENTS, np.zeros(3), np.diag(MOMENTS), np.zeros(3), False, -1.0)
KINDS = np.array(list(L.FORCE_KINDS.values()), dtype=np.int64)
PARAMS = RNG.uniform(0.2, 1.0, (len(KINDS), L.FORCE_PARAMS))
PARAMS[1, 1:4] = [5.0, 4.0, -3.0]  # central gravity: its centre away from the body
SYSTEM = RigidSystem(BODY, KINDS, PARAMS)
FREE = TorqueFreeSystem(FREE_BODY)
TETRA = (
    np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
    np.array([[0, 2, 1], [0, 3, 2], [0, 1, 3], [1, 2, 3]]),
)
W3 = RNG.normal(size=(4, 3))
QUATS = RNG.normal(size=(4, 4))
QUATS /= np.linalg.norm(QUATS, axis=1, keepdims=True)


def _out(n=18):
    return np.zeros(n)


INERTIA = np.array([[2.0, 0.1, -0.2], [0.1, 3.0, 0.3], [-0.2, 0.3, 4.0]])
Y33 = np.concatenate([Y, Q.T.ravel(), [1.0, 2.0, 3.0, -0.1, 0.2, 0.3]])


def _ppoly():
    """A cubic piecewise polynomial of ω_e on [0, 1, 2] and a constant a_O."""
    wc = RNG.normal(size=(4, 2, 3))
    return np.array([0.0, 1.0, 2.0]), wc, np.array([0.0, 1.0]), RNG.normal(size=(1, 1, 3))


def _relative_system():
    from poinsot.kernels.systems import RelativeSystem

    return RelativeSystem(FREE_BODY, np.diag(MOMENTS), KINDS, PARAMS, np.array([0.0, 0.0]),
                          *_ppoly())  # fmt: skip


@functools.cache
def _native_engine():
    """A generated model (the pendulum in its angle), compiled in a folder of its own."""
    import os
    import tempfile

    from poinsot.lagrange.engine import compile_system
    from poinsot.models import pendulum_polar

    old = os.environ.get("POINSOT_CACHE_DIR")
    os.environ["POINSOT_CACHE_DIR"] = tempfile.mkdtemp(prefix="poinsot-native-")
    try:
        return compile_system(pendulum_polar().system)  # parameters g, l, m
    finally:
        if old is None:
            del os.environ["POINSOT_CACHE_DIR"]
        else:
            os.environ["POINSOT_CACHE_DIR"] = old


def _native_system():
    return _native_engine().native_system(np.array([9.81, 1.0, 1.0]), np.zeros(0), (10.0, 10.0))


def _native_chunk(method):
    from poinsot.integrate import get_solver

    template = _native_engine().native_lanes(np.array([[9.81, 1.0, 1.0], [9.81, 2.0, 1.0]]),
                                             np.zeros((2, 0)))  # fmt: skip
    Z0 = np.array([[0.3, 0.0], [1.0, -0.5]])
    times = np.array([0.0, 0.02, 0.05])
    out = (np.zeros((2, 3, 2)), *_counters(2))
    if method == "dop853":
        return (template, NoObserver(0.0), CONTROL, Z0, 0.0, 0.05, times, *out)
    solver = get_solver("rk4")
    return (template, NoObserver(0.0), solver.A, solver.B, solver.C, Z0, 0.0, 0.05, 0.01, times,
            *out)  # fmt: skip


def _force_args():
    return (PARAMS, 2, BODY, 0.5, Y)


def _regime():
    from poinsot.kernels.torque_free import regime_into

    out = np.zeros(18)
    regime_into(MOMENTS, 0, 0.3, 1.0, 0.2, out)
    return out


def _attitude():
    from poinsot.kernels.torque_free import attitude_setup_into

    out = np.zeros(13)
    attitude_setup_into(MOMENTS, _regime(), 0.3, 1.0, 0.2, Q, out)
    return out


CONTROL = np.array([1e-8, 1e-10, 0.9, 0.2, 10.0, np.inf, 0.0])

# name -> callable returning the argument tuple (fresh arrays each call)
ARGS = {
    # layout
    "pack_state": lambda: (np.ones(3), np.ones(3), Q, np.ones(3)),
    "load_state": lambda: (np.arange(36.0), 1, 2),
    "store_state": lambda: (np.zeros(36), 1, 2, tuple(Y)),
    "body_vector": lambda: (2.0, MOMENTS, np.zeros(3), np.eye(3), np.zeros(3), False, -1.0),
    # so3
    "hat": lambda: (W3,),
    "hat_into": lambda: (W3[0], np.zeros((3, 3))),
    "vee": lambda: (RNG.normal(size=(4, 3, 3)),),
    "exp_so3": lambda: (W3,),
    "exp_so3_into": lambda: (0.3, -0.2, 0.5, np.zeros((3, 3))),
    "rodrigues": lambda: (W3[0],),
    "log_so3": lambda: (Q,),
    "dexpinv3": lambda: (0.1, 0.2, -0.3, 1.0, 0.5, -0.2),
    "dexpinv": lambda: (W3, W3[::-1].copy()),
    "axis_rotation": lambda: (1, 0.3),
    "quat_multiply_into": lambda: (QUATS[0], QUATS[1], np.zeros(4)),
    "quat_multiply": lambda: (QUATS, QUATS[::-1].copy()),
    "quat_conjugate": lambda: (QUATS,),
    "quat_normalize": lambda: (QUATS * 3.0,),
    "quat_to_matrix_into": lambda: (QUATS[0], np.zeros((3, 3))),
    "quat_to_matrix": lambda: (QUATS,),
    "quat_rotate": lambda: (QUATS, W3),
    "matrix_to_quat_into": lambda: (Q, np.zeros(4)),
    "matrix_to_quat": lambda: (np.stack([Q, Q.T]),),
    "rotvec_to_quat_into": lambda: (W3[0], np.zeros(4)),
    "rotvec_to_quat": lambda: (W3,),
    "quat_to_rotvec_into": lambda: (QUATS[0], np.zeros(3)),
    "quat_to_rotvec": lambda: (QUATS,),
    # inertia
    "center_of_mass": lambda: (RNG.uniform(1, 2, 5), RNG.normal(size=(5, 3))),
    "particle_inertia": lambda: (RNG.uniform(1, 2, 5), RNG.normal(size=(5, 3))),
    "parallel_axis": lambda: (np.eye(3), 2.0, RNG.normal(size=3)),
    "planar_inertia": lambda: (np.diag([1.0, 2, 3]),),
    "rotate_inertia": lambda: (np.diag([1.0, 2, 3]), Q),
    "principal_decomposition": lambda: (np.array([[2.0, 0.3, 0], [0.3, 1, 0.1], [0, 0.1, 3]]),),
    "polyhedron_mass_properties": lambda: TETRA,
    "symmetry_code": lambda: (np.array([1.0, 1.0, 2.0]), 1e-12),
    "is_degenerate": lambda: (np.array([0.0, 1.0, 1.0]), 1e-12),
    # rigid
    "omega_dot_principal": lambda: (1.0, 2.0, 3.0, 1.0, 0.5, 1 / 3, 0.3, -0.2, 0.5, 0.1, 0, 0),
    "euler_omega_dot": lambda: (MOMENTS, W3, W3[::-1].copy()),
    "shift_torque_to_pivot": lambda: (BODY, Y, 1.0, 2.0, 3.0, 0.1, 0.2, 0.3),
    "free_rigid_derivative": lambda: (BODY, Y, 1.0, 2.0, 3.0, 0.1, 0.2, 0.3, _out()),
    "free_rigid_rates": lambda: (BODY, Y, 1.0, 2.0, 3.0, 0.1, 0.2, 0.3),
    "rigid_rates": lambda: (BODY, Y, 1.0, 2.0, 3.0, 0.1, 0.2, 0.3),
    "attitude_rate": lambda: (*Q.ravel(), 0.3, -0.2, 0.5),
    "pivot_constrained": lambda: (BODY, Y),
    "rigid_derivative": lambda: (BODY, Y, 1.0, 2.0, 3.0, 0.1, 0.2, 0.3, _out()),
    "project_onto_pivot": lambda: (BODY, Y.copy()),
    "rotational_energy": lambda: (np.diag(MOMENTS), W3),
    "kinetic_energy": lambda: (np.diag(MOMENTS), 2.0, W3, W3[::-1].copy()),
    "angular_momentum_body": lambda: (np.diag(MOMENTS), W3),
    "angular_momentum_com": lambda: (np.diag(MOMENTS), np.stack([Q] * 4), W3),
    "angular_momentum": lambda: (
        np.diag(MOMENTS),
        2.0,
        W3,
        W3[::-1].copy(),
        np.stack([Q] * 4),
        W3,
    ),
    "omega_space": lambda: (np.stack([Q] * 4), W3),
    "orthogonality_error": lambda: (np.stack([Q] * 4),),
    "state_to_principal_into": lambda: (Q, Y, _out()),
    "state_from_principal_into": lambda: (Q, Y, _out()),
    "states_to_principal": lambda: (Q, np.stack([Y, Y])),
    "states_from_principal": lambda: (Q, np.stack([Y, Y])),
    "rotor_code": lambda: (MOMENTS, 1e-12),
    "rotate_pair_into": lambda: (1, 0.3, Y.copy()),
    "free_rotor_step_into": lambda: (BODY, Y.copy(), 0.01, np.zeros((3, 3)), np.zeros((3, 3))),
    "free_rotor_step": lambda: (MOMENTS, Y[15:18].copy(), Q, 0.01),
    "particle_positions": lambda: (W3[0], Q, RNG.normal(size=(5, 3))),
    "particle_velocities": lambda: (W3[0], Q, W3[1], RNG.normal(size=(5, 3))),
    "particle_trajectories": lambda: (W3, np.stack([Q] * 4), RNG.normal(size=(5, 3))),
    "rigid_body_parameters": lambda: (2.0, MOMENTS, Q, np.array([0.1, 0, 0.2]), np.eye(3), True),
    "rigid_motion_from_particles": lambda: (
        RNG.uniform(1, 2, 5),
        RNG.normal(size=(5, 3)),
        RNG.normal(size=(5, 3)),
        np.zeros(3),
        np.eye(3),
    ),
    "zxz_body_rates": lambda: (W3, W3[::-1].copy()),
    "zxz_angle_rates": lambda: (W3 + np.array([0, 1.0, 0]), W3[::-1].copy()),
    "zxz_matrix_into": lambda: (0.3, 1.1, -0.4, np.zeros((3, 3))),
    # freebody
    "invariants": lambda: (MOMENTS, W3),
    "energy_ellipsoid_semi_axes": lambda: (MOMENTS, 0.5),
    "momentum_ellipsoid_semi_axes": lambda: (MOMENTS, 1.3),
    "cone_coefficients": lambda: (MOMENTS, 0.5, 1.3),
    "euler_jacobian": lambda: (np.diag(MOMENTS), W3[0]),
    # shapes
    "box_inertia": lambda: (2.0, np.array([1.0, 2.0, 3.0])),
    "sphere_inertia": lambda: (2.0, 0.5),
    "spherical_shell_inertia": lambda: (2.0, 0.5),
    "cylinder_inertia": lambda: (2.0, 0.5, 3.0),
    "ellipsoid_inertia": lambda: (2.0, np.array([1.0, 2.0, 3.0])),
    "rod_inertia": lambda: (2.0, 3.0),
    "cone_inertia": lambda: (2.0, 0.5, 3.0),
    "equivalent_box_half_extents": lambda: (MOMENTS, 2.0),
    # elliptic
    "jacobi_agm_scalar": lambda: (0.7, 0.6, 0.4),
    "jacobi_near_one_scalar": lambda: (0.7, 1 - 1e-8, 1e-8),
    "jacobi_sn_cn_dn_am": lambda: (np.linspace(0, 5, 7), 0.7, 0.3),
    "jacobi_reduced_scalar": lambda: (3.3, 0.7, 0.3, 2.0753631352924691),
    "jacobi_reduced": lambda: (np.linspace(-9, 9, 13), 0.7, 0.3, 2.0753631352924691),
    "carlson_rf": lambda: (0.3, 0.7, 1.0),
    "carlson_rj": lambda: (0.3, 0.7, 1.0, 2.5),
    "carlson_rc1p": lambda: (-0.4,),
    "ellipk_m1": lambda: (0.3,),
    "ellipf_scalar": lambda: (4.0, 0.7, 0.3),
    "ellippi_complete": lambda: (-0.6, 0.7, 0.3),
    "ellippi_scalar": lambda: (-0.6, 4.0, 0.7, 0.3),
    "first_kind_from_sn_cn": lambda: (0.6, -0.8, 0.7, 0.3),
    "third_kind_separatrix": lambda: (-2.0, 1.5),
    "third_kind_u_scalar": lambda: (-2.0, 5.5, 0.7, 0.3, 2.0753631352924691),
    "third_kind_u": lambda: (-2.0, np.linspace(-9, 9, 7), 0.7, 0.3),
    # torque_free
    "regime_into": lambda: (MOMENTS, 0, 0.3, 1.0, 0.2, np.zeros(18)),
    "omega_at": lambda: (MOMENTS, _regime(), 0.3, 1.0, 0.2, 2.5),
    "period_of": lambda: (_regime(),),
    "flip_interval_of": lambda: (_regime(),),
    "periods": lambda: (_regime()[None, :],),
    "flip_intervals": lambda: (_regime()[None, :],),
    "attitude_setup_into": lambda: (MOMENTS, _regime(), 0.3, 1.0, 0.2, Q, np.zeros(13)),
    "attitude_at_into": lambda: (
        MOMENTS,
        _regime(),
        _attitude(),
        0.3,
        1.0,
        0.2,
        Q,
        2.5,
        np.zeros((3, 3)),
        np.zeros((3, 3)),
    ),
    "regimes": lambda: (MOMENTS, np.eye(3), 0, W3),
    "exact_omegas": lambda: (MOMENTS, np.eye(3), 0, W3, np.linspace(0, 3, 4)),
    "exact_attitudes": lambda: (MOMENTS, np.eye(3), 0, W3, Q[None], np.linspace(0, 3, 4)),
    # forces
    "moment_about_center": lambda: (0.1, 0.2, 0.3, Y, 1.0, -1.0, 2.0),
    "gravity_wrench": _force_args,
    "gravity_potential": _force_args,
    "central_gravity_wrench": _force_args,
    "central_gravity_potential": _force_args,
    "spring_wrench": _force_args,
    "spring_potential": _force_args,
    "linear_drag_wrench": _force_args,
    "quadratic_drag_wrench": _force_args,
    "point_force_wrench": _force_args,
    "torque_wrench": _force_args,
    "force_wrench_of": lambda: (3, PARAMS, 2, BODY, 0.5, Y),
    "force_potential": lambda: (3, PARAMS, 2, BODY, 0.5, Y),
    "builtin_wrench": lambda: (KINDS, PARAMS, BODY, 0.5, Y),
    "builtin_potential": lambda: (KINDS, PARAMS, BODY, 0.5, Y),
    "force_wrench": lambda: (3, PARAMS[2].copy(), BODY, 0.5, Y),
    "force_potential_of": lambda: (3, PARAMS[2].copy(), BODY, 0.5, Y),
    "potential_energies": lambda: (KINDS, PARAMS, BODY, np.array([0.0, 1.0]), np.stack([Y, Y])),
    # systems (the registered implementations of the generic functions)
    "rigid_wrench": lambda: (SYSTEM, 0.5, Y),
    "rigid_vector_field": lambda: (SYSTEM, 0.5, Y, _out()),
    "rigid_rates_of": lambda: (BODY, KINDS, PARAMS, 0.5, Y),
    "rigid_potential": lambda: (SYSTEM, 0.5, Y),
    "torque_free_vector_field": lambda: (FREE, 0.5, Y, _out()),
    "relative_vector_field": lambda: (_relative_system(), 0.5, Y33, _out(33)),
    "native_vector_field": lambda: (_native_system(), 0.5, np.array([0.4, -0.3]), _out(2)),
    # generated models: ensembles of any state size; small linear systems
    "chunk_states_dop853": lambda: _native_chunk("dop853"),
    "chunk_states_erk": lambda: _native_chunk("erk"),
    "solve_spd_augmented": lambda: (np.array([[4.0, 2.0, 2.0], [2.0, 3.0, 5.0]]), 2),
    "solve_augmented": lambda: (
        np.array([[0.0, 2.0, 1.0, 4.0], [1.0, 1.0, 0.0, 3.0], [2.0, 0.0, 5.0, 1.0]]),
        3,
    ),
    # relative motion
    "transport_moment_of": lambda: (np.diag(MOMENTS), 0.3, -0.2, 0.5, 0.1, 0.4, -0.6),
    "coriolis_moment_of": lambda: (INERTIA, 0.3, -0.2, 0.5, 0.1, 0.4, -0.6),
    "coriolis_three_term_of": lambda: (INERTIA, 0.3, -0.2, 0.5, 0.1, 0.4, -0.6),
    "transport_moment": lambda: (INERTIA, W3, W3[::-1].copy()),
    "coriolis_moment": lambda: (INERTIA, W3, W3[::-1].copy()),
    "coriolis_moment_three_term": lambda: (INERTIA, W3, W3[::-1].copy()),
    "coriolis_moment_particles": lambda: (
        RNG.uniform(1, 2, 5),
        RNG.normal(size=(5, 3)),
        W3,
        W3[::-1].copy(),
    ),
    "planar_inertia_particles": lambda: (RNG.uniform(1, 2, 5), RNG.normal(size=(5, 3))),
    "carrier_motion_ppoly": lambda: (*_ppoly(), 0.7),
    "carrier_motions_ppoly": lambda: (*_ppoly(), np.array([-0.5, 0.2, 0.7, 3.0])),
    "absolute_state_of": lambda: (Y33, tuple(RNG.normal(size=9))),
    "absolute_states": lambda: (np.stack([Y33, Y33]), RNG.normal(size=(2, 9))),
    "relative_rates": lambda: (
        FREE_BODY,
        np.diag(MOMENTS),
        np.array([0.0, 0.0]),
        Y33,
        tuple(RNG.normal(size=9)),
        0.1,
        0.2,
        -0.3,
        0.4,
        -0.5,
        0.6,
    ),
    # steppers
    "evaluate": lambda: (SYSTEM, 0.5, Y, _out()),
    "erk_step": lambda: (SYSTEM, *_rk4_tableau(), 0.0, Y, 0.01, np.zeros((4, 18)), _out(), _out()),
    "rk4_tuple_step": lambda: (SYSTEM, 0.0, tuple(Y), 0.01, 0),
    "rkmk_step": lambda: (
        SYSTEM,
        *_rk4_tableau(),
        0.0,
        Y,
        0.01,
        np.zeros((4, 18)),
        _out(),
        np.zeros((4, 3)),
        np.zeros((3, 3)),
        _out(),
    ),
    "splitting_step": lambda: (
        FREE,
        0.0,
        Y,
        0.01,
        _out(),
        np.zeros((3, 3)),
        np.zeros((3, 3)),
        _out(),
    ),
    "solver_init_into": lambda: (3, SYSTEM, Y, _out()),
    "solver_output_into": lambda: (3, SYSTEM, Y, _out()),
    "dop853_step": lambda: (
        SYSTEM,
        0.0,
        Y,
        _rhs(Y),
        0.01,
        np.zeros((16, 18)),
        _out(),
        _out(),
        _out(),
    ),
    "dop853_error_norm": lambda: (RNG.normal(size=(16, 18)), 0.01, Y, Y + 1e-9, 1e-8, 1e-10),
    "dop853_dense_into": lambda: (
        SYSTEM,
        0.0,
        0.01,
        Y,
        Y + 1e-3,
        _rhs(Y),
        RNG.normal(size=(16, 18)),
        _out(),
        np.zeros((7, 18)),
    ),
    "dop853_interpolate_into": lambda: (RNG.normal(size=(7, 18)), Y, 0.3, _out()),
    "hermite_interpolate_into": lambda: (Y, _rhs(Y), Y + 0.01, _rhs(Y), 0.01, 0.4, _out()),
    "step_size_factor": lambda: (0.5, 7, False, CONTROL),
    "initial_step_size": lambda: (SYSTEM, 0.0, Y, _rhs(Y), 1.0, 7, CONTROL, _out(), _out()),
    # drivers
    "run_rk4": lambda: _fixed_driver_args(),
    "run_erk": lambda: _fixed_driver_args(),
    "run_rkmk": lambda: _fixed_driver_args(),
    "run_splitting": lambda: _fixed_driver_args(system=FREE),
    # rigid: per-state forms and initial states
    "rotational_energy_of": lambda: (np.diag(MOMENTS), 0.3, -0.7, 1.1),
    "kinetic_energy_of": lambda: (np.diag(MOMENTS), 2.0, Y),
    "angular_momentum_com_of": lambda: (np.diag(MOMENTS), Y),
    "orthogonality_error_of": lambda: (Y,),
    "pivot_point_of": lambda: (BODY, Y),
    "initial_states": lambda: (
        Q[None],
        W3,
        np.zeros((0, 3)),
        np.zeros((0, 3)),
        np.ones(3),
        np.array([0.1, 0, -0.2]),
        np.zeros(3),
        True,
        np.zeros(3),
    ),
    # ensembles
    "member_bodies": lambda: (
        2.0,
        np.stack([np.diag(MOMENTS), np.diag([1.5, 2.0, 3.0])]),
        np.array([0.1, 0.0, -0.2]),
        True,
    ),
    "principal_members": lambda: (np.stack([BODY, BODY]), Q[None], np.stack([Y, Y]), True),
    "chunk_rk4": lambda: _chunk_args("rk4"),
    "chunk_erk": lambda: _chunk_args("erk"),
    "chunk_rkmk": lambda: _chunk_args("rkmk4"),
    "chunk_splitting": lambda: _chunk_args("splitting"),
    "chunk_dop853": lambda: (
        _lanes(),
        flip_observer(3),
        CONTROL,
        Q[None],
        np.stack([Y] * 3),
        0.0,
        0.05,
        np.array([0.02, 0.05]),
        np.zeros((3, 2, 18)),
        *_counters(3),
    ),
    "chunk_statistics": lambda: (
        _lanes(),
        Q[None],
        np.diag(MOMENTS)[None],
        2.0,
        0.0,
        np.stack([Y] * 3),
        np.array([0.02, 0.05]),
        np.stack([np.stack([Y, 1.01 * Y])] * 3),
        *_counters(3, float),
    ),
    "run_adaptive": lambda: (
        SYSTEM,
        NoObserver(0.0),
        np.array([0.0, 0.0]),
        Y.copy(),
        _out(),
        0.1,
        CONTROL,
        np.array([0.05, 0.1]),
        1,
        np.zeros(2),
        np.zeros((2, 18)),
        np.zeros(6, dtype=np.int64),
        10**6,
    ),
}


def _rk4_tableau():
    from poinsot.kernels.tableaux import RK4_A, RK4_B, RK4_C

    return RK4_A, RK4_B, RK4_C


def _rhs(y):
    from poinsot.kernels.systems import rigid_vector_field

    out = np.zeros(18)
    rigid_vector_field(SYSTEM, 0.0, y, out)
    return out


def _lanes():
    from poinsot.kernels.systems import RigidLanes

    return RigidLanes(np.stack([BODY] * 3), KINDS[:1], np.stack([PARAMS[:1]] * 3), 3)


def _counters(m, dtype=np.int64):
    return tuple(np.zeros(m, dtype=dtype) for _ in range(3))


def _chunk_args(method):
    from poinsot.integrate import get_solver
    from poinsot.kernels.observers import flip_observer
    from poinsot.kernels.systems import TorqueFreeLanesVaried

    solver = get_solver("rk4" if method == "erk" else method)  # ERK: RK4's tableau as data
    template = TorqueFreeLanesVaried(np.stack([FREE_BODY] * 3), 3) if method != "rk4" else _lanes()
    return (
        template,
        flip_observer(3),
        solver.A,
        solver.B,
        solver.C,
        Q[None],
        np.stack([Y] * 3),
        0.0,
        0.05,
        0.01,
        np.array([0.02, 0.05]),
        np.zeros((3, 2, 18)),
        *_counters(3),
    )


def _fixed_driver_args(system=SYSTEM):
    return (
        system,
        NoObserver(0.0),
        *_rk4_tableau(),
        np.array([0.0, 0.0]),
        Y.copy(),
        0.1,
        0.01,
        np.array([0.05, 0.1]),
        1,
        np.zeros(2),
        np.zeros((2, 18)),
        np.zeros(6, dtype=np.int64),
        10**6,
    )


#: Public names that are not compiled kernels, and why.
EXEMPT = {
    # constants and data
    **{n: "a layout constant" for n in L.__all__ if n.isupper()},
    "STATE_SLICES": "a dict of slices for NumPy code",
    "FORCE_KINDS": "a dict of force-kind codes",
    "unpack_state": "returns NumPy views for any number of leading axes (not a formula)",
    "SYMMETRY_CLASSES": "names of the symmetry codes",
    "SYMMETRY_RTOL": "a tolerance",
    "DEGENERATE_RTOL": "a tolerance",
    "RigidSystem": "a named tuple type (the system's data)",
    "NativeSystem": "a named tuple type (the system's data)",
    "NativeLanes": "a named tuple type (the system's data)",
    "native_vector_field": "calls generated code by address, which Python cannot: compared "
    "with the generated module's own rhs in tests/lagrange/test_engine.py",
    "call_rhs": "an intrinsic (typed in compiled code only; run by native_vector_field)",
    "call_project": "an intrinsic (typed in compiled code only; run by the chunks' projection)",
    "TorqueFreeSystem": "a named tuple type (the system's data)",
    "UserForcesSystem": "a named tuple type (the system's data)",
    "TorqueFreeLanes": "a named tuple type (the system's data)",
    "TorqueFreeLanesVaried": "a named tuple type (the system's data)",
    "RigidLanes": "a named tuple type (the system's data)",
    "NoObserver": "a named tuple type (an observer's data)",
    "FlipObserver": "a named tuple type (an observer's data)",
    "flip_observer": "builds a FlipObserver's arrays (NumPy)",
    "observe": "generic: compiled through the drivers tested here",
    "lanes": "generic: compiled through the registered implementations tested here",
    "rates": "generic: compiled through the registered implementations tested here",
    "constrain": "generic: compiled through the registered implementations tested here",
    "member_system": "generic: compiled through the chunk kernels tested here",
    "block_system": "generic: compiled through the chunk kernels tested here",
    "member_observer": "generic: compiled through the chunk kernels tested here",
    "block_observer": "generic: compiled through the chunk kernels tested here",
    "BLOCK": "a block width",
    "tuple_axpy": "elementwise tuple arithmetic, generated for each length (tests/kernels)",
    "tuple_rk4_combine": "elementwise tuple arithmetic, generated for each length",
    "vector_field": "generic: compiled through the registered implementations tested here",
    "relative_motion": "generic: compiled through the registered implementations tested here",
    "RelativeSystem": "a system type (a named tuple)",
    "RelativeUserSystem": "a system type (a named tuple)",
    "REGISTER_SYSTEMS": "the system types that step in registers",
    "RELATIVE_STATE_SIZE": "a layout size",
    "CARRIER_Q_AT": "a state offset",
    "ORIGIN_AT": "a state offset",
    "ORIGIN_V_AT": "a state offset",
    "MOTION_SIZE": "a layout size",
    "BALANCE_TRANSPORT": "an offset in the options vector",
    "HOLD_COM": "an offset in the options vector",
    "OPTIONS_SIZE": "a layout size",
    "wrench": "generic: compiled through the registered implementations tested here",
    "project": "generic: compiled through the registered implementations tested here",
    "body_parameters": "generic: compiled through the registered implementations tested here",
    "potential": "generic: compiled through the registered implementations tested here",
    "state_size": "generic: compiled through the registered implementations tested here",
    "kernel": "the decorator that compiles kernels",
    "generic": "the decorator that makes generic kernels",
    "jit": "numba.njit of a kernel's source, for tests and user code",
    "python_twin": "builds the Python version of a kernel (the Python backend)",
    "accepts_sequences": "the decorator of the batched kernels' Python entries",
    "kernel_layer_stamp": "a hash of the kernel sources, for numba's cache",
}
for _name in (
    "GRAVITY",
    "CENTRAL_GRAVITY",
    "SPRING",
    "LINEAR_DRAG",
    "QUADRATIC_DRAG",
    "POINT_FORCE",
    "TORQUE",
):
    EXEMPT[_name] = "a force-kind code"
for _name in ("RK4", "ERK", "RKMK", "SPLITTING", "DOP853", "METHOD_CODES"):
    EXEMPT[_name] = "a method code"
for _name in (
    "RTOL",
    "ATOL",
    "SAFETY",
    "MIN_FACTOR",
    "MAX_FACTOR",
    "MAX_STEP",
    "FIRST_STEP",
    "CONTROL_SIZE",
):
    EXEMPT[_name] = "an offset in the controller's parameter vector"
for _name in (
    "RUNNING",
    "FINISHED",
    "NONFINITE",
    "STEP_TOO_SMALL",
    "OUTPUT_FULL",
    "STATUS",
    "N_OUT",
    "NEXT_SAMPLE",
    "N_STEPS",
    "N_FEV",
    "N_REJECTED",
    "COUNTERS_SIZE",
    "CLOCK_SIZE",
    "CHECK_EVERY",
):
    EXEMPT[_name] = "a driver status code or counter offset"
for _name in importlib.import_module("poinsot.kernels.tableaux").__all__:
    EXEMPT[_name] = "a Butcher tableau (data)"
for _module in ("torque_free", "elliptic"):
    for _name in importlib.import_module(f"poinsot.kernels.{_module}").__all__:
        if _name.isupper():
            EXEMPT[_name] = "a regime case code, a row offset or a tolerance"


def _public():
    for module_name in MODULES:
        module = importlib.import_module(f"poinsot.kernels.{module_name}")
        for name in module.__all__:
            yield module_name, name, getattr(module, name)


PUBLIC = list(_public())


@pytest.mark.parametrize(("module", "name"), [(m, n) for m, n, _ in PUBLIC])
def test_public_kernel_compiles_and_equals_python(module, name):
    value = getattr(importlib.import_module(f"poinsot.kernels.{module}"), name)
    if name in EXEMPT:
        assert not isinstance(value, CPUDispatcher) or name in ARGS, name
        return
    kernel = _kernel_of(value)
    assert isinstance(kernel, CPUDispatcher), f"{module}.{name} is public but not a kernel"
    assert name in ARGS, f"{module}.{name}: give representative arguments (or an exemption)"
    args = ARGS[name]()
    compiled = value(*copy.deepcopy(args))
    plain = python_twin(kernel)(*copy.deepcopy(args))
    _assert_same(compiled, plain)


def _kernel_of(value):
    """The compiled kernel behind a public name (``accepts_sequences`` entries wrap one)."""
    inner = getattr(value, "__wrapped__", None)
    return inner if isinstance(inner, CPUDispatcher) else value


def _assert_same(a, b):
    if isinstance(a, tuple):
        assert isinstance(b, tuple) and len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _assert_same(x, y)
    elif a is None:
        assert b is None
    else:
        np.testing.assert_allclose(
            np.asarray(a, float), np.asarray(b, float), rtol=1e-13, atol=1e-15
        )


def test_every_compiled_kernel_has_arguments_here():
    unknown = [
        n for _, n, v in PUBLIC if isinstance(_kernel_of(v), CPUDispatcher) and n not in ARGS
    ]
    assert not unknown
    stale = set(ARGS) - {n for _, n, _ in PUBLIC}
    assert not stale, f"arguments for names that are not public kernels: {sorted(stale)}"


def test_generic_functions_dispatch_on_python_systems():
    from poinsot.kernels.systems import vector_field

    class Harmonic:
        def vector_field(self, t, y, out):
            out[0], out[1] = y[1], -y[0]

    out = np.zeros(2)
    vector_field(Harmonic(), 0.0, np.array([1.0, 2.0]), out)
    assert out.tolist() == [2.0, -1.0]
    with pytest.raises(TypeError, match="does not provide vector_field"):
        vector_field(object(), 0.0, np.zeros(2), out)


def test_jit_compiles_a_kernel_source():
    from poinsot.kernels import so3

    w = np.array([0.3, -0.2, 0.5])
    np.testing.assert_allclose(jit(so3.rodrigues)(w), so3.rodrigues(w), atol=1e-16)
    assert isinstance(python_twin(so3.rodrigues), types.FunctionType)
