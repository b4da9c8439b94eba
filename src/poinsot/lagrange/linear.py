"""Equilibria of a Lagrangian system and its linearisation about them.

Equilibria solve ``f(q, 0, t0) + G_hᵀ λ = 0`` and ``g(q, t0) = 0`` (q̇ = 0) by Newton's method
(``scipy.optimize.root``) from many starting points; the linearisation is the Jacobian of the
first-order equations of motion at ``(q*, 0)`` by central differences, restricted to the tangent
space of the constraint manifold (null space of the constraint Jacobian).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

__all__ = ["Linearization", "equilibria", "linearize"]


@dataclass(frozen=True)
class Linearization:
    """A linearisation about an equilibrium.

    Attributes
    ----------
    equilibrium : dict {coordinate: value}
    matrix : ndarray (d, d)
        The linear map of the first-order system on the constraint manifold's tangent space
        (d = 2n − m_holonomic − m).
    eigenvalues : ndarray (d,) complex
    frequencies : ndarray
        Natural frequencies in rad/s: the distinct positive imaginary parts of the eigenvalues.
    stable : bool
        Linear stability: no eigenvalue with positive real part (beyond round-off); undamped
        oscillations (centres) count as stable.
    """

    equilibrium: dict
    matrix: np.ndarray
    eigenvalues: np.ndarray
    frequencies: np.ndarray
    stable: bool


def _numeric(system, params):
    from .numeric import _numeric as build
    from .numeric import as_params

    return build(system, as_params(params, system))


def equilibria(system, params=None, *, bounds=None, starts=None, t=0.0, tol=1e-10):
    """Equilibria of ``system``: a list of ``{coordinate: value}`` (duplicates removed).

    Parameters
    ----------
    bounds : dict {coordinate: (low, high)}, optional
        Where to start the Newton iterations (default ``(−π, π)`` for every coordinate);
        solutions outside the box are kept too.
    starts : int, optional
        Starting points per coordinate (default 13 for one coordinate, 7 for two, else 150
        random points in the box).
    """
    from scipy.optimize import root

    num = _numeric(system, params)
    n, nh = system.n_coordinates, system.n_holonomic
    zeros = np.zeros(n)
    lo = np.full(n, -np.pi)
    hi = np.full(n, np.pi)
    for q, (a, b) in (bounds or {}).items():
        if q not in system.coordinates:
            raise ValueError(f"`bounds`: {q} is not a coordinate of the system")
        lo[system.coordinates.index(q)], hi[system.coordinates.index(q)] = a, b

    def residual(x):
        q, lam = x[:n], x[n:]
        f = num.mat(num.f, q, zeros, t, (n,))
        if not nh:
            return f
        G = num.mat(num.G, q, zeros, t, (num.m, n))[:nh]
        g = num.mat(num.g, q, zeros, t, (nh,))
        return np.concatenate([f + G.T @ lam, g])

    if n <= 2:
        k = starts or (13 if n == 1 else 7)
        grid = [np.linspace(lo[i], hi[i], k) for i in range(n)]
        points = [np.array(p) for p in itertools.product(*grid)]
    else:
        rng = np.random.default_rng(0)
        points = list(rng.uniform(lo, hi, size=(starts or 150, n)))
    found = []
    for p in points:
        x0 = np.concatenate([p, np.zeros(nh)])
        with np.errstate(all="ignore"):
            sol = root(residual, x0, method="hybr", tol=1e-14)
        if not np.all(np.isfinite(sol.x)):
            continue
        r = residual(sol.x)
        if np.max(np.abs(r)) > tol * (1 + np.max(np.abs(sol.x))):
            continue
        q = sol.x[:n]
        if not any(np.max(np.abs(q - f)) < 1e-7 * (1 + np.max(np.abs(q))) for f in found):
            found.append(q)
    found.sort(key=lambda q: tuple(np.round(q, 9)))
    return [dict(zip(system.coordinates, map(float, q), strict=True)) for q in found]


def _null_space(A, n):
    if A.shape[0] == 0:
        return np.eye(n)
    _, s, vt = np.linalg.svd(A)
    rank = int(np.sum(s > 1e-10 * max(1.0, s.max())))
    return vt[rank:].T


def linearize(system, equilibrium, params=None, *, t=0.0):
    """Linearise about ``equilibrium`` ({coordinate: value}, q̇ = 0): eigenvalues, natural
    frequencies (rad/s) and stability; see :class:`Linearization`."""
    from .numeric import _ODE

    num = _numeric(system, params)
    n, m, nh = system.n_coordinates, num.m, num.n_hol
    q0 = np.empty(n)
    for i, q in enumerate(system.coordinates):
        if q not in equilibrium:
            raise ValueError(f"`equilibrium` must give every coordinate: missing {q}")
        q0[i] = float(equilibrium[q])
    ode = _ODE(num, None, (0.0, 0.0))
    y0 = np.concatenate([q0, np.zeros(n)])
    f0 = ode.rhs(t, y0)
    if np.max(np.abs(f0[n:])) > 1e-8 * (1 + np.max(np.abs(f0))):
        raise ValueError(
            f"`equilibrium` is not an equilibrium: accelerations {np.round(f0[n:], 10).tolist()}"
        )
    J = np.empty((2 * n, 2 * n))
    for j in range(2 * n):
        h = 1e-6 * (1 + abs(y0[j]))
        e = np.zeros(2 * n)
        e[j] = h
        J[:, j] = (ode.rhs(t, y0 + e) - ode.rhs(t, y0 - e)) / (2 * h)
    G = num.mat(num.G, q0, np.zeros(n), t, (m, n)) if m else np.zeros((0, n))
    Nq = _null_space(G[:nh], n)
    Nv = _null_space(G, n)
    T = np.zeros((2 * n, Nq.shape[1] + Nv.shape[1]))
    T[:n, : Nq.shape[1]] = Nq
    T[n:, Nq.shape[1] :] = Nv
    A = np.linalg.pinv(T) @ J @ T
    eig = np.linalg.eigvals(A)
    scale = max(1.0, float(np.abs(eig).max()))
    freqs = np.unique(np.round(eig.imag[eig.imag > 1e-9 * scale], 10))
    stable = bool(np.all(eig.real <= 1e-6 * scale))
    return Linearization(dict(equilibrium), A, eig, freqs, stable)
