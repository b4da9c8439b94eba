"""The identification's figures plot what their labels say."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot.identify import identify
from poinsot.viz.identify import plot_identified_axes, plot_identified_fit, plot_identified_polhode


@pytest.fixture(scope="module")
def fitted():
    from poinsot.identify import synthetic_throw

    th = synthetic_throw(rotor=False, seed=61)
    return th, identify(th.t, th.omega)


def test_fit_figure_shows_the_readings_the_fit_and_the_residuals(fitted):
    _, res = fitted
    fig = plot_identified_fit(res)
    top, bottom = fig.axes[:2]
    lines = {ln.get_label(): ln for ln in top.get_lines()}
    np.testing.assert_array_equal(lines["ω_y measured"].get_ydata(), res.omega_measured[:, 1])
    np.testing.assert_array_equal(lines["ω_z fitted"].get_ydata(), res.omega_fit[:, 2])
    resid = {ln.get_label(): ln for ln in bottom.get_lines()}
    np.testing.assert_array_equal(resid["x"].get_ydata(), res.residuals[:, 0])
    assert bottom.get_xlabel() == "t [s]" and "rad/s" in bottom.get_ylabel()


def test_polhode_figure_stays_on_the_energy_ellipsoid_for_a_torque_free_fit(fitted):
    _, res = fitted
    fig = plot_identified_polhode(res)
    (path,) = [ln for ln in fig.axes[0].get_lines() if ln.get_label() == "fitted ω(t)"]
    x, y, z = path.get_data_3d()
    w = np.column_stack([x, y, z])
    np.testing.assert_allclose(w, (res.omega_fit - res.gyro_bias) @ res.axes)
    energy = w**2 @ res.principal_moments
    np.testing.assert_allclose(energy, energy[0], rtol=1e-6)  # torque-free: k is constant


def test_axes_figure_draws_the_fitted_axes(fitted):
    _, res = fitted
    fig = plot_identified_axes(res)
    ax = fig.axes[0]
    arrows = [c for c in ax.collections if c.__class__.__name__ == "Line3DCollection"]
    assert len(arrows) == 3
    for k, q in enumerate(arrows):
        seg = np.asarray(q._segments3d[0])  # the shaft, from the origin along e_k
        d = seg[1] - seg[0]
        assert abs(abs(d @ res.axes[:, k]) / np.linalg.norm(d) - 1) < 1e-9
    assert "arbitrary units" in ax.get_xlabel()
    fig = plot_identified_axes(res, box=(0.07, 0.06, 0.03))
    assert fig.axes[0].get_xlabel() == "sensor x [m]"
