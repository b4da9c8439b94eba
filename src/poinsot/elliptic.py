"""Elliptic integrals and Jacobi functions parametrised by ``m`` *and* ``m1 = 1 − m``.

Near ``m = 1`` (the separatrix of the free rigid body) the complementary parameter carries the
precision, so every function here takes it explicitly. The integrals use Carlson's symmetric
forms from :mod:`scipy.special` (``elliprf``, ``elliprj``), whose arguments
``Δ² = 1 − m sin²φ = cos²φ + m1 sin²φ`` are formed without cancellation; the complete integral
uses :func:`scipy.special.ellipkm1`, which takes ``m1`` directly (DLMF §19.25(i), 19.25.5 and
19.25.14).
"""

from __future__ import annotations

import numpy as np

from .kernels.elliptic import jacobi_sn_cn_dn_am

__all__ = ["ellipf", "ellipk", "ellippi", "ellippi_complete", "jacobi"]


def jacobi(u, m, m1):
    """``(sn, cn, dn, am)`` of ``u`` with ``m1 = 1 − m`` given to full precision."""
    return jacobi_sn_cn_dn_am(u, float(m), float(m1))


def ellipk(m1):
    """Complete integral of the first kind ``K(m)`` from ``m1 = 1 − m`` (``ellipkm1``)."""
    from scipy.special import ellipkm1

    return float(ellipkm1(m1))


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
