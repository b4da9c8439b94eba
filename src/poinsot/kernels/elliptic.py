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

__all__ = ["jacobi_sn_cn_dn_am"]

_EPS = 2.220446049250313e-16
_MAX_ITER = 64


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
    u = np.asarray(u, dtype=float)
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
