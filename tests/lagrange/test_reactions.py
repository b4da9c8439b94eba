"""Forces of the constraints that minimal coordinates hide (poinsot.lagrange.reactions): each
against an independent route — a second formulation with the constraint explicit, Newton's law
for the centre of mass, the statics of a body at rest."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from poinsot import models
from poinsot.lagrange import HiddenConstraint, LagrangianSystem, PointMass


def _multipliers(system, params, t, q, qd):
    """λ of ``system`` at the given states, by the augmented linear system (6.60) written
    out here with SymPy: [[M, −Gᵀ], [G, 0]] [q̈; λ] = [f; −γ]."""
    K = system.augmented_matrix
    F = system.augmented_forcing
    names = system.plain
    values = {k: sp.Float(v) for k, v in params.items()}
    args = (system.t, names.q, names.v)
    fK = sp.lambdify(args, [names.of(e).xreplace(values) for e in K], "numpy")
    fF = sp.lambdify(args, [names.of(e).xreplace(values) for e in F], "numpy")
    n = system.n_coordinates
    out = []
    for ti, qi, vi in zip(t, q, qd, strict=True):
        Kn = np.array(fK(ti, qi, vi), dtype=float).reshape(K.shape)
        Fn = np.array(fF(ti, qi, vi), dtype=float)
        out.append(np.linalg.solve(Kn, Fn)[n:])
    return np.array(out)


def _cartesian_double_pendulum():
    """The double pendulum in the bobs' Cartesian coordinates, both rods as explicit
    constraints: the force on bob 1 from rod 1 is 2λ1 r1, so its tension is T1 = −2 λ1 l1;
    rod 2 pulls bob 2 with 2λ2 (r2 − r1), T2 = −2 λ2 l2."""
    x1, y1, x2, y2 = dynamicsymbols("x1 y1 x2 y2")
    m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g", positive=True)
    system = LagrangianSystem(
        [x1, y1, x2, y2],
        bodies=[PointMass(m1, [x1, y1, 0]), PointMass(m2, [x2, y2, 0])],
        potential=m1 * g * y1 + m2 * g * y2,
        holonomic=[x1**2 + y1**2 - l1**2, (x2 - x1) ** 2 + (y2 - y1) ** 2 - l2**2],
    )
    return system, {m1: 1.0, m2: 1.0, l1: 1.0, l2: 1.0, g: 9.81}, (l1, l2)


def test_double_pendulum_tensions_in_angles_equal_the_cartesian_models():
    model = models.double_pendulum()
    assert model.system.coordinates == list(dynamicsymbols("theta1 theta2"))  # minimal
    t = np.linspace(0, 10, 401)
    sol = model.simulate((0, 10), t_eval=t)  # θ0 = (2, 1) rad: chaotic
    forces = model.system.reaction_forces(sol)
    th1, th2 = sol.q.T
    w1, w2 = sol.qd.T
    # the same states in Cartesian coordinates (l1 = l2 = 1)
    q = np.column_stack([np.sin(th1), -np.cos(th1), np.sin(th1) + np.sin(th2),
                         -np.cos(th1) - np.cos(th2)])  # fmt: skip
    qd = np.column_stack([np.cos(th1) * w1, np.sin(th1) * w1,
                          np.cos(th1) * w1 + np.cos(th2) * w2,
                          np.sin(th1) * w1 + np.sin(th2) * w2])  # fmt: skip
    cart, params, _ = _cartesian_double_pendulum()
    lam = _multipliers(cart, params, t, q, qd)
    T1, T2 = -2 * lam[:, 0], -2 * lam[:, 1]
    assert np.ptp(T1) > 20 and T2.min() < 5 < T2.max()  # a run that explores
    np.testing.assert_allclose(forces["rod 1 tension T1"], T1, rtol=0, atol=1e-8)
    np.testing.assert_allclose(forces["rod 2 tension T2"], T2, rtol=0, atol=1e-8)


def test_double_pendulum_at_equilibria():
    model = models.double_pendulum()
    t1, t2 = model.system.coordinates
    hanging = model.system.reaction_forces({t1: 0.0, t2: 0.0}, params=model.params)
    assert hanging == pytest.approx({"rod 1 tension T1": 2 * 9.81, "rod 2 tension T2": 9.81},
                                    rel=1e-14)  # fmt: skip
    # both bobs balanced upside down: the rods push (negative tension)
    up = model.system.reaction_forces({"theta1": np.pi, "theta2": np.pi}, params=model.params)
    assert up["rod 1 tension T1"] == pytest.approx(-2 * 9.81, rel=1e-12)
    assert up["rod 2 tension T2"] == pytest.approx(-9.81, rel=1e-12)
    one = model.system.reaction_forces({t1: 0.0, t2: 0.0}, params=model.params,
                                       names=["rod 2 tension T2"])  # fmt: skip
    assert list(one) == ["rod 2 tension T2"]


def test_spinning_bob_tension_is_the_centripetal_force():
    """A minimal-coordinate system built by a user: a bob on a string in the plane, at rest
    in its angle but moving: T = m g cos θ + m l θ̇² (circular motion)."""
    th, rho = dynamicsymbols("theta rho")
    m, g, l = sp.symbols("m g l", positive=True)
    system = LagrangianSystem(
        [th], bodies=[PointMass(m, [rho * sp.sin(th), -rho * sp.cos(th), 0])],
        potential=-m * g * rho * sp.cos(th),
        hidden=[HiddenConstraint(rho, l, "tension", "N", -1)])  # fmt: skip
    T = system.reaction_forces({th: 0.4}, qd={th: 3.0}, params={"m": 2.0, "g": 9.81, "l": 0.5})
    assert T["tension"] == pytest.approx(2 * 9.81 * np.cos(0.4) + 2 * 0.5 * 9.0, rel=1e-13)


def _acceleration(sol, point):
    """The acceleration (n_samples, 3) of a point given by expressions in q(t): d²r/dt² =
    J q̈ + (J̇ q̇), J and J̇q̇ evaluated along the run, q̈ the solution's accelerations."""
    system = sol.system
    t = system.t
    qdd = [sp.Symbol(f"a{j}") for j in range(system.n_coordinates)]
    second = {q.diff(t, 2): a for q, a in zip(system.coordinates, qdd, strict=True)}
    out = np.zeros((len(sol.t), 3))
    for k, c in enumerate(point):
        d2 = sp.sympify(c).diff(t, 2).xreplace(second)
        rest = d2.xreplace(dict.fromkeys(qdd, 0))
        J = [d2.diff(a) for a in qdd]
        out[:, k] = sol.evaluate(rest) + np.einsum("nj,nj->n", sol.evaluate(J), sol.accelerations)
    return out


def test_heavy_top_pivot_reaction_is_newtons():
    model = models.heavy_symmetric_top()
    sol = model.simulate((0, 1), t_eval=np.linspace(0, 1, 201))
    values = model.reaction_values(sol)
    F = np.column_stack([values[f"pivot reaction F_{c}"][0] for c in "xyz"])
    M, g = model.params[model.symbols["M"]], model.params[model.symbols["g"]]
    a_c = _acceleration(sol, model.points["centre of mass"])
    newton = M * (a_c - np.array([0.0, 0.0, -g]))  # F + M g = M a_c
    np.testing.assert_allclose(F, newton, rtol=0, atol=1e-9 * np.abs(newton).max())
    # and by finite differences of the centre's position along a finer run (independent of q̈)
    fine = model.simulate((0, 0.02), t_eval=np.linspace(0, 0.02, 2001))
    R = fine.evaluate(list(model.points["centre of mass"]))
    h = fine.t[1] - fine.t[0]
    a_fd = (R[2:] - 2 * R[1:-1] + R[:-2]) / h**2
    F_fine = np.column_stack([model.system.reaction_forces(fine)[f"pivot reaction F_{c}"]
                              for c in "xyz"])[1:-1]  # fmt: skip
    gravity = np.array([0.0, 0.0, -g])
    np.testing.assert_allclose(F_fine, M * (a_fd - gravity), atol=1e-4 * np.abs(F_fine).max())


def test_rolling_coin_contact_force_is_newtons():
    model = models.rolling_coin()
    m, r, g = (model.params[model.symbols[k]] for k in "mrg")
    system = model.system
    names = ("friction F_x", "friction F_y", "normal force N")
    # at rest, upright: the table carries the weight, no friction
    rest = system.reaction_forces({q: 0.0 for q in system.coordinates}, params=model.params)
    assert rest["normal force N"] == pytest.approx(m * g, rel=1e-14)
    lam = system.lam_vec
    model_reactions = model.reactions
    assert set(model_reactions) == set(names[:2]) and lam.shape == (2, 1)
    # steady rolling, upright and straight at 25 rad/s: the same force, all along the run
    x, y, psi, th, ph = system.coordinates
    upright = {x: 0, y: 0, psi: 0, th: 0, ph: 0}
    spin = {psi: 0, th: 0, ph: 25.0}
    steady = model.simulate((0, 1), q0=upright, qd0=spin, t_eval=np.linspace(0, 1, 51))
    assert np.abs(steady.qd[:, 0]).max() == pytest.approx(25 * r, rel=1e-12)  # it rolls
    values = model.reaction_values(steady)
    np.testing.assert_allclose(values["normal force N"][0], m * g, rtol=1e-12)
    np.testing.assert_allclose(values["friction F_x"][0], 0, atol=1e-12 * m * g)
    np.testing.assert_allclose(values["friction F_y"][0], 0, atol=1e-12 * m * g)
    # the default run wobbles and curves: the whole contact force is m (a_c − g) throughout
    sol = model.simulate((0, 1), t_eval=np.linspace(0, 1, 201))
    values = model.reaction_values(sol)
    F = np.column_stack([values[n][0] for n in names])
    a_c = _acceleration(sol, model.points["centre"])
    newton = m * (a_c - np.array([0.0, 0.0, -g]))
    assert np.abs(newton[:, :2]).max() > 1e-3 * m * g  # friction at work
    np.testing.assert_allclose(F, newton, rtol=0, atol=1e-8 * m * g)


def test_rolling_disk_friction_is_the_centripetal_force_in_steady_rolling():
    """The vertical disk rolls round a circle at constant speed: the friction at the contact
    is the whole horizontal force, m v²/ρ toward the centre (v = R θ̇, ρ = v/φ̇)."""
    model = models.rolling_disk()
    sol = model.simulate((0, 2), t_eval=np.linspace(0, 2, 101))
    values = model.reaction_values(sol)
    F = np.column_stack([values["friction F_x"][0], values["friction F_y"][0]])
    m, R = model.params[model.symbols["m"]], model.params[model.symbols["R"]]
    phid, thd = 0.8, 4.0
    v = R * thd
    np.testing.assert_allclose(np.linalg.norm(F, axis=1), m * v * phid, rtol=1e-9)
    heading = np.column_stack([np.cos(sol.q[:, 2]), np.sin(sol.q[:, 2])])
    assert np.abs(np.einsum("ni,ni->n", F, heading)).max() < 1e-9  # no force along the path


def test_hidden_constraints_refused_clearly():
    th, rho = dynamicsymbols("theta rho")
    m, l = sp.symbols("m l", positive=True)
    bob = [PointMass(m, [rho * sp.sin(th), -rho * sp.cos(th), 0])]
    with pytest.raises(ValueError, match=r"hidden\[0\]\.coordinate.*one of the coordinates"):
        LagrangianSystem([th, rho], bodies=bob, hidden=[HiddenConstraint(rho, l, "T")])
    with pytest.raises(TypeError, match=r"hidden\[0\]"):
        LagrangianSystem([th], bodies=bob, hidden=[(rho, l)])
    plain = models.pendulum_polar().system
    with pytest.raises(ValueError, match="declares no hidden constraint"):
        plain.reaction_forces({plain.coordinates[0]: 0.0})
    dp = models.double_pendulum()
    with pytest.raises(ValueError, match=r"`names`: 'T3'"):
        dp.system.reaction_forces({"theta1": 0, "theta2": 0}, params=dp.params, names=["T3"])
    no_g = {"m1": 1, "m2": 1, "l1": 1, "l2": 1}
    with pytest.raises(ValueError, match="missing g"):
        dp.system.reaction_forces({"theta1": 0, "theta2": 0}, params=no_g)


def test_double_pendulum_reports_its_tensions_with_units(tmp_path):
    from poinsot.app.job import run_scenario
    from poinsot.app.scenario import load_example

    scenario = load_example("double-pendulum")
    scenario.outputs["figures"] = False
    summary = run_scenario(scenario, tmp_path / "o", plotlyjs="cdn")
    for name in ("rod 1 tension T1", "rod 2 tension T2"):
        entry = summary["reactions"][name]
        assert entry["unit"] == "N" and entry["min"] < entry["max"]
        assert summary["units"][name] == "N"
    page = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    assert "rod 1 tension T1: range" in page and "<td class='unit'>N</td>" in page
    header = (tmp_path / "o" / "solution.csv").read_text().splitlines()[0]
    assert "rod 2 tension T2 [N]" in header
