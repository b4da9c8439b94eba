"""Jacobi elliptic functions that take the complementary parameter ``m1 = 1 − m`` directly.

:func:`scipy.special.ellipj` takes only ``m``. Near the separatrix of the free rigid body
``1 − m`` can be 1e-14 or smaller, and forming ``m`` first rounds most of its digits away; so we
deliberately write the descending arithmetic–geometric-mean algorithm (Abramowitz & Stegun
16.4; the same recurrence as Cephes' ``ellpj``) starting from ``b₀ = √m1``, which keeps every
digit of ``m1``. ``tests/kernels/test_elliptic.py`` checks it against ``scipy.special.ellipj``
where both apply and against the ``m → 1`` limits (tanh, sech) near the separatrix.

Each formula is a scalar kernel (``*_scalar``); the public functions apply it to arrays of any
shape.
"""

from __future__ import annotations

import math

import numpy as np

from .jit import kernel

__all__ = [
    "jacobi_agm_scalar",
    "jacobi_near_one_scalar",
    "jacobi_reduced",
    "jacobi_reduced_scalar",
    "jacobi_sn_cn_dn_am",
]

_EPS = 2.220446049250313e-16
_MAX_ITER = 64
#: Below this m1, |u| ≤ K/2 is evaluated by one ascending Landen step and the hyperbolic
#: expansion (neglected terms O(m1³)); above it the AGM's relative error, ~eps·K/m1^¼, is
#: below 3e-14.
NEAR_ONE = 1e-5


@kernel
def jacobi_agm_scalar(u, m, m1):
    """``sn, cn, dn, am`` of one argument ``u`` by the descending AGM (A&S 16.4), with
    ``m1 = 1 − m`` given separately (it carries the precision when ``m`` is close to 1).
    ``am`` is the amplitude φ (continuous, ``sn = sin φ``)."""
    if m1 <= 0.0:  # m = 1: the separatrix limit
        sech = 1.0 / math.cosh(u)
        return math.tanh(u), sech, sech, 2.0 * math.atan(math.tanh(0.5 * u))  # Gudermannian
    if m <= 0.0:
        return math.sin(u), math.cos(u), 1.0, u
    a = np.empty(_MAX_ITER + 1)
    c = np.empty(_MAX_ITER + 1)
    a[0] = 1.0
    c[0] = math.sqrt(m)
    b = math.sqrt(m1)
    i = 0
    while abs(c[i] / a[i]) > _EPS and i < _MAX_ITER:
        a_prev = a[i]
        a[i + 1] = 0.5 * (a_prev + b)
        c[i + 1] = 0.5 * (a_prev - b)
        b = math.sqrt(a_prev * b)
        i += 1
    phi = (2.0**i) * a[i] * u
    while i > 0:
        phi = 0.5 * (math.asin(c[i] * math.sin(phi) / a[i]) + phi)
        i -= 1
    sn = math.sin(phi)
    cn = math.cos(phi)
    dn = math.sqrt(cn * cn + m1 * sn * sn)  # = √(1 − m sn²) without cancellation; dn > 0
    return sn, cn, dn, phi


@kernel
def jacobi_sn_cn_dn_am(u, m, m1):
    """``sn, cn, dn, am`` of ``u`` (an array of any shape) for parameter ``m`` with
    ``m1 = 1 − m`` given separately; see :func:`jacobi_agm_scalar`."""
    u = np.asarray(u)
    flat = np.ascontiguousarray(u).ravel().astype(np.float64)
    sn = np.empty_like(flat)
    cn = np.empty_like(flat)
    dn = np.empty_like(flat)
    am = np.empty_like(flat)
    for k in range(flat.size):
        sn[k], cn[k], dn[k], am[k] = jacobi_agm_scalar(flat[k], m, m1)
    return sn.reshape(u.shape), cn.reshape(u.shape), dn.reshape(u.shape), am.reshape(u.shape)


@kernel
def jacobi_near_one_scalar(u, m, m1):
    """``sn, cn, dn`` for ``m1 ≪ 1`` and ``|u| ≤ K/2``, to round-off relative to each value.

    One ascending Landen transformation (A&S 16.14.2–4) maps ``m`` to ``μ`` with complement
    ``μ1 = r²``, ``r = (1 − √m)/(1 + √m) = m1/(1 + √m)²`` (no cancellation); for parameter
    ``μ`` the first-order hyperbolic expansion (A&S 16.15.1–3) is exact to O(μ1² e^{4|w|}),
    i.e. O(m1³) on |u| ≤ K/2. Then ``sn = (1 + r) sn_μ cn_μ / dn_μ``,
    ``cn = (1 + r)/μ · (dn_μ² − r)/dn_μ``, ``dn = (1 − r)/μ · (dn_μ² + r)/dn_μ``.
    """
    r = m1 / (1.0 + math.sqrt(m)) ** 2
    mu1 = r * r
    mu = 1.0 - mu1
    w = u / (1.0 + r)
    t = math.tanh(w)
    s = 1.0 / math.cosh(w)
    # sinh·cosh·sech² = tanh and sinh·cosh·tanh·sech = tanh²/sech: no overflow for large w
    sn_mu = t + 0.25 * mu1 * (t - w * s * s)
    cn_mu = s - 0.25 * mu1 * (t * t / s - w * t * s)
    dn_mu = s + 0.25 * mu1 * (t * t / s + w * t * s)
    sn = (1.0 + r) * sn_mu * cn_mu / dn_mu
    cn = (1.0 + r) / mu * (dn_mu * dn_mu - r) / dn_mu
    dn = (1.0 - r) / mu * (dn_mu * dn_mu + r) / dn_mu
    return sn, cn, dn


@kernel
def _base(u, m, m1):
    if m1 < NEAR_ONE:
        return jacobi_near_one_scalar(u, m, m1)
    sn, cn, dn, _ = jacobi_agm_scalar(u, m, m1)
    return sn, cn, dn


@kernel
def jacobi_reduced_scalar(u, m, m1, K):
    """``sn, cn, dn`` of ``u`` with small ``cn``, ``dn`` kept to relative precision, and the
    reduction ``u = 2pK + v`` (|v| ≤ K): returns ``(sn, cn, dn, p, v)``.

    Near odd multiples of the quarter period K (where ``sn ≈ ±1``), the amplitude computed by
    the AGM rounds to ±π/2 and ``cn``, ``dn`` lose all relative precision — exactly where the
    free body lingers near its unstable axis. So for |v| > K/2 the quarter-period shift
    ``x = K − |v|``: ``sn v = ±cd x``, ``cn v = √m1 sd x``, ``dn v = √m1 nd x`` (DLMF 22.4.3),
    with ``sn(u) = (−1)^p sn v``, ``cn(u) = (−1)^p cn v``, ``dn(u) = dn v``. ``K = inf``
    (m = 1) leaves ``u`` unreduced.
    """
    if math.isinf(K):
        sn, cn, dn, _ = jacobi_agm_scalar(u, m, m1)
        return sn, cn, dn, 0.0, u
    p = np.round(u / (2.0 * K))
    v = u - 2.0 * K * p
    if abs(v) > 0.5 * K:
        sx, cx, dx = _base(K - abs(v), m, m1)
        r = math.sqrt(m1)
        sn = math.copysign(1.0, v) * cx / dx
        cn = r * sx / dx
        dn = r / dx
    else:
        sn, cn, dn = _base(v, m, m1)
    parity = 1.0 - 2.0 * (abs(p) % 2.0)
    return parity * sn, parity * cn, dn, p, v


@kernel
def jacobi_reduced(u, m, m1, K):
    """:func:`jacobi_reduced_scalar` on an array ``u`` of any shape: ``sn, cn, dn, p, v``."""
    u = np.asarray(u)
    flat = np.ascontiguousarray(u).ravel().astype(np.float64)
    out = np.empty((5, flat.size))
    for k in range(flat.size):
        sn, cn, dn, p, v = jacobi_reduced_scalar(flat[k], m, m1, K)
        out[0, k] = sn
        out[1, k] = cn
        out[2, k] = dn
        out[3, k] = p
        out[4, k] = v
    s = u.shape
    return (
        out[0].reshape(s),
        out[1].reshape(s),
        out[2].reshape(s),
        out[3].reshape(s),
        out[4].reshape(s),
    )
