"""Elliptic integrals and Jacobi functions parametrised by ``m`` *and* ``m1 = 1 − m``.

Near ``m = 1`` (the separatrix of the free rigid body) the complementary parameter carries the
precision, so every function here takes it explicitly. These are array front-ends of the
compiled core (``poinsot._core``, the Rust crate ``poinsot-core``, module ``elliptic``):
Carlson's symmetric forms
``R_F``, ``R_J`` (whose arguments ``Δ² = 1 − m sin²φ = cos²φ + m1 sin²φ`` are formed without
cancellation), ``K(m) = R_F(0, m1, 1)`` and the descending AGM (DLMF §19.25(i), 19.25.5 and
19.25.14; A&S 16.4).
"""

from __future__ import annotations

import numpy as np

from ._bindings import elliptic as core_elliptic

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
    ``elliptic::jacobi_reduced`` of the core for the error bound)."""
    sn, cn, dn, _, _ = core_elliptic.jacobi_reduced(_floats(u), float(m), float(m1), ellipk(m1))
    return sn, cn, dn


def jacobi_am(u, m, m1):
    """``(sn, cn, dn, am)`` by the plain AGM (``am`` continuous in ``u``)."""
    return tuple(core_elliptic.jacobi_sn_cn_dn_am(_floats(u), float(m), float(m1)))


def ellipk(m1):
    """Complete integral of the first kind ``K(m)`` from ``m1 = 1 − m``; ``inf`` at
    ``m1 = 0``."""
    return float(core_elliptic.ellipk_m1(float(m1)))


def ellipf(phi, m, m1):
    """Incomplete integral of the first kind ``F(φ | m)`` for any real ``φ`` (scalar or
    array): the core's ``elliptic::ellipf``."""
    phi = _floats(phi)
    out = core_elliptic.ellipf(phi, float(m), float(m1))
    return out if phi.ndim else float(out)


def ellippi_complete(n, m, m1):
    """Complete integral of the third kind ``Π(n | m)`` for ``n < 1``."""
    _check_n(n)
    return float(core_elliptic.ellippi_complete(float(n), float(m), float(m1)))


def ellippi(n, phi, m, m1):
    """Incomplete integral of the third kind
    ``Π(n; φ | m) = ∫₀^φ dθ / ((1 − n sin²θ) √(1 − m sin²θ))`` for ``n < 1`` and any real φ
    (scalar or array): the core's ``elliptic::ellippi``."""
    _check_n(n)
    phi = _floats(phi)
    out = core_elliptic.ellippi(float(n), phi, float(m), float(m1))
    return out if phi.ndim else float(out)


def first_kind_from_sn_cn(s, c, m, m1):
    """The argument ``u`` in (−2K, 2K] with ``sn u = s``, ``cn u = c`` (``s² + c² = 1``):
    the core's ``elliptic::first_kind_from_sn_cn``."""
    return float(core_elliptic.first_kind_from_sn_cn(float(s), float(c), float(m), float(m1)))


def third_kind_u(n, u, m, m1):
    """``∫₀^u du' / (1 − n sn²u')  (= Π(n; am u | m))`` for ``n < 1``, accurate for every u
    (scalar or array): the core's ``elliptic::third_kind_u``."""
    _check_n(n)
    u = _floats(u)
    out = core_elliptic.third_kind_u(float(n), u, float(m), float(m1))
    return out if u.ndim else float(out)


def _floats(x):
    """``x`` as a float64 array (any shape) for the core."""
    return np.asarray(x, dtype=np.float64)


def _check_n(n):
    if not n < 1:
        raise ValueError(f"`n` must be < 1 (no pole on the path), found {n}")
