"""The inertia moments of relative motion as named quantities (``docs/relative.md``; paper eqs
(2)–(6), (16)).

Every function checks its arguments and calls one function of the core
(``poinsot_core::relative``; the planar inertia: ``poinsot_core::inertia``); vectors are
body-frame components and may carry leading axes (``(..., 3)``), so a whole trajectory is
evaluated in one call.
"""

from __future__ import annotations

import numpy as np

from .._bindings import inertia as core_inertia
from .._bindings import relative as core_relative
from .._validation import as_array

__all__ = [
    "balancing_moment",
    "coriolis_moment",
    "coriolis_moment_particles",
    "coriolis_moment_three_term",
    "planar_inertia",
    "planar_inertia_ellipsoid",
    "planar_principal_moments",
    "transport_moment",
]


def _inertia(J) -> np.ndarray:
    J = as_array(J, "J", (3, 3))
    if not np.allclose(J, J.T, rtol=1e-12, atol=1e-300 + 1e-12 * float(np.abs(J).max())):
        raise ValueError("`J` must be a symmetric inertia tensor")
    return np.ascontiguousarray(J)


def _vectors(value, name) -> np.ndarray:
    arr = np.asarray(value, dtype=float) if not isinstance(value, str) else None
    if arr is None or arr.ndim == 0 or arr.shape[-1] != 3:
        shape = None if arr is None else arr.shape
        raise ValueError(f"`{name}` must have shape (3,) or (..., 3), found {shape}")
    return as_array(arr, name, arr.shape)


def _pair(a, b, na, nb):
    a = _vectors(a, na)
    b = _vectors(b, nb)
    if a.shape != b.shape:
        a, b = np.broadcast_arrays(a, b)
    return np.ascontiguousarray(a), np.ascontiguousarray(b)


def _rows(func, *args, a, b):
    """``func(*args, a_rows, b_rows)`` on (n, 3) rows, returned in the shape of ``a``."""
    shape = a.shape
    out = func(
        *args, np.ascontiguousarray(a.reshape(-1, 3)), np.ascontiguousarray(b.reshape(-1, 3))
    )
    return out.reshape(shape)


def planar_inertia(J) -> np.ndarray:
    """The planar inertia tensor ``J' = ½ tr(J) 𝟙 − J`` (paper eqs (3)–(4)).

    Its diagonal holds the planar moments ``Σ m x²``, ``Σ m y²``, ``Σ m z²`` (about the
    coordinate planes), its off-diagonal the products of inertia ``Σ m x y``, … .

    Parameters
    ----------
    J : array_like (3, 3)
        Inertia tensor about the centre of mass.

    Returns
    -------
    ndarray (3, 3)

    Examples
    --------
    >>> import numpy as np
    >>> np.diag(planar_inertia(np.diag([1.0, 2.0, 3.0]))).tolist()  # A' = (B + C − A)/2, …
    [2.0, 1.0, 0.0]
    """
    return core_inertia.planar_inertia(_inertia(J))


def planar_principal_moments(moments) -> np.ndarray:
    """``A' = (B + C − A)/2``, ``B' = (C + A − B)/2``, ``C' = (A + B − C)/2`` (paper, after
    (12)) from the principal moments ``(A, B, C)``: the diagonal of :func:`planar_inertia` in
    principal axes.

    Examples
    --------
    >>> planar_principal_moments([2.0, 3.0, 4.0]).tolist()
    [2.5, 1.5, 0.5]
    """
    m = as_array(moments, "moments", (3,))
    return np.diag(core_inertia.planar_inertia(np.diag(m))).copy()


def planar_inertia_ellipsoid(J):
    """The planar inertia ellipsoid (the paper's analogue of the inertia ellipsoid): semi-axes
    ``1/√A'``, ``1/√B'``, ``1/√C'`` along the principal axes of ``J'``.

    Returns
    -------
    semi_axes : ndarray (3,)
        ``inf`` along an axis whose planar moment is zero (all mass in that plane).
    axes : ndarray (3, 3)
        The principal axes (columns), those of ``J``.
    """
    Jp = planar_inertia(J)
    moments, axes = np.linalg.eigh(Jp)
    with np.errstate(divide="ignore"):
        semi = np.where(moments > 0, 1.0 / np.sqrt(np.maximum(moments, 0)), np.inf)
    return semi, axes


def transport_moment(J, omega_e, epsilon_e) -> np.ndarray:
    """The transport inertia moment ``M_e = −J ε_e + Jω_e × ω_e`` (paper eq. (2)).

    Parameters
    ----------
    J : array_like (3, 3)
        Inertia about the centre of mass, body frame.
    omega_e, epsilon_e : array_like (3,) or (..., 3)
        The carrier's angular velocity and acceleration, body components.

    Returns
    -------
    ndarray (..., 3)

    Examples
    --------
    >>> transport_moment([[1, 0, 0], [0, 2, 0], [0, 0, 3]], [1, 1, 0], [0, 0, 1]).tolist()
    [0.0, 0.0, -4.0]
    """
    J = _inertia(J)
    w, e = _pair(omega_e, epsilon_e, "omega_e", "epsilon_e")
    return _rows(core_relative.transport_moments, J, a=w, b=e)


def balancing_moment(J, omega_e, epsilon_e) -> np.ndarray:
    """The physical moment that cancels the transport moment, case (16):
    ``M(F) = J ε_e − Jω_e × ω_e = −M_e``. Under it the relative rotational energy is conserved
    (17); ``simulate_relative(..., balance_transport=True)`` applies it.

    Examples
    --------
    >>> balancing_moment(np.eye(3), [0, 0, 1], [0, 0, 2]).tolist()
    [0.0, 0.0, 2.0]
    """
    # 0.0 − M_e rather than −M_e, so that a zero component prints as 0.0, not −0.0
    return 0.0 - transport_moment(J, omega_e, epsilon_e)


def coriolis_moment(J, omega_r, omega_e) -> np.ndarray:
    """The Coriolis inertia moment in the compact form ``M_c = 2 ω_r × (J' ω_e)`` (paper
    eq. (5)): twice the cross product of the relative angular velocity with the *planar*
    angular momentum of the transport rotation.

    Parameters
    ----------
    J : array_like (3, 3)
        Inertia about the centre of mass, body frame.
    omega_r, omega_e : array_like (3,) or (..., 3)
        Relative and transport angular velocities, body components.

    Returns
    -------
    ndarray (..., 3)

    Examples
    --------
    >>> coriolis_moment(np.diag([1.0, 2.0, 3.0]), [0, 0, 1], [1, 0, 0]).tolist()
    [0.0, 4.0, 0.0]
    """
    J = _inertia(J)
    r, w = _pair(omega_r, omega_e, "omega_r", "omega_e")
    return _rows(core_relative.coriolis_moments, J, a=r, b=w)


def coriolis_moment_three_term(J, omega_r, omega_e) -> np.ndarray:
    """The Coriolis inertia moment in its three-term form (paper eq. (2)):
    ``M_c = Jω_r × ω_e + Jω_e × ω_r + J(ω_r × ω_e)``; equal to :func:`coriolis_moment`.

    Examples
    --------
    >>> J = np.diag([1.0, 2.0, 3.0])
    >>> np.allclose(coriolis_moment_three_term(J, [0.3, -1, 2], [1, 0.5, 0]),
    ...             coriolis_moment(J, [0.3, -1, 2], [1, 0.5, 0]))
    True
    """
    J = _inertia(J)
    r, w = _pair(omega_r, omega_e, "omega_r", "omega_e")
    return _rows(core_relative.coriolis_moments_three_term, J, a=r, b=w)


def coriolis_moment_particles(masses, rho, omega_r, omega_e) -> np.ndarray:
    """The Coriolis inertia moment by its definition (paper eq. (6)): the moment about the
    centre of mass of the particles' Coriolis inertia forces,
    ``M_c = −2 Σ m ρ × (ω_e × (ω_r × ρ))``.

    Parameters
    ----------
    masses : array_like (N,)
    rho : array_like (N, 3)
        Particle positions relative to the centre of mass, body frame.
    omega_r, omega_e : array_like (3,) or (..., 3)

    Examples
    --------
    >>> coriolis_moment_particles([1.0, 1.0], [[1, 0, 0], [-1, 0, 0]], [0, 0, 1],
    ...                           [1, 0, 0]).tolist()   # J' = diag(2, 0, 0): 2 e3 × 2 e1
    [0.0, 4.0, 0.0]
    """
    m = as_array(masses, "masses", (None,))
    if np.any(m <= 0):
        i = int(np.argmax(m <= 0))
        raise ValueError(f"`masses[{i}]` must be a positive number, found {m[i]}")
    rho = as_array(rho, "rho", (len(m), 3))
    r, w = _pair(omega_r, omega_e, "omega_r", "omega_e")
    return _rows(core_relative.coriolis_moments_particles, np.ascontiguousarray(m),
                 np.ascontiguousarray(rho), a=r, b=w)  # fmt: skip
