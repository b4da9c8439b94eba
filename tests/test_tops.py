"""The heavy symmetric top's steady precession rates (crates/core/src/tops.rs through
poinsot.tops), each against an independent route: a simulated top started in steady precession
keeps its tilt and precesses at that rate; Lagrange's equation for θ derived by SymPy vanishes
there; a fast top's mean precession tends to the gyroscopic estimate."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from poinsot import Gravity, LinearDrag, RigidBody, models, simulate
from poinsot.rotation import body_rates_from_euler, matrix_from_euler
from poinsot.tops import (
    gyroscopic_precession_rate,
    heavy_top,
    steady_precession_rates,
    top_motion,
)

CYLINDER = RigidBody.cylinder(1.0, 0.3, 0.2)
PIVOT = (0.0, 0.0, -0.5)


def _launch(theta0, rate, spin, t1, samples=401):
    """The cylinder top on its tip, tilted θ0, started with ψ̇ = rate, θ̇ = 0 and spin ω₃."""
    angles = np.array([0.0, theta0, 0.0])
    rates = np.array([rate, 0.0, spin - rate * np.cos(theta0)])  # ω₃ = φ̇ + ψ̇ cos θ
    return simulate(CYLINDER, (0, t1), omega0=body_rates_from_euler(angles, rates),
                    Q0=matrix_from_euler(angles), forces=[Gravity((0, 0, -9.81))], pivot=PIVOT,
                    rtol=1e-12, atol=1e-12, t_eval=np.linspace(0, t1, samples))  # fmt: skip


@pytest.mark.parametrize("root", [0, 1])
def test_a_top_launched_at_a_steady_rate_precesses_steadily(root):
    top = heavy_top(CYLINDER, np.array(PIVOT), [Gravity((0, 0, -9.81))])
    theta0, spin = 0.6, 100.0
    rate = steady_precession_rates(top.A, top.C, top.mgl, theta0, spin)[root]
    traj = _launch(theta0, rate, spin, t1=3.0 if root == 0 else 0.5)
    motion = top_motion(traj, top)
    assert np.abs(motion.theta - theta0).max() < 1e-8  # no nutation at all
    np.testing.assert_allclose(traj.euler_rates()[:, 0], rate, rtol=1e-8)
    assert motion.mean_precession_rate == pytest.approx(rate, rel=1e-8)


def test_a_top_launched_at_another_rate_nutates():
    top = heavy_top(CYLINDER, np.array(PIVOT), [Gravity((0, 0, -9.81))])
    slow, _ = steady_precession_rates(top.A, top.C, top.mgl, 0.6, 100.0)
    motion = top_motion(_launch(0.6, 1.2 * slow, 100.0, 2.0), top)
    assert motion.theta_band[1] - motion.theta_band[0] > 1e-3


def test_the_rates_make_lagranges_equation_for_theta_vanish():
    """The θ equation of the heavy-top model in Euler angles (SymPy's derivation), at θ̇ = θ̈ = 0
    and constant ψ̇, φ̇: zero exactly at the two steady rates, and not at their mean."""
    model = models.heavy_symmetric_top()
    system = model.system
    psi, th, ph = system.coordinates
    t = system.t
    eq = system.equations()[1]
    residual = eq.lhs - eq.rhs
    Omega, spin, theta = sp.symbols("Omega spin theta")
    steady = {psi.diff(t, 2): 0, th.diff(t, 2): 0, ph.diff(t, 2): 0, th.diff(t): 0,
              psi.diff(t): Omega, ph.diff(t): spin - Omega * sp.cos(theta)}  # fmt: skip
    r = sp.lambdify((Omega, spin, theta), residual.subs(steady).subs(th, theta).subs(model.params))
    p = {str(k): v for k, v in model.params.items()}
    A, C, mgl = p["A"], p["C"], p["M"] * p["g"] * p["l"]
    for theta0, w3 in ((0.6, 100.0), (1.2, 40.0), (2.4, 5.0), (0.3, -60.0)):
        slow, fast = steady_precession_rates(A, C, mgl, theta0, w3)
        scale = abs(C * w3 * slow) + mgl
        assert abs(r(slow, w3, theta0)) < 1e-12 * scale
        assert abs(r(fast, w3, theta0)) < 1e-12 * abs(C * w3 * fast)
        assert abs(r(0.5 * (slow + fast), w3, theta0)) > 1e-3 * scale


@settings(max_examples=60, deadline=None)
@given(st.floats(0.05, 2.0), st.floats(0.05, 2.0), st.floats(0.1, 10.0),
       st.floats(0.05, np.pi - 0.05), st.floats(-500.0, 500.0))  # fmt: skip
def test_vieta(A, C, mgl, theta, spin):
    """Sum and product of the roots of A cos θ Ω² − C ω₃ Ω + M g l = 0."""
    slow, fast = steady_precession_rates(A, C, mgl, theta, spin)
    disc = (C * spin) ** 2 - 4 * A * mgl * np.cos(theta)
    if disc < 0:
        assert np.isnan(slow) and np.isnan(fast)
        return
    if abs(np.cos(theta)) < 1e-6:
        return
    a = A * np.cos(theta)
    assert slow * fast == pytest.approx(mgl / a, rel=1e-10)
    assert slow + fast == pytest.approx(C * spin / a, rel=1e-9, abs=1e-9 * abs(fast))
    assert abs(slow) <= abs(fast) * (1 + 1e-12)


def test_a_fast_top_precesses_at_the_gyroscopic_rate():
    """Released with ψ̇ = θ̇ = 0, a fast top nutates in small cusps and its mean precession
    tends to M g l/(C ω₃) as ω₃ grows (the error falls like 1/ω₃²)."""
    top = heavy_top(CYLINDER, np.array(PIVOT), [Gravity((0, 0, -9.81))])
    errors = []
    for spin in (100.0, 400.0):
        motion = top_motion(_launch(0.6, 0.0, spin, 6.0, samples=6001), top)
        gyro = gyroscopic_precession_rate(top.C, top.mgl, spin)
        errors.append(abs(motion.mean_precession_rate / gyro - 1))
    assert errors[1] < 0.01 and errors[1] < errors[0] / 8


def test_what_is_a_heavy_top():
    g = [Gravity((0, 0, -9.81))]
    top = heavy_top(CYLINDER, np.array(PIVOT), g)
    assert top.A == pytest.approx(CYLINDER.principal_moments[0] + 0.25, rel=1e-12)
    assert top.mgl == pytest.approx(9.81 * 0.5, rel=1e-12)
    np.testing.assert_allclose(top.up, [0, 0, 1])
    box = RigidBody.box(1.0, (1, 2, 3))
    assert heavy_top(box, np.array(PIVOT), g) is None  # asymmetric
    assert heavy_top(CYLINDER, None, g) is None  # no pivot
    assert heavy_top(CYLINDER, np.array([0.1, 0.0, -0.5]), g) is None  # off the axis
    assert heavy_top(CYLINDER, np.array(PIVOT), [*g, LinearDrag(0.1)]) is None
    with pytest.raises(ValueError, match="`A` and `C` must be positive"):
        steady_precession_rates(-1.0, 1.0, 1.0, 0.5, 10.0)


@pytest.mark.parametrize("psi0", [0.0, 1.0, -2.5])
def test_psi_is_the_trajectorys_own_euler_angle_and_the_axis_points_at_psi_minus_90deg(psi0):
    """Issue 43: the plotted ψ was the Euler ψ + π/2 in an internal frame (2.571 for ψ₀ = 1).
    Under gravity along −z with the axis on body z, θ, ψ and φ are the trajectory's own z-x-z
    angles, and the axis (tip → centre of mass, space components) lies at azimuth ψ − π/2."""
    top = heavy_top(CYLINDER, np.array(PIVOT), [Gravity((0, 0, -9.81))])
    angles = np.array([psi0, 0.6, 0.3])
    traj = simulate(
        CYLINDER,
        (0, 0.5),
        omega0=(0.0, 1.5, 100.0),
        Q0=matrix_from_euler(angles),
        forces=[Gravity((0, 0, -9.81))],
        pivot=PIVOT,
        t_eval=np.linspace(0, 0.5, 21),
    )
    motion = top_motion(traj, top)
    euler = traj.euler_angles()
    assert motion.psi[0] == pytest.approx(psi0, abs=1e-12)
    np.testing.assert_allclose(np.unwrap(euler[:, 0]), motion.psi, atol=1e-12)
    np.testing.assert_allclose(euler[:, 1], motion.theta, atol=1e-12)
    axis = np.einsum("nij,j->ni", traj.Q, top.axis)  # the symmetry axis in space
    azimuth = np.arctan2(axis[:, 1], axis[:, 0])
    np.testing.assert_allclose(np.angle(np.exp(1j * (motion.psi - np.pi / 2 - azimuth))), 0,
                               atol=1e-10)  # fmt: skip
    assert motion.psi_reference().startswith("line of nodes from +x about +z")
    assert motion.exact.psi[0] == pytest.approx(psi0, abs=1e-12)


def test_the_top_frame_is_the_cyclic_axes_tilted_onto_the_vertical():
    """Gravity along −x: the top's space axes are (y, z, x); the angles are those of Q in them."""
    top = heavy_top(CYLINDER, np.array(PIVOT), [Gravity((-9.81, 0, 0))])
    np.testing.assert_array_equal(top.space(), np.eye(3)[[1, 2, 0]])
    np.testing.assert_array_equal(top.frame(), np.eye(3))
    assert np.linalg.det(top.space()) == pytest.approx(1.0)
