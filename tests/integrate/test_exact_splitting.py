"""The exact-flow splittings (``exact-splitting``, ``-4``, ``-6``) through the public API,
against independent routes: their own equations integrated by SciPy's DOP853 at rtol 1e-13
(written here, in NumPy), FRB's published trajectory (ACM TOMS Algorithm 903, example 1), the
closed form of the torque-free motion, and the ensemble's exact grading.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from poinsot import CentralGravity, Gravity, RigidBody, Spring, simulate
from poinsot.bodies import UnphysicalInertiaWarning
from poinsot.ensemble import simulate_ensemble
from poinsot.integrate import METHODS

EXACT = ("exact-splitting", "exact-splitting4", "exact-splitting6")
DATA = Path(__file__).parents[1] / "data" / "frb_example1.txt"

# FRB's example 1: moments about the tip, the torque u × e3 with u = Qᵀ u0
FRB_MOMENTS = np.array([1.0, 1.0126869887825154, 3.3062374224730378])
FRB_U0 = np.array([9.5586303547238536e-05, 4.8777318247201465e-04, -8.6772148817192390e-04])
FRB_PI0 = np.array([-0.3479095708854734, -0.1982291459967592, -0.9163318919276364])
L = 0.25  # the centre of mass above the tip (M = 1, M l² a power of two: exact moments)


def frb_top(scale=1.0):
    """FRB's heavy top as poinsot's: a body whose moments about the tip are FRB's, the centre
    of mass ``L`` along e3, gravity ``g = −u0/(M L)`` (the torque ``M L e3 × Qᵀg = u × e3``);
    ``scale`` multiplies the torque."""
    inertia = np.diag(FRB_MOMENTS - np.array([L * L, L * L, 0.0]))
    with warnings.catch_warnings():  # FRB's moments break the triangle inequality on purpose
        warnings.simplefilter("ignore", UnphysicalInertiaWarning)
        body = RigidBody(1.0, inertia, (0.0, 0.0, L), allow_unphysical=True)
    return body, [Gravity(-scale * FRB_U0 / L)]


def top_reference(omega0, t, scale=1.0):
    """(ω, Q) at ``t`` of the top by SciPy's DOP853 on ``π̇ = π × ω + u × e3``, ``Q̇ = QΩ̂``."""
    inv = 1.0 / FRB_MOMENTS

    def rhs(_, y):
        Q = y[:9].reshape(3, 3)
        pi = y[9:]
        w = inv * pi
        u = Q.T @ (scale * FRB_U0)
        W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        return np.concatenate([(Q @ W).ravel(), np.cross(pi, w) + np.array([u[1], -u[0], 0.0])])

    y0 = np.concatenate([np.eye(3).ravel(), FRB_MOMENTS * omega0])
    sol = solve_ivp(rhs, (0, t), y0, method="DOP853", rtol=1e-13, atol=1e-15)
    return inv * sol.y[9:, -1], sol.y[:9, -1].reshape(3, 3)


def test_the_registry_declares_the_methods():
    for name, order in zip(EXACT, (2, 4, 6), strict=True):
        cls = METHODS[name]
        assert cls.order == order and cls.kind == "exact-splitting"
        assert cls.needs_position_only_forces and cls.requires == "rigid"
        assert abs(cls.flows.sum() - 1) < 1e-14 and abs(cls.kicks.sum() - 1) < 1e-14
    six = METHODS["exact-splitting6"]
    assert (len(six.flows), len(six.kicks), six.kick_first) == (15, 14, False)


def test_frb_example_1_is_reproduced():
    """``exact-splitting6`` with FRB's step reproduces FRB's published output within 1e-9 over
    the whole run (sampled every 40th step), and within 1e-13 over its first ten steps."""
    body, forces = frb_top()
    published = np.loadtxt(DATA)
    t = published[:, 12]
    traj = simulate(body, (0, 5000), omega0=FRB_PI0 / FRB_MOMENTS, forces=forces,
                    pivot=(0, 0, 0), method="exact-splitting6", dt=0.5, t_eval=t)  # fmt: skip
    pi = traj.omega * FRB_MOMENTS
    Q = published[:, 3:12].reshape(-1, 3, 3).transpose(0, 2, 1)  # column by column
    d_pi = np.abs(pi - published[:, :3]).max(axis=1)
    d_Q = np.abs(traj.Q - Q).max(axis=(1, 2))
    first = t <= 5.0
    assert d_pi[first].max() < 1e-13 and d_Q[first].max() < 1e-13
    assert d_pi.max() < 1e-9 and d_Q.max() < 1e-9, (d_pi.max(), d_Q.max())


@pytest.mark.parametrize("name", EXACT)
def test_torque_free_the_method_is_the_closed_form(name):
    """Without forces each method is the exact flow at any step: 2000 steps of 0.375 equal the
    closed form (its own route, the FreeRigidBody) to round-off."""
    from poinsot.torquefree import FreeRigidBody

    body = RigidBody.box(2.0, (1.0, 2.0, 3.0))
    w0 = np.array([0.3, 1.0, 0.2])
    t = np.linspace(0, 750, 11)
    traj = simulate(body, (0, 750), omega0=w0, method=name, dt=0.375, t_eval=t)
    free = FreeRigidBody.from_body(body)
    np.testing.assert_allclose(traj.omega, free.exact_omega(w0, t), rtol=0, atol=1e-12)
    np.testing.assert_allclose(traj.Q, free.exact_attitude(w0, t, np.eye(3)), rtol=0, atol=1e-12)


@pytest.mark.parametrize("gap", [1e-6, 1e-9, 1e-11])
def test_a_nearly_symmetric_body_about_its_middle_axis_keeps_its_digits(gap):
    """I2 − I1 = gap, spun about e2: the polhode's rate λ ~ √gap, and ψ's factor 1/λ had
    magnified the rounding of Π(u) − Π(u0)'s first-kind part, the difference of two rounded
    arguments: Q was 4e-12, 6e-11 and 2e-10 off at t = 40, in the closed form and in every
    flow. The first-kind part is λt, taken exactly. Reference: DOP853 at rtol 1e-13, an
    independent route (its own error about 2e-13)."""
    from poinsot.torquefree import FreeRigidBody

    moments = np.array([1.0, 1.0 + gap, 2.0])
    body = RigidBody(1.0, np.diag(moments))
    w0 = np.array([1e-7, 1.0, 1e-7])
    t = np.linspace(0, 40, 9)
    ref = simulate(body, (0, 40), omega0=w0, method="dop853", rtol=1e-13, atol=1e-16, t_eval=t)
    closed = FreeRigidBody(moments).exact_attitude(w0, t)
    flows = simulate(body, (0, 40), omega0=w0, method="exact-splitting4", dt=0.37, t_eval=t)
    for Q in (closed, flows.Q):
        assert np.abs(Q - ref.Q).max() < 2e-12


def _order(errors, hs):
    return np.polyfit(np.log(hs), np.log(errors), 1)[0]


@pytest.fixture(scope="module")
def top_40s():
    """FRB's top with a torque 3000 times FRB's (the errors stand well above the reference's,
    about 1e-13), its (ω, Q) at t = 40 by SciPy."""
    return top_reference(FRB_PI0 / FRB_MOMENTS, 40.0, scale=3000.0)


# the step ranges where each method is in its asymptotic regime (measured: the local slopes
# there are within 0.05 of the order) and above the reference's error
@pytest.mark.parametrize(("name", "order", "steps"), [
    ("exact-splitting", 2, (0.25, 0.125, 0.0625)),
    ("exact-splitting4", 4, (0.5, 0.25, 0.125)),
    ("exact-splitting6", 6, (0.5, 0.25, 0.125)),
])  # fmt: skip
def test_orders_on_a_heavy_top(name, order, steps, top_40s):
    """FRB's top with a torque 3000 times FRB's, over 40 s: the errors in ω and Q against
    SciPy fall as hᵖ, p = 2, 4, 6 ± 0.2."""
    body, forces = frb_top(scale=3000.0)
    w_ref, Q_ref = top_40s
    errors = []
    for h in steps:
        traj = simulate(body, (0, 40), omega0=FRB_PI0 / FRB_MOMENTS, forces=forces,
                        pivot=(0, 0, 0), method=name, dt=h, t_eval=[40.0])  # fmt: skip
        errors.append(max(np.abs(traj.omega[-1] - w_ref).max(), np.abs(traj.Q[-1] - Q_ref).max()))
    assert abs(_order(errors, steps) - order) < 0.2, errors


def satellite_reference(body, R0, V0, omega0, mu, t):
    """(ω, Q, R) at ``t`` of a satellite in a central field with MacCullagh's gradient terms
    (derived from ``U = −μM/r − μ/(2r³)(tr A − 3 n̂·A n̂)``), by SciPy's DOP853."""
    A = np.diag(body.principal_moments)
    M = body.mass
    inv = 1.0 / body.principal_moments

    def rhs(_, y):
        R, V, Q, pi = y[:3], y[3:6], y[6:15].reshape(3, 3), y[15:]
        r = np.linalg.norm(R)
        b = Q.T @ R
        Ab = A @ b
        F = (-mu * M * R / r**3 - 1.5 * mu * np.trace(A) * R / r**5 - 3 * mu * Q @ Ab / r**5
             + 7.5 * mu * (b @ Ab) * R / r**7)  # fmt: skip
        tau = 3 * mu / r**5 * np.cross(b, Ab)
        w = inv * pi
        W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        return np.concatenate([V, F / M, (Q @ W).ravel(), np.cross(pi, w) + tau])

    y0 = np.concatenate([R0, V0, np.eye(3).ravel(), body.principal_moments * omega0])
    sol = solve_ivp(rhs, (0, t), y0, method="DOP853", rtol=1e-13, atol=1e-15)
    y = sol.y[:, -1]
    return inv * y[15:], y[6:15].reshape(3, 3), y[:3]


@pytest.mark.parametrize(("name", "order", "counts"), [
    ("exact-splitting", 2, (60, 120, 240)),
    ("exact-splitting4", 4, (120, 240, 480)),
    ("exact-splitting6", 6, (50, 75, 100)),
])  # fmt: skip
def test_orders_on_a_satellite(name, order, counts):
    """A box on a circular orbit (μ = 1, r = 1: period 2π) under the gravity-gradient torque,
    tumbling at half the orbital rate, over two orbits in whole steps (a last step cut short
    to land on the end adds its own error): the errors in ω, Q and R against SciPy fall as
    hᵖ. The orbit itself is Kepler's exact flow (the drift); the error is the torque's."""
    body = RigidBody.box(1.0, (0.3, 0.2, 0.1))  # principal axes = body axes
    R0, V0, omega0 = np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0.1, 0.5, 0.2])
    t = 4 * np.pi
    w_ref, Q_ref, R_ref = satellite_reference(body, R0, V0, omega0, 1.0, t)
    steps = [t / n for n in counts]
    errors = []
    for h in steps:
        traj = simulate(body, (0, t), omega0=omega0, R0=R0, V0=V0, forces=[CentralGravity(1.0)],
                        method=name, dt=h, t_eval=[t])  # fmt: skip
        errors.append(max(np.abs(traj.omega[-1] - w_ref).max(), np.abs(traj.Q[-1] - Q_ref).max(),
                          np.abs(traj.R[-1] - R_ref).max()))  # fmt: skip
    assert abs(_order(errors, steps) - order) < 0.2, errors


def test_a_point_mass_orbit_is_keplers_exact_flow_at_any_step():
    """A body under a central gravity without the gradient terms: the kicks carry nothing, so
    each step is the exact free flow and Kepler's exact flow. An eccentric orbit (e ≈ 0.44)
    at 3 steps an orbit, over 20 orbits, against its classical elements (Kepler's equation
    in the eccentric anomaly): the centre of mass to round-off, and the rotation the closed
    form's."""
    from poinsot.torquefree import FreeRigidBody

    body = RigidBody.box(1.0, (0.3, 0.2, 0.1))
    mu, R0, V0 = 2.0, np.array([1.0, 0.2, -0.1]), np.array([0.1, 1.6, 0.5])
    omega0 = np.array([0.3, 1.1, -0.4])
    a = 1.0 / (2.0 / np.linalg.norm(R0) - V0 @ V0 / mu)
    period = 2 * np.pi * np.sqrt(a**3 / mu)
    t = 20 * period
    traj = simulate(body, (0, t), omega0=omega0, R0=R0, V0=V0,
                    forces=[CentralGravity(mu, gradient=False)], method="exact-splitting6",
                    dt=period / 3, t_eval=np.linspace(0, t, 41))  # fmt: skip
    h = np.cross(R0, V0)
    ev = np.cross(V0, h) / mu - R0 / np.linalg.norm(R0)
    e = np.linalg.norm(ev)
    P, Qv = ev / e, np.cross(h / np.linalg.norm(h), ev / e)
    E0 = np.arctan2(R0 @ V0 / (e * np.sqrt(mu * a)), (1 - np.linalg.norm(R0) / a) / e)
    M = E0 - e * np.sin(E0) + np.sqrt(mu / a**3) * traj.t
    E = M.copy()
    for _ in range(50):
        E -= (E - e * np.sin(E) - M) / (1 - e * np.cos(E))
    R_exact = (a * (np.cos(E) - e))[:, None] * P + (a * np.sqrt(1 - e * e) * np.sin(E))[
        :, None
    ] * Qv
    assert 0.4 < e < 0.5
    # each flow restarts Kepler's flow from the state it is handed: round-off grows with the
    # number of flows (15 a step, 900 here; measured 3e-15 of |R| a flow)
    flows = 15 * 60
    assert np.abs(traj.R - R_exact).max() < 4e-15 * flows * np.abs(R_exact).max()
    free = FreeRigidBody.from_body(body)
    np.testing.assert_allclose(traj.omega, free.exact_omega(omega0, traj.t), rtol=0, atol=1e-12)


def test_an_ensemble_runs_each_member_as_its_single_run_and_grades_exactly():
    """A torque-free ensemble with ``exact-splitting4``: every member bit for bit its single
    run, and the exact grading (each member against its closed form) at round-off."""
    body = RigidBody.box(2.0, (1.0, 2.0, 3.0))
    omega0 = np.array([[0.3, 1.0, 0.2], [0.1, -0.5, 0.9], [1.0, 1e-6, 0.577]])
    t = np.linspace(0, 30, 7)
    result = simulate_ensemble(body, (0, 30), omega0=omega0, method="exact-splitting4", dt=0.5,
                               t_eval=t, progress=False)  # fmt: skip
    errors = result.exact_errors()
    assert errors["omega"].max() < 1e-13 and errors["attitude"].max() < 1e-13
    for i, w in enumerate(omega0):
        single = simulate(body, (0, 30), omega0=w, method="exact-splitting4", dt=0.5, t_eval=t)
        np.testing.assert_array_equal(result.omega[i], single.omega)


def test_a_heavy_top_ensemble_in_lanes_runs_each_member_as_its_single_run():
    """40 of FRB's heavy tops with ``exact-splitting6``: a block of lanes (the free flows in
    SIMD lanes, the kicks lane by lane), every member bit for bit its single run."""
    body, forces = frb_top()
    rng = np.random.default_rng(3)
    omega0 = FRB_PI0 / FRB_MOMENTS + 0.05 * rng.normal(size=(40, 3))
    t = np.linspace(0, 20, 5)
    kw = dict(forces=forces, pivot=(0, 0, 0), method="exact-splitting6", dt=0.5, t_eval=t)
    result = simulate_ensemble(body, (0, 20), omega0=omega0, progress=False, **kw)
    for i in (0, 17, 39):
        single = simulate(body, (0, 20), omega0=omega0[i], **kw)
        np.testing.assert_array_equal(result.omega[i], single.omega)
        np.testing.assert_array_equal(result.Q[i], single.Q)


def test_forces_that_depend_on_velocity_are_refused():
    from poinsot import LinearDrag

    body = RigidBody.box(1.0, (1.0, 2.0, 3.0))
    with pytest.raises(ValueError, match="exact-splitting4"):
        simulate(body, (0, 1), omega0=(0, 1, 0), forces=[LinearDrag(0.1)],
                 method="exact-splitting4", dt=0.1)  # fmt: skip


def test_a_scenario_runs_each_method_from_the_command_line(tmp_path, capsys):
    """The heavy-top example with ``method = "exact-splitting6"`` at a step eight times the
    example's ends where DOP853 at rtol 1e-12 ends."""
    import json

    from poinsot.app.cli import main
    from poinsot.app.scenario import example_text

    text = example_text("heavy-top") + "\n[output]\nfigures = false\nreport = false\n"
    finals = {}
    for method, step in (("exact-splitting6", "dt = 0.004"), ("dop853", "rtol = 1e-12")):
        path = tmp_path / f"{method}.toml"
        path.write_text(text.replace('method = "splitting"', f'method = "{method}"')
                        .replace("dt = 0.0005", step))  # fmt: skip
        assert main(["run", str(path), "--out", str(tmp_path / method), "--json"]) == 0
        summary = json.loads(capsys.readouterr().out)
        assert summary["integration"]["method"] == method
        finals[method] = np.array(summary["final"]["omega"])
    np.testing.assert_allclose(finals["exact-splitting6"], finals["dop853"], rtol=0, atol=1e-7)


PIVOTED = RigidBody(2.0, np.diag([0.6, 0.9, 1.3]), (0.1, -0.2, 0.3))


@pytest.mark.parametrize(("force", "name", "order", "steps"), [
    ("central", "splitting", 2, (0.02, 0.01, 0.005)),
    ("central", "exact-splitting", 2, (0.02, 0.01, 0.005)),
    ("spring", "splitting", 2, (0.02, 0.01, 0.005)),
    ("spring", "exact-splitting", 2, (0.02, 0.01, 0.005)),
    ("spring", "exact-splitting4", 4, (0.1, 0.05, 0.025)),
    ("spring", "exact-splitting6", 6, (0.2, 0.1, 0.05)),
])  # fmt: skip
def test_orders_about_a_pivot_off_the_centre_of_mass(force, name, order, steps):
    """A body about a pivot off its centre of mass under a force that depends on where the
    centre of mass is (a central gravity, a spring): each free flow moves the centre of mass
    with the attitude, so the next kick acts where it now is. With the step's starting `R`
    kept until the end every splitting had been first order. Errors in ω and Q at t = 2
    against DOP853 at rtol 1e-13."""
    forces = {"central": [CentralGravity(10.0, (3.0, 0.0, 0.0))],
              "spring": [Spring((0.1, 0.0, 0.2), (0.5, 0.3, 1.0), 20.0, 0.3)]}[force]  # fmt: skip
    kw = dict(omega0=(0.4, 1.1, -0.3), forces=forces, pivot=(0.05, 0.02, -0.4), t_eval=[2.0])
    ref = simulate(PIVOTED, (0, 2), method="dop853", rtol=1e-13, atol=1e-15, **kw)
    errors = []
    for h in steps:
        traj = simulate(PIVOTED, (0, 2), method=name, dt=h, **kw)
        errors.append(max(np.abs(traj.omega[-1] - ref.omega[-1]).max(),
                          np.abs(traj.Q[-1] - ref.Q[-1]).max()))  # fmt: skip
    assert abs(_order(errors, steps) - order) < 0.2, errors
