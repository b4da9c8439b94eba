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

from .._bindings import identify as core_identify
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
        Of the column-scaled regressor (unit-norm columns), descending.
    condition : float
        ``σ_1 / σ_k`` of the column-scaled regressor, ``σ_k`` the smallest singular value
        that must be nonzero (the second smallest for a null vector): large when the motion
        does not excite every unknown.
    gap : float
        ``σ_{p−1} / σ_p`` for a null vector (inf for an ordinary least-squares problem): near 1
        when a second direction is almost as null as the first, so the estimate is ambiguous
        (see :meth:`candidates`).
    null_pair : ndarray (2, p) or None
        The right singular vectors of the two smallest singular values (unscaled; ``p`` = 6,
        or 7 with ``J``), for a null vector.
    """

    inertia: np.ndarray
    rotor_inertia: float | None
    absolute: bool
    singular_values: np.ndarray
    condition: float
    gap: float = np.inf
    null_pair: np.ndarray | None = None

    def candidates(self, n: int = 12) -> list[tuple[np.ndarray, float | None]]:
        """Physical inertias (trace 1) along the pencil ``cos φ v_p + sin φ v_{p−1}`` of the two
        most nearly null directions, at ``n`` angles in [0, π): those that are positive
        definite and obey ``I1 + I2 ≥ I3``, each with its ``J`` (None without a rotor). When
        :attr:`gap` is near 1 the data cannot choose among them by this linear fit; the
        output-error fit started from each can."""
        if self.null_pair is None:
            return []
        out = []
        v6, v5 = self.null_pair
        for phi in np.pi * np.arange(n) / n:
            v = np.cos(phi) * v6 + np.sin(phi) * v5
            I = inertia_from_entries(v[:6])
            tr = np.trace(I)
            if tr == 0:
                continue
            I = I / tr
            m = np.linalg.eigvalsh(I)
            if m[0] > 0 and m[0] + m[1] >= m[2] * (1 - 1e-9):
                out.append((I, float(v[6] / tr) if len(v) > 6 else None))
        return out

    @property
    def physical(self) -> bool:
        """Whether :attr:`inertia` is positive definite and obeys ``I1 + I2 ≥ I3``."""
        m = np.linalg.eigvalsh(self.inertia)
        return bool(m[0] > 0 and m[0] + m[1] >= m[2] * (1 - 1e-9))


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
    phi = core_identify.gyrostat_regressor(
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
    # the small normal matrix (columns scaled to unit norm) rather than an SVD of the tall
    # regressor: the same singular vectors, and no LAPACK threads on a tall matrix
    if rotor_speed is not None and rotor_inertia is not None:
        J = float(rotor_inertia)
        As = A[:, :6] / norms[:6]
        N = As.T @ As
        sv = _singular_values(N)
        x = np.linalg.solve(N, As.T @ (-J * A[:, 6])) if sv[-1] > 0 else np.full(6, np.nan)
        I = inertia_from_entries(x / norms[:6])
        cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf
        return EquationErrorFit(I, J, True, sv, cond)
    As = A / norms
    lam, V = np.linalg.eigh(As.T @ As)
    sv = np.sqrt(np.clip(lam[::-1], 0.0, None))
    v = V[:, 0] / norms
    I = inertia_from_entries(v[:6])
    tr = np.trace(I)
    if tr == 0:
        tr = 1.0
    I = I / tr
    J = float(v[6] / tr) if rotor_speed is not None else None
    cond = float(sv[0] / sv[-2]) if sv[-2] > 0 else np.inf
    gap = float(sv[-2] / sv[-1]) if sv[-1] > 0 else np.inf
    pair = np.array([V[:, 0] / norms, V[:, 1] / norms])
    return EquationErrorFit(I, J, False, sv, cond, gap, pair)


def _singular_values(N) -> np.ndarray:
    """Singular values (descending) of ``A`` from ``N = AᵀA``."""
    return np.sqrt(np.clip(np.linalg.eigvalsh(N)[::-1], 0.0, None))
