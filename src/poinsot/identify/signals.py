"""Smoothing, derivatives and the noise level of a sampled signal (numerical glue, no physics).

Savitzky–Golay filters: a least-squares polynomial of degree ``order`` over a sliding window,
evaluated (or differentiated) at the window's centre; the first and last half windows take
the polynomial fitted to the first and last whole window (SciPy's ``mode="interp"``). The
filter is :func:`scipy.signal.savgol_filter`'s, written here in a few lines of NumPy
(:func:`savgol`, tested against SciPy's to round-off) because importing ``scipy.signal``
costs about 0.4 s, close to half of what identifying a throw may take from a cold start.
The filters need equal spacing: a log whose sample times jitter is resampled onto its mean
spacing first, filtered, and read back at its own times.
"""

from __future__ import annotations

import numpy as np

__all__ = ["savgol", "savgol_weights", "smooth", "smoothing_window", "white_noise_std"]

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


def _fit_matrix(window: int, order: int) -> np.ndarray:
    """``pinv(V)`` (order + 1, window) of the Vandermonde matrix ``V[i, j] = x_i^j`` on the
    window's positions ``x = −h … h``: the least-squares polynomial's coefficients."""
    h = window // 2
    x = np.arange(-h, h + 1, dtype=float)
    return np.linalg.pinv(np.vander(x, order + 1, increasing=True))


def _derivative_row(r, order: int, deriv: int) -> np.ndarray:
    """``d^deriv/dx^deriv`` of the monomials ``x^j``, j = 0 … order, at ``x = r`` (any shape)."""
    r = np.asarray(r, dtype=float)[..., None]
    j = np.arange(order + 1)
    factor = np.ones(order + 1)
    for k in range(deriv):
        factor *= np.clip(j - k, 0, None)
    power = np.clip(j - deriv, 0, None)
    return factor * r**power


def savgol_weights(window: int, order: int, deriv: int = 0, delta: float = 1.0) -> np.ndarray:
    """The Savitzky–Golay filter (window,): the ``deriv``-th derivative at the window's centre
    of the degree-``order`` least-squares polynomial, for samples ``delta`` apart; the
    coefficients of :func:`scipy.signal.savgol_coeffs` with ``use="dot"``.

    Examples
    --------
    >>> savgol_weights(5, 2).round(6).tolist()  # the classic (−3, 12, 17, 12, −3)/35
    [-0.085714, 0.342857, 0.485714, 0.342857, -0.085714]
    """
    row = _derivative_row(0.0, order, deriv)
    return row @ _fit_matrix(window, order) / delta**deriv


def savgol(x, window: int, order: int, deriv: int = 0, delta: float = 1.0) -> np.ndarray:
    """Savitzky–Golay filtering of ``x`` (n,) or (n, k) along its first axis, with SciPy's
    ``mode="interp"`` ends: the values of :func:`scipy.signal.savgol_filter`.

    Examples
    --------
    >>> x = np.arange(10.0) ** 2
    >>> (savgol(x, 5, 2, deriv=1).round(9) + 0.0).tolist()  # exact on a parabola, ends too
    [0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0]
    """
    from numpy.lib.stride_tricks import sliding_window_view

    x = np.require(x, dtype=float, requirements=["C", "A"])  # rounding whatever the layout
    flat = x.ndim == 1
    x2 = x[:, None] if flat else x
    n = len(x2)
    if window % 2 != 1 or window > n or order >= window:
        raise ValueError(f"savgol needs an odd window ≤ {n} samples above the order {order}, "
                         f"found {window}")  # fmt: skip
    h = window // 2
    fit = _fit_matrix(window, order)
    w = _derivative_row(0.0, order, deriv) @ fit / delta**deriv
    out = np.empty_like(x2)
    out[h : n - h] = sliding_window_view(x2, window, axis=0) @ w
    # the ends: the polynomial of the first (last) whole window, at the positions it covers
    ends = _derivative_row(np.arange(-h, 0), order, deriv) @ fit / delta**deriv
    out[:h] = ends @ x2[:window]
    tail = _derivative_row(np.arange(1, h + 1), order, deriv) @ fit / delta**deriv
    out[n - h :] = tail @ x2[n - window :]
    return out[:, 0] if flat else out


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
    out = savgol(y, window, order, deriv=deriv, delta=dt)
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
    x = np.asarray(x, dtype=float)
    if x.ndim == 1:
        x = x[:, None]
    n = len(x)
    if n < window:
        return np.full(x.shape[1], np.nan)
    c0 = savgol_weights(window, order)[window // 2]
    r = x - savgol(x, window, order)
    r = r[window // 2 : n - window // 2]
    mad = np.median(np.abs(r - np.median(r, axis=0)), axis=0)
    return 1.482602218505602 * mad / np.sqrt(1.0 - c0)
