"""Smoothing, derivatives and the noise level of a sampled signal (numerical glue, no physics).

Savitzky–Golay filters (SciPy's :func:`scipy.signal.savgol_filter`): a least-squares
polynomial of degree ``order`` over a sliding window, evaluated (or differentiated) at the
window's centre. They need equal spacing: a log whose sample times jitter is resampled onto
its mean spacing first, filtered, and read back at its own times.
"""

from __future__ import annotations

import numpy as np

__all__ = ["smooth", "smoothing_window", "white_noise_std"]

#: Default span of the smoothing window [s]: long enough to average gyro noise, short against
#: a tumble's period (a 30 rad/s spin turns 0.6 rad in it).
SMOOTHING_SPAN = 0.02
#: Relative jitter of the sample spacing below which a log counts as evenly sampled.
EVEN_SPACING = 1e-6


def smoothing_window(t, span: float | None = None, order: int = 3) -> int:
    """An odd number of samples covering about ``span`` seconds (default
    :data:`SMOOTHING_SPAN`), at least ``order + 2`` (a polynomial needs more points than
    coefficients) and at most the number of samples (made odd).

    Examples
    --------
    >>> smoothing_window(np.arange(4001) / 4000.0)
    81
    >>> smoothing_window(np.arange(100) / 100.0)
    5
    """
    t = np.asarray(t, dtype=float)
    n = len(t)
    dt = (t[-1] - t[0]) / max(n - 1, 1)
    span = SMOOTHING_SPAN if span is None else float(span)
    w = round(span / dt) if dt > 0 else order + 2
    w = max(w, order + 2)
    w = min(w, n if n % 2 else n - 1)
    return w if w % 2 else w + 1 if w + 1 <= n else w - 1


def smooth(t, x, *, window: int | None = None, order: int = 3, deriv: int = 0) -> np.ndarray:
    """The Savitzky–Golay smoothed signal (``deriv=0``) or its ``deriv``-th time derivative.

    Parameters
    ----------
    t : array_like, shape (n,)
        Increasing sample times [s].
    x : array_like, shape (n,) or (n, k)
        Samples (columns filtered independently).
    window : int, optional
        Odd window length in samples (default :func:`smoothing_window` of ``t``).
    order : int
        Polynomial degree.
    deriv : int
        Order of the derivative (units of x per second^deriv).

    Returns
    -------
    ndarray, the shape of ``x``.

    Examples
    --------
    The derivative of a cubic is exact:

    >>> t = np.linspace(0.0, 1.0, 201)
    >>> bool(np.allclose(smooth(t, t**3, deriv=1), 3 * t**2))
    True
    """
    from scipy.signal import savgol_filter

    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    n = len(t)
    if window is None:
        window = smoothing_window(t, order=order)
    if n < order + 2:
        raise ValueError(f"smoothing needs at least {order + 2} samples, found {n}")
    dt = (t[-1] - t[0]) / (n - 1)
    grid = t[0] + dt * np.arange(n)
    even = np.max(np.abs(t - grid)) <= EVEN_SPACING * dt
    y = x if even else _interp_columns(grid, t, x)
    out = savgol_filter(y, window, order, deriv=deriv, delta=dt, axis=0, mode="interp")
    return out if even else _interp_columns(t, grid, out)


def _interp_columns(t_new, t, x):
    if x.ndim == 1:
        return np.interp(t_new, t, x)
    return np.column_stack([np.interp(t_new, t, x[:, k]) for k in range(x.shape[1])])


def white_noise_std(x, *, window: int = 7, order: int = 2) -> np.ndarray:
    """The standard deviation of the white noise on a smooth signal, per column.

    The residual ``r = x − S x`` of a short Savitzky–Golay smoother ``S`` keeps the noise and
    almost none of the signal: for white noise of variance σ², ``var r = σ² (1 − c0)`` with
    ``c0`` the filter's central weight. σ is estimated robustly from the median absolute
    residual (``σ ≈ 1.4826 · MAD``), so a few outliers do not count. The estimate is good when
    the signal is nearly a polynomial of degree ``order`` over ``window`` samples (a fast
    sampling rate); otherwise it overestimates σ.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> t = np.arange(4000) / 4000.0
    >>> x = np.sin(2 * np.pi * t)[:, None] + 0.02 * rng.standard_normal((4000, 1))
    >>> bool(abs(white_noise_std(x)[0] / 0.02 - 1) < 0.05)
    True
    """
    from scipy.signal import savgol_coeffs, savgol_filter

    x = np.asarray(x, dtype=float)
    if x.ndim == 1:
        x = x[:, None]
    n = len(x)
    if n < window:
        return np.full(x.shape[1], np.nan)
    c0 = savgol_coeffs(window, order)[window // 2]
    r = x - savgol_filter(x, window, order, axis=0, mode="interp")
    r = r[window // 2 : n - window // 2]
    mad = np.median(np.abs(r - np.median(r, axis=0)), axis=0)
    return 1.482602218505602 * mad / np.sqrt(1.0 - c0)
