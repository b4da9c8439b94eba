"""The equation-error estimate: the gyrostat equation solved for the inertia as a linear
least-squares problem (``docs/theory.md`` §4).

Along a motion of the gyrostat, ``I ω̇ + ω × (I ω + h) + ḣ = 0`` with ``h = J ω_R a``. For
measured ``ω``, ``ω̇``, ``ω_R``, ``ω̇_R`` this is linear in ``θ = (I11, I22, I33, I12, I13, I23,
J)``: ``Φ θ = 0`` with the regressor ``Φ`` (3 rows per sample) of the compiled core
(``poinsot._core.gyrostat_regressor``). The derivatives come from Savitzky–Golay filters
(:mod:`poinsot.identify.signals`).

* No rotor: ``θ = I`` is the right singular vector of the smallest singular value of the
  stacked ``Φ`` (its null vector): ``I`` up to scale.
* A rotor of unknown ``J``: the null vector of all seven columns: ``(I, J)`` up to one scale.
* A rotor of known ``J``: ``Φ_I θ_I = −J Φ_J``, an ordinary least-squares problem: ``I`` in
  the units of ``J``.

The smoothed derivatives make this estimate slightly biased; it is the starting point of the
output-error fit (:mod:`poinsot.identify.output_error`), which is not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _core
from .signals import smooth, smoothing_window

__all__ = ["EquationErrorFit", "equation_error", "inertia_from_entries"]


@dataclass(frozen=True)
class EquationErrorFit:
    """The equation-error estimate.

    Attributes
    ----------
    inertia : ndarray (3, 3)
        Sensor frame; in the units of ``rotor_inertia`` when that was given (``absolute``),
        else normalised to trace 1.
    rotor_inertia : float or None
        ``J`` on the scale of ``inertia`` (given, fitted, or None without a rotor).
    absolute : bool
        Whether ``inertia`` is in physical units (``J`` given).
    singular_values : ndarray
        Of the column-scaled regressor, descending.
    condition : float
        ``σ_1 / σ_k`` of the column-scaled regressor, ``σ_k`` the smallest singular value
        that must be nonzero (the second smallest for a null vector): large when the motion
        does not excite every unknown.
    """

    inertia: np.ndarray
    rotor_inertia: float | None
    absolute: bool
    singular_values: np.ndarray
    condition: float


def inertia_from_entries(theta) -> np.ndarray:
    """The symmetric (3, 3) matrix of ``(I11, I22, I33, I12, I13, I23)``.

    Examples
    --------
    >>> inertia_from_entries([1, 2, 3, 4, 5, 6]).tolist()
    [[1.0, 4.0, 5.0], [4.0, 2.0, 6.0], [5.0, 6.0, 3.0]]
    """
    a, b, c, d, e, f = (float(x) for x in theta)
    return np.array([[a, d, e], [d, b, f], [e, f, c]])


def equation_error(
    t,
    omega,
    *,
    rotor_speed=None,
    rotor_axis=None,
    rotor_inertia=None,
    window: int | None = None,
) -> EquationErrorFit:
    """Estimate the inertia from the gyrostat equation by linear least squares.

    Parameters
    ----------
    t : ndarray (n,)
        Increasing times [s] of one free flight.
    omega : ndarray (n, 3)
        Gyro readings [rad/s], sensor frame.
    rotor_speed : ndarray (n,), optional
        The rotor's speed relative to the body [rad/s].
    rotor_axis : ndarray (3,), optional
        Its unit axis, sensor frame (required with ``rotor_speed``).
    rotor_inertia : float, optional
        Its axial moment of inertia ``J`` [kg m²]; fitted (on the scale of the result) when
        not given.
    window : int, optional
        Savitzky–Golay window in samples (default about 20 ms).

    Returns
    -------
    EquationErrorFit

    Examples
    --------
    A torque-free tumble of a box with moments (1, 2, 3):

    >>> from poinsot.torquefree import FreeRigidBody
    >>> t = np.linspace(0.0, 3.0, 3001)
    >>> w = FreeRigidBody((1.0, 2.0, 3.0)).exact_omega((1.0, 2.0, 0.5), t)
    >>> fit = equation_error(t, w)
    >>> (fit.inertia / fit.inertia[0, 0]).diagonal().round(4).tolist()
    [1.0, 2.0, 3.0]
    """
    t = np.asarray(t, dtype=float)
    w = np.asarray(omega, dtype=float)
    win = smoothing_window(t) if window is None else int(window)
    ws = smooth(t, w, window=win)
    wd = smooth(t, w, window=win, deriv=1)
    n = len(t)
    if rotor_speed is None:
        s = np.zeros(n)
        sd = np.zeros(n)
        axis = np.array([1.0, 0.0, 0.0])
    else:
        s = smooth(t, rotor_speed, window=win)
        sd = smooth(t, rotor_speed, window=win, deriv=1)
        axis = np.asarray(rotor_axis, dtype=float)
    # the filter's ends extrapolate: drop half a window on each side when there is room
    keep = slice(win // 2, n - win // 2) if n > 4 * win else slice(0, n)
    phi = _core.gyrostat_regressor(
        np.ascontiguousarray(ws[keep]),
        np.ascontiguousarray(wd[keep]),
        np.ascontiguousarray(s[keep]),
        np.ascontiguousarray(sd[keep]),
        axis,
    )
    A = phi.reshape(-1, 7)
    if rotor_speed is None:
        A = A[:, :6]
    norms = np.linalg.norm(A, axis=0)
    norms[norms == 0] = 1.0
    if rotor_speed is not None and rotor_inertia is not None:
        J = float(rotor_inertia)
        As = A[:, :6] / norms[:6]
        sv = np.linalg.svd(As, compute_uv=False)
        x, *_ = np.linalg.lstsq(As, -J * A[:, 6], rcond=None)
        I = inertia_from_entries(x / norms[:6])
        cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf
        return EquationErrorFit(I, J, True, sv, cond)
    As = A / norms
    _, sv, vt = np.linalg.svd(As, full_matrices=False)
    v = vt[-1] / norms
    I = inertia_from_entries(v[:6])
    tr = np.trace(I)
    if tr == 0:
        tr = 1.0
    I = I / tr
    J = float(v[6] / tr) if rotor_speed is not None else None
    cond = float(sv[0] / sv[-2]) if sv[-2] > 0 else np.inf
    return EquationErrorFit(I, J, False, sv, cond)
