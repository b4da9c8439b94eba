"""Relative motion (poinsot.relative; docs/relative.md, paper eqs (1)-(18)).

Every formula is checked against an independent route: the compact Coriolis moment (5) against
its three-term form (2) and its particle-sum definition (6); the transport moment against the
particles' transport inertia forces; the relative simulation against poinsot's absolute
simulation of the same body under the same forces (the decisive test); the Euler-angle
equations (12)-(15) against the rotation-matrix engine; case (16) against its conservation law.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import example, given, settings
from hypothesis import strategies as st

from poinsot import RigidBody, simulate
from poinsot.forces import Gravity, Spring
from poinsot.relative import (
    Carrier,
    balancing_moment,
    coriolis_moment,
    coriolis_moment_particles,
    coriolis_moment_three_term,
    planar_inertia,
    planar_inertia_ellipsoid,
    planar_principal_moments,
    relative_equations,
    simulate_relative,
    transport_moment,
)

T = sp.Symbol("t", real=True)
#: One time-varying carrier shared by the tests (its engine compiles once per process): a
#: vehicle whose turn rate varies, nodding, and speeding up along its own x axis.
VARYING = Carrier(
    omega_e=[0.2 * sp.sin(0.7 * T), 0.1 * T, 0.8 + 0.3 * sp.cos(1.3 * T)],
    origin_acceleration=[0.5 + 0.2 * T, 0, 0],
    t=T,
    name="turning vehicle",
)
BODY = RigidBody.box(3.0, (0.4, 0.7, 1.2), orientation=[[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0],
                                                         [0.48, 0.64, 0.6]])  # fmt: skip

finite = st.floats(-10, 10, allow_nan=False)
vectors = st.tuples(finite, finite, finite).map(np.array)


def _random_particles(seed, n=7):
    rng = np.random.default_rng(seed)
    m = rng.uniform(0.1, 2.0, n)
    x = rng.normal(size=(n, 3)) * rng.uniform(0.2, 3.0, 3)
    rho = x - m @ x / m.sum()
    return m, rho


def _inertia(m, rho):
    return sum(mi * (r @ r * np.eye(3) - np.outer(r, r)) for mi, r in zip(m, rho, strict=True))


# --------------------------------------------------------------------------- the moments
@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), wr=vectors, we=vectors)
@example(seed=0, wr=np.array([0.0, 0.0, 4.630374632459643e-293]), we=np.array([0.0, 1.0, 1.0]))
def test_coriolis_compact_equals_three_term_and_particle_sum(seed, wr, we):
    m, rho = _random_particles(seed)
    J = _inertia(m, rho)
    compact = coriolis_moment(J, wr, we)
    three = coriolis_moment_three_term(J, wr, we)
    particles = coriolis_moment_particles(m, rho, wr, we)
    # max|·| rather than the norm, whose squares underflow for |ω| near 1e-293
    scale = np.trace(J) * np.abs(wr).max() * np.abs(we).max() + 1e-300
    assert np.max(np.abs(compact - three)) <= 1e-12 * scale
    assert np.max(np.abs(compact - particles)) <= 1e-12 * scale


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), s=st.floats(1e-100, 1e100), a=st.floats(1e-50, 1e50))
def test_coriolis_and_transport_scale_invariance(seed, s, a):
    """Both moments are linear in J and quadratic in the angular velocities (ε ~ ω²)."""
    m, rho = _random_particles(seed)
    J = _inertia(m, rho)
    wr, we, ee = np.random.default_rng(seed).normal(size=(3, 3))
    Mc = coriolis_moment(J, wr, we)
    Me = transport_moment(J, we, ee)
    np.testing.assert_allclose(coriolis_moment(s * J, a * wr, a * we), s * a * a * Mc,
                               rtol=1e-12, atol=1e-12 * s * a * a * np.abs(Mc).max())  # fmt: skip
    np.testing.assert_allclose(transport_moment(s * J, a * we, a * a * ee), s * a * a * Me,
                               rtol=1e-12, atol=1e-12 * s * a * a * np.abs(Me).max())  # fmt: skip


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_planar_inertia_definition_and_principal_relation(seed):
    """J' = Σ m ρρᵀ (paper (3)-(4)) = ½ tr(J) 𝟙 − J, and A' = (B + C − A)/2 in principal axes."""

    def planar_inertia_particles(m, rho):  # the definition, paper (3)-(4): Σ m ρρᵀ
        return np.einsum("i,ij,ik->jk", m, rho, rho)

    m, rho = _random_particles(seed)
    J = _inertia(m, rho)
    Jp = planar_inertia(J)
    np.testing.assert_allclose(Jp, planar_inertia_particles(m, rho), rtol=1e-12,
                               atol=1e-13 * np.trace(J))  # fmt: skip
    A, B, C = np.linalg.eigvalsh(J)
    E = np.linalg.eigh(J)[1]
    np.testing.assert_allclose(np.diag(E.T @ Jp @ E), [(B + C - A) / 2, (C + A - B) / 2,
                               (A + B - C) / 2], rtol=1e-10, atol=1e-12 * np.trace(J))  # fmt: skip
    np.testing.assert_allclose(planar_principal_moments([A, B, C]),
                               [(B + C - A) / 2, (C + A - B) / 2, (A + B - C) / 2])  # fmt: skip


def test_transport_moment_equals_the_particles_transport_inertia_forces():
    """M_e is the moment about the centre of mass of −m (ε_e × ρ + ω_e × (ω_e × ρ))."""
    m, rho = _random_particles(3)
    J = _inertia(m, rho)
    rng = np.random.default_rng(4)
    for we, ee in rng.normal(size=(5, 2, 3)):
        acc = np.cross(ee, rho) + np.cross(we, np.cross(we, rho))
        direct = -np.sum(m[:, None] * np.cross(rho, acc), axis=0)
        np.testing.assert_allclose(transport_moment(J, we, ee), direct, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(balancing_moment(J, we, ee), -direct, rtol=1e-12, atol=1e-12)


def test_textbook_values_of_the_moments():
    # a rod of two unit masses at x = ±1: J' = diag(2, 0, 0), J = diag(0, 2, 2)
    J = np.diag([0.0, 2.0, 2.0])
    np.testing.assert_allclose(planar_inertia(J), np.diag([2.0, 0.0, 0.0]))
    # spinning about z relative to a carrier turning about x: M_c = 2 e3 × (2 e1) = 4 e2
    np.testing.assert_allclose(coriolis_moment(J, [0, 0, 1], [1, 0, 0]), [0, 4, 0])
    semi, _axes = planar_inertia_ellipsoid(np.diag([1.0, 2.0, 3.0]))  # J' = diag(2, 1, 0)
    np.testing.assert_allclose(np.sort(semi)[:2], [1 / np.sqrt(2), 1.0])
    assert np.isinf(semi).sum() == 1


def test_moments_broadcast_over_trajectories():
    J = np.diag([1.0, 2.0, 3.0])
    wr = np.random.default_rng(0).normal(size=(4, 5, 3))
    out = coriolis_moment(J, wr, [0.0, 0.0, 1.0])
    assert out.shape == (4, 5, 3)
    np.testing.assert_allclose(out[2, 3], coriolis_moment(J, wr[2, 3], [0, 0, 1]))


# --------------------------------------------------------------------------- the decisive test
def _absolute_twin(sol, forces, t):
    """poinsot's absolute simulation of the same body under the same physical forces, from the
    relative run's initial absolute state."""
    return simulate(BODY, (t[0], t[-1]), omega0=sol.omega_absolute[0], Q0=sol.Q_absolute[0],
                    R0=sol.R_absolute[0], V0=sol.V_absolute[0], forces=forces, t_eval=t,
                    rtol=1e-11, atol=1e-13)  # fmt: skip


def _assert_same_motion(sol, ab, tol):
    assert np.max(np.abs(sol.Q_absolute - ab.Q)) < tol
    assert np.max(np.abs(sol.omega_absolute - ab.omega)) < tol * np.abs(ab.omega).max()
    assert np.max(np.abs(sol.R_absolute - ab.R)) < tol * (1 + np.abs(ab.R).max())
    assert np.max(np.abs(sol.V_absolute - ab.V)) < tol * (1 + np.abs(ab.V).max())


FORCES = (Gravity((0.0, 0.0, -9.81)), Spring((0.2, 0.35, 0.6), (0.5, -0.3, 2.0), 15.0, 0.4))


def test_relative_equals_absolute_for_a_constant_carrier():
    t = np.linspace(0, 6, 61)
    carrier = Carrier(omega_e=(0.3, -0.4, 1.5))
    sol = simulate_relative(BODY, (0, 6), omega_r0=(0.5, -1.0, 2.0), carrier=carrier,
                            forces=FORCES, t_eval=t, rtol=1e-11, atol=1e-13,
                            Q_carrier0=[0.9, 0.1, -0.3, 0.3])  # fmt: skip
    assert sol.success and sol.backend == "compiled"
    _assert_same_motion(sol, _absolute_twin(sol, FORCES, t), 1e-8)


def test_relative_equals_absolute_for_a_time_varying_carrier():
    t = np.linspace(0, 6, 61)
    sol = simulate_relative(BODY, (0, 6), omega_r0=(0.5, -1.0, 2.0), carrier=VARYING,
                            forces=FORCES, t_eval=t, rtol=1e-11, atol=1e-13,
                            r0=(1.0, 0.5, -0.2), v_r0=(0.1, 0.0, 0.3))  # fmt: skip
    assert np.abs(sol.carrier_motion[:, 3:6]).max() > 0.1  # ε_e really varies
    assert np.abs(sol.origin).max() > 1.0  # the origin really accelerates
    _assert_same_motion(sol, _absolute_twin(sol, FORCES, t), 1e-8)


def test_spline_carrier_matches_its_polynomial_sympy_twin():
    """A cubic spline of ω_e is a polynomial on each piece: the same carrier as a SymPy
    polynomial gives the same motion, and ε_e is the spline's exact derivative."""
    from scipy.interpolate import CubicSpline

    poly = [0.1 * T**3 - 0.2 * T, 0.3 * T**2, 1.0 + 0.05 * T**3]
    x = np.linspace(-1, 5, 7)
    values = np.array([[float(p.subs(T, s)) for p in poly] for s in x])
    d2 = np.array([[float(sp.diff(p, T, 2).subs(T, s)) for p in poly] for s in x[[0, -1]]])
    spline = CubicSpline(x, values, bc_type=((2, d2[0]), (2, d2[1])))
    s = Carrier(omega_e=spline)
    e = Carrier(omega_e=poly, t=T)
    tt = np.linspace(0, 4, 9)
    np.testing.assert_allclose(s.motions(tt), e.motions(tt), rtol=1e-12, atol=1e-12)
    a = simulate_relative(BODY, (0, 4), omega_r0=(1, 0, 0.5), carrier=s, t_eval=tt)
    b = simulate_relative(BODY, (0, 4), omega_r0=(1, 0, 0.5), carrier=e, t_eval=tt)
    np.testing.assert_allclose(a.y, b.y, rtol=1e-9, atol=1e-9)


def test_python_callable_carrier_runs_the_same_kernels():
    w = sp.lambdify(T, VARYING.expressions["omega_e"])
    e = sp.lambdify(T, VARYING.expressions["epsilon_e"])
    carrier = Carrier(omega_e=w, epsilon_e=e, origin_acceleration=lambda t: [0.5 + 0.2 * t, 0, 0])
    t = np.linspace(0, 1, 5)
    kw = dict(omega_r0=(0.5, -1.0, 2.0), forces=FORCES, t_eval=t, method="rk4", dt=0.01)
    py = simulate_relative(BODY, (0, 1), carrier=carrier, **kw)
    assert py.backend == "python"
    compiled = simulate_relative(BODY, (0, 1), carrier=VARYING, **kw)
    np.testing.assert_allclose(py.y, compiled.y, rtol=1e-12, atol=1e-12)


def test_rk4_converges_at_fourth_order_on_the_relative_system():
    carrier = Carrier(omega_e=(0.3, -0.4, 1.5))
    ref = simulate_relative(BODY, (0, 2), omega_r0=(0.5, -1.0, 2.0), carrier=carrier,
                            rtol=1e-13, atol=1e-15, t_eval=[2.0]).y[-1]  # fmt: skip
    errors = []
    for dt in (0.04, 0.02, 0.01):
        y = simulate_relative(BODY, (0, 2), omega_r0=(0.5, -1.0, 2.0), carrier=carrier,
                              method="rk4", dt=dt, t_eval=[2.0]).y[-1]  # fmt: skip
        errors.append(np.abs(y - ref).max())
    slopes = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(np.abs(slopes - 4) < 0.3), slopes


# --------------------------------------------------------------------------- case (16)
def test_balanced_transport_conserves_the_relative_energy_and_bounds_the_hodograph():
    """Case (16): under the balancing moment, ½ω_r·Jω_r is conserved over a long run, and
    max|ω_r|/min|ω_r| never exceeds √(C/A) (18), a bound the motion comes close to here."""
    body = RigidBody.box(1.0, (0.3, 1.0, 2.0))
    carrier = Carrier(omega_e=[2.0 * sp.sin(0.3 * T), 3.0, 1.5 * sp.cos(0.2 * T)], t=T)
    sol = simulate_relative(body, (0, 300), omega_r0=(0.05, 0.0, 1.0), carrier=carrier,
                            balance_transport=True, t_eval=np.linspace(0, 300, 20001),
                            rtol=1e-11, atol=1e-13)  # fmt: skip
    E = sol.relative_energy
    assert np.max(np.abs(E - E[0])) < 1e-8 * E[0]
    ratio, bound = sol.hodograph_ratio(), sol.hodograph_bound()
    assert ratio <= bound * (1 + 1e-8)
    assert ratio > 0.95 * bound, (ratio, bound)
    # without the balancing moment the energy is not conserved
    free = simulate_relative(body, (0, 20), omega_r0=(0.05, 0.0, 1.0), carrier=carrier,
                             t_eval=np.linspace(0, 20, 201))  # fmt: skip
    assert np.ptp(free.relative_energy) > 0.1 * free.relative_energy[0]


# --------------------------------------------------------------------------- Euler angles
def test_euler_angle_equations_agree_with_the_rotation_matrix_engine():
    """Eqs (12)-(15) in Euler angles, integrated by SciPy, against the compiled engine, away
    from θ = 0, π."""
    from scipy.integrate import solve_ivp

    body = RigidBody.box(3.0, (0.4, 0.7, 1.2))  # principal axes = body axes
    A, B, C = np.diag(body.inertia)
    carrier = Carrier(omega_e=[0.2 * sp.sin(0.7 * T), 0.1 * T, 0.8 + 0.3 * sp.cos(1.3 * T)], t=T)
    eqs = relative_equations((A, B, C), carrier=carrier, torque=(0, 0, 0))
    q = eqs.coordinates
    dq = [sp.diff(c, eqs.t) for c in q]
    x, v = sp.symbols("x0:3"), sp.symbols("v0:3")
    subs = {**dict(zip(dq, v, strict=True)), **dict(zip(q, x, strict=True))}
    M = sp.lambdify((eqs.t, x, v), eqs.mass_matrix().subs(subs))
    f = sp.lambdify((eqs.t, x, v), eqs.forcing().subs(subs))

    def rhs(t, z):
        acc = np.linalg.solve(np.array(M(t, z[:3], z[3:]), float), np.array(f(t, z[:3], z[3:]),
                              float).ravel())  # fmt: skip
        return np.concatenate([z[3:], acc])

    angles0, rates0 = np.array([0.3, 1.1, -0.4]), np.array([0.5, -0.2, 1.5])
    t = np.linspace(0, 3, 31)
    ref = solve_ivp(rhs, (0, 3), np.concatenate([angles0, rates0]), t_eval=t, rtol=1e-12,
                    atol=1e-12, method="DOP853")  # fmt: skip
    sol = simulate_relative(body, (0, 3), euler_angles0=angles0, euler_rates0=rates0,
                            carrier=carrier, hold_com=True, t_eval=t)  # fmt: skip
    from poinsot.rotation import matrix_from_euler

    np.testing.assert_allclose(sol.Q_r, matrix_from_euler(ref.y[:3].T, "ZXZ"), atol=1e-8)
    np.testing.assert_allclose(sol.euler_rates(), ref.y[3:].T, atol=1e-8)
    assert "\\begin{align}" in eqs.latex() and "\\theta" in eqs.latex()


def test_euler_rates_refused_at_the_gimbal_lock():
    sol = simulate_relative(BODY, (0, 1), euler_angles0=(0.2, 0.0, 0.1), omega_r0=(0, 0, 1),
                            carrier=Carrier(omega_e=(0, 0, 0.5)), t_eval=[0, 1])  # fmt: skip
    with pytest.raises(ValueError, match="gimbal lock"):
        sol.euler_rates()


def test_carrier_given_by_euler_angles_or_attitude():
    """ω_e from the carrier's Euler angles (14) equals vee(Q_cᵀ Q̇_c) of the same rotation, and
    the integrated carrier attitude follows the exact one."""
    from poinsot.relative.carrier import zxz_matrix

    angles = [0.4 * T, 0.8 + 0.2 * sp.sin(T), 1.5 * T]
    by_angles = Carrier(euler_angles=angles, t=T)
    by_matrix = Carrier(rotation=zxz_matrix(*angles), t=T)
    tt = np.linspace(0, 3, 7)
    np.testing.assert_allclose(by_angles.motions(tt), by_matrix.motions(tt), atol=1e-12)
    sol = simulate_relative(BODY, (0, 3), omega_r0=(0.2, 0.1, 0), carrier=by_angles, t_eval=tt,
                            hold_com=True)  # fmt: skip
    np.testing.assert_allclose(sol.Q_carrier, by_angles.attitude(tt), atol=1e-9)
    half = sp.Rational(1, 2)
    quat = Carrier(quaternion=[sp.cos(half * T), 0, 0, sp.sin(half * T)], t=T)  # about z, 1 rad/s
    np.testing.assert_allclose(quat.motions(tt)[:, :3], np.tile([0, 0, 1.0], (7, 1)), atol=1e-14)


def test_turntable_example_in_the_docstring_frame_conventions():
    """A body at rest on a turntable turning about the carrier's z, one of the body's principal
    axes: it stays at rest relative to the turntable (a steady rotation), Q_c = Rz(ωt)."""
    body = RigidBody.box(3.0, (0.4, 0.7, 1.2))
    sol = simulate_relative(body, (0, 2), omega_r0=(0, 0, 0), carrier=Carrier(omega_e=(0, 0, 0.5)),
                            hold_com=True, t_eval=[2.0], rtol=1e-12, atol=1e-14)  # fmt: skip
    c, s = np.cos(1.0), np.sin(1.0)
    np.testing.assert_allclose(sol.Q_carrier[-1], [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-10)
    assert np.abs(sol.omega_r).max() < 1e-12  # held still relative to the carrier


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        (dict(omega_e=lambda t: [0, 0, 1]), ValueError, "needs `epsilon_e`"),
        (dict(omega_e=(0, 0, 1), epsilon_e=lambda t: [0, 0, 0]), ValueError, "`epsilon_e` is for"),
        (dict(omega_e=(0, 0, 1), euler_angles=["t", 0, 0]), ValueError, "exactly one way"),
        (dict(), ValueError, "exactly one way"),
        (dict(omega_e=(0, 1)), ValueError, r"`omega_e` must have shape \(3,\)"),
        (dict(omega_e=(0, np.nan, 1)), ValueError, r"`omega_e\[1\]` must be finite"),
        (dict(omega_e=["t", "2*x", 0]), ValueError, "unknown name .x."),
        (dict(omega_e=["t", "sin(", 0]), ValueError, r"`omega_e\[1\]`: not an expression"),
        (dict(euler_angles=(0.1, 0.2, 0.3)), TypeError, "SymPy expressions"),
        (dict(omega_e=(0, 0, 1), origin_acceleration=(1, 2)), ValueError, "origin_acceleration"),
        (dict(omega_e=object()), TypeError, "`omega_e` must be"),
    ],
)
def test_carrier_bad_input(kwargs, error, match):
    with pytest.raises(error, match=match):
        Carrier(**kwargs)


def test_simulate_relative_bad_input():
    from scipy.interpolate import CubicSpline

    c = Carrier(omega_e=(0, 0, 1))
    with pytest.raises(TypeError, match="`carrier` must be"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 0, 1), carrier=(0, 0, 1))
    with pytest.raises(ValueError, match="needs the rigid-body structure"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 0, 1), carrier=c, method="splitting", dt=0.1)
    with pytest.raises(ValueError, match=r"`omega_r0` must have shape \(3,\)"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 1), carrier=c)
    with pytest.raises(ValueError, match=r"`omega_r0\[2\]` must be finite"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 1, np.inf), carrier=c)
    with pytest.raises(ValueError, match="`Q_r0` or `euler_angles0`"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 0, 1), Q_r0=np.eye(3),
                          euler_angles0=(0, 1, 0), carrier=c)  # fmt: skip
    with pytest.raises(ValueError, match="`omega_r0` must be given"):
        simulate_relative(BODY, (0, 1), carrier=c)
    with pytest.raises(ValueError, match="`Q_carrier0` must be omitted"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 0, 1), Q_carrier0=np.eye(3),
                          carrier=Carrier(euler_angles=["t", 1, 0]))  # fmt: skip
    spline = Carrier(omega_e=CubicSpline([0, 1, 2], np.ones((3, 3))))
    with pytest.raises(ValueError, match="leaves the spline's domain"):
        simulate_relative(BODY, (0, 3), omega_r0=(0, 0, 1), carrier=spline)
    bad = Carrier(omega_e=lambda t: [0, 0, np.nan], epsilon_e=lambda t: [0, 0, 0])
    with pytest.raises(ValueError, match="`omega_e` is not finite"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 0, 1), carrier=bad)
    wrong = Carrier(omega_e=lambda t: [0, 1], epsilon_e=lambda t: [0, 0, 0])
    with pytest.raises(ValueError, match=r"`omega_e`\(0\) must return a 3-vector"):
        simulate_relative(BODY, (0, 1), omega_r0=(0, 0, 1), carrier=wrong)
