"""Figures of a simulated trajectory plot the quantities their problem conserves, with the
body inside the axes, and the method comparison plots what it says (data read back)."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

from poinsot import Gravity, LinearDrag, RigidBody, simulate
from poinsot.app.scenario import load_example
from poinsot.conservation import invariants_of
from poinsot.torquefree import FreeRigidBody
from poinsot.viz import (
    plot_attitude_frames,
    plot_center_of_mass_path,
    plot_conservation,
    plot_method_comparison,
)

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def heavy_top():
    return load_example("heavy-top").simulate()


def _conserved(traj):
    return [i.symbol for i in invariants_of(traj) if i.conserved]


def test_heavy_top_conserves_energy_vertical_and_spin_momenta_not_L(heavy_top):
    # Goldstein, Classical Mechanics (3rd ed.) §5.7: the heavy symmetric top has the three
    # integrals E, p_ψ = L·ẑ and p_φ = L·e₃ (both about the fixed tip)
    assert _conserved(heavy_top) == ["E", "L_P·ĝ", "L_P·a"]
    by = {i.symbol: i for i in invariants_of(heavy_top)}
    assert not by["L_P"].conserved and by["L_P"].change.max() > 0.1  # gravity torques it
    for s in ("E", "L_P·ĝ", "L_P·a"):
        assert by[s].change.max() < 1e-7
    # L·a = C ω·a (body frame, C about the tip = about the c.o.m. for the symmetry axis a)
    C = heavy_top.body.principal_moments[2]  # 0.045 kg·m², the cylinder axis a = z
    np.testing.assert_allclose(by["L_P·a"].values, C * heavy_top.omega[:, 2], rtol=1e-12)


def test_conservation_figure_plots_only_the_conserved_quantities(heavy_top):
    fig = plot_conservation(heavy_top)
    ax = fig.axes[0]
    labels = [line.get_label() for line in ax.get_lines()]
    assert [label.split(" ")[0] for label in labels] == ["E", "L_P·ĝ", "L_P·a"]
    assert "not conserved here: L_P" in ax.get_title()
    by = {i.symbol: i for i in invariants_of(heavy_top)}
    for line in ax.get_lines():  # the curve is the relative change of that quantity
        inv = by[line.get_label().split(" ")[0]]
        np.testing.assert_allclose(line.get_ydata(), inv.change + 1e-17, rtol=1e-12)
    assert ax.get_yscale() == "log"


def test_free_body_conserves_L_about_the_centre_of_mass_and_momentum():
    body = RigidBody.box(2.0, (0.2, 0.4, 0.6))
    traj = simulate(body, (0, 5), omega0=(1, 2, 3), V0=(1, 0, 0), t_eval=np.linspace(0, 5, 51),
                    rtol=1e-11, atol=1e-12)  # fmt: skip
    assert _conserved(traj) == ["E", "L_G", "|L_G|", "K_rot", "p"]
    for inv in invariants_of(traj):
        assert inv.change.max() < 1e-8, inv.name


def test_drag_conserves_nothing_and_the_figure_shows_the_energy_in_joules():
    body = RigidBody.box(2.0, (0.2, 0.4, 0.6))
    traj = simulate(body, (0, 2), omega0=(1, 2, 3), V0=(1, 0, 0), forces=[LinearDrag(0.5)],
                    t_eval=np.linspace(0, 2, 41))  # fmt: skip
    invs = invariants_of(traj)
    assert not any(i.conserved for i in invs)
    fig = plot_conservation(traj)
    ax = fig.axes[0]
    assert ax.get_ylabel() == "E(t) − E(0) [J]" and "not conserved" in ax.get_title()
    E = traj.total_energy
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), E - E[0])
    assert E[-1] < E[0]  # drag dissipates


def test_central_gravity_conserves_L_about_the_centre():
    from poinsot import CentralGravity

    body = RigidBody.box(1.0, (0.5, 1.0, 2.0))
    traj = simulate(body, (0, 3), omega0=(0.3, 0.2, 0.5), R0=(10, 0, 0), V0=(0, 3, 0.5),
                    forces=[CentralGravity(100.0)], rtol=1e-12, atol=1e-12,
                    t_eval=np.linspace(0, 3, 31))  # fmt: skip
    by = {i.symbol: i for i in invariants_of(traj)}
    assert by["L_O"].conserved and by["L_O"].change.max() < 1e-9
    spin = traj.angular_momentum_com
    assert np.abs(spin - spin[0]).max() > 1e-6  # the gravity-gradient torque turns the spin


@pytest.mark.parametrize("half", [(0.01, 0.02, 0.03), (1.0, 2.0, 3.0), (30.0, 1.0, 1.0)])
def test_attitude_frames_contain_the_body(half):
    Q = np.array([np.eye(3), [[0, -1, 0], [1, 0, 0], [0, 0, 1]]])
    fig = plot_attitude_frames(Q, (0, 1), half_extents=half)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    reach = np.abs(corners * half).max()
    for ax in fig.axes:
        for lim in (ax.get_xlim(), ax.get_ylim(), ax.get_zlim()):
            assert lim[0] <= -reach and lim[1] >= reach
            assert lim[1] <= 3 * np.linalg.norm(half)  # scaled to the body, not ±1


def test_centre_of_mass_at_rest_says_so():
    body = RigidBody.box(1.0, (1, 2, 3))
    traj = simulate(body, (0, 1), omega0=(0, 1, 0), t_eval=np.linspace(0, 1, 5))
    fig = plot_center_of_mass_path(traj)
    assert not fig.axes[0].get_lines()
    assert "at rest" in fig.axes[0].texts[0].get_text()


def test_method_comparison_errors_are_the_exact_solution_errors():
    body = RigidBody.box(1.0, (1, 2, 3))
    free = FreeRigidBody.from_body(body)
    t = np.linspace(0, 5, 26)
    runs = {m: simulate(body, (0, 5), omega0=(0.1, 1, 0.2), method=m, dt=0.2, t_eval=t)
            for m in ("rk4", "rkmk4")}  # fmt: skip
    errors = {m: {"orthogonality": r.orthogonality_error, **free.error_series(r)}
              for m, r in runs.items()}  # fmt: skip
    fig = plot_method_comparison(t, errors)
    so3, attitude, omega = fig.axes
    assert "rad/s" in omega.get_ylabel() and "dimensionless" in so3.get_ylabel()
    rk4 = {line.get_label(): line.get_ydata() for line in so3.get_lines()}["rk4"]
    assert rk4.max() > 1e-8  # RK4 leaves SO(3); RKMK4 stays on it to round-off
    rkmk4 = {line.get_label(): line.get_ydata() for line in so3.get_lines()}["rkmk4"]
    assert rkmk4.max() < 1e-13
    err = free.trajectory_error(runs["rk4"])
    line = {ln.get_label(): ln.get_ydata() for ln in attitude.get_lines()}["rk4"]
    assert line.max() == pytest.approx(err["attitude"] + 1e-17, rel=1e-12)


def test_uniform_gravity_does_not_torque_a_free_body():
    body = RigidBody.box(1.0, (1, 2, 3))
    traj = simulate(body, (0, 2), omega0=(0.1, 1, 0.2), forces=[Gravity((0, 0, -9.8))],
                    t_eval=np.linspace(0, 2, 11))  # fmt: skip
    assert "L_G" in _conserved(traj) and "p" not in _conserved(traj)
