"""FreeRigidBody: exact solution against DOP853, mpmath and differentiation; fixed points."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from poinsot import RigidBody, simulate
from poinsot._core import exp_so3, vee
from poinsot.torquefree import FreeRigidBody

I123 = (1.0, 2.0, 3.0)
T30 = np.linspace(0, 30, 601)


def _reference(moments, omega0, t, Q0=None):
    body = RigidBody(1.0, np.diag(moments))
    return simulate(body, (0, t[-1]), omega0=omega0, Q0=Q0, rtol=2.5e-14, atol=1e-15, t_eval=t)


def _mp_flip_interval(I, w):
    """Independent high-precision route (mpmath, 40 digits) to 2K(m)/λ."""
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 40
    I1, I2, I3 = (mp.mpf(str(x)) for x in I)
    w1, w2, w3 = (mp.mpf(str(x)) if not isinstance(x, mp.mpf) else x for x in w)
    P3 = I1 * (I3 - I1) * w1**2 + I2 * (I3 - I2) * w2**2
    P1 = I2 * (I2 - I1) * w2**2 + I3 * (I3 - I1) * w3**2
    D2 = I3 * (I3 - I2) * w3**2 - I1 * (I2 - I1) * w1**2
    if D2 > 0:
        lam, m = mp.sqrt((I3 - I2) * P1 / (I1 * I2 * I3)), (I2 - I1) * P3 / ((I3 - I2) * P1)
    else:
        lam, m = mp.sqrt((I2 - I1) * P3 / (I1 * I2 * I3)), (I3 - I2) * P1 / ((I2 - I1) * P3)
    return float(2 * mp.ellipk(m) / lam)


@pytest.mark.parametrize("seed", range(6))
def test_exact_omega_against_dop853_both_regimes(seed):
    rng = np.random.default_rng(seed)
    fb = FreeRigidBody(I123)
    omega0 = rng.normal(size=3)
    if seed % 2:  # force the other regime: dominant e1 or e3 component
        omega0[0] *= 3
    else:
        omega0[2] *= 3
    ref = _reference(I123, omega0, T30)
    assert np.abs(fb.exact_omega(omega0, T30) - ref.omega).max() <= 1e-10
    assert np.abs(fb.exact_attitude(omega0, T30) - ref.Q).max() <= 1e-10


def test_both_regimes_are_exercised():
    fb = FreeRigidBody(I123)
    assert fb.classify((2.0, 0.5, 0.1)) == "around e1"
    assert fb.classify((0.1, 0.5, 2.0)) == "around e3"
    assert fb.classify((0.0, 1.0, 0.0)) == "fixed point"
    k, a = fb.invariants(fb.point_on_polhode(0.5, math.sqrt(2 * 0.5 * 2.0)))
    assert a * a / (2 * k) == pytest.approx(2.0)


def test_flip_interval_textbook_values():
    fb = FreeRigidBody(I123)
    w0 = (1e-3, 1.0, 1e-3)
    flip = fb.flip_interval(w0)
    # value given in the issue (8 digits) and the mpmath route (13 digits)
    assert flip == pytest.approx(27.530840553491, rel=1e-8)
    assert flip == pytest.approx(_mp_flip_interval(I123, w0), rel=1e-13)
    # sign changes of ω2 in the numerical solution are 27.5308 apart
    t = np.linspace(0, 90, 90001)
    ref = _reference(I123, w0, t)
    w2 = ref.omega[:, 1]
    i = np.nonzero(np.diff(np.sign(w2)) != 0)[0]
    crossings = t[i] - w2[i] * (t[i + 1] - t[i]) / (w2[i + 1] - w2[i])
    assert len(crossings) >= 3
    np.testing.assert_allclose(np.diff(crossings), 27.5308, atol=1e-4)
    # tennis racket (Ashbaugh, Chicone & Cushman 1991 data): I in kg m², ω in rad/s
    racket = FreeRigidBody((0.00121, 0.01638, 0.01748))
    assert racket.flip_interval((0.01, 2 * np.pi, 0.01)) == pytest.approx(3.3357687, abs=5e-8)


def test_near_separatrix_flip_interval_and_omega():
    fb = FreeRigidBody(I123)
    w0 = (1e-7, 1.0, 1e-7)
    flip = fb.flip_interval(w0)
    assert math.isfinite(flip)
    assert flip == pytest.approx(_mp_flip_interval(I123, w0), rel=1e-12)
    # ω(t) against DOP853 while the unstable numerical error stays small (σ t ≲ 11)
    t = np.linspace(0, 18, 361)
    ref = _reference(I123, w0, t)
    assert np.abs(fb.exact_omega(w0, t) - ref.omega).max() < 1e-8
    # and the solution is periodic with the flip structure: ω2(t0 + flip) = −ω2(t0)
    w = fb.exact_omega(w0, [0.0, flip, 2 * flip])
    np.testing.assert_allclose(w[1], w[0] * [-1, -1, 1], atol=1e-9)
    np.testing.assert_allclose(w[2], w[0], atol=1e-9)


def test_separatrix_itself():
    fb = FreeRigidBody(I123)
    w0 = fb.point_on_polhode(0.5, math.sqrt(2 * 0.5 * 2.0))
    assert fb.classify(w0) == "separatrix"
    assert fb.flip_interval(w0) == math.inf
    assert fb.period(w0) == math.inf
    t = np.linspace(0, 10, 101)
    ref = _reference(I123, w0, t)
    assert np.abs(fb.exact_omega(w0, t) - ref.omega).max() < 1e-8
    w = fb.exact_omega(w0, [200.0])[0]  # tends to the unstable axis e2 (on the ellipsoid k=½)
    np.testing.assert_allclose(np.abs(w), [0, math.sqrt(0.5), 0], atol=1e-12)
    for s1, s3 in ((1, -1), (-1, 1), (-1, -1)):  # the four separatrix arcs
        w_arc = np.asarray(w0) * [s1, 1, s3]
        ref = _reference(I123, w_arc, t)
        assert np.abs(fb.exact_omega(w_arc, t) - ref.omega).max() < 1e-8
        assert np.abs(fb.exact_attitude(w_arc, t) - ref.Q).max() < 1e-8


@given(
    hnp.arrays(float, 3, elements=st.floats(-2, 2)).filter(lambda w: np.linalg.norm(w) > 0.1),
    st.floats(0.0, 20.0),
)
@settings(max_examples=40, deadline=None)
def test_exact_attitude_conserves_L_and_satisfies_kinematics(omega0, t0):
    fb = FreeRigidBody((1.0, 2.5, 3.0))
    Q0 = exp_so3([0.3, -0.2, 0.5])
    t = np.array([t0])
    h = 1e-5
    Q = fb.exact_attitude(omega0, t, Q0)[0]
    w = fb.exact_omega(omega0, t)[0]
    L0 = Q0 @ fb.inertia @ omega0
    np.testing.assert_allclose(Q @ fb.inertia @ w, L0, atol=1e-11 * max(1, np.abs(L0).max()))
    dQ = fb.exact_attitude(omega0, t + h, Q0)[0] - fb.exact_attitude(omega0, t - h, Q0)[0]
    omega_fd = vee(Q.T @ dQ / (2 * h))
    np.testing.assert_allclose(omega_fd, w, atol=1e-7 * max(1, np.abs(w).max() ** 3))
    np.testing.assert_allclose(Q.T @ Q, np.eye(3), atol=1e-13)


def test_a_subnormal_component_is_zero_to_round_off():
    # ω = (2.2e-313, 0, 1/8) is the steady spin about e3 to within 1e-312: the closed forms
    # give that rotation to round-off (they used to work with the subnormal's few digits and
    # landed 3e-11 off), and ω(t) stays on the axis; a relatively tiny normal component keeps
    # its own, physical, motion
    fb = FreeRigidBody((1.0, 2.5, 3.0))
    Q0 = exp_so3([0.3, -0.2, 0.5])
    t = np.array([-1e-5, 1e-5, 1.0, 7.0])
    for w0 in ([2.22507386e-313, 0.0, 0.125], [0.0, -3e-320, 0.125], [-1e-310, 1e-315, 0.125]):
        Q = fb.exact_attitude(w0, t, Q0)
        for Qk, tk in zip(Q, t, strict=True):
            c, s = math.cos(0.125 * tk), math.sin(0.125 * tk)
            ref = Q0 @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
            assert np.abs(Qk - ref).max() < 4e-16, (w0, tk)
        np.testing.assert_array_equal(np.abs(fb.exact_omega(w0, t)), [[0.0, 0.0, 0.125]] * 4)
    w = fb.exact_omega([1e-200, 0.0, 0.125], [1.0])[0]
    assert 0 < np.abs(w[:2]).max() < 1e-199


@pytest.mark.parametrize(
    "moments", [(1.0, 1.0, 2.0), (2.0, 1.0, 1.0), (1.5, 1.5, 1.5), (3.0, 1.0, 2.0)]
)
def test_symmetric_spherical_and_permuted_bodies(moments):
    fb = FreeRigidBody(moments)
    rng = np.random.default_rng(3)
    omega0 = rng.normal(size=3)
    Q0 = exp_so3(rng.normal(size=3))
    t = np.linspace(0, 20, 201)
    ref = _reference(moments, omega0, t, Q0)
    assert np.abs(fb.exact_omega(omega0, t) - ref.omega).max() < 1e-10
    assert np.abs(fb.exact_attitude(omega0, t, Q0) - ref.Q).max() < 1e-10


def test_from_body_maps_frames():
    body = RigidBody.box(3.0, (1.0, 2.0, 0.5), orientation=exp_so3([0.4, 0.1, -0.7]))
    fb = FreeRigidBody.from_body(body)
    omega0 = np.array([0.3, -1.0, 0.8])
    t = np.linspace(0, 10, 51)
    ref = simulate(body, (0, 10), omega0=omega0, rtol=2.5e-14, atol=1e-15, t_eval=t)
    assert np.abs(fb.exact_omega(omega0, t) - ref.omega).max() < 1e-10
    assert np.abs(fb.exact_attitude(omega0, t) - ref.Q).max() < 1e-10
    errors = fb.trajectory_error(ref)
    assert errors["omega"] < 1e-10 and errors["attitude"] < 1e-10
    rk = simulate(body, (0, 10), omega0=omega0, method="rk4", dt=0.05, t_eval=t)
    assert fb.trajectory_error(rk)["omega"] > 1e-8  # the oracle sees RK4's error


def test_fixed_points_and_stability_three_cases():
    fb = FreeRigidBody(I123)
    pts = fb.fixed_points()
    assert [p.stable for p in pts] == [True, False, True]
    w = 2.0
    s2 = fb.stability((0, w, 0))
    assert s2.kind == "saddle" and not s2.stable
    sigma = w * math.sqrt((2 - 1) * (3 - 2) / (1 * 3))
    assert s2.growth_rate == pytest.approx(sigma)
    assert np.sort(s2.eigenvalues.real)[[0, 2]] == pytest.approx([-sigma, sigma])
    s1 = fb.stability((w, 0, 0))
    assert s1.kind == "center" and s1.stable
    assert s1.wobble_frequency == pytest.approx(w * math.sqrt(1 * 2 / (2 * 3)))
    assert np.abs(s1.eigenvalues.imag).max() == pytest.approx(s1.wobble_frequency)
    s3 = fb.stability((0, 0, w))
    assert s3.wobble_frequency == pytest.approx(w * math.sqrt(2 * 1 / (1 * 2)))
    # the wobble frequency is the frequency of ω near e3 (exact solution)
    near = (1e-4, 1e-4, w)
    assert fb.period(near) == pytest.approx(2 * math.pi / s3.wobble_frequency, rel=1e-6)
    # growth on e2: the exact solution departs at rate σ
    w_t = fb.exact_omega((1e-9, w, 1e-9), [0.0, 5.0])
    assert abs(w_t[1, 0]) / 1e-9 == pytest.approx(math.exp(sigma * 5) * 0.5, rel=0.6)

    oblate = FreeRigidBody((1.0, 1.0, 2.0))
    kinds = [(p.kind, p.stable) for p in oblate.fixed_points()]
    assert kinds == [("plane", False), ("axis", True)]
    assert oblate.stability((1.0, 0.5, 0.0)).kind == "degenerate"
    assert oblate.stability((0.0, 0.0, 1.0)).kind == "center"

    prolate = FreeRigidBody((1.0, 2.0, 2.0))
    assert [(p.kind, p.stable) for p in prolate.fixed_points()] == [
        ("axis", True),
        ("plane", False),
    ]
    sphere = FreeRigidBody((1.0, 1.0, 1.0))
    (allpts,) = sphere.fixed_points()
    assert allpts.kind == "all" and sphere.stability((0.3, 0.2, 0.1)).kind == "trivial"
    with pytest.raises(ValueError, match="is not a fixed point"):
        fb.stability((1.0, 1.0, 0.0))


def test_fixed_point_motion_rodrigues_vs_jordan():
    fb = FreeRigidBody(I123)
    t = np.linspace(0, 7, 15)
    w = (0.0, 0.0, 1.3)
    a = fb.fixed_point_attitude(w, t)
    b = fb.fixed_point_attitude(w, t, method="jordan")
    np.testing.assert_allclose(a, b, atol=1e-14)
    np.testing.assert_allclose(fb.exact_attitude(w, t), a, atol=1e-14)
    sphere = FreeRigidBody((2.0, 2.0, 2.0))
    w = np.array([0.3, -0.5, 0.9])
    np.testing.assert_allclose(
        sphere.fixed_point_attitude(w, t, method="jordan"),
        sphere.fixed_point_attitude(w, t),
        atol=1e-14,
    )


def test_invariants_cone_and_feasibility():
    fb = FreeRigidBody(I123)
    w = np.array([0.3, -0.4, 0.5])
    k, a = fb.invariants(w)
    assert 2 * k == pytest.approx(np.sum(np.array(I123) * w**2))
    assert a * a == pytest.approx(np.sum((np.array(I123) * w) ** 2))
    b = fb.cone_coefficients(k, a)
    assert b @ w**2 == pytest.approx(0, abs=1e-14)  # ω on the cone (32)
    assert w @ fb.cone_matrix(k, a) @ w == pytest.approx(0, abs=1e-14)
    with pytest.raises(
        ValueError,
        match=r"I1 ≤ a²/\(2k\) ≤ I3 \(33\), found I1 = 1, "
        r"a²/\(2k\) = 4, I3 = 3",
    ):
        fb.cone_coefficients(0.5, 2.0)
    with pytest.raises(ValueError, match="`energy` must be a positive number"):
        fb.check_feasible(-1.0, 1.0)


def test_polhode_points_on_both_ellipsoids():
    fb = FreeRigidBody(I123)
    I = np.array(I123)
    for family in fb.polhode_family(energy=0.5, levels=7, n=300):
        p = family.points
        np.testing.assert_allclose(0.5 * (I * p * p).sum(1), 0.5, atol=1e-12)
        np.testing.assert_allclose(np.sqrt(((I * p) ** 2).sum(1)), family.momentum, atol=1e-12)
    names = {f.family for f in fb.polhode_family(0.5)}
    assert names == {"around e1", "around e3", "separatrix", "fixed point"}
    closed = fb.polhode((0.2, 0.1, 0.5))
    np.testing.assert_allclose(closed.points[0], closed.points[-1], atol=1e-12)
    by_invariants = fb.polhode(energy=0.5, momentum=math.sqrt(2 * 0.5 * 2.5))
    assert by_invariants.family == "around e3"
    with pytest.raises(ValueError, match="give `omega0`, or both"):
        fb.polhode(energy=0.5)


def test_herpolhode_lies_in_the_invariable_plane():
    fb = FreeRigidBody(I123)
    w0 = np.array([0.4, 0.7, 0.5])
    k, a = fb.invariants(w0)
    h = fb.herpolhode(w0, np.linspace(0, 20, 201))
    np.testing.assert_allclose(h[:, 2], 2 * k / a, atol=1e-12)


def test_period_and_flip_errors():
    fb = FreeRigidBody(I123)
    with pytest.raises(ValueError, match="fixed point: ω2 never changes sign"):
        fb.flip_interval((0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="has no period"):
        fb.period((1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="needs three distinct `moments`; this body is oblate"):
        FreeRigidBody((1, 1, 2)).flip_interval((0.1, 0.2, 1.0))
    assert FreeRigidBody((1, 1, 2)).period((0.1, 0.2, 1.0)) == pytest.approx(2 * math.pi)


@pytest.mark.parametrize(
    ("moments", "match"),
    [
        ((1.0, 2.0), r"`moments` must have shape \(3,\)"),
        ((1.0, 0.0, 1.0), r"`moments\[1\]` must be positive"),
        ((1.0, 1.0, 3.0), r"I1 \+ I2 ≥ I3"),
        ((1.0, np.nan, 1.0), r"`moments\[1\]` must be finite"),
    ],
)
def test_bad_moments(moments, match):
    with pytest.raises(ValueError, match=match):
        FreeRigidBody(moments)


def test_degenerate_body_refused():
    with pytest.raises(ValueError, match="degenerate"):
        FreeRigidBody.from_body(RigidBody.rod(1.0, 1.0))


@pytest.mark.parametrize("tiny", [1e-7, 1e-12, 1e-20, 1e-155])
def test_attitude_kinematics_while_lingering_by_the_unstable_axis(tiny):
    """Regression: ψ(t) used Π(n; am u), and am rounds to ±π/2 near the unstable axis."""
    fb = FreeRigidBody((1.0, 2.0, 3.0))
    w0 = np.array([tiny, 1.0, 2 * tiny])
    t = np.linspace(0.0, 40.0, 9)
    Q = fb.exact_attitude(w0, t)
    w = fb.exact_omega(w0, t)
    # 4th-order stencil, h = 1e-3: truncation ~h⁴, and the ~1e-12 absolute error of the
    # elliptic functions is divided by h only once
    h = 1e-3

    def at(dt):
        return fb.exact_attitude(w0, t + dt)

    dQ = (at(-2 * h) - 8 * at(-h) + 8 * at(h) - at(2 * h)) / (12 * h)
    omega_fd = vee(np.einsum("nji,njk->nik", Q, dQ))
    np.testing.assert_allclose(omega_fd, w, atol=1e-8)
    ref = _reference((1.0, 2.0, 3.0), w0, np.linspace(0, 15, 16))
    assert np.abs(fb.exact_attitude(w0, ref.t) - ref.Q).max() < 1e-10
    L = np.einsum("nij,nj->ni", Q, w * [1.0, 2.0, 3.0])
    np.testing.assert_allclose(L, np.tile(L[0], (len(t), 1)), atol=1e-12)


def test_describe_summarises_the_motion():
    fb = FreeRigidBody(I123)
    d = fb.describe((1e-3, 1.0, 1e-3))
    assert d["family"] == "around e3"
    assert d["flip_interval"] == pytest.approx(27.530840553733, rel=1e-12)
    assert d["period"] == pytest.approx(2 * d["flip_interval"])
    assert "flip_interval" not in fb.describe((0.0, 0.0, 1.0))  # fixed point: undefined
    sep = fb.describe(fb.point_on_polhode(0.5, math.sqrt(2 * 0.5 * 2.0)))
    assert sep["flip_interval"] == "inf"


@pytest.mark.parametrize("bad", [-1, 0, 5e-324, 2.5, True, "many", float("nan")])
def test_polhode_counts_are_checked_by_name(bad):
    """``levels`` and ``n`` are counts, refused by name (``levels=-1``, ``0`` and ``5e-324``
    drew the default ten curves)."""
    body = FreeRigidBody(I123)
    with pytest.raises(ValueError, match="`levels` must be an integer from 1 to 1000"):
        body.polhode_family(0.5, levels=bad)
    with pytest.raises(ValueError, match="`n` must be an integer from 2"):
        body.polhode_family(0.5, n=bad)
    w = body.point_on_polhode(0.5, 1.2)
    with pytest.raises(ValueError, match="`n` must be an integer from 2"):
        body.polhode(w, n=bad)
    # levels a²/2k = 4/3, 5/3 (around e1) and 2.5 (around e3), two branches each, the
    # separatrix's four arcs and the six fixed points
    family = body.polhode_family(0.5, levels=3)
    assert len(family) == 3 * 2 + 4 + 6
    kinds = [p.family for p in family]
    assert kinds.count("around e1") == 4 and kinds.count("around e3") == 2


def test_the_polhode_family_shows_both_families_of_a_tennis_racket():
    """Issue 43: with I2 within 7 % of I3 every level fell around e1, and a run around e3 had
    no curve of its own family on its figure. Half the levels go to each family."""
    racket = FreeRigidBody((0.00121, 0.01638, 0.01748))
    kinds = [p.family for p in racket.polhode_family(0.3, levels=9)]
    assert kinds.count("around e1") == 2 * 5 and kinds.count("around e3") == 2 * 4
