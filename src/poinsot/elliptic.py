"""Elliptic integrals and Jacobi functions parametrised by ``m`` *and* ``m1 = 1 − m``.

Near ``m = 1`` (the separatrix of the free rigid body) the complementary parameter carries the
precision, so every function here takes it explicitly. These are array front-ends of the
compiled scalar kernels of :mod:`poinsot.kernels.elliptic`: Carlson's symmetric forms
``R_F``, ``R_J`` (whose arguments ``Δ² = 1 − m sin²φ = cos²φ + m1 sin²φ`` are formed without
cancellation), ``K(m) = R_F(0, m1, 1)`` and the descending AGM (DLMF §19.25(i), 19.25.5 and
19.25.14; A&S 16.4).
"""

from __future__ import annotations

import numpy as np

from .kernels import elliptic as _k

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
    sn, cn, dn, _, _ = _k.jacobi_reduced(u, float(m), float(m1), ellipk(m1))
    return sn, cn, dn


def jacobi_am(u, m, m1):
    """``(sn, cn, dn, am)`` by the plain AGM (``am`` continuous in ``u``)."""
    return _k.jacobi_sn_cn_dn_am(u, float(m), float(m1))


def ellipk(m1):
    """Complete integral of the first kind ``K(m)`` from ``m1 = 1 − m``; ``inf`` at
    ``m1 = 0``."""
    return float(_k.ellipk_m1(float(m1)))


def ellipf(phi, m, m1):
    """Incomplete integral of the first kind ``F(φ | m)`` for any real ``φ`` (scalar or
    array): :func:`poinsot.kernels.elliptic.ellipf_scalar`."""
    phi = np.asarray(phi, dtype=float)
    values = [_k.ellipf_scalar(float(p), float(m), float(m1)) for p in phi.reshape(-1)]
    return np.array(values).reshape(phi.shape) if phi.ndim else values[0]


def ellippi_complete(n, m, m1):
    """Complete integral of the third kind ``Π(n | m)`` for ``n < 1``."""
    _check_n(n)
    return float(_k.ellippi_complete(float(n), float(m), float(m1)))


def ellippi(n, phi, m, m1):
    """Incomplete integral of the third kind
    ``Π(n; φ | m) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − m sin²θ))`` for ``n < 1`` and any real φ
    (scalar or array): :func:`poinsot.kernels.elliptic.ellippi_scalar`."""
    _check_n(n)
    phi = np.asarray(phi, dtype=float)
    values = [_k.ellippi_scalar(float(n), float(p), float(m), float(m1)) for p in phi.reshape(-1)]
    return np.array(values).reshape(phi.shape) if phi.ndim else values[0]


def first_kind_from_sn_cn(s, c, m, m1):
    """The argument ``u`` in (−2K, 2K] with ``sn u = s``, ``cn u = c`` (``s² + c² = 1``):
    :func:`poinsot.kernels.elliptic.first_kind_from_sn_cn`."""
    return float(_k.first_kind_from_sn_cn(float(s), float(c), float(m), float(m1)))


def third_kind_u(n, u, m, m1):
    """``∫₀^u du' / (1 − n sn²u')  (= Π(n; am u | m))`` for ``n < 1``, accurate for every u
    (scalar or array): :func:`poinsot.kernels.elliptic.third_kind_u_scalar`."""
    _check_n(n)
    u = np.asarray(u, dtype=float)
    out = _k.third_kind_u(float(n), u, float(m), float(m1))
    return out if u.ndim else float(out)


def _check_n(n):
    if not n < 1:
        raise ValueError(f"`n` must be < 1 (no pole on the path), found {n}")
