"""One name, one meaning, in a heavy top's figures: e₁, e₂, e₃ are the principal axes about the
centre of mass G (those of the body table), the axes about a pivot are e₁ᴾ, e₂ᴾ, e₃ᴾ, the top's
symmetry axis is a (from the tip towards the centre of mass); the 3-D view of a pivoted body is
in the space coordinates of the trajectory; titles fit their panels whatever the gravity."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

from poinsot import Gravity, RigidBody, simulate
from poinsot.tops import heavy_top, top_motion

matplotlib.use("Agg")
import matplotlib.pyplot as plt

#: An x-axis top under tilted gravity (its symmetry axis is e₁ about G and e₁ᴾ about the tip),
#: pivot and centre of mass away from the origin of the body's frame.
X_BODY = RigidBody(2.0, np.diag([0.05, 0.2, 0.2]), (0.3, 0.1, -0.2))
X_PIVOT = (0.0, 0.1, -0.2)
X_GRAVITY = Gravity((1.0, -2.0, -9.0))
#: The cylinder top of the heavy-top example: its symmetry axis is e₃ about G, e₁ᴾ about the tip.
CYLINDER = RigidBody.cylinder(1.0, 0.3, 0.2)


@pytest.fixture(scope="module")
def xtop():
    Q0 = np.array([[0.0, -1.0, 0.0], [0.6, 0.0, -0.8], [0.8, 0.0, 0.6]])
    traj = simulate(X_BODY, (0, 1), omega0=(20.0, 0.5, -0.3), Q0=Q0, pivot=X_PIVOT,
                    forces=[X_GRAVITY], t_eval=np.linspace(0, 1, 101))  # fmt: skip
    return traj, heavy_top(X_BODY, X_PIVOT, [X_GRAVITY])


def test_the_axes_about_a_pivot_are_not_called_e1_e2_e3():
    from poinsot.viz import plot_omega_series

    traj = simulate(CYLINDER, (0, 0.2), omega0=(0, 1.5, 100), forces=[Gravity((0, 0, -9.81))],
                    pivot=(0, 0, -0.5))  # fmt: skip
    fig = plot_omega_series(traj)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0] == "ω·e₁ᴾ (I₁ᴾ = 0.045 kg·m² about the pivot)"
    assert labels[2] == "ω·e₃ᴾ (I₃ᴾ = 0.2758 kg·m² about the pivot)"
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), traj.omega[:, 2])  # e₁ᴾ = z
    assert ax.get_ylabel() == "ω along e₁ᴾ, e₂ᴾ, e₃ᴾ [rad/s]"
    assert "about the pivot P" in ax.get_title()
    # e₁ of the same body (about G, the body table's) is x: a pivot's axis is never called so
    assert CYLINDER.principal_axes[:, 0] @ [1, 0, 0] == pytest.approx(1.0)
    assert not any(label.startswith(("ω·e₁ (", "ω·e₂ (", "ω·e₃ (")) for label in labels)
    plt.close(fig)


def test_the_interactive_omega_panel_names_the_same_axes(xtop):
    pytest.importorskip("plotly")
    import plotly.graph_objects as go

    from poinsot.viz.report import _series_figure

    traj, _ = xtop
    fig = _series_figure(traj, go)
    names = [t.name for t in fig.data[:3]]
    assert names[0] == "ω·e₁ᴾ (I₁ᴾ = 0.05 kg·m² about the pivot)"
    np.testing.assert_allclose(fig.data[0].y, traj.omega[:, 0])  # e₁ᴾ = x, the top's axis
    assert fig.layout.yaxis.title.text == "ω along e₁ᴾ, e₂ᴾ, e₃ᴾ [rad/s]"
    assert fig.layout.annotations[0].text == "ω along the principal axes about the pivot P"


def test_the_pivoted_body_is_drawn_in_space_coordinates(xtop):
    pytest.importorskip("plotly")
    import plotly.graph_objects as go

    from poinsot.viz.report import _body_figure

    traj, _ = xtop
    fig = _body_figure(traj, go)
    scene = fig.layout.scene
    assert [scene[f"{c}axis"].title.text for c in "xyz"] == ["x [m]", "y [m]", "z [m]"]
    pivot = next(t for t in fig.data if "pivot" in t.name)
    P = traj.pivot_position
    assert not np.allclose(P, 0)  # the pivot is not the origin of space
    np.testing.assert_allclose([pivot.x[0], pivot.y[0], pivot.z[0]], P, atol=1e-15)
    np.testing.assert_allclose([pivot.x[1], pivot.y[1], pivot.z[1]], traj.R[0], atol=1e-15)
    for k, c in enumerate("xyz"):  # the scene holds the pivot and the body
        lo, hi = scene[f"{c}axis"].range
        assert lo < P[k] < hi and lo < traj.R[0, k] < hi
    e1 = next(t for t in fig.data if t.name.startswith("e₁"))
    assert e1.name == "e₁ (principal axis about G)"
    np.testing.assert_allclose([e1.x[0], e1.y[0], e1.z[0]], traj.R[0], atol=1e-15)
    assert "space coordinates" in fig.layout.title.text and "about the centre of mass G" in (
        fig.layout.title.text
    )


def test_a_free_body_is_drawn_about_its_centre_of_mass_and_its_axes_say_so():
    pytest.importorskip("plotly")
    import plotly.graph_objects as go

    from poinsot.viz.report import _body_figure

    traj = simulate(CYLINDER, (0, 1), omega0=(0, 1, 3), V0=(1, 0, 0))
    fig = _body_figure(traj, go)
    scene = fig.layout.scene
    assert [scene[f"{c}axis"].title.text for c in "xyz"] == [
        "x − x_G [m]", "y − y_G [m]", "z − z_G [m]"]  # fmt: skip
    box = fig.data[0]
    centre = np.nanmean(np.array([box.x, box.y, box.z], dtype=float), axis=1)
    np.testing.assert_allclose(centre, 0, atol=1e-12)  # drawn about G


def _boxes(fig):
    fig.canvas.draw()
    return [ax.title.get_window_extent() for ax in fig.axes]


def test_attitude_titles_fit_their_panels_under_tilted_gravity(xtop):
    from poinsot.viz.trajectory import plot_attitude

    traj, top = xtop
    motion = top_motion(traj, top)
    reference = motion.psi_reference()
    assert len(reference) > 100  # a tilted vertical: the long label of the audit
    fig = plot_attitude(motion, title="xtop")
    left, right = _boxes(fig)
    assert left.x1 < right.x0, "the two titles overlap"
    width = fig.bbox.width
    for box, ax in zip((left, right), fig.axes, strict=True):
        assert 0 <= box.x0 and box.x1 <= width, "a title runs off the figure"
        axes = ax.get_window_extent()
        assert box.x0 >= axes.x0 - 2 and box.x1 <= axes.x1 + 2, "a title is wider than its panel"
    said = " ".join(fig.axes[1].get_title().split())
    assert said == f"Precession ψ: {reference}"  # all of it, the azimuth ψ − 90° included
    assert "symmetry axis a" in fig.axes[0].get_title()
    plt.close(fig)


def test_interactive_attitude_titles_are_wrapped(xtop):
    pytest.importorskip("plotly")
    import plotly.graph_objects as go

    from poinsot.viz.report import _top_figure

    traj, top = xtop
    motion = top_motion(traj, top)
    fig = _top_figure(motion, go)
    titles = [a.text for a in fig.layout.annotations]
    for text in titles:
        assert all(len(line) <= 60 for line in text.split("<br>")), text  # half the page
    assert (
        " ".join(titles[1].split("<br>")) == f"Precession ψ (unwrapped): {motion.psi_reference()}"
    )
    assert fig.layout.margin.t >= 60 + 20 * max(t.count("<br>") for t in titles)
    names = [t.name for t in fig.data]
    assert any(n.startswith("gyroscopic M g l/(C ω·a)") for n in names)
    assert not any("ω₃" in n for n in names)


def test_the_notebook_traces_a_top_by_its_axis_a():
    """A top that is a sphere about its centre of mass has no symmetry axis of its own: the
    notebook's ``traj.plot("axis_trace")`` traces a, from the tip towards the centre of mass
    (it had refused: "the body is spherical")."""
    from poinsot.viz.display import _trajectory_plot

    sphere = RigidBody(1.0, np.diag([0.01, 0.01, 0.01]))
    traj = simulate(sphere, (0, 0.5), omega0=(0, 1, 50), pivot=(0, 0, -0.3),
                    forces=[Gravity((0, 0, -9.81))], t_eval=np.linspace(0, 0.5, 51))  # fmt: skip
    fig = _trajectory_plot(traj, "axis_trace")
    ax = fig.axes[0]
    path = next(line for line in ax.get_lines() if line.get_label() == "direction of a")
    np.testing.assert_allclose(np.array(path.get_data_3d()).T, traj.axis_trace((0, 0, 1)))
    assert "symmetry axis a (tip → centre of mass)" in ax.get_title()
    plt.close(fig)
