"""Finding the free flight in a log: where the body tumbled with nothing touching it.

An accelerometer at the point ``p`` of a body (``p`` from the centre of mass, sensor frame)
reads the specific force ``f = a_p − g``. In free flight the centre of mass falls with ``g``,
so the reading is the rigid-body acceleration of ``p`` relative to the centre of mass, plus the
sensor's bias ``b``:

    f = ω̇ × p + ω × (ω × p) + b,

linear in ``(p, b)`` for a measured ``ω``: ``f = (hat(ω̇) + hat(ω)²) p + b``. Free flight is
the longest stretch of the log that this one model explains (a small bias, a residual at the
noise level); in the hand, at rest or at the catch, the reading holds gravity or the hand's
push, which no lever arm explains. A saturated gyro sample (a reading clipped at the sensor's
range) ends a stretch: its ω is not the body's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._bindings import identify as core_identify
from .signals import smooth, smoothing_window

__all__ = ["FreeFlight", "find_free_flight", "lever_arm_design", "saturated_samples"]

#: A plateau of this many equal consecutive samples at a column's largest |value| marks the
#: sensor's clipping level when no ``saturation`` is given.
PLATEAU = 4
#: The largest accelerometer bias accepted in free flight [m/s²] (a quarter of g: a stretch
#: that needs more holds gravity or a push, not a bias).
MAX_ACCEL_BIAS = 2.5
#: The smallest residual threshold [m/s²] for the lever-arm model's inliers.
MIN_THRESHOLD = 0.3
#: Threshold in units of the seed stretch's residual RMS.
THRESHOLD_SIGMAS = 5.0
#: Length of the seed stretches [s] tried along the log.
SEED_SPAN = 0.04
#: Samples below the threshold interrupted by at most this long a gap [s] still count as one
#: stretch (isolated spikes).
GAP = 0.002


@dataclass(frozen=True)
class FreeFlight:
    """A free-flight stretch of a log.

    Attributes
    ----------
    window : (float, float)
        Its first and last sample times [s].
    start, stop : int
        The samples ``start:stop`` of the log.
    lever_arm : ndarray (3,) or None
        ``p``: the accelerometer's position from the centre of mass, sensor frame [m] (None
        without an accelerometer).
    accel_bias : ndarray (3,) or None
        ``b`` [m/s²].
    accel_residual_rms : float or None
        RMS of ``|f − (ω̇ × p + ω × (ω × p) + b)|`` over the stretch [m/s²].
    saturated : ndarray (n,) of bool
        The samples of the whole log with a clipped gyro reading.
    found_by : str
        ``"accelerometer"``, ``"window"`` (given by the user) or ``"gyroscope"`` (the longest
        stretch without a saturated sample).
    """

    window: tuple[float, float]
    start: int
    stop: int
    lever_arm: np.ndarray | None
    accel_bias: np.ndarray | None
    accel_residual_rms: float | None
    saturated: np.ndarray
    found_by: str


def saturated_samples(omega, saturation: float | None = None) -> np.ndarray:
    """Samples (n,) with a clipped gyro reading.

    With ``saturation`` [rad/s] given: any component with ``|ω_i| ≥ saturation``. Without it,
    a clipping level is recognised as a plateau: at least :data:`PLATEAU` consecutive equal
    samples at a column's largest ``|ω_i|`` (a real peak is not flat over several samples), in a
    column that is not constant over most of the log.

    Examples
    --------
    >>> w = np.zeros((10, 3)); w[3:8, 0] = 35.0; w[2, 0] = 20.0
    >>> np.flatnonzero(saturated_samples(w)).tolist()
    [3, 4, 5, 6, 7]
    >>> np.flatnonzero(saturated_samples(w, 30.0)).tolist()
    [3, 4, 5, 6, 7]
    """
    w = np.asarray(omega, dtype=float)
    if saturation is not None:
        return np.any(np.abs(w) >= saturation, axis=1)
    out = np.zeros(len(w), dtype=bool)
    for k in range(w.shape[1]):
        a = np.abs(w[:, k])
        top = a.max(initial=0.0)
        if top == 0.0:
            continue
        at = a == top
        if at.sum() > len(a) // 2:  # a constant column, not a clipped signal
            continue
        for lo, hi in _runs(at):
            if hi - lo >= PLATEAU and np.all(w[lo:hi, k] == w[lo, k]):
                out[lo:hi] = True
    return out


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """The ``[lo, hi)`` runs of True in ``mask``."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(np.diff(m.astype(np.int8)))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def lever_arm_design(omega, omega_dot) -> np.ndarray:
    """The (n, 3, 6) matrices ``[hat(ω̇) + hat(ω)², 𝟙]`` with ``f = D (p, b)``: the specific
    force of a point ``p`` of a body in free flight, ``ω̇ × p + ω × (ω × p) + b`` (the point's
    acceleration from the compiled core, ``poinsot._core.point_acceleration_matrices``).

    Examples
    --------
    >>> D = lever_arm_design([[0.0, 0.0, 2.0]], [[0.0, 0.0, 0.0]])
    >>> (D[0] @ [0.1, 0.0, 0.0, 0.0, 0.0, 0.0]).tolist()  # centripetal: −ω² p
    [-0.4, 0.0, 0.0]
    """
    w = np.ascontiguousarray(omega, dtype=float)
    wd = np.ascontiguousarray(omega_dot, dtype=float)
    D = np.zeros((len(w), 3, 6))
    D[:, :, :3] = core_identify.point_acceleration_matrices(w, wd)
    D[:, :, 3:] = np.eye(3)
    return D


def _fit(D, f, idx):
    A = D[idx].reshape(-1, D.shape[2])
    y = f[idx].reshape(-1)
    N = A.T @ A  # the small normal matrix (no LAPACK threads on a tall one)
    try:
        return np.linalg.solve(N + 1e-12 * np.trace(N) * np.eye(len(N)), A.T @ y)
    except np.linalg.LinAlgError:
        return np.full(A.shape[1], np.inf)


def _residual(D, f, x):
    return np.linalg.norm(f - D @ x, axis=1)


def _grow(good: np.ndarray, bridgeable: np.ndarray, centre: int, gap: int) -> tuple[int, int]:
    """The stretch ``[lo, hi)`` of ``good`` around ``centre``, bridging gaps of at most
    ``gap`` samples that are all ``bridgeable`` (a saturated sample is never bridged)."""
    n = len(good)
    if not good[centre]:
        return centre, centre
    lo = centre
    while lo > 0:
        j, miss = lo - 1, 0
        while j >= 0 and not good[j] and bridgeable[j] and miss < gap:
            j -= 1
            miss += 1
        if j < 0 or not good[j]:
            break
        lo = j
    hi = centre + 1
    while hi < n:
        j, miss = hi, 0
        while j < n and not good[j] and bridgeable[j] and miss < gap:
            j += 1
            miss += 1
        if j >= n or not good[j]:
            break
        hi = j + 1
    return lo, hi


def find_free_flight(t, omega, accel=None, *, saturation=None, window=None) -> FreeFlight:
    """The free flight of a log: the longest stretch that the lever-arm model explains.

    Parameters
    ----------
    t : ndarray (n,)
        Increasing sample times [s] (checked by the caller).
    omega : ndarray (n, 3)
        Gyro readings [rad/s], sensor frame.
    accel : ndarray (n, 3), optional
        Specific force [m/s²], sensor frame, at the same times. Without it the flight is
        ``window``, or else the longest stretch without a saturated gyro sample.
    saturation : float, optional
        The gyro's clipping level [rad/s] (default: recognised by :func:`saturated_samples`).
    window : (float, float), optional
        Where to look (the user's window): the flight is searched within it.

    Returns
    -------
    FreeFlight

    Raises
    ------
    ValueError
        Naming ``accel`` when no stretch is explained by a lever arm with a small bias, or
        ``omega`` when every sample is saturated.

    Examples
    --------
    >>> from poinsot.identify.synthetic import synthetic_throw
    >>> throw = synthetic_throw(rotor=False, accel=True, hand=True, seed=3)
    >>> flight = find_free_flight(throw.t, throw.omega, throw.accel)
    >>> bool(throw.window[0] <= flight.window[0] < flight.window[1] <= throw.window[1])
    True
    >>> bool(np.linalg.norm(flight.lever_arm - throw.lever_arm) < 1e-3)  # metres
    True
    """
    t = np.asarray(t, dtype=float)
    w = np.asarray(omega, dtype=float)
    n = len(t)
    sat = saturated_samples(w, saturation)
    usable = ~sat
    if window is not None:
        inside = (t >= window[0]) & (t <= window[1])
        usable &= inside
    if not usable.any():
        where = " within `window`" if window is not None else ""
        raise ValueError(f"`omega`: every gyro sample{where} is saturated (clipped)")
    if accel is None:
        lo, hi = max(_runs(usable), key=lambda r: r[1] - r[0])
        found_by = "window" if window is not None else "gyroscope"
        return FreeFlight((float(t[lo]), float(t[hi - 1])), lo, hi, None, None, None, sat,
                          found_by)  # fmt: skip
    f = np.asarray(accel, dtype=float)
    win = smoothing_window(t)
    wd = smooth(t, w, window=win, deriv=1)
    D = lever_arm_design(w, wd)
    dt = (t[-1] - t[0]) / max(n - 1, 1)
    seed = max(12, round(SEED_SPAN / dt))
    gap = max(2, round(GAP / dt))
    best = None
    covered = np.zeros(n, dtype=bool)
    for centre in range(seed // 2, n - seed // 2, max(1, seed // 2)):
        if covered[centre] or not usable[centre]:
            continue
        idx = np.arange(centre - seed // 2, centre + seed // 2 + 1)
        idx = idx[usable[idx]]
        if len(idx) < 12:
            continue
        # over a short seed ω hardly changes, so p and b cannot be told apart: fit p alone
        x = np.zeros(6)
        x[:3] = _fit(D[:, :, :3], f, idx)
        if np.sqrt(np.mean(_residual(D[idx], f[idx], x) ** 2)) > MAX_ACCEL_BIAS:
            continue  # gravity or a push: not a free flight
        for _ in range(6):
            r = _residual(D, f, x)
            rms = float(np.sqrt(np.mean(r[idx] ** 2)))
            tau = max(THRESHOLD_SIGMAS * rms, MIN_THRESHOLD)
            lo, hi = _grow((r < tau) & usable, usable, centre, gap)
            if hi - lo < 12:
                break
            new = np.arange(lo, hi)
            new = new[usable[new]]
            if np.array_equal(new, idx):
                break
            idx = new
            x = _fit(D, f, idx) if len(idx) >= 4 * seed else np.r_[_fit(D[:, :, :3], f, idx),
                                                                   0.0, 0.0, 0.0]  # fmt: skip
        if len(idx) < 12 or np.linalg.norm(x[3:]) > MAX_ACCEL_BIAS:
            continue
        lo, hi = int(idx[0]), int(idx[-1]) + 1
        covered[lo:hi] = True
        if best is None or hi - lo > best[1] - best[0]:
            best = (lo, hi, x)
    if best is None:
        raise ValueError(
            "`accel`: no free flight found: no stretch of the log is explained by a rigid "
            f"lever arm f = ω̇ × p + ω × (ω × p) + b with |b| ≤ {MAX_ACCEL_BIAS} m/s² (is the "
            "accelerometer in m/s², in the gyro's frame and at the gyro's times?)"
        )
    lo, hi, x = best
    # the smoothed ω̇ near the ends mixes in the throw and the catch: trim half a window
    trim = win // 2
    if hi - lo > 4 * trim:
        lo, hi = lo + trim, hi - trim
    r = _residual(D, f, x)[lo:hi]
    return FreeFlight(
        (float(t[lo]), float(t[hi - 1])),
        lo,
        hi,
        x[:3].copy(),
        x[3:].copy(),
        float(np.sqrt(np.mean(r**2))),
        sat,
        "accelerometer",
    )
