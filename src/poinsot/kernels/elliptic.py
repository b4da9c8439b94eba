"""Jacobi elliptic functions and elliptic integrals that take ``m1 = 1 − m`` directly.

:func:`scipy.special.ellipj` takes only ``m``. Near the separatrix of the free rigid body
``1 − m`` can be 1e-14 or smaller, and forming ``m`` first rounds most of its digits away; so we
deliberately write the descending arithmetic–geometric-mean algorithm (Abramowitz & Stegun
16.4; the same recurrence as Cephes' ``ellpj``) starting from ``b₀ = √m1``, which keeps every
digit of ``m1``. ``tests/kernels/test_elliptic.py`` checks it against ``scipy.special.ellipj``
where both apply and against the ``m → 1`` limits (tanh, sech) near the separatrix.

The integrals are Carlson's symmetric forms ``R_F``, ``R_J`` and ``R_C`` by the duplication
algorithm (B. C. Carlson, "Numerical computation of real or complex elliptic integrals",
*Numer. Algorithms* 10 (1995) 13–26; DLMF §19.36(i)), written here rather than taken from
:mod:`scipy.special` because they must compile into the exact torque-free ensembles; the tests
compare them with ``scipy.special.elliprf``/``elliprj`` and mpmath. From them: the complete
integral ``K(m) = R_F(0, m1, 1)`` (DLMF 19.25.1), the incomplete integrals of the first and
third kinds, and the inverse of ``(sn, cn)``.

Each formula is a scalar kernel (``*_scalar``); the public functions apply it to arrays of any
shape.
"""

from __future__ import annotations

import math

import numpy as np

from .jit import kernel

__all__ = [
    "carlson_rc1p",
    "carlson_rf",
    "carlson_rj",
    "ellipf_scalar",
    "ellipk_m1",
    "ellippi_complete",
    "ellippi_scalar",
    "first_kind_from_sn_cn",
    "jacobi_agm_scalar",
    "jacobi_near_one_scalar",
    "jacobi_reduced",
    "jacobi_reduced_scalar",
    "jacobi_sn_cn_dn_am",
    "third_kind_separatrix",
    "third_kind_u",
    "third_kind_u_scalar",
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


# --------------------------------------------------------------------------- Carlson's forms
#: Carlson's stopping rule for a relative error below ``r``: ``(3r)^(-1/6)`` (R_F) and
#: ``(r/4)^(-1/6)`` (R_J), with ``r = 2⁻⁵³``.
_RF_FACTOR = (3.0 * 2.0**-53) ** (-1.0 / 6.0)
_RJ_FACTOR = (0.25 * 2.0**-53) ** (-1.0 / 6.0)


@kernel
def carlson_rf(x, y, z):
    """``R_F(x, y, z) = ½ ∫₀^∞ dt / √((t + x)(t + y)(t + z))`` for ``x, y, z ≥ 0``, at most one
    zero (DLMF 19.16.1), by duplication (Carlson 1995, algorithm 1; DLMF 19.36.1).

    Examples
    --------
    >>> round(carlson_rf(1.0, 2.0, 0.0), 13)   # Carlson (1995) test value 1.3110287771461
    1.3110287771461
    """
    A0 = (x + y + z) / 3.0
    Q = _RF_FACTOR * max(abs(A0 - x), abs(A0 - y), abs(A0 - z))
    dx = A0 - x
    dy = A0 - y
    A = A0
    scale = 1.0  # 4^-n
    while scale * Q >= abs(A) and scale > 0.0:
        sx = math.sqrt(x)
        sy = math.sqrt(y)
        sz = math.sqrt(z)
        lam = sx * sy + sx * sz + sy * sz
        A = 0.25 * (A + lam)
        x = 0.25 * (x + lam)
        y = 0.25 * (y + lam)
        z = 0.25 * (z + lam)
        scale *= 0.25
    X = dx * scale / A
    Y = dy * scale / A
    Z = -(X + Y)
    E2 = X * Y - Z * Z
    E3 = X * Y * Z
    return (1.0 - E2 / 10.0 + E3 / 14.0 + E2 * E2 / 24.0 - 3.0 * E2 * E3 / 44.0) / math.sqrt(A)


@kernel
def carlson_rj(x, y, z, p):
    """``R_J(x, y, z, p) = 3/2 ∫₀^∞ dt / ((t + p) √((t + x)(t + y)(t + z)))`` for
    ``x, y, z ≥ 0`` (at most one zero) and ``p > 0`` (DLMF 19.16.2), by duplication (Carlson
    1995, algorithm 3; DLMF 19.36.1), with ``R_C(1, 1 + e)`` in its cancellation-free form.

    Examples
    --------
    >>> round(carlson_rj(2.0, 3.0, 4.0, 5.0), 13)   # Carlson (1995) test value 0.14297579667157
    0.1429757966716
    """
    A0 = (x + y + z + 2.0 * p) / 5.0
    Q = _RJ_FACTOR * max(abs(A0 - x), abs(A0 - y), abs(A0 - z), abs(A0 - p))
    delta = (p - x) * (p - y) * (p - z)
    dx = A0 - x
    dy = A0 - y
    dz = A0 - z
    A = A0
    scale = 1.0  # 4^-m
    total = 0.0
    while scale * Q >= abs(A) and scale > 0.0:
        sx = math.sqrt(x)
        sy = math.sqrt(y)
        sz = math.sqrt(z)
        sp = math.sqrt(p)
        lam = sx * sy + sx * sz + sy * sz
        d = (sp + sx) * (sp + sy) * (sp + sz)
        e = scale * scale * scale * delta / (d * d)
        total += scale * carlson_rc1p(e) / d
        A = 0.25 * (A + lam)
        x = 0.25 * (x + lam)
        y = 0.25 * (y + lam)
        z = 0.25 * (z + lam)
        p = 0.25 * (p + lam)
        scale *= 0.25
    X = dx * scale / A
    Y = dy * scale / A
    Z = dz * scale / A
    P = -0.5 * (X + Y + Z)
    E2 = X * Y + X * Z + Y * Z - 3.0 * P * P
    E3 = X * Y * Z + 2.0 * E2 * P + 4.0 * P * P * P
    E4 = (2.0 * X * Y * Z + E2 * P + 3.0 * P * P * P) * P
    E5 = X * Y * Z * P * P
    series = (
        1.0
        - 3.0 * E2 / 14.0
        + E3 / 6.0
        + 9.0 * E2 * E2 / 88.0
        - 3.0 * E4 / 22.0
        - 9.0 * E2 * E3 / 52.0
        + 3.0 * E5 / 26.0
    )
    return scale * series / (A * math.sqrt(A)) + 6.0 * total


@kernel
def carlson_rc1p(e):
    """``R_C(1, 1 + e)`` for ``e > −1`` (DLMF 19.2.17–19): ``atan(√e)/√e`` for e > 0,
    ``atanh(√−e)/√−e`` for e < 0, 1 at 0 — accurate for small |e|, where ``R_C(x, y)`` with
    ``y → x`` cancels."""
    if e > 0.0:
        r = math.sqrt(e)
        return math.atan(r) / r
    if e < 0.0:
        r = math.sqrt(-e)
        return math.atanh(r) / r
    return 1.0


# --------------------------------------------------------------------------- integrals in (m, m1)
@kernel
def ellipk_m1(m1):
    """The complete integral of the first kind ``K(m) = R_F(0, m1, 1)`` (DLMF 19.25.1) from the
    complementary parameter ``m1 = 1 − m`` (as :func:`scipy.special.ellipkm1`); ``inf`` at
    ``m1 = 0``.

    Examples
    --------
    >>> round(ellipk_m1(1.0), 12)   # K(0) = π/2
    1.570796326795
    """
    if m1 <= 0.0:
        return math.inf
    return carlson_rf(0.0, m1, 1.0)


@kernel
def _reduce_angle(phi):
    """``φ = jπ + r`` with ``r ∈ [−π/2, π/2]``: ``(j, r)``."""
    j = np.round(phi / math.pi)
    return j, phi - j * math.pi


@kernel
def ellipf_scalar(phi, m, m1):
    """The incomplete integral of the first kind ``F(φ | m)`` for any real ``φ``:
    ``sin r · R_F(cos²r, cos²r + m1 sin²r, 1) + 2jK`` with ``φ = jπ + r``, |r| ≤ π/2
    (DLMF 19.25.5; the second argument ``Δ² = 1 − m sin²r`` formed without cancellation)."""
    j, r = _reduce_angle(phi)
    s = math.sin(r)
    c = math.cos(r)
    value = s * carlson_rf(c * c, c * c + m1 * s * s, 1.0)
    if j != 0.0:
        value += 2.0 * j * ellipk_m1(m1)
    return value


@kernel
def ellippi_complete(n, m, m1):
    """The complete integral of the third kind ``Π(n | m) = R_F(0, m1, 1) + (n/3) R_J(0, m1, 1,
    1 − n)`` for ``n < 1`` (DLMF 19.25.2)."""
    return carlson_rf(0.0, m1, 1.0) + n / 3.0 * carlson_rj(0.0, m1, 1.0, 1.0 - n)


@kernel
def ellippi_scalar(n, phi, m, m1):
    """The incomplete integral of the third kind
    ``Π(n; φ | m) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − m sin²θ))`` for ``n < 1`` and any real φ:
    ``s R_F(c², Δ², 1) + (n/3) s³ R_J(c², Δ², 1, 1 − n s²)`` on |φ| ≤ π/2 (DLMF 19.25.14),
    extended by ``Π(n; φ + jπ) = Π(n; φ) + 2jΠ(n)``."""
    j, r = _reduce_angle(phi)
    s = math.sin(r)
    c = math.cos(r)
    c2 = c * c
    d2 = c2 + m1 * s * s
    value = s * carlson_rf(c2, d2, 1.0) + n / 3.0 * s * s * s * carlson_rj(
        c2, d2, 1.0, 1.0 - n * s * s
    )
    if j != 0.0:
        value += 2.0 * j * ellippi_complete(n, m, m1)
    return value


@kernel
def first_kind_from_sn_cn(s, c, m, m1):
    """The argument ``u`` in (−2K, 2K] with ``sn u = s``, ``cn u = c`` (``s² + c² = 1``).

    Carlson's form on the branch of ``c``: ``u = s R_F(c², c² + m1 s², 1)`` for ``c ≥ 0``, and
    ``sign(s)·2K − s R_F(…)`` for ``c < 0`` — no angle is formed, so a tiny ``c`` keeps its
    digits (an ``atan2`` would round the amplitude to ±π/2). On the separatrix (``m1 = 0``)
    ``sn = tanh u``, ``cn = sech u``: ``u = asinh(s/c)``.
    """
    if m1 == 0.0:
        if c > 0.0:
            return math.asinh(s / c)
        return math.copysign(math.inf, s)
    c2 = c * c
    r = s * carlson_rf(c2, c2 + m1 * s * s, 1.0)
    if c >= 0.0:
        return r
    return (1.0 if s >= 0.0 else -1.0) * 2.0 * ellipk_m1(m1) - r


@kernel
def third_kind_separatrix(n, u):
    """``∫₀^u du/(1 − n tanh²u)`` (m = 1, sn = tanh) for ``n < 1``: with ν = −n,
    ``u/(1 + ν) + √ν/(1 + ν) · atan(√ν tanh u)`` (ν > 0), and for 0 < n < 1
    ``u/(1 − n) − √n/(1 − n) · atanh(√n tanh u)``."""
    if n <= 0.0:
        nu = -n
        r = math.sqrt(nu)
        return u / (1.0 + nu) + r / (1.0 + nu) * math.atan(r * math.tanh(u))
    r = math.sqrt(n)
    return u / (1.0 - n) - r / (1.0 - n) * math.atanh(r * math.tanh(u))


#: Below this ``m1`` the third-kind integral in u uses the separatrix forms (see
#: :func:`third_kind_u_scalar`).
TINY_M1 = 1e-32


@kernel
def third_kind_u_scalar(n, u, m, m1, K):
    """``∫₀^u du' / (1 − n sn²u')  (= Π(n; am u | m))`` for ``n < 1``, accurate for every u;
    ``K = K(m)``.

    ``u = 2pK + v`` with |v| ≤ K: the integral is ``2p Π(n|m) + G(v)``, with
    ``G(v) = s R_F(c², d², 1) + (n/3) s³ R_J(c², d², 1, 1 − n s²)`` from ``s = sn v``,
    ``c = cn v ≥ 0``, ``d = dn v`` taken from :func:`jacobi_reduced_scalar` (accurate near
    v = ±K, where the free body lingers by its unstable axis). For ``m1 < TINY_M1``,
    ``sn(v|m) = tanh v + O(√m1)`` on |v| ≤ K/2 and ``cd ≈ 1`` beyond, so there ``G`` is the
    separatrix form, and ``Π(n|m) − (K − |v|)/(1 − n)`` up to K, both exact to O(√m1) < 1e-16.
    """
    if m1 == 0.0:
        return third_kind_separatrix(n, u)
    _, _, _, p, v = jacobi_reduced_scalar(u, m, m1, K)
    if m1 < TINY_M1:
        if abs(v) <= 0.5 * K:
            G = third_kind_separatrix(n, v)
        else:
            G = math.copysign(1.0, v) * (ellippi_complete(n, m, m1) - (K - abs(v)) / (1.0 - n))
    else:
        s, c, d, _, _ = jacobi_reduced_scalar(v, m, m1, K)
        c2 = c * c
        d2 = d * d
        G = s * carlson_rf(c2, d2, 1.0) + n / 3.0 * s * s * s * carlson_rj(
            c2, d2, 1.0, 1.0 - n * s * s
        )
    if p != 0.0:
        G += 2.0 * p * ellippi_complete(n, m, m1)
    return G


@kernel
def third_kind_u(n, u, m, m1):
    """:func:`third_kind_u_scalar` on an array ``u`` of any shape."""
    u = np.asarray(u)
    flat = np.ascontiguousarray(u).ravel().astype(np.float64)
    K = ellipk_m1(m1)
    out = np.empty(flat.size)
    for k in range(flat.size):
        out[k] = third_kind_u_scalar(n, flat[k], m, m1, K)
    return out.reshape(u.shape)
