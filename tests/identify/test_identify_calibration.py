"""Calibrated uncertainty and error against noise, over many synthetic throws.

* The reported standard errors cover the truth at their nominal rate: over 200 throws (slow
  suite) each ratio falls within 2 standard errors 95.4 % of the time (±5 %), the axes'
  error rotations within the 95 % ellipsoid of their covariance (χ² with 3 degrees of freedom
  below 7.815) 95 % of the time (±5 %), and the trace within 2 standard errors likewise; the
  spread of the ratios' errors in standard errors is 1 within 0.15 (three times its own
  standard error over 200 throws). The 68 % rate is printed, not tested: over 200 throws its
  own standard error is 3.3 %, too close to the 5 % tolerance for a test that must not fail
  by chance. The default suite runs 20 throws with a looser check. Throws refused as not
  identifiable, or flagged, make no claim and are left out (at most 5 %).
* Error against noise: halve the gyro noise and the error halves, within the spread.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from poinsot.identify import ModelMismatchWarning, NotIdentifiableError, identify, synthetic_throw

CHI2_3_95 = 7.814727903251178  # scipy.stats.chi2.ppf(0.95, 3)


def _axis_rotation(res, th):
    """The small rotation (fitted principal frame → true one) about the fitted axes [rad]."""
    T = th.axes * np.sign(np.sum(th.axes * res.axes, axis=0))
    R = res.axes.T @ T
    return 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])


def _campaign(n, *, seed0, rotor=True, noise=0.02, omega0=None):
    """z-scores of the ratios (m, 2), χ² of the axes (m,), z of the trace, relative errors
    (m, 5: the ratios and the axes' angles [rad]) of the m throws identified and not flagged."""
    z, chi2, zt, err = [], [], [], []
    for s in range(n):
        th = synthetic_throw(seed=seed0 + s, rotor=rotor, noise=noise, omega0=omega0)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                res = identify(th.t, th.omega, **th.kwargs())
        except (NotIdentifiableError, ModelMismatchWarning):
            continue  # refused or flagged: no claim to check
        z.append((res.ratios - th.ratios) / res.ratios_stderr)
        d = _axis_rotation(res, th)
        chi2.append(d @ np.linalg.solve(res.axes_covariance, d))
        if res.absolute:
            zt.append((res.trace - np.trace(th.inertia)) / res.trace_stderr)
        err.append(np.r_[res.ratios / th.ratios - 1, np.radians(th.axis_errors_deg(res.axes))])
    return np.array(z), np.array(chi2), np.array(zt), np.array(err)


def test_standard_errors_are_calibrated_20_throws():
    z, chi2, zt, _ = _campaign(20, seed0=5000)
    assert len(z) >= 19
    assert 0.6 < z.std() < 1.5 and np.mean(np.abs(z) < 2) > 0.85
    assert 1.5 < chi2.mean() < 4.5 and np.mean(chi2 < CHI2_3_95) > 0.8
    assert 0.5 < zt.std() < 1.6


@pytest.mark.slow
@pytest.mark.parametrize("rotor", [True, False])
def test_standard_errors_are_calibrated_200_throws(rotor):
    z, chi2, zt, _ = _campaign(200, seed0=7000, rotor=rotor)
    assert len(z) >= 190
    print(f"68 % rate: {np.mean(np.abs(z) < 1, axis=0)}, 95 %: {np.mean(np.abs(z) < 2, axis=0)}")
    for k in range(2):
        assert abs(np.mean(np.abs(z[:, k]) < 2) - 0.9545) < 0.05, np.mean(np.abs(z) < 2, 0)
        assert abs(z[:, k].std() - 1) < 0.15, z.std(axis=0)
    assert abs(np.mean(chi2 < CHI2_3_95) - 0.95) < 0.05
    if rotor:
        assert abs(np.mean(np.abs(zt) < 2) - 0.9545) < 0.05
        assert abs(zt.std() - 1) < 0.15


def _rms(err):
    return np.sqrt(np.mean(err**2, axis=0))


def test_halving_the_noise_halves_the_error_10_throws():
    """The same throws and noise draws at half the noise: the errors halve (no floor from
    the model, the integrator or the smoothing)."""
    *_, e1 = _campaign(10, seed0=6000, noise=0.02)
    *_, e2 = _campaign(10, seed0=6000, noise=0.01)
    ratio = _rms(e1) / _rms(e2)
    assert np.all(np.abs(ratio - 2) < 0.2), ratio


@pytest.mark.slow
def test_halving_the_noise_halves_the_error_200_throws():
    """One motion, 200 independent noise draws at each noise level: the ratio of the RMS
    errors is 2 within three of its standard errors (for Gaussian errors an RMS over N draws
    has a relative standard error 1/√(2N))."""
    w0 = synthetic_throw(seed=8000).omega_true[0]
    *_, e1 = _campaign(200, seed0=8000, noise=0.02, omega0=w0)
    *_, e2 = _campaign(200, seed0=9000, noise=0.01, omega0=w0)
    ratio = _rms(e1) / _rms(e2)
    spread = 2 * np.sqrt(1 / (2 * len(e1)) + 1 / (2 * len(e2)))
    assert np.all(np.abs(ratio - 2) < 3 * spread), (ratio, spread)
