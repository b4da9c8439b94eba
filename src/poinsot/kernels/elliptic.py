"""Jacobi elliptic functions that take the complementary parameter ``m1 = 1 − m`` directly.

:func:`scipy.special.ellipj` takes only ``m``. Near the separatrix of the free rigid body
``1 − m`` can be 1e-14 or smaller, and forming ``m`` first rounds most of its digits away; so we
deliberately write the descending arithmetic–geometric-mean algorithm (Abramowitz & Stegun
16.4; the same recurrence as Cephes' ``ellpj``) starting from ``b₀ = √m1``, which keeps every
digit of ``m1``. ``tests/kernels/test_elliptic.py`` checks it against ``scipy.special.ellipj``
where both apply and against the ``m → 1`` limits (tanh, sech) near the separatrix.
"""

from __future__ import annotations

import numpy as np

__all__ = ["jacobi_reduced", "jacobi_sn_cn_dn_am"]

_EPS = 2.220446049250313e-16
_MAX_ITER = 64
#: Below this m1, |u| ≤ K/2 is evaluated by one ascending Landen step and the hyperbolic
#: expansion (neglected terms O(m1³)); above it the AGM's relative error, ~eps·K/m1^¼, is
#: below 3e-14.
_NEAR_ONE = 1e-5


def jacobi_sn_cn_dn_am(u, m, m1):
    """``sn, cn, dn, am`` of ``u`` for parameter ``m`` with ``m1 = 1 − m`` given separately.

    Parameters
    ----------
    u : array_like
        Argument (any shape).
    m, m1 : float
        Parameter and complementary parameter, ``0 ≤ m ≤ 1``, ``m + m1 = 1`` (``m1`` carries
        the precision when ``m`` is close to 1).

    Returns
    -------
    sn, cn, dn, am : ndarray
        Same shape as ``u``. ``am`` is the amplitude φ (continuous, ``sn = sin φ``).
    """
    u = np.asarray(u) * 1.0  # float copy (the numba-compatible spelling)
    if m1 <= 0.0:  # m = 1: the separatrix limit
        am = 2.0 * np.arctan(np.tanh(0.5 * u))  # Gudermannian
        sech = 1.0 / np.cosh(u)
        return np.tanh(u), sech, sech, am
    if m <= 0.0:
        return np.sin(u), np.cos(u), np.ones_like(u), u.copy()
    a = [1.0]
    c = [np.sqrt(m)]
    b = np.sqrt(m1)
    i = 0
    while abs(c[i] / a[i]) > _EPS and i < _MAX_ITER:
        a_prev = a[i]
        a.append(0.5 * (a_prev + b))
        c.append(0.5 * (a_prev - b))
        b = np.sqrt(a_prev * b)
        i += 1
    phi = (2.0**i) * a[i] * u
    while i > 0:
        phi = 0.5 * (np.arcsin(c[i] * np.sin(phi) / a[i]) + phi)
        i -= 1
    sn = np.sin(phi)
    cn = np.cos(phi)
    dn = np.sqrt(cn * cn + m1 * sn * sn)  # = √(1 − m sn²) without cancellation; dn > 0
    return sn, cn, dn, phi


def jacobi_reduced(u, m, m1, K):
    """``sn, cn, dn`` of ``u`` with small ``cn``, ``dn`` kept to relative precision.

    Near odd multiples of the quarter period K (where ``sn ≈ ±1``), the amplitude computed by
    the AGM rounds to ±π/2 and ``cn``, ``dn`` lose all relative precision — exactly where the
    free body lingers near its unstable axis. So ``u = 2pK + v`` (|v| ≤ K) and, for |v| > K/2,
    the quarter-period shift ``x = K − |v|``: ``sn v = ±cd x``, ``cn v = √m1 sd x``,
    ``dn v = √m1 nd x`` (DLMF 22.4.3), with ``sn(u) = (−1)^p sn v``, ``cn(u) = (−1)^p cn v``,
    ``dn(u) = dn v``.

    Returns ``sn, cn, dn, p, v`` (``p`` integer array, ``v`` the reduced argument).
    ``K = inf`` (m = 1) leaves ``u`` unreduced.
    """
    shape = np.shape(u)
    u = np.atleast_1d(np.asarray(u, dtype=float)).ravel()
    if np.isinf(K):
        sn, cn, dn, _ = jacobi_sn_cn_dn_am(u, m, m1)
        out = (sn, cn, dn, np.zeros_like(u), u)
        return tuple(np.reshape(x, shape) for x in out)
    p = np.round(u / (2.0 * K))
    v = u - 2.0 * K * p
    base = _jacobi_near_one if m1 < _NEAR_ONE else _jacobi_agm
    sn, cn, dn = base(v, m, m1)
    near = np.abs(v) > 0.5 * K
    if np.any(near):
        x = K - np.abs(v[near])
        sx, cx, dx = base(x, m, m1)
        r = np.sqrt(m1)
        sn[near] = np.sign(v[near]) * cx / dx
        cn[near] = r * sx / dx
        dn[near] = r / dx
    parity = 1.0 - 2.0 * (np.abs(p) % 2)
    out = (parity * sn, parity * cn, dn, p, v)
    return tuple(np.reshape(x, shape) for x in out)


def _jacobi_agm(u, m, m1):
    sn, cn, dn, _ = jacobi_sn_cn_dn_am(u, m, m1)
    return sn, cn, dn


def _jacobi_near_one(u, m, m1):
    """``sn, cn, dn`` for ``m1 ≪ 1`` and ``|u| ≤ K/2``, to round-off relative to each value.

    One ascending Landen transformation (A&S 16.14.2–4) maps ``m`` to ``μ`` with complement
    ``μ1 = r²``, ``r = (1 − √m)/(1 + √m) = m1/(1 + √m)²`` (no cancellation); for parameter
    ``μ`` the first-order hyperbolic expansion (A&S 16.15.1–3) is exact to O(μ1² e^{4|w|}),
    i.e. O(m1³) on |u| ≤ K/2. Then ``sn = (1 + r) sn_μ cn_μ / dn_μ``,
    ``cn = (1 + r)/μ · (dn_μ² − r)/dn_μ``, ``dn = (1 − r)/μ · (dn_μ² + r)/dn_μ``.
    """
    u = np.asarray(u, dtype=float)
    r = m1 / (1.0 + np.sqrt(m)) ** 2
    mu1 = r * r
    mu = 1.0 - mu1
    w = u / (1.0 + r)
    t = np.tanh(w)
    s = 1.0 / np.cosh(w)
    # sinh·cosh·sech² = tanh and sinh·cosh·tanh·sech = tanh²/sech: no overflow for large w
    sn_mu = t + 0.25 * mu1 * (t - w * s * s)
    cn_mu = s - 0.25 * mu1 * (t * t / s - w * t * s)
    dn_mu = s + 0.25 * mu1 * (t * t / s + w * t * s)
    sn = (1.0 + r) * sn_mu * cn_mu / dn_mu
    cn = (1.0 + r) / mu * (dn_mu * dn_mu - r) / dn_mu
    dn = (1.0 - r) / mu * (dn_mu * dn_mu + r) / dn_mu
    return sn, cn, dn
