"""Exact torque-free solutions for arrays of initial conditions (N, 3).

Independent routes: the same closed form for one member at a time (the vectorised kernels
must equal the scalar calls exactly), DOP853 at tight tolerance, the scale invariance of
Euler's equation, and SciPy's Carlson integrals for the compiled R_F, R_J.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from poinsot import RigidBody, simulate
from poinsot import _core as ek
from poinsot._core import exp_so3
from poinsot.torquefree import FreeRigidBody

I123 = (1.0, 2.0, 3.0)
T = np.linspace(0.0, 12.0, 25)


def _mixed_members(rng, n=40):
    """Both polhode families, a separatrix member, fixed points on all three axes, zero."""
    W = rng.normal(size=(n, 3))
    W[::3, 0] *= 4.0  # around e1
    W[1::3, 2] *= 4.0  # around e3
    extra = np.array(
        [
            [0.0, 1.0, 0.0],  # unstable axis: fixed point
            [2.0, 0.0, 0.0],
            [0.0, 0.0, -1.5],
            [0.0, 0.0, 0.0],
            [math.sqrt(3.0 / 2.0), 1.0, math.sqrt(3.0 / 2.0) / math.sqrt(3.0)],
        ]
    )
    return np.vstack([W, extra])


@pytest.mark.parametrize("moments", [I123, (2.0, 2.0, 3.0), (1.0, 3.0, 3.0), (2.0, 2.0, 2.0)])
def test_vectorised_equals_one_member_at_a_time(moments):
    rng = np.random.default_rng(3)
    fb = FreeRigidBody(moments)
    W = _mixed_members(rng)
    omega = fb.exact_omega(W, T)
    Q0 = np.stack([exp_so3(rng.normal(size=3)) for _ in W])
    Q = fb.exact_attitude(W, T, Q0)
    assert omega.shape == (len(W), len(T), 3) and Q.shape == (len(W), len(T), 3, 3)
    k, a = fb.invariants(W)
    names = fb.classify(W)
    periods = fb.period(W)
    flips = fb.flip_interval(W)
    for i, w in enumerate(W):
        np.testing.assert_array_equal(omega[i], fb.exact_omega(w, T))
        np.testing.assert_array_equal(Q[i], fb.exact_attitude(w, T, Q0[i]))
        assert (k[i], a[i]) == fb.invariants(w)
        assert names[i] == fb.classify(w)
        for batch, scalar in ((periods, fb.period), (flips, fb.flip_interval)):
            try:
                expected = scalar(w)
            except ValueError:  # undefined for one member: NaN in the array
                assert math.isnan(batch[i])
            else:
                assert batch[i] == expected or (math.isinf(batch[i]) and math.isinf(expected))


def test_one_shared_attitude_and_identity_default():
    fb = FreeRigidBody(I123)
    W = np.array([[0.1, 1.0, 0.2], [1.0, 0.1, 0.3]])
    Q0 = exp_so3(np.array([0.3, -0.2, 0.5]))
    shared = fb.exact_attitude(W, T, Q0)
    each = fb.exact_attitude(W, T, np.stack([Q0, Q0]))
    np.testing.assert_array_equal(shared, each)
    at_zero = fb.exact_attitude(W, [0.0])[:, 0]
    np.testing.assert_allclose(at_zero, np.stack([np.eye(3)] * 2), rtol=0, atol=1e-15)


def test_vectorised_against_dop853():
    rng = np.random.default_rng(11)
    fb = FreeRigidBody(I123)
    W = _mixed_members(rng, n=6)[:6]
    omega = fb.exact_omega(W, T)
    Q = fb.exact_attitude(W, T)
    body = RigidBody(1.0, np.diag(I123))
    for i, w in enumerate(W):
        ref = simulate(body, (0, T[-1]), omega0=w, rtol=2.5e-14, atol=1e-15, t_eval=T)
        assert np.abs(omega[i] - ref.omega).max() <= 1e-10
        assert np.abs(Q[i] - ref.Q).max() <= 1e-10


def _landau_reference(moments, w, ts, mp):
    """ω(t) at 40 digits by Landau & Lifshitz, *Mechanics* §37, in mpmath (sorted moments,
    a member off the separatrix); and the rate λ of its argument."""
    I1, I2, I3 = (mp.mpf(x) for x in moments)
    w1, w2, w3 = (mp.mpf(x) for x in w)
    E2 = I1 * w1**2 + I2 * w2**2 + I3 * w3**2  # 2E
    M2 = (I1 * w1) ** 2 + (I2 * w2) ** 2 + (I3 * w3) ** 2
    a1 = mp.sqrt((E2 * I3 - M2) / (I1 * (I3 - I1)))
    a3 = mp.sqrt((M2 - E2 * I1) / (I3 * (I3 - I1)))
    if M2 > E2 * I2:  # around e3: (a1 cn, ±a2 sn, ±a3 dn), the signs of ω2 and ω3 tied
        a2 = mp.sqrt((E2 * I3 - M2) / (I2 * (I3 - I2)))
        lam = mp.sqrt((I3 - I2) * (M2 - E2 * I1) / (I1 * I2 * I3))
        m = (I2 - I1) * (E2 * I3 - M2) / ((I3 - I2) * (M2 - E2 * I1))
        sign, kinds, amps = mp.sign(w3), ("cn", "sn", "dn"), (a1, a2, a3)
        signs, c0 = (1, sign, sign), w1 / a1
    else:  # around e1: (±a1 dn, ±a2 sn, a3 cn)
        a2 = mp.sqrt((M2 - E2 * I1) / (I2 * (I2 - I1)))
        lam = mp.sqrt((I2 - I1) * (E2 * I3 - M2) / (I1 * I2 * I3))
        m = (I3 - I2) * (M2 - E2 * I1) / ((I2 - I1) * (E2 * I3 - M2))
        sign, kinds, amps = mp.sign(w1), ("dn", "sn", "cn"), (a1, a2, a3)
        signs, c0 = (sign, sign, 1), w3 / a3
    u0 = mp.ellipf(mp.atan2(w2 / (sign * a2), c0), m)
    rows = [
        [
            float(s * a * mp.ellipfun(k, u0 + lam * mp.mpf(t), m=m))
            for s, a, k in zip(signs, amps, kinds, strict=True)
        ]
        for t in ts
    ]
    return np.array(rows), float(lam)


def test_exact_omega_against_mpmath():
    """Members in SIMD lanes against Landau's solution at 40 digits (mpmath): the error is
    round-off, within 6 eps |ω0| (1 + λt) — the argument u = u0 + λt carries eps |u|."""
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 40
    rng = np.random.default_rng(5)
    W = rng.normal(size=(200, 3)) * np.exp(rng.normal(size=(200, 1)))
    W[::7, 1] *= 1e-6  # near the stable ends of the polhodes
    ts = np.array([0.0, 0.7, 3.0, 10.0, 31.0])
    fb = FreeRigidBody(I123)
    got = fb.exact_omega(W, ts)
    for i, w in enumerate(W):
        ref, lam = _landau_reference(I123, w, ts, mp)
        bound = 6 * 2.2e-16 * np.abs(w).max() * (1 + lam * ts)
        assert (np.abs(got[i] - ref).max(axis=1) <= bound).all(), (w, got[i] - ref)


# components are 0 or at least 1e-100, so that s ω0 stays representable for every s below
COMPONENT = st.floats(-2, 2).map(lambda x: x if abs(x) > 1e-100 else 0.0)


@settings(max_examples=40, deadline=None)
@given(
    st.tuples(*[COMPONENT for _ in range(3)]).filter(lambda w: np.linalg.norm(w) > 0.05),
    st.sampled_from([1e-150, 1e-8, 0.37, 5.0, 1e6, 1e150]),
    st.sampled_from([1e-30, 1.0, 7e20]),
)
def test_scale_invariance(omega0, s, c):
    """Euler's equation is invariant under ω → sω, t → t/s, and under I → cI: so
    ω(t; sω0) = s ω(st; ω0), Q(t; sω0) = Q(st; ω0) for any moments scaled by c."""
    w = np.asarray(omega0)
    base = FreeRigidBody(I123)
    scaled = FreeRigidBody(tuple(c * x for x in I123))
    t = T / s
    np.testing.assert_allclose(
        scaled.exact_omega(s * w, t) / s,
        base.exact_omega(w, T),
        rtol=1e-9,
        atol=1e-9 * abs(w).max(),
    )
    np.testing.assert_allclose(
        scaled.exact_attitude(s * w, t), base.exact_attitude(w, T), atol=1e-8
    )
    W = np.stack([w, 2 * w])
    np.testing.assert_allclose(
        scaled.flip_interval(s * W) * s, base.flip_interval(W), rtol=1e-12, equal_nan=True
    )


def test_components_near_the_underflow_threshold():
    """Regression: with ω ~ 1e-160 the squared components fell to subnormals and the family
    polynomials lost all their digits (a scaled invariant is now formed first)."""
    fb = FreeRigidBody(I123)
    w = np.array([0.3, 1.0, 0.2])
    for s in (1e-160, 1e-200, 1e160):
        np.testing.assert_allclose(
            fb.exact_omega(s * w, T / s) / s, fb.exact_omega(w, T), rtol=1e-12, atol=1e-13
        )
        assert fb.flip_interval(s * w) * s == pytest.approx(fb.flip_interval(w), rel=1e-13)
        assert fb.classify(s * w) == fb.classify(w) == "around e3"


def test_bad_member_arrays_named():
    fb = FreeRigidBody(I123)
    W = np.ones((4, 3))
    W[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"`omega0\[2\]\[1\]` must be finite"):
        fb.exact_omega(W, T)
    with pytest.raises(ValueError, match=r"`omega0` must have shape \(3,\) or \(N, 3\)"):
        fb.exact_omega(np.ones((4, 2)), T)
    Q0 = np.stack([np.eye(3)] * 4)
    Q0[3, 0, 0] = 2.0
    with pytest.raises(ValueError, match=r"`Q0\[3\]` is not a rotation"):
        fb.exact_attitude(np.ones((4, 3)), T, Q0)
    with pytest.raises(ValueError, match=r"`Q0` must be one rotation .*\(4, 3, 3\)"):
        fb.exact_attitude(np.ones((4, 3)), T, np.stack([np.eye(3)] * 3))


# --------------------------------------------------------------------------- Carlson integrals
scipy_special = pytest.importorskip("scipy.special")


@pytest.mark.parametrize("seed", range(4))
def test_carlson_rf_rj_against_scipy(seed):
    """Our domain: x, y in [0, 1], z = 1, p >= 1 (third kind with n < 0)."""
    rng = np.random.default_rng(seed)
    for _ in range(200):
        x, y = rng.uniform(0, 1, 2) ** rng.choice([1, 4])
        p = 1.0 + rng.exponential(3.0)
        assert ek.carlson_rf(x, y, 1.0) == pytest.approx(
            scipy_special.elliprf(x, y, 1.0), rel=4e-15
        )
        assert ek.carlson_rj(x, y, 1.0, p) == pytest.approx(
            scipy_special.elliprj(x, y, 1.0, p), rel=4e-15
        )


def test_complete_integrals_against_scipy():
    for m1 in (1e-300, 1e-12, 1e-3, 0.3, 1.0):
        assert ek.ellipk_m1(m1) == pytest.approx(scipy_special.ellipkm1(m1), rel=2e-15)
    for phi, m in ((0.4, 0.3), (1.5, 0.99), (7.0, 0.5), (-2.0, 0.1)):
        assert float(ek.ellipf(np.array([phi]), m, 1 - m)[0]) == pytest.approx(
            scipy_special.ellipkinc(phi, m), rel=4e-15
        )
