"""Jacobi functions and elliptic integrals in (m, m1) against scipy, mpmath and quadrature."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.special import ellipj, ellipkinc

from poinsot import elliptic
from poinsot._core import jacobi_sn_cn_dn_am

U = np.linspace(-25, 25, 1001)


@pytest.mark.parametrize("m", [0.0, 1e-6, 0.1, 0.5, 0.9, 0.999])
def test_agm_matches_scipy_ellipj(m):
    ours = jacobi_sn_cn_dn_am(U, m, 1 - m)
    theirs = ellipj(U, m)
    for a, b in zip(ours, theirs, strict=True):
        np.testing.assert_allclose(a, b, atol=5e-13, rtol=0)


@pytest.mark.parametrize("m1", [1e-8, 1e-12, 1e-14, 1e-20, 0.0])
def test_near_m_equal_one_against_mpmath(m1):
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 50
    u = np.array([0.3, 2.0, 9.0, 17.0, 23.0])
    m = 1 - m1
    sn, cn, dn = elliptic.jacobi(u, m, m1)
    mm = 1 - mp.mpf(m1)
    for i, ui in enumerate(u):
        ref = [float(mp.ellipfun(kind, mp.mpf(ui), m=mm)) for kind in ("sn", "cn", "dn")]
        # cn and dn down to 1e-10 keep ≥ 9 digits (the AGM's absolute error is ~eps·|u|);
        # sn keeps full precision
        np.testing.assert_allclose([sn[i], cn[i], dn[i]], ref, rtol=1e-9, atol=0)
        assert sn[i] == pytest.approx(ref[0], rel=1e-14)


def test_reduced_jacobi_keeps_relative_accuracy_at_quarter_periods():
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 60
    m1 = 1e-30
    K = elliptic.ellipk(m1)
    u = np.array([K - 0.5, K + 0.25, 3 * K - 1.0])
    sn, cn, dn = elliptic.jacobi(u, 1 - m1, m1)
    mm = 1 - mp.mpf(m1)
    Kmp = mp.ellipk(mm)
    for i, shift in enumerate([-0.5, 0.25, None]):
        um = (Kmp + shift) if shift is not None else 3 * Kmp - 1
        ref = [float(mp.ellipfun(k, um, m=mm)) for k in ("sn", "cn", "dn")]
        np.testing.assert_allclose([sn[i], cn[i], dn[i]], ref, rtol=1e-10, atol=1e-300)


@pytest.mark.parametrize("m", [0.2, 0.7, 1 - 1e-9])
def test_first_kind_and_inverse(m):
    m1 = 1 - m
    phi = np.linspace(-3 * np.pi, 3 * np.pi, 37)
    np.testing.assert_allclose(elliptic.ellipf(phi, m, m1), ellipkinc(phi, m), rtol=1e-12)
    for u in (-1.7, 0.4, 1.1, 2.5):
        sn, cn, _ = elliptic.jacobi(np.array([u]), m, m1)
        if abs(u) < 2 * elliptic.ellipk(m1):
            assert elliptic.first_kind_from_sn_cn(sn[0], cn[0], m, m1) == pytest.approx(u)


@pytest.mark.parametrize("m1", [0.8, 0.3, 1e-3, 1e-5, 1e-9, 1e-15, 1e-40])
def test_first_kind_from_sn_cn_against_mpmath(m1):
    """The inverse of (sn, cn) (Bulirsch's el1 on the AGM sequence) against mpmath's F(φ|m)
    at 80 digits (m = 1 − m1 keeps m1's digits), over the whole period (−2K, 2K], with tiny
    cn (φ by π/2, where the body lingers by its unstable axis) and tiny sn: within 3 eps of
    K + |u|."""
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 80
    m = 1 - m1
    mm = 1 - mp.mpf(m1)
    K = elliptic.ellipk(m1)
    phis = list(np.linspace(-np.pi, np.pi, 41)[1:])
    for tiny in (1e-300, 1e-17, 1e-9):
        phis += [np.pi / 2 - tiny, np.pi / 2 + tiny, -np.pi / 2 + tiny, tiny, -tiny, np.pi - tiny]
    for phi in phis:
        s, c = math.sin(phi), math.cos(phi)
        # the exact u of these two doubles: F of the reduced amplitude, on c's branch
        f = mp.ellipf(mp.atan(abs(mp.mpf(s)) / abs(mp.mpf(c))), mm) if c else mp.ellipk(mm)
        ref = math.copysign(1, s) * (f if c >= 0 else 2 * mp.ellipk(mm) - f)
        got = elliptic.first_kind_from_sn_cn(s, c, m, m1)
        assert abs(got - float(ref)) <= 3 * 2.2e-16 * (K + abs(float(ref))), (phi, got, ref)


@pytest.mark.parametrize(("n", "m"), [(-0.5, 0.3), (-3.0, 0.8), (-1.5, 1 - 1e-10), (-2.0, 1.0)])
def test_third_kind_in_u_against_quadrature(n, m):
    m1 = 1 - m

    def sn(x):
        return elliptic.jacobi(np.array([x]), m, m1)[0][0]

    for u in (0.3, 2.0, 7.5, -4.0):
        ref, _ = quad(
            lambda x: 1.0 / (1 - n * sn(x) ** 2), 0, u, epsabs=1e-13, epsrel=1e-13, limit=200
        )
        assert elliptic.third_kind_u(n, u, m, m1) == pytest.approx(ref, rel=1e-10, abs=1e-12)


def test_third_kind_incomplete_and_complete():
    n, m = -0.7, 0.4
    phi = 1.2
    ref, _ = quad(
        lambda t: 1 / ((1 - n * np.sin(t) ** 2) * np.sqrt(1 - m * np.sin(t) ** 2)),
        0,
        phi,
        epsabs=1e-14,
    )
    assert elliptic.ellippi(n, phi, m, 1 - m) == pytest.approx(ref, rel=1e-12)
    full, _ = quad(
        lambda t: 1 / ((1 - n * np.sin(t) ** 2) * np.sqrt(1 - m * np.sin(t) ** 2)),
        0,
        np.pi / 2,
        epsabs=1e-14,
    )
    assert elliptic.ellippi_complete(n, m, 1 - m) == pytest.approx(full, rel=1e-12)
    assert elliptic.ellippi(n, phi + 2 * np.pi, m, 1 - m) == pytest.approx(ref + 4 * full)
    with pytest.raises(ValueError, match="`n` must be < 1"):
        elliptic.ellippi(1.5, 0.3, m, 1 - m)


@settings(max_examples=60, deadline=None)
@given(
    log_n=st.floats(-1.0, 17.0),
    m=st.floats(0.0, 0.999999),
    phi=st.floats(-7.0, 7.0).filter(lambda x: abs(x) > 1e-6),
)
def test_third_kind_keeps_its_digits_for_large_negative_n(log_n, m, phi):
    """Π(n; φ | m) and Π(n | m) for n from −0.1 to −1e17 within 2e-15 of mpmath (30 digits).
    Below n = −1 the direct form `s R_F + (n/3) s³ R_J` cancels to O(|n|^−½): it had lost
    √|n| of its relative accuracy (7e-9 at n = −1e13); DLMF 19.7.9 keeps them. Beyond
    |φ| = π/2 the reduction `φ − jπ` rounds by up to 2e-16 rad where the integrand is 1."""
    import mpmath as mp

    n = -(10.0**log_n)
    with mp.workdps(30):
        ref = mp.ellippi(n, phi, m)
        full = mp.ellippi(n, m)
    reduction = 2e-16 if abs(phi) > np.pi / 2 else 0.0
    assert abs(elliptic.ellippi(n, phi, m, 1 - m) - ref) <= 2e-15 * abs(ref) + reduction
    assert abs(elliptic.ellippi_complete(n, m, 1 - m) - full) <= 2e-15 * abs(full)


@pytest.mark.parametrize("m1", [1e-20, 1e-31, 1e-33, 1e-80, 1.2e-158])
def test_third_kind_derivative_near_quarter_period_for_tiny_m1(m1):
    """Regression: d/du ∫ du/(1 − n sn²) must be 1/(1 − n sn²) around u = K as m1 → 0."""
    n, m = -9.0, 1 - m1
    K = elliptic.ellipk(m1)
    for u in (K - 2.0, K - 0.3, K, K + 0.7, 0.5 * K, 1.5 * K, 3 * K + 0.1):
        h = 1e-4
        d = elliptic.third_kind_u(n, u + h, m, m1) - elliptic.third_kind_u(n, u - h, m, m1)
        sn = elliptic.jacobi(np.array([u]), m, m1)[0][0]
        assert d / (2 * h) == pytest.approx(1 / (1 - n * sn**2), rel=1e-6)
