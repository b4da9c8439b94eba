"""The compiled core: backends agree, forces are immutable data, C functions are called by
address, nothing is compiled at run time, and the steps equal their references."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from poinsot import (
    CentralGravity,
    CustomForce,
    Gravity,
    LinearDrag,
    PointForce,
    QuadraticDrag,
    RigidBody,
    Spring,
    Torque,
    simulate,
)
from poinsot.dynamics import RigidBodySystem
from poinsot.rotation import matrix_from_euler

BODY = RigidBody.box(2.0, (1.0, 0.6, 0.3), position=(0.1, 0.2, 0.3))
PIVOT = (0.1, 0.2, 0.6)
FORCES = {
    "gravity": Gravity((0.3, -0.2, -9.8)),
    "central_gravity": CentralGravity(50.0, center=(-4.0, 1.0, -3.0)),
    "spring": Spring((0.5, 0.3, 0.15), (1.0, 0.5, 1.0), 30.0, 0.2),
    "damped_spring": Spring((0.5, 0.3, 0.15), (1.0, 0.5, 1.0), 30.0, 0.2, damping=0.7),
    "tether": Spring((-0.5, 0.0, 0.0), (-1.0, 0.2, 1.0), 20.0, 0.5, tether=True),
    "linear_drag": LinearDrag(0.4, rotational=0.05),
    "quadratic_drag": QuadraticDrag(0.4, rotational=0.05),
    "point_force_space": PointForce((0.6, 0.2, 0.3), (1.0, -2.0, 0.5), frame="space"),
    "point_force_body": PointForce((0.6, 0.2, 0.3), (1.0, -2.0, 0.5), frame="body"),
    "torque_space": Torque((0.2, -0.1, 0.3), frame="space"),
    "torque_body": Torque((0.2, -0.1, 0.3), frame="body"),
}
METHODS = {"rk4": 0.01, "rkmk4": 0.01, "splitting": 0.01, "dop853": None}


def _run(force, method, pivot, backend, t1=0.4):
    return simulate(
        BODY,
        (0, t1),
        omega0=(0.3, 1.2, -0.5),
        Q0=matrix_from_euler([0.1, 0.6, -0.3], "ZXZ"),
        forces=[force],
        pivot=pivot,
        method=method,
        dt=METHODS[method],
        **({"rtol": 1e-9, "atol": 1e-11} if METHODS[method] is None else {}),
        t_eval=np.linspace(0, t1, 5),
        backend=backend,
    )


@pytest.mark.parametrize("pivot", [None, PIVOT], ids=["free", "pivot"])
@pytest.mark.parametrize("method", sorted(METHODS))
@pytest.mark.parametrize("kind", sorted(FORCES))
def test_backends_agree_to_roundoff(kind, method, pivot):
    force = FORCES[kind]
    if method == "splitting" and not force.position_only:
        pytest.skip("the splitting method takes position-only forces")
    compiled = _run(force, method, pivot, "compiled")
    python = _run(force, method, pivot, "python")
    assert compiled.backend == "compiled" and python.backend == "python"
    scale = np.abs(compiled.state).max()
    np.testing.assert_allclose(python.state, compiled.state, rtol=0, atol=1e-13 * scale)
    assert python.nfev == compiled.nfev and python.nsteps == compiled.nsteps


def _lift(t, y):
    """A force of the time and the body-frame state: (F in space, τ body about the c.o.m.)."""
    return 0.5, -0.2, 9.8, 0.1 * np.sin(t), 0.0, 0.2 * y[17]


def _c_force():
    """``_lift`` as a C function (ctypes): the core calls it by address."""
    import ctypes

    proto = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
                             ctypes.POINTER(ctypes.c_double))  # fmt: skip

    def lift(t, y, out):
        w = _lift(t, [y[k] for k in range(18)])
        for k in range(6):
            out[k] = w[k]
        return 0

    c_lift = proto(lift)
    force = CustomForce(c_lift, name="lift")
    force.__dict__["_keep"] = c_lift  # the callback must outlive the runs
    return force


def _python_force():
    def lift(ctx):
        w = _lift(ctx.t, ctx.state())
        return np.array(w[:3]), np.array(w[3:])

    return CustomForce(lift, name="lift")


@pytest.mark.parametrize("method", ["rk4", "dop853", pytest.param("rkmk4", marks=pytest.mark.slow)])
def test_a_c_force_is_called_by_address_and_equals_the_python_force(method):
    """The same wrench as a C function (no Python between the core and it: ``compiled``) and as
    a Python callable (called back: ``python``) gives the same motion, bit for bit."""
    force = _c_force()
    assert force.address is not None and not force.compiled
    assert RigidBodySystem(BODY, [force]).compiled
    c = _run(force, method, None, None)
    python = _run(_python_force(), method, None, None)
    assert (c.backend, python.backend) == ("compiled", "python")
    np.testing.assert_array_equal(c.state, python.state)
    two = simulate(BODY, (0, 0.4), omega0=(0.3, 1.2, -0.5), forces=[force, _c_force()],
                   method="rk4", dt=0.01)  # fmt: skip
    assert two.backend == "python"  # two C forces: summed through Python


def test_c_functions_of_the_wrong_signature_are_refused():
    import ctypes

    wrong = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_double)(lambda t: 0.0)
    with pytest.raises(TypeError, match=r"int f\(double t, const double \*y, double \*wrench\)"):
        CustomForce(wrong)


def test_python_callables_take_the_python_path_and_are_refused_by_the_compiled_one():
    slow = Torque(lambda t: [0.0, 0.0, t])
    assert not RigidBodySystem(BODY, [slow]).compiled
    assert _run(slow, "rk4", None, None).backend == "python"
    with pytest.raises(ValueError, match="needs built-in forces; these are Python callables"):
        _run(slow, "rk4", None, "compiled")
    with pytest.raises(ValueError, match="`backend` must be one of"):
        _run(Gravity(), "rk4", None, "gpu")


# --------------------------------------------------------------------------- forces as data
def test_a_force_shared_by_two_systems_is_not_changed_by_the_second():
    """Regression: ``bind()`` used to write the body's centre of mass into the force, so
    building a second system changed the first system's torque."""
    spring = Spring((0.5, 0.3, 0.15), (1.0, 0.5, 1.0), 30.0, 0.2)
    first = RigidBodySystem(BODY, [spring])
    y = first.initial_state(omega0=(0.3, 1.2, -0.5), Q0=matrix_from_euler([0.1, 0.6, -0.3]))
    before = first.wrench(0.0, y[0:3], y[3:6], y[6:15].reshape(3, 3), y[15:18])
    other = RigidBody.box(5.0, (2.0, 1.0, 1.0), position=(3.0, -1.0, 2.0))
    RigidBodySystem(other, [spring])
    after = first.wrench(0.0, y[0:3], y[3:6], y[6:15].reshape(3, 3), y[15:18])
    np.testing.assert_array_equal(before[0], after[0])
    np.testing.assert_array_equal(before[1], after[1])
    with pytest.raises(AttributeError, match="Spring is immutable"):
        spring.stiffness = 3.0
    with pytest.raises(ValueError, match="read-only"):
        spring.point[0] = 1.0


def test_damped_spring_is_not_conservative():
    damped = FORCES["damped_spring"]
    assert damped.has_potential and damped.dissipative and not damped.conservative
    assert not damped.position_only
    assert FORCES["spring"].conservative
    tr = simulate(BODY, (0, 5), omega0=(0.3, 1.2, -0.5), forces=[damped], t_eval=[0, 2.5, 5])
    assert not tr.is_conservative and not tr.diagnostics()["energy_conserved_by_model"]
    assert tr.total_energy[-1] < tr.total_energy[0]


# --------------------------------------------------------------------------- particle sums
PARTICLES = RigidBody.from_particles(
    np.random.default_rng(3).uniform(0.5, 2.0, 20), np.random.default_rng(4).normal(size=(20, 3))
)
Q_TEST = matrix_from_euler([0.7, -0.4, 1.9], "ZXZ")


def _particle_wrench(body, forces_on_particles):
    """The definition, eq. (08): ``F = Σ F_i`` and ``τ = Σ u_i × Qᵀ F_i``."""
    F = forces_on_particles.sum(0)
    tau = np.cross(body.u, forces_on_particles @ Q_TEST).sum(0)
    return F, tau


def _kernel_wrench(force, body=PARTICLES, R=None, V=None, omega=None):
    system = RigidBodySystem(body, [force])
    R = body.center_of_mass if R is None else R
    V = np.zeros(3) if V is None else V
    omega = np.zeros(3) if omega is None else omega
    from poinsot.forces import ForceContext

    return force.wrench(ForceContext(body, 0.0, R, V, Q_TEST, omega)), system


def test_gravity_equals_the_particle_sum():
    g = np.array([0.3, -0.2, -9.8])
    (F, tau), _ = _kernel_wrench(Gravity(g))
    F_ref, tau_ref = _particle_wrench(PARTICLES, np.outer(PARTICLES.particle_masses, g))
    np.testing.assert_allclose(F, F_ref, rtol=1e-14)
    np.testing.assert_allclose(tau, tau_ref, atol=1e-12)


def test_point_force_and_spring_equal_a_force_on_one_particle():
    point = PARTICLES.particle_positions[7]
    u = PARTICLES.u
    f = np.array([1.0, -2.0, 0.5])
    for frame in ("space", "body"):
        (F, tau), _ = _kernel_wrench(PointForce(point, f, frame=frame))
        F_i = np.zeros((len(u), 3))
        F_i[7] = Q_TEST @ f if frame == "body" else f
        F_ref, tau_ref = _particle_wrench(PARTICLES, F_i)
        np.testing.assert_allclose(F, F_ref, atol=1e-14)
        np.testing.assert_allclose(tau, tau_ref, atol=1e-13)
    # spring: T d̂ on the particle it is attached to, T = k (ℓ − ℓ₀) − c d̂·ṙ_p
    anchor = np.array([3.0, 1.0, -2.0])
    V, w = np.array([0.3, 0.1, -0.2]), np.array([0.5, -1.0, 0.7])
    spring = Spring(point, anchor, 7.0, 0.5, damping=0.3)
    (F, tau), _ = _kernel_wrench(spring, V=V, omega=w)
    r_p = PARTICLES.center_of_mass + Q_TEST @ u[7]
    v_p = V + Q_TEST @ np.cross(w, u[7])
    d = anchor - r_p
    ell = np.linalg.norm(d)
    tension = 7.0 * (ell - 0.5) - 0.3 * (d / ell) @ v_p
    F_i = np.zeros((len(u), 3))
    F_i[7] = tension * d / ell
    F_ref, tau_ref = _particle_wrench(PARTICLES, F_i)
    np.testing.assert_allclose(F, F_ref, rtol=1e-13)
    np.testing.assert_allclose(tau, tau_ref, rtol=1e-12, atol=1e-13)


def test_torque_equals_a_couple_of_two_particle_forces():
    # a couple: F at particle 3 and −F at particle 5 gives τ = (u3 − u5) × QᵀF, F = 0
    u = PARTICLES.u
    F_space = np.array([0.4, 1.0, -0.3])
    F_i = np.zeros((len(u), 3))
    F_i[3], F_i[5] = F_space, -F_space
    F_ref, tau_ref = _particle_wrench(PARTICLES, F_i)
    (F, tau), _ = _kernel_wrench(Torque(Q_TEST @ tau_ref, frame="space"))
    np.testing.assert_allclose(F, F_ref, atol=1e-14)
    np.testing.assert_allclose(tau, tau_ref, atol=1e-13)
    (F, tau), _ = _kernel_wrench(Torque(tau_ref, frame="body"))
    np.testing.assert_allclose(tau, tau_ref, atol=1e-15)


def test_linear_drag_equals_the_particle_sum_and_quadratic_its_closed_form():
    # linear drag on each particle −(c/M) m_i ṙ_i sums to −c V (the rotational part is a model)
    V, w = np.array([0.3, 0.1, -0.2]), np.array([0.5, -1.0, 0.7])
    (F, tau), _ = _kernel_wrench(LinearDrag(0.8, rotational=0.2), V=V, omega=w)
    m = PARTICLES.particle_masses
    v_i = V + np.cross(w, PARTICLES.u) @ Q_TEST.T
    np.testing.assert_allclose(F, -(0.8 / m.sum()) * (m[:, None] * v_i).sum(0), atol=1e-14)
    np.testing.assert_allclose(tau, -0.2 * w, atol=1e-15)
    (F, tau), _ = _kernel_wrench(QuadraticDrag(0.8, rotational=0.2), V=V, omega=w)
    np.testing.assert_allclose(F, -0.8 * np.linalg.norm(V) * V, atol=1e-15)
    np.testing.assert_allclose(tau, -0.2 * np.linalg.norm(w) * w, atol=1e-15)


def test_central_gravity_converges_to_the_particle_sum_at_the_expected_rate():
    """MacCullagh's formula truncates the multipole expansion after the quadrupole: against the
    exact particle sum, the force error falls like r⁻⁵ (the octupole term, (d/r)³ relative to
    μM/r²) and the torque error like r⁻⁴ (relative (d/r) to the quadrupole torque μI/r³)."""
    mu = 7.0
    direction = np.array([0.6, -0.48, 0.64])
    errors_F, errors_tau = [], []
    radii = np.array([20.0, 40.0, 80.0])
    for r in radii:
        R = PARTICLES.center_of_mass + r * direction
        (F, tau), _ = _kernel_wrench(CentralGravity(mu), R=R)
        r_i = R + PARTICLES.u @ Q_TEST.T
        F_i = (
            -mu
            * PARTICLES.particle_masses[:, None]
            * r_i
            / np.linalg.norm(r_i, axis=1)[:, None] ** 3
        )
        F_ref, tau_ref = _particle_wrench(PARTICLES, F_i)
        errors_F.append(np.linalg.norm(F - F_ref))
        errors_tau.append(np.linalg.norm(tau - tau_ref))
    slope_F = np.polyfit(np.log(radii), np.log(errors_F), 1)[0]
    slope_tau = np.polyfit(np.log(radii), np.log(errors_tau), 1)[0]
    assert slope_F < -4.7, (slope_F, errors_F)
    assert slope_tau < -3.7, (slope_tau, errors_tau)


# --------------------------------------------------------------------------- the engine
def test_rk4_in_registers_equals_the_tableau_step_to_roundoff():
    """The core's RK4 with the rigid state in registers against its general tableau step
    (an ExplicitRungeKutta with RK4's data): the same run to round-off."""
    from poinsot.integrate import RK4, ExplicitRungeKutta

    class RK4AsTableau(ExplicitRungeKutta):  # the generic stepper with RK4's data
        name = "rk4-as-tableau"
        order = 4
        A, B, C = RK4.A, RK4.B, RK4.C

    kw = dict(omega0=(0.3, 1.2, -0.5), V0=(0.1, 0, 0.2), forces=[FORCES["spring"],
              FORCES["gravity"]], dt=0.01, t_eval=np.linspace(0, 1, 11))  # fmt: skip
    a = simulate(BODY, (0, 1), method=RK4, **kw)
    b = simulate(BODY, (0, 1), method=RK4AsTableau, **kw)
    np.testing.assert_allclose(a.state, b.state, rtol=0, atol=1e-14 * np.abs(a.state).max())


def test_dop853_equals_scipy_solve_ivp():
    """The same method, controller and first-step rule as SciPy's DOP853 (the cross-check; not
    the engine): a whole run takes the same steps (the same first step, the same error norm,
    the same controller) and gives the same solution to the tolerance; the vector field is
    Python's, called back from the core."""
    from scipy.integrate import DOP853 as ScipyDOP853
    from scipy.integrate import solve_ivp

    from poinsot.integrate.driver import integrate

    class Euler:  # Euler's equations (27)–(29), a plain vector field
        I = np.array([1.0, 2.0, 3.0])

        def rhs(self, t, w):
            I = self.I
            return np.array(
                [
                    (I[1] - I[2]) / I[0] * w[1] * w[2],
                    (I[2] - I[0]) / I[1] * w[2] * w[0],
                    (I[0] - I[1]) / I[2] * w[0] * w[1],
                ]
            )

    w0 = np.array([0.3, 1.0, 0.5])
    ref = ScipyDOP853(Euler().rhs, 0.0, w0, 30.0, rtol=1e-9, atol=1e-12)
    # a whole run: the same number of steps, the same solution to the tolerance
    ours = integrate(Euler(), "dop853", (0, 30), w0, rtol=1e-9, atol=1e-12)
    steps = 0
    while ref.status == "running":
        ref.step()
        steps += 1
    assert ours.nsteps == steps
    np.testing.assert_allclose(ours.y[-1], ref.y, rtol=0, atol=1e-8)
    t = np.linspace(0, 30, 7)
    sampled = integrate(Euler(), "dop853", (0, 30), w0, t_eval=t, rtol=1e-9, atol=1e-12)
    dense = solve_ivp(Euler().rhs, (0, 30), w0, method="DOP853", rtol=1e-9, atol=1e-12, t_eval=t)
    np.testing.assert_allclose(sampled.y, dense.y.T, rtol=0, atol=1e-8)


def test_a_run_compiles_nothing():
    """The engine is compiled when the package is built (the Rust core): a fresh process runs
    a simulation without any run-time compiler (numba is no dependency)."""
    code = textwrap.dedent(
        """
        import sys
        from poinsot import Gravity, RigidBody, simulate
        body = RigidBody.box(1.0, (1.0, 2.0, 3.0))
        tr = simulate(body, (0, 1), omega0=(0, 1, 1), forces=[Gravity()], method="rk4", dt=0.01)
        print(tr.backend, "numba" in sys.modules)
        """
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.split() == ["compiled", "False"], run.stdout


# --------------------------------------------------------------------------- unphysical bodies
def test_unphysical_moments_need_consent_and_then_run():
    """Hairer, Lubich & Wanner, Geometric Numerical Integration, §IV.1: the free rigid body with
    I = (2, 1, 2/3) (I2 + I3 < I1) is a standard test problem; poinsot runs it on request."""
    from poinsot.bodies import UnphysicalInertiaWarning

    inertia = np.diag([2.0, 1.0, 2.0 / 3.0])
    with pytest.raises(ValueError, match=r"I1 \+ I2 ≥ I3 .*allow_unphysical=True"):
        RigidBody(1.0, inertia)
    with pytest.warns(UnphysicalInertiaWarning, match="accepted with allow_unphysical"):
        body = RigidBody(1.0, inertia, allow_unphysical=True)
    w0 = np.array([np.cos(1.1), 0.0, np.sin(1.1)])  # HLW's initial momentum direction
    tr = simulate(
        body, (0, 100), omega0=w0 / np.diag(inertia), method="splitting", dt=0.01, save_every=100
    )
    L = tr.angular_momentum_com
    assert np.abs(np.linalg.norm(L, axis=1) / np.linalg.norm(L[0]) - 1).max() < 1e-13
    assert np.abs(tr.energy_drift).max() < 1e-3
