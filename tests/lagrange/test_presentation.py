"""What a Lagrangian run shows: constants of the motion, reactions as named forces, the
mechanism's geometry and the panels (each checked against an independent route)."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from poinsot import models
from poinsot.lagrange import LagrangianSystem
from poinsot.viz.lagrange import lagrangian_panels, plot_mechanism_frames

matplotlib.use("Agg")


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("pendulum-on-cart", ["h", "p_x"]),  # free cart: momentum along the rail
        ("spherical-pendulum", ["h", "p_phi"]),  # vertical angular momentum
        ("heavy-top-euler", ["h", "p_psi", "p_phi"]),  # Goldstein §5.7, the three integrals
        ("rolling-disk", ["h", "p_phi"]),  # rolling: no work; no reaction about the vertical
        ("bead-on-hoop", ["h"]),  # the Jacobi integral, not T + U (the motor does work)
        ("atwood", ["h"]),
        ("double-pendulum", ["h"]),
    ],
)
def test_constants_of_motion_of_the_canonical_systems(name, expected):
    model = models.MODELS[name]()
    assert [c[1] for c in model.system.constants_of_motion()] == expected
    sol = model.simulate((0, 2), t_eval=np.linspace(0, 2, 81), rtol=1e-10, atol=1e-12)
    for inv in sol.invariants:
        assert inv.change.max() < 1e-7, inv.name


def test_forcing_and_moving_constraints_remove_the_energy_integral():
    x, y = dynamicsymbols("x y")
    m, k, c = sp.symbols("m k c", positive=True)
    t = sp.Symbol("t")
    T = m * (x.diff() ** 2 + y.diff() ** 2) / 2
    damped = LagrangianSystem([x, y], kinetic=T, forces=[{x: -c * x.diff()}])
    assert [s for _, s, *_ in damped.constants_of_motion()] == ["p_y"]
    moving = LagrangianSystem([x, y], kinetic=T, holonomic=[y - sp.sin(t)])
    assert [s for _, s, *_ in moving.constants_of_motion()] == ["p_x"]
    spring = LagrangianSystem([x, y], kinetic=T, potential=k * x**2 / 2, units={x: "m"})
    consts = spring.constants_of_motion()
    assert [s for _, s, *_ in consts] == ["h", "p_y"] and consts[1][2] == ""  # y has no unit
    with pytest.raises(ValueError, match=r"`units`: z\(t\) is not one of the coordinates"):
        LagrangianSystem([x], kinetic=T, units={dynamicsymbols("z"): "m"})


def test_atwood_tensions_are_the_textbook_values():
    # a = (m1 − m2) g / (m1 + m2 + I/r²), T1 = m1 (g − a), T2 = m2 (g + a) (Kleppner & Kolenkow
    # 2nd ed., §7.7 "Atwood's machine with a massive pulley")
    model = models.atwood_machine()
    sol = model.simulate((0, 1), t_eval=np.linspace(0, 1, 11))
    p = {str(k): v for k, v in model.params.items()}
    a = (p["m1"] - p["m2"]) * p["g"] / (p["m1"] + p["m2"] + p["I"] / p["r"] ** 2)
    values = model.reaction_values(sol)
    T1, unit, _ = values["tension T1 (string on mass 1)"]
    T2 = values["tension T2 (string on mass 2)"][0]
    assert unit == "N"
    np.testing.assert_allclose(T1, p["m1"] * (p["g"] - a), rtol=1e-8)
    np.testing.assert_allclose(T2, p["m2"] * (p["g"] + a), rtol=1e-8)
    # the pulley's angular acceleration balances the torque of the two tensions
    np.testing.assert_allclose((T1 - T2) * p["r"], p["I"] * a / p["r"], rtol=1e-8)


def test_pendulum_rod_tension_is_centripetal_plus_gravity():
    model = models.pendulum_cartesian()
    sol = model.simulate((0, 2), t_eval=np.linspace(0, 2, 41), rtol=1e-11, atol=1e-12)
    T = model.reaction_values(sol)["rod tension T"][0]
    y = sol.q[:, 1]
    vx, vy = sol.qd.T
    # m v²/l + m g cos θ with cos θ = −y/l (m = l = 1, g = 9.81)
    np.testing.assert_allclose(T, (vx**2 + vy**2) + 9.81 * (-y), rtol=1e-7)
    assert np.all(T > 0)  # the rod pulls


def test_rolling_disk_friction_is_the_centripetal_force():
    model = models.rolling_disk()
    sol = model.simulate((0, 3), t_eval=np.linspace(0, 3, 31))
    r = model.reaction_values(sol)
    F = np.hypot(r["friction F_x"][0], r["friction F_y"][0])
    m, R = 1.0, 0.5
    phid, thd = sol.qd[:, 2], sol.qd[:, 3]
    np.testing.assert_allclose(F, m * R * thd * np.abs(phid), rtol=1e-7)  # m v Ω


def test_mechanism_geometry_follows_the_coordinates():
    model = models.double_pendulum()
    sol = model.simulate((0, 3), t_eval=np.linspace(0, 3, 31))
    names, P = model.positions(sol)
    pivot, b1, b2 = (P[:, names.index(n)] for n in ("pivot", "bob 1", "bob 2"))
    np.testing.assert_allclose(np.linalg.norm(b1 - pivot, axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(b2 - b1, axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(b1[:, 0], np.sin(sol.q[:, 0]), rtol=1e-12, atol=1e-15)
    fig = plot_mechanism_frames(model, sol, frames=4)
    ax = fig.axes[0]
    lo, hi = ax.get_xlim()
    assert lo <= P[..., 0].min() and hi >= P[..., 0].max()  # every position inside the axes
    assert ax.get_xlabel() == "x [m]"


def test_panels_show_only_what_the_system_has():
    dp = models.double_pendulum()  # no constraint in its angles: no λ, no residuals
    panels = lagrangian_panels(dp.simulate((0, 1)), dp)
    titles = [p[0] for p in panels]
    assert not any("lagrange multipliers" in t.lower() or "residual" in t.lower() for t in titles)
    # but the rods' tensions, which its angles hide (HiddenConstraint), in newtons
    (reactions,) = [p for p in panels if "reactions" in p[0]]
    assert reactions[1] == "force [N]"
    assert [c[0] for c in reactions[3]] == ["rod 1 tension T1", "rod 2 tension T2"]
    cart = models.pendulum_on_cart()
    panels = lagrangian_panels(cart.simulate((0, 1)), cart)
    by_title = {p[0]: p for p in panels}
    assert by_title["Generalized coordinates: lengths"][1] == "length [m]"  # m and rad apart
    assert by_title["Generalized coordinates: angles"][1] == "angle [rad]"
    pc = models.pendulum_cartesian()
    reactions = [p for p in lagrangian_panels(pc.simulate((0, 1)), pc) if "reactions" in p[0]]
    assert reactions and reactions[0][1] == "force [N]"
    assert reactions[0][3][0][0].startswith("rod tension T")
