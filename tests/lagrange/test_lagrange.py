"""LagrangianSystem: textbook systems, multipliers, constraint forces, cross-checks."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols

from poinsot import models
from poinsot.lagrange import ConstraintDriftWarning, LagrangianSystem, PointMass


def test_cartesian_pendulum_rod_tension_from_multiplier():
    # T = m g (3 cos θ − 2 cos θ0) (Goldstein §1.6; Marion & Thornton ex. 7.9)
    mdl = models.pendulum_cartesian(theta0=math.pi / 3)
    s = mdl.symbols
    sol = mdl.simulate((0, 10), t_eval=np.linspace(0, 10, 501))
    cos_theta = -sol[s["y"]]  # θ from the downward vertical, l = 1
    tension = -2 * sol.multipliers[:, 0] * 1.0  # force on the bob 2λ(x, y), |r| = l
    expected = 1.0 * 9.81 * (3 * cos_theta - 2 * math.cos(math.pi / 3))
    np.testing.assert_allclose(tension, expected, rtol=1e-6)
    # constraint_forces is that physical force on the bob
    r = np.column_stack([sol[s["x"]], sol[s["y"]]])
    np.testing.assert_allclose(sol.constraint_forces, 2 * sol.multipliers[:, :1] * r, atol=1e-12)


def test_stabilisation_keeps_residual_small_and_drift_shows_without():
    mdl = models.pendulum_cartesian(theta0=math.pi / 3)
    t = np.linspace(0, 100, 1001)
    stab = mdl.simulate((0, 100), t_eval=t)
    assert np.abs(stab.constraint_residual).max() <= 1e-8
    proj = mdl.simulate((0, 100), t_eval=t, stabilization="projection")
    assert np.abs(proj.constraint_residual).max() <= 1e-12
    with pytest.warns(ConstraintDriftWarning, match=r"max \|g\(q, t\)\| = .*rtol = 1e-08"):
        free = mdl.simulate((0, 100), t_eval=t, stabilization=None, rtol=1e-8, atol=1e-10)
    drift = np.abs(free.constraint_residual[:, 0])
    assert drift.max() > 10 * np.abs(stab.constraint_residual).max()  # reported, and it grows
    assert drift[-100:].mean() > drift[:100].mean()


def test_minimal_and_multiplier_formulations_agree():
    polar = models.pendulum_polar(theta0=1.0)
    cart = models.pendulum_cartesian(theta0=1.0)
    t = np.linspace(0, 10, 101)
    a = polar.simulate((0, 10), t_eval=t)
    b = cart.simulate((0, 10), t_eval=t)
    theta = a[polar.symbols["theta"]]
    np.testing.assert_allclose(b[cart.symbols["x"]], np.sin(theta), atol=1e-8)
    np.testing.assert_allclose(b[cart.symbols["y"]], -np.cos(theta), atol=1e-8)
    np.testing.assert_allclose(a.energy, b.energy, rtol=1e-8)


def test_bead_on_hoop_equilibria_and_frequency():
    mdl = models.bead_on_rotating_hoop()
    s, p = mdl.symbols, mdl.params
    w, g, R = p[s["omega"]], p[s["g"]], p[s["R"]]
    assert w**2 > g / R
    eqs = mdl.system.equilibria(params=p)
    thetas = sorted(e[s["theta"]] for e in eqs)
    th_star = math.acos(g / (w**2 * R))
    for expected in (-math.pi, -th_star, 0.0, th_star, math.pi):
        assert min(abs(x - expected) for x in thetas) < 1e-9, thetas
    lin = mdl.system.linearize({s["theta"]: th_star}, params=p)
    assert lin.stable
    assert lin.frequencies[0] == pytest.approx(w * math.sin(th_star), rel=1e-7)
    bottom = mdl.system.linearize({s["theta"]: 0.0}, params=p)
    assert not bottom.stable  # ω² > g/R: the bottom has become unstable
    slow = {**p, s["omega"]: 2.0}
    assert 2.0**2 < g / R
    low = mdl.system.linearize({s["theta"]: 0.0}, params=slow)
    assert low.stable and low.frequencies[0] == pytest.approx(math.sqrt(g / R - 4.0), rel=1e-7)


def test_atwood_machine_acceleration_and_tensions():
    mdl = models.atwood_machine()
    s, p = mdl.symbols, mdl.params
    m1, m2, I, r, g = (p[s[k]] for k in ("m1", "m2", "I", "r", "g"))
    a = (m1 - m2) * g / (m1 + m2 + I / r**2)  # mass 1 descends
    sol = mdl.simulate((0, 2), t_eval=np.linspace(0, 2, 21))
    iy1, iy2 = 0, 1
    np.testing.assert_allclose(sol.accelerations[:, iy1], -a, rtol=1e-9)
    np.testing.assert_allclose(sol.accelerations[:, iy2], a, rtol=1e-9)
    lam1, lam2 = sol.multipliers[:, 0], sol.multipliers[:, 1]
    np.testing.assert_allclose(lam1, m2 * (g + a), rtol=1e-9)  # T2: pulls mass 2 up
    np.testing.assert_allclose(lam1 + lam2, m1 * (g - a), rtol=1e-9)  # T1 on mass 1
    np.testing.assert_allclose(sol[s["y1"]], -0.5 * a * sol.t**2, atol=1e-8)


def test_double_pendulum_energy_and_equations_match_sympy():
    mdl = models.double_pendulum()
    sol = mdl.simulate((0, 100), t_eval=np.linspace(0, 100, 1001), rtol=1e-11, atol=1e-12)
    assert np.abs(sol.energy - sol.energy[0]).max() < 1e-7 * abs(sol.energy[0]) + 1e-8
    # equations identical to sympy.physics.mechanics.LagrangesMethod after simplification
    system = mdl.system
    lm = LagrangesMethod(system.lagrangian, system.coordinates)
    lm.form_lagranges_equations()
    assert sp.simplify(lm.mass_matrix - system.mass_matrix) == sp.zeros(2, 2)
    assert sp.simplify(lm.forcing - system.forcing) == sp.zeros(2, 1)


def test_multipliers_match_sympy_up_to_the_documented_sign():
    x, y = dynamicsymbols("x y")
    m, g, l = sp.symbols("m g l", positive=True)
    T = m * (x.diff() ** 2 + y.diff() ** 2) / 2
    ours = LagrangianSystem([x, y], kinetic=T, potential=m * g * y, holonomic=[x**2 + y**2 - l**2])
    lm = LagrangesMethod(T - m * g * y, [x, y], hol_coneqs=[x**2 + y**2 - l**2])
    lm.form_lagranges_equations()
    # at a state on the constraint, solve both for λ
    state = {x: 0.6, y: -0.8, x.diff(): 1.2, y.diff(): 0.9, m: 1.0, g: 9.81, l: 1.0}
    sol_sympy = lm.mass_matrix_full.subs(state).LUsolve(lm.forcing_full.subs(state))
    lam_sympy = float(sol_sympy[-1])
    sol = ours.simulate(
        (0, 1e-9),
        q0={x: 0.6, y: -0.8},
        qd0={x: 1.2, y: 0.9},
        params={m: 1.0, g: 9.81, l: 1.0},
        t_eval=[0.0],
    )
    lam_ours = sol.multipliers[0, 0]
    # poinsot (6.60): M q̈ − f = +Gᵀλ with G = ∇g. SymPy 1.14's LagrangesMethod stores
    # lam_coeffs = −G and moves the term across the equation, so its λ equals ours
    assert lm.lam_coeffs == -ours.constraint_jacobian
    assert lam_sympy == pytest.approx(lam_ours, rel=1e-12)
    # the same for a Pfaffian (velocity) constraint ẋ − c ẏ = 0
    c = sp.Symbol("c")
    lm2 = LagrangesMethod(T - m * g * y, [x, y], nonhol_coneqs=[x.diff() - c * y.diff()])
    lm2.form_lagranges_equations()
    state2 = {x: 0.0, y: 0.0, x.diff(): 0.5, y.diff(): 0.25, m: 1.0, g: 9.81, c: 2.0}
    lam2_sympy = float(lm2.mass_matrix_full.subs(state2).LUsolve(lm2.forcing_full.subs(state2))[-1])
    ours2 = LagrangianSystem(
        [x, y], kinetic=T, potential=m * g * y, nonholonomic=[x.diff() - c * y.diff()]
    )
    sol2 = ours2.simulate(
        (0, 1e-9),
        q0={x: 0.0, y: 0.0},
        qd0={x: 0.5, y: 0.25},
        params={m: 1.0, g: 9.81, c: 2.0},
        t_eval=[0.0],
    )
    assert lam2_sympy == pytest.approx(sol2.multipliers[0, 0], rel=1e-12)


def test_rolling_disk_nonholonomic_constraints_and_energy():
    mdl = models.rolling_disk()
    s, p = mdl.symbols, mdl.params
    sol = mdl.simulate((0, 10), t_eval=np.linspace(0, 10, 201))
    assert np.abs(sol.constraint_velocity_residual).max() < 1e-9
    assert np.abs(sol.energy - sol.energy[0]).max() < 1e-9
    R = p[s["R"]]
    i = {k: mdl.system.coordinates.index(s[k]) for k in ("x", "y", "phi", "theta")}
    qd = sol.qd
    np.testing.assert_allclose(
        qd[:, i["x"]], R * qd[:, i["theta"]] * np.cos(sol.q[:, i["phi"]]), atol=1e-9
    )
    # constant spin and heading rates: the contact point runs round a circle of radius
    # R θ̇/φ̇ (a classical closed form)
    radius = R * 4.0 / 0.8
    xy = np.column_stack([sol[s["x"]], sol[s["y"]]])
    center = np.array([0.0, radius])
    np.testing.assert_allclose(np.linalg.norm(xy - center, axis=1), radius, rtol=1e-7)


def test_spherical_pendulum_conserves_vertical_angular_momentum():
    mdl = models.spherical_pendulum()
    s, p = mdl.symbols, mdl.params
    sol = mdl.simulate((0, 20), t_eval=np.linspace(0, 20, 201))
    th = sol[s["theta"]]
    phid = sol.qd[:, 1]
    Lz = p[s["m"]] * p[s["l"]] ** 2 * np.sin(th) ** 2 * phid
    np.testing.assert_allclose(Lz, Lz[0], rtol=1e-8)


def test_heavy_top_in_euler_angles_matches_the_rigid_body_simulator():
    from poinsot import Gravity, RigidBody, simulate
    from poinsot.rotation import body_rates_from_euler, matrix_from_euler

    mdl = models.heavy_symmetric_top()
    s = mdl.symbols
    # a nutating top: slight kick in θ̇
    q0 = {s["psi"]: 0.0, s["theta"]: 0.6, s["phi"]: 0.0}
    qd0 = {s["psi"]: 1.0, s["theta"]: 1.5, s["phi"]: 100.0}
    t = np.linspace(0, 2, 101)
    lag = mdl.simulate((0, 2), q0=q0, qd0=qd0, t_eval=t, rtol=1e-12, atol=1e-12)
    body = RigidBody.cylinder(1.0, 0.3, 0.2)
    angles = np.array([0.0, 0.6, 0.0])
    rates = np.array([1.0, 1.5, 100.0])
    rb = simulate(
        body,
        (0, 2),
        omega0=body_rates_from_euler(angles, rates),
        Q0=matrix_from_euler(angles, "ZXZ"),
        pivot=(0, 0, -0.5),
        forces=[Gravity((0, 0, -9.81))],
        rtol=1e-12,
        atol=1e-12,
        t_eval=t,
    )
    theta_rb = np.arccos(np.clip(rb.Q[:, 2, 2], -1, 1))
    np.testing.assert_allclose(lag[s["theta"]], theta_rb, atol=1e-7)
    psi_rb = np.unwrap(np.arctan2(rb.Q[:, 0, 2], -rb.Q[:, 1, 2]))
    np.testing.assert_allclose(lag[s["psi"]], psi_rb, atol=1e-7)


def test_generalized_forces_spherical_example():
    # (6.61): Q_r = F_r, Q_θ = r F_θ, Q_φ = r sin θ F_φ
    r, th, ph = dynamicsymbols("r theta phi")
    Fr, Ft, Fp, m = sp.symbols("F_r F_theta F_phi m")
    er = sp.Matrix([sp.sin(th) * sp.cos(ph), sp.sin(th) * sp.sin(ph), sp.cos(th)])
    et = sp.Matrix([sp.cos(th) * sp.cos(ph), sp.cos(th) * sp.sin(ph), -sp.sin(th)])
    ep = sp.Matrix([-sp.sin(ph), sp.cos(ph), 0])
    point = r * er
    force = Fr * er + Ft * et + Fp * ep
    system = LagrangianSystem([r, th, ph], bodies=[PointMass(m, point)], forces=[(point, force)])
    Q = sp.simplify(system.generalized_forces)
    assert sp.simplify(Q - sp.Matrix([Fr, r * Ft, r * sp.sin(th) * Fp])) == sp.zeros(3, 1)


def test_damped_pendulum_with_generalized_force_loses_energy():
    th = dynamicsymbols("theta")
    c = sp.Symbol("c")
    L = th.diff() ** 2 / 2 + 9.81 * sp.cos(th)
    system = LagrangianSystem([th], L, forces=[{th: -c * th.diff()}])
    sol = system.simulate((0, 10), q0={th: 1.0}, params={c: 0.3})
    assert np.all(np.diff(sol.energy) < 1e-12)
    assert sol.energy[-1] < 0.5 * sol.energy[0]


def test_linearized_pendulum_frequency_minimal_and_constrained():
    polar = models.pendulum_polar()
    lin = polar.system.linearize({polar.symbols["theta"]: 0.0}, params=polar.params)
    assert lin.frequencies[0] == pytest.approx(math.sqrt(9.81), rel=1e-7)
    cart = models.pendulum_cartesian()
    s = cart.symbols
    eq = cart.system.equilibria(
        params=cart.params, bounds={s["x"]: (-1.5, 1.5), s["y"]: (-1.5, 1.5)}
    )
    ys = sorted(round(e[s["y"]], 9) for e in eq)
    assert ys == [-1.0, 1.0]
    lin = cart.system.linearize({s["x"]: 0.0, s["y"]: -1.0}, params=cart.params)
    assert lin.stable and lin.frequencies[0] == pytest.approx(math.sqrt(9.81), rel=1e-6)
    assert not cart.system.linearize({s["x"]: 0.0, s["y"]: 1.0}, params=cart.params).stable


def test_rigid_body_in_bodies_list():
    # a compound pendulum: a rod hanging from its end, angle θ about the y axis
    from poinsot import RigidBody

    th = dynamicsymbols("theta")
    g = sp.Symbol("g")
    rod = RigidBody.rod(2.0, 1.0)
    Q = sp.Matrix([[sp.cos(th), 0, sp.sin(th)], [0, 1, 0], [-sp.sin(th), 0, sp.cos(th)]])
    com = Q * sp.Matrix([0, 0, -0.5])
    system = LagrangianSystem([th], bodies=[(rod, com, Q)], potential=2.0 * g * com[2])
    lin = system.linearize({th: 0.0}, params={g: 9.81})
    I_pivot = 2.0 / 12 + 2.0 * 0.25
    assert lin.frequencies[0] == pytest.approx(math.sqrt(2.0 * 9.81 * 0.5 / I_pivot), rel=1e-7)


# --------------------------------------------------------------------------- bad input
def test_structural_errors_at_build_time():
    x, y = dynamicsymbols("x y")
    a = sp.Symbol("a")
    T = (x.diff() ** 2 + y.diff() ** 2) / 2
    with pytest.raises(ValueError, match=r"`coordinates\[1\]` = a is not a function of time"):
        LagrangianSystem([x, a], kinetic=T)
    with pytest.raises(
        ValueError,
        match=r"`holonomic\[0\]` = a - 1 does not depend on the "
        r"coordinates",
    ):
        LagrangianSystem([x, y], kinetic=T, holonomic=[a - 1])
    with pytest.raises(
        ValueError,
        match=r"redundant or inconsistent: the constraint Jacobian "
        r"has rank 1 < 2",
    ):
        LagrangianSystem([x, y], kinetic=T, holonomic=[x + y, 2 * x + 2 * y - 3])
    with pytest.raises(ValueError, match="not linear in the velocities"):
        LagrangianSystem([x, y], kinetic=T, nonholonomic=[x.diff() ** 2 - y.diff()])
    with pytest.raises(ValueError, match="contains velocities"):
        LagrangianSystem([x, y], kinetic=T, holonomic=[x.diff() - y])
    with pytest.raises(ValueError, match="not both"):
        LagrangianSystem([x, y], T, kinetic=T)


def test_inconsistent_initial_conditions_and_bad_keys():
    mdl = models.pendulum_cartesian()
    s = mdl.symbols
    with pytest.raises(
        ValueError,
        match=r"inconsistent initial conditions: .* max \|g\(q0\)\| "
        r"= 0\.5",
    ):
        mdl.simulate((0, 1), q0={s["x"]: 0.5, s["y"]: 0.5})
    with pytest.raises(ValueError, match=r"velocity constraints are violated"):
        mdl.simulate((0, 1), q0={s["x"]: 0.0, s["y"]: -1.0}, qd0={s["x"]: 0.0, s["y"]: 1.0})
    z = dynamicsymbols("z")
    with pytest.raises(ValueError, match=r"`q0`: z\(t\) is not a coordinate"):
        mdl.simulate((0, 1), q0={z: 1.0})
    with pytest.raises(ValueError, match=r"missing l"):
        mdl.simulate((0, 1), params={s["m"]: 1.0, s["g"]: 9.81})
    with pytest.raises(ValueError, match="`stabilization` must be"):
        mdl.simulate((0, 1), stabilization="spring")
    with pytest.raises(ValueError, match="integrates rigid bodies"):
        mdl.simulate((0, 1), method="splitting", dt=0.1)


def test_dependent_coordinates_solved_for():
    mdl = models.pendulum_cartesian()
    s = mdl.symbols
    sol = mdl.simulate(
        (0, 1), q0={s["x"]: 0.6}, qd0={s["x"]: 0.3}, guess={s["y"]: -1.0}, t_eval=[0.0, 1.0]
    )
    assert sol.q[0, 1] == pytest.approx(-0.8, abs=1e-14)
    # velocity: x ẋ + y ẏ = 0
    assert sol.qd[0, 1] == pytest.approx(0.6 * 0.3 / 0.8, rel=1e-13)


def test_symbolic_outputs():
    mdl = models.pendulum_cartesian()
    x, y = mdl.symbols["x"], mdl.symbols["y"]
    eqs = mdl.system.equations()
    lam = mdl.system.lam_vec[0]
    m, g = mdl.symbols["m"], mdl.symbols["g"]
    assert sp.simplify(eqs[0].lhs - m * x.diff(mdl.system.t, 2)) == 0
    assert sp.simplify(eqs[1].rhs - 2 * y * lam) == 0
    assert sp.simplify(eqs[1].lhs - (m * y.diff(mdl.system.t, 2) + m * g)) == 0
    assert mdl.system.constraint_gamma[0] == 2 * x.diff() ** 2 + 2 * y.diff() ** 2
    assert set(mdl.system.parameters) == {mdl.symbols["m"], mdl.symbols["g"], mdl.symbols["l"]}


def test_augmented_system_solves_to_the_simulated_accelerations_and_multipliers():
    mdl = models.pendulum_cartesian()
    s, system = mdl.symbols, mdl.system
    x, y = s["x"], s["y"]
    state = {x.diff(): 1.2, y.diff(): 0.9, x: 0.6, y: -0.8, **mdl.params}
    K = system.augmented_matrix.subs(state)
    rhs = system.augmented_forcing.subs(state)
    solved = [float(v) for v in K.LUsolve(rhs)]
    sol = system.simulate(
        (0, 1e-9), q0={x: 0.6, y: -0.8}, qd0={x: 1.2, y: 0.9}, params=mdl.params, t_eval=[0.0]
    )
    np.testing.assert_allclose(solved[:2], sol.accelerations[0], rtol=1e-12)
    assert solved[2] == pytest.approx(sol.multipliers[0, 0], rel=1e-12)
    assert system.augmented_matrix.shape == (3, 3)


@pytest.mark.parametrize("n", [1, 3, 6])
def test_point_masses_by_their_jacobians_equal_the_route_through_the_lagrangian(n):
    """A system of point masses derives M, f and h from the positions' Jacobians
    (``Σ m Jᵀ J``, ``−Σ m Jᵀ J̇q̇ − ∇U``, ``T + U``); the same system given its kinetic energy
    (differentiated twice) must agree, at random states and parameters, with a constraint and
    a generalized force in play."""
    from sympy import cos, sin

    q = dynamicsymbols(f"q:{n + 1}")
    ms, ls, g, c = sp.symbols(f"m:{n + 1}"), sp.symbols(f"l:{n}"), sp.Symbol("g"), sp.Symbol("c")
    pts = [sp.Matrix([q[0], 0, 0])]
    for i in range(n):
        pts.append(pts[-1] + ls[i] * sp.Matrix([-sin(q[i + 1]), cos(q[i + 1]), 0]))
    U = sum(mi * g * p[1] for mi, p in zip(ms, pts, strict=True))
    forces = [{q[1]: -c * q[1].diff()}]  # a damper on the first joint
    hol = [q[0] - sp.Rational(1, 2) * sin(q[1])] if n > 1 else []
    jac = LagrangianSystem(q, bodies=[PointMass(m, p) for m, p in zip(ms, pts, strict=True)],
                           potential=U, forces=forces, holonomic=hol)  # fmt: skip
    T = sum(m * (p.diff(jac.t).T * p.diff(jac.t))[0] / 2 for m, p in zip(ms, pts, strict=True))
    lag = LagrangianSystem(q, kinetic=T, potential=U, forces=forces, holonomic=hol)
    assert jac._point_mass_route is not None and lag._point_mass_route is None
    rng = np.random.default_rng(n)
    for _ in range(3):
        values = {s: rng.uniform(0.5, 1.5) for s in (*ms, *ls, g, c)}
        values.update({qi: rng.uniform(-2, 2) for qi in q})
        values.update({qi.diff(): rng.uniform(-2, 2) for qi in q})

        def num(e, values=values):
            # speeds first: Derivative(q(t), t) contains q(t)
            speeds = {k: v for k, v in values.items() if isinstance(k, sp.Derivative)}
            rest = {k: v for k, v in values.items() if not isinstance(k, sp.Derivative)}
            e = e if isinstance(e, sp.MatrixBase) else sp.Matrix([e])
            return np.array(e.xreplace(speeds).xreplace(rest), dtype=float)

        for a, b in ((jac.mass_matrix, lag.mass_matrix), (jac.forcing, lag.forcing),
                     (jac.energy_function, lag.energy_function)):  # fmt: skip
            np.testing.assert_allclose(num(a), num(b), rtol=1e-12, atol=1e-12)
