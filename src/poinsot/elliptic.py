"""Elliptic integrals and Jacobi functions parametrised by ``m`` *and* ``m1 = 1 − m``.

Near ``m = 1`` (the separatrix of the free rigid body) the complementary parameter carries the
precision, so every function here takes it explicitly. The integrals use Carlson's symmetric
forms from :mod:`scipy.special` (``elliprf``, ``elliprj``), whose arguments
``Δ² = 1 − m sin²φ = cos²φ + m1 sin²φ`` are formed without cancellation; the complete integral
uses :func:`scipy.special.ellipkm1`, which takes ``m1`` directly (DLMF §19.25(i), 19.25.5 and
19.25.14).
"""

from __future__ import annotations

import math

import numpy as np

from .kernels.elliptic import jacobi_reduced, jacobi_sn_cn_dn_am

__all__ = [
    "ellipf",
    "ellipk",
    "ellippi",
    "ellippi_complete",
    "first_kind_from_sn_cn",
    "jacobi",
    "jacobi_am",
    "third_kind_u",
]


def jacobi(u, m, m1):
    """``(sn, cn, dn)`` of ``u`` with ``m1 = 1 − m`` given to full precision; small ``cn`` and
    ``dn`` near the quarter periods keep their relative precision (see
    :func:`poinsot.kernels.elliptic.jacobi_reduced` for the error bound)."""
    sn, cn, dn, _, _ = jacobi_reduced(u, float(m), float(m1), ellipk(m1))
    return sn, cn, dn


def jacobi_am(u, m, m1):
    """``(sn, cn, dn, am)`` by the plain AGM (``am`` continuous in ``u``)."""
    return jacobi_sn_cn_dn_am(u, float(m), float(m1))


def ellipk(m1):
    """Complete integral of the first kind ``K(m)`` from ``m1 = 1 − m`` (``ellipkm1``);
    ``inf`` at ``m1 = 0``."""
    from scipy.special import ellipkm1

    return float(ellipkm1(m1)) if m1 > 0 else float("inf")


def _reduce(phi):
    """``φ = jπ + φr`` with ``φr ∈ [−π/2, π/2]``; returns ``(j, φr)``."""
    phi = np.asarray(phi, dtype=float)
    j = np.round(phi / np.pi)
    return j, phi - j * np.pi


def ellipf(phi, m, m1):
    """Incomplete integral of the first kind ``F(φ | m)`` for any real ``φ``.

    ``F = sin φ · R_F(cos²φ, cos²φ + m1 sin²φ, 1)`` on ``|φ| ≤ π/2``, extended by
    ``F(φ + jπ) = F(φ) + 2jK``.
    """
    from scipy.special import elliprf

    j, r = _reduce(phi)
    s, c = np.sin(r), np.cos(r)
    c2 = c * c
    value = s * elliprf(c2, c2 + m1 * s * s, 1.0)
    return value + 2.0 * j * ellipk(m1) if np.any(j) else value


def ellippi_complete(n, m, m1):
    """Complete integral of the third kind ``Π(n | m)`` for ``n < 1``."""
    from scipy.special import elliprf, elliprj

    return float(elliprf(0.0, m1, 1.0) + n / 3.0 * elliprj(0.0, m1, 1.0, 1.0 - n))


def ellippi(n, phi, m, m1):
    """Incomplete integral of the third kind
    ``Π(n; φ | m) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − m sin²θ))`` for ``n < 1`` and any real φ.

    Carlson form ``sin φ R_F(c², Δ², 1) + (n/3) sin³φ R_J(c², Δ², 1, 1 − n sin²φ)`` on
    ``|φ| ≤ π/2``, extended by ``Π(n; φ + jπ) = Π(n; φ) + 2jΠ(n)``.
    """
    from scipy.special import elliprf, elliprj

    if n >= 1:
        raise ValueError(f"`n` must be < 1 (no pole on the path), found {n}")
    j, r = _reduce(phi)
    s, c = np.sin(r), np.cos(r)
    c2 = c * c
    d2 = c2 + m1 * s * s
    value = s * elliprf(c2, d2, 1.0) + n / 3.0 * s**3 * elliprj(c2, d2, 1.0, 1.0 - n * s * s)
    return value + 2.0 * j * ellippi_complete(n, m, m1) if np.any(j) else value


def first_kind_from_sn_cn(s, c, m, m1):
    """The argument ``u`` in (−2K, 2K] with ``sn u = s``, ``cn u = c`` (``s² + c² = 1``).

    Carlson's form on the branch of ``c``: ``u = s R_F(c², c² + m1 s², 1)`` for ``c ≥ 0``, and
    ``sign(s)·2K − s R_F(…)`` for ``c < 0`` — no angle is formed, so a tiny ``c`` keeps its
    digits (an ``atan2`` would round the amplitude to ±π/2).
    """
    from scipy.special import elliprf

    if m1 == 0:  # m = 1: sn = tanh u, cn = sech u > 0, so u = asinh(s / c)
        return math.asinh(s / c) if c > 0 else math.copysign(math.inf, s)
    c2 = c * c
    r = s * float(elliprf(c2, c2 + m1 * s * s, 1.0))
    if c >= 0:
        return r
    return (1.0 if s >= 0 else -1.0) * 2.0 * ellipk(m1) - r


_TINY_M1 = 1e-32


def _third_kind_separatrix(n, u):
    """m = 1, sn = tanh: with ν = −n > 0,
    ``∫₀^u du/(1 + ν tanh²u) = u/(1 + ν) + √ν/(1 + ν) · atan(√ν tanh u)``."""
    nu = -n
    r = math.sqrt(max(nu, 0.0))
    return u / (1 + nu) + r / (1 + nu) * np.arctan(r * np.tanh(u))


def third_kind_u(n, u, m, m1):
    """``∫₀^u du' / (1 − n sn²u')  (= Π(n; am u | m))`` for ``n < 1``, accurate for every u.

    ``u = 2pK + v`` with |v| ≤ K: the integral is ``2p Π(n|m) + G(v)``, ``G`` from Carlson's
    form with ``sn v``, ``cn v ≥ 0``, ``dn v`` taken from
    :func:`~poinsot.kernels.elliptic.jacobi_reduced` (accurate near v = ±K, where the body
    lingers by its unstable axis).
    """
    from scipy.special import elliprf, elliprj

    if n >= 1:
        raise ValueError(f"`n` must be < 1 (no pole on the path), found {n}")
    u = np.asarray(u, dtype=float)
    if m1 == 0:
        return _third_kind_separatrix(n, u)
    K = ellipk(m1)
    _, _, _, p, v = jacobi_reduced(u, float(m), float(m1), K)
    if m1 < _TINY_M1:
        # sn(v|m) = tanh v + O(√m1) on |v| ≤ K/2, and cd ≈ 1 beyond: G(v) is the m = 1 form
        # there and Π(n|m) − (K − |v|)/(1 − n) up to K, both exact to O(√m1) < 1e-16 (scipy's
        # R_J loses digits when its two small arguments approach 1e-160)
        av = np.abs(v)
        inner = _third_kind_separatrix(n, v)
        outer = np.sign(v) * (ellippi_complete(n, m, m1) - (K - av) / (1.0 - n))
        G = np.where(av <= 0.5 * K, inner, outer)
        return 2.0 * p * ellippi_complete(n, m, m1) + G if np.any(p) else G
    s, c, d, _, _ = jacobi_reduced(v, float(m), float(m1), K)
    c2, d2 = c * c, d * d
    G = s * elliprf(c2, d2, 1.0) + n / 3.0 * s**3 * elliprj(c2, d2, 1.0, 1.0 - n * s * s)
    if not np.any(p):
        return G
    return 2.0 * p * ellippi_complete(n, m, m1) + G
