"""The exact derivatives of the heavy symmetric top's closed form (``tops.exact_derivatives``,
``TopTangent`` in ``crates/core/src/heavy_top.rs``) against two independent routes: the
variational equations of Lagrange's equations for the same top in Euler angles
(``models.heavy_symmetric_top``, integrated by DOP853 with the run's own sensitivities), and
Richardson-extrapolated differences of the closed form for the body's ω0 and for the
nutation period and mean precession rate."""

from dataclasses import replace

import numpy as np
import pytest

from poinsot import Gravity, RigidBody
from poinsot.models import heavy_symmetric_top
from poinsot.rotation import body_rates_from_euler, matrix_from_euler
from poinsot.tops import exact_derivatives, exact_motion, heavy_top, steady_precession_rates

# the model's own top: a cylinder of mass 1, radius 0.3, height 0.2, tip 0.5 below its centre
TOP = heavy_top(RigidBody.cylinder(1.0, 0.3, 0.2), (0, 0, -0.5), [Gravity()])

CASES = {
    # released from rest: cusps, a turning point at t = 0
    "from rest": ((0.0, 0.6, 0.0), (0.0, 0.0, 100.0)),
    # thrown mid-swing
    "mid-swing": ((0.3, 0.7, 0.1), (2.0, 1.5, 60.0)),
    # a slow top with a wide nutation
    "slow": ((0.1, 1.1, 0.0), (0.7, -0.4, 12.0)),
}


def richardson(f, h):
    d1 = (f(h) - f(-h)) / (2 * h)
    d2 = (f(h / 2) - f(-h / 2)) / h
    return (4 * d2 - d1) / 3


def start(angles, rates):
    angles, rates = np.array(angles), np.array(rates)
    return body_rates_from_euler(angles, rates), matrix_from_euler(angles, "ZXZ")


@pytest.mark.parametrize("case", CASES)
def test_the_closed_forms_derivatives_equal_lagranges_variational_equations(case):
    angles, rates = CASES[case]
    w0, Q0 = start(angles, rates)
    T = 1.3
    d = exact_derivatives(TOP, w0, Q0, [0.0, T])
    np.testing.assert_allclose(d.angles[0], angles, atol=1e-14)
    np.testing.assert_allclose(d.rates[0], rates, atol=1e-12)
    mdl = heavy_symmetric_top()
    coords = {str(c.func): c for c in mdl.system.coordinates}
    names = ("psi", "theta", "phi")
    sol = mdl.simulate(
        (0, T), t_eval=[0, T], method="dop853", rtol=1e-12, atol=1e-14,
        q0={coords[k]: v for k, v in zip(names, angles, strict=True)},
        qd0={coords[k]: v for k, v in zip(names, rates, strict=True)},
        sensitivities=("q0", "qd0", "params"),
    )  # fmt: skip
    np.testing.assert_allclose(sol.q[-1][:3], d.angles[-1], rtol=1e-10)
    labels = sol.sensitivities.directions.labels
    # A, C, M g l (the model's g times M l), then the initial angles and rates
    cols = [labels.index(f"params[{p}]") for p in ("A", "C", "g")]
    cols += [labels.index(f"{w}[{k}]") for w in ("q0", "qd0") for k in names]
    symbols = {str(s): s for s in mdl.params}
    M, l = mdl.params[symbols["M"]], mdl.params[symbols["l"]]
    for output, got in (("q", d.d_angles[-1]), ("qd", d.d_rates[-1])):
        ref = sol.sensitivity(output)[-1][:3][:, cols]
        ref[:, 2] /= M * l  # ∂/∂(M g l) = ∂/∂g / (M l)
        err = np.abs(got - ref).max() / np.abs(ref).max()
        assert err < 1e-10, f"{case}: ∂{output} off by {err:.1e}"
    # at t = 0 the angles move only along themselves
    np.testing.assert_allclose(d.d_angles[0][:, 3:6], np.eye(3), atol=1e-12)
    np.testing.assert_allclose(d.d_angles[0][:, [0, 1, 2, 6, 7, 8]], 0.0, atol=1e-12)


@pytest.mark.parametrize("case", CASES)
def test_the_derivatives_along_omega0_and_of_the_period_equal_differences(case):
    angles, rates = CASES[case]
    w0, Q0 = start(angles, rates)
    t = 0.9
    d = exact_derivatives(TOP, w0, Q0, [t])
    for j in range(3):
        e = np.eye(3)[j]

        def moved(h, e=e):
            m = exact_motion(TOP, w0 + h * e, Q0, [t])
            return np.array([m.psi[0], m.theta[0], m.phi[0]])

        np.testing.assert_allclose(d.d_angles_d_omega0[0][:, j], richardson(moved, 1e-4),
                                   rtol=1e-7, atol=1e-7)  # fmt: skip
    for j, name in enumerate(("A", "C", "mgl")):

        def summary(h, name=name):
            top = replace(TOP, **{name: getattr(TOP, name) + h})
            m = exact_motion(top, w0, Q0, [t])
            return np.array([m.nutation_period, m.mean_precession_rate])

        fd = richardson(summary, 1e-5)
        got = [d.d_nutation_period[j], d.d_mean_precession_rate[j]]
        np.testing.assert_allclose(got, fd, rtol=1e-7)


def test_a_top_without_nutation_has_no_derivatives_and_says_so():
    theta0, spin = 0.6, 100.0
    rate = steady_precession_rates(TOP.A, TOP.C, TOP.mgl, theta0, spin)[0]
    w0, Q0 = start((0.0, theta0, 0.0), (rate, 0.0, spin - rate * np.cos(theta0)))
    with pytest.raises(ValueError, match="does not nutate"):
        exact_derivatives(TOP, w0, Q0, [1.0])


@pytest.mark.parametrize("case", CASES)
def test_the_bodys_omega_and_attitude_derivatives_equal_a_rigid_runs_sensitivities(case):
    # a third route: the rigid body itself on its pivot under gravity (Euler's equations with
    # the pivot, not Euler angles), DOP853 with the variational equations along ω0
    from poinsot import simulate

    angles, rates = CASES[case]
    w0, Q0 = start(angles, rates)
    T = 1.1
    d = exact_derivatives(TOP, w0, Q0, [0.0, T])
    m = exact_motion(TOP, w0, Q0, [0.0, T])
    np.testing.assert_allclose(d.Q, m.Q, atol=1e-14)
    np.testing.assert_allclose(d.omega, m.omega, atol=1e-12)
    traj = simulate(RigidBody.cylinder(1.0, 0.3, 0.2), (0, T), omega0=w0, Q0=Q0,
                    forces=[Gravity()], pivot=(0, 0, -0.5), method="dop853", rtol=1e-12,
                    atol=1e-14, t_eval=[0, T], sensitivities="omega0")  # fmt: skip
    for got, ref in (
        (d.d_omega_d_omega0[-1], traj.sensitivity("omega", "omega0")[-1]),
        (d.d_Q_d_omega0[-1], traj.sensitivity("Q", "omega0")[-1].reshape(3, 3, 3)),
    ):
        assert np.abs(got - ref).max() <= 1e-9 * np.abs(ref).max(), case
