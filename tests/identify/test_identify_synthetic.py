"""The synthetic throws are what they claim: the body's inertia by hand, the motion against
SciPy's integrator on the equations written here, the accelerometer against finite
differences, the sensor errors by their statistics."""

from __future__ import annotations

import numpy as np
from identify_throws import throw

from poinsot.identify.synthetic import (
    BLOCK,
    IMU_OFFSET,
    LOGGER,
    LOGGER_OFFSET,
    LOGGER_TURN_DEG,
    logger_block,
    rotor_profile,
)


def _box(m, size):
    a, b, c = size
    return m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def test_logger_block_by_hand():
    """Two boxes, the logger turned about z, shifted to the common centre of mass
    (parallel-axis theorem), then seen from the logger's frame."""
    (bs, bm), (ls, lm) = BLOCK, LOGGER
    c, s = np.cos(np.radians(LOGGER_TURN_DEG)), np.sin(np.radians(LOGGER_TURN_DEG))
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    r = np.asarray(LOGGER_OFFSET)
    com = lm * r / (bm + lm)

    def shifted(m, d):
        return m * (d @ d * np.eye(3) - np.outer(d, d))

    I = _box(bm, bs) + shifted(bm, -com) + R @ _box(lm, ls) @ R.T + shifted(lm, r - com)
    body, p = logger_block()
    assert body.mass == bm + lm
    np.testing.assert_allclose(body.inertia, R.T @ I @ R, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(p, R.T @ (r + R @ IMU_OFFSET - com), atol=1e-15)
    assert body.symmetry == "asymmetric"


def test_torque_free_throw_solves_eulers_equation():
    from scipy.integrate import solve_ivp

    th = throw(rotor=False, seed=2, noise=0.0, bias=0.0)
    I = th.inertia

    def rhs(_, w):
        return np.linalg.solve(I, np.cross(I @ w, w))

    ref = solve_ivp(rhs, (0, 0.5), th.omega_true[0], method="DOP853", t_eval=th.t,
                    rtol=1e-12, atol=1e-12).y.T  # fmt: skip
    assert np.abs(th.omega_true - ref).max() < 1e-8
    np.testing.assert_array_equal(th.omega, th.omega_true)  # no noise, no bias
    assert th.rotor_speed is None and th.accel is None


def test_rotor_throw_solves_the_gyrostat_equation():
    from scipy.integrate import solve_ivp

    th = throw(rotor=True, seed=2)
    I, J, a = th.inertia, th.rotor_inertia, th.rotor_axis

    def rhs(time, w):
        s, sd = rotor_profile(np.array([time]))
        return np.linalg.solve(I, -np.cross(w, I @ w + J * s[0] * a) - J * sd[0] * a)

    ref = solve_ivp(rhs, (0, 0.5), th.omega_true[0], method="DOP853", t_eval=th.t,
                    rtol=1e-12, atol=1e-12).y.T  # fmt: skip
    assert np.abs(th.omega_true - ref).max() < 1e-6
    assert np.abs(th.omega_true).max() <= 30.0
    speed, _ = rotor_profile(th.t)
    np.testing.assert_array_equal(th.rotor_speed, speed)
    assert speed.min() == 200.0 and abs(speed.max() - 1300.0) < 1e-9


def test_sensor_errors_have_the_stated_size():
    th = throw(rotor=True, seed=5, noise=0.02, bias=0.01, saturation=None)
    e = th.omega - th.omega_true - th.gyro_bias
    assert abs(e.std() / 0.02 - 1) < 0.05 and abs(e.mean()) < 0.002
    np.testing.assert_array_equal(np.abs(th.gyro_bias), 0.01)
    clipped = throw(rotor=True, seed=5, noise=0.02, bias=0.01, saturation=20.0)
    assert np.abs(clipped.omega).max() == 20.0
    assert np.abs(clipped.omega_true).max() > 20.0


def test_accelerometer_reads_the_lever_arm():
    """In flight f = ω̇ × p + ω × (ω × p) + b, with ω̇ here by central differences; in the
    hand it feels gravity."""
    th = throw(rotor=True, seed=3, accel=True, hand=True, noise=0.0, accel_noise=0.0)
    t, w, f, p = th.t, th.omega_true, th.accel, th.lever_arm
    inside = np.flatnonzero((t > th.window[0] + 1e-3) & (t < th.window[1] - 1e-3))
    k = inside[1:-1]
    wd = (w[k + 1] - w[k - 1]) / (t[k + 1] - t[k - 1])[:, None]
    want = np.cross(wd, p) + np.cross(w[k], np.cross(w[k], p)) + th.accel_bias
    assert np.abs(f[k] - want).max() < 1e-3 * np.abs(want).max()
    before = t < th.window[0] - 0.15
    np.testing.assert_allclose(np.linalg.norm(f[before] - th.accel_bias, axis=1), 9.80665,
                               rtol=1e-12)  # fmt: skip
    assert abs(th.window[1] - th.window[0] - 0.5) < 1e-12
