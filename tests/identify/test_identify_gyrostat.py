"""The gyrostat in the compiled core, from Python: its right-hand side, its regressor and its
integrated motion, each against a route that does not use it (a direct solve of the full
tensor, SciPy's DOP853 on the velocity form written here, the exact torque-free solution)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poinsot import _core
from poinsot.identify.output_error import gyrostat_run
from poinsot.identify.synthetic import rotor_profile
from poinsot.integrate.driver import run_spec
from poinsot.rotation import matrix_from_rotvec

MOMENTS = np.array([1.2e-4, 1.5e-4, 1.8e-4])
AXES = matrix_from_rotvec([0.3, -0.5, 0.8])
INERTIA = AXES @ np.diag(MOMENTS) @ AXES.T


def velocity_form(w, h, h_dot, inertia=INERTIA):
    """``ω̇`` from ``I ω̇ + ω × (I ω + h) + ḣ = 0`` by a linear solve (no principal frame)."""
    return np.linalg.solve(inertia, -np.cross(w, inertia @ w + h) - h_dot)


@settings(max_examples=30, deadline=None)
@given(
    st.lists(st.floats(-40, 40), min_size=3, max_size=3),
    st.lists(st.floats(-3e-3, 3e-3), min_size=3, max_size=3),
    st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3),
)
def test_omega_dot_is_the_velocity_form(w, h, hd):
    got = _core.gyrostat_omega_dot(MOMENTS, AXES, np.array([w]), np.array([h]), np.array([hd]))
    want = velocity_form(np.array(w), np.array(h), np.array(hd))
    scale = np.linalg.norm(want) + 1e-9
    np.testing.assert_allclose(got[0], want, atol=1e-11 * scale)


def test_without_a_rotor_it_is_the_torque_free_euler_equation():
    from poinsot.torquefree import FreeRigidBody

    w = np.array([[3.0, -7.0, 11.0], [0.1, 25.0, -2.0]])
    got = _core.gyrostat_omega_dot(MOMENTS, AXES, w, np.zeros((2, 3)), np.zeros((2, 3)))
    free = FreeRigidBody(MOMENTS)  # the body frame is the principal frame here
    np.testing.assert_allclose(got @ AXES, free.euler_rhs(w @ AXES), rtol=1e-12)


def test_the_regressor_reproduces_the_equation():
    rng = np.random.default_rng(4)
    n = 50
    w, wd = rng.normal(0, 20, (n, 3)), rng.normal(0, 300, (n, 3))
    s, sd = rng.uniform(200, 1300, n), rng.normal(0, 5e3, n)
    a = np.array([0.0, 0.6, 0.8])
    J = 1.7e-6
    phi = _core.gyrostat_regressor(w, wd, s, sd, a)
    theta = np.array([*INERTIA.diagonal(), INERTIA[0, 1], INERTIA[0, 2], INERTIA[1, 2], J])
    h = J * s[:, None] * a
    want = wd @ INERTIA + np.cross(w, w @ INERTIA + h) + J * sd[:, None] * a
    np.testing.assert_allclose(phi @ theta, want, rtol=1e-12, atol=1e-14)


def test_the_integrated_gyrostat_matches_scipy_on_the_velocity_form():
    """RK4 on the momentum form with the rotor sampled at 16 kHz against SciPy's DOP853 on
    the velocity form with the profile's exact ω_R(t) and ω̇_R(t)."""
    from scipy.integrate import solve_ivp

    a, J = np.array([0.0, 0.6, 0.8]), 1.7e-6
    t = np.arange(2001) / 4000.0
    tr = np.arange(8001) / 16000.0
    speed, _ = rotor_profile(tr)

    def rhs(time, w):
        s, sd = rotor_profile(np.array([time]))
        return velocity_form(w, J * s[0] * a, J * sd[0] * a)

    w0 = np.array([12.0, -20.0, 6.0])
    ref = solve_ivp(rhs, (0, 0.5), w0, method="DOP853", t_eval=t, rtol=1e-12, atol=1e-12).y.T
    run = gyrostat_run(t, 1.0 / 16000)
    got = _core.gyrostat_omegas(MOMENTS[None], AXES[None], np.array([J]), w0[None], run, tr,
                                speed, a)[0]  # fmt: skip
    assert np.abs(got - ref).max() < 1e-6 * np.abs(ref).max()
    # and the rotor does matter here: J = 0 is far off
    free = _core.gyrostat_omegas(MOMENTS[None], AXES[None], np.zeros(1), w0[None], run, tr,
                                 speed, a)[0]  # fmt: skip
    assert np.abs(free - ref).max() > 1.0


def test_members_are_independent_and_match_single_runs():
    t = np.arange(401) / 4000.0
    speed = np.linspace(200, 900, 401)
    a = np.array([1.0, 0.0, 0.0])
    w0 = np.array([[10.0, 2.0, -3.0], [0.0, 20.0, 1.0], [5.0, 5.0, 5.0]])
    moments = np.array([MOMENTS, MOMENTS * [1, 1.1, 1], MOMENTS * 2])
    axes = np.array([AXES, np.eye(3), AXES.T])
    J = np.array([1.7e-6, 0.0, 3e-6])
    run = gyrostat_run(t, 0.0)
    batch = _core.gyrostat_omegas(moments, axes, J, w0, run, t, speed, a)
    for i in range(3):
        one = _core.gyrostat_omegas(moments[i : i + 1], axes[i : i + 1], J[i : i + 1],
                                    w0[i : i + 1], run, t, speed, a)  # fmt: skip
        np.testing.assert_array_equal(batch[i], one[0])
    np.testing.assert_allclose(batch[:, 0], w0, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize(
    ("change", "name"),
    [
        ({"spec": gyrostat_run(np.array([0.0, 0.1, 0.1]), 0.0)}, "`t_eval`"),
        ({"spec": run_spec("splitting", t_end=0.2, dt=0.1, t_eval=[0.0, 0.2])}, "rigid body"),
        ({"rotor_t": np.array([0.0, 2.0, 1.0])}, "`rotor_t`"),
        ({"rotor_speed": np.array([1.0, 2.0])}, "`rotor_speed`"),
        ({"omega0": np.zeros((2, 3))}, "`omega0`"),
        ({"axes": np.zeros((1, 3, 2))}, "`axes`"),
        ({"rotor_axis": np.zeros(2)}, "`rotor_axis`"),
    ],
)
def test_binding_refuses_bad_arguments_by_name(change, name):
    args = {
        "moments": MOMENTS[None],
        "axes": AXES[None],
        "rotor_inertia": np.zeros(1),
        "omega0": np.ones((1, 3)),
        "spec": gyrostat_run(np.array([0.0, 0.1, 0.2]), 0.0),
        "rotor_t": np.array([0.0, 1.0, 2.0]),
        "rotor_speed": np.array([1.0, 2.0, 3.0]),
        "rotor_axis": np.array([0.0, 0.0, 1.0]),
    }
    args.update(change)
    with pytest.raises(ValueError, match=name):
        _core.gyrostat_omegas(**args)


def test_the_fits_run_takes_its_method_from_the_spec():
    """The gyrostat runs through the run contract: a DOP853 spec at tight tolerances gives
    the motion RK4 gives at a fine step (two routes), and the fit's spec is built once per
    stretch and shared by every call."""
    from poinsot.integrate.control import StepSizeController

    t = np.arange(401) / 4000.0
    speed = np.linspace(200, 900, 401)
    a, J = np.array([0.0, 0.6, 0.8]), np.array([1.7e-6])
    w0 = np.array([[10.0, -20.0, 5.0]])
    rk4 = _core.gyrostat_omegas(MOMENTS[None], AXES[None], J, w0, gyrostat_run(t, 1e-5), t,
                                speed, a)[0]  # fmt: skip
    control = StepSizeController(1e-12, 1e-12)
    dop = run_spec("dop853", t_end=t[-1], controller=control, t_eval=t)
    other = _core.gyrostat_omegas(MOMENTS[None], AXES[None], J, w0, dop, t, speed, a)[0]
    np.testing.assert_allclose(other, rk4, rtol=0, atol=1e-9 * np.abs(w0).max())
    assert not np.array_equal(other, rk4)
