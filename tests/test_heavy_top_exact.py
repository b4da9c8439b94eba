"""The heavy symmetric top in closed form (``poinsot.tops.exact_motion``, the core's
``heavy_top.rs``) against independent routes: a 34-digit reference from mpmath's Taylor ODE
solver (``tests/data/heavy_top_mpmath.json``, made by ``make_heavy_top_reference.py``), the
quadratures of the cubic for the nutation period and the precession rate, and integrations
of the body's own equations (DOP853, exact-splitting6), field by field."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from poinsot import Gravity, RigidBody, _core, simulate
from poinsot.rotation import matrix_from_euler
from poinsot.tops import exact_motion, heavy_top, steady_precession_rates, top_motion

REFERENCE = json.loads((Path(__file__).parent / "data" / "heavy_top_mpmath.json").read_text())
BODY = RigidBody.cylinder(1.0, 0.3, 0.2)
PIVOT = (0.0, 0.0, -0.5)
TOP = heavy_top(BODY, PIVOT, [Gravity()])


@pytest.mark.parametrize("name", sorted(REFERENCE["cases"]))
def test_angles_agree_with_a_34_digit_reference(name):
    """θ, ψ, φ over ten nutation periods within 1e-13 (relative) of mpmath's, for a fast top,
    a slow top, a top released from rest (a cusp) and one nearly asleep (0.01 rad)."""
    top, case = REFERENCE["top"], REFERENCE["cases"][name]
    ref = np.array([[float(v) for v in row] for row in case["theta_thetadot_psi_phi"]])
    motion, _ = _core.heavy_top_motions(top["A"], top["C"], top["mgl"], [case["angles"]],
                                        [case["rates"]], case["t"])  # fmt: skip
    for ours, col in ((motion[0, :, 1], 0), (motion[0, :, 0], 2), (motion[0, :, 2], 3)):
        scale = np.maximum(np.abs(ref[:, col]), 1e-300)
        rel = np.abs(ours - ref[:, col]) / scale
        assert rel[np.abs(ref[:, col]) > 1e-12].max() < 1e-13, (name, col, rel.max())


@pytest.mark.parametrize("name", sorted(REFERENCE["cases"]))
def test_period_and_precession_rate_are_the_quadratures_of_the_cubic(name):
    """T = 2∫du/√f(u) and ψ's mean rate (2/T)∫ψ̇(u) du/√f(u) between the turning points, and the
    turning points the cubic's roots: mpmath (30 digits: its polynomial roots and tanh-sinh
    quadrature, u = u₁ + (u₂ − u₁) sin²χ)."""
    import mpmath as mp

    mp.mp.dps = 30
    top, case = REFERENCE["top"], REFERENCE["cases"][name]
    A, C, mgl = (mp.mpf(top[k]) for k in ("A", "C", "mgl"))
    _, th, _ = (mp.mpf(x) for x in case["angles"])
    psid, thd, phid = (mp.mpf(x) for x in case["rates"])
    w3 = phid + psid * mp.cos(th)
    a, beta = C * w3 / A, 2 * mgl / A
    b = psid * mp.sin(th) ** 2 + a * mp.cos(th)
    alpha = beta * mp.cos(th) + thd**2 + psid**2 * mp.sin(th) ** 2
    u1, u2, u3 = sorted(
        mp.re(r)
        for r in mp.polyroots(
            [beta, -(alpha + a * a), 2 * a * b - beta, alpha - b * b], maxsteps=200, extraprec=200
        )
    )
    u = lambda chi: u1 + (u2 - u1) * mp.sin(chi) ** 2  # noqa: E731
    weight = lambda chi: 2 / mp.sqrt(beta * (u3 - u(chi)))  # noqa: E731
    period = 2 * mp.quad(weight, [0, mp.pi / 2])
    advance = 2 * mp.quad(lambda c: (b - a * u(c)) / (1 - u(c) ** 2) * weight(c), [0, mp.pi / 2])
    _, summary = _core.heavy_top_motions(top["A"], top["C"], top["mgl"], [case["angles"]],
                                         [case["rates"]], [0.0])  # fmt: skip
    s = summary[0]
    assert s[3] == pytest.approx(float(period), rel=1e-13)
    assert s[4] == pytest.approx(float(advance / period), rel=1e-12)
    np.testing.assert_allclose(s[:3], [float(u1), float(u2), float(u3)], rtol=0, atol=1e-14)


@pytest.mark.parametrize("spin", [1e4, 3e5])
def test_a_fast_top_released_from_rest_precesses(spin):
    """A fast top released from rest nutates in a band of 1e-8 rad whose turning points lie
    far below its third root (x₃ ≈ a²/β ≈ 1e8): its band, nutation period and mean precession
    rate are the cubic's (mpmath: its roots and quadratures at 40 digits), and the precession
    is about the gyroscopic M g l/(C ω₃), not zero (the band had been taken for none)."""
    import mpmath as mp

    mp.mp.dps = 40
    Q0 = matrix_from_euler([0.0, 0.6, 0.0])
    m = exact_motion(TOP, (0.0, 0.0, spin), Q0, [0.0])
    A, C, mgl = mp.mpf(TOP.A), mp.mpf(TOP.C), mp.mpf(TOP.mgl)
    u0 = mp.cos(mp.mpf(0.6))
    a, beta = C * spin / A, 2 * mgl / A
    b, alpha = a * u0, beta * u0
    cubic = [beta, -(alpha + a * a), 2 * a * b - beta, alpha - b * b]
    u1, u2, u3 = sorted(mp.re(r) for r in mp.polyroots(cubic, maxsteps=400, extraprec=400))
    u = lambda chi: u1 + (u2 - u1) * mp.sin(chi) ** 2  # noqa: E731
    weight = lambda chi: 2 / mp.sqrt(beta * (u3 - u(chi)))  # noqa: E731
    period = 2 * mp.quad(weight, [0, mp.pi / 2])
    advance = 2 * mp.quad(lambda c: (b - a * u(c)) / (1 - u(c) ** 2) * weight(c), [0, mp.pi / 2])
    assert m.nutation_period == pytest.approx(float(period), rel=1e-10)
    assert m.mean_precession_rate == pytest.approx(float(advance / period), rel=1e-8)
    assert m.mean_precession_rate == pytest.approx(m.gyroscopic_rate, rel=1e-3)
    assert m.theta_band[1] - m.theta_band[0] == pytest.approx(
        float(mp.acos(u1) - mp.acos(u2)), rel=1e-6)  # fmt: skip


@pytest.mark.parametrize("spin", [0.0, 1e-12, 1e-9, 1e-6, 1e-4])
def test_a_top_with_almost_no_spin_keeps_its_digits_at_the_bottom(spin):
    """Released at θ = 0.6 rad with little or no spin, the top falls past the hanging vertical
    (through it, without spin), where ψ turns by nearly π (steps by π): its motion agrees with
    DOP853 (rtol 1e-13, itself within 1.3e-12 of rtol 1e-12) to 2e-12 and keeps its energy to
    1e-13. `F₋ Π(n₋)` with `n₋ = −(u₂ − u₁)/(1 + u₁)` → −∞ had cancelled (0.33 in Q at spin
    1e-12, 2.6e-7 at 1e-6, NaN without spin): DLMF 19.7.9's form keeps it."""
    Q0 = matrix_from_euler([0.0, 0.6, 0.0])
    w0, t = (0.0, 0.0, spin), np.linspace(0, 2, 201)
    exact = exact_motion(TOP, w0, Q0, t)
    ref = simulate(BODY, (0, 2), omega0=w0, Q0=Q0, pivot=PIVOT, forces=[Gravity()],
                   method="dop853", rtol=1e-13, atol=1e-15, t_eval=t)  # fmt: skip
    assert np.abs(exact.Q - ref.Q).max() < 2e-12
    assert np.abs(exact.omega - ref.omega).max() < 2e-12
    assert exact.theta_band[1] == pytest.approx(np.pi, abs=1e-5)
    I = BODY.inertia_about(PIVOT)
    com = np.einsum("nij,j->ni", exact.Q, np.asarray(BODY.center_of_mass) - PIVOT)
    energy = 0.5 * np.einsum("ni,ij,nj->n", exact.omega, I, exact.omega) + 9.81 * com[:, 2]
    assert np.ptp(energy) < 1e-13 * TOP.mgl


@pytest.mark.parametrize("spin", [5.0, 30.0])
@pytest.mark.parametrize("offset", [0.0, 1e-12, 1e-8, -1e-8])
def test_a_top_passing_by_the_upward_vertical_keeps_its_digits(spin, offset):
    """Thrown up from θ = 0.3 rad with `L_z` within `offset` (relative) of `L₃` (`b = a`), the
    axis passes through or by the upward vertical, where `n₊ = (u₂ − u₁)/(1 − u₁)` → 1: `R_J`'s
    `1 − n₊ sn²` is formed as `(1 − u)/(1 − u₁)`. Within 2e-12 of DOP853 (rtol 1e-13)."""
    from poinsot.rotation import body_rates_from_euler

    th0 = 0.3
    u0, s2 = np.cos(th0), np.sin(th0) ** 2
    a, beta = TOP.C * spin / TOP.A, 2 * TOP.mgl / TOP.A
    psid = a * (1 - u0) / s2 * (1 + offset)
    angles = np.array([0.0, th0, 0.0])
    rates = np.array([psid, -2 * np.sqrt(beta * (1 - u0) + 1.0), spin - psid * u0])
    w0 = (body_rates_from_euler(angles[None], rates[None]) @ TOP.frame().T)[0]
    Q0, t = matrix_from_euler(angles), np.linspace(0, 3, 151)
    exact = exact_motion(TOP, w0, Q0, t)
    ref = simulate(BODY, (0, 3), omega0=w0, Q0=Q0, pivot=PIVOT, forces=[Gravity()],
                   method="dop853", rtol=1e-13, atol=1e-15, t_eval=t)  # fmt: skip
    assert exact.spin == pytest.approx(spin, rel=1e-14)
    assert np.abs(exact.Q - ref.Q).max() < 2e-12
    assert np.abs(exact.omega - ref.omega).max() < 2e-12 * spin
    assert exact.theta_band[0] < 1e-3


@pytest.mark.parametrize(
    "theta0, thetadot, spin",
    [(2.583, -26.04530642, 0.0), (0.6219, -91.15, 0.0), (1.0, 30.0, 1e-9), (0.002, 0.0, 0.0),
     (1.0, 3.0, 0.0), (1.55, -7.22155097, -1.98e-4)],
)  # fmt: skip
def test_a_swing_in_a_vertical_plane(theta0, thetadot, spin):
    """Without precession or spin the axis swings in a vertical plane: over the top and through
    both verticals (the first three: the band is all of [−1, 1], ψ steps by π at each), or
    through the hanging one. Within 5e-12 of DOP853 (rtol 1e-13). The first had been taken for
    no nutation (the rounding of `f(1) = −(b − a)² = 0` gave `u₃ = 1`), the looping ones had NaN
    precession rates and angles (`F₊ Π(n₊)` at `n₊ = 1`). The last passes within 8e-6 rad of
    the upward vertical and 3e-6 of the hanging one: ψ's step there had taken the rounding of
    `1 − u₂` (formed as a difference), 4e-6 rad, 7e-6 in Q."""
    from poinsot.rotation import body_rates_from_euler

    angles, rates = np.array([0.3, theta0, -0.2]), np.array([0.0, thetadot, spin])
    w0 = (body_rates_from_euler(angles[None], rates[None]) @ TOP.frame().T)[0]
    Q0, t = matrix_from_euler(angles), np.linspace(0, 2, 81)
    exact = exact_motion(TOP, w0, Q0, t)
    ref = simulate(BODY, (0, 2), omega0=w0, Q0=Q0, pivot=PIVOT, forces=[Gravity()],
                   method="dop853", rtol=1e-13, atol=1e-15, t_eval=t)  # fmt: skip
    assert np.isfinite(exact.mean_precession_rate) and np.isfinite(exact.nutation_period)
    assert np.abs(exact.Q - ref.Q).max() < 5e-12
    assert np.abs(exact.omega - ref.omega).max() < 5e-12 * max(1.0, abs(thetadot))


def _roots_at_digits(theta0, rates):
    """The roots `u₁ ≤ u₂ ≤ u₃` of (T1) and `β`, at mpmath's working precision, from the double
    inputs θ₀ and `(ψ̇₀, θ̇₀, φ̇₀)` of `TOP` (Goldstein §5.7)."""
    import mpmath as mp

    A, C, mgl = (mp.mpf(v) for v in (TOP.A, TOP.C, TOP.mgl))
    th, pd, td, fd = (mp.mpf(v) for v in (theta0, *rates))
    u0, s2 = mp.cos(th), mp.sin(th) ** 2
    a, beta = C * (fd + pd * u0) / A, 2 * mgl / A
    b, alpha = pd * s2 + a * u0, beta * u0 + td**2 + pd**2 * s2
    cubic = [beta, -(alpha + a * a), 2 * a * b - beta, alpha - b * b]
    roots = sorted(mp.re(r) for r in mp.polyroots(cubic, maxsteps=800, extraprec=800))
    return roots, beta


@pytest.mark.parametrize(
    "theta0, rates",
    [(1.611, [3.12357268e-08, 6.08246667, -4.18428012e-04]),
     (3.088, [0.0, -8.43085224, 3.82955724e-05]),
     (0.799, [3.17499745e-10, 3.28015873, 2.07041846e-09])],
)  # fmt: skip
def test_near_its_separatrix_the_period_keeps_its_digits(theta0, rates):
    """Thrown almost hard enough to swing over the top (m1 = 3e-5, 6e-6, 2e-5), the upper roots
    u₂, u₃ of (T1) nearly meet: their separation is found about u = 1 (`upper_pair`), where
    Newton about u₀ had kept few digits of it (period 4e-9 and 5e-7 off). The nutation period
    2K(m)/λ within 1e-11 of mpmath's from the cubic's roots at 60 digits, from the same double
    inputs."""
    import mpmath as mp

    A, C, mgl = TOP.A, TOP.C, TOP.mgl
    _, summary = _core.heavy_top_motions(A, C, mgl, [[0.0, theta0, 0.0]], [rates], [0.0])
    with mp.workdps(60):
        (u1, u2, u3), beta = _roots_at_digits(theta0, rates)
        period = 2 * mp.ellipk((u2 - u1) / (u3 - u1)) / (mp.sqrt(beta * (u3 - u1)) / 2)
    assert summary[0, 3] == pytest.approx(float(period), rel=1e-11)


@pytest.mark.parametrize("offset", [1e-4, 1e-6])
def test_the_band_keeps_its_digits_by_the_upward_vertical(offset):
    """The band's upper edge θ_min (1.2e-6 and 1.2e-8 rad from the vertical here) within 1e-9
    (relative) of mpmath's `acos u₂` (roots at 50 digits from the same double inputs): it is
    taken from the gap `1 − u₂` itself (the cubic's value at 1), where `arccos` of `u₂` had
    kept few digits (7e-5 relative at 1.2e-6 rad)."""
    import mpmath as mp

    th0, spin = 0.3, 5.0
    A, C, mgl = TOP.A, TOP.C, TOP.mgl
    u0, s2 = np.cos(th0), np.sin(th0) ** 2
    psid = C * spin / A * (1 - u0) / s2 * (1 + offset)
    thd = -2 * np.sqrt(2 * mgl / A * (1 - u0) + 1.0)
    angles, rates = [0.0, th0, 0.0], [psid, thd, spin - psid * u0]
    _, summary = _core.heavy_top_motions(A, C, mgl, [angles], [rates], [0.0])
    with mp.workdps(50):
        (u1, u2, _), _ = _roots_at_digits(th0, rates)
        theta_min, theta_max = float(mp.acos(u2)), float(mp.acos(u1))
    assert summary[0, 7] == pytest.approx(theta_min, rel=1e-9)
    assert summary[0, 8] == pytest.approx(theta_max, rel=1e-13)


def test_exact_motion_is_top_motion_field_by_field():
    """A fast top simulated by DOP853 (rtol 1e-13) and by exact-splitting6, and its closed
    form: θ, ψ, φ, Q, ω agree sample by sample; the band and rate agree with the samples'."""
    Q0 = matrix_from_euler([0.2, 0.6, 0.0])
    w0 = np.array([0.3, 1.5, 100.0])
    t = np.linspace(0, 2, 101)
    exact = exact_motion(TOP, w0, Q0, t)
    for method, kw, tol in (("dop853", dict(rtol=1e-13, atol=1e-15), 1e-10),
                            ("exact-splitting6", dict(dt=0.002), 1e-8)):  # fmt: skip
        traj = simulate(BODY, (0, 2), omega0=w0, Q0=Q0, pivot=PIVOT, forces=[Gravity()],
                        method=method, t_eval=t, **kw)  # fmt: skip
        sim = top_motion(traj, TOP)
        for field in ("theta", "psi", "phi", "Q", "omega"):
            np.testing.assert_allclose(getattr(exact, field), getattr(sim, field), rtol=0,
                                       atol=tol, err_msg=f"{method} {field}")  # fmt: skip
        assert exact.spin == pytest.approx(sim.spin, rel=1e-13)
    assert exact.theta_band[0] <= exact.theta.min() and exact.theta.max() <= exact.theta_band[1]
    assert exact.mean_precession_rate == pytest.approx(sim.mean_precession_rate, rel=1e-2)
    assert np.isfinite(exact.nutation_period) and np.isnan(sim.nutation_period)


def test_vectorised_over_initial_conditions():
    rng = np.random.default_rng(3)
    w0 = np.column_stack([rng.normal(0, 1, 5), rng.normal(0, 1, 5), 50 + 10 * rng.random(5)])
    Q0 = matrix_from_euler(np.column_stack([rng.random(5), 0.3 + rng.random(5), rng.random(5)]))
    t = np.linspace(0, 1, 7)
    many = exact_motion(TOP, w0, Q0, t)
    assert len(many) == 5
    for k in range(5):
        one = exact_motion(TOP, w0[k], Q0[k], t)
        np.testing.assert_array_equal(one.Q, many[k].Q)
        assert one.nutation_period == many[k].nutation_period


def test_sleeping_top_stability_criterion():
    """Tilted by 1e-4 rad, a top spinning above ω₃² = 4 M g l A / C² stays within a few times
    its tilt (its turning points the double root at u = 1); below it falls far (Goldstein
    §5.7)."""
    critical = np.sqrt(4 * TOP.mgl * TOP.A / TOP.C**2)
    Q0 = matrix_from_euler([0.0, 1e-4, 0.0])
    fast = exact_motion(TOP, (0.0, 0.0, 1.2 * critical), Q0, [0.0])
    slow = exact_motion(TOP, (0.0, 0.0, 0.8 * critical), Q0, [0.0])
    assert fast.theta_band[1] < 1e-3
    assert slow.theta_band[1] > 0.3


def test_steady_precession_has_no_nutation():
    """Started at the slow steady rate (θ̇ = 0), θ stays where it is and ψ turns at that rate."""
    theta0, spin = 0.7, 80.0
    slow, _ = steady_precession_rates(TOP.A, TOP.C, TOP.mgl, theta0, spin)
    angles = [0.0, theta0, 0.0]
    rates = [slow, 0.0, spin - slow * np.cos(theta0)]
    motion, summary = _core.heavy_top_motions(TOP.A, TOP.C, TOP.mgl, [angles], [rates],
                                              np.linspace(0, 3, 31))  # fmt: skip
    assert np.abs(motion[0, :, 1] - theta0).max() < 1e-12
    assert summary[0, 4] == pytest.approx(slow, rel=1e-12)


def test_bad_input_is_refused_by_name():
    with pytest.raises(ValueError, match="`mgl` must be a positive number"):
        _core.heavy_top_motions(1.0, 1.0, -1.0, [[0, 1, 0]], [[0, 0, 1]], [0.0])
    with pytest.raises(ValueError, match=r"`rates\[0\]` must be finite"):
        _core.heavy_top_motions(1.0, 1.0, 1.0, [[0, 1, 0]], [[np.nan, 0, 1]], [0.0])
    with pytest.raises(ValueError, match=r"`Q0` puts the top's axis on the vertical"):
        exact_motion(TOP, (0, 0, 50.0), np.eye(3), [0.0])
    # in a batch, the member is named
    Q0 = np.stack([matrix_from_euler([0.0, 0.5, 0.0]), np.eye(3)])
    with pytest.raises(ValueError, match=r"`Q0\[1\]` puts the top's axis on the vertical"):
        exact_motion(TOP, np.tile((0, 0, 50.0), (2, 1)), Q0, [0.0])


def test_exact_grading_of_a_top_ensemble():
    """An ensemble of tops is graded against each member's closed form: exact-splitting6 at a
    step of 4 ms to round-off level, RKMK4 at 1 ms to its truncation error."""
    from poinsot.ensemble import simulate_ensemble

    rng = np.random.default_rng(0)
    n = 12
    w0 = np.column_stack([rng.normal(0, 1, n), rng.normal(0, 1, n), 80 + 10 * rng.random(n)])
    Q0 = matrix_from_euler(np.column_stack([rng.random(n), 0.3 + rng.random(n), rng.random(n)]))
    errors = {}
    for method, dt in (("exact-splitting6", 4e-3), ("rkmk4", 1e-3)):
        result = simulate_ensemble(BODY, (0, 2), omega0=w0, Q0=Q0, pivot=PIVOT,
                                   forces=[Gravity()], method=method, dt=dt,
                                   t_eval=np.linspace(0, 2, 11), progress=False)  # fmt: skip
        errors[method] = result.exact_errors()
    assert errors["exact-splitting6"]["omega"].max() < 1e-10
    assert errors["exact-splitting6"]["attitude"].max() < 1e-10
    assert errors["rkmk4"]["omega"].max() > 1e-6  # a real error, measured


def test_the_tops_functions_refuse_what_is_not_a_top_or_a_rotation():
    """`top` must be what heavy_top returns (None for any other body); `Q0` a rotation, as
    `simulate` requires (a sheared matrix had been taken as it was), named with its member."""
    from poinsot.tops import exact_derivatives

    Q0 = matrix_from_euler([0.0, 0.6, 0.0])
    w0 = (0.0, 0.0, 100.0)
    sheared = Q0.copy()
    sheared[0, 1] += 0.3
    for call in (lambda Q: exact_motion(TOP, w0, Q, [0.0]),
                 lambda Q: exact_derivatives(TOP, w0, Q, [0.0])):  # fmt: skip
        with pytest.raises(ValueError, match="`Q0` is not a rotation"):
            call(sheared)
    with pytest.raises(ValueError, match=r"`Q0\[1\]` is not a rotation"):
        exact_motion(TOP, np.array([w0, w0]), np.array([Q0, sheared]), [0.0])
    not_a_top = heavy_top(RigidBody.box(1.0, (1, 2, 3)), PIVOT, [Gravity()])
    assert not_a_top is None
    for call in (lambda: exact_motion(not_a_top, w0, Q0, [0.0]),
                 lambda: exact_derivatives(not_a_top, w0, Q0, [0.0])):  # fmt: skip
        with pytest.raises(TypeError, match="`top` must be the HeavyTop"):
            call()
    traj = simulate(BODY, (0, 1), omega0=w0, Q0=Q0, pivot=PIVOT, forces=[Gravity()], t_eval=[])
    with pytest.raises(ValueError, match="`traj` has no samples"):
        top_motion(traj, TOP)
    with pytest.raises(TypeError, match="`top` must be the HeavyTop"):
        top_motion(traj, None)


def test_no_times_give_empty_results_and_unresolved_times_are_refused():
    """No sample times: empty fields, the constants of the motion still there (as every closed
    form, docs/reliability.md); times where the phase exceeds 2⁵² rad: refused by name."""
    Q0 = matrix_from_euler([0.0, 0.6, 0.0])
    empty = exact_motion(TOP, (0.0, 0.0, 100.0), Q0, [])
    assert empty.theta.shape == (0,) and empty.Q.shape == (0, 3, 3)
    assert empty.omega.shape == (0, 3) and np.isnan(empty.theta_mean)
    assert empty.nutation_period == pytest.approx(0.433236, rel=1e-6)
    with pytest.raises(ValueError, match="`t` reaches 1e\\+16 s"):
        exact_motion(TOP, (0.0, 0.0, 100.0), Q0, [0.0, 1e16])
    # and so are its derivatives' (they had given numbers at t = 1e14, a phase of 6e15 rad)
    from poinsot.tops import exact_derivatives

    with pytest.raises(ValueError, match=r"`t` reaches 1e\+14 s.*beyond 2⁵² rad"):
        exact_derivatives(TOP, (0.1, 0.0, 100.0), Q0, [0.0, 1e14])


def test_a_top_built_by_hand_is_checked():
    from poinsot.tops import HeavyTop

    top = HeavyTop(TOP.A, TOP.C, TOP.mgl, TOP.axis, TOP.up, TOP.length)
    assert top.mgl == TOP.mgl
    with pytest.raises(ValueError, match=r"`HeavyTop\.axis` must be a unit vector"):
        HeavyTop(TOP.A, TOP.C, TOP.mgl, 2 * TOP.axis, TOP.up, TOP.length)
    with pytest.raises(ValueError, match=r"`HeavyTop\.mgl` must be positive"):
        HeavyTop(TOP.A, TOP.C, -1.0, TOP.axis, TOP.up, TOP.length)
    with pytest.raises(ValueError, match=r"`HeavyTop\.up` must be 3 finite numbers"):
        HeavyTop(TOP.A, TOP.C, TOP.mgl, TOP.axis, (0.0, np.nan, 1.0), TOP.length)
