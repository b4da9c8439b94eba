"""Formulas of the torque-free body (``docs/theory.md`` §1, "Torque-free body", eqs (20)–(33)).

All in principal axes (ascending moments ``I1 ≤ I2 ≤ I3``), batched over leading axes where an
argument is a vector of ω:

* the invariants (30)–(31): rotational energy ``k`` with ``2k = Σ I_i ω_i²`` and the momentum
  ``a = |L| = √(Σ I_i² ω_i²)``: :func:`invariants`;
* the energy (Poinsot) and momentum ellipsoids' semi-axes: :func:`energy_ellipsoid_semi_axes`,
  :func:`momentum_ellipsoid_semi_axes`;
* the cone (32) ``Σ b_i ω_i² = 0``, ``b_i = I_i (a²/(2k) − I_i)`` (erratum: ``a²/(2k)``, not
  the notebook code's ``a^2/2*k``): :func:`cone_coefficients`;
* the linearisation of Euler's equation (20) about ω: :func:`euler_jacobian`.
"""

from __future__ import annotations

import math

import numpy as np

from .jit import kernel
from .so3 import hat_into

__all__ = [
    "cone_coefficients",
    "energy_ellipsoid_semi_axes",
    "euler_jacobian",
    "invariants",
    "momentum_ellipsoid_semi_axes",
]


@kernel
def invariants(moments, omega):
    """``(k, a)`` for principal ``moments`` (3,) and ω (..., 3) in principal axes: the
    rotational kinetic energy ``2k = Σ I_i ω_i²`` (30) and ``a = |L|``, ``a² = Σ I_i² ω_i²``
    (31). Returns two arrays of shape (...).

    Examples
    --------
    >>> import numpy as np
    >>> k, a = invariants(np.array([1.0, 2.0, 3.0]), np.array([1.0, 0.0, 0.0]))
    >>> float(k), float(a)
    (0.5, 1.0)
    """
    omega = np.asarray(omega)
    w = np.ascontiguousarray(omega).reshape((-1, 3)).astype(np.float64)
    k = np.empty(w.shape[0])
    a = np.empty(w.shape[0])
    for i in range(w.shape[0]):
        e = 0.0
        m = 0.0
        for j in range(3):
            p = moments[j] * w[i, j]
            e += p * w[i, j]
            m += p * p
        k[i] = 0.5 * e
        a[i] = math.sqrt(m)
    return k.reshape(omega.shape[:-1]), a.reshape(omega.shape[:-1])


@kernel
def energy_ellipsoid_semi_axes(moments, energy):
    """Semi-axes ``√(2k/I_i)`` of the energy (Poinsot) ellipsoid ``Σ I_i ω_i² = 2k`` (30)."""
    out = np.empty(3)
    for j in range(3):
        out[j] = math.sqrt(2.0 * energy / moments[j])
    return out


@kernel
def momentum_ellipsoid_semi_axes(moments, momentum):
    """Semi-axes ``a/I_i`` of the momentum ellipsoid ``Σ I_i² ω_i² = a²`` (31)."""
    out = np.empty(3)
    for j in range(3):
        out[j] = momentum / moments[j]
    return out


@kernel
def cone_coefficients(moments, energy, momentum):
    """``b_i = I_i (a²/(2k) − I_i)``: the cone (32) ``Σ b_i ω_i² = 0`` on which every motion
    with invariants ``(k, a)`` lies (the combination ``a²·(30) − 2k·(31)``)."""
    D = momentum * momentum / (2.0 * energy)
    out = np.empty(3)
    for j in range(3):
        out[j] = moments[j] * (D - moments[j])
    return out


@kernel
def euler_jacobian(inertia, omega):
    """``∂ω̇/∂ω = A⁻¹(hat(Aω) − hat(ω) A)`` (3, 3) of Euler's equation (20) ``A ω̇ = Aω × ω``,
    for any symmetric inertia (3, 3) and ω (3,) in the same frame: the linearisation whose
    eigenvalues decide the stability of a fixed point."""
    L = inertia @ omega
    hat_L = np.empty((3, 3))
    hat_w = np.empty((3, 3))
    hat_into(L, hat_L)
    hat_into(omega, hat_w)
    return np.linalg.solve(inertia, hat_L - hat_w @ inertia)
