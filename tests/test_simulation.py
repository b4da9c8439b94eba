"""simulate(): the notebook's run, conservation, heavy top, initial conditions, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from poinsot import (
    Gravity,
    LinearDrag,
    ParticleForce,
    RigidBody,
    SimulationError,
    Spring,
    Torque,
    simulate,
)
from poinsot.dynamics import DegenerateBodyWarning
from poinsot.rotation import body_rates_from_euler, matrix_from_euler

G = 9.8
NOTEBOOK_T = np.linspace(0, 20, 101)


def test_notebook_gravity_run(notebook_body):
    # docs/theory.md §1: ω(0) = (0, 1, 1), R(0) = Ṙ(0) = 0... here R(0) is the body's centre of mass
    tr = simulate(
        notebook_body,
        (0, 20),
        omega0=(0, 1, 1),
        forces=[Gravity((0, 0, -G))],
        method="rk4",
        dt=0.2,
        t_eval=NOTEBOOK_T,
    )
    assert len(tr) == 101
    np.testing.assert_array_equal(tr.t, NOTEBOOK_T)
    drop = tr.R - tr.R[0]
    np.testing.assert_allclose(drop[:, :2], 0, atol=1e-12)
    np.testing.assert_allclose(drop[:, 2], -0.5 * G * tr.t**2, atol=1e-9, rtol=0)
    # gravity exerts no torque about the centre of mass: ω follows the torque-free equation
    free = simulate(
        notebook_body, (0, 20), omega0=(0, 1, 1), rtol=1e-13, atol=1e-14, t_eval=NOTEBOOK_T
    )
    err02 = np.abs(tr.omega - free.omega).max()
    half = simulate(
        notebook_body, (0, 20), omega0=(0, 1, 1), method="rk4", dt=0.1, t_eval=NOTEBOOK_T
    )
    err01 = np.abs(half.omega - free.omega).max()
    assert err02 < 1e-3
    assert 10 < err02 / err01 < 24  # RK4's h⁴: halving dt divides the error by ~16
    # rk4 reports its drift off SO(3)
    assert tr.diagnostics()["orthogonality_error"] > 1e-6


def test_particle_gravity_equals_uniform_gravity(notebook_body):
    m = notebook_body.particle_masses
    weight = ParticleForce(
        lambda t, r, v: np.outer(m, [0, 0, -G]), name="weights", position_only=True
    )
    a = simulate(notebook_body, (0, 5), omega0=(0, 1, 1), forces=[weight], t_eval=[0, 2.5, 5])
    b = simulate(
        notebook_body, (0, 5), omega0=(0, 1, 1), forces=[Gravity((0, 0, -G))], t_eval=[0, 2.5, 5]
    )
    np.testing.assert_allclose(a.state, b.state, atol=1e-9)


def test_torque_from_particle_forces_is_sum_u_cross_QtF(notebook_body):
    from poinsot._core import exp_so3
    from poinsot.dynamics import RigidBodySystem

    rng = np.random.default_rng(1)
    F = rng.normal(size=(27, 3))
    system = RigidBodySystem(notebook_body, [ParticleForce(lambda t, r, v: F)])
    Q = exp_so3([0.3, -0.4, 1.1])
    Ftot, tau = system.wrench(0.0, np.zeros(3), np.zeros(3), Q, np.zeros(3))
    np.testing.assert_allclose(Ftot, F.sum(0))
    expected = sum(np.cross(u, Q.T @ f) for u, f in zip(notebook_body.u, F, strict=True))
    np.testing.assert_allclose(tau, expected, atol=1e-13)  # eq. (08)


def _torque_free(method, steps, dt):
    body = RigidBody(1.0, np.diag([1.0, 2.0, 3.0]))
    return simulate(
        body,
        (0, steps * dt),
        omega0=(0.4, 1.0, -0.3),
        method=method,
        dt=dt,
        save_every=steps // 200,
    )


def test_splitting_conserves_momentum_to_roundoff_over_1e5_steps():
    tr = _torque_free("splitting", 100_000, 0.01)
    L = tr.angular_momentum_com
    Lnorm = np.linalg.norm(L, axis=1)
    assert np.abs(Lnorm / Lnorm[0] - 1).max() <= 1e-12
    assert np.abs(L - L[0]).max() <= 1e-11
    assert tr.orthogonality_error.max() <= 1e-12
    # bounded energy error, no trend: the two halves of the run have the same spread
    E = tr.energy_drift
    first, second = np.abs(E[: len(E) // 2]).max(), np.abs(E[len(E) // 2 :]).max()
    assert max(first, second) < 1e-3
    assert second < 2 * first
    slope = np.polyfit(tr.t, E, 1)[0] * tr.t[-1]
    assert abs(slope) < 0.2 * np.abs(E).max()


def test_rk4_reports_its_drift():
    tr = _torque_free("rk4", 100_000, 0.01)
    d = tr.diagnostics()
    # at dt = 0.01 the drift is small but systematic and reported: energy and |QᵀQ − I| grow
    assert d["orthogonality_error"] > 1e-12 and d["energy_drift"] > 1e-12
    n = len(tr) // 4
    assert np.abs(tr.energy_drift[-n:]).mean() > 2 * np.abs(tr.energy_drift[n : 2 * n]).mean()
    assert tr.orthogonality_error[-1] > tr.orthogonality_error[n]


@pytest.mark.parametrize(
    ("method", "dt"),
    [
        ("dop853", None),
        pytest.param("rkmk4", 5e-4, marks=pytest.mark.slow),
        pytest.param("splitting", 1.5e-4, marks=pytest.mark.slow),
    ],
)
def test_heavy_symmetric_top_steady_precession(method, dt):
    # Goldstein, Classical Mechanics (3rd ed.) §5.7: steady precession when
    # M g l = ψ̇ (C ω3 − A ψ̇ cos θ); the slow root of the quadratic in ψ̇.
    m, g, l = 1.0, 9.81, 0.5
    body = RigidBody.cylinder(m, 0.3, 0.2)
    pivot = (0, 0, -l)
    Ip = body.inertia_about(pivot)
    A, C = Ip[0, 0], Ip[2, 2]
    theta0, omega3 = 0.6, 100.0
    a, b, c = A * np.cos(theta0), -C * omega3, m * g * l
    psid = (-b - np.sqrt(b * b - 4 * a * c)) / (2 * a)
    phid = omega3 - psid * np.cos(theta0)
    angles = np.array([0.0, theta0, 0.0])
    period = 2 * np.pi / psid
    t_eval = np.linspace(0, 3 * period, 301)
    tr = simulate(
        body,
        (0, 3 * period),
        omega0=body_rates_from_euler(angles, [psid, 0, phid]),
        Q0=matrix_from_euler(angles, "ZXZ"),
        pivot=pivot,
        forces=[Gravity((0, 0, -g))],
        method=method,
        dt=dt,
        rtol=1e-12,
        atol=1e-12,
        t_eval=t_eval,
    )
    axis = tr.Q[:, :, 2]  # symmetry axis in space: (sin θ sin ψ, −sin θ cos ψ, cos θ)
    theta = np.arccos(np.clip(axis[:, 2], -1, 1))
    psi = np.unwrap(np.arctan2(axis[:, 0], -axis[:, 1]))
    psid_measured = np.diff(psi) / np.diff(tr.t)
    assert np.abs(theta - theta0).max() < 1e-6
    assert np.abs(psid_measured / psid - 1).max() < 1e-6
    # the pivot stays fixed
    c_body = body.center_of_mass - np.array(pivot)
    pivot_space = tr.R - np.einsum("nij,j->ni", tr.Q, c_body)
    np.testing.assert_allclose(pivot_space, np.tile(pivot, (len(tr), 1)), atol=1e-9)


@pytest.mark.parametrize("method", ["rk4", "rkmk4", "splitting"])
@pytest.mark.parametrize(
    "body",
    [
        RigidBody.box(1.0, (1, 2, 3)),
        RigidBody.box(1.0, (3, 2, 1)),
        RigidBody.cylinder(1, 0.3, 0.2),
        RigidBody.ellipsoid(2.0, (0.5, 1.5, 1.0), orientation=[0.8, 0.6, 0, 0]),
    ],
    ids=["box123", "box321", "cylinder", "ellipsoid-rotated"],
)
@pytest.mark.parametrize("pivot", [None, (0.1, 0.0, -0.5)], ids=["free", "pivot"])
def test_fixed_step_methods_agree_with_reference_on_any_body(method, body, pivot):
    """Regression: principal frames from eigh can be left-handed; every method must still
    follow the reference on bodies whose axes come out in any order and sign."""
    kw = dict(
        omega0=(1.0, 0.5, 8.0),
        Q0=matrix_from_euler([0.1, 0.6, -0.3], "ZXZ"),
        pivot=pivot,
        forces=[Gravity((0, 0, -9.81))],
        t_eval=[0, 1.0],
    )
    a = simulate(body, (0, 1), method=method, dt=2e-3, **kw)
    b = simulate(body, (0, 1), rtol=1e-12, atol=1e-12, **kw)
    assert np.abs(a.omega[-1] - b.omega[-1]).max() < 1e-3
    assert np.abs(a.Q[-1] - b.Q[-1]).max() < 1e-4


def test_compound_pendulum_small_oscillation_period():
    # physical pendulum: T = 2π √(I_P / (M g d)) (Meriam & Kraige, Dynamics, §8/5)
    rod = RigidBody.box(1.0, (0.02, 0.02, 1.0))
    pivot = (0, 0, 0.5)  # top end; hangs along −z
    eps = 1e-3
    tr = simulate(
        rod,
        (0, 10),
        omega0=(0, 0, 0),
        Q0=matrix_from_euler([0, eps, 0], "ZXZ"),
        pivot=pivot,
        forces=[Gravity((0, 0, -9.81))],
        rtol=1e-12,
        atol=1e-14,
        t_eval=np.linspace(0, 10, 20001),
    )
    Ip = rod.inertia_about(pivot)[0, 0]
    expected = 2 * np.pi * np.sqrt(Ip / (1.0 * 9.81 * 0.5))
    angle = tr.Q[:, 2, 1]  # ≈ sin of the swing angle
    i = np.nonzero(np.diff(np.sign(angle)) != 0)[0]
    crossings = tr.t[i] - angle[i] * (tr.t[i + 1] - tr.t[i]) / (angle[i + 1] - angle[i])
    measured = 2 * np.mean(np.diff(crossings))
    assert measured == pytest.approx(expected, rel=1e-5)


def test_energy_conserved_with_springs_and_gravity():
    body = RigidBody.box(2.0, (1.0, 0.6, 0.3))
    forces = [
        Spring((0.5, 0.3, 0.15), (1.0, 0.5, 1.0), 30.0, 0.2),
        Spring((-0.5, 0.0, 0.0), (-1.0, 0.0, 1.0), 20.0),
        Gravity((0, 0, -9.81)),
    ]
    tr = simulate(
        body,
        (0, 20),
        omega0=(0.3, 1.2, -0.5),
        V0=(0.1, 0, 0.2),
        forces=forces,
        rtol=1e-11,
        atol=1e-12,
        t_eval=np.linspace(0, 20, 401),
    )
    assert tr.is_conservative
    assert np.abs(tr.total_energy - tr.total_energy[0]).max() < 1e-8 * abs(tr.total_energy).max()
    # and the splitting method keeps it bounded
    sp = simulate(
        body,
        (0, 20),
        omega0=(0.3, 1.2, -0.5),
        V0=(0.1, 0, 0.2),
        forces=forces,
        method="splitting",
        dt=1e-3,
        t_eval=np.linspace(0, 20, 401),
    )
    assert np.abs(sp.energy_drift).max() < 1e-4


def test_drag_dissipates_energy():
    body = RigidBody.sphere(1.0, 0.1)
    tr = simulate(
        body,
        (0, 5),
        omega0=(0, 0, 3.0),
        V0=(1, 0, 0),
        forces=[LinearDrag(0.5, rotational=0.01)],
        t_eval=np.linspace(0, 5, 11),
    )
    assert not tr.is_conservative
    assert np.all(np.diff(tr.kinetic_energy) < 0)
    np.testing.assert_allclose(tr.V[:, 0], np.exp(-0.5 * tr.t), rtol=1e-8)


def test_particle_initial_conditions_match_state_initial_conditions(notebook_body):
    V, w = np.array([0.3, -0.2, 0.5]), np.array([0.1, 0.7, -0.4])
    vel = V + np.cross(w, notebook_body.u)
    forces = [Gravity((0, 0, -G))]
    a = simulate(notebook_body, (0, 3), particle_velocities=vel, forces=forces, t_eval=[0, 1.5, 3])
    b = simulate(notebook_body, (0, 3), omega0=w, V0=V, forces=forces, t_eval=[0, 1.5, 3])
    np.testing.assert_allclose(a.state, b.state, atol=1e-10)
    np.testing.assert_allclose(a.positions()[0], notebook_body.particle_positions, atol=1e-14)


def test_non_rigid_particle_velocities_refused(notebook_body):
    vel = np.zeros((27, 3))
    vel[5] = [0, 0, 1.0]
    with pytest.raises(ValueError, match=r"not a rigid motion: largest residual .* particle 5"):
        simulate(notebook_body, (0, 1), particle_velocities=vel)


def test_degenerate_body_minimum_norm_omega():
    line = RigidBody.from_particles([1.0, 2.0, 1.0], [[0, 0, 0], [0, 0, 1], [0, 0, 2]])
    vel = np.cross([0.5, 0, 0], line.u)  # tumbling about x
    with pytest.warns(DegenerateBodyWarning, match="spin about that line is undefined"):
        tr = simulate(line, (0, 1), particle_velocities=vel, t_eval=[0, 1])
    np.testing.assert_allclose(tr.omega[0], [0.5, 0, 0], atol=1e-12)
    with pytest.warns(DegenerateBodyWarning, match="component 2"):
        tr = simulate(line, (0, 1), omega0=(0.5, 0, 2.0), t_eval=[0, 1])
    np.testing.assert_allclose(tr.omega[:, 2], 0, atol=1e-12)


def test_omega_in_space_frame():
    body = RigidBody.box(1.0, (1, 2, 3))
    Q0 = matrix_from_euler([0.3, 0.7, -0.2], "ZXZ")
    w_space = np.array([0.2, -0.5, 1.0])
    a = simulate(body, (0, 2), omega0=w_space, Q0=Q0, omega_frame="space", t_eval=[0, 2])
    b = simulate(body, (0, 2), omega0=Q0.T @ w_space, Q0=Q0, t_eval=[0, 2])
    np.testing.assert_allclose(a.state, b.state, atol=1e-14)
    np.testing.assert_allclose(a.omega_space[0], w_space, atol=1e-14)


def test_non_finite_state_stops_with_partial_trajectory():
    body = RigidBody.sphere(1.0, 1.0)
    boom = Torque(lambda t: [1e308 if t > 0.5 else 0.0, 0, 0])
    with pytest.raises(SimulationError, match=r"non-finite .*omega.* at t = 0\.") as info:
        simulate(
            body,
            (0, 1),
            omega0=(1, 0, 0),
            forces=[boom],
            method="rk4",
            dt=0.1,
            t_eval=np.linspace(0, 1, 11),
        )
    partial = info.value.trajectory
    assert 5 <= len(partial) <= 7 and np.all(np.isfinite(partial.state))


def test_exports(tmp_path, notebook_body):
    tr = simulate(
        notebook_body,
        (0, 2),
        omega0=(0, 1, 1),
        forces=[Gravity((0, 0, -G))],
        t_eval=np.linspace(0, 2, 5),
    )
    tr.to_npz(tmp_path / "t.npz")
    data = np.load(tmp_path / "t.npz")
    np.testing.assert_array_equal(data["Q"], tr.Q)
    np.testing.assert_array_equal(data["total_energy"], tr.total_energy)
    tr.to_csv(tmp_path / "t.csv")
    header = (tmp_path / "t.csv").read_text().splitlines()[0].split(",")
    table = np.loadtxt(tmp_path / "t.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[:, header.index("omega_y [rad/s]")], tr.omega[:, 1])
    np.testing.assert_array_equal(table[:, header.index("R_z [m]")], tr.R[:, 2])
    assert header[0] == "t [s]" and "total_energy [J]" in header
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv", "t.npz"]  # no temp files
    positions = tr.positions()
    assert positions.shape == (5, 27, 3)
    assert tr.rigidity_error.max() < 1e-9


def test_xarray_export():
    xr = pytest.importorskip("xarray")
    body = RigidBody.box(1.0, (1, 2, 3))
    ds = simulate(body, (0, 1), omega0=(0, 1, 0.1), t_eval=[0, 0.5, 1]).to_xarray()
    assert isinstance(ds, xr.Dataset) and ds["omega"].shape == (3, 3)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"Q0": np.diag([1.0, 1, -1])}, "`Q0` is not a rotation"),
        ({"omega0": (0, np.nan, 1)}, r"`omega0\[1\]` must be finite"),
        ({"omega0": (0, 1)}, r"`omega0` must have shape \(3,\)"),
        ({"method": "euler"}, "`method` must be one of"),
        ({"method": "rkmk4"}, "fixed-step: `dt` must be given"),
        ({"method": "rk4", "dt": -0.1}, "`dt` must be a positive number"),
        ({"t_span": (1, 0)}, "`t_span` must increase"),
        ({"t_span": 5}, r"`t_span` must be a pair"),
        ({"t_eval": [0, 0.5, 0.2]}, "strictly increasing"),
        ({"t_eval": [0, 2]}, "within t_span"),
        ({"omega_frame": "lab"}, "`omega_frame` must be 'body' or 'space'"),
        ({"omega0": None}, "`omega0` must be given"),
        ({"forces": [lambda t: 0]}, r"`forces\[0\]` must be a poinsot Force"),
        ({"forces": Gravity()}, "`forces` must be a sequence"),
        ({"save_every": 0}, "`save_every` must be a positive integer"),
        ({"pivot": (0, 0, 1), "V0": (1, 0, 0)}, "`V0` must be omitted with a `pivot`"),
    ],
)
def test_bad_input(kwargs, match):
    args = {"t_span": (0, 1), "omega0": (0, 1, 0)} | kwargs
    t_span = args.pop("t_span")
    with pytest.raises((ValueError, TypeError), match=match):
        simulate(RigidBody.box(1.0, (1, 2, 3)), t_span, **args)


@pytest.mark.parametrize(
    ("force", "match"),
    [
        (
            ParticleForce(lambda t, r, v: np.zeros(3), name="wind"),
            r"force wind returned particle forces of shape \(3,\), expected \(27, 3\)",
        ),
        (
            ParticleForce(lambda t, r, v: np.full((27, 3), np.nan), name="wind"),
            "force wind returned a non-finite particle forces",
        ),
        (Torque(lambda t: [1, 2]), r"force Torque returned torque of shape \(2,\)"),
    ],
)
def test_broken_force_callables(force, match, notebook_body):
    with pytest.raises(ValueError, match=match):
        simulate(notebook_body, (0, 1), omega0=(0, 1, 1), forces=[force])


def test_particle_force_needs_particles():
    with pytest.raises(ValueError, match="ParticleForce needs a body built from particles"):
        simulate(
            RigidBody.sphere(1, 1),
            (0, 1),
            omega0=(0, 1, 0),
            forces=[ParticleForce(lambda t, r, v: r)],
        )
