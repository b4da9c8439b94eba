"""Figures build, and what they plot is the physics (data read back from the artists)."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest

from poinsot.torquefree import FreeRigidBody
from poinsot.viz import (
    animate_tumbling,
    plot_attitude_frames,
    plot_energy_ellipsoid,
    plot_omega,
    plot_polhode_family,
)

matplotlib.use("Agg")
BODY = FreeRigidBody((25 / 3, 50 / 3, 65 / 3))


def _lines3d(ax):
    out = []
    for line in ax.get_lines():
        x, y, z = line.get_data_3d()
        out.append((line, np.column_stack([x, y, z])))
    return out


def test_polhode_family_figure_data():
    fig = plot_polhode_family(BODY, 0.5, levels=5)
    ax = fig.axes[0]
    I = BODY.principal_moments
    seps = [pts for line, pts in _lines3d(ax) if line.get_linestyle() == "--"]
    assert len(seps) == 4  # the four separatrix arcs, dashed
    for _line, pts in _lines3d(ax):
        if len(pts) > 2:  # every curve lies on the energy ellipsoid of k = 1/2
            w = pts @ BODY._S
            np.testing.assert_allclose((I * w * w).sum(1), 1.0, atol=1e-12)
    labels = ax.get_legend_handles_labels()[1]
    assert {"around e1", "around e3", "separatrix", "stable", "unstable"} <= set(labels)
    stable = next(c for c in ax.collections if c.get_label() == "stable")
    unstable = next(c for c in ax.collections if c.get_label() == "unstable")
    assert len(stable._offsets3d[0]) == 4 and len(unstable._offsets3d[0]) == 2
    xlim, zlim = ax.get_xlim(), ax.get_zlim()
    assert xlim == pytest.approx(zlim)  # equal axes


def test_energy_ellipsoid_and_cone_figure():
    k, D = 0.5, 14.0
    fig = plot_energy_ellipsoid(BODY, k, math.sqrt(2 * k * D))
    ax = fig.axes[0]
    curves = [
        pts
        for line, pts in _lines3d(ax)
        if line.get_label() == "intersection (polhode)" or line.get_color() == "crimson"
    ]
    assert len(curves) == 2  # both branches of the polhode
    I = BODY.principal_moments
    for pts in curves:
        w = pts @ BODY._S
        np.testing.assert_allclose((I * w * w).sum(1), 2 * k, atol=1e-12)
        np.testing.assert_allclose(((I * w) ** 2).sum(1), 2 * k * D, atol=1e-10)
        b = BODY.cone_coefficients(k, math.sqrt(2 * k * D))
        np.testing.assert_allclose((b * w * w).sum(1), 0, atol=1e-10)
    assert "a²/2k = 14" in ax.get_title()
    with pytest.raises(ValueError, match=r"I1 ≤ a²/\(2k\) ≤ I3"):
        plot_energy_ellipsoid(BODY, 2.0, 4.0)


def test_two_equal_and_all_equal_cases():
    with pytest.warns(UserWarning, match="no mass distribution"):
        sym = FreeRigidBody((3.0, 3.0, 9.0), allow_unphysical=True)
    ax = plot_energy_ellipsoid(sym, 0.5, math.sqrt(3.0)).axes[0]
    circle = next(pts for line, pts in _lines3d(ax) if line.get_color() == "crimson")
    np.testing.assert_allclose(circle[:, 2], 0, atol=1e-15)  # the plane ω3 = 0
    plot_energy_ellipsoid(FreeRigidBody((1, 1, 1)), 0.5, 1.0)
    fig = plot_polhode_family(FreeRigidBody((3, 3, 5)), 0.5)
    assert "unstable plane of fixed points" in fig.axes[0].get_legend_handles_labels()[1]


def test_omega_and_frames_and_animation(tmp_path):
    t = np.linspace(0, 10, 50)
    w = BODY.exact_omega((0.01, 0.2, 0.01), t)
    fig = plot_omega(t, w, exact=w)
    np.testing.assert_array_equal(fig.axes[0].get_lines()[0].get_ydata(), w[:, 0])
    Q = BODY.exact_attitude((0.01, 0.2, 0.01), t)
    fig = plot_attitude_frames(Q, t)
    assert len(fig.axes) == 5 and fig.axes[-1].get_title() == "t = 10 s"
    fig.savefig(tmp_path / "frames.png")
    assert (tmp_path / "frames.png").stat().st_size > 5000
    for name in ("tumble.gif", "tumble.html"):
        animate_tumbling(Q[::10], t[::10], tmp_path / name)
        assert (tmp_path / name).stat().st_size > 1000
    with pytest.raises(ValueError, match=r"`path` must end in \.gif, \.mp4 or \.html"):
        animate_tumbling(Q[:2], t[:2], tmp_path / "x.avi")
    assert not list(tmp_path.glob(".x.avi*"))  # the temporary file is removed


def test_interactive_figures_data():
    pytest.importorskip("plotly")
    from poinsot.viz.interactive import energy_ellipsoid_figure, polhode_family_figure

    fig = polhode_family_figure(BODY, 0.5, levels=5, omega=np.zeros((2, 3)))
    I = BODY.principal_moments
    lines = [t for t in fig.data if t.type == "scatter3d" and t.mode == "lines"][:-1]
    assert sum(t.name == "separatrix" for t in lines) == 4
    for t in lines:
        w = np.column_stack([t.x, t.y, t.z]) @ BODY._S
        np.testing.assert_allclose((I * w * w).sum(1), 1.0, atol=1e-12)
    names = {t.name for t in fig.data}
    assert {"stable fixed points", "unstable fixed points", "ω(t)"} <= names
    fig = energy_ellipsoid_figure(BODY, 0.5, math.sqrt(14.0))
    poly = [t for t in fig.data if t.type == "scatter3d"]
    assert len(poly) == 2
    with pytest.raises(ValueError, match="infeasible"):
        energy_ellipsoid_figure(BODY, 2.0, 4.0)
