"""Force models: wrenches against their potentials (finite differences) and closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import (
    CentralGravity,
    CustomForce,
    Gravity,
    PointForce,
    QuadraticDrag,
    RigidBody,
    Spring,
    Torque,
    simulate,
)
from poinsot._core import exp_so3, hat
from poinsot.dynamics import RigidBodySystem

BODY = RigidBody.box(2.0, (1.0, 0.6, 0.3), position=(0.1, 0.2, 0.3))


def _wrench_and_potential(force, R, Q):
    system = RigidBodySystem(BODY, [force])
    ctx = system.context(0.0, R, np.zeros(3), Q, np.zeros(3))
    F, tau = force.wrench(ctx)
    return (
        F,
        tau,
        (lambda R_, Q_: force.potential(system.context(0.0, R_, np.zeros(3), Q_, np.zeros(3)))),
    )


@pytest.mark.parametrize(
    "force",
    [
        Gravity((0.3, -0.2, -9.8)),
        Spring((0.5, 0.4, 0.0), (2.0, 1.0, -1.0), 7.0, 0.5),
        Spring((0.5, 0.4, 0.0), (2.0, 1.0, -1.0), 7.0, 0.5, tether=True),
        CentralGravity(3.0, center=(-4.0, 1.0, 2.0)),
    ],
    ids=["gravity", "spring", "tether", "central-gravity"],
)
def test_force_and_torque_are_minus_gradient_of_potential(force):
    R = np.array([0.4, -0.3, 0.8])
    Q = exp_so3([0.3, -0.8, 0.5])
    F, tau, U = _wrench_and_potential(force, R, Q)
    h = 1e-6
    grad_R = np.array([(U(R + h * e, Q) - U(R - h * e, Q)) / (2 * h) for e in np.eye(3)])
    np.testing.assert_allclose(F, -grad_R, atol=1e-7 * max(1, np.abs(F).max()))
    # torque about the centre of mass in the body frame: τ = −∂U/∂θ for Q ← Q exp(θ̂)
    grad_th = np.array(
        [(U(R, Q @ exp_so3(h * e)) - U(R, Q @ exp_so3(-h * e))) / (2 * h) for e in np.eye(3)]
    )
    np.testing.assert_allclose(tau, -grad_th, atol=1e-7 * max(1, np.abs(tau).max()))


def test_slack_tether_exerts_nothing():
    tether = Spring((0.5, 0.0, 0.0), (0.7, 0.2, 0.3), 10.0, rest_length=5.0, tether=True)
    F, tau, U = _wrench_and_potential(tether, np.zeros(3), np.eye(3))
    assert not F.any() and not tau.any() and U(np.zeros(3), np.eye(3)) == 0


def test_gravity_gradient_torque_closed_form():
    # τ = 3μ/r³ n̂ × (A n̂) (Hughes, Spacecraft Attitude Dynamics, §8.2)
    mu, r = 4.0, 10.0
    force = CentralGravity(mu)
    Q = exp_so3([0.2, 0.5, -0.1])
    R = np.array([r, 0, 0])
    _, tau, _ = _wrench_and_potential(force, R, Q)
    n = Q.T @ np.array([1.0, 0, 0])
    np.testing.assert_allclose(tau, 3 * mu / r**3 * np.cross(n, BODY.inertia @ n), rtol=1e-12)


def test_central_gravity_orbit_conserves_energy_and_momentum():
    mu = 10.0
    body = RigidBody.box(1.0, (0.3, 0.2, 0.1))
    v_circ = np.sqrt(mu / 1.0)
    tr = simulate(
        body,
        (0, 10),
        omega0=(0.1, 0.2, 1.0),
        R0=(1.0, 0, 0),
        V0=(0, v_circ, 0),
        forces=[CentralGravity(mu)],
        rtol=1e-12,
        atol=1e-13,
        t_eval=np.linspace(0, 10, 51),
    )
    assert np.abs(tr.energy_drift).max() < 1e-9
    L = tr.angular_momentum  # about the attracting centre (the origin): conserved
    assert np.abs(L - L[0]).max() < 1e-9 * np.linalg.norm(L[0])
    # point-mass gravity alone: the circular orbit keeps its radius (the gradient terms perturb
    # it by O(I / M r²))
    circ = simulate(
        body,
        (0, 10),
        omega0=(0.1, 0.2, 1.0),
        R0=(1.0, 0, 0),
        V0=(0, v_circ, 0),
        forces=[CentralGravity(mu, gradient=False)],
        rtol=1e-12,
        atol=1e-13,
        t_eval=np.linspace(0, 10, 51),
    )
    np.testing.assert_allclose(np.linalg.norm(circ.R, axis=1), 1.0, rtol=1e-9)


def test_point_force_body_and_space_frames():
    Q = exp_so3([0.0, 0.0, np.pi / 2])
    f_space = PointForce((0.6, 0.2, 0.3), (1.0, 0, 0), frame="space")
    f_body = PointForce((0.6, 0.2, 0.3), (1.0, 0, 0), frame="body")
    sysm = RigidBodySystem(BODY, [f_space, f_body])
    ctx = sysm.context(0.0, np.zeros(3), np.zeros(3), Q, np.zeros(3))
    F1, t1 = f_space.wrench(ctx)
    F2, t2 = f_body.wrench(ctx)
    np.testing.assert_allclose(F1, [1, 0, 0])
    np.testing.assert_allclose(F2, Q @ [1, 0, 0], atol=1e-15)
    offset = np.array([0.6, 0.2, 0.3]) - BODY.center_of_mass
    np.testing.assert_allclose(t2, np.cross(offset, [1, 0, 0]), atol=1e-15)
    np.testing.assert_allclose(t1, np.cross(offset, Q.T @ [1, 0, 0]), atol=1e-15)


@pytest.mark.parametrize("frame", ["space", "body"])
def test_a_callable_force_or_torque_is_applied_by_the_cores_formula(frame):
    """A point force or torque given as a callable of t is the built-in kind's formula applied
    to the callable's output (no second formula in Python): the same wrench, bit for bit, as
    the constant force with that value, and against the hand computation b × Qᵀ F."""
    Q = exp_so3([0.3, -0.2, 1.1])
    point, f = (0.6, 0.2, 0.3), np.array([1.0, -2.0, 0.5])
    sysm = RigidBodySystem(BODY, [])
    ctx = sysm.context(0.7, np.zeros(3), np.zeros(3), Q, np.array([0.1, 0.2, 0.3]))
    for constant, callable_ in (
        (PointForce(point, f, frame=frame), PointForce(point, lambda t: f, frame=frame)),
        (Torque(f, frame=frame), Torque(lambda t: f, frame=frame)),
    ):
        assert constant.compiled and not callable_.compiled
        want, got = constant.wrench(ctx), callable_.wrench(ctx)
        assert all(np.array_equal(a, b) for a, b in zip(want, got, strict=True))
    F = Q @ f if frame == "body" else f
    offset = np.array(point) - BODY.center_of_mass
    F_got, tau_got = PointForce(point, lambda t: f, frame=frame).wrench(ctx)
    np.testing.assert_allclose(F_got, F, atol=1e-15)
    np.testing.assert_allclose(tau_got, np.cross(offset, Q.T @ F), atol=1e-14)


def test_time_dependent_body_torque_spins_up_sphere():
    # I ω̇ = τ(t) = t ẑ ⇒ ω_z = t²/(2I)
    body = RigidBody.sphere(2.0, 0.5)
    I = 0.4 * 2.0 * 0.25
    tr = simulate(
        body,
        (0, 2),
        omega0=(0, 0, 0),
        forces=[Torque(lambda t: [0, 0, t])],
        t_eval=np.linspace(0, 2, 5),
    )
    np.testing.assert_allclose(tr.omega[:, 2], tr.t**2 / (2 * I), rtol=1e-10, atol=1e-14)
    space = simulate(
        body,
        (0, 2),
        omega0=(0, 0, 0),
        Q0=exp_so3([1.0, 0, 0]),
        forces=[Torque((0, 0, 1.0), frame="space")],
        t_eval=[2.0],
    )
    np.testing.assert_allclose(space.omega_space[-1], [0, 0, 2.0 / I], rtol=1e-9, atol=1e-12)


def test_quadratic_drag_terminal_velocity():
    # m g = c v_t² ⇒ v_t = √(m g / c)
    body = RigidBody.sphere(1.0, 0.1)
    tr = simulate(
        body,
        (0, 30),
        omega0=(0, 0, 0),
        forces=[Gravity((0, 0, -9.81)), QuadraticDrag(0.4)],
        t_eval=[30.0],
    )
    assert tr.V[-1, 2] == pytest.approx(-np.sqrt(9.81 / 0.4), rel=1e-8)


def test_custom_force_with_potential_and_errors():
    k = 3.0
    spring_to_origin = CustomForce(
        lambda c: (-k * c.R, np.zeros(3)),
        potential=lambda c: 0.5 * k * c.R @ c.R,
        position_only=True,
        name="harmonic",
    )
    tr = simulate(
        BODY,
        (0, 5),
        omega0=(0.1, 0, 0),
        R0=(1, 0, 0),
        forces=[spring_to_origin],
        method="splitting",
        dt=1e-3,
        t_eval=np.linspace(0, 5, 11),
    )
    np.testing.assert_allclose(tr.R[:, 0], np.cos(np.sqrt(k / BODY.mass) * tr.t), atol=1e-5)
    with pytest.raises(ValueError, match="force bad must return a pair"):
        simulate(BODY, (0, 1), omega0=(0, 0, 1), forces=[CustomForce(lambda c: 1.0, name="bad")])
    with pytest.raises(NotImplementedError, match="has no potential"):
        CustomForce(lambda c: (np.zeros(3), np.zeros(3))).potential(None)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: Gravity((0, 0)), r"`g` must have shape \(3,\)"),
        (lambda: Spring((0, 0, 0), (1, 0, 0), -1.0), "`stiffness` must be a positive number"),
        (lambda: Spring((0, 0, 0), (1, 0, 0), 1.0, -2.0), "`rest_length` must be ≥ 0"),
        (lambda: Spring((0, 0, 0), (1, 0, 0), 1.0, damping=-1), "`damping` must be ≥ 0"),
        (lambda: PointForce((0, 0, 0), (1, 0, 0), frame="world"), "`frame` must be"),
        (lambda: Torque((1, 0, 0), frame="x"), "`frame` must be"),
        (lambda: QuadraticDrag(-1.0), "must be ≥ 0"),
        (lambda: CentralGravity(0.0), "`mu` must be a positive number"),
        (lambda: CustomForce(3), "`func` must be callable"),
    ],
)
def test_force_bad_input(make, match):
    with pytest.raises((ValueError, TypeError), match=match):
        make()


def test_hat_used_consistently():
    w = np.array([1.0, 2.0, 3.0])
    assert np.allclose(hat(w) @ w, 0)


def test_an_exception_in_a_users_force_names_the_force_and_the_time():
    """Issue 44: an exception raised by a user's callable arrived bare. It is re-raised as a
    ForceError naming the force and t, with the user's exception as its cause; the potential
    and the per-force wrenches say the same."""
    from poinsot import PointForce
    from poinsot.forces import ForceError

    def flaky(t):
        if t > 0.3:
            raise ZeroDivisionError("the user's bug")
        return (0.0, 0.0, 1.0)

    body = RigidBody.box(1.0, (1, 2, 3))
    with pytest.raises(ForceError, match=r"force PointForce raised ZeroDivisionError at t = 0\.3")\
            as err:  # fmt: skip
        simulate(body, (0, 1), omega0=(0, 1, 0), forces=[PointForce((0, 0, 0.5), flaky)])
    assert isinstance(err.value.__cause__, ZeroDivisionError)
    assert "the user's bug" in str(err.value)
