"""Stability of motions from the sensitivities: the Floquet picture of periodic torque-free
motions (every multiplier 1, one Jordan block) and the growth rate about the intermediate axis
against its closed form."""

import math

import numpy as np
import pytest

from poinsot import FreeRigidBody, RigidBody, simulate

MOMENTS = (1.0, 2.0, 3.0)


def euler_rate(moments, w):
    """ω̇ = A⁻¹ (Aω × ω), written here independently of the library."""
    I = np.asarray(moments, float)
    return np.cross(I * w, w) / I


def near_separatrix(eps):
    """ω0 whose a²/2k is I2 (1 + eps) for MOMENTS (around e3)."""
    I1, I2, I3 = MOMENTS
    w3 = 0.5
    return (math.sqrt(I3 * (I3 - I2) / (I1 * (I2 - I1))) * w3 * (1 - eps), 1.0, w3)


PERIODIC = [(0.1, 1.0, 0.1), (1.0, 0.3, 0.2), (0.2, 0.3, 1.0), (1e-3, 1.0, 1e-3),
            (-0.7, 0.2, 0.9), near_separatrix(1e-6)]  # fmt: skip
PERIODIC_IDS = ["tennis racket", "around e1", "around e3", "near the separatrix", "mixed signs",
                "1e-6 from the separatrix"]  # fmt: skip


@pytest.mark.parametrize("omega0", PERIODIC, ids=PERIODIC_IDS)
def test_a_periodic_torque_free_motion_has_every_floquet_multiplier_one(omega0):
    # the closed form's exact monodromy: also 1e-6 from the separatrix (an integrated run
    # passes the saddle there and its error grows as 1/ε)
    body = FreeRigidBody(MOMENTS)
    f = body.floquet(omega0)
    assert f.method == "closed form"
    M, I = f.monodromy, np.eye(3)
    scale = max(np.abs(M).max(), 1.0)
    # the characteristic polynomial (λ − 1)³: trace 3, det 1, and one Jordan block
    assert abs(np.trace(M) - 3) <= 1e-9 * scale
    assert abs(np.linalg.det(M) - 1) <= 1e-9 * scale**3
    assert np.abs((M - I) @ (M - I)).max() <= 1e-9 * scale**2
    # the flow direction is carried onto itself
    v = euler_rate(MOMENTS, np.asarray(omega0, float))
    assert np.abs(M @ v - v).max() <= 1e-9 * scale * np.abs(v).max()
    # ... and the block is not trivial: a neighbour on another polhode drifts in phase
    assert np.abs(M - I).max() > 1e-3


@pytest.mark.parametrize("omega0", PERIODIC, ids=PERIODIC_IDS)
def test_the_jordan_block_is_the_periods_sensitivity(omega0):
    # ω(T(ω0); ω0) = ω0 for every ω0, so M − I = −ω̇(0) ∇T(ω0)ᵀ: the monodromy (∂ω at
    # t = T) against the period's gradient, two parts of the closed form's derivatives
    body = FreeRigidBody(MOMENTS)
    f = body.floquet(omega0)
    grad = body.exact_derivatives(omega0, [0.0]).d_period_d_omega0
    v = euler_rate(MOMENTS, np.asarray(omega0, float))
    expected = -np.outer(v, grad)
    err = np.abs(f.monodromy - np.eye(3) - expected).max() / np.abs(expected).max()
    assert err <= 1e-9
    assert f.drift == pytest.approx(np.linalg.norm(v) * np.linalg.norm(grad), rel=1e-9)


@pytest.mark.parametrize("omega0", [*PERIODIC[:3], PERIODIC[4]], ids=[*PERIODIC_IDS[:3], "mixed"])
def test_the_closed_forms_monodromy_equals_an_integrated_runs(omega0):
    body = FreeRigidBody(MOMENTS)
    exact = body.floquet(omega0)
    run = body.floquet(omega0, period=exact.period)  # any given period: the DOP853 route
    assert run.method == "dop853"
    np.testing.assert_allclose(run.monodromy, exact.monodromy, atol=1e-9)


def test_near_the_separatrix_the_drift_grows_as_one_over_the_distance():
    drifts = [FreeRigidBody(MOMENTS).floquet(near_separatrix(eps)).drift
              for eps in (1e-4, 1e-6, 1e-8)]  # fmt: skip
    assert 50 < drifts[1] / drifts[0] < 200 and 50 < drifts[2] / drifts[1] < 200


def test_describe_reports_the_floquet_drift():
    body = FreeRigidBody(MOMENTS)
    out = body.describe((0.1, 1.0, 0.1))
    assert out["floquet_drift"] == pytest.approx(body.floquet((0.1, 1.0, 0.1)).drift)
    assert "floquet_drift" not in body.describe((0.0, 1.0, 0.0))  # a fixed point


@pytest.mark.parametrize("w2", [1.0, -2.5, 1e-3])
@pytest.mark.parametrize("moments", [MOMENTS, (0.5, 2.2, 2.4)])
def test_the_growth_rate_about_the_intermediate_axis(moments, w2):
    I1, I2, I3 = moments
    sigma = abs(w2) * math.sqrt((I2 - I1) * (I3 - I2) / (I1 * I3))
    f = FreeRigidBody(moments).floquet((0.0, w2, 0.0))
    assert abs(f.exponents[0] - sigma) <= 1e-6 * sigma
    assert abs(f.exponents[2] + sigma) <= 1e-6 * sigma
    assert abs(f.exponents[1]) <= 1e-9 * sigma


def test_finite_time_lyapunov_exponents_approach_the_growth_rate():
    body = RigidBody.box(1.0, (1, 2, 3))
    I1, I2, I3 = body.principal_moments
    sigma = math.sqrt((I2 - I1) * (I3 - I2) / (I1 * I3))
    traj = simulate(body, (0, 40), omega0=(0, 1, 0), method="dop853", rtol=1e-12,
                    atol=1e-14, sensitivities="omega0", t_eval=np.linspace(0, 40, 5))  # fmt: skip
    lam = traj.lyapunov_exponents()
    assert np.isnan(lam[0]).all()
    # λ(t) = σ + ln c/t: the error falls as 1/t
    err = np.abs(lam[1:, 0] - sigma)
    assert np.all(np.diff(err) < 0) and err[-1] < 0.01 * sigma
    assert abs(lam[1, 0] + lam[1, 1] + lam[1, 2]) < 1e-9  # volume preserved


def test_floquet_refuses_what_has_no_period():
    body = FreeRigidBody(MOMENTS)
    with pytest.raises(ValueError, match="at rest"):
        body.floquet((0, 0, 0))
    with pytest.raises(ValueError, match="period"):
        body.floquet((0.1, 1, 0.1), period=-1.0)


@pytest.mark.parametrize("omega0", [(0.1, 1, 0.1), (0.0, 1.0, 0.0)], ids=["closed form", "run"])
@pytest.mark.parametrize(
    ("kw", "error", "message"),
    [
        ({"rtol": -1, "atol": "x"}, ValueError, "`rtol` must be a positive number"),
        ({"rtol": 2.0}, ValueError, "`rtol` must be below 1"),
        ({"atol": "x"}, TypeError, "`atol` must be a real number"),
        ({"atol": 0.0}, ValueError, "`atol` must be a positive number"),
        ({"period": "1"}, TypeError, "`period` must be a real number"),
        ({"period": np.array([2.0])}, ValueError, r"`period` must be a scalar, found shape \(1,\)"),
        ({"period": math.nan}, ValueError, "`period` must be finite"),
        ({"period": 0.0}, ValueError, "`period` must be a positive finite time"),
    ],
)
def test_floquet_checks_every_argument_on_either_path(omega0, kw, error, message):
    """The closed form's path took ``rtol=-1, atol="x"`` and ``period="1"`` without a word
    (the run's refused them), and ``period=np.array([2.])`` raised NumPy's message."""
    with pytest.raises(error, match=message):
        FreeRigidBody(MOMENTS).floquet(omega0, **kw)


@pytest.mark.parametrize("name", ["rtol", "atol"])
def test_a_tolerance_given_to_the_closed_form_is_refused(name):
    """The closed form integrates nothing: a tolerance would have no effect there."""
    body = FreeRigidBody(MOMENTS)
    with pytest.raises(ValueError, match=rf"`{name}` has no effect here: .*closed form"):
        body.floquet((0.1, 1.0, 0.1), **{name: 1e-10})
    # where a DOP853 run gives the monodromy, it takes them
    twice = 2 * body.period((0.1, 1.0, 0.1))  # a period, not the motion's own
    assert body.floquet((0.1, 1.0, 0.1), period=twice, **{name: 1e-10}).method == "dop853"
    assert body.floquet((0.0, 1.0, 0.0), **{name: 1e-10}).method == "dop853"
    loose = body.floquet((0.0, 1.0, 0.0), period=5.0, rtol=1e-4, atol=1e-6)
    tight = body.floquet((0.0, 1.0, 0.0), period=5.0)
    assert 0 < np.abs(loose.monodromy - tight.monodromy).max() < 1e-2  # an effect


# ------------------------------------------------------ Lagrangian steady motions (Floquet)


def _matched(a, b, tol):
    """Each of ``a`` within ``tol`` of some element of ``b`` and the reverse (multisets of
    multipliers, in any order)."""
    d = np.abs(np.asarray(a)[:, None] - np.asarray(b)[None, :])
    return d.min(axis=1).max() <= tol and d.min(axis=0).max() <= tol


def test_the_inverted_pendulums_floquet_exponent_is_its_growth_rate():
    import math

    from poinsot.models import pendulum_polar

    mdl = pendulum_polar()
    th = mdl.system.coordinates[0]
    lin = mdl.system.linearize({th: math.pi}, params=mdl.params)
    values = {str(k): float(v) for k, v in mdl.params.items()}
    sigma = math.sqrt(values["g"] / values["l"])  # the inverted pendulum's growth rate
    for T in (0.5, 1.0):
        f = lin.floquet(period=T)
        assert f.exponents[0] == pytest.approx(sigma, rel=1e-9)
        assert f.exponents[1] == pytest.approx(-sigma, rel=1e-9)
        assert _matched(f.multipliers, np.exp(lin.eigenvalues * T), 1e-9 * math.exp(sigma * T))


@pytest.mark.parametrize("root", [0, 1], ids=["slow", "fast"])
def test_a_steady_precessions_multipliers_are_its_linearisations(root):
    # the heavy top's steady precession (Lagrange's equations in Euler angles): the monodromy
    # of the nonlinear run over a turn of the spin has the multipliers exp(λT), all on the unit
    # circle (spectrally stable), the ignorable angles' drift a Jordan block at 1
    import math

    from poinsot.models import heavy_symmetric_top
    from poinsot.tops import steady_precession_rates

    top = heavy_symmetric_top()
    sym = {str(s): s for s in top.params}
    coords = {str(c.func): c for c in top.system.coordinates}
    A, C, M, g, l = (top.params[sym[k]] for k in ("A", "C", "M", "g", "l"))
    theta0, spin = 0.6, 100.0
    rate = steady_precession_rates(A, C, M * g * l, theta0, spin)[root]
    point = {coords["psi"]: 0.0, coords["theta"]: theta0, coords["phi"]: 0.0}
    speeds = {coords["psi"]: rate, coords["theta"]: 0.0,
              coords["phi"]: spin - rate * math.cos(theta0)}  # fmt: skip
    lin = top.system.linearize(point, params=top.params, speeds=speeds)
    assert lin.reduced_verdict == "spectrally stable"
    f = lin.floquet()
    assert f.period == pytest.approx(2 * math.pi / abs(speeds[coords["phi"]]))
    assert _matched(f.multipliers, np.exp(lin.eigenvalues * f.period), 1e-8)
    np.testing.assert_allclose(np.abs(f.multipliers), 1.0, atol=1e-8)
    assert f.drift > 0.1  # the precession angle and the spin drift with their rates


def test_floquet_of_a_linearisation_says_what_it_needs():
    import math

    from poinsot.models import pendulum_polar

    mdl = pendulum_polar()
    th = mdl.system.coordinates[0]
    lin = mdl.system.linearize({th: math.pi}, params=mdl.params)
    with pytest.raises(ValueError, match="every time is a period"):
        lin.floquet()
    with pytest.raises(ValueError, match="positive finite"):
        lin.floquet(period=-1.0)
    # over 20 s round-off (exp(σ T) ~ 1e27 times) has thrown the pendulum off the top and
    # round once: its "exponents" had been 1.5 and 1.2, det M 1e23, without a word
    with pytest.raises(ValueError, match=r"`period` 20: the motion does not return over it "
                                         r"\(the state \(q, q̇\) is 6\.2\d from where"):  # fmt: skip
        lin.floquet(period=20.0)


def test_floquet_over_a_time_that_is_not_a_period_is_refused():
    """A free body's monodromy over 5 s, a fifth of its period, had given multipliers of
    modulus 12, 0.06 and 1.4, which read as unstable."""
    body = FreeRigidBody(MOMENTS)
    w = (0.1, 1.0, 0.1)
    own = body.period(w)
    with pytest.raises(ValueError, match=rf"`period` 5: the motion does not return over it "
                                         rf"\(ω is .*; its own period is {own:.5f}"):  # fmt: skip
        body.floquet(w, period=5.0)
    # two periods are a period; at a fixed point every time is one
    f = body.floquet(w, period=2 * own)
    # a Jordan block's double 1 splits by about √(its error): 7e-7 here
    np.testing.assert_allclose(np.abs(f.multipliers), 1.0, atol=1e-5)
    assert abs(np.linalg.det(f.monodromy) - 1) < 1e-9
    assert body.floquet((0.0, 1.0, 0.0), period=5.0).method == "dop853"


@pytest.mark.parametrize("angle", [0.0, math.pi], ids=["hanging", "inverted"])
def test_a_constrained_pendulums_multipliers_are_the_unconstrained_ones(angle):
    # the same pendulum twice: in its angle (no constraint) and as a bob at (x, y) held by
    # the rod's holonomic constraint, its monodromy formed on the constraint manifold in the
    # chart of one independent coordinate and velocity: the same two multipliers
    from poinsot.models import pendulum_cartesian, pendulum_polar

    polar, cart = pendulum_polar(), pendulum_cartesian()
    th = polar.system.coordinates[0]
    x, y = cart.system.coordinates
    f = polar.system.linearize({th: angle}, params=polar.params).floquet(period=0.7)
    lin = cart.system.linearize({x: 0.0, y: -math.cos(angle)}, params=cart.params)
    g = lin.floquet(period=0.7)
    assert g.multipliers.shape == (2,) and lin.matrix.shape == (2, 2)
    scale = np.abs(f.multipliers).max()
    assert _matched(g.multipliers, f.multipliers, 1e-9 * scale)
    assert _matched(g.multipliers, np.exp(lin.eigenvalues * 0.7), 1e-9 * scale)


def test_a_rolling_disks_steady_motion_has_every_multiplier_one():
    # non-holonomic: the vertical disk rolling straight on (a steady motion: the velocities
    # constant); the chart keeps the four coordinates and two of the velocities. Every one
    # of the six multipliers is 1, and the rolling angle's and the position's drift is a
    # Jordan block (a neighbour rolls at another rate)
    from poinsot.models import rolling_disk

    disk = rolling_disk()
    x, y, ph, th = disk.system.coordinates
    radius = {str(k): float(v) for k, v in disk.params.items()}["R"]
    point = {x: 0.0, y: 0.0, ph: 0.3, th: 0.0}
    speeds = {th: 4.0, x: radius * 4.0 * math.cos(0.3), y: radius * 4.0 * math.sin(0.3)}
    lin = disk.system.linearize(point, params=disk.params, speeds=speeds)
    f = lin.floquet()
    assert f.period == pytest.approx(2 * math.pi / 4.0)
    assert f.multipliers.shape == (6,) == lin.eigenvalues.shape
    np.testing.assert_allclose(f.multipliers, 1.0, atol=1e-9)
    assert f.drift > 0.1
