"""Finding the free flight: the accelerometer's lever-arm model, saturation, the user's
window; and the estimators underneath (equation error, smoothing, noise level)."""

from __future__ import annotations

import numpy as np
import pytest
from identify_throws import throw

from poinsot.identify.flight import find_free_flight, lever_arm_design, saturated_samples


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("rotor", [False, True])
def test_the_flight_is_found_and_the_lever_arm_measured(seed, rotor):
    th = throw(rotor=rotor, seed=seed, accel=True, hand=True)
    fl = find_free_flight(th.t, th.omega, th.accel)
    assert fl.found_by == "accelerometer"
    # inside the true flight, and most of it (the ends trimmed by half a smoothing window)
    assert th.window[0] <= fl.window[0] < th.window[0] + 0.03
    assert th.window[1] - 0.03 < fl.window[1] <= th.window[1]
    assert np.linalg.norm(fl.lever_arm - th.lever_arm) < 2e-4  # 0.2 mm
    assert np.linalg.norm(fl.accel_bias - th.accel_bias) < 0.05
    assert fl.accel_residual_rms < 3 * 0.05  # the accelerometer's noise, 3 axes


def test_the_lever_arm_design_is_the_rigid_body_acceleration():
    """``D (p, b)`` against ``ω̇ × p + ω × (ω × p) + b`` written with np.cross."""
    rng = np.random.default_rng(0)
    w, wd = rng.normal(0, 10, (20, 3)), rng.normal(0, 100, (20, 3))
    p, b = rng.normal(0, 0.05, 3), rng.normal(0, 0.1, 3)
    want = np.cross(wd, p) + np.cross(w, np.cross(w, p)) + b
    np.testing.assert_allclose(lever_arm_design(w, wd) @ np.r_[p, b], want, rtol=1e-12)


def test_without_a_free_flight_the_accelerometer_is_refused():
    th = throw(rotor=False, seed=1, accel=True, hand=True)
    held = th.t < th.window[0] - 0.13  # only the part held still in the hand
    with pytest.raises(ValueError, match=r"`accel`: no free flight found"):
        find_free_flight(th.t[held], th.omega[held], th.accel[held])
    # an accelerometer read in another frame (turned 90° about z): no lever arm explains it
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match=r"`accel`.*in the gyro's frame"):
        find_free_flight(th.t, th.omega, th.accel @ turn.T)


def test_saturated_samples_end_a_stretch():
    t = np.arange(400) / 100.0
    w = np.column_stack([40 * np.sin(t), np.cos(t), 0.1 * t])
    clipped = np.clip(w, -35, 35)
    sat = saturated_samples(clipped)
    np.testing.assert_array_equal(sat, np.abs(w[:, 0]) >= 35)
    np.testing.assert_array_equal(saturated_samples(clipped, 35.0), sat)
    fl = find_free_flight(t, clipped)
    assert not sat[fl.start : fl.stop].any()
    runs = np.diff(np.r_[0, (~sat).astype(int), 0])
    longest = (np.flatnonzero(runs == -1) - np.flatnonzero(runs == 1)).max()
    assert fl.stop - fl.start == longest
    # a peak that is not flat is no saturation; nor is a constant column
    assert not saturated_samples(w).any()
    assert not saturated_samples(np.ones((50, 3))).any()


def test_the_users_window_bounds_the_search():
    th = throw(rotor=False, seed=2, accel=True, hand=True)
    fl = find_free_flight(th.t, th.omega, th.accel, window=(0.4, 0.7))
    assert 0.4 <= fl.window[0] < fl.window[1] <= 0.7
    fl = find_free_flight(th.t, th.omega, window=(0.4, 0.7))
    assert fl.found_by == "window" and fl.lever_arm is None
    assert fl.window == (float(th.t[fl.start]), float(th.t[fl.stop - 1]))


# ---------------------------------------------------------------------- the estimators
def test_equation_error_is_exact_on_exact_data():
    """Noise-free readings of the exact torque-free solution: the null vector is the inertia
    up to scale (the smoothing's bias at 4 kHz is below 1e-6)."""
    from poinsot.identify.equation_error import equation_error
    from poinsot.identify.synthetic import logger_block
    from poinsot.torquefree import FreeRigidBody

    body, _ = logger_block()
    t = np.arange(2001) / 4000.0
    w = FreeRigidBody.from_body(body).exact_omega((12.0, -15.0, 9.0), t)
    fit = equation_error(t, w)
    np.testing.assert_allclose(fit.inertia, body.inertia / np.trace(body.inertia), atol=1e-6)
    assert not fit.absolute and fit.physical and fit.gap > 100


def test_equation_error_with_a_known_rotor_is_absolute():
    from poinsot.identify.equation_error import equation_error

    th = throw(seed=2, noise=0.0, bias=0.0, saturation=None)
    fit = equation_error(th.t, th.omega, rotor_speed=th.rotor_speed, rotor_axis=th.rotor_axis,
                         rotor_inertia=th.rotor_inertia)  # fmt: skip
    np.testing.assert_allclose(fit.inertia, th.inertia, atol=1e-5 * np.trace(th.inertia))
    free = equation_error(th.t, th.omega, rotor_speed=th.rotor_speed, rotor_axis=th.rotor_axis)
    np.testing.assert_allclose(free.rotor_inertia, th.rotor_inertia / np.trace(th.inertia),
                               rtol=1e-4)  # fmt: skip


def test_smoothing_and_noise_level():
    from poinsot.identify.signals import smooth, white_noise_std

    rng = np.random.default_rng(2)
    t = np.sort(rng.uniform(0, 1, 3000))  # uneven samples are resampled for the filter
    x = np.column_stack([np.sin(3 * t), t**2])
    np.testing.assert_allclose(smooth(t, x), x, atol=1e-5)
    np.testing.assert_allclose(smooth(t, x, deriv=1), np.column_stack([3 * np.cos(3 * t), 2 * t]),
                               atol=2e-3)  # fmt: skip
    t = np.arange(20000) / 4000.0
    noisy = np.sin(t)[:, None] + rng.normal(0, [0.01, 0.05], (20000, 2))
    np.testing.assert_allclose(white_noise_std(noisy), [0.01, 0.05], rtol=0.05)


@pytest.mark.parametrize(("window", "order", "deriv"), [(5, 2, 0), (81, 3, 1), (21, 3, 2),
                                                        (7, 2, 0), (9, 4, 1)])  # fmt: skip
def test_savgol_is_scipys(window, order, deriv):
    """The NumPy Savitzky–Golay filter against SciPy's, interior and ends (mode "interp")."""
    from scipy.signal import savgol_coeffs, savgol_filter

    from poinsot.identify.signals import savgol, savgol_weights

    x = np.random.default_rng(window).standard_normal((300, 3)).cumsum(axis=0)
    want = savgol_filter(x, window, order, deriv=deriv, delta=0.01, axis=0, mode="interp")
    got = savgol(x, window, order, deriv=deriv, delta=0.01)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())
    np.testing.assert_allclose(savgol_weights(window, order, deriv, 0.01),
                               savgol_coeffs(window, order, deriv, 0.01, use="dot"),
                               atol=1e-9 * 100**deriv)  # fmt: skip
